//! The files a scene names, and the limits of what loading it may read and decode.
//!
//! A scene file is untrusted input: every file it names (a glTF buffer or image, an OBJ's
//! `mtllib`, an MTL's texture map) is read through [`Files`], which
//!
//! - resolves the name inside the folder of the scene file, and refuses (unless
//!   [`LoadOptions::allow_outside`]) an absolute path, a `file:` URI, a `..` that leaves the
//!   folder and a symbolic link that points out of it (the resolved path is canonicalized
//!   and must stay under the canonical folder); any other URI scheme than `data:` is
//!   refused always;
//! - reads only regular files: a FIFO, a device, a socket or a folder is refused from its
//!   metadata before it is opened, even when reading outside is allowed
//!   ([`streaks_image::input::open_regular`]);
//! - reads no more than it needs: a buffer's `byteLength` bytes, checked against the file's
//!   size first; other files up to [`LoadOptions::max_file_bytes`].
//!
//! Decoded data is bounded too: compressed geometry (meshopt, Draco) by
//! [`LoadOptions::max_decoded_bytes`] over the whole scene, images by
//! [`streaks_image::input::MAX_PIXELS`] from their headers, and the vertex data read from
//! accessors by [`EXPANSION`] times the bytes of the scene's files (its JSON or GLB, its
//! buffers and its decoded geometry) plus [`EXPANSION_SLACK`]: an accessor is checked against
//! its bufferView, but a thousand primitives or placements can read the same one.

use super::SceneError;
use std::cell::Cell;
use std::path::{Component, Path, PathBuf};

/// How many times the bytes of a scene's files its accessors may decode to: 16 (quantized 8-bit
/// values become 32-bit floats, 4 times larger, and an emissive mesh is read once per
/// placement).
pub(super) const EXPANSION: u64 = 16;

/// What a scene's accessors may decode to on top of [`EXPANSION`] times its files' bytes:
/// 64 MiB, so that small files placing a mesh many times still load.
pub(super) const EXPANSION_SLACK: u64 = 64 << 20;

/// What loading a scene may read and decode ([`super::Scene::load_with`]).
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Read files the scene names outside its folder: absolute paths, `file:` URIs, `..`
    /// out of the folder, symbolic links out of it. Off by default: a scene from elsewhere
    /// could otherwise read any file the user can. Non-regular files (FIFOs, devices) are
    /// refused even then.
    pub allow_outside: bool,
    /// The largest file read (the scene file, a buffer, an image, a material library), in
    /// bytes: 4 GiB by default, the largest a GLB can be.
    pub max_file_bytes: u64,
    /// The most bytes compressed geometry (EXT_meshopt_compression,
    /// KHR_draco_mesh_compression) may decode to over the whole scene: 1 GiB by default.
    pub max_decoded_bytes: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            allow_outside: false,
            max_file_bytes: 4 << 30,
            max_decoded_bytes: 1 << 30,
        }
    }
}

/// Why a name was refused before anything was read.
enum Refusal {
    /// Outside the folder (absolute, `file:`, `..`, a symbolic link); allowed by the option.
    Outside(String),
    /// Refused always (an unsupported scheme, undecodable escapes).
    Invalid(String),
}

/// Reads the files one scene file names (see the module documentation).
pub(super) struct Files<'a> {
    /// The scene file, named in every error.
    scene: &'a Path,
    /// Its folder, as given (names are joined to it).
    folder: PathBuf,
    /// The options.
    options: &'a LoadOptions,
    /// Decoded bytes still allowed ([`LoadOptions::max_decoded_bytes`] less what was decoded).
    decode_budget: Cell<u64>,
    /// Bytes of the scene's files read and of its decoded geometry.
    backing: Cell<u64>,
    /// Bytes of vertex data its accessors have decoded.
    expanded: Cell<u64>,
}

/// An encoded payload named by a URI: the bytes of a `data:` URI, or a file to read.
pub(super) enum Uri {
    /// The decoded bytes of a `data:` URI and its media type.
    Data(Vec<u8>, Option<String>),
    /// A file, resolved and checked, to read.
    File(PathBuf),
}

impl<'a> Files<'a> {
    /// The files named by `scene`, under `options`.
    pub(super) fn new(scene: &'a Path, options: &'a LoadOptions) -> Self {
        let folder = match scene.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Self {
            scene,
            folder,
            options,
            decode_budget: Cell::new(options.max_decoded_bytes),
            backing: Cell::new(0),
            expanded: Cell::new(0),
        }
    }

    /// The scene file's folder, against which names resolve.
    pub(super) fn folder(&self) -> &Path {
        &self.folder
    }

    /// The scene file itself, whole, within [`LoadOptions::max_file_bytes`].
    pub(super) fn read_scene(&self) -> Result<Vec<u8>, SceneError> {
        let bytes = streaks_image::input::read_file(self.scene, self.options.max_file_bytes)
            .map_err(|source| SceneError::Io {
                path: self.scene.to_path_buf(),
                element: "the file".into(),
                source,
            })?;
        self.add_backing(bytes.len());
        Ok(bytes)
    }

    /// Counts `bytes` of the scene's data toward what its accessors may decode to.
    fn add_backing(&self, bytes: usize) {
        self.backing
            .set(self.backing.get().saturating_add(bytes as u64));
    }

    /// Takes `bytes` of vertex data an accessor is about to decode from what the scene's
    /// files allow ([`EXPANSION`]), or returns the reason it is exceeded.
    pub(super) fn charge_expanded(&self, bytes: u64) -> Result<(), String> {
        let spent = self.expanded.get().saturating_add(bytes);
        let limit = self
            .backing
            .get()
            .saturating_mul(EXPANSION)
            .saturating_add(EXPANSION_SLACK);
        if spent > limit {
            return Err(format!(
                "reading it would bring the vertex data decoded from the scene's accessors to \
                 {spent} bytes, more than {EXPANSION} times the {} bytes of its files plus \
                 {EXPANSION_SLACK} (is one accessor read by very many primitives or \
                 placements?)",
                self.backing.get()
            ));
        }
        self.expanded.set(spent);
        Ok(())
    }

    /// Resolves the relative file name `name` (an OBJ's `mtllib`, an MTL's map, a glTF URI
    /// after percent-decoding) that `element` names, inside the scene's folder unless
    /// reading outside is allowed, to a regular file.
    pub(super) fn resolve(&self, name: &Path, element: &str) -> Result<PathBuf, SceneError> {
        let shown = name.display().to_string();
        self.check(name)
            .map_err(|r| self.refused(r, element, &shown))?;
        let path = self.folder.join(name);
        let io = |source| SceneError::Io {
            path: self.scene.to_path_buf(),
            element: format!("{element} ({shown:?} -> {})", path.display()),
            source,
        };
        // Metadata follows symbolic links and opens nothing: a FIFO is refused here.
        streaks_image::input::check_regular(&path).map_err(io)?;
        if self.options.allow_outside {
            return Ok(path);
        }
        let canonical = std::fs::canonicalize(&path).map_err(io)?;
        let folder = std::fs::canonicalize(&self.folder).map_err(io)?;
        if !canonical.starts_with(&folder) {
            return Err(self.refused(
                Refusal::Outside(format!(
                    "it resolves (through a symbolic link) to {}, outside {}",
                    canonical.display(),
                    folder.display()
                )),
                element,
                &shown,
            ));
        }
        Ok(canonical)
    }

    /// Checks a name before it is resolved: relative, and no `..` leaving the folder (unless
    /// reading outside is allowed).
    fn check(&self, name: &Path) -> Result<(), Refusal> {
        if self.options.allow_outside {
            return Ok(());
        }
        let mut depth = 0usize;
        for c in name.components() {
            match c {
                Component::Prefix(_) | Component::RootDir => {
                    return Err(Refusal::Outside("it is an absolute path".into()))
                }
                Component::ParentDir if depth == 0 => {
                    return Err(Refusal::Outside(format!(
                        "its \"..\" leaves the folder {}",
                        self.folder.display()
                    )))
                }
                Component::ParentDir => depth -= 1,
                Component::Normal(_) => depth += 1,
                Component::CurDir => {}
            }
        }
        Ok(())
    }

    /// The error for a refused name.
    fn refused(&self, refusal: Refusal, element: &str, uri: &str) -> SceneError {
        match refusal {
            Refusal::Outside(reason) => SceneError::OutsideFolder {
                path: self.scene.to_path_buf(),
                element: element.to_string(),
                uri: uri.to_string(),
                reason,
            },
            Refusal::Invalid(reason) => SceneError::invalid(self.scene, element, reason),
        }
    }

    /// Parses a glTF URI: a `data:` URI is decoded (its size is bounded by the scene file's,
    /// already read), a relative reference is percent-decoded and resolved
    /// ([`Files::resolve`]); a `file:` URI is a path outside the folder (allowed only with
    /// [`LoadOptions::allow_outside`]); any other scheme is refused.
    pub(super) fn uri(&self, uri: &str, element: &str) -> Result<Uri, SceneError> {
        let bad = |reason: String| SceneError::invalid(self.scene, element, reason);
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((media, payload)) = rest.split_once(";base64,") else {
                return Err(bad(
                    "a data URI must be base64 (data:<type>;base64,<data>)".into()
                ));
            };
            let bytes = base64::decode(payload)
                .map_err(|e| bad(format!("its data URI is not valid base64: {e}")))?;
            self.add_backing(bytes.len());
            let media = (!media.is_empty()).then(|| media.to_string());
            return Ok(Uri::Data(bytes, media));
        }
        let name = match scheme(uri) {
            Some(file) if file.eq_ignore_ascii_case("file") => {
                if !self.options.allow_outside {
                    return Err(self.refused(
                        Refusal::Outside("it is a file: URI, which names any file".into()),
                        element,
                        uri,
                    ));
                }
                let rest = &uri[file.len() + 1..];
                rest.strip_prefix("//").unwrap_or(rest)
            }
            Some(other) => {
                return Err(self.refused(
                    Refusal::Invalid(format!(
                        "the URI {uri:?} has the scheme {other:?}; only data: URIs and \
                         relative file names are read"
                    )),
                    element,
                    uri,
                ))
            }
            None => uri,
        };
        let decoded = urlencoding::decode(name).map_err(|_| {
            self.refused(
                Refusal::Invalid(format!("the URI {uri:?} has escapes that are not UTF-8")),
                element,
                uri,
            )
        })?;
        self.resolve(Path::new(decoded.as_ref()), element)
            .map(Uri::File)
    }

    /// Reads the first `len` bytes of the resolved file `path` for `element`: an error
    /// before anything is reserved if the file is shorter or `len` is beyond
    /// [`LoadOptions::max_file_bytes`].
    pub(super) fn read_prefix(
        &self,
        path: &Path,
        len: u64,
        element: &str,
    ) -> Result<Vec<u8>, SceneError> {
        if len > self.options.max_file_bytes {
            return Err(SceneError::invalid(
                self.scene,
                element,
                format!(
                    "{len} bytes, more than the limit of {}",
                    self.options.max_file_bytes
                ),
            ));
        }
        let bytes =
            streaks_image::input::read_file_prefix(path, len).map_err(|source| SceneError::Io {
                path: self.scene.to_path_buf(),
                element: element.to_string(),
                source,
            })?;
        self.add_backing(bytes.len());
        Ok(bytes)
    }

    /// Reads the whole resolved file `path` for `element`, within
    /// [`LoadOptions::max_file_bytes`].
    pub(super) fn read(&self, path: &Path, element: &str) -> Result<Vec<u8>, SceneError> {
        streaks_image::input::read_file(path, self.options.max_file_bytes).map_err(|source| {
            SceneError::Io {
                path: self.scene.to_path_buf(),
                element: element.to_string(),
                source,
            }
        })
    }

    /// The decoded bytes still allowed.
    pub(super) fn decode_budget(&self) -> u64 {
        self.decode_budget.get()
    }

    /// Takes `bytes` of decoded data from the budget, or returns the reason it is exceeded.
    pub(super) fn charge_decoded(&self, bytes: u64) -> Result<(), String> {
        let left = self.decode_budget.get();
        if bytes > left {
            return Err(format!(
                "decodes to {bytes} bytes, more than the {left} left of the limit of {} on \
                 decoded geometry",
                self.options.max_decoded_bytes
            ));
        }
        self.decode_budget.set(left - bytes);
        self.add_backing(bytes as usize);
        Ok(())
    }
}

/// The scheme of an absolute URI (RFC 3986: a letter, then letters, digits, `+`, `-` or
/// `.`, then `:`), lowercased; `None` for a relative reference.
fn scheme(uri: &str) -> Option<&str> {
    let (scheme, _) = uri.split_once(':')?;
    let mut chars = scheme.chars();
    let valid = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
    // A name with a colon after a slash ("textures/a:b.png") is a relative path.
    (valid || !scheme.contains('/')).then_some(scheme)
}
