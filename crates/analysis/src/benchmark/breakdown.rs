//! The errors of an estimate broken down by streak length and by distance, so that a reader
//! sees where a method fails (the breakdown by condition is by sample: see
//! [`streaks_dataset::meta::Condition`] and [`super::report::by_condition`]).
//!
//! - **Streak length**: the streak pixels on the road ([`Masks::streaks`] and [`Masks::road`])
//!   form streaks, the connected components of that mask (8-connected); a streak's length is
//!   its vertical extent, the rows it spans (`max y - min y + 1`), as a share of the image's
//!   height so that the bins mean the same at every resolution: [`STREAK_LENGTH_BINS`],
//!   short below 5 % of the height, medium 5-20 %, long 20 % and more (16 and 64 px at 320 px
//!   high, 24 and 96 px at 480, 40 and 160 px at 800). Each bin scores its streaks' pixels.
//! - **Distance**: the ground-truth depth (`depth0.pfm`, metres) in [`DISTANCE_BINS`] (0-10,
//!   10-20, 20-40, 40 m and more), each bin scoring the road surface (its `below_1px` the
//!   phantom-hole rate at that distance) and the pixels off the road and off the streaks
//!   (`off_road`, read for its bad-2). A sample without a depth has no distance breakdown
//!   (pair folders, KITTI, Middlebury).
//!
//! A bin without a pixel with ground truth is `None` (not available, never a zero); a whole
//! breakdown whose masks or depth the sample lacks is `None`. Every bin is scored by the one
//! scorer [`compare_disparity_where`] and pooled pixel-weighted with
//! [`DisparityErrors::pooled`], as the regions are.

use super::{Masks, BAD_THRESHOLD_PX};
use crate::sgm::{compare_disparity_where, DisparityErrors, SgmError};
use streaks_image::{ensure_same_size, GrayImage};

/// A bin of a breakdown: its name and the half-open range `[low, high)` of its values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bin {
    /// Its name in the report.
    pub name: &'static str,
    /// Lowest value in the bin.
    pub low: f64,
    /// The value the bin stops before (`inf` for the last).
    pub high: f64,
}

/// The streak-length bins, in shares of the image height.
pub const STREAK_LENGTH_BINS: [Bin; 3] = [
    Bin {
        name: "short",
        low: 0.0,
        high: 0.05,
    },
    Bin {
        name: "medium",
        low: 0.05,
        high: 0.2,
    },
    Bin {
        name: "long",
        low: 0.2,
        high: f64::INFINITY,
    },
];

/// The distance bins, in metres of ground-truth depth.
pub const DISTANCE_BINS: [Bin; 4] = [
    Bin {
        name: "0-10 m",
        low: 0.0,
        high: 10.0,
    },
    Bin {
        name: "10-20 m",
        low: 10.0,
        high: 20.0,
    },
    Bin {
        name: "20-40 m",
        low: 20.0,
        high: 40.0,
    },
    Bin {
        name: "40+ m",
        low: 40.0,
        high: f64::INFINITY,
    },
];

/// The index of the bin of `bins` (consecutive, each starting where the one before stops)
/// that holds `value`; `None` for a value below the first, not finite, or NaN.
pub fn bin_index(bins: &[Bin], value: f64) -> Option<usize> {
    if !value.is_finite() {
        return None;
    }
    bins.iter().position(|b| value >= b.low && value < b.high)
}

/// The vertical extent (rows spanned) of the streak each pixel belongs to, 0 off the streaks:
/// the streaks are the 8-connected components of the pixels in both `streaks` and `road`
/// (non-zero), which must have the same size.
pub fn streak_extents(streaks: &GrayImage, road: &GrayImage) -> Result<Vec<usize>, SgmError> {
    ensure_same_size(
        "the streak mask",
        streaks.size(),
        "the road mask",
        road.size(),
    )?;
    let (w, h) = (streaks.width, streaks.height);
    let mut extent = vec![0usize; w * h];
    for members in components8(w, h, |i| streaks.data[i] > 0.0 && road.data[i] > 0.0) {
        let (y0, y1) = members
            .iter()
            .fold((usize::MAX, 0), |(a, b), &i| (a.min(i / w), b.max(i / w)));
        for &i in &members {
            extent[i] = y1 - y0 + 1;
        }
    }
    Ok(extent)
}

/// The 8-connected components of the pixels of a `w` x `h` image that `on` accepts (by index
/// `y * w + x`), each as its pixels' indices, in the order of their first pixel.
pub fn components8(w: usize, h: usize, on: impl Fn(usize) -> bool) -> Vec<Vec<usize>> {
    let mut seen = vec![false; w * h];
    let mut stack = Vec::new();
    let mut out = Vec::new();
    for start in 0..w * h {
        if seen[start] || !on(start) {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let mut members = Vec::new();
        while let Some(i) = stack.pop() {
            members.push(i);
            let (x, y) = (i % w, i / w);
            for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    let j = ny * w + nx;
                    if !seen[j] && on(j) {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        out.push(members);
    }
    out
}

/// What a sample's breakdown needs besides the estimate, computed once per sample: each
/// pixel's streak-length bin and distance bin.
#[derive(Clone, Debug)]
pub struct SampleBins {
    /// Width and height.
    size: (usize, usize),
    /// Per pixel, the [`STREAK_LENGTH_BINS`] index of its streak on the road (`None` off
    /// them); `None` without a streak and a road mask.
    streak_length: Option<Vec<Option<usize>>>,
    /// Per pixel, the [`DISTANCE_BINS`] index of its depth; `None` without a depth.
    distance: Option<Vec<Option<usize>>>,
}

impl SampleBins {
    /// The bins of a sample with `masks` and ground-truth `depth` (metres, its size; `None`
    /// when the sample has none) whose ground truth has `size`.
    pub fn new(
        size: (usize, usize),
        masks: &Masks,
        depth: Option<&GrayImage>,
    ) -> Result<Self, SgmError> {
        let streak_length = match (masks.streaks, masks.road) {
            (Some(s), Some(r)) => {
                ensure_same_size("the streak mask", s.size(), "the ground truth", size)?;
                let height = size.1.max(1) as f64;
                Some(
                    streak_extents(s, r)?
                        .into_iter()
                        .map(|e| {
                            (e > 0)
                                .then(|| bin_index(&STREAK_LENGTH_BINS, e as f64 / height))
                                .flatten()
                        })
                        .collect(),
                )
            }
            _ => None,
        };
        let distance = match depth {
            Some(d) => {
                ensure_same_size("the depth", d.size(), "the ground truth", size)?;
                Some(
                    d.data
                        .iter()
                        .map(|&z| bin_index(&DISTANCE_BINS, f64::from(z)))
                        .collect(),
                )
            }
            None => None,
        };
        Ok(Self {
            size,
            streak_length,
            distance,
        })
    }
}

/// One bin's errors.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BinErrors {
    /// The bin's name ([`Bin::name`]).
    pub bin: String,
    /// Its errors; `None` when no pixel with ground truth falls in it.
    pub errors: Option<DisparityErrors>,
}

/// An estimate's errors by streak length and by distance (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Breakdown {
    /// The streak pixels on the road by their streak's length, [`STREAK_LENGTH_BINS`] in
    /// order (`None` without a streak and a road mask).
    pub streak_length: Option<Vec<BinErrors>>,
    /// The whole road surface by distance, [`DISTANCE_BINS`] in order; each bin's
    /// `below_1px` is its phantom-hole rate (`None` without a road mask or a depth).
    pub road_surface_by_distance: Option<Vec<BinErrors>>,
    /// The pixels neither streak nor road by distance (`None` without a streak and a road
    /// mask, or without a depth).
    pub off_road_by_distance: Option<Vec<BinErrors>>,
}

impl Breakdown {
    /// The breakdowns of several images together, pixel-weighted: each bin pooled over the
    /// images that have pixels in it ([`DisparityErrors::pooled`]), each breakdown over the
    /// images that have it.
    pub fn pooled(parts: &[&Breakdown]) -> Breakdown {
        let pool = |f: fn(&Breakdown) -> &Option<Vec<BinErrors>>| {
            let have: Vec<&Vec<BinErrors>> = parts.iter().filter_map(|p| f(p).as_ref()).collect();
            let first = have.first()?;
            Some(
                first
                    .iter()
                    .enumerate()
                    .map(|(k, b)| BinErrors {
                        bin: b.bin.clone(),
                        errors: DisparityErrors::pooled(
                            &have
                                .iter()
                                .filter_map(|v| v.get(k).and_then(|b| b.errors))
                                .collect::<Vec<_>>(),
                        ),
                    })
                    .collect(),
            )
        };
        Breakdown {
            streak_length: pool(|b| &b.streak_length),
            road_surface_by_distance: pool(|b| &b.road_surface_by_distance),
            off_road_by_distance: pool(|b| &b.off_road_by_distance),
        }
    }
}

/// Scores `estimate` against `truth` in the bins of `bins`, with the regions of `masks` (the
/// sample's, as [`SampleBins::new`] took them).
pub fn score_breakdown(
    estimate: &GrayImage,
    truth: &GrayImage,
    masks: &Masks,
    bins: &SampleBins,
) -> Result<Breakdown, SgmError> {
    ensure_same_size("the ground truth", truth.size(), "the bins", bins.size)?;
    let score = |select: &dyn Fn(usize) -> bool| -> Result<Option<DisparityErrors>, SgmError> {
        let e = compare_disparity_where(estimate, truth, BAD_THRESHOLD_PX, select)?;
        Ok((e.truth_pixels > 0).then_some(e))
    };
    let by = |table: &[Bin],
              index: &[Option<usize>],
              within: &dyn Fn(usize) -> bool|
     -> Result<Vec<BinErrors>, SgmError> {
        table
            .iter()
            .enumerate()
            .map(|(k, b)| {
                Ok(BinErrors {
                    bin: b.name.to_string(),
                    errors: score(&|i| index[i] == Some(k) && within(i))?,
                })
            })
            .collect()
    };
    let on = |m: &GrayImage, i: usize| m.data[i] > 0.0;
    let streak_length = bins
        .streak_length
        .as_ref()
        .map(|index| by(&STREAK_LENGTH_BINS, index, &|_| true))
        .transpose()?;
    let (mut road_surface_by_distance, mut off_road_by_distance) = (None, None);
    if let Some(index) = &bins.distance {
        if let Some(r) = masks.road {
            road_surface_by_distance = Some(by(&DISTANCE_BINS, index, &|i| on(r, i))?);
            if let Some(s) = masks.streaks {
                off_road_by_distance =
                    Some(by(&DISTANCE_BINS, index, &|i| !on(r, i) && !on(s, i))?);
            }
        }
    }
    Ok(Breakdown {
        streak_length,
        road_surface_by_distance,
        off_road_by_distance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, v: &[f32]) -> GrayImage {
        GrayImage::from_vec(w, h, v.to_vec()).unwrap()
    }

    #[test]
    fn bins_are_half_open_and_skip_what_is_not_finite() {
        assert_eq!(bin_index(&DISTANCE_BINS, 0.0), Some(0));
        assert_eq!(bin_index(&DISTANCE_BINS, 9.99), Some(0));
        assert_eq!(bin_index(&DISTANCE_BINS, 10.0), Some(1));
        assert_eq!(bin_index(&DISTANCE_BINS, 39.9), Some(2));
        assert_eq!(bin_index(&DISTANCE_BINS, 40.0), Some(3));
        assert_eq!(bin_index(&DISTANCE_BINS, 1e6), Some(3));
        assert_eq!(bin_index(&DISTANCE_BINS, -1.0), None);
        assert_eq!(bin_index(&DISTANCE_BINS, f64::INFINITY), None);
        assert_eq!(bin_index(&DISTANCE_BINS, f64::NAN), None);
        // 100 px high: short below 5 rows, medium 5 to 19, long from 20.
        assert_eq!(bin_index(&STREAK_LENGTH_BINS, 4.0 / 100.0), Some(0));
        assert_eq!(bin_index(&STREAK_LENGTH_BINS, 5.0 / 100.0), Some(1));
        assert_eq!(bin_index(&STREAK_LENGTH_BINS, 19.0 / 100.0), Some(1));
        assert_eq!(bin_index(&STREAK_LENGTH_BINS, 20.0 / 100.0), Some(2));
    }

    #[test]
    fn streaks_are_8_connected_components_on_the_road_measured_by_rows() {
        // 5x6. Streak A: a diagonal (8-connected) from (0,0) to (2,2) plus (2,3): rows 0-3,
        // extent 4. Streak B: (4,0) alone, extent 1. Streak C: (4,3) to (4,5) but (4,4) is
        // off the road, so two streaks (4,3) and (4,5), extent 1 each. (0,5) is a streak pixel
        // off the road: in no streak.
        #[rustfmt::skip]
        let streaks = image(5, 6, &[
            1., 0., 0., 0., 1.,
            0., 1., 0., 0., 0.,
            0., 0., 1., 0., 0.,
            0., 0., 1., 0., 1.,
            0., 0., 0., 0., 1.,
            1., 0., 0., 0., 1.,
        ]);
        let mut road = image(5, 6, &[1.0; 30]);
        road.set(4, 4, 0.0);
        road.set(0, 5, 0.0);
        let e = streak_extents(&streaks, &road).unwrap();
        #[rustfmt::skip]
        let expected = [
            4, 0, 0, 0, 1,
            0, 4, 0, 0, 0,
            0, 0, 4, 0, 0,
            0, 0, 4, 0, 1,
            0, 0, 0, 0, 0,
            0, 0, 0, 0, 1,
        ];
        assert_eq!(e, expected);
        // Without the road's gap, the right-hand column is one streak of rows 3-5.
        let full = image(5, 6, &[1.0; 30]);
        let e = streak_extents(&streaks, &full).unwrap();
        assert_eq!((e[3 * 5 + 4], e[5 * 5 + 4], e[5 * 5]), (3, 3, 1));
        assert!(streak_extents(&streaks, &image(5, 5, &[1.0; 25])).is_err());
    }

    #[test]
    fn breakdown_scores_each_bin_and_leaves_empty_ones_unavailable() {
        // 3 columns x 40 rows, every pixel 10 px of disparity. Column 0: one streak on the
        // road spanning all 40 rows (100 % of the height: long), at 5 m. Column 1: off the
        // road at 5 m. Column 2: rows 0-19 off the road at 5 m, rows 20-39 road at 25 m, with
        // one short streak pixel at row 30 (1 row, 2.5 % of the height).
        let (w, h) = (3, 40);
        let mut streaks = GrayImage::new(w, h, 0.0).unwrap();
        let mut road = GrayImage::new(w, h, 0.0).unwrap();
        let mut depth = GrayImage::new(w, h, 5.0).unwrap();
        for y in 0..h {
            streaks.set(0, y, 1.0);
            road.set(0, y, 1.0);
            if y >= 20 {
                road.set(2, y, 1.0);
                depth.set(2, y, 25.0);
            }
        }
        streaks.set(2, 30, 1.0);
        let truth = GrayImage::new(w, h, 10.0).unwrap();
        // The estimate: exact but on column 2's road, 3 px too far (a phantom hole).
        let mut est = truth.clone();
        for y in 20..h {
            est.set(2, y, 7.0);
        }
        let masks = Masks {
            streaks: Some(&streaks),
            road: Some(&road),
            non_occluded: None,
        };
        let bins = SampleBins::new((w, h), &masks, Some(&depth)).unwrap();
        let b = score_breakdown(&est, &truth, &masks, &bins).unwrap();
        let sl = b.streak_length.as_ref().unwrap();
        assert_eq!(sl.len(), 3);
        assert_eq!(sl[0].bin, "short");
        let short = sl[0].errors.unwrap();
        assert_eq!(
            (short.truth_pixels, short.mean_abs, short.below_1px),
            (1, 3.0, 1.0)
        );
        assert_eq!(sl[1].errors, None);
        let long = sl[2].errors.unwrap();
        assert_eq!((long.truth_pixels, long.mean_abs), (40, 0.0));
        // Road by distance: column 0 at 5 m (40 px, exact), column 2's rows 20-39 at 25 m.
        let road_d = b.road_surface_by_distance.as_ref().unwrap();
        let near = road_d[0].errors.unwrap();
        assert_eq!((near.truth_pixels, near.below_1px), (40, 0.0));
        assert_eq!(road_d[1].errors, None);
        let mid = road_d[2].errors.unwrap();
        assert_eq!((mid.truth_pixels, mid.below_1px, mid.bad_2), (20, 1.0, 1.0));
        assert_eq!(road_d[3].errors, None);
        // Off road: column 1 and column 2's rows 0-19, at 5 m, exact.
        let off = b.off_road_by_distance.as_ref().unwrap();
        let near = off[0].errors.unwrap();
        assert_eq!((near.truth_pixels, near.bad_2), (60, 0.0));
        assert!(off[1..].iter().all(|b| b.errors.is_none()));
        // Pooled with itself: counts double, shares stay; with a sample without depth, the
        // distance bins are that of the one with a depth.
        let no_depth = score_breakdown(
            &est,
            &truth,
            &masks,
            &SampleBins::new((w, h), &masks, None).unwrap(),
        )
        .unwrap();
        assert_eq!(no_depth.road_surface_by_distance, None);
        let pooled = Breakdown::pooled(&[&b, &b, &no_depth]);
        let long = pooled.streak_length.as_ref().unwrap()[2].errors.unwrap();
        assert_eq!(long.truth_pixels, 120);
        let mid = pooled.road_surface_by_distance.as_ref().unwrap()[2]
            .errors
            .unwrap();
        assert_eq!((mid.truth_pixels, mid.below_1px), (40, 1.0));
        assert_eq!(pooled.streak_length.as_ref().unwrap()[1].errors, None);
        // No masks: no breakdown at all.
        let none = Masks::default();
        let b = score_breakdown(
            &est,
            &truth,
            &none,
            &SampleBins::new((w, h), &none, None).unwrap(),
        )
        .unwrap();
        assert_eq!(b, Breakdown::default());
        assert_eq!(Breakdown::pooled(&[]), Breakdown::default());
    }
}
