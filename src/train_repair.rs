//! `streaks train-repair`: trains the streak-robust stereo model
//! ([`streaks_analysis::repair::RepairModel`]) on datasets of `streaks dataset generate`.
//!
//! 1. **Rows**: each sample of the training split is matched by semi-global matching at its
//!    defaults on its 8-bit PNGs (what `streaks disparity` and the benchmark see), and about
//!    `--pixels` of its pixels give rows of [`FEATURES`]: labelled *wrong* (semi-global
//!    matching's value more than 1 px beneath the truth or more than 2 px off), for the pixels
//!    with a value, and *road streak* (`streaks0.png` ∩ `road0.png`), for all.
//! 2. **Trees**: gradient boosting of each label ([`streaks_analysis::gbdt`]).
//! 3. **Operating point and calibration**, over every pixel of the validation split (samples
//!    the trees never saw, of other streets): the streak mask's smoothing and threshold for
//!    `--precision`, then the whole repair, whose right shares per `wrong` decile and per
//!    repair window are the confidence map's calibration. The validation figures (phantom
//!    holes, off-road bad-2, densities, the streak mask's score) are printed and recorded.
//!
//! Everything is deterministic: the same datasets and settings give the same file, whatever
//! the number of threads.

use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use streaks_analysis::gbdt::{self, Dataset, TrainParams};
use streaks_analysis::repair::{
    is_right, robust_from_features, streak_objects, RepairCounts, RepairModel, StereoFeatures,
    StreakHandling, FEATURES,
};
use streaks_analysis::sgm::{sgm, SgmParams};
use streaks_analysis::streak_classifier::{smooth_probability, SMOOTHING_RADII};
use streaks_dataset::files::{load_mask, SampleDir, SAMPLE_NAMES};
use streaks_image::pfm::read_pfm;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::rig::Eye;

use crate::cli::sample_truths;
use crate::train_detector::{dataset_provenance, split_samples};

/// Train the streak-robust stereo model on datasets.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Dataset folders (with dataset.json) to train on; their samples need the `images`,
    /// `gt` and `masks` groups.
    #[arg(required = true)]
    pub datasets: Vec<PathBuf>,
    /// The model to write (JSON).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The split whose samples train the trees.
    #[arg(long, default_value = "train")]
    pub train_split: String,
    /// The splits whose samples choose the streak mask's threshold and calibrate the
    /// confidence, comma-separated (other streets than the training split's).
    #[arg(long, default_value = "val", value_delimiter = ',')]
    pub val_split: Vec<String>,
    /// The precision the streak mask's threshold is chosen for, on the validation split.
    #[arg(long, default_value_t = 0.9)]
    pub precision: f64,
    /// Training pixels per sample (every k-th pixel, k = pixels in the image / this).
    #[arg(long, default_value_t = 20_000)]
    pub pixels: usize,
    /// Boosting rounds of each classifier.
    #[arg(long, default_value_t = 150)]
    pub rounds: usize,
    /// Learning rate.
    #[arg(long, default_value_t = TrainParams::default().learning_rate)]
    pub learning_rate: f32,
    /// Most leaves per tree.
    #[arg(long, default_value_t = 15)]
    pub max_leaves: usize,
    /// Fewest training rows in a leaf: large, because a street's pixels are far from
    /// independent and small leaves learn the training streets.
    #[arg(long, default_value_t = 1000)]
    pub min_leaf: usize,
}

/// A sample matched and described: its features, semi-global matching's map, the truth and
/// the masks.
struct Sample {
    features: StereoFeatures,
    sgm: GrayImage,
    truth: GrayImage,
    road: GrayImage,
    road_streaks: GrayImage,
}

fn load_sample(dir: &Path) -> Result<Option<Sample>> {
    let sample = SampleDir::new(dir);
    let meta = sample.load_meta()?;
    let (_, on_road) = sample_truths(&sample, &meta)?;
    let Some(road_streaks) = on_road else {
        return Ok(None);
    };
    let size = (meta.rig.width as usize, meta.rig.height as usize);
    let road = load_mask(&sample.road_mask(Eye::Left), size, "the image")?;
    let read =
        |p: PathBuf| GrayImage::load(&p).with_context(|| format!("cannot read {}", p.display()));
    let left = read(sample.png(Eye::Left))?;
    let right = read(sample.png(Eye::Right))?;
    let truth_path = sample.disparity(Eye::Left);
    let truth =
        read_pfm(&truth_path).with_context(|| format!("cannot read {}", truth_path.display()))?;
    if left.size() != truth.size() || right.size() != truth.size() || road.size() != truth.size() {
        bail!(
            "{}: the images, masks and ground truth differ in size",
            dir.display()
        );
    }
    let sgm = sgm(&left, &right, &SgmParams::default())?;
    let features = StereoFeatures::new(&left, &right, &sgm)?;
    Ok(Some(Sample {
        features,
        sgm,
        truth,
        road,
        road_streaks,
    }))
}

/// Rows of every `stride`-th pixel from `offset`: (wrong rows, streak rows).
fn rows(s: &Sample, stride: usize, offset: usize) -> (Dataset, Dataset) {
    let mut wrong = Dataset::new(FEATURES.len());
    let mut streak = Dataset::new(FEATURES.len());
    let mut row = [0f32; FEATURES.len()];
    let n = s.truth.data.len();
    for i in (offset % stride..n).step_by(stride) {
        let t = s.truth.data[i];
        if !t.is_finite() {
            continue;
        }
        s.features.row(i, &mut row);
        streak.push(&row, s.road_streaks.data[i] > 0.0);
        let e = s.sgm.data[i];
        if e.is_finite() && e > 0.0 {
            wrong.push(&row, !is_right(e, t));
        }
    }
    (wrong, streak)
}

fn train_one(name: &str, data: &Dataset, params: &TrainParams) -> Result<gbdt::Model> {
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

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    if !(args.precision > 0.0 && args.precision < 1.0) {
        bail!("--precision must be in (0, 1), not {}", args.precision);
    }
    if args.pixels == 0 {
        bail!("--pixels must be at least 1");
    }
    if args.val_split.contains(&args.train_split) {
        bail!("the training and validation splits must differ: the calibration needs samples the trees did not see");
    }
    let params = TrainParams {
        rounds: args.rounds,
        learning_rate: args.learning_rate,
        max_leaves: args.max_leaves,
        min_leaf: args.min_leaf,
        ..TrainParams::default()
    };
    params.validate().context("training settings")?;
    let train = split_samples(&args.datasets, &args.train_split)?;
    let mut val = vec![];
    for split in &args.val_split {
        val.extend(split_samples(&args.datasets, split)?);
    }
    let val_name = args.val_split.join("+");
    if train.is_empty() || val.is_empty() {
        bail!(
            "need samples in both splits: {} in {:?}, {} in {:?}",
            train.len(),
            args.train_split,
            val.len(),
            val_name
        );
    }
    let t0 = std::time::Instant::now();
    eprintln!("matching and reading {} training samples", train.len());
    let bar = crate::cli::progress_bar(train.len() as u64);
    let parts = train
        .par_iter()
        .enumerate()
        .map(|(k, dir)| {
            let s = load_sample(dir).with_context(|| format!("sample {}", dir.display()))?;
            bar.inc(1);
            Ok(s.map(|s| {
                let stride = s.truth.data.len().div_ceil(args.pixels);
                rows(&s, stride, k)
            }))
        })
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let skipped = parts.iter().filter(|p| p.is_none()).count();
    if skipped > 0 {
        eprintln!("{skipped} training samples have no road mask and were skipped");
    }
    let mut wrong_rows = Dataset::new(FEATURES.len());
    let mut streak_rows = Dataset::new(FEATURES.len());
    for (w, s) in parts.iter().flatten() {
        wrong_rows.extend(w);
        streak_rows.extend(s);
    }
    let wrong = train_one("wrong", &wrong_rows, &params)?;
    let streak = train_one("streak", &streak_rows, &params)?;
    let train_s = t0.elapsed().as_secs_f64();
    eprintln!("trained in {train_s:.1} s");

    let mut model = RepairModel::new(wrong, streak);
    eprintln!("matching {} validation samples", val.len());
    let bar = crate::cli::progress_bar(val.len() as u64);
    let val_samples: Vec<Sample> = val
        .par_iter()
        .map(|dir| {
            let s = load_sample(dir).with_context(|| format!("sample {}", dir.display()));
            bar.inc(1);
            s
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    bar.finish_and_clear();
    // The streak mask's operating point: per smoothing radius and threshold, the streak-level
    // precision and recall over the validation samples; the most recall at `--precision`.
    let probabilities: Vec<GrayImage> = val_samples
        .iter()
        .map(|s| s.features.probability(&model.streak))
        .collect();
    let mut best: Option<(usize, f32, f64, f64)> = None;
    for smooth in SMOOTHING_RADII {
        let smoothed: Vec<GrayImage> = probabilities
            .iter()
            .map(|p| smooth_probability(p, smooth))
            .collect();
        for k in 1..20 {
            let t = k as f32 * 0.05;
            let (mut found, mut truths, mut correct, mut detected) = (0, 0, 0, 0);
            for (p, s) in smoothed.iter().zip(&val_samples) {
                let mut mask = p.clone();
                for v in &mut mask.data {
                    *v = f32::from(u8::from(*v >= t));
                }
                let c = streak_objects(&mask, &s.road_streaks);
                found += c.0;
                truths += c.1;
                correct += c.2;
                detected += c.3;
            }
            let precision = correct as f64 / detected.max(1) as f64;
            let recall = found as f64 / truths.max(1) as f64;
            if detected > 0 && precision >= args.precision && best.is_none_or(|b| recall > b.3) {
                best = Some((smooth, t, precision, recall));
            }
        }
    }
    match best {
        Some((smooth, t, p, r)) => {
            model.streak_smooth = smooth;
            model.streak_threshold = t;
            eprintln!(
                "streak mask: smoothing radius {smooth}, threshold {t:.2}: {val_name} streak-level P {p:.3} R {r:.3}"
            );
        }
        None => eprintln!(
            "no streak threshold reaches streak-level precision {} on the {val_name} split: keeping 0.5",
            args.precision
        ),
    }
    // The drop threshold: a value is dropped where it is more likely wrong than a repair is,
    // so it is measured from the repairs at the default threshold first.
    let pass = |model: &RepairModel| {
        let mut counts = RepairCounts::default();
        for s in &val_samples {
            let r = robust_from_features(&s.features, &s.sgm, StreakHandling::Repair, model);
            counts.add(&s.sgm, &r, model, &s.truth, &s.road, &s.road_streaks);
        }
        counts
    };
    let first = pass(&model);
    let (right, all) = first
        .repaired
        .iter()
        .fold((0, 0), |(r, a), &(x, y)| (r + x, a + y));
    if all > 0 {
        model.wrong_threshold = 1.0 - right as f32 / all as f32;
        eprintln!(
            "repairs at threshold 0.5 are right at {:.3}: values are dropped at a wrong probability of {:.3}",
            right as f32 / all as f32,
            model.wrong_threshold
        );
    }
    let counts = pass(&model);
    model.calibration = counts.calibration();
    let (ph_sgm, ph) = counts.phantom();
    let (off_sgm, off) = counts.off_road_bad2();
    let score = counts.streak_score();
    let (level_p, level_r) = counts.streak_level();
    let pct = |v: f64| 100.0 * v;
    eprintln!(
        "{val_name} split, {} samples: phantom holes {:.2} % -> {:.2} %; off-road bad-2 {:.2} % -> {:.2} %; road density {:.1} % -> {:.1} %, off-road {:.1} % -> {:.1} %; streak mask P {:.3} R {:.3} (pixels), P {:.3} R {:.3} (streaks)",
        val_samples.len(),
        pct(ph_sgm),
        pct(ph),
        pct(off_sgm),
        pct(off),
        pct(counts.road_valid_sgm as f64 / counts.road.max(1) as f64),
        pct(counts.road_valid as f64 / counts.road.max(1) as f64),
        pct(counts.off_valid_sgm as f64 / counts.off.max(1) as f64),
        pct(counts.off_valid as f64 / counts.off.max(1) as f64),
        score.precision,
        score.recall,
        level_p,
        level_r,
    );
    eprintln!(
        "calibration: kept {:?}, repaired {:?}",
        model.calibration.kept, model.calibration.repaired
    );
    let left = 0;
    model.provenance = serde_json::json!({
        "trained_by": format!("streaks {} train-repair", env!("CARGO_PKG_VERSION")),
        "datasets": dataset_provenance(&args.datasets),
        "train_split": args.train_split,
        "train_samples": train.len() - skipped,
        "wrong_rows": wrong_rows.rows(),
        "streak_rows": streak_rows.rows(),
        "pixels_per_sample": args.pixels,
        "params": params,
        "images": format!("{} and {} (8-bit, luminance)", SAMPLE_NAMES.png[0], SAMPLE_NAMES.png[1]),
        "streak_truth": format!("{} ∩ {}", SAMPLE_NAMES.streak_mask[left], SAMPLE_NAMES.road_mask[left]),
        "sgm": "SgmParams::default()",
        "val_split": args.val_split,
        "val_samples": val_samples.len(),
        "target_precision": args.precision,
        "val_figures": {
            "phantom_holes_sgm": ph_sgm,
            "phantom_holes": ph,
            "off_road_bad2_sgm": off_sgm,
            "off_road_bad2": off,
            "streak_mask": score,
            "streak_level_precision": level_p,
            "streak_level_recall": level_r,
        },
        "train_seconds": train_s,
    });
    let json = serde_json::to_vec(&model)?;
    write_bytes_atomically(&args.output, &json)
        .with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "wrote {} ({} + {} trees, {} kB)",
        args.output.display(),
        model.wrong.trees.len(),
        model.streak.trees.len(),
        json.len() / 1024
    );
    Ok(())
}
