//! Materials (INTERFACE SKELETON, filled in by the scene-loading work): what a scene stores;
//! [`Material::bsdf_at`] turns one into a [`Bsdf`] at a surface point.

use crate::bsdf::Bsdf;
use crate::texture::{Texture, TextureId};
use glam::{Vec2, Vec3};

/// Which of the paper's models an `extras.streaks` material uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PaperModel {
    /// `"ggx"`.
    Ggx,
    /// `"ward"`.
    Ward,
    /// `"blinn_phong"`.
    BlinnPhong,
}

/// How a material reflects light.
#[derive(Clone, Debug, PartialEq)]
pub enum Reflectance {
    /// Lambertian with an optional texture multiplying `kd`.
    Diffuse {
        /// Diffuse reflectance.
        kd: Vec3,
        /// Optional linear-RGB texture multiplying `kd`.
        kd_texture: Option<TextureId>,
    },
    /// One of the paper's models from `extras.streaks`.
    Paper {
        /// Which model.
        model: PaperModel,
        /// Diffuse reflectance.
        kd: Vec3,
        /// Specular reflectance (the wet value where a wetness map exists).
        ks: Vec3,
        /// Microfacet alpha (ggx, ward); the wet value where a wetness map exists.
        alpha: f32,
        /// Shininess (blinn_phong).
        shininess: f32,
        /// Optional texture multiplying `kd` (the glTF baseColorTexture).
        kd_texture: Option<TextureId>,
        /// Optional wet/dry modulation (see scenes/README.md).
        wetness: Option<Wetness>,
    },
    /// glTF metallic-roughness.
    GltfPbr {
        /// baseColorFactor (linear RGB).
        base_color: Vec3,
        /// baseColorTexture.
        base_color_texture: Option<TextureId>,
        /// metallicFactor.
        metallic: f32,
        /// roughnessFactor.
        roughness: f32,
        /// metallicRoughnessTexture (B = metal, G = roughness).
        metallic_roughness_texture: Option<TextureId>,
    },
}

/// Wet and dry patches: a texture channel gives dryness `w` in [0, 1] (0 = the material's wet
/// `alpha`/`ks`, 1 = `alpha_dry`/`ks_dry`), interpolated linearly.
#[derive(Clone, Debug, PartialEq)]
pub struct Wetness {
    /// The dryness map (green channel of the glTF metallicRoughnessTexture).
    pub texture: TextureId,
    /// Alpha (or, for blinn_phong, shininess) where fully dry.
    pub alpha_dry: f32,
    /// Specular reflectance where fully dry.
    pub ks_dry: Vec3,
}

/// A surface material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name from the scene file (or a generated one), for messages.
    pub name: String,
    /// How it reflects.
    pub reflectance: Reflectance,
    /// Emitted radiance (emissiveFactor x emissive strength), linear RGB.
    pub emission: Vec3,
    /// Optional texture multiplying `emission`.
    pub emission_texture: Option<TextureId>,
    /// Emits (and is shaded) on both faces.
    pub double_sided: bool,
}

impl Material {
    /// The BSDF at texture coordinate `uv`.
    pub fn bsdf_at(&self, uv: Vec2, textures: &[Texture]) -> Bsdf {
        let _ = (uv, textures);
        unimplemented!("skeleton")
    }

    /// Emitted radiance at `uv` (front face; the caller checks sidedness).
    pub fn emission_at(&self, uv: Vec2, textures: &[Texture]) -> Vec3 {
        let _ = (uv, textures);
        unimplemented!("skeleton")
    }

    /// Whether the material emits at all.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}
