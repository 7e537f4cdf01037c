//! The checks of the generator config's values, shared by every section's `validate`: a range
//! `[min, max]`, a count range and a probability, each error naming the value's TOML key
//! (`road.radius`, `rig.baseline`, ...) and what it must be.

use crate::procedural::{CountRange, Range};

/// The checks of one section of the config; its name prefixes each key (empty: the keys are
/// given in full).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Section(pub(crate) &'static str);

impl Section {
    /// The full key of `name`.
    fn key(&self, name: &str) -> String {
        if self.0.is_empty() {
            name.to_owned()
        } else {
            format!("{}.{name}", self.0)
        }
    }

    /// `r` is a range `[min, max]` of finite values with `min <= max`, within `[lo, hi]`.
    pub(crate) fn range(&self, name: &str, r: Range, lo: f64, hi: f64) -> Result<(), String> {
        if r.iter().all(|v| v.is_finite() && (lo..=hi).contains(v)) && r[0] <= r[1] {
            Ok(())
        } else {
            Err(format!(
                "{} = [{}, {}] must be a range [min, max] with min <= max, within [{lo}, {hi}]",
                self.key(name),
                r[0],
                r[1]
            ))
        }
    }

    /// `r` is a count range `[min, max]` with `min <= max <= hi`.
    pub(crate) fn count(&self, name: &str, r: CountRange, hi: u32) -> Result<(), String> {
        if r[0] <= r[1] && r[1] <= hi {
            Ok(())
        } else {
            Err(format!(
                "{} = [{}, {}] must be a range [min, max] with min <= max <= {hi}",
                self.key(name),
                r[0],
                r[1]
            ))
        }
    }

    /// `p` is a probability in `[0, 1]`.
    pub(crate) fn prob(&self, name: &str, p: f64) -> Result<(), String> {
        if p.is_finite() && (0.0..=1.0).contains(&p) {
            Ok(())
        } else {
            Err(format!(
                "{} = {p} must be a probability in [0, 1]",
                self.key(name)
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_key_and_the_rule() {
        let road = Section("road");
        assert!(road.range("radius", [60.0, 400.0], 10.0, 1e4).is_ok());
        for bad in [[400.0, 60.0], [f64::NAN, 1.0], [1.0, 2e4]] {
            let e = road.range("radius", bad, 10.0, 1e4).unwrap_err();
            assert!(
                e.starts_with("road.radius = [") && e.contains("within [10, 10000]"),
                "{e}"
            );
        }
        assert!(road.count("potholes", [0, 4], 50).is_ok());
        let e = road.count("potholes", [5, 4], 50).unwrap_err();
        assert!(
            e.contains("road.potholes = [5, 4]") && e.contains("<= 50"),
            "{e}"
        );
        assert!(road.count("potholes", [0, 51], 50).is_err());
        let top = Section("");
        assert!(top.prob("rig.headlights", 1.0).is_ok());
        for p in [-0.1, 1.5, f64::NAN] {
            let e = top.prob("rig.headlights", p).unwrap_err();
            assert!(
                e.starts_with("rig.headlights = ") && e.contains("probability"),
                "{e}"
            );
        }
    }
}
