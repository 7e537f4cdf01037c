//! Lights and the light choice, one file per concept:
//!
//! - [`punctual`]: [`Light`], the point, spot and directional lights of KHR_lights_punctual;
//! - [`emitter`]: [`Emitter`], what the light choice chooses between: a punctual light, or an
//!   emitter mesh ([`MeshEmitter`], connected emissive triangles of one material, which are
//!   area lights); [`Emitters`] builds the list once, with the scene;
//! - [`environment`]: [`Environment`], the light from directions that escape the scene (a
//!   constant or an equirectangular map), looked up by escaping rays and sampled as one more
//!   choice beside the tree;
//! - [`tree`]: [`LightTree`], the emitters grouped by position into a flat 16-ary tree;
//! - [`choice`]: [`LightSampler`], which picks an emitter per shading point by the irradiance
//!   and the BSDF toward it, down the tree, and samples it; and the density of that choice;
//! - `receiver`: [`Receiver`], the shading point as the choice and the children's weights see
//!   it;
//! - `child_weights`: the weights of a tree node's children, computed in SIMD lanes (4, 8 or 16 at a
//!   time, by [`crate::simd::level`]) from a structure-of-arrays copy of each node's children.
//!
//! A [`crate::scene::Scene`] builds its [`LightSampler`] when it is built: every render of the
//! scene (both eyes of a stereo pair) uses the same emitters and tree, and `rig.json` records
//! the same emitters for the analysis.
//!
//! Conventions of every `sample_li` (pbrt's `SampleLi`): `wi` points from the shading point
//! toward the light, `li` is the radiance arriving along `-wi` and `pdf` is the solid-angle
//! density of `wi`. Delta lights (point, spot, directional) are flagged with `delta: true`,
//! their `pdf` is 1 and `li` is already the incident irradiance on a surface facing the light
//! (intensity / r^2, or the directional irradiance), so `f * li * cos / pdf` is the estimate
//! either way.

mod child_weights;
pub mod choice;
pub mod emitter;
pub mod environment;
pub mod punctual;
mod receiver;
#[cfg(test)]
mod test_scenes;
pub mod tree;

pub use choice::LightSampler;
pub use emitter::{Emitter, Emitters, MeshEmitter, SurfaceMesh};
pub use environment::{Environment, EnvironmentError, EnvironmentMap};
pub use punctual::{range_window, spot_falloff, Light, LUMINOUS_EFFICACY};
pub use receiver::Receiver;
pub use tree::{LightTree, Node, BRANCHING};

use glam::Vec3;

/// A sampled direction toward a light, see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Distance to the light point (`inf` for directional lights and the environment).
    pub dist: f32,
    /// Incident radiance (area lights) or irradiance (delta lights).
    pub li: Vec3,
    /// Solid-angle density of `wi` (1 for delta lights).
    pub pdf: f32,
    /// Whether the light is a delta light (not reachable by BSDF sampling: no MIS).
    pub delta: bool,
    /// How to test that the light arrives.
    pub visibility: Visibility,
}

/// How the integrator decides whether a [`LightSample`] is visible.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// The sample is a point at `dist`: trace a shadow ray (any hit) up to it; `li` is the
    /// light's radiance there. With `dist` infinite (a directional light, the environment)
    /// the ray is unbounded and must escape the scene.
    ShadowRay,
    /// The sample is only a direction toward emitter `emitter` (sampled uniformly in the cone
    /// that bounds it): trace a closest-hit ray; the light arrives if the ray first hits one of
    /// that emitter's triangles, with the radiance that triangle emits toward the shading point
    /// (`li` is zero until then; `dist` is the distance to the far side of the emitter's
    /// bounding sphere, beyond which the ray need not look).
    FirstHit {
        /// Index of the emitter among the scene's [`Emitters`].
        emitter: u32,
    },
}
