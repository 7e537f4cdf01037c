//! [`capture`]: a linear radiance image through the lens ([`crate::lens`]) and the sensor
//! ([`crate::sensor`]) to raw DN ([`Capture`]).

use crate::lens::{convolve, psf_is_identity, psfs, vignetting};
use crate::sensor::Sensor;
use crate::{SensorError, SensorProfile};
use glam::Vec3;
use rayon::prelude::*;
use streaks_image::RgbImage;

/// A raw capture: DN per pixel and channel, with what developing it needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Capture {
    /// Raw DN (integers in `0..=white_dn`, exact in f32 up to 24 bits), R, G, B.
    pub dn: RgbImage,
    /// The black level in DN.
    pub black_dn: f64,
    /// The white level `2^bit_depth - 1` in DN.
    pub white_dn: f64,
    /// The digital gain of the tone curve in stops.
    pub develop_ev: f64,
}

impl Capture {
    /// The capture developed to 8-bit sRGB ([`crate::develop`]).
    pub fn develop(&self) -> image::RgbImage {
        crate::develop::develop(self)
    }

    /// The capture developed as [`Capture::develop`] does, at 16 bits.
    pub fn develop16(&self) -> image::ImageBuffer<image::Rgb<u16>, Vec<u16>> {
        crate::develop::develop16(self)
    }
}

/// Exposes `radiance` (linear RGB, W/(m^2 sr)) with `profile`: the radiance is scaled by
/// `2^scene_ev` (a correction for scenes whose lights are not at physical scale; 0 for
/// physical scenes), spread by the lens's PSF, vignetted for a focal length of `focal_px`
/// pixels (infinite for an orthographic camera: no vignetting), turned into electrons with noise drawn from `seed` (deterministic for a seed on any
/// number of threads; give each eye of a pair its own) and read out to DN.
pub fn capture(
    profile: &SensorProfile,
    radiance: &RgbImage,
    focal_px: f64,
    scene_ev: f64,
    seed: u64,
) -> Result<Capture, SensorError> {
    // A profile built in code has not been through the TOML reader's checks.
    profile.check("given to capture")?;
    let (w, h) = (radiance.width as usize, radiance.height as usize);
    if w == 0 || h == 0 || radiance.pixels.len() != w * h {
        return Err(SensorError::Image(format!(
            "{} pixels for a {}x{} image",
            radiance.pixels.len(),
            w,
            h
        )));
    }
    if focal_px.is_nan() || focal_px <= 0.0 {
        return Err(SensorError::Image(format!(
            "the focal length must be a positive number of pixels (or infinite), got {focal_px}"
        )));
    }
    if !scene_ev.is_finite() {
        return Err(SensorError::Image(format!(
            "the exposure must be a finite number of stops, got {scene_ev}"
        )));
    }
    let scale = scene_ev.exp2() as f32;
    let mut planes: [Vec<f32>; 3] =
        std::array::from_fn(|c| radiance.pixels.iter().map(|p| p[c] * scale).collect());
    if !psf_is_identity(profile) {
        let radius = profile.psf_radius_px as usize;
        let kernels = psfs(profile);
        for (plane, kernel) in planes.iter_mut().zip(&kernels) {
            // NaN and infinity would spread over the whole frame: no light.
            plane
                .iter_mut()
                .filter(|v| !v.is_finite())
                .for_each(|v| *v = 0.0);
            convolve(plane, w, h, kernel, radius);
        }
    }
    let sensor = Sensor::new(profile);
    let mut dn = vec![Vec3::ZERO; w * h];
    dn.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let mut rng = Sensor::row_rng(seed, y as u32);
        for (x, out) in row.iter_mut().enumerate() {
            let i = y * w + x;
            let v = vignetting(
                x as u32,
                y as u32,
                w as u32,
                h as u32,
                focal_px,
                profile.vignetting,
            );
            for c in 0..3 {
                let mean = sensor.mean_electrons(planes[c][i], v);
                out[c] = sensor.read_out(mean, &mut rng);
            }
        }
    });
    Ok(Capture {
        dn: RgbImage {
            width: radiance.width,
            height: radiance.height,
            pixels: dn,
        },
        black_dn: profile.black_level_dn,
        white_dn: profile.white_dn(),
        develop_ev: profile.develop_ev,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A profile as EMVA 1288 measures a sensor: a flat field on the bare sensor (no PSF, no
    /// vignetting).
    fn bare(name: &str) -> SensorProfile {
        SensorProfile {
            veil: 0.0,
            diffraction: false,
            vignetting: 0.0,
            ..SensorProfile::preset(name).unwrap()
        }
    }

    fn flat(radiance: f64, size: u32) -> RgbImage {
        RgbImage::from_fn(size, size, |_, _| Vec3::splat(radiance as f32))
    }

    /// Mean and temporal variance (from the difference of two frames) of a flat field whose
    /// pixels collect `electrons` mean photo-electrons, frames of seeds `seed` and `seed + 1`.
    fn pair_stats(p: &SensorProfile, electrons: f64, seed: u64) -> (f64, f64) {
        let s = Sensor::new(p);
        let img = flat(electrons / s.electrons_per_radiance, 160);
        let a = capture(p, &img, 1000.0, 0.0, seed).unwrap();
        let b = capture(p, &img, 1000.0, 0.0, seed + 1).unwrap();
        let (mut sum, mut diff2, mut n) = (0.0, 0.0, 0.0);
        for (pa, pb) in a.dn.pixels.iter().zip(&b.dn.pixels) {
            for c in 0..3 {
                let (ya, yb) = (f64::from(pa[c]), f64::from(pb[c]));
                sum += ya + yb;
                diff2 += (ya - yb) * (ya - yb);
                n += 1.0;
            }
        }
        (sum / (2.0 * n), diff2 / (2.0 * n))
    }

    /// The photon-transfer method of EMVA 1288 (linear model): ten flat fields from dark to
    /// 70 % of saturation, two frames each; the slope of the variance over the mean (above
    /// dark) is the system gain K (DN/e-), and the dark variance less the quantisation noise
    /// gives the temporal dark noise, read noise and dark-current shot noise together.
    #[test]
    fn photon_transfer_recovers_gain_and_read_noise() {
        for name in ["automotive_linear", "automotive_hdr"] {
            let p = bare(name);
            let (dark_mean, dark_var) = pair_stats(&p, 0.0, 100);
            let (mut sxy, mut sxx) = (0.0, 0.0);
            for level in 1..=9u32 {
                let electrons = 0.7 * p.full_well_e * f64::from(level) / 9.0;
                let (mean, var) = pair_stats(&p, electrons, 100 + 2 * u64::from(level));
                let (x, y) = (mean - dark_mean, var - dark_var);
                sxy += x * y;
                sxx += x * x;
            }
            let k = sxy / sxx;
            let gain = 1.0 / k;
            let sigma_d = (dark_var - 1.0 / 12.0).sqrt() / k;
            let dark_e = p.dark_current_e_per_s * p.exposure_s;
            let want_sigma_d = (p.read_noise_e.powi(2) + dark_e).sqrt();
            eprintln!(
                "{name}: gain {gain:.4} e-/DN (profile {}), dark noise {sigma_d:.4} e- \
                 (read noise and dark shot noise {want_sigma_d:.4})",
                p.gain_e_per_dn
            );
            assert!(
                (gain / p.gain_e_per_dn - 1.0).abs() < 0.02,
                "{name}: gain {gain} e-/DN, profile {}",
                p.gain_e_per_dn
            );
            assert!(
                (sigma_d / want_sigma_d - 1.0).abs() < 0.05,
                "{name}: dark noise {sigma_d} e-, profile {want_sigma_d}"
            );
            // The dark level is the black level plus the dark current.
            let want = p.black_level_dn + dark_e / p.gain_e_per_dn;
            assert!(
                (dark_mean - want).abs() < 0.05,
                "{name}: {dark_mean} vs {want}"
            );
        }
    }

    #[test]
    fn saturation_at_the_full_well() {
        let p = bare("automotive_linear");
        let fw_dn = p.full_well_e / p.gain_e_per_dn + p.black_level_dn;
        let (mean, var) = pair_stats(&p, 0.7 * p.full_well_e, 1);
        let (sat_mean, sat_var) = pair_stats(&p, 3.0 * p.full_well_e, 3);
        assert!((sat_mean - fw_dn).abs() < 0.05, "{sat_mean} vs {fw_dn}");
        // Past saturation only the read noise is left: the variance collapses.
        let read_var = (p.read_noise_e / p.gain_e_per_dn).powi(2) + 1.0 / 12.0;
        assert!(
            (sat_var / read_var - 1.0).abs() < 0.05,
            "{sat_var} vs {read_var}"
        );
        assert!(var > 10.0 * sat_var && mean < sat_mean);
    }

    #[test]
    fn mean_dn_matches_the_camera_equation() {
        // The ideal camera: exactly round(mean electrons / gain + black).
        let p = SensorProfile::preset("ideal").unwrap();
        let s = Sensor::new(&p);
        let l = 1.0 / 683.0; // 1 cd/m^2
        let raw = capture(&p, &flat(l, 8), 1000.0, 0.0, 0).unwrap();
        let e = s.electrons_per_radiance * l;
        let want = (e / p.gain_e_per_dn + p.black_level_dn).round() as f32;
        assert!(raw.dn.pixels.iter().all(|q| q == &Vec3::splat(want)));
        // pi/4 tau L / N^2 * A t * lambda/(hc) * eta by hand: 75.3 e- for this camera.
        assert!((e - 75.3).abs() < 0.05, "{e}");
        // --exposure: 2^EV on the radiance.
        let raw2 = capture(&p, &flat(l, 8), 1000.0, 2.0, 0).unwrap();
        let want2 = (4.0 * e / p.gain_e_per_dn + p.black_level_dn).round() as f32;
        assert_eq!(raw2.dn.pixels[0], Vec3::splat(want2));
        // A noisy camera: the same mean, within its noise.
        let p = bare("automotive_linear");
        let e = 2000.0;
        let (mean, _) = pair_stats(&p, e, 9);
        let want = (e + p.dark_current_e_per_s * p.exposure_s) / p.gain_e_per_dn + p.black_level_dn;
        assert!((mean - want).abs() < 0.1, "{mean} vs {want}");
    }

    #[test]
    fn vignetting_darkens_the_corners_by_cos4() {
        let p = SensorProfile {
            vignetting: 1.0,
            ..SensorProfile::preset("ideal").unwrap()
        };
        let raw = capture(&p, &flat(10.0, 64), 40.0, 0.0, 0).unwrap();
        let corner = f64::from(raw.dn.get(0, 0).y);
        let centre = f64::from(raw.dn.get(31, 31).y);
        let v = vignetting(0, 0, 64, 64, 40.0, 1.0) / vignetting(31, 31, 64, 64, 40.0, 1.0);
        assert!(
            (corner / centre - v).abs() < 1e-4,
            "{corner} / {centre} vs {v}"
        );
        assert!(v < 0.5);
        // An orthographic camera has no field angle.
        let raw = capture(&p, &flat(10.0, 64), f64::INFINITY, 0.0, 0).unwrap();
        assert_eq!(raw.dn.get(0, 0), raw.dn.get(31, 31));
    }

    #[test]
    fn seeds_give_independent_noise_and_the_same_seed_the_same() {
        let p = SensorProfile::preset("automotive_linear").unwrap();
        let s = Sensor::new(&p);
        let img = flat(500.0 / s.electrons_per_radiance, 96);
        let a = capture(&p, &img, 100.0, 0.0, 5).unwrap();
        let a_again = capture(&p, &img, 100.0, 0.0, 5).unwrap();
        assert_eq!(a, a_again);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        assert_eq!(one.install(|| capture(&p, &img, 100.0, 0.0, 5).unwrap()), a);
        let b = capture(&p, &img, 100.0, 0.0, 6).unwrap();
        // The noise (each frame less the mean of both: the PSF and vignetting are common) of
        // two seeds is uncorrelated.
        let xs: Vec<(f64, f64)> =
            a.dn.pixels
                .iter()
                .zip(&b.dn.pixels)
                .flat_map(|(pa, pb)| (0..3).map(move |c| (f64::from(pa[c]), f64::from(pb[c]))))
                .collect();
        // Noise about each pixel's expectation, which the ideal camera gives.
        let ideal = SensorProfile {
            shot_noise: false,
            read_noise_e: 0.0,
            ..p.clone()
        };
        let m = capture(&ideal, &img, 100.0, 0.0, 0).unwrap();
        let means: Vec<f64> =
            m.dn.pixels
                .iter()
                .flat_map(|q| (0..3).map(move |c| f64::from(q[c])))
                .collect();
        let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
        for ((ya, yb), mu) in xs.iter().zip(&means) {
            let (na, nb) = (ya - mu, yb - mu);
            sab += na * nb;
            saa += na * na;
            sbb += nb * nb;
        }
        let rho = sab / (saa * sbb).sqrt();
        // 27,648 values: the standard error of rho is 0.006.
        assert!(rho.abs() < 0.03, "correlation {rho}");
        assert!(saa > 0.0 && a != b);
    }

    #[test]
    fn bad_images_are_errors() {
        let p = SensorProfile::default();
        let bad = RgbImage {
            width: 3,
            height: 3,
            pixels: vec![Vec3::ZERO; 4],
        };
        assert!(capture(&p, &bad, 100.0, 0.0, 0).is_err());
        assert!(capture(&p, &flat(0.1, 4), 0.0, 0.0, 0).is_err());
        assert!(capture(&p, &flat(0.1, 4), 10.0, f64::NAN, 0).is_err());
        let bad_profile = SensorProfile {
            veil_core_px: 0.0,
            ..p.clone()
        };
        let e = capture(&bad_profile, &flat(0.1, 4), 10.0, 0.0, 0).unwrap_err();
        assert!(e.to_string().contains("veil_core_px"), "{e}");
        // NaN and infinite radiance are no light, not a frame full of NaN.
        let mut img = flat(0.0, 16);
        img.pixels[5] = Vec3::new(f32::NAN, f32::INFINITY, -1.0);
        let raw = capture(&p, &img, 10.0, 0.0, 0).unwrap();
        assert!(raw.dn.pixels.iter().all(|q| q.is_finite()));
    }
}
