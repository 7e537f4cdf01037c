//! `streaks dataset generate`: render the samples of a dataset (or one shard of them).
//!
//! First every sample of the shard is checked (in parallel): against `manifest.jsonl` when it
//! lists the sample (every file's sha256, no file missing or extra), otherwise with the checks of
//! `streaks dataset index --rebuild` (every file there, images decode at the dataset's size...).
//! Then, for each index `i` of the shard: a good sample is skipped; a missing one, or a damaged
//! one (removed first, the message says why), is built with the procedural generator from
//! `(config, seed, i)`, rendered into `samples/.tmp-NNNNNN-PID/`, its KITTI files written, and
//! the folder renamed to `samples/NNNNNN/`. Rendering is deterministic, so a repaired sample has
//! the bytes the manifest lists (the message says whether it does).
//!
//! Locks ([`streaks_dataset::lock`]): a run of the whole dataset holds the dataset lock exclusively (a
//! second one is refused, naming the holder), a shard holds it shared; a sample is cleaned and
//! rendered under its own lock, so two shards never render one sample at once and temporary
//! folders are removed only when no live run renders that sample. Without `--shard` the
//! manifest is written at the end ([`super::index::rebuild_dir`]).

use super::index::{dataset_lock, rebuild_dir};
use super::sample::{render_sample, SampleSettings};
use crate::cli::{image_size, progress_bar};
use crate::render_opts::flag_error;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::cell::Cell;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::Instant;
use streaks_dataset::files::{DATASET_JSON, LOCK, SAMPLE_LOCK_PREFIX, TMP_PREFIX};
use streaks_dataset::layout::{
    sample_id, Conventions, DatasetInfo, FileList, Layout, FORMAT, MAX_COUNT,
};
use streaks_dataset::lock::{Lock, Mode};
use streaks_dataset::manifest::{sha256_hex, verify_entry, Difference, Manifest};
use streaks_dataset::outputs::{Output, Outputs};
use streaks_dataset::settings::Settings;
use streaks_dataset::shard::Shard;
use streaks_dataset::verify::check_sample;
use streaks_image::denoise::Denoiser;
use streaks_image::stats::quantile_sorted;
use streaks_image::write_bytes_atomically;
use streaks_scenes::procedural::{GeneratorConfig, GENERATOR_VERSION};
use streaks_settings::{check_noise_target, RenderSettings};

/// Render the samples of a dataset (all, or one shard) into a folder; resumable.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The dataset folder (created if missing; must be empty or hold the same dataset).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of samples in the dataset (indices 0..N, at most 1000000).
    #[arg(long)]
    pub count: u64,
    /// Dataset seed: with the config and the index it determines each sample.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Generator config (TOML) [default: the documented default config].
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Image width in pixels.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 384)]
    pub height: u32,
    /// Samples per pixel per eye (the cap, with --noise-target).
    #[arg(long, default_value_t = DEFAULT_SPP)]
    pub spp: u32,
    /// Adaptive sampling (`streaks render --noise-target`): stop each tile of pixels once its
    /// estimated relative standard error is below REL, --spp being the cap; `off` takes --spp
    /// samples everywhere.
    #[arg(long, value_name = "REL|off", default_value_t = NoiseTarget(Some(DEFAULT_NOISE_TARGET)))]
    pub noise_target: NoiseTarget,
    /// Render only the samples whose index is K modulo N (0 <= K < N); shards may run at the
    /// same time into one folder; then run `streaks dataset index DIR`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Longest path, Mitsuba's meaning: 1 = emitters only, 2 = direct light, 3 = one bounce...
    #[arg(long, default_value_t = 8)]
    pub max_depth: u32,
    /// Render without path regularisation (on by default here: fewer fireflies, a small bias
    /// in indirect light; see `streaks render --regularize`).
    #[arg(long)]
    pub no_regularize: bool,
    /// Denoise each eye's image with Intel Open Image Denoise (`streaks render --denoise`):
    /// `auto` when the library is installed (`pip install pyoidn`, or OIDN_LIBRARY), with a
    /// warning when it is not; `on` fails without it; `off` keeps the renders as they are.
    /// Ground truth, masks and the specular layer are never denoised; `dataset.json` and each
    /// `meta.json` record whether the images are.
    #[arg(long, value_enum, default_value_t = DenoiseMode::Auto)]
    pub denoise: DenoiseMode,
    /// Keep the render before denoising in each EXR (its `raw` layer; dropped by default).
    #[arg(long)]
    pub keep_raw: bool,
    /// The groups of files each sample keeps, comma-separated: images (im0/im1.png), images16
    /// (the same at 16 bits, im0_16/im1_16.png; not kept by default), exr,
    /// gt (disparity, depth, occlusion), masks (streak, road, rain, fog), segmentation, flow,
    /// scene, kitti (the KITTI view), sceneflow (the SceneFlow view); calib.txt and meta.json
    /// always. Part of the dataset: a rerun must give the same groups.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "GROUP,...",
        default_value = "images,exr,gt,masks,segmentation,flow,scene,kitti,sceneflow"
    )]
    pub outputs: Vec<Output>,
}

/// `--denoise`: whether a dataset's images are denoised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DenoiseMode {
    /// When Intel Open Image Denoise is installed.
    Auto,
    /// Always; an error without the library.
    On,
    /// Never.
    Off,
}

/// The denoiser of `--denoise` (`None`: no denoising), loaded before anything is written.
fn denoiser(mode: DenoiseMode) -> Result<Option<Denoiser>> {
    match mode {
        DenoiseMode::Off => Ok(None),
        DenoiseMode::On => Ok(Some(Denoiser::load().context("--denoise on")?)),
        DenoiseMode::Auto => match Denoiser::load() {
            Ok(d) => Ok(Some(d)),
            Err(e) => {
                eprintln!("warning: the images are not denoised: {e}");
                Ok(None)
            }
        },
    }
}

/// The default cap of samples per pixel per eye (see docs/decisions/0013).
pub const DEFAULT_SPP: u32 = 64;

/// The default adaptive-sampling target of a dataset (see docs/benchmarks.md, "Adaptive sampling").
pub const DEFAULT_NOISE_TARGET: f32 = 0.1;

/// `--noise-target`: a positive, finite relative standard error, or `off` (`None`); the
/// renderer's `f32`, which `dataset.json` records as its shortest decimal (`0.1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseTarget(pub Option<f32>);

impl std::fmt::Display for NoiseTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(rel) => write!(f, "{rel}"),
            None => f.write_str("off"),
        }
    }
}

impl std::str::FromStr for NoiseTarget {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        if s == "off" {
            return Ok(Self(None));
        }
        match s.parse::<f32>() {
            Ok(rel) if check_noise_target(rel).is_ok() => Ok(Self(Some(rel))),
            _ => Err(format!(
                "expected a positive, finite relative standard error (such as 0.1) or `off`, \
                 got {s:?}"
            )),
        }
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    // Phase 1: the flags and the config; nothing is written before they are all good.
    if args.count == 0 {
        bail!("--count must be at least 1");
    }
    if args.count > MAX_COUNT {
        bail!(
            "--count {} is too large: sample ids have six digits (at most {MAX_COUNT})",
            args.count
        );
    }
    image_size(Some(args.width), Some(args.height), None)?;
    let render = RenderSettings {
        spp: args.spp,
        max_depth: args.max_depth,
        regularize: !args.no_regularize,
        noise_target: args.noise_target.0,
    };
    render.check().map_err(flag_error)?;
    let denoiser = denoiser(args.denoise)?;
    if args.keep_raw && denoiser.is_none() {
        bail!("--keep-raw keeps the render beside its denoised image: it needs denoising");
    }
    let config = match &args.config {
        Some(path) => GeneratorConfig::from_toml_file(path)
            .with_context(|| format!("cannot use the config {}", path.display()))?,
        None => GeneratorConfig::default(),
    };
    let config_hash = sha256_hex(config.to_toml().as_bytes());
    let info = DatasetInfo {
        format: FORMAT.to_owned(),
        generator_version: GENERATOR_VERSION.to_owned(),
        config: config.to_json(),
        config_hash: config_hash.clone(),
        count: args.count,
        seed: args.seed,
        settings: Settings {
            width: args.width,
            height: args.height,
            render,
            denoise: denoiser.is_some(),
            keep_raw: args.keep_raw,
            outputs: Outputs(args.outputs.iter().copied().collect()),
        },
        files: FileList::current().kept(&Outputs(args.outputs.iter().copied().collect())),
        conventions: Conventions::current(),
        classes: streaks_dataset::segmentation::class_table(),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;

    // Phase 2: the folder: new, or the same dataset; locked for this run.
    let layout = Layout::new(&args.output);
    let root = layout.root();
    std::fs::create_dir_all(root)
        .with_context(|| format!("cannot create the dataset folder {}", root.display()))?;
    let (mode, what) = match args.shard {
        None => (Mode::Exclusive, "streaks dataset generate".to_owned()),
        Some(s) => (
            Mode::Shared,
            format!("streaks dataset generate --shard {s}"),
        ),
    };
    let _dataset_lock = dataset_lock(&layout, mode, &what)?;
    prepare_folder(&layout, &info)?;
    let shard = args.shard.unwrap_or(Shard::ALL);
    let manifest = match Manifest::load(&layout, args.count, &|i| shard.contains(i)) {
        Ok(m) => m,
        Err(e) => {
            eprintln!(
                "warning: {e}; the samples are checked without it{}",
                if args.shard.is_none() {
                    " and it is written again at the end"
                } else {
                    ""
                }
            );
            None
        }
    };

    // Phase 3: check the samples of this shard.
    let indices: Vec<u64> = (0..args.count).filter(|&i| shard.contains(i)).collect();
    let settings = SampleSettings {
        config,
        config_hash,
        seed: args.seed,
        settings: info.settings.clone(),
        denoiser: denoiser.map(std::sync::Arc::new),
    };
    let check = |index: u64| health(&layout, &info, index, manifest.as_ref());
    let bar = progress_bar(indices.len() as u64);
    let healths: Vec<Health> = pool.install(|| {
        indices
            .par_iter()
            .map(|&i| {
                let h = check(i);
                bar.inc(1);
                h
            })
            .collect()
    });
    bar.finish_and_clear();
    let leftovers = leftovers(&layout)?;

    // Phase 4: render what is missing or damaged, each sample under its lock.
    let bar = progress_bar(indices.len() as u64);
    let start = Instant::now();
    let mut shares = Vec::new();
    let mut bytes = 0u64;
    let mut skipped = 0usize;
    let mut repaired = 0usize;
    let warned_no_road = Cell::new(false);
    for (&index, found) in indices.iter().zip(healths) {
        let id = sample_id(index);
        if matches!(found, Health::Good) && !leftovers.contains(&index) {
            skipped += 1;
            bar.inc(1);
            continue;
        }
        let waited = Cell::new(false);
        let _sample_lock = Lock::acquire(
            &layout.sample_lock(index),
            Mode::Exclusive,
            &what,
            true,
            &|holder| {
                waited.set(true);
                bar.suspend(|| eprintln!("sample {id}: {holder} is on it; waiting"));
            },
        )?;
        for stale in layout.remove_stale_tmp(index)? {
            bar.suspend(|| {
                eprintln!(
                    "sample {id}: removed {}, the temporary folder of an interrupted run",
                    layout.relative(&stale)
                )
            });
        }
        // Another run may have rendered or repaired it since the check.
        let found = if waited.get() || !matches!(found, Health::Good) {
            check(index)
        } else {
            found
        };
        match &found {
            Health::Good => {
                skipped += 1;
                bar.inc(1);
                continue;
            }
            Health::Missing => {}
            Health::Damaged(why) => {
                bar.suspend(|| eprintln!("sample {id}: {why}; removing it and rendering it again"));
                remove_sample(&layout.sample_dir(index))?;
            }
        }
        let rendered = pool.install(|| {
            render_sample(&layout, &settings, index, &|w| {
                bar.suspend(|| eprintln!("warning: {w}"))
            })
        })?;
        if !rendered.road_mask && !warned_no_road.replace(true) {
            bar.suspend(|| {
                eprintln!(
                    "warning: the scene of sample {id} flags no road material \
                     (extras.streaks.road); road0.png is not written and meta.json says so \
                     (road_mask: false); said once"
                )
            });
        }
        let share = rendered.stats.streak_share;
        shares.push(share);
        bytes += rendered.bytes;
        bar.suspend(|| {
            eprintln!(
                "sample {id}: {:.2} s, streak share {:.3} %",
                rendered.seconds,
                100.0 * share
            )
        });
        if matches!(found, Health::Damaged(_)) {
            repaired += 1;
            if let Some(entry) = manifest.as_ref().and_then(|m| m.get(index)) {
                let diffs = verify_entry(&layout, entry);
                bar.suspend(|| {
                    if diffs.is_empty() {
                        eprintln!(
                            "sample {id}: repaired; its files are again those manifest.jsonl lists"
                        );
                    } else {
                        eprintln!(
                            "warning: sample {id}: rendered again, but it differs from \
                             manifest.jsonl ({}): the renderer or its settings changed since \
                             the manifest was written",
                            describe(&diffs)
                        );
                    }
                });
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    let seconds = start.elapsed().as_secs_f64();
    let repairs = if repaired > 0 {
        format!(" ({repaired} of them repaired)")
    } else {
        String::new()
    };
    let mut summary = format!(
        "shard {shard}: {} samples rendered{repairs}, {skipped} already done, in {seconds:.1} s",
        shares.len()
    );
    if !shares.is_empty() {
        shares.sort_by(f64::total_cmp);
        summary += &format!(
            " ({:.0} pairs per hour); streak share min {:.3} %, median {:.3} %, max {:.3} %",
            shares.len() as f64 * 3600.0 / seconds.max(1e-9),
            100.0 * shares[0],
            100.0 * quantile_sorted(&shares, 0.5).unwrap_or(f64::NAN),
            100.0 * shares[shares.len() - 1]
        );
        summary += &format!(
            "; {:.0} bytes per sample (its folder and its KITTI and SceneFlow files)",
            bytes as f64 / shares.len() as f64
        );
    }
    eprintln!("{summary}");

    if args.shard.is_some() {
        eprintln!(
            "when all shards are done, run: streaks dataset index --rebuild {}",
            layout.root().display()
        );
        return Ok(());
    }
    rebuild_dir(&layout)
}

/// What the check before rendering found of a sample.
#[derive(Clone, Debug)]
enum Health {
    /// Its files are those the manifest lists, or (not listed) it passes the index's checks.
    Good,
    /// No folder.
    Missing,
    /// Anything else, with what is wrong.
    Damaged(String),
}

/// Checks sample `index`: against `manifest` when it lists the sample, with the checks of
/// `streaks dataset index --rebuild` (without writing KITTI files) otherwise.
fn health(layout: &Layout, info: &DatasetInfo, index: u64, manifest: Option<&Manifest>) -> Health {
    let dir = layout.sample_dir(index);
    match std::fs::symlink_metadata(&dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Health::Missing,
        Err(e) => return Health::Damaged(format!("{}: {e}", dir.display())),
        Ok(m) if !m.is_dir() => {
            return Health::Damaged(format!("{} is not a folder", layout.relative(&dir)))
        }
        Ok(_) => {}
    }
    match manifest.and_then(|m| m.get(index)) {
        Some(entry) => {
            let diffs = verify_entry(layout, entry);
            if !diffs.is_empty() {
                Health::Damaged(describe(&diffs))
            } else if !layout.is_complete(index, &info.settings.outputs) {
                Health::Damaged("its files match manifest.jsonl, which lists too few".into())
            } else {
                Health::Good
            }
        }
        None => match check_sample(layout, info, index, &dir, None) {
            Ok(_) => Health::Good,
            Err(e) => Health::Damaged(format!("{e:#}")),
        },
    }
}

/// The first differences, and how many more.
fn describe(diffs: &[Difference]) -> String {
    let shown: Vec<String> = diffs.iter().take(3).map(|d| d.to_string()).collect();
    let mut text = shown.join("; ");
    if diffs.len() > 3 {
        text += &format!(" (and {} more)", diffs.len() - 3);
    }
    text
}

/// The indices with a temporary folder or a lock file in `samples/` (maybe stale: cleaned
/// under the sample's lock).
fn leftovers(layout: &Layout) -> Result<BTreeSet<u64>> {
    let dir = layout.samples_dir();
    let mut out = BTreeSet::new();
    for entry in
        std::fs::read_dir(&dir).with_context(|| format!("cannot list {}", dir.display()))?
    {
        let name = entry
            .with_context(|| format!("cannot list {}", dir.display()))?
            .file_name();
        let name = name.to_string_lossy();
        let digits = name
            .strip_prefix(TMP_PREFIX)
            .or_else(|| name.strip_prefix(SAMPLE_LOCK_PREFIX))
            .and_then(|rest| rest.get(..6))
            .filter(|d| d.bytes().all(|b| b.is_ascii_digit()));
        if let Some(index) = digits.and_then(|d| d.parse().ok()) {
            out.insert(index);
        }
    }
    Ok(out)
}

/// Removes a damaged sample folder (or whatever is at its path).
fn remove_sample(dir: &Path) -> Result<()> {
    let is_dir = std::fs::symlink_metadata(dir).is_ok_and(|m| m.is_dir());
    let removed = if is_dir {
        std::fs::remove_dir_all(dir)
    } else {
        std::fs::remove_file(dir)
    };
    match removed {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove the damaged sample {}", dir.display()))
        }
        _ => Ok(()),
    }
}

/// Fails unless the bytes of an existing `dataset.json` describe the dataset `info`.
fn check_existing(info: &DatasetInfo, existing: &[u8], path: &std::path::Path) -> Result<()> {
    let value: serde_json::Value = serde_json::from_slice(existing)
        .with_context(|| format!("{} is not a dataset.json (not JSON)", path.display()))?;
    Ok(info.check_same(&value, path)?)
}

/// Writes the dataset folder's `dataset.json`, or checks that the folder holds the same
/// dataset; a folder with other files (besides the dataset lock) and no `dataset.json` is
/// refused.
fn prepare_folder(layout: &Layout, info: &DatasetInfo) -> Result<()> {
    let root = layout.root();
    let json = layout.dataset_json();
    match streaks_image::input::read_file(&json, streaks_image::input::MAX_TEXT_BYTES) {
        Ok(existing) => check_existing(info, &existing, &json)?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            // Another shard may be writing dataset.json right now (its temporary file
            // `.dataset.json.*.tmp`, then the file): those do not make the folder non-empty.
            let entries = std::fs::read_dir(root)
                .with_context(|| format!("cannot list {}", root.display()))?;
            for entry in entries {
                let name = entry?.file_name().to_string_lossy().into_owned();
                if name != DATASET_JSON
                    && name != LOCK
                    && !name.starts_with(&format!(".{DATASET_JSON}."))
                {
                    bail!(
                        "{} is not empty (it holds {name}) and has no dataset.json: it is not a \
                         dataset; give an empty or new folder",
                        root.display()
                    );
                }
            }
            write_bytes_atomically(&json, &info.to_bytes())
                .with_context(|| format!("cannot write into {}", root.display()))?;
            // A shard with other settings that wrote at the same time is caught here.
            let written =
                streaks_image::input::read_file(&json, streaks_image::input::MAX_TEXT_BYTES)
                    .with_context(|| format!("cannot read {}", json.display()))?;
            check_existing(info, &written, &json)?;
        }
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", json.display())),
    }
    let samples = layout.samples_dir();
    std::fs::create_dir_all(&samples)
        .with_context(|| format!("cannot create the folder {}", samples.display()))?;
    Ok(())
}
