//! The KITTI 2015 view of a dataset sample: `image_2` and `image_3` are copies of its 8-bit
//! images, `disp_occ_0` its left disparity as uint16 x 256.

use crate::error::DatasetError;
use crate::files::SampleDir;
use crate::layout::Layout;
use std::path::Path;
use streaks_image::kitti::write_kitti_disparity;
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
    Ok(())
}

fn create_parent(path: &Path) -> Result<(), DatasetError> {
    if let Some(p) = path.parent() {
        std::fs::create_dir_all(p).map_err(|e| DatasetError::io("create the folder", p, e))?;
    }
    Ok(())
}
