//! `streaks detect`: specular streak detection ([`streaks_analysis::detector`]) on one image,
//! or scored over a dataset of `streaks dataset generate` against the renderer's masks.
//!
//! Two detectors: `learned`, the per-pixel classifier of
//! [`streaks_analysis::streak_classifier`] on linear luminance (the one shipped with the crate,
//! or `--model FILE` from `streaks train-detector`), the default on linear input (EXR, and
//! datasets); and `hand`, the region-growing detector of [`streaks_analysis::detect`], the
//! default on 8-bit images, where it does better than the classifier.
//!
//! On an image it writes the detector's mask (PNG, 0/255) and, with `--truth MASK`, prints
//! precision and recall against it. On a dataset folder it runs the detector on each sample's
//! left image (`im0.exr` for `learned`, `im0.png` for `hand`, as a photograph would be;
//! `--image` picks), with the horizon of the sample's own camera (`meta.json`), and scores it
//! against two truths:
//!
//! - **all**: the renderer's streak mask `streaks0.png` (every pixel whose light is mostly a
//!   glossy reflection of an emitter: road streaks, but also glints on windows and car bodies);
//! - **road**: the part of it on the road surface (`road0.png`): the streaks that fool stereo
//!   into phantom holes, and the target of the detector.
//!
//! Scores are pixel-pooled over the samples (counts summed) and also listed per sample;
//! `-o FILE` writes them as JSON.

use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use streaks_analysis::detect::{score_mask, DetectParams};
use streaks_analysis::detector::{DatasetScore, Detector, Found, SampleScore};
use streaks_analysis::streak_classifier::StreakClassifier;
use streaks_dataset::files::{SampleDir, SAMPLE_NAMES};
use streaks_dataset::layout::Layout;
use streaks_dataset::DatasetError;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::rig::Eye;

/// Detect specular streaks in an image, or score the detector over a dataset.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// An image (PNG, JPEG, EXR), or a dataset folder (with dataset.json).
    pub input: PathBuf,
    /// Image: the mask to write (PNG, 255 on streak pixels) [default: INPUT_streaks.png].
    /// Dataset: the scores as JSON.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Image: a ground-truth mask (PNG, non-zero = streak) to score the detection against.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Image: the horizon row (image y) [default: the image centre, a level camera].
    /// Dataset: ignored (each sample's camera gives it).
    #[arg(long)]
    pub horizon: Option<f32>,
    /// Dataset: only the samples of this split (train, val, test).
    #[arg(long)]
    pub split: Option<String>,
    /// Dataset: which left image to run on [default: exr for the learned detector, png for
    /// the hand-built one].
    #[arg(long, value_enum)]
    pub image: Option<ImageKind>,
    /// The detector [default: learned on linear input (an EXR image; a dataset, whose im0.exr
    /// it reads), hand on 8-bit images (PNG, JPEG; a dataset with --image png), where the
    /// learned one has lost what it needs; --model or --threshold ask for learned, the
    /// hand-built detector's settings for hand].
    #[arg(long, value_enum)]
    pub detector: Option<DetectorKind>,
    /// Learned detector: a classifier of `streaks train-detector` [default: the one shipped
    /// with streaks, trained on procedural streets].
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Learned detector: the probability threshold [default: the classifier's own, chosen at
    /// training for its target precision].
    #[arg(long)]
    pub threshold: Option<f32>,
    /// Hand-built detector settings (see `streaks_analysis::detect::DetectParams`; defaults
    /// there).
    #[command(flatten)]
    pub params: ParamArgs,
}

/// The two detectors.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DetectorKind {
    /// The per-pixel classifier on linear luminance (`streaks_analysis::streak_classifier`).
    Learned,
    /// The region-growing detector for 8-bit images (`streaks_analysis::detect`).
    Hand,
}

/// The detector `args` ask for (see `--detector`), for a dataset (`dataset`) or an image.
pub fn detector_kind(args: &Args, dataset: bool) -> DetectorKind {
    if let Some(k) = args.detector {
        return k;
    }
    if args.model.is_some() || args.threshold.is_some() {
        return DetectorKind::Learned;
    }
    if args.params != ParamArgs::default() {
        return DetectorKind::Hand;
    }
    let linear = if dataset {
        args.image != Some(ImageKind::Png)
    } else {
        args.input
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    };
    if linear {
        DetectorKind::Learned
    } else {
        DetectorKind::Hand
    }
}

/// The detector of kind `kind` with the arguments' settings: loads and checks `--model`.
pub fn detector_from_args(args: &Args, kind: DetectorKind) -> Result<Detector> {
    match kind {
        DetectorKind::Hand => {
            if args.model.is_some() || args.threshold.is_some() {
                bail!("--model and --threshold apply to --detector learned");
            }
            args.params
                .params(None)
                .validate()
                .context("detector parameters")?;
            Ok(Detector::Hand(args.params.params(None)))
        }
        DetectorKind::Learned => {
            if args.params != ParamArgs::default() {
                bail!("the hand-built detector's settings need --detector hand");
            }
            let mut c = match &args.model {
                Some(p) => load_classifier(p)?,
                None => StreakClassifier::shipped(),
            };
            if let Some(t) = args.threshold {
                if !(0.0..=1.0).contains(&t) {
                    bail!("--threshold {t} is not a probability in [0, 1]");
                }
                c.threshold = t;
            }
            Ok(Detector::Learned(Box::new(c)))
        }
    }
}

/// The dataset image `detector` reads by default.
fn default_image(detector: &Detector) -> ImageKind {
    if detector.reads_linear() {
        ImageKind::Exr
    } else {
        ImageKind::Png
    }
}

/// Runs `detector` on the image at `path` (read as linear or 8-bit luminance, as the detector
/// wants) with the horizon at row `horizon` (`None`: the image centre).
pub fn detect_file(detector: &Detector, path: &Path, horizon: Option<f32>) -> Result<Found> {
    let image = if detector.reads_linear() {
        GrayImage::load_linear(path)
    } else {
        GrayImage::load(path)
    }
    .with_context(|| format!("cannot read {}", path.display()))?;
    detector
        .detect(&image, horizon)
        .with_context(|| format!("detecting streaks in {}", path.display()))
}

/// Loads and checks a classifier file.
pub fn load_classifier(path: &Path) -> Result<StreakClassifier> {
    let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
        .with_context(|| format!("cannot read the classifier {}", path.display()))?;
    StreakClassifier::from_json(&text)
        .with_context(|| format!("{} is not a usable streak classifier", path.display()))
}

/// Which image of a dataset sample the detector sees.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// `im0.png`: 8-bit sRGB at the sample's exposure, as a camera gives.
    Png,
    /// `im0.exr`: linear radiance.
    Exr,
}

/// Overrides of the detector's parameters.
#[derive(clap::Args, Debug, Default, Clone, PartialEq)]
pub struct ParamArgs {
    /// Seed threshold, in noise deviations above the row's background.
    #[arg(long)]
    pub high: Option<f32>,
    /// Growth threshold, likewise.
    #[arg(long)]
    pub low: Option<f32>,
    /// Share of a row's peak contrast a streak pixel must reach.
    #[arg(long)]
    pub row_fraction: Option<f32>,
    /// Least noise deviation, as a share of the 99.9th percentile of the contrasts.
    #[arg(long)]
    pub noise_floor: Option<f32>,
    /// Fewest rows of a streak.
    #[arg(long)]
    pub min_rows: Option<usize>,
    /// Smallest ratio of height to mean width of a streak.
    #[arg(long)]
    pub min_elongation: Option<f32>,
    /// Largest |slope| of a streak's axis (pixels of x per row).
    #[arg(long)]
    pub max_slope: Option<f32>,
    /// Radius of the box filter before thresholding.
    #[arg(long)]
    pub smooth_radius: Option<usize>,
    /// Width of the window whose median is a pixel's background, as a share of the image
    /// width (0: the whole row).
    #[arg(long)]
    pub background_width: Option<f32>,
    /// Brightness-gap ratio for cutting a region (0 disables).
    #[arg(long)]
    pub gap: Option<f32>,
    /// Head ratio for splitting a lamp off its streak (0 disables).
    #[arg(long)]
    pub head_ratio: Option<f32>,
}

impl ParamArgs {
    /// The detector parameters: the defaults with these overrides and `horizon`.
    pub fn params(&self, horizon: Option<f32>) -> DetectParams {
        let d = DetectParams::default();
        DetectParams {
            horizon,
            high: self.high.unwrap_or(d.high),
            low: self.low.unwrap_or(d.low),
            row_fraction: self.row_fraction.unwrap_or(d.row_fraction),
            noise_floor: self.noise_floor.unwrap_or(d.noise_floor),
            min_rows: self.min_rows.unwrap_or(d.min_rows),
            min_elongation: self.min_elongation.unwrap_or(d.min_elongation),
            max_slope: self.max_slope.unwrap_or(d.max_slope),
            smooth_radius: self.smooth_radius.unwrap_or(d.smooth_radius),
            background_width: self.background_width.unwrap_or(d.background_width),
            gap: self.gap.unwrap_or(d.gap),
            head_ratio: self.head_ratio.unwrap_or(d.head_ratio),
        }
    }
}

/// Image file name of a dataset sample's left view.
fn image_file(kind: ImageKind) -> &'static str {
    let left = 0;
    match kind {
        ImageKind::Png => SAMPLE_NAMES.png[left],
        ImageKind::Exr => SAMPLE_NAMES.exr[left],
    }
}

/// Scores the detector on one sample folder.
/// With the learned detector, also its (probability, road truth) per pixel.
fn score_sample(
    sample: &SampleDir,
    id: &str,
    kind: ImageKind,
    detector: &Detector,
) -> Result<(SampleScore, Vec<(f32, bool)>)> {
    let meta = sample.load_meta()?;
    let image = match kind {
        ImageKind::Png => sample.png(Eye::Left),
        ImageKind::Exr => sample.exr(Eye::Left),
    };
    let horizon = crate::cli::sample_horizon(&meta);
    let found = detect_file(detector, &image, Some(horizon))?;
    let (truth, on_road) = crate::cli::sample_truths(sample, &meta)?;
    let (score, pairs) =
        SampleScore::new(id, &meta.split, horizon, &found, &truth, on_road.as_ref())?;
    Ok((score, pairs))
}

/// Scores the detector over the dataset in `dir`.
pub fn score_dataset(
    dir: &Path,
    split: Option<&str>,
    kind: ImageKind,
    detector: &Detector,
) -> Result<DatasetScore> {
    let layout = Layout::new(dir);
    let ids = layout.sample_ids(split)?;
    let bar = crate::cli::progress_bar(ids.len() as u64);
    let samples = ids
        .par_iter()
        .map(|id| {
            let sample = layout.sample_by_id(id);
            let s = score_sample(&sample, id, kind, detector)
                .with_context(|| format!("sample {}", sample.path().display()));
            bar.inc(1);
            s
        })
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let (samples, pairs): (Vec<SampleScore>, Vec<Vec<(f32, bool)>>) = samples.into_iter().unzip();
    let pairs: Vec<(f32, bool)> = pairs.into_iter().flatten().collect();
    Ok(DatasetScore::pooled(
        dir.to_path_buf(),
        split.map(str::to_owned),
        image_file(kind).into(),
        samples,
        pairs,
    ))
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let dataset = Layout::new(&args.input).dataset_json().is_file();
    let detector = detector_from_args(&args, detector_kind(&args, dataset))?;
    if dataset {
        let kind = args.image.unwrap_or(default_image(&detector));
        let score = score_dataset(&args.input, args.split.as_deref(), kind, &detector)?;
        eprint!("{}", score.table());
        if let Some(out) = &args.output {
            let json = serde_json::to_vec_pretty(&score)?;
            write_bytes_atomically(out, &json)
                .with_context(|| format!("writing {}", out.display()))?;
        }
        return Ok(());
    }
    if args.input.is_dir() {
        bail!(
            "{} is a folder without dataset.json: give an image, or a dataset of `streaks \
             dataset generate`",
            args.input.display()
        );
    }
    if args.split.is_some() || args.image.is_some() {
        bail!("--split and --image apply to a dataset folder, not to an image");
    }
    // The truth is read first: a bad one stops the run before anything is written.
    let truth = match &args.truth {
        Some(t) => {
            let m = GrayImage::load(t).with_context(|| format!("cannot read {}", t.display()))?;
            Some((t, m))
        }
        None => None,
    };
    let found = detect_file(&detector, &args.input, args.horizon)?;
    let (w, h) = (found.mask.width, found.mask.height);
    if let Some((t, m)) = &truth {
        DatasetError::check_size(t, (m.width, m.height), (w, h), "the image")?;
    }
    let out = args.output.clone().unwrap_or_else(|| {
        let stem = args
            .input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "image".into());
        args.input.with_file_name(format!("{stem}_streaks.png"))
    });
    found
        .mask
        .save_png(&out)
        .with_context(|| format!("writing the mask {}", out.display()))?;
    let pixels = found.mask.data.iter().filter(|&&v| v > 0.5).count();
    let horizon = args.horizon.unwrap_or(0.5 * h as f32);
    match found.streaks {
        Some(n) => eprintln!(
            "{n} streaks, {pixels} pixels (horizon at row {horizon:.1}); mask in {}",
            out.display()
        ),
        None => eprintln!(
            "{pixels} streak pixels ({:.2} %, horizon at row {horizon:.1}); mask in {}",
            100.0 * pixels as f64 / (w * h) as f64,
            out.display()
        ),
    }
    if let Some((_, t)) = &truth {
        let s = score_mask(&found.mask, t)?;
        println!("{}", serde_json::to_string_pretty(&s)?);
    }
    Ok(())
}
