//! Advisory file locks of a dataset folder, so that runs on one folder are safe or refused.
//!
//! - `DIR/.lock`, the dataset lock: `generate` without `--shard` and `index --rebuild` hold it
//!   exclusively (a second such run, or a shard, is refused with the holder's PID); shards of
//!   `generate --shard` and `index` (verifying) hold it shared, so shards run side by side.
//! - `samples/.lock-NNNNNN`, a sample lock: held exclusively while sample `NNNNNN` is checked,
//!   cleaned or rendered; another run that wants the same sample waits for it. A temporary
//!   folder `samples/.tmp-NNNNNN-PID/` is removed as stale only under this lock, so no run
//!   removes the folder of a live one.
//!
//! The locks are `flock`-style locks of std's [`File::lock`]: the system releases them when
//! their process ends, however it ends, so the lock file a killed run leaves behind is not
//! held and the next run takes it over. A lock file holds the holder's PID (for the messages
//! only). The last holder removes its lock file; a run that got the lock of a file removed
//! meanwhile opens the new one (checked by device and inode on Unix; elsewhere lock files are
//! kept).

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A lock that could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// The lock file cannot be created, opened, locked or written.
    #[error("cannot lock {}: {source}", path.display())]
    Io {
        /// The lock file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The lock path exists and is no regular file (a symbolic link, a folder, a FIFO...).
    #[error("cannot lock {}: it exists and is not a regular file", path.display())]
    NotAFile {
        /// The lock file.
        path: PathBuf,
    },
    /// Another live process holds the lock (and this run does not wait).
    #[error("{} is held by another run ({holder})", path.display())]
    Busy {
        /// The lock file.
        path: PathBuf,
        /// Who holds it, as its file says (`PID 1234 (streaks dataset generate)`).
        holder: String,
    },
}

/// Shared (many holders) or exclusive (one holder).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Many holders at once.
    Shared,
    /// One holder.
    Exclusive,
}

/// A held lock; released (and its file removed when no one else holds it) on drop.
#[derive(Debug)]
pub struct Lock {
    file: File,
    path: PathBuf,
    mode: Mode,
}

/// At most this many bytes of a lock file are read for the holder's description.
const HOLDER_BYTES: u64 = 200;

impl Lock {
    /// Takes the lock `path` in `mode`, creating the file if needed. If another process holds
    /// it: with `wait`, calls `waiting` with the holder's description and blocks until it is
    /// free; without, returns [`LockError::Busy`]. `what` describes this holder in the file.
    pub fn acquire(
        path: &Path,
        mode: Mode,
        what: &str,
        wait: bool,
        waiting: &dyn Fn(&str),
    ) -> Result<Lock, LockError> {
        let io = |source| LockError::Io {
            path: path.to_path_buf(),
            source,
        };
        loop {
            // A symbolic link would make the holder's line overwrite the file it points to.
            match std::fs::symlink_metadata(path) {
                Ok(m) if !m.file_type().is_file() => {
                    return Err(LockError::NotAFile {
                        path: path.to_path_buf(),
                    })
                }
                Ok(_) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(io(e)),
            }
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(path)
                .map_err(io)?;
            let tried = match mode {
                Mode::Shared => file.try_lock_shared(),
                Mode::Exclusive => file.try_lock(),
            };
            match tried {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => {
                    // The holder writes its line just after it gets the lock: give it a moment.
                    let mut holder = read_holder(&file);
                    for _ in 0..20 {
                        if holder.is_some() {
                            break;
                        }
                        std::thread::sleep(std::time::Duration::from_millis(5));
                        holder = read_holder(&file);
                    }
                    let holder = holder.unwrap_or_else(|| "an unknown process".to_owned());
                    if !wait {
                        return Err(LockError::Busy {
                            path: path.to_path_buf(),
                            holder,
                        });
                    }
                    waiting(&holder);
                    match mode {
                        Mode::Shared => file.lock_shared(),
                        Mode::Exclusive => file.lock(),
                    }
                    .map_err(io)?;
                }
                Err(TryLockError::Error(e)) => return Err(io(e)),
            }
            if !is_at(&file, path).map_err(io)? {
                // Its last holder removed it while this run waited: lock the new one.
                continue;
            }
            let line = format!("PID {} ({what})\n", std::process::id());
            let mut f = &file;
            f.set_len(0)
                .and_then(|()| f.seek(SeekFrom::Start(0)))
                .and_then(|_| f.write_all(line.as_bytes()))
                .map_err(io)?;
            return Ok(Lock {
                file,
                path: path.to_path_buf(),
                mode,
            });
        }
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        // The file is removed only by a sole holder: a shared holder lets go and tries to
        // take it exclusively (if another holds it, the file stays for the last one).
        let sole = match self.mode {
            Mode::Exclusive => true,
            Mode::Shared => self.file.unlock().is_ok() && self.file.try_lock().is_ok(),
        };
        if cfg!(unix) && sole && is_at(&self.file, &self.path).unwrap_or(false) {
            let _ = std::fs::remove_file(&self.path);
        }
        let _ = self.file.unlock();
    }
}

/// The holder's description in a lock file: its first line, printable, at most
/// [`HOLDER_BYTES`] bytes; `None` when empty.
fn read_holder(file: &File) -> Option<String> {
    let mut bytes = Vec::new();
    let mut f = file;
    let _ = f
        .seek(SeekFrom::Start(0))
        .and_then(|_| f.take(HOLDER_BYTES).read_to_end(&mut bytes));
    let text = String::from_utf8_lossy(&bytes);
    let line: String = text
        .lines()
        .next()
        .unwrap_or("")
        .chars()
        .filter(|c| !c.is_control())
        .collect();
    let line = line.trim();
    (!line.is_empty()).then(|| line.to_owned())
}

/// Whether the open `file` is still the file at `path` (same device and inode).
#[cfg(unix)]
fn is_at(file: &File, path: &Path) -> std::io::Result<bool> {
    use std::os::unix::fs::MetadataExt;
    let open = file.metadata()?;
    match std::fs::symlink_metadata(path) {
        Ok(now) => Ok(open.dev() == now.dev() && open.ino() == now.ino()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
        Err(e) => Err(e),
    }
}

/// Elsewhere lock files are never removed, so the open file is the one at `path`.
#[cfg(not(unix))]
fn is_at(_file: &File, _path: &Path) -> std::io::Result<bool> {
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exclusive_locks_exclude_and_shared_ones_share() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".lock");
        let a = Lock::acquire(&path, Mode::Exclusive, "a", false, &|_| {}).unwrap();
        match Lock::acquire(&path, Mode::Exclusive, "b", false, &|_| {}) {
            Err(LockError::Busy { holder, .. }) => {
                assert_eq!(holder, format!("PID {} (a)", std::process::id()))
            }
            other => panic!("{other:?}"),
        }
        let busy = |mode| {
            matches!(
                Lock::acquire(&path, mode, "b", false, &|_| {}),
                Err(LockError::Busy { .. })
            )
        };
        assert!(busy(Mode::Shared));
        drop(a);
        assert!(!path.exists(), "the sole holder removes its file");
        let s1 = Lock::acquire(&path, Mode::Shared, "s1", false, &|_| {}).unwrap();
        let s2 = Lock::acquire(&path, Mode::Shared, "s2", false, &|_| {}).unwrap();
        assert!(busy(Mode::Exclusive));
        drop(s1);
        assert!(path.exists(), "another shared holder keeps the file");
        drop(s2);
        assert!(!path.exists());
    }

    #[test]
    fn a_waiter_takes_the_lock_when_its_holder_ends() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".lock-000001");
        let held = Lock::acquire(&path, Mode::Exclusive, "first", false, &|_| {}).unwrap();
        let waited = std::sync::atomic::AtomicBool::new(false);
        std::thread::scope(|s| {
            let h = s.spawn(|| {
                Lock::acquire(&path, Mode::Exclusive, "second", true, &|holder| {
                    assert!(holder.contains("first"), "{holder}");
                    waited.store(true, std::sync::atomic::Ordering::SeqCst);
                })
                .unwrap()
            });
            while !waited.load(std::sync::atomic::Ordering::SeqCst) {
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
            drop(held);
            let second = h.join().unwrap();
            assert!(path.exists(), "the waiter locked the new file");
            drop(second);
        });
        assert!(!path.exists());
    }

    #[test]
    fn a_lock_path_that_is_a_symlink_is_refused_and_its_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("precious.txt");
        std::fs::write(&target, "keep me").unwrap();
        let path = dir.path().join(".lock");
        #[cfg(unix)]
        std::os::unix::fs::symlink(&target, &path).unwrap();
        #[cfg(not(unix))]
        std::fs::create_dir(&path).unwrap();
        let err = Lock::acquire(&path, Mode::Exclusive, "x", false, &|_| {}).unwrap_err();
        assert!(matches!(err, LockError::NotAFile { .. }), "{err}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");
    }
}
