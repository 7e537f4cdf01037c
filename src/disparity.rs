//! `streaks disparity`: dense disparity of the left image by semi-global matching, written as
//! a PFM (inf where the left-right check fails), with an optional colour preview and an
//! optional comparison against ground truth. `--streaks mask|repair` makes it streak-robust
//! ([`streaks_analysis::repair`]): the pixels streaks and reflections put beneath the road
//! plane (fitted from the pair itself) are made invalid or given the road's disparity, and a
//! confidence map is written beside the output.

use anyhow::{bail, Context};
use std::path::PathBuf;
use streaks_analysis::repair::{estimate, Estimate, StreakHandling};
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
    /// Streak-robust output: `mask` marks detected streak and below-the-road (reflection)
    /// pixels invalid; `repair` gives them the road plane's disparity.
    #[arg(long, value_enum)]
    pub streaks: Option<Handling>,
    /// Where the confidence map goes with --streaks (PFM: 1 measured, 0.5 repaired, 0 no
    /// value); default: OUTPUT with `_confidence` added to its stem.
    #[arg(long, requires = "streaks")]
    pub confidence: Option<PathBuf>,
}

/// `--streaks`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handling {
    /// Mark streak and reflection pixels invalid.
    Mask,
    /// Replace them with the road plane's disparity.
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
    let handling = args.streaks.map(|h| match h {
        Handling::Mask => StreakHandling::Mask,
        Handling::Repair => StreakHandling::Repair,
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
        match r.plane {
            Some(p) => eprintln!(
                "road plane: d = {:.4} (y - {:.1}), {} inliers ({:.0} %), RMS {:.2} px",
                p.slope,
                p.horizon,
                p.inliers,
                100.0 * p.inlier_share,
                p.rms_px
            ),
            None => eprintln!("no road plane found: streak pixels are masked, not repaired"),
        }
        eprintln!(
            "streaks: {} detected pixels, {} below the road; {} repaired, {} masked",
            r.streak_pixels, r.below_road_pixels, r.repaired_pixels, r.masked_pixels
        );
        let conf_path = args.confidence.clone().unwrap_or_else(|| {
            let stem = args
                .output
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "disparity".into());
            args.output.with_file_name(format!("{stem}_confidence.pfm"))
        });
        write_pfm(&conf_path, &r.confidence)
            .with_context(|| format!("writing the confidence map {}", conf_path.display()))?;
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
