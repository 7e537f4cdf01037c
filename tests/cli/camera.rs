//! End-to-end tests of the cameras: orthographic cameras (`streaks render`, `export-mitsuba`,
//! and the stereo error), `--camera` by name and by number, and the default camera of a scene
//! without one.

use crate::common::TestDir;
use streaks_image::exr::read_exr_rgb;
use streaks_image::RgbImage;

/// Writes `NAME.gltf` + `NAME.bin`: the Khronos sample model "Cameras" (CC0: a unit square
/// in [0, 1]^2 rotated -45 degrees about X, a perspective camera of yfov 0.7 and aspect 1
/// and an orthographic camera of xmag = ymag = 1, both at (0.5, 0.5, 3) looking along -Z),
/// with an emissive material of radiance 1 so that it is seen without a light. With
/// `cameras` false it has no camera.
fn write_cameras_model(t: &TestDir, name: &str, cameras: bool) {
    let c = std::f32::consts::FRAC_1_SQRT_2;
    let positions: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let indices: [u16; 6] = [0, 1, 3, 0, 3, 2];
    let mut bin = Vec::new();
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    for p in positions {
        for v in p {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(t.join(&format!("{name}.bin")), &bin).unwrap();
    // The model's rotation (-0.383, 0, 0, 0.92375), normalised: -45 degrees about X.
    let rotation = [-(0.5 - 0.5 * c).sqrt(), 0.0, 0.0, (0.5 + 0.5 * c).sqrt()];
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"rotation": rotation, "mesh": 0},
            {"translation": [0.5, 0.5, 3.0], "camera": 0},
            {"translation": [0.5, 0.5, 3.0], "camera": 1}
        ],
        "cameras": [
            {"type": "perspective",
             "perspective": {"aspectRatio": 1.0, "yfov": 0.7, "zfar": 100, "znear": 0.01}},
            {"type": "orthographic",
             "orthographic": {"xmag": 1.0, "ymag": 1.0, "zfar": 100, "znear": 0.01}}
        ],
        "materials": [{"emissiveFactor": [1, 1, 1], "doubleSided": true,
                       "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0, "material": 0}]}],
        "buffers": [{"uri": format!("{name}.bin"), "byteLength": 60}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12, "target": 34963},
            {"buffer": 0, "byteOffset": 12, "byteLength": 48, "target": 34962}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5123, "count": 6, "type": "SCALAR",
             "max": [3], "min": [0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3",
             "max": [1, 1, 0], "min": [0, 0, 0]}
        ]
    });
    if !cameras {
        doc["scenes"][0]["nodes"] = serde_json::json!([0]);
        doc.as_object_mut().unwrap().remove("cameras");
        doc["nodes"] = serde_json::json!([doc["nodes"][0].clone()]);
    }
    std::fs::write(t.join(&format!("{name}.gltf")), doc.to_string()).unwrap();
}

/// The columns lit (radiance above 0.5) in row `y`: first and last, or `None`.
fn lit_span(img: &RgbImage, y: u32) -> Option<(u32, u32)> {
    let lit: Vec<u32> = (0..img.width).filter(|&x| img.get(x, y).x > 0.5).collect();
    Some((*lit.first()?, *lit.last()?))
}

fn render(t: &TestDir, scene: &str, out: &str, extra: &[&str]) -> (RgbImage, String) {
    let mut args = vec!["render", scene, "-o", out, "--spp", "4", "--max-depth", "1"];
    args.extend_from_slice(extra);
    let run = t.streaks(&args);
    run.assert_success();
    (read_exr_rgb(&t.join(out)).unwrap(), run.stderr())
}

#[test]
fn the_cameras_model_renders_from_both_cameras() {
    let t = TestDir::new();
    write_cameras_model(&t, "cameras", true);
    // The orthographic camera, by number and by its label: a 2 m x 2 m view, so 60 px/m
    // at 120 px, and a square image by default (xmag / ymag = 1).
    let (ortho, _) = render(
        &t,
        "cameras.gltf",
        "ortho.exr",
        &["--camera", "1", "--height", "120"],
    );
    assert_eq!((ortho.width, ortho.height), (120, 120));
    let (by_name, _) = render(
        &t,
        "cameras.gltf",
        "ortho2.exr",
        &["--camera", "camera1", "--height", "120"],
    );
    assert_eq!(ortho.pixels, by_name.pixels);
    // The square spans x in [0, 1] (columns 30..90) and y in [0, 0.707] (rows 47.6..90):
    // an axis-aligned rectangle, every lit row the same width.
    for y in 0..120 {
        let span = lit_span(&ortho, y);
        if (49..89).contains(&y) {
            assert_eq!(span, Some((30, 89)), "row {y}");
        } else if !(47..=90).contains(&y) {
            assert_eq!(span, None, "row {y}");
        }
    }
    // The perspective camera (the first, so also the default): foreshortened, the far
    // (upper) edge narrower than the near one.
    let (persp, _) = render(&t, "cameras.gltf", "persp.exr", &["--height", "120"]);
    let (cam0, _) = render(
        &t,
        "cameras.gltf",
        "persp0.exr",
        &["--camera", "0", "--height", "120"],
    );
    assert_eq!(persp.pixels, cam0.pixels);
    let rows: Vec<u32> = (0..120)
        .filter(|&y| lit_span(&persp, y).is_some())
        .collect();
    let (top, bottom) = (rows[0] + 1, rows[rows.len() - 1] - 1);
    let width = |y| lit_span(&persp, y).map(|(a, b)| b - a).unwrap();
    assert!(
        width(top) + 4 < width(bottom),
        "{} vs {}",
        width(top),
        width(bottom)
    );
    // A number past the list and an unknown name are errors naming the cameras.
    t.streaks(&["render", "cameras.gltf", "-o", "x.exr", "--camera", "2"])
        .assert_failure_mentioning("\"camera0\", \"camera1\"");
}

#[test]
fn orthographic_views_keep_square_pixels_when_both_sizes_are_given() {
    let t = TestDir::new();
    write_cameras_model(&t, "cameras", true);
    // 240 x 120 of a 2 m x 2 m view: the height (1/60 m per pixel) wins and the width
    // grows to 4 m; the square is still 60 px wide, centred.
    let (img, _) = render(
        &t,
        "cameras.gltf",
        "wide.exr",
        &["--camera", "1", "--width", "240", "--height", "120"],
    );
    assert_eq!(lit_span(&img, 70), Some((90, 149)));
}

#[test]
fn a_scene_without_a_camera_is_framed_with_one_warning() {
    let t = TestDir::new();
    write_cameras_model(&t, "nocam", false);
    let (img, err) = render(&t, "nocam.gltf", "out.exr", &["--height", "60"]);
    // 4:3 by default.
    assert_eq!((img.width, img.height), (80, 60));
    let warning = "scene has no camera: framed its bounds from +Z, 25 degrees above the horizon, with a 45 degree field of view";
    assert_eq!(err.matches(warning).count(), 1, "{err}");
    // The square is seen whole, centred, and not cut by the border.
    let lit: Vec<(u32, u32)> = (0..60)
        .flat_map(|y| (0..80).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get(x, y).x > 0.5)
        .collect();
    assert!(lit.len() > 200, "{}", lit.len());
    assert!(lit.iter().all(|&(x, y)| x > 0 && x < 79 && y > 0 && y < 59));
    let cx = lit.iter().map(|p| p.0 as f32).sum::<f32>() / lit.len() as f32;
    assert!((cx - 39.5).abs() < 1.0, "{cx}");
    // A name still has to exist.
    t.streaks(&["render", "nocam.gltf", "-o", "x.exr", "--camera", "cam"])
        .assert_failure_mentioning("scene has no camera");
    // The stereo pair of the default camera: a pinhole rig.
    t.streaks(&[
        "stereo",
        "nocam.gltf",
        "-o",
        "pair",
        "--spp",
        "1",
        "--height",
        "30",
        "--max-depth",
        "1",
    ])
    .assert_success();
    assert!(t.join("pair/im0.exr").exists());
    // The Mitsuba export frames it the same way, with the warning.
    let run = t.streaks(&[
        "export-mitsuba",
        "nocam.gltf",
        "-o",
        "mi",
        "--width",
        "80",
        "--height",
        "60",
    ]);
    run.assert_success();
    assert!(run.stderr().contains(warning), "{}", run.stderr());
    let xml = std::fs::read_to_string(t.join("mi/scene.xml")).unwrap();
    assert!(
        xml.contains("<sensor type=\"perspective\">") && xml.contains("value=\"45.0\""),
        "{xml}"
    );
}

#[test]
fn orthographic_cameras_make_no_stereo_pair_and_export_to_mitsuba() {
    let t = TestDir::new();
    write_cameras_model(&t, "cameras", true);
    t.streaks(&[
        "stereo",
        "cameras.gltf",
        "-o",
        "pair",
        "--camera",
        "1",
        "--spp",
        "1",
    ])
    .assert_failure_mentioning(
        "a stereo pair needs a perspective camera; camera \"camera1\" is orthographic",
    );
    assert!(!t.join("pair/im0.exr").exists());
    let run = t.streaks(&[
        "export-mitsuba",
        "cameras.gltf",
        "-o",
        "mi",
        "--camera",
        "1",
        "--width",
        "160",
        "--height",
        "120",
    ]);
    run.assert_success();
    let xml = std::fs::read_to_string(t.join("mi/scene.xml")).unwrap();
    // Half-width 4/3 m (160 px at 1/60 m), rays starting on the camera plane z = 3.
    assert!(
        xml.contains(
            "<sensor type=\"orthographic\"><float name=\"near_clip\" value=\"0.01\"/>\
             <transform name=\"to_world\"><scale x=\"1.3333334\" y=\"1.3333334\"/>\
             <lookat origin=\"0.5, 0.5, 3.01\" target=\"0.5, 0.5, 2.01\" up=\"0.0, 1.0, 0.0\"/>"
        ),
        "{xml}"
    );
}
