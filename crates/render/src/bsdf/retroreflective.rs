//! [`Retroreflective`]: road-marking paint with glass beads, the paper's GGX model with a third
//! part that sends light back toward where it came from.
//!
//! Glass beads half sunk in the paint act as cat's eyes: light entering a bead is focused on
//! its back, reflected by the paint and leaves along the way it came, within a degree or two.
//! Road engineers measure it as the coefficient of retroreflected luminance `R_L = L / E_perp`
//! (luminance seen over the illuminance on a plane facing the lamp, in mcd m^-2 lx^-1), at the
//! geometry of EN 1436 and ASTM E1710: a lamp 1.24 degrees above the road, the eye 1.05 degrees
//! above the lamp's direction, which is a driver 30 m from the marking. White paint with beads
//! measures 100-300 when dry and 25-50 under a film of water, which drowns the beads' optics
//! (EN 1436's RW classes); plain paint measures 2-3, its Lambertian `kd / pi cos(88.76 deg)`.
//!
//! The retroreflective lobe is a cone about `wo` (the light's direction is near the viewer's):
//! `f_r = kr (n + 1) / (2 pi) max(0, wo.wi)^n / max(wo.z, wi.z)`, so that
//!
//! - it is reciprocal (both factors are symmetric in `wo` and `wi`);
//! - it conserves energy: `f_r cos(theta_i)` is at most `kr` times the cone's density, so the
//!   lobe reflects at most `kr`;
//! - `R_L = f_r cos(theta_i)` is about `kr (n + 1) / (2 pi) cos^n(gamma)` at observation angle
//!   `gamma`, whatever the incidence, as beads measure: the same paint is bright at 30 m and
//!   at 80 m under a car's headlights (see [`Retroreflective::kr_for_rl`]).
//!
//! The cone's width is `1 / sqrt(n)` radians (where `cos^n` falls to `e^-1/2`).
//!
//! Its value counts as diffuse ([`super::LobeValues::diffuse`]), as a glTF sheen's does: the
//! glossy values are what the renderer's `specular` layer and the streak mask take for a
//! mirror image of a light, and a marking that shines back at the headlights lighting it is
//! seen where it is, at the surface's disparity. It is sampled with the glossy lobe: sampling
//! the glossy lobe picks the GGX part or the cone with probabilities from their albedo
//! estimates for `wo`, and the glossy strategy's density is their mixture. The cone is
//! sampled about `wo` by `cos^n` (density `(n + 1) / (2 pi) (wo.wi)^n`); its mass below the
//! horizon is lost, as any glossy lobe's.

use super::ggx::{albedo_factor, microfacet, sample_visible_normal, GgxAtWo};
use super::numbers::{Lanes, Spectrum};
use super::{glossy_probability, reflect, Lobes, Model, Reflectances, MIN_ALPHA};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;
use streaks_image::luminance;

/// Bead paint: `f = kd/pi + ks GGX(wo, wi) + kr (n + 1) / (2 pi) max(0, wo.wi)^n /
/// max(wo.z, wi.z)`, the paper's [`super::Ggx`] (its separable-Smith GGX lobe, the wet film
/// on the paint) plus the retroreflective cone of the module documentation, whose value
/// counts as diffuse and which is sampled with the glossy lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Retroreflective {
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance of the GGX lobe.
    pub ks: Vec3,
    /// The GGX lobe's alpha.
    pub alpha: f32,
    /// The retroreflective cone's reflectance (its albedo at most; see
    /// [`Retroreflective::kr_for_rl`] for the value of a measured paint).
    pub kr: Vec3,
    /// The cone's exponent `n`: its width is `1 / sqrt(n)` radians.
    pub exponent: f32,
}

/// The retroreflective cone's width where a material gives none, radians: 1.5 degrees, the
/// observation angle at which bead paint's `R_L` has fallen to about 60 % of its peak.
pub const BEAD_CONE_WIDTH: f32 = 0.026;

/// EN 1436's illumination angle for `R_L`: the lamp 1.24 degrees above the road.
pub const RL_ILLUMINATION_DEG: f32 = 1.24;
/// EN 1436's observation angle for `R_L`: the eye 1.05 degrees above the lamp's direction.
pub const RL_OBSERVATION_DEG: f32 = 1.05;

impl Retroreflective {
    /// `alpha`, kept at or above [`MIN_ALPHA`].
    #[inline]
    fn alpha(&self) -> f32 {
        self.alpha.max(MIN_ALPHA)
    }

    /// The exponent, kept non-negative.
    #[inline]
    fn exponent(&self) -> f32 {
        self.exponent.max(0.0)
    }

    /// The cone's exponent for a width of `width` radians, `1 / width^2`.
    pub fn exponent_for_width(width: f32) -> f32 {
        1.0 / (width * width)
    }

    /// The `kr` (grey) that makes the cone of exponent `n` alone measure `rl` (cd m^-2 lx^-1,
    /// not millicandela) at EN 1436's geometry ([`RL_ILLUMINATION_DEG`],
    /// [`RL_OBSERVATION_DEG`]): `R_L = f_r cos(theta_i)` there.
    pub fn kr_for_rl(rl: f32, n: f32) -> f32 {
        rl / Self::cone_rl(n)
    }

    /// `R_L` of the cone of exponent `n` with `kr = 1` at EN 1436's geometry.
    fn cone_rl(n: f32) -> f32 {
        let light = RL_ILLUMINATION_DEG.to_radians();
        let eye = light + RL_OBSERVATION_DEG.to_radians();
        let (wi, wo) = (elevated(light), elevated(eye));
        let cos = wo.dot(wi);
        (n + 1.0) / TAU * cos.powf(n) / wo.z.max(wi.z) * wi.z
    }
}

/// A direction `elevation` radians above the surface, in the x-z plane.
fn elevated(elevation: f32) -> Vec3 {
    let (s, c) = elevation.sin_cos();
    Vec3::new(c, 0.0, s)
}

/// The GGX lobe's terms for `wo`, the cone's exponent and normalisation, and the share of
/// the glossy lobe's samples that go to the cone.
#[derive(Clone, Copy, Debug)]
pub(super) struct RetroAtWo {
    ggx: GgxAtWo,
    n: f32,
    norm: f32,
    cone_share: f32,
}

/// The cone's value without its colour, `(n + 1) / (2 pi) (wo.wi)^n / max(wo.z, wi.z)`, and
/// its sampling density `(n + 1) / (2 pi) (wo.wi)^n`, for `wo` and `wi` above the surface.
#[inline(always)]
fn cone<L: Lanes>(at: &RetroAtWo, wo: Vec3, wi: [L; 3]) -> (L, L) {
    let cos = (wi[0] * wo.x + wi[1] * wo.y + wi[2] * wo.z).saturate();
    let pdf = cos.powf(at.n) * at.norm;
    // max(a, b) = (a + b + |a - b|) / 2, in lanes.
    let z = L::splat(wo.z);
    let max_z = (wi[2] + z + (wi[2] - z).abs()) * 0.5;
    (pdf / max_z, pdf)
}

impl Model for Retroreflective {
    type AtWo = RetroAtWo;

    #[inline]
    fn at_wo(&self, wo: Vec3) -> RetroAtWo {
        let n = self.exponent();
        let (ggx, cone) = self.glossy_estimates(wo);
        RetroAtWo {
            ggx: GgxAtWo::new(self.alpha(), wo),
            n,
            norm: (n + 1.0) / TAU,
            cone_share: if cone > 0.0 { cone / (ggx + cone) } else { 0.0 },
        }
    }

    #[inline]
    fn reflectances(&self) -> Reflectances<Vec3> {
        Reflectances {
            diffuse: self.kd,
            glossy: self.ks,
            sheen: Vec3::ZERO,
            retro: self.kr,
        }
    }

    #[inline(always)]
    fn lobes<L: Lanes, S: Spectrum<L>>(
        at: &RetroAtWo,
        r: Reflectances<S>,
        wo: Vec3,
        wi: [L; 3],
    ) -> Lobes<S, L> {
        let (spec, spec_pdf) = microfacet(&at.ggx, wo, wi);
        let (retro, retro_pdf) = cone(at, wo, wi);
        let q = at.cone_share;
        let mut lobes = Lobes::paper(r, (spec, spec_pdf * (1.0 - q)));
        lobes.diffuse = lobes.diffuse + r.retro * retro;
        lobes.glossy_pdf = lobes.glossy_pdf + retro_pdf * q;
        lobes
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let (ggx, cone) = self.glossy_estimates(wo);
        glossy_probability(ggx + cone, 1.0, luminance(self.kd))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let (ggx, cone) = self.glossy_estimates(wo);
        let q = if cone > 0.0 { cone / (ggx + cone) } else { 0.0 };
        if u.x < q {
            // Reuse the chosen part of `u.x` for the cone's polar angle.
            let ux = u.x / q;
            let cos_t = (1.0 - ux).powf(1.0 / (self.exponent() + 1.0));
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let (s, c) = (TAU * u.y).sin_cos();
            let (t, b) = wo.any_orthonormal_pair();
            Some(cos_t * wo + sin_t * (c * t + s * b))
        } else {
            let ux = ((u.x - q) / (1.0 - q)).min(1.0 - f32::EPSILON);
            sample_visible_normal(wo, self.alpha(), Vec2::new(ux, u.y)).map(|h| reflect(wo, h))
        }
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.kd + self.ks + self.kr
    }
}

impl Retroreflective {
    /// The albedo estimates of the glossy lobe's two parts for `wo`: the GGX lobe's
    /// `luminance(ks)` times its closed-form factor, the cone's `luminance(kr)` times the
    /// share of the cone above the horizon (about half at grazing).
    #[inline]
    fn glossy_estimates(&self, wo: Vec3) -> (f32, f32) {
        let ggx = luminance(self.ks) * albedo_factor(wo.z, self.alpha());
        let width = 1.0 / (self.exponent() + 1.0).sqrt();
        let above = (0.5 + 0.5 * (wo.z / width).min(1.0)).min(1.0);
        (ggx, luminance(self.kr) * above)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::tests::{mc_albedo, random_dir, run, MIXED_ANGLES, RETRO_EXPONENTS};
    use crate::bsdf::{Bsdf, Ggx};
    use crate::sampling::Pcg32;
    use glam::Quat;
    use std::f32::consts::PI;

    /// The chi-square tests' materials: the cone alone, and wet paint (a dark diffuse part,
    /// a GGX film and a weaker cone).
    fn retro_materials() -> [(Vec3, Vec3, Vec3); 2] {
        [
            (Vec3::ZERO, Vec3::ZERO, Vec3::ONE),
            (
                Vec3::new(0.3, 0.3, 0.28),
                Vec3::splat(0.05),
                Vec3::new(0.2, 0.2, 0.15),
            ),
        ]
    }

    #[test]
    fn chi_square_retroreflective() {
        for (i, (kd, ks, kr)) in retro_materials().into_iter().enumerate() {
            for exponent in RETRO_EXPONENTS {
                for &theta in &MIXED_ANGLES {
                    let b = Bsdf::Retroreflective(Retroreflective {
                        kd,
                        ks,
                        alpha: 0.1,
                        kr,
                        exponent,
                    });
                    run(
                        format!("retroreflective {i} n {exponent} theta_o {theta}"),
                        b,
                        theta,
                        5,
                    );
                }
            }
        }
    }

    /// Without the cone it is exactly the paper's GGX model.
    #[test]
    fn no_cone_is_the_paper_ggx() {
        let mut rng = Pcg32::new(21, 1);
        let (kd, ks, alpha) = (Vec3::new(0.2, 0.3, 0.1), Vec3::new(0.7, 0.5, 0.9), 0.2);
        let retro = Bsdf::Retroreflective(Retroreflective {
            kd,
            ks,
            alpha,
            kr: Vec3::ZERO,
            exponent: 500.0,
        });
        let ggx = Bsdf::Ggx(Ggx { kd, ks, alpha });
        for _ in 0..500 {
            let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
            assert_eq!(retro.eval_pdf(wo, wi), ggx.eval_pdf(wo, wi), "{wo} {wi}");
        }
    }

    /// The cone is brightest toward `wo` itself, and there `f cos(theta_i)` is
    /// `kr (n + 1) / (2 pi)` at every incidence.
    #[test]
    fn the_cone_peaks_back_toward_the_viewer() {
        let b = Retroreflective {
            kd: Vec3::ZERO,
            ks: Vec3::ZERO,
            alpha: 0.1,
            kr: Vec3::splat(0.01),
            exponent: 2000.0,
        };
        for theta in [0.0f32, 60.0, 88.76] {
            let (s, c) = theta.to_radians().sin_cos();
            let wo = Vec3::new(s, 0.0, c);
            let f = Bsdf::Retroreflective(b).eval(wo, wo).x * wo.z;
            let want = 0.01 * 2001.0 / TAU;
            assert!((f - want).abs() < 1e-3 * want, "{theta}: {f} vs {want}");
            let tilt = Quat::from_axis_angle(wo.any_orthonormal_vector(), 2f32.to_radians());
            let off = tilt * wo;
            let f_off = Bsdf::Retroreflective(b).eval(wo, off).x * off.z;
            assert!(f_off < 0.5 * f, "{theta}: {f_off} vs {f}");
        }
    }

    /// The cone's light counts as diffuse: the glossy values are the GGX film's alone, so the
    /// `specular` layer and the streak mask never take a lit marking for a streak.
    #[test]
    fn the_cone_is_no_streak() {
        let mut rng = Pcg32::new(22, 1);
        let (kd, ks, alpha) = (Vec3::splat(0.3), Vec3::splat(0.05), 0.1);
        let kr = Vec3::splat(0.01);
        let retro = Bsdf::Retroreflective(Retroreflective {
            kd,
            ks,
            alpha,
            kr,
            exponent: 2000.0,
        });
        let ggx = Bsdf::Ggx(Ggx { kd, ks, alpha });
        for _ in 0..200 {
            let wo = random_dir(&mut rng);
            let wo = Vec3::new(wo.x, wo.y, wo.z.abs());
            for wi in [wo, random_dir(&mut rng)] {
                let (a, b) = (retro.eval_lobes(wo, wi), ggx.eval_lobes(wo, wi));
                assert_eq!(a.glossy, b.glossy);
                assert!(a.diffuse.x >= b.diffuse.x);
            }
            assert!(retro.eval_lobes(wo, wo).diffuse.x > 10.0 * kd.x / PI);
        }
    }

    /// Roughened for path regularisation, it is still a model whose sampling, density and
    /// values agree, with a wider cone.
    #[test]
    fn roughened_retroreflective_samples_what_it_evaluates() {
        let b = Bsdf::Retroreflective(Retroreflective {
            kd: Vec3::splat(0.3),
            ks: Vec3::splat(0.05),
            alpha: 0.02,
            kr: Vec3::splat(0.2),
            exponent: 5000.0,
        });
        let r = b.roughened(0.41);
        let Bsdf::Retroreflective(m) = r else {
            unreachable!()
        };
        assert_eq!(m.alpha, 0.41);
        assert!(
            (m.exponent - 1.0 / (0.82 * 0.82)).abs() < 1e-3,
            "{}",
            m.exponent
        );
        run("roughened retroreflective".into(), r, 75.0, 6);
    }

    /// A paint made for `R_L` measures it at EN 1436's geometry.
    #[test]
    fn kr_for_rl_gives_the_measured_rl() {
        let n = Retroreflective::exponent_for_width(1.5f32.to_radians());
        let kr = Retroreflective::kr_for_rl(0.3, n);
        let b = Bsdf::Retroreflective(Retroreflective {
            kd: Vec3::ZERO,
            ks: Vec3::ZERO,
            alpha: 0.1,
            kr: Vec3::splat(kr),
            exponent: n,
        });
        let light = RL_ILLUMINATION_DEG.to_radians();
        let wi = elevated(light);
        let wo = elevated(light + RL_OBSERVATION_DEG.to_radians());
        let rl = b.eval(wo, wi).x * wi.z;
        assert!((rl - 0.3).abs() < 1e-3, "R_L {rl}");
        assert!(kr > 0.0 && kr < 0.01, "kr {kr}");
    }

    /// The cone reflects at most `kr`: a white cone's directional albedo.
    #[test]
    fn white_furnace_retroreflective() {
        for exponent in [2.0f32, 30.0, 1000.0] {
            let b = Bsdf::Retroreflective(Retroreflective {
                kd: Vec3::ZERO,
                ks: Vec3::ZERO,
                alpha: 0.1,
                kr: Vec3::ONE,
                exponent,
            });
            for theta in [0.0f32, 45.0, 80.0, 88.0] {
                let (s, c) = theta.to_radians().sin_cos();
                let (a, err) = mc_albedo(&b, Vec3::new(s, 0.0, c), 100_000, 41);
                assert!(
                    a <= 1.0 + 4.0 * err,
                    "n {exponent} at {theta}: {a} +- {err}"
                );
                assert!(a > 0.3, "n {exponent} at {theta}: {a}");
            }
        }
    }
}
