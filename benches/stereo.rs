//! Stereo estimator benchmarks, per megapixel: 1D Lucas-Kanade along rows (one estimate per
//! pixel: every pixel of the image is a `(row, x)` centre) and semi-global matching (dense
//! disparity, default parameters: 64 disparities, census 7x7, 8 paths, sub-pixel, left-right
//! check and median), both from `streaks-analysis`, on a synthetic textured 640x480 pair, and the
//! streak-robust pass on SGM's map (`robust_disparity` with the shipped model: its features,
//! both classifiers' trees at every pixel and the fill).
//!
//! Run: `cargo bench --bench stereo`. Throughput is in pixels per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use streaks_analysis::lk::{lk_rows, LkParams};
use streaks_analysis::repair::{robust_disparity, RepairModel, StreakHandling};
use streaks_analysis::sgm::{sgm, SgmParams};
use streaks_analysis::synth::SynthScene;

const WIDTH: usize = 640;
const HEIGHT: usize = 480;

fn bench_estimators(c: &mut Criterion) {
    let pair = SynthScene::textured(WIDTH, HEIGHT, 3)
        .render()
        .expect("the synthetic pair renders in memory");
    let mut group = c.benchmark_group("stereo_640x480");
    group.sample_size(10);
    group.throughput(Throughput::Elements((WIDTH * HEIGHT) as u64));

    let lk = LkParams::default();
    let centres: Vec<(usize, f32)> = (0..HEIGHT)
        .flat_map(|y| (0..WIDTH).map(move |x| (y, x as f32 + 0.5)))
        .collect();
    group.bench_function("lk_rows_every_pixel", |b| {
        b.iter(|| {
            lk_rows(black_box(&pair.left), black_box(&pair.right), &centres, &lk).map(|d| d.len())
        })
    });

    let params = SgmParams::default();
    group.bench_function("sgm_dense", |b| {
        b.iter(|| sgm(black_box(&pair.left), black_box(&pair.right), &params).map(|d| d.width))
    });

    let disp = sgm(&pair.left, &pair.right, &params).expect("SGM of the synthetic pair");
    let model = RepairModel::shipped();
    group.bench_function("streak_repair_after_sgm", |b| {
        b.iter(|| {
            robust_disparity(
                black_box(&pair.left),
                black_box(&pair.right),
                black_box(&disp),
                StreakHandling::Repair,
                model,
            )
            .map(|r| r.repaired_pixels)
        })
    });
    group.finish();
}

criterion_group!(benches, bench_estimators);
criterion_main!(benches);
