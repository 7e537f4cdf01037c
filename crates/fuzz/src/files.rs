//! Several files in one fuzz input, so that a glTF and its `.bin`, or an OBJ and its MTL, are
//! mutated and read together.
//!
//! The format is the main file's bytes, then for each further file a separator line and its
//! bytes:
//!
//! ```text
//! <bytes of the main file>
//! --8<-- scene.bin
//! <bytes of scene.bin>
//! --8<-- textures/wood.png
//! <bytes of textures/wood.png>
//! ```
//!
//! A separator is `\n--8<-- NAME\n`: the newline before it belongs to the separator, not to the
//! file before. Any bytes parse (the format is total, as a fuzzer's input must be): a name
//! that is not a plain relative path (empty, `..`, `.`, a leading `/`, a character outside
//! `A-Z a-z 0-9 . _ - space`, more than 100 bytes) drops its file, and of two files with one
//! name the last wins. Text inputs stay readable, and `streaks-fuzz --pack DIR MAIN` packs a
//! folder into one.

use std::io;
use std::path::Path;

/// What starts a file's header: a newline, the scissors, a space.
pub const SEPARATOR: &[u8] = b"\n--8<-- ";

/// The longest file name kept.
const MAX_NAME: usize = 100;

/// One file of an input: its name (`None` for the main file) and bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Part {
    /// The relative path, `None` for the main file.
    pub name: Option<String>,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// Splits an input into its files, the main one first (see the module docs). Headers keep
/// their names even when unsafe, so that [`join`] gives the input back; [`write`] skips them.
pub fn split(data: &[u8]) -> Vec<Part> {
    let mut parts = Vec::new();
    let mut name = None;
    let mut rest = data;
    loop {
        let Some(at) = find(rest, SEPARATOR) else {
            parts.push(Part {
                name,
                bytes: rest.to_vec(),
            });
            return parts;
        };
        parts.push(Part {
            name,
            bytes: rest[..at].to_vec(),
        });
        let header = &rest[at + SEPARATOR.len()..];
        let end = header
            .iter()
            .position(|&b| b == b'\n')
            .unwrap_or(header.len());
        name = Some(String::from_utf8_lossy(&header[..end]).into_owned());
        rest = &header[(end + 1).min(header.len())..];
    }
}

/// The input made of `parts` (the inverse of [`split`] for parts whose bytes hold no
/// separator).
pub fn join(parts: &[Part]) -> Vec<u8> {
    let mut out = Vec::new();
    for part in parts {
        if let Some(name) = &part.name {
            out.extend_from_slice(SEPARATOR);
            out.extend_from_slice(name.as_bytes());
            out.push(b'\n');
        }
        out.extend_from_slice(&part.bytes);
    }
    out
}

/// Whether `name` is a plain relative path that [`write`] writes.
pub fn is_safe_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_NAME
        && name.split('/').all(|c| {
            !c.is_empty()
                && c != "."
                && c != ".."
                && c.bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"._- ".contains(&b))
        })
}

/// Writes the files of `data` into `dir`: the main file as `main`, the others under their
/// names (folders created as needed). Files with unsafe names, or whose path collides with
/// another's folder, are skipped.
pub fn write(data: &[u8], dir: &Path, main: &str) -> io::Result<()> {
    for part in split(data) {
        let name = part.name.as_deref().unwrap_or(main);
        if !is_safe_name(name) {
            continue;
        }
        let path = dir.join(name);
        if let Some(parent) = path.parent() {
            if std::fs::create_dir_all(parent).is_err() {
                continue;
            }
        }
        if path.is_dir() {
            continue;
        }
        std::fs::write(&path, &part.bytes)?;
    }
    Ok(())
}

/// Packs the regular files under `dir` into one input, `main` (a path relative to `dir`)
/// first, the others sorted by name.
pub fn pack(dir: &Path, main: &str) -> io::Result<Vec<u8>> {
    let mut names = Vec::new();
    collect(dir, "", &mut names)?;
    names.sort();
    let mut parts = vec![Part {
        name: None,
        bytes: std::fs::read(dir.join(main))?,
    }];
    for name in names.into_iter().filter(|n| n != main) {
        let bytes = std::fs::read(dir.join(&name))?;
        parts.push(Part {
            name: Some(name),
            bytes,
        });
    }
    Ok(join(&parts))
}

/// The relative names of the regular files under `dir`.
fn collect(dir: &Path, prefix: &str, out: &mut Vec<String>) -> io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = format!("{prefix}{}", entry.file_name().to_string_lossy());
        let kind = entry.file_type()?;
        if kind.is_dir() {
            collect(&entry.path(), &format!("{name}/"), out)?;
        } else if kind.is_file() {
            out.push(name);
        }
    }
    Ok(())
}

/// The first position of `needle` in `haystack`.
fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_and_join_round_trip() {
        let data = b"{\"a\": 1}\n--8<-- scene.bin\n\x00\x01\n--8<-- t/x.png\nPNG";
        let parts = split(data);
        assert_eq!(parts.len(), 3);
        assert_eq!(parts[0].bytes, b"{\"a\": 1}");
        assert_eq!(parts[1].name.as_deref(), Some("scene.bin"));
        assert_eq!(parts[1].bytes, b"\x00\x01");
        assert_eq!(parts[2].name.as_deref(), Some("t/x.png"));
        assert_eq!(join(&parts), data);
        // A header cut short is a file with an empty body.
        assert_eq!(split(b"x\n--8<-- a").len(), 2);
    }

    #[test]
    fn unsafe_names_are_not_written() {
        for bad in [
            "",
            "../x",
            "/etc/x",
            "a//b",
            "./a",
            "a\\b",
            "a/../../b",
            "é",
        ] {
            assert!(!is_safe_name(bad), "{bad:?}");
        }
        assert!(is_safe_name("textures/wood 2.png"));
        let dir = tempfile::tempdir().unwrap();
        let inner = dir.path().join("in");
        std::fs::create_dir(&inner).unwrap();
        write(b"main\n--8<-- ../out\nx\n--8<-- ok\ny", &inner, "m.txt").unwrap();
        assert!(!dir.path().join("out").exists());
        assert_eq!(std::fs::read(inner.join("ok")).unwrap(), b"y");
        assert_eq!(std::fs::read(inner.join("m.txt")).unwrap(), b"main");
    }
}
