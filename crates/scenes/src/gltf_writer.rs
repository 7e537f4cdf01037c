//! A small glTF 2.0 document builder: meshes in world coordinates, materials following the
//! project's scene contract (`extras.streaks`, emissive strength, the dryness texture),
//! KHR_lights_punctual lights and named perspective cameras; written as `NAME.gltf` with one
//! external `NAME.bin` buffer and PNG images beside it.
//!
//! Output is byte-for-byte deterministic: JSON objects are built with `serde_json` (keys in a
//! fixed order), floats written to the buffer are quantised (see [`quantise`]) so that a
//! last-bit difference in a platform's `sin`/`cos` does not change the files.

use crate::mesh::Mesh;
use crate::Error;
use glam::{Quat, Vec3};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::Arc;
pub use streaks_render::class::Class;

/// glTF `ARRAY_BUFFER` target.
const ARRAY_BUFFER: u32 = 34962;
/// glTF `ELEMENT_ARRAY_BUFFER` target.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// glTF component type FLOAT.
const FLOAT: u32 = 5126;
/// glTF component type UNSIGNED_SHORT.
const UNSIGNED_SHORT: u32 = 5123;
/// glTF component type UNSIGNED_INT.
const UNSIGNED_INT: u32 = 5125;

/// Rounds `x` to a multiple of 2^-`bits` (ties away from zero), so computed geometry does not
/// depend on the last bit of the platform's libm.
pub fn quantise(x: f32, bits: i32) -> f32 {
    let s = (2.0f32).powi(bits);
    (x * s).round() / s
}

/// Rounds a JSON number to 7 decimals (see [`quantise`]); keeps the JSON short and stable.
/// Negative zero becomes zero.
pub fn round7(x: f64) -> f64 {
    (x * 1e7).round() / 1e7 + 0.0
}

/// One of the paper's reflectance models, written as `extras.streaks`.
#[derive(Clone, Debug, PartialEq)]
pub enum PaperBsdf {
    /// GGX microfacet (Mitsuba's blend of diffuse and roughconductor); `alpha` is the
    /// microfacet alpha.
    Ggx {
        /// Microfacet alpha.
        alpha: f64,
    },
    /// The paper's isotropic Ward model.
    Ward {
        /// Ward alpha.
        alpha: f64,
    },
    /// Normalised Blinn-Phong.
    BlinnPhong {
        /// Shininess exponent s.
        shininess: f64,
    },
}

/// Wet/dry modulation of a paper material: the green channel of the material's
/// metallicRoughnessTexture is the dryness w (see scenes/README.md).
#[derive(Clone, Debug, PartialEq)]
pub struct Dryness {
    /// Index of the image (from [`Doc::add_png`]) holding the dryness map.
    pub image: usize,
    /// Alpha where fully dry (w = 1).
    pub alpha_dry: f64,
    /// Specular reflectance where fully dry (w = 1).
    pub ks_dry: [f64; 3],
}

/// A tangent-space normal map on a paper material (glTF `normalTexture`), tiled over the
/// mesh's texture coordinates by `KHR_texture_transform` when `tiles` is not 1.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalTexture {
    /// Index of the image (from [`Doc::add_png`]).
    pub image: usize,
    /// `normalTexture.scale`: the strength of the map's X and Y.
    pub scale: f64,
    /// Repeats of the image across one unit of the texture coordinates (u, v).
    pub tiles: [f64; 2],
}

/// How a material reflects.
#[derive(Clone, Debug, PartialEq)]
pub enum Reflect {
    /// A paper model from `extras.streaks`.
    Paper {
        /// The model and its roughness parameter.
        bsdf: PaperBsdf,
        /// Diffuse reflectance.
        kd: [f64; 3],
        /// Specular reflectance (no Fresnel).
        ks: [f64; 3],
        /// Optional wet/dry map.
        dryness: Option<Dryness>,
        /// Optional albedo texture (image index from [`Doc::add_png`]), written as the
        /// baseColorTexture: its linear RGB multiplies `kd`.
        albedo: Option<usize>,
        /// Optional normal map (rain ripples on the road).
        normal: Option<NormalTexture>,
        /// Optional glass beads (a `ggx` material only): `extras.streaks.kr` (grey) and
        /// `retro_width` (radians), bead paint's retroreflective cone.
        beads: Option<Beads>,
    },
    /// A black, non-reflecting surface (glTF metallic-roughness with base colour 0): used
    /// for emitters, whose look is their emission.
    Black,
    /// glTF metallic-roughness, with an optional clear coat and transmission: car paint,
    /// glass, rubber, metal, and the materials of the user's assets.
    Pbr(Pbr),
}

/// Glass beads in road-marking paint: the renderer's retroreflective cone
/// (`streaks_render::bsdf::Retroreflective`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beads {
    /// The cone's reflectance (grey).
    pub kr: f64,
    /// The cone's width, radians.
    pub width: f64,
}

impl Beads {
    /// Beads of the renderer's default cone width that measure `rl_mcd` (mcd m^-2 lx^-1) at
    /// EN 1436's geometry.
    pub fn for_rl(rl_mcd: f64) -> Self {
        use streaks_render::bsdf::{Retroreflective, BEAD_CONE_WIDTH};
        let n = Retroreflective::exponent_for_width(BEAD_CONE_WIDTH);
        Self {
            kr: round7(f64::from(Retroreflective::kr_for_rl(
                (rl_mcd / 1000.0) as f32,
                n,
            ))),
            width: round7(f64::from(BEAD_CONE_WIDTH)),
        }
    }
}

/// glTF metallic-roughness parameters (`pbrMetallicRoughness`), with
/// `KHR_materials_clearcoat`, `KHR_materials_transmission`, `KHR_materials_ior` and
/// `KHR_materials_volume` when set.
#[derive(Clone, Debug, PartialEq)]
pub struct Pbr {
    /// baseColorFactor (linear RGB; alpha is written as 1).
    pub base_color: [f64; 3],
    /// metallicFactor in [0, 1].
    pub metallic: f64,
    /// roughnessFactor in [0, 1] (perceptual: GGX alpha is its square).
    pub roughness: f64,
    /// baseColorTexture: an sRGB PNG multiplying `base_color`, read with the mesh's texture
    /// coordinates.
    pub base_color_texture: Option<Png>,
    /// A clear coat over the base (car paint).
    pub clearcoat: Option<Clearcoat>,
    /// Specular transmission (glass).
    pub transmission: Option<Transmission>,
}

impl Pbr {
    /// An opaque dielectric or metal without texture, coat or transmission.
    pub fn new(base_color: [f64; 3], metallic: f64, roughness: f64) -> Self {
        Self {
            base_color,
            metallic,
            roughness,
            base_color_texture: None,
            clearcoat: None,
            transmission: None,
        }
    }
}

/// `KHR_materials_clearcoat`: a smooth dielectric layer (index 1.5) over the base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearcoat {
    /// clearcoatFactor in [0, 1].
    pub factor: f64,
    /// clearcoatRoughnessFactor in [0, 1].
    pub roughness: f64,
}

/// `KHR_materials_transmission` with its index of refraction (`KHR_materials_ior`).
/// Without a volume the surface is thin-walled: light goes through without bending, tinted
/// by the base colour (a window pane modelled as one sheet).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transmission {
    /// transmissionFactor in [0, 1].
    pub factor: f64,
    /// Index of refraction (1.5 for soda-lime glass).
    pub ior: f64,
    /// `KHR_materials_volume`, for a closed mesh of thick glass.
    pub volume: Option<Volume>,
}

/// `KHR_materials_volume`: the medium inside a closed transmissive mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volume {
    /// thicknessFactor, metres (> 0).
    pub thickness: f64,
    /// attenuationColor: the colour white light has after `attenuation_distance`.
    pub attenuation_color: [f64; 3],
    /// attenuationDistance, metres (> 0).
    pub attenuation_distance: f64,
}

/// A PNG image carried by a material before it is in a [`Doc`]: written once per document
/// as `DOC_NAME.png`, shared by every material that carries the same name and bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Png {
    /// The file-name suffix (`DOC_NAME.png`).
    pub name: String,
    /// The encoded PNG.
    pub bytes: Arc<Vec<u8>>,
}

/// A material: reflectance plus optional emission.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name written to the glTF.
    pub name: String,
    /// How it reflects.
    pub reflect: Reflect,
    /// Emitted radiance (linear RGB, W m^-2 sr^-1), written as emissiveFactor (max
    /// component 1) times KHR_materials_emissive_strength.
    pub emission: Option<[f64; 3]>,
    /// Whether both faces are shaded (and emit).
    pub double_sided: bool,
    /// Whether this is the road surface (`extras.streaks.road`: the dataset's road mask is
    /// the pixels whose first hit has such a material).
    pub road: bool,
}

impl Material {
    /// A paper-model material without emission.
    pub fn paper(name: &str, bsdf: PaperBsdf, kd: [f64; 3], ks: [f64; 3]) -> Self {
        Self {
            name: name.to_owned(),
            reflect: Reflect::Paper {
                bsdf,
                kd,
                ks,
                dryness: None,
                albedo: None,
                normal: None,
                beads: None,
            },
            emission: None,
            double_sided: false,
            road: false,
        }
    }

    /// The same paper material with a dryness map (no effect on other reflectances).
    pub fn with_dryness(mut self, d: Dryness) -> Self {
        if let Reflect::Paper { dryness, .. } = &mut self.reflect {
            *dryness = Some(d);
        }
        self
    }

    /// The same paper material with an albedo texture multiplying `kd` (no effect on other
    /// reflectances).
    pub fn with_albedo(mut self, image: usize) -> Self {
        if let Reflect::Paper { albedo, .. } = &mut self.reflect {
            *albedo = Some(image);
        }
        self
    }

    /// The same paper material with glass beads (no effect on other reflectances; the
    /// renderer takes them for a `ggx` material only).
    pub fn with_beads(mut self, b: Beads) -> Self {
        if let Reflect::Paper { beads, .. } = &mut self.reflect {
            *beads = Some(b);
        }
        self
    }

    /// The same paper material with a normal map (no effect on other reflectances).
    pub fn with_normal(mut self, n: NormalTexture) -> Self {
        if let Reflect::Paper { normal, .. } = &mut self.reflect {
            *normal = Some(n);
        }
        self
    }

    /// The same material, marked as the road surface.
    pub fn as_road(mut self) -> Self {
        self.road = true;
        self
    }

    /// A Mitsuba-style diffuse material: `ggx` with ks = 0.
    pub fn diffuse(name: &str, kd: [f64; 3]) -> Self {
        Self::paper(name, PaperBsdf::Ggx { alpha: 0.5 }, kd, [0.0; 3])
    }

    /// A glTF metallic-roughness material without emission.
    pub fn pbr(name: &str, pbr: Pbr) -> Self {
        Self {
            name: name.to_owned(),
            reflect: Reflect::Pbr(pbr),
            emission: None,
            double_sided: false,
            road: false,
        }
    }

    /// A black, one-sided emitter of radiance `radiance`.
    pub fn emitter(name: &str, radiance: [f64; 3]) -> Self {
        Self {
            name: name.to_owned(),
            reflect: Reflect::Black,
            emission: Some(radiance),
            double_sided: false,
            road: false,
        }
    }
}

/// A punctual light (KHR_lights_punctual).
#[derive(Clone, Debug, PartialEq)]
pub enum LightKind {
    /// Point light.
    Point,
    /// Spot light along the node's -Z with the glTF cone angles (radians).
    Spot {
        /// innerConeAngle.
        inner: f64,
        /// outerConeAngle.
        outer: f64,
    },
}

/// Lumens per watt of the scene contract: a light of `I` W/sr is written as `683 I` candela
/// (KHR_lights_punctual's unit), which the renderer reads back as `I` W/sr
/// (`streaks_render::light::LUMINOUS_EFFICACY`; a test checks that they agree).
pub const LUMENS_PER_WATT: f64 = 683.0;

/// A point or spot light: `color * intensity` is the radiant intensity (W/sr); the file gets
/// it in candela (times [`LUMENS_PER_WATT`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Node and light name.
    pub name: String,
    /// Point or spot.
    pub kind: LightKind,
    /// Colour, max component 1.
    pub color: [f64; 3],
    /// Radiant intensity, W/sr.
    pub intensity: f64,
    /// Position in world space.
    pub position: Vec3,
    /// Spot direction (ignored for point lights).
    pub direction: Vec3,
}

/// What a node is: its semantic class and the object it is part of, written as the node's
/// `extras.streaks` (`class`, `instance`; see [`streaks_render::class`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tag {
    /// The semantic class.
    pub class: Class,
    /// The object this node is part of (all the nodes of one car share it); `None` for stuff
    /// (road, sidewalk, buildings) that has no instances.
    pub instance: Option<u32>,
}

impl Tag {
    /// A node of class `class` that is part of no countable object.
    pub fn stuff(class: Class) -> Self {
        Self {
            class,
            instance: None,
        }
    }

    /// A node of class `class` that is part of object `instance`.
    pub fn object(class: Class, instance: u32) -> Self {
        Self {
            class,
            instance: Some(instance),
        }
    }
}

/// A glTF document under construction.
pub struct Doc {
    name: String,
    bin: Vec<u8>,
    accessors: Vec<Value>,
    views: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    materials: Vec<Value>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
    images: Vec<(String, Vec<u8>)>,
    textures_used: Vec<usize>,
    triangles: usize,
    description: String,
    /// `scenes[0].extras.streaks`: the environment, fog and rain, if any.
    scene_extras: serde_json::Map<String, Value>,
}

impl std::fmt::Debug for Doc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Doc")
            .field("name", &self.name)
            .field("triangles", &self.triangles)
            .field("lights", &self.lights.len())
            .field("materials", &self.materials.len())
            .field("images", &self.images.len())
            .finish_non_exhaustive()
    }
}

impl Doc {
    /// A new empty document that will be written as `name.gltf` and `name.bin`.
    pub fn new(name: &str, description: &str) -> Self {
        Self {
            name: name.to_owned(),
            bin: Vec::new(),
            accessors: Vec::new(),
            views: Vec::new(),
            meshes: Vec::new(),
            nodes: Vec::new(),
            materials: Vec::new(),
            cameras: Vec::new(),
            lights: Vec::new(),
            images: Vec::new(),
            textures_used: Vec::new(),
            triangles: 0,
            description: description.to_owned(),
            scene_extras: serde_json::Map::new(),
        }
    }

    /// Sets the scene's environment light, `scenes[0].extras.streaks.environment` (for
    /// example `{"color": [r, g, b]}`).
    pub fn set_environment(&mut self, environment: serde_json::Value) {
        self.set_scene_extra("environment", environment);
    }

    /// Sets `scenes[0].extras.streaks.KEY` (`environment`, `fog`, `rain`: the scene-level
    /// extras the renderer reads).
    pub fn set_scene_extra(&mut self, key: &str, value: serde_json::Value) {
        self.scene_extras.insert(key.to_owned(), value);
    }

    /// Number of triangles added so far.
    pub fn triangle_count(&self) -> usize {
        self.triangles
    }

    /// Number of punctual lights added so far.
    pub fn light_count(&self) -> usize {
        self.lights.len()
    }

    /// Adds an encoded PNG image written as `NAME_suffix.png`; returns its image index.
    pub fn add_png(&mut self, suffix: &str, png: Vec<u8>) -> usize {
        let file = format!("{}_{}.png", self.name, suffix);
        self.images.push((file, png));
        self.images.len() - 1
    }

    fn push_view(&mut self, bytes: &[u8], target: u32) -> usize {
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": bytes.len(),
            "target": target,
        }));
        self.views.len() - 1
    }

    fn push_vec_accessor(&mut self, data: &[[f32; 3]], with_bounds: bool) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flat_map(|v| v.iter().flat_map(|c| c.to_le_bytes()))
            .collect();
        let view = self.push_view(&bytes, ARRAY_BUFFER);
        let mut acc = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": data.len(),
            "type": "VEC3",
        });
        if with_bounds {
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for v in data {
                for k in 0..3 {
                    min[k] = min[k].min(v[k]);
                    max[k] = max[k].max(v[k]);
                }
            }
            acc["min"] = json!(min);
            acc["max"] = json!(max);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    /// Adds `mesh` (world coordinates) as a node named `name` with material `material` and no
    /// semantic tag.
    pub fn add_mesh(&mut self, name: &str, mesh: &Mesh, material: &Material) -> Result<(), Error> {
        self.add_node(name, mesh, material, None)
    }

    /// Adds `mesh` (world coordinates) as a node named `name` with material `material`, tagged
    /// with its class and instance (`extras.streaks`).
    pub fn add_tagged_mesh(
        &mut self,
        name: &str,
        mesh: &Mesh,
        material: &Material,
        tag: Tag,
    ) -> Result<(), Error> {
        self.add_node(name, mesh, material, Some(tag))
    }

    fn add_node(
        &mut self,
        name: &str,
        mesh: &Mesh,
        material: &Material,
        tag: Option<Tag>,
    ) -> Result<(), Error> {
        if mesh.indices.is_empty() {
            return Err(Error::Scene {
                scene: self.name.clone(),
                element: name.to_owned(),
                reason: "empty mesh".to_owned(),
            });
        }
        let positions: Vec<[f32; 3]> = mesh
            .positions
            .iter()
            .map(|p| p.to_array().map(|c| quantise(c, 16)))
            .collect();
        let normals: Vec<[f32; 3]> = mesh
            .normals
            .iter()
            .map(|n| n.to_array().map(|c| quantise(c, 22)))
            .collect();
        let pos = self.push_vec_accessor(&positions, true);
        let nor = self.push_vec_accessor(&normals, false);
        let mut attributes = json!({ "POSITION": pos, "NORMAL": nor });
        let textured = match &material.reflect {
            Reflect::Paper {
                dryness,
                albedo,
                normal,
                ..
            } => dryness.is_some() || albedo.is_some() || normal.is_some(),
            Reflect::Pbr(p) => p.base_color_texture.is_some(),
            Reflect::Black => false,
        };
        if textured && mesh.uvs.len() != mesh.positions.len() {
            return Err(Error::Scene {
                scene: self.name.clone(),
                element: name.to_owned(),
                reason: format!(
                    "a textured material needs one texture coordinate per vertex ({} for {})",
                    mesh.uvs.len(),
                    mesh.positions.len()
                ),
            });
        }
        if textured {
            let bytes: Vec<u8> = mesh
                .uvs
                .iter()
                .flat_map(|t| t.to_array().map(|c| quantise(c, 20)))
                .flat_map(|c| c.to_le_bytes())
                .collect();
            let view = self.push_view(&bytes, ARRAY_BUFFER);
            self.accessors.push(json!({
                "bufferView": view,
                "componentType": FLOAT,
                "count": mesh.uvs.len(),
                "type": "VEC2",
            }));
            attributes["TEXCOORD_0"] = json!(self.accessors.len() - 1);
        }
        // 16-bit indices up to 65534 (65535 is the primitive-restart value in some APIs).
        let (bytes, component): (Vec<u8>, u32) = if mesh.positions.len() < usize::from(u16::MAX) {
            let b = mesh
                .indices
                .iter()
                .flat_map(|&i| (i as u16).to_le_bytes())
                .collect();
            (b, UNSIGNED_SHORT)
        } else {
            let b = mesh.indices.iter().flat_map(|&i| i.to_le_bytes()).collect();
            (b, UNSIGNED_INT)
        };
        let view = self.push_view(&bytes, ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": component,
            "count": mesh.indices.len(),
            "type": "SCALAR",
        }));
        let indices = self.accessors.len() - 1;
        let mat = self.material_index(material);
        self.meshes.push(json!({
            "name": name,
            "primitives": [{ "attributes": attributes, "indices": indices, "material": mat }],
        }));
        let mut node = json!({ "name": name, "mesh": self.meshes.len() - 1 });
        if let Some(tag) = tag {
            let mut streaks = json!({ "class": tag.class.name() });
            if let Some(instance) = tag.instance {
                streaks["instance"] = json!(instance);
            }
            node["extras"] = json!({ "streaks": streaks });
        }
        self.nodes.push(node);
        self.triangles += mesh.indices.len() / 3;
        Ok(())
    }

    /// The glTF texture index of image `image`, adding the texture on first use.
    fn texture_index(&mut self, image: usize) -> usize {
        match self.textures_used.iter().position(|&i| i == image) {
            Some(t) => t,
            None => {
                self.textures_used.push(image);
                self.textures_used.len() - 1
            }
        }
    }

    /// The image index of `png`, adding it on first use (same name and bytes); another
    /// image of the same name gets a numbered name.
    fn png_index(&mut self, png: &Png) -> usize {
        let mut suffix = png.name.clone();
        for n in 1.. {
            let file = format!("{}_{}.png", self.name, suffix);
            match self.images.iter().position(|(f, _)| *f == file) {
                Some(i) if self.images[i].1[..] == png.bytes[..] => return i,
                Some(_) => suffix = format!("{}_{n}", png.name),
                None => break,
            }
        }
        self.add_png(&suffix, png.bytes.to_vec())
    }

    fn material_index(&mut self, m: &Material) -> usize {
        let mut v = json!({ "name": m.name });
        match &m.reflect {
            Reflect::Pbr(p) => {
                let b = p.base_color.map(round7);
                let mut pbr = json!({
                    "baseColorFactor": [b[0], b[1], b[2], 1.0],
                    "metallicFactor": round7(p.metallic),
                    "roughnessFactor": round7(p.roughness),
                });
                if let Some(png) = &p.base_color_texture {
                    let image = self.png_index(png);
                    let tex = self.texture_index(image);
                    pbr["baseColorTexture"] = json!({ "index": tex });
                }
                v["pbrMetallicRoughness"] = pbr;
                let mut ext = serde_json::Map::new();
                if let Some(c) = p.clearcoat {
                    ext.insert(
                        "KHR_materials_clearcoat".into(),
                        json!({
                            "clearcoatFactor": round7(c.factor),
                            "clearcoatRoughnessFactor": round7(c.roughness),
                        }),
                    );
                }
                if let Some(t) = p.transmission {
                    ext.insert(
                        "KHR_materials_transmission".into(),
                        json!({ "transmissionFactor": round7(t.factor) }),
                    );
                    ext.insert("KHR_materials_ior".into(), json!({ "ior": round7(t.ior) }));
                    if let Some(vol) = t.volume {
                        ext.insert(
                            "KHR_materials_volume".into(),
                            json!({
                                "thicknessFactor": round7(vol.thickness),
                                "attenuationColor": vol.attenuation_color.map(round7),
                                "attenuationDistance": round7(vol.attenuation_distance),
                            }),
                        );
                    }
                }
                if !ext.is_empty() {
                    v["extensions"] = Value::Object(ext);
                }
            }
            Reflect::Black => {
                v["pbrMetallicRoughness"] = json!({
                    "baseColorFactor": [0.0, 0.0, 0.0, 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0,
                });
            }
            Reflect::Paper {
                bsdf,
                kd,
                ks,
                dryness,
                albedo,
                normal,
                beads,
            } => {
                let mut s = json!({ "kd": kd, "ks": ks });
                if let Some(b) = beads {
                    s["kr"] = json!([b.kr, b.kr, b.kr]);
                    s["retro_width"] = json!(b.width);
                }
                // glTF fallback for other viewers: roughness = sqrt(alpha).
                let fallback_alpha = match bsdf {
                    PaperBsdf::Ggx { alpha } => {
                        s["bsdf"] = json!("ggx");
                        s["alpha"] = json!(alpha);
                        *alpha
                    }
                    PaperBsdf::Ward { alpha } => {
                        s["bsdf"] = json!("ward");
                        s["alpha"] = json!(alpha);
                        *alpha
                    }
                    PaperBsdf::BlinnPhong { shininess } => {
                        s["bsdf"] = json!("blinn_phong");
                        s["shininess"] = json!(shininess);
                        // Blinn-Phong s ~ 2 / alpha^2 - 2.
                        (2.0 / (shininess + 2.0)).sqrt()
                    }
                };
                let mut pbr = json!({
                    "baseColorFactor": [kd[0], kd[1], kd[2], 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": round7(fallback_alpha.sqrt()),
                });
                if let Some(d) = dryness {
                    s["alpha_dry"] = json!(d.alpha_dry);
                    s["ks_dry"] = json!(d.ks_dry);
                    pbr["roughnessFactor"] = json!(round7(d.alpha_dry.sqrt()));
                    let tex = self.texture_index(d.image);
                    pbr["metallicRoughnessTexture"] = json!({ "index": tex });
                }
                if let Some(image) = albedo {
                    let tex = self.texture_index(*image);
                    pbr["baseColorTexture"] = json!({ "index": tex });
                }
                v["pbrMetallicRoughness"] = pbr;
                if let Some(n) = normal {
                    let mut info =
                        json!({ "index": self.texture_index(n.image), "scale": n.scale });
                    if n.tiles != [1.0, 1.0] {
                        info["extensions"] =
                            json!({ "KHR_texture_transform": { "scale": n.tiles } });
                    }
                    v["normalTexture"] = info;
                }
                if m.road {
                    s["road"] = json!(true);
                }
                v["extras"] = json!({ "streaks": s });
            }
        }
        if let Some(e) = m.emission {
            let peak = e[0].max(e[1]).max(e[2]);
            if peak > 0.0 {
                v["emissiveFactor"] = json!([
                    round7(e[0] / peak),
                    round7(e[1] / peak),
                    round7(e[2] / peak)
                ]);
                if peak != 1.0 {
                    v["extensions"]["KHR_materials_emissive_strength"] =
                        json!({ "emissiveStrength": peak });
                }
            }
        }
        if m.double_sided {
            v["doubleSided"] = json!(true);
        }
        match self.materials.iter().position(|x| *x == v) {
            Some(i) => i,
            None => {
                self.materials.push(v);
                self.materials.len() - 1
            }
        }
    }

    /// Adds a punctual light as a node.
    pub fn add_light(&mut self, l: &Light) {
        let mut v = json!({
            "name": l.name,
            "color": l.color,
            "intensity": l.intensity * LUMENS_PER_WATT,
        });
        let mut node = json!({
            "name": l.name,
            "translation": round_vec(l.position),
            "extensions": { "KHR_lights_punctual": { "light": self.lights.len() } },
        });
        match l.kind {
            LightKind::Point => v["type"] = json!("point"),
            LightKind::Spot { inner, outer } => {
                v["type"] = json!("spot");
                v["spot"] = json!({
                    "innerConeAngle": round7(inner),
                    "outerConeAngle": round7(outer),
                });
                let q = Quat::from_rotation_arc(Vec3::NEG_Z, l.direction.normalize());
                node["rotation"] = round_quat(q);
            }
        }
        self.lights.push(v);
        self.nodes.push(node);
    }

    /// Adds a perspective camera node named `name` at `eye` looking at `target` (+Y up).
    pub fn add_camera(&mut self, name: &str, eye: Vec3, target: Vec3, yfov_deg: f64, aspect: f64) {
        self.add_camera_up(name, eye, target, Vec3::Y, yfov_deg, aspect);
    }

    /// Adds a perspective camera node named `name` at `eye` looking at `target`, its image's
    /// up direction as close to `up` as the view allows (a rolled camera has an `up` tilted
    /// about the view direction).
    pub fn add_camera_up(
        &mut self,
        name: &str,
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        yfov_deg: f64,
        aspect: f64,
    ) {
        let forward = (target - eye).normalize();
        // Right-handed basis with local -Z = forward, local +Y as close to `up` as possible.
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        let pose =
            glam::Affine3A::from_mat3_translation(glam::Mat3::from_cols(right, up, -forward), eye);
        self.add_camera_pose(name, pose, yfov_deg, aspect);
    }

    /// Adds a perspective camera node named `name` with the rigid pose `world_from_camera`
    /// (the camera looks along its local -Z with local +Y up).
    pub fn add_camera_pose(
        &mut self,
        name: &str,
        world_from_camera: glam::Affine3A,
        yfov_deg: f64,
        aspect: f64,
    ) {
        let q = Quat::from_mat3a(&world_from_camera.matrix3).normalize();
        self.cameras.push(json!({
            "name": name,
            "type": "perspective",
            "perspective": {
                "yfov": round7(yfov_deg.to_radians()),
                "aspectRatio": round7(aspect),
                "znear": 0.01,
            },
        }));
        self.nodes.push(json!({
            "name": name,
            "camera": self.cameras.len() - 1,
            "translation": round_vec(Vec3::from(world_from_camera.translation)),
            "rotation": round_quat(q),
        }));
    }

    /// Writes `NAME.gltf`, `NAME.bin` and the PNGs into `dir`; returns the written paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        let bin_name = format!("{}.bin", self.name);
        let mut root = json!({
            "asset": {
                "version": "2.0",
                "generator": "streaks-scenes (crates/scenes)",
            },
            "scene": 0,
            "scenes": [{
                "name": self.name,
                "nodes": (0..self.nodes.len()).collect::<Vec<_>>(),
                "extras": { "description": self.description },
            }],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{ "uri": bin_name, "byteLength": self.bin.len() }],
        });
        if !self.cameras.is_empty() {
            root["cameras"] = json!(self.cameras);
        }
        if !self.scene_extras.is_empty() {
            root["scenes"][0]["extras"]["streaks"] = Value::Object(self.scene_extras.clone());
        }
        let mut used = Vec::new();
        if !self.lights.is_empty() {
            used.push("KHR_lights_punctual");
            root["extensions"] = json!({ "KHR_lights_punctual": { "lights": self.lights } });
        }
        for ext in [
            "KHR_materials_emissive_strength",
            "KHR_materials_clearcoat",
            "KHR_materials_transmission",
            "KHR_materials_ior",
            "KHR_materials_volume",
        ] {
            if self
                .materials
                .iter()
                .any(|m| m.pointer(&format!("/extensions/{ext}")).is_some())
            {
                used.push(ext);
            }
        }
        if self.materials.iter().any(|m| {
            m.pointer("/normalTexture/extensions/KHR_texture_transform")
                .is_some()
        }) {
            used.push("KHR_texture_transform");
        }
        if !used.is_empty() {
            root["extensionsUsed"] = json!(used);
        }
        if !self.textures_used.is_empty() {
            // Bilinear, with glTF's default repeat wrapping (what the project's loader does).
            root["samplers"] = json!([{ "magFilter": 9729, "minFilter": 9729 }]);
            root["images"] = json!(self
                .textures_used
                .iter()
                .map(|&i| json!({ "uri": self.images[i].0, "mimeType": "image/png" }))
                .collect::<Vec<_>>());
            root["textures"] = json!((0..self.textures_used.len())
                .map(|i| json!({ "source": i, "sampler": 0 }))
                .collect::<Vec<_>>());
        }
        let mut text = serde_json::to_string_pretty(&root).map_err(|e| Error::Scene {
            scene: self.name.clone(),
            element: "JSON".to_owned(),
            reason: e.to_string(),
        })?;
        text.push('\n');
        let mut written = Vec::new();
        written.push(write_atomic(
            dir,
            &format!("{}.gltf", self.name),
            text.as_bytes(),
        )?);
        written.push(write_atomic(dir, &bin_name, &self.bin)?);
        for &i in &self.textures_used {
            let (file, png) = &self.images[i];
            written.push(write_atomic(dir, file, png)?);
        }
        Ok(written)
    }
}

fn round_vec(v: Vec3) -> Value {
    json!([
        round7(f64::from(v.x)),
        round7(f64::from(v.y)),
        round7(f64::from(v.z))
    ])
}

fn round_quat(q: Quat) -> Value {
    let q = q.normalize();
    json!([
        round7(f64::from(q.x)),
        round7(f64::from(q.y)),
        round7(f64::from(q.z)),
        round7(f64::from(q.w))
    ])
}

/// Writes `bytes` to `dir/file` through a temporary file renamed into place, so an
/// interrupted run never leaves a truncated scene.
pub fn write_atomic(dir: &Path, file: &str, bytes: &[u8]) -> Result<PathBuf, Error> {
    let path = dir.join(file);
    let tmp = dir.join(format!(".{file}.tmp"));
    let io = |e: std::io::Error| Error::Io {
        path: path.clone(),
        source: e,
    };
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, &path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_looks_along_minus_z_of_its_node() {
        let mut d = Doc::new("t", "");
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let target = Vec3::new(4.0, 0.0, -7.0);
        d.add_camera("c", eye, target, 40.0, 1.5);
        let r = &d.nodes[0]["rotation"];
        let q = Quat::from_xyzw(
            r[0].as_f64().unwrap() as f32,
            r[1].as_f64().unwrap() as f32,
            r[2].as_f64().unwrap() as f32,
            r[3].as_f64().unwrap() as f32,
        );
        let f = q * Vec3::NEG_Z;
        assert!((f - (target - eye).normalize()).length() < 1e-5);
        let up = q * Vec3::Y;
        assert!(up.y > 0.0 && (q * Vec3::X).y.abs() < 1e-6);
    }

    #[test]
    fn identical_materials_are_shared() {
        let mut d = Doc::new("t", "");
        let a = Material::diffuse("wall", [0.5; 3]);
        let b = Material::emitter("lamp", [3.0, 2.0, 1.0]);
        assert_eq!(d.material_index(&a), 0);
        assert_eq!(d.material_index(&b), 1);
        assert_eq!(d.material_index(&a), 0);
        assert_eq!(
            d.materials[1]["emissiveFactor"][2].as_f64(),
            Some(round7(1.0 / 3.0))
        );
    }

    /// Paint with a clear coat, thin glass and thick glass written by the writer load in the
    /// renderer as glTF PBR with the factors written, and without warnings.
    #[test]
    fn pbr_materials_load_in_the_renderer() {
        use streaks_render::material::Reflectance;
        let mut d = Doc::new("pbr", "");
        let paint = Pbr {
            clearcoat: Some(Clearcoat {
                factor: 1.0,
                roughness: 0.03,
            }),
            ..Pbr::new([0.5, 0.02, 0.01], 0.4, 0.35)
        };
        let thin = Pbr {
            transmission: Some(Transmission {
                factor: 0.9,
                ior: 1.52,
                volume: None,
            }),
            ..Pbr::new([0.8, 0.85, 0.82], 0.0, 0.0)
        };
        let thick = Pbr {
            transmission: Some(Transmission {
                factor: 1.0,
                ior: 1.5,
                volume: Some(Volume {
                    thickness: 0.01,
                    attenuation_color: [0.5, 0.8, 0.7],
                    attenuation_distance: 0.2,
                }),
            }),
            ..Pbr::new([1.0; 3], 0.0, 0.05)
        };
        let mut lit = Material::pbr("lit", Pbr::new([0.1; 3], 0.0, 0.5));
        lit.emission = Some([4.0, 2.0, 1.0]);
        let mut m = Mesh::new();
        m.cuboid(Vec3::ZERO, Vec3::ONE);
        for (k, mat) in [
            Material::pbr("paint", paint),
            Material::pbr("thin_glass", thin),
            Material::pbr("thick_glass", thick),
            lit,
        ]
        .iter()
        .enumerate()
        {
            d.add_tagged_mesh(&format!("m{k}"), &m, mat, Tag::object(Class::Car, 1))
                .unwrap();
        }
        let dir = tempfile::tempdir().unwrap();
        d.write(dir.path()).unwrap();
        let scene = streaks_render::scene::Scene::load(&dir.path().join("pbr.gltf")).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let get = |name: &str| {
            let m = scene.materials.iter().find(|m| m.name == name).unwrap();
            let Reflectance::GltfPbr(p) = &m.reflectance else {
                panic!("{name} is not glTF PBR: {:?}", m.reflectance);
            };
            (p.clone(), m.emission)
        };
        let (p, _) = get("paint");
        assert_eq!(p.base_color, glam::Vec3::new(0.5, 0.02, 0.01));
        assert_eq!((p.metallic, p.roughness), (0.4, 0.35));
        assert_eq!((p.clearcoat, p.clearcoat_roughness), (1.0, 0.03));
        assert_eq!(p.transmission, 0.0);
        let (p, _) = get("thin_glass");
        assert_eq!((p.transmission, p.ior, p.clearcoat), (0.9, 1.52, 0.0));
        assert!(p.volume.is_none());
        let (p, _) = get("thick_glass");
        let v = p.volume.expect("a volume");
        assert_eq!(v.thickness, 0.01);
        // attenuationColor c after distance d: sigma_a = -ln(c) / d.
        let want = -(0.8f32.ln()) / 0.2;
        assert!((v.sigma_a.y - want).abs() < 1e-4, "{} {want}", v.sigma_a.y);
        let (_, e) = get("lit");
        assert_eq!(e, glam::Vec3::new(4.0, 2.0, 1.0));
    }

    /// Paint with beads made for an `R_L` loads as bead paint that measures it at EN 1436's
    /// geometry (to the rounding of `kr`).
    #[test]
    fn bead_paint_loads_and_measures_its_rl() {
        use streaks_render::bsdf::{Bsdf, RL_ILLUMINATION_DEG, RL_OBSERVATION_DEG};
        let mut d = Doc::new("beads", "");
        let paint = Material::paper("paint", PaperBsdf::Ggx { alpha: 0.2 }, [0.5; 3], [0.05; 3])
            .with_beads(Beads::for_rl(250.0));
        let mut m = Mesh::new();
        m.cuboid(Vec3::ZERO, Vec3::ONE);
        d.add_tagged_mesh("marks", &m, &paint, Tag::stuff(Class::Marking))
            .unwrap();
        let dir = tempfile::tempdir().unwrap();
        d.write(dir.path()).unwrap();
        let scene = streaks_render::scene::Scene::load(&dir.path().join("beads.gltf")).unwrap();
        assert!(
            scene.warnings.iter().all(|w| !w.contains("paint")),
            "{:?}",
            scene.warnings
        );
        let at = streaks_render::geometry::VertexAttributes::from_uv(glam::Vec2::ZERO);
        let b = scene.materials[0].bsdf_at(&at, &scene.textures);
        assert!(matches!(b, Bsdf::Retroreflective(_)), "{b:?}");
        let dir_at = |deg: f32| {
            let (s, c) = deg.to_radians().sin_cos();
            Vec3::new(c, 0.0, s)
        };
        let wi = dir_at(RL_ILLUMINATION_DEG);
        let wo = dir_at(RL_ILLUMINATION_DEG + RL_OBSERVATION_DEG);
        // R_L = f cos(theta_i), less the Lambertian and GGX parts' share.
        let rl =
            (b.eval(wo, wi).x - b.eval_lobes(wo, wi).glossy.x - 0.5 / std::f32::consts::PI) * wi.z;
        assert!((rl - 0.25).abs() < 2e-3, "R_L {rl}");
    }

    #[test]
    fn quantise_is_exact_on_the_grid() {
        assert_eq!(quantise(0.5 + 1e-9, 16), 0.5);
        assert_eq!(quantise(-1.25, 16), -1.25);
    }
}
