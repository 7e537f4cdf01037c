//! `streaks paper -o DIR`: the paper's figures in one command, each beside the paper's claim
//! and our numbers in `DIR/index.md`.
//!
//! Fig. 2: the three `paper_fig2` scenes rendered (left eye of the default rig); Fig. 3: their
//! ground-plane texture maps; Fig. 4 and Fig. 5: the column model; Fig. 6: a stereo render of
//! `paper_fig6`, the 1D LK disparity along the streak against Eq. 4 and against the
//! streak-centre model (pixels and degrees against elevation), with the RMS differences and a
//! line fit to each curve.

use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;
use streaks_analysis::figures;
use streaks_analysis::plot::{Marker, Plot, Series, BLACK_RGB, BLUE, GREY, ORANGE};
use streaks_analysis::report::{AnalyzeParams, Comparison, Report, RowRecord, StreakReport};
use streaks_dataset::write::write_pair;
use streaks_image::png::write_png;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_render::scene::Scene;
use streaks_settings::RenderSettings;
use streaks_stereo::render::{render_eye, render_pair, rig_from_camera, PairSettings};
use streaks_stereo::rig::{Eye, Rig};
use streaks_stereo::streak_mask::StreakMaskParams;
use streaks_stereo::texture_map::{plot_texture_map, texture_map, MapSpec};

/// Reproduce the paper's figures (2 to 6) with our renderer and model, and an index.md.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output folder (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The folder holding the paper_fig2_*.gltf and paper_fig6.gltf scenes.
    #[arg(long, default_value = "scenes")]
    pub scenes: PathBuf,
    /// Fig. 2 image width (the height follows the camera's 14 x 28 degree view).
    #[arg(long, default_value_t = 200)]
    pub fig2_width: u32,
    /// Fig. 2 samples per pixel.
    #[arg(long, default_value_t = 32)]
    pub fig2_spp: u32,
    /// Fig. 6 image height (square images; the streak covers about a quarter of the rows).
    #[arg(long, default_value_t = 640)]
    pub fig6_size: u32,
    /// Fig. 6 samples per pixel per eye.
    #[arg(long, default_value_t = 64)]
    pub fig6_spp: u32,
}

const FIG2: [(&str, &str); 3] = [
    ("blinn_phong", "(a) Blinn-Phong, s = 1000"),
    ("ward", "(b) Ward, alpha = 0.05"),
    ("sphere", "(c) ray sampled, spherical lights"),
];

fn step(n: usize, what: &str) {
    eprintln!("[{n}/5] {what}");
}

/// The three Fig. 2 renders and their texture maps (Fig. 3).
fn fig2_and_3(args: &Args, out: &Path, index: &mut String) -> Result<()> {
    step(1, "Fig. 2: rendering the three paper_fig2 scenes");
    let mut images = Vec::new();
    for (name, caption) in FIG2 {
        let path = args.scenes.join(format!("paper_fig2_{name}.gltf"));
        let scene = Scene::load(&path)
            .with_context(|| format!("cannot load the scene {}", path.display()))?;
        let camera = scene
            .camera(None)
            .with_context(|| format!("in the scene {}", path.display()))?;
        let (w, h) = crate::cli::image_size(Some(args.fig2_width), None, camera.aspect_ratio())?;
        let rig = rig_from_camera(camera, w, h, Rig::DEFAULT_BASELINE)?;
        let settings = PairSettings {
            render: RenderSettings::new(args.fig2_spp, 8),
            seed: 0,
            exposure_ev: 0.0,
            mask: StreakMaskParams::default(),
            motion: Default::default(),
            albedo: false,
        };
        let bar = crate::cli::progress_bar(w as u64 * h as u64 * args.fig2_spp as u64);
        let view = render_eye(&scene, &rig, Eye::Left, &settings, &|n| bar.inc(n))?;
        bar.finish_and_clear();
        let png = out.join(format!("fig2_{name}.png"));
        write_png(&png, &view.output.image, 0.0)?;
        eprintln!(
            "  {caption}: {w}x{h}, {} spp in {:.1} s",
            args.fig2_spp, view.output.stats.seconds
        );
        images.push((name, caption, rig, view.output.image));
    }
    step(2, "Fig. 3: texture maps of the Fig. 2 renders");
    // The lamps are at Z_L = 50 m, X = -4, 0, 4 m: the map covers the 14 degree view up to them.
    let spec = MapSpec::new((-7.0, 7.0), (1.0, 52.0), 0.05)?;
    for (name, caption, rig, image) in &images {
        let (w, h) = (image.width as usize, image.height as usize);
        let channels = (0..3)
            .map(|c| GrayImage::from_vec(w, h, image.pixels.iter().map(|p| p[c]).collect()))
            .collect::<Result<Vec<_>, _>>()?;
        let map = texture_map(&channels, rig, Eye::Left, &spec)?;
        plot_texture_map(
            &map,
            &out.join(format!("fig3_{name}.png")),
            &format!("Fig. 3 {caption}"),
        )?;
    }
    let _ = writeln!(
        index,
        "## Fig. 2 and Fig. 3: streaks from three reflectance models\n\n\
         Paper: the three models (Blinn-Phong s = 1000, Ward alpha = 0.05, ray-sampled spherical \
         lights) all give vertically elongated streaks of similar width and length below lamps at \
         heights Z_L/50, 2 Z_L/50, 3 Z_L/50; in the texture map (Fig. 3) the streaks' axes pass \
         through the viewer's feet (X, Z) = (0, 0).\n\n\
         Ours: {} x {} pixels, {} spp (left eye of the rig at the scene's `viewer` camera); \
         texture maps over X in [-7, 7] m, Z in [1, 52] m at 5 cm.\n",
        args.fig2_width,
        images.first().map_or(0, |i| i.3.height),
        args.fig2_spp
    );
    let _ = writeln!(index, "| model | Fig. 2 | Fig. 3 |\n|---|---|---|");
    for (name, caption, _, _) in &images {
        let _ = writeln!(
            index,
            "| {caption} | ![](fig2_{name}.png) | ![](fig3_{name}.png) |"
        );
    }
    index.push('\n');
    Ok(())
}

fn fig4_and_5(out: &Path, index: &mut String) -> Result<()> {
    step(3, "Fig. 4 and Fig. 5: the virtual light columns of Eq. 4");
    figures::fig4()?.write_png(&out.join("fig4.png"))?;
    figures::fig5()?.write_png(&out.join("fig5.png"))?;
    let _ = writeln!(
        index,
        "## Fig. 4 and Fig. 5: the virtual light column\n\n\
         Paper: the locus of L_virtual (Eq. 4) for lights at Z_L/20, Z_L/10, 3 Z_L/20 (viewer at \
         Z_L/10, tilt of h below 4 degrees) is a column below the road, slightly sloped; the slope \
         comes from the tilt of h (Fig. 5).\n\n![](fig4.png)\n\n![](fig5.png)\n"
    );
    Ok(())
}

fn fmt_fit(c: &Comparison) -> (String, String) {
    let f = |fit: Option<streaks_analysis::report::LineFit>| {
        fit.map_or("-".to_string(), |f| {
            format!("{:.2e} +- {:.1e} px/row", f.slope, f.slope_se)
        })
    };
    (f(c.measured_fit), f(c.predicted_fit))
}

/// The two Fig. 6 plots, `fig6_deg.png` (disparity in degrees) and `fig6_px.png` (in pixels,
/// with the matte road's disparity dashed), of the rows where the streak was measured.
fn fig6_plots(out: &Path, streak: &StreakReport) -> Result<()> {
    let rows: Vec<&RowRecord> = streak
        .rows
        .iter()
        .filter(|r| r.measured_px.is_finite())
        .collect();
    let pts = |f: &dyn Fn(&RowRecord) -> Option<f64>| -> Vec<(f64, f64)> {
        rows.iter()
            .filter_map(|r| f(r).map(|v| (v, r.elevation_deg)))
            .collect()
    };
    /// One Fig. 6 plot: its unit, file and the value each series takes from a row.
    struct Unit {
        unit: &'static str,
        file: &'static str,
        measured: fn(&RowRecord) -> Option<f64>,
        predicted: fn(&RowRecord) -> Option<f64>,
        centre: fn(&RowRecord) -> Option<f64>,
        road: Option<fn(&RowRecord) -> Option<f64>>,
    }
    let units = [
        Unit {
            unit: "degrees",
            file: "fig6_deg.png",
            measured: |r| Some(r.measured_deg),
            predicted: |r| r.predicted_deg,
            centre: |r| r.centre_deg,
            road: None,
        },
        Unit {
            unit: "px",
            file: "fig6_px.png",
            measured: |r| Some(r.measured_px),
            predicted: |r| r.predicted_px,
            centre: |r| r.centre_px,
            road: Some(|r| r.road_px),
        },
    ];
    for u in units {
        let title_unit = if u.unit == "px" { "pixels" } else { u.unit };
        let mut plot = Plot::new(
            format!("Fig. 6: disparity along the streak ({title_unit})"),
            format!("disparity ({})", u.unit),
            "elevation below the horizon (degrees)",
        )
        .with(Series::scatter(
            "measured (1D LK)",
            BLACK_RGB,
            Marker::Circle,
            pts(&u.measured),
        ))
        .with(Series::line("Eq. 4 + Eq. 5", BLUE, pts(&u.predicted)))
        .with(Series::line("streak-centre model", ORANGE, pts(&u.centre)));
        if let Some(road) = u.road {
            plot = plot.with(Series::dashed(
                "road surface (matte road)",
                GREY,
                pts(&road),
            ));
        }
        plot.write_png(&out.join(u.file))?;
    }
    Ok(())
}

/// The Fig. 6 stereo render, its analysis and plots.
fn fig6(args: &Args, out: &Path, index: &mut String) -> Result<Report> {
    step(4, "Fig. 6: stereo render of paper_fig6");
    let path = args.scenes.join("paper_fig6.gltf");
    let scene =
        Scene::load(&path).with_context(|| format!("cannot load the scene {}", path.display()))?;
    let camera = scene
        .camera(None)
        .with_context(|| format!("in the scene {}", path.display()))?;
    let (w, h) = crate::cli::image_size(None, Some(args.fig6_size), camera.aspect_ratio())?;
    let rig = rig_from_camera(camera, w, h, Rig::DEFAULT_BASELINE)?;
    let settings = PairSettings {
        render: RenderSettings::new(args.fig6_spp, 8),
        seed: 0,
        exposure_ev: 0.0,
        mask: StreakMaskParams::default(),
        motion: Default::default(),
        albedo: false,
    };
    let bar = crate::cli::progress_bar(2 * w as u64 * h as u64 * args.fig6_spp as u64);
    let views = render_pair(&scene, &rig, &settings, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    let seconds: f64 = views.iter().map(|v| v.output.stats.seconds).sum();
    eprintln!("  {w}x{h}, {} spp per eye in {seconds:.1} s", args.fig6_spp);
    let dir = out.join("fig6");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_pair(&dir, &scene, &rig, &views, 0.0)?;
    step(5, "Fig. 6: 1D LK along the streak against Eq. 4");
    let report = crate::cli::analyze_pair(&dir, &AnalyzeParams::default())?;
    let streak = report
        .streaks
        .iter()
        .filter(|s| s.light.is_some() && s.comparison.is_some())
        .max_by_key(|s| s.rows.len())
        .context("no streak of paper_fig6 was matched to its light")?;
    let c = streak.comparison.context("no comparison")?;
    let cc = streak
        .centre_comparison
        .context("no comparison with the streak-centre model")?;
    fig6_plots(out, streak)?;
    let (mfit, pfit) = fmt_fit(&c);
    let (_, cfit) = fmt_fit(&cc);
    let span_deg = |f: &dyn Fn(&RowRecord) -> Option<f64>| {
        let v: Vec<f64> = streak
            .rows
            .iter()
            .filter_map(f)
            .filter(|v| v.is_finite())
            .collect();
        v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - v.iter().copied().fold(f64::INFINITY, f64::min)
    };
    // Where the two fitted lines meet: (a_p - a_m) / (b_m - b_p) with y = a + b row.
    let crossing = match (c.measured_fit, c.predicted_fit) {
        (Some(m), Some(p)) if (m.slope - p.slope).abs() > 1e-12 => {
            Some((p.intercept - m.intercept) / (m.slope - p.slope))
        }
        _ => None,
    };
    let elev = span_deg(&|r| r.predicted_px.map(|_| r.elevation_deg));
    let _ = writeln!(
        index,
        "## Fig. 6: disparity along a streak, measured against Eq. 4\n\n\
         Paper: light 15 m ahead at 1.5 m, viewer at 1.5 m, baseline 6.5 cm, Ward road. The 1D \
         Lucas-Kanade disparity along the streak and the disparity of the L_virtual locus (Eq. 4 \
         with Eq. 5) are both nearly constant: the model's varies by 0.007 degrees over nearly 9 \
         degrees of elevation; the differences between the curves are very small.\n\n\
         Ours: {w} x {h} pixels (f = {:.1} px), {} spp per eye, streak rows {}..{} ({} rows \
         with both curves, {elev:.2} degrees of elevation).\n\n\
         | quantity | measured (LK) | predicted (Eq. 4) | streak-centre model |\n|---|---|---|---|\n\
         | span along the streak | {:.4} px = {:.5} deg | {:.4} px = {:.5} deg | {:.4} px = {:.5} deg |\n\
         | line fit, disparity against row | {mfit} | {pfit} | {cfit} |\n\
         | RMS difference from the measurement | | {:.4} px = {:.5} deg (mean {:+.4} px) | {:.4} px = {:.5} deg (mean {:+.4} px) |\n\
         | slope agrees with the measurement's (within 2 combined standard errors) | | {} | {} |\n\
         | a matte road over the same rows would span | {} px | |\n\
         | median depth stereo assigns / median height of the implied points | {:.2} m / {:.2} m | light at Z = 15 m, mirror image at Y = -1.5 m |\n\
         | row where the fitted lines cross (paper: at the mirror image) | {} | mirror image at row {:.1} |\n\n\
         ![](fig6_deg.png)\n\n![](fig6_px.png)\n\n\
         **Why the measurement is flatter than Eq. 4.** Each eye sees a row's streak brightest \
         where the half vector is nearest the normal (the maximum of any isotropic microfacet \
         distribution): the streak-centre model (`streaks locus --model centre`, \
         `crates/analysis/src/centre.rs`). That point lies on (or within micrometres of) the \
         vertical plane through the eye and the light's vertical line; the whole plane projects \
         onto the light's own image column, so each eye sees the streak centre in the column \
         where it sees the light, and the streak's disparity is the light's, f b / Z_L, on every \
         row. Eq. 4 mirrors the light about the rig centre's microfacet at each ground point, \
         whose slant moves the virtual light nearer at the near end and farther at the far end; \
         the two agree at the mirror point only.\n\n\
         The whole analysis (report.json, plots, depth map, \
         side view of the point cloud) is in [fig6/analysis](fig6/analysis/).\n",
        rig.focal_px(),
        args.fig6_spp,
        streak.first_row,
        streak.last_row,
        c.rows,
        c.measured_span_px,
        span_deg(&|r| Some(r.measured_deg)),
        c.predicted_span_px,
        span_deg(&|r| r.predicted_deg),
        cc.predicted_span_px,
        span_deg(&|r| r.centre_deg),
        c.rms_px,
        c.rms_deg,
        c.bias_px,
        cc.rms_px,
        cc.rms_deg,
        cc.bias_px,
        if c.slope_agrees { "yes" } else { "no" },
        if cc.slope_agrees { "yes" } else { "no" },
        streak.road_span_px.map_or("-".into(), |v| format!("{v:.3}")),
        streak.median_depth_m,
        streak.median_road_y_m,
        crossing.map_or("-".into(), |y| format!("{y:.1}")),
        streak.light.as_ref().map_or(f64::NAN, |l| l.mirror_px[1]),
    );
    Ok(report)
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    for (name, v) in [
        ("--fig2-width", args.fig2_width),
        ("--fig2-spp", args.fig2_spp),
        ("--fig6-size", args.fig6_size),
        ("--fig6-spp", args.fig6_spp),
    ] {
        if v == 0 {
            anyhow::bail!("{name} must be at least 1");
        }
    }
    let start = Instant::now();
    let out = &args.output;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the folder {}", out.display()))?;
    let mut index = String::from(
        "# Specular streaks in stereo: the paper's figures, reproduced\n\n\
         Made by `streaks paper`. Each section states the paper's claim and our numbers.\n\n",
    );
    fig2_and_3(&args, out, &mut index)?;
    fig4_and_5(out, &mut index)?;
    fig6(&args, out, &mut index)?;
    let _ = writeln!(index, "Made in {:.0} s.", start.elapsed().as_secs_f64());
    let path = out.join("index.md");
    write_bytes_atomically(&path, index.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!(
        "wrote {} in {:.1} s",
        path.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
