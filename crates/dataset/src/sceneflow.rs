//! The SceneFlow (FlyingThings3D) view of a dataset sample, as SceneFlow's stereo loaders read
//! it (torchvision's `SceneFlowStereo` with the dataset folder as root, RAFT-Stereo's
//! `SceneFlowDatasets` with `SceneFlow/` as root):
//!
//! ```text
//! SceneFlow/FlyingThings3D/frames_cleanpass/SPLIT/L/SSSS/left/NNNNNNN.png     = im0.png
//! SceneFlow/FlyingThings3D/frames_cleanpass/SPLIT/L/SSSS/right/NNNNNNN.png    = im1.png
//! SceneFlow/FlyingThings3D/disparity/SPLIT/L/SSSS/left/NNNNNNN.pfm            disp0, 0 on the sky
//! SceneFlow/FlyingThings3D/disparity/SPLIT/L/SSSS/right/NNNNNNN.pfm           disp1, 0 on the sky
//! SceneFlow/FlyingThings3D/disparity_occlusions/SPLIT/L/SSSS/left/NNNNNNN.png = occ0.png
//! SceneFlow/FlyingThings3D/disparity_occlusions/SPLIT/L/SSSS/right/NNNNNNN.png = occ1.png
//! ```
//!
//! `SPLIT/L` is `TRAIN/A` for the train split, `TEST/B` for val and `TEST/C` for test
//! (FlyingThings3D's TRAIN and TEST, its letters telling our val and test apart); `SSSS` the
//! street (a drive, as a FlyingThings3D scene is a sequence), four digits or more; `NNNNNNN`
//! the sample index, seven digits. SceneFlow's disparities are positive in both views (the
//! right view's match in the left image is at `x + d`), PFM `Pf` with rows bottom to top, and
//! defined everywhere: the sky, at infinity, has disparity 0 (RAFT-Stereo counts a pixel valid
//! where `d < 512`). The occlusion maps are 0/255 as the FlyingThings3D subset's
//! `disparity_occlusions`.

use crate::error::DatasetError;
use crate::files::SampleDir;
use crate::kitti::create_parent;
use crate::layout::Layout;
use streaks_image::pfm::{read_pfm, write_pfm};
use streaks_image::write_bytes_atomically;
use streaks_stereo::rig::Eye;

/// Writes the SceneFlow view of sample `index` (of split `split` and street `street`, from its
/// `meta.json`) from the files of its folder `sample`; each file atomically. A split that is
/// not one of the dataset's is an error naming `meta.json`.
pub fn write_sceneflow(
    layout: &Layout,
    index: u64,
    split: &str,
    street: u64,
    sample: &SampleDir,
) -> Result<(), DatasetError> {
    let files = layout
        .sceneflow(index, split, street)
        .ok_or_else(|| DatasetError::Invalid {
            path: sample.meta(),
            reason: format!("its split {split:?} is not train, val or test"),
        })?;
    for (k, eye) in Eye::BOTH.into_iter().enumerate() {
        for (src, dst) in [
            (sample.png(eye), &files.images[k]),
            (sample.occlusion(eye), &files.occlusion[k]),
        ] {
            let bytes = std::fs::read(&src).map_err(|e| DatasetError::io("read", &src, e))?;
            create_parent(dst)?;
            write_bytes_atomically(dst, &bytes)?;
        }
        let mut disp = read_pfm(&sample.disparity(eye))?;
        for d in &mut disp.data {
            if !d.is_finite() {
                *d = 0.0;
            }
        }
        create_parent(&files.disparity[k])?;
        write_pfm(&files.disparity[k], &disp)?;
    }
    Ok(())
}
