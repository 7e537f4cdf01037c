//! The errors of image reading, writing and comparison; each names the file or the region.

use std::path::PathBuf;

/// A region's name followed by a space, or nothing for an unnamed region.
fn labelled(name: &str) -> String {
    if name.is_empty() {
        String::new()
    } else {
        format!("{name} ")
    }
}

/// An error of this crate.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// A file could not be read or decoded.
    #[error("cannot read image {path}: {reason}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// Creating, writing, syncing or renaming a file failed.
    #[error("cannot write {path}")]
    Write {
        /// The destination.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The EXR encoder or decoder failed (also: the file is not an EXR).
    #[error("EXR error in {path}")]
    Exr {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: exr::error::Error,
    },
    /// The PNG encoder failed.
    #[error("PNG error in {path}")]
    Png {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: image::ImageError,
    },
    /// An EXR has no channels of the requested names.
    #[error("{path} has no {what}")]
    MissingChannels {
        /// The file.
        path: PathBuf,
        /// What was looked for, e.g. `R, G, B channels`.
        what: String,
    },
    /// An image to write has no pixels, or a pixel count that does not match its size.
    #[error("cannot write {path}: {reason}")]
    BadImage {
        /// The destination.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A zero or overflowing size, or data that does not fit the size.
    #[error("invalid image size {width}x{height}: {reason}")]
    Size {
        /// Width asked for.
        width: u64,
        /// Height asked for.
        height: u64,
        /// Why it is invalid.
        reason: &'static str,
    },
    /// Two images that must have the same size do not.
    #[error(transparent)]
    SizeMismatch(#[from] crate::SizeMismatch),
    /// A region does not parse.
    #[error("bad region {text:?}: {reason} (expected {expected})")]
    BadRegion {
        /// The text given.
        text: String,
        /// What is wrong.
        reason: String,
        /// The form expected: `x0,y0,x1,y1` or `[name=]x0,y0,x1,y1`.
        expected: &'static str,
    },
    /// A masked region marks no pixel.
    #[error("the mask {name} marks no pixel")]
    EmptyMask {
        /// The mask's name.
        name: String,
    },
    /// A region is empty or extends past the image.
    #[error(
        "region {}({x0},{y0})-({x1},{y1}) is empty or outside the {width}x{height} image",
        labelled(.name)
    )]
    RegionOutside {
        /// Region name (empty for an unnamed one).
        name: String,
        /// Left.
        x0: usize,
        /// Top.
        y0: usize,
        /// Right (exclusive).
        x1: usize,
        /// Bottom (exclusive).
        y1: usize,
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
    },
}
