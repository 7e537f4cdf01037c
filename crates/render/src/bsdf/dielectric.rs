//! A dielectric interface's transmission, for the transmissive [`super::GltfPbr`]
//! (KHR_materials_transmission and KHR_materials_volume): refraction by Snell's law, the
//! cosine on the outside of the interface that Schlick's Fresnel takes, and the GGX microfacet
//! BTDF of Walter, Marschner, Li and Torrance 2007 ("Microfacet Models for Refraction through
//! Rough Surfaces"), written as pbrt-v4's `DielectricBxDF` (and Mitsuba 3's
//! `roughdielectric.cpp`) write it, with the height-correlated Smith masking the glTF model
//! uses for reflection.
//!
//! Relative index: `etap = eta(wi's side) / eta(wo's side)`, `ior` when `wo` is outside a
//! volume, `1 / ior` when it is inside. The BTDF is the one for radiance (pbrt's
//! `TransportMode::Radiance`): it carries the factor `1 / etap^2`, so radiance grows by
//! `ior^2` entering the denser medium and shrinks by as much leaving it, and the generalized
//! reciprocity `f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2` holds (Veach 1997, eq. 5.14, with
//! `eta_o`, `eta_i` the indices on `wo`'s and `wi`'s sides; tested in `gltf.rs`).

use super::ggx::{masking_root, GgxAtWo};
use glam::Vec3;
use std::f32::consts::PI;

/// `wo` (unit, `wo.m > 0`) refracted through the microfacet of normal `m` (unit) with relative
/// index `etap`; `None` under total internal reflection. (pbrt-v4's `Refract`.)
#[inline]
pub(super) fn refract(wo: Vec3, m: Vec3, etap: f32) -> Option<Vec3> {
    let cos_o = wo.dot(m);
    let sin2_o = (1.0 - cos_o * cos_o).max(0.0);
    let sin2_t = sin2_o / (etap * etap);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / etap + (cos_o / etap - cos_t) * m).normalize())
}

/// The cosine, with the microfacet normal, of the direction on the *outside* of the interface
/// for `wo` of cosine `cos_o` with it: `cos_o` itself when `wo` is outside (`etap >= 1`), else
/// the refracted direction's, `sqrt(1 - (1 - cos_o^2) / etap^2)`, and 0 under total internal
/// reflection. Schlick's approximation is accurate with the outside cosine (Schlick 1994; the
/// inside one would let no total internal reflection happen), and both directions of a
/// refraction share it, so the Fresnel factor is reciprocal.
#[inline]
pub(super) fn outside_cos(cos_o: f32, etap: f32) -> f32 {
    if etap >= 1.0 {
        cos_o
    } else {
        (1.0 - (1.0 - cos_o * cos_o) / (etap * etap))
            .max(0.0)
            .sqrt()
    }
}

/// GGX's `D(m) = alpha^2 / (pi (m.z^2 (alpha^2 - 1) + 1)^2)` for a unit `m`.
#[inline]
fn ggx_d(m_z: f32, a2: f32) -> f32 {
    let t = m_z * m_z * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// The GGX microfacet transmission for `wo` above and `wi` below the surface, with `at` the
/// lobe's [`GgxAtWo`] for `wo` and `etap` the relative index, without its Fresnel and colour:
/// `(btdf, pdf, cos_outside)`, where
///
/// - `m = normalize(wo + etap wi)`, turned to `+Z`, is the generalized half vector
///   (Walter et al. eq. 16); `wo.m > 0 > wi.m` or there is no transmission (`None`);
/// - `btdf = D(m) G2(wo, wi) |wi.m| |wo.m| / (|wi.z| |wo.z| (wi.m + wo.m / etap)^2) / etap^2`
///   (Walter et al. eq. 21 with the radiance factor), `G2 = 1 / (1 + Lambda(wo) +
///   Lambda(wi))`, so `G2 / (|wi.z| |wo.z|) = 2 / (ro |wi.z| + ri |wo.z|)` with the
///   [`masking_root`]s;
/// - `pdf` is the density of `wi` when `m` is sampled from the visible normals of `wo` and
///   `wo` refracted through it: `D(m) G1(wo) (wo.m) / wo.z` times the Jacobian
///   `|wi.m| / (wi.m + wo.m / etap)^2` (Walter et al. eq. 17);
/// - `cos_outside` is [`outside_cos`], what Schlick's Fresnel takes.
#[inline]
pub(super) fn microfacet_transmission(
    at: &GgxAtWo,
    wo: Vec3,
    wi: Vec3,
    etap: f32,
) -> Option<(f32, f32, f32)> {
    let m = (wo + wi * etap).try_normalize()?;
    let m = if m.z < 0.0 { -m } else { m };
    let (cos_o, cos_i) = (wo.dot(m), wi.dot(m));
    if !(cos_o > 0.0 && cos_i < 0.0) {
        return None;
    }
    let sum = cos_i + cos_o / etap;
    let denom = sum * sum;
    let d = ggx_d(m.z, at.a2);
    let ri = masking_root(wi.to_array(), at.a2);
    let btdf = d * 2.0 * -cos_i * cos_o / ((at.ro * -wi.z + ri * wo.z) * denom) / (etap * etap);
    let pdf = d * 2.0 * cos_o * -cos_i / (at.go * denom);
    let cos_outside = if etap >= 1.0 { cos_o } else { -cos_i };
    (btdf.is_finite() && pdf.is_finite()).then_some((btdf, pdf, cos_outside))
}
