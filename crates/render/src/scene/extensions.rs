//! Which glTF extensions the loader honours, and what happens to the others: nothing in a file
//! is dropped silently.
//!
//! - An extension in `extensionsRequired` that the loader does not honour is an error
//!   ([`SceneError::UnsupportedExtension`]) that names it and, for the ones street assets and
//!   Blender's exporter use, says what to do instead.
//! - An extension in `extensionsUsed` that the loader does not honour is a warning for every
//!   material, node, mesh, texture or other element that uses it, naming the element and
//!   saying how it is rendered without it.
//!
//! The check reads the file's JSON as it is (the `gltf` crate keeps only the extensions it
//! knows), before the document is validated.

use super::SceneError;
use serde_json::Value;
use std::path::Path;

/// The extensions the loader honours.
pub const HONOURED: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_draco_mesh_compression",
    "KHR_materials_specular",
    "KHR_materials_ior",
    "KHR_materials_clearcoat",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "EXT_mesh_gpu_instancing",
];

/// How an element that uses `extension` is rendered when the extension is not honoured.
fn without(extension: &str) -> &'static str {
    match extension {
        "KHR_materials_sheen" => "rendered without sheen",
        "KHR_materials_iridescence" => "rendered without iridescence",
        "KHR_materials_anisotropy" => "rendered as an isotropic surface",
        "KHR_materials_dispersion" => "rendered without dispersion",
        "KHR_materials_unlit" => "shaded as a lit surface, not as unlit",
        "KHR_materials_pbrSpecularGlossiness" => {
            "its specular-glossiness parameters are ignored (metallic-roughness defaults)"
        }
        "KHR_texture_basisu" | "EXT_texture_webp" | "EXT_texture_avif" | "MSFT_texture_dds" => {
            "its textures in that format are not decoded"
        }
        "KHR_materials_variants" => "rendered with its default material",
        "KHR_animation_pointer" => "rendered at rest, without animation",
        _ => "the extension is ignored",
    }
}

/// What to do about a required extension the loader does not honour.
fn advice(extension: &str) -> &'static str {
    match extension {
        "KHR_texture_basisu" | "EXT_texture_webp" | "EXT_texture_avif" => {
            "textures in that format are not decoded; export PNG or JPEG textures"
        }
        _ => "the file cannot be rendered correctly without it",
    }
}

/// A label for element `index` of the top-level array `array` (`"materials"`, ...).
fn label(array: &str, index: usize, element: &Value) -> String {
    let kind = match array {
        "materials" => "material",
        "meshes" => "mesh",
        "nodes" => "node",
        "textures" => "texture",
        "images" => "image",
        "samplers" => "sampler",
        "cameras" => "camera",
        "scenes" => "scene",
        "skins" => "skin",
        "animations" => "animation",
        "accessors" => "accessor",
        "bufferViews" => "buffer view",
        "buffers" => "buffer",
        other => other,
    };
    match element.get("name").and_then(Value::as_str) {
        Some(name) => format!("{kind} {name:?} ({index})"),
        None => format!("{kind} {index}"),
    }
}

/// Whether `value` (an element or anything inside it) has `"extensions": {extension: ...}`.
fn uses(value: &Value, extension: &str) -> bool {
    match value {
        Value::Object(map) => {
            map.get("extensions")
                .and_then(Value::as_object)
                .is_some_and(|e| e.contains_key(extension))
                || map.values().any(|v| uses(v, extension))
        }
        Value::Array(items) => items.iter().any(|v| uses(v, extension)),
        _ => false,
    }
}

/// The elements of the document that use `extension`, labelled for messages; the root itself
/// when only it does.
fn users(json: &Value, extension: &str) -> Vec<String> {
    let mut found = Vec::new();
    if let Some(root) = json.as_object() {
        for (array, items) in root {
            let Some(items) = items.as_array() else {
                continue;
            };
            for (i, item) in items.iter().enumerate() {
                if uses(item, extension) {
                    found.push(label(array, i, item));
                }
            }
        }
        let at_root = root
            .get("extensions")
            .and_then(Value::as_object)
            .is_some_and(|e| e.contains_key(extension));
        if at_root && found.is_empty() {
            found.push("the file".into());
        }
    }
    found
}

/// The string list `json[key]` (`extensionsUsed`, `extensionsRequired`).
fn names<'a>(json: &'a Value, key: &str) -> impl Iterator<Item = &'a str> {
    json.get(key)
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(Value::as_str)
}

/// Checks the file's extensions (see the module documentation): an error for the first
/// required one that is not honoured, else the warnings for the used ones that are not.
pub fn check(path: &Path, json: &Value) -> Result<Vec<String>, SceneError> {
    if let Some(extension) = names(json, "extensionsRequired").find(|e| !HONOURED.contains(e)) {
        return Err(SceneError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: extension.to_owned(),
            advice: advice(extension).to_owned(),
        });
    }
    let mut warnings = Vec::new();
    for extension in names(json, "extensionsUsed").filter(|e| !HONOURED.contains(e)) {
        let users = users(json, extension);
        if users.is_empty() {
            warnings.push(format!(
                "{extension} is listed in extensionsUsed but nothing uses it"
            ));
        }
        for user in users {
            warnings.push(format!(
                "{user} uses {extension}, which is not supported: {}",
                without(extension)
            ));
        }
    }
    Ok(warnings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn required_and_unsupported_is_an_error_naming_the_extension() {
        let doc = json!({"extensionsRequired": ["KHR_lights_punctual", "KHR_texture_basisu"],
                         "extensionsUsed": ["KHR_lights_punctual", "KHR_texture_basisu"]});
        let err = check(Path::new("car.glb"), &doc).unwrap_err().to_string();
        assert!(
            err.contains("car.glb")
                && err.contains("KHR_texture_basisu")
                && err.contains("export PNG or JPEG"),
            "{err}"
        );
        let ok = json!({"extensionsRequired": ["KHR_lights_punctual"]});
        assert!(check(Path::new("a.gltf"), &ok).unwrap().is_empty());
    }

    #[test]
    fn used_and_unsupported_warns_for_every_user_by_name() {
        let doc = json!({
            "extensionsUsed": ["KHR_materials_iridescence", "KHR_materials_sheen",
                               "KHR_materials_emissive_strength", "EXT_unknown"],
            "materials": [
                {"name": "glass", "extensions": {"KHR_materials_iridescence": {"iridescenceFactor": 1}}},
                {"name": "road", "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1]}}},
                {"extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}}
            ]
        });
        let w = check(Path::new("street.gltf"), &doc).unwrap();
        assert_eq!(w.len(), 3, "{w:?}");
        assert!(
            w[0].contains("material \"glass\" (0) uses KHR_materials_iridescence"),
            "{w:?}"
        );
        assert!(w[0].contains("without iridescence"), "{w:?}");
        assert!(
            w[1].contains("material \"road\" (1) uses KHR_materials_sheen"),
            "{w:?}"
        );
        assert!(
            w[2].contains("EXT_unknown") && w[2].contains("nothing uses it"),
            "{w:?}"
        );
    }

    #[test]
    fn labels_name_the_element_kind() {
        let doc = json!({"extensionsUsed": ["EXT_node_thing"],
            "nodes": [{"mesh": 0}, {"name": "trees", "extensions": {"EXT_node_thing": {}}}]});
        let w = check(Path::new("s.gltf"), &doc).unwrap();
        assert_eq!(w.len(), 1);
        assert!(
            w[0].starts_with("node \"trees\" (1) uses EXT_node_thing"),
            "{w:?}"
        );
        assert!(w[0].contains("ignored"), "{w:?}");
        let root = json!({"extensionsUsed": ["KHR_x"], "extensions": {"KHR_x": {}}});
        assert!(check(Path::new("s.gltf"), &root).unwrap()[0].starts_with("the file uses"));
        let mesh = json!({"extensionsUsed": ["KHR_x"], "meshes": [{"primitives": [{"extensions": {"KHR_x": {}}}]}]});
        assert!(check(Path::new("s.gltf"), &mesh).unwrap()[0].starts_with("mesh 0 uses"));
    }
}
