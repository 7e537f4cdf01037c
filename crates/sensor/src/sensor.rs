//! The linear image sensor (EMVA 1288's linear model): irradiance to electrons, noise, full
//! well, read-out and the ADC.
//!
//! Per pixel and channel (a colour camera after demosaicing: each channel is a full-resolution
//! plane with the same pixel, quantum efficiency and noise; no Bayer mosaic and no colour
//! matrix), in this order:
//!
//! 1. **Radiance to electrons** (the camera equation of a thin lens, object far away):
//!    `mu_e = eta * A * t * (pi/4) * tau * L * v / N^2 * lambda / (h c)`, with the radiance `L`
//!    in W/(m^2 sr) as the renderer gives it, `v` the vignetting factor
//!    ([`crate::lens::vignetting`]), `A` the pixel area, `t` the exposure, `tau` the lens
//!    transmission, `N` the f-number and `eta` the quantum efficiency. The renderer's watts
//!    are photometric under its 683 lm/W convention (one W/(m^2 sr) is 683 cd/m^2), i.e. light
//!    at 555 nm, so photons are counted at `lambda = 555 nm`: a road of 1 cd/m^2 gives about
//!    68 electrons at f/1.6, 10 ms, 3 um pixels and eta = 0.6.
//! 2. **Dark current**: `mu_d = dark_current_e_per_s * t` electrons.
//! 3. **Shot noise**: `n ~ Poisson(mu_e + mu_d)` (the mean without
//!    [`SensorProfile::shot_noise`]).
//! 4. **Full well**: `n = min(n, full_well_e)`.
//! 5. **Read noise**: `n += N(0, read_noise_e^2)`.
//! 6. **ADC**: `DN = round(n / gain_e_per_dn + black_level_dn)` clipped to
//!    `0..=2^bit_depth - 1`.
//!
//! Noise is drawn from ChaCha8 streams keyed by the caller's seed and the row, so an image is
//! the same for a seed on any number of threads, and two seeds (the two eyes of a pair) give
//! independent noise. Nothing is allocated per pixel.

use crate::SensorProfile;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Poisson, StandardNormal};

/// Planck's constant, J s (exact, SI 2019).
const PLANCK: f64 = 6.626_070_15e-34;
/// The speed of light, m/s (exact).
const LIGHT_SPEED: f64 = 299_792_458.0;
/// The wavelength at which the renderer's photometric watts are counted as photons, m.
pub const PHOTOMETRIC_WAVELENGTH_M: f64 = 555e-9;

/// Mixed into the caller's seed so the sensor's streams differ from any other user of it.
const SEED_DOMAIN: u64 = 0x5e75_0a0c_11d0_e5e1;

/// Above this many standard deviations past the full well, the Poisson draw is the full well.
const SATURATED_SIGMAS: f64 = 10.0;

/// The per-pixel constants of a profile.
#[derive(Clone, Copy, Debug)]
pub struct Sensor {
    /// Mean electrons per W/(m^2 sr) of radiance on the axis (no vignetting).
    pub electrons_per_radiance: f64,
    /// Mean dark electrons in one exposure.
    pub dark_electrons: f64,
    full_well: f64,
    read_noise: f64,
    gain: f64,
    black: f64,
    white: f64,
    shot_noise: bool,
}

impl Sensor {
    /// The constants of `profile` (which is assumed checked: [`SensorProfile::check`]).
    pub fn new(profile: &SensorProfile) -> Self {
        let p = profile;
        let area = (p.pixel_pitch_um * 1e-6).powi(2);
        let photons_per_joule = PHOTOMETRIC_WAVELENGTH_M / (PLANCK * LIGHT_SPEED);
        let irradiance_per_radiance =
            std::f64::consts::FRAC_PI_4 * p.transmission / (p.f_number * p.f_number);
        Self {
            electrons_per_radiance: p.quantum_efficiency
                * area
                * p.exposure_s
                * irradiance_per_radiance
                * photons_per_joule,
            dark_electrons: p.dark_current_e_per_s * p.exposure_s,
            full_well: p.full_well_e,
            read_noise: p.read_noise_e,
            gain: p.gain_e_per_dn,
            black: p.black_level_dn,
            white: p.white_dn(),
            shot_noise: p.shot_noise,
        }
    }

    /// The noise stream of row `row` for `seed`.
    pub fn row_rng(seed: u64, row: u32) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ SEED_DOMAIN);
        rng.set_stream(u64::from(row));
        rng
    }

    /// The mean electrons (photo-electrons and dark) of a pixel with radiance `radiance`
    /// (W/(m^2 sr)) and vignetting factor `vignetting`, before the full well.
    #[inline]
    pub fn mean_electrons(&self, radiance: f32, vignetting: f64) -> f64 {
        let l = f64::from(radiance);
        // Negative (FFT round-off) and NaN radiance is no light.
        let l = if l > 0.0 { l } else { 0.0 };
        self.electrons_per_radiance * l * vignetting + self.dark_electrons
    }

    /// The DN of a pixel whose mean electrons are `mean` (shot noise, full well, read noise,
    /// ADC), drawing from `rng`.
    #[inline]
    pub fn read_out(&self, mean: f64, rng: &mut impl Rng) -> f32 {
        let mut n = if !self.shot_noise {
            mean
        } else if mean <= 0.0 {
            0.0
        } else if mean - SATURATED_SIGMAS * mean.sqrt() > self.full_well {
            self.full_well
        } else {
            // A mean below the full well plus ten sigmas is far below Poisson's limit.
            match Poisson::new(mean) {
                Ok(p) => p.sample(rng),
                Err(_) => mean,
            }
        };
        n = n.min(self.full_well);
        if self.read_noise > 0.0 {
            let z: f64 = rng.sample(StandardNormal);
            n += self.read_noise * z;
        }
        let dn = (n / self.gain + self.black).round();
        dn.clamp(0.0, self.white) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_equation_worked_example() {
        // 1 cd/m^2 at f/1.6, 10 ms, 3 um, eta 0.6, tau 1: about 68 electrons.
        let p = SensorProfile {
            f_number: 1.6,
            exposure_s: 0.01,
            pixel_pitch_um: 3.0,
            quantum_efficiency: 0.6,
            transmission: 1.0,
            ..SensorProfile::default()
        };
        let s = Sensor::new(&p);
        let e = s.electrons_per_radiance / 683.0;
        assert!((e - 67.7).abs() < 0.2, "{e}");
        // By hand: E = pi/4 L / N^2, photons = E A t lambda / (h c).
        let l = 1.0 / 683.0;
        let irradiance = std::f64::consts::PI / 4.0 * l / (1.6 * 1.6);
        let photons = irradiance * 9e-12 * 0.01 * 555e-9 / (6.626_070_15e-34 * 299_792_458.0);
        assert!((e / (0.6 * photons) - 1.0).abs() < 1e-12);
    }

    /// Chi-square of the read-out electrons (gain 1, no read noise, no black level) against
    /// the Poisson pmf, cells with fewer than 5 expected merged, at the 0.001 level.
    #[test]
    fn shot_noise_is_poisson() {
        let p = SensorProfile {
            read_noise_e: 0.0,
            gain_e_per_dn: 1.0,
            black_level_dn: 0.0,
            bit_depth: 24,
            full_well_e: 1e6,
            ..SensorProfile::default()
        };
        let s = Sensor::new(&p);
        // Chi-square 0.999 quantiles for 1..=40 degrees of freedom would need a table; the
        // Wilson-Hilferty approximation is within 1 % of them here.
        let critical = |dof: f64| {
            let z = 3.090_2; // the normal's 0.999 quantile
            dof * (1.0 - 2.0 / (9.0 * dof) + z * (2.0 / (9.0 * dof)).sqrt()).powi(3)
        };
        for (mean, seed) in [(0.7, 1), (3.7, 2), (11.5, 3), (57.0, 4), (400.0, 5)] {
            let n = 200_000;
            let max = (mean + 12.0 * f64::sqrt(mean) + 20.0) as usize;
            let mut counts = vec![0u32; max + 1];
            let mut rng = Sensor::row_rng(seed, 0);
            for _ in 0..n {
                let k = s.read_out(mean, &mut rng) as usize;
                counts[k.min(max)] += 1;
            }
            // Poisson pmf by the recurrence p(k) = p(k-1) mean / k, in logs for large means.
            let pmf = |k: usize| -> f64 {
                let mut log = -mean;
                for i in 1..=k {
                    log += (mean / i as f64).ln();
                }
                log.exp()
            };
            let (mut chi2, mut dof) = (0.0, 0.0);
            let (mut exp_acc, mut obs_acc) = (0.0, 0.0);
            let mut tail = 1.0;
            for (k, &c) in counts.iter().enumerate() {
                let e = if k == max { tail } else { pmf(k) };
                tail -= e;
                exp_acc += e * f64::from(n);
                obs_acc += f64::from(c);
                if exp_acc >= 5.0 || k == max {
                    chi2 += (obs_acc - exp_acc).powi(2) / exp_acc.max(1e-9);
                    dof += 1.0;
                    exp_acc = 0.0;
                    obs_acc = 0.0;
                }
            }
            let dof = dof - 1.0;
            assert!(
                chi2 < critical(dof),
                "mean {mean}: chi2 {chi2} with {dof} dof"
            );
        }
    }

    #[test]
    fn read_out_clips_to_the_full_well_and_the_adc() {
        let p = SensorProfile::default();
        let s = Sensor::new(&p);
        let mut rng = Sensor::row_rng(1, 0);
        // Far above the full well: the full well's DN (with read noise around it).
        let fw_dn = p.full_well_e / p.gain_e_per_dn + p.black_level_dn;
        for _ in 0..100 {
            let dn = f64::from(s.read_out(1e12, &mut rng));
            assert!((dn - fw_dn).abs() < 6.0 * p.read_noise_e / p.gain_e_per_dn + 1.0);
            assert!(dn <= p.white_dn());
        }
        // An ADC narrower than the full well clips at its white level.
        let narrow = SensorProfile {
            gain_e_per_dn: 1.0,
            ..p.clone()
        };
        let s = Sensor::new(&narrow);
        assert_eq!(f64::from(s.read_out(1e12, &mut rng)), narrow.white_dn());
        // No light, no dark current, no read noise: exactly the black level.
        let dark = SensorProfile {
            read_noise_e: 0.0,
            dark_current_e_per_s: 0.0,
            ..p.clone()
        };
        let s = Sensor::new(&dark);
        let m = s.mean_electrons(-1.0, 1.0);
        assert_eq!(m, 0.0);
        assert_eq!(f64::from(s.read_out(m, &mut rng)), p.black_level_dn);
        let m = s.mean_electrons(f32::NAN, 1.0);
        assert_eq!(f64::from(s.read_out(m, &mut rng)), p.black_level_dn);
        // A black level of 0 and read noise: negative values clip at 0 DN.
        let zero = SensorProfile {
            black_level_dn: 0.0,
            ..p.clone()
        };
        let s = Sensor::new(&zero);
        let dns: Vec<f32> = (0..1000).map(|_| s.read_out(0.0, &mut rng)).collect();
        assert!(dns.iter().all(|&d| d >= 0.0));
        assert!(dns.iter().filter(|&&d| d == 0.0).count() > 300);
    }
}
