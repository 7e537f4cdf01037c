//! Compressed and quantized glTF files load as the same geometry as the file they were made
//! from: `scenes/crosscheck.gltf` written by glTF-Transform 4.5.1 with KHR_mesh_quantization,
//! with EXT_meshopt_compression (quantized, octahedral normals), with
//! KHR_draco_mesh_compression, and by gltfpack 1.3 with meshopt compression (see
//! `tests/data/README.md` for the commands).
//!
//! The encoders reorder and deduplicate vertices, so the comparison is per material: the total
//! area, the area-weighted centroid and the area-weighted mean shading normal of its
//! triangles, within the encoders' quantization (positions to 14 bits or finer over each
//! mesh's extent, normals to 8 bits or finer).

use glam::Vec3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use streaks_render::scene::Scene;

/// Per material name: total area, area-weighted centroid, area-weighted mean shading normal.
fn moments(scene: &Scene) -> BTreeMap<String, (f64, Vec3, Vec3)> {
    let mut out: BTreeMap<String, (f64, Vec3, Vec3)> = BTreeMap::new();
    for (t, &m) in scene
        .mesh
        .triangles
        .iter()
        .zip(&scene.mesh.triangle_materials)
    {
        let [a, b, c] = t.map(|i| scene.mesh.positions[i as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        let n = t
            .iter()
            .map(|&i| scene.mesh.normals[i as usize])
            .sum::<Vec3>()
            / 3.0;
        let e = out
            .entry(scene.materials[m as usize].name.clone())
            .or_insert((0.0, Vec3::ZERO, Vec3::ZERO));
        e.0 += area as f64;
        e.1 += (a + b + c) / 3.0 * area;
        e.2 += n * area;
    }
    for e in out.values_mut() {
        e.1 /= e.0 as f32;
        e.2 /= e.0 as f32;
    }
    out
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn compressed_and_quantized_files_load_as_the_original_geometry() {
    let original = Scene::load(&repo().join("scenes/crosscheck.gltf")).unwrap();
    let want = moments(&original);
    let (_, radius) = original.bounding_sphere();
    for name in [
        "crosscheck_quantized.glb",
        "crosscheck_meshopt.glb",
        "crosscheck_draco.glb",
        "crosscheck_gltfpack.glb",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name);
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            !scene
                .warnings
                .iter()
                .any(|w| w.contains("compression") || w.contains("quantization")),
            "{name}: {:?}",
            scene.warnings
        );
        assert_eq!(scene.lights.len(), original.lights.len(), "{name}");
        assert_eq!(scene.cameras.len(), original.cameras.len(), "{name}");
        let got = moments(&scene);
        assert_eq!(
            got.keys().collect::<Vec<_>>(),
            want.keys().collect::<Vec<_>>(),
            "{name}"
        );
        for (material, (area, centroid, normal)) in &want {
            let (a, c, n) = got[material];
            assert!(
                (a - area).abs() <= 2e-3 * area,
                "{name} {material}: area {a} vs {area}"
            );
            assert!(
                (c - *centroid).length() <= 1e-3 * radius,
                "{name} {material}: centroid {c} vs {centroid}"
            );
            assert!(
                (n - *normal).length() <= 0.02,
                "{name} {material}: mean normal {n} vs {normal}"
            );
        }
    }
}

#[test]
fn corrupt_compressed_data_is_an_error_naming_the_element() {
    let dir = tempfile::tempdir().unwrap();
    for (name, element) in [
        ("crosscheck_meshopt.glb", "EXT_meshopt_compression"),
        ("crosscheck_draco.glb", "KHR_draco_mesh_compression"),
    ] {
        let mut bytes = std::fs::read(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/data")
                .join(name),
        )
        .unwrap();
        // Scramble the binary chunk (after the 12-byte header, the JSON chunk and the binary
        // chunk's own 8-byte header), keeping the sizes.
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let bin = 20 + json_len + 8;
        for (i, b) in bytes[bin..].iter_mut().enumerate() {
            *b = (i as u8).wrapping_mul(151).wrapping_add(7);
        }
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(err.contains(name) && err.contains(element), "{err}");
    }
}

#[test]
fn decoded_geometry_is_held_to_the_scenes_budget() {
    use streaks_render::scene::LoadOptions;
    for (name, element) in [
        ("crosscheck_meshopt.glb", "EXT_meshopt_compression"),
        ("crosscheck_draco.glb", "KHR_draco_mesh_compression"),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name);
        // The file decodes within the default budget, and not within 1000 bytes.
        Scene::load(&path).unwrap();
        let small = LoadOptions {
            max_decoded_bytes: 1000,
            ..LoadOptions::default()
        };
        let err = Scene::load_with(&path, &small).unwrap_err().to_string();
        assert!(err.contains(name) && err.contains(element), "{err}");
        assert!(err.contains("limit") || err.contains("Limit"), "{err}");
    }
}
