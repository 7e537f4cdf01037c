//! A triangle mesh's vertex arrays and triangles ([`TriangleMesh`]), defined once for the
//! scene's flat world-space triangles and for each instanced mesh (in object space), checked
//! and completed the same way for both, and the points on its triangles that ray hits shade
//! ([`Geometry::surface_at`]).

use super::SceneError;
use crate::geometry::VertexAttributes;
use crate::light::SurfaceMesh;
use crate::material::Material;
use glam::{Vec2, Vec3, Vec4};
use std::path::Path;

/// The vertex arrays and triangles of a mesh: the scene's flat triangles (world space,
/// [`super::Scene::mesh`]) or an instanced mesh (object space, placed by
/// [`super::Instance`]s). Once checked (by [`super::Scene::from_parts`]) every vertex has a
/// unit or zero normal and a uv.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    /// A label for messages (`mesh "name" (index)` for a glTF mesh); empty for the flat
    /// triangles.
    pub name: String,
    /// Vertex positions (world space for the scene's flat triangles, object space for an
    /// instanced mesh).
    pub positions: Vec<Vec3>,
    /// One normal per vertex, or empty for face normals everywhere; a zero normal means "use
    /// the face normal" (where the file had none). Unit once checked.
    pub normals: Vec<Vec3>,
    /// One uv (`TEXCOORD_0`) per vertex, or empty for zeros (filled when checked).
    pub uvs: Vec<Vec2>,
    /// One tangent per vertex for normal maps (xyz: unit tangent, w: handedness +-1), or
    /// empty when no material has a normal map; a zero tangent means "not normal mapped here"
    /// (see [`crate::normal_map`]).
    pub tangents: Vec<Vec4>,
    /// One `TEXCOORD_1` per vertex, or empty when no primitive has one (`uvs` is read
    /// instead).
    pub uvs1: Vec<Vec2>,
    /// One vertex colour (`COLOR_0`, linear RGBA) per vertex, or empty when no primitive has
    /// them (white).
    pub colors: Vec<Vec4>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Material index of each triangle.
    pub triangle_materials: Vec<u32>,
    /// The slot in [`super::Scene::objects`] of each triangle (what it is part of, for the
    /// segmentation layers), or empty for all unlabelled ([`super::UNLABELLED_OBJECT`],
    /// filled when checked). An instanced mesh's are not read: each of its placements has
    /// its own ([`super::Instance::object`]).
    pub triangle_objects: Vec<u32>,
}

impl TriangleMesh {
    /// Checks every array length and index against the vertex count, `material_count` and
    /// `object_count`, normalises the normals and fills absent normals and uvs (zeros) and
    /// object slots ([`super::UNLABELLED_OBJECT`]). Errors name the element, prefixed by the
    /// mesh's name if it has one.
    pub(super) fn check(
        &mut self,
        source: &Path,
        material_count: usize,
        object_count: usize,
    ) -> Result<(), SceneError> {
        let prefix = if self.name.is_empty() {
            String::new()
        } else {
            format!("{}: ", self.name)
        };
        let bad = |element: String, reason: String| {
            SceneError::invalid(source, format!("{prefix}{element}"), reason)
        };
        let nv = self.positions.len();
        for (i, &p) in self.positions.iter().enumerate() {
            super::validate::position(p).map_err(|r| bad(format!("vertex {i}"), r))?;
        }
        if self.normals.is_empty() {
            self.normals = vec![Vec3::ZERO; nv];
        } else if self.normals.len() != nv {
            return Err(bad(
                "normals".into(),
                format!("{} normals for {nv} vertices", self.normals.len()),
            ));
        }
        for n in &mut self.normals {
            *n = n.normalize_or_zero();
        }
        if self.uvs.is_empty() {
            self.uvs = vec![Vec2::ZERO; nv];
        } else if self.uvs.len() != nv {
            return Err(bad(
                "uvs".into(),
                format!("{} uvs for {nv} vertices", self.uvs.len()),
            ));
        }
        if !self.tangents.is_empty() && self.tangents.len() != nv {
            return Err(bad(
                "tangents".into(),
                format!("{} tangents for {nv} vertices", self.tangents.len()),
            ));
        }
        if let Some(i) = self.tangents.iter().position(|t| !t.is_finite()) {
            return Err(bad(format!("vertex {i}"), "tangent is not finite".into()));
        }
        if !self.uvs1.is_empty() && self.uvs1.len() != nv {
            return Err(bad(
                "TEXCOORD_1".into(),
                format!("{} uvs for {nv} vertices", self.uvs1.len()),
            ));
        }
        if !self.colors.is_empty() && self.colors.len() != nv {
            return Err(bad(
                "vertex colours".into(),
                format!("{} colours for {nv} vertices", self.colors.len()),
            ));
        }
        if self.triangle_materials.len() != self.triangles.len() {
            return Err(bad(
                "triangle materials".into(),
                format!(
                    "{} material indices for {} triangles",
                    self.triangle_materials.len(),
                    self.triangles.len()
                ),
            ));
        }
        if self.triangle_objects.is_empty() {
            self.triangle_objects = vec![super::UNLABELLED_OBJECT; self.triangles.len()];
        } else if self.triangle_objects.len() != self.triangles.len() {
            return Err(bad(
                "triangle objects".into(),
                format!(
                    "{} object slots for {} triangles",
                    self.triangle_objects.len(),
                    self.triangles.len()
                ),
            ));
        }
        if let Some(i) = self
            .triangle_objects
            .iter()
            .position(|&o| o as usize >= object_count)
        {
            return Err(bad(
                format!("triangle {i}"),
                format!(
                    "object slot {} out of range ({object_count} objects)",
                    self.triangle_objects[i],
                ),
            ));
        }
        if nv > u32::MAX as usize {
            return Err(bad("vertices".into(), "more than 2^32 - 1 vertices".into()));
        }
        for (i, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&v| v as usize >= nv) {
                return Err(bad(
                    format!("triangle {i}"),
                    format!("vertex index {t:?} out of range ({nv} vertices)"),
                ));
            }
        }
        if let Some(i) = self
            .triangle_materials
            .iter()
            .position(|&m| m as usize >= material_count)
        {
            return Err(bad(
                format!("triangle {i}"),
                format!(
                    "material {} out of range ({material_count} materials)",
                    self.triangle_materials[i],
                ),
            ));
        }
        Ok(())
    }

    /// Approximate heap memory of the arrays.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.positions.as_slice())
            + std::mem::size_of_val(self.normals.as_slice())
            + std::mem::size_of_val(self.uvs.as_slice())
            + std::mem::size_of_val(self.tangents.as_slice())
            + std::mem::size_of_val(self.uvs1.as_slice())
            + std::mem::size_of_val(self.colors.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
            + std::mem::size_of_val(self.triangle_materials.as_slice())
            + std::mem::size_of_val(self.triangle_objects.as_slice())
    }

    /// The mesh's triangles with their vertex attributes and `materials`, as the emitters and
    /// the alpha test read them (once checked by [`super::Scene::from_parts`], which fills the
    /// uvs).
    #[inline]
    pub fn surface<'a>(&'a self, materials: &'a [Material]) -> SurfaceMesh<'a> {
        SurfaceMesh {
            positions: &self.positions,
            uvs: &self.uvs,
            uvs1: &self.uvs1,
            colors: &self.colors,
            triangles: &self.triangles,
            triangle_materials: &self.triangle_materials,
            materials,
        }
    }

    /// The mesh as [`Geometry`] (after [`TriangleMesh::check`], which fills normals and uvs).
    #[inline]
    pub(super) fn geometry<'a>(&'a self, materials: &'a [Material]) -> Geometry<'a> {
        Geometry {
            mesh: self.surface(materials),
            normals: &self.normals,
            tangents: &self.tangents,
        }
    }
}

/// A checked mesh's arrays as hit shading reads them (the scene's own arrays or an instanced
/// mesh's).
#[derive(Clone, Copy, Debug)]
pub(super) struct Geometry<'a> {
    /// Positions, texture coordinates, colours, triangles and materials.
    pub mesh: SurfaceMesh<'a>,
    /// One unit normal per vertex (zero: the face normal).
    pub normals: &'a [Vec3],
    /// One tangent per vertex, or empty.
    pub tangents: &'a [Vec4],
}

/// A point on a triangle, in the space of its mesh's vertices.
#[derive(Clone, Copy, Debug)]
pub(super) struct LocalSurface {
    /// Position.
    pub p: Vec3,
    /// Unit geometric normal from the winding (zero for a degenerate triangle).
    pub ng: Vec3,
    /// Unit interpolated vertex normal; `ng` where the vertices have none.
    pub ns: Vec3,
    /// Interpolated texture coordinates and colour.
    pub attributes: VertexAttributes,
    /// Material index.
    pub material: u32,
}

impl Geometry<'_> {
    /// The point of triangle `triangle` at barycentrics `b` (weights of its second and third
    /// vertices).
    #[inline]
    pub fn surface_at(&self, triangle: u32, b: Vec2) -> LocalSurface {
        let t = triangle as usize;
        let [i0, i1, i2] = self.mesh.triangles[t].map(|v| v as usize);
        let b0 = 1.0 - b.x - b.y;
        let positions = self.mesh.positions;
        let (p0, p1, p2) = (positions[i0], positions[i1], positions[i2]);
        let ng = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let p = p0 * b0 + p1 * b.x + p2 * b.y;
        let ns = self.normals[i0] * b0 + self.normals[i1] * b.x + self.normals[i2] * b.y;
        LocalSurface {
            p,
            ng,
            ns: ns.try_normalize().unwrap_or(ng),
            attributes: self.mesh.attributes_at(t, b),
            material: self.mesh.triangle_materials[t],
        }
    }

    /// The interpolated tangent of triangle `triangle` at barycentrics `b` (zero where the
    /// mesh has no tangents).
    #[inline]
    pub fn tangent_at(&self, triangle: u32, b: Vec2) -> Vec4 {
        if self.tangents.is_empty() {
            return Vec4::ZERO;
        }
        let t = self.mesh.triangles[triangle as usize].map(|v| self.tangents[v as usize]);
        t[0] * (1.0 - b.x - b.y) + t[1] * b.x + t[2] * b.y
    }
}
