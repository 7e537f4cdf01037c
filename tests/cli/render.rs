//! End-to-end tests of `streaks render`, and of every shipped scene through it.

use crate::common::TestDir;
use streaks_image::exr::read_exr_rgb;
use streaks_render::output::read_exr_layer;

#[test]
fn render_writes_exr_with_layers_and_png() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let run = t.streaks(&[
        "render",
        "scene.gltf",
        "-o",
        "out/img.exr",
        "--png",
        "out/img.png",
        "--spp",
        "4",
        "--height",
        "20",
        "--max-depth",
        "3",
        "--layers",
        "depth,normal,albedo,specular",
    ]);
    run.assert_success();
    let err = run.stderr();
    assert!(err.contains("samples/s") && err.contains("rays/s"), "{err}");
    assert_eq!(t.files_in("out"), ["img.exr", "img.png"]);

    let img = read_exr_rgb(&t.join("out/img.exr")).unwrap();
    // Width from the camera's aspect ratio 1.5.
    assert_eq!((img.width, img.height), (30, 20));
    assert!(img
        .pixels
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
    // The lit floor fills the bottom row; the sky (top row) is black except for the sign.
    let bottom = img.get(15, 19);
    assert!(bottom.min_element() > 0.0, "{bottom}");
    assert_eq!(img.get(0, 0), glam::Vec3::ZERO);
    // The emissive sign is seen directly: radiance (1, 0.5, 0.2) * 4 somewhere in the image.
    let sign = glam::Vec3::new(4.0, 2.0, 0.8);
    assert!(
        img.pixels
            .iter()
            .any(|p| (*p - sign).abs().max_element() < 1e-4),
        "the emissive sign is missing"
    );

    let depth = read_exr_layer(&t.join("out/img.exr"), "depth").unwrap();
    assert_eq!(depth.get(0, 0).x, f32::INFINITY);
    let d = depth.get(15, 19).x;
    assert!(d.is_finite() && d > 0.5 && d < 5.0, "{d}");
    let normal = read_exr_layer(&t.join("out/img.exr"), "normal").unwrap();
    assert!((normal.get(15, 19) - glam::Vec3::Y).length() < 1e-4);
    let albedo = read_exr_layer(&t.join("out/img.exr"), "albedo").unwrap();
    assert!(albedo.get(15, 19).min_element() > 0.0);
    let specular = read_exr_layer(&t.join("out/img.exr"), "specular").unwrap();
    // The specular part never exceeds the whole.
    for (s, p) in specular.pixels.iter().zip(&img.pixels) {
        assert!(
            s.min_element() >= 0.0 && (*s - *p).max_element() <= 1e-4 * p.max_element().max(1.0)
        );
    }
    assert!(specular.pixels.iter().any(|s| s.max_element() > 0.0));

    let png = std::fs::read(t.join("out/img.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn png_output_and_explicit_size() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    t.streaks(&[
        "render",
        "scene.gltf",
        "-o",
        "a.png",
        "--spp",
        "1",
        "--width",
        "12",
        "--height",
        "5",
        "--exposure",
        "-1",
        "--threads",
        "1",
    ])
    .assert_success();
    assert_eq!(t.files_in("."), ["a.png", "scene.bin", "scene.gltf"]);
}

#[test]
fn same_image_whatever_the_thread_count() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    for (threads, out) in [("1", "one.exr"), ("2", "two.exr")] {
        t.streaks(&[
            "render",
            "scene.gltf",
            "-o",
            out,
            "--spp",
            "3",
            "--height",
            "12",
            "--threads",
            threads,
            "--seed",
            "7",
        ])
        .assert_success();
    }
    let one = read_exr_rgb(&t.join("one.exr")).unwrap();
    let two = read_exr_rgb(&t.join("two.exr")).unwrap();
    assert_eq!(one, two);
}

#[test]
fn bad_arguments_fail_clearly() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let base = ["render", "scene.gltf", "-o", "x.exr"];
    let with = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        t.streaks(&args)
    };
    with(&["--spp", "0"]).assert_failure_mentioning("--spp");
    with(&["--width", "0"]).assert_failure_mentioning("size");
    with(&["--width", "4294967295", "--height", "4294967295"])
        .assert_failure_mentioning("too large");
    with(&["--max-depth", "0"]).assert_failure_mentioning("--max-depth");
    with(&["--layers", "depth,sparkle"]).assert_failure_mentioning("sparkle");
    with(&["--spp", "-3"]).assert_failure_mentioning("-3");
    with(&["--spp=-3"]).assert_failure_mentioning("--spp");
    with(&["--spp", "many"]).assert_failure_mentioning("many");
    with(&["--camera", "nope"]).assert_failure_mentioning("nope");
    for rel in ["0", "-0.1", "nan", "inf"] {
        with(&["--noise-target", rel]).assert_failure_mentioning("--noise-target must be");
    }
    with(&["--noise-target", "low"]).assert_failure_mentioning("low");
    t.streaks(&["render", "scene.gltf", "-o", "x.jpg"])
        .assert_failure_mentioning("x.jpg");
    t.streaks(&["render", "missing.gltf", "-o", "x.exr"])
        .assert_failure_mentioning("missing.gltf");
    std::fs::write(t.join("broken.gltf"), "{ not json").unwrap();
    t.streaks(&["render", "broken.gltf", "-o", "x.exr"])
        .assert_failure_mentioning("broken.gltf");
    // Nothing was written by any of them.
    assert_eq!(t.files_in("."), ["broken.gltf", "scene.bin", "scene.gltf"]);
}

#[test]
fn unwritable_output_leaves_no_file() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    // The output's folder cannot be created: a file is in the way.
    std::fs::write(t.join("blocker"), "").unwrap();
    t.streaks(&[
        "render",
        "scene.gltf",
        "-o",
        "blocker/img.exr",
        "--spp",
        "1",
        "--height",
        "4",
    ])
    .assert_failure_mentioning("blocker");
    // The output is an existing folder: the final rename fails, and no temporary file remains.
    std::fs::create_dir(t.join("taken.exr")).unwrap();
    t.streaks(&[
        "render",
        "scene.gltf",
        "-o",
        "taken.exr",
        "--spp",
        "1",
        "--height",
        "4",
    ])
    .assert_failure_mentioning("taken.exr");
    assert_eq!(
        t.files_in("."),
        ["blocker", "scene.bin", "scene.gltf", "taken.exr"]
    );
    assert!(t.files_in("taken.exr").is_empty());
}

/// Every shipped scene renders through the real command, with light in it and no dropped
/// samples (tiny size and spp: this checks the scenes and the loader together, not quality).
#[test]
fn every_shipped_scene_renders() {
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut names: Vec<_> = std::fs::read_dir(&scenes)
        .expect("scenes/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "gltf"))
        .collect();
    names.sort();
    assert!(
        names.len() >= 7,
        "expected the shipped scenes, found {names:?}"
    );
    let dir = TestDir::new();
    for path in names {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let out = dir.join(&format!("{stem}.exr"));
        let run = dir.streaks(&[
            "render",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--height",
            "48",
            "--spp",
            "2",
            "--max-depth",
            "3",
        ]);
        run.assert_success();
        let stderr = run.stderr();
        assert!(!stderr.contains("warning"), "{stem}: {stderr}");
        assert!(stderr.contains(" 0 samples dropped"), "{stem}: {stderr}");
        let img = read_exr_rgb(&out).unwrap();
        let mean: f32 =
            img.pixels.iter().map(|p| p.x + p.y + p.z).sum::<f32>() / (3 * img.pixels.len()) as f32;
        assert!(mean.is_finite() && mean > 0.0, "{stem}: mean {mean}");
    }
}

/// `--regularize` changes the image but not its specular layer (the first glossy bounce),
/// `--road-mask` writes the road pixels, and `streaks compare` reports the regularised image's
/// fireflies and the road's brightness through the mask.
#[test]
fn regularize_keeps_the_streaks_and_compare_measures_it() {
    let scene =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rainy_street_small.gltf");
    let scene = scene.to_str().unwrap();
    let t = TestDir::new();
    for (out, extra) in [("plain.exr", None), ("reg.exr", Some("--regularize"))] {
        let mut args = vec![
            "render",
            scene,
            "-o",
            out,
            "--height",
            "32",
            "--spp",
            "2",
            "--layers",
            "specular",
            "--road-mask",
            "road.png",
        ];
        args.extend(extra);
        t.streaks(&args).assert_success();
    }
    let (plain, reg) = (t.join("plain.exr"), t.join("reg.exr"));
    assert_ne!(read_exr_rgb(&plain).unwrap(), read_exr_rgb(&reg).unwrap());
    assert_eq!(
        read_exr_layer(&plain, "specular").unwrap(),
        read_exr_layer(&reg, "specular").unwrap()
    );
    let road = streaks_image::GrayImage::load(&t.join("road.png")).unwrap();
    let on = road.data.iter().filter(|&&v| v > 0.5).count();
    assert!(on > 0 && on < road.data.len(), "{on} road pixels");

    let run = t.streaks(&[
        "compare",
        "reg.exr",
        "plain.exr",
        "--mask",
        "road.png",
        "--json",
    ]);
    run.assert_success();
    let c: serde_json::Value = serde_json::from_slice(&run.output.stdout).unwrap();
    assert_eq!(c["regions"][0]["region"]["name"], "road");
    assert_eq!(c["regions"][0]["pixels"].as_u64(), Some(on as u64));
    let share = c["fireflies"]["share"].as_f64().unwrap();
    assert!((0.0..1.0).contains(&share), "{share}");

    // A scene without a road material has no road mask.
    t.write_tiny_gltf();
    t.streaks(&[
        "render",
        "scene.gltf",
        "-o",
        "x.exr",
        "--spp",
        "1",
        "--height",
        "8",
        "--road-mask",
        "r.png",
    ])
    .assert_failure_mentioning("flags no road material");
    assert!(!t.join("r.png").exists() && !t.join("x.exr").exists());
    t.streaks(&["compare", "reg.exr", "plain.exr", "--mask", "missing.png"])
        .assert_failure_mentioning("missing.png");
}

/// `--noise-target` with the `spp` layer: deterministic across thread counts, the layer holds
/// the counts (one per 16x16 tile; the tiles of black sky at the minimum of 16, never above
/// the cap), and the samples reported are the ones taken.
#[test]
fn noise_target_writes_the_spp_layer_and_is_deterministic() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let mut stderr = Vec::new();
    for (threads, out) in [("1", "one.exr"), ("2", "two.exr")] {
        let run = t.streaks(&[
            "render",
            "scene.gltf",
            "-o",
            out,
            "--spp",
            "64",
            "--noise-target",
            "0.05",
            "--height",
            "48",
            "--max-depth",
            "3",
            "--threads",
            threads,
            "--layers",
            "spp",
        ]);
        run.assert_success();
        stderr.push(run.stderr());
    }
    let one = read_exr_rgb(&t.join("one.exr")).unwrap();
    let two = read_exr_rgb(&t.join("two.exr")).unwrap();
    assert_eq!(one, two);
    let spp = read_exr_layer(&t.join("one.exr"), "spp").unwrap();
    assert_eq!(spp, read_exr_layer(&t.join("two.exr"), "spp").unwrap());
    // The horizon is near y = 18: the top row of tiles sees only the black sky.
    assert_eq!(spp.get(0, 0).x, 16.0, "the black sky stops at the minimum");
    for y in 0..spp.height {
        for x in 0..spp.width {
            assert_eq!(
                spp.get(x, y),
                spp.get(x / 16 * 16, y / 16 * 16),
                "({x}, {y})"
            );
        }
    }
    assert!(spp.pixels.iter().all(|n| (16.0..=64.0).contains(&n.x)));
    assert!(
        spp.pixels.iter().any(|n| n.x > 16.0),
        "the lit floor takes more"
    );
    let mean = spp.pixels.iter().map(|n| n.x as f64).sum::<f64>() / spp.pixels.len() as f64;
    let said = format!("{mean:.1} spp on average (noise target 0.05, cap 64)");
    assert!(stderr[0].contains(&said), "{} (wanted {said})", stderr[0]);
}

#[test]
fn scene_files_outside_its_folder_need_the_flag_and_fifos_are_never_read() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    std::fs::create_dir(t.join("sub")).unwrap();
    let json = std::fs::read_to_string(t.join("scene.gltf")).unwrap();
    std::fs::write(
        t.join("sub/up.gltf"),
        json.replace("\"uri\": \"scene.bin\"", "\"uri\": \"../scene.bin\""),
    )
    .unwrap();
    let render = [
        "render",
        "sub/up.gltf",
        "-o",
        "x.png",
        "--spp",
        "1",
        "--width",
        "12",
    ];
    t.streaks(&render)
        .assert_failure_mentioning("--allow-outside-scene")
        .assert_failure_mentioning("../scene.bin");
    let mut allowed = render.to_vec();
    allowed.push("--allow-outside-scene");
    t.streaks(&allowed).assert_success();
    // A FIFO as the buffer: refused at once, even with the flag, by render and stereo.
    let fifo = t.join("sub/pipe.bin");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
    std::fs::write(
        t.join("sub/pipe.gltf"),
        json.replace("\"uri\": \"scene.bin\"", "\"uri\": \"pipe.bin\""),
    )
    .unwrap();
    let start = std::time::Instant::now();
    t.streaks(&[
        "render",
        "sub/pipe.gltf",
        "-o",
        "y.png",
        "--allow-outside-scene",
    ])
    .assert_failure_mentioning("FIFO");
    t.streaks(&[
        "stereo",
        "sub/pipe.gltf",
        "-o",
        "pair",
        "--allow-outside-scene",
    ])
    .assert_failure_mentioning("FIFO");
    assert!(start.elapsed() < std::time::Duration::from_secs(10));
    assert!(!t.join("y.png").exists() && !t.join("pair").exists());
}

/// A glTF sample-model's kind of file: 5 materials using an extension the renderer does not
/// honour, a required KHR_materials_unlit and a morph target. The command renders it and
/// names the unhonoured extension once, with the materials counted (not once per material).
#[test]
fn gltf_warnings_name_each_feature_once() {
    let dir = TestDir::new();
    // One triangle in z = -2 in front of the camera; its morph target moves it by +Y.
    let floats: [f32; 18] = [
        -1., -1., -2., 1., -1., -2., 0., 1., -2., 0., 1., 0., 0., 1., 0., 0., 1., 0.,
    ];
    let bin: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(dir.join("model.bin"), &bin).unwrap();
    let aniso = serde_json::json!({"KHR_materials_anisotropy": {"anisotropyStrength": 0.5}});
    let mut materials: Vec<serde_json::Value> = (0..5)
        .map(|i| serde_json::json!({"name": format!("m{i}"), "extensions": aniso}))
        .collect();
    materials.push(
        serde_json::json!({"name": "flat", "extensions": {"KHR_materials_unlit": {}},
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}),
    );
    let primitives: Vec<serde_json::Value> = (0..6)
        .map(|m| {
            serde_json::json!({"attributes": {"POSITION": 0}, "material": m,
            "targets": [{"POSITION": 1}]})
        })
        .collect();
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_anisotropy", "KHR_materials_unlit"],
        "extensionsRequired": ["KHR_materials_unlit"],
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}],
        "meshes": [{"primitives": primitives, "weights": [0.5]}],
        "materials": materials,
        "buffers": [{"uri": "model.bin", "byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 36}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [-1, -1, -2], "max": [1, 1, -2]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}
        ]
    });
    let scene = dir.join("model.gltf");
    std::fs::write(&scene, doc.to_string()).unwrap();
    let out = dir.join("model.exr");
    let run = dir.streaks(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "1",
    ]);
    run.assert_success();
    let stderr = run.stderr();
    let lines: Vec<&str> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0]
            .contains("KHR_materials_anisotropy on 5 materials: rendered as an isotropic surface")
            && lines[0].contains("and 2 more"),
        "{stderr}"
    );
}

/// `--env`, `--env-color` and `--env-strength` light the scene from the sky: a pixel that sees
/// only the sky shows the environment's radiance there; bad values are errors naming the flag
/// or the file; a scene with no light gets the default environment and one warning, which a
/// flag takes away; the Mitsuba export writes the environment.
#[test]
fn environment_flags_light_the_sky() {
    use glam::Vec3;
    let t = TestDir::new();
    t.write_tiny_gltf();
    let base = ["render", "scene.gltf", "--spp", "2", "--height", "20"];
    let render = |extra: &[&str], out: &str| {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(&["-o", out]);
        args.extend_from_slice(extra);
        t.streaks(&args)
    };
    // A constant sky: the top-left pixel sees only it.
    render(
        &["--env-color", "0.2,0.3,0.4", "--env-strength", "2"],
        "c.exr",
    )
    .assert_success();
    let img = read_exr_rgb(&t.join("c.exr")).unwrap();
    assert!(
        (img.get(0, 0) - Vec3::new(0.4, 0.6, 0.8))
            .abs()
            .max_element()
            < 1e-6
    );
    // A map of one colour per column band: every texel 0.5 but the +Z half bright.
    let sky = streaks_image::RgbImage::from_fn(8, 4, |x, _| {
        if (2..6).contains(&x) {
            Vec3::splat(4.0)
        } else {
            Vec3::splat(0.5)
        }
    });
    streaks_image::exr::write_exr_rgb(&t.join("sky.exr"), &sky).unwrap();
    render(&["--env", "sky.exr"], "m.exr").assert_success();
    let img = read_exr_rgb(&t.join("m.exr")).unwrap();
    // The camera looks along -Z: the dim half, exactly 0.5 near the image's top centre.
    assert!(
        (img.get(15, 0) - Vec3::splat(0.5)).abs().max_element() < 1e-5,
        "{}",
        img.get(15, 0)
    );

    render(&["--env", "missing.exr"], "x.exr").assert_failure_mentioning("missing.exr");
    std::fs::write(t.join("sky.png"), b"\x89PNG\r\n\x1a\n").unwrap();
    render(&["--env", "sky.png"], "x.exr").assert_failure_mentioning("not an OpenEXR");
    render(&["--env", "sky.exr", "--env-strength", "-1"], "x.exr")
        .assert_failure_mentioning("strength");
    render(&["--env-color", "1,2"], "x.exr").assert_failure_mentioning("three numbers");
    render(&["--env-strength", "2"], "x.exr").assert_failure_mentioning("--env-strength needs");
    render(&["--env-color", "1,nan,1"], "x.exr").assert_failure_mentioning("env-color");

    // Without its lamp and with a black sign, the scene has no light.
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(t.join("scene.gltf")).unwrap()).unwrap();
    doc["scenes"][0]["nodes"] = serde_json::json!([0, 1, 2]);
    doc["materials"][1]["emissiveFactor"] = serde_json::json!([0, 0, 0]);
    std::fs::write(t.join("dark.gltf"), doc.to_string()).unwrap();
    let dark = [
        "render",
        "dark.gltf",
        "--spp",
        "2",
        "--height",
        "20",
        "-o",
        "d.exr",
    ];
    let run = t.streaks(&dark);
    run.assert_success();
    let warning = "scene has no light: lit by a uniform white environment of radiance 1";
    assert_eq!(run.stderr().matches(warning).count(), 1, "{}", run.stderr());
    let img = read_exr_rgb(&t.join("d.exr")).unwrap();
    assert_eq!(img.get(0, 0), Vec3::ONE);
    assert!(img.get(15, 19).min_element() > 0.05);
    let mut with_env = dark.to_vec();
    with_env.extend_from_slice(&["--env-color", "1,1,1"]);
    let run = t.streaks(&with_env);
    run.assert_success();
    assert!(!run.stderr().contains(warning), "{}", run.stderr());

    // The export writes the environment map beside the XML.
    t.streaks(&[
        "export-mitsuba",
        "scene.gltf",
        "-o",
        "mi",
        "--env",
        "sky.exr",
    ])
    .assert_success();
    let xml = std::fs::read_to_string(t.join("mi/scene.xml")).unwrap();
    assert!(xml.contains("<emitter type=\"envmap\">"), "{xml}");
    assert!(t.join("mi/textures/environment.exr").exists());
    // And stereo takes the same flags.
    let help = t.streaks(&["stereo", "--help"]);
    let text = String::from_utf8_lossy(&help.output.stdout);
    assert!(
        text.contains("--env <SKY.exr>") && text.contains("--env-color"),
        "{text}"
    );
}

#[test]
fn rain_writes_its_layer_and_motion_flags_are_checked() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let gltf = std::fs::read_to_string(t.join("scene.gltf")).unwrap();
    let with_rain = |rain: &str| {
        gltf.replace(
            r#""scenes": [{"nodes": [0, 1, 2, 3]}]"#,
            &format!(
                r#""scenes": [{{"nodes": [0, 1, 2, 3], "extras": {{"streaks": {{"rain": {rain}}}}}}}]"#
            ),
        )
    };
    std::fs::write(
        t.join("rain.gltf"),
        with_rain(r#"{"rate_mm_h": 100, "radius": 3}"#),
    )
    .unwrap();
    let args = |scene: &'static str, out: &'static str| {
        vec![
            "render",
            scene,
            "-o",
            out,
            "--spp",
            "16",
            "--height",
            "40",
            "--max-depth",
            "4",
            "--layers",
            "depth",
        ]
    };
    let mut rainy = args("rain.gltf", "rain.exr");
    rainy.extend(["--shutter", "0.02", "--rig-velocity", "1,0,-2"]);
    t.streaks(&rainy).assert_success();
    let rain = read_exr_layer(&t.join("rain.exr"), "rain").unwrap();
    let share: f32 = rain.pixels.iter().map(|p| p.x).sum::<f32>() / rain.pixels.len() as f32;
    assert!(share > 0.0 && share < 0.2, "rain share {share}");
    // Depth is that of the dry scene: the drops are not in the ground truth.
    t.streaks(&args("scene.gltf", "dry.exr")).assert_success();
    let depth = |f: &str| read_exr_layer(&t.join(f), "depth").unwrap();
    assert_eq!(depth("rain.exr"), depth("dry.exr"));
    // A dry scene has no rain layer.
    assert!(read_exr_layer(&t.join("dry.exr"), "rain").is_err());

    let mut bad = args("rain.gltf", "x.exr");
    bad.extend(["--shutter", "-1"]);
    t.streaks(&bad).assert_failure_mentioning("--shutter");
    let mut bad = args("rain.gltf", "x.exr");
    bad.extend(["--rig-velocity", "1,2"]);
    t.streaks(&bad).assert_failure_mentioning("--rig-velocity");
    std::fs::write(t.join("bad.gltf"), with_rain(r#"{"rate_mm_h": -1}"#)).unwrap();
    t.streaks(&args("bad.gltf", "x.exr"))
        .assert_failure_mentioning("extras.streaks.rain.rate_mm_h");
    std::fs::write(t.join("bad.gltf"), with_rain(r#"{"rate": 5}"#)).unwrap();
    t.streaks(&args("bad.gltf", "x.exr"))
        .assert_failure_mentioning("rate");
    assert!(!t.join("x.exr").exists());
}

/// The tiny scene with `fog` in its scene's extras.
fn write_foggy_gltf(t: &TestDir, fog: &str) {
    let path = t.write_tiny_gltf();
    let text = std::fs::read_to_string(&path).unwrap().replace(
        r#""scenes": [{"nodes": [0, 1, 2, 3]}]"#,
        &format!(
            r#""scenes": [{{"nodes": [0, 1, 2, 3], "extras": {{"streaks": {{"fog": {fog}}}}}}}]"#
        ),
    );
    assert!(text.contains("\"fog\""));
    std::fs::write(&path, text).unwrap();
}

#[test]
fn a_foggy_scene_renders_with_its_fog_layer() {
    let t = TestDir::new();
    write_foggy_gltf(
        &t,
        r#"{"sigma_t": [0.1, 0.15, 0.2], "albedo": 0.9, "g": 0.7}"#,
    );
    let args = [
        "render",
        "scene.gltf",
        "-o",
        "out/img.exr",
        "--spp",
        "4",
        "--height",
        "20",
    ];
    t.streaks(&args).assert_success();
    let path = t.join("out/img.exr");
    let fog = read_exr_layer(&path, "fog").unwrap();
    let partly = |x: f32| x > 0.0 && x < 1.0;
    // The floor seen through a few metres of fog; nothing of the black sky comes through.
    assert!(partly(fog.get(15, 19).x), "{}", fog.get(15, 19));
    assert_eq!(fog.get(0, 0).x, 0.0);
    // Without fog there is no fog layer.
    let clear = TestDir::new();
    clear.write_tiny_gltf();
    clear.streaks(&args).assert_success();
    assert!(read_exr_layer(&clear.join("out/img.exr"), "fog").is_err());
}

#[test]
fn bad_fog_fails_naming_the_key() {
    let t = TestDir::new();
    write_foggy_gltf(&t, r#"{"sigma_t": 0.1, "albedo": 0.9, "g": 1.5}"#);
    t.streaks(&["render", "scene.gltf", "-o", "img.exr", "--spp", "1"])
        .assert_failure_mentioning("extras.streaks.fog");
}

/// `--denoise`: the EXR's `R`, `G`, `B` are the denoised image and its `raw` layer the render,
/// which the denoiser smooths (less difference between neighbouring pixels of the lit floor)
/// while keeping its brightness; the depth layer is as rendered. With OIDN_LIBRARY pointing
/// nowhere, the command fails naming the file and writes nothing. Needs the library (CI
/// installs it and sets STREAKS_REQUIRE_OIDN); skipped without it.
#[test]
fn render_denoise_keeps_the_raw_render() {
    if !crate::common::denoiser_available() {
        return;
    }
    let t = TestDir::new();
    t.write_tiny_gltf();
    let args = |out: &str| {
        vec![
            "render".to_owned(),
            "scene.gltf".into(),
            "-o".into(),
            out.into(),
            "--spp".into(),
            "2".into(),
            "--height".into(),
            "40".into(),
            "--layers".into(),
            "depth".into(),
            "--denoise".into(),
        ]
    };
    let a = args("out/img.exr");
    t.streaks(&a.iter().map(String::as_str).collect::<Vec<_>>())
        .assert_success();
    let path = t.join("out/img.exr");
    let denoised = read_exr_rgb(&path).unwrap();
    let raw = read_exr_layer(&path, "raw").unwrap();
    assert_eq!((raw.width, raw.height), (denoised.width, denoised.height));
    // The floor: the bottom third, away from the sign.
    let roughness = |img: &streaks_image::RgbImage| {
        let (mut sum, mut n) = (0.0f64, 0);
        for y in 2 * img.height / 3..img.height {
            for x in 1..img.width {
                sum += f64::from((img.get(x, y) - img.get(x - 1, y)).abs().element_sum());
                n += 1;
            }
        }
        sum / f64::from(n)
    };
    let mean = |img: &streaks_image::RgbImage| {
        img.pixels
            .iter()
            .map(|p| f64::from(p.element_sum()))
            .sum::<f64>()
            / img.pixels.len() as f64
    };
    assert!(
        roughness(&denoised) < 0.7 * roughness(&raw),
        "{} vs raw {}",
        roughness(&denoised),
        roughness(&raw)
    );
    assert!((mean(&denoised) / mean(&raw) - 1.0).abs() < 0.1);
    // The emissive sign seen directly is added back as rendered, not spread: where a pixel
    // sees only the sign, the denoised pixel is the sign's radiance.
    let sign = glam::Vec3::new(4.0, 2.0, 0.8);
    let mut seen = 0;
    for (d, r) in denoised.pixels.iter().zip(&raw.pixels) {
        if (*r - sign).abs().max_element() < 1e-4 {
            seen += 1;
            assert!(
                (*d - sign).abs().max_element() < 0.05 * 4.0,
                "{d} vs {sign}"
            );
        }
    }
    assert!(seen > 0, "the sign is not seen whole in any pixel");
    let depth = read_exr_layer(&path, "depth").unwrap();
    assert_eq!(depth.get(0, 0).x, f32::INFINITY);

    let b = args("bad/img.exr");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_streaks"))
        .args(&b)
        .current_dir(t.path())
        .env("CI", "true")
        .env("OIDN_LIBRARY", "/nonexistent/libOpenImageDenoise.so")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("--denoise") && err.contains("/nonexistent/libOpenImageDenoise.so"),
        "{err}"
    );
    assert!(!t.join("bad").exists());
}
