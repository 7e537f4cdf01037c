//! `streaks export-mitsuba`: writes a scene as a Mitsuba 3 scene (XML, PLY meshes, EXR
//! textures) with the same render settings as `streaks render`, for the cross-check in
//! tools/mitsuba/. Every approximation of the mapping is printed as a warning.

use anyhow::Context;
use std::path::PathBuf;
use streaks_render::mitsuba::{export, ExportOptions};

/// Arguments of `streaks export-mitsuba`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The glTF (or OBJ) scene.
    pub scene: PathBuf,
    /// Output folder (created): scene.xml, meshes/, textures/.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 480)]
    pub height: u32,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Maximum path depth (Mitsuba's meaning: 1 emitters only, 2 direct light, ...).
    #[arg(long, default_value_t = 8)]
    pub max_depth: u32,
    /// Camera name or number, as `streaks render --camera` (default: the scene's first camera;
    /// a scene without cameras gets the default camera, with a warning).
    #[arg(long)]
    pub camera: Option<String>,
    /// Sampler seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Let the scene read files outside its folder (as `streaks render`).
    #[arg(long)]
    pub allow_outside_scene: bool,
    /// The environment light flags.
    #[command(flatten)]
    pub env: crate::render_opts::EnvOpts,
}

/// Runs the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let scene = args.env.load_scene(&args.scene, args.allow_outside_scene)?;
    let opts = ExportOptions {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        seed: args.seed,
        camera: args.camera,
    };
    let exported = export(&scene, &opts)?;
    for w in &exported.warnings {
        eprintln!("warning: {w}");
    }
    exported
        .write(&args.output)
        .with_context(|| format!("writing the Mitsuba scene to {}", args.output.display()))?;
    println!(
        "wrote {} ({} meshes, {} textures, {} warnings)",
        args.output.join("scene.xml").display(),
        exported.meshes.len(),
        exported.textures.len(),
        exported.warnings.len()
    );
    Ok(())
}
