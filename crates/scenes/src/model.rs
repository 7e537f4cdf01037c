//! A [`Model`]: an object built in its own frame (metres; +X right, +Y up, -Z forward, the
//! origin on the ground at the centre of its footprint) from [`Part`]s that each have a mesh,
//! a material and a semantic class, plus the punctual lights it carries. The generator builds
//! cars, street furniture and buildings as models and places each with one rigid transform
//! ([`Doc::add_model`]), so that an object's pose is one number to record, to move between the
//! frames of a sequence, and to derive motion ground truth from.

use crate::gltf_writer::{Class, Doc, Light, Material, Tag};
use crate::mesh::Mesh;
use crate::Error;
use glam::Affine3A;

/// One part of a model: a mesh in the model's frame with one material and one class.
#[derive(Clone, Debug)]
pub struct Part {
    /// The part's name (the node is named `MODEL/PART`).
    pub name: String,
    /// The mesh, in the model's frame.
    pub mesh: Mesh,
    /// Its material.
    pub material: Material,
    /// Its semantic class (a car's lamps are [`Class::LightSource`], its body [`Class::Car`]).
    pub class: Class,
}

/// An object in its own frame: parts and lights.
#[derive(Clone, Debug, Default)]
pub struct Model {
    /// The meshes.
    pub parts: Vec<Part>,
    /// Punctual lights, in the model's frame (positions and spot directions).
    pub lights: Vec<Light>,
}

impl Model {
    /// An empty model.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a part.
    pub fn push(&mut self, name: &str, mesh: Mesh, material: Material, class: Class) {
        self.parts.push(Part {
            name: name.to_owned(),
            mesh,
            material,
            class,
        });
    }

    /// The bounds (min, max) of the vertices of every part, moved by `pose`.
    pub fn bounds(&self, pose: Affine3A) -> (glam::Vec3, glam::Vec3) {
        let mut lo = glam::Vec3::splat(f32::INFINITY);
        let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
        for p in &self.parts {
            for &q in &p.mesh.positions {
                let q = pose.transform_point3(q);
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo, hi)
    }

    /// Adds every part and light of `other`, placed in this model's frame by `pose`.
    pub fn merge(&mut self, other: &Model, pose: Affine3A) {
        for p in &other.parts {
            self.parts.push(Part {
                mesh: transformed(&p.mesh, pose),
                ..p.clone()
            });
        }
        self.lights
            .extend(other.lights.iter().map(|l| transformed_light(l, pose)));
    }
}

/// `mesh` with positions moved by `pose` and normals by its inverse transpose (renormalised);
/// texture coordinates unchanged.
pub fn transformed(mesh: &Mesh, pose: Affine3A) -> Mesh {
    let normal = pose.matrix3.inverse().transpose();
    Mesh {
        positions: mesh
            .positions
            .iter()
            .map(|&p| pose.transform_point3(p))
            .collect(),
        normals: mesh
            .normals
            .iter()
            .map(|&n| (normal * n).normalize_or_zero())
            .collect(),
        uvs: mesh.uvs.clone(),
        indices: mesh.indices.clone(),
    }
}

/// `light` moved by `pose` (position, and the spot direction rotated).
pub fn transformed_light(light: &Light, pose: Affine3A) -> Light {
    Light {
        position: pose.transform_point3(light.position),
        direction: pose.transform_vector3(light.direction).normalize_or_zero(),
        ..light.clone()
    }
}

impl Doc {
    /// Adds every part of `model` placed in the world by `world_from_model` as a node
    /// `NAME/PART` tagged with the part's class and `instance` (`None` for stuff such as a
    /// building front), and its lights as `NAME/LIGHT`.
    pub fn add_model(
        &mut self,
        name: &str,
        model: &Model,
        world_from_model: Affine3A,
        instance: Option<u32>,
    ) -> Result<(), Error> {
        for p in &model.parts {
            let tag = Tag {
                class: p.class,
                instance,
            };
            self.add_tagged_mesh(
                &format!("{name}/{}", p.name),
                &transformed(&p.mesh, world_from_model),
                &p.material,
                tag,
            )?;
        }
        for l in &model.lights {
            let mut placed = transformed_light(l, world_from_model);
            placed.name = format!("{name}/{}", l.name);
            self.add_light(&placed);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    #[test]
    fn a_placed_box_keeps_its_faces_outward_and_its_size() {
        let mut m = Mesh::new();
        m.cuboid(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(1.0, 1.5, 2.0));
        let pose = Affine3A::from_rotation_translation(
            Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.05),
            Vec3::new(3.0, 0.2, -10.0),
        );
        let t = transformed(&m, pose);
        let centre = pose.transform_point3(Vec3::new(0.0, 0.75, 0.0));
        for tri in t.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| t.positions[tri[k] as usize]);
            let n = (b - a).cross(c - a);
            // Every face's geometric normal points away from the box's centre...
            assert!(n.dot(a - centre) > 0.0);
            // ... and agrees with the vertex normal.
            assert!(n.normalize().dot(t.normals[tri[0] as usize]) > 0.999);
        }
        let d = t.positions[0].distance(t.positions[1]);
        let d0 = m.positions[0].distance(m.positions[1]);
        assert!((d - d0).abs() < 1e-5);
    }
}
