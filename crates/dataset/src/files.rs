//! Every file name of a sample folder and of a dataset folder, spelled once, and
//! [`SampleDir`], the one type that names, reads and checks a sample's files.
//!
//! A sample folder (Middlebury style; a dataset's `samples/NNNNNN/`, and the folder of
//! `streaks stereo -o DIR`):
//!
//! ```text
//! im0.exr, im1.exr        linear float32 RGB with the depth, normal and specular layers
//! im0.png, im1.png        8-bit sRGB of the render times 2^exposure
//! disp0.pfm, disp1.pfm    ground-truth disparity of the left and right view
//! depth0.pfm, depth1.pfm  ground-truth depth of the left and right view
//! occ0.png, occ1.png      occlusion masks: 255 where the pixel's point is hidden from the other
//!                         eye or outside its image
//! streaks0.png            streak mask of the left view (streaks1.png: the right view's)
//! road0.png               road-surface mask of the left view, when the scene flags a road
//!                         (road1.png: the right view's)
//! semantic0.png, semantic1.png   8-bit label ids (Cityscapes labelIds; see segmentation)
//! instance0.png, instance1.png   16-bit instance ids (Cityscapes instanceIds)
//! flow0.png               the left view's forward optical flow to the next frame, KITTI
//!                         flow_occ style: 16-bit RGB, u x 64 + 2^15, v x 64 + 2^15, valid
//! flow0.pfm               the same flow as float (PF: u, v, 0; inf where it has none)
//! dispchange0.pfm         the left view's disparity change to the next frame (SceneFlow's)
//! flowmask0.png           what each pixel's flow is: 255 visible in the next frame,
//!                         128 occluded in it, 64 out of its view, 0 no surface (the sky)
//! calib.txt               Middlebury 2014 calibration
//! meta.json               a dataset sample's metadata (rig, lights, seeds, statistics)
//! rig.json                a pair's rig and lights (`streaks stereo`)
//! anaglyph.png, side_by_side.png   a pair's viewing aids (`streaks stereo`)
//! scene.gltf, scene.bin, scene_*.png   a dataset sample's scene
//! ```
//!
//! A dataset folder also has, per street, `sequences/SSSSSS/poses.txt` (KITTI odometry: the
//! left camera's pose in the first frame's camera frame, 12 numbers a line, one line per
//! frame) and `times.txt` (each frame's time, seconds), written by `streaks dataset index`
//! from the samples' `meta.json`.
//!
//! A dataset sample has the left view's streak and road masks only; a `streaks stereo` folder
//! has both views'. Folders that `streaks stereo` wrote before it used this layout (`left.exr`,
//! `disparity_left.pfm`, ...: [`PAIR_NAMES`]) are still read: [`SampleDir::open`] finds which
//! layout a folder has.

use crate::error::DatasetError;
use crate::meta::SampleMeta;
use std::path::{Path, PathBuf};
use streaks_image::GrayImage;
use streaks_stereo::calib::MiddleburyCalib;
use streaks_stereo::rig::{Eye, Intrinsics, Rig};
use streaks_stereo::rigfile::{LightRecord, RigFile};

/// `dataset.json`: a dataset's settings and conventions.
pub const DATASET_JSON: &str = "dataset.json";
/// `manifest.jsonl`: one line per good sample of a dataset.
pub const MANIFEST: &str = "manifest.jsonl";
/// The dataset lock's file name in the dataset folder.
pub const LOCK: &str = ".lock";
/// The name prefix of the sample locks in `samples/`: `.lock-NNNNNN`.
pub const SAMPLE_LOCK_PREFIX: &str = ".lock-";
/// The name prefix of the temporary folders in `samples/`: `.tmp-NNNNNN-PID`.
pub const TMP_PREFIX: &str = ".tmp-";
/// A dataset's sample folders.
pub const SAMPLES_DIR: &str = "samples";
/// A dataset's split lists.
pub const SPLITS_DIR: &str = "splits";
/// The extension of a split list (`splits/train.txt`).
pub const SPLIT_EXTENSION: &str = "txt";
/// A dataset's KITTI 2015 view (`kitti/training/...`).
pub const KITTI_DIR: [&str; 2] = ["kitti", "training"];
/// The KITTI view's left images.
pub const KITTI_IMAGE_2: &str = "image_2";
/// The KITTI view's right images.
pub const KITTI_IMAGE_3: &str = "image_3";
/// The KITTI view's left disparities.
pub const KITTI_DISP_OCC_0: &str = "disp_occ_0";
/// The KITTI view's right-view disparities (as torchvision's `Kitti2015Stereo` reads them).
pub const KITTI_DISP_OCC_1: &str = "disp_occ_1";
/// The KITTI view's left disparities of the pixels both eyes see.
pub const KITTI_DISP_NOC_0: &str = "disp_noc_0";
/// The KITTI view's calibration files (`calib_cam_to_cam/NNNNNN.txt`).
pub const KITTI_CALIB: &str = "calib_cam_to_cam";
/// The extension of a KITTI calibration file.
pub const KITTI_CALIB_EXTENSION: &str = "txt";
/// KITTI's semantic maps (its semantics benchmark's `semantic/`: label ids, 8 bit).
pub const KITTI_SEMANTIC: &str = "semantic";
/// KITTI's instance maps (`instance/`: `labelId * 256 + k`, 16 bit).
pub const KITTI_INSTANCE: &str = "instance";
/// A dataset's SceneFlow view (`SceneFlow/FlyingThings3D/...`).
pub const SCENEFLOW_DIR: [&str; 2] = ["SceneFlow", "FlyingThings3D"];
/// The SceneFlow view's images (the clean pass: the render as the camera saw it).
pub const SCENEFLOW_IMAGES: &str = "frames_cleanpass";
/// The SceneFlow view's disparities.
pub const SCENEFLOW_DISPARITY: &str = "disparity";
/// The SceneFlow view's occlusion maps.
pub const SCENEFLOW_OCCLUSION: &str = "disparity_occlusions";
/// The suffix of a KITTI file name after the sample id (`NNNNNN_10.png`).
pub const KITTI_SUFFIX: &str = "_10.png";

/// A dataset's per-street sequence folders (`sequences/SSSSSS/`).
pub const SEQUENCES_DIR: &str = "sequences";
/// A sequence's camera poses (KITTI odometry format).
pub const POSES: &str = "poses.txt";
/// A sequence's frame times, seconds.
pub const TIMES: &str = "times.txt";

/// The left view's optical flow to the next frame as a KITTI 2015 16-bit flow PNG.
pub const FLOW_PNG: &str = "flow0.png";
/// The left view's optical flow to the next frame as a three-channel PFM (u, v, 0).
pub const FLOW_PFM: &str = "flow0.pfm";
/// The left view's disparity change to the next frame, PFM.
pub const DISPARITY_CHANGE: &str = "dispchange0.pfm";
/// What each left pixel's flow is (visible, occluded, out of view, no surface), 8-bit PNG.
pub const FLOW_MASK: &str = "flowmask0.png";
/// The flow files of a sample of a sequence (every generated sample with a `sequence`
/// record in its `meta.json`), sorted.
pub const FLOW_FILES: [&str; 4] = [DISPARITY_CHANGE, FLOW_PFM, FLOW_PNG, FLOW_MASK];

/// `calib.txt`: the Middlebury 2014 calibration.
pub const CALIB: &str = "calib.txt";
/// `meta.json`: a dataset sample's metadata.
pub const META: &str = "meta.json";
/// `rig.json`: a pair's rig and lights.
pub const RIG: &str = "rig.json";
/// `anaglyph.png`: a pair's red-cyan view.
pub const ANAGLYPH: &str = "anaglyph.png";
/// `side_by_side.png`: a pair's two views side by side.
pub const SIDE_BY_SIDE: &str = "side_by_side.png";
/// The scene's glTF in a sample folder (with [`SCENE_BIN`] and its `scene_*.png` textures).
pub const SCENE_GLTF: &str = "scene.gltf";
/// The scene's buffer in a sample folder.
pub const SCENE_BIN: &str = "scene.bin";
/// The road-surface mask of the left view, present when the scene flags a road material.
pub const ROAD_MASK: &str = "road0.png";

/// The files of every dataset sample folder besides the scene's, sorted.
pub const SAMPLE_FILES: [&str; 15] = [
    CALIB,
    "depth0.pfm",
    "depth1.pfm",
    "disp0.pfm",
    "disp1.pfm",
    "im0.exr",
    "im0.png",
    "im0_16.png",
    "im1.exr",
    "im1.png",
    "im1_16.png",
    META,
    "occ0.png",
    "occ1.png",
    "streaks0.png",
];

/// The names of the per-eye files of one layout, left then right.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Names {
    /// The linear image with its layers.
    pub exr: [&'static str; 2],
    /// The 8-bit sRGB image.
    pub png: [&'static str; 2],
    /// The same image at 16 bits (datasets with `--outputs images16`).
    pub png16: [&'static str; 2],
    /// Ground-truth disparity.
    pub disparity: [&'static str; 2],
    /// Ground-truth depth.
    pub depth: [&'static str; 2],
    /// The renderer's streak mask.
    pub streak_mask: [&'static str; 2],
    /// The road-surface mask.
    pub road_mask: [&'static str; 2],
    /// The rain mask: the share of the pixel's camera samples that met a rain drop.
    pub rain_mask: [&'static str; 2],
    /// The fog's transmittance from the camera to the pixel's first hit.
    pub fog: [&'static str; 2],
    /// The semantic map (label ids).
    pub semantic: [&'static str; 2],
    /// The instance map (Cityscapes instance ids).
    pub instance: [&'static str; 2],
    /// The occlusion mask: the pixels whose point the other eye does not see.
    pub occlusion: [&'static str; 2],
}

/// The sample layout (Middlebury style): `im0.png`, `disp0.pfm`, ...
pub const SAMPLE_NAMES: Names = Names {
    exr: ["im0.exr", "im1.exr"],
    png: ["im0.png", "im1.png"],
    png16: ["im0_16.png", "im1_16.png"],
    disparity: ["disp0.pfm", "disp1.pfm"],
    depth: ["depth0.pfm", "depth1.pfm"],
    streak_mask: ["streaks0.png", "streaks1.png"],
    road_mask: [ROAD_MASK, "road1.png"],
    rain_mask: ["rain0.png", "rain1.png"],
    fog: ["fog0.pfm", "fog1.pfm"],
    semantic: ["semantic0.png", "semantic1.png"],
    instance: ["instance0.png", "instance1.png"],
    occlusion: ["occ0.png", "occ1.png"],
};

/// The older pair layout of `streaks stereo`: `left.png`, `disparity_left.pfm`, ... (read,
/// never written).
pub const PAIR_NAMES: Names = Names {
    exr: ["left.exr", "right.exr"],
    png: ["left.png", "right.png"],
    png16: ["left_16.png", "right_16.png"],
    disparity: ["disparity_left.pfm", "disparity_right.pfm"],
    depth: ["depth_left.pfm", "depth_right.pfm"],
    streak_mask: ["streak_mask_left.png", "streak_mask_right.png"],
    road_mask: ["road_mask_left.png", "road_mask_right.png"],
    rain_mask: ["rain_mask_left.png", "rain_mask_right.png"],
    fog: ["fog_left.pfm", "fog_right.pfm"],
    semantic: ["semantic_left.png", "semantic_right.png"],
    instance: ["instance_left.png", "instance_right.png"],
    occlusion: ["occlusion_left.png", "occlusion_right.png"],
};

fn eye_index(eye: Eye) -> usize {
    match eye {
        Eye::Left => 0,
        Eye::Right => 1,
    }
}

/// A sample folder: the paths of its files in its layout, and reading what they hold.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SampleDir {
    dir: PathBuf,
    names: &'static Names,
}

impl SampleDir {
    /// The sample folder `dir` in the sample layout (for writing, or reading a folder known
    /// to have it).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: dir.into(),
            names: &SAMPLE_NAMES,
        }
    }

    /// The layout `dir` has: the sample layout when its left image is there in it, else the
    /// older pair layout when its is, else `None`.
    fn detect(dir: &Path) -> Option<&'static Names> {
        [&SAMPLE_NAMES, &PAIR_NAMES].into_iter().find(|names| {
            let i = eye_index(Eye::Left);
            dir.join(names.png[i]).is_file() || dir.join(names.exr[i]).is_file()
        })
    }

    /// The sample folder `dir` as it is on disk: the sample layout, or the older pair layout
    /// of `streaks stereo`. Fails naming the folder when it has neither's left image.
    pub fn open(dir: impl Into<PathBuf>) -> Result<Self, DatasetError> {
        let dir = dir.into();
        match Self::detect(&dir) {
            Some(names) => Ok(Self { dir, names }),
            None => Err(DatasetError::NotASample {
                path: dir,
                left: SAMPLE_NAMES.png[0],
                right: SAMPLE_NAMES.png[1],
                old_left: PAIR_NAMES.png[0],
                old_right: PAIR_NAMES.png[1],
            }),
        }
    }

    /// Whether `dir` holds a stereo pair to measure, in either layout: both 8-bit images and
    /// the left view's ground-truth disparity.
    pub fn is_pair(dir: &Path) -> bool {
        Self::detect(dir).is_some_and(|n| {
            n.png.iter().all(|f| dir.join(f).is_file()) && dir.join(n.disparity[0]).is_file()
        })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Whether the folder has the older pair layout (`left.png`, ...).
    pub fn is_old_pair_layout(&self) -> bool {
        *self.names == PAIR_NAMES
    }

    fn eye_file(&self, names: [&'static str; 2], eye: Eye) -> PathBuf {
        self.dir.join(names[eye_index(eye)])
    }

    /// The linear image with its layers (`im0.exr`).
    pub fn exr(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.exr, eye)
    }

    /// The 8-bit sRGB image (`im0.png`).
    pub fn png(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.png, eye)
    }

    /// The same image at 16 bits (`im0_16.png`), in datasets that keep it.
    pub fn png16(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.png16, eye)
    }

    /// The eye's image to measure: the EXR if it exists, else the PNG.
    pub fn image(&self, eye: Eye) -> PathBuf {
        let exr = self.exr(eye);
        if exr.exists() {
            exr
        } else {
            self.png(eye)
        }
    }

    /// Ground-truth disparity (`disp0.pfm`).
    pub fn disparity(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.disparity, eye)
    }

    /// Ground-truth depth (`depth0.pfm`).
    pub fn depth(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.depth, eye)
    }

    /// The renderer's streak mask (`streaks0.png`, 0/255).
    pub fn streak_mask(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.streak_mask, eye)
    }

    /// The pixels whose first hit is the road surface (`road0.png`, 0/255; written only when
    /// the scene flags a road material).
    pub fn road_mask(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.road_mask, eye)
    }

    /// The rain mask (`rain0.png`: 0 where no camera sample met a drop, 255 where all did;
    /// written only when the scene has rain).
    pub fn rain_mask(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.rain_mask, eye)
    }

    /// The fog's transmittance from the camera to each pixel's first hit (`fog0.pfm`, 1 = no
    /// fog, 0 on the sky through a homogeneous fog; written only when the scene has fog).
    pub fn fog(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.fog, eye)
    }

    /// The semantic map (`semantic0.png`, 8-bit label ids; see [`crate::segmentation`]).
    pub fn semantic(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.semantic, eye)
    }

    /// The instance map (`instance0.png`, 16-bit Cityscapes instance ids; see
    /// [`crate::segmentation`]).
    pub fn instance(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.instance, eye)
    }

    /// The occlusion mask (`occ0.png`, 0/255: 255 where the pixel's point is hidden from the
    /// other eye or outside its image; see [`streaks_stereo::occlusion`]).
    pub fn occlusion(&self, eye: Eye) -> PathBuf {
        self.eye_file(self.names.occlusion, eye)
    }

    /// `calib.txt`.
    pub fn calib(&self) -> PathBuf {
        self.dir.join(CALIB)
    }

    /// `meta.json`.
    pub fn meta(&self) -> PathBuf {
        self.dir.join(META)
    }

    /// `rig.json`.
    pub fn rig_json(&self) -> PathBuf {
        self.dir.join(RIG)
    }

    /// `anaglyph.png`.
    pub fn anaglyph(&self) -> PathBuf {
        self.dir.join(ANAGLYPH)
    }

    /// `side_by_side.png`.
    pub fn side_by_side(&self) -> PathBuf {
        self.dir.join(SIDE_BY_SIDE)
    }

    /// `scene.gltf`.
    pub fn scene(&self) -> PathBuf {
        self.dir.join(SCENE_GLTF)
    }

    /// The left view's flow as a KITTI flow PNG.
    pub fn flow_png(&self) -> PathBuf {
        self.dir.join(FLOW_PNG)
    }

    /// The left view's flow as a float PFM.
    pub fn flow_pfm(&self) -> PathBuf {
        self.dir.join(FLOW_PFM)
    }

    /// The left view's disparity change.
    pub fn disparity_change(&self) -> PathBuf {
        self.dir.join(DISPARITY_CHANGE)
    }

    /// The left view's flow mask.
    pub fn flow_mask(&self) -> PathBuf {
        self.dir.join(FLOW_MASK)
    }

    /// A file of the folder by its name (a name of this module).
    pub fn file(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Reads `meta.json`.
    pub fn load_meta(&self) -> Result<SampleMeta, DatasetError> {
        SampleMeta::load(&self.meta())
    }

    /// The rig and the scene's lights: from `rig.json` when the folder has one (a pair),
    /// else from `meta.json` (a dataset sample).
    pub fn rig(&self) -> Result<(Rig, Vec<LightRecord>), DatasetError> {
        let rig_json = self.rig_json();
        if rig_json.exists() {
            let file = RigFile::load(&rig_json)?;
            return Ok((file.rig()?, file.lights));
        }
        let meta = self.load_meta()?;
        let r = &meta.rig;
        let invalid = |e: streaks_stereo::error::StereoError| DatasetError::Invalid {
            path: self.meta(),
            reason: format!("its rig: {e}"),
        };
        let rig = Rig::new(
            Intrinsics::new(r.width, r.height, r.focal_px).map_err(invalid)?,
            r.baseline_m,
            r.world_from_rig.to_affine(),
        )
        .map_err(invalid)?;
        Ok((rig, meta.lights))
    }

    /// Reads `calib.txt`.
    pub fn load_calib(&self) -> Result<MiddleburyCalib, DatasetError> {
        Ok(MiddleburyCalib::load(&self.calib())?)
    }

    /// The first of `files` that is not a regular file in the folder, as an error.
    pub fn require(&self, files: &[PathBuf]) -> Result<(), DatasetError> {
        match files.iter().find(|p| !p.is_file()) {
            Some(p) => Err(DatasetError::Missing {
                dir: self.dir.clone(),
                file: p
                    .file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned(),
            }),
            None => Ok(()),
        }
    }
}

/// Reads the 0/255 (or 0/1) mask `path`, a sample's streak or road mask, and checks that it
/// has the `expected` size (width, height): a mask of another size would score the wrong
/// pixels. `against` names what gives that size in the error (`the ground truth`).
pub fn load_mask(
    path: &Path,
    expected: (usize, usize),
    against: &'static str,
) -> Result<GrayImage, DatasetError> {
    let mask = GrayImage::load(path)?;
    DatasetError::check_size(path, (mask.width, mask.height), expected, against)?;
    Ok(mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(p: PathBuf) -> String {
        p.file_name().unwrap().to_string_lossy().into_owned()
    }

    #[test]
    fn names_follow_the_sample_layout() {
        let dir = tempfile::tempdir().unwrap();
        let s = SampleDir::new(dir.path());
        assert_eq!(name(s.disparity(Eye::Left)), "disp0.pfm");
        assert_eq!(name(s.streak_mask(Eye::Right)), "streaks1.png");
        assert_eq!(name(s.road_mask(Eye::Left)), ROAD_MASK);
        assert_eq!(name(s.rig_json()), RIG);
        // The image to measure: the EXR when there is one.
        assert_eq!(name(s.image(Eye::Left)), "im0.png");
        std::fs::write(s.exr(Eye::Left), b"").unwrap();
        assert_eq!(name(s.image(Eye::Left)), "im0.exr");
        // Every name of SAMPLE_FILES is one of the layout's.
        for f in SAMPLE_FILES {
            assert!(
                [CALIB, META].contains(&f)
                    || [
                        SAMPLE_NAMES.exr,
                        SAMPLE_NAMES.png,
                        SAMPLE_NAMES.png16,
                        SAMPLE_NAMES.disparity,
                        SAMPLE_NAMES.depth,
                        SAMPLE_NAMES.streak_mask,
                        SAMPLE_NAMES.occlusion
                    ]
                    .iter()
                    .any(|n| n.contains(&f)),
                "{f}"
            );
        }
    }

    #[test]
    fn open_finds_the_layout_of_a_folder() {
        let dir = tempfile::tempdir().unwrap();
        let err = SampleDir::open(dir.path()).unwrap_err().to_string();
        assert!(err.contains("im0.png") && err.contains("left.png"), "{err}");
        for f in ["left.png", "right.png", "disparity_left.pfm"] {
            std::fs::write(dir.path().join(f), b"").unwrap();
        }
        let s = SampleDir::open(dir.path()).unwrap();
        assert!(s.is_old_pair_layout());
        assert_eq!(name(s.disparity(Eye::Left)), "disparity_left.pfm");
        assert_eq!(name(s.streak_mask(Eye::Left)), "streak_mask_left.png");
        assert!(SampleDir::is_pair(dir.path()));
        std::fs::write(dir.path().join("im0.exr"), b"").unwrap();
        let s = SampleDir::open(dir.path()).unwrap();
        assert!(!s.is_old_pair_layout());
        assert!(
            !SampleDir::is_pair(dir.path()),
            "no im0.png, im1.png, disp0.pfm"
        );
        let err = s.require(&[s.png(Eye::Left)]).unwrap_err().to_string();
        assert!(err.contains("lacks im0.png"), "{err}");
    }

    #[test]
    fn masks_of_another_size_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let s = SampleDir::new(dir.path());
        let path = s.streak_mask(Eye::Left);
        GrayImage::new(4, 3, 1.0).unwrap().save_png(&path).unwrap();
        let mask = load_mask(&path, (4, 3), "the ground truth").unwrap();
        assert_eq!((mask.width, mask.height), (4, 3));
        let err = load_mask(&path, (5, 3), "the ground truth")
            .unwrap_err()
            .to_string();
        assert!(
            err.ends_with("streaks0.png is 4x3, the ground truth 5x3"),
            "{err}"
        );
        let err = load_mask(&s.road_mask(Eye::Left), (4, 3), "the ground truth")
            .unwrap_err()
            .to_string();
        assert!(err.contains("road0.png"), "{err}");
    }
}
