//! The parts of a benchmark report (`report.json` of `streaks benchmark`, format
//! `streaks-benchmark/3`) that do not depend on where the samples came from: a method's
//! figures on a sample and pooled over samples, its failures, and what the report states
//! about them. The report's top level (`format`, `input`) is the command's, with the reading
//! of its input. The whole schema:
//!
//! ```text
//! format             "streaks-benchmark/3"
//! input              the folder benchmarked, its kind (dataset, pair, pairs, kitti,
//!                    middlebury) and split
//! aggregation        how the summary pools samples (pixel-weighted)
//! bad_threshold_px   the threshold of `bad` (2.0; bad_1/2/3 are always given)
//! regions            what each region means
//! methods[]          name, kind (built-in, command, batch-command, predictions),
//!                    description, timing (what its seconds cover)
//! breakdown          what the breakdowns mean (condition, streak_length, distance,
//!                    empty_bins)
//! summary[]          per method: pooled errors by region, phantom-hole rate, breakdown
//!                    (streak_length, road_surface_by_distance, off_road_by_distance: each
//!                    a list of {bin, errors}, errors null for a bin without pixels),
//!                    seconds, megapixels, seconds per megapixel (`null` for predictions:
//!                    not timed), samples, failed (how many of them the method failed on)
//! by_condition[]     per condition (dry, rain, fog, noise): condition, samples, and a
//!                    summary[] over those samples (null when no sample has a meta.json)
//! samples[]          per sample: id, folder, size, which masks it has (streak_mask,
//!                    road_mask, occlusion_mask), its conditions (null without a
//!                    meta.json), the road-plane check, and per method the
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
//! `bad_3`, `d1` (KITTI), `bad` and `bad_all` at `threshold`, `below_1px`, `bad_2_filled`:
//! bad-2 over every truth pixel after KITTI's background fill of the missing values).
//!
//! Version 3 adds `breakdown`, `by_condition`, each figure's `breakdown` and each sample's
//! `conditions` to version 2; every field of version 2 is still there and means the same.

use super::breakdown::{Breakdown, DISTANCE_BINS, STREAK_LENGTH_BINS};
use super::RegionErrors;
use serde::Serialize;
use streaks_dataset::meta::{Condition, NOISE_GAIN_EV};

/// The report's format.
pub const FORMAT: &str = "streaks-benchmark/3";

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
    /// Errors by streak length and by distance ([`Breakdown`]).
    pub breakdown: Breakdown,
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
            breakdown: Breakdown::default(),
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

    /// These figures with their breakdown by streak length and distance.
    pub fn with_breakdown(self, breakdown: Breakdown) -> Self {
        Self { breakdown, ..self }
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
        let breakdowns: Vec<&Breakdown> = scored.iter().map(|p| &p.breakdown).collect();
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
            breakdown: Breakdown::pooled(&breakdowns),
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
    summary_of(methods, &samples.iter().collect::<Vec<_>>())
}

/// [`summary`] of some of the samples.
fn summary_of<'a>(
    methods: impl IntoIterator<Item = &'a str>,
    samples: &[&SampleReport],
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

/// The figures of the samples in one condition.
#[derive(Clone, Debug, Serialize)]
pub struct ConditionSummary {
    /// The condition.
    pub condition: Condition,
    /// How many samples are in it.
    pub samples: usize,
    /// Per method, its figures pooled over those samples as in the summary (empty when no
    /// sample is in the condition: not available, not zero).
    pub summary: Vec<MethodScore>,
}

/// Per condition of [`Condition::ALL`], the figures of `methods` pooled over the samples in it
/// ([`summary`]); `None` when no sample has conditions (no `meta.json`: pair folders, KITTI,
/// Middlebury).
pub fn by_condition<'a>(
    methods: impl IntoIterator<Item = &'a str> + Clone,
    samples: &[SampleReport],
) -> Option<Vec<ConditionSummary>> {
    if samples.iter().all(|s| s.conditions.is_none()) {
        return None;
    }
    Some(
        Condition::ALL
            .into_iter()
            .map(|c| {
                let in_it: Vec<&SampleReport> = samples
                    .iter()
                    .filter(|s| s.conditions.as_ref().is_some_and(|cs| cs.contains(&c)))
                    .collect();
                ConditionSummary {
                    condition: c,
                    samples: in_it.len(),
                    summary: summary_of(methods.clone(), &in_it).unwrap_or_default(),
                }
            })
            .collect(),
    )
}

/// The breakdowns' definitions, as the report states them (`breakdown`).
pub fn breakdown_definitions() -> serde_json::Map<String, serde_json::Value> {
    let names =
        |bins: &[super::breakdown::Bin]| bins.iter().map(|b| b.name).collect::<Vec<_>>().join(", ");
    [
        (
            "condition",
            format!(
                "per sample, from its meta.json weather record: rain = rain_mm_h > 0; fog = fog \
                 not null; dry = neither rain nor fog (also a sample without a weather record); \
                 noise = the auto-exposure gain log2(sensor preset exposure_s / exposure_s) > \
                 {NOISE_GAIN_EV} stops (a shutter shorter than the preset's) with a preset that \
                 has noise; a sample can be in several; samples without meta.json have none \
                 (by_condition is null when no sample has one); each condition's summary pools \
                 its samples as the summary does"
            ),
        ),
        (
            "streak_length",
            format!(
                "the streak pixels on the road (streak and road masks), by the vertical extent \
                 (rows spanned) of their streak, an 8-connected component of those pixels, as a \
                 share of the image height: {} below {}, {} {} to {}, {} from {}; null without \
                 the masks",
                STREAK_LENGTH_BINS[0].name,
                STREAK_LENGTH_BINS[0].high,
                STREAK_LENGTH_BINS[1].name,
                STREAK_LENGTH_BINS[1].low,
                STREAK_LENGTH_BINS[1].high,
                STREAK_LENGTH_BINS[2].name,
                STREAK_LENGTH_BINS[2].low,
            ),
        ),
        (
            "distance",
            format!(
                "the ground-truth depth (depth0.pfm, metres) in bins {}: \
                 road_surface_by_distance is the whole road mask (its below_1px the \
                 phantom-hole rate), off_road_by_distance the pixels neither streak nor road \
                 (read its bad_2); null without a depth or the masks",
                names(&DISTANCE_BINS)
            ),
        ),
        (
            "empty_bins",
            "a bin without a pixel with ground truth has errors null (not available, never \
             0); each bin is pooled pixel-weighted over the samples with pixels in it"
                .to_string(),
        ),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), serde_json::Value::from(v)))
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
    /// The conditions it was rendered in, from its `meta.json` (`None` without one: pair
    /// folders, KITTI, Middlebury).
    pub conditions: Option<Vec<Condition>>,
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

    #[test]
    fn conditions_pool_their_own_samples() {
        let truth = GrayImage::new(2, 1, 5.0).unwrap();
        let sample = |id: &str, estimate: f32, conditions: Option<Vec<Condition>>| {
            let est = GrayImage::new(2, 1, estimate).unwrap();
            let errors = score_regions(&est, &truth, &Masks::default()).unwrap();
            SampleReport {
                id: id.into(),
                dir: id.into(),
                width: 2,
                height: 1,
                streak_mask: false,
                road_mask: false,
                occlusion_mask: false,
                conditions,
                road_plane: None,
                results: vec![MethodScore::new("m", errors, None, 2e-6, None)],
            }
        };
        use Condition::*;
        // a: rain, 1 px off; b: rain and noise, exact; c: dry, exact.
        let samples = [
            sample("a", 6.0, Some(vec![Rain])),
            sample("b", 5.0, Some(vec![Rain, Noise])),
            sample("c", 5.0, Some(vec![Dry])),
        ];
        let by = by_condition(["m"], &samples).unwrap();
        let names: Vec<_> = by.iter().map(|c| (c.condition, c.samples)).collect();
        assert_eq!(names, [(Dry, 1), (Rain, 2), (Fog, 0), (Noise, 1)]);
        assert_eq!(by[1].summary[0].errors.all.truth_pixels, 4);
        assert_eq!(by[1].summary[0].errors.all.mean_abs, 0.5);
        assert_eq!(by[0].summary[0].errors.all.mean_abs, 0.0);
        // No sample in fog: no figures at all, not zeros.
        assert!(by[2].summary.is_empty());
        // Without any meta.json there is no breakdown by condition.
        let pairs = [sample("p", 5.0, None)];
        assert!(by_condition(["m"], &pairs).is_none());
        let defs = breakdown_definitions();
        assert!(defs["streak_length"]
            .as_str()
            .unwrap()
            .contains("short below 0.05, medium 0.05 to 0.2, long from 0.2;"));
    }
}
