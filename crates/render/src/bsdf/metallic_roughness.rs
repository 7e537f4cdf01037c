//! The glTF 2.0 metallic-roughness BRDF [`GltfPbr`] (specification appendix B) with the
//! parameters of KHR_materials_specular, KHR_materials_ior, KHR_materials_sheen and
//! KHR_materials_clearcoat: a Lambertian lobe and a GGX lobe coupled by Schlick's Fresnel,
//! under an optional sheen and an optional smooth GGX coat, with the specular transmission of KHR_materials_transmission (thin-walled, or
//! refracting into a KHR_materials_volume).

use super::dielectric::{microfacet_transmission, outside_cos, refract};
use super::diffuse::lambert;
use super::ggx;
use super::iridescence;
use super::numbers::{Lanes, Spectrum};
use super::sheen::SheenAtWo;
use super::{
    glossy_probability, half_vector, reflect, rgb_lobes, BsdfSample, Lobe, LobeValues, Lobes,
    Model, Reflectances, MIN_ALPHA, MIN_LOBE_PROBABILITY,
};
use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use streaks_image::luminance;

/// The glTF 2.0 metallic-roughness BRDF with KHR_materials_specular, KHR_materials_ior and
/// KHR_materials_clearcoat, exactly as the specification's appendix B and the extensions
/// define it, with `s = (1 - |wo.h|)^5` (Schlick's weight) and `alpha = roughness^2`:
///
/// - `specular_brdf = D V`, GGX with the height-correlated Smith visibility
///   (`ggx::microfacet_correlated`);
/// - metal: `metal_brdf = (base + (1 - base) s) specular_brdf`;
/// - dielectric (KHR_materials_specular's `fresnel_mix`): with
///   `f0 = min(((ior - 1) / (ior + 1))^2 specular_color, 1)` (KHR_materials_ior; ior 0 gives
///   `f0 = specular_color`, clamped) and `fr = f0 + (1 - f0) s`,
///   `dielectric_brdf = (1 - specular max_value(fr)) base / pi + specular fr specular_brdf`;
/// - `material = mix(dielectric_brdf, metal_brdf, metallic)`;
/// - iridescence (KHR_materials_iridescence): both Fresnel terms, the dielectric's `fr` and
///   the metal's `base + (1 - base) s`, become `mix(F, F_film(wo.h, F0), iridescence)` with
///   `F_film` the thin film's reflectance over a base of that F0 (see `iridescence.rs`), in
///   the specular lobe and in the dielectric's diffuse weight `1 - specular max_value(fr)`;
///   not from inside a volume, and the transmission keeps Schlick's weight;
/// - sheen (KHR_materials_sheen's albedo scaling, see `sheen.rs`): `sheen_material =
///   sheen_color f_sheen + material (1 - max3(sheen_color) max(E(n.wo), E(n.wi)))`, with
///   `f_sheen` the Charlie lobe of `alpha = sheen_roughness^2` and `E` its directional
///   albedo; the sheen is part of the diffuse lobe, sampled cosine-weighted;
/// - clearcoat (KHR_materials_clearcoat's `fresnel_coat`): `f = mix(sheen_material, coat_brdf,
///   clearcoat Fc)` with `coat_brdf` the same `D V` at `alpha = clearcoat_roughness^2` and
///   `Fc = 0.04 + 0.96 (1 - |n.wo|)^5`.
///
/// As the extension says, the coat's Fresnel is taken at the normal, not the half vector, so
/// a coated material is not reciprocal (its coat weight depends on `wo` alone).
///
/// The coat has its own normal `nc` ([`GltfPbr::coat_normal`], KHR_materials_clearcoat's
/// clearcoatNormalTexture; without one the interpolated normal, not the base's mapped one):
/// `Fc` takes `nc.wo`, and the coat's lobe is the GGX lobe in the frame of `nc`, as a BRDF
/// about `nc`: its contribution toward `wi` is `coat_brdf(wo, wi) (nc.wi)`, so its value in
/// this frame (whose cosine is `n.wi`) is `coat_brdf (nc.wi) / (n.wi)`, zero where `wi` is
/// below `nc`'s hemisphere; no coat where `wo` is. Its visible normals are sampled about `nc`. Without the
/// extensions (specular 1, specular colour 1, ior 1.5, clearcoat 0) this is the core model,
/// whose diffuse weight is `(1 - metallic) (1 - F_dielectric)`.
///
/// Lobes: the Lambertian part is the diffuse lobe; the base's and the coat's microfacet parts
/// are the glossy lobe. Sampling picks the glossy lobe as every model does, and within it the
/// coat with a probability from the two parts' albedo estimates for `wo`; the glossy lobe's
/// density is the mixture of the two visible-normal densities.
///
/// # Transmission
///
/// KHR_materials_transmission replaces the share `transmission` of the dielectric's diffuse
/// part by a specular transmission tinted by the base colour, with the same microfacet
/// roughness and the same Fresnel weight:
/// `(1 - metallic) transmission (1 - specular max_value(fr)) base specular_btdf`, under the
/// coat's `1 - clearcoat Fc` (the diffuse part keeps `1 - transmission` of its weight). Its
/// directions are below the surface (`wi.z < 0`); [`GltfPbr::transmission`] 0 is the opaque
/// model above, exactly. `specular_btdf` is
///
/// - thin-walled (no KHR_materials_volume, the extension's default): light goes through
///   without bending, so `specular_btdf(wo, wi)` is the reflection lobe `D V` at `wi`
///   mirrored through the surface (`wi.z -> -wi.z`), with `fr` at that reflection's half
///   vector; for a smooth surface a delta lobe at `wi = -wo`. Reflection and transmission sum
///   to the GGX lobe's albedo for a white base (exactly 1 for a smooth one);
/// - a volume's boundary ([`GltfPbr::thin_walled`] false): the GGX BTDF of Walter et al. 2007
///   with the relative index `ior` entering (`1 / ior` leaving, [`GltfPbr::inside`]), for
///   radiance (see `dielectric.rs`); `fr` takes the cosine on the outside of the interface
///   (total internal reflection: `fr = 1`), also in the reflection lobe when `wo` is inside;
///   for a smooth surface a delta lobe at the refracted `wo`. (`ior` 0 refracts with 1.5.)
///
/// "Smooth" is `alpha <= MIN_ALPHA`, i.e. roughness at most 0.01: then the transmission is a
/// delta lobe (never evaluated; sampled with the discrete probability of its lobe), while the
/// reflection stays the GGX lobe at `MIN_ALPHA`, as for an opaque material.
///
/// The lobe choice of a transmissive material is among three lobes (diffuse, glossy,
/// transmission), by the same albedo estimates at `wo`, every lobe that can be non-zero kept at
/// a probability of at least 0.05.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfPbr {
    /// Base colour, linear RGB.
    pub base_color: Vec3,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (alpha = roughness^2).
    pub roughness: f32,
    /// KHR_materials_specular `specular`, the dielectric's specular strength in [0, 1] (1
    /// without the extension; 0 is a pure diffuse dielectric).
    pub specular: f32,
    /// KHR_materials_specular `specularColor`, linear RGB, non-negative (1 without it).
    pub specular_color: Vec3,
    /// KHR_materials_ior `ior`: 1.5 without the extension, 0 or at least 1.
    pub ior: f32,
    /// KHR_materials_sheen `sheenColor`, linear RGB in [0, 1] (black: no sheen).
    pub sheen_color: Vec3,
    /// KHR_materials_sheen `sheenRoughness` in [0, 1].
    pub sheen_roughness: f32,
    /// KHR_materials_iridescence `iridescence` in [0, 1] (0: no thin film).
    pub iridescence: f32,
    /// KHR_materials_iridescence `iridescenceIor`, the film's index (1.3 by default).
    pub iridescence_ior: f32,
    /// The film's thickness in nanometres (KHR_materials_iridescence; 0: no film).
    pub iridescence_thickness: f32,
    /// KHR_materials_clearcoat `clearcoat` in [0, 1] (0: no coat).
    pub clearcoat: f32,
    /// KHR_materials_clearcoat `clearcoatRoughness` in [0, 1].
    pub clearcoat_roughness: f32,
    /// The coat's unit normal in the local shading frame: `Vec3::Z` (the shading normal)
    /// unless a clearcoatNormalTexture tilts it, or the base's normal map tilts the shading
    /// normal and the coat keeps the interpolated one (see [`GltfPbr`]).
    pub coat_normal: Vec3,
    /// KHR_materials_transmission `transmission` in [0, 1] (0: opaque).
    pub transmission: f32,
    /// Thin-walled (no KHR_materials_volume): transmitted light goes straight through; false:
    /// the surface bounds a volume and refracts.
    pub thin_walled: bool,
    /// `wo` is inside the volume (the back face of a volume's boundary; see
    /// [`super::Bsdf::seen_from_back`]); false when thin-walled.
    pub inside: bool,
}

/// The glTF defaults: white, metallic 1, roughness 1, and the extensions' defaults (specular 1,
/// specular colour 1, ior 1.5, no sheen, no clear coat, no transmission).
impl Default for GltfPbr {
    fn default() -> Self {
        GltfPbr {
            base_color: Vec3::ONE,
            metallic: 1.0,
            roughness: 1.0,
            specular: 1.0,
            specular_color: Vec3::ONE,
            ior: 1.5,
            sheen_color: Vec3::ZERO,
            sheen_roughness: 0.0,
            iridescence: 0.0,
            iridescence_ior: 1.3,
            iridescence_thickness: 400.0,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            coat_normal: Vec3::Z,
            transmission: 0.0,
            thin_walled: true,
            inside: false,
        }
    }
}

/// Reflectance at normal incidence of a dielectric of index `ior` in air (KHR_materials_ior):
/// `((ior - 1) / (ior + 1))^2`; 0.04 for the default 1.5, and 1 for `ior = 0`, which
/// KHR_materials_specular uses to let `specularColor` alone set F0.
#[inline]
pub fn ior_f0(ior: f32) -> f32 {
    let r = (ior - 1.0) / (ior + 1.0);
    r * r
}

/// F0 of the coat, KHR_materials_clearcoat's fixed ior 1.5.
const COAT_F0: f32 = 0.04;

impl GltfPbr {
    /// `alpha = roughness^2`, kept at or above [`MIN_ALPHA`] (as Mitsuba's principled BSDF does).
    #[inline]
    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(MIN_ALPHA)
    }

    /// The coat's `alpha = clearcoat_roughness^2`, kept at or above [`MIN_ALPHA`].
    #[inline]
    fn coat_alpha(&self) -> f32 {
        (self.clearcoat_roughness * self.clearcoat_roughness).max(MIN_ALPHA)
    }

    /// `c_diff = base_color (1 - metallic)`, of which the diffuse lobe keeps `1 -
    /// transmission`.
    #[inline]
    fn diffuse_color(&self) -> Vec3 {
        self.base_color * (1.0 - self.metallic) * (1.0 - self.transmission)
    }

    /// The transmission's colour, `base_color (1 - metallic) transmission`.
    #[inline]
    fn transmission_color(&self) -> Vec3 {
        self.base_color * (1.0 - self.metallic) * self.transmission
    }

    /// Whether the transmission is a delta lobe (`alpha <= MIN_ALPHA`).
    #[inline]
    fn smooth(&self) -> bool {
        self.roughness * self.roughness <= MIN_ALPHA
    }

    /// The relative index of a refraction, `eta(wi's side) / eta(wo's side)`: `ior` entering
    /// the volume, `1 / ior` leaving it (1.5 for `ior` below 1).
    #[inline]
    fn etap(&self) -> f32 {
        let eta = if self.ior >= 1.0 { self.ior } else { 1.5 };
        if self.inside {
            1.0 / eta
        } else {
            eta
        }
    }

    /// Schlick's weight for `wo` at cosine `cos` with the microfacet normal: with the cosine on
    /// the outside of the interface ([`outside_cos`]) when `wo` is inside a volume.
    #[inline]
    fn schlick_at(&self, cos: f32) -> f32 {
        if self.inside {
            schlick_weight(outside_cos(cos, self.etap()))
        } else {
            schlick_weight(cos)
        }
    }

    /// The dielectric's `f0 = min(ior_f0 specular_color, 1)`, before the specular strength.
    #[inline]
    fn dielectric_f0(&self) -> Vec3 {
        (ior_f0(self.ior) * self.specular_color).min(Vec3::ONE)
    }

    /// The glossy colour's value at `s = 0`: `(1 - metallic) specular f0 + metallic base`.
    #[inline]
    fn glossy_f0(&self) -> Vec3 {
        (1.0 - self.metallic) * self.specular * self.dielectric_f0()
            + self.metallic * self.base_color
    }

    /// The glossy colour's value at `s = 1`: `(1 - metallic) specular + metallic`. The glossy
    /// colour is `glossy_f0 (1 - s) + glossy_f90 s`.
    #[inline]
    fn glossy_f90(&self) -> f32 {
        (1.0 - self.metallic) * self.specular + self.metallic
    }

    /// The dielectric's diffuse weight `1 - specular max_value(fr)` is `a - b s` with these
    /// `(a, b)`: `max_value(f0 + (1 - f0) s) = m + (1 - m) s` for `m = max_value(f0)`, as
    /// Schlick's interpolation is increasing in `f0`.
    #[inline]
    fn diffuse_weight_terms(&self) -> (f32, f32) {
        let m = self.dielectric_f0().max_element();
        (1.0 - self.specular * m, self.specular * (1.0 - m))
    }

    /// The sheen's terms for `wo` of cosine `cos_o`; `None` without a sheen.
    #[inline]
    fn sheen_at(&self, cos_o: f32) -> Option<SheenAtWo> {
        (self.sheen_color.max_element() > 0.0).then(|| SheenAtWo::new(self.sheen_roughness, cos_o))
    }

    /// The base's weight under the sheen for `wo` alone, `1 - max3(sheen_color) E(cos_o)`
    /// (1 without a sheen): what the sheen leaves of the light arriving along `wo`.
    #[inline]
    fn sheen_base_weight(&self, sheen: &Option<SheenAtWo>) -> f32 {
        sheen.map_or(1.0, |s| 1.0 - self.sheen_color.max_element() * s.e_o)
    }

    /// The coat's weight for `wo` of cosine `cos_c` with the coat's normal, `clearcoat
    /// Fc(nc.wo)`; 0 where `wo` is below the coat.
    #[inline]
    fn coat_weight(&self, cos_c: f32) -> f32 {
        if cos_c <= 0.0 {
            return 0.0;
        }
        self.clearcoat * (COAT_F0 + (1.0 - COAT_F0) * schlick_weight(cos_c))
    }

    /// `nc.wo`, the cosine of `wo` with the coat's normal.
    #[inline]
    fn coat_cos(&self, wo: Vec3) -> f32 {
        if self.coat_normal == Vec3::Z {
            wo.z
        } else {
            wo.dot(self.coat_normal)
        }
    }

    /// The coat's frame for `wo` where its normal is not the shading normal.
    #[inline]
    fn coat_frame(&self, wo: Vec3) -> Option<CoatFrame> {
        (self.clearcoat > 0.0 && self.coat_normal != Vec3::Z).then(|| {
            let (s, t) = self.coat_normal.any_orthonormal_pair();
            let n = self.coat_normal;
            CoatFrame {
                s,
                t,
                n,
                wo: Vec3::new(wo.dot(s), wo.dot(t), wo.dot(n)),
            }
        })
    }

    /// The albedo estimates of the diffuse part, the base's microfacet part, the coat and the
    /// transmission for `wo` of cosine `cos_o`: each Fresnel weight at `s(cos_o)`, times
    /// `ggx::albedo_factor` for the microfacet parts; the transmission's Fresnel weight is kept
    /// at or above a tenth of its value at normal incidence, as rough microfacets transmit
    /// where the macroscopic direction would be totally reflected.
    #[inline]
    fn lobe_estimates(&self, wo: Vec3) -> [f32; 4] {
        let (cos_o, cos_c) = (wo.z, self.coat_cos(wo));
        let s = self.schlick_at(cos_o);
        let coat_weight = self.coat_weight(cos_c);
        let mut base_weight = 1.0 - coat_weight;
        let sheen = self.sheen_at(cos_o);
        let mut sheen_estimate = 0.0;
        if let Some(sh) = sheen {
            sheen_estimate = base_weight * luminance(self.sheen_color) * sh.e_o;
            base_weight *= self.sheen_base_weight(&sheen);
        }
        let glossy_colour = self.glossy_f0() * (1.0 - s) + Vec3::splat(self.glossy_f90() * s);
        let base = base_weight * luminance(glossy_colour) * ggx::albedo_factor(cos_o, self.alpha());
        let coat = coat_weight * ggx::albedo_factor(cos_c, self.coat_alpha());
        let (a, b) = self.diffuse_weight_terms();
        let diffuse = base_weight * luminance(self.diffuse_color()) * (a - b * s) + sheen_estimate;
        let transmission =
            base_weight * luminance(self.transmission_color()) * (a - b * s).max(0.1 * a);
        [diffuse, base, coat, transmission]
    }

    /// The probability of the glossy lobe and, within it, of the coat, for `wo` of cosine
    /// `cos_o`, from [`GltfPbr::lobe_estimates`]. The coat's share is 0 without a coat, 1 when
    /// the base has no microfacet part, else clamped to `[0.05, 0.95]` as the lobe choice is.
    #[inline]
    fn lobe_probabilities(&self, wo: Vec3) -> (f32, f32) {
        let [diffuse, base, coat, _] = self.lobe_estimates(wo);
        let coat_share = if coat <= 0.0 {
            0.0
        } else if base <= 0.0 {
            1.0
        } else {
            (coat / (coat + base)).clamp(0.05, 0.95)
        };
        (glossy_probability(base + coat, 1.0, diffuse), coat_share)
    }

    /// A transmissive material's lobe probabilities for `wo` of cosine `cos_o`: diffuse,
    /// glossy, transmission, proportional to [`GltfPbr::lobe_estimates`], and every lobe whose
    /// colour is not black kept at [`MIN_LOBE_PROBABILITY`] or more.
    #[inline]
    fn transmissive_probabilities(&self, wo: Vec3) -> [f32; 3] {
        let [diffuse, base, coat, transmission] = self.lobe_estimates(wo);
        let w = [diffuse, base + coat, transmission];
        let possible = [
            luminance(self.diffuse_color()) > 0.0 || luminance(self.sheen_color) > 0.0,
            luminance(self.glossy_f0()) > 0.0 || self.glossy_f90() > 0.0 || self.clearcoat > 0.0,
            luminance(self.transmission_color()) > 0.0,
        ];
        let sum: f32 = w.iter().sum();
        let p: [f32; 3] = std::array::from_fn(|k| {
            if !possible[k] {
                0.0
            } else if sum > 0.0 {
                (w[k] / sum).max(MIN_LOBE_PROBABILITY)
            } else {
                1.0
            }
        });
        let total: f32 = p.iter().sum();
        if total > 0.0 {
            p.map(|x| x / total)
        } else {
            [0.0; 3]
        }
    }

    /// `f(wo, wi)` split by lobe and the density of [`GltfPbr::sample_transmissive`], for a
    /// transmissive material: the reflection lobes above the surface, the transmission below
    /// it (zero for a smooth surface, whose transmission is a delta lobe).
    pub(super) fn eval_pdf_transmissive(&self, wo: Vec3, wi: Vec3) -> (LobeValues, f32) {
        if wo.z <= 0.0 || wi.z == 0.0 {
            return (LobeValues::default(), 0.0);
        }
        let [p_diffuse, p_glossy, p_transmission] = self.transmissive_probabilities(wo);
        if wi.z > 0.0 {
            let (f, glossy_pdf) = rgb_lobes(self, wo, wi);
            let mut pdf = 0.0;
            if p_diffuse > 0.0 {
                pdf += p_diffuse * square_to_cosine_hemisphere_pdf(wi);
            }
            if p_glossy > 0.0 {
                pdf += p_glossy * glossy_pdf;
            }
            return (f, pdf);
        }
        if self.smooth() || p_transmission <= 0.0 {
            return (LobeValues::default(), 0.0);
        }
        let (t, pdf) = self.transmission_lobe(&self.at_wo(wo), wo, wi);
        let f = LobeValues {
            transmission: t,
            ..LobeValues::default()
        };
        (f, p_transmission * pdf)
    }

    /// The rough transmission's value and its own sampling density at `wi` below the surface
    /// (see the type's documentation).
    #[inline]
    fn transmission_lobe(&self, at: &GltfAtWo, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let colour = self.transmission_color() * (at.base_weight * at.sheen_transmission);
        let weight = |s: f32| at.diffuse_a - at.diffuse_b * s;
        if self.thin_walled {
            let mirrored = Vec3::new(wi.x, wi.y, -wi.z);
            let (spec, pdf) = ggx::microfacet_correlated(&at.base, wo, mirrored.to_array());
            let s = schlick_weight((wo + mirrored).normalize().dot(wo));
            return (colour * (weight(s) * spec), pdf);
        }
        match microfacet_transmission(&at.base, wo, wi, self.etap()) {
            Some((btdf, pdf, cos_outside)) => {
                (colour * (weight(schlick_weight(cos_outside)) * btdf), pdf)
            }
            None => (Vec3::ZERO, 0.0),
        }
    }

    /// Samples a transmissive material: a lobe by [`GltfPbr::transmissive_probabilities`]
    /// (`u_lobe`), then a direction in it (`u`); the transmission by the visible normals of
    /// `wo`, mirrored (thin-walled) or refracted (a volume) through the sampled normal, or its
    /// delta direction for a smooth surface.
    pub(super) fn sample_transmissive(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let [p_diffuse, p_glossy, p_transmission] = self.transmissive_probabilities(wo);
        let (wi, lobe) = if u_lobe < p_glossy {
            (self.sample_glossy(wo, u)?, Lobe::Glossy)
        } else if u_lobe < p_glossy + p_transmission || p_diffuse <= 0.0 {
            if p_transmission <= 0.0 {
                return None;
            }
            if self.smooth() {
                return self.sample_delta_transmission(wo, p_transmission);
            }
            let h = ggx::sample_visible_normal(wo, self.alpha(), u)?;
            let wi = if self.thin_walled {
                let r = reflect(wo, h);
                Vec3::new(r.x, r.y, -r.z)
            } else {
                refract(wo, h, self.etap())?
            };
            (wi, Lobe::Transmission)
        } else {
            (square_to_cosine_hemisphere(u), Lobe::Diffuse)
        };
        if (lobe == Lobe::Transmission) != (wi.z < 0.0) || wi.z == 0.0 {
            return None;
        }
        let (f, pdf) = self.eval_pdf_transmissive(wo, wi);
        BsdfSample::continuous(wi, f.total(), pdf, lobe)
    }

    /// The smooth transmission's delta sample, chosen with probability `p`: `-wo`
    /// (thin-walled) or `wo` refracted through the surface (a volume; `None` under total
    /// internal reflection), of weight `f |wi.z| / p` with `f |wi.z|` the transmitted fraction:
    /// the colour times the Fresnel weight at the outside cosine (over `etap^2` for a volume).
    fn sample_delta_transmission(&self, wo: Vec3, p: f32) -> Option<BsdfSample> {
        let (wi, cos_outside, scale) = if self.thin_walled {
            (-wo, wo.z, 1.0)
        } else {
            let etap = self.etap();
            let wi = refract(wo, Vec3::Z, etap)?;
            let cos_outside = if etap >= 1.0 { wo.z } else { -wi.z };
            (wi, cos_outside, 1.0 / (etap * etap))
        };
        if wi.z >= 0.0 {
            return None;
        }
        let (a, b) = self.diffuse_weight_terms();
        let base_weight = (1.0 - self.coat_weight(self.coat_cos(wo)))
            * self.sheen_base_weight(&self.sheen_at(wo.z));
        let weight = (a - b * schlick_weight(cos_outside)) * base_weight * scale;
        let f = self.transmission_color() * (weight / -wi.z);
        Some(BsdfSample {
            wi,
            f,
            pdf: p,
            lobe: Lobe::Transmission,
            delta: true,
        })
    }

    /// The coat's share of the glossy lobe's samples for `wo` (0 without a coat).
    #[inline]
    fn coat_share(&self, wo: Vec3) -> f32 {
        if self.clearcoat > 0.0 {
            self.lobe_probabilities(wo).1
        } else {
            0.0
        }
    }
}

/// The coat's orthonormal frame (`n` its normal) in the shading frame, and `wo` in it.
#[derive(Clone, Copy, Debug)]
pub(super) struct CoatFrame {
    s: Vec3,
    t: Vec3,
    n: Vec3,
    wo: Vec3,
}

impl CoatFrame {
    /// Directions in lanes from the shading frame to the coat's.
    #[inline(always)]
    fn coat_from_shading<L: Lanes>(&self, w: [L; 3]) -> [L; 3] {
        [self.s, self.t, self.n].map(|a| w[0] * a.x + w[1] * a.y + w[2] * a.z)
    }

    /// A direction from the coat's frame to the shading frame.
    #[inline]
    fn shading_from_coat(&self, w: Vec3) -> Vec3 {
        self.s * w.x + self.t * w.y + self.n * w.z
    }
}

/// Schlick's weight `(1 - |cos|)^5`, clamped to `[0, 1]`: Fresnel is `F0 + (1 - F0)` times it.
#[inline(always)]
fn schlick_weight<L: Lanes>(cos: L) -> L {
    (L::splat(1.0) - cos.abs()).saturate().pow5()
}

/// A [`GltfPbr`]'s terms that depend on the material and `wo` alone.
#[derive(Clone, Copy, Debug)]
pub(super) struct GltfAtWo {
    /// The base's GGX lobe.
    base: ggx::GgxAtWo,
    /// The coat's GGX lobe (for `wo` in the coat's frame).
    coat: ggx::GgxAtWo,
    /// The coat's frame where its normal is not the shading normal.
    coat_frame: Option<CoatFrame>,
    /// [`GltfPbr::glossy_f90`].
    f90: f32,
    /// [`GltfPbr::diffuse_weight_terms`].
    diffuse_a: f32,
    diffuse_b: f32,
    /// `1 - clearcoat Fc(wo)`, the base's weight under the coat.
    base_weight: f32,
    /// `clearcoat Fc(wo)`, the coat's weight.
    coat_weight: f32,
    /// [`GltfPbr::coat_share`].
    coat_share: f32,
    /// `ior` when `wo` is inside a volume (Schlick's weight then takes the outside cosine),
    /// else 0.
    inside_ior: f32,
    /// The sheen's terms (`None` without a sheen).
    sheen: Option<SheenAtWo>,
    /// `max3(sheen_color)`.
    sheen_max: f32,
    /// The transmission's weight under the sheen, `1 - max3(sheen_color) E(cos_o)`.
    sheen_transmission: f32,
    /// The thin film (`None` without one).
    film: Option<Film>,
}

/// A [`GltfPbr`]'s thin film (KHR_materials_iridescence) and the Fresnel terms it changes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Film {
    iridescence: f32,
    ior: f32,
    thickness: f32,
    /// The dielectric's F0 ([`GltfPbr::dielectric_f0`]) and the metal's (the base colour).
    dielectric_f0: Vec3,
    metal_f0: Vec3,
    specular: f32,
    metallic: f32,
}

impl Film {
    /// The dielectric's Fresnel term `mix(f0 + (1 - f0) s, F_film, iridescence)` at the
    /// cosine `cos` of `wo` with the microfacet normal.
    #[inline]
    fn dielectric(&self, cos: f32) -> Vec3 {
        self.mixed(cos, self.dielectric_f0)
    }

    /// `mix(f0 + (1 - f0) s, F_film(f0), iridescence)`.
    #[inline]
    fn mixed(&self, cos: f32, f0: Vec3) -> Vec3 {
        let cos = cos.abs();
        let s = schlick_weight(cos);
        let schlick = f0 + (Vec3::ONE - f0) * s;
        let film = iridescence::fresnel(cos, self.ior, self.thickness, f0);
        schlick + (film - schlick) * self.iridescence
    }

    /// The glossy colour `(1 - metallic) specular F_dielectric + metallic F_metal`.
    #[inline]
    fn glossy_colour(&self, cos: f32) -> Vec3 {
        (1.0 - self.metallic) * self.specular * self.dielectric(cos)
            + self.metallic * self.mixed(cos, self.metal_f0)
    }

    /// The dielectric's diffuse weight `1 - specular max_value(F_dielectric)`.
    #[inline]
    fn diffuse_weight(&self, cos: f32) -> f32 {
        1.0 - self.specular * self.dielectric(cos).max_element()
    }
}

impl Model for GltfPbr {
    type AtWo = GltfAtWo;

    #[inline]
    fn at_wo(&self, wo: Vec3) -> GltfAtWo {
        let (diffuse_a, diffuse_b) = self.diffuse_weight_terms();
        let coat_frame = self.coat_frame(wo);
        let coat_wo = coat_frame.map_or(wo, |c| c.wo);
        let coat_weight = self.coat_weight(coat_wo.z);
        let sheen = self.sheen_at(wo.z);
        GltfAtWo {
            base: ggx::GgxAtWo::new(self.alpha(), wo),
            coat: ggx::GgxAtWo::new(self.coat_alpha(), coat_wo),
            coat_frame,
            f90: self.glossy_f90(),
            diffuse_a,
            diffuse_b,
            base_weight: 1.0 - coat_weight,
            coat_weight,
            coat_share: self.coat_share(wo),
            inside_ior: if self.inside { 1.0 / self.etap() } else { 0.0 },
            sheen,
            sheen_max: self.sheen_color.max_element(),
            sheen_transmission: self.sheen_base_weight(&sheen),
            film: (self.iridescence > 0.0 && self.iridescence_thickness > 0.0 && !self.inside)
                .then(|| Film {
                    iridescence: self.iridescence,
                    ior: self.iridescence_ior,
                    thickness: self.iridescence_thickness,
                    dielectric_f0: self.dielectric_f0(),
                    metal_f0: self.base_color,
                    specular: self.specular,
                    metallic: self.metallic,
                }),
        }
    }

    /// `c_diff`, [`GltfPbr::glossy_f0`] and the sheen colour: the diffuse lobe is the
    /// Lambertian lobe of `c_diff` times the lane term `1 - specular max_value(fr)`, the glossy
    /// lobe `glossy_f0 (1 - s) + glossy_f90 s` times the microfacet lobe, both under the
    /// sheen's albedo scaling, plus the sheen colour times the sheen lobe (in the diffuse
    /// lobe); all under the coat's `1 - clearcoat Fc`.
    #[inline]
    fn reflectances(&self) -> Reflectances<Vec3> {
        Reflectances {
            diffuse: self.diffuse_color(),
            glossy: self.glossy_f0(),
            sheen: self.sheen_color,
            retro: Vec3::ZERO,
        }
    }

    #[inline(always)]
    fn lobes<L: Lanes, S: Spectrum<L>>(
        at: &GltfAtWo,
        r: Reflectances<S>,
        wo: Vec3,
        wi: [L; 3],
    ) -> Lobes<S, L> {
        let (spec, pdf) = ggx::microfacet_correlated(&at.base, wo, wi);
        let h = half_vector(wo, wi);
        let cos = h[0] * wo.x + h[1] * wo.y + h[2] * wo.z;
        let s = if at.inside_ior > 0.0 {
            // `outside_cos` in lanes: `sqrt(1 - (1 - cos^2) ior^2)`, 0 when totally reflected.
            let ior2 = at.inside_ior * at.inside_ior;
            schlick_weight(
                (L::splat(1.0) - (L::splat(1.0) - cos * cos) * ior2)
                    .saturate()
                    .sqrt(),
            )
        } else {
            schlick_weight(cos)
        };
        let (mut diffuse_weight, colour) = match &at.film {
            None => (
                (L::splat(at.diffuse_a) - s * at.diffuse_b) * at.base_weight,
                r.glossy * s.one_minus() + S::grey(s * at.f90),
            ),
            Some(film) => (
                cos.lanewise(|c| film.diffuse_weight(c)) * at.base_weight,
                S::from_rgb(cos, |c| film.glossy_colour(c)),
            ),
        };
        let mut glossy = colour * (spec * at.base_weight);
        let mut sheen = None;
        if let Some(sh) = &at.sheen {
            let scale = sh.base_weight(at.sheen_max, wi[2]);
            diffuse_weight = diffuse_weight * scale;
            glossy = glossy * scale;
            sheen = Some(r.sheen * (sh.lobe(h[2], wi[2]) * at.base_weight));
        }
        let mut glossy_pdf = pdf;
        if at.coat_weight > 0.0 {
            let (coat, coat_pdf) = match &at.coat_frame {
                None => ggx::microfacet_correlated(&at.coat, wo, wi),
                Some(c) => {
                    let wi_c = c.coat_from_shading(wi);
                    let (coat, pdf) = ggx::microfacet_correlated(&at.coat, c.wo, wi_c);
                    // A BRDF about the coat's normal (see the type's documentation); the
                    // visible normals' density is zero where the half vector is below it.
                    (
                        (coat * wi_c[2] / wi[2]).where_positive(wi_c[2]),
                        pdf.where_positive(wi_c[2] + c.wo.z),
                    )
                }
            };
            glossy = glossy + S::grey(coat * at.coat_weight);
            glossy_pdf = pdf * (1.0 - at.coat_share) + coat_pdf * at.coat_share;
        }
        let mut diffuse = lambert(r.diffuse) * diffuse_weight;
        if let Some(sheen) = sheen {
            diffuse = diffuse + sheen;
        }
        Lobes {
            diffuse,
            glossy,
            glossy_pdf,
        }
    }

    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        self.lobe_probabilities(wo).0
    }

    /// The coat with probability [`GltfPbr::coat_share`] (`u.x` rescaled to choose), else the
    /// base's lobe; each by its visible normals (the coat's about its own normal).
    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let q = self.coat_share(wo);
        let (alpha, u) = if u.x < q {
            let u = Vec2::new(u.x / q, u.y);
            if let Some(c) = self.coat_frame(wo) {
                let h = ggx::sample_visible_normal(c.wo, self.coat_alpha(), u)?;
                return Some(c.shading_from_coat(reflect(c.wo, h)));
            }
            (self.coat_alpha(), u)
        } else {
            (self.alpha(), Vec2::new((u.x - q) / (1.0 - q), u.y))
        };
        ggx::sample_visible_normal(wo, alpha, u).map(|h| reflect(wo, h))
    }

    /// The base colour.
    #[inline]
    fn albedo(&self) -> Vec3 {
        self.base_color
    }
}

#[cfg(test)]
mod tests {
    //! The chi-square tests of [`GltfPbr`] (the core model at grazing angles too, and the
    //! extensions' variants), its identity with the specification's formulas written again in
    //! f64 from appendix B and the extensions' pseudocode, white furnaces and analytic cases.
    use super::*;
    use crate::bsdf::tests::{
        d3, gltf_variants, mc_albedo, random_dir, run, COAT_NORMALS, COAT_NORMAL_ANGLES,
        GLTF_ANGLES, GLTF_ROUGHNESS, GLTF_VARIANT_ANGLES,
    };
    use crate::bsdf::{Bsdf, Diffuse, Ggx};
    use crate::sampling::Pcg32;
    use std::f32::consts::PI;
    use std::f64::consts::PI as PI64;

    fn pbr(base_color: Vec3, metallic: f32, roughness: f32) -> GltfPbr {
        GltfPbr {
            base_color,
            metallic,
            roughness,
            ..GltfPbr::default()
        }
    }

    #[test]
    fn chi_square_gltf() {
        for metallic in [0.0, 1.0] {
            for roughness in GLTF_ROUGHNESS {
                for theta in GLTF_ANGLES {
                    let b = Bsdf::GltfPbr(pbr(Vec3::new(0.8, 0.5, 0.2), metallic, roughness));
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
    fn chi_square_gltf_specular_ior_and_clearcoat() {
        for (k, g) in gltf_variants().into_iter().enumerate() {
            for theta in GLTF_VARIANT_ANGLES {
                run(
                    format!("gltf variant {k} {g:?} theta_o {theta}"),
                    Bsdf::GltfPbr(g),
                    theta,
                    6,
                );
            }
        }
    }

    /// A coat whose normal is tilted by `tilt` radians toward +X of the shading frame.
    fn tilted_coat(base: GltfPbr, tilt: f32) -> GltfPbr {
        GltfPbr {
            coat_normal: Vec3::new(tilt.sin(), 0.0, tilt.cos()),
            ..base
        }
    }

    /// A tilted coat (clearcoatNormalTexture) samples what it evaluates: over a dark rough
    /// dielectric and over a metal, the tilt toward and away from `wo`'s azimuth.
    #[test]
    fn chi_square_tilted_coat() {
        let materials: [GltfPbr; COAT_NORMALS] = [
            tilted_coat(gltf_variants()[2], 0.3),
            tilted_coat(gltf_variants()[3], -0.5),
        ];
        for (k, g) in materials.into_iter().enumerate() {
            for theta in COAT_NORMAL_ANGLES {
                let name = format!("tilted coat {k} {g:?} theta_o {theta}");
                run(name, Bsdf::GltfPbr(g), theta, 8 + k as u64);
            }
        }
    }

    /// A coat normal map tilts the coat's highlight and not the base's: with the coat's
    /// normal tilted by 10 degrees, the coat's peak moves to the mirror direction about the
    /// tilted normal, and the base's value at its own mirror direction is unchanged but for
    /// the coat's Fresnel weight, now taken at the tilted normal.
    #[test]
    fn coat_normal_tilts_the_coat_highlight_only() {
        let flat = GltfPbr {
            base_color: Vec3::splat(0.5),
            metallic: 1.0,
            roughness: 0.4,
            clearcoat: 1.0,
            clearcoat_roughness: 0.05,
            ..GltfPbr::default()
        };
        let tilt = 10f32.to_radians();
        let tilted = tilted_coat(flat, tilt);
        let wo = Vec3::new(30f32.to_radians().sin(), 0.0, 30f32.to_radians().cos());
        let mirror = |n: Vec3| 2.0 * wo.dot(n) * n - wo;
        let (r_base, r_coat) = (mirror(Vec3::Z), mirror(tilted.coat_normal));
        let glossy = |g: GltfPbr, wi: Vec3| Bsdf::GltfPbr(g).eval_lobes(wo, wi).glossy.x;
        let base_only = |g: GltfPbr, wi: Vec3| {
            Bsdf::GltfPbr(GltfPbr {
                clearcoat: 0.0,
                ..g
            })
            .eval_lobes(wo, wi)
            .glossy
            .x
        };
        // The coat's narrow peak: at r_coat when tilted, at r_base when flat.
        assert!(glossy(tilted, r_coat) > 20.0 * glossy(flat, r_coat));
        assert!(
            glossy(flat, r_base) > 20.0 * glossy(tilted, r_base) - 20.0 * base_only(flat, r_base)
        );
        // At r_base the tilted material is the base alone, weighed by 1 - Fc(nc.wo).
        let fc = |cos: f32| 0.04 + 0.96 * (1.0 - cos).powi(5);
        let want = base_only(flat, r_base) * (1.0 - fc(wo.dot(tilted.coat_normal)));
        let got = glossy(tilted, r_base);
        assert!((got - want).abs() < 1e-3 * want, "{got} vs {want}");
        // The coat's value at its peak is the flat coat's for the same directions in the
        // coat's frame (20 degrees), times nc.wi / n.wi.
        let coat = |g: GltfPbr, wo: Vec3, wi: Vec3| {
            let all = Bsdf::GltfPbr(g).eval_lobes(wo, wi).glossy.x;
            let base = Bsdf::GltfPbr(GltfPbr {
                clearcoat: 0.0,
                ..g
            })
            .eval_lobes(wo, wi)
            .glossy
            .x;
            all - base * (1.0 - fc(wo.dot(g.coat_normal)))
        };
        let wo_c = Vec3::new(20f32.to_radians().sin(), 0.0, 20f32.to_radians().cos());
        let ratio = r_coat.dot(tilted.coat_normal) / r_coat.z;
        let c_tilted = coat(tilted, wo, r_coat);
        let c_flat = coat(flat, wo_c, Vec3::new(-wo_c.x, 0.0, wo_c.z)) * ratio;
        assert!(
            (c_tilted - c_flat).abs() < 2e-3 * c_flat,
            "{c_tilted} vs {c_flat}"
        );
        // Flat: exactly the untilted material.
        assert_eq!(tilted_coat(flat, 0.0), flat);
    }

    /// GGX's `D` and the height-correlated `V` as appendix B writes them.
    fn spec_d_v(alpha: f64, n_h: f64, n_l: f64, n_v: f64) -> f64 {
        let a2 = alpha * alpha;
        let t = n_h * n_h * (a2 - 1.0) + 1.0;
        let d = a2 / (PI64 * t * t);
        let v = 0.5
            / (n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt()
                + n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt());
        d * v
    }

    /// The coated material of KHR_materials_clearcoat over KHR_materials_specular's and
    /// KHR_materials_ior's metallic-roughness material, from their pseudocode, in f64.
    fn spec_reference(g: &GltfPbr, wo: Vec3, wi: Vec3) -> [f64; 3] {
        let (v, l) = (d3(wo), d3(wi));
        let hs = [v[0] + l[0], v[1] + l[1], v[2] + l[2]];
        let len = (hs[0] * hs[0] + hs[1] * hs[1] + hs[2] * hs[2]).sqrt();
        let h = hs.map(|c| c / len);
        let v_h = (v[0] * h[0] + v[1] * h[1] + v[2] * h[2]).abs();
        let alpha = ((g.roughness as f64).powi(2)).max(MIN_ALPHA as f64);
        let coat_alpha = ((g.clearcoat_roughness as f64).powi(2)).max(MIN_ALPHA as f64);
        let specular_brdf = spec_d_v(alpha, h[2], l[2], v[2]);
        let coat_brdf = spec_d_v(coat_alpha, h[2], l[2], v[2]);
        let w = (1.0 - v_h).powi(5);
        let ior = g.ior as f64;
        let ior_f0 = ((1.0 - ior) / (1.0 + ior)).powi(2);
        // KHR_materials_iridescence: each Fresnel term mixed with the thin film's.
        let k = if g.iridescence_thickness > 0.0 {
            g.iridescence as f64
        } else {
            0.0
        };
        let film = |f0: [f64; 3]| {
            let (ior, d) = (g.iridescence_ior as f64, g.iridescence_thickness as f64);
            super::super::iridescence::tests::reference(v_h, ior, d, f0)
        };
        let f0_d: [f64; 3] =
            std::array::from_fn(|c| (ior_f0 * g.specular_color[c] as f64).min(1.0));
        let film_d = film(f0_d);
        let film_m = film(g.base_color.to_array().map(f64::from));
        let fr: [f64; 3] = std::array::from_fn(|c| {
            let f0 = f0_d[c];
            let schlick = f0 + (1.0 - f0) * w;
            schlick + (film_d[c] - schlick) * k
        });
        let fr_max = fr[0].max(fr[1]).max(fr[2]);
        let (weight, metallic) = (g.specular as f64, g.metallic as f64);
        let coat = g.clearcoat as f64 * (0.04 + 0.96 * (1.0 - v[2].abs()).powi(5));
        // KHR_materials_sheen's albedo scaling (E from the table; the variants' roughnesses
        // are where E <= 1, so the lobe is not renormalised).
        let sheen_max = g.sheen_color.max_element() as f64;
        let e = |cos: f64| super::super::sheen::albedo(cos as f32, g.sheen_roughness) as f64;
        let scaling = 1.0 - sheen_max * e(v[2]).max(e(l[2]));
        let sheen_brdf = super::super::sheen::integration::lobe(g.sheen_roughness as f64, v, l);
        std::array::from_fn(|c| {
            let base = g.base_color[c] as f64;
            let dielectric = (1.0 - weight * fr_max) * base / PI64 + weight * fr[c] * specular_brdf;
            let metal_f = base + (1.0 - base) * w;
            let metal = (metal_f + (film_m[c] - metal_f) * k) * specular_brdf;
            let mut material = (1.0 - metallic) * dielectric + metallic * metal;
            if sheen_max > 0.0 {
                material = g.sheen_color[c] as f64 * sheen_brdf + material * scaling;
            }
            (1.0 - coat) * material + coat * coat_brdf
        })
    }

    #[test]
    fn gltf_is_the_specification() {
        let mut rng = Pcg32::new(17, 1);
        let mut materials = gltf_variants().to_vec();
        materials.push(pbr(Vec3::new(0.9, 0.6, 0.3), 0.4, 0.5));
        materials.push(pbr(Vec3::new(0.2, 0.7, 0.5), 1.0, 0.2));
        for g in materials {
            let b = Bsdf::GltfPbr(g);
            for _ in 0..3000 {
                let [wo, wi] = [random_dir(&mut rng), random_dir(&mut rng)]
                    .map(|w| Vec3::new(w.x, w.y, w.z.abs()));
                if wo.z.min(wi.z) < 1e-3 {
                    continue;
                }
                let ours = b.eval(wo, wi);
                let want = spec_reference(&g, wo, wi);
                for c in 0..3 {
                    let got = ours[c] as f64;
                    assert!(
                        (got - want[c]).abs() <= 2e-4 * want[c].abs() + 1e-6,
                        "{g:?} wo {wo} wi {wi} channel {c}: {got} vs the specification {}",
                        want[c]
                    );
                }
            }
        }
    }

    #[test]
    fn gltf_at_normal_incidence() {
        // wo = wi = n: h = n, s = 0, D = 1 / (pi alpha^2), V = 1/4, so
        // glossy = F0 / (4 pi alpha^2) with F0 = mix(0.04, base, metallic), and
        // diffuse = (1 - metallic) (1 - 0.04) base / pi.
        let g = pbr(Vec3::new(0.5, 0.25, 1.0), 0.5, 0.6);
        let l = Bsdf::GltfPbr(g).eval_lobes(Vec3::Z, Vec3::Z);
        let alpha2 = 0.36f32 * 0.36;
        let f0 = Vec3::new(0.27, 0.145, 0.52);
        let c_diff = Vec3::new(0.25, 0.125, 0.5);
        assert!(
            (l.glossy - f0 / (4.0 * PI * alpha2)).abs().max_element() < 1e-5,
            "{l:?}"
        );
        assert!(
            (l.diffuse - 0.96 * c_diff / PI).abs().max_element() < 1e-6,
            "{l:?}"
        );
        // A coat of roughness 0.3 at normal incidence adds 0.04 clearcoat / (4 pi alpha_c^2)
        // and takes 0.04 clearcoat of the base.
        let coated = GltfPbr {
            clearcoat: 0.5,
            clearcoat_roughness: 0.3,
            ..g
        };
        let c = Bsdf::GltfPbr(coated).eval_lobes(Vec3::Z, Vec3::Z);
        let coat = 0.02 / (4.0 * PI * 0.09 * 0.09);
        assert!(
            (c.glossy - (0.98 * l.glossy + Vec3::splat(coat)))
                .abs()
                .max_element()
                < 1e-4,
            "{c:?}"
        );
        assert!(
            (c.diffuse - 0.98 * l.diffuse).abs().max_element() < 1e-6,
            "{c:?}"
        );
    }

    /// Specular 0 (Blender's Specular IOR Level 0): exactly the Lambertian lobe of the base
    /// colour, in value, density and samples, with no Fresnel lobe.
    #[test]
    fn specular_zero_is_exactly_lambertian() {
        let base_color = Vec3::new(0.05, 0.04, 0.03);
        let road = Bsdf::GltfPbr(GltfPbr {
            specular: 0.0,
            ..pbr(base_color, 0.0, 0.4)
        });
        let lambert = Bsdf::Diffuse(Diffuse { kd: base_color });
        assert_eq!(road.glossy_probability(Vec3::new(0.999, 0.0, 0.0447)), 0.0);
        let mut rng = Pcg32::new(18, 0);
        for _ in 0..2000 {
            let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
            assert_eq!(road.eval_lobes(wo, wi), lambert.eval_lobes(wo, wi));
            assert_eq!(road.pdf(wo, wi), lambert.pdf(wo, wi));
            let (u, u2) = (rng.next_f32(), rng.next_2d());
            assert_eq!(road.sample(wo, u, u2), lambert.sample(wo, u, u2));
        }
    }

    /// A white sheen over a white Lambertian base (specular 0) or a white metal reflects at
    /// most what it receives, at low roughness (where the extension's lobe alone gains
    /// energy at grazing angles and is renormalised) as at high; and a sheen over black
    /// reflects about `sheen_color E` (the table) at normal incidence.
    #[test]
    fn white_furnace_sheen() {
        for sheen_roughness in [0.05f32, 0.15, 0.3, 0.6, 1.0] {
            for theta in [0.0f32, 60.0, 80.0, 88.0] {
                let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
                for base in [
                    GltfPbr {
                        specular: 0.0,
                        ..pbr(Vec3::ONE, 0.0, 0.5)
                    },
                    pbr(Vec3::ONE, 1.0, 0.3),
                ] {
                    let g = GltfPbr {
                        sheen_color: Vec3::ONE,
                        sheen_roughness,
                        ..base
                    };
                    let (a, err) = mc_albedo(&Bsdf::GltfPbr(g), wo, 100_000, 26);
                    assert!(
                        a <= 1.0 + 3.0 * err + 2e-3,
                        "{g:?} theta {theta}: albedo {a} +- {err}"
                    );
                }
            }
        }
        let black = GltfPbr {
            specular: 0.0,
            sheen_color: Vec3::splat(0.8),
            sheen_roughness: 0.7,
            ..pbr(Vec3::ZERO, 0.0, 0.5)
        };
        let (a, err) = mc_albedo(&Bsdf::GltfPbr(black), Vec3::Z, 200_000, 27);
        let want = 0.8 * super::super::sheen::albedo(1.0, 0.7) as f64;
        assert!(
            (a - want).abs() < 4.0 * err + 2e-3,
            "{a} +- {err} vs {want}"
        );
    }

    #[test]
    fn white_furnace_gltf() {
        let white = Vec3::ONE;
        for theta in [0.0f32, 60.0, 85.0, 88.0] {
            let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
            let albedo = |g: GltfPbr| mc_albedo(&Bsdf::GltfPbr(g), wo, 100_000, 23);
            // A white metal reflects at most what it receives, at every angle.
            for g in [
                pbr(white, 1.0, 1.0),
                pbr(white, 1.0, 0.5),
                pbr(white, 1.0, 0.1),
            ] {
                let (a, err) = albedo(g);
                assert!(
                    a <= 1.0 + 3.0 * err,
                    "{g:?} theta {theta}: albedo {a} +- {err}"
                );
            }
            // A white dielectric too, up to 60 degrees. Beyond, the specification's mix gains
            // energy: it weights the diffuse lobe by `1 - F(wo.h)` for each pair of directions,
            // and `wo.h` is large for most `wi` even where `wo` is grazing, while the specular
            // lobe takes the grazing Fresnel. Measured here (roughness 0.3 / 1): 0.999 / 0.972
            // at normal incidence, 1.025 / 0.975 at 60 degrees, 1.30 / 0.99 at 85 degrees.
            // (KHR_materials_clearcoat takes its coat's Fresnel at `n.wo` to avoid this.)
            for g in [
                pbr(white, 0.0, 1.0),
                pbr(white, 0.0, 0.3),
                GltfPbr {
                    clearcoat: 1.0,
                    clearcoat_roughness: 0.1,
                    ..pbr(white, 0.0, 0.8)
                },
            ] {
                let (a, err) = albedo(g);
                let bound = if theta == 0.0 || (theta <= 60.0 && g.roughness > 0.5) {
                    1.0
                } else {
                    1.4
                };
                assert!(
                    a <= bound + 3.0 * err,
                    "{g:?} theta {theta}: albedo {a} +- {err}"
                );
            }
            // Specular 0: Lambertian, so every sample weighs exactly the base colour.
            let (a, err) = albedo(GltfPbr {
                specular: 0.0,
                ..pbr(white, 0.0, 0.5)
            });
            assert!(
                (a - 1.0).abs() < 1e-5 && err < 1e-5,
                "theta {theta}: {a} +- {err}"
            );
            // A white metal loses only the masking, less with the height-correlated Smith term
            // than with the separable one of the paper's GGX at the same alpha.
            for roughness in [0.3f32, 0.8] {
                let (metal, err) = albedo(pbr(white, 1.0, roughness));
                let (separable, err_s) = mc_albedo(
                    &Bsdf::Ggx(Ggx {
                        kd: Vec3::ZERO,
                        ks: white,
                        alpha: roughness * roughness,
                    }),
                    wo,
                    100_000,
                    23,
                );
                assert!(
                    metal > separable - 3.0 * (err + err_s),
                    "roughness {roughness} theta {theta}: {metal} vs separable {separable}"
                );
            }
        }
        // Near-smooth white metal at normal incidence reflects everything.
        let (a, err) = mc_albedo(&Bsdf::GltfPbr(pbr(white, 1.0, 0.1)), Vec3::Z, 100_000, 24);
        assert!(a > 0.995 && a < 1.0 + 3.0 * err, "{a} +- {err}");
        // A smooth coat over black: 0.04 at normal incidence.
        let (a, err) = mc_albedo(
            &Bsdf::GltfPbr(GltfPbr {
                clearcoat: 1.0,
                clearcoat_roughness: 0.1,
                specular: 0.0,
                ..pbr(Vec3::ZERO, 0.0, 0.5)
            }),
            Vec3::Z,
            100_000,
            25,
        );
        assert!((a - 0.04).abs() < 3.0 * err + 2e-4, "{a} +- {err}");
    }
}

#[cfg(test)]
mod transmission_tests {
    //! KHR_materials_transmission and KHR_materials_volume: chi-square tests over the whole
    //! sphere (thin-walled, entering and leaving a volume; rough and smooth, grazing angles
    //! included), white furnaces, the reciprocity of reflection and the generalized
    //! reciprocity of refraction, and the analytic values of a smooth interface.
    use super::*;
    use crate::bsdf::tests::random_dir;
    use crate::bsdf::Bsdf;
    use crate::sampling::Pcg32;
    use crate::testing::{check_bsdf, ChiSquareConfig};

    const ROUGHNESS: [f32; 4] = [0.0, 0.15, 0.5, 1.0];
    const ANGLES: [f32; 3] = [0.0, 60.0, 88.0];
    /// Thin-walled, entering a volume, leaving it.
    const MODES: [(bool, bool); 3] = [(true, false), (false, false), (false, true)];
    const MIXED: usize = 2;
    const NUM_TESTS: usize = MODES.len() * ANGLES.len() * (ROUGHNESS.len() + MIXED);

    fn glass(roughness: f32, (thin_walled, inside): (bool, bool)) -> GltfPbr {
        GltfPbr {
            base_color: Vec3::new(0.9, 0.8, 0.7),
            metallic: 0.0,
            roughness,
            transmission: 1.0,
            thin_walled,
            inside,
            ..GltfPbr::default()
        }
    }

    /// Partly transmissive materials: half diffuse, and a coated rough glass of ior 1.33.
    fn mixed(mode: (bool, bool)) -> [GltfPbr; MIXED] {
        [
            GltfPbr {
                transmission: 0.5,
                ..glass(0.3, mode)
            },
            GltfPbr {
                ior: 1.33,
                clearcoat: 0.5,
                clearcoat_roughness: 0.1,
                ..glass(0.6, mode)
            },
        ]
    }

    fn wo_at(theta_deg: f32) -> Vec3 {
        let (st, ct) = theta_deg.to_radians().sin_cos();
        let (sp, cp) = 0.7f32.sin_cos();
        Vec3::new(st * cp, st * sp, ct)
    }

    #[test]
    fn chi_square_transmission_over_the_sphere() {
        let config = |seed| ChiSquareConfig {
            samples: 100_000,
            num_tests: NUM_TESTS,
            seed,
            ..ChiSquareConfig::default()
        };
        let mut k = 0;
        for mode in MODES {
            // Roughness 0: a delta transmission beside a diffuse lobe, without the
            // reflection (a GGX lobe at MIN_ALPHA, too narrow for the cells' quadrature);
            // the delta samples are counted against the mass the density leaves uncovered.
            let materials = ROUGHNESS.map(|r| {
                if r == 0.0 {
                    GltfPbr {
                        specular: 0.0,
                        transmission: 0.5,
                        ..glass(r, mode)
                    }
                } else {
                    glass(r, mode)
                }
            });
            let materials = materials.into_iter();
            for g in materials.chain(mixed(mode)) {
                for theta in ANGLES {
                    k += 1;
                    let b = Bsdf::GltfPbr(g);
                    let name = format!("{g:?} theta_o {theta}");
                    let report = check_bsdf(&name, &b, wo_at(theta), &config(40 + k));
                    assert!(report.passed, "{report}");
                }
            }
        }
        assert_eq!(k as usize, NUM_TESTS);
    }

    /// `E[f |cos| / pdf]` split into reflection and transmission, with `f` scaled by `etap^2`
    /// for transmitted samples of a volume (radiance to energy), and the standard error of
    /// the total.
    fn furnace(g: &GltfPbr, wo: Vec3, n: usize, seed: u64) -> (f64, f64, f64) {
        let b = Bsdf::GltfPbr(*g);
        let etap2 = if g.thin_walled {
            1.0
        } else {
            g.etap() * g.etap()
        };
        let mut rng = Pcg32::new(seed, 7);
        let (mut r, mut t, mut sum2) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..n {
            if let Some(s) = b.sample(wo, rng.next_f32(), rng.next_2d()) {
                let v = (s.f.x * s.wi.z.abs() / s.pdf) as f64;
                if s.wi.z < 0.0 {
                    t += v * etap2 as f64;
                    sum2 += (v * etap2 as f64).powi(2);
                } else {
                    r += v;
                    sum2 += v * v;
                }
            }
        }
        let (r, t) = (r / n as f64, t / n as f64);
        let mean = r + t;
        let err = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        (r, t, err)
    }

    fn white(roughness: f32, mode: (bool, bool)) -> GltfPbr {
        GltfPbr {
            base_color: Vec3::ONE,
            ..glass(roughness, mode)
        }
    }

    #[test]
    fn white_furnace_smooth_reflects_and_transmits_everything() {
        for mode in MODES {
            for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
                let g = white(0.0, mode);
                let (r, t, err) = furnace(&g, wo_at(theta), 50_000, 3);
                // The reflection is the GGX lobe at MIN_ALPHA (masking loses ~1e-4).
                assert!(
                    (r + t - 1.0).abs() < 3.0 * err + 2e-3,
                    "{mode:?} theta {theta}: R {r} + T {t}"
                );
                // Leaving the volume beyond the critical angle (41.8 degrees): all reflected.
                if mode == (false, true) && theta > 42.0 {
                    assert_eq!(t, 0.0, "theta {theta}");
                }
            }
        }
    }

    #[test]
    fn white_furnace_rough_loses_only_masking() {
        for mode in MODES {
            for roughness in [0.15, 0.5, 1.0] {
                for theta in [0.0, 60.0, 85.0] {
                    let wo = wo_at(theta);
                    let (r, t, err) = furnace(&white(roughness, mode), wo, 100_000, 4);
                    let total = r + t;
                    assert!(
                        total <= 1.0 + 3.0 * err,
                        "{mode:?} {roughness} {theta}: {total}"
                    );
                    // Measured: 0.82-0.9999 up to roughness 0.5 (leaving a volume at grazing
                    // angles loses the most: its light is reflected more times inside).
                    if roughness <= 0.5 {
                        assert!(total > 0.8, "{mode:?} {roughness} {theta}: {total}");
                    }
                    if mode.0 {
                        // Thin-walled: the transmission is the mirrored reflection lobe, so
                        // both sum to a white metal's albedo of the same roughness.
                        let metal = Bsdf::GltfPbr(GltfPbr {
                            base_color: Vec3::ONE,
                            metallic: 1.0,
                            roughness,
                            ..GltfPbr::default()
                        });
                        let (m, m_err) = crate::bsdf::tests::mc_albedo(&metal, wo, 100_000, 5);
                        assert!(
                            (total - m).abs() < 4.0 * (err + m_err) + 1e-3,
                            "{roughness} {theta}: {total} vs metal {m}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn smooth_transmission_at_normal_incidence_is_one_minus_f0() {
        let f0 = ior_f0(1.5);
        for mode in MODES {
            let g = glass(0.0, mode);
            let b = Bsdf::GltfPbr(g);
            // Transmission is the only lobe chosen above the glossy one's probability.
            let s = b
                .sample(Vec3::Z, 0.999, Vec2::splat(0.5))
                .expect("a sample");
            assert!(s.delta && s.lobe == Lobe::Transmission);
            assert!((s.wi + Vec3::Z).length() < 1e-6, "{s:?}");
            let etap2 = if mode.0 { 1.0 } else { g.etap() * g.etap() };
            let weight = s.f * (s.wi.z.abs() * etap2);
            let want = g.base_color * (1.0 - f0);
            assert!(
                (weight - want).abs().max_element() < 1e-5,
                "{mode:?}: {weight}"
            );
        }
    }

    /// `f(wo, wi)` for `wo` above and `wi` below against the reverse path seen from the other
    /// face (the frame flipped toward the new `wo`): equal when thin-walled, and
    /// `f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2` across a volume's boundary (radiance
    /// transport, see `dielectric.rs`). Reflection is reciprocal on each side.
    #[test]
    fn reciprocity_of_reflection_and_transmission() {
        let flip = |v: Vec3| Vec3::new(v.x, v.y, -v.z);
        let mut rng = Pcg32::new(21, 0);
        let mut compared = 0;
        for roughness in [0.15, 0.5, 1.0] {
            let thin = glass(roughness, (true, false));
            let (outside, inside) = (
                glass(roughness, (false, false)),
                glass(roughness, (false, true)),
            );
            let eta2 = 1.5f32 * 1.5;
            for _ in 0..4000 {
                let wo = random_dir(&mut rng);
                let wo = Vec3::new(wo.x, wo.y, wo.z.abs());
                // Half near the refracted or straight-through direction.
                let wi = if rng.next_f32() < 0.5 {
                    let d = random_dir(&mut rng);
                    Vec3::new(d.x, d.y, -d.z.abs())
                } else {
                    let target = refract(wo, Vec3::Z, 1.5).unwrap_or(-wo);
                    (target + 0.3 * roughness * random_dir(&mut rng)).normalize()
                };
                if wi.z >= 0.0 || wo.z <= 0.0 {
                    continue;
                }
                // f32 rounding: `wo + etap wi` and `wi.m + wo.m / etap` cancel near grazing
                // configurations (0.14% seen at wo.z = 0.05).
                let close = |a: f32, b: f32| (a - b).abs() <= 5e-3 * a.abs().max(b.abs()) + 1e-6;
                let (f, r) = (
                    Bsdf::GltfPbr(thin).eval(wo, wi),
                    Bsdf::GltfPbr(thin).eval(flip(wi), flip(wo)),
                );
                assert!(close(f.x, r.x), "thin {roughness} {wo} {wi}: {f} vs {r}");
                let f = Bsdf::GltfPbr(outside).eval(wo, wi);
                let r = Bsdf::GltfPbr(inside).eval(flip(wi), flip(wo));
                assert!(
                    close(f.x, r.x / eta2),
                    "volume {roughness} {wo} {wi}: {f} vs {r}"
                );
                compared += (f.x > 0.1) as usize;
                // Reflection on either side.
                let up = Vec3::new(wi.x, wi.y, -wi.z);
                for g in [thin, outside, inside] {
                    let (a, b) = (Bsdf::GltfPbr(g).eval(wo, up), Bsdf::GltfPbr(g).eval(up, wo));
                    assert!(close(a.x, b.x), "{g:?} {wo} {up}: {a} vs {b}");
                }
            }
        }
        assert!(compared > 100, "too few transmissions compared: {compared}");
    }

    #[test]
    fn opaque_is_unchanged_and_nothing_transmits_without_transmission() {
        let g = GltfPbr {
            base_color: Vec3::new(0.5, 0.4, 0.3),
            metallic: 0.0,
            roughness: 0.4,
            thin_walled: false,
            ..GltfPbr::default()
        };
        let b = Bsdf::GltfPbr(g);
        assert!(!b.transmits() && b.seen_from_back() == b);
        assert_eq!(b.eval(Vec3::Z, -Vec3::Z), Vec3::ZERO);
        // With transmission, a volume's back face refracts from inside.
        let t = Bsdf::GltfPbr(GltfPbr {
            transmission: 1.0,
            ..g
        });
        let Bsdf::GltfPbr(back) = t.seen_from_back() else {
            unreachable!()
        };
        assert!(back.inside && (back.etap() - 1.0 / 1.5).abs() < 1e-7);
    }
}
