//! `streaks texture-map`: resample an image onto the road plane (the paper's Fig. 3) and plot it
//! with axes in metres.

use anyhow::Context;
use std::path::PathBuf;
use streaks_image::gray::load_rgb_channels;
use streaks_stereo::rig::Eye;
use streaks_stereo::rigfile::RigFile;
use streaks_stereo::texture_map::{plot_texture_map, texture_map, MapSpec};

/// Which eye saw the image.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum EyeArg {
    /// The left eye.
    Left,
    /// The right eye.
    Right,
}

impl From<EyeArg> for Eye {
    fn from(e: EyeArg) -> Eye {
        match e {
            EyeArg::Left => Eye::Left,
            EyeArg::Right => Eye::Right,
        }
    }
}

/// Parses "MIN,MAX" (metres).
pub fn parse_range(s: &str) -> Result<(f32, f32), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("{s:?} is not MIN,MAX"))?;
    let num = |t: &str| {
        t.trim()
            .parse::<f32>()
            .map_err(|e| format!("{t:?} in {s:?}: {e}"))
    };
    Ok((num(a)?, num(b)?))
}

/// Resample an image (seen by one eye of a rig) onto road coordinates (X, Z).
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The image (PNG or JPEG), the size given in rig.json.
    pub image: PathBuf,
    /// The rig.json written by `streaks stereo`.
    #[arg(long)]
    pub rig: PathBuf,
    /// The eye that saw the image.
    #[arg(long, value_enum, default_value = "left")]
    pub eye: EyeArg,
    /// Road X range in metres (to the camera's right), MIN,MAX.
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true, default_value = "-5,5")]
    pub x_range: (f32, f32),
    /// Road Z range in metres (forward), MIN,MAX.
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true, default_value = "2,40")]
    pub z_range: (f32, f32),
    /// Cell size in metres.
    #[arg(long, default_value_t = 0.05)]
    pub resolution: f32,
    /// Output PNG.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Runs the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let rig = RigFile::load(&args.rig)?.rig()?;
    let spec = MapSpec::new(args.x_range, args.z_range, args.resolution)?;
    let channels = load_rgb_channels(&args.image)?;
    let eye = Eye::from(args.eye);
    let map = texture_map(&channels, &rig, eye, &spec)
        .with_context(|| format!("texture map of {}", args.image.display()))?;
    let name = args
        .image
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    plot_texture_map(
        &map,
        &args.output,
        &format!("{name} on the road ({eye} eye)"),
    )?;
    eprintln!(
        "wrote {} ({} x {} cells of {} m)",
        args.output.display(),
        spec.nx(),
        spec.nz(),
        spec.resolution
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse() {
        assert_eq!(parse_range("-5,5"), Ok((-5.0, 5.0)));
        assert_eq!(parse_range(" 2 , 40.5"), Ok((2.0, 40.5)));
        assert!(parse_range("5").is_err());
        assert!(parse_range("a,1").is_err());
    }
}
