//! [`GrayImage`]: a single-channel float image, the currency of the stereo and analysis code
//! (grey levels, disparity and depth maps, masks).

use crate::color::{luminance, srgb_to_linear};
use crate::input::load_image;
use crate::png::write_png_buffer;
use crate::{ImageError, RgbImage};
use glam::Vec3;
use std::path::Path;

/// A grey-level image of `f32` values, row-major, top row first (pixel (x, y) at `y * width + x`).
#[derive(Clone, Debug, PartialEq)]
pub struct GrayImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width * height` values.
    pub data: Vec<f32>,
}

impl GrayImage {
    /// A `width` x `height` image filled with `value`; an error for a zero or overflowing size.
    pub fn new(width: usize, height: usize, value: f32) -> Result<Self, ImageError> {
        let n = checked_len(width, height)?;
        Ok(Self {
            width,
            height,
            data: vec![value; n],
        })
    }

    /// Wraps existing data; an error when the length does not match the size.
    pub fn from_vec(width: usize, height: usize, data: Vec<f32>) -> Result<Self, ImageError> {
        let n = checked_len(width, height)?;
        if n != data.len() {
            return Err(ImageError::Size {
                width: width as u64,
                height: height as u64,
                reason: "data length does not match width x height",
            });
        }
        Ok(Self {
            width,
            height,
            data,
        })
    }

    /// Width and height in pixels, the form [`crate::ensure_same_size`] compares.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The value at (x, y).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// Sets the value at (x, y).
    #[inline]
    pub fn set(&mut self, x: usize, y: usize, v: f32) {
        self.data[y * self.width + x] = v;
    }

    /// Bilinear interpolation at continuous pixel coordinates (pixel centres at `i + 0.5`),
    /// clamped to the edge pixels; `None` outside `[0, width] x [0, height]`.
    #[inline]
    pub fn sample_bilinear(&self, x: f32, y: f32) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x <= self.width as f32 && y <= self.height as f32) {
            return None;
        }
        let (u, v) = (x - 0.5, y - 0.5);
        let (x0, y0) = (u.floor(), v.floor());
        let (tx, ty) = (u - x0, v - y0);
        let clamp_x = |i: f32| (i.max(0.0) as usize).min(self.width - 1);
        let clamp_y = |i: f32| (i.max(0.0) as usize).min(self.height - 1);
        let (xa, xb, ya, yb) = (
            clamp_x(x0),
            clamp_x(x0 + 1.0),
            clamp_y(y0),
            clamp_y(y0 + 1.0),
        );
        let top = self.get(xa, ya) * (1.0 - tx) + self.get(xb, ya) * tx;
        let bottom = self.get(xa, yb) * (1.0 - tx) + self.get(xb, yb) * tx;
        Some(top * (1.0 - ty) + bottom * ty)
    }

    /// The image as 8-bit grey levels: values in [0, 1] are scaled to [0, 255], rounded, and
    /// clipped (NaN becomes 0).
    pub fn to_gray8(&self) -> ::image::GrayImage {
        let data = self.data.iter().map(|&v| to_u8(v)).collect();
        ::image::GrayImage::from_raw(self.width as u32, self.height as u32, data)
            .expect("size checked at construction")
    }

    /// The grey levels repeated in three channels, as [`GrayImage::to_gray8`].
    pub fn to_rgb8(&self) -> ::image::RgbImage {
        let data = self.data.iter().flat_map(|&v| [to_u8(v); 3]).collect();
        ::image::RgbImage::from_raw(self.width as u32, self.height as u32, data)
            .expect("size checked at construction")
    }

    /// Writes the image as an 8-bit greyscale PNG (see [`GrayImage::to_gray8`]), atomically.
    pub fn save_png(&self, path: &Path) -> Result<(), ImageError> {
        write_png_buffer(path, &self.to_gray8())
    }

    /// The luminance ([`luminance`]) of every pixel of a linear RGB image.
    pub fn luminance_of(img: &RgbImage) -> Result<Self, ImageError> {
        let data = img.pixels.iter().map(|&p| luminance(p)).collect();
        Self::from_vec(img.width as usize, img.height as usize, data)
    }

    /// Loads any image the `image` crate reads (PNG, JPEG, EXR; 8/16-bit or float; within the
    /// limits of [`crate::input`]) as its
    /// [`luminance`] (of the stored values: sRGB-encoded for PNG and JPEG, linear for EXR), in
    /// [0, 1] for integer formats.
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let [r, g, b] = load_rgb_channels(path)?;
        let data = r
            .data
            .iter()
            .zip(&g.data)
            .zip(&b.data)
            .map(|((&r, &g), &b)| luminance(Vec3::new(r, g, b)))
            .collect();
        Self::from_vec(r.width, r.height, data)
    }
}

impl GrayImage {
    /// Loads an image as the [`luminance`] of its *linear* RGB: float formats (EXR) as stored,
    /// integer formats (PNG, JPEG: sRGB-encoded) decoded with [`srgb_to_linear`] first. The
    /// input a detector working on radiance needs; an 8-bit image's clipped highlights stay
    /// clipped.
    pub fn load_linear(path: &Path) -> Result<Self, ImageError> {
        let img = load_image(path)?;
        let float = matches!(
            img,
            ::image::DynamicImage::ImageRgb32F(_) | ::image::DynamicImage::ImageRgba32F(_)
        );
        let rgb = img.to_rgb32f();
        let decode = |c: f32| if float { c } else { srgb_to_linear(c) };
        let data = rgb
            .pixels()
            .map(|p| luminance(Vec3::new(decode(p[0]), decode(p[1]), decode(p[2]))))
            .collect();
        Self::from_vec(rgb.width() as usize, rgb.height() as usize, data)
    }
}

/// Loads any image the `image` crate reads as its three channels R, G, B as stored (sRGB
/// values in [0, 1] for PNG and JPEG, linear for EXR).
pub fn load_rgb_channels(path: &Path) -> Result<[GrayImage; 3], ImageError> {
    let read_err = |reason: String| ImageError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let img = load_image(path)?;
    let rgb = img.to_rgb32f();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    let channel = |c: usize| {
        let data = rgb.pixels().map(|p| p[c]).collect();
        GrayImage::from_vec(w, h, data).map_err(|e| read_err(e.to_string()))
    };
    Ok([channel(0)?, channel(1)?, channel(2)?])
}

fn checked_len(width: usize, height: usize) -> Result<usize, ImageError> {
    let size = |reason| ImageError::Size {
        width: width as u64,
        height: height as u64,
        reason,
    };
    if width == 0 || height == 0 {
        return Err(size("zero width or height"));
    }
    match width.checked_mul(height) {
        Some(n) if n <= (1usize << 31) => Ok(n),
        _ => Err(size("more than 2^31 pixels")),
    }
}

#[inline]
fn to_u8(v: f32) -> u8 {
    // NaN fails both comparisons of clamp's inputs and becomes 0 through `as`.
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert!(GrayImage::new(0, 4, 0.0).is_err());
        assert!(GrayImage::new(usize::MAX, 2, 0.0).is_err());
        assert!(GrayImage::from_vec(2, 2, vec![0.0; 3]).is_err());
        let mut g = GrayImage::new(3, 2, 0.5).unwrap();
        g.set(2, 1, 7.0);
        assert_eq!(g.get(2, 1), 7.0);
        assert_eq!(g.data[5], 7.0);
    }

    #[test]
    fn bilinear_sampling_hits_pixel_centres_and_interpolates() {
        let g = GrayImage::from_vec(2, 2, vec![0.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(g.sample_bilinear(0.5, 0.5), Some(0.0));
        assert_eq!(g.sample_bilinear(1.5, 1.5), Some(3.0));
        assert_eq!(g.sample_bilinear(1.0, 0.5), Some(0.5));
        assert_eq!(g.sample_bilinear(1.0, 1.0), Some(1.5));
        assert_eq!(
            g.sample_bilinear(0.0, 0.0),
            Some(0.0),
            "clamped at the edge"
        );
        assert_eq!(g.sample_bilinear(2.1, 1.0), None);
        assert_eq!(g.sample_bilinear(f32::NAN, 1.0), None);
    }

    #[test]
    fn png_round_trip_and_atomic_write() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("g.png");
        let g = GrayImage::from_vec(3, 1, vec![0.0, 0.5, 2.0]).unwrap();
        g.save_png(&p).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let back = GrayImage::load(&p).unwrap();
        assert_eq!(back.data[0], 0.0);
        assert!((back.data[1] - 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(back.data[2], 1.0);
        assert!(g.save_png(&dir.path().join("no/such/dir.png")).is_err());
    }

    #[test]
    fn load_linear_decodes_png_but_not_exr() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("g.png");
        GrayImage::from_vec(2, 1, vec![0.5, 1.0])
            .unwrap()
            .save_png(&png)
            .unwrap();
        let lin = GrayImage::load_linear(&png).unwrap();
        assert!(
            (lin.data[0] - srgb_to_linear(128.0 / 255.0)).abs() < 1e-5,
            "{}",
            lin.data[0]
        );
        assert!((lin.data[1] - 1.0).abs() < 1e-5);
        let exr = dir.path().join("g.exr");
        let mut rgb = RgbImage::new(2, 1);
        rgb.pixels = vec![Vec3::splat(0.25), Vec3::splat(7.0)];
        crate::exr::write_exr_rgb(&exr, &rgb).unwrap();
        let lin = GrayImage::load_linear(&exr).unwrap();
        assert!(
            (lin.data[0] - 0.25).abs() < 1e-5 && (lin.data[1] - 7.0).abs() < 1e-4,
            "{:?}",
            lin.data
        );
        assert!(GrayImage::load_linear(&dir.path().join("none.png")).is_err());
    }
}
