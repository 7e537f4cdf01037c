//! [`SensorError`]: what can go wrong reading a profile or exposing an image; each names the
//! profile (file or preset) and the field, or the image.

use std::path::PathBuf;

/// An error of this crate.
#[derive(Debug, thiserror::Error)]
pub enum SensorError {
    /// A profile file could not be read.
    #[error("cannot read the sensor profile {path}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A profile is not valid TOML for a profile (the message names an unknown or mistyped
    /// field).
    #[error("sensor profile {source_name}: {message}")]
    Parse {
        /// The file or the preset.
        source_name: String,
        /// The parser's message.
        message: String,
    },
    /// A field of a profile is out of its range.
    #[error("sensor profile {source_name}: {field} {reason}")]
    Field {
        /// The file or the preset.
        source_name: String,
        /// The field.
        field: &'static str,
        /// What is wrong with its value.
        reason: String,
    },
    /// `--sensor` named no preset and no file.
    #[error("no sensor preset {name:?} (the presets are {presets}; a profile file's path contains a / or ends in .toml)")]
    UnknownPreset {
        /// The name given.
        name: String,
        /// The presets' names.
        presets: String,
    },
    /// The image or the camera geometry given to the sensor cannot be exposed.
    #[error("cannot expose the image: {0}")]
    Image(String),
}
