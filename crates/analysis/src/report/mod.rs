//! Per-streak analysis of a rectified stereo pair (the paper's Fig. 6 and Fig. 8 measurements).
//!
//! [`analyze`] takes a pair written by `streaks stereo` or a dataset sample
//! ([`StereoInput::load`], through [`streaks_dataset::SampleDir`]: the two EXRs, the rig
//! (`rig.json`, or a sample's `meta.json`), and the left view's ground-truth disparity and
//! depth when present), detects the streaks of the left image ([`crate::detect`]), matches each to the
//! scene light whose mirror image `(X_L, -Y_L, Z_L)` projects nearest the streak's axis (below
//! the light), measures its disparity row by row with the 1D Lucas-Kanade estimator along the
//! streak's centres ([`crate::lk::lk_rows`]) and predicts it with Eq. 4 and Eq. 5
//! ([`crate::model::streak_rows`]). For every row it records the depth a stereo system would
//! assign (`Z = f b / d`) and how far below the road the implied 3D point lies (the pixel
//! back-projected at that depth, its Y in the road frame). Thin vertical objects (poles, found in
//! the ground-truth depth), plain road (the most textured road pixel of every row) and named
//! regions are measured the same way against their ground truth, as in Fig. 8; rows whose
//! match has a low NCC are left out of their RMS and counted. Every LK measurement, streaks
//! and regions, is made on the pair with its Monte Carlo fireflies removed and its range
//! log-compressed ([`crate::lk::despeckle`], [`crate::lk::log_compress`]): a single firefly
//! in a window outweighs a dark road's texture and a faint streak alike. A dense SGM disparity
//! ([`crate::sgm`]) gives the point cloud of the side view, and is scored against the ground
//! truth (bad-2.0, mean error) on streak and other pixels.
//!
//! [`write_outputs`] writes `report.json`, one disparity-against-row plot per region, a
//! disparity (inverse depth) map with the streak pixels marked, and the side view of the point
//! cloud (Z forward against Y up) that shows the streaks' columns below the road.
//!
//! # Stages, one file each
//!
//! - `mod.rs` (this file): the errors ([`ReportError`]) and the report's types, what
//!   `report.json` holds ([`Report`], [`StreakReport`], [`RegionReport`], [`RowRecord`],
//!   [`RigSummary`]) and [`Analysis`].
//! - `input.rs`: loading a pair ([`StereoInput`]), and the input's rig as the stages use it.
//!   Every angle, the horizon and the projection come from the stereo crate's camera model,
//!   [`streaks_stereo::rig::RoadRig`]; the report computes none of its own.
//! - `stats.rs`: line fits ([`fit_line`]), measured against predicted ([`compare`]), spans and
//!   medians.
//! - `lights.rs`: which scene light makes a streak ([`MatchedLight`]).
//! - `targets.rs`: what else to measure, picked from the ground truth: poles and plain road.
//! - `dense.rs`: the dense SGM disparity over the scene's range, its point cloud in the road
//!   frame ([`DenseSummary`]) and its score against the ground truth ([`dense_accuracy`]).
//! - `pipeline.rs`: the analysis itself ([`analyze`], [`AnalyzeParams`]): streaks and regions
//!   measured row by row against their predictions; [`analyze_dir`], a pair folder read,
//!   analysed and written into its `analysis/` folder in one call.
//! - `output.rs`: plots ([`rows_plot`]), `report.json` ([`write_report_json`]), every output
//!   file ([`write_outputs`]) and the console table ([`summary_table`]).

mod dense;
mod input;
mod lights;
mod output;
mod pipeline;
mod stats;
mod targets;

pub use dense::{dense_accuracy, DenseAccuracy, DenseSummary};
pub use input::StereoInput;
pub use lights::MatchedLight;
pub use output::{rows_plot, summary_table, write_outputs, write_report_json};
pub use pipeline::{analyze, analyze_dir, AnalyzeParams, DirAnalysis};
pub use stats::{compare, fit_line, Comparison, LineFit};

use crate::detect::{DetectError, MaskScore};
use crate::lk::LkError;
use crate::model::ModelError;
use crate::plot::PlotError;
use crate::road_plane::RoadPlaneCheck;
use crate::sgm::SgmError;
use serde::Serialize;
use std::path::PathBuf;
use streaks_image::{GrayImage, ImageError, Region};
use streaks_stereo::error::StereoError;

/// Errors of the analysis.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// An input or output image.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The rig file or its geometry.
    #[error(transparent)]
    Stereo(#[from] StereoError),
    /// The LK estimator.
    #[error("{what}: {source}")]
    Lk {
        /// Which measurement.
        what: String,
        /// The estimator's error.
        source: LkError,
    },
    /// Streak detection.
    #[error(transparent)]
    Detect(#[from] DetectError),
    /// Dense matching.
    #[error(transparent)]
    Sgm(#[from] SgmError),
    /// The column model.
    #[error("{what}: {source}")]
    Model {
        /// Which prediction.
        what: String,
        /// The model's error.
        source: ModelError,
    },
    /// A plot.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// An input is missing or inconsistent.
    #[error("{path}: {reason}")]
    Input {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// Writing an output.
    #[error("writing {path}: {reason}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A stage of [`analyze_dir`] failed on a pair folder (reading it, analysing it, writing
    /// the analysis).
    #[error("{stage} {}", dir.display())]
    Folder {
        /// What was being done, e.g. "reading the pair in".
        stage: &'static str,
        /// The folder.
        dir: PathBuf,
        /// The stage's error.
        #[source]
        source: Box<ReportError>,
    },
    /// A parameter is out of range.
    #[error("invalid analysis parameter {name}: {reason}")]
    Param {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: String,
    },
}

/// One image row of a measured region.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RowRecord {
    /// Row index.
    pub row: usize,
    /// Left-image x of the measurement.
    pub x: f32,
    /// Elevation of the row's ray below the horizon, degrees (positive below).
    pub elevation_deg: f64,
    /// Measured disparity, pixels.
    pub measured_px: f64,
    /// Measured disparity as an angle (left minus right azimuth), degrees.
    pub measured_deg: f64,
    /// Predicted disparity (Eq. 4 + 5 for a streak; ground truth for a region), pixels.
    pub predicted_px: Option<f64>,
    /// Predicted disparity, degrees.
    pub predicted_deg: Option<f64>,
    /// For a streak: the streak-centre model's disparity ([`crate::centre`]), pixels.
    pub centre_px: Option<f64>,
    /// The streak-centre model's disparity, degrees.
    pub centre_deg: Option<f64>,
    /// For a streak: the disparity of the road point seen through the pixel (what a matte
    /// road would give), pixels.
    pub road_px: Option<f64>,
    /// The depth stereo assigns, `f b / d`, metres (`inf` for `d <= 0`).
    pub depth_m: f64,
    /// Height above the road of the point that depth implies, metres (negative: below).
    pub road_y_m: f64,
    /// Forward distance of that point in the road frame, metres.
    pub road_z_m: f64,
    /// NCC of the LK match.
    pub ncc: f32,
}

/// One streak's measurement.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StreakReport {
    /// Index among the detected streaks.
    pub index: usize,
    /// First row.
    pub first_row: usize,
    /// Last row (inclusive).
    pub last_row: usize,
    /// Brightest value.
    pub peak: f32,
    /// The light that makes it, if one matched.
    pub light: Option<MatchedLight>,
    /// Per row.
    pub rows: Vec<RowRecord>,
    /// Measured against Eq. 4.
    pub comparison: Option<Comparison>,
    /// Measured against the streak-centre model ([`crate::centre`]) over the rows that have
    /// both, if a light matched.
    pub centre_comparison: Option<Comparison>,
    /// The road's disparity span over the same rows (what a matte road would give), pixels.
    pub road_span_px: Option<f64>,
    /// Median depth stereo assigns along the streak, metres.
    pub median_depth_m: f64,
    /// Median height of the implied points above the road (negative: below), metres.
    pub median_road_y_m: f64,
    /// Lowest implied point, metres.
    pub min_road_y_m: f64,
}

/// A measured region (a vertical object or plain road).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RegionReport {
    /// Its name.
    pub name: String,
    /// `object`, `road` or `named`.
    pub kind: String,
    /// The pixels: a named region is measured at its centre column, an object at its centre
    /// in every row, the road at the most textured road pixel of every row (each row's `x`).
    pub region: Region,
    /// LK window width, pixels (an object's is fitted to its width).
    pub window: usize,
    /// Rows whose NCC is below this are left out of `comparison`.
    pub min_ncc: f32,
    /// How many rows were left out.
    pub low_confidence_rows: usize,
    /// Per row; `predicted` is the ground-truth disparity.
    pub rows: Vec<RowRecord>,
    /// Measured against the ground truth over the confident rows.
    pub comparison: Option<Comparison>,
    /// Measured against the ground truth over every row.
    pub comparison_all_rows: Option<Comparison>,
}

/// The rig as the report states it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RigSummary {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Focal length, pixels.
    pub focal_px: f32,
    /// Baseline, metres.
    pub baseline_m: f32,
    /// Rig height above the road, metres.
    pub height_m: f32,
    /// Downward pitch, degrees.
    pub pitch_deg: f64,
    /// Image row of the horizon.
    pub horizon_row: f64,
}

/// `report.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The rig.
    pub rig: RigSummary,
    /// The horizon row used by the detector.
    pub horizon_row: f32,
    /// Lamps found by the detector.
    pub lamps: usize,
    /// Glows found by the detector (bright regions below the horizon reaching the bottom row:
    /// the near end of a reflection; in the streak mask, not measured by LK).
    pub glows: usize,
    /// The streaks.
    pub streaks: Vec<StreakReport>,
    /// Vertical objects, road and named regions.
    pub regions: Vec<RegionReport>,
    /// The dense disparity.
    pub dense: DenseSummary,
    /// The detector's streak pixels scored against the renderer's streak mask, when the input
    /// has one (`streak_mask_left.png`).
    pub detection: Option<MaskScore>,
    /// The same against only the mask's road streaks: pixels below the horizon in connected
    /// components taller than wide ([`crate::detect::vertical_truth`]). The renderer's mask
    /// also marks glints on windows and broad glossy road, which the detector does not look
    /// for; this recall is the honest measure of the detector (its precision counts
    /// detections outside those components as false).
    pub detection_vertical: Option<MaskScore>,
    /// How far the road departs from the plane `Y = 0` that Eq. 4 and the streak-centre model
    /// assume, from the ground-truth depth and road mask when the input has both. When it is
    /// violated, no streak gets a prediction (docs/decisions/0048).
    pub road_plane: Option<RoadPlaneCheck>,
}

/// The report and the images it was made from.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// The numbers.
    pub report: Report,
    /// The detector's streak mask of the left image.
    pub streak_mask: GrayImage,
    /// The SGM disparity of the left image (`inf` where invalid).
    pub dense: GrayImage,
}
