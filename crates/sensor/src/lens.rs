//! The lens between the scene and the sensor: the point spread function (diffraction at the
//! aperture and a scattering veil) and natural vignetting.
//!
//! **PSF.** Per channel, `PSF = (1 - V) Airy + V Veil`, normalised to sum 1 over the kernel
//! (energy conserving: the light a lamp sends into the camera is moved, not made or lost):
//!
//! - `Airy`: the diffraction pattern of a circular aperture in the focal plane, intensity per
//!   unit area `p(r) = pi / (4 lambda^2 N^2) [2 J1(v) / v]^2` with `v = pi r / (lambda N)`
//!   (unit integral over the plane; first zero at `r = 1.22 lambda N`), integrated over each
//!   pixel's square (16 x 16 points within 6 pixels of the centre; farther out the rings are
//!   finer than a pixel and their mean `pi / (4 lambda^2 N^2) 4 / (pi v^3)` is integrated on
//!   4 x 4 points). The wavelength is the channel's ([`SensorProfile::wavelengths_nm`]).
//! - `Veil`: the light the lens scatters (veiling glare, share [`SensorProfile::veil`]), the
//!   long-tailed kernel `r0 / (2 pi (r^2 + r0^2)^(3/2))` (r and r0 =
//!   [`SensorProfile::veil_core_px`] in pixels; unit integral over the plane, falling as
//!   `1/r^3`, so a lamp gets a bright halo a few `r0` wide and a faint glare to the kernel's
//!   edge), integrated over each pixel on 4 x 4 points.
//!
//! The kernel is square, `2 R + 1` pixels wide (`R` = [`SensorProfile::psf_radius_px`]); the
//! light either part would spread beyond it (for the Airy part about `2 / (pi v_R)`, for the
//! veil `r0 / R`) is kept in the kernel by the normalisation.
//!
//! **Convolution** by FFT (rustfft) on each channel zero-padded to at least
//! `width + R` by `height + R` (sizes of the form 2^a 3^b 5^c), so that nothing wraps round.
//! **Edges**: the image is zero outside the frame, so the light the PSF spreads out of the
//! frame is lost and lamps outside the frame send no glare into it (as no render of them
//! exists); the image's total is kept exactly for light farther than `R` from every edge.
//!
//! **Vignetting**: the irradiance at a pixel whose centre is at field angle `theta` is the
//! on-axis one times `1 - s (1 - cos^4 theta)`, `cos theta = f / sqrt(f^2 + dx^2 + dy^2)`
//! (`f` the focal length in pixels, `dx, dy` from the image centre), `s` =
//! [`SensorProfile::vignetting`] (1: the natural cos^4 law of a thin lens).

use crate::SensorProfile;
use rayon::prelude::*;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use std::f64::consts::PI;

/// Pixels within this distance (in pixels) of the kernel centre integrate the exact Airy
/// pattern; farther ones its ring-averaged envelope.
const AIRY_EXACT_PX: f64 = 6.0;

/// The Bessel function of the first kind of order 1, `J1(x)` (Numerical Recipes' rational
/// approximations; absolute error below 1e-7).
pub fn bessel_j1(x: f64) -> f64 {
    let ax = x.abs();
    if ax < 8.0 {
        let y = x * x;
        let a = x
            * (72_362_614_232.0
                + y * (-7_895_059_235.0
                    + y * (242_396_853.1
                        + y * (-2_972_611.439 + y * (15_704.482_60 + y * (-30.160_366_06))))));
        let b = 144_725_228_442.0
            + y * (2_300_535_178.0
                + y * (18_583_304.74 + y * (99_447.433_94 + y * (376.999_139_7 + y))));
        a / b
    } else {
        let z = 8.0 / ax;
        let y = z * z;
        let xx = ax - 3.0 * std::f64::consts::FRAC_PI_4;
        let a = 1.0
            + y * (0.183_105e-2
                + y * (-0.351_639_649_6e-4 + y * (0.245_752_017_4e-5 + y * (-0.240_337_019e-6))));
        let b = 0.046_874_999_95
            + y * (-0.200_269_087_3e-3
                + y * (0.844_919_909_6e-5 + y * (-0.882_289_87e-6 + y * 0.105_787_412e-6)));
        let ans = (std::f64::consts::FRAC_2_PI / ax).sqrt() * (xx.cos() * a - z * xx.sin() * b);
        if x < 0.0 {
            -ans
        } else {
            ans
        }
    }
}

/// The Airy pattern's intensity per unit area at distance `r` from its centre, for wavelength
/// `lambda` and f-number `n` (`r` and `lambda` in one unit; the result per that unit
/// squared), with unit integral over the plane.
pub fn airy_density(r: f64, lambda: f64, n: f64) -> f64 {
    let peak = PI / (4.0 * lambda * lambda * n * n);
    let v = PI * r / (lambda * n);
    if v < 1e-6 {
        return peak;
    }
    let a = 2.0 * bessel_j1(v) / v;
    peak * a * a
}

/// [`airy_density`] averaged over its rings (the far field, `v >> 1`).
fn airy_envelope(r: f64, lambda: f64, n: f64) -> f64 {
    let v = PI * r / (lambda * n);
    PI / (4.0 * lambda * lambda * n * n) * 4.0 / (PI * v * v * v)
}

/// The veil kernel per unit area (pixels) at `r` pixels: `r0 / (2 pi (r^2 + r0^2)^1.5)`.
pub fn veil_density(r: f64, r0: f64) -> f64 {
    r0 / (2.0 * PI * (r * r + r0 * r0).powf(1.5))
}

/// The mean of `f(x, y)` over the pixel square centred at `(cx, cy)` on `n x n` points.
fn pixel_mean(cx: f64, cy: f64, n: u32, f: impl Fn(f64, f64) -> f64) -> f64 {
    let step = 1.0 / f64::from(n);
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let x = cx - 0.5 + (f64::from(i) + 0.5) * step;
            let y = cy - 0.5 + (f64::from(j) + 0.5) * step;
            sum += f(x, y);
        }
    }
    sum / f64::from(n * n)
}

/// The Airy pattern integrated over each pixel of a `(2 radius + 1)^2` kernel (row-major,
/// centre at `(radius, radius)`), pixel pitch and wavelength in micrometres; not normalised
/// (it sums to the share of the pattern's light inside the kernel).
pub fn airy_kernel(radius: u32, pitch_um: f64, lambda_um: f64, f_number: f64) -> Vec<f64> {
    kernel(radius, |dx, dy| {
        let rc = (dx * dx + dy * dy).sqrt();
        let area = pitch_um * pitch_um;
        if rc <= AIRY_EXACT_PX {
            area * pixel_mean(dx, dy, 16, |x, y| {
                airy_density((x * x + y * y).sqrt() * pitch_um, lambda_um, f_number)
            })
        } else {
            area * pixel_mean(dx, dy, 4, |x, y| {
                airy_envelope((x * x + y * y).sqrt() * pitch_um, lambda_um, f_number)
            })
        }
    })
}

/// The veil kernel ([`veil_density`]) integrated over each pixel of a `(2 radius + 1)^2`
/// kernel; not normalised.
pub fn veil_kernel(radius: u32, r0: f64) -> Vec<f64> {
    kernel(radius, |dx, dy| {
        pixel_mean(dx, dy, 4, |x, y| veil_density((x * x + y * y).sqrt(), r0))
    })
}

/// A `(2 radius + 1)^2` kernel of `f(dx, dy)` (pixel offsets from the centre), row-major.
fn kernel(radius: u32, f: impl Fn(f64, f64) -> f64 + Sync) -> Vec<f64> {
    let side = 2 * radius as usize + 1;
    let r = f64::from(radius);
    (0..side * side)
        .into_par_iter()
        .map(|i| f((i % side) as f64 - r, (i / side) as f64 - r))
        .collect()
}

/// The PSF of channel `c` (0 = R, 1 = G, 2 = B) of `profile`: `(1 - veil) Airy + veil Veil`
/// (the Airy part a delta without [`SensorProfile::diffraction`]), normalised to sum 1;
/// `(2 R + 1)^2` values, row-major, centre at `(R, R)`.
pub fn psf(profile: &SensorProfile, c: usize) -> Vec<f64> {
    mix(profile, c, veil(profile).as_deref())
}

/// The PSFs of the three channels ([`psf`]), the veil computed once.
pub fn psfs(profile: &SensorProfile) -> [Vec<f64>; 3] {
    let veil = veil(profile);
    std::array::from_fn(|c| mix(profile, c, veil.as_deref()))
}

/// The profile's normalised veil kernel, if it has a veil.
fn veil(profile: &SensorProfile) -> Option<Vec<f64>> {
    (profile.veil > 0.0).then(|| {
        let mut v = veil_kernel(profile.psf_radius_px, profile.veil_core_px);
        normalise(&mut v);
        v
    })
}

/// Channel `c`'s PSF from its Airy part and the normalised `veil` kernel.
fn mix(profile: &SensorProfile, c: usize, veil: Option<&[f64]>) -> Vec<f64> {
    let radius = profile.psf_radius_px;
    let side = 2 * radius as usize + 1;
    let centre = radius as usize * side + radius as usize;
    let mut k = if profile.diffraction {
        let mut a = airy_kernel(
            radius,
            profile.pixel_pitch_um,
            profile.wavelengths_nm[c] * 1e-3,
            profile.f_number,
        );
        normalise(&mut a);
        a
    } else {
        let mut d = vec![0.0; side * side];
        d[centre] = 1.0;
        d
    };
    if let Some(v) = veil {
        for (k, v) in k.iter_mut().zip(v) {
            *k = (1.0 - profile.veil) * *k + profile.veil * v;
        }
    }
    normalise(&mut k);
    k
}

/// Scales `k` to sum 1.
fn normalise(k: &mut [f64]) {
    let sum: f64 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
}

/// Whether the profile's PSF is the identity (no diffraction and no veil).
pub fn psf_is_identity(profile: &SensorProfile) -> bool {
    !profile.diffraction && profile.veil == 0.0
}

/// The smallest `n >= min` of the form `2^a 3^b 5^c` (FFT sizes that are fast).
pub fn fft_size(min: usize) -> usize {
    let mut n = min.max(1);
    loop {
        let mut m = n;
        for p in [2, 3, 5] {
            while m % p == 0 {
                m /= p;
            }
        }
        if m == 1 {
            return n;
        }
        n += 1;
    }
}

/// A 2-D FFT of a row-major `w x h` complex buffer in place (rows, then columns through a
/// transposed copy), forward or inverse (unnormalised, as rustfft).
fn fft2d(buf: &mut [Complex<f32>], w: usize, h: usize, inverse: bool) {
    let mut planner = FftPlanner::<f32>::new();
    let (row, col) = if inverse {
        (planner.plan_fft_inverse(w), planner.plan_fft_inverse(h))
    } else {
        (planner.plan_fft_forward(w), planner.plan_fft_forward(h))
    };
    buf.par_chunks_mut(w).for_each(|r| row.process(r));
    let mut t = transpose(buf, w, h);
    t.par_chunks_mut(h).for_each(|c| col.process(c));
    buf.copy_from_slice(&transpose(&t, h, w));
}

/// The transpose of a row-major `w x h` buffer (`h x w`).
fn transpose(buf: &[Complex<f32>], w: usize, h: usize) -> Vec<Complex<f32>> {
    let mut t = vec![Complex::default(); w * h];
    t.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
        for (y, v) in col.iter_mut().enumerate() {
            *v = buf[y * w + x];
        }
    });
    t
}

/// Convolves the `width x height` row-major `plane` with the `(2 R + 1)^2` `kernel` (centre at
/// `(R, R)`), zero outside the frame (see the module documentation), in place.
pub fn convolve(plane: &mut [f32], width: usize, height: usize, kernel: &[f64], radius: usize) {
    let side = 2 * radius + 1;
    debug_assert_eq!(kernel.len(), side * side);
    debug_assert_eq!(plane.len(), width * height);
    let (pw, ph) = (fft_size(width + radius), fft_size(height + radius));
    let mut img = vec![Complex::<f32>::default(); pw * ph];
    for (y, row) in plane.chunks(width).enumerate() {
        for (x, &v) in row.iter().enumerate() {
            img[y * pw + x].re = v;
        }
    }
    // The kernel with its centre at (0, 0), negative offsets wrapped round.
    let mut ker = vec![Complex::<f32>::default(); pw * ph];
    for j in 0..side {
        for i in 0..side {
            let x = (i + pw - radius) % pw;
            let y = (j + ph - radius) % ph;
            ker[y * pw + x].re = kernel[j * side + i] as f32;
        }
    }
    fft2d(&mut img, pw, ph, false);
    fft2d(&mut ker, pw, ph, false);
    let scale = 1.0 / (pw * ph) as f32;
    img.par_iter_mut()
        .zip(&ker)
        .for_each(|(a, b)| *a = *a * *b * scale);
    fft2d(&mut img, pw, ph, true);
    for (y, row) in plane.chunks_mut(width).enumerate() {
        for (x, v) in row.iter_mut().enumerate() {
            *v = img[y * pw + x].re;
        }
    }
}

/// The vignetting factor `1 - s (1 - cos^4 theta)` of the pixel `(x, y)` of a `width x height`
/// image with focal length `focal_px` pixels (see the module documentation); 1 for an
/// infinite focal length (an orthographic camera).
#[inline]
pub fn vignetting(x: u32, y: u32, width: u32, height: u32, focal_px: f64, strength: f64) -> f64 {
    if strength == 0.0 || focal_px.is_infinite() {
        return 1.0;
    }
    let dx = f64::from(x) + 0.5 - 0.5 * f64::from(width);
    let dy = f64::from(y) + 0.5 - 0.5 * f64::from(height);
    let f2 = focal_px * focal_px;
    let cos2 = f2 / (f2 + dx * dx + dy * dy);
    1.0 - strength * (1.0 - cos2 * cos2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `J1(x) = (1/pi) int_0^pi cos(t - x sin t) dt`, by the midpoint rule.
    fn j1_integral(x: f64) -> f64 {
        let n = 20_000;
        let h = PI / f64::from(n);
        (0..n)
            .map(|i| {
                let t = (f64::from(i) + 0.5) * h;
                (t - x * t.sin()).cos()
            })
            .sum::<f64>()
            * h
            / PI
    }

    #[test]
    fn bessel_j1_matches_its_integral_and_known_values() {
        for x in [
            0.0, 0.3, 1.0, 2.5, 3.8317, 7.9, 8.1, 12.0, 40.0, 200.0, -5.0,
        ] {
            let (a, b) = (bessel_j1(x), j1_integral(x));
            assert!((a - b).abs() < 2e-7, "J1({x}) = {a}, integral {b}");
        }
        assert!((bessel_j1(1.0) - 0.440_050_585_7).abs() < 1e-8);
        // The first zero of J1, 3.8317: the Airy pattern's first dark ring.
        assert!(bessel_j1(3.831_705_97).abs() < 1e-7);
    }

    #[test]
    fn airy_first_zero_at_1_22_lambda_n_and_unit_integral() {
        for (lambda, n) in [(0.55, 1.6), (0.465, 2.8), (0.61, 1.8)] {
            let peak = airy_density(0.0, lambda, n);
            let zero = 3.831_705_97 / PI * lambda * n; // 1.2197 lambda N
            assert!((zero / (lambda * n) - 1.22).abs() < 1e-3);
            assert!(airy_density(zero, lambda, n) < 1e-12 * peak);
            assert!(airy_density(0.9 * zero, lambda, n) > 1e-3 * peak);
            assert!(airy_density(1.1 * zero, lambda, n) > 1e-5 * peak);
            // Encircled energy: int_0^R p 2 pi r dr = 1 - J0(v)^2 - J1(v)^2 -> 1, and within
            // the first dark ring 83.8 %.
            let steps = 200_000;
            let rmax = zero;
            let h = rmax / f64::from(steps);
            let ee: f64 = (0..steps)
                .map(|i| {
                    let r = (f64::from(i) + 0.5) * h;
                    airy_density(r, lambda, n) * 2.0 * PI * r * h
                })
                .sum();
            assert!((ee - 0.838).abs() < 1e-3, "EE at the first zero {ee}");
        }
    }

    #[test]
    fn kernels_hold_the_light_the_formulas_say() {
        // Airy at f/1.6, 550 nm, 3 um pixels, R = 64 px: the share outside radius R is about
        // 2 / (pi v_R) (the square kernel holds a little more: its corners).
        let (radius, pitch, lambda, n) = (64, 3.0, 0.55, 1.6);
        let sum: f64 = airy_kernel(radius, pitch, lambda, n).iter().sum();
        let v_r = PI * f64::from(radius) * pitch / (lambda * n);
        let outside = 2.0 / (PI * v_r);
        assert!(
            sum < 1.0 && sum > 1.0 - outside && sum < 1.0 - 0.5 * outside,
            "{sum}, outside the disc {outside}"
        );
        // The veil: the share inside radius R is 1 - r0 / sqrt(R^2 + r0^2) for the disc.
        let r0 = 4.0;
        let sum: f64 = veil_kernel(radius, r0).iter().sum();
        let disc = 1.0 - r0 / (f64::from(radius).powi(2) + r0 * r0).sqrt();
        assert!(sum > disc && sum < disc + 0.03, "{sum} vs disc {disc}");
    }

    #[test]
    fn psf_sums_to_one_and_conserves_energy() {
        let profile = SensorProfile {
            psf_radius_px: 20,
            ..SensorProfile::default()
        };
        for c in 0..3 {
            let k = psf(&profile, c);
            assert!((k.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(k.iter().all(|&v| v >= 0.0));
            // Symmetric, peaked at the centre.
            let side = 41;
            assert!((k[20 * side + 19] - k[20 * side + 21]).abs() < 1e-15);
            assert!(k[20 * side + 20] > k[20 * side + 21]);
        }
        // Red spreads wider than blue.
        let (r, b) = (psf(&profile, 0), psf(&profile, 2));
        assert!(r[20 * 41 + 20] < b[20 * 41 + 20]);
        // A point light in the middle of a frame keeps its energy; at the edge it loses some.
        let (w, h) = (64, 48);
        let k = psf(&profile, 1);
        let mut plane = vec![0.0f32; w * h];
        plane[24 * w + 32] = 1000.0;
        convolve(&mut plane, w, h, &k, 20);
        let total: f64 = plane.iter().map(|&v| f64::from(v)).sum();
        assert!((total - 1000.0).abs() < 1e-2, "{total}");
        // The convolution is the kernel, placed at the light.
        for (dy, dx) in [(0, 0), (0, 3), (5, -7), (20, 20), (-20, 0)] {
            let got = plane[((24 + dy) * w as i64 + 32 + dx) as usize];
            let want = 1000.0 * k[((20 + dy) * 41 + 20 + dx) as usize] as f32;
            assert!((got - want).abs() < 1e-3 * want.max(1e-2), "{dy},{dx}");
        }
        let mut edge = vec![0.0f32; w * h];
        edge[0] = 1000.0;
        convolve(&mut edge, w, h, &k, 20);
        let total: f32 = edge.iter().sum();
        assert!(total < 990.0 && total > 250.0, "{total}");
        // Nothing wraps round: the far corner stays dark.
        assert!(edge[w * h - 1].abs() < 1e-4);
    }

    #[test]
    fn vignetting_is_cos4_at_a_corner() {
        let (w, h, f) = (640, 480, 400.0);
        let dx = 0.5 - 320.0f64;
        let dy = 0.5 - 240.0f64;
        let cos = f / (f * f + dx * dx + dy * dy).sqrt();
        let v = vignetting(0, 0, w, h, f, 1.0);
        assert!((v - cos.powi(4)).abs() < 1e-12);
        assert!(v < 0.5);
        assert_eq!(vignetting(0, 0, w, h, f, 0.0), 1.0);
        assert!((vignetting(0, 0, w, h, f, 0.5) - (1.0 - 0.5 * (1.0 - v))).abs() < 1e-12);
        assert!((vignetting(319, 239, w, h, f, 1.0) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn fft_sizes() {
        assert_eq!(fft_size(1), 1);
        assert_eq!(fft_size(7), 8);
        assert_eq!(fft_size(1440), 1440);
        assert_eq!(fft_size(1441), 1458);
    }
}
