//! Scoring stereo methods against ground truth by region, for `streaks benchmark`.
//!
//! - this file: the regions, [`score_regions`], the LK method's map, error maps;
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
//! estimate puts more than 1 px beneath the road. Without a road mask only `all` and `streak`
//! (and `non_streak`, the rest) are scored.
//!
//! The errors of each region are [`DisparityErrors`] (EPE, bad-1/2/3, KITTI D1, valid share,
//! below-1-px share), computed by the one scorer [`compare_disparity_where`];
//! [`RegionErrors::pooled`] combines samples pixel-weighted (every pixel counts once, the
//! KITTI convention).
//!
//! # The Lucas-Kanade method where it applies
//!
//! The paper's per-row LK ([`crate::lk`]) measures one disparity per row of a streak, at its
//! centre. [`lk_streak_disparity`] runs it as `streaks analyze` does (streaks detected in the
//! left image as it is, LK on the pair with fireflies removed and the range log-compressed,
//! 21 x 5 windows) and writes each row's estimate on the row's run of detected streak pixels
//! through the centre; every other pixel has no value. Its valid share is therefore small and
//! its scores speak only for the detected streak rows.

pub mod method;
pub mod report;

use crate::detect::{detect_streaks, DetectError, DetectParams};
use crate::lk::{lk_rows, prepare_pair, LkError, LkParams};
use crate::sgm::{check_against_truth, compare_disparity_where, DisparityErrors, SgmError};
use streaks_image::{ensure_same_size, GrayImage, ImageError};

/// The threshold of [`DisparityErrors::bad`] in the benchmark (bad-2.0, as `streaks disparity`).
pub const BAD_THRESHOLD_PX: f32 = 2.0;

/// The errors of one estimate by region (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RegionErrors {
    /// Every pixel with a ground truth.
    pub all: DisparityErrors,
    /// The renderer's streak pixels.
    pub streak: DisparityErrors,
    /// Every pixel off the streaks.
    pub non_streak: DisparityErrors,
    /// Road-surface pixels off the streaks (`None` without a road mask).
    pub road: Option<DisparityErrors>,
    /// Pixels neither streak nor road (`None` without a road mask).
    pub off_road: Option<DisparityErrors>,
    /// The whole road surface, streaks included: its `below_1px` is the phantom-hole rate
    /// (`None` without a road mask).
    pub road_surface: Option<DisparityErrors>,
}

impl RegionErrors {
    /// The phantom-hole rate: the share of road-surface pixels estimated more than 1 px below
    /// the truth (`None` without a road mask).
    pub fn phantom_hole_rate(&self) -> Option<f64> {
        self.road_surface.map(|r| r.below_1px)
    }

    /// The errors of several images together, pixel-weighted. The road regions are pooled
    /// over the images that have a road mask (`None` if none has). `None` for an empty list.
    pub fn pooled(parts: &[RegionErrors]) -> Option<RegionErrors> {
        let pool = |f: fn(&RegionErrors) -> DisparityErrors| {
            DisparityErrors::pooled(&parts.iter().map(f).collect::<Vec<_>>())
        };
        let pool_opt = |f: fn(&RegionErrors) -> Option<DisparityErrors>| {
            DisparityErrors::pooled(&parts.iter().filter_map(f).collect::<Vec<_>>())
        };
        Some(RegionErrors {
            all: pool(|r| r.all)?,
            streak: pool(|r| r.streak)?,
            non_streak: pool(|r| r.non_streak)?,
            road: pool_opt(|r| r.road),
            off_road: pool_opt(|r| r.off_road),
            road_surface: pool_opt(|r| r.road_surface),
        })
    }
}

/// Scores `estimate` against `truth` by region: `streaks` is the streak mask and `road` the
/// road mask (non-zero = in the mask), both of the truth's size.
pub fn score_regions(
    estimate: &GrayImage,
    truth: &GrayImage,
    streaks: &GrayImage,
    road: Option<&GrayImage>,
) -> Result<RegionErrors, SgmError> {
    for mask in std::iter::once(streaks).chain(road) {
        ensure_same_size("the mask", mask.size(), "the ground truth", truth.size())?;
    }
    let t = BAD_THRESHOLD_PX;
    let streak = |i: usize| streaks.data[i] > 0.0;
    let score =
        |select: &dyn Fn(usize) -> bool| compare_disparity_where(estimate, truth, t, select);
    let (road_errors, off_road, road_surface) = match road {
        None => (None, None, None),
        Some(road) => {
            let on = |i: usize| road.data[i] > 0.0;
            (
                Some(score(&|i| on(i) && !streak(i))?),
                Some(score(&|i| !on(i) && !streak(i))?),
                Some(score(&on)?),
            )
        }
    };
    Ok(RegionErrors {
        all: score(&|_| true)?,
        streak: score(&streak)?,
        non_streak: score(&|i| !streak(i))?,
        road: road_errors,
        off_road,
        road_surface,
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
                Box::new(EstimateError::from(RepairError::from(detect()))),
                detect().to_string(),
                "streak-robust disparity: streak detection: invalid",
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
        let r = score_regions(&est, &truth, &streaks, Some(&road)).unwrap();
        assert_eq!(r.all.truth_pixels, 7);
        let (road_e, off) = (r.road.unwrap(), r.off_road.unwrap());
        assert_eq!(
            r.streak.truth_pixels + road_e.truth_pixels + off.truth_pixels,
            7
        );
        assert_eq!(r.streak.mean_abs, 3.5);
        // Road pixels 3 and 8.5 are below 10 by more than 1 px: 2 of 4.
        assert_eq!(r.phantom_hole_rate(), Some(0.5));
        assert_eq!(off.density, 2.0 / 3.0);
        assert_eq!(off.bad_3, 0.5);
        let pooled = RegionErrors::pooled(&[r, r]).unwrap();
        assert_eq!(pooled.all.truth_pixels, 14);
        assert_eq!(pooled.phantom_hole_rate(), Some(0.5));
        let no_road = score_regions(&est, &truth, &streaks, None).unwrap();
        assert!(no_road.road.is_none() && no_road.phantom_hole_rate().is_none());
        // A pooled list keeps the road of the images that have one.
        let mixed = RegionErrors::pooled(&[r, no_road]).unwrap();
        assert_eq!(mixed.road_surface.unwrap().truth_pixels, 4);
        let small = GrayImage::new(3, 2, 0.0).unwrap();
        assert!(score_regions(&est, &truth, &small, None).is_err());
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
