//! Textures: decoded RGBA images in linear values, and the references materials hold to them.
//!
//! Colour textures (base colour, emissive) are sRGB-decoded once, when they are loaded; data
//! textures (metallic-roughness, dryness) are kept linear.
//!
//! A material refers to a texture through a [`TextureRef`]: the image, which texture
//! coordinate set it reads (`TEXCOORD_0` or `TEXCOORD_1`), the glTF sampler's wrap modes and
//! magnification filter ([`Sampler`]), and a KHR_texture_transform ([`uv_transform`]). The
//! image is stored once however many samplers read it.
//!
//! # Filtering in a path tracer
//!
//! Each texture lookup is a point sample (bilinear, or nearest for `magFilter: NEAREST`) at the
//! ray's hit point, and every pixel is supersampled over its footprint, so the average over a
//! pixel's samples converges to the texture filtered by the pixel footprint (better than a
//! mipmap's approximation of it). The glTF `minFilter` (mipmapped or not) therefore changes
//! only the noise at low sample counts, not the converged image: it is ignored, without a
//! warning. `magFilter: NEAREST` is honoured (it shows as blocky texels however many samples
//! a pixel takes).

use glam::{Affine2, Vec2, Vec4};
use std::sync::LazyLock;
use streaks_image::color::srgb_to_linear;

/// Index of a texture in [`crate::scene::Scene::textures`].
pub type TextureId = u32;

/// How texture coordinates outside `[0, 1]` map to texels on one axis (glTF sampler `wrapS`,
/// `wrapT`; OpenGL semantics).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// `REPEAT` (10497, the glTF default): the image tiles.
    #[default]
    Repeat,
    /// `CLAMP_TO_EDGE` (33071): coordinates are clamped to the edge texels.
    ClampToEdge,
    /// `MIRRORED_REPEAT` (33648): the image tiles, every other tile mirrored.
    MirroredRepeat,
}

/// How a texture is filtered between texel centres (glTF `magFilter`; see the module
/// documentation for `minFilter`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// `LINEAR` (the default here, as glTF leaves it to the implementation): bilinear.
    #[default]
    Linear,
    /// `NEAREST`: the texel the point lies in.
    Nearest,
}

/// A glTF sampler as far as it changes the converged image: wrap modes per axis and the
/// magnification filter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Sampler {
    /// Wrapping along u (`wrapS`).
    pub wrap_s: Wrap,
    /// Wrapping along v (`wrapT`).
    pub wrap_t: Wrap,
    /// Filter between texels.
    pub filter: Filter,
}

/// The KHR_texture_transform matrix `T * R * S` applied to `(u, v, 1)`, with
/// `T = [1 0 ox; 0 1 oy]`, `R = [cos r, sin r; -sin r, cos r]` and `S = diag(sx, sy)` (the
/// extension's specification, in its row-major notation): `rotation` turns the uvs
/// counter-clockwise as seen in the image (whose v points down).
pub fn uv_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
    let (sin, cos) = rotation.sin_cos();
    // Columns of R * S: R's columns are (cos, -sin) and (sin, cos).
    Affine2::from_cols(
        Vec2::new(cos, -sin) * scale.x,
        Vec2::new(sin, cos) * scale.y,
        offset,
    )
}

/// A material's reference to a texture: which image, read at which texture coordinate set,
/// through which sampler and uv transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// The image.
    pub texture: TextureId,
    /// The texture coordinate set (0 for `TEXCOORD_0`, 1 for `TEXCOORD_1`).
    pub texcoord: u8,
    /// Wrapping and filtering.
    pub sampler: Sampler,
    /// KHR_texture_transform's matrix ([`uv_transform`]); `None` is the identity.
    pub transform: Option<Affine2>,
}

impl TextureRef {
    /// A reference to `texture` at `TEXCOORD_0` with the default sampler and no transform.
    pub fn new(texture: TextureId) -> Self {
        Self {
            texture,
            texcoord: 0,
            sampler: Sampler::default(),
            transform: None,
        }
    }

    /// The texture coordinates this reference samples at, from the point's coordinate sets:
    /// the chosen set, transformed.
    #[inline]
    pub fn uv(&self, uvs: [Vec2; 2]) -> Vec2 {
        let uv = uvs[usize::from(self.texcoord & 1)];
        match &self.transform {
            Some(m) => m.transform_point2(uv),
            None => uv,
        }
    }

    /// The filtered texel value at the point with coordinate sets `uvs`; one where the id is
    /// out of range (which [`crate::scene::Scene::from_parts`] rules out).
    #[inline]
    pub fn sample(&self, uvs: [Vec2; 2], textures: &[Texture]) -> Vec4 {
        textures
            .get(self.texture as usize)
            .map_or(Vec4::ONE, |t| t.sample_with(self.uv(uvs), self.sampler))
    }
}

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
    /// An 8-bit image whose every texel is grey and opaque (`r = g = b`, `a = 255`; a grey
    /// PNG such as a road's asphalt), one byte per texel, decoded as [`Texels::Rgba8`] would:
    /// the same values in a quarter of its memory, so that a street's textures stay in the
    /// core's cache (docs/decisions/0017-textures-as-bytes.md).
    Grey8 { texels: Vec<u8>, srgb: bool },
    /// Linear float RGBA (16-bit and float images, procedural textures).
    Rgba32F(Vec<Vec4>),
}

/// A decoded RGBA image in linear values, sampled through a [`Sampler`] (bilinear filtering
/// and repeat wrapping by default, glTF's default sampler). 8-bit images keep their bytes (see
/// [`Texture::from_rgba8`]).
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
        let srgb = space == ColorSpace::Srgb;
        let grey = bytes
            .chunks_exact(4)
            .all(|c| c[0] == c[1] && c[1] == c[2] && c[3] == u8::MAX);
        let texels = if grey {
            Texels::Grey8 {
                texels: bytes.iter().step_by(4).copied().collect(),
                srgb,
            }
        } else {
            Texels::Rgba8 {
                texels: bytes
                    .chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect(),
                srgb,
            }
        };
        Some(Self {
            width,
            height,
            texels,
        })
    }

    fn size_matches(width: u32, height: u32, count: usize) -> bool {
        width > 0 && height > 0 && count as u64 == u64::from(width) * u64::from(height)
    }

    /// Number of texels (`width * height`).
    pub fn texel_count(&self) -> usize {
        match &self.texels {
            Texels::Rgba8 { texels, .. } => texels.len(),
            Texels::Grey8 { texels, .. } => texels.len(),
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
            Texels::Grey8 { texels, srgb } => {
                let rgb = if *srgb { &SRGB_BYTES } else { &LINEAR_BYTES };
                decode_grey8(texels[index], rgb)
            }
            Texels::Rgba32F(texels) => texels[index],
        }
    }

    /// The linear values of all texels, row-major, top row first.
    pub fn texels(&self) -> impl ExactSizeIterator<Item = Vec4> + '_ {
        (0..self.texel_count()).map(|i| self.texel(i))
    }

    /// The filtered value at `uv` with the default sampler: bilinear between texel centres
    /// (texel `(i, j)` has its centre at `((i + 0.5) / width, (j + 0.5) / height)`), repeat
    /// wrapping.
    #[inline]
    pub fn sample(&self, uv: Vec2) -> Vec4 {
        self.sample_with(uv, Sampler::default())
    }

    /// The value at `uv` through `sampler`: bilinear between texel centres, or the texel `uv`
    /// lies in for [`Filter::Nearest`], with each axis wrapped as its [`Wrap`] says. A
    /// non-finite `uv` reads texel 0.
    #[inline]
    pub fn sample_with(&self, uv: Vec2, sampler: Sampler) -> Vec4 {
        if !uv.is_finite() {
            return self.texel(0);
        }
        let row = self.width as usize;
        if sampler.filter == Filter::Nearest {
            let x = nearest(uv.x, self.width, sampler.wrap_s);
            let y = nearest(uv.y, self.height, sampler.wrap_t);
            return self.texel(y * row + x);
        }
        let (xa, xb, fx) = linear_pair(uv.x, self.width, sampler.wrap_s);
        let (ya, yb, fy) = linear_pair(uv.y, self.height, sampler.wrap_t);
        let [i00, i10, i01, i11] = [ya * row + xa, ya * row + xb, yb * row + xa, yb * row + xb];
        let [c00, c10, c01, c11] = match &self.texels {
            Texels::Rgba8 { texels, srgb } => {
                let (rgb, alpha) = (
                    if *srgb { &*SRGB_BYTES } else { &*LINEAR_BYTES },
                    &*LINEAR_BYTES,
                );
                [i00, i10, i01, i11].map(|i| decode_rgba8(texels[i], rgb, alpha))
            }
            Texels::Grey8 { texels, srgb } => {
                let rgb = if *srgb { &*SRGB_BYTES } else { &*LINEAR_BYTES };
                [i00, i10, i01, i11].map(|i| decode_grey8(texels[i], rgb))
            }
            Texels::Rgba32F(texels) => [i00, i10, i01, i11].map(|i| texels[i]),
        };
        c00.lerp(c10, fx).lerp(c01.lerp(c11, fx), fy)
    }
}

/// The two texels bilinear filtering blends on an axis of `n` texels at coordinate `u`, and
/// the weight of the second: texel `i` has its centre at `(i + 0.5) / n`, and the texel
/// indices outside `[0, n)` are wrapped as `wrap` says.
#[inline]
fn linear_pair(u: f32, n: u32, wrap: Wrap) -> (usize, usize, f32) {
    match wrap {
        Wrap::Repeat => {
            // Reduce to one period first so that huge uvs keep their precision.
            let x = (u - u.floor()) * n as f32 - 0.5;
            let x0 = x.floor();
            let (a, b) = wrap_pair(x0, n);
            (a, b, x - x0)
        }
        Wrap::ClampToEdge => {
            // Clamping u first changes nothing: beyond the outer texel centres both texels
            // clamp to the edge one.
            let x = u.clamp(0.0, 1.0) * n as f32 - 0.5;
            let x0 = x.floor();
            let last = n as i64 - 1;
            let a = (x0 as i64).clamp(0, last) as usize;
            let b = (x0 as i64 + 1).clamp(0, last) as usize;
            (a, b, x - x0)
        }
        Wrap::MirroredRepeat => {
            // Period 2 (a tile and its mirror image), texel index period 2n.
            let x = (u - 2.0 * (0.5 * u).floor()) * n as f32 - 0.5;
            let x0 = x.floor();
            let a = mirror(x0 as i64, n);
            let b = mirror(x0 as i64 + 1, n);
            (a, b, x - x0)
        }
    }
}

/// The texel index on an axis of `n` texels that coordinate `u` lies in (nearest filtering),
/// wrapped as `wrap` says.
#[inline]
fn nearest(u: f32, n: u32, wrap: Wrap) -> usize {
    let last = n as i64 - 1;
    match wrap {
        Wrap::Repeat => (((u - u.floor()) * n as f32) as i64).min(last) as usize,
        Wrap::ClampToEdge => ((u.clamp(0.0, 1.0) * n as f32) as i64).min(last) as usize,
        Wrap::MirroredRepeat => {
            let i = ((u - 2.0 * (0.5 * u).floor()) * n as f32) as i64;
            mirror(i.min(2 * last + 1), n)
        }
    }
}

/// Texel index `i` (any integer) of an axis of `n` texels, mirrored-repeated: `0..n` as they
/// are, `n..2n` backwards, and so on with period `2n`.
#[inline]
fn mirror(i: i64, n: u32) -> usize {
    let n = i64::from(n);
    let k = i.rem_euclid(2 * n);
    (if k < n { k } else { 2 * n - 1 - k }) as usize
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

/// One grey, opaque 8-bit texel's linear value: its byte through `rgb` in R, G and B, and
/// alpha 1 (`LINEAR_BYTES[255]`, exactly what [`decode_rgba8`] gives an opaque texel).
#[inline]
fn decode_grey8(v: u8, rgb: &[f32; 256]) -> Vec4 {
    let c = rgb[usize::from(v)];
    Vec4::new(c, c, c, 1.0)
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

    /// A 4x1 ramp whose texel `i` has the value `i` (linear, any value allowed in floats).
    fn ramp() -> Texture {
        let texels = (0..4).map(|i| Vec4::splat(i as f32)).collect();
        Texture::from_rgba(4, 1, texels, ColorSpace::Linear).unwrap()
    }

    fn with(wrap_s: Wrap, filter: Filter) -> Sampler {
        Sampler {
            wrap_s,
            wrap_t: Wrap::Repeat,
            filter,
        }
    }

    /// Bilinear values at analytic points: texel `i` has its centre at `(i + 0.5) / 4`.
    #[test]
    fn wrap_modes_bilinear() {
        let t = ramp();
        let at = |u: f32, wrap| {
            t.sample_with(Vec2::new(u, 0.5), with(wrap, Filter::Linear))
                .x
        };
        let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
        // Centres are exact in every mode.
        for wrap in [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat] {
            for i in 0..4 {
                assert!(
                    close(at((i as f32 + 0.5) / 4.0, wrap), i as f32),
                    "{wrap:?} {i}"
                );
            }
            assert!(close(at(0.5, wrap), 1.5));
        }
        // Repeat: u = 0 blends the last and the first texel; the default sampler is repeat.
        assert!(close(at(0.0, Wrap::Repeat), 1.5) && close(at(2.125, Wrap::Repeat), 0.0));
        assert_eq!(
            t.sample(Vec2::new(0.3, 0.5)),
            t.sample_with(Vec2::new(0.3, 0.5), with(Wrap::Repeat, Filter::Linear))
        );
        // Clamp: the edge texels beyond the outer centres, however far.
        for (u, want) in [(0.0, 0.0), (0.1, 0.0), (-7.0, 0.0), (1.0, 3.0), (1e9, 3.0)] {
            assert!(close(at(u, Wrap::ClampToEdge), want), "clamp {u}");
        }
        // Mirrored repeat: u and -u, 2 - u, 2 + u read the same; the edge texel is doubled.
        for (u, want) in [
            (0.0, 0.0),
            (-0.125, 0.0),
            (1.0, 3.0),
            (1.125, 3.0),
            (1.25, 2.5),
            (-0.75, 2.5),
            (2.75, 2.5),
            (-3.25, 2.5),
        ] {
            assert!(
                close(at(u, Wrap::MirroredRepeat), want),
                "mirror {u}: {}",
                at(u, Wrap::MirroredRepeat)
            );
        }
    }

    #[test]
    fn wrap_modes_nearest_and_per_axis() {
        let t = ramp();
        let at = |u: f32, wrap| {
            t.sample_with(Vec2::new(u, 0.5), with(wrap, Filter::Nearest))
                .x
        };
        for (u, repeat, clamp, mirror) in [
            (0.3, 1.0, 1.0, 1.0),
            (0.49, 1.0, 1.0, 1.0),
            (0.51, 2.0, 2.0, 2.0),
            (-0.1, 3.0, 0.0, 0.0),
            (1.1, 0.0, 3.0, 3.0),
            (1.0, 0.0, 3.0, 3.0),
            (1.6, 2.0, 3.0, 1.0),
            (-1.6, 1.0, 0.0, 1.0),
        ] {
            assert_eq!(at(u, Wrap::Repeat), repeat, "repeat {u}");
            assert_eq!(at(u, Wrap::ClampToEdge), clamp, "clamp {u}");
            assert_eq!(at(u, Wrap::MirroredRepeat), mirror, "mirror {u}");
        }
        // Per axis: a 1x4 column clamps along v while u repeats.
        let texels = (0..4).map(|i| Vec4::splat(i as f32)).collect();
        let column = Texture::from_rgba(1, 4, texels, ColorSpace::Linear).unwrap();
        let s = Sampler {
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::ClampToEdge,
            filter: Filter::Nearest,
        };
        assert_eq!(column.sample_with(Vec2::new(-3.3, 1.7), s).x, 3.0);
        assert_eq!(column.sample_with(Vec2::new(5.5, -1.0), s).x, 0.0);
        assert_eq!(column.sample_with(Vec2::new(0.5, 0.6), s).x, 2.0);
    }

    /// KHR_texture_transform is `T * R * S`: scale first, then rotate, then offset.
    #[test]
    fn uv_transform_is_translation_rotation_scale() {
        let m = uv_transform(
            Vec2::new(0.5, 0.0),
            std::f32::consts::FRAC_PI_2,
            Vec2::splat(2.0),
        );
        // (0.25, 0.1) -> S (0.5, 0.2) -> R [0 1; -1 0] (0.2, -0.5) -> T (0.7, -0.5).
        let q = m.transform_point2(Vec2::new(0.25, 0.1));
        assert!((q - Vec2::new(0.7, -0.5)).length() < 1e-6, "{q}");
        assert_eq!(uv_transform(Vec2::ZERO, 0.0, Vec2::ONE), Affine2::IDENTITY);
        // A 4x4 texture of texel (i, j) = i + 4 j, read through an offset of one texel in u
        // and at TEXCOORD_1: uv (0.125, 0.375) lands in texel (1, 1).
        let texels = (0..16).map(|k| Vec4::splat(k as f32)).collect();
        let textures = [Texture::from_rgba(4, 4, texels, ColorSpace::Linear).unwrap()];
        let r = TextureRef {
            texcoord: 1,
            transform: Some(uv_transform(Vec2::new(0.25, 0.0), 0.0, Vec2::ONE)),
            ..TextureRef::new(0)
        };
        let uvs = [Vec2::new(0.875, 0.875), Vec2::new(0.125, 0.375)];
        assert!((r.sample(uvs, &textures).x - 5.0).abs() < 1e-5);
        assert!((TextureRef::new(0).sample(uvs, &textures).x - 15.0).abs() < 1e-5);
    }

    /// The texture of RGBA `bytes` decoded to floats at load time, as 8-bit textures were
    /// before they kept their bytes.
    fn decoded_at_load(width: u32, height: u32, bytes: &[u8], space: ColorSpace) -> Texture {
        let floats = bytes
            .chunks_exact(4)
            .map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 255.0)
            .collect();
        Texture::from_rgba(width, height, floats, space).unwrap()
    }

    /// Bytes kept as bytes sample to exactly the values of decoding them at load time.
    #[test]
    fn rgba8_samples_as_decoded_floats() {
        let mut rng = crate::sampling::Pcg32::new(5, 9);
        let bytes: Vec<u8> = (0..5 * 3 * 4)
            .map(|_| (rng.next_f32() * 256.0) as u8)
            .collect();
        for space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let a = Texture::from_rgba8(5, 3, &bytes, space).unwrap();
            let b = decoded_at_load(5, 3, &bytes, space);
            assert!(a.texels().eq(b.texels()));
            for _ in 0..200 {
                let uv = Vec2::new(rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 4.0 - 2.0);
                assert_eq!(a.sample(uv), b.sample(uv), "{space:?} at {uv}");
            }
        }
        assert!(Texture::from_rgba8(5, 3, &bytes[..56], ColorSpace::Linear).is_none());
    }

    /// A grey, opaque image is kept one byte per texel and samples to exactly the values of
    /// decoding it at load time; one coloured or translucent texel keeps all four bytes.
    #[test]
    fn grey_bytes_sample_as_decoded_floats() {
        let mut rng = crate::sampling::Pcg32::new(7, 3);
        let grey: Vec<u8> = (0..6 * 4)
            .flat_map(|_| {
                let v = (rng.next_f32() * 256.0) as u8;
                [v, v, v, 255]
            })
            .collect();
        for space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let a = Texture::from_rgba8(6, 4, &grey, space).unwrap();
            assert!(matches!(a.texels, Texels::Grey8 { .. }), "{space:?}");
            let b = decoded_at_load(6, 4, &grey, space);
            assert!(a.texels().eq(b.texels()));
            for _ in 0..200 {
                let uv = Vec2::new(rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 4.0 - 2.0);
                for filter in [Filter::Linear, Filter::Nearest] {
                    let s = Sampler {
                        filter,
                        ..Sampler::default()
                    };
                    let (x, y) = (a.sample_with(uv, s), b.sample_with(uv, s));
                    assert_eq!(x, y, "{space:?} {filter:?} at {uv}");
                }
            }
        }
        for (k, v) in [(1, 7), (3, 254)] {
            let mut bytes = grey.clone();
            bytes[4 * 5 + k] = v;
            let t = Texture::from_rgba8(6, 4, &bytes, ColorSpace::Linear).unwrap();
            assert!(matches!(t.texels, Texels::Rgba8 { .. }), "byte {k} = {v}");
        }
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
