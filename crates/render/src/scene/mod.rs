//! Scenes (INTERFACE SKELETON, filled in by the scene-loading work): one flat triangle soup in
//! world space with per-vertex attributes, materials, textures, lights, cameras and the BVH.

use crate::accel::Accel;
use crate::camera::Camera;
use crate::geometry::Ray;
use crate::light::Light;
use crate::material::Material;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::path::PathBuf;

/// A loaded scene, shared read-only by all render threads (never copied per thread).
#[derive(Debug)]
pub struct Scene {
    /// The file it was loaded from.
    pub source: PathBuf,
    /// World-space vertex positions.
    pub positions: Vec<Vec3>,
    /// World-space unit shading normals, one per vertex (face normals where the file had none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per vertex (zero where the file had none).
    pub uvs: Vec<Vec2>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Material index of each triangle.
    pub triangle_materials: Vec<u32>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Decoded textures.
    pub textures: Vec<Texture>,
    /// All lights, emissive triangles included.
    pub lights: Vec<Light>,
    /// Cameras, in file order.
    pub cameras: Vec<Camera>,
    /// The BVH over `triangles`.
    pub accel: Accel,
}

/// A ray's closest intersection with the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// World position.
    pub p: Vec3,
    /// Unit geometric normal (from the winding, not flipped toward the ray).
    pub ng: Vec3,
    /// Unit interpolated shading normal (oriented to the same side as `ng`).
    pub ns: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Triangle index.
    pub triangle: u32,
    /// Material index.
    pub material: u32,
}

impl Scene {
    /// Closest hit along `ray` within `[0, ray.t_max)`.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        let _ = ray;
        unimplemented!("skeleton")
    }

    /// Whether anything blocks `ray` within `[0, ray.t_max)` (shadow query).
    pub fn occluded(&self, ray: &Ray) -> bool {
        let _ = ray;
        unimplemented!("skeleton")
    }
}
