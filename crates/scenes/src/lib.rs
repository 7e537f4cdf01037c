//! Generates the glTF scenes shipped in `scenes/`: the paper's configurations (Fig. 2 in three
//! reflectance variants, Fig. 6), realistic rainy streets (full and small) and the Mitsuba 3
//! cross-check scene. Each scene is written as `NAME.gltf` + `NAME.bin` (+ PNG textures),
//! byte-for-byte deterministic; `scenes/README.md` describes them and the scene contract.
//!
//! The pieces: [`mesh::Mesh`] builds triangle meshes from simple solids, [`gltf_writer::Doc`] turns
//! meshes, [`gltf_writer::Material`]s, [`gltf_writer::Light`]s and cameras into a glTF document,
//! [`estimate`] chooses light intensities from the streak's peak radiance, [`wetness`] makes
//! the road's dryness map, and [`paper`], [`street`] and [`crosscheck`] lay out the scenes.
//! [`procedural`] draws streets for datasets, with lamp colours from spectra
//! ([`light_sources`]) and the weather ([`weather`]: rain, fog, sensor, exposure, motion).
//!
//! ```
//! let dir = tempfile::tempdir()?;
//! let written = streaks_scenes::generate_all(dir.path())?;
//! assert!(written.iter().any(|p| p.ends_with("rainy_street.gltf")));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

pub mod albedo;
pub mod buildings;
mod check;
pub mod crosscheck;
pub mod drive;
pub mod estimate;
pub mod gltf_writer;
pub mod light_sources;
pub mod mesh;
pub mod model;
pub mod objects;
pub mod paper;
pub mod procedural;
pub mod road;
pub mod street;
pub mod surfaces;
pub mod weather;
pub mod wetness;

use std::path::{Path, PathBuf};

/// What can go wrong while generating scenes.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Writing a file failed.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A scene element could not be built.
    #[error("scene {scene}, {element}: {reason}")]
    Scene {
        /// Scene name.
        scene: String,
        /// Element (node, material, ...).
        element: String,
        /// What is wrong.
        reason: String,
    },
    /// Encoding a texture failed.
    #[error("cannot encode texture: {0}")]
    Texture(String),
    /// Reading a file failed.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A glTF asset of the user's pool cannot be used.
    #[error("asset {}: {reason}", path.display())]
    Asset {
        /// The asset's file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A generator config does not parse or has a bad value.
    #[error("generator config {origin}: {reason}")]
    Config {
        /// The file (or other source) of the config.
        origin: String,
        /// What is wrong.
        reason: String,
    },
}

/// Builds every shipped scene (in memory).
pub fn build_all() -> Result<Vec<gltf_writer::Doc>, Error> {
    Ok(vec![
        paper::fig2(paper::Fig2::BlinnPhong)?,
        paper::fig2(paper::Fig2::Ward)?,
        paper::fig2(paper::Fig2::Sphere)?,
        paper::fig6()?,
        street::Street::full().build()?,
        street::Street::small().build()?,
        crosscheck::crosscheck()?,
    ])
}

/// Writes every shipped scene into `dir` (which must exist); returns the files written.
pub fn generate_all(dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    for d in build_all()? {
        written.extend(d.write(dir)?);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn committed_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
    }

    /// Regenerating gives exactly the committed files, and every committed scene file is
    /// generated (none is stale).
    #[test]
    fn committed_scenes_are_up_to_date() {
        let tmp = tempfile::tempdir().unwrap();
        let written = generate_all(tmp.path()).unwrap();
        let dir = committed_dir();
        for path in &written {
            let name = path.file_name().unwrap();
            let fresh = std::fs::read(path).unwrap();
            let committed = std::fs::read(dir.join(name)).unwrap_or_else(|_| {
                panic!("{name:?} is not in scenes/: run `cargo run -p streaks-scenes`")
            });
            assert!(
                fresh == committed,
                "{name:?} differs from scenes/: run `cargo run -p streaks-scenes` and commit"
            );
        }
        for entry in std::fs::read_dir(&dir).unwrap() {
            let p = entry.unwrap().path();
            if matches!(p.extension().and_then(|e| e.to_str()), Some("gltf" | "bin")) {
                assert!(
                    written.iter().any(|w| w.file_name() == p.file_name()),
                    "{p:?} is not generated"
                );
            }
        }
    }

    /// One-sided emitters meant to be seen by the driver (windows, signals, lamp lenses, the
    /// car ahead's tail lights, the oncoming car's headlamps) face the driver's eye.
    #[test]
    fn street_emitters_face_the_driver() {
        let tmp = tempfile::tempdir().unwrap();
        generate_all(tmp.path()).unwrap();
        for name in ["rainy_street", "rainy_street_small"] {
            let (doc, buffers, _) = gltf::import(tmp.path().join(format!("{name}.gltf"))).unwrap();
            let eye = glam::Vec3::from(
                doc.nodes()
                    .find(|n| n.name() == Some("driver"))
                    .unwrap()
                    .transform()
                    .decomposed()
                    .0,
            );
            let mut checked = 0;
            for node in doc.nodes() {
                let (Some(mesh), Some(node_name)) = (node.mesh(), node.name()) else {
                    continue;
                };
                let seen = node_name.starts_with("windows_lit")
                    || node_name.starts_with("signal_")
                    || node_name == "lamp_lenses"
                    || node_name == "car_0_tail_lights"
                    || node_name == "car_1_headlamps";
                if !seen {
                    continue;
                }
                for p in mesh.primitives() {
                    let r = p.reader(|b| Some(&buffers[b.index()]));
                    let pos: Vec<glam::Vec3> =
                        r.read_positions().unwrap().map(glam::Vec3::from).collect();
                    let idx: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
                    for t in idx.chunks(3) {
                        let [a, b, c] = [0, 1, 2].map(|k| pos[t[k] as usize]);
                        let n = (b - a).cross(c - a);
                        assert!(n.dot(eye - a) > 0.0, "{name}: {node_name} faces away");
                        checked += 1;
                    }
                }
            }
            assert!(
                checked >= 8,
                "{name}: only {checked} emitter triangles checked"
            );
        }
    }

    /// The committed scenes load with the project's renderer without warnings, with the named
    /// camera, the punctual and emissive lights, and (streets) a road whose alpha follows the
    /// dryness map between the wet and dry values.
    /// The generator writes intensities in candela with the renderer's lumens per watt.
    #[test]
    fn lumens_per_watt_is_the_renderers() {
        assert_eq!(
            crate::gltf_writer::LUMENS_PER_WATT,
            f64::from(streaks_render::light::LUMINOUS_EFFICACY)
        );
    }

    #[test]
    fn committed_scenes_load_in_the_renderer() {
        use streaks_render::bsdf::Bsdf;
        use streaks_render::light::Light;
        use streaks_render::scene::Scene;
        let expect = [
            ("paper_fig2_blinn_phong", "viewer", 3, false),
            ("paper_fig2_ward", "viewer", 3, false),
            ("paper_fig2_sphere", "viewer", 0, true),
            ("paper_fig6", "rig", 1, false),
            ("rainy_street", "driver", 15, true),
            ("rainy_street_small", "driver", 3, true),
            ("crosscheck", "cam", 1, true),
        ];
        for (name, cam, punctual, emissive) in expect {
            let path = committed_dir().join(format!("{name}.gltf"));
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
            let cams: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
            assert_eq!(cams, [cam], "{name}");
            let n_punctual = scene
                .lights
                .iter()
                .filter(|l| matches!(l, Light::Point { .. } | Light::Spot { .. }))
                .count();
            assert_eq!(n_punctual, punctual, "{name}");
            let n_area = scene.light_sampler.emitters().len() - scene.lights.len();
            assert_eq!(n_area > 0, emissive, "{name}: {n_area} emitter meshes");
            if name.starts_with("rainy") {
                let road = scene
                    .materials
                    .iter()
                    .find(|m| m.name == "wet_asphalt")
                    .unwrap();
                let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
                for k in 0..400 {
                    let uv = glam::Vec2::new((k % 20) as f32 / 20.0, (k / 20) as f32 / 20.0);
                    let Bsdf::Ggx(g) = road.bsdf_at(
                        &streaks_render::geometry::VertexAttributes::from_uv(uv),
                        &scene.textures,
                    ) else {
                        panic!("{name}: the road is not ggx");
                    };
                    lo = lo.min(g.alpha);
                    hi = hi.max(g.alpha);
                }
                assert!(lo < 0.03 && hi > 0.25, "{name}: road alpha in [{lo}, {hi}]");
            }
        }
    }

    #[test]
    fn generation_is_deterministic() {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let wa = generate_all(a.path()).unwrap();
        let wb = generate_all(b.path()).unwrap();
        assert_eq!(wa.len(), wb.len());
        for (x, y) in wa.iter().zip(&wb) {
            assert_eq!(std::fs::read(x).unwrap(), std::fs::read(y).unwrap());
        }
    }

    /// The scenes load with the `gltf` crate the renderer uses, with named cameras, the
    /// lights, emissive strengths and extras visible, and the expected sizes.
    #[test]
    fn scenes_load_with_the_gltf_crate() {
        let tmp = tempfile::tempdir().unwrap();
        generate_all(tmp.path()).unwrap();
        let expect = [
            ("paper_fig2_blinn_phong", "viewer", 3, 2, 0),
            ("paper_fig2_ward", "viewer", 3, 2, 0),
            ("paper_fig2_sphere", "viewer", 0, 2500, 3),
            ("paper_fig6", "rig", 1, 2, 0),
            ("rainy_street", "driver", 15, 50_000, 5),
            ("rainy_street_small", "driver", 3, 2_000, 4),
            ("crosscheck", "cam", 1, 1000, 1),
        ];
        for (name, cam, lights, max_tris, emitters) in expect {
            let (doc, buffers, images) =
                gltf::import(tmp.path().join(format!("{name}.gltf"))).unwrap();
            let cams: Vec<_> = doc
                .nodes()
                .filter(|n| n.camera().is_some())
                .map(|n| n.name().unwrap_or("").to_owned())
                .collect();
            assert_eq!(cams, [cam], "{name}");
            let n_lights = doc.lights().map(|l| l.count()).unwrap_or(0);
            if name.starts_with("rainy") {
                assert!(n_lights >= lights.min(3), "{name}: {n_lights} lights");
            } else {
                assert_eq!(n_lights, lights, "{name}");
            }
            let mut tris = 0;
            for m in doc.meshes() {
                for p in m.primitives() {
                    let r = p.reader(|b| Some(&buffers[b.index()]));
                    tris += r.read_indices().unwrap().into_u32().count() / 3;
                }
            }
            assert!(tris <= max_tris, "{name}: {tris} triangles");
            let strong = doc
                .materials()
                .filter(|m| m.emissive_strength().unwrap_or(1.0) > 1.0)
                .count();
            assert!(strong >= emitters, "{name}");
            assert!(
                doc.materials()
                    .filter(|m| m.emissive_strength().is_none())
                    .all(|m| m.extras().is_some()),
                "{name}: a reflecting material without extras.streaks"
            );
            if name.starts_with("rainy") {
                // Dryness, asphalt, stone, brick and wood.
                assert_eq!(images.len(), 5, "{name}");
            }
        }
    }
}
