//! `streaks train-detector`: trains the learned streak detector
//! ([`streaks_analysis::streak_classifier`]) on datasets of `streaks dataset generate`.
//!
//! 1. **Rows**: from each sample of the training split, every `stride`-th pixel of the left
//!    view's linear luminance (`im0.exr`), about `--pixels` per sample, labelled by the road's
//!    streak mask (`streaks0.png` ∩ `road0.png`), with the horizon of the sample's camera.
//! 2. **Trees**: gradient boosting on those rows ([`streaks_analysis::gbdt`]).
//! 3. **Threshold and smoothing**: over every pixel of the validation split (samples the trees
//!    never saw, of other streets), for each smoothing radius of the probability (0, 1, 2),
//!    the lowest threshold whose precision reaches `--precision`; the radius with the highest
//!    recall at its threshold is kept.
//!
//! The classifier is written as JSON, with its provenance (datasets, splits, settings, the
//! validation score). Everything is deterministic: the same datasets and settings give the
//! same file, whatever the number of threads.

use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use streaks_analysis::gbdt::{self, Dataset, TrainParams};
use streaks_analysis::streak_classifier::{
    choose_operating_point, training_rows, OperatingPoint, StreakClassifier, FEATURES,
};
use streaks_image::{write_bytes_atomically, GrayImage};

use crate::cli::{sample_horizon, sample_truths};
use streaks_dataset::files::{SampleDir, SAMPLE_NAMES};
use streaks_dataset::layout::Layout;
use streaks_stereo::rig::Eye;

/// Train the learned streak detector on datasets.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Dataset folders (with dataset.json) to train on.
    #[arg(required = true)]
    pub datasets: Vec<PathBuf>,
    /// The classifier to write (JSON).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The split whose samples train the trees.
    #[arg(long, default_value = "train")]
    pub train_split: String,
    /// The splits whose samples choose the threshold and smoothing (other streets than the
    /// training split's), comma-separated: more samples give a threshold that holds on more
    /// streets.
    #[arg(long, default_value = "val", value_delimiter = ',')]
    pub val_split: Vec<String>,
    /// The precision the threshold is chosen for, on the validation split.
    #[arg(long, default_value_t = 0.9)]
    pub precision: f64,
    /// Training pixels per sample (every k-th pixel, k = pixels in the image / this).
    #[arg(long, default_value_t = 40_000)]
    pub pixels: usize,
    /// Boosting rounds. The defaults of these four are the shipped classifier's: small trees
    /// with large leaves, because a street's pixels are far from independent, and deeper
    /// trees learn the training streets rather than streaks (docs/stereo.md, "Streak detection").
    #[arg(long, default_value_t = 150)]
    pub rounds: usize,
    /// Learning rate.
    #[arg(long, default_value_t = TrainParams::default().learning_rate)]
    pub learning_rate: f32,
    /// Most leaves per tree.
    #[arg(long, default_value_t = 15)]
    pub max_leaves: usize,
    /// Fewest training rows in a leaf.
    #[arg(long, default_value_t = 2000)]
    pub min_leaf: usize,
}

/// A sample's inputs: the linear luminance, its horizon, the road-streak truth.
struct Sample {
    lum: GrayImage,
    horizon: f32,
    truth: GrayImage,
}

fn load_sample(dir: &Path) -> Result<Option<Sample>> {
    let sample = SampleDir::new(dir);
    let meta = sample.load_meta()?;
    let (_, on_road) = sample_truths(&sample, &meta)?;
    let Some(truth) = on_road else {
        return Ok(None);
    };
    let image = sample.exr(Eye::Left);
    let lum = GrayImage::load_linear(&image)
        .with_context(|| format!("cannot read {}", image.display()))?;
    if (lum.width, lum.height) != (truth.width, truth.height) {
        bail!("{} and its masks differ in size", image.display());
    }
    Ok(Some(Sample {
        lum,
        horizon: sample_horizon(&meta),
        truth,
    }))
}

/// The sample folders of `split` in every dataset, in order.
pub(crate) fn split_samples(datasets: &[PathBuf], split: &str) -> Result<Vec<PathBuf>> {
    let mut out = vec![];
    for d in datasets {
        let layout = Layout::new(d);
        if !layout.dataset_json().is_file() {
            bail!(
                "{} is not a dataset folder (no {})",
                d.display(),
                streaks_dataset::files::DATASET_JSON
            );
        }
        // A split that one dataset leaves empty (a small dataset's val split, say) adds
        // nothing; the callers refuse a selection that is empty over all datasets.
        let ids = match layout.sample_ids(Some(split)) {
            Err(streaks_dataset::error::DatasetError::NoSamples { .. }) => continue,
            ids => ids.with_context(|| format!("the {split} split of {}", d.display()))?,
        };
        out.extend(
            ids.iter()
                .map(|id| layout.sample_by_id(id).path().to_path_buf()),
        );
    }
    Ok(out)
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let params = training_params(
        args.precision,
        args.pixels,
        TrainParams {
            rounds: args.rounds,
            learning_rate: args.learning_rate,
            max_leaves: args.max_leaves,
            min_leaf: args.min_leaf,
            ..TrainParams::default()
        },
    )?;
    let (train, val, val_name) =
        training_splits(&args.datasets, &args.train_split, &args.val_split)?;
    let t0 = std::time::Instant::now();
    eprintln!("reading {} training samples", train.len());
    let bar = crate::cli::progress_bar(train.len() as u64);
    let parts = train
        .par_iter()
        .enumerate()
        .map(|(i, dir)| {
            let rows =
                match load_sample(dir).with_context(|| format!("sample {}", dir.display()))? {
                    Some(s) => {
                        let stride = (s.lum.width * s.lum.height).div_ceil(args.pixels);
                        Some(training_rows(&s.lum, s.horizon, &s.truth, stride, i)?)
                    }
                    None => None,
                };
            bar.inc(1);
            Ok(rows)
        })
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let skipped = parts.iter().filter(|p| p.is_none()).count();
    if skipped > 0 {
        eprintln!("{skipped} training samples have no road mask and were skipped");
    }
    let mut data = Dataset::new(FEATURES.len());
    for p in parts.iter().flatten() {
        data.extend(p);
    }
    let positives = data.labels.iter().filter(|&&y| y).count();
    let model = train_trees("streak", &data, &params)?;
    let train_s = t0.elapsed().as_secs_f64();
    eprintln!("trained in {train_s:.1} s");

    let mut classifier = StreakClassifier::new(model);
    // Threshold and smoothing on every pixel of the validation samples.
    let maps = val
        .par_iter()
        .map(|dir| -> Result<Option<(GrayImage, GrayImage)>> {
            let Some(s) = load_sample(dir).with_context(|| format!("sample {}", dir.display()))?
            else {
                return Ok(None);
            };
            Ok(Some((classifier.probability(&s.lum, s.horizon)?, s.truth)))
        })
        .collect::<Result<Vec<_>>>()?;
    let maps: Vec<(GrayImage, GrayImage)> = maps.into_iter().flatten().collect();
    let best = choose_operating_point(&maps, args.precision, |smooth, point| match point {
        None => eprintln!(
            "smoothing radius {smooth}: no threshold reaches precision {}",
            args.precision
        ),
        Some(p) => eprintln!(
            "smoothing radius {smooth}, threshold {:.4}: {} split P {:.3} R {:.3} F1 {:.3}",
            p.threshold, val_name, p.score.precision, p.score.recall, p.score.f1
        ),
    });
    let Some(OperatingPoint {
        smooth,
        threshold,
        score: val_score,
    }) = best
    else {
        bail!(
            "no threshold reaches precision {} on the {} split: more training data or rounds are needed",
            args.precision,
            val_name
        );
    };
    classifier.threshold = threshold;
    classifier.smooth = smooth;
    eprintln!(
        "kept smoothing radius {smooth}, threshold {threshold:.4}: {} split P {:.3} R {:.3} over {} samples",
        val_name,
        val_score.precision,
        val_score.recall,
        maps.len()
    );
    let datasets = dataset_provenance(&args.datasets);
    // The left view's files of a sample, by their names.
    let left = 0;
    classifier.provenance = serde_json::json!({
        "trained_by": format!("streaks {} train-detector", env!("CARGO_PKG_VERSION")),
        "datasets": datasets,
        "train_split": args.train_split,
        "train_samples": train.len() - skipped,
        "rows": data.rows(),
        "positive_rows": positives,
        "pixels_per_sample": args.pixels,
        "params": params,
        "truth": format!("{} ∩ {}", SAMPLE_NAMES.streak_mask[left], SAMPLE_NAMES.road_mask[left]),
        "image": format!("{} (linear luminance)", SAMPLE_NAMES.exr[left]),
        "val_split": args.val_split,
        "val_samples": val.len(),
        "target_precision": args.precision,
        "val_score": val_score,
    });
    let json = serde_json::to_vec(&classifier)?;
    write_bytes_atomically(&args.output, &json)
        .with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "wrote {} ({} trees, {} kB)",
        args.output.display(),
        classifier.model.trees.len(),
        json.len() / 1024
    );
    Ok(())
}

/// What a trained model's provenance records of each dataset it was trained on: the folder's
/// name and the settings `dataset.json` holds.
pub(crate) fn dataset_provenance(datasets: &[PathBuf]) -> Vec<serde_json::Value> {
    datasets
        .iter()
        .map(|d| {
            let info: serde_json::Value = streaks_image::input::read_text(
                &Layout::new(d).dataset_json(),
                streaks_image::input::MAX_TEXT_BYTES,
            )
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default();
            serde_json::json!({
                "folder": d.file_name().map(|n| n.to_string_lossy().into_owned()),
                "seed": info.get("seed"),
                "count": info.get("count"),
                "config_hash": info.get("config_hash"),
                "width": info.get("width"),
                "height": info.get("height"),
                "spp": info.get("spp"),
            })
        })
        .collect()
}

/// Checks the settings a trained model's command shares (a target precision in (0, 1), at
/// least one pixel per sample, the trees' parameters) and returns the trees' parameters.
pub(crate) fn training_params(
    precision: f64,
    pixels: usize,
    params: TrainParams,
) -> Result<TrainParams> {
    if !(precision > 0.0 && precision < 1.0) {
        bail!("--precision must be in (0, 1), not {precision}");
    }
    if pixels == 0 {
        bail!("--pixels must be at least 1");
    }
    params.validate().context("training settings")?;
    Ok(params)
}

/// The training split's and the validation splits' sample folders in `datasets`, and the
/// validation splits' name (`val+test`); an error if the splits overlap or one is empty.
pub(crate) fn training_splits(
    datasets: &[PathBuf],
    train_split: &str,
    val_split: &[String],
) -> Result<(Vec<PathBuf>, Vec<PathBuf>, String)> {
    if val_split.iter().any(|s| s == train_split) {
        bail!("the training and validation splits must differ: the validation needs samples the trees did not see");
    }
    let train = split_samples(datasets, train_split)?;
    let mut val = vec![];
    for split in val_split {
        val.extend(split_samples(datasets, split)?);
    }
    let val_name = val_split.join("+");
    if train.is_empty() || val.is_empty() {
        bail!(
            "need samples in both splits: {} in {:?}, {} in {:?}",
            train.len(),
            train_split,
            val.len(),
            val_name
        );
    }
    Ok((train, val, val_name))
}

/// Trains the trees of `data` with a progress bar, printing the rows, the share of positive
/// labels and the final training log-loss under `name`.
pub(crate) fn train_trees(name: &str, data: &Dataset, params: &TrainParams) -> Result<gbdt::Model> {
    let positives = data.labels.iter().filter(|&&y| y).count();
    eprintln!(
        "{name}: {} rows, {:.2} % positive; training {} rounds",
        data.rows(),
        100.0 * positives as f64 / data.rows().max(1) as f64,
        params.rounds
    );
    let bar = crate::cli::progress_bar(params.rounds as u64);
    let mut last = 0.0;
    let model = gbdt::train(data, params, |_, loss| {
        last = loss;
        bar.inc(1);
    })
    .with_context(|| format!("training the {name} trees"))?;
    bar.finish_and_clear();
    eprintln!("{name}: training log-loss {last:.4}");
    Ok(model)
}
