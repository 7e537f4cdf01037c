//! The one tone curve from raw DN to the 8-bit (or 16-bit) sRGB of a developed image.
//!
//! Per channel: `x = max(DN - black, 0) / (white - black) * 2^develop_ev` (black subtraction,
//! normalisation to the ADC's range, the ISP's digital gain), then the exponential shoulder
//! `y = 1 - exp(-x)` (linear with slope 1 in the dark, so the noise of the shadows is shown
//! as it is; it bends from about `x = 0.3` and reaches white smoothly, so lamps and their
//! clipped cores saturate without a hard edge), then the sRGB transfer function, rounded to
//! 8 bits. `white = 2^bit_depth - 1`. See docs/decisions/0032-sensor-tone-curve.md.

use crate::Capture;
use streaks_image::color::srgb_oetf;

/// The tone curve of one value, `x` the normalised, gained DN: `1 - exp(-x)`, then sRGB, in
/// [0, 1] before rounding.
#[inline]
fn tone_encoded(x: f64) -> f32 {
    let x = if x > 0.0 { x } else { 0.0 };
    let y = -(-x).exp_m1();
    srgb_oetf(y as f32)
}

/// The tone curve of one value, `x` the normalised, gained DN: `1 - exp(-x)`, sRGB, 8 bits.
#[inline]
pub fn tone(x: f64) -> u8 {
    (tone_encoded(x) * 255.0 + 0.5) as u8
}

/// The tone curve rounded to 16 bits instead of 8 ([`tone`]).
#[inline]
pub fn tone16(x: f64) -> u16 {
    (tone_encoded(x) * 65535.0 + 0.5) as u16
}

/// The capture developed through the tone curve `curve` (8 or 16 bits). A capture with fewer
/// pixels than its size (only a hand-made one) develops its missing pixels black.
fn develop_with<T: image::Primitive>(
    capture: &Capture,
    curve: impl Fn(f64) -> T,
) -> image::ImageBuffer<image::Rgb<T>, Vec<T>>
where
    image::Rgb<T>: image::Pixel<Subpixel = T>,
{
    let dn = &capture.dn;
    let scale = capture.develop_ev.exp2() / (capture.white_dn - capture.black_dn);
    image::ImageBuffer::from_fn(dn.width, dn.height, |x, y| {
        let i = y as usize * dn.width as usize + x as usize;
        let p = dn.pixels.get(i).copied().unwrap_or(glam::Vec3::ZERO);
        image::Rgb(
            p.to_array()
                .map(|v| curve((f64::from(v) - capture.black_dn) * scale)),
        )
    })
}

/// The capture developed through the tone curve (see the module documentation), 8 bits.
pub fn develop(capture: &Capture) -> image::RgbImage {
    develop_with(capture, tone)
}

/// The capture developed through the same tone curve at 16 bits ([`tone16`]).
pub fn develop16(capture: &Capture) -> image::ImageBuffer<image::Rgb<u16>, Vec<u16>> {
    develop_with(capture, tone16)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use streaks_image::RgbImage;

    #[test]
    fn the_curve() {
        assert_eq!(tone(0.0), 0);
        assert_eq!(tone(-3.0), 0);
        assert_eq!(tone(40.0), 255);
        assert_eq!(tone(f64::NAN), 0);
        for x in [0.0, 0.001, 0.05, 0.3, 1.0, 5.0, 40.0] {
            let (v8, v16) = (f64::from(tone(x)), f64::from(tone16(x)));
            assert!((v16 / 257.0 - v8).abs() <= 0.5, "{x}: {v8} {v16}");
        }
        assert_eq!(tone16(40.0), 65535);
        // Linear in the dark: 0.002 -> 0.002 * 12.92 * 255 = 6.6.
        assert_eq!(tone(0.002), 7);
        // 0.18 -> 1 - e^-0.18 = 0.1647 -> sRGB 0.444 -> 113.
        assert_eq!(tone(0.18), 113);
        let mut last = 0;
        for i in 0..1000 {
            let t = tone(f64::from(i) * 0.01);
            assert!(t >= last);
            last = t;
        }
    }

    #[test]
    fn black_and_white_levels() {
        let capture = Capture {
            dn: RgbImage {
                width: 3,
                height: 1,
                pixels: vec![Vec3::splat(168.0), Vec3::splat(100.0), Vec3::splat(4095.0)],
            },
            black_dn: 168.0,
            white_dn: 4095.0,
            develop_ev: 0.0,
        };
        let img = develop(&capture);
        assert_eq!(img.as_raw(), &[0, 0, 0, 0, 0, 0, 208, 208, 208]);
        let bright = Capture {
            develop_ev: 5.0,
            ..capture
        };
        assert_eq!(develop(&bright).as_raw()[6..], [255, 255, 255]);
        // A hand-made capture short of pixels does not panic.
        let mut short = bright.clone();
        short.dn.pixels.pop();
        assert_eq!(develop(&short).as_raw()[6..], [0, 0, 0]);
    }
}
