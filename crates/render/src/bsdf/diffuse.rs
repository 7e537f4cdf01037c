//! The Lambertian lobe `kd / pi`, which every model's diffuse part is, and the model that is
//! only that, [`Diffuse`]. (The lobe mixture in the parent module samples it cosine-weighted.)

use super::numbers::{Lanes, Spectrum};
use super::{Lobes, Model, Reflectances};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// `f = kd / pi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Diffuse reflectance (albedo), linear RGB.
    pub kd: Vec3,
}

/// The Lambertian lobe of reflectance `kd`: `kd / pi`.
#[inline(always)]
pub(super) fn lambert<L: Lanes, S: Spectrum<L>>(kd: S) -> S {
    kd * FRAC_1_PI
}

/// The Lambertian lobe has no terms that depend on `wo`.
#[derive(Clone, Copy, Debug)]
pub(super) struct DiffuseAtWo;

impl Model for Diffuse {
    type AtWo = DiffuseAtWo;

    #[inline]
    fn at_wo(&self, _wo: Vec3) -> DiffuseAtWo {
        DiffuseAtWo
    }

    #[inline]
    fn reflectances(&self) -> Reflectances<Vec3> {
        Reflectances {
            diffuse: self.kd,
            glossy: Vec3::ZERO,
            sheen: Vec3::ZERO,
            retro: Vec3::ZERO,
        }
    }

    #[inline(always)]
    fn lobes<L: Lanes, S: Spectrum<L>>(
        _at: &DiffuseAtWo,
        r: Reflectances<S>,
        _wo: Vec3,
        _wi: [L; 3],
    ) -> Lobes<S, L> {
        Lobes {
            diffuse: lambert(r.diffuse),
            glossy: r.glossy,
            glossy_pdf: L::splat(0.0),
        }
    }

    #[inline]
    fn glossy_probability(&self, _wo: Vec3) -> f32 {
        0.0
    }

    #[inline]
    fn sample_glossy(&self, _wo: Vec3, _u: Vec2) -> Option<Vec3> {
        None
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.kd
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::tests::{mc_albedo, run};
    use crate::bsdf::Bsdf;

    #[test]
    fn chi_square_diffuse() {
        for theta in [0.0, 80.0] {
            let b = Bsdf::Diffuse(Diffuse {
                kd: Vec3::splat(0.5),
            });
            run(format!("diffuse theta_o {theta}"), b, theta, 5);
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
}
