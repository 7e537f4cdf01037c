//! End-to-end tests of `streaks stereo`, `streaks texture-map` and `streaks prepare`.

use crate::common::TestDir;
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
            "calib.txt",
            "depth0.pfm",
            "depth1.pfm",
            "disp0.pfm",
            "disp1.pfm",
            "im0.exr",
            "im0.png",
            "im1.exr",
            "im1.png",
            "instance0.png",
            "instance1.png",
            "occ0.png",
            "occ1.png",
            "rig.json",
            "semantic0.png",
            "semantic1.png",
            "side_by_side.png",
            "streaks0.png",
            "streaks1.png",
        ]
    );
    let file = RigFile::load(&t.join("out/rig.json")).unwrap();
    let rig = file.rig().unwrap();
    assert_eq!(
        (rig.intrinsics().width(), rig.intrinsics().height()),
        (30, 20)
    );
    assert_eq!(rig.baseline(), 0.1);
    // calib.txt agrees with rig.json (Middlebury's baseline in mm, width, height).
    let calib = streaks_stereo::calib::MiddleburyCalib::load(&t.join("out/calib.txt")).unwrap();
    assert_eq!((calib.width, calib.height), (30, 20));
    assert!(
        (calib.baseline_mm - 100.0).abs() < 1e-3,
        "{}",
        calib.baseline_mm
    );
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
    let disp = streaks_image::pfm::read_pfm(&t.join("out/disp0.pfm")).unwrap();
    // The floor at the bottom: positive finite disparity; the sky at the top corner: inf.
    assert!(disp.get(15, 19).is_finite() && disp.get(15, 19) > 0.0);
    assert!(disp.get(0, 0).is_infinite());

    t.streaks(&[
        "texture-map",
        "out/im0.png",
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
        "out/im0.png",
        "out/im1.png",
        "-o",
        "prep",
        "--shift",
        "1.5",
    ])
    .assert_success();
    assert_eq!(
        t.files_in("prep"),
        ["anaglyph.png", "im0.png", "im1.png", "side_by_side.png"]
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
    // Without a camera the default camera is the rig centre; a named one must exist.
    let run = t.streaks(&[
        "stereo",
        "nocam.gltf",
        "-o",
        "out2",
        "--spp",
        "1",
        "--height",
        "8",
    ]);
    run.assert_success();
    assert!(run
        .stderr()
        .contains("scene has no camera: framed its bounds"));
    t.streaks(&[
        "stereo",
        "nocam.gltf",
        "-o",
        "out3",
        "--camera",
        "cam",
        "--spp",
        "1",
    ])
    .assert_failure_mentioning("scene has no camera");
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

// Rendered scenes: ground truth and measured disparity (the renderer and the analysis together).

use glam::Vec3;
use std::path::{Path, PathBuf};
use streaks_analysis::lk::{lk_region, LkParams};
use streaks_dataset::write::write_pair;
use streaks_image::{GrayImage, Region, RgbImage};
use streaks_render::scene::Scene;
use streaks_settings::RenderSettings;
use streaks_stereo::render::{render_pair, rig_from_camera, EyeView, PairSettings};
use streaks_stereo::rig::Eye;
use streaks_stereo::streak_mask::StreakMaskParams;

fn luminance_image(img: &RgbImage) -> GrayImage {
    GrayImage::luminance_of(img).unwrap()
}

/// Writes a glTF scene: a camera at `camera` (looking along -Z, pitched by `pitch`
/// radians), one quad (4 corners, with UVs) carrying `texture` as its baseColorTexture (or
/// a plain grey), and a directional light shining along `light_dir`.
fn write_scene(
    dir: &Path,
    camera: Vec3,
    pitch: f32,
    yfov: f32,
    corners: [Vec3; 4],
    texture: Option<&image::RgbImage>,
    light_dir: Vec3,
) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    for c in corners {
        for v in c.to_array() {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        for v in uv {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    std::fs::write(dir.join("scene.bin"), &bin).unwrap();
    let (lo, hi) = corners.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(a, b), &c| (a.min(c), b.max(c)),
    );
    let mut material = serde_json::json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}});
    let mut extra = serde_json::json!({});
    if let Some(tex) = texture {
        tex.save(dir.join("texture.png")).unwrap();
        material["pbrMetallicRoughness"]["baseColorFactor"] =
            serde_json::json!([1.0, 1.0, 1.0, 1.0]);
        material["pbrMetallicRoughness"]["baseColorTexture"] = serde_json::json!({"index": 0});
        extra = serde_json::json!({
            "textures": [{"source": 0, "sampler": 0}],
            "images": [{"uri": "texture.png"}],
            "samplers": [{"magFilter": 9729, "minFilter": 9729}]
        });
    }
    // The light's node rotation: local -Z onto light_dir.
    let q = glam::Quat::from_rotation_arc(-Vec3::Z, light_dir.normalize());
    let cq = glam::Quat::from_rotation_x(pitch);
    let mut gltf = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 2049.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "name": "cam", "translation": camera.to_array(), "rotation": cq.to_array()},
            {"rotation": q.to_array(), "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.01, "aspectRatio": 4.0 / 3.0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [material],
        "buffers": [{"uri": "scene.bin", "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 32},
            {"buffer": 0, "byteOffset": 80, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ]
    });
    if let serde_json::Value::Object(extra) = extra {
        for (k, v) in extra {
            gltf[k] = v;
        }
    }
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_string_pretty(&gltf).unwrap()).unwrap();
    path
}

fn settings(spp: u32) -> PairSettings {
    PairSettings {
        render: RenderSettings::new(spp, 2),
        seed: 7,
        exposure_ev: 0.0,
        mask: StreakMaskParams::default(),
        motion: Default::default(),
        albedo: false,
    }
}

#[test]
fn road_plane_disparity_matches_the_analytic_plane() {
    let dir = tempfile::tempdir().unwrap();
    let h = 1.5f32;
    let road = [
        Vec3::new(-50.0, 0.0, 10.0),
        Vec3::new(50.0, 0.0, 10.0),
        Vec3::new(50.0, 0.0, -200.0),
        Vec3::new(-50.0, 0.0, -200.0),
    ];
    let path = write_scene(
        dir.path(),
        Vec3::new(0.0, h, 0.0),
        0.0,
        0.6,
        road,
        None,
        Vec3::new(0.0, -1.0, -0.2),
    );
    let scene = Scene::load(&path).unwrap();
    let cam = scene.camera(None).unwrap();
    let rig = rig_from_camera(cam, 64, 48, 0.065).unwrap();
    let views = render_pair(&scene, &rig, &settings(1), &|_| {}).unwrap();
    let f = rig.focal_px();
    let cy = 24.0;
    let mut checked = 0;
    for (eye, view) in Eye::BOTH.into_iter().zip(&views) {
        for y in 0..48 {
            for x in 0..64 {
                let d = view.disparity.get(x, y);
                let yc = y as f32 + 0.5 - cy;
                if yc <= 0.0 {
                    assert!(d.is_infinite(), "{eye} sky ({x}, {y}): {d}");
                    continue;
                }
                // A level rig of height h sees the road at Z = f h / (y - cy): d = b (y - cy) / h.
                let z = f * h / yc;
                if z > 190.0 {
                    continue;
                }
                let expect = 0.065 * yc / h;
                assert!(
                    (d - expect).abs() < 1e-4 * expect.max(1.0),
                    "{eye} ({x}, {y}): {d} vs {expect}"
                );
                assert!(view.road[y * 64 + x]);
                checked += 1;
            }
        }
    }
    assert!(checked > 2000, "{checked}");
    // Write the whole pair and read a few files back.
    write_pair(dir.path(), &scene, &rig, &views, 0.0).unwrap();
    for name in [
        "im0.exr",
        "im1.exr",
        "im0.png",
        "im1.png",
        "side_by_side.png",
        "anaglyph.png",
        "disp0.pfm",
        "depth0.pfm",
        "streaks0.png",
        "streaks1.png",
        "rig.json",
    ] {
        assert!(dir.path().join(name).exists(), "{name}");
    }
    let disp = streaks_image::pfm::read_pfm(&dir.path().join("disp0.pfm")).unwrap();
    assert_eq!(disp, views[0].disparity);
    let file = RigFile::load(&dir.path().join("rig.json")).unwrap();
    assert_eq!(file.rig().unwrap().intrinsics(), rig.intrinsics());
    assert!(matches!(file.lights[0], LightRecord::Directional { .. }));
    let sbs = image::open(dir.path().join("side_by_side.png")).unwrap();
    assert_eq!((sbs.width(), sbs.height()), (128, 48));
}

#[test]
fn rendered_fronto_parallel_plane_has_disparity_f_b_over_z() {
    let dir = tempfile::tempdir().unwrap();
    // A smooth procedural texture: sinusoids with periods of 16-50 image pixels at 5 m.
    let n = 256u32;
    let tex = image::RgbImage::from_fn(n, n, |i, j| {
        let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
        let tau = std::f32::consts::TAU;
        let s = 0.5
            + 0.18 * (tau * 6.0 * u).sin()
            + 0.12 * (tau * 11.0 * u + 1.0).sin()
            + 0.08 * (tau * 17.0 * u + 2.0).sin()
            + 0.1 * (tau * 5.0 * v).sin();
        let g = (s.clamp(0.0, 1.0) * 255.0).round() as u8;
        image::Rgb([g, g, g])
    });
    let z = 5.0f32;
    let plane = [
        Vec3::new(-3.0, -3.0, -z),
        Vec3::new(3.0, -3.0, -z),
        Vec3::new(3.0, 3.0, -z),
        Vec3::new(-3.0, 3.0, -z),
    ];
    let path = write_scene(
        dir.path(),
        Vec3::ZERO,
        0.0,
        0.5,
        plane,
        Some(&tex),
        -Vec3::Z,
    );
    let scene = Scene::load(&path).unwrap();
    let rig = rig_from_camera(scene.camera(None).unwrap(), 160, 120, 0.065).unwrap();
    let views = render_pair(&scene, &rig, &settings(16), &|_| {}).unwrap();
    let expect = rig.disparity_px(z);
    // Ground truth first: the whole view sees the plane at depth Z.
    for v in &views {
        assert!(v
            .disparity
            .data
            .iter()
            .all(|&d| (d - expect).abs() < 1e-3 * expect));
    }
    let lum = |v: &EyeView| luminance_image(&v.output.image);
    let (l, r) = (lum(&views[0]), lum(&views[1]));
    // The project's estimator, one window per row at the image centre, averaged over rows.
    let params = LkParams {
        window: 101,
        min_disp: 0,
        max_disp: 8,
        ..LkParams::default()
    };
    let rows = lk_region(
        &l,
        &r,
        Region {
            x0: 20,
            y0: 10,
            x1: 140,
            y1: 110,
        },
        &params,
    )
    .unwrap();
    assert!(
        rows.iter().all(|r| r.converged && r.ncc > 0.99),
        "{:?}",
        rows[0]
    );
    let d = rows.iter().map(|r| r.disparity).sum::<f32>() / rows.len() as f32;
    let worst = rows
        .iter()
        .map(|r| (r.disparity - expect).abs())
        .fold(0.0f32, f32::max);
    assert!(
        (d - expect).abs() < 0.05,
        "measured {d} px, f b / Z = {expect} px"
    );
    assert!(worst < 0.1, "worst row off by {worst} px");
}

/// `rig.json` lists exactly the renderer's emitters: the same count, kinds and order, each lamp
/// at the centre the light choice uses (and that centre is where the lamp is: near the
/// area-weighted centroid of its triangles).
#[test]
fn rig_json_lists_the_renderers_emitters() {
    use streaks_render::light::Emitter;
    let t = TestDir::new();
    let scene_path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rainy_street_small.gltf");
    t.streaks(&[
        "stereo",
        scene_path.to_str().unwrap(),
        "-o",
        "out",
        "--spp",
        "1",
        "--height",
        "16",
    ])
    .assert_success();
    let file = RigFile::load(&t.join("out/rig.json")).unwrap();
    let scene = streaks_render::scene::Scene::load(&scene_path).unwrap();
    let emitters = scene.light_sampler.emitters();
    assert_eq!(file.lights.len(), emitters.len());
    let mut lamps = 0;
    for (record, emitter) in file.lights.iter().zip(emitters.list()) {
        match (record, emitter) {
            (
                LightRecord::Emissive {
                    centroid,
                    triangles,
                    area,
                    ..
                },
                Emitter::Mesh(m),
            ) => {
                lamps += 1;
                assert_eq!(glam::Vec3::from(centroid.world), m.centre());
                assert_eq!((*triangles, *area), (m.triangle_count(), m.area()));
                // The lamp's own triangles, found independently of the renderer's grouping:
                // those of its material within its bounding sphere.
                let (mut weighted, mut total) = (glam::Vec3::ZERO, 0.0);
                for (t, &mat) in scene.mesh.triangle_materials.iter().enumerate() {
                    let [a, b, c] =
                        scene.mesh.triangles[t].map(|v| scene.mesh.positions[v as usize]);
                    let near = [a, b, c]
                        .iter()
                        .all(|v| v.distance(m.centre()) <= m.radius());
                    if mat == m.material() && near {
                        let area = 0.5 * (b - a).cross(c - a).length();
                        weighted += area * (a + b + c) / 3.0;
                        total += area;
                    }
                }
                let centroid = weighted / total;
                assert!(
                    centroid.distance(m.centre()) < 0.05 * m.radius(),
                    "lamp {} centred at {} but its triangles' centroid is {centroid}",
                    lamps,
                    m.centre()
                );
            }
            (LightRecord::Point { position, .. }, Emitter::Punctual(l))
            | (LightRecord::Spot { position, .. }, Emitter::Punctual(l)) => {
                assert_eq!(Some(glam::Vec3::from(position.world)), l.position());
            }
            (LightRecord::Directional { .. }, Emitter::Punctual(l)) => {
                assert_eq!(l.position(), None);
            }
            (r, e) => panic!("rig.json has {r:?} where the renderer has {e:?}"),
        }
    }
    assert!(lamps > 0, "rainy_street_small has emissive lamps");
}

#[test]
fn the_road_surface_mask_is_the_first_hit_of_road_materials() {
    use streaks_stereo::render::scene_has_road;
    let t = TestDir::new();
    let path = t.write_tiny_gltf();
    let scene = Scene::load(&path).unwrap();
    let rig = rig_from_camera(scene.camera(None).unwrap(), 30, 20, 0.1).unwrap();
    let plain = render_pair(&scene, &rig, &settings(1), &|_| {}).unwrap();
    assert!(!scene_has_road(&scene));
    assert!(plain.iter().all(|v| v.road_surface.iter().all(|&r| !r)));
    // Flag the floor's material as the road surface.
    let mut gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    gltf["materials"][0]["extras"]["streaks"]["road"] = serde_json::json!(true);
    std::fs::write(&path, gltf.to_string()).unwrap();
    let scene = Scene::load(&path).unwrap();
    assert!(scene_has_road(&scene));
    let flagged = render_pair(&scene, &rig, &settings(1), &|_| {}).unwrap();
    for (a, b) in plain.iter().zip(&flagged) {
        // The floor is flat: its pixels are exactly the upward-facing ones; the sign and the
        // sky are not road.
        assert_eq!(b.road_surface, a.road);
        assert!(b.road_surface.iter().any(|&r| r) && b.road_surface.iter().any(|&r| !r));
        let sign = b
            .road_surface
            .iter()
            .zip(&b.depth.data)
            .filter(|(r, z)| !**r && z.is_finite())
            .count();
        assert!(sign > 0, "the sign is in view and is not road");
        // The flag changes no pixel of the images or masks.
        assert_eq!(a.output.image, b.output.image);
        assert_eq!(a.streak_mask, b.streak_mask);
    }
}

/// `stereo --denoise`: each eye's EXR holds the denoised image and the raw render (`raw`),
/// and the ground truth and the streak masks are those of the pair without it (never
/// denoised). Needs the library (see the render test); skipped without it.
#[test]
fn stereo_denoise_changes_the_images_only() {
    if !crate::common::denoiser_available() {
        return;
    }
    let t = TestDir::new();
    t.write_tiny_gltf();
    for (out, extra) in [("plain", None), ("denoised", Some("--denoise"))] {
        let mut args = vec![
            "stereo",
            "scene.gltf",
            "-o",
            out,
            "--spp",
            "2",
            "--height",
            "20",
            "--baseline",
            "0.1",
        ];
        args.extend(extra);
        t.streaks(&args).assert_success();
    }
    for eye in ["0", "1"] {
        let exr = t.join(&format!("denoised/im{eye}.exr"));
        let raw = streaks_render::output::read_exr_layer(&exr, "raw").unwrap();
        let plain =
            streaks_image::exr::read_exr_rgb(&t.join(&format!("plain/im{eye}.exr"))).unwrap();
        assert_eq!(
            raw.pixels, plain.pixels,
            "eye {eye}: the raw render is the plain one"
        );
        let denoised = streaks_image::exr::read_exr_rgb(&exr).unwrap();
        assert_ne!(denoised.pixels, plain.pixels);
        for file in [format!("disp{eye}.pfm"), format!("streaks{eye}.png")] {
            assert_eq!(
                std::fs::read(t.join(&format!("plain/{file}"))).unwrap(),
                std::fs::read(t.join(&format!("denoised/{file}"))).unwrap(),
                "{file}"
            );
        }
    }
}
