//! `streaks dataset preview SAMPLE -o PNG`: one picture of a sample for a person to look at:
//! the left image as the sample's camera saw it (`im0.png`) beside its ground-truth disparity
//! (`disp0.pfm`, turbo colours from 0 px to the sample's largest disparity, no value black)
//! and, when the sample has them, its rain mask (`rain0.png`, stretched so that its brightest
//! pixel is white: most drops cover a pixel for a small share of the shutter) or else its fog
//! transmittance (`fog0.pfm`, white = clear, black = hidden) as a third panel, and its flow to
//! the next frame (`flow0.pfm`, the Middlebury colour wheel normalised by the largest flow
//! shown; pixels without a flow in the next image, `flowmask0.png` below 128, black) as the
//! last.

use anyhow::{bail, Context, Result};
use image::{imageops, Rgb, RgbImage};
use std::path::PathBuf;
use streaks_analysis::sgm::disparity_preview;
use streaks_dataset::files::SampleDir;
use streaks_image::flow_color::flow_color;
use streaks_image::input::load_image;
use streaks_image::pfm::{read_pfm, read_pfm_rgb};
use streaks_image::png::write_png_buffer;
use streaks_stereo::rig::Eye;

/// Write a sample's left image beside its ground-truth disparity (and its rain mask or fog
/// transmittance) as one PNG.
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
    let fog_path = files.fog(Eye::Left);
    let third = if rain_path.is_file() {
        let mask = load_image(&rain_path)
            .with_context(|| format!("cannot read the rain mask {}", rain_path.display()))?
            .to_luma8();
        let top = mask.pixels().map(|p| p.0[0]).max().unwrap_or(0).max(1);
        Some(RgbImage::from_fn(mask.width(), mask.height(), |x, y| {
            let v = (u32::from(mask.get_pixel(x, y).0[0]) * 255 / u32::from(top)) as u8;
            Rgb([v, v, v])
        }))
    } else if fog_path.is_file() {
        let fog = read_pfm(&fog_path)
            .with_context(|| format!("cannot read the fog {}", fog_path.display()))?;
        Some(RgbImage::from_fn(
            fog.width as u32,
            fog.height as u32,
            |x, y| {
                let t = fog.data[y as usize * fog.width + x as usize];
                let v = (t.clamp(0.0, 1.0) * 255.0).round() as u8;
                Rgb([v, v, v])
            },
        ))
    } else {
        None
    };
    let flow = if files.flow_pfm().is_file() {
        Some(flow_panel(&files)?)
    } else {
        None
    };
    let (w, h) = left.dimensions();
    for panel in third.iter().chain(&flow) {
        if panel.dimensions() != (w, h) {
            bail!(
                "the rain, fog or flow map of {} is not {w}x{h}",
                args.sample.display()
            );
        }
    }
    let panels = [Some(&left), Some(&colours), third.as_ref(), flow.as_ref()];
    let shown: Vec<&RgbImage> = panels.into_iter().flatten().collect();
    let mut out = RgbImage::from_pixel(shown.len() as u32 * w, h, Rgb([0, 0, 0]));
    for (i, panel) in shown.into_iter().enumerate() {
        imageops::replace(&mut out, panel, i as i64 * i64::from(w), 0);
    }
    if let Some(parent) = args.output.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create the folder {}", parent.display()))?;
    }
    write_png_buffer(&args.output, &out)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    Ok(())
}

/// The sample's flow in the Middlebury colours, normalised by its largest flow shown; black
/// where the point is not in the next image (`flowmask0.png` below 128).
fn flow_panel(files: &SampleDir) -> Result<RgbImage> {
    let path = files.flow_pfm();
    let flow =
        read_pfm_rgb(&path).with_context(|| format!("cannot read the flow {}", path.display()))?;
    let mask_path = files.flow_mask();
    let mask = load_image(&mask_path)
        .with_context(|| format!("cannot read the flow mask {}", mask_path.display()))?
        .to_luma8();
    if mask.dimensions() != (flow.width, flow.height) {
        bail!(
            "{} is not the size of {}",
            mask_path.display(),
            path.display()
        );
    }
    let shown = |i: usize| mask.as_raw()[i] >= 128;
    let largest = flow
        .pixels
        .iter()
        .enumerate()
        .filter(|&(i, _)| shown(i))
        .map(|(_, f)| f.x.hypot(f.y))
        .filter(|r| r.is_finite())
        .fold(0.0f32, f32::max);
    Ok(RgbImage::from_fn(flow.width, flow.height, |x, y| {
        let i = (y * flow.width + x) as usize;
        let f = flow.pixels[i];
        if shown(i) {
            Rgb(flow_color(f.x, f.y, largest.max(1e-3)))
        } else {
            Rgb([0, 0, 0])
        }
    }))
}
