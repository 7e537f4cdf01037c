//! PNG writing: 8-bit sRGB of a linear image with an exposure ([`write_png`]), and any 8- or
//! 16-bit grey or colour buffer of the `image` crate ([`write_png_buffer`]), both atomically and
//! through the one encoder call, which also gives the bytes in memory ([`png_bytes`]). Reading any image file is [`crate::GrayImage::load`] and
//! [`crate::gray::load_rgb_channels`].

use crate::atomic::{write_atomically, WriteFailure};
use crate::color::srgb_oetf;
use crate::{ImageError, RgbImage};
use image::ImageEncoder;
use std::io::Write;
use std::path::Path;

/// Converts a linear image to 8-bit sRGB, three bytes per pixel: scale by `2^exposure_ev`,
/// clip to [0, 1] (NaN to 0), apply the sRGB OETF and round.
pub fn to_srgb8(image: &RgbImage, exposure_ev: f32) -> Vec<u8> {
    let scale = exposure_ev.exp2();
    image
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|v| {
            let v = (v * scale).clamp(0.0, 1.0);
            let v = if v.is_nan() { 0.0 } else { v };
            (srgb_oetf(v) * 255.0 + 0.5) as u8
        })
        .collect()
}

/// The linear image as an 8-bit sRGB buffer of the `image` crate (see [`to_srgb8`]).
pub fn to_srgb8_image(image: &RgbImage, exposure_ev: f32) -> Option<image::RgbImage> {
    image::RgbImage::from_raw(image.width, image.height, to_srgb8(image, exposure_ev))
}

/// Writes an 8-bit sRGB PNG of a linear image with exposure `exposure_ev` (see [`to_srgb8`]).
pub fn write_png(path: &Path, image: &RgbImage, exposure_ev: f32) -> Result<(), ImageError> {
    let bad = || ImageError::BadImage {
        path: path.to_path_buf(),
        reason: format!(
            "{}x{} image with {} pixels",
            image.width,
            image.height,
            image.pixels.len()
        ),
    };
    if !image.is_well_formed() {
        return Err(bad());
    }
    write_png_buffer(path, &to_srgb8_image(image, exposure_ev).ok_or_else(bad)?)
}

/// Encodes any `image` crate buffer (8- or 16-bit grey or colour) as PNG into `w`: the one
/// encoder call of this project.
fn encode_png<P, C>(w: impl Write, img: &image::ImageBuffer<P, C>) -> Result<(), image::ImageError>
where
    P: image::PixelWithColorType,
    C: std::ops::Deref<Target = [P::Subpixel]>,
    [P::Subpixel]: image::EncodableLayout,
{
    use image::EncodableLayout;
    image::codecs::png::PngEncoder::new(w).write_image(
        img.as_raw().as_bytes(),
        img.width(),
        img.height(),
        P::COLOR_TYPE,
    )
}

/// Encodes any `image` crate buffer (8- or 16-bit grey or colour) as PNG and writes it
/// atomically: the one way this project writes PNG files.
pub fn write_png_buffer<P, C>(path: &Path, img: &image::ImageBuffer<P, C>) -> Result<(), ImageError>
where
    P: image::PixelWithColorType,
    C: std::ops::Deref<Target = [P::Subpixel]>,
    [P::Subpixel]: image::EncodableLayout,
{
    if img.width() == 0 || img.height() == 0 {
        return Err(ImageError::BadImage {
            path: path.to_path_buf(),
            reason: format!("{}x{} image", img.width(), img.height()),
        });
    }
    write_atomically(path, |w| {
        encode_png(w.by_ref(), img).map_err(WriteFailure::Png)
    })
}

/// The PNG bytes of any `image` crate buffer, in memory (for pages that embed their images
/// as data URIs); the same encoder as [`write_png_buffer`].
pub fn png_bytes<P, C>(img: &image::ImageBuffer<P, C>) -> Result<Vec<u8>, image::ImageError>
where
    P: image::PixelWithColorType,
    C: std::ops::Deref<Target = [P::Subpixel]>,
    [P::Subpixel]: image::EncodableLayout,
{
    let mut bytes = Vec::new();
    encode_png(&mut bytes, img)?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn png_bytes_decode_to_the_image() {
        let img =
            image::RgbImage::from_fn(3, 2, |x, y| image::Rgb([x as u8 * 80, y as u8 * 200, 7]));
        let bytes = png_bytes(&img).unwrap();
        let back = image::load_from_memory(&bytes).unwrap().to_rgb8();
        assert_eq!(back, img);
    }

    #[test]
    fn png_exposure_clip_and_srgb() {
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
        let bytes = to_srgb8(&img, 1.0);
        assert_eq!(&bytes[0..3], &[0, 255, 255]);
        // 0.25 * 2 = 0.5 -> sRGB 0.7354 -> 188
        assert_eq!(&bytes[3..6], &[188, 188, 188]);
        assert_eq!(&bytes[6..9], &[0, 0, 255]);
        // Linear segment: 0.002 * 12.92 * 255 = 6.6
        assert_eq!(bytes[9], 7);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.png");
        write_png(&path, &img, 1.0).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back.as_raw(), &bytes);
        // Missing folder, empty image.
        assert!(write_png(&dir.path().join("no/such.png"), &img, 0.0).is_err());
        let err = write_png(&dir.path().join("e.png"), &RgbImage::new(0, 2), 0.0).unwrap_err();
        assert!(err.to_string().contains("e.png"), "{err}");
    }

    #[test]
    fn sixteen_bit_grey_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.png");
        let img = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(3, 1, vec![0u16, 256, 65535])
            .unwrap();
        write_png_buffer(&path, &img).unwrap();
        let back = image::open(&path).unwrap().to_luma16();
        assert_eq!(back.as_raw(), &[0, 256, 65535]);
    }
}
