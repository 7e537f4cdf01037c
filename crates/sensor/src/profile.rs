//! [`SensorProfile`]: the camera's numbers (shutter, aperture, lens, pixel, noise, ADC, tone
//! curve), read from TOML with a documented default for every field, and the embedded presets.
//!
//! A profile file names only the fields it changes; unknown fields are errors (a typo must not
//! silently fall back to a default). [`SensorProfile::resolve`] takes what `--sensor` takes: a
//! preset name ([`PRESETS`]) or the path of a TOML file (a name containing a path separator or
//! ending in `.toml` is a file).

use crate::error::SensorError;
use serde::Deserialize;
use std::path::Path;

/// Largest accepted profile file (a profile is a few hundred bytes).
const MAX_PROFILE_BYTES: u64 = 1 << 20;

/// The embedded presets: name and TOML text (`crates/sensor/presets/*.toml`, each documented
/// with its sources in its comments).
pub const PRESETS: [(&str, &str); 3] = [
    (
        "automotive_hdr",
        include_str!("../presets/automotive_hdr.toml"),
    ),
    (
        "automotive_linear",
        include_str!("../presets/automotive_linear.toml"),
    ),
    ("ideal", include_str!("../presets/ideal.toml")),
];

/// A camera: lens, sensor and the tone curve of its developed images. Units are in the field
/// names; every field has the default given in its documentation (the `automotive_linear`
/// preset's numbers, except where noted), so a profile may name only some.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorProfile {
    /// Shutter (integration) time in seconds [default 0.01]; also the renderer's shutter
    /// interval when motion blur is rendered.
    pub exposure_s: f64,
    /// The lens's f-number N (focal length / entrance pupil diameter) [default 1.8].
    pub f_number: f64,
    /// The lens's on-axis transmission, 0 < tau <= 1 [default 0.9].
    pub transmission: f64,
    /// Share of the light reaching the sensor that the lens scatters into a wide veil (veiling
    /// glare), 0 <= V < 1 [default 0.03; real lenses 1-5 %].
    pub veil: f64,
    /// Core radius r0 of the veil kernel `r0 / (2 pi (r^2 + r0^2)^1.5)`, in pixels
    /// [default 4].
    pub veil_core_px: f64,
    /// Whether the PSF has the aperture's diffraction (Airy) core [default true]; without it,
    /// the part `1 - veil` of the light stays in its pixel.
    pub diffraction: bool,
    /// Radius of the PSF kernel in pixels, 1..=1024 [default 160]: light the PSF would spread
    /// farther is kept in the kernel by its normalisation.
    pub psf_radius_px: u32,
    /// Wavelengths in nanometres of the R, G and B channels for diffraction
    /// [default 610, 550, 465].
    pub wavelengths_nm: [f64; 3],
    /// Strength of the natural vignetting, 0..=1: the irradiance falls as
    /// `1 - s (1 - cos^4 theta)` with the field angle theta (1 = the natural cos^4, 0 = none)
    /// [default 1].
    pub vignetting: f64,
    /// Pixel pitch in micrometres (square pixels, fill factor 1 with microlenses)
    /// [default 3.75].
    pub pixel_pitch_um: f64,
    /// Quantum efficiency at 555 nm, electrons per photon, 0 < eta <= 1 [default 0.6].
    pub quantum_efficiency: f64,
    /// Whether the photo-electrons and dark electrons are Poisson-distributed (photon shot
    /// noise) [default true]; false gives their mean, for tests and the `ideal` preset.
    pub shot_noise: bool,
    /// Dark current in electrons per second per pixel [default 25].
    pub dark_current_e_per_s: f64,
    /// Full-well capacity in electrons: the photo-electrons a pixel holds before it saturates
    /// [default 11700].
    pub full_well_e: f64,
    /// Temporal read noise (dark noise) in electrons rms, Gaussian [default 4.8].
    pub read_noise_e: f64,
    /// Conversion gain in electrons per DN (EMVA 1288's 1/K) [default 3].
    pub gain_e_per_dn: f64,
    /// Black level (pedestal) in DN added to every pixel, below the white level
    /// [default 168].
    pub black_level_dn: f64,
    /// Bits of the ADC, 8..=24: DN are clipped to `0..=2^bit_depth - 1` [default 12].
    pub bit_depth: u32,
    /// Digital gain of the developed image in stops [default 5]: the tone curve maps
    /// `(DN - black) / (white - black) * 2^develop_ev` (see [`crate::develop`]).
    pub develop_ev: f64,
}

impl Default for SensorProfile {
    fn default() -> Self {
        Self {
            exposure_s: 0.01,
            f_number: 1.8,
            transmission: 0.9,
            veil: 0.03,
            veil_core_px: 4.0,
            diffraction: true,
            psf_radius_px: 160,
            wavelengths_nm: [610.0, 550.0, 465.0],
            vignetting: 1.0,
            pixel_pitch_um: 3.75,
            quantum_efficiency: 0.6,
            shot_noise: true,
            dark_current_e_per_s: 25.0,
            full_well_e: 11_700.0,
            read_noise_e: 4.8,
            gain_e_per_dn: 3.0,
            black_level_dn: 168.0,
            bit_depth: 12,
            develop_ev: 5.0,
        }
    }
}

impl SensorProfile {
    /// The largest DN the ADC gives, `2^bit_depth - 1`.
    pub fn white_dn(&self) -> f64 {
        f64::from((1u32 << self.bit_depth.min(24)) - 1)
    }

    /// Reads a profile from TOML text; `source` names it in errors (the file or the preset).
    pub fn from_toml(text: &str, source: &str) -> Result<Self, SensorError> {
        let profile: Self = toml::from_str(text).map_err(|e| {
            // The parser names unknown fields but not the field of a mistyped value: quote
            // the line.
            let message = match e.span() {
                Some(span) => {
                    let line = text[..span.start.min(text.len())].matches('\n').count();
                    let quoted = text.lines().nth(line).unwrap_or("").trim();
                    format!("line {} `{quoted}`: {}", line + 1, e.message())
                }
                None => e.message().to_string(),
            };
            SensorError::Parse {
                source_name: source.to_string(),
                message,
            }
        })?;
        profile.check(source)?;
        Ok(profile)
    }

    /// Reads a profile file.
    pub fn load(path: &Path) -> Result<Self, SensorError> {
        let text = streaks_image::input::read_text(path, MAX_PROFILE_BYTES).map_err(|source| {
            SensorError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// The embedded preset `name`.
    pub fn preset(name: &str) -> Result<Self, SensorError> {
        let (_, text) =
            PRESETS
                .iter()
                .find(|(n, _)| *n == name)
                .ok_or_else(|| SensorError::UnknownPreset {
                    name: name.to_string(),
                    presets: PRESETS.map(|(n, _)| n).join(", "),
                })?;
        Self::from_toml(text, &format!("preset {name}"))
    }

    /// What `--sensor` takes: the path of a TOML file when `arg` contains a path separator or
    /// ends in `.toml`, else a preset name.
    pub fn resolve(arg: &str) -> Result<Self, SensorError> {
        let is_path = arg.contains('/')
            || arg.contains(std::path::MAIN_SEPARATOR)
            || arg.to_ascii_lowercase().ends_with(".toml");
        if is_path {
            Self::load(Path::new(arg))
        } else {
            Self::preset(arg)
        }
    }

    /// Checks every field's range; the error names `source` and the field.
    pub fn check(&self, source: &str) -> Result<(), SensorError> {
        let bad = |field: &'static str, reason: String| {
            Err(SensorError::Field {
                source_name: source.to_string(),
                field,
                reason,
            })
        };
        let positive = [
            ("exposure_s", self.exposure_s),
            ("f_number", self.f_number),
            ("veil_core_px", self.veil_core_px),
            ("pixel_pitch_um", self.pixel_pitch_um),
            ("full_well_e", self.full_well_e),
            ("gain_e_per_dn", self.gain_e_per_dn),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, format!("must be a positive number, got {v}"));
            }
        }
        let non_negative = [
            ("dark_current_e_per_s", self.dark_current_e_per_s),
            ("read_noise_e", self.read_noise_e),
            ("black_level_dn", self.black_level_dn),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("must be zero or more, got {v}"));
            }
        }
        let unit = [
            ("transmission", self.transmission),
            ("quantum_efficiency", self.quantum_efficiency),
        ];
        for (field, v) in unit {
            if !(v > 0.0 && v <= 1.0) {
                return bad(field, format!("must be in (0, 1], got {v}"));
            }
        }
        if !(0.0..1.0).contains(&self.veil) {
            return bad("veil", format!("must be in [0, 1), got {}", self.veil));
        }
        if !(0.0..=1.0).contains(&self.vignetting) {
            return bad(
                "vignetting",
                format!("must be in [0, 1], got {}", self.vignetting),
            );
        }
        if !(1..=1024).contains(&self.psf_radius_px) {
            return bad(
                "psf_radius_px",
                format!("must be 1..=1024, got {}", self.psf_radius_px),
            );
        }
        if let Some(w) = self
            .wavelengths_nm
            .iter()
            .find(|w| !(w.is_finite() && **w > 0.0))
        {
            return bad(
                "wavelengths_nm",
                format!("must be positive numbers, got {w}"),
            );
        }
        if !(8..=24).contains(&self.bit_depth) {
            return bad(
                "bit_depth",
                format!("must be 8..=24, got {}", self.bit_depth),
            );
        }
        if self.black_level_dn >= self.white_dn() {
            return bad(
                "black_level_dn",
                format!(
                    "{} must be below the white level 2^bit_depth - 1 = {}",
                    self.black_level_dn,
                    self.white_dn()
                ),
            );
        }
        if !self.develop_ev.is_finite() {
            return bad(
                "develop_ev",
                format!("must be a finite number of stops, got {}", self.develop_ev),
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_load_and_the_default_is_valid() {
        SensorProfile::default().check("default").unwrap();
        for (name, _) in PRESETS {
            SensorProfile::preset(name).unwrap();
            SensorProfile::resolve(name).unwrap();
        }
        let e = SensorProfile::resolve("nope").unwrap_err().to_string();
        assert!(e.contains("automotive_hdr"), "{e}");
    }

    #[test]
    fn a_profile_names_only_some_fields() {
        let p = SensorProfile::from_toml("f_number = 2.8\nbit_depth = 10", "t").unwrap();
        assert_eq!(p.f_number, 2.8);
        assert_eq!(p.bit_depth, 10);
        assert_eq!(p.read_noise_e, SensorProfile::default().read_noise_e);
        assert_eq!(
            SensorProfile::from_toml("", "t").unwrap(),
            Default::default()
        );
    }

    #[test]
    fn errors_name_the_source_and_the_field() {
        let cases = [
            ("read_noise_e = -1", "read_noise_e"),
            ("bit_depth = 25", "bit_depth"),
            ("bit_depth = 7", "bit_depth"),
            ("bit_depth = 8\nblack_level_dn = 255", "black_level_dn"),
            ("gain_e_per_dn = 0", "gain_e_per_dn"),
            ("full_well_e = nan", "full_well_e"),
            ("veil = 1.0", "veil"),
            ("quantum_efficiency = 1.5", "quantum_efficiency"),
            ("gain = 2", "gain"),
            ("exposure_s = \"fast\"", "exposure_s"),
        ];
        for (text, field) in cases {
            let e = SensorProfile::from_toml(text, "cam.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains("cam.toml") && e.contains(field), "{text}: {e}");
        }
    }

    #[test]
    fn files_and_paths() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cam.toml");
        std::fs::write(&path, "exposure_s = 0.02\n").unwrap();
        let p = SensorProfile::resolve(path.to_str().unwrap()).unwrap();
        assert_eq!(p.exposure_s, 0.02);
        let missing = dir.path().join("missing.toml");
        let e = SensorProfile::resolve(missing.to_str().unwrap()).unwrap_err();
        assert!(e.to_string().contains("missing.toml"), "{e}");
    }
}
