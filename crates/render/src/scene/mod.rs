//! Scenes: one flat triangle soup in world space with per-vertex attributes, instanced meshes
//! ([`Instances`]: stored once in object space, placed by transforms), materials, textures,
//! lights, cameras and the BVH, loaded from glTF 2.0 (`.gltf`, `.glb`) or OBJ/MTL
//! ([`Scene::load`]) or built from memory ([`Scene::from_parts`]).
//!
//! # The scene contract (see docs/design.md)
//!
//! - glTF: the default scene (else scene 0) is flattened, `world = parent * local`. Triangle
//!   primitives (strips and fans are converted) become world-space triangles; points and lines
//!   are skipped with a warning. A mesh placed more than once (by several nodes, or by the
//!   instances of EXT_mesh_gpu_instancing, `world = node world * T * R * S`) is instead stored
//!   once in object space and placed by [`Instance`]s, unless it has an emissive material
//!   (emitters are world triangles); hits on instances are shaded as the flattened triangles
//!   would be (see [`Instances`]), and [`SurfaceHit::triangle`] is then
//!   [`INSTANCED_TRIANGLE`]. Normals go through the inverse transpose; where a primitive
//!   has none the shading normal is the face normal (stored as a zero vertex normal). A node
//!   whose world transform has a negative determinant has its winding reversed, as the glTF
//!   specification says, so the geometric normal from the winding stays the front side.
//! - Morph targets and skins are in the specification's default pose: a primitive's
//!   POSITION, NORMAL and TANGENT get the sum of the weights times the targets' deltas (the
//!   placing node's `weights`, else the mesh's); a skinned mesh's vertices are moved by the
//!   weighted sum of its joints' matrices (each joint's world transform times its inverse bind
//!   matrix; JOINTS_n and WEIGHTS_n), and the skinned node's own transform is ignored, as the
//!   specification says. Such meshes are flattened, never instanced. Animations are not
//!   played (a warning): the rest pose is rendered.
//! - Extensions ([`extensions`]): the ones the loader honours are listed in
//!   [`extensions::HONOURED`]; any other extension in `extensionsUsed` is one warning for the
//!   file, which says what is rendered without it, counts the elements that use it and names
//!   the first of them. One in `extensionsRequired` is an error naming it, unless it only
//!   changes the shading ([`extensions::RENDERED_WITHOUT`]: sheen, iridescence, anisotropy,
//!   dispersion, ...), where the file loads with that warning (docs/decisions/0025). Every
//!   other warning of the loader (skipped primitives, an `occlusionTexture`, which a path
//!   tracer does not need, animations) is likewise one per file and feature.
//! - Geometry may be quantized (KHR_mesh_quantization: 8- and 16-bit attributes, normalized
//!   or not), sparse, or compressed (EXT_meshopt_compression, KHR_draco_mesh_compression,
//!   decoded when the file is loaded).
//! - Perspective and orthographic cameras ([`Camera`]); a camera's name is the camera's, else
//!   its node's, else `camera<i>`; `world_from_camera` is the node's world transform with
//!   scale removed. A scene without a camera is shown by the default camera
//!   ([`Scene::default_camera`]: the glTF sample viewer's framing of its bounds).
//! - KHR_lights_punctual: `color * intensity` is in candela (point, spot) or lux
//!   (directional), as the specification says, and becomes W/sr or W/m^2 divided by 683 lm/W
//!   ([`crate::light::LUMINOUS_EFFICACY`]), as Blender's importer does. A file written in
//!   radiometric units says so with `"asset": {"extras": {"streaks": {"light_units":
//!   "radiometric"}}}` (the default is `"photometric"`); its intensities are then used as
//!   they are.
//! - Materials: glTF metallic-roughness ([`crate::bsdf::GltfPbr`]: the specification's
//!   appendix B with the height-correlated Smith visibility), with KHR_materials_specular
//!   (specularFactor and specularTexture's alpha, specularColorFactor and the sRGB
//!   specularColorTexture), KHR_materials_ior (ior, 1.5 by default, 0 or at least 1),
//!   KHR_materials_sheen (sheenColorFactor and the sRGB sheenColorTexture's RGB,
//!   sheenRoughnessFactor and sheenRoughnessTexture's alpha: the Charlie sheen lobe over the
//!   base by the extension's albedo scaling, see `bsdf/sheen.rs`), KHR_materials_iridescence
//!   (iridescenceFactor and iridescenceTexture's red channel, iridescenceIor, the thickness
//!   range blended by iridescenceThicknessTexture's green channel: the thin-film Fresnel of
//!   `bsdf/iridescence.rs`) and
//!   KHR_materials_clearcoat (clearcoatFactor and clearcoatTexture's red channel,
//!   clearcoatRoughnessFactor and clearcoatRoughnessTexture's green channel, and
//!   clearcoatNormalTexture, the coat's own normal map in the base's tangent space; without
//!   it the coat is shaded with the interpolated normal, not the base's mapped one, as the
//!   extension says: [`crate::geometry::SurfaceHit::coat_normal`]), with those
//!   extensions' formulas; values outside the schemas' ranges are errors naming the material.
//!   KHR_materials_transmission (transmissionFactor and transmissionTexture's red channel)
//!   makes that share of the dielectric's diffuse part a specular transmission tinted by the
//!   base colour, with the surface's roughness (0: a smooth, delta dielectric). Without
//!   KHR_materials_volume, or with thicknessFactor 0, the surface is thin-walled, as the
//!   extension says: light goes through it without bending, and a closed mesh (a glass box)
//!   is two such interfaces, its faces each transmitting without refraction. With a
//!   thicknessFactor above 0 the mesh bounds a volume: it refracts by its ior entering
//!   through the front faces and leaving through the back faces, and absorbs inside by
//!   Beer-Lambert's law from attenuationColor and attenuationDistance over the distance the
//!   path travels inside ([`crate::material::Volume`]). A thicknessTexture is validated
//!   and not used: the extension says ray tracers should ignore it and use the traced
//!   distance, as the path tracer does.
//!   A specularFactor of 0 (Blender's Specular IOR Level 0) is exactly Lambertian. Unless
//!   `extras.streaks` chooses one of the paper's models: `{"bsdf": "ggx" | "ward" | "blinn_phong", "kd": [r,g,b], "ks": [r,g,b],
//!   "alpha": a, "shininess": s}` (`alpha` for ggx and ward, `shininess` for blinn_phong;
//!   `kd` and `ks` default to black). The baseColorTexture, if any, multiplies `kd`. A `ggx`
//!   material may add glass beads, `"kr": [r,g,b]` (each at most 1) and `"retro_width": w`
//!   (radians, in (0, 1], default 0.026): bead paint, [`crate::bsdf::Retroreflective`], whose
//!   cone of width `w` sends light back toward its source (road markings under headlights).
//!   `extras.streaks.road: true` (with a paper model, or alone on a metallic-roughness
//!   material) flags the road surface ([`crate::material::Material::road`]), which the
//!   integrator's `material` layer lets datasets mask; it changes no pixel.
//! - Normal maps ([`crate::normal_map`]): a material's `normalTexture` (linear RGB, `scale`
//!   multiplying X and Y) perturbs the shading normal in tangent space. Tangents are stored
//!   per vertex ([`TriangleMesh::tangents`], empty when no material has a normal map; zero for the
//!   vertices of primitives without one): a primitive's TANGENT (xyz by the model matrix, not
//!   the inverse transpose; w, the handedness, flipped by a mirroring transform), or, where it
//!   has none or has no NORMAL (then TANGENT is ignored, as the specification says),
//!   MikkTSpace tangents generated from the world-space positions, the normals (the face
//!   normals for flat primitives) and the uvs (vertices whose triangles disagree, as on a uv
//!   mirror seam, are duplicated). A normal-mapped primitive without TEXCOORD_0 is rendered
//!   without the map (a warning), and so is one with a vertex shared by more than 4,096
//!   triangles (MikkTSpace recurses once per triangle around a vertex). A perturbed normal is tilted back toward the geometric
//!   normal where the viewer's mirror direction would go below the surface
//!   ([`crate::normal_map::valid_reflection_normal`]).
//! - Textures ([`crate::texture`]): every material texture reads its `texCoord` set
//!   (`TEXCOORD_0` or `TEXCOORD_1`; a higher set is a warning and reads `TEXCOORD_0`, and so
//!   does a primitive without the set its material reads, with a warning), through its
//!   KHR_texture_transform (`offset`, `rotation`, `scale`, and its `texCoord` override) and
//!   its sampler's `wrapS`/`wrapT` (repeat, clamp to edge, mirrored repeat) and `magFilter`
//!   (nearest or linear). `minFilter` is ignored: each pixel is supersampled, which filters
//!   the texture over the pixel footprint as a mipmap approximates (see [`crate::texture`]).
//!   An image is decoded once per colour space, whatever samplers read it. Images are PNG or
//!   JPEG; a KTX2 image (KHR_texture_basisu), recognised by its content whatever its MIME
//!   type or name, is not decoded: the texture's fallback image (its core `source`) is read
//!   where it has one, and otherwise the texture is left out (the material keeps its factor),
//!   with one warning naming the images; a file that requires KHR_texture_basisu is an error
//!   (docs/decisions/0026). A missing image file is an error naming it and the material.
//! - Vertex colours `COLOR_0` (RGB or RGBA; float, or normalized unsigned byte or short)
//!   multiply the base colour (`kd` for the paper's models) and its alpha. The second uv set
//!   and the colours are stored only when some primitive has them ([`TriangleMesh::uvs1`],
//!   [`TriangleMesh::colors`]).
//! - `alphaMode`: alpha is `baseColorFactor.a x baseColorTexture.a x COLOR_0.a`. `MASK`
//!   (`alphaCutoff`, default 0.5) cuts the surface away where alpha is below the cutoff;
//!   `BLEND` is stochastic transparency: a ray stops at the surface with probability alpha
//!   and passes through it otherwise, decided by a hash of the ray and the triangle, so an
//!   image is the same for the same seed whatever the thread count. Both hold for every ray
//!   ([`Scene::intersect`] and [`Scene::occluded`] alike). An emissive triangle that is not
//!   opaque emits `emission x` the probability that a ray stops there (nothing in a hole,
//!   alpha on a `BLEND` surface) in light samples; a ray that hits it sees its full emission,
//!   which is the same on average.
//! - Emission `emissiveFactor * KHR_materials_emissive_strength` (times the emissive texture)
//!   is radiance; the triangles of an emissive material are area lights, grouped into the
//!   scene's emitters ([`crate::light::Emitters`]) when it is built. Emission is one-sided (the
//!   winding's front face) unless the material is `doubleSided`.
//! - KHR_materials_unlit ([`crate::material::Reflectance::Unlit`]): the surface reflects
//!   nothing and emits its base colour (factor, texture, times COLOR_0) as radiance, so the
//!   camera sees exactly the base colour; like any emitter it lights the rest of the scene
//!   (docs/decisions/0027).
//! - Rain (`scenes[i].extras.streaks.rain = {"rate_mm_h": R, "seed": n, "radius": m}`, seed
//!   and radius optional, 0 and 20 m): [`Scene::rain`] holds it and a water material; its
//!   drops are placed for a view by [`Scene::place_rain`] and met by camera rays through
//!   [`Scene::intersect_path`] ([`crate::rain`] has the physics and the limits).
//!
//! ## Wet and dry patches (an extension of the contract)
//!
//! An `extras.streaks` material may also give `"alpha_dry"` (and optionally `"ks_dry"`,
//! default `ks`). Its glTF `metallicRoughnessTexture` (required then) is the dryness map: the
//! green channel is the dryness `w` in [0, 1] (linear), and at each point
//! `alpha(uv) = mix(alpha, alpha_dry, w)`, `ks(uv) = mix(ks, ks_dry, w)`. For blinn_phong,
//! `alpha_dry` is the dry shininess and interpolates `shininess`. So black (w = 0) is the wet
//! value given by `alpha`/`ks` and green (w = 1) is fully dry.
//!
//! - Values are checked against the specification and the extensions' schemas (the
//!   `validate` module): colours and factors in their ranges (baseColorFactor,
//!   emissiveFactor, metallic, roughness, light colour in [0, 1]; emissiveStrength, intensity
//!   and the paper models' `kd`, `ks`, `alpha`, `shininess` finite and non-negative), light
//!   ranges above 0, spot cones with `0 <= inner <= outer <= pi/2` (inner may equal outer: a
//!   hard edge), cameras' yfov, xmag, ymag, znear, zfar and aspectRatio, node transforms
//!   finite and invertible, vertex positions finite and within [`MAX_COORDINATE`] once
//!   placed. Anything else is an error naming the file and the light, camera, material, node
//!   or mesh.
//! - Limits: a node graph may visit at most [`MAX_PLACEMENTS`] nodes (a node reached by
//!   several paths counts once per path; counted before the walk) and place as many meshes,
//!   and the placed meshes may hold at most [`MAX_TRIANGLES`] triangles (counted from the
//!   accessors before any geometry is read).
//! - OBJ/MTL (via tobj, triangulated): `Kd` with a non-zero `Ks` (and `illum` not 0 or 1) is
//!   blinn_phong with shininess `Ns`; otherwise Lambertian `Kd` (times `map_Kd`); `Ke` is
//!   emission. A missing MTL file is a warning (every material becomes grey diffuse). OBJ has no
//!   cameras or punctual lights, and no normal maps (`map_Bump` is a warning).
//!
//! # Files a scene names
//!
//! Every buffer, image, material library and texture map a scene names is read through the
//! `files` module: inside the scene file's folder unless [`LoadOptions::allow_outside`],
//! regular files only, no more bytes than needed, and counts, decoded sizes and image sizes
//! checked before memory is reserved (see [`LoadOptions`]).
//!
//! # Ray queries
//!
//! [`Scene::intersect`] and [`Scene::occluded`] go through [`Accel`] (and, when the scene has
//! instances, the top-level BVH over them and each instanced mesh's own BVH); hits closer than
//! [`Accel::t_min`] (a tiny distance relative to the scene's size) are ignored to guard against
//! self-intersection, on top of the origin offset callers apply with
//! [`crate::geometry::offset_ray_origin`].

mod error;
mod files;
mod gltf;
mod instances;
mod mesh;
mod obj;
mod objects;
mod tangents;
mod validate;

pub use error::SceneError;
pub use files::LoadOptions;
pub use gltf::extensions;
pub use gltf::{MAX_PLACEMENTS, MAX_TRIANGLES};
pub use instances::{Instance, InstancedMesh, Instances};
pub use mesh::TriangleMesh;
pub use objects::{base_table, ObjectTable, SceneObject, SKY_OBJECT, UNLABELLED_OBJECT};
pub use validate::MAX_COORDINATE;

use crate::accel::Accel;
use crate::camera::Camera;
use crate::geometry::{offset_ray_origin, Ray, SurfaceHit, VertexAttributes};
use crate::light::{Environment, Light, LightSampler, SurfaceMesh};
use crate::material::Material;
use crate::medium::Fog;
use crate::motion::Motion;
use crate::normal_map::{self, MappedNormal, NormalMap};
use crate::rain::{offset_from_drop, DropField, Rain, RainError, RainParams, RainPath, RainView};
use crate::sampling::{pcg_hash, u32_to_unit_f32};
use crate::texture::Texture;
use glam::{Vec2, Vec3, Vec4};
use mesh::{Geometry, LocalSurface};
use std::path::{Path, PathBuf};

/// [`SurfaceHit::triangle`] of a hit on an instanced mesh: no triangle of the flat soup (and
/// never an emitter's; see [`Instances`]).
pub const INSTANCED_TRIANGLE: u32 = u32::MAX;

/// The radiance of the environment a scene with no light at all is lit by: a uniform white
/// of 1, Mitsuba's `constant` emitter's default, so that the Mitsuba export of such a scene is
/// lit the same way (docs/decisions/0028-default-environment-light.md).
pub const DEFAULT_ENVIRONMENT_RADIANCE: f32 = 1.0;

/// The warning (after the scene's file name) of a scene that has no light: no punctual light,
/// no emissive triangle and no environment.
pub const NO_LIGHT_WARNING: &str = "scene has no light: lit by a uniform white environment of \
                                    radiance 1; --env or extras.streaks.environment sets one";

/// A loaded scene, shared read-only by all render threads (never copied per thread).
#[derive(Debug)]
pub struct Scene {
    /// The file it was loaded from.
    pub source: PathBuf,
    /// The flat triangles in world space, checked (normals unit or zero, uvs filled; see
    /// [`TriangleMesh`]).
    pub mesh: TriangleMesh,
    /// Materials.
    pub materials: Vec<Material>,
    /// Decoded textures.
    pub textures: Vec<Texture>,
    /// The point, spot and directional lights, in file order.
    pub lights: Vec<Light>,
    /// Cameras, in the order the node walk reaches them (depth-first, children in file
    /// order); the first is the default.
    pub cameras: Vec<Camera>,
    /// What the default camera ([`Scene::default_camera`]) frames: the union
    /// ([`crate::camera::union_bounds`]) of the world-space bounding boxes of the
    /// loaded primitives (computed from their triangles as loaded, not from the accessors'
    /// `min` and `max`; an instanced primitive's box is its object-space box's eight corners
    /// placed by the instance). A scene from OBJ or [`Scene::from_parts`] counts as one
    /// primitive. `None` for a scene without geometry.
    pub framing_bounds: Option<[Vec3; 2]>,
    /// The BVH over `mesh.triangles`.
    pub accel: Accel,
    /// The instanced meshes (in object space, each stored once), their instances and the
    /// top-level BVH over them; empty for most scenes (see [`Instances`]).
    pub instances: Instances,
    /// The emitters (`lights` and the emissive triangles) and the light tree over them, built
    /// with the scene from its triangles, materials and lights, and the environment light
    /// ([`Scene::environment`]).
    pub light_sampler: LightSampler,
    /// The fog that fills the space outside the objects (`scenes[i].extras.streaks.fog` in
    /// glTF), if any; see [`crate::medium`].
    pub fog: Option<Fog>,
    /// Things in the file that were skipped or defaulted, for the command to print.
    pub warnings: Vec<String>,
    /// Rain in the air (`scenes[i].extras.streaks.rain`, [`crate::rain`]): its drops are
    /// placed for a view by [`Scene::place_rain`]; `None` for a dry scene.
    pub rain: Option<Rain>,
    /// What the triangles are part of, by slot ([`TriangleMesh::triangle_objects`],
    /// [`Instance::object`]): the sky and the unlabelled object first ([`base_table`]), then
    /// one slot per distinct (class, instance) of the glTF nodes' tags.
    pub objects: Vec<SceneObject>,
}

/// The in-memory ingredients of a [`Scene`], for [`Scene::from_parts`].
#[derive(Clone, Debug, Default)]
pub struct SceneParts {
    /// Where the scene came from (used in messages; may be any label).
    pub source: PathBuf,
    /// The flat triangles in world space (a name, if given, prefixes their errors).
    pub mesh: TriangleMesh,
    /// Materials.
    pub materials: Vec<Material>,
    /// Textures.
    pub textures: Vec<Texture>,
    /// Point, spot and directional lights (emissive triangles become emitters by themselves).
    pub lights: Vec<Light>,
    /// Cameras.
    pub cameras: Vec<Camera>,
    /// Meshes stored once in object space and placed by `instances` (none may have an
    /// emissive material: emitters are world triangles).
    pub instanced_meshes: Vec<TriangleMesh>,
    /// Placements of `instanced_meshes`.
    pub instances: Vec<Instance>,
    /// The environment light (`scenes[i].extras.streaks.environment` in glTF); with none,
    /// and no punctual light or emissive triangle either, the scene gets a uniform white
    /// environment ([`DEFAULT_ENVIRONMENT_RADIANCE`]) and a warning ([`NO_LIGHT_WARNING`]).
    pub environment: Option<Environment>,
    /// The fog (`scenes[i].extras.streaks.fog` in glTF), if any.
    pub fog: Option<Fog>,
    /// Warnings to pass on.
    pub warnings: Vec<String>,
    /// The objects the triangles' and instances' slots index; empty for [`base_table`] (all
    /// unlabelled). Otherwise it must start with [`base_table`].
    pub objects: Vec<SceneObject>,
}

impl Scene {
    /// Loads a scene file with the default [`LoadOptions`] (only files inside its folder),
    /// choosing the loader by extension: `.gltf` and `.glb` (glTF 2.0) or `.obj` (with its
    /// MTL), case-insensitively.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Self::load_with(path, &LoadOptions::default())
    }

    /// Loads a scene file as [`Scene::load`] does, reading what `options` allow: the files it
    /// names resolve inside its folder unless [`LoadOptions::allow_outside`], only regular
    /// files are read, and sizes and decoded data are limited (see [`LoadOptions`]).
    pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let files = files::Files::new(path, options);
        match ext.as_deref() {
            Some("gltf" | "glb") => gltf::load(path, &files),
            Some("obj") => obj::load(path, &files),
            _ => Err(SceneError::UnsupportedFormat {
                path: path.to_path_buf(),
            }),
        }
    }

    /// Builds a scene from in-memory parts: checks every index, fills absent normals and uvs,
    /// builds the BVH, and builds the emitters and the light tree ([`LightSampler`]) from the
    /// lights and the non-degenerate triangles of emissive materials.
    pub fn from_parts(parts: SceneParts) -> Result<Scene, SceneError> {
        let SceneParts {
            source,
            mut mesh,
            materials,
            textures,
            lights,
            cameras,
            instanced_meshes,
            instances,
            environment,
            fog,
            mut warnings,
            objects,
        } = parts;
        let bad = |element: String, reason: String| SceneError::invalid(&source, element, reason);
        let objects = if objects.is_empty() {
            base_table()
        } else if objects.starts_with(&base_table()) {
            objects
        } else {
            return Err(bad(
                "objects".into(),
                "the table must start with the sky and the unlabelled object".into(),
            ));
        };
        mesh.check(&source, materials.len(), objects.len())?;
        for m in &materials {
            if let Some(t) = m.texture_ids().find(|&t| t as usize >= textures.len()) {
                return Err(bad(
                    format!("material {:?}", m.name),
                    format!("texture {t} out of range ({} textures)", textures.len()),
                ));
            }
        }
        let alpha_tested = |m: u32| !materials[m as usize].alpha.is_opaque();
        let mut meshes = Vec::with_capacity(instanced_meshes.len());
        for mut m in instanced_meshes {
            m.check(&source, materials.len(), objects.len())?;
            if let Some(&e) = m
                .triangle_materials
                .iter()
                .find(|&&t| materials[t as usize].is_emissive())
            {
                return Err(bad(
                    m.name.clone(),
                    format!(
                        "is instanced but its material {:?} is emissive (emitters must be \
                         world triangles)",
                        materials[e as usize].name
                    ),
                ));
            }
            let accel = Accel::build_alpha_tested(&m.positions, &m.triangles, |t| {
                alpha_tested(m.triangle_materials[t])
            });
            meshes.push(InstancedMesh { mesh: m, accel });
        }
        if let Some((i, inst)) = instances
            .iter()
            .enumerate()
            .find(|(_, inst)| inst.object as usize >= objects.len())
        {
            return Err(bad(
                format!("instance {i}"),
                format!(
                    "object slot {} out of range ({} objects)",
                    inst.object,
                    objects.len()
                ),
            ));
        }
        if let Some((i, inst)) = instances
            .iter()
            .enumerate()
            .find(|(_, inst)| inst.mesh as usize >= meshes.len())
        {
            return Err(bad(
                format!("instance {i}"),
                format!(
                    "mesh {} out of range ({} instanced meshes)",
                    inst.mesh,
                    meshes.len()
                ),
            ));
        }
        let instances = Instances::build(meshes, instances)
            .map_err(|(element, reason)| bad(element, reason))?;
        let mut accel = Accel::build_alpha_tested(&mesh.positions, &mesh.triangles, |t| {
            alpha_tested(mesh.triangle_materials[t])
        });
        let bounds = bounding_box(&mesh.positions, &instances);
        if let Some([lo, hi]) = bounds.filter(|_| !instances.is_empty()) {
            // One self-intersection distance for all hits, from the extent of everything.
            accel.raise_t_min(16.0 * f32::EPSILON * lo.abs().max(hi.abs()).max_element());
        }
        let mut light_sampler =
            LightSampler::new(&lights, mesh.surface(&materials), bounding_sphere(bounds).1);
        let environment = match environment {
            None if light_sampler.emitters().is_empty() => {
                warnings.push(format!("{}: {NO_LIGHT_WARNING}", source.display()));
                Some(Environment::Constant {
                    radiance: Vec3::splat(DEFAULT_ENVIRONMENT_RADIANCE),
                })
            }
            other => other,
        };
        light_sampler.set_environment(environment);
        Ok(Scene {
            source,
            mesh,
            materials,
            textures,
            lights,
            cameras,
            framing_bounds: crate::camera::union_bounds(bounds),
            accel,
            instances,
            light_sampler,
            fog,
            warnings,
            rain: None,
            objects,
        })
    }

    /// The environment light, if any (the scene's, the default one of a scene without
    /// lights, or the one [`Scene::set_environment`] gave).
    #[inline]
    pub fn environment(&self) -> Option<&Environment> {
        self.light_sampler.environment()
    }

    /// Replaces the scene's environment light (a command's `--env`); the warning that a
    /// scene without lights got the default one goes with it.
    pub fn set_environment(&mut self, environment: Environment) {
        self.light_sampler.set_environment(Some(environment));
        self.warnings.retain(|w| !w.ends_with(NO_LIGHT_WARNING));
    }

    /// The camera called `name` (else, if `name` is a number `i` and no camera has that name,
    /// the `i`-th camera of [`Scene::cameras`], from 0), or the first camera when `name` is
    /// `None`. A scene without cameras is an error here; [`Scene::find_camera`] and
    /// [`Scene::default_camera`] give it the default camera.
    pub fn camera(&self, name: Option<&str>) -> Result<&Camera, SceneError> {
        let found = match name {
            Some(n) => self
                .cameras
                .iter()
                .find(|c| c.name == n)
                .or_else(|| n.parse::<usize>().ok().and_then(|i| self.cameras.get(i))),
            None => self.cameras.first(),
        };
        found.ok_or_else(|| match name {
            Some(n) if !self.cameras.is_empty() => SceneError::UnknownCamera {
                path: self.source.clone(),
                name: n.to_string(),
                available: self
                    .cameras
                    .iter()
                    .map(|c| format!("{:?}", c.name))
                    .collect::<Vec<_>>()
                    .join(", "),
            },
            _ => SceneError::NoCamera {
                path: self.source.clone(),
            },
        })
    }

    /// The camera [`Scene::camera`] chooses, or `None` when the scene has no camera and no
    /// `name` is asked for (the caller then uses [`Scene::default_camera`], once it knows the
    /// image size, and says so with [`crate::camera::FRAMING_WARNING`]).
    pub fn find_camera(&self, name: Option<&str>) -> Result<Option<&Camera>, SceneError> {
        if name.is_none() && self.cameras.is_empty() {
            return Ok(None);
        }
        self.camera(name).map(Some)
    }

    /// The default camera for an image of aspect ratio `aspect` (width / height): the glTF
    /// sample viewer's, [`Camera::framing`] of [`Scene::framing_bounds`] (a scene without
    /// geometry frames the cube of side 2 around the origin).
    pub fn default_camera(&self, aspect: f32) -> Camera {
        let bounds = self
            .framing_bounds
            .unwrap_or([Vec3::splat(-1.0), Vec3::splat(1.0)]);
        Camera::framing(bounds, aspect)
    }

    /// Centre and radius of a sphere enclosing all vertices, the instances' included (the
    /// centre of their bounding box and its half diagonal); `(0, 0)` for an empty scene.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        bounding_sphere(bounding_box(&self.mesh.positions, &self.instances))
    }

    /// The number of triangles in the world: the flat ones and every instance's.
    pub fn world_triangle_count(&self) -> usize {
        self.mesh.triangles.len() + self.instances.instanced_triangle_count()
    }

    /// Radiance emitted from `hit` toward `wo` (unit, pointing away from the surface): the
    /// material's emission on the front face (by winding), on both faces if it is
    /// double-sided, zero otherwise.
    #[inline]
    pub fn emitted_radiance(&self, hit: &SurfaceHit, wo: Vec3) -> Vec3 {
        let material = &self.materials[hit.material as usize];
        if !material.is_emissive() || (!material.double_sided && hit.ng.dot(wo) <= 0.0) {
            return Vec3::ZERO;
        }
        material.emission_at(&hit.attributes, &self.textures)
    }

    /// The scene's (flat, world-space) triangles with their vertex attributes and materials.
    #[inline]
    pub fn surface(&self) -> SurfaceMesh<'_> {
        self.mesh.surface(&self.materials)
    }

    /// The scene's own (flat, world-space) triangles as hit shading reads them.
    #[inline]
    fn geometry(&self) -> Geometry<'_> {
        self.mesh.geometry(&self.materials)
    }

    /// Whether `ray` stops at its hit at barycentrics `b` on triangle `triangle` of
    /// `geometry`, a triangle of a material that is not opaque: by
    /// [`crate::material::Alpha::stop_probability`], for `BLEND` against a hash of the ray
    /// and `id` ([`transparency_hash`]; the triangle, made unique per instance for instanced
    /// meshes), so the same ray always gets the same answer.
    #[inline]
    fn stops(&self, geometry: Geometry<'_>, ray: &Ray, triangle: u32, id: u32, b: Vec2) -> bool {
        let mesh = geometry.mesh;
        let material = &self.materials[mesh.triangle_materials[triangle as usize] as usize];
        let at = mesh.attributes_at(triangle as usize, b);
        let p = material.alpha.stop_probability(&at, &self.textures);
        p >= 1.0 || (p > 0.0 && transparency_hash(ray, id) < p)
    }

    /// [`Scene::stops`] for triangle `triangle` of instance `instance`.
    #[inline]
    fn instance_stops(&self, ray: &Ray, instance: u32, triangle: u32, b: Vec2) -> bool {
        let mesh = self.instances.instances[instance as usize].mesh;
        let geometry = self.instances.meshes[mesh as usize]
            .mesh
            .geometry(&self.materials);
        let id = triangle ^ pcg_hash(instance.wrapping_add(1));
        self.stops(geometry, ray, triangle, id, b)
    }

    /// Closest hit along `ray` (at its time), the ray of a camera path in state `path`, on
    /// the scene's surfaces or a rain drop: what [`Scene::intersect`] finds, unless a drop the
    /// path can meet ([`RainPath`]: the camera ray the drops its camera sees, a ray leaving a
    /// drop that drop) is nearer. A drop's hit has [`crate::rain::RAIN_TRIANGLE`] as its
    /// triangle and the water material ([`crate::rain::water_material`]).
    #[inline]
    pub fn intersect_path(&self, ray: &Ray, path: &mut RainPath) -> Option<SurfaceHit> {
        let surface = self.intersect(ray);
        let (Some(rain), true) = (&self.rain, path.camera.is_some() || path.drop.is_some()) else {
            return surface;
        };
        let t_max = surface.as_ref().map_or(ray.t_max, |h| h.t);
        match path.intersect(ray, t_max) {
            Some((t, _, n)) => Some(SurfaceHit {
                t,
                p: ray.at(t),
                ng: n,
                ns: n,
                mapped: None,
                coat_normal: None,
                attributes: VertexAttributes::from_uv(Vec2::ZERO),
                triangle: crate::rain::RAIN_TRIANGLE,
                material: rain.material,
                object: UNLABELLED_OBJECT,
            }),
            None => surface,
        }
    }

    /// The origin of a ray that leaves `hit` (with geometric normal `ng`) toward `w`: offset
    /// off the surface by [`offset_ray_origin`], or for a rain drop by
    /// [`crate::rain::offset_from_drop`] (a drop can be smaller than the triangles' offset).
    #[inline]
    pub fn spawn_origin(&self, hit: &SurfaceHit, ng: Vec3, w: Vec3) -> Vec3 {
        if hit.triangle == crate::rain::RAIN_TRIANGLE {
            offset_from_drop(hit.p, ng, w)
        } else {
            offset_ray_origin(hit.p, ng, w)
        }
    }

    /// Gives the scene rain (what `extras.streaks.rain` asks for): adds the water material
    /// to [`Scene::materials`]; no drops until [`Scene::place_rain`].
    pub fn set_rain(&mut self, params: RainParams) {
        let material = self.materials.len() as u32;
        self.materials.push(crate::rain::water_material());
        self.rain = Some(Rain {
            params,
            material,
            field: DropField::default(),
            estimator: crate::rain::RainEstimator::default(),
        });
    }

    /// Places the scene's rain drops (if it has rain) for a `width` x `height` view of
    /// `camera` with the shutter and rig motion of `motion`: in the camera's view frustum
    /// widened by [`crate::rain::RIG_MARGIN`], so that both eyes of a stereo rig centred on
    /// `camera` see the same drops. Returns the number of drops. Renders of other views see
    /// these drops too (all of them where they are seen from this camera's region).
    pub fn place_rain(
        &mut self,
        camera: &Camera,
        width: u32,
        height: u32,
        motion: Motion,
    ) -> Result<usize, RainError> {
        let Some(rain) = &mut self.rain else {
            return Ok(0);
        };
        let view = RainView::of_camera(camera, width, height, motion, crate::rain::RIG_MARGIN)
            .ok_or(RainError::Orthographic)?;
        rain.field = DropField::place(&rain.params, &view)?;
        Ok(rain.field.len())
    }

    /// Closest hit along `ray` within `(t_min, ray.t_max)` (see [`Accel::t_min`]) on the
    /// scene's surfaces (never a rain drop: [`Scene::intersect_path`]), where the
    /// ray stops, on the flat triangles or an instance: hits on alpha-masked-out points are
    /// skipped, and `BLEND` surfaces stop the ray with probability alpha (stochastic
    /// transparency, decided by a hash of the ray and the triangle). The shading normal is the
    /// interpolated vertex normal (the face normal where there is none), through the
    /// material's normal map where it has one and the vertices have tangents (made valid for
    /// the viewer `-ray.direction` by [`normal_map::valid_reflection_normal`]), and oriented to
    /// the side of the geometric normal. A hit on an instance has
    /// [`INSTANCED_TRIANGLE`] as its triangle.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        let flat = self
            .accel
            .intersect_filtered(ray, |t, b| self.stops(self.geometry(), ray, t, t, b));
        if !self.instances.is_empty() {
            let mut nearer = *ray;
            if let Some(h) = &flat {
                nearer.t_max = h.t;
            }
            let t_min = self.accel.t_min();
            let instanced = self
                .instances
                .intersect(&nearer, t_min, |i, t, b| self.instance_stops(ray, i, t, b));
            if let Some(h) = instanced {
                let inst = &self.instances.instances[h.instance as usize];
                let geometry = self.instances.meshes[inst.mesh as usize]
                    .mesh
                    .geometry(&self.materials);
                let b = h.hit.barycentrics;
                let local = geometry.surface_at(h.hit.triangle, b);
                let ng = inst.normal_to_world(local.ng);
                let world = LocalSurface {
                    p: inst.world_from_object.transform_point3(local.p),
                    ng,
                    ns: inst.normal_to_world(local.ns),
                    ..local
                };
                let tangent = || inst.tangent_to_world(geometry.tangent_at(h.hit.triangle, b));
                let at = (INSTANCED_TRIANGLE, inst.object);
                return Some(self.shade(ray, h.hit.t, at, world, tangent));
            }
        }
        let hit = flat?;
        let geometry = self.geometry();
        let b = hit.barycentrics;
        let surface = geometry.surface_at(hit.triangle, b);
        let tangent = || geometry.tangent_at(hit.triangle, b);
        let at = (
            hit.triangle,
            self.mesh.triangle_objects[hit.triangle as usize],
        );
        Some(self.shade(ray, hit.t, at, surface, tangent))
    }

    /// The [`SurfaceHit`] at parameter `t` of `ray` on the world-space point `s` of
    /// triangle `triangle` of object slot `object` (`at`), with the normal map applied (`tangent` gives the interpolated
    /// world-space tangent, asked only for a normal-mapped material), with the smooth and the
    /// mapped normal for the diffuse lobe where the map applied.
    #[inline]
    fn shade(
        &self,
        ray: &Ray,
        t: f32,
        (triangle, object): (u32, u32),
        s: LocalSurface,
        tangent: impl FnOnce() -> Vec4,
    ) -> SurfaceHit {
        let ng = s.ng;
        let material = &self.materials[s.material as usize];
        let tangent = material.tangent_space_map().map(|_| tangent());
        let tangent = tangent.filter(|t| t.truncate() != Vec3::ZERO);
        // A mapped normal made valid on the viewer's side of the surface, as the integrator
        // shades it.
        let wo = -ray.direction;
        let side = if ng.dot(wo) < 0.0 { -1.0 } else { 1.0 };
        let mapped_normal = |map: NormalMap, tangent: Vec4| {
            let n = map.perturb(s.ns, tangent, s.attributes.uv, &self.textures);
            let valid = normal_map::valid_reflection_normal(ng * side, wo, n * side) * side;
            (n, valid)
        };
        let (ns, mapped) = match (material.normal_map, tangent) {
            (Some(map), Some(tangent)) => {
                let (n, valid) = mapped_normal(map, tangent);
                let mapped = MappedNormal {
                    smooth: s.ns,
                    mapped: n,
                };
                (valid, Some(mapped))
            }
            _ => (s.ns, None),
        };
        // The coat's own normal (KHR_materials_clearcoat): its map's, else the interpolated
        // normal where the base's map changed the shading normal.
        let coat_normal = match (material.coat_normal_map(), tangent) {
            (Some(map), Some(tangent)) => Some(mapped_normal(map, tangent).1),
            _ if mapped.is_some() && material.has_coat() => Some(s.ns),
            _ => None,
        };
        SurfaceHit {
            t,
            p: s.p,
            ng,
            ns: if ns.dot(ng) < 0.0 { -ns } else { ns },
            coat_normal: coat_normal.map(|n| if n.dot(ng) < 0.0 { -n } else { n }),
            // Both turned by the smooth normal's side (the mapped one may point below).
            mapped: mapped.map(|m| {
                let side = if m.smooth.dot(ng) < 0.0 { -1.0 } else { 1.0 };
                MappedNormal {
                    smooth: m.smooth * side,
                    mapped: m.mapped * side,
                }
            }),
            attributes: s.attributes,
            triangle,
            material: s.material,
            object,
        }
    }

    /// Whether anything blocks `ray` within `(t_min, ray.t_max)` (shadow query), with the
    /// same alpha test as [`Scene::intersect`]; rain drops cast no shadow ([`crate::rain`]).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.accel
            .occluded_filtered(ray, |t, b| self.stops(self.geometry(), ray, t, t, b))
            || (!self.instances.is_empty()
                && self.instances.occluded(ray, self.accel.t_min(), |i, t, b| {
                    self.instance_stops(ray, i, t, b)
                }))
    }
}

/// A number in `[0, 1)` that depends only on `ray` (origin and direction) and
/// `triangle` (an id of the triangle): the uniform variate of a `BLEND` surface's stochastic transparency, the same
/// for a ray whichever thread traces it.
#[inline]
fn transparency_hash(ray: &Ray, triangle: u32) -> f32 {
    let words = [
        ray.origin.x,
        ray.origin.y,
        ray.origin.z,
        ray.direction.x,
        ray.direction.y,
        ray.direction.z,
    ];
    let h = words
        .iter()
        .fold(pcg_hash(triangle), |h, w| pcg_hash(h ^ w.to_bits()));
    u32_to_unit_f32(h)
}

/// The bounding box `[min, max]` of `positions` and the instances; `None` when both are
/// empty.
fn bounding_box(positions: &[Vec3], instances: &Instances) -> Option<[Vec3; 2]> {
    let flat = points_bounds(positions);
    match (flat, instances.bounds()) {
        (Some([a, b]), Some([c, d])) => Some([a.min(c), b.max(d)]),
        (flat, inst) => flat.or(inst),
    }
}

/// The bounding box `[min, max]` of `points`; `None` without points.
pub(crate) fn points_bounds(points: &[Vec3]) -> Option<[Vec3; 2]> {
    (!points.is_empty()).then(|| {
        points.iter().fold(
            [Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)],
            |[lo, hi], &p| [lo.min(p), hi.max(p)],
        )
    })
}

/// Centre and radius of a sphere enclosing the box `bounds` (see [`Scene::bounding_sphere`]).
fn bounding_sphere(bounds: Option<[Vec3; 2]>) -> (Vec3, f32) {
    match bounds {
        None => (Vec3::ZERO, 0.0),
        Some([lo, hi]) => ((lo + hi) * 0.5, (hi - lo).length() * 0.5),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Alpha, AlphaMode};
    use crate::texture::{Filter, Sampler, TextureRef};
    use glam::Vec4;

    /// SplitMix64: a tiny fixed-seed generator for test data.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
        fn vec(&mut self, scale: f32) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 * scale - scale
        }
    }

    /// Random triangle soup of `n` triangles in a cube of half-size 10.
    fn soup(rng: &mut Rng, n: usize) -> SceneParts {
        let mut parts = SceneParts {
            source: "soup".into(),
            materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
            ..SceneParts::default()
        };
        for i in 0..n {
            let c = rng.vec(10.0);
            for _ in 0..3 {
                parts.mesh.positions.push(c + rng.vec(1.0));
            }
            let k = 3 * i as u32;
            parts.mesh.triangles.push([k, k + 1, k + 2]);
            parts.mesh.triangle_materials.push(0);
        }
        parts
    }

    /// Möller-Trumbore without culling: `(t, b1, b2)`.
    fn brute_hit(p: [Vec3; 3], ray: &Ray) -> Option<(f32, f32, f32)> {
        let e1 = p[1] - p[0];
        let e2 = p[2] - p[0];
        let q = ray.direction.cross(e2);
        let det = e1.dot(q);
        if det.abs() < 1e-12 {
            return None;
        }
        let s = ray.origin - p[0];
        let b1 = s.dot(q) / det;
        let r = s.cross(e1);
        let b2 = ray.direction.dot(r) / det;
        let t = e2.dot(r) / det;
        (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && t > 1e-4 && t < ray.t_max)
            .then_some((t, b1, b2))
    }

    #[test]
    fn intersect_and_occluded_agree_with_brute_force() {
        let mut rng = Rng(7);
        let scene = Scene::from_parts(soup(&mut rng, 3000)).unwrap();
        let (mut hits, mut mismatches) = (0, 0);
        for k in 0..2000 {
            let mut ray = Ray::new(rng.vec(12.0), rng.vec(1.0).normalize());
            if k % 2 == 1 {
                ray.t_max = 6.0 * rng.next();
            }
            let brute = scene
                .mesh
                .triangles
                .iter()
                .enumerate()
                .filter_map(|(i, t)| {
                    brute_hit(t.map(|v| scene.mesh.positions[v as usize]), &ray).map(|h| (i, h))
                })
                .min_by(|a, b| a.1 .0.total_cmp(&b.1 .0));
            let got = scene.intersect(&ray);
            assert_eq!(scene.occluded(&ray), got.is_some(), "ray {k}");
            match (brute, got) {
                (None, None) => {}
                (Some((i, (t, b1, b2))), Some(h)) => {
                    hits += 1;
                    assert!(
                        (h.t - t).abs() < 1e-4 * t.max(1.0),
                        "ray {k}: {} vs {t}",
                        h.t
                    );
                    if h.triangle as usize == i {
                        let tri = scene.mesh.triangles[i].map(|v| scene.mesh.positions[v as usize]);
                        let p = tri[0] * (1.0 - b1 - b2) + tri[1] * b1 + tri[2] * b2;
                        assert!((h.p - p).length() < 1e-3, "ray {k}");
                        assert!((h.p - ray.at(h.t)).length() < 1e-3, "ray {k}");
                        let ng = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
                        assert!((h.ng - ng).length() < 1e-5 && h.ns == h.ng);
                    }
                }
                // Only rays grazing an edge may disagree.
                _ => mismatches += 1,
            }
        }
        assert!(hits > 300, "too few hits to test anything: {hits}");
        assert!(mismatches <= 2, "{mismatches} mismatches");
    }

    #[test]
    fn empty_scene_misses_everything() {
        let scene = Scene::from_parts(SceneParts::default()).unwrap();
        let ray = Ray::new(Vec3::ONE, Vec3::X);
        assert!(scene.intersect(&ray).is_none() && !scene.occluded(&ray));
        assert_eq!(scene.bounding_sphere(), (Vec3::ZERO, 0.0));
        let err = scene.camera(None).unwrap_err().to_string();
        assert!(err.contains("scene has no camera"), "{err}");
    }

    #[test]
    fn from_parts_checks_indices_and_builds_emitters() {
        let mut rng = Rng(3);
        let mut parts = soup(&mut rng, 4);
        let mut glow = Material::diffuse("glow", Vec3::ZERO);
        glow.emission = Vec3::ONE;
        parts.materials.push(glow);
        parts.mesh.triangle_materials[2] = 1;
        let scene = Scene::from_parts(parts.clone()).unwrap();
        assert!(scene.lights.is_empty());
        let emitters = scene.light_sampler.emitters();
        assert_eq!(emitters.len(), 1);
        assert_eq!(emitters.emitter_of(2), Some((0, 0)));
        assert!((0..4)
            .filter(|&t| t != 2)
            .all(|t| emitters.emitter_of(t).is_none()));
        let (c, r) = scene.bounding_sphere();
        assert!(scene
            .mesh
            .positions
            .iter()
            .all(|p| (*p - c).length() <= r * 1.0001));

        let mut bad = parts.clone();
        bad.mesh.triangles[1][2] = 99;
        let err = Scene::from_parts(bad).unwrap_err().to_string();
        assert!(err.contains("soup: triangle 1"), "{err}");
        let mut bad = parts.clone();
        bad.mesh.triangle_materials[3] = 5;
        let err = Scene::from_parts(bad).unwrap_err().to_string();
        assert!(
            err.contains("triangle 3") && err.contains("material 5"),
            "{err}"
        );
        let mut bad = parts;
        bad.mesh.positions[0].x = f32::NAN;
        assert!(Scene::from_parts(bad).is_err());
    }

    #[test]
    fn emitted_radiance_is_one_sided_unless_double_sided() {
        for double_sided in [false, true] {
            let mut glow = Material::diffuse("glow", Vec3::ZERO);
            glow.emission = Vec3::new(2.0, 1.0, 0.5);
            glow.double_sided = double_sided;
            // A triangle in the plane z = 1 facing -Z, toward the origin.
            let s = Scene::from_parts(SceneParts {
                source: "glow".into(),
                mesh: TriangleMesh {
                    positions: vec![
                        Vec3::new(-0.5, -0.3, 1.0),
                        Vec3::new(0.2, 0.6, 1.0),
                        Vec3::new(0.7, -0.4, 1.0),
                    ],
                    triangles: vec![[0, 1, 2]],
                    triangle_materials: vec![0],
                    ..TriangleMesh::default()
                },
                materials: vec![glow],
                ..SceneParts::default()
            })
            .unwrap();
            let hit = s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z)).unwrap();
            assert_eq!(s.emitted_radiance(&hit, -Vec3::Z), Vec3::new(2.0, 1.0, 0.5));
            let back = s.emitted_radiance(&hit, Vec3::Z);
            assert_eq!(back != Vec3::ZERO, double_sided);
        }
    }

    /// A unit quad in the plane `z` (x, y in [0, 1], uv = (x, y)) of material `material`.
    fn quad(parts: &mut SceneParts, z: f32, material: u32) {
        let k = parts.mesh.positions.len() as u32;
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            parts.mesh.positions.push(Vec3::new(x, y, z));
            parts.mesh.uvs.push(Vec2::new(x, y));
        }
        parts
            .mesh
            .triangles
            .extend([[k, k + 1, k + 2], [k, k + 2, k + 3]]);
        parts.mesh.triangle_materials.extend([material; 2]);
    }

    /// A material whose alpha is `mode` with factor `factor` and `texture` (an alpha map).
    fn alpha_material(mode: AlphaMode, factor: f32, texture: Option<TextureRef>) -> Material {
        let mut m = Material::diffuse("leaf", Vec3::splat(0.5));
        m.alpha = Alpha {
            mode,
            factor,
            texture,
        };
        m
    }

    /// A ray through a masked-out hole hits what lies behind it, and a shadow ray passes; a
    /// ray through the solid part stops there.
    #[test]
    fn alpha_mask_cuts_holes_for_camera_and_shadow_rays() {
        // Alpha map: left half 0 (hole), right half 1 (solid), nearest filtering.
        let map = Texture::from_rgba(
            2,
            1,
            vec![Vec4::new(1.0, 1.0, 1.0, 0.0), Vec4::ONE],
            crate::texture::ColorSpace::Linear,
        )
        .unwrap();
        let texture = TextureRef {
            sampler: Sampler {
                filter: Filter::Nearest,
                ..Sampler::default()
            },
            ..TextureRef::new(0)
        };
        let mut parts = SceneParts {
            source: "mask".into(),
            materials: vec![
                alpha_material(AlphaMode::Mask { cutoff: 0.5 }, 1.0, Some(texture)),
                Material::diffuse("wall", Vec3::ONE),
            ],
            textures: vec![map],
            ..SceneParts::default()
        };
        quad(&mut parts, 1.0, 0);
        quad(&mut parts, 2.0, 1);
        let scene = Scene::from_parts(parts).unwrap();
        let hole = Ray::new(Vec3::new(0.25, 0.5, 0.0), Vec3::Z);
        let solid = Ray::new(Vec3::new(0.75, 0.5, 0.0), Vec3::Z);
        let h = scene.intersect(&hole).unwrap();
        assert!((h.t - 2.0).abs() < 1e-5 && h.material == 1, "{h:?}");
        let h = scene.intersect(&solid).unwrap();
        assert!((h.t - 1.0).abs() < 1e-5 && h.material == 0, "{h:?}");
        let shadow = |mut r: Ray| {
            r.t_max = 1.5;
            scene.occluded(&r)
        };
        assert!(!shadow(hole) && shadow(solid));
        // The factor scales the alpha: at 0.4 everything is below the cutoff.
        let mut parts = SceneParts {
            source: "mask".into(),
            materials: vec![alpha_material(AlphaMode::Mask { cutoff: 0.5 }, 0.4, None)],
            ..SceneParts::default()
        };
        quad(&mut parts, 1.0, 0);
        let scene = Scene::from_parts(parts).unwrap();
        assert!(scene.intersect(&solid).is_none() && !scene.occluded(&solid));
    }

    /// A BLEND surface of alpha 0.3 stops 30% of the rays (within a binomial bound), and the
    /// same ray always gets the same answer, from both queries.
    #[test]
    fn alpha_blend_is_stochastic_and_deterministic() {
        let mut parts = SceneParts {
            source: "blend".into(),
            materials: vec![alpha_material(AlphaMode::Blend, 0.3, None)],
            ..SceneParts::default()
        };
        quad(&mut parts, 1.0, 0);
        let scene = Scene::from_parts(parts).unwrap();
        let mut rng = Rng(11);
        let n = 20_000;
        let mut passed = 0;
        for _ in 0..n {
            let target = Vec3::new(0.05 + 0.9 * rng.next(), 0.05 + 0.9 * rng.next(), 1.0);
            let origin = Vec3::new(rng.next(), rng.next(), -rng.next());
            let ray = Ray::new(origin, (target - origin).normalize());
            let hit = scene.intersect(&ray);
            assert_eq!(scene.intersect(&ray), hit);
            assert_eq!(scene.occluded(&ray), hit.is_some());
            passed += usize::from(hit.is_none());
        }
        let fraction = passed as f64 / n as f64;
        let sigma = (0.7 * 0.3 / n as f64).sqrt();
        assert!((fraction - 0.7).abs() < 4.0 * sigma, "{fraction}");
    }

    #[test]
    fn shading_normal_is_interpolated_and_flipped_to_the_geometric_side() {
        let parts = SceneParts {
            source: "tri".into(),
            mesh: TriangleMesh {
                positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                // Authored pointing away from the winding's normal (+Z).
                normals: vec![-Vec3::Z, Vec3::new(0.6, 0.0, -0.8), -Vec3::Z],
                uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y],
                triangles: vec![[0, 1, 2]],
                triangle_materials: vec![0],
                ..TriangleMesh::default()
            },
            materials: vec![Material::diffuse("m", Vec3::ONE)],
            ..SceneParts::default()
        };
        let scene = Scene::from_parts(parts).unwrap();
        let h = scene
            .intersect(&Ray::new(Vec3::new(0.5, 0.25, -1.0), Vec3::Z))
            .unwrap();
        assert_eq!(h.ng, Vec3::Z);
        let expected = -(Vec3::new(0.3, 0.0, -0.4) - 0.5 * Vec3::Z).normalize();
        assert!((h.ns - expected).length() < 1e-5, "{}", h.ns);
        assert!((h.attributes.uv[0] - Vec2::new(0.5, 0.25)).length() < 1e-6);
    }
}
