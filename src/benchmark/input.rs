//! The samples of `streaks benchmark DIR`: a dataset (`streaks dataset generate`), one
//! `streaks stereo` pair folder, or a folder of pair folders.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use streaks_dataset::files::{SampleDir, PAIR_NAMES, SAMPLE_NAMES};
use streaks_dataset::layout::Layout;
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

/// The files of the sample folder `dir` (a dataset sample or a `streaks stereo` folder, in
/// either of its layouts, [`SampleDir::open`]); `rerun` says how to make the missing ones.
fn sample(id: String, dir: &Path, rerun: &str) -> Result<Sample> {
    let files = SampleDir::open(dir)?;
    let sample = Sample {
        id,
        left: files.png(Eye::Left),
        right: files.png(Eye::Right),
        truth: files.disparity(Eye::Left),
        streaks: files.streak_mask(Eye::Left),
        road: Some(files.road_mask(Eye::Left)).filter(|p| p.is_file()),
        dir: dir.to_path_buf(),
    };
    files
        .require(&[
            sample.left.clone(),
            sample.right.clone(),
            sample.truth.clone(),
            sample.streaks.clone(),
        ])
        .with_context(|| format!("{} is incomplete ({rerun})", dir.display()))?;
    Ok(sample)
}

/// How to make a pair folder's missing files.
const RENDER_AGAIN: &str = "render it again with `streaks stereo`";

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
    if SampleDir::is_pair(dir) {
        let id = dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "pair".into());
        return Ok((InputKind::Pair, vec![sample(id, dir, RENDER_AGAIN)?]));
    }
    let mut subs: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir() && SampleDir::is_pair(p))
        .collect();
    subs.sort();
    if subs.is_empty() {
        bail!(
            "{} is neither a dataset (no {}), nor a `streaks stereo` pair folder \
             (no {}, {} and {}, nor {}, {} and {}), nor a folder of pair folders",
            dir.display(),
            streaks_dataset::files::DATASET_JSON,
            SAMPLE_NAMES.png[0],
            SAMPLE_NAMES.png[1],
            SAMPLE_NAMES.disparity[0],
            PAIR_NAMES.png[0],
            PAIR_NAMES.png[1],
            PAIR_NAMES.disparity[0],
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
            sample(id, p, RENDER_AGAIN)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((InputKind::Pairs, samples))
}
