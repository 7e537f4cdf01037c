//! End-to-end tests of `streaks benchmark`: a tiny dataset with every built-in method and an
//! external command that must score exactly as `sgm`, pair folders (with the road mask
//! `streaks stereo` writes), and bad input that must fail clearly without a report.

use crate::common::TestDir;
use serde_json::Value;

/// The report of a benchmark run.
fn report(t: &TestDir, out: &str) -> Value {
    let text = std::fs::read_to_string(t.join(out).join("report.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The summary entry of `method`.
fn summary<'a>(r: &'a Value, method: &str) -> &'a Value {
    r["summary"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == method)
        .unwrap_or_else(|| panic!("no {method} in the summary"))
}

/// `streaks disparity {left} {right} -o {out}`: the external twin of `sgm`.
fn again() -> String {
    format!(
        "again={} disparity {{left}} {{right}} -o {{out}}",
        env!("CARGO_BIN_EXE_streaks")
    )
}

#[test]
fn dataset_benchmark_scores_every_method_and_a_command_like_sgm() {
    let t = TestDir::new();
    t.streaks(&[
        "dataset", "generate", "-o", "ds", "--count", "2", "--width", "96", "--height", "64",
        "--spp", "4",
    ])
    .assert_success();
    let cmd = again();
    t.streaks(&[
        "benchmark",
        "ds",
        "--method",
        "sgm",
        "sgm-streaks",
        "lk",
        "--method-cmd",
        &cmd,
        "-o",
        "out",
    ])
    .assert_success();
    let r = report(&t, "out");
    assert_eq!(r["format"], "streaks-benchmark/1");
    assert_eq!(r["input"]["kind"], "dataset");
    let names: Vec<&str> = r["methods"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["sgm", "sgm-streaks", "lk", "again"]);
    let samples = r["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 2);
    for s in samples {
        assert_eq!(
            (s["width"].as_u64(), s["height"].as_u64()),
            (Some(96), Some(64))
        );
        assert_eq!(s["road_mask"], true);
        let res = s["results"].as_array().unwrap();
        // The command's map is `sgm`'s, bit for bit, so are its scores.
        assert_eq!(res[3]["errors"], res[0]["errors"], "sample {}", s["id"]);
        for m in res {
            let e = &m["errors"];
            let n = |k: &str| e[k]["truth_pixels"].as_u64().unwrap();
            // The regions partition the pixels with a ground truth.
            assert_eq!(n("streak") + n("road") + n("off_road"), n("all"));
            assert_eq!(n("streak") + n("non_streak"), n("all"));
            assert!(n("all") > 0 && n("road_surface") > 0);
            assert_eq!(m["phantom_hole_rate"], e["road_surface"]["below_1px"]);
            assert!(m["seconds"].as_f64().unwrap() > 0.0);
            for k in ["bad_1", "bad_2", "bad_3", "d1", "density"] {
                let v = e["all"][k].as_f64().unwrap();
                assert!((0.0..=1.0).contains(&v), "{k} = {v}");
            }
            let (b1, b3) = (e["all"]["bad_1"].as_f64(), e["all"]["bad_3"].as_f64());
            assert!(b1 >= b3, "{b1:?} {b3:?}");
        }
    }
    // Pixel-weighted pooling: the summary's pixel counts are the samples' sums.
    let sgm = summary(&r, "sgm");
    let total: u64 = samples
        .iter()
        .map(|s| {
            s["results"][0]["errors"]["all"]["truth_pixels"]
                .as_u64()
                .unwrap()
        })
        .sum();
    assert_eq!(sgm["errors"]["all"]["truth_pixels"].as_u64(), Some(total));
    assert_eq!(summary(&r, "again")["errors"], sgm["errors"]);
    // LK measures only along detected streaks: far fewer values than SGM.
    let density = |m: &str| summary(&r, m)["errors"]["all"]["density"].as_f64().unwrap();
    assert!(density("lk") < 0.2 * density("sgm"), "{}", density("lk"));
    assert!(density("sgm") > 0.3, "{}", density("sgm"));
    // The repair leaves no road pixel far below the road plane it fitted: never more phantom
    // holes than plain SGM.
    let holes = |m: &str| summary(&r, m)["phantom_hole_rate"].as_f64().unwrap();
    assert!(
        holes("sgm-streaks") <= holes("sgm"),
        "{} {}",
        holes("sgm-streaks"),
        holes("sgm")
    );
    // The page: every method, a left thumbnail and an error map per method and sample.
    let page = std::fs::read_to_string(t.join("out/index.html")).unwrap();
    for m in names {
        assert!(page.contains(m), "{m}");
    }
    assert_eq!(page.matches("src=\"data:image/png;base64,").count(), 2 * 5);
    assert!(page.contains("<svg") && page.contains("phantom-hole rate"));
    // A split: exactly its samples.
    let split = ["train", "val", "test"]
        .into_iter()
        .find(|s| {
            std::fs::read_to_string(t.join(&format!("ds/splits/{s}.txt")))
                .is_ok_and(|text| !text.trim().is_empty())
        })
        .unwrap();
    let ids: Vec<String> = std::fs::read_to_string(t.join(&format!("ds/splits/{split}.txt")))
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    t.streaks(&[
        "benchmark",
        "ds",
        "--split",
        split,
        "--method",
        "lk",
        "-o",
        "split",
    ])
    .assert_success();
    let got: Vec<String> = report(&t, "split")["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["id"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(got, ids);
}

/// Renders the tiny scene with its floor flagged as the road into `dir`.
fn road_pair(t: &TestDir, dir: &str) {
    let scene = t.write_tiny_gltf();
    let text = std::fs::read_to_string(&scene).unwrap();
    let flagged = text.replace("\"alpha\": 0.1}", "\"alpha\": 0.1, \"road\": true}");
    assert_ne!(flagged, text);
    std::fs::write(&scene, flagged).unwrap();
    t.streaks(&[
        "stereo",
        "scene.gltf",
        "-o",
        dir,
        "--spp",
        "2",
        "--height",
        "32",
        "--baseline",
        "0.2",
    ])
    .assert_success();
}

#[test]
fn pair_folders_are_benchmarked_with_their_road_masks() {
    let t = TestDir::new();
    road_pair(&t, "pairs/a");
    road_pair(&t, "pairs/b");
    // `streaks stereo` writes the road mask of each eye; the floor is most of the image.
    let mask = streaks_image::GrayImage::load(&t.join("pairs/a/road_mask_left.png")).unwrap();
    let road = mask.data.iter().filter(|&&v| v > 0.0).count();
    assert!(road > mask.data.len() / 3, "{road}");
    assert!(t.join("pairs/a/road_mask_right.png").exists());
    // One pair folder.
    t.streaks(&["benchmark", "pairs/a", "--method", "sgm", "-o", "one"])
        .assert_success();
    let one = report(&t, "one");
    assert_eq!(one["input"]["kind"], "pair");
    assert_eq!(one["samples"][0]["id"], "a");
    assert_eq!(one["samples"][0]["road_mask"], true);
    let road_pixels = one["samples"][0]["results"][0]["errors"]["road_surface"]["truth_pixels"]
        .as_u64()
        .unwrap();
    assert_eq!(road_pixels as usize, road);
    // A folder of pair folders.
    t.streaks(&["benchmark", "pairs", "--method", "sgm", "-o", "two"])
        .assert_success();
    let two = report(&t, "two");
    assert_eq!(two["input"]["kind"], "pairs");
    let ids: Vec<&str> = two["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["id"].as_str().unwrap())
        .collect();
    assert_eq!(ids, ["a", "b"]);
}

#[test]
fn bad_benchmark_input_fails_clearly_without_a_report() {
    let t = TestDir::new();
    road_pair(&t, "pair");
    std::fs::create_dir(t.join("empty")).unwrap();
    let fails = |args: &[&str], needle: &str| {
        let mut all = vec!["benchmark"];
        all.extend(args);
        all.extend(["-o", "out"]);
        t.streaks(&all).assert_failure_mentioning(needle);
        assert!(
            !t.join("out/report.json").exists(),
            "{args:?} left a report"
        );
        assert!(!t.join("out/index.html").exists(), "{args:?} left a page");
    };
    fails(&["pair", "--method", "sgbm"], "unknown method \"sgbm\"");
    fails(
        &["pair", "--method-cmd", "x=run {left} {right}"],
        "has no {out}",
    );
    fails(&["pair", "--method-cmd", "sgm=run {out}"], "built-in");
    fails(&["pair"], "no method");
    fails(&["empty", "--method", "sgm"], "neither a dataset");
    fails(&["nowhere", "--method", "sgm"], "nowhere");
    fails(
        &["pair", "--split", "test", "--method", "sgm"],
        "needs a dataset",
    );
    // A failing command: its name, the sample and its stderr.
    fails(
        &[
            "pair",
            "--method",
            "sgm",
            "--method-cmd",
            "boom=echo kaputt >&2; exit 3 # {out}",
        ],
        "kaputt",
    );
    let run = t.streaks(&[
        "benchmark",
        "pair",
        "--method-cmd",
        "boom=echo kaputt >&2; exit 3 # {out}",
        "-o",
        "out",
    ]);
    let err = run.stderr();
    assert!(
        err.contains("method boom on sample pair") && err.contains("exit status: 3"),
        "{err}"
    );
    // A command that writes nothing, and one that writes a map of the wrong size.
    fails(&["pair", "--method-cmd", "lazy=true {out}"], "wrote no");
    let small = t.join("small.pfm");
    streaks_image::pfm::write_pfm(&small, &streaks_image::GrayImage::new(5, 4, 1.0).unwrap())
        .unwrap();
    let copy = format!("small=cp {} {{out}}", small.display());
    fails(&["pair", "--method-cmd", &copy], "5x4 disparity map");
}
