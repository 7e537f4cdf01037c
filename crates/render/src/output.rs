//! Image output and input: EXR (linear float32 with named layers) and PNG (sRGB, exposure,
//! clipping).
//!
//! Every writer goes through [`write_atomically`]: the bytes go to a temporary file in the
//! destination's folder, which is renamed onto the destination only once it is complete, so
//! an interrupted or failed write never leaves a truncated or half-written image.
//!
//! EXR layout: one part whose channels are `R`, `G`, `B` (the beauty image, linear, float32)
//! plus, when present, `depth.Z`, `normal.X`/`normal.Y`/`normal.Z`, `albedo.R`/`.G`/`.B` and
//! `specular.R`/`.G`/`.B` (OpenEXR's `layer.channel` naming, which Blender, Nuke and
//! `exrheader` show as layers).

use crate::integrator::RenderOutput;
use glam::Vec3;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A linear RGB float image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels.
    pub pixels: Vec<Vec3>,
}

impl RgbImage {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// The pixel in column `x`, row `y` (row 0 at the top).
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }
}

/// Errors of image reading and writing; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Creating, writing or renaming a file failed.
    #[error("cannot write {path}")]
    Io {
        /// The destination.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The EXR encoder or decoder failed (also: the file is not an EXR).
    #[error("EXR error in {path}")]
    Exr {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: exr::error::Error,
    },
    /// The PNG encoder failed.
    #[error("PNG error in {path}")]
    Png {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: image::ImageError,
    },
    /// The EXR has no channels of the requested name.
    #[error("{path} has no {what}")]
    MissingChannels {
        /// The file.
        path: PathBuf,
        /// What was looked for, e.g. `R, G, B channels`.
        what: String,
    },
    /// An image with no pixels, or a pixel count that does not match its size.
    #[error("cannot write {path}: {reason}")]
    BadImage {
        /// The destination.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

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

/// Writes `path` atomically: `write` fills a buffered temporary file in the same folder, which
/// is flushed, synced and renamed onto `path`. On any failure the temporary file is removed
/// and `path` is left as it was (absent or the previous version).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), WriteFailure>,
) -> Result<(), OutputError> {
    let io_err = |source| OutputError::Io {
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
    let tmp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io_err)?;
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
        Err(WriteFailure::Exr(source)) => Err(OutputError::Exr {
            path: path.to_path_buf(),
            source,
        }),
        Err(WriteFailure::Png(source)) => Err(OutputError::Png {
            path: path.to_path_buf(),
            source,
        }),
        Ok(()) => tmp_path.persist(path).map_err(|e| io_err(e.error)),
    }
}

fn check_size(path: &Path, width: u32, height: u32, len: usize) -> Result<(), OutputError> {
    if width == 0 || height == 0 || len != width as usize * height as usize {
        return Err(OutputError::BadImage {
            path: path.to_path_buf(),
            reason: format!("{width}x{height} image with {len} pixels"),
        });
    }
    Ok(())
}

/// Writes the render as a float32 EXR: `R`, `G`, `B` and the layers present in `output`
/// (see the module documentation for the channel names).
pub fn write_exr(path: &Path, output: &RenderOutput) -> Result<(), OutputError> {
    use exr::prelude::*;
    let img = &output.image;
    check_size(path, img.width, img.height, img.pixels.len())?;
    let n = img.pixels.len();
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    let mut push_rgb = |prefix: &str, names: [&str; 3], image: &RgbImage| {
        for (k, name) in names.iter().enumerate() {
            let samples = image.pixels.iter().map(|p| p[k]).collect();
            channels.push(AnyChannel::new(
                format!("{prefix}{name}").as_str(),
                FlatSamples::F32(samples),
            ));
        }
    };
    push_rgb("", ["R", "G", "B"], img);
    for (name, layer) in [("albedo.", &output.albedo), ("specular.", &output.specular)] {
        if let Some(layer) = layer {
            check_size(path, layer.width, layer.height, layer.pixels.len())?;
            push_rgb(name, ["R", "G", "B"], layer);
        }
    }
    if let Some(normal) = &output.normal {
        check_size(path, normal.width, normal.height, normal.pixels.len())?;
        push_rgb("normal.", ["X", "Y", "Z"], normal);
    }
    if let Some(depth) = &output.depth {
        check_size(path, img.width, img.height, depth.len())?;
        channels.push(AnyChannel::new("depth.Z", FlatSamples::F32(depth.clone())));
    }
    debug_assert!(channels.iter().all(|c| c.sample_data.len() == n));
    let layer = Layer::new(
        (img.width as usize, img.height as usize),
        LayerAttributes::named("streaks"),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    write_atomically(path, |w| {
        image.write().to_buffered(w).map_err(WriteFailure::Exr)
    })
}

/// The channels of the first EXR part that has all of `names`, in that order.
fn read_exr_channels(
    path: &Path,
    names: &[&str],
) -> Result<(u32, u32, Vec<Vec<f32>>), OutputError> {
    let image =
        exr::prelude::read_all_flat_layers_from_file(path).map_err(|source| OutputError::Exr {
            path: path.to_path_buf(),
            source,
        })?;
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
    Err(OutputError::MissingChannels {
        path: path.to_path_buf(),
        what: format!("{} channels", names.join(", ")),
    })
}

fn planes_to_rgb(width: u32, height: u32, planes: &[Vec<f32>]) -> RgbImage {
    let pixels = (0..width as usize * height as usize)
        .map(|i| Vec3::new(planes[0][i], planes[1][i], planes[2][i]))
        .collect();
    RgbImage {
        width,
        height,
        pixels,
    }
}

/// Reads the main `R`, `G`, `B` channels of any EXR (any sample type, converted to f32).
pub fn read_exr_rgb(path: &Path) -> Result<RgbImage, OutputError> {
    let (w, h, planes) = read_exr_channels(path, &["R", "G", "B"])?;
    Ok(planes_to_rgb(w, h, &planes))
}

/// Reads a layer written by [`write_exr`]: `"albedo"`, `"specular"` (RGB), `"normal"` (XYZ
/// into the RGB slots) or `"depth"` (Z, repeated into all three slots).
pub fn read_exr_layer(path: &Path, name: &str) -> Result<RgbImage, OutputError> {
    let suffixes: &[&str] = match name {
        "normal" => &["X", "Y", "Z"],
        "depth" => &["Z"],
        _ => &["R", "G", "B"],
    };
    let names: Vec<String> = suffixes.iter().map(|s| format!("{name}.{s}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let (w, h, planes) = read_exr_channels(path, &names)?;
    if planes.len() == 1 {
        let p = &planes[0];
        return Ok(planes_to_rgb(w, h, &[p.clone(), p.clone(), p.clone()]));
    }
    Ok(planes_to_rgb(w, h, &planes))
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1) on a linear value in [0, 1].
#[inline]
pub fn srgb_oetf(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Converts a linear image to 8-bit sRGB: scale by `2^exposure_ev`, clip to [0, 1] (NaN to 0),
/// apply the sRGB OETF and round.
pub fn to_srgb8(image: &RgbImage, exposure_ev: f32) -> Vec<u8> {
    let scale = exposure_ev.exp2();
    image
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|v| {
            let v = (v * scale).clamp(0.0, 1.0);
            let v = if v.is_nan() { 0.0 } else { v };
            (srgb_oetf(v) * 255.0 + 0.5) as u8
        })
        .collect()
}

/// Writes an 8-bit sRGB PNG of a linear image with exposure `exposure_ev` (see [`to_srgb8`]).
pub fn write_png(path: &Path, image: &RgbImage, exposure_ev: f32) -> Result<(), OutputError> {
    use image::ImageEncoder;
    check_size(path, image.width, image.height, image.pixels.len())?;
    let bytes = to_srgb8(image, exposure_ev);
    write_atomically(path, |w| {
        image::codecs::png::PngEncoder::new(w.by_ref())
            .write_image(
                &bytes,
                image.width,
                image.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(WriteFailure::Png)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{RenderOutput, RenderStats};

    fn gradient(w: u32, h: u32) -> RgbImage {
        let pixels = (0..w * h)
            .map(|i| Vec3::new(i as f32, 0.5 * i as f32, -(i as f32)))
            .collect();
        RgbImage {
            width: w,
            height: h,
            pixels,
        }
    }

    fn output(w: u32, h: u32) -> RenderOutput {
        RenderOutput {
            image: gradient(w, h),
            depth: Some((0..w * h).map(|i| i as f32 + 0.25).chain([]).collect()),
            normal: Some(RgbImage {
                pixels: vec![Vec3::Y; (w * h) as usize],
                ..RgbImage::new(w, h)
            }),
            albedo: None,
            specular: Some(gradient(w, h)),
            stats: RenderStats::default(),
        }
    }

    #[test]
    fn exr_round_trip_with_layers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let mut out = output(5, 3);
        out.depth.as_mut().unwrap()[4] = f32::INFINITY;
        write_exr(&path, &out).unwrap();
        assert_eq!(read_exr_rgb(&path).unwrap(), out.image);
        assert_eq!(read_exr_layer(&path, "specular").unwrap(), out.image);
        assert_eq!(
            read_exr_layer(&path, "normal").unwrap(),
            *out.normal.as_ref().unwrap()
        );
        let depth = read_exr_layer(&path, "depth").unwrap();
        assert_eq!(depth.get(1, 0).x, 1.25);
        assert_eq!(depth.get(4, 0).z, f32::INFINITY);
        let err = read_exr_layer(&path, "albedo").unwrap_err();
        assert!(err.to_string().contains("albedo.R"), "{err}");
        // Only the image is left in the folder (no temporary files).
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn unreadable_exr_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("not.exr");
        std::fs::write(&path, b"hello").unwrap();
        let err = read_exr_rgb(&path).unwrap_err().to_string();
        assert!(err.contains("not.exr"), "{err}");
        let err = read_exr_rgb(&dir.path().join("missing.exr")).unwrap_err();
        assert!(err.to_string().contains("missing.exr"), "{err}");
    }

    #[test]
    fn failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        // The destination is a folder: the final rename fails.
        let target = dir.path().join("taken.exr");
        std::fs::create_dir(&target).unwrap();
        let err = write_exr(&target, &output(2, 2)).unwrap_err();
        assert!(matches!(err, OutputError::Io { .. }), "{err}");
        // A writer that fails half-way.
        let path = dir.path().join("half.png");
        let err = write_atomically(&path, |w| {
            w.write_all(b"partial").map_err(WriteFailure::Io)?;
            Err(WriteFailure::Io(std::io::Error::other("disk full")))
        })
        .unwrap_err();
        assert!(err.to_string().contains("half.png"), "{err}");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("taken.exr")]);
        // Missing folder.
        assert!(write_png(&dir.path().join("no/such.png"), &gradient(2, 2), 0.0).is_err());
    }

    #[test]
    fn png_exposure_clip_and_srgb() {
        let img = RgbImage {
            width: 4,
            height: 1,
            pixels: vec![
                Vec3::new(0.0, 1.0, 2.0),
                Vec3::splat(0.25),
                Vec3::new(-1.0, f32::NAN, f32::INFINITY),
                Vec3::splat(0.001),
            ],
        };
        let bytes = to_srgb8(&img, 1.0);
        assert_eq!(&bytes[0..3], &[0, 255, 255]);
        // 0.25 * 2 = 0.5 -> sRGB 0.7354 -> 188
        assert_eq!(&bytes[3..6], &[188, 188, 188]);
        assert_eq!(&bytes[6..9], &[0, 0, 255]);
        // Linear segment: 0.002 * 12.92 * 255 = 6.6
        assert_eq!(bytes[9], 7);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.png");
        write_png(&path, &img, 1.0).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back.as_raw(), &bytes);
    }
}
