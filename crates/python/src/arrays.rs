//! Images as numpy arrays: row-major, `H x W` for one channel, `H x W x 3` for three, the
//! values unchanged (the arrays hold exactly the numbers the project's files hold).

use numpy::ndarray::{Array2, Array3};
use numpy::{Element, IntoPyArray};
use pyo3::prelude::*;
use streaks_image::{GrayImage, RgbImage};

/// An `H x W` array of `data` (row-major, `width * height` values).
pub fn plane<'py, T: Element>(
    py: Python<'py>,
    width: usize,
    height: usize,
    data: Vec<T>,
) -> PyResult<Bound<'py, PyAny>> {
    let array = Array2::from_shape_vec((height, width), data).map_err(shape_error)?;
    Ok(array.into_pyarray(py).into_any())
}

/// An `H x W x C` array of `data` (row-major, channels last).
pub fn channels<'py, T: Element>(
    py: Python<'py>,
    width: usize,
    height: usize,
    depth: usize,
    data: Vec<T>,
) -> PyResult<Bound<'py, PyAny>> {
    let array = Array3::from_shape_vec((height, width, depth), data).map_err(shape_error)?;
    Ok(array.into_pyarray(py).into_any())
}

/// An `H x W x 3` float32 array of a linear RGB image.
pub fn rgb<'py>(py: Python<'py>, img: &RgbImage) -> PyResult<Bound<'py, PyAny>> {
    let data = img.pixels.iter().flat_map(|p| p.to_array()).collect();
    channels(py, img.width as usize, img.height as usize, 3, data)
}

/// An `H x W` float32 array of a grey image.
pub fn gray<'py>(py: Python<'py>, img: &GrayImage) -> PyResult<Bound<'py, PyAny>> {
    plane(py, img.width, img.height, img.data.clone())
}

/// An `H x W x C` float32 array of `planes` (C planes of `width * height` values).
pub fn interleave<'py>(
    py: Python<'py>,
    width: usize,
    height: usize,
    planes: &[Vec<f32>],
) -> PyResult<Bound<'py, PyAny>> {
    if let [one] = planes {
        return plane(py, width, height, one.clone());
    }
    let n = width * height;
    let data = (0..n)
        .flat_map(|i| planes.iter().map(move |p| p[i]))
        .collect();
    channels(py, width, height, planes.len(), data)
}

/// The error of an array whose data does not fill its shape (a bug, never bad input: every
/// image here has `width * height` pixels by construction).
fn shape_error(e: numpy::ndarray::ShapeError) -> PyErr {
    crate::StreaksError::new_err(format!("an image does not fill its shape: {e}"))
}
