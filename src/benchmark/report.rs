//! `OUT/report.json` of `streaks benchmark`: the report's top level, [`Report`]; its schema
//! and every part but the input are [`streaks_analysis::benchmark::report`]'s.

use serde::Serialize;
pub use streaks_analysis::benchmark::report::{
    breakdown_definitions, by_condition, summary, ConditionSummary, Failure, FailureKind,
    MethodInfo, MethodScore, SampleReport, AGGREGATION, FAILURE_SCORING, FORMAT, REGIONS,
    UNAVAILABLE,
};

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// [`FORMAT`].
    pub format: &'static str,
    /// What was benchmarked.
    pub input: Input,
    /// [`AGGREGATION`].
    pub aggregation: &'static str,
    /// The threshold of `bad` and `bad_all`, pixels.
    pub bad_threshold_px: f32,
    /// [`REGIONS`] as a map.
    pub regions: serde_json::Map<String, serde_json::Value>,
    /// The methods, in the order run.
    pub methods: Vec<MethodInfo>,
    /// [`breakdown_definitions`]: what the breakdowns mean.
    pub breakdown: serde_json::Map<String, serde_json::Value>,
    /// Per method, over all samples.
    pub summary: Vec<MethodScore>,
    /// Per condition, per method, over the samples in it ([`by_condition`]; `None` when no
    /// sample has a `meta.json`).
    pub by_condition: Option<Vec<ConditionSummary>>,
    /// Per sample.
    pub samples: Vec<SampleReport>,
    /// [`FAILURE_SCORING`].
    pub failure_scoring: &'static str,
    /// [`UNAVAILABLE`]: what a `null` region means.
    pub unavailable: &'static str,
}

/// The input folder.
#[derive(Clone, Debug, Serialize)]
pub struct Input {
    /// The folder as given.
    pub dir: String,
    /// What it is.
    pub kind: super::input::InputKind,
    /// The dataset split, if one was chosen.
    pub split: Option<String>,
}
