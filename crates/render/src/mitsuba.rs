//! Export of a [`Scene`] to Mitsuba 3 (XML `version="3.0.0"` with binary PLY meshes and EXR
//! textures), so that the reference renderer can render the same picture as ours.
//!
//! [`export`] builds a [`MitsubaExport`] in memory (the XML text, one [`PlyMesh`] per material
//! group, the baked textures and the list of warnings); [`MitsubaExport::write`] writes it to a
//! folder (`scene.xml`, `meshes/*.ply`, `textures/*.exr`), each file through a temporary file
//! and a rename.
//!
//! # Mapping (docs/design.md, "Mitsuba 3 as the reference")
//!
//! | ours | Mitsuba 3 | exact? |
//! |---|---|---|
//! | point light (W/sr) | `point`, same `intensity` | yes; glTF `range` is ignored (warning) |
//! | spot light | `spot`, `intensity`, `cutoff_angle` = outer, `beam_width` = inner (degrees) | no: Mitsuba's falloff is linear in angle, glTF's smooth in cosine (warning) |
//! | directional light | `directional`, same `irradiance` | yes |
//! | emissive material | its mesh gets an `area` emitter of the same `radiance` | yes for one-sided emission; `doubleSided` emission is one-sided in Mitsuba (warning) |
//! | `ggx` | `blendbsdf` weight 0.5 of `diffuse` (reflectance 2 kd) and `roughconductor` (ggx, material none, alpha, specular_reflectance 2 ks); when 2 kd or 2 ks would exceed 1 (Mitsuba rejects it), the equivalent weight w = ks/(kd+ks) with reflectances kd/(1-w) and ks/w | yes (if kd + ks <= 1) |
//! | `ward` | the same blend with `beckmann` and the same alpha | no (warning) |
//! | `blinn_phong` | the same blend with `beckmann`, alpha = sqrt(2 / (s + 2)) | no (warning) |
//! | glTF metallic-roughness | `principled` (base_color, metallic, roughness) | no: different Fresnel and diffuse models (warning); metallicRoughnessTexture ignored (warning) |
//! | KHR_materials_transmission 1, metallic 0, with KHR_materials_volume | `dielectric` (roughness 0) or `roughdielectric` (ggx, alpha = roughness^2), `int_ior` = ior, `specular_transmittance` = base colour | no: exact Fresnel instead of Schlick's (warning); the volume's attenuation needs an interior medium, not exported (warning) |
//! | the same, thin-walled and smooth | `thindielectric` | no: a slab with two interfaces and its inter-reflections, ours one interface (warning) |
//! | other transmissive materials | `principled` (a volume) or `principledthin` (thin-walled) with `spec_trans` = transmission | no (warning) |
//! | KHR_materials_iridescence | not exported | no (warning) |
//! | KHR_materials_sheen (opaque glTF) | principled `sheen` = max3(sheenColor), `sheen_tint` 0 | no: Disney's white, Schlick-weighted sheen, not the Charlie lobe; sheenColor's hue, sheenRoughness and the textures are lost (warning); not exported on transmissive materials (warning) |
//! | diffuse | `diffuse` | yes |
//! | KHR_materials_unlit ([`Reflectance::Unlit`]) | `diffuse` of reflectance 0 and an `area` emitter of the base colour | yes (vertex colours are not exported, as for every material) |
//! | kd / base colour / emission texture | `bitmap` (an EXR of texture x factor, so the factor is baked in) | yes (bilinear, repeat) |
//! | wet/dry map ([`Wetness`](crate::material::Wetness)) | `alpha` and `specular_reflectance` as `bitmap`s baked per texel of the dryness map (`mix(wet, dry, w)`) | yes for `ggx` and `ward`'s alpha (linear in `w`, so bilinear filtering commutes); blinn_phong's alpha is not linear in the shininess (approximation already) |
//! | double-sided material | BSDF wrapped in `twosided` | yes |
//! | normal map ([`NormalMap`](crate::normal_map::NormalMap)), clearcoatNormalTexture | not exported | no (warning) |
//! | instanced mesh ([`Instances`]) | a `shapegroup` of its object-space meshes (one PLY per material) and an `instance` with its `to_world` matrix per placement | yes |
//! | perspective camera | `perspective`, `fov_axis` y, `fov` in degrees, `to_world` as a `lookat` | yes |
//! | orthographic camera | `orthographic`, `to_world` a `scale` by the half-width then a `lookat` moved back by `near_clip` (see [`sensor_xml`]) | yes |
//! | no camera | the default camera ([`Scene::default_camera`]) as a `perspective` camera | yes (warning) |
//! | constant environment ([`Environment::Constant`], also the default of a scene without lights) | `constant` with the same `radiance` | yes |
//! | environment map ([`Environment::Map`]) | `envmap` of the map's texels (written to `textures/environment.exr`), `scale` = strength, no `to_world` | yes: the same direction mapping, texel centres and bilinear lookup (a map of one row or column is written with it repeated) |
//! | film, filter | `hdrfilm` (rgb, float32) with a `box` filter | yes |
//! | integrator | `path` with the same `max_depth` (`volpath` with fog) | yes (Russian roulette differs: unbiased either way) |
//! | fog ([`Fog`]), homogeneous | `homogeneous` medium `fog` (`sigma_t` as RGB / its largest channel, times `scale`; `albedo`; `hg` phase with the same `g`), referenced by the sensor and as the `exterior` of shapes whose material has a volume | yes (Mitsuba's shadow rays estimate the transmittance by tracking, ours evaluate it: the same expectation) |
//! | fog with `height_falloff` | refused ([`MitsubaError::FogFalloff`]) | falloff is tested against quadrature in our own tests |
//! | sampler | `independent` with `sample_count` and `seed` | noise differs, expectation the same |
//!
//! Mitsuba's camera looks along +Z in its local frame with +X to the *left*; `lookat` with our
//! camera's origin, a target along its -Z and its +Y as up gives the same picture as ours
//! (checked by rendering: see tools/mitsuba/README.md).

use crate::bsdf;
use crate::camera::{Camera, Projection};
use crate::light::{Environment, Light};
use crate::material::{GltfPbrParams, Material, PaperModel, Reflectance};
use crate::medium::Fog;
use crate::scene::{Instances, Scene, SceneError, TriangleMesh};
use crate::texture::{Sampler, Texture, TextureId, TextureRef};
use glam::{Vec2, Vec3};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use streaks_image::exr::write_exr_rgb;
use streaks_image::{write_bytes_atomically, ImageError, RgbImage};

/// Errors of the Mitsuba export.
#[derive(Debug, thiserror::Error)]
pub enum MitsubaError {
    /// The scene has no camera of the requested name (or no camera at all).
    #[error(transparent)]
    Camera(#[from] SceneError),
    /// An option is out of range.
    #[error("invalid export option: {0}")]
    InvalidOption(String),
    /// A material refers to a texture the scene does not have.
    #[error("{file}: material {material:?} refers to texture {texture}, which does not exist")]
    MissingTexture {
        /// The scene file.
        file: PathBuf,
        /// The material's name.
        material: String,
        /// The texture index.
        texture: TextureId,
    },
    /// Creating the output folder failed.
    #[error("cannot create {path}")]
    Io {
        /// The folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Writing a file failed.
    #[error(transparent)]
    Output(#[from] ImageError),
    /// The scene's fog falls off with height, which Mitsuba's `homogeneous` medium cannot
    /// express.
    #[error(
        "{file}: extras.streaks.fog: height_falloff {falloff} cannot be exported (Mitsuba's \
         homogeneous medium has none); export the scene with a homogeneous fog"
    )]
    FogFalloff {
        /// The scene file.
        file: PathBuf,
        /// The fog's height falloff, per metre.
        falloff: f32,
    },
}

/// Render settings written into the Mitsuba scene (the same as `streaks render`'s).
#[derive(Clone, Debug, PartialEq)]
pub struct ExportOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Maximum path depth, Mitsuba's meaning (1: emitters only, 2: direct light, ...).
    pub max_depth: u32,
    /// Sampler seed.
    pub seed: u32,
    /// Camera name (`None`: the first camera).
    pub camera: Option<String>,
}

/// A triangle mesh in a binary little-endian PLY file (positions, normals, uvs).
#[derive(Clone, Debug, PartialEq)]
pub struct PlyMesh {
    /// File name relative to the export folder (e.g. `meshes/road.ply`).
    pub file_name: String,
    /// Vertex positions (world space).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (glTF convention, (0, 0) at the image's top-left).
    pub uvs: Vec<Vec2>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl PlyMesh {
    /// The PLY file's bytes: an ASCII header, then `float x y z nx ny nz u v` per vertex and
    /// `uchar 3, int i j k` per face, little-endian.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out =
            Vec::with_capacity(256 + self.positions.len() * 32 + self.triangles.len() * 13);
        let header = format!(
            "ply\nformat binary_little_endian 1.0\ncomment written by streaks export-mitsuba\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             property float u\nproperty float v\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.positions.len(),
            self.triangles.len()
        );
        out.extend_from_slice(header.as_bytes());
        for ((p, n), uv) in self.positions.iter().zip(&self.normals).zip(&self.uvs) {
            for v in [p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        for t in &self.triangles {
            out.push(3);
            for &i in t {
                out.extend_from_slice(&(i as i32).to_le_bytes());
            }
        }
        out
    }
}

/// A texture multiplied by a constant factor, written as a linear float EXR for a `bitmap`.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedTexture {
    /// File name relative to the export folder (e.g. `textures/mat0_kd.exr`).
    pub file_name: String,
    /// The linear RGB texels.
    pub image: RgbImage,
}

/// A Mitsuba scene ready to be written: the XML, its meshes and textures, and the warnings
/// about every approximation made.
#[derive(Clone, Debug)]
pub struct MitsubaExport {
    /// The scene XML (`scene.xml`).
    pub xml: String,
    /// One mesh per material that has triangles (and per instanced mesh and material).
    pub meshes: Vec<PlyMesh>,
    /// Textures referenced by `bitmap` elements.
    pub textures: Vec<BakedTexture>,
    /// Every approximation, one sentence each.
    pub warnings: Vec<String>,
}

impl MitsubaExport {
    /// Writes `scene.xml`, `meshes/*.ply` and `textures/*.exr` into `dir` (created if needed).
    /// Each file is written to a temporary file in its folder and renamed.
    pub fn write(&self, dir: &Path) -> Result<(), MitsubaError> {
        for sub in ["meshes", "textures"] {
            let d = dir.join(sub);
            std::fs::create_dir_all(&d).map_err(|source| MitsubaError::Io { path: d, source })?;
        }
        for mesh in &self.meshes {
            write_bytes_atomically(&dir.join(&mesh.file_name), &mesh.to_bytes())?;
        }
        for tex in &self.textures {
            write_exr_rgb(&dir.join(&tex.file_name), &tex.image)?;
        }
        Ok(write_bytes_atomically(
            &dir.join("scene.xml"),
            self.xml.as_bytes(),
        )?)
    }
}

/// What the exporter reads of a scene (everything but the BVH): a [`Scene`]'s fields, or an
/// instanced mesh's as an object of its own.
pub(crate) struct ExportedScene<'a> {
    pub(crate) source: &'a Path,
    pub(crate) mesh: &'a TriangleMesh,
    pub(crate) materials: &'a [Material],
    pub(crate) textures: &'a [Texture],
    pub(crate) lights: &'a [Light],
    pub(crate) instances: &'a Instances,
    pub(crate) environment: Option<&'a Environment>,
    pub(crate) fog: Option<&'a Fog>,
}

/// Converts `scene` to Mitsuba 3 with the render settings `opts`. A scene without a camera
/// is exported with its default camera ([`Scene::default_camera`] for the image's aspect
/// ratio), and a warning says so.
pub fn export(scene: &Scene, opts: &ExportOptions) -> Result<MitsubaExport, MitsubaError> {
    let parts = ExportedScene {
        source: &scene.source,
        mesh: &scene.mesh,
        materials: &scene.materials,
        textures: &scene.textures,
        lights: &scene.lights,
        instances: &scene.instances,
        environment: scene.environment(),
        fog: scene.fog.as_ref(),
    };
    match scene.find_camera(opts.camera.as_deref())? {
        Some(camera) => export_parts(&parts, camera, opts),
        None => {
            let aspect = opts.width as f32 / opts.height.max(1) as f32;
            let mut exported = export_parts(&parts, &scene.default_camera(aspect), opts)?;
            exported.warnings.insert(
                0,
                format!(
                    "{}: {}",
                    scene.source.display(),
                    crate::camera::FRAMING_WARNING
                ),
            );
            Ok(exported)
        }
    }
}

/// Escapes text for an XML attribute value.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// A file-name-safe version of a material name.
fn file_stem(index: usize, name: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .take(40)
        .collect();
    format!("m{index}_{clean}")
}

fn v3(v: Vec3) -> String {
    format!("{:?}, {:?}, {:?}", v.x, v.y, v.z)
}

/// The `blendbsdf` weight `w` (the roughconductor's share) for a paper material whose largest
/// diffuse and specular reflectances are `kd_max` and `ks_max`. The blend of diffuse with
/// reflectance `kd / (1 - w)` and roughconductor with `ks / w` equals ours, and Mitsuba requires
/// both reflectances to be at most 1. docs/design.md's mapping (w = 0.5: diffuse 2 kd, conductor
/// 2 ks) is used whenever it is valid; otherwise w = ks_max / (kd_max + ks_max). The flag is
/// false when kd_max + ks_max > 1, where no weight is exact.
fn blend_weight(kd_max: f32, ks_max: f32) -> (f32, bool) {
    if 2.0 * kd_max <= 1.0 && 2.0 * ks_max <= 1.0 {
        return (0.5, true);
    }
    let total = kd_max + ks_max;
    (ks_max / total, total <= 1.0)
}

fn rgb(name: &str, v: Vec3) -> String {
    format!(
        "<rgb name=\"{name}\" value=\"{:?}, {:?}, {:?}\"/>",
        v.x, v.y, v.z
    )
}

/// Context for one material's conversion: collects warnings and baked textures.
struct MaterialWriter<'a> {
    parts: &'a ExportedScene<'a>,
    warnings: &'a mut Vec<String>,
    textures: &'a mut Vec<BakedTexture>,
}

impl<'a> MaterialWriter<'a> {
    /// A `bitmap` texture parameter `name` of the given linear texels (written as
    /// `textures/{stem}_{name}.exr`).
    fn bitmap(&mut self, stem: &str, name: &str, tex: &Texture, texels: Vec<Vec3>) -> String {
        let file_name = format!("textures/{stem}_{name}.exr");
        self.textures.push(BakedTexture {
            file_name: file_name.clone(),
            image: RgbImage {
                width: tex.width,
                height: tex.height,
                pixels: texels,
            },
        });
        format!(
            "<texture type=\"bitmap\" name=\"{name}\">\
             <string name=\"filename\" value=\"{}\"/>\
             <string name=\"filter_type\" value=\"bilinear\"/>\
             <string name=\"wrap_mode\" value=\"repeat\"/>\
             <boolean name=\"raw\" value=\"true\"/></texture>",
            esc(&file_name)
        )
    }

    /// The scene texture `r` refers to in `material`, or a [`MitsubaError::MissingTexture`];
    /// a warning when the reference reads it other than as exported (TEXCOORD_0, repeat,
    /// bilinear, untransformed).
    fn texture(&mut self, material: &Material, r: TextureRef) -> Result<&'a Texture, MitsubaError> {
        if r.texcoord != 0 || r.sampler != Sampler::default() || r.transform.is_some() {
            self.warnings.push(format!(
                "material {:?}: texture {} is exported at TEXCOORD_0 with repeat wrapping and \
                 bilinear filtering, without its uv transform",
                material.name, r.texture
            ));
        }
        let id = r.texture;
        self.parts
            .textures
            .get(id as usize)
            .ok_or_else(|| MitsubaError::MissingTexture {
                file: self.parts.source.to_path_buf(),
                material: material.name.clone(),
                texture: id,
            })
    }

    /// A parameter that follows the dryness `w` (green channel of the wet/dry map, clamped to
    /// [0, 1] as the renderer does): a `bitmap` of `value(w)` per texel of the map.
    fn by_dryness(
        &mut self,
        material: &Material,
        stem: &str,
        name: &str,
        map: TextureRef,
        value: impl Fn(f32) -> Vec3,
    ) -> Result<String, MitsubaError> {
        let tex = self.texture(material, map)?;
        let texels = tex.texels().map(|t| value(t.y.clamp(0.0, 1.0))).collect();
        Ok(self.bitmap(stem, name, tex, texels))
    }

    /// A colour parameter: an `rgb`, or a `bitmap` of `texture x factor`.
    fn colour(
        &mut self,
        material: &Material,
        stem: &str,
        name: &str,
        factor: Vec3,
        texture: Option<TextureRef>,
    ) -> Result<String, MitsubaError> {
        let Some(id) = texture else {
            return Ok(rgb(name, factor));
        };
        let tex = self.texture(material, id)?;
        let texels = tex.texels().map(|t| t.truncate() * factor).collect();
        Ok(self.bitmap(stem, name, tex, texels))
    }

    /// An opaque glTF material as Mitsuba's `principled` BSDF (an approximation, warned about).
    fn principled(
        &mut self,
        m: &Material,
        stem: &str,
        g: &GltfPbrParams,
    ) -> Result<String, MitsubaError> {
        self.warnings.push(format!(
            "material {:?}: glTF metallic-roughness exported as Mitsuba's principled BSDF \
             (different Fresnel, diffuse and multiple-scattering terms: approximation)",
            m.name
        ));
        let unexported = [
            ("metallicRoughnessTexture", g.metallic_roughness_texture),
            ("specularTexture", g.specular_texture),
            ("specularColorTexture", g.specular_color_texture),
            ("clearcoatTexture", g.clearcoat_texture),
            ("clearcoatRoughnessTexture", g.clearcoat_roughness_texture),
            ("sheenColorTexture", g.sheen_color_texture),
            ("sheenRoughnessTexture", g.sheen_roughness_texture),
        ];
        if g.clearcoat > 0.0 && g.clearcoat_normal_map.is_some() {
            self.warnings.push(format!(
                "material {:?}: clearcoatNormalTexture is not exported; the coat is shaded \
                 with the interpolated normal",
                m.name
            ));
        }
        for (name, texture) in unexported {
            if texture.is_some() {
                self.warnings.push(format!(
                    "material {:?}: {name} is not exported; its factor is used everywhere",
                    m.name
                ));
            }
        }
        let base = self.colour(m, stem, "base_color", g.base_color, g.base_color_texture)?;
        let (specular, specular_color) = (g.specular, g.specular_color);
        let dielectric = principled_dielectric(specular, specular_color, g.ior);
        if !dielectric.exact {
            self.warnings.push(format!(
                "material {:?}: KHR_materials_specular's strength {specular} and colour \
                 {specular_color} become principled specular (F0 = 0.08 specular, \
                 grey, Fresnel 1 at grazing): approximation",
                m.name
            ));
        }
        let coat = if g.clearcoat > 0.0 {
            let alpha = g.clearcoat_roughness * g.clearcoat_roughness;
            let gloss = ((0.1 - alpha) / 0.099).clamp(0.0, 1.0);
            self.warnings.push(format!(
                "material {:?}: KHR_materials_clearcoat exported as principled clearcoat \
                 {:?} (Disney's coat, GTR1 of alpha 0.1 to 0.001, a quarter of the \
                 weight, over an unattenuated base) with clearcoat_gloss {gloss:?}: \
                 approximation",
                m.name,
                4.0 * g.clearcoat
            ));
            format!(
                "<float name=\"clearcoat\" value=\"{:?}\"/>\
                 <float name=\"clearcoat_gloss\" value=\"{gloss:?}\"/>",
                4.0 * g.clearcoat
            )
        } else {
            String::new()
        };
        if g.iridescence > 0.0 {
            self.warnings.push(format!(
                "material {:?}: KHR_materials_iridescence is not exported (Mitsuba's principled \
                 BSDF has no thin film); rendered without iridescence",
                m.name
            ));
        }
        let sheen = g.sheen_color.max_element();
        let sheen = if sheen > 0.0 {
            self.warnings.push(format!(
                "material {:?}: KHR_materials_sheen (colour {}, roughness {}) exported as                  principled sheen {sheen:?} (Disney's white sheen, Schlick-weighted, not the                  Charlie lobe; the colour's hue and the roughness are lost): approximation",
                m.name, g.sheen_color, g.sheen_roughness
            ));
            format!("<float name=\"sheen\" value=\"{sheen:?}\"/>")
        } else {
            String::new()
        };
        Ok(format!(
            "<bsdf type=\"principled\">{base}\
             <float name=\"metallic\" value=\"{:?}\"/>\
             <float name=\"roughness\" value=\"{:?}\"/>{}{sheen}{coat}</bsdf>",
            g.metallic, g.roughness, dielectric.xml
        ))
    }

    /// A glTF material with KHR_materials_transmission. A fully transmissive dielectric
    /// (transmission 1, metallic 0) becomes `dielectric` (smooth) or `roughdielectric` (GGX,
    /// `alpha = roughness^2`) when it has a volume, `thindielectric` when it is thin-walled and
    /// smooth, with `int_ior` the glTF ior and `specular_transmittance` the base colour; any
    /// other transmissive material becomes `principled` (a volume) or `principledthin`
    /// (thin-walled) with `spec_trans` the transmission. Each approximation is warned about:
    /// Mitsuba's dielectrics use the exact Fresnel equations (glTF: Schlick's), its
    /// `thindielectric` is a slab with two interfaces and its inter-reflections (ours: one
    /// interface, light going straight through), `principledthin` scales the transmission's
    /// roughness, and the volume's absorption needs an interior medium on the shape, which is
    /// not exported.
    fn transmissive(
        &mut self,
        m: &Material,
        stem: &str,
        g: &GltfPbrParams,
    ) -> Result<String, MitsubaError> {
        let name = &m.name;
        let smooth = g.roughness * g.roughness <= bsdf::MIN_ALPHA;
        let eta = if g.ior >= 1.0 { g.ior } else { 1.5 };
        if g.transmission_texture.is_some() {
            self.warnings.push(format!(
                "material {name:?}: transmissionTexture is not exported; its factor is used \
                 everywhere"
            ));
        }
        if g.sheen_color.max_element() > 0.0 {
            self.warnings.push(format!(
                "material {name:?}: KHR_materials_sheen is not exported on a transmissive \
                 material; rendered without sheen"
            ));
        }
        if g.iridescence > 0.0 {
            self.warnings.push(format!(
                "material {name:?}: KHR_materials_iridescence is not exported; rendered \
                 without iridescence"
            ));
        }
        if let Some(v) = g.volume {
            if v.sigma_a != Vec3::ZERO {
                self.warnings.push(format!(
                    "material {name:?}: KHR_materials_volume's attenuation is not exported \
                     (Mitsuba needs an interior medium on the shape); rendered clear"
                ));
            }
        }
        let full = g.transmission >= 1.0 && g.metallic <= 0.0;
        if !full || (g.volume.is_none() && !smooth) {
            let kind = if g.volume.is_some() {
                "principled"
            } else {
                "principledthin"
            };
            self.warnings.push(format!(
                "material {name:?}: KHR_materials_transmission {} exported as Mitsuba's {kind} \
                 BSDF with spec_trans (its own Fresnel, diffuse and transmission roughness): \
                 approximation",
                g.transmission
            ));
            let base = self.colour(m, stem, "base_color", g.base_color, g.base_color_texture)?;
            let metallic = if kind == "principled" {
                format!("<float name=\"metallic\" value=\"{:?}\"/>", g.metallic)
            } else {
                String::new()
            };
            return Ok(format!(
                "<bsdf type=\"{kind}\">{base}{metallic}\
                 <float name=\"roughness\" value=\"{:?}\"/>\
                 <float name=\"spec_trans\" value=\"{:?}\"/>\
                 <float name=\"eta\" value=\"{eta:?}\"/></bsdf>",
                g.roughness, g.transmission
            ));
        }
        let tint = self.colour(
            m,
            stem,
            "specular_transmittance",
            g.base_color,
            g.base_color_texture,
        )?;
        let ior = format!("<float name=\"int_ior\" value=\"{eta:?}\"/>");
        self.warnings.push(format!(
            "material {name:?}: KHR_materials_transmission exported as a Mitsuba dielectric \
             (exact Fresnel instead of glTF's Schlick approximation)"
        ));
        Ok(match (g.volume.is_some(), smooth) {
            (true, true) => format!("<bsdf type=\"dielectric\">{ior}{tint}</bsdf>"),
            (true, false) => format!(
                "<bsdf type=\"roughdielectric\">\
                 <string name=\"distribution\" value=\"ggx\"/>\
                 <float name=\"alpha\" value=\"{:?}\"/>{ior}{tint}</bsdf>",
                g.roughness * g.roughness
            ),
            _ => {
                self.warnings.push(format!(
                    "material {name:?}: thin-walled transmission exported as Mitsuba's \
                     thindielectric, a slab with two interfaces and its inter-reflections \
                     (streaks: one interface): approximation"
                ));
                format!("<bsdf type=\"thindielectric\">{ior}{tint}</bsdf>")
            }
        })
    }

    /// The `<bsdf>` element of a material.
    fn bsdf(&mut self, index: usize, m: &Material) -> Result<String, MitsubaError> {
        let stem = file_stem(index, &m.name);
        if !m.alpha.is_opaque() {
            self.warnings.push(format!(
                "material {:?}: alphaMode {:?} is not exported (rendered opaque)",
                m.name, m.alpha.mode
            ));
        }
        let mut out = String::new();
        match &m.reflectance {
            Reflectance::Diffuse { kd, kd_texture } => {
                let refl = self.colour(m, &stem, "reflectance", *kd, *kd_texture)?;
                let _ = write!(out, "<bsdf type=\"diffuse\">{refl}</bsdf>");
            }
            // Black: an unlit surface is seen by its emission, exported as an area emitter.
            Reflectance::Unlit => {
                let black = rgb("reflectance", Vec3::ZERO);
                let _ = write!(out, "<bsdf type=\"diffuse\">{black}</bsdf>");
            }
            Reflectance::Paper {
                model,
                kd,
                ks,
                alpha,
                shininess,
                kd_texture,
                wetness,
                retro,
            } => {
                if retro.is_some() {
                    self.warnings.push(format!(
                        "material {:?}: Mitsuba has no retroreflective model; exported \
                         without its glass beads' cone (darker under lights near the camera)",
                        m.name
                    ));
                }
                // Mitsuba's alpha for our alpha (or, for blinn_phong, shininess).
                let to_alpha = |a: f32| match model {
                    PaperModel::Ggx | PaperModel::Ward => a,
                    PaperModel::BlinnPhong => (2.0 / (a + 2.0)).sqrt(),
                };
                let (distribution, a) = match model {
                    PaperModel::Ggx => ("ggx", *alpha),
                    PaperModel::Ward => {
                        self.warnings.push(format!(
                            "material {:?}: Mitsuba has no Ward model; exported as a beckmann \
                             roughconductor with the same alpha ({alpha}) (approximation)",
                            m.name
                        ));
                        ("beckmann", *alpha)
                    }
                    PaperModel::BlinnPhong => {
                        let a = to_alpha(*shininess);
                        self.warnings.push(format!(
                            "material {:?}: Mitsuba has no Blinn-Phong model; exported as a \
                             beckmann roughconductor with alpha = sqrt(2/(s+2)) = {a} \
                             (approximation)",
                            m.name
                        ));
                        ("beckmann", a)
                    }
                };
                // The largest ks anywhere on the surface sets the blend weight.
                let ks_max = wetness
                    .as_ref()
                    .map_or(*ks, |wet| ks.max(wet.ks_dry))
                    .max_element();
                let (w, exact) = blend_weight(kd.max_element(), ks_max);
                if !exact {
                    self.warnings.push(format!(
                        "material {:?}: kd + ks exceeds 1, which Mitsuba's blendbsdf cannot \
                         express; the exported reflectances are clipped to 1 (darker)",
                        m.name
                    ));
                }
                let scale = |c: Vec3, share: f32| {
                    if share > 0.0 {
                        (c / share).min(Vec3::ONE)
                    } else {
                        Vec3::ZERO
                    }
                };
                let diffuse =
                    self.colour(m, &stem, "reflectance", scale(*kd, 1.0 - w), *kd_texture)?;
                let (alpha_xml, specular) = match wetness {
                    None => (
                        format!("<float name=\"alpha\" value=\"{a:?}\"/>"),
                        rgb("specular_reflectance", scale(*ks, w)),
                    ),
                    Some(wet) => {
                        let own = match model {
                            PaperModel::BlinnPhong => *shininess,
                            PaperModel::Ggx | PaperModel::Ward => *alpha,
                        };
                        let alpha_at = |dry: f32| own + (wet.alpha_dry - own) * dry;
                        (
                            self.by_dryness(m, &stem, "alpha", wet.texture, |dry| {
                                Vec3::splat(to_alpha(alpha_at(dry)))
                            })?,
                            self.by_dryness(
                                m,
                                &stem,
                                "specular_reflectance",
                                wet.texture,
                                |dry| scale(ks.lerp(wet.ks_dry, dry), w),
                            )?,
                        )
                    }
                };
                let _ = write!(
                    out,
                    "<bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"{w:?}\"/>\
                     <bsdf type=\"diffuse\">{diffuse}</bsdf>\
                     <bsdf type=\"roughconductor\">\
                     <string name=\"distribution\" value=\"{distribution}\"/>\
                     <string name=\"material\" value=\"none\"/>\
                     {alpha_xml}{specular}</bsdf></bsdf>"
                );
            }
            Reflectance::GltfPbr(g) => {
                if g.transmission > 0.0 {
                    out = self.transmissive(m, &stem, g)?;
                } else {
                    out = self.principled(m, &stem, g)?;
                }
            }
        }
        if m.normal_map.is_some() {
            self.warnings.push(format!(
                "material {:?}: its normal map is not exported; Mitsuba shades it with the \
                 interpolated normals",
                m.name
            ));
        }
        if m.double_sided {
            out = format!("<bsdf type=\"twosided\">{out}</bsdf>");
        }
        Ok(out)
    }
}

/// How a glTF dielectric's reflectance is written for Mitsuba's principled BSDF, and whether
/// that is exact up to the principled model's own Fresnel.
struct PrincipledDielectric {
    /// Nothing (the principled default, eta 1.5, glTF's default), `eta` or `specular`.
    xml: String,
    exact: bool,
}

/// The principled BSDF's `eta` or `specular` (F0 = 0.08 specular; the two cannot both be
/// given) for KHR_materials_specular's strength and colour and KHR_materials_ior's index: the
/// glTF default writes nothing, a white specular colour at full strength the `eta`, and any
/// other combination the `specular` of the largest channel of glTF's F0 (exact only at
/// strength 0, a pure diffuse dielectric in both).
fn principled_dielectric(specular: f32, specular_color: Vec3, ior: f32) -> PrincipledDielectric {
    if specular == 1.0 && specular_color == Vec3::ONE && ior >= 1.0 {
        let xml = if ior == 1.5 {
            String::new()
        } else {
            format!("<float name=\"eta\" value=\"{ior:?}\"/>")
        };
        return PrincipledDielectric { xml, exact: true };
    }
    let f0 = specular
        * (bsdf::ior_f0(ior) * specular_color)
            .min(Vec3::ONE)
            .max_element();
    // Mitsuba's eta from specular, 2 / (1 - sqrt(0.08 specular)) - 1, needs F0 below 1.
    let principled = (f0 / 0.08).min(12.4);
    PrincipledDielectric {
        xml: format!("<float name=\"specular\" value=\"{principled:?}\"/>"),
        exact: specular == 0.0,
    }
}

/// The emitter element of a punctual light.
fn light_xml(light: &Light, warnings: &mut Vec<String>) -> String {
    match *light {
        Light::Point {
            position,
            intensity,
            range,
        } => {
            if range.is_some() {
                warnings.push(format!(
                    "point light at {position}: glTF range is not exported (Mitsuba's point \
                     light has no range)"
                ));
            }
            format!(
                "<emitter type=\"point\"><point name=\"position\" value=\"{}\"/>{}</emitter>",
                v3(position),
                rgb("intensity", intensity)
            )
        }
        Light::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
            range,
        } => {
            warnings.push(format!(
                "spot light at {position}: Mitsuba's spot falloff is linear in angle between \
                 beam_width and cutoff_angle, glTF's is smooth in cosine (approximation)"
            ));
            if range.is_some() {
                warnings.push(format!(
                    "spot light at {position}: glTF range is not exported"
                ));
            }
            let outer = cos_outer.clamp(-1.0, 1.0).acos().to_degrees();
            let inner = cos_inner.clamp(-1.0, 1.0).acos().to_degrees().min(outer);
            let up = if direction.y.abs() < 0.9 {
                Vec3::Y
            } else {
                Vec3::X
            };
            format!(
                "<emitter type=\"spot\"><transform name=\"to_world\">\
                 <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>{}\
                 <float name=\"cutoff_angle\" value=\"{outer:?}\"/>\
                 <float name=\"beam_width\" value=\"{inner:?}\"/></emitter>",
                v3(position),
                v3(position + direction),
                v3(up),
                rgb("intensity", intensity)
            )
        }
        Light::Directional {
            direction,
            irradiance,
        } => format!(
            "<emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/>{}</emitter>",
            v3(direction),
            rgb("irradiance", irradiance)
        ),
    }
}

/// Mitsuba's default `near_clip` of an orthographic sensor, where its rays start (see
/// [`sensor_xml`]).
const ORTHO_NEAR_CLIP: f32 = 0.01;

/// The `<sensor>` element: our camera as a Mitsuba `perspective` or `orthographic` camera.
///
/// Mitsuba's orthographic sensor (src/sensors/orthographic.cpp and `orthographic_projection`
/// in include/mitsuba/render/sensor.h) maps the film to local x in [-1, 1] (the width) and
/// y in [-1/a, 1/a] (a = W/H, so pixels are square), and starts its rays at local
/// z = `near_clip` along +Z. So `to_world` = `lookat` x `scale(k, k, 1)` with `k` our
/// half-width `s W / 2` gives our rectangle (`s` the pixel size,
/// [`Camera::pixel_metres`]), and the lookat origin is moved back by `near_clip` so that
/// the rays start on our camera plane.
fn sensor_xml(cam: &Camera, opts: &ExportOptions, medium: Option<&str>) -> String {
    let origin = cam.position();
    let forward = cam
        .world_from_camera
        .transform_vector3(-Vec3::Z)
        .normalize();
    let up = cam.world_from_camera.transform_vector3(Vec3::Y).normalize();
    // (type, its parameters, a scale before the lookat, the lookat origin)
    let (kind, projection, scale, origin) = match cam.projection {
        Projection::Perspective { yfov, .. } => (
            "perspective",
            format!(
                "<string name=\"fov_axis\" value=\"y\"/>\
                 <float name=\"fov\" value=\"{:?}\"/>",
                yfov.to_degrees()
            ),
            String::new(),
            origin,
        ),
        Projection::Orthographic { .. } => {
            let pixel = cam.pixel_metres(opts.width, opts.height).unwrap_or(0.0);
            let k = 0.5 * opts.width as f32 * pixel;
            (
                "orthographic",
                format!("<float name=\"near_clip\" value=\"{ORTHO_NEAR_CLIP:?}\"/>"),
                format!("<scale x=\"{k:?}\" y=\"{k:?}\"/>"),
                origin - ORTHO_NEAR_CLIP * forward,
            )
        }
    };
    let medium = medium.map_or(String::new(), |id| format!("<ref id=\"{id}\"/>"));
    format!(
        "<sensor type=\"{kind}\">{medium}{projection}\
         <transform name=\"to_world\">{scale}<lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>\
         <sampler type=\"independent\"><integer name=\"sample_count\" value=\"{}\"/>\
         <integer name=\"seed\" value=\"{}\"/></sampler>\
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/>\
         <integer name=\"height\" value=\"{}\"/>\
         <string name=\"pixel_format\" value=\"rgb\"/>\
         <string name=\"component_format\" value=\"float32\"/>\
         <rfilter type=\"box\"/></film></sensor>",
        v3(origin),
        v3(origin + forward),
        v3(up),
        opts.spp,
        opts.seed,
        opts.width,
        opts.height
    )
}

/// Splits the triangle soup into one mesh per material, with compact vertex arrays.
fn meshes_by_material(parts: &ExportedScene<'_>) -> Vec<(usize, PlyMesh)> {
    let mut groups: Vec<Option<(HashMap<u32, u32>, PlyMesh)>> =
        (0..parts.materials.len()).map(|_| None).collect();
    let flat = parts.mesh;
    for (tri, &mat) in flat.triangles.iter().zip(&flat.triangle_materials) {
        let Some(slot) = groups.get_mut(mat as usize) else {
            continue;
        };
        let (remap, mesh) = slot.get_or_insert_with(|| {
            (
                HashMap::new(),
                PlyMesh {
                    file_name: format!(
                        "meshes/{}.ply",
                        file_stem(mat as usize, &parts.materials[mat as usize].name)
                    ),
                    positions: Vec::new(),
                    normals: Vec::new(),
                    uvs: Vec::new(),
                    triangles: Vec::new(),
                },
            )
        });
        let mut local = [0u32; 3];
        for (k, &v) in tri.iter().enumerate() {
            local[k] = *remap.entry(v).or_insert_with(|| {
                let i = v as usize;
                mesh.positions.push(flat.positions[i]);
                mesh.normals
                    .push(flat.normals.get(i).copied().unwrap_or(Vec3::ZERO));
                mesh.uvs
                    .push(flat.uvs.get(i).copied().unwrap_or(Vec2::ZERO));
                (mesh.positions.len() - 1) as u32
            });
        }
        mesh.triangles.push(local);
    }
    groups
        .into_iter()
        .enumerate()
        .filter_map(|(i, g)| g.map(|(_, mesh)| (i, mesh)))
        .collect()
}

/// The `id` of the exported fog's `<medium>`.
const FOG_ID: &str = "fog";

/// The fog as a Mitsuba `homogeneous` medium with an `hg` phase function: `sigma_t` as an RGB
/// in [0, 1] (its largest channel 1) times `scale` (the plugin asks for RGB extinction in
/// [0, 1]), `albedo`, `g`. A fog that falls off with height is refused
/// ([`MitsubaError::FogFalloff`]).
fn fog_xml(source: &Path, fog: &Fog) -> Result<String, MitsubaError> {
    if fog.height_falloff() != 0.0 {
        return Err(MitsubaError::FogFalloff {
            file: source.to_path_buf(),
            falloff: fog.height_falloff(),
        });
    }
    let sigma = fog.sigma_t();
    let scale = sigma.max_element();
    let unit = if scale > 0.0 {
        sigma / scale
    } else {
        Vec3::ZERO
    };
    Ok(format!(
        "<medium type=\"homogeneous\" id=\"{FOG_ID}\">{}<float name=\"scale\" value=\"{scale:?}\"/>\
         {}<phase type=\"hg\"><float name=\"g\" value=\"{:?}\"/></phase></medium>",
        rgb("sigma_t", unit),
        rgb("albedo", fog.albedo()),
        fog.phase().g
    ))
}

/// `<ref name="exterior" id="fog"/>` for a shape whose material has a volume (which the path
/// tracer enters through its front face and leaves into the fog), when the scene has fog;
/// else nothing. Thin-walled and opaque shapes keep the path's medium, as ours do.
fn exterior_xml(parts: &ExportedScene<'_>, m: &Material) -> String {
    if parts.fog.is_some() && m.volume().is_some() {
        format!("<ref name=\"exterior\" id=\"{FOG_ID}\"/>")
    } else {
        String::new()
    }
}

/// [`export`] on the parts of a scene, with the camera already chosen.
pub(crate) fn export_parts(
    parts: &ExportedScene<'_>,
    camera: &Camera,
    opts: &ExportOptions,
) -> Result<MitsubaExport, MitsubaError> {
    if opts.width == 0 || opts.height == 0 || opts.spp == 0 || opts.max_depth == 0 {
        return Err(MitsubaError::InvalidOption(format!(
            "width, height, spp and max_depth must be positive (got {}x{}, {} spp, depth {})",
            opts.width, opts.height, opts.spp, opts.max_depth
        )));
    }
    let mut warnings = Vec::new();
    let mut textures = Vec::new();
    let mut xml = String::new();
    let _ = writeln!(
        xml,
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n\
         <!-- Exported by streaks export-mitsuba from {} -->\n<scene version=\"3.0.0\">",
        esc(&parts.source.display().to_string()).replace("--", "- -")
    );
    let integrator = if parts.fog.is_some() {
        "volpath"
    } else {
        "path"
    };
    let _ = writeln!(
        xml,
        "<integrator type=\"{integrator}\"><integer name=\"max_depth\" value=\"{}\"/></integrator>",
        opts.max_depth
    );
    if let Some(fog) = parts.fog {
        let _ = writeln!(xml, "{}", fog_xml(parts.source, fog)?);
    }
    let fog_ref = parts.fog.map(|_| FOG_ID);
    let _ = writeln!(xml, "{}", sensor_xml(camera, opts, fog_ref));
    for light in parts.lights {
        let _ = writeln!(xml, "{}", light_xml(light, &mut warnings));
    }
    match parts.environment {
        None => {}
        Some(Environment::Constant { radiance }) => {
            let _ = writeln!(
                xml,
                "<emitter type=\"constant\">{}</emitter>",
                rgb("radiance", *radiance)
            );
        }
        Some(Environment::Map(map)) => {
            let file_name = "textures/environment.exr".to_string();
            let _ = writeln!(
                xml,
                "<emitter type=\"envmap\"><string name=\"filename\" value=\"{}\"/>\
                 <float name=\"scale\" value=\"{}\"/></emitter>",
                esc(&file_name),
                map.strength()
            );
            textures.push(BakedTexture {
                file_name,
                image: map.texels(),
            });
        }
    }
    let mut meshes = meshes_by_material(parts);
    let mut mw = MaterialWriter {
        parts,
        warnings: &mut warnings,
        textures: &mut textures,
    };
    // Each material's BSDF is made once (its textures baked once), whichever meshes use it.
    let mut bsdfs: HashMap<usize, String> = HashMap::new();
    let mut bsdf_of = |mw: &mut MaterialWriter, index: usize| -> Result<String, MitsubaError> {
        if let Some(b) = bsdfs.get(&index) {
            return Ok(b.clone());
        }
        let b = mw.bsdf(index, &parts.materials[index])?;
        bsdfs.insert(index, b.clone());
        Ok(b)
    };
    for (index, mesh) in &meshes {
        let m = &parts.materials[*index];
        let bsdf = bsdf_of(&mut mw, *index)?;
        let mut emitter = String::new();
        if m.is_emissive() {
            if m.double_sided {
                mw.warnings.push(format!(
                    "material {:?}: doubleSided emission; Mitsuba's area emitters are one-sided \
                     (only the front face emits)",
                    m.name
                ));
            }
            let stem = file_stem(*index, &m.name);
            let radiance = mw.colour(m, &stem, "radiance", m.emission, m.emission_texture)?;
            emitter = format!("<emitter type=\"area\">{radiance}</emitter>");
        }
        // Our emission is one-sided by the geometric normal (the winding); Mitsuba's area
        // emitter tests the shading normal, which on a smooth lamp mesh darkens the rim (0.2% of
        // a sphere lamp's streak on scenes/crosscheck.gltf). Face normals make the two agree.
        let face_normals = m.is_emissive();
        let exterior = exterior_xml(parts, m);
        let _ = writeln!(
            xml,
            "<shape type=\"ply\"><string name=\"filename\" value=\"{}\"/>\
             <boolean name=\"face_normals\" value=\"{face_normals}\"/>{bsdf}{emitter}{exterior}</shape>",
            esc(&mesh.file_name)
        );
    }
    for (k, instanced) in parts.instances.meshes.iter().enumerate() {
        let object = ExportedScene {
            mesh: &instanced.mesh,
            ..*parts
        };
        let _ = write!(xml, "<shape type=\"shapegroup\" id=\"instanced{k}\">");
        for (index, mut mesh) in meshes_by_material(&object) {
            mesh.file_name = mesh
                .file_name
                .replacen("meshes/", &format!("meshes/i{k}_"), 1);
            let bsdf = bsdf_of(&mut mw, index)?;
            let exterior = exterior_xml(parts, &parts.materials[index]);
            let _ = write!(
                xml,
                "<shape type=\"ply\"><string name=\"filename\" value=\"{}\"/>{bsdf}{exterior}</shape>",
                esc(&mesh.file_name)
            );
            meshes.push((index, mesh));
        }
        let _ = writeln!(xml, "</shape>");
    }
    for inst in &parts.instances.instances {
        let m = glam::Mat4::from(inst.world_from_object)
            .transpose()
            .to_cols_array();
        let values: Vec<String> = m.iter().map(|v| format!("{v:?}")).collect();
        let _ = writeln!(
            xml,
            "<shape type=\"instance\"><ref id=\"instanced{}\"/><transform name=\"to_world\">\
             <matrix value=\"{}\"/></transform></shape>",
            inst.mesh,
            values.join(" ")
        );
    }
    xml.push_str("</scene>\n");
    Ok(MitsubaExport {
        xml,
        meshes: meshes.into_iter().map(|(_, m)| m).collect(),
        textures,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Wetness;
    use crate::scene::SceneParts;
    use crate::texture::ColorSpace;
    use glam::{Affine3A, Vec4};

    fn mat(name: &str, reflectance: Reflectance, emission: Vec3) -> Material {
        Material {
            name: name.into(),
            reflectance,
            emission,
            emission_texture: None,
            normal_map: None,
            double_sided: false,
            alpha: crate::material::Alpha::OPAQUE,
            road: false,
        }
    }

    struct Fixture {
        mesh: TriangleMesh,
        materials: Vec<Material>,
        textures: Vec<Texture>,
        lights: Vec<Light>,
        cameras: Vec<Camera>,
        instances: Instances,
    }

    impl Fixture {
        fn new() -> Self {
            // Two quads (road at y = 0, lamp at y = 3) and a wall triangle.
            let positions = vec![
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(-1.0, 0.0, 1.0),
                Vec3::new(0.0, 3.0, 0.0),
                Vec3::new(0.1, 3.0, 0.0),
                Vec3::new(0.0, 3.0, 0.1),
                Vec3::new(0.0, 0.0, -2.0),
                Vec3::new(1.0, 0.0, -2.0),
                Vec3::new(0.0, 1.0, -2.0),
            ];
            let n = positions.len();
            let ggx = Reflectance::Paper {
                model: PaperModel::Ggx,
                kd: Vec3::splat(0.05),
                ks: Vec3::splat(0.04),
                alpha: 0.1,
                shininess: 0.0,
                kd_texture: Some(TextureRef::new(0)),
                wetness: Some(Wetness {
                    texture: TextureRef::new(0),
                    alpha_dry: 0.5,
                    ks_dry: Vec3::splat(0.02),
                }),
                retro: None,
            };
            let lamp = Reflectance::Diffuse {
                kd: Vec3::ZERO,
                kd_texture: None,
            };
            let wall = Reflectance::Paper {
                model: PaperModel::Ward,
                kd: Vec3::splat(0.3),
                ks: Vec3::splat(0.1),
                alpha: 0.2,
                shininess: 0.0,
                kd_texture: None,
                wetness: None,
                retro: None,
            };
            Fixture {
                mesh: TriangleMesh {
                    positions,
                    normals: vec![Vec3::Y; n],
                    uvs: vec![Vec2::new(0.25, 0.75); n],
                    triangles: vec![[0, 2, 1], [0, 3, 2], [4, 6, 5], [7, 8, 9]],
                    triangle_materials: vec![0, 0, 1, 2],
                    ..TriangleMesh::default()
                },
                materials: vec![
                    mat("road & <wet>", ggx, Vec3::ZERO),
                    mat("lamp", lamp, Vec3::new(10.0, 9.0, 8.0)),
                    mat("wall", wall, Vec3::ZERO),
                ],
                textures: vec![Texture::from_rgba(
                    2,
                    1,
                    vec![Vec4::new(1.0, 0.5, 0.25, 1.0), Vec4::ONE],
                    ColorSpace::Linear,
                )
                .unwrap()],
                lights: vec![
                    Light::Point {
                        position: Vec3::new(0.0, 5.0, -3.0),
                        intensity: Vec3::new(100.0, 90.0, 80.0),
                        range: None,
                    },
                    Light::Spot {
                        position: Vec3::new(2.0, 5.0, 0.0),
                        direction: Vec3::NEG_Y,
                        intensity: Vec3::splat(50.0),
                        cos_inner: 0.9,
                        cos_outer: 0.8,
                        range: Some(20.0),
                    },
                ],
                cameras: vec![Camera::perspective(
                    "cam",
                    Affine3A::from_translation(Vec3::new(0.0, 1.5, 4.0)),
                    0.7,
                    None,
                )],
                instances: Instances::default(),
            }
        }

        fn parts(&self) -> ExportedScene<'_> {
            ExportedScene {
                source: Path::new("test.gltf"),
                mesh: &self.mesh,
                materials: &self.materials,
                textures: &self.textures,
                lights: &self.lights,
                instances: &self.instances,
                environment: None,
                fog: None,
            }
        }
    }

    fn opts() -> ExportOptions {
        ExportOptions {
            width: 64,
            height: 48,
            spp: 16,
            max_depth: 5,
            seed: 7,
            camera: Some("cam".into()),
        }
    }

    fn floats(s: &str) -> Vec<f32> {
        s.split(',').map(|x| x.trim().parse().unwrap()).collect()
    }

    /// An instanced mesh is written once, in object space, as a `shapegroup`, and each
    /// placement as an `instance` with its `to_world` matrix (row-major).
    #[test]
    fn instanced_meshes_are_shapegroups_with_one_instance_per_placement() {
        let fx = Fixture::new();
        let tri = TriangleMesh {
            name: "mesh \"tri\" (0)".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 2]],
            triangle_materials: vec![0],
            ..Default::default()
        };
        let moves = [Vec3::new(0.0, 0.0, -3.0), Vec3::new(2.0, 0.0, -3.0)];
        let scene = Scene::from_parts(SceneParts {
            source: "inst.gltf".into(),
            materials: fx.materials.clone(),
            textures: fx.textures.clone(),
            cameras: fx.cameras.clone(),
            instanced_meshes: vec![tri],
            instances: moves
                .iter()
                .map(|&t| {
                    let m =
                        glam::Mat4::from_translation(t) * glam::Mat4::from_scale(Vec3::splat(2.0));
                    crate::scene::Instance::new(0, m).unwrap()
                })
                .collect(),
            ..Default::default()
        })
        .unwrap();
        let ex = export(&scene, &opts()).unwrap();
        let doc = roxmltree::Document::parse(&ex.xml).unwrap();
        let of_type = |ty: &str| {
            doc.descendants()
                .filter(|n| n.has_tag_name("shape") && n.attribute("type") == Some(ty))
                .collect::<Vec<_>>()
        };
        let groups = of_type("shapegroup");
        assert_eq!(groups.len(), 1);
        assert_eq!(groups[0].attribute("id"), Some("instanced0"));
        let ply: Vec<_> = groups[0]
            .children()
            .filter(|n| n.has_tag_name("shape"))
            .collect();
        assert_eq!(ply.len(), 1);
        assert!(ply[0].children().any(|n| n.has_tag_name("bsdf")));
        assert_eq!(ex.meshes.len(), 1);
        assert!(
            ex.meshes[0].file_name.starts_with("meshes/i0_"),
            "{}",
            ex.meshes[0].file_name
        );
        assert_eq!(ex.meshes[0].positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
        let instances = of_type("instance");
        assert_eq!(instances.len(), 2);
        for (inst, t) in instances.iter().zip(moves) {
            let matrix = inst
                .descendants()
                .find(|n| n.has_tag_name("matrix"))
                .and_then(|n| n.attribute("value"))
                .unwrap();
            let v: Vec<f32> = matrix.split(' ').map(|x| x.parse().unwrap()).collect();
            assert_eq!(
                v,
                [2., 0., 0., t.x, 0., 2., 0., t.y, 0., 0., 2., t.z, 0., 0., 0., 1.]
            );
            assert!(inst
                .descendants()
                .any(|n| n.attribute("id") == Some("instanced0")));
        }
    }

    /// An unlit material exports as the fixture's lamp does: a black diffuse BSDF and an area
    /// emitter of its emission (the base colour).
    #[test]
    fn unlit_materials_are_black_with_an_area_emitter() {
        let fx = Fixture::new();
        let lamp = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
        let mut unlit = Fixture::new();
        unlit.materials[1].reflectance = Reflectance::Unlit;
        let ex = export_parts(&unlit.parts(), &unlit.cameras[0], &opts()).unwrap();
        assert_eq!(ex.xml, lamp.xml);
        assert!(ex.xml.contains("<emitter type=\"area\">"), "{}", ex.xml);
    }

    #[test]
    fn fog_exports_as_a_homogeneous_medium_the_sensor_refers_to() {
        let fx = Fixture::new();
        let fog = Fog::homogeneous(Vec3::new(0.02, 0.04, 0.05), Vec3::splat(0.9), 0.7).unwrap();
        let parts = ExportedScene {
            fog: Some(&fog),
            ..fx.parts()
        };
        let ex = export_parts(&parts, &fx.cameras[0], &opts()).unwrap();
        let doc = roxmltree::Document::parse(&ex.xml).unwrap();
        let medium = doc
            .descendants()
            .find(|n| n.has_tag_name("medium"))
            .unwrap();
        assert_eq!(medium.attribute("type"), Some("homogeneous"));
        assert_eq!(medium.attribute("id"), Some("fog"));
        let value = |name: &str| {
            medium
                .descendants()
                .find(|c| c.attribute("name") == Some(name))
                .and_then(|c| c.attribute("value"))
                .unwrap()
                .to_owned()
        };
        let unit = floats(&value("sigma_t"));
        let scale: f32 = value("scale").parse().unwrap();
        for (c, want) in [0.02f32, 0.04, 0.05].into_iter().enumerate() {
            assert!((unit[c] * scale - want).abs() < 1e-7, "{unit:?} x {scale}");
        }
        assert_eq!(floats(&value("albedo")), [0.9, 0.9, 0.9]);
        assert_eq!(value("g"), "0.7");
        let sensor = doc
            .descendants()
            .find(|n| n.has_tag_name("sensor"))
            .unwrap();
        assert!(sensor
            .children()
            .any(|c| c.has_tag_name("ref") && c.attribute("id") == Some("fog")));
        let integrator = doc.descendants().find(|n| n.has_tag_name("integrator"));
        assert_eq!(integrator.unwrap().attribute("type"), Some("volpath"));
        // A fog that thins with height is refused, naming the file.
        let falling = Fog::new(Vec3::splat(0.1), Vec3::ONE, 0.0, 0.2, 0.0).unwrap();
        let parts = ExportedScene {
            fog: Some(&falling),
            ..fx.parts()
        };
        let err = export_parts(&parts, &fx.cameras[0], &opts()).unwrap_err();
        assert!(matches!(err, MitsubaError::FogFalloff { .. }), "{err}");
        assert!(err.to_string().contains("test.gltf"), "{err}");
    }

    #[test]
    fn xml_is_well_formed_and_has_the_mapped_elements() {
        let fx = Fixture::new();
        let ex = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
        let doc = roxmltree::Document::parse(&ex.xml).unwrap();
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "scene");
        assert_eq!(root.attribute("version"), Some("3.0.0"));
        let find = |tag: &str, ty: &str| {
            doc.descendants()
                .filter(|n| n.has_tag_name(tag) && n.attribute("type") == Some(ty))
                .collect::<Vec<_>>()
        };
        let param = |n: roxmltree::Node, name: &str| {
            n.children()
                .find(|c| c.attribute("name") == Some(name))
                .and_then(|c| c.attribute("value"))
                .map(str::to_owned)
        };
        let integ = find("integrator", "path")[0];
        assert_eq!(param(integ, "max_depth").as_deref(), Some("5"));
        let sensor = find("sensor", "perspective")[0];
        assert_eq!(param(sensor, "fov_axis").as_deref(), Some("y"));
        let fov: f32 = param(sensor, "fov").unwrap().parse().unwrap();
        assert!((fov - 0.7f32.to_degrees()).abs() < 1e-4);
        let lookat = sensor
            .descendants()
            .find(|n| n.has_tag_name("lookat"))
            .unwrap();
        assert_eq!(floats(lookat.attribute("origin").unwrap()), [0.0, 1.5, 4.0]);
        assert_eq!(floats(lookat.attribute("target").unwrap()), [0.0, 1.5, 3.0]);
        assert_eq!(floats(lookat.attribute("up").unwrap()), [0.0, 1.0, 0.0]);
        let sampler = find("sampler", "independent")[0];
        assert_eq!(param(sampler, "sample_count").as_deref(), Some("16"));
        assert_eq!(param(sampler, "seed").as_deref(), Some("7"));
        let film = find("film", "hdrfilm")[0];
        assert_eq!(param(film, "width").as_deref(), Some("64"));
        assert_eq!(param(film, "height").as_deref(), Some("48"));
        assert_eq!(find("rfilter", "box").len(), 1);

        let point = find("emitter", "point")[0];
        assert_eq!(
            floats(&param(point, "intensity").unwrap()),
            [100.0, 90.0, 80.0]
        );
        let spot = find("emitter", "spot")[0];
        let cutoff: f32 = param(spot, "cutoff_angle").unwrap().parse().unwrap();
        let beam: f32 = param(spot, "beam_width").unwrap().parse().unwrap();
        assert!((cutoff - 0.8f32.acos().to_degrees()).abs() < 1e-4);
        assert!((beam - 0.9f32.acos().to_degrees()).abs() < 1e-4);

        let shapes = find("shape", "ply");
        assert_eq!(shapes.len(), 3);
        // Emitters use face normals (one-sided by the winding, as ours); the rest are smooth.
        for shape in &shapes {
            let emits = shape.children().any(|c| c.has_tag_name("emitter"));
            let face = param(*shape, "face_normals");
            assert_eq!(face.as_deref(), Some(if emits { "true" } else { "false" }));
        }
        // Road: blend of diffuse (bitmap of 2 kd) and a ggx roughconductor with 2 ks.
        let blend = shapes[0]
            .children()
            .find(|c| c.has_tag_name("bsdf"))
            .unwrap();
        assert_eq!(blend.attribute("type"), Some("blendbsdf"));
        assert_eq!(param(blend, "weight").as_deref(), Some("0.5"));
        let cond = find("bsdf", "roughconductor");
        assert_eq!(param(cond[0], "distribution").as_deref(), Some("ggx"));
        assert_eq!(param(cond[0], "material").as_deref(), Some("none"));
        assert_eq!(param(cond[1], "distribution").as_deref(), Some("beckmann"));
        // The wall has no wet/dry map: plain alpha and 2 ks.
        assert_eq!(param(cond[1], "alpha").as_deref(), Some("0.2"));
        assert_eq!(
            floats(&param(cond[1], "specular_reflectance").unwrap()),
            [0.2; 3]
        );
        // The road's kd texture, and its alpha and ks baked from the dryness map (green
        // channel 0.5 and 1): alpha mix(0.1, 0.5, w), specular 2 mix(0.04, 0.02, w).
        let bitmaps = find("texture", "bitmap");
        let names: Vec<_> = bitmaps.iter().map(|b| b.attribute("name")).collect();
        assert_eq!(
            names,
            [
                Some("reflectance"),
                Some("alpha"),
                Some("specular_reflectance")
            ]
        );
        assert_eq!(bitmaps[1].parent(), Some(cond[0]));
        assert_eq!(bitmaps[2].parent(), Some(cond[0]));
        assert_eq!(ex.textures.len(), 3);
        assert_eq!(ex.textures[0].image.pixels[0], Vec3::new(0.1, 0.05, 0.025));
        let close = |a: Vec3, b: f32| (a - Vec3::splat(b)).abs().max_element() < 1e-6;
        let (alpha, spec) = (&ex.textures[1].image.pixels, &ex.textures[2].image.pixels);
        assert!(close(alpha[0], 0.3) && close(alpha[1], 0.5), "{alpha:?}");
        assert!(close(spec[0], 0.06) && close(spec[1], 0.04), "{spec:?}");
        // Lamp: an area emitter of the same radiance.
        let area = find("emitter", "area");
        assert_eq!(area.len(), 1);
        assert_eq!(
            floats(&param(area[0], "radiance").unwrap()),
            [10.0, 9.0, 8.0]
        );
        // Warnings: Ward, spot falloff, spot range; the wet/dry map is exact.
        assert!(
            !ex.warnings.iter().any(|w| w.contains("wet")),
            "{:?}",
            ex.warnings
        );
        for needle in ["Ward", "falloff", "range"] {
            assert!(
                ex.warnings.iter().any(|w| w.contains(needle)),
                "no warning about {needle}: {:?}",
                ex.warnings
            );
        }
    }

    #[test]
    fn bad_options_are_errors() {
        let fx = Fixture::new();
        let mut o = opts();
        o.spp = 0;
        assert!(matches!(
            export_parts(&fx.parts(), &fx.cameras[0], &o),
            Err(MitsubaError::InvalidOption(_))
        ));
    }

    /// Parses a PLY written by [`PlyMesh::to_bytes`] back (test-only reader).
    fn read_ply(bytes: &[u8]) -> PlyMesh {
        let end = b"end_header\n";
        let h = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        let header = std::str::from_utf8(&bytes[..h]).unwrap();
        assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"));
        let count = |el: &str| -> usize {
            header
                .lines()
                .find_map(|l| l.strip_prefix(&format!("element {el} ")))
                .unwrap()
                .parse()
                .unwrap()
        };
        let (nv, nf) = (count("vertex"), count("face"));
        let mut rest = &bytes[h..];
        let mut f32s = |n: usize| -> Vec<f32> {
            let v = rest[..4 * n]
                .chunks(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect();
            rest = &rest[4 * n..];
            v
        };
        let verts = f32s(nv * 8);
        let mut mesh = PlyMesh {
            file_name: String::new(),
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles: Vec::new(),
        };
        for v in verts.chunks(8) {
            mesh.positions.push(Vec3::new(v[0], v[1], v[2]));
            mesh.normals.push(Vec3::new(v[3], v[4], v[5]));
            mesh.uvs.push(Vec2::new(v[6], v[7]));
        }
        for _ in 0..nf {
            assert_eq!(rest[0], 3);
            let i = |k: usize| i32::from_le_bytes(rest[1 + 4 * k..5 + 4 * k].try_into().unwrap());
            mesh.triangles.push([i(0) as u32, i(1) as u32, i(2) as u32]);
            rest = &rest[13..];
        }
        assert!(rest.is_empty());
        mesh
    }

    #[test]
    fn ply_round_trips_and_groups_by_material() {
        let fx = Fixture::new();
        let ex = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
        assert_eq!(ex.meshes.len(), 3);
        let road = &ex.meshes[0];
        assert_eq!(road.positions.len(), 4);
        assert_eq!(road.triangles.len(), 2);
        let mut back = read_ply(&road.to_bytes());
        back.file_name = road.file_name.clone();
        assert_eq!(&back, road);
        // The compact mesh reproduces the original triangles.
        for (t, orig) in road.triangles.iter().zip(&fx.mesh.triangles[..2]) {
            for k in 0..3 {
                assert_eq!(
                    road.positions[t[k] as usize],
                    fx.mesh.positions[orig[k] as usize]
                );
            }
        }
    }

    #[test]
    fn write_creates_all_files() {
        let fx = Fixture::new();
        let ex = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        ex.write(dir.path()).unwrap();
        assert!(dir.path().join("scene.xml").is_file());
        for m in &ex.meshes {
            assert!(dir.path().join(&m.file_name).is_file());
        }
        let tex = dir.path().join(&ex.textures[0].file_name);
        let img = exr::prelude::read_first_rgba_layer_from_file(
            &tex,
            |res, _| vec![[0.0f32; 3]; res.width() * res.height()],
            |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * 2 + pos.x()] = [r, g, b];
            },
        )
        .unwrap();
        assert_eq!(img.layer_data.channel_data.pixels[0], [0.1, 0.05, 0.025]);
    }

    #[test]
    fn blend_weight_keeps_reflectances_at_most_one() {
        assert_eq!(blend_weight(0.05, 0.5), (0.5, true));
        let (w, exact) = blend_weight(0.55, 0.1);
        assert!(exact && (0.55 / (1.0 - w) - 0.65).abs() < 1e-6 && 0.1 / w <= 1.0 + 1e-6);
        assert_eq!(blend_weight(0.8, 0.0), (0.0, true));
        assert_eq!(blend_weight(0.0, 0.9), (1.0, true));
        assert!(!blend_weight(0.9, 0.4).1);
    }

    #[test]
    fn transmission_maps_to_mitsuba_dielectrics() {
        use crate::material::{GltfPbrParams, Volume};
        let glass = |roughness: f32, transmission: f32, volume: Option<Volume>| {
            Reflectance::GltfPbr(GltfPbrParams {
                base_color: Vec3::new(0.9, 0.95, 1.0),
                metallic: 0.0,
                roughness,
                ior: 1.45,
                transmission,
                volume,
                ..GltfPbrParams::default()
            })
        };
        let clear = Some(Volume::new(0.02, Vec3::ONE, f32::INFINITY));
        let tinted = Some(Volume::new(0.02, Vec3::splat(0.5), 1.0));
        for (reflectance, ty, needles) in [
            (glass(0.0, 1.0, clear), "dielectric", vec!["exact Fresnel"]),
            (
                glass(0.3, 1.0, tinted),
                "roughdielectric",
                vec!["exact Fresnel", "attenuation is not exported"],
            ),
            (
                glass(0.0, 1.0, None),
                "thindielectric",
                vec!["two interfaces"],
            ),
            (
                glass(0.3, 1.0, None),
                "principledthin",
                vec!["principledthin"],
            ),
            (glass(0.3, 0.5, clear), "principled", vec!["spec_trans"]),
        ] {
            let mut fx = Fixture::new();
            fx.materials[2].reflectance = reflectance;
            let ex = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
            let doc = roxmltree::Document::parse(&ex.xml).unwrap();
            let bsdf = doc
                .descendants()
                .find(|n| n.has_tag_name("bsdf") && n.attribute("type") == Some(ty))
                .unwrap_or_else(|| panic!("no {ty} in {}", ex.xml));
            let value = |name: &str| {
                bsdf.children()
                    .find(|c| c.attribute("name") == Some(name))
                    .and_then(|c| c.attribute("value"))
                    .map(str::to_owned)
            };
            match ty {
                "dielectric" | "thindielectric" => {
                    assert_eq!(value("int_ior").as_deref(), Some("1.45"));
                    assert_eq!(
                        floats(&value("specular_transmittance").unwrap()),
                        [0.9, 0.95, 1.0]
                    );
                }
                "roughdielectric" => {
                    let alpha: f32 = value("alpha").unwrap().parse().unwrap();
                    assert!((alpha - 0.09).abs() < 1e-6);
                }
                _ => assert!(value("spec_trans").is_some()),
            }
            for needle in needles {
                assert!(
                    ex.warnings
                        .iter()
                        .any(|w| w.contains("\"wall\"") && w.contains(needle)),
                    "{ty}: no warning about {needle}: {:?}",
                    ex.warnings
                );
            }
        }
    }

    /// A constant environment (the default one of a scene without lights included) becomes
    /// `constant` with its radiance, a map `envmap` of its texels with `scale` the strength.
    #[test]
    fn environments_are_exported() {
        use crate::light::{Environment, EnvironmentMap};
        let build = |environment: Option<Environment>| {
            let mut parts = crate::scene::SceneParts {
                materials: vec![Material::diffuse("floor", Vec3::splat(0.5))],
                cameras: vec![Camera::perspective(
                    "cam",
                    Affine3A::from_translation(Vec3::new(0.0, 1.5, 4.0)),
                    0.7,
                    None,
                )],
                environment,
                ..Default::default()
            };
            parts.mesh.positions = vec![Vec3::ZERO, Vec3::X, Vec3::Z];
            parts.mesh.triangles = vec![[0, 2, 1]];
            parts.mesh.triangle_materials = vec![0];
            export(&Scene::from_parts(parts).unwrap(), &opts()).unwrap()
        };
        let default = build(None);
        assert!(
            default.xml.contains(
                "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"1.0, 1.0, 1.0\"/></emitter>"
            ),
            "{}",
            default.xml
        );
        let image = RgbImage::from_fn(4, 3, |x, y| Vec3::new(x as f32, y as f32, 0.5));
        let map = EnvironmentMap::new(Path::new("/elsewhere/sky.exr"), &image, 2.5).unwrap();
        let e = build(Some(Environment::Map(Box::new(map))));
        assert!(
            e.xml.contains(
                "<emitter type=\"envmap\"><string name=\"filename\" value=\"textures/environment.exr\"/><float name=\"scale\" value=\"2.5\"/></emitter>"
            ),
            "{}",
            e.xml
        );
        let baked = e
            .textures
            .iter()
            .find(|t| t.file_name == "textures/environment.exr");
        assert_eq!(baked.unwrap().image, image);
        // The XML parses.
        roxmltree::Document::parse(&e.xml).unwrap();
    }

    /// KHR_materials_sheen becomes principled `sheen` (its colour's largest channel) with a
    /// warning on an opaque material, and is dropped with a warning on a transmissive one;
    /// a clear coat's normal map is named as not exported.
    #[test]
    fn sheen_and_coat_normal_are_approximated_with_warnings() {
        use crate::material::GltfPbrParams;
        use crate::normal_map::NormalMap;
        let velvet = |transmission: f32| {
            Reflectance::GltfPbr(GltfPbrParams {
                base_color: Vec3::splat(0.05),
                metallic: 0.0,
                roughness: 0.7,
                sheen_color: Vec3::new(0.2, 0.6, 0.4),
                sheen_roughness: 0.5,
                clearcoat: 0.5,
                clearcoat_normal_map: Some(NormalMap {
                    texture: TextureRef::new(0),
                    scale: 1.0,
                }),
                transmission,
                ..GltfPbrParams::default()
            })
        };
        let mut fx = Fixture::new();
        fx.materials[2].reflectance = velvet(0.0);
        let ex = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
        let doc = roxmltree::Document::parse(&ex.xml).unwrap();
        let sheen = doc
            .descendants()
            .find(|n| n.attribute("name") == Some("sheen"))
            .and_then(|n| n.attribute("value"))
            .unwrap_or_else(|| panic!("no sheen in {}", ex.xml));
        assert_eq!(sheen, "0.6");
        for needle in [
            "KHR_materials_sheen",
            "clearcoatNormalTexture is not exported",
        ] {
            assert!(
                ex.warnings
                    .iter()
                    .any(|w| w.contains("\"wall\"") && w.contains(needle)),
                "no warning about {needle}: {:?}",
                ex.warnings
            );
        }
        fx.materials[2].reflectance = velvet(0.5);
        let ex = export_parts(&fx.parts(), &fx.cameras[0], &opts()).unwrap();
        assert!(!ex.xml.contains("name=\"sheen\""), "{}", ex.xml);
        assert!(
            ex.warnings
                .iter()
                .any(|w| w.contains("KHR_materials_sheen is not exported")),
            "{:?}",
            ex.warnings
        );
    }
}
