//! Normalised Blinn-Phong [`BlinnPhong`]: its glossy lobe, sampled by `cos^s` of the half
//! vector.

use super::numbers::{Lanes, Spectrum};
use super::{glossy_probability, half_vector, reflect_about_half, Lobes, Model, Reflectances};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};
use streaks_image::luminance;

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

impl BlinnPhong {
    /// The exponent, kept non-negative.
    #[inline]
    fn shininess(&self) -> f32 {
        self.shininess.max(0.0)
    }
}

/// The Blinn-Phong exponent `s` and the lobe's normalisation `(s + 8) / (8 pi)`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BlinnPhongAtWo {
    s: f32,
    norm: f32,
}

/// The Blinn-Phong glossy lobe without its colour, `(s + 8) / (8 pi) cos^s(theta_h)`, and its
/// sampling density, for `wo` and `wi` above the surface: the half vector is drawn with density
/// `(s + 1) / (2 pi) cos^s(theta_h)`, and `1 / (4 wo.h)` turns it into a density of `wi`.
#[inline(always)]
fn lobe<L: Lanes>(at: &BlinnPhongAtWo, wo: Vec3, wi: [L; 3]) -> (L, L) {
    let BlinnPhongAtWo { s, norm } = *at;
    let h = half_vector(wo, wi);
    let cos_s = h[2].powf(s);
    let wo_h = h[0] * wo.x + h[1] * wo.y + h[2] * wo.z;
    (cos_s * norm, cos_s * ((s + 1.0) / TAU) / (wo_h * 4.0))
}

impl Model for BlinnPhong {
    type AtWo = BlinnPhongAtWo;

    #[inline]
    fn at_wo(&self, _wo: Vec3) -> BlinnPhongAtWo {
        let s = self.shininess();
        BlinnPhongAtWo {
            s,
            norm: (s + 8.0) / (8.0 * PI),
        }
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
        at: &BlinnPhongAtWo,
        r: Reflectances<S>,
        wo: Vec3,
        wi: [L; 3],
    ) -> Lobes<S, L> {
        Lobes::paper(r, lobe(at, wo, wi))
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

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let cos_t = (1.0 - u.x).powf(1.0 / (self.shininess() + 1.0));
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        reflect_about_half(wo, cos_t, sin_t, u.y)
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.kd + self.ks
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::tests::{paper_materials, run, SHININESS};
    use crate::bsdf::Bsdf;

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
    fn blinn_phong_at_normal_incidence() {
        // h = n: f = kd / pi + ks (s + 8) / (8 pi).
        let (kd, ks) = (Vec3::splat(0.2), Vec3::splat(0.5));
        let b = Bsdf::BlinnPhong(BlinnPhong {
            kd,
            ks,
            shininess: 100.0,
        })
        .eval(Vec3::Z, Vec3::Z);
        assert!((b.x - (0.2 / PI + 0.5 * 108.0 / (8.0 * PI))).abs() < 1e-5);
    }
}
