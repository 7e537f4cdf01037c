//! Statistical tests for sampling code: a chi-square goodness-of-fit harness after Mitsuba 3's
//! `ChiSquareTest` and pbrt-v4's BxDF tests, for warps and BSDFs alike.
//!
//! The test draws `samples` points from a sampling routine, bins them on a regular grid over a
//! rectangle (for directions: `cos(theta)` in `[-1, 1]` times `phi` in `[0, 2 pi)`, cells of
//! equal solid angle), and compares the counts with the counts the routine's claimed density
//! predicts. Expected counts come from integrating the density over each cell with nested
//! adaptive Simpson quadrature (forced to a minimum subdivision so narrow lobes are not
//! stepped over). Failed samples (`None`) are counted in one more cell whose expected count
//! is the mass the density does not cover, so a sampler that loses more (or less) mass than
//! its density admits fails too. Cells with expected counts below `min_expected` are pooled.
//! The p-value comes from the chi-square distribution (`statrs`); the test passes when it is
//! at least the Sidak-corrected significance `1 - (1 - significance)^(1 / num_tests)`.
//!
//! [`check_bsdf`] runs the test on a [`Bsdf`] for one `wo` over the whole sphere of `wi`
//! (transmitted directions below the surface included), and also checks every sample against
//! `eval` and `pdf`: adding a model to the [`Bsdf`] enum is enough for it to apply. A delta
//! lobe's samples (a smooth dielectric's transmission) have no density: they are counted with
//! the failed samples, against the mass the density leaves uncovered, so the probability of
//! choosing the delta lobe is tested too.
//!
//! ```
//! use streaks_render::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
//! use streaks_render::testing::{chi_square_sphere, ChiSquareConfig};
//!
//! let config = ChiSquareConfig { samples: 20_000, ..ChiSquareConfig::default() };
//! let report = chi_square_sphere(
//!     "cosine hemisphere",
//!     &config,
//!     |rng| Some(square_to_cosine_hemisphere(rng.next_2d())),
//!     square_to_cosine_hemisphere_pdf,
//! );
//! assert!(report.passed, "{report}");
//! ```

use crate::bsdf::Bsdf;
use crate::sampling::Pcg32;
use glam::{Vec2, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::TAU;
use std::fmt;

/// Parameters of a chi-square test.
#[derive(Clone, Debug, PartialEq)]
pub struct ChiSquareConfig {
    /// Grid resolution `(nx, ny)`; for directions `nx` cells in `cos(theta)` and `ny` in `phi`.
    pub cells: (usize, usize),
    /// Number of sampling attempts (failed samples included).
    pub samples: usize,
    /// Significance level of the whole family of tests (before the Sidak correction).
    pub significance: f64,
    /// Number of tests in the family, for the Sidak correction.
    pub num_tests: usize,
    /// Seed of the random numbers fed to the sampling routine.
    pub seed: u64,
    /// Cells expecting fewer samples than this are pooled.
    pub min_expected: f64,
    /// Minimum number of bisections per axis in the cell integration.
    pub min_depth: u32,
    /// Maximum number of bisections per axis in the cell integration.
    pub max_depth: u32,
}

impl Default for ChiSquareConfig {
    fn default() -> Self {
        Self {
            cells: (32, 64),
            samples: 100_000,
            significance: 0.01,
            num_tests: 1,
            seed: 0x5eed,
            min_expected: 5.0,
            min_depth: 2,
            max_depth: 14,
        }
    }
}

/// The outcome of one chi-square test.
#[derive(Clone, Debug, PartialEq)]
pub struct ChiSquareReport {
    /// The test's name, as given by the caller.
    pub name: String,
    /// The chi-square statistic.
    pub statistic: f64,
    /// Degrees of freedom (bins after pooling, minus one).
    pub dof: usize,
    /// Probability of a statistic at least this large if the density is right.
    pub p_value: f64,
    /// The Sidak-corrected significance the p-value is compared with.
    pub threshold: f64,
    /// Integral of the density over the whole domain (1 when no mass is lost).
    pub pdf_integral: f64,
    /// Fraction of sampling attempts that returned a point.
    pub sampled_fraction: f64,
    /// Problems found besides the statistic (samples where the density is 0, a density that
    /// integrates to more than 1, disagreement between `sample`, `eval` and `pdf`, ...).
    pub problems: Vec<String>,
    /// Whether the test passed: `p_value >= threshold` and no problems.
    pub passed: bool,
}

impl fmt::Display for ChiSquareReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "chi-square test '{}' {}: statistic {:.2} with {} dof, p = {:.3e} (threshold {:.3e}); \
             pdf integral {:.5}, sampled fraction {:.5}",
            self.name,
            if self.passed { "passed" } else { "FAILED" },
            self.statistic,
            self.dof,
            self.p_value,
            self.threshold,
            self.pdf_integral,
            self.sampled_fraction,
        )?;
        for p in &self.problems {
            write!(f, "\n  - {p}")?;
        }
        Ok(())
    }
}

/// Adaptive Simpson quadrature of `f` over `[a, b]` to absolute tolerance `eps`, bisecting at
/// least `min_depth` and at most `max_depth` times.
pub fn adaptive_simpson(
    f: &mut impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    eps: f64,
    min_depth: u32,
    max_depth: u32,
) -> f64 {
    let fa = f(a);
    let fb = f(b);
    let m = 0.5 * (a + b);
    let fm = f(m);
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    simpson_rec(f, a, b, fa, fm, fb, whole, eps, min_depth, max_depth)
}

#[allow(clippy::too_many_arguments)]
fn simpson_rec(
    f: &mut impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    eps: f64,
    force: u32,
    depth: u32,
) -> f64 {
    let m = 0.5 * (a + b);
    let flm = f(0.5 * (a + m));
    let frm = f(0.5 * (m + b));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if force == 0 && (depth == 0 || delta.abs() <= 15.0 * eps) {
        return left + right + delta / 15.0;
    }
    let force = force.saturating_sub(1);
    let depth = depth.saturating_sub(1);
    simpson_rec(f, a, m, fa, flm, fm, left, 0.5 * eps, force, depth)
        + simpson_rec(f, m, b, fm, frm, fb, right, 0.5 * eps, force, depth)
}

/// Integral of `density` over the rectangle `[x0, x1] x [y0, y1]` (nested adaptive Simpson).
fn integrate_cell(
    density: &impl Fn(f64, f64) -> f64,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    eps: f64,
    config: &ChiSquareConfig,
) -> f64 {
    let inner_eps = eps / (x1 - x0);
    let mut outer = |x: f64| {
        let mut inner = |y: f64| density(x, y);
        adaptive_simpson(
            &mut inner,
            y0,
            y1,
            inner_eps,
            config.min_depth,
            config.max_depth,
        )
    };
    adaptive_simpson(&mut outer, x0, x1, eps, config.min_depth, config.max_depth)
}

/// The chi-square test on a rectangle `x_range x y_range`: `sample` returns a point of the
/// rectangle (or `None` for a failed sample), `density` is its claimed density per unit area.
pub fn chi_square_2d(
    name: &str,
    config: &ChiSquareConfig,
    x_range: (f64, f64),
    y_range: (f64, f64),
    mut sample: impl FnMut(&mut Pcg32) -> Option<(f64, f64)>,
    density: impl Fn(f64, f64) -> f64,
) -> ChiSquareReport {
    let (nx, ny) = config.cells;
    assert!(nx > 0 && ny > 0 && config.samples > 0, "empty test grid");
    let n = config.samples as f64;
    let mut problems = Vec::new();

    // Histogram.
    let mut observed = vec![0u64; nx * ny];
    let mut failed = 0u64;
    let mut outside = 0u64;
    let mut rng = Pcg32::new(config.seed, 0x7e57);
    let (x0, x1) = x_range;
    let (y0, y1) = y_range;
    for _ in 0..config.samples {
        match sample(&mut rng) {
            None => failed += 1,
            Some((x, y)) => {
                let fx = (x - x0) / (x1 - x0) * nx as f64;
                let fy = (y - y0) / (y1 - y0) * ny as f64;
                if !(fx > -1e-6 && fx < nx as f64 + 1e-6 && fy > -1e-6 && fy < ny as f64 + 1e-6) {
                    outside += 1;
                    continue;
                }
                let ix = (fx.max(0.0) as usize).min(nx - 1);
                let iy = (fy.max(0.0) as usize).min(ny - 1);
                observed[ix * ny + iy] += 1;
            }
        }
    }
    if outside > 0 {
        problems.push(format!("{outside} samples outside the domain"));
    }

    // Expected counts: integrate the density over each cell to about 0.02 samples.
    let eps = 0.02 / n;
    let dx = (x1 - x0) / nx as f64;
    let dy = (y1 - y0) / ny as f64;
    let mut integrals = vec![0.0f64; nx * ny];
    for ix in 0..nx {
        for iy in 0..ny {
            let xr = (x0 + ix as f64 * dx, x0 + (ix + 1) as f64 * dx);
            let yr = (y0 + iy as f64 * dy, y0 + (iy + 1) as f64 * dy);
            integrals[ix * ny + iy] = integrate_cell(&density, xr, yr, eps, config);
        }
    }
    let pdf_integral: f64 = integrals.iter().sum();
    if pdf_integral > 1.0 + 1e-3 {
        problems.push(format!("the density integrates to {pdf_integral} > 1"));
    }

    // Cells: the grid plus one cell for failed samples.
    let mut cells: Vec<(f64, u64, usize)> = integrals
        .iter()
        .zip(&observed)
        .enumerate()
        .map(|(i, (&p, &o))| (p * n, o, i))
        .collect();
    cells.push(((1.0 - pdf_integral).max(0.0) * n, failed, usize::MAX));
    for &(e, o, i) in &cells {
        if o > 0 && e < 1e-6 {
            let what = if i == usize::MAX {
                "failed samples".to_owned()
            } else {
                format!("cell ({}, {})", i / ny, i % ny)
            };
            problems.push(format!(
                "{o} samples in {what}, where the density predicts {e:.2e}"
            ));
        }
    }

    // Pool small cells, then the statistic.
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut bins: Vec<(f64, u64)> = Vec::new();
    let mut pool = (0.0f64, 0u64);
    for &(e, o, _) in &cells {
        if e < config.min_expected {
            pool.0 += e;
            pool.1 += o;
        } else {
            bins.push((e, o));
        }
    }
    if pool.0 >= config.min_expected || bins.is_empty() {
        bins.push(pool);
    } else if let Some(first) = bins.first_mut() {
        first.0 += pool.0;
        first.1 += pool.1;
    }
    let statistic: f64 = bins
        .iter()
        .filter(|(e, _)| *e > 0.0)
        .map(|&(e, o)| (o as f64 - e).powi(2) / e)
        .sum();
    let dof = bins.len().saturating_sub(1);
    let p_value = if dof == 0 {
        problems.push("fewer than two bins after pooling: more samples or cells needed".into());
        0.0
    } else {
        match ChiSquared::new(dof as f64) {
            Ok(d) => d.sf(statistic),
            Err(e) => {
                problems.push(format!("chi-square distribution: {e}"));
                0.0
            }
        }
    };
    let threshold = 1.0 - (1.0 - config.significance).powf(1.0 / config.num_tests.max(1) as f64);
    let passed = p_value >= threshold && problems.is_empty();
    ChiSquareReport {
        name: name.to_owned(),
        statistic,
        dof,
        p_value,
        threshold,
        pdf_integral,
        sampled_fraction: (config.samples as u64 - failed) as f64 / n,
        problems,
        passed,
    }
}

/// `(cos theta, phi)` of a direction, `phi` in `[0, 2 pi)`.
#[inline]
fn sphere_coords(v: Vec3) -> (f64, f64) {
    let v = v.as_dvec3();
    let phi = v.y.atan2(v.x);
    (v.z, if phi < 0.0 { phi + TAU } else { phi })
}

/// The direction with `cos(theta) = z` and azimuth `phi`.
#[inline]
fn sphere_direction(z: f64, phi: f64) -> Vec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
}

/// The chi-square test for directions: `sample` returns a unit vector (or `None`), `pdf` its
/// claimed density per unit solid angle. Cells are equal-area: `cos(theta)` times `phi`.
pub fn chi_square_sphere(
    name: &str,
    config: &ChiSquareConfig,
    mut sample: impl FnMut(&mut Pcg32) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
) -> ChiSquareReport {
    chi_square_2d(
        name,
        config,
        (-1.0, 1.0),
        (0.0, TAU),
        |rng| sample(rng).map(sphere_coords),
        |z, phi| f64::from(pdf(sphere_direction(z, phi))),
    )
}

/// Tests a BSDF's sampling for one `wo`: the chi-square test of `sample` against `pdf`, and
/// for every sample, that `sample().f == eval()`, `sample().pdf == pdf()`, the direction is a
/// unit vector above the surface, and all values are finite and positive.
pub fn check_bsdf(name: &str, bsdf: &Bsdf, wo: Vec3, config: &ChiSquareConfig) -> ChiSquareReport {
    const MAX_PROBLEMS: usize = 5;
    let mut problems: Vec<String> = Vec::new();
    let note = |p: String, problems: &mut Vec<String>| {
        if problems.len() < MAX_PROBLEMS {
            problems.push(p);
        }
    };
    let close = |a: f32, b: f32| (a - b).abs() <= 2e-3 * a.abs().max(b.abs()) + 1e-6;
    let mut report = chi_square_sphere(
        name,
        config,
        |rng| {
            let u_lobe = rng.next_f32();
            let u = rng.next_2d();
            let s = bsdf.sample(wo, u_lobe, u)?;
            let (f, pdf) = (bsdf.eval(wo, s.wi), bsdf.pdf(wo, s.wi));
            let side_ok = s.wi.z > 0.0 || (s.wi.z < 0.0 && bsdf.transmits());
            if !(s.pdf.is_finite() && s.pdf > 0.0 && s.f.is_finite() && s.f.min_element() >= 0.0) {
                note(
                    format!("bad sample {s:?} for u = {u_lobe}, {u}"),
                    &mut problems,
                );
            } else if (s.wi.length() - 1.0).abs() > 1e-4 || !side_ok {
                note(
                    format!(
                        "sampled wi {} not a unit vector above the surface (or below it, \
                         for a transmitting BSDF)",
                        s.wi
                    ),
                    &mut problems,
                );
            } else if s.delta {
                // A delta lobe has no density: its samples count with the mass `pdf` does not
                // cover, and `eval` and `pdf` must not see them.
                if f != Vec3::ZERO || pdf != 0.0 || s.pdf > 1.0 {
                    note(
                        format!("delta sample {s:?} but eval() = {f}, pdf() = {pdf}"),
                        &mut problems,
                    );
                }
                return None;
            } else if !close(s.pdf, pdf) {
                note(
                    format!(
                        "sample().pdf = {} but pdf() = {pdf} at wi = {}",
                        s.pdf, s.wi
                    ),
                    &mut problems,
                );
            } else if !(close(s.f.x, f.x) && close(s.f.y, f.y) && close(s.f.z, f.z)) {
                note(
                    format!("sample().f = {} but eval() = {f} at wi = {}", s.f, s.wi),
                    &mut problems,
                );
            }
            Some(s.wi)
        },
        |wi| bsdf.pdf(wo, wi),
    );
    if !problems.is_empty() {
        report.passed = false;
        report.problems.extend(problems);
    }
    report
}

/// Convenience for 2D warps: the chi-square test on `[x0, x1] x [y0, y1]` with points as [`Vec2`].
pub fn chi_square_plane(
    name: &str,
    config: &ChiSquareConfig,
    x_range: (f32, f32),
    y_range: (f32, f32),
    mut sample: impl FnMut(&mut Pcg32) -> Option<Vec2>,
    density: impl Fn(Vec2) -> f32,
) -> ChiSquareReport {
    chi_square_2d(
        name,
        config,
        (f64::from(x_range.0), f64::from(x_range.1)),
        (f64::from(y_range.0), f64::from(y_range.1)),
        |rng| sample(rng).map(|p| (f64::from(p.x), f64::from(p.y))),
        |x, y| f64::from(density(Vec2::new(x as f32, y as f32))),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::*;

    #[test]
    fn simpson_integrates_polynomials_and_peaks() {
        let mut cubic = |x: f64| x * x * x;
        assert!((adaptive_simpson(&mut cubic, 0.0, 2.0, 1e-9, 0, 10) - 4.0).abs() < 1e-12);
        let mut peak = |x: f64| (-(x - 0.3) * (x - 0.3) / 1e-4).exp();
        let exact = (std::f64::consts::PI * 1e-4).sqrt();
        let got = adaptive_simpson(&mut peak, 0.0, 1.0, 1e-9, 3, 20);
        assert!((got - exact).abs() < 1e-7, "{got} vs {exact}");
    }

    #[test]
    fn uniform_sphere_passes() {
        let config = ChiSquareConfig::default();
        let r = chi_square_sphere(
            "uniform sphere",
            &config,
            |rng| Some(square_to_uniform_sphere(rng.next_2d())),
            square_to_uniform_sphere_pdf,
        );
        assert!(r.passed, "{r}");
        assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{r}");
    }

    #[test]
    fn wrong_density_fails() {
        // Cosine-weighted samples against the uniform-hemisphere density.
        let config = ChiSquareConfig::default();
        let r = chi_square_sphere(
            "cosine samples, uniform pdf",
            &config,
            |rng| Some(square_to_cosine_hemisphere(rng.next_2d())),
            |v| {
                if v.z > 0.0 {
                    0.5 / std::f32::consts::PI
                } else {
                    0.0
                }
            },
        );
        assert!(!r.passed, "{r}");
        assert!(r.p_value < 1e-10, "{r}");
    }

    #[test]
    fn lost_mass_must_match_failed_samples() {
        // Half the samples fail but the density claims the full hemisphere: must fail.
        let config = ChiSquareConfig::default();
        let r = chi_square_sphere(
            "lost mass not in the pdf",
            &config,
            |rng| {
                let v = square_to_cosine_hemisphere(rng.next_2d());
                (rng.next_f32() < 0.5).then_some(v)
            },
            square_to_cosine_hemisphere_pdf,
        );
        assert!(!r.passed, "{r}");
        // The same with the density halved: passes.
        let r = chi_square_sphere(
            "lost mass in the pdf",
            &config,
            |rng| {
                let v = square_to_cosine_hemisphere(rng.next_2d());
                (rng.next_f32() < 0.5).then_some(v)
            },
            |v| 0.5 * square_to_cosine_hemisphere_pdf(v),
        );
        assert!(r.passed, "{r}");
        assert!((r.pdf_integral - 0.5).abs() < 1e-4, "{r}");
    }
}
