//! Streak-robust stereo: which of semi-global matching's disparities a streak or a mirror
//! reflection fooled, their masking or repair from the surface around them, a calibrated
//! confidence map and the streak mask, all from the pair alone.
//!
//! # Why
//!
//! A wet road's reflections (streaks of lamps and headlights, mirror images of cars and
//! facades) are matched at the disparity of the reflected object's virtual image, which lies
//! *beneath* the road: stereo then reports holes in the road (phantom holes). Rain drops,
//! sensor noise and the dark, nearly textureless road between the streaks add mismatches of
//! their own, and semi-global matching's smoothness spreads a streak's disparity over them.
//!
//! # No road model
//!
//! Nothing here assumes a planar road, a horizon or a calibrated camera: streets bend, climb
//! and are crowned, and one wrong global estimate (a road plane fitted to the wrong rows)
//! must not be able to spoil a whole image. Every decision is local, from what the physics
//! gives at and around the pixel ([`StereoFeatures`]):
//!
//! - a reflection's disparity is that of its virtual image, far below the surface: it is
//!   *lower* than the disparities beside it on its row (upper quantiles of a row window, at
//!   three widths; of its column and of a square, where a wide reflection fills the row's
//!   window) and, being the image of a vertical column of light, nearly *constant down
//!   its column*, where a road's disparity grows toward the camera;
//! - a specular streak breaks photo-consistency between the eyes in a way a Lambertian
//!   surface does not: warped by the surface's disparity (the row's upper quartile) the right
//!   image does not match the left where a streak is, while at the streak's own disparity it
//!   does;
//! - a streak is bright against the road beside it, over a long vertical run (contrast over
//!   row medians, persisting down the column), and the surface around it is seen in both
//!   eyes (textured, with consistent disparities).
//!
//! # The learned part
//!
//! Two gradient-boosted classifiers ([`crate::gbdt`]) on those features, trained on generated
//! streets by `streaks train-repair` and shipped as `models/streak_repair.json`
//! ([`RepairModel::shipped`]; its `provenance` records the datasets, seeds and settings):
//!
//! - `wrong`: the probability that semi-global matching's value at a pixel is wrong (more than
//!   1 px beneath the truth, or more than 2 px off);
//! - `streak`: the probability that a pixel is a road streak (the renderer's streak mask on its
//!   road mask), smoothed and thresholded at an operating point chosen for precision on
//!   streets the trees never saw: the streak mask.
//!
//! Each decides from windows a few dozen pixels wide, and a wide reflection or a long faint
//! streak is then decided pixel by pixel, each from too little. A **second stage**
//! ([`RepairModel::context`], [`probabilities`]) decides both again from the features and
//! the first stage's probabilities pooled down the column, along the row and over squares,
//! with the disparity against the surface of the values the first stage trusts and against
//! the line those values follow down the column below the pixel, near and, peeled of the
//! values beneath it, far ([`StereoFeatures::context`], [`CONTEXT_FEATURES`]): a region's
//! verdict seen as a whole (auto-context), and the road a wide reflection lies beneath. At
//! its mirror row a reflection's value meets the lit surface it mirrors. The second
//! stage's trees learn from first-stage probabilities of streets those trees did not see, as
//! they will meet them.
//!
//! # Mask, repair, confidence ([`robust_disparity`])
//!
//! A value whose `wrong` probability reaches [`RepairModel::wrong_threshold`] is dropped: the
//! probability above which a value is more likely wrong than a repair is right, measured by
//! training on the validation streets, so that every value given out is at least as
//! reliable as a repair (a missing value is shown as missing; a wrong one is read as a
//! surface). `mask` leaves a dropped value without a value (`inf`); `repair` gives it the
//! surface around it, from the smallest of the windows [`FILL_RADII`] that has support (at
//! least a quarter of its pixels kept) and holds one surface (the kept values' quartiles
//! within 1 px or 10 % of each other): first the pixel's row (twice the radius to each
//! side: a road's disparity changes little along a row, and the surface on both sides of a
//! streak is seen by both eyes), then the square (rows, then columns). The value is the
//! upper quartile, since a fooled value lies beneath the surface. Nothing models the
//! surface's shape, and where the kept values around disagree (a depth edge: an occlusion's
//! repair would take the far side, a reflection's the near one) the value stays missing. The
//! confidence map is calibrated: for a kept value, the share of kept values of its
//! `wrong`-probability decile that were right on the validation streets; for a repaired one,
//! the share of repaired values right at its window's size; 0 where there is no value.

use crate::benchmark::breakdown::{bin_index, Bin, STREAK_LENGTH_BINS};
use crate::detect::MaskScore;
use crate::filter::{finite_quantile, max, max_above, mean, median, Axis};
use crate::gbdt::{GbdtError, Model};
use crate::sgm::{sgm, SgmError, SgmParams};
use crate::streak_classifier::{smooth_probability, streak_mask};
use serde::{Deserialize, Serialize};
use streaks_image::stats::quantile;
use streaks_image::{ensure_same_size, GrayImage, ImageError, SizeMismatch};

/// The format tag of a saved repair model.
pub const FORMAT: &str = "streaks-repair/1";

/// The value of a feature that is not defined at a pixel (no disparity there, or none in its
/// window): far outside every real value, so a tree splits it off.
pub const MISSING: f32 = 1.0e4;

/// The half-widths of the row windows of the disparity features, pixels.
const ROW_RADII: [usize; 3] = [8, 32, 96];

/// The half-widths of the windows a repair takes its value from, smallest first, pixels.
pub const FILL_RADII: [usize; 5] = [2, 4, 8, 16, 32];

/// The quantile of the kept values a repair takes (rows, then columns).
const FILL_QUANTILE: f32 = 0.75;

/// A window's kept values describe one surface when their quartiles differ by at most this,
/// pixels, ...
const FILL_AGREEMENT_PX: f32 = 1.0;

/// ... or by at most this share of the upper quartile.
const FILL_AGREEMENT_SHARE: f32 = 0.1;

/// The share of a repair window's pixels that must be kept values.
const FILL_SUPPORT: f32 = 0.25;

/// The number of `wrong`-probability bins of the kept values' calibration.
pub const CALIBRATION_BINS: usize = 10;

/// The names of the features, in order (see the module documentation and
/// [`StereoFeatures::new`]).
pub const FEATURES: [&str; 30] = [
    "valid",
    "d_minus_q75_r8",
    "d_minus_q75_r32",
    "d_minus_q75_r96",
    "d_minus_q90_r8",
    "d_minus_q90_r32",
    "d_minus_q90_r96",
    "d_relative_to_q75_r32",
    "d_change_4_rows_down",
    "d_change_12_rows_down",
    "d_std_5x5",
    "valid_share_5x5",
    "l_minus_p999",
    "contrast_9",
    "contrast_31",
    "contrast_91",
    "contrast_31_over_15_rows",
    "contrast_31_over_45_rows",
    "texture_5x5",
    "photo_at_d",
    "photo_at_surface",
    "photo_surface_minus_d",
    "right_contrast_31_at_d",
    "brightest_above_minus_l",
    "contrast_31_run_45_rows",
    "vertical_minus_horizontal_mean_45",
    "vertical_contrast_91",
    "d_minus_q75_column_r48",
    "d_minus_q90_square_r32",
    "d_change_32_rows_down",
];

/// The names of the second stage's context features, in order ([`StereoFeatures::context`]):
/// the first stage's probabilities at the pixel and pooled over its column, its row and
/// squares, the disparity against the surface of the values the first stage trusts and
/// against the lines they follow down the column below it, and the disparity at the mirror
/// row.
pub const CONTEXT_FEATURES: [&str; 21] = [
    "wrong1",
    "streak1",
    "wrong1_column_r22",
    "wrong1_column_r66",
    "wrong1_row_r32",
    "wrong1_square_r16",
    "wrong1_square_r48",
    "streak1_column_r22",
    "streak1_column_r66",
    "streak1_row_max_r8",
    "streak1_square_r16",
    "streak1_above_max_r4",
    "d_minus_trusted_q75_row_r32",
    "d_minus_trusted_q75_column_r48",
    "d_minus_trusted_q75_square_r32",
    "trusted_share_row_r32",
    "d_minus_trusted_line_below",
    "trusted_line_below_slope",
    "d_minus_trusted_line_far_below",
    "trusted_line_far_below_slope",
    "mirror_d_minus",
];

/// A value the first stage's `wrong` probability puts below this is trusted by the second
/// stage's surface features.
const TRUSTED_BELOW: f32 = 0.5;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum RepairError {
    /// The images or the disparity map differ in size.
    #[error(transparent)]
    Size(#[from] SizeMismatch),
    /// An image could not be made.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// A saved model is not one this version reads.
    #[error("repair model: {0}")]
    Format(String),
    /// A model's trees are malformed.
    #[error(transparent)]
    Gbdt(#[from] GbdtError),
}

/// The per-pixel features of a pair and its disparity (see the module documentation), one
/// plane per feature of [`FEATURES`].
#[derive(Clone, Debug)]
pub struct StereoFeatures {
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    planes: Vec<Vec<f32>>,
}

/// `ln(v + 1/255)` of an image's values in [0, 1]: a log luminance whose floor is an 8-bit
/// camera's step.
fn log_luminance(img: &GrayImage) -> GrayImage {
    let mut out = img.clone();
    for v in &mut out.data {
        *v = (v.max(0.0) + 1.0 / 255.0).ln();
    }
    out
}

/// The mean over the `(2 r + 1)`-square around each pixel (clipped at the borders).
fn box_mean(img: &GrayImage, r: usize) -> GrayImage {
    mean(&mean(img, Axis::Rows, r), Axis::Columns, r)
}

/// The mean of `values` over the `(2 r + 1)`-square where `values` is finite, with the share
/// of finite pixels: `(mean, share)`, the mean `MISSING` where the share is 0.
fn finite_box_mean(values: &[f32], w: usize, h: usize, r: usize) -> (Vec<f32>, Vec<f32>) {
    let plane = |f: &dyn Fn(f32) -> f32| GrayImage {
        width: w,
        height: h,
        data: values.iter().map(|&v| f(v)).collect(),
    };
    let sum = box_mean(&plane(&|v| if v.is_finite() { v } else { 0.0 }), r);
    let share = box_mean(&plane(&|v| f32::from(u8::from(v.is_finite()))), r);
    let m = sum
        .data
        .iter()
        .zip(&share.data)
        .map(|(&s, &c)| if c > 1e-6 { s / c } else { MISSING })
        .collect();
    (m, share.data)
}

impl StereoFeatures {
    /// The features of the left view's pixels, from the left and right luminance (values in
    /// [0, 1], as [`GrayImage::load`] reads a camera's PNG) and the left view's disparity
    /// (`inf` or a value <= 0: none).
    pub fn new(left: &GrayImage, right: &GrayImage, disp: &GrayImage) -> Result<Self, RepairError> {
        ensure_same_size(
            "the left image",
            left.size(),
            "the right image",
            right.size(),
        )?;
        ensure_same_size(
            "the left image",
            left.size(),
            "the disparity map",
            disp.size(),
        )?;
        let (w, h) = (left.width, left.height);
        let n = w * h;
        let mut d = disp.clone();
        for v in &mut d.data {
            if !(v.is_finite() && *v > 0.0) {
                *v = f32::INFINITY;
            }
        }
        let valid = |i: usize| d.data[i].is_finite();
        let or_missing = |v: f32| if v.is_finite() { v } else { MISSING };
        let l = log_luminance(left);
        let rl = log_luminance(right);
        let mut planes: Vec<Vec<f32>> = Vec::with_capacity(FEATURES.len());
        planes.push((0..n).map(|i| f32::from(u8::from(valid(i)))).collect());
        let q75: Vec<GrayImage> = ROW_RADII
            .iter()
            .map(|&r| finite_quantile(&d, Axis::Rows, r, 0.75))
            .collect();
        let q90: Vec<GrayImage> = ROW_RADII
            .iter()
            .map(|&r| finite_quantile(&d, Axis::Rows, r, 0.9))
            .collect();
        // The disparity against a window's quantile, and its change k rows down the column.
        let minus = |q: &GrayImage| -> Vec<f32> {
            (0..n).map(|i| or_missing(d.data[i] - q.data[i])).collect()
        };
        let change_down = |k: usize| -> Vec<f32> {
            (0..n)
                .map(|i| {
                    if i + k * w < n {
                        or_missing(d.data[i + k * w] - d.data[i])
                    } else {
                        MISSING
                    }
                })
                .collect()
        };
        for q in q75.iter().chain(&q90) {
            planes.push(minus(q));
        }
        let surface = &q75[1];
        planes.push(
            (0..n)
                .map(|i| or_missing((d.data[i] - surface.data[i]) / surface.data[i].max(0.5)))
                .collect(),
        );
        for k in [4, 12] {
            planes.push(change_down(k));
        }
        let (m1, share) = finite_box_mean(&d.data, w, h, 2);
        let sq: Vec<f32> = d.data.iter().map(|v| v * v).collect();
        let (m2, _) = finite_box_mean(&sq, w, h, 2);
        planes.push(
            (0..n)
                .map(|i| {
                    if share[i] > 1e-6 {
                        (m2[i] - m1[i] * m1[i]).max(0.0).sqrt()
                    } else {
                        MISSING
                    }
                })
                .collect(),
        );
        planes.push(share);
        let p999 = quantile(l.data.iter().copied(), 0.999).unwrap_or(0.0);
        planes.push(l.data.iter().map(|v| v - p999).collect());
        let contrast = |r: usize| {
            let m = median(&l, Axis::Rows, r);
            GrayImage {
                width: w,
                height: h,
                data: l.data.iter().zip(&m.data).map(|(a, b)| a - b).collect(),
            }
        };
        let c31 = contrast(15);
        planes.push(contrast(4).data);
        planes.push(c31.data.clone());
        planes.push(contrast(45).data);
        planes.push(mean(&c31, Axis::Columns, 7).data);
        planes.push(mean(&c31, Axis::Columns, 22).data);
        let lm = box_mean(&l, 2);
        let l2 = box_mean(
            &GrayImage {
                width: w,
                height: h,
                data: l.data.iter().map(|v| v * v).collect(),
            },
            2,
        );
        planes.push(
            lm.data
                .iter()
                .zip(&l2.data)
                .map(|(m, s)| (s - m * m).max(0.0).sqrt())
                .collect(),
        );
        // Photo-consistency: |left - right warped by a disparity|, averaged over 5x5 where the
        // disparity is defined.
        let photo = |disparity: &dyn Fn(usize) -> f32| {
            let diff: Vec<f32> = (0..n)
                .map(|i| {
                    let dv = disparity(i);
                    if !dv.is_finite() {
                        return f32::INFINITY;
                    }
                    let (x, y) = (i % w, i / w);
                    let xr = (x as f32 - dv).round();
                    if xr < 0.0 {
                        return f32::INFINITY;
                    }
                    (l.data[i] - rl.data[y * w + (xr as usize).min(w - 1)]).abs()
                })
                .collect();
            finite_box_mean(&diff, w, h, 2).0
        };
        let at_d = photo(&|i| d.data[i]);
        let at_s = photo(&|i| surface.data[i]);
        let own = |p: &[f32], i: usize| if valid(i) { p[i] } else { MISSING };
        planes.push((0..n).map(|i| own(&at_d, i)).collect());
        planes.push((0..n).map(|i| at_s[i]).collect());
        planes.push(
            (0..n)
                .map(|i| {
                    if valid(i) && at_s[i] < MISSING && at_d[i] < MISSING {
                        at_s[i] - at_d[i]
                    } else {
                        MISSING
                    }
                })
                .collect(),
        );
        // The right eye sees a streak at its own disparity: its contrast there.
        let rc31 = {
            let m = median(&rl, Axis::Rows, 15);
            let c: Vec<f32> = rl.data.iter().zip(&m.data).map(|(a, b)| a - b).collect();
            c
        };
        planes.push(
            (0..n)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    let xr = (x as f32 - d.data[i]).round();
                    if valid(i) && xr >= 0.0 {
                        rc31[y * w + (xr as usize).min(w - 1)]
                    } else {
                        MISSING
                    }
                })
                .collect(),
        );
        // The light a streak hangs from lies above it, within a few columns.
        let above = max(&max_above(&l), Axis::Rows, 2);
        planes.push(above.data.iter().zip(&l.data).map(|(a, b)| a - b).collect());
        let run = GrayImage {
            width: w,
            height: h,
            data: c31
                .data
                .iter()
                .map(|&c| f32::from(u8::from(c > 0.5)))
                .collect(),
        };
        planes.push(mean(&run, Axis::Columns, 22).data);
        // A streak is long down its column and narrow across its row; a lamp or a window is
        // compact both ways.
        let vertical = mean(&l, Axis::Columns, 22);
        let horizontal = mean(&l, Axis::Rows, 22);
        planes.push(
            vertical
                .data
                .iter()
                .zip(&horizontal.data)
                .map(|(a, b)| a - b)
                .collect(),
        );
        let column_median = median(&l, Axis::Columns, 45);
        planes.push(
            l.data
                .iter()
                .zip(&column_median.data)
                .map(|(a, b)| a - b)
                .collect(),
        );
        // Wider context for a reflection that fills its row window (a lit facade or an
        // underpass mouth mirrored over a wide stretch of far road): the disparities down the
        // pixel's column, where the road below comes nearer; the upper quantile of a square
        // (rows, then columns); the change over a third of a window down the column.
        planes.push(minus(&finite_quantile(&d, Axis::Columns, 48, 0.75)));
        planes.push(minus(&finite_quantile(&q90[1], Axis::Columns, 32, 0.9)));
        planes.push(change_down(32));
        debug_assert_eq!(planes.len(), FEATURES.len());
        Ok(Self {
            width: w,
            height: h,
            planes,
        })
    }

    /// The features of pixel `i` (`y * width + x`).
    pub fn row(&self, i: usize, out: &mut [f32; FEATURES.len()]) {
        self.row_with(&[], i, out);
    }

    /// The features of pixel `i` followed by its values of `extra` planes (the second
    /// stage's [`StereoFeatures::context`]); `out` holds one value per plane.
    pub fn row_with(&self, extra: &[Vec<f32>], i: usize, out: &mut [f32]) {
        debug_assert_eq!(out.len(), self.planes.len() + extra.len());
        for (o, p) in out.iter_mut().zip(self.planes.iter().chain(extra)) {
            *o = p[i];
        }
    }

    /// The probability of `model` at every pixel.
    pub fn probability(&self, model: &Model) -> GrayImage {
        self.probability_where(model, |_| true, 0.0)
    }

    /// The probability of `model` at the pixels `at` accepts, `otherwise` elsewhere (the
    /// trees are the cost of a pixel: a pixel that needs no answer is not asked).
    pub fn probability_where(
        &self,
        model: &Model,
        at: impl Fn(usize) -> bool + Sync,
        otherwise: f32,
    ) -> GrayImage {
        self.probability_with(&[], model, at, otherwise)
    }

    /// [`StereoFeatures::probability_where`] of a model of these features followed by
    /// `extra` planes.
    pub fn probability_with(
        &self,
        extra: &[Vec<f32>],
        model: &Model,
        at: impl Fn(usize) -> bool + Sync,
        otherwise: f32,
    ) -> GrayImage {
        let data = model.probabilities_of(
            self.width * self.height,
            self.planes.len() + extra.len(),
            |i, row| self.row_with(extra, i, row),
            at,
            otherwise,
        );
        GrayImage {
            width: self.width,
            height: self.height,
            data,
        }
    }

    /// The second stage's context planes ([`CONTEXT_FEATURES`]) of the left view's disparity
    /// `disp` (`inf` or <= 0: none) and the first stage's probabilities `wrong` (1 where
    /// there is no value) and `streak` (unsmoothed).
    ///
    /// The first stage decides from windows of a few dozen pixels; a wide reflection or a
    /// long faint streak is decided pixel by pixel, each from too little. Its probabilities
    /// pooled down the column, along the row and over squares let the second stage see a
    /// region's verdict as a whole (auto-context), and the disparities it trusts give the
    /// surface a fooled value lies beneath.
    pub fn context(
        &self,
        disp: &GrayImage,
        wrong: &GrayImage,
        streak: &GrayImage,
    ) -> Vec<Vec<f32>> {
        let (w, h) = (self.width, self.height);
        let n = w * h;
        let d = |i: usize| {
            let v = disp.data[i];
            if v.is_finite() && v > 0.0 {
                v
            } else {
                f32::INFINITY
            }
        };
        let trusted = GrayImage {
            width: w,
            height: h,
            data: (0..n)
                .map(|i| {
                    if wrong.data[i] < TRUSTED_BELOW {
                        d(i)
                    } else {
                        f32::INFINITY
                    }
                })
                .collect(),
        };
        let minus = |q: &GrayImage| -> Vec<f32> {
            (0..n)
                .map(|i| {
                    let v = d(i) - q.data[i];
                    if v.is_finite() {
                        v
                    } else {
                        MISSING
                    }
                })
                .collect()
        };
        let row_q = finite_quantile(&trusted, Axis::Rows, 32, 0.75);
        let column_q = finite_quantile(&trusted, Axis::Columns, 48, 0.75);
        // The square's: the rows' upper quartiles, then the columns'.
        let square_q = finite_quantile(&row_q, Axis::Columns, 32, 0.75);
        let trusted_share = mean(
            &GrayImage {
                width: w,
                height: h,
                data: trusted
                    .data
                    .iter()
                    .map(|v| f32::from(u8::from(v.is_finite())))
                    .collect(),
            },
            Axis::Rows,
            32,
        );
        let (line_minus, line_slope) = against_line(&trusted_line(&trusted, NEAR_LINE), w, d);
        let far = peeled_line(&trusted, FAR_LINE);
        let (far_minus, far_slope) = against_line(&far, w, d);
        let mirror = mirror_minus(&far, w, d);
        // A streak hangs below its light: the most streak-like pixel a few columns wide above.
        let above = max(&max_above(streak), Axis::Rows, 4);
        let planes = vec![
            wrong.data.clone(),
            streak.data.clone(),
            mean(wrong, Axis::Columns, 22).data,
            mean(wrong, Axis::Columns, 66).data,
            mean(wrong, Axis::Rows, 32).data,
            box_mean(wrong, 16).data,
            box_mean(wrong, 48).data,
            mean(streak, Axis::Columns, 22).data,
            mean(streak, Axis::Columns, 66).data,
            max(streak, Axis::Rows, 8).data,
            box_mean(streak, 16).data,
            above.data,
            minus(&row_q),
            minus(&column_q),
            minus(&square_q),
            trusted_share.data,
            line_minus,
            line_slope,
            far_minus,
            far_slope,
            mirror,
        ];
        debug_assert_eq!(planes.len(), CONTEXT_FEATURES.len());
        planes
    }
}

/// Where a pixel's road line is fitted ([`trusted_line`]): to the trusted values of `rows`
/// rows from `gap` rows below the pixel, in the columns within `band` of its own, when at
/// least `min` of them are there.
#[derive(Clone, Copy, Debug)]
struct LineSpan {
    gap: usize,
    rows: usize,
    band: usize,
    min: f64,
}

/// The near line: the pixel's own column, the 64 rows from 6 below it (at least 12 values).
const NEAR_LINE: LineSpan = LineSpan {
    gap: 6,
    rows: 64,
    band: 0,
    min: 12.0,
};

/// The far line ([`peeled_line`]): 17 columns around the pixel's, the 192 rows from 6 below
/// it (at least 64 values). Where a wide reflection fools the road for dozens of rows below
/// it too, the near line has nothing right to stand on; the road farther down and beside it
/// often has.
const FAR_LINE: LineSpan = LineSpan {
    gap: 6,
    rows: 192,
    band: 8,
    min: 64.0,
};

/// Per pixel, the straight line `c + k y` (disparity against row) fitted by least squares to
/// the `trusted` values (finite: trusted) that `span` takes below it: `[c, k]`, NaN where
/// fewer than `span.min` values fit or their rows do not vary.
///
/// A road's disparity grows steadily toward the camera down a column, whatever its bends and
/// slopes over a few dozen rows (on a plane, exactly linearly), and the nearer road below a
/// reflection is seen by both eyes; a wide reflection that fools every value of its row is a
/// plateau beneath that line. Computed from a summed-area table of the values' count, row,
/// value, row squared and row times value, so a fit costs a few lookups whatever its span.
fn trusted_line(trusted: &GrayImage, span: LineSpan) -> Vec<[f32; 2]> {
    let (w, h) = (trusted.width, trusted.height);
    let stride = w + 1;
    let mut table = vec![[0f64; 5]; (h + 1) * stride];
    for y in 0..h {
        let mut run = [0f64; 5];
        for x in 0..w {
            let v = trusted.data[y * w + x];
            if v.is_finite() {
                let (r, v) = (y as f64, f64::from(v));
                run[0] += 1.0;
                run[1] += r;
                run[2] += v;
                run[3] += r * r;
                run[4] += r * v;
            }
            let above = table[y * stride + x + 1];
            table[(y + 1) * stride + x + 1] = std::array::from_fn(|k| above[k] + run[k]);
        }
    }
    let mut out = vec![[f32::NAN; 2]; w * h];
    for y in 0..h {
        let (a, b) = ((y + span.gap).min(h), (y + span.gap + span.rows).min(h));
        for x in 0..w {
            let (l, r) = (x.saturating_sub(span.band), (x + span.band + 1).min(w));
            let at = |row: usize, col: usize| table[row * stride + col];
            let (bb, ab, bl, al) = (at(b, r), at(a, r), at(b, l), at(a, l));
            let s: [f64; 5] = std::array::from_fn(|k| bb[k] - ab[k] - bl[k] + al[k]);
            let n = s[0];
            let det = n * s[3] - s[1] * s[1];
            if n < span.min || det <= 1e-9 * n * n {
                continue;
            }
            let k = (n * s[4] - s[1] * s[2]) / det;
            let c = (s[2] - k * s[1]) / n;
            out[y * w + x] = [c as f32, k as f32];
        }
    }
    out
}

/// The most times [`peeled_line`] refits the line (a bound; it stops when a refit removes
/// nothing).
const MAX_PEELS: usize = 32;

/// [`trusted_line`], refitted without the trusted values that lie more than 1 px beneath
/// their own line until none does (at most [`MAX_PEELS`] times).
///
/// A wide reflection that the first stage trusts is, row after row, part of the span that the
/// line of the pixels above it is fitted to, and drags that line down to itself. Its lower
/// rows, though, lie clearly beneath the line of the road farther below them; without them
/// the rows above see that road too, and each refit peels the reflection further up. A road
/// value is not beneath its own line, so the road keeps its values.
fn peeled_line(trusted: &GrayImage, span: LineSpan) -> Vec<[f32; 2]> {
    let w = trusted.width;
    let mut line = trusted_line(trusted, span);
    let mut kept = trusted.clone();
    for _ in 0..MAX_PEELS {
        let mut removed = false;
        for (i, v) in kept.data.iter_mut().enumerate() {
            let [c, k] = line[i];
            if *v < c + k * (i / w) as f32 - 1.0 {
                *v = f32::INFINITY;
                removed = true;
            }
        }
        if !removed {
            break;
        }
        line = trusted_line(&kept, span);
    }
    line
}

/// The disparity `d(i)` of each pixel against its `line` ([`trusted_line`]) extrapolated to
/// its row, and the line's slope (disparity per row): `(d minus line, slope)`, [`MISSING`]
/// where the pixel has no value or no line.
fn against_line(line: &[[f32; 2]], w: usize, d: impl Fn(usize) -> f32) -> (Vec<f32>, Vec<f32>) {
    let mut minus = vec![MISSING; line.len()];
    let mut slope = vec![MISSING; line.len()];
    for (i, &[c, k]) in line.iter().enumerate() {
        let dv = d(i);
        if dv.is_finite() && c.is_finite() {
            minus[i] = dv - (c + k * (i / w) as f32);
            slope[i] = k;
        }
    }
    (minus, slope)
}

/// The smallest slope (disparity per row) of a road line that [`mirror_minus`] reads as a
/// road growing toward the camera.
const MIRROR_MIN_SLOPE: f32 = 1.0e-3;

/// For each pixel with a value `d` beneath its road `line` (the line reaches `d` at least a
/// row above it): the disparity at its mirror row less `d`, [`MISSING`] where there is none
/// to compare.
///
/// A wet road mirrors a lit surface standing on it at the surface's own distance, so the
/// reflection's disparity is the surface's, and the reflection is the surface flipped about
/// the row where the road's disparity equals it (where the surface stands). That row is
/// where the line reaches `d`; the mirror row lies as far above it as the pixel lies below.
/// There semi-global matching sees the lit surface itself, at about `d`, if the pixel's value
/// is a reflection; noise or a wrong match has no such partner.
fn mirror_minus(line: &[[f32; 2]], w: usize, d: impl Fn(usize) -> f32) -> Vec<f32> {
    let h = line.len() / w.max(1);
    let mut out = vec![MISSING; line.len()];
    for (i, &[c, k]) in line.iter().enumerate() {
        let dv = d(i);
        if !(dv.is_finite() && c.is_finite() && k > MIRROR_MIN_SLOPE) {
            continue;
        }
        let (x, y) = (i % w, (i / w) as f32);
        let stands = (dv - c) / k;
        let mirror = (2.0 * stands - y).round();
        if (0.0..h as f32).contains(&mirror) && stands <= y - 1.0 {
            let m = d(mirror as usize * w + x);
            if m.is_finite() {
                out[i] = m - dv;
            }
        }
    }
    out
}

/// The calibration of the confidence map: measured shares of right values on the
/// validation streets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// For kept values, by decile of the `wrong` probability (below the threshold, in
    /// [`CALIBRATION_BINS`] equal bins of [0, threshold)): the share that was right.
    pub kept: Vec<f32>,
    /// For repaired values, by the window they took their value from ([`FILL_RADII`]): the
    /// share that was right.
    pub repaired: Vec<f32>,
}

/// A trained streak-robust stereo model: the two classifiers, their thresholds and the
/// confidence calibration (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RepairModel {
    /// [`FORMAT`].
    pub format: String,
    /// The feature names ([`FEATURES`] when saved by this version).
    pub features: Vec<String>,
    /// The probability that semi-global matching's value is wrong.
    pub wrong: Model,
    /// A value is dropped where `wrong` reaches this.
    pub wrong_threshold: f32,
    /// The probability that a pixel is a road streak.
    pub streak: Model,
    /// A pixel is a streak where the smoothed `streak` probability reaches this.
    pub streak_threshold: f32,
    /// Radius of the box filter on the `streak` probability before its threshold.
    pub streak_smooth: usize,
    /// The streak mask's hysteresis: a streak is a connected region where the smoothed
    /// probability reaches this lower threshold and somewhere reaches `streak_threshold`
    /// (a streak's faint tail is kept with its bright core; a faint speck alone is not).
    /// `None`: the plain threshold (models written before it was added).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub streak_grow_threshold: Option<f32>,
    /// The second stage, if the model has one: `wrong` and `streak` decided again from the
    /// features and the first stage's context ([`StereoFeatures::context`]); the thresholds
    /// and the calibration are then the second stage's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub context: Option<ContextStage>,
    /// The confidence map's calibration.
    pub calibration: Calibration,
    /// What the model was trained on and how (free-form, for people).
    pub provenance: serde_json::Value,
}

/// A repair model's second stage: its classifiers read [`FEATURES`] followed by
/// [`CONTEXT_FEATURES`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContextStage {
    /// The context feature names ([`CONTEXT_FEATURES`] when saved by this version).
    pub features: Vec<String>,
    /// The probability that semi-global matching's value is wrong.
    pub wrong: Model,
    /// The probability that a pixel is a road streak.
    pub streak: Model,
}

impl ContextStage {
    /// A second stage of these classifiers with this version's context features.
    pub fn new(wrong: Model, streak: Model) -> Self {
        Self {
            features: CONTEXT_FEATURES.iter().map(|s| s.to_string()).collect(),
            wrong,
            streak,
        }
    }
}

/// The first stage's probabilities and, with a second stage, its context planes and the
/// second stage's probabilities: `(wrong, unsmoothed streak)`, `wrong` at the pixels with a
/// value of `disp` (1 elsewhere). With a second stage, `wrong` is 1 where the value lies
/// beneath the road ([`beneath_the_road`]).
pub fn probabilities(
    features: &StereoFeatures,
    disp: &GrayImage,
    model: &RepairModel,
) -> (GrayImage, GrayImage) {
    let valid = |i: usize| disp.data[i].is_finite() && disp.data[i] > 0.0;
    let wrong = features.probability_where(&model.wrong, valid, 1.0);
    let streak = features.probability(&model.streak);
    match &model.context {
        None => (wrong, streak),
        Some(stage) => {
            let extra = features.context(disp, &wrong, &streak);
            let mut wrong = features.probability_with(&extra, &stage.wrong, valid, 1.0);
            let plane = |name: &str| {
                let k = CONTEXT_FEATURES.iter().position(|n| *n == name);
                &extra[k.expect("a context feature of this version")]
            };
            let minus = plane("d_minus_trusted_line_far_below");
            let slope = plane("trusted_line_far_below_slope");
            for (i, p) in wrong.data.iter_mut().enumerate() {
                if beneath_the_road(minus[i], slope[i]) {
                    *p = 1.0;
                }
            }
            (
                wrong,
                features.probability_with(&extra, &stage.streak, |_| true, 0.0),
            )
        }
    }
}

/// A value further than this beneath the road's far line is wrong whatever the trees say
/// ([`beneath_the_road`]): twice the phantom-hole margin, so that the line's own scatter
/// (a few tenths of a pixel on a road) does not reach it.
pub const BENEATH_ROAD_PX: f32 = 2.0;

/// The smallest slope (disparity per row) of a far line that [`beneath_the_road`] reads as a
/// road growing toward the camera.
const BENEATH_ROAD_MIN_SLOPE: f32 = 0.02;

/// Whether a value lies more than [`BENEATH_ROAD_PX`] beneath its far line (its context
/// features `d_minus_trusted_line_far_below` and `trusted_line_far_below_slope`, the line
/// peeled of the values beneath it and rising toward the camera).
///
/// Nothing that stands on a road or above it lies beneath the road's line: a car, a wall or a
/// lamp post has the disparity of the road where it stands, above which the line is lower
/// still. What lies beneath it is a mirror image, or a road falling away beyond a crest
/// (whose values are then dropped, not made wrong). The trees learn their rules from the
/// generator's streets, where a lit surface mirrored over the whole road near the camera is
/// rare, and on streets where it is not they trusted such bands; the physics holds on every
/// street.
fn beneath_the_road(minus: f32, slope: f32) -> bool {
    minus < -BENEATH_ROAD_PX && slope > BENEATH_ROAD_MIN_SLOPE && slope < MISSING
}

impl RepairModel {
    /// A model of two classifiers with this version's format and features, thresholds 0.5,
    /// no smoothing, a neutral calibration and no provenance: what training has before it
    /// measures them.
    pub fn new(wrong: Model, streak: Model) -> Self {
        Self {
            format: FORMAT.into(),
            features: FEATURES.iter().map(|s| s.to_string()).collect(),
            wrong,
            wrong_threshold: 0.5,
            streak,
            streak_threshold: 0.5,
            streak_smooth: 0,
            streak_grow_threshold: None,
            context: None,
            calibration: Calibration {
                kept: vec![0.5; CALIBRATION_BINS],
                repaired: vec![0.5; FILL_RADII.len()],
            },
            provenance: serde_json::Value::Null,
        }
    }

    /// Checks a loaded model: format, features, thresholds, calibration, the trees.
    pub fn validate(&self) -> Result<(), RepairError> {
        let bad = |m: String| Err(RepairError::Format(m));
        if self.format != FORMAT {
            return bad(format!("format {:?}, expected {FORMAT:?}", self.format));
        }
        if self.features != FEATURES
            || self.wrong.features != FEATURES.len()
            || self.streak.features != FEATURES.len()
        {
            return bad(format!(
                "features {:?}, this version computes {FEATURES:?}",
                self.features
            ));
        }
        for (name, t) in [
            ("wrong_threshold", self.wrong_threshold),
            ("streak_threshold", self.streak_threshold),
        ] {
            if !(0.0..=1.0).contains(&t) {
                return bad(format!("{name} {t} is not a probability"));
            }
        }
        if let Some(g) = self.streak_grow_threshold {
            if !(0.0..=self.streak_threshold).contains(&g) {
                return bad(format!(
                    "streak_grow_threshold {g} is not a probability at most streak_threshold {}",
                    self.streak_threshold
                ));
            }
        }
        let c = &self.calibration;
        if c.kept.len() != CALIBRATION_BINS
            || c.repaired.len() != FILL_RADII.len()
            || c.kept
                .iter()
                .chain(&c.repaired)
                .any(|v| !(0.0..=1.0).contains(v))
        {
            return bad(format!(
                "calibration needs {CALIBRATION_BINS} kept and {} repaired shares in [0, 1]",
                FILL_RADII.len()
            ));
        }
        self.wrong.validate()?;
        self.streak.validate()?;
        if let Some(stage) = &self.context {
            let all = FEATURES.len() + CONTEXT_FEATURES.len();
            if stage.features != CONTEXT_FEATURES
                || stage.wrong.features != all
                || stage.streak.features != all
            {
                return bad(format!(
                    "context features {:?}, this version computes {CONTEXT_FEATURES:?}",
                    stage.features
                ));
            }
            stage.wrong.validate()?;
            stage.streak.validate()?;
        }
        Ok(())
    }

    /// Parses and checks a model saved as JSON.
    pub fn from_json(text: &str) -> Result<Self, RepairError> {
        let m: Self = serde_json::from_str(text).map_err(|e| RepairError::Format(e.to_string()))?;
        m.validate()?;
        Ok(m)
    }

    /// The model that ships with the crate (`models/streak_repair.json`), trained by
    /// `streaks train-repair` on generated streets (its `provenance` says which).
    pub fn shipped() -> &'static Self {
        static SHIPPED: std::sync::OnceLock<RepairModel> = std::sync::OnceLock::new();
        SHIPPED.get_or_init(|| {
            Self::from_json(include_str!("../models/streak_repair.json"))
                .expect("the shipped repair model is valid (tested)")
        })
    }

    /// The calibration bin of a kept value's `wrong` probability `p`.
    fn kept_bin(&self, p: f32) -> usize {
        let t = self.wrong_threshold.max(1e-6);
        ((p / t * CALIBRATION_BINS as f32) as usize).min(CALIBRATION_BINS - 1)
    }
}

/// What to do with the values a streak or reflection fooled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreakHandling {
    /// Leave them without a value.
    Mask,
    /// Give them the surface around them: the upper quartile of the kept values of the
    /// smallest window that holds one surface.
    Repair,
}

/// A masked or repaired disparity map and what was done.
#[derive(Clone, Debug)]
pub struct RobustDisparity {
    /// The disparities (`inf`: no value).
    pub disparity: GrayImage,
    /// The calibrated probability that each value is right (within 2 px and not more than
    /// 1 px beneath the truth); 0 where there is no value.
    pub confidence: GrayImage,
    /// The `wrong` probability of every pixel (1 where semi-global matching gave no value).
    pub wrong: GrayImage,
    /// The smoothed road-streak probability.
    pub streak_probability: GrayImage,
    /// The streak mask ([`streak_mask`] of the smoothed probability at the model's
    /// thresholds).
    pub streaks: GrayImage,
    /// How the value of each pixel came about.
    pub origin: Vec<Origin>,
    /// Pixels the streak mask holds.
    pub streak_pixels: usize,
    /// Values dropped as fooled.
    pub dropped_pixels: usize,
    /// Dropped values repaired.
    pub repaired_pixels: usize,
    /// Dropped values left without a value.
    pub masked_pixels: usize,
}

/// How a pixel's value in a [`RobustDisparity`] came about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// Semi-global matching gave none.
    None,
    /// Semi-global matching's value, kept.
    Kept,
    /// Dropped and left without a value.
    Masked,
    /// Dropped and repaired from the window of [`FILL_RADII`] with this index.
    Repaired(u8),
}

/// The repair of each dropped pixel from the kept values around it (see the module
/// documentation): the repaired value and the index of its window in [`FILL_RADII`], per
/// pixel; `None` where no window has the support and one surface.
fn fill(kept: &GrayImage) -> Vec<Option<(f32, u8)>> {
    let (w, h) = (kept.width, kept.height);
    let mut out: Vec<Option<(f32, u8)>> = vec![None; w * h];
    let agree = |lo: f32, hi: f32| hi - lo <= FILL_AGREEMENT_PX.max(FILL_AGREEMENT_SHARE * hi);
    for (k, &r) in FILL_RADII.iter().enumerate() {
        // The row first: a road's disparity changes little along a row, and the surface on
        // both sides of a streak is seen by both eyes.
        let hi = finite_quantile(kept, Axis::Rows, 2 * r, FILL_QUANTILE);
        let lo = finite_quantile(kept, Axis::Rows, 2 * r, 1.0 - FILL_QUANTILE);
        let share = mean(
            &GrayImage {
                width: w,
                height: h,
                data: kept
                    .data
                    .iter()
                    .map(|v| f32::from(u8::from(v.is_finite())))
                    .collect(),
            },
            Axis::Rows,
            2 * r,
        );
        // Then a square (rows, then columns): robust to the outliers that survive.
        let rows = finite_quantile(kept, Axis::Rows, r, FILL_QUANTILE);
        let sq = finite_quantile(&rows, Axis::Columns, r, FILL_QUANTILE);
        let rows_lo = finite_quantile(kept, Axis::Rows, r, 1.0 - FILL_QUANTILE);
        let sq_lo = finite_quantile(&rows_lo, Axis::Columns, r, 1.0 - FILL_QUANTILE);
        let (_, sq_share) = finite_box_mean(&kept.data, w, h, r);
        for i in 0..w * h {
            if out[i].is_some() {
                continue;
            }
            if hi.data[i].is_finite()
                && share.data[i] >= FILL_SUPPORT
                && agree(lo.data[i], hi.data[i])
            {
                out[i] = Some((hi.data[i], k as u8));
            } else if sq.data[i].is_finite()
                && sq_share[i] >= FILL_SUPPORT
                && agree(sq_lo.data[i], sq.data[i])
            {
                out[i] = Some((sq.data[i], k as u8));
            }
        }
    }
    out
}

/// Masks or repairs the values of `disp` (the left view's disparity) that streaks and
/// reflections fool, from the pair's luminance `left` and `right` and `model`; see the module
/// documentation.
pub fn robust_disparity(
    left: &GrayImage,
    right: &GrayImage,
    disp: &GrayImage,
    handling: StreakHandling,
    model: &RepairModel,
) -> Result<RobustDisparity, RepairError> {
    let features = StereoFeatures::new(left, right, disp)?;
    Ok(robust_from_features(&features, disp, handling, model))
}

/// [`robust_disparity`] on features already computed (training measures the calibration so).
pub fn robust_from_features(
    features: &StereoFeatures,
    disp: &GrayImage,
    handling: StreakHandling,
    model: &RepairModel,
) -> RobustDisparity {
    let (w, h) = (features.width, features.height);
    let n = w * h;
    let valid = |i: usize| disp.data[i].is_finite() && disp.data[i] > 0.0;
    let (wrong, streak) = probabilities(features, disp, model);
    let streak_probability = smooth_probability(&streak, model.streak_smooth);
    let streaks = streak_mask(
        &streak_probability,
        model.streak_threshold,
        model.streak_grow_threshold,
    );
    let mut kept = GrayImage {
        width: w,
        height: h,
        data: vec![f32::INFINITY; n],
    };
    let mut origin = vec![Origin::None; n];
    for (i, o) in origin.iter_mut().enumerate() {
        if valid(i) {
            if wrong.data[i] < model.wrong_threshold {
                kept.data[i] = disp.data[i];
                *o = Origin::Kept;
            } else {
                *o = Origin::Masked;
            }
        }
    }
    let filled = match handling {
        StreakHandling::Repair => fill(&kept),
        StreakHandling::Mask => vec![None; n],
    };
    let mut out = kept.clone();
    let mut confidence = GrayImage {
        width: w,
        height: h,
        data: vec![0.0; n],
    };
    let (mut dropped, mut repaired) = (0, 0);
    for i in 0..n {
        match origin[i] {
            Origin::Kept => {
                confidence.data[i] = model.calibration.kept[model.kept_bin(wrong.data[i])];
            }
            Origin::Masked => {
                dropped += 1;
                if let Some((v, k)) = filled[i] {
                    out.data[i] = v;
                    origin[i] = Origin::Repaired(k);
                    confidence.data[i] = model.calibration.repaired[k as usize];
                    repaired += 1;
                }
            }
            Origin::None | Origin::Repaired(_) => {}
        }
    }
    let streak_pixels = streaks.data.iter().filter(|&&v| v > 0.0).count();
    RobustDisparity {
        disparity: out,
        confidence,
        wrong,
        streak_probability,
        streaks,
        origin,
        streak_pixels,
        dropped_pixels: dropped,
        repaired_pixels: repaired,
        masked_pixels: dropped - repaired,
    }
}

/// The shortest streak (rows spanned, as a share of the image height) that the streak-level
/// score counts, in the truth and in the mask: shorter specks are not streaks.
pub const MIN_STREAK_EXTENT: f32 = 0.03;

/// A truth streak is found when the mask covers at least this share of its pixels.
pub const FOUND_COVER: f32 = 0.25;

/// A detected streak is correct when at least this share of its pixels lies within 2 px of
/// the truth's streak pixels.
pub const CORRECT_SHARE: f32 = 0.5;

/// The contrast bins of a truth streak, in 8-bit code values of the image's luminance: the
/// streak's mean less the mean of the pixels beside it ([`TruthStreak::contrast`]). A faint
/// streak is within a few noise steps of the road around it.
pub const STREAK_CONTRAST_BINS: [Bin; 3] = [
    Bin {
        name: "faint",
        low: f64::NEG_INFINITY,
        high: 10.0,
    },
    Bin {
        name: "moderate",
        low: 10.0,
        high: 40.0,
    },
    Bin {
        name: "bright",
        low: 40.0,
        high: f64::INFINITY,
    },
];

/// How many columns on each side of a truth streak's pixels [`TruthStreak::contrast`] takes
/// as the pixels beside it.
const CONTRAST_SIDE_PX: usize = 4;

/// One streak of the road-streak truth, as the streak-level score counts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthStreak {
    /// Rows it spans, as a share of the image height.
    pub extent: f32,
    /// Its mean luminance less that of the pixels beside it (within [`CONTRAST_SIDE_PX`]
    /// columns on its rows, not on any truth streak), in 8-bit code values (luminance in
    /// [0, 1] times 255); `None` without an image or without such pixels.
    pub contrast: Option<f32>,
    /// Whether the mask covers at least [`FOUND_COVER`] of its pixels.
    pub found: bool,
}

/// The streaks of the road-streak `truth` (non-zero on streak pixels): its 8-connected
/// components spanning at least [`MIN_STREAK_EXTENT`] of the image's rows, each with whether
/// `mask` finds it and, given the image's luminance `lum` (in [0, 1]), its contrast. The
/// three images have one size.
pub fn truth_streaks(
    mask: &GrayImage,
    truth: &GrayImage,
    lum: Option<&GrayImage>,
) -> Vec<TruthStreak> {
    use crate::benchmark::breakdown::components8;
    let (w, h) = (truth.width, truth.height);
    let min_rows = (MIN_STREAK_EXTENT * h as f32).ceil() as usize;
    let mut beside = vec![usize::MAX; if lum.is_some() { w * h } else { 0 }];
    let mut out = vec![];
    for (k, c) in components8(w, h, |i| truth.data[i] > 0.0)
        .iter()
        .enumerate()
    {
        let rows = rows_spanned(c, w);
        if rows < min_rows {
            continue;
        }
        let covered = c.iter().filter(|&&i| mask.data[i] > 0.0).count();
        let contrast = lum.and_then(|l| {
            let (mut side, mut n) = (0.0f64, 0usize);
            for &i in c {
                let (x, y) = (i % w, i / w);
                let row = y * w;
                for nx in x.saturating_sub(CONTRAST_SIDE_PX)..=(x + CONTRAST_SIDE_PX).min(w - 1) {
                    let j = row + nx;
                    if truth.data[j] <= 0.0 && beside[j] != k {
                        beside[j] = k;
                        side += f64::from(l.data[j]);
                        n += 1;
                    }
                }
            }
            let on = c.iter().map(|&i| f64::from(l.data[i])).sum::<f64>() / c.len() as f64;
            (n > 0).then(|| (255.0 * (on - side / n as f64)) as f32)
        });
        out.push(TruthStreak {
            extent: rows as f32 / h as f32,
            contrast,
            found: covered as f32 >= FOUND_COVER * c.len() as f32,
        });
    }
    out
}

/// The streak-level counts of a streak mask against the road-streak truth (both non-zero on
/// streak pixels): `(truth streaks found, truth streaks, detected streaks correct, detected
/// streaks)`. Streaks are 8-connected components spanning at least [`MIN_STREAK_EXTENT`] of
/// the image's rows; see [`truth_streaks`] and [`detected_streaks`].
pub fn streak_objects(mask: &GrayImage, truth: &GrayImage) -> (usize, usize, usize, usize) {
    let truths = truth_streaks(mask, truth, None);
    let (correct, detected) = detected_streaks(mask, truth);
    let found = truths.iter().filter(|t| t.found).count();
    (found, truths.len(), correct, detected)
}

/// The streaks of `mask` (its 8-connected components spanning at least [`MIN_STREAK_EXTENT`]
/// of the rows) against the road-streak `truth`: `(correct, detected)`, a detected streak
/// being correct when at least [`CORRECT_SHARE`] of its pixels lie within 2 px of the truth.
pub fn detected_streaks(mask: &GrayImage, truth: &GrayImage) -> (usize, usize) {
    use crate::benchmark::breakdown::components8;
    let (w, h) = (truth.width, truth.height);
    let min_rows = (MIN_STREAK_EXTENT * h as f32).ceil() as usize;
    let near_truth = max(&max(truth, Axis::Rows, 2), Axis::Columns, 2);
    let (mut correct, mut detected) = (0, 0);
    for c in components8(w, h, |i| mask.data[i] > 0.0)
        .iter()
        .filter(|c| rows_spanned(c, w) >= min_rows)
    {
        detected += 1;
        let on = c.iter().filter(|&&i| near_truth.data[i] > 0.0).count();
        correct += usize::from(on as f32 >= CORRECT_SHARE * c.len() as f32);
    }
    (correct, detected)
}

/// The rows a component (pixel indices of an image `w` wide) spans.
fn rows_spanned(c: &[usize], w: usize) -> usize {
    let (y0, y1) = c
        .iter()
        .fold((usize::MAX, 0), |(a, b), &i| (a.min(i / w), b.max(i / w)));
    y1 + 1 - y0
}

/// Whether an estimate `e` of the true disparity `t` is right: within 2 px and not more than
/// 1 px beneath it (the `wrong` classifier's label and the confidence map's meaning).
pub fn is_right(e: f32, t: f32) -> bool {
    (e - t).abs() <= 2.0 && e >= t - 1.0
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

/// Semi-global matching of `left` and `right` with `params`, then, given a handling and a
/// model (usually [`RepairModel::shipped`]), the streak-robust pass ([`robust_disparity`]).
/// One function, so that `streaks disparity [--streaks mask|repair]` and the benchmark's
/// `sgm` and `sgm-streaks` methods compute exactly the same map.
pub fn estimate(
    left: &GrayImage,
    right: &GrayImage,
    params: &SgmParams,
    handling: Option<(StreakHandling, &RepairModel)>,
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
        Some((handling, model)) => {
            let r = robust_disparity(left, right, &disp, handling, model)?;
            Estimate {
                disparity: r.disparity.clone(),
                sgm_seconds,
                robust: Some(r),
            }
        }
    })
}

/// Counts for the figures of a repair on samples with ground truth: the phantom holes, the
/// off-road bad-2, the densities, the streak mask's score and the calibration's counts.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RepairCounts {
    /// Road pixels with a finite truth.
    pub road: usize,
    /// Of those, semi-global matching's values more than 1 px beneath the truth.
    pub road_below_sgm: usize,
    /// Of those, the repaired map's values more than 1 px beneath the truth.
    pub road_below: usize,
    /// Road pixels with a value, semi-global matching and repaired.
    pub road_valid_sgm: usize,
    /// See `road_valid_sgm`.
    pub road_valid: usize,
    /// Off-road pixels with a finite truth and a value, semi-global matching and repaired.
    pub off_valid_sgm: usize,
    /// See `off_valid_sgm`.
    pub off_valid: usize,
    /// Of those, more than 2 px off: semi-global matching and repaired.
    pub off_bad_sgm: usize,
    /// See `off_bad_sgm`.
    pub off_bad: usize,
    /// Off-road pixels with a finite truth.
    pub off: usize,
    /// Pixels with a finite truth whose value is missing or wrong ([`is_right`]): semi-global
    /// matching and repaired.
    pub missing_or_wrong_sgm: usize,
    /// See `missing_or_wrong_sgm`.
    pub missing_or_wrong: usize,
    /// Pixels with a finite truth.
    pub truth: usize,
    /// Pixels with a finite truth whose value was dropped (repaired or masked).
    pub dropped: usize,
    /// Streak mask against the road-streak truth: pixels in both.
    pub streak_true_positives: usize,
    /// Pixels of the streak mask.
    pub streak_detected: usize,
    /// Pixels of the road-streak truth.
    pub streak_truth: usize,
    /// Truth streaks found by the streak mask ([`truth_streaks`]).
    pub streaks_found: usize,
    /// Truth streaks.
    pub streaks_true: usize,
    /// Detected streaks that are correct ([`detected_streaks`]).
    pub detections_correct: usize,
    /// Detected streaks.
    pub detections: usize,
    /// Truth streaks by their length ([`STREAK_LENGTH_BINS`]): (found, all).
    #[serde(default)]
    pub streaks_by_length: Vec<(usize, usize)>,
    /// Truth streaks by their contrast ([`STREAK_CONTRAST_BINS`]): (found, all); a streak
    /// without a contrast is in none.
    #[serde(default)]
    pub streaks_by_contrast: Vec<(usize, usize)>,
    /// Kept values by calibration bin: (right, all).
    pub kept: Vec<(usize, usize)>,
    /// Repaired values by window: (right, all).
    pub repaired: Vec<(usize, usize)>,
}

impl RepairCounts {
    /// Adds the counts of one sample: the left image's luminance `left` (in [0, 1]),
    /// semi-global matching's map `sgm`, the repair `r` of it with `model`, the truth, and the
    /// road and road-streak masks (non-zero: in the mask), all of one size.
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &mut self,
        left: &GrayImage,
        sgm: &GrayImage,
        r: &RobustDisparity,
        model: &RepairModel,
        truth: &GrayImage,
        road: &GrayImage,
        road_streaks: &GrayImage,
    ) {
        if self.kept.is_empty() {
            self.kept = vec![(0, 0); CALIBRATION_BINS];
            self.repaired = vec![(0, 0); FILL_RADII.len()];
        }
        if self.streaks_by_length.is_empty() {
            self.streaks_by_length = vec![(0, 0); STREAK_LENGTH_BINS.len()];
            self.streaks_by_contrast = vec![(0, 0); STREAK_CONTRAST_BINS.len()];
        }
        let truths = truth_streaks(&r.streaks, road_streaks, Some(left));
        let (correct, detected) = detected_streaks(&r.streaks, road_streaks);
        self.streaks_found += truths.iter().filter(|t| t.found).count();
        self.streaks_true += truths.len();
        self.detections_correct += correct;
        self.detections += detected;
        for t in &truths {
            let length = bin_index(&STREAK_LENGTH_BINS, f64::from(t.extent));
            let contrast = t
                .contrast
                .and_then(|c| bin_index(&STREAK_CONTRAST_BINS, f64::from(c)));
            for slot in [
                length.map(|k| &mut self.streaks_by_length[k]),
                contrast.map(|k| &mut self.streaks_by_contrast[k]),
            ]
            .into_iter()
            .flatten()
            {
                slot.0 += usize::from(t.found);
                slot.1 += 1;
            }
        }
        for i in 0..truth.data.len() {
            let t = truth.data[i];
            let (s, e) = (sgm.data[i], r.disparity.data[i]);
            let streak = road_streaks.data[i] > 0.0;
            let detected = r.streaks.data[i] > 0.0;
            self.streak_truth += usize::from(streak);
            self.streak_detected += usize::from(detected);
            self.streak_true_positives += usize::from(streak && detected);
            if !t.is_finite() {
                continue;
            }
            let (sv, ev) = (s.is_finite() && s > 0.0, e.is_finite());
            self.truth += 1;
            self.missing_or_wrong_sgm += usize::from(!(sv && is_right(s, t)));
            self.missing_or_wrong += usize::from(!(ev && is_right(e, t)));
            if road.data[i] > 0.0 {
                self.road += 1;
                self.road_below_sgm += usize::from(sv && s < t - 1.0);
                self.road_below += usize::from(ev && e < t - 1.0);
                self.road_valid_sgm += usize::from(sv);
                self.road_valid += usize::from(ev);
            } else {
                self.off += 1;
                self.off_valid_sgm += usize::from(sv);
                self.off_valid += usize::from(ev);
                self.off_bad_sgm += usize::from(sv && (s - t).abs() > 2.0);
                self.off_bad += usize::from(ev && (e - t).abs() > 2.0);
            }
            self.dropped +=
                usize::from(matches!(r.origin[i], Origin::Masked | Origin::Repaired(_)));
            let slot = match r.origin[i] {
                Origin::Kept => Some(&mut self.kept[model.kept_bin(r.wrong.data[i])]),
                Origin::Repaired(k) => Some(&mut self.repaired[k as usize]),
                Origin::None | Origin::Masked => None,
            };
            if let Some(c) = slot {
                c.0 += usize::from(is_right(e, t));
                c.1 += 1;
            }
        }
    }

    /// The phantom-hole rates (semi-global matching, repaired): road pixels more than 1 px
    /// beneath the truth, over all road pixels with a truth.
    pub fn phantom(&self) -> (f64, f64) {
        let f = |a: usize| a as f64 / self.road.max(1) as f64;
        (f(self.road_below_sgm), f(self.road_below))
    }

    /// The share of pixels with a truth whose value is missing or wrong (semi-global
    /// matching, repaired).
    pub fn missing_or_wrong(&self) -> (f64, f64) {
        let f = |a: usize| a as f64 / self.truth.max(1) as f64;
        (f(self.missing_or_wrong_sgm), f(self.missing_or_wrong))
    }

    /// Off-road bad-2 over the off-road values (semi-global matching, repaired).
    pub fn off_road_bad2(&self) -> (f64, f64) {
        (
            self.off_bad_sgm as f64 / self.off_valid_sgm.max(1) as f64,
            self.off_bad as f64 / self.off_valid.max(1) as f64,
        )
    }

    /// The streak-level score: (precision, recall) over the detected and the truth streaks
    /// ([`streak_objects`]); 1 where there is nothing to count.
    pub fn streak_level(&self) -> (f64, f64) {
        let f = |a: usize, b: usize| if b > 0 { a as f64 / b as f64 } else { 1.0 };
        (
            f(self.detections_correct, self.detections),
            f(self.streaks_found, self.streaks_true),
        )
    }

    /// The streak mask's pixel score.
    pub fn streak_score(&self) -> MaskScore {
        MaskScore::from_counts(
            self.streak_true_positives,
            self.streak_detected,
            self.streak_truth,
        )
    }

    /// The calibration these counts measure (a bin without values gets its neighbours'
    /// share, or 0.5 with none).
    pub fn calibration(&self) -> Calibration {
        let shares = |c: &[(usize, usize)]| -> Vec<f32> {
            let raw: Vec<Option<f32>> = c
                .iter()
                .map(|&(r, a)| (a > 0).then(|| r as f32 / a as f32))
                .collect();
            (0..raw.len())
                .map(|k| {
                    raw[k]
                        .or_else(|| (0..k).rev().find_map(|j| raw[j]))
                        .or_else(|| raw[k..].iter().find_map(|v| *v))
                        .unwrap_or(0.5)
                })
                .collect()
        };
        Calibration {
            kept: shares(&self.kept),
            repaired: shares(&self.repaired),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gbdt::Node;

    /// A textured road whose disparity grows down the rows (`floor(0.2 (y - 20))`), with a bright
    /// streak column at x in 60..64 that semi-global matching read at 1 px all the way down
    /// (the virtual light far beneath the road), and no value
    /// in the top 20 rows (the sky): `(left, right, disparity, truth)`.
    fn scene(w: usize, h: usize) -> (GrayImage, GrayImage, GrayImage, GrayImage) {
        let texture = |x: f32, y: usize| 0.2 + 0.1 * ((x * 0.9).sin() * (y as f32 * 0.7).cos());
        let mut left = GrayImage::new(w, h, 0.0).unwrap();
        let mut right = GrayImage::new(w, h, 0.0).unwrap();
        let mut disp = GrayImage::new(w, h, f32::INFINITY).unwrap();
        let mut truth = GrayImage::new(w, h, f32::INFINITY).unwrap();
        for y in 0..h {
            // Whole pixels, so that the right image is the left one shifted exactly.
            let road = (0.2 * (y as f32 + 0.5 - 20.0)).floor();
            for x in 0..w {
                left.set(x, y, texture(x as f32, y));
                right.set(x, y, texture(x as f32 + road.max(0.0), y));
                if road > 0.0 {
                    truth.set(x, y, road);
                    let streak = (60..64).contains(&x);
                    disp.set(x, y, if streak { 1.0 } else { road });
                    if streak {
                        left.set(x, y, 0.95);
                    }
                }
            }
        }
        (left, right, disp, truth)
    }

    /// One stump: log-odds `hi` where `feature > value`, `lo` elsewhere.
    fn stump(feature: &str, value: f32, lo: f32, hi: f32) -> Model {
        let f = FEATURES.iter().position(|n| *n == feature).unwrap();
        stump_at(f, FEATURES.len(), value, lo, hi)
    }

    /// A second-stage stump on the context feature `feature` (see [`stump`]).
    fn context_stump(feature: &str, value: f32, lo: f32, hi: f32) -> Model {
        let f = CONTEXT_FEATURES.iter().position(|n| *n == feature).unwrap();
        let all = FEATURES.len() + CONTEXT_FEATURES.len();
        stump_at(FEATURES.len() + f, all, value, lo, hi)
    }

    /// One stump on feature index `f` of `features`.
    fn stump_at(f: usize, features: usize, value: f32, lo: f32, hi: f32) -> Model {
        let f = f as u16;
        Model {
            features,
            base: 0.0,
            trees: vec![vec![
                Node {
                    feature: f,
                    value,
                    left: 1,
                    right: 2,
                },
                Node {
                    feature: 0,
                    value: lo,
                    left: 0,
                    right: 0,
                },
                Node {
                    feature: 0,
                    value: hi,
                    left: 0,
                    right: 0,
                },
            ]],
        }
    }

    /// `wrong` where the value is more than 2 px below its row's upper quartile (32 px), a
    /// streak where the 31-px contrast exceeds 0.5.
    fn model() -> RepairModel {
        let mut m = RepairModel::new(
            stump("d_minus_q75_r32", -2.0, 4.0, -4.0),
            stump("contrast_31", 0.5, -4.0, 4.0),
        );
        m.calibration.kept = (0..CALIBRATION_BINS)
            .map(|k| 0.9 - 0.01 * k as f32)
            .collect();
        m.calibration.repaired = vec![0.7, 0.6, 0.5, 0.4, 0.3];
        m
    }

    #[test]
    fn features_see_the_streak_below_its_row_and_nothing_where_there_is_no_value() {
        let (left, right, disp, _) = scene(160, 100);
        let f = StereoFeatures::new(&left, &right, &disp).unwrap();
        let at = |name: &str, x: usize, y: usize| {
            let mut row = [0f32; FEATURES.len()];
            f.row(y * 160 + x, &mut row);
            row[FEATURES.iter().position(|n| *n == name).unwrap()]
        };
        let road = (0.2f32 * (80.5 - 20.0)).floor();
        assert!((at("d_minus_q75_r32", 61, 80) - (1.0 - road)).abs() < 0.01);
        assert!(at("d_minus_q75_r32", 100, 80).abs() < 0.01);
        assert!(at("contrast_31", 61, 80) > 1.0);
        // The road beside the streak matches at its disparity; the streak does not match at
        // the surface's, where it does at its own.
        assert!(
            at("photo_at_d", 100, 80) < 0.01,
            "{}",
            at("photo_at_d", 100, 80)
        );
        assert!(at("photo_surface_minus_d", 61, 80) > 0.05);
        assert_eq!(at("valid", 30, 5), 0.0);
        assert_eq!(at("d_minus_q75_r8", 30, 5), MISSING);
        assert_eq!(at("photo_at_d", 30, 5), MISSING);
        // A streak's disparity does not grow down its column, the road's does.
        assert!(at("d_change_12_rows_down", 100, 60) >= 2.0);
        assert!(at("d_change_12_rows_down", 61, 60).abs() < at("d_change_12_rows_down", 100, 60));
    }

    #[test]
    fn repair_gives_fooled_values_the_surface_around_them_and_mask_removes_them() {
        let (left, right, disp, truth) = scene(160, 100);
        let m = model();
        let r = robust_disparity(&left, &right, &disp, StreakHandling::Repair, &m).unwrap();
        for y in 40..100 {
            for x in 60..64 {
                let want = truth.get(x, y);
                let got = r.disparity.get(x, y);
                // The upper quartile of a window on a road whose disparity grows down the rows
                // leans a little toward the near side.
                assert!((got - want).abs() <= 1.0, "({x}, {y}): {got} for {want}");
                let Origin::Repaired(k) = r.origin[y * 160 + x] else {
                    panic!("({x}, {y}) is not repaired");
                };
                assert_eq!(r.confidence.get(x, y), m.calibration.repaired[k as usize]);
                assert_eq!(r.streaks.get(x, y), 1.0);
            }
        }
        assert_eq!(r.disparity.get(100, 80), disp.get(100, 80));
        assert_eq!(r.confidence.get(100, 80), m.calibration.kept[0]);
        assert_eq!(r.confidence.get(100, 5), 0.0);
        assert_eq!(r.streaks.get(100, 80), 0.0);
        assert_eq!(r.dropped_pixels, r.repaired_pixels + r.masked_pixels);
        let k = robust_disparity(&left, &right, &disp, StreakHandling::Mask, &m).unwrap();
        assert!(k.disparity.get(61, 80).is_infinite());
        assert_eq!(k.confidence.get(61, 80), 0.0);
        assert_eq!(k.masked_pixels, k.dropped_pixels);
        assert!(k.dropped_pixels >= 4 * 60);
        // The counts: phantom holes gone, the streak found.
        let road = GrayImage::new(160, 100, 1.0).unwrap();
        let mut c = RepairCounts::default();
        c.add(&left, &disp, &r, &m, &truth, &road, &r.streaks.clone());
        let (before, after) = c.phantom();
        assert!(before > 0.02 && after == 0.0, "{before} {after}");
        assert_eq!(c.streak_level(), (1.0, 1.0));
        assert!(c.repaired.iter().all(|&(right, all)| right == all));
    }

    #[test]
    fn the_second_stage_sees_the_first_stages_verdict_pooled_and_the_trusted_surface() {
        let (left, right, disp, truth) = scene(160, 100);
        let f = StereoFeatures::new(&left, &right, &disp).unwrap();
        let m = model();
        let (wrong, streak) = probabilities(&f, &disp, &m);
        let extra = f.context(&disp, &wrong, &streak);
        assert_eq!(extra.len(), CONTEXT_FEATURES.len());
        let at = |name: &str, x: usize, y: usize| {
            extra[CONTEXT_FEATURES.iter().position(|n| *n == name).unwrap()][y * 160 + x]
        };
        // The first stage calls the streak wrong and a streak; pooled down its column, so
        // does its context, and nothing does beside it.
        assert!(at("wrong1", 61, 80) > 0.9 && at("wrong1", 100, 80) < 0.1);
        assert!(at("wrong1_column_r22", 61, 80) > 0.9);
        // (The streak starts at row 25, within the 133-row window.)
        assert!(at("streak1_column_r66", 61, 80) > 0.8);
        assert!(at("streak1_row_max_r8", 68, 80) > 0.9 && at("streak1_row_max_r8", 100, 80) < 0.1);
        assert!(
            at("wrong1_row_r32", 61, 80) < 0.2,
            "{}",
            at("wrong1_row_r32", 61, 80)
        );
        // The trusted values around the streak are the road: the streak's value lies beneath
        // them by about the road's disparity; a road value is on them; no value, no feature.
        let below = at("d_minus_trusted_q75_row_r32", 61, 80);
        assert!((below + truth.get(61, 80) - 1.0).abs() <= 1.0, "{below}");
        assert!(at("d_minus_trusted_q75_row_r32", 100, 80).abs() <= 1.0);
        assert_eq!(at("d_minus_trusted_q75_column_r48", 100, 5), MISSING);
        assert!(at("trusted_share_row_r32", 61, 80) > 0.8);

        // A second stage that trusts nothing the first stage's column calls wrong, and calls a
        // streak only what the first stage's row maximum does.
        let mut two = m.clone();
        two.context = Some(ContextStage::new(
            context_stump("wrong1_column_r22", 0.5, -4.0, 4.0),
            context_stump("streak1_row_max_r8", 0.5, -4.0, 4.0),
        ));
        assert!(RepairModel::from_json(&serde_json::to_string(&two).unwrap()).is_ok());
        let (wrong2, streak2) = probabilities(&f, &disp, &two);
        assert!(wrong2.get(61, 80) > 0.9 && wrong2.get(100, 80) < 0.1);
        assert!(streak2.get(68, 80) > 0.9 && streak1_differs(&streak, &streak2));
        assert_eq!(wrong2.get(100, 5), 1.0);
        let r = robust_disparity(&left, &right, &disp, StreakHandling::Repair, &two).unwrap();
        assert!((r.disparity.get(61, 80) - truth.get(61, 80)).abs() <= 1.0);

        // A second stage of other features is refused.
        let mut bad = two.clone();
        bad.context.as_mut().unwrap().features.pop();
        let e = RepairModel::from_json(&serde_json::to_string(&bad).unwrap()).unwrap_err();
        assert!(e.to_string().contains("context features"), "{e}");
        let mut bad = two;
        bad.context.as_mut().unwrap().wrong = stump("contrast_31", 0.5, -4.0, 4.0);
        assert!(RepairModel::from_json(&serde_json::to_string(&bad).unwrap()).is_err());
    }

    #[test]
    fn a_value_beneath_the_roads_far_line_is_wrong_whatever_the_trees_say() {
        let (left, right, disp, truth) = scene(160, 100);
        let f = StereoFeatures::new(&left, &right, &disp).unwrap();
        // A second stage whose trees trust every value.
        let mut m = model();
        m.context = Some(ContextStage::new(
            context_stump("wrong1", 2.0, -4.0, 4.0),
            context_stump("streak1", 2.0, -4.0, 4.0),
        ));
        let (wrong, _) = probabilities(&f, &disp, &m);
        // The streak reads 1 px where the road below it gives 6 to 12: beneath the road.
        for y in [50, 65, 80] {
            assert!(truth.get(61, y) - disp.get(61, y) > BENEATH_ROAD_PX + 1.0);
            assert_eq!(wrong.get(61, y), 1.0, "row {y}");
        }
        // The road keeps the trees' verdict.
        assert!(wrong.get(100, 60) < 0.1 && wrong.get(100, 80) < 0.1);
        // Without a second stage the trees alone decide.
        m.context = None;
        m.wrong = stump("d_minus_q75_r32", 1.0e6, -4.0, 4.0);
        let (wrong, _) = probabilities(&f, &disp, &m);
        assert!(wrong.get(61, 80) < 0.1);
    }

    #[test]
    fn the_line_below_a_plateau_shows_it_beneath_the_road() {
        // One column: a road whose disparity grows by 0.25 px a row from row 0, with a
        // plateau of 5 px (a reflection) over rows 40..60 that nothing trusts.
        let (w, h) = (3, 140);
        let road = |y: usize| 0.25 * y as f32;
        let d = |i: usize| {
            if (40..60).contains(&(i / w)) {
                5.0
            } else {
                road(i / w)
            }
        };
        let trusted = GrayImage {
            width: w,
            height: h,
            data: (0..w * h)
                .map(|i| {
                    if (40..60).contains(&(i / w)) {
                        f32::INFINITY
                    } else {
                        d(i)
                    }
                })
                .collect(),
        };
        let (minus, slope) = against_line(&trusted_line(&trusted, NEAR_LINE), w, d);
        let at = |v: &[f32], y: usize| v[y * w + 1];
        assert!(at(&minus, 20).abs() < 1e-3 && (at(&slope, 20) - 0.25).abs() < 1e-3);
        // On the plateau the road below predicts 0.25 px a row: the reflection is beneath it.
        assert!(
            (at(&minus, 50) - (5.0 - road(50))).abs() < 1e-3,
            "{}",
            at(&minus, 50)
        );
        // Too few rows below: no line.
        assert_eq!(at(&minus, h - 10), MISSING);
        assert_eq!(at(&slope, h - 10), MISSING);
    }

    #[test]
    fn the_far_line_and_the_mirror_see_a_reflection_over_a_fooled_road() {
        // A flat road seen from above: disparity 0.25 (y - 20) px from the horizon at row 20,
        // 41 columns. A lit wall stands on it at row 60 (disparity 10) and rises to row 30; on
        // the wet road its reflection fills every column over rows 60..90 at the wall's
        // disparity, and the road below is fooled or dropped too down to row 160.
        let (w, h) = (41, 260);
        let road = |y: usize| 0.25 * (y as f32 - 20.0);
        let d = |i: usize| match i / w {
            30..90 => 10.0,
            y => road(y),
        };
        let trusted = GrayImage {
            width: w,
            height: h,
            data: (0..w * h)
                .map(|i| if i / w < 160 { f32::INFINITY } else { d(i) })
                .collect(),
        };
        let at = |v: &[f32], x: usize, y: usize| v[y * w + x];
        // The near line has no trusted value in the 64 rows from row 86; the far one has.
        let (near, _) = against_line(&trusted_line(&trusted, NEAR_LINE), w, d);
        assert_eq!(at(&near, 20, 80), MISSING);
        let far = peeled_line(&trusted, FAR_LINE);
        let (minus, slope) = against_line(&far, w, d);
        for x in [0, 20, 40] {
            assert!((at(&minus, x, 80) - (10.0 - road(80))).abs() < 1e-2);
            assert!((at(&slope, x, 80) - 0.25).abs() < 1e-4);
        }
        // The reflection at row 80 stands at row 60 and mirrors row 40: the wall, at its
        // disparity. A road value at row 150 is on its line, its own mirror.
        let mirror = mirror_minus(&far, w, d);
        assert!(at(&mirror, 20, 80).abs() < 1e-3, "{}", at(&mirror, 20, 80));
        assert_eq!(at(&mirror, 20, 150), MISSING);
        // A value beneath the line with no lit surface at its mirror row: no partner.
        let noise = |i: usize| if i == 80 * w + 20 { 3.0 } else { road(i / w) };
        let m = mirror_minus(&far, w, noise);
        // It stands at row 32 and mirrors row -16: outside the image.
        assert_eq!(at(&m, 20, 80), MISSING);
        let noise = |i: usize| if i == 80 * w + 20 { 12.0 } else { road(i / w) };
        let m = mirror_minus(&far, w, noise);
        // It stands at row 68 and mirrors row 56, whose road value is 9 px: 3 px beneath it.
        assert!((at(&m, 20, 80) + 3.0).abs() < 1e-3, "{}", at(&m, 20, 80));
    }

    #[test]
    fn the_peeled_line_sees_the_road_beneath_a_trusted_reflection() {
        // The road of the test above, with a reflection at 5 px over rows 50..110 that the
        // first stage trusts like the road below it.
        let (w, h) = (41, 260);
        let road = |y: usize| 0.25 * (y as f32 - 20.0);
        let d = |i: usize| match i / w {
            50..110 => 5.0,
            y => road(y),
        };
        let trusted = GrayImage {
            width: w,
            height: h,
            data: (0..w * h).map(d).collect(),
        };
        let at = |v: &[f32], y: usize| v[y * w + 20];
        // Fitted to every trusted value, the line of row 60 stands partly on the reflection
        // and sees it less than 4 px beneath; peeled, it is the road's: 5 px beneath.
        let (raw, _) = against_line(&trusted_line(&trusted, FAR_LINE), w, d);
        let (peeled, slope) = against_line(&peeled_line(&trusted, FAR_LINE), w, d);
        assert!(at(&raw, 60) > -4.0, "{}", at(&raw, 60));
        assert!(
            (at(&peeled, 60) - (5.0 - road(60))).abs() < 0.05,
            "{}",
            at(&peeled, 60)
        );
        assert!((at(&slope, 60) - 0.25).abs() < 1e-3);
        // The road keeps its line.
        for y in [20, 45, 120, 200] {
            assert!(at(&peeled, y).abs() < 1e-3, "{y}: {}", at(&peeled, y));
        }
    }

    /// Whether the second stage's streak probability differs from the first's somewhere.
    fn streak1_differs(first: &GrayImage, second: &GrayImage) -> bool {
        first.data.iter().zip(&second.data).any(|(a, b)| a != b)
    }

    #[test]
    fn streak_objects_count_tall_components_found_and_correct() {
        let mut truth = GrayImage::new(50, 100, 0.0).unwrap();
        let mut mask = truth.clone();
        for y in 10..60 {
            truth.set(5, y, 1.0); // a 50-row streak, found (mask covers 30 rows)
            truth.set(30, y, 1.0); // a 50-row streak, missed (mask covers 5 rows)
            if y < 40 {
                mask.set(5, y, 1.0);
            }
            if y < 15 {
                mask.set(30, y, 1.0);
            }
            mask.set(45, y, 1.0); // a detection far from any streak
        }
        truth.set(20, 90, 1.0); // one row: too short to count
        assert_eq!(streak_objects(&mask, &truth), (1, 2, 2, 3));
    }

    #[test]
    fn truth_streaks_have_their_extent_contrast_and_found_flag() {
        let (w, h) = (40, 100);
        let mut truth = GrayImage::new(w, h, 0.0).unwrap();
        let mut lum = GrayImage::new(w, h, 0.2).unwrap();
        let mut mask = truth.clone();
        for y in 10..60 {
            // A bright streak (0.2 + 60/255 on a 0.2 road), found, beside a faint one.
            truth.set(5, y, 1.0);
            lum.set(5, y, 0.2 + 60.0 / 255.0);
            mask.set(5, y, 1.0);
            truth.set(30, y, 1.0);
            lum.set(30, y, 0.2 + 4.0 / 255.0);
        }
        // A second truth streak beside the bright one is not its background.
        for y in 10..20 {
            truth.set(8, y, 1.0);
            lum.set(8, y, 1.0);
        }
        let t = truth_streaks(&mask, &truth, Some(&lum));
        assert_eq!(t.len(), 3, "{t:?}");
        let bright = t.iter().find(|s| s.found).unwrap();
        assert_eq!(bright.extent, 0.5);
        assert!((bright.contrast.unwrap() - 60.0).abs() < 1e-3, "{bright:?}");
        let faint = t.iter().find(|s| s.extent == 0.5 && !s.found).unwrap();
        assert!((faint.contrast.unwrap() - 4.0).abs() < 1e-3, "{faint:?}");
        assert_eq!(
            bin_index(&STREAK_CONTRAST_BINS, f64::from(faint.contrast.unwrap())),
            Some(0)
        );
        // Without an image there is no contrast; the same streaks are found.
        let plain = truth_streaks(&mask, &truth, None);
        assert!(plain.iter().all(|s| s.contrast.is_none()));
        assert_eq!(plain.iter().filter(|s| s.found).count(), 1);
        // The counts bin them: the 50-row streaks are long (50 % of the height), the 10-row
        // one medium; by contrast one faint, two bright.
        let r = RobustDisparity {
            disparity: truth.clone(),
            confidence: truth.clone(),
            wrong: truth.clone(),
            streak_probability: truth.clone(),
            streaks: mask.clone(),
            origin: vec![Origin::None; w * h],
            streak_pixels: 0,
            dropped_pixels: 0,
            repaired_pixels: 0,
            masked_pixels: 0,
        };
        let mut c = RepairCounts::default();
        let none = GrayImage::new(w, h, f32::INFINITY).unwrap();
        c.add(&lum, &none, &r, &model(), &none, &truth, &truth);
        assert_eq!(c.streaks_by_length, vec![(0, 0), (0, 1), (1, 2)]);
        assert_eq!(c.streaks_by_contrast, vec![(0, 1), (0, 0), (1, 2)]);
    }

    #[test]
    fn models_are_checked_when_read_and_the_shipped_one_is_valid() {
        let shipped = RepairModel::shipped();
        assert!(shipped.provenance["datasets"]
            .as_array()
            .is_some_and(|d| !d.is_empty()));
        let text = serde_json::to_string(&model()).unwrap();
        assert!(RepairModel::from_json(&text).is_ok());
        let mut bad = model();
        bad.wrong_threshold = 1.5;
        let e = RepairModel::from_json(&serde_json::to_string(&bad).unwrap()).unwrap_err();
        assert!(e.to_string().contains("wrong_threshold"), "{e}");
        let mut bad = model();
        bad.streak_grow_threshold = Some(bad.streak_threshold + 0.1);
        let e = RepairModel::from_json(&serde_json::to_string(&bad).unwrap()).unwrap_err();
        assert!(e.to_string().contains("streak_grow_threshold"), "{e}");
        let mut bad = model();
        bad.calibration.repaired.pop();
        assert!(RepairModel::from_json(&serde_json::to_string(&bad).unwrap()).is_err());
        let e = RepairModel::from_json(&text.replace(FORMAT, "streaks-repair/0")).unwrap_err();
        assert!(e.to_string().contains("format"), "{e}");
        assert!(RepairModel::from_json("{").is_err());
    }

    #[test]
    fn sizes_must_agree() {
        let (left, right, disp, _) = scene(40, 30);
        let small = GrayImage::new(39, 30, 1.0).unwrap();
        assert!(matches!(
            StereoFeatures::new(&left, &small, &disp),
            Err(RepairError::Size(..))
        ));
        assert!(matches!(
            robust_disparity(&left, &right, &small, StreakHandling::Mask, &model()),
            Err(RepairError::Size(..))
        ));
    }
}
