//! Mesh instancing: a mesh placed many times (by several glTF nodes, or by one node's
//! EXT_mesh_gpu_instancing attributes) is stored once, in object space, with its own BVH, and
//! each placement is an [`Instance`]: the mesh's index and its world-from-object affine
//! transform with the inverse and the normal matrix. A top-level BVH ([`Tlas`]) over the
//! instances' world boxes finds the instances a ray may hit; the ray is taken into each one's
//! object space with its direction unnormalised, so hit parameters are the world ray's.
//!
//! Hits are shaded in object space and taken to world space as the loader takes flattened
//! meshes: positions by the transform, normals (geometric and shading) by the inverse
//! transpose, tangents' xyz by the transform with the handedness flipped by a mirroring one.
//! The geometric normal from the inverse transpose is the one that a mirrored node's reversed
//! winding (glTF 2.0, section 3.7.4) gives, so front faces agree with the flat triangles'.
//!
//! Emissive meshes are never instanced (the emitters and the light tree work on world
//! triangles): the loader flattens them, and [`super::Scene::from_parts`] rejects an
//! instanced mesh with an emissive material.

use super::mesh::TriangleMesh;
use crate::accel::{Accel, AccelHit, Tlas};
use crate::geometry::Ray;
use glam::{Affine3A, Mat3A, Mat4, Vec2, Vec3, Vec4};

/// One placement of an instanced mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index of the mesh in [`Instances::meshes`].
    pub mesh: u32,
    /// The object-to-world transform.
    pub world_from_object: Affine3A,
    /// Its inverse.
    pub object_from_world: Affine3A,
    /// The inverse transpose of its linear part (normals to world space).
    pub world_from_object_normal: Mat3A,
    /// Whether the transform mirrors (negative determinant).
    pub mirrored: bool,
    /// The slot in [`super::Scene::objects`] of this placement's triangles
    /// ([`super::UNLABELLED_OBJECT`] unless set).
    pub object: u32,
}

impl Instance {
    /// Mesh `mesh` placed by `world_from_object` (an affine matrix; its last row is ignored).
    /// `None` when the transform is not finite or not invertible.
    pub fn new(mesh: u32, world_from_object: Mat4) -> Option<Self> {
        let m = Affine3A::from_mat4(world_from_object);
        let det = m.matrix3.determinant();
        if !m.is_finite() || !det.is_finite() || det.abs() < 1e-30 {
            return None;
        }
        let inverse = m.inverse();
        inverse.is_finite().then(|| Self {
            mesh,
            world_from_object: m,
            object_from_world: inverse,
            world_from_object_normal: inverse.matrix3.transpose(),
            mirrored: det < 0.0,
            object: super::UNLABELLED_OBJECT,
        })
    }

    /// `ray` in object space: origin and direction through the inverse transform, the
    /// direction not renormalised, so a parameter `t` means the same point on both.
    #[inline]
    pub fn object_ray(&self, ray: &Ray) -> Ray {
        Ray {
            origin: self.object_from_world.transform_point3(ray.origin),
            direction: self.object_from_world.transform_vector3(ray.direction),
            t_max: ray.t_max,
            time: ray.time,
        }
    }

    /// An object-space normal in world space, unit (zero if it is zero).
    #[inline]
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        (self.world_from_object_normal * n).normalize_or_zero()
    }

    /// An object-space tangent (xyz: direction, w: handedness) in world space (xyz not
    /// normalised).
    #[inline]
    pub fn tangent_to_world(&self, t: Vec4) -> Vec4 {
        let w = if self.mirrored { -t.w } else { t.w };
        self.world_from_object
            .transform_vector3(t.truncate())
            .extend(w)
    }
}

/// An instanced mesh: its checked object-space arrays and its BVH.
#[derive(Debug)]
pub struct InstancedMesh {
    /// The vertex arrays and triangles, in object space.
    pub mesh: TriangleMesh,
    /// The BVH over them (the instance's BLAS).
    pub accel: Accel,
}

/// A scene's instanced meshes and their instances, with the top-level BVH over the instances.
#[derive(Debug, Default)]
pub struct Instances {
    /// The meshes, each stored once.
    pub meshes: Vec<InstancedMesh>,
    /// The placements.
    pub instances: Vec<Instance>,
    /// The BVH over the instances' world boxes (`None` without instances).
    tlas: Option<Tlas>,
    /// The world box of all instances (`None` without instances or without triangles).
    bounds: Option<[Vec3; 2]>,
}

/// A closest hit on an instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct InstanceHit {
    /// Index of the instance in [`Instances::instances`].
    pub instance: u32,
    /// The hit on its mesh (triangle index into the mesh's triangles).
    pub hit: AccelHit,
}

impl Instances {
    /// The meshes (checked) with their BVHs, the instances (whose mesh indices are in range;
    /// those of meshes without triangles are dropped), their world boxes (the box of each
    /// instance's transformed vertices, so as tight as the flattened triangles' would be) and
    /// the TLAS over them. An instance whose box is not finite or reaches beyond
    /// [`super::validate::MAX_COORDINATE`] (a large scale times a large coordinate) is an
    /// error: the element (instance and mesh) and the reason.
    pub(super) fn build(
        meshes: Vec<InstancedMesh>,
        mut instances: Vec<Instance>,
    ) -> Result<Self, (String, String)> {
        // An instance of a mesh without triangles can be hit by nothing (and has no box).
        instances.retain(|i| !meshes[i.mesh as usize].mesh.triangles.is_empty());
        let mut boxes: Vec<[Vec3; 2]> = Vec::with_capacity(instances.len());
        for (i, inst) in instances.iter().enumerate() {
            let m = &meshes[inst.mesh as usize].mesh;
            let b = m.positions.iter().fold(
                [Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)],
                |[lo, hi], &p| {
                    let q = inst.world_from_object.transform_point3(p);
                    [lo.min(q), hi.max(q)]
                },
            );
            for corner in b {
                super::validate::position(corner).map_err(|r| {
                    let mesh = if m.name.is_empty() {
                        format!("mesh {}", inst.mesh)
                    } else {
                        m.name.clone()
                    };
                    (format!("instance {i} of {mesh}"), format!("world box: {r}"))
                })?;
            }
            boxes.push(b);
        }
        let bounds = boxes.iter().filter(|[lo, hi]| lo.cmple(*hi).all()).fold(
            None,
            |acc: Option<[Vec3; 2]>, &[lo, hi]| {
                Some(acc.map_or([lo, hi], |[a, b]| [a.min(lo), b.max(hi)]))
            },
        );
        Ok(Self {
            tlas: Tlas::build(&boxes),
            meshes,
            instances,
            bounds,
        })
    }

    /// Whether there are no instances.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// The world box `[min, max]` of all instances' vertices, if there are any.
    pub fn bounds(&self) -> Option<[Vec3; 2]> {
        self.bounds
    }

    /// The number of triangles stored (each mesh once).
    pub fn stored_triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.mesh.triangles.len()).sum()
    }

    /// The number of triangles the instances place in the world (what flattening would
    /// store).
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh as usize].mesh.triangles.len())
            .sum()
    }

    /// Approximate heap memory of the meshes, their BVHs, the instances and the TLAS.
    pub fn memory_bytes(&self) -> usize {
        let meshes: usize = self
            .meshes
            .iter()
            .map(|m| m.accel.memory_bytes() + m.mesh.memory_bytes())
            .sum();
        meshes
            + std::mem::size_of_val(self.instances.as_slice())
            + self.tlas.as_ref().map_or(0, Tlas::memory_bytes)
    }

    /// The closest hit on an instance with `t_min < t < ray.t_max` where `stops(instance,
    /// triangle, barycentrics)` accepts it (asked only for alpha-tested triangles).
    #[inline]
    pub(super) fn intersect(
        &self,
        ray: &Ray,
        t_min: f32,
        mut stops: impl FnMut(u32, u32, Vec2) -> bool,
    ) -> Option<InstanceHit> {
        let tlas = self.tlas.as_ref()?;
        let mut best = None;
        tlas.closest(ray, t_min, |i, t_max| {
            let inst = &self.instances[i as usize];
            let mut r = inst.object_ray(ray);
            r.t_max = t_max;
            match self.meshes[inst.mesh as usize]
                .accel
                .intersect_object(&r, t_min, |t, b| stops(i, t, b))
            {
                Some(hit) => {
                    best = Some(InstanceHit { instance: i, hit });
                    hit.t
                }
                None => f32::INFINITY,
            }
        });
        best
    }

    /// Whether some instance blocks `ray` within `(t_min, ray.t_max)`, with the alpha test
    /// of [`Instances::intersect`].
    #[inline]
    pub(super) fn occluded(
        &self,
        ray: &Ray,
        t_min: f32,
        mut stops: impl FnMut(u32, u32, Vec2) -> bool,
    ) -> bool {
        let Some(tlas) = self.tlas.as_ref() else {
            return false;
        };
        tlas.any(ray, t_min, |i| {
            let inst = &self.instances[i as usize];
            self.meshes[inst.mesh as usize].accel.occluded_object(
                &inst.object_ray(ray),
                t_min,
                |t, b| stops(i, t, b),
            )
        })
    }
}
