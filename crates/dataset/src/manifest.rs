//! Reading `manifest.jsonl` back, and checking the files on disk against it.
//!
//! The manifest is read as untrusted input: each line is at most [`MAX_LINE_BYTES`] bytes,
//! there are at most `count` lines, every line names a sample of the dataset once, and every
//! path it lists is one of that sample's own files (`samples/NNNNNN/NAME` or its three KITTI
//! files), so nothing outside the dataset folder is ever read. Errors name the line.
//! Checking never follows a symbolic link and never opens anything but a regular file.

use crate::layout::{sample_id, Layout};
use rayon::prelude::*;
use serde::Deserialize;
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// sha256 of bytes, lowercase hex (as the manifest lists files).
pub fn sha256_hex(bytes: &[u8]) -> String {
    format!("{:x}", Sha256::digest(bytes))
}

/// The longest line accepted (a sample's line is a few kilobytes).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// What is wrong with a `manifest.jsonl`.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The file cannot be opened or read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The manifest.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The manifest path is no regular file.
    #[error("{} is not a regular file", path.display())]
    NotAFile {
        /// The manifest.
        path: PathBuf,
    },
    /// A line is longer than [`MAX_LINE_BYTES`].
    #[error("{} line {line}: longer than {MAX_LINE_BYTES} bytes", path.display())]
    LineTooLong {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
    },
    /// More lines than the dataset has samples.
    #[error("{} line {line}: more lines than the dataset's {count} samples", path.display())]
    TooManyLines {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
        /// The dataset's count.
        count: u64,
    },
    /// A line is not a JSON object with `id`, `index` and `files`.
    #[error("{} line {line}: not a manifest line: {source}", path.display())]
    Json {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
        /// The parser's error.
        source: serde_json::Error,
    },
    /// `index` is outside `0..count`, or `id` is not its six-digit id.
    #[error(
        "{} line {line}: id {id:?} with index {index} is no sample of this dataset (ids 000000 \
         to {last})", path.display()
    )]
    NotASample {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
        /// The line's id.
        id: String,
        /// The line's index.
        index: u64,
        /// The last id of the dataset.
        last: String,
    },
    /// A sample is listed twice.
    #[error("{} line {line}: sample {id} is listed again (first on line {first})", path.display())]
    Duplicate {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
        /// The sample id.
        id: String,
        /// The line that listed it first.
        first: usize,
    },
    /// A listed path is not one of the sample's own files (`..`, absolute, another folder).
    #[error(
        "{} line {line}: {file:?} is not a file of sample {id} (samples/{id}/NAME or its KITTI \
         files)", path.display()
    )]
    ForeignPath {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
        /// The sample id.
        id: String,
        /// The listed path.
        file: String,
    },
    /// A listed hash is not 64 lowercase hexadecimal digits.
    #[error("{} line {line}: the sha256 of {file:?} is not 64 lowercase hex digits", path.display())]
    BadHash {
        /// The manifest.
        path: PathBuf,
        /// The line number (from 1).
        line: usize,
        /// The listed path.
        file: String,
    },
}

/// The index of a manifest line (the rest is skipped by the parser, unallocated).
#[derive(Deserialize)]
struct IndexOnly {
    index: u64,
}

/// The part of a manifest line that checking needs.
#[derive(Deserialize)]
struct RawLine {
    id: String,
    #[serde(default)]
    split: String,
    #[serde(default)]
    street: u64,
    files: BTreeMap<String, String>,
}

/// One sample as the manifest lists it.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The line number (from 1).
    pub line: usize,
    /// The sample index.
    pub index: u64,
    /// Its split, as the line names it.
    pub split: String,
    /// Its street, as the line names it.
    pub street: u64,
    /// sha256 of each file, by path relative to the dataset folder (validated).
    pub files: BTreeMap<String, String>,
}

/// A read and validated `manifest.jsonl`.
#[derive(Clone, Debug, Default)]
pub struct Manifest {
    /// The samples, in the order of the file.
    pub entries: Vec<Entry>,
    by_index: HashMap<u64, usize>,
}

/// Opens `layout`'s manifest (a regular file, never a link or a FIFO); `None` if there is none.
fn open(layout: &Layout) -> Result<Option<(BufReader<std::fs::File>, PathBuf)>, ManifestError> {
    let path = layout.manifest();
    match std::fs::symlink_metadata(&path) {
        Ok(m) if m.file_type().is_file() => {}
        Ok(_) => return Err(ManifestError::NotAFile { path }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => return Err(ManifestError::Io { path, source }),
    }
    let file = std::fs::File::open(&path).map_err(|source| ManifestError::Io {
        path: path.clone(),
        source,
    })?;
    Ok(Some((BufReader::new(file), path)))
}

impl Manifest {
    /// Reads `layout`'s manifest of a dataset of `count` samples; `None` if there is none.
    /// Only the samples for which `keep` holds are kept (and their files checked): a shard
    /// of a large dataset holds its own lines only; every line is still checked to be JSON,
    /// of a sample of the dataset, and listed once.
    pub fn load(
        layout: &Layout,
        count: u64,
        keep: &dyn Fn(u64) -> bool,
    ) -> Result<Option<Manifest>, ManifestError> {
        match open(layout)? {
            Some((reader, path)) => Self::parse(layout, count, keep, reader, &path).map(Some),
            None => Ok(None),
        }
    }

    /// Parses manifest lines from `reader` (`path` names it in errors), keeping the samples
    /// for which `keep` holds.
    pub fn parse(
        layout: &Layout,
        count: u64,
        keep: &dyn Fn(u64) -> bool,
        reader: impl BufRead,
        path: &Path,
    ) -> Result<Manifest, ManifestError> {
        let mut lines = Lines::new(layout, count, reader, path);
        let mut manifest = Manifest::default();
        while let Some(entry) = lines.next_kept(keep)? {
            manifest
                .by_index
                .insert(entry.index, manifest.entries.len());
            manifest.entries.push(entry);
        }
        Ok(manifest)
    }

    /// The entry of sample `index`, if listed.
    pub fn get(&self, index: u64) -> Option<&Entry> {
        self.by_index.get(&index).map(|&k| &self.entries[k])
    }
}

/// Reads a manifest line by line, validating each (memory: one line, and the line number of
/// each sample seen, for duplicates).
pub struct Lines<R> {
    reader: R,
    path: PathBuf,
    layout: Layout,
    count: u64,
    line: usize,
    first_line: HashMap<u64, usize>,
    buf: Vec<u8>,
}

impl Lines<BufReader<std::fs::File>> {
    /// Opens `layout`'s manifest of a dataset of `count` samples; `None` if there is none.
    pub fn open(layout: &Layout, count: u64) -> Result<Option<Self>, ManifestError> {
        Ok(open(layout)?.map(|(reader, path)| Lines::new(layout, count, reader, &path)))
    }
}

impl<R: BufRead> Lines<R> {
    /// Reads the lines of `reader` (`path` names it in errors).
    pub fn new(layout: &Layout, count: u64, reader: R, path: &Path) -> Self {
        Lines {
            reader,
            path: path.to_path_buf(),
            layout: layout.clone(),
            count,
            line: 0,
            first_line: HashMap::new(),
            buf: Vec::new(),
        }
    }

    /// Whether a line read so far lists sample `index`.
    pub fn listed(&self, index: u64) -> bool {
        self.first_line.contains_key(&index)
    }

    /// The next line whose sample `keep` holds for (the others are checked to be JSON, of a
    /// sample of the dataset and not listed before, and skipped); `None` at the end.
    pub fn next_kept(
        &mut self,
        keep: &dyn Fn(u64) -> bool,
    ) -> Result<Option<Entry>, ManifestError> {
        loop {
            self.buf.clear();
            self.line += 1;
            let (path, line, count) = (self.path.clone(), self.line, self.count);
            let n = self
                .reader
                .by_ref()
                .take(MAX_LINE_BYTES as u64 + 1)
                .read_until(b'\n', &mut self.buf)
                .map_err(|source| ManifestError::Io {
                    path: path.clone(),
                    source,
                })?;
            if n == 0 {
                return Ok(None);
            }
            if self.buf.last() == Some(&b'\n') {
                self.buf.pop();
            }
            if self.buf.len() > MAX_LINE_BYTES {
                return Err(ManifestError::LineTooLong { path, line });
            }
            if self.buf.iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            if self.first_line.len() as u64 >= count {
                return Err(ManifestError::TooManyLines { path, line, count });
            }
            let json = |source| ManifestError::Json {
                path: path.clone(),
                line,
                source,
            };
            let index = serde_json::from_slice::<IndexOnly>(&self.buf)
                .map_err(json)?
                .index;
            let kept = keep(index);
            let (id, split, street, files) = if kept {
                let raw: RawLine = serde_json::from_slice(&self.buf).map_err(json)?;
                (raw.id, raw.split, raw.street, raw.files)
            } else {
                (sample_id(index), String::new(), 0, BTreeMap::new())
            };
            if index >= count || id != sample_id(index) {
                return Err(ManifestError::NotASample {
                    path,
                    line,
                    id,
                    index,
                    last: sample_id(count.saturating_sub(1)),
                });
            }
            if let Some(&first) = self.first_line.get(&index) {
                return Err(ManifestError::Duplicate {
                    path,
                    line,
                    id,
                    first,
                });
            }
            let own = own_files(&self.layout, index, &split, street);
            for (file, sha) in &files {
                if !own.is_own(file) {
                    return Err(ManifestError::ForeignPath {
                        path,
                        line,
                        id,
                        file: file.clone(),
                    });
                }
                if sha.len() != 64 || !sha.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f')) {
                    return Err(ManifestError::BadHash {
                        path,
                        line,
                        file: file.clone(),
                    });
                }
            }
            self.first_line.insert(index, line);
            if kept {
                return Ok(Some(Entry {
                    line,
                    index,
                    split,
                    street,
                    files,
                }));
            }
        }
    }
}

/// The paths (relative to the dataset folder) a sample may own.
struct OwnFiles {
    /// `samples/NNNNNN/`.
    folder: String,
    /// Its files of the dataset's views (KITTI, SceneFlow).
    views: Vec<String>,
}

impl OwnFiles {
    /// Whether `file` is `samples/NNNNNN/NAME` (one plain name) or one of the views' files.
    fn is_own(&self, file: &str) -> bool {
        if self.views.iter().any(|k| k == file) {
            return true;
        }
        file.strip_prefix(&self.folder).is_some_and(|name| {
            !name.is_empty()
                && name != "."
                && name != ".."
                && !name.contains(['/', '\\', '\0'])
                && !name.contains(':')
        })
    }
}

fn own_files(layout: &Layout, index: u64, split: &str, street: u64) -> OwnFiles {
    OwnFiles {
        folder: format!("samples/{}/", sample_id(index)),
        views: layout
            .view_files(index, split, street, &Default::default())
            .into_iter()
            .map(|(rel, _)| rel)
            .collect(),
    }
}

/// How a file on disk differs from the manifest.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Difference {
    /// The sample's folder is not there.
    SampleMissing,
    /// A listed file is not there.
    Missing {
        /// Path relative to the dataset folder.
        file: String,
    },
    /// A listed file has other bytes.
    Changed {
        /// Path relative to the dataset folder.
        file: String,
        /// The manifest's sha256.
        expected: String,
        /// The file's sha256.
        found: String,
    },
    /// A file of the sample that the manifest does not list.
    Extra {
        /// Path relative to the dataset folder.
        file: String,
    },
    /// A listed path that is a symbolic link, a folder or another special file, or that
    /// cannot be read.
    Unreadable {
        /// Path relative to the dataset folder.
        file: String,
        /// Why.
        why: String,
    },
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Difference::SampleMissing => write!(f, "the sample's folder is missing"),
            Difference::Missing { file } => write!(f, "{file}: missing"),
            Difference::Changed {
                file,
                expected,
                found,
            } => write!(f, "{file}: sha256 {found}, the manifest lists {expected}"),
            Difference::Extra { file } => write!(f, "{file}: not in the manifest"),
            Difference::Unreadable { file, why } => write!(f, "{file}: {why}"),
        }
    }
}

/// sha256 of the regular file `path` (read in blocks), lowercase hex; anything else (a FIFO
/// swapped in since it was listed) is an error rather than a blocking open.
pub fn sha256_file(path: &Path) -> std::io::Result<String> {
    let (mut file, _) = streaks_image::input::open_regular(path)?;
    let mut hasher = Sha256::new();
    std::io::copy(&mut file, &mut hasher)?;
    Ok(format!("{:x}", hasher.finalize()))
}

/// What a path on disk is.
#[derive(Debug, PartialEq, Eq)]
enum Kind {
    Missing,
    File,
    Folder,
    Other,
}

/// What `rel` (validated: under the dataset folder) is, without following symbolic links:
/// `Err` names a symbolic link on the way, or the error.
fn kind(root: &Path, rel: &str) -> Result<Kind, String> {
    let mut path = root.to_path_buf();
    let parts: Vec<&str> = rel.split('/').collect();
    let mut last = Kind::Missing;
    for (k, part) in parts.iter().enumerate() {
        path.push(part);
        last = match std::fs::symlink_metadata(&path) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(format!("{} is a symbolic link", parts[..=k].join("/")))
            }
            Ok(m) if m.is_file() => Kind::File,
            Ok(m) if m.is_dir() => Kind::Folder,
            Ok(_) => Kind::Other,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Kind::Missing),
            Err(e) => return Err(e.to_string()),
        };
    }
    Ok(last)
}

/// Compares sample `entry`'s files on disk with the manifest: every listed file by sha256,
/// and the files of its folder and its KITTI files that the manifest does not list.
pub fn verify_entry(layout: &Layout, entry: &Entry) -> Vec<Difference> {
    let root = layout.root();
    let folder = format!("samples/{}", sample_id(entry.index));
    match kind(root, &folder) {
        Ok(Kind::Folder) => {}
        Ok(Kind::Missing) => return vec![Difference::SampleMissing],
        Ok(_) => {
            return vec![Difference::Unreadable {
                file: folder,
                why: "not a folder".into(),
            }]
        }
        Err(why) => return vec![Difference::Unreadable { file: folder, why }],
    }
    let mut out = Vec::new();
    for (file, expected) in &entry.files {
        match kind(root, file) {
            Ok(Kind::Missing) => out.push(Difference::Missing { file: file.clone() }),
            Ok(Kind::File) => match sha256_file(&root.join(file)) {
                Ok(found) if &found == expected => {}
                Ok(found) => out.push(Difference::Changed {
                    file: file.clone(),
                    expected: expected.clone(),
                    found,
                }),
                Err(e) => out.push(Difference::Unreadable {
                    file: file.clone(),
                    why: e.to_string(),
                }),
            },
            Ok(_) => out.push(Difference::Unreadable {
                file: file.clone(),
                why: "not a regular file".into(),
            }),
            Err(why) => out.push(Difference::Unreadable {
                file: file.clone(),
                why,
            }),
        }
    }
    let mut on_disk: BTreeSet<String> = BTreeSet::new();
    if let Ok(entries) = std::fs::read_dir(root.join(&folder)) {
        for e in entries.flatten() {
            on_disk.insert(format!("{folder}/{}", e.file_name().to_string_lossy()));
        }
    }
    // Every view's files, also those of groups the dataset does not keep: a view's file on
    // disk that the manifest does not list is reported either way.
    let all = crate::outputs::Outputs::default();
    for (rel, path) in layout.view_files(entry.index, &entry.split, entry.street, &all) {
        if std::fs::symlink_metadata(path).is_ok() {
            on_disk.insert(rel);
        }
    }
    for file in on_disk {
        if !entry.files.contains_key(&file) {
            out.push(Difference::Extra { file });
        }
    }
    out
}

/// Verifies `entries` in parallel (in the current rayon pool), calling `done` after each;
/// returns the differences of each entry, in order.
pub fn verify_batch(
    layout: &Layout,
    entries: &[Entry],
    done: &(dyn Fn() + Sync),
) -> Vec<Vec<Difference>> {
    entries
        .par_iter()
        .map(|entry| {
            let d = verify_entry(layout, entry);
            done();
            d
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Manifest, ManifestError> {
        let layout = Layout::new(Path::new("/data/ds"));
        Manifest::parse(
            &layout,
            3,
            &|_| true,
            text.as_bytes(),
            Path::new(crate::files::MANIFEST),
        )
    }

    const SHA: &str = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";

    fn line(id: &str, index: u64, file: &str) -> String {
        format!("{{\"id\":\"{id}\",\"index\":{index},\"files\":{{\"{file}\":\"{SHA}\"}}}}\n")
    }

    #[test]
    fn good_lines_parse() {
        let text = line("000000", 0, "samples/000000/im0.png")
            + &line("000002", 2, "kitti/training/image_2/000002_10.png");
        let m = parse(&text).unwrap();
        assert_eq!(m.entries.len(), 2);
        assert_eq!(m.get(2).unwrap().line, 2);
        assert!(m.get(1).is_none());
    }

    #[test]
    fn a_shard_keeps_its_lines_and_still_checks_the_others() {
        let layout = Layout::new(Path::new("/data/ds"));
        let text = line("000000", 0, "samples/000000/im0.png")
            + &line("000001", 1, "samples/000001/../../x")
            + &line("000002", 2, "samples/000002/im0.png");
        let even = |i: u64| i.is_multiple_of(2);
        let m = Manifest::parse(&layout, 3, &even, text.as_bytes(), Path::new("m")).unwrap();
        assert_eq!(m.entries.len(), 2);
        let dup = text.clone() + &line("000001", 1, "samples/000001/im0.png");
        let err = Manifest::parse(&layout, 4, &even, dup.as_bytes(), Path::new("m")).unwrap_err();
        assert!(
            err.to_string()
                .contains("line 4: sample 000001 is listed again"),
            "{err}"
        );
        let bad = text + "{\"index\": 1, \n";
        let err = Manifest::parse(&layout, 4, &even, bad.as_bytes(), Path::new("m")).unwrap_err();
        assert!(
            err.to_string().contains("line 4: not a manifest line"),
            "{err}"
        );
    }

    #[test]
    fn hostile_manifests_are_refused_with_their_line() {
        let ok = line("000000", 0, "samples/000000/im0.png");
        let cases: Vec<(String, &str)> = vec![
            (ok.clone() + "{not json\n", "line 2: not a manifest line"),
            (
                ok.clone() + &"x".repeat(MAX_LINE_BYTES + 5),
                "line 2: longer than",
            ),
            (
                ok.clone() + &ok,
                "line 2: sample 000000 is listed again (first on line 1)",
            ),
            (
                line("000000", 0, "samples/000000/../../../etc/passwd"),
                "line 1: \"samples/000000/../../../etc/passwd\" is not a file",
            ),
            (
                line("000000", 0, "/etc/passwd"),
                "is not a file of sample 000000",
            ),
            (
                line("000000", 0, "samples/000000/.."),
                "is not a file of sample",
            ),
            (
                line("000000", 0, "samples/000001/im0.png"),
                "is not a file of sample 000000",
            ),
            (
                line("000000", 0, "samples/000000/a\\\\..\\\\b"),
                "is not a file",
            ),
            (
                line("000001", 0, "samples/000000/im0.png"),
                "is no sample of this dataset",
            ),
            (line("000007", 7, "samples/000007/im0.png"), "is no sample"),
            (ok.replace(SHA, "../x"), "is not 64 lowercase hex"),
            (
                ok.clone()
                    + &line("000001", 1, "samples/000001/x")
                    + &line("000002", 2, "samples/000002/x")
                    + &ok,
                "line 4: more lines than the dataset's 3",
            ),
        ];
        for (text, needle) in cases {
            let err = parse(&text).unwrap_err().to_string();
            assert!(err.contains(needle), "{needle}: {err}");
        }
    }
}
