//! `streaks render`: path-trace one camera of a glTF/OBJ scene to EXR (and PNG).

use anyhow::{bail, Context, Result};
use indicatif::ProgressBar;
use std::path::{Path, PathBuf};
use streaks_image::png::write_png;
use streaks_image::GrayImage;
use streaks_render::camera::Camera;
use streaks_render::integrator::{self, Layers, RenderJob, RenderOutput};
use streaks_render::output;
use streaks_render::scene::Scene;
use streaks_settings::{RenderSettings, SettingsError};

use crate::cli::{image_size, load_scene, progress_bar};
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

/// The rendering flags that `streaks render` and `streaks stereo` share.
#[derive(clap::Args, Debug)]
pub struct RenderOpts {
    /// Samples per pixel (per eye for a stereo pair); the cap with --noise-target.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Adaptive sampling: stop each 16x16 tile of pixels once the estimated relative standard
    /// error of its pixels' mean luminance is below REL (e.g. 0.1), after at least 16 samples,
    /// --spp being the cap. Deterministic: the same image for a seed on any number of threads.
    #[arg(long, value_name = "REL", allow_negative_numbers = true)]
    pub noise_target: Option<f32>,
    /// Image width in pixels [default: from the height and the camera's aspect ratio].
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels [default: 480, or from the width and the aspect ratio].
    #[arg(long)]
    pub height: Option<u32>,
    /// Longest path, Mitsuba's meaning: 1 = emitters only, 2 = direct light, 3 = one bounce...
    #[arg(long, default_value_t = 8)]
    pub max_depth: u32,
    /// Sampler seed: the same seed gives the same image on any number of threads (a stereo
    /// pair's right eye uses seed + 1).
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Camera name [default: the scene's first camera].
    #[arg(long)]
    pub camera: Option<String>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Exposure of the PNGs in stops (linear * 2^EV before the sRGB curve).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Path regularisation (biased): roughen glossy lobes after a diffuse or rough bounce, as
    /// Cycles' "Filter Glossy" does; far fewer fireflies, the first bounce (streaks) unchanged.
    #[arg(long)]
    pub regularize: bool,
    /// Let the scene read files outside its folder (absolute paths, file: URIs, `..`, links
    /// out of it). Off by default, so an untrusted scene cannot read other files; FIFOs and
    /// devices are refused even then.
    #[arg(long)]
    pub allow_outside_scene: bool,
}

/// A scene loaded for rendering, with the chosen camera and the image size.
pub struct Loaded {
    /// The scene (one BVH, shared by every view).
    pub scene: Scene,
    /// The chosen camera.
    pub camera: Camera,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl RenderOpts {
    /// Phase 1: checks the flags that need no scene.
    pub fn check(&self) -> Result<()> {
        self.settings().check().map_err(flag_error)?;
        if !self.exposure.is_finite() {
            bail!("--exposure must be a finite number of stops");
        }
        Ok(())
    }

    /// The render settings of the flags (`--spp`, `--max-depth`, `--regularize`,
    /// `--noise-target`).
    pub fn settings(&self) -> RenderSettings {
        RenderSettings {
            spp: self.spp,
            max_depth: self.max_depth,
            regularize: self.regularize,
            noise_target: self.noise_target,
        }
    }

    /// Phase 2: loads the scene (printing its warnings), picks the camera and sizes the image.
    pub fn load(&self, path: &Path) -> Result<Loaded> {
        let scene = load_scene(path, self.allow_outside_scene)?;
        for warning in &scene.warnings {
            eprintln!("warning: {warning}");
        }
        let camera = scene
            .camera(self.camera.as_deref())
            .with_context(|| format!("in the scene {}", path.display()))?
            .clone();
        let (width, height) = image_size(self.width, self.height, camera.aspect_ratio)?;
        Ok(Loaded {
            scene,
            camera,
            width,
            height,
        })
    }

    /// The worker pool of `--threads` (all cores by default).
    pub fn thread_pool(&self) -> Result<rayon::ThreadPool> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads.unwrap_or(0))
            .build()
            .context("cannot start the worker threads")
    }

    /// A progress bar over `views` renders of `width` x `height` pixels at `--spp`.
    pub fn progress(&self, views: u64, width: u32, height: u32) -> Result<ProgressBar> {
        let total = (views * width as u64 * height as u64)
            .checked_mul(self.spp as u64)
            .context("the number of samples (views x width x height x spp) overflows")?;
        Ok(progress_bar(total))
    }
}

/// A render setting out of its range as the command line says it: `--spp must be at least 1`.
pub fn flag_error(e: SettingsError) -> anyhow::Error {
    anyhow::anyhow!("--{} {}", e.name().replace('_', "-"), e.reason())
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
