//! Mesh primitives: their vertex attributes taken to world space, triangulation of strips and
//! fans, and tangents for normal maps (the file's, or MikkTSpace's).

use super::{accessors, mesh_label, Loader};
use crate::scene::{points_bounds, tangents, validate, SceneError};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

/// Triangles (local vertex indices) of a triangle, strip or fan primitive (glTF 2.0 section
/// 3.7.2.1); degenerate strip and fan triangles are kept (they are never hit).
pub(super) fn triangulate(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (0..idx.len().saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i], idx[i + 1], idx[i + 2]]
                } else {
                    [idx[i + 1], idx[i], idx[i + 2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..idx.len().saturating_sub(1))
            .map(|i| [idx[i], idx[i + 1], idx[0]])
            .collect(),
        _ => Vec::new(),
    }
}

/// The pose a mesh is placed in: the morph weights (weight i scales target i's deltas;
/// missing weights are 0) and, for a skinned placement, the skin's joint matrices (each
/// joint's world transform times its inverse bind matrix; empty: unskinned).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Pose<'a> {
    pub(super) weights: &'a [f32],
    pub(super) joints: &'a [Mat4],
}

impl Loader<'_> {
    /// Adds `mesh` placed by `world` to the scene's world triangles, in `pose`: its morph
    /// weights first, then its skin.
    pub(super) fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        world: Mat4,
        pose: Pose,
    ) -> Result<(), SceneError> {
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        let flip = world.determinant() < 0.0;
        for prim in mesh.primitives() {
            let element = format!("{}, primitive {}", mesh_label(mesh), prim.index());
            let mode = prim.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                let element = format!("{element} ({mode:?})");
                let without = "skipped: only triangles are rendered";
                self.warn("point and line primitives", "primitive", &element, without);
                continue;
            }
            let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
                return Err(self.bad(element, "has no POSITION attribute"));
            };
            if let Some(a) = prim.indices() {
                self.check_accessor(
                    &a,
                    &format!("{element}, indices"),
                    &[
                        (Dimensions::Scalar, DataType::U8),
                        (Dimensions::Scalar, DataType::U16),
                        (Dimensions::Scalar, DataType::U32),
                    ],
                )?;
            }
            let mut positions: Vec<Vec3> = self
                .attribute(&pos_acc, &element, "POSITION", accessors::POSITION, None)?
                .into_iter()
                .map(Vec3::from)
                .collect();
            let n = positions.len();
            let mut normals: Vec<Vec3> = match prim.get(&gltf::Semantic::Normals) {
                Some(a) => self
                    .attribute(&a, &element, "NORMAL", accessors::DIRECTION, Some(n))?
                    .into_iter()
                    .map(Vec3::from)
                    .collect(),
                None => vec![Vec3::ZERO; n],
            };
            let tangent_deltas =
                self.morph(&prim, &element, pose.weights, &mut positions, &mut normals)?;
            let skin = self.skin(&prim, &element, pose.joints, n)?;
            if let Some(skin) = &skin {
                for ((p, v), m) in positions.iter_mut().zip(&mut normals).zip(skin) {
                    *p = m.transform_point3(*p);
                    *v = Mat3::from_mat4(*m).inverse().transpose() * *v;
                }
            }
            for v in &mut normals {
                *v = (normal_matrix * *v).try_normalize().unwrap_or(Vec3::ZERO);
            }
            let uvs: Vec<Vec2> = match prim.get(&gltf::Semantic::TexCoords(0)) {
                Some(a) => self
                    .attribute(&a, &element, "TEXCOORD_0", accessors::TEXCOORD, Some(n))?
                    .into_iter()
                    .map(Vec2::from)
                    .collect(),
                None => vec![Vec2::ZERO; n],
            };
            // A normal-mapped primitive's tangents: the file's if it has TANGENT and NORMAL.
            let normal_mapped = prim
                .material()
                .index()
                .is_some_and(|i| self.parts.materials[i].tangent_space_map().is_some());
            let has_normals = prim.get(&gltf::Semantic::Normals).is_some();
            let tangent_acc = prim
                .get(&gltf::Semantic::Tangents)
                .filter(|_| normal_mapped);
            let file_tangents: Option<Vec<[f32; 4]>> = match &tangent_acc {
                Some(a) if has_normals => {
                    let mut t: Vec<[f32; 4]> =
                        self.attribute(a, &element, "TANGENT", accessors::DIRECTION, Some(n))?;
                    for (t, d) in t.iter_mut().zip(tangent_deltas.iter().flatten()) {
                        let moved = Vec3::new(t[0], t[1], t[2]) + *d;
                        (t[0], t[1], t[2]) = (moved.x, moved.y, moved.z);
                    }
                    for (t, m) in t.iter_mut().zip(skin.iter().flatten()) {
                        let moved = m.transform_vector3(Vec3::new(t[0], t[1], t[2]));
                        (t[0], t[1], t[2]) = (moved.x, moved.y, moved.z);
                    }
                    Some(t)
                }
                _ => None,
            };
            let buffers = &self.buffers;
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.0.as_slice()));
            let uvs1: Option<Vec<Vec2>> = match prim.get(&gltf::Semantic::TexCoords(1)) {
                Some(a) => Some(
                    self.attribute(&a, &element, "TEXCOORD_1", accessors::TEXCOORD, Some(n))?
                        .into_iter()
                        .map(Vec2::from)
                        .collect(),
                ),
                None => None,
            };
            let colors: Option<Vec<Vec4>> = match prim.get(&gltf::Semantic::Colors(0)) {
                Some(a) if a.dimensions() == Dimensions::Vec3 => Some(
                    self.attribute::<3>(&a, &element, "COLOR_0", accessors::COLOR, Some(n))?
                        .into_iter()
                        .map(|c| Vec3::from(c).extend(1.0))
                        .collect(),
                ),
                Some(a) => Some(
                    self.attribute::<4>(&a, &element, "COLOR_0", accessors::COLOR, Some(n))?
                        .into_iter()
                        .map(Vec4::from)
                        .collect(),
                ),
                None => None,
            };
            if colors
                .as_ref()
                .is_some_and(|c| c.iter().any(|c| !c.is_finite()))
            {
                return Err(self.bad(format!("{element}, COLOR_0"), "contains a non-finite value"));
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(it) => it.into_u32().collect(),
                None => (0..n as u32).collect(),
            };
            if let Some(bad) = indices.iter().find(|&&i| i as usize >= n) {
                return Err(self.bad(
                    format!("{element}, indices"),
                    format!("index {bad} out of range ({n} vertices)"),
                ));
            }
            let mut tris = triangulate(mode, &indices);
            if mode == Mode::Triangles && indices.len() % 3 != 0 {
                self.warn(
                    "a triangle index count that is not a multiple of 3",
                    "primitive",
                    &element,
                    "the indices after the last whole triangle are ignored",
                );
            }
            let material = match prim.material().index() {
                Some(i) => i as u32,
                None => self.default_material(),
            };
            if flip {
                tris.iter_mut().for_each(|t| t.swap(1, 2));
            }
            let mut positions: Vec<Vec3> = positions
                .iter()
                .map(|&p| world.transform_point3(p))
                .collect();
            // In world space: a finite vertex times a large scale may overflow.
            for (k, &p) in positions.iter().enumerate() {
                validate::position(p).map_err(|r| self.bad(format!("{element}, vertex {k}"), r))?;
            }
            let (mut normals, mut uvs) = (normals, uvs);
            let (mut uvs1, mut colors) = (uvs1, colors);
            let tangents = if normal_mapped {
                let (t, copies) = match file_tangents {
                    Some(t) => (tangents::to_world(t.into_iter(), world), Vec::new()),
                    None => {
                        let has = (
                            tangent_acc.is_some(),
                            prim.get(&gltf::Semantic::TexCoords(0)).is_some(),
                        );
                        // MikkTSpace works in the normal map's own texture space: its uv set
                        // through its KHR_texture_transform (a rotation turns the frame).
                        let map_uvs: Vec<Vec2> =
                            match self.parts.materials[material as usize].tangent_space_map() {
                                Some(map) => (0..uvs.len())
                                    .map(|i| {
                                        let uv1 = uvs1.as_ref().map_or(uvs[i], |u| u[i]);
                                        map.texture.uv([uvs[i], uv1])
                                    })
                                    .collect(),
                                None => uvs.clone(),
                            };
                        self.tangents(&element, has, &positions, &normals, &map_uvs, &mut tris)
                    }
                };
                tangents::extend_copies(&mut positions, &copies);
                tangents::extend_copies(&mut normals, &copies);
                tangents::extend_copies(&mut uvs, &copies);
                if let Some(uvs1) = &mut uvs1 {
                    tangents::extend_copies(uvs1, &copies);
                }
                if let Some(colors) = &mut colors {
                    tangents::extend_copies(colors, &copies);
                }
                Some(t)
            } else {
                None
            };
            if uvs1.is_none()
                && self.parts.materials[material as usize]
                    .texture_refs()
                    .any(|t| t.texcoord == 1)
            {
                self.warn(
                    "a material reading TEXCOORD_1 the primitive does not have",
                    "primitive",
                    &element,
                    "TEXCOORD_0 is read instead",
                );
            }
            let first = self.parts.mesh.positions.len();
            if first + positions.len() > u32::MAX as usize {
                return Err(self.bad(element, "the scene has more than 2^32 - 1 vertices"));
            }
            self.primitive_boxes.extend(points_bounds(&positions));
            let out = &mut self.parts.mesh;
            if let Some(t) = tangents {
                out.tangents.resize(first, Vec4::ZERO);
                out.tangents.extend(t);
            }
            let first = first as u32;
            for t in &mut tris {
                *t = t.map(|i| i + first);
            }
            out.positions.extend(positions);
            out.normals.extend(normals);
            // The second uv set and the colours are stored only once some primitive has them:
            // earlier vertices get TEXCOORD_0 and white, as do later primitives without them.
            match uvs1 {
                Some(uvs1) => {
                    if out.uvs1.is_empty() {
                        out.uvs1 = out.uvs.clone();
                    }
                    out.uvs1.extend(uvs1);
                }
                None if !out.uvs1.is_empty() => out.uvs1.extend_from_slice(&uvs),
                None => {}
            }
            match colors {
                Some(colors) => {
                    if out.colors.is_empty() {
                        out.colors = vec![Vec4::ONE; out.uvs.len()];
                    }
                    out.colors.extend(colors);
                }
                None if !out.colors.is_empty() => {
                    out.colors.extend(std::iter::repeat_n(Vec4::ONE, uvs.len()));
                }
                None => {}
            }
            out.uvs.extend(uvs);
            out.triangle_materials
                .extend(std::iter::repeat_n(material, tris.len()));
            out.triangles.extend(tris);
        }
        Ok(())
    }

    /// Moves a primitive's object-space `positions` and `normals` to the pose of the morph
    /// `weights`: each target i adds weight i times its POSITION and NORMAL deltas (glTF 2.0,
    /// "Morph Targets"; normals are renormalised later). Returns the sum of the weighted
    /// TANGENT deltas, for the file's tangents, where a target has them. A target without a
    /// weight, or with weight 0, is not read; a non-finite weight is an error.
    fn morph(
        &self,
        prim: &gltf::Primitive,
        element: &str,
        weights: &[f32],
        positions: &mut [Vec3],
        normals: &mut [Vec3],
    ) -> Result<Option<Vec<Vec3>>, SceneError> {
        let n = positions.len();
        let mut tangents: Option<Vec<Vec3>> = None;
        for (i, target) in prim.morph_targets().enumerate() {
            let w = weights.get(i).copied().unwrap_or(0.0);
            if !w.is_finite() {
                let why = format!("morph target {i}'s weight {w} is not finite");
                return Err(self.bad(element, why));
            }
            if w == 0.0 {
                continue;
            }
            let add = |out: &mut [Vec3], deltas: Vec<[f32; 3]>| {
                for (v, d) in out.iter_mut().zip(deltas) {
                    *v += w * Vec3::from(d);
                }
            };
            let name = |attribute: &str| format!("morph target {i} {attribute}");
            if let Some(a) = target.positions() {
                let name = name("POSITION");
                add(
                    positions,
                    self.attribute(&a, element, &name, accessors::POSITION, Some(n))?,
                );
            }
            // Normal deltas only where the primitive has normals (else they are the face's).
            if let Some(a) = target
                .normals()
                .filter(|_| prim.get(&gltf::Semantic::Normals).is_some())
            {
                let name = name("NORMAL");
                add(
                    normals,
                    self.attribute(&a, element, &name, accessors::DIRECTION, Some(n))?,
                );
            }
            if let Some(a) = target.tangents() {
                let name = name("TANGENT");
                let deltas = self.attribute(&a, element, &name, accessors::DIRECTION, Some(n))?;
                add(tangents.get_or_insert_with(|| vec![Vec3::ZERO; n]), deltas);
            }
        }
        Ok(tangents)
    }

    /// The skinning matrix of each of a primitive's `n` vertices, `sum_k w_k * joints[j_k]`
    /// over its JOINTS_s / WEIGHTS_s sets (glTF 2.0, "Skins"; `joints` are the skin's joint
    /// matrices, world times inverse bind matrix); `None` for an unskinned placement (no
    /// joints). A joint index past the skin's joints, or a skinned placement of a primitive
    /// without JOINTS_0 and WEIGHTS_0, is an error.
    fn skin(
        &self,
        prim: &gltf::Primitive,
        element: &str,
        joints: &[Mat4],
        n: usize,
    ) -> Result<Option<Vec<Mat4>>, SceneError> {
        if joints.is_empty() {
            return Ok(None);
        }
        let mut skin = vec![Mat4::ZERO; n];
        let mut set = 0;
        while let (Some(j), Some(w)) = (
            prim.get(&gltf::Semantic::Joints(set)),
            prim.get(&gltf::Semantic::Weights(set)),
        ) {
            let (jn, wn) = (format!("JOINTS_{set}"), format!("WEIGHTS_{set}"));
            let indices = self.attribute::<4>(&j, element, &jn, accessors::JOINTS, Some(n))?;
            let weights = self.attribute::<4>(&w, element, &wn, accessors::COLOR, Some(n))?;
            for ((m, js), ws) in skin.iter_mut().zip(indices).zip(weights) {
                for (j, w) in js.into_iter().zip(ws).filter(|&(_, w)| w != 0.0) {
                    let Some(joint) = joints.get(j as usize) else {
                        let why = format!("joint {j} is not one of the skin's {}", joints.len());
                        return Err(self.bad(format!("{element}, {jn}"), why));
                    };
                    *m += *joint * w;
                }
            }
            set += 1;
        }
        if set == 0 {
            let why = "is skinned (its node has a skin) but has no JOINTS_0 and WEIGHTS_0";
            return Err(self.bad(element, why));
        }
        Ok(Some(skin))
    }

    /// The generated tangents of a normal-mapped primitive without usable TANGENT (see
    /// [`tangents`]): MikkTSpace's from the world-space `positions`, `normals` (zero: the face
    /// normal) and `uvs`, which may renumber `tris` to duplicated vertices (the second value
    /// lists the vertex each duplicate copies). `has` says whether the primitive has TANGENT
    /// (then ignored: it has no NORMAL) and TEXCOORD_0 (without it there is nothing to map:
    /// zero tangents). Both cases are warned about.
    pub(super) fn tangents(
        &mut self,
        element: &str,
        has: (bool, bool),
        positions: &[Vec3],
        normals: &[Vec3],
        uvs: &[Vec2],
        tris: &mut [[u32; 3]],
    ) -> (Vec<Vec4>, Vec<u32>) {
        let (has_tangents, has_uvs) = has;
        if !has_uvs {
            self.warn(
                "a normal texture on a primitive without TEXCOORD_0",
                "primitive",
                element,
                "rendered without the normal map",
            );
            return (vec![Vec4::ZERO; positions.len()], Vec::new());
        }
        if has_tangents {
            self.warn(
                "TANGENT without NORMAL",
                "primitive",
                element,
                "the tangents are ignored and generated from flat normals, as the glTF \
                 specification says",
            );
        }
        tangents::generate(positions, normals, uvs, tris).unwrap_or_else(|valence| {
            let what = format!(
                "a vertex shared by more triangles than MikkTSpace can take ({}: it recurses \
                 once per triangle around a vertex; here {valence})",
                tangents::MAX_VALENCE
            );
            self.warn(
                &what,
                "primitive",
                element,
                "rendered without the normal map",
            );
            (vec![Vec4::ZERO; positions.len()], Vec::new())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{
        add_accessor, add_tangent, add_vec3s, error, load_doc, load_err, normal_mapped_doc,
        png_uri, quad_normal, test_doc, with, write_embedded,
    };
    use super::*;

    use crate::scene::Scene;
    use glam::{Mat4, Vec3};
    use serde_json::json;

    use std::time::{Duration, Instant};

    /// Skins in the rest pose: each vertex is moved by its weighted joint matrices (the
    /// joints' world transforms times their inverse bind matrices), and the skinned mesh
    /// node's own transform is ignored.
    #[test]
    fn skins_place_vertices_by_their_joints() {
        let (mut doc, mut bin) = test_doc();
        // The lamp's triangle (0,0,0), (1,0,0), (0,1,0): vertex 0 on joint 0, vertex 1 on
        // joint 1, vertex 2 half on each.
        let joints: Vec<u8> = [0, 1, 0, 0].repeat(3);
        let j = add_accessor(&mut doc, &mut bin, &joints, (5121, 3, "VEC4"));
        let weights = [1f32, 0., 0., 0., 0., 1., 0., 0., 0.5, 0.5, 0., 0.];
        let bytes: Vec<u8> = weights.iter().flat_map(|f| f.to_le_bytes()).collect();
        let w = add_accessor(&mut doc, &mut bin, &bytes, (5126, 3, "VEC4"));
        // Joint 0's inverse bind matrix is the identity, joint 1's a translation by +X.
        let ibm: Vec<f32> = Mat4::IDENTITY
            .to_cols_array()
            .into_iter()
            .chain(Mat4::from_translation(Vec3::X).to_cols_array())
            .collect();
        let bytes: Vec<u8> = ibm.iter().flat_map(|f| f.to_le_bytes()).collect();
        let m = add_accessor(&mut doc, &mut bin, &bytes, (5126, 2, "MAT4"));
        let attributes = &mut doc["meshes"][1]["primitives"][0]["attributes"];
        attributes["JOINTS_0"] = json!(j);
        attributes["WEIGHTS_0"] = json!(w);
        // Joint 0 at (0, 5, 0) under the node "bulb" (1, 2, 3): (1, 7, 3); joint 1 at the
        // origin. The lamp node's translation (0, 0, -3) is ignored.
        let nodes = doc["nodes"].as_array_mut().unwrap();
        nodes.push(json!({"name": "bone0", "translation": [0, 5, 0]}));
        nodes.push(json!({"name": "bone1"}));
        nodes[4]["children"] = json!([7]);
        doc["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!(8));
        doc["nodes"][2]["skin"] = json!(0);
        doc["skins"] = json!([{"joints": [7, 8], "inverseBindMatrices": m}]);
        let scene = load_doc(doc.clone(), &bin);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let expected = [
            Vec3::new(1.0, 7.0, 3.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.0, 4.5, 1.5),
        ];
        for (got, want) in scene.mesh.positions[4..].iter().zip(expected) {
            assert!((*got - want).length() < 1e-5, "{got} != {want}");
        }
        // A joint index past the skin's joints names the attribute.
        doc["skins"][0]["joints"] = json!([7]);
        doc["skins"][0]
            .as_object_mut()
            .unwrap()
            .remove("inverseBindMatrices");
        let err = load_err(doc.clone(), &bin);
        assert!(err.contains("JOINTS_0") && err.contains("joint 1"), "{err}");
        // A joint outside the scene names the skin.
        doc["skins"][0]["joints"] = json!([7, 6]);
        doc["scenes"][0]["nodes"] = json!([0, 2, 3, 4, 5]);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("skin 0 of node \"lamp\" (2)") && err.contains("\"sun\""),
            "{err}"
        );
    }

    /// Morph targets in the specification's default pose: each vertex moves by the sum of
    /// the weights times the targets' deltas, the weights being the node's, else the mesh's;
    /// two nodes placing one morphed mesh each get their own pose.
    #[test]
    fn morph_targets_take_the_default_weights() {
        let (mut doc, mut bin) = test_doc();
        // The lamp's triangle (0,0,0), (1,0,0), (0,1,0) at z = -3: target 0 lifts every vertex
        // by +Z, target 1 moves vertex 0 by +X and has NORMAL deltas.
        let up = add_vec3s(&mut doc, &mut bin, &[0., 0., 1.].repeat(3));
        let side = add_vec3s(&mut doc, &mut bin, &[1., 0., 0., 0., 0., 0., 0., 0., 0.]);
        let nrm = add_vec3s(&mut doc, &mut bin, &[0.; 9]);
        doc["meshes"][1]["primitives"][0]["targets"] =
            json!([{"POSITION": up}, {"POSITION": side, "NORMAL": nrm}]);
        doc["meshes"][1]["weights"] = json!([0.5, 0.25]);
        // A second placement of the same mesh whose node has its own weights.
        doc["nodes"].as_array_mut().unwrap().push(
            json!({"name": "lamp2", "mesh": 1, "translation": [0, 0, -10], "weights": [1, 0]}),
        );
        doc["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!(7));
        let scene = load_doc(doc.clone(), &bin);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        // The quad's 4 vertices first, then the lamp's 3, then lamp2's 3.
        let p = &scene.mesh.positions;
        assert_eq!(p.len(), 10);
        let expected = [
            Vec3::new(0.25, 0.0, -2.5),
            Vec3::new(1.0, 0.0, -2.5),
            Vec3::new(0.0, 1.0, -2.5),
            Vec3::new(0.0, 0.0, -9.0),
            Vec3::new(1.0, 0.0, -9.0),
            Vec3::new(0.0, 1.0, -9.0),
        ];
        for (got, want) in p[4..].iter().zip(expected) {
            assert!((*got - want).length() < 1e-6, "{got} != {want}");
        }
        // No weights anywhere: the base shape.
        let mut rest = doc.clone();
        rest["meshes"][1].as_object_mut().unwrap().remove("weights");
        let scene = load_doc(rest, &bin);
        assert!((scene.mesh.positions[4] - Vec3::new(0.0, 0.0, -3.0)).length() < 1e-6);
        // A weight beyond f32's range is an error naming the primitive.
        doc["meshes"][1]["weights"] = json!([1e39, 0]);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("mesh \"tri\" (1), primitive 0") && err.contains("weight"),
            "{err}"
        );
    }

    #[test]
    fn index_out_of_range_is_an_error() {
        let (doc, mut bin) = test_doc();
        // The quad's indices follow positions (48 bytes), normals (48) and uvs (32).
        bin[128..130].copy_from_slice(&7u16.to_le_bytes());
        let err = load_err(doc, &bin);
        assert!(
            err.contains("mesh \"quad\" (0), primitive 0, indices") && err.contains("index 7"),
            "{err}"
        );
    }

    #[test]
    fn points_primitive_is_skipped_with_a_warning() {
        let dir = tempfile::tempdir().unwrap();
        let (mut doc, bin) = test_doc();
        doc["meshes"][1]["primitives"][0]["mode"] = json!(0);
        let path = write_embedded(dir.path(), doc, &bin);
        let scene = Scene::load(&path).unwrap();
        assert_eq!(scene.mesh.triangles.len(), 2);
        assert_eq!(scene.warnings.len(), 1);
        assert!(
            scene.warnings[0].contains("(mesh \"tri\" (1), primitive 0 (Points))"),
            "{:?}",
            scene.warnings
        );
        assert!(scene.warnings[0].contains("point and line primitives on 1 primitive: skipped"));
    }

    #[test]
    fn strips_and_fans_are_triangulated() {
        assert_eq!(
            triangulate(Mode::TriangleStrip, &[0, 1, 2, 3]),
            vec![[0, 1, 2], [2, 1, 3]]
        );
        assert_eq!(
            triangulate(Mode::TriangleFan, &[0, 1, 2, 3]),
            vec![[1, 2, 0], [2, 3, 0]]
        );
    }

    #[test]
    fn normal_texture_without_tangent_gets_mikktspace_tangents() {
        // No normal map: no tangents stored at all.
        assert!(load_doc(test_doc().0, &test_doc().1)
            .mesh
            .tangents
            .is_empty());
        let theta = 0.4f32;
        let (doc, bin) = normal_mapped_doc(theta, 1.0);
        let scene = load_doc(doc, &bin);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let m = scene.materials[0].normal_map.unwrap();
        assert_eq!((m.texture.texture, m.scale), (0, 1.0));
        // One tangent per vertex; the quad's are +X with w = +1, the unmapped triangle's zero.
        assert_eq!(scene.mesh.tangents.len(), scene.mesh.positions.len());
        for t in &scene.mesh.tangents[..4] {
            assert!((*t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5, "{t}");
        }
        assert!(scene.mesh.tangents[4..].iter().all(|t| *t == Vec4::ZERO));
        // The texel (8-bit) tilts the normal by theta toward the tangent.
        let ns = quad_normal(&scene);
        assert!((ns.dot(Vec3::Y).acos() - theta).abs() < 0.01, "{ns}");
        assert!(ns.x > 0.0 && ns.z.abs() < 0.01, "{ns}");
        // scale 0 flattens the map: (2c - 1) * (0, 0, 1).
        let (doc, bin) = normal_mapped_doc(theta, 0.0);
        assert!((quad_normal(&load_doc(doc, &bin)) - Vec3::Y).length() < 1e-6);
    }

    /// KHR_materials_clearcoat's clearcoatNormalTexture tilts the coat's normal and not the
    /// shading normal (and gets tangents generated); a base normal map without a coat map
    /// leaves the coat on the interpolated normal.
    #[test]
    fn clearcoat_normal_texture_tilts_the_coat_only() {
        let theta = 0.4f32;
        let coat_doc = |theta: f32, base_too: bool| {
            let (mut doc, bin) = normal_mapped_doc(theta, 1.0);
            let map = doc["materials"][0]["normalTexture"].clone();
            if !base_too {
                doc["materials"][0]
                    .as_object_mut()
                    .unwrap()
                    .remove("normalTexture");
            }
            let mut coat = json!({"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1});
            if !base_too {
                coat["clearcoatNormalTexture"] = map;
            }
            // A metallic-roughness material (not the paper model of `extras`).
            doc["materials"][0]
                .as_object_mut()
                .unwrap()
                .remove("extras");
            doc["materials"][0]["extensions"] = json!({ "KHR_materials_clearcoat": coat });
            doc["extensionsUsed"]
                .as_array_mut()
                .unwrap()
                .push(json!("KHR_materials_clearcoat"));
            (doc, bin)
        };
        let (doc, bin) = coat_doc(theta, false);
        let scene = load_doc(doc, &bin);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        assert_eq!(scene.mesh.tangents.len(), scene.mesh.positions.len());
        let ray = crate::geometry::Ray::new(Vec3::new(21.0, 5.0, 0.5), -Vec3::Y);
        let hit = scene.intersect(&ray).unwrap();
        assert!((hit.ns - Vec3::Y).length() < 1e-6, "{}", hit.ns);
        let coat = hit.coat_normal.expect("a coat normal");
        assert!((coat.dot(Vec3::Y).acos() - theta).abs() < 0.01, "{coat}");
        assert!(coat.x > 0.0 && coat.z.abs() < 0.01, "{coat}");
        // The base's map alone: the coat keeps the interpolated normal.
        let (doc, bin) = coat_doc(theta, true);
        let hit = load_doc(doc, &bin).intersect(&ray).unwrap();
        assert!((hit.ns.dot(Vec3::Y).acos() - theta).abs() < 0.01);
        assert_eq!(hit.coat_normal, Some(Vec3::Y));
        // Neither map: no coat normal.
        let (doc, bin) = coat_doc(0.0, true);
        let mut doc = doc;
        doc["materials"][0]
            .as_object_mut()
            .unwrap()
            .remove("normalTexture");
        assert_eq!(
            load_doc(doc, &bin).intersect(&ray).unwrap().coat_normal,
            None
        );
    }

    #[test]
    fn tangent_attribute_is_read_and_mirrored_nodes_flip_its_handedness() {
        let (mut doc, mut bin) = normal_mapped_doc(0.0, 1.0);
        // TANGENT along -X with w = -1: the same bitangent (-Z) as the generated one.
        add_tangent(&mut doc, &mut bin, [-1.0, 0.0, 0.0, -1.0]);
        // A texel tilting toward +Y of tangent space, i.e. the bitangent.
        let theta = 0.5f32;
        let texel = |x: f32| (255.0 * (x + 1.0) / 2.0).round() as u8;
        doc["images"][0]["uri"] = json!(png_uri([128, texel(theta.sin()), texel(theta.cos())]));
        let scene = load_doc(doc.clone(), &bin);
        for t in &scene.mesh.tangents[..4] {
            assert!(
                (*t - Vec4::new(-1.0, 0.0, 0.0, -1.0)).length() < 1e-5,
                "{t}"
            );
        }
        let ns = quad_normal(&scene);
        assert!((ns.dot(Vec3::Y).acos() - theta).abs() < 0.01, "{ns}");
        assert!(
            ns.z < 0.0 && ns.x.abs() < 0.01,
            "tilted up the image (-Z): {ns}"
        );
        // Mirrored in x: the tangent is mirrored, w flips, and the bitangent -Z stays, so the
        // shading normal tilts the same way.
        doc["nodes"][0]["scale"] = json!([-2, 2, 2]);
        let scene = load_doc(doc, &bin);
        for t in &scene.mesh.tangents[..4] {
            assert!((*t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5, "{t}");
        }
        let ray = crate::geometry::Ray::new(Vec3::new(-21.0, 5.0, 0.5), -Vec3::Y);
        let ns = scene.intersect(&ray).unwrap().ns;
        assert!(
            (ns.dot(Vec3::Y).acos() - theta).abs() < 0.01 && ns.z < 0.0,
            "{ns}"
        );
    }

    #[test]
    fn flat_or_uv_less_primitives_with_a_normal_texture_are_handled_and_warned() {
        // The quad without NORMAL but with TANGENT: the tangents are ignored (and generated
        // from the flat normal), with a warning.
        let (mut doc, mut bin) = normal_mapped_doc(0.3, 1.0);
        add_tangent(&mut doc, &mut bin, [0.0, 0.0, 1.0, 1.0]);
        let attributes = &mut doc["meshes"][0]["primitives"][0]["attributes"];
        attributes.as_object_mut().unwrap().remove("NORMAL");
        let scene = load_doc(doc.clone(), &bin);
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("TANGENT without NORMAL")),
            "{:?}",
            scene.warnings
        );
        let t = scene.mesh.tangents[0];
        assert!((t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5, "{t}");
        assert!((quad_normal(&scene).dot(Vec3::Y).acos() - 0.3).abs() < 0.01);
        // Without TEXCOORD_0 there is nothing to map: a warning, and the plain normal.
        let attributes = &mut doc["meshes"][0]["primitives"][0]["attributes"];
        attributes.as_object_mut().unwrap().remove("TEXCOORD_0");
        attributes.as_object_mut().unwrap().remove("TANGENT");
        let scene = load_doc(doc, &bin);
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("without TEXCOORD_0")),
            "{:?}",
            scene.warnings
        );
        assert!((quad_normal(&scene) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn positions_that_overflow_the_bvh_name_the_mesh() {
        // A finite, invertible node transform that takes a vertex beyond the limit.
        let (doc, bin) = with("/nodes/2/scale", json!([1e20, 1, 1e-20]));
        let err = error(doc, &bin);
        assert!(
            err.contains("mesh \"tri\" (1), primitive 0, vertex 1") && err.contains("overflow"),
            "{err}"
        );
        // A finite coordinate beyond the limit in the buffer (the last vertex's y).
        let (doc, mut bin) = test_doc();
        let n = bin.len();
        bin[n - 8..n - 4].copy_from_slice(&f32::MAX.to_le_bytes());
        let err = error(doc, &bin);
        assert!(
            err.contains("mesh \"tri\" (1), primitive 0, vertex 2"),
            "{err}"
        );
        // An instanced mesh (placed twice) whose second instance reaches beyond the limit.
        let (mut doc, bin) = test_doc();
        doc["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!({"mesh": 0, "scale": [1e20, 1, 1e-20]}));
        doc["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!(7));
        let err = error(doc, &bin);
        assert!(err.contains("instance 1 of mesh \"quad\" (0)"), "{err}");
    }

    #[test]
    fn positions_at_the_limit_build_a_bvh() {
        // 256 triangles reaching 0.99 of MAX_COORDINATE on every axis, overlapping, half of
        // them coincident: the BVH's box areas and costs stay finite, the build neither
        // panics nor loses one, and a ray finds the nearest.
        let a = 0.99 * f64::from(crate::scene::MAX_COORDINATE);
        let (mut doc, bin) = test_doc();
        let first = doc["nodes"].as_array().unwrap().len();
        for i in 0..256 {
            let z = if i % 2 == 0 { a } else { -a };
            let z = if i < 128 { z } else { z * (i as f64 / 256.0) };
            doc["nodes"].as_array_mut().unwrap().push(json!({
                "mesh": 1,
                "translation": [-a, -a, z],
                "scale": [2.0 * a, 2.0 * a, 1.0 / (4.0 * a * a)],
            }));
            doc["scenes"][0]["nodes"]
                .as_array_mut()
                .unwrap()
                .push(json!(first + i));
        }
        let dir = tempfile::tempdir().unwrap();
        let path = write_embedded(dir.path(), doc, &bin);
        let scene = Scene::load(&path).unwrap();
        let ray =
            crate::geometry::Ray::new(Vec3::new(-0.5 * a as f32, -0.5 * a as f32, 0.0), Vec3::Z);
        let hit = scene.intersect(&ray).expect("a hit at the limit");
        let nearest = 0.5 * a;
        assert!((f64::from(hit.t) / nearest - 1.0).abs() < 0.02, "{}", hit.t);
    }

    /// A triangle fan of 500,000 vertices on a circle (slivers that all hold its centre)
    /// loads in about `n log n`: its BVH took 19 s before (PLOC stalls on such boxes).
    #[test]
    fn huge_triangle_fans_load_quickly() {
        let (mut doc, mut bin) = test_doc();
        let n = 500_000;
        let at = bin.len();
        let fan: Vec<u8> = (0..n)
            .flat_map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                if i == 0 {
                    [0.0; 3]
                } else {
                    [a.cos(), a.sin(), 0.0]
                }
            })
            .flat_map(f32::to_le_bytes)
            .collect();
        bin.extend(&fan);
        doc["bufferViews"]
            .as_array_mut()
            .unwrap()
            .push(json!({"buffer": 0, "byteOffset": at, "byteLength": fan.len()}));
        doc["accessors"]
            .as_array_mut()
            .unwrap()
            .push(json!({"bufferView": 5,
            "componentType": 5126, "count": n, "type": "VEC3", "min": [-1, -1, 0],
            "max": [1, 1, 0]}));
        doc["buffers"][0]["byteLength"] = json!(bin.len());
        doc["meshes"][1]["primitives"][0] = json!({"attributes": {"POSITION": 5}, "mode": 6});
        let dir = tempfile::tempdir().unwrap();
        let path = write_embedded(dir.path(), doc, &bin);
        let start = Instant::now();
        let scene = Scene::load(&path).unwrap();
        let took = start.elapsed();
        assert!(took < Duration::from_secs(5), "{took:?}");
        assert_eq!(scene.mesh.triangles.len(), 2 + n - 2);
    }
}
