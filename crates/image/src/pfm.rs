//! PFM maps (disparity, depth) in the Middlebury convention: greyscale `Pf`, little-endian
//! (negative scale), rows stored bottom to top, `inf` for "no value". Written atomically.

use crate::atomic::write_bytes_atomically;
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

/// Reads a greyscale PFM (either byte order); rows are returned top row first.
pub fn read_pfm(path: &Path) -> Result<GrayImage, ImageError> {
    let err = |reason: String| ImageError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let bytes = std::fs::read(path).map_err(|e| err(e.to_string()))?;
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
    if magic != "Pf" {
        return Err(err(format!(
            "not a greyscale PFM (magic {magic:?}, expected \"Pf\")"
        )));
    }
    let width: usize = token()?.parse().map_err(|_| err("bad width".into()))?;
    let height: usize = token()?.parse().map_err(|_| err("bad height".into()))?;
    let scale: f32 = token()?.parse().map_err(|_| err("bad scale".into()))?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(err("scale must be a non-zero number".into()));
    }
    let data_start = pos + 1;
    // The pixels must be in the file before memory is reserved for them: a header alone can
    // claim any size.
    let have = bytes.len().saturating_sub(data_start);
    let need = width.checked_mul(height).and_then(|n| n.checked_mul(4));
    if need.is_none_or(|need| have < need) {
        let expected = need.map_or_else(|| "more than can be addressed".into(), |n| n.to_string());
        return Err(err(format!(
            "truncated data: {have} bytes for {width}x{height}, expected {expected}"
        )));
    }
    let need = need.unwrap_or_default();
    let mut img = GrayImage::new(width, height, 0.0).map_err(|e| err(e.to_string()))?;
    let little = scale < 0.0;
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
        let (x, row_from_bottom) = (i % width, i / width);
        img.set(x, height - 1 - row_from_bottom, v);
    }
    Ok(img)
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
    fn a_size_the_file_does_not_hold_is_refused_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.pfm");
        // 2^62 pixels: the size overflows any allocation; 40000 x 30000 (4.8 GB): allowed by
        // the pixel limit but not backed by the 8 bytes that follow.
        for header in [
            "Pf\n2147483648 2147483648\n-1.0\n",
            "Pf\n40000 30000\n-1.0\n",
        ] {
            std::fs::write(&p, [header.as_bytes(), &[0; 8]].concat()).unwrap();
            let e = read_pfm(&p).unwrap_err().to_string();
            assert!(e.contains("truncated data: 8 bytes"), "{e}");
        }
    }
}
