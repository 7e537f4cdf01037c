//! Scoring stereo methods against ground truth by region, for `streaks benchmark`.
//!
//! - this file: the regions, [`score_regions`], the LK method's map, error maps;
//! - [`breakdown`]: the errors by streak length and by distance;
//! - [`method`]: the built-in methods by name ([`method::BuiltIn`]);
//! - [`report`]: a method's figures per sample and pooled, its failures.
//!
//! # Regions
//!
//! Every pixel with a finite ground truth is in `all` and in exactly one of
//! - `streak`: the renderer's streak mask (specular streaks, on the road or not);
//! - `road`: the road surface (the renderer's road mask), off the streaks;
//! - `off_road`: everything else.
//!
//! `road_surface` is the whole road mask, streaks included: its
//! [`DisparityErrors::below_1px`] is the **phantom-hole rate**, the share of the road that an
//! estimate puts more than 1 px beneath the road. `non_occluded` is the pixels the right view
//! also sees (KITTI's `disp_noc_0`, Middlebury's `mask0nocc.png`).
//!
//! A region needs its masks ([`Masks`]): without a streak mask (KITTI or Middlebury data)
//! `streak`, `non_streak`, `road` and `off_road` are not available (`None`, never a zero);
//! without a road mask `road`, `off_road` and `road_surface` are not; without an occlusion
//! mask `non_occluded` is not. `all` is always scored.
//!
//! The errors of each region are [`DisparityErrors`] (EPE, bad-1/2/3, KITTI D1, valid share,
//! below-1-px share), computed by the one scorer [`compare_disparity_where`];
//! [`RegionErrors::pooled`] combines samples pixel-weighted (every pixel counts once, the
//! KITTI convention).
//!
//! # Breakdown
//!
//! Where a method fails is shown by three breakdowns, each scored by the same scorer and
//! pooled the same way: by the sample's **condition** (`dry`, `rain`, `fog`, `noise`, read
//! from its `meta.json`: [`streaks_dataset::meta::Condition`]; [`report::by_condition`]
//! pools the samples of each), by **streak length** and by **distance**
//! ([`breakdown`]).
//!
//! # The Lucas-Kanade method where it applies
//!
//! The paper's per-row LK ([`crate::lk`]) measures one disparity per row of a streak, at its
//! centre. [`lk_streak_disparity`] runs it as `streaks analyze` does (streaks detected in the
//! left image as it is, LK on the pair with fireflies removed and the range log-compressed,
//! 21 x 5 windows) and writes each row's estimate on the row's run of detected streak pixels
//! through the centre; every other pixel has no value. Its valid share is therefore small and
//! its scores speak only for the detected streak rows.

pub mod breakdown;
pub mod method;
pub mod report;

use crate::detect::{detect_streaks, DetectError, DetectParams};
use crate::lk::{lk_rows, prepare_pair, LkError, LkParams};
use crate::sgm::{check_against_truth, compare_disparity_where, DisparityErrors, SgmError};
use streaks_image::{ensure_same_size, GrayImage, ImageError};

/// The threshold of [`DisparityErrors::bad`] in the benchmark (bad-2.0, as `streaks disparity`).
pub const BAD_THRESHOLD_PX: f32 = 2.0;

/// The errors of one estimate by region (see the module documentation); a region whose
/// masks the sample lacks is `None`: not available, never a zero.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RegionErrors {
    /// Every pixel with a ground truth.
    pub all: DisparityErrors,
    /// The renderer's streak pixels (`None` without a streak mask).
    pub streak: Option<DisparityErrors>,
    /// Every pixel off the streaks (`None` without a streak mask).
    pub non_streak: Option<DisparityErrors>,
    /// Road-surface pixels off the streaks (`None` without a road and a streak mask).
    pub road: Option<DisparityErrors>,
    /// Pixels neither streak nor road (`None` without a road and a streak mask).
    pub off_road: Option<DisparityErrors>,
    /// The whole road surface, streaks included: its `below_1px` is the phantom-hole rate
    /// (`None` without a road mask).
    pub road_surface: Option<DisparityErrors>,
    /// The pixels the right view also sees (`None` without an occlusion mask).
    #[serde(default)]
    pub non_occluded: Option<DisparityErrors>,
}

impl RegionErrors {
    /// The phantom-hole rate: the share of road-surface pixels estimated more than 1 px below
    /// the truth (`None` without a road mask).
    pub fn phantom_hole_rate(&self) -> Option<f64> {
        self.road_surface.map(|r| r.below_1px)
    }

    /// The errors of several images together, pixel-weighted. Each region but `all` is pooled
    /// over the images that have it (`None` if none has). `None` for an empty list.
    pub fn pooled(parts: &[RegionErrors]) -> Option<RegionErrors> {
        let pool_opt = |f: fn(&RegionErrors) -> Option<DisparityErrors>| {
            DisparityErrors::pooled(&parts.iter().filter_map(f).collect::<Vec<_>>())
        };
        Some(RegionErrors {
            all: DisparityErrors::pooled(&parts.iter().map(|r| r.all).collect::<Vec<_>>())?,
            streak: pool_opt(|r| r.streak),
            non_streak: pool_opt(|r| r.non_streak),
            road: pool_opt(|r| r.road),
            off_road: pool_opt(|r| r.off_road),
            road_surface: pool_opt(|r| r.road_surface),
            non_occluded: pool_opt(|r| r.non_occluded),
        })
    }
}

/// The masks of one sample that define its regions, each of the ground truth's size (non-zero
/// = in the mask); a mask the sample lacks is `None`, and so are the regions that need it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Masks<'a> {
    /// The renderer's streak mask.
    pub streaks: Option<&'a GrayImage>,
    /// The road-surface mask.
    pub road: Option<&'a GrayImage>,
    /// The pixels the right view also sees.
    pub non_occluded: Option<&'a GrayImage>,
}

/// Scores `estimate` against `truth` by region, with the regions `masks` define (see the
/// module documentation).
pub fn score_regions(
    estimate: &GrayImage,
    truth: &GrayImage,
    masks: &Masks,
) -> Result<RegionErrors, SgmError> {
    for mask in [masks.streaks, masks.road, masks.non_occluded]
        .into_iter()
        .flatten()
    {
        ensure_same_size("the mask", mask.size(), "the ground truth", truth.size())?;
    }
    let t = BAD_THRESHOLD_PX;
    let score =
        |select: &dyn Fn(usize) -> bool| compare_disparity_where(estimate, truth, t, select);
    let within = |mask: Option<&GrayImage>, select: &dyn Fn(&GrayImage, usize) -> bool| {
        mask.map(|m| score(&|i| select(m, i))).transpose()
    };
    let on = |m: &GrayImage, i: usize| m.data[i] > 0.0;
    let (mut road, mut off_road) = (None, None);
    if let (Some(s), Some(r)) = (masks.streaks, masks.road) {
        road = Some(score(&|i| on(r, i) && !on(s, i))?);
        off_road = Some(score(&|i| !on(r, i) && !on(s, i))?);
    }
    Ok(RegionErrors {
        all: score(&|_| true)?,
        streak: within(masks.streaks, &on)?,
        non_streak: within(masks.streaks, &|m, i| !on(m, i))?,
        road,
        off_road,
        road_surface: within(masks.road, &on)?,
        non_occluded: within(masks.non_occluded, &on)?,
    })
}

/// What went wrong in [`lk_streak_disparity`].
#[derive(Debug, thiserror::Error)]
pub enum StreakLkError {
    /// The streak detector failed (the cause is the source, so a chain prints it once).
    #[error("streak detection")]
    Detect(#[from] DetectError),
    /// The estimator failed (the cause is the source).
    #[error("Lucas-Kanade")]
    Lk(#[from] LkError),
    /// An image could not be made.
    #[error(transparent)]
    Image(#[from] ImageError),
}

/// The LK parameters of [`lk_streak_disparity`]: `streaks analyze`'s 21 x 5 windows, searching
/// the disparities `streaks disparity` searches (0 to 63).
pub fn streak_lk_params() -> LkParams {
    LkParams {
        window: 21,
        rows: 5,
        max_disp: 63,
        ..LkParams::default()
    }
}

/// The per-row Lucas-Kanade disparity of the streaks detected in `left`, as a disparity map of
/// the left view: each row's estimate on the row's run of detected pixels through the streak's
/// centre, `inf` everywhere else (see the module documentation).
pub fn lk_streak_disparity(
    left: &GrayImage,
    right: &GrayImage,
    lk: &LkParams,
    detect: &DetectParams,
) -> Result<GrayImage, StreakLkError> {
    let found = detect_streaks(left, detect)?;
    let (pl, pr) = prepare_pair(left, right);
    let (w, h) = (left.width, left.height);
    let mut out = GrayImage::new(w, h, f32::INFINITY)?;
    let mask = &found.mask;
    for streak in &found.streaks {
        let centres: Vec<(usize, f32)> = streak
            .centres
            .iter()
            .copied()
            .filter(|&(y, x)| y < h && x >= 0.0 && x < w as f32)
            .collect();
        for r in lk_rows(&pl, &pr, &centres, lk)? {
            if !r.disparity.is_finite() {
                continue;
            }
            let (y, xc) = (r.row, (r.x.floor() as usize).min(w - 1));
            let on = |x: usize| mask.data[y * w + x] > 0.0;
            let (mut x0, mut x1) = (xc, xc);
            while x0 > 0 && on(x0 - 1) && on(xc) {
                x0 -= 1;
            }
            while x1 + 1 < w && on(x1 + 1) && on(xc) {
                x1 += 1;
            }
            for x in x0..=x1 {
                out.data[y * w + x] = r.disparity;
            }
        }
    }
    Ok(out)
}

/// Largest signed error shown by [`error_map`] (its colours saturate beyond), pixels.
pub const ERROR_MAP_RANGE_PX: f32 = 4.0;

/// The colour of [`error_map`] for pixels without ground truth (sky).
pub const NO_TRUTH_RGB: [u8; 3] = [34, 38, 46];

/// The colour of [`error_map`] for pixels with ground truth but no estimate.
pub const NO_ESTIMATE_RGB: [u8; 3] = [150, 150, 150];

/// The diverging colour of a signed error `e` (estimate minus truth, pixels): blue below the
/// truth (farther: a phantom hole on the road), white at 0, red above (nearer), saturating at
/// [`ERROR_MAP_RANGE_PX`] (ColorBrewer's RdBu).
pub fn error_colour(e: f32) -> [u8; 3] {
    // RdBu, from -range (blue) to +range (red).
    const STOPS: [[f32; 3]; 7] = [
        [33.0, 102.0, 172.0],
        [103.0, 169.0, 207.0],
        [209.0, 229.0, 240.0],
        [247.0, 247.0, 247.0],
        [253.0, 219.0, 199.0],
        [239.0, 138.0, 98.0],
        [178.0, 24.0, 43.0],
    ];
    let t = ((e / ERROR_MAP_RANGE_PX).clamp(-1.0, 1.0) + 1.0) * 0.5 * (STOPS.len() - 1) as f32;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f32;
    let c = |k: usize| (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    [c(0), c(1), c(2)]
}

/// The signed error map of `estimate` against `truth` (same size): [`error_colour`] of
/// estimate minus truth, [`NO_ESTIMATE_RGB`] where only the truth has a value,
/// [`NO_TRUTH_RGB`] where the truth has none.
pub fn error_map(estimate: &GrayImage, truth: &GrayImage) -> Result<image::RgbImage, SgmError> {
    check_against_truth(estimate, truth)?;
    Ok(image::RgbImage::from_fn(
        truth.width as u32,
        truth.height as u32,
        |x, y| {
            let (e, t) = (
                estimate.get(x as usize, y as usize),
                truth.get(x as usize, y as usize),
            );
            image::Rgb(if !t.is_finite() {
                NO_TRUTH_RGB
            } else if !e.is_finite() {
                NO_ESTIMATE_RGB
            } else {
                error_colour(e - t)
            })
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repair::{EstimateError, RepairError};
    use std::error::Error;

    /// `err` and its causes as `{:#}` of an `anyhow::Error` prints them.
    fn chain<'a>(err: &'a (dyn Error + 'static)) -> String {
        let texts: Vec<String> = std::iter::successors(Some(err), |&e: &&'a dyn Error| e.source())
            .map(|e| e.to_string())
            .collect();
        texts.join(": ")
    }

    #[test]
    fn a_printed_chain_names_each_cause_once() {
        let detect = || DetectError::Param {
            name: "gap",
            reason: "must be positive",
        };
        let lk = || LkError::Param {
            name: "window",
            reason: "must be odd".into(),
        };
        let cases: [(Box<dyn Error>, String, &str); 3] = [
            (
                Box::new(StreakLkError::from(detect())),
                detect().to_string(),
                "streak detection: invalid streak detection parameter gap",
            ),
            (
                Box::new(StreakLkError::from(lk())),
                lk().to_string(),
                "Lucas-Kanade: invalid Lucas-Kanade parameter window",
            ),
            (
                Box::new(EstimateError::from(RepairError::Format("no trees".into()))),
                "no trees".to_string(),
                "streak-robust disparity: repair model: no trees",
            ),
        ];
        for (err, cause, start) in cases {
            let text = chain(&*err);
            assert_eq!(text.matches(&cause).count(), 1, "{text}");
            assert!(text.starts_with(start), "{text}");
        }
    }

    #[test]
    fn regions_partition_the_pixels_and_find_phantom_holes() {
        // 4x2: row 0 road (the first two pixels streaks), row 1 off road; the last pixel sky.
        let truth = GrayImage::from_vec(
            4,
            2,
            vec![10.0, 10.0, 10.0, 10.0, 5.0, 5.0, 5.0, f32::INFINITY],
        )
        .unwrap();
        let est = GrayImage::from_vec(
            4,
            2,
            vec![3.0, 10.0, 8.5, 10.0, 5.0, 9.0, f32::INFINITY, 1.0],
        )
        .unwrap();
        let streaks =
            GrayImage::from_vec(4, 2, vec![1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        let road = GrayImage::from_vec(4, 2, vec![1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        let masks = Masks {
            streaks: Some(&streaks),
            road: Some(&road),
            non_occluded: None,
        };
        let r = score_regions(&est, &truth, &masks).unwrap();
        assert_eq!(r.all.truth_pixels, 7);
        let (road_e, off) = (r.road.unwrap(), r.off_road.unwrap());
        assert_eq!(
            r.streak.unwrap().truth_pixels + road_e.truth_pixels + off.truth_pixels,
            7
        );
        assert_eq!(r.streak.unwrap().mean_abs, 3.5);
        // Road pixels 3 and 8.5 are below 10 by more than 1 px: 2 of 4.
        assert_eq!(r.phantom_hole_rate(), Some(0.5));
        assert_eq!(off.density, 2.0 / 3.0);
        assert_eq!(off.bad_3, 0.5);
        let pooled = RegionErrors::pooled(&[r, r]).unwrap();
        assert_eq!(pooled.all.truth_pixels, 14);
        assert_eq!(pooled.phantom_hole_rate(), Some(0.5));
        let streaks_only = Masks {
            road: None,
            ..masks
        };
        let no_road = score_regions(&est, &truth, &streaks_only).unwrap();
        assert!(no_road.road.is_none() && no_road.phantom_hole_rate().is_none());
        assert_eq!(no_road.streak, r.streak);
        // A pooled list keeps the road of the images that have one.
        let mixed = RegionErrors::pooled(&[r, no_road]).unwrap();
        assert_eq!(mixed.road_surface.unwrap().truth_pixels, 4);
        let small = GrayImage::new(3, 2, 0.0).unwrap();
        let bad = Masks {
            non_occluded: Some(&small),
            ..Masks::default()
        };
        assert!(score_regions(&est, &truth, &bad).is_err());
    }

    #[test]
    fn missing_masks_leave_their_regions_unavailable() {
        // 3x1: the last pixel occluded; no streak or road mask (KITTI, Middlebury).
        let truth = GrayImage::from_vec(3, 1, vec![10.0, 20.0, 30.0]).unwrap();
        let est = GrayImage::from_vec(3, 1, vec![10.5, 17.0, f32::INFINITY]).unwrap();
        let noc = GrayImage::from_vec(3, 1, vec![1.0, 1.0, 0.0]).unwrap();
        let masks = Masks {
            non_occluded: Some(&noc),
            ..Masks::default()
        };
        let r = score_regions(&est, &truth, &masks).unwrap();
        assert_eq!(
            (r.streak, r.non_streak, r.road, r.off_road),
            (None, None, None, None)
        );
        assert_eq!(r.phantom_hole_rate(), None);
        assert_eq!(r.all.mean_abs, 1.75);
        assert_eq!(r.all.density, 2.0 / 3.0);
        let n = r.non_occluded.unwrap();
        assert_eq!((n.truth_pixels, n.valid_pixels, n.mean_abs), (2, 2, 1.75));
        assert_eq!((n.bad_1, n.bad_2, n.bad_3, n.d1), (0.5, 0.5, 0.0, 0.0));
        // Pooled with a sample that has a streak mask: the streak region is that sample's.
        let streaks = GrayImage::from_vec(3, 1, vec![1.0, 0.0, 0.0]).unwrap();
        let with = score_regions(
            &est,
            &truth,
            &Masks {
                streaks: Some(&streaks),
                ..Masks::default()
            },
        )
        .unwrap();
        let pooled = RegionErrors::pooled(&[r, with]).unwrap();
        assert_eq!(pooled.streak, with.streak);
        assert_eq!(pooled.non_occluded, r.non_occluded);
        assert_eq!(pooled.all.truth_pixels, 6);
    }

    #[test]
    fn error_map_colours_sign_and_missing_values() {
        assert_eq!(error_colour(0.0), [247, 247, 247]);
        assert_eq!(error_colour(-100.0), [33, 102, 172]);
        assert_eq!(error_colour(ERROR_MAP_RANGE_PX), [178, 24, 43]);
        let truth = GrayImage::from_vec(3, 1, vec![5.0, 5.0, f32::INFINITY]).unwrap();
        let est = GrayImage::from_vec(3, 1, vec![1.0, f32::INFINITY, 2.0]).unwrap();
        let map = error_map(&est, &truth).unwrap();
        assert_eq!(map.get_pixel(0, 0).0, error_colour(-4.0));
        assert_eq!(map.get_pixel(1, 0).0, NO_ESTIMATE_RGB);
        assert_eq!(map.get_pixel(2, 0).0, NO_TRUTH_RGB);
    }

    #[test]
    fn lk_fills_only_detected_streak_rows() {
        // A dim textured pair with one bright vertical streak below the horizon, 5 px apart.
        let (w, h) = (96, 64);
        let tex = crate::synth::Texture::new(5);
        let mut left = GrayImage::new(w, h, 0.0).unwrap();
        let mut right = left.clone();
        for y in 0..h {
            for x in 0..w {
                left.set(x, y, 0.03 + 0.02 * tex.at(x as f32, y as f32));
                right.set(x, y, 0.03 + 0.02 * tex.at(x as f32 + 5.0, y as f32));
            }
        }
        for y in 38..h {
            for dx in 0..3 {
                let v = 0.9 - 0.05 * dx as f32;
                left.set(50 + dx, y, v);
                right.set(45 + dx, y, v);
            }
        }
        let d = lk_streak_disparity(&left, &right, &streak_lk_params(), &DetectParams::default())
            .unwrap();
        let found = detect_streaks(&left, &DetectParams::default()).unwrap();
        assert!(!found.streaks.is_empty());
        let centres: Vec<usize> = found
            .streaks
            .iter()
            .flat_map(|s| s.centres.iter().map(|&(y, x)| y * w + x.floor() as usize))
            .collect();
        let mut values = Vec::new();
        for (i, &v) in d.data.iter().enumerate() {
            if v.is_finite() {
                assert!(found.mask.data[i] > 0.0 || centres.contains(&i), "{i}");
                values.push(v);
            }
        }
        assert!(values.len() >= 20, "{}", values.len());
        values.sort_by(f32::total_cmp);
        let median = values[values.len() / 2];
        assert!((median - 5.0).abs() < 0.3, "{median}");
        // Nothing above the streak's first row.
        assert!(d.data[..38 * w].iter().all(|v| v.is_infinite()));
    }
}
