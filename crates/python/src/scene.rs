//! `streaks.Scene`: a scene loaded once (one BVH) and rendered as often as asked, one view
//! (`render`) or a rectified stereo pair (`render_pair`), with the options of `streaks render`
//! and `streaks stereo` as keywords.

use crate::options::{Checked, Options};
use crate::pair::Pair;
use crate::{arrays, StreaksError};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::time::Instant;
use streaks_render::camera::FRAMING_WARNING;
use streaks_render::integrator::{render, Layers, RenderJob};
use streaks_render::light::Environment;
use streaks_render::scene::{LoadOptions, Scene as RenderScene, SceneError};
use streaks_render::view::{frame_view, View};
use streaks_stereo::render::{
    denoise_pair, expose_pair, render_pair, rig_from_camera, PairSettings,
};
use streaks_stereo::rig::Rig;
use streaks_stereo::streak_mask::StreakMaskParams;

/// A scene loaded from a .gltf, .glb or .obj file, ready to render.
///
/// Load it with `Scene.load(path)`; it is loaded once (one BVH) and can be rendered any number
/// of times. A scene reads only files inside its folder unless `allow_outside_scene=True`.
#[pyclass(module = "streaks._streaks")]
pub struct Scene {
    /// The loaded scene (its rain drops placed for the last view rendered).
    pub(crate) scene: RenderScene,
    /// The file it was loaded from.
    path: PathBuf,
}

/// Issues a Python `UserWarning` with `message`.
fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let text = CString::new(message.replace('\0', " "))
        .map_err(|e| StreaksError::new_err(e.to_string()))?;
    PyErr::warn(py, &py.get_type::<PyUserWarning>(), &text, 1)
}

/// Loads the scene at `path` with the renderer's checks for untrusted files, and the
/// environment given (if any) in place of the scene's.
fn load(
    path: &Path,
    allow_outside: bool,
    environment: Option<Environment>,
) -> Result<RenderScene, String> {
    let options = LoadOptions {
        allow_outside,
        ..LoadOptions::default()
    };
    let mut scene = RenderScene::load_with(path, &options).map_err(|e| {
        let hint = if matches!(e, SceneError::OutsideFolder { .. }) {
            " (allow_outside_scene=True lets it read files outside its folder)"
        } else {
            ""
        };
        format!(
            "cannot load the scene {}{hint}: {}",
            path.display(),
            crate::chain(&e)
        )
    })?;
    if let Some(env) = environment {
        scene.set_environment(env);
    }
    Ok(scene)
}

/// The environment of `env`, `env_color` and `env_strength` (as `--env`, `--env-color` and
/// `--env-strength`), if either of the first two is given.
fn environment(
    env: Option<PathBuf>,
    env_color: Option<[f32; 3]>,
    env_strength: Option<f32>,
) -> PyResult<Option<Environment>> {
    let strength = env_strength.unwrap_or(1.0);
    let fail = |what: &str, e: &(dyn std::error::Error + 'static)| {
        StreaksError::new_err(format!("{what}: {}", crate::chain(e)))
    };
    match (env, env_color) {
        (Some(_), Some(_)) => Err(StreaksError::new_err(
            "env and env_color cannot be given together",
        )),
        (Some(path), None) => Environment::load_map(&path, strength)
            .map(Some)
            .map_err(|e| fail(&format!("env {}", path.display()), &e)),
        (None, Some(c)) => Environment::constant(glam::Vec3::from_array(c), strength)
            .map(Some)
            .map_err(|e| fail("env_color/env_strength", &e)),
        (None, None) if env_strength.is_some() => {
            Err(StreaksError::new_err("env_strength needs env or env_color"))
        }
        (None, None) => Ok(None),
    }
}

/// The scene, borrowed to render: one render at a time per `Scene`, another thread's call
/// raises `StreaksError` instead of waiting.
fn busy<'py>(slf: &Bound<'py, Scene>) -> PyResult<PyRefMut<'py, Scene>> {
    slf.try_borrow_mut().map_err(|_| {
        StreaksError::new_err(
            "the scene is being rendered or saved by another thread; one render at a time \
             per Scene (load it once per thread to render in parallel)",
        )
    })
}

impl Scene {
    /// Checks `options`, frames their view (camera, size, rain drops) and warns as the command
    /// does when the scene has no camera.
    fn frame(&mut self, py: Python<'_>, options: &Options) -> PyResult<(Checked, View)> {
        let checked = options.check()?;
        let view = frame_view(
            &mut self.scene,
            options.camera.as_deref(),
            options.width,
            options.height,
            checked.motion,
        )
        .map_err(|e| {
            StreaksError::new_err(format!(
                "in the scene {}: {}",
                self.path.display(),
                crate::chain(&e)
            ))
        })?;
        if view.framed {
            warn(py, &format!("{}: {FRAMING_WARNING}", self.path.display()))?;
        }
        Ok((checked, view))
    }
}

#[pymethods]
impl Scene {
    /// Loads a scene (.gltf, .glb or .obj) with the checks for untrusted files of `streaks
    /// render`: a scene reads only files inside its folder (no absolute paths, `file:` URIs,
    /// `..` or links out of it) unless `allow_outside_scene=True`; FIFOs and devices are
    /// refused even then. `env` (an equirectangular linear-RGB EXR) or `env_color` (linear
    /// RGB) replace the scene's environment, times `env_strength` (default 1). The scene's
    /// warnings are issued as `UserWarning`s and kept in `warnings`. Raises `StreaksError`
    /// naming the file and the reason.
    #[staticmethod]
    #[pyo3(signature = (path, *, allow_outside_scene=false, env=None, env_color=None, env_strength=None))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        allow_outside_scene: bool,
        env: Option<PathBuf>,
        env_color: Option<[f32; 3]>,
        env_strength: Option<f32>,
    ) -> PyResult<Self> {
        let environment = environment(env, env_color, env_strength)?;
        let scene = py
            .detach(|| load(&path, allow_outside_scene, environment))
            .map_err(StreaksError::new_err)?;
        for warning in &scene.warnings {
            warn(py, warning)?;
        }
        Ok(Self { scene, path })
    }

    /// The file the scene was loaded from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The warnings the loader gave (also issued as `UserWarning`s by `load`).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene.warnings.clone()
    }

    /// The names of the scene's cameras, in the order `camera=` numbers them.
    #[getter]
    fn cameras(&self) -> Vec<String> {
        self.scene.cameras.iter().map(|c| c.name.clone()).collect()
    }

    /// How the scene was loaded.
    fn __repr__(&self) -> String {
        format!("Scene.load({:?})", self.path.display().to_string())
    }

    /// Renders one view, as `streaks render` with every layer: a dict of float32 arrays under
    /// the names `streaks.io.read_exr` gives an EXR's layers: `rgb` (linear, H x W x 3; the
    /// denoised image with `denoise=True`, the render before it then under `raw`), `depth`
    /// (camera-space Z of the first hit, `inf` on a miss), `normal`, `albedo`, `specular`
    /// (H x W x 3), `spp`, `object` (H x W; as float32, as the EXR holds them), `rain` and
    /// `fog` for a scene with rain or fog, and `sensor` (the camera's raw DN) with `sensor=`.
    /// The options are those of `render_pair` but `baseline`. The GIL is released while
    /// rendering; Ctrl-C is taken once the render returns.
    #[pyo3(signature = (**options))]
    fn render<'py>(
        slf: &Bound<'py, Self>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (options, _) = Options::from_kwargs("render", options, false)?;
        let py = slf.py();
        let mut this = busy(slf)?;
        let (checked, view) = this.frame(py, &options)?;
        let scene = &this.scene;
        let job = RenderJob {
            width: view.width,
            height: view.height,
            seed: options.seed,
            layers: Layers {
                depth: true,
                normal: true,
                albedo: true,
                specular: true,
                material: false,
                object: true,
                spp: true,
                rain: scene.rain.is_some(),
                fog: scene.fog.is_some(),
                emission: checked.denoiser.is_some(),
            },
            settings: checked.settings,
            motion: checked.motion,
        };
        let (out, raw) = py
            .detach(|| -> Result<_, String> {
                let mut out = checked
                    .pool
                    .install(|| render(scene, &view.camera, &job, &|_| {}));
                if let Some(d) = &checked.denoiser {
                    streaks_render::output::denoise(&mut out, d)
                        .map_err(|e| format!("denoising the render: {}", crate::chain(&e)))?;
                }
                let raw = match &checked.sensor {
                    Some(profile) => {
                        let focal = view
                            .camera
                            .focal_px(out.image.height)
                            .map_or(f64::INFINITY, f64::from);
                        let capture = streaks_sensor::capture(
                            profile,
                            &out.image,
                            focal,
                            f64::from(options.exposure),
                            u64::from(options.seed),
                        )
                        .map_err(|e| format!("sensor: {}", crate::chain(&e)))?;
                        Some(capture.dn)
                    }
                    None => None,
                };
                Ok((out, raw))
            })
            .map_err(StreaksError::new_err)?;
        let (w, h) = (out.image.width as usize, out.image.height as usize);
        let dict = PyDict::new(py);
        dict.set_item("rgb", arrays::rgb(py, &out.image)?)?;
        let rgb_layers = [
            ("raw", &out.raw),
            ("albedo", &out.albedo),
            ("specular", &out.specular),
            ("normal", &out.normal),
            ("sensor", &raw),
        ];
        for (name, layer) in rgb_layers {
            if let Some(img) = layer {
                dict.set_item(name, arrays::rgb(py, img)?)?;
            }
        }
        let as_float =
            |v: &Option<Vec<u32>>| v.as_ref().map(|v| v.iter().map(|&n| n as f32).collect());
        let planes: [(&str, Option<Vec<f32>>); 5] = [
            ("depth", out.depth.clone()),
            ("spp", as_float(&out.spp)),
            ("rain", out.rain.clone()),
            ("fog", out.fog.clone()),
            ("object", as_float(&out.object)),
        ];
        for (name, plane) in planes {
            if let Some(data) = plane {
                dict.set_item(name, arrays::plane(py, w, h, data)?)?;
            }
        }
        Ok(dict)
    }

    /// Renders a rectified stereo pair of the scene's camera with ground truth, as `streaks
    /// stereo` does with the same options: the same seed and options give the same numbers
    /// as the command's files. Keywords (the command's flags):
    ///
    /// - `width`, `height`: image size in pixels (one given: the other from the camera's
    ///   aspect ratio; none: 480 rows).
    /// - `spp` (64): samples per pixel per eye (the cap with `noise_target`); `max_depth` (8):
    ///   longest path (1 = emitters only, 2 = direct light, ...); `seed` (0): the left eye's
    ///   sampler seed (the right eye uses seed + 1); `noise_target`: adaptive sampling's
    ///   relative standard error per 16x16 tile; `regularize`: path regularisation (biased,
    ///   fewer fireflies).
    /// - `camera`: a camera name or number (default: the scene's first camera; a scene without
    ///   one is framed from +Z, with a warning).
    /// - `baseline` (`streaks.DEFAULT_BASELINE` m): left eye at -b/2, right eye at +b/2 along
    ///   the camera's +X.
    /// - `exposure` (0): stops of the saved PNGs; with `sensor`, a factor 2^EV on the radiance.
    /// - `sensor`: a camera model, a preset (`automotive_hdr`, `automotive_linear`, `ideal`) or
    ///   a profile file; `shutter`: seconds (default: the sensor's exposure time, else 0);
    ///   `rig_velocity`: (x, y, z) m/s.
    /// - `denoise`: Intel Open Image Denoise (needs the library: `pip install pyoidn`, or
    ///   `OIDN_LIBRARY`); only the images are denoised, never the ground truth.
    /// - `threads`: worker threads (default: all cores).
    ///
    /// The GIL is released while rendering; Ctrl-C is taken once the render returns.
    #[pyo3(signature = (**options))]
    fn render_pair(slf: &Bound<'_, Self>, options: Option<&Bound<'_, PyDict>>) -> PyResult<Pair> {
        let py = slf.py();
        let (options, baseline) = Options::from_kwargs("render_pair", options, true)?;
        let baseline = baseline.unwrap_or(Rig::DEFAULT_BASELINE);
        if !(baseline.is_finite() && baseline > 0.0) {
            return Err(StreaksError::new_err(format!(
                "baseline must be a positive number of metres, got {baseline}"
            )));
        }
        let mut this = busy(slf)?;
        let (checked, view) = this.frame(py, &options)?;
        let path = this.path.clone();
        let rig =
            rig_from_camera(&view.camera, view.width, view.height, baseline).map_err(|e| {
                StreaksError::new_err(format!(
                    "the stereo rig of {}: {}",
                    path.display(),
                    crate::chain(&e)
                ))
            })?;
        let settings = PairSettings {
            render: checked.settings,
            seed: options.seed,
            exposure_ev: options.exposure,
            mask: StreakMaskParams::default(),
            motion: checked.motion,
            albedo: checked.denoiser.is_some(),
        };
        let scene = &this.scene;
        let start = Instant::now();
        let views = py
            .detach(|| -> Result<_, String> {
                let mut views = checked
                    .pool
                    .install(|| render_pair(scene, &rig, &settings, &|_| {}))
                    .map_err(|e| crate::chain(&e))?;
                if let Some(d) = &checked.denoiser {
                    denoise_pair(&mut views, d).map_err(|e| {
                        format!(
                            "denoising the pair of {}: {}",
                            path.display(),
                            crate::chain(&e)
                        )
                    })?;
                }
                if let Some(profile) = &checked.sensor {
                    checked
                        .pool
                        .install(|| {
                            expose_pair(&mut views, &rig, profile, options.seed, options.exposure)
                        })
                        .map_err(|e| crate::chain(&e))?;
                }
                Ok(views)
            })
            .map_err(StreaksError::new_err)?;
        let seconds = start.elapsed().as_secs_f64();
        let record = crate::pair::Record {
            options: &options,
            scene: &path,
            camera: &view.camera.name,
            baseline,
            seconds,
        };
        let meta = crate::pair::meta(py, &this.scene, &rig, &views, &record)?;
        drop(this);
        Pair::new(py, slf.clone().unbind(), rig, views, options.exposure, meta)
    }
}
