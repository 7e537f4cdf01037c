//! # streaks-image
//!
//! The image layer that the renderer, the stereo code and the analysis share, one concept per
//! module:
//!
//! - [`rgb`]: [`RgbImage`], a linear RGB float image (a render);
//! - [`gray`]: [`GrayImage`], a single-channel float image (grey levels, disparity, depth,
//!   masks), and loading any image file as grey levels or channels;
//! - [`region`]: [`Region`] and [`NamedRegion`], rectangles of pixels, with the one parser of
//!   `[name=]x0,y0,x1,y1`;
//! - [`color`]: [`luminance`] and the sRGB transfer functions;
//! - [`develop`](mod@develop): [`develop()`], a render through the exposure, the clip and the sRGB tone
//!   curve to the 8-bit image every PNG of a render holds;
//! - [`atomic`]: [`write_atomically`], through which every file of the project is written
//!   (a uniquely named temporary file, then a rename);
//! - [`exr`], [`png`], [`pfm`]: reading and writing the three formats (EXR with named float
//!   channels; PNG as 8-bit sRGB or any 8/16-bit buffer; PFM in the Middlebury convention);
//! - [`input`]: reading files that may be hostile: regular files only, capped reads, images
//!   checked against a pixel limit from their header ([`input::MAX_PIXELS`]);
//! - [`kitti`]: disparity maps in the KITTI 2015 encoding (16-bit PNG, disparity x 256);
//!   optical flow in KITTI's (16-bit RGB, flow x 64 + 2^15, valid);
//! - [`flow_color`]: the Middlebury colour coding of optical flow;
//! - [`stats`]: quantiles and medians of pixel values (nearest rank, and the two other
//!   definitions the project's numbers depend on);
//! - [`denoise`]: [`denoise::Denoiser`], Intel Open Image Denoise loaded at run time, which
//!   denoises a render guided by its albedo and normal layers;
//! - [`compare`]: statistics of the difference between two images (relative RMSE, bias, the
//!   noise test), per region;
//! - [`size`]: [`ensure_same_size`] and its [`SizeMismatch`], the one size check that the
//!   other crates' errors wrap;
//! - [`error`]: [`ImageError`], which names the file or the region.
//!
//! ```
//! use streaks_image::{pfm, GrayImage, NamedRegion};
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("disparity.pfm");
//! let mut map = GrayImage::new(4, 3, f32::INFINITY)?;
//! map.set(1, 2, 12.5);
//! pfm::write_pfm(&path, &map)?;
//! assert_eq!(pfm::read_pfm(&path)?, map);
//!
//! let road: NamedRegion = "road=0,2,4,3".parse()?;
//! assert!(road.region.fits(map.width, map.height));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

pub mod atomic;
pub mod color;
pub mod compare;
pub mod denoise;
pub mod develop;
pub mod error;
pub mod exr;
pub mod flow_color;
pub mod gray;
pub mod input;
pub mod kitti;
pub mod pfm;
pub mod png;
pub mod region;
pub mod rgb;
pub mod size;
pub mod stats;

pub use atomic::{write_atomically, write_bytes_atomically, WriteFailure};
pub use color::luminance;
pub use develop::develop;
pub use error::ImageError;
pub use gray::GrayImage;
pub use region::{NamedRegion, Region};
pub use rgb::RgbImage;
pub use size::{ensure_pair_size, ensure_same_size, SizeMismatch};
