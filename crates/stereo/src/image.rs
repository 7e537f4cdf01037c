//! A single-channel float image, the currency of the stereo and analysis code.

use std::path::Path;

/// Errors reading or writing images.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be read or decoded.
    #[error("cannot read image {path}: {reason}")]
    Read {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
    /// The file could not be written.
    #[error("cannot write image {path}: {reason}")]
    Write {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
    /// A zero or overflowing size, or data that does not fit the size.
    #[error("invalid image size {width}x{height}: {reason}")]
    Size {
        /// Width asked for.
        width: u64,
        /// Height asked for.
        height: u64,
        /// Why it is invalid.
        reason: &'static str,
    },
}

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

    /// Loads any image the `image` crate reads (PNG, JPEG, EXR; 8/16-bit or float) as luminance
    /// (Rec. 709 weights) in [0, 1] for integer formats.
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let img = ::image::open(path).map_err(|e| ImageError::Read {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        let rgb = img.to_rgb32f();
        let (w, h) = (rgb.width() as usize, rgb.height() as usize);
        let data = rgb
            .pixels()
            .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
            .collect();
        Self::from_vec(w, h, data).map_err(|e| ImageError::Read {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    }
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
}
