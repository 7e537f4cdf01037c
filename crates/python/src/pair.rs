//! `streaks.Pair`: a rendered stereo pair as numpy arrays (the numbers of the files `streaks
//! stereo` writes), its metadata, and `save`, which writes the command's sample folder.

use crate::options::Options;
use crate::scene::Scene;
use crate::{arrays, error, StreaksError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use streaks_dataset::write::write_pair;
use streaks_image::GrayImage;
use streaks_render::scene::Scene as RenderScene;
use streaks_stereo::occlusion::occlusion_mask;
use streaks_stereo::render::{light_records, EyeView};
use streaks_stereo::rig::{Eye, Rig};
use streaks_stereo::rigfile::RigFile;

/// What a pair's metadata records besides the rig and the views.
pub struct Record<'a> {
    /// The options it was rendered with.
    pub options: &'a Options,
    /// The scene file.
    pub scene: &'a Path,
    /// The camera's name.
    pub camera: &'a str,
    /// The baseline in metres.
    pub baseline: f32,
    /// Wall time of the render (both eyes, the denoiser and the sensor), seconds.
    pub seconds: f64,
}

/// A rendered stereo pair: the images, the ground truth and the metadata, as numpy arrays.
///
/// `left`, `right`: float32 H x W x 3, linear RGB (the EXRs' `R`, `G`, `B`; denoised with
/// `denoise=True`). `disparity`, `disparity_right`: float32 H x W, `f b / Z` in pixels, `inf`
/// where the pixel sees no surface (the sky): mask it before a loss. For the left view a
/// pixel's match in the right view is at `x - d`, for the right view (Middlebury's `disp1`)
/// at `x + d` in the left. `depth`, `depth_right`: camera-space Z in metres (`inf` on a miss).
/// `streak_mask`, `road_mask`, `occlusion` (and their `_right`): bool H x W; `occlusion` marks
/// the pixels whose point the other eye does not see (hidden there or outside its image).
/// `left_camera`, `right_camera`: uint8 H x W x 3, the sRGB images as the camera sees them
/// (the PNGs `save` writes). `sensor`, `sensor_right`: the
/// camera model's raw DN (H x W x 3), `None` without `sensor=`. `meta`: a dict (see
/// `docs/python.md`).
#[pyclass(module = "streaks._streaks", frozen)]
pub struct Pair {
    /// The scene it was rendered from (its lights and objects are written by `save`).
    scene: Py<Scene>,
    /// The rig.
    rig: Rig,
    /// Both rendered views.
    views: [EyeView; 2],
    /// Exposure of the saved PNGs in stops.
    exposure: f32,
    /// The left image.
    #[pyo3(get)]
    left: Py<PyAny>,
    /// The right image.
    #[pyo3(get)]
    right: Py<PyAny>,
    /// The left view's disparity.
    #[pyo3(get)]
    disparity: Py<PyAny>,
    /// The right view's disparity.
    #[pyo3(get)]
    disparity_right: Py<PyAny>,
    /// The left view's depth.
    #[pyo3(get)]
    depth: Py<PyAny>,
    /// The right view's depth.
    #[pyo3(get)]
    depth_right: Py<PyAny>,
    /// The left view's streak mask.
    #[pyo3(get)]
    streak_mask: Py<PyAny>,
    /// The right view's streak mask.
    #[pyo3(get)]
    streak_mask_right: Py<PyAny>,
    /// The left view's road-surface mask.
    #[pyo3(get)]
    road_mask: Py<PyAny>,
    /// The right view's road-surface mask.
    #[pyo3(get)]
    road_mask_right: Py<PyAny>,
    /// The left view's occlusion mask.
    #[pyo3(get)]
    occlusion: Py<PyAny>,
    /// The right view's occlusion mask.
    #[pyo3(get)]
    occlusion_right: Py<PyAny>,
    /// The left image as the camera sees it (`im0.png`).
    #[pyo3(get)]
    left_camera: Py<PyAny>,
    /// The right image as the camera sees it (`im1.png`).
    #[pyo3(get)]
    right_camera: Py<PyAny>,
    /// The left camera's raw DN, or None.
    #[pyo3(get)]
    sensor: Option<Py<PyAny>>,
    /// The right camera's raw DN, or None.
    #[pyo3(get)]
    sensor_right: Option<Py<PyAny>>,
    /// The metadata.
    #[pyo3(get)]
    meta: Py<PyDict>,
}

/// A bool H x W array of a 0/1 mask image.
fn mask<'py>(py: Python<'py>, img: &GrayImage) -> PyResult<Bound<'py, PyAny>> {
    let data = img.data.iter().map(|&m| m > 0.0).collect();
    arrays::plane(py, img.width, img.height, data)
}

/// The metadata dict of a pair: `scene`, `camera`, `seed`, `rig` (the contents of the
/// `rig.json` `save` writes), `settings` (the options), `timings` and `stats`.
pub fn meta<'py>(
    py: Python<'py>,
    scene: &RenderScene,
    rig: &Rig,
    views: &[EyeView; 2],
    record: &Record<'_>,
) -> PyResult<Bound<'py, PyDict>> {
    let road = rig.road_frame().ok();
    let rig_file = RigFile::new(rig, light_records(scene, road.as_ref()));
    let text = serde_json::to_string(&rig_file)
        .map_err(|e| StreaksError::new_err(format!("the pair's rig record: {e}")))?;
    let rig_dict = py.import("json")?.call_method1("loads", (text,))?;
    let o = record.options;
    let meta = PyDict::new(py);
    meta.set_item("scene", record.scene)?;
    meta.set_item("camera", record.camera)?;
    meta.set_item("seed", o.seed)?;
    meta.set_item("rig", rig_dict)?;
    let settings = PyDict::new(py);
    settings.set_item("width", rig.intrinsics().width())?;
    settings.set_item("height", rig.intrinsics().height())?;
    settings.set_item("spp", o.settings.spp)?;
    settings.set_item("max_depth", o.settings.max_depth)?;
    settings.set_item("regularize", o.settings.regularize)?;
    settings.set_item("noise_target", o.settings.noise_target)?;
    settings.set_item("baseline", record.baseline)?;
    settings.set_item("exposure", o.exposure)?;
    settings.set_item("sensor", o.sensor.as_deref())?;
    settings.set_item("shutter", o.shutter)?;
    settings.set_item("rig_velocity", o.rig_velocity)?;
    settings.set_item("denoise", o.denoise)?;
    settings.set_item("threads", o.threads)?;
    meta.set_item("settings", settings)?;
    let timings = PyDict::new(py);
    timings.set_item("left_s", views[0].output.stats.seconds)?;
    timings.set_item("right_s", views[1].output.stats.seconds)?;
    timings.set_item("total_s", record.seconds)?;
    meta.set_item("timings", timings)?;
    let stats = PyDict::new(py);
    let per_eye = |f: fn(&EyeView) -> f64| [f(&views[0]), f(&views[1])];
    stats.set_item("samples", per_eye(|v| v.output.stats.samples as f64))?;
    stats.set_item(
        "nonfinite_dropped",
        per_eye(|v| v.output.stats.nonfinite_dropped as f64),
    )?;
    stats.set_item(
        "streak_threshold",
        per_eye(|v| f64::from(v.streak_threshold)),
    )?;
    meta.set_item("stats", stats)?;
    Ok(meta)
}

impl Pair {
    /// The pair of `views` rendered from `scene` with `rig` (saved with PNGs at `exposure`
    /// stops), its arrays made once.
    pub fn new(
        py: Python<'_>,
        scene: Py<Scene>,
        rig: Rig,
        views: [EyeView; 2],
        exposure: f32,
        meta: Bound<'_, PyDict>,
    ) -> PyResult<Self> {
        let [l, r] = &views;
        let road = |v: &EyeView| {
            let img = v.road_surface_mask().map_err(|e| error(&e))?;
            mask(py, &img).map(Bound::unbind)
        };
        let sensor = |v: &EyeView| {
            v.sensor
                .as_ref()
                .map(|c| arrays::rgb(py, &c.dn).map(Bound::unbind))
                .transpose()
        };
        let occlusion = |eye: Eye, v: &EyeView, other: &EyeView| {
            let img =
                occlusion_mask(eye, &v.depth, &v.disparity, &other.depth).map_err(|e| error(&e))?;
            mask(py, &img).map(Bound::unbind)
        };
        let camera = |v: &EyeView| {
            let img = v.camera_image(exposure).map_err(|e| error(&e))?;
            let (w, h) = (img.width() as usize, img.height() as usize);
            arrays::channels(py, w, h, 3, img.into_raw()).map(Bound::unbind)
        };
        Ok(Self {
            occlusion: occlusion(Eye::Left, l, r)?,
            occlusion_right: occlusion(Eye::Right, r, l)?,
            left_camera: camera(l)?,
            right_camera: camera(r)?,
            left: arrays::rgb(py, &l.output.image)?.unbind(),
            right: arrays::rgb(py, &r.output.image)?.unbind(),
            disparity: arrays::gray(py, &l.disparity)?.unbind(),
            disparity_right: arrays::gray(py, &r.disparity)?.unbind(),
            depth: arrays::gray(py, &l.depth)?.unbind(),
            depth_right: arrays::gray(py, &r.depth)?.unbind(),
            streak_mask: mask(py, &l.streak_mask)?.unbind(),
            streak_mask_right: mask(py, &r.streak_mask)?.unbind(),
            road_mask: road(l)?,
            road_mask_right: road(r)?,
            sensor: sensor(l)?,
            sensor_right: sensor(r)?,
            meta: meta.unbind(),
            scene,
            rig,
            exposure,
            views,
        })
    }
}

#[pymethods]
impl Pair {
    /// Writes the pair into the folder `dir` (created if missing) exactly as `streaks stereo
    /// -o DIR` does: per eye the EXR with its layers, the sRGB PNG, the disparity, depth,
    /// streak and road masks, the segmentation maps, then `side_by_side.png`, `anaglyph.png`,
    /// `rig.json` and `calib.txt`. Every file is written atomically. Returns the folder.
    fn save(&self, py: Python<'_>, dir: PathBuf) -> PyResult<PathBuf> {
        let scene = self.scene.bind(py).try_borrow().map_err(|_| {
            StreaksError::new_err("the pair's scene is being rendered; save the pair after it")
        })?;
        let scene = &scene.scene;
        py.detach(|| -> Result<(), String> {
            std::fs::create_dir_all(&dir)
                .map_err(|e| format!("cannot create the folder {}: {e}", dir.display()))?;
            write_pair(&dir, scene, &self.rig, &self.views, self.exposure).map_err(|e| {
                format!(
                    "writing the pair into {}: {}",
                    dir.display(),
                    crate::chain(&e)
                )
            })
        })
        .map_err(StreaksError::new_err)?;
        Ok(dir)
    }

    /// The pair's size, focal length and baseline.
    fn __repr__(&self) -> String {
        let i = self.rig.intrinsics();
        format!(
            "<streaks.Pair {}x{}, f = {:.1} px, baseline {} m>",
            i.width(),
            i.height(),
            i.focal_px(),
            self.rig.baseline()
        )
    }
}
