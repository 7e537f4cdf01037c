//! EXR reading and writing: float32 channels with arbitrary names in one part, so a render's
//! layers travel in one file (OpenEXR's `layer.channel` naming, which Blender, Nuke and
//! `exrheader` show as layers; the renderer's layout is in `streaks_render::output`).

use crate::atomic::{write_atomically, WriteFailure};
use crate::input::{check_pixels, open_regular};
use crate::{ImageError, RgbImage};
use std::io::Seek;
use std::path::Path;

/// One channel to write: its full name (`R`, `depth.Z`, ...) and `width * height` values.
pub type ExrChannel<'a> = (&'a str, Vec<f32>);

/// Writes float32 `channels` of a `width` x `height` image as one EXR part (named `streaks`,
/// lossless compression), atomically.
///
/// Blocks are compressed in parallel but written in increasing order, so the same pixels
/// always give the same bytes: the dataset index's sha256 and "byte-identical files whatever
/// `--threads`" depend on it (exr's `FAST_LOSSLESS` alone writes blocks in the order its
/// threads finish them).
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    channels: Vec<ExrChannel<'_>>,
) -> Result<(), ImageError> {
    use exr::prelude::*;
    let n = width as usize * height as usize;
    if n == 0 || channels.is_empty() {
        return Err(ImageError::BadImage {
            path: path.to_path_buf(),
            reason: format!("{width}x{height} image with {} channels", channels.len()),
        });
    }
    if let Some((name, values)) = channels.iter().find(|(_, v)| v.len() != n) {
        return Err(ImageError::BadImage {
            path: path.to_path_buf(),
            reason: format!(
                "channel {name} has {} values for a {width}x{height} image",
                values.len()
            ),
        });
    }
    let channels: Vec<AnyChannel<FlatSamples>> = channels
        .into_iter()
        .map(|(name, values)| AnyChannel::new(name, FlatSamples::F32(values)))
        .collect();
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named("streaks"),
        Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        },
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    write_atomically(path, |w| {
        image.write().to_buffered(w).map_err(WriteFailure::Exr)
    })
}

/// Writes a linear RGB image as an EXR with channels `R`, `G`, `B`.
pub fn write_exr_rgb(path: &Path, image: &RgbImage) -> Result<(), ImageError> {
    let channels = ["R", "G", "B"]
        .into_iter()
        .enumerate()
        .map(|(c, name)| (name, image.plane(c)))
        .collect();
    write_exr(path, image.width, image.height, channels)
}

/// The channels of the first EXR part that has all of `names` (any sample type, converted to
/// f32), in that order, with the part's width and height. Only a regular file is read, and
/// its headers are checked against [`crate::input::MAX_PIXELS`] and
/// [`crate::input::MAX_IMAGE_BYTES`] before any pixel is.
pub fn read_exr_channels(
    path: &Path,
    names: &[&str],
) -> Result<(u32, u32, Vec<Vec<f32>>), ImageError> {
    use exr::prelude::traits::*;
    let exr_err = |source| ImageError::Exr {
        path: path.to_path_buf(),
        source,
    };
    let read_err = |reason: String| ImageError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let (file, _) = open_regular(path).map_err(|e| read_err(e.to_string()))?;
    let mut reader = std::io::BufReader::new(file);
    // The decoder asserts some of its own invariants instead of returning an error, and a
    // malformed file can break them (a tile whose level differs from the one being read
    // fails `line should have been filtered`; B44 blocks overflow its arithmetic in debug
    // builds): such a panic is a malformed file too. Blocks are decompressed on this thread,
    // where the panic can be caught (a panic in the decoder's thread pool aborts).
    let read = std::panic::catch_unwind(move || {
        // The headers first: every part's size against the pixel limit, the samples the read
        // will hold and the block sizes against the allocation limits, before any pixel is
        // read.
        let meta = exr::meta::MetaData::read_from_buffered(&mut reader, false)?;
        for header in &meta.headers {
            let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
            if let Err(reason) = check_pixels(w, h) {
                return Ok(Err(reason));
            }
        }
        if let Some(reason) = too_large(&meta.headers) {
            return Ok(Err(reason));
        }
        reader.rewind()?;
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .non_parallel()
            .from_buffered(reader)
            .map(Ok)
    })
    .map_err(|panic| {
        read_err(format!(
            "malformed EXR (the decoder failed: {})",
            panic_message(&*panic)
        ))
    })?;
    let image = read.map_err(exr_err)?.map_err(read_err)?;
    for layer in &image.layer_data {
        let found: Option<Vec<Vec<f32>>> = names
            .iter()
            .map(|name| {
                layer
                    .channel_data
                    .list
                    .iter()
                    .find(|c| c.name.to_string() == *name)
                    .map(|c| c.sample_data.values_as_f32().collect())
            })
            .collect();
        if let Some(planes) = found {
            return Ok((layer.size.0 as u32, layer.size.1 as u32, planes));
        }
    }
    Err(ImageError::MissingChannels {
        path: path.to_path_buf(),
        what: format!("{} channels", names.join(", ")),
    })
}

/// The most samples (pixels times channels, over all layers) an EXR may hold: 2^28, 1 GiB as
/// `f32`. The headers say how many there are before any memory is reserved for them.
pub const MAX_EXR_SAMPLES: u64 = 1 << 28;

/// A block may claim at most this many bytes when its layer's pixels take fewer.
const MAX_SMALL_LAYER_BLOCK: u64 = 64 << 20;

/// Why the EXR whose headers are `headers` may not be read, if so: more than [`MAX_EXR_SAMPLES`]
/// samples, or a block size larger than the layer it belongs to (the decoder reserves a
/// block's claimed size before reading it).
fn too_large(headers: &[exr::meta::header::Header]) -> Option<String> {
    let mut samples = 0u64;
    for (i, header) in headers.iter().enumerate() {
        let size = header.layer_size;
        let area = (size.0 as u64).saturating_mul(size.1 as u64);
        samples = samples.saturating_add(area.saturating_mul(header.channels.list.len() as u64));
        if samples > MAX_EXR_SAMPLES {
            return Some(format!(
                "layer {i} ({}x{}, {} channels) takes the image past {MAX_EXR_SAMPLES} samples",
                size.0,
                size.1,
                header.channels.list.len()
            ));
        }
        let layer_bytes = area.saturating_mul(header.channels.bytes_per_pixel as u64);
        let block = header.max_block_byte_size() as u64;
        if block > layer_bytes.max(MAX_SMALL_LAYER_BLOCK) {
            return Some(format!(
                "layer {i} ({}x{}) has blocks of {block} bytes, larger than the layer",
                size.0, size.1
            ));
        }
    }
    None
}

/// The message of a caught panic.
fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".to_owned())
}

/// Reads three channels of an EXR as an RGB image (for example `R`, `G`, `B`).
pub fn read_exr_rgb_channels(path: &Path, names: [&str; 3]) -> Result<RgbImage, ImageError> {
    let (w, h, planes) = read_exr_channels(path, &names)?;
    Ok(RgbImage::from_planes(
        w,
        h,
        [&planes[0], &planes[1], &planes[2]],
    ))
}

/// Reads the main `R`, `G`, `B` channels of any EXR.
pub fn read_exr_rgb(path: &Path) -> Result<RgbImage, ImageError> {
    read_exr_rgb_channels(path, ["R", "G", "B"])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn gradient(w: u32, h: u32) -> RgbImage {
        RgbImage::from_fn(w, h, |x, y| {
            let i = (y * w + x) as f32;
            Vec3::new(i, 0.5 * i, -i)
        })
    }

    /// Many tiles compressed in parallel must still land in one order: the header says
    /// increasing, and rewriting the same pixels gives the same bytes.
    #[test]
    fn exr_bytes_do_not_depend_on_thread_timing() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (640, 384);
        let mut img = gradient(w, h);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            // varied content, so the tiles' compression times differ
            *p *= ((i * 2_654_435_761) % 97) as f32;
        }
        let first = dir.path().join("0.exr");
        write_exr_rgb(&first, &img).unwrap();
        let meta = ::exr::meta::MetaData::read_from_file(&first, false).unwrap();
        assert_eq!(
            meta.headers[0].line_order,
            ::exr::meta::attribute::LineOrder::Increasing
        );
        let bytes = std::fs::read(&first).unwrap();
        for k in 1..4 {
            let path = dir.path().join(format!("{k}.exr"));
            write_exr_rgb(&path, &img).unwrap();
            assert!(std::fs::read(&path).unwrap() == bytes, "write {k} differs");
        }
        assert_eq!(read_exr_rgb(&first).unwrap(), img);
    }

    #[test]
    fn exr_round_trip_with_named_channels() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let img = gradient(5, 3);
        let mut depth: Vec<f32> = (0..15).map(|i| i as f32 + 0.25).collect();
        depth[4] = f32::INFINITY;
        let mut channels: Vec<ExrChannel> = vec![("R", img.plane(0)), ("G", img.plane(1))];
        channels.push(("B", img.plane(2)));
        channels.push(("depth.Z", depth.clone()));
        write_exr(&path, 5, 3, channels).unwrap();
        assert_eq!(read_exr_rgb(&path).unwrap(), img);
        let (w, h, planes) = read_exr_channels(&path, &["depth.Z"]).unwrap();
        assert_eq!((w, h), (5, 3));
        assert_eq!(planes[0], depth);
        let err = read_exr_channels(&path, &["albedo.R"]).unwrap_err();
        assert!(err.to_string().contains("albedo.R"), "{err}");
        // Only the image is left in the folder (no temporary files).
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        write_exr_rgb(&path, &img).unwrap();
        assert_eq!(read_exr_rgb(&path).unwrap(), img);
    }

    #[test]
    fn bad_input_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("not.exr");
        std::fs::write(&path, b"hello").unwrap();
        let err = read_exr_rgb(&path).unwrap_err().to_string();
        assert!(err.contains("not.exr"), "{err}");
        let err = read_exr_rgb(&dir.path().join("missing.exr")).unwrap_err();
        assert!(err.to_string().contains("missing.exr"), "{err}");
        let out = dir.path().join("short.exr");
        let err = write_exr(&out, 2, 2, vec![("R", vec![0.0; 3])]).unwrap_err();
        assert!(err.to_string().contains("channel R has 3 values"), "{err}");
        assert!(write_exr(&out, 0, 2, vec![("R", vec![])]).is_err());
        assert!(!out.exists());
    }

    #[test]
    fn a_huge_header_is_refused_before_reading_pixels() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.exr");
        write_exr_rgb(&path, &gradient(4, 4)).unwrap();
        // Rewrite the dataWindow (box2i: xMin, yMin, xMax, yMax) to 100000 x 100000 pixels.
        let mut bytes = std::fs::read(&path).unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        for (i, v) in [0i32, 0, 99_999, 99_999].iter().enumerate() {
            bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
        }
        std::fs::write(&path, bytes).unwrap();
        let start = std::time::Instant::now();
        let err = read_exr_rgb(&path).unwrap_err().to_string();
        assert!(
            err.contains("100000x100000") && err.contains("huge.exr"),
            "{err}"
        );
        assert!(start.elapsed() < std::time::Duration::from_secs(1));
        let err = read_exr_rgb(Path::new("/dev/zero"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("not a regular file"), "{err}");
    }

    #[test]
    fn a_file_that_breaks_the_decoders_assertions_is_an_error() {
        // Found by the exr fuzz target: a tiled file with a block of another level than the
        // one read, which fails an assertion of the exr crate (in debug builds).
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.exr");
        let bytes = include_bytes!("../../../fuzz/regressions/exr/crash-tile-of-another-level");
        std::fs::write(&p, bytes).unwrap();
        let e = read_exr_rgb(&p).unwrap_err().to_string();
        assert!(e.contains("malformed EXR") && e.contains("bad.exr"), "{e}");
    }

    /// Reads the fuzz regression input `name` as an EXR: the error.
    fn read_regression(name: &str, bytes: &[u8]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(format!("{name}.exr"));
        std::fs::write(&p, bytes).unwrap();
        let e = read_exr_rgb(&p).unwrap_err().to_string();
        assert!(e.contains(name), "{e}");
        e
    }

    #[test]
    fn a_decoder_panic_in_a_block_is_an_error_not_an_abort() {
        // Found by the exr fuzz target: B44 blocks whose values overflow the decoder's
        // arithmetic (a panic in debug builds, which aborted the process when blocks were
        // decompressed in the decoder's thread pool).
        let bytes =
            include_bytes!("../../../fuzz/regressions/exr/crash-b44-overflow-in-the-thread-pool");
        let e = read_regression("b44", bytes);
        assert!(e.contains("malformed EXR"), "{e}");
    }

    #[test]
    fn a_block_larger_than_its_layer_is_refused_before_it_is_allocated() {
        // Found by the exr fuzz target: a 3x2 layer with 3 GB tiles, whose first block claims
        // 2 GB, which the decoder reserved before reading it.
        let bytes = include_bytes!("../../../fuzz/regressions/exr/oom-block-larger-than-its-layer");
        let e = read_regression("tiles", bytes);
        assert!(e.contains("larger than the layer"), "{e}");
    }

    #[test]
    fn an_image_past_the_sample_limit_is_refused() {
        use exr::meta::attribute::{ChannelDescription, SampleType};
        use exr::meta::header::Header;
        let channels = ["R", "G", "B"]
            .map(|n| ChannelDescription::named(n, SampleType::F32))
            .to_vec();
        let header = |w, h| {
            Header::new(
                "main".into(),
                (w, h),
                exr::prelude::SmallVec::from_vec(channels.clone()),
            )
        };
        assert_eq!(too_large(&[header(1920, 1080)]), None);
        // 3 x 10000 x 10000 = 3 x 10^8 samples, 1.2 GB as f32.
        let e = too_large(&[header(10000, 10000)]).unwrap();
        assert!(e.contains("10000x10000, 3 channels"), "{e}");
    }
}
