//! Streak-robust stereo: the road plane from a pair's own disparities, and the masking or
//! repair of the pixels a streak or a mirror reflection fools.
//!
//! # Why
//!
//! A wet road's reflections (streaks of lamps and headlights, mirror images of cars and
//! facades) are seen at the disparity of the reflected object's virtual image, which lies
//! *beneath* the road: stereo then reports holes in the road (phantom holes). Nothing opaque
//! can be seen beneath the road surface, so an estimate below the road plane is a reflection
//! or a mismatch, never a measurement of a real surface.
//!
//! # The road plane ([`fit_road_plane`])
//!
//! For a roll-free rectified rig over a planar road every image row `y` below the horizon
//! sees the road at one disparity, linear in the row: `d = a (y - y_h)`, with
//! `a = b / h` (baseline over camera height) and `y_h` the horizon (the v-disparity line of
//! Labayrade et al. 2002). Walls and cars are not on that line (a facade along the street has
//! a disparity that changes along the row, an object standing on the road is nearer than
//! the road behind it and has a larger disparity). The fit is a Hough vote over the
//! valid, unmasked disparities of the lower part of the image: for each slope `a` on a
//! log-spaced grid (`b / h` from 0.005 to 2) the offsets `d - a y` are histogrammed at
//! 0.25 px, and the slope and offset with the most votes win; a least-squares fit on the
//! winners' inliers (within 0.75 px) refines them. It needs no camera calibration, so it
//! works on photographs.
//!
//! [`estimate`] is the whole dense estimate: semi-global matching, then, if asked, the masking
//! or repair below.
//!
//! # Mask and repair ([`robust_disparity`])
//!
//! The pixels to distrust are those the streak detector marks (streaks and the wide glows of
//! mirror reflections at the bottom, [`crate::detect::detect_streaks`]), dilated by the census
//! window's reach, plus every pixel whose disparity is more than `below_tolerance` below
//! the road plane at its row. `mask` makes them invalid (infinite, the PFM convention);
//! `repair` gives each the road plane's disparity at its row, the surface it lies on, where
//! the row is below the horizon. The confidence map is 1 for kept measurements, 0.5 for
//! repaired pixels (a model value, not a measurement) and 0 where there is no value.

use crate::detect::{detect_streaks, DetectError, DetectParams};
use crate::sgm::{sgm, SgmError, SgmParams};
use streaks_image::{ensure_same_size, GrayImage, ImageError, SizeMismatch};

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum RepairError {
    /// The streak detector failed (the cause is the source, so a chain prints it once).
    #[error("streak detection")]
    Detect(#[from] DetectError),
    /// An image could not be made.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The left image and the disparity map differ in size.
    #[error(transparent)]
    Size(#[from] SizeMismatch),
}

/// The road's v-disparity line `d = slope (y - horizon)`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RoadPlane {
    /// Disparity per image row, pixels per pixel (`b / h` for a level rig).
    pub slope: f64,
    /// The image row where the road's disparity reaches 0.
    pub horizon: f64,
    /// Pixels that voted for the line (inliers within 0.75 px).
    pub inliers: usize,
    /// Share of the voting pixels that are inliers.
    pub inlier_share: f64,
    /// RMS of the inliers' residuals, pixels.
    pub rms_px: f64,
}

impl RoadPlane {
    /// The road's disparity at the centre of row `row`, if the row is below the horizon.
    pub fn disparity_at(&self, row: usize) -> Option<f32> {
        let d = self.slope * (row as f64 + 0.5 - self.horizon);
        (d > 0.0).then_some(d as f32)
    }
}

/// Fits the road's v-disparity line to the valid (finite, positive) disparities of `disp`
/// outside `exclude` (non-zero = excluded) in the lower `lower_share` of the rows (see the
/// module documentation). `None` if fewer than 50 pixels vote for any line.
pub fn fit_road_plane(
    disp: &GrayImage,
    exclude: Option<&GrayImage>,
    lower_share: f64,
) -> Option<RoadPlane> {
    let (w, h) = (disp.width, disp.height);
    let first = ((1.0 - lower_share.clamp(0.05, 1.0)) * h as f64) as usize;
    let step = if w * (h - first) > 200_000 { 2 } else { 1 };
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for y in (first..h).step_by(step) {
        for x in (0..w).step_by(step) {
            let i = y * w + x;
            let d = disp.data[i];
            if d.is_finite() && d > 0.0 && exclude.is_none_or(|m| m.data[i] == 0.0) {
                pts.push((y as f64 + 0.5, d as f64));
            }
        }
    }
    if pts.len() < 50 {
        return None;
    }
    const BIN: f64 = 0.25;
    let (mut best, mut best_votes) = ((0.0, 0.0), 0usize);
    let mut hist: Vec<u32> = Vec::new();
    for k in 0..=240 {
        let a = 0.005 * (400f64).powf(k as f64 / 240.0);
        // Offsets c = d - a y; the road's is -a y_h.
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), p| {
                let c = p.1 - a * p.0;
                (l.min(c), u.max(c))
            });
        let bins = (((hi - lo) / BIN) as usize + 2).min(1 << 20);
        hist.clear();
        hist.resize(bins, 0);
        for p in &pts {
            let b = (((p.1 - a * p.0) - lo) / BIN) as usize;
            hist[b.min(bins - 1)] += 1;
        }
        // Votes of a bin and its two neighbours (a line straddling bins).
        for b in 1..bins.saturating_sub(1) {
            let v = (hist[b - 1] + hist[b] + hist[b + 1]) as usize;
            if v > best_votes {
                best_votes = v;
                best = (a, lo + (b as f64 + 0.5) * BIN);
            }
        }
    }
    // Refine by least squares on the inliers, twice.
    let (mut a, mut c) = best;
    let mut inl: Vec<(f64, f64)> = Vec::new();
    for _ in 0..2 {
        inl = pts
            .iter()
            .copied()
            .filter(|p| (p.1 - a * p.0 - c).abs() < 0.75)
            .collect();
        if inl.len() < 50 {
            return None;
        }
        let n = inl.len() as f64;
        let (sx, sy) = inl.iter().fold((0.0, 0.0), |s, p| (s.0 + p.0, s.1 + p.1));
        let (mx, my) = (sx / n, sy / n);
        let (sxx, sxy) = inl.iter().fold((0.0, 0.0), |s, p| {
            (s.0 + (p.0 - mx).powi(2), s.1 + (p.0 - mx) * (p.1 - my))
        });
        if sxx <= 0.0 {
            break;
        }
        a = sxy / sxx;
        c = my - a * mx;
    }
    if a <= 0.0 {
        return None;
    }
    let n = inl.len() as f64;
    let rms = (inl.iter().map(|p| (p.1 - a * p.0 - c).powi(2)).sum::<f64>() / n).sqrt();
    Some(RoadPlane {
        slope: a,
        horizon: -c / a,
        inliers: inl.len(),
        inlier_share: n / pts.len() as f64,
        rms_px: rms,
    })
}

/// What to do with the pixels a streak or reflection fools.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreakHandling {
    /// Mark them invalid.
    Mask,
    /// Give them the road plane's disparity.
    Repair,
}

/// The parameters of [`robust_disparity`].
#[derive(Clone, Debug, PartialEq)]
pub struct RepairParams {
    /// The streak detector's parameters (its horizon defaults to the road plane's).
    pub detect: DetectParams,
    /// Radius by which the detected streak mask grows (the census window's reach), pixels.
    pub dilate: usize,
    /// A disparity more than this below the road plane is a reflection, pixels.
    pub below_tolerance: f32,
    /// The share of the rows, from the bottom, used to fit the road plane.
    pub lower_share: f64,
}

impl Default for RepairParams {
    fn default() -> Self {
        Self {
            detect: DetectParams::default(),
            dilate: 3,
            below_tolerance: 1.0,
            lower_share: 0.45,
        }
    }
}

/// A repaired or masked disparity map and what was done.
#[derive(Clone, Debug)]
pub struct RobustDisparity {
    /// The disparities (infinite: no value).
    pub disparity: GrayImage,
    /// Confidence per pixel: 1 measured, 0.5 repaired (the road plane's), 0 no value.
    pub confidence: GrayImage,
    /// The road plane, if one was found.
    pub plane: Option<RoadPlane>,
    /// Pixels the streak detector marked (after dilation).
    pub streak_pixels: usize,
    /// Pixels whose disparity lay below the road plane.
    pub below_road_pixels: usize,
    /// Pixels repaired (given the road plane's disparity).
    pub repaired_pixels: usize,
    /// Pixels masked (made invalid) that had a value.
    pub masked_pixels: usize,
}

/// What went wrong in [`estimate`].
#[derive(Debug, thiserror::Error)]
pub enum EstimateError {
    /// Semi-global matching failed (the cause is the source, so a chain prints it once).
    #[error("semi-global matching")]
    Sgm(#[from] SgmError),
    /// The streak-robust pass failed.
    #[error("streak-robust disparity")]
    Repair(#[from] RepairError),
}

/// A dense disparity of the left view: semi-global matching's, or the streak-robust one.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// The disparity of the left view (`inf`: no value): SGM's, or the streak-robust one.
    pub disparity: GrayImage,
    /// Wall time of the semi-global matching alone, seconds.
    pub sgm_seconds: f64,
    /// With a streak handling: what the streak-robust pass did (its `disparity` is
    /// [`Estimate::disparity`]).
    pub robust: Option<RobustDisparity>,
}

/// Semi-global matching of `left` and `right` with `params`, then, given a `handling`, the
/// streak-robust pass with its default parameters ([`robust_disparity`]). One function, so
/// that `streaks disparity [--streaks mask|repair]` and the benchmark's `sgm` and
/// `sgm-streaks` methods compute exactly the same map.
pub fn estimate(
    left: &GrayImage,
    right: &GrayImage,
    params: &SgmParams,
    handling: Option<StreakHandling>,
) -> Result<Estimate, EstimateError> {
    let start = std::time::Instant::now();
    let disp = sgm(left, right, params)?;
    let sgm_seconds = start.elapsed().as_secs_f64();
    Ok(match handling {
        None => Estimate {
            disparity: disp,
            sgm_seconds,
            robust: None,
        },
        Some(handling) => {
            let r = robust_disparity(left, &disp, handling, &RepairParams::default())?;
            Estimate {
                disparity: r.disparity.clone(),
                sgm_seconds,
                robust: Some(r),
            }
        }
    })
}

/// `mask` grown by `r` pixels (a square structuring element).
fn dilate(mask: &GrayImage, r: usize) -> GrayImage {
    let (w, h) = (mask.width, mask.height);
    let mut rows = mask.clone();
    for y in 0..h {
        for x in 0..w {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
            rows.data[y * w + x] = f32::from(u8::from(
                mask.data[y * w + x0..y * w + x1].iter().any(|&v| v > 0.0),
            ));
        }
    }
    let mut out = rows.clone();
    for y in 0..h {
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
        for x in 0..w {
            out.data[y * w + x] =
                f32::from(u8::from((y0..y1).any(|yy| rows.data[yy * w + x] > 0.0)));
        }
    }
    out
}

/// Masks or repairs the pixels of `disp` (the left view's disparity) that streaks and
/// reflections fool, using `left` (the left image's luminance) to detect streaks; see the
/// module documentation.
pub fn robust_disparity(
    left: &GrayImage,
    disp: &GrayImage,
    handling: StreakHandling,
    params: &RepairParams,
) -> Result<RobustDisparity, RepairError> {
    ensure_same_size(
        "the left image",
        left.size(),
        "the disparity map",
        disp.size(),
    )?;
    let (w, h) = (disp.width, disp.height);
    // The plane from all valid pixels first (streaks are few), for the detector's horizon.
    let first = fit_road_plane(disp, None, params.lower_share);
    let mut detect = params.detect;
    if detect.horizon.is_none() {
        if let Some(p) = first {
            if p.horizon.is_finite() && p.horizon > 0.0 && p.horizon < h as f64 {
                detect.horizon = Some(p.horizon as f32);
            }
        }
    }
    let detection = detect_streaks(left, &detect)?;
    let streaks = dilate(&detection.mask, params.dilate);
    let plane = fit_road_plane(disp, Some(&streaks), params.lower_share).or(first);
    let mut out = disp.clone();
    let mut confidence = GrayImage::new(w, h, 0.0)?;
    let (mut streak_pixels, mut below, mut repaired, mut masked) = (0, 0, 0, 0);
    for y in 0..h {
        let road = plane.and_then(|p| p.disparity_at(y));
        for x in 0..w {
            let i = y * w + x;
            let d = disp.data[i];
            let in_streak = streaks.data[i] > 0.0;
            let beneath = road.is_some_and(|r| d.is_finite() && d < r - params.below_tolerance);
            streak_pixels += usize::from(in_streak);
            below += usize::from(beneath);
            if in_streak || beneath {
                match (handling, road) {
                    (StreakHandling::Repair, Some(r)) => {
                        out.data[i] = r;
                        confidence.data[i] = 0.5;
                        repaired += 1;
                    }
                    _ => {
                        masked += usize::from(d.is_finite());
                        out.data[i] = f32::INFINITY;
                    }
                }
            } else if d.is_finite() {
                confidence.data[i] = 1.0;
            }
        }
    }
    Ok(RobustDisparity {
        disparity: out,
        confidence,
        plane,
        streak_pixels,
        below_road_pixels: below,
        repaired_pixels: repaired,
        masked_pixels: masked,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic scene: road rows `d = 0.2 (y - 40)`, a wall on the left third (constant
    /// 30 px), and a streak column at x in 60..64 reading 5 px below the road.
    fn scene(w: usize, h: usize) -> (GrayImage, GrayImage) {
        let mut disp = GrayImage::new(w, h, f32::INFINITY).unwrap();
        let mut left = GrayImage::new(w, h, 0.05).unwrap();
        for y in 0..h {
            for x in 0..w {
                let road = 0.2 * (y as f32 + 0.5 - 40.0);
                let d = if x < w / 3 {
                    30.0
                } else if road > 0.0 {
                    road + 0.05 * ((x * 7 + y * 3) % 5) as f32 - 0.1
                } else {
                    f32::INFINITY
                };
                disp.set(x, y, d);
            }
        }
        for y in 50..h {
            for x in 60..64 {
                let road = 0.2 * (y as f32 + 0.5 - 40.0);
                disp.set(x, y, (road - 5.0).max(0.1));
                left.set(x, y, 0.9);
            }
        }
        (left, disp)
    }

    #[test]
    fn plane_is_found_among_walls() {
        let (_, disp) = scene(160, 120);
        let p = fit_road_plane(&disp, None, 0.6).unwrap();
        assert!((p.slope - 0.2).abs() < 0.005, "{p:?}");
        assert!((p.horizon - 40.0).abs() < 1.0, "{p:?}");
        assert!(p.inlier_share > 0.4, "{p:?}");
    }

    #[test]
    fn repair_puts_streaks_on_the_road_and_mask_removes_them() {
        let (left, disp) = scene(160, 120);
        let params = RepairParams {
            detect: DetectParams {
                horizon: Some(40.0),
                ..DetectParams::default()
            },
            ..RepairParams::default()
        };
        let r = robust_disparity(&left, &disp, StreakHandling::Repair, &params).unwrap();
        for y in 50..120 {
            let road = 0.2 * (y as f32 + 0.5 - 40.0);
            for x in 60..64 {
                assert!((r.disparity.get(x, y) - road).abs() < 0.3, "({x}, {y})");
                assert_eq!(r.confidence.get(x, y), 0.5);
            }
        }
        // The wall, nearer than the road, is untouched.
        assert_eq!(r.disparity.get(10, 100), 30.0);
        assert_eq!(r.confidence.get(10, 100), 1.0);
        assert!(r.below_road_pixels >= 4 * 60, "{}", r.below_road_pixels);
        let m = robust_disparity(&left, &disp, StreakHandling::Mask, &params).unwrap();
        assert!(m.disparity.get(61, 100).is_infinite());
        assert_eq!(m.confidence.get(61, 100), 0.0);
        assert!(m.masked_pixels >= 4 * 60);
        assert_eq!(m.disparity.get(100, 100), disp.get(100, 100));
    }

    #[test]
    fn sizes_must_agree_and_empty_maps_have_no_plane() {
        let (left, _) = scene(40, 30);
        let disp = GrayImage::new(41, 30, 1.0).unwrap();
        let e = robust_disparity(&left, &disp, StreakHandling::Mask, &RepairParams::default());
        assert!(matches!(e, Err(RepairError::Size(..))));
        let empty = GrayImage::new(40, 30, f32::INFINITY).unwrap();
        assert!(fit_road_plane(&empty, None, 0.5).is_none());
    }
}
