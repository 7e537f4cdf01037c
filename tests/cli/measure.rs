//! End-to-end tests of the measuring commands on synthetic pairs with known disparity.

use crate::common::TestDir;
use streaks_analysis::synth::{SynthPair, Texture};
use streaks_stereo::image::GrayImage;

/// The constant disparity of the synthetic pair.
const D: f32 = 3.4;

/// RMS error of `streaks lk`'s per-row disparities (JSON) against [`D`].
fn lk_rms(t: &TestDir, extra: &[&str]) -> f64 {
    let mut args = vec![
        "lk",
        "left.png",
        "right.png",
        "--region",
        "40,2,48,30",
        "--max-disp",
        "16",
        "--format",
        "json",
    ];
    args.extend_from_slice(extra);
    let run = t.streaks(&args);
    run.assert_success();
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&run.output.stdout).unwrap();
    assert_eq!(rows.len(), 28);
    let sq: f64 = rows
        .iter()
        .map(|r| (r["disparity"].as_f64().unwrap_or(f64::INFINITY) - D as f64).powi(2))
        .sum();
    (sq / rows.len() as f64).sqrt()
}

#[test]
fn lk_measures_through_fireflies_unless_raw() {
    // A dark textured pair at a constant disparity, with one-pixel fireflies in the left
    // image along the measured column, as a 16-spp render has them.
    let t = TestDir::new();
    let (w, h) = (96, 32);
    let texture = Texture::new(5);
    let mut left = GrayImage::new(w, h, 0.0).unwrap();
    let mut right = GrayImage::new(w, h, 0.0).unwrap();
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = (x as f32 + 0.5, y as f32 + 0.5);
            left.set(x, y, 0.3 * texture.at(xc, yc));
            right.set(x, y, 0.3 * texture.at(xc + D, yc));
        }
    }
    for y in (3..30).step_by(2) {
        left.set(44 + (y % 5) - 2, y, 1.0);
    }
    let disparity = GrayImage::new(w, h, D).unwrap();
    SynthPair {
        left,
        right,
        disparity,
    }
    .save(t.path())
    .unwrap();
    let raw = lk_rms(&t, &["--raw"]);
    let prepared = lk_rms(&t, &[]);
    // Measured: 0.14 px prepared, 3.6 px raw.
    assert!(prepared < 0.25, "prepared pair: RMS {prepared} px");
    assert!(raw > 5.0 * prepared, "raw {raw} px, prepared {prepared} px");
}
