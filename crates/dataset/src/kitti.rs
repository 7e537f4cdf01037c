//! The KITTI 2015 view of a dataset sample: `image_2` and `image_3` are copies of its 8-bit
//! images, `disp_occ_0` its left disparity as uint16 x 256, and, as KITTI's semantics
//! benchmark has them, `semantic` a copy of its left label ids (`semantic0.png`) and
//! `instance` its left instances as `labelId * 256 + k` (uint16; `labelId * 256` for stuff).

use crate::error::DatasetError;
use crate::files::SampleDir;
use crate::layout::Layout;
use crate::segmentation::{MAX_INSTANCES_PER_CLASS, MAX_KITTI_INSTANCES_PER_CLASS};
use image::{ImageBuffer, Luma};
use std::path::Path;
use streaks_image::kitti::write_kitti_disparity;
use streaks_image::png::write_png_buffer;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::rig::Eye;

/// Writes the KITTI view of sample `index` from its folder `sample` (which may still be the
/// sample's temporary folder) and its left disparity `disp0`; each file atomically.
pub fn write_kitti(
    layout: &Layout,
    index: u64,
    sample: &SampleDir,
    disp0: &GrayImage,
) -> Result<(), DatasetError> {
    let k = layout.kitti(index);
    for (eye, dst) in [(Eye::Left, &k.image_2), (Eye::Right, &k.image_3)] {
        let src = sample.png(eye);
        let bytes = std::fs::read(&src).map_err(|e| DatasetError::io("read", &src, e))?;
        create_parent(dst)?;
        write_bytes_atomically(dst, &bytes)?;
    }
    create_parent(&k.disp_occ_0)?;
    write_kitti_disparity(&k.disp_occ_0, disp0)?;
    let src = sample.semantic(Eye::Left);
    let bytes = std::fs::read(&src).map_err(|e| DatasetError::io("read", &src, e))?;
    create_parent(&k.semantic)?;
    write_bytes_atomically(&k.semantic, &bytes)?;
    let src = sample.instance(Eye::Left);
    let ids = kitti_instances(&src)?;
    create_parent(&k.instance)?;
    write_png_buffer(&k.instance, &ids)?;
    Ok(())
}

/// The instance map at `path` (`instance0.png`: `labelId`, or `labelId * 1000 + k`) in KITTI's
/// convention, `labelId * 256 + k`; an error naming the file when a `k` does not fit.
pub fn kitti_instances(path: &Path) -> Result<ImageBuffer<Luma<u16>, Vec<u16>>, DatasetError> {
    let bytes = std::fs::read(path).map_err(|e| DatasetError::io("read", path, e))?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| DatasetError::Invalid {
            path: path.to_path_buf(),
            reason: format!("is not a PNG: {e}"),
        })?
        .into_luma16();
    let per = MAX_INSTANCES_PER_CLASS as u16;
    let mut out = ImageBuffer::new(img.width(), img.height());
    for (o, p) in out.pixels_mut().zip(img.pixels()) {
        let v = p.0[0];
        let (label, k) = if v < per { (v, 0) } else { (v / per, v % per) };
        if u32::from(k) >= MAX_KITTI_INSTANCES_PER_CLASS {
            return Err(DatasetError::Invalid {
                path: path.to_path_buf(),
                reason: format!(
                    "object {k} of label {label} does not fit KITTI's labelId * 256 + k"
                ),
            });
        }
        *o = Luma([label * 256 + k]);
    }
    Ok(out)
}

fn create_parent(path: &Path) -> Result<(), DatasetError> {
    if let Some(p) = path.parent() {
        std::fs::create_dir_all(p).map_err(|e| DatasetError::io("create the folder", p, e))?;
    }
    Ok(())
}
