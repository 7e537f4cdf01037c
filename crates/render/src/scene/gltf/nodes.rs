//! The node walk and what it places: node transforms, cameras, the limits on placements and
//! triangles, and each mesh flattened into world triangles or stored once as instances.

use super::meshes::Pose;
use super::{accessors, mesh_label, node_label, Loader};
use crate::camera::Camera;
use crate::scene::{points_bounds, validate, Instance, SceneError, TriangleMesh};
use glam::{Affine3A, Mat4, Quat, Vec3, Vec4};
use gltf::mesh::Mode;
use std::path::Path;

/// The most node visits (a node reached by several paths of the hierarchy is visited once per
/// path) and, separately, mesh placements (node meshes and EXT_mesh_gpu_instancing instances)
/// a scene may have: a hierarchy in which each node lists the next one twice reaches 2^40
/// placements in 40 levels, so the walk counts them before it makes them.
pub const MAX_PLACEMENTS: usize = 1_000_000;

/// The most triangles a scene may hold once its meshes are placed: the flattened placements'
/// (every placement of a mesh placed once, or with an emissive material or morph targets) and
/// the instanced meshes' (stored once); counted from the accessors before any geometry is read. About
/// 8 GB of scene and BVH; an emissive mesh placed many times would otherwise multiply it.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// The error for a hierarchy that places more than [`MAX_PLACEMENTS`] nodes or instances,
/// found at `node`.
pub(super) fn too_many_placements(path: &Path, node: &gltf::Node) -> SceneError {
    SceneError::invalid(
        path,
        node_label(node),
        format!(
            "the node hierarchy places more than {MAX_PLACEMENTS} nodes or mesh instances \
             (a node reached by several paths is placed once per path)"
        ),
    )
}

/// The number of node visits the walk of `scene` makes (each node once per path from a root
/// to it), counted without walking: a node's count is one plus its children's, each node
/// computed once (depth-first, without recursion). A cycle, or more than [`MAX_PLACEMENTS`]
/// visits, is an error naming a node.
pub(super) fn count_visits(
    path: &Path,
    document: &gltf::Document,
    scene: &gltf::Scene,
) -> Result<usize, SceneError> {
    const UNSEEN: usize = usize::MAX;
    const OPEN: usize = usize::MAX - 1;
    let mut visits = vec![UNSEEN; document.nodes().len()];
    let mut total = 0usize;
    for root in scene.nodes() {
        // (node, whether its children have been pushed)
        let mut stack = vec![(root.clone(), false)];
        while let Some((node, expanded)) = stack.pop() {
            let i = node.index();
            if expanded {
                let sum = node
                    .children()
                    .fold(1usize, |s, c| s.saturating_add(visits[c.index()]));
                if sum > MAX_PLACEMENTS {
                    return Err(too_many_placements(path, &node));
                }
                visits[i] = sum;
                continue;
            }
            match visits[i] {
                UNSEEN => {}
                OPEN => {
                    return Err(SceneError::invalid(
                        path,
                        node_label(&node),
                        "the node hierarchy has a cycle",
                    ))
                }
                _ => continue,
            }
            visits[i] = OPEN;
            stack.push((node.clone(), true));
            for c in node.children() {
                match visits[c.index()] {
                    OPEN => {
                        return Err(SceneError::invalid(
                            path,
                            node_label(&c),
                            "the node hierarchy has a cycle",
                        ))
                    }
                    UNSEEN => stack.push((c, false)),
                    _ => {}
                }
            }
        }
        total = total.saturating_add(visits[root.index()]);
        if total > MAX_PLACEMENTS {
            return Err(too_many_placements(path, &root));
        }
    }
    Ok(total)
}

/// The number of triangles primitive `prim` makes (from its index or POSITION count and its
/// mode; 0 for points and lines, which are skipped).
pub(super) fn primitive_triangles(prim: &gltf::Primitive) -> usize {
    let n = match prim.indices() {
        Some(a) => a.count(),
        None => prim
            .get(&gltf::Semantic::Positions)
            .map_or(0, |a| a.count()),
    };
    match prim.mode() {
        Mode::Triangles => n / 3,
        Mode::TriangleStrip | Mode::TriangleFan => n.saturating_sub(2),
        _ => 0,
    }
}

impl Loader<'_> {
    /// Adds what `node` carries (camera, light; its mesh's placements, with the object slot
    /// `object` of its tag, are recorded for [`Loader::place_meshes`]); returns its world
    /// transform.
    pub(super) fn node(
        &mut self,
        node: &gltf::Node,
        parent: Mat4,
        object: u32,
        document: &gltf::Document,
    ) -> Result<Mat4, SceneError> {
        let local = match node.transform() {
            gltf::scene::Transform::Matrix { matrix } => Mat4::from_cols_array_2d(&matrix),
            gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            } => Mat4::from_scale_rotation_translation(
                Vec3::from(scale),
                // A zero quaternion becomes NaN here and fails the check below.
                Quat::from_array(rotation).normalize(),
                Vec3::from(translation),
            ),
        };
        let world = parent * local;
        let det = world.determinant();
        if !world.is_finite() || !det.is_finite() || det.abs() < 1e-30 {
            return Err(self.bad(
                node_label(node),
                format!("world transform is not invertible or not finite: {world:?}"),
            ));
        }
        // A node reached by several paths keeps its first world transform for the skins whose
        // joint it is.
        if let Some(w) = self.node_worlds.get_mut(node.index()) {
            w.get_or_insert(world);
        }
        if let Some(mesh) = node.mesh() {
            match node.extension_value("EXT_mesh_gpu_instancing") {
                Some(ext) => {
                    let locals = self.gpu_instances(node, ext, document)?;
                    if self.placements.len() + locals.len() > MAX_PLACEMENTS {
                        return Err(too_many_placements(self.path, node));
                    }
                    for (i, local) in locals.iter().enumerate() {
                        let w = world * *local;
                        if Instance::new(0, w).is_none() {
                            return Err(self.bad(
                                format!(
                                    "{}, EXT_mesh_gpu_instancing instance {i}",
                                    node_label(node)
                                ),
                                format!("world transform is not invertible or not finite: {w:?}"),
                            ));
                        }
                        self.placements
                            .push((mesh.index(), w, node.index(), object));
                    }
                }
                None => {
                    if self.placements.len() >= MAX_PLACEMENTS {
                        return Err(too_many_placements(self.path, node));
                    }
                    self.placements
                        .push((mesh.index(), world, node.index(), object));
                }
            }
        }
        if let Some(camera) = node.camera() {
            self.camera(node, &camera, world)?;
        }
        if let Some(light) = node.light() {
            self.light(node, &light, world)?;
        }
        Ok(world)
    }

    /// Turns the recorded placements into geometry: a mesh placed more than once, without an
    /// emissive material and without morph targets is loaded once in object space and placed
    /// by instances, every other placement is flattened into world triangles (see the module
    /// documentation); a mesh with morph targets takes the weights of the node that places it,
    /// else its own (the specification's default pose).
    pub(super) fn place_meshes(&mut self, document: &gltf::Document) -> Result<(), SceneError> {
        let meshes: Vec<gltf::Mesh> = document.meshes().collect();
        let mut count = vec![0usize; meshes.len()];
        for &(m, _, _, _) in &self.placements {
            count[m] += 1;
        }
        // Meshes flattened at every placement: emissive ones (emitters are world triangles),
        // morphed ones (each placement may have its own weights) and skinned ones.
        let mut flattened: Vec<bool> = meshes
            .iter()
            .map(|mesh| {
                mesh.primitives().any(|p| {
                    p.morph_targets().len() > 0
                        || p.material()
                            .index()
                            .is_some_and(|i| self.parts.materials[i].is_emissive())
                })
            })
            .collect();
        let nodes: Vec<gltf::Node> = document.nodes().collect();
        for &(m, _, node, _) in &self.placements {
            flattened[m] |= nodes[node].skin().is_some();
        }
        // Triangles stored: a flattened mesh's at each placement, an instanced one's once.
        let mut stored = 0usize;
        for (m, mesh) in meshes.iter().enumerate() {
            let copies = match (count[m], flattened[m]) {
                (0, _) => 0,
                (n, true) | (n @ 1, false) => n,
                (_, false) => 1,
            };
            let triangles: usize = mesh.primitives().map(|p| primitive_triangles(&p)).sum();
            stored = stored.saturating_add(triangles.saturating_mul(copies));
            if stored > MAX_TRIANGLES {
                return Err(self.bad(
                    mesh_label(mesh),
                    format!(
                        "the scene would hold more than {MAX_TRIANGLES} triangles once its \
                         meshes are placed (this mesh: {triangles} triangles, stored {copies} \
                         times)"
                    ),
                ));
            }
        }
        let mut instanced: Vec<Option<u32>> = vec![None; meshes.len()];
        // The object-space boxes of each instanced mesh's primitives.
        let mut object_boxes: Vec<Vec<[Vec3; 2]>> = Vec::new();
        for (m, world, node, object) in std::mem::take(&mut self.placements) {
            let mesh = &meshes[m];
            if count[m] < 2 || flattened[m] {
                let node = &nodes[node];
                let weights = node.weights().or(mesh.weights()).unwrap_or_default();
                // A skinned mesh is placed by its joints alone: the specification says its
                // node's own transform is ignored.
                let (world, joints) = match node.skin() {
                    Some(skin) => (Mat4::IDENTITY, self.joint_matrices(node, &skin)?),
                    None => (world, Vec::new()),
                };
                let pose = Pose {
                    weights,
                    joints: &joints,
                };
                self.mesh(mesh, world, pose)?;
                let n = self.parts.mesh.triangles.len();
                self.parts.mesh.triangle_objects.resize(n, object);
                continue;
            }
            let index = match instanced[m] {
                Some(i) => i,
                None => {
                    let first_box = self.primitive_boxes.len();
                    let object = self.object_mesh(mesh)?;
                    object_boxes.push(self.primitive_boxes.split_off(first_box));
                    let i = self.parts.instanced_meshes.len() as u32;
                    self.parts.instanced_meshes.push(object);
                    instanced[m] = Some(i);
                    i
                }
            };
            for &[lo, hi] in &object_boxes[index as usize] {
                let corners = std::array::from_fn::<Vec3, 8, _>(|k| {
                    let corner =
                        Vec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo);
                    world.transform_point3(corner)
                });
                self.primitive_boxes.extend(points_bounds(&corners));
            }
            // The walk checked that the transform is invertible.
            if let Some(instance) = Instance::new(index, world) {
                self.parts.instances.push(Instance { object, ..instance });
            }
        }
        Ok(())
    }

    /// `mesh` loaded in its own (object) space, as [`Loader::mesh`] loads it with the identity
    /// transform, into its own arrays.
    pub(super) fn object_mesh(&mut self, mesh: &gltf::Mesh) -> Result<TriangleMesh, SceneError> {
        let world = std::mem::take(&mut self.parts.mesh);
        // Meshes with morph targets or skins are never instanced: the rest pose here.
        let loaded = self.mesh(mesh, Mat4::IDENTITY, Pose::default());
        let mut object = std::mem::replace(&mut self.parts.mesh, world);
        loaded?;
        if !object.tangents.is_empty() {
            object.tangents.resize(object.positions.len(), Vec4::ZERO);
        }
        object.name = mesh_label(mesh);
        Ok(object)
    }

    /// The joint matrices of `skin`, used by `node`'s mesh: each joint's world transform (from
    /// the walk) times its inverse bind matrix (identity without inverseBindMatrices). A joint
    /// outside the scene, or a non-finite matrix, is an error naming the skin.
    fn joint_matrices(
        &self,
        node: &gltf::Node,
        skin: &gltf::Skin,
    ) -> Result<Vec<Mat4>, SceneError> {
        let element = match skin.name() {
            Some(n) => format!("skin {n:?} ({}) of {}", skin.index(), node_label(node)),
            None => format!("skin {} of {}", skin.index(), node_label(node)),
        };
        let joints: Vec<gltf::Node> = skin.joints().collect();
        let inverse_binds: Vec<Mat4> = match skin.inverse_bind_matrices() {
            Some(a) => {
                let name = "inverseBindMatrices";
                self.attribute::<16>(&a, &element, name, accessors::MATRIX, Some(joints.len()))?
                    .iter()
                    .map(Mat4::from_cols_array)
                    .collect()
            }
            None => vec![Mat4::IDENTITY; joints.len()],
        };
        joints
            .iter()
            .zip(inverse_binds)
            .map(|(joint, inverse_bind)| {
                let Some(world) = self.node_worlds.get(joint.index()).copied().flatten() else {
                    let why = format!("its joint {} is not in the scene", node_label(joint));
                    return Err(self.bad(&element, why));
                };
                let m = world * inverse_bind;
                if !m.is_finite() {
                    let why = format!("joint {} has a non-finite matrix", node_label(joint));
                    return Err(self.bad(&element, why));
                }
                Ok(m)
            })
            .collect()
    }

    pub(super) fn camera(
        &mut self,
        node: &gltf::Node,
        camera: &gltf::Camera,
        world: Mat4,
    ) -> Result<(), SceneError> {
        let name = camera
            .name()
            .or(node.name())
            .map_or_else(|| format!("camera{}", camera.index()), str::to_string);
        let element = format!(
            "camera {name:?} ({}) on {}",
            camera.index(),
            node_label(node)
        );
        let (_, rotation, translation) = world.to_scale_rotation_translation();
        let world_from_camera =
            Affine3A::from_rotation_translation(rotation.normalize(), translation);
        let camera = match camera.projection() {
            gltf::camera::Projection::Perspective(p) => {
                validate::perspective(&p).map_err(|r| self.bad(&element, r))?;
                Camera::perspective(name, world_from_camera, p.yfov(), p.aspect_ratio())
            }
            gltf::camera::Projection::Orthographic(o) => {
                validate::orthographic(&o).map_err(|r| self.bad(&element, r))?;
                Camera::orthographic(name, world_from_camera, o.xmag(), o.ymag())
            }
        };
        self.parts.cameras.push(camera);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{
        approx, assert_same_hits, box_placements, check_test_scene, doubling_dag, error, load_doc,
        load_err, placed_boxes, rejects, test_doc, write_embedded,
    };

    use crate::scene::Scene;
    use glam::Vec3;
    use serde_json::{json, Value};

    #[test]
    fn bad_transforms_name_the_node() {
        let (mut doc, bin) = test_doc();
        // JSON has no NaN: a value beyond f32 range becomes infinite.
        doc["nodes"][1]["matrix"][0] = json!(1e39);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("node \"child\" (1)") && err.contains("not invertible"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["nodes"][0]["scale"] = json!([1, 0, 1]);
        let err = load_err(doc, &bin);
        assert!(err.contains("node \"parent\" (0)"), "{err}");
    }

    #[test]
    fn scene_zero_is_used_without_a_default_and_cycles_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let (mut doc, bin) = test_doc();
        doc.as_object_mut().unwrap().remove("scene");
        check_test_scene(&Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap());
        let (mut doc, bin) = test_doc();
        doc["nodes"][1]["children"] = json!([0]);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("node \"parent\" (0)") && err.contains("cycle"),
            "{err}"
        );
    }

    #[test]
    fn mirrored_nodes_keep_the_front_face() {
        let dir = tempfile::tempdir().unwrap();
        let (mut doc, bin) = test_doc();
        doc["nodes"][2]["scale"] = json!([-1, 1, 1]);
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let hit = scene
            .intersect(&crate::geometry::Ray::new(
                Vec3::new(-0.2, 0.2, 1.0),
                -Vec3::Z,
            ))
            .unwrap();
        assert!(approx(hit.ng, Vec3::Z), "{}", hit.ng);
    }

    /// One mesh referenced by many nodes (rotations, non-uniform and mirroring scales, a
    /// parent) is stored once and placed by instances, and every ray hits it as it hits the
    /// same scene with the triangles copied per node: same hits, normals (normal-mapped),
    /// uvs, vertex colours and alpha-masked holes.
    #[test]
    fn nodes_sharing_a_mesh_are_instances_that_hit_like_copies() {
        use crate::geometry::Ray;
        let placements = box_placements();
        let (doc, bin) = placed_boxes(&placements, true);
        let instanced = load_doc(doc, &bin);
        let (doc, bin) = placed_boxes(&placements, false);
        let flat = load_doc(doc, &bin);
        assert!(flat.instances.is_empty());
        assert_eq!(flat.mesh.triangles.len(), placements.len() * 14);
        assert!(instanced.mesh.triangles.is_empty() && instanced.mesh.positions.is_empty());
        assert_eq!(instanced.instances.meshes.len(), 1);
        assert_eq!(instanced.instances.instances.len(), placements.len());
        assert_eq!(instanced.instances.stored_triangle_count(), 14);
        assert_eq!(instanced.world_triangle_count(), flat.mesh.triangles.len());
        assert!(
            instanced
                .instances
                .instances
                .iter()
                .filter(|i| i.mirrored)
                .count()
                == 2
        );
        let (ca, ra) = instanced.bounding_sphere();
        let (cb, rb) = flat.bounding_sphere();
        assert!((ca - cb).length() < 1e-5 && (ra - rb).abs() < 1e-5);
        assert!((instanced.accel.t_min() - flat.accel.t_min()).abs() < 1e-9);
        let hits = assert_same_hits(&instanced, &flat, 6000);
        assert!(hits > 1000, "{hits} hits");
        // The mask cuts holes in the instances too: some rays through a fence quad's
        // transparent half reach a box behind it or miss.
        let fence = instanced
            .materials
            .iter()
            .position(|m| m.name == "fence")
            .unwrap() as u32;
        let mut rng = crate::sampling::Pcg32::new(9, 1);
        let fence_hits = (0..2000)
            .filter(|_| {
                let o = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 5.0);
                let r = Ray::new(o, -Vec3::Z);
                let inst = &instanced.instances.instances[0];
                let world = Ray::new(
                    inst.world_from_object.transform_point3(r.origin),
                    inst.world_from_object
                        .transform_vector3(r.direction)
                        .normalize(),
                );
                instanced
                    .intersect(&world)
                    .is_some_and(|h| h.material == fence)
            })
            .count();
        assert!((700..1300).contains(&fence_hits), "{fence_hits}");
    }

    /// The triangles stored for a mesh do not grow with the number of nodes placing it.
    #[test]
    fn instanced_triangle_storage_does_not_grow_with_the_instances() {
        let storage = |n: usize| {
            let locals: Vec<Value> = (0..n)
                .map(|i| json!({"translation": [i as f32 * 1.5, 0, 0]}))
                .collect();
            let (doc, bin) = placed_boxes(&locals, true);
            let s = load_doc(doc, &bin);
            assert_eq!(s.world_triangle_count(), 14 * n);
            let m = &s.instances.meshes[0];
            (
                s.mesh.triangles.len(),
                m.mesh.triangles.len(),
                m.mesh.positions.len(),
                m.accel.memory_bytes(),
            )
        };
        assert_eq!(storage(2), storage(300));
        assert_eq!(storage(2).0, 0);
    }

    #[test]
    fn cameras_outside_the_specification_are_named() {
        let named = &["camera \"cam_node\" (0) on node \"cam_node\" (3)"][..];
        let p = "/cameras/0/perspective";
        rejects(&[
            (&format!("{p}/yfov"), json!(4), named),
            (&format!("{p}/yfov"), json!(0), named),
            (&format!("{p}/znear"), json!(0), named),
            (&format!("{p}/znear"), json!(-1), named),
            (&format!("{p}/znear"), json!(1e39), named),
            (&format!("{p}/aspectRatio"), json!(0), named),
            (&format!("{p}/aspectRatio"), json!(1e39), named),
        ]);
        let (mut doc, bin) = test_doc();
        doc["cameras"][0]["perspective"]["zfar"] = json!(0.05);
        let err = error(doc, &bin);
        assert!(err.contains("zfar 0.05"), "{err}");
    }

    #[test]
    fn orthographic_cameras_load_and_bad_ones_are_named() {
        let (mut doc, bin) = test_doc();
        doc["cameras"][0] = json!({"name": "ortho", "type": "orthographic",
            "orthographic": {"xmag": 2, "ymag": 0.5, "znear": 0.1, "zfar": 10}});
        let scene = load_doc(doc, &bin);
        let cam = scene.camera(Some("ortho")).unwrap();
        assert_eq!(
            cam.projection,
            crate::camera::Projection::Orthographic {
                xmag: 2.0,
                ymag: 0.5
            }
        );
        assert_eq!(cam.aspect_ratio(), Some(4.0));
        let named = &["camera \"ortho\" (0) on node \"cam_node\" (3)"][..];
        let o = "/cameras/0/orthographic";
        let base = |doc: &mut Value| {
            doc["cameras"][0] = json!({"name": "ortho", "type": "orthographic",
                "orthographic": {"xmag": 2, "ymag": 0.5, "znear": 0.1, "zfar": 10}});
        };
        for (field, value, says) in [
            ("xmag", json!(0), "xmag 0"),
            ("ymag", json!(-1), "ymag -1"),
            ("xmag", json!(1e39), "xmag inf"),
            ("znear", json!(-0.5), "znear -0.5"),
            ("zfar", json!(0.05), "zfar 0.05"),
        ] {
            let (mut doc, bin) = test_doc();
            base(&mut doc);
            doc["cameras"][0]["orthographic"][field] = value;
            let err = error(doc, &bin);
            assert!(
                err.contains(named[0]) && err.contains(says),
                "{o}/{field}: {err}"
            );
        }
    }

    /// The default camera's bounds unite one box per primitive placement, whether the mesh
    /// is flattened (placed once per mesh copy) or instanced (one mesh placed twice).
    #[test]
    fn framing_bounds_unite_the_boxes_of_the_placed_primitives() {
        let bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        for share in [true, false] {
            let mesh = |m: usize| if share { 0 } else { m };
            let doc = json!({
                "asset": {"version": "2.0"},
                "scenes": [{"nodes": [0, 1]}],
                "nodes": [{"mesh": mesh(0)}, {"mesh": mesh(1), "translation": [10, 0, 0]}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]},
                           {"primitives": [{"attributes": {"POSITION": 0}}]}],
                "buffers": [{"byteLength": 36}],
                "bufferViews": [{"buffer": 0, "byteLength": 36}],
                "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3,
                               "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]
            });
            let scene = load_doc(doc, &bin);
            assert_eq!(scene.instances.is_empty(), !share);
            let [lo, hi] = scene.framing_bounds.unwrap();
            let want_lo = Vec3::ZERO;
            let want_hi = Vec3::new(11.0, 1.0, 0.0);
            assert!(
                (lo - want_lo).length() < 1e-5 && (hi - want_hi).length() < 1e-5,
                "share {share}: {lo} {hi}"
            );
        }
    }

    #[test]
    fn exponential_node_graphs_are_refused_before_they_are_walked() {
        let (mut doc, bin) = test_doc();
        doubling_dag(&mut doc, 40, 1);
        let err = error(doc, &bin);
        assert!(err.contains("more than 1000000"), "{err}");
        // 2^18 placements of an emissive (so flattened) strip of 100 triangles: 26 million.
        let (mut doc, mut bin) = test_doc();
        let at = bin.len();
        let strip: Vec<u8> = (0..102)
            .flat_map(|i| [i as f32 * 0.1, (i % 2) as f32, 0.0])
            .flat_map(f32::to_le_bytes)
            .collect();
        bin.extend(&strip);
        let views = doc["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": strip.len()}));
        let view = views.len() - 1;
        let accessors = doc["accessors"].as_array_mut().unwrap();
        accessors.push(
            json!({"bufferView": view, "componentType": 5126, "count": 102,
            "type": "VEC3", "min": [0, 0, 0], "max": [10.1, 1, 0]}),
        );
        let accessor = accessors.len() - 1;
        doc["buffers"][0]["byteLength"] = json!(bin.len());
        doc["meshes"]
            .as_array_mut()
            .unwrap()
            .push(json!({"name": "strip", "primitives":
            [{"attributes": {"POSITION": accessor}, "mode": 5, "material": 1}]}));
        doubling_dag(&mut doc, 18, 2);
        let err = error(doc, &bin);
        assert!(
            err.contains("mesh \"strip\" (2)") && err.contains("more than 20000000 triangles"),
            "{err}"
        );
    }
}
