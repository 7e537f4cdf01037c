//! Dense disparity by semi-global matching (Hirschmüller 2008) with a census-transform cost,
//! the method driver-assistance stereo cameras use.
//!
//! 1. **Census transform** of both images (5x5 or 7x7 window; bit set when a neighbour is darker
//!    than the centre): only the order of intensities matters, so a gain or an offset between
//!    the cameras changes nothing. The matching cost of left pixel `x` at disparity `d` is the
//!    Hamming distance of the census codes of `x` and `x - d` (a `u8`).
//! 2. **Aggregation** along 4 (horizontal and vertical) or 8 (and diagonal) paths:
//!    `L_r(p, d) = C(p, d) + min(L_r(p-r, d), L_r(p-r, d±1) + P1, min_k L_r(p-r, k) + P2) -
//!    min_k L_r(p-r, k)`, summed into `S(p, d)` (`u16`, the one `W x H x D` array). P2 may be
//!    lowered across intensity edges: `P2 / (1 + p2_gradient |ΔI| / range)`, at least P1.
//!    Rows of the horizontal paths run in parallel; the vertical and diagonal paths sweep down
//!    and then up, the pixels of a row in parallel.
//! 3. **Winner-take-all** with a parabola through the three costs around the minimum (sub-pixel),
//!    a **left-right consistency check** against the right image's winners (read from the same
//!    `S`), and an optional 3x3 median of the valid disparities. Invalid pixels are `inf`, as in
//!    the PFM convention.
//!
//! Memory: `2 W H D` bytes (128 MB for a megapixel at D = 64) plus row buffers.
//! Disparity follows docs/design.md: `d = x_left - x_right`; the range `[min_disp, max_disp]` may
//! include negative values (photographs aligned by hand).

use rayon::prelude::*;
use streaks_image::stats::quantile;
use streaks_image::{ensure_pair_size, ensure_same_size, GrayImage, ImageError, SizeMismatch};

/// Errors of the dense matcher (about user-supplied sizes and parameters).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SgmError {
    /// Left and right images (or an estimate and its ground truth) differ in size.
    #[error(transparent)]
    SizeMismatch(#[from] SizeMismatch),
    /// A parameter is out of range.
    #[error("invalid semi-global matching parameter {name}: {reason}")]
    Param {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: String,
    },
    /// The volume would be too large.
    #[error("a {width}x{height} image with {disparities} disparities needs {bytes} bytes (limit {limit})")]
    TooLarge {
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
        /// Number of disparities.
        disparities: usize,
        /// Bytes needed.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
}

/// Census window.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Census {
    /// 5x5 window, 24 bits.
    Census5x5,
    /// 7x7 window, 48 bits.
    #[default]
    Census7x7,
}

impl Census {
    fn radius(self) -> isize {
        match self {
            Census::Census5x5 => 2,
            Census::Census7x7 => 3,
        }
    }

    /// Default penalties (P1, P2) for this window's cost range.
    pub fn default_penalties(self) -> (u16, u16) {
        match self {
            Census::Census5x5 => (4, 43),
            Census::Census7x7 => (7, 86),
        }
    }

    /// Number of bits of a code (the largest possible cost).
    pub fn bits(self) -> u32 {
        let n = 2 * self.radius() as u32 + 1;
        n * n - 1
    }
}

/// Aggregation paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Paths {
    /// Left-right, right-left, top-down, bottom-up.
    Four,
    /// The four plus the four diagonals.
    #[default]
    Eight,
}

/// Parameters of semi-global matching.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SgmParams {
    /// Smallest disparity.
    pub min_disp: i32,
    /// Largest disparity (the volume has `max_disp - min_disp + 1` disparities).
    pub max_disp: i32,
    /// Census window.
    pub census: Census,
    /// Aggregation paths.
    pub paths: Paths,
    /// Penalty of a disparity change of one pixel between neighbours.
    pub p1: u16,
    /// Penalty of a larger change.
    pub p2: u16,
    /// Lowering of P2 across intensity edges (0: constant P2).
    pub p2_gradient: f32,
    /// Parabola sub-pixel refinement.
    pub subpixel: bool,
    /// Largest left-right disagreement in pixels; `None` skips the check.
    pub lr_tolerance: Option<f32>,
    /// 3x3 median filter of the valid disparities.
    pub median: bool,
}

impl Default for SgmParams {
    fn default() -> Self {
        Self {
            min_disp: 0,
            max_disp: 63,
            census: Census::Census7x7,
            paths: Paths::Eight,
            p1: Census::Census7x7.default_penalties().0,
            p2: Census::Census7x7.default_penalties().1,
            p2_gradient: 0.0,
            subpixel: true,
            lr_tolerance: Some(1.0),
            median: true,
        }
    }
}

/// Largest aggregation volume accepted (bytes).
pub const MAX_VOLUME_BYTES: u64 = 4 << 30;

impl SgmParams {
    /// The number of disparities.
    pub fn disparities(&self) -> usize {
        (self.max_disp as i64 - self.min_disp as i64 + 1).max(0) as usize
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), SgmError> {
        let bad = |name, reason: &str| {
            Err(SgmError::Param {
                name,
                reason: reason.to_string(),
            })
        };
        if self.min_disp > self.max_disp {
            return bad("min_disp", "must not exceed max_disp");
        }
        if self.disparities() < 3 || self.disparities() > 1024 {
            return bad("max_disp", "the range must hold from 3 to 1024 disparities");
        }
        if self.p1 == 0 || self.p1 > self.p2 || self.p2 > 1000 {
            return bad("p2", "need 0 < P1 <= P2 <= 1000");
        }
        if !self.p2_gradient.is_finite() || self.p2_gradient < 0.0 {
            return bad("p2_gradient", "must be a non-negative number");
        }
        if let Some(t) = self.lr_tolerance {
            if !t.is_finite() || t < 0.0 {
                return bad("lr_tolerance", "must be a non-negative number");
            }
        }
        Ok(())
    }
}

/// Census codes of an image (bit set when the neighbour is darker than the centre; the window
/// is clamped at the borders).
pub fn census_transform(img: &GrayImage, census: Census) -> Vec<u64> {
    let (w, h) = (img.width as isize, img.height as isize);
    let r = census.radius();
    let mut out = vec![0u64; img.data.len()];
    out.par_chunks_mut(img.width)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as isize;
            for (x, code) in row.iter_mut().enumerate() {
                let x = x as isize;
                let c = img.data[(y * w + x) as usize];
                let mut bits = 0u64;
                for dy in -r..=r {
                    let yy = (y + dy).clamp(0, h - 1);
                    let line = &img.data[(yy * w) as usize..((yy + 1) * w) as usize];
                    for dx in -r..=r {
                        if dx == 0 && dy == 0 {
                            continue;
                        }
                        let v = line[(x + dx).clamp(0, w - 1) as usize];
                        bits = (bits << 1) | u64::from(v < c);
                    }
                }
                *code = bits;
            }
        });
    out
}

/// Everything the passes share.
struct Ctx<'a> {
    width: usize,
    height: usize,
    nd: usize,
    min_disp: i32,
    p1: u16,
    p2: u16,
    p2_gradient: f32,
    out_cost: u8,
    left_census: &'a [u64],
    right_census: &'a [u64],
    /// Left intensities divided by their 1-99 % range (for the adaptive P2).
    left_norm: Vec<f32>,
}

impl Ctx<'_> {
    /// The matching costs of left pixel (x, y) for every disparity.
    #[inline]
    fn costs(&self, x: usize, y: usize, out: &mut [u8]) {
        let row = y * self.width;
        let cl = self.left_census[row + x];
        for (k, c) in out.iter_mut().enumerate() {
            let xr = x as i64 - (self.min_disp as i64 + k as i64);
            *c = if xr >= 0 && (xr as usize) < self.width {
                (cl ^ self.right_census[row + xr as usize]).count_ones() as u8
            } else {
                self.out_cost
            };
        }
    }

    /// P2 for the step from pixel index `from` to pixel index `to`.
    #[inline]
    fn p2_between(&self, from: usize, to: usize) -> u16 {
        if self.p2_gradient == 0.0 {
            return self.p2;
        }
        let di = (self.left_norm[to] - self.left_norm[from]).abs();
        let p2 = self.p2 as f32 / (1.0 + self.p2_gradient * di);
        (p2.round() as u16).max(self.p1)
    }
}

/// One step along a path: `out = cost + min(prev, prev±1 + P1, min(prev) + P2) - min(prev)`.
#[inline]
fn path_step(cost: &[u8], prev: &[u16], out: &mut [u16], p1: u16, p2: u16) {
    let n = cost.len();
    let min_prev = prev.iter().copied().min().unwrap_or(0);
    let cap = min_prev + p2;
    let first = prev[0].min(prev[1] + p1).min(cap);
    out[0] = cost[0] as u16 + first - min_prev;
    for ((o, &c), w) in out[1..n - 1]
        .iter_mut()
        .zip(&cost[1..n - 1])
        .zip(prev.windows(3))
    {
        let m = w[1].min(w[0] + p1).min(w[2] + p1).min(cap);
        *o = c as u16 + m - min_prev;
    }
    let last = prev[n - 1].min(prev[n - 2] + p1).min(cap);
    out[n - 1] = cost[n - 1] as u16 + last - min_prev;
}

#[inline]
fn start_path(cost: &[u8], out: &mut [u16]) {
    for (o, &c) in out.iter_mut().zip(cost) {
        *o = c as u16;
    }
}

#[inline]
fn accumulate(sum: &mut [u16], l: &[u16]) {
    for (s, &v) in sum.iter_mut().zip(l) {
        *s += v;
    }
}

/// Left-to-right and right-to-left paths of every row, written (not added) into `sum`.
fn horizontal_paths(ctx: &Ctx, sum: &mut [u16]) {
    let (w, nd) = (ctx.width, ctx.nd);
    sum.par_chunks_mut(w * nd).enumerate().for_each_init(
        || (vec![0u8; w * nd], vec![0u16; 2 * nd]),
        |(cost, lbuf), (y, srow)| {
            for x in 0..w {
                ctx.costs(x, y, &mut cost[x * nd..(x + 1) * nd]);
            }
            let (prev, cur) = lbuf.split_at_mut(nd);
            for x in 0..w {
                let c = &cost[x * nd..(x + 1) * nd];
                if x == 0 {
                    start_path(c, cur);
                } else {
                    let p2 = ctx.p2_between(y * w + x - 1, y * w + x);
                    path_step(c, prev, cur, ctx.p1, p2);
                }
                srow[x * nd..(x + 1) * nd].copy_from_slice(cur);
                prev.copy_from_slice(cur);
            }
            for x in (0..w).rev() {
                let c = &cost[x * nd..(x + 1) * nd];
                if x == w - 1 {
                    start_path(c, cur);
                } else {
                    let p2 = ctx.p2_between(y * w + x + 1, y * w + x);
                    path_step(c, prev, cur, ctx.p1, p2);
                }
                accumulate(&mut srow[x * nd..(x + 1) * nd], cur);
                prev.copy_from_slice(cur);
            }
        },
    );
}

/// Pixels per parallel task in the vertical sweeps.
const CHUNK: usize = 32;

/// The vertical path (and with `diagonals` the two diagonal ones) sweeping down (`down`) or up,
/// added into `sum`.
fn vertical_paths(ctx: &Ctx, sum: &mut [u16], down: bool, diagonals: bool) {
    let (w, h, nd) = (ctx.width, ctx.height, ctx.nd);
    // Path p comes from column x + DX[p] of the previous row.
    const DX: [isize; 3] = [0, -1, 1];
    let np = if diagonals { 3 } else { 1 };
    let mut prev = vec![0u16; w * np * nd];
    let mut cur = vec![0u16; w * np * nd];
    for i in 0..h {
        let y = if down { i } else { h - 1 - i };
        let y_prev = if down { y.wrapping_sub(1) } else { y + 1 };
        let srow = &mut sum[y * w * nd..(y + 1) * w * nd];
        let prev_ref = &prev;
        srow.par_chunks_mut(CHUNK * nd)
            .zip(cur.par_chunks_mut(CHUNK * np * nd))
            .enumerate()
            .for_each_init(
                || vec![0u8; nd],
                |cost, (chunk, (schunk, cchunk))| {
                    for j in 0..schunk.len() / nd {
                        let x = chunk * CHUNK + j;
                        ctx.costs(x, y, cost);
                        for (p, &dx) in DX.iter().enumerate().take(np) {
                            let px = x as isize + dx;
                            let out = &mut cchunk[(j * np + p) * nd..(j * np + p + 1) * nd];
                            if i == 0 || px < 0 || px >= w as isize {
                                start_path(cost, out);
                            } else {
                                let px = px as usize;
                                let p2 = ctx.p2_between(y_prev * w + px, y * w + x);
                                let from = &prev_ref[(px * np + p) * nd..(px * np + p + 1) * nd];
                                path_step(cost, from, out, ctx.p1, p2);
                            }
                            accumulate(&mut schunk[j * nd..(j + 1) * nd], out);
                        }
                    }
                },
            );
        std::mem::swap(&mut prev, &mut cur);
    }
}

/// Winner-take-all, sub-pixel refinement and the left-right check on the aggregated costs.
fn select(ctx: &Ctx, sum: &[u16], params: &SgmParams) -> Vec<f32> {
    let (w, nd) = (ctx.width, ctx.nd);
    let mut out = vec![f32::INFINITY; w * ctx.height];
    out.par_chunks_mut(w)
        .zip(sum.par_chunks(w * nd))
        .for_each_init(
            || vec![0i64; w],
            |right_best, (orow, srow)| {
                // Right image winners: x_r matches left x = x_r + d.
                for (xr, rb) in right_best.iter_mut().enumerate() {
                    let mut best = (u16::MAX, i64::MIN);
                    for k in 0..nd {
                        let x = xr as i64 + ctx.min_disp as i64 + k as i64;
                        if x >= 0 && (x as usize) < w && srow[x as usize * nd + k] < best.0 {
                            best = (srow[x as usize * nd + k], k as i64);
                        }
                    }
                    *rb = best.1;
                }
                for (x, o) in orow.iter_mut().enumerate() {
                    let s = &srow[x * nd..(x + 1) * nd];
                    let mut k = 0;
                    for (j, &v) in s.iter().enumerate() {
                        if v < s[k] {
                            k = j;
                        }
                    }
                    let mut d = k as f32;
                    if params.subpixel && k > 0 && k + 1 < nd {
                        let (a, b, c) = (s[k - 1] as f32, s[k] as f32, s[k + 1] as f32);
                        let den = a - 2.0 * b + c;
                        if den > 0.0 {
                            d += (0.5 * (a - c) / den).clamp(-0.5, 0.5);
                        }
                    }
                    let disparity = ctx.min_disp as f32 + d;
                    if let Some(tol) = params.lr_tolerance {
                        let xr = x as i64 - (ctx.min_disp as i64 + k as i64);
                        if xr < 0 || xr as usize >= w {
                            continue;
                        }
                        let kr = right_best[xr as usize];
                        if kr == i64::MIN || ((kr - k as i64).abs() as f32) > tol {
                            continue;
                        }
                    }
                    *o = disparity;
                }
            },
        );
    out
}

/// 3x3 median of the finite values around each finite pixel (invalid pixels stay invalid).
pub fn median3x3(img: &GrayImage) -> GrayImage {
    let (w, h) = (img.width, img.height);
    let mut out = img.clone();
    out.data.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            if !img.get(x, y).is_finite() {
                continue;
            }
            let mut vals = [0.0f32; 9];
            let mut n = 0;
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    let v = img.get(xx, yy);
                    if v.is_finite() {
                        vals[n] = v;
                        n += 1;
                    }
                }
            }
            let vals = &mut vals[..n];
            vals.sort_unstable_by(f32::total_cmp);
            *o = vals[n / 2];
        }
    });
    out
}

/// [`ensure_same_size`] of a disparity estimate and its ground truth.
pub(crate) fn check_against_truth(estimate: &GrayImage, truth: &GrayImage) -> Result<(), SgmError> {
    let (e, t) = (estimate.size(), truth.size());
    Ok(ensure_same_size("the estimate", e, "the ground truth", t)?)
}

/// Dense disparity of the left image by semi-global matching; invalid pixels are `inf`.
pub fn sgm(left: &GrayImage, right: &GrayImage, params: &SgmParams) -> Result<GrayImage, SgmError> {
    ensure_pair_size(left.size(), right.size())?;
    params.validate()?;
    let (w, h, nd) = (left.width, left.height, params.disparities());
    let bytes = (w * h) as u64 * nd as u64 * 2;
    if bytes > MAX_VOLUME_BYTES {
        return Err(SgmError::TooLarge {
            width: w,
            height: h,
            disparities: nd,
            bytes,
            limit: MAX_VOLUME_BYTES,
        });
    }
    let left_census = census_transform(left, params.census);
    let right_census = census_transform(right, params.census);
    let left_norm = if params.p2_gradient > 0.0 {
        let q = |p| quantile(left.data.iter().copied(), p).unwrap_or(0.0);
        let (lo, hi) = (q(0.01), q(0.99));
        let scale = if hi > lo { 1.0 / (hi - lo) } else { 1.0 };
        left.data.iter().map(|&v| v * scale).collect()
    } else {
        Vec::new()
    };
    let ctx = Ctx {
        width: w,
        height: h,
        nd,
        min_disp: params.min_disp,
        p1: params.p1,
        p2: params.p2,
        p2_gradient: params.p2_gradient,
        out_cost: params.census.bits() as u8,
        left_census: &left_census,
        right_census: &right_census,
        left_norm,
    };
    let mut sum = vec![0u16; w * h * nd];
    horizontal_paths(&ctx, &mut sum);
    let diagonals = params.paths == Paths::Eight;
    vertical_paths(&ctx, &mut sum, true, diagonals);
    vertical_paths(&ctx, &mut sum, false, diagonals);
    let disp = select(&ctx, &sum, params);
    drop(sum);
    let disp = GrayImage::from_vec(w, h, disp).map_err(|e| SgmError::Param {
        name: "size",
        reason: e.to_string(),
    })?;
    Ok(if params.median {
        median3x3(&disp)
    } else {
        disp
    })
}

/// Errors of an estimate against ground truth.
///
/// The shares of estimated pixels (`bad`, `bad_1`, `bad_2`, `bad_3`, `d1`) and the errors
/// (`mean_abs`, `rms`) are over the pixels with both a finite truth and a finite estimate;
/// `density`, `bad_all` and `below_1px` are over the pixels with a finite truth.
/// [`DisparityErrors::pooled`] combines the errors of several images pixel-weighted.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DisparityErrors {
    /// Pixels with a finite ground truth.
    pub truth_pixels: usize,
    /// Of those, the pixels with a finite estimate.
    pub valid_pixels: usize,
    /// Fraction of those with a finite estimate (density, the valid share).
    pub density: f64,
    /// Fraction of the estimated ones off by more than the threshold (bad-T).
    pub bad: f64,
    /// Fraction of all ground-truth pixels that are missing or off by more than the threshold.
    pub bad_all: f64,
    /// Fraction of the estimated ones off by more than 1 px (bad-1).
    pub bad_1: f64,
    /// Fraction of the estimated ones off by more than 2 px (bad-2).
    pub bad_2: f64,
    /// Fraction of the estimated ones off by more than 3 px (bad-3).
    pub bad_3: f64,
    /// KITTI 2015's D1: fraction of the estimated ones off by more than 3 px *and* by more
    /// than 5 % of the true disparity.
    pub d1: f64,
    /// Mean absolute error over estimated pixels (the end-point error, EPE).
    pub mean_abs: f64,
    /// Root-mean-square error over estimated pixels.
    pub rms: f64,
    /// The threshold in pixels.
    pub threshold: f32,
    /// Fraction of all ground-truth pixels whose estimate is more than 1 px *below* the truth
    /// (farther away). Over road pixels this is the phantom-hole rate: the share of the road
    /// that stereo puts beneath the road.
    pub below_1px: f64,
    /// Fraction of all ground-truth pixels off by more than 2 px once the estimate's missing
    /// values are filled as KITTI's development kit fills a sparse submission
    /// ([`background_fill`]): dense and sparse methods on one scale. Reports written before
    /// it was added read as 0.
    #[serde(default)]
    pub bad_2_filled: f64,
}

impl DisparityErrors {
    /// The errors of the union of disjoint pixel sets, from the errors of each (pixel-weighted:
    /// every pixel counts once, the KITTI convention), all with the same threshold. `None`
    /// for an empty list or differing thresholds.
    pub fn pooled(parts: &[DisparityErrors]) -> Option<DisparityErrors> {
        let threshold = parts.first()?.threshold;
        if parts.iter().any(|p| p.threshold != threshold) {
            return None;
        }
        let n: usize = parts.iter().map(|p| p.truth_pixels).sum();
        let m: usize = parts.iter().map(|p| p.valid_pixels).sum();
        // Each share times its own denominator is a count; their sums over the parts are the
        // union's counts.
        let over_valid = |f: fn(&DisparityErrors) -> f64| {
            let c: f64 = parts.iter().map(|p| f(p) * p.valid_pixels as f64).sum();
            if m > 0 {
                c / m as f64
            } else {
                0.0
            }
        };
        let over_truth = |f: fn(&DisparityErrors) -> f64| {
            let c: f64 = parts.iter().map(|p| f(p) * p.truth_pixels as f64).sum();
            if n > 0 {
                c / n as f64
            } else {
                0.0
            }
        };
        Some(DisparityErrors {
            truth_pixels: n,
            valid_pixels: m,
            density: if n > 0 { m as f64 / n as f64 } else { 0.0 },
            bad: over_valid(|p| p.bad),
            bad_all: over_truth(|p| p.bad_all),
            bad_1: over_valid(|p| p.bad_1),
            bad_2: over_valid(|p| p.bad_2),
            bad_3: over_valid(|p| p.bad_3),
            d1: over_valid(|p| p.d1),
            mean_abs: over_valid(|p| p.mean_abs),
            rms: over_valid(|p| p.rms * p.rms).sqrt(),
            threshold,
            below_1px: over_truth(|p| p.below_1px),
            bad_2_filled: over_truth(|p| p.bad_2_filled),
        })
    }
}

/// Compares an estimate with ground truth (both `inf` where there is no value).
pub fn compare_disparity(
    estimate: &GrayImage,
    truth: &GrayImage,
    threshold: f32,
) -> Result<DisparityErrors, SgmError> {
    compare_disparity_where(estimate, truth, threshold, |_| true)
}

/// [`compare_disparity`] over the pixels whose index `y * width + x` `select` accepts (for
/// example the pixels of a streak mask, or all the others).
pub fn compare_disparity_where(
    estimate: &GrayImage,
    truth: &GrayImage,
    threshold: f32,
    select: impl Fn(usize) -> bool,
) -> Result<DisparityErrors, SgmError> {
    check_against_truth(estimate, truth)?;
    let filled = background_fill(estimate);
    let (mut n, mut m, mut bad, mut sa, mut ss) = (0usize, 0usize, 0usize, 0.0f64, 0.0f64);
    let (mut below, mut over) = (0usize, [0usize; 3]);
    let (mut d1, mut bad_filled) = (0usize, 0usize);
    for (i, (&e, &t)) in estimate.data.iter().zip(&truth.data).enumerate() {
        if !t.is_finite() || !select(i) {
            continue;
        }
        n += 1;
        let f = filled.data[i];
        bad_filled += usize::from(!(f.is_finite() && (f - t).abs() <= 2.0));
        if !e.is_finite() {
            continue;
        }
        m += 1;
        let err = (e - t).abs() as f64;
        if err > threshold as f64 {
            bad += 1;
        }
        below += usize::from(e < t - 1.0);
        for (k, c) in over.iter_mut().enumerate() {
            *c += usize::from(err > (k + 1) as f64);
        }
        d1 += usize::from(err > 3.0 && err > 0.05 * t.abs() as f64);
        sa += err;
        ss += err * err;
    }
    let frac = |a: usize, b: usize| if b > 0 { a as f64 / b as f64 } else { 0.0 };
    Ok(DisparityErrors {
        truth_pixels: n,
        valid_pixels: m,
        density: frac(m, n),
        bad: frac(bad, m),
        bad_all: frac(bad + n - m, n),
        bad_1: frac(over[0], m),
        bad_2: frac(over[1], m),
        bad_3: frac(over[2], m),
        d1: frac(d1, m),
        mean_abs: if m > 0 { sa / m as f64 } else { 0.0 },
        rms: if m > 0 { (ss / m as f64).sqrt() } else { 0.0 },
        threshold,
        below_1px: frac(below, n),
        bad_2_filled: frac(bad_filled, n),
    })
}

/// The estimate with its missing values (not finite) filled as KITTI's development kit fills
/// a sparse submission before scoring it (`interpolateBackground`): along each row, a gap
/// between two values takes the smaller of them (the background's); a row's ends take its
/// first and last value; then a column's ends take its first and last value. A pixel of a row
/// without any value that lies between rows with values stays missing.
pub fn background_fill(estimate: &GrayImage) -> GrayImage {
    let (w, h) = (estimate.width, estimate.height);
    let mut out = estimate.clone();
    for row in out.data.chunks_exact_mut(w) {
        let mut last: Option<usize> = None;
        for u in 0..w {
            if !row[u].is_finite() {
                continue;
            }
            if let Some(l) = last {
                if u > l + 1 {
                    let d = row[l].min(row[u]);
                    row[l + 1..u].fill(d);
                }
            }
            last = Some(u);
        }
        if let (Some(first), Some(l)) = (row.iter().position(|v| v.is_finite()), last) {
            let (a, b) = (row[first], row[l]);
            row[..first].fill(a);
            row[l + 1..].fill(b);
        }
    }
    for u in 0..w {
        let valid = |v: &usize| out.data[v * w + u].is_finite();
        if let (Some(top), Some(bottom)) = ((0..h).find(valid), (0..h).rev().find(valid)) {
            let (a, b) = (out.data[top * w + u], out.data[bottom * w + u]);
            for v in 0..top {
                out.data[v * w + u] = a;
            }
            for v in bottom + 1..h {
                out.data[v * w + u] = b;
            }
        }
    }
    out
}

/// A colour preview of a disparity map (turbo colour map over `range`, or over the 1-99 %
/// range of the finite values; invalid pixels black).
pub fn disparity_preview(disp: &GrayImage, range: Option<(f32, f32)>) -> image::RgbImage {
    let q = |p| quantile(disp.data.iter().copied(), p).unwrap_or(0.0);
    let (lo, hi) = range.unwrap_or_else(|| (q(0.01), q(0.99)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    image::RgbImage::from_fn(disp.width as u32, disp.height as u32, |x, y| {
        let d = disp.get(x as usize, y as usize);
        if !d.is_finite() {
            return image::Rgb([0, 0, 0]);
        }
        let t = ((d - lo) / span).clamp(0.0, 1.0);
        image::Rgb(turbo(t))
    })
}

/// Writes [`disparity_preview`] as a PNG, through a temporary file renamed into place.
pub fn write_disparity_png(
    path: &std::path::Path,
    disp: &GrayImage,
    range: Option<(f32, f32)>,
) -> Result<(), ImageError> {
    streaks_image::png::write_png_buffer(path, &disparity_preview(disp, range))
}

/// Google's turbo colour map (the polynomial approximation by Mikhailov, 2019).
fn turbo(t: f32) -> [u8; 3] {
    let t = t as f64;
    let (t2, t3, t4, t5) = (t * t, t * t * t, t * t * t * t, t * t * t * t * t);
    let r = 0.13572138 + 4.61539260 * t - 42.66032258 * t2 + 132.13108234 * t3 - 152.94239396 * t4
        + 59.28637943 * t5;
    let g = 0.09140261 + 2.19418839 * t + 4.84296658 * t2 - 14.18503333 * t3
        + 4.27729857 * t4
        + 2.82956604 * t5;
    let b = 0.10667330 + 12.64194608 * t - 60.58204836 * t2 + 110.36276771 * t3 - 89.90310912 * t4
        + 27.34824973 * t5;
    let c = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    [c(r), c(g), c(b)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::SynthScene;

    fn run(scene: &SynthScene, params: &SgmParams) -> DisparityErrors {
        let pair = scene.render().unwrap();
        let disp = sgm(&pair.left, &pair.right, params).unwrap();
        compare_disparity(&disp, &pair.disparity, 2.0).unwrap()
    }

    #[test]
    fn textured_pair_is_matched() {
        let scene = SynthScene::textured(256, 160, 11);
        let params = SgmParams {
            max_disp: 47,
            ..SgmParams::default()
        };
        let e = run(&scene, &params);
        eprintln!("SGM 8 paths, 7x7 census, 256x160: {e:?}");
        assert!(
            e.bad < 0.05 && e.mean_abs < 0.5 && e.density > 0.85,
            "{e:?}"
        );
    }

    #[test]
    fn exposure_difference_noise_and_four_paths() {
        let scene = SynthScene {
            gain: 0.6,
            offset: 0.1,
            noise: 0.01,
            ..SynthScene::textured(256, 160, 12)
        };
        let params = SgmParams {
            max_disp: 47,
            paths: Paths::Four,
            census: Census::Census5x5,
            p1: 4,
            p2: 43,
            p2_gradient: 4.0,
            ..SgmParams::default()
        };
        let e = run(&scene, &params);
        eprintln!("SGM 4 paths, 5x5 census, gain 0.6, noise 0.01: {e:?}");
        assert!(e.bad < 0.06 && e.mean_abs < 0.9 && e.density > 0.8, "{e:?}");
    }

    #[test]
    fn negative_disparities() {
        let scene = SynthScene {
            boxes: vec![],
            disparity_top: -6.3,
            disparity_bottom: -2.2,
            ..SynthScene::textured(160, 96, 13)
        };
        let params = SgmParams {
            min_disp: -16,
            max_disp: 15,
            ..SgmParams::default()
        };
        let e = run(&scene, &params);
        assert!(e.bad < 0.03 && e.mean_abs < 0.3 && e.density > 0.9, "{e:?}");
    }

    #[test]
    fn median_keeps_invalid_pixels_and_bad_input_is_an_error() {
        let mut img = GrayImage::new(3, 3, 1.0).unwrap();
        img.set(1, 1, 9.0);
        img.set(0, 0, f32::INFINITY);
        let m = median3x3(&img);
        assert_eq!(m.get(1, 1), 1.0);
        assert!(m.get(0, 0).is_infinite());
        let small = GrayImage::new(3, 2, 0.0).unwrap();
        assert!(sgm(&img, &small, &SgmParams::default()).is_err());
        let p = SgmParams {
            p1: 100,
            p2: 10,
            ..SgmParams::default()
        };
        assert!(sgm(&img, &img, &p).is_err());
        assert!(compare_disparity(&img, &small, 2.0).is_err());
        let preview = disparity_preview(&img, None);
        assert_eq!(preview.get_pixel(0, 0).0, [0, 0, 0]);
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("d.png");
        write_disparity_png(&png, &img, Some((0.0, 10.0))).unwrap();
        assert_eq!(::image::open(&png).unwrap().width(), 3);
        assert!(write_disparity_png(&dir.path().join("no/d.png"), &img, None).is_err());
    }

    #[test]
    fn errors_against_truth_count_only_the_selected_pixels() {
        // Truth 5 everywhere but one pixel without a surface; the estimate is right on the left
        // half, 3 px off on the right half, and missing at one pixel.
        let mut truth = GrayImage::new(4, 2, 5.0).unwrap();
        truth.set(0, 1, f32::INFINITY);
        let mut est = GrayImage::new(4, 2, 5.0).unwrap();
        for y in 0..2 {
            est.set(2, y, 8.0);
            est.set(3, y, 8.0);
        }
        est.set(1, 0, f32::INFINITY);
        let all = compare_disparity(&est, &truth, 2.0).unwrap();
        assert_eq!(all.truth_pixels, 7);
        assert!((all.density - 6.0 / 7.0).abs() < 1e-12);
        assert!((all.bad - 4.0 / 6.0).abs() < 1e-12);
        assert!((all.bad_all - 5.0 / 7.0).abs() < 1e-12);
        assert!((all.mean_abs - 2.0).abs() < 1e-6);
        let right = compare_disparity_where(&est, &truth, 2.0, |i| i % 4 >= 2).unwrap();
        assert_eq!(
            (right.truth_pixels, right.bad, right.mean_abs),
            (4, 1.0, 3.0)
        );
        let left = compare_disparity_where(&est, &truth, 2.0, |i| i % 4 < 2).unwrap();
        assert_eq!(left.truth_pixels, 3);
        assert_eq!(
            (left.density, left.bad, left.mean_abs),
            (2.0 / 3.0, 0.0, 0.0)
        );
        let none = compare_disparity_where(&est, &truth, 2.0, |_| false).unwrap();
        assert_eq!((none.truth_pixels, none.density), (0, 0.0));
    }

    #[test]
    fn bad_thresholds_d1_and_pooling_count_pixels() {
        // Truth 10 everywhere but one 100 px pixel; errors 0, 1.5, 2.5, 4 (on 10: D1) and 4
        // (on 100: under 5 %, not D1), one missing estimate, one pixel without truth.
        let truth = GrayImage::from_vec(
            7,
            1,
            vec![10.0, 10.0, 10.0, 10.0, 100.0, 10.0, f32::INFINITY],
        )
        .unwrap();
        let est = GrayImage::from_vec(7, 1, vec![10.0, 11.5, 7.5, 6.0, 96.0, f32::INFINITY, 3.0])
            .unwrap();
        let e = compare_disparity(&est, &truth, 2.0).unwrap();
        assert_eq!((e.truth_pixels, e.valid_pixels), (6, 5));
        assert_eq!((e.bad_1, e.bad_2, e.bad_3), (0.8, 0.6, 0.4));
        assert_eq!(e.bad, e.bad_2);
        assert_eq!(e.d1, 0.2);
        assert_eq!(e.mean_abs, (1.5 + 2.5 + 4.0 + 4.0) / 5.0);
        // Below by more than 1 px: 7.5, 6 and 96, of 6 truth pixels.
        assert_eq!(e.below_1px, 0.5);
        // Filled as KITTI fills: the missing value takes the smaller neighbour, 3 (7 px off).
        assert_eq!(e.bad_2_filled, 4.0 / 6.0);
        // Pooling the two halves gives the whole.
        let a = compare_disparity_where(&est, &truth, 2.0, |i| i < 3).unwrap();
        let b = compare_disparity_where(&est, &truth, 2.0, |i| i >= 3).unwrap();
        let p = DisparityErrors::pooled(&[a, b]).unwrap();
        assert_eq!((p.truth_pixels, p.valid_pixels), (6, 5));
        for (x, y) in [
            (p.density, e.density),
            (p.bad_1, e.bad_1),
            (p.bad_3, e.bad_3),
            (p.d1, e.d1),
            (p.mean_abs, e.mean_abs),
            (p.rms, e.rms),
            (p.bad_all, e.bad_all),
            (p.below_1px, e.below_1px),
            (p.bad_2_filled, e.bad_2_filled),
        ] {
            assert!((x - y).abs() < 1e-12, "{p:?} against {e:?}");
        }
        assert!(DisparityErrors::pooled(&[]).is_none());
        let other = compare_disparity(&est, &truth, 3.0).unwrap();
        assert!(DisparityErrors::pooled(&[a, other]).is_none());
    }

    #[test]
    fn background_fill_is_kittis() {
        let n = f32::INFINITY;
        #[rustfmt::skip]
        let est = GrayImage::from_vec(5, 4, vec![
            n, 4.0, n, n, 6.0, // a gap takes the smaller side; the row's start its first value
            n, n, n, n, n,     // no value: stays missing between rows with values
            2.0, n, 9.0, n, n, // the row's end takes its last value
            n, n, n, n, n,     // below the last row with values: the column's last value
        ]).unwrap();
        let f = background_fill(&est);
        #[rustfmt::skip]
        let want = [
            4.0, 4.0, 4.0, 4.0, 6.0,
            n, n, n, n, n,
            2.0, 2.0, 9.0, 9.0, 9.0,
            2.0, 2.0, 9.0, 9.0, 9.0,
        ];
        assert_eq!(f.data, want);
        let empty = GrayImage::new(3, 2, n).unwrap();
        assert!(background_fill(&empty).data.iter().all(|v| v.is_infinite()));
    }

    /// Timing of a megapixel pair: `cargo test --release -p streaks-analysis -- --ignored
    /// --nocapture megapixel` (RAYON_NUM_THREADS sets the threads).
    #[test]
    #[ignore]
    fn megapixel_timing() {
        let scene = SynthScene::textured(1280, 800, 21);
        let pair = scene.render().unwrap();
        for (max_disp, paths) in [(63, Paths::Eight), (127, Paths::Eight), (63, Paths::Four)] {
            let params = SgmParams {
                max_disp,
                paths,
                ..SgmParams::default()
            };
            let t = std::time::Instant::now();
            let disp = sgm(&pair.left, &pair.right, &params).unwrap();
            let secs = t.elapsed().as_secs_f64();
            let e = compare_disparity(&disp, &pair.disparity, 2.0).unwrap();
            eprintln!(
                "SGM 1280x800, D={} {paths:?}: {secs:.2} s, {e:?}",
                max_disp + 1
            );
        }
    }
}
