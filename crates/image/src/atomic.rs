//! Atomic writes: every file this project writes (images, maps, JSON, scenes) goes through
//! [`write_atomically`]. The bytes go to a uniquely named temporary file in the destination's
//! folder (`.NAME.XXXXXX.tmp`, so two writers of the same file never collide), which is
//! flushed, synced and renamed onto the destination only once it is complete: an interrupted
//! or failed write never leaves a truncated file, and the destination is either its previous
//! version or the new one. The file gets the usual permissions (`0o666` less the umask).

use crate::ImageError;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Why [`write_atomically`]'s writer callback failed.
#[derive(Debug)]
pub enum WriteFailure {
    /// An I/O error.
    Io(std::io::Error),
    /// An EXR encoder error.
    Exr(exr::error::Error),
    /// A PNG encoder error.
    Png(image::ImageError),
}

impl From<std::io::Error> for WriteFailure {
    fn from(e: std::io::Error) -> Self {
        WriteFailure::Io(e)
    }
}

/// Writes `path` atomically (see the module documentation): `write` fills a buffered
/// temporary file in the same folder. On any failure the temporary file is removed and `path`
/// is left as it was (absent or the previous version).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), WriteFailure>,
) -> Result<(), ImageError> {
    let io_err = |source| ImageError::Write {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let file_name = path.file_name().ok_or_else(|| {
        io_err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the path names no file",
        ))
    })?;
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(file_name);
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(dir).map_err(io_err)?;
    let (file, tmp_path) = tmp.into_parts();
    let mut writer = BufWriter::new(file);
    let result = write(&mut writer).and_then(|()| {
        let file = writer
            .into_inner()
            .map_err(|e| WriteFailure::Io(e.into_error()))?;
        file.sync_all().map_err(WriteFailure::Io)
    });
    match result {
        // `tmp_path` deletes the temporary file when dropped on the error paths.
        Err(WriteFailure::Io(source)) => Err(io_err(source)),
        Err(WriteFailure::Exr(source)) => Err(ImageError::Exr {
            path: path.to_path_buf(),
            source,
        }),
        Err(WriteFailure::Png(source)) => Err(ImageError::Png {
            path: path.to_path_buf(),
            source,
        }),
        Ok(()) => tmp_path.persist(path).map_err(|e| io_err(e.error)),
    }
}

/// [`write_atomically`] of bytes already in memory.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    write_atomically(path, |w| w.write_all(bytes).map_err(WriteFailure::Io))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        // The destination is a folder: the final rename fails.
        let target = dir.path().join("taken.exr");
        std::fs::create_dir(&target).unwrap();
        let err = write_bytes_atomically(&target, b"x").unwrap_err();
        assert!(matches!(err, ImageError::Write { .. }), "{err}");
        // A writer that fails half-way.
        let path = dir.path().join("half.png");
        let err = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err(WriteFailure::Io(std::io::Error::other("disk full")))
        })
        .unwrap_err();
        assert!(err.to_string().contains("half.png"), "{err}");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("taken.exr")]);
        // A missing folder.
        assert!(write_bytes_atomically(&dir.path().join("no/such.json"), b"{}").is_err());
    }

    #[test]
    fn replaces_the_file_and_leaves_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.json");
        write_bytes_atomically(&path, b"one").unwrap();
        write_bytes_atomically(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode();
            assert_eq!(
                mode & 0o644,
                0o644,
                "readable by all under a usual umask: {mode:o}"
            );
        }
    }

    #[test]
    fn two_writers_of_one_file_do_not_collide() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("shared.pfm");
        std::thread::scope(|s| {
            for k in 0..8u8 {
                let path = &path;
                s.spawn(move || {
                    for _ in 0..20 {
                        write_bytes_atomically(path, &[k; 4096]).unwrap();
                    }
                });
            }
        });
        // Whoever won, the file is one writer's whole content.
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len(), 4096);
        assert!(bytes.iter().all(|&b| b == bytes[0]));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
