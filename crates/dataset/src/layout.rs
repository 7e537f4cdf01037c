//! The dataset folder: where each file goes, `dataset.json` and the conventions it states.
//!
//! ```text
//! DIR/dataset.json                      settings, generator version, config, conventions
//! DIR/samples/NNNNNN/                   one sample (Middlebury style, see crate::files)
//! DIR/samples/.tmp-NNNNNN-PID/          a sample being rendered (renamed when complete)
//! DIR/samples/.lock-NNNNNN              its lock, while a run checks or renders it
//! DIR/.lock                             the dataset lock, while a run uses the folder
//! DIR/kitti/training/image_2/NNNNNN_10.png       = im0.png
//! DIR/kitti/training/image_3/NNNNNN_10.png       = im1.png
//! DIR/kitti/training/disp_occ_0/NNNNNN_10.png    disp0 as uint16 x 256, 0 = no value
//! DIR/kitti/training/disp_occ_1/NNNNNN_10.png    disp1 as uint16 x 256
//! DIR/kitti/training/disp_noc_0/NNNNNN_10.png    disp0, 0 where occ0.png says occluded
//! DIR/kitti/training/calib_cam_to_cam/NNNNNN.txt P_rect_02, P_rect_03 (KITTI's format)
//! DIR/manifest.jsonl                    one line per good sample (`streaks dataset index`)
//! DIR/splits/{train,val,test}.txt       sample ids, split by street
//! ```

use crate::error::DatasetError;
use crate::files::SampleDir;
use crate::files::{
    DATASET_JSON, KITTI_CALIB, KITTI_CALIB_EXTENSION, KITTI_DIR, KITTI_DISP_NOC_0,
    KITTI_DISP_OCC_0, KITTI_DISP_OCC_1, KITTI_IMAGE_2, KITTI_IMAGE_3, KITTI_INSTANCE,
    KITTI_SEMANTIC, KITTI_SUFFIX, LOCK, MANIFEST, ROAD_MASK, SAMPLES_DIR, SAMPLE_FILES,
    SAMPLE_LOCK_PREFIX, SCENEFLOW_DIR, SCENEFLOW_DISPARITY, SCENEFLOW_IMAGES, SCENEFLOW_OCCLUSION,
    SCENE_BIN, SCENE_GLTF, SPLITS_DIR, SPLIT_EXTENSION, TMP_PREFIX,
};
use crate::outputs::{Output, Outputs};
use crate::segmentation::ClassRecord;
use crate::settings::Settings;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The format of `dataset.json` and of the folder it describes.
pub const FORMAT: &str = "streaks-dataset/1";

/// Sample ids have six digits: at most this many samples.
pub const MAX_COUNT: u64 = 1_000_000;

/// The largest `dataset.json` read (the file holds the settings and the generator config).
pub const MAX_DATASET_JSON_BYTES: u64 = 16 << 20;

/// The splits, in the order of `splits/`.
pub const SPLITS: [&str; 3] = ["train", "val", "test"];

/// The id (folder name) of sample `index`: six digits.
pub fn sample_id(index: u64) -> String {
    format!("{index:06}")
}

/// The KITTI 2015 files of one sample.
#[derive(Clone, Debug)]
pub struct KittiFiles {
    /// `image_2/NNNNNN_10.png`: the left image.
    pub image_2: PathBuf,
    /// `image_3/NNNNNN_10.png`: the right image.
    pub image_3: PathBuf,
    /// `disp_occ_0/NNNNNN_10.png`: the left disparity, uint16 x 256.
    pub disp_occ_0: PathBuf,
    /// `disp_occ_1/NNNNNN_10.png`: the right view's disparity, uint16 x 256 (torchvision's
    /// `Kitti2015Stereo` reads it as the right disparity).
    pub disp_occ_1: PathBuf,
    /// `disp_noc_0/NNNNNN_10.png`: the left disparity where the right eye sees the point too
    /// (0 where `occ0.png` says occluded).
    pub disp_noc_0: PathBuf,
    /// `calib_cam_to_cam/NNNNNN.txt`: the rectified projection matrices `P_rect_02` and
    /// `P_rect_03` (the baseline is `(P_rect_02[0][3] - P_rect_03[0][3]) / P_rect_03[0][0]`).
    pub calib: PathBuf,
    /// `semantic/NNNNNN_10.png`: the left view's label ids (`semantic0.png`).
    pub semantic: PathBuf,
    /// `instance/NNNNNN_10.png`: the left view's instances as `labelId * 256 + k`.
    pub instance: PathBuf,
}

impl KittiFiles {
    /// The paths with their names relative to the dataset folder.
    pub fn named(&self, layout: &Layout) -> [(String, &Path); 8] {
        [
            &self.image_2,
            &self.image_3,
            &self.disp_occ_0,
            &self.disp_occ_1,
            &self.disp_noc_0,
            &self.calib,
            &self.semantic,
            &self.instance,
        ]
        .map(|p| (layout.relative(p), p.as_path()))
    }
}

/// The SceneFlow (FlyingThings3D) files of one sample (see [`crate::sceneflow`]), left then
/// right.
#[derive(Clone, Debug)]
pub struct SceneFlowFiles {
    /// `frames_cleanpass/.../left|right/NNNNNNN.png`: the images.
    pub images: [PathBuf; 2],
    /// `disparity/.../left|right/NNNNNNN.pfm`: the disparities.
    pub disparity: [PathBuf; 2],
    /// `disparity_occlusions/.../left|right/NNNNNNN.png`: the occlusion maps.
    pub occlusion: [PathBuf; 2],
}

impl SceneFlowFiles {
    /// The paths with their names relative to the dataset folder.
    pub fn named(&self, layout: &Layout) -> Vec<(String, &Path)> {
        [&self.images, &self.disparity, &self.occlusion]
            .into_iter()
            .flatten()
            .map(|p| (layout.relative(p), p.as_path()))
            .collect()
    }
}

/// The SceneFlow folders `SPLIT/L` of a dataset split (see [`crate::sceneflow`]).
fn sceneflow_split(split: &str) -> Option<[&'static str; 2]> {
    match split {
        "train" => Some(["TRAIN", "A"]),
        "val" => Some(["TEST", "B"]),
        "test" => Some(["TEST", "C"]),
        _ => None,
    }
}

/// The paths of a dataset folder.
#[derive(Clone, Debug)]
pub struct Layout {
    root: PathBuf,
}

impl Layout {
    /// The layout of the folder `root`.
    pub fn new(root: &Path) -> Self {
        Self {
            root: root.to_path_buf(),
        }
    }

    /// The dataset folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `dataset.json`.
    pub fn dataset_json(&self) -> PathBuf {
        self.root.join(DATASET_JSON)
    }

    /// `manifest.jsonl`.
    pub fn manifest(&self) -> PathBuf {
        self.root.join(MANIFEST)
    }

    /// Whether `manifest.jsonl` exists (as anything: a symbolic link or folder there is
    /// refused when it is read).
    pub fn manifest_present(&self) -> bool {
        std::fs::symlink_metadata(self.manifest()).is_ok()
    }

    /// `.lock`: the dataset lock (see [`crate::lock`]).
    pub fn lock(&self) -> PathBuf {
        self.root.join(LOCK)
    }

    /// `samples/.lock-NNNNNN`: the lock of sample `index` (see [`crate::lock`]).
    pub fn sample_lock(&self, index: u64) -> PathBuf {
        self.samples_dir()
            .join(format!("{SAMPLE_LOCK_PREFIX}{}", sample_id(index)))
    }

    /// `splits/`.
    pub fn splits_dir(&self) -> PathBuf {
        self.root.join(SPLITS_DIR)
    }

    /// `sequences/`: per street, the drive's `poses.txt` and `times.txt`.
    pub fn sequences_dir(&self) -> PathBuf {
        self.root.join(crate::files::SEQUENCES_DIR)
    }

    /// The sequence folder of street `street`: `sequences/SSSSSS/` (six digits, as sample
    /// ids).
    pub fn sequence_dir(&self, street: u64) -> PathBuf {
        self.sequences_dir().join(sample_id(street))
    }

    /// `samples/`.
    pub fn samples_dir(&self) -> PathBuf {
        self.root.join(SAMPLES_DIR)
    }

    /// `samples/NNNNNN/`.
    pub fn sample_dir(&self, index: u64) -> PathBuf {
        self.samples_dir().join(sample_id(index))
    }

    /// The files of `samples/NNNNNN/`.
    pub fn sample(&self, index: u64) -> SampleDir {
        SampleDir::new(self.sample_dir(index))
    }

    /// The files of the sample folder `samples/ID/`.
    pub fn sample_by_id(&self, id: &str) -> SampleDir {
        SampleDir::new(self.samples_dir().join(id))
    }

    /// The name prefix of sample `index`'s temporary folders: `.tmp-NNNNNN-`.
    pub fn tmp_prefix(index: u64) -> String {
        format!("{TMP_PREFIX}{}-", sample_id(index))
    }

    /// This process's temporary folder for sample `index`: `samples/.tmp-NNNNNN-PID/`.
    pub fn tmp_dir(&self, index: u64) -> PathBuf {
        self.samples_dir()
            .join(format!("{}{}", Self::tmp_prefix(index), std::process::id()))
    }

    /// Whether sample `index` is published and has all the files of the groups `outputs`
    /// (a cheap check: the files are there and `meta.json` names the index; `streaks dataset
    /// index` checks their contents).
    pub fn is_complete(&self, index: u64, outputs: &Outputs) -> bool {
        let sample = self.sample(index);
        let present = |name: &str| !outputs.keeps(name) || sample.file(name).is_file();
        if !SAMPLE_FILES.iter().all(|f| present(f)) || !present(SCENE_GLTF) {
            return false;
        }
        match sample.load_meta() {
            Ok(meta) => meta.index == index && (!meta.road_mask || present(ROAD_MASK)),
            Err(_) => false,
        }
    }

    /// Removes sample `index`'s temporary folders (`.tmp-NNNNNN-*`) and returns them. Call it
    /// only while holding the sample's lock ([`Layout::sample_lock`]): every run renders a
    /// sample under that lock, so then no live run owns such a folder and they are all stale.
    pub fn remove_stale_tmp(&self, index: u64) -> Result<Vec<PathBuf>, DatasetError> {
        let prefix = Self::tmp_prefix(index);
        let dir = self.samples_dir();
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return Ok(Vec::new());
        };
        let mut removed = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| DatasetError::io("list", &dir, e))?;
            if entry.file_name().to_string_lossy().starts_with(&prefix) {
                let path = entry.path();
                let is_dir = std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir());
                if is_dir {
                    std::fs::remove_dir_all(&path)
                } else {
                    std::fs::remove_file(&path)
                }
                .map_err(|e| DatasetError::io("remove the stale folder", &path, e))?;
                removed.push(path);
            }
        }
        Ok(removed)
    }

    /// The KITTI view's files of sample `index`.
    pub fn kitti(&self, index: u64) -> KittiFiles {
        let dir = self.root.join(KITTI_DIR[0]).join(KITTI_DIR[1]);
        let name = format!("{}{KITTI_SUFFIX}", sample_id(index));
        KittiFiles {
            image_2: dir.join(KITTI_IMAGE_2).join(&name),
            image_3: dir.join(KITTI_IMAGE_3).join(&name),
            disp_occ_0: dir.join(KITTI_DISP_OCC_0).join(&name),
            disp_occ_1: dir.join(KITTI_DISP_OCC_1).join(&name),
            disp_noc_0: dir.join(KITTI_DISP_NOC_0).join(&name),
            calib: dir
                .join(KITTI_CALIB)
                .join(format!("{}.{KITTI_CALIB_EXTENSION}", sample_id(index))),
            semantic: dir.join(KITTI_SEMANTIC).join(&name),
            instance: dir.join(KITTI_INSTANCE).join(&name),
        }
    }

    /// The SceneFlow view's files of sample `index` of split `split` and street `street`;
    /// `None` for a split that is not the dataset's.
    pub fn sceneflow(&self, index: u64, split: &str, street: u64) -> Option<SceneFlowFiles> {
        let [set, letter] = sceneflow_split(split)?;
        let root = self.root.join(SCENEFLOW_DIR[0]).join(SCENEFLOW_DIR[1]);
        let part = |kind: &str, eye: &str, ext: &str| {
            root.join(kind)
                .join(set)
                .join(letter)
                .join(format!("{street:04}"))
                .join(eye)
                .join(format!("{index:07}.{ext}"))
        };
        let eyes = |kind: &str, ext: &str| ["left", "right"].map(|e| part(kind, e, ext));
        Some(SceneFlowFiles {
            images: eyes(SCENEFLOW_IMAGES, "png"),
            disparity: eyes(SCENEFLOW_DISPARITY, "pfm"),
            occlusion: eyes(SCENEFLOW_OCCLUSION, "png"),
        })
    }

    /// The files of the dataset's views (KITTI and SceneFlow, those of `outputs`) of sample
    /// `index` of split `split` and street `street`, with their names relative to the dataset
    /// folder.
    pub fn view_files(
        &self,
        index: u64,
        split: &str,
        street: u64,
        outputs: &Outputs,
    ) -> Vec<(String, PathBuf)> {
        let mut out: Vec<(String, PathBuf)> = Vec::new();
        if outputs.has(Output::Kitti) {
            let kitti = self.kitti(index);
            out.extend(kitti.named(self).map(|(n, p)| (n, p.to_path_buf())));
        }
        if let Some(sf) = self
            .sceneflow(index, split, street)
            .filter(|_| outputs.has(Output::Sceneflow))
        {
            out.extend(
                sf.named(self)
                    .into_iter()
                    .map(|(n, p)| (n, p.to_path_buf())),
            );
        }
        out
    }

    /// The ids of the dataset's samples, sorted: with `split`, those that `streaks dataset
    /// index` listed in `splits/SPLIT.txt`; without, every complete sample folder (six digits;
    /// the `.tmp-` folders of samples in progress are left out). Fails on an unknown split, a
    /// missing split file, or no samples.
    pub fn sample_ids(&self, split: Option<&str>) -> Result<Vec<String>, DatasetError> {
        let mut ids: Vec<String> = match split {
            Some(name) => {
                if !SPLITS.contains(&name) {
                    return Err(DatasetError::UnknownSplit {
                        name: name.to_owned(),
                        known: SPLITS.join(", "),
                    });
                }
                let path = self.split_file(name);
                let text =
                    streaks_image::input::read_text(&path, streaks_image::input::MAX_TEXT_BYTES)
                        .map_err(|source| DatasetError::Split {
                            path: path.clone(),
                            root: self.root.clone(),
                            source,
                        })?;
                text.lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty())
                    .map(String::from)
                    .collect()
            }
            None => {
                let samples = self.samples_dir();
                std::fs::read_dir(&samples)
                    .map_err(|e| DatasetError::io("list", &samples, e))?
                    .filter_map(|e| e.ok())
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .filter(|n| n.len() == 6 && n.bytes().all(|b| b.is_ascii_digit()))
                    .collect()
            }
        };
        ids.sort();
        if ids.is_empty() {
            return Err(DatasetError::NoSamples {
                root: self.root.clone(),
                split: split.map(String::from),
            });
        }
        Ok(ids)
    }

    /// `splits/SPLIT.txt`: the ids of the split `name`.
    pub fn split_file(&self, name: &str) -> PathBuf {
        self.splits_dir().join(format!("{name}.{SPLIT_EXTENSION}"))
    }

    /// `path` relative to the dataset folder, with `/` separators (for the manifest).
    pub fn relative(&self, path: &Path) -> String {
        let rel = path.strip_prefix(&self.root).unwrap_or(path);
        rel.components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/")
    }
}

/// The conventions of the files, stated in `dataset.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Conventions {
    /// Coordinates of the world, the cameras and the pixels.
    pub coordinates: String,
    /// Disparity: sign, units, no value.
    pub disparity: String,
    /// Depth.
    pub depth: String,
    /// The PFM files.
    pub pfm: String,
    /// The images.
    pub images: String,
    /// The masks.
    pub masks: String,
    /// `calib.txt`.
    pub calib: String,
    /// The KITTI view.
    pub kitti: String,
    /// The SceneFlow view (empty in datasets written before it).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub sceneflow: String,
    /// The occlusion masks (empty in datasets written before them).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub occlusion: String,
    /// The flow, the disparity change and the poses of a drive (empty in a `dataset.json`
    /// written before they existed).
    #[serde(default)]
    pub flow: String,
    /// The splits.
    pub splits: String,
    /// Seeds.
    pub seeds: String,
    /// The segmentation maps (empty in datasets written before them).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub segmentation: String,
}

impl Conventions {
    /// This version's conventions.
    pub fn current() -> Self {
        let s = |t: &str| t.to_owned();
        Self {
            coordinates: s("world: glTF's (right-handed, +Y up, metres, road at Y = 0); cameras look along local -Z with +Y up; \
                 pixels: x right, y down, pixel (i, j) covers [i, i+1) x [j, j+1); the rig centre is the scene's camera, \
                 left eye at -b/2 and right eye at +b/2 along its +X, same orientation and intrinsics (rectified)"),
            disparity: s("pixels, d = x_left - x_right = f b / Z > 0 in front of the rig; disp0 is the left view's, \
                 disp1 the right view's (its match in the left view is at x + d); inf = no value (the pixel-centre ray hits nothing)"),
            depth: s("depth0.pfm: view-space depth Z in metres of the left view's pixel-centre first hit (along the camera's -Z), inf = none"),
            pfm: s("Middlebury/SceneFlow: greyscale 'Pf', scale -1 (little-endian), rows stored bottom to top, inf = no value"),
            images: s("im0/im1.png: 8-bit sRGB developed from the camera's raw values (the sensor layer) through the sensor's \
                 tone curve (docs/sensor.md) when meta.json has weather, else the linear render times 2^exposure_ev (meta.json), clipped; \
                 im0_16/im1_16.png (outputs images16): the same curve rounded to 16 bits; \
                 im0/im1.exr: linear float32 RGB (the exact render, no noise or glare) with the layers depth.Z, normal.X/Y/Z and \
                 specular.R/G/B, and sensor.R/G/B (raw DN), rain.Y and fog.Y when present"),
            masks: s("8-bit greyscale PNG, 0 or 255: streaks0.png the left view's streak pixels (specular layer threshold), \
                 road0.png the left pixels whose first hit is a road material (extras.streaks.road), absent when the scene flags none; \
                 rain0/rain1.png 0-255: the share of each pixel's camera samples that met a rain drop (present when it rains); \
                 fog0/fog1.pfm: the fog's transmittance from the camera to the pixel-centre ray's first hit (present with fog)"),
            calib: s("Middlebury 2014 calib.txt: cam0/cam1 = [f 0 cx; 0 f cy; 0 0 1] with the top-left pixel centre at (0, 0), \
                 doffs = 0, baseline in mm, ndisp a multiple of 16 above the largest disparity, vmin/vmax the finite disparity range"),
            kitti: s("KITTI 2015: image_2 = im0.png, image_3 = im1.png, disp_occ_0 = disp0 as uint16 PNG of round(256 d), 0 = no value \
                 (also disparities that do not fit in 1..65535), disp_occ_1 = disp1 likewise (the right view's, as torchvision reads it), \
                 disp_noc_0 = disp0 with 0 where occ0 says occluded; calib_cam_to_cam/NNNNNN.txt: S_rect_0x, R_rect_0x (identity), \
                 P_rect_02 = [f 0 cx 0; 0 f cy 0; 0 0 1 0] (the left eye, the reference) and P_rect_03 = [f 0 cx -f b; 0 f cy 0; 0 0 1 0], \
                 b in metres, numbers as C's %e"),
            sceneflow: s("SceneFlow/FlyingThings3D/{frames_cleanpass,disparity,disparity_occlusions}/SPLIT/L/SSSS/{left,right}/NNNNNNN: \
                 SPLIT/L = TRAIN/A (train), TEST/B (val), TEST/C (test), SSSS the street, NNNNNNN the sample index; images = im0/im1.png, \
                 disparity PFMs = disp0/disp1 (positive, 'Pf', rows bottom to top) with 0 on the sky (at infinity), \
                 disparity_occlusions = occ0/occ1.png"),
            occlusion: s("occ0/occ1.png, 0/255: 255 where the pixel's point (its pixel-centre ray's first hit) is not seen by the other eye: \
                 it falls outside the other image (x - d < 0 from the left, x + d >= W from the right) or both of the other eye's pixels \
                 whose centres bracket it see something nearer than its depth by more than 0.1 %; 0 elsewhere and on the sky"),
            flow: s("the left view's forward flow to the next frame of the street's drive (frame k at k / fps), of the surfaces                  (no rain, no blur): flow0.png KITTI 2015 flow_occ (16-bit RGB, u x 64 + 2^15, v x 64 + 2^15, valid = the point is in                  the next image, visible or occluded), flow0.pfm 'PF' (u, v, 0), inf where the point has no projection;                  dispchange0.pfm f b / Z' - f b / Z; flowmask0.png 255 visible, 128 occluded, 64 out of view, 0 no surface;                  sequences/SSSSSS/poses.txt KITTI odometry (the left camera in the first frame's left camera frame, x right,                  y down, z forward, 3x4 row by row), times.txt seconds"),
            splits: s("by street: every sample of one street is in the same split (splits/{train,val,test}.txt, sample ids)"),
            seeds: s("each sample is reproducible from (config, seed, index); its render seed is derived from (seed, index), \
                 the right eye uses render seed + 1"),
            segmentation: s("Cityscapes label convention, per eye: semantic0/semantic1.png 8-bit label ids (dataset.json classes) of the \
                 pixel-centre ray's first hit, sky on a miss, rain where drops cover at least half of the pixel's samples; \
                 instance0/instance1.png 16-bit: labelId for stuff and things without an instance, labelId * 1000 + k for an \
                 object's pixels (k: its index among the sample's objects of its class, ordered by instance id; meta.json \
                 instances maps (class, k) to the scene's extras.streaks.instance); under rain the instance map keeps the \
                 surface behind the drops. KITTI view: kitti/training/semantic = semantic0, kitti/training/instance = labelId * 256 + k"),
        }
    }
}

/// The files of a sample, as `dataset.json` lists them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FileList {
    /// In every sample folder.
    pub sample: Vec<String>,
    /// In a sample folder under a condition (file -> condition).
    pub optional: BTreeMap<String, String>,
    /// The scene's files in a sample folder.
    pub scene: Vec<String>,
    /// The sample's KITTI files (NNNNNN = the sample id).
    pub kitti: Vec<String>,
    /// The sample's SceneFlow files (empty in datasets written before the view existed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sceneflow: Vec<String>,
}

impl FileList {
    /// This version's files.
    pub fn current() -> Self {
        Self {
            sample: SAMPLE_FILES.map(String::from).to_vec(),
            optional: BTreeMap::from([
                (
                    ROAD_MASK.to_owned(),
                    "the scene flags a road material (meta.json road_mask)".to_owned(),
                ),
                (
                    "rain0.png, rain1.png".to_owned(),
                    "it rains (meta.json weather.rain_mm_h > 0)".to_owned(),
                ),
                (
                    "fog0.pfm, fog1.pfm".to_owned(),
                    "the scene has fog (meta.json weather.fog)".to_owned(),
                ),
                (
                    "semantic0.png, semantic1.png, instance0.png, instance1.png".to_owned(),
                    "the sample has segmentation maps (meta.json instances)".to_owned(),
                ),
                (
                    crate::files::FLOW_FILES.join(", "),
                    "the sample is a frame of a drive (meta.json sequence)".to_owned(),
                ),
            ]),
            scene: vec![
                SCENE_GLTF.to_owned(),
                SCENE_BIN.to_owned(),
                "scene_*.png (the textures scene.gltf refers to)".to_owned(),
            ],
            kitti: [
                KITTI_IMAGE_2,
                KITTI_IMAGE_3,
                KITTI_DISP_OCC_0,
                KITTI_DISP_OCC_1,
                KITTI_DISP_NOC_0,
                KITTI_SEMANTIC,
                KITTI_INSTANCE,
            ]
            .map(|d| format!("{}/{}/{d}/NNNNNN{KITTI_SUFFIX}", KITTI_DIR[0], KITTI_DIR[1]))
            .into_iter()
            .chain([format!(
                "{}/{}/{KITTI_CALIB}/NNNNNN.{KITTI_CALIB_EXTENSION}",
                KITTI_DIR[0], KITTI_DIR[1]
            )])
            .collect(),
            sceneflow: [
                (SCENEFLOW_IMAGES, "png"),
                (SCENEFLOW_DISPARITY, "pfm"),
                (SCENEFLOW_OCCLUSION, "png"),
            ]
            .into_iter()
            .flat_map(|(kind, ext)| {
                ["left", "right"].map(|eye| {
                    format!(
                        "{}/{}/{kind}/{{TRAIN/A,TEST/B,TEST/C}}/SSSS/{eye}/NNNNNNN.{ext}",
                        SCENEFLOW_DIR[0], SCENEFLOW_DIR[1]
                    )
                })
            })
            .collect(),
        }
    }

    /// The files of this list that a dataset keeping the groups `outputs` writes.
    pub fn kept(mut self, outputs: &Outputs) -> Self {
        self.sample.retain(|f| outputs.keeps(f));
        // An optional entry names its files `a, b`: one group each.
        self.optional
            .retain(|files, _| outputs.keeps(files.split(", ").next().unwrap_or(files)));
        for (group, list) in [
            (Output::Scene, &mut self.scene),
            (Output::Kitti, &mut self.kitti),
            (Output::Sceneflow, &mut self.sceneflow),
        ] {
            if !outputs.has(group) {
                list.clear();
            }
        }
        self
    }
}

/// The contents of `dataset.json`: everything that makes two runs the same dataset (nothing
/// that depends on the shard, the machine or the time, so every shard writes the same bytes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetInfo {
    /// [`FORMAT`].
    pub format: String,
    /// The procedural generator's version.
    pub generator_version: String,
    /// The generator config.
    pub config: Value,
    /// sha256 of the config's TOML.
    pub config_hash: String,
    /// Number of samples (indices `0..count`).
    pub count: u64,
    /// The dataset seed.
    pub seed: u64,
    /// How the samples are rendered (its fields are fields of `dataset.json` itself).
    #[serde(flatten)]
    pub settings: Settings,
    /// The files.
    pub files: FileList,
    /// The conventions.
    pub conventions: Conventions,
    /// The semantic classes of the segmentation maps (empty in datasets written before
    /// them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub classes: Vec<ClassRecord>,
}

impl DatasetInfo {
    /// Reads `dataset.json`.
    /// The file must be a regular file of at most [`MAX_DATASET_JSON_BYTES`] (a FIFO or a
    /// device is not opened) and its `count` in `1..=MAX_COUNT`, since commands loop over it.
    pub fn load(path: &Path) -> Result<Self, DatasetError> {
        let meta = std::fs::metadata(path).map_err(|e| DatasetError::io("read", path, e))?;
        let invalid = |reason: String| DatasetError::Invalid {
            path: path.to_path_buf(),
            reason,
        };
        if !meta.is_file() {
            return Err(invalid("not a regular file".into()));
        }
        if meta.len() > MAX_DATASET_JSON_BYTES {
            return Err(invalid(format!(
                "{} bytes, more than a dataset.json has ({MAX_DATASET_JSON_BYTES})",
                meta.len()
            )));
        }
        let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
            .map_err(|e| DatasetError::io("read", path, e))?;
        let info: Self = serde_json::from_str(&text).map_err(|source| DatasetError::Json {
            path: path.to_path_buf(),
            what: format!("a dataset.json of {FORMAT}"),
            source,
        })?;
        if info.count == 0 || info.count > MAX_COUNT {
            return Err(invalid(format!(
                "count {} is not in 1..={MAX_COUNT}",
                info.count
            )));
        }
        Ok(info)
    }

    /// The file's bytes (pretty JSON, a final newline).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut text = serde_json::to_string_pretty(self).expect("dataset.json serialises");
        text.push('\n');
        text.into_bytes()
    }

    /// Fails, naming the first field that differs, unless `existing` (the folder's
    /// `dataset.json` as JSON) describes the same dataset as `self`. A `dataset.json` without
    /// `regularize` (written before the field existed) describes a dataset rendered without
    /// path regularisation: it matches a run with `--no-regularize`, and the message for any
    /// other run says so. Likewise one without `noise_target` was rendered at fixed spp: it
    /// matches a run with `--noise-target off`.
    pub fn check_same(&self, existing: &Value, path: &Path) -> Result<(), DatasetError> {
        let mut existing = existing.clone();
        let (mut unrecorded, mut target_unrecorded) = (false, false);
        if let Value::Object(map) = &mut existing {
            // Before denoising existed: not denoised.
            for key in ["denoise", "keep_raw"] {
                map.entry(key).or_insert(Value::Bool(false));
            }
            // Before --outputs existed: every group.
            map.entry("outputs").or_insert_with(|| {
                serde_json::to_value(crate::outputs::Outputs::default()).expect("outputs serialise")
            });
            if !map.contains_key("regularize") {
                map.insert("regularize".into(), Value::Bool(false));
                unrecorded = true;
            }
            if !map.contains_key("noise_target") {
                map.insert("noise_target".into(), Value::Null);
                target_unrecorded = true;
            }
        }
        // The value of the bytes this run would write (a value made from `self` directly would
        // hold `noise_target` widened from f32, 0.10000000149011612 for the file's 0.1).
        let new = serde_json::from_slice(&self.to_bytes()).expect("dataset.json reads back");
        // The groups first: they also change the file list, whose difference says less.
        let null = Value::Null;
        let outputs = |v: &Value| v.get("outputs").unwrap_or(&null).clone();
        let differs = first_difference("outputs", &outputs(&existing), &outputs(&new))
            .or_else(|| first_difference("", &existing, &new));
        if let Some((field, old, new)) = differs {
            let hint = match field.as_str() {
                "regularize" if unrecorded => {
                    " (it predates the setting and was rendered without path regularisation: \
                     add --no-regularize to continue it)"
                }
                "regularize" if self.settings.render.regularize => {
                    " (add --no-regularize to continue it)"
                }
                "regularize" => " (drop --no-regularize to continue it)",
                "noise_target" if target_unrecorded => {
                    " (it predates the setting and was rendered at fixed spp: add \
                     --noise-target off to continue it)"
                }
                "noise_target" => " (give its --noise-target to continue it)",
                "denoise" if self.settings.denoise => " (add --denoise off to continue it)",
                "denoise" => {
                    " (it was denoised: add --denoise on, with Intel Open Image Denoise \
                     installed, to continue it)"
                }
                "keep_raw" if self.settings.keep_raw => " (drop --keep-raw to continue it)",
                "keep_raw" => " (add --keep-raw to continue it)",
                "outputs" => {
                    " (give --outputs the groups its dataset.json lists under outputs to \
                     continue it)"
                }
                f if f == "format" || f.starts_with("conventions") || f.starts_with("files") => {
                    " (it was written by another version of streaks, whose files differ: \
                     continue it with that version, or write this run into a new folder)"
                }
                _ => "",
            };
            return Err(DatasetError::OtherDataset {
                path: path.to_path_buf(),
                field,
                old,
                new,
                hint,
            });
        }
        Ok(())
    }
}

/// The first path (`a.b.c`) at which two JSON values differ, with both values.
fn first_difference(at: &str, old: &Value, new: &Value) -> Option<(String, String, String)> {
    let join = |key: &str| {
        if at.is_empty() {
            key.to_owned()
        } else {
            format!("{at}.{key}")
        }
    };
    match (old, new) {
        (Value::Object(a), Value::Object(b)) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
            keys.sort();
            keys.dedup();
            let null = Value::Null;
            keys.into_iter().find_map(|k| {
                first_difference(
                    &join(k),
                    a.get(k).unwrap_or(&null),
                    b.get(k).unwrap_or(&null),
                )
            })
        }
        (a, b) if a == b => None,
        (a, b) => Some((
            if at.is_empty() {
                "content".into()
            } else {
                at.to_owned()
            },
            short(a),
            short(b),
        )),
    }
}

/// A JSON value for a message, cut to 80 characters.
fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 80 {
        format!("{}...", s.chars().take(77).collect::<String>())
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;
    use streaks_settings::RenderSettings;

    #[test]
    fn differences_are_named_by_path() {
        let a = json!({"count": 3, "config": {"street": {"lanes": [1, 2]}}, "seed": 0});
        let b = json!({"count": 3, "config": {"street": {"lanes": [1, 3]}}, "seed": 0});
        let (field, old, new) = first_difference("", &a, &b).unwrap();
        assert_eq!(
            (field.as_str(), old.as_str(), new.as_str()),
            ("config.street.lanes", "[1,2]", "[1,3]")
        );
        assert!(first_difference("", &a, &a).is_none());
        let c = json!({"count": 3, "config": {"street": {"lanes": [1, 2]}}});
        assert_eq!(first_difference("", &a, &c).unwrap().0, "seed");
    }

    fn info(regularize: bool) -> DatasetInfo {
        DatasetInfo {
            format: FORMAT.into(),
            generator_version: "g".into(),
            config: json!({"a": 1}),
            config_hash: "h".into(),
            count: 2,
            seed: 0,
            settings: Settings {
                width: 64,
                height: 40,
                render: RenderSettings {
                    regularize,
                    ..RenderSettings::new(2, 8)
                },
                denoise: false,
                keep_raw: false,
                outputs: Default::default(),
            },
            files: FileList::current(),
            conventions: Conventions::current(),
            classes: Vec::new(),
        }
    }

    /// A dataset.json from before `regularize` existed reads as rendered without it: it is
    /// continued with --no-regularize, and refused otherwise with a message that says so.
    #[test]
    fn datasets_without_the_regularize_field_are_unregularised() {
        let path = Path::new("d/dataset.json");
        let mut old = serde_json::to_value(info(false)).unwrap();
        old.as_object_mut().unwrap().remove("regularize");
        let back: DatasetInfo = serde_json::from_value(old.clone()).unwrap();
        assert_eq!(back, info(false));
        info(false).check_same(&old, path).unwrap();
        let err = info(true).check_same(&old, path).unwrap_err().to_string();
        assert!(
            err.contains("its regularize is false, this run's is true")
                && err.contains("predates the setting")
                && err.contains("--no-regularize"),
            "{err}"
        );
        let new = serde_json::to_value(info(true)).unwrap();
        info(true).check_same(&new, path).unwrap();
        let err = info(false).check_same(&new, path).unwrap_err().to_string();
        assert!(err.contains("drop --no-regularize"), "{err}");
    }

    /// A dataset.json from before `noise_target` existed reads as rendered at fixed spp: it
    /// is continued with --noise-target off, and refused otherwise with a message that says
    /// so; a recorded target must be given again.
    #[test]
    fn datasets_without_the_noise_target_field_are_fixed_spp() {
        let path = Path::new("d/dataset.json");
        let mut old = serde_json::to_value(info(true)).unwrap();
        old.as_object_mut().unwrap().remove("noise_target");
        let back: DatasetInfo = serde_json::from_value(old.clone()).unwrap();
        assert_eq!(back.settings.render.noise_target, None);
        info(true).check_same(&old, path).unwrap();
        let mut adaptive = info(true);
        adaptive.settings.render.noise_target = Some(0.1);
        let err = adaptive.check_same(&old, path).unwrap_err().to_string();
        assert!(
            err.contains("its noise_target is null, this run's is 0.1")
                && err.contains("predates the setting")
                && err.contains("--noise-target off"),
            "{err}"
        );
        let new: Value = serde_json::from_slice(&adaptive.to_bytes()).unwrap();
        assert_eq!(new["noise_target"], serde_json::json!(0.1));
        adaptive.check_same(&new, path).unwrap();
        let err = info(true).check_same(&new, path).unwrap_err().to_string();
        assert!(err.contains("give its --noise-target"), "{err}");
    }

    /// A dataset.json of another version's files (its file list or conventions differ) is
    /// refused with a message that says so.
    #[test]
    fn datasets_of_another_version_are_named_so() {
        let path = Path::new("d/dataset.json");
        let mut old = serde_json::to_value(info(true)).unwrap();
        old["conventions"]["kitti"] = Value::String("KITTI 2015: image_2 only".into());
        let err = info(true).check_same(&old, path).unwrap_err().to_string();
        assert!(
            err.contains("its conventions.kitti is") && err.contains("another version of streaks"),
            "{err}"
        );
        let mut old = serde_json::to_value(info(true)).unwrap();
        old["files"]["sample"] = serde_json::json!(["im0.png"]);
        let err = info(true).check_same(&old, path).unwrap_err().to_string();
        assert!(err.contains("another version of streaks"), "{err}");
    }

    #[test]
    fn paths_follow_the_layout() {
        let l = Layout::new(Path::new("/d"));
        assert_eq!(l.sample_dir(7), Path::new("/d/samples/000007"));
        assert_eq!(Layout::tmp_prefix(12), ".tmp-000012-");
        let k = l.kitti(3);
        assert_eq!(
            k.named(&l).map(|(n, _)| n),
            [
                "kitti/training/image_2/000003_10.png",
                "kitti/training/image_3/000003_10.png",
                "kitti/training/disp_occ_0/000003_10.png",
                "kitti/training/disp_occ_1/000003_10.png",
                "kitti/training/disp_noc_0/000003_10.png",
                "kitti/training/calib_cam_to_cam/000003.txt",
                "kitti/training/semantic/000003_10.png",
                "kitti/training/instance/000003_10.png"
            ]
        );
    }
}
