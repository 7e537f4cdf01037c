//! `streaks prepare`: the paper's Fig. 7 treatment of a photographed stereo pair (grey level,
//! histogram equalisation, an optional shift that gives a chosen disparity zero), written as
//! the treated pair, side-by-side and red-cyan anaglyph.

use anyhow::Context;
use std::path::PathBuf;
use streaks_image::GrayImage;
use streaks_stereo::pair::{prepare_pair, write_pair_views};

/// Treat a photographed pair as in the paper's Fig. 7.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Left image.
    pub left: PathBuf,
    /// Right image.
    pub right: PathBuf,
    /// Output folder (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Shift the left image this many pixels to the left, so that points of this disparity
    /// (x_left - x_right) end up with zero disparity.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub shift: f32,
}

/// Runs the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let left = GrayImage::load(&args.left)?;
    let right = GrayImage::load(&args.right)?;
    let (l, r) = prepare_pair(&left, &right, args.shift)?;
    let dir = &args.output;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    l.save_png(&dir.join("left.png"))?;
    r.save_png(&dir.join("right.png"))?;
    write_pair_views(dir, &l.to_rgb8(), &r.to_rgb8())?;
    eprintln!(
        "wrote left.png, right.png, side_by_side.png, anaglyph.png to {}",
        dir.display()
    );
    Ok(())
}
