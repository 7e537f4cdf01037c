//! Fuzz targets for every reader of the streaks project, shared by two runners:
//!
//! - the stable runner (`src/main.rs`, `cargo run -p streaks-fuzz -- --all`): replays each
//!   target's corpus and regressions, then mutates the corpus for a time budget, each target
//!   in a child process with a memory limit and a per-input time limit; CI runs it;
//! - cargo-fuzz (the repository's `fuzz/` folder, `cargo +nightly fuzz run gltf`): libFuzzer
//!   with coverage feedback, calling the same functions.
//!
//! [`targets`] holds one function per reader, [`files`] the format of inputs made of several
//! files, [`mutate`] the stable runner's mutator and [`seeds`] the crafted seed inputs. The
//! inputs live in the repository's `fuzz/` folder, where cargo-fuzz looks for them:
//! `corpus/<target>/` (seeds), `regressions/<target>/` (findings since fixed, replayed by
//! every run and by `cargo test`), `open/<target>/` (findings not fixed yet, replayed with
//! `--open`) and `artifacts/<target>/` (new findings, not committed).

pub mod files;
pub mod mutate;
pub mod seeds;
pub mod targets;

use std::path::{Path, PathBuf};

/// The repository's `fuzz/` folder (`corpus/`, `regressions/`, `open/`, `artifacts/`).
pub fn fuzz_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    dir.canonicalize().unwrap_or(dir)
}
