//! Per-row 1D Lucas-Kanade disparity: the paper's estimator (section IV, Figs. 6 and 8).
//!
//! For each image row of a region, the horizontal disparity at one column (the region's
//! centre, or a per-row centre such as a streak's) is estimated over a `W x rows` window:
//!
//! 1. an integer search picks the disparity with the best zero-mean normalised cross-correlation
//!    (NCC) over `[min_disp, max_disp]`;
//! 2. Gauss-Newton iterations refine it: with `e_k = R(x_k - d) - L(x_k)` (window means removed
//!    unless [`Photometric::None`]) and the symmetric gradient `g_k = (L'(x_k) + R'(x_k - d)) / 2`, the
//!    update is `d += sum(e g) / sum(g^2)`, until it is below `tolerance`. With
//!    [`Photometric::GainOffset`] the right window is also scaled to the left's contrast
//!    (the ratio of standard deviations at the best integer match). The right image is
//!    sampled between pixels by linear or Catmull-Rom cubic interpolation along the row.
//!
//! Each row reports a confidence: the best NCC, the mean squared gradient in the window
//! (texture), the final RMS residual and whether the iterations converged.
//!
//! Coarse to fine (optional, [`LkParams::levels`] > 1): both images are reduced by 2x2 box
//! averaging `levels - 1` times; the whole range `[min_disp, max_disp]` (scaled down) is searched
//! and refined only on the coarsest level, and each finer level searches the 5 integer
//! disparities around twice the coarser estimate before refining. For a wide disparity range
//! this cuts the integer search by about `2^(levels-1)`, and the coarse levels see a larger
//! part of the image, which steers a window with repetitive texture to the right match.
//!
//! Coordinates follow docs/design.md: `x` is an image coordinate in pixels (pixel `i` covers
//! `[i, i+1)`, its centre is `i + 0.5`); rows are pixel indices; `d = x_left - x_right`.

use streaks_image::{ensure_pair_size, stats, GrayImage, ImageError, Region, SizeMismatch};

/// Errors of the Lucas-Kanade estimator (all about user-supplied sizes and parameters).
#[derive(Debug, thiserror::Error)]
pub enum LkError {
    /// Left and right images differ in size.
    #[error(transparent)]
    SizeMismatch(#[from] SizeMismatch),
    /// A parameter is out of range.
    #[error("invalid Lucas-Kanade parameter {name}: {reason}")]
    Param {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: String,
    },
    /// The region is empty or leaves the image.
    #[error(transparent)]
    Region(ImageError),
}

/// Sub-pixel interpolation of the images along a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Interp {
    /// Linear interpolation (gradient: linear interpolation of central differences).
    Linear,
    /// Catmull-Rom cubic (Keys, a = -0.5) with its analytic derivative.
    #[default]
    Cubic,
}

/// Compensation of exposure differences between the two windows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Photometric {
    /// Compare raw intensities.
    None,
    /// Remove each window's mean (an offset between the cameras).
    #[default]
    Offset,
    /// Remove each window's mean and scale the right window to the left's standard deviation
    /// (a gain and an offset). Needs a window with clear texture: on a nearly linear ramp a
    /// gain and a shift cannot be told apart.
    GainOffset,
}

/// Parameters of the per-row estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LkParams {
    /// Window width in pixels (odd, at least 3).
    pub window: usize,
    /// Window height in rows (odd, at least 1); rows beyond the image are clamped.
    pub rows: usize,
    /// Smallest disparity searched (may be negative for photographs aligned by hand).
    pub min_disp: i32,
    /// Largest disparity searched.
    pub max_disp: i32,
    /// Most Gauss-Newton iterations.
    pub max_iters: usize,
    /// Convergence threshold on the update, in pixels.
    pub tolerance: f32,
    /// Interpolation of sub-pixel samples.
    pub interp: Interp,
    /// How exposure differences between the cameras are compensated.
    pub photometric: Photometric,
    /// Pyramid levels for coarse-to-fine estimation (1: none; at most 8; see the module
    /// documentation).
    pub levels: usize,
}

impl Default for LkParams {
    fn default() -> Self {
        Self {
            window: 15,
            rows: 1,
            min_disp: 0,
            max_disp: 64,
            max_iters: 100,
            tolerance: 1e-3,
            interp: Interp::Cubic,
            photometric: Photometric::Offset,
            levels: 1,
        }
    }
}

impl LkParams {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), LkError> {
        let bad = |name, reason: &str| {
            Err(LkError::Param {
                name,
                reason: reason.to_string(),
            })
        };
        if self.window < 3 || self.window % 2 == 0 || self.window > 1025 {
            return bad("window", "must be odd, from 3 to 1025");
        }
        if self.rows == 0 || self.rows % 2 == 0 || self.rows > 63 {
            return bad("rows", "must be odd, from 1 to 63");
        }
        if self.min_disp > self.max_disp {
            return bad("min_disp", "must not exceed max_disp");
        }
        if self.max_disp - self.min_disp > 4096 {
            return bad("max_disp", "the disparity range is limited to 4096");
        }
        if self.tolerance.is_nan() || self.tolerance <= 0.0 {
            return bad("tolerance", "must be positive");
        }
        if !(1..=8).contains(&self.levels) {
            return bad("levels", "must be from 1 to 8");
        }
        Ok(())
    }
}

/// The estimate for one row.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RowDisparity {
    /// Row index.
    pub row: usize,
    /// Image x coordinate of the window centre in the left image.
    pub x: f32,
    /// Disparity `x_left - x_right` in pixels.
    pub disparity: f32,
    /// Zero-mean NCC of the best integer disparity (1 = perfect match, NaN for a flat window).
    pub ncc: f32,
    /// Mean squared horizontal gradient in the window (texture: near 0 means no information).
    pub gradient_energy: f32,
    /// RMS residual after the last iteration.
    pub residual: f32,
    /// Whether the update fell below the tolerance within the iteration limit.
    pub converged: bool,
}

/// Reusable buffers, so estimating many rows does not allocate.
#[derive(Clone, Debug, Default)]
pub struct LkScratch {
    left: Vec<f32>,
    left_grad: Vec<f32>,
    right: Vec<f32>,
    right_grad: Vec<f32>,
}

/// Samples row `y` at index coordinate `u` (pixel centres at integers), clamping at the edges;
/// returns (value, d value / du).
#[inline]
fn sample(img: &GrayImage, y: usize, u: f32, interp: Interp) -> (f32, f32) {
    let row = &img.data[y * img.width..(y + 1) * img.width];
    let last = img.width as isize - 1;
    let at = |i: isize| row[i.clamp(0, last) as usize];
    let fu = u.floor();
    let i = fu as isize;
    let t = u - fu;
    match interp {
        Interp::Linear => {
            let (a, b) = (at(i), at(i + 1));
            let ga = 0.5 * (at(i + 1) - at(i - 1));
            let gb = 0.5 * (at(i + 2) - at(i));
            (a + t * (b - a), ga + t * (gb - ga))
        }
        Interp::Cubic => {
            let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
            let a = -0.5 * p0 + 1.5 * p1 - 1.5 * p2 + 0.5 * p3;
            let b = p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3;
            let c = -0.5 * p0 + 0.5 * p2;
            let v = ((a * t + b) * t + c) * t + p1;
            let g = (3.0 * a * t + 2.0 * b) * t + c;
            (v, g)
        }
    }
}

/// Estimates the disparity of row `row` at image x coordinate `x` (left image).
/// The caller checks sizes and parameters ([`lk_rows`] and [`lk_region`] do).
pub fn lk_row(
    left: &GrayImage,
    right: &GrayImage,
    row: usize,
    x: f32,
    params: &LkParams,
    scratch: &mut LkScratch,
) -> RowDisparity {
    let half = (params.window / 2) as isize;
    let half_rows = (params.rows / 2) as isize;
    let n = params.window * params.rows;
    scratch.left.resize(n, 0.0);
    scratch.left_grad.resize(n, 0.0);
    scratch.right.resize(n, 0.0);
    scratch.right_grad.resize(n, 0.0);
    let uc = x - 0.5;
    let last_row = left.height as isize - 1;
    let row_of = |r: isize| (row as isize + r).clamp(0, last_row) as usize;

    // Left window (values and gradients), and its mean.
    let mut k = 0;
    for r in -half_rows..=half_rows {
        let y = row_of(r);
        for c in -half..=half {
            let (v, g) = sample(left, y, uc + c as f32, params.interp);
            scratch.left[k] = v;
            scratch.left_grad[k] = g;
            k += 1;
        }
    }
    let nf = n as f32;
    let left_mean = if params.photometric != Photometric::None {
        scratch.left.iter().sum::<f32>() / nf
    } else {
        0.0
    };
    let left_var: f32 = scratch
        .left
        .iter()
        .map(|&v| (v - left_mean) * (v - left_mean))
        .sum();

    // Integer search by zero-mean NCC (the same fractional phase as the left window).
    let mut best = (f32::NEG_INFINITY, params.min_disp);
    let mut best_var_r = 0.0f32;
    for d in params.min_disp..=params.max_disp {
        let mut k = 0;
        let (mut sr, mut srr, mut slr) = (0.0f32, 0.0f32, 0.0f32);
        for r in -half_rows..=half_rows {
            let y = row_of(r);
            for c in -half..=half {
                let (v, _) = sample(right, y, uc + c as f32 - d as f32, params.interp);
                let l = scratch.left[k] - left_mean;
                sr += v;
                srr += v * v;
                slr += l * v;
                k += 1;
            }
        }
        // sum((l)(v - mean_v)) = sum(l v) since sum(l) = 0 after removing the left mean.
        let var_r = srr - sr * sr / nf;
        let ncc = slr / (left_var * var_r).sqrt();
        if ncc > best.0 {
            best = (ncc, d);
            best_var_r = var_r;
        }
    }
    let ncc = if best.0.is_finite() { best.0 } else { f32::NAN };

    // The contrast ratio of the best integer match starts the gain (GainOffset only).
    let mut gain =
        if params.photometric == Photometric::GainOffset && best_var_r > 0.0 && left_var > 0.0 {
            (left_var / best_var_r).sqrt()
        } else {
            1.0
        };

    // Gauss-Newton on the shift.
    let mut d = best.1 as f32;
    let mut converged = false;
    let mut residual = f32::NAN;
    let mut gradient_energy = 0.0;
    let (lo, hi) = (params.min_disp as f32 - 1.0, params.max_disp as f32 + 1.0);
    for _ in 0..params.max_iters.max(1) {
        let mut k = 0;
        let mut right_mean = 0.0;
        for r in -half_rows..=half_rows {
            let y = row_of(r);
            for c in -half..=half {
                let (v, g) = sample(right, y, uc + c as f32 - d, params.interp);
                scratch.right[k] = v;
                scratch.right_grad[k] = g;
                right_mean += v;
                k += 1;
            }
        }
        right_mean = if params.photometric != Photometric::None {
            right_mean / nf
        } else {
            0.0
        };
        // Sums over the window: r = right - mean, l = left - mean, g = symmetric gradient.
        let (mut srr, mut srg, mut sgg, mut srl, mut sgl) = (0.0f32, 0.0, 0.0, 0.0, 0.0);
        for k in 0..n {
            let rv = scratch.right[k] - right_mean;
            let lv = scratch.left[k] - left_mean;
            let g = 0.5 * (scratch.left_grad[k] / gain + scratch.right_grad[k]);
            srr += rv * rv;
            srg += rv * g;
            sgg += g * g;
            srl += rv * lv;
            sgl += g * lv;
        }
        gradient_energy = sgg / nf;
        if sgg.is_nan() || sgg <= 0.0 {
            let see: f32 = (0..n)
                .map(|k| {
                    let e = gain * (scratch.right[k] - right_mean) - (scratch.left[k] - left_mean);
                    e * e
                })
                .sum();
            residual = (see / nf).sqrt();
            break;
        }
        // Least squares of gain (r - step g) = l: linear in a = gain and b = gain * step.
        let step = if params.photometric == Photometric::GainOffset {
            let det = srr * sgg - srg * srg;
            let a = (srl * sgg - srg * sgl) / det;
            let b = (srg * srl - srr * sgl) / det;
            if det > 0.0 && a > 0.0 && a.is_finite() && b.is_finite() {
                gain = a;
                b / a
            } else {
                (srg - sgl / gain) / sgg
            }
        } else {
            (srg - sgl) / sgg
        };
        // The residual sum(gain r - l)^2 before the step.
        residual = ((gain * gain * srr - 2.0 * gain * srl + left_var).max(0.0) / nf).sqrt();
        d += step;
        if !(lo..=hi).contains(&d) {
            d = d.clamp(lo, hi);
            break;
        }
        if step.abs() < params.tolerance {
            converged = true;
            break;
        }
    }
    RowDisparity {
        row,
        x,
        disparity: d,
        ncc,
        gradient_energy,
        residual,
        converged,
    }
}

fn check(left: &GrayImage, right: &GrayImage, params: &LkParams) -> Result<(), LkError> {
    ensure_pair_size(left.size(), right.size())?;
    params.validate()
}

/// The image reduced by 2: each pixel the mean of a 2x2 block (a last odd row or column is
/// dropped; at least one pixel remains). Pixel `i` of the result covers `[2i, 2i+2)` of the
/// input, so a coordinate `x` becomes `x / 2`.
fn half_size(img: &GrayImage) -> GrayImage {
    let (w, h) = ((img.width / 2).max(1), (img.height / 2).max(1));
    let at = |x: usize, y: usize| img.get(x.min(img.width - 1), y.min(img.height - 1));
    let data = (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| {
                0.25 * (at(2 * x, 2 * y)
                    + at(2 * x + 1, 2 * y)
                    + at(2 * x, 2 * y + 1)
                    + at(2 * x + 1, 2 * y + 1))
            })
        })
        .collect();
    GrayImage::from_vec(w, h, data).expect("a reduced image keeps at least one pixel")
}

/// Estimates the disparity of each `(row, x)` (row index, left-image x coordinate), coarse to
/// fine when `params.levels > 1`. Rows outside the image or non-finite `x` are errors.
pub fn lk_rows(
    left: &GrayImage,
    right: &GrayImage,
    centres: &[(usize, f32)],
    params: &LkParams,
) -> Result<Vec<RowDisparity>, LkError> {
    check(left, right, params)?;
    // pyramid[l] is level l + 1 (level 0 is the input).
    let mut pyramid: Vec<(GrayImage, GrayImage)> = Vec::with_capacity(params.levels - 1);
    for _ in 1..params.levels {
        let (l, r) = pyramid.last().map_or((left, right), |(l, r)| (l, r));
        pyramid.push((half_size(l), half_size(r)));
    }
    let coarsest = pyramid.len() as u32;
    // [min_disp, max_disp] on level `level` (floor and ceiling of the scaled bounds).
    let full_range = |level: u32| {
        let scale = 1i32 << level;
        (
            params.min_disp.div_euclid(scale),
            -(-params.max_disp).div_euclid(scale),
        )
    };
    let mut scratch = LkScratch::default();
    centres
        .iter()
        .map(|&(row, x)| {
            if row >= left.height || !(0.0..=left.width as f32).contains(&x) {
                return Err(LkError::Param {
                    name: "centre",
                    reason: format!(
                        "row {row}, x {x} is outside the {}x{} image",
                        left.width, left.height
                    ),
                });
            }
            // The search range of the current level, from the coarsest level down.
            let mut range = full_range(coarsest);
            for level in (1..=coarsest).rev() {
                let (l, r) = &pyramid[level as usize - 1];
                let p = LkParams {
                    min_disp: range.0,
                    max_disp: range.1,
                    ..*params
                };
                let f = (1u32 << level) as f32;
                let y = (row >> level).min(l.height - 1);
                let d = lk_row(l, r, y, x / f, &p, &mut scratch).disparity;
                // The next finer level: 5 integers around twice this estimate, in range.
                let (lo, hi) = full_range(level - 1);
                let centre = (2.0 * d).round() as i32;
                range = ((centre - 2).clamp(lo, hi), (centre + 2).clamp(lo, hi));
            }
            let p = LkParams {
                min_disp: range.0,
                max_disp: range.1,
                ..*params
            };
            Ok(lk_row(left, right, row, x, &p, &mut scratch))
        })
        .collect()
}

/// Estimates the disparity of every row of `region` at its centre column.
pub fn lk_region(
    left: &GrayImage,
    right: &GrayImage,
    region: Region,
    params: &LkParams,
) -> Result<Vec<RowDisparity>, LkError> {
    region
        .check_fits("", left.width, left.height)
        .map_err(LkError::Region)?;
    let x = region.centre_x();
    let centres: Vec<(usize, f32)> = (region.y0..region.y1).map(|y| (y, x)).collect();
    lk_rows(left, right, &centres, params)
}

/// Removes Monte Carlo fireflies: a pixel brighter than `ratio` times the second brightest of
/// its 8 neighbours is replaced by that neighbour (border pixels are kept; the second, so that
/// two fireflies side by side both go). A firefly lands in one eye only, and one in a window
/// outweighs the whole texture of a dark road; a real feature (an edge, a streak, a lamp) spans
/// more than two pixels and is left alone, but for the last pixel of a one-pixel-wide line.
pub fn despeckle(img: &GrayImage, ratio: f32) -> GrayImage {
    let mut out = img.clone();
    let (w, h) = (img.width, img.height);
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let (mut m1, mut m2) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
            for (dx, dy) in [
                (0, 0),
                (1, 0),
                (2, 0),
                (0, 1),
                (2, 1),
                (0, 2),
                (1, 2),
                (2, 2),
            ] {
                let v = img.get(x + dx - 1, y + dy - 1);
                if v > m1 {
                    (m1, m2) = (v, m1);
                } else if v > m2 {
                    m2 = v;
                }
            }
            if img.get(x, y) > ratio * m2.max(0.0) {
                out.set(x, y, m2);
            }
        }
    }
    out
}

/// Compresses the dynamic range: `ln(max(v, 0) + floor)`. On a night image lit by a few lamps
/// the texture of a dark road is multiplied by the illumination; in the log it has the same
/// contrast everywhere, and bright neighbours no longer dominate a window. `floor` (positive)
/// keeps the noise of the darkest pixels from being amplified without bound.
pub fn log_compress(img: &GrayImage, floor: f32) -> GrayImage {
    let mut out = img.clone();
    for v in &mut out.data {
        *v = (v.max(0.0) + floor).ln();
    }
    out
}

/// A rendered or photographed pair as LK measures it best at night: fireflies removed
/// ([`despeckle`], ratio 2) and the range compressed ([`log_compress`], floor a tenth of the
/// left image's median, so both eyes get the same curve). `streaks analyze` measures streaks,
/// poles and road on this, and `streaks lk` does unless told `--raw`.
pub fn prepare_pair(left: &GrayImage, right: &GrayImage) -> (GrayImage, GrayImage) {
    let median = stats::median(left.data.iter().copied()).unwrap_or(0.0);
    let floor = (0.1 * median).max(1e-6);
    let prep = |img: &GrayImage| log_compress(&despeckle(img, 2.0), floor);
    (prep(left), prep(right))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{SynthPair, SynthScene};

    fn shifted_pair(d: f32, gain: f32, offset: f32) -> (GrayImage, GrayImage) {
        let p = SynthPair::shifted(96, 24, 7, d, gain, offset).unwrap();
        (p.left, p.right)
    }

    #[test]
    fn despeckle_removes_single_pixels_only_and_log_compress_is_monotone() {
        let mut img = GrayImage::new(7, 7, 0.1).unwrap();
        img.set(2, 2, 5.0); // a firefly
        img.set(2, 4, 6.0); // two side by side
        img.set(3, 4, 4.0);
        for y in 0..7 {
            img.set(5, y, 3.0); // a one-pixel-wide vertical line: a feature, not a firefly
        }
        let d = despeckle(&img, 2.0);
        assert_eq!(d.get(2, 2), 0.1);
        assert_eq!((d.get(2, 4), d.get(3, 4)), (0.1, 0.1));
        for y in 0..7 {
            assert_eq!(d.get(5, y), 3.0);
        }
        assert_eq!(d.get(0, 0), 0.1);
        let l = log_compress(&img, 0.01);
        assert!((l.get(0, 0) - 0.11f32.ln()).abs() < 1e-6);
        assert!(l.get(2, 2) > l.get(5, 0) && l.get(5, 0) > l.get(0, 0));
    }

    #[test]
    fn sub_pixel_shift_is_recovered() {
        for photometric in [Photometric::Offset, Photometric::GainOffset] {
            let mut worst = [0.0f32; 2];
            for &d in &[0.0f32, 0.25, 3.4, 7.77, 12.5] {
                let (l, r) = shifted_pair(d, 1.0, 0.0);
                for (i, interp) in [Interp::Cubic, Interp::Linear].into_iter().enumerate() {
                    let p = LkParams {
                        max_disp: 20,
                        interp,
                        photometric,
                        ..LkParams::default()
                    };
                    let region = Region {
                        x0: 30,
                        y0: 2,
                        x1: 61,
                        y1: 22,
                    };
                    for e in lk_region(&l, &r, region, &p).unwrap() {
                        assert!(e.converged, "{interp:?} {e:?}");
                        assert!(e.ncc > 0.95 && e.gradient_energy > 0.0);
                        worst[i] = worst[i].max((e.disparity - d).abs());
                    }
                }
            }
            eprintln!(
                "LK {photometric:?} worst error: cubic {} px, linear {} px",
                worst[0], worst[1]
            );
            assert!(worst[0] < 0.05 && worst[1] < 0.1, "{worst:?}");
        }
    }

    #[test]
    fn coarse_to_fine_finds_large_disparities_with_a_narrow_search() {
        // 160 x 24 pair shifted by up to 45.6 px, searched over [0, 64]: the pyramid finds the
        // same sub-pixel answer as the full search; a wrong start range cannot hide it, since
        // the coarsest level still searches the whole (scaled) range.
        let region = Region {
            x0: 100,
            y0: 4,
            x1: 131,
            y1: 20,
        };
        for &d in &[3.4f32, 21.37, 45.6] {
            let SynthPair {
                left: l, right: r, ..
            } = SynthPair::shifted(160, 24, 11, d, 1.0, 0.0).unwrap();
            for levels in [1, 2, 3, 4] {
                let p = LkParams {
                    max_disp: 64,
                    levels,
                    ..LkParams::default()
                };
                for e in lk_region(&l, &r, region, &p).unwrap() {
                    assert!(
                        (e.disparity - d).abs() < 0.05,
                        "levels {levels}, d {d}: {e:?}"
                    );
                }
            }
        }
        // The reduced image is the 2x2 mean, and levels out of range are errors.
        let img = GrayImage::from_vec(3, 2, vec![1.0, 3.0, 9.0, 5.0, 7.0, 9.0]).unwrap();
        let half = half_size(&img);
        assert_eq!((half.width, half.height, half.get(0, 0)), (1, 1, 4.0));
        for levels in [0, 9] {
            let p = LkParams {
                levels,
                ..LkParams::default()
            };
            assert!(matches!(
                p.validate(),
                Err(LkError::Param { name: "levels", .. })
            ));
        }
    }

    #[test]
    fn exposure_difference_and_window_rows() {
        let (l, r) = shifted_pair(5.3, 0.7, 0.1);
        let p = LkParams {
            rows: 3,
            max_disp: 16,
            photometric: Photometric::GainOffset,
            ..LkParams::default()
        };
        let est = lk_rows(&l, &r, &[(5, 40.2), (12, 50.0)], &p).unwrap();
        for e in est {
            // A gain is not modelled by the zero-mean residual, but it does not bias the shift.
            assert!((e.disparity - 5.3).abs() < 0.05, "{e:?}");
        }
    }

    #[test]
    fn negative_disparities_and_a_slanted_scene() {
        let (l, r) = shifted_pair(-4.6, 1.0, 0.0);
        let p = LkParams {
            min_disp: -10,
            max_disp: 10,
            ..LkParams::default()
        };
        let est = lk_region(
            &l,
            &r,
            Region {
                x0: 40,
                y0: 0,
                x1: 41,
                y1: 24,
            },
            &p,
        )
        .unwrap();
        assert!(est.iter().all(|e| (e.disparity + 4.6).abs() < 0.05));

        // The synthetic road: disparity changes from row to row.
        let scene = SynthScene {
            boxes: vec![],
            ..SynthScene::textured(128, 64, 3)
        };
        let pair = scene.render().unwrap();
        let p = LkParams {
            max_disp: 16,
            ..LkParams::default()
        };
        let est = lk_region(
            &pair.left,
            &pair.right,
            Region {
                x0: 50,
                y0: 0,
                x1: 81,
                y1: 64,
            },
            &p,
        )
        .unwrap();
        for e in est {
            let truth = scene.background_disparity(e.row);
            assert!((e.disparity - truth).abs() < 0.05, "{e:?} truth {truth}");
        }
    }

    #[test]
    fn a_flat_window_is_flagged_and_bad_input_is_an_error() {
        let l = GrayImage::new(40, 4, 0.5).unwrap();
        let est = lk_rows(&l, &l, &[(1, 20.0)], &LkParams::default()).unwrap();
        assert!(!est[0].converged && est[0].gradient_energy == 0.0 && est[0].ncc.is_nan());
        let small = GrayImage::new(39, 4, 0.5).unwrap();
        assert!(matches!(
            lk_rows(&l, &small, &[], &LkParams::default()),
            Err(LkError::SizeMismatch(_))
        ));
        let even = LkParams {
            window: 4,
            ..LkParams::default()
        };
        assert!(lk_rows(&l, &l, &[], &even).is_err());
        let r = Region {
            x0: 0,
            y0: 0,
            x1: 41,
            y1: 2,
        };
        assert!(matches!(
            lk_region(&l, &l, r, &LkParams::default()),
            Err(LkError::Region(_))
        ));
        assert!(lk_rows(&l, &l, &[(4, 1.0)], &LkParams::default()).is_err());
    }
}
