//! The sweep over Khronos glTF sample models (`tests/data/khronos/`, see its README): each one
//! renders through the real command with the default camera and light, as a new user would
//! run it, without an error, a panic, a non-finite pixel or a black model, and names each
//! feature it cannot render once.

use crate::common::TestDir;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use streaks_image::exr::read_exr_channels;

/// The sample models' folder.
fn models_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/khronos")
}

/// Every model's main file (`<Name>/<variant>/<file>.gltf|glb`), by model name.
fn model_files() -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    for model in std::fs::read_dir(models_dir()).expect("tests/data/khronos is missing") {
        let model = model.unwrap().path();
        if !model.is_dir() {
            continue;
        }
        let name = model.file_name().unwrap().to_string_lossy().into_owned();
        let mut mains = Vec::new();
        for variant in std::fs::read_dir(&model).unwrap() {
            let variant = variant.unwrap().path();
            if !variant.is_dir() {
                continue;
            }
            for file in std::fs::read_dir(&variant).unwrap() {
                let file = file.unwrap().path();
                let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("");
                if ext == "gltf" || ext == "glb" {
                    mains.push(file);
                }
            }
        }
        assert_eq!(
            mains.len(),
            1,
            "{name}: expected one glTF file, found {mains:?}"
        );
        out.insert(name, mains.pop().unwrap());
    }
    out
}

/// What a render of one model shows: the share of pixels on the model (finite depth), the
/// mean luminance over those pixels, and the lines of standard error.
struct Rendered {
    covered: f64,
    model_luminance: f64,
    warnings: Vec<String>,
}

/// Renders `file` at 64x48, 4 spp, with the depth layer, and reads the result back.
fn render(dir: &TestDir, name: &str, file: &Path) -> Rendered {
    let out = dir.join(&format!("{name}.exr"));
    let run = dir.streaks(&[
        "render",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "48",
        "--spp",
        "4",
        "--max-depth",
        "4",
        "--layers",
        "depth",
    ]);
    let stderr = run.stderr();
    assert!(!stderr.contains("panicked"), "{name} panicked: {stderr}");
    assert!(run.output.status.success(), "{name} failed: {stderr}");
    let (w, h, channels) = read_exr_channels(&out, &["R", "G", "B", "depth.Z"])
        .unwrap_or_else(|e| panic!("{name}: cannot read its render: {e}"));
    let (mut covered, mut sum) = (0usize, 0.0f64);
    let [r, g, b, depth] = &channels[..] else {
        panic!("{name}: four channels expected");
    };
    for (i, &z) in depth.iter().enumerate() {
        let rgb = [r[i], g[i], b[i]];
        assert!(
            rgb.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{name}: pixel {i} is {rgb:?}"
        );
        if z.is_finite() {
            covered += 1;
            sum += (0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]) as f64;
        }
    }
    let warnings = stderr
        .lines()
        .filter(|l| l.starts_with("warning"))
        .map(str::to_owned)
        .collect();
    Rendered {
        covered: covered as f64 / (w * h) as f64,
        model_luminance: if covered == 0 {
            0.0
        } else {
            sum / covered as f64
        },
        warnings,
    }
}

/// A feature each of these models uses that is not rendered, and the words of its warning.
const EXPECTED_WARNINGS: &[(&str, &str)] = &[
    ("AnimatedMorphCube", "animations on 1 animation"),
    ("AnisotropyStrengthTest", "KHR_materials_anisotropy on"),
    (
        "MeshPrimitiveModes",
        "point and line primitives on 4 primitives",
    ),
    (
        "TextureTransformMultiTest",
        "occlusionTexture on 3 materials",
    ),
];

#[test]
fn every_sample_model_renders_framed_lit_and_warned_once() {
    let models = model_files();
    assert!(models.len() >= 30, "only {} models", models.len());
    let dir = TestDir::new();
    let mut failures = Vec::new();
    for (name, file) in &models {
        let r = render(&dir, name, file);
        // The default camera frames the model: it covers a good part of the image.
        if r.covered < 0.02 {
            failures.push(format!(
                "{name}: the model covers {:.1} % of the image",
                100.0 * r.covered
            ));
        }
        // Lit: the model is not black. Under the default environment (radiance 1) even the
        // darkest albedo here gives more than 0.01; a file's own photometric lights can be
        // dim (IridescenceSuzanne's is 2 lux, 2/683 W/m^2, as Blender's importer reads it
        // too), so there only light must arrive.
        let default_light = r.warnings.iter().any(|w| w.contains("scene has no light"));
        let floor = if default_light { 1e-2 } else { 1e-6 };
        if r.model_luminance < floor {
            failures.push(format!(
                "{name}: the model is black (mean luminance {:.2e})",
                r.model_luminance
            ));
        }
        // What each model cannot render is named.
        if let Some((_, needle)) = EXPECTED_WARNINGS.iter().find(|(m, _)| m == name) {
            if !r.warnings.iter().any(|w| w.contains(needle)) {
                failures.push(format!(
                    "{name}: no warning about {needle:?}: {:?}",
                    r.warnings
                ));
            }
        }
        // Each warning once.
        let mut seen = std::collections::BTreeSet::new();
        for w in &r.warnings {
            if !seen.insert(w.as_str()) {
                failures.push(format!("{name}: warning repeated: {w}"));
            }
        }
        eprintln!(
            "{name}: {:.0} % covered, model luminance {:.3}, {} warnings",
            100.0 * r.covered,
            r.model_luminance,
            r.warnings.len()
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
