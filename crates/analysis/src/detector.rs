//! A streak detector of either kind ready to run on a loaded image, and its score over samples
//! whose streaks are known (a rendered dataset's masks).
//!
//! - [`Detector`]: the learned classifier ([`crate::streak_classifier`], on linear luminance)
//!   or the hand-built rules ([`crate::detect`], on 8-bit luminance); [`Found`] is what it
//!   found in one image.
//! - [`horizon_row`]: the horizon of a sample's camera, for the detector.
//! - [`road_streaks`]: the target of the detector, the streak mask's part on the road.
//! - [`SampleScore`] and [`DatasetScore`]: per-sample scores against both truths, pooled over
//!   the samples with a point of the learned detector's precision-recall curve.
//!
//! Reading images and masks is the caller's: everything here takes loaded images.

use crate::detect::{detect_streaks, score_mask, DetectError, DetectParams, MaskScore};
use crate::streak_classifier::{operating_point, ClassifierError, StreakClassifier};
use serde::Serialize;
use std::path::PathBuf;
use streaks_image::GrayImage;
use streaks_stereo::rigfile::PoseRecord;

/// What went wrong while detecting or scoring.
#[derive(Debug, thiserror::Error)]
pub enum DetectorError {
    /// The hand-built detector, or scoring a mask.
    #[error(transparent)]
    Detect(#[from] DetectError),
    /// The learned classifier.
    #[error(transparent)]
    Classifier(#[from] ClassifierError),
}

/// A detector ready to run.
#[derive(Clone, Debug)]
pub enum Detector {
    /// The learned classifier.
    Learned(Box<StreakClassifier>),
    /// The hand-built detector with these settings (their horizon is replaced per image).
    Hand(DetectParams),
}

/// What a detector found in one image.
#[derive(Clone, Debug)]
pub struct Found {
    /// 1 on streak pixels, 0 elsewhere.
    pub mask: GrayImage,
    /// The learned detector's smoothed streak probability (the mask is where it reaches the
    /// threshold).
    pub probability: Option<GrayImage>,
    /// The number of streaks (regions), for the hand-built detector.
    pub streaks: Option<usize>,
}

impl Detector {
    /// Whether the detector reads linear luminance (an EXR, a raw frame): the learned one
    /// does, the hand-built one reads an 8-bit image's luminance.
    pub fn reads_linear(&self) -> bool {
        matches!(self, Self::Learned(_))
    }

    /// Runs on `image` (linear or 8-bit luminance, see [`Detector::reads_linear`]) with the
    /// horizon at row `horizon` (`None`: the image centre, a level camera).
    pub fn detect(&self, image: &GrayImage, horizon: Option<f32>) -> Result<Found, DetectorError> {
        match self {
            Self::Learned(c) => {
                let horizon = horizon.unwrap_or(0.5 * image.height as f32);
                let p = c.smoothed_probability(image, horizon)?;
                Ok(Found {
                    mask: c.mask_of(&p),
                    probability: Some(p),
                    streaks: None,
                })
            }
            Self::Hand(params) => {
                let params = DetectParams { horizon, ..*params };
                let det = detect_streaks(image, &params)?;
                let mut mask = det.mask;
                for v in &mut mask.data {
                    *v = if *v > 0.5 { 1.0 } else { 0.0 };
                }
                Ok(Found {
                    mask,
                    probability: None,
                    streaks: Some(det.streaks.len()),
                })
            }
        }
    }
}

/// The horizon row (image y) of a camera at `pose` with focal length `focal_px` and principal
/// point row `principal_y`: `c_y - f tan(pitch)`, with the pitch from the pose's -Z axis (the
/// viewing direction), `asin(z_y)` below the horizontal.
pub fn horizon_row(pose: &PoseRecord, principal_y: f32, focal_px: f32) -> f32 {
    let zy = pose.z_axis[1].clamp(-0.999, 0.999);
    let tan_pitch = zy / (1.0 - zy * zy).sqrt();
    principal_y - focal_px * tan_pitch
}

/// The part of the streak mask `streaks` on the road (`road > 0.5`): the streaks that fool
/// stereo into phantom holes, and the detector's target. The masks must be of one size.
pub fn road_streaks(streaks: &GrayImage, road: &GrayImage) -> GrayImage {
    let mut on_road = streaks.clone();
    for (t, &r) in on_road.data.iter_mut().zip(&road.data) {
        if r <= 0.5 {
            *t = 0.0;
        }
    }
    on_road
}

/// The scores of one sample.
#[derive(Clone, Debug, Serialize)]
pub struct SampleScore {
    /// The sample id.
    pub id: String,
    /// Its split.
    pub split: String,
    /// The horizon row used.
    pub horizon: f32,
    /// Streaks the detector found (the hand-built detector; the learned one classifies
    /// pixels).
    pub streaks: Option<usize>,
    /// Against the whole streak mask.
    pub all: MaskScore,
    /// Against its part on the road ([`road_streaks`]); `None` without a road mask.
    pub road: Option<MaskScore>,
}

impl SampleScore {
    /// Scores what was found in sample `id` of `split` (with the horizon at `horizon`) against
    /// the streak mask `truth` and its part on the road `on_road`. Also gives the learned
    /// detector's (probability, on-road truth) per pixel, for the precision-recall curve
    /// (empty for the hand-built detector or without a road mask).
    pub fn new(
        id: &str,
        split: &str,
        horizon: f32,
        found: &Found,
        truth: &GrayImage,
        on_road: Option<&GrayImage>,
    ) -> Result<(Self, Vec<(f32, bool)>), DetectorError> {
        let all = score_mask(&found.mask, truth)?;
        let road = match on_road {
            Some(t) => Some(score_mask(&found.mask, t)?),
            None => None,
        };
        let pairs = match (&found.probability, on_road) {
            (Some(p), Some(t)) => p
                .data
                .iter()
                .zip(&t.data)
                .map(|(&p, &t)| (p, t > 0.5))
                .collect(),
            _ => vec![],
        };
        let score = SampleScore {
            id: id.to_owned(),
            split: split.to_owned(),
            horizon,
            streaks: found.streaks,
            all,
            road,
        };
        Ok((score, pairs))
    }
}

/// The scores of a dataset.
#[derive(Clone, Debug, Serialize)]
pub struct DatasetScore {
    /// The dataset folder.
    pub dataset: PathBuf,
    /// The split scored (`None`: all samples).
    pub split: Option<String>,
    /// The image the detector saw (`im0.png` or `im0.exr`).
    pub image: String,
    /// Pixel-pooled score against the streak masks.
    pub all: MaskScore,
    /// Pixel-pooled score against the road's streaks (samples with a road mask).
    pub road: MaskScore,
    /// The learned detector: the threshold over these samples that gives the highest road
    /// recall at [`AT_PRECISION`] (chosen on the scored samples themselves: a point of their
    /// precision-recall curve, not an operating point); `None` for the hand-built detector or
    /// when no threshold reaches that precision.
    pub road_at_precision: Option<CurvePoint>,
    /// Per sample.
    pub samples: Vec<SampleScore>,
}

/// The precision at which [`DatasetScore::road_at_precision`] reads the curve (the detector's
/// target: recall 0.8 at precision 0.9).
pub const AT_PRECISION: f64 = 0.9;

/// A point of a precision-recall curve.
#[derive(Clone, Debug, Serialize)]
pub struct CurvePoint {
    /// The probability threshold.
    pub threshold: f32,
    /// The pooled score at it.
    pub score: MaskScore,
}

impl DatasetScore {
    /// The samples' scores pooled (pixel counts summed), with the curve point of the
    /// (probability, truth) `pairs` of every sample ([`SampleScore::new`]).
    pub fn pooled(
        dataset: PathBuf,
        split: Option<String>,
        image: String,
        samples: Vec<SampleScore>,
        pairs: Vec<(f32, bool)>,
    ) -> Self {
        let road_at_precision = if pairs.is_empty() {
            None
        } else {
            operating_point(pairs, AT_PRECISION)
                .map(|(threshold, score)| CurvePoint { threshold, score })
        };
        DatasetScore {
            dataset,
            split,
            image,
            all: MaskScore::pooled(samples.iter().map(|s| &s.all)),
            road: MaskScore::pooled(samples.iter().filter_map(|s| s.road.as_ref())),
            road_at_precision,
            samples,
        }
    }

    /// The scores as a text table: one line per sample, then the pooled scores.
    pub fn table(&self) -> String {
        let mut out = String::from(
            "sample  split  horizon  streaks  all P/R (true px)    road P/R (true px)\n",
        );
        let cell = |m: &MaskScore| format!("{:.2}/{:.2} ({:>6})", m.precision, m.recall, m.truth);
        for s in &self.samples {
            out.push_str(&format!(
                "{:<7} {:<6} {:>7.1} {:>8}  {:<20} {}\n",
                s.id,
                s.split,
                s.horizon,
                s.streaks.map_or("-".into(), |n| n.to_string()),
                cell(&s.all),
                s.road
                    .as_ref()
                    .map(cell)
                    .unwrap_or_else(|| "no road mask".into())
            ));
        }
        out.push_str(&format!(
            "pooled over {} samples: all P {:.3} R {:.3} F1 {:.3}; road P {:.3} R {:.3} F1 {:.3}\n",
            self.samples.len(),
            self.all.precision,
            self.all.recall,
            self.all.f1,
            self.road.precision,
            self.road.recall,
            self.road.f1
        ));
        if let Some(c) = &self.road_at_precision {
            out.push_str(&format!(
                "road precision-recall curve: recall {:.3} at precision {:.3} (threshold {:.4}, \
                 chosen on these samples)\n",
                c.score.recall, c.score.precision, c.threshold
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_camera_has_its_horizon_at_the_principal_point() {
        let level = PoseRecord {
            position: [0.0; 3],
            x_axis: [1.0, 0.0, 0.0],
            y_axis: [0.0, 1.0, 0.0],
            z_axis: [0.0, 0.0, 1.0],
        };
        assert_eq!(horizon_row(&level, 120.0, 500.0), 120.0);
        // Pitched down: -Z points below the horizontal, +Z up, the horizon moves up the image.
        let s = 0.1f32;
        let down = PoseRecord {
            z_axis: [0.0, s, (1.0 - s * s).sqrt()],
            ..level
        };
        let h = horizon_row(&down, 120.0, 500.0);
        assert!(
            (h - (120.0 - 500.0 * s / (1.0 - s * s).sqrt())).abs() < 1e-3,
            "{h}"
        );
    }

    #[test]
    fn scores_pool_and_road_truth_is_the_streaks_on_the_road() {
        let streaks = GrayImage::from_vec(4, 1, vec![1.0, 1.0, 0.0, 0.0]).unwrap();
        let road = GrayImage::from_vec(4, 1, vec![1.0, 0.0, 1.0, 0.0]).unwrap();
        let on_road = road_streaks(&streaks, &road);
        assert_eq!(on_road.data, vec![1.0, 0.0, 0.0, 0.0]);
        let found = Found {
            mask: GrayImage::from_vec(4, 1, vec![1.0, 0.0, 1.0, 0.0]).unwrap(),
            probability: Some(GrayImage::from_vec(4, 1, vec![0.9, 0.2, 0.6, 0.1]).unwrap()),
            streaks: None,
        };
        let (s, pairs) =
            SampleScore::new("0", "val", 0.0, &found, &streaks, Some(&on_road)).unwrap();
        assert_eq!((s.all.precision, s.all.recall), (0.5, 0.5));
        assert_eq!(s.road.as_ref().map(|r| r.recall), Some(1.0));
        assert_eq!(pairs.len(), 4);
        let d = DatasetScore::pooled("d".into(), None, "im0.exr".into(), vec![s], pairs);
        // Above 0.6 only the true road pixel remains: precision 1 at threshold 0.9.
        let c = d.road_at_precision.as_ref().unwrap();
        assert_eq!((c.threshold, c.score.recall), (0.9, 1.0));
        assert!(d.table().contains("pooled over 1 samples"));
    }
}
