//! The film: per-pixel accumulation with a box pixel filter.
//!
//! Each sample's film position is uniform in its own pixel (pixel `(i, j)` covers
//! `[i, i+1) x [j, j+1)`), and a pixel's value is the mean of its kept samples: the box filter,
//! as Mitsuba's `box` rfilter. Samples never land in a neighbour, so rows can be filled in
//! parallel with no synchronisation, and the memory per pixel is a fixed-size [`Pixel`]
//! whatever the sample count.
//!
//! A sample whose radiance (or specular part) is NaN or infinite is dropped and counted,
//! never accumulated (DESIGN.md).

use glam::Vec3;
use streaks_image::RgbImage;

/// One pixel's accumulators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pixel {
    /// Sum of the kept samples' radiance.
    pub radiance: Vec3,
    /// Sum of the kept samples' specular part (see [`crate::integrator`]).
    pub specular: Vec3,
    /// Number of kept samples.
    pub kept: u32,
    /// Number of dropped (non-finite) samples.
    pub dropped: u32,
    /// Camera-space depth of the pixel-centre ray's first hit (`inf` on a miss).
    pub depth: f32,
    /// First-hit shading normal (world space, facing the camera; zero on a miss).
    pub normal: Vec3,
    /// First-hit BSDF albedo (zero on a miss).
    pub albedo: Vec3,
    /// Index into the scene's materials of the pixel-centre ray's first hit ([`NO_MATERIAL`]
    /// on a miss).
    pub material: u32,
}

/// [`Pixel::material`] of a pixel whose centre ray hits nothing.
pub const NO_MATERIAL: u32 = u32::MAX;

impl Default for Pixel {
    fn default() -> Self {
        Self {
            radiance: Vec3::ZERO,
            specular: Vec3::ZERO,
            kept: 0,
            dropped: 0,
            depth: f32::INFINITY,
            normal: Vec3::ZERO,
            albedo: Vec3::ZERO,
            material: NO_MATERIAL,
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

    /// The box-filtered specular part.
    #[inline]
    pub fn mean_specular(&self) -> Vec3 {
        if self.kept == 0 {
            Vec3::ZERO
        } else {
            self.specular / self.kept as f32
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

    /// Total number of dropped samples.
    pub fn dropped(&self) -> u64 {
        self.pixels.iter().map(|p| p.dropped as u64).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    }
}
