//! End-to-end tests of `--sensor` on `streaks render` and `streaks stereo`: the raw DN layer,
//! the developed PNGs, independent noise per eye, untouched ground truth, and bad profiles.

use crate::common::TestDir;
use streaks_image::exr::read_exr_rgb;
use streaks_image::pfm::read_pfm;
use streaks_render::output::read_exr_layer;
use streaks_sensor::sensor::Sensor;
use streaks_sensor::SensorProfile;

const RENDER: [&str; 8] = [
    "render",
    "scene.gltf",
    "--spp",
    "4",
    "--height",
    "20",
    "--max-depth",
    "3",
];

#[test]
fn render_through_the_ideal_camera_keeps_the_render_and_adds_the_dn() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let plain = [&RENDER[..], &["-o", "plain.exr", "--png", "plain.png"]].concat();
    t.streaks(&plain).assert_success();
    let cam = [
        &RENDER[..],
        &["-o", "cam.exr", "--png", "cam.png", "--sensor", "ideal"],
    ]
    .concat();
    t.streaks(&cam).assert_success();
    // The render (ground truth for radiance) is the same with and without a camera.
    let img = read_exr_rgb(&t.join("cam.exr")).unwrap();
    assert_eq!(img, read_exr_rgb(&t.join("plain.exr")).unwrap());
    assert!(read_exr_layer(&t.join("plain.exr"), "sensor").is_err());
    // The ideal camera's DN are the camera equation's: round(electrons / gain + black).
    let dn = read_exr_layer(&t.join("cam.exr"), "sensor").unwrap();
    let p = SensorProfile::preset("ideal").unwrap();
    let s = Sensor::new(&p);
    for (l, d) in img.pixels.iter().zip(&dn.pixels) {
        for c in 0..3 {
            let want = (s.electrons_per_radiance * f64::from(l[c]) / p.gain_e_per_dn
                + p.black_level_dn)
                .round();
            assert_eq!(f64::from(d[c]), want);
        }
    }
    // The PNG is developed from the DN, not from the radiance.
    let a = std::fs::read(t.join("cam.png")).unwrap();
    assert_ne!(a, std::fs::read(t.join("plain.png")).unwrap());
    // A PNG-only output works too, and is the same image.
    let png = [&RENDER[..], &["-o", "only.png", "--sensor", "ideal"]].concat();
    t.streaks(&png).assert_success();
    assert_eq!(a, std::fs::read(t.join("only.png")).unwrap());
}

#[test]
fn stereo_eyes_get_independent_noise_and_the_same_ground_truth() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let args = [
        "stereo",
        "scene.gltf",
        "--spp",
        "2",
        "--height",
        "24",
        "--max-depth",
        "2",
    ];
    t.streaks(&[&args[..], &["-o", "plain"]].concat())
        .assert_success();
    let cam = [&args[..], &["-o", "cam", "--sensor", "automotive_linear"]].concat();
    t.streaks(&cam).assert_success();
    for f in ["disp0.pfm", "disp1.pfm", "depth0.pfm"] {
        let (a, b) = (t.join(&format!("plain/{f}")), t.join(&format!("cam/{f}")));
        assert_eq!(read_pfm(&a).unwrap(), read_pfm(&b).unwrap(), "{f}");
    }
    for f in ["streaks0.png", "streaks1.png"] {
        let a = std::fs::read(t.join(&format!("plain/{f}"))).unwrap();
        assert_eq!(
            a,
            std::fs::read(t.join(&format!("cam/{f}"))).unwrap(),
            "{f}"
        );
    }
    let left = read_exr_layer(&t.join("cam/im0.exr"), "sensor").unwrap();
    let right = read_exr_layer(&t.join("cam/im1.exr"), "sensor").unwrap();
    // Dark pixels (the sky) differ between the eyes only by noise: both are noisy, and not
    // alike.
    let p = SensorProfile::preset("automotive_linear").unwrap();
    let sky = |img: &streaks_image::RgbImage| -> Vec<f32> {
        img.pixels[..img.width as usize * 3]
            .iter()
            .map(|q| q.y)
            .collect()
    };
    let (l, r) = (sky(&left), sky(&right));
    assert!(l.iter().any(|&v| f64::from(v) != p.black_level_dn));
    assert_ne!(l, r);
    // The same command again gives the same DN (noise seeded by --seed).
    t.streaks(&[&args[..], &["-o", "again", "--sensor", "automotive_linear"]].concat())
        .assert_success();
    let again = read_exr_layer(&t.join("again/im0.exr"), "sensor").unwrap();
    assert_eq!(again, left);
    assert!(t.join("cam/im0.png").exists() && t.join("cam/side_by_side.png").exists());
}

#[test]
fn bad_sensor_profiles_are_named() {
    let t = TestDir::new();
    t.write_tiny_gltf();
    let run =
        |sensor: &str| t.streaks(&[&RENDER[..], &["-o", "x.exr", "--sensor", sensor]].concat());
    run("nope").assert_failure_mentioning("automotive_hdr");
    std::fs::write(t.join("bad.toml"), "bit_depth = 30\n").unwrap();
    run("bad.toml").assert_failure_mentioning("bit_depth");
    std::fs::write(t.join("typo.toml"), "read_noise = 3\n").unwrap();
    run("typo.toml").assert_failure_mentioning("read_noise");
    run("missing.toml").assert_failure_mentioning("missing.toml");
    assert!(!t.join("x.exr").exists());
}
