//! PFM maps (disparity, depth) in the Middlebury convention: greyscale `Pf`, little-endian
//! (negative scale), rows stored bottom to top, `inf` for "no value"; and three-channel `PF`
//! maps (optical flow as SceneFlow stores it: `u`, `v`, 0). Written atomically.

use crate::atomic::write_bytes_atomically;
use crate::input::{check_pixels, read_file, MAX_PIXELS};
use crate::{GrayImage, ImageError};
use std::path::Path;

/// Writes `img` as a little-endian greyscale PFM.
pub fn write_pfm(path: &Path, img: &GrayImage) -> Result<(), ImageError> {
    let mut bytes = format!("Pf\n{} {}\n-1.0\n", img.width, img.height).into_bytes();
    bytes.reserve(img.data.len() * 4);
    for y in (0..img.height).rev() {
        for &v in &img.data[y * img.width..(y + 1) * img.width] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    write_bytes_atomically(path, &bytes)
}

/// Writes `img` as a little-endian three-channel PFM (`PF`).
pub fn write_pfm_rgb(path: &Path, img: &crate::RgbImage) -> Result<(), ImageError> {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut bytes = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    bytes.reserve(img.pixels.len() * 12);
    for y in (0..h).rev() {
        for p in &img.pixels[y * w..(y + 1) * w] {
            for v in p.to_array() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    write_bytes_atomically(path, &bytes)
}

/// Reads a three-channel PFM (`PF`, either byte order); rows top row first. The same limits
/// as [`read_pfm`].
pub fn read_pfm_rgb(path: &Path) -> Result<crate::RgbImage, ImageError> {
    let (w, h, data) = read_pfm_channels(path, "PF", 3)?;
    let pixels = data
        .chunks_exact(3)
        .map(|c| glam::Vec3::new(c[0], c[1], c[2]))
        .collect();
    Ok(crate::RgbImage {
        width: w as u32,
        height: h as u32,
        pixels,
    })
}

/// The longest PFM header read: the magic, the size and the scale, with room for spaces.
const MAX_HEADER_BYTES: u64 = 1024;

/// Reads a greyscale PFM (either byte order); rows are returned top row first. Only a regular
/// file is read, at most [`MAX_PIXELS`] floats and a header; the size in the header is checked
/// against the limit and against the bytes the file holds before the image is allocated.
pub fn read_pfm(path: &Path) -> Result<GrayImage, ImageError> {
    let (w, h, data) = read_pfm_channels(path, "Pf", 1)?;
    GrayImage::from_vec(w, h, data)
}

/// Reads a PFM of magic `magic` with `channels` floats per pixel: width, height and the values,
/// rows top row first.
fn read_pfm_channels(
    path: &Path,
    magic_expected: &str,
    channels: usize,
) -> Result<(usize, usize, Vec<f32>), ImageError> {
    let err = |reason: String| ImageError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let bytes = read_file(path, MAX_PIXELS * 4 * channels as u64 + MAX_HEADER_BYTES)
        .map_err(|e| err(e.to_string()))?;
    // Header: three whitespace-separated tokens after the magic, then one whitespace byte.
    let mut pos = 0usize;
    let mut token = || -> Result<String, ImageError> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            return Err(err("truncated header".into()));
        }
        Ok(String::from_utf8_lossy(&bytes[start..pos]).into_owned())
    };
    let magic = token()?;
    if magic != magic_expected {
        let kind = if channels == 1 { "greyscale" } else { "colour" };
        return Err(err(format!(
            "not a {kind} PFM (magic {magic:?}, expected {magic_expected:?})"
        )));
    }
    let width: usize = token()?.parse().map_err(|_| err("bad width".into()))?;
    let height: usize = token()?.parse().map_err(|_| err("bad height".into()))?;
    let scale: f32 = token()?.parse().map_err(|_| err("bad scale".into()))?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(err("scale must be a non-zero number".into()));
    }
    let data_start = pos + 1;
    check_pixels(width as u64, height as u64).map_err(err)?;
    // The pixels must be in the file before memory is reserved for them: a header alone can
    // claim any size.
    let have = bytes.len().saturating_sub(data_start);
    let need = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(4 * channels));
    if need.is_none_or(|need| have < need) {
        let expected = need.map_or_else(|| "more than can be addressed".into(), |n| n.to_string());
        return Err(err(format!(
            "truncated data: {have} bytes for {width}x{height}, expected {expected}"
        )));
    }
    let need = need.unwrap_or_default();
    let mut data = vec![0.0f32; width * height * channels];
    let little = scale < 0.0;
    let row = width * channels;
    for (i, chunk) in bytes[data_start..data_start + need]
        .chunks_exact(4)
        .enumerate()
    {
        let b = [chunk[0], chunk[1], chunk[2], chunk[3]];
        let v = if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        let (col, row_from_bottom) = (i % row, i / row);
        data[(height - 1 - row_from_bottom) * row + col] = v;
    }
    Ok((width, height, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_rows_and_inf() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("d.pfm");
        let img = GrayImage::from_vec(3, 2, vec![1.0, 2.0, f32::INFINITY, -4.0, 5.5, 6.0]).unwrap();
        write_pfm(&p, &img).unwrap();
        let raw = std::fs::read(&p).unwrap();
        // The first stored row is the bottom one.
        let body = &raw[raw.len() - 24..];
        assert_eq!(
            f32::from_le_bytes([body[0], body[1], body[2], body[3]]),
            -4.0
        );
        assert_eq!(read_pfm(&p).unwrap(), img);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// A colour PFM keeps its rows and channels; a greyscale reader refuses it and back.
    #[test]
    fn colour_maps_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.pfm");
        let img = crate::RgbImage::from_fn(3, 2, |x, y| {
            glam::Vec3::new(x as f32 - 1.5, y as f32 * 2.0, f32::INFINITY)
        });
        write_pfm_rgb(&p, &img).unwrap();
        let raw = std::fs::read(&p).unwrap();
        assert!(raw.starts_with(b"PF\n3 2\n-1.0\n"));
        // The first stored pixel is the bottom row's first: (-1.5, 2, inf).
        let body = &raw[raw.len() - 72..];
        assert_eq!(
            f32::from_le_bytes([body[4], body[5], body[6], body[7]]),
            2.0
        );
        assert_eq!(read_pfm_rgb(&p).unwrap(), img);
        assert!(read_pfm(&p).unwrap_err().to_string().contains("greyscale"));
        let grey = dir.path().join("g.pfm");
        write_pfm(&grey, &GrayImage::new(2, 2, 1.0).unwrap()).unwrap();
        assert!(read_pfm_rgb(&grey)
            .unwrap_err()
            .to_string()
            .contains("colour"));
    }

    #[test]
    fn bad_files_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.pfm");
        std::fs::write(&p, b"P6\n1 1\n255\n\0\0\0").unwrap();
        assert!(read_pfm(&p).is_err());
        std::fs::write(&p, b"Pf\n4 4\n-1.0\n\0\0").unwrap();
        assert!(read_pfm(&p).unwrap_err().to_string().contains("truncated"));
        assert!(read_pfm(&dir.path().join("missing.pfm")).is_err());
    }

    #[test]
    fn a_huge_header_is_refused_before_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("huge.pfm");
        let start = std::time::Instant::now();
        std::fs::write(&p, b"Pf\n100000 100000\n-1.0\n\0\0\0\0").unwrap();
        let err = read_pfm(&p).unwrap_err().to_string();
        assert!(
            err.contains("100000x100000") && err.contains("huge.pfm"),
            "{err}"
        );
        std::fs::write(&p, b"Pf\n40000 40000\n-1.0\n\0\0\0\0").unwrap();
        let err = read_pfm(&p).unwrap_err().to_string();
        assert!(
            err.contains("40000x40000") && err.contains("limit"),
            "{err}"
        );
        // Within the limit but not backed by the file's bytes.
        std::fs::write(&p, b"Pf\n16384 16384\n-1.0\n\0\0\0\0").unwrap();
        let err = read_pfm(&p).unwrap_err().to_string();
        assert!(err.contains("truncated"), "{err}");
        assert!(start.elapsed() < std::time::Duration::from_secs(1));
        // A device is not read.
        let err = read_pfm(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
    }
}
