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
//!   `specular_color` (KHR_materials_specular); the sheen colour texture's RGB multiplies
//!   `sheen_color` and the sheen roughness texture's alpha `sheen_roughness`
//!   (KHR_materials_sheen); the iridescence texture's red channel multiplies `iridescence`
//!   and the thickness texture's green channel blends the film's thickness from its minimum
//!   to its maximum (KHR_materials_iridescence); the clearcoat texture's red channel multiplies
//!   `clearcoat` and the clearcoat roughness texture's green channel `clearcoat_roughness`
//!   (KHR_materials_clearcoat); the transmission texture's red channel multiplies
//!   `transmission` (KHR_materials_transmission).
//! - The vertex colour `COLOR_0` (RGB) multiplies the base colour, as glTF says, and so `kd`
//!   of the other models too (white where a scene has none).
//!
//! Each texture is read through its [`TextureRef`] (coordinate set, sampler, uv transform).
//! A material's [`Alpha`] says how much of its surface is there (glTF `alphaMode`, see
//! [`Alpha::stop_probability`]). A normal map ([`Material::normal_map`]) changes the shading
//! normal, not the BSDF: the scene applies it at the hit ([`crate::normal_map`]), and so
//! does a clear coat's normal map ([`Material::coat_normal_map`]), whose normal the
//! integrator gives the BSDF ([`Bsdf::with_coat_normal`]).

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

/// Glass beads in a paper `ggx` material (`extras.streaks.kr`, `retro_width`): the
/// retroreflective cone of [`bsdf::Retroreflective`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Retro {
    /// The cone's reflectance.
    pub kr: Vec3,
    /// The cone's exponent (its width is `1 / sqrt(exponent)` radians).
    pub exponent: f32,
}

/// How a material reflects light.
// The glTF variant holds eleven texture references; a scene has few materials and `bsdf_at`
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
        /// Glass beads (ggx only): the retroreflective cone of [`bsdf::Retroreflective`]; the
        /// dryness map does not change it.
        retro: Option<Retro>,
    },
    /// glTF metallic-roughness with its extensions' parameters.
    GltfPbr(GltfPbrParams),
    /// KHR_materials_unlit: reflects nothing; what is seen is the material's emission, which
    /// the loader sets to the base colour (factor, texture), and which the vertex colour
    /// multiplies ([`Material::emission_at`]). Like any emitter it lights other surfaces.
    Unlit,
}

/// The parameters of a glTF metallic-roughness material and of the material extensions the
/// loader honours, each factor with its optional texture. [`Default`] gives the glTF defaults
/// (white, metallic 1, roughness 1, and every extension absent).
#[derive(Clone, Debug, PartialEq)]
pub struct GltfPbrParams {
    /// baseColorFactor (linear RGB).
    pub base_color: Vec3,
    /// baseColorTexture.
    pub base_color_texture: Option<TextureRef>,
    /// metallicFactor.
    pub metallic: f32,
    /// roughnessFactor.
    pub roughness: f32,
    /// metallicRoughnessTexture (B = metal, G = roughness).
    pub metallic_roughness_texture: Option<TextureRef>,
    /// KHR_materials_specular specularFactor (1 without the extension).
    pub specular: f32,
    /// KHR_materials_specular specularTexture (A = specular).
    pub specular_texture: Option<TextureRef>,
    /// KHR_materials_specular specularColorFactor, linear RGB (1 without the extension).
    pub specular_color: Vec3,
    /// KHR_materials_specular specularColorTexture (RGB, sRGB-encoded).
    pub specular_color_texture: Option<TextureRef>,
    /// KHR_materials_ior ior (1.5 without the extension; 0 or at least 1).
    pub ior: f32,
    /// KHR_materials_sheen sheenColorFactor, linear RGB in [0, 1] (black: no sheen).
    pub sheen_color: Vec3,
    /// KHR_materials_sheen sheenColorTexture (RGB, sRGB-encoded).
    pub sheen_color_texture: Option<TextureRef>,
    /// KHR_materials_sheen sheenRoughnessFactor in [0, 1].
    pub sheen_roughness: f32,
    /// KHR_materials_sheen sheenRoughnessTexture (A = sheen roughness).
    pub sheen_roughness_texture: Option<TextureRef>,
    /// KHR_materials_iridescence iridescenceFactor in [0, 1] (0: no thin film).
    pub iridescence: f32,
    /// KHR_materials_iridescence iridescenceTexture (R = iridescence).
    pub iridescence_texture: Option<TextureRef>,
    /// KHR_materials_iridescence iridescenceIor (1.3 by default).
    pub iridescence_ior: f32,
    /// KHR_materials_iridescence iridescenceThicknessMinimum and Maximum, in nanometres.
    pub iridescence_thickness: [f32; 2],
    /// KHR_materials_iridescence iridescenceThicknessTexture (G blends from the minimum to
    /// the maximum thickness; without it the thickness is the maximum).
    pub iridescence_thickness_texture: Option<TextureRef>,
    /// KHR_materials_clearcoat clearcoatFactor (0: no coat).
    pub clearcoat: f32,
    /// KHR_materials_clearcoat clearcoatTexture (R = clearcoat).
    pub clearcoat_texture: Option<TextureRef>,
    /// KHR_materials_clearcoat clearcoatRoughnessFactor.
    pub clearcoat_roughness: f32,
    /// KHR_materials_clearcoat clearcoatRoughnessTexture (G = clearcoat roughness).
    pub clearcoat_roughness_texture: Option<TextureRef>,
    /// KHR_materials_clearcoat clearcoatNormalTexture: the coat's own tangent-space normal
    /// map (in the base's tangent frame). Without it the coat is shaded with the interpolated
    /// normal, not the base's mapped one, as the extension says.
    pub clearcoat_normal_map: Option<NormalMap>,
    /// KHR_materials_transmission transmissionFactor in [0, 1] (0: opaque).
    pub transmission: f32,
    /// KHR_materials_transmission transmissionTexture (R = transmission).
    pub transmission_texture: Option<TextureRef>,
    /// KHR_materials_volume with a thickness above 0: the surface bounds a closed volume
    /// (refraction and absorption inside); `None` is a thin-walled surface.
    pub volume: Option<Volume>,
}

/// The glTF defaults.
impl Default for GltfPbrParams {
    fn default() -> Self {
        GltfPbrParams {
            base_color: Vec3::ONE,
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            specular: 1.0,
            specular_texture: None,
            specular_color: Vec3::ONE,
            specular_color_texture: None,
            ior: 1.5,
            sheen_color: Vec3::ZERO,
            sheen_color_texture: None,
            sheen_roughness: 0.0,
            sheen_roughness_texture: None,
            iridescence: 0.0,
            iridescence_texture: None,
            iridescence_ior: 1.3,
            iridescence_thickness: [100.0, 400.0],
            iridescence_thickness_texture: None,
            clearcoat: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness: 0.0,
            clearcoat_roughness_texture: None,
            clearcoat_normal_map: None,
            transmission: 0.0,
            transmission_texture: None,
            volume: None,
        }
    }
}

/// KHR_materials_volume: the medium inside a closed surface, which absorbs by Beer-Lambert's
/// law. Light that travels a distance `d` inside keeps `exp(-sigma_a d)` of its radiance, with
/// `sigma_a = -ln(attenuationColor) / attenuationDistance` per channel, so that at
/// `attenuationDistance` the transmitted colour is `attenuationColor` (the extension's
/// definition).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volume {
    /// thicknessFactor (> 0; the thickness texture is not used: the extension says ray tracers
    /// should use the distance travelled inside, which the path tracer measures).
    pub thickness: f32,
    /// The absorption coefficient `sigma_a` per channel, 1/m (0: clear).
    pub sigma_a: Vec3,
}

impl Volume {
    /// The medium of attenuationColor `color` and attenuationDistance `distance` (infinite:
    /// no absorption).
    pub fn new(thickness: f32, color: Vec3, distance: f32) -> Self {
        let sigma_a = if distance.is_finite() && distance > 0.0 {
            Vec3::from_array(color.to_array().map(|c| -c.max(1e-30).ln() / distance))
        } else {
            Vec3::ZERO
        };
        Volume {
            thickness,
            sigma_a: sigma_a.max(Vec3::ZERO),
        }
    }

    /// Beer-Lambert transmittance over `distance` inside the medium.
    #[inline]
    pub fn transmittance(&self, distance: f32) -> Vec3 {
        if self.sigma_a == Vec3::ZERO {
            Vec3::ONE
        } else {
            (-self.sigma_a * distance).exp()
        }
    }
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
    /// The road surface of the scene contract (`extras.streaks.road: true`): datasets mark
    /// the pixels whose first hit has such a material.
    pub road: bool,
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
            road: false,
        }
    }

    /// An untextured, dry-everywhere GGX road surface (the paper's model) of diffuse albedo
    /// `kd`, specular reflectance `ks` and roughness `alpha`, marked as road for the road mask.
    pub fn glossy_road(name: impl Into<String>, kd: Vec3, ks: Vec3, alpha: f32) -> Self {
        Self {
            reflectance: Reflectance::Paper {
                model: PaperModel::Ggx,
                kd,
                ks,
                alpha,
                shininess: 0.0,
                kd_texture: None,
                wetness: None,
                retro: None,
            },
            road: true,
            ..Self::diffuse(name, Vec3::ZERO)
        }
    }

    /// Every texture the material refers to.
    pub fn texture_ids(&self) -> impl Iterator<Item = TextureId> + '_ {
        self.texture_refs().map(|t| t.texture)
    }

    /// Every texture reference the material holds.
    pub fn texture_refs(&self) -> impl Iterator<Item = TextureRef> + '_ {
        let r = match &self.reflectance {
            Reflectance::Diffuse { kd_texture, .. } => [
                *kd_texture,
                None,
                None,
                None,
                None,
                None,
                None,
                None,
                None,
                None,
                None,
            ],
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
                None,
                None,
                None,
                None,
                None,
            ],
            Reflectance::Unlit => [None; 11],
            Reflectance::GltfPbr(g) => [
                g.base_color_texture,
                g.metallic_roughness_texture,
                g.specular_texture,
                g.specular_color_texture,
                g.sheen_color_texture,
                g.sheen_roughness_texture,
                g.iridescence_texture,
                g.iridescence_thickness_texture,
                g.clearcoat_texture,
                g.clearcoat_roughness_texture,
                g.transmission_texture,
            ],
        };
        r.into_iter()
            .chain([
                self.emission_texture,
                self.alpha.texture,
                self.normal_map.map(|n| n.texture),
                self.coat_normal_map().map(|n| n.texture),
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
                retro,
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
                    PaperModel::Ggx => match retro {
                        Some(r) => Bsdf::Retroreflective(bsdf::Retroreflective {
                            kd,
                            ks,
                            alpha,
                            kr: r.kr,
                            exponent: r.exponent,
                        }),
                        None => Bsdf::Ggx(bsdf::Ggx { kd, ks, alpha }),
                    },
                    PaperModel::Ward => Bsdf::Ward(bsdf::Ward { kd, ks, alpha }),
                    PaperModel::BlinnPhong => {
                        Bsdf::BlinnPhong(bsdf::BlinnPhong { kd, ks, shininess })
                    }
                }
            }
            Reflectance::GltfPbr(g) => {
                let sample = |t: Option<TextureRef>| sample_or_one(t, at, textures);
                let mr = sample(g.metallic_roughness_texture);
                Bsdf::GltfPbr(bsdf::GltfPbr {
                    base_color: g.base_color
                        * sample(g.base_color_texture).truncate()
                        * vertex_color,
                    metallic: (g.metallic * mr.z).clamp(0.0, 1.0),
                    roughness: (g.roughness * mr.y).clamp(0.0, 1.0),
                    specular: (g.specular * sample(g.specular_texture).w).clamp(0.0, 1.0),
                    specular_color: (g.specular_color
                        * sample(g.specular_color_texture).truncate())
                    .max(Vec3::ZERO),
                    ior: g.ior,
                    sheen_color: if g.sheen_color.max_element() > 0.0 {
                        (g.sheen_color * sample(g.sheen_color_texture).truncate())
                            .clamp(Vec3::ZERO, Vec3::ONE)
                    } else {
                        Vec3::ZERO
                    },
                    sheen_roughness: (g.sheen_roughness * sample(g.sheen_roughness_texture).w)
                        .clamp(0.0, 1.0),
                    iridescence: if g.iridescence > 0.0 {
                        (g.iridescence * sample(g.iridescence_texture).x).clamp(0.0, 1.0)
                    } else {
                        0.0
                    },
                    iridescence_ior: g.iridescence_ior,
                    iridescence_thickness: {
                        let [min, max] = g.iridescence_thickness;
                        match g.iridescence_thickness_texture {
                            Some(t) => min + (max - min) * sample(Some(t)).y,
                            None => max,
                        }
                    },
                    clearcoat: (g.clearcoat * sample(g.clearcoat_texture).x).clamp(0.0, 1.0),
                    clearcoat_roughness: (g.clearcoat_roughness
                        * sample(g.clearcoat_roughness_texture).y)
                        .clamp(0.0, 1.0),
                    coat_normal: Vec3::Z,
                    transmission: if g.transmission > 0.0 {
                        (g.transmission * sample(g.transmission_texture).x).clamp(0.0, 1.0)
                    } else {
                        0.0
                    },
                    thin_walled: g.volume.is_none(),
                    inside: false,
                })
            }
            Reflectance::Unlit => Bsdf::Diffuse(bsdf::Diffuse { kd: Vec3::ZERO }),
        }
    }

    /// Emitted radiance at a point with vertex attributes `at` (front face; the caller checks
    /// sidedness). The vertex colour does not change it (glTF's COLOR_0 is a base colour),
    /// except on an unlit material, whose emission is its base colour.
    #[inline]
    pub fn emission_at(&self, at: &VertexAttributes, textures: &[Texture]) -> Vec3 {
        let emission = match self.emission_texture {
            None => self.emission,
            texture => self.emission * sample_or_one(texture, at, textures).truncate(),
        };
        match self.reflectance {
            Reflectance::Unlit => emission * at.color.truncate(),
            _ => emission,
        }
    }

    /// Whether the material has a clear coat (KHR_materials_clearcoat with a factor above 0),
    /// whose normal may differ from the shading normal.
    #[inline]
    pub fn has_coat(&self) -> bool {
        matches!(&self.reflectance, Reflectance::GltfPbr(g) if g.clearcoat > 0.0)
    }

    /// The clear coat's normal map (clearcoatNormalTexture), where the material has a coat.
    #[inline]
    pub fn coat_normal_map(&self) -> Option<NormalMap> {
        match &self.reflectance {
            Reflectance::GltfPbr(g) if g.clearcoat > 0.0 => g.clearcoat_normal_map,
            _ => None,
        }
    }

    /// The normal map that tangents are generated for (MikkTSpace in its texture space): the
    /// base's, else the coat's; `None` when the material needs no tangents.
    #[inline]
    pub fn tangent_space_map(&self) -> Option<NormalMap> {
        self.normal_map.or(self.coat_normal_map())
    }

    /// The medium inside the material's surface (KHR_materials_volume), if it bounds one.
    #[inline]
    pub fn volume(&self) -> Option<Volume> {
        match &self.reflectance {
            Reflectance::GltfPbr(g) => g.volume,
            _ => None,
        }
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
                retro: None,
            },
            emission: Vec3::ZERO,
            emission_texture: None,
            normal_map: None,
            double_sided: false,
            alpha: Alpha::OPAQUE,
            road: false,
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
        m.reflectance = Reflectance::GltfPbr(GltfPbrParams {
            base_color: Vec3::splat(0.5),
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
            transmission: 0.5,
            transmission_texture: Some(TextureRef::new(0)),
            ..GltfPbrParams::default()
        });
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
        // Transmission x R.
        assert_eq!((b.transmission, b.thin_walled), (0.0, true));
        assert_eq!(
            m.emission_at(&at(0.0, 0.0), &[mr]),
            Vec3::new(0.0, 0.0, 0.25)
        );
        assert!(m.is_emissive());
    }
}
