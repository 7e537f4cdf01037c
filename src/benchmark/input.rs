//! The samples of `streaks benchmark DIR`: a dataset (`streaks dataset generate`), one
//! `streaks stereo` pair folder, a folder of pair folders, or a public benchmark's folder as a
//! user downloads it:
//!
//! - KITTI 2015: `DIR/training/` (or `DIR` itself) with `image_2/NNNNNN_10.png`,
//!   `image_3/NNNNNN_10.png` and the ground truth `disp_occ_0/NNNNNN_10.png` (uint16 x 256),
//!   and `disp_noc_0/NNNNNN_10.png` where present (its valid pixels are the non-occluded
//!   ones). A sample is an `image_2` file with its `disp_occ_0`; its id is the file's stem,
//!   `NNNNNN_10`. The second frames (`_11`) have no disparity and are not samples.
//! - Middlebury 2014 (and MiddEval3): a scene folder, or a folder of scene folders, with
//!   `im0.png`, `im1.png`, the ground truth `disp0GT.pfm` (MiddEval3) or `disp0.pfm` (the 2014
//!   scenes), and `mask0nocc.png` where present (255: non-occluded). A scene's id is its
//!   folder's name. `calib.txt` is not needed: the disparities compare as they are. A folder
//!   with `rig.json` or `meta.json` is a `streaks` pair or sample, never a Middlebury scene.
//!
//! Such folders have no streak or road masks: the regions that need them are not available
//! ([`streaks_analysis::benchmark::Masks`]).

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use streaks_analysis::benchmark::Masks;
use streaks_dataset::files::{
    load_mask, SampleDir, KITTI_DISP_OCC_0, KITTI_IMAGE_2, KITTI_IMAGE_3, KITTI_SUFFIX, META,
    PAIR_NAMES, RIG, SAMPLE_NAMES,
};
use streaks_dataset::layout::Layout;
use streaks_dataset::meta::{Condition, PresetNoise, SampleMeta};
use streaks_image::pfm::read_pfm;
use streaks_image::GrayImage;
use streaks_stereo::rig::Eye;

/// KITTI 2015's non-occluded ground truth folder, beside `disp_occ_0`.
const KITTI_DISP_NOC_0: &str = "disp_noc_0";
/// KITTI 2015's training folder.
const KITTI_TRAINING: &str = "training";
/// A Middlebury scene's ground truth in MiddEval3, preferred to [`MIDDLEBURY_DISP`].
const MIDDLEBURY_DISP_GT: &str = "disp0GT.pfm";
/// A Middlebury 2014 scene's ground truth.
const MIDDLEBURY_DISP: &str = "disp0.pfm";
/// A Middlebury scene's non-occlusion mask (255: the right view sees the pixel).
const MIDDLEBURY_NOCC: &str = "mask0nocc.png";
/// The grey level above which a Middlebury mask pixel is non-occluded (255, not 128 or 0).
const MIDDLEBURY_NOCC_LEVEL: f32 = 0.75;

/// How a sample marks the pixels the right view also sees.
#[derive(Clone, Debug)]
pub enum Occlusion {
    /// KITTI's `disp_noc_0`: a disparity map whose valid pixels are the non-occluded ones.
    KittiNoc(PathBuf),
    /// Middlebury's `mask0nocc.png`: 255 non-occluded, 128 occluded, 0 no truth.
    MiddleburyMask(PathBuf),
}

/// The masks of one sample as read, owned ([`Sample::masks`]).
pub struct SampleMasks {
    /// The streak mask.
    pub streaks: Option<GrayImage>,
    /// The road mask.
    pub road: Option<GrayImage>,
    /// The non-occluded pixels (1) and the others (0).
    pub non_occluded: Option<GrayImage>,
}

impl SampleMasks {
    /// The masks as the scorer takes them.
    pub fn as_masks(&self) -> Masks<'_> {
        Masks {
            streaks: self.streaks.as_ref(),
            road: self.road.as_ref(),
            non_occluded: self.non_occluded.as_ref(),
        }
    }
}

/// The sensor preset `name`'s shutter time and whether it has noise, for a sample's noise
/// condition (`None` for a preset this version does not know).
fn preset_noise(name: &str) -> Option<PresetNoise> {
    let p = streaks_sensor::SensorProfile::preset(name).ok()?;
    Some(PresetNoise {
        exposure_s: p.exposure_s,
        noisy: p.shot_noise || p.read_noise_e > 0.0,
    })
}

/// The files of one sample to benchmark on.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Its name in the report: the dataset's sample id, or the pair folder's name.
    pub id: String,
    /// Its folder.
    pub dir: PathBuf,
    /// The left image (8-bit sRGB PNG).
    pub left: PathBuf,
    /// The right image.
    pub right: PathBuf,
    /// The left view's ground-truth disparity (PFM, or KITTI's uint16 PNG: read by
    /// extension, [`super::maps::read_disparity`]).
    pub truth: PathBuf,
    /// The renderer's streak mask of the left view (PNG, 0/255); `None` for KITTI and
    /// Middlebury data.
    pub streaks: Option<PathBuf>,
    /// The road-surface mask of the left view (PNG, 0/255), when the scene flagged a road.
    pub road: Option<PathBuf>,
    /// The non-occluded pixels, when the data marks them.
    pub occlusion: Option<Occlusion>,
    /// The left view's ground-truth depth (PFM, metres), when the sample has one (dataset
    /// samples and pair folders; not KITTI or Middlebury data).
    pub depth: Option<PathBuf>,
    /// Its `meta.json`, when it has one (dataset samples): its conditions.
    pub meta: Option<PathBuf>,
}

impl Sample {
    /// Its ground truth, with every value that is not finite or not positive made `inf` (no
    /// value): KITTI writes 0 there.
    pub fn read_truth(&self) -> Result<GrayImage> {
        let mut truth = super::maps::read_disparity(&self.truth)
            .with_context(|| format!("reading the ground truth {}", self.truth.display()))?;
        streaks_analysis::benchmark::method::no_value_below_zero(&mut truth);
        Ok(truth)
    }

    /// Its ground-truth depth, metres, checked to have the ground truth's `size` (`None`
    /// without one).
    pub fn read_depth(&self, size: (usize, usize)) -> Result<Option<GrayImage>> {
        let Some(path) = &self.depth else {
            return Ok(None);
        };
        let depth =
            read_pfm(path).with_context(|| format!("reading the depth {}", path.display()))?;
        streaks_image::ensure_same_size("the depth", depth.size(), "the ground truth", size)
            .with_context(|| format!("the depth {}", path.display()))?;
        Ok(Some(depth))
    }

    /// The conditions it was rendered in, from its `meta.json`
    /// ([`SampleMeta::conditions`]); `None` without one.
    pub fn conditions(&self) -> Result<Option<Vec<Condition>>> {
        let Some(path) = &self.meta else {
            return Ok(None);
        };
        Ok(Some(SampleMeta::load(path)?.conditions(preset_noise)))
    }

    /// Its masks, each checked to have the ground truth's `size`.
    pub fn masks(&self, size: (usize, usize)) -> Result<SampleMasks> {
        let against = "the ground truth";
        let mask = |p: &Option<PathBuf>| -> Result<Option<GrayImage>> {
            Ok(match p {
                Some(p) => Some(load_mask(p, size, against)?),
                None => None,
            })
        };
        let non_occluded = match &self.occlusion {
            None => None,
            Some(Occlusion::KittiNoc(p)) => {
                let mut m = super::maps::read_disparity(p)
                    .with_context(|| format!("reading {}", p.display()))?;
                for v in &mut m.data {
                    *v = f32::from(u8::from(v.is_finite() && *v > 0.0));
                }
                Some(m)
            }
            Some(Occlusion::MiddleburyMask(p)) => {
                let mut m = load_mask(p, size, against)?;
                for v in &mut m.data {
                    *v = f32::from(u8::from(*v > MIDDLEBURY_NOCC_LEVEL));
                }
                Some(m)
            }
        };
        if let Some(m) = &non_occluded {
            if (m.width, m.height) != size {
                bail!(
                    "the occlusion mask of sample {} is {}x{}, the ground truth {}x{}",
                    self.id,
                    m.width,
                    m.height,
                    size.0,
                    size.1
                );
            }
        }
        Ok(SampleMasks {
            streaks: mask(&self.streaks)?,
            road: mask(&self.road)?,
            non_occluded,
        })
    }
}

/// What `DIR` was.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputKind {
    /// A dataset folder (`dataset.json`).
    Dataset,
    /// One pair folder.
    Pair,
    /// A folder of pair folders.
    Pairs,
    /// A folder in the KITTI 2015 layout.
    Kitti,
    /// A Middlebury 2014 scene folder, or a folder of them.
    Middlebury,
}

/// The files of the sample folder `dir` (a dataset sample or a `streaks stereo` folder, in
/// either of its layouts, [`SampleDir::open`]); `rerun` says how to make the missing ones.
fn sample(id: String, dir: &Path, rerun: &str) -> Result<Sample> {
    let files = SampleDir::open(dir)?;
    let sample = Sample {
        id,
        left: files.png(Eye::Left),
        right: files.png(Eye::Right),
        truth: files.disparity(Eye::Left),
        streaks: Some(files.streak_mask(Eye::Left)),
        road: Some(files.road_mask(Eye::Left)).filter(|p| p.is_file()),
        occlusion: None,
        depth: Some(files.depth(Eye::Left)).filter(|p| p.is_file()),
        meta: Some(files.meta()).filter(|p| p.is_file()),
        dir: dir.to_path_buf(),
    };
    files
        .require(&[
            sample.left.clone(),
            sample.right.clone(),
            sample.truth.clone(),
            files.streak_mask(Eye::Left),
        ])
        .with_context(|| format!("{} is incomplete ({rerun})", dir.display()))?;
    Ok(sample)
}

/// How to make a pair folder's missing files.
const RENDER_AGAIN: &str = "render it again with `streaks stereo`";

/// The folder's name, for a sample id.
fn folder_name(dir: &Path) -> String {
    dir.canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "pair".into())
}

/// The ground truth of the Middlebury scene `dir` when it is one (see the module
/// documentation): `disp0GT.pfm`, else `disp0.pfm`, beside `im0.png` and `im1.png`, in a
/// folder that is not a `streaks` pair or sample.
fn middlebury_truth(dir: &Path) -> Option<PathBuf> {
    let has = |name: &str| dir.join(name).is_file();
    if !SAMPLE_NAMES.png.iter().all(|f| has(f)) || has(RIG) || has(META) {
        return None;
    }
    [MIDDLEBURY_DISP_GT, MIDDLEBURY_DISP]
        .into_iter()
        .find(|f| has(f))
        .map(|f| dir.join(f))
}

/// The Middlebury scene `dir` with its ground truth `truth`.
fn middlebury_sample(dir: &Path, truth: PathBuf) -> Sample {
    let nocc = dir.join(MIDDLEBURY_NOCC);
    Sample {
        id: folder_name(dir),
        left: dir.join(SAMPLE_NAMES.png[0]),
        right: dir.join(SAMPLE_NAMES.png[1]),
        truth,
        streaks: None,
        road: None,
        occlusion: nocc.is_file().then_some(Occlusion::MiddleburyMask(nocc)),
        depth: None,
        meta: None,
        dir: dir.to_path_buf(),
    }
}

/// The KITTI 2015 folder holding `image_2` in `dir`: `dir/training` or `dir` itself.
fn kitti_root(dir: &Path) -> Option<PathBuf> {
    [dir.join(KITTI_TRAINING), dir.to_path_buf()]
        .into_iter()
        .find(|d| d.join(KITTI_IMAGE_2).is_dir() && d.join(KITTI_DISP_OCC_0).is_dir())
}

/// The samples of the KITTI 2015 folder `root` (see the module documentation).
fn kitti_samples(root: &Path) -> Result<Vec<Sample>> {
    let images = root.join(KITTI_IMAGE_2);
    let mut names: Vec<String> = std::fs::read_dir(&images)
        .with_context(|| format!("cannot list {}", images.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(KITTI_SUFFIX) && root.join(KITTI_DISP_OCC_0).join(n).is_file())
        .collect();
    names.sort();
    if names.is_empty() {
        bail!(
            "{} is a KITTI 2015 folder without samples: no {KITTI_IMAGE_2}/*{KITTI_SUFFIX} has              a ground truth {KITTI_DISP_OCC_0}/ of the same name (the testing folder has none)",
            root.display()
        );
    }
    names
        .into_iter()
        .map(|name| {
            let right = root.join(KITTI_IMAGE_3).join(&name);
            if !right.is_file() {
                bail!(
                    "{} has no right image {} for {KITTI_IMAGE_2}/{name}",
                    root.display(),
                    right.display()
                );
            }
            let noc = root.join(KITTI_DISP_NOC_0).join(&name);
            Ok(Sample {
                id: name.trim_end_matches(".png").to_string(),
                dir: root.to_path_buf(),
                left: images.join(&name),
                right,
                truth: root.join(KITTI_DISP_OCC_0).join(&name),
                streaks: None,
                road: None,
                occlusion: noc.is_file().then_some(Occlusion::KittiNoc(noc)),
                depth: None,
                meta: None,
            })
        })
        .collect()
}

/// The samples of `dir`, in order, restricted to `split` for a dataset (see the module
/// documentation). An error names the folder and what it lacks when it is none of them.
pub fn samples(dir: &Path, split: Option<&str>) -> Result<(InputKind, Vec<Sample>)> {
    if !dir.is_dir() {
        bail!("{} is not a folder", dir.display());
    }
    let layout = Layout::new(dir);
    if layout.dataset_json().is_file() {
        let ids = layout.sample_ids(split)?;
        let samples = ids
            .iter()
            .map(|id| {
                sample(
                    id.clone(),
                    layout.sample_by_id(id).path(),
                    "run `streaks dataset index` on the dataset",
                )
            })
            .collect::<Result<Vec<_>>>()?;
        return Ok((InputKind::Dataset, samples));
    }
    if let Some(s) = split {
        bail!(
            "--split {s} needs a dataset, and {} has no dataset.json",
            dir.display()
        );
    }
    if let Some(root) = kitti_root(dir) {
        return Ok((InputKind::Kitti, kitti_samples(&root)?));
    }
    if let Some(truth) = middlebury_truth(dir) {
        return Ok((InputKind::Middlebury, vec![middlebury_sample(dir, truth)]));
    }
    if SampleDir::is_pair(dir) {
        return Ok((
            InputKind::Pair,
            vec![sample(folder_name(dir), dir, RENDER_AGAIN)?],
        ));
    }
    let mut subs: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    subs.sort();
    let mut samples = Vec::new();
    let mut all_middlebury = true;
    for p in &subs {
        let id = p
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        if let Some(truth) = middlebury_truth(p) {
            samples.push(middlebury_sample(p, truth));
        } else if SampleDir::is_pair(p) {
            all_middlebury = false;
            samples.push(sample(id, p, RENDER_AGAIN)?);
        }
    }
    if samples.is_empty() {
        bail!(
            "{} is none of the folders `streaks benchmark` reads: not a dataset (no {}), not a \
             `streaks stereo` pair folder (no {}, {} and {}, nor {}, {} and {}), not a KITTI \
             2015 folder (no {KITTI_TRAINING}/{KITTI_IMAGE_2}/ and {KITTI_DISP_OCC_0}/), not a \
             Middlebury 2014 scene (no {}, {} and {MIDDLEBURY_DISP_GT} or {MIDDLEBURY_DISP}), \
             and no subfolder is a pair folder or a Middlebury scene",
            dir.display(),
            streaks_dataset::files::DATASET_JSON,
            SAMPLE_NAMES.png[0],
            SAMPLE_NAMES.png[1],
            SAMPLE_NAMES.disparity[0],
            PAIR_NAMES.png[0],
            PAIR_NAMES.png[1],
            PAIR_NAMES.disparity[0],
            SAMPLE_NAMES.png[0],
            SAMPLE_NAMES.png[1],
        );
    }
    let kind = if all_middlebury {
        InputKind::Middlebury
    } else {
        InputKind::Pairs
    };
    Ok((kind, samples))
}
