//! `streaks dataset index DIR`: verify a dataset against its `manifest.jsonl`, or (the first
//! time, or with `--rebuild`) check the samples on disk and write `manifest.jsonl` and
//! `splits/{train,val,test}.txt` from the good ones.
//!
//! Verifying ([`verify`]) hashes every file the manifest lists (in parallel) and compares it with
//! the manifest's sha256; it also reports the files of a sample the manifest does not list,
//! samples of the dataset missing from the manifest, and folders of `samples/` that are no
//! sample. It writes nothing; any difference makes it fail.
//!
//! Rebuilding ([`index_dir`]): a sample is good when its folder has every file (`dataset.json`'s
//! list, `road0.png` when its meta says so, and the files its `scene.gltf` refers to), its
//! images, EXRs and PFMs decode at the dataset's size, its `calib.txt` parses with that size, and
//! its `meta.json` parses and names its index. Missing samples (indices in `0..count` without a
//! folder), corrupt ones (with the reason), stale temporary folders and lock files of interrupted
//! runs and folders that are no sample of the dataset are reported; the command then exits
//! non-zero, after writing the manifest and the splits of the good samples. Missing KITTI files
//! of good samples are written again from the sample.
//!
//! `manifest.jsonl`: one JSON object per line, in index order, with `id`, `index`, `street`,
//! `split`, `seed`, `render_seed`, `files` (path relative to the dataset folder -> sha256 of
//! every file of the sample folder and of its KITTI files) and `stats` (from `meta.json`).

use super::sample::SampleStats;
use crate::cli::progress_bar;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use streaks_dataset::files::{
    SampleDir, SAMPLES_DIR, SAMPLE_FILES, SAMPLE_LOCK_PREFIX, SCENE_GLTF, TMP_PREFIX,
};
use streaks_dataset::kitti::write_kitti;
use streaks_dataset::layout::{sample_id, DatasetInfo, Layout, SPLITS};
use streaks_dataset::lock::{Lock, LockError, Mode};
use streaks_dataset::manifest::{sha256_hex, verify_batch, Lines};
use streaks_image::exr::read_exr_rgb;
use streaks_image::kitti::read_kitti_disparity;
use streaks_image::pfm::read_pfm;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::calib::MiddleburyCalib;
use streaks_stereo::rig::Eye;

/// Verify a dataset folder against its manifest.jsonl (or write it the first time).
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The dataset folder (with its dataset.json).
    pub dir: PathBuf,
    /// Check the samples on disk and write manifest.jsonl and splits/ again from the good ones,
    /// instead of verifying the files against the manifest.
    #[arg(long)]
    pub rebuild: bool,
    /// Worker threads for hashing and checking [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
}

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
}

/// What indexing found.
#[derive(Debug, Default)]
pub struct IndexReport {
    /// Good samples.
    pub good: usize,
    /// Indices in `0..count` without a folder.
    pub missing: Vec<u64>,
    /// Folders that are not good samples, with the reason.
    pub corrupt: Vec<(String, String)>,
    /// KITTI files written again.
    pub kitti_repaired: usize,
}

impl IndexReport {
    /// Prints the report on stderr and fails if any sample is missing or corrupt.
    pub fn finish(self, layout: &Layout) -> Result<()> {
        let root = layout.root().display();
        if self.kitti_repaired > 0 {
            eprintln!("wrote {} missing KITTI files again", self.kitti_repaired);
        }
        for (what, why) in &self.corrupt {
            eprintln!("corrupt: {what}: {why}");
        }
        if !self.missing.is_empty() {
            let ids: Vec<String> = self.missing.iter().map(|&i| sample_id(i)).collect();
            eprintln!("missing samples ({}): {}", ids.len(), abbreviate(&ids));
        }
        eprintln!(
            "indexed {root}: {} good samples in manifest.jsonl and splits/, {} missing, {} corrupt",
            self.good,
            self.missing.len(),
            self.corrupt.len()
        );
        if !self.missing.is_empty() || !self.corrupt.is_empty() {
            bail!(
                "the dataset {root} is incomplete: {} missing, {} corrupt (see above); \
                 rerun `streaks dataset generate` with the same arguments to render and repair them",
                self.missing.len(),
                self.corrupt.len()
            );
        }
        Ok(())
    }
}

/// At most 20 ids, then how many more.
fn abbreviate(ids: &[String]) -> String {
    if ids.len() <= 20 {
        ids.join(", ")
    } else {
        format!("{}, ... ({} more)", ids[..20].join(", "), ids.len() - 20)
    }
}

/// Runs the subcommand: verifies when the folder has a manifest, rebuilds otherwise or with
/// `--rebuild`.
pub fn run(args: Args) -> Result<()> {
    let layout = Layout::new(&args.dir);
    let info = DatasetInfo::load(&layout.dataset_json())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;
    let rebuild = args.rebuild || !layout.manifest_present();
    let mode = if rebuild {
        Mode::Exclusive
    } else {
        Mode::Shared
    };
    let what = if rebuild {
        "streaks dataset index --rebuild"
    } else {
        "streaks dataset index"
    };
    let _lock = match dataset_lock(&layout, mode, what) {
        Ok(lock) => Some(lock),
        // A copy on a read-only disk can still be verified: nothing can write it either.
        Err(e) if !rebuild && unwritable(&e) => {
            eprintln!("warning: {e:#}; verifying without the lock");
            None
        }
        Err(e) => return Err(e),
    };
    if rebuild {
        return pool.install(|| index_dir(&layout))?.finish(&layout);
    }
    let lines = Lines::open(&layout, info.count)
        .context("cannot verify against the manifest")?
        .context("the manifest disappeared")?;
    pool.install(|| verify(&layout, &info, lines))
}

/// Takes the dataset lock of `layout` (see [`streaks_dataset::lock`]), or fails naming the folder and
/// the run that holds it.
pub fn dataset_lock(layout: &Layout, mode: Mode, what: &str) -> Result<Lock> {
    match Lock::acquire(&layout.lock(), mode, what, false, &|_| {}) {
        Ok(lock) => Ok(lock),
        Err(LockError::Busy { holder, .. }) => bail!(
            "the dataset folder {} is in use by another run: {holder} holds {}; wait for it to \
             end (shards of `streaks dataset generate --shard K/N` may run side by side, but \
             not with a run of the whole dataset or `streaks dataset index --rebuild`)",
            layout.root().display(),
            layout.lock().display()
        ),
        Err(e) => Err(e.into()),
    }
}

/// Whether `e` says the lock file cannot be created because the folder is not writable.
fn unwritable(e: &anyhow::Error) -> bool {
    use std::io::ErrorKind::{PermissionDenied, ReadOnlyFilesystem};
    matches!(
        e.downcast_ref::<LockError>(),
        Some(LockError::Io { source, .. }) if matches!(source.kind(), PermissionDenied | ReadOnlyFilesystem)
    )
}

/// Samples hashed per batch by [`verify`]: enough to keep every core busy, few enough that
/// memory stays small whatever the manifest's size.
const VERIFY_BATCH: usize = 1024;

/// Verifies the files of the dataset in `layout` against its manifest (read as `lines`, in
/// batches); writes nothing and fails if anything differs.
pub fn verify<R: std::io::BufRead>(
    layout: &Layout,
    info: &DatasetInfo,
    mut lines: Lines<R>,
) -> Result<()> {
    let root = layout.root().display();
    let start = std::time::Instant::now();
    let bar = progress_bar(info.count);
    let mut problems = 0usize;
    let (mut samples, mut files) = (0usize, 0usize);
    // The splits as the manifest has them (`index --rebuild` writes them in manifest order).
    let mut splits: BTreeMap<&str, String> = SPLITS.iter().map(|&s| (s, String::new())).collect();
    loop {
        let mut batch = Vec::with_capacity(VERIFY_BATCH);
        while batch.len() < VERIFY_BATCH {
            match lines.next_kept(&|_| true).context(
                "cannot verify against the manifest (`--rebuild` writes it again from the samples)",
            )? {
                Some(entry) => batch.push(entry),
                None => break,
            }
        }
        if batch.is_empty() {
            break;
        }
        let differences = verify_batch(layout, &batch, &|| bar.inc(1));
        for (entry, diffs) in batch.iter().zip(&differences) {
            if let Some(list) = splits.get_mut(entry.split.as_str()) {
                list.push_str(&sample_id(entry.index));
                list.push('\n');
            }
            samples += 1;
            files += entry.files.len();
            for d in diffs {
                bar.suspend(|| {
                    eprintln!(
                        "sample {} (manifest line {}): {d}",
                        sample_id(entry.index),
                        entry.line
                    )
                });
                problems += 1;
            }
        }
    }
    bar.finish_and_clear();
    let mut unlisted = Vec::new();
    let mut missing = Vec::new();
    for index in 0..info.count {
        if !lines.listed(index) {
            if std::fs::symlink_metadata(layout.sample_dir(index)).is_ok() {
                unlisted.push(sample_id(index));
            } else {
                missing.push(sample_id(index));
            }
        }
    }
    if !unlisted.is_empty() {
        eprintln!(
            "samples on disk but not in the manifest ({}): {}",
            unlisted.len(),
            abbreviate(&unlisted)
        );
    }
    if !missing.is_empty() {
        eprintln!(
            "samples neither on disk nor in the manifest ({}): {}",
            missing.len(),
            abbreviate(&missing)
        );
    }
    let strangers = strangers(layout, info)?;
    for (what, why) in &strangers {
        eprintln!("{what}: {why}");
    }
    problems += unlisted.len() + missing.len() + strangers.len();
    for (split, ids) in &splits {
        let path = layout.splits_dir().join(format!("{split}.txt"));
        let rel = layout.relative(&path);
        let found = match std::fs::symlink_metadata(&path) {
            Ok(m) if m.is_file() && m.len() == ids.len() as u64 => std::fs::read(&path)
                .map(|bytes| bytes == ids.as_bytes())
                .unwrap_or(false),
            _ => false,
        };
        if !found {
            eprintln!(
                "{rel}: not the {} ids the manifest puts in {split}",
                ids.lines().count()
            );
            problems += 1;
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    if problems > 0 {
        bail!(
            "the dataset {root} differs from its manifest.jsonl in {problems} place{} (see above; \
             the manifest is unchanged): `streaks dataset generate` with the dataset's arguments \
             renders missing and damaged samples again, `streaks dataset index --rebuild {root}` \
             writes the manifest from the samples on disk",
            if problems == 1 { "" } else { "s" }
        );
    }
    eprintln!(
        "verified {root}: {samples} samples, {files} files match manifest.jsonl ({seconds:.1} s)"
    );
    Ok(())
}

/// The entries of `samples/` that are no sample of the dataset, with the reason: temporary
/// folders and lock files of runs, and anything else.
fn strangers(layout: &Layout, info: &DatasetInfo) -> Result<Vec<(String, String)>> {
    let samples = layout.samples_dir();
    let mut names: Vec<String> = match std::fs::read_dir(&samples) {
        Ok(entries) => entries
            .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
            .collect::<Result<_, _>>()
            .with_context(|| format!("cannot list {}", samples.display()))?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(e).with_context(|| format!("cannot list {}", samples.display())),
    };
    names.sort();
    let mut out = Vec::new();
    for name in &names {
        if name.starts_with(TMP_PREFIX) {
            out.push((
                format!("{SAMPLES_DIR}/{name}"),
                "temporary folder of a running or interrupted run (generate removes it when no \
                 run renders that sample)"
                    .into(),
            ));
        } else if name.starts_with(SAMPLE_LOCK_PREFIX) {
            out.push((
                format!("{SAMPLES_DIR}/{name}"),
                "lock file of a running or interrupted run (generate removes it when no run \
                 holds it)"
                    .into(),
            ));
        } else if !(name.len() == 6
            && name.bytes().all(|b| b.is_ascii_digit())
            && name.parse::<u64>().is_ok_and(|i| i < info.count))
        {
            out.push((
                format!("{SAMPLES_DIR}/{name}"),
                format!(
                    "not a sample of this dataset (ids 000000 to {})",
                    sample_id(info.count - 1)
                ),
            ));
        }
    }
    Ok(out)
}

/// Checks every sample of the dataset in `layout`, repairs missing KITTI files, and writes
/// `manifest.jsonl` and `splits/` of the good samples (atomically, deterministic bytes).
pub fn index_dir(layout: &Layout) -> Result<IndexReport> {
    let info = DatasetInfo::load(&layout.dataset_json())?;
    let mut report = IndexReport::default();
    let mut manifest = String::new();
    let mut splits: BTreeMap<&str, String> = SPLITS.iter().map(|&s| (s, String::new())).collect();

    // Entries of samples/ that are no sample of the dataset.
    report.corrupt = strangers(layout, &info)?;

    // Every sample, in parallel; the results in index order.
    let bar = progress_bar(info.count);
    let checked: Vec<_> = (0..info.count)
        .into_par_iter()
        .map(|index| {
            let dir = layout.sample_dir(index);
            let result = dir.is_dir().then(|| {
                let mut repaired = 0;
                let r = check_sample(layout, &info, index, &dir, Some(&mut repaired));
                (r, repaired)
            });
            bar.inc(1);
            result
        })
        .collect();
    bar.finish_and_clear();
    for (index, result) in (0..info.count).zip(checked) {
        let Some((result, repaired)) = result else {
            report.missing.push(index);
            continue;
        };
        report.kitti_repaired += repaired;
        match result {
            Ok((line, split)) => {
                let Some(list) = splits.get_mut(split.as_str()) else {
                    report.corrupt.push((
                        sample_id(index),
                        format!("meta.json names the split {split:?}, not train, val or test"),
                    ));
                    continue;
                };
                list.push_str(&line.id);
                list.push('\n');
                manifest.push_str(&serde_json::to_string(&line)?);
                manifest.push('\n');
                report.good += 1;
            }
            Err(reason) => report
                .corrupt
                .push((sample_id(index), format!("{reason:#}"))),
        }
    }

    write_bytes_atomically(&layout.manifest(), manifest.as_bytes())?;
    let dir = layout.splits_dir();
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    for (split, ids) in &splits {
        write_bytes_atomically(&layout.split_file(split), ids.as_bytes())?;
    }
    Ok(report)
}

/// The files a sample's `scene.gltf` refers to (buffers and images with a relative `uri`).
fn scene_files(gltf: &Path) -> Result<Vec<String>> {
    // As the renderer would read it: a regular file within its size limit.
    let limit = streaks_render::scene::LoadOptions::default().max_file_bytes;
    let text = streaks_image::input::read_text(gltf, limit).context("cannot read scene.gltf")?;
    let json: serde_json::Value = serde_json::from_str(&text).context("scene.gltf is not JSON")?;
    let mut files = Vec::new();
    for key in ["buffers", "images"] {
        for item in json[key].as_array().into_iter().flatten() {
            if let Some(uri) = item["uri"].as_str().filter(|u| !u.starts_with("data:")) {
                // The generator writes plain names next to scene.gltf; nothing else is looked at.
                if uri.is_empty() || uri == "." || uri == ".." || uri.contains(['/', '\\', ':']) {
                    bail!("scene.gltf refers to {uri:?}, not a file of the sample's folder");
                }
                files.push(uri.to_owned());
            }
        }
    }
    Ok(files)
}

/// Fails unless the sample folder `dir` is a folder (not a symbolic link) whose entries, and
/// the sample's KITTI files that exist, are all regular files.
fn only_regular_files(layout: &Layout, index: u64, dir: &Path) -> Result<()> {
    let what = |m: &std::fs::Metadata| {
        if m.file_type().is_symlink() {
            "a symbolic link"
        } else if m.is_dir() {
            "a folder"
        } else {
            "a special file"
        }
    };
    let m =
        std::fs::symlink_metadata(dir).with_context(|| format!("cannot read {}", dir.display()))?;
    if !m.is_dir() {
        bail!("{} is {}", layout.relative(dir), what(&m));
    }
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .with_context(|| format!("cannot list {}", dir.display()))?;
    let kitti = layout.kitti(index);
    paths.extend(kitti.named(layout).map(|(_, p)| p.to_path_buf()));
    for path in paths {
        match std::fs::symlink_metadata(&path) {
            Ok(m) if !m.is_file() => bail!("{} is {}", layout.relative(&path), what(&m)),
            _ => {}
        }
    }
    Ok(())
}

/// The file name of `path`, for messages.
fn file_name(path: &Path) -> String {
    path.file_name()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned()
}

/// Checks that `path` is an image of `w` x `h` pixels.
fn check_size(
    path: &Path,
    (w, h): (usize, usize),
    img: Result<GrayImage, impl Into<anyhow::Error>>,
) -> Result<()> {
    let img = img.map_err(Into::into)?;
    if (img.width, img.height) != (w, h) {
        bail!(
            "{} is {}x{}, the dataset's images are {w}x{h}",
            file_name(path),
            img.width,
            img.height
        );
    }
    Ok(())
}

/// Checks one sample folder; returns its manifest line and split. Missing KITTI files are
/// written again (and counted) with `kitti_repaired`, and make the check fail without.
pub fn check_sample(
    layout: &Layout,
    info: &DatasetInfo,
    index: u64,
    dir: &Path,
    kitti_repaired: Option<&mut usize>,
) -> Result<(ManifestLine, String)> {
    // Nothing is read through a symbolic link or from a special file (a FIFO would block).
    only_regular_files(layout, index, dir)?;
    let sample = SampleDir::new(dir);
    let meta = sample
        .load_meta()
        .map_err(|e| anyhow::anyhow!("meta.json: {e:#}"))?;
    if meta.index != index || meta.seed != info.seed || meta.config_hash != info.config_hash {
        bail!(
            "meta.json is of another sample or dataset (index {}, seed {}, config {})",
            meta.index,
            meta.seed,
            meta.config_hash
        );
    }
    let mut expected: Vec<String> = SAMPLE_FILES.map(String::from).to_vec();
    let road_mask = sample.road_mask(Eye::Left);
    if meta.road_mask {
        expected.push(file_name(&road_mask));
    }
    expected.push(SCENE_GLTF.to_owned());
    if dir.join(SCENE_GLTF).is_file() {
        expected.extend(scene_files(&dir.join(SCENE_GLTF))?);
    }
    let absent: Vec<&String> = expected.iter().filter(|f| !dir.join(f).is_file()).collect();
    if !absent.is_empty() {
        let list: Vec<&str> = absent.iter().map(|s| s.as_str()).collect();
        bail!("missing files: {}", list.join(", "));
    }
    let size = (info.settings.width as usize, info.settings.height as usize);
    let mut pngs = vec![
        sample.png(Eye::Left),
        sample.png(Eye::Right),
        sample.streak_mask(Eye::Left),
    ];
    if meta.road_mask {
        pngs.push(road_mask);
    }
    for p in pngs {
        check_size(&p, size, GrayImage::load(&p))?;
    }
    for p in [
        sample.disparity(Eye::Left),
        sample.disparity(Eye::Right),
        sample.depth(Eye::Left),
    ] {
        check_size(&p, size, read_pfm(&p))?;
    }
    for p in Eye::BOTH.map(|eye| sample.exr(eye)) {
        let img = read_exr_rgb(&p)?;
        if (img.width as usize, img.height as usize) != size {
            bail!(
                "{} is {}x{}, the dataset's images are {}x{}",
                file_name(&p),
                img.width,
                img.height,
                size.0,
                size.1
            );
        }
    }
    let calib = MiddleburyCalib::load(&sample.calib())?;
    if (calib.width, calib.height) != (info.settings.width, info.settings.height) {
        bail!(
            "{} is for {}x{}, the dataset's images are {}x{}",
            file_name(&sample.calib()),
            calib.width,
            calib.height,
            info.settings.width,
            info.settings.height
        );
    }

    // The KITTI view: written again where missing.
    let kitti = layout.kitti(index);
    let named = kitti.named(layout);
    if named.iter().any(|(_, p)| !p.is_file()) {
        let missing: Vec<&str> = named
            .iter()
            .filter(|(_, p)| !p.is_file())
            .map(|(rel, _)| rel.as_str())
            .collect();
        let Some(repaired) = kitti_repaired else {
            bail!("missing KITTI files: {}", missing.join(", "));
        };
        write_kitti(
            layout,
            index,
            &sample,
            &read_pfm(&sample.disparity(Eye::Left))?,
        )?;
        *repaired += missing.len();
    }
    check_size(
        &kitti.disp_occ_0,
        size,
        read_kitti_disparity(&kitti.disp_occ_0),
    )?;

    let mut files = BTreeMap::new();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    entries.sort();
    for path in entries
        .iter()
        .map(PathBuf::as_path)
        .chain(named.iter().map(|(_, p)| *p))
    {
        if !path.is_file() {
            bail!("{} is not a file", layout.relative(path));
        }
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        files.insert(layout.relative(path), sha256_hex(&bytes));
    }
    Ok((
        ManifestLine {
            id: sample_id(index),
            index,
            street: meta.street,
            split: meta.split.clone(),
            seed: meta.seed,
            render_seed: meta.render_seed,
            files,
            stats: meta.stats,
        },
        meta.split,
    ))
}
