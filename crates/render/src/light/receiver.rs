//! The shading point as the light choice sees it ([`Receiver`]): the one type that the choice
//! ([`super::choice`]) and the weights of a tree node's children (`child_weights`) both read,
//! kept apart from both so that neither imports the other for it.

use crate::bsdf::{Bsdf, Diffuse};
use crate::geometry::Frame;
use glam::Vec3;

/// What the light choice may know about the shading point: position, geometric normal,
/// shading frame, outgoing direction and BSDF.
#[derive(Clone, Copy, Debug)]
pub struct Receiver {
    /// Shading point.
    pub p: Vec3,
    /// Geometric normal, on the side of `wo`.
    pub ng: Vec3,
    /// Shading frame (normal on the side of `wo`).
    pub frame: Frame,
    /// Outgoing direction in the shading frame.
    pub wo_local: Vec3,
    /// BSDF at the point.
    pub bsdf: Bsdf,
}

impl Receiver {
    /// A point in a medium (a fog collision), which has no surface: its BSDF is black, so
    /// every `E F` weight of the choice is zero and the choice goes by the irradiance-like
    /// weight `E` alone, from every direction (no normal, no cosine; see [`super::choice`]).
    /// Its normal and frame are placeholders that nothing reads.
    #[inline]
    pub fn in_medium(p: Vec3) -> Self {
        Self {
            p,
            ng: Vec3::Z,
            frame: Frame::from_normal(Vec3::Z),
            wo_local: Vec3::Z,
            bsdf: Bsdf::Diffuse(Diffuse { kd: Vec3::ZERO }),
        }
    }
}
