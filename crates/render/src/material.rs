//! Materials: what a scene stores; [`Material::bsdf_at`] turns one into a [`Bsdf`] at a
//! surface point, reading the material's textures there.
//!
//! Textures modulate parameters as follows:
//! - [`Reflectance::Diffuse`] and [`Reflectance::Paper`]: the texture's RGB multiplies `kd`.
//! - [`Reflectance::Paper`] with [`Wetness`]: the dryness `w` (green channel of the dryness map)
//!   interpolates `alpha` (or, for blinn_phong, the shininess) and `ks` linearly between the
//!   wet and the dry values.
//! - [`Reflectance::GltfPbr`]: RGB multiplies the base colour; the metallic-roughness texture's
//!   blue channel multiplies `metallic` and its green channel `roughness` (glTF 2.0); the
//!   specular texture's alpha multiplies `specular` and the specular colour texture's RGB
//!   `specular_color` (KHR_materials_specular); the clearcoat texture's red channel multiplies
//!   `clearcoat` and the clearcoat roughness texture's green channel `clearcoat_roughness`
//!   (KHR_materials_clearcoat).
//! - The vertex colour `COLOR_0` (RGB) multiplies the base colour, as glTF says, and so `kd`
//!   of the other models too (white where a scene has none).
//!
//! Each texture is read through its [`TextureRef`] (coordinate set, sampler, uv transform).
//! A material's [`Alpha`] says how much of its surface is there (glTF `alphaMode`, see
//! [`Alpha::stop_probability`]). A normal map ([`Material::normal_map`]) changes the shading
//! normal, not the BSDF: the scene applies it at the hit ([`crate::normal_map`]).

use crate::bsdf::{self, Bsdf};
use crate::geometry::VertexAttributes;
use crate::normal_map::NormalMap;
use crate::texture::{Texture, TextureId, TextureRef};
use glam::{Vec3, Vec4};

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
// The glTF variant holds ten texture references; a scene has few materials and `bsdf_at`
// reads them by reference, so boxing it would only add an indirection per hit.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Reflectance {
    /// Lambertian with an optional texture multiplying `kd`.
    Diffuse {
        /// Diffuse reflectance.
        kd: Vec3,
        /// Optional linear-RGB texture multiplying `kd`.
        kd_texture: Option<TextureRef>,
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
        kd_texture: Option<TextureRef>,
        /// Optional wet/dry modulation (see [`Wetness`] and the `scene` module documentation).
        wetness: Option<Wetness>,
    },
    /// glTF metallic-roughness.
    GltfPbr {
        /// baseColorFactor (linear RGB).
        base_color: Vec3,
        /// baseColorTexture.
        base_color_texture: Option<TextureRef>,
        /// metallicFactor.
        metallic: f32,
        /// roughnessFactor.
        roughness: f32,
        /// metallicRoughnessTexture (B = metal, G = roughness).
        metallic_roughness_texture: Option<TextureRef>,
        /// KHR_materials_specular specularFactor (1 without the extension).
        specular: f32,
        /// KHR_materials_specular specularTexture (A = specular).
        specular_texture: Option<TextureRef>,
        /// KHR_materials_specular specularColorFactor, linear RGB (1 without the extension).
        specular_color: Vec3,
        /// KHR_materials_specular specularColorTexture (RGB, sRGB-encoded).
        specular_color_texture: Option<TextureRef>,
        /// KHR_materials_ior ior (1.5 without the extension; 0 or at least 1).
        ior: f32,
        /// KHR_materials_clearcoat clearcoatFactor (0: no coat).
        clearcoat: f32,
        /// KHR_materials_clearcoat clearcoatTexture (R = clearcoat).
        clearcoat_texture: Option<TextureRef>,
        /// KHR_materials_clearcoat clearcoatRoughnessFactor.
        clearcoat_roughness: f32,
        /// KHR_materials_clearcoat clearcoatRoughnessTexture (G = clearcoat roughness).
        clearcoat_roughness_texture: Option<TextureRef>,
    },
}

/// Wet and dry patches: a texture channel gives dryness `w` in [0, 1] (0 = the material's wet
/// `alpha`/`ks`, 1 = `alpha_dry`/`ks_dry`), interpolated linearly.
#[derive(Clone, Debug, PartialEq)]
pub struct Wetness {
    /// The dryness map (green channel of the glTF metallicRoughnessTexture).
    pub texture: TextureRef,
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
    pub emission_texture: Option<TextureRef>,
    /// Optional tangent-space normal map (glTF `normalTexture`), applied to the shading normal
    /// where the scene has vertex tangents ([`crate::normal_map`]).
    pub normal_map: Option<NormalMap>,
    /// Emits (and is shaded) on both faces.
    pub double_sided: bool,
    /// How much of the surface is there (glTF `alphaMode`).
    pub alpha: Alpha,
}

/// glTF `alphaMode`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// `OPAQUE`: alpha is ignored.
    Opaque,
    /// `MASK`: the surface is there where alpha `>= cutoff` (`alphaCutoff`, default 0.5).
    Mask {
        /// `alphaCutoff`.
        cutoff: f32,
    },
    /// `BLEND`: the surface is there with probability alpha (stochastic transparency).
    Blend,
}

/// A material's coverage: `alpha = factor x texture.a x COLOR_0.a` (glTF: the alpha of the
/// base colour factor, texture and vertex colour), and what it means ([`AlphaMode`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alpha {
    /// How alpha is used.
    pub mode: AlphaMode,
    /// The alpha of baseColorFactor.
    pub factor: f32,
    /// The baseColorTexture, whose alpha channel multiplies `factor`.
    pub texture: Option<TextureRef>,
}

impl Alpha {
    /// An opaque surface.
    pub const OPAQUE: Alpha = Alpha {
        mode: AlphaMode::Opaque,
        factor: 1.0,
        texture: None,
    };

    /// Whether the surface is opaque everywhere (ray queries then skip the alpha test).
    #[inline]
    pub fn is_opaque(&self) -> bool {
        self.mode == AlphaMode::Opaque
    }

    /// The probability that a ray meeting the surface at `at` stops there: 1 for `OPAQUE`; 1
    /// where alpha `>= cutoff` and 0 elsewhere for `MASK`; alpha (clamped to [0, 1]) for
    /// `BLEND`. Ray queries pass through the surface otherwise (deciding `BLEND` by a hash
    /// of the ray, see [`crate::scene::Scene::intersect`]); area lights emit this fraction of
    /// their emission, as many rays as stop there on average.
    #[inline]
    pub fn stop_probability(&self, at: &VertexAttributes, textures: &[Texture]) -> f32 {
        let alpha = || {
            let t = self.texture.map_or(1.0, |t| t.sample(at.uv, textures).w);
            self.factor * t * at.color.w
        };
        match self.mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask { cutoff } => f32::from(u8::from(alpha() >= cutoff)),
            AlphaMode::Blend => alpha().clamp(0.0, 1.0),
        }
    }
}

/// The texture's value at `at`, or one where there is no texture (or the id is out of range,
/// which [`crate::scene::Scene::from_parts`] rules out).
#[inline]
fn sample_or_one(texture: Option<TextureRef>, at: &VertexAttributes, textures: &[Texture]) -> Vec4 {
    texture.map_or(Vec4::ONE, |t| t.sample(at.uv, textures))
}

impl Material {
    /// A non-emissive, one-sided Lambertian material of albedo `kd`.
    pub fn diffuse(name: impl Into<String>, kd: Vec3) -> Self {
        Self {
            name: name.into(),
            reflectance: Reflectance::Diffuse {
                kd,
                kd_texture: None,
            },
            emission: Vec3::ZERO,
            emission_texture: None,
            normal_map: None,
            double_sided: false,
            alpha: Alpha::OPAQUE,
        }
    }

    /// Every texture the material refers to.
    pub fn texture_ids(&self) -> impl Iterator<Item = TextureId> + '_ {
        self.texture_refs().map(|t| t.texture)
    }

    /// Every texture reference the material holds.
    pub fn texture_refs(&self) -> impl Iterator<Item = TextureRef> + '_ {
        let r = match &self.reflectance {
            Reflectance::Diffuse { kd_texture, .. } => [*kd_texture, None, None, None, None, None],
            Reflectance::Paper {
                kd_texture,
                wetness,
                ..
            } => [
                *kd_texture,
                wetness.as_ref().map(|w| w.texture),
                None,
                None,
                None,
                None,
            ],
            Reflectance::GltfPbr {
                base_color_texture,
                metallic_roughness_texture,
                specular_texture,
                specular_color_texture,
                clearcoat_texture,
                clearcoat_roughness_texture,
                ..
            } => [
                *base_color_texture,
                *metallic_roughness_texture,
                *specular_texture,
                *specular_color_texture,
                *clearcoat_texture,
                *clearcoat_roughness_texture,
            ],
        };
        r.into_iter()
            .chain([
                self.emission_texture,
                self.alpha.texture,
                self.normal_map.map(|n| n.texture),
            ])
            .flatten()
    }

    /// The BSDF at a point with vertex attributes `at`.
    pub fn bsdf_at(&self, at: &VertexAttributes, textures: &[Texture]) -> Bsdf {
        let vertex_color = at.color.truncate();
        match &self.reflectance {
            Reflectance::Diffuse { kd, kd_texture } => Bsdf::Diffuse(bsdf::Diffuse {
                kd: *kd * sample_or_one(*kd_texture, at, textures).truncate() * vertex_color,
            }),
            Reflectance::Paper {
                model,
                kd,
                ks,
                alpha,
                shininess,
                kd_texture,
                wetness,
            } => {
                let kd = *kd * sample_or_one(*kd_texture, at, textures).truncate() * vertex_color;
                let (mut ks, mut alpha, mut shininess) = (*ks, *alpha, *shininess);
                if let Some(w) = wetness {
                    let dry = sample_or_one(Some(w.texture), at, textures)
                        .y
                        .clamp(0.0, 1.0);
                    ks = ks.lerp(w.ks_dry, dry);
                    match model {
                        PaperModel::BlinnPhong => shininess += (w.alpha_dry - shininess) * dry,
                        PaperModel::Ggx | PaperModel::Ward => alpha += (w.alpha_dry - alpha) * dry,
                    }
                }
                match model {
                    PaperModel::Ggx => Bsdf::Ggx(bsdf::Ggx { kd, ks, alpha }),
                    PaperModel::Ward => Bsdf::Ward(bsdf::Ward { kd, ks, alpha }),
                    PaperModel::BlinnPhong => {
                        Bsdf::BlinnPhong(bsdf::BlinnPhong { kd, ks, shininess })
                    }
                }
            }
            Reflectance::GltfPbr {
                base_color,
                base_color_texture,
                metallic,
                roughness,
                metallic_roughness_texture,
                specular,
                specular_texture,
                specular_color,
                specular_color_texture,
                ior,
                clearcoat,
                clearcoat_texture,
                clearcoat_roughness,
                clearcoat_roughness_texture,
            } => {
                let mr = sample_or_one(*metallic_roughness_texture, at, textures);
                let sample = |t: &Option<TextureRef>| sample_or_one(*t, at, textures);
                Bsdf::GltfPbr(bsdf::GltfPbr {
                    base_color: *base_color * sample(base_color_texture).truncate() * vertex_color,
                    metallic: (*metallic * mr.z).clamp(0.0, 1.0),
                    roughness: (*roughness * mr.y).clamp(0.0, 1.0),
                    specular: (*specular * sample(specular_texture).w).clamp(0.0, 1.0),
                    specular_color: (*specular_color * sample(specular_color_texture).truncate())
                        .max(Vec3::ZERO),
                    ior: *ior,
                    clearcoat: (*clearcoat * sample(clearcoat_texture).x).clamp(0.0, 1.0),
                    clearcoat_roughness: (*clearcoat_roughness
                        * sample(clearcoat_roughness_texture).y)
                        .clamp(0.0, 1.0),
                })
            }
        }
    }

    /// Emitted radiance at a point with vertex attributes `at` (front face; the caller checks
    /// sidedness). The vertex colour does not change it (glTF's COLOR_0 is a base colour).
    #[inline]
    pub fn emission_at(&self, at: &VertexAttributes, textures: &[Texture]) -> Vec3 {
        if self.emission_texture.is_none() {
            return self.emission;
        }
        self.emission * sample_or_one(self.emission_texture, at, textures).truncate()
    }

    /// Whether the material emits at all.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::ColorSpace;
    use glam::Vec2;

    fn at(u: f32, v: f32) -> VertexAttributes {
        VertexAttributes::from_uv(Vec2::new(u, v))
    }

    #[test]
    fn wetness_interpolates_alpha_and_ks_and_texture_multiplies_kd() {
        // Dryness map: left texel wet (G = 0), right texel dry (G = 1).
        let dry_map = Texture::from_rgba(
            2,
            1,
            vec![Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, 1.0)],
            ColorSpace::Linear,
        )
        .unwrap();
        let kd_map = Texture::from_rgba(
            1,
            1,
            vec![Vec4::new(0.5, 1.0, 0.25, 1.0)],
            ColorSpace::Linear,
        )
        .unwrap();
        let m = Material {
            name: "road".into(),
            reflectance: Reflectance::Paper {
                model: PaperModel::Ggx,
                kd: Vec3::splat(0.4),
                ks: Vec3::splat(0.8),
                alpha: 0.05,
                shininess: 0.0,
                kd_texture: Some(TextureRef::new(1)),
                wetness: Some(Wetness {
                    texture: TextureRef::new(0),
                    alpha_dry: 0.45,
                    ks_dry: Vec3::splat(0.1),
                }),
            },
            emission: Vec3::ZERO,
            emission_texture: None,
            normal_map: None,
            double_sided: false,
            alpha: Alpha::OPAQUE,
        };
        let textures = [dry_map, kd_map];
        let Bsdf::Ggx(wet) = m.bsdf_at(&at(0.25, 0.5), &textures) else {
            panic!("not ggx")
        };
        assert!((wet.alpha - 0.05).abs() < 1e-6 && (wet.ks.x - 0.8).abs() < 1e-6);
        assert!((wet.kd - Vec3::new(0.2, 0.4, 0.1)).length() < 1e-6);
        let Bsdf::Ggx(dry) = m.bsdf_at(&at(0.75, 0.5), &textures) else {
            panic!("not ggx")
        };
        assert!((dry.alpha - 0.45).abs() < 1e-6 && (dry.ks.x - 0.1).abs() < 1e-6);
        let Bsdf::Ggx(half) = m.bsdf_at(&at(0.5, 0.5), &textures) else {
            panic!("not ggx")
        };
        assert!((half.alpha - 0.25).abs() < 1e-6, "{}", half.alpha);
        assert_eq!(m.texture_ids().collect::<Vec<_>>(), vec![1, 0]);
    }

    #[test]
    fn pbr_texture_channels_and_emission() {
        let mr = Texture::from_rgba(
            1,
            1,
            vec![Vec4::new(0.0, 0.5, 0.25, 1.0)],
            ColorSpace::Linear,
        )
        .unwrap();
        let mut m = Material::diffuse("m", Vec3::ONE);
        m.reflectance = Reflectance::GltfPbr {
            base_color: Vec3::splat(0.5),
            base_color_texture: None,
            metallic: 1.0,
            roughness: 0.8,
            metallic_roughness_texture: Some(TextureRef::new(0)),
            specular: 0.5,
            specular_texture: Some(TextureRef::new(0)),
            specular_color: Vec3::new(2.0, 1.0, 0.5),
            specular_color_texture: Some(TextureRef::new(0)),
            ior: 1.33,
            clearcoat: 0.8,
            clearcoat_texture: Some(TextureRef::new(0)),
            clearcoat_roughness: 0.6,
            clearcoat_roughness_texture: Some(TextureRef::new(0)),
        };
        m.emission = Vec3::new(2.0, 0.0, 1.0);
        m.emission_texture = Some(TextureRef::new(0));
        let Bsdf::GltfPbr(b) = m.bsdf_at(&at(0.0, 0.0), std::slice::from_ref(&mr)) else {
            panic!("not pbr")
        };
        assert!((b.metallic - 0.25).abs() < 1e-6 && (b.roughness - 0.4).abs() < 1e-6);
        // Texel (0, 0.5, 0.25, 1): specular x A, colour x RGB, clearcoat x R, its roughness x G.
        assert_eq!(b.specular, 0.5);
        assert_eq!(b.specular_color, Vec3::new(0.0, 0.5, 0.125));
        assert_eq!(b.ior, 1.33);
        assert_eq!((b.clearcoat, b.clearcoat_roughness), (0.0, 0.3));
        assert_eq!(
            m.emission_at(&at(0.0, 0.0), &[mr]),
            Vec3::new(0.0, 0.0, 0.25)
        );
        assert!(m.is_emissive());
    }
}
