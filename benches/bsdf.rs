//! BSDF benchmarks: each model's `sample`, `eval` and `pdf` on a batch of fixed random
//! directions, the light choice that weighs emitters by each model's BSDF in SIMD lanes
//! (`LightSampler::sample_li` on `rainy_street`'s road), and the closed-enum dispatch of [`Bsdf`] against
//! a trait-object version of the same calls (docs/design.md chooses the enum; this
//! measures the choice).
//!
//! The Owen-scrambled Sobol sampler's `next_1d` and `next_2d` are measured here too.
//!
//! Run: `cargo bench --bench bsdf`. Throughput is reported in calls per second.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::{Vec2, Vec3};
use std::hint::black_box;
use std::path::Path;
use streaks_render::bsdf::{
    BlinnPhong, Bsdf, BsdfSample, Diffuse, Ggx, GltfPbr, Retroreflective, Ward,
};
use streaks_render::geometry::Frame;
use streaks_render::light::Receiver;
use streaks_render::sampling::{square_to_cosine_hemisphere, Pcg32, Sampler};
use streaks_render::scene::Scene;

/// Calls per iteration: large enough to hide the loop, small enough to stay in L1.
const BATCH: usize = 1024;

/// One call's inputs: `wo`, `wi` (both above the surface), the lobe number and the 2D sample.
#[derive(Clone, Copy)]
struct Input {
    wo: Vec3,
    wi: Vec3,
    u_lobe: f32,
    u: Vec2,
}

/// `BATCH` inputs from a fixed seed; directions cosine-distributed, like a path tracer's.
fn inputs(seed: u64) -> Vec<Input> {
    let mut rng = Pcg32::new(seed, 7);
    (0..BATCH)
        .map(|_| Input {
            wo: square_to_cosine_hemisphere(rng.next_2d()),
            wi: square_to_cosine_hemisphere(rng.next_2d()),
            u_lobe: rng.next_f32(),
            u: rng.next_2d(),
        })
        .collect()
}

/// A wet-road-like parameter set for every model.
fn models() -> Vec<(&'static str, Bsdf)> {
    let kd = Vec3::splat(0.05);
    let ks = Vec3::splat(0.6);
    vec![
        (
            "diffuse",
            Bsdf::Diffuse(Diffuse {
                kd: Vec3::splat(0.5),
            }),
        ),
        ("ggx", Bsdf::Ggx(Ggx { kd, ks, alpha: 0.1 })),
        ("ward", Bsdf::Ward(Ward { kd, ks, alpha: 0.1 })),
        (
            "blinn_phong",
            Bsdf::BlinnPhong(BlinnPhong {
                kd,
                ks,
                shininess: 200.0,
            }),
        ),
        (
            "gltf_pbr",
            Bsdf::GltfPbr(GltfPbr {
                base_color: Vec3::new(0.3, 0.3, 0.35),
                metallic: 0.0,
                roughness: 0.3,
                ..GltfPbr::default()
            }),
        ),
    ]
}

fn bench_models(c: &mut Criterion) {
    let input = inputs(1);
    let mut group = c.benchmark_group("bsdf");
    group.throughput(Throughput::Elements(BATCH as u64));
    for (name, bsdf) in models() {
        group.bench_with_input(BenchmarkId::new("sample", name), &bsdf, |b, bsdf| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for i in &input {
                    if let Some(s) = black_box(bsdf).sample(i.wo, i.u_lobe, i.u) {
                        acc += s.pdf + s.f.x;
                    }
                }
                acc
            })
        });
        group.bench_with_input(BenchmarkId::new("eval", name), &bsdf, |b, bsdf| {
            b.iter(|| {
                let mut acc = Vec3::ZERO;
                for i in &input {
                    acc += black_box(bsdf).eval(i.wo, i.wi);
                }
                acc
            })
        });
        group.bench_with_input(BenchmarkId::new("pdf", name), &bsdf, |b, bsdf| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for i in &input {
                    acc += black_box(bsdf).pdf(i.wo, i.wi);
                }
                acc
            })
        });
    }
    group.finish();
}

/// The light choice as the integrator makes it (`LightSampler::sample_li`: down the light
/// tree, each node's children weighed by irradiance and by the BSDF toward them in SIMD lanes,
/// then a sample of the chosen emitter) at [`BATCH`] points of `rainy_street`'s road (142
/// emitters, a two-level tree), for every model. The lanes' width is the process's
/// (`streaks_render::simd::level`): compare widths with `STREAKS_SIMD=sse|avx2|avx512 cargo
/// bench --bench bsdf -- light_choice`.
fn bench_light_choice(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rainy_street.gltf");
    let scene = match Scene::load(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("skipping the light-choice bench: {e}");
            return;
        }
    };
    let mut rng = Pcg32::new(4, 7);
    // Road points ahead of the camera, seen from the driver's height.
    let points: Vec<(Vec3, Vec3, [f32; 3])> = (0..BATCH)
        .map(|_| {
            let p = Vec3::new(
                rng.next_f32() * 8.0 - 4.0,
                0.0,
                -2.0 - rng.next_f32() * 40.0,
            );
            let wo = (Vec3::new(0.0, 1.3, 0.0) - p).normalize();
            (p, wo, [rng.next_f32(), rng.next_f32(), rng.next_f32()])
        })
        .collect();
    let frame = Frame::from_normal(Vec3::Y);
    let mut group = c.benchmark_group("light_choice");
    group.throughput(Throughput::Elements(BATCH as u64));
    let level = streaks_render::simd::level().name();
    for (name, bsdf) in models() {
        group.bench_with_input(BenchmarkId::new(level, name), &bsdf, |b, bsdf| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for &(p, wo, [u_light, u0, u1]) in &points {
                    let rx = Receiver {
                        p,
                        ng: Vec3::Y,
                        frame,
                        wo_local: frame.to_local(wo),
                        bsdf: *black_box(bsdf),
                    };
                    let ls = scene.light_sampler.sample_li(
                        &scene.materials,
                        &scene.textures,
                        &rx,
                        u_light,
                        Vec2::new(u0, u1),
                    );
                    acc += ls.map_or(0.0, |s| s.pdf);
                }
                acc
            })
        });
    }
    group.finish();
}

// ---------------------------------------------------------------------------------------------
// Enum against trait objects

/// The hot BSDF calls as an object-safe trait: what the renderer would look like with
/// `Box<dyn BsdfDyn>` materials instead of the closed enum.
trait BsdfDyn {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3;
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample>;
}

/// Implements [`BsdfDyn`] for one model by wrapping it in its enum variant. The variant is a
/// constant inside each impl, so after inlining the `match` folds away and the only dispatch
/// left is the virtual call: exactly the cost a trait-object design pays.
macro_rules! dyn_model {
    ($ty:ident) => {
        impl BsdfDyn for $ty {
            #[inline]
            fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
                Bsdf::$ty(*self).eval(wo, wi)
            }
            #[inline]
            fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                Bsdf::$ty(*self).pdf(wo, wi)
            }
            #[inline]
            fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
                Bsdf::$ty(*self).sample(wo, u_lobe, u)
            }
        }
    };
}
dyn_model!(Diffuse);
dyn_model!(Ggx);
dyn_model!(Ward);
dyn_model!(BlinnPhong);
dyn_model!(GltfPbr);
dyn_model!(Retroreflective);

fn boxed(bsdf: Bsdf) -> Box<dyn BsdfDyn> {
    match bsdf {
        Bsdf::Diffuse(m) => Box::new(m),
        Bsdf::Ggx(m) => Box::new(m),
        Bsdf::Ward(m) => Box::new(m),
        Bsdf::BlinnPhong(m) => Box::new(m),
        Bsdf::GltfPbr(m) => Box::new(m),
        Bsdf::Retroreflective(m) => Box::new(m),
    }
}

/// The same work as a path tracer's shading step: sample a direction, evaluate light
/// sampling's direction and its pdf (NEE with MIS needs all three).
#[inline]
fn shade_enum(bsdf: &Bsdf, i: &Input) -> f32 {
    let mut acc = bsdf.eval(i.wo, i.wi).x + bsdf.pdf(i.wo, i.wi);
    if let Some(s) = bsdf.sample(i.wo, i.u_lobe, i.u) {
        acc += s.f.x / s.pdf;
    }
    acc
}

#[inline]
fn shade_dyn(bsdf: &dyn BsdfDyn, i: &Input) -> f32 {
    let mut acc = bsdf.eval(i.wo, i.wi).x + bsdf.pdf(i.wo, i.wi);
    if let Some(s) = bsdf.sample(i.wo, i.u_lobe, i.u) {
        acc += s.f.x / s.pdf;
    }
    acc
}

fn bench_dispatch(c: &mut Criterion) {
    let input = inputs(2);
    let all: Vec<Bsdf> = models().into_iter().map(|(_, m)| m).collect();
    // Two material sequences: one model throughout (a road-filling frame: the branch predictor
    // always wins), and a random model per call (incoherent bounces hitting everything).
    let mut rng = Pcg32::new(3, 1);
    let mixed: Vec<Bsdf> = (0..BATCH)
        .map(|_| all[(rng.next_u32() as usize) % all.len()])
        .collect();
    let uniform: Vec<Bsdf> = vec![all[1]; BATCH];
    let mut group = c.benchmark_group("dispatch");
    group.throughput(Throughput::Elements(BATCH as u64));
    for (name, seq) in [("one_model", &uniform), ("mixed_models", &mixed)] {
        // The enum is stored inline in the material array, as the renderer stores it.
        group.bench_with_input(BenchmarkId::new("enum", name), seq, |b, seq| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for (bsdf, i) in seq.iter().zip(&input) {
                    acc += shade_enum(black_box(bsdf), i);
                }
                acc
            })
        });
        let objects: Vec<Box<dyn BsdfDyn>> = seq.iter().map(|m| boxed(*m)).collect();
        group.bench_with_input(
            BenchmarkId::new("trait_object", name),
            &objects,
            |b, seq| {
                b.iter(|| {
                    let mut acc = 0.0f32;
                    for (bsdf, i) in seq.iter().zip(&input) {
                        acc += shade_dyn(black_box(bsdf.as_ref()), i);
                    }
                    acc
                })
            },
        );
    }
    group.finish();
}

/// The sampler's per-dimension cost: one pixel sample drawing `BATCH` dimensions (a path
/// tracer draws about 2 + 5 per bounce).
fn bench_sampler(c: &mut Criterion) {
    let mut group = c.benchmark_group("sampler");
    group.throughput(Throughput::Elements(BATCH as u64));
    let mut sampler = Sampler::new(1);
    group.bench_function("next_2d", |b| {
        let mut index = 0u32;
        b.iter(|| {
            index = (index + 1) % 1024;
            sampler.start_pixel_sample((index, 7), index);
            let mut acc = Vec2::ZERO;
            for _ in 0..BATCH {
                acc += sampler.next_2d();
            }
            acc
        })
    });
    group.bench_function("next_4d", |b| {
        let mut index = 0u32;
        b.iter(|| {
            index = (index + 1) % 1024;
            sampler.start_pixel_sample((index, 7), index);
            let mut acc = [0.0f32; 4];
            for _ in 0..BATCH {
                let v = sampler.next_4d();
                for (a, x) in acc.iter_mut().zip(v) {
                    *a += x;
                }
            }
            acc
        })
    });
    group.bench_function("next_1d", |b| {
        let mut index = 0u32;
        b.iter(|| {
            index = (index + 1) % 1024;
            sampler.start_pixel_sample((index, 7), index);
            let mut acc = 0.0f32;
            for _ in 0..BATCH {
                acc += sampler.next_1d();
            }
            acc
        })
    });
    group.finish();
}

criterion_group!(
    benches,
    bench_models,
    bench_light_choice,
    bench_dispatch,
    bench_sampler
);
criterion_main!(benches);
