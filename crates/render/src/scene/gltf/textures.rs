//! Textures: texture infos (with KHR_texture_transform, read by the gltf crate or from the
//! JSON), samplers, and images decoded once per colour space.

use super::{uri_label, Loader};
use crate::scene::files::Uri;
use crate::scene::SceneError;
use crate::texture::{
    uv_transform, ColorSpace, Filter, Sampler, Texture, TextureId, TextureRef, Wrap,
};
use glam::{Affine2, Vec2, Vec4};
use serde::Deserialize;

/// A textureInfo read from the JSON: the texture's index and its texCoord set.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct JsonTextureInfo {
    pub(super) index: usize,
    #[serde(default)]
    pub(super) tex_coord: u32,
    /// Its KHR_texture_transform, read from its `extensions`.
    #[serde(
        default,
        rename = "extensions",
        deserialize_with = "transform_in_extensions"
    )]
    pub(super) transform: Option<UvTransform>,
}

/// The KHR_texture_transform of a texture info's `extensions` object, if it has one.
pub(super) fn transform_in_extensions<'de, D: serde::Deserializer<'de>>(
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
pub(super) struct UvTransform {
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
    pub(super) fn from_json(value: &serde_json::Value) -> Result<Self, String> {
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

    /// Whether its offset, rotation and scale are finite (a texture that is read checks this
    /// when it is decoded).
    pub(super) fn is_finite(&self) -> bool {
        Vec2::from(self.offset).is_finite()
            && self.rotation.is_finite()
            && Vec2::from(self.scale).is_finite()
    }
}

/// The first 12 bytes of every KTX2 file: `«KTX 20»\r\n\x1A\n`.
pub(super) const KTX2_MAGIC: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// The warning for KTX2 images: the feature, and how the materials are rendered without them.
const KTX2_WHAT: &str = "KTX2 (KHR_texture_basisu, not decoded)";
/// How the materials that use a KTX2 image are rendered (see [`KTX2_WHAT`]).
const KTX2_WITHOUT: &str =
    "their textures are left out; the materials are rendered with their factors alone";

/// Gives every texture of the file's JSON that has a KHR_texture_basisu `source` but no core
/// `source` the extension's, so that its image is found (and, being KTX2, left out with the
/// KTX2 warning) instead of failing validation. The extension's image is the preferred one and
/// the core `source` its fallback (the extension's specification); without a decoder the
/// fallback is what is read, where there is one. Only files that do not require the extension
/// get here (see [`super::extensions::check`]).
pub(super) fn basisu_sources(raw: &mut serde_json::Value) {
    let Some(textures) = raw.get_mut("textures").and_then(|t| t.as_array_mut()) else {
        return;
    };
    for texture in textures.iter_mut().filter_map(|t| t.as_object_mut()) {
        let source = texture
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_basisu"))
            .and_then(|b| b.get("source"))
            .cloned();
        if let Some(source) = source.filter(|_| !texture.contains_key("source")) {
            texture.insert("source".into(), source);
        }
    }
}

/// What of a glTF sampler the renderer honours: the wrap modes and the magnification filter
/// (see [`crate::texture`] for why `minFilter` does not change the converged image).
pub(super) fn sampler(s: &gltf::texture::Sampler) -> Sampler {
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

/// Converts a decoded image to a linear RGBA texture: 8-bit images stay bytes (RGBA8), others
/// become floats (16-bit values over 65535); grey (and grey-alpha) images replicate their
/// value, as image viewers do.
pub(super) fn decode_image(image: image::DynamicImage, space: ColorSpace) -> Option<Texture> {
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

impl Loader<'_> {
    /// The reference a material's texture info makes: its image (decoded once per colour
    /// space), texture coordinate set, sampler and KHR_texture_transform; `None` where the
    /// image is not decoded (KTX2, with a warning: the material keeps its factor).
    pub(super) fn texture(
        &mut self,
        info: &gltf::texture::Info,
        space: ColorSpace,
        material: &str,
    ) -> Result<Option<TextureRef>, SceneError> {
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
    /// and transform; `None` where the image is not decoded (see [`Loader::image`]).
    pub(super) fn texture_of(
        &mut self,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<UvTransform>,
        space: ColorSpace,
        material: &str,
    ) -> Result<Option<TextureRef>, SceneError> {
        let element = format!("{material}, texture {}", texture.index());
        // KHR_texture_transform's texCoord overrides the texture info's.
        let set = transform
            .as_ref()
            .and_then(|t| t.tex_coord)
            .unwrap_or(tex_coord);
        let texcoord = match set {
            0 | 1 => set as u8,
            _ => {
                let what = format!("TEXCOORD_{set}");
                let without = "only TEXCOORD_0 and TEXCOORD_1 are read; TEXCOORD_0 is used";
                self.warn(&what, "texture", &element, without);
                0
            }
        };
        let transform = match transform {
            None => None,
            Some(t) => {
                let (offset, rotation, scale) =
                    (Vec2::from(t.offset), t.rotation, Vec2::from(t.scale));
                if !t.is_finite() {
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
        Ok(image.map(|texture| TextureRef {
            texture,
            texcoord,
            sampler,
            transform,
        }))
    }

    /// The decoded image of `texture` in colour space `space`, decoded once; `None` for a KTX2
    /// image (found by its content, whatever its MIME type or name say), which is not decoded:
    /// one warning names every such image, and the materials keep their factors. A KTX2 image
    /// in a file that requires KHR_texture_basisu never gets here (the extension check fails
    /// the file).
    pub(super) fn image(
        &mut self,
        texture: &gltf::Texture,
        space: ColorSpace,
        material: &str,
    ) -> Result<Option<TextureId>, SceneError> {
        let image = texture.source();
        let key = (image.index(), space);
        if let Some(&id) = self.textures.get(&key) {
            return Ok(id);
        }
        let image_label = match image.source() {
            gltf::image::Source::Uri { uri, .. } => {
                format!("image {} ({})", image.index(), uri_label(&self.base, uri))
            }
            gltf::image::Source::View { view, .. } => {
                format!("image {} (bufferView {})", image.index(), view.index())
            }
        };
        let element = format!("{material}, {image_label}");
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
        if bytes.starts_with(&KTX2_MAGIC) {
            self.warn(KTX2_WHAT, "image", &image_label, KTX2_WITHOUT);
            self.textures.insert(key, None);
            return Ok(None);
        }
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
        self.textures.insert(key, Some(id));
        Ok(Some(id))
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{
        approx, load_doc, load_err, normal_mapped_doc, png_file, test_doc, write_embedded, Doc,
    };
    use super::*;

    use crate::material::{AlphaMode, GltfPbrParams, Reflectance};
    use crate::scene::Scene;
    use glam::{Vec2, Vec3};
    use serde_json::json;

    /// A KTX2 file: the magic, then bytes that are no image (the loader never decodes them).
    fn ktx2_bytes() -> Vec<u8> {
        let mut bytes = KTX2_MAGIC.to_vec();
        bytes.extend([0u8; 68]);
        bytes
    }

    /// The base colour texture of material `m` of `scene`, if it has one.
    fn base_texture(scene: &Scene, m: usize) -> Option<TextureRef> {
        match scene.materials[m].reflectance {
            Reflectance::GltfPbr(GltfPbrParams {
                base_color_texture, ..
            }) => base_color_texture,
            _ => panic!("not a glTF material"),
        }
    }

    /// KTX2 images are found by their content, whatever their name and MIME type say, and
    /// left out with one warning for the file naming them; the material keeps its factor.
    #[test]
    fn ktx2_images_are_sniffed_and_left_out_with_one_warning() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("lamp.png"), ktx2_bytes()).unwrap();
        std::fs::write(dir.path().join("lamp_n.ktx2"), ktx2_bytes()).unwrap();
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_texture_basisu"]);
        doc["images"] =
            json!([{"uri": "lamp.png", "mimeType": "image/png"}, {"uri": "lamp_n.ktx2"}]);
        doc["textures"] = json!([{"source": 0}, {"source": 1}]);
        doc["materials"][1]["pbrMetallicRoughness"] = json!({"baseColorFactor": [0.5, 0.25, 1, 1], "baseColorTexture": {"index": 0},
                   "metallicRoughnessTexture": {"index": 0}});
        doc["materials"][1]["normalTexture"] = json!({"index": 1});
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        assert!(scene.textures.is_empty());
        assert!(base_texture(&scene, 1).is_none());
        assert!(scene.materials[1].normal_map.is_none());
        let Reflectance::GltfPbr(p) = &scene.materials[1].reflectance else {
            panic!()
        };
        assert_eq!(p.base_color, Vec3::new(0.5, 0.25, 1.0));
        let ktx2: Vec<&String> = scene
            .warnings
            .iter()
            .filter(|w| w.contains("KTX2"))
            .collect();
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
        assert_eq!(ktx2.len(), 1, "{:?}", scene.warnings);
        assert!(
            ktx2[0].contains("on 2 images")
                && ktx2[0].contains("image 0 (\"lamp.png\"")
                && ktx2[0].contains("image 1 (\"lamp_n.ktx2\"")
                && ktx2[0].contains("factors alone"),
            "{ktx2:?}"
        );
    }

    /// KHR_texture_basisu: the texture's core source is the fallback and is read, with one
    /// warning; without a fallback the KTX2 image is left out; a file that requires the
    /// extension is an error naming it.
    #[test]
    fn basisu_textures_use_their_fallback_image() {
        let dir = png_file("lamp.png", 1, 1, vec![255, 0, 0, 255]);
        std::fs::write(dir.path().join("lamp.ktx2"), ktx2_bytes()).unwrap();
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_texture_basisu"]);
        doc["images"] =
            json!([{"uri": "lamp.png"}, {"uri": "lamp.ktx2", "mimeType": "image/ktx2"}]);
        let basisu = json!({"KHR_texture_basisu": {"source": 1}});
        doc["textures"] = json!([{"source": 0, "extensions": basisu}, {"extensions": basisu}]);
        doc["materials"][1]["pbrMetallicRoughness"] = json!({"baseColorTexture": {"index": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        let base = base_texture(&scene, 1).expect("the fallback PNG");
        let red = scene.textures[base.texture as usize].texel(0);
        assert!((red.truncate() - Vec3::X).length() < 1e-6, "{red}");
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
        assert!(
            scene.warnings[0].contains("KHR_texture_basisu on 2 textures")
                && scene.warnings[0].contains("fallback image"),
            "{:?}",
            scene.warnings
        );
        // The texture without a fallback: left out, its KTX2 image named.
        doc["materials"][1]["pbrMetallicRoughness"] = json!({"baseColorTexture": {"index": 1}});
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert!(base_texture(&scene, 1).is_none());
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("KTX2") && w.contains("image 1 (\"lamp.ktx2\"")),
            "{:?}",
            scene.warnings
        );
        // An extension source that is no image is an error, not a panic.
        let mut bad = doc.clone();
        bad["textures"][1]["extensions"]["KHR_texture_basisu"]["source"] = json!(99);
        let err = Scene::load(&write_embedded(dir.path(), bad, &bin)).unwrap_err();
        let err = format!("{err}: {:?}", std::error::Error::source(&err));
        assert!(err.contains("textures[1].source"), "{err}");
        doc["extensionsRequired"] = json!(["KHR_texture_basisu"]);
        let err = Scene::load(&write_embedded(dir.path(), doc, &bin))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("requires the glTF extension KHR_texture_basisu")
                && err.contains("export PNG or JPEG"),
            "{err}"
        );
    }

    /// A texture whose file is missing is an error naming the file and the material.
    #[test]
    fn a_missing_texture_file_is_an_error_naming_it() {
        let (mut doc, bin) = test_doc();
        doc["images"] = json!([{"uri": "textures/asphalt_albedo.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["pbrMetallicRoughness"] = json!({"baseColorTexture": {"index": 0}});
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"glow\" (1)")
                && err.contains("asphalt_albedo.png")
                && err.contains("image 0"),
            "{err}"
        );
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
        assert_eq!(scene.mesh.uvs1.len(), 7);
        assert_eq!(scene.mesh.uvs1[2], Vec2::new(0.5, 0.5));
        assert_eq!(scene.mesh.uvs1[4..], scene.mesh.uvs[4..]);
        assert!((scene.mesh.colors[2] - Vec4::new(0.0, 0.0, 1.0, 0.2)).length() < 1e-6);
        assert_eq!(scene.mesh.colors[5], Vec4::ONE);
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
        let scene = load_doc(doc, &bin);
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
        let scene = load_doc(doc, &bin);
        for t in &scene.mesh.tangents[..4] {
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
}
