//! Disparity and optical flow maps in the KITTI 2015 encodings.
//!
//! Disparity maps: a 16-bit greyscale PNG whose value is the
//! disparity in pixels times 256, rounded, with 0 for "no value" (the development kit's
//! `disp_read`: `d = png / 256`, valid where `png > 0`).
//!
//! A disparity that does not fit (not finite, below 1/512 px so that it would round to 0, or
//! at or above 65535.5 / 256 px) is written as 0, "no value", never clipped to a wrong value.
//! Reading gives back `inf` for "no value", the project's PFM convention ([`crate::pfm`]), so a
//! KITTI map and its PFM compare directly (within 1/512 px, the rounding).
//!
//! ```
//! use streaks_image::{kitti, GrayImage};
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("000000_10.png");
//! let mut d = GrayImage::new(3, 1, f32::INFINITY)?;
//! d.set(0, 0, 12.3);
//! kitti::write_kitti_disparity(&path, &d)?;
//! let back = kitti::read_kitti_disparity(&path)?;
//! assert!((back.get(0, 0) - 12.3).abs() <= 1.0 / 512.0);
//! assert_eq!(back.get(1, 0), f32::INFINITY);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::png::write_png_buffer;
use crate::{GrayImage, ImageError};
use std::path::Path;

/// The KITTI scale: stored value = disparity x 256.
pub const KITTI_DISPARITY_SCALE: f32 = 256.0;

/// The stored 16-bit value of one disparity (0 where it has no value or does not fit).
pub fn encode_kitti_disparity(d: f32) -> u16 {
    let v = (d * KITTI_DISPARITY_SCALE).round();
    if d.is_finite() && (1.0..=u16::MAX as f32).contains(&v) {
        v as u16
    } else {
        0
    }
}

/// The disparity of one stored 16-bit value (`inf` for 0, "no value").
pub fn decode_kitti_disparity(v: u16) -> f32 {
    if v == 0 {
        f32::INFINITY
    } else {
        v as f32 / KITTI_DISPARITY_SCALE
    }
}

/// Writes a disparity map (pixels, `inf` = no value) as a KITTI 2015 16-bit PNG, atomically.
pub fn write_kitti_disparity(path: &Path, disparity: &GrayImage) -> Result<(), ImageError> {
    let data: Vec<u16> = disparity
        .data
        .iter()
        .map(|&d| encode_kitti_disparity(d))
        .collect();
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(
        disparity.width as u32,
        disparity.height as u32,
        data,
    )
    .ok_or_else(|| ImageError::BadImage {
        path: path.to_path_buf(),
        reason: format!("{}x{} disparity map", disparity.width, disparity.height),
    })?;
    write_png_buffer(path, &img)
}

/// Reads a KITTI 2015 disparity PNG (16-bit greyscale) as pixels, `inf` where it has no value.
pub fn read_kitti_disparity(path: &Path) -> Result<GrayImage, ImageError> {
    let err = |reason: String| ImageError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let img = crate::input::load_image(path)?;
    let image::DynamicImage::ImageLuma16(img) = img else {
        return Err(err(format!(
            "a KITTI disparity map is a 16-bit greyscale PNG, this is {:?}",
            img.color()
        )));
    };
    let (w, h) = (img.width() as usize, img.height() as usize);
    let data = img
        .into_raw()
        .into_iter()
        .map(decode_kitti_disparity)
        .collect();
    GrayImage::from_vec(w, h, data)
}

/// The KITTI flow scale: stored value = flow x 64 + 2^15.
pub const KITTI_FLOW_SCALE: f32 = 64.0;
/// The KITTI flow offset: the stored value of a zero flow.
pub const KITTI_FLOW_OFFSET: f32 = 32768.0;

/// The stored 16-bit `(u, v, valid)` of one flow vector in the KITTI 2015 flow encoding
/// (`flow_occ`: `u x 64 + 2^15`, `v x 64 + 2^15`, 1); `(0, 0, 0)` when it has no value or a
/// component does not fit (outside about +-512 px).
pub fn encode_kitti_flow(flow: Option<[f32; 2]>) -> [u16; 3] {
    let code = |f: f32| {
        let v = (f * KITTI_FLOW_SCALE + KITTI_FLOW_OFFSET).round();
        (f.is_finite() && (0.0..=u16::MAX as f32).contains(&v)).then_some(v as u16)
    };
    match flow.and_then(|[u, v]| Some([code(u)?, code(v)?])) {
        Some([u, v]) => [u, v, 1],
        None => [0, 0, 0],
    }
}

/// The flow of one stored `(u, v, valid)` (`None` where `valid` is 0).
pub fn decode_kitti_flow(px: [u16; 3]) -> Option<[f32; 2]> {
    (px[2] != 0).then(|| {
        [
            (px[0] as f32 - KITTI_FLOW_OFFSET) / KITTI_FLOW_SCALE,
            (px[1] as f32 - KITTI_FLOW_OFFSET) / KITTI_FLOW_SCALE,
        ]
    })
}

/// Writes a flow map (`width x height` vectors, rows top to bottom, `None` = no value) as a
/// KITTI 2015 16-bit RGB flow PNG, atomically.
pub fn write_kitti_flow(
    path: &Path,
    width: usize,
    height: usize,
    flow: &[Option<[f32; 2]>],
) -> Result<(), ImageError> {
    let data: Vec<u16> = flow.iter().flat_map(|&f| encode_kitti_flow(f)).collect();
    let img = image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(
        width as u32,
        height as u32,
        data,
    )
    .ok_or_else(|| ImageError::BadImage {
        path: path.to_path_buf(),
        reason: format!("{width}x{height} flow map with {} vectors", flow.len()),
    })?;
    write_png_buffer(path, &img)
}

/// A flow map as read from a file: width, height and the vectors, rows top to bottom, `None`
/// where it has no value.
pub type FlowMap = (usize, usize, Vec<Option<[f32; 2]>>);

/// Reads a KITTI 2015 flow PNG (16-bit RGB): its size and its vectors, rows top to bottom,
/// `None` where it has no value.
pub fn read_kitti_flow(path: &Path) -> Result<FlowMap, ImageError> {
    let img = crate::input::load_image(path)?;
    let image::DynamicImage::ImageRgb16(img) = img else {
        return Err(ImageError::Read {
            path: path.to_path_buf(),
            reason: format!(
                "a KITTI flow map is a 16-bit RGB PNG, this is {:?}",
                img.color()
            ),
        });
    };
    let (w, h) = (img.width() as usize, img.height() as usize);
    let flow = img.pixels().map(|p| decode_kitti_flow(p.0)).collect();
    Ok((w, h, flow))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_round_to_a_256th_and_misfits_have_no_value() {
        assert_eq!(encode_kitti_disparity(1.0), 256);
        assert_eq!(encode_kitti_disparity(0.5 / 256.0), 1);
        assert_eq!(encode_kitti_disparity(0.4 / 256.0), 0);
        assert_eq!(encode_kitti_disparity(0.0), 0);
        assert_eq!(encode_kitti_disparity(-3.0), 0);
        assert_eq!(encode_kitti_disparity(f32::INFINITY), 0);
        assert_eq!(encode_kitti_disparity(f32::NAN), 0);
        assert_eq!(encode_kitti_disparity(255.99), 65533);
        assert_eq!(encode_kitti_disparity(65535.0 / 256.0), 65535);
        assert_eq!(encode_kitti_disparity(256.0), 0);
        assert_eq!(decode_kitti_disparity(0), f32::INFINITY);
        assert_eq!(decode_kitti_disparity(384), 1.5);
    }

    /// Flow vectors are stored as x 64 + 2^15 with a valid flag; misfits have no value.
    #[test]
    fn flow_round_trips_within_the_rounding() {
        assert_eq!(encode_kitti_flow(Some([0.0, -1.0])), [32768, 32704, 1]);
        assert_eq!(encode_kitti_flow(Some([600.0, 0.0])), [0, 0, 0]);
        assert_eq!(encode_kitti_flow(Some([f32::INFINITY, 0.0])), [0, 0, 0]);
        assert_eq!(encode_kitti_flow(None), [0, 0, 0]);
        assert_eq!(
            decode_kitti_flow([32768 + 96, 32768 - 32, 1]),
            Some([1.5, -0.5])
        );
        assert_eq!(decode_kitti_flow([32768, 32768, 0]), None);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.png");
        let flow: Vec<Option<[f32; 2]>> = (0..6)
            .map(|i| (i != 4).then_some([0.3 * i as f32 - 1.0, 2.0 - 0.7 * i as f32]))
            .collect();
        write_kitti_flow(&path, 3, 2, &flow).unwrap();
        let (w, h, back) = read_kitti_flow(&path).unwrap();
        assert_eq!((w, h), (3, 2));
        for (a, b) in flow.iter().zip(&back) {
            match (a, b) {
                (Some(a), Some(b)) => {
                    assert!((a[0] - b[0]).abs() <= 0.5 / 64.0 && (a[1] - b[1]).abs() <= 0.5 / 64.0)
                }
                (None, None) => {}
                _ => panic!("{a:?} vs {b:?}"),
            }
        }
        assert!(write_kitti_flow(&path, 4, 2, &flow).is_err());
    }

    #[test]
    fn a_map_round_trips_within_the_rounding() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.png");
        let data: Vec<f32> = (0..12).map(|i| 0.37 * i as f32 + 0.01).collect();
        let mut d = GrayImage::from_vec(4, 3, data).unwrap();
        d.set(3, 2, f32::INFINITY);
        write_kitti_disparity(&path, &d).unwrap();
        let back = read_kitti_disparity(&path).unwrap();
        assert_eq!((back.width, back.height), (4, 3));
        for (a, b) in d.data.iter().zip(&back.data) {
            if a.is_finite() {
                assert!((a - b).abs() <= 0.5 / 256.0, "{a} {b}");
            } else {
                assert_eq!(*b, f32::INFINITY);
            }
        }
        // An 8-bit PNG is not a KITTI disparity map.
        let grey = dir.path().join("grey.png");
        d.save_png(&grey).unwrap();
        let err = read_kitti_disparity(&grey).unwrap_err();
        assert!(err.to_string().contains("16-bit"), "{err}");
        let err = read_kitti_disparity(&dir.path().join("none.png")).unwrap_err();
        assert!(err.to_string().contains("none.png"), "{err}");
    }
}
