//! Scene-loading errors: every variant names the file and, where there is one, the element
//! (buffer, image, mesh and primitive, node, camera, material) at fault.

use std::path::PathBuf;
use thiserror::Error;

/// Why a scene could not be loaded or built.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The file name's extension is not one we load.
    #[error("{path}: unsupported scene format (expected .gltf, .glb or .obj)")]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
    /// The file (or one it refers to) could not be read.
    #[error("{path}: cannot read {element}")]
    Io {
        /// The scene file.
        path: PathBuf,
        /// What was being read (e.g. `buffer 0 ("road.bin" -> /x/road.bin)`).
        element: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The glTF JSON or GLB container is malformed or fails validation.
    #[error("{path}: invalid glTF")]
    Gltf {
        /// The file.
        path: PathBuf,
        /// The parser's error.
        source: gltf::Error,
    },
    /// The OBJ file could not be parsed.
    #[error("{path}: invalid OBJ")]
    Obj {
        /// The file.
        path: PathBuf,
        /// The parser's error.
        source: tobj::LoadError,
    },
    /// An element of the scene is invalid: a buffer, image, accessor, node transform, camera,
    /// light or material.
    #[error("{path}: {element}: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The element, e.g. `mesh "road" (0), primitive 1, attribute POSITION`.
        element: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A file the scene names is outside the scene's folder (an absolute path, a `file:` URI,
    /// a `..` leaving the folder, a symbolic link out of it), and reading outside was not
    /// allowed ([`super::LoadOptions::allow_outside`]).
    #[error(
        "{path}: {element}: refused {uri:?}: {reason}; a scene reads only files inside its \
         folder unless reading outside is allowed"
    )]
    OutsideFolder {
        /// The scene file.
        path: PathBuf,
        /// The element naming the file, e.g. `buffer 0` or `mtllib`.
        element: String,
        /// The name or URI as the file gives it.
        uri: String,
        /// Why it is outside.
        reason: String,
    },
    /// The file requires a glTF extension the loader does not honour.
    #[error("{path}: requires the glTF extension {extension}, which is not supported: {advice}")]
    UnsupportedExtension {
        /// The file.
        path: PathBuf,
        /// The extension, as named in `extensionsRequired`.
        extension: String,
        /// What it means and what to do instead.
        advice: String,
    },
    /// The scene has no camera at all.
    #[error("{path}: scene has no camera")]
    NoCamera {
        /// The file.
        path: PathBuf,
    },
    /// No camera has the requested name.
    #[error("{path}: no camera named {name:?} (available: {available})")]
    UnknownCamera {
        /// The file.
        path: PathBuf,
        /// The requested name.
        name: String,
        /// The cameras the scene has, comma-separated.
        available: String,
    },
}

impl SceneError {
    /// Shorthand for [`SceneError::Invalid`].
    pub fn invalid(
        path: impl Into<PathBuf>,
        element: impl Into<String>,
        reason: impl Into<String>,
    ) -> Self {
        Self::Invalid {
            path: path.into(),
            element: element.into(),
            reason: reason.into(),
        }
    }
}
