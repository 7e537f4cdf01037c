//! The paper's isotropic Ward model [`Ward`]: its glossy lobe, sampled by the Gaussian in
//! `tan(delta)` (Walter 2005, "Notes on the Ward BRDF").

use super::numbers::{Lanes, Spectrum};
use super::{glossy_probability, reflect_about_half, Lobes, Model, Reflectances, MIN_ALPHA};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use streaks_image::luminance;

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

impl Ward {
    /// `alpha`, kept at or above [`MIN_ALPHA`].
    #[inline]
    fn alpha(&self) -> f32 {
        self.alpha.max(MIN_ALPHA)
    }
}

/// The Ward glossy lobe without its colour,
/// `exp(-tan^2(delta)/alpha^2) / (4 pi alpha^2 sqrt(cos_i cos_o))`, and its sampling density,
/// for `wo` and `wi` above the surface. The half vector is drawn with the normalised slope
/// density's solid-angle form `exp(-tan^2/alpha^2) / (pi alpha^2 cos^3(delta))`, and
/// `1 / (4 wo.h)` turns it into a density of `wi`. Both are computed from the unnormalised
/// half vector `h = wo + wi`: `tan^2(delta) = (h.x^2 + h.y^2) / h.z^2` and
/// `cos^3(delta) wo.h = h.z^3 (wo . h) / |h|^4`.
#[inline(always)]
fn lobe<L: Lanes>(wo: Vec3, wi: [L; 3], a2: f32) -> (L, L) {
    let [hx, hy, hz] = [wi[0] + wo.x, wi[1] + wo.y, wi[2] + wo.z];
    let tan2 = (hx * hx + hy * hy) / (hz * hz);
    let gauss = (-tan2 / a2).exp() / (PI * a2);
    let f = gauss / ((wi[2] * wo.z).sqrt() * 4.0);
    let h2 = hx * hx + hy * hy + hz * hz;
    let wo_h = hx * wo.x + hy * wo.y + hz * wo.z;
    (f, gauss * h2 * h2 / (hz * hz * hz * 4.0 * wo_h))
}

impl Model for Ward {
    /// `alpha^2`.
    type AtWo = f32;

    #[inline]
    fn at_wo(&self, _wo: Vec3) -> f32 {
        self.alpha() * self.alpha()
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
        a2: &f32,
        r: Reflectances<S>,
        wo: Vec3,
        wi: [L; 3],
    ) -> Lobes<S, L> {
        Lobes::paper(r, lobe(wo, wi, *a2))
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

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        // tan^2(delta) = -alpha^2 ln(1 - u): 1 - u is in (0, 1], so the log is finite.
        let tan2 = -self.alpha() * self.alpha() * (1.0 - u.x).ln();
        let cos_d = 1.0 / (1.0 + tan2).sqrt();
        let sin_d = (tan2 * cos_d * cos_d).sqrt();
        reflect_about_half(wo, cos_d, sin_d, u.y)
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.kd + self.ks
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::tests::{paper_materials, run, ALPHAS};
    use crate::bsdf::Bsdf;

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
    fn ward_at_normal_incidence() {
        // h = n: glossy = ks / (4 pi alpha^2).
        let (kd, ks) = (Vec3::splat(0.2), Vec3::splat(0.5));
        let w = Bsdf::Ward(Ward { kd, ks, alpha: 0.2 }).eval_lobes(Vec3::Z, Vec3::Z);
        assert!((w.glossy.x - 0.5 / (4.0 * PI * 0.04)).abs() < 1e-5);
        assert!((w.diffuse.x - 0.2 / PI).abs() < 1e-7);
    }
}
