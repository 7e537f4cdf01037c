//! `streaks render`: path-trace one camera of a glTF/OBJ scene to EXR (and PNG).

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use streaks_image::color::luminance;
use streaks_image::png::{write_png, write_png_buffer};
use streaks_image::stats::quantile_below;
use streaks_image::{GrayImage, RgbImage};
use streaks_render::camera::Camera;
use streaks_render::integrator::{self, Layers, RenderJob, RenderOutput};
use streaks_render::output;
use streaks_sensor::{capture, Capture, SensorProfile};

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
    /// The first hit's object slot (channel `object.Y`; 0 is the sky, 1 unlabelled, then
    /// one slot per distinct `extras.streaks` class and instance of the scene's nodes, in
    /// the order the node walk meets them).
    Object,
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
    let sensor = opts.sensor_profile()?;
    // The denoiser's guides come with --denoise.
    let denoiser = opts.denoiser()?;
    let guides = denoiser.is_some();
    let layers = Layers {
        depth: args.layers.contains(&Layer::Depth),
        normal: guides || args.layers.contains(&Layer::Normal),
        albedo: guides || args.layers.contains(&Layer::Albedo),
        specular: args.layers.contains(&Layer::Specular),
        material: args.road_mask.is_some(),
        object: args.layers.contains(&Layer::Object),
        spp: args.layers.contains(&Layer::Spp),
        rain: false,
        fog: false,
        emission: guides,
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
        // The rain layer comes with every render of a rainy scene, and a foggy scene's EXR
        // gets the fog's transmittance (`fog.Y`).
        layers: Layers {
            rain: scene.rain.is_some(),
            fog: scene.fog.is_some() && format == Format::Exr,
            ..layers
        },
        settings: opts.settings(),
        motion: opts.motion()?,
    };
    create_parent(&args.output)?;
    for path in args.png.iter().chain(&args.road_mask) {
        create_parent(path)?;
    }

    // Phase 3: render and write.
    let pool = opts.thread_pool()?;
    let bar = opts.progress(1, width, height)?;
    let mut out: RenderOutput =
        pool.install(|| integrator::render(&scene, &camera, &job, &|n| bar.inc(n)));
    bar.finish_and_clear();
    if let Some(d) = &denoiser {
        output::denoise(&mut out, d)
            .with_context(|| format!("denoising the render of {}", args.scene.display()))?;
    }

    let raw = match &sensor {
        Some(profile) => Some(expose(profile, &out.image, &camera, opts)?),
        None => None,
    };
    let png_of = |path: &Path| -> Result<()> {
        match &raw {
            Some(raw) => write_png_buffer(path, &raw.develop())?,
            None => write_png(path, &out.image, opts.exposure)?,
        }
        Ok(())
    };
    match format {
        Format::Exr => {
            output::write_exr_with_sensor(&args.output, &out, raw.as_ref().map(|r| &r.dn))?
        }
        Format::Png => png_of(&args.output)?,
    }
    if let Some(png) = &args.png {
        png_of(png)?;
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
    // A camera's image is as its profile develops it.
    if let Some(warning) = black_image_warning(&out.image, opts.exposure).filter(|_| raw.is_none())
    {
        eprintln!("warning: {}: {warning}", args.output.display());
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

/// The render through the camera `profile`: `--exposure` scales the radiance, the focal
/// length in pixels gives the vignetting (none for an orthographic camera), the noise is drawn
/// from `--seed`.
fn expose(
    profile: &SensorProfile,
    image: &RgbImage,
    camera: &Camera,
    opts: &RenderOpts,
) -> Result<Capture> {
    let focal = camera
        .focal_px(image.height)
        .map_or(f64::INFINITY, f64::from);
    Ok(capture(
        profile,
        image,
        focal,
        f64::from(opts.exposure),
        u64::from(opts.seed),
    )?)
}

/// Below this linear luminance a pixel develops to at most 8 of 255 in sRGB: black to the eye.
const BLACK: f32 = 0.0024;

/// A render whose 99th-percentile luminance, at `exposure` stops, develops to black ([`BLACK`])
/// though light reached the film gets a warning with the exposure that would show it: the one
/// that takes the 99th-percentile luminance (the brightest pixel's, when fewer than 1 % of
/// the pixels got light) to 18 % grey. Files with weak photometric lights do this (a 3 lux
/// directional light is 3/683 W/m^2), as do models whose only light is hidden from the camera,
/// and a black image without a word looks like a failure.
fn black_image_warning(image: &RgbImage, exposure: f32) -> Option<String> {
    let lum: Vec<f32> = image.pixels.iter().map(|&p| luminance(p)).collect();
    let p99 = quantile_below(lum.iter().copied(), 0.99)?;
    if p99 * exposure.exp2() >= BLACK {
        return None;
    }
    let brightest = lum
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f32::max);
    let bright = if p99 > 0.0 { p99 } else { brightest };
    if bright <= 0.0 {
        return None;
    }
    let ev = (0.18 / bright).log2().round();
    Some(format!(
        "the image is black at --exposure {exposure} (99th-percentile luminance {p99:.2e}, \
         brightest {brightest:.2e}); --exposure {ev} shows it, or light the scene with --env or \
         --env-color"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dim_render_is_named_with_the_exposure_that_shows_it() {
        let dim = RgbImage::from_fn(10, 10, |x, _| glam::Vec3::splat(1e-5 * x as f32));
        let w = black_image_warning(&dim, 0.0).expect("a warning");
        assert!(w.contains("--exposure 11 shows it"), "{w}");
        assert!(black_image_warning(&dim, 11.0).is_none());
        assert!(black_image_warning(&RgbImage::new(4, 4), 0.0).is_none());
        let lit = RgbImage::from_fn(4, 4, |_, _| glam::Vec3::splat(0.5));
        assert!(black_image_warning(&lit, 0.0).is_none());
    }

    #[test]
    fn formats_from_extensions() {
        assert_eq!(format_of(Path::new("a/b.EXR")).unwrap(), Format::Exr);
        assert_eq!(format_of(Path::new("b.png")).unwrap(), Format::Png);
        assert!(format_of(Path::new("b.jpg")).is_err());
        assert!(format_of(Path::new("b")).is_err());
    }
}
