//! `streaks lk`: the paper's per-row 1D Lucas-Kanade disparity over an image region, or along
//! the centre of every streak detected in the left image (`--streaks`).

use anyhow::{bail, Context};
use std::path::PathBuf;
use streaks_analysis::detect::{detect_streaks, DetectParams};
use streaks_analysis::lk::{
    lk_region, lk_rows, prepare_pair, Interp, LkParams, Photometric, RowDisparity,
};
use streaks_image::{GrayImage, Region};

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
#[command(group(clap::ArgGroup::new("where").required(true).args(["region", "streaks"])))]
pub struct Args {
    /// Left image (PNG, JPEG; converted to luminance).
    pub left: PathBuf,
    /// Right image.
    pub right: PathBuf,
    /// Region of the left image, pixel indices x0,y0,x1,y1 (half-open: x0 <= x < x1).
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    pub region: Option<Region>,
    /// Instead of a region: detect streaks in the left image and estimate along each one's
    /// centre (adds a `streak` column: the streak's index).
    #[arg(long)]
    pub streaks: bool,
    /// Horizon row (image y) for --streaks; default: the image centre (pitch-0 rig).
    #[arg(long)]
    pub horizon: Option<f32>,
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
    /// Pyramid levels for coarse-to-fine estimation (1: search the whole disparity range at
    /// full resolution; 2 to 8: search it on the image reduced 2^(levels-1) times, then refine
    /// level by level).
    #[arg(long, default_value_t = 1)]
    pub levels: usize,
    /// Measure the images as they are. By default they are prepared as `streaks analyze`
    /// does: single-pixel fireflies removed and the range log-compressed.
    #[arg(long)]
    pub raw: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
}

/// Runs the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let left = GrayImage::load(&args.left).context("reading the left image")?;
    let right = GrayImage::load(&args.right).context("reading the right image")?;
    // LK measures the prepared pair; streaks are detected on the left image as it is (as
    // `streaks analyze` does).
    let prepared = (!args.raw).then(|| prepare_pair(&left, &right));
    let (lk_left, lk_right) = prepared.as_ref().map_or((&left, &right), |(l, r)| (l, r));
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
        levels: args.levels,
        ..LkParams::default()
    };
    // (streak index, estimate) pairs.
    let rows: Vec<(Option<usize>, RowDisparity)> = match args.region {
        Some(region) => lk_region(lk_left, lk_right, region, &params)
            .context("estimating disparities")?
            .into_iter()
            .map(|r| (None, r))
            .collect(),
        None => {
            let detect = DetectParams {
                horizon: args.horizon,
                ..DetectParams::default()
            };
            let found = detect_streaks(&left, &detect).context("detecting streaks")?;
            eprintln!(
                "{} streaks, {} lamps (horizon y = {})",
                found.streaks.len(),
                found.lamps.len(),
                found.horizon
            );
            let mut rows = Vec::new();
            for (i, streak) in found.streaks.iter().enumerate() {
                let est = lk_rows(lk_left, lk_right, &streak.centres, &params)
                    .with_context(|| format!("estimating disparities along streak {i}"))?;
                rows.extend(est.into_iter().map(|r| (Some(i), r)));
            }
            rows
        }
    };
    let mut out = String::new();
    match args.format {
        Format::Csv => {
            if args.streaks {
                out.push_str("streak,");
            }
            out.push_str("row,x,disparity,ncc,gradient_energy,residual,converged\n");
            for (streak, r) in &rows {
                if let Some(i) = streak {
                    out.push_str(&format!("{i},"));
                }
                out.push_str(&format!(
                    "{},{},{},{},{},{},{}\n",
                    r.row, r.x, r.disparity, r.ncc, r.gradient_energy, r.residual, r.converged
                ));
            }
        }
        Format::Json => {
            let values: Vec<serde_json::Value> = rows
                .iter()
                .map(|(streak, r)| {
                    let mut v = serde_json::to_value(r)?;
                    if let (Some(i), Some(obj)) = (streak, v.as_object_mut()) {
                        obj.insert("streak".into(), (*i).into());
                    }
                    Ok(v)
                })
                .collect::<Result<_, serde_json::Error>>()?;
            out = serde_json::to_string_pretty(&values)?;
            out.push('\n');
        }
    }
    use std::io::Write;
    match std::io::stdout().lock().write_all(out.as_bytes()) {
        // A closed pipe (`| head`) is the reader's choice, not an error.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other.context("writing the estimates"),
    }
}
