//! The samples of `streaks benchmark DIR`: a dataset (`streaks dataset generate`), one
//! `streaks stereo` pair folder, or a folder of pair folders.

use crate::dataset::layout::{Layout, ROAD_MASK};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use streaks_stereo::pair_dir::PairDir;
use streaks_stereo::rig::Eye;

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
    /// The left view's ground-truth disparity (PFM).
    pub truth: PathBuf,
    /// The renderer's streak mask of the left view (PNG, 0/255).
    pub streaks: PathBuf,
    /// The road-surface mask of the left view (PNG, 0/255), when the scene flagged a road.
    pub road: Option<PathBuf>,
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
}

/// A dataset sample's files (the dataset layout's names).
fn dataset_sample(id: &str, dir: PathBuf) -> Result<Sample> {
    let sample = Sample {
        id: id.to_string(),
        left: dir.join("im0.png"),
        right: dir.join("im1.png"),
        truth: dir.join("disp0.pfm"),
        streaks: dir.join("streaks0.png"),
        road: Some(dir.join(ROAD_MASK)).filter(|p| p.exists()),
        dir,
    };
    for p in [&sample.left, &sample.right, &sample.truth, &sample.streaks] {
        if !p.is_file() {
            bail!(
                "sample {} of the dataset lacks {} (run `streaks dataset index` on the dataset)",
                sample.dir.display(),
                p.file_name().unwrap_or_default().to_string_lossy()
            );
        }
    }
    Ok(sample)
}

/// Whether `dir` is a `streaks stereo` pair folder (its left and right PNGs and the left
/// ground truth).
fn is_pair(dir: &Path) -> bool {
    let p = PairDir::new(dir);
    p.png(Eye::Left).is_file() && p.png(Eye::Right).is_file() && p.disparity(Eye::Left).is_file()
}

/// A pair folder's files ([`PairDir`]'s names).
fn pair_sample(id: String, dir: &Path) -> Result<Sample> {
    let p = PairDir::new(dir);
    let streaks = p.streak_mask(Eye::Left);
    if !streaks.is_file() {
        bail!(
            "the pair folder {} lacks {} (render it again with `streaks stereo`)",
            dir.display(),
            streaks.file_name().unwrap_or_default().to_string_lossy()
        );
    }
    Ok(Sample {
        id,
        left: p.png(Eye::Left),
        right: p.png(Eye::Right),
        truth: p.disparity(Eye::Left),
        road: Some(p.road_mask(Eye::Left)).filter(|r| r.is_file()),
        streaks,
        dir: dir.to_path_buf(),
    })
}

/// The samples of `dir`, in order, restricted to `split` for a dataset (see the module
/// documentation). An error names the folder when it is none of the three.
pub fn samples(dir: &Path, split: Option<&str>) -> Result<(InputKind, Vec<Sample>)> {
    if !dir.is_dir() {
        bail!("{} is not a folder", dir.display());
    }
    let layout = Layout::new(dir);
    if layout.dataset_json().is_file() {
        let ids = layout.sample_ids(split)?;
        let samples = ids
            .iter()
            .map(|id| dataset_sample(id, layout.samples_dir().join(id)))
            .collect::<Result<Vec<_>>>()?;
        return Ok((InputKind::Dataset, samples));
    }
    if let Some(s) = split {
        bail!(
            "--split {s} needs a dataset, and {} has no dataset.json",
            dir.display()
        );
    }
    if is_pair(dir) {
        let id = dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "pair".into());
        return Ok((InputKind::Pair, vec![pair_sample(id, dir)?]));
    }
    let mut subs: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir() && is_pair(p))
        .collect();
    subs.sort();
    if subs.is_empty() {
        bail!(
            "{} is neither a dataset (no dataset.json), nor a `streaks stereo` pair folder \
             (no left.png, right.png and disparity_left.pfm), nor a folder of pair folders",
            dir.display()
        );
    }
    let samples = subs
        .iter()
        .map(|p| {
            let id = p
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            pair_sample(id, p)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((InputKind::Pairs, samples))
}
