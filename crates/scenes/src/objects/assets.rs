//! The user's own glTF assets in the object pool.
//!
//! The generator config lists assets (`[[objects.assets]]`), each with its `path` (relative
//! to the config file), semantic `class`, `license` (an SPDX id or the text), `attribution`,
//! `weight`, `role` (what it may replace) and an optional `scale`. [`AssetPool::load`] reads
//! each file with the `gltf` crate (no shell, no network: buffers and images from the file's
//! directory or data URIs) into a [`Model`]: every triangle primitive of the default scene's
//! node tree, placed by the nodes' transforms, turned from glTF's "front faces +Z" to the
//! models' -Z forward, scaled, and moved so that its footprint is centred on the origin and
//! its lowest point is on the ground. Materials keep what the writer can write: base colour
//! factor and texture, metallic, roughness, emission, clear coat, transmission, index of
//! refraction and volume; emissive parts are [`Class::LightSource`].
//!
//! [`AssetPool::pick`] chooses, for a role, between the procedural builder (weight 1) and
//! the assets of that role (their weights); the chosen asset's [`Asset::params`] (path,
//! license, attribution) go into the sample's parameters.

use super::ObjectsConfig;
#[cfg(test)]
use crate::gltf_writer::Reflect;
use crate::gltf_writer::{Clearcoat, Material, Pbr, Png, Transmission, Volume};
use crate::mesh::Mesh;
use crate::model::{transformed, Model};
use crate::Error;
use glam::{Affine3A, Mat4, Vec2, Vec3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use streaks_render::class::Class;

/// What an asset may stand in for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AssetRole {
    /// A parked car (lights off).
    ParkedCar,
    /// A street tree.
    Tree,
    /// A pole (lamp post without light, utility pole).
    Pole,
    /// A road sign.
    Sign,
    /// A bus stop.
    BusStop,
    /// A bollard.
    Bollard,
    /// Any other furniture on the pavement (benches, bins, planters).
    Furniture,
}

/// One entry of `[[objects.assets]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AssetEntry {
    /// The `.gltf` or `.glb` file, relative to the config file.
    pub path: PathBuf,
    /// Its semantic class (a class name: `car`, `vegetation`, `pole`, ...).
    pub class: String,
    /// Its license: an SPDX identifier (`CC0-1.0`, `CC-BY-4.0`) or the license text.
    pub license: String,
    /// Who to credit (may be empty only for `CC0-1.0`).
    #[serde(default)]
    pub attribution: String,
    /// Weight against the procedural builder of its role (which weighs 1).
    #[serde(default = "one")]
    pub weight: f64,
    /// What it may replace.
    pub role: AssetRole,
    /// Factor from the file's units to metres (glTF's unit is the metre: 1).
    #[serde(default)]
    pub scale: Option<f64>,
}

fn one() -> f64 {
    1.0
}

impl AssetEntry {
    /// Checks the entry's values (not the file).
    pub fn validate(&self) -> Result<(), String> {
        if Class::from_name(&self.class).is_none() {
            return Err(format!("class {:?} is not a class name", self.class));
        }
        if self.license.trim().is_empty() {
            return Err("license is empty: give an SPDX id or the license text".into());
        }
        if self.attribution.trim().is_empty() && self.license.trim() != "CC0-1.0" {
            return Err(format!(
                "attribution is empty, but license {:?} is not CC0-1.0",
                self.license
            ));
        }
        if !(self.weight.is_finite() && self.weight >= 0.0) {
            return Err(format!("weight {} must be >= 0", self.weight));
        }
        if let Some(s) = self.scale {
            if !(s.is_finite() && s > 0.0) {
                return Err(format!("scale {s} must be > 0"));
            }
        }
        Ok(())
    }
}

/// A loaded asset: its entry and its model.
#[derive(Clone, Debug)]
pub struct Asset {
    /// The config entry (path as written in the config).
    pub entry: AssetEntry,
    /// The model in the models' frame.
    pub model: Model,
}

impl Asset {
    /// Loads `entry`, its path resolved against `base` (the config file's directory).
    pub fn load(entry: &AssetEntry, base: &Path) -> Result<Self, Error> {
        let path = base.join(&entry.path);
        let fail = |reason: String| Error::Asset {
            path: path.clone(),
            reason,
        };
        entry.validate().map_err(&fail)?;
        let class = Class::from_name(&entry.class).expect("validated");
        if !path.is_file() {
            return Err(fail("no such file".into()));
        }
        let (doc, buffers, images) = gltf::import(&path).map_err(|e| fail(e.to_string()))?;
        let scene = doc
            .default_scene()
            .or_else(|| doc.scenes().next())
            .ok_or_else(|| fail("the file has no scene".into()))?;
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("asset")
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect::<String>();
        let mut loader = Loader {
            buffers: &buffers,
            images: &images,
            stem,
            class,
            model: Model::new(),
        };
        for node in scene.nodes() {
            loader.node(&node, Mat4::IDENTITY).map_err(&fail)?;
        }
        let mut model = loader.model;
        if model.parts.is_empty() {
            return Err(fail("the default scene has no triangle meshes".into()));
        }
        // glTF's front faces +Z, the models' -Z: half a turn about Y; then the scale.
        let scale = entry.scale.unwrap_or(1.0) as f32;
        let turn = Affine3A::from_scale(Vec3::splat(scale))
            * Affine3A::from_rotation_y(std::f32::consts::PI);
        let (lo, hi) = model.bounds(turn);
        let centre = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
        let pose = Affine3A::from_translation(-centre) * turn;
        let mut placed = Model::new();
        placed.merge(&model, pose);
        model = placed;
        Ok(Self {
            entry: entry.clone(),
            model,
        })
    }

    /// What a sample records about the asset it used: path, class, role, license,
    /// attribution.
    pub fn params(&self) -> Value {
        json!({
            "path": self.entry.path.display().to_string(),
            "class": self.entry.class,
            "role": self.entry.role,
            "license": self.entry.license,
            "attribution": self.entry.attribution,
        })
    }
}

struct Loader<'a> {
    buffers: &'a [gltf::buffer::Data],
    images: &'a [gltf::image::Data],
    stem: String,
    class: Class,
    model: Model,
}

impl Loader<'_> {
    fn node(&mut self, node: &gltf::Node, parent: Mat4) -> Result<(), String> {
        let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            let name = node
                .name()
                .or(mesh.name())
                .map_or_else(|| format!("node{}", node.index()), str::to_owned);
            for (k, prim) in mesh.primitives().enumerate() {
                let part = format!("{name}_{k}");
                self.primitive(&prim, m, &part)
                    .map_err(|e| format!("node {name:?}, primitive {k}: {e}"))?;
            }
        }
        for child in node.children() {
            self.node(&child, m)?;
        }
        Ok(())
    }

    fn primitive(&mut self, prim: &gltf::Primitive, m: Mat4, name: &str) -> Result<(), String> {
        if prim.mode() != gltf::mesh::Mode::Triangles {
            return Err(format!(
                "mode {:?}: only triangle lists are read",
                prim.mode()
            ));
        }
        let r = prim.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = r
            .read_positions()
            .ok_or("no POSITION")?
            .map(Vec3::from)
            .collect();
        let indices: Vec<u32> = match r.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if indices.len() % 3 != 0 || indices.iter().any(|&i| i as usize >= positions.len()) {
            return Err("indices out of range or not whole triangles".into());
        }
        let uvs: Option<Vec<Vec2>> = r
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(Vec2::from).collect());
        let normals: Option<Vec<Vec3>> = r.read_normals().map(|n| n.map(Vec3::from).collect());
        let pose = Affine3A::from_mat4(m);
        let mut mesh = Mesh::new();
        match normals {
            Some(n) if n.len() == positions.len() => {
                mesh.positions = positions;
                mesh.normals = n;
                mesh.uvs = uvs
                    .filter(|u| u.len() == mesh.positions.len())
                    .unwrap_or_else(|| vec![Vec2::ZERO; mesh.positions.len()]);
                mesh.indices = indices;
            }
            _ => {
                // Flat facets where the file has no normals (glTF's rule).
                for t in indices.chunks(3) {
                    let p = [0, 1, 2].map(|k| positions[t[k] as usize]);
                    let n = (p[1] - p[0]).cross(p[2] - p[0]);
                    let first = mesh.positions.len() as u32;
                    for k in 0..3 {
                        mesh.positions.push(p[k]);
                        mesh.normals.push(n.normalize_or_zero());
                        let uv = uvs.as_ref().and_then(|u| u.get(t[k] as usize)).copied();
                        mesh.uvs.push(uv.unwrap_or(Vec2::ZERO));
                    }
                    mesh.indices.extend([first, first + 1, first + 2]);
                }
            }
        }
        let mut mesh = transformed(&mesh, pose);
        if pose.matrix3.determinant() < 0.0 {
            // A mirroring transform turns the winding: turn it back.
            for t in mesh.indices.chunks_mut(3) {
                t.swap(1, 2);
            }
        }
        let (material, emissive) = self.material(&prim.material())?;
        let class = if emissive {
            Class::LightSource
        } else {
            self.class
        };
        self.model.push(name, mesh, material, class);
        Ok(())
    }

    /// The material as the writer can write it, and whether it emits.
    fn material(&self, m: &gltf::Material) -> Result<(Material, bool), String> {
        let pbr = m.pbr_metallic_roughness();
        let base = pbr.base_color_factor();
        let mut p = Pbr::new(
            [base[0], base[1], base[2]].map(f64::from),
            f64::from(pbr.metallic_factor()),
            f64::from(pbr.roughness_factor()),
        );
        if let Some(info) = pbr.base_color_texture() {
            if info.tex_coord() == 0 {
                let index = info.texture().source().index();
                let image = self
                    .images
                    .get(index)
                    .ok_or_else(|| format!("image {index} is missing"))?;
                p.base_color_texture = Some(Png {
                    name: format!("{}_{index}", self.stem),
                    bytes: Arc::new(png(image).map_err(|e| format!("image {index}: {e}"))?),
                });
            }
        }
        let num = |v: Option<&Value>, key: &str, default: f64| {
            v.and_then(|v| v.get(key))
                .and_then(Value::as_f64)
                .unwrap_or(default)
        };
        if let Some(c) = m.extension_value("KHR_materials_clearcoat") {
            p.clearcoat = Some(Clearcoat {
                factor: num(Some(c), "clearcoatFactor", 0.0),
                roughness: num(Some(c), "clearcoatRoughnessFactor", 0.0),
            });
        }
        if let Some(t) = m.extension_value("KHR_materials_transmission") {
            let v = m.extension_value("KHR_materials_volume");
            let thickness = num(v, "thicknessFactor", 0.0);
            p.transmission = Some(Transmission {
                factor: num(Some(t), "transmissionFactor", 0.0),
                ior: f64::from(m.ior().unwrap_or(1.5)),
                volume: (thickness > 0.0).then(|| Volume {
                    thickness,
                    attenuation_color: v
                        .and_then(|v| v.get("attenuationColor"))
                        .and_then(|c| serde_json::from_value::<[f64; 3]>(c.clone()).ok())
                        .unwrap_or([1.0; 3]),
                    attenuation_distance: num(v, "attenuationDistance", f64::MAX),
                }),
            });
        }
        let name = m
            .name()
            .map_or_else(|| format!("{}_material", self.stem), str::to_owned);
        let mut material = Material::pbr(&name, p);
        material.double_sided = m.double_sided();
        let strength = m.emissive_strength().unwrap_or(1.0);
        let e = m.emissive_factor().map(|c| f64::from(c * strength));
        let emissive = e.iter().any(|&c| c > 0.0);
        if emissive {
            material.emission = Some(e);
        }
        Ok((material, emissive))
    }
}

/// An 8-bit image of the file as PNG bytes.
fn png(image: &gltf::image::Data) -> Result<Vec<u8>, String> {
    use gltf::image::Format;
    let (w, h) = (image.width, image.height);
    let rgba: Vec<u8> = match image.format {
        Format::R8G8B8A8 => image.pixels.clone(),
        Format::R8G8B8 => image
            .pixels
            .chunks(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        Format::R8G8 => image
            .pixels
            .chunks(2)
            .flat_map(|c| [c[0], c[0], c[0], c[1]])
            .collect(),
        Format::R8 => image.pixels.iter().flat_map(|&c| [c, c, c, 255]).collect(),
        other => return Err(format!("pixel format {other:?} is not read (8-bit only)")),
    };
    let img = image::RgbaImage::from_raw(w, h, rgba)
        .ok_or_else(|| format!("{w} x {h} pixels do not match the data"))?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// The assets of a config, loaded.
#[derive(Clone, Debug, Default)]
pub struct AssetPool {
    /// Every asset, in config order.
    pub assets: Vec<Asset>,
}

impl AssetPool {
    /// Loads every asset of `config.assets`, paths relative to `base` (the config file's
    /// directory); the first that fails is the error.
    pub fn load(config: &ObjectsConfig, base: &Path) -> Result<Self, Error> {
        let assets = config
            .assets
            .iter()
            .map(|e| Asset::load(e, base))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self { assets })
    }

    /// For an object of `role`: an asset of that role, or `None` for the procedural
    /// builder (weight 1 against the assets' weights). Draws one number only when the pool
    /// has assets of that role.
    pub fn pick(&self, rng: &mut ChaCha8Rng, role: AssetRole) -> Option<&Asset> {
        let candidates: Vec<&Asset> = self
            .assets
            .iter()
            .filter(|a| a.entry.role == role && a.entry.weight > 0.0)
            .collect();
        if candidates.is_empty() {
            return None;
        }
        let total = 1.0 + candidates.iter().map(|a| a.entry.weight).sum::<f64>();
        let mut x = rng.random_range(0.0..total) - 1.0;
        if x < 0.0 {
            return None;
        }
        for a in &candidates {
            if x < a.entry.weight {
                return Some(a);
            }
            x -= a.entry.weight;
        }
        candidates.last().copied()
    }
}

/// The directory of a config file, against which asset paths resolve.
pub fn config_dir(config_file: &Path) -> PathBuf {
    config_file
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn fixtures() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets")
    }

    fn entry(path: &str) -> AssetEntry {
        AssetEntry {
            path: PathBuf::from(path),
            class: "street_furniture".into(),
            license: "CC-BY-4.0".into(),
            attribution: "Cesium".into(),
            weight: 1.0,
            role: AssetRole::Furniture,
            scale: None,
        }
    }

    /// Khronos' Box: a unit cube under a node that turns the mesh's +Z up. Loaded, it is
    /// the cube standing on the ground, centred, each vertex where the node's matrix and
    /// the half turn put it; with `scale` 2 it is twice as large.
    #[test]
    fn the_box_loads_with_its_transform() {
        let path = fixtures().join("box/Box.gltf");
        let (doc, buffers, _) = gltf::import(&path).unwrap();
        let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
        let r = prim.reader(|b| Some(&buffers[b.index()].0[..]));
        let file: Vec<Vec3> = r.read_positions().unwrap().map(Vec3::from).collect();
        let file_normals: Vec<Vec3> = r.read_normals().unwrap().map(Vec3::from).collect();
        for scale in [1.0f32, 2.0] {
            let mut e = entry("box/Box.gltf");
            e.scale = (scale != 1.0).then_some(f64::from(scale));
            let a = Asset::load(&e, &fixtures()).unwrap();
            assert_eq!(a.model.parts.len(), 1);
            let mesh = &a.model.parts[0].mesh;
            let (lo, hi) = mesh.bounds();
            assert!(
                (lo - Vec3::new(-0.5, 0.0, -0.5) * scale)
                    .abs()
                    .max_element()
                    < 1e-6
            );
            assert!((hi - Vec3::new(0.5, 1.0, 0.5) * scale).abs().max_element() < 1e-6);
            // The node maps (x, y, z) to (x, z, -y); the half turn about Y to (-x, z, y);
            // then the scale and the lift by half the box.
            let place = |p: Vec3| Vec3::new(-p.x, p.z + 0.5, p.y) * scale;
            assert_eq!(mesh.positions.len(), file.len());
            for (k, &p) in file.iter().enumerate() {
                assert!((mesh.positions[k] - place(p)).length() < 1e-6, "{k}");
                let n = file_normals[k];
                let want = Vec3::new(-n.x, n.z, n.y);
                assert!((mesh.normals[k] - want).length() < 1e-6, "{k}");
            }
            assert_eq!(a.model.parts[0].class, Class::StreetFurniture);
            let Reflect::Pbr(p) = &a.model.parts[0].material.reflect else {
                panic!("not PBR");
            };
            assert_eq!(p.base_color, [f64::from(0.8f32), 0.0, 0.0]);
            assert_eq!((p.metallic, p.roughness), (1.0, 1.0));
            assert_eq!(a.params()["license"], "CC-BY-4.0");
        }
    }

    /// A texture written by the project's writer comes back with the same pixels, the
    /// model is centred on its footprint and put on the ground, and emissive parts are light
    /// sources with their radiance.
    #[test]
    fn textures_and_emission_survive_a_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let img = image::RgbaImage::from_fn(4, 2, |x, y| {
            image::Rgba([x as u8 * 60, y as u8 * 100, 7, 255])
        });
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
        let png = Png {
            name: "tex".into(),
            bytes: Arc::new(bytes.into_inner()),
        };
        let mut doc = crate::gltf_writer::Doc::new("thing", "");
        let mut m = Mesh::new();
        m.cuboid(Vec3::new(2.0, 1.0, 3.0), Vec3::new(4.0, 2.0, 4.0));
        let textured = Pbr {
            base_color_texture: Some(png),
            ..Pbr::new([1.0; 3], 0.0, 0.5)
        };
        doc.add_mesh("box", &m, &Material::pbr("textured", textured))
            .unwrap();
        let mut lamp = Mesh::new();
        lamp.rect(Vec3::new(3.0, 2.5, 3.5), Vec3::X * 0.1, Vec3::Z * 0.1);
        doc.add_mesh("lamp", &lamp, &Material::emitter("glow", [3.0, 2.0, 1.0]))
            .unwrap();
        doc.write(dir.path()).unwrap();
        let mut e = entry("thing.gltf");
        e.class = "car".into();
        let a = Asset::load(&e, dir.path()).unwrap();
        let boxed = a
            .model
            .parts
            .iter()
            .find(|p| p.name.starts_with("box"))
            .unwrap();
        let Reflect::Pbr(p) = &boxed.material.reflect else {
            panic!("not PBR")
        };
        let back = image::load_from_memory(&p.base_color_texture.as_ref().unwrap().bytes)
            .unwrap()
            .to_rgba8();
        assert_eq!(back, img);
        assert_eq!(boxed.class, Class::Car);
        // Footprint x [2, 4], z [3, 4], y from 1 to 2.5: centred and put on the ground.
        let (lo, hi) = boxed.mesh.bounds();
        assert!(
            (lo - Vec3::new(-1.0, 0.0, -0.5)).abs().max_element() < 1e-5,
            "{lo}"
        );
        assert!(
            (hi - Vec3::new(1.0, 1.0, 0.5)).abs().max_element() < 1e-5,
            "{hi}"
        );
        let glow = a
            .model
            .parts
            .iter()
            .find(|p| p.name.starts_with("lamp"))
            .unwrap();
        assert_eq!(glow.class, Class::LightSource);
        let e = glow.material.emission.unwrap();
        assert!(
            (0..3).all(|k| (e[k] - [3.0, 2.0, 1.0][k]).abs() < 1e-6),
            "{e:?}"
        );
    }

    /// A missing file, a file that is not glTF and bad entries give errors naming the file
    /// and the reason.
    #[test]
    fn bad_assets_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let e = Asset::load(&entry("nowhere/car.glb"), dir.path())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("nowhere/car.glb") && e.contains("no such file"),
            "{e}"
        );
        std::fs::write(dir.path().join("junk.gltf"), "{ not json").unwrap();
        let e = Asset::load(&entry("junk.gltf"), dir.path())
            .unwrap_err()
            .to_string();
        assert!(e.contains("junk.gltf"), "{e}");
        let mut bad = entry("box/Box.gltf");
        bad.class = "spaceship".into();
        let e = Asset::load(&bad, &fixtures()).unwrap_err().to_string();
        assert!(e.contains("Box.gltf") && e.contains("spaceship"), "{e}");
        let mut bad = entry("box/Box.gltf");
        bad.attribution.clear();
        assert!(bad.validate().unwrap_err().contains("attribution"));
        bad.license = "CC0-1.0".into();
        bad.validate().unwrap();
        let mut config = ObjectsConfig::default();
        config.assets.push(entry("box/Box.gltf"));
        config.assets[0].scale = Some(-1.0);
        let e = config.validate().unwrap_err();
        assert!(
            e.contains("objects.assets[0]") && e.contains("scale"),
            "{e}"
        );
    }

    /// The pool picks an asset of the role about as often as its weight says, never one of
    /// another role, and is reproducible.
    #[test]
    fn the_pool_picks_by_role_and_weight() {
        let mut config = ObjectsConfig::default();
        let mut e = entry("box/Box.gltf");
        e.weight = 3.0;
        config.assets.push(e);
        let pool = AssetPool::load(&config, &fixtures()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        assert!(pool.pick(&mut rng, AssetRole::Tree).is_none());
        let n = 2000;
        let hits = (0..n)
            .filter(|_| pool.pick(&mut rng, AssetRole::Furniture).is_some())
            .count();
        // Weight 3 against the procedural builder's 1: three quarters.
        assert!((1400..1600).contains(&hits), "{hits}");
    }
}
