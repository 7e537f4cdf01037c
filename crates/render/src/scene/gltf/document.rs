//! The glTF loader's entry: the GLB header and the references the gltf crate would follow
//! unchecked, then [`load`], which reads the buffers, decodes compressed geometry, reads the
//! materials, walks the nodes and places the meshes.

use super::buffers::{check_views, load_buffers};
use super::extensions::{self, light_units};
use super::nodes::count_visits;
use super::{compression, node_label, Loader};
use crate::scene::files::Files;
use crate::scene::{ObjectTable, Scene, SceneError, SceneObject, SceneParts};
use glam::{Mat4, Vec4};
use std::collections::HashMap;
use std::path::Path;

/// Size of a GLB file's header: magic, version and total length, 4 bytes each.
pub(super) const GLB_HEADER_SIZE: usize = 12;

/// Checks the GLB header's total length before the gltf crate reads the chunks, which
/// subtracts the header size from it unchecked (an overflow panic for a length below 12).
pub(super) fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
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
pub(super) fn check_references(path: &Path, raw: &serde_json::Value) -> Result<(), SceneError> {
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
pub(in crate::scene) fn load(path: &Path, files: &Files) -> Result<Scene, SceneError> {
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
    let mut warnings = super::warnings::Warnings::default();
    extensions::check(path, &raw, &mut warnings)?;
    super::textures::basisu_sources(&mut raw);
    let light_units = light_units(path, &raw)?;
    // The extensions the loader honours or renders without have been checked; the gltf
    // crate's validation would reject the required ones it does not implement itself.
    if let Some(serde_json::Value::Array(required)) = raw.get_mut("extensionsRequired") {
        required.retain(|e| {
            !e.as_str().is_some_and(|e| {
                extensions::HONOURED.contains(&e) || extensions::RENDERED_WITHOUT.contains(&e)
            })
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
        objects: ObjectTable::default(),
        primitive_boxes: Vec::new(),
        warnings,
        node_worlds: vec![None; document.nodes().len()],
    };
    for animation in document.animations() {
        let label = match animation.name() {
            Some(n) => format!("animation {n:?} ({})", animation.index()),
            None => format!("animation {}", animation.index()),
        };
        let without = "not played: the nodes' rest pose is rendered";
        loader.warn("animations", "animation", &label, without);
    }
    for (i, m) in document.materials().enumerate() {
        let material = loader.material(&m, i, &document)?;
        loader.parts.materials.push(material);
    }
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    let mut rain = None;
    match scene {
        Some(scene) => {
            loader.parts.environment = loader.environment(&scene)?;
            rain = loader.rain(&scene)?;
            loader.parts.fog = loader.fog(&scene)?;
            // Nodes reached by several paths (a DAG) are visited once per path, which may be
            // exponentially many: they are counted first.
            count_visits(path, &document, &scene)?;
            // Depth-first in file order with an explicit stack; a depth beyond the node count
            // can only come from a cycle.
            let node_count = document.nodes().len();
            // Each entry carries its parent's world transform and tag.
            let mut stack: Vec<(gltf::Node, Mat4, usize, SceneObject)> = scene
                .nodes()
                .map(|n| (n, Mat4::IDENTITY, 0, SceneObject::UNLABELLED))
                .collect();
            stack.reverse();
            while let Some((node, parent, depth, parent_tag)) = stack.pop() {
                if depth > node_count {
                    return Err(SceneError::invalid(
                        path,
                        node_label(&node),
                        "the node hierarchy has a cycle",
                    ));
                }
                let tag = loader.node_tag(&node, parent_tag)?;
                let object = loader.objects.slot(tag);
                let world = loader.node(&node, parent, object, &document)?;
                let first_child = stack.len();
                stack.extend(node.children().map(|c| (c, world, depth + 1, tag)));
                stack[first_child..].reverse();
            }
        }
        None => loader.warnings.note("the file has no scene".into()),
    }
    loader.place_meshes(&document)?;
    if !loader.parts.mesh.tangents.is_empty() {
        let n = loader.parts.mesh.positions.len();
        loader.parts.mesh.tangents.resize(n, Vec4::ZERO);
    }
    let lines = loader.warnings.lines(path);
    loader.parts.warnings.extend(lines);
    let boxes = std::mem::take(&mut loader.primitive_boxes);
    loader.parts.objects = std::mem::take(&mut loader.objects).into_objects();
    let mut scene = Scene::from_parts(loader.parts)?;
    scene.framing_bounds = crate::camera::union_bounds(boxes);
    if let Some(rain) = rain {
        scene.set_rain(rain);
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{
        add_accessor, add_vec3s, check_test_scene, load_err, test_doc, write_embedded,
        write_external, write_glb,
    };
    use super::*;

    use crate::scene::Scene;

    use serde_json::json;

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
        doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_anisotropy"]);
        doc["materials"][0]["extensions"] =
            json!({"KHR_materials_anisotropy": {"anisotropyStrength": 1}});
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        assert!(
            scene.warnings.iter().any(|w| w.contains(
                "KHR_materials_anisotropy on 1 material: rendered as an isotropic surface \
                 (material \"asphalt\" (0))"
            )),
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

    /// What the loader leaves out without a word otherwise: an occlusion texture and
    /// animations are each named once for the file, with the elements counted.
    #[test]
    fn occlusion_and_animations_warn_once() {
        let (mut doc, mut bin) = test_doc();
        doc["images"] = json!([{"uri": super::super::test_docs::png_uri([255, 255, 255])}]);
        doc["textures"] = json!([{"source": 0}]);
        let mut glow2 = doc["materials"][1].clone();
        glow2["name"] = json!("glow2");
        doc["materials"].as_array_mut().unwrap().push(glow2);
        for m in [1, 2] {
            doc["materials"][m]["occlusionTexture"] = json!({"index": 0, "strength": 0.5});
        }
        // Two animations of the lamp's translation (keyframe times 0 and 1).
        let times: Vec<u8> = [0f32, 1.].iter().flat_map(|f| f.to_le_bytes()).collect();
        let input = add_accessor(&mut doc, &mut bin, &times, (5126, 2, "SCALAR"));
        doc["accessors"][input]["min"] = json!([0]);
        doc["accessors"][input]["max"] = json!([1]);
        let output = add_vec3s(&mut doc, &mut bin, &[0., 0., 0., 1., 0., 0.]);
        let animation = json!({"channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}}],
            "samplers": [{"input": input, "output": output}]});
        let mut named = animation.clone();
        named["name"] = json!("sway");
        doc["animations"] = json!([animation, named]);
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let w = &scene.warnings;
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].ends_with(
                "animations on 2 animations: not played: the nodes' rest pose is rendered \
                 (animation 0; animation \"sway\" (1))"
            ),
            "{w:?}"
        );
        assert!(
            w[1].ends_with(
                "occlusionTexture on 2 materials: ignored: the path tracer computes occlusion \
                 itself (material \"glow\" (1); material \"glow2\" (2))"
            ),
            "{w:?}"
        );
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
}
