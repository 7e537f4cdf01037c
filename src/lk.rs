//! `streaks lk`: the paper's per-row 1D Lucas-Kanade disparity over an image region.

use anyhow::{bail, Context};
use std::path::PathBuf;
use streaks_analysis::lk::{lk_region, Interp, LkParams, Photometric, Region};
use streaks_stereo::image::GrayImage;

/// Output format.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Comma-separated values with a header line.
    Csv,
    /// A JSON array of objects.
    Json,
}

/// Arguments of `streaks lk`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Left image (PNG, JPEG; converted to luminance).
    pub left: PathBuf,
    /// Right image.
    pub right: PathBuf,
    /// Region of the left image, pixel indices x0,y0,x1,y1 (half-open: x0 <= x < x1).
    #[arg(long, value_parser = parse_region)]
    pub region: Region,
    /// Window width in pixels (odd).
    #[arg(long, default_value_t = 15)]
    pub window: usize,
    /// Window height in rows (odd).
    #[arg(long, default_value_t = 1)]
    pub rows: usize,
    /// Smallest disparity searched (may be negative).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub min_disp: i32,
    /// Largest disparity searched.
    #[arg(long, default_value_t = 64, allow_negative_numbers = true)]
    pub max_disp: i32,
    /// Linear instead of cubic interpolation.
    #[arg(long)]
    pub linear: bool,
    /// Compensate a gain (contrast) difference as well as an offset between the cameras.
    #[arg(long)]
    pub gain: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
}

fn parse_region(s: &str) -> Result<Region, String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("expected x0,y0,x1,y1 as non-negative integers: {e}"))?;
    match v[..] {
        [x0, y0, x1, y1] => Ok(Region { x0, y0, x1, y1 }),
        _ => Err(format!("expected 4 numbers x0,y0,x1,y1, got {}", v.len())),
    }
}

/// Runs the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let left = GrayImage::load(&args.left).context("reading the left image")?;
    let right = GrayImage::load(&args.right).context("reading the right image")?;
    if args.min_disp > args.max_disp {
        bail!(
            "--min-disp {} exceeds --max-disp {}",
            args.min_disp,
            args.max_disp
        );
    }
    let params = LkParams {
        window: args.window,
        rows: args.rows,
        min_disp: args.min_disp,
        max_disp: args.max_disp,
        interp: if args.linear {
            Interp::Linear
        } else {
            Interp::Cubic
        },
        photometric: if args.gain {
            Photometric::GainOffset
        } else {
            Photometric::Offset
        },
        ..LkParams::default()
    };
    let rows = lk_region(&left, &right, args.region, &params).context("estimating disparities")?;
    let mut out = String::new();
    match args.format {
        Format::Csv => {
            out.push_str("row,x,disparity,ncc,gradient_energy,residual,converged\n");
            for r in &rows {
                out.push_str(&format!(
                    "{},{},{},{},{},{},{}\n",
                    r.row, r.x, r.disparity, r.ncc, r.gradient_energy, r.residual, r.converged
                ));
            }
        }
        Format::Json => {
            out = serde_json::to_string_pretty(&rows)?;
            out.push('\n');
        }
    }
    print!("{out}");
    Ok(())
}
