//! `streaks dataset preview SAMPLE -o PNG`: one picture of a sample for a person to look at:
//! the left image as the sample's camera saw it (`im0.png`) beside its ground-truth disparity
//! (`disp0.pfm`, turbo colours from 0 px to the sample's largest disparity, no value black)
//! and, when it rains, the rain mask (`rain0.png`) under them.

use anyhow::{bail, Context, Result};
use image::{imageops, Rgb, RgbImage};
use std::path::PathBuf;
use streaks_analysis::sgm::disparity_preview;
use streaks_dataset::files::SampleDir;
use streaks_image::input::load_image;
use streaks_image::pfm::read_pfm;
use streaks_image::png::write_png_buffer;
use streaks_stereo::rig::Eye;

/// Write a sample's left image beside its ground-truth disparity (and rain mask) as one PNG.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The sample folder (`DIR/samples/NNNNNN`).
    pub sample: PathBuf,
    /// The PNG to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Runs `streaks dataset preview`.
pub fn run(args: Args) -> Result<()> {
    let files = SampleDir::new(&args.sample);
    let image_path = files.png(Eye::Left);
    let left = load_image(&image_path)
        .with_context(|| format!("cannot read the left image {}", image_path.display()))?
        .to_rgb8();
    let disp_path = files.disparity(Eye::Left);
    let disp = read_pfm(&disp_path)
        .with_context(|| format!("cannot read the disparity {}", disp_path.display()))?;
    if (disp.width as u32, disp.height as u32) != left.dimensions() {
        bail!(
            "{} is {}x{} but {} is {}x{}",
            disp_path.display(),
            disp.width,
            disp.height,
            image_path.display(),
            left.width(),
            left.height()
        );
    }
    let largest = disp
        .data
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(0.0f32, f32::max);
    let colours = disparity_preview(&disp, Some((0.0, largest.max(1.0))));
    let rain_path = files.rain_mask(Eye::Left);
    let rain = if rain_path.is_file() {
        let mask = load_image(&rain_path)
            .with_context(|| format!("cannot read the rain mask {}", rain_path.display()))?
            .to_rgb8();
        Some(mask)
    } else {
        None
    };
    let (w, h) = left.dimensions();
    let rows = if rain.is_some() { 2 } else { 1 };
    let mut out = RgbImage::from_pixel(2 * w, rows * h, Rgb([0, 0, 0]));
    imageops::replace(&mut out, &left, 0, 0);
    imageops::replace(&mut out, &colours, i64::from(w), 0);
    if let Some(mask) = &rain {
        imageops::replace(&mut out, mask, 0, i64::from(h));
    }
    if let Some(parent) = args.output.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create the folder {}", parent.display()))?;
    }
    write_png_buffer(&args.output, &out)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    Ok(())
}
