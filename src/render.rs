//! `streaks render`: path-trace one camera of a glTF/OBJ scene to EXR (and PNG).

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use streaks_image::png::write_png;
use streaks_image::GrayImage;
use streaks_render::integrator::{self, Layers, RenderJob, RenderOutput};
use streaks_render::output;

use crate::render_opts::{Loaded, RenderOpts};
use streaks_stereo::render::{road_surface, scene_has_road};

/// A layer that `--layers` can ask for.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layer {
    /// View-space depth (distance along the camera's -Z axis) of the first hit.
    Depth,
    /// First-hit shading normal (world space, facing the camera).
    Normal,
    /// First-hit albedo.
    Albedo,
    /// Light reflected once by the glossy lobe at the first hit (streaks).
    Specular,
    /// Samples taken per pixel (channel `spp.Y`; all `--spp` unless `--noise-target`).
    Spp,
}

/// Path-trace a scene's camera to a linear EXR (and optionally an sRGB PNG).
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene (.gltf, .glb or .obj).
    pub scene: PathBuf,
    /// Output image: .exr (linear float32 with layers) or .png (sRGB).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The rendering flags.
    #[command(flatten)]
    pub render: RenderOpts,
    /// Also write an sRGB PNG here.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Extra EXR layers, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub layers: Vec<Layer>,
    /// Also write the road mask here: a 0/255 PNG of the pixels whose pixel-centre ray hits a
    /// road material (extras.streaks.road) first, as a dataset's road0.png (for `streaks
    /// compare --mask`).
    #[arg(long, value_name = "MASK.png")]
    pub road_mask: Option<PathBuf>,
}

/// The output format, from the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Exr,
    Png,
}

fn format_of(path: &Path) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => Ok(Format::Exr),
        Some("png") => Ok(Format::Png),
        _ => bail!("output {} must end in .exr or .png", path.display()),
    }
}

/// Creates the parent folder of an output file.
fn create_parent(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    }
    Ok(())
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    // Phase 1: check everything that needs no scene.
    let format = format_of(&args.output)?;
    if let Some(png) = &args.png {
        if format_of(png)? != Format::Png {
            bail!("--png {} must end in .png", png.display());
        }
    }
    let opts = &args.render;
    opts.check()?;
    let layers = Layers {
        depth: args.layers.contains(&Layer::Depth),
        normal: args.layers.contains(&Layer::Normal),
        albedo: args.layers.contains(&Layer::Albedo),
        specular: args.layers.contains(&Layer::Specular),
        material: args.road_mask.is_some(),
        spp: args.layers.contains(&Layer::Spp),
    };
    if let Some(mask) = &args.road_mask {
        if format_of(mask)? != Format::Png {
            bail!("--road-mask {} must end in .png", mask.display());
        }
    }
    if format == Format::Png && !args.layers.is_empty() {
        eprintln!(
            "warning: --layers are written only to EXR outputs; {} is a PNG",
            args.output.display()
        );
    }

    // Phase 2: the scene and the camera.
    let Loaded {
        scene,
        camera,
        width,
        height,
    } = opts.load(&args.scene)?;
    if args.road_mask.is_some() && !scene_has_road(&scene) {
        bail!(
            "--road-mask: the scene {} flags no road material (extras.streaks.road)",
            args.scene.display()
        );
    }
    let job = RenderJob {
        width,
        height,
        seed: opts.seed,
        layers,
        settings: opts.settings(),
    };
    create_parent(&args.output)?;
    for path in args.png.iter().chain(&args.road_mask) {
        create_parent(path)?;
    }

    // Phase 3: render and write.
    let pool = opts.thread_pool()?;
    let bar = opts.progress(1, width, height)?;
    let out: RenderOutput =
        pool.install(|| integrator::render(&scene, &camera, &job, &|n| bar.inc(n)));
    bar.finish_and_clear();

    match format {
        Format::Exr => output::write_exr(&args.output, &out)?,
        Format::Png => write_png(&args.output, &out.image, opts.exposure)?,
    }
    if let Some(png) = &args.png {
        write_png(png, &out.image, opts.exposure)?;
    }
    if let (Some(path), Some(material)) = (&args.road_mask, &out.material) {
        let road = road_surface(&scene, material)
            .into_iter()
            .map(|r| if r { 1.0 } else { 0.0 })
            .collect();
        GrayImage::from_vec(width as usize, height as usize, road)?
            .save_png(path)
            .with_context(|| format!("cannot write the road mask {}", path.display()))?;
    }
    let s = &out.stats;
    let secs = s.seconds.max(1e-9);
    let pixels = (width as u64 * height as u64).max(1);
    let spp = match opts.noise_target {
        None => format!("{} spp", opts.spp),
        Some(rel) => format!(
            "{:.1} spp on average (noise target {rel}, cap {})",
            s.samples as f64 / pixels as f64,
            opts.spp
        ),
    };
    eprintln!(
        "rendered {width}x{height} at {spp}, max depth {} in {:.2} s: {:.3} M samples/s, {:.3} M rays/s, {} samples dropped (NaN/inf)",
        opts.max_depth,
        s.seconds,
        s.samples as f64 / secs / 1e6,
        s.rays as f64 / secs / 1e6,
        s.nonfinite_dropped
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_from_extensions() {
        assert_eq!(format_of(Path::new("a/b.EXR")).unwrap(), Format::Exr);
        assert_eq!(format_of(Path::new("b.png")).unwrap(), Format::Png);
        assert!(format_of(Path::new("b.jpg")).is_err());
        assert!(format_of(Path::new("b")).is_err());
    }
}
