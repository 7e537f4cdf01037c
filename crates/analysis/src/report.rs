//! Per-streak analysis of a rectified stereo pair (the paper's Fig. 6 and Fig. 8 measurements).
//!
//! [`analyze`] takes a pair written by `streaks stereo` ([`StereoInput::load`]: `left.exr`,
//! `right.exr`, `rig.json`, and the ground truth `disparity_left.pfm` / `depth_left.pfm` when
//! present), detects the streaks of the left image ([`crate::detect`]), matches each to the
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
//! in a window outweighs a dark road's texture and a faint streak alike. A dense SGM disparity ([`crate::sgm`]) gives the point cloud of the side view, and
//! is scored against the ground truth (bad-2.0, mean error) on streak and other pixels.
//!
//! [`write_outputs`] writes `report.json`, one disparity-against-row plot per region, a
//! disparity (inverse depth) map with the streak pixels marked, and the side view of the point
//! cloud (Z forward against Y up) that shows the streaks' columns below the road.

use crate::detect::{
    detect_streaks, score_mask, vertical_truth, DetectError, DetectParams, MaskScore, Streak,
};
use crate::lk::{lk_rows, prepare_pair, LkError, LkParams, Region, RowDisparity};
use crate::model::{streak_rows, ModelError, RoadCamera, StereoRig};
use crate::plot::{Marker, Plot, PlotError, Series, BLACK_RGB, BLUE, GREY, RED};
use crate::sgm::{
    compare_disparity_where, disparity_preview, sgm, DisparityErrors, SgmError, SgmParams,
};
use glam::{DVec2, DVec3, Vec2, Vec3};
use serde::Serialize;
use std::path::{Path, PathBuf};
use streaks_stereo::error::StereoError;
use streaks_stereo::image::{save_rgb8_png, write_file_atomic, GrayImage, ImageError};
use streaks_stereo::pfm::read_pfm;
use streaks_stereo::rig::{Eye, Rig, RoadFrame};
use streaks_stereo::rigfile::{LightRecord, RigFile};

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
    /// A parameter is out of range.
    #[error("invalid analysis parameter {name}: {reason}")]
    Param {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: String,
    },
}

/// A pair and what is known about it.
#[derive(Clone, Debug)]
pub struct StereoInput {
    /// Left image (linear luminance).
    pub left: GrayImage,
    /// Right image.
    pub right: GrayImage,
    /// The rig.
    pub rig: Rig,
    /// The scene's lights.
    pub lights: Vec<LightRecord>,
    /// Ground-truth disparity of the left image (`inf` where nothing was hit), if known.
    pub truth_disparity: Option<GrayImage>,
    /// Ground-truth depth of the left image, if known.
    pub truth_depth: Option<GrayImage>,
    /// The renderer's streak mask of the left image (`streak_mask_left.png`), if present.
    pub truth_streak_mask: Option<GrayImage>,
}

impl StereoInput {
    /// Loads `dir/{left,right}.exr` (or `.png` when there is no EXR), `dir/rig.json` and the
    /// ground truth `dir/disparity_left.pfm`, `dir/depth_left.pfm` and the renderer's streak
    /// mask `dir/streak_mask_left.png` if present.
    pub fn load(dir: &Path) -> Result<Self, ReportError> {
        let image = |name: &str| -> Result<GrayImage, ReportError> {
            let exr = dir.join(format!("{name}.exr"));
            let path = if exr.exists() {
                exr
            } else {
                dir.join(format!("{name}.png"))
            };
            Ok(GrayImage::load(&path)?)
        };
        let (left, right) = (image("left")?, image("right")?);
        let file = RigFile::load(&dir.join("rig.json"))?;
        let rig = file.rig()?;
        let optional = |name: &str| -> Result<Option<GrayImage>, ReportError> {
            let p = dir.join(name);
            Ok(if p.exists() {
                Some(read_pfm(&p)?)
            } else {
                None
            })
        };
        let input = Self {
            left,
            right,
            rig,
            lights: file.lights,
            truth_disparity: optional("disparity_left.pfm")?,
            truth_depth: optional("depth_left.pfm")?,
            truth_streak_mask: {
                let p = dir.join("streak_mask_left.png");
                if p.exists() {
                    Some(GrayImage::load(&p)?)
                } else {
                    None
                }
            },
        };
        let i = input.rig.intrinsics();
        let size = (i.width() as usize, i.height() as usize);
        let named = [
            ("left image", Some(&input.left)),
            ("right image", Some(&input.right)),
            ("disparity_left.pfm", input.truth_disparity.as_ref()),
            ("depth_left.pfm", input.truth_depth.as_ref()),
            ("streak_mask_left.png", input.truth_streak_mask.as_ref()),
        ];
        for (what, img) in named {
            if let Some(img) = img {
                if (img.width, img.height) != size {
                    return Err(ReportError::Input {
                        path: dir.to_path_buf(),
                        reason: format!(
                            "the {what} is {}x{}, rig.json says {}x{}",
                            img.width, img.height, size.0, size.1
                        ),
                    });
                }
            }
        }
        Ok(input)
    }
}

/// A region named on the command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NamedRegion {
    /// Its name in the report.
    pub name: String,
    /// The pixels.
    pub region: Region,
}

/// Parameters of [`analyze`].
#[derive(Clone, Debug)]
pub struct AnalyzeParams {
    /// The per-row estimator, 21 x 5 pixels by default (its largest disparity is replaced by the scene's, from the ground
    /// truth or the road at the bottom row).
    pub lk: LkParams,
    /// The streak detector (its horizon defaults to the rig's).
    pub detect: DetectParams,
    /// Dense matching for the point cloud (its range is set from the scene).
    pub sgm: SgmParams,
    /// Regions to measure besides the streaks.
    pub regions: Vec<NamedRegion>,
    /// How many vertical objects to pick automatically from the ground-truth depth.
    pub auto_objects: usize,
    /// Whether to pick a plain road region automatically.
    pub auto_road: bool,
    /// Rows of a region whose LK match has a lower NCC are left out of its comparison with the
    /// ground truth (and counted).
    pub min_ncc: f32,
    /// Farthest a light's mirror image may be from a streak's axis, in pixels.
    pub match_tolerance_px: f32,
    /// A light match is dropped when the streak's median measured disparity is within this
    /// many pixels of the road's (a specular streak lies below the road; one at road disparity
    /// is road texture or a diffuse glow, not the light's reflection). 0 disables.
    pub road_reject_px: f32,
}

impl Default for AnalyzeParams {
    fn default() -> Self {
        Self {
            // 21 x 5 windows: one estimate per row, averaged over 5 rows against render noise.
            lk: LkParams {
                window: 21,
                rows: 5,
                ..LkParams::default()
            },
            detect: DetectParams::default(),
            sgm: SgmParams::default(),
            regions: Vec::new(),
            auto_objects: 3,
            auto_road: true,
            min_ncc: 0.8,
            match_tolerance_px: 12.0,
            road_reject_px: 0.5,
        }
    }
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

/// A least-squares line `y = intercept + slope x` with the slope's standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineFit {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
    /// Standard error of the slope (NaN with fewer than 3 points).
    pub slope_se: f64,
    /// Number of points.
    pub n: usize,
}

/// Fits a line to `(x, y)` points; `None` with fewer than 2 distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<LineFit> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = points.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let slope_se = if n > 2 {
        let sse: f64 = points
            .iter()
            .map(|p| (p.1 - intercept - slope * p.0).powi(2))
            .sum();
        (sse / (nf - 2.0) / sxx).sqrt()
    } else {
        f64::NAN
    };
    Some(LineFit {
        slope,
        intercept,
        slope_se,
        n,
    })
}

/// Measured against predicted over the rows that have both.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Rows with both values.
    pub rows: usize,
    /// RMS of measured minus predicted, pixels.
    pub rms_px: f64,
    /// RMS of measured minus predicted, degrees.
    pub rms_deg: f64,
    /// Mean of measured minus predicted, pixels.
    pub bias_px: f64,
    /// Largest minus smallest measured disparity, pixels.
    pub measured_span_px: f64,
    /// Largest minus smallest predicted disparity, pixels.
    pub predicted_span_px: f64,
    /// Line fit of measured disparity (px) against row.
    pub measured_fit: Option<LineFit>,
    /// Line fit of predicted disparity (px) against row.
    pub predicted_fit: Option<LineFit>,
    /// Whether the slopes agree within twice their combined standard error.
    pub slope_agrees: bool,
}

fn span(v: impl Iterator<Item = f64> + Clone) -> f64 {
    v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Compares the measured and predicted disparities of `rows`.
pub fn compare(rows: &[RowRecord]) -> Option<Comparison> {
    let both: Vec<&RowRecord> = rows
        .iter()
        .filter(|r| r.predicted_px.is_some() && r.measured_px.is_finite())
        .collect();
    if both.is_empty() {
        return None;
    }
    let n = both.len() as f64;
    let diff_px = both
        .iter()
        .map(|r| r.measured_px - r.predicted_px.unwrap_or(f64::NAN));
    let rms_px = (diff_px.clone().map(|d| d * d).sum::<f64>() / n).sqrt();
    let bias_px = diff_px.sum::<f64>() / n;
    let rms_deg = (both
        .iter()
        .map(|r| (r.measured_deg - r.predicted_deg.unwrap_or(f64::NAN)).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let measured: Vec<(f64, f64)> = both.iter().map(|r| (r.row as f64, r.measured_px)).collect();
    let predicted: Vec<(f64, f64)> = both
        .iter()
        .map(|r| (r.row as f64, r.predicted_px.unwrap_or(f64::NAN)))
        .collect();
    let (mf, pf) = (fit_line(&measured), fit_line(&predicted));
    let slope_agrees = match (mf, pf) {
        (Some(m), Some(p)) => {
            let se = (m.slope_se.powi(2) + p.slope_se.powi(2)).sqrt();
            se.is_finite() && (m.slope - p.slope).abs() <= 2.0 * se
        }
        _ => false,
    };
    Some(Comparison {
        rows: both.len(),
        rms_px,
        rms_deg,
        bias_px,
        measured_span_px: span(measured.iter().map(|p| p.1)),
        predicted_span_px: span(predicted.iter().map(|p| p.1)),
        measured_fit: mf,
        predicted_fit: pf,
        slope_agrees,
    })
}

/// The light a streak was matched to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MatchedLight {
    /// Index into rig.json's lights.
    pub index: usize,
    /// Its kind (`point`, `spot`, `emissive`).
    pub kind: String,
    /// Position in the road frame (metres).
    pub road: [f64; 3],
    /// Where its mirror image projects in the left image.
    pub mirror_px: [f64; 2],
    /// Horizontal distance from the streak's axis at the mirror image's row, pixels.
    pub distance_px: f64,
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

/// Summary of the dense disparity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DenseSummary {
    /// Disparity range searched.
    pub range: (i32, i32),
    /// Share of pixels with a valid disparity.
    pub density: f64,
    /// Valid streak pixels whose implied point is more than 0.1 m below the road.
    pub streak_pixels_below_road: usize,
    /// Valid streak pixels.
    pub streak_pixels: usize,
    /// Valid non-streak pixels more than 0.1 m below the road.
    pub other_pixels_below_road: usize,
    /// The dense disparity scored against the ground truth, when the input has it.
    pub accuracy: Option<DenseAccuracy>,
}

/// The dense disparity scored against the ground-truth disparity: bad-2.0 (the share of the
/// estimated pixels off by more than 2 px), mean absolute error and the share of pixels with
/// an estimate ([`DisparityErrors`]), over every pixel that sees a surface and separately over
/// the streak pixels and the others. Streak pixels are expected to be wrong: stereo sees the
/// virtual light there, not the road.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DenseAccuracy {
    /// The mask that tells streak pixels from the others: `renderer` (the input's
    /// `streak_mask_left.png`) or `detector` (the analysis' own, when the input has none).
    pub streak_mask: &'static str,
    /// Every pixel with a ground truth.
    pub all: DisparityErrors,
    /// The streak pixels.
    pub streak: DisparityErrors,
    /// The other pixels.
    pub non_streak: DisparityErrors,
}

/// Bad-2.0, mean absolute error and density of `dense` against `truth`, overall and split by
/// `streak_mask` (a pixel is a streak pixel when its mask value exceeds 0.5).
pub fn dense_accuracy(
    dense: &GrayImage,
    truth: &GrayImage,
    streak_mask: &GrayImage,
    mask_name: &'static str,
) -> Result<DenseAccuracy, ReportError> {
    if (streak_mask.width, streak_mask.height) != (truth.width, truth.height) {
        return Err(SgmError::SizeMismatch {
            lw: streak_mask.width,
            lh: streak_mask.height,
            rw: truth.width,
            rh: truth.height,
        }
        .into());
    }
    let on = |i: usize| streak_mask.data[i] > 0.5;
    Ok(DenseAccuracy {
        streak_mask: mask_name,
        all: compare_disparity_where(dense, truth, 2.0, |_| true)?,
        streak: compare_disparity_where(dense, truth, 2.0, on)?,
        non_streak: compare_disparity_where(dense, truth, 2.0, |i| !on(i))?,
    })
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
    /// components taller than wide ([`vertical_truth`]). The renderer's mask also marks glints
    /// on windows and broad glossy road, which the detector does not look for; this recall is
    /// the honest measure of the detector (its precision counts detections outside those
    /// components as false).
    pub detection_vertical: Option<MaskScore>,
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

/// The rig's geometry in the road frame, as the model needs it.
struct Geometry {
    road: RoadFrame,
    model_rig: StereoRig,
    rig: Rig,
    cx: f64,
    cy: f64,
    f: f64,
    pitch: f64,
}

impl Geometry {
    fn new(rig: &Rig) -> Result<Self, ReportError> {
        let road = rig.road_frame()?;
        let fwd = rig.forward();
        let pitch = (-fwd.y as f64).clamp(-1.0, 1.0).asin();
        let i = rig.intrinsics();
        let pp = i.principal_point();
        let camera = RoadCamera::new(
            DVec3::new(0.0, rig.height() as f64, 0.0),
            pitch.to_degrees(),
            i.focal_px() as f64,
            DVec2::new(pp.x as f64, pp.y as f64),
        )
        .map_err(|source| ReportError::Model {
            what: "the rig's camera".into(),
            source,
        })?;
        let model_rig =
            StereoRig::new(camera, rig.baseline() as f64).map_err(|source| ReportError::Model {
                what: "the rig".into(),
                source,
            })?;
        Ok(Self {
            road,
            model_rig,
            rig: *rig,
            cx: pp.x as f64,
            cy: pp.y as f64,
            f: i.focal_px() as f64,
            pitch,
        })
    }

    fn horizon_row(&self) -> f64 {
        self.cy - self.f * self.pitch.tan()
    }

    fn elevation_deg(&self, y: f64) -> f64 {
        (((y - self.cy) / self.f).atan() + self.pitch).to_degrees()
    }

    fn angle_deg(&self, x: f64, d: f64) -> f64 {
        (((x - self.cx) / self.f).atan() - ((x - d - self.cx) / self.f).atan()).to_degrees()
    }

    /// The road-frame point the left eye sees through `(x, y)` at depth `z`.
    fn implied(&self, x: f32, y: f32, z: f32) -> Vec3 {
        let w = self.rig.eye(Eye::Left).back_project(Vec2::new(x, y), z);
        self.road.road_from_world_point(w)
    }

    fn record(
        &self,
        r: &RowDisparity,
        predicted_px: Option<f64>,
        road_px: Option<f64>,
    ) -> RowRecord {
        let (x, y, d) = (r.x as f64, r.row as f64 + 0.5, r.disparity as f64);
        let depth = if d > 0.0 {
            self.f * self.rig.baseline() as f64 / d
        } else {
            f64::INFINITY
        };
        let p = if depth.is_finite() {
            self.implied(r.x, y as f32, depth as f32)
        } else {
            Vec3::splat(f32::NAN)
        };
        RowRecord {
            row: r.row,
            x: r.x,
            elevation_deg: self.elevation_deg(y),
            measured_px: d,
            measured_deg: self.angle_deg(x, d),
            predicted_px,
            predicted_deg: predicted_px.map(|p| self.angle_deg(x, p)),
            road_px,
            depth_m: depth,
            road_y_m: p.y as f64,
            road_z_m: p.z as f64,
            ncc: r.ncc,
        }
    }
}

/// A light's kind, road-frame position and strength (radiant intensity, luminance; an emissive
/// group's radiance times its area).
fn light_position(light: &LightRecord) -> Option<(&'static str, [f32; 3], f64)> {
    let lum = |c: [f32; 3]| (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) as f64;
    match light {
        LightRecord::Point {
            position,
            intensity,
            ..
        } => position.road.map(|p| ("point", p, lum(*intensity))),
        LightRecord::Spot {
            position,
            intensity,
            ..
        } => position.road.map(|p| ("spot", p, lum(*intensity))),
        LightRecord::Emissive {
            centroid,
            radiance,
            area,
            ..
        } => centroid
            .road
            .map(|p| ("emissive", p, lum(*radiance) * *area as f64)),
        LightRecord::Directional { .. } => None,
    }
}

/// The light that makes a streak: among the lights whose mirror image `(X, -Y, Z)` projects
/// within `tolerance` pixels of the streak's axis (at the mirror image's row, or the streak's
/// first row if the mirror image is above it), whose own image is above the streak's first
/// row and whose mirror image is not below its last row, the one with the strongest predicted
/// streak: strength over the squared distance from the camera to the mirror image (a faint
/// light that happens to line up does not win over the lamp that makes the streak).
fn match_light(
    streak: &Streak,
    lights: &[LightRecord],
    geo: &Geometry,
    tolerance: f32,
) -> Option<MatchedLight> {
    let cam = &geo.model_rig.camera;
    let mut best: Option<(f64, MatchedLight)> = None;
    for (index, light) in lights.iter().enumerate() {
        let Some((kind, p, strength)) = light_position(light) else {
            continue;
        };
        let p = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        if p.y <= 0.0 || p.z <= 0.0 {
            continue;
        }
        let virt = DVec3::new(p.x, -p.y, p.z);
        let Some(mirror) = cam.project(virt) else {
            continue;
        };
        let Some(lamp) = cam.project(p) else { continue };
        // The streak hangs below the light: its first row is below the light's image, and the
        // mirror image is not below the streak's last row.
        if lamp.y > streak.first_row as f64 + 0.5 || mirror.y > streak.last_row as f64 + 4.0 {
            continue;
        }
        // Left-image x: the cyclopean x plus half the disparity of the virtual light.
        let half = 0.5 * geo.model_rig.pixel_disparity(virt);
        let row = mirror.y.max(streak.first_row as f64);
        let axis = streak.axis_a as f64 + streak.axis_b as f64 * row;
        let distance = (axis - (mirror.x + half)).abs();
        let predicted =
            strength / (virt - DVec3::new(0.0, geo.rig.height() as f64, 0.0)).length_squared();
        if distance <= tolerance as f64 && best.as_ref().is_none_or(|b| predicted > b.0) {
            best = Some((
                predicted,
                MatchedLight {
                    index,
                    kind: kind.into(),
                    road: p.to_array(),
                    mirror_px: [mirror.x + half, mirror.y],
                    distance_px: distance,
                },
            ));
        }
    }
    best.map(|b| b.1)
}

fn lk_err(what: impl Into<String>) -> impl FnOnce(LkError) -> ReportError {
    let what = what.into();
    move |source| ReportError::Lk { what, source }
}

fn analyze_streak(
    index: usize,
    streak: &Streak,
    input: &StereoInput,
    prepared: (&GrayImage, &GrayImage),
    geo: &Geometry,
    params: &AnalyzeParams,
    lk: &LkParams,
) -> Result<StreakReport, ReportError> {
    let (w, h) = (input.left.width as f32, input.left.height);
    let centres: Vec<(usize, f32)> = streak
        .centres
        .iter()
        .copied()
        .filter(|&(y, x)| y < h && (0.0..=w).contains(&x))
        .collect();
    let measured = lk_rows(prepared.0, prepared.1, &centres, lk)
        .map_err(lk_err(format!("LK along streak {index}")))?;
    let mut light = match_light(streak, &input.lights, geo, params.match_tolerance_px);
    let mut predicted = std::collections::HashMap::new();
    if let Some(l) = &light {
        let rows = streak.first_row as u32..streak.last_row as u32 + 1;
        let model_x = l.mirror_px[0]
            - 0.5
                * geo
                    .model_rig
                    .pixel_disparity(DVec3::new(l.road[0], -l.road[1], l.road[2]));
        let pred = streak_rows(
            DVec3::from_array(l.road),
            &geo.model_rig,
            rows,
            Some(model_x),
            None,
        )
        .map_err(|source| ReportError::Model {
            what: format!("Eq. 4 for streak {index}"),
            source,
        })?;
        for p in pred {
            let road_px = geo.model_rig.pixel_disparity(p.point.reflection.ground);
            predicted.insert(p.row as usize, (p.point.disparity_px, road_px));
        }
    }
    let mut rows: Vec<RowRecord> = measured
        .iter()
        .map(|r| {
            let p = predicted.get(&r.row);
            geo.record(r, p.map(|p| p.0), p.map(|p| p.1))
        })
        .collect();
    let off_road = median(
        rows.iter()
            .filter_map(|r| r.road_px.map(|road| (r.measured_px - road).abs()))
            .collect(),
    );
    if off_road.is_finite() && off_road < params.road_reject_px as f64 {
        light = None;
        for r in &mut rows {
            (r.predicted_px, r.predicted_deg, r.road_px) = (None, None, None);
        }
    }
    let road: Vec<f64> = rows.iter().filter_map(|r| r.road_px).collect();
    Ok(StreakReport {
        index,
        first_row: streak.first_row,
        last_row: streak.last_row,
        peak: streak.peak,
        light,
        comparison: compare(&rows),
        road_span_px: (!road.is_empty()).then(|| span(road.iter().copied())),
        median_depth_m: median(rows.iter().map(|r| r.depth_m).collect()),
        median_road_y_m: median(rows.iter().map(|r| r.road_y_m).collect()),
        min_road_y_m: rows
            .iter()
            .map(|r| r.road_y_m)
            .filter(|y| y.is_finite())
            .fold(f64::INFINITY, f64::min),
        rows,
    })
}

/// What [`measure_region`] needs besides the region.
struct RegionInput<'a> {
    input: &'a StereoInput,
    geo: &'a Geometry,
    /// The prepared pair ([`prepare_pair`]).
    left: &'a GrayImage,
    right: &'a GrayImage,
    min_ncc: f32,
}

/// Measures a region row by row at `centres` (row, left-image x) with `lk`, against the
/// ground truth at the pixel of each centre; the comparison keeps the rows whose NCC reaches
/// `min_ncc`.
fn measure_region(
    name: String,
    kind: &str,
    region: Region,
    centres: &[(usize, f32)],
    lk: &LkParams,
    ri: &RegionInput,
) -> Result<RegionReport, ReportError> {
    let measured = lk_rows(ri.left, ri.right, centres, lk)
        .map_err(lk_err(format!("LK over region {name}")))?;
    let w = ri.input.left.width;
    let rows: Vec<RowRecord> = measured
        .iter()
        .map(|r| {
            let xc = (r.x.max(0.0) as usize).min(w - 1);
            let truth = ri
                .input
                .truth_disparity
                .as_ref()
                .map(|t| t.get(xc, r.row) as f64)
                .filter(|d| d.is_finite());
            ri.geo.record(r, truth, None)
        })
        .collect();
    let confident: Vec<RowRecord> = rows
        .iter()
        .filter(|r| r.ncc >= ri.min_ncc)
        .copied()
        .collect();
    Ok(RegionReport {
        name,
        kind: kind.into(),
        region,
        window: lk.window,
        min_ncc: ri.min_ncc,
        low_confidence_rows: rows.len() - confident.len(),
        comparison: compare(&confident),
        comparison_all_rows: compare(&rows),
        rows,
    })
}

/// Height above the road of the ground-truth point at pixel `(x, y)`.
fn truth_road_y(depth: &GrayImage, geo: &Geometry, x: usize, y: usize) -> f32 {
    let z = depth.get(x, y);
    if !(z.is_finite() && z > 0.0) {
        return f32::NAN;
    }
    geo.implied(x as f32 + 0.5, y as f32 + 0.5, z).y
}

/// A region picked from the ground truth: its bounding box, the per-row centres LK measures
/// at, and the window width that fits it.
#[derive(Clone, Debug, PartialEq)]
struct Picked {
    region: Region,
    centres: Vec<(usize, f32)>,
    window: usize,
}

/// Narrowest and widest vertical object [`find_objects`] picks, pixels.
const OBJECT_WIDTH: (usize, usize) = (4, 32);

/// Thin vertical objects (poles, posts): in every row, the maximal runs of pixels more than
/// 0.1 m above the road whose ground-truth depth changes by less than 2 % from one pixel to the
/// next, [`OBJECT_WIDTH`] wide, 2 pixels or more from the border of both images. A column is followed down while such a run holds it and its
/// depth changes by less than 2 % from row to row; the longest runs (at least `h / 12` and
/// 12 rows) are picked, at least a tenth of the image width apart. LK is centred on the
/// object in every row, with a window 4 pixels wider than its median width (odd, at most
/// `max_window`): the object and its two edges, little of the background behind it.
fn find_objects(depth: &GrayImage, geo: &Geometry, count: usize, max_window: usize) -> Vec<Picked> {
    let (w, h) = (depth.width, depth.height);
    let near = |a: f32, b: f32| (a / b - 1.0).abs() < 0.02;
    // Per pixel: its row run's first and last column (usize::MAX when not an object pixel).
    let mut runs = vec![(usize::MAX, usize::MAX); w * h];
    for y in 0..h {
        let valid = |x: usize| {
            let z = depth.get(x, y);
            z.is_finite() && z > 0.0 && truth_road_y(depth, geo, x, y) > 0.1
        };
        let mut x = 0;
        while x < w {
            if !valid(x) {
                x += 1;
                continue;
            }
            let x0 = x;
            x += 1;
            while x < w && valid(x) && near(depth.get(x, y), depth.get(x - 1, y)) {
                x += 1;
            }
            for r in &mut runs[y * w + x0..y * w + x] {
                *r = (x0, x - 1);
            }
        }
    }
    // Thin, and with its edges and 2 pixels beyond them inside both images (the right image
    // sees the object `f b / Z` pixels further left).
    let fb = geo.f as f32 * geo.rig.baseline();
    let thin = |x: usize, y: usize| {
        let (a, b) = runs[y * w + x];
        a != usize::MAX
            && (OBJECT_WIDTH.0..=OBJECT_WIDTH.1).contains(&(b - a + 1))
            && a as f32 - 2.0 - fb / depth.get(x, y) >= 0.0
            && b + 3 <= w
    };
    let min_rows = (h / 12).max(12);
    let mut found: Vec<(usize, usize, usize)> = Vec::new(); // (length, x, y0)
    for x in 0..w {
        let mut y = 0;
        while y < h {
            if !thin(x, y) {
                y += 1;
                continue;
            }
            let y0 = y;
            y += 1;
            while y < h && thin(x, y) && near(depth.get(x, y), depth.get(x, y - 1)) {
                y += 1;
            }
            if y - y0 >= min_rows {
                found.push((y - y0, x, y0));
            }
        }
    }
    found.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut picked: Vec<Picked> = Vec::new();
    for (len, x, y0) in found {
        if picked.len() == count {
            break;
        }
        if picked
            .iter()
            .any(|p| (p.region.centre_x() - x as f32).abs() <= 0.1 * w as f32)
        {
            continue;
        }
        let rows = y0..y0 + len;
        let centres: Vec<(usize, f32)> = rows
            .clone()
            .map(|y| {
                let (a, b) = runs[y * w + x];
                (y, 0.5 * (a + b + 1) as f32)
            })
            .collect();
        let mut widths: Vec<usize> = rows
            .clone()
            .map(|y| {
                let (a, b) = runs[y * w + x];
                b - a + 1
            })
            .collect();
        widths.sort_unstable();
        let window = ((widths[widths.len() / 2] + 4) | 1)
            .min(max_window | 1)
            .max(3);
        let x0 = rows.clone().map(|y| runs[y * w + x].0).min().unwrap_or(x);
        let x1 = rows.map(|y| runs[y * w + x].1 + 1).max().unwrap_or(x + 1);
        picked.push(Picked {
            region: Region {
                x0,
                x1,
                y0,
                y1: y0 + len,
            },
            centres,
            window,
        });
    }
    picked
}

/// Plain road, one measurement per row: among the pixels whose LK window (`half` either side)
/// lies on the road in the ground truth (within 2 cm of the plane at its centre and both ends),
/// inside the right image as well, and off the streak mask, the one whose window has the most texture, the largest sum of the
/// squared horizontal gradient of the prepared left image averaged over 3 rows (against the
/// noise). Lane markings and the asphalt's grain win over the smooth glow of the reflections.
/// Rows without such a pixel are skipped; `None` with fewer than 12 rows.
fn find_road(
    depth: &GrayImage,
    mask: &GrayImage,
    img: &GrayImage,
    geo: &Geometry,
    half: usize,
) -> Option<Picked> {
    let (w, h) = (depth.width, depth.height);
    if w < 2 * half + 3 || h < 3 {
        return None;
    }
    let fb = geo.f as f32 * geo.rig.baseline();
    let mut centres = Vec::new();
    let (mut gsum, mut msum) = (vec![0.0f64; w + 1], vec![0usize; w + 1]);
    for y in 0..h {
        let (ya, yb) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let avg = |x: usize| (img.get(x, ya) + img.get(x, y) + img.get(x, yb)) as f64 / 3.0;
        for x in 0..w {
            let g = if x > 0 && x + 1 < w {
                (avg(x + 1) - avg(x - 1)).powi(2)
            } else {
                0.0
            };
            gsum[x + 1] = gsum[x] + if g.is_finite() { g } else { 0.0 };
            msum[x + 1] = msum[x] + (mask.get(x, y) > 0.5) as usize;
        }
        let mut best: Option<(f64, usize)> = None;
        for x in half + 1..w - half - 1 {
            let (a, b) = (x - half, x + half + 1);
            if msum[b] != msum[a] {
                continue;
            }
            // On the road, and the window inside the right image too.
            let on_road = [a, x, b - 1]
                .iter()
                .all(|&xx| truth_road_y(depth, geo, xx, y).abs() < 0.02)
                && a as f32 - fb / depth.get(a, y) >= 0.0;
            let energy = gsum[b] - gsum[a];
            if on_road && best.is_none_or(|(e, _)| energy > e) {
                best = Some((energy, x));
            }
        }
        if let Some((_, x)) = best {
            centres.push((y, x as f32 + 0.5));
        }
    }
    if centres.len() < 12 {
        return None;
    }
    let xs = || centres.iter().map(|c| c.1 as usize);
    let region = Region {
        x0: xs().min()? - half,
        x1: xs().max()? + half + 1,
        y0: centres.first()?.0,
        y1: centres.last()?.0 + 1,
    };
    Some(Picked {
        region,
        centres,
        window: 2 * half + 1,
    })
}

/// The SGM range that covers the scene: up to the largest ground-truth disparity (or that of
/// the road at the bottom row), plus a margin, within what the matcher allows.
fn disparity_range(input: &StereoInput, geo: &Geometry) -> i32 {
    let truth_max = input.truth_disparity.as_ref().and_then(|t| {
        let mut v: Vec<f32> = t.data.iter().copied().filter(|d| d.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        let i = ((v.len() - 1) as f64 * 0.995) as usize;
        let (_, q, _) = v.select_nth_unstable_by(i, f32::total_cmp);
        Some(*q as f64)
    });
    let bottom = geo
        .model_rig
        .camera
        .ground_point(DVec2::new(geo.cx, input.left.height as f64 - 0.5))
        .map(|g| geo.model_rig.pixel_disparity(g));
    let d = truth_max.or(bottom).unwrap_or(64.0);
    ((d * 1.2).ceil() as i32 + 4).clamp(16, 256)
}

/// Runs the whole analysis.
pub fn analyze(input: &StereoInput, params: &AnalyzeParams) -> Result<Analysis, ReportError> {
    if !(params.match_tolerance_px.is_finite() && params.match_tolerance_px > 0.0) {
        return Err(ReportError::Param {
            name: "match_tolerance_px",
            reason: format!("must be positive, got {}", params.match_tolerance_px),
        });
    }
    if !(-1.0..=1.0).contains(&params.min_ncc) {
        return Err(ReportError::Param {
            name: "min_ncc",
            reason: format!("must be from -1 to 1, got {}", params.min_ncc),
        });
    }
    if !(params.road_reject_px.is_finite() && params.road_reject_px >= 0.0) {
        return Err(ReportError::Param {
            name: "road_reject_px",
            reason: format!("must be non-negative, got {}", params.road_reject_px),
        });
    }
    let geo = Geometry::new(&input.rig)?;
    let range = disparity_range(input, &geo);
    // The search range of the scene: a wider one lets windows near the left edge run out of
    // the right image and the integer search pick a flat window.
    let lk = LkParams {
        max_disp: range.max(params.lk.min_disp),
        ..params.lk
    };
    let detect = DetectParams {
        horizon: params.detect.horizon.or(Some(
            geo.horizon_row().clamp(0.0, input.left.height as f64) as f32,
        )),
        ..params.detect
    };
    let found = detect_streaks(&input.left, &detect)?;
    // Every LK measurement is made on the prepared pair.
    let (left, right) = prepare_pair(&input.left, &input.right);
    let streaks = found
        .streaks
        .iter()
        .enumerate()
        .map(|(i, s)| analyze_streak(i, s, input, (&left, &right), &geo, params, &lk))
        .collect::<Result<Vec<_>, _>>()?;
    let ri = RegionInput {
        input,
        geo: &geo,
        left: &left,
        right: &right,
        min_ncc: params.min_ncc,
    };
    let mut regions = Vec::new();
    for r in &params.regions {
        let g = r.region;
        if g.x0 >= g.x1 || g.y0 >= g.y1 || g.x1 > input.left.width || g.y1 > input.left.height {
            return Err(ReportError::Lk {
                what: format!("region {}", r.name),
                source: LkError::Region {
                    x0: g.x0,
                    y0: g.y0,
                    x1: g.x1,
                    y1: g.y1,
                    width: input.left.width,
                    height: input.left.height,
                },
            });
        }
        let centres: Vec<(usize, f32)> = (g.y0..g.y1).map(|y| (y, g.centre_x())).collect();
        regions.push(measure_region(
            r.name.clone(),
            "named",
            g,
            &centres,
            &lk,
            &ri,
        )?);
    }
    if let Some(depth) = &input.truth_depth {
        for (i, p) in find_objects(depth, &geo, params.auto_objects, lk.window)
            .into_iter()
            .enumerate()
        {
            let lk = LkParams {
                window: p.window,
                ..lk
            };
            let name = format!("object{i}");
            regions.push(measure_region(
                name, "object", p.region, &p.centres, &lk, &ri,
            )?);
        }
        if params.auto_road {
            // Off the renderer's streaks and the detector's.
            let mut mask = found.mask.clone();
            if let Some(t) = &input.truth_streak_mask {
                for (m, &t) in mask.data.iter_mut().zip(&t.data) {
                    if t > 0.5 {
                        *m = 1.0;
                    }
                }
            }
            if let Some(p) = find_road(depth, &mask, &left, &geo, lk.window / 2) {
                regions.push(measure_region(
                    "road".into(),
                    "road",
                    p.region,
                    &p.centres,
                    &lk,
                    &ri,
                )?);
            }
        }
    }
    let sgm_params = SgmParams {
        min_disp: 0,
        max_disp: range,
        ..params.sgm
    };
    let dense = sgm(&input.left, &input.right, &sgm_params)?;
    let accuracy = match (&input.truth_disparity, &input.truth_streak_mask) {
        (Some(truth), Some(mask)) => Some(dense_accuracy(&dense, truth, mask, "renderer")?),
        (Some(truth), None) => Some(dense_accuracy(&dense, truth, &found.mask, "detector")?),
        (None, _) => None,
    };
    let dense_summary = summarize_dense(&dense, &found.mask, &geo, sgm_params.max_disp, accuracy);
    let (detection, detection_vertical) = match &input.truth_streak_mask {
        Some(truth) => (
            Some(score_mask(&found.mask, truth)?),
            Some(score_mask(
                &found.mask,
                &vertical_truth(truth, found.horizon),
            )?),
        ),
        None => (None, None),
    };
    let i = input.rig.intrinsics();
    let report = Report {
        rig: RigSummary {
            width: i.width(),
            height: i.height(),
            focal_px: i.focal_px(),
            baseline_m: input.rig.baseline(),
            height_m: input.rig.height(),
            pitch_deg: geo.pitch.to_degrees(),
            horizon_row: geo.horizon_row(),
        },
        horizon_row: found.horizon,
        lamps: found.lamps.len(),
        glows: found.glows.len(),
        streaks,
        regions,
        dense: dense_summary,
        detection,
        detection_vertical,
    };
    Ok(Analysis {
        report,
        streak_mask: found.mask,
        dense,
    })
}

/// Calls `f(x, y, is_streak, road point)` for every valid pixel of the dense disparity.
fn for_each_point(
    dense: &GrayImage,
    mask: &GrayImage,
    geo: &Geometry,
    mut f: impl FnMut(usize, usize, bool, Vec3),
) {
    let fb = geo.f as f32 * geo.rig.baseline();
    for y in 0..dense.height {
        for x in 0..dense.width {
            let d = dense.get(x, y);
            if d.is_finite() && d > 0.0 {
                let p = geo.implied(x as f32 + 0.5, y as f32 + 0.5, fb / d);
                f(x, y, mask.get(x, y) > 0.0, p);
            }
        }
    }
}

fn summarize_dense(
    dense: &GrayImage,
    mask: &GrayImage,
    geo: &Geometry,
    max: i32,
    accuracy: Option<DenseAccuracy>,
) -> DenseSummary {
    let (mut valid, mut streak, mut streak_below, mut other_below) = (0usize, 0, 0, 0);
    for_each_point(dense, mask, geo, |_, _, is_streak, p| {
        valid += 1;
        let below = p.y < -0.1;
        if is_streak {
            streak += 1;
            streak_below += below as usize;
        } else {
            other_below += below as usize;
        }
    });
    DenseSummary {
        range: (0, max),
        density: valid as f64 / dense.data.len().max(1) as f64,
        streak_pixels_below_road: streak_below,
        streak_pixels: streak,
        other_pixels_below_road: other_below,
        accuracy,
    }
}

/// The disparity-against-row plot of one region: measured black, predicted blue, and for a
/// streak the road's disparity grey. Given `min_ncc`, the rows whose match has a lower NCC
/// (left out of a region's comparison) are drawn grey.
pub fn rows_plot(
    title: &str,
    rows: &[RowRecord],
    predicted_label: &str,
    min_ncc: Option<f32>,
) -> Plot {
    let low = |r: &RowRecord| min_ncc.is_some_and(|m| r.ncc < m || r.ncc.is_nan());
    let pts = |f: &dyn Fn(&RowRecord) -> Option<f64>| -> Vec<(f64, f64)> {
        rows.iter()
            .filter_map(|r| f(r).filter(|v| v.is_finite()).map(|v| (r.row as f64, v)))
            .collect()
    };
    let mut plot = Plot::new(title, "image row (down)", "disparity (px)").with(Series::scatter(
        "measured (1D LK)",
        BLACK_RGB,
        Marker::Circle,
        pts(&|r| (!low(r)).then_some(r.measured_px)),
    ));
    let left_out = pts(&|r| low(r).then_some(r.measured_px));
    if let (Some(m), false) = (min_ncc, left_out.is_empty()) {
        plot = plot.with(Series::scatter(
            format!("measured, NCC < {m} (left out)"),
            GREY,
            Marker::Circle,
            left_out,
        ));
    }
    let predicted = pts(&|r| r.predicted_px);
    if !predicted.is_empty() {
        plot = plot.with(Series::line(predicted_label, BLUE, predicted));
    }
    let road = pts(&|r| r.road_px);
    if !road.is_empty() {
        plot = plot.with(Series::dashed("road surface (no streak)", GREY, road));
    }
    plot
}

fn write_err(path: &Path) -> impl FnOnce(String) -> ReportError + '_ {
    move |reason| ReportError::Write {
        path: path.to_path_buf(),
        reason,
    }
}

/// Writes `report.json` atomically.
pub fn write_report_json(path: &Path, report: &Report) -> Result<(), ReportError> {
    let text = serde_json::to_string_pretty(report).map_err(|e| write_err(path)(e.to_string()))?;
    write_file_atomic(path, text.as_bytes()).map_err(|e| write_err(path)(e.to_string()))
}

/// Writes everything into `dir` (created if missing): `report.json`, `streak<i>.png` and
/// `<region>.png` (disparity against row), `depth.png` (the SGM disparity, i.e. inverse
/// depth, turbo colours, with the streak pixels outlined red), `streak_mask.png` (the
/// detector's streak pixels, white) and `side_view.png` (the SGM
/// point cloud, Z forward against Y up, streak points red). Returns the files written.
pub fn write_outputs(
    dir: &Path,
    analysis: &Analysis,
    input: &StereoInput,
) -> Result<Vec<PathBuf>, ReportError> {
    std::fs::create_dir_all(dir).map_err(|e| write_err(dir)(e.to_string()))?;
    let mut written = Vec::new();
    let report = &analysis.report;
    let path = dir.join("report.json");
    write_report_json(&path, report)?;
    written.push(path);
    for s in &report.streaks {
        let title = match &s.light {
            Some(l) => format!(
                "streak {} (light {} at X {:.1}, Y {:.1}, Z {:.1} m)",
                s.index, l.index, l.road[0], l.road[1], l.road[2]
            ),
            None => format!("streak {} (no light matched)", s.index),
        };
        let path = dir.join(format!("streak{}.png", s.index));
        rows_plot(&title, &s.rows, "predicted (Eq. 4 + Eq. 5)", None).write_png(&path)?;
        written.push(path);
    }
    for r in &report.regions {
        let path = dir.join(format!("{}.png", r.name));
        let title = format!("{} {} (x {}..{})", r.kind, r.name, r.region.x0, r.region.x1);
        rows_plot(&title, &r.rows, "ground truth", Some(r.min_ncc)).write_png(&path)?;
        written.push(path);
    }
    let geo = Geometry::new(&input.rig)?;
    // The disparity map with the streak pixels outlined.
    let mut img = disparity_preview(&analysis.dense, None);
    let mask = &analysis.streak_mask;
    for y in 0..mask.height {
        for x in 0..mask.width {
            if mask.get(x, y) <= 0.0 {
                continue;
            }
            let edge = [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)]
                .iter()
                .any(|&(dx, dy)| {
                    let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                    xx < 0
                        || yy < 0
                        || xx >= mask.width as i64
                        || yy >= mask.height as i64
                        || mask.get(xx as usize, yy as usize) <= 0.0
                });
            if edge {
                img.put_pixel(x as u32, y as u32, image::Rgb([255, 0, 0]));
            }
        }
    }
    let path = dir.join("depth.png");
    save_rgb8_png(&path, &img)?;
    written.push(path);
    let path = dir.join("streak_mask.png");
    analysis
        .streak_mask
        .save_png(&path)
        .map_err(|e| write_err(&path)(e.to_string()))?;
    written.push(path);
    // Side view of the point cloud.
    let (mut other, mut streak) = (Vec::new(), Vec::new());
    for_each_point(&analysis.dense, mask, &geo, |x, y, is_streak, p| {
        if !(p.z > 0.0 && p.z < 80.0 && p.y > -10.0 && p.y < 15.0) {
            return;
        }
        if is_streak {
            streak.push((p.z as f64, p.y as f64));
        } else if (x + y) % 3 == 0 {
            other.push((p.z as f64, p.y as f64));
        }
    });
    let z_max = other
        .iter()
        .chain(&streak)
        .map(|p| p.0)
        .fold(1.0f64, f64::max);
    let mut plot = Plot::new(
        "side view of the SGM point cloud (road frame)",
        "Z forward (m)",
        "Y up (m)",
    )
    .with(
        Series::scatter("scene", GREY, Marker::Circle, other).with_mark(
            crate::plot::Mark::Points {
                marker: Marker::Circle,
                size: 1,
            },
        ),
    )
    .with(
        Series::scatter("streak pixels", RED, Marker::Circle, streak).with_mark(
            crate::plot::Mark::Points {
                marker: Marker::Circle,
                size: 2,
            },
        ),
    )
    .with(Series::line(
        "road surface",
        BLACK_RGB,
        vec![(0.0, 0.0), (z_max, 0.0)],
    ));
    plot.size = (1200, 600);
    let path = dir.join("side_view.png");
    plot.write_png(&path)?;
    written.push(path);
    Ok(written)
}

/// A short text table: one line per streak and region.
pub fn summary_table(report: &Report) -> String {
    let mut s = String::from(
        "what        rows  light  meas span  pred span  road span  RMS px   RMS deg   slope ok  median Z  median Y\n",
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    for st in &report.streaks {
        let c = st.comparison.as_ref();
        s.push_str(&format!(
            "streak{:<5} {:>4}  {:>5}  {:>9}  {:>9}  {:>9}  {:>7}  {:>8}  {:>8}  {:>7.2}m  {:>7.2}m\n",
            st.index,
            st.rows.len(),
            st.light.as_ref().map_or("-".into(), |l| l.index.to_string()),
            format!("{:.3}", span(st.rows.iter().map(|r| r.measured_px))),
            opt(c.map(|c| c.predicted_span_px)),
            opt(st.road_span_px),
            opt(c.map(|c| c.rms_px)),
            c.map_or("-".into(), |c| format!("{:.5}", c.rms_deg)),
            c.map_or("-", |c| if c.slope_agrees { "yes" } else { "no" }),
            st.median_depth_m,
            st.median_road_y_m,
        ));
    }
    for r in &report.regions {
        let c = r.comparison.as_ref();
        s.push_str(&format!(
            "{:<11} {:>4}  {:>5}  {:>9}  {:>9}  {:>9}  {:>7}  {:>8}  {:>8}  {:>7.2}m  {:>7.2}m\n",
            r.name,
            r.rows.len() - r.low_confidence_rows,
            "-",
            format!("{:.3}", span(r.rows.iter().map(|x| x.measured_px))),
            opt(c.map(|c| c.predicted_span_px)),
            "-",
            opt(c.map(|c| c.rms_px)),
            c.map_or("-".into(), |c| format!("{:.5}", c.rms_deg)),
            c.map_or("-", |c| if c.slope_agrees { "yes" } else { "no" }),
            median(r.rows.iter().map(|x| x.depth_m).collect()),
            median(r.rows.iter().map(|x| x.road_y_m).collect()),
        ));
    }
    if !report.regions.is_empty() {
        s.push_str(&format!(
            "regions: rows = rows with NCC >= {} (their RMS against the ground truth); left out:{}\n",
            report.regions[0].min_ncc,
            report
                .regions
                .iter()
                .map(|r| format!(" {} {} of {}", r.name, r.low_confidence_rows, r.rows.len()))
                .collect::<String>()
        ));
    }
    s.push_str(&format!(
        "dense SGM (0..{} px): {:.0}% valid; {} of {} streak pixels imply points > 0.1 m below the road ({} other pixels do)\n",
        report.dense.range.1,
        100.0 * report.dense.density,
        report.dense.streak_pixels_below_road,
        report.dense.streak_pixels,
        report.dense.other_pixels_below_road
    ));
    if let Some(a) = &report.dense.accuracy {
        s.push_str(&format!(
            "dense SGM against the ground truth ({} streak mask): bad-2.0 / mean abs error / valid\n",
            a.streak_mask
        ));
        for (what, e) in [
            ("all", &a.all),
            ("streak", &a.streak),
            ("non-streak", &a.non_streak),
        ] {
            s.push_str(&format!(
                "  {what:<10} {:>5.1}% / {:>6.2} px / {:>5.1}% of {} pixels\n",
                100.0 * e.bad,
                e.mean_abs,
                100.0 * e.density,
                e.truth_pixels
            ));
        }
    }
    s.push_str(&format!(
        "detector: {} streaks, {} glows (wide reflections at the bottom, masked, not measured), {} lamps\n",
        report.streaks.len(),
        report.glows,
        report.lamps
    ));
    if let Some(d) = &report.detection {
        s.push_str(&format!(
            "streak detection against the renderer's streak mask: precision {:.2}, recall {:.2} ({} detected, {} true pixels)\n",
            d.precision, d.recall, d.detected, d.truth
        ));
    }
    if let Some(d) = &report.detection_vertical {
        s.push_str(&format!(
            "  against its road streaks only (below the horizon, components taller than wide): precision {:.2}, recall {:.2} ({} true pixels)\n",
            d.precision, d.recall, d.truth
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::SynthScene;
    use glam::Affine3A;
    use streaks_stereo::rig::Intrinsics;

    #[test]
    fn streaks_are_matched_to_the_light_whose_mirror_image_is_on_their_axis() {
        let rig = Rig::new(
            Intrinsics::new(320, 240, 300.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let geo = Geometry::new(&rig).unwrap();
        let light_i = |x: f32, y: f32, z: f32, i: f32| LightRecord::Point {
            // World -Z is road +Z for a rig looking along -Z.
            position: streaks_stereo::rigfile::Placed::point(Vec3::new(x, y, -z), Some(&geo.road)),
            intensity: [i; 3],
            range: None,
        };
        let light = |x: f32, y: f32, z: f32| light_i(x, y, z, 1.0);
        let lights = vec![light(-3.0, 5.0, 30.0), light(1.0, 4.0, 20.0)];
        // The second light's mirror image (1, -4, 20) seen from (0, 1.5, 0): x = 160 + 15,
        // y = 120 + 300 * 5.5 / 20 = 202.5. A vertical streak through it.
        let streak = Streak {
            first_row: 150,
            last_row: 220,
            centres: (150..=220).map(|y| (y, 175.5)).collect(),
            axis_a: 175.5,
            axis_b: 0.0,
            peak: 1.0,
            elongation: 10.0,
            pixels: 500,
        };
        let m = match_light(&streak, &lights, &geo, 4.0).expect("matched");
        assert_eq!(m.index, 1);
        assert!(m.distance_px < 1.5, "{m:?}");
        assert!((m.mirror_px[1] - 202.5).abs() < 1e-3);
        // A second light in the same column farther away (mirror image at x 175, y 175): the
        // one with the stronger predicted streak wins, whichever lines up more closely.
        for (i, want) in [(0.01f32, 1usize), (100.0, 2)] {
            let mut lights = lights.clone();
            lights.push(light_i(1.5, 4.0, 30.0, i));
            let m = match_light(&streak, &lights, &geo, 4.0).expect("matched");
            assert_eq!(m.index, want, "intensity {i}: {m:?}");
        }
        // Too far from every axis: no match.
        let off = Streak {
            axis_a: 260.0,
            ..streak
        };
        assert!(match_light(&off, &lights, &geo, 4.0).is_none());
    }

    #[test]
    fn line_fit_recovers_a_line_and_its_uncertainty() {
        let pts: Vec<(f64, f64)> = (0..20).map(|i| (i as f64, 2.0 - 0.5 * i as f64)).collect();
        let f = fit_line(&pts).unwrap();
        assert!((f.slope + 0.5).abs() < 1e-12 && (f.intercept - 2.0).abs() < 1e-12);
        assert!(f.slope_se < 1e-9);
        assert!(fit_line(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
    }

    /// The paper's point in miniature: a box drawn at a larger disparity than the surface it
    /// lies on (as a streak shows the virtual light, not the road). SGM follows the image, so
    /// against the surface's ground truth the "streak" pixels are bad and the others good.
    #[test]
    fn dense_disparity_is_scored_against_the_truth_split_by_the_streak_mask() {
        let mut scene = SynthScene::textured(160, 120, 5);
        scene.boxes.truncate(1);
        scene.noise = 0.0;
        let b = scene.boxes[0];
        let pair = scene.render().unwrap();
        let mut truth = pair.disparity.clone();
        let mut mask = GrayImage::new(160, 120, 0.0).unwrap();
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                truth.set(x, y, scene.background_disparity(y));
                mask.set(x, y, 1.0);
            }
        }
        let rig = Rig::new(
            Intrinsics::new(160, 120, 150.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let mut input = StereoInput {
            left: pair.left,
            right: pair.right,
            rig,
            lights: Vec::new(),
            truth_disparity: Some(truth),
            truth_depth: None,
            truth_streak_mask: Some(mask),
        };
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        let acc = a.report.dense.accuracy.expect("scored against the truth");
        eprintln!("{acc:?}");
        assert_eq!(acc.streak_mask, "renderer");
        let box_pixels = (b.x1 - b.x0) * (b.y1 - b.y0);
        assert_eq!(acc.streak.truth_pixels, box_pixels);
        assert_eq!(acc.all.truth_pixels, 160 * 120);
        assert_eq!(acc.non_streak.truth_pixels, 160 * 120 - box_pixels);
        assert!(acc.non_streak.bad < 0.05, "{:?}", acc.non_streak);
        assert!(acc.non_streak.mean_abs < 0.5, "{:?}", acc.non_streak);
        assert!(acc.non_streak.density > 0.8, "{:?}", acc.non_streak);
        assert!(acc.streak.bad > 0.8, "{:?}", acc.streak);
        assert!(acc.streak.mean_abs > 4.0, "{:?}", acc.streak);
        assert!(acc.all.bad > acc.non_streak.bad && acc.all.bad < acc.streak.bad);
        let table = summary_table(&a.report);
        assert!(
            table.contains("bad-2.0") && table.contains("non-streak"),
            "{table}"
        );
        // Without its own mask the analysis splits by the detector's; without a truth there is
        // no score.
        input.truth_streak_mask = None;
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        assert_eq!(a.report.dense.accuracy.unwrap().streak_mask, "detector");
        input.truth_disparity = None;
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        assert!(a.report.dense.accuracy.is_none());
    }

    /// A level rig 1.5 m above a road, and the ground-truth depth of a road that ends at the
    /// horizon (row 60 of 120) with the sky above.
    fn level_rig(baseline: f32) -> (Rig, GrayImage) {
        let rig = Rig::new(
            Intrinsics::new(160, 120, 150.0).unwrap(),
            baseline,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let mut depth = GrayImage::new(160, 120, f32::INFINITY).unwrap();
        for y in 60..120 {
            for x in 0..160 {
                depth.set(x, y, 150.0 * 1.5 / (y as f32 + 0.5 - 60.0));
            }
        }
        (rig, depth)
    }

    #[test]
    fn thin_vertical_objects_are_found_in_the_ground_truth_with_a_window_to_fit() {
        let (rig, mut depth) = level_rig(0.065);
        let geo = Geometry::new(&rig).unwrap();
        // A wall 20 m away above the road, a 6 px pole 8 m away standing on the road, and a
        // pole at the left border (its match would leave the right image).
        for y in 0..120 {
            for x in 0..160 {
                let wall_ground = y as f32 + 0.5 - 60.0 > 150.0 * 1.5 / 20.0;
                if !wall_ground {
                    depth.set(x, y, 20.0);
                }
            }
        }
        let pole_bottom = (60.0 + 150.0 * 1.5 / 8.0) as usize; // row 88
        for y in 0..pole_bottom {
            for x in (100..106).chain(0..3) {
                depth.set(x, y, 8.0);
            }
        }
        let found = find_objects(&depth, &geo, 3, 21);
        assert_eq!(found.len(), 1, "{found:?}");
        let p = &found[0];
        assert_eq!((p.region.x0, p.region.x1, p.region.y0), (100, 106, 0));
        // The rows more than 0.1 m above the road.
        assert!((p.region.y1 as i64 - 86).abs() <= 1, "{:?}", p.region);
        assert_eq!(p.window, 11);
        assert!(p.centres.iter().all(|c| c.1 == 103.0));
        // The widest pole is 32 pixels.
        for y in 0..pole_bottom {
            for x in 100..140 {
                depth.set(x, y, 8.0);
            }
        }
        assert!(find_objects(&depth, &geo, 3, 21).is_empty());
    }

    /// Fireflies (single pixels tens of times brighter than the texture, in one eye at a time)
    /// on a textured road: measured on the raw pair they throw whole rows off; after
    /// [`prepare_pair`] the road is sub-pixel accurate, and the analysis finds it by itself.
    #[test]
    fn road_is_measured_sub_pixel_through_fireflies() {
        let (rig, depth) = level_rig(0.3);
        // The road's disparity b (y + 0.5 - 60) / 1.5 on every row (negative above the
        // horizon, where the truth has no surface).
        let mut scene = SynthScene::textured(160, 120, 9);
        scene.boxes.clear();
        scene.disparity_top = -11.9;
        scene.disparity_bottom = 11.9;
        let mut pair = scene.render().unwrap();
        let mut rng = crate::synth::SplitMix(4);
        for img in [&mut pair.left, &mut pair.right] {
            for v in &mut img.data {
                if rng.uniform() < 1.0 / 150.0 {
                    *v += 20.0;
                }
            }
        }
        let mut truth = pair.disparity.clone();
        for (t, z) in truth.data.iter_mut().zip(&depth.data) {
            if !z.is_finite() {
                *t = f32::INFINITY;
            }
        }
        let input = StereoInput {
            left: pair.left,
            right: pair.right,
            rig,
            lights: Vec::new(),
            truth_disparity: Some(truth),
            truth_depth: Some(depth),
            truth_streak_mask: None,
        };
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        let road = a.report.regions.iter().find(|r| r.kind == "road");
        let road = road.expect("the road is found");
        let c = road.comparison.expect("confident rows");
        eprintln!("road: {} rows left out; {c:?}", road.low_confidence_rows);
        assert!(road.rows.len() >= 50, "{}", road.rows.len());
        assert!(c.rows + road.low_confidence_rows >= road.rows.len() - 2);
        assert!(c.rows >= 45, "{c:?}");
        assert!(c.rms_px < 0.1, "{c:?}");
        // The plot draws the left-out rows apart.
        let plot = rows_plot("road", &road.rows, "ground truth", Some(road.min_ncc));
        let count = |i: usize| plot.series[i].paths.iter().map(Vec::len).sum::<usize>();
        assert_eq!(count(0), road.rows.len() - road.low_confidence_rows);
        assert_eq!(count(1), road.low_confidence_rows);
        // Left out: the last rows, whose windows are cut by the bottom border.
        assert!(
            road.low_confidence_rows <= 5,
            "{}",
            road.low_confidence_rows
        );
        assert_eq!(road.comparison_all_rows.unwrap().rows, road.rows.len());
        // The same rows on the raw pair.
        let geo = Geometry::new(&input.rig).unwrap();
        let raw = RegionInput {
            input: &input,
            geo: &geo,
            left: &input.left,
            right: &input.right,
            min_ncc: -1.0,
        };
        let centres: Vec<(usize, f32)> = road.rows.iter().map(|r| (r.row, r.x)).collect();
        let lk = LkParams {
            window: road.window,
            rows: 5,
            max_disp: 16,
            ..LkParams::default()
        };
        let r = measure_region("raw".into(), "road", road.region, &centres, &lk, &raw).unwrap();
        let raw_rms = r.comparison.unwrap().rms_px;
        eprintln!("raw pair: RMS {raw_rms} px");
        assert!(raw_rms > 0.5, "{raw_rms}");
    }

    /// Streaks at 6.35 px in a pair sprinkled with fireflies: on the prepared pair the analysis
    /// measures them as on a clean one; on the raw pair the fireflies throw rows off.
    #[test]
    fn streaks_are_measured_through_fireflies() {
        let (mut left, _, _) = crate::detect::tests::scene_shifted(1.0, 0.0);
        let (mut right, _, _) = crate::detect::tests::scene_shifted(1.0, 6.35);
        let mut rng = crate::synth::SplitMix(8);
        for img in [&mut left, &mut right] {
            for v in &mut img.data {
                if rng.uniform() < 1.0 / 150.0 {
                    *v += 5.0;
                }
            }
        }
        let rig = Rig::new(
            Intrinsics::new(320, 240, 300.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let input = StereoInput {
            left,
            right,
            rig,
            lights: Vec::new(),
            truth_disparity: None,
            truth_depth: None,
            truth_streak_mask: None,
        };
        let params = AnalyzeParams {
            lk: LkParams {
                min_disp: 0,
                max_disp: 16,
                ..AnalyzeParams::default().lk
            },
            ..AnalyzeParams::default()
        };
        let a = analyze(&input, &params).unwrap();
        let rows: Vec<&RowRecord> = a.report.streaks.iter().flat_map(|s| &s.rows).collect();
        assert!(rows.len() > 150, "{} rows", rows.len());
        let rms = |d: &[f64]| (d.iter().map(|e| e * e).sum::<f64>() / d.len() as f64).sqrt();
        let err: Vec<f64> = rows.iter().map(|r| r.measured_px - 6.35).collect();
        eprintln!(
            "{} streak rows through fireflies: RMS {} px",
            err.len(),
            rms(&err)
        );
        assert!(rms(&err) < 0.25, "{}", rms(&err));
        let lk = LkParams {
            max_disp: 16,
            ..params.lk
        };
        let centres: Vec<(usize, f32)> = rows.iter().map(|r| (r.row, r.x)).collect();
        let raw = lk_rows(&input.left, &input.right, &centres, &lk).unwrap();
        let err: Vec<f64> = raw.iter().map(|r| r.disparity as f64 - 6.35).collect();
        eprintln!("the same rows on the raw pair: RMS {} px", rms(&err));
        assert!(rms(&err) > 0.5, "{}", rms(&err));
    }

    /// A synthetic pair with a known answer: a textured road whose disparity falls linearly
    /// from the bottom row to the top; LK over a region measured against the known value
    /// must agree, with the same slope.
    #[test]
    fn region_on_a_synthetic_pair_matches_its_known_disparity() {
        let mut scene = SynthScene::textured(160, 120, 3);
        scene.boxes.clear();
        scene.noise = 0.0;
        let pair = scene.render().unwrap();
        let rig = Rig::new(
            Intrinsics::new(160, 120, 150.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let input = StereoInput {
            left: pair.left,
            right: pair.right,
            rig,
            lights: Vec::new(),
            truth_disparity: Some(pair.disparity),
            truth_depth: None,
            truth_streak_mask: None,
        };
        let geo = Geometry::new(&input.rig).unwrap();
        let region = Region {
            x0: 60,
            x1: 75,
            y0: 20,
            y1: 100,
        };
        // The search range of the scene (the background spans 2.5 to 10 px).
        let lk = LkParams {
            max_disp: 16,
            ..LkParams::default()
        };
        let (left, right) = prepare_pair(&input.left, &input.right);
        let ri = RegionInput {
            input: &input,
            geo: &geo,
            left: &left,
            right: &right,
            min_ncc: 0.8,
        };
        let centres: Vec<(usize, f32)> = (20..100).map(|y| (y, region.centre_x())).collect();
        let r = measure_region("r".into(), "named", region, &centres, &lk, &ri).unwrap();
        assert_eq!(r.low_confidence_rows, 0);
        let c = r.comparison.unwrap();
        assert_eq!(c.rows, 80);
        eprintln!("synthetic road region: {c:?}");
        assert!(c.rms_px < 0.05, "RMS {} px", c.rms_px);
        assert!(c.slope_agrees, "{c:?}");
        let (m, p) = (c.measured_fit.unwrap(), c.predicted_fit.unwrap());
        assert!((m.slope - p.slope).abs() < 2e-3, "{m:?} vs {p:?}");
        // The depth stereo assigns is f b / d.
        let row = &r.rows[10];
        assert!((row.depth_m * row.measured_px - 150.0 * 0.065).abs() < 1e-3);
    }
}
