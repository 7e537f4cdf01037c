//! Sampling: warps from the unit square with their densities and inverses, the power heuristic
//! for multiple importance sampling, discrete distributions, and the Owen-scrambled Sobol
//! [`Sampler`].
//!
//! Warps come in threes, after Mitsuba 3 (`core/warp.h`): `square_to_x(u)` maps a uniform point
//! of `[0,1)^2` to the domain `x`, `square_to_x_pdf(v)` is the density of the result (per unit
//! solid angle for directions, per unit area for disks and triangles), and `x_to_square(v)` is
//! the inverse, so `x_to_square(square_to_x(u)) == u` up to rounding.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};
use std::sync::LazyLock;

// ---------------------------------------------------------------------------------------------
// Disk

/// Shirley and Chiu's concentric map from the square to the unit disk (area-preserving,
/// low distortion).
#[inline]
pub fn square_to_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let p = 2.0 * u - Vec2::ONE;
    if p.x == 0.0 && p.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) = if p.x.abs() > p.y.abs() {
        (p.x, FRAC_PI_4 * (p.y / p.x))
    } else {
        (p.y, FRAC_PI_2 - FRAC_PI_4 * (p.x / p.y))
    };
    let (s, c) = phi.sin_cos();
    Vec2::new(r * c, r * s)
}

/// Density of [`square_to_uniform_disk_concentric`] per unit area: `1/pi` inside the disk.
#[inline]
pub fn square_to_uniform_disk_concentric_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// Inverse of [`square_to_uniform_disk_concentric`].
#[inline]
pub fn uniform_disk_to_square_concentric(p: Vec2) -> Vec2 {
    let r = p.length();
    let mut phi = p.y.atan2(p.x);
    if phi < -FRAC_PI_4 {
        phi += TAU;
    }
    let (a, b) = if phi < FRAC_PI_4 {
        // Right wedge: a = r, b = phi * a / (pi/4).
        (r, phi * r / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        // Top wedge.
        (-(phi - FRAC_PI_2) * r / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, -(phi - PI) * r / FRAC_PI_4)
    } else {
        ((phi - 3.0 * FRAC_PI_2) * r / FRAC_PI_4, -r)
    };
    Vec2::new(0.5 * (a + 1.0), 0.5 * (b + 1.0))
}

// ---------------------------------------------------------------------------------------------
// Hemisphere and sphere

/// Cosine-weighted hemisphere about +Z (Malley's method on the concentric disk).
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let p = square_to_uniform_disk_concentric(u);
    let z = (1.0 - p.length_squared()).max(0.0).sqrt();
    Vec3::new(p.x, p.y, z)
}

/// Density of [`square_to_cosine_hemisphere`] per unit solid angle: `max(z, 0) / pi`.
#[inline]
pub fn square_to_cosine_hemisphere_pdf(v: Vec3) -> f32 {
    v.z.max(0.0) * FRAC_1_PI
}

/// Inverse of [`square_to_cosine_hemisphere`].
#[inline]
pub fn cosine_hemisphere_to_square(v: Vec3) -> Vec2 {
    uniform_disk_to_square_concentric(Vec2::new(v.x, v.y))
}

/// Uniform direction on the unit sphere (`z = 1 - 2 u.y`, `phi = 2 pi u.x`).
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.y;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (TAU * u.x).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Density of [`square_to_uniform_sphere`]: `1 / (4 pi)`.
#[inline]
pub fn square_to_uniform_sphere_pdf(_v: Vec3) -> f32 {
    0.25 * FRAC_1_PI
}

/// Inverse of [`square_to_uniform_sphere`].
#[inline]
pub fn uniform_sphere_to_square(v: Vec3) -> Vec2 {
    Vec2::new(wrapped_phi(v) / TAU, 0.5 * (1.0 - v.z))
}

/// Uniform direction in the cone of directions within `theta_max` of +Z, given
/// `one_minus_cos_max = 1 - cos(theta_max)` (in `(0, 2]`; passing `1 - cos` rather than `cos`
/// keeps narrow cones exact: a lamp of radius 5 cm at 100 m has `1 - cos = 1.25e-7`, below
/// `f32`'s resolution near 1). `1 - cos(theta) = u.y * one_minus_cos_max`.
#[inline]
pub fn square_to_uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    debug_assert!((0.0..=2.0).contains(&one_minus_cos_max));
    let one_minus_z = u.y * one_minus_cos_max;
    let z = 1.0 - one_minus_z;
    let r = (one_minus_z * (2.0 - one_minus_z)).max(0.0).sqrt();
    let (s, c) = (TAU * u.x).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Density of [`square_to_uniform_cone`]: `1 / (2 pi (1 - cos_max))` inside the cone, else 0.
#[inline]
pub fn square_to_uniform_cone_pdf(v: Vec3, one_minus_cos_max: f32) -> f32 {
    if one_minus_cos_of(v) <= one_minus_cos_max {
        1.0 / (TAU * one_minus_cos_max)
    } else {
        0.0
    }
}

/// Inverse of [`square_to_uniform_cone`].
#[inline]
pub fn uniform_cone_to_square(v: Vec3, one_minus_cos_max: f32) -> Vec2 {
    Vec2::new(
        wrapped_phi(v) / TAU,
        one_minus_cos_of(v) / one_minus_cos_max,
    )
}

/// `1 - v.z` for a unit vector, from `x^2 + y^2` near the axis (no cancellation).
#[inline]
fn one_minus_cos_of(v: Vec3) -> f32 {
    if v.z > 0.0 {
        (v.x * v.x + v.y * v.y) / (1.0 + v.z)
    } else {
        1.0 - v.z
    }
}

/// `atan2(y, x)` wrapped to `[0, 2 pi)`.
#[inline]
fn wrapped_phi(v: Vec3) -> f32 {
    let phi = v.y.atan2(v.x);
    if phi < 0.0 {
        (phi + TAU).min(TAU * (1.0 - f32::EPSILON / 2.0))
    } else {
        phi
    }
}

// ---------------------------------------------------------------------------------------------
// Triangle

/// Uniform point on the triangle, as barycentrics `(b1, b2)` (the first vertex gets
/// `1 - b1 - b2`): Mitsuba's `t = sqrt(1 - u.x)`, `(1 - t, t u.y)`.
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let t = (1.0 - u.x).max(0.0).sqrt();
    Vec2::new(1.0 - t, t * u.y)
}

/// Density of [`square_to_uniform_triangle`] per unit barycentric area: 2 inside, else 0.
#[inline]
pub fn square_to_uniform_triangle_pdf(b: Vec2) -> f32 {
    if b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 {
        2.0
    } else {
        0.0
    }
}

/// Inverse of [`square_to_uniform_triangle`].
#[inline]
pub fn uniform_triangle_to_square(b: Vec2) -> Vec2 {
    let t = 1.0 - b.x;
    let uy = if t > 0.0 { (b.y / t).min(1.0) } else { 0.0 };
    Vec2::new(1.0 - t * t, uy)
}

// ---------------------------------------------------------------------------------------------
// Multiple importance sampling

/// Veach's power heuristic with beta = 2: the weight of strategy `f` (`n_f` samples of density
/// `pdf_f`) against strategy `g`. Safe for infinite densities (a delta strategy gets weight 1)
/// and for both densities 0 (weight 0).
#[inline]
pub fn power_heuristic(n_f: f32, pdf_f: f32, n_g: f32, pdf_g: f32) -> f32 {
    let f = n_f * pdf_f;
    let g = n_g * pdf_g;
    if f.is_infinite() {
        return if g.is_infinite() { 0.5 } else { 1.0 };
    }
    if g.is_infinite() {
        return 0.0;
    }
    let ff = f * f;
    let gg = g * g;
    if ff + gg > 0.0 {
        if ff.is_infinite() || gg.is_infinite() {
            // Overflow of the squares: compare the ratio instead.
            let r = g / f;
            return 1.0 / (1.0 + r * r);
        }
        ff / (ff + gg)
    } else {
        0.0
    }
}

// ---------------------------------------------------------------------------------------------
// Discrete distributions

/// A discrete distribution over `0..n` proportional to non-negative weights, sampled by
/// inverting its cumulative distribution with a binary search (O(log n), no allocation).
#[derive(Clone, Debug, PartialEq)]
pub struct DiscreteDistribution {
    /// `cdf[i]` = probability of the indices `< i`; `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f32>,
    /// Normalised probabilities.
    pmf: Vec<f32>,
}

impl DiscreteDistribution {
    /// Builds the distribution; `None` when `weights` is empty, sums to zero, or holds a
    /// negative, NaN or infinite weight.
    pub fn new(weights: &[f32]) -> Option<Self> {
        if weights.is_empty() || weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        if total <= 0.0 {
            return None;
        }
        let pmf: Vec<f32> = weights
            .iter()
            .map(|&w| (f64::from(w) / total) as f32)
            .collect();
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0f32);
        for &w in weights {
            acc += f64::from(w);
            cdf.push((acc / total) as f32);
        }
        // Entries after the last positive weight become exactly 1, so that `u < 1` never lands
        // on a zero-weight index through rounding.
        let last = weights.iter().rposition(|&w| w > 0.0)?;
        for c in &mut cdf[last + 1..] {
            *c = 1.0;
        }
        Some(Self { cdf, pmf })
    }

    /// Number of entries.
    #[inline]
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// Always false (an empty distribution cannot be built); kept for the `len` convention.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// Probability of index `i` (0 out of range).
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }

    /// Samples an index from `u` in `[0, 1)`; returns it with its probability. Never returns an
    /// index of zero weight.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let (i, pmf, _) = self.sample_reuse(u);
        (i, pmf)
    }

    /// Like [`DiscreteDistribution::sample`], and also returns `u` rescaled to `[0, 1)` within
    /// the chosen entry, so the same random number can be used again.
    #[inline]
    pub fn sample_reuse(&self, u: f32) -> (usize, f32, f32) {
        debug_assert!((0.0..=1.0).contains(&u), "u = {u}");
        let n = self.pmf.len();
        // Largest i with cdf[i] <= u, in 0..n.
        let i = (self.cdf.partition_point(|&c| c <= u)).clamp(1, n) - 1;
        // Rounding can still land on a zero-weight entry only when u == cdf[i+1]; walk back.
        let mut i = i;
        while self.pmf[i] == 0.0 && i > 0 {
            i -= 1;
        }
        let width = self.cdf[i + 1] - self.cdf[i];
        let reused = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, self.pmf[i], reused)
    }
}

/// The largest `f32` below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

// ---------------------------------------------------------------------------------------------
// Random numbers

/// A 32-bit integer hash (the PCG output permutation applied to an LCG step; Jarzynski and
/// Olano, "Hash Functions for GPU Rendering", 2020). Used to derive seeds.
#[inline]
pub fn pcg_hash(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Maps 32 random bits to a float in `[0, 1)` (the top 24 bits, exactly representable).
#[inline]
pub fn u32_to_unit_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// O'Neill's PCG32 generator (XSH-RR): a small, fast, seedable stream of independent uniform
/// numbers, for tests and for anything that needs plain (not low-discrepancy) random numbers.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Pcg32 {
    /// A generator for `seed` on stream `stream` (different streams are independent).
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Self {
            state: 0,
            inc: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// A uniform float in `[0, 1)`.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        u32_to_unit_f32(self.next_u32())
    }

    /// A uniform point in `[0, 1)^2`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let x = self.next_f32();
        Vec2::new(x, self.next_f32())
    }
}

/// Sobol dimensions 0 to 3 (`sobol_burley`'s dimension set 0) by byte of the bit-reversed
/// sample index: entry `[b][v]` is the XOR of the direction vectors of the set bits of `v` in
/// byte `b` of the index's top 16 bits (the only bits `sobol_burley` uses). Two lookups
/// replace its loop over the set bits (about eight, data-dependent); 8 KB.
static SOBOL_SET0_BY_BYTE: LazyLock<[[[u32; 4]; 256]; 2]> = LazyLock::new(|| {
    std::array::from_fn(|b| {
        std::array::from_fn(|v| {
            let bits = (v as u32) << (24 - 8 * b as u32);
            sobol_burley::parts::sobol_int4_rev(bits, 0).into()
        })
    })
});

/// `sobol_burley::sample_4d(sample_index, 0, seed)`, bit for bit (tested), with the Sobol
/// part from [`SOBOL_SET0_BY_BYTE`]: the same index shuffle, Owen scramble and constants.
#[inline]
fn sobol_4d(sample_index: u32, seed: u32) -> [f32; 4] {
    use sobol_burley::parts::{hash, hash_int4, owen_scramble_int4_rev, owen_scramble_rev, Int4};
    let index_rev = owen_scramble_rev(sample_index.reverse_bits(), hash(seed ^ 0x79c68e4a));
    let table = &*SOBOL_SET0_BY_BYTE;
    let sobol = Int4::from(table[0][(index_rev >> 24) as usize])
        ^ Int4::from(table[1][((index_rev >> 16) & 0xff) as usize]);
    let s = seed.wrapping_mul(0x9c8f2d3b);
    let scramble = Int4::from([
        s ^ 0x912f69ba,
        s ^ 0x174f18ab,
        s ^ 0x691e72ca,
        s ^ 0xb40cc1b8,
    ]);
    owen_scramble_int4_rev(sobol, hash_int4(scramble))
        .reverse_bits()
        .to_f32_norm()
}

/// The sample indices `sobol_burley` supports (`2^16`).
pub const SOBOL_MAX_SAMPLES: u32 = 1 << 16;

/// Owen-scrambled Sobol sampler (Burley 2020, via the `sobol_burley` crate), padded the way
/// Burley and pbrt-v4's `PaddedSobolSampler` do.
///
/// Each call to [`Sampler::next_1d`], [`Sampler::next_2d`] or [`Sampler::next_4d`] consumes one
/// *dimension slot*. Slot `d` of pixel `(x, y)` reads Sobol dimension 0 (1D), dimensions 0 and 1
/// (2D) or dimensions 0 to 3 (4D) with the scramble seed `hash(seed, x, y, d)`. Dimensions 0 and 1 of Sobol form a (0,2)-sequence, so
/// every 2D request is as well stratified as Sobol can be, independent slots are decorrelated by
/// their seeds, pixels are decorrelated by hashing the pixel into the seed, and there is no
/// dimension limit. Values depend only on `(seed, pixel, sample_index, slot)`, so renders are
/// identical whatever the thread count or tile order.
///
/// `sobol_burley` supports sample indices below [`SOBOL_MAX_SAMPLES`] (2^16); from that index
/// on the sampler falls back to hashed random numbers (a PCG32 stream seeded by the same
/// hash and the sample index), still deterministic but without stratification.
#[derive(Clone, Debug)]
pub struct Sampler {
    seed: u32,
    pixel_seed: u32,
    sample_index: u32,
    dimension: u32,
}

impl Sampler {
    /// A sampler for the render seed `seed`.
    pub fn new(seed: u32) -> Self {
        Self {
            seed,
            pixel_seed: pcg_hash(seed),
            sample_index: 0,
            dimension: 0,
        }
    }

    /// Starts sample `sample_index` of `pixel`; the next request reads dimension slot 0.
    #[inline]
    pub fn start_pixel_sample(&mut self, pixel: (u32, u32), sample_index: u32) {
        self.pixel_seed = pcg_hash(pcg_hash(pcg_hash(self.seed) ^ pixel.0) ^ pixel.1);
        self.sample_index = sample_index;
        self.dimension = 0;
    }

    /// The scramble seed of the current dimension slot, and advance to the next slot.
    #[inline]
    fn next_slot_seed(&mut self) -> u32 {
        let s = pcg_hash(self.pixel_seed ^ pcg_hash(self.dimension));
        self.dimension = self.dimension.wrapping_add(1);
        s
    }

    /// Fallback for sample indices past `sobol_burley`'s limit.
    #[inline]
    fn hashed(&self, slot_seed: u32) -> Pcg32 {
        Pcg32::new(
            (u64::from(slot_seed) << 32) | u64::from(self.sample_index),
            u64::from(self.seed),
        )
    }

    /// The next 1D value in `[0, 1)`.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        let s = self.next_slot_seed();
        let v = if self.sample_index < SOBOL_MAX_SAMPLES {
            // Dimension 0 of `sobol_4d`: exactly `sobol_burley::sample(i, 0, s)` (tested).
            sobol_4d(self.sample_index, s)[0]
        } else {
            self.hashed(s).next_f32()
        };
        debug_assert!((0.0..1.0).contains(&v));
        v
    }

    /// The next 2D value in `[0, 1)^2`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let s = self.next_slot_seed();
        if self.sample_index < SOBOL_MAX_SAMPLES {
            // `sample_4d` returns exactly `sample(i, 0..4, s)` (sobol_burley tests this), and
            // shares the index scramble and uses SIMD: one call is cheaper than two `sample`s.
            let [x, y, _, _] = sobol_4d(self.sample_index, s);
            Vec2::new(x, y)
        } else {
            self.hashed(s).next_2d()
        }
    }

    /// The next 4D value in `[0, 1)^4`: Sobol dimensions 0 to 3 of one slot (one hash and one
    /// `sample_4d` call for four numbers). Dimensions 0 and 1 form a (0,2)-sequence, so put the
    /// 2D sample that needs the best stratification there (a direction or a point on a light)
    /// and the 1D choices (light, lobe, roulette) in 2 and 3.
    #[inline]
    pub fn next_4d(&mut self) -> [f32; 4] {
        let s = self.next_slot_seed();
        if self.sample_index < SOBOL_MAX_SAMPLES {
            sobol_4d(self.sample_index, s)
        } else {
            let mut rng = self.hashed(s);
            [
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
            ]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sobol_4d_is_sobol_burley_sample_4d() {
        let mut rng = Pcg32::new(3, 4);
        for i in (0..300).chain([1023, 4096, 65535]) {
            for _ in 0..50 {
                let seed = rng.next_u32();
                let v = sobol_4d(i, seed);
                assert_eq!(
                    v,
                    sobol_burley::sample_4d(i, 0, seed),
                    "index {i}, seed {seed}"
                );
                for (d, x) in v.into_iter().enumerate() {
                    assert_eq!(x, sobol_burley::sample(i, d as u32, seed));
                }
            }
        }
    }
    use crate::testing::{chi_square_plane, chi_square_sphere, ChiSquareConfig};

    const WARP_TESTS: usize = 5;

    fn config() -> ChiSquareConfig {
        ChiSquareConfig {
            num_tests: WARP_TESTS,
            ..ChiSquareConfig::default()
        }
    }

    fn grid(n: usize) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i / n) as f32 + 0.37) / n as f32,
                ((i % n) as f32 + 0.61) / n as f32,
            )
        })
    }

    #[test]
    fn warps_invert() {
        for u in grid(40) {
            let checks = [
                (
                    "disk",
                    uniform_disk_to_square_concentric(square_to_uniform_disk_concentric(u)),
                ),
                (
                    "cosine",
                    cosine_hemisphere_to_square(square_to_cosine_hemisphere(u)),
                ),
                (
                    "sphere",
                    uniform_sphere_to_square(square_to_uniform_sphere(u)),
                ),
                (
                    "cone",
                    uniform_cone_to_square(square_to_uniform_cone(u, 0.1), 0.1),
                ),
                (
                    "triangle",
                    uniform_triangle_to_square(square_to_uniform_triangle(u)),
                ),
            ];
            for (name, back) in checks {
                assert!(
                    (back - u).abs().max_element() < 2e-4,
                    "{name}: {u} -> {back}"
                );
            }
        }
    }

    #[test]
    fn warps_land_in_their_domains() {
        for u in grid(30) {
            assert!(square_to_uniform_disk_concentric(u).length() <= 1.0 + 1e-6);
            let v = square_to_cosine_hemisphere(u);
            assert!((v.length() - 1.0).abs() < 1e-5 && v.z >= 0.0);
            assert!((square_to_uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            let c = square_to_uniform_cone(u, 0.5);
            assert!((c.length() - 1.0).abs() < 1e-5 && c.z >= 0.5 - 1e-6);
            let b = square_to_uniform_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
        }
    }

    #[test]
    fn chi_square_direction_warps() {
        let c = config();
        let r = chi_square_sphere(
            "cosine hemisphere",
            &c,
            |rng| Some(square_to_cosine_hemisphere(rng.next_2d())),
            square_to_cosine_hemisphere_pdf,
        );
        assert!(r.passed && (r.pdf_integral - 1.0).abs() < 1e-3, "{r}");
        let r = chi_square_sphere(
            "uniform sphere",
            &c,
            |rng| Some(square_to_uniform_sphere(rng.next_2d())),
            square_to_uniform_sphere_pdf,
        );
        assert!(r.passed && (r.pdf_integral - 1.0).abs() < 1e-3, "{r}");
        let r = chi_square_sphere(
            "uniform cone 0.8",
            &c,
            |rng| Some(square_to_uniform_cone(rng.next_2d(), 0.2)),
            |v| square_to_uniform_cone_pdf(v, 0.2),
        );
        assert!(r.passed && (r.pdf_integral - 1.0).abs() < 1e-3, "{r}");
    }

    #[test]
    fn chi_square_plane_warps() {
        let c = ChiSquareConfig {
            cells: (32, 32),
            ..config()
        };
        let r = chi_square_plane(
            "concentric disk",
            &c,
            (-1.0, 1.0),
            (-1.0, 1.0),
            |rng| Some(square_to_uniform_disk_concentric(rng.next_2d())),
            square_to_uniform_disk_concentric_pdf,
        );
        assert!(r.passed && (r.pdf_integral - 1.0).abs() < 1e-3, "{r}");
        let r = chi_square_plane(
            "triangle",
            &c,
            (0.0, 1.0),
            (0.0, 1.0),
            |rng| Some(square_to_uniform_triangle(rng.next_2d())),
            square_to_uniform_triangle_pdf,
        );
        assert!(r.passed && (r.pdf_integral - 1.0).abs() < 1e-3, "{r}");
    }

    #[test]
    fn power_heuristic_cases() {
        assert_eq!(power_heuristic(1.0, 1.0, 1.0, 1.0), 0.5);
        assert!((power_heuristic(1.0, 3.0, 1.0, 1.0) - 0.9).abs() < 1e-6);
        assert_eq!(power_heuristic(1.0, f32::INFINITY, 1.0, 5.0), 1.0);
        assert_eq!(power_heuristic(1.0, 5.0, 1.0, f32::INFINITY), 0.0);
        assert_eq!(power_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
        let w = power_heuristic(1.0, 1e30, 1.0, 1e29);
        assert!((w - 100.0 / 101.0).abs() < 1e-5 && w.is_finite());
        let sum = power_heuristic(1.0, 0.3, 2.0, 0.7) + power_heuristic(2.0, 0.7, 1.0, 0.3);
        assert!((sum - 1.0).abs() < 1e-6);
    }

    #[test]
    fn discrete_distribution_rejects_bad_weights() {
        assert!(DiscreteDistribution::new(&[]).is_none());
        assert!(DiscreteDistribution::new(&[0.0, 0.0]).is_none());
        assert!(DiscreteDistribution::new(&[1.0, -1.0]).is_none());
        assert!(DiscreteDistribution::new(&[1.0, f32::NAN]).is_none());
        assert!(DiscreteDistribution::new(&[1.0, f32::INFINITY]).is_none());
    }

    #[test]
    fn discrete_distribution_samples_its_pmf() {
        let w = [0.0, 1.0, 3.0, 0.0, 6.0, 0.0];
        let d = DiscreteDistribution::new(&w).unwrap();
        assert_eq!(d.len(), 6);
        assert!(!d.is_empty());
        assert_eq!(d.pmf(2), 0.3);
        assert_eq!(d.pmf(17), 0.0);
        let n = 100_000;
        let mut counts = [0usize; 6];
        let mut rng = Pcg32::new(7, 1);
        for _ in 0..n {
            let (i, p, r) = d.sample_reuse(rng.next_f32());
            assert_eq!(p, d.pmf(i));
            assert!((0.0..1.0).contains(&r));
            counts[i] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let expect = d.pmf(i) as f64 * n as f64;
            let sigma = (expect * (1.0 - d.pmf(i) as f64)).sqrt().max(1.0);
            assert!(
                (c as f64 - expect).abs() < 5.0 * sigma,
                "index {i}: {c} vs {expect}"
            );
        }
        // Edge values of u never pick a zero weight.
        for u in [0.0, 1e-9, 0.1, 0.1 + 1e-8, 0.4, ONE_MINUS_EPSILON, 1.0] {
            let (i, p) = d.sample(u);
            assert!(p > 0.0 && w[i] > 0.0, "u = {u} picked {i}");
        }
    }

    #[test]
    fn sampler_is_deterministic_and_in_range() {
        let mut a = Sampler::new(42);
        let mut b = Sampler::new(42);
        let mut c = Sampler::new(43);
        let mut differs = false;
        for s in [
            0u32,
            1,
            77,
            SOBOL_MAX_SAMPLES - 1,
            SOBOL_MAX_SAMPLES,
            1 << 20,
        ] {
            a.start_pixel_sample((3, 5), s);
            b.start_pixel_sample((3, 5), s);
            c.start_pixel_sample((3, 5), s);
            for _ in 0..300 {
                let (x, y) = (a.next_1d(), b.next_1d());
                assert_eq!(x, y);
                assert!((0.0..1.0).contains(&x));
                let (p, q) = (a.next_2d(), b.next_2d());
                assert_eq!(p, q);
                assert!(p.min_element() >= 0.0 && p.max_element() < 1.0);
                differs |= c.next_1d() != x;
                c.next_2d();
            }
        }
        assert!(differs, "the seed changes nothing");
    }

    #[test]
    fn sampler_decorrelates_pixels_and_dimensions() {
        let mut s = Sampler::new(1);
        s.start_pixel_sample((0, 0), 3);
        let a = (s.next_2d(), s.next_2d());
        s.start_pixel_sample((1, 0), 3);
        let b = (s.next_2d(), s.next_2d());
        assert_ne!(a.0, b.0);
        assert_ne!(a.0, a.1);
    }

    #[test]
    fn sampler_2d_is_stratified() {
        // Each of the 16 cells of a 4x4 grid gets exactly one of the first 16 points, in every
        // dimension slot and pixel; 64 points fill an 8x8 grid the same way.
        let mut s = Sampler::new(9);
        for pixel in [(0, 0), (17, 3), (640, 480)] {
            for slot in 0..6 {
                for (n, k) in [(16u32, 4usize), (64, 8)] {
                    let mut hit = vec![0u32; k * k];
                    for i in 0..n {
                        s.start_pixel_sample(pixel, i);
                        for _ in 0..slot {
                            s.next_2d();
                        }
                        let p = s.next_2d();
                        let cell = (p.x * k as f32) as usize * k + (p.y * k as f32) as usize;
                        hit[cell] += 1;
                    }
                    assert!(
                        hit.iter().all(|&h| h == 1),
                        "pixel {pixel:?} slot {slot}: {hit:?}"
                    );
                }
            }
        }
        // 1D: the first 16 values fall one in each sixteenth.
        let mut hit = [0u32; 16];
        for i in 0..16 {
            s.start_pixel_sample((2, 2), i);
            hit[(s.next_1d() * 16.0) as usize] += 1;
        }
        assert!(hit.iter().all(|&h| h == 1), "{hit:?}");
    }

    #[test]
    fn sampler_2d_matches_two_scalar_sobol_dimensions() {
        // next_2d uses sobol_burley::sample_4d for speed; it must give the scalar values.
        let mut s = Sampler::new(5);
        for i in 0..64 {
            s.start_pixel_sample((3, 9), i);
            let seed = {
                let mut probe = s.clone();
                probe.next_slot_seed()
            };
            let v = s.next_2d();
            assert_eq!(v.x, sobol_burley::sample(i, 0, seed));
            assert_eq!(v.y, sobol_burley::sample(i, 1, seed));
        }
    }

    #[test]
    fn sampler_4d_is_four_sobol_dimensions_of_one_slot() {
        // next_4d reads dimensions 0..4 of one slot: the first two are the same (0,2)-sequence
        // as next_2d, each of the last two is stratified in 1D, and a slot is consumed.
        let mut s = Sampler::new(11);
        let (mut hit_xy, mut hit_z, mut hit_w) = ([0u32; 16], [0u32; 16], [0u32; 16]);
        for i in 0..16 {
            s.start_pixel_sample((7, 1), i);
            s.next_2d();
            let seed = {
                let mut probe = s.clone();
                probe.next_slot_seed()
            };
            let v = s.next_4d();
            for (d, x) in v.iter().enumerate() {
                assert_eq!(*x, sobol_burley::sample(i, d as u32, seed));
                assert!((0.0..1.0).contains(x));
            }
            hit_xy[(v[0] * 4.0) as usize * 4 + (v[1] * 4.0) as usize] += 1;
            hit_z[(v[2] * 16.0) as usize] += 1;
            hit_w[(v[3] * 16.0) as usize] += 1;
            // The next slot is a different one.
            assert_ne!(s.clone().next_4d(), v);
        }
        for hit in [hit_xy, hit_z, hit_w] {
            assert!(hit.iter().all(|&h| h == 1), "{hit:?}");
        }
        // Past sobol_burley's limit: hashed values, still in range and deterministic.
        s.start_pixel_sample((7, 1), SOBOL_MAX_SAMPLES + 3);
        let a = s.next_4d();
        s.start_pixel_sample((7, 1), SOBOL_MAX_SAMPLES + 3);
        assert_eq!(a, s.next_4d());
        assert!(a.iter().all(|x| (0.0..1.0).contains(x)));
    }
}
