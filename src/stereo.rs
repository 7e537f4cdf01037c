//! `streaks stereo`: render a scene's camera as a rectified stereo pair with ground truth
//! (disparity and depth maps, streak masks, rig.json), an anaglyph and a side-by-side view.

use crate::render_opts::{Loaded, RenderOpts};
use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use streaks_analysis::report::AnalyzeParams;
use streaks_dataset::write::write_pair;
use streaks_stereo::render::{
    denoise_pair, expose_pair, render_pair, rig_from_camera, PairSettings,
};
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
    /// The rendering flags (as `streaks render`).
    #[command(flatten)]
    pub render: RenderOpts,
    /// Then analyse the pair (as `streaks analyze OUTPUT`), writing OUTPUT/analysis/.
    #[arg(long)]
    pub analyze: bool,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    // Phase 1: everything that needs no scene.
    let opts = &args.render;
    opts.check()?;
    let sensor = opts.sensor_profile()?;
    if !(args.baseline.is_finite() && args.baseline > 0.0) {
        bail!(
            "--baseline must be a positive number of metres, got {}",
            args.baseline
        );
    }
    // Phase 2: the scene (loaded once, one BVH for both eyes) and the rig.
    let Loaded {
        scene,
        camera,
        width,
        height,
    } = opts.load(&args.scene)?;
    let rig = rig_from_camera(&camera, width, height, args.baseline)
        .with_context(|| format!("the stereo rig of {}", args.scene.display()))?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create the folder {}", args.output.display()))?;
    let denoiser = opts.denoiser()?;
    let settings = PairSettings {
        render: opts.settings(),
        seed: opts.seed,
        exposure_ev: opts.exposure,
        mask: StreakMaskParams::default(),
        motion: opts.motion()?,
        albedo: denoiser.is_some(),
    };
    // Phase 3: render both eyes under one progress bar and write everything.
    let pool = opts.thread_pool()?;
    let bar = opts.progress(2, width, height)?;
    let mut views = pool.install(|| render_pair(&scene, &rig, &settings, &|n| bar.inc(n)))?;
    bar.finish_and_clear();
    if let Some(d) = &denoiser {
        denoise_pair(&mut views, d)
            .with_context(|| format!("denoising the pair of {}", args.scene.display()))?;
    }
    if let Some(profile) = &sensor {
        pool.install(|| expose_pair(&mut views, &rig, profile, opts.seed, opts.exposure))?;
    }
    write_pair(&args.output, &scene, &rig, &views, opts.exposure)
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
        opts.spp,
        args.baseline,
        rig.focal_px(),
        streak(0),
        streak(1),
        args.output.display()
    );
    if args.analyze {
        crate::cli::analyze_pair(&args.output, &AnalyzeParams::default())?;
    }
    Ok(())
}
