//! Loading a pair ([`StereoInput`]) and its rig as the stages use it ([`RigView`]).

use super::ReportError;
use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};
use streaks_dataset::SampleDir;
use streaks_image::pfm::read_pfm;
use streaks_image::{GrayImage, ImageError};
use streaks_stereo::rig::{Eye, EyeCamera, Rig, RoadFrame, RoadRig};
use streaks_stereo::rigfile::LightRecord;

/// A pair and what is known about it.
#[derive(Clone, Debug)]
pub struct StereoInput {
    /// Left image (linear luminance).
    pub left: GrayImage,
    /// Right image.
    pub right: GrayImage,
    /// The rig.
    pub rig: Rig,
    /// The scene's lights.
    pub lights: Vec<LightRecord>,
    /// Ground-truth disparity of the left image (`inf` where nothing was hit), if known.
    pub truth_disparity: Option<GrayImage>,
    /// Ground-truth depth of the left image, if known.
    pub truth_depth: Option<GrayImage>,
    /// The renderer's streak mask of the left image, if present.
    pub truth_streak_mask: Option<GrayImage>,
    /// The left view's road-surface mask (`road0.png`), if present.
    pub truth_road_mask: Option<GrayImage>,
}

impl StereoInput {
    /// Loads the sample folder `dir` ([`SampleDir`]: a `streaks stereo` folder in either
    /// layout, or a dataset sample): both images (the EXR, or the PNG when there is no EXR),
    /// the rig and lights (`rig.json`, or a dataset sample's `meta.json`), and the left view's
    /// ground-truth disparity and depth, the renderer's streak mask and the road-surface mask if
    /// present.
    pub fn load(dir: &Path) -> Result<Self, ReportError> {
        let dataset = |e: streaks_dataset::DatasetError| ReportError::Input {
            path: dir.to_path_buf(),
            reason: e.to_string(),
        };
        let files = SampleDir::open(dir).map_err(dataset)?;
        let left = GrayImage::load(&files.image(Eye::Left))?;
        let right = GrayImage::load(&files.image(Eye::Right))?;
        let (rig, lights) = files.rig().map_err(dataset)?;
        let optional = |p: PathBuf, read: fn(&Path) -> Result<GrayImage, ImageError>| {
            p.exists().then(|| read(&p)).transpose()
        };
        let input = Self {
            left,
            right,
            rig,
            lights,
            truth_disparity: optional(files.disparity(Eye::Left), read_pfm)?,
            truth_depth: optional(files.depth(Eye::Left), read_pfm)?,
            truth_streak_mask: optional(files.streak_mask(Eye::Left), GrayImage::load)?,
            truth_road_mask: optional(files.road_mask(Eye::Left), GrayImage::load)?,
        };
        let i = input.rig.intrinsics();
        let size = (i.width() as usize, i.height() as usize);
        let name = |p: PathBuf| {
            p.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        };
        let named = [
            ("left image".to_owned(), Some(&input.left)),
            ("right image".to_owned(), Some(&input.right)),
            (
                name(files.disparity(Eye::Left)),
                input.truth_disparity.as_ref(),
            ),
            (name(files.depth(Eye::Left)), input.truth_depth.as_ref()),
            (
                name(files.streak_mask(Eye::Left)),
                input.truth_streak_mask.as_ref(),
            ),
            (
                name(files.road_mask(Eye::Left)),
                input.truth_road_mask.as_ref(),
            ),
        ];
        for (what, img) in named {
            if let Some(img) = img {
                if (img.width, img.height) != size {
                    return Err(ReportError::Input {
                        path: dir.to_path_buf(),
                        reason: format!(
                            "the {what} is {}x{}, the rig says {}x{}",
                            img.width, img.height, size.0, size.1
                        ),
                    });
                }
            }
        }
        Ok(input)
    }
}

/// The input's rig as the stages use it, made once from the stereo crate's camera model: the
/// rig in `f64` road coordinates ([`RoadRig`]: projection, horizon, elevations, disparities in
/// pixels and degrees, Eq. 4's predictions), and the `f32` rig with its left eye and road frame,
/// as the ground truth was rendered (the points a disparity or a true depth implies).
pub(super) struct RigView {
    /// The rig as rig.json gives it.
    pub rig: Rig,
    /// The same rig in `f64` road coordinates.
    pub camera: RoadRig,
    road: RoadFrame,
    left: EyeCamera,
}

impl RigView {
    /// The view of `rig`; an error when it has no road frame (it looks straight up or down).
    pub fn new(rig: &Rig) -> Result<Self, ReportError> {
        Ok(Self {
            rig: *rig,
            camera: rig.road_rig()?,
            road: rig.road_frame()?,
            left: rig.eye(Eye::Left),
        })
    }

    /// The road-frame point the left eye sees through `(x, y)` at depth `z`.
    pub fn implied(&self, x: f32, y: f32, z: f32) -> Vec3 {
        let w = self.left.back_project(Vec2::new(x, y), z);
        self.road.road_from_world_point(w)
    }
}
