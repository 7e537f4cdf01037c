//! Which glTF extensions the loader honours, and what happens to the others: nothing in a file
//! is dropped silently.
//!
//! - An extension in `extensionsRequired` that the loader does not honour is an error
//!   ([`SceneError::UnsupportedExtension`]) that names it and, for the ones street assets and
//!   Blender's exporter use, says what to do instead; except the ones in [`RENDERED_WITHOUT`]
//!   (shading only), which are warnings as used ones are.
//! - An extension in `extensionsUsed` that the loader does not honour is one warning per file,
//!   saying how it is rendered without it, how many materials, nodes, meshes, textures or
//!   other elements use it and naming the first of them.
//!
//! The check reads the file's JSON as it is (the `gltf` crate keeps only the extensions it
//! knows), before the document is validated.

use super::warnings::Warnings;
use super::{accessors, node_label, Loader};
use crate::light::{Light, LUMINOUS_EFFICACY};
use crate::scene::{validate, SceneError};
use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;
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
    "KHR_materials_sheen",
    "KHR_materials_iridescence",
    "KHR_materials_clearcoat",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "EXT_mesh_gpu_instancing",
    "KHR_materials_unlit",
];

/// How an element that uses `extension` is rendered when the extension is not honoured.
fn without(extension: &str) -> &'static str {
    match extension {
        "KHR_materials_anisotropy" => "rendered as an isotropic surface",
        "KHR_materials_dispersion" => "rendered without dispersion",
        "KHR_materials_pbrSpecularGlossiness" => {
            "its specular-glossiness parameters are ignored (metallic-roughness defaults)"
        }
        "KHR_texture_basisu" => {
            "the KTX2 images are not decoded: each texture's fallback image (its core source) \
             is read, and a texture without one is left out"
        }
        "EXT_texture_webp" | "EXT_texture_avif" | "MSFT_texture_dds" => {
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

/// The kind (`material`) and the label for messages of element `index` of the top-level
/// array `array` (`"materials"`, ...).
fn label(array: &str, index: usize, element: &Value) -> (&'static str, String) {
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
        _ => "element",
    };
    let noun = if kind == "element" { array } else { kind };
    let label = match element.get("name").and_then(Value::as_str) {
        Some(name) => format!("{noun} {name:?} ({index})"),
        None => format!("{noun} {index}"),
    };
    (kind, label)
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

/// The elements of the document that use `extension`, as kinds and labels for messages; the
/// root itself when only it does.
fn users(json: &Value, extension: &str) -> Vec<(&'static str, String)> {
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
            found.push(("file", "the file".into()));
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

/// The extensions that change only how surfaces are shaded, or what of a file is shown
/// (variants, animation), and that the renderer can leave out and still show the model: a file
/// that *requires* one of them loads, with the warning of a used one, which says that the file
/// requires it. The glTF specification says a client must not load such a file; users asked
/// to see the model (docs/decisions/0025 has the reasons). Extensions that geometry or images
/// need are not here: without them there is nothing right to show.
pub const RENDERED_WITHOUT: &[&str] = &[
    "KHR_materials_anisotropy",
    "KHR_materials_dispersion",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_variants",
    "KHR_animation_pointer",
];

/// Checks the file's extensions (see the module documentation): an error for the first
/// required one that is neither honoured nor in [`RENDERED_WITHOUT`]; a warning in `warnings`
/// for each used one that is not honoured, counting the elements that use it.
pub(super) fn check(path: &Path, json: &Value, warnings: &mut Warnings) -> Result<(), SceneError> {
    let required: Vec<&str> = names(json, "extensionsRequired").collect();
    if let Some(extension) = required
        .iter()
        .find(|e| !HONOURED.contains(e) && !RENDERED_WITHOUT.contains(e))
    {
        return Err(SceneError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: (*extension).to_owned(),
            advice: advice(extension).to_owned(),
        });
    }
    let used = names(json, "extensionsUsed").chain(required.iter().copied());
    let mut seen: Vec<&str> = Vec::new();
    for extension in used.filter(|e| !HONOURED.contains(e)) {
        if seen.contains(&extension) {
            continue;
        }
        seen.push(extension);
        let what = if required.contains(&extension) {
            format!("{extension} (required by the file, which is loaded without it)")
        } else {
            extension.to_owned()
        };
        let users = users(json, extension);
        // KTX2 images named by a texture's core source use KHR_texture_basisu without its
        // object; the image loader names them (see textures.rs).
        if users.is_empty() && extension != "KHR_texture_basisu" {
            warnings.note(format!(
                "{extension} is listed in extensionsUsed but nothing uses it"
            ));
        }
        for (kind, user) in users {
            warnings.add(&what, kind, &user, without(extension));
        }
    }
    Ok(())
}

/// The units of a file's KHR_lights_punctual intensities: the specification's photometric ones
/// (candela for point and spot lights, lux for directional lights), or, where the file says so
/// with `asset.extras.streaks.light_units: "radiometric"`, W/sr and W/m^2 as they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum LightUnits {
    Photometric,
    Radiometric,
}

/// `asset.extras.streaks` (see the `scene` module documentation).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AssetExtras {
    light_units: LightUnits,
}

/// The light units `asset.extras.streaks.light_units` of the file's JSON chooses (photometric
/// when absent).
pub(super) fn light_units(path: &Path, json: &serde_json::Value) -> Result<LightUnits, SceneError> {
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
    /// The local transforms `T * R * S` of the instances of `node`'s EXT_mesh_gpu_instancing
    /// `ext` (its TRANSLATION, ROTATION and SCALE accessors, each optional, of one count;
    /// quantized as KHR_mesh_quantization allows).
    pub(super) fn gpu_instances(
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
                    self.attribute::<3>(&a, &element, name, accessors::POSITION, None)
                        .map(|v| v.into_iter().map(Vec3::from).collect())
                })
                .transpose()
        };
        let translation = read3("TRANSLATION")?;
        let scale = read3("SCALE")?;
        let rotation: Option<Vec<Quat>> = accessor("ROTATION")?
            .map(|a| {
                self.attribute::<4>(&a, &element, "ROTATION", accessors::DIRECTION, None)
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

    pub(super) fn light(
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn required_and_unsupported_is_an_error_naming_the_extension() {
        let doc = json!({"extensionsRequired": ["KHR_lights_punctual", "KHR_texture_basisu"],
                         "extensionsUsed": ["KHR_lights_punctual", "KHR_texture_basisu"]});
        let err = lines("car.glb", &doc).unwrap_err().to_string();
        assert!(
            err.contains("car.glb")
                && err.contains("KHR_texture_basisu")
                && err.contains("export PNG or JPEG"),
            "{err}"
        );
        let ok = json!({"extensionsRequired": ["KHR_lights_punctual"]});
        assert!(lines("a.gltf", &ok).unwrap().is_empty());
    }

    /// The warnings `check` gives for `doc` read from `path`.
    fn lines(path: &str, doc: &Value) -> Result<Vec<String>, SceneError> {
        let mut warnings = Warnings::default();
        check(Path::new(path), doc, &mut warnings)?;
        Ok(warnings.lines(Path::new(path)))
    }

    #[test]
    fn used_and_unsupported_warns_once_counting_the_users() {
        let doc = json!({
            "extensionsUsed": ["KHR_materials_dispersion", "KHR_materials_anisotropy",
                               "KHR_materials_emissive_strength", "EXT_unknown"],
            "materials": [
                {"name": "glass", "extensions": {"KHR_materials_dispersion": {"dispersion": 1}}},
                {"name": "road", "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 1}}},
                {"extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}},
                {"extensions": {"KHR_materials_dispersion": {}}},
                {"extensions": {"KHR_materials_dispersion": {}}},
                {"extensions": {"KHR_materials_dispersion": {}}}
            ]
        });
        let w = lines("street.gltf", &doc).unwrap();
        assert_eq!(
            w,
            [
                "street.gltf: EXT_unknown is listed in extensionsUsed but nothing uses it",
                "street.gltf: KHR_materials_dispersion on 4 materials: rendered without \
                 dispersion (material \"glass\" (0); material 3; material 4 and 1 more)",
                "street.gltf: KHR_materials_anisotropy on 1 material: rendered as an \
                 isotropic surface (material \"road\" (1))",
            ]
        );
    }

    /// A required extension that changes only the shading loads with the warning a used one
    /// gets, saying the file requires it; one the images need is still an error.
    #[test]
    fn required_shading_extensions_are_warnings() {
        let doc = json!({
            "extensionsUsed": ["KHR_materials_dispersion"],
            "extensionsRequired": ["KHR_materials_anisotropy"],
            "materials": [
                {"extensions": {"KHR_materials_anisotropy": {}}},
                {"extensions": {"KHR_materials_anisotropy": {}}}
            ]
        });
        let w = lines("s.gltf", &doc).unwrap();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].contains("KHR_materials_dispersion is listed"), "{w:?}");
        assert!(
            w[1].starts_with(
                "s.gltf: KHR_materials_anisotropy (required by the file, which is loaded \
                 without it) on 2 materials: rendered as an isotropic surface"
            ),
            "{w:?}"
        );
        let doc = json!({"extensionsRequired": ["KHR_materials_sheen", "EXT_texture_webp"]});
        let err = lines("s.gltf", &doc).unwrap_err().to_string();
        assert!(err.contains("EXT_texture_webp"), "{err}");
    }

    #[test]
    fn labels_name_the_element_kind() {
        let doc = json!({"extensionsUsed": ["EXT_node_thing"],
            "nodes": [{"mesh": 0}, {"name": "trees", "extensions": {"EXT_node_thing": {}}}]});
        let w = lines("s.gltf", &doc).unwrap();
        assert_eq!(
            w,
            ["s.gltf: EXT_node_thing on 1 node: the extension is ignored (node \"trees\" (1))"]
        );
        let root = json!({"extensionsUsed": ["KHR_x"], "extensions": {"KHR_x": {}}});
        assert!(lines("s.gltf", &root).unwrap()[0]
            .contains("KHR_x on 1 file: the extension is ignored (the file)"));
        let mesh = json!({"extensionsUsed": ["KHR_x"], "meshes": [{"primitives": [{"extensions": {"KHR_x": {}}}]}]});
        assert!(lines("s.gltf", &mesh).unwrap()[0].ends_with("(mesh 0)"));
        let other = json!({"extensionsUsed": ["KHR_x"], "things": [{"extensions": {"KHR_x": {}}}]});
        assert!(lines("s.gltf", &other).unwrap()[0]
            .contains("on 1 element: the extension is ignored (things 0)"));
    }
}

#[cfg(test)]
mod lights_and_instancing_tests {
    use super::super::test_docs::{
        assert_same_hits, box_mesh, boxes_doc, boxes_parent, load_doc, load_err, placed_boxes,
        rejects, test_doc, write_embedded, Doc,
    };
    use super::*;

    use crate::scene::Scene;

    use serde_json::{json, Value};

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
        let instanced = load_doc(doc.clone(), &bin);
        // Unlit: only the default environment's warning.
        assert!(
            instanced
                .warnings
                .iter()
                .all(|w| w.ends_with(crate::scene::NO_LIGHT_WARNING)),
            "{:?}",
            instanced.warnings
        );
        assert_eq!(instanced.instances.instances.len(), 4);
        assert!(instanced.mesh.triangles.is_empty());
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
        let flat = load_doc(nodes, &flat_bin);
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
}
