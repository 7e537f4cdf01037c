//! KHR_materials_iridescence: the thin-film Fresnel term of Belcour and Barla (2017, "A
//! Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence") in the
//! extension's approximation, which [`super::GltfPbr`] mixes into its specular Fresnel:
//! `F = mix(F_schlick, F_iridescence, iridescence)`.
//!
//! A film of index `eta2` and thickness `d` (nm) lies between the outside (index 1) and the
//! base, whose index is inferred from its F0 (`(1 + sqrt(F0)) / (1 - sqrt(F0))` per channel,
//! F0 at most 0.9999). Both interfaces reflect by Schlick's approximation (`R12` at the
//! outside cosine, `R23` at the cosine refracted into the film); the phase shifts are 0 or pi
//! by which side has the higher index; the Airy summation's first three terms are integrated
//! against the CIE XYZ sensitivities in Fourier space (Gaussian fits) and turned into linear
//! Rec. 709 RGB, negative values clamped to 0. The optical path difference is
//! `2 eta2 d cos(theta2)`, with the refracted cosine (the extension's text writes `cos_theta1`;
//! the glTF sample renderer and the paper take the film's). A film totally reflecting the
//! outside light gives 1.

use glam::{Mat3, Vec3};
use std::f32::consts::PI;

/// The XYZ to linear Rec. 709 matrix (columns), with the extension's digits.
#[allow(clippy::excessive_precision)]
const XYZ_TO_REC709: Mat3 = Mat3::from_cols_array(&[
    3.2404542, -0.9692660, 0.0556434, -1.5371385, 1.8760108, -0.2040259, -0.4985314, 0.0415560,
    1.0572252,
]);

/// `((n_t - n_i) / (n_t + n_i))^2`.
#[inline]
fn f0_of(n_t: f32, n_i: f32) -> f32 {
    let r = (n_t - n_i) / (n_t + n_i);
    r * r
}

/// Schlick's `F0 + (1 - F0) (1 - cos)^5`.
#[inline]
fn schlick(f0: f32, cos: f32) -> f32 {
    f0 + (1.0 - f0) * (1.0 - cos).clamp(0.0, 1.0).powi(5)
}

/// The sensitivity term of an optical path difference `opd` (nm) and phase shifts `shift`,
/// as linear RGB.
#[inline]
fn sensitivity(opd: f32, shift: Vec3) -> Vec3 {
    let phase = 2.0 * PI * opd * 1.0e-9;
    let val = [5.4856e-13f32, 4.4201e-13, 5.2481e-13];
    let pos = [1.6810e+06f32, 1.7953e+06, 2.2084e+06];
    let var = [4.3278e+09f32, 9.3046e+09, 6.6121e+09];
    let mut xyz = Vec3::from_array(std::array::from_fn(|k| {
        val[k]
            * (2.0 * PI * var[k]).sqrt()
            * (pos[k] * phase + shift[k]).cos()
            * (-phase * phase * var[k]).exp()
    }));
    xyz.x += 9.7470e-14
        * (2.0 * PI * 4.5282e+09f32).sqrt()
        * (2.2399e+06 * phase + shift.x).cos()
        * (-4.5282e+09 * phase * phase).exp();
    XYZ_TO_REC709 * (xyz / 1.0685e-7)
}

/// The thin film's Fresnel reflectance (linear RGB) at the cosine `cos1` of the angle between
/// the outgoing direction and the microfacet normal, for a film of index `film_ior` and
/// thickness `thickness` (nm) over a base of normal-incidence reflectance `base_f0`.
pub(super) fn fresnel(cos1: f32, film_ior: f32, thickness: f32, base_f0: Vec3) -> Vec3 {
    let outside = 1.0;
    let sin2_sq = (outside / film_ior).powi(2) * (1.0 - cos1 * cos1);
    let cos2_sq = 1.0 - sin2_sq;
    if cos2_sq < 0.0 {
        return Vec3::ONE;
    }
    let cos2 = cos2_sq.sqrt();
    // First interface.
    let r12 = schlick(f0_of(film_ior, outside), cos1);
    let t121 = 1.0 - r12;
    let phi12 = if film_ior < outside { PI } else { 0.0 };
    let phi21 = PI - phi12;
    // Second interface.
    let base_ior = base_f0
        .min(Vec3::splat(0.9999))
        .max(Vec3::ZERO)
        .to_array()
        .map(|f| {
            let s = f.sqrt();
            (1.0 + s) / (1.0 - s)
        });
    let r23 = Vec3::from_array(base_ior.map(|n| schlick(f0_of(n, film_ior), cos2)));
    let phi23 = Vec3::from_array(base_ior.map(|n| if n < film_ior { PI } else { 0.0 }));
    let opd = 2.0 * film_ior * thickness * cos2;
    let phi = Vec3::splat(phi21) + phi23;
    // Compound terms.
    let r123 = (r12 * r23).clamp(Vec3::splat(1e-5), Vec3::splat(0.9999));
    let sqrt_r123 = r123.to_array().map(f32::sqrt);
    let rs = t121 * t121 * r23 / (Vec3::ONE - r123);
    let mut i = Vec3::splat(r12) + rs;
    let mut cm = rs - Vec3::splat(t121);
    for m in 1..=2 {
        cm *= Vec3::from_array(sqrt_r123);
        i += cm * 2.0 * sensitivity(m as f32 * opd, m as f32 * phi);
    }
    i.max(Vec3::ZERO)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The extension's code, written again in f64 (columns of the matrix as GLSL's `mat3`
    /// takes them), against the f32 function.
    pub(crate) fn reference(cos1: f64, eta2: f64, d: f64, base_f0: [f64; 3]) -> [f64; 3] {
        use std::f64::consts::PI;
        let sq = |x: f64| x * x;
        let schlick = |f0: f64, c: f64| f0 + (1.0 - f0) * (1.0 - c).powi(5);
        let ior_to_f0 = |t: f64, i: f64| sq((t - i) / (t + i));
        let sin2 = sq(1.0 / eta2) * (1.0 - sq(cos1));
        if 1.0 - sin2 < 0.0 {
            return [1.0; 3];
        }
        let cos2 = (1.0 - sin2).sqrt();
        let r12 = schlick(ior_to_f0(eta2, 1.0), cos1);
        let t121 = 1.0 - r12;
        let phi21 = PI - if eta2 < 1.0 { PI } else { 0.0 };
        let opd = 2.0 * eta2 * d * cos2;
        let sens = |opd: f64, shift: [f64; 3]| {
            let phase = 2.0 * PI * opd * 1.0e-9;
            let val = [5.4856e-13, 4.4201e-13, 5.2481e-13];
            let pos = [1.6810e+06, 1.7953e+06, 2.2084e+06];
            let var = [4.3278e+09, 9.3046e+09, 6.6121e+09];
            let mut xyz: [f64; 3] = std::array::from_fn(|k| {
                val[k]
                    * (2.0 * PI * var[k]).sqrt()
                    * (pos[k] * phase + shift[k]).cos()
                    * (-sq(phase) * var[k]).exp()
            });
            xyz[0] += 9.7470e-14
                * (2.0 * PI * 4.5282e+09f64).sqrt()
                * (2.2399e+06 * phase + shift[0]).cos()
                * (-4.5282e+09 * sq(phase)).exp();
            let xyz = xyz.map(|v| v / 1.0685e-7);
            let m = [
                [3.2404542, -1.5371385, -0.4985314],
                [-0.9692660, 1.8760108, 0.0415560],
                [0.0556434, -0.2040259, 1.0572252],
            ];
            std::array::from_fn::<f64, 3, _>(|r| {
                m[r][0] * xyz[0] + m[r][1] * xyz[1] + m[r][2] * xyz[2]
            })
        };
        std::array::from_fn(|c| {
            let f0 = base_f0[c].min(0.9999);
            let n = (1.0 + f0.sqrt()) / (1.0 - f0.sqrt());
            let r23 = schlick(ior_to_f0(n, eta2), cos2);
            let phi = phi21 + if n < eta2 { PI } else { 0.0 };
            let r123 = (r12 * r23).clamp(1e-5, 0.9999);
            let rs = sq(t121) * r23 / (1.0 - r123);
            let mut i = r12 + rs;
            let mut cm = rs - t121;
            for m in 1..=2 {
                cm *= r123.sqrt();
                let shifts = [m as f64 * phi; 3];
                i += cm * 2.0 * sens(m as f64 * opd, shifts)[c];
            }
            i.max(0.0)
        })
    }

    #[test]
    fn thin_film_is_the_extension() {
        for (eta2, d, f0) in [
            (1.3f32, 400.0f32, Vec3::splat(0.04)),
            (1.8, 250.0, Vec3::new(0.9, 0.6, 0.3)),
            (1.2, 100.0, Vec3::splat(0.08)),
        ] {
            for cos1 in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
                let got = fresnel(cos1, eta2, d, f0);
                let want = reference(
                    cos1 as f64,
                    eta2 as f64,
                    d as f64,
                    f0.to_array().map(f64::from),
                );
                for c in 0..3 {
                    assert!(
                        (got[c] as f64 - want[c]).abs() < 2e-3,
                        "{eta2} {d} {f0} cos {cos1}: {got} vs {want:?}"
                    );
                }
            }
        }
    }

    /// A film reflects a colour that changes with its thickness, stays in [0, 1.05], and
    /// reflects everything at grazing incidence.
    #[test]
    fn thin_film_colours() {
        let f0 = Vec3::splat(0.04);
        let (a, b) = (fresnel(1.0, 1.3, 300.0, f0), fresnel(1.0, 1.3, 500.0, f0));
        assert!((a - b).abs().max_element() > 0.01, "{a} {b}");
        for d in [100.0, 250.0, 400.0, 800.0] {
            for cos in [1.0, 0.7, 0.3] {
                let f = fresnel(cos, 1.3, d, f0);
                assert!(
                    f.min_element() >= 0.0 && f.max_element() <= 1.05,
                    "{d} {cos} {f}"
                );
            }
        }
        let grazing = fresnel(0.0, 1.3, 400.0, f0);
        assert!(grazing.min_element() > 0.9, "{grazing}");
    }
}
