//! Full-render benchmarks on `scenes/rainy_street_small.gltf` (`benches/render.rs` renders an
//! in-memory street instead): samples per second on one thread and on all threads (the "two threads >= 1.8x one thread" target), and loading
//! `scenes/rainy_street.gltf` (scene + BVH build, the "< 5% of a default render" target).
//!
//! Before the timed runs the bench checks two properties with a counting global allocator and
//! prints them: the number of heap allocations of a render does not grow with the sample count
//! (no allocation per sample), and its peak heap does not either (memory per pixel is
//! independent of spp).
//!
//! Run: `cargo bench --bench render_scene`. Skipped, with a message, when the scenes are missing.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use streaks_render::integrator::{render, Layers, RenderJob};
use streaks_render::scene::Scene;
use streaks_settings::RenderSettings;

/// The system allocator, counting allocations and live/peak heap bytes.
struct CountingAlloc;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(by: usize) {
    let live = LIVE.fetch_add(by, Ordering::Relaxed) + by;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

// SAFETY: forwards every call to `System` unchanged; only counts.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
            grew(layout.size());
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
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
            if new_size >= layout.size() {
                grew(new_size - layout.size());
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

/// The race's image (the Mitsuba measurement): 320x240, max depth 4.
fn job(spp: u32) -> RenderJob {
    RenderJob {
        width: 320,
        height: 240,
        seed: 1,
        layers: Layers::default(),
        settings: RenderSettings::new(spp, 4),
        motion: Default::default(),
    }
}

/// Allocations and peak heap growth of one render with `spp` samples per pixel.
fn render_footprint(scene: &Scene, spp: u32) -> (usize, usize) {
    let camera = &scene.cameras[0];
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let count = ALLOCATIONS.load(Ordering::Relaxed);
    let out = render(scene, camera, &job(spp), &|_| {});
    black_box(&out);
    let allocations = ALLOCATIONS.load(Ordering::Relaxed) - count;
    let peak = PEAK.load(Ordering::Relaxed) - before;
    (allocations, peak)
}

fn report_footprint(scene: &Scene) {
    let pixels = 320 * 240;
    // A first render warms up rayon's pool (its threads allocate once).
    render_footprint(scene, 1);
    for spp in [1, 4, 16] {
        let (allocations, peak) = render_footprint(scene, spp);
        eprintln!(
            "render 320x240 at {spp:>2} spp: {allocations} heap allocations, peak heap growth \
             {:.1} MB ({:.0} bytes per pixel)",
            peak as f64 / 1e6,
            peak as f64 / pixels as f64
        );
    }
}

fn bench_render(c: &mut Criterion) {
    let path = scene_path("rainy_street_small.gltf");
    let scene = match Scene::load(&path) {
        Ok(s) if !s.cameras.is_empty() => s,
        Ok(_) => {
            eprintln!(
                "skipping the render benches: {} has no camera",
                path.display()
            );
            return;
        }
        Err(e) => {
            eprintln!("skipping the render benches: {e}");
            return;
        }
    };
    report_footprint(&scene);
    let camera = &scene.cameras[0];
    let spp = 8;
    let s = job(spp);
    let mut group = c.benchmark_group("render_rainy_street_small");
    group.sample_size(10);
    group.throughput(Throughput::Elements(
        u64::from(s.width) * u64::from(s.height) * u64::from(spp),
    ));
    let all = rayon::current_num_threads();
    let mut threads = vec![1];
    if all > 1 {
        threads.push(all);
    }
    for n in threads {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("a rayon pool");
        group.bench_function(BenchmarkId::new("threads", n), |b| {
            b.iter(|| pool.install(|| render(&scene, camera, &s, &|_| {})))
        });
    }
    group.finish();
}

fn bench_load(c: &mut Criterion) {
    let path = scene_path("rainy_street.gltf");
    if let Err(e) = Scene::load(&path) {
        eprintln!("skipping the load bench: {e}");
        return;
    }
    let mut group = c.benchmark_group("scene_load");
    group.sample_size(10);
    group.bench_function("rainy_street", |b| {
        b.iter(|| Scene::load(black_box(&path)).map(|s| s.mesh.triangles.len()))
    });
    group.finish();
}

criterion_group!(benches, bench_render, bench_load);
criterion_main!(benches);
