//! Lights (INTERFACE SKELETON, filled in by the lights/integrator work).
//!
//! Scene contract (DESIGN.md): for point and spot lights `color * intensity` is the radiant
//! intensity in W/sr (linear RGB, no photometric conversion); for directional lights it is the
//! irradiance; emissive triangles are area lights of radiance `emission`.

use glam::Vec3;

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light.
    Point {
        /// World position.
        position: Vec3,
        /// Radiant intensity (W/sr), linear RGB.
        intensity: Vec3,
        /// glTF `range` (None = infinite).
        range: Option<f32>,
    },
    /// glTF spot light (smooth falloff between the inner and outer cone).
    Spot {
        /// World position.
        position: Vec3,
        /// Unit direction the spot points along (the node's local -Z), world space.
        direction: Vec3,
        /// Radiant intensity on the axis (W/sr).
        intensity: Vec3,
        /// cos(innerConeAngle).
        cos_inner: f32,
        /// cos(outerConeAngle).
        cos_outer: f32,
        /// glTF `range` (None = infinite).
        range: Option<f32>,
    },
    /// Directional light.
    Directional {
        /// Unit direction the light travels along (the node's local -Z), world space.
        direction: Vec3,
        /// Irradiance on a surface facing the light (W/m^2).
        irradiance: Vec3,
    },
    /// One emissive triangle of the scene; its radiance comes from its material.
    Triangle {
        /// Index into [`crate::scene::Scene::triangles`].
        triangle: u32,
    },
}
