//! `streaks disparity`: dense disparity of the left image by semi-global matching, written as
//! a PFM (inf where the left-right check fails), with an optional colour preview and an
//! optional comparison against ground truth.

use anyhow::{bail, Context};
use std::path::PathBuf;
use streaks_analysis::sgm::{
    compare_disparity, sgm, write_disparity_png, Census, Paths, SgmParams,
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
    let start = std::time::Instant::now();
    let disp = sgm(&left, &right, &params).context("semi-global matching")?;
    eprintln!(
        "{}x{}, {} disparities: {:.2} s",
        left.width,
        left.height,
        params.disparities(),
        start.elapsed().as_secs_f64()
    );
    write_pfm(&args.output, &disp).context("writing the disparity map")?;
    if let Some(png) = &args.png {
        write_disparity_png(png, &disp, None).context("writing the preview")?;
    }
    if let Some(truth) = &args.truth {
        let truth = read_pfm(truth).context("reading the ground truth")?;
        let errors = compare_disparity(&disp, &truth, 2.0).context("comparing with the truth")?;
        println!("{}", serde_json::to_string_pretty(&errors)?);
    }
    Ok(())
}
