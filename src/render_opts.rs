//! The rendering flags that `streaks render` and `streaks stereo` share ([`RenderOpts`]), the
//! scene they load ([`Loaded`]), and how a render setting out of range is reported as a flag.

use anyhow::{bail, Context, Result};
use glam::Vec3;
use indicatif::ProgressBar;
use std::path::Path;
use streaks_render::camera::{Camera, FRAMING_WARNING};
use streaks_render::light::Environment;
use streaks_render::motion::Motion;
use streaks_render::scene::Scene;
use streaks_render::view::{frame_view, View};
use streaks_sensor::SensorProfile;
use streaks_settings::{RenderSettings, SettingsError};

use crate::cli::{load_scene, progress_bar};

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
    /// Image width in pixels [default: from the height and the camera's aspect ratio (an
    /// orthographic camera's xmag/ymag)]; with both --width and --height an orthographic
    /// view keeps square pixels and shows more along one axis.
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
    /// Camera name, or its number in the scene's list of cameras (0 is the first; a name
    /// wins over a number) [default: the scene's first camera; a scene without cameras is
    /// framed from +Z as the glTF sample viewer frames it, with a warning].
    #[arg(long)]
    pub camera: Option<String>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Exposure of the PNGs in stops (linear * 2^EV before the sRGB curve); with --sensor,
    /// a factor 2^EV on the scene's radiance before the lens (for scenes whose lights are not
    /// at physical scale).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// See the render through a camera: a preset (automotive_hdr, automotive_linear, ideal) or
    /// a profile file (a path with a / or ending in .toml; see docs/sensor.md). The EXR gets
    /// the raw DN as a `sensor` layer and the PNGs are developed from them; the render and
    /// the ground truth stay as they are.
    #[arg(long, value_name = "PRESET|FILE.toml")]
    pub sensor: Option<String>,
    /// Path regularisation (biased): roughen glossy lobes after a diffuse or rough bounce, as
    /// Cycles' "Filter Glossy" does; far fewer fireflies, the first bounce (streaks) unchanged.
    #[arg(long)]
    pub regularize: bool,
    /// Let the scene read files outside its folder (absolute paths, file: URIs, `..`, links
    /// out of it). Off by default, so an untrusted scene cannot read other files; FIFOs and
    /// devices are refused even then.
    #[arg(long)]
    pub allow_outside_scene: bool,
    /// The environment light flags.
    #[command(flatten)]
    pub env: EnvOpts,
    /// Shutter time in seconds, centred on the scene's moment (open at -S/2, close at +S/2):
    /// rain drops and a moving rig (--rig-velocity) blur over it [default: the --sensor
    /// profile's exposure_s, else 0, no blur].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub shutter: Option<f32>,
    /// The rig's velocity in m/s, world space, during the shutter (both eyes move together).
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub rig_velocity: Option<Vec<f32>>,
    /// Denoise the render with Intel Open Image Denoise, guided by the albedo and normal
    /// layers (rendered for it): the EXR's `R`, `G`, `B` and the PNGs are the denoised image,
    /// the EXR's `raw` layer the render before; depth, disparity, masks and the specular
    /// layer are never denoised. Needs the library: `pip install pyoidn`, or OIDN_LIBRARY
    /// set to libOpenImageDenoise.so.
    #[arg(long)]
    pub denoise: bool,
}

/// The environment light flags of `streaks render`, `streaks stereo` and `streaks
/// export-mitsuba`: they replace the scene's environment.
#[derive(clap::Args, Debug, Default)]
pub struct EnvOpts {
    /// Light the scene with this equirectangular linear-RGB OpenEXR map (Mitsuba's envmap
    /// mapping: top row +Y, left edge -Z, centre +Z), replacing the scene's environment.
    #[arg(long, value_name = "SKY.exr")]
    pub env: Option<std::path::PathBuf>,
    /// Light the scene with a constant environment of this linear RGB radiance instead.
    #[arg(
        long,
        value_name = "R,G,B",
        value_delimiter = ',',
        conflicts_with = "env",
        allow_negative_numbers = true
    )]
    pub env_color: Option<Vec<f32>>,
    /// Factor on --env or --env-color [default: 1].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub env_strength: Option<f32>,
}

impl EnvOpts {
    /// Phase 1: checks the strength and the colour.
    pub fn check(&self) -> Result<()> {
        if self.env_strength.is_some() && self.env.is_none() && self.env_color.is_none() {
            bail!("--env-strength needs --env or --env-color");
        }
        let colour =
            three_numbers("--env-color", "R,G,B", self.env_color.as_deref())?.unwrap_or(Vec3::ONE);
        Environment::constant(colour, self.strength())
            .map_err(|e| anyhow::anyhow!("--env-color/--env-strength: {e}"))?;
        Ok(())
    }

    /// `--env-strength`, 1 by default.
    fn strength(&self) -> f32 {
        self.env_strength.unwrap_or(1.0)
    }

    /// The environment of `--env` or `--env-color` (with `--env-strength`), if either is given.
    pub fn environment(&self) -> Result<Option<Environment>> {
        self.check()?;
        if let Some(path) = &self.env {
            let env = Environment::load_map(path, self.strength())
                .with_context(|| format!("--env {}", path.display()))?;
            return Ok(Some(env));
        }
        Ok(match self.env_color.as_deref() {
            Some(&[r, g, b]) => Some(Environment::constant(Vec3::new(r, g, b), self.strength())?),
            _ => None,
        })
    }

    /// Loads the scene at `path` as [`load_scene`] does, with the environment of the flags.
    pub fn load_scene(&self, path: &Path, allow_outside: bool) -> Result<Scene> {
        let environment = self.environment()?;
        let mut scene = load_scene(path, allow_outside)?;
        if let Some(env) = environment {
            scene.set_environment(env);
        }
        Ok(scene)
    }
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
        self.sensor_profile()?;
        self.motion()?;
        self.env.check()
    }

    /// The denoiser `--denoise` asks for, loaded before anything is rendered (so a missing
    /// library fails at once); `None` without the flag.
    pub fn denoiser(&self) -> Result<Option<streaks_image::denoise::Denoiser>> {
        self.denoise
            .then(|| streaks_image::denoise::Denoiser::load().context("--denoise"))
            .transpose()
    }

    /// The camera profile of `--sensor`, if given.
    pub fn sensor_profile(&self) -> Result<Option<SensorProfile>> {
        self.sensor
            .as_deref()
            .map(|arg| SensorProfile::resolve(arg).context("--sensor"))
            .transpose()
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

    /// The shutter and rig motion of `--shutter` and `--rig-velocity`: without `--shutter`,
    /// the shutter is the `--sensor` profile's exposure time (a camera's exposure is its
    /// shutter), or closed without a sensor.
    pub fn motion(&self) -> Result<Motion> {
        let shutter = match self.shutter {
            Some(s) => s,
            None => self
                .sensor_profile()?
                .map_or(0.0, |profile| profile.exposure_s as f32),
        };
        if !(shutter.is_finite() && shutter >= 0.0) {
            bail!("--shutter must be a time of 0 s or more (got {shutter})");
        }
        let rig_velocity = three_numbers(
            "--rig-velocity",
            "X,Y,Z in m/s",
            self.rig_velocity.as_deref(),
        )?
        .unwrap_or(Vec3::ZERO);
        let motion = Motion::centred(shutter, rig_velocity);
        motion
            .check()
            .map_err(|e| anyhow::anyhow!("--shutter/--rig-velocity: {e}"))?;
        Ok(motion)
    }

    /// Phase 2: loads the scene (with the environment of `--env` or `--env-color`, if given;
    /// printing its warnings) and frames the view of the flags ([`frame_view`]: the camera, the
    /// image size, the rain drops for the shutter of the flags).
    pub fn load(&self, path: &Path) -> Result<Loaded> {
        let mut scene = self.env.load_scene(path, self.allow_outside_scene)?;
        for warning in &scene.warnings {
            eprintln!("warning: {warning}");
        }
        let View {
            camera,
            width,
            height,
            framed,
        } = frame_view(
            &mut scene,
            self.camera.as_deref(),
            self.width,
            self.height,
            self.motion()?,
        )
        .with_context(|| format!("in the scene {}", path.display()))?;
        if framed {
            eprintln!("warning: {}: {FRAMING_WARNING}", path.display());
        }
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

/// The vector of a flag that takes three comma-separated numbers (`what` names them), if
/// given; an error naming the flag for any other count.
fn three_numbers(flag: &str, what: &str, values: Option<&[f32]>) -> Result<Option<Vec3>> {
    match values {
        Some(&[x, y, z]) => Ok(Some(Vec3::new(x, y, z))),
        Some(other) => bail!("{flag} takes three numbers, {what} (got {})", other.len()),
        None => Ok(None),
    }
}

/// A render setting out of its range as the command line says it: `--spp must be at least 1`.
pub fn flag_error(e: SettingsError) -> anyhow::Error {
    anyhow::anyhow!("--{} {}", e.name().replace('_', "-"), e.reason())
}
