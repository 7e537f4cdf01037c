//! Specular streak detection: bright, vertically elongated regions below the horizon.
//!
//! 1. **Thresholds relative to the local background** (robust to exposure and to a road that
//!    is brighter in some rows than others): the image is smoothed with a small box filter;
//!    per row, the background `b` is the row's median and the noise `s` its MAD-based standard
//!    deviation (at least `noise_floor` of the brightest contrasts below the horizon). Pixels above `b + low s` are candidates, and a region is kept only if it
//!    reaches `b + high s` (hysteresis). Within a streak, each row keeps the pixels whose
//!    contrast `v - b` is at least `row_fraction` of the row's peak contrast (the streak's
//!    cross-section, not the glow around it).
//! 2. **Regions** are 8-connected, but never across the horizon (given, or the principal
//!    point's row, the image centre, for a pitch-0 rig): a street lamp above the horizon and its
//!    streak below it come apart. A region below the horizon is further **cut at brightness
//!    gaps**: a row whose peak is below `gap` times the smaller of the peaks above and below it
//!    (a low headlight and its streak), and a bright compact **head** is split off its top
//!    (leading rows brighter than `head_ratio` times the region's median row peak).
//! 3. **Classification**: a region spanning at least `min_rows` rows and `min_elongation` times
//!    taller than its mean width is a streak; a region below the horizon, at least `min_rows`
//!    tall, that reaches the bottom row of the image is a **glow**, the near end of a reflection that widens as the road comes
//!    closer (a lamp cannot appear there: it would have to be a light a metre or two in front
//!    of the camera), and its pixels join the streak mask; the others are lamps.
//! 4. **Per streak**: its centre per row (intensity-weighted, weights above the low threshold),
//!    the axis `x = a + b y` fitted to the centres (weighted least squares), row extent, peak,
//!    elongation.
//!
//! [`score_mask`] compares a detection mask with a ground-truth mask (precision and recall).
//! Coordinates follow docs/design.md: image x and y with pixel centres at `i + 0.5`; rows are indices.

use crate::filter::{median, Axis};
use streaks_image::stats::quantile_in;
use streaks_image::{ensure_same_size, GrayImage, SizeMismatch};

/// Errors of streak detection.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DetectError {
    /// A parameter is out of range.
    #[error("invalid streak detection parameter {name}: {reason}")]
    Param {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: &'static str,
    },
    /// Two masks differ in size.
    #[error(transparent)]
    SizeMismatch(#[from] SizeMismatch),
}

/// Parameters of the detector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectParams {
    /// Image y coordinate of the horizon; `None`: the image centre (pitch-0 rig).
    pub horizon: Option<f32>,
    /// Radius of the box filter applied before thresholding, pixels (0: none).
    pub smooth_radius: usize,
    /// Width of the horizontal window whose median is a pixel's background, as a share of the
    /// image width (0: the whole row). A streak narrower than half the window does not raise
    /// its own background; facades and pavements beside the road do not raise the road's.
    pub background_width: f32,
    /// High (seed) threshold in noise deviations above the row's background.
    pub high: f32,
    /// Low (growth) threshold, likewise.
    pub low: f32,
    /// Least noise deviation, as a share of the 99.9th percentile of the contrasts below the
    /// horizon: keeps the thresholds finite on noise-free (black-background) images.
    pub noise_floor: f32,
    /// Share of a row's peak contrast a streak pixel must reach (0 keeps all grown pixels).
    pub row_fraction: f32,
    /// Brightness-gap ratio for cutting a region (0 disables).
    pub gap: f32,
    /// A region's leading rows brighter than this many times its median row peak, if compact,
    /// are a lamp touching its streak (0 disables).
    pub head_ratio: f32,
    /// Fewest rows of a streak.
    pub min_rows: usize,
    /// Smallest ratio of height to mean width of a streak.
    pub min_elongation: f32,
    /// Largest |slope| (pixels of x per pixel of y) of a streak's axis: streaks of a level rig
    /// hang nearly vertically; a steeper elongated region is a lane marking or a kerb, and
    /// is dropped.
    pub max_slope: f32,
}

impl Default for DetectParams {
    fn default() -> Self {
        Self {
            horizon: None,
            smooth_radius: 1,
            background_width: 0.25,
            high: 6.0,
            low: 3.0,
            row_fraction: 0.5,
            noise_floor: 0.01,
            gap: 0.5,
            head_ratio: 2.0,
            min_rows: 8,
            min_elongation: 2.0,
            max_slope: 0.5,
        }
    }
}

impl DetectParams {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), DetectError> {
        let bad = |name, reason| Err(DetectError::Param { name, reason });
        if !(self.low > 0.0 && self.low <= self.high && self.high.is_finite()) {
            return bad("low", "need 0 < low <= high, finite");
        }
        if !(0.0..1.0).contains(&self.row_fraction) {
            return bad("row_fraction", "must be in [0, 1)");
        }
        if !(0.0..1.0).contains(&self.noise_floor) {
            return bad("noise_floor", "must be in [0, 1)");
        }
        if !(0.0..=1.0).contains(&self.background_width) {
            return bad("background_width", "must be in [0, 1]");
        }
        if self.smooth_radius > 16 {
            return bad("smooth_radius", "must be at most 16");
        }
        if self.head_ratio.is_nan() || self.head_ratio < 0.0 {
            return bad("head_ratio", "must be non-negative");
        }
        if !(0.0..1.0).contains(&self.gap) {
            return bad("gap", "must be in [0, 1)");
        }
        if self.horizon.is_some_and(|h| !h.is_finite()) {
            return bad("horizon", "must be a finite number");
        }
        if self.max_slope.is_nan() || self.max_slope < 0.0 {
            return bad("max_slope", "must be non-negative");
        }
        if self.min_elongation.is_nan() || self.min_elongation < 0.0 {
            return bad("min_elongation", "must be non-negative");
        }
        Ok(())
    }
}

/// A detected streak.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Streak {
    /// First row (index).
    pub first_row: usize,
    /// Last row (index, inclusive).
    pub last_row: usize,
    /// Per row: (row index, intensity-weighted centre as an image x coordinate).
    pub centres: Vec<(usize, f32)>,
    /// Axis `x = a + b y` (image coordinates): `a`.
    pub axis_a: f32,
    /// Axis slope `b` (pixels of x per pixel of y).
    pub axis_b: f32,
    /// Highest intensity.
    pub peak: f32,
    /// Rows spanned divided by the mean width in pixels.
    pub elongation: f32,
    /// Number of pixels.
    pub pixels: usize,
}

/// A bright compact region (a lamp, a headlight).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Lamp {
    /// Intensity-weighted centre, image x.
    pub x: f32,
    /// Intensity-weighted centre, image y.
    pub y: f32,
    /// Highest intensity.
    pub peak: f32,
    /// Number of pixels.
    pub pixels: usize,
}

/// The result of [`detect_streaks`].
#[derive(Clone, Debug, PartialEq)]
pub struct Detection {
    /// Streaks, by first row.
    pub streaks: Vec<Streak>,
    /// Lamps.
    pub lamps: Vec<Lamp>,
    /// Glows: bright regions below the horizon, at least `min_rows` tall but not elongated,
    /// reaching the bottom row (their pixels are in `mask`; LK does not follow them).
    pub glows: Vec<Lamp>,
    /// 1 on streak pixels, 0 elsewhere.
    pub mask: GrayImage,
    /// The horizon used (image y).
    pub horizon: f32,
    /// The low and high thresholds used, as contrasts above the background, medians over the
    /// rows below the horizon.
    pub thresholds: (f32, f32),
}

/// `img` smoothed with a `(2 r + 1)`-square box filter (clamped at the borders); non-finite
/// values count as 0.
fn box_blur(img: &GrayImage, r: usize) -> GrayImage {
    let (w, h) = (img.width, img.height);
    let mut out = img.clone();
    for v in &mut out.data {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    if r == 0 {
        return out;
    }
    let mut tmp = vec![0.0f32; w * h];
    let mut prefix = vec![0.0f64; w.max(h) + 1];
    for y in 0..h {
        for x in 0..w {
            prefix[x + 1] = prefix[x] + out.data[y * w + x] as f64;
        }
        for x in 0..w {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
            tmp[y * w + x] = ((prefix[x1] - prefix[x0]) / (x1 - x0) as f64) as f32;
        }
    }
    for x in 0..w {
        for y in 0..h {
            prefix[y + 1] = prefix[y] + tmp[y * w + x] as f64;
        }
        for y in 0..h {
            let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
            out.data[y * w + x] = ((prefix[y1] - prefix[y0]) / (y1 - y0) as f64) as f32;
        }
    }
    out
}

/// Each pixel's contrast above its background, and per row the low and high thresholds.
struct RowThresholds {
    contrast: Vec<f32>,
    lo: Vec<f32>,
    hi: Vec<f32>,
}

/// Each pixel's value minus the median of its row's window of `share` times the image width
/// (odd, at least 3 pixels; clipped at the image's sides; 0: the whole row), row-major.
fn local_contrast(img: &GrayImage, share: f32, buf: &mut Vec<f32>) -> Vec<f32> {
    let (w, h) = (img.width, img.height);
    let mut out = vec![0.0f32; w * h];
    if share <= 0.0 {
        for (row, o) in img.data.chunks_exact(w).zip(out.chunks_exact_mut(w)) {
            let b = quantile_in(row.iter().copied(), 0.5, buf).unwrap_or(0.0);
            for (o, &v) in o.iter_mut().zip(row) {
                *o = v - b;
            }
        }
        return out;
    }
    let r = ((share * w as f32 / 2.0).round() as usize).max(1);
    let background = median(img, Axis::Rows, r);
    for ((o, &v), &b) in out.iter_mut().zip(&img.data).zip(&background.data) {
        *o = v - b;
    }
    out
}

/// Finds streaks and lamps in `img`.
pub fn detect_streaks(img: &GrayImage, params: &DetectParams) -> Result<Detection, DetectError> {
    params.validate()?;
    let (w, h) = (img.width, img.height);
    let horizon = params.horizon.unwrap_or(0.5 * h as f32);
    // Rows with centre below the horizon (y + 0.5 > horizon) are "below".
    let below = |y: usize| y as f32 + 0.5 > horizon;
    let mut mask = GrayImage::new(w, h, 0.0).map_err(|_| DetectError::Param {
        name: "image",
        reason: "empty image",
    })?;
    let img = &box_blur(img, params.smooth_radius);
    let mut buf = Vec::with_capacity(w);
    let mut th = RowThresholds {
        contrast: local_contrast(img, params.background_width, &mut buf),
        lo: vec![f32::INFINITY; h],
        hi: vec![f32::INFINITY; h],
    };
    let mut noise = vec![0.0f32; h];
    let mut dev = vec![0.0f32; w];
    for (row, n) in th.contrast.chunks_exact(w).zip(&mut noise) {
        let m = quantile_in(row.iter().copied(), 0.5, &mut buf).unwrap_or(0.0);
        for (d, &c) in dev.iter_mut().zip(row) {
            *d = (c - m).abs();
        }
        *n = 1.4826 * quantile_in(dev.iter().copied(), 0.5, &mut buf).unwrap_or(0.0);
    }
    // The floor: a share of the brightest contrasts below the horizon (lamps above it, however
    // bright, do not raise it).
    let contrasts = (0..w * h).filter(|&i| below(i / w)).map(|i| th.contrast[i]);
    let floor = params.noise_floor
        * quantile_in(contrasts, 0.999, &mut buf)
            .unwrap_or(0.0)
            .max(0.0);
    for ((n, lo), hi) in noise.iter().zip(&mut th.lo).zip(&mut th.hi) {
        let s = n.max(floor);
        if s > 0.0 {
            *lo = params.low * s;
            *hi = params.high * s;
        }
    }
    let rows_below: Vec<usize> = (0..h).filter(|&y| below(y)).collect();
    let med_of = |v: &[f32], buf: &mut Vec<f32>| {
        quantile_in(rows_below.iter().map(|&y| v[y]), 0.5, buf).unwrap_or(0.0)
    };
    let thresholds = (med_of(&th.lo, &mut buf), med_of(&th.hi, &mut buf));
    let mut det = Detection {
        streaks: Vec::new(),
        lamps: Vec::new(),
        glows: Vec::new(),
        mask: mask.clone(),
        horizon,
        thresholds,
    };
    let on = |i: usize| th.contrast[i] >= th.lo[i / w];
    let mut label = vec![false; w * h];
    let mut stack = Vec::new();
    let mut region: Vec<usize> = Vec::new();
    for start in 0..w * h {
        if label[start] || !on(start) {
            continue;
        }
        // Flood fill (8-connected, not across the horizon).
        region.clear();
        label[start] = true;
        stack.push(start);
        while let Some(i) = stack.pop() {
            region.push(i);
            let (x, y) = (i % w, i / w);
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                if below(ny) != below(y) {
                    continue;
                }
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    let j = ny * w + nx;
                    if !label[j] && on(j) {
                        label[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        region.sort_unstable();
        if below(start / w) {
            for part in split_at_gaps(img, &region, params.gap) {
                let (head, rest) = split_head(img, part, params.head_ratio);
                for p in [head, rest] {
                    classify(img, p, &th, params, &mut det, &mut mask);
                }
            }
        } else {
            classify(img, &region, &th, params, &mut det, &mut mask);
        }
    }
    det.streaks.sort_by_key(|s| (s.first_row, s.pixels));
    det.mask = mask;
    Ok(det)
}

/// Cuts a region (pixel indices sorted by row) at rows whose peak is below `gap` times the
/// smaller of the highest peaks above and below; the cut rows are dropped.
fn split_at_gaps<'a>(img: &GrayImage, region: &'a [usize], gap: f32) -> Vec<&'a [usize]> {
    let w = img.width;
    // Row starts within `region`.
    let mut rows: Vec<(usize, usize, f32)> = Vec::new(); // (row, start index, peak)
    for (k, &i) in region.iter().enumerate() {
        let y = i / w;
        match rows.last_mut() {
            Some(r) if r.0 == y => r.2 = r.2.max(img.data[i]),
            _ => rows.push((y, k, img.data[i])),
        }
    }
    let n = rows.len();
    let mut above_max = vec![0.0f32; n];
    let mut below_max = vec![0.0f32; n];
    for k in 1..n {
        above_max[k] = above_max[k - 1].max(rows[k - 1].2);
        below_max[n - 1 - k] = below_max[n - k].max(rows[n - k].2);
    }
    let mut parts = Vec::new();
    let mut part_start = Some(0usize);
    for k in 0..n {
        let end = if k + 1 < n {
            rows[k + 1].1
        } else {
            region.len()
        };
        let cut = gap > 0.0 && rows[k].2 < gap * above_max[k].min(below_max[k]);
        if cut {
            if let Some(s) = part_start.take() {
                if rows[k].1 > s {
                    parts.push(&region[s..rows[k].1]);
                }
            }
        } else if part_start.is_none() {
            part_start = Some(rows[k].1);
        }
        if k + 1 == n {
            if let Some(s) = part_start {
                parts.push(&region[s..end]);
            }
        }
    }
    parts
}

/// Splits off a bright compact head (a lamp touching the top of its streak): rows rising to a
/// run of rows whose peak exceeds `ratio` times the median row peak, and the falling tail
/// after it, if they are at most twice as many as their widest row is wide. Returns (head, rest); the head may be empty.
fn split_head<'a>(img: &GrayImage, region: &'a [usize], ratio: f32) -> (&'a [usize], &'a [usize]) {
    let w = img.width;
    if ratio <= 0.0 || region.is_empty() {
        return (&[], region);
    }
    // (start index, peak, width) per row.
    let mut rows: Vec<(usize, f32, usize)> = Vec::new();
    let mut last_row = usize::MAX;
    for (k, &i) in region.iter().enumerate() {
        if i / w != last_row {
            last_row = i / w;
            rows.push((k, img.data[i], 0));
        }
        let r = rows.last_mut().expect("a row was pushed");
        r.1 = r.1.max(img.data[i]);
        r.2 += 1;
    }
    let mut peaks: Vec<f32> = rows.iter().map(|r| r.1).collect();
    let mid = peaks.len() / 2;
    let median = *peaks.select_nth_unstable_by(mid, f32::total_cmp).1;
    // The first bright row must be the top of a blob (peaks rising to it), the head runs
    // through the bright rows and on down the blob's falling tail.
    let Some(first_bright) = rows.iter().position(|r| r.1 > ratio * median) else {
        return (&[], region);
    };
    if rows[..=first_bright].windows(2).any(|p| p[1].1 < p[0].1) {
        return (&[], region);
    }
    let mut head_rows = first_bright;
    while head_rows < rows.len() && rows[head_rows].1 > ratio * median {
        head_rows += 1;
    }
    while head_rows + 1 < rows.len() && rows[head_rows + 1].1 < rows[head_rows].1 {
        head_rows += 1;
    }
    if head_rows + 1 >= rows.len() {
        return (&[], region);
    }
    let widest = rows[..head_rows].iter().map(|r| r.2).max().unwrap_or(0);
    if head_rows > 2 * widest {
        return (&[], region);
    }
    region.split_at(rows[head_rows].0)
}

/// The cross-section of a region's row (pixel indices of one row, by column): the run of
/// pixels at least `keep` in contrast, without gaps wider than one pixel, that holds the row's
/// brightest pixel. A lane marking or a second reflection that touches the streak in the same
/// row is separated from it by darker road, and is left out.
fn cross_section<'a>(
    row: &'a [usize],
    w: usize,
    contrast: &impl Fn(usize) -> f32,
    keep: f32,
) -> &'a [usize] {
    let Some(peak) = (0..row.len()).max_by(|&a, &b| contrast(row[a]).total_cmp(&contrast(row[b])))
    else {
        return row;
    };
    let joined = |a: usize, b: usize| row[b] % w - row[a] % w <= 2 && contrast(row[b]) >= keep;
    let (mut lo, mut hi) = (peak, peak + 1);
    while lo > 0 && joined(lo - 1, lo) && contrast(row[lo - 1]) >= keep {
        lo -= 1;
    }
    while hi < row.len() && joined(hi - 1, hi) {
        hi += 1;
    }
    &row[lo..hi]
}

/// Measures a region and records it as a streak (below the horizon, elongated) or a lamp.
fn classify(
    img: &GrayImage,
    region: &[usize],
    th: &RowThresholds,
    params: &DetectParams,
    det: &mut Detection,
    mask: &mut GrayImage,
) {
    let w = img.width;
    let contrast = |i: usize| th.contrast[i];
    let peak = region.iter().map(|&i| img.data[i]).fold(f32::MIN, f32::max);
    if region.is_empty() || !region.iter().any(|&i| contrast(i) >= th.hi[i / w]) {
        return;
    }
    let first_row = region[0] / w;
    let last_row = region[region.len() - 1] / w;
    let nrows = last_row - first_row + 1;
    let mean_width = region.len() as f32 / nrows as f32;
    let elongation = nrows as f32 / mean_width;
    let below = first_row as f32 + 0.5 > det.horizon;
    let glow = below && last_row + 1 == img.height && nrows >= params.min_rows;
    if !below || nrows < params.min_rows || elongation < params.min_elongation {
        let (mut sw, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
        for &i in region {
            let wgt = (contrast(i) - th.lo[i / w]).max(0.0) as f64 + 1e-12;
            sw += wgt;
            sx += wgt * ((i % w) as f64 + 0.5);
            sy += wgt * ((i / w) as f64 + 0.5);
        }
        let lamp = Lamp {
            x: (sx / sw) as f32,
            y: (sy / sw) as f32,
            peak,
            pixels: region.len(),
        };
        if glow {
            // The pixels of each row within `row_fraction` of its peak contrast, as a streak's.
            let mut k = 0;
            while k < region.len() {
                let y = region[k] / w;
                let end = k + region[k..].iter().take_while(|&&i| i / w == y).count();
                let row = &region[k..end];
                let keep =
                    params.row_fraction * row.iter().map(|&i| contrast(i)).fold(0.0, f32::max);
                for &i in cross_section(row, w, &contrast, keep) {
                    mask.data[i] = 1.0;
                }
                k = end;
            }
            det.glows.push(lamp);
        } else {
            det.lamps.push(lamp);
        }
        return;
    }
    // Per-row weighted centres, then the weighted line fit x = a + b y.
    let mut centres = Vec::with_capacity(nrows);
    let mut kept = Vec::with_capacity(region.len());
    let r = params.smooth_radius;
    let (mut s, mut sy, mut sx, mut syy, mut sxy) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
    let mut k = 0;
    while k < region.len() {
        let y = region[k] / w;
        let end = k + region[k..].iter().take_while(|&&i| i / w == y).count();
        // The smoothing spreads a streak's ends by its radius.
        if y < first_row + r || y + r > last_row {
            k = end;
            continue;
        }
        let row_peak = region[k..end]
            .iter()
            .map(|&i| contrast(i))
            .fold(0.0f32, f32::max);
        let keep = params.row_fraction * row_peak;
        let (mut rw, mut rx) = (0.0f64, 0.0f64);
        for &i in cross_section(&region[k..end], w, &contrast, keep) {
            let c = contrast(i);
            let wgt = (c - keep) as f64 + 1e-12;
            rw += wgt;
            rx += wgt * ((i % w) as f64 + 0.5);
            kept.push(i);
        }
        k = end;
        let xc = rx / rw;
        let yc = y as f64 + 0.5;
        centres.push((y, xc as f32));
        s += rw;
        sy += rw * yc;
        sx += rw * xc;
        syy += rw * yc * yc;
        sxy += rw * xc * yc;
    }
    let den = s * syy - sy * sy;
    let b = if den > 0.0 {
        (s * sxy - sx * sy) / den
    } else {
        0.0
    };
    let a = (sx - b * sy) / s;
    if b.abs() > params.max_slope as f64 {
        return;
    }
    for &i in &kept {
        mask.data[i] = 1.0;
    }
    det.streaks.push(Streak {
        first_row: first_row + r,
        last_row: last_row - r,
        centres,
        axis_a: a as f32,
        axis_b: b as f32,
        peak,
        elongation,
        pixels: kept.len(),
    });
}

/// Precision and recall of a detection mask against a ground-truth mask.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct MaskScore {
    /// Detected pixels that are true streak pixels, as a fraction of the detected ones.
    pub precision: f64,
    /// True streak pixels detected, as a fraction of the true ones.
    pub recall: f64,
    /// Harmonic mean of the two.
    pub f1: f64,
    /// Detected pixels.
    pub detected: usize,
    /// True pixels.
    pub truth: usize,
    /// Pixels both detected and true.
    pub true_positives: usize,
}

impl MaskScore {
    /// The score of `true_positives` hits among `detected` detections of `truth` true pixels
    /// (precision and recall are 0 when their denominator is).
    pub fn from_counts(true_positives: usize, detected: usize, truth: usize) -> Self {
        let precision = if detected > 0 {
            true_positives as f64 / detected as f64
        } else {
            0.0
        };
        let recall = if truth > 0 {
            true_positives as f64 / truth as f64
        } else {
            0.0
        };
        let f1 = if precision + recall > 0.0 {
            2.0 * precision * recall / (precision + recall)
        } else {
            0.0
        };
        Self {
            precision,
            recall,
            f1,
            detected,
            truth,
            true_positives,
        }
    }

    /// The pixel-pooled score of several images: their counts summed, so that each pixel
    /// weighs the same (an image without streaks adds only its false detections).
    pub fn pooled<'a>(scores: impl IntoIterator<Item = &'a MaskScore>) -> Self {
        let (mut tp, mut nd, mut nt) = (0, 0, 0);
        for s in scores {
            tp += s.true_positives;
            nd += s.detected;
            nt += s.truth;
        }
        Self::from_counts(tp, nd, nt)
    }
}

/// Scores `detected` against `truth` (a pixel is "on" when its value exceeds 0.5).
pub fn score_mask(detected: &GrayImage, truth: &GrayImage) -> Result<MaskScore, DetectError> {
    ensure_same_size(
        "the detected mask",
        detected.size(),
        "the true mask",
        truth.size(),
    )?;
    let (mut tp, mut nd, mut nt) = (0usize, 0usize, 0usize);
    for (&d, &t) in detected.data.iter().zip(&truth.data) {
        let (d, t) = (d > 0.5, t > 0.5);
        nd += d as usize;
        nt += t as usize;
        tp += (d && t) as usize;
    }
    Ok(MaskScore::from_counts(tp, nd, nt))
}

/// The part of a ground-truth streak mask the detector is meant to find: "on" pixels (above
/// 0.5) below `horizon` (pixel centre below it) in 8-connected components taller than wide.
/// Glints on windows above the horizon and wide glossy patches are left out.
pub fn vertical_truth(truth: &GrayImage, horizon: f32) -> GrayImage {
    let (w, h) = (truth.width, truth.height);
    let mut out = GrayImage {
        width: w,
        height: h,
        data: vec![0.0; w * h],
    };
    let on = |i: usize| truth.data[i] > 0.5 && (i / w) as f32 + 0.5 > horizon;
    let mut seen = vec![false; w * h];
    let (mut stack, mut comp) = (Vec::new(), Vec::new());
    for start in 0..w * h {
        if seen[start] || !on(start) {
            continue;
        }
        comp.clear();
        seen[start] = true;
        stack.push(start);
        let (mut x0, mut x1, mut y0, mut y1) = (w, 0, h, 0);
        while let Some(i) = stack.pop() {
            comp.push(i);
            let (x, y) = (i % w, i / w);
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    let j = ny * w + nx;
                    if !seen[j] && on(j) {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        if y1 - y0 > x1 - x0 {
            for &i in &comp {
                out.data[i] = 1.0;
            }
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::synth::SplitMix;

    /// Streak axes (a, b, first y, last y, amplitude) below a horizon at y = 120, lamps above
    /// it, a low headlight with its own streak, and noise. Returns the image and the truth mask
    /// (a streak's contribution above half its peak: the half-maximum width, where the default
    /// `row_fraction` puts a streak's edge).
    fn scene(exposure: f32) -> (GrayImage, GrayImage, Vec<(f32, f32)>) {
        scene_shifted(exposure, 0.0)
    }

    /// The scene seen with everything shifted left by `disparity` pixels (a right image).
    pub(crate) fn scene_shifted(
        exposure: f32,
        disparity: f32,
    ) -> (GrayImage, GrayImage, Vec<(f32, f32)>) {
        let (w, h) = (320, 240);
        let streaks = [
            (60.0f32, 0.05f32, 124.0f32, 236.0f32, 0.5f32),
            (170.0, -0.02, 126.0, 230.0, 0.4),
            (200.0, 0.30, 122.0, 200.0, 0.6),
            (280.0, 0.0, 149.0, 235.0, 0.35),
        ];
        let lamps = [
            (66.0f32, 100.0f32),
            (168.0, 110.0),
            (240.0, 90.0),
            (280.5, 146.0),
        ];
        let mut img = GrayImage::new(w, h, 0.0).unwrap();
        let mut truth = GrayImage::new(w, h, 0.0).unwrap();
        let mut rng = SplitMix(5 + disparity.to_bits() as u64);
        for y in 0..h {
            for x in 0..w {
                let (xc, yc) = (x as f32 + 0.5 + disparity, y as f32 + 0.5);
                let mut s = 0.0f32;
                let mut core = false;
                for &(a, b, y0, y1, amp) in &streaks {
                    if (y0..=y1).contains(&yc) {
                        let dx = xc - (a + b * yc);
                        let v = amp * (-dx * dx / (2.0 * 2.5 * 2.5)).exp();
                        core |= v > 0.5 * amp;
                        s += v;
                    }
                }
                let mut l = 0.0f32;
                for &(lx, ly) in &lamps {
                    let r2 = (xc - lx).powi(2) + (yc - ly).powi(2);
                    l += 1.0 * (-r2 / (2.0 * 2.0 * 2.0)).exp();
                }
                let v = 0.03 + 0.01 * rng.gaussian() + s + l;
                img.set(x, y, exposure * v);
                truth.set(x, y, if core { 1.0 } else { 0.0 });
            }
        }
        let axes = streaks.iter().map(|s| (s.0, s.1)).collect();
        (img, truth, axes)
    }

    #[test]
    fn streaks_are_found_and_separated_from_lamps() {
        for exposure in [1.0f32, 0.2, 5.0] {
            let (img, truth, axes) = scene(exposure);
            let det = detect_streaks(&img, &DetectParams::default()).unwrap();
            assert_eq!(
                det.streaks.len(),
                4,
                "exposure {exposure}: {:?}",
                det.streaks
            );
            assert_eq!(det.lamps.len(), 4, "{:?}", det.lamps);
            for (a, b) in axes {
                // The detected streak whose axis passes closest at y = 180.
                let s = det
                    .streaks
                    .iter()
                    .min_by(|p, q| {
                        let e = |s: &&Streak| (s.axis_a + s.axis_b * 180.0 - (a + b * 180.0)).abs();
                        e(p).total_cmp(&e(q))
                    })
                    .unwrap();
                assert!(
                    (s.axis_a + s.axis_b * 180.0 - (a + b * 180.0)).abs() < 0.3,
                    "{s:?}"
                );
                assert!((s.axis_b - b).abs() < 0.01, "{s:?}");
                assert!(s.first_row >= 120 && s.elongation > 5.0);
            }
            let score = score_mask(&det.mask, &truth).unwrap();
            eprintln!("detection at exposure {exposure}: {score:?}");
            assert!(score.precision > 0.9 && score.recall > 0.85, "{score:?}");
        }
    }

    #[test]
    fn lucas_kanade_along_detected_streaks() {
        use crate::lk::{lk_rows, LkParams};
        let (left, _, _) = scene_shifted(1.0, 0.0);
        let (right, _, _) = scene_shifted(1.0, 6.35);
        let det = detect_streaks(&left, &DetectParams::default()).unwrap();
        let params = LkParams {
            window: 21,
            max_disp: 16,
            ..LkParams::default()
        };
        // Independent noise (0.01, streak amplitudes 0.35-0.6) limits single rows to ~0.1 px.
        let (mut worst, mut sum, mut n) = (0.0f32, 0.0f32, 0);
        for s in &det.streaks {
            for e in lk_rows(&left, &right, &s.centres, &params).unwrap() {
                worst = worst.max((e.disparity - 6.35).abs());
                sum += e.disparity - 6.35;
                n += 1;
            }
        }
        let bias = sum / n as f32;
        eprintln!("LK along detected streaks: {n} rows, bias {bias} px, worst {worst} px");
        assert!(bias.abs() < 0.02 && worst < 0.3, "{bias} {worst}");
    }

    /// A faint streak on a road whose brightness ramps down the image, under a lamp 300 times
    /// brighter: thresholds from the image's percentiles would miss it; the row background
    /// finds it. A lane marking (slope 1.5) is not a streak.
    #[test]
    fn faint_streak_on_a_ramped_road_under_a_bright_lamp() {
        let (w, h) = (200, 160);
        let mut img = GrayImage::new(w, h, 0.0).unwrap();
        let mut truth = GrayImage::new(w, h, 0.0).unwrap();
        let mut rng = SplitMix(11);
        for y in 0..h {
            for x in 0..w {
                let (xc, yc) = (x as f32 + 0.5, y as f32 + 0.5);
                let road = 0.05 + 0.3 * yc / h as f32;
                let dx = xc - (100.0 + 0.05 * yc);
                let s = if (70.0..150.0).contains(&yc) {
                    0.15 * (-dx * dx / (2.0 * 3.0 * 3.0)).exp()
                } else {
                    0.0
                };
                let r2 = (xc - 100.0).powi(2) + (yc - 30.0).powi(2);
                let lamp = 50.0 * (-r2 / 8.0).exp();
                let lane = if yc > 70.0 && (xc - (80.0 - 1.5 * (yc - 70.0))).abs() < 1.5 {
                    0.3
                } else {
                    0.0
                };
                img.set(x, y, road + s + lamp + lane + 0.005 * rng.gaussian());
                truth.set(x, y, if s > 0.5 * 0.15 { 1.0 } else { 0.0 });
            }
        }
        let p = DetectParams {
            horizon: Some(60.0),
            ..DetectParams::default()
        };
        let det = detect_streaks(&img, &p).unwrap();
        assert_eq!(det.streaks.len(), 1, "{:?}", det.streaks);
        let s = &det.streaks[0];
        assert!((s.axis_a + s.axis_b * 110.0 - 105.5).abs() < 0.5, "{s:?}");
        let score = score_mask(&det.mask, &truth).unwrap();
        assert!(score.precision > 0.9 && score.recall > 0.8, "{score:?}");
        // The same truth is all vertical and below the horizon; a wide blob and anything above
        // the horizon are not.
        let mut t2 = truth.clone();
        for y in 20..30 {
            for x in 10..60 {
                t2.set(x, y + 100, 1.0);
                t2.set(x + 100, y, 1.0);
            }
        }
        let v = vertical_truth(&t2, 60.0);
        assert_eq!(v.data, truth.data);
    }

    /// A wide glow reaching the bottom of the image (the near end of a reflection) joins the
    /// streak mask; a compact headlight below the horizon stays a lamp, out of the mask.
    #[test]
    fn a_glow_at_the_bottom_is_a_reflection_and_a_headlight_a_lamp() {
        let (w, h) = (200, 120);
        let mut img = GrayImage::new(w, h, 0.0).unwrap();
        let mut rng = SplitMix(3);
        for y in 0..h {
            for x in 0..w {
                let (xc, yc) = (x as f32 + 0.5, y as f32 + 0.5);
                let glow =
                    0.5 * (-((xc - 120.0) / 18.0).powi(2) - ((yc - 120.0) / 15.0).powi(2)).exp();
                let head = 1.0 * (-((xc - 50.0).powi(2) + (yc - 80.0).powi(2)) / 8.0).exp();
                img.set(x, y, 0.03 + glow + head + 0.005 * rng.gaussian());
            }
        }
        let p = DetectParams {
            horizon: Some(60.0),
            ..DetectParams::default()
        };
        let det = detect_streaks(&img, &p).unwrap();
        assert!(det.streaks.is_empty(), "{:?}", det.streaks);
        assert_eq!(det.glows.len(), 1, "{:?}", det.glows);
        assert!((det.glows[0].x - 120.0).abs() < 2.0, "{:?}", det.glows);
        assert_eq!(det.lamps.len(), 1, "{:?}", det.lamps);
        assert!((det.lamps[0].x - 50.0).abs() < 1.0 && (det.lamps[0].y - 80.0).abs() < 1.0);
        assert!(det.mask.get(120, 115) > 0.5 && det.mask.get(120, h - 1) > 0.5);
        assert_eq!(det.mask.get(50, 80), 0.0);
    }

    #[test]
    fn bad_input_is_an_error_and_a_flat_image_has_nothing() {
        let flat = GrayImage::new(20, 10, 0.3).unwrap();
        let det = detect_streaks(&flat, &DetectParams::default()).unwrap();
        assert!(det.streaks.is_empty() && det.lamps.is_empty());
        let p = DetectParams {
            low: 0.5,
            high: 0.2,
            ..DetectParams::default()
        };
        assert!(detect_streaks(&flat, &p).is_err());
        let other = GrayImage::new(20, 11, 0.0).unwrap();
        assert!(score_mask(&flat, &other).is_err());
    }
}
