//! The sensor on a 1280x720 render: the PSF by FFT and the noise (automotive_linear), and the
//! noise alone (no PSF).

use criterion::{criterion_group, criterion_main, Criterion};
use glam::Vec3;
use streaks_image::RgbImage;
use streaks_sensor::{capture, SensorProfile};

fn bench(c: &mut Criterion) {
    let img = RgbImage::from_fn(1280, 720, |x, y| {
        let lamp = (x / 40 + y / 40) % 9 == 0;
        Vec3::splat(if lamp {
            50.0
        } else {
            0.002 + 1e-5 * (x + y) as f32
        })
    });
    let profile = SensorProfile::preset("automotive_linear").unwrap();
    let mut g = c.benchmark_group("sensor");
    g.sample_size(10);
    g.bench_function("capture_1280x720", |b| {
        b.iter(|| capture(&profile, &img, 1000.0, 0.0, 1).unwrap())
    });
    let noise_only = SensorProfile {
        veil: 0.0,
        diffraction: false,
        ..profile.clone()
    };
    g.bench_function("noise_1280x720", |b| {
        b.iter(|| capture(&noise_only, &img, 1000.0, 0.0, 1).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
