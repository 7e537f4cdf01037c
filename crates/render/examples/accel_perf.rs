//! Measures the BVH on a random soup: build time, BVH memory, and single-threaded closest-hit
//! rays per second for random incoherent rays. Run in release, under `/usr/bin/time -v` for the
//! peak resident memory:
//!
//! ```text
//! cargo run --release -p streaks-render --example accel_perf -- 1000000 1000000
//! ```

use glam::Vec3;
use std::time::Instant;
use streaks_render::geometry::Ray;
use streaks_render::material::Material;
use streaks_render::scene::{Scene, SceneParts};

/// SplitMix64 mapped to [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn vec(&mut self, scale: f32) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * 2.0 * scale - scale
    }
}

/// CPU time of the calling thread in seconds (Linux `/proc`; 10 ms resolution), so that the
/// figures mean something on a loaded machine.
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n_tris: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let n_rays: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let mut rng = Rng(1);
    // Triangles of edge ~0.5 in a cube of half-size 50 (about 1% covered along a ray).
    let mut parts = SceneParts {
        source: "soup".into(),
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        ..SceneParts::default()
    };
    for i in 0..n_tris {
        let c = rng.vec(50.0);
        for _ in 0..3 {
            parts.positions.push(c + rng.vec(0.5));
        }
        let k = 3 * i as u32;
        parts.triangles.push([k, k + 1, k + 2]);
        parts.triangle_materials.push(0);
    }
    let start = Instant::now();
    let scene = Scene::from_parts(parts).expect("valid soup");
    let build = start.elapsed();
    println!(
        "{n_tris} triangles: from_parts (BVH build included) {:.3} s on {} threads, BVH + triangle copies {:.1} MiB",
        build.as_secs_f64(),
        rayon::current_num_threads(),
        scene.accel.memory_bytes() as f64 / (1 << 20) as f64
    );
    let rays: Vec<Ray> = (0..n_rays)
        .map(|_| Ray::new(rng.vec(50.0), rng.vec(1.0).normalize()))
        .collect();
    let start = Instant::now();
    let cpu = thread_cpu_seconds();
    let mut hits = 0usize;
    for r in &rays {
        hits += usize::from(scene.intersect(r).is_some());
    }
    let t = start.elapsed().as_secs_f64();
    let c = cpu.zip(thread_cpu_seconds()).map_or(t, |(a, b)| b - a);
    println!(
        "closest hit: {n_rays} random rays, {t:.3} s wall, {c:.2} s CPU = {:.2} Mrays/s per CPU-second ({:.1}% hit)",
        n_rays as f64 / c / 1e6,
        100.0 * hits as f64 / n_rays as f64
    );
    let start = Instant::now();
    let cpu = thread_cpu_seconds();
    let mut occluded = 0usize;
    for r in &rays {
        occluded += usize::from(scene.occluded(r));
    }
    let t = start.elapsed().as_secs_f64();
    let c = cpu.zip(thread_cpu_seconds()).map_or(t, |(a, b)| b - a);
    println!(
        "any hit: {t:.3} s wall, {c:.2} s CPU = {:.2} Mrays/s per CPU-second ({occluded} occluded)",
        n_rays as f64 / c / 1e6
    );
}
