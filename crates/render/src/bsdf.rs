//! Reflectance models: Lambertian, the paper's `ggx`, `ward` and `blinn_phong`, and the glTF 2.0
//! metallic-roughness BRDF, as one closed enum [`Bsdf`] with `eval`, `pdf` and `sample`.
//!
//! Direction convention, stated once for the whole crate: every direction points *away* from
//! the surface point. `wo` points toward the viewer (where the path came from), `wi` toward the
//! light (where the path goes next). Both are in the local shading frame, normal = +Z, so
//! `cos(theta) = w.z`. `eval` returns the BRDF value `f(wo, wi)` WITHOUT the cosine factor
//! (pbrt's convention; Mitsuba's `eval` includes the cosine and swaps the names).
//!
//! No paper model has a Fresnel term: `ks` is the specular reflectance. Only [`GltfPbr`] has one
//! (Schlick's, as the glTF specification says).
//!
//! Sampling: every model with both lobes picks the glossy lobe with a probability that depends
//! only on `wo`: proportional to an estimate of the two lobes' directional albedos for this `wo`
//! (`luminance(ks)` times a cheap closed-form factor against `luminance(kd)`), clamped to
//! `[0.05, 0.95]`, and exactly 0 or 1 when one lobe is black. So a dark wet road (small `kd`,
//! large `ks`) spends almost all its samples on the glossy lobe. [`Bsdf::pdf`] returns the same
//! mixture density [`Bsdf::sample`] draws from, and `sample().f == eval()`,
//! `sample().pdf == pdf()` exactly. The diffuse lobe is sampled cosine-weighted; the glossy
//! lobes: GGX by visible normals (Dupuy and Benyoub 2023, "Sampling Visible GGX Normals with
//! Spherical Caps", which draws exactly Heitz 2018's distribution), Ward by the Gaussian in
//! `tan(delta)` (Walter 2005, "Notes on the Ward BRDF"), Blinn-Phong by `cos^s` of the half
//! vector. Mass that the glossy lobe sends below the horizon is lost (the sample returns `None`
//! and `pdf` integrates to less than 1): the estimators stay unbiased.
//!
//! The chi-square, reciprocity, white-furnace and Mitsuba-identity tests are at the bottom of
//! this file; [`crate::testing::check_bsdf`] checks a model for one `wo`.

use crate::sampling::{luminance, square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI, TAU};

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
/// and Schlick Fresnel with F0 = mix(0.04, base_color, metallic):
/// `f = (1 - F) c_diff / pi + F D G1(wi) G1(wo) / (4 cos_i cos_o)`, `F = F0 + (1 - F0)(1 - |wo.h|)^5`.
/// The visibility is the specification's *separable* Smith-GGX form (the same `G1` as [`Ggx`]),
/// not the height-correlated alternative, so both GGX models share one masking function and
/// one visible-normal sampling routine.
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

// ---------------------------------------------------------------------------------------------
// Shared pieces

/// Bounds of the glossy-lobe probability when both lobes are non-zero.
const MIN_LOBE_PROBABILITY: f32 = 0.05;

/// Mirror `wo` about `h`.
#[inline]
fn reflect(wo: Vec3, h: Vec3) -> Vec3 {
    2.0 * wo.dot(h) * h - wo
}

/// Half vector of two directions above the surface (`h.z > 0`).
#[inline]
fn half_vector(wo: Vec3, wi: Vec3) -> Vec3 {
    (wo + wi).normalize()
}

/// The glossy-lobe probability from the two lobes' albedo estimates for this `wo`:
/// exactly 0 (1) when the glossy (diffuse) lobe is black, else clamped to `[0.05, 0.95]`.
#[inline]
fn glossy_probability(ks_luminance: f32, glossy_factor: f32, diffuse_weight: f32) -> f32 {
    if ks_luminance <= 0.0 {
        0.0
    } else if diffuse_weight <= 0.0 {
        1.0
    } else {
        let g = ks_luminance * glossy_factor;
        (g / (g + diffuse_weight)).clamp(MIN_LOBE_PROBABILITY, 1.0 - MIN_LOBE_PROBABILITY)
    }
}

/// GGX (Trowbridge-Reitz) normal distribution `D(h)`, as Mitsuba 3's `MicrofacetDistribution::eval`
/// (including its cut-off of values below 1e-20).
#[inline]
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
    let d = 1.0 / (PI * a2 * t * t);
    if d * h.z > 1e-20 {
        d
    } else {
        0.0
    }
}

/// Separable Smith masking `G1(v, h)` for GGX, as Mitsuba 3's `smith_g1`:
/// `2 / (1 + sqrt(1 + alpha^2 tan^2(theta_v)))`, 0 when `v` sees the back of the microfacet.
#[inline]
pub fn ggx_smith_g1(v: Vec3, h: Vec3, alpha: f32) -> f32 {
    if v.dot(h) * v.z <= 0.0 {
        return 0.0;
    }
    let xy_alpha_2 = alpha * alpha * (v.x * v.x + v.y * v.y);
    if xy_alpha_2 == 0.0 {
        return 1.0;
    }
    let tan_theta_alpha_2 = xy_alpha_2 / (v.z * v.z);
    2.0 / (1.0 + (1.0 + tan_theta_alpha_2).sqrt())
}

/// Samples a GGX visible normal for `wo` (density `D(h) G1(wo, h) max(0, wo.h) / wo.z`) by
/// Dupuy and Benyoub's spherical caps. `None` only in a degenerate (measure-zero) case.
#[inline]
fn sample_ggx_visible_normal(wo: Vec3, alpha: f32, u: Vec2) -> Option<Vec3> {
    debug_assert!(wo.z > 0.0);
    // Stretch to the hemisphere configuration (alpha = 1).
    let wo_std = Vec3::new(wo.x * alpha, wo.y * alpha, wo.z).normalize();
    // Sample the spherical cap in (-wo_std.z, 1].
    let phi = TAU * u.x;
    let z = (1.0 - u.y) * (1.0 + wo_std.z) - wo_std.z;
    let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
    let (s, c) = phi.sin_cos();
    let h_std = Vec3::new(sin_theta * c, sin_theta * s, z) + wo_std;
    // Unstretch.
    let h = Vec3::new(h_std.x * alpha, h_std.y * alpha, h_std.z.max(0.0)).normalize_or_zero();
    (h.z > 0.0).then_some(h)
}

/// Solid-angle density of `wi` when the GGX glossy lobe samples visible normals:
/// `D(h) G1(wo, h) / (4 wo.z)` (the Jacobian `1 / (4 wo.h)` cancels `wo.h`).
#[inline]
fn ggx_visible_pdf(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    let h = half_vector(wo, wi);
    ggx_d(h, alpha) * ggx_smith_g1(wo, h, alpha) / (4.0 * wo.z)
}

/// Hemisphere check shared by every model.
#[inline]
fn above(wo: Vec3, wi: Vec3) -> bool {
    wo.z > 0.0 && wi.z > 0.0
}

// ---------------------------------------------------------------------------------------------
// The models: each gives its lobes, the glossy lobe's pdf and sampling, and the lobe choice.

impl Diffuse {
    #[inline]
    fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        if !above(wo, wi) {
            return LobeValues::default();
        }
        LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: Vec3::ZERO,
        }
    }
}

impl Ggx {
    #[inline]
    fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        if !above(wo, wi) {
            return LobeValues::default();
        }
        let h = half_vector(wo, wi);
        let spec = ggx_d(h, self.alpha)
            * ggx_smith_g1(wo, h, self.alpha)
            * ggx_smith_g1(wi, h, self.alpha)
            / (4.0 * wo.z * wi.z);
        LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: self.ks * spec,
        }
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        // Directional albedo of the glossy lobe ~ G1(wo) (exact for small alpha, close otherwise).
        let g1 = ggx_smith_g1(wo, Vec3::Z, self.alpha);
        glossy_probability(luminance(self.ks), g1, luminance(self.kd))
    }
}

impl Ward {
    /// The normalised slope density's solid-angle form `exp(-tan^2/alpha^2) / (pi alpha^2 cos^3)`
    /// (density of the sampled half vector).
    #[inline]
    fn half_vector_pdf(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let tan2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        (-tan2 / a2).exp() / (PI * a2 * h.z * h.z * h.z)
    }

    #[inline]
    fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        if !above(wo, wi) {
            return LobeValues::default();
        }
        let h = half_vector(wo, wi);
        let a2 = self.alpha * self.alpha;
        let tan2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        let spec = (-tan2 / a2).exp() / (4.0 * PI * a2 * (wo.z * wi.z).sqrt());
        LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: self.ks * spec,
        }
    }

    #[inline]
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = half_vector(wo, wi);
        self.half_vector_pdf(h) / (4.0 * wo.dot(h))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        // tan^2(delta) = -alpha^2 ln(1 - u): 1 - u is in (0, 1], so the log is finite.
        let tan2 = -self.alpha * self.alpha * (1.0 - u.x).ln();
        let cos_d = 1.0 / (1.0 + tan2).sqrt();
        let sin_d = (tan2 * cos_d * cos_d).sqrt();
        let (s, c) = (TAU * u.y).sin_cos();
        let h = Vec3::new(sin_d * c, sin_d * s, cos_d);
        (wo.dot(h) > 0.0).then(|| reflect(wo, h))
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        // For small alpha the glossy albedo of this Ward form is ~ ks cos(theta_o).
        glossy_probability(luminance(self.ks), wo.z, luminance(self.kd))
    }
}

impl BlinnPhong {
    #[inline]
    fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        if !above(wo, wi) {
            return LobeValues::default();
        }
        let h = half_vector(wo, wi);
        let s = self.shininess;
        let spec = (s + 8.0) / (8.0 * PI) * h.z.powf(s);
        LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: self.ks * spec,
        }
    }

    #[inline]
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = half_vector(wo, wi);
        let s = self.shininess;
        (s + 1.0) / TAU * h.z.max(0.0).powf(s) / (4.0 * wo.dot(h))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let cos_t = (1.0 - u.x).powf(1.0 / (self.shininess + 1.0));
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let (s, c) = (TAU * u.y).sin_cos();
        let h = Vec3::new(sin_t * c, sin_t * s, cos_t);
        (wo.dot(h) > 0.0).then(|| reflect(wo, h))
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        // Glossy albedo ~ ks cos^2(theta_o) (s + 8) / (s + 1) for a narrow lobe.
        let s = self.shininess;
        let factor = wo.z * wo.z * (s + 8.0) / (s + 1.0);
        glossy_probability(luminance(self.ks), factor, luminance(self.kd))
    }
}

impl GltfPbr {
    /// `alpha = roughness^2`, kept above 1e-4 as Mitsuba's principled BSDF does.
    #[inline]
    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(1e-4)
    }

    #[inline]
    fn diffuse_color(&self) -> Vec3 {
        self.base_color * (1.0 - self.metallic)
    }

    #[inline]
    fn f0(&self) -> Vec3 {
        Vec3::splat(0.04).lerp(self.base_color, self.metallic)
    }

    #[inline]
    fn schlick(&self, cos: f32) -> Vec3 {
        let f0 = self.f0();
        f0 + (Vec3::ONE - f0) * (1.0 - cos.abs()).clamp(0.0, 1.0).powi(5)
    }

    #[inline]
    fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        if !above(wo, wi) {
            return LobeValues::default();
        }
        let alpha = self.alpha();
        let h = half_vector(wo, wi);
        let f = self.schlick(wo.dot(h));
        let spec = ggx_d(h, alpha) * ggx_smith_g1(wo, h, alpha) * ggx_smith_g1(wi, h, alpha)
            / (4.0 * wo.z * wi.z);
        LobeValues {
            diffuse: (Vec3::ONE - f) * self.diffuse_color() * FRAC_1_PI,
            glossy: f * spec,
        }
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let f = luminance(self.schlick(wo.z));
        let g1 = ggx_smith_g1(wo, Vec3::Z, self.alpha());
        glossy_probability(f, g1, luminance(self.diffuse_color()) * (1.0 - f))
    }
}

// ---------------------------------------------------------------------------------------------
// Dispatch

impl Bsdf {
    /// `f(wo, wi)` split by lobe; zero when either direction is below the surface.
    #[inline]
    pub fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        match self {
            Bsdf::Diffuse(m) => m.eval_lobes(wo, wi),
            Bsdf::Ggx(m) => m.eval_lobes(wo, wi),
            Bsdf::Ward(m) => m.eval_lobes(wo, wi),
            Bsdf::BlinnPhong(m) => m.eval_lobes(wo, wi),
            Bsdf::GltfPbr(m) => m.eval_lobes(wo, wi),
        }
    }

    /// `f(wo, wi)`, all lobes.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_lobes(wo, wi).total()
    }

    /// Probability that [`Bsdf::sample`] picks the glossy lobe for this `wo` (0 for diffuse).
    #[inline]
    pub fn glossy_probability(&self, wo: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        let p = match self {
            Bsdf::Diffuse(_) => 0.0,
            Bsdf::Ggx(m) => m.glossy_probability(wo),
            Bsdf::Ward(m) => m.glossy_probability(wo),
            Bsdf::BlinnPhong(m) => m.glossy_probability(wo),
            Bsdf::GltfPbr(m) => m.glossy_probability(wo),
        };
        debug_assert!((0.0..=1.0).contains(&p), "glossy probability {p}");
        p
    }

    /// Solid-angle density of `wi` under the glossy lobe's own sampling strategy alone.
    #[inline]
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Diffuse(_) => 0.0,
            Bsdf::Ggx(m) => ggx_visible_pdf(wo, wi, m.alpha),
            Bsdf::Ward(m) => m.glossy_pdf(wo, wi),
            Bsdf::BlinnPhong(m) => m.glossy_pdf(wo, wi),
            Bsdf::GltfPbr(m) => ggx_visible_pdf(wo, wi, m.alpha()),
        }
    }

    /// Samples `wi` from the glossy lobe alone (may be below the surface).
    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        match self {
            Bsdf::Diffuse(_) => None,
            Bsdf::Ggx(m) => sample_ggx_visible_normal(wo, m.alpha, u).map(|h| reflect(wo, h)),
            Bsdf::Ward(m) => m.sample_glossy(wo, u),
            Bsdf::BlinnPhong(m) => m.sample_glossy(wo, u),
            Bsdf::GltfPbr(m) => sample_ggx_visible_normal(wo, m.alpha(), u).map(|h| reflect(wo, h)),
        }
    }

    /// The mixture density for a known glossy probability.
    #[inline]
    fn mixture_pdf(&self, wo: Vec3, wi: Vec3, p_glossy: f32) -> f32 {
        let mut pdf = 0.0;
        if p_glossy < 1.0 {
            pdf += (1.0 - p_glossy) * square_to_cosine_hemisphere_pdf(wi);
        }
        if p_glossy > 0.0 {
            pdf += p_glossy * self.glossy_pdf(wo, wi);
        }
        pdf
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi` given `wo`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !above(wo, wi) {
            return 0.0;
        }
        let pdf = self.mixture_pdf(wo, wi, self.glossy_probability(wo));
        debug_assert!(pdf >= 0.0 && !pdf.is_nan(), "pdf {pdf} for {wo} {wi}");
        pdf
    }

    /// Samples `wi` given `wo`: `u_lobe` chooses the lobe, `u` samples within it.
    /// `None` when no valid direction results (a failed sample is not an error).
    #[inline]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let p_glossy = self.glossy_probability(wo);
        let (wi, lobe) = if u_lobe < p_glossy {
            (self.sample_glossy(wo, u)?, Lobe::Glossy)
        } else {
            (square_to_cosine_hemisphere(u), Lobe::Diffuse)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.mixture_pdf(wo, wi, p_glossy);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.eval(wo, wi),
            pdf,
            lobe,
        })
    }

    /// Hemispherical albedo estimate for the albedo layer: `kd + ks` for the paper models,
    /// `kd` for diffuse, the base colour for glTF.
    #[inline]
    pub fn albedo(&self) -> Vec3 {
        match self {
            Bsdf::Diffuse(m) => m.kd,
            Bsdf::Ggx(m) => m.kd + m.ks,
            Bsdf::Ward(m) => m.kd + m.ks,
            Bsdf::BlinnPhong(m) => m.kd + m.ks,
            Bsdf::GltfPbr(m) => m.base_color,
        }
    }
}
