//! `streaks dataset index DIR`: verify a dataset against its `manifest.jsonl`, or (the first
//! time, or with `--rebuild`) check the samples on disk and write `manifest.jsonl` and
//! `splits/{train,val,test}.txt` from the good ones.
//!
//! The checks are [`streaks_dataset::verify`]'s; this module takes the dataset lock, runs
//! them in a pool of `--threads` with a progress bar, prints what they found and fails when
//! anything is missing, corrupt or differs. Verifying writes nothing; rebuilding writes the
//! manifest and the splits of the good samples (and missing KITTI files of good samples) and
//! then fails if any sample is missing or corrupt.

use crate::cli::progress_bar;
use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use streaks_dataset::layout::{sample_id, DatasetInfo, Layout};
use streaks_dataset::lock::{Lock, LockError, Mode};
use streaks_dataset::manifest::Lines;
use streaks_dataset::verify::{index_dir, verify, IndexReport};

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

/// Checks every sample of the dataset in `layout` and writes `manifest.jsonl` and `splits/`
/// of the good ones ([`index_dir`], with a progress bar), prints what it found on stderr, and
/// fails if any sample is missing or corrupt.
pub fn rebuild_dir(layout: &Layout) -> Result<()> {
    let info = DatasetInfo::load(&layout.dataset_json())?;
    let bar = progress_bar(info.count);
    let report = index_dir(layout, &|| bar.inc(1));
    bar.finish_and_clear();
    finish(report?, layout)
}

/// Prints `report` on stderr and fails if any sample is missing or corrupt.
fn finish(report: IndexReport, layout: &Layout) -> Result<()> {
    let root = layout.root().display();
    if report.kitti_repaired > 0 {
        eprintln!("wrote {} missing KITTI files again", report.kitti_repaired);
    }
    for (what, why) in &report.corrupt {
        eprintln!("corrupt: {what}: {why}");
    }
    if !report.missing.is_empty() {
        eprintln!(
            "missing samples ({}): {}",
            report.missing.len(),
            abbreviate(&report.missing)
        );
    }
    eprintln!(
        "indexed {root}: {} good samples in manifest.jsonl and splits/, {} missing, {} corrupt",
        report.good,
        report.missing.len(),
        report.corrupt.len()
    );
    if !report.is_complete() {
        bail!(
            "the dataset {root} is incomplete: {} missing, {} corrupt (see above); \
             rerun `streaks dataset generate` with the same arguments to render and repair them",
            report.missing.len(),
            report.corrupt.len()
        );
    }
    Ok(())
}

/// The ids of the samples `indices`: at most 20, then how many more.
fn abbreviate(indices: &[u64]) -> String {
    let ids: Vec<String> = indices.iter().take(20).map(|&i| sample_id(i)).collect();
    if indices.len() <= 20 {
        ids.join(", ")
    } else {
        format!("{}, ... ({} more)", ids.join(", "), indices.len() - 20)
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
        return pool.install(|| rebuild_dir(&layout));
    }
    let lines = Lines::open(&layout, info.count)
        .context("cannot verify against the manifest")?
        .context("the manifest disappeared")?;
    pool.install(|| check_against_manifest(&layout, &info, lines))
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

/// Verifies the files of the dataset in `layout` against its manifest (read as `lines`) with
/// [`verify`], printing every difference on stderr; writes nothing and fails if anything
/// differs.
fn check_against_manifest<R: std::io::BufRead>(
    layout: &Layout,
    info: &DatasetInfo,
    lines: Lines<R>,
) -> Result<()> {
    let root = layout.root().display();
    let start = std::time::Instant::now();
    let bar = progress_bar(info.count);
    let found = verify(layout, info, lines, &|| bar.inc(1), &mut |entry, d| {
        bar.suspend(|| {
            eprintln!(
                "sample {} (manifest line {}): {d}",
                sample_id(entry.index),
                entry.line
            )
        })
    })
    .context("cannot verify against the manifest (`--rebuild` writes it again from the samples)");
    bar.finish_and_clear();
    let found = found?;
    if !found.unlisted.is_empty() {
        eprintln!(
            "samples on disk but not in the manifest ({}): {}",
            found.unlisted.len(),
            abbreviate(&found.unlisted)
        );
    }
    if !found.missing.is_empty() {
        eprintln!(
            "samples neither on disk nor in the manifest ({}): {}",
            found.missing.len(),
            abbreviate(&found.missing)
        );
    }
    for (what, why) in &found.strangers {
        eprintln!("{what}: {why}");
    }
    for (file, split, ids) in &found.bad_splits {
        eprintln!("{file}: not the {ids} ids the manifest puts in {split}");
    }
    let seconds = start.elapsed().as_secs_f64();
    let problems = found.problems();
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
        "verified {root}: {} samples, {} files match manifest.jsonl ({seconds:.1} s)",
        found.samples, found.files
    );
    Ok(())
}
