//! Learned streak detection: a per-pixel classifier ([`crate::gbdt`]) on features of the
//! linear luminance, trained on rendered datasets against the renderer's road-streak mask.
//!
//! The hand-built detector ([`crate::detect`]) finds the bright, elongated core of a streak in
//! an 8-bit image. The renderer's truth is wider: every road pixel whose light is mostly a
//! glossy reflection of an emitter and bright enough to matter. That set is separable in
//! linear radiance (an EXR, a raw camera frame), where the streak's tails are still above the
//! diffuse road, but not after an 8-bit camera curve has clipped the streak and crushed the
//! tails. The features, all of the log luminance `l = ln(L + 1e-4) - ln(P99.9(L) + 1e-4)`
//! (so that exposure does not matter):
//!
//! | # | feature | why |
//! |---|---|---|
//! | 0 | `l` | brightness relative to the image's brightest |
//! | 1–4 | `l` minus the median of a horizontal window of 9, 31, 91, 181 px | contrast above the road beside the streak, at four widths |
//! | 5, 6 | the 31-px contrast averaged over 9 and 31 rows | a streak's contrast persists down its length |
//! | 7 | max of `l` over 15 rows minus max over 15 columns | vertical against horizontal extent |
//! | 8 | `(y + 0.5 - horizon) / height` | streaks lie below the horizon, longer nearer it |
//! | 9, 10 | the brightest `l` above the pixel within ±2 columns, and that minus `l` | the light a streak hangs from lies above it |
//! | 11 | `l` minus the median of a vertical window of 31 px | a lamp or a window is compact vertically, a streak is not |
//! | 12 | the share of the 31 rows around the pixel whose 31-px contrast exceeds 0.5 | the streak's vertical run |
//! | 13 | `l` averaged over 3x3 px | less noise than one pixel of a fast render |
//! | 14 | `l` averaged over 9 rows | a streak continues down the column |
//! | 15 | `l` minus the image's median `l` below the horizon | brightness above the wet road's sheen, which sets how bright a reflection must be to be a streak |
//! | 16 | `l` minus the 99.9th percentile of `l` below the horizon | brightness relative to the brightest reflections (lamps hang above the horizon): the renderer's mask is relative to them |
//!
//! No feature is constant over an image: a model trained on a few dozen streets would use
//! such a feature to tell the streets apart, and learn them rather than streaks.
//!
//! A pixel is a streak where the model's probability, averaged over a small square
//! ([`StreakClassifier::smooth`]: neighbours agree on a streak, noise does not), reaches the
//! classifier's threshold. Both are chosen at training on samples the trees never saw, for a
//! target precision.

use crate::detect::MaskScore;
use crate::filter::{max, max_above, mean, median, Axis};
use crate::gbdt::{Dataset, GbdtError, Model};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use streaks_image::stats::quantile_in;
use streaks_image::{ensure_same_size, GrayImage, SizeMismatch};

/// The format tag of a saved classifier.
pub const FORMAT: &str = "streaks-classifier/1";

/// The names of the features, in order (see the module documentation).
pub const FEATURES: [&str; 17] = [
    "l",
    "contrast_9",
    "contrast_31",
    "contrast_91",
    "contrast_181",
    "contrast_31_over_9_rows",
    "contrast_31_over_31_rows",
    "vertical_minus_horizontal_max",
    "below_horizon",
    "brightest_above",
    "brightest_above_minus_l",
    "vertical_contrast_31",
    "vertical_run_31",
    "l_3x3",
    "l_over_9_rows",
    "l_minus_median_below_horizon",
    "l_minus_p999_below_horizon",
];

/// Errors of the classifier.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ClassifierError {
    /// The image has no pixels, or its luminance is not finite and non-negative somewhere.
    #[error("bad image: {0}")]
    Image(String),
    /// A mask and the image differ in size.
    #[error(transparent)]
    SizeMismatch(#[from] SizeMismatch),
    /// A saved classifier is not one this version reads.
    #[error("not a streak classifier: {0}")]
    Format(String),
    /// Training or the model failed.
    #[error(transparent)]
    Model(#[from] GbdtError),
}

/// The per-pixel features of one image, feature-major: `values[f][y * width + x]`.
pub struct Features {
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// One plane per entry of [`FEATURES`].
    pub planes: Vec<Vec<f32>>,
}

impl Features {
    /// The features of the linear luminance `lum` with the horizon at image row `horizon`.
    pub fn new(lum: &GrayImage, horizon: f32) -> Result<Self, ClassifierError> {
        let (w, h) = (lum.width, lum.height);
        if w == 0 || h == 0 {
            return Err(ClassifierError::Image("no pixels".into()));
        }
        if let Some(i) = lum.data.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(ClassifierError::Image(format!(
                "pixel ({}, {}) has luminance {}; need finite and >= 0",
                i % w,
                i / w,
                lum.data[i]
            )));
        }
        let mut buf = Vec::new();
        let mut quantile =
            |v: &[f32], q: f32| quantile_in(v.iter().copied(), q, &mut buf).unwrap_or(0.0);
        let offset = (quantile(&lum.data, 0.999) + 1e-4).ln();
        // The rows whose centre is below the horizon (at least the bottom row).
        let first_below = ((horizon - 0.5).ceil().max(0.0) as usize).min(h - 1);
        let below = &lum.data[first_below * w..];
        let road_median = (quantile(below, 0.5) + 1e-4).ln() - offset;
        let below_p999 = (quantile(below, 0.999) + 1e-4).ln() - offset;
        let l = GrayImage {
            width: w,
            height: h,
            data: lum.data.iter().map(|&v| (v + 1e-4).ln() - offset).collect(),
        };
        let minus = |a: &GrayImage, b: &GrayImage| -> GrayImage {
            GrayImage {
                width: w,
                height: h,
                data: a.data.iter().zip(&b.data).map(|(x, y)| x - y).collect(),
            }
        };
        let contrast = |r| minus(&l, &median(&l, Axis::Rows, r));
        let c31 = contrast(15);
        let above = max_above(&max(&l, Axis::Rows, 2));
        let run = GrayImage {
            width: w,
            height: h,
            data: c31.data.iter().map(|&c| (c > 0.5) as u8 as f32).collect(),
        };
        let below_horizon = GrayImage {
            width: w,
            height: h,
            data: (0..h)
                .flat_map(|y| std::iter::repeat_n((y as f32 + 0.5 - horizon) / h as f32, w))
                .collect(),
        };
        // In the order of FEATURES.
        let planes = [
            l.clone(),
            contrast(4),
            c31.clone(),
            contrast(45),
            contrast(90),
            mean(&c31, Axis::Columns, 4),
            mean(&c31, Axis::Columns, 15),
            minus(&max(&l, Axis::Columns, 7), &max(&l, Axis::Rows, 7)),
            below_horizon,
            above.clone(),
            minus(&above, &l),
            minus(&l, &median(&l, Axis::Columns, 15)),
            mean(&run, Axis::Columns, 15),
            mean(&mean(&l, Axis::Rows, 1), Axis::Columns, 1),
            mean(&l, Axis::Columns, 4),
            GrayImage {
                width: w,
                height: h,
                data: l.data.iter().map(|v| v - road_median).collect(),
            },
            GrayImage {
                width: w,
                height: h,
                data: l.data.iter().map(|v| v - below_p999).collect(),
            },
        ];
        let out: Vec<Vec<f32>> = planes.into_iter().map(|p| p.data).collect();
        debug_assert_eq!(out.len(), FEATURES.len());
        Ok(Self {
            width: w,
            height: h,
            planes: out,
        })
    }

    /// Pixel `i`'s features into `row`.
    pub fn row(&self, i: usize, row: &mut [f32; FEATURES.len()]) {
        for (r, p) in row.iter_mut().zip(&self.planes) {
            *r = p[i];
        }
    }
}

/// A trained streak classifier: the trees and the probability threshold.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StreakClassifier {
    /// [`FORMAT`].
    pub format: String,
    /// The feature names ([`FEATURES`] when saved by this version).
    pub features: Vec<String>,
    /// A pixel is a streak where the smoothed probability is at least this.
    pub threshold: f32,
    /// Radius of the square box filter applied to the probability before the threshold
    /// (0: none).
    #[serde(default)]
    pub smooth: usize,
    /// What the classifier was trained on and how (free-form, for people).
    pub provenance: serde_json::Value,
    /// The trees.
    pub model: Model,
}

impl StreakClassifier {
    /// A classifier of `model` with this version's format and features, threshold 0.5, no
    /// smoothing and no provenance: what training has before it chooses its operating point.
    pub fn new(model: Model) -> Self {
        Self {
            format: FORMAT.into(),
            features: FEATURES.iter().map(|s| s.to_string()).collect(),
            threshold: 0.5,
            smooth: 0,
            provenance: serde_json::Value::Null,
            model,
        }
    }

    /// Checks a loaded classifier: format, features, the trees.
    pub fn validate(&self) -> Result<(), ClassifierError> {
        if self.format != FORMAT {
            return Err(ClassifierError::Format(format!(
                "format {:?}, expected {FORMAT:?}",
                self.format
            )));
        }
        if self.features != FEATURES || self.model.features != FEATURES.len() {
            return Err(ClassifierError::Format(format!(
                "features {:?}, this version computes {FEATURES:?}",
                self.features
            )));
        }
        if !(0.0..=1.0).contains(&self.threshold) {
            return Err(ClassifierError::Format(format!(
                "threshold {} is not a probability",
                self.threshold
            )));
        }
        self.model.validate()?;
        Ok(())
    }

    /// Parses and checks a classifier saved as JSON.
    pub fn from_json(text: &str) -> Result<Self, ClassifierError> {
        let c: Self =
            serde_json::from_str(text).map_err(|e| ClassifierError::Format(e.to_string()))?;
        c.validate()?;
        Ok(c)
    }

    /// The classifier that ships with the crate (`models/streak_classifier.json`), trained by
    /// `streaks train-detector` on procedural streets (its `provenance` says which).
    pub fn shipped() -> Self {
        Self::from_json(include_str!("../models/streak_classifier.json"))
            .expect("the shipped classifier is valid (tested)")
    }

    /// The streak probability of every pixel of the linear luminance `lum`.
    pub fn probability(&self, lum: &GrayImage, horizon: f32) -> Result<GrayImage, ClassifierError> {
        let f = Features::new(lum, horizon)?;
        let data = self.model.probabilities_of(
            f.width * f.height,
            FEATURES.len(),
            |i, row| f.row(i, row.try_into().expect("one row of FEATURES")),
            |_| true,
            0.0,
        );
        Ok(GrayImage {
            width: f.width,
            height: f.height,
            data,
        })
    }

    /// [`Self::probability`] averaged over the classifier's `smooth` radius: the probability
    /// that [`Self::mask_of`] thresholds.
    pub fn smoothed_probability(
        &self,
        lum: &GrayImage,
        horizon: f32,
    ) -> Result<GrayImage, ClassifierError> {
        Ok(smooth_probability(
            &self.probability(lum, horizon)?,
            self.smooth,
        ))
    }

    /// The streak mask (1 where `p >= threshold`, 0 elsewhere) of a smoothed probability.
    pub fn mask_of(&self, p: &GrayImage) -> GrayImage {
        streak_mask(p, self.threshold, None)
    }

    /// The streak mask (1 on streak pixels, 0 elsewhere) of the linear luminance `lum`.
    pub fn mask(&self, lum: &GrayImage, horizon: f32) -> Result<GrayImage, ClassifierError> {
        Ok(self.mask_of(&self.smoothed_probability(lum, horizon)?))
    }
}

/// `p` averaged over the `(2 r + 1)`-square around each pixel (clipped at the borders);
/// `p` itself for `r = 0`.
pub fn smooth_probability(p: &GrayImage, r: usize) -> GrayImage {
    if r == 0 {
        return p.clone();
    }
    mean(&mean(p, Axis::Rows, r), Axis::Columns, r)
}

/// The streak mask (1 on streaks, 0 elsewhere) of a smoothed streak probability `p`: the
/// pixels where it reaches `threshold`, and with a `grow` threshold (hysteresis) the whole
/// 8-connected regions where it reaches `grow` that hold such a pixel.
pub fn streak_mask(p: &GrayImage, threshold: f32, grow: Option<f32>) -> GrayImage {
    use crate::benchmark::breakdown::components8;
    let mut mask = p.clone();
    match grow {
        None => {
            for v in &mut mask.data {
                *v = f32::from(u8::from(*v >= threshold));
            }
        }
        Some(g) => {
            mask.data.fill(0.0);
            for c in components8(p.width, p.height, |i| p.data[i] >= g.min(threshold)) {
                if c.iter().any(|&i| p.data[i] >= threshold) {
                    for i in c {
                        mask.data[i] = 1.0;
                    }
                }
            }
        }
    }
    mask
}

/// Training rows from one image: the features of every `stride`-th pixel (row-major order,
/// starting at `offset % stride`), labelled by `truth > 0.5`.
pub fn training_rows(
    lum: &GrayImage,
    horizon: f32,
    truth: &GrayImage,
    stride: usize,
    offset: usize,
) -> Result<Dataset, ClassifierError> {
    ensure_same_size("the mask", truth.size(), "the image", lum.size())?;
    let f = Features::new(lum, horizon)?;
    let stride = stride.max(1);
    let mut d = Dataset::new(FEATURES.len());
    let mut row = [0f32; FEATURES.len()];
    for i in (offset % stride..f.width * f.height).step_by(stride) {
        f.row(i, &mut row);
        d.push(&row, truth.data[i] > 0.5);
    }
    Ok(d)
}

/// The operating point for a target `precision` over pooled (probability, truth) pairs: the
/// lowest threshold `t` at which the pixels with `probability >= t` reach that precision against
/// the truth, and their score (the highest recall at that precision); `None` if no threshold
/// does. Ties are kept together: a threshold takes every pixel at or above it.
pub fn operating_point(mut pairs: Vec<(f32, bool)>, precision: f64) -> Option<(f32, MaskScore)> {
    pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
    let truth = pairs.iter().filter(|p| p.1).count();
    let (mut tp, mut best) = (0usize, None);
    let mut i = 0;
    while i < pairs.len() {
        let t = pairs[i].0;
        while i < pairs.len() && pairs[i].0 == t {
            tp += pairs[i].1 as usize;
            i += 1;
        }
        if tp as f64 >= precision * i as f64 && tp > 0 {
            best = Some((t, MaskScore::from_counts(tp, i, truth)));
        }
    }
    best
}

/// The smoothing radii of the probability that [`choose_operating_point`] tries.
pub const SMOOTHING_RADII: std::ops::RangeInclusive<usize> = 0..=2;

/// A classifier's operating point: a smoothing radius, a threshold and the score they give.
#[derive(Clone, Debug, PartialEq)]
pub struct OperatingPoint {
    /// The smoothing radius ([`StreakClassifier::smooth`]).
    pub smooth: usize,
    /// The probability threshold ([`StreakClassifier::threshold`]).
    pub threshold: f32,
    /// The pooled score at them.
    pub score: MaskScore,
}

/// The operating point of a classifier for a target `precision` over `maps`, pairs of its
/// (unsmoothed) probability and the truth on samples it was not trained on: for each radius
/// of [`SMOOTHING_RADII`], the lowest threshold whose pooled precision reaches `precision`
/// ([`operating_point`]); the radius with the highest recall at its threshold wins (the first
/// on ties). `each` hears every radius's point (`None`: no threshold reaches the precision).
pub fn choose_operating_point(
    maps: &[(GrayImage, GrayImage)],
    precision: f64,
    mut each: impl FnMut(usize, Option<&OperatingPoint>),
) -> Option<OperatingPoint> {
    let mut best: Option<OperatingPoint> = None;
    for smooth in SMOOTHING_RADII {
        let pairs: Vec<(f32, bool)> = maps
            .par_iter()
            .flat_map_iter(|(p, truth)| {
                let p = smooth_probability(p, smooth);
                p.data
                    .into_iter()
                    .zip(truth.data.iter().map(|&t| t > 0.5))
                    .collect::<Vec<_>>()
            })
            .collect();
        let point = operating_point(pairs, precision).map(|(threshold, score)| OperatingPoint {
            smooth,
            threshold,
            score,
        });
        each(smooth, point.as_ref());
        if let Some(point) = point {
            if best
                .as_ref()
                .is_none_or(|b| point.score.recall > b.score.recall)
            {
                best = Some(point);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_operating_point_is_chosen_over_every_radius() {
        // A probability that is exact on a 2-pixel streak: radius 0 reaches precision 1 at
        // full recall; smoothing blurs the streak into its neighbours.
        let mut p = GrayImage::new(9, 9, 0.0).unwrap();
        let mut truth = GrayImage::new(9, 9, 0.0).unwrap();
        for y in 3..5 {
            p.set(4, y, 1.0);
            truth.set(4, y, 1.0);
        }
        let mut heard = vec![];
        let best = choose_operating_point(&[(p, truth)], 0.9, |r, point| {
            heard.push((r, point.is_some()))
        })
        .unwrap();
        assert_eq!(heard.iter().map(|h| h.0).collect::<Vec<_>>(), vec![0, 1, 2]);
        assert!(heard[0].1);
        assert_eq!(
            (best.smooth, best.threshold, best.score.recall),
            (0, 1.0, 1.0)
        );
        // No pixel is true: no threshold reaches any precision.
        let none = GrayImage::new(3, 3, 0.0).unwrap();
        assert!(choose_operating_point(&[(none.clone(), none)], 0.9, |_, _| ()).is_none());
    }

    /// A dark road with a diffuse glow and a vertical streak below a lamp, on a black sky:
    /// the streak's pixels, and the luminance.
    fn street(w: usize, h: usize, streak_x: f32, seed: u32) -> (GrayImage, GrayImage) {
        let horizon = h as f32 * 0.4;
        let mut lum = GrayImage::new(w, h, 0.0).unwrap();
        let mut truth = GrayImage::new(w, h, 0.0).unwrap();
        let noise = |x: usize, y: usize| {
            let v = (x as u32).wrapping_mul(73856093) ^ (y as u32).wrapping_mul(19349663) ^ seed;
            (v.wrapping_mul(2654435761) >> 8) as f32 / (1u32 << 24) as f32
        };
        for y in 0..h {
            for x in 0..w {
                let yf = y as f32 + 0.5;
                let mut v = 0.002 * (1.0 + noise(x, y));
                if yf > horizon {
                    // road: a broad diffuse pool plus the streak, a narrow Gaussian
                    let dx = x as f32 + 0.5 - streak_x;
                    v += 0.02 * (-(dx / 40.0).powi(2)).exp();
                    let s = 0.5 * (-(dx / 2.5).powi(2)).exp();
                    v += s;
                    if s > 0.05 {
                        truth.set(x, y, 1.0);
                    }
                } else if (x as f32 + 0.5 - streak_x).abs() < 2.0
                    && (yf - horizon * 0.4).abs() < 2.0
                {
                    v = 20.0; // the lamp
                }
                lum.set(x, y, v);
            }
        }
        (lum, truth)
    }

    #[test]
    fn features_are_named_finite_and_exposure_invariant() {
        let (lum, _) = street(64, 48, 30.0, 1);
        let f = Features::new(&lum, 19.2).unwrap();
        assert_eq!(f.planes.len(), FEATURES.len());
        assert!(f.planes.iter().flatten().all(|v| v.is_finite()));
        // Four times the exposure: the same features (up to the 1e-4 offset).
        let bright = GrayImage {
            data: lum.data.iter().map(|v| 4.0 * v).collect(),
            ..lum.clone()
        };
        let g = Features::new(&bright, 19.2).unwrap();
        for (p, q) in f.planes.iter().zip(&g.planes) {
            for (a, b) in p.iter().zip(q) {
                assert!((a - b).abs() < 0.06, "{a} vs {b}");
            }
        }
        let bad = GrayImage {
            data: vec![f32::NAN; 64 * 48],
            ..lum
        };
        assert!(matches!(
            Features::new(&bad, 19.2),
            Err(ClassifierError::Image(_))
        ));
    }

    #[test]
    fn a_classifier_trained_on_some_streets_finds_the_streak_of_another() {
        let mut data = Dataset::new(FEATURES.len());
        for (i, x) in [14.0, 31.0, 50.0, 22.0].into_iter().enumerate() {
            let (lum, truth) = street(72, 48, x, i as u32);
            data.extend(&training_rows(&lum, 19.2, &truth, 1, 0).unwrap());
        }
        let params = crate::gbdt::TrainParams {
            rounds: 40,
            ..crate::gbdt::TrainParams::default()
        };
        let model = crate::gbdt::train(&data, &params, |_, _| {}).unwrap();
        let c = StreakClassifier {
            format: FORMAT.into(),
            features: FEATURES.iter().map(|s| s.to_string()).collect(),
            threshold: 0.5,
            smooth: 1,
            provenance: serde_json::json!({"test": true}),
            model,
        };
        c.validate().unwrap();
        // A street it never saw: the streak elsewhere, other noise, twice the exposure.
        let (lum, truth) = street(72, 48, 40.0, 99);
        let lum = GrayImage {
            data: lum.data.iter().map(|v| 2.0 * v).collect(),
            ..lum
        };
        let mask = c.mask(&lum, 19.2).unwrap();
        let s = crate::detect::score_mask(&mask, &truth).unwrap();
        assert!(s.precision > 0.9 && s.recall > 0.9, "{s:?}");
        let back = StreakClassifier::from_json(&serde_json::to_string(&c).unwrap()).unwrap();
        assert_eq!(back, c);
    }

    #[test]
    fn the_threshold_is_the_lowest_reaching_the_precision() {
        let pairs = vec![
            (0.9, true),
            (0.8, true),
            (0.7, false),
            (0.6, true),
            (0.5, false),
            (0.4, false),
        ];
        // At 0.6: 3 of 4 = 0.75, all 3 true pixels; at 0.8: 2 of 2.
        let (t, s) = operating_point(pairs.clone(), 0.75).unwrap();
        assert_eq!((t, s.true_positives, s.detected, s.truth), (0.6, 3, 4, 3));
        let (t, s) = operating_point(pairs, 0.9).unwrap();
        assert_eq!((t, s.true_positives, s.detected), (0.8, 2, 2));
        assert!((s.recall - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(operating_point(vec![(0.5, false)], 0.5), None);
    }

    #[test]
    fn the_shipped_classifier_loads_and_bad_files_are_refused() {
        let c = StreakClassifier::shipped();
        assert_eq!(c.features, FEATURES);
        assert!(c.threshold > 0.0 && c.threshold < 1.0);
        let mut bad = c.clone();
        bad.format = "other/1".into();
        assert!(matches!(bad.validate(), Err(ClassifierError::Format(_))));
        let mut bad = c;
        bad.features.pop();
        assert!(matches!(bad.validate(), Err(ClassifierError::Format(_))));
        assert!(matches!(
            StreakClassifier::from_json("{"),
            Err(ClassifierError::Format(_))
        ));
    }
    #[test]
    fn the_streak_mask_grows_from_cores_into_their_faint_tails_only() {
        // Column 1: a core (0.8) with a faint tail (0.3) below it; column 4: a faint speck
        // (0.3) alone.
        let mut p = GrayImage::new(6, 6, 0.0).unwrap();
        for y in 0..2 {
            p.set(1, y, 0.8);
        }
        for y in 2..6 {
            p.set(1, y, 0.3);
        }
        p.set(4, 3, 0.3);
        p.set(4, 4, 0.3);
        let on = |m: &GrayImage| -> Vec<(usize, usize)> {
            (0..36)
                .filter(|&i| m.data[i] > 0.0)
                .map(|i| (i % 6, i / 6))
                .collect()
        };
        assert_eq!(on(&streak_mask(&p, 0.5, None)), vec![(1, 0), (1, 1)]);
        let grown = on(&streak_mask(&p, 0.5, Some(0.2)));
        assert_eq!(grown, (0..6).map(|y| (1, y)).collect::<Vec<_>>());
        // A lower threshold above the tail grows nothing.
        assert_eq!(on(&streak_mask(&p, 0.5, Some(0.4))), vec![(1, 0), (1, 1)]);
    }
}
