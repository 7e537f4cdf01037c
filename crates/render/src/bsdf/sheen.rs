//! The sheen lobe of KHR_materials_sheen, which [`super::GltfPbr`] layers over its base: the
//! "Charlie" microfiber distribution (Estevez and Kulla 2017, "Production Friendly Microfacet
//! Sheen BRDF") with the extension's fitted visibility, and the lobe's directional albedo
//! `E(cos, roughness)` ([`albedo`], tabulated in `sheen_table.rs`) that the layering uses.
//!
//! With `alpha = sheenRoughness^2` (the extension's mapping), the lobe without its colour is
//! `f = D(h) V(wo, wi)` (no Fresnel term, as the extension allows):
//!
//! - `D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi)`;
//! - `V = 1 / ((1 + lambda(cos_o) + lambda(cos_i)) 4 cos_o cos_i)`, with
//!   `lambda(c) = exp(l(c))` for `c < 0.5` and `exp(2 l(0.5) - l(1 - c))` otherwise, and
//!   `l(x) = a / (1 + b x^c) + d x + e`, whose five coefficients are interpolated between two
//!   fits by `(1 - alpha)^2`.
//!
//! The layering (the extension's "albedo scaling"): `f = sheenColor f_sheen + base (1 -
//! max3(sheenColor) max(E(cos_o), E(cos_i)))`, the extension's `min(1 - m E(cos_o), 1 - m
//! E(cos_i))` form, which is reciprocal, and gains no energy as long as the base does not:
//! the sheen reflects at most `m E(cos_o)` of the light arriving along `wo` and the base is
//! weighted by at most `1 - m E(cos_o)`.
//!
//! The extension's fitted visibility is not energy conserving everywhere: below a sheen
//! roughness of about 0.27 and at grazing `wo` (`cos_o` below 0.07, beyond 86 degrees), the
//! lobe's albedo `E` exceeds 1 (at most 1.1 at roughness 0.23, 1.7 at 0.13, 3.2 at 0.065,
//! 9.6 at 0.02; `sheen_table.rs`).
//! There the lobe is divided by `max(1, E(cos_o), E(cos_i))` (reciprocal, and 1 wherever
//! `E <= 1`, so the lobe is the extension's everywhere else) and `E` is taken as at most 1 in
//! the base's weight, so a white furnace never gains energy. (The glTF sample viewer reads
//! `E` from an 8-bit texture, which clamps it at 1 as well.)
//!
//! Sampling: the lobe is broad (it spreads over the whole hemisphere at high roughness and
//! peaks at grazing angles at low roughness), so it is sampled cosine-weighted, with the
//! diffuse lobe: the lobe mixture counts it in the diffuse lobe's share by its albedo
//! estimate `luminance(sheenColor) E(cos_o)`. Its value is in [`super::LobeValues::diffuse`]
//! (it is no source of streaks).

use super::numbers::Lanes;
use super::sheen_table::{SHEEN_ALBEDO, SHEEN_TABLE_SIZE};
use std::f32::consts::PI;

/// The sheen roughness below which `alpha` is clamped: a roughness of 0 makes `D` a spike at
/// grazing half vectors (the glTF sample renderer clamps at 1e-6; below 0.02 the lobe lies
/// within a degree of the horizon, too narrow for the albedo table's integration).
pub(super) const MIN_SHEEN_ROUGHNESS: f32 = 0.02;

/// The sheen lobe's terms for one roughness and one `wo`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SheenAtWo {
    /// `1 / alpha`.
    inv_alpha: f32,
    /// `D`'s normalisation, `(2 + 1/alpha) / (2 pi)`.
    d_norm: f32,
    /// The coefficients `a, b, c, d, e` of `l(x)`.
    fit: [f32; 5],
    /// `2 l(0.5)`.
    two_l_half: f32,
    /// `1 + lambda(cos_o)`.
    one_plus_lambda_o: f32,
    /// `4 cos_o`.
    four_cos_o: f32,
    /// The albedo table's row below the roughness, and the weight of the row above.
    row: usize,
    row_t: f32,
    /// `max(1, E(cos_o))`, the table's value before the clamp.
    e_o_raw: f32,
    /// `min(1, E(cos_o))`.
    pub(super) e_o: f32,
}

/// The coefficients of `l(x)` for `alpha`: the extension's two fits mixed by
/// `t = (1 - alpha)^2`.
fn fit(alpha: f32) -> [f32; 5] {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |x: f32, y: f32| x * (1.0 - t) + y * t;
    [
        mix(21.5473, 25.3245),
        mix(3.82987, 3.32435),
        mix(0.19823, 0.16801),
        mix(-1.97760, -1.27393),
        mix(-4.32054, -4.85967),
    ]
}

/// `l(x) = a / (1 + b x^c) + d x + e` for `x` in `[0, 0.5]`.
#[inline(always)]
fn l<L: Lanes>(fit: &[f32; 5], x: L) -> L {
    let [a, b, c, d, e] = *fit;
    L::splat(a) / (x.powf(c) * b + 1.0) + x * d + e
}

/// The sheen roughness clamped to `[MIN_SHEEN_ROUGHNESS, 1]`, and its `alpha`.
#[inline]
pub(super) fn alpha(roughness: f32) -> f32 {
    let r = roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0);
    r * r
}

impl SheenAtWo {
    /// The terms for sheen roughness `roughness` and `wo` of cosine `cos_o > 0`.
    #[inline]
    pub(super) fn new(roughness: f32, cos_o: f32) -> Self {
        let alpha = alpha(roughness);
        let inv_alpha = 1.0 / alpha;
        let fit = fit(alpha);
        let two_l_half = 2.0 * l(&fit, 0.5f32);
        let (row, row_t) = row(roughness);
        let mut at = SheenAtWo {
            inv_alpha,
            d_norm: (2.0 + inv_alpha) / (2.0 * PI),
            fit,
            two_l_half,
            one_plus_lambda_o: 0.0,
            four_cos_o: 4.0 * cos_o,
            row,
            row_t,
            e_o_raw: 0.0,
            e_o: 0.0,
        };
        at.one_plus_lambda_o = 1.0 + at.lambda(cos_o);
        let e = at.albedo(cos_o);
        at.e_o_raw = e.max(1.0);
        at.e_o = e.min(1.0);
        at
    }

    /// `lambda(cos)` for cosines in `[0, 1]`: `exp(l(x))` below 0.5 and `exp(2 l(0.5) -
    /// l(x))` above, with `x = min(cos, 1 - cos)` (the two agree at 0.5).
    #[inline(always)]
    fn lambda<L: Lanes>(&self, cos: L) -> L {
        let x = ((L::splat(1.0) - (cos * 2.0 + -1.0).abs()) * 0.5).saturate();
        let lx = l(&self.fit, x);
        (lx + (L::splat(self.two_l_half) - lx - lx).where_positive(cos + -0.5)).exp()
    }

    /// The lobe `D V / max(1, E(cos_o), E(cos_i))` (without the colour; see the module
    /// documentation) for `wi` above the surface, given with the cosine of its half vector
    /// with `wo`.
    #[inline(always)]
    pub(super) fn lobe<L: Lanes>(&self, cos_h: L, cos_i: L) -> L {
        let norm = cos_i.lanewise(|c| self.albedo(c).max(self.e_o_raw));
        self.lobe_unclamped(cos_h, cos_i) / norm
    }

    /// The extension's lobe `D V`.
    #[inline(always)]
    fn lobe_unclamped<L: Lanes>(&self, cos_h: L, cos_i: L) -> L {
        let sin2 = (L::splat(1.0) - cos_h * cos_h).saturate();
        let d = sin2.powf(0.5 * self.inv_alpha) * self.d_norm;
        let g = self.lambda(cos_i) + self.one_plus_lambda_o;
        d / (g * cos_i * self.four_cos_o)
    }

    /// The directional albedo `E(cos)` of [`SheenAtWo::lobe_unclamped`] at this roughness
    /// (bilinear in the table, in `sqrt(cos)` and the roughness).
    #[inline(always)]
    pub(super) fn albedo(&self, cos: f32) -> f32 {
        let (col, col_t) = cell(cos.max(0.0).sqrt());
        let at = |r: usize, c: usize| SHEEN_ALBEDO[r.min(SHEEN_TABLE_SIZE - 1)][c];
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let below = lerp(at(self.row, col), at(self.row, col + 1), col_t);
        let above = lerp(at(self.row + 1, col), at(self.row + 1, col + 1), col_t);
        lerp(below, above, self.row_t)
    }

    /// The base's weight under the sheen toward `wi` (cosines in lanes), `1 - m max(E(cos_o),
    /// E(cos_i))` with `m` the sheen colour's largest channel.
    #[inline(always)]
    pub(super) fn base_weight<L: Lanes>(&self, max_color: f32, cos_i: L) -> L {
        cos_i.lanewise(|c| 1.0 - max_color * self.albedo(c).min(1.0).max(self.e_o))
    }
}

/// The table's node below `x` in `[0, 1]` and the weight of the next one.
#[inline(always)]
fn cell(x: f32) -> (usize, f32) {
    let s = x.clamp(0.0, 1.0) * (SHEEN_TABLE_SIZE - 1) as f32;
    let i = (s as usize).min(SHEEN_TABLE_SIZE - 2);
    (i, s - i as f32)
}

/// The table's row below the sheen roughness `roughness` and the weight of the next one.
#[inline]
fn row(roughness: f32) -> (usize, f32) {
    cell(roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0))
}

/// The directional albedo `E(cos_o, roughness) = integral of D V cos_i over the hemisphere`
/// (of the extension's lobe), from the table.
#[cfg(test)]
pub(super) fn albedo(cos_o: f32, roughness: f32) -> f32 {
    SheenAtWo::new(roughness, cos_o.max(1e-4)).albedo(cos_o)
}

/// Where the table's values come from: the integral of the lobe, written again in f64, by
/// a midpoint rule in `(sqrt(cos_i), phi)`, at `cos_o = max((k / (N - 1))^2, 1e-5)` and sheen
/// roughness `max(j / (N - 1), MIN_SHEEN_ROUGHNESS)`.
#[cfg(test)]
pub(super) mod integration {
    use super::MIN_SHEEN_ROUGHNESS;
    use std::f64::consts::PI;

    /// `D V` in f64, from the extension's formulas.
    pub(crate) fn lobe(roughness: f64, wo: [f64; 3], wi: [f64; 3]) -> f64 {
        let alpha = roughness.clamp(MIN_SHEEN_ROUGHNESS as f64, 1.0).powi(2);
        let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
        let cos_h = h[2] / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        let inv_r = 1.0 / alpha;
        let sin2h = (1.0 - cos_h * cos_h).max(0.0);
        let d = (2.0 + inv_r) * sin2h.powf(inv_r * 0.5) / (2.0 * PI);
        let t = (1.0 - alpha) * (1.0 - alpha);
        let mix = |x: f64, y: f64| x * (1.0 - t) + y * t;
        let (a, b, c) = (
            mix(21.5473, 25.3245),
            mix(3.82987, 3.32435),
            mix(0.19823, 0.16801),
        );
        let (dd, e) = (mix(-1.97760, -1.27393), mix(-4.32054, -4.85967));
        let l = |x: f64| a / (1.0 + b * x.powf(c)) + dd * x + e;
        let lambda = |cos: f64| {
            if cos.abs() < 0.5 {
                l(cos).exp()
            } else {
                (2.0 * l(0.5) - l(1.0 - cos)).exp()
            }
        };
        let (n_v, n_l) = (wo[2], wi[2]);
        d / ((1.0 + lambda(n_v) + lambda(n_l)) * (4.0 * n_v * n_l))
    }

    /// `E(cos_o, roughness)` by the midpoint rule over `t = sqrt(cos_i)` (`n` steps, `dcos_i
    /// = 2 t dt`: the lobe's grazing part gets the most points) and `phi` (`2n`).
    pub(crate) fn albedo(cos_o: f64, roughness: f64, n: usize) -> f64 {
        let wo = [(1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o];
        let mut sum = 0.0;
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64;
            let z = t * t;
            let s = (1.0 - z * z).sqrt();
            // phi over [0, pi], doubled (the lobe is symmetric about the plane of wo).
            for j in 0..2 * n {
                let phi = PI * (j as f64 + 0.5) / (2 * n) as f64;
                let wi = [s * phi.cos(), s * phi.sin(), z];
                sum += lobe(roughness, wo, wi) * z * 2.0 * t;
            }
        }
        sum * 2.0 * (1.0 / n as f64) * (PI / (2 * n) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{square_to_cosine_hemisphere, Pcg32};
    use glam::Vec3;

    /// Writes `sheen_table.rs` from [`integration::albedo`] (run with `--ignored` to
    /// regenerate it; a few minutes).
    #[test]
    #[ignore]
    fn write_sheen_table() {
        let n = SHEEN_TABLE_SIZE;
        let mut out = String::new();
        out.push_str(
            "//! The sheen lobe's directional albedo `E(cos_o, sheenRoughness)` (see `sheen.rs`):\n\
             //! row `j` is the sheen roughness `max(j / 31, 0.02)`, column `k` is\n\
             //! `cos_o = max((k / 31)^2, 1e-5)`. Generated by the ignored test\n\
             //! `bsdf::sheen::tests::write_sheen_table` (a midpoint rule in f64, 500 x 1000 points per\n\
             //! entry); `sheen::tests::table_is_the_integral` checks it against Monte Carlo.\n\n",
        );
        out.push_str("/// Entries per side of [`SHEEN_ALBEDO`].\n");
        out.push_str(&format!(
            "pub(super) const SHEEN_TABLE_SIZE: usize = {n};\n\n"
        ));
        out.push_str("/// `E(cos_o, roughness)`, `[roughness][cos_o]`.\n");
        out.push_str("#[rustfmt::skip]\n#[allow(clippy::excessive_precision)]\n");
        out.push_str(&format!(
            "pub(super) const SHEEN_ALBEDO: [[f32; {n}]; {n}] = [\n"
        ));
        for j in 0..n {
            let r = (j as f64 / (n - 1) as f64).max(MIN_SHEEN_ROUGHNESS as f64);
            out.push_str("    [");
            for k in 0..n {
                let mu = (k as f64 / (n - 1) as f64).powi(2).max(1e-5);
                let e = integration::albedo(mu, r, 500);
                out.push_str(&format!("{:.6}", e as f32));
                if k + 1 < n {
                    out.push_str(", ");
                }
            }
            out.push_str("],\n");
        }
        out.push_str("];\n");
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/bsdf/sheen_table.rs");
        std::fs::write(path, out).unwrap();
    }

    /// The lobe in f32 (what rendering evaluates) is the f64 formulas of the extension.
    #[test]
    fn lobe_is_the_extension() {
        let mut rng = Pcg32::new(5, 9);
        for roughness in [0.05f32, 0.3, 0.6, 1.0] {
            for _ in 0..2000 {
                let wo = crate::sampling::square_to_uniform_sphere(rng.next_2d())
                    * Vec3::new(1.0, 1.0, 0.0)
                    + Vec3::Z * rng.next_f32();
                let wo = wo.normalize();
                let wi = crate::sampling::square_to_uniform_sphere(rng.next_2d());
                let wi = Vec3::new(wi.x, wi.y, wi.z.abs());
                if wo.z < 1e-3 || wi.z < 1e-3 {
                    continue;
                }
                let at = SheenAtWo::new(roughness, wo.z);
                let h = (wo + wi).normalize();
                let got = at.lobe_unclamped(h.z, wi.z) as f64;
                let d = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
                let want = integration::lobe(roughness as f64, d(wo), d(wi));
                assert!(
                    (got - want).abs() <= 2e-3 * want + 1e-7,
                    "roughness {roughness} {wo} {wi}: {got} vs {want}"
                );
            }
        }
    }

    /// The table against a fresh Monte Carlo integration (cosine-weighted directions, f32
    /// lobe), at its nodes and between them.
    #[test]
    fn table_is_the_integral() {
        let mut rng = Pcg32::new(7, 2);
        for (cos_o, roughness) in [
            (1.0f32, 1.0f32),
            (0.5, 0.5),
            (0.2, 0.3),
            (0.05, 0.8),
            (0.9, 0.1),
            (0.37, 0.66),
            (0.71, 0.23),
            (0.13, 0.95),
        ] {
            let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
            let at = SheenAtWo::new(roughness, cos_o);
            let n = 400_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let wi = square_to_cosine_hemisphere(rng.next_2d());
                if wi.z <= 0.0 {
                    continue;
                }
                let h = (wo + wi).normalize();
                // f cos / pdf with pdf = cos / pi.
                let v = (at.lobe_unclamped(h.z, wi.z) * PI) as f64;
                sum += v;
                sum2 += v * v;
            }
            let mean = sum / n as f64;
            let err = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            let table = albedo(cos_o, roughness) as f64;
            assert!(
                (table - mean).abs() < 4.0 * err + 5e-3,
                "cos_o {cos_o} roughness {roughness}: table {table} vs {mean} +- {err}"
            );
        }
    }

    /// The normalised lobe's albedo (Monte Carlo) never exceeds 1, where the extension's
    /// exceeds it too; and the table is finite and non-negative.
    #[test]
    fn normalised_lobe_albedo_is_at_most_one() {
        for row in SHEEN_ALBEDO {
            for e in row {
                assert!(e.is_finite() && e >= 0.0, "{e}");
            }
        }
        let mut rng = Pcg32::new(8, 1);
        for (cos_o, roughness) in [(0.03f32, 0.05f32), (0.01, 0.1), (0.2, 0.1), (0.0, 0.3)] {
            let cos_o = cos_o.max(1e-4);
            let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
            let at = SheenAtWo::new(roughness, cos_o);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let wi = square_to_cosine_hemisphere(rng.next_2d());
                if wi.z > 0.0 {
                    sum += (at.lobe((wo + wi).normalize().z, wi.z) * PI) as f64;
                }
            }
            let a = sum / n as f64;
            assert!(a <= 1.0 + 0.02, "cos_o {cos_o} roughness {roughness}: {a}");
        }
        assert!(
            albedo(0.001, 0.05) > 1.2,
            "the extension's lobe gains energy"
        );
    }

    /// `lambda` in lanes is the scalar one, and continuous at 0.5.
    #[test]
    fn lambda_branches_meet() {
        let at = SheenAtWo::new(0.5, 0.7);
        let below = at.lambda(0.5f32 - 1e-6);
        let above = at.lambda(0.5f32 + 1e-6);
        assert!((below - above).abs() < 1e-3 * below, "{below} {above}");
        let lanes = at.lambda(glam::Vec4::new(0.1, 0.5, 0.7, 1.0)).to_array();
        for (c, v) in [0.1f32, 0.5, 0.7, 1.0].into_iter().zip(lanes) {
            assert_eq!(v.to_bits(), at.lambda(c).to_bits());
        }
    }
}
