//! What the subcommands share: loading a scene with the command's hints, the progress bar, and
//! the analysis of a pair folder with its console summary; the horizon and streak truths of a dataset sample, which `streaks
//! detect` and `streaks train-detector` both read. Subcommands use these and never
//! call each other.

use anyhow::Result;
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

/// The image size of the flags and the camera's aspect ratio (its home is the renderer's
/// [`streaks_render::view`], which the Python package frames its views with too).
pub use streaks_render::view::image_size;

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
