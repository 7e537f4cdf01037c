//! `streaks.io`: the project's files read into numpy arrays by the project's readers (one way
//! of reading each format, with their checks against hostile files: regular files only, sizes
//! checked from the header before anything is allocated).

use crate::{arrays, error};
use image::DynamicImage;
use pyo3::prelude::*;
use std::path::PathBuf;
use streaks_image::input::{load_image, read_file_prefix};
use streaks_image::pfm::{read_pfm as read_gray_pfm, read_pfm_rgb};
use streaks_image::ImageError;

/// Reads a PFM (the Middlebury convention: rows stored bottom first, either byte order) as a
/// float32 array, top row first: `H x W` for a greyscale file (`Pf`: disparity, depth),
/// `H x W x 3` for a colour one (`PF`). Values are as stored (`inf` stays `inf`).
#[pyfunction]
pub fn read_pfm(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let colour = read_file_prefix(&path, 2).is_ok_and(|magic| magic == b"PF");
    if colour {
        let img = py.detach(|| read_pfm_rgb(&path)).map_err(|e| error(&e))?;
        arrays::rgb(py, &img)
    } else {
        let img = py.detach(|| read_gray_pfm(&path)).map_err(|e| error(&e))?;
        arrays::gray(py, &img)
    }
}

/// The eight bytes every PNG starts with.
const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

/// Reads a PNG as stored, without any colour conversion: `uint8` for an 8-bit file, `uint16`
/// for a 16-bit one (a KITTI disparity map: disparity x 256, 0 where there is none), `H x W`
/// for grey, `H x W x C` otherwise (C = 2, 3 or 4). Masks (`streaks0.png`, `road0.png`) are
/// 0/255 grey.
#[pyfunction]
pub fn read_png(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let img = py
        .detach(|| {
            let not_png = |reason: String| ImageError::Read {
                path: path.clone(),
                reason,
            };
            let magic = read_file_prefix(&path, PNG_SIGNATURE.len() as u64)
                .map_err(|e| not_png(e.to_string()))?;
            if magic != PNG_SIGNATURE {
                return Err(not_png("not a PNG file (no PNG signature)".into()));
            }
            load_image(&path)
        })
        .map_err(|e| error(&e))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    match img {
        DynamicImage::ImageLuma8(b) => arrays::plane(py, w, h, b.into_raw()),
        DynamicImage::ImageLumaA8(b) => arrays::channels(py, w, h, 2, b.into_raw()),
        DynamicImage::ImageRgb8(b) => arrays::channels(py, w, h, 3, b.into_raw()),
        DynamicImage::ImageRgba8(b) => arrays::channels(py, w, h, 4, b.into_raw()),
        DynamicImage::ImageLuma16(b) => arrays::plane(py, w, h, b.into_raw()),
        DynamicImage::ImageLumaA16(b) => arrays::channels(py, w, h, 2, b.into_raw()),
        DynamicImage::ImageRgb16(b) => arrays::channels(py, w, h, 3, b.into_raw()),
        DynamicImage::ImageRgba16(b) => arrays::channels(py, w, h, 4, b.into_raw()),
        other => Err(crate::StreaksError::new_err(format!(
            "cannot read image {}: an unexpected PNG sample type {:?}",
            path.display(),
            other.color()
        ))),
    }
}

/// Reads an EXR the renderer wrote (a render, or one eye of a pair) as a dict of float32
/// arrays by layer: `rgb` (`R`, `G`, `B`, linear, `H x W x 3`), then each layer the file has:
/// `albedo`, `raw`, `specular`, `sensor`, `normal` (`H x W x 3`), `depth`, `spp`, `rain`,
/// `fog`, `object` (`H x W`).
#[pyfunction]
pub fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    let (w, h, layers) = py
        .detach(|| streaks_render::output::read_exr_layers(&path))
        .map_err(|e| error(&e))?;
    let dict = pyo3::types::PyDict::new(py);
    for (name, planes) in layers {
        dict.set_item(
            name,
            arrays::interleave(py, w as usize, h as usize, &planes)?,
        )?;
    }
    Ok(dict)
}
