//! The Henyey-Greenstein phase function ([`HenyeyGreenstein`]): how the fog
//! ([`crate::medium::Fog`]) scatters light at a collision.
//!
//! Directions follow the BSDFs' convention (`wo` toward the viewer, `wi` toward the light,
//! both pointing away from the scattering point), and `g` has Mitsuba 3's sign (`hg.cpp`):
//! `g > 0` scatters forward, i.e. light keeps going roughly the way it went, which is
//! `wi ~ -wo`. With `cos theta = -wo . wi` the cosine of the deflection,
//!
//! `p(theta) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2))`,
//!
//! normalised over the sphere of `wi`. Sampling inverts its cdf exactly (Mitsuba's
//! `HGPhaseFunction::sample`), so the sampled direction's weight `p / pdf` is 1.

use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// Below this `|g|` the phase function is sampled as isotropic (the exact inversion divides
/// by `g`).
const ISOTROPIC_G: f32 = 1e-3;

/// The Henyey-Greenstein phase function with asymmetry `g` in (-1, 1) (see the module
/// documentation for the convention).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    /// The mean cosine of the deflection: > 0 forward, < 0 backward, 0 isotropic.
    pub g: f32,
}

/// A sampled direction of a phase function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseSample {
    /// The sampled direction toward the light (unit, world space).
    pub wi: Vec3,
    /// The phase function's value at `wi`, which is also its density (per steradian).
    pub pdf: f32,
}

impl HenyeyGreenstein {
    /// The phase function's value for the deflection cosine `cos_theta`.
    #[inline]
    fn eval_cos(self, cos_theta: f32) -> f32 {
        let g = self.g;
        let denom = (1.0 + g * g - 2.0 * g * cos_theta).max(1e-12);
        (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
    }

    /// The phase function's value (= its sampling density) for light arriving from `wi` and
    /// leaving toward `wo` (both unit, pointing away from the point).
    #[inline]
    pub fn eval(self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_cos(-wo.dot(wi))
    }

    /// Samples `wi` for `wo` with `u` in [0, 1)^2, exactly by the phase function (weight 1).
    #[inline]
    pub fn sample(self, wo: Vec3, u: Vec2) -> PhaseSample {
        let g = self.g;
        let cos_theta = if g.abs() < ISOTROPIC_G {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
            ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
        };
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = TAU * u.y;
        // Theta is the light's deflection: it travels along -wi before and along wo after, so
        // theta = 0 (no deflection) is wi = -wo.
        let frame = Frame::from_normal(-wo);
        let wi = frame
            .to_world(Vec3::new(
                sin_theta * phi.cos(),
                sin_theta * phi.sin(),
                cos_theta,
            ))
            .normalize();
        PhaseSample {
            wi,
            pdf: self.eval_cos(cos_theta),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{chi_square_sphere, ChiSquareConfig};

    const GS: [f32; 7] = [-0.9, -0.5, -0.0005, 0.0, 0.3, 0.7, 0.95];

    #[test]
    fn sampling_follows_the_density_for_forward_backward_and_isotropic_g() {
        let wos = [Vec3::Z, Vec3::new(0.3, -0.5, 0.81).normalize()];
        let config = ChiSquareConfig {
            num_tests: GS.len() * wos.len(),
            ..ChiSquareConfig::default()
        };
        for g in GS {
            for wo in wos {
                let hg = HenyeyGreenstein { g };
                let report = chi_square_sphere(
                    &format!("hg g={g} wo={wo}"),
                    &config,
                    |rng| {
                        let s = hg.sample(wo, rng.next_2d());
                        let back = hg.eval(wo, s.wi);
                        assert!(
                            (s.pdf - back).abs() <= 1e-3 * back.max(1e-3),
                            "{g}: {} vs {back}",
                            s.pdf
                        );
                        assert!((s.wi.length() - 1.0).abs() < 1e-4);
                        Some(s.wi)
                    },
                    |wi| hg.eval(wo, wi),
                );
                assert!(report.passed, "{report}");
            }
        }
    }

    #[test]
    fn integrates_to_one_and_has_mean_cosine_g() {
        // Midpoint rule over the deflection cosine: int p 2 pi dmu = 1, int mu p 2 pi dmu = g.
        for g in GS {
            let hg = HenyeyGreenstein { g };
            let n = 400_000;
            let (mut total, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let mu = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
                let p = hg.eval_cos(mu as f32) as f64 * TAU as f64 * 2.0 / n as f64;
                total += p;
                mean += mu * p;
            }
            assert!((total - 1.0).abs() < 2e-3, "{g}: {total}");
            assert!((mean - g as f64).abs() < 2e-3, "{g}: {mean}");
        }
    }

    #[test]
    fn positive_g_scatters_forward_as_mitsuba_has_it() {
        // Light travelling along +X (from wi = -X) toward a viewer at +X (wo = +X): no
        // deflection, the peak for g > 0.
        let hg = HenyeyGreenstein { g: 0.7 };
        let forward = hg.eval(Vec3::X, -Vec3::X);
        let back = hg.eval(Vec3::X, Vec3::X);
        assert!(forward > 10.0 * back, "{forward} {back}");
        // Mitsuba's eval_hg(dot(wo_m, wi_m)) with wi_m = our wo and wo_m = our wi.
        let mitsuba = |c: f32| (1.0 - 0.49) / (4.0 * PI * (1.0 + 0.49 + 1.4 * c).powf(1.5));
        for wi in [Vec3::X, -Vec3::X, Vec3::Y, Vec3::new(0.6, 0.8, 0.0)] {
            let ours = hg.eval(Vec3::X, wi);
            let theirs = mitsuba(Vec3::X.dot(wi));
            assert!((ours - theirs).abs() < 1e-5 * theirs.max(1.0), "{wi}");
        }
        // u.x = 1 samples the peak (no deflection).
        let s = hg.sample(Vec3::X, Vec2::new(0.999_999, 0.3));
        assert!(s.wi.dot(-Vec3::X) > 0.999, "{}", s.wi);
    }
}
