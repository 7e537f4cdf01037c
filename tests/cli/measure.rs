//! End-to-end tests of the measuring commands on synthetic pairs with known disparity.

use crate::common::TestDir;
use streaks_analysis::synth::SynthPair;
use streaks_dataset::files::SAMPLE_NAMES;

/// The constant disparity of the synthetic pair.
const D: f32 = 3.4;

/// RMS error of `streaks lk`'s per-row disparities (JSON) against [`D`].
fn lk_rms(t: &TestDir, extra: &[&str]) -> f64 {
    let mut args = vec![
        "lk",
        SAMPLE_NAMES.png[0],
        SAMPLE_NAMES.png[1],
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
    let mut pair = SynthPair::shifted(96, 32, 5, D, 1.0, 0.0).unwrap();
    for img in [&mut pair.left, &mut pair.right] {
        for v in &mut img.data {
            *v *= 0.3;
        }
    }
    for y in (3..30).step_by(2) {
        pair.left.set(44 + (y % 5) - 2, y, 1.0);
    }
    pair.save(t.path()).unwrap();
    let raw = lk_rms(&t, &["--raw"]);
    let prepared = lk_rms(&t, &[]);
    // Measured: 0.14 px prepared, 3.6 px raw.
    assert!(prepared < 0.25, "prepared pair: RMS {prepared} px");
    assert!(raw > 5.0 * prepared, "raw {raw} px, prepared {prepared} px");
}

/// `streaks locus --model centre` prints the streak-centre model beside Eq. 4: in the paper's
/// Fig. 6 configuration its disparity is flat (the light's, 0.24828 deg) where Eq. 4's spans
/// 0.0078 deg over the 4-degree tilt range.
#[test]
fn locus_centre_model_is_flat_where_eq4_is_not() {
    let t = TestDir::new();
    let run = t.streaks(&[
        "locus",
        "--light",
        "0,1.5,15",
        "--viewer",
        "0,1.5,0",
        "--max-tilt",
        "4",
        "--samples",
        "9",
        "--model",
        "centre",
    ]);
    run.assert_success();
    let text = String::from_utf8_lossy(&run.output.stdout).into_owned();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (d, e4, el) = (
        col("disparity_deg"),
        col("eq4_disparity_deg"),
        col("elevation_deg"),
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 9);
    let span = |c: usize| {
        let v = rows.iter().map(|r| r[c]);
        v.clone().fold(f64::MIN, f64::max) - v.fold(f64::MAX, f64::min)
    };
    assert!(span(d) < 0.0005, "centre span {} deg", span(d));
    assert!(
        (span(e4) - 0.00778).abs() < 1e-4,
        "Eq. 4 span {} deg",
        span(e4)
    );
    assert!((span(el) - 8.0).abs() < 1e-3, "elevation span {}", span(el));
    for r in &rows {
        assert!((r[d] - 0.248281).abs() < 0.0003, "{r:?}");
    }
}

/// `streaks disparity --streaks repair` on a rendered pair writes the repaired map, its
/// confidence map (probabilities, 0 exactly where there is no value) and the streak mask,
/// and `--truth --road` scores the road's phantom-hole rate; `--road` without `--truth`, a
/// bad `--streaks` and a bad `--model` are errors.
#[test]
fn disparity_streak_repair_writes_confidence_and_scores_phantom_holes() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    t.streaks(&[
        "stereo",
        "scene.gltf",
        "-o",
        "pair",
        "--spp",
        "4",
        "--height",
        "48",
        "--baseline",
        "0.1",
    ])
    .assert_success();
    // The floor is the road: a road mask of the pixels with a ground truth below the horizon.
    let truth = streaks_image::pfm::read_pfm(&t.join("pair/disp0.pfm")).unwrap();
    let road = image::GrayImage::from_fn(truth.width as u32, truth.height as u32, |x, y| {
        let d = truth.get(x as usize, y as usize);
        image::Luma([if d.is_finite() && y as usize > truth.height / 2 {
            255
        } else {
            0
        }])
    });
    road.save(t.join("road.png")).unwrap();
    let run = t.streaks(&[
        "disparity",
        "pair/im0.png",
        "pair/im1.png",
        "-o",
        "d.pfm",
        "--max-disp",
        "31",
        "--streaks",
        "repair",
        "--truth",
        "pair/disp0.pfm",
        "--road",
        "road.png",
    ]);
    run.assert_success();
    let json: serde_json::Value = serde_json::from_slice(&run.output.stdout).unwrap();
    let phantom = json["phantom_hole_rate"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&phantom), "{json}");
    assert!(
        json["off_road"]["truth_pixels"].as_u64().is_some(),
        "{json}"
    );
    assert!(run.stderr().contains("streaks:"), "{}", run.stderr());
    let conf = streaks_image::pfm::read_pfm(&t.join("d_confidence.pfm")).unwrap();
    assert_eq!((conf.width, conf.height), (truth.width, truth.height));
    let disp = streaks_image::pfm::read_pfm(&t.join("d.pfm")).unwrap();
    for (&c, &d) in conf.data.iter().zip(&disp.data) {
        assert!((0.0..=1.0).contains(&c), "confidence {c}");
        assert_eq!(c == 0.0, !d.is_finite(), "confidence {c} for disparity {d}");
    }
    assert!(conf.data.iter().any(|&c| c > 0.5));
    let mask = image::open(t.join("d_streaks.png")).unwrap().to_luma8();
    assert_eq!(
        (mask.width() as usize, mask.height() as usize),
        (truth.width, truth.height)
    );
    assert!(mask.pixels().all(|p| p[0] == 0 || p[0] == 255));
    std::fs::write(t.join("bad.json"), "{\"format\": \"streaks-repair/0\"}").unwrap();
    t.streaks(&[
        "disparity",
        "pair/im0.png",
        "pair/im1.png",
        "-o",
        "f.pfm",
        "--streaks",
        "mask",
        "--model",
        "bad.json",
    ])
    .assert_failure_mentioning("bad.json");
    t.streaks(&[
        "disparity",
        "pair/im0.png",
        "pair/im1.png",
        "-o",
        "e.pfm",
        "--road",
        "road.png",
    ])
    .assert_failure_mentioning("--truth");
    t.streaks(&[
        "disparity",
        "pair/im0.png",
        "pair/im1.png",
        "-o",
        "e.pfm",
        "--streaks",
        "fix",
    ])
    .assert_failure_mentioning("fix");
}
