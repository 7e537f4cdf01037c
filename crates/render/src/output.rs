//! The renderer's EXR layout: a render and its layers in one float32 EXR part.
//!
//! Channels: `R`, `G`, `B` (the beauty image, linear) plus, when present, `depth.Z`,
//! `normal.X`/`normal.Y`/`normal.Z`, `albedo.R`/`.G`/`.B`, `specular.R`/`.G`/`.B` and
//! `raw.R`/`.G`/`.B` (the render before denoising, when `R`, `G`, `B` are denoised),
//! `spp.Y` (samples taken per pixel, as float32: exact up to 2^24), `rain.Y` (the share of
//! the pixel's camera samples whose first hit was a rain drop) and `fog.Y` (the fog's
//! transmittance to the pixel-centre ray's first hit, 1 without fog) and `object.Y` (the
//! slot in the scene's objects of the pixel-centre ray's first hit, as float32: exact up to
//! 2^24; 0 is the sky, see [`crate::scene::SceneObject`]) (OpenEXR's
//! `layer.channel` naming, which Blender, Nuke and `exrheader` show as layers).
//! A render through a camera model (`--sensor`) also has `sensor.R`/`.G`/`.B`, the camera's
//! raw values in DN as float32 ([`write_exr_with_sensor`]); `R`, `G`, `B` stay the render.
//! [`write_exr`] writes them and [`read_exr_layer`] reads them back, from the names here; the
//! file itself is written by [`streaks_image::exr`] (atomically).

use crate::integrator::RenderOutput;
use glam::Vec3;
use std::path::Path;
use streaks_image::exr::{read_exr_channels, ExrChannel};
use streaks_image::{ImageError, RgbImage};

/// The beauty image's channels.
pub const BEAUTY: [&str; 3] = ["R", "G", "B"];
/// The albedo layer's channels.
pub const ALBEDO: [&str; 3] = ["albedo.R", "albedo.G", "albedo.B"];
/// The specular layer's channels.
pub const SPECULAR: [&str; 3] = ["specular.R", "specular.G", "specular.B"];
/// The normal layer's channels (world space X, Y, Z).
pub const NORMAL: [&str; 3] = ["normal.X", "normal.Y", "normal.Z"];
/// The depth layer's channel.
pub const DEPTH: &str = "depth.Z";
/// The samples-per-pixel layer's channel.
pub const SPP: &str = "spp.Y";
/// The sensor layer's channels (raw DN of a camera model).
pub const SENSOR: [&str; 3] = ["sensor.R", "sensor.G", "sensor.B"];
/// The rain layer's channel: the share of the pixel's camera samples whose first hit was a
/// rain drop.
pub const RAIN: &str = "rain.Y";
/// The fog transmittance layer's channel.
pub const FOG: &str = "fog.Y";
/// The object layer's channel: the slot in the scene's objects of the pixel-centre ray's
/// first hit.
pub const OBJECT: &str = "object.Y";
/// The raw layer's channels: the render before denoising, beside the denoised `R`, `G`, `B`.
pub const RAW: [&str; 3] = ["raw.R", "raw.G", "raw.B"];

/// Denoises `output.image` with `denoiser` (Intel Open Image Denoise), guided by its
/// `albedo` and `normal` layers when it has them, and keeps the render before in
/// [`RenderOutput::raw`] (the EXR's `raw` layer). With an `emission` layer, only the rest is
/// denoised and the light seen directly (lamp lenses, lit windows, the sky: exact once each
/// sample's first hit is known) is added back as rendered, so the denoiser does not spread
/// small bright emitters. Only the beauty image changes: depth, normals, albedo, the specular
/// layer and every mask stay as rendered.
pub fn denoise(
    output: &mut RenderOutput,
    denoiser: &streaks_image::denoise::Denoiser,
) -> Result<(), streaks_image::denoise::DenoiseError> {
    let guides = output
        .albedo
        .as_ref()
        .map(|albedo| streaks_image::denoise::Guides {
            albedo,
            normal: output.normal.as_ref(),
        });
    let mut denoised = match &output.emission {
        Some(emission) => {
            let mut rest = output.image.clone();
            for (p, e) in rest.pixels.iter_mut().zip(&emission.pixels) {
                *p = (*p - *e).max(Vec3::ZERO);
            }
            denoiser.denoise(&rest, guides)?
        }
        None => denoiser.denoise(&output.image, guides)?,
    };
    if let Some(emission) = &output.emission {
        for (p, e) in denoised.pixels.iter_mut().zip(&emission.pixels) {
            *p += *e;
        }
    }
    output.raw = Some(std::mem::replace(&mut output.image, denoised));
    Ok(())
}

/// Writes the render as a float32 EXR: the beauty image and the layers present in `output`
/// (see the module documentation), atomically.
pub fn write_exr(path: &Path, output: &RenderOutput) -> Result<(), ImageError> {
    write_exr_with_sensor(path, output, None)
}

/// [`write_exr`] with the `sensor` layer (raw DN of a camera model, the size of the render)
/// when `sensor` is given.
pub fn write_exr_with_sensor(
    path: &Path,
    output: &RenderOutput,
    sensor: Option<&RgbImage>,
) -> Result<(), ImageError> {
    let img = &output.image;
    let mut channels: Vec<ExrChannel> = Vec::new();
    let mut push_rgb = |names: [&'static str; 3], image: &RgbImage| {
        for (c, name) in names.into_iter().enumerate() {
            channels.push((name, image.plane(c)));
        }
    };
    push_rgb(BEAUTY, img);
    for (names, layer) in [
        (RAW, &output.raw),
        (ALBEDO, &output.albedo),
        (SPECULAR, &output.specular),
    ] {
        if let Some(layer) = layer {
            push_rgb(names, layer);
        }
    }
    if let Some(normal) = &output.normal {
        push_rgb(NORMAL, normal);
    }
    if let Some(sensor) = sensor {
        push_rgb(SENSOR, sensor);
    }
    if let Some(depth) = &output.depth {
        channels.push((DEPTH, depth.clone()));
    }
    if let Some(spp) = &output.spp {
        channels.push((SPP, spp.iter().map(|&n| n as f32).collect()));
    }
    if let Some(rain) = &output.rain {
        channels.push((RAIN, rain.clone()));
    }
    if let Some(fog) = &output.fog {
        channels.push((FOG, fog.clone()));
    }
    if let Some(object) = &output.object {
        channels.push((OBJECT, object.iter().map(|&n| n as f32).collect()));
    }
    streaks_image::exr::write_exr(path, img.width, img.height, channels)
}

/// Every layer [`write_exr`] may write besides the beauty image ([`BEAUTY`]), by the name
/// [`read_exr_layer`] takes, with its channels: three for an RGB or XYZ layer, one otherwise.
pub const LAYERS: [(&str, &[&str]); 10] = [
    ("albedo", &ALBEDO),
    ("raw", &RAW),
    ("specular", &SPECULAR),
    ("sensor", &SENSOR),
    ("normal", &NORMAL),
    ("depth", &[DEPTH]),
    ("spp", &[SPP]),
    ("rain", &[RAIN]),
    ("fog", &[FOG]),
    ("object", &[OBJECT]),
];

/// Reads a layer written by [`write_exr`]: `"albedo"`, `"specular"`, `"sensor"` (RGB),
/// `"normal"` (XYZ into the RGB slots), `"depth"` (Z), `"spp"` (samples per pixel), `"rain"`
/// (rain share), `"fog"` (fog transmittance) or `"object"` (object slot; the last five one
/// channel, repeated into all three slots); see [`LAYERS`].
pub fn read_exr_layer(path: &Path, name: &str) -> Result<RgbImage, ImageError> {
    let Some((_, channels)) = LAYERS.iter().find(|(n, _)| *n == name) else {
        let names: Vec<&str> = LAYERS.iter().map(|(n, _)| *n).collect();
        return Err(ImageError::MissingChannels {
            path: path.to_path_buf(),
            what: format!("layer {name:?} (the layers are {})", names.join(", ")),
        });
    };
    let (w, h, planes) = read_exr_channels(path, channels)?;
    Ok(match planes.as_slice() {
        [r, g, b] => RgbImage::from_planes(w, h, [r, g, b]),
        _ => RgbImage::from_planes(w, h, [&planes[0], &planes[0], &planes[0]]),
    })
}

/// Every layer of a file [`write_exr`] wrote, as `(width, height, layers)`: first `"rgb"`, the
/// beauty image's channels `R`, `G`, `B` (required), then each layer of [`LAYERS`] the file
/// has, each with its channels' planes (row-major, three or one). The file is read once per
/// layer, each read as checked as [`read_exr_channels`]'s.
#[allow(clippy::type_complexity)]
pub fn read_exr_layers(
    path: &Path,
) -> Result<(u32, u32, Vec<(&'static str, Vec<Vec<f32>>)>), ImageError> {
    let (w, h, beauty) = read_exr_channels(path, &BEAUTY)?;
    let mut layers = vec![("rgb", beauty)];
    for (name, channels) in LAYERS {
        match read_exr_channels(path, channels) {
            Ok((lw, lh, planes)) if (lw, lh) == (w, h) => layers.push((name, planes)),
            Ok((lw, lh, _)) => {
                return Err(ImageError::Read {
                    path: path.to_path_buf(),
                    reason: format!("its layer {name} is {lw}x{lh}, its image {w}x{h}"),
                })
            }
            Err(ImageError::MissingChannels { .. }) => {}
            Err(e) => return Err(e),
        }
    }
    Ok((w, h, layers))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::RenderStats;
    use glam::Vec3;
    use streaks_image::exr::read_exr_rgb;

    fn gradient(w: u32, h: u32) -> RgbImage {
        RgbImage::from_fn(w, h, |x, y| {
            let i = (y * w + x) as f32;
            Vec3::new(i, 0.5 * i, -i)
        })
    }

    fn output(w: u32, h: u32) -> RenderOutput {
        RenderOutput {
            image: gradient(w, h),
            raw: None,
            depth: Some((0..w * h).map(|i| i as f32 + 0.25).collect()),
            normal: Some(RgbImage {
                pixels: vec![Vec3::Y; (w * h) as usize],
                ..RgbImage::new(w, h)
            }),
            albedo: None,
            specular: Some(gradient(w, h)),
            emission: None,
            material: None,
            object: Some((0..w * h).map(|i| 3 * i).collect()),
            spp: Some((0..w * h).map(|i| 16 + 8 * i).collect()),
            rain: Some((0..w * h).map(|i| i as f32 / 16.0).collect()),
            fog: Some((0..w * h).map(|i| 1.0 / (1 + i) as f32).collect()),
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
        let spp = read_exr_layer(&path, "spp").unwrap();
        assert_eq!(spp.get(2, 1).x, (16 + 8 * 7) as f32);
        let rain = read_exr_layer(&path, "rain").unwrap();
        assert_eq!(rain.get(2, 1).y, 7.0 / 16.0);
        let fog = read_exr_layer(&path, "fog").unwrap();
        assert_eq!(fog.get(2, 1).y, 1.0 / 8.0);
        let object = read_exr_layer(&path, "object").unwrap();
        assert_eq!(object.get(2, 1).z, 21.0);
        let err = read_exr_layer(&path, "albedo").unwrap_err();
        assert!(err.to_string().contains("albedo.R"), "{err}");
        let err = read_exr_layer(&path, "beauty").unwrap_err();
        assert!(err.to_string().contains("\"beauty\""), "{err}");
        // Only the image is left in the folder (no temporary files).
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        assert!(read_exr_layer(&path, "sensor").is_err());
        let raw = gradient(5, 3);
        write_exr_with_sensor(&path, &out, Some(&raw)).unwrap();
        assert_eq!(read_exr_layer(&path, "sensor").unwrap(), raw);
        assert_eq!(read_exr_rgb(&path).unwrap(), out.image);
    }

    #[test]
    fn a_layer_of_the_wrong_size_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.exr");
        let mut out = output(4, 2);
        out.depth = Some(vec![0.0; 3]);
        let err = write_exr(&path, &out).unwrap_err();
        assert!(err.to_string().contains("bad.exr"), "{err}");
        assert!(!path.exists());
    }
}
