//! Textures (INTERFACE SKELETON, filled in by the scene-loading work).

use glam::{Vec2, Vec4};

/// Index of a texture in [`crate::scene::Scene::textures`].
pub type TextureId = u32;

/// How a texture's texels are stored once decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    /// sRGB-encoded colour data (base colour, emissive): decoded to linear on load.
    Srgb,
    /// Linear data (metallic-roughness, wetness).
    Linear,
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
    /// The filtered value at `uv`.
    pub fn sample(&self, uv: Vec2) -> Vec4 {
        let _ = uv;
        unimplemented!("skeleton")
    }
}
