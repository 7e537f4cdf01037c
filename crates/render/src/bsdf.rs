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

use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3, Vec4};
use std::f32::consts::{FRAC_1_PI, PI, TAU};
use std::ops::{Add, Div, Mul, Neg};
use streaks_image::luminance;

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

/// Smallest microfacet alpha the models use: a smaller (or zero) alpha is raised to it, so a
/// mirror-like material stays finite. Mitsuba's principled BSDF uses the same floor.
pub const MIN_ALPHA: f32 = 1e-4;

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

/// `v.z + sqrt(v.z^2 + alpha^2 (v.x^2 + v.y^2))` for `v` above the surface: GGX's separable
/// Smith masking over the cosine, `G1(v) / v.z`, is `2 /` this. (Mitsuba 3's `smith_g1` is
/// `2 / (1 + sqrt(1 + alpha^2 tan^2(theta_v)))`, 0 when `v` sees the back of the microfacet,
/// which never happens for the half vector of two directions above the surface.)
#[inline]
fn ggx_g1_denominator<L: Lanes>(v: [L; 3], a2: f32) -> L {
    let [x, y, z] = v;
    z + (z * z + (x * x + y * y) * a2).sqrt()
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

/// The GGX glossy lobe's microfacet BRDF without `ks`, `D(h) G1(wo) G1(wi) / (4 wo.z wi.z)`,
/// for `wo` and `wi` above the surface, given `go = ggx_g1_denominator(wo, alpha^2)`; also
/// returns `ggx_g1_denominator(wi, alpha^2)`. With the half vector left unnormalised,
/// `h = wo + wi`, and `q = h.x^2 + h.y^2 + alpha^2 h.z^2`, Mitsuba 3's GGX
/// `D = 1 / (pi alpha^2 ((h.x^2 + h.y^2) / alpha^2 + h.z^2)^2)` of the normalised half vector
/// is `alpha^2 |h|^4 / (pi q^2)`, so the lobe is `alpha^2 |h|^4 / (pi q^2 go gi)`: one division
/// and one square root besides `go`. (Mitsuba also cuts `D` to 0 below 1e-20; that is not
/// done here.)
/// Generic in [`Lanes`] for the light choice; the operations are those of the scalar formula
/// above, in its order, so every lane gives the scalar result bit for bit.
#[inline]
fn ggx_spec<L: Lanes>(wo: Vec3, wi: [L; 3], a2: f32, go: f32) -> (L, L) {
    let [hx, hy, hz] = [wi[0] + wo.x, wi[1] + wo.y, wi[2] + wo.z];
    let h2 = hx * hx + hy * hy + hz * hz;
    let q = hx * hx + hy * hy + hz * a2 * hz;
    let gi = ggx_g1_denominator(wi, a2);
    (h2 * a2 * h2 / (q * PI * q * go * gi), gi)
}

/// [`ggx_spec`] and the solid-angle density of `wi` when the lobe samples visible normals,
/// `D(h) G1(wo, h) / (4 wo.z)` (the Jacobian `1 / (4 wo.h)` cancels `wo.h`), which is the lobe
/// times `wi.z / G1(wi)`, i.e. times `gi / 2`.
#[inline]
fn ggx_spec_pdf(wo: Vec3, wi: Vec3, alpha: f32) -> (f32, f32) {
    let a2 = alpha * alpha;
    let (spec, gi) = ggx_spec(wo, wi.to_array(), a2, ggx_g1_denominator(wo.to_array(), a2));
    (spec, 0.5 * spec * gi)
}

/// Cheap estimate of the GGX glossy lobe's directional albedo (with `ks = 1`): `G1` at
/// `max(cos(theta_o), alpha)`. Visible normals tilt toward a grazing `wo`, so the reflected
/// directions are less grazing than `wo`; measured albedos (alpha 0.1 / 0.7): 0.99 / 0.50 at
/// normal incidence and 0.90 / 0.72 at 88 degrees, against estimates 1.0 / 1.0 and 0.83 / 0.90.
#[inline]
fn ggx_albedo_factor(cos_o: f32, alpha: f32) -> f32 {
    let mu = cos_o.max(alpha).min(1.0);
    let tan2 = (1.0 - mu * mu) / (mu * mu);
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// The density of the lobe mixture: the diffuse lobe (cosine-weighted) with probability
/// `1 - p_glossy`, the glossy lobe (its own density `glossy_pdf`) with `p_glossy`. A lobe that is
/// never chosen adds nothing (not even an infinite density times zero).
#[inline]
fn mixture_pdf(wi: Vec3, glossy_pdf: f32, p_glossy: f32) -> f32 {
    let mut pdf = 0.0;
    if p_glossy < 1.0 {
        pdf += (1.0 - p_glossy) * square_to_cosine_hemisphere_pdf(wi);
    }
    if p_glossy > 0.0 {
        pdf += p_glossy * glossy_pdf;
    }
    pdf
}

/// A number, or four of them in SIMD lanes: [`LuminanceEval`]'s lobes and the GGX terms are
/// written once for both, and the light choice evaluates four emitters at a time. Every
/// operation is the IEEE one in each lane, so a lane holds exactly the scalar result.
pub(crate) trait Lanes:
    Copy
    + Add<Output = Self>
    + Add<f32, Output = Self>
    + Mul<Output = Self>
    + Mul<f32, Output = Self>
    + Div<Output = Self>
    + Div<f32, Output = Self>
    + Neg<Output = Self>
{
    /// The same value in every lane.
    fn splat(x: f32) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `e^self`.
    fn exp(self) -> Self;
    /// `self^e`.
    fn powf(self, e: f32) -> Self;
    /// `self^5`, as `f32::powi(self, 5)` computes it.
    fn pow5(self) -> Self;
    /// `1 - self`.
    fn one_minus(self) -> Self;
    /// Clamped to `[0, 1]`.
    fn saturate(self) -> Self;
    /// `self` where `z > 0`, else 0.
    fn where_positive(self, z: Self) -> Self;
}

impl Lanes for f32 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f32::exp(self)
    }
    #[inline(always)]
    fn powf(self, e: f32) -> Self {
        f32::powf(self, e)
    }
    #[inline(always)]
    fn pow5(self) -> Self {
        self.powi(5)
    }
    #[inline(always)]
    fn one_minus(self) -> Self {
        1.0 - self
    }
    #[inline(always)]
    fn saturate(self) -> Self {
        self.clamp(0.0, 1.0)
    }
    #[inline(always)]
    fn where_positive(self, z: Self) -> Self {
        if z > 0.0 {
            self
        } else {
            0.0
        }
    }
}

impl Lanes for Vec4 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Vec4::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vec4::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        Vec4::from_array(self.to_array().map(f32::exp))
    }
    #[inline(always)]
    fn powf(self, e: f32) -> Self {
        Vec4::from_array(self.to_array().map(|x| x.powf(e)))
    }
    #[inline(always)]
    fn pow5(self) -> Self {
        Vec4::from_array(self.to_array().map(|x| x.powi(5)))
    }
    #[inline(always)]
    fn one_minus(self) -> Self {
        1.0 - self
    }
    #[inline(always)]
    fn saturate(self) -> Self {
        self.clamp(Vec4::ZERO, Vec4::ONE)
    }
    #[inline(always)]
    fn where_positive(self, z: Self) -> Self {
        Vec4::select(z.cmpgt(Vec4::ZERO), self, Vec4::ZERO)
    }
}

/// Hemisphere check shared by every model.
#[inline]
fn above(wo: Vec3, wi: Vec3) -> bool {
    wo.z > 0.0 && wi.z > 0.0
}

// ---------------------------------------------------------------------------------------------
// The models: each gives its lobes, the glossy lobe's pdf and sampling, and the lobe choice.

// Each model's `eval_pdf` takes `wo` and `wi` above the surface and returns `f(wo, wi)` split
// by lobe with the glossy lobe's own sampling density of `wi` (see `Bsdf::eval_pdf`): both
// come from the same half vector and microfacet terms.

impl Diffuse {
    #[inline]
    fn eval_pdf(&self, _wo: Vec3, _wi: Vec3) -> (LobeValues, f32) {
        let f = LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: Vec3::ZERO,
        };
        (f, 0.0)
    }
}

impl Ggx {
    /// `alpha`, kept at or above [`MIN_ALPHA`].
    #[inline]
    fn alpha(&self) -> f32 {
        self.alpha.max(MIN_ALPHA)
    }

    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        let (spec, pdf) = ggx_spec_pdf(wo, wi, self.alpha());
        let f = LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: self.ks * spec,
        };
        (f, pdf)
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let factor = ggx_albedo_factor(wo.z, self.alpha());
        glossy_probability(luminance(self.ks), factor, luminance(self.kd))
    }
}

impl Ward {
    /// `alpha`, kept at or above [`MIN_ALPHA`].
    #[inline]
    fn alpha(&self) -> f32 {
        self.alpha.max(MIN_ALPHA)
    }

    /// The glossy lobe `exp(-tan^2(delta)/alpha^2) / (4 pi alpha^2 sqrt(cos_i cos_o))` and its
    /// sampling density: the half vector is drawn with the normalised slope density's
    /// solid-angle form `exp(-tan^2/alpha^2) / (pi alpha^2 cos^3(delta))`, and `1 / (4 wo.h)`
    /// turns it into a density of `wi`.
    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        let h = half_vector(wo, wi);
        let a2 = self.alpha() * self.alpha();
        let tan2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        let gauss = (-tan2 / a2).exp() / (PI * a2);
        let f = LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: self.ks * (gauss / (4.0 * (wo.z * wi.z).sqrt())),
        };
        (f, gauss / (h.z * h.z * h.z * 4.0 * wo.dot(h)))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        // tan^2(delta) = -alpha^2 ln(1 - u): 1 - u is in (0, 1], so the log is finite.
        let tan2 = -self.alpha() * self.alpha() * (1.0 - u.x).ln();
        let cos_d = 1.0 / (1.0 + tan2).sqrt();
        let sin_d = (tan2 * cos_d * cos_d).sqrt();
        let (s, c) = (TAU * u.y).sin_cos();
        let h = Vec3::new(sin_d * c, sin_d * s, cos_d);
        (wo.dot(h) > 0.0).then(|| reflect(wo, h))
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        // For a narrow lobe the glossy albedo of this Ward form is ~ ks cos(theta_o); a lobe of
        // width alpha keeps about ks alpha above the horizon at grazing angles.
        glossy_probability(
            luminance(self.ks),
            wo.z.max(self.alpha()),
            luminance(self.kd),
        )
    }
}

impl BlinnPhong {
    /// The exponent, kept non-negative.
    #[inline]
    fn shininess(&self) -> f32 {
        self.shininess.max(0.0)
    }

    /// The glossy lobe `(s + 8) / (8 pi) cos^s(theta_h)` and its sampling density: the half
    /// vector is drawn with density `(s + 1) / (2 pi) cos^s(theta_h)`, and `1 / (4 wo.h)` turns
    /// it into a density of `wi`.
    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        let h = half_vector(wo, wi);
        let s = self.shininess();
        let cos_s = h.z.powf(s);
        let f = LobeValues {
            diffuse: self.kd * FRAC_1_PI,
            glossy: self.ks * ((s + 8.0) / (8.0 * PI) * cos_s),
        };
        (f, (s + 1.0) / TAU * cos_s / (4.0 * wo.dot(h)))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let cos_t = (1.0 - u.x).powf(1.0 / (self.shininess() + 1.0));
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let (s, c) = (TAU * u.y).sin_cos();
        let h = Vec3::new(sin_t * c, sin_t * s, cos_t);
        (wo.dot(h) > 0.0).then(|| reflect(wo, h))
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        // Glossy albedo ~ ks cos^2(theta_o) (s + 8) / (s + 1) for a narrow lobe; the cosine is
        // kept above the lobe's angular width sqrt(2 / (s + 2)) for grazing angles.
        let s = self.shininess();
        let mu = wo.z.max((2.0 / (s + 2.0)).sqrt());
        let factor = mu * mu * (s + 8.0) / (s + 1.0);
        glossy_probability(luminance(self.ks), factor, luminance(self.kd))
    }
}

impl GltfPbr {
    /// `alpha = roughness^2`, kept at or above [`MIN_ALPHA`] (as Mitsuba's principled BSDF does).
    #[inline]
    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(MIN_ALPHA)
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
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        let fresnel = self.schlick(wo.dot(half_vector(wo, wi)));
        let (spec, pdf) = ggx_spec_pdf(wo, wi, self.alpha());
        let f = LobeValues {
            diffuse: (Vec3::ONE - fresnel) * self.diffuse_color() * FRAC_1_PI,
            glossy: fresnel * spec,
        };
        (f, pdf)
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let f = luminance(self.schlick(wo.z));
        let factor = ggx_albedo_factor(wo.z, self.alpha());
        glossy_probability(f, factor, luminance(self.diffuse_color()) * (1.0 - f))
    }
}

// ---------------------------------------------------------------------------------------------
// Dispatch

impl Bsdf {
    /// `f(wo, wi)` split by lobe and the glossy lobe's own sampling density of `wi`; zero when
    /// either direction is below the surface.
    #[inline]
    fn eval_glossy_pdf(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        if !above(wo, wi) {
            return (LobeValues::default(), 0.0);
        }
        match self {
            Bsdf::Diffuse(m) => m.eval_pdf(wo, wi),
            Bsdf::Ggx(m) => m.eval_pdf(wo, wi),
            Bsdf::Ward(m) => m.eval_pdf(wo, wi),
            Bsdf::BlinnPhong(m) => m.eval_pdf(wo, wi),
            Bsdf::GltfPbr(m) => m.eval_pdf(wo, wi),
        }
    }

    /// `f(wo, wi)` split by lobe; zero when either direction is below the surface.
    #[inline]
    pub fn eval_lobes(&self, wo: Vec3, wi: Vec3) -> LobeValues {
        self.eval_glossy_pdf(wo, wi).0
    }

    /// `f(wo, wi)` split by lobe and [`Bsdf::pdf`] together, for the price of one: both share
    /// the half vector and the microfacet terms (next-event estimation with MIS needs both).
    #[inline]
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        let (f, glossy_pdf) = self.eval_glossy_pdf(wo, wi);
        if !above(wo, wi) {
            return (f, 0.0);
        }
        let pdf = mixture_pdf(wi, glossy_pdf, self.glossy_probability(wo));
        debug_assert!(pdf >= 0.0 && !pdf.is_nan(), "pdf {pdf} for {wo} {wi}");
        (f, pdf)
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

    /// Samples `wi` from the glossy lobe alone (may be below the surface).
    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        match self {
            Bsdf::Diffuse(_) => None,
            Bsdf::Ggx(m) => sample_ggx_visible_normal(wo, m.alpha(), u).map(|h| reflect(wo, h)),
            Bsdf::Ward(m) => m.sample_glossy(wo, u),
            Bsdf::BlinnPhong(m) => m.sample_glossy(wo, u),
            Bsdf::GltfPbr(m) => sample_ggx_visible_normal(wo, m.alpha(), u).map(|h| reflect(wo, h)),
        }
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi` given `wo`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi).1
    }

    /// Samples `wi` given `wo`: `u_lobe` chooses the lobe, `u` samples within it.
    /// `None` when no valid direction results (a failed sample is not an error).
    #[inline]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        debug_assert!(
            (wo.length() - 1.0).abs() < 1e-3,
            "wo {wo} is not a unit vector"
        );
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
        let (f, glossy_pdf) = self.eval_glossy_pdf(wo, wi);
        let pdf = mixture_pdf(wi, glossy_pdf, p_glossy);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: f.total(),
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

/// `luminance(f(wo, wi))` for one `wo` and many `wi`: the light choice's per-emitter BSDF
/// weight, a dozen evaluations per path vertex. What depends on `wo` alone (the lobes'
/// luminances, GGX's masking term of `wo`) is computed once by [`Bsdf::luminance_at`];
/// each [`LuminanceEval::eval`] then costs a half vector and the lobe's own terms, and
/// [`LuminanceEval::eval4`] evaluates four directions at once in SIMD lanes.
/// Equal to `luminance(bsdf.eval(wo, wi))` up to rounding (tested).
#[derive(Clone, Copy, Debug)]
pub struct LuminanceEval {
    wo: Vec3,
    /// Diffuse luminance `luminance(kd) / pi` (for glTF: of `(1 - F0) c_diff / pi`).
    diffuse: f32,
    /// Luminance of the glossy lobe's reflectance (`ks`; for glTF: of `F0`).
    glossy: f32,
    lobe: LuminanceLobe,
}

/// The glossy lobe of a [`LuminanceEval`], with its `wo`-only terms.
#[derive(Clone, Copy, Debug)]
enum LuminanceLobe {
    None,
    /// GGX: `alpha^2` and `ggx_g1_denominator(wo)`.
    Ggx {
        a2: f32,
        go: f32,
    },
    /// glTF: GGX as above, with Schlick's Fresnel applied to both lobes.
    GltfGgx {
        a2: f32,
        go: f32,
    },
    /// Ward: `alpha^2`.
    Ward {
        a2: f32,
    },
    /// Blinn-Phong: the exponent and its normalisation `(s + 8) / (8 pi)`.
    BlinnPhong {
        s: f32,
        norm: f32,
    },
}

impl LuminanceEval {
    /// `luminance(f(wo, wi))`; zero when either direction is below the surface.
    #[inline]
    pub fn eval(&self, wi: Vec3) -> f32 {
        self.eval_lanes(wi.to_array())
    }

    /// [`LuminanceEval::eval`] of four directions at once, given as their x, y and z lanes.
    #[inline]
    pub fn eval4(&self, wi: [Vec4; 3]) -> Vec4 {
        self.eval_lanes(wi)
    }

    #[inline(always)]
    fn eval_lanes<L: Lanes>(&self, wi: [L; 3]) -> L {
        let (wo, diffuse, glossy) = (self.wo, self.diffuse, self.glossy);
        if !above(wo, Vec3::Z) {
            return L::splat(0.0);
        }
        // The half vector normalised as `Vec3::normalize` does it.
        let half = || {
            let h = [wi[0] + wo.x, wi[1] + wo.y, wi[2] + wo.z];
            let r = L::splat(1.0) / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            h.map(|c| c * r)
        };
        let f = match self.lobe {
            LuminanceLobe::None => L::splat(diffuse),
            LuminanceLobe::Ggx { a2, go } => ggx_spec(wo, wi, a2, go).0 * glossy + diffuse,
            LuminanceLobe::GltfGgx { a2, go } => {
                let spec = ggx_spec(wo, wi, a2, go).0;
                let h = half();
                // F = F0 + (1 - F0) s, so luminance(F) = L(F0) + (1 - L(F0)) s, and
                // 1 - F = (1 - F0)(1 - s) scales the diffuse lobe by (1 - s).
                let cos = h[0] * wo.x + h[1] * wo.y + h[2] * wo.z;
                let s = cos.abs().one_minus().saturate().pow5();
                s.one_minus() * diffuse + (s * (1.0 - glossy) + glossy) * spec
            }
            LuminanceLobe::Ward { a2 } => {
                // tan^2 of the half vector's angle, from the unnormalised wo + wi.
                let [hx, hy, hz] = [wi[0] + wo.x, wi[1] + wo.y, wi[2] + wo.z];
                let tan2 = (hx * hx + hy * hy) / (hz * hz);
                let gauss = (-tan2 / a2).exp() / (PI * a2);
                (gauss / ((wi[2] * wo.z).sqrt() * 4.0)) * glossy + diffuse
            }
            LuminanceLobe::BlinnPhong { s, norm } => half()[2].powf(s) * norm * glossy + diffuse,
        };
        f.where_positive(wi[2])
    }
}

impl Bsdf {
    /// The evaluator of `luminance(f(wo, wi))` for this `wo` and any `wi` (see
    /// [`LuminanceEval`]).
    #[inline]
    pub fn luminance_at(&self, wo: Vec3) -> LuminanceEval {
        let ggx = |alpha: f32| {
            let a2 = alpha * alpha;
            (a2, ggx_g1_denominator(wo.to_array(), a2))
        };
        let (diffuse, glossy, lobe) = match self {
            Bsdf::Diffuse(m) => (luminance(m.kd), 0.0, LuminanceLobe::None),
            Bsdf::Ggx(m) => (luminance(m.kd), luminance(m.ks), {
                let (a2, go) = ggx(m.alpha());
                LuminanceLobe::Ggx { a2, go }
            }),
            Bsdf::Ward(m) => (
                luminance(m.kd),
                luminance(m.ks),
                LuminanceLobe::Ward {
                    a2: m.alpha() * m.alpha(),
                },
            ),
            Bsdf::BlinnPhong(m) => (
                luminance(m.kd),
                luminance(m.ks),
                LuminanceLobe::BlinnPhong {
                    s: m.shininess(),
                    norm: (m.shininess() + 8.0) / (8.0 * PI),
                },
            ),
            Bsdf::GltfPbr(m) => (
                luminance((Vec3::ONE - m.f0()) * m.diffuse_color()),
                luminance(m.f0()),
                {
                    let (a2, go) = ggx(m.alpha());
                    LuminanceLobe::GltfGgx { a2, go }
                },
            ),
        };
        LuminanceEval {
            wo,
            diffuse: diffuse * FRAC_1_PI,
            glossy,
            lobe,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testing::{check_bsdf, ChiSquareConfig};

    const ANGLES: [f32; 5] = [0.0, 45.0, 75.0, 85.0, 88.0];
    const ALPHAS: [f32; 4] = [0.02, 0.1, 0.3, 0.7];
    const SHININESS: [f32; 3] = [10.0, 100.0, 1000.0];
    const MIXED_ANGLES: [f32; 3] = [0.0, 75.0, 88.0];
    const GLTF_ROUGHNESS: [f32; 3] = [0.15, 0.5, 1.0];
    const GLTF_ANGLES: [f32; 3] = [0.0, 45.0, 85.0];
    /// Every chi-square test in this module, for the Sidak correction.
    const NUM_TESTS: usize = 2 * ALPHAS.len() * (ANGLES.len() + MIXED_ANGLES.len())
        + SHININESS.len() * (ANGLES.len() + MIXED_ANGLES.len())
        + 2 * GLTF_ROUGHNESS.len() * GLTF_ANGLES.len()
        + 2;

    /// Direction at `theta` degrees from the normal, at an azimuth off the axes.
    fn wo_at(theta_deg: f32) -> Vec3 {
        let (st, ct) = theta_deg.to_radians().sin_cos();
        let (sp, cp) = 0.7f32.sin_cos();
        Vec3::new(st * cp, st * sp, ct)
    }

    fn config(seed: u64) -> ChiSquareConfig {
        ChiSquareConfig {
            samples: 100_000,
            num_tests: NUM_TESTS,
            seed,
            ..ChiSquareConfig::default()
        }
    }

    fn run(name: String, bsdf: Bsdf, theta: f32, seed: u64) {
        let report = check_bsdf(&name, &bsdf, wo_at(theta), &config(seed));
        assert!(report.passed, "{report}");
        assert!(
            (report.pdf_integral - report.sampled_fraction).abs() < 5e-3,
            "{report}"
        );
    }

    /// The paper models with `kd = 0, ks = 1` and with a mixed dark-wet-road material.
    fn paper_materials() -> [(Vec3, Vec3, &'static [f32]); 2] {
        [
            (Vec3::ZERO, Vec3::ONE, &ANGLES),
            (
                Vec3::new(0.05, 0.04, 0.03),
                Vec3::new(0.6, 0.6, 0.5),
                &MIXED_ANGLES,
            ),
        ]
    }

    #[test]
    fn chi_square_ggx() {
        for (kd, ks, angles) in paper_materials() {
            for alpha in ALPHAS {
                for &theta in angles {
                    let b = Bsdf::Ggx(Ggx { kd, ks, alpha });
                    run(
                        format!("ggx kd {kd} alpha {alpha} theta_o {theta}"),
                        b,
                        theta,
                        1,
                    );
                }
            }
        }
    }

    #[test]
    fn chi_square_ward() {
        for (kd, ks, angles) in paper_materials() {
            for alpha in ALPHAS {
                for &theta in angles {
                    let b = Bsdf::Ward(Ward { kd, ks, alpha });
                    run(
                        format!("ward kd {kd} alpha {alpha} theta_o {theta}"),
                        b,
                        theta,
                        2,
                    );
                }
            }
        }
    }

    #[test]
    fn chi_square_blinn_phong() {
        for (kd, ks, angles) in paper_materials() {
            for shininess in SHININESS {
                for &theta in angles {
                    let b = Bsdf::BlinnPhong(BlinnPhong { kd, ks, shininess });
                    run(
                        format!("blinn-phong kd {kd} s {shininess} theta_o {theta}"),
                        b,
                        theta,
                        3,
                    );
                }
            }
        }
    }

    #[test]
    fn chi_square_gltf_and_diffuse() {
        for metallic in [0.0, 1.0] {
            for roughness in GLTF_ROUGHNESS {
                for theta in GLTF_ANGLES {
                    let b = Bsdf::GltfPbr(GltfPbr {
                        base_color: Vec3::new(0.8, 0.5, 0.2),
                        metallic,
                        roughness,
                    });
                    run(
                        format!("gltf metallic {metallic} roughness {roughness} theta_o {theta}"),
                        b,
                        theta,
                        4,
                    );
                }
            }
        }
        for theta in [0.0, 80.0] {
            let b = Bsdf::Diffuse(Diffuse {
                kd: Vec3::splat(0.5),
            });
            run(format!("diffuse theta_o {theta}"), b, theta, 5);
        }
    }
}

#[cfg(test)]
mod identity_tests {
    //! Reciprocity, energy and the identity with Mitsuba 3's `blendbsdf`, with the microfacet
    //! formulas written again here in f64 straight from Mitsuba 3's `microfacet.h` and
    //! `roughconductor.cpp`, independently of the code under test.
    use super::*;
    use crate::sampling::Pcg32;
    use crate::testing::adaptive_simpson;
    use std::f64::consts::PI as PI64;

    /// Mitsuba's `MicrofacetDistribution::eval` (GGX, isotropic).
    fn mi_d(m: [f64; 3], alpha: f64) -> f64 {
        let t = (m[0] / alpha).powi(2) + (m[1] / alpha).powi(2) + m[2] * m[2];
        let r = 1.0 / (PI64 * alpha * alpha * t * t);
        if r * m[2] > 1e-20 {
            r
        } else {
            0.0
        }
    }

    /// Mitsuba's `smith_g1` (GGX).
    fn mi_g1(v: [f64; 3], m: [f64; 3], alpha: f64) -> f64 {
        let xy = (alpha * v[0]).powi(2) + (alpha * v[1]).powi(2);
        let mut r = 2.0 / (1.0 + (1.0 + xy / (v[2] * v[2])).sqrt());
        if xy == 0.0 {
            r = 1.0;
        }
        if (v[0] * m[0] + v[1] * m[1] + v[2] * m[2]) * v[2] <= 0.0 {
            r = 0.0;
        }
        r
    }

    fn d3(v: Vec3) -> [f64; 3] {
        [v.x as f64, v.y as f64, v.z as f64]
    }

    /// Mitsuba's `blendbsdf(weight 0.5, diffuse(2 kd), roughconductor(ggx, none, alpha, 2 ks))`
    /// `eval(si.wi, wo)` for one channel: Mitsuba's `si.wi` is our `wo` and its `wo` our `wi`,
    /// and the value includes the cosine of its `wo`. `material none` has Fresnel 1.
    fn mitsuba_blend_eval(kd: f64, ks: f64, alpha: f64, mi_wi: [f64; 3], mi_wo: [f64; 3]) -> f64 {
        let (ci, co) = (mi_wi[2], mi_wo[2]);
        if ci <= 0.0 || co <= 0.0 {
            return 0.0;
        }
        let diffuse = 2.0 * kd / PI64 * co;
        let s = [
            mi_wi[0] + mi_wo[0],
            mi_wi[1] + mi_wo[1],
            mi_wi[2] + mi_wo[2],
        ];
        let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        let h = [s[0] / len, s[1] / len, s[2] / len];
        let d = mi_d(h, alpha);
        let g = mi_g1(mi_wi, h, alpha) * mi_g1(mi_wo, h, alpha);
        let conductor = if d != 0.0 {
            2.0 * ks * d * g / (4.0 * ci)
        } else {
            0.0
        };
        0.5 * diffuse + 0.5 * conductor
    }

    fn random_dir(rng: &mut Pcg32) -> Vec3 {
        crate::sampling::square_to_uniform_sphere(rng.next_2d())
    }

    fn all_models() -> Vec<Bsdf> {
        let kd = Vec3::new(0.2, 0.3, 0.1);
        let ks = Vec3::new(0.7, 0.5, 0.9);
        let mut v = vec![Bsdf::Diffuse(Diffuse { kd })];
        for alpha in [0.05, 0.3, 0.8] {
            v.push(Bsdf::Ggx(Ggx { kd, ks, alpha }));
            v.push(Bsdf::Ward(Ward { kd, ks, alpha }));
            v.push(Bsdf::GltfPbr(GltfPbr {
                base_color: ks,
                metallic: alpha,
                roughness: alpha,
            }));
        }
        for shininess in [5.0, 200.0] {
            v.push(Bsdf::BlinnPhong(BlinnPhong { kd, ks, shininess }));
        }
        v
    }

    #[test]
    fn ggx_is_mitsuba_blendbsdf() {
        let mut rng = Pcg32::new(11, 0);
        let mut compared = 0;
        for alpha in [0.02f32, 0.1, 0.3, 0.7] {
            let (kd, ks) = (Vec3::new(0.1, 0.3, 0.0), Vec3::new(0.9, 0.4, 1.0));
            let b = Bsdf::Ggx(Ggx { kd, ks, alpha });
            for _ in 0..4000 {
                let wo = random_dir(&mut rng);
                // Half the pairs near the mirror direction, where the glossy lobe matters.
                let wi = if rng.next_f32() < 0.5 {
                    random_dir(&mut rng)
                } else {
                    let m = Vec3::new(-wo.x, -wo.y, wo.z);
                    (m + 0.3 * alpha * random_dir(&mut rng)).normalize()
                };
                let ours = b.eval(wo, wi) * wi.z.max(0.0);
                for c in 0..3 {
                    let mi = mitsuba_blend_eval(
                        kd[c] as f64,
                        ks[c] as f64,
                        alpha as f64,
                        d3(wo),
                        d3(wi),
                    );
                    let got = ours[c] as f64;
                    assert!(
                        (got - mi).abs() <= 1e-4 * mi.abs() + 1e-6,
                        "alpha {alpha} wo {wo} wi {wi} channel {c}: ours {got} vs Mitsuba {mi}"
                    );
                    compared += (mi > 1.0) as usize;
                }
            }
        }
        assert!(compared > 100, "too few glossy comparisons: {compared}");
    }

    #[test]
    fn luminance_eval_is_luminance_of_eval() {
        let mut rng = Pcg32::new(11, 3);
        let (kd, ks) = (Vec3::new(0.2, 0.3, 0.1), Vec3::new(0.7, 0.5, 0.9));
        let narrow = [0.01, MIN_ALPHA].map(|alpha| Bsdf::Ggx(Ggx { kd, ks, alpha }));
        for b in all_models().into_iter().chain(narrow) {
            for _ in 0..2000 {
                let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
                let want = luminance(b.eval(wo, wi));
                let got = b.luminance_at(wo).eval(wi);
                assert!(
                    (got - want).abs() <= 1e-5 * want.abs().max(1e-3),
                    "{b:?} {wo} {wi}: {got} vs {want}"
                );
            }
        }
    }

    /// Four directions in SIMD lanes give exactly the four scalar values, below the surface
    /// included, for every model.
    #[test]
    fn luminance_eval_lanes_are_the_scalar_values() {
        let mut rng = Pcg32::new(12, 5);
        for b in all_models() {
            for _ in 0..500 {
                let wo = random_dir(&mut rng);
                let f = b.luminance_at(wo);
                let wi: [Vec3; 4] = std::array::from_fn(|_| {
                    let w = random_dir(&mut rng);
                    // Some below the surface.
                    if rng.next_f32() < 0.2 {
                        -w
                    } else {
                        w
                    }
                });
                let lanes = [0, 1, 2].map(|k| Vec4::from_array(wi.map(|w| w.to_array()[k])));
                let got = f.eval4(lanes).to_array();
                for (w, g) in wi.iter().zip(got) {
                    assert_eq!(g.to_bits(), f.eval(*w).to_bits(), "{b:?} {wo} {w}");
                }
            }
        }
    }

    #[test]
    fn reciprocity() {
        let mut rng = Pcg32::new(12, 0);
        for b in all_models() {
            for _ in 0..2000 {
                let (a, c) = (random_dir(&mut rng), random_dir(&mut rng));
                let (f1, f2) = (b.eval(a, c), b.eval(c, a));
                let tol = 1e-4 * f1.abs().max(f2.abs()).max_element() + 1e-7;
                assert!((f1 - f2).abs().max_element() <= tol, "{b:?}: {f1} vs {f2}");
            }
        }
    }

    #[test]
    fn below_the_surface_is_zero() {
        let mut rng = Pcg32::new(13, 0);
        for b in all_models() {
            for _ in 0..500 {
                let up = random_dir(&mut rng) * Vec3::new(1.0, 1.0, 0.0) + Vec3::Z * 0.5;
                let up = up.normalize();
                let down = Vec3::new(up.x, up.y, -up.z);
                assert_eq!(b.eval(up, down), Vec3::ZERO);
                assert_eq!(b.eval(down, up), Vec3::ZERO);
                assert_eq!(b.pdf(up, down), 0.0);
                assert_eq!(b.pdf(down, up), 0.0);
                assert!(b.sample(down, rng.next_f32(), rng.next_2d()).is_none());
            }
        }
    }

    /// Monte Carlo directional albedo `E[f cos / pdf]` with the model's own sampling,
    /// with its standard error.
    fn mc_albedo(b: &Bsdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
        let mut rng = Pcg32::new(seed, 3);
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            if let Some(s) = b.sample(wo, rng.next_f32(), rng.next_2d()) {
                let v = (luminance(s.f) * s.wi.z / s.pdf) as f64;
                sum += v;
                sum2 += v * v;
            }
        }
        let mean = sum / n as f64;
        (mean, ((sum2 / n as f64 - mean * mean) / n as f64).sqrt())
    }

    /// Independent quadrature of `int D G1(wo) G1(wi) / (4 cos_o) dwi` over the hemisphere
    /// (Mitsuba's formulas in f64; `theta_i` and `phi_i` nested adaptive Simpson).
    fn quadrature_ggx_albedo(wo: [f64; 3], alpha: f64) -> f64 {
        let mut outer = |theta: f64| {
            let (st, ct) = theta.sin_cos();
            let mut inner = |phi: f64| {
                let wi = [st * phi.cos(), st * phi.sin(), ct];
                mitsuba_blend_eval(0.0, 1.0, alpha, wo, wi) * st
            };
            adaptive_simpson(&mut inner, 0.0, std::f64::consts::TAU, 1e-7, 5, 18)
        };
        adaptive_simpson(&mut outer, 0.0, std::f64::consts::FRAC_PI_2, 1e-6, 5, 18)
    }

    #[test]
    fn white_furnace_ggx_loses_only_masking() {
        for (alpha, theta) in [
            (0.1f32, 0.0f32),
            (0.3, 0.0),
            (0.3, 60.0),
            (0.7, 0.0),
            (0.7, 80.0),
        ] {
            let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
            let b = Bsdf::Ggx(Ggx {
                kd: Vec3::ZERO,
                ks: Vec3::ONE,
                alpha,
            });
            let (mc, err) = mc_albedo(&b, wo, 200_000, 21);
            let quad = quadrature_ggx_albedo(d3(wo), alpha as f64);
            assert!(
                (mc - quad).abs() < 4.0 * err + 2e-3,
                "alpha {alpha} theta {theta}: MC {mc} +- {err}, quadrature {quad}"
            );
            assert!(quad <= 1.0 + 1e-3, "albedo {quad} > 1");
            if theta == 0.0 && alpha <= 0.1 {
                assert!(
                    quad > 0.98,
                    "alpha {alpha}: albedo {quad} should be close to 1"
                );
            }
        }
    }

    #[test]
    fn white_furnace_diffuse() {
        let b = Bsdf::Diffuse(Diffuse { kd: Vec3::ONE });
        for theta in [0.0f32, 60.0, 89.0] {
            let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
            let (mc, err) = mc_albedo(&b, wo, 20_000, 22);
            assert!(
                (mc - 1.0).abs() < 1e-3 && err < 1e-3,
                "theta {theta}: {mc} +- {err}"
            );
        }
    }

    #[test]
    fn lobe_choice() {
        let wo = Vec3::new(0.966, 0.0, 0.259); // 75 degrees
        let ks = Vec3::splat(0.8);
        let dark_wet = Vec3::splat(0.02);
        for (b, lo) in [
            (
                Bsdf::Ggx(Ggx {
                    kd: dark_wet,
                    ks,
                    alpha: 0.1,
                }),
                0.9,
            ),
            (
                Bsdf::Ward(Ward {
                    kd: dark_wet,
                    ks,
                    alpha: 0.1,
                }),
                0.8,
            ),
            (
                Bsdf::BlinnPhong(BlinnPhong {
                    kd: dark_wet,
                    ks,
                    shininess: 100.0,
                }),
                0.6,
            ),
        ] {
            let p = b.glossy_probability(wo);
            assert!(p >= lo && p <= 0.95, "{b:?}: {p}");
        }
        let only_glossy = Bsdf::Ward(Ward {
            kd: Vec3::ZERO,
            ks,
            alpha: 0.1,
        });
        assert_eq!(only_glossy.glossy_probability(wo), 1.0);
        let only_diffuse = Bsdf::Ggx(Ggx {
            kd: dark_wet,
            ks: Vec3::ZERO,
            alpha: 0.1,
        });
        assert_eq!(only_diffuse.glossy_probability(wo), 0.0);
        let bright = Bsdf::BlinnPhong(BlinnPhong {
            kd: Vec3::ONE,
            ks: Vec3::splat(0.01),
            shininess: 10.0,
        });
        assert_eq!(bright.glossy_probability(wo), 0.05);
    }

    #[test]
    fn albedo_estimates() {
        let kd = Vec3::new(0.1, 0.2, 0.3);
        let ks = Vec3::splat(0.5);
        assert_eq!(Bsdf::Ggx(Ggx { kd, ks, alpha: 0.1 }).albedo(), kd + ks);
        assert_eq!(Bsdf::Diffuse(Diffuse { kd }).albedo(), kd);
        let g = GltfPbr {
            base_color: kd,
            metallic: 0.5,
            roughness: 0.5,
        };
        assert_eq!(Bsdf::GltfPbr(g).albedo(), kd);
    }
}

#[cfg(test)]
mod value_tests {
    //! Values worked out by hand from the formulas.
    use super::*;

    #[test]
    fn gltf_at_normal_incidence() {
        // wo = wi = n: h = n, F = F0, D = 1 / (pi alpha^2), G1 = 1, so
        // glossy = F0 / (4 pi alpha^2) and diffuse = (1 - F0) c_diff / pi.
        let g = GltfPbr {
            base_color: Vec3::new(0.5, 0.25, 1.0),
            metallic: 0.5,
            roughness: 0.6,
        };
        let l = Bsdf::GltfPbr(g).eval_lobes(Vec3::Z, Vec3::Z);
        let alpha2 = 0.36f32 * 0.36;
        let f0 = Vec3::new(0.27, 0.145, 0.52);
        let c_diff = Vec3::new(0.25, 0.125, 0.5);
        assert!(
            (l.glossy - f0 / (4.0 * PI * alpha2)).abs().max_element() < 1e-5,
            "{l:?}"
        );
        assert!(
            (l.diffuse - (Vec3::ONE - f0) * c_diff / PI)
                .abs()
                .max_element()
                < 1e-6,
            "{l:?}"
        );
    }

    #[test]
    fn paper_models_at_normal_incidence() {
        // h = n: Ward glossy = ks / (4 pi alpha^2), Blinn-Phong = ks (s + 8) / (8 pi),
        // GGX = ks / (4 pi alpha^2) (D = 1 / (pi alpha^2), G1 = 1).
        let (kd, ks) = (Vec3::splat(0.2), Vec3::splat(0.5));
        let w = Bsdf::Ward(Ward { kd, ks, alpha: 0.2 }).eval_lobes(Vec3::Z, Vec3::Z);
        assert!((w.glossy.x - 0.5 / (4.0 * PI * 0.04)).abs() < 1e-5);
        assert!((w.diffuse.x - 0.2 / PI).abs() < 1e-7);
        let b = Bsdf::BlinnPhong(BlinnPhong {
            kd,
            ks,
            shininess: 100.0,
        })
        .eval(Vec3::Z, Vec3::Z);
        assert!((b.x - (0.2 / PI + 0.5 * 108.0 / (8.0 * PI))).abs() < 1e-5);
        let g = Bsdf::Ggx(Ggx { kd, ks, alpha: 0.2 }).eval_lobes(Vec3::Z, Vec3::Z);
        assert!((g.glossy.x - 0.5 / (4.0 * PI * 0.04)).abs() < 1e-5);
    }

    #[test]
    fn zero_alpha_stays_finite() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        for b in [
            Bsdf::Ggx(Ggx {
                kd: Vec3::ZERO,
                ks: Vec3::ONE,
                alpha: 0.0,
            }),
            Bsdf::Ward(Ward {
                kd: Vec3::ZERO,
                ks: Vec3::ONE,
                alpha: 0.0,
            }),
        ] {
            let s = b.sample(wo, 0.5, Vec2::new(0.3, 0.7)).expect("a sample");
            assert!(
                s.f.is_finite() && s.pdf.is_finite() && s.pdf > 0.0,
                "{b:?}: {s:?}"
            );
            assert!((s.wi - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-3);
        }
    }
}
