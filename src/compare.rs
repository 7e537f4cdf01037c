//! `streaks compare`: relative RMSE and bias of one render against a reference, overall, per
//! region and for the worst 8x8 block, optionally with the noise test (second renders with
//! other seeds) and a false-colour difference PNG. See `streaks_image::compare` for the
//! statistics.

use anyhow::Context;
use std::path::{Path, PathBuf};
use streaks_image::compare::{compare, write_diff_png, Inputs};
use streaks_image::exr::read_exr_rgb;
use streaks_image::{NamedRegion, RgbImage};

/// Arguments of `streaks compare`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The image under test (EXR).
    pub a: PathBuf,
    /// The reference image (EXR).
    pub b: PathBuf,
    /// A region `[name=]x0,y0,x1,y1` (pixels, x1 and y1 exclusive); repeatable.
    #[arg(long = "region", value_name = "[NAME=]X0,Y0,X1,Y1")]
    pub regions: Vec<NamedRegion>,
    /// Print the comparison as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write the false-colour signed relative difference (blue: A darker, red: A brighter).
    #[arg(long, value_name = "D.png")]
    pub diff_png: Option<PathBuf>,
    /// Relative difference shown at full red or blue in the difference PNG.
    #[arg(long, default_value_t = 0.5)]
    pub diff_scale: f64,
    /// Block size for the largest local difference.
    #[arg(long, default_value_t = 8)]
    pub block: u32,
    /// Second render of A with another seed (enables the noise test; needs --b2).
    #[arg(long, requires = "b2")]
    pub a2: Option<PathBuf>,
    /// Second render of B with another seed (enables the noise test; needs --a2).
    #[arg(long, requires = "a2")]
    pub b2: Option<PathBuf>,
    /// Noise test threshold: a region fails when |bias| exceeds K standard errors.
    #[arg(long, default_value_t = 4.0)]
    pub k: f64,
}

fn read(path: &Path) -> anyhow::Result<RgbImage> {
    read_exr_rgb(path).with_context(|| format!("reading {}", path.display()))
}

/// Runs the command; fails (non-zero exit) when the noise test runs and a region fails.
pub fn run(args: Args) -> anyhow::Result<()> {
    let a = read(&args.a)?;
    let b = read(&args.b)?;
    let seconds = match (&args.a2, &args.b2) {
        (Some(a2), Some(b2)) => Some((read(a2)?, read(b2)?)),
        _ => None,
    };
    let names = match (&args.a2, &args.b2) {
        (Some(a2), Some(b2)) => format!(
            "A = {}, B = {}, A2 = {}, B2 = {}",
            args.a.display(),
            args.b.display(),
            a2.display(),
            b2.display()
        ),
        _ => format!("A = {}, B = {}", args.a.display(), args.b.display()),
    };
    let inputs = Inputs {
        a: &a,
        b: &b,
        seconds: seconds.as_ref().map(|(a2, b2)| (a2, b2)),
    };
    let c = compare(&inputs, &args.regions, args.block, args.k)
        .with_context(|| format!("comparing {names}"))?;
    if let Some(path) = &args.diff_png {
        write_diff_png(path, &a, &b, args.diff_scale)
            .with_context(|| format!("comparing {names}"))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        println!("{names}");
        print!("{}", c.table());
    }
    if c.passed() == Some(false) {
        anyhow::bail!(
            "the renders disagree beyond their noise (|z| > {}) in at least one region",
            args.k
        );
    }
    Ok(())
}
