//! Textures: decoded RGBA images in linear values, sampled with bilinear filtering and repeat
//! wrapping (glTF's default sampler). Colour textures (base colour, emissive) are sRGB-decoded
//! once, when they are loaded; data textures (metallic-roughness, dryness) are kept linear.

use glam::{Vec2, Vec4};
use std::sync::LazyLock;
use streaks_image::color::srgb_to_linear;

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

/// Linear values of the 256 byte values: `i / 255`.
static LINEAR_BYTES: LazyLock<[f32; 256]> = LazyLock::new(|| byte_table(|v| v));
/// sRGB-decoded values of the 256 byte values: `srgb_to_linear(i / 255)`.
static SRGB_BYTES: LazyLock<[f32; 256]> = LazyLock::new(|| byte_table(srgb_to_linear));

fn byte_table(decode: fn(f32) -> f32) -> [f32; 256] {
    std::array::from_fn(|i| decode(f32::from(i as u8) / 255.0))
}

/// How the texels are stored.
#[derive(Clone, Debug)]
enum Texels {
    /// 8-bit RGBA as in the image file (a quarter of the memory traffic of floats), decoded per
    /// fetch by table: `srgb` says whether RGB is sRGB-encoded (alpha never is). The decoded
    /// values are exactly those of decoding at load time.
    Rgba8 { texels: Vec<[u8; 4]>, srgb: bool },
    /// Linear float RGBA (16-bit and float images, procedural textures).
    Rgba32F(Vec<Vec4>),
}

/// A decoded RGBA image in linear values, sampled with bilinear filtering and repeat wrapping
/// (glTF's default sampler). 8-bit images keep their bytes (see [`Texture::from_rgba8`]).
#[derive(Clone, Debug)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, top row first (glTF uv (0,0) is the top-left corner).
    texels: Texels,
}

impl Texture {
    /// A texture from normalised RGBA values in [0, 1] (top row first); RGB is sRGB-decoded
    /// when `space` is [`ColorSpace::Srgb`] (alpha is always linear). `None` when the size does
    /// not match the texel count or is zero.
    pub fn from_rgba(width: u32, height: u32, rgba: Vec<Vec4>, space: ColorSpace) -> Option<Self> {
        if !Self::size_matches(width, height, rgba.len()) {
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
            texels: Texels::Rgba32F(texels),
        })
    }

    /// A texture from 8-bit RGBA bytes (top row first), kept as bytes: each fetch decodes
    /// them by table to the same values [`Texture::from_rgba`] would store (`byte / 255`,
    /// sRGB-decoded in RGB for [`ColorSpace::Srgb`]). `None` when the size does not match the
    /// byte count or is zero.
    pub fn from_rgba8(width: u32, height: u32, bytes: &[u8], space: ColorSpace) -> Option<Self> {
        if bytes.len() % 4 != 0 || !Self::size_matches(width, height, bytes.len() / 4) {
            return None;
        }
        let texels = bytes
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        Some(Self {
            width,
            height,
            texels: Texels::Rgba8 {
                texels,
                srgb: space == ColorSpace::Srgb,
            },
        })
    }

    fn size_matches(width: u32, height: u32, count: usize) -> bool {
        width > 0 && height > 0 && count as u64 == u64::from(width) * u64::from(height)
    }

    /// Number of texels (`width * height`).
    pub fn texel_count(&self) -> usize {
        match &self.texels {
            Texels::Rgba8 { texels, .. } => texels.len(),
            Texels::Rgba32F(texels) => texels.len(),
        }
    }

    /// The linear value of texel `index` (row-major, top row first).
    #[inline]
    pub fn texel(&self, index: usize) -> Vec4 {
        match &self.texels {
            Texels::Rgba8 { texels, srgb } => {
                let rgb = if *srgb { &SRGB_BYTES } else { &LINEAR_BYTES };
                decode_rgba8(texels[index], rgb, &LINEAR_BYTES)
            }
            Texels::Rgba32F(texels) => texels[index],
        }
    }

    /// The linear values of all texels, row-major, top row first.
    pub fn texels(&self) -> impl ExactSizeIterator<Item = Vec4> + '_ {
        (0..self.texel_count()).map(|i| self.texel(i))
    }

    /// The filtered value at `uv`: bilinear between texel centres (texel `(i, j)` has its
    /// centre at `((i + 0.5) / width, (j + 0.5) / height)`), repeat wrapping.
    #[inline]
    pub fn sample(&self, uv: Vec2) -> Vec4 {
        if !uv.is_finite() {
            return self.texel(0);
        }
        // Reduce to one period first so that huge uvs keep their precision.
        let u = uv.x - uv.x.floor();
        let v = uv.y - uv.y.floor();
        let x = u * self.width as f32 - 0.5;
        let y = v * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xa, xb) = wrap_pair(x0, self.width);
        let (ya, yb) = wrap_pair(y0, self.height);
        let row = self.width as usize;
        let [i00, i10, i01, i11] = [ya * row + xa, ya * row + xb, yb * row + xa, yb * row + xb];
        let [c00, c10, c01, c11] = match &self.texels {
            Texels::Rgba8 { texels, srgb } => {
                let (rgb, alpha) = (
                    if *srgb { &*SRGB_BYTES } else { &*LINEAR_BYTES },
                    &*LINEAR_BYTES,
                );
                [i00, i10, i01, i11].map(|i| decode_rgba8(texels[i], rgb, alpha))
            }
            Texels::Rgba32F(texels) => [i00, i10, i01, i11].map(|i| texels[i]),
        };
        c00.lerp(c10, fx).lerp(c01.lerp(c11, fx), fy)
    }
}

/// The texel indices of `x0` and `x0 + 1` on an axis of `n` texels, repeated: `x0` is the
/// floor of `u n - 0.5` for `u` in `[0, 1]`, so it lies in `[-1, n - 1]` and one comparison
/// per end wraps it (what `rem_euclid` would give, without its two divisions).
#[inline]
fn wrap_pair(x0: f32, n: u32) -> (usize, usize) {
    let (x0, n) = (x0 as i64, i64::from(n));
    debug_assert!((-1..n).contains(&x0), "{x0} outside [-1, {n})");
    let a = if x0 < 0 { n - 1 } else { x0.min(n - 1) };
    let b = if x0 + 1 >= n { 0 } else { (x0 + 1).max(0) };
    (a as usize, b as usize)
}

/// One 8-bit texel's linear value: RGB through `rgb`, alpha through `alpha`.
#[inline]
fn decode_rgba8(c: [u8; 4], rgb: &[f32; 256], alpha: &[f32; 256]) -> Vec4 {
    Vec4::new(
        rgb[usize::from(c[0])],
        rgb[usize::from(c[1])],
        rgb[usize::from(c[2])],
        alpha[usize::from(c[3])],
    )
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

    /// The comparison wrap is `rem_euclid` over the floors a `uv` in one period gives, and
    /// uvs at the ends of a period (including those that round to 1) stay in range.
    #[test]
    fn wrapping_is_rem_euclid() {
        for n in [1u32, 2, 3, 256] {
            for x0 in -1..n as i64 {
                let want = (
                    x0.rem_euclid(i64::from(n)) as usize,
                    (x0 + 1).rem_euclid(i64::from(n)) as usize,
                );
                assert_eq!(wrap_pair(x0 as f32, n), want, "{x0} of {n}");
            }
        }
        let t = checker();
        for u in [
            -1e-10f32,
            -0.0,
            0.0,
            1e-10,
            0.999_999_94,
            1.0 - 1e-10,
            3.0,
            -7.5,
        ] {
            let c = t.sample(Vec2::new(u, 0.25));
            assert!((0.0..=1.0).contains(&c.x), "{u}: {c}");
        }
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

    /// Bytes kept as bytes sample to exactly the values of decoding them at load time.
    #[test]
    fn rgba8_samples_as_decoded_floats() {
        let mut rng = crate::sampling::Pcg32::new(5, 9);
        let bytes: Vec<u8> = (0..5 * 3 * 4)
            .map(|_| (rng.next_f32() * 256.0) as u8)
            .collect();
        for space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let floats = bytes
                .chunks_exact(4)
                .map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 255.0)
                .collect();
            let a = Texture::from_rgba8(5, 3, &bytes, space).unwrap();
            let b = Texture::from_rgba(5, 3, floats, space).unwrap();
            assert!(a.texels().eq(b.texels()));
            for _ in 0..200 {
                let uv = Vec2::new(rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 4.0 - 2.0);
                assert_eq!(a.sample(uv), b.sample(uv), "{space:?} at {uv}");
            }
        }
        assert!(Texture::from_rgba8(5, 3, &bytes[..56], ColorSpace::Linear).is_none());
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
