//! Instanced against flattened: a field of 1000 placements of one 2,304-triangle sphere mesh
//! (random rotations and non-uniform scales, one in ten mirrored) on a ground quad, written as
//! a glTF where all nodes share the mesh (instanced: the mesh stored once, a top-level BVH
//! over the instances) and one where each node has its own copy of it (flattened into 2.3 M
//! world triangles). Prints, for each: load time (file to BVH, best of `--loads`), stored
//! triangles, approximate heap memory of the geometry and BVHs, and the time of a render
//! (320x240, 4 spp, max depth 3). Figures in docs/benchmarks.md ("Instancing").
//!
//! Run: `cargo run --release -p streaks-render --example instancing [-- --loads N]`.

use serde_json::json;
use std::path::Path;
use std::time::Instant;
use streaks_render::integrator::{render, RenderJob};
use streaks_render::sampling::Pcg32;
use streaks_render::scene::Scene;
use streaks_settings::RenderSettings;

/// A UV sphere of radius 0.5: `(positions, normals, indices)`.
fn sphere(rings: u32, segments: u32) -> (Vec<f32>, Vec<f32>, Vec<u32>) {
    let (mut pos, mut nrm, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let n = [
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ];
            pos.extend(n.map(|c| 0.5 * c));
            nrm.extend(n);
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            idx.extend([a, a + 1, b, a + 1, b + 1, b]);
        }
    }
    (pos, nrm, idx)
}

/// Writes the field as a `.gltf` with its buffer beside it; `shared`: all nodes reference
/// mesh 0, otherwise each its own copy.
fn write_field(dir: &Path, shared: bool, count: usize) -> std::path::PathBuf {
    let (pos, nrm, idx) = sphere(24, 48);
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut add = |bytes: Vec<u8>| {
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        views.len() - 1
    };
    let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let ground = [
        -40.0f32, 0., -40., -40., 0., 40., 40., 0., 40., 40., 0., -40.,
    ];
    let accessors = json!([
        {"bufferView": add(f(&pos)), "componentType": 5126, "count": pos.len() / 3,
         "type": "VEC3", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
        {"bufferView": add(f(&nrm)), "componentType": 5126, "count": nrm.len() / 3, "type": "VEC3"},
        {"bufferView": add(idx.iter().flat_map(|i| i.to_le_bytes()).collect()),
         "componentType": 5125, "count": idx.len(), "type": "SCALAR"},
        {"bufferView": add(f(&ground)), "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [-40, 0, -40], "max": [40, 0, 40]},
        {"bufferView": add([0u32, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()).collect()),
         "componentType": 5125, "count": 6, "type": "SCALAR"}
    ]);
    let ball = json!({"name": "ball", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
        "indices": 2, "material": 1}]});
    let mut meshes = vec![
        json!({"name": "ground", "primitives": [{"attributes": {"POSITION": 3},
        "indices": 4, "material": 0}]}),
    ];
    let mut nodes = vec![json!({"mesh": 0})];
    let mut rng = Pcg32::new(1, 1);
    let side = (count as f32).sqrt().ceil() as usize;
    for i in 0..count {
        let (x, z) = ((i % side) as f32, (i / side) as f32);
        let mut u = || rng.next_f32();
        let q = glam::Quat::from_axis_angle(
            glam::Vec3::new(u() - 0.5, 1.0, u() - 0.5).normalize(),
            6.0 * u(),
        );
        let s = [0.4 + 0.5 * u(), 0.4 + 0.8 * u(), 0.4 + 0.5 * u()];
        let scale = if i % 10 == 3 { [-s[0], s[1], s[2]] } else { s };
        if !shared || i == 0 {
            meshes.push(ball.clone());
        }
        nodes.push(json!({"mesh": meshes.len() - 1,
            "translation": [2.0 * (x - side as f32 / 2.0), 0.6, -2.0 * z],
            "rotation": q.to_array(), "scale": scale}));
    }
    nodes.push(json!({"camera": 0, "translation": [0, 6, 8], "rotation": [-0.26, 0, 0, 0.966]}));
    nodes.push(json!({"rotation": [-0.5, 0.3, 0.1, 0.8], "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [
            {"name": "ground", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.5}},
            {"name": "ball", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.4, 0.2, 1],
             "metallicFactor": 0.3, "roughnessFactor": 0.3}}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 2000}]}},
        "buffers": [{"byteLength": bin.len(), "uri": "field.bin"}],
        "bufferViews": views,
        "accessors": accessors
    });
    std::fs::write(dir.join("field.bin"), &bin).unwrap();
    let path = dir.join(if shared {
        "instanced.gltf"
    } else {
        "flat.gltf"
    });
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

/// Heap bytes of the scene's geometry and BVHs (flat arrays, flat BVH, instanced meshes).
fn geometry_bytes(s: &Scene) -> usize {
    s.accel.memory_bytes() + s.mesh.memory_bytes() + s.instances.memory_bytes()
}

fn main() {
    let loads = std::env::args()
        .skip_while(|a| a != "--loads")
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(3usize);
    let dir = tempfile::tempdir().unwrap();
    let job = RenderJob {
        width: 320,
        height: 240,
        seed: 1,
        layers: Default::default(),
        settings: RenderSettings::new(4, 3),
        motion: Default::default(),
    };
    let mut images = Vec::new();
    for shared in [true, false] {
        let path = write_field(dir.path(), shared, 1000);
        let mut best = f64::INFINITY;
        let mut scene = None;
        for _ in 0..loads {
            drop(scene.take());
            let t = Instant::now();
            scene = Some(Scene::load(&path).unwrap());
            best = best.min(t.elapsed().as_secs_f64());
        }
        let scene = scene.unwrap();
        let out = render(&scene, scene.camera(None).unwrap(), &job, &|_| {});
        println!(
            "{}: load {:.3} s (best of {loads}), {} triangles stored ({} in the world, {} \
             instances), geometry + BVH {:.1} MB, render {}x{} {} spp: {:.2} s ({:.2} M rays/s)",
            if shared { "instanced" } else { "flattened" },
            best,
            scene.mesh.triangles.len() + scene.instances.stored_triangle_count(),
            scene.world_triangle_count(),
            scene.instances.instances.len(),
            geometry_bytes(&scene) as f64 / 1e6,
            job.width,
            job.height,
            job.settings.spp,
            out.stats.seconds,
            out.stats.rays as f64 / out.stats.seconds / 1e6,
        );
        images.push(out.image);
    }
    let (a, b) = (&images[0], &images[1]);
    let diff: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| f64::from((*p - *q).abs().element_sum()))
        .sum::<f64>()
        / a.pixels
            .iter()
            .map(|p| f64::from(p.element_sum()))
            .sum::<f64>();
    println!("relative L1 difference of the two images: {diff:.2e}");
}
