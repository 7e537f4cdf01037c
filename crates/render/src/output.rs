//! Image output and input (INTERFACE SKELETON, filled in by the integrator/output work):
//! EXR (linear float32, named layers) and PNG (sRGB, exposure, clipping), written atomically
//! (a temporary file in the same folder, then a rename).

use glam::Vec3;

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
