//! Makes the render regression references (`streaks_render::regression`): for every case, the
//! mean and per-sample variance of many one-sample renders, written to
//! `crates/render/tests/references/<scene>.exr`.
//!
//! ```text
//! cargo run --release -p streaks-render --example regression_references [SCENE...]
//! ```
//!
//! Remake them only when a change of the images is intended, and say so in the commit.

use std::time::Instant;
use streaks_render::regression::{REFERENCE_RENDERS, REGRESSION_CASES};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let only: Vec<String> = std::env::args().skip(1).collect();
    for case in REGRESSION_CASES {
        if !only.is_empty() && !only.iter().any(|s| s == case.scene) {
            continue;
        }
        let start = Instant::now();
        let scene = case.load()?;
        let reference = case.make_reference(&scene)?;
        let path = case.reference_path();
        reference.save(&path)?;
        println!(
            "{}: {}x{}, {} one-sample renders in {:.1} s, wrote {}",
            case.scene,
            case.width,
            case.height,
            REFERENCE_RENDERS,
            start.elapsed().as_secs_f64(),
            path.display()
        );
    }
    Ok(())
}
