//! `streaks.dataset.open`: a dataset written by `streaks dataset generate` as a sequence of
//! samples, each a dict of numpy arrays under the names of `streaks.Pair`. The files are named
//! by the dataset crate ([`streaks_dataset::layout::Layout`],
//! [`streaks_dataset::files::SampleDir`]) and read with the project's readers.

use crate::{arrays, error, StreaksError};
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use streaks_dataset::files::{load_mask, SampleDir};
use streaks_dataset::layout::{DatasetInfo, Layout};
use streaks_dataset::outputs::Outputs;
use streaks_image::pfm::read_pfm;
use streaks_image::GrayImage;
use streaks_stereo::rig::Eye;

/// A dataset's samples (all, or one split's), in the order of their ids.
///
/// `len(ds)` is the number of samples; `ds[i]` (negative indices count from the end) reads
/// sample i as a dict: `left`, `right` (float32 H x W x 3, linear, from the EXRs),
/// `left_camera`, `right_camera` (the PNGs as the camera sees them, uint8 H x W x 3; with
/// `--outputs images16` also `left_camera16`, `right_camera16`, uint16),
/// `disparity`, `disparity_right`, `depth`, `depth_right` (float32 H x W, `inf` where there is
/// none), `streak_mask`, `road_mask`, `occlusion`, `occlusion_right` (bool H x W; no
/// `road_mask` when the scene flags no road), `id` (the sample's folder name) and `meta` (its
/// `meta.json`). The arrays of the groups of files the dataset did not keep (`dataset.json`'s
/// `outputs`) are absent; those it keeps must be there.
#[pyclass(module = "streaks._streaks", frozen, sequence)]
pub struct Dataset {
    /// The dataset's folders.
    layout: Layout,
    /// The sample ids, sorted.
    ids: Vec<String>,
    /// The groups of files its samples keep (`dataset generate --outputs`).
    outputs: Outputs,
}

/// A sample's 0/255 mask PNG as a bool array, checked to be `size` (width, height) as the
/// sample's rig says ([`load_mask`]).
fn mask_png<'py>(
    py: Python<'py>,
    path: &std::path::Path,
    size: (usize, usize),
) -> PyResult<Bound<'py, PyAny>> {
    let img = py
        .detach(|| load_mask(path, size, "the sample's rig"))
        .map_err(|e| error(&e))?;
    let data = img.data.iter().map(|&v| v > 0.5).collect();
    arrays::plane(py, img.width, img.height, data)
}

/// A PFM as a float32 array.
fn pfm<'py>(py: Python<'py>, path: &std::path::Path) -> PyResult<Bound<'py, PyAny>> {
    let img: GrayImage = py.detach(|| read_pfm(path)).map_err(|e| error(&e))?;
    arrays::gray(py, &img)
}

/// The linear RGB of an eye's EXR.
fn exr<'py>(py: Python<'py>, path: &std::path::Path) -> PyResult<Bound<'py, PyAny>> {
    let img = py
        .detach(|| streaks_image::exr::read_exr_rgb(path))
        .map_err(|e| error(&e))?;
    arrays::rgb(py, &img)
}

#[pymethods]
impl Dataset {
    /// Opens the dataset in `root`: every complete sample, or with `split` (`train`, `val`,
    /// `test`) those `streaks dataset index` listed in `splits/SPLIT.txt`. Raises
    /// `StreaksError` for an unknown or missing split or a dataset without samples.
    #[new]
    #[pyo3(signature = (root, *, split=None))]
    fn new(root: PathBuf, split: Option<String>) -> PyResult<Self> {
        let layout = Layout::new(&root);
        let info = DatasetInfo::load(&layout.dataset_json()).map_err(|e| error(&e))?;
        let ids = layout.sample_ids(split.as_deref()).map_err(|e| error(&e))?;
        Ok(Self {
            layout,
            ids,
            outputs: info.settings.outputs,
        })
    }

    /// The sample ids (folder names), in order.
    #[getter]
    fn ids(&self) -> Vec<String> {
        self.ids.clone()
    }

    /// The number of samples.
    fn __len__(&self) -> usize {
        self.ids.len()
    }

    /// Sample `index` (negative counts from the end) read from its files, as a dict.
    fn __getitem__<'py>(&self, py: Python<'py>, index: isize) -> PyResult<Bound<'py, PyDict>> {
        let n = self.ids.len() as isize;
        let i = if index < 0 { index + n } else { index };
        if !(0..n).contains(&i) {
            return Err(PyIndexError::new_err(format!(
                "sample {index} out of range (the dataset has {n})"
            )));
        }
        let id = &self.ids[i as usize];
        let files: SampleDir = self.layout.sample_by_id(id);
        let meta = files.load_meta().map_err(|e| error(&e))?;
        let text = serde_json::to_string(&meta)
            .map_err(|e| StreaksError::new_err(format!("{}: {e}", files.meta().display())))?;
        let size = (meta.rig.width as usize, meta.rig.height as usize);
        let sample = PyDict::new(py);
        sample.set_item("id", id)?;
        let kept = |path: &Path| {
            let name = path
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or_default();
            self.outputs.keeps(name)
        };
        for (eye, suffix) in [(Eye::Left, ""), (Eye::Right, "_right")] {
            let image = if suffix.is_empty() { "left" } else { "right" };
            let (exr_path, png_path) = (files.exr(eye), files.png(eye));
            if kept(&exr_path) {
                sample.set_item(image, exr(py, &exr_path)?)?;
            }
            if kept(&png_path) {
                sample.set_item(
                    format!("{image}_camera"),
                    crate::io::read_png(py, png_path)?,
                )?;
            }
            let png16_path = files.png16(eye);
            if kept(&png16_path) {
                sample.set_item(
                    format!("{image}_camera16"),
                    crate::io::read_png(py, png16_path)?,
                )?;
            }
            for (name, path) in [
                ("disparity", files.disparity(eye)),
                ("depth", files.depth(eye)),
            ] {
                if kept(&path) && (eye == Eye::Left || path.is_file()) {
                    sample.set_item(format!("{name}{suffix}"), pfm(py, &path)?)?;
                }
            }
            let occlusion = files.occlusion(eye);
            if kept(&occlusion) {
                sample.set_item(
                    format!("occlusion{suffix}"),
                    mask_png(py, &occlusion, size)?,
                )?;
            }
        }
        let streaks = files.streak_mask(Eye::Left);
        if kept(&streaks) {
            sample.set_item("streak_mask", mask_png(py, &streaks, size)?)?;
        }
        let road = files.road_mask(Eye::Left);
        if meta.road_mask && kept(&road) {
            sample.set_item("road_mask", mask_png(py, &road, size)?)?;
        }
        sample.set_item("meta", py.import("json")?.call_method1("loads", (text,))?)?;
        Ok(sample)
    }

    /// The dataset's folder and its number of samples.
    fn __repr__(&self) -> String {
        format!(
            "<streaks.dataset {} ({} samples)>",
            self.layout.root().display(),
            self.ids.len()
        )
    }
}
