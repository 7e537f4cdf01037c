//! The analysis itself ([`analyze`]): streaks found, matched to their lights and measured row
//! by row against Eq. 4; named regions, poles and road measured against the ground truth; the
//! dense disparity summarised. Each step calls its stage's module.

use super::dense::{dense_accuracy, disparity_range, summarize_dense};
use super::input::{RigView, StereoInput};
use super::lights::match_light;
use super::output::write_outputs;
use super::stats::{compare, compare_with, span};
use super::targets::{find_objects, find_road};
use super::{Analysis, RegionReport, Report, ReportError, RigSummary, RowRecord, StreakReport};
use crate::centre::CentreModel;
use crate::detect::{detect_streaks, score_mask, vertical_truth, DetectParams, Streak};
use crate::lk::{lk_rows, prepare_pair, LkError, LkParams, RowDisparity};
use crate::model::streak_rows;
use crate::road_plane::RoadPlaneCheck;
use crate::sgm::{sgm, SgmParams};
use glam::{DVec3, Vec3};
use std::path::{Path, PathBuf};
use streaks_image::stats::median;
use streaks_image::{GrayImage, NamedRegion, Region};

/// Parameters of [`analyze`].
#[derive(Clone, Debug)]
pub struct AnalyzeParams {
    /// The per-row estimator, 21 x 5 pixels by default (its largest disparity is replaced by
    /// the scene's, from the ground truth or the road at the bottom row).
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

/// The record of one LK measurement: its angles and the point its disparity implies, with
/// the prediction (Eq. 4 for a streak, the ground truth for a region) and, for a streak, the
/// road's disparity at the same pixel.
fn record(
    view: &RigView,
    r: &RowDisparity,
    predicted_px: Option<f64>,
    road_px: Option<f64>,
) -> RowRecord {
    let cam = &view.camera;
    let (x, y, d) = (r.x as f64, r.row as f64 + 0.5, r.disparity as f64);
    let depth = if d > 0.0 {
        cam.depth_from_disparity_px(d)
    } else {
        f64::INFINITY
    };
    let p = if depth.is_finite() {
        view.implied(r.x, y as f32, depth as f32)
    } else {
        Vec3::splat(f32::NAN)
    };
    RowRecord {
        row: r.row,
        x: r.x,
        elevation_deg: cam.row_elevation_deg(y),
        measured_px: d,
        measured_deg: cam.angular_disparity_deg_px(x, d),
        predicted_px,
        predicted_deg: predicted_px.map(|p| cam.angular_disparity_deg_px(x, p)),
        centre_px: None,
        centre_deg: None,
        road_px,
        depth_m: depth,
        road_y_m: p.y as f64,
        road_z_m: p.z as f64,
        ncc: r.ncc,
    }
}

/// Wraps an estimator error with what was being measured.
fn lk_err(what: impl Into<String>) -> impl FnOnce(LkError) -> ReportError {
    let what = what.into();
    move |source| ReportError::Lk { what, source }
}

/// Measures one streak along its centres and predicts it from the light it is matched to
/// (unless `predict` is false: the road is not the plane Eq. 4 assumes, [`RoadPlaneCheck`]); the
/// match is dropped when the streak's disparity is the road's
/// ([`AnalyzeParams::road_reject_px`]: a glow or road texture, not a reflection).
fn analyze_streak(
    index: usize,
    streak: &Streak,
    on: &RegionInput,
    params: &AnalyzeParams,
    lk: &LkParams,
    predict: bool,
) -> Result<StreakReport, ReportError> {
    let (input, view) = (on.input, on.view);
    let (w, h) = (input.left.width as f32, input.left.height);
    let centres: Vec<(usize, f32)> = streak
        .centres
        .iter()
        .copied()
        .filter(|&(y, x)| y < h && (0.0..=w).contains(&x))
        .collect();
    let measured = lk_rows(on.left, on.right, &centres, lk)
        .map_err(lk_err(format!("LK along streak {index}")))?;
    let mut light = match_light(streak, &input.lights, view, params.match_tolerance_px);
    let mut predicted = std::collections::HashMap::new();
    if let Some(l) = light.as_ref().filter(|_| predict) {
        let rows = streak.first_row as u32..streak.last_row as u32 + 1;
        let mirror = DVec3::new(l.road[0], -l.road[1], l.road[2]);
        let model_x = l.mirror_px[0] - 0.5 * view.camera.disparity_px(mirror);
        let pred = streak_rows(
            DVec3::from_array(l.road),
            &view.camera,
            rows,
            Some(model_x),
            None,
        )
        .map_err(|source| ReportError::Model {
            what: format!("Eq. 4 for streak {index}"),
            source,
        })?;
        // The streak-centre model on the same rows: each eye's brightest point of the row's
        // ground line (a roll-free rig sees one depth per row in both eyes).
        let centre =
            CentreModel::new(DVec3::from_array(l.road), view.camera).map_err(|source| {
                ReportError::Model {
                    what: format!("the streak-centre model for streak {index}"),
                    source,
                }
            })?;
        for p in pred {
            let road_px = view.camera.disparity_px(p.point.reflection.ground);
            let centre_px = centre.row(p.point.reflection.ground.z).disparity_px;
            predicted.insert(p.row as usize, (p.point.disparity_px, road_px, centre_px));
        }
    }
    let mut rows: Vec<RowRecord> = measured
        .iter()
        .map(|r| {
            let p = predicted.get(&r.row);
            let mut rec = record(view, r, p.map(|p| p.0), p.map(|p| p.1));
            rec.centre_px = p.map(|p| p.2).filter(|d| d.is_finite());
            rec.centre_deg = rec
                .centre_px
                .map(|d| view.camera.angular_disparity_deg_px(f64::from(r.x), d));
            rec
        })
        .collect();
    let off_road = median(
        rows.iter()
            .filter_map(|r| r.road_px.map(|road| (r.measured_px - road).abs())),
    )
    .unwrap_or(f64::NAN);
    if off_road.is_finite() && off_road < params.road_reject_px as f64 {
        light = None;
        for r in &mut rows {
            (r.predicted_px, r.predicted_deg, r.road_px) = (None, None, None);
            (r.centre_px, r.centre_deg) = (None, None);
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
        centre_comparison: compare_with(&rows, |r| r.centre_px.zip(r.centre_deg)),
        road_span_px: (!road.is_empty()).then(|| span(road.iter().copied())),
        median_depth_m: median(rows.iter().map(|r| r.depth_m)).unwrap_or(f64::NAN),
        median_road_y_m: median(rows.iter().map(|r| r.road_y_m)).unwrap_or(f64::NAN),
        min_road_y_m: rows
            .iter()
            .map(|r| r.road_y_m)
            .filter(|y| y.is_finite())
            .fold(f64::INFINITY, f64::min),
        rows,
    })
}

/// What [`measure_region`] and [`analyze_streak`] need besides the region or streak.
struct RegionInput<'a> {
    input: &'a StereoInput,
    view: &'a RigView,
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
            record(ri.view, r, truth, None)
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
    let view = RigView::new(&input.rig)?;
    let road_plane = match (&input.truth_depth, &input.truth_road_mask) {
        (Some(depth), Some(road)) => RoadPlaneCheck::from_depth(depth, road, &input.rig),
        _ => None,
    };
    let predict = road_plane.is_none_or(|c| !c.violated);
    let range = disparity_range(input, &view);
    // The search range of the scene: a wider one lets windows near the left edge run out of
    // the right image and the integer search pick a flat window.
    let lk = LkParams {
        max_disp: range.max(params.lk.min_disp),
        ..params.lk
    };
    let detect = DetectParams {
        horizon: params.detect.horizon.or(Some(
            view.camera
                .horizon_row()
                .clamp(0.0, input.left.height as f64) as f32,
        )),
        ..params.detect
    };
    let found = detect_streaks(&input.left, &detect)?;
    // Every LK measurement is made on the prepared pair.
    let (left, right) = prepare_pair(&input.left, &input.right);
    let ri = RegionInput {
        input,
        view: &view,
        left: &left,
        right: &right,
        min_ncc: params.min_ncc,
    };
    let streaks = found
        .streaks
        .iter()
        .enumerate()
        .map(|(i, s)| analyze_streak(i, s, &ri, params, &lk, predict))
        .collect::<Result<Vec<_>, _>>()?;
    let mut regions = Vec::new();
    for r in &params.regions {
        let g = r.region;
        g.check_fits(&r.name, input.left.width, input.left.height)?;
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
        for (i, p) in find_objects(depth, &view, params.auto_objects, lk.window)
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
            if let Some(p) = find_road(depth, &mask, &left, &view, lk.window / 2) {
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
    let dense_summary = summarize_dense(&dense, &found.mask, &view, sgm_params.max_disp, accuracy);
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
            pitch_deg: view.camera.pitch().to_degrees(),
            horizon_row: view.camera.horizon_row(),
        },
        horizon_row: found.horizon,
        lamps: found.lamps.len(),
        glows: found.glows.len(),
        streaks,
        regions,
        dense: dense_summary,
        detection,
        detection_vertical,
        road_plane,
    };
    Ok(Analysis {
        report,
        streak_mask: found.mask,
        dense,
    })
}

#[cfg(test)]
mod tests {
    use super::super::rows_plot;
    use super::super::targets::tests::level_rig;
    use super::*;
    use crate::synth::SynthScene;
    use glam::Affine3A;
    use streaks_stereo::rig::{Intrinsics, Rig};

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
            truth_road_mask: None,
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
        let view = RigView::new(&input.rig).unwrap();
        let raw = RegionInput {
            input: &input,
            view: &view,
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
            truth_road_mask: None,
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
            truth_road_mask: None,
        };
        let view = RigView::new(&input.rig).unwrap();
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
            view: &view,
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

/// A pair folder analysed by [`analyze_dir`].
#[derive(Clone, Debug)]
pub struct DirAnalysis {
    /// The numbers.
    pub report: Report,
    /// The folder the outputs went into (`DIR/analysis`).
    pub out: PathBuf,
    /// The files written there.
    pub written: Vec<PathBuf>,
}

/// Reads the pair in `dir` ([`StereoInput::load`]), analyses it with `params` ([`analyze`])
/// and writes every output into `dir/analysis/` ([`write_outputs`]): what `streaks analyze
/// DIR` does, and `streaks stereo --analyze` and `streaks paper` after rendering a pair.
pub fn analyze_dir(dir: &Path, params: &AnalyzeParams) -> Result<DirAnalysis, ReportError> {
    let in_folder = |stage: &'static str, dir: &Path| {
        let dir = dir.to_path_buf();
        move |e: ReportError| ReportError::Folder {
            stage,
            dir,
            source: Box::new(e),
        }
    };
    let input = StereoInput::load(dir).map_err(in_folder("reading the pair in", dir))?;
    let analysis = analyze(&input, params).map_err(in_folder("analysing", dir))?;
    let out = dir.join("analysis");
    let written = write_outputs(&out, &analysis, &input)
        .map_err(in_folder("writing the analysis into", &out))?;
    Ok(DirAnalysis {
        report: analysis.report,
        out,
        written,
    })
}
