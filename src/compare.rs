//! `streaks compare`: relative RMSE and bias of one render against a reference, overall, per
//! region (rectangles, or masks such as a dataset's `road0.png`) and for the worst 8x8 block,
//! A's fireflies, optionally with the noise test (second renders with other seeds) and a
//! false-colour difference PNG. See `streaks_image::compare` for the statistics.

use anyhow::Context;
use std::path::{Path, PathBuf};
use streaks_image::compare::{compare_masked, write_diff_png, Inputs, MaskRegion};
use streaks_image::exr::read_exr_rgb;
use streaks_image::{GrayImage, NamedRegion, RgbImage};

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
    /// A region given by a mask image `[name=]FILE` (non-zero pixels are in; the name defaults
    /// to the file's stem), such as a dataset's road0.png; repeatable.
    #[arg(long = "mask", value_name = "[NAME=]FILE")]
    pub masks: Vec<String>,
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

/// Reads a `--mask [NAME=]FILE`.
fn read_mask(spec: &str) -> anyhow::Result<MaskRegion> {
    let (name, file) = match spec.split_once('=') {
        Some((name, file)) => (name.to_owned(), PathBuf::from(file)),
        None => {
            let file = PathBuf::from(spec);
            let stem = file
                .file_stem()
                .map_or_else(|| "mask".to_owned(), |s| s.to_string_lossy().into_owned());
            (stem, file)
        }
    };
    let img =
        GrayImage::load(&file).with_context(|| format!("reading the mask {}", file.display()))?;
    Ok(MaskRegion {
        name,
        width: img.width as u32,
        height: img.height as u32,
        mask: img.data.iter().map(|&v| v > 0.0).collect(),
    })
}

/// Runs the command; fails (non-zero exit) when the noise test runs and a region fails.
pub fn run(args: Args) -> anyhow::Result<()> {
    let a = read(&args.a)?;
    let b = read(&args.b)?;
    let masks = args
        .masks
        .iter()
        .map(|m| read_mask(m))
        .collect::<anyhow::Result<Vec<_>>>()?;
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
    let c = compare_masked(&inputs, &args.regions, &masks, args.block, args.k)
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
