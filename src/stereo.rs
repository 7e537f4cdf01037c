//! `streaks stereo`: render a scene's camera as a rectified stereo pair with ground truth
//! (disparity and depth maps, streak masks, rig.json), an anaglyph and a side-by-side view.

use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use streaks_render::scene::Scene;
use streaks_stereo::render::{render_pair, rig_from_camera, write_pair, PairSettings};
use streaks_stereo::rig::Rig;
use streaks_stereo::streak_mask::StreakMaskParams;

/// Render a rectified stereo pair of a scene's camera, with ground truth.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene (.gltf, .glb or .obj).
    pub scene: PathBuf,
    /// Output folder (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Baseline in metres (left eye at -b/2, right eye at +b/2 along the camera's +X).
    #[arg(long, default_value_t = Rig::DEFAULT_BASELINE)]
    pub baseline: f32,
    /// Samples per pixel (per eye).
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Image width in pixels [default: from the height and the camera's aspect ratio].
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels [default: 480, or from the width and the aspect ratio].
    #[arg(long)]
    pub height: Option<u32>,
    /// Camera name [default: the scene's first camera].
    #[arg(long)]
    pub camera: Option<String>,
    /// Sampler seed of the left eye (the right eye uses seed + 1).
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Longest path, Mitsuba's meaning: 1 = emitters only, 2 = direct light, 3 = one bounce...
    #[arg(long, default_value_t = 8)]
    pub max_depth: u32,
    /// Exposure of the PNGs in stops (linear * 2^EV before the sRGB curve).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Then analyse the pair (as `streaks analyze OUTPUT`), writing OUTPUT/analysis/.
    #[arg(long)]
    pub analyze: bool,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    // Phase 1: everything that needs no scene.
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    if args.max_depth == 0 {
        bail!("--max-depth must be at least 1 (1 renders only emitters seen directly)");
    }
    if !args.exposure.is_finite() {
        bail!("--exposure must be a finite number of stops");
    }
    if !(args.baseline.is_finite() && args.baseline > 0.0) {
        bail!(
            "--baseline must be a positive number of metres, got {}",
            args.baseline
        );
    }
    // Phase 2: the scene (loaded once, one BVH for both eyes) and the rig.
    let scene = Scene::load(&args.scene)
        .with_context(|| format!("cannot load the scene {}", args.scene.display()))?;
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    let camera = scene
        .camera(args.camera.as_deref())
        .with_context(|| format!("in the scene {}", args.scene.display()))?;
    let (width, height) = crate::render::image_size(args.width, args.height, camera.aspect_ratio)?;
    let rig = rig_from_camera(camera, width, height, args.baseline)
        .with_context(|| format!("the stereo rig of {}", args.scene.display()))?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create the folder {}", args.output.display()))?;
    let settings = PairSettings {
        spp: args.spp,
        max_depth: args.max_depth,
        seed: args.seed,
        exposure_ev: args.exposure,
        mask: StreakMaskParams::default(),
    };
    // Phase 3: render both eyes under one progress bar and write everything.
    let total = (2 * width as u64 * height as u64)
        .checked_mul(args.spp as u64)
        .context("2 * width * height * spp overflows")?;
    let bar = crate::render::progress_bar(total);
    let views = render_pair(&scene, &rig, &settings, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    write_pair(&args.output, &scene, &rig, &views, args.exposure)
        .with_context(|| format!("writing the pair into {}", args.output.display()))?;
    let seconds: f64 = views.iter().map(|v| v.output.stats.seconds).sum();
    let dropped: u64 = views.iter().map(|v| v.output.stats.nonfinite_dropped).sum();
    let streak = |i: usize| {
        views[i]
            .streak_mask
            .data
            .iter()
            .filter(|&&m| m > 0.0)
            .count()
    };
    eprintln!(
        "rendered {width}x{height}, {} spp per eye, baseline {} m, f = {:.1} px in {seconds:.2} s \
         ({dropped} non-finite samples dropped); streak pixels: {} left, {} right; wrote {}",
        args.spp,
        args.baseline,
        rig.focal_px(),
        streak(0),
        streak(1),
        args.output.display()
    );
    if args.analyze {
        let params = crate::analyze::Args::for_dir(&args.output).params();
        crate::analyze::analyze_dir(&args.output, &params)?;
    }
    Ok(())
}
