//! Framing a view of a loaded scene: which camera, the image size from the asked width and
//! height and the camera's aspect ratio, and the rain drops placed around that camera. The
//! `streaks` commands and the Python package (`streaks.Scene`) frame their views with
//! [`frame_view`], so both see the same camera, size and drops for the same options.

use crate::camera::Camera;
use crate::motion::Motion;
use crate::rain::RainError;
use crate::scene::{Scene, SceneError};
use thiserror::Error;

/// Largest image accepted, in pixels (2^26, twice 8K UHD; the film keeps about 72 bytes per
/// pixel, so 4.5 GiB).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Default image height when neither the width nor the height is given.
pub const DEFAULT_HEIGHT: u32 = 480;

/// Why a view could not be framed.
#[derive(Debug, Error)]
pub enum ViewError {
    /// The asked or derived image size is zero, out of range or too large.
    #[error("{0}")]
    Size(String),
    /// The asked camera is not in the scene.
    #[error(transparent)]
    Camera(#[from] SceneError),
    /// The scene's rain could not be placed for the camera.
    #[error("the scene's rain: {0}")]
    Rain(#[from] RainError),
}

/// The image size from the asked `width` and `height` and the camera's `aspect` ratio (width /
/// height; 4:3 when unknown): both given are kept; one given derives the other from the aspect
/// ratio; none gives [`DEFAULT_HEIGHT`] rows. Zero, a derived size out of range and more than
/// [`MAX_PIXELS`] pixels are errors.
pub fn image_size(
    width: Option<u32>,
    height: Option<u32>,
    aspect: Option<f32>,
) -> Result<(u32, u32), ViewError> {
    let aspect = aspect
        .filter(|a| a.is_finite() && *a > 0.0)
        .unwrap_or(4.0 / 3.0) as f64;
    for (what, value) in [("width", width), ("height", height)] {
        if value == Some(0) {
            return Err(ViewError::Size(format!(
                "the image size must be positive, got a {what} of 0"
            )));
        }
    }
    let derive = |v: f64, what: &str| -> Result<u32, ViewError> {
        let r = v.round();
        if !(1.0..=u32::MAX as f64).contains(&r) {
            return Err(ViewError::Size(format!(
                "the derived image size ({what} {v:.1}) is out of range; give the width and \
                 the height"
            )));
        }
        Ok(r as u32)
    };
    let (w, h) = match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, derive(w as f64 / aspect, "height")?),
        (None, Some(h)) => (derive(h as f64 * aspect, "width")?, h),
        (None, None) => (
            derive(DEFAULT_HEIGHT as f64 * aspect, "width")?,
            DEFAULT_HEIGHT,
        ),
    };
    if w as u64 * h as u64 > MAX_PIXELS {
        return Err(ViewError::Size(format!(
            "the image size {w}x{h} is too large (at most {MAX_PIXELS} pixels)"
        )));
    }
    Ok((w, h))
}

/// A framed view of a scene: the camera and the image size.
#[derive(Clone, Debug)]
pub struct View {
    /// The chosen camera, or the default framing ([`Scene::default_camera`]).
    pub camera: Camera,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Whether the scene has no camera and the view is the default framing: the caller says so
    /// with [`crate::camera::FRAMING_WARNING`].
    pub framed: bool,
}

/// Frames a view of `scene`: the camera `camera` names ([`Scene::find_camera`]: a name, or a
/// number in the scene's list; the first by default, the default framing for a scene without
/// cameras), the image size of `width` and `height` with that camera's aspect ratio
/// ([`image_size`]), and the scene's rain drops placed for it with the shutter and rig motion of
/// `motion` ([`Scene::place_rain`]).
pub fn frame_view(
    scene: &mut Scene,
    camera: Option<&str>,
    width: Option<u32>,
    height: Option<u32>,
    motion: Motion,
) -> Result<View, ViewError> {
    let found = scene.find_camera(camera)?;
    let (width, height) = image_size(width, height, found.and_then(Camera::aspect_ratio))?;
    let (camera, framed) = match found {
        Some(camera) => (camera.clone(), false),
        None => (scene.default_camera(width as f32 / height as f32), true),
    };
    scene.place_rain(&camera, width, height, motion)?;
    Ok(View {
        camera,
        width,
        height,
        framed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_follow_the_aspect_ratio() {
        assert_eq!(
            image_size(None, None, Some(16.0 / 9.0)).unwrap(),
            (853, 480)
        );
        assert_eq!(image_size(None, None, None).unwrap(), (640, 480));
        assert_eq!(image_size(Some(320), None, Some(2.0)).unwrap(), (320, 160));
        assert_eq!(image_size(None, Some(100), Some(1.5)).unwrap(), (150, 100));
        assert_eq!(image_size(Some(7), Some(9), Some(2.0)).unwrap(), (7, 9));
        assert!(image_size(Some(0), None, None).is_err());
        assert!(image_size(Some(1), None, Some(100.0)).is_err());
        assert!(image_size(Some(u32::MAX), Some(u32::MAX), None).is_err());
        assert!(image_size(None, Some(u32::MAX), Some(4.0)).is_err());
    }
}
