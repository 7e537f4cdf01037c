//! The scene's fog, from `scenes[i].extras.streaks.fog`: `{"sigma_t": s | [r, g, b],
//! "albedo": a | [r, g, b], "g": g, "height_falloff": k, "reference_height": y0}`, with
//! `sigma_t` the extinction per metre at height `y0` (scalar or RGB), `albedo` the
//! single-scattering albedo, `g` the Henyey-Greenstein asymmetry (Mitsuba's sign, > 0
//! forward), `height_falloff` the exponential falloff of the density with height per metre
//! (optional, 0: homogeneous) and `reference_height` in metres (optional, 0). See
//! [`crate::medium::Fog`].

use super::Loader;
use crate::medium::Fog;
use crate::scene::SceneError;
use glam::Vec3;
use serde::Deserialize;

/// A scalar or an RGB triple named `key`, as linear RGB.
fn colour(key: &str, value: &serde_json::Value) -> Result<Vec3, String> {
    let number = |v: &serde_json::Value| v.as_f64().map(|x| x as f32);
    if let Some(x) = number(value) {
        return Ok(Vec3::splat(x));
    }
    match value
        .as_array()
        .map(|a| a.iter().map(number).collect::<Option<Vec<f32>>>())
    {
        Some(Some(c)) if c.len() == 3 => Ok(Vec3::new(c[0], c[1], c[2])),
        _ => Err(format!("{key} must be a number or [r, g, b], got {value}")),
    }
}

/// `extras.streaks.fog` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FogExtras {
    sigma_t: serde_json::Value,
    albedo: serde_json::Value,
    g: f32,
    height_falloff: Option<f32>,
    reference_height: Option<f32>,
}

impl Loader<'_> {
    /// The fog `scene`'s extras give, if any.
    pub(super) fn fog(&self, scene: &gltf::Scene) -> Result<Option<Fog>, SceneError> {
        let element = format!("scene {}, extras.streaks.fog", scene.index());
        let bad = |reason: String| self.bad(&element, reason);
        let Some(raw) = scene.extras() else {
            return Ok(None);
        };
        let extras: serde_json::Value =
            serde_json::from_str(raw.get()).map_err(|e| bad(format!("extras: {e}")))?;
        let Some(value) = extras.pointer("/streaks/fog") else {
            return Ok(None);
        };
        let fog: FogExtras =
            serde_json::from_value(value.clone()).map_err(|e| bad(e.to_string()))?;
        Fog::new(
            colour("sigma_t", &fog.sigma_t).map_err(bad)?,
            colour("albedo", &fog.albedo).map_err(bad)?,
            fog.g,
            fog.height_falloff.unwrap_or(0.0),
            fog.reference_height.unwrap_or(0.0),
        )
        .map(Some)
        .map_err(|e| bad(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{load_doc, load_err, test_doc, test_doc_with_streaks_extra};
    use crate::medium::Fog;
    use glam::Vec3;
    use serde_json::json;

    /// The test document with `fog` in its scene's extras, and its buffer.
    fn doc(fog: serde_json::Value) -> (serde_json::Value, Vec<u8>) {
        test_doc_with_streaks_extra("fog", fog)
    }

    #[test]
    fn fog_is_read_scalar_or_rgb_with_its_defaults() {
        let (d, bin) = doc(json!({"sigma_t": 0.05, "albedo": [0.9, 0.8, 0.7], "g": 0.7}));
        let s = load_doc(d, &bin);
        let expected = Fog::new(Vec3::splat(0.05), Vec3::new(0.9, 0.8, 0.7), 0.7, 0.0, 0.0);
        assert_eq!(s.fog, Some(expected.unwrap()));
        let (d, bin) = doc(
            json!({"sigma_t": [0.01, 0.02, 0.03], "albedo": 1.0, "g": -0.2,
                                  "height_falloff": 0.1, "reference_height": 2.0}),
        );
        let s = load_doc(d, &bin);
        let expected = Fog::new(Vec3::new(0.01, 0.02, 0.03), Vec3::ONE, -0.2, 0.1, 2.0);
        assert_eq!(s.fog, Some(expected.unwrap()));
        let (d, bin) = test_doc();
        assert_eq!(load_doc(d, &bin).fog, None);
    }

    #[test]
    fn bad_fog_is_an_error_naming_the_key() {
        for (fog, needle) in [
            (json!({"sigma_t": -1.0, "albedo": 1.0, "g": 0.5}), "sigma_t"),
            (
                json!({"sigma_t": 0.1, "albedo": [1.0, 2.0, 1.0], "g": 0.5}),
                "albedo",
            ),
            (json!({"sigma_t": 0.1, "albedo": 1.0, "g": 1.0}), "g must"),
            (json!({"sigma_t": 0.1, "albedo": 1.0}), "g"),
            (
                json!({"sigma_t": 0.1, "albedo": 1.0, "g": 0.1, "height_falloff": -1}),
                "height_falloff",
            ),
            (
                json!({"sigma_t": 0.1, "albedo": 1.0, "g": 0.1, "density": 1}),
                "density",
            ),
            (
                json!({"sigma_t": [0.1, 0.2], "albedo": 1.0, "g": 0.1}),
                "sigma_t",
            ),
        ] {
            let (d, bin) = doc(fog.clone());
            let err = load_err(d, &bin);
            assert!(
                err.contains("extras.streaks.fog") && err.contains(needle),
                "{fog}: {err}"
            );
        }
    }
}
