//! Lamp colours from physics: the spectra of street lamps and headlights, turned into the
//! renderer's linear sRGB at a given luminance.
//!
//! A [`LightSource`] names a lamp technology (low- and high-pressure sodium, LED street lights
//! at 2200 K to 4000 K, halogen, xenon and LED headlights) and its [`Spectrum`]: the sodium
//! D doublet for low-pressure sodium, Planck's law at the correlated colour temperature for the
//! others. [`spectrum_xyz`] integrates a spectrum against the CIE 1931 2-degree colour-matching
//! functions (embedded, 380-780 nm at 5 nm, CIE 015:2018 table 1 as tabulated by CVRL), and
//! [`xyz_to_linear_srgb`] applies the IEC 61966-2-1 matrix.
//!
//! Colours a display cannot show are clipped to the sRGB gamut by setting the negative
//! components to zero (low-pressure sodium's 589 nm line is the one preset outside the gamut:
//! it becomes `(1, 0.22, 0)` at peak 1, a deep orange). Every colour is then scaled to a
//! chosen luminance: [`LightSource::rgb_with_luminance`] returns the linear RGB whose
//! luminance (Rec. 709 weights, `streaks_image::color::luminance`) is the given value, so a
//! lamp's photometric intensity in candela (divided by 683 lm/W) fixes its luminance and the
//! spectrum fixes only the colour. A warm and a cold lamp of the same intensity are then
//! equally bright to the eye.
//!
//! High-pressure sodium is approximated by a blackbody at 2050 K: its real spectrum is a broad,
//! self-reversed sodium band whose chromaticity lies close to the Planckian locus at a CCT of
//! 1900-2200 K (manufacturers quote 2000-2100 K for standard SON-T lamps), so the blackbody
//! gives the colour within a few thousandths in xy, not the spectrum. LED colour
//! temperatures are the nominal CCTs sold for street lighting; halogen headlights (H4/H7) run
//! at about 3200 K, xenon (D-lamp) headlights at about 4300 K, LED headlights at about
//! 5700 K; all are blackbody approximations at those CCTs.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The CIE 1931 2-degree colour-matching functions `[x-bar, y-bar, z-bar]` from
/// [`CMF_START_NM`] in steps of [`CMF_STEP_NM`].
const CMF: [[f64; 3]; 81] = include!("cie1931_2deg.in");
/// Wavelength of the first row of [`CMF`], nm.
const CMF_START_NM: f64 = 380.0;
/// Wavelength step of [`CMF`], nm.
const CMF_STEP_NM: f64 = 5.0;

/// Planck's constant, J s.
const H: f64 = 6.626_070_15e-34;
/// Speed of light, m/s.
const C: f64 = 299_792_458.0;
/// Boltzmann's constant, J/K.
const K_B: f64 = 1.380_649e-23;

/// Spectral radiance of a blackbody at `kelvin` and wavelength `nm` (Planck's law), W/(m^2 sr m).
pub fn planck(nm: f64, kelvin: f64) -> f64 {
    let l = nm * 1e-9;
    2.0 * H * C * C / l.powi(5) / ((H * C / (l * K_B * kelvin)).exp_m1())
}

/// The colour-matching functions at `nm`, linearly interpolated in the 5 nm table (zero
/// outside 380-780 nm).
pub fn cmf(nm: f64) -> [f64; 3] {
    let t = (nm - CMF_START_NM) / CMF_STEP_NM;
    if !(0.0..=(CMF.len() - 1) as f64).contains(&t) {
        return [0.0; 3];
    }
    let i = (t.floor() as usize).min(CMF.len() - 2);
    let f = t - i as f64;
    std::array::from_fn(|c| CMF[i][c] * (1.0 - f) + CMF[i + 1][c] * f)
}

/// A light's spectral power distribution (relative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spectrum {
    /// A blackbody at this temperature, kelvin.
    Blackbody(f64),
    /// Emission lines `(wavelength nm, relative power)`.
    Lines(&'static [(f64, f64)]),
}

/// CIE 1931 XYZ of a spectrum, scaled to `Y = 1`. A blackbody is summed over the table's
/// 5 nm steps (CIE 15's recommended interval); lines read the table interpolated at their
/// wavelengths.
pub fn spectrum_xyz(spectrum: Spectrum) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    match spectrum {
        Spectrum::Blackbody(kelvin) => {
            for (i, row) in CMF.iter().enumerate() {
                let b = planck(CMF_START_NM + CMF_STEP_NM * i as f64, kelvin);
                for c in 0..3 {
                    xyz[c] += row[c] * b;
                }
            }
        }
        Spectrum::Lines(lines) => {
            for &(nm, power) in lines {
                let row = cmf(nm);
                for c in 0..3 {
                    xyz[c] += row[c] * power;
                }
            }
        }
    }
    let y = xyz[1];
    xyz.map(|v| v / y)
}

/// CIE 1931 xy chromaticity of an XYZ colour.
pub fn chromaticity(xyz: [f64; 3]) -> [f64; 2] {
    let s = xyz[0] + xyz[1] + xyz[2];
    [xyz[0] / s, xyz[1] / s]
}

/// XYZ to linear sRGB (IEC 61966-2-1, D65 white), unclipped: components may be negative
/// for colours outside the sRGB gamut.
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = xyz;
    [
        3.240_454_2 * x - 1.537_138_5 * y - 0.498_531_4 * z,
        -0.969_266 * x + 1.876_010_8 * y + 0.041_556 * z,
        0.055_643_4 * x - 0.204_025_9 * y + 1.057_225_2 * z,
    ]
}

/// Luminance of a linear sRGB colour (Rec. 709 weights), in f64.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    f64::from(streaks_image::color::luminance(Vec3::new(
        rgb[0] as f32,
        rgb[1] as f32,
        rgb[2] as f32,
    )))
}

/// The linear sRGB colour of an XYZ colour, clipped to the gamut (negative components set to
/// zero) and scaled to luminance `y`.
pub fn rgb_with_luminance(xyz: [f64; 3], y: f64) -> [f64; 3] {
    let rgb = xyz_to_linear_srgb(xyz).map(|c| c.max(0.0));
    let l = luminance(rgb);
    if l > 0.0 {
        rgb.map(|c| c * y / l)
    } else {
        [0.0; 3]
    }
}

/// Linear sRGB colour, max component 1, of a blackbody at `kelvin` (clamped to 1000-25000 K),
/// from Planck's law and the CIE 1931 colour-matching functions.
pub fn blackbody_rgb(kelvin: f64) -> [f64; 3] {
    peak_one(rgb_with_luminance(
        spectrum_xyz(Spectrum::Blackbody(kelvin.clamp(1000.0, 25000.0))),
        1.0,
    ))
}

/// `rgb` scaled to max component 1 (all zero stays zero).
pub fn peak_one(rgb: [f64; 3]) -> [f64; 3] {
    let peak = rgb[0].max(rgb[1]).max(rgb[2]);
    if peak > 0.0 {
        rgb.map(|c| c / peak)
    } else {
        rgb
    }
}

/// The sodium D doublet: D2 at 588.995 nm and D1 at 589.592 nm, D2 twice as strong (their
/// oscillator strengths are 2:1).
const SODIUM_D: [(f64, f64); 2] = [(588.995, 2.0), (589.592, 1.0)];

/// A lamp technology with a known spectrum. The TOML names are the snake_case ones
/// ([`LightSource::name`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightSource {
    /// Low-pressure sodium (SOX): the sodium D doublet at 589.0/589.6 nm, monochromatic
    /// orange, outside the sRGB gamut.
    LowPressureSodium,
    /// High-pressure sodium (SON): a blackbody at 2050 K.
    HighPressureSodium,
    /// Amber LED street light, 2200 K.
    #[serde(rename = "led_2200k")]
    Led2200K,
    /// Warm LED street light, 2700 K.
    #[serde(rename = "led_2700k")]
    Led2700K,
    /// LED street light, 3000 K.
    #[serde(rename = "led_3000k")]
    Led3000K,
    /// Neutral LED street light, 4000 K.
    #[serde(rename = "led_4000k")]
    Led4000K,
    /// Halogen headlight (H4/H7), 3200 K.
    Halogen,
    /// Xenon (HID, D-lamp) headlight, 4300 K.
    Xenon,
    /// LED headlight, 5700 K.
    LedHeadlight,
}

impl LightSource {
    /// Every source, in declaration order.
    pub const ALL: [LightSource; 9] = [
        LightSource::LowPressureSodium,
        LightSource::HighPressureSodium,
        LightSource::Led2200K,
        LightSource::Led2700K,
        LightSource::Led3000K,
        LightSource::Led4000K,
        LightSource::Halogen,
        LightSource::Xenon,
        LightSource::LedHeadlight,
    ];

    /// The TOML and `meta.json` name.
    pub fn name(self) -> &'static str {
        match self {
            LightSource::LowPressureSodium => "low_pressure_sodium",
            LightSource::HighPressureSodium => "high_pressure_sodium",
            LightSource::Led2200K => "led_2200k",
            LightSource::Led2700K => "led_2700k",
            LightSource::Led3000K => "led_3000k",
            LightSource::Led4000K => "led_4000k",
            LightSource::Halogen => "halogen",
            LightSource::Xenon => "xenon",
            LightSource::LedHeadlight => "led_headlight",
        }
    }

    /// The correlated colour temperature, kelvin (`None` for low-pressure sodium, which is
    /// too far from the Planckian locus to have one).
    pub fn cct(self) -> Option<f64> {
        match self {
            LightSource::LowPressureSodium => None,
            LightSource::HighPressureSodium => Some(2050.0),
            LightSource::Led2200K => Some(2200.0),
            LightSource::Led2700K => Some(2700.0),
            LightSource::Led3000K => Some(3000.0),
            LightSource::Led4000K => Some(4000.0),
            LightSource::Halogen => Some(3200.0),
            LightSource::Xenon => Some(4300.0),
            LightSource::LedHeadlight => Some(5700.0),
        }
    }

    /// Its spectrum.
    pub fn spectrum(self) -> Spectrum {
        match self.cct() {
            Some(kelvin) => Spectrum::Blackbody(kelvin),
            None => Spectrum::Lines(&SODIUM_D),
        }
    }

    /// Linear sRGB of this source at luminance `y` (clipped to the gamut, see the module
    /// documentation): a lamp of photometric intensity `cd` candela is
    /// `rgb_with_luminance(cd / 683)` W/sr.
    pub fn rgb_with_luminance(self, y: f64) -> [f64; 3] {
        rgb_with_luminance(spectrum_xyz(self.spectrum()), y)
    }

    /// Linear sRGB of this source, max component 1.
    pub fn rgb(self) -> [f64; 3] {
        peak_one(self.rgb_with_luminance(1.0))
    }
}

impl std::fmt::Display for LightSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Planckian chromaticities of CIE 15 / Wyszecki & Stiles (table 1(3.3.4)).
    #[test]
    fn planckian_chromaticities_match_cie_15() {
        for (kelvin, reference) in [
            (2000.0, [0.5267, 0.4133]),
            (3000.0, [0.4369, 0.4041]),
            (4000.0, [0.3805, 0.3768]),
            (5000.0, [0.3451, 0.3516]),
            (6500.0, [0.3135, 0.3237]),
        ] {
            let xy = chromaticity(spectrum_xyz(Spectrum::Blackbody(kelvin)));
            for c in 0..2 {
                assert!(
                    (xy[c] - reference[c]).abs() < 1e-3,
                    "{kelvin} K: xy {xy:?}, CIE 15 {reference:?}"
                );
            }
        }
    }

    /// The CMF table integrates to equal-energy white (x = y = 1/3) and peaks at 555 nm.
    #[test]
    fn the_table_is_the_cie_1931_observer() {
        let sums = CMF
            .iter()
            .fold([0.0; 3], |s, r| [s[0] + r[0], s[1] + r[1], s[2] + r[2]]);
        let xy = chromaticity(sums);
        assert!((xy[0] - 1.0 / 3.0).abs() < 2e-4 && (xy[1] - 1.0 / 3.0).abs() < 2e-4);
        assert_eq!(cmf(555.0)[1], 1.0);
        assert_eq!(cmf(300.0), [0.0; 3]);
        // Interpolation between rows.
        let mid = cmf(557.5);
        assert!((mid[0] - 0.5 * (0.5120501 + 0.5945)).abs() < 1e-9);
    }

    /// Low-pressure sodium is the spectral locus at 589.2 nm, outside sRGB: clipped to a deep
    /// orange with no blue.
    #[test]
    fn low_pressure_sodium_is_clipped_orange() {
        let xyz = spectrum_xyz(LightSource::LowPressureSodium.spectrum());
        let xy = chromaticity(xyz);
        // The spectral locus in the 1 nm CIE 1931 table: (0.5693, 0.4301) at 589 nm,
        // (0.5752, 0.4242) at 590 nm.
        assert!(
            (xy[0] - 0.569).abs() < 3e-3 && (xy[1] - 0.430).abs() < 3e-3,
            "{xy:?}"
        );
        let raw = xyz_to_linear_srgb(xyz);
        assert!(raw[2] < 0.0, "out of gamut: {raw:?}");
        let rgb = LightSource::LowPressureSodium.rgb();
        assert_eq!(rgb[0], 1.0);
        assert!((rgb[1] - 0.22).abs() < 0.01 && rgb[2] == 0.0, "{rgb:?}");
    }

    /// A source's colour at luminance Y has luminance Y; warm lamps have a higher peak than
    /// cold ones at the same luminance.
    #[test]
    fn colours_carry_the_asked_luminance() {
        for source in LightSource::ALL {
            for y in [1e-3, 1.0, 25.0] {
                let rgb = source.rgb_with_luminance(y);
                assert!(rgb.iter().all(|c| *c >= 0.0));
                assert!(
                    (luminance(rgb) - y).abs() < 1e-6 * y,
                    "{source}: {rgb:?} has luminance {} not {y}",
                    luminance(rgb)
                );
            }
        }
        let hps = LightSource::HighPressureSodium.rgb_with_luminance(1.0);
        let led = LightSource::Led4000K.rgb_with_luminance(1.0);
        assert!(hps[0] > led[0] && hps[2] < led[2], "{hps:?} {led:?}");
        // 6500 K is near-white (D65 lies slightly off the locus).
        let white = blackbody_rgb(6500.0);
        assert!(white.iter().all(|&c| c > 0.93), "{white:?}");
    }

    /// Planck's law: Wien's displacement law places the peak at 2897.77 um K / T.
    #[test]
    fn planck_peaks_where_wien_says() {
        let kelvin = 5000.0;
        let peak = (300..1200)
            .map(|nm| nm as f64)
            .max_by(|a, b| planck(*a, kelvin).total_cmp(&planck(*b, kelvin)))
            .unwrap();
        assert!((peak - 2_897_771.955 / kelvin).abs() <= 1.0, "{peak}");
    }
}
