//! Peak streak radiance of a point light over a glossy ground plane, used to choose light
//! intensities: at the mirror point of the light (where the half vector is the surface
//! normal) the reflected radiance is `L = f(wi, wo) * I * cos_i / r^2`, with `f` the BRDF of
//! the scene contract at h = n. The streak's peak is close to that point, so intensities
//! are chosen to put it near 1 (exposure 0).

use glam::DVec3;

/// A reflectance model of the scene contract with its parameters (no texture).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Brdf {
    /// GGX with microfacet alpha.
    Ggx {
        /// Diffuse reflectance (grey).
        kd: f64,
        /// Specular reflectance (grey).
        ks: f64,
        /// Microfacet alpha.
        alpha: f64,
    },
    /// The paper's isotropic Ward.
    Ward {
        /// Diffuse reflectance.
        kd: f64,
        /// Specular reflectance.
        ks: f64,
        /// Ward alpha.
        alpha: f64,
    },
    /// Normalised Blinn-Phong.
    BlinnPhong {
        /// Diffuse reflectance.
        kd: f64,
        /// Specular reflectance.
        ks: f64,
        /// Shininess.
        shininess: f64,
    },
}

impl Brdf {
    /// The BRDF at h = n (mirror configuration) for the given cosines.
    pub fn at_mirror(&self, cos_i: f64, cos_o: f64) -> f64 {
        let pi = std::f64::consts::PI;
        match *self {
            Brdf::Ggx { kd, ks, alpha } => {
                let g1 = |c: f64| {
                    let tan2 = (1.0 - c * c) / (c * c);
                    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
                };
                let d = 1.0 / (pi * alpha * alpha);
                kd / pi + ks * d * g1(cos_i) * g1(cos_o) / (4.0 * cos_i * cos_o)
            }
            Brdf::Ward { kd, ks, alpha } => {
                kd / pi + ks / (4.0 * pi * alpha * alpha * (cos_i * cos_o).sqrt())
            }
            Brdf::BlinnPhong { kd, ks, shininess } => kd / pi + ks * (shininess + 8.0) / (8.0 * pi),
        }
    }
}

/// The point on the plane Y = 0 where the mirror image of `light` is seen from `eye`.
pub fn mirror_point(eye: DVec3, light: DVec3) -> DVec3 {
    let t = eye.y / (eye.y + light.y);
    let p = eye + (light - eye) * t;
    DVec3::new(p.x, 0.0, p.z)
}

/// Estimated peak streak radiance of a point light of radiant intensity `intensity` (W/sr)
/// at `light`, seen from `eye` over the ground plane Y = 0 with reflectance `brdf`.
pub fn peak_radiance(brdf: Brdf, eye: DVec3, light: DVec3, intensity: f64) -> f64 {
    let p = mirror_point(eye, light);
    let to_light = light - p;
    let r2 = to_light.length_squared();
    let cos_i = to_light.normalize().y;
    let cos_o = (eye - p).normalize().y;
    brdf.at_mirror(cos_i, cos_o) * intensity * cos_i / r2
}

/// The radiant intensity that gives a peak streak radiance `target`, rounded to two
/// significant digits so the number reads well in the README.
pub fn intensity_for_peak(brdf: Brdf, eye: DVec3, light: DVec3, target: f64) -> f64 {
    round_sig2(target / peak_radiance(brdf, eye, light, 1.0))
}

/// Rounds to two significant digits.
pub fn round_sig2(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    let e = x.abs().log10().floor() as i32 - 1;
    if e < 0 {
        let s = 10f64.powi(-e);
        (x * s).round() / s
    } else {
        let s = 10f64.powi(e);
        (x / s).round() * s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_point_reflects() {
        let eye = DVec3::new(0.0, 2.0, 0.0);
        let light = DVec3::new(0.0, 2.0, -50.0);
        let p = mirror_point(eye, light);
        assert!((p - DVec3::new(0.0, 0.0, -25.0)).length() < 1e-12);
        // Equal angles of incidence and reflection.
        let a = (light - p).normalize();
        let b = (eye - p).normalize();
        assert!((a.y - b.y).abs() < 1e-12);
    }

    #[test]
    fn ward_peak_matches_closed_form() {
        // At the mirror point cos_i = cos_o, so L = ks I / (4 pi alpha^2 r^2).
        let brdf = Brdf::Ward {
            kd: 0.0,
            ks: 1.0,
            alpha: 0.05,
        };
        let eye = DVec3::new(0.0, 2.0, 0.0);
        let light = DVec3::new(0.0, 2.0, -50.0);
        let r2 = 25.0f64 * 25.0 + 4.0;
        let want = 10.0 / (4.0 * std::f64::consts::PI * 0.0025 * r2);
        assert!((peak_radiance(brdf, eye, light, 10.0) - want).abs() < 1e-9 * want);
    }

    #[test]
    fn intensity_round_trips_to_target() {
        let brdf = Brdf::Ggx {
            kd: 0.05,
            ks: 0.5,
            alpha: 0.1,
        };
        let eye = DVec3::new(0.0, 1.5, 0.0);
        let light = DVec3::new(1.0, 3.0, -10.0);
        let i = intensity_for_peak(brdf, eye, light, 1.0);
        let l = peak_radiance(brdf, eye, light, i);
        assert!((l - 1.0).abs() < 0.05, "{l}");
        assert_eq!(round_sig2(0.012345), 0.012);
        assert_eq!(round_sig2(197.6), 200.0);
    }
}
