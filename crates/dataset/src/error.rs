//! The crate's error type.

use std::path::{Path, PathBuf};
use streaks_image::ImageError;
use streaks_stereo::error::StereoError;

pub use crate::lock::LockError;
pub use crate::manifest::ManifestError;

/// Errors from reading, writing and checking a sample folder or a dataset folder. Each names
/// the file it is about.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// A file or folder cannot be read, listed, created or removed.
    #[error("cannot {action} {}: {source}", path.display())]
    Io {
        /// What was tried (`read`, `list`, `create the folder`...).
        action: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A JSON file does not parse as what it should hold.
    #[error("{} is not {what}: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// What it should be (`a dataset.json of streaks-dataset/1`, `a sample's meta.json`).
        what: String,
        /// The parser's error.
        source: serde_json::Error,
    },
    /// A file parses but its contents are refused.
    #[error("{}: {reason}", path.display())]
    Invalid {
        /// The file or folder.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A folder is neither a sample nor a `streaks stereo` pair folder.
    #[error(
        "{} is not a sample folder (no {left} and {right}, nor the older {old_left} and {old_right})",
        path.display()
    )]
    NotASample {
        /// The folder.
        path: PathBuf,
        /// The left image's name.
        left: &'static str,
        /// The right image's name.
        right: &'static str,
        /// The left image's name in the older pair layout.
        old_left: &'static str,
        /// The right image's name in the older pair layout.
        old_right: &'static str,
    },
    /// A file a sample must have is missing.
    #[error("the sample {} lacks {file}", dir.display())]
    Missing {
        /// The sample folder.
        dir: PathBuf,
        /// The file's name.
        file: String,
    },
    /// Files a sample must have are missing.
    #[error("missing {what}: {}", files.join(", "))]
    MissingFiles {
        /// The sample folder.
        dir: PathBuf,
        /// Which files (`files`, `KITTI files`).
        what: &'static str,
        /// Their names in the folder (or paths relative to the dataset folder).
        files: Vec<String>,
    },
    /// An entry of a sample that must be a regular file (or the sample's folder) is not.
    #[error("{file} is {kind}")]
    NotRegular {
        /// The entry, relative to the dataset folder.
        file: String,
        /// What it is instead (`a symbolic link`, `a folder`, `a special file`, `not a file`).
        kind: &'static str,
    },
    /// A sample's scene refers to a file outside the sample's folder.
    #[error("{file} refers to {uri:?}, not a file of the sample's folder")]
    OutsideSample {
        /// The scene file's name.
        file: &'static str,
        /// The reference.
        uri: String,
    },
    /// An image, map or calibration has another size than the one it must have.
    #[error(
        "{} is {}x{}, {against} {}x{}",
        path.display(),
        size.0,
        size.1,
        expected.0,
        expected.1
    )]
    WrongSize {
        /// The file.
        path: PathBuf,
        /// Its width and height in pixels.
        size: (usize, usize),
        /// The size it must have.
        expected: (usize, usize),
        /// What gives that size, as the message says it (`the dataset's images are`).
        against: &'static str,
    },
    /// A split name that datasets do not have.
    #[error("--split {name}: a dataset's splits are {known}")]
    UnknownSplit {
        /// The name asked for.
        name: String,
        /// The splits there are.
        known: String,
    },
    /// A split file cannot be read (the dataset was not indexed).
    #[error(
        "cannot read the split {} (run `streaks dataset index {}`): {source}",
        path.display(),
        root.display()
    )]
    Split {
        /// The split file.
        path: PathBuf,
        /// The dataset folder.
        root: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A dataset (or one of its splits) has no samples.
    #[error("the dataset {} has no samples{}", root.display(), split.as_ref().map(|s| format!(" in its {s} split")).unwrap_or_default())]
    NoSamples {
        /// The dataset folder.
        root: PathBuf,
        /// The split asked for.
        split: Option<String>,
    },
    /// An existing `dataset.json` describes another dataset than the one asked for.
    #[error(
        "{} describes another dataset: its {field} is {old}, this run's is {new}{hint}; \
         datasets are not mixed: write into another folder (or remove this one)",
        path.display()
    )]
    OtherDataset {
        /// The existing `dataset.json`.
        path: PathBuf,
        /// The first field that differs (`a.b.c`).
        field: String,
        /// Its value in the file.
        old: String,
        /// This run's value.
        new: String,
        /// How to continue the existing dataset, when the field says so.
        hint: &'static str,
    },
    /// An image or PFM file cannot be read or written.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// A rig, calibration or stereo file cannot be read or written.
    #[error(transparent)]
    Stereo(#[from] StereoError),
    /// `manifest.jsonl` is refused.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// A lock cannot be taken.
    #[error(transparent)]
    Lock(#[from] LockError),
}

impl DatasetError {
    /// An I/O error of `action` on `path`.
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            action,
            path: path.into(),
            source,
        }
    }

    /// `Ok` when the file `path` of `size` (width, height) has the `expected` size, else
    /// [`DatasetError::WrongSize`]; `against` says what gives that size.
    pub fn check_size(
        path: &Path,
        size: (usize, usize),
        expected: (usize, usize),
        against: &'static str,
    ) -> Result<(), Self> {
        if size == expected {
            Ok(())
        } else {
            Err(Self::WrongSize {
                path: path.to_path_buf(),
                size,
                expected,
                against,
            })
        }
    }
}
