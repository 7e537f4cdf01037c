//! `streaks dataset`: generate stereo datasets of procedural rainy streets, and index them.
//!
//! - [`generate`]: `streaks dataset generate -o DIR --count N ...` renders the samples (or one
//!   shard of them) into `DIR/samples/NNNNNN/`, each published atomically, with its KITTI view;
//! - [`index`]: `streaks dataset index DIR` verifies the files against `manifest.jsonl`, or
//!   (the first time, or with `--rebuild`) checks what is on disk and writes `manifest.jsonl`
//!   and `splits/`;
//! - [`preview`]: `streaks dataset preview SAMPLE -o PNG` writes a sample's left image beside
//!   its ground-truth disparity (and rain mask) for a person to look at;
//! - [`stats`]: `streaks dataset stats DIR` writes an HTML page of histograms of the drawn
//!   parameters, with thumbnails, and a contact sheet;
//! - [`sample`]: rendering and writing one sample.
//! - [`sample`]: rendering and writing one sample;
//! - [`flow`]: a sample's flow ground truth, from the scene of the next frame of its drive.
//!
//! The folder layout, `dataset.json`, `meta.json`, the manifest, the locks, the shards and the
//! checks of the samples are the `streaks-dataset` crate's.
//!
//! docs/datasets.md describes the layout and the conventions for users.

pub mod flow;
pub mod generate;
pub mod index;
pub mod preview;
pub mod sample;
pub mod stats;

use anyhow::Result;

/// Generate stereo datasets of procedural rainy streets, and index them.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// Render samples (all, or one shard) into a dataset folder; resumable, repairs damaged
    /// samples.
    Generate(generate::Args),
    /// Verify a dataset folder against its manifest.jsonl (or, the first time or with
    /// --rebuild, write manifest.jsonl and splits/ from what is on disk).
    Index(index::Args),
    /// Write a sample's left image beside its ground-truth disparity (and rain or fog mask) as one
    /// PNG.
    Preview(preview::Args),
    /// Write an HTML page of histograms of the drawn parameters, with thumbnails, and a contact
    /// sheet of twelve samples.
    Stats(stats::Args),
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    match args.command {
        Command::Generate(a) => generate::run(a),
        Command::Index(a) => index::run(a),
        Command::Preview(a) => preview::run(a),
        Command::Stats(a) => stats::run(a),
    }
}
