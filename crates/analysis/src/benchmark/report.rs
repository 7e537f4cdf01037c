//! The parts of a benchmark report (`report.json` of `streaks benchmark`, format
//! `streaks-benchmark/2`) that do not depend on where the samples came from: a method's
//! figures on a sample and pooled over samples, its failures, and what the report states
//! about them. The report's top level (`format`, `input`) is the command's, with the reading
//! of its input. The whole schema:
//!
//! ```text
//! format             "streaks-benchmark/2"
//! input              the folder benchmarked, its kind (dataset, pair, pairs, kitti,
//!                    middlebury) and split
//! aggregation        how the summary pools samples (pixel-weighted)
//! bad_threshold_px   the threshold of `bad` (2.0; bad_1/2/3 are always given)
//! regions            what each region means
//! methods[]          name, kind (built-in, command, batch-command, predictions),
//!                    description, timing (what its seconds cover)
//! summary[]          per method: pooled errors by region, phantom-hole rate, seconds,
//!                    megapixels, seconds per megapixel (`null` for predictions: not
//!                    timed), samples, failed (how many of them the method failed on)
//! samples[]          per sample: id, folder, size, which masks it has (streak_mask,
//!                    road_mask, occlusion_mask), the road-plane check, and per method the
//!                    same figures for that sample alone, with `failure` (kind, reason,
//!                    stderr_tail, stdout_tail) when the method failed on it
//! failure_scoring    how a failed sample counts in the scores
//! unavailable        what a `null` region means
//! ```
//!
//! A method that fails on a sample (a command that exits non-zero, runs past its time limit, is
//! killed by a signal, writes no map or an unreadable one or one of the wrong size; a
//! prediction folder without the sample's map or with a bad one) is left out of its summary,
//! which covers the samples it succeeded on ([`FAILURE_SCORING`]).
//!
//! Errors by region are [`RegionErrors`]: `all`, `streak`, `non_streak`, `road` (road surface
//! off the streaks), `off_road`, `road_surface` (the whole road, whose `below_1px` is the
//! phantom-hole rate) and `non_occluded`; a region whose masks a sample lacks is `null` (not
//! available: KITTI and Middlebury data have no streak or road masks), never zeros
//! ([`UNAVAILABLE`]). Each is a [`crate::sgm::DisparityErrors`] (`truth_pixels`,
//! `valid_pixels`, `density` = the valid share, `mean_abs` = EPE, `rms`, `bad_1`, `bad_2`,
//! `bad_3`, `d1` (KITTI), `bad` and `bad_all` at `threshold`, `below_1px`).

use super::RegionErrors;
use serde::Serialize;

/// The report's format.
pub const FORMAT: &str = "streaks-benchmark/2";

/// How the summary pools samples.
pub const AGGREGATION: &str = "pixel-weighted: every pixel of every sample counts once (the \
    KITTI convention); shares of valid pixels (EPE, bad-N, D1) over all samples' valid pixels, \
    shares of truth pixels (valid share, phantom holes) over all samples' truth pixels";

/// How a failed sample counts, as the report states it.
pub const FAILURE_SCORING: &str = "a method's summary covers the samples it succeeded on \
    (`samples` minus `failed`), time included: methods whose `failed` differ were scored on \
    different samples; a sample it failed on keeps its failure and the figures of a map with no \
    value (valid share 0, no phantom-hole rate); a method that failed on every sample has no \
    values in its summary";

/// The regions, as the report states them.
pub const REGIONS: [(&str, &str); 7] = [
    ("all", "every pixel with a ground truth"),
    ("streak", "the renderer's streak mask"),
    ("non_streak", "every pixel off the streak mask"),
    (
        "road",
        "the road surface (the renderer's road mask) off the streaks",
    ),
    ("off_road", "neither streak nor road"),
    (
        "road_surface",
        "the whole road mask, streaks included; its below_1px is the phantom-hole rate",
    ),
    (
        "non_occluded",
        "the pixels the right view also sees (KITTI disp_noc_0, Middlebury mask0nocc.png)",
    ),
];

/// What a `null` region means, as the report states it.
pub const UNAVAILABLE: &str = "a region is null where the samples lack its masks (KITTI and \
    Middlebury folders have no streak or road masks): not available, not zero; a pooled region \
    covers the samples that have it";

/// Why a method failed on a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// The command could not be started (no such program, not executable).
    Spawn,
    /// It exited with a non-zero status.
    Exit,
    /// It was killed by a signal (not by the time limit).
    Signal,
    /// It ran past `--method-timeout`; its process group was killed.
    Timeout,
    /// It exited with status 0 but wrote no map.
    NoOutput,
    /// A prediction folder (`--predictions`) has no map for the sample.
    Missing,
    /// Its map is not a regular file, not a readable PFM or KITTI PNG, too large, or of the
    /// wrong size.
    BadOutput,
    /// A built-in method's error, or the run could not prepare the command.
    Error,
}

/// A method's failure on one sample.
#[derive(Clone, Debug, Serialize)]
pub struct Failure {
    /// What kind of failure.
    pub kind: FailureKind,
    /// What happened, in a sentence.
    pub reason: String,
    /// The end of the command's stderr (its last lines, at most a few thousand characters;
    /// empty for a built-in).
    pub stderr_tail: String,
    /// The end of its stdout, likewise.
    pub stdout_tail: String,
}

/// A method.
#[derive(Clone, Debug, Serialize)]
pub struct MethodInfo {
    /// Its name.
    pub name: String,
    /// `built-in`, `command` (a process per sample), `batch-command` (one process for all
    /// samples) or `predictions` (maps read from a folder).
    pub kind: &'static str,
    /// What it does (for a command: its template; for predictions: the folder).
    pub description: String,
    /// What its seconds cover.
    pub timing: &'static str,
}

/// One method's figures over some pixels (a sample, or all of them).
#[derive(Clone, Debug, Serialize)]
pub struct MethodScore {
    /// The method.
    pub method: String,
    /// Errors by region.
    pub errors: RegionErrors,
    /// The phantom-hole rate (`errors.road_surface.below_1px`; `null` without road masks, and
    /// for a failure).
    pub phantom_hole_rate: Option<f64>,
    /// The method's wall time, seconds (`None` for predictions: not timed).
    pub seconds: Option<f64>,
    /// Megapixels estimated.
    pub megapixels: f64,
    /// `seconds / megapixels` (`None` when not timed).
    pub seconds_per_megapixel: Option<f64>,
    /// Samples the method ran on.
    pub samples: usize,
    /// How many of them it failed on; the other figures leave them out (see
    /// [`FAILURE_SCORING`]).
    pub failed: usize,
    /// Why the method failed on this sample (per-sample figures only; absent when it did
    /// not).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<Failure>,
}

impl MethodScore {
    /// The figures of `method` on one sample from its errors and time, and its failure there
    /// if it failed.
    pub fn new(
        method: &str,
        errors: RegionErrors,
        seconds: Option<f64>,
        megapixels: f64,
        failure: Option<Failure>,
    ) -> Self {
        Self {
            samples: 1,
            failed: usize::from(failure.is_some()),
            method: method.to_string(),
            phantom_hole_rate: errors.phantom_hole_rate().filter(|_| failure.is_none()),
            failure,
            errors,
            seconds,
            megapixels,
            seconds_per_megapixel: seconds.map(|s| {
                if megapixels > 0.0 {
                    s / megapixels
                } else {
                    0.0
                }
            }),
        }
    }

    /// The pooled figures of one method's per-sample figures: over the samples it succeeded
    /// on, or, when it failed on all, their maps with no value (and no phantom-hole rate).
    pub fn pooled(method: &str, parts: &[&MethodScore]) -> Option<Self> {
        let succeeded: Vec<&MethodScore> = parts
            .iter()
            .copied()
            .filter(|p| p.failure.is_none())
            .collect();
        let scored = if succeeded.is_empty() {
            parts
        } else {
            &succeeded
        };
        let errors: Vec<RegionErrors> = scored.iter().map(|p| p.errors).collect();
        let pooled = Self::new(
            method,
            RegionErrors::pooled(&errors)?,
            scored.iter().map(|p| p.seconds).sum::<Option<f64>>(),
            scored.iter().map(|p| p.megapixels).sum(),
            None,
        );
        Some(Self {
            samples: parts.iter().map(|p| p.samples).sum(),
            failed: parts.iter().map(|p| p.failed).sum(),
            phantom_hole_rate: pooled.phantom_hole_rate.filter(|_| !succeeded.is_empty()),
            ..pooled
        })
    }
}

/// Per method of `methods`, in order, its figures pooled over `samples`
/// ([`MethodScore::pooled`]); `None` if a method has no figures on any sample.
pub fn summary<'a>(
    methods: impl IntoIterator<Item = &'a str>,
    samples: &[SampleReport],
) -> Option<Vec<MethodScore>> {
    methods
        .into_iter()
        .map(|m| {
            let parts: Vec<&MethodScore> = samples
                .iter()
                .flat_map(|s| s.results.iter().filter(|r| r.method == m))
                .collect();
            MethodScore::pooled(m, &parts)
        })
        .collect()
}

/// One sample.
#[derive(Clone, Debug, Serialize)]
pub struct SampleReport {
    /// Its id.
    pub id: String,
    /// Its folder.
    pub dir: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Whether it has a streak mask (else the streak regions are `null`).
    pub streak_mask: bool,
    /// Whether it has a road mask (else the road regions are `null`).
    pub road_mask: bool,
    /// Whether it has an occlusion mask (else `non_occluded` is `null`).
    pub occlusion_mask: bool,
    /// How far its road departs from the plane `Y = 0` the analysis assumes, when it has a
    /// road mask and a ground-truth depth ([`crate::road_plane`]).
    pub road_plane: Option<crate::road_plane::RoadPlaneCheck>,
    /// Per method.
    pub results: Vec<MethodScore>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmark::{score_regions, Masks};
    use streaks_image::GrayImage;

    #[test]
    fn failures_are_left_out_of_the_summary() {
        let truth = GrayImage::new(4, 2, 5.0).unwrap();
        let streaks = GrayImage::new(4, 2, 0.0).unwrap();
        let road = GrayImage::new(4, 2, 255.0).unwrap();
        let score = |estimate: f32| {
            let est = GrayImage::new(4, 2, estimate).unwrap();
            let masks = Masks {
                streaks: Some(&streaks),
                road: Some(&road),
                non_occluded: None,
            };
            score_regions(&est, &truth, &masks).unwrap()
        };
        let failure = || Failure {
            kind: FailureKind::Timeout,
            reason: "slow".into(),
            stderr_tail: String::new(),
            stdout_tail: String::new(),
        };
        // Below the road everywhere where it succeeded; no value where it failed.
        let ok = MethodScore::new("m", score(1.0), Some(2.0), 1.0, None);
        let failed = MethodScore::new("m", score(f32::INFINITY), Some(600.0), 1.0, Some(failure()));
        assert_eq!((failed.failed, failed.phantom_hole_rate), (1, None));
        let pooled = MethodScore::pooled("m", &[&ok, &failed]).unwrap();
        assert_eq!((pooled.samples, pooled.failed), (2, 1));
        assert_eq!(pooled.errors, ok.errors);
        assert_eq!(pooled.phantom_hole_rate, Some(1.0));
        assert_eq!(
            (pooled.seconds, pooled.seconds_per_megapixel),
            (Some(2.0), Some(2.0))
        );
        // Predictions are not timed: no time, pooled or not.
        let untimed = MethodScore::new("p", score(1.0), None, 0.5, None);
        let pooled = MethodScore::pooled("p", &[&untimed, &untimed]).unwrap();
        assert_eq!((pooled.seconds, pooled.seconds_per_megapixel), (None, None));
        assert_eq!(pooled.megapixels, 1.0);
        assert!(pooled.failure.is_none());
        // Every sample failed: no values, no phantom-hole rate.
        let all = MethodScore::pooled("m", &[&failed, &failed]).unwrap();
        assert_eq!((all.samples, all.failed), (2, 2));
        assert_eq!(
            (all.errors.all.valid_pixels, all.phantom_hole_rate),
            (0, None)
        );
    }
}
