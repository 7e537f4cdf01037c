//! `streaks train-repair`: trains the streak-robust stereo model
//! ([`streaks_analysis::repair::RepairModel`]) on datasets of `streaks dataset generate`.
//!
//! 1. **Rows**: each sample of the training split is matched by semi-global matching at its
//!    defaults on its 8-bit PNGs (what `streaks disparity` and the benchmark see), and about
//!    `--pixels` of its pixels give rows of [`FEATURES`]: labelled *wrong* (semi-global
//!    matching's value more than 1 px beneath the truth or more than 2 px off), for the pixels
//!    with a value, and *road streak* (`streaks0.png` ∩ `road0.png`), for all.
//! 2. **Trees**: gradient boosting of each label ([`streaks_analysis::gbdt`]); then, unless
//!    `--first-stage-only`, the second stage: the first stage's trees are trained again on
//!    each half of the training samples and give the other half its probabilities (out of
//!    fold, as the trees will meet streets they never saw), whose context planes
//!    ([`StereoFeatures::context`]) join the features of a second pair of classifiers.
//! 3. **Operating point and calibration**, over every pixel of the validation split (samples
//!    the trees never saw, of other streets) and of every sample of the `--val-dataset`s:
//!    the streak mask's smoothing, threshold and lower (hysteresis) threshold for
//!    `--precision`, then the whole repair, whose right
//!    shares per `wrong` decile and per repair window are the confidence map's calibration.
//!    The validation figures (phantom holes, off-road bad-2, densities, the streak mask's
//!    score) are printed and recorded.
//!
//! Everything is deterministic: the same datasets and settings give the same file, whatever
//! the number of threads.

use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use streaks_analysis::benchmark::breakdown::{Bin, STREAK_LENGTH_BINS};
use streaks_analysis::gbdt::{Dataset, TrainParams};
use streaks_analysis::repair::{
    is_right, probabilities, robust_from_features, streak_objects, ContextStage, RepairCounts,
    RepairModel, StereoFeatures, StreakHandling, FEATURES, STREAK_CONTRAST_BINS,
};
use streaks_analysis::sgm::{sgm, SgmParams};
use streaks_analysis::streak_classifier::{smooth_probability, streak_mask, SMOOTHING_RADII};
use streaks_dataset::files::{load_mask, SampleDir, SAMPLE_NAMES};
use streaks_dataset::layout::Layout;
use streaks_image::pfm::read_pfm;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::rig::Eye;

use crate::cli::sample_truths;
use crate::train_detector::{
    dataset_provenance, split_samples, train_trees, training_params, training_splits,
};
use streaks_analysis::detector::road_streaks;

/// Train the streak-robust stereo model on datasets.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Dataset folders (with dataset.json) to train on; their samples need the `images`,
    /// `gt` and `masks` groups. With --evaluate, pair folders too.
    #[arg(required = true)]
    pub datasets: Vec<PathBuf>,
    /// The model to write (JSON); with --evaluate, where the figures go (JSON), if anywhere.
    #[arg(short, long, required_unless_present = "evaluate")]
    pub output: Option<PathBuf>,
    /// Train nothing: score a model (--model, else the shipped one) on DIRS, which may be
    /// datasets (their --val-split samples; `all` for every sample) and `streaks stereo` pair
    /// folders, and print the figures the training prints for its validation split.
    #[arg(long)]
    pub evaluate: bool,
    /// With --evaluate: the model to score.
    #[arg(long, requires = "evaluate")]
    pub model: Option<PathBuf>,
    /// The split whose samples train the trees.
    #[arg(long, default_value = "train")]
    pub train_split: String,
    /// The splits whose samples choose the streak mask's threshold, the drop threshold and
    /// calibrate the confidence, comma-separated (other streets than the training split's).
    #[arg(long, default_value = "val,test", value_delimiter = ',')]
    pub val_split: Vec<String>,
    /// Datasets whose every sample joins the validation: more streets to choose the operating
    /// point and calibrate on than the --val-split samples of DATASETS (none of them trains
    /// a tree).
    #[arg(long = "val-dataset", value_name = "DIR", conflicts_with = "evaluate")]
    pub val_datasets: Vec<PathBuf>,
    /// The precision the streak mask's threshold is chosen for, on the validation split.
    #[arg(long, default_value_t = 0.9)]
    pub precision: f64,
    /// Training pixels per sample (every k-th pixel, k = pixels in the image / this).
    #[arg(long, default_value_t = 20_000)]
    pub pixels: usize,
    /// Boosting rounds of each classifier. The defaults of these four are the shipped
    /// model's.
    #[arg(long, default_value_t = 300)]
    pub rounds: usize,
    /// Learning rate.
    #[arg(long, default_value_t = TrainParams::default().learning_rate)]
    pub learning_rate: f32,
    /// Most leaves per tree.
    #[arg(long, default_value_t = 31)]
    pub max_leaves: usize,
    /// Fewest training rows in a leaf: large, because a street's pixels are far from
    /// independent and small leaves learn the training streets.
    #[arg(long, default_value_t = 500)]
    pub min_leaf: usize,
    /// Train the first stage only. By default a second stage decides again from the
    /// features and the first stage's probabilities pooled over columns, rows and squares,
    /// trained on first-stage probabilities of streets those trees did not see (two folds of
    /// the training samples): four times the trees.
    #[arg(long)]
    pub first_stage_only: bool,
}

/// A sample matched and described: its features, semi-global matching's map, the truth and
/// the masks.
struct Sample {
    /// The left image's luminance (the streak-level score's contrast).
    left: GrayImage,
    features: StereoFeatures,
    sgm: GrayImage,
    truth: GrayImage,
    road: GrayImage,
    road_streaks: GrayImage,
}

fn load_sample(dir: &Path) -> Result<Option<Sample>> {
    let sample = SampleDir::new(dir);
    let read =
        |p: PathBuf| GrayImage::load(&p).with_context(|| format!("cannot read {}", p.display()));
    let left = read(sample.png(Eye::Left))?;
    let right = read(sample.png(Eye::Right))?;
    let size = (left.width, left.height);
    let (road, road_streaks) = if sample.meta().is_file() {
        let meta = sample.load_meta()?;
        let (_, on_road) = sample_truths(&sample, &meta)?;
        let Some(road_streaks) = on_road else {
            return Ok(None);
        };
        let road = load_mask(&sample.road_mask(Eye::Left), size, "the image")?;
        (road, road_streaks)
    } else {
        // A `streaks stereo` pair folder: its masks, if the scene flags a road.
        if !sample.road_mask(Eye::Left).is_file() {
            return Ok(None);
        }
        let road = load_mask(&sample.road_mask(Eye::Left), size, "the image")?;
        let streaks = load_mask(&sample.streak_mask(Eye::Left), size, "the image")?;
        let on_road = road_streaks(&streaks, &road);
        (road, on_road)
    };
    let truth_path = sample.disparity(Eye::Left);
    let truth =
        read_pfm(&truth_path).with_context(|| format!("cannot read {}", truth_path.display()))?;
    if right.size() != left.size() || truth.size() != left.size() {
        bail!(
            "{}: the images and the ground truth differ in size",
            dir.display()
        );
    }
    let sgm = sgm(&left, &right, &SgmParams::default())?;
    let features = StereoFeatures::new(&left, &right, &sgm)?;
    Ok(Some(Sample {
        left,
        features,
        sgm,
        truth,
        road,
        road_streaks,
    }))
}

/// Rows of every `stride`-th pixel from `offset`, of the features followed by the `extra`
/// planes: (wrong rows, streak rows).
fn rows(s: &Sample, extra: &[Vec<f32>], stride: usize, offset: usize) -> (Dataset, Dataset) {
    let width = FEATURES.len() + extra.len();
    let mut wrong = Dataset::new(width);
    let mut streak = Dataset::new(width);
    let mut row = vec![0f32; width];
    let n = s.truth.data.len();
    for i in (offset % stride..n).step_by(stride) {
        let t = s.truth.data[i];
        if !t.is_finite() {
            continue;
        }
        s.features.row_with(extra, i, &mut row);
        streak.push(&row, s.road_streaks.data[i] > 0.0);
        let e = s.sgm.data[i];
        if e.is_finite() && e > 0.0 {
            wrong.push(&row, !is_right(e, t));
        }
    }
    (wrong, streak)
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
    if args.evaluate {
        return evaluate(&args);
    }
    let Some(output) = args.output.clone() else {
        bail!("--output is needed to train");
    };
    if let Some(d) = args
        .val_datasets
        .iter()
        .find(|d| args.datasets.iter().any(|t| same_folder(t, d)))
    {
        bail!(
            "{} is both a training dataset and a validation dataset: the validation needs streets the trees did not see",
            d.display()
        );
    }
    let (train, mut val, mut val_name) =
        training_splits(&args.datasets, &args.train_split, &args.val_split)?;
    for d in &args.val_datasets {
        val.extend(all_samples(d)?);
        val_name.push_str(&format!(" and all of {}", d.display()));
    }
    let t0 = std::time::Instant::now();
    eprintln!("matching and reading {} training samples", train.len());
    let train_samples = load_samples(&train)?;
    let skipped = train.len() - train_samples.len();
    if skipped > 0 {
        eprintln!("{skipped} training samples have no road mask and were skipped");
    }
    let stride = |s: &Sample| s.truth.data.len().div_ceil(args.pixels);
    let parts: Vec<(Dataset, Dataset)> = train_samples
        .par_iter()
        .enumerate()
        .map(|(k, s)| rows(s, &[], stride(s), k))
        .collect();
    let gather = |parts: &[(Dataset, Dataset)], take: &dyn Fn(usize) -> bool| {
        let width = parts.first().map_or(FEATURES.len(), |p| p.0.features);
        let (mut wrong, mut streak) = (Dataset::new(width), Dataset::new(width));
        for (k, (w, s)) in parts.iter().enumerate() {
            if take(k) {
                wrong.extend(w);
                streak.extend(s);
            }
        }
        (wrong, streak)
    };
    let (wrong_rows, streak_rows) = gather(&parts, &|_| true);
    let wrong = train_trees("wrong", &wrong_rows, &params)?;
    let streak = train_trees("streak", &streak_rows, &params)?;
    let mut model = RepairModel::new(wrong, streak);
    let mut context_rows = None;
    if !args.first_stage_only {
        // The second stage learns from first-stage probabilities of streets those trees did
        // not see, as it will meet them: out of fold, two folds of the training samples.
        let mut first: Vec<Option<(GrayImage, GrayImage)>> = vec![None; train_samples.len()];
        for fold in 0..2 {
            eprintln!("context fold {}/2", fold + 1);
            let (w, s) = gather(&parts, &|k| k % 2 != fold);
            let fold_model = RepairModel::new(
                train_trees("wrong (fold)", &w, &params)?,
                train_trees("streak (fold)", &s, &params)?,
            );
            for (k, sample) in train_samples.iter().enumerate() {
                if k % 2 == fold {
                    first[k] = Some(probabilities(&sample.features, &sample.sgm, &fold_model));
                }
            }
        }
        let parts2: Vec<(Dataset, Dataset)> = train_samples
            .par_iter()
            .zip(&first)
            .enumerate()
            .map(|(k, (s, p))| {
                let (wrong, streak) = p.as_ref().expect("every sample is in a fold");
                let extra = s.features.context(&s.sgm, wrong, streak);
                rows(s, &extra, stride(s), k)
            })
            .collect();
        drop(first);
        let (w2, s2) = gather(&parts2, &|_| true);
        model.context = Some(ContextStage::new(
            train_trees("wrong (second stage)", &w2, &params)?,
            train_trees("streak (second stage)", &s2, &params)?,
        ));
        context_rows = Some((w2.rows(), s2.rows()));
    }
    drop(train_samples);
    let train_s = t0.elapsed().as_secs_f64();
    eprintln!("trained in {train_s:.1} s");

    eprintln!("matching {} validation samples", val.len());
    let val_samples = load_samples(&val)?;
    // The streak mask's operating point: per smoothing radius, threshold and hysteresis
    // (lower) threshold, the streak-level precision and recall over the validation samples;
    // the most recall at `--precision`.
    let probabilities: Vec<GrayImage> = val_samples
        .iter()
        .map(|s| probabilities(&s.features, &s.sgm, &model).1)
        .collect();
    let mut best: Option<(usize, f32, Option<f32>, f64, f64)> = None;
    for smooth in SMOOTHING_RADII {
        let smoothed: Vec<GrayImage> = probabilities
            .iter()
            .map(|p| smooth_probability(p, smooth))
            .collect();
        for k in 1..20 {
            let t = k as f32 * 0.05;
            let grows = std::iter::once(None).chain((1..k).map(|j| Some(j as f32 * 0.05)));
            for grow in grows {
                let (found, truths, correct, detected) = smoothed
                    .par_iter()
                    .zip(&val_samples)
                    .map(|(p, s)| streak_objects(&streak_mask(p, t, grow), &s.road_streaks))
                    .reduce(
                        || (0, 0, 0, 0),
                        |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3),
                    );
                let precision = correct as f64 / detected.max(1) as f64;
                let recall = found as f64 / truths.max(1) as f64;
                if detected > 0 && precision >= args.precision && best.is_none_or(|b| recall > b.4)
                {
                    best = Some((smooth, t, grow, precision, recall));
                }
            }
        }
    }
    match best {
        Some((smooth, t, grow, p, r)) => {
            model.streak_smooth = smooth;
            model.streak_threshold = t;
            model.streak_grow_threshold = grow;
            let grown = grow.map_or(String::new(), |g| format!(", grown down to {g:.2}"));
            eprintln!(
                "streak mask: smoothing radius {smooth}, threshold {t:.2}{grown}: {val_name} streak-level P {p:.3} R {r:.3}"
            );
        }
        None => eprintln!(
            "no streak threshold reaches streak-level precision {} on the {val_name} split: keeping 0.5",
            args.precision
        ),
    }
    // The drop threshold: a value is dropped where it is more likely wrong than a repair is
    // right, so that every value given out is at least as reliable as a repair. A missing
    // value is shown as missing (confidence 0); a wrong one is read as a surface, a phantom
    // hole among them. The repairs' precision is measured at the default threshold first.
    let pass = |model: &RepairModel| score(&val_samples, model);
    let first = pass(&model);
    let (right, all) = first
        .repaired
        .iter()
        .fold((0, 0), |(r, a), &(x, y)| (r + x, a + y));
    if all > 0 {
        let q = right as f32 / all as f32;
        model.wrong_threshold = 1.0 - q;
        eprintln!(
            "repairs at threshold 0.5 are right at {q:.3}: values are dropped at a wrong probability of {:.3}",
            model.wrong_threshold
        );
    }
    let counts = pass(&model);
    model.calibration = counts.calibration();
    let figures = print_figures(&format!("{val_name} split"), val_samples.len(), &counts);
    eprintln!(
        "confidence calibration: kept values {:?}, repaired values {:?}",
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
        "context": context_rows.map(|(wrong, streak)| serde_json::json!({
            "folds": 2,
            "wrong_rows": wrong,
            "streak_rows": streak,
        })),
        "pixels_per_sample": args.pixels,
        "params": params,
        "images": format!("{} and {} (8-bit, luminance)", SAMPLE_NAMES.png[0], SAMPLE_NAMES.png[1]),
        "streak_truth": format!("{} ∩ {}", SAMPLE_NAMES.streak_mask[left], SAMPLE_NAMES.road_mask[left]),
        "sgm": "SgmParams::default()",
        "val_split": args.val_split,
        "val_datasets": (!args.val_datasets.is_empty()).then(|| dataset_provenance(&args.val_datasets)),
        "val_samples": val_samples.len(),
        "target_precision": args.precision,
        "val_figures": figures,
        "train_seconds": train_s,
    });
    let json = serde_json::to_vec(&model)?;
    write_bytes_atomically(&output, &json)
        .with_context(|| format!("writing {}", output.display()))?;
    eprintln!(
        "wrote {} ({} + {} trees, {} kB)",
        output.display(),
        model.wrong.trees.len(),
        model.streak.trees.len(),
        json.len() / 1024
    );
    Ok(())
}

/// Matches and describes the samples of `dirs` (in parallel, with a progress bar); samples
/// without a road mask are left out.
fn load_samples(dirs: &[PathBuf]) -> Result<Vec<Sample>> {
    let bar = crate::cli::progress_bar(dirs.len() as u64);
    let samples = dirs
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
    Ok(samples)
}

/// The counts of `model`'s repair over `samples`.
fn score(samples: &[Sample], model: &RepairModel) -> RepairCounts {
    let mut counts = RepairCounts::default();
    for s in samples {
        let r = robust_from_features(&s.features, &s.sgm, StreakHandling::Repair, model);
        counts.add(
            &s.left,
            &s.sgm,
            &r,
            model,
            &s.truth,
            &s.road,
            &s.road_streaks,
        );
    }
    counts
}

/// Prints the figures of `counts` over `n` samples of `what`, and returns them as JSON.
fn print_figures(what: &str, n: usize, counts: &RepairCounts) -> serde_json::Value {
    let (ph_sgm, ph) = counts.phantom();
    let (off_sgm, off) = counts.off_road_bad2();
    let score = counts.streak_score();
    let (level_p, level_r) = counts.streak_level();
    let (mw_sgm, mw) = counts.missing_or_wrong();
    let pct = |v: f64| 100.0 * v;
    let share = |a: usize, b: usize| a as f64 / b.max(1) as f64;
    eprintln!(
        "{what}, {n} samples: phantom holes {:.2} % -> {:.2} %; off-road bad-2 {:.2} % -> {:.2} %; missing or wrong {:.2} % -> {:.2} %; road density {:.1} % -> {:.1} %, off-road {:.1} % -> {:.1} %; streak mask P {:.3} R {:.3} (pixels), P {:.3} R {:.3} (streaks: {} true, {} detected)",
        pct(ph_sgm),
        pct(ph),
        pct(off_sgm),
        pct(off),
        pct(mw_sgm),
        pct(mw),
        pct(share(counts.road_valid_sgm, counts.road)),
        pct(share(counts.road_valid, counts.road)),
        pct(share(counts.off_valid_sgm, counts.off)),
        pct(share(counts.off_valid, counts.off)),
        score.precision,
        score.recall,
        level_p,
        level_r,
        counts.streaks_true,
        counts.detections,
    );
    serde_json::json!({
        "samples": n,
        "phantom_holes_sgm": ph_sgm,
        "phantom_holes": ph,
        "off_road_bad2_sgm": off_sgm,
        "off_road_bad2": off,
        "missing_or_wrong_sgm": mw_sgm,
        "missing_or_wrong": mw,
        "road_density_sgm": share(counts.road_valid_sgm, counts.road),
        "road_density": share(counts.road_valid, counts.road),
        "off_road_density_sgm": share(counts.off_valid_sgm, counts.off),
        "off_road_density": share(counts.off_valid, counts.off),
        "streak_mask": score,
        "streak_level_precision": level_p,
        "streak_level_recall": level_r,
        "streak_recall_by_length": by_bins(&STREAK_LENGTH_BINS, &counts.streaks_by_length),
        "streak_recall_by_contrast": by_bins(&STREAK_CONTRAST_BINS, &counts.streaks_by_contrast),
        "counts": counts,
    })
}

/// Per bin: its name, the truth streaks in it and the share of them found.
fn by_bins(bins: &[Bin], counts: &[(usize, usize)]) -> serde_json::Value {
    bins.iter()
        .zip(counts)
        .map(|(b, &(found, all))| {
            serde_json::json!({
                "bin": b.name,
                "streaks": all,
                "recall": (all > 0).then(|| found as f64 / all as f64),
            })
        })
        .collect()
}

/// The folders of every sample of the dataset `d`.
fn all_samples(d: &Path) -> Result<Vec<PathBuf>> {
    let layout = Layout::new(d);
    let ids = layout
        .sample_ids(None)
        .with_context(|| format!("the samples of {}", d.display()))?;
    Ok(ids
        .iter()
        .map(|id| layout.sample_by_id(id).path().to_path_buf())
        .collect())
}

/// Whether two paths name one folder (compared canonically where they exist).
fn same_folder(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// `--evaluate`: scores a model on datasets and pair folders.
fn evaluate(args: &Args) -> Result<()> {
    let model = match &args.model {
        Some(path) => {
            let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
                .with_context(|| format!("reading the repair model {}", path.display()))?;
            RepairModel::from_json(&text)
                .with_context(|| format!("the repair model {}", path.display()))?
        }
        None => RepairModel::shipped().clone(),
    };
    let mut dirs = vec![];
    for d in &args.datasets {
        if Layout::new(d).dataset_json().is_file() {
            for split in &args.val_split {
                if split == "all" {
                    dirs.extend(all_samples(d)?);
                } else {
                    dirs.extend(split_samples(std::slice::from_ref(d), split)?);
                }
            }
        } else if SampleDir::is_pair(d) {
            dirs.push(d.clone());
        } else {
            bail!(
                "{} is neither a dataset (dataset.json) nor a pair folder (im0.png, im1.png, disp0.pfm)",
                d.display()
            );
        }
    }
    if dirs.is_empty() {
        bail!("no samples to score");
    }
    let samples = load_samples(&dirs)?;
    if samples.is_empty() {
        bail!(
            "none of the {} samples has a road mask to score against",
            dirs.len()
        );
    }
    let counts = score(&samples, &model);
    let figures = print_figures("scored", samples.len(), &counts);
    if let Some(out) = &args.output {
        write_bytes_atomically(out, &serde_json::to_vec_pretty(&figures)?)
            .with_context(|| format!("writing {}", out.display()))?;
    }
    Ok(())
}
