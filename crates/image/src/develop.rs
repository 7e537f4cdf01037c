//! Developing a render without a camera model: linear radiance to the 8-bit sRGB that the PNGs
//! of `streaks render` and `streaks stereo` hold without `--sensor` (and a dataset's
//! `im0.png`/`im1.png` when its config has no `[weather]`). With a camera model the
//! `streaks-sensor` crate develops its raw DN by its own curve (noise, glare and vignetting
//! included).
//!
//! This curve has no noise, glare or vignetting: the exposure scales the radiance by
//! `2^exposure_ev`, values clip at 1 (negative values and NaN to 0), and the tone curve is the
//! sRGB transfer function, rounded to 8 bits.

use crate::color::srgb_oetf;
use crate::{ImageError, RgbImage};

/// One channel value developed: scaled by `scale` (`2^exposure_ev`), clipped to [0, 1] (NaN to
/// 0) and through the sRGB curve, in [0, 1] before rounding.
#[inline]
fn encode(v: f32, scale: f32) -> f32 {
    let v = (v * scale).clamp(0.0, 1.0);
    let v = if v.is_nan() { 0.0 } else { v };
    srgb_oetf(v)
}

/// One channel value developed ([`encode`]) and rounded to 8 bits.
#[inline]
fn develop_value(v: f32, scale: f32) -> u8 {
    (encode(v, scale) * 255.0 + 0.5) as u8
}

/// The render developed with exposure `exposure_ev` as 8-bit sRGB bytes, three per pixel,
/// row-major (see the module documentation).
pub fn develop_srgb8(render: &RgbImage, exposure_ev: f32) -> Vec<u8> {
    let scale = exposure_ev.exp2();
    render
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|v| develop_value(v, scale))
        .collect()
}

/// The render developed with exposure `exposure_ev` as an 8-bit sRGB image of the `image`
/// crate, ready to encode (see the module documentation); an error when the render has fewer
/// pixels than its size needs.
pub fn develop(render: &RgbImage, exposure_ev: f32) -> Result<image::RgbImage, ImageError> {
    image::RgbImage::from_raw(
        render.width,
        render.height,
        develop_srgb8(render, exposure_ev),
    )
    .ok_or(ImageError::Size {
        width: u64::from(render.width),
        height: u64::from(render.height),
        reason: "fewer pixels than the size needs",
    })
}

/// The render developed as [`develop`] does, rounded to 16 bits instead of 8 (the same curve:
/// a value of the 8-bit image is this one's divided by 257, to within rounding), for datasets
/// that keep the images' shadows and highlights at full precision.
pub fn develop16(
    render: &RgbImage,
    exposure_ev: f32,
) -> Result<image::ImageBuffer<image::Rgb<u16>, Vec<u16>>, ImageError> {
    let scale = exposure_ev.exp2();
    let data = render
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|v| (encode(v, scale) * 65535.0 + 0.5) as u16)
        .collect();
    image::ImageBuffer::from_raw(render.width, render.height, data).ok_or(ImageError::Size {
        width: u64::from(render.width),
        height: u64::from(render.height),
        reason: "fewer pixels than the size needs",
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn exposure_clip_and_srgb() {
        let img = RgbImage {
            width: 4,
            height: 1,
            pixels: vec![
                Vec3::new(0.0, 1.0, 2.0),
                Vec3::splat(0.25),
                Vec3::new(-1.0, f32::NAN, f32::INFINITY),
                Vec3::splat(0.001),
            ],
        };
        let bytes = develop_srgb8(&img, 1.0);
        assert_eq!(&bytes[0..3], &[0, 255, 255]);
        // 0.25 * 2 = 0.5 -> sRGB 0.7354 -> 188
        assert_eq!(&bytes[3..6], &[188, 188, 188]);
        assert_eq!(&bytes[6..9], &[0, 0, 255]);
        // Linear segment: 0.002 * 12.92 * 255 = 6.6
        assert_eq!(bytes[9], 7);
        assert_eq!(develop(&img, 1.0).unwrap().as_raw(), &bytes);
        let wide = develop16(&img, 1.0).unwrap();
        for (&v16, &v8) in wide.as_raw().iter().zip(&bytes) {
            assert!(
                (f64::from(v16) / 257.0 - f64::from(v8)).abs() <= 0.5,
                "{v16} {v8}"
            );
        }
        assert_eq!(&wide.as_raw()[0..3], &[0, 65535, 65535]);
        let bad = RgbImage { width: 5, ..img };
        assert!(develop(&bad, 0.0).is_err());
        assert!(develop16(&bad, 0.0).is_err());
    }
}
