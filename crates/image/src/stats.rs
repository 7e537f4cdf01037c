//! Order statistics of pixel values: quantiles and medians, written once for the stereo code
//! (streak-mask thresholds), the analysis (detector noise floors, SGM display ranges, report
//! medians) and the dataset summary.
//!
//! Every function here looks only at the finite values (`inf` marks an invalid disparity in
//! the PFM convention, NaN a failed pixel) unless its documentation says otherwise, and
//! returns `None` when there are none, so that each caller says what an empty set means to it.
//!
//! Three definitions are in use, each kept because numbers the project writes depend on it:
//!
//! - [`quantile`] (and [`median`], [`quantile_in`], [`quantile_sorted`]): the **nearest rank**,
//!   the element at index `round(p (n - 1))` of the sorted values, computed in the values' own
//!   precision; the median of an even count is the upper of the two middle values;
//! - [`quantile_below`]: the element at index `floor(p (n - 1))` (the rank at or below);
//! - [`median_midpoint`]: the mean of the two middle values of an even count (a small
//!   neighbourhood's median, where the upper one would bias a two-pixel window).

use std::cmp::Ordering;

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A float type the quantiles work on: `f32` (pixels) or `f64` (statistics of many images).
///
/// The rank is computed in the type's own precision, so that a quantile picks the element it
/// picked when each crate computed it itself.
pub trait Sample: Copy + sealed::Sealed {
    /// One half, the median's `p`.
    const HALF: Self;
    /// Whether the value is neither infinite nor NaN.
    fn is_finite(self) -> bool;
    /// The total order of IEEE 754 (`f32::total_cmp`).
    fn total_cmp(&self, other: &Self) -> Ordering;
    /// The index `round(p (n - 1))`, at most `n - 1`, of the `p`-quantile of `n > 0` sorted
    /// values.
    fn nearest_rank(p: Self, n: usize) -> usize;
}

/// The one implementation of [`Sample`], for each float type.
macro_rules! sample {
    ($t:ty) => {
        impl Sample for $t {
            const HALF: $t = 0.5;
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            fn total_cmp(&self, other: &$t) -> Ordering {
                <$t>::total_cmp(self, other)
            }
            fn nearest_rank(p: $t, n: usize) -> usize {
                ((p * (n - 1) as $t).round() as usize).min(n - 1)
            }
        }
    };
}
sample!(f32);
sample!(f64);

/// The `p`-quantile (`p` in 0..=1) of the finite `values` by the nearest rank, with `buf` as
/// scratch space (cleared first; pass the same one on hot paths to allocate once); `None` when
/// no value is finite.
pub fn quantile_in<T: Sample>(
    values: impl IntoIterator<Item = T>,
    p: T,
    buf: &mut Vec<T>,
) -> Option<T> {
    buf.clear();
    buf.extend(values.into_iter().filter(|v| v.is_finite()));
    if buf.is_empty() {
        return None;
    }
    let k = T::nearest_rank(p, buf.len());
    Some(*buf.select_nth_unstable_by(k, T::total_cmp).1)
}

/// The `p`-quantile (`p` in 0..=1) of the finite `values` by the nearest rank; `None` when no
/// value is finite. [`quantile_in`] without a buffer to reuse.
pub fn quantile<T: Sample>(values: impl IntoIterator<Item = T>, p: T) -> Option<T> {
    quantile_in(values, p, &mut Vec::new())
}

/// The median of the finite `values`, the upper of the two middle ones for an even count (the
/// nearest-rank [`quantile`] at one half); `None` when no value is finite.
pub fn median<T: Sample>(values: impl IntoIterator<Item = T>) -> Option<T> {
    quantile(values, T::HALF)
}

/// The nearest-rank `p`-quantile of values already sorted in ascending order, all of them
/// (finite or not); `None` for none.
pub fn quantile_sorted<T: Sample>(sorted: &[T], p: T) -> Option<T> {
    if sorted.is_empty() {
        return None;
    }
    Some(sorted[T::nearest_rank(p, sorted.len())])
}

/// The `p`-quantile of the finite `values` at the rank at or below `p (n - 1)`: the element at
/// index `floor(p (n - 1))` of the sorted values; `None` when no value is finite.
pub fn quantile_below(values: impl IntoIterator<Item = f32>, p: f64) -> Option<f32> {
    let mut v: Vec<f32> = values.into_iter().filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    let k = (((v.len() - 1) as f64 * p) as usize).min(v.len() - 1);
    Some(*v.select_nth_unstable_by(k, f32::total_cmp).1)
}

/// The median of all `values` (finite or not), sorting them in place: the middle value of an
/// odd count, the mean of the two middle ones of an even count; `None` for none.
pub fn median_midpoint(values: &mut [f32]) -> Option<f32> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    values.sort_unstable_by(f32::total_cmp);
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_rounds_and_skips_non_finite_values() {
        let v = [
            3.0f32,
            f32::NAN,
            1.0,
            f32::INFINITY,
            2.0,
            4.0,
            f32::NEG_INFINITY,
        ];
        // Finite values 1, 2, 3, 4: ranks round(p * 3).
        assert_eq!(quantile(v, 0.0), Some(1.0));
        assert_eq!(quantile(v, 0.4), Some(2.0));
        assert_eq!(quantile(v, 0.5), Some(3.0));
        assert_eq!(quantile(v, 1.0), Some(4.0));
        assert_eq!(median(v), Some(3.0), "the upper middle value");
        assert_eq!(median([5.0f64, 1.0, 3.0]), Some(3.0));
        assert_eq!(quantile([f32::NAN], 0.5), None);
        assert_eq!(median(Vec::<f64>::new()), None);
    }

    #[test]
    fn the_buffer_is_reused_and_cleared() {
        let mut buf = vec![100.0f32; 8];
        assert_eq!(quantile_in([2.0, 1.0], 0.0, &mut buf), Some(1.0));
        assert_eq!(buf.len(), 2);
        assert_eq!(quantile_in([7.0], 1.0, &mut buf), Some(7.0));
    }

    #[test]
    fn rank_is_computed_in_the_values_precision() {
        // Each type rounds its own product, so that a shared quantile picks the element the
        // copies it replaced picked.
        let n = 1501;
        let f32_rank = (0.999f32 * (n - 1) as f32).round() as usize;
        let f64_rank = (0.999f64 * (n - 1) as f64).round() as usize;
        assert_eq!(f32::nearest_rank(0.999, n), f32_rank);
        assert_eq!(f64::nearest_rank(0.999, n), f64_rank);
        assert_eq!(
            f32::nearest_rank(2.0, n),
            n - 1,
            "clamped to the last index"
        );
    }

    #[test]
    fn sorted_below_and_midpoint_variants() {
        assert_eq!(quantile_sorted(&[1.0f64, 2.0, 3.0, 4.0], 0.5), Some(3.0));
        assert_eq!(quantile_sorted::<f64>(&[], 0.5), None);
        // floor(0.995 * 3) = 2, where the nearest rank is 3.
        let v = [4.0f32, 1.0, 3.0, 2.0, f32::INFINITY];
        assert_eq!(quantile_below(v, 0.995), Some(3.0));
        assert_eq!(quantile(v, 0.995), Some(4.0));
        assert_eq!(quantile_below([f32::NAN], 0.5), None);
        let mut even = [4.0f32, 1.0, 3.0, 2.0];
        assert_eq!(median_midpoint(&mut even), Some(2.5));
        assert_eq!(even, [1.0, 2.0, 3.0, 4.0], "sorted in place");
        assert_eq!(median_midpoint(&mut [5.0, 1.0, 3.0]), Some(3.0));
        assert_eq!(median_midpoint(&mut []), None);
    }
}
