//! Colour: luminance and the sRGB transfer functions, written once for the renderer (light
//! choice, texture decoding, PNG output) and the stereo and analysis code (grey levels).

use glam::Vec3;

/// Rec. 709 / sRGB-primaries luminance of a linear RGB colour (the Y row of the sRGB-to-XYZ
/// matrix).
#[inline]
pub fn luminance(rgb: Vec3) -> f32 {
    0.212_671 * rgb.x + 0.715_160 * rgb.y + 0.072_169 * rgb.z
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1) on a linear value in [0, 1]:
/// linear to encoded.
#[inline]
pub fn srgb_oetf(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): encoded value in [0, 1] to
/// linear.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luminance_weights_sum_to_one() {
        assert!((luminance(Vec3::ONE) - 1.0).abs() < 1e-6);
        assert!(luminance(Vec3::Y) > luminance(Vec3::X) && luminance(Vec3::X) > luminance(Vec3::Z));
    }

    #[test]
    fn srgb_curves_are_inverse() {
        for i in 0..=100 {
            let v = i as f32 / 100.0;
            assert!((srgb_to_linear(srgb_oetf(v)) - v).abs() < 1e-5, "{v}");
        }
        assert_eq!(srgb_oetf(0.0), 0.0);
        assert!((srgb_oetf(1.0) - 1.0).abs() < 1e-6);
        // 0.5 linear is 0.7354 encoded.
        assert!((srgb_oetf(0.5) - 0.735_357).abs() < 1e-5);
    }
}
