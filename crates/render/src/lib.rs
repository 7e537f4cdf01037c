//! # streaks-render
//!
//! A physically based, BVH-accelerated path tracer for wet night streets.
//!
//! The main types, by concept (one module each, after pbrt-v4's division):
//!
//! - [`geometry`]: [`geometry::Ray`], the hit record [`geometry::SurfaceHit`], the shading
//!   [`geometry::Frame`], robust ray offsets.
//! - [`sampling`]: warps with their pdfs and inverses, MIS weights, discrete distributions and
//!   the Owen-scrambled Sobol sampler.
//! - [`bsdf`]: the closed set of reflectance models ([`bsdf::Bsdf`]): diffuse, the paper's
//!   `ggx`, `ward` and `blinn_phong`, and the glTF metallic-roughness BRDF.
//! - [`material`] and [`texture`]: what a scene stores; a material turns into a [`bsdf::Bsdf`]
//!   at a surface point. [`normal_map`]: tangent-space normal maps and the rule that keeps a
//!   perturbed shading normal valid.
//! - [`medium`]: the scene's fog ([`medium::Fog`]: extinction, albedo, height falloff, exact
//!   transmittance and free-flight sampling) and [`phase`]: its Henyey-Greenstein phase function.
//! - [`light`]: one file per concept: the punctual lights ([`light::Light`]), the emitters
//!   ([`light::Emitters`]: punctual lights and meshes of emissive triangles, built once with the
//!   scene), the light tree ([`light::LightTree`]) and the light choice ([`light::LightSampler`]).
//! - [`accel`]: the only module that sees obvhs; closest-hit and shadow queries.
//! - [`simd`]: the SIMD width (SSE, AVX2, AVX-512) of the hot kernels, chosen at run time.
//! - [`scene`]: loading glTF 2.0 and OBJ into a [`scene::Scene`], with errors that name the file
//!   and the element.
//! - [`camera`]: the pinhole camera of docs/design.md (pixel centres at `i + 0.5`, `f = (H/2)/tan(yfov/2)`).
//!   [`view`]: framing a view of a loaded scene (the camera, the image size, the rain drops).
//! - [`integrator`]: unidirectional path tracing with next-event estimation and MIS; one image
//!   is a [`integrator::RenderJob`]: its size, seed and layers, and how to sample it
//!   ([`streaks_settings::RenderSettings`], the `streaks-settings` crate's one type, which pairs
//!   and datasets nest too).
//! - [`film`]: the box-filtered film with its layers; [`output`]: the renderer's EXR layout
//!   (images, regions, file formats and comparisons are the `streaks-image` crate's).
//! - [`mitsuba`]: export to Mitsuba 3 (the reference renderer).
//! - [`testing`]: the chi-square harness for warps and BSDFs; [`regression`]: render
//!   regression tests against stored mean and variance images.
//!
//! ```
//! use glam::{Affine3A, Vec3};
//! use streaks_render::camera::Camera;
//! use streaks_render::integrator::{render, Layers, RenderJob};
//! use streaks_render::material::Material;
//! use streaks_render::scene::{Scene, SceneParts, TriangleMesh};
//! use streaks_settings::RenderSettings;
//!
//! // An emissive quad of radiance 2 filling the view of a camera at the origin.
//! let mut glow = Material::diffuse("glow", Vec3::ZERO);
//! glow.emission = Vec3::splat(2.0);
//! let scene = Scene::from_parts(SceneParts {
//!     mesh: TriangleMesh {
//!         positions: vec![
//!             Vec3::new(-9.0, -9.0, -1.0),
//!             Vec3::new(9.0, -9.0, -1.0),
//!             Vec3::new(9.0, 9.0, -1.0),
//!             Vec3::new(-9.0, 9.0, -1.0),
//!         ],
//!         triangles: vec![[0, 1, 2], [0, 2, 3]],
//!         triangle_materials: vec![0, 0],
//!         ..TriangleMesh::default()
//!     },
//!     materials: vec![glow],
//!     ..SceneParts::default()
//! })?;
//! // The scene's emitters are built with it: one mesh of two triangles.
//! assert_eq!(scene.light_sampler.emitters().len(), 1);
//! let camera = Camera::perspective("cam", Affine3A::IDENTITY, 0.8, None);
//! let job = RenderJob {
//!     width: 8,
//!     height: 6,
//!     seed: 0,
//!     layers: Layers::default(),
//!     settings: RenderSettings::new(4, 1),
//!     motion: Default::default(),
//! };
//! let out = render(&scene, &camera, &job, &|_| {});
//! assert!(out.image.pixels.iter().all(|p| (*p - Vec3::splat(2.0)).abs().max_element() < 1e-6));
//! # Ok::<(), streaks_render::scene::SceneError>(())
//! ```
#![deny(missing_docs)]

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod class;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod light;
pub mod material;
pub mod medium;
pub mod mitsuba;
pub mod motion;
pub mod normal_map;
pub mod output;
pub mod phase;
pub mod rain;
pub mod regression;
pub mod sampling;
pub mod scene;
pub mod simd;
pub mod testing;
pub mod texture;
pub mod view;
