//! What the analysis writes: the disparity-against-row plots ([`rows_plot`]), `report.json`
//! ([`write_report_json`]), every output file ([`write_outputs`]) and the console table
//! ([`summary_table`]).

use super::dense::for_each_point;
use super::input::{RigView, StereoInput};
use super::stats::span;
use super::{Analysis, Report, ReportError, RowRecord};
use crate::plot::{Marker, Plot, Series, BLACK_RGB, BLUE, GREY, RED};
use crate::sgm::disparity_preview;
use std::path::{Path, PathBuf};
use streaks_image::png::write_png_buffer;
use streaks_image::stats::median;
use streaks_image::write_bytes_atomically;

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
    write_bytes_atomically(path, text.as_bytes()).map_err(|e| write_err(path)(e.to_string()))
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
    let view = RigView::new(&input.rig)?;
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
    write_png_buffer(&path, &img)?;
    written.push(path);
    let path = dir.join("streak_mask.png");
    analysis
        .streak_mask
        .save_png(&path)
        .map_err(|e| write_err(&path)(e.to_string()))?;
    written.push(path);
    // Side view of the point cloud.
    let (mut other, mut streak) = (Vec::new(), Vec::new());
    for_each_point(&analysis.dense, mask, &view, |x, y, is_streak, p| {
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
        "what        rows  light  meas span  pred span  road span  RMS px   RMS deg   slope ok  median Z  median Y  centre RMS px\n",
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    for st in &report.streaks {
        let c = st.comparison.as_ref();
        s.push_str(&format!(
            "streak{:<5} {:>4}  {:>5}  {:>9}  {:>9}  {:>9}  {:>7}  {:>8}  {:>8}  {:>7.2}m  {:>7.2}m  {:>13}\n",
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
            opt(st.centre_comparison.map(|c| c.rms_px)),
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
            median(r.rows.iter().map(|x| x.depth_m)).unwrap_or(f64::NAN),
            median(r.rows.iter().map(|x| x.road_y_m)).unwrap_or(f64::NAN),
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
    if let Some(c) = &report.road_plane {
        let warn = if c.violated { "warning: " } else { "" };
        s.push_str(&format!("{warn}{}\n", c.message()));
    }
    s
}
