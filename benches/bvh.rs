//! BVH benchmarks: building the BVH (obvhs' binary tree collapsed into the project's wide one)
//! over 10k, 100k and 1M triangles, and closest-hit and shadow rays per second on `scenes/rainy_street.gltf` for primary (coherent) and
//! diffuse-bounce (incoherent) rays.
//!
//! Coherent rays (`coherent_<street>` groups; docs/decisions/0006): primary rays and the road's
//! first glossy bounce on `rainy_street` and on a procedural street (the generator's default
//! config, seed 0, sample 0: the scene of `streaks dataset generate --count 1`'s
//! `samples/000000`, camera `driver`), closest hits traced one at a time in scanline order,
//! in sorted orders (pixels in Morton and 4x4-tile order; bounce rays by direction octant,
//! then origin Morton code), and one pixel's eight samples in turn (the order a renderer that
//! traces a pixel's samples in turn has). The packet traversal that decision measured against
//! these is not kept (the decision says where to find it).
//!
//! Before the timed runs the bench prints the peak heap memory of one 1M-triangle build (a
//! counting global allocator wraps the system one), for the "< 300 MB" target in docs/benchmarks.md.
//!
//! Run: `cargo bench --bench bvh` (`cargo bench --bench bvh -- coherent` for the coherent rays
//! alone). With `STREAKS_BVH_RAYS_OUT=DIR`, the coherent benches also write each street's
//! triangles and four of its ray sets to `DIR/<street>/` (`write_rays`), which
//! `tools/embree/race.py` traces with Embree. The ray benches are skipped, with a message, when the scene file is missing.
//! Instruction counts of the coherent sets: run the bench binary under
//! `valgrind --tool=callgrind` with `--bench coherent_<street> --profile-time 1` and
//! `STREAKS_COHERENT_HEIGHT=60` (a smaller image, so that making the rays takes minutes, not
//! hours); each ray set is traced by its own instance of `trace_single::<SET>`, so
//! `callgrind_annotate --inclusive=yes` gives each set's
//! instructions (divide by the calls and the set's rays).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::{Vec2, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use streaks_render::accel::Accel;
use streaks_render::camera::Camera;
use streaks_render::geometry::{offset_ray_origin, Frame, Ray};
use streaks_render::light::Light;
use streaks_render::sampling::{square_to_cosine_hemisphere, Pcg32};
use streaks_render::scene::Scene;
use streaks_scenes::procedural::{sample, GeneratorConfig};

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

/// Image height of the coherent-ray sets (`STREAKS_COHERENT_HEIGHT` overrides it); the
/// width follows the camera's aspect ratio.
const COHERENT_HEIGHT: u32 = 240;

/// Samples per pixel of the "one pixel's samples" sets (as many as an AVX2 register has lanes).
const PIXEL_SAMPLES: u32 = 8;

/// GGX alpha of the road's glossy bounce (the wet asphalt of both streets has 0.02-0.04).
const ROAD_ALPHA: f32 = 0.03;

/// The bits of `x` spread to every `stride`-th bit (`stride` 2 or 3; `bits` of them).
fn spread(x: u32, bits: u32, stride: u32) -> u64 {
    (0..bits).fold(0, |m, i| m | (u64::from(x >> i & 1) << (i * stride)))
}

/// Morton code of pixel `(x, y)`.
fn morton2(x: u32, y: u32) -> u64 {
    spread(x, 16, 2) | spread(y, 16, 2) << 1
}

/// Morton code of `p` in the box `[lo, hi]`, 10 bits per axis.
fn morton3(p: Vec3, lo: Vec3, hi: Vec3) -> u64 {
    let q = ((p - lo) / (hi - lo).max(Vec3::splat(1e-6)) * 1023.0)
        .clamp(Vec3::ZERO, Vec3::splat(1023.0));
    spread(q.x as u32, 10, 3) | spread(q.y as u32, 10, 3) << 1 | spread(q.z as u32, 10, 3) << 2
}

/// Bounce rays sorted by direction octant, then by the Morton code of their origin in the
/// origins' bounding box (the sort key costs and the sort itself are what a renderer would
/// pay on top; the `sort` bench measures them).
fn sorted_by_octant_and_origin(rays: &[Ray]) -> Vec<Ray> {
    let (lo, hi) = rays.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), r| (lo.min(r.origin), hi.max(r.origin)),
    );
    let mut keyed: Vec<(u64, Ray)> = rays
        .iter()
        .map(|r| {
            let d = r.direction;
            let octant =
                u64::from(d.x < 0.0) << 2 | u64::from(d.y < 0.0) << 1 | u64::from(d.z < 0.0);
            (octant << 30 | morton3(r.origin, lo, hi), *r)
        })
        .collect();
    keyed.sort_by_key(|(k, _)| *k);
    keyed.into_iter().map(|(_, r)| r).collect()
}

/// A GGX reflection of `ray` at its hit on the road: the microfacet normal drawn from
/// `D(m) cos(m)` (alpha [`ROAD_ALPHA`]) about the shading normal `n` (facing the ray's
/// origin), the direction reflected about it; `None` if that goes below the surface.
fn glossy_bounce(ray: &Ray, p: Vec3, n: Vec3, ng: Vec3, u: Vec2) -> Option<Ray> {
    let tan2 = ROAD_ALPHA * ROAD_ALPHA * u.x / (1.0 - u.x);
    let cos = 1.0 / (1.0 + tan2).sqrt();
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    let m = Frame::from_normal(n).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos));
    let d = ray.direction - 2.0 * ray.direction.dot(m) * m;
    let ng = if ng.dot(ray.direction) > 0.0 { -ng } else { ng };
    (d.dot(ng) > 0.0).then(|| Ray::new(offset_ray_origin(p, ng, d), d.normalize()))
}

/// The coherent ray sets of one street (see the module documentation).
struct CoherentSets {
    width: u32,
    height: u32,
    /// Pixel-centre rays in scanline, Morton and 4x4-tile order.
    scanline: Vec<Ray>,
    morton: Vec<Ray>,
    tiles: Vec<Ray>,
    /// [`PIXEL_SAMPLES`] jittered rays per pixel, pixels in scanline order.
    pixel_samples: Vec<Ray>,
    /// Glossy bounces off the road from the pixel-centre hits, in scanline order and sorted.
    bounce: Vec<Ray>,
    bounce_sorted: Vec<Ray>,
    /// Glossy bounces of the jittered rays that hit the road, pixel by pixel.
    bounce_pixel_samples: Vec<Ray>,
}

fn coherent_sets(scene: &Scene, camera: &Camera) -> CoherentSets {
    let height = std::env::var("STREAKS_COHERENT_HEIGHT")
        .ok()
        .and_then(|h| h.parse().ok())
        .unwrap_or(COHERENT_HEIGHT);
    let width = (height as f32 * camera.aspect_ratio().unwrap_or(4.0 / 3.0)).round() as u32;
    let mut rng = Pcg32::new(23, 0);
    let centre = |x: u32, y: u32| {
        camera.generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), width, height)
    };
    let road_bounce = |ray: &Ray, u: Vec2| {
        let hit = scene.intersect(ray)?;
        if !scene.materials[hit.material as usize].road {
            return None;
        }
        let n = if hit.ns.dot(ray.direction) > 0.0 {
            -hit.ns
        } else {
            hit.ns
        };
        glossy_bounce(ray, hit.p, n, hit.ng, u)
    };
    let mut pixels: Vec<(u32, u32)> = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .collect();
    let scanline: Vec<Ray> = pixels.iter().map(|&(x, y)| centre(x, y)).collect();
    let mut bounce_of = vec![None; pixels.len()];
    for (i, r) in scanline.iter().enumerate() {
        bounce_of[i] = road_bounce(r, rng.next_2d());
    }
    let bounce: Vec<Ray> = bounce_of.iter().flatten().copied().collect();
    pixels.sort_by_key(|&(x, y)| morton2(x, y));
    let morton = pixels.iter().map(|&(x, y)| centre(x, y)).collect();
    pixels.sort_by_key(|&(x, y)| (y / 4, x / 4, y % 4, x % 4));
    let tiles = pixels.iter().map(|&(x, y)| centre(x, y)).collect();
    let (mut pixel_samples, mut bounce_pixel_samples) = (Vec::new(), Vec::new());
    for y in 0..height {
        for x in 0..width {
            for _ in 0..PIXEL_SAMPLES {
                let film = Vec2::new(x as f32, y as f32) + rng.next_2d();
                let ray = camera.generate_ray(film, width, height);
                pixel_samples.push(ray);
                if let Some(b) = road_bounce(&ray, rng.next_2d()) {
                    bounce_pixel_samples.push(b);
                }
            }
        }
    }
    CoherentSets {
        width,
        height,
        scanline,
        morton,
        tiles,
        pixel_samples,
        bounce_sorted: sorted_by_octant_and_origin(&bounce),
        bounce,
        bounce_pixel_samples,
    }
}

/// Closest hits of `rays`, one at a time, in order; how many hit. `SET` only names the ray
/// set, so that callgrind counts each set's calls apart.
#[inline(never)]
fn trace_single<const SET: u8>(accel: &Accel, rays: &[Ray]) -> u32 {
    // Keeps the instances apart (identical code would be merged into one symbol).
    black_box(SET);
    let mut hits = 0u32;
    for r in rays {
        hits += u32::from(accel.intersect(black_box(r)).is_some());
    }
    hits
}

/// `rainy_street` (its first camera) and the procedural street (camera `driver`); a street
/// that cannot be made is skipped with a message.
fn coherent_streets() -> Vec<(&'static str, Scene, String)> {
    let mut streets = vec![];
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rainy_street.gltf");
    match Scene::load(&path) {
        Ok(s) if !s.cameras.is_empty() => {
            let camera = s.cameras[0].name.clone();
            streets.push(("rainy_street", s, camera));
        }
        Ok(_) => eprintln!("skipping rainy_street: no camera"),
        Err(e) => eprintln!("skipping rainy_street: {e}"),
    }
    let procedural = || -> Result<(Scene, String), String> {
        let s = sample(&GeneratorConfig::default(), 0, 0).map_err(|e| e.to_string())?;
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        s.doc.write(dir.path()).map_err(|e| e.to_string())?;
        let scene = Scene::load(&dir.path().join("scene.gltf")).map_err(|e| e.to_string())?;
        Ok((scene, s.camera))
    };
    match procedural() {
        Ok((scene, camera)) => streets.push(("procedural", scene, camera)),
        Err(e) => eprintln!("skipping the procedural street: {e}"),
    }
    streets
}

fn bench_coherent(c: &mut Criterion) {
    for (name, scene, camera) in coherent_streets() {
        let Ok(cam) = scene.camera(Some(&camera)) else {
            eprintln!("skipping {name}: no camera {camera}");
            continue;
        };
        let sets = coherent_sets(&scene, cam);
        let accel = &scene.accel;
        let hit = |rays: &[Ray]| trace_single::<0>(accel, rays) as f64 / rays.len().max(1) as f64;
        eprintln!(
            "{name}: {} triangles, {} instances, {}x{} pixels, {} road bounces ({:.0}% of the \
             pixels; {:.0}% of them hit), {} samples' bounces",
            accel.triangle_count(),
            scene.instances.instances.len(),
            sets.width,
            sets.height,
            sets.bounce.len(),
            100.0 * sets.bounce.len() as f64 / sets.scanline.len() as f64,
            100.0 * hit(&sets.bounce),
            sets.bounce_pixel_samples.len(),
        );
        if let Some(dir) = std::env::var_os("STREAKS_BVH_RAYS_OUT") {
            let dir = Path::new(&dir).join(name);
            let sets = [
                ("primary_scanline", &sets.scanline),
                ("primary_spp8", &sets.pixel_samples),
                ("bounce_scanline", &sets.bounce),
                ("bounce_spp8", &sets.bounce_pixel_samples),
            ];
            match write_rays(&dir, &scene, &sets) {
                Ok(()) => eprintln!("{name}: triangles and rays written to {}", dir.display()),
                Err(e) => eprintln!("{name}: writing {}: {e}", dir.display()),
            }
        }
        let mut group = c.benchmark_group(format!("coherent_{name}"));
        group.sample_size(20);
        let mut single = |id: &str, rays: &[Ray], trace: fn(&Accel, &[Ray]) -> u32| {
            group.throughput(Throughput::Elements(rays.len() as u64));
            group.bench_function(id, |b| b.iter(|| trace(accel, rays)));
        };
        single("primary/scanline", &sets.scanline, trace_single::<1>);
        single("primary/morton", &sets.morton, trace_single::<2>);
        single("primary/tiles4x4", &sets.tiles, trace_single::<3>);
        single(
            "primary_spp8/single",
            &sets.pixel_samples,
            trace_single::<4>,
        );
        single("bounce/scanline", &sets.bounce, trace_single::<5>);
        single("bounce/sorted", &sets.bounce_sorted, trace_single::<6>);
        single(
            "bounce_spp8/single",
            &sets.bounce_pixel_samples,
            trace_single::<7>,
        );
        // What sorting the bounce rays costs, per ray.
        group.throughput(Throughput::Elements(sets.bounce.len() as u64));
        group.bench_function("bounce/sort", |b| {
            b.iter(|| sorted_by_octant_and_origin(black_box(&sets.bounce)))
        });
        group.finish();
    }
}

/// Writes the triangles the street's BVH holds and ray sets to `dir`, for tracing the same
/// rays with another library (`tools/embree/race.py` reads them): `triangles.f32` (each
/// triangle's three vertices, 9 little-endian `f32`), and per set `NAME.f32` (origin,
/// direction and `t_max` of each ray, 7 `f32`) and `NAME.hits` (how many of them this BVH hits,
/// in decimal).
fn write_rays(dir: &Path, scene: &Scene, sets: &[(&str, &Vec<Ray>)]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let floats = |v: &mut Vec<u8>, xs: &[f32]| xs.iter().for_each(|x| v.extend(x.to_le_bytes()));
    let mut tris = Vec::new();
    for t in &scene.mesh.triangles {
        for &i in t {
            floats(&mut tris, &scene.mesh.positions[i as usize].to_array());
        }
    }
    std::fs::write(dir.join("triangles.f32"), tris)?;
    for (name, rays) in sets {
        let mut out = Vec::new();
        for r in rays.iter() {
            floats(&mut out, &r.origin.to_array());
            floats(&mut out, &r.direction.to_array());
            floats(&mut out, &[r.t_max]);
        }
        std::fs::write(dir.join(format!("{name}.f32")), out)?;
        let hits = trace_single::<0>(&scene.accel, rays);
        std::fs::write(dir.join(format!("{name}.hits")), hits.to_string())?;
    }
    Ok(())
}

criterion_group!(benches, bench_build, bench_rays, bench_coherent);
criterion_main!(benches);
