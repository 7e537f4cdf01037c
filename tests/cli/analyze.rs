//! End-to-end tests of `streaks analyze` (on a tiny `streaks stereo` render of
//! rainy_street_small) and `streaks paper` (at tiny sizes).

use crate::common::TestDir;
use std::path::PathBuf;

fn scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

fn finite(v: &serde_json::Value) -> bool {
    v.as_f64().is_some_and(f64::is_finite)
}

#[test]
fn analyze_reports_streaks_matched_to_lights_with_depths_below_the_road() {
    let t = TestDir::new();
    let scene = scenes().join("rainy_street_small.gltf");
    t.streaks(&[
        "stereo",
        scene.to_str().unwrap(),
        "-o",
        "out",
        "--spp",
        "4",
        "--height",
        "120",
    ])
    .assert_success();
    let run = t.streaks(&["analyze", "out", "--region", "left_half=20,70,35,110"]);
    run.assert_success();
    assert!(run.stderr().contains("RMS px"), "{}", run.stderr());
    let files = t.files_in("out/analysis");
    for f in ["report.json", "depth.png", "side_view.png", "left_half.png"] {
        assert!(files.contains(&f.to_string()), "{f} missing from {files:?}");
    }
    let text = std::fs::read_to_string(t.join("out/analysis/report.json")).unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(r["rig"]["height"], 120);
    assert!((r["rig"]["baseline_m"].as_f64().unwrap() - 0.065).abs() < 1e-6);
    let streaks = r["streaks"].as_array().unwrap();
    assert!(!streaks.is_empty(), "no streak detected");
    // At least one streak comes from a light: its Eq. 4 prediction is about f b / Z_L and its
    // implied points lie below the road.
    let matched: Vec<&serde_json::Value> =
        streaks.iter().filter(|s| !s["light"].is_null()).collect();
    assert!(!matched.is_empty(), "no streak matched to a light");
    let f = r["rig"]["focal_px"].as_f64().unwrap();
    for s in &matched {
        let light_z = s["light"]["road"][2].as_f64().unwrap();
        let c = &s["comparison"];
        assert!(finite(&c["rms_px"]) && finite(&c["rms_deg"]), "{c}");
        for row in s["rows"].as_array().unwrap() {
            if let Some(p) = row["predicted_px"].as_f64() {
                // The virtual light is within a few metres of the light's depth.
                let z = f * 0.065 / p;
                assert!((z - light_z).abs() < 0.3 * light_z, "{z} vs {light_z}");
            }
        }
        assert!(s["median_road_y_m"].as_f64().unwrap() < 0.0, "{s}");
    }
    let n_named = r["regions"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|g| g["name"] == "left_half")
        .count();
    assert_eq!(n_named, 1);
    // Road and a pole picked from the ground truth, sub-pixel against it on their confident
    // rows (NCC >= 0.8; the others are counted).
    for kind in ["road", "object"] {
        let g = r["regions"]
            .as_array()
            .unwrap()
            .iter()
            .find(|g| g["kind"] == kind)
            .unwrap_or_else(|| panic!("no {kind} region"));
        let rows = g["rows"].as_array().unwrap().len() as u64;
        let left_out = g["low_confidence_rows"].as_u64().unwrap();
        let c = &g["comparison"];
        assert!(
            2 * left_out < rows,
            "{kind}: {left_out} of {rows} rows left out"
        );
        assert!(c["rms_px"].as_f64().unwrap() < 0.5, "{kind}: {c}");
        assert!(g["window"].as_u64().unwrap() % 2 == 1, "{g}");
    }
    assert!(r["dense"]["density"].as_f64().unwrap() > 0.2);
    // The SGM disparity scored against the ground truth, split by the renderer's streak mask.
    let acc = &r["dense"]["accuracy"];
    assert_eq!(acc["streak_mask"], "renderer", "{acc}");
    let pixels = |k: &str| acc[k]["truth_pixels"].as_u64().unwrap();
    assert!(pixels("streak") > 0, "{acc}");
    assert_eq!(
        pixels("all"),
        pixels("streak") + pixels("non_streak"),
        "{acc}"
    );
    for k in ["all", "streak", "non_streak"] {
        for f in ["bad", "mean_abs", "density"] {
            assert!(finite(&acc[k][f]), "{k}.{f}: {acc}");
        }
    }
    assert!(run.stderr().contains("bad-2.0"), "{}", run.stderr());
    // The paper's point: SGM goes wrong on the streaks, not elsewhere.
    let bad = |k: &str| acc[k]["bad"].as_f64().unwrap();
    assert!(bad("streak") > 2.0 * bad("non_streak"), "{acc}");
    assert!(bad("non_streak") < 0.1, "{acc}");
    // Bad inputs are errors, not panics.
    let bad = t.streaks(&["analyze", "out", "--region", "x=1,2,3"]);
    assert!(!bad.output.status.success());
    let missing = t.streaks(&["analyze", "nowhere"]);
    assert!(!missing.output.status.success());
    assert!(missing.stderr().contains("nowhere"), "{}", missing.stderr());
}

#[test]
fn paper_writes_every_figure_and_the_fig6_numbers() {
    let t = TestDir::new();
    let scenes = scenes();
    t.streaks(&[
        "paper",
        "-o",
        "paper",
        "--scenes",
        scenes.to_str().unwrap(),
        "--fig2-width",
        "40",
        "--fig2-spp",
        "2",
        "--fig6-size",
        "200",
        "--fig6-spp",
        "8",
    ])
    .assert_success();
    let files = t.files_in("paper");
    for f in [
        "fig2_blinn_phong.png",
        "fig2_ward.png",
        "fig2_sphere.png",
        "fig3_ward.png",
        "fig4.png",
        "fig5.png",
        "fig6_deg.png",
        "fig6_px.png",
        "index.md",
    ] {
        assert!(files.contains(&f.to_string()), "{f} missing from {files:?}");
    }
    let text = std::fs::read_to_string(t.join("paper/fig6/analysis/report.json")).unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    let s = r["streaks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["light"]["index"] == 0)
        .expect("the Fig. 6 streak is matched to its light");
    // Eq. 4 predicts f b / 15 m or so; LK must be close to it.
    let rms = s["comparison"]["rms_px"].as_f64().unwrap();
    assert!(rms < 0.1, "Fig. 6 RMS {rms} px");
    let index = std::fs::read_to_string(t.join("paper/index.md")).unwrap();
    assert!(index.contains("RMS difference"), "{index}");
}

/// `streaks analyze` reads a dataset sample as it reads a `streaks stereo` folder: the images
/// and ground truth by the sample layout's names, the rig and lights from `meta.json`.
#[test]
fn analyze_reads_a_dataset_sample() {
    let t = TestDir::new();
    t.streaks(&[
        "dataset", "generate", "-o", "ds", "--count", "1", "--width", "96", "--height", "64",
        "--spp", "2",
    ])
    .assert_success();
    let sample = "ds/samples/000000";
    let run = t.streaks(&["analyze", sample]);
    run.assert_success();
    let text = std::fs::read_to_string(t.join(&format!("{sample}/analysis/report.json"))).unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    let meta: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(t.join(&format!("{sample}/{}", streaks_dataset::files::META)))
            .unwrap(),
    )
    .unwrap();
    assert_eq!(r["rig"]["width"], 96);
    assert_eq!(r["rig"]["height"], 64);
    let baseline = |v: &serde_json::Value| v.as_f64().unwrap();
    assert!(
        (baseline(&r["rig"]["baseline_m"]) - baseline(&meta["rig"]["baseline_m"])).abs() < 1e-6
    );
}

/// `streaks analyze` checks the road plane of a dataset sample from its depth and road mask;
/// with the road pixels' depths stretched by 30 % (points below the plane, farther down the
/// farther they are), it warns, records the violation in report.json, and predicts no streak.
#[test]
fn analyze_says_when_the_road_is_not_a_plane() {
    let t = TestDir::new();
    let flat = t.write_flat_street_config();
    t.streaks(&[
        "dataset", "generate", "--config", &flat, "-o", "ds", "--count", "1", "--width", "96",
        "--height", "64", "--spp", "2",
    ])
    .assert_success();
    let sample = t.join("ds/samples/000000");
    let run = t.streaks(&["analyze", "ds/samples/000000"]);
    run.assert_success();
    let report = || -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(sample.join("analysis/report.json")).unwrap())
            .unwrap()
    };
    let plane = &report()["road_plane"];
    assert!(plane["points"].as_u64().unwrap() >= 20, "{plane}");
    assert!(run.stderr().contains("road plane") || run.stderr().contains("road-plane"));

    let depth_path = sample.join("depth0.pfm");
    let mut depth = streaks_image::pfm::read_pfm(&depth_path).unwrap();
    let road = streaks_image::GrayImage::load(&sample.join("road0.png")).unwrap();
    for (z, m) in depth.data.iter_mut().zip(&road.data) {
        if *m > 0.5 {
            *z *= 1.3;
        }
    }
    streaks_image::pfm::write_pfm(&depth_path, &depth).unwrap();
    let run = t.streaks(&["analyze", "ds/samples/000000"]);
    run.assert_success();
    assert!(
        run.stderr()
            .contains("warning: road-plane assumption violated"),
        "{}",
        run.stderr()
    );
    let r = report();
    let plane = &r["road_plane"];
    assert_eq!(plane["violated"], true, "{plane}");
    // The rig is about 1.2 m high: at 30 % more depth a road point is 0.3 x 1.2 m below.
    assert!(plane["max_m"].as_f64().unwrap() < -0.2, "{plane}");
    for s in r["streaks"].as_array().unwrap() {
        assert!(s["comparison"].is_null() && s["centre_comparison"].is_null());
        for row in s["rows"].as_array().unwrap() {
            assert!(row["predicted_px"].is_null(), "{row}");
        }
    }
}

/// A generated street over a crest is not a plane: `streaks analyze` says so from the sample's
/// own depth, untouched.
#[test]
fn analyze_finds_a_crest_off_the_road_plane() {
    let t = TestDir::new();
    std::fs::write(
        t.join("crest.toml"),
        "[road]\ncurve = 0.0\nhill = 1.0\ngrade = [0.05, 0.06]\ngrade_change = [-0.12, -0.1]\n\
         vertical_curve_start = [5.0, 8.0]\nvertical_curve_length = [25.0, 30.0]\n",
    )
    .unwrap();
    t.streaks(&[
        "dataset",
        "generate",
        "--config",
        "crest.toml",
        "-o",
        "ds",
        "--count",
        "1",
        "--width",
        "96",
        "--height",
        "64",
        "--spp",
        "2",
    ])
    .assert_success();
    let run = t.streaks(&["analyze", "ds/samples/000000"]);
    run.assert_success();
    assert!(
        run.stderr()
            .contains("warning: road-plane assumption violated"),
        "{}",
        run.stderr()
    );
    let report: serde_json::Value = serde_json::from_slice(
        &std::fs::read(t.join("ds/samples/000000/analysis/report.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        report["road_plane"]["violated"], true,
        "{}",
        report["road_plane"]
    );
}
