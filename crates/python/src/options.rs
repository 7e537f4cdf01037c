//! The rendering options of `Scene.render` and `Scene.render_pair`: the flags of `streaks
//! render` and `streaks stereo` as keywords (`--max-depth` is `max_depth=`), checked as the
//! command checks them, with messages naming the keyword.

use crate::StreaksError;
use glam::Vec3;
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use streaks_image::denoise::Denoiser;
use streaks_render::motion::Motion;
use streaks_sensor::SensorProfile;
use streaks_settings::RenderSettings;

/// A camera asked for by name, or by its number in the scene's list (0 is the first).
#[derive(FromPyObject)]
pub enum CameraArg {
    /// A camera's name (a name wins over a number, as on the command line).
    Name(String),
    /// A camera's number.
    Index(u64),
}

impl CameraArg {
    /// The camera as the command line's `--camera` takes it.
    pub fn as_flag(&self) -> String {
        match self {
            Self::Name(name) => name.clone(),
            Self::Index(i) => i.to_string(),
        }
    }
}

/// The keywords shared by `render` and `render_pair` (see their docstrings), with the
/// command's defaults.
pub struct Options {
    /// Image width in pixels (`None`: from the height and the camera's aspect ratio).
    pub width: Option<u32>,
    /// Image height in pixels (`None`: 480, or from the width).
    pub height: Option<u32>,
    /// `spp`, `max_depth`, `regularize` and `noise_target`: how each view is sampled.
    pub settings: RenderSettings,
    /// Sampler seed (the right eye uses seed + 1).
    pub seed: u32,
    /// The camera (`None`: the scene's first, or the default framing).
    pub camera: Option<String>,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// Exposure in stops (of the PNGs; with a sensor, on the scene's radiance).
    pub exposure: f32,
    /// A sensor preset or profile file.
    pub sensor: Option<String>,
    /// Shutter time in seconds (`None`: the sensor's exposure time, else 0).
    pub shutter: Option<f32>,
    /// The rig's velocity in m/s, world space.
    pub rig_velocity: Option<[f32; 3]>,
    /// Denoise with Intel Open Image Denoise.
    pub denoise: bool,
}

/// The keyword names [`Options::from_kwargs`] takes, in the order the docs list them.
pub const KEYWORDS: [&str; 15] = [
    "width",
    "height",
    "spp",
    "max_depth",
    "seed",
    "camera",
    "threads",
    "exposure",
    "sensor",
    "regularize",
    "noise_target",
    "shutter",
    "rig_velocity",
    "denoise",
    "baseline",
];

/// The value of keyword `key` as a `T`; a value of another type is a `TypeError` naming the
/// keyword.
fn value<'py, T: FromPyObjectOwned<'py>>(key: &str, v: &Bound<'py, PyAny>) -> PyResult<T> {
    v.extract::<T>().map_err(|e| {
        let e: PyErr = e.into();
        PyTypeError::new_err(format!("{key}: {}", e.value(v.py())))
    })
}

impl Options {
    /// The options of the keywords `kwargs` of the method `method` (the command's defaults for
    /// those not given), and `baseline` if `with_baseline` (`None` when not given). A keyword
    /// the method does not take, or a value of the wrong type, is a `TypeError`, as Python's
    /// own for a function's keywords.
    pub fn from_kwargs(
        method: &str,
        kwargs: Option<&Bound<'_, PyDict>>,
        with_baseline: bool,
    ) -> PyResult<(Self, Option<f32>)> {
        let mut o = Options {
            width: None,
            height: None,
            settings: RenderSettings::new(64, 8),
            seed: 0,
            camera: None,
            threads: None,
            exposure: 0.0,
            sensor: None,
            shutter: None,
            rig_velocity: None,
            denoise: false,
        };
        let mut baseline = None;
        for (k, v) in kwargs.into_iter().flat_map(|d| d.iter()) {
            let key: String = k.extract()?;
            match key.as_str() {
                "width" => o.width = value(&key, &v)?,
                "height" => o.height = value(&key, &v)?,
                "spp" => o.settings.spp = value(&key, &v)?,
                "max_depth" => o.settings.max_depth = value(&key, &v)?,
                "seed" => o.seed = value(&key, &v)?,
                "camera" => o.camera = value::<Option<CameraArg>>(&key, &v)?.map(|c| c.as_flag()),
                "threads" => o.threads = value(&key, &v)?,
                "exposure" => o.exposure = value(&key, &v)?,
                "sensor" => o.sensor = value(&key, &v)?,
                "regularize" => o.settings.regularize = value(&key, &v)?,
                "noise_target" => o.settings.noise_target = value(&key, &v)?,
                "shutter" => o.shutter = value(&key, &v)?,
                "rig_velocity" => o.rig_velocity = value(&key, &v)?,
                "denoise" => o.denoise = value(&key, &v)?,
                "baseline" if with_baseline => baseline = Some(value(&key, &v)?),
                _ => {
                    let known = KEYWORDS
                        .iter()
                        .filter(|k| with_baseline || **k != "baseline");
                    return Err(PyTypeError::new_err(format!(
                        "{method}() got an unexpected keyword argument '{key}' (it takes {})",
                        known.copied().collect::<Vec<_>>().join(", ")
                    )));
                }
            }
        }
        Ok((o, baseline))
    }
}

/// What the options resolve to before anything is rendered.
pub struct Checked {
    /// How each view is sampled.
    pub settings: RenderSettings,
    /// The shutter and the rig's motion.
    pub motion: Motion,
    /// The camera profile of `sensor`.
    pub sensor: Option<SensorProfile>,
    /// The denoiser `denoise` asks for, loaded before rendering (a missing library fails at
    /// once).
    pub denoiser: Option<Denoiser>,
    /// The worker pool of `threads`.
    pub pool: rayon::ThreadPool,
}

impl Options {
    /// Checks every option that needs no scene, as `streaks stereo` does before loading one,
    /// and loads what they name (the sensor profile, the denoiser).
    pub fn check(&self) -> PyResult<Checked> {
        let settings = self.settings;
        settings
            .check()
            .map_err(|e| StreaksError::new_err(format!("{} {}", e.name(), e.reason())))?;
        if !self.exposure.is_finite() {
            return Err(StreaksError::new_err(
                "exposure must be a finite number of stops",
            ));
        }
        let sensor = self
            .sensor
            .as_deref()
            .map(|arg| {
                SensorProfile::resolve(arg)
                    .map_err(|e| StreaksError::new_err(format!("sensor: {}", crate::chain(&e))))
            })
            .transpose()?;
        // A camera's exposure is its shutter, as on the command line.
        let shutter = match self.shutter {
            Some(s) => s,
            None => sensor.as_ref().map_or(0.0, |p| p.exposure_s as f32),
        };
        if !(shutter.is_finite() && shutter >= 0.0) {
            return Err(StreaksError::new_err(format!(
                "shutter must be a time of 0 s or more (got {shutter})"
            )));
        }
        let velocity = self.rig_velocity.map_or(Vec3::ZERO, Vec3::from_array);
        let motion = Motion::centred(shutter, velocity);
        motion
            .check()
            .map_err(|e| StreaksError::new_err(format!("shutter/rig_velocity: {e}")))?;
        let denoiser = self
            .denoise
            .then(|| {
                Denoiser::load()
                    .map_err(|e| StreaksError::new_err(format!("denoise: {}", crate::chain(&e))))
            })
            .transpose()?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads.unwrap_or(0))
            .build()
            .map_err(|e| StreaksError::new_err(format!("cannot start the worker threads: {e}")))?;
        Ok(Checked {
            settings,
            motion,
            sensor,
            denoiser,
            pool,
        })
    }
}
