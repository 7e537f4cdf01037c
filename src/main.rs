//! The `streaks` command: one module per subcommand, each thin over the library crates.
//!
//! Each subcommand module exposes an `Args` struct (clap) and `run(args) -> anyhow::Result<()>`.
//! Errors are printed with their whole chain and the process exits non-zero.

mod analyze;
mod benchmark;
mod cli;
mod compare;
mod dataset;
mod detect;
mod disparity;
mod export_mitsuba;
mod figure;
mod html;
mod lk;
mod locus;
mod paper;
mod prepare;
mod render;
mod render_opts;
mod stereo;
mod texture_map;
mod train_detector;
mod train_repair;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Render rainy night streets in stereo and measure what specular streaks do to depth.
#[derive(Parser, Debug)]
#[command(name = "streaks", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Path-trace one camera of a scene to EXR (and PNG).
    Render(render::Args),
    /// Render a rectified stereo pair with ground-truth disparity, depth and streak masks.
    Stereo(stereo::Args),
    /// Analyse a stereo pair: streak disparity per row against Eq. 4, depth below the road.
    Analyze(analyze::Args),
    /// Reproduce the paper's Figs. 2-6 with our renderer and model, with an index.md.
    Paper(paper::Args),
    /// Per-row 1D Lucas-Kanade disparity over a region (the paper's estimator).
    Lk(lk::Args),
    /// Dense disparity by semi-global matching (census cost), written as PFM.
    Disparity(disparity::Args),
    /// Print the virtual light column (Eq. 4) of a light seen from a viewer.
    Locus(locus::Args),
    /// Draw one of the paper's figures from the model as a PNG.
    Figure(figure::Args),
    /// Resample an image of a rendered or photographed pair onto the road plane (paper Fig. 3).
    TextureMap(texture_map::Args),
    /// Grey level, histogram equalisation and a disparity shift for a photographed pair (Fig. 7).
    Prepare(prepare::Args),
    /// Write a scene as a Mitsuba 3 scene (XML, PLY, EXR textures) for the cross-check.
    ExportMitsuba(export_mitsuba::Args),
    /// Compare a render with a reference: relative RMSE and bias per region, noise test.
    Compare(compare::Args),
    /// Detect specular streaks in an image, or score the detector over a dataset.
    Detect(detect::Args),
    /// Train the learned streak detector on datasets (for `streaks detect --model`).
    TrainDetector(train_detector::Args),
    /// Train the streak-robust stereo model on datasets (for `streaks disparity --streaks`).
    TrainRepair(train_repair::Args),
    /// Generate stereo datasets of procedural rainy streets (generate), and index them (index).
    Dataset(dataset::Args),
    /// Score stereo methods (built-in, external, predictions) against the ground truth of a
    /// dataset, pair folders, KITTI 2015 or Middlebury 2014, by region.
    Benchmark(benchmark::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result: anyhow::Result<()> = match cli.command {
        Command::TextureMap(args) => texture_map::run(args),
        Command::Prepare(args) => prepare::run(args),
        Command::Stereo(args) => stereo::run(args),
        Command::Render(args) => render::run(args),
        Command::Analyze(args) => analyze::run(args),
        Command::Paper(args) => paper::run(args),
        Command::Locus(args) => locus::run(args),
        Command::Figure(args) => figure::run(args),
        Command::ExportMitsuba(args) => export_mitsuba::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Lk(args) => lk::run(args),
        Command::Disparity(args) => disparity::run(args),
        Command::Dataset(args) => dataset::run(args),
        Command::Benchmark(args) => benchmark::run(args),
        Command::Detect(args) => detect::run(args),
        Command::TrainDetector(args) => train_detector::run(args),
        Command::TrainRepair(args) => train_repair::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
