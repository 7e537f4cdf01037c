//! Checking a dataset folder: every sample on disk against the dataset's conventions
//! ([`check_sample`], [`index_dir`]), or every file against `manifest.jsonl` ([`verify`]).
//!
//! A sample is good when its folder has every file ([`SAMPLE_FILES`], the road mask when its
//! meta says so, the segmentation maps when its meta has `instances`, and the files its
//! `scene.gltf` refers to), only regular files, its images, EXRs and PFMs decode at the
//! dataset's size, its segmentation maps hold only ids of `dataset.json`'s class table, its `calib.txt` parses with that size, and its
//! `meta.json` parses and names its index, the dataset's seed and configuration. Missing
//! KITTI files of a good sample are written again from it when the caller allows.
//!
//! [`index_dir`] checks every sample and writes `manifest.jsonl` and `splits/` of the good
//! ones; [`verify`] hashes every file the manifest lists and compares it with the manifest's
//! sha256, and also finds the files of a sample the manifest does not list, samples missing
//! from it, folders of `samples/` that are no sample, and split lists that disagree with it;
//! it writes nothing.
//!
//! `manifest.jsonl`: one JSON object per line ([`ManifestLine`]), in index order, with `id`,
//! `index`, `street`, `split`, `seed`, `render_seed`, `files` (path relative to the dataset
//! folder -> sha256 of every file of the sample folder and of its KITTI files) and `stats`
//! (from `meta.json`).
//!
//! The functions report and count; printing, progress bars and the decision to fail are the
//! command's.

use crate::error::DatasetError;
use crate::files::{
    SampleDir, FLOW_FILES, FLOW_MASK, POSES, SAMPLES_DIR, SAMPLE_FILES, SAMPLE_LOCK_PREFIX,
    SCENE_GLTF, TIMES, TMP_PREFIX,
};
use crate::kitti::write_kitti;
use crate::layout::{sample_id, DatasetInfo, Layout, SPLITS};
use crate::manifest::{sha256_hex, verify_batch, Difference, Entry, Lines};
use crate::meta::{SampleMeta, SampleStats};
use crate::outputs::{Output, Outputs};
use crate::sceneflow::write_sceneflow;
use crate::segmentation::{check_instance, check_semantic};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use streaks_image::exr::read_exr_rgb;
use streaks_image::kitti::{read_kitti_disparity, read_kitti_flow};
use streaks_image::pfm::{read_pfm, read_pfm_rgb};
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::flow::FlowState;
use streaks_stereo::rig::Eye;

/// The largest `scene.gltf` read to find the files it refers to: the renderer's limit on a
/// scene file (`streaks_render::scene::LoadOptions::max_file_bytes`), so that a sample is
/// refused here exactly when its scene could not be loaded.
pub const MAX_SCENE_BYTES: u64 = 4 << 30;

/// Samples hashed per batch by [`verify`]: enough to keep every core busy, few enough that
/// memory stays small whatever the manifest's size.
const VERIFY_BATCH: usize = 1024;

/// One line of `manifest.jsonl`.
#[derive(Clone, Debug, Serialize)]
pub struct ManifestLine {
    /// The sample id.
    pub id: String,
    /// The sample index.
    pub index: u64,
    /// The street it belongs to.
    pub street: u64,
    /// Its split.
    pub split: String,
    /// The dataset seed.
    pub seed: u64,
    /// The render seed of the left eye.
    pub render_seed: u32,
    /// sha256 of each file, by path relative to the dataset folder.
    pub files: BTreeMap<String, String>,
    /// The sample's statistics.
    pub stats: SampleStats,
    /// Its frame and time in its street's drive and its KITTI pose line, for the street's
    /// `poses.txt` and `times.txt` (not in the manifest).
    #[serde(skip)]
    pub sequence: Option<(u64, f64, [f64; 12])>,
}

/// What [`index_dir`] found.
#[derive(Debug, Default)]
pub struct IndexReport {
    /// Good samples.
    pub good: usize,
    /// Indices in `0..count` without a folder.
    pub missing: Vec<u64>,
    /// Entries of `samples/` that are not good samples (the sample id, or the entry's path
    /// relative to the dataset folder), with the reason.
    pub corrupt: Vec<(String, String)>,
    /// KITTI files written again.
    pub kitti_repaired: usize,
}

impl IndexReport {
    /// Whether every sample of the dataset is good.
    pub fn is_complete(&self) -> bool {
        self.missing.is_empty() && self.corrupt.is_empty()
    }
}

/// What [`verify`] found besides the differences of each listed sample, which it reports as
/// it goes.
#[derive(Debug, Default)]
pub struct Verified {
    /// Samples the manifest lists.
    pub samples: usize,
    /// Files the manifest lists.
    pub files: usize,
    /// Differences between the listed samples and their files.
    pub differences: usize,
    /// Samples on disk that the manifest does not list.
    pub unlisted: Vec<u64>,
    /// Samples neither on disk nor in the manifest.
    pub missing: Vec<u64>,
    /// Entries of `samples/` that are no sample of the dataset, with the reason.
    pub strangers: Vec<(String, String)>,
    /// Split lists that are not the manifest's: the file (relative to the dataset folder),
    /// the split and how many ids the manifest puts in it.
    pub bad_splits: Vec<(String, String, usize)>,
}

impl Verified {
    /// How many places differ from the manifest.
    pub fn problems(&self) -> usize {
        self.differences
            + self.unlisted.len()
            + self.missing.len()
            + self.strangers.len()
            + self.bad_splits.len()
    }
}

/// Verifies the files of the dataset in `layout` against its manifest (read as `lines`, in
/// batches, each in parallel in the current rayon pool); writes nothing. Calls `done` after
/// each sample and `difference` for each difference of a listed sample (its manifest entry
/// and what differs), in manifest order. Fails only when the manifest or `samples/` cannot be
/// read.
pub fn verify<R: std::io::BufRead>(
    layout: &Layout,
    info: &DatasetInfo,
    mut lines: Lines<R>,
    done: &(dyn Fn() + Sync),
    difference: &mut dyn FnMut(&Entry, &Difference),
) -> Result<Verified, DatasetError> {
    let mut out = Verified::default();
    // The splits as the manifest has them (`index_dir` writes them in manifest order).
    let mut splits: BTreeMap<&str, String> = SPLITS.iter().map(|&s| (s, String::new())).collect();
    loop {
        let mut batch = Vec::with_capacity(VERIFY_BATCH);
        while batch.len() < VERIFY_BATCH {
            match lines.next_kept(&|_| true)? {
                Some(entry) => batch.push(entry),
                None => break,
            }
        }
        if batch.is_empty() {
            break;
        }
        let differences = verify_batch(layout, &batch, done);
        for (entry, diffs) in batch.iter().zip(&differences) {
            if let Some(list) = splits.get_mut(entry.split.as_str()) {
                list.push_str(&sample_id(entry.index));
                list.push('\n');
            }
            out.samples += 1;
            out.files += entry.files.len();
            for d in diffs {
                difference(entry, d);
                out.differences += 1;
            }
        }
    }
    for index in 0..info.count {
        if !lines.listed(index) {
            if std::fs::symlink_metadata(layout.sample_dir(index)).is_ok() {
                out.unlisted.push(index);
            } else {
                out.missing.push(index);
            }
        }
    }
    out.strangers = strangers(layout, info.count)?;
    for (split, ids) in &splits {
        let path = layout.split_file(split);
        let found = match std::fs::symlink_metadata(&path) {
            Ok(m) if m.is_file() && m.len() == ids.len() as u64 => std::fs::read(&path)
                .map(|bytes| bytes == ids.as_bytes())
                .unwrap_or(false),
            _ => false,
        };
        if !found {
            out.bad_splits.push((
                layout.relative(&path),
                split.to_string(),
                ids.lines().count(),
            ));
        }
    }
    Ok(out)
}

/// The entries of `samples/` that are no sample of the dataset, with the reason: temporary
/// folders and lock files of runs, and anything else, of a dataset of `count` samples.
pub fn strangers(layout: &Layout, count: u64) -> Result<Vec<(String, String)>, DatasetError> {
    let samples = layout.samples_dir();
    let list = |e| DatasetError::io("list", &samples, e);
    let mut names: Vec<String> = match std::fs::read_dir(&samples) {
        Ok(entries) => entries
            .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
            .collect::<Result<_, _>>()
            .map_err(list)?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(list(e)),
    };
    names.sort();
    let mut out = Vec::new();
    for name in &names {
        let reason = if name.starts_with(TMP_PREFIX) {
            "temporary folder of a running or interrupted run (generate removes it when no \
             run renders that sample)"
                .to_owned()
        } else if name.starts_with(SAMPLE_LOCK_PREFIX) {
            "lock file of a running or interrupted run (generate removes it when no run \
             holds it)"
                .to_owned()
        } else if !(name.len() == 6
            && name.bytes().all(|b| b.is_ascii_digit())
            && name.parse::<u64>().is_ok_and(|i| i < count))
        {
            format!(
                "not a sample of this dataset (ids 000000 to {})",
                sample_id(count - 1)
            )
        } else {
            continue;
        };
        out.push((format!("{SAMPLES_DIR}/{name}"), reason));
    }
    Ok(out)
}

/// Checks every sample of the dataset in `layout` (in parallel in the current rayon pool,
/// calling `done` after each), repairs missing KITTI files, and writes `manifest.jsonl` and
/// `splits/` of the good samples (atomically, deterministic bytes).
pub fn index_dir(layout: &Layout, done: &(dyn Fn() + Sync)) -> Result<IndexReport, DatasetError> {
    let info = DatasetInfo::load(&layout.dataset_json())?;
    let mut report = IndexReport::default();
    let mut manifest = String::new();
    let mut splits: BTreeMap<&str, String> = SPLITS.iter().map(|&s| (s, String::new())).collect();

    // Entries of samples/ that are no sample of the dataset.
    report.corrupt = strangers(layout, info.count)?;

    // Every sample, in parallel; the results in index order.
    let checked: Vec<_> = (0..info.count)
        .into_par_iter()
        .map(|index| {
            let dir = layout.sample_dir(index);
            let result = dir.is_dir().then(|| {
                let mut repaired = 0;
                let r = check_sample(layout, &info, index, &dir, Some(&mut repaired));
                (r, repaired)
            });
            done();
            result
        })
        .collect();
    // street -> frame -> (time, pose) of the good samples.
    let mut sequences: BTreeMap<u64, BTreeMap<u64, (f64, [f64; 12])>> = BTreeMap::new();
    for (index, result) in (0..info.count).zip(checked) {
        let Some((result, repaired)) = result else {
            report.missing.push(index);
            continue;
        };
        report.kitti_repaired += repaired;
        match result {
            Ok(line) => {
                let Some(list) = splits.get_mut(line.split.as_str()) else {
                    let e = DatasetError::Invalid {
                        path: layout.sample(index).meta(),
                        reason: format!(
                            "it names the split {:?}, not {}",
                            line.split,
                            SPLITS.join(", ")
                        ),
                    };
                    report.corrupt.push((sample_id(index), e.to_string()));
                    continue;
                };
                list.push_str(&line.id);
                list.push('\n');
                if let Some((frame, time, pose)) = line.sequence {
                    sequences
                        .entry(line.street)
                        .or_default()
                        .insert(frame, (time, pose));
                }
                manifest
                    .push_str(&serde_json::to_string(&line).expect("a manifest line serialises"));
                manifest.push('\n');
                report.good += 1;
            }
            Err(reason) => report.corrupt.push((sample_id(index), reason.to_string())),
        }
    }

    write_bytes_atomically(&layout.manifest(), manifest.as_bytes())?;
    let dir = layout.splits_dir();
    std::fs::create_dir_all(&dir).map_err(|e| DatasetError::io("create the folder", &dir, e))?;
    for (split, ids) in &splits {
        write_bytes_atomically(&layout.split_file(split), ids.as_bytes())?;
    }
    write_sequences(layout, &sequences)?;
    Ok(report)
}

/// Writes `sequences/SSSSSS/poses.txt` and `times.txt` of every street whose good samples
/// are frames 0, 1, ... without a gap (a street with a missing or bad frame gets none: its
/// lines would not match the frame numbers).
fn write_sequences(
    layout: &Layout,
    sequences: &BTreeMap<u64, BTreeMap<u64, (f64, [f64; 12])>>,
) -> Result<(), DatasetError> {
    for (street, frames) in sequences {
        if !frames.keys().copied().eq(0..frames.len() as u64) {
            continue;
        }
        let (mut poses, mut times) = (String::new(), String::new());
        for (time, pose) in frames.values() {
            let line: Vec<String> = pose.iter().map(|v| format!("{:.9e}", v + 0.0)).collect();
            poses.push_str(&line.join(" "));
            poses.push('\n');
            times.push_str(&format!("{:.6e}\n", time));
        }
        let dir = layout.sequence_dir(*street);
        std::fs::create_dir_all(&dir)
            .map_err(|e| DatasetError::io("create the folder", &dir, e))?;
        write_bytes_atomically(&dir.join(POSES), poses.as_bytes())?;
        write_bytes_atomically(&dir.join(TIMES), times.as_bytes())?;
    }
    Ok(())
}

/// The files a sample's `scene.gltf` refers to (buffers and images with a relative `uri`).
fn scene_files(gltf: &Path) -> Result<Vec<String>, DatasetError> {
    // As the renderer would read it: a regular file within its size limit.
    let text = streaks_image::input::read_text(gltf, MAX_SCENE_BYTES)
        .map_err(|e| DatasetError::io("read", gltf, e))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|source| DatasetError::Json {
            path: gltf.to_path_buf(),
            what: "JSON".into(),
            source,
        })?;
    let mut files = Vec::new();
    for key in ["buffers", "images"] {
        for item in json[key].as_array().into_iter().flatten() {
            if let Some(uri) = item["uri"].as_str().filter(|u| !u.starts_with("data:")) {
                // The generator writes plain names next to scene.gltf; nothing else is looked at.
                if uri.is_empty() || uri == "." || uri == ".." || uri.contains(['/', '\\', ':']) {
                    return Err(DatasetError::OutsideSample {
                        file: SCENE_GLTF,
                        uri: uri.to_owned(),
                    });
                }
                files.push(uri.to_owned());
            }
        }
    }
    Ok(files)
}

/// What the entry with metadata `m` is, when it is not a regular file.
fn kind(m: &std::fs::Metadata) -> &'static str {
    if m.file_type().is_symlink() {
        "a symbolic link"
    } else if m.is_dir() {
        "a folder"
    } else {
        "a special file"
    }
}

/// Fails unless the sample folder `dir` is a folder (not a symbolic link) whose entries, and
/// the files of its views `views` that exist, are all regular files.
fn only_regular_files(
    layout: &Layout,
    dir: &Path,
    views: &[(String, PathBuf)],
) -> Result<(), DatasetError> {
    let m = std::fs::symlink_metadata(dir).map_err(|e| DatasetError::io("read", dir, e))?;
    if !m.is_dir() {
        return Err(DatasetError::NotRegular {
            file: layout.relative(dir),
            kind: kind(&m),
        });
    }
    let mut paths = list(dir)?;
    paths.extend(views.iter().map(|(_, p)| p.clone()));
    for path in paths {
        match std::fs::symlink_metadata(&path) {
            Ok(m) if !m.is_file() => {
                return Err(DatasetError::NotRegular {
                    file: layout.relative(&path),
                    kind: kind(&m),
                })
            }
            _ => {}
        }
    }
    Ok(())
}

/// The paths of the entries of the folder `dir`, in the order the system lists them.
fn list(dir: &Path) -> Result<Vec<PathBuf>, DatasetError> {
    std::fs::read_dir(dir)
        .and_then(|entries| entries.map(|e| e.map(|e| e.path())).collect())
        .map_err(|e| DatasetError::io("list", dir, e))
}

/// Checks that the image read from `path` has `size` pixels, the dataset's.
fn check_size(
    path: &Path,
    size: (usize, usize),
    img: Result<GrayImage, impl Into<DatasetError>>,
) -> Result<(), DatasetError> {
    let img = img.map_err(Into::into)?;
    DatasetError::check_size(path, (img.width, img.height), size, DATASET_SIZE)
}

/// Checks a sample's flow files: each decodes at `size`, the flow mask holds only the
/// classes' values, and the KITTI PNG has a flow exactly where the mask says visible or
/// occluded.
fn check_flow(sample: &SampleDir, size: (usize, usize)) -> Result<(), DatasetError> {
    let png = sample.flow_png();
    let (w, h, kitti) = read_kitti_flow(&png)?;
    DatasetError::check_size(&png, (w, h), size, DATASET_SIZE)?;
    let pfm = sample.flow_pfm();
    let flow = read_pfm_rgb(&pfm)?;
    DatasetError::check_size(
        &pfm,
        (flow.width as usize, flow.height as usize),
        size,
        DATASET_SIZE,
    )?;
    let change = sample.disparity_change();
    check_size(&change, size, read_pfm(&change))?;
    let mask_path = sample.flow_mask();
    let mask = streaks_image::input::load_image(&mask_path)?.to_luma8();
    let mask_size = (mask.width() as usize, mask.height() as usize);
    DatasetError::check_size(&mask_path, mask_size, size, DATASET_SIZE)?;
    for (i, (&m, k)) in mask.as_raw().iter().zip(&kitti).enumerate() {
        let Some(state) = FlowState::from_mask_value(m) else {
            return Err(DatasetError::Invalid {
                path: mask_path,
                reason: format!("pixel {i} holds {m}, not a flow class (0, 64, 128, 255)"),
            });
        };
        if state.has_flow()
            && k.is_none()
            && flow.pixels[i].x.abs() < 511.0
            && flow.pixels[i].y.abs() < 511.0
            || !state.has_flow() && k.is_some()
        {
            return Err(DatasetError::Invalid {
                path: png,
                reason: format!("pixel {i}: its valid flag disagrees with {FLOW_MASK} ({m})"),
            });
        }
    }
    Ok(())
}

/// Writes the views `outputs` has (KITTI, SceneFlow) of sample `index`, whose `meta.json` is
/// `meta`, from the files of its folder `sample`.
pub fn write_views(
    layout: &Layout,
    index: u64,
    meta: &SampleMeta,
    sample: &SampleDir,
    outputs: &Outputs,
) -> Result<(), DatasetError> {
    if outputs.has(Output::Kitti) {
        write_kitti(layout, index, sample)?;
    }
    if outputs.has(Output::Sceneflow) {
        write_sceneflow(layout, index, &meta.split, meta.street, sample)?;
    }
    Ok(())
}

/// What the size of a sample's files is checked against, in messages.
const DATASET_SIZE: &str = "the dataset's images are";

/// The file name of `path`.
fn file_name(path: &Path) -> String {
    path.file_name()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned()
}

/// Checks one sample folder (see the module documentation) and returns its manifest line.
/// Missing KITTI files are written again (and counted) with `kitti_repaired`, and make the
/// check fail without.
pub fn check_sample(
    layout: &Layout,
    info: &DatasetInfo,
    index: u64,
    dir: &Path,
    kitti_repaired: Option<&mut usize>,
) -> Result<ManifestLine, DatasetError> {
    // Nothing is read through a symbolic link or from a special file (a FIFO would block).
    only_regular_files(layout, dir, &[])?;
    let sample = SampleDir::new(dir);
    let meta = sample.load_meta()?;
    let outputs = &info.settings.outputs;
    let kept = |p: &Path| outputs.keeps(&file_name(p));
    let views = layout.view_files(index, &meta.split, meta.street, outputs);
    only_regular_files(layout, dir, &views)?;
    if meta.index != index || meta.seed != info.seed || meta.config_hash != info.config_hash {
        return Err(DatasetError::Invalid {
            path: sample.meta(),
            reason: format!(
                "it is of another sample or dataset (index {}, seed {}, config {})",
                meta.index, meta.seed, meta.config_hash
            ),
        });
    }
    let mut expected: Vec<String> = SAMPLE_FILES.map(String::from).to_vec();
    let road_mask = sample.road_mask(Eye::Left);
    if meta.road_mask {
        expected.push(file_name(&road_mask));
    }
    let weather = meta.weather.as_ref();
    let rain_masks = Eye::BOTH.map(|eye| sample.rain_mask(eye));
    let fog_maps = Eye::BOTH.map(|eye| sample.fog(eye));
    let has_rain = weather.is_some_and(|w| w.rain_mm_h > 0.0);
    let has_fog = weather.is_some_and(|w| w.fog.is_some());
    if has_rain {
        expected.extend(rain_masks.iter().map(|p| file_name(p)));
    }
    if has_fog {
        expected.extend(fog_maps.iter().map(|p| file_name(p)));
    }
    let has_segmentation = meta.instances.is_some() && outputs.has(Output::Segmentation);
    let semantic = Eye::BOTH.map(|eye| sample.semantic(eye));
    let instance = Eye::BOTH.map(|eye| sample.instance(eye));
    if has_segmentation {
        expected.extend(semantic.iter().chain(&instance).map(|p| file_name(p)));
    }
    if meta.sequence.is_some() {
        expected.extend(FLOW_FILES.map(String::from));
    }
    expected.retain(|f| outputs.keeps(f));
    if outputs.has(Output::Scene) {
        expected.push(SCENE_GLTF.to_owned());
        if sample.scene().is_file() {
            expected.extend(scene_files(&sample.scene())?);
        }
    }
    let absent: Vec<String> = expected
        .into_iter()
        .filter(|f| !sample.file(f).is_file())
        .collect();
    if !absent.is_empty() {
        return Err(DatasetError::MissingFiles {
            dir: dir.to_path_buf(),
            what: "files",
            files: absent,
        });
    }
    let size = (info.settings.width as usize, info.settings.height as usize);
    let mut pngs = vec![
        sample.png(Eye::Left),
        sample.png(Eye::Right),
        sample.streak_mask(Eye::Left),
        sample.occlusion(Eye::Left),
        sample.occlusion(Eye::Right),
    ];
    if meta.road_mask {
        pngs.push(road_mask);
    }
    if has_rain {
        pngs.extend(rain_masks);
    }
    for p in pngs.into_iter().filter(|p| kept(p)) {
        check_size(&p, size, GrayImage::load(&p))?;
    }
    if has_segmentation {
        if info.classes.is_empty() {
            return Err(DatasetError::Invalid {
                path: sample.meta(),
                reason: "the sample has segmentation maps but dataset.json has no classes".into(),
            });
        }
        for p in &semantic {
            check_semantic(p, size, &info.classes)?;
        }
        for p in &instance {
            check_instance(p, size, &info.classes)?;
        }
    }
    for p in [
        sample.disparity(Eye::Left),
        sample.disparity(Eye::Right),
        sample.depth(Eye::Left),
        sample.depth(Eye::Right),
    ]
    .into_iter()
    .chain(has_fog.then_some(fog_maps).into_iter().flatten())
    .filter(|p| kept(p))
    {
        check_size(&p, size, read_pfm(&p))?;
    }
    if meta.sequence.is_some() && outputs.has(Output::Flow) {
        check_flow(&sample, size)?;
    }
    for p in Eye::BOTH
        .map(|eye| sample.exr(eye))
        .into_iter()
        .filter(|p| kept(p))
    {
        let img = read_exr_rgb(&p)?;
        DatasetError::check_size(
            &p,
            (img.width as usize, img.height as usize),
            size,
            DATASET_SIZE,
        )?;
    }
    let calib = sample.load_calib()?;
    DatasetError::check_size(
        &sample.calib(),
        (calib.width as usize, calib.height as usize),
        size,
        DATASET_SIZE,
    )?;

    // The KITTI and SceneFlow views: written again where missing.
    let kitti = layout.kitti(index);
    let missing: Vec<String> = views
        .iter()
        .filter(|(_, p)| !p.is_file())
        .map(|(rel, _)| rel.clone())
        .collect();
    if !missing.is_empty() {
        let Some(repaired) = kitti_repaired else {
            return Err(DatasetError::MissingFiles {
                dir: dir.to_path_buf(),
                what: "files of its KITTI or SceneFlow view",
                files: missing,
            });
        };
        write_views(layout, index, &meta, &sample, outputs)?;
        *repaired += missing.len();
    }
    if outputs.has(Output::Kitti) {
        for p in [&kitti.disp_occ_0, &kitti.disp_occ_1, &kitti.disp_noc_0] {
            check_size(p, size, read_kitti_disparity(p))?;
        }
    }

    let mut files = BTreeMap::new();
    let mut entries = list(dir)?;
    entries.sort();
    for path in entries
        .iter()
        .map(PathBuf::as_path)
        .chain(views.iter().map(|(_, p)| p.as_path()))
    {
        if !path.is_file() {
            return Err(DatasetError::NotRegular {
                file: layout.relative(path),
                kind: "not a file",
            });
        }
        let bytes = std::fs::read(path).map_err(|e| DatasetError::io("read", path, e))?;
        files.insert(layout.relative(path), sha256_hex(&bytes));
    }
    Ok(ManifestLine {
        id: sample_id(index),
        index,
        street: meta.street,
        split: meta.split,
        seed: meta.seed,
        render_seed: meta.render_seed,
        files,
        stats: meta.stats,
        sequence: meta
            .sequence
            .as_ref()
            .map(|q| (q.frame, q.time_s, q.kitti_pose)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strangers_name_leftovers_and_foreign_entries() {
        let dir = tempfile::tempdir().unwrap();
        let layout = Layout::new(dir.path());
        let samples = layout.samples_dir();
        std::fs::create_dir_all(samples.join("000001")).unwrap();
        std::fs::create_dir_all(samples.join(format!("{TMP_PREFIX}000000-7"))).unwrap();
        std::fs::write(samples.join(format!("{SAMPLE_LOCK_PREFIX}000000")), b"").unwrap();
        std::fs::create_dir_all(samples.join("000002")).unwrap();
        std::fs::write(samples.join("notes.txt"), b"").unwrap();
        let found = strangers(&layout, 2).unwrap();
        let names: Vec<&str> = found.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "samples/.lock-000000",
                "samples/.tmp-000000-7",
                "samples/000002",
                "samples/notes.txt"
            ]
        );
        assert!(
            found[2].1.contains("ids 000000 to 000001"),
            "{:?}",
            found[2]
        );
    }

    /// The limit is the renderer's, so that a sample is refused exactly when its scene could
    /// not be loaded.
    #[cfg(feature = "render")]
    #[test]
    fn the_scene_limit_is_the_renderers() {
        let renderer = streaks_render::scene::LoadOptions::default().max_file_bytes;
        assert_eq!(MAX_SCENE_BYTES, renderer);
    }

    #[test]
    fn scene_references_outside_the_folder_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let gltf = dir.path().join(SCENE_GLTF);
        std::fs::write(
            &gltf,
            r#"{"buffers":[{"uri":"scene.bin"}],"images":[{"uri":"data:x"},{"uri":"t.png"}]}"#,
        )
        .unwrap();
        assert_eq!(scene_files(&gltf).unwrap(), ["scene.bin", "t.png"]);
        std::fs::write(&gltf, r#"{"buffers":[{"uri":"../../secret.txt"}]}"#).unwrap();
        let err = scene_files(&gltf).unwrap_err().to_string();
        assert_eq!(
            err,
            "scene.gltf refers to \"../../secret.txt\", not a file of the sample's folder"
        );
        std::fs::write(&gltf, "{").unwrap();
        let err = scene_files(&gltf).unwrap_err().to_string();
        assert!(err.contains("scene.gltf is not JSON"), "{err}");
    }
}
