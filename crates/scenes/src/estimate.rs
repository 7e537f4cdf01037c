//! Peak streak radiance of a point light over a glossy ground plane, used to choose light
//! intensities. A point light of radiant intensity I lights a ground point p with reflected
//! radiance `L(p) = f(wi, wo) * I * cos_i / r^2` (f the BRDF of the scene contract, r the
//! distance from the light to p). By symmetry the streak's centre line lies in the vertical
//! plane through the eye and the light, so its peak is the maximum of L along the ground
//! segment from the eye's foot to the light's foot; [`peak_radiance`] finds it by dense
//! sampling. It lies beyond the mirror point (where h = n): going towards the lamp, r
//! shrinks faster than the lobe falls off.

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
    /// The BRDF (without the cosine) for unit directions `wi` (to the light) and `wo` (to
    /// the viewer) above the ground plane with normal +Y.
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        let pi = std::f64::consts::PI;
        let (ci, co) = (wi.y, wo.y);
        if ci <= 0.0 || co <= 0.0 {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        let nh = h.y;
        match *self {
            Brdf::Ggx { kd, ks, alpha } => {
                let a2 = alpha * alpha;
                let d = a2 / (pi * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
                let g1 = |w: DVec3| {
                    if w.dot(h) <= 0.0 {
                        return 0.0;
                    }
                    let tan2 = (1.0 - w.y * w.y) / (w.y * w.y);
                    2.0 / (1.0 + (1.0 + a2 * tan2).sqrt())
                };
                kd / pi + ks * d * g1(wi) * g1(wo) / (4.0 * ci * co)
            }
            Brdf::Ward { kd, ks, alpha } => {
                let tan2 = (1.0 - nh * nh) / (nh * nh);
                kd / pi
                    + ks * (-tan2 / (alpha * alpha)).exp()
                        / (4.0 * pi * alpha * alpha * (ci * co).sqrt())
            }
            Brdf::BlinnPhong { kd, ks, shininess } => {
                kd / pi + ks * (shininess + 8.0) / (8.0 * pi) * nh.max(0.0).powf(shininess)
            }
        }
    }
}

/// Radiance reflected towards `eye` at ground point `p` from a point light of intensity
/// `intensity` at `light`.
pub fn radiance_at(brdf: Brdf, eye: DVec3, light: DVec3, intensity: f64, p: DVec3) -> f64 {
    let to_light = light - p;
    let r2 = to_light.length_squared();
    let wi = to_light.normalize();
    brdf.eval(wi, (eye - p).normalize()) * intensity * wi.y / r2
}

/// The point on the plane Y = 0 where the mirror image of `light` is seen from `eye`.
pub fn mirror_point(eye: DVec3, light: DVec3) -> DVec3 {
    let t = eye.y / (eye.y + light.y);
    let p = eye + (light - eye) * t;
    DVec3::new(p.x, 0.0, p.z)
}

/// Peak streak radiance of a point light of radiant intensity `intensity` (W/sr) at `light`,
/// seen from `eye` over the ground plane Y = 0 with reflectance `brdf`: the maximum over
/// 4000 points of the ground segment between the eye's and the light's feet.
pub fn peak_radiance(brdf: Brdf, eye: DVec3, light: DVec3, intensity: f64) -> f64 {
    let a = DVec3::new(eye.x, 0.0, eye.z);
    let b = DVec3::new(light.x, 0.0, light.z);
    let n = 4000;
    (1..n)
        .map(|k| a + (b - a) * (k as f64 / n as f64))
        .chain(std::iter::once(mirror_point(eye, light)))
        .map(|p| radiance_at(brdf, eye, light, intensity, p))
        .fold(0.0, f64::max)
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
    fn at_the_mirror_point_ward_matches_its_closed_form() {
        // At the mirror point h = n and cos_i = cos_o, so L = ks I / (4 pi alpha^2 r^2).
        let brdf = Brdf::Ward {
            kd: 0.0,
            ks: 1.0,
            alpha: 0.05,
        };
        let eye = DVec3::new(0.0, 2.0, 0.0);
        let light = DVec3::new(0.0, 2.0, -50.0);
        let r2 = 25.0f64 * 25.0 + 4.0;
        let want = 10.0 / (4.0 * std::f64::consts::PI * 0.0025 * r2);
        let p = mirror_point(eye, light);
        let got = radiance_at(brdf, eye, light, 10.0, p);
        assert!((got - want).abs() < 1e-9 * want, "{got} {want}");
        // The streak's peak lies beyond the mirror point, towards the lamp.
        let peak = peak_radiance(brdf, eye, light, 10.0);
        assert!(peak > 1.5 * want, "{peak} {want}");
    }

    #[test]
    fn ggx_and_blinn_phong_at_the_mirror_point() {
        let (ci, co) = (0.3f64, 0.3f64);
        let wi = DVec3::new(0.0, ci, -(1.0 - ci * ci).sqrt());
        let wo = DVec3::new(0.0, co, (1.0 - co * co).sqrt());
        let a = 0.1f64;
        let ggx = Brdf::Ggx {
            kd: 0.0,
            ks: 1.0,
            alpha: a,
        };
        let tan2 = (1.0 - ci * ci) / (ci * ci);
        let g1 = 2.0 / (1.0 + (1.0 + a * a * tan2).sqrt());
        let want = g1 * g1 / (std::f64::consts::PI * a * a * 4.0 * ci * co);
        assert!((ggx.eval(wi, wo) - want).abs() < 1e-9 * want);
        let bp = Brdf::BlinnPhong {
            kd: 0.0,
            ks: 1.0,
            shininess: 1000.0,
        };
        let want = 1008.0 / (8.0 * std::f64::consts::PI);
        assert!((bp.eval(wi, wo) - want).abs() < 1e-9 * want);
        // Below the horizon nothing is reflected.
        assert_eq!(bp.eval(-wi, wo), 0.0);
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
