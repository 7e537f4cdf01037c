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

/// The same as one batch command: `streaks disparity` on each line of the list.
fn batch() -> String {
    format!(
        "batch=sh -c 'tab=$(printf \"\\t\"); while IFS=\"$tab\" read -r l r o; do \
         \"$0\" disparity \"$l\" \"$r\" -o \"$o\" || exit 1; done < \"$1\"' {} {{list}}",
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
    let (cmd, batch) = (again(), batch());
    t.streaks(&[
        "benchmark",
        "ds",
        "--method",
        "sgm",
        "sgm-streaks",
        "lk",
        "--method-cmd",
        &cmd,
        "--method-cmd",
        &batch,
        "-o",
        "out",
    ])
    .assert_success();
    let r = report(&t, "out");
    assert_eq!(r["format"], "streaks-benchmark/3");
    assert_eq!(r["input"]["kind"], "dataset");
    let names: Vec<&str> = r["methods"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["sgm", "sgm-streaks", "lk", "again", "batch"]);
    let samples = r["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 2);
    for s in samples {
        assert_eq!(
            (s["width"].as_u64(), s["height"].as_u64()),
            (Some(96), Some(64))
        );
        assert_eq!(s["road_mask"], true);
        let res = s["results"].as_array().unwrap();
        // The commands' maps are `sgm`'s, bit for bit, so are their scores.
        assert_eq!(res[3]["errors"], res[0]["errors"], "sample {}", s["id"]);
        assert_eq!(res[4]["errors"], res[0]["errors"], "sample {}", s["id"]);
        for m in res {
            let e = &m["errors"];
            let n = |k: &str| e[k]["truth_pixels"].as_u64().unwrap();
            // The regions partition the pixels with a ground truth.
            assert_eq!(n("streak") + n("road") + n("off_road"), n("all"));
            assert_eq!(n("streak") + n("non_streak"), n("all"));
            assert!(n("all") > 0 && n("road_surface") > 0);
            assert_eq!(m["phantom_hole_rate"], e["road_surface"]["below_1px"]);
            assert!(m["seconds"].as_f64().unwrap() > 0.0);
            assert!(m["seconds_per_megapixel"].as_f64().unwrap() > 0.0);
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
    assert_eq!(summary(&r, "batch")["errors"], sgm["errors"]);
    assert_eq!(r["methods"][4]["kind"], "batch-command");
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
    assert_eq!(page.matches("src=\"data:image/png;base64,").count(), 2 * 6);
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
    let mask = streaks_image::GrayImage::load(&t.join("pairs/a/road0.png")).unwrap();
    let road = mask.data.iter().filter(|&&v| v > 0.0).count();
    assert!(road > mask.data.len() / 3, "{road}");
    assert!(t.join("pairs/a/road1.png").exists());
    // One pair folder.
    t.streaks(&["benchmark", "pairs/a", "--method", "sgm", "-o", "one"])
        .assert_success();
    let one = report(&t, "one");
    assert_eq!(one["input"]["kind"], "pair");
    assert_eq!(one["samples"][0]["id"], "a");
    assert_eq!(one["samples"][0]["road_mask"], true);
    // No meta.json: no conditions, no breakdown by condition.
    assert!(one["samples"][0]["conditions"].is_null() && one["by_condition"].is_null());
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

/// A pair folder that `streaks stereo` wrote before it used the sample layout (`left.png`,
/// `disparity_left.pfm`, ...) is benchmarked as before, with the same result.
#[test]
fn pair_folders_in_the_older_layout_are_still_read() {
    let t = TestDir::new();
    road_pair(&t, "new");
    std::fs::create_dir(t.join("old")).unwrap();
    let new = streaks_dataset::files::SAMPLE_NAMES;
    let old = streaks_dataset::files::PAIR_NAMES;
    for (from, to) in [
        (new.png, old.png),
        (new.disparity, old.disparity),
        (new.streak_mask, old.streak_mask),
        (new.road_mask, old.road_mask),
    ] {
        for i in 0..2 {
            std::fs::copy(
                t.join(&format!("new/{}", from[i])),
                t.join(&format!("old/{}", to[i])),
            )
            .unwrap();
        }
    }
    for (dir, out) in [("new", "r_new"), ("old", "r_old")] {
        t.streaks(&["benchmark", dir, "--method", "sgm", "-o", out])
            .assert_success();
    }
    let (a, b) = (report(&t, "r_new"), report(&t, "r_old"));
    assert_eq!(b["input"]["kind"], "pair");
    assert_eq!(b["samples"][0]["road_mask"], true);
    assert_eq!(
        a["samples"][0]["results"][0]["errors"],
        b["samples"][0]["results"][0]["errors"]
    );
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
    fails(
        &[
            "pair",
            "--method-cmd",
            "a=run {out}",
            "--predictions",
            "a=.",
        ],
        "given twice",
    );
    fails(&["pair", "--method-cmd", "b=run {list} {out}"], "not both");
    fails(&["empty", "--method", "sgm"], "not a dataset");
    fails(&["nowhere", "--method", "sgm"], "nowhere");
    fails(
        &["pair", "--split", "test", "--method", "sgm"],
        "needs a dataset",
    );
    fails(
        &["pair", "--method-cmd", "q=run 'unclosed {out}"],
        "unclosed quote",
    );
    fails(
        &["pair", "--method-cmd", "q=sh -c 'run {left} > {out}'"],
        "program text",
    );
    for bad in ["0", "-1", "soon", "inf"] {
        let flag = format!("--method-timeout={bad}");
        fails(&["pair", "--method", "sgm", &flag], "--method-timeout");
    }
}

#[test]
fn failing_commands_are_recorded_and_the_run_goes_on() {
    let t = TestDir::new();
    road_pair(&t, "pair");
    let small = t.join("small.pfm");
    streaks_image::pfm::write_pfm(&small, &streaks_image::GrayImage::new(5, 4, 1.0).unwrap())
        .unwrap();
    std::fs::write(t.join("junk.pfm"), "not a pfm").unwrap();
    let copy = |name: &str, from: &str| format!("{name}=cp {} {{out}}", t.join(from).display());
    let (small_cmd, junk_cmd) = (copy("small", "small.pfm"), copy("junk", "junk.pfm"));
    let args = [
        "benchmark",
        "pair",
        "--method",
        "sgm",
        "--method-cmd",
        "boom=sh -c 'echo kaputt >&2; echo said >&1; exit 3' sh {out}",
        "--method-cmd",
        "lazy=true {out}",
        "--method-cmd",
        &small_cmd,
        "--method-cmd",
        &junk_cmd,
        "--method-cmd",
        "missing=/no/such/program {out}",
        "--method-cmd",
        "killed=sh -c 'kill -9 $$' sh {out}",
        "--method-cmd",
        "link=ln -s /dev/zero {out}",
        "-o",
        "out",
    ];
    // Every failure is named on stderr, the report is written, and the exit status says so.
    let run = t.streaks(&args);
    run.assert_failure_mentioning("7 method runs failed");
    let err = run.stderr();
    assert!(
        err.contains("method boom failed on sample \"pair\": exited with status 3")
            && err.contains("kaputt"),
        "{err}"
    );
    let r = report(&t, "out");
    let results = r["samples"][0]["results"].as_array().unwrap();
    let failure = |m: &str| {
        results
            .iter()
            .find(|x| x["method"] == m)
            .unwrap_or_else(|| panic!("no {m}"))["failure"]
            .clone()
    };
    assert!(failure("sgm").is_null());
    for (m, kind, reason) in [
        ("boom", "exit", "exited with status 3"),
        ("lazy", "no_output", "wrote no"),
        ("small", "bad_output", "5x4 disparity map"),
        ("junk", "bad_output", "not a readable PFM"),
        ("missing", "spawn", "/no/such/program"),
        ("killed", "signal", "signal 9"),
        ("link", "bad_output", "not a regular file"),
    ] {
        let f = failure(m);
        assert_eq!(f["kind"], kind, "{m}: {f}");
        assert!(f["reason"].as_str().unwrap().contains(reason), "{m}: {f}");
        // A failed sample is scored as no value: nothing valid, everything bad.
        let e = &summary(&r, m)["errors"]["all"];
        assert_eq!(
            (
                e["valid_pixels"].as_u64(),
                e["bad_all"].as_f64(),
                e["bad_2_filled"].as_f64()
            ),
            (Some(0), Some(1.0), Some(1.0))
        );
        assert_eq!(summary(&r, m)["failed"], 1);
        assert!(summary(&r, m)["phantom_hole_rate"].is_null());
    }
    assert_eq!(failure("boom")["stderr_tail"], "kaputt");
    assert_eq!(failure("boom")["stdout_tail"], "said");
    assert_eq!(summary(&r, "sgm")["failed"], 0);
    let page = std::fs::read_to_string(t.join("out/index.html")).unwrap();
    assert!(page.contains("id=\"failures\"") && page.contains("boom failed on every sample"));
    assert!(page.contains("kaputt") && page.contains("exited with status 3"));
    // --allow-failures: the same report, exit 0.
    let mut allowed = args.to_vec();
    allowed.push("--allow-failures");
    let run = t.streaks(&allowed);
    run.assert_success();
    assert!(run.stderr().contains("warning: 7 method runs failed"));
}

/// A dataset of two 96x64 samples at 4 spp in `dir` of the test folder.
fn tiny_dataset(t: &TestDir, dir: &str) {
    t.streaks(&[
        "dataset", "generate", "-o", dir, "--count", "2", "--width", "96", "--height", "64",
        "--spp", "4",
    ])
    .assert_success();
}

/// The sum of `truth_pixels` over a breakdown's bins; every bin is null or has pixels.
fn bin_pixels(bins: &Value) -> u64 {
    bins.as_array()
        .unwrap()
        .iter()
        .map(|b| match &b["errors"] {
            Value::Null => 0,
            e => {
                let n = e["truth_pixels"].as_u64().unwrap();
                assert!(n > 0, "a bin with no pixels must be null: {b}");
                n
            }
        })
        .sum()
}

#[test]
fn a_dataset_report_breaks_the_errors_down_by_condition_streak_length_and_distance() {
    let t = TestDir::new();
    tiny_dataset(&t, "ds");
    // Set the two samples' weather: 000000 dry at 5 ms (1 stop of gain over the presets'
    // 10 ms: noise), 000001 in rain and fog at 20 ms (no gain).
    let set = |id: &str, rain: f64, fog: Value, exposure: f64| {
        let path = t.join(&format!("ds/samples/{id}/meta.json"));
        let mut meta: Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let w = &mut meta["weather"];
        w["rain_mm_h"] = rain.into();
        w["fog"] = fog;
        w["exposure_s"] = exposure.into();
        std::fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    };
    set("000000", 0.0, Value::Null, 0.005);
    let fog = serde_json::json!({"sigma_t": 0.02, "albedo": 0.95, "g": 0.8, "height_falloff": 0.1});
    set("000001", 3.0, fog, 0.02);
    t.streaks(&["benchmark", "ds", "--method", "sgm", "-o", "out"])
        .assert_success();
    let r = report(&t, "out");
    for k in ["condition", "streak_length", "distance", "empty_bins"] {
        assert!(r["breakdown"][k].is_string(), "{k}");
    }
    let samples = r["samples"].as_array().unwrap();
    assert_eq!(
        samples[0]["conditions"],
        serde_json::json!(["dry", "noise"])
    );
    assert_eq!(samples[1]["conditions"], serde_json::json!(["rain", "fog"]));
    // Each condition pools its own sample; a condition without samples has no figures.
    let all_pixels = |k: usize| samples[k]["results"][0]["errors"]["all"]["truth_pixels"].clone();
    let by = r["by_condition"].as_array().unwrap();
    let names: Vec<&str> = by
        .iter()
        .map(|c| c["condition"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["dry", "rain", "fog", "noise"]);
    for (c, k) in by.iter().zip([0, 1, 1, 0]) {
        assert_eq!(c["samples"], 1, "{}", c["condition"]);
        assert_eq!(c["summary"][0]["method"], "sgm");
        assert_eq!(
            c["summary"][0]["errors"]["all"]["truth_pixels"],
            all_pixels(k)
        );
    }
    // The breakdown by streak length covers exactly the streak pixels on the road with a
    // ground truth; by distance, the road surface and the off-road region.
    let sgm = summary(&r, "sgm");
    let b = &sgm["breakdown"];
    let bins: Vec<&str> = b["streak_length"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["bin"].as_str().unwrap())
        .collect();
    assert_eq!(bins, ["short", "medium", "long"]);
    let mut on_road_streaks = 0;
    for id in ["000000", "000001"] {
        let dir = t.join(&format!("ds/samples/{id}"));
        let streaks = streaks_image::GrayImage::load(&dir.join("streaks0.png")).unwrap();
        let road = streaks_image::GrayImage::load(&dir.join("road0.png")).unwrap();
        let truth = streaks_image::pfm::read_pfm(&dir.join("disp0.pfm")).unwrap();
        on_road_streaks += (0..truth.data.len())
            .filter(|&i| {
                streaks.data[i] > 0.0
                    && road.data[i] > 0.0
                    && truth.data[i].is_finite()
                    && truth.data[i] > 0.0
            })
            .count() as u64;
    }
    assert!(on_road_streaks > 0);
    assert_eq!(bin_pixels(&b["streak_length"]), on_road_streaks);
    let region = |k: &str| sgm["errors"][k]["truth_pixels"].as_u64().unwrap();
    assert_eq!(
        bin_pixels(&b["road_surface_by_distance"]),
        region("road_surface")
    );
    assert_eq!(bin_pixels(&b["off_road_by_distance"]), region("off_road"));
    assert_eq!(b["road_surface_by_distance"][3]["bin"], "40+ m");
    // Per sample too, and the page has the tables.
    let own = &samples[0]["results"][0]["breakdown"];
    assert!(own["streak_length"].is_array() && own["road_surface_by_distance"].is_array());
    let page = std::fs::read_to_string(t.join("out/index.html")).unwrap();
    for heading in ["By condition", "By streak length", "By distance"] {
        assert!(page.contains(heading), "{heading}");
    }
}

#[test]
fn hostile_folder_names_reach_a_method_as_literal_paths() {
    let t = TestDir::new();
    tiny_dataset(&t, "ds");
    let names = [
        // The old substitution put `{right}`'s quoted path inside the quoted left path, which
        // unquoted it: its command substitutions ran.
        "ds {right} \"$(touch PWNED1)\" `touch PWNED2`;touch PWNED3",
        // Placeholders, quotes, a newline, a variable.
        "ds {out} {left} '\"$(touch PWNED4)\" it's\n$HOME;touch PWNED5 \\",
    ];
    let recorder = "recorder=sh -c 'printf %s \"$1\" > args.txt; \
                    printf %s \"$STREAKS_LEFT|$STREAKS_OUT\" > env.txt' sh {left} {out}";
    let cmd = again();
    let mut from = "ds";
    for name in names {
        std::fs::rename(t.join(from), t.join(name)).unwrap();
        from = name;
        t.streaks(&[
            "benchmark",
            name,
            "--method",
            "sgm",
            "--method-cmd",
            &cmd,
            "--method-cmd",
            recorder,
            "--allow-failures",
            "-o",
            "out",
        ])
        .assert_success();
        for k in 1..=5 {
            let f = format!("PWNED{k}");
            assert!(!t.join(&f).exists(), "{name:?} created {f}");
            assert!(!t.join(name).join(&f).exists(), "{name:?} created {f}");
        }
        let r = report(&t, "out");
        // The command got the right images: it scores as `sgm` does.
        assert_eq!(summary(&r, "again")["errors"], summary(&r, "sgm")["errors"]);
        assert_eq!(summary(&r, "again")["failed"], 0);
        // The path arrived byte for byte, as an argument and in the environment.
        let left = t.path().join(name).join("samples/000001/im0.png");
        let got = std::fs::read_to_string(t.join("args.txt")).unwrap();
        assert_eq!(got, left.to_str().unwrap());
        let env = std::fs::read_to_string(t.join("env.txt")).unwrap();
        let (env_left, env_out) = env.split_once('|').unwrap();
        assert_eq!(env_left, got);
        // The output path is in the run's private folder, named by the sample's index.
        assert!(env_out.ends_with("/000001-recorder.pfm"), "{env_out}");
        assert!(
            !std::path::Path::new(env_out).exists(),
            "the private folder is left behind"
        );
        assert_eq!(summary(&r, "recorder")["failed"], 2);
        // A batch command reads the same paths from its list file, blanks, quotes and braces
        // as they are; a newline cannot be written in it: refused before anything runs.
        let _ = std::fs::remove_dir_all(t.join("batch_out"));
        let run = t.streaks(&[
            "benchmark",
            name,
            "--method-cmd",
            &batch(),
            "-o",
            "batch_out",
        ]);
        if name.contains('\n') {
            run.assert_failure_mentioning("tab, newline or carriage return");
            assert!(!t.join("batch_out").exists());
        } else {
            run.assert_success();
            let b = report(&t, "batch_out");
            assert_eq!(summary(&b, "batch")["errors"], summary(&r, "sgm")["errors"]);
        }
        for k in 1..=5 {
            assert!(!t.join(&format!("PWNED{k}")).exists(), "{name:?}: PWNED{k}");
        }
    }
}

/// Runs `streaks ARGS` in `t`, and gives its exit status, stderr and peak memory (kB).
// The child is reaped by wait4, which also gives its resource usage, not by `Child::wait`.
#[allow(clippy::zombie_processes)]
fn streaks_peak_memory(t: &TestDir, args: &[&str]) -> (bool, String, i64) {
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_streaks"))
        .args(args)
        .current_dir(t.path())
        .env("CI", "true")
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(t.join("stderr.txt")).unwrap())
        .spawn()
        .unwrap();
    let mut status = 0;
    // SAFETY: a zeroed rusage is valid; wait4 reaps our own child and fills both.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t);
    let ok = libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0;
    let err = std::fs::read_to_string(t.join("stderr.txt")).unwrap();
    (ok, err, usage.ru_maxrss)
}

#[test]
fn hanging_loud_and_forking_methods_are_bounded() {
    let t = TestDir::new();
    tiny_dataset(&t, "ds");
    let cmd = again();
    let bg = format!(
        "bg=sh -c 'sleep 1237 & exec {} disparity \"$1\" \"$2\" -o \"$3\"' sh {{left}} {{right}} {{out}}",
        env!("CARGO_BIN_EXE_streaks")
    );
    let start = std::time::Instant::now();
    let (ok, err, peak_kb) = streaks_peak_memory(
        &t,
        &[
            "benchmark",
            "ds",
            "--method-timeout",
            "2",
            "--method-cmd",
            &cmd,
            "--method-cmd",
            "slow=sh -c 'echo waiting >&2; sleep 1236' sh {out}",
            "--method-cmd",
            &bg,
            "--method-cmd",
            "loud=sh -c 'head -c 300000000 /dev/zero; echo last words >&2; exit 3' sh {out}",
            "-o",
            "out",
        ],
    );
    let seconds = start.elapsed().as_secs_f64();
    // Two 2 s timeouts and the rest; unbounded, `slow` alone would take 41 minutes and `bg`
    // would hang on the pipes its child holds.
    assert!(seconds < 30.0, "{seconds} s");
    assert!(!ok && err.contains("4 method runs failed"), "{err}");
    // 300 MB printed per sample, a bounded tail kept: far below the output's size.
    assert!(peak_kb < 120_000, "{peak_kb} kB");
    let r = report(&t, "out");
    for s in r["samples"].as_array().unwrap() {
        let res = s["results"].as_array().unwrap();
        let by = |m: &str| res.iter().find(|x| x["method"] == m).unwrap();
        assert_eq!(by("slow")["failure"]["kind"], "timeout", "{s}");
        assert!(by("slow")["failure"]["reason"]
            .as_str()
            .unwrap()
            .contains("--method-timeout 2 s"));
        assert_eq!(by("slow")["failure"]["stderr_tail"], "waiting");
        assert!(by("slow")["seconds"].as_f64().unwrap() < 10.0);
        assert!(by("bg")["failure"].is_null(), "{s}");
        assert_eq!(by("bg")["errors"], by("again")["errors"]);
        assert_eq!(by("loud")["failure"]["stderr_tail"], "last words");
        let out_tail = by("loud")["failure"]["stdout_tail"].as_str().unwrap();
        assert!(out_tail.len() < 20_000, "{}", out_tail.len());
    }
    // No process of the commands is left running.
    let ps = std::process::Command::new("ps")
        .args(["-eo", "args"])
        .output()
        .unwrap();
    let ps = String::from_utf8_lossy(&ps.stdout);
    assert!(
        !ps.contains("sleep 1236") && !ps.contains("sleep 1237"),
        "{ps}"
    );
}

#[test]
fn a_terminated_benchmark_takes_its_running_method_with_it() {
    let t = TestDir::new();
    road_pair(&t, "pair");
    // The command runs in a process group of its own, out of reach of the terminal's Ctrl-C
    // and of a signal to `streaks`' group: `streaks` must kill it when it is told to end.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_streaks"))
        .args([
            "benchmark",
            "pair",
            "--method-cmd",
            "slow=sh -c 'touch started; sleep 97.5' sh {out}",
            "-o",
            "out",
        ])
        .current_dir(t.path())
        .env("CI", "true")
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !t.join("started").exists() {
        assert!(start.elapsed().as_secs() < 30, "the method did not start");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // SAFETY: kill only sends a signal to our own child.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
    let status = child.wait().unwrap();
    assert!(!status.success());
    let gone = std::time::Instant::now();
    loop {
        let ps = std::process::Command::new("ps")
            .args(["-eo", "args"])
            .output()
            .unwrap();
        if !String::from_utf8_lossy(&ps.stdout).contains("sleep 97.5") {
            break;
        }
        assert!(gone.elapsed().as_secs() < 5, "the method outlived streaks");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert!(!t.join("out/report.json").exists());
}

/// An 8x4 test image (any content: the maps below are made beforehand, not estimated).
fn write_rgb(path: &std::path::Path, seed: u8) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let img = image::RgbImage::from_fn(8, 4, |x, y| {
        let v = (x * 29 + y * 53 + u32::from(seed)) as u8;
        image::Rgb([v, v / 2, 255 - v])
    });
    streaks_image::png::write_png_buffer(path, &img).unwrap();
}

/// An 8x4 disparity map from its 32 values, row by row.
fn map(values: [f32; 32]) -> streaks_image::GrayImage {
    streaks_image::GrayImage::from_vec(8, 4, values.to_vec()).unwrap()
}

const INF: f32 = f32::INFINITY;

/// The first sample's ground truth: 16 px everywhere but the first four pixels (no value).
fn truth_a() -> streaks_image::GrayImage {
    let mut v = [16.0; 32];
    v[..4].fill(INF);
    map(v)
}

/// The first sample's estimate: pixels 8-11 off by +2.5 px, 12-13 by -4 px, 14 no value.
fn estimate_a() -> streaks_image::GrayImage {
    let mut e = truth_a();
    e.data[8..12].fill(18.5);
    e.data[12..14].fill(12.0);
    e.data[14] = INF;
    e
}

/// Its non-occluded pixels: all with a truth but pixels 4-7.
fn non_occluded_a() -> streaks_image::GrayImage {
    let mut n = truth_a();
    n.data[4..8].fill(INF);
    n
}

/// The second sample's ground truth (8 px everywhere) and estimate (pixel 20 off by 1.5 px).
fn truth_b() -> streaks_image::GrayImage {
    map([8.0; 32])
}

fn estimate_b() -> streaks_image::GrayImage {
    let mut e = truth_b();
    e.data[20] = 9.5;
    e
}

/// Asserts that the number `v` is `want` up to rounding (the scorer divides counts in its own
/// order).
fn close(v: &Value, want: f64) {
    let got = v.as_f64().unwrap_or_else(|| panic!("{v} is not a number"));
    assert!(
        (got - want).abs() <= 1e-12 * want.abs().max(1.0),
        "{got} != {want}"
    );
}

/// Checks the scores of the first sample against the values counted by hand: of 28 truth
/// pixels, 27 have a value; errors 4 x 2.5 + 2 x 4 = 18 px; bad-1 = bad-2 = 6, bad-3 = D1 = 2
/// (4 px is more than 5 % of 16); of the 24 non-occluded pixels 23 have a value, same errors.
fn assert_scores_a(errors: &Value, non_occluded: bool) {
    let all = &errors["all"];
    assert_eq!(all["truth_pixels"], 28);
    assert_eq!(all["valid_pixels"], 27);
    close(&all["density"], 27.0 / 28.0);
    close(&all["mean_abs"], 18.0 / 27.0);
    for (k, n) in [("bad_1", 6.0), ("bad_2", 6.0), ("bad_3", 2.0), ("d1", 2.0)] {
        close(&all[k], n / 27.0);
    }
    // No streak or road masks: those regions are not available, not zero.
    for region in ["streak", "non_streak", "road", "off_road", "road_surface"] {
        assert!(errors[region].is_null(), "{region}: {}", errors[region]);
    }
    let noc = &errors["non_occluded"];
    if non_occluded {
        assert_eq!(
            (noc["truth_pixels"].as_u64(), noc["valid_pixels"].as_u64()),
            (Some(24), Some(23))
        );
        close(&noc["mean_abs"], 18.0 / 23.0);
        close(&noc["bad_2"], 6.0 / 23.0);
    } else {
        assert!(noc.is_null(), "{noc}");
    }
}

/// Checks the second sample's scores: 32 truth pixels, all valid, one off by 1.5 px.
fn assert_scores_b(errors: &Value) {
    let all = &errors["all"];
    assert_eq!(
        (all["truth_pixels"].as_u64(), all["valid_pixels"].as_u64()),
        (Some(32), Some(32))
    );
    close(&all["mean_abs"], 1.5 / 32.0);
    close(&all["bad_1"], 1.0 / 32.0);
    close(&all["bad_2"], 0.0);
    assert!(errors["streak"].is_null() && errors["non_occluded"].is_null());
}

/// The per-sample results of `method`, in sample order.
fn results<'a>(r: &'a Value, method: &str) -> Vec<&'a Value> {
    r["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            s["results"]
                .as_array()
                .unwrap()
                .iter()
                .find(|x| x["method"] == method)
                .unwrap()
        })
        .collect()
}

#[test]
fn a_kitti_folder_is_scored_with_predictions_and_a_batch_command() {
    use streaks_image::kitti::write_kitti_disparity;
    use streaks_image::pfm::write_pfm;
    let t = TestDir::new();
    let root = t.join("kitti/training");
    let at = |dir: &str, name: &str| root.join(dir).join(name);
    for (k, name) in ["000000_10.png", "000001_10.png", "000002_10.png"]
        .iter()
        .enumerate()
    {
        write_rgb(&at("image_2", name), k as u8);
        write_rgb(&at("image_3", name), k as u8 + 1);
    }
    // A second frame has no ground truth: not a sample.
    write_rgb(&at("image_2", "000000_11.png"), 9);
    std::fs::create_dir_all(root.join("disp_occ_0")).unwrap();
    std::fs::create_dir_all(root.join("disp_noc_0")).unwrap();
    write_kitti_disparity(&at("disp_occ_0", "000000_10.png"), &truth_a()).unwrap();
    write_kitti_disparity(&at("disp_noc_0", "000000_10.png"), &non_occluded_a()).unwrap();
    write_kitti_disparity(&at("disp_occ_0", "000001_10.png"), &truth_b()).unwrap();
    write_kitti_disparity(&at("disp_occ_0", "000002_10.png"), &truth_b()).unwrap();
    // Predictions: KITTI PNG, PFM, and a wrongly sized one; the batch command copies them.
    std::fs::create_dir(t.join("pred")).unwrap();
    write_kitti_disparity(&t.join("pred/000000_10.png"), &estimate_a()).unwrap();
    write_pfm(&t.join("pred/000001_10.pfm"), &estimate_b()).unwrap();
    write_pfm(
        &t.join("pred/000002_10.pfm"),
        &streaks_image::GrayImage::new(4, 4, 8.0).unwrap(),
    )
    .unwrap();
    // The batch command: for each `left<TAB>right<TAB>out` line, the left image's stem's
    // KITTI PNG prediction becomes `out` (`:png`); a line without one is recorded.
    let batch = format!(
        "copier:png=sh -c 'tab=$(printf \"\\t\"); while IFS=\"$tab\" read -r l r o; do \
         s=$(basename \"$l\" .png); if [ -f \"$0/$s.png\" ]; then cp \"$0/$s.png\" \"$o\"; \
         else printf \"%s\\t%s\\t%s\\n\" \"$l\" \"$r\" \"$o\" >> \"$0/seen.tsv\"; fi; done < \"$1\"' \
         {} {{list}}",
        t.join("pred").display()
    );
    let args = [
        "benchmark",
        "kitti",
        "--predictions",
        "mine=pred",
        "--method-cmd",
        &batch,
        "-o",
        "out",
    ];
    let run = t.streaks(&args);
    run.assert_failure_mentioning("method runs failed");
    let err = run.stderr();
    assert!(
        err.contains("000002_10.pfm is a 4x4 disparity map, the sample is 8x4"),
        "{err}"
    );
    let r = report(&t, "out");
    assert_eq!(r["format"], "streaks-benchmark/3");
    assert_eq!(r["input"]["kind"], "kitti");
    // No masks, no depth, no meta.json: no breakdown, not zeros.
    assert!(r["by_condition"].is_null());
    let b = &r["samples"][0]["results"][0]["breakdown"];
    assert!(b["streak_length"].is_null() && b["road_surface_by_distance"].is_null());
    let ids: Vec<&str> = r["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["id"].as_str().unwrap())
        .collect();
    assert_eq!(ids, ["000000_10", "000001_10", "000002_10"]);
    let s0 = &r["samples"][0];
    assert_eq!(
        (&s0["streak_mask"], &s0["road_mask"], &s0["occlusion_mask"]),
        (&Value::Bool(false), &Value::Bool(false), &Value::Bool(true))
    );
    assert_eq!(r["samples"][1]["occlusion_mask"], false);
    let mine = results(&r, "mine");
    assert_scores_a(&mine[0]["errors"], true);
    assert_scores_b(&mine[1]["errors"]);
    assert!(mine[0]["seconds"].is_null() && mine[0]["seconds_per_megapixel"].is_null());
    assert_eq!(mine[2]["failure"]["kind"], "bad_output");
    // The batch command copied the KITTI PNG only: the other two samples' outputs are missing,
    // and its list held the three samples' absolute paths.
    let copier = results(&r, "copier");
    assert_scores_a(&copier[0]["errors"], true);
    for s in &copier[1..] {
        assert_eq!(s["failure"]["kind"], "no_output", "{s}");
    }
    let seen = std::fs::read_to_string(t.join("pred/seen.tsv")).unwrap();
    let lines: Vec<Vec<&str>> = seen.lines().map(|l| l.split('\t').collect()).collect();
    assert_eq!(lines.len(), 2);
    let root_abs = root.canonicalize().unwrap();
    assert_eq!(
        std::path::Path::new(lines[0][0]).canonicalize().unwrap(),
        root_abs.join("image_2/000001_10.png")
    );
    assert_eq!(
        std::path::Path::new(lines[1][1]).canonicalize().unwrap(),
        root_abs.join("image_3/000002_10.png")
    );
    assert!(
        lines[0][2].ends_with("000001-copier.png"),
        "{}",
        lines[0][2]
    );
    // The batch's time is shared by pixels: the same seconds per megapixel on every sample.
    let spm: Vec<f64> = copier
        .iter()
        .map(|s| s["seconds_per_megapixel"].as_f64().unwrap())
        .collect();
    assert!(
        spm[0] > 0.0 && (spm[0] - spm[2]).abs() < 1e-9 * spm[0],
        "{spm:?}"
    );
    // The summary pools the samples each method succeeded on; predictions are not timed.
    let m = summary(&r, "mine");
    assert_eq!(
        (m["samples"].as_u64(), m["failed"].as_u64()),
        (Some(3), Some(1))
    );
    assert_eq!(m["errors"]["all"]["truth_pixels"], 60);
    assert_eq!(m["errors"]["all"]["valid_pixels"], 59);
    let pooled_epe = m["errors"]["all"]["mean_abs"].as_f64().unwrap();
    assert!((pooled_epe - 19.5 / 59.0).abs() < 1e-12, "{pooled_epe}");
    assert_eq!(m["errors"]["non_occluded"]["truth_pixels"], 24);
    assert!(m["errors"]["streak"].is_null() && m["phantom_hole_rate"].is_null());
    assert!(m["seconds_per_megapixel"].is_null());
    assert!(
        summary(&r, "copier")["seconds_per_megapixel"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    let kinds: Vec<&str> = r["methods"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["batch-command", "predictions"]);
    let page = std::fs::read_to_string(t.join("out/index.html")).unwrap();
    assert!(page.contains("n/a") && page.contains("not timed"));
    assert!(page.contains("region-non_occluded"));
    // Pointing at `training/` itself is the same folder; --allow-failures exits 0.
    let mut again = args.to_vec();
    again[1] = "kitti/training";
    again.push("--allow-failures");
    t.streaks(&again).assert_success();
    assert_eq!(report(&t, "out")["samples"].as_array().unwrap().len(), 3);
}

#[test]
fn middlebury_scenes_are_scored_with_their_occlusion_masks() {
    use streaks_image::kitti::write_kitti_disparity;
    use streaks_image::pfm::write_pfm;
    let t = TestDir::new();
    // A MiddEval3 scene (disp0GT.pfm, mask0nocc.png) and a 2014 scene (disp0.pfm).
    let a = t.join("mb/Adirondack");
    write_rgb(&a.join("im0.png"), 1);
    write_rgb(&a.join("im1.png"), 2);
    write_pfm(&a.join("disp0GT.pfm"), &truth_a()).unwrap();
    // 255 non-occluded, 128 occluded, 0 no truth.
    let nocc = image::GrayImage::from_fn(8, 4, |x, y| {
        image::Luma([match y * 8 + x {
            0..4 => 0,
            4..8 => 128,
            _ => 255,
        }])
    });
    streaks_image::png::write_png_buffer(&a.join("mask0nocc.png"), &nocc).unwrap();
    std::fs::write(a.join("calib.txt"), "not read\n").unwrap();
    let b = t.join("mb/Motorcycle");
    write_rgb(&b.join("im0.png"), 3);
    write_rgb(&b.join("im1.png"), 4);
    write_pfm(&b.join("disp0.pfm"), &truth_b()).unwrap();
    std::fs::create_dir(t.join("mb/notes")).unwrap();
    std::fs::create_dir(t.join("pred")).unwrap();
    write_pfm(&t.join("pred/Adirondack.pfm"), &estimate_a()).unwrap();
    write_kitti_disparity(&t.join("pred/Motorcycle.png"), &estimate_b()).unwrap();
    t.streaks(&["benchmark", "mb", "--predictions", "mine=pred", "-o", "out"])
        .assert_success();
    let r = report(&t, "out");
    assert_eq!(r["input"]["kind"], "middlebury");
    let mine = results(&r, "mine");
    assert_eq!(r["samples"][0]["id"], "Adirondack");
    assert_scores_a(&mine[0]["errors"], true);
    assert_scores_b(&mine[1]["errors"]);
    // One scene folder; predictions named with --method too, beside a built-in.
    t.streaks(&[
        "benchmark",
        "mb/Motorcycle",
        "--method",
        "mine",
        "--predictions",
        "mine=pred",
        "-o",
        "one",
    ])
    .assert_success();
    let one = report(&t, "one");
    assert_eq!(one["input"]["kind"], "middlebury");
    assert_scores_b(&results(&one, "mine")[0]["errors"]);
    // A missing prediction fails its sample, naming the files looked for; the report is
    // written all the same.
    std::fs::remove_file(t.join("pred/Motorcycle.png")).unwrap();
    let run = t.streaks(&["benchmark", "mb", "--predictions", "mine=pred", "-o", "two"]);
    run.assert_failure_mentioning("1 method runs failed");
    assert!(
        run.stderr().contains("Motorcycle.pfm nor"),
        "{}",
        run.stderr()
    );
    let two = report(&t, "two");
    assert_eq!(results(&two, "mine")[1]["failure"]["kind"], "missing");
    let pooled = &summary(&two, "mine")["errors"];
    assert_eq!(pooled["all"]["truth_pixels"], 28);
    assert_eq!(pooled["non_occluded"]["valid_pixels"], 23);
    // Neither layout: a clear error naming both.
    std::fs::create_dir(t.join("junk")).unwrap();
    std::fs::write(t.join("junk/im0.png"), "x").unwrap();
    t.streaks(&[
        "benchmark",
        "junk",
        "--predictions",
        "mine=pred",
        "-o",
        "three",
    ])
    .assert_failure_mentioning("not a KITTI 2015 folder");
    assert!(!t.join("three").exists());
    t.streaks(&[
        "benchmark",
        "mb",
        "--predictions",
        "mine=nowhere",
        "-o",
        "three",
    ])
    .assert_failure_mentioning("nowhere is not a folder");
}
