//! GGX: the microfacet lobe that [`Ggx`] and [`super::GltfPbr`] share (the Smith masking, the
//! microfacet BRDF with its visible-normal density, visible-normal sampling, and the albedo
//! estimate of the lobe choice), and the paper's `ggx` model [`Ggx`]. The paper's model uses
//! the separable Smith visibility `G1(wo) G1(wi)` ([`microfacet`], as Mitsuba does), the glTF
//! model the height-correlated one ([`microfacet_correlated`], as the glTF specification's
//! appendix B does); both sample the same visible normals.

use super::numbers::{Lanes, Spectrum};
use super::{glossy_probability, reflect, Lobes, Model, Reflectances, MIN_ALPHA};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};
use streaks_image::luminance;

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

impl Ggx {
    /// `alpha`, kept at or above [`MIN_ALPHA`].
    #[inline]
    fn alpha(&self) -> f32 {
        self.alpha.max(MIN_ALPHA)
    }
}

impl Model for Ggx {
    type AtWo = GgxAtWo;

    #[inline]
    fn at_wo(&self, wo: Vec3) -> GgxAtWo {
        GgxAtWo::new(self.alpha(), wo)
    }

    #[inline]
    fn reflectances(&self) -> Reflectances<Vec3> {
        Reflectances {
            diffuse: self.kd,
            glossy: self.ks,
            sheen: Vec3::ZERO,
            retro: Vec3::ZERO,
        }
    }

    #[inline(always)]
    fn lobes<L: Lanes, S: Spectrum<L>>(
        at: &GgxAtWo,
        r: Reflectances<S>,
        wo: Vec3,
        wi: [L; 3],
    ) -> Lobes<S, L> {
        Lobes::paper(r, microfacet(at, wo, wi))
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let factor = albedo_factor(wo.z, self.alpha());
        glossy_probability(luminance(self.ks), factor, luminance(self.kd))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        sample_visible_normal(wo, self.alpha(), u).map(|h| reflect(wo, h))
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.kd + self.ks
    }
}

/// `v.z + sqrt(v.z^2 + alpha^2 (v.x^2 + v.y^2))` for `v` above the surface: GGX's separable
/// Smith masking over the cosine, `G1(v) / v.z`, is `2 /` this. (Mitsuba 3's `smith_g1` is
/// `2 / (1 + sqrt(1 + alpha^2 tan^2(theta_v)))`, 0 when `v` sees the back of the microfacet,
/// which never happens for the half vector of two directions above the surface.)
#[inline(always)]
fn g1_denominator<L: Lanes>(v: [L; 3], a2: f32) -> L {
    v[2] + masking_root(v, a2)
}

/// `sqrt(v.z^2 + alpha^2 (v.x^2 + v.y^2))` for a unit `v` above the surface, i.e.
/// `sqrt(alpha^2 + (1 - alpha^2) cos^2(theta_v))`: `v.z` times `1 + 2 Lambda(v)`, with
/// `Lambda` GGX's Smith masking exponent.
#[inline(always)]
pub(super) fn masking_root<L: Lanes>(v: [L; 3], a2: f32) -> L {
    let [x, y, z] = v;
    (z * z + (x * x + y * y) * a2).sqrt()
}

/// A GGX lobe's terms that depend on its alpha and `wo` alone.
#[derive(Clone, Copy, Debug)]
pub(super) struct GgxAtWo {
    /// `alpha^2`.
    pub(super) a2: f32,
    /// [`g1_denominator`] of `wo`.
    pub(super) go: f32,
    /// [`masking_root`] of `wo`.
    pub(super) ro: f32,
}

impl GgxAtWo {
    /// The terms for `alpha` (already at or above [`MIN_ALPHA`]) and `wo`.
    #[inline]
    pub(super) fn new(alpha: f32, wo: Vec3) -> Self {
        let a2 = alpha * alpha;
        let ro = masking_root(wo.to_array(), a2);
        GgxAtWo {
            a2,
            go: wo.z + ro,
            ro,
        }
    }
}

/// The GGX microfacet lobe without its colour, `D(h) G1(wo) G1(wi) / (4 wo.z wi.z)`, and the
/// solid-angle density of `wi` when the lobe samples visible normals, for `wo` and `wi` above
/// the surface and `at` the lobe's [`GgxAtWo`] for `wo`.
///
/// With the half vector left unnormalised, `h = wo + wi`, and
/// `q = h.x^2 + h.y^2 + alpha^2 h.z^2`, Mitsuba 3's GGX
/// `D = 1 / (pi alpha^2 ((h.x^2 + h.y^2) / alpha^2 + h.z^2)^2)` of the normalised half vector
/// is `alpha^2 |h|^4 / (pi q^2)`, so with `go`, `gi` the [`g1_denominator`]s of `wo` and `wi`
/// the lobe is `alpha^2 |h|^4 / (pi q^2 go gi)`. (Mitsuba also cuts `D` to 0 below 1e-20; that
/// is not done here.) The visible-normal density `D(h) G1(wo, h) / (4 wo.z)` (the Jacobian
/// `1 / (4 wo.h)` cancels `wo.h`) is the lobe times `wi.z / G1(wi)`, i.e. times `gi / 2`.
#[inline(always)]
pub(super) fn microfacet<L: Lanes>(at: &GgxAtWo, wo: Vec3, wi: [L; 3]) -> (L, L) {
    let GgxAtWo { a2, go, .. } = *at;
    let (h2, q) = half_vector_terms(wo, wi, a2);
    let gi = g1_denominator(wi, a2);
    let spec = h2 * a2 * h2 / (q * PI * q * go * gi);
    (spec, spec * 0.5 * gi)
}

/// `|h|^2` and `q = h.x^2 + h.y^2 + alpha^2 h.z^2` of the unnormalised half vector
/// `h = wo + wi` (see [`microfacet`]): `D(h) = alpha^2 |h|^4 / (pi q^2)`.
#[inline(always)]
fn half_vector_terms<L: Lanes>(wo: Vec3, wi: [L; 3], a2: f32) -> (L, L) {
    let [hx, hy, hz] = [wi[0] + wo.x, wi[1] + wo.y, wi[2] + wo.z];
    let h2 = hx * hx + hy * hy + hz * hz;
    let q = hx * hx + hy * hy + hz * a2 * hz;
    (h2, q)
}

/// The GGX microfacet lobe with the height-correlated Smith visibility, `D(h) V(wo, wi)`, and
/// the same visible-normal density as [`microfacet`], for `wo` and `wi` above the surface and
/// `at` the lobe's [`GgxAtWo`] for `wo`.
///
/// The glTF 2.0 specification, appendix B (and Heitz 2014, "Understanding the
/// Masking-Shadowing Function in Microfacet-Based BRDFs", eq. 99):
/// `V = G2 / (4 cos_o cos_i) = 0.5 / (cos_i sqrt(alpha^2 + (1 - alpha^2) cos_o^2) +
/// cos_o sqrt(alpha^2 + (1 - alpha^2) cos_i^2))`, with `G2 = 1 / (1 + Lambda(wo) +
/// Lambda(wi))`, written with the [`masking_root`]s `ro`, `ri`. The density of sampled
/// visible normals, `D G1(wo) / (4 cos_o) = D / (2 go)`, depends on the masking of `wo` alone,
/// so it is [`microfacet`]'s.
#[inline(always)]
pub(super) fn microfacet_correlated<L: Lanes>(at: &GgxAtWo, wo: Vec3, wi: [L; 3]) -> (L, L) {
    let GgxAtWo { a2, go, ro } = *at;
    let (h2, q) = half_vector_terms(wo, wi, a2);
    let d = h2 * a2 * h2 / (q * PI * q);
    let ri = masking_root(wi, a2);
    let spec = d * 0.5 / (wi[2] * ro + ri * wo.z);
    (spec, d * (0.5 / go))
}

/// Samples a GGX visible normal for `wo` (density `D(h) G1(wo, h) max(0, wo.h) / wo.z`) by
/// Dupuy and Benyoub's spherical caps. `None` only in a degenerate (measure-zero) case.
#[inline]
pub(super) fn sample_visible_normal(wo: Vec3, alpha: f32, u: Vec2) -> Option<Vec3> {
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

/// Cheap estimate of the GGX lobe's directional albedo (with `ks = 1`) for the lobe choice:
/// `G1` at `max(cos(theta_o), alpha)`. Visible normals tilt toward a grazing `wo`, so the
/// reflected directions are less grazing than `wo`; measured albedos (alpha 0.1 / 0.7): 0.99 /
/// 0.50 at normal incidence and 0.90 / 0.72 at 88 degrees, against estimates 1.0 / 1.0 and
/// 0.83 / 0.90.
#[inline]
pub(super) fn albedo_factor(cos_o: f32, alpha: f32) -> f32 {
    let mu = cos_o.max(alpha).min(1.0);
    let tan2 = (1.0 - mu * mu) / (mu * mu);
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

#[cfg(test)]
mod tests {
    //! The chi-square tests of [`Ggx`], and its identity with Mitsuba 3's `blendbsdf` with the
    //! microfacet formulas written again here in f64 straight from Mitsuba 3's `microfacet.h`
    //! and `roughconductor.cpp`, independently of the code under test.
    use super::*;
    use crate::bsdf::tests::{d3, mc_albedo, paper_materials, random_dir, run, ALPHAS};
    use crate::bsdf::Bsdf;
    use crate::sampling::Pcg32;
    use crate::testing::adaptive_simpson;
    use std::f64::consts::PI as PI64;

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
    fn ggx_at_normal_incidence() {
        // h = n: D = 1 / (pi alpha^2), G1 = 1, so glossy = ks / (4 pi alpha^2).
        let (kd, ks) = (Vec3::splat(0.2), Vec3::splat(0.5));
        let g = Bsdf::Ggx(Ggx { kd, ks, alpha: 0.2 }).eval_lobes(Vec3::Z, Vec3::Z);
        assert!((g.glossy.x - 0.5 / (4.0 * PI * 0.04)).abs() < 1e-5);
    }
}
