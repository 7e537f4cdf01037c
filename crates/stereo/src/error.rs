//! The crate's error type.

use std::path::PathBuf;
use streaks_image::ImageError;

/// Errors from the stereo rig, its files and the image treatments.
#[derive(Debug, thiserror::Error)]
pub enum StereoError {
    /// The baseline is not a positive finite number of metres.
    #[error("invalid stereo baseline {0} m: it must be a positive finite number")]
    Baseline(f32),
    /// The intrinsics are unusable (zero or overflowing size, bad focal length).
    #[error("invalid camera intrinsics: {0}")]
    Intrinsics(String),
    /// The rig pose is not a rigid transform (finite, orthonormal, right-handed).
    #[error("invalid rig pose: {0}")]
    Pose(String),
    /// The road frame cannot be built (the camera looks straight up or down).
    #[error("no road frame: {0}")]
    RoadFrame(String),
    /// A rig.json file could not be read, parsed or written.
    #[error("rig file {path}: {reason}")]
    RigFile {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A Middlebury calib.txt could not be read or parsed.
    #[error("calibration file {path}: {reason}")]
    CalibFile {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The camera cannot be a rig's centre (an orthographic camera: a rectified pair needs
    /// a pinhole); the message says which and why.
    #[error("{0}")]
    Camera(String),
    /// Two images that must have the same size do not.
    #[error(transparent)]
    SizeMismatch(#[from] streaks_image::SizeMismatch),
    /// A parameter out of its range (texture-map ranges, resolution, shift, thresholds).
    #[error("invalid parameter {name}: {reason}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// Why.
        reason: String,
    },
    /// Reading or writing an image failed.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// Rendering failed (scene errors are reported by the renderer).
    #[error("rendering failed: {0}")]
    Render(String),
}
