//! `streaks disparity`: dense disparity of the left image by semi-global matching, written as
//! a PFM (inf where the left-right check fails), with an optional colour preview and an
//! optional comparison against ground truth. `--streaks mask|repair` makes it streak-robust
//! ([`streaks_analysis::repair`]): the values a learned classifier finds fooled by streaks,
//! reflections and noise are made invalid or given the surface around them, and a calibrated
//! confidence map and the streak mask are written beside the output.

use anyhow::{bail, Context};
use std::path::PathBuf;
use streaks_analysis::repair::{estimate, Estimate, RepairModel, StreakHandling};
use streaks_analysis::sgm::{
    compare_disparity, compare_disparity_where, write_disparity_png, Census, Paths, SgmParams,
};
use streaks_image::pfm::{read_pfm, write_pfm};
use streaks_image::GrayImage;

/// Arguments of `streaks disparity`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Left image (PNG, JPEG; converted to luminance).
    pub left: PathBuf,
    /// Right image.
    pub right: PathBuf,
    /// Output disparity map (PFM).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Colour-mapped preview (PNG).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Smallest disparity (may be negative).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub min_disp: i32,
    /// Largest disparity.
    #[arg(long, default_value_t = 63, allow_negative_numbers = true)]
    pub max_disp: i32,
    /// Aggregation paths: 4 or 8.
    #[arg(long, default_value_t = 8)]
    pub paths: u8,
    /// Census window: 5 (5x5) or 7 (7x7).
    #[arg(long, default_value_t = 7)]
    pub census: u8,
    /// Penalty P1 (small disparity changes).
    #[arg(long)]
    pub p1: Option<u16>,
    /// Penalty P2 (large disparity changes).
    #[arg(long)]
    pub p2: Option<u16>,
    /// Lower P2 across intensity edges by 1 / (1 + G |dI| / range); 0 keeps it constant.
    #[arg(long, default_value_t = 0.0)]
    pub p2_gradient: f32,
    /// Skip the left-right consistency check.
    #[arg(long)]
    pub no_lr_check: bool,
    /// Skip the 3x3 median filter.
    #[arg(long)]
    pub no_median: bool,
    /// Ground-truth disparity (PFM): print bad-2.0, mean error and density as JSON.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// With --truth: a road mask (PNG, non-zero = road) to also score the road pixels
    /// (with their phantom-hole rate, `below_1px`) and the others separately.
    #[arg(long, requires = "truth")]
    pub road: Option<PathBuf>,
    /// Streak-robust output: `mask` leaves the values that streaks, reflections and noise
    /// fooled without a value; `repair` gives them the surface around them where one is seen.
    #[arg(long, value_enum)]
    pub streaks: Option<Handling>,
    /// Where the confidence map goes with --streaks (PFM: the calibrated probability that a
    /// value is within 2 px and not more than 1 px beneath the truth; 0 no value); default:
    /// OUTPUT with `_confidence` added to its stem.
    #[arg(long, requires = "streaks")]
    pub confidence: Option<PathBuf>,
    /// Where the streak mask goes with --streaks (PNG, 255 on road streaks); default: OUTPUT
    /// with `_streaks` added to its stem, as a PNG.
    #[arg(long, requires = "streaks")]
    pub streak_mask: Option<PathBuf>,
    /// Where the streak probability goes with --streaks (PFM: the streak classifier's
    /// smoothed probability that a pixel is a road streak, which the streak mask thresholds);
    /// default: not written.
    #[arg(long, requires = "streaks")]
    pub streak_probability: Option<PathBuf>,
    /// With --streaks: a model of `streaks train-repair` instead of the shipped one.
    #[arg(long, requires = "streaks")]
    pub model: Option<PathBuf>,
}

/// `--streaks`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handling {
    /// Leave fooled values without a value.
    Mask,
    /// Replace them with the surface around them where one is seen.
    Repair,
}

/// Runs the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let left = GrayImage::load(&args.left).context("reading the left image")?;
    let right = GrayImage::load(&args.right).context("reading the right image")?;
    let defaults = SgmParams::default();
    let paths = match args.paths {
        4 => Paths::Four,
        8 => Paths::Eight,
        n => bail!("--paths must be 4 or 8, not {n}"),
    };
    let census = match args.census {
        5 => Census::Census5x5,
        7 => Census::Census7x7,
        n => bail!("--census must be 5 or 7, not {n}"),
    };
    let (p1, p2) = census.default_penalties();
    let params = SgmParams {
        min_disp: args.min_disp,
        max_disp: args.max_disp,
        census,
        paths,
        p1: args.p1.unwrap_or(p1),
        p2: args.p2.unwrap_or(p2),
        p2_gradient: args.p2_gradient,
        lr_tolerance: if args.no_lr_check { None } else { Some(1.0) },
        median: !args.no_median,
        ..defaults
    };
    let model = match &args.model {
        Some(path) => {
            let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
                .with_context(|| format!("reading the repair model {}", path.display()))?;
            Some(
                RepairModel::from_json(&text)
                    .with_context(|| format!("the repair model {}", path.display()))?,
            )
        }
        None => None,
    };
    let handling = args.streaks.map(|h| {
        let h = match h {
            Handling::Mask => StreakHandling::Mask,
            Handling::Repair => StreakHandling::Repair,
        };
        (h, model.as_ref().unwrap_or_else(|| RepairModel::shipped()))
    });
    let Estimate {
        disparity: disp,
        sgm_seconds,
        robust,
    } = estimate(&left, &right, &params, handling)?;
    eprintln!(
        "{}x{}, {} disparities: {sgm_seconds:.2} s",
        left.width,
        left.height,
        params.disparities(),
    );
    if let Some(r) = &robust {
        eprintln!(
            "streaks: {} streak pixels; {} values dropped as fooled, {} repaired, {} masked",
            r.streak_pixels, r.dropped_pixels, r.repaired_pixels, r.masked_pixels
        );
        let beside = |suffix: &str, ext: &str| {
            let stem = args
                .output
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "disparity".into());
            args.output.with_file_name(format!("{stem}_{suffix}.{ext}"))
        };
        let conf_path = args
            .confidence
            .clone()
            .unwrap_or_else(|| beside("confidence", "pfm"));
        write_pfm(&conf_path, &r.confidence)
            .with_context(|| format!("writing the confidence map {}", conf_path.display()))?;
        let mask_path = args
            .streak_mask
            .clone()
            .unwrap_or_else(|| beside("streaks", "png"));
        r.streaks
            .save_png(&mask_path)
            .with_context(|| format!("writing the streak mask {}", mask_path.display()))?;
        if let Some(path) = &args.streak_probability {
            write_pfm(path, &r.streak_probability)
                .with_context(|| format!("writing the streak probability {}", path.display()))?;
        }
    }
    write_pfm(&args.output, &disp).context("writing the disparity map")?;
    if let Some(png) = &args.png {
        write_disparity_png(png, &disp, None).context("writing the preview")?;
    }
    if let Some(truth) = &args.truth {
        let truth = read_pfm(truth).context("reading the ground truth")?;
        let errors = compare_disparity(&disp, &truth, 2.0).context("comparing with the truth")?;
        match &args.road {
            None => println!("{}", serde_json::to_string_pretty(&errors)?),
            Some(road) => {
                let mask = GrayImage::load(road)
                    .with_context(|| format!("reading the road mask {}", road.display()))?;
                if (mask.width, mask.height) != (truth.width, truth.height) {
                    bail!(
                        "the road mask {} is {}x{}, the truth {}x{}",
                        road.display(),
                        mask.width,
                        mask.height,
                        truth.width,
                        truth.height
                    );
                }
                let on = |i: usize| mask.data[i] > 0.0;
                let road_err = compare_disparity_where(&disp, &truth, 2.0, on)?;
                let off_err = compare_disparity_where(&disp, &truth, 2.0, |i| !on(i))?;
                let all = serde_json::json!({
                    "all": errors,
                    "road": road_err,
                    "off_road": off_err,
                    "phantom_hole_rate": road_err.below_1px,
                });
                println!("{}", serde_json::to_string_pretty(&all)?);
            }
        }
    }
    Ok(())
}
