//! BVH benchmarks: building the obvhs CWBVH over 10k, 100k and 1M triangles, and closest-hit
//! and shadow rays per second on `scenes/rainy_street.gltf` for primary (coherent) and
//! diffuse-bounce (incoherent) rays.
//!
//! Before the timed runs the bench prints the peak heap memory of one 1M-triangle build (a
//! counting global allocator wraps the system one), for the "< 300 MB" target of BENCHMARKS.md.
//!
//! Run: `cargo bench --bench bvh`. The ray benches are skipped, with a message, when the scene
//! file is missing.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::{Vec2, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use streaks_render::accel::Accel;
use streaks_render::geometry::{offset_ray_origin, Frame, Ray};
use streaks_render::light::Light;
use streaks_render::sampling::{square_to_cosine_hemisphere, Pcg32};
use streaks_render::scene::Scene;

/// The system allocator, counting live and peak heap bytes.
struct CountingAlloc;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call to `System` unchanged; only counts.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout);
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if !p.is_null() {
            if new_size >= layout.size() {
                let live = LIVE.fetch_add(new_size - layout.size(), Ordering::Relaxed)
                    + (new_size - layout.size());
                PEAK.fetch_max(live, Ordering::Relaxed);
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

/// A rolling terrain of about `target` triangles: an `n x n` grid of quads, two triangles each,
/// with a smooth height field (realistic, non-degenerate, spatially coherent geometry).
fn terrain(target: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let n = ((target as f64 / 2.0).sqrt().round() as usize).max(1);
    let size = 200.0f32;
    let step = size / n as f32;
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f32 * step, j as f32 * step);
            let y = 2.0 * (x * 0.05).sin() * (z * 0.07).cos() + 0.3 * (x * 0.9 + z * 1.3).sin();
            positions.push(Vec3::new(x, y, z));
        }
    }
    let mut triangles = Vec::with_capacity(2 * n * n);
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (positions, triangles)
}

/// Prints the time and peak heap growth of one 1M-triangle build.
fn report_build_memory() {
    let (positions, triangles) = terrain(1_000_000);
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let start = Instant::now();
    let accel = Accel::build(&positions, &triangles);
    let seconds = start.elapsed().as_secs_f64();
    let peak = PEAK.load(Ordering::Relaxed) - before;
    eprintln!(
        "bvh build of {} triangles: {seconds:.3} s, peak heap growth {:.1} MB, \
         kept {:.1} MB (input mesh {:.1} MB not counted)",
        accel.triangle_count(),
        peak as f64 / 1e6,
        accel.memory_bytes() as f64 / 1e6,
        (std::mem::size_of_val(positions.as_slice()) + std::mem::size_of_val(triangles.as_slice()))
            as f64
            / 1e6,
    );
}

fn bench_build(c: &mut Criterion) {
    report_build_memory();
    let mut group = c.benchmark_group("bvh_build");
    for (label, target, samples) in [
        ("10k", 10_000, 30),
        ("100k", 100_000, 10),
        ("1M", 1_000_000, 10),
    ] {
        let (positions, triangles) = terrain(target);
        group.sample_size(samples);
        group.throughput(Throughput::Elements(triangles.len() as u64));
        group.bench_function(BenchmarkId::from_parameter(label), |b| {
            b.iter(|| Accel::build(black_box(&positions), black_box(&triangles)))
        });
    }
    group.finish();
}

/// Image size of the ray sets (rainy_street's default camera, 4:3).
const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

/// The ray sets traced on a scene.
struct RaySets {
    /// One camera ray per pixel centre, row by row (coherent).
    primary: Vec<Ray>,
    /// From each primary hit, one cosine-distributed bounce about the shading normal
    /// (incoherent).
    bounce: Vec<Ray>,
    /// From each primary hit toward the scene's first point or spot light, stopping short of it.
    shadow: Vec<Ray>,
}

fn ray_sets(scene: &Scene) -> RaySets {
    let camera = &scene.cameras[0];
    let light = scene.lights.iter().find_map(Light::position);
    let mut rng = Pcg32::new(11, 0);
    let mut primary = Vec::new();
    let mut bounce = Vec::new();
    let mut shadow = Vec::new();
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let ray = camera.generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), WIDTH, HEIGHT);
            primary.push(ray);
            let Some(hit) = scene.intersect(&ray) else {
                continue;
            };
            let n = if hit.ns.dot(ray.direction) > 0.0 {
                -hit.ns
            } else {
                hit.ns
            };
            let d = Frame::from_normal(n).to_world(square_to_cosine_hemisphere(rng.next_2d()));
            bounce.push(Ray::new(offset_ray_origin(hit.p, hit.ng, d), d));
            if let Some(lp) = light {
                let to = lp - hit.p;
                let dist = to.length();
                let d = to / dist;
                let mut r = Ray::new(offset_ray_origin(hit.p, hit.ng, d), d);
                r.t_max = dist * (1.0 - 1e-4);
                shadow.push(r);
            }
        }
    }
    RaySets {
        primary,
        bounce,
        shadow,
    }
}

fn bench_rays(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rainy_street.gltf");
    let scene = match Scene::load(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("skipping the ray benches: {e}");
            return;
        }
    };
    if scene.cameras.is_empty() {
        eprintln!("skipping the ray benches: {} has no camera", path.display());
        return;
    }
    let sets = ray_sets(&scene);
    let mut group = c.benchmark_group("rays_rainy_street");
    group.sample_size(20);
    for (name, rays) in [("primary", &sets.primary), ("bounce", &sets.bounce)] {
        group.throughput(Throughput::Elements(rays.len() as u64));
        group.bench_function(BenchmarkId::new("closest_hit", name), |b| {
            b.iter(|| {
                let mut hits = 0u32;
                for r in rays {
                    hits += u32::from(scene.accel.intersect(black_box(r)).is_some());
                }
                hits
            })
        });
        group.bench_function(BenchmarkId::new("closest_hit_surface", name), |b| {
            b.iter(|| {
                let mut hits = 0u32;
                for r in rays {
                    hits += u32::from(scene.intersect(black_box(r)).is_some());
                }
                hits
            })
        });
        group.bench_function(BenchmarkId::new("any_hit", name), |b| {
            b.iter(|| {
                let mut blocked = 0u32;
                for r in rays {
                    blocked += u32::from(scene.occluded(black_box(r)));
                }
                blocked
            })
        });
    }
    if !sets.shadow.is_empty() {
        group.throughput(Throughput::Elements(sets.shadow.len() as u64));
        group.bench_function(BenchmarkId::new("any_hit", "shadow_to_light"), |b| {
            b.iter(|| {
                let mut blocked = 0u32;
                for r in &sets.shadow {
                    blocked += u32::from(scene.occluded(black_box(r)));
                }
                blocked
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_build, bench_rays);
criterion_main!(benches);
