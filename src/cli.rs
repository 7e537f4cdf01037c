//! What the subcommands share: loading a scene with the command's hints, the image size from
//! `--width`/`--height` and the camera, the progress bar, and the analysis of a pair folder
//! with its console summary; the horizon and streak truths of a dataset sample, which `streaks
//! detect` and `streaks train-detector` both read. Subcommands use these and never
//! call each other.

use anyhow::{bail, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;
use streaks_analysis::detector::{horizon_row, road_streaks};
use streaks_analysis::report::{analyze_dir, summary_table, AnalyzeParams, Report};
use streaks_dataset::files::{load_mask, SampleDir};
use streaks_dataset::meta::SampleMeta;
use streaks_image::GrayImage;
use streaks_render::scene::{LoadOptions, Scene, SceneError};
use streaks_stereo::rig::Eye;

/// Largest image accepted, in pixels (2^26, twice 8K UHD; the film keeps about 72 bytes per
/// pixel, so 4.5 GiB).
const MAX_PIXELS: u64 = 1 << 26;

/// Loads a scene for a command; `allow_outside` lets it read files outside its folder
/// (`--allow-outside-scene`), and a refusal says which flag allows it.
pub fn load_scene(path: &Path, allow_outside: bool) -> Result<Scene> {
    let options = LoadOptions {
        allow_outside,
        ..LoadOptions::default()
    };
    Scene::load_with(path, &options).map_err(|e| {
        let hint = if matches!(e, SceneError::OutsideFolder { .. }) {
            " (--allow-outside-scene lets it read files outside its folder)"
        } else {
            ""
        };
        anyhow::Error::new(e).context(format!("cannot load the scene {}{hint}", path.display()))
    })
}

/// Default image height when neither `--width` nor `--height` is given.
const DEFAULT_HEIGHT: u32 = 480;

/// Image size from the flags and the camera's aspect ratio (see the flags' help).
pub fn image_size(
    width: Option<u32>,
    height: Option<u32>,
    aspect: Option<f32>,
) -> Result<(u32, u32)> {
    let aspect = aspect
        .filter(|a| a.is_finite() && *a > 0.0)
        .unwrap_or(4.0 / 3.0) as f64;
    for (flag, value) in [("--width", width), ("--height", height)] {
        if value == Some(0) {
            bail!("the image size must be positive, got {flag} 0");
        }
    }
    let derive = |v: f64, what: &str| -> Result<u32> {
        let r = v.round();
        if !(1.0..=u32::MAX as f64).contains(&r) {
            bail!(
                "the derived image size ({what} {v:.1}) is out of range; give --width and --height"
            );
        }
        Ok(r as u32)
    };
    let (w, h) = match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, derive(w as f64 / aspect, "height")?),
        (None, Some(h)) => (derive(h as f64 * aspect, "width")?, h),
        (None, None) => (
            derive(DEFAULT_HEIGHT as f64 * aspect, "width")?,
            DEFAULT_HEIGHT,
        ),
    };
    if w as u64 * h as u64 > MAX_PIXELS {
        bail!("the image size {w}x{h} is too large (at most {MAX_PIXELS} pixels)");
    }
    Ok((w, h))
}

/// A progress bar over `total` pixel samples on stderr (hidden in CI and when not a terminal).
pub fn progress_bar(total: u64) -> ProgressBar {
    let in_ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
    if in_ci || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{elapsed_precise} [{wide_bar}] {percent:>3}% samples, eta {eta}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// Analyses the pair in `dir` ([`analyze_dir`]: `dir/analysis/`), prints the summary table
/// and what was written, and returns the report: `streaks analyze`, and `streaks stereo
/// --analyze` and `streaks paper` after rendering.
pub fn analyze_pair(dir: &Path, params: &AnalyzeParams) -> Result<Report> {
    let start = Instant::now();
    let done = analyze_dir(dir, params)?;
    eprint!("{}", summary_table(&done.report));
    eprintln!(
        "analysed in {:.1} s; wrote {} files into {}",
        start.elapsed().as_secs_f64(),
        done.written.len(),
        done.out.display()
    );
    Ok(done.report)
}

/// The horizon row (image y) of a dataset sample's left camera ([`horizon_row`] of its rig).
pub fn sample_horizon(meta: &SampleMeta) -> f32 {
    let rig = &meta.rig;
    horizon_row(&rig.world_from_rig, rig.principal_point[1], rig.focal_px)
}

/// The truth masks of the dataset sample `sample` (with its `meta`): its left streak mask, and
/// that mask's part on the road ([`road_streaks`] with the road mask), if the scene flags a
/// road.
pub fn sample_truths(
    sample: &SampleDir,
    meta: &SampleMeta,
) -> Result<(GrayImage, Option<GrayImage>)> {
    let size = (meta.rig.width as usize, meta.rig.height as usize);
    let truth = load_mask(&sample.streak_mask(Eye::Left), size, "the image")?;
    if !meta.road_mask {
        return Ok((truth, None));
    }
    let road = load_mask(&sample.road_mask(Eye::Left), size, "the image")?;
    let on_road = road_streaks(&truth, &road);
    Ok((truth, Some(on_road)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_follow_the_aspect_ratio() {
        assert_eq!(
            image_size(None, None, Some(16.0 / 9.0)).unwrap(),
            (853, 480)
        );
        assert_eq!(image_size(None, None, None).unwrap(), (640, 480));
        assert_eq!(image_size(Some(320), None, Some(2.0)).unwrap(), (320, 160));
        assert_eq!(image_size(None, Some(100), Some(1.5)).unwrap(), (150, 100));
        assert_eq!(image_size(Some(7), Some(9), Some(2.0)).unwrap(), (7, 9));
        assert!(image_size(Some(0), None, None).is_err());
        assert!(image_size(Some(1), None, Some(100.0)).is_err());
        assert!(image_size(Some(u32::MAX), Some(u32::MAX), None).is_err());
        assert!(image_size(None, Some(u32::MAX), Some(4.0)).is_err());
    }
}
