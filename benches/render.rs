//! Path-tracer throughput on a small street built in memory: a wet GGX road, kerbs, facades
//! with emissive windows and two rows of street lamps (point lights), 160 x 120 pixels, one
//! sample per pixel, max depth 4 (`cargo bench --bench render`).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::{Affine3A, Quat, Vec3};
use streaks_render::camera::Camera;
use streaks_render::integrator::{render, Layers, RenderJob};
use streaks_render::light::Light;
use streaks_render::material::Material;
use streaks_render::scene::{Scene, SceneParts};
use streaks_settings::RenderSettings;

/// Adds an axis-aligned box (12 triangles, faces pointing out) of material `m`.
fn add_box(parts: &mut SceneParts, lo: Vec3, hi: Vec3, m: u32) {
    let base = parts.mesh.positions.len() as u32;
    for i in 0..8u32 {
        let pick = |bit: u32, a: f32, b: f32| if i & bit == 0 { a } else { b };
        parts.mesh.positions.push(Vec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        ));
    }
    // Corner index bits: x = 1, y = 2, z = 4. Counter-clockwise seen from outside.
    let faces = [
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
    ];
    for [a, b, c, d] in faces {
        parts.mesh.triangles.push([base + a, base + b, base + c]);
        parts.mesh.triangles.push([base + a, base + c, base + d]);
        parts.mesh.triangle_materials.extend([m, m]);
    }
}

fn street() -> Scene {
    let road = Material::glossy_road("road", Vec3::splat(0.05), Vec3::splat(0.3), 0.08);
    let mut window = Material::diffuse("window", Vec3::ZERO);
    window.emission = Vec3::new(2.0, 1.8, 1.2);
    let mut parts = SceneParts {
        source: "bench street".into(),
        materials: vec![
            road,
            Material::diffuse("kerb", Vec3::splat(0.4)),
            Material::diffuse("facade", Vec3::new(0.3, 0.25, 0.2)),
            window,
        ],
        ..Default::default()
    };
    add_box(
        &mut parts,
        Vec3::new(-5.0, -0.1, -190.0),
        Vec3::new(5.0, 0.0, 10.0),
        0,
    );
    for side in [-1.0f32, 1.0] {
        let (x0, x1) = if side < 0.0 { (-8.0, -5.0) } else { (5.0, 8.0) };
        add_box(
            &mut parts,
            Vec3::new(x0, 0.0, -190.0),
            Vec3::new(x1, 0.15, 10.0),
            1,
        );
    }
    for k in 0..8 {
        let z = -8.0 - 15.0 * k as f32;
        for side in [-1.0f32, 1.0] {
            let x = side * 5.5;
            add_box(
                &mut parts,
                Vec3::new(x - 0.08, 0.0, z - 0.08),
                Vec3::new(x + 0.08, 5.0, z + 0.08),
                2,
            );
            parts.lights.push(Light::Point {
                position: Vec3::new(x, 5.2, z),
                intensity: Vec3::new(300.0, 240.0, 150.0),
                range: None,
            });
            let (x0, x1) = if side < 0.0 {
                (-12.0, -8.0)
            } else {
                (8.0, 12.0)
            };
            add_box(
                &mut parts,
                Vec3::new(x0, 0.0, z - 7.0),
                Vec3::new(x1, 12.0, z + 7.0),
                2,
            );
            let wx = if side < 0.0 { -8.0 + 0.05 } else { 8.0 - 0.05 };
            for f in 0..3 {
                let y = 2.0 + 3.5 * f as f32;
                add_box(
                    &mut parts,
                    Vec3::new(wx - 0.04, y, z - 2.0),
                    Vec3::new(wx + 0.04, y + 1.5, z + 2.0),
                    3,
                );
            }
        }
    }
    Scene::from_parts(parts).expect("the bench scene is valid")
}

fn bench(c: &mut Criterion) {
    let scene = street();
    let camera = Camera::perspective(
        "cam",
        Affine3A::from_rotation_translation(
            Quat::from_rotation_x(-0.087),
            Vec3::new(1.5, 1.4, 0.0),
        ),
        0.7,
        Some(4.0 / 3.0),
    );
    let job = RenderJob {
        width: 160,
        height: 120,
        seed: 0,
        layers: Layers::default(),
        settings: RenderSettings::new(1, 4),
        motion: Default::default(),
    };
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.throughput(Throughput::Elements(160 * 120));
    group.bench_function("street_160x120_1spp_depth4", |b| {
        b.iter(|| render(&scene, &camera, &job, &|_| {}))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
