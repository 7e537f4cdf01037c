//! Render regression tests, after Mitsuba 3's `test_renders.py`: a change in light transport is
//! caught inside `cargo test`, without the Python cross-check.
//!
//! For each [`RegressionCase`] (a shipped scene at a small size), a stored reference holds the
//! per-pixel mean of [`REFERENCE_RENDERS`] independent one-sample renders (seeds `0..M`) and the
//! per-pixel variance of one sample (their sample variance). A new render at `spp` samples with
//! another seed is compared channel by channel with a Z-test ([`Reference::z_test`]):
//! `z = |mean - reference| / sqrt(var / spp + var / M)` (the second term is the reference's own
//! noise), `p = 2 (1 - Phi(z))`, and the image passes when the smallest `p` is at least the
//! Sidak-corrected significance `1 - (1 - alpha)^(1 / n)` over its `n` values. Variances are
//! floored ([`VARIANCE_FLOOR`]) so that a pixel that is the same in every sample (a lamp seen
//! directly, the black sky) tolerates float rounding but nothing more.
//!
//! The test compares the means of small blocks of pixels (their variance is the pixels' summed
//! variance over the block size squared) rather than single pixels. The Z-test assumes that a
//! mean is nearly normal; on a night street a single pixel's mean is not, because rare bright
//! paths (a diffuse wall seen through a glossy road lit by a small lamp; a light-tree group
//! aimed beside its member) put one sample in thousands far above the rest, and one such
//! sample is a ten-sigma outlier of a pixel. Measured over 16 seeds: single pixels at 64 spp
//! failed on 9 (cross-check scene) and 11 (small street) of them, 4x4 blocks at 128 spp on none,
//! the largest z being 3.5 against a threshold of 4.3. The cases also stop at a small
//! `max_depth` (3 for the cross-check scene, 2 for the street) for the same reason.
//!
//! The new render uses quasi-random (Owen-scrambled Sobol) samples, whose error is at most the
//! independent samples' that the variance describes, so the test errs on the side of passing
//! a correct renderer; with fixed seeds it is deterministic. A bias of 3% or a missing bounce
//! fails it (tested).
//!
//! The references are made by `cargo run --release -p streaks-render --example
//! regression_references` (about a minute) and stored in [`REFERENCE_DIR`]; remake them only
//! when a change of the images is intended, and say so in the commit.

use crate::integrator::{render, Layers, RenderJob};
use crate::scene::{Scene, SceneError};
use glam::Vec3;
use statrs::distribution::{ContinuousCDF, Normal};
use std::fmt;
use std::path::{Path, PathBuf};
use streaks_image::exr::{read_exr_rgb_channels, write_exr};
use streaks_image::{ImageError, RgbImage};
use streaks_settings::RenderSettings;

/// How many one-sample renders make a reference.
pub const REFERENCE_RENDERS: u32 = 16384;

/// Smallest per-sample variance the test assumes, relative to the square of the reference
/// value, plus an absolute floor of `1e-12` (radiance units squared).
pub const VARIANCE_FLOOR: f32 = 1e-6;

/// The folder of the stored references, `crates/render/tests/references`.
pub const REFERENCE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/references");

/// The folder of the shipped scenes, `scenes/` at the top of the workspace.
pub const SCENE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");

/// One regression case: a shipped scene (its first camera) at a small size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegressionCase {
    /// The scene's file stem in [`SCENE_DIR`].
    pub scene: &'static str,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Mitsuba's `max_depth`.
    pub max_depth: u32,
}

/// The cases: the cross-check scene (GGX, spot and point lights, an emissive sphere), the small
/// wet street (textures, wet and dry patches, emitter meshes and punctual lights), and the
/// paper's Ward and Blinn-Phong planes.
pub const REGRESSION_CASES: [RegressionCase; 4] = [
    RegressionCase {
        scene: "crosscheck",
        width: 64,
        height: 48,
        max_depth: 3,
    },
    RegressionCase {
        scene: "rainy_street_small",
        width: 64,
        height: 36,
        max_depth: 2,
    },
    RegressionCase {
        scene: "paper_fig2_ward",
        width: 32,
        height: 64,
        max_depth: 3,
    },
    RegressionCase {
        scene: "paper_fig2_blinn_phong",
        width: 32,
        height: 64,
        max_depth: 3,
    },
];

/// The EXR channels of a reference: the mean, then the variance.
const CHANNELS: [&str; 6] = ["R", "G", "B", "var.R", "var.G", "var.B"];

impl RegressionCase {
    /// The scene file.
    pub fn scene_path(&self) -> PathBuf {
        Path::new(SCENE_DIR).join(format!("{}.gltf", self.scene))
    }

    /// The stored reference.
    pub fn reference_path(&self) -> PathBuf {
        Path::new(REFERENCE_DIR).join(format!("{}.exr", self.scene))
    }

    /// Loads the scene.
    pub fn load(&self) -> Result<Scene, SceneError> {
        Scene::load(&self.scene_path())
    }

    /// The case's image at `spp` samples with `seed`.
    pub fn job(&self, spp: u32, seed: u32) -> RenderJob {
        RenderJob {
            width: self.width,
            height: self.height,
            seed,
            layers: Layers::default(),
            settings: RenderSettings::new(spp, self.max_depth),
            motion: Default::default(),
        }
    }

    /// Renders the scene's first camera at `spp` samples with `seed`.
    pub fn render(&self, scene: &Scene, spp: u32, seed: u32) -> Result<RgbImage, SceneError> {
        let camera = scene.camera(None)?;
        Ok(render(scene, camera, &self.job(spp, seed), &|_| {}).image)
    }

    /// Makes the reference: the per-pixel mean and per-sample variance of
    /// [`REFERENCE_RENDERS`] one-sample renders with seeds `0..REFERENCE_RENDERS`.
    pub fn make_reference(&self, scene: &Scene) -> Result<Reference, SceneError> {
        let n = (self.width * self.height) as usize;
        let (mut sum, mut sum2) = (vec![[0f64; 3]; n], vec![[0f64; 3]; n]);
        for seed in 0..REFERENCE_RENDERS {
            let img = self.render(scene, 1, seed)?;
            for (i, p) in img.pixels.iter().enumerate() {
                for c in 0..3 {
                    let v = f64::from(p[c]);
                    sum[i][c] += v;
                    sum2[i][c] += v * v;
                }
            }
        }
        let m = f64::from(REFERENCE_RENDERS);
        let (mut mean, mut var) = (
            RgbImage::new(self.width, self.height),
            RgbImage::new(self.width, self.height),
        );
        for i in 0..n {
            for c in 0..3 {
                let mu = sum[i][c] / m;
                mean.pixels[i][c] = mu as f32;
                var.pixels[i][c] = ((sum2[i][c] - m * mu * mu) / (m - 1.0)).max(0.0) as f32;
            }
        }
        Ok(Reference { mean, var })
    }
}

/// A reference: per-pixel mean and per-sample variance.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// Mean of [`REFERENCE_RENDERS`] samples per pixel.
    pub mean: RgbImage,
    /// Variance of one sample per pixel.
    pub var: RgbImage,
}

impl Reference {
    /// Writes it as one EXR (`R`, `G`, `B`: the mean; `var.R`, `var.G`, `var.B`: the variance).
    pub fn save(&self, path: &Path) -> Result<(), ImageError> {
        let planes = (0..3)
            .map(|c| self.mean.plane(c))
            .chain((0..3).map(|c| self.var.plane(c)));
        let channels = CHANNELS.into_iter().zip(planes).collect();
        write_exr(path, self.mean.width, self.mean.height, channels)
    }

    /// Reads one written by [`Reference::save`].
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let [r, g, b, vr, vg, vb] = CHANNELS;
        Ok(Self {
            mean: read_exr_rgb_channels(path, [r, g, b])?,
            var: read_exr_rgb_channels(path, [vr, vg, vb])?,
        })
    }

    /// The Z-test (see the module documentation) of `image`, rendered with `spp` samples per
    /// pixel, on the means of `block` x `block` pixel blocks (1: every pixel), at significance
    /// `alpha` (before the Sidak correction).
    pub fn z_test(&self, image: &RgbImage, spp: u32, block: u32, alpha: f64) -> ZTest {
        assert_eq!(
            (image.width, image.height),
            (self.mean.width, self.mean.height),
            "the image and the reference differ in size"
        );
        let (w, h, b) = (image.width, image.height, block.max(1));
        let (bw, bh) = (w.div_ceil(b), h.div_ceil(b));
        let threshold = 1.0 - (1.0 - alpha).powf(1.0 / f64::from(3 * bw * bh));
        let normal = Normal::standard();
        let inverse_counts = 1.0 / f64::from(spp) + 1.0 / f64::from(REFERENCE_RENDERS);
        let mut worst = ZTest {
            p: 1.0,
            threshold,
            z: 0.0,
            pixel: (0, 0),
            block: b,
            channel: 0,
            value: 0.0,
            reference: 0.0,
            passed: true,
        };
        for (by, bx) in (0..bh).flat_map(|by| (0..bw).map(move |bx| (by, bx))) {
            let (x0, y0) = (bx * b, by * b);
            for c in 0..3 {
                let (mut x, mut mu, mut var, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
                for y in y0..(y0 + b).min(h) {
                    for px in x0..(x0 + b).min(w) {
                        let i = (y * w + px) as usize;
                        let r = f64::from(self.mean.pixels[i][c]);
                        let floor = f64::from(VARIANCE_FLOOR) * r * r + 1e-12;
                        x += f64::from(image.pixels[i][c]);
                        mu += r;
                        var += f64::from(self.var.pixels[i][c]).max(floor);
                        n += 1.0;
                    }
                }
                // Block means; the variance of a block mean is the pixels' sum over n^2.
                let (x, mu) = (x / n, mu / n);
                let z = (x - mu).abs() / ((var / (n * n)) * inverse_counts).sqrt();
                // p = 2 (1 - Phi(z)), without cancellation in the tail; NaN fails.
                let p_value = if z.is_nan() {
                    0.0
                } else {
                    2.0 * normal.cdf(-z)
                };
                if p_value < worst.p {
                    worst = ZTest {
                        p: p_value,
                        z,
                        pixel: (x0, y0),
                        channel: c,
                        value: x,
                        reference: mu,
                        ..worst
                    };
                }
            }
        }
        worst.passed = worst.p >= threshold;
        worst
    }
}

/// The outcome of [`Reference::z_test`]: its least likely value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZTest {
    /// The smallest p-value over all pixels and channels.
    pub p: f64,
    /// The Sidak-corrected significance it must reach.
    pub threshold: f64,
    /// Its z statistic.
    pub z: f64,
    /// Its block's first pixel.
    pub pixel: (u32, u32),
    /// The block size.
    pub block: u32,
    /// Its channel.
    pub channel: usize,
    /// The rendered value.
    pub value: f64,
    /// The reference value.
    pub reference: f64,
    /// Whether `p >= threshold`.
    pub passed: bool,
}

impl fmt::Display for ZTest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: smallest p-value {:.3e} (threshold {:.3e}) in the {}x{} block at {:?}, channel \
             {}: {:.6e} against the reference {:.6e} (z = {:.2})",
            if self.passed { "passed" } else { "FAILED" },
            self.p,
            self.threshold,
            self.block,
            self.block,
            self.pixel,
            self.channel,
            self.value,
            self.reference,
            self.z
        )
    }
}

/// The mean radiance of an image (all pixels and channels), for messages.
pub fn mean_radiance(image: &RgbImage) -> f64 {
    let sum: Vec3 = image.pixels.iter().copied().sum();
    f64::from(sum.x + sum.y + sum.z) / (3 * image.pixels.len().max(1)) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// A synthetic reference of mean 1 and per-sample variance `sd^2`, and images of `spp`
    /// independent samples with mean `scale`.
    #[test]
    fn the_z_test_passes_noise_and_fails_bias() {
        let block = 1;
        let (w, h, sd, spp) = (32u32, 16u32, 0.5f32, 16u32);
        let reference = Reference {
            mean: RgbImage {
                pixels: vec![Vec3::ONE; (w * h) as usize],
                ..RgbImage::new(w, h)
            },
            var: RgbImage {
                pixels: vec![Vec3::splat(sd * sd); (w * h) as usize],
                ..RgbImage::new(w, h)
            },
        };
        let mut rng = Pcg32::new(3, 5);
        let mut image = |scale: f32| {
            let mut img = RgbImage::new(w, h);
            for p in &mut img.pixels {
                for c in 0..3 {
                    // The mean of `spp` uniform samples of variance sd^2.
                    let s: f32 = (0..spp).map(|_| rng.next_f32() - 0.5).sum::<f32>() / spp as f32;
                    p[c] = scale + s * sd * 12f32.sqrt();
                }
            }
            img
        };
        let unbiased = image(1.0);
        for block in [1, 2, 4] {
            let t = reference.z_test(&unbiased, spp, block, 0.01);
            assert!(t.passed, "{t}");
        }
        // A 10% bias is 0.1 / (0.5 / 4) = 0.8 standard errors of a pixel, 3.2 of a 4x4 block
        // (then the largest of 96 block values is beyond the corrected threshold); a 30% bias
        // is 2.4 standard errors of a pixel.
        let biased = image(1.1);
        assert!(!reference.z_test(&biased, spp, 4, 0.01).passed);
        let t = reference.z_test(&image(1.3), spp, 1, 0.01);
        assert!(!t.passed, "{t}");
        // One broken pixel fails the test; a NaN fails it.
        let mut one = image(1.0);
        one.pixels[17].y = 4.0;
        let t = reference.z_test(&one, spp, block, 0.01);
        assert!(!t.passed && t.pixel == (17, 0) && t.channel == 1, "{t}");
        one.pixels[17].y = f32::NAN;
        assert!(!reference.z_test(&one, spp, block, 0.01).passed);
    }

    #[test]
    fn a_noiseless_pixel_tolerates_rounding_only() {
        let reference = Reference {
            mean: RgbImage {
                pixels: vec![Vec3::splat(2.0)],
                ..RgbImage::new(1, 1)
            },
            var: RgbImage::new(1, 1),
        };
        let img = |v: f32| RgbImage {
            pixels: vec![Vec3::splat(v)],
            ..RgbImage::new(1, 1)
        };
        assert!(reference.z_test(&img(2.0), 4, 1, 0.01).passed);
        assert!(
            reference
                .z_test(&img(2.0 * (1.0 + 1e-6)), 4, 1, 0.01)
                .passed
        );
        assert!(!reference.z_test(&img(2.0 * 1.01), 4, 1, 0.01).passed);
    }

    #[test]
    fn references_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.exr");
        let reference = Reference {
            mean: RgbImage {
                pixels: vec![Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO],
                ..RgbImage::new(2, 1)
            },
            var: RgbImage {
                pixels: vec![Vec3::new(0.5, 0.25, 0.125), Vec3::ONE],
                ..RgbImage::new(2, 1)
            },
        };
        reference.save(&path).unwrap();
        assert_eq!(Reference::load(&path).unwrap(), reference);
    }
}
