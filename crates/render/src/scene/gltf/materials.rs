//! The glTF 2.0 loader (`.gltf` with external or base64-embedded buffers, and `.glb`).
//!
//! Every accessor is checked (type, bounds within its buffer view and buffer) before it is
//! read, so malformed files give a [`SceneError`] naming the element instead of a panic.
//! Vertex attributes are read by the `accessor` module (every component type of the core
//! specification and of KHR_mesh_quantization, sparse accessors); meshopt- and
//! Draco-compressed geometry is decoded first by the `compression` module. Sparse index
//! accessors are not supported (an error names them).
//!
//! Instancing: the scene's nodes are walked first and every placement of a mesh recorded (a
//! node with a mesh, or each instance of a node's EXT_mesh_gpu_instancing, whose TRANSLATION,
//! ROTATION and SCALE attributes give `node world * T * R * S`). A mesh placed more than once
//! and without an emissive material is loaded once in object space (its MikkTSpace tangents,
//! if generated, from the object-space positions) and becomes instances
//! ([`super::Instances`]); every other placement is flattened into world triangles, in the
//! order of the walk.

use super::files::{Files, Uri};
use super::{
    accessor, compression, extensions, tangents, validate, Instance, MeshParts, Scene, SceneError,
    SceneParts,
};
use crate::camera::Camera;
use crate::light::{Light, LUMINOUS_EFFICACY};
use crate::material::{
    Alpha, AlphaMode, GltfPbrParams, Material, PaperModel, Reflectance, Volume, Wetness,
};
use crate::normal_map::NormalMap;
use crate::texture::{
    uv_transform, ColorSpace, Filter, Sampler, Texture, TextureId, TextureRef, Wrap,
};
use glam::{Affine2, Affine3A, Mat3, Mat4, Quat, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use serde::Deserialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// `extras.streaks` of a material (see the `scene` module documentation).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StreaksExtras {
    /// The paper model; absent, the material is glTF metallic-roughness and `extras.streaks`
    /// may only carry `road`.
    #[serde(default)]
    bsdf: Option<StreaksBsdf>,
    /// Marks the road surface (datasets mask the pixels whose first hit has such a
    /// material); no effect on shading.
    #[serde(default)]
    road: bool,
    #[serde(default)]
    kd: Option<[f32; 3]>,
    #[serde(default)]
    ks: Option<[f32; 3]>,
    #[serde(default)]
    alpha: Option<f32>,
    #[serde(default)]
    shininess: Option<f32>,
    #[serde(default)]
    alpha_dry: Option<f32>,
    #[serde(default)]
    ks_dry: Option<[f32; 3]>,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "snake_case")]
enum StreaksBsdf {
    Ggx,
    Ward,
    BlinnPhong,
}

/// A material's KHR_materials_specular and KHR_materials_ior parameters.
struct Specular {
    factor: f32,
    texture: Option<TextureRef>,
    color: Vec3,
    color_texture: Option<TextureRef>,
    ior: f32,
}

/// A material's KHR_materials_clearcoat object, as the JSON has it, and its decoded textures.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase")]
struct Clearcoat {
    #[serde(default)]
    clearcoat_factor: f32,
    clearcoat_texture: Option<JsonTextureInfo>,
    #[serde(default)]
    clearcoat_roughness_factor: f32,
    clearcoat_roughness_texture: Option<JsonTextureInfo>,
    clearcoat_normal_texture: Option<serde_json::Value>,
    #[serde(skip)]
    texture: Option<TextureRef>,
    #[serde(skip)]
    roughness_texture: Option<TextureRef>,
}

/// A material's KHR_materials_transmission object, as the JSON has it, and its decoded texture.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase")]
struct Transmission {
    #[serde(default)]
    transmission_factor: f32,
    transmission_texture: Option<JsonTextureInfo>,
    #[serde(skip)]
    texture: Option<TextureRef>,
}

/// A material's KHR_materials_volume object, as the JSON has it.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
struct JsonVolume {
    #[serde(default)]
    thickness_factor: f32,
    thickness_texture: Option<serde_json::Value>,
    #[serde(default = "infinite")]
    attenuation_distance: f32,
    #[serde(default = "white")]
    attenuation_color: [f32; 3],
}

/// KHR_materials_volume's default attenuationDistance: no attenuation.
fn infinite() -> f32 {
    f32::INFINITY
}

/// KHR_materials_volume's default attenuationColor.
fn white() -> [f32; 3] {
    [1.0; 3]
}

/// A textureInfo read from the JSON: the texture's index and its texCoord set.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
struct JsonTextureInfo {
    index: usize,
    #[serde(default)]
    tex_coord: u32,
    /// Its KHR_texture_transform, read from its `extensions`.
    #[serde(
        default,
        rename = "extensions",
        deserialize_with = "transform_in_extensions"
    )]
    transform: Option<UvTransform>,
}

/// The KHR_texture_transform of a texture info's `extensions` object, if it has one.
fn transform_in_extensions<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<UvTransform>, D::Error> {
    let extensions = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
    extensions
        .get("KHR_texture_transform")
        .map(UvTransform::from_json)
        .transpose()
        .map_err(serde::de::Error::custom)
}

/// A texture info's KHR_texture_transform, from the gltf crate's accessor or, for the texture
/// infos it has none for (normalTexture), from the extension's JSON.
#[derive(Clone, Copy, Debug)]
struct UvTransform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
    tex_coord: Option<u32>,
}

impl From<gltf::texture::TextureTransform<'_>> for UvTransform {
    fn from(t: gltf::texture::TextureTransform<'_>) -> Self {
        Self {
            offset: t.offset(),
            rotation: t.rotation(),
            scale: t.scale(),
            tex_coord: t.tex_coord(),
        }
    }
}

impl UvTransform {
    /// The transform in an `"extensions": {"KHR_texture_transform": ...}` value.
    fn from_json(value: &serde_json::Value) -> Result<Self, String> {
        let t: gltf::json::extensions::texture::TextureTransform =
            serde_json::from_value(value.clone())
                .map_err(|e| format!("KHR_texture_transform: {e}"))?;
        Ok(Self {
            offset: t.offset.0,
            rotation: t.rotation.0,
            scale: t.scale.0,
            tex_coord: t.tex_coord,
        })
    }
}

/// Size of a GLB file's header: magic, version and total length, 4 bytes each.
const GLB_HEADER_SIZE: usize = 12;

/// Checks the GLB header's total length before the gltf crate reads the chunks, which
/// subtracts the header size from it unchecked (an overflow panic for a length below 12).
fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let length = bytes
        .get(8..GLB_HEADER_SIZE)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    match length {
        None => Err(SceneError::invalid(
            path,
            "GLB header",
            format!(
                "the file has {} bytes, less than the {GLB_HEADER_SIZE}-byte header",
                bytes.len()
            ),
        )),
        Some(length) if length < GLB_HEADER_SIZE => Err(SceneError::invalid(
            path,
            "GLB header",
            format!("its length {length} is less than the {GLB_HEADER_SIZE}-byte header"),
        )),
        Some(_) => Ok(()),
    }
}

/// Checks, in the JSON as written, the references the gltf crate follows without checking
/// them (it panics instead of reporting): every image has a `uri`, or a `bufferView` in range
/// with a `mimeType`; every accessor a mesh primitive names (attributes, `indices`, morph
/// targets) exists, which the crate's own validation indexes before it checks.
fn check_references(path: &Path, raw: &serde_json::Value) -> Result<(), SceneError> {
    let count = |key: &str| raw.get(key).and_then(|v| v.as_array()).map_or(0, Vec::len);
    let views = count("bufferViews");
    let accessors = count("accessors");
    let list = |key: &str| {
        raw.get(key)
            .and_then(|v| v.as_array())
            .map(Vec::as_slice)
            .unwrap_or_default()
    };
    for (i, image) in list("images").iter().enumerate() {
        let element = format!("image {i}");
        match (image.get("uri"), image.get("bufferView")) {
            (None, None) => {
                return Err(SceneError::invalid(
                    path,
                    element,
                    "it has neither a uri nor a bufferView",
                ))
            }
            (_, Some(view)) => {
                if view.as_u64().is_none_or(|v| (v as usize) >= views) {
                    return Err(SceneError::invalid(
                        path,
                        element,
                        format!("its bufferView {view} is not one of the {views} bufferViews"),
                    ));
                }
                if !image.get("mimeType").is_some_and(|m| m.is_string()) {
                    return Err(SceneError::invalid(
                        path,
                        element,
                        "it is stored in a bufferView but has no mimeType",
                    ));
                }
            }
            (Some(_), None) => {}
        }
    }
    for (m, mesh) in list("meshes").iter().enumerate() {
        let primitives = mesh
            .get("primitives")
            .and_then(|v| v.as_array())
            .map(Vec::as_slice)
            .unwrap_or_default();
        for (p, primitive) in primitives.iter().enumerate() {
            let element = |what: &str| format!("mesh {m}, primitive {p}, {what}");
            let mut named: Vec<(String, &serde_json::Value)> = Vec::new();
            fn attributes(v: Option<&serde_json::Value>) -> Vec<(String, &serde_json::Value)> {
                v.and_then(|v| v.as_object())
                    .into_iter()
                    .flatten()
                    .map(|(k, v)| (k.clone(), v))
                    .collect()
            }
            for (name, index) in attributes(primitive.get("attributes")) {
                named.push((element(&format!("attribute {name}")), index));
            }
            if let Some(index) = primitive.get("indices") {
                named.push((element("indices"), index));
            }
            let targets = primitive
                .get("targets")
                .and_then(|v| v.as_array())
                .map(Vec::as_slice)
                .unwrap_or_default();
            for (t, target) in targets.iter().enumerate() {
                for (name, index) in attributes(Some(target)) {
                    named.push((element(&format!("morph target {t}, {name}")), index));
                }
            }
            for (element, index) in named {
                if index.as_u64().is_none_or(|a| (a as usize) >= accessors) {
                    return Err(SceneError::invalid(
                        path,
                        element,
                        format!("accessor {index} is not one of the {accessors} accessors"),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Loads a `.gltf` or `.glb` file, reading the files it names through `files`.
pub(super) fn load(path: &Path, files: &Files) -> Result<Scene, SceneError> {
    let bytes = files.read_scene()?;
    let gltf_err = |source| SceneError::Gltf {
        path: path.to_path_buf(),
        source,
    };
    // The JSON as written, for what the gltf crate does not keep: the extensions it does not
    // know (checked before its validation, which would reject a required one less clearly)
    // and the asset's extras. Compressed geometry is decoded into it before it is read.
    let (raw, blob) = if bytes.starts_with(b"glTF") {
        check_glb_header(path, &bytes)?;
        let glb = gltf::binary::Glb::from_slice(&bytes).map_err(gltf_err)?;
        let raw = serde_json::from_slice(&glb.json);
        (raw, glb.bin.map(|b| b.into_owned()))
    } else {
        (serde_json::from_slice(&bytes), None)
    };
    let mut raw: serde_json::Value = raw.map_err(|e| gltf_err(gltf::Error::Deserialize(e)))?;
    let extension_warnings = extensions::check(path, &raw)?;
    let light_units = light_units(path, &raw)?;
    // The extensions the loader honours have been checked; the gltf crate's validation would
    // reject the required ones it does not implement itself.
    if let Some(serde_json::Value::Array(required)) = raw.get_mut("extensionsRequired") {
        required.retain(|e| {
            !e.as_str()
                .is_some_and(|e| extensions::HONOURED.contains(&e))
        });
    }
    let read = |raw: serde_json::Value| {
        serde_json::from_value(raw)
            .map_err(gltf::Error::Deserialize)
            .and_then(gltf::Document::from_json)
            .map_err(gltf_err)
    };
    // The buffers are loaded first, from the file's buffer list alone: compressed geometry
    // must be decoded before the whole document is valid (Draco's accessors have no
    // bufferView until then).
    let buffer_list = serde_json::json!({
        "asset": raw.get("asset").cloned().unwrap_or_default(),
        // A file with no geometry (lights and cameras only) may have no buffer list.
        "buffers": raw.get("buffers").cloned().unwrap_or_else(|| serde_json::json!([])),
    });
    let base = files.folder().to_path_buf();
    let fallbacks = compression::fallback_buffers(&raw);
    let mut buffers = load_buffers(path, files, &read(buffer_list)?, blob, &fallbacks)?;
    compression::decode(path, &mut raw, &mut buffers, files)?;
    check_references(path, &raw)?;
    let document = read(raw)?;
    check_views(path, &document, &buffers, &fallbacks)?;
    let mut loader = Loader {
        path,
        base,
        files,
        buffers,
        parts: SceneParts {
            source: path.to_path_buf(),
            ..SceneParts::default()
        },
        textures: HashMap::new(),
        default_material: None,
        light_units,
        placements: Vec::new(),
    };
    for w in extension_warnings {
        loader.warn(w);
    }
    for (i, m) in document.materials().enumerate() {
        let material = loader.material(&m, i, &document)?;
        loader.parts.materials.push(material);
    }
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            // Nodes reached by several paths (a DAG) are visited once per path, which may be
            // exponentially many: they are counted first.
            count_visits(path, &document, &scene)?;
            // Depth-first in file order with an explicit stack; a depth beyond the node count
            // can only come from a cycle.
            let node_count = document.nodes().len();
            let mut stack: Vec<(gltf::Node, Mat4, usize)> =
                scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
            stack.reverse();
            while let Some((node, parent, depth)) = stack.pop() {
                if depth > node_count {
                    return Err(SceneError::invalid(
                        path,
                        node_label(&node),
                        "the node hierarchy has a cycle",
                    ));
                }
                let world = loader.node(&node, parent, &document)?;
                let first_child = stack.len();
                stack.extend(node.children().map(|c| (c, world, depth + 1)));
                stack[first_child..].reverse();
            }
        }
        None => loader
            .parts
            .warnings
            .push(format!("{}: the file has no scene", path.display())),
    }
    loader.place_meshes(&document)?;
    if !loader.parts.tangents.is_empty() {
        let n = loader.parts.positions.len();
        loader.parts.tangents.resize(n, Vec4::ZERO);
    }
    Scene::from_parts(loader.parts)
}

/// The most node visits (a node reached by several paths of the hierarchy is visited once per
/// path) and, separately, mesh placements (node meshes and EXT_mesh_gpu_instancing instances)
/// a scene may have: a hierarchy in which each node lists the next one twice reaches 2^40
/// placements in 40 levels, so the walk counts them before it makes them.
pub const MAX_PLACEMENTS: usize = 1_000_000;

/// The most triangles a scene may hold once its meshes are placed: the flattened placements'
/// (every placement of a mesh placed once, or with an emissive material) and the instanced
/// meshes' (stored once); counted from the accessors before any geometry is read. About
/// 8 GB of scene and BVH; an emissive mesh placed many times would otherwise multiply it.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// The error for a hierarchy that places more than [`MAX_PLACEMENTS`] nodes or instances,
/// found at `node`.
fn too_many_placements(path: &Path, node: &gltf::Node) -> SceneError {
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
fn count_visits(
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
fn primitive_triangles(prim: &gltf::Primitive) -> usize {
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

/// Swaps the vertex arrays and triangles of `parts` with those of `mesh`.
fn swap_geometry(parts: &mut SceneParts, mesh: &mut MeshParts) {
    std::mem::swap(&mut parts.positions, &mut mesh.positions);
    std::mem::swap(&mut parts.normals, &mut mesh.normals);
    std::mem::swap(&mut parts.uvs, &mut mesh.uvs);
    std::mem::swap(&mut parts.tangents, &mut mesh.tangents);
    std::mem::swap(&mut parts.uvs1, &mut mesh.uvs1);
    std::mem::swap(&mut parts.colors, &mut mesh.colors);
    std::mem::swap(&mut parts.triangles, &mut mesh.triangles);
    std::mem::swap(&mut parts.triangle_materials, &mut mesh.triangle_materials);
}

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

/// Loads every buffer of `document` (external files, data URIs, the GLB binary chunk), except
/// the meshopt fallback buffers `fallbacks`, which are placeholders without data (left empty).
/// Each holds exactly its `byteLength` bytes: a file is checked to be at least that long
/// before they are reserved, and nothing past them is read.
fn load_buffers(
    path: &Path,
    files: &Files,
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    fallbacks: &[usize],
) -> Result<Vec<gltf::buffer::Data>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        if fallbacks.contains(&buffer.index()) {
            buffers.push(gltf::buffer::Data(Vec::new()));
            continue;
        }
        let length = buffer.length();
        let (element, data) = match buffer.source() {
            gltf::buffer::Source::Bin => {
                let element = format!("buffer {} (GLB binary chunk)", buffer.index());
                let data = blob.take().ok_or_else(|| {
                    SceneError::invalid(path, &element, "the GLB file has no binary chunk")
                })?;
                (element, data)
            }
            gltf::buffer::Source::Uri(uri) => {
                let element = format!(
                    "buffer {} ({})",
                    buffer.index(),
                    uri_label(files.folder(), uri)
                );
                let data = match files.uri(uri, &format!("buffer {}", buffer.index()))? {
                    Uri::Data(bytes, _) => bytes,
                    Uri::File(file) => files.read_prefix(&file, length as u64, &element)?,
                };
                (element, data)
            }
        };
        if data.len() < length {
            return Err(SceneError::invalid(
                path,
                element,
                format!("holds {} bytes but byteLength is {length}", data.len()),
            ));
        }
        let mut data = data;
        data.truncate(length);
        buffers.push(gltf::buffer::Data(data));
    }
    Ok(buffers)
}

/// Checks that every bufferView lies within its buffer, and that none (after decompression)
/// reads a meshopt fallback buffer.
fn check_views(
    path: &Path,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    fallbacks: &[usize],
) -> Result<(), SceneError> {
    for view in document.views() {
        if fallbacks.contains(&view.buffer().index()) {
            return Err(SceneError::invalid(
                path,
                format!("bufferView {}", view.index()),
                format!(
                    "reads buffer {}, a {} fallback without data, but is not compressed",
                    view.buffer().index(),
                    compression::MESHOPT
                ),
            ));
        }
        let end = view.offset().checked_add(view.length());
        let have = buffers[view.buffer().index()].len();
        if end.is_none_or(|e| e > have) {
            return Err(SceneError::invalid(
                path,
                format!("bufferView {}", view.index()),
                format!(
                    "bytes {}..+{} exceed buffer {} ({have} bytes)",
                    view.offset(),
                    view.length(),
                    view.buffer().index()
                ),
            ));
        }
    }
    Ok(())
}

struct Loader<'a> {
    path: &'a Path,
    base: PathBuf,
    /// Reads the files the scene names (images), inside its folder.
    files: &'a Files<'a>,
    buffers: Vec<gltf::buffer::Data>,
    parts: SceneParts,
    /// Decoded textures by (image index, colour space).
    textures: HashMap<(usize, ColorSpace), TextureId>,
    /// Index of the glTF default material, once a primitive needs it.
    default_material: Option<u32>,
    /// What KHR_lights_punctual's intensities are in.
    light_units: LightUnits,
    /// Every placement of a mesh in the walk's order: mesh index and world transform.
    placements: Vec<(usize, Mat4)>,
}

/// The units of a file's KHR_lights_punctual intensities: the specification's photometric ones
/// (candela for point and spot lights, lux for directional lights), or, where the file says so
/// with `asset.extras.streaks.light_units: "radiometric"`, W/sr and W/m^2 as they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum LightUnits {
    Photometric,
    Radiometric,
}

/// `asset.extras.streaks` (see the `scene` module documentation).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct AssetExtras {
    light_units: LightUnits,
}

/// The light units `asset.extras.streaks.light_units` of the file's JSON chooses (photometric
/// when absent).
fn light_units(path: &Path, json: &serde_json::Value) -> Result<LightUnits, SceneError> {
    let bad = |reason: String| SceneError::invalid(path, "asset.extras", reason);
    match json.pointer("/asset/extras/streaks") {
        None => Ok(LightUnits::Photometric),
        Some(streaks) => serde_json::from_value::<AssetExtras>(streaks.clone())
            .map(|x| x.light_units)
            .map_err(|e| {
                bad(format!(
                    "streaks: {e} (expected {{\"light_units\": \"photometric\" | \"radiometric\"}})"
                ))
            }),
    }
}

impl Loader<'_> {
    fn bad(&self, element: impl Into<String>, reason: impl Into<String>) -> SceneError {
        SceneError::invalid(self.path, element, reason)
    }

    fn warn(&mut self, msg: String) {
        self.parts
            .warnings
            .push(format!("{}: {msg}", self.path.display()));
    }

    /// Adds what `node` carries (camera, light; its mesh's placements are recorded for
    /// [`Loader::place_meshes`]); returns its world transform.
    fn node(
        &mut self,
        node: &gltf::Node,
        parent: Mat4,
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
                        self.placements.push((mesh.index(), w));
                    }
                }
                None => {
                    if self.placements.len() >= MAX_PLACEMENTS {
                        return Err(too_many_placements(self.path, node));
                    }
                    self.placements.push((mesh.index(), world));
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

    /// The local transforms `T * R * S` of the instances of `node`'s EXT_mesh_gpu_instancing
    /// `ext` (its TRANSLATION, ROTATION and SCALE accessors, each optional, of one count;
    /// quantized as KHR_mesh_quantization allows).
    fn gpu_instances(
        &self,
        node: &gltf::Node,
        ext: &serde_json::Value,
        document: &gltf::Document,
    ) -> Result<Vec<Mat4>, SceneError> {
        let element = format!("{}, EXT_mesh_gpu_instancing", node_label(node));
        let attributes = ext.get("attributes").and_then(|a| a.as_object());
        let Some(attributes) = attributes else {
            return Err(self.bad(element, "has no attributes object"));
        };
        let accessor = |name: &str| -> Result<Option<gltf::Accessor>, SceneError> {
            match attributes.get(name) {
                None => Ok(None),
                Some(v) => v
                    .as_u64()
                    .and_then(|i| document.accessors().nth(i as usize))
                    .map(Some)
                    .ok_or_else(|| {
                        self.bad(format!("{element}, {name}"), format!("no accessor {v}"))
                    }),
            }
        };
        let read3 = |name: &str| -> Result<Option<Vec<Vec3>>, SceneError> {
            accessor(name)?
                .map(|a| {
                    self.attribute::<3>(&a, &element, name, accessor::POSITION, None)
                        .map(|v| v.into_iter().map(Vec3::from).collect())
                })
                .transpose()
        };
        let translation = read3("TRANSLATION")?;
        let scale = read3("SCALE")?;
        let rotation: Option<Vec<Quat>> = accessor("ROTATION")?
            .map(|a| {
                self.attribute::<4>(&a, &element, "ROTATION", accessor::DIRECTION, None)
                    .map(|v| {
                        v.into_iter()
                            .map(|q| Quat::from_array(q).normalize())
                            .collect()
                    })
            })
            .transpose()?;
        let counts = [
            translation.as_ref().map(Vec::len),
            rotation.as_ref().map(Vec::len),
            scale.as_ref().map(Vec::len),
        ];
        let mut known = counts.iter().flatten();
        let Some(&count) = known.next() else {
            return Err(self.bad(
                element,
                "has none of the attributes TRANSLATION, ROTATION, SCALE",
            ));
        };
        if known.any(|&c| c != count) {
            return Err(self.bad(
                element,
                format!("attribute counts differ (TRANSLATION, ROTATION, SCALE: {counts:?})"),
            ));
        }
        Ok((0..count)
            .map(|i| {
                Mat4::from_scale_rotation_translation(
                    scale.as_ref().map_or(Vec3::ONE, |s| s[i]),
                    // A zero quaternion becomes NaN here and fails the caller's check.
                    rotation.as_ref().map_or(Quat::IDENTITY, |r| r[i]),
                    translation.as_ref().map_or(Vec3::ZERO, |t| t[i]),
                )
            })
            .collect())
    }

    /// Turns the recorded placements into geometry: a mesh placed more than once and without
    /// an emissive material is loaded once in object space and placed by instances, every
    /// other placement is flattened into world triangles (see the module documentation).
    fn place_meshes(&mut self, document: &gltf::Document) -> Result<(), SceneError> {
        let meshes: Vec<gltf::Mesh> = document.meshes().collect();
        let mut count = vec![0usize; meshes.len()];
        for &(m, _) in &self.placements {
            count[m] += 1;
        }
        let emissive: Vec<bool> = meshes
            .iter()
            .map(|mesh| {
                mesh.primitives().any(|p| {
                    p.material()
                        .index()
                        .is_some_and(|i| self.parts.materials[i].is_emissive())
                })
            })
            .collect();
        // Triangles stored: a flattened mesh's at each placement, an instanced one's once.
        let mut stored = 0usize;
        for (m, mesh) in meshes.iter().enumerate() {
            let copies = match (count[m], emissive[m]) {
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
        for (m, world) in std::mem::take(&mut self.placements) {
            let mesh = &meshes[m];
            if count[m] < 2 || emissive[m] {
                self.mesh(mesh, world)?;
                continue;
            }
            let index = match instanced[m] {
                Some(i) => i,
                None => {
                    let object = self.object_mesh(mesh)?;
                    let i = self.parts.instanced_meshes.len() as u32;
                    self.parts.instanced_meshes.push(object);
                    instanced[m] = Some(i);
                    i
                }
            };
            // The walk checked that the transform is invertible.
            if let Some(instance) = Instance::new(index, world) {
                self.parts.instances.push(instance);
            }
        }
        Ok(())
    }

    /// `mesh` loaded in its own (object) space, as [`Loader::mesh`] loads it with the identity
    /// transform, into its own arrays.
    fn object_mesh(&mut self, mesh: &gltf::Mesh) -> Result<MeshParts, SceneError> {
        let mut world = MeshParts::default();
        swap_geometry(&mut self.parts, &mut world);
        let loaded = self.mesh(mesh, Mat4::IDENTITY);
        let mut object = MeshParts::default();
        swap_geometry(&mut self.parts, &mut object);
        swap_geometry(&mut self.parts, &mut world);
        loaded?;
        if !object.tangents.is_empty() {
            object.tangents.resize(object.positions.len(), Vec4::ZERO);
        }
        object.name = mesh_label(mesh);
        Ok(object)
    }

    fn camera(
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
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            return Err(self.bad(element, "orthographic cameras are not supported"));
        };
        validate::perspective(&p).map_err(|r| self.bad(&element, r))?;
        let yfov = p.yfov();
        let (_, rotation, translation) = world.to_scale_rotation_translation();
        self.parts.cameras.push(Camera {
            name,
            world_from_camera: Affine3A::from_rotation_translation(
                rotation.normalize(),
                translation,
            ),
            yfov,
            aspect_ratio: p.aspect_ratio(),
        });
        Ok(())
    }

    fn light(
        &mut self,
        node: &gltf::Node,
        light: &gltf::khr_lights_punctual::Light,
        world: Mat4,
    ) -> Result<(), SceneError> {
        use gltf::khr_lights_punctual::Kind;
        validate::light(light).map_err(|r| {
            let name = light.name().map_or(String::new(), |n| format!("{n:?} "));
            let element = format!("light {name}({}) on {}", light.index(), node_label(node));
            self.bad(element, r)
        })?;
        // Photometric (candela, lux) to radiometric (W/sr, W/m^2) unless the file is radiometric.
        let power = match self.light_units {
            LightUnits::Photometric => {
                Vec3::from(light.color()) * (light.intensity() / LUMINOUS_EFFICACY)
            }
            LightUnits::Radiometric => Vec3::from(light.color()) * light.intensity(),
        };
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(-Vec3::Z).normalize();
        let range = light.range();
        self.parts.lights.push(match light.kind() {
            Kind::Point => Light::Point {
                position,
                intensity: power,
                range,
            },
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => Light::Spot {
                position,
                direction,
                intensity: power,
                cos_inner: inner_cone_angle.cos(),
                cos_outer: outer_cone_angle.cos(),
                range,
            },
            Kind::Directional => Light::Directional {
                direction,
                irradiance: power,
            },
        });
        Ok(())
    }

    /// Checks that `accessor` has one of the `allowed` layouts and lies within its view.
    /// The values of vertex attribute `name` of primitive `element` (`accessor`), of `N`
    /// components of one of the types `allowed`, and `count` of them if given.
    fn attribute<const N: usize>(
        &self,
        accessor: &gltf::Accessor,
        element: &str,
        name: &str,
        allowed: &[accessor::Component],
        count: Option<usize>,
    ) -> Result<Vec<[f32; N]>, SceneError> {
        let element = format!("{element}, {name} (accessor {})", accessor.index());
        // What the values will take, charged before they are read (the accessor itself is
        // checked against its bufferView by the read).
        self.files
            .charge_expanded((accessor.count() as u64).saturating_mul(4 * N as u64))
            .map_err(|r| self.bad(&element, r))?;
        let values = accessor::read::<N>(accessor, &self.buffers, allowed)
            .map_err(|r| self.bad(&element, r))?;
        match count {
            Some(n) if values.len() != n => Err(self.bad(
                element,
                format!("{} values for {n} positions", values.len()),
            )),
            _ => Ok(values),
        }
    }

    fn check_accessor(
        &self,
        accessor: &gltf::Accessor,
        element: &str,
        allowed: &[(Dimensions, DataType)],
    ) -> Result<(), SceneError> {
        let element = format!("{element} (accessor {})", accessor.index());
        if accessor.sparse().is_some() {
            return Err(self.bad(element, "sparse accessors are not supported"));
        }
        let layout = (accessor.dimensions(), accessor.data_type());
        if !allowed.contains(&layout) {
            return Err(self.bad(
                element,
                format!("unexpected layout {layout:?} (allowed: {allowed:?})"),
            ));
        }
        let count = accessor.count();
        if count == 0 {
            return Err(self.bad(element, "count is 0"));
        }
        // The indices will be read as 32-bit values.
        self.files
            .charge_expanded((count as u64).saturating_mul(4))
            .map_err(|r| self.bad(&element, r))?;
        let Some(view) = accessor.view() else {
            return Err(self.bad(element, "has no bufferView"));
        };
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(self.bad(
                element,
                format!("byteStride {stride} is smaller than an element ({size} bytes)"),
            ));
        }
        let end = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(accessor.offset()));
        if end.is_none_or(|e| e > view.length()) {
            return Err(self.bad(
                element,
                format!(
                    "{count} elements from byte {} (stride {stride}) overrun bufferView {} \
                     ({} bytes)",
                    accessor.offset(),
                    view.index(),
                    view.length()
                ),
            ));
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh, world: Mat4) -> Result<(), SceneError> {
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        let flip = world.determinant() < 0.0;
        for prim in mesh.primitives() {
            let element = format!("{}, primitive {}", mesh_label(mesh), prim.index());
            let mode = prim.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.warn(format!("{element}: skipped {mode:?} primitive"));
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
            let positions: Vec<Vec3> = self
                .attribute(&pos_acc, &element, "POSITION", accessor::POSITION, None)?
                .into_iter()
                .map(Vec3::from)
                .collect();
            let n = positions.len();
            let normals: Vec<Vec3> = match prim.get(&gltf::Semantic::Normals) {
                Some(a) => self
                    .attribute(&a, &element, "NORMAL", accessor::DIRECTION, Some(n))?
                    .into_iter()
                    .map(|v: [f32; 3]| {
                        (normal_matrix * Vec3::from(v))
                            .try_normalize()
                            .unwrap_or(Vec3::ZERO)
                    })
                    .collect(),
                None => vec![Vec3::ZERO; n],
            };
            let uvs: Vec<Vec2> = match prim.get(&gltf::Semantic::TexCoords(0)) {
                Some(a) => self
                    .attribute(&a, &element, "TEXCOORD_0", accessor::TEXCOORD, Some(n))?
                    .into_iter()
                    .map(Vec2::from)
                    .collect(),
                None => vec![Vec2::ZERO; n],
            };
            // A normal-mapped primitive's tangents: the file's if it has TANGENT and NORMAL.
            let normal_mapped = prim
                .material()
                .index()
                .is_some_and(|i| self.parts.materials[i].normal_map.is_some());
            let has_normals = prim.get(&gltf::Semantic::Normals).is_some();
            let tangent_acc = prim
                .get(&gltf::Semantic::Tangents)
                .filter(|_| normal_mapped);
            let file_tangents: Option<Vec<[f32; 4]>> = match &tangent_acc {
                Some(a) if has_normals => {
                    Some(self.attribute(a, &element, "TANGENT", accessor::DIRECTION, Some(n))?)
                }
                _ => None,
            };
            let buffers = &self.buffers;
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.0.as_slice()));
            let uvs1: Option<Vec<Vec2>> = match prim.get(&gltf::Semantic::TexCoords(1)) {
                Some(a) => Some(
                    self.attribute(&a, &element, "TEXCOORD_1", accessor::TEXCOORD, Some(n))?
                        .into_iter()
                        .map(Vec2::from)
                        .collect(),
                ),
                None => None,
            };
            let colors: Option<Vec<Vec4>> = match prim.get(&gltf::Semantic::Colors(0)) {
                Some(a) if a.dimensions() == Dimensions::Vec3 => Some(
                    self.attribute::<3>(&a, &element, "COLOR_0", accessor::COLOR, Some(n))?
                        .into_iter()
                        .map(|c| Vec3::from(c).extend(1.0))
                        .collect(),
                ),
                Some(a) => Some(
                    self.attribute::<4>(&a, &element, "COLOR_0", accessor::COLOR, Some(n))?
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
                self.warn(format!(
                    "{element}: {} indices is not a multiple of 3; the rest is ignored",
                    indices.len()
                ));
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
                            match self.parts.materials[material as usize].normal_map {
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
                self.warn(format!(
                    "{element}: its material reads TEXCOORD_1, which the primitive does not \
                     have; TEXCOORD_0 is read instead"
                ));
            }
            let first = self.parts.positions.len();
            if first + positions.len() > u32::MAX as usize {
                return Err(self.bad(element, "the scene has more than 2^32 - 1 vertices"));
            }
            if let Some(t) = tangents {
                self.parts.tangents.resize(first, Vec4::ZERO);
                self.parts.tangents.extend(t);
            }
            let first = first as u32;
            for t in &mut tris {
                *t = t.map(|i| i + first);
            }
            self.parts.positions.extend(positions);
            self.parts.normals.extend(normals);
            // The second uv set and the colours are stored only once some primitive has them:
            // earlier vertices get TEXCOORD_0 and white, as do later primitives without them.
            let parts = &mut self.parts;
            match uvs1 {
                Some(uvs1) => {
                    if parts.uvs1.is_empty() {
                        parts.uvs1 = parts.uvs.clone();
                    }
                    parts.uvs1.extend(uvs1);
                }
                None if !parts.uvs1.is_empty() => parts.uvs1.extend_from_slice(&uvs),
                None => {}
            }
            match colors {
                Some(colors) => {
                    if parts.colors.is_empty() {
                        parts.colors = vec![Vec4::ONE; parts.uvs.len()];
                    }
                    parts.colors.extend(colors);
                }
                None if !parts.colors.is_empty() => {
                    parts
                        .colors
                        .extend(std::iter::repeat_n(Vec4::ONE, uvs.len()));
                }
                None => {}
            }
            self.parts.uvs.extend(uvs);
            self.parts
                .triangle_materials
                .extend(std::iter::repeat_n(material, tris.len()));
            self.parts.triangles.extend(tris);
        }
        Ok(())
    }

    /// The generated tangents of a normal-mapped primitive without usable TANGENT (see
    /// [`tangents`]): MikkTSpace's from the world-space `positions`, `normals` (zero: the face
    /// normal) and `uvs`, which may renumber `tris` to duplicated vertices (the second value
    /// lists the vertex each duplicate copies). `has` says whether the primitive has TANGENT
    /// (then ignored: it has no NORMAL) and TEXCOORD_0 (without it there is nothing to map:
    /// zero tangents). Both cases are warned about.
    fn tangents(
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
            self.warn(format!(
                "{element}: its material has a normal texture but the primitive has no \
                 TEXCOORD_0; rendered without the normal map"
            ));
            return (vec![Vec4::ZERO; positions.len()], Vec::new());
        }
        if has_tangents {
            self.warn(format!(
                "{element}: has TANGENT but no NORMAL; the tangents are ignored and generated \
                 from flat normals, as the glTF specification says"
            ));
        }
        tangents::generate(positions, normals, uvs, tris).unwrap_or_else(|valence| {
            self.warn(format!(
                "{element}: a vertex is shared by {valence} triangles, more than MikkTSpace can \
                 take ({}: it recurses once per triangle around a vertex); rendered without \
                 the normal map",
                tangents::MAX_VALENCE
            ));
            (vec![Vec4::ZERO; positions.len()], Vec::new())
        })
    }

    /// The glTF default material (white, metallic 1, roughness 1), added once when needed.
    fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.parts.materials.push(Material {
                name: "default".into(),
                reflectance: Reflectance::GltfPbr(GltfPbrParams::default()),
                emission: Vec3::ZERO,
                emission_texture: None,
                normal_map: None,
                double_sided: false,
                alpha: Alpha::OPAQUE,
                road: false,
            });
            (self.parts.materials.len() - 1) as u32
        })
    }

    fn material(
        &mut self,
        m: &gltf::Material,
        index: usize,
        document: &gltf::Document,
    ) -> Result<Material, SceneError> {
        let name = m
            .name()
            .map_or_else(|| format!("material{index}"), str::to_string);
        let element = format!("material {name:?} ({index})");
        validate::material(m).map_err(|r| self.bad(&element, r))?;
        let pbr = m.pbr_metallic_roughness();
        let base_color_texture = match pbr.base_color_texture() {
            Some(info) => Some(self.texture(&info, ColorSpace::Srgb, &element)?),
            None => None,
        };
        let mr_texture = match pbr.metallic_roughness_texture() {
            Some(info) => Some(self.texture(&info, ColorSpace::Linear, &element)?),
            None => None,
        };
        let emission_texture = match m.emissive_texture() {
            Some(info) => Some(self.texture(&info, ColorSpace::Srgb, &element)?),
            None => None,
        };
        let normal_map = match m.normal_texture() {
            Some(info) => {
                let scale = info.scale();
                if !scale.is_finite() {
                    return Err(
                        self.bad(element, format!("normalTexture.scale {scale} is invalid"))
                    );
                }
                Some(NormalMap {
                    texture: {
                        let transform = info
                            .extension_value("KHR_texture_transform")
                            .map(UvTransform::from_json)
                            .transpose()
                            .map_err(|e| self.bad(format!("{element}, normalTexture"), e))?;
                        self.texture_of(
                            &info.texture(),
                            info.tex_coord(),
                            transform,
                            ColorSpace::Linear,
                            &element,
                        )?
                    },
                    scale,
                })
            }
            None => None,
        };
        let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        if !emission.is_finite() || emission.min_element() < 0.0 {
            return Err(self.bad(element, format!("emission {emission} is invalid")));
        }
        let base = Vec4::from(pbr.base_color_factor());
        let mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => {
                let cutoff = m.alpha_cutoff().unwrap_or(0.5);
                if !cutoff.is_finite() {
                    return Err(self.bad(element, format!("alphaCutoff {cutoff} is invalid")));
                }
                AlphaMode::Mask { cutoff }
            }
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        let alpha = match mode {
            AlphaMode::Opaque => Alpha::OPAQUE,
            mode => Alpha {
                mode,
                factor: base.w,
                texture: base_color_texture,
            },
        };
        let extras = self.streaks_extras(m, &element)?;
        let road = extras.as_ref().is_some_and(|x| x.road);
        let reflectance = match extras.filter(|x| x.bsdf.is_some()) {
            Some(x) => self.paper(x, base_color_texture, mr_texture, &element)?,
            None => {
                let specular = self.specular(m, &element)?;
                let clearcoat = self.clearcoat(m, document, &element)?;
                let transmission = self.transmission(m, document, &element)?;
                let volume = self.volume(m, &element)?;
                Reflectance::GltfPbr(GltfPbrParams {
                    base_color: base.truncate(),
                    base_color_texture,
                    metallic: pbr.metallic_factor(),
                    roughness: pbr.roughness_factor(),
                    metallic_roughness_texture: mr_texture,
                    specular: specular.factor,
                    specular_texture: specular.texture,
                    specular_color: specular.color,
                    specular_color_texture: specular.color_texture,
                    ior: specular.ior,
                    clearcoat: clearcoat.clearcoat_factor,
                    clearcoat_texture: clearcoat.texture,
                    clearcoat_roughness: clearcoat.clearcoat_roughness_factor,
                    clearcoat_roughness_texture: clearcoat.roughness_texture,
                    transmission: transmission.transmission_factor,
                    transmission_texture: transmission.texture,
                    volume,
                })
            }
        };
        Ok(Material {
            name,
            reflectance,
            emission,
            emission_texture,
            normal_map,
            double_sided: m.double_sided(),
            alpha,
            road,
        })
    }

    /// KHR_materials_specular and KHR_materials_ior of a glTF material, with their defaults
    /// where absent (specular 1, specular colour 1, ior 1.5); out-of-range values are errors.
    fn specular(&mut self, m: &gltf::Material, element: &str) -> Result<Specular, SceneError> {
        let ior = m.ior().unwrap_or(1.5);
        if !(ior == 0.0 || (ior.is_finite() && ior >= 1.0)) {
            return Err(self.bad(
                element,
                format!("KHR_materials_ior: ior {ior} must be 0 or at least 1"),
            ));
        }
        let Some(sp) = m.specular() else {
            return Ok(Specular {
                factor: 1.0,
                texture: None,
                color: Vec3::ONE,
                color_texture: None,
                ior,
            });
        };
        let (factor, color) = (sp.specular_factor(), Vec3::from(sp.specular_color_factor()));
        if !(0.0..=1.0).contains(&factor) {
            return Err(self.bad(
                element,
                format!("KHR_materials_specular: specularFactor {factor} is not in [0, 1]"),
            ));
        }
        if !(color.is_finite() && color.min_element() >= 0.0) {
            return Err(self.bad(
                element,
                format!("KHR_materials_specular: specularColorFactor {color} is invalid"),
            ));
        }
        let texture = match sp.specular_texture() {
            Some(info) => Some(self.texture(&info, ColorSpace::Linear, element)?),
            None => None,
        };
        let color_texture = match sp.specular_color_texture() {
            Some(info) => Some(self.texture(&info, ColorSpace::Srgb, element)?),
            None => None,
        };
        Ok(Specular {
            factor,
            texture,
            color,
            color_texture,
            ior,
        })
    }

    /// KHR_materials_clearcoat of a glTF material (no coat where absent), read from the JSON
    /// (the gltf crate does not know the extension); its textures are decoded, and a
    /// clearcoatNormalTexture is a warning, as the coat is shaded with the base's normal.
    fn clearcoat(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Clearcoat, SceneError> {
        let Some(value) = m.extension_value("KHR_materials_clearcoat") else {
            return Ok(Clearcoat::default());
        };
        let reason = |r: String| format!("KHR_materials_clearcoat: {r}");
        let mut c: Clearcoat = serde_json::from_value(value.clone())
            .map_err(|e| self.bad(element, reason(e.to_string())))?;
        for (key, v) in [
            ("clearcoatFactor", c.clearcoat_factor),
            ("clearcoatRoughnessFactor", c.clearcoat_roughness_factor),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(self.bad(element, reason(format!("{key} {v} is not in [0, 1]"))));
            }
        }
        if c.clearcoat_normal_texture.is_some() {
            self.warn(format!(
                "{element}: KHR_materials_clearcoat clearcoatNormalTexture is not used; the \
                 clear coat is shaded with the base's normal"
            ));
        }
        for (key, info, space) in [
            ("clearcoatTexture", c.clearcoat_texture, ColorSpace::Linear),
            (
                "clearcoatRoughnessTexture",
                c.clearcoat_roughness_texture,
                ColorSpace::Linear,
            ),
        ] {
            let Some(info) = info else { continue };
            let Some(texture) = document.textures().nth(info.index) else {
                let why = format!("{key}: texture {} does not exist", info.index);
                return Err(self.bad(element, reason(why)));
            };
            let id = self.texture_of(&texture, info.tex_coord, info.transform, space, element)?;
            match key {
                "clearcoatTexture" => c.texture = Some(id),
                _ => c.roughness_texture = Some(id),
            }
        }
        Ok(c)
    }

    /// KHR_materials_transmission of a glTF material (none: transmission 0), with its texture;
    /// a factor outside [0, 1] is an error.
    fn transmission(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Transmission, SceneError> {
        let Some(value) = m.extension_value("KHR_materials_transmission") else {
            return Ok(Transmission::default());
        };
        let reason = |r: String| format!("KHR_materials_transmission: {r}");
        let mut t: Transmission = serde_json::from_value(value.clone())
            .map_err(|e| self.bad(element, reason(e.to_string())))?;
        let factor = t.transmission_factor;
        if !(0.0..=1.0).contains(&factor) {
            let why = format!("transmissionFactor {factor} is not in [0, 1]");
            return Err(self.bad(element, reason(why)));
        }
        if let Some(info) = t.transmission_texture {
            let Some(texture) = document.textures().nth(info.index) else {
                let why = format!("transmissionTexture: texture {} does not exist", info.index);
                return Err(self.bad(element, reason(why)));
            };
            t.texture = Some(self.texture_of(
                &texture,
                info.tex_coord,
                info.transform,
                ColorSpace::Linear,
                element,
            )?);
        }
        Ok(t)
    }

    /// KHR_materials_volume of a glTF material: `None` (thin-walled, as the extension says)
    /// without it or with thicknessFactor 0; out-of-range values are errors, and a
    /// thicknessTexture is a warning (the path tracer measures the distance travelled inside
    /// instead of reading it).
    fn volume(&mut self, m: &gltf::Material, element: &str) -> Result<Option<Volume>, SceneError> {
        let Some(value) = m.extension_value("KHR_materials_volume") else {
            return Ok(None);
        };
        let reason = |r: String| format!("KHR_materials_volume: {r}");
        let v: JsonVolume = serde_json::from_value(value.clone())
            .map_err(|e| self.bad(element, reason(e.to_string())))?;
        let colour = Vec3::from(v.attenuation_color);
        if !(v.thickness_factor.is_finite() && v.thickness_factor >= 0.0) {
            let why = format!("thicknessFactor {} is invalid", v.thickness_factor);
            return Err(self.bad(element, reason(why)));
        }
        if v.attenuation_distance.is_nan() || v.attenuation_distance <= 0.0 {
            let why = format!(
                "attenuationDistance {} must be positive",
                v.attenuation_distance
            );
            return Err(self.bad(element, reason(why)));
        }
        if !(colour.is_finite() && colour.min_element() >= 0.0 && colour.max_element() <= 1.0) {
            let why = format!("attenuationColor {colour} is not in [0, 1]");
            return Err(self.bad(element, reason(why)));
        }
        if v.thickness_factor == 0.0 {
            return Ok(None);
        }
        if v.thickness_texture.is_some() {
            self.warn(format!(
                "{element}: KHR_materials_volume thicknessTexture is not used; the volume's \
                 thickness is the distance the path travels inside the closed mesh"
            ));
        }
        Ok(Some(Volume::new(
            v.thickness_factor,
            colour,
            v.attenuation_distance,
        )))
    }

    fn streaks_extras(
        &self,
        m: &gltf::Material,
        element: &str,
    ) -> Result<Option<StreaksExtras>, SceneError> {
        let Some(raw) = m.extras() else {
            return Ok(None);
        };
        let value: serde_json::Value = serde_json::from_str(raw.get())
            .map_err(|e| self.bad(element, format!("extras: {e}")))?;
        let Some(streaks) = value.get("streaks") else {
            return Ok(None);
        };
        let x: StreaksExtras = serde_json::from_value(streaks.clone())
            .map_err(|e| self.bad(element, format!("extras.streaks: {e}")))?;
        let paper_keys = [
            ("kd", x.kd.is_some()),
            ("ks", x.ks.is_some()),
            ("alpha", x.alpha.is_some()),
            ("shininess", x.shininess.is_some()),
            ("alpha_dry", x.alpha_dry.is_some()),
            ("ks_dry", x.ks_dry.is_some()),
        ];
        if x.bsdf.is_none() {
            if let Some((key, _)) = paper_keys.iter().find(|(_, given)| *given) {
                return Err(self.bad(
                    element,
                    format!(
                        "extras.streaks: {key:?} needs \"bsdf\" (\"ggx\", \"ward\" or \"blinn_phong\"); \
                         without it only \"road\" may be given"
                    ),
                ));
            }
        }
        Ok(Some(x))
    }

    fn paper(
        &self,
        x: StreaksExtras,
        kd_texture: Option<TextureRef>,
        mr_texture: Option<TextureRef>,
        element: &str,
    ) -> Result<Reflectance, SceneError> {
        let bad = |reason: String| self.bad(element, format!("extras.streaks: {reason}"));
        let colour = |c: Option<[f32; 3]>, key: &str| {
            let v = Vec3::from(c.unwrap_or([0.0; 3]));
            if v.is_finite() && v.min_element() >= 0.0 {
                Ok(v)
            } else {
                Err(bad(format!("{key} {v} must be finite and non-negative")))
            }
        };
        let kd = colour(x.kd, "kd")?;
        let ks = colour(x.ks, "ks")?;
        let ks_dry = colour(x.ks_dry.or(x.ks), "ks_dry")?;
        let Some(bsdf) = x.bsdf else {
            return Err(bad("no \"bsdf\"".into()));
        };
        let model = match bsdf {
            StreaksBsdf::Ggx => PaperModel::Ggx,
            StreaksBsdf::Ward => PaperModel::Ward,
            StreaksBsdf::BlinnPhong => PaperModel::BlinnPhong,
        };
        let (alpha, shininess) = match model {
            PaperModel::Ggx | PaperModel::Ward => match x.alpha {
                Some(a) if a.is_finite() && a > 0.0 => (a, 0.0),
                Some(a) => return Err(bad(format!("alpha {a} must be positive"))),
                None => return Err(bad(format!("{model:?} needs \"alpha\""))),
            },
            PaperModel::BlinnPhong => match x.shininess {
                Some(s) if s.is_finite() && s >= 0.0 => (0.0, s),
                Some(s) => return Err(bad(format!("shininess {s} must be non-negative"))),
                None => return Err(bad("blinn_phong needs \"shininess\"".into())),
            },
        };
        let wetness = match x.alpha_dry {
            None => None,
            Some(a)
                if !(a.is_finite() && a >= 0.0)
                    || (a == 0.0 && model != PaperModel::BlinnPhong) =>
            {
                return Err(bad(format!("alpha_dry {a} is invalid")));
            }
            Some(alpha_dry) => {
                let Some(texture) = mr_texture else {
                    return Err(bad(
                        "alpha_dry needs a metallicRoughnessTexture (the dryness map)".into(),
                    ));
                };
                Some(Wetness {
                    texture,
                    alpha_dry,
                    ks_dry,
                })
            }
        };
        Ok(Reflectance::Paper {
            model,
            kd,
            ks,
            alpha,
            shininess,
            kd_texture,
            wetness,
        })
    }

    /// The reference a material's texture info makes: its image (decoded once per colour
    /// space), texture coordinate set, sampler and KHR_texture_transform.
    fn texture(
        &mut self,
        info: &gltf::texture::Info,
        space: ColorSpace,
        material: &str,
    ) -> Result<TextureRef, SceneError> {
        let transform = info.texture_transform().map(UvTransform::from);
        self.texture_of(
            &info.texture(),
            info.tex_coord(),
            transform,
            space,
            material,
        )
    }

    /// The reference to `texture` read at TEXCOORD_`tex_coord` through its KHR_texture_transform
    /// `transform`: its image (decoded once per colour space), texture coordinate set, sampler
    /// and transform.
    fn texture_of(
        &mut self,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<UvTransform>,
        space: ColorSpace,
        material: &str,
    ) -> Result<TextureRef, SceneError> {
        let element = format!("{material}, texture {}", texture.index());
        // KHR_texture_transform's texCoord overrides the texture info's.
        let set = transform
            .as_ref()
            .and_then(|t| t.tex_coord)
            .unwrap_or(tex_coord);
        let texcoord = match set {
            0 | 1 => set as u8,
            _ => {
                self.warn(format!(
                    "{element} uses TEXCOORD_{set}; only TEXCOORD_0 and TEXCOORD_1 are read, \
                     TEXCOORD_0 is used instead"
                ));
                0
            }
        };
        let transform = match transform {
            None => None,
            Some(t) => {
                let (offset, rotation, scale) =
                    (Vec2::from(t.offset), t.rotation, Vec2::from(t.scale));
                if !(offset.is_finite() && rotation.is_finite() && scale.is_finite()) {
                    return Err(self.bad(
                        element,
                        "KHR_texture_transform has a non-finite offset, rotation or scale",
                    ));
                }
                let m = uv_transform(offset, rotation, scale);
                (m != Affine2::IDENTITY).then_some(m)
            }
        };
        let sampler = sampler(&texture.sampler());
        let image = self.image(texture, space, material)?;
        Ok(TextureRef {
            texture: image,
            texcoord,
            sampler,
            transform,
        })
    }

    /// The decoded image of `texture` in colour space `space`, decoded once.
    fn image(
        &mut self,
        texture: &gltf::Texture,
        space: ColorSpace,
        material: &str,
    ) -> Result<TextureId, SceneError> {
        let image = texture.source();
        let key = (image.index(), space);
        if let Some(&id) = self.textures.get(&key) {
            return Ok(id);
        }
        let element = match image.source() {
            gltf::image::Source::Uri { uri, .. } => format!(
                "{material}, image {} ({})",
                image.index(),
                uri_label(&self.base, uri)
            ),
            gltf::image::Source::View { view, .. } => format!(
                "{material}, image {} (bufferView {})",
                image.index(),
                view.index()
            ),
        };
        let (bytes, mime) = match image.source() {
            gltf::image::Source::Uri { uri, mime_type } => {
                match self
                    .files
                    .uri(uri, &format!("{material}, image {}", image.index()))?
                {
                    Uri::Data(bytes, media) => (bytes, media.or(mime_type.map(str::to_string))),
                    Uri::File(file) => (
                        self.files.read(&file, &element)?,
                        mime_type.map(str::to_string),
                    ),
                }
            }
            gltf::image::Source::View { view, mime_type } => {
                let bytes = self
                    .buffers
                    .get(view.buffer().index())
                    .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
                    .ok_or_else(|| self.bad(&element, "its bufferView exceeds its buffer"))?;
                (bytes.to_vec(), Some(mime_type.to_string()))
            }
        };
        // glTF images are PNG or JPEG: by their content, else by their MIME type.
        let format = match (image::guess_format(&bytes), mime.as_deref()) {
            (Ok(f @ (image::ImageFormat::Png | image::ImageFormat::Jpeg)), _) => f,
            (Err(_), Some("image/png")) => image::ImageFormat::Png,
            (Err(_), Some("image/jpeg")) => image::ImageFormat::Jpeg,
            _ => return Err(self.bad(&element, "is not a PNG or JPEG image")),
        };
        let decoded = streaks_image::input::decode_image(&bytes, Some(format))
            .map_err(|reason| self.bad(&element, reason))?;
        drop(bytes);
        let texture = decode_image(decoded, space)
            .ok_or_else(|| self.bad(&element, "pixel data does not match its size"))?;
        let id = self.parts.textures.len() as TextureId;
        self.parts.textures.push(texture);
        self.textures.insert(key, id);
        Ok(id)
    }
}

/// What of a glTF sampler the renderer honours: the wrap modes and the magnification filter
/// (see [`crate::texture`] for why `minFilter` does not change the converged image).
fn sampler(s: &gltf::texture::Sampler) -> Sampler {
    use gltf::texture::{MagFilter, WrappingMode};
    let wrap = |w| match w {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
    };
    Sampler {
        wrap_s: wrap(s.wrap_s()),
        wrap_t: wrap(s.wrap_t()),
        filter: match s.mag_filter() {
            Some(MagFilter::Nearest) => Filter::Nearest,
            Some(MagFilter::Linear) | None => Filter::Linear,
        },
    }
}

/// Triangles (local vertex indices) of a triangle, strip or fan primitive (glTF 2.0 section
/// 3.7.2.1); degenerate strip and fan triangles are kept (they are never hit).
fn triangulate(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
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

/// Converts a decoded image to a linear RGBA texture: 8-bit images stay bytes (RGBA8), others
/// become floats (16-bit values over 65535); grey (and grey-alpha) images replicate their
/// value, as image viewers do.
fn decode_image(image: image::DynamicImage, space: ColorSpace) -> Option<Texture> {
    use image::DynamicImage as D;
    let (width, height) = (image.width(), image.height());
    let rgba8 = |bytes: &[u8], channels: usize| -> Vec<u8> {
        bytes
            .chunks_exact(channels)
            .flat_map(|c| match channels {
                1 => [c[0], c[0], c[0], 255],
                2 => [c[0], c[0], c[0], c[1]],
                3 => [c[0], c[1], c[2], 255],
                _ => [c[0], c[1], c[2], c[3]],
            })
            .collect()
    };
    let u16s = |v: &[u16]| {
        v.iter()
            .map(|&x| f32::from(x) / 65535.0)
            .collect::<Vec<_>>()
    };
    let (values, channels): (Vec<f32>, usize) = match image {
        D::ImageLuma8(i) => return Texture::from_rgba8(width, height, &rgba8(&i, 1), space),
        D::ImageLumaA8(i) => return Texture::from_rgba8(width, height, &rgba8(&i, 2), space),
        D::ImageRgb8(i) => return Texture::from_rgba8(width, height, &rgba8(&i, 3), space),
        D::ImageRgba8(i) => return Texture::from_rgba8(width, height, &i, space),
        D::ImageLuma16(i) => (u16s(&i), 1),
        D::ImageLumaA16(i) => (u16s(&i), 2),
        D::ImageRgb16(i) => (u16s(&i), 3),
        D::ImageRgba16(i) => (u16s(&i), 4),
        D::ImageRgb32F(i) => (i.into_raw(), 3),
        D::ImageRgba32F(i) => (i.into_raw(), 4),
        other => (other.to_rgba32f().into_raw(), 4),
    };
    let texels = values
        .chunks_exact(channels)
        .map(|c| match channels {
            1 => Vec4::new(c[0], c[0], c[0], 1.0),
            2 => Vec4::new(c[0], c[0], c[0], c[1]),
            3 => Vec4::new(c[0], c[1], c[2], 1.0),
            _ => Vec4::new(c[0], c[1], c[2], c[3]),
        })
        .collect();
    Texture::from_rgba(width, height, texels, space)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::VertexAttributes;
    use serde_json::{json, Value};
    use std::f32::consts::FRAC_1_SQRT_2;

    /// A glTF document under construction: one binary buffer, views and accessors.
    #[derive(Default)]
    struct Doc {
        bin: Vec<u8>,
        views: Vec<Value>,
        accessors: Vec<Value>,
    }

    impl Doc {
        fn view(&mut self, bytes: &[u8]) -> usize {
            while self.bin.len() % 4 != 0 {
                self.bin.push(0);
            }
            self.views.push(
                json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}),
            );
            self.bin.extend_from_slice(bytes);
            self.views.len() - 1
        }

        fn floats(&mut self, data: &[f32], ty: &str, width: usize) -> usize {
            let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
            let view = self.view(&bytes);
            let mut acc = json!({"bufferView": view, "componentType": 5126,
                "count": data.len() / width, "type": ty});
            if ty == "VEC3" {
                let col = |k: usize| data.iter().skip(k).step_by(3).copied();
                let min: Vec<f32> = (0..3).map(|k| col(k).fold(f32::MAX, f32::min)).collect();
                let max: Vec<f32> = (0..3).map(|k| col(k).fold(f32::MIN, f32::max)).collect();
                acc["min"] = json!(min);
                acc["max"] = json!(max);
            }
            self.accessors.push(acc);
            self.accessors.len() - 1
        }

        fn indices(&mut self, data: &[u16]) -> usize {
            let bytes: Vec<u8> = data.iter().flat_map(|i| i.to_le_bytes()).collect();
            let view = self.view(&bytes);
            self.accessors
                .push(json!({"bufferView": view, "componentType": 5123,
                "count": data.len(), "type": "SCALAR"}));
            self.accessors.len() - 1
        }
    }

    /// The test scene: a quad (indexed, normals, uvs) under a TRS parent and a matrix child, a
    /// non-indexed emissive triangle without normals, a camera, and three punctual lights.
    pub(super) fn test_doc() -> (Value, Vec<u8>) {
        let mut d = Doc::default();
        let quad_pos = d.floats(&[0., 0., 0., 0., 0., 1., 1., 0., 1., 1., 0., 0.], "VEC3", 3);
        let quad_nrm = d.floats(&[0., 1., 0.].repeat(4), "VEC3", 3);
        let quad_uv = d.floats(&[0., 0., 0., 1., 1., 1., 1., 0.], "VEC2", 2);
        let quad_idx = d.indices(&[0, 1, 2, 0, 2, 3]);
        let tri_pos = d.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3", 3);
        let s = FRAC_1_SQRT_2;
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
            "scene": 0,
            "scenes": [{"nodes": [0, 2, 3, 4, 5, 6]}],
            "nodes": [
                {"name": "parent", "translation": [0, 1, 0], "scale": [2, 2, 2], "children": [1]},
                {"name": "child", "mesh": 0,
                 "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 10,0,0,1]},
                {"name": "lamp", "mesh": 1, "translation": [0, 0, -3]},
                {"name": "cam_node", "camera": 0, "translation": [0, 2, 5], "scale": [3, 3, 3],
                 "rotation": [0, s, 0, s]},
                {"name": "bulb", "translation": [1, 2, 3],
                 "extensions": {"KHR_lights_punctual": {"light": 0}}},
                {"name": "spot", "translation": [0, 5, 0], "rotation": [-s, 0, 0, s],
                 "extensions": {"KHR_lights_punctual": {"light": 1}}},
                {"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 2}}}
            ],
            "meshes": [
                {"name": "quad", "primitives": [{"attributes":
                    {"POSITION": quad_pos, "NORMAL": quad_nrm, "TEXCOORD_0": quad_uv},
                    "indices": quad_idx, "material": 0}]},
                {"name": "tri", "primitives": [{"attributes": {"POSITION": tri_pos}, "material": 1}]}
            ],
            "materials": [
                {"name": "asphalt", "extras": {"streaks": {"bsdf": "ggx", "kd": [0.1, 0.1, 0.1],
                    "ks": [0.5, 0.5, 0.5], "alpha": 0.05}}},
                {"name": "glow", "emissiveFactor": [1, 0.5, 0], "doubleSided": true,
                 "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}}
            ],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}],
            // Candela and lux: 10 W/sr, 3 W/sr and 2 W/m^2 at 683 lm/W.
            "extensions": {"KHR_lights_punctual": {"lights": [
                {"type": "point", "color": [1, 0.5, 0.25], "intensity": 6830, "range": 20},
                {"type": "spot", "intensity": 2049, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
                {"type": "directional", "intensity": 1366}
            ]}},
            "buffers": [{"byteLength": d.bin.len()}],
            "bufferViews": d.views,
            "accessors": d.accessors
        });
        (doc, d.bin)
    }

    pub(super) fn write_embedded(dir: &Path, mut doc: Value, bin: &[u8]) -> PathBuf {
        doc["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            base64::encode(bin)
        ));
        let path = dir.join("scene.gltf");
        std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
        path
    }

    fn write_external(dir: &Path, mut doc: Value, bin: &[u8]) -> PathBuf {
        doc["buffers"][0]["uri"] = json!("scene data.bin");
        std::fs::write(dir.join("scene data.bin"), bin).unwrap();
        let path = dir.join("external.gltf");
        std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
        path
    }

    fn write_glb(dir: &Path, doc: &Value, bin: &[u8]) -> PathBuf {
        let mut json = serde_json::to_vec(doc).unwrap();
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut bin = bin.to_vec();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
        out.extend_from_slice(&bin);
        let path = dir.join("scene.glb");
        std::fs::write(&path, out).unwrap();
        path
    }

    fn approx(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    fn check_test_scene(scene: &Scene) {
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        // Quad: world = T(0,1,0) S(2) T(10,0,0).
        assert_eq!(scene.triangles.len(), 3);
        assert!(approx(scene.positions[2], Vec3::new(22.0, 1.0, 2.0)));
        assert!(approx(scene.positions[0], Vec3::new(20.0, 1.0, 0.0)));
        assert!(approx(scene.normals[1], Vec3::Y));
        assert_eq!(scene.uvs[2], Vec2::new(1.0, 1.0));
        // The emissive triangle has face normals (stored as zero) and sits at z = -3.
        assert_eq!(scene.normals[5], Vec3::ZERO);
        assert!(approx(scene.positions[5], Vec3::new(1.0, 0.0, -3.0)));
        // A ray down onto the quad hits it with the right uv and normal.
        let hit = scene
            .intersect(&crate::geometry::Ray::new(
                Vec3::new(21.0, 5.0, 0.5),
                -Vec3::Y,
            ))
            .expect("hits the quad");
        assert!((hit.t - 4.0).abs() < 1e-5 && approx(hit.ng, Vec3::Y) && approx(hit.ns, Vec3::Y));
        assert!(
            (hit.attributes.uv[0] - Vec2::new(0.5, 0.25)).length() < 1e-5,
            "{}",
            hit.attributes.uv[0]
        );
        assert_eq!(scene.materials[hit.material as usize].name, "asphalt");
        // The triangle: ng = +Z from its winding, ns falls back to ng.
        let hit = scene
            .intersect(&crate::geometry::Ray::new(
                Vec3::new(0.2, 0.2, 1.0),
                -Vec3::Z,
            ))
            .unwrap();
        assert!(approx(hit.ng, Vec3::Z) && approx(hit.ns, Vec3::Z));
        // Materials.
        let Reflectance::Paper {
            model, ks, alpha, ..
        } = &scene.materials[0].reflectance
        else {
            panic!("asphalt is not a paper material")
        };
        assert_eq!((*model, *alpha), (PaperModel::Ggx, 0.05));
        assert!(approx(*ks, Vec3::splat(0.5)));
        let glow = &scene.materials[1];
        assert!(approx(glow.emission, Vec3::new(5.0, 2.5, 0.0)) && glow.double_sided);
        assert!(matches!(
            glow.reflectance,
            Reflectance::GltfPbr(GltfPbrParams { metallic: 1.0, .. })
        ));
        // Camera: named after the node, scale removed, looking along world -X.
        let cam = scene.camera(None).unwrap();
        assert_eq!(cam.name, "cam_node");
        assert_eq!(scene.camera(Some("cam_node")).unwrap().name, "cam_node");
        assert!((cam.yfov - 0.7).abs() < 1e-6 && cam.aspect_ratio == Some(1.5));
        assert!(approx(cam.position(), Vec3::new(0.0, 2.0, 5.0)));
        let fwd = cam.world_from_camera.transform_vector3(-Vec3::Z);
        assert!(approx(fwd, -Vec3::X), "{fwd}");
        assert!((cam.world_from_camera.matrix3.determinant() - 1.0).abs() < 1e-5);
        let err = scene.camera(Some("nope")).unwrap_err().to_string();
        assert!(
            err.contains("nope") && err.contains("\"cam_node\""),
            "{err}"
        );
        // Lights: three punctual ones; emitters: those and the emissive triangle.
        assert_eq!(scene.lights.len(), 3);
        assert_eq!(
            scene.lights[0],
            Light::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                intensity: Vec3::new(10.0, 5.0, 2.5),
                range: Some(20.0)
            }
        );
        let Light::Spot {
            position,
            direction,
            cos_inner,
            cos_outer,
            range,
            ..
        } = scene.lights[1]
        else {
            panic!("not a spot")
        };
        assert!(approx(position, Vec3::new(0.0, 5.0, 0.0)) && approx(direction, -Vec3::Y));
        assert!((cos_inner - 0.2f32.cos()).abs() < 1e-6 && (cos_outer - 0.5f32.cos()).abs() < 1e-6);
        assert_eq!(range, None);
        assert!(
            matches!(scene.lights[2], Light::Directional { direction, irradiance }
            if approx(direction, -Vec3::Z) && approx(irradiance, Vec3::splat(2.0)))
        );
        let emitters = scene.light_sampler.emitters();
        assert_eq!(emitters.len(), 4);
        assert_eq!(emitters.emitter_of(2), Some((3, 0)));
    }

    /// KHR_lights_punctual is photometric (candela, lux) unless `asset.extras.streaks` says
    /// the file is radiometric; anything else there is an error naming it.
    #[test]
    fn light_units_are_photometric_unless_the_asset_says_radiometric() {
        let dir = tempfile::tempdir().unwrap();
        let (mut doc, bin) = test_doc();
        let lights = |doc: &Value| -> Vec<Light> {
            let path = write_embedded(dir.path(), doc.clone(), &bin);
            Scene::load(&path).unwrap().lights
        };
        let photometric = lights(&doc);
        doc["asset"]["extras"] = json!({"streaks": {"light_units": "radiometric"}});
        doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = json!(10);
        doc["extensions"]["KHR_lights_punctual"]["lights"][1]["intensity"] = json!(3);
        doc["extensions"]["KHR_lights_punctual"]["lights"][2]["intensity"] = json!(2);
        let radiometric = lights(&doc);
        assert_eq!(photometric.len(), 3);
        for (a, b) in photometric.iter().zip(&radiometric) {
            let power = |l: &Light| match *l {
                Light::Point { intensity, .. } | Light::Spot { intensity, .. } => intensity,
                Light::Directional { irradiance, .. } => irradiance,
            };
            assert!(
                (power(a) - power(b)).abs().max_element() < 1e-5,
                "{a:?} {b:?}"
            );
        }
        // Other extras of the asset are not ours; a wrong value of ours is an error.
        doc["asset"]["extras"] = json!({"author": "someone"});
        assert_eq!(lights(&doc).len(), 3);
        doc["asset"]["extras"] = json!({"streaks": {"light_units": "watts"}});
        let err = load_err(doc, &bin);
        assert!(
            err.contains("asset.extras") && err.contains("watts"),
            "{err}"
        );
    }

    #[test]
    fn loads_embedded_external_and_glb() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let embedded = write_embedded(dir.path(), doc.clone(), &bin);
        check_test_scene(&Scene::load(&embedded).unwrap());
        let external = write_external(dir.path(), doc.clone(), &bin);
        check_test_scene(&Scene::load(&external).unwrap());
        let glb = write_glb(dir.path(), &doc, &bin);
        check_test_scene(&Scene::load(&glb).unwrap());
    }

    #[test]
    fn a_glb_length_below_its_header_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let glb = write_glb(dir.path(), &doc, &bin);
        let mut bytes = std::fs::read(&glb).unwrap();
        for (length, file) in [(2u32, bytes.clone()), (0, b"glTF\x02\0\0\0".to_vec())] {
            bytes = file;
            if bytes.len() >= 12 {
                bytes[8..12].copy_from_slice(&length.to_le_bytes());
            }
            std::fs::write(&glb, &bytes).unwrap();
            let err = Scene::load(&glb).unwrap_err().to_string();
            assert!(
                err.contains("scene.glb") && err.contains("GLB header"),
                "{err}"
            );
        }
    }

    #[test]
    fn images_without_a_source_or_mime_type_are_errors() {
        let (mut doc, bin) = test_doc();
        doc["images"] = json!([{"name": "nothing"}]);
        let err = load_err(doc.clone(), &bin);
        assert!(
            err.contains("image 0") && err.contains("neither a uri"),
            "{err}"
        );
        doc["images"] = json!([{"bufferView": 0}]);
        let err = load_err(doc.clone(), &bin);
        assert!(
            err.contains("image 0") && err.contains("no mimeType"),
            "{err}"
        );
        doc["images"] = json!([{"bufferView": 99, "mimeType": "image/png"}]);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("image 0") && err.contains("bufferView 99"),
            "{err}"
        );
    }

    #[test]
    fn a_primitive_naming_a_missing_accessor_is_an_error() {
        let (mut doc, bin) = test_doc();
        doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("mesh 0, primitive 0, attribute POSITION") && err.contains("accessor 99"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["meshes"][0]["primitives"][0]["indices"] = json!(-1);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("indices") && err.contains("accessor -1"),
            "{err}"
        );
    }

    /// Loads `doc` (embedded) and returns the error message; panics if it loads.
    fn load_err(doc: Value, bin: &[u8]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = write_embedded(dir.path(), doc, bin);
        let err = Scene::load(&path).expect_err("should fail").to_string();
        assert!(err.contains("scene.gltf"), "no file name in: {err}");
        err
    }

    #[test]
    fn truncated_json_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let path = write_embedded(dir.path(), doc, &bin);
        let text = std::fs::read(&path).unwrap();
        std::fs::write(&path, &text[..text.len() / 2]).unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("scene.gltf") && err.contains("invalid glTF"),
            "{err}"
        );
    }

    #[test]
    fn truncated_glb_and_bad_uris_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let path = write_glb(dir.path(), &doc, &bin);
        let bytes = std::fs::read(&path).unwrap();
        for cut in [bytes.len() - 8, bytes.len() / 2, 30, 10] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let err = Scene::load(&path).unwrap_err().to_string();
            assert!(err.contains("scene.glb"), "{err}");
        }
        let (mut doc, _) = test_doc();
        doc["buffers"][0]["uri"] = json!("%FF%FE.bin");
        let path = dir.path().join("bad uri.gltf");
        std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(err.contains("buffer 0") && err.contains("UTF-8"), "{err}");
    }

    #[test]
    fn missing_bin_names_the_buffer_file() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let path = write_external(dir.path(), doc, &bin);
        std::fs::remove_file(dir.path().join("scene data.bin")).unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("external.gltf") && err.contains("buffer 0"),
            "{err}"
        );
        assert!(err.contains("scene data.bin"), "{err}");
    }

    #[test]
    fn accessor_out_of_range_names_mesh_and_primitive() {
        let (mut doc, bin) = test_doc();
        doc["accessors"][0]["count"] = json!(400);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("mesh \"quad\" (0), primitive 0, POSITION") && err.contains("overrun"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["bufferViews"][0]["byteLength"] = json!(100_000);
        let err = load_err(doc, &bin);
        assert!(err.contains("bufferView 0"), "{err}");
        let (mut doc, bin) = test_doc();
        doc["accessors"][3]["componentType"] = json!(5126); // float indices
        let err = load_err(doc, &bin);
        assert!(err.contains("primitive 0, indices"), "{err}");
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
        assert_eq!(scene.triangles.len(), 2);
        assert_eq!(scene.warnings.len(), 1);
        assert!(
            scene.warnings[0].contains("mesh \"tri\" (1), primitive 0"),
            "{:?}",
            scene.warnings
        );
        assert!(scene.warnings[0].contains("Points"));
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

    #[test]
    fn road_materials_are_flagged_with_or_without_a_paper_model() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        assert!(scene.materials.iter().all(|m| !m.road));
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["road"] = json!(true);
        // A glTF metallic-roughness material may carry the flag alone.
        doc["materials"][1]["extras"] = json!({"streaks": {"road": true}});
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let asphalt = &scene.materials[0];
        assert!(asphalt.road);
        assert!(matches!(asphalt.reflectance, Reflectance::Paper { .. }));
        assert!(scene.materials[1].road);
        assert!(matches!(
            scene.materials[1].reflectance,
            Reflectance::GltfPbr(_)
        ));
        // Paper parameters without a model are an error that says what is missing.
        let (mut doc, bin) = test_doc();
        doc["materials"][1]["extras"] = json!({"streaks": {"road": true, "alpha": 0.1}});
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"glow\" (1)") && err.contains("needs \"bsdf\""),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["road"] = json!("yes");
        let err = load_err(doc, &bin);
        assert!(err.contains("extras.streaks"), "{err}");
    }

    #[test]
    fn bad_materials_and_cameras_are_named() {
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["bsdf"] = json!("phong");
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"asphalt\" (0)") && err.contains("phong"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["alpha"] = json!(-1);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"asphalt\" (0)") && err.contains("alpha"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["alpha_dry"] = json!(0.3);
        let err = load_err(doc, &bin);
        assert!(err.contains("metallicRoughnessTexture"), "{err}");
        let (mut doc, bin) = test_doc();
        doc["cameras"][0] = json!({"name": "ortho", "type": "orthographic",
            "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}});
        let err = load_err(doc, &bin);
        assert!(
            err.contains("camera \"ortho\"") && err.contains("orthographic"),
            "{err}"
        );
    }

    #[test]
    fn unsupported_inputs_are_errors() {
        let (mut doc, bin) = test_doc();
        doc["extensionsRequired"] = json!(["KHR_texture_basisu"]);
        doc["extensionsUsed"] = json!(["KHR_texture_basisu"]);
        let err = load_err(doc.clone(), &bin);
        assert!(
            err.contains("requires the glTF extension KHR_texture_basisu")
                && err.contains("export PNG or JPEG"),
            "{err}"
        );
        // The same file as a GLB.
        let dir = tempfile::tempdir().unwrap();
        let err = Scene::load(&write_glb(dir.path(), &doc, &bin)).unwrap_err();
        assert!(err.to_string().contains("KHR_texture_basisu"), "{err}");
        // Used but not required: a warning naming the material, and the scene loads.
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_sheen"]);
        doc["materials"][0]["extensions"] =
            json!({"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1]}});
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("material \"asphalt\" (0) uses KHR_materials_sheen")),
            "{:?}",
            scene.warnings
        );
        let err = Scene::load(Path::new("road.ply")).unwrap_err().to_string();
        assert!(
            err.contains("road.ply") && err.contains("unsupported"),
            "{err}"
        );
        let err = Scene::load(Path::new("/nonexistent/road.glb"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("road.glb"), "{err}");
    }

    /// TEXCOORD_1, COLOR_0 (normalized bytes), KHR_texture_transform with its texCoord
    /// override, a sampler, alphaMode MASK and an emissive texture sharing the image.
    #[test]
    fn second_uvs_vertex_colours_transforms_samplers_and_masks() {
        // 2x2 white PNG, alpha: top row opaque, transparent; bottom row the other way round.
        let texels = [255, 255, 255, 255, 255, 255, 255, 0]
            .into_iter()
            .chain([255, 255, 255, 0, 255, 255, 255, 255])
            .collect();
        let dir = png_file("leaf.png", 2, 2, texels);
        let mut d = Doc::default();
        // A unit quad in z = 0 facing +Z; uv1 = uv0 / 2; red opaque at y = 0, blue 0.2 at y = 1.
        let pos = d.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.], "VEC3", 3);
        let uv0 = d.floats(&[0., 0., 1., 0., 1., 1., 0., 1.], "VEC2", 2);
        let uv1 = d.floats(&[0., 0., 0.5, 0., 0.5, 0.5, 0., 0.5], "VEC2", 2);
        let colours = d.view(&[255, 0, 0, 255, 255, 0, 0, 255, 0, 0, 255, 51, 0, 0, 255, 51]);
        d.accessors
            .push(json!({"bufferView": colours, "componentType": 5121,
            "normalized": true, "count": 4, "type": "VEC4"}));
        let col = d.accessors.len() - 1;
        let idx = d.indices(&[0, 1, 2, 0, 2, 3]);
        // Behind it, an emissive triangle in z = -1 without uvs or colours.
        let tri = d.floats(&[0., 0., -1., 1., 0., -1., 0., 1., -1.], "VEC3", 3);
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_texture_transform"],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [
                {"attributes": {"POSITION": pos, "TEXCOORD_0": uv0, "TEXCOORD_1": uv1,
                    "COLOR_0": col}, "indices": idx, "material": 0},
                {"attributes": {"POSITION": tri}, "material": 1}]}],
            "materials": [
                {"name": "leaf", "alphaMode": "MASK", "pbrMetallicRoughness": {
                    "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                        {"offset": [0.25, 0], "texCoord": 1}}}}},
                {"name": "glow", "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 1}}
            ],
            "images": [{"uri": "leaf.png"}],
            "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}],
            "textures": [{"source": 0, "sampler": 0}, {"source": 0}],
            "buffers": [{"byteLength": d.bin.len()}],
            "bufferViews": d.views,
            "accessors": d.accessors
        });
        let scene = Scene::load(&write_embedded(dir.path(), doc, &d.bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        // One image for both textures (same colour space); the second uv set and the colours
        // are stored for every vertex, TEXCOORD_0 and white where a primitive has none.
        assert_eq!(scene.textures.len(), 1);
        assert_eq!(scene.uvs1.len(), 7);
        assert_eq!(scene.uvs1[2], Vec2::new(0.5, 0.5));
        assert_eq!(scene.uvs1[4..], scene.uvs[4..]);
        assert!((scene.colors[2] - Vec4::new(0.0, 0.0, 1.0, 0.2)).length() < 1e-6);
        assert_eq!(scene.colors[5], Vec4::ONE);
        let Reflectance::GltfPbr(GltfPbrParams {
            base_color_texture: Some(base),
            ..
        }) = scene.materials[0].reflectance
        else {
            panic!("no base colour texture")
        };
        assert_eq!(
            base,
            TextureRef {
                texture: 0,
                texcoord: 1,
                sampler: Sampler {
                    wrap_s: Wrap::ClampToEdge,
                    wrap_t: Wrap::MirroredRepeat,
                    filter: Filter::Nearest,
                },
                transform: Some(uv_transform(Vec2::new(0.25, 0.0), 0.0, Vec2::ONE)),
            }
        );
        let leaf = &scene.materials[0];
        assert_eq!(leaf.alpha.mode, AlphaMode::Mask { cutoff: 0.5 });
        // At x = 0.4 the transformed TEXCOORD_1 (0.45, 0.1) is in the opaque texel (TEXCOORD_0
        // would be in the transparent one); at x = 0.7 (0.6, 0.1) is in the transparent one,
        // so the ray goes on to the triangle behind.
        let down = |x: f32, y: f32| {
            scene
                .intersect(&crate::geometry::Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z))
                .unwrap()
        };
        let hit = down(0.4, 0.2);
        assert!((hit.t - 1.0).abs() < 1e-5 && hit.material == 0);
        assert!((hit.attributes.uv[1] - Vec2::new(0.2, 0.1)).length() < 1e-6);
        let c = hit.attributes.color;
        assert!((c - Vec4::new(0.8, 0.0, 0.2, 0.84)).length() < 1e-5, "{c}");
        let crate::bsdf::Bsdf::GltfPbr(b) = leaf.bsdf_at(&hit.attributes, &scene.textures) else {
            panic!("not pbr")
        };
        assert!((b.base_color - Vec3::new(0.8, 0.0, 0.2)).length() < 1e-5);
        let hit = down(0.7, 0.2);
        assert!((hit.t - 2.0).abs() < 1e-5 && hit.material == 1, "{hit:?}");
        // The emissive texture is read (white: the emission is the factor).
        assert!(scene.materials[1].emission_texture.is_some());
        assert!(approx(scene.emitted_radiance(&hit, Vec3::Z), Vec3::ONE));
    }

    #[test]
    fn wet_dry_material_reads_the_dryness_map() {
        // A 2x1 PNG: left texel G = 0 (wet), right texel G = 255 (dry).
        let dir = png_file("dry.png", 2, 1, vec![0, 0, 0, 255, 0, 255, 0, 255]);
        let (mut doc, bin) = test_doc();
        doc["images"] = json!([{"uri": "dry.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][0]["pbrMetallicRoughness"] =
            json!({"metallicRoughnessTexture": {"index": 0}});
        doc["materials"][0]["extras"]["streaks"]["alpha_dry"] = json!(0.45);
        doc["materials"][0]["extras"]["streaks"]["ks_dry"] = json!([0.1, 0.1, 0.1]);
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert_eq!(scene.textures.len(), 1);
        let m = &scene.materials[0];
        let crate::bsdf::Bsdf::Ggx(wet) = m.bsdf_at(
            &VertexAttributes::from_uv(Vec2::new(0.25, 0.5)),
            &scene.textures,
        ) else {
            panic!("not ggx")
        };
        let crate::bsdf::Bsdf::Ggx(dry) = m.bsdf_at(
            &VertexAttributes::from_uv(Vec2::new(0.75, 0.5)),
            &scene.textures,
        ) else {
            panic!("not ggx")
        };
        assert!((wet.alpha - 0.05).abs() < 1e-6 && (dry.alpha - 0.45).abs() < 1e-6);
        assert!((dry.ks.x - 0.1).abs() < 1e-6);
        // A missing image names the material, the image and the file.
        std::fs::remove_file(dir.path().join("dry.png")).unwrap();
        let err = Scene::load(&write_embedded(dir.path(), doc, &bin))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("material \"asphalt\" (0), image 0") && err.contains("dry.png"),
            "{err}"
        );
    }
    /// A 1x1 PNG of `rgb` as a data URI (a tiny embedded texture).
    fn png_uri(rgb: [u8; 3]) -> String {
        let png = png_bytes(1, 1, vec![rgb[0], rgb[1], rgb[2], 255]);
        format!("data:image/png;base64,{}", base64::encode(png))
    }

    /// A `width` x `height` PNG of the RGBA bytes `texels`.
    pub(super) fn png_bytes(width: u32, height: u32, texels: Vec<u8>) -> Vec<u8> {
        let mut png = Vec::new();
        image::RgbaImage::from_raw(width, height, texels)
            .unwrap()
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        png
    }

    /// A temporary folder holding that PNG as `name`.
    pub(super) fn png_file(
        name: &str,
        width: u32,
        height: u32,
        texels: Vec<u8>,
    ) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(name), png_bytes(width, height, texels)).unwrap();
        dir
    }

    /// The test document with a normal texture on the quad's material ("asphalt") that tilts
    /// the normal by `theta` toward +X of tangent space; the quad's tangent space is: tangent
    /// +X (u), bitangent -Z (up the image: glTF's v grows along +Z), normal +Y.
    fn normal_mapped_doc(theta: f32, scale: f32) -> (Value, Vec<u8>) {
        let (mut doc, bin) = test_doc();
        let texel = |x: f32| (255.0 * (x + 1.0) / 2.0).round() as u8;
        doc["images"] = json!([{"uri": png_uri([texel(theta.sin()), 128, texel(theta.cos())])}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][0]["normalTexture"] = json!({"index": 0, "scale": scale});
        (doc, bin)
    }

    fn load(doc: Value, bin: &[u8]) -> Scene {
        let dir = tempfile::tempdir().unwrap();
        Scene::load(&write_embedded(dir.path(), doc, bin)).unwrap()
    }

    /// The shading normal of a ray straight down onto the quad.
    fn quad_normal(scene: &Scene) -> Vec3 {
        let ray = crate::geometry::Ray::new(Vec3::new(21.0, 5.0, 0.5), -Vec3::Y);
        scene.intersect(&ray).unwrap().ns
    }

    #[test]
    fn normal_and_clearcoat_textures_read_their_texture_transform() {
        let (mut doc, bin) = normal_mapped_doc(0.4, 1.0);
        // glTF's own material model (the clear coat is one of its layers).
        doc["materials"][0]
            .as_object_mut()
            .unwrap()
            .remove("extras");
        doc["extensionsUsed"] = json!(["KHR_texture_transform", "KHR_materials_clearcoat"]);
        doc["materials"][0]["normalTexture"]["extensions"] =
            json!({"KHR_texture_transform": {"scale": [2, 2], "texCoord": 1}});
        doc["materials"][0]["extensions"] = json!({"KHR_materials_clearcoat": {
            "clearcoatFactor": 1,
            "clearcoatTexture": {"index": 0, "extensions":
                {"KHR_texture_transform": {"offset": [0.5, 0]}}}}});
        let scene = load(doc, &bin);
        let t = scene.materials[0].normal_map.unwrap().texture;
        assert_eq!(t.texcoord, 1);
        let m = t.transform.expect("a transform");
        assert!((m.transform_point2(Vec2::ONE) - Vec2::splat(2.0)).length() < 1e-6);
        let Reflectance::GltfPbr(GltfPbrParams {
            clearcoat_texture: Some(c),
            ..
        }) = scene.materials[0].reflectance
        else {
            panic!("no clearcoat texture")
        };
        let m = c.transform.expect("a transform");
        assert!((m.transform_point2(Vec2::ZERO) - Vec2::new(0.5, 0.0)).length() < 1e-6);
        // Tangents follow the normal map's texture space: a quarter turn of its uvs turns the
        // quad's generated tangents from +X to the Z axis.
        let (mut doc, bin) = normal_mapped_doc(0.4, 1.0);
        doc["materials"][0]["normalTexture"]["extensions"] =
            json!({"KHR_texture_transform": {"rotation": std::f32::consts::FRAC_PI_2}});
        let scene = load(doc, &bin);
        for t in &scene.tangents[..4] {
            assert!(t.x.abs() < 1e-4 && (t.z.abs() - 1.0).abs() < 1e-4, "{t}");
        }
        // A malformed transform names the material's normal texture.
        let (mut doc, bin) = normal_mapped_doc(0.4, 1.0);
        doc["materials"][0]["normalTexture"]["extensions"] =
            json!({"KHR_texture_transform": {"scale": "big"}});
        let err = load_err(doc, &bin);
        assert!(
            err.contains("normalTexture") && err.contains("KHR_texture_transform"),
            "{err}"
        );
    }

    #[test]
    fn normal_texture_without_tangent_gets_mikktspace_tangents() {
        // No normal map: no tangents stored at all.
        assert!(load(test_doc().0, &test_doc().1).tangents.is_empty());
        let theta = 0.4f32;
        let (doc, bin) = normal_mapped_doc(theta, 1.0);
        let scene = load(doc, &bin);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let m = scene.materials[0].normal_map.unwrap();
        assert_eq!((m.texture.texture, m.scale), (0, 1.0));
        // One tangent per vertex; the quad's are +X with w = +1, the unmapped triangle's zero.
        assert_eq!(scene.tangents.len(), scene.positions.len());
        for t in &scene.tangents[..4] {
            assert!((*t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5, "{t}");
        }
        assert!(scene.tangents[4..].iter().all(|t| *t == Vec4::ZERO));
        // The texel (8-bit) tilts the normal by theta toward the tangent.
        let ns = quad_normal(&scene);
        assert!((ns.dot(Vec3::Y).acos() - theta).abs() < 0.01, "{ns}");
        assert!(ns.x > 0.0 && ns.z.abs() < 0.01, "{ns}");
        // scale 0 flattens the map: (2c - 1) * (0, 0, 1).
        let (doc, bin) = normal_mapped_doc(theta, 0.0);
        assert!((quad_normal(&load(doc, &bin)) - Vec3::Y).length() < 1e-6);
    }

    /// Gives the quad a TANGENT attribute of `t` at every vertex.
    fn add_tangent(doc: &mut Value, bin: &mut Vec<u8>, t: [f32; 4]) {
        let offset = bin.len();
        bin.extend(t.repeat(4).iter().flat_map(|f| f.to_le_bytes()));
        let views = doc["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 64}));
        let view = views.len() - 1;
        let accessors = doc["accessors"].as_array_mut().unwrap();
        accessors.push(
            json!({"bufferView": view, "componentType": 5126, "count": 4,
            "type": "VEC4"}),
        );
        doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(accessors.len() - 1);
        doc["buffers"][0]["byteLength"] = json!(bin.len());
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
        let scene = load(doc.clone(), &bin);
        for t in &scene.tangents[..4] {
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
        let scene = load(doc, &bin);
        for t in &scene.tangents[..4] {
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
        let scene = load(doc.clone(), &bin);
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("TANGENT but no NORMAL")),
            "{:?}",
            scene.warnings
        );
        let t = scene.tangents[0];
        assert!((t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5, "{t}");
        assert!((quad_normal(&scene).dot(Vec3::Y).acos() - 0.3).abs() < 0.01);
        // Without TEXCOORD_0 there is nothing to map: a warning, and the plain normal.
        let attributes = &mut doc["meshes"][0]["primitives"][0]["attributes"];
        attributes.as_object_mut().unwrap().remove("TEXCOORD_0");
        attributes.as_object_mut().unwrap().remove("TANGENT");
        let scene = load(doc, &bin);
        assert!(
            scene.warnings.iter().any(|w| w.contains("no TEXCOORD_0")),
            "{:?}",
            scene.warnings
        );
        assert!((quad_normal(&scene) - Vec3::Y).length() < 1e-6);
    }
    /// A box of 24 vertices (flat normals, uvs, one TANGENT per face) with a normal-mapped
    /// material, and a quad in front of it whose COLOR_0 alpha runs from 0 to 1 along x under
    /// an alphaMode MASK material: the primitives of the mesh the instancing tests place.
    fn box_mesh(d: &mut Doc) -> Value {
        let faces = [
            (Vec3::X, Vec3::Z),
            (-Vec3::X, Vec3::Y),
            (Vec3::Y, Vec3::X),
            (-Vec3::Y, Vec3::Z),
            (Vec3::Z, Vec3::Y),
            (-Vec3::Z, Vec3::X),
        ];
        let (mut pos, mut nrm, mut uv, mut tan, mut idx) = (vec![], vec![], vec![], vec![], vec![]);
        for (f, (n, t)) in faces.into_iter().enumerate() {
            let b = n.cross(t);
            for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                pos.extend((0.5 * (n + x * t + y * b)).to_array());
                nrm.extend(n.to_array());
                uv.extend([(x + 1.0) / 2.0 + f as f32, (y + 1.0) / 2.0]);
                tan.extend(t.extend(1.0).to_array());
            }
            let o = 4 * f as u16;
            idx.extend([o, o + 1, o + 2, o, o + 2, o + 3]);
        }
        let pos = d.floats(&pos, "VEC3", 3);
        let nrm = d.floats(&nrm, "VEC3", 3);
        let uv = d.floats(&uv, "VEC2", 2);
        let tan = d.floats(&tan, "VEC4", 4);
        let idx = d.indices(&idx);
        let quad = d.floats(
            &[
                -0.5, -0.5, 0.8, 0.5, -0.5, 0.8, 0.5, 0.5, 0.8, -0.5, 0.5, 0.8,
            ],
            "VEC3",
            3,
        );
        let col = d.floats(
            &[[1., 1., 1., 0.], [1.; 4], [1.; 4], [1., 1., 1., 0.]].concat(),
            "VEC4",
            4,
        );
        let quad_idx = d.indices(&[0, 1, 2, 0, 2, 3]);
        json!([
            {"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv, "TANGENT": tan},
             "indices": idx, "material": 0},
            {"attributes": {"POSITION": quad, "COLOR_0": col}, "indices": quad_idx, "material": 1}
        ])
    }

    /// A document placing the box mesh ([`box_mesh`]) by `locals` (TRS node properties) under
    /// a rotated, translated parent: with `share`, every node references the one mesh;
    /// otherwise each has its own copy of it (the same primitives), so it is flattened.
    fn placed_boxes(locals: &[Value], share: bool) -> (Value, Vec<u8>) {
        let mut d = Doc::default();
        let prims = box_mesh(&mut d);
        let children: Vec<usize> = (1..=locals.len()).collect();
        let mut nodes = vec![boxes_parent(&children)];
        for (i, local) in locals.iter().enumerate() {
            let mut n = local.clone();
            n["mesh"] = json!(if share { 0 } else { i });
            nodes.push(n);
        }
        let copies = if share { 1 } else { locals.len() };
        boxes_doc(
            d,
            json!(nodes),
            json!(vec![json!({"name": "box", "primitives": prims}); copies]),
        )
    }

    /// The parent node of the placed boxes, rotated, translated and scaled.
    fn boxes_parent(children: &[usize]) -> Value {
        json!({"name": "parent", "translation": [0.5, 1, -2],
            "rotation": [0.2, 0.3, 0.1, 0.927], "scale": [1, 1.5, 1], "children": children})
    }

    /// The document of the box tests: scene 0 is node 0, the given nodes and meshes, the
    /// box's materials and normal texture, and `d`'s buffer.
    fn boxes_doc(d: Doc, nodes: Value, meshes: Value) -> (Value, Vec<u8>) {
        let doc = json!({
            "asset": {"version": "2.0"},
            "scenes": [{"nodes": [0]}],
            "nodes": nodes,
            "meshes": meshes,
            "materials": [
                {"name": "painted", "normalTexture": {"index": 0, "scale": 0.8}},
                {"name": "fence", "alphaMode": "MASK", "doubleSided": true}
            ],
            "images": [{"uri": png_uri([200, 100, 230])}],
            "textures": [{"source": 0}],
            "buffers": [{"byteLength": d.bin.len()}],
            "bufferViews": d.views,
            "accessors": d.accessors
        });
        (doc, d.bin)
    }

    /// Placements with rotations, non-uniform and negative (mirroring) scales.
    fn box_placements() -> Vec<Value> {
        vec![
            json!({}),
            json!({"translation": [2.5, 0, 0], "rotation": [0, 0.6, 0, 0.8]}),
            json!({"translation": [-2.5, 0.5, 0], "scale": [1, 2, 0.5]}),
            json!({"translation": [0, 2.5, 0.5], "scale": [-1, 1, 1],
                   "rotation": [0.28, 0, 0.96, 0]}),
            json!({"translation": [0, -2.5, 0], "scale": [1.5, -0.7, -1.2],
                   "rotation": [0.5, 0.5, 0.5, 0.5]}),
            json!({"matrix": [0.8, 0.3, 0, 0, -0.3, 1.2, 0.2, 0, 0.1, 0, -0.9, 0, 1, 1, 2, 1]}),
        ]
    }

    /// Casts `n` random rays at both scenes and checks that they agree: the same hit or miss
    /// (but for a few rays grazing an edge), with the same parameter, point, normals, uv,
    /// colour and material up to float rounding, and the same shadow-ray answer. Returns the
    /// number of hits.
    fn assert_same_hits(a: &Scene, b: &Scene, n: usize) -> usize {
        use crate::geometry::Ray;
        let mut rng = crate::sampling::Pcg32::new(5, 3);
        let mut v = |s: f32| {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 * s - Vec3::splat(s)
        };
        let (mut hits, mut mismatches) = (0, 0);
        for k in 0..n {
            let origin = v(9.0);
            let target = v(3.5) + Vec3::new(0.5, 1.0, -2.0);
            let mut ray = Ray::new(origin, (target - origin).normalize());
            if k % 3 == 0 {
                ray.t_max = (target - origin).length();
            }
            match (a.intersect(&ray), b.intersect(&ray)) {
                (None, None) => {}
                (Some(x), Some(y)) => {
                    hits += 1;
                    let close = |p: Vec3, q: Vec3, tol: f32| (p - q).length() <= tol;
                    assert!(
                        (x.t - y.t).abs() <= 1e-4 * x.t.max(1.0),
                        "ray {k}: {x:?} {y:?}"
                    );
                    assert!(close(x.p, y.p, 1e-4), "ray {k}: {x:?} {y:?}");
                    assert!(close(x.ng, y.ng, 1e-4), "ray {k}: {x:?} {y:?}");
                    assert!(close(x.ns, y.ns, 1e-3), "ray {k}: {x:?} {y:?}");
                    let [u, w] = [0, 1].map(|s| (x.attributes.uv[s] - y.attributes.uv[s]).length());
                    assert!(u < 1e-4 && w < 1e-4, "ray {k}: {x:?} {y:?}");
                    assert!((x.attributes.color - y.attributes.color).length() < 1e-4);
                    assert_eq!(
                        a.materials[x.material as usize].name,
                        b.materials[y.material as usize].name
                    );
                }
                _ => mismatches += 1,
            }
            if a.occluded(&ray) != b.occluded(&ray) {
                mismatches += 1;
            }
        }
        assert!(mismatches <= n / 500, "{mismatches} mismatches in {n} rays");
        hits
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
        let instanced = load(doc, &bin);
        let (doc, bin) = placed_boxes(&placements, false);
        let flat = load(doc, &bin);
        assert!(flat.instances.is_empty());
        assert_eq!(flat.triangles.len(), placements.len() * 14);
        assert!(instanced.triangles.is_empty() && instanced.positions.is_empty());
        assert_eq!(instanced.instances.meshes.len(), 1);
        assert_eq!(instanced.instances.instances.len(), placements.len());
        assert_eq!(instanced.instances.stored_triangle_count(), 14);
        assert_eq!(instanced.world_triangle_count(), flat.triangles.len());
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
            let s = load(doc, &bin);
            assert_eq!(s.world_triangle_count(), 14 * n);
            let m = &s.instances.meshes[0];
            (
                s.triangles.len(),
                m.parts.triangles.len(),
                m.parts.positions.len(),
                m.accel.memory_bytes(),
            )
        };
        assert_eq!(storage(2), storage(300));
        assert_eq!(storage(2).0, 0);
    }

    /// EXT_mesh_gpu_instancing, float and quantized: TRANSLATION as floats, ROTATION as
    /// normalized shorts, SCALE as normalized bytes, under a parent; the instances hit as
    /// nodes with the same (dequantized) transforms do. Mismatched counts are an error naming
    /// the node.
    #[test]
    fn ext_mesh_gpu_instancing_with_float_and_quantized_attributes() {
        let t = [
            [0.0f32, 0.0, 0.0],
            [2.5, 0.0, 0.0],
            [-1.0, 2.0, 0.5],
            [0.0, -2.0, 1.0],
        ];
        let q: [[i16; 4]; 4] = [
            [0, 0, 0, 32767],
            [0, 19660, 0, 26214],
            [9830, 0, 31457, 0],
            [16384, 16384, 16384, 16384],
        ];
        let s: [[i8; 3]; 4] = [
            [127, 127, 127],
            [64, 127, 100],
            [-127, 90, 127],
            [127, -80, -127],
        ];
        let mut d = Doc::default();
        let prims = box_mesh(&mut d);
        let translation = d.floats(&t.concat(), "VEC3", 3);
        let rot_bytes: Vec<u8> = q.concat().iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = d.view(&rot_bytes);
        d.accessors
            .push(json!({"bufferView": view, "componentType": 5122,
            "normalized": true, "count": 4, "type": "VEC4"}));
        let rotation = d.accessors.len() - 1;
        // Each element padded to 4 bytes, as the specification requires of strides.
        let scale_bytes: Vec<u8> = s
            .iter()
            .flat_map(|e| [e[0] as u8, e[1] as u8, e[2] as u8, 0])
            .collect();
        let view = d.view(&scale_bytes);
        d.views[view]["byteStride"] = json!(4);
        d.accessors
            .push(json!({"bufferView": view, "componentType": 5120,
            "normalized": true, "count": 4, "type": "VEC3"}));
        let scale = d.accessors.len() - 1;
        let nodes = json!([boxes_parent(&[1]), {"name": "trees", "mesh": 0, "extensions": {
            "EXT_mesh_gpu_instancing": {"attributes":
                {"TRANSLATION": translation, "ROTATION": rotation, "SCALE": scale}}}}]);
        let (mut doc, bin) = boxes_doc(d, nodes, json!([{"name": "box", "primitives": prims}]));
        let used = json!(["EXT_mesh_gpu_instancing", "KHR_mesh_quantization"]);
        doc["extensionsUsed"] = used.clone();
        doc["extensionsRequired"] = used;
        let instanced = load(doc.clone(), &bin);
        assert!(instanced.warnings.is_empty(), "{:?}", instanced.warnings);
        assert_eq!(instanced.instances.instances.len(), 4);
        assert!(instanced.triangles.is_empty());
        // The same placements as nodes, with the values dequantized by the specification's
        // rules (max(c / 32767, -1), max(c / 127, -1)).
        let locals: Vec<Value> = (0..4)
            .map(|i| {
                let r: Vec<f32> = q[i]
                    .iter()
                    .map(|&c| (c as f32 / 32767.0).max(-1.0))
                    .collect();
                let sc: Vec<f32> = s[i].iter().map(|&c| (c as f32 / 127.0).max(-1.0)).collect();
                json!({"translation": t[i], "rotation": r, "scale": sc})
            })
            .collect();
        let (nodes, flat_bin) = placed_boxes(&locals, false);
        let flat = load(nodes, &flat_bin);
        assert!(flat.instances.is_empty());
        let hits = assert_same_hits(&instanced, &flat, 4000);
        assert!(hits > 500, "{hits} hits");

        let mut bad = doc;
        bad["accessors"][translation]["count"] = json!(3);
        let err = load_err(bad, &bin);
        assert!(
            err.contains("node \"trees\" (1), EXT_mesh_gpu_instancing") && err.contains("counts"),
            "{err}"
        );
    }
}

#[cfg(test)]
mod material_extension_tests {
    //! KHR_materials_specular, KHR_materials_ior and KHR_materials_clearcoat: their parsing,
    //! their defaults, their textures' channels and colour spaces, and their errors.
    use super::tests::{png_file, test_doc, write_embedded};
    use crate::bsdf::Bsdf;
    use crate::material::{GltfPbrParams, Reflectance};
    use crate::scene::Scene;
    use glam::{Vec2, Vec3};
    use serde_json::json;

    #[test]
    fn plain_material_has_the_extensions_defaults() {
        let (doc, bin) = test_doc();
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let Reflectance::GltfPbr(g) = &scene.materials[1].reflectance else {
            panic!("glow is not a glTF material")
        };
        let defaults = GltfPbrParams {
            base_color: g.base_color,
            ..GltfPbrParams::default()
        };
        assert_eq!(*g, defaults);
    }

    #[test]
    fn specular_ior_and_clearcoat_are_read_with_their_textures() {
        // One texel: R 255, G 128, B 0, A 64.
        let dir = png_file("t.png", 1, 1, vec![255, 128, 0, 64]);
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!([
            "KHR_lights_punctual",
            "KHR_materials_emissive_strength",
            "KHR_materials_specular",
            "KHR_materials_ior",
            "KHR_materials_clearcoat"
        ]);
        doc["images"] = json!([{"uri": "t.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["extensions"]["KHR_materials_specular"] = json!({
            "specularFactor": 0.5, "specularTexture": {"index": 0},
            "specularColorFactor": [2, 1, 0.5], "specularColorTexture": {"index": 0}});
        doc["materials"][1]["extensions"]["KHR_materials_ior"] = json!({"ior": 1.33});
        doc["materials"][1]["extensions"]["KHR_materials_clearcoat"] = json!({
            "clearcoatFactor": 0.8, "clearcoatTexture": {"index": 0},
            "clearcoatRoughnessFactor": 0.2, "clearcoatRoughnessTexture": {"index": 0},
            "clearcoatNormalTexture": {"index": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        // Honoured: no "uses KHR_materials_..." warning; the coat's normal map is named.
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
        assert!(
            scene.warnings[0].contains("material \"glow\" (1)")
                && scene.warnings[0].contains("clearcoatNormalTexture is not used"),
            "{:?}",
            scene.warnings
        );
        // The image decoded twice: linear (specular, clearcoat) and sRGB (specular colour).
        assert_eq!(scene.textures.len(), 2);
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(
            &crate::geometry::VertexAttributes::from_uv(Vec2::ZERO),
            &scene.textures,
        ) else {
            panic!("not a glTF material")
        };
        let close = |a: f32, b: f32| (a - b).abs() < 1e-4;
        assert!(close(g.specular, 0.5 * 64.0 / 255.0), "{g:?}");
        // sRGB 128/255 is linear 0.2158.
        assert!(
            (g.specular_color - Vec3::new(2.0, 0.2158, 0.0))
                .abs()
                .max_element()
                < 1e-3,
            "{g:?}"
        );
        assert_eq!(g.ior, 1.33);
        assert!(close(g.clearcoat, 0.8), "{g:?}");
        assert!(close(g.clearcoat_roughness, 0.2 * 128.0 / 255.0), "{g:?}");
        // Defaults inside the extensions: an empty clear coat is no coat, an empty specular
        // is the default strength and colour; ior 0 is allowed.
        let mut d = doc.clone();
        d["materials"][1]["extensions"] = json!({
            "KHR_materials_specular": {}, "KHR_materials_clearcoat": {},
            "KHR_materials_ior": {"ior": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(
            &crate::geometry::VertexAttributes::from_uv(Vec2::ZERO),
            &scene.textures,
        ) else {
            panic!("not a glTF material")
        };
        assert_eq!((g.specular, g.specular_color, g.ior), (1.0, Vec3::ONE, 0.0));
        assert_eq!((g.clearcoat, g.clearcoat_roughness), (0.0, 0.0));
        // Out of range: errors naming the material and the extension.
        for (ext, value, what) in [
            ("KHR_materials_ior", json!({"ior": 0.5}), "ior 0.5"),
            (
                "KHR_materials_clearcoat",
                json!({"clearcoatFactor": 2}),
                "clearcoatFactor 2",
            ),
            (
                "KHR_materials_clearcoat",
                json!({"clearcoatTexture": {"index": 7}}),
                "texture 7",
            ),
            (
                "KHR_materials_specular",
                json!({"specularColorFactor": [1, -1, 1]}),
                "specularColorFactor",
            ),
        ] {
            let mut d = doc.clone();
            d["materials"][1]["extensions"] = json!({ ext: value });
            let err = Scene::load(&write_embedded(dir.path(), d, &bin))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("material \"glow\" (1)") && err.contains(what),
                "{ext}: {err}"
            );
        }
    }

    #[test]
    fn transmission_and_volume_are_read() {
        // One texel: R 128 (transmission x 0.502), linear.
        let dir = png_file("t.png", 1, 1, vec![128, 0, 0, 255]);
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!([
            "KHR_lights_punctual",
            "KHR_materials_emissive_strength",
            "KHR_materials_transmission",
            "KHR_materials_volume"
        ]);
        doc["images"] = json!([{"uri": "t.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["extensions"] = json!({
            "KHR_materials_transmission": {
                "transmissionFactor": 0.8, "transmissionTexture": {"index": 0}}});
        let at = crate::geometry::VertexAttributes::from_uv(Vec2::ZERO);
        // Thin-walled without KHR_materials_volume; no warning.
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(&at, &scene.textures) else {
            panic!("not a glTF material")
        };
        assert!((g.transmission - 0.8 * 128.0 / 255.0).abs() < 1e-4, "{g:?}");
        assert!(g.thin_walled && scene.materials[1].volume().is_none());
        // A volume: attenuation colour and distance give sigma_a; thicknessTexture warns.
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_volume"] = json!({
            "thicknessFactor": 0.02, "thicknessTexture": {"index": 0},
            "attenuationDistance": 0.5, "attenuationColor": [0.5, 1.0, 0.25]});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
        assert!(
            scene.warnings[0].contains("material \"glow\" (1)")
                && scene.warnings[0].contains("thicknessTexture is not used"),
            "{:?}",
            scene.warnings
        );
        let v = scene.materials[1].volume().expect("a volume");
        let want = Vec3::new(0.5f32.ln(), 0.0, 0.25f32.ln()) / -0.5;
        assert!((v.sigma_a - want).abs().max_element() < 1e-5, "{v:?}");
        assert!(
            (v.transmittance(0.5) - Vec3::new(0.5, 1.0, 0.25))
                .abs()
                .max_element()
                < 1e-5
        );
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(&at, &scene.textures) else {
            panic!("not a glTF material")
        };
        assert!(!g.thin_walled);
        // Thickness 0 is thin-walled, as the extension says; no attenuation by default.
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_volume"] = json!({});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        assert!(scene.materials[1].volume().is_none() && scene.warnings.is_empty());
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_volume"] = json!({"thicknessFactor": 1});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        assert_eq!(scene.materials[1].volume().unwrap().sigma_a, Vec3::ZERO);
        // Out of range: errors naming the material and the value.
        for (ext, value, what) in [
            (
                "KHR_materials_transmission",
                json!({"transmissionFactor": 1.5}),
                "transmissionFactor 1.5",
            ),
            (
                "KHR_materials_transmission",
                json!({"transmissionTexture": {"index": 9}}),
                "texture 9",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessFactor": -1}),
                "thicknessFactor -1",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessFactor": 1, "attenuationDistance": 0}),
                "attenuationDistance 0",
            ),
            (
                "KHR_materials_volume",
                json!({"attenuationColor": [2, 0, 0]}),
                "attenuationColor",
            ),
        ] {
            let mut d = doc.clone();
            d["materials"][1]["extensions"] = json!({ ext: value });
            let err = Scene::load(&write_embedded(dir.path(), d, &bin))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("material \"glow\" (1)") && err.contains(what),
                "{ext}: {err}"
            );
        }
    }
}

/// Values outside the specification, overflowing positions and exploding node graphs: each
/// an error naming the file and the element, found before the work it would cause.
#[cfg(test)]
mod hostile_tests {
    use super::tests::{test_doc, write_embedded};
    use super::*;
    use serde_json::{json, Value};
    use std::time::{Duration, Instant};

    /// The error loading `doc` (with buffer `bin`) gives, checked to name the file and to
    /// come within a second.
    fn error(doc: Value, bin: &[u8]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = write_embedded(dir.path(), doc, bin);
        let start = Instant::now();
        let err = Scene::load(&path).expect_err("should fail").to_string();
        assert!(
            start.elapsed() < Duration::from_secs(1),
            "{err}: {:?}",
            start.elapsed()
        );
        assert!(err.contains("scene.gltf"), "no file name in: {err}");
        err
    }

    #[test]
    fn a_file_without_buffers_loads() {
        // Lights only: no buffers, accessors or meshes, which the specification allows.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lights.gltf");
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5.0}]}},
            "nodes": [{"extensions": {"KHR_lights_punctual": {"light": 0}}}],
            "scenes": [{"nodes": [0]}]
        });
        std::fs::write(&path, doc.to_string()).unwrap();
        let scene = Scene::load(&path).unwrap();
        assert_eq!(scene.lights.len(), 1);
    }

    /// The test scene with `value` at the JSON pointer `pointer` (its parent must exist).
    fn with(pointer: &str, value: Value) -> (Value, Vec<u8>) {
        let (mut doc, bin) = test_doc();
        let (parent, key) = pointer.rsplit_once('/').unwrap();
        let parent = doc
            .pointer_mut(parent)
            .unwrap_or_else(|| panic!("{pointer}"));
        match key.parse::<usize>() {
            Ok(i) if parent.is_array() => parent[i] = value,
            _ => parent[key] = value,
        }
        (doc, bin)
    }

    /// Each `(pointer, value, words)`: the test scene with that value fails naming `words`.
    fn rejects(cases: &[(&str, Value, &[&str])]) {
        for (pointer, value, words) in cases {
            let (doc, bin) = with(pointer, value.clone());
            let err = error(doc, &bin);
            for w in *words {
                assert!(err.contains(w), "{pointer} = {value}: {w:?} not in: {err}");
            }
        }
    }

    const LIGHTS: &str = "/extensions/KHR_lights_punctual/lights";

    #[test]
    fn lights_outside_the_specification_are_named() {
        let point = &["light (0) on node \"bulb\" (4)"][..];
        let spot = &["light (1) on node \"spot\" (5)", "innerConeAngle"][..];
        rejects(&[
            (&format!("{LIGHTS}/0/color"), json!([-1, 1, 1]), point),
            (&format!("{LIGHTS}/0/color"), json!([1e39, 1, 1]), point),
            (&format!("{LIGHTS}/0/color"), json!([2, 1, 1]), point),
            (&format!("{LIGHTS}/0/intensity"), json!(-1), point),
            (&format!("{LIGHTS}/0/intensity"), json!(1e39), point),
            (&format!("{LIGHTS}/0/range"), json!(0), point),
            (&format!("{LIGHTS}/0/range"), json!(-5), point),
            (&format!("{LIGHTS}/0/range"), json!(1e39), point),
            (&format!("{LIGHTS}/1/spot/innerConeAngle"), json!(0.6), spot),
            (
                &format!("{LIGHTS}/1/spot/innerConeAngle"),
                json!(-0.1),
                spot,
            ),
            (&format!("{LIGHTS}/1/spot/outerConeAngle"), json!(2.0), spot),
            (
                &format!("{LIGHTS}/1/spot/outerConeAngle"),
                json!(1e39),
                spot,
            ),
        ]);
        // The edges of the ranges load: inner = outer (the project's hard edge), outer =
        // pi/2, intensity 0.
        let dir = tempfile::tempdir().unwrap();
        let (mut doc, bin) = test_doc();
        doc["extensions"]["KHR_lights_punctual"]["lights"][1]["spot"] =
            json!({"innerConeAngle": 0.5, "outerConeAngle": 0.5});
        doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = json!(0);
        Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let (mut doc, bin) = test_doc();
        doc["extensions"]["KHR_lights_punctual"]["lights"][1]["spot"] =
            json!({"innerConeAngle": 0, "outerConeAngle": std::f64::consts::FRAC_PI_2});
        Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
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
    fn materials_outside_the_specification_are_named() {
        let asphalt = &["material \"asphalt\" (0)"][..];
        let glow = &["material \"glow\" (1)"][..];
        rejects(&[
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"baseColorFactor": [-0.5, 0.5, 0.5, 1]}),
                &["material \"asphalt\" (0)", "baseColorFactor"],
            ),
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"baseColorFactor": [1e39, 0.5, 0.5, 1]}),
                asphalt,
            ),
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"metallicFactor": 1.5}),
                asphalt,
            ),
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"roughnessFactor": -0.1}),
                asphalt,
            ),
            ("/materials/0/alphaCutoff", json!(-1), asphalt),
            ("/materials/1/emissiveFactor", json!([-1, 0, 0]), glow),
            ("/materials/1/emissiveFactor", json!([2, 0, 0]), glow),
            ("/materials/1/emissiveFactor", json!([1e39, 0, 0]), glow),
            (
                "/materials/1/extensions/KHR_materials_emissive_strength/emissiveStrength",
                json!(-5),
                &["material \"glow\" (1)", "emissiveStrength"],
            ),
            (
                "/materials/1/extensions/KHR_materials_emissive_strength/emissiveStrength",
                json!(1e39),
                glow,
            ),
            ("/materials/0/extras/streaks/kd", json!([-1, 0, 0]), asphalt),
            (
                "/materials/0/extras/streaks/ks",
                json!([1e39, 0, 0]),
                asphalt,
            ),
            ("/materials/0/extras/streaks/alpha", json!(1e39), asphalt),
        ]);
        // A negative strength is an error even where the factor is black.
        let (mut doc, bin) = test_doc();
        doc["materials"][1]["emissiveFactor"] = json!([0, 0, 0]);
        doc["materials"][1]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] =
            json!(-1);
        let err = error(doc, &bin);
        assert!(err.contains("material \"glow\" (1)"), "{err}");
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

    /// A chain of `depth` nodes, each listing the next twice, above a node placing mesh
    /// `mesh`: 2^depth placements of it.
    fn doubling_dag(doc: &mut Value, depth: usize, mesh: usize) {
        let base = doc["nodes"].as_array().unwrap().len();
        let nodes = doc["nodes"].as_array_mut().unwrap();
        for i in 0..depth {
            nodes.push(json!({"name": format!("d{i}"), "children": [base + i + 1, base + i + 1]}));
        }
        nodes.push(json!({"name": "leaf", "mesh": mesh}));
        doc["scenes"][0]["nodes"] = json!([base]);
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
        assert_eq!(scene.triangles.len(), 2 + n - 2);
    }
}
