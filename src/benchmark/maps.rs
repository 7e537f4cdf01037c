//! Disparity maps on disk as the benchmark reads them: a ground truth, a command's output or a
//! prediction, in either of the two formats the benchmark takes, chosen by the extension:
//!
//! - `.pfm`: Middlebury's float PFM (`inf`, NaN or a value <= 0: no value);
//! - `.png`: KITTI 2015's uint16 PNG, disparity x 256 (0: no value).
//!
//! A method's map ([`read_method_map`]) is also checked before it is read: a regular file (a
//! command's output must not be a link either), no larger than a map of the sample's size can
//! be, and of that size once read.

use super::report::FailureKind;
use anyhow::{bail, Result};
use std::path::Path;
use streaks_analysis::benchmark::method::no_value_below_zero;
use streaks_image::kitti::read_kitti_disparity;
use streaks_image::pfm::read_pfm;
use streaks_image::GrayImage;

/// The format of a disparity map file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapFormat {
    /// Middlebury PFM, float pixels.
    Pfm,
    /// KITTI 2015 uint16 PNG, disparity x 256.
    KittiPng,
}

impl MapFormat {
    /// Both, in the order a prediction folder is searched.
    pub const ALL: [MapFormat; 2] = [MapFormat::Pfm, MapFormat::KittiPng];

    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            MapFormat::Pfm => "pfm",
            MapFormat::KittiPng => "png",
        }
    }

    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            MapFormat::Pfm => "PFM",
            MapFormat::KittiPng => "KITTI uint16 PNG",
        }
    }

    /// The format of a file named `path`, by its extension (`None` for any other).
    pub fn of(path: &Path) -> Option<MapFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Self::ALL.into_iter().find(|f| f.extension() == ext)
    }

    /// The largest file a map of `width` x `height` pixels can be in this format: a PFM's
    /// floats and a header; a PNG's rows stored uncompressed, with the deflate and chunk
    /// overhead of any encoder.
    fn most_bytes(self, width: u64, height: u64) -> u64 {
        match self {
            MapFormat::Pfm => width * height * 4 + 4096,
            MapFormat::KittiPng => {
                let raw = (width * 2 + 1) * height;
                raw + raw / 64 + 65536
            }
        }
    }
}

/// Reads the disparity map `path` in the format its extension names (see the module
/// documentation), `inf` where it has no value.
pub fn read_disparity(path: &Path) -> Result<GrayImage> {
    match MapFormat::of(path) {
        Some(MapFormat::Pfm) => Ok(read_pfm(path)?),
        Some(MapFormat::KittiPng) => Ok(read_kitti_disparity(path)?),
        None => bail!(
            "{} is neither a .pfm nor a KITTI .png disparity map",
            path.display()
        ),
    }
}

/// Reads a method's map `path` for a sample of `size` (width, height): a regular file
/// (`follow_links`: a symbolic link to one counts), not larger than such a map can be, readable
/// in its extension's format and of that size; every value that is not finite or not positive
/// made `inf`. The error is the failure's kind and reason, naming the file.
pub fn read_method_map(
    path: &Path,
    size: (usize, usize),
    follow_links: bool,
) -> std::result::Result<GrayImage, (FailureKind, String)> {
    let bad = |reason: String| (FailureKind::BadOutput, reason);
    let meta = if follow_links {
        std::fs::metadata(path)
    } else {
        std::fs::symlink_metadata(path)
    };
    let meta = meta.map_err(|e| (FailureKind::Missing, format!("{}: {e}", path.display())))?;
    if !meta.file_type().is_file() {
        return Err(bad(format!(
            "{} is not a regular file (a {}folder or device)",
            path.display(),
            if follow_links { "" } else { "link, " }
        )));
    }
    let Some(format) = MapFormat::of(path) else {
        return Err(bad(format!("{} is neither .pfm nor .png", path.display())));
    };
    let (w, h) = (size.0 as u64, size.1 as u64);
    let most = format.most_bytes(w, h);
    if meta.len() > most {
        return Err(bad(format!(
            "{} is {} bytes, more than a {w}x{h} .{}'s {most}",
            path.display(),
            meta.len(),
            format.extension()
        )));
    }
    let mut disp = read_disparity(path).map_err(|e| {
        bad(format!(
            "{} is not a readable {}: {e:#}",
            path.display(),
            format.name()
        ))
    })?;
    if (disp.width, disp.height) != size {
        return Err(bad(format!(
            "{} is a {}x{} disparity map, the sample is {w}x{h}",
            path.display(),
            disp.width,
            disp.height
        )));
    }
    no_value_below_zero(&mut disp);
    Ok(disp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use streaks_image::kitti::write_kitti_disparity;
    use streaks_image::pfm::write_pfm;

    #[test]
    fn both_formats_by_extension_with_their_checks() {
        let dir = tempfile::tempdir().unwrap();
        let d = GrayImage::from_vec(3, 2, vec![1.5, 0.0, -1.0, f32::NAN, 2.25, 64.0]).unwrap();
        let (pfm, png) = (dir.path().join("a.pfm"), dir.path().join("a.PNG"));
        write_pfm(&pfm, &d).unwrap();
        write_kitti_disparity(&png, &d).unwrap();
        let inf = f32::INFINITY;
        let want = [1.5, inf, inf, inf, 2.25, 64.0];
        for p in [&pfm, &png] {
            assert_eq!(read_method_map(p, (3, 2), false).unwrap().data, want);
        }
        // The wrong size, a missing file, a link where links are refused, another format.
        let (kind, reason) = read_method_map(&pfm, (2, 3), false).unwrap_err();
        assert_eq!(kind, FailureKind::BadOutput);
        assert!(
            reason.contains("3x2 disparity map, the sample is 2x3"),
            "{reason}"
        );
        let none = dir.path().join("none.pfm");
        assert_eq!(
            read_method_map(&none, (3, 2), false).unwrap_err().0,
            FailureKind::Missing
        );
        let link = dir.path().join("link.pfm");
        std::os::unix::fs::symlink(&pfm, &link).unwrap();
        assert_eq!(read_method_map(&link, (3, 2), true).unwrap().data, want);
        let (kind, reason) = read_method_map(&link, (3, 2), false).unwrap_err();
        assert_eq!(kind, FailureKind::BadOutput);
        assert!(reason.contains("not a regular file"), "{reason}");
        let txt = dir.path().join("a.txt");
        std::fs::write(&txt, "1").unwrap();
        assert!(read_method_map(&txt, (3, 2), false).is_err());
        // A file larger than any map of the size is refused before it is read.
        let big = dir.path().join("big.png");
        std::fs::write(&big, vec![0u8; 70_000]).unwrap();
        let (_, reason) = read_method_map(&big, (3, 2), false).unwrap_err();
        assert!(reason.contains("70000 bytes"), "{reason}");
    }
}
