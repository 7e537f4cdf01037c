//! End-to-end tests of `streaks dataset generate`, `streaks dataset index` and `streaks dataset
//! stats`: determinism
//! (repeated, other thread counts, sharded), resuming and repair, the ground truth's formats,
//! and bad input. Tiny images (64 x 40 at 2 spp) keep them fast in debug builds.

use crate::common::TestDir;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use streaks_image::kitti::read_kitti_disparity;
use streaks_image::pfm::read_pfm;
use streaks_stereo::calib::MiddleburyCalib;

/// The image flags of the test datasets: 64 x 40 at 2 spp.
const SMALL: [&str; 6] = ["--width", "64", "--height", "40", "--spp", "2"];

/// `streaks dataset generate -o DIR --count 3` with the small flags and `extra`.
fn generate(t: &TestDir, dir: &str, extra: &[&str]) -> crate::common::Run {
    generate_n(t, dir, "3", extra)
}

/// `streaks dataset generate -o DIR --count N` with the small flags and `extra`.
fn generate_n(t: &TestDir, dir: &str, count: &str, extra: &[&str]) -> crate::common::Run {
    let mut args = vec!["dataset", "generate", "-o", dir, "--count", count];
    args.extend(SMALL);
    args.extend(extra);
    t.streaks(&args)
}

/// Every file under `root` (relative path -> bytes).
fn tree(root: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                let rel = path
                    .strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(root, root, &mut out);
    out
}

/// Panics naming the first file that differs between two trees.
fn assert_same_tree(a: &Path, b: &Path) {
    let (ta, tb) = (tree(a), tree(b));
    let names = |t: &BTreeMap<String, Vec<u8>>| t.keys().cloned().collect::<Vec<_>>();
    assert_eq!(
        names(&ta),
        names(&tb),
        "{} and {}",
        a.display(),
        b.display()
    );
    for (name, bytes) in &ta {
        assert!(
            bytes == &tb[name],
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn datasets_are_byte_identical_across_runs_threads_and_shards() {
    let t = TestDir::new();
    generate(&t, "a", &["--threads", "1"]).assert_success();
    generate(&t, "b", &["--threads", "1"]).assert_success();
    assert_same_tree(&t.join("a"), &t.join("b"));
    generate(&t, "c", &["--threads", "2"]).assert_success();
    assert_same_tree(&t.join("a"), &t.join("c"));

    // Two shards at the same time into one folder, then the index.
    let shard = |k: &str| {
        let mut args = vec!["dataset", "generate", "-o", "d", "--count", "3"];
        args.extend(["--threads", "1", "--shard", k]);
        args.extend(SMALL);
        Command::new(env!("CARGO_BIN_EXE_streaks"))
            .args(&args)
            .current_dir(t.path())
            .env("CI", "true")
            .output()
            .unwrap()
    };
    let (s0, s1) = std::thread::scope(|s| {
        let h0 = s.spawn(|| shard("0/2"));
        let h1 = s.spawn(|| shard("1/2"));
        (h0.join().unwrap(), h1.join().unwrap())
    });
    for out in [&s0, &s1] {
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        assert!(err.contains("streaks dataset index"), "{err}");
    }
    assert!(!t.join("d/manifest.jsonl").exists());
    t.streaks(&["dataset", "index", "d"]).assert_success();
    assert_same_tree(&t.join("a"), &t.join("d"));

    // The layout of a sample and of the dataset.
    let files = t.files_in("a/samples/000001");
    for f in [
        "calib.txt",
        "depth0.pfm",
        "depth1.pfm",
        "disp0.pfm",
        "disp1.pfm",
        "im0.exr",
        "im0.png",
        "im1.exr",
        "im1.png",
        "meta.json",
        "occ0.png",
        "occ1.png",
        "road0.png",
        "scene.bin",
        "scene.gltf",
        "streaks0.png",
    ] {
        assert!(files.contains(&f.to_owned()), "{f} missing from {files:?}");
    }
    let manifest = std::fs::read_to_string(t.join("a/manifest.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = manifest
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3);
    let mut in_splits = Vec::new();
    for split in ["train", "val", "test"] {
        let text = std::fs::read_to_string(t.join(&format!("a/splits/{split}.txt"))).unwrap();
        in_splits.extend(text.lines().map(|id| (id.to_owned(), split.to_owned())));
    }
    in_splits.sort();
    for (k, line) in lines.iter().enumerate() {
        let id = format!("{k:06}");
        assert_eq!(line["id"], id.as_str());
        assert_eq!(
            in_splits[k],
            (id.clone(), line["split"].as_str().unwrap().to_owned())
        );
        let files = line["files"].as_object().unwrap();
        let sha = files[&format!("samples/{id}/im0.png")].as_str().unwrap();
        assert_eq!(sha.len(), 64);
        assert_eq!(files[&format!("kitti/training/image_2/{id}_10.png")], sha);
        assert!(files.contains_key(&format!("kitti/training/disp_occ_0/{id}_10.png")));
        assert_eq!(
            files[&format!("kitti/training/semantic/{id}_10.png")],
            files[&format!("samples/{id}/semantic0.png")]
        );
        assert!(files.contains_key(&format!("kitti/training/instance/{id}_10.png")));
    }
    let info: serde_json::Value =
        serde_json::from_slice(&std::fs::read(t.join("a/dataset.json")).unwrap()).unwrap();
    assert_eq!(
        (info["count"].as_u64(), info["width"].as_u64()),
        (Some(3), Some(64))
    );
    assert!(info["conventions"]["pfm"]
        .as_str()
        .unwrap()
        .contains("bottom to top"));

    // A rerun skips every sample and changes nothing.
    let run = generate(&t, "a", &[]);
    run.assert_success();
    assert!(
        run.stderr().contains("0 samples rendered, 3 already done"),
        "{}",
        run.stderr()
    );
    assert_same_tree(&t.join("a"), &t.join("b"));
}

#[test]
fn ground_truth_reads_back_as_stereo_loaders_read_it() {
    let t = TestDir::new();
    generate_n(&t, "ds", "1", &[]).assert_success();
    let dir = t.join("ds/samples/000000");
    let disp = read_pfm(&dir.join("disp0.pfm")).unwrap();
    let depth = read_pfm(&dir.join("depth0.pfm")).unwrap();
    assert_eq!((disp.width, disp.height), (64, 40));
    // KITTI's instances: labelId * 256 + k for Cityscapes' labelId * 1000 + k.
    let load16 = |p: &str| image::open(t.join(p)).unwrap().into_luma16();
    let cityscapes = load16("ds/samples/000000/instance0.png");
    let kitti_ids = load16("ds/kitti/training/instance/000000_10.png");
    for (c, k) in cityscapes.pixels().zip(kitti_ids.pixels()) {
        let (c, k) = (c.0[0], k.0[0]);
        let expected = if c < 1000 {
            c * 256
        } else {
            c / 1000 * 256 + c % 1000
        };
        assert_eq!(k, expected);
    }
    // KITTI: uint16 / 256 equals the PFM within 1/256 px; 0 where the PFM has no value.
    let kitti =
        read_kitti_disparity(&t.join("ds/kitti/training/disp_occ_0/000000_10.png")).unwrap();
    let mut finite = 0;
    for (k, d) in kitti.data.iter().zip(&disp.data) {
        if d.is_finite() && *d * 256.0 >= 0.5 {
            assert!((k - d).abs() <= 1.0 / 256.0, "{k} {d}");
            finite += 1;
        } else {
            assert_eq!(*k, f32::INFINITY, "{d}");
        }
    }
    assert!(finite > disp.data.len() / 4, "{finite} finite disparities");
    // calib.txt: d = f b / Z with its f and baseline (mm), and vmin/vmax/ndisp bound it.
    let calib = MiddleburyCalib::load(&dir.join("calib.txt")).unwrap();
    assert_eq!((calib.width, calib.height, calib.doffs), (64, 40, 0.0));
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (d, z) in disp.data.iter().zip(&depth.data) {
        assert_eq!(d.is_finite(), z.is_finite());
        if d.is_finite() {
            let expect = calib.focal_px * calib.baseline_mm / 1000.0 / *z as f64;
            assert!(
                (*d as f64 - expect).abs() <= 1e-4 * expect.max(1.0),
                "{d} {expect}"
            );
            lo = lo.min(*d as f64);
            hi = hi.max(*d as f64);
        }
    }
    // vmin/vmax are the f32 disparities in their shortest decimal form.
    assert_eq!(
        (calib.vmin as f32, calib.vmax as f32),
        (lo as f32, hi as f32)
    );
    assert!(calib.ndisp as f64 > hi && calib.ndisp.is_multiple_of(16));
    // image_2 is im0.png, image_3 is im1.png.
    let bytes = |p: &str| std::fs::read(t.join(p)).unwrap();
    assert_eq!(
        bytes("ds/kitti/training/image_2/000000_10.png"),
        bytes("ds/samples/000000/im0.png")
    );
    assert_eq!(
        bytes("ds/kitti/training/image_3/000000_10.png"),
        bytes("ds/samples/000000/im1.png")
    );
    // The streak mask is 0/255.
    let mask = image::open(dir.join("streaks0.png")).unwrap().into_luma8();
    assert!(mask.pixels().all(|p| p.0[0] == 0 || p.0[0] == 255));
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["index"], 0);
    // The generator flags its road: road0.png marks the road's first hits, 0/255, and only
    // pixels with a finite depth.
    assert_eq!(meta["road_mask"], true);
    let road = image::open(dir.join("road0.png")).unwrap().into_luma8();
    let road_pixels = road.pixels().filter(|p| p.0[0] == 255).count();
    assert!(road.pixels().all(|p| p.0[0] == 0 || p.0[0] == 255));
    assert!(road_pixels > 0 && road_pixels < 64 * 40, "{road_pixels}");
    for (p, z) in road.pixels().zip(&depth.data) {
        assert!(p.0[0] == 0 || z.is_finite());
    }
    let share = meta["stats"]["road_share"].as_f64().unwrap();
    assert_eq!(share, road_pixels as f64 / (64.0 * 40.0));
    assert!(meta["rig"]["baseline_m"].as_f64().unwrap() > 0.0);
    assert!(meta["stats"]["disparity_max"].as_f64().unwrap() > 0.0);
    assert!(meta.get("seconds").is_none());
    // The generator's weather: rain, fog (or null), sensor, exposure time and rig velocity.
    let weather = &meta["weather"];
    assert!(weather["rain_mm_h"].as_f64().unwrap() >= 0.0, "{weather}");
    assert!(weather["fog"].is_null() || weather["fog"]["sigma_t"].as_f64().unwrap() > 0.0);
    assert!(weather["sensor"].is_string() && weather["exposure_s"].as_f64().unwrap() > 0.0);
    assert_eq!(weather["rig_velocity"].as_array().unwrap().len(), 3);
}

/// Each eye's depth, its occlusion mask, and the KITTI and SceneFlow views of a sample hold
/// what their documented rules say, read as the loaders read them: KITTI's uint16 / 256 with 0
/// for no value, its calibration's baseline as `(P_rect_02[0][3] - P_rect_03[0][3]) / f`,
/// SceneFlow's paths as torchvision's and RAFT-Stereo's globs find them.
#[test]
fn per_eye_ground_truth_and_the_kitti_and_sceneflow_views() {
    let t = TestDir::new();
    generate_n(&t, "ds", "1", &[]).assert_success();
    let dir = t.join("ds/samples/000000");
    let calib = MiddleburyCalib::load(&dir.join("calib.txt")).unwrap();
    let fb = calib.focal_px * calib.baseline_mm / 1000.0;
    let (w, h) = (64usize, 40usize);
    let pfm = |name: &str| read_pfm(&dir.join(name)).unwrap();
    let mask = |path: &Path| {
        let m = image::open(path).unwrap().into_luma8();
        assert!(m.pixels().all(|p| p.0[0] == 0 || p.0[0] == 255));
        m.into_raw()
            .iter()
            .map(|&v| v == 255)
            .collect::<Vec<bool>>()
    };
    let disp = [pfm("disp0.pfm"), pfm("disp1.pfm")];
    let depth = [pfm("depth0.pfm"), pfm("depth1.pfm")];
    let occ = [mask(&dir.join("occ0.png")), mask(&dir.join("occ1.png"))];
    for eye in 0..2 {
        // The right eye's depth is its disparity's: d = f b / Z.
        for (d, z) in disp[eye].data.iter().zip(&depth[eye].data) {
            assert_eq!(d.is_finite(), z.is_finite());
            if d.is_finite() {
                let expect = fb / f64::from(*z);
                assert!((f64::from(*d) - expect).abs() <= 1e-4 * expect.max(1.0));
            }
        }
        // Occlusion: the sky never; a point outside the other image always; and the points
        // both eyes see agree with the other eye's disparity there (left-right consistency)
        // but for thin objects' edges.
        let sign = if eye == 0 { -1.0 } else { 1.0 };
        let (mut seen, mut consistent, mut occluded) = (0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let d = f64::from(disp[eye].data[i]);
                if !d.is_finite() {
                    assert!(!occ[eye][i], "eye {eye} pixel ({x}, {y}): sky is occluded");
                    continue;
                }
                let at = x as f64 + 0.5 + sign * d;
                if !(0.0..w as f64).contains(&at) {
                    assert!(occ[eye][i], "eye {eye} pixel ({x}, {y}) is out of view");
                }
                if occ[eye][i] {
                    occluded += 1;
                    continue;
                }
                seen += 1;
                let j = ((at - 0.5).floor().max(0.0) as usize).min(w - 1);
                let other = &disp[1 - eye].data[y * w..y * w + w];
                let near = [j, (j + 1).min(w - 1)]
                    .iter()
                    .any(|&k| (f64::from(other[k]) - d).abs() <= 1.0);
                consistent += usize::from(near);
            }
        }
        assert!(occluded > 0, "eye {eye}: no occluded pixel");
        assert!(
            consistent as f64 >= 0.95 * seen as f64,
            "eye {eye}: {consistent} of {seen} visible pixels consistent"
        );
    }

    // KITTI: disp_occ_1 is disp1, disp_noc_0 is disp0 where occ0 is 0 and no value elsewhere.
    let kitti = |name: &str| {
        read_kitti_disparity(&t.join(&format!("ds/kitti/training/{name}/000000_10.png"))).unwrap()
    };
    let (occ0, occ1, noc0) = (
        kitti("disp_occ_0"),
        kitti("disp_occ_1"),
        kitti("disp_noc_0"),
    );
    for (i, &occluded) in occ[0].iter().enumerate() {
        for (k, d) in [
            (occ0.data[i], disp[0].data[i]),
            (occ1.data[i], disp[1].data[i]),
        ] {
            if d.is_finite() && d * 256.0 >= 0.5 {
                assert!((k - d).abs() <= 1.0 / 256.0, "{k} {d}");
            } else {
                assert_eq!(k, f32::INFINITY);
            }
        }
        if occluded {
            assert_eq!(
                noc0.data[i],
                f32::INFINITY,
                "occluded pixel {i} in disp_noc_0"
            );
        } else {
            assert_eq!(noc0.data[i].to_bits(), occ0.data[i].to_bits(), "pixel {i}");
        }
    }
    let text =
        std::fs::read_to_string(t.join("ds/kitti/training/calib_cam_to_cam/000000.txt")).unwrap();
    let row = |key: &str| -> Vec<f64> {
        let line = text
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key}: ")))
            .unwrap_or_else(|| panic!("no {key} in {text}"));
        line.split(' ').map(|v| v.parse().unwrap()).collect()
    };
    let (p2, p3) = (row("P_rect_02"), row("P_rect_03"));
    let baseline = (p2[3] - p3[3]) / p3[0];
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("meta.json")).unwrap()).unwrap();
    let b = meta["rig"]["baseline_m"].as_f64().unwrap();
    assert!((baseline - b).abs() <= 1e-6 * b, "{baseline} {b}");
    assert!((p2[0] - calib.focal_px).abs() <= 1e-6 * calib.focal_px);
    assert_eq!([p2[2], p2[6]], [calib.cx, calib.cy]);

    // SceneFlow: where torchvision's (SceneFlow/FlyingThings3D/frames_cleanpass/*/*/*/left)
    // and RAFT-Stereo's (FlyingThings3D/frames_cleanpass/TRAIN|TEST/*/*/left) globs look, the
    // disparity path RAFT-Stereo derives from the image's; disparities positive, 0 on the sky.
    let split = meta["split"].as_str().unwrap();
    let set = match split {
        "train" => "TRAIN/A",
        "val" => "TEST/B",
        _ => "TEST/C",
    };
    let street = meta["street"].as_u64().unwrap();
    let root = "ds/SceneFlow/FlyingThings3D";
    for (k, eye) in ["left", "right"].into_iter().enumerate() {
        let image = format!("{root}/frames_cleanpass/{set}/{street:04}/{eye}/0000000.png");
        assert_eq!(
            std::fs::read(t.join(&image)).unwrap(),
            std::fs::read(dir.join(format!("im{k}.png"))).unwrap()
        );
        let disparity = image
            .replace("frames_cleanpass", "disparity")
            .replace(".png", ".pfm");
        let sf = read_pfm(&t.join(&disparity)).unwrap();
        for (s, d) in sf.data.iter().zip(&disp[k].data) {
            let expect = if d.is_finite() { *d } else { 0.0 };
            assert_eq!(s.to_bits(), expect.to_bits());
        }
        let occlusion = image.replace("frames_cleanpass", "disparity_occlusions");
        assert_eq!(mask(&t.join(&occlusion)), occ[k]);
    }
    let manifest = std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap();
    let line: serde_json::Value = serde_json::from_str(manifest.lines().next().unwrap()).unwrap();
    let listed = line["files"].as_object().unwrap();
    assert!(listed.contains_key(&format!(
        "SceneFlow/FlyingThings3D/disparity/{set}/{street:04}/right/0000000.pfm"
    )));
    assert!(listed.contains_key("kitti/training/calib_cam_to_cam/000000.txt"));
    t.streaks(&["dataset", "index", "ds"]).assert_success();
}

/// `--outputs` keeps only the chosen groups: the sample folder holds those files (and
/// `calib.txt`, `meta.json`), the views chosen are made all the same, the manifest lists
/// exactly the files written and `dataset index` verifies them; a rerun with other groups is
/// refused with a hint, and an unknown group names the groups there are.
#[test]
fn outputs_keep_only_the_chosen_groups() {
    let t = TestDir::new();
    let run = generate_n(&t, "ds", "1", &["--outputs", "gt,kitti"]);
    run.assert_success();
    assert!(
        run.stderr().contains(" bytes per sample"),
        "{}",
        run.stderr()
    );
    assert_eq!(
        t.files_in("ds/samples/000000"),
        [
            "calib.txt",
            "depth0.pfm",
            "depth1.pfm",
            "disp0.pfm",
            "disp1.pfm",
            "meta.json",
            "occ0.png",
            "occ1.png"
        ]
    );
    assert!(!t.join("ds/SceneFlow").exists());
    assert!(t.join("ds/kitti/training/image_2/000000_10.png").is_file());
    assert!(t.join("ds/kitti/training/semantic/000000_10.png").is_file());
    let manifest = std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap();
    let line: serde_json::Value = serde_json::from_str(manifest.lines().next().unwrap()).unwrap();
    let mut listed: Vec<String> = line["files"].as_object().unwrap().keys().cloned().collect();
    let mut on_disk: Vec<String> = tree(&t.join("ds"))
        .into_keys()
        .filter(|f| f.starts_with("samples/") || f.starts_with("kitti/"))
        .collect();
    listed.sort();
    on_disk.sort();
    assert_eq!(listed, on_disk);
    assert_eq!(listed.len(), 8 + 8);
    let info: serde_json::Value =
        serde_json::from_slice(&std::fs::read(t.join("ds/dataset.json")).unwrap()).unwrap();
    assert_eq!(info["outputs"], serde_json::json!(["gt", "kitti"]));
    // dataset.json lists the files kept.
    let list = &info["files"];
    assert_eq!(
        list["sample"],
        serde_json::json!(t.files_in("ds/samples/000000"))
    );
    assert_eq!(list["scene"], serde_json::json!([]));
    assert!(list.get("sceneflow").is_none());
    assert_eq!(list["kitti"].as_array().unwrap().len(), 8);
    assert!(list["optional"].as_object().unwrap().is_empty(), "{list}");
    let verified = t.streaks(&["dataset", "index", "ds"]);
    verified.assert_success();
    assert!(
        verified.stderr().contains("16 files match manifest.jsonl"),
        "{}",
        verified.stderr()
    );
    // A rerun skips the sample; one with other groups is refused.
    let again = generate_n(&t, "ds", "1", &["--outputs", "kitti,gt"]);
    again.assert_success();
    assert!(again
        .stderr()
        .contains("0 samples rendered, 1 already done"));
    generate_n(&t, "ds", "1", &[])
        .assert_failure_mentioning("outputs")
        .assert_failure_mentioning("give --outputs");
    let bad = generate_n(&t, "bad", "1", &["--outputs", "gt,png"]);
    assert!(!bad.output.status.success());
    assert!(
        bad.stderr().contains("unknown output group \"png\"")
            && bad.stderr().contains("images, images16, exr, gt"),
        "{}",
        bad.stderr()
    );
    assert!(!t.join("bad").exists());
}

#[test]
fn images16_keeps_the_images_at_16_bits() {
    let t = TestDir::new();
    generate_n(&t, "ds", "1", &["--outputs", "images,images16,gt"]).assert_success();
    let dir = t.join("ds/samples/000000");
    assert!(t
        .files_in("ds/samples/000000")
        .contains(&"im1_16.png".to_string()));
    for eye in ["0", "1"] {
        let wide = image::open(dir.join(format!("im{eye}_16.png"))).unwrap();
        let narrow = image::open(dir.join(format!("im{eye}.png"))).unwrap();
        let (wide, narrow) = (wide.as_rgb16().unwrap(), narrow.as_rgb8().unwrap());
        assert_eq!(wide.dimensions(), narrow.dimensions());
        // The same curve: the 8-bit value is the 16-bit one over 257, to within rounding.
        for (&w, &n) in wide.as_raw().iter().zip(narrow.as_raw()) {
            assert!(
                (f64::from(w) / 257.0 - f64::from(n)).abs() <= 0.5,
                "{w} {n}"
            );
        }
        assert!(
            wide.as_raw().iter().any(|&w| w % 257 != 0),
            "16 bits carry more"
        );
    }
    let verified = t.streaks(&["dataset", "index", "ds"]);
    verified.assert_success();
    // Without the group, no 16-bit images.
    generate_n(&t, "plain", "1", &["--outputs", "images"]).assert_success();
    assert!(!t.join("plain/samples/000000/im0_16.png").exists());
}

#[test]
fn interrupted_and_damaged_datasets_are_reported_then_repaired() {
    let t = TestDir::new();
    generate(&t, "ds", &[]).assert_success();
    let good = tree(&t.join("ds"));
    // A sample with a file removed, a stale temporary folder, a missing sample and a missing
    // KITTI file.
    std::fs::remove_file(t.join("ds/samples/000001/disp0.pfm")).unwrap();
    std::fs::create_dir(t.join("ds/samples/.tmp-000000-4242")).unwrap();
    std::fs::write(t.join("ds/samples/.tmp-000000-4242/im0.png"), b"half").unwrap();
    std::fs::remove_dir_all(t.join("ds/samples/000002")).unwrap();
    std::fs::remove_file(t.join("ds/kitti/training/image_3/000000_10.png")).unwrap();
    std::fs::write(t.join("ds/splits/val.txt"), "000001\n000002\n000007\n").unwrap();

    // Verifying (the default with a manifest) reports each difference and writes nothing.
    let run = t.streaks(&["dataset", "index", "ds"]);
    run.assert_failure_mentioning("differs from its manifest.jsonl");
    let err = run.stderr();
    for needle in [
        "sample 000001 (manifest line 2): samples/000001/disp0.pfm: missing",
        "sample 000002 (manifest line 3): the sample's folder is missing",
        "sample 000000 (manifest line 1): kitti/training/image_3/000000_10.png: missing",
        "samples/.tmp-000000-4242: temporary folder",
        "splits/val.txt: not the ",
        "the manifest is unchanged",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert_eq!(
        std::fs::read(t.join("ds/manifest.jsonl")).unwrap(),
        good["manifest.jsonl"]
    );
    assert!(!t.join("ds/kitti/training/image_3/000000_10.png").exists());

    // Rebuilding checks what is on disk and writes the manifest of the good samples.
    let run = t.streaks(&["dataset", "index", "--rebuild", "ds"]);
    run.assert_failure_mentioning("incomplete");
    let err = run.stderr();
    assert!(err.contains("000001: missing files: disp0.pfm"), "{err}");
    assert!(
        err.contains("samples/.tmp-000000-4242: temporary folder"),
        "{err}"
    );
    assert!(err.contains("missing samples (1): 000002"), "{err}");
    // The good sample's KITTI file is written again; the manifest lists the good sample only.
    assert_eq!(
        std::fs::read(t.join("ds/kitti/training/image_3/000000_10.png")).unwrap(),
        good["kitti/training/image_3/000000_10.png"]
    );
    let manifest = std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap();
    assert_eq!(manifest.lines().count(), 1);
    // A rerun renders what is missing, removes the stale folder, and the dataset is whole.
    let run = generate(&t, "ds", &[]);
    run.assert_success();
    let err = run.stderr();
    assert!(
        err.contains("2 samples rendered (1 of them repaired), 1 already done"),
        "{err}"
    );
    assert!(
        err.contains("sample 000001: missing files: disp0.pfm; removing it and rendering it again"),
        "{err}"
    );
    assert!(
        err.contains("sample 000000: removed samples/.tmp-000000-4242, the temporary folder"),
        "{err}"
    );
    assert_eq!(tree(&t.join("ds")), good);
    t.streaks(&["dataset", "index", "ds"]).assert_success();
}

/// A file whose bytes changed (same size, so only its hash tells) is reported by `index` with
/// both hashes, and `generate` renders its sample again, byte for byte as the manifest says.
#[test]
fn changed_files_are_found_by_their_hash_and_restored_byte_for_byte() {
    let t = TestDir::new();
    generate(&t, "ds", &[]).assert_success();
    let good = tree(&t.join("ds"));
    let flip = |rel: &str| {
        let path = t.join(rel);
        let mut bytes = std::fs::read(&path).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 0x5a;
        std::fs::write(&path, bytes).unwrap();
    };
    flip("ds/samples/000001/im0.exr");
    flip("ds/kitti/training/disp_occ_0/000002_10.png");
    std::fs::write(t.join("ds/samples/000000/notes.txt"), "mine").unwrap();
    // A file replaced by a symbolic link out of the folder, another by a FIFO: reported, never
    // followed nor opened (a FIFO would block the reader forever).
    let secret = t.join("secret.txt");
    std::fs::write(&secret, "outside").unwrap();
    let mut places = 3;
    #[cfg(unix)]
    {
        std::fs::remove_file(t.join("ds/samples/000002/calib.txt")).unwrap();
        std::os::unix::fs::symlink(&secret, t.join("ds/samples/000002/calib.txt")).unwrap();
        std::fs::remove_file(t.join("ds/samples/000000/meta.json")).unwrap();
        let made = Command::new("mkfifo")
            .arg(t.join("ds/samples/000000/meta.json"))
            .status()
            .unwrap();
        assert!(made.success());
        places += 2;
    }
    let hex = |bytes: &[u8]| format!("{:x}", <sha2::Sha256 as sha2::Digest>::digest(bytes));
    let bad = hex(&std::fs::read(t.join("ds/samples/000001/im0.exr")).unwrap());
    let expected = hex(&good["samples/000001/im0.exr"]);

    let run = t.streaks(&["dataset", "index", "ds"]);
    run.assert_failure_mentioning(&format!(
        "differs from its manifest.jsonl in {places} places"
    ));
    let err = run.stderr();
    #[cfg(unix)]
    {
        assert!(
            err.contains("samples/000002/calib.txt: samples/000002/calib.txt is a symbolic link"),
            "{err}"
        );
        assert!(
            err.contains("samples/000000/meta.json: not a regular file"),
            "{err}"
        );
    }
    assert!(
        err.contains(&format!(
            "sample 000001 (manifest line 2): samples/000001/im0.exr: sha256 {bad}, the manifest \
             lists {expected}"
        )),
        "{err}"
    );
    assert!(
        err.contains(
            "sample 000002 (manifest line 3): kitti/training/disp_occ_0/000002_10.png: sha256"
        ),
        "{err}"
    );
    assert!(
        err.contains(
            "sample 000000 (manifest line 1): samples/000000/notes.txt: not in the manifest"
        ),
        "{err}"
    );
    assert_eq!(
        std::fs::read(t.join("ds/manifest.jsonl")).unwrap(),
        good["manifest.jsonl"]
    );

    let run = generate(&t, "ds", &["--threads", "1"]);
    run.assert_success();
    let err = run.stderr();
    assert!(
        err.contains("3 samples rendered (3 of them repaired), 0 already done"),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "sample 000001: samples/000001/im0.exr: sha256 {bad}, the manifest lists {expected}; \
             removing it and rendering it again"
        )),
        "{err}"
    );
    assert!(
        err.contains("sample 000001: repaired; its files are again those manifest.jsonl lists"),
        "{err}"
    );
    assert_eq!(tree(&t.join("ds")), good);
    assert_eq!(std::fs::read_to_string(&secret).unwrap(), "outside");
    let run = t.streaks(&["dataset", "index", "ds"]);
    run.assert_success();
    assert!(
        run.stderr().contains("verified ds: 3 samples, ")
            && run.stderr().contains(" files match manifest.jsonl"),
        "{}",
        run.stderr()
    );
}

/// A hostile manifest (paths out of the folder, bad JSON, duplicates, a huge line) is refused
/// with its line, and nothing outside the folder is read; `generate` warns, checks the samples
/// without it and writes it again; `--rebuild` replaces it.
#[test]
fn hostile_manifests_are_refused_with_their_line_number() {
    let t = TestDir::new();
    generate_n(&t, "ds", "2", &[]).assert_success();
    let good = std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let secret = t.join("secret.txt");
    std::fs::write(&secret, "outside").unwrap();
    let escape = lines[1].replacen(
        "\"samples/000001/calib.txt\"",
        "\"samples/000001/../../../secret.txt\"",
        1,
    );
    let absolute = lines[1].replacen(
        "\"samples/000001/calib.txt\"",
        &format!("{:?}", secret.display().to_string()),
        1,
    );
    let cases = [
        (
            format!("{}\n{escape}\n", lines[0]),
            "line 2: \"samples/000001/../../../secret.txt\" is not a file of sample 000001",
        ),
        (format!("{}\n{absolute}\n", lines[0]), "line 2: "),
        (
            format!("{}\n{{\"id\": \n", lines[0]),
            "line 2: not a manifest line",
        ),
        (
            format!("{}\n{}\n", lines[0], lines[0]),
            "line 2: sample 000000 is listed again (first on line 1)",
        ),
        (
            format!("{}\n{}\n", "x".repeat(2 << 20), lines[1]),
            "line 1: longer than 1048576 bytes",
        ),
        (
            format!("{}\n{}\n{}\n", lines[0], lines[1], lines[1]),
            "line 3: more lines than the dataset's 2",
        ),
    ];
    for (text, needle) in &cases {
        std::fs::write(t.join("ds/manifest.jsonl"), text).unwrap();
        t.streaks(&["dataset", "index", "ds"])
            .assert_failure_mentioning(needle);
        assert_eq!(
            &std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap(),
            text
        );
    }
    assert_eq!(std::fs::read_to_string(&secret).unwrap(), "outside");
    // A manifest that is a FIFO or a symbolic link is not opened.
    std::fs::remove_file(t.join("ds/manifest.jsonl")).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&secret, t.join("ds/manifest.jsonl")).unwrap();
        t.streaks(&["dataset", "index", "ds"])
            .assert_failure_mentioning("is not a regular file");
        std::fs::remove_file(t.join("ds/manifest.jsonl")).unwrap();
    }
    // generate: a warning, the samples checked by decoding, the manifest written again.
    std::fs::write(t.join("ds/manifest.jsonl"), &cases[0].0).unwrap();
    let run = generate_n(&t, "ds", "2", &[]);
    run.assert_success();
    assert!(
        run.stderr().contains("warning: ") && run.stderr().contains("checked without it"),
        "{}",
        run.stderr()
    );
    assert_eq!(
        std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap(),
        good
    );
    std::fs::write(t.join("ds/manifest.jsonl"), "{bad").unwrap();
    t.streaks(&["dataset", "index", "--rebuild", "ds"])
        .assert_success();
    assert_eq!(
        std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap(),
        good
    );

    // A dataset.json whose count no one could loop over is refused before any loop.
    let json = std::fs::read_to_string(t.join("ds/dataset.json")).unwrap();
    let huge = json.replacen("\"count\": 2,", "\"count\": 1000000000000000000,", 1);
    assert_ne!(huge, json);
    std::fs::write(t.join("ds/dataset.json"), huge).unwrap();
    for rebuild in [false, true] {
        let mut args = vec!["dataset", "index", "ds"];
        if rebuild {
            args.push("--rebuild");
        }
        t.streaks(&args)
            .assert_failure_mentioning("count 1000000000000000000 is not in 1..=1000000");
    }
}

/// Rebuilding (and `generate` without a manifest) never reads a sample's file through a
/// symbolic link or from a FIFO, nor a file its scene names outside its folder: they are
/// reported as damage, and `generate` renders the sample again.
#[cfg(unix)]
#[test]
fn rebuild_reports_special_files_without_opening_them() {
    let t = TestDir::new();
    generate(&t, "ds", &[]).assert_success();
    let good = tree(&t.join("ds"));
    std::fs::remove_file(t.join("ds/manifest.jsonl")).unwrap();
    std::fs::write(t.join("secret.txt"), "outside").unwrap();
    std::fs::remove_file(t.join("ds/samples/000000/meta.json")).unwrap();
    let made = Command::new("mkfifo")
        .arg(t.join("ds/samples/000000/meta.json"))
        .status()
        .unwrap();
    assert!(made.success());
    std::fs::remove_file(t.join("ds/samples/000001/calib.txt")).unwrap();
    std::os::unix::fs::symlink(t.join("secret.txt"), t.join("ds/samples/000001/calib.txt"))
        .unwrap();
    let gltf = t.join("ds/samples/000002/scene.gltf");
    let text = std::fs::read_to_string(&gltf).unwrap();
    std::fs::write(
        &gltf,
        text.replacen("\"scene.bin\"", "\"../../../secret.txt\"", 1),
    )
    .unwrap();
    let run = t.streaks(&["dataset", "index", "ds"]);
    run.assert_failure_mentioning("incomplete");
    let err = run.stderr();
    for needle in [
        "corrupt: 000000: samples/000000/meta.json is a special file",
        "corrupt: 000001: samples/000001/calib.txt is a symbolic link",
        "corrupt: 000002: scene.gltf refers to \"../../../secret.txt\"",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    std::fs::remove_file(t.join("ds/manifest.jsonl")).unwrap();
    let run = generate(&t, "ds", &[]);
    run.assert_success();
    assert!(
        run.stderr()
            .contains("3 samples rendered (3 of them repaired)"),
        "{}",
        run.stderr()
    );
    assert_eq!(tree(&t.join("ds")), good);
    assert_eq!(
        std::fs::read_to_string(t.join("secret.txt")).unwrap(),
        "outside"
    );
}

/// Runs `streaks ARGS` in `dir` without waiting (CI=true, output captured).
fn spawn(dir: &Path, args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_streaks"))
        .args(args)
        .current_dir(dir)
        .env("CI", "true")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Two identical runs of the whole dataset started at once: each finishes correctly, or the
/// second is refused at once naming the folder and the holder's PID; a run while another
/// holds the dataset lock is refused; shards started twice each render every sample once.
#[test]
fn concurrent_runs_on_one_folder_are_safe_or_refused() {
    let t = TestDir::new();
    generate(&t, "ref", &[]).assert_success();
    let mut args = vec![
        "dataset",
        "generate",
        "-o",
        "ds",
        "--count",
        "3",
        "--threads",
        "1",
    ];
    args.extend(SMALL);
    let children = [spawn(t.path(), &args), spawn(t.path(), &args)];
    let outs: Vec<_> = children
        .into_iter()
        .map(|c| c.wait_with_output().unwrap())
        .collect();
    let mut finished = 0;
    for out in &outs {
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{err}");
        if out.status.success() {
            finished += 1;
        } else {
            assert!(
                err.contains("the dataset folder ds is in use by another run: PID ")
                    && err.contains("(streaks dataset generate) holds ds/.lock"),
                "{err}"
            );
        }
    }
    assert!(finished >= 1);
    assert_same_tree(&t.join("ref"), &t.join("ds"));

    // While this test holds the dataset lock, a run is refused at once, naming the holder.
    let lock = std::fs::File::create(t.join("ds/.lock")).unwrap();
    lock.lock().unwrap();
    std::fs::write(t.join("ds/.lock"), "PID 4242 (a test)\n").unwrap();
    let started = std::time::Instant::now();
    generate(&t, "ds", &[])
        .assert_failure_mentioning("ds is in use by another run: PID 4242 (a test) holds");
    t.streaks(&["dataset", "index", "--rebuild", "ds"])
        .assert_failure_mentioning("PID 4242 (a test)");
    assert!(started.elapsed().as_secs() < 20);
    drop(lock);
    std::fs::remove_file(t.join("ds/.lock")).unwrap();

    // The same shards twice at once (as a retried Ray task may be): both succeed, each sample
    // is rendered once, and nothing is left behind.
    let shard = |k: &str| {
        let mut a = vec![
            "dataset",
            "generate",
            "-o",
            "sh",
            "--count",
            "3",
            "--threads",
            "1",
        ];
        a.extend(["--shard", k]);
        a.extend(SMALL);
        spawn(t.path(), &a)
    };
    let children = [shard("0/2"), shard("0/2"), shard("1/2"), shard("1/2")];
    let mut rendered = 0;
    for c in children {
        let out = c.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        rendered += err.matches(", streak share ").count();
    }
    assert_eq!(rendered, 3, "each sample rendered by exactly one run");
    t.streaks(&["dataset", "index", "sh"]).assert_success();
    assert_same_tree(&t.join("ref"), &t.join("sh"));
}

/// A killed run leaves a temporary folder and its lock file behind (no process holds the
/// lock): the next run removes both and says so; a sample someone renders (its lock held)
/// is waited for.
#[test]
fn a_killed_runs_leftovers_are_cleaned() {
    let t = TestDir::new();
    generate(&t, "ds", &[]).assert_success();
    let good = tree(&t.join("ds"));
    std::fs::create_dir(t.join("ds/samples/.tmp-000001-999999")).unwrap();
    std::fs::write(t.join("ds/samples/.tmp-000001-999999/im0.png"), b"half").unwrap();
    std::fs::write(
        t.join("ds/samples/.lock-000001"),
        "PID 999999 (streaks dataset generate)\n",
    )
    .unwrap();
    std::fs::write(
        t.join("ds/.lock"),
        "PID 999999 (streaks dataset generate)\n",
    )
    .unwrap();
    t.streaks(&["dataset", "index", "ds"])
        .assert_failure_mentioning("differs");
    let run = generate(&t, "ds", &[]);
    run.assert_success();
    let err = run.stderr();
    assert!(
        err.contains("sample 000001: removed samples/.tmp-000001-999999, the temporary folder of an interrupted run"),
        "{err}"
    );
    assert!(err.contains("0 samples rendered, 3 already done"), "{err}");
    assert_eq!(tree(&t.join("ds")), good);

    // A run that holds sample 000002's lock: a shard run waits for it, then finds the sample
    // good and skips it.
    std::fs::remove_dir_all(t.join("ds/samples/000002")).unwrap();
    let lock = std::fs::File::create(t.join("ds/samples/.lock-000002")).unwrap();
    lock.lock().unwrap();
    std::fs::write(t.join("ds/samples/.lock-000002"), "PID 4242 (a test)\n").unwrap();
    let mut args = vec![
        "dataset", "generate", "-o", "ds", "--count", "3", "--shard", "0/1",
    ];
    args.extend(SMALL);
    let mut child = spawn(t.path(), &args);
    // Its stderr up to the line that says it waits.
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut err = String::new();
    loop {
        let mut line = String::new();
        let n = std::io::BufRead::read_line(&mut stderr, &mut line).unwrap();
        assert!(n > 0, "the run ended without waiting: {err}");
        err += &line;
        if line.contains("is on it; waiting") {
            break;
        }
    }
    assert!(
        err.contains("sample 000002: PID 4242 (a test) is on it; waiting"),
        "{err}"
    );
    // "Render" it as the holder would, then let go.
    std::fs::create_dir(t.join("ds/samples/000002")).unwrap();
    for (name, bytes) in &good {
        if let Some(file) = name.strip_prefix("samples/000002/") {
            std::fs::write(t.join("ds/samples/000002").join(file), bytes).unwrap();
        }
    }
    std::fs::remove_file(t.join("ds/samples/.lock-000002")).unwrap();
    drop(lock);
    std::io::Read::read_to_string(&mut stderr, &mut err).unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{err}");
    assert!(err.contains("0 samples rendered, 3 already done"), "{err}");
    assert_eq!(tree(&t.join("ds")), good);
}

#[test]
fn bad_dataset_arguments_are_refused() {
    let t = TestDir::new();
    generate(&t, "x", &["--shard", "2/2"]).assert_failure_mentioning("less than N = 2");
    generate(&t, "x", &["--shard", "1"]).assert_failure_mentioning("K/N");
    generate(&t, "x", &["--config", "none.toml"]).assert_failure_mentioning("none.toml");
    std::fs::write(t.join("bad.toml"), "[street\nlanes = ").unwrap();
    generate(&t, "x", &["--config", "bad.toml"]).assert_failure_mentioning("bad.toml");
    std::fs::write(t.join("unknown.toml"), "[street]\nlanez = [1, 2]\n").unwrap();
    generate(&t, "x", &["--config", "unknown.toml"]).assert_failure_mentioning("lanez");
    std::fs::write(t.join("range.toml"), "[rig]\nbaseline = [0.4, 0.1]\n").unwrap();
    generate(&t, "x", &["--config", "range.toml"]).assert_failure_mentioning("rig.baseline");
    std::fs::write(t.join("fog.toml"), "[weather.fog]\ng = [0.5, 1.5]\n").unwrap();
    generate(&t, "x", &["--config", "fog.toml"]).assert_failure_mentioning("weather.fog.g");
    generate_n(&t, "x", "0", &[]).assert_failure_mentioning("--count");
    // Nothing was written by the refused runs.
    assert!(!t.join("x").exists());
    // A folder with other files is not a dataset.
    std::fs::create_dir(t.join("other")).unwrap();
    std::fs::write(t.join("other/notes.txt"), "mine").unwrap();
    generate(&t, "other", &[]).assert_failure_mentioning("not a dataset");
    // A folder with another dataset: the differing setting is named.
    generate_n(&t, "ds", "1", &[]).assert_success();
    generate_n(&t, "ds", "1", &["--seed", "7"])
        .assert_failure_mentioning("its seed is 0, this run's is 7");
    let mut args = vec!["dataset", "generate", "-o", "ds", "--count", "1"];
    args.extend(["--width", "64", "--height", "40", "--spp", "4"]);
    t.streaks(&args)
        .assert_failure_mentioning("its spp is 2, this run's is 4");
    generate(&t, "ds", &[]).assert_failure_mentioning("count");
    t.streaks(&["dataset", "index", "nowhere"])
        .assert_failure_mentioning("nowhere");
}

/// Adaptive sampling in datasets (`--noise-target`): byte-identical across thread counts,
/// recorded in `dataset.json` and `meta.json` with the samples each eye took, on by default,
/// `off` recorded as null, and a dataset is continued only with its own target.
#[test]
fn adaptive_datasets_record_their_target_and_are_deterministic() {
    let t = TestDir::new();
    // A straight, flat street, so that the sky shows in the top tiles, without weather: in
    // fog the lanterns and the rig's headlights light the air in front of the sky, which
    // then takes every sample.
    let flat = t.write_flat_street_config();
    let mut config = std::fs::read_to_string(&flat).unwrap();
    config.push_str("[weather]\nenabled = false\n");
    std::fs::write(&flat, config).unwrap();
    let adaptive = |dir: &str, threads: &str| {
        t.streaks(&[
            "dataset",
            "generate",
            "--config",
            &flat,
            "-o",
            dir,
            "--count",
            "1",
            "--width",
            "64",
            "--height",
            "40",
            "--spp",
            "32",
            "--noise-target",
            "0.3",
            "--threads",
            threads,
        ])
    };
    adaptive("a", "1").assert_success();
    adaptive("b", "2").assert_success();
    assert_same_tree(&t.join("a"), &t.join("b"));
    let json = |path: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(t.join(path)).unwrap()).unwrap()
    };
    assert_eq!(
        json("a/dataset.json")["noise_target"],
        serde_json::json!(0.3)
    );
    let render = &json("a/samples/000000/meta.json")["render"];
    assert_eq!(render["noise_target"], serde_json::json!(0.3));
    let mean_spp: Vec<f64> = render["mean_spp"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(mean_spp.len(), 2);
    assert!(
        mean_spp.iter().all(|&n| (16.0..32.0).contains(&n)),
        "{mean_spp:?}: the black sky stops at 16"
    );

    // The default target is recorded; `off` is null and takes --spp everywhere.
    generate_n(&t, "c", "1", &[]).assert_success();
    assert_eq!(
        json("c/dataset.json")["noise_target"],
        serde_json::json!(0.1)
    );
    generate_n(&t, "d", "1", &["--noise-target", "off"]).assert_success();
    assert!(json("d/dataset.json")["noise_target"].is_null());
    let render = &json("d/samples/000000/meta.json")["render"];
    assert!(render["noise_target"].is_null());
    assert_eq!(render["mean_spp"], serde_json::json!([2.0, 2.0]));
    // With a cap of 2 (below the minimum of 16) the target changes no pixel.
    assert_eq!(
        std::fs::read(t.join("c/samples/000000/im0.exr")).unwrap(),
        std::fs::read(t.join("d/samples/000000/im0.exr")).unwrap()
    );

    // Another target does not continue a dataset; bad targets are refused.
    generate_n(&t, "d", "1", &[])
        .assert_failure_mentioning("its noise_target is null, this run's is 0.1");
    generate_n(&t, "c", "1", &["--noise-target", "0.2"])
        .assert_failure_mentioning("give its --noise-target");
    generate_n(&t, "x", "1", &["--noise-target", "0"]).assert_failure_mentioning("positive");
    generate_n(&t, "x", "1", &["--noise-target", "low"]).assert_failure_mentioning("off");
    assert!(!t.join("x").exists());
}

/// A sample in heavy rain and fog has its per-eye rain masks and fog transmittance, the
/// sensor's raw layer, a weather record, and passes `index`; `dataset preview` draws it as
/// four panels (image, disparity, rain mask, flow to the next frame), a missing sample is an
/// error naming the file.
#[test]
fn weather_samples_have_rain_and_fog_masks_and_a_preview() {
    let t = TestDir::new();
    std::fs::write(
        t.join("wet.toml"),
        "[weather]\nrain = [{ name = \"heavy\", probability = 1.0, mm_h = [40.0, 40.0] }]\n\
         sensor = { automotive_linear = 1.0 }\n\
         [weather.fog]\nprobability = 1.0\nsigma_t = [0.02, 0.02]\n",
    )
    .unwrap();
    generate_n(&t, "ds", "1", &["--config", "wet.toml"]).assert_success();
    let sample = t.join("ds/samples/000000");
    for f in ["rain0.png", "rain1.png", "fog0.pfm", "fog1.pfm"] {
        assert!(sample.join(f).is_file(), "{f}");
    }
    let fog = read_pfm(&sample.join("fog0.pfm")).unwrap();
    assert!(fog.data.iter().all(|&v| (0.0..=1.0).contains(&v)));
    assert!(fog.data.iter().any(|&v| v < 1.0));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(sample.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["weather"]["rain_mm_h"], 40.0);
    assert_eq!(meta["weather"]["sensor"], "automotive_linear");
    assert!(streaks_render::output::read_exr_layer(&sample.join("im0.exr"), "sensor").is_ok());
    t.streaks(&["dataset", "index", "ds"]).assert_success();
    // A missing rain mask is found.
    std::fs::remove_file(sample.join("rain1.png")).unwrap();
    t.streaks(&["dataset", "index", "ds", "--rebuild"])
        .assert_failure_mentioning("rain1.png");

    t.streaks(&[
        "dataset",
        "preview",
        "ds/samples/000000",
        "-o",
        "p/preview.png",
    ])
    .assert_success();
    let preview = image::open(t.join("p/preview.png")).unwrap();
    assert_eq!((preview.width(), preview.height()), (4 * 64, 40));
    t.streaks(&["dataset", "preview", "ds/samples/000009", "-o", "q.png"])
        .assert_failure_mentioning("im0.png");
    assert!(!t.join("q.png").exists());
}

/// `dataset stats` writes its page, thumbnails and contact sheet; the page shows the drawn
/// parameters with their config ranges; hostile strings in a `meta.json` reach the page
/// escaped; a broken sample and a missing one are named, skipped and listed.
#[test]
fn stats_page_shows_the_parameters_and_escapes_what_it_reads() {
    let t = TestDir::new();
    generate(&t, "ds", &[]).assert_success();
    t.streaks(&["dataset", "stats", "ds"]).assert_success();
    let page = std::fs::read_to_string(t.join("ds/stats.html")).unwrap();
    // The bytes per sample are those of the files the manifest lists.
    let manifest = std::fs::read_to_string(t.join("ds/manifest.jsonl")).unwrap();
    let mut bytes = 0u64;
    for line in manifest.lines() {
        let line: serde_json::Value = serde_json::from_str(line).unwrap();
        for file in line["files"].as_object().unwrap().keys() {
            bytes += std::fs::metadata(t.join(&format!("ds/{file}")))
                .unwrap()
                .len();
        }
    }
    let per_sample = format!("{:.0} bytes per sample", bytes as f64 / 3.0);
    assert!(page.contains(&per_sample), "{per_sample}");
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(t.join("ds/dataset.json")).unwrap()).unwrap();
    let height = config["config"]["lamps"]["height"].to_string();
    assert!(page.contains("[lamps]") && page.contains(">lamps.height</text>"));
    assert!(
        page.contains(&format!("config: <code>{height}</code>")),
        "{height}"
    );
    assert_eq!(
        t.files_in("ds/stats/thumbs"),
        ["000000.png", "000001.png", "000002.png"]
    );
    for id in ["000000", "000001", "000002"] {
        assert!(page.contains(&format!("href=\"samples/{id}/\"")), "{id}");
    }
    // Three tiles of 480 x 300 (64 x 40 enlarged), captions of 26 px, gaps of 4 px.
    let sheet = image::open(t.join("ds/stats/contact_sheet.png")).unwrap();
    assert_eq!(
        (sheet.width(), sheet.height()),
        (3 * 480 + 4 * 4, 300 + 26 + 2 * 4)
    );

    // Hostile strings, a broken sample and a missing one.
    let meta_path = t.join("ds/samples/000001/meta.json");
    let mut meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&meta_path).unwrap()).unwrap();
    meta["params"]["lamps"]["type"] = "<script>alert(1)</script>".into();
    meta["split"] = "\"><img src=x onerror=alert(2)>".into();
    std::fs::write(&meta_path, serde_json::to_vec(&meta).unwrap()).unwrap();
    std::fs::write(t.join("ds/samples/000002/meta.json"), "{broken").unwrap();
    std::fs::remove_dir_all(t.join("ds/samples/000000")).unwrap();
    let run = t.streaks(&["dataset", "stats", "ds", "-o", "out/page.html"]);
    run.assert_success();
    assert!(
        run.stderr().contains("sample 000002 skipped"),
        "{}",
        run.stderr()
    );
    let page = std::fs::read_to_string(t.join("out/page.html")).unwrap();
    assert!(!page.contains("<script>") && !page.contains("<img src=x"));
    assert!(page.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(page.contains("&quot;&gt;&lt;img src=x onerror=alert(2)&gt;"));
    assert!(page.contains("Missing or skipped (2)"));
    assert!(page.contains("<td>000000</td><td class=\"reason\">missing: no sample folder</td>"));
    assert!(page.contains("<td>000002</td><td class=\"reason\">"));
    // The page is outside the dataset: its links are file URLs.
    assert!(page.contains("href=\"file:///"));
}

/// `--denoise`: `on` denoises both eyes (recorded in `dataset.json` and `meta.json`, the EXR
/// without its raw render unless `--keep-raw`), the disparity and masks are those of `off`,
/// a dataset is continued only with its own choice, and `--keep-raw` without denoising is
/// refused. Needs the library (see the render test); skipped without it.
#[test]
fn denoised_datasets_record_it_and_keep_their_ground_truth() {
    if !crate::common::denoiser_available() {
        return;
    }
    let t = TestDir::new();
    generate_n(&t, "on", "1", &["--denoise", "on"]).assert_success();
    generate_n(&t, "off", "1", &["--denoise", "off"]).assert_success();
    generate_n(&t, "raw", "1", &["--denoise", "on", "--keep-raw"]).assert_success();
    let json = |path: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(t.join(path)).unwrap()).unwrap()
    };
    for (dir, denoised, keep) in [
        ("on", true, false),
        ("off", false, false),
        ("raw", true, true),
    ] {
        let info = json(&format!("{dir}/dataset.json"));
        assert_eq!(info["denoise"], denoised, "{dir}");
        assert_eq!(info["keep_raw"], keep, "{dir}");
        let meta = json(&format!("{dir}/samples/000000/meta.json"));
        assert_eq!(meta["render"]["denoised"], denoised, "{dir}");
        let exr = t.join(&format!("{dir}/samples/000000/im0.exr"));
        assert_eq!(
            streaks_render::output::read_exr_layer(&exr, "raw").is_ok(),
            keep,
            "{dir}"
        );
    }
    let sample = |dir: &str, file: &str| {
        std::fs::read(t.join(&format!("{dir}/samples/000000/{file}"))).unwrap()
    };
    for file in ["disp0.pfm", "streaks0.png", "semantic0.png"] {
        assert_eq!(sample("on", file), sample("off", file), "{file}");
    }
    assert_ne!(sample("on", "im0.png"), sample("off", "im0.png"));
    // The raw layer is the render of `off`.
    let raw = streaks_render::output::read_exr_layer(&t.join("raw/samples/000000/im0.exr"), "raw")
        .unwrap();
    let plain = streaks_image::exr::read_exr_rgb(&t.join("off/samples/000000/im0.exr")).unwrap();
    assert_eq!(raw.pixels, plain.pixels);
    // Continued only with its own choice.
    generate_n(&t, "on", "1", &["--denoise", "off"]).assert_failure_mentioning("denoise");
    generate_n(&t, "x", "1", &["--denoise", "off", "--keep-raw"])
        .assert_failure_mentioning("--keep-raw");
}
