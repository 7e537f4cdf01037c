//! End-to-end tests of `streaks stereo`, `streaks texture-map` and `streaks prepare`.

mod common;

use common::TestDir;
use streaks_stereo::rigfile::{LightRecord, RigFile};

#[test]
fn stereo_writes_the_pair_ground_truth_and_rig_then_maps_and_prepares_it() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    t.streaks(&[
        "stereo",
        "scene.gltf",
        "-o",
        "out",
        "--spp",
        "2",
        "--height",
        "20",
        "--baseline",
        "0.1",
    ])
    .assert_success();
    assert_eq!(
        t.files_in("out"),
        [
            "anaglyph.png",
            "depth_left.pfm",
            "depth_right.pfm",
            "disparity_left.pfm",
            "disparity_right.pfm",
            "left.exr",
            "left.png",
            "rig.json",
            "right.exr",
            "right.png",
            "side_by_side.png",
            "streak_mask_left.png",
            "streak_mask_right.png",
        ]
    );
    let file = RigFile::load(&t.join("out/rig.json")).unwrap();
    let rig = file.rig().unwrap();
    assert_eq!(
        (rig.intrinsics().width(), rig.intrinsics().height()),
        (30, 20)
    );
    assert_eq!(rig.baseline(), 0.1);
    // The point lamp 2 m above the road and the emissive sign (one lamp of two triangles,
    // centred at (0, 1.75, -3) in the world).
    assert!(file
        .lights
        .iter()
        .any(|l| matches!(l, LightRecord::Point { position, .. }
        if (position.road.unwrap()[1] - 2.0).abs() < 1e-5)));
    let sign = file
        .lights
        .iter()
        .find_map(|l| match l {
            LightRecord::Emissive {
                centroid,
                triangles,
                ..
            } => Some((centroid.world, *triangles)),
            _ => None,
        })
        .expect("the emissive sign");
    assert_eq!(sign.1, 2);
    assert!((glam::Vec3::from(sign.0) - glam::Vec3::new(0.0, 1.75, -3.0)).length() < 1e-5);
    let disp = streaks_stereo::pfm::read_pfm(&t.join("out/disparity_left.pfm")).unwrap();
    // The floor at the bottom: positive finite disparity; the sky at the top corner: inf.
    assert!(disp.get(15, 19).is_finite() && disp.get(15, 19) > 0.0);
    assert!(disp.get(0, 0).is_infinite());

    t.streaks(&[
        "texture-map",
        "out/left.png",
        "--rig",
        "out/rig.json",
        "--x-range",
        "-3,3",
        "--z-range",
        "1,8",
        "--resolution",
        "0.05",
        "-o",
        "map.png",
    ])
    .assert_success();
    assert!(image::open(t.join("map.png")).unwrap().width() > 120);
    t.streaks(&[
        "prepare",
        "out/left.png",
        "out/right.png",
        "-o",
        "prep",
        "--shift",
        "1.5",
    ])
    .assert_success();
    assert_eq!(
        t.files_in("prep"),
        ["anaglyph.png", "left.png", "right.png", "side_by_side.png"]
    );
}

#[test]
fn bad_inputs_are_clear_errors() {
    let t = TestDir::new();
    let scene = t.write_tiny_gltf();
    t.streaks(&["stereo", "scene.gltf", "-o", "out", "--baseline", "0"])
        .assert_failure_mentioning("baseline");
    t.streaks(&["stereo", "scene.gltf", "-o", "out", "--camera", "nope"])
        .assert_failure_mentioning("nope");
    // The same scene without its camera.
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        r#"{"camera": 0, "name": "cam", "translation": [0, 1, 4], "rotation": [-0.049979, 0, 0, 0.99875]}"#,
        r#"{"name": "cam"}"#,
    );
    assert!(!text.contains("\"camera\": 0"));
    std::fs::write(t.join("nocam.gltf"), text).unwrap();
    t.streaks(&[
        "stereo",
        "nocam.gltf",
        "-o",
        "out2",
        "--spp",
        "1",
        "--height",
        "8",
    ])
    .assert_failure_mentioning("camera");
    t.streaks(&[
        "texture-map",
        "scene.gltf",
        "--rig",
        "missing.json",
        "-o",
        "m.png",
    ])
    .assert_failure_mentioning("missing.json");
    std::fs::write(t.join("a.png"), b"not a png").unwrap();
    t.streaks(&["prepare", "a.png", "a.png", "-o", "p"])
        .assert_failure_mentioning("a.png");
}
