//! # streaks-stereo
//!
//! Stereo geometry and images (skeleton; the stereo work fills it in).
//!
//! - [`image`]: the single-channel float image used by the stereo and analysis code.
//! - [`pfm`]: PFM disparity and depth maps (Middlebury convention).
#![deny(missing_docs)]

pub mod image;
pub mod pfm;
