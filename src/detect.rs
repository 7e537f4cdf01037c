//! `streaks detect`: specular streak detection ([`streaks_analysis::detect`]) on one image, or
//! scored over a dataset of `streaks dataset generate` against the renderer's masks.
//!
//! On an image it writes the detector's mask (PNG, 0/255) and, with `--truth MASK`, prints
//! precision and recall against it. On a dataset folder it runs the detector on each sample's
//! left image (`im0.png`, as a photograph would be; `--image exr` for the linear one), with the
//! horizon of the sample's own camera (`meta.json`), and scores it against two truths:
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
use serde::Serialize;
use std::path::{Path, PathBuf};
use streaks_analysis::detect::{detect_streaks, score_mask, DetectParams, MaskScore};
use streaks_image::{write_bytes_atomically, GrayImage};

use crate::dataset::layout::Layout;
use crate::dataset::sample::SampleMeta;

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
    /// Dataset: which left image to run on.
    #[arg(long, value_enum, default_value_t = ImageKind::Png)]
    pub image: ImageKind,
    /// Detector settings (see `streaks_analysis::detect::DetectParams`; defaults there).
    #[command(flatten)]
    pub params: ParamArgs,
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
#[derive(clap::Args, Debug, Default, Clone)]
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

/// The scores of one dataset sample.
#[derive(Clone, Debug, Serialize)]
pub struct SampleScore {
    /// The sample id.
    pub id: String,
    /// Its split.
    pub split: String,
    /// The horizon row used.
    pub horizon: f32,
    /// Streaks the detector found.
    pub streaks: usize,
    /// Against `streaks0.png`.
    pub all: MaskScore,
    /// Against the part of `streaks0.png` on the road (`road0.png`); `None` without a road
    /// mask.
    pub road: Option<MaskScore>,
}

/// The scores of a dataset.
#[derive(Clone, Debug, Serialize)]
pub struct DatasetScore {
    /// The dataset folder.
    pub dataset: PathBuf,
    /// The split scored (`None`: all samples).
    pub split: Option<String>,
    /// The image the detector saw (`im0.png` or `im0.exr`).
    pub image: String,
    /// Pixel-pooled score against `streaks0.png`.
    pub all: MaskScore,
    /// Pixel-pooled score against the road's streaks (samples with a road mask).
    pub road: MaskScore,
    /// Per sample.
    pub samples: Vec<SampleScore>,
}

/// The horizon row (image y) of a sample's left camera: `c_y - f tan(pitch)`, with the pitch
/// from the rig's pose (its -Z axis, the viewing direction, `asin(z_y)` below the horizontal).
pub fn sample_horizon(meta: &SampleMeta) -> f32 {
    let rig = &meta.rig;
    let zy = rig.world_from_rig.z_axis[1].clamp(-0.999, 0.999);
    let tan_pitch = zy / (1.0 - zy * zy).sqrt();
    rig.principal_point[1] - rig.focal_px * tan_pitch
}

/// Loads a 0/255 (or 0/1) mask, checking its size against `w` x `h`.
fn load_mask(path: &Path, w: usize, h: usize) -> Result<GrayImage> {
    let m = GrayImage::load(path).with_context(|| format!("cannot read {}", path.display()))?;
    if (m.width, m.height) != (w, h) {
        bail!(
            "{} is {}x{}, the image {w}x{h}",
            path.display(),
            m.width,
            m.height
        );
    }
    Ok(m)
}

/// Scores the detector on one sample folder.
fn score_sample(dir: &Path, id: &str, kind: ImageKind, params: &ParamArgs) -> Result<SampleScore> {
    let meta = SampleMeta::load(&dir.join("meta.json"))?;
    let image = dir.join(match kind {
        ImageKind::Png => "im0.png",
        ImageKind::Exr => "im0.exr",
    });
    let img =
        GrayImage::load(&image).with_context(|| format!("cannot read {}", image.display()))?;
    let horizon = sample_horizon(&meta);
    let det = detect_streaks(&img, &params.params(Some(horizon)))
        .with_context(|| format!("detecting streaks in {}", image.display()))?;
    let truth = load_mask(&dir.join("streaks0.png"), img.width, img.height)?;
    let all = score_mask(&det.mask, &truth)?;
    let road = if meta.road_mask {
        let road = load_mask(&dir.join("road0.png"), img.width, img.height)?;
        let mut on_road = truth.clone();
        for (t, &r) in on_road.data.iter_mut().zip(&road.data) {
            if r <= 0.5 {
                *t = 0.0;
            }
        }
        Some(score_mask(&det.mask, &on_road)?)
    } else {
        None
    };
    Ok(SampleScore {
        id: id.to_owned(),
        split: meta.split,
        horizon,
        streaks: det.streaks.len(),
        all,
        road,
    })
}

/// Scores the detector over the dataset in `dir`.
pub fn score_dataset(
    dir: &Path,
    split: Option<&str>,
    kind: ImageKind,
    params: &ParamArgs,
) -> Result<DatasetScore> {
    let layout = Layout::new(dir);
    let ids = layout.sample_ids(split)?;
    params
        .params(None)
        .validate()
        .context("detector parameters")?;
    let bar = crate::render::progress_bar(ids.len() as u64);
    let samples = ids
        .par_iter()
        .map(|id| {
            let sample = layout.samples_dir().join(id);
            let s = score_sample(&sample, id, kind, params)
                .with_context(|| format!("sample {}", sample.display()));
            bar.inc(1);
            s
        })
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    Ok(DatasetScore {
        dataset: dir.to_path_buf(),
        split: split.map(str::to_owned),
        image: match kind {
            ImageKind::Png => "im0.png",
            ImageKind::Exr => "im0.exr",
        }
        .into(),
        all: MaskScore::pooled(samples.iter().map(|s| &s.all)),
        road: MaskScore::pooled(samples.iter().filter_map(|s| s.road.as_ref())),
        samples,
    })
}

/// The table `streaks detect DIR` prints.
fn table(score: &DatasetScore) -> String {
    let mut out =
        String::from("sample  split  horizon  streaks  all P/R (true px)    road P/R (true px)\n");
    let cell = |m: &MaskScore| format!("{:.2}/{:.2} ({:>6})", m.precision, m.recall, m.truth);
    for s in &score.samples {
        out.push_str(&format!(
            "{:<7} {:<6} {:>7.1} {:>8}  {:<20} {}\n",
            s.id,
            s.split,
            s.horizon,
            s.streaks,
            cell(&s.all),
            s.road
                .as_ref()
                .map(cell)
                .unwrap_or_else(|| "no road mask".into())
        ));
    }
    out.push_str(&format!(
        "pooled over {} samples: all P {:.3} R {:.3} F1 {:.3}; road P {:.3} R {:.3} F1 {:.3}\n",
        score.samples.len(),
        score.all.precision,
        score.all.recall,
        score.all.f1,
        score.road.precision,
        score.road.recall,
        score.road.f1
    ));
    out
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    if args.input.join("dataset.json").is_file() {
        let score = score_dataset(&args.input, args.split.as_deref(), args.image, &args.params)?;
        eprint!("{}", table(&score));
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
    if args.split.is_some() {
        bail!("--split applies to a dataset folder, not to an image");
    }
    let img = GrayImage::load(&args.input)
        .with_context(|| format!("cannot read {}", args.input.display()))?;
    // The truth is read first: a bad one stops the run before anything is written.
    let truth = match &args.truth {
        Some(t) => Some(load_mask(t, img.width, img.height)?),
        None => None,
    };
    let det = detect_streaks(&img, &args.params.params(args.horizon))
        .with_context(|| format!("detecting streaks in {}", args.input.display()))?;
    let out = args.output.clone().unwrap_or_else(|| {
        let stem = args
            .input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "image".into());
        args.input.with_file_name(format!("{stem}_streaks.png"))
    });
    let mut mask = det.mask.clone();
    for v in &mut mask.data {
        *v = if *v > 0.5 { 1.0 } else { 0.0 };
    }
    mask.save_png(&out)
        .with_context(|| format!("writing the mask {}", out.display()))?;
    eprintln!(
        "{} streaks, {} glows, {} lamps (horizon at row {:.1}); mask in {}",
        det.streaks.len(),
        det.glows.len(),
        det.lamps.len(),
        det.horizon,
        out.display()
    );
    if let Some(t) = &truth {
        let s = score_mask(&det.mask, t)?;
        println!("{}", serde_json::to_string_pretty(&s)?);
    }
    Ok(())
}
