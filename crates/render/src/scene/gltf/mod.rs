//! The glTF 2.0 loader (`.gltf` with external or base64-embedded buffers, and `.glb`).
//!
//! Every accessor is checked (type, bounds within its buffer view and buffer) before it is
//! read, so malformed files give a [`SceneError`] naming the element instead of a panic.
//! Vertex attributes are read by the `accessors` module (every component type of the core
//! specification and of KHR_mesh_quantization, sparse accessors); meshopt- and
//! Draco-compressed geometry is decoded first by the `compression` module. Sparse index
//! accessors are not supported (an error names them).
//!
//! Instancing: the scene's nodes are walked first and every placement of a mesh recorded (a
//! node with a mesh, or each instance of a node's EXT_mesh_gpu_instancing, whose TRANSLATION,
//! ROTATION and SCALE attributes give `node world * T * R * S`). A mesh placed more than once,
//! without an emissive material and without morph targets is loaded once in object space (its
//! MikkTSpace tangents,
//! if generated, from the object-space positions) and becomes instances
//! ([`super::Instances`]); every other placement is flattened into world triangles, in the
//! order of the walk. Morph targets are applied with the default weights (the placing node's
//! `weights`, else the mesh's), as the specification's default pose.
//!
//! One file per concept:
//!
//! - `document`: the entry, [`load`]: the GLB header, the references the gltf crate follows
//!   unchecked, then the steps in order (buffers, compressed geometry, materials, the node
//!   walk, the meshes' placements);
//! - `buffers`: buffers and bufferViews, and reading accessors (layouts, bounds, the decoded
//!   bytes charged against [`super::LoadOptions`]);
//! - `accessors`: the accessor formats (component types, normalization, sparse accessors);
//! - `compression`: EXT_meshopt_compression and KHR_draco_mesh_compression, decoded into
//!   plain buffers and accessors before the document is read;
//! - `nodes`: the node walk, cameras, the limits [`MAX_PLACEMENTS`] and [`MAX_TRIANGLES`],
//!   and the placement of meshes as world triangles or instances;
//! - `meshes`: primitives, their attributes in world space, triangulation, tangents;
//! - `materials`: materials and their KHR_materials_* extensions, `extras.streaks`;
//! - `environment`: the scene's environment light, `scenes[i].extras.streaks.environment`;
//! - `rain`: the scene's rain, `scenes[i].extras.streaks.rain` ([`crate::rain`]);
//! - `fog`: the scene's fog, `scenes[i].extras.streaks.fog` ([`crate::medium::Fog`]);
//! - `tags`: the nodes' semantic tags, `extras.streaks.class` and `instance`, inherited
//!   through the hierarchy ([`crate::scene::SceneObject`]);
//! - `textures`: texture infos, KHR_texture_transform, samplers, images;
//! - [`extensions`]: which extensions are honoured, and the ones that are not a material's
//!   field: KHR_lights_punctual (and the file's light units), EXT_mesh_gpu_instancing;
//! - `warnings`: the warnings, gathered by feature so that each is named once per file;
//! - `test_docs` (tests only): the documents the tests build, write and load;
//! - this file: the [`Loader`] state the others add to, and the labels errors name elements by.

mod accessors;
mod buffers;
mod compression;
mod document;
mod environment;
pub mod extensions;
mod fog;
mod materials;
mod meshes;
mod nodes;
mod rain;
mod tags;
#[cfg(test)]
mod test_docs;
mod textures;
mod warnings;

pub(super) use document::load;
pub use nodes::{MAX_PLACEMENTS, MAX_TRIANGLES};

use super::files::Files;
use super::{ObjectTable, SceneError, SceneParts};
use crate::texture::{ColorSpace, TextureId};
use extensions::LightUnits;
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use warnings::Warnings;

fn node_label(node: &gltf::Node) -> String {
    match node.name() {
        Some(n) => format!("node {n:?} ({})", node.index()),
        None => format!("node {}", node.index()),
    }
}

fn mesh_label(mesh: &gltf::Mesh) -> String {
    match mesh.name() {
        Some(n) => format!("mesh {n:?} ({})", mesh.index()),
        None => format!("mesh {}", mesh.index()),
    }
}

/// Describes where a URI points, for messages.
fn uri_label(base: &Path, uri: &str) -> String {
    if uri.starts_with("data:") {
        "embedded data URI".into()
    } else {
        format!("{uri:?} -> {}", base.join(uri).display())
    }
}

struct Loader<'a> {
    path: &'a Path,
    base: PathBuf,
    /// Reads the files the scene names (images), inside its folder.
    files: &'a Files<'a>,
    buffers: Vec<gltf::buffer::Data>,
    parts: SceneParts,
    /// Decoded textures by (image index, colour space); `None` for an image that is not
    /// decoded (KTX2).
    textures: HashMap<(usize, ColorSpace), Option<TextureId>>,
    /// Index of the glTF default material, once a primitive needs it.
    default_material: Option<u32>,
    /// What KHR_lights_punctual's intensities are in.
    light_units: LightUnits,
    /// Every placement of a mesh in the walk's order: mesh index, world transform, the
    /// index of the node that places it (whose morph weights apply) and its object slot.
    placements: Vec<(usize, Mat4, usize, u32)>,
    /// The objects the nodes' tags name, one slot each.
    objects: ObjectTable,
    /// What the file uses that is skipped or rendered differently, by feature.
    warnings: Warnings,
    /// Each node's world transform, once the walk has reached it (joints of skins).
    node_worlds: Vec<Option<Mat4>>,
    /// The bounding box of each primitive loaded so far, in the space it was loaded in (world,
    /// or object space while an instanced mesh is loaded), for the default camera.
    primitive_boxes: Vec<[Vec3; 2]>,
}

impl Loader<'_> {
    fn bad(&self, element: impl Into<String>, reason: impl Into<String>) -> SceneError {
        SceneError::invalid(self.path, element, reason)
    }

    /// Records that `element`, of kind `kind` (`material`, `primitive`), uses `what`, which is
    /// rendered `without`; see [`Warnings::add`].
    fn warn(&mut self, what: &str, kind: &'static str, element: &str, without: &str) {
        self.warnings.add(what, kind, element, without);
    }
}
