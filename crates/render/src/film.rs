//! The film: per-pixel accumulation with a box pixel filter.
//!
//! Each sample's film position is uniform in its own pixel (pixel `(i, j)` covers
//! `[i, i+1) x [j, j+1)`), and a pixel's value is the mean of its kept samples: the box filter,
//! as Mitsuba's `box` rfilter. Samples never land in a neighbour, so rows can be filled in
//! parallel with no synchronisation, and the memory per pixel is a fixed-size [`Pixel`]
//! whatever the sample count.
//!
//! A sample whose radiance (or specular part) is NaN or infinite is dropped and counted,
//! never accumulated (docs/design.md).
//!
//! For adaptive sampling ([`crate::integrator::RenderSettings::noise_target`]) each pixel also
//! keeps the running mean and sum of squared deviations of its kept samples' luminance
//! (Welford's update: two `f32`s, no allocation, stable where a running sum of squares would
//! cancel), from which [`Pixel::mean_variance`] estimates the variance of the pixel's mean; the
//! integrator pools these over a tile of pixels. These statistics never enter the image: the
//! beauty and specular sums are accumulated exactly as without them.

use glam::Vec3;
use streaks_image::color::luminance;
use streaks_image::RgbImage;

/// One pixel's accumulators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pixel {
    /// Sum of the kept samples' radiance.
    pub radiance: Vec3,
    /// Sum of the kept samples' specular part (see [`crate::integrator`]).
    pub specular: Vec3,
    /// Sum of the kept samples' light seen directly: emission or the environment met by the
    /// camera ray's first segment (see [`crate::integrator`]).
    pub emission: Vec3,
    /// Number of kept samples.
    pub kept: u32,
    /// Number of dropped (non-finite) samples.
    pub dropped: u32,
    /// Running mean of the kept samples' luminance (Welford).
    pub lum_mean: f32,
    /// Running sum of the squared deviations of the kept samples' luminance from their mean
    /// (Welford's `M2`; the sample variance is `M2 / (kept - 1)`).
    pub lum_m2: f32,
    /// Camera-space depth of the pixel-centre ray's first hit (`inf` on a miss).
    pub depth: f32,
    /// First-hit shading normal (world space, facing the camera; zero on a miss).
    pub normal: Vec3,
    /// First-hit BSDF albedo (zero on a miss).
    pub albedo: Vec3,
    /// Index into the scene's materials of the pixel-centre ray's first hit ([`NO_MATERIAL`]
    /// on a miss).
    pub material: u32,
    /// The slot in the scene's objects ([`crate::scene::Scene::objects`]) of the pixel-centre
    /// ray's first hit ([`crate::scene::SKY_OBJECT`] on a miss).
    pub object: u32,
    /// Sum over the camera samples (kept or dropped) of the share of the shutter during which
    /// the sample's ray met a rain drop first (1 or 0 for a sample taken at one time).
    pub rain: f32,
    /// Luminance of the fog's transmittance from the camera to the pixel-centre ray's first
    /// hit (to the sky on a miss; 1 without fog).
    pub fog: f32,
}

/// [`Pixel::material`] of a pixel whose centre ray hits nothing.
pub const NO_MATERIAL: u32 = u32::MAX;

impl Default for Pixel {
    fn default() -> Self {
        Self {
            radiance: Vec3::ZERO,
            specular: Vec3::ZERO,
            emission: Vec3::ZERO,
            kept: 0,
            dropped: 0,
            lum_mean: 0.0,
            lum_m2: 0.0,
            depth: f32::INFINITY,
            normal: Vec3::ZERO,
            albedo: Vec3::ZERO,
            material: NO_MATERIAL,
            object: crate::scene::SKY_OBJECT,
            rain: 0.0,
            fog: 1.0,
        }
    }
}

impl Pixel {
    /// Adds one sample; returns `false` (and counts it as dropped) if any value is not finite.
    #[inline]
    pub fn add_sample(&mut self, radiance: Vec3, specular: Vec3) -> bool {
        if radiance.is_finite() && specular.is_finite() {
            self.radiance += radiance;
            self.specular += specular;
            self.kept += 1;
            let l = luminance(radiance);
            let delta = l - self.lum_mean;
            self.lum_mean += delta / self.kept as f32;
            self.lum_m2 += delta * (l - self.lum_mean);
            true
        } else {
            self.dropped += 1;
            false
        }
    }

    /// The box-filtered radiance (zero if no sample was kept).
    #[inline]
    pub fn mean_radiance(&self) -> Vec3 {
        if self.kept == 0 {
            Vec3::ZERO
        } else {
            self.radiance / self.kept as f32
        }
    }

    /// Samples taken: kept plus dropped (the samples-per-pixel layer).
    #[inline]
    pub fn taken(&self) -> u32 {
        self.kept + self.dropped
    }

    /// Estimated variance of the pixel's mean luminance, `s^2 / n` over its `n` kept samples
    /// (`s^2` the sample variance); `None` with fewer than two kept samples (no estimate yet).
    #[inline]
    pub fn mean_variance(&self) -> Option<f32> {
        if self.kept < 2 {
            return None;
        }
        let n = self.kept as f32;
        Some((self.lum_m2 / (n - 1.0)).max(0.0) / n)
    }

    /// The box-filtered specular part.
    #[inline]
    pub fn mean_specular(&self) -> Vec3 {
        if self.kept == 0 {
            Vec3::ZERO
        } else {
            self.specular / self.kept as f32
        }
    }

    /// The box-filtered light seen directly.
    #[inline]
    pub fn mean_emission(&self) -> Vec3 {
        if self.kept == 0 {
            Vec3::ZERO
        } else {
            self.emission / self.kept as f32
        }
    }
}

/// A `width` x `height` grid of [`Pixel`]s, row-major, top row first.
#[derive(Clone, Debug)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The pixels.
    pub pixels: Vec<Pixel>,
}

impl Film {
    /// An empty film.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Pixel::default(); width as usize * height as usize],
        }
    }

    /// Mutable rows (each `width` pixels long), for filling them in parallel.
    pub fn par_rows_mut(&mut self) -> rayon::slice::ChunksExactMut<'_, Pixel> {
        use rayon::slice::ParallelSliceMut;
        self.pixels.par_chunks_exact_mut(self.width.max(1) as usize)
    }

    /// Mutable bands of `rows` full rows each (the last one may be shorter), for filling
    /// them in parallel.
    pub fn par_bands_mut(&mut self, rows: u32) -> rayon::slice::ChunksMut<'_, Pixel> {
        use rayon::slice::ParallelSliceMut;
        let len = self.width.max(1) as usize * rows.max(1) as usize;
        self.pixels.par_chunks_mut(len)
    }

    fn map(&self, f: impl Fn(&Pixel) -> Vec3) -> RgbImage {
        RgbImage {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        }
    }

    /// The box-filtered beauty image.
    pub fn image(&self) -> RgbImage {
        self.map(Pixel::mean_radiance)
    }

    /// The box-filtered specular layer.
    pub fn specular(&self) -> RgbImage {
        self.map(Pixel::mean_specular)
    }

    /// The box-filtered layer of the light seen directly.
    pub fn emission(&self) -> RgbImage {
        self.map(Pixel::mean_emission)
    }

    /// The normal layer.
    pub fn normal(&self) -> RgbImage {
        self.map(|p| p.normal)
    }

    /// The albedo layer.
    pub fn albedo(&self) -> RgbImage {
        self.map(|p| p.albedo)
    }

    /// The depth layer.
    pub fn depth(&self) -> Vec<f32> {
        self.pixels.iter().map(|p| p.depth).collect()
    }

    /// The first-hit material layer ([`NO_MATERIAL`] on a miss).
    pub fn material(&self) -> Vec<u32> {
        self.pixels.iter().map(|p| p.material).collect()
    }

    /// The first-hit object layer ([`crate::scene::SKY_OBJECT`] on a miss).
    pub fn object(&self) -> Vec<u32> {
        self.pixels.iter().map(|p| p.object).collect()
    }

    /// The fog layer: the fog's transmittance to the pixel-centre ray's first hit, row-major.
    pub fn fog(&self) -> Vec<f32> {
        self.pixels.iter().map(|p| p.fog).collect()
    }

    /// The samples-per-pixel layer: samples taken per pixel (kept and dropped), row-major.
    pub fn spp(&self) -> Vec<u32> {
        self.pixels.iter().map(Pixel::taken).collect()
    }

    /// The rain layer: the mean over each pixel's samples (kept and dropped) of the share of
    /// the shutter during which the first hit was a rain drop, row-major (0 for a pixel
    /// without samples).
    pub fn rain(&self) -> Vec<f32> {
        self.pixels
            .iter()
            .map(|p| p.rain / p.taken().max(1) as f32)
            .collect()
    }

    /// Total number of samples taken (kept and dropped).
    pub fn samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.taken() as u64).sum()
    }

    /// Total number of dropped samples.
    pub fn dropped(&self) -> u64 {
        self.pixels.iter().map(|p| p.dropped as u64).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The memory per pixel that docs/benchmarks.md gives ("Targets").
    #[test]
    fn a_pixel_is_96_bytes() {
        assert_eq!(std::mem::size_of::<Pixel>(), 96);
    }

    #[test]
    fn box_filter_means_kept_samples_and_drops_non_finite() {
        let mut film = Film::new(3, 2);
        {
            use rayon::iter::{IndexedParallelIterator, ParallelIterator};
            assert_eq!(film.par_rows_mut().len(), 2);
            film.par_rows_mut().enumerate().for_each(|(y, row)| {
                assert_eq!(row.len(), 3);
                if y == 0 {
                    assert!(row[1].add_sample(Vec3::splat(1.0), Vec3::ZERO));
                    assert!(row[1].add_sample(Vec3::splat(3.0), Vec3::X));
                    assert!(!row[1].add_sample(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ZERO));
                    assert!(!row[1].add_sample(Vec3::ONE, Vec3::splat(f32::INFINITY)));
                } else {
                    assert!(!row[2].add_sample(Vec3::splat(f32::NEG_INFINITY), Vec3::ZERO));
                }
            });
        }
        let img = film.image();
        assert_eq!(img.get(1, 0), Vec3::splat(2.0));
        assert_eq!(film.specular().get(1, 0), Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(img.get(2, 1), Vec3::ZERO);
        assert_eq!(film.dropped(), 3);
        assert!(img.pixels.iter().all(|p| p.is_finite()));
        assert_eq!(film.depth()[0], f32::INFINITY);
        assert_eq!(film.material(), vec![NO_MATERIAL; 6]);
        assert_eq!(film.object(), vec![crate::scene::SKY_OBJECT; 6]);
        assert_eq!(film.spp(), vec![0, 4, 0, 0, 0, 1]);
        assert_eq!(film.samples(), 5);
    }

    #[test]
    fn welford_statistics_give_the_variance_of_the_mean() {
        let mut p = Pixel::default();
        assert_eq!(p.mean_variance(), None);
        assert!(p.add_sample(Vec3::splat(7.0), Vec3::ZERO));
        assert_eq!(
            p.mean_variance(),
            None,
            "one sample has no variance estimate"
        );
        let mut p = Pixel::default();
        // Luminances 1, 2, 3, 4 (grey samples): mean 2.5, sample variance 5/3.
        for v in [1.0f32, 2.0, 3.0, 4.0] {
            assert!(p.add_sample(Vec3::splat(v), Vec3::ZERO));
        }
        assert!(!p.add_sample(Vec3::splat(f32::NAN), Vec3::ZERO));
        assert!((p.lum_mean - 2.5).abs() < 1e-6);
        assert!((p.lum_m2 / 3.0 - 5.0 / 3.0).abs() < 1e-5);
        // The dropped sample does not count: 4 kept samples.
        let want = 5.0f32 / 3.0 / 4.0;
        assert!((p.mean_variance().unwrap() - want).abs() < 1e-6);
        assert_eq!(p.taken(), 5);
        // A black pixel has no variance at all.
        let mut black = Pixel::default();
        for _ in 0..3 {
            black.add_sample(Vec3::ZERO, Vec3::ZERO);
        }
        assert_eq!(black.mean_variance(), Some(0.0));
    }
}
