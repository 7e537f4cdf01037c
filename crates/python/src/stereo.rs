//! `streaks.disparity` and `streaks.score`: the benchmark's built-in stereo methods and its
//! scorer on numpy arrays, so that a Python user gets the numbers `streaks benchmark` reports
//! (the same methods, [`BuiltIn`], and the same regions and metrics, [`score_regions`]: EPE,
//! bad-N, KITTI's D1, the valid share and the phantom-hole rate).

use crate::{error, StreaksError};
use glam::Vec3;
use numpy::ndarray::ArrayViewD;
use numpy::PyReadonlyArrayDyn;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use streaks_analysis::benchmark::method::{BuiltIn, BUILT_INS};
use streaks_analysis::benchmark::{score_regions, Masks};
use streaks_image::{GrayImage, RgbImage};

/// The values of an array view as `f32`, scaled, in row-major order whatever its strides.
fn values<T: Copy + Into<f64>>(view: &ArrayViewD<'_, T>, scale: f64) -> Vec<f32> {
    view.iter().map(|&v| (v.into() * scale) as f32).collect()
}

/// The shape and values of a numpy array as `f32`: floats as they are, and with `integers`
/// `uint8` and `uint16` scaled to [0, 1]; `None` for any other dtype.
fn array_values(obj: &Bound<'_, PyAny>, integers: bool) -> Option<(Vec<usize>, Vec<f32>)> {
    fn read<T: Copy + Into<f64> + numpy::Element>(
        obj: &Bound<'_, PyAny>,
        scale: f64,
    ) -> Option<(Vec<usize>, Vec<f32>)> {
        let a = obj.extract::<PyReadonlyArrayDyn<'_, T>>().ok()?;
        let v = a.as_array();
        Some((v.shape().to_vec(), values(&v, scale)))
    }
    read::<f32>(obj, 1.0)
        .or_else(|| read::<f64>(obj, 1.0))
        .or_else(|| integers.then(|| read::<u8>(obj, 1.0 / 255.0)).flatten())
        .or_else(|| integers.then(|| read::<u16>(obj, 1.0 / 65535.0)).flatten())
}

/// An image array as a grey image: `H x W` as it is, `H x W x 3` as its luminance (of the
/// stored values, as the benchmark reads PNGs); `uint8` and `uint16` scaled to [0, 1], floats
/// as they are. `name` is the argument's name in errors.
fn gray_of(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<GrayImage> {
    let Some((shape, data)) = array_values(obj, true) else {
        return Err(PyTypeError::new_err(format!(
            "{name} must be a numpy array of uint8, uint16, float32 or float64"
        )));
    };
    let image = match shape[..] {
        [h, w] => GrayImage::from_vec(w, h, data),
        [h, w, 3] => {
            let pixels = data
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect();
            let rgb = RgbImage {
                width: w as u32,
                height: h as u32,
                pixels,
            };
            GrayImage::luminance_of(&rgb)
        }
        _ => {
            return Err(PyValueError::new_err(format!(
                "{name} must be H x W or H x W x 3, got the shape {shape:?}"
            )))
        }
    };
    image.map_err(|e| error(&e))
}

/// A float H x W disparity map (float32 or float64) as a grey image; `name` is the
/// argument's name in errors.
fn disparity_map(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<GrayImage> {
    let Some((shape, data)) = array_values(obj, false) else {
        return Err(PyTypeError::new_err(format!(
            "{name} must be a float disparity map (a float32 or float64 numpy array)"
        )));
    };
    match shape[..] {
        [h, w] => GrayImage::from_vec(w, h, data).map_err(|e| error(&e)),
        _ => Err(PyValueError::new_err(format!(
            "{name} must be an H x W disparity map, got the shape {shape:?}"
        ))),
    }
}

/// A bool (or 0/1) mask array as a grey image of 1 and 0, `None` for `None`.
fn mask_of(name: &str, obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<GrayImage>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let (shape, data): (Vec<usize>, Vec<f32>) =
        if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, bool>>() {
            let v = a.as_array();
            (
                v.shape().to_vec(),
                v.iter().map(|&m| f32::from(u8::from(m))).collect(),
            )
        } else {
            let g = gray_of(name, obj)?;
            (vec![g.height, g.width], g.data)
        };
    match shape[..] {
        [h, w] => GrayImage::from_vec(w, h, data)
            .map(Some)
            .map_err(|e| error(&e)),
        _ => Err(PyValueError::new_err(format!(
            "{name} must be an H x W mask, got the shape {shape:?}"
        ))),
    }
}

/// The left view's disparity of a rectified pair by one of the benchmark's built-in methods
/// (`"sgm"`, `"sgm-streaks"`, `"lk"`; `streaks benchmark --method`): float32 H x W in pixels,
/// `inf` where the method gives no value. `left` and `right` are H x W x 3 images (their
/// luminance is matched) or H x W grey ones, `uint8`/`uint16` (scaled to [0, 1]) or floats:
/// the camera's PNGs as stored, as the benchmark reads them. The GIL is released meanwhile.
#[pyfunction]
#[pyo3(signature = (left, right, method = "sgm"))]
pub fn disparity<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let Some(method) = BuiltIn::from_name(method) else {
        let names: Vec<&str> = BUILT_INS.iter().map(|(n, _)| *n).collect();
        return Err(PyValueError::new_err(format!(
            "no built-in method {method:?}; the methods are {}",
            names.join(", ")
        )));
    };
    let (l, r) = (gray_of("left", left)?, gray_of("right", right)?);
    let disp = py
        .detach(|| method.disparity(&l, &r))
        .map_err(|e| error(&e))?;
    crate::arrays::gray(py, &disp)
}

/// Scores a disparity `estimate` of the left view against the `truth` (both float32 H x W,
/// `inf` or a value <= 0 where there is none) by region, as `streaks benchmark` does: a dict
/// with `all` and, where their masks are given, `streak`, `non_streak`, `road`, `off_road`,
/// `road_surface` (the whole road; its `below_1px` is the phantom-hole rate) and
/// `non_occluded` (pixels not in `occlusion`). A region without its masks is `None`. Each
/// region is a dict: `mean_abs` (EPE, px), `rms`, `bad_1`, `bad_2`, `bad_3`, `d1`, `density`
/// (the valid share), `below_1px`, `truth_pixels`, `valid_pixels`, ...; also
/// `phantom_hole_rate` at the top (`None` without a road mask).
#[pyfunction]
#[pyo3(signature = (estimate, truth, *, streak_mask = None, road_mask = None, occlusion = None))]
pub fn score<'py>(
    py: Python<'py>,
    estimate: &Bound<'py, PyAny>,
    truth: &Bound<'py, PyAny>,
    streak_mask: Option<&Bound<'py, PyAny>>,
    road_mask: Option<&Bound<'py, PyAny>>,
    occlusion: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (estimate, truth) = (
        disparity_map("estimate", estimate)?,
        disparity_map("truth", truth)?,
    );
    let streaks = mask_of("streak_mask", streak_mask)?;
    let road = mask_of("road_mask", road_mask)?;
    let non_occluded = mask_of("occlusion", occlusion)?.map(|mut m| {
        m.data
            .iter_mut()
            .for_each(|v| *v = if *v > 0.0 { 0.0 } else { 1.0 });
        m
    });
    let masks = Masks {
        streaks: streaks.as_ref(),
        road: road.as_ref(),
        non_occluded: non_occluded.as_ref(),
    };
    let regions = py
        .detach(|| score_regions(&estimate, &truth, &masks))
        .map_err(|e| error(&e))?;
    let mut value = serde_json::to_value(regions)
        .map_err(|e| StreaksError::new_err(format!("the scores: {e}")))?;
    value["phantom_hole_rate"] = serde_json::json!(regions.phantom_hole_rate());
    let json = py.import("json")?;
    json.call_method1("loads", (value.to_string(),))
}
