//! [`LuminanceEval`]: `luminance(f(wo, wi))` for one `wo` and many `wi`, the light choice's
//! per-emitter BSDF weight, one direction at a time or 4, 8 or 16 in SIMD lanes. It evaluates each
//! model's own lobes (the functions `eval` uses) with the model's reflectances replaced by
//! their luminances, so it is the luminance of `eval` up to rounding. What depends on `wo`
//! alone (the reflectances' luminances, the model's `Model::AtWo`) is computed once, by
//! [`Bsdf::luminance_at`]; [`AtWo`] holds the model's, one variant per [`Bsdf`] variant, and
//! no formula.

use super::numbers::Lanes;
use super::{
    BlinnPhong, Bsdf, Diffuse, Ggx, GltfPbr, Lobes, Model, Reflectances, Retroreflective, Ward,
};
use glam::Vec3;
use streaks_image::luminance;

/// `luminance(f(wo, wi))` for one `wo` and any `wi` (see [`Bsdf::luminance_at`]):
/// [`LuminanceEval::eval`] evaluates one direction and `eval_lanes` (crate-internal) 4, 8 or
/// 16 at once in SIMD lanes, each lane exactly the scalar value. Equal to `luminance(bsdf.eval(wo, wi))`
/// up to rounding (tested), except below the surface for a transmissive [`GltfPbr`]: its
/// transmission is not evaluated here (zero), so the light choice's BSDF-aware share looks at
/// reflection only.
#[derive(Clone, Copy, Debug)]
pub struct LuminanceEval {
    wo: Vec3,
    /// The luminances of the model's reflectances.
    reflectances: Reflectances<f32>,
    /// The model's terms for `wo`.
    at: AtWo,
}

/// A [`Bsdf`]'s [`Model::AtWo`], for the model its variant names. The glTF variant is the
/// largest (its sheen, coat frame and thin film); it is made once per `wo` on the hot path,
/// where boxing it would allocate.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
enum AtWo {
    Diffuse(<Diffuse as Model>::AtWo),
    Ggx(<Ggx as Model>::AtWo),
    Ward(<Ward as Model>::AtWo),
    BlinnPhong(<BlinnPhong as Model>::AtWo),
    GltfPbr(<GltfPbr as Model>::AtWo),
    Retroreflective(<Retroreflective as Model>::AtWo),
}

impl LuminanceEval {
    /// `luminance(f(wo, wi))`; zero when either direction is below the surface.
    #[inline]
    pub fn eval(&self, wi: Vec3) -> f32 {
        self.eval_lanes(wi.to_array())
    }

    /// [`LuminanceEval::eval`] of several directions at once, given as their x, y and z
    /// lanes; each lane is exactly the scalar value.
    #[inline(always)]
    pub(crate) fn eval_lanes<L: Lanes>(&self, wi: [L; 3]) -> L {
        self.lobes_lanes(wi, |lobes| lobes.diffuse + lobes.glossy)
    }

    /// The glossy lobe's part of [`LuminanceEval::eval`].
    #[inline]
    pub(crate) fn eval_glossy(&self, wi: Vec3) -> f32 {
        self.lobes_lanes(wi.to_array(), |lobes| lobes.glossy)
    }

    /// `part` of the lobes' luminances toward `wi`; zero when either direction is below the
    /// surface.
    #[inline(always)]
    fn lobes_lanes<L: Lanes>(&self, wi: [L; 3], part: impl Fn(Lobes<L, L>) -> L) -> L {
        if self.wo.z > 0.0 {
            let (r, wo) = (self.reflectances.map(L::splat), self.wo);
            let lobes: Lobes<L, L> = match &self.at {
                AtWo::Diffuse(at) => Diffuse::lobes(at, r, wo, wi),
                AtWo::Ggx(at) => Ggx::lobes(at, r, wo, wi),
                AtWo::Ward(at) => Ward::lobes(at, r, wo, wi),
                AtWo::BlinnPhong(at) => BlinnPhong::lobes(at, r, wo, wi),
                AtWo::GltfPbr(at) => GltfPbr::lobes(at, r, wo, wi),
                AtWo::Retroreflective(at) => Retroreflective::lobes(at, r, wo, wi),
            };
            part(lobes).where_positive(wi[2])
        } else {
            L::splat(0.0)
        }
    }
}

impl LuminanceEval {
    /// Whether its lobes call the C library per lane (Ward's `exp`, Blinn-Phong's and the
    /// retroreflective cone's `pow`):
    /// such a model is evaluated four lanes at a time even where wider lanes exist, since a
    /// call per lane from a wide kernel costs more than the lanes save
    /// (docs/decisions/0003-light-choice-in-simd-lanes.md).
    #[inline]
    pub(crate) fn calls_libm(&self) -> bool {
        matches!(
            self.at,
            AtWo::Ward(_) | AtWo::BlinnPhong(_) | AtWo::Retroreflective(_)
        )
    }

    /// Whether the model has a glossy lobe, whose peak lies near the mirror direction of `wo`
    /// (every model but [`Diffuse`]).
    #[inline]
    pub(crate) fn has_glossy(&self) -> bool {
        !matches!(self.at, AtWo::Diffuse(_))
    }

    /// The luminance of the glossy lobe's reflectance (`ks`, or a glTF material's `F0`).
    #[inline]
    pub(crate) fn glossy_reflectance(&self) -> f32 {
        self.reflectances.glossy
    }
}

impl Bsdf {
    /// The evaluator of `luminance(f(wo, wi))` for this `wo` and any `wi` (see
    /// [`LuminanceEval`]).
    #[inline]
    pub fn luminance_at(&self, wo: Vec3) -> LuminanceEval {
        let (at, reflectances) = match self {
            Bsdf::Diffuse(m) => (AtWo::Diffuse(m.at_wo(wo)), m.reflectances()),
            Bsdf::Ggx(m) => (AtWo::Ggx(m.at_wo(wo)), m.reflectances()),
            Bsdf::Ward(m) => (AtWo::Ward(m.at_wo(wo)), m.reflectances()),
            Bsdf::BlinnPhong(m) => (AtWo::BlinnPhong(m.at_wo(wo)), m.reflectances()),
            Bsdf::GltfPbr(m) => (AtWo::GltfPbr(m.at_wo(wo)), m.reflectances()),
            Bsdf::Retroreflective(m) => (AtWo::Retroreflective(m.at_wo(wo)), m.reflectances()),
        };
        LuminanceEval {
            wo,
            reflectances: reflectances.map(luminance),
            at,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::numbers::{Wide, WideLanes};
    use crate::bsdf::tests::{all_models, random_dir};
    use crate::bsdf::{Ggx, MIN_ALPHA};
    use crate::sampling::Pcg32;
    use glam::Vec4;

    #[test]
    fn luminance_eval_is_luminance_of_eval() {
        let mut rng = Pcg32::new(11, 3);
        let (kd, ks) = (Vec3::new(0.2, 0.3, 0.1), Vec3::new(0.7, 0.5, 0.9));
        let narrow = [0.01, MIN_ALPHA].map(|alpha| Bsdf::Ggx(Ggx { kd, ks, alpha }));
        for b in all_models().into_iter().chain(narrow) {
            for _ in 0..2000 {
                let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
                let want = luminance(b.eval(wo, wi));
                let got = b.luminance_at(wo).eval(wi);
                assert!(
                    (got - want).abs() <= 1e-5 * want.abs().max(1e-3),
                    "{b:?} {wo} {wi}: {got} vs {want}"
                );
            }
        }
    }

    /// The glossy part is the whole value without a diffuse lobe, none of it for a Lambertian
    /// BSDF, and never more than the whole.
    #[test]
    fn eval_glossy_is_the_glossy_part() {
        let mut rng = Pcg32::new(13, 7);
        let (kd, ks) = (Vec3::new(0.2, 0.3, 0.1), Vec3::new(0.7, 0.5, 0.9));
        let pure = Bsdf::Ggx(Ggx {
            kd: Vec3::ZERO,
            ks,
            alpha: 0.2,
        });
        let mixed = Bsdf::Ggx(Ggx { kd, ks, alpha: 0.2 });
        let lambert = Bsdf::Diffuse(crate::bsdf::Diffuse { kd });
        for _ in 0..500 {
            let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
            let f = pure.luminance_at(wo);
            assert_eq!(f.eval_glossy(wi).to_bits(), f.eval(wi).to_bits());
            let f = mixed.luminance_at(wo);
            assert!(f.eval_glossy(wi) <= f.eval(wi));
            assert_eq!(lambert.luminance_at(wo).eval_glossy(wi), 0.0);
            if wo.z > 0.0 && wi.z > 0.0 {
                assert!(f.eval(wi) - f.eval_glossy(wi) > 0.0, "{wo} {wi}");
            }
        }
    }

    /// Directions in SIMD lanes (4, 8 and 16 of them) give exactly the scalar values, below
    /// the surface included, for every model.
    #[test]
    fn luminance_eval_lanes_are_the_scalar_values() {
        fn check<L: WideLanes>(b: &Bsdf, f: &LuminanceEval, wo: Vec3, wi: &[Vec3]) {
            let mut coord = [[0.0f32; 16]; 3];
            for (i, w) in wi.iter().enumerate() {
                [coord[0][i], coord[1][i], coord[2][i]] = w.to_array();
            }
            let mut got = [0.0f32; 16];
            f.eval_lanes(coord.map(|c| L::load(&c))).store(&mut got);
            for (w, g) in wi.iter().zip(&got[..L::WIDTH]) {
                assert_eq!(g.to_bits(), f.eval(*w).to_bits(), "{b:?} {wo} {w}");
            }
        }
        let mut rng = Pcg32::new(12, 5);
        for b in all_models() {
            for _ in 0..500 {
                let wo = random_dir(&mut rng);
                let f = b.luminance_at(wo);
                let wi: [Vec3; 16] = std::array::from_fn(|_| {
                    let w = random_dir(&mut rng);
                    // Some below the surface.
                    if rng.next_f32() < 0.2 {
                        -w
                    } else {
                        w
                    }
                });
                check::<Vec4>(&b, &f, wo, &wi[..4]);
                check::<Wide<8>>(&b, &f, wo, &wi[..8]);
                check::<Wide<16>>(&b, &f, wo, &wi);
            }
        }
    }
}
