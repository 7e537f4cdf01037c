//! `--shard K/N`: the samples whose index is K modulo N.

use std::fmt;
use std::str::FromStr;

/// One shard of a dataset: the indices `i` with `i % count == index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// K, in `0..count`.
    pub index: u64,
    /// N, at least 1.
    pub count: u64,
}

impl Shard {
    /// The whole dataset (shard 0/1).
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Whether sample `i` belongs to this shard.
    pub fn contains(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let usage = "expected K/N with whole numbers 0 <= K < N, e.g. 0/4";
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("{s:?} has no '/': {usage}"))?;
        let number = |v: &str, what: &str| {
            v.trim()
                .parse::<u64>()
                .map_err(|_| format!("{what} {v:?} in {s:?} is not a whole number: {usage}"))
        };
        let (index, count) = (number(k, "K")?, number(n, "N")?);
        if count == 0 {
            return Err(format!("N must be at least 1 in {s:?}: {usage}"));
        }
        if index >= count {
            return Err(format!(
                "K = {index} must be less than N = {count} in {s:?} (shards are 0/{count} to {}/{count})",
                count - 1
            ));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_partition_the_indices() {
        let s: Shard = "1/3".parse().unwrap();
        assert_eq!(s, Shard { index: 1, count: 3 });
        assert_eq!(s.to_string(), "1/3");
        let picked: Vec<u64> = (0..8).filter(|&i| s.contains(i)).collect();
        assert_eq!(picked, [1, 4, 7]);
        assert!((0..5).all(|i| Shard::ALL.contains(i)));
        for (bad, needle) in [
            ("3/3", "less than"),
            ("0/0", "at least 1"),
            ("1", "no '/'"),
            ("a/2", "K \"a\""),
            ("1/-2", "N \"-2\""),
        ] {
            let err = bad.parse::<Shard>().unwrap_err();
            assert!(err.contains(needle), "{bad}: {err}");
        }
    }
}
