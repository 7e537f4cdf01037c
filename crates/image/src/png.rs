//! PNG writing: a render developed to 8-bit sRGB ([`write_png`], through
//! [`crate::develop::develop`]), and any 8- or
//! 16-bit grey or colour buffer of the `image` crate ([`write_png_buffer`]), both atomically and
//! through the one encoder call, which also gives the bytes in memory ([`png_bytes`]). Reading any image file is [`crate::GrayImage::load`] and
//! [`crate::gray::load_rgb_channels`].

use crate::atomic::{write_atomically, WriteFailure};
use crate::develop::develop;
use crate::{ImageError, RgbImage};
use image::ImageEncoder;
use std::io::Write;
use std::path::Path;

/// Writes a render developed with exposure `exposure_ev` as an 8-bit sRGB PNG (see
/// [`mod@crate::develop`]).
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
    write_png_buffer(path, &develop(image, exposure_ev).map_err(|_| bad())?)
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
    fn png_holds_the_developed_render() {
        let mut img = RgbImage::new(3, 2);
        img.pixels[1] = Vec3::new(0.25, 2.0, f32::NAN);
        img.pixels[4] = Vec3::splat(0.001);
        let bytes = crate::develop::develop_srgb8(&img, 1.0);
        assert_eq!(&bytes[3..6], &[188, 255, 0]);
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
