//! The glTF 2.0 metallic-roughness BRDF [`GltfPbr`] (specification appendix B): the Lambertian
//! and GGX lobes coupled by Schlick's Fresnel.

use super::diffuse::lambert;
use super::ggx;
use super::lanes::{Lanes, Spectrum};
use super::{glossy_probability, half_vector, reflect, Lobes, Model, Reflectances, MIN_ALPHA};
use glam::{Vec2, Vec3};
use streaks_image::luminance;

/// The glTF 2.0 metallic-roughness BRDF (specification appendix B): Lambert diffuse of
/// `base_color (1 - metallic)` mixed with a GGX/Smith specular lobe of alpha = roughness^2
/// and Schlick Fresnel with F0 = mix(0.04, base_color, metallic):
/// `f = (1 - F) c_diff / pi + F D G1(wi) G1(wo) / (4 cos_i cos_o)`, `F = F0 + (1 - F0)(1 - |wo.h|)^5`.
/// The visibility is the specification's *separable* Smith-GGX form (the same `G1` as
/// [`super::Ggx`]), not the height-correlated alternative, so both GGX models share one masking
/// function and one visible-normal sampling routine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfPbr {
    /// Base colour, linear RGB.
    pub base_color: Vec3,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (alpha = roughness^2).
    pub roughness: f32,
}

impl GltfPbr {
    /// `alpha = roughness^2`, kept at or above [`MIN_ALPHA`] (as Mitsuba's principled BSDF does).
    #[inline]
    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(MIN_ALPHA)
    }

    /// `c_diff = base_color (1 - metallic)`.
    #[inline]
    fn diffuse_color(&self) -> Vec3 {
        self.base_color * (1.0 - self.metallic)
    }

    /// `F0 = mix(0.04, base_color, metallic)`.
    #[inline]
    fn f0(&self) -> Vec3 {
        Vec3::splat(0.04).lerp(self.base_color, self.metallic)
    }
}

/// Schlick's weight `(1 - |cos|)^5`, clamped to `[0, 1]`: Fresnel is `F0 + (1 - F0)` times it.
#[inline(always)]
fn schlick_weight<L: Lanes>(cos: L) -> L {
    (L::splat(1.0) - cos.abs()).saturate().pow5()
}

/// Schlick's Fresnel `F0 + (1 - F0) s` for the weight `s` of [`schlick_weight`].
#[inline(always)]
fn schlick<L: Lanes, S: Spectrum<L>>(f0: S, s: L) -> S {
    f0 + f0.one_minus() * s
}

impl Model for GltfPbr {
    type AtWo = ggx::GgxAtWo;

    #[inline]
    fn at_wo(&self, wo: Vec3) -> ggx::GgxAtWo {
        ggx::GgxAtWo::new(self.alpha(), wo)
    }

    /// `(1 - F0) c_diff` and `F0`: with `1 - F = (1 - F0)(1 - s)`, the diffuse lobe is the
    /// Lambertian lobe of `(1 - F0) c_diff` times the lane term `1 - s`, and the glossy lobe
    /// `F0 + (1 - F0) s` times the microfacet lobe.
    #[inline]
    fn reflectances(&self) -> Reflectances<Vec3> {
        let f0 = self.f0();
        Reflectances {
            diffuse: (Vec3::ONE - f0) * self.diffuse_color(),
            glossy: f0,
        }
    }

    #[inline(always)]
    fn lobes<L: Lanes, S: Spectrum<L>>(
        at: &ggx::GgxAtWo,
        r: Reflectances<S>,
        wo: Vec3,
        wi: [L; 3],
    ) -> Lobes<S, L> {
        let (spec, pdf) = ggx::microfacet(at, wo, wi);
        let h = half_vector(wo, wi);
        let s = schlick_weight(h[0] * wo.x + h[1] * wo.y + h[2] * wo.z);
        Lobes {
            diffuse: lambert(r.diffuse) * s.one_minus(),
            glossy: schlick(r.glossy, s) * spec,
            glossy_pdf: pdf,
        }
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let f = luminance(schlick(self.f0(), schlick_weight(wo.z)));
        let factor = ggx::albedo_factor(wo.z, self.alpha());
        glossy_probability(f, factor, luminance(self.diffuse_color()) * (1.0 - f))
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        ggx::sample_visible_normal(wo, self.alpha(), u).map(|h| reflect(wo, h))
    }

    /// The base colour.
    #[inline]
    fn albedo(&self) -> Vec3 {
        self.base_color
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::tests::{run, GLTF_ANGLES, GLTF_ROUGHNESS};
    use crate::bsdf::Bsdf;
    use std::f32::consts::PI;

    #[test]
    fn chi_square_gltf() {
        for metallic in [0.0, 1.0] {
            for roughness in GLTF_ROUGHNESS {
                for theta in GLTF_ANGLES {
                    let b = Bsdf::GltfPbr(GltfPbr {
                        base_color: Vec3::new(0.8, 0.5, 0.2),
                        metallic,
                        roughness,
                    });
                    run(
                        format!("gltf metallic {metallic} roughness {roughness} theta_o {theta}"),
                        b,
                        theta,
                        4,
                    );
                }
            }
        }
    }

    #[test]
    fn gltf_at_normal_incidence() {
        // wo = wi = n: h = n, F = F0, D = 1 / (pi alpha^2), G1 = 1, so
        // glossy = F0 / (4 pi alpha^2) and diffuse = (1 - F0) c_diff / pi.
        let g = GltfPbr {
            base_color: Vec3::new(0.5, 0.25, 1.0),
            metallic: 0.5,
            roughness: 0.6,
        };
        let l = Bsdf::GltfPbr(g).eval_lobes(Vec3::Z, Vec3::Z);
        let alpha2 = 0.36f32 * 0.36;
        let f0 = Vec3::new(0.27, 0.145, 0.52);
        let c_diff = Vec3::new(0.25, 0.125, 0.5);
        assert!(
            (l.glossy - f0 / (4.0 * PI * alpha2)).abs().max_element() < 1e-5,
            "{l:?}"
        );
        assert!(
            (l.diffuse - (Vec3::ONE - f0) * c_diff / PI)
                .abs()
                .max_element()
                < 1e-6,
            "{l:?}"
        );
    }
}
