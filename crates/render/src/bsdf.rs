//! Reflectance models (INTERFACE SKELETON: bodies are filled in by the BSDF work).
//!
//! Direction convention, stated once for the whole crate: every direction points *away* from
//! the surface point. `wo` points toward the viewer (where the path came from), `wi` toward the
//! light (where the path goes next). Both are in the local shading frame, normal = +Z, so
//! `cos(theta) = w.z`. `eval` returns the BRDF value `f(wo, wi)` WITHOUT the cosine factor
//! (pbrt's convention; Mitsuba's `eval` includes the cosine and swaps the names).
//!
//! No model has a Fresnel term: `ks` is the specular reflectance (the paper's models).

use glam::{Vec2, Vec3};

/// Which part of a model produced a sampled or evaluated contribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    /// The Lambertian part (`kd / pi`).
    Diffuse,
    /// The glossy (microfacet or Phong-like) part; streaks come from it.
    Glossy,
}

/// BRDF values split by lobe, so the integrator can attribute glossy light to the specular layer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LobeValues {
    /// Diffuse part of `f(wo, wi)`.
    pub diffuse: Vec3,
    /// Glossy part of `f(wo, wi)`.
    pub glossy: Vec3,
}

impl LobeValues {
    /// `diffuse + glossy`.
    #[inline]
    pub fn total(&self) -> Vec3 {
        self.diffuse + self.glossy
    }
}

/// The result of sampling a direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Sampled direction toward the light, local frame.
    pub wi: Vec3,
    /// The full `f(wo, wi)` (all lobes), without the cosine.
    pub f: Vec3,
    /// Solid-angle density of `wi` under the whole sampling strategy (lobe choice included).
    pub pdf: f32,
    /// The lobe that was chosen to generate `wi`.
    pub lobe: Lobe,
}

/// `f = kd / pi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Diffuse reflectance (albedo), linear RGB.
    pub kd: Vec3,
}

/// The paper's GGX model: `f = kd/pi + ks D(h) G1(wi) G1(wo) / (4 cos_i cos_o)`; exactly Mitsuba 3's
/// `blendbsdf` (weight 0.5) of `diffuse` (2 kd) and `roughconductor` (ggx, material none, 2 ks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance.
    pub ks: Vec3,
    /// GGX alpha (not a glTF roughness).
    pub alpha: f32,
}

/// The paper's isotropic Ward model:
/// `f = kd/pi + ks exp(-tan^2(delta)/alpha^2) / (4 pi alpha^2 sqrt(cos_i cos_o))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ward {
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance.
    pub ks: Vec3,
    /// Ward alpha (spread of microfacet slopes).
    pub alpha: f32,
}

/// Normalised Blinn-Phong: `f = kd/pi + ks (s+8)/(8 pi) (n.h)^s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhong {
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance.
    pub ks: Vec3,
    /// Shininess exponent `s`.
    pub shininess: f32,
}

/// The glTF 2.0 metallic-roughness BRDF (specification appendix B): Lambert diffuse of
/// `base_color (1 - metallic)` mixed with a GGX/Smith specular lobe of alpha = roughness^2
/// and Schlick Fresnel with F0 = mix(0.04, base_color, metallic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfPbr {
    /// Base colour, linear RGB.
    pub base_color: Vec3,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (alpha = roughness^2).
    pub roughness: f32,
}

/// The closed set of reflectance models; hot calls `match` on it (no trait objects).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian.
    Diffuse(Diffuse),
    /// Paper GGX (Mitsuba-compatible).
    Ggx(Ggx),
    /// Paper Ward.
    Ward(Ward),
    /// Paper Blinn-Phong.
    BlinnPhong(BlinnPhong),
    /// glTF metallic-roughness.
    GltfPbr(GltfPbr),
}

impl Bsdf {
    /// `f(wo, wi)` split by lobe; zero when either direction is below the surface.
    pub fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        let _ = (wo, wi);
        unimplemented!("skeleton")
    }

    /// `f(wo, wi)`, all lobes.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_lobes(wo, wi).total()
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi` given `wo`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let _ = (wo, wi);
        unimplemented!("skeleton")
    }

    /// Samples `wi` given `wo`: `u_lobe` chooses the lobe, `u` samples within it.
    /// `None` when no valid direction results (a failed sample is not an error).
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let _ = (wo, u_lobe, u);
        unimplemented!("skeleton")
    }

    /// Hemispherical albedo estimate used for the albedo layer and for lobe selection.
    pub fn albedo(&self) -> Vec3 {
        unimplemented!("skeleton")
    }
}
