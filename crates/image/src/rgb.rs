//! [`RgbImage`]: a linear RGB float image, the renderer's film output and the comparison's
//! input.

use glam::Vec3;

/// A linear RGB float image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels.
    pub pixels: Vec<Vec3>,
}

impl RgbImage {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// The image whose pixel in column `x`, row `y` is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> Vec3) -> Self {
        let pixels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Self {
            width,
            height,
            pixels,
        }
    }

    /// The pixel in column `x`, row `y` (row 0 at the top).
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Component `c` (0, 1, 2) of every pixel, in pixel order: one plane of the image.
    pub fn plane(&self, c: usize) -> Vec<f32> {
        self.pixels.iter().map(|p| p[c]).collect()
    }

    /// The image whose pixels have the components of three planes (each `width * height`
    /// values, as [`RgbImage::plane`] gives them).
    pub fn from_planes(width: u32, height: u32, planes: [&[f32]; 3]) -> Self {
        let pixels = (0..width as usize * height as usize)
            .map(|i| Vec3::new(planes[0][i], planes[1][i], planes[2][i]))
            .collect();
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Whether the pixel count matches the size and the size is not zero.
    pub fn is_well_formed(&self) -> bool {
        self.width > 0
            && self.height > 0
            && self.pixels.len() == self.width as usize * self.height as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_round_trip() {
        let img = RgbImage {
            width: 2,
            height: 1,
            pixels: vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)],
        };
        let planes = [img.plane(0), img.plane(1), img.plane(2)];
        assert_eq!(planes[1], [2.0, 5.0]);
        let back = RgbImage::from_planes(2, 1, [&planes[0], &planes[1], &planes[2]]);
        assert_eq!(back, img);
        assert_eq!(img.get(1, 0), Vec3::new(4.0, 5.0, 6.0));
        assert!(img.is_well_formed() && !RgbImage::new(0, 3).is_well_formed());
    }

    #[test]
    fn from_fn_is_row_major() {
        let img = RgbImage::from_fn(3, 2, |x, y| Vec3::new(x as f32, y as f32, 0.0));
        assert_eq!(img.pixels.len(), 6);
        assert_eq!(img.get(2, 1), Vec3::new(2.0, 1.0, 0.0));
        assert_eq!(img.pixels[3], Vec3::new(0.0, 1.0, 0.0));
    }
}
