//! `streaks prepare`: the paper's Fig. 7 treatment of a photographed stereo pair (grey level,
//! histogram equalisation, an optional shift that gives a chosen disparity zero), written as
//! the treated pair, side-by-side and red-cyan anaglyph.

use anyhow::Context;
use std::path::PathBuf;
use streaks_dataset::SampleDir;
use streaks_image::GrayImage;
use streaks_stereo::pair::{prepare_pair, write_pair_views};
use streaks_stereo::rig::Eye;

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
    let files = SampleDir::new(dir);
    l.save_png(&files.png(Eye::Left))?;
    r.save_png(&files.png(Eye::Right))?;
    write_pair_views(
        &files.side_by_side(),
        &files.anaglyph(),
        &l.to_rgb8(),
        &r.to_rgb8(),
    )?;
    let name = |p: PathBuf| {
        p.file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned()
    };
    eprintln!(
        "wrote {}, {}, {}, {} to {}",
        name(files.png(Eye::Left)),
        name(files.png(Eye::Right)),
        name(files.side_by_side()),
        name(files.anaglyph()),
        dir.display()
    );
    Ok(())
}
