//! Textures: decoded RGBA images in linear values, sampled with bilinear filtering and repeat
//! wrapping (glTF's default sampler). Colour textures (base colour, emissive) are sRGB-decoded
//! once, when they are loaded; data textures (metallic-roughness, dryness) are kept linear.

use glam::{Vec2, Vec4};

/// Index of a texture in [`crate::scene::Scene::textures`].
pub type TextureId = u32;

/// How a texture's texels are stored once decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// sRGB-encoded colour data (base colour, emissive): decoded to linear on load.
    Srgb,
    /// Linear data (metallic-roughness, wetness).
    Linear,
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): encoded value in [0, 1] to
/// linear.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A decoded RGBA image in linear values, sampled with bilinear filtering and repeat wrapping
/// (glTF's default sampler).
#[derive(Clone, Debug)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, top row first (glTF uv (0,0) is the top-left corner).
    pub texels: Vec<Vec4>,
}

impl Texture {
    /// A texture from normalised RGBA values in [0, 1] (top row first); RGB is sRGB-decoded
    /// when `space` is [`ColorSpace::Srgb`] (alpha is always linear). `None` when the size does
    /// not match the texel count or is zero.
    pub fn from_rgba(width: u32, height: u32, rgba: Vec<Vec4>, space: ColorSpace) -> Option<Self> {
        if width == 0 || height == 0 || rgba.len() as u64 != u64::from(width) * u64::from(height) {
            return None;
        }
        let texels = match space {
            ColorSpace::Linear => rgba,
            ColorSpace::Srgb => rgba
                .into_iter()
                .map(|c| {
                    Vec4::new(
                        srgb_to_linear(c.x),
                        srgb_to_linear(c.y),
                        srgb_to_linear(c.z),
                        c.w,
                    )
                })
                .collect(),
        };
        Some(Self {
            width,
            height,
            texels,
        })
    }

    /// A texture from 8-bit RGBA bytes (top row first).
    pub fn from_rgba8(width: u32, height: u32, bytes: &[u8], space: ColorSpace) -> Option<Self> {
        let rgba = bytes
            .chunks_exact(4)
            .map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 255.0)
            .collect();
        Self::from_rgba(width, height, rgba, space)
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> Vec4 {
        let x = x.rem_euclid(i64::from(self.width)) as usize;
        let y = y.rem_euclid(i64::from(self.height)) as usize;
        self.texels[y * self.width as usize + x]
    }

    /// The filtered value at `uv`: bilinear between texel centres (texel `(i, j)` has its
    /// centre at `((i + 0.5) / width, (j + 0.5) / height)`), repeat wrapping.
    #[inline]
    pub fn sample(&self, uv: Vec2) -> Vec4 {
        if !uv.is_finite() {
            return self.texels[0];
        }
        // Reduce to one period first so that huge uvs keep their precision.
        let u = uv.x - uv.x.floor();
        let v = uv.y - uv.y.floor();
        let x = u * self.width as f32 - 0.5;
        let y = v * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        // 2x2: black, white / white, black (linear).
        let b = Vec4::new(0.0, 0.0, 0.0, 1.0);
        let w = Vec4::ONE;
        Texture::from_rgba(2, 2, vec![b, w, w, b], ColorSpace::Linear).unwrap()
    }

    #[test]
    fn texel_centres_are_exact_and_midpoints_blend() {
        let t = checker();
        assert_eq!(t.sample(Vec2::new(0.25, 0.25)).x, 0.0);
        assert_eq!(t.sample(Vec2::new(0.75, 0.25)).x, 1.0);
        assert!((t.sample(Vec2::new(0.5, 0.25)).x - 0.5).abs() < 1e-6);
        // Repeat wrapping: u = 0 blends the last and first columns.
        assert!((t.sample(Vec2::new(0.0, 0.25)).x - 0.5).abs() < 1e-6);
        assert_eq!(t.sample(Vec2::new(-1.25, 3.25)).x, 1.0);
    }

    #[test]
    fn srgb_is_decoded() {
        let t = Texture::from_rgba8(1, 1, &[255, 128, 0, 128], ColorSpace::Srgb).unwrap();
        let c = t.sample(Vec2::new(0.3, 0.9));
        assert!((c.x - 1.0).abs() < 1e-6 && c.z == 0.0);
        assert!((c.y - 0.2158605).abs() < 1e-4, "{c}");
        assert!((c.w - 128.0 / 255.0).abs() < 1e-6);
        assert!(Texture::from_rgba8(2, 1, &[0; 4], ColorSpace::Linear).is_none());
    }
}
