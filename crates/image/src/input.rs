//! Reading files that may be hostile, the one way this project reads its inputs' bytes and
//! decodes their images.
//!
//! - Only regular files are read ([`open_regular`]): a FIFO, a device (`/dev/zero`), a socket
//!   or a folder is refused from its metadata before it is opened, and the open itself does
//!   not block (`O_NONBLOCK`), so nothing waits on a writer or reads forever.
//! - Reads are capped ([`read_file`], [`read_file_prefix`]): never more than the caller's
//!   limit or the bytes it needs, whatever the file grows to while it is read.
//! - Images are checked against [`MAX_PIXELS`] from their header, before any pixel is
//!   allocated, and decoded within [`MAX_IMAGE_BYTES`] ([`decode_image`], [`load_image`]).

use ::image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader, Limits};
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Seek};
use std::path::Path;

/// The most pixels an image read by this project may have: 2^28, 16384 x 16384. Checked from
/// the header (PNG, JPEG, EXR, PFM) before anything is allocated.
pub const MAX_PIXELS: u64 = 1 << 28;

/// The most bytes decoding one image may allocate: 1 GiB (16384 x 16384 RGBA 8-bit, or
/// 8192 x 8192 RGBA float).
pub const MAX_IMAGE_BYTES: u64 = 1 << 30;

/// Checks an image's size read from a header: neither side zero and at most [`MAX_PIXELS`]
/// pixels. The reason is returned otherwise, for the caller to name the file.
pub fn check_pixels(width: u64, height: u64) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("its header gives a {width}x{height} image"));
    }
    match width.checked_mul(height) {
        Some(n) if n <= MAX_PIXELS => Ok(()),
        _ => Err(format!(
            "its header claims {width}x{height} pixels, more than the limit of {MAX_PIXELS} \
             (16384 x 16384)"
        )),
    }
}

/// What kind of non-regular file `t` is, for messages.
fn kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// The error for a file of type `t` that is not a regular file.
fn not_regular(t: std::fs::FileType) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{}, not a regular file: only regular files are read",
            kind(t)
        ),
    )
}

/// Checks from its metadata (after following symbolic links), without opening it, that
/// `path` is a regular file; the error names what it is otherwise (a FIFO, a device...).
pub fn check_regular(path: &Path) -> io::Result<()> {
    let meta = std::fs::metadata(path)?;
    if meta.is_file() {
        Ok(())
    } else {
        Err(not_regular(meta.file_type()))
    }
}

/// Opens `path` for reading if it is a regular file (after following symbolic links), with
/// its size. Anything else (a FIFO, a device, a socket, a folder) is an error found from the
/// metadata before the open; the open does not block even if the file is swapped for a FIFO
/// meanwhile, and the opened file's own type is checked again.
pub fn open_regular(path: &Path) -> io::Result<(File, u64)> {
    check_regular(path)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_regular(meta.file_type()));
    }
    Ok((file, meta.len()))
}

/// Reads up to `limit` bytes of `reader` into a vector reserved for `expected` of them.
fn read_capped(reader: impl Read, expected: u64, limit: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::with_capacity(expected.min(limit) as usize);
    reader.take(limit).read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// The whole of the regular file `path`, refused (before reading) if it is larger than
/// `max_bytes`; a file that grows while it is read is cut at `max_bytes` and refused.
pub fn read_file(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    let (file, len) = open_regular(path)?;
    let too_big = |len: u64| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{len} bytes, more than the limit of {max_bytes}"),
        )
    };
    if len > max_bytes {
        return Err(too_big(len));
    }
    let bytes = read_capped(file, len, max_bytes.saturating_add(1))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The size limit for a text file a user names (a rig, a calibration, a generator config, a
/// model, a dataset's JSON): far beyond any real one, small enough to read whole.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// The regular file `path` as UTF-8 text, read as [`read_file`] reads (no FIFO, device or
/// folder, at most `max_bytes`): a special file given where a text file belongs is a prompt
/// error rather than a hang or an endless read.
pub fn read_text(path: &Path, max_bytes: u64) -> io::Result<String> {
    String::from_utf8(read_file(path, max_bytes)?)
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("not UTF-8 text: {e}")))
}

/// The first `len` bytes of the regular file `path`: an error, before anything is reserved,
/// if the file is shorter; nothing past them is read.
pub fn read_file_prefix(path: &Path, len: u64) -> io::Result<Vec<u8>> {
    let (file, size) = open_regular(path)?;
    let short = |size: u64| {
        io::Error::new(
            io::ErrorKind::UnexpectedEof,
            format!("the file holds {size} bytes, fewer than the {len} needed"),
        )
    };
    if size < len {
        return Err(short(size));
    }
    let bytes = read_capped(file, len, len)?;
    if (bytes.len() as u64) < len {
        return Err(short(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The decoding limits of every image this project reads (see [`MAX_IMAGE_BYTES`]).
fn limits() -> Limits {
    let mut limits = Limits::default();
    limits.max_alloc = Some(MAX_IMAGE_BYTES);
    limits
}

/// Decodes an image from `reader` (format from its content, else `hint`), checking its
/// header's size against [`MAX_PIXELS`] before decoding any pixel. Errors are the reason.
fn decode_from<R: BufRead + Seek>(
    reader: R,
    hint: Option<ImageFormat>,
) -> Result<DynamicImage, String> {
    let mut reader = ImageReader::new(reader);
    if let Some(format) = hint {
        reader.set_format(format);
    }
    let mut reader = reader.with_guessed_format().map_err(|e| e.to_string())?;
    reader.limits(limits());
    let decoder = reader.into_decoder().map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions();
    check_pixels(width.into(), height.into())?;
    let too_big = || {
        format!(
            "decoding its {width}x{height} pixels needs more than the limit of {MAX_IMAGE_BYTES} \
             bytes"
        )
    };
    if decoder.total_bytes() > MAX_IMAGE_BYTES {
        return Err(too_big());
    }
    DynamicImage::from_decoder(decoder).map_err(|e| match e {
        ::image::ImageError::Limits(_) => too_big(),
        e => e.to_string(),
    })
}

/// Decodes an encoded image (PNG, JPEG, EXR) held in memory, its format from its content, else
/// `hint`; the size in its header is checked against [`MAX_PIXELS`] before decoding, and the
/// decoding is limited to [`MAX_IMAGE_BYTES`]. The error is the reason, for the caller to name
/// the image.
pub fn decode_image(bytes: &[u8], hint: Option<ImageFormat>) -> Result<DynamicImage, String> {
    decode_from(io::Cursor::new(bytes), hint)
}

/// Loads an image file (PNG, JPEG, EXR: the format from its content, else its extension) as
/// [`decode_image`] does, reading only a regular file ([`open_regular`]).
pub fn load_image(path: &Path) -> Result<DynamicImage, crate::ImageError> {
    let err = |reason: String| crate::ImageError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let (file, _) = open_regular(path).map_err(|e| err(e.to_string()))?;
    decode_from(BufReader::new(file), ImageFormat::from_path(path).ok()).map_err(err)
}

/// A PNG whose header claims `width` x `height` RGBA pixels of `depth` bits per channel,
/// with no pixel data: a hostile file's shape, for the tests of every crate that reads images
/// (this module's pixel limit, the renderer's textures).
#[doc(hidden)]
pub fn png_header(width: u32, height: u32, depth: u8) -> Vec<u8> {
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        let crc = crc32(&c[4..]);
        c.extend_from_slice(&crc.to_be_bytes());
        c
    };
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([depth, 6, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    png.extend(chunk(b"IEND", &[]));
    png
}

/// The CRC-32 of PNG chunks.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    #[test]
    fn a_huge_png_header_is_refused_before_decoding() {
        let start = Instant::now();
        let err = decode_image(&png_header(100_000, 100_000, 8), None).unwrap_err();
        assert!(
            err.contains("100000x100000") && err.contains("limit"),
            "{err}"
        );
        // Under the pixel limit but over the allocation limit (16-bit RGBA): the decoder's.
        let err = decode_image(&png_header(16000, 16000, 16), None).unwrap_err();
        assert!(err.contains("needs more than the limit"), "{err}");
        assert!(start.elapsed() < Duration::from_secs(1));
        let ok = ::image::RgbaImage::from_pixel(3, 2, ::image::Rgba([1, 2, 3, 4]));
        let png = crate::png::png_bytes(&ok).unwrap();
        assert_eq!(decode_image(&png, None).unwrap().to_rgba8(), ok);
    }

    #[test]
    fn special_files_are_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
        let start = Instant::now();
        for path in [fifo.as_path(), Path::new("/dev/zero"), dir.path()] {
            let err = read_file(path, 1 << 20).unwrap_err().to_string();
            assert!(
                err.contains("not a regular file"),
                "{}: {err}",
                path.display()
            );
            assert!(read_file_prefix(path, 4).is_err());
            assert!(load_image(path).is_err());
            assert!(read_text(path, MAX_TEXT_BYTES).is_err());
        }
        assert!(start.elapsed() < Duration::from_secs(1));
    }

    #[test]
    fn text_is_capped_and_utf8() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rig.json");
        std::fs::write(&path, "{}").unwrap();
        assert_eq!(read_text(&path, 2).unwrap(), "{}");
        assert!(read_text(&path, 1)
            .unwrap_err()
            .to_string()
            .contains("limit of 1"));
        std::fs::write(&path, b"\xff{}").unwrap();
        assert!(read_text(&path, 16)
            .unwrap_err()
            .to_string()
            .contains("UTF-8"));
    }

    #[test]
    fn reads_are_capped() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.bin");
        std::fs::write(&path, b"0123456789").unwrap();
        assert_eq!(read_file(&path, 10).unwrap(), b"0123456789");
        assert!(read_file(&path, 9)
            .unwrap_err()
            .to_string()
            .contains("limit of 9"));
        assert_eq!(read_file_prefix(&path, 4).unwrap(), b"0123");
        let err = read_file_prefix(&path, 4 << 30).unwrap_err().to_string();
        assert!(err.contains("fewer than the 4294967296 needed"), "{err}");
    }
}
