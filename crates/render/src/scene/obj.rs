//! The OBJ/MTL loader (through tobj, triangulated, one index per vertex).
//!
//! Materials: `Kd` with a non-zero `Ks` (unless `illum` is 0 or 1) is the paper's
//! normalised blinn_phong with shininess `Ns` (default 1); otherwise Lambertian `Kd`, with
//! `map_Kd` (sRGB) multiplying it. `Ke` is emitted radiance. A missing or unreadable MTL file is
//! a warning: every material becomes the default grey diffuse (albedo 0.5), as do faces without
//! a material. An MTL file or texture map outside the OBJ's folder, or not a regular file, is
//! an error (see the `files` module). OBJ texture coordinates have v pointing up; they are stored as `(u, 1 - v)` to
//! match the glTF convention of [`crate::texture::Texture`]. Bump and normal maps (`map_Bump`,
//! `bump`) are not read: a warning names the material.

use super::files::Files;
use super::{Scene, SceneError, SceneParts};
use crate::material::{Alpha, Material, PaperModel, Reflectance};
use crate::texture::{ColorSpace, Texture, TextureId, TextureRef};
use glam::{Vec2, Vec3};
use std::cell::RefCell;
use std::io::ErrorKind;
use std::path::Path;

/// Albedo of the material used where the MTL gives none.
const DEFAULT_GREY: f32 = 0.5;

/// The lines of an OBJ or MTL file as tobj reads them (split at `\n`, a trailing `\r`
/// dropped), numbered from 1, up to the first that is not UTF-8 (where tobj stops too).
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &str)> {
    bytes
        .split(|&b| b == b'\n')
        .map(|line| std::str::from_utf8(line.strip_suffix(b"\r").unwrap_or(line)))
        .map_while(Result::ok)
        .enumerate()
        .map(|(i, line)| (i + 1, line))
}

/// Checks every index of the OBJ's faces and lines (`f`, `l`) before tobj resolves them: a
/// negative index must not reach before the first element declared so far, a positive one
/// must not exceed the elements of the whole file, and 0 is not an OBJ index. tobj turns an
/// out-of-range relative index into a huge one and overflows multiplying it.
fn check_obj_indices(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    const KINDS: [(&str, &str); 3] = [("v", "vertex"), ("vt", "texcoord"), ("vn", "normal")];
    let kind = |word: &str| KINDS.iter().position(|&(k, _)| k == word);
    let mut total = [0usize; 3];
    for (_, line) in lines(bytes) {
        if let Some(k) = line.split_whitespace().next().and_then(kind) {
            total[k] += 1;
        }
    }
    let mut seen = [0usize; 3];
    for (number, line) in lines(bytes) {
        let mut words = line.split_whitespace();
        match words.next() {
            Some(word @ ("f" | "l")) => {
                for vertex in words {
                    for (k, index) in vertex.split('/').take(3).enumerate() {
                        // What does not parse is left to tobj, which rejects it.
                        let Ok(index) = index.parse::<i64>() else {
                            continue;
                        };
                        let (available, within) = if index < 0 {
                            (seen[k], "declared before it")
                        } else {
                            (total[k], "in the file")
                        };
                        if index == 0 || index.unsigned_abs() > available as u64 {
                            return Err(SceneError::invalid(
                                path,
                                format!("line {number} ({word} {vertex:?})"),
                                format!(
                                    "{} index {index} is out of range ({available} {}s {within})",
                                    KINDS[k].1, KINDS[k].1
                                ),
                            ));
                        }
                    }
                }
            }
            Some(word) => {
                if let Some(k) = kind(word) {
                    seen[k] += 1;
                }
            }
            None => {}
        }
    }
    Ok(())
}

/// Checks that every colour of an MTL file (`Ka`, `Kd`, `Ks`, `Ke`) has three numbers before
/// tobj reads it: with fewer it panics.
fn check_mtl_colours(path: &Path, element: &str, bytes: &[u8]) -> Result<(), SceneError> {
    for (number, line) in lines(bytes) {
        let mut words = line.split_whitespace();
        if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
            let n = words.count();
            if n < 3 {
                return Err(SceneError::invalid(
                    path,
                    format!("{element}, line {number} ({key})"),
                    format!("a colour needs 3 numbers, it has {n}"),
                ));
            }
        }
    }
    Ok(())
}

/// Loads an `.obj` file and its MTL, reading them through `files`: the MTL and the texture
/// maps resolve inside the OBJ's folder, and a refused one (outside the folder, not a
/// regular file, too large) is an error; a missing or unreadable one is a warning.
pub(super) fn load(path: &Path, files: &Files) -> Result<Scene, SceneError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let bytes = files.read_scene()?;
    check_obj_indices(path, &bytes)?;
    // What reading the material libraries met: refusals fail the load, the rest are warnings.
    let refused: RefCell<Option<SceneError>> = RefCell::new(None);
    let unreadable: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let loaded = tobj::load_obj_buf(&mut bytes.as_slice(), &options, |name| {
        let element = format!("mtllib {:?}", name.display().to_string());
        let read = files
            .resolve(name, &element)
            .and_then(|file| files.read(&file, &element));
        match read {
            Ok(bytes) => match check_mtl_colours(path, &element, &bytes) {
                Ok(()) => tobj::load_mtl_buf(&mut bytes.as_slice()),
                Err(e) => {
                    refused.borrow_mut().get_or_insert(e);
                    Err(tobj::LoadError::OpenFileFailed)
                }
            },
            Err(SceneError::Io { source, .. })
                if !matches!(
                    source.kind(),
                    ErrorKind::InvalidInput | ErrorKind::InvalidData
                ) =>
            {
                unreadable.borrow_mut().push(format!("{element}: {source}"));
                Err(tobj::LoadError::OpenFileFailed)
            }
            Err(e) => {
                refused.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    if let Some(e) = refused.into_inner() {
        return Err(e);
    }
    let (models, mtl) = loaded.map_err(|source| SceneError::Obj {
        path: path.to_path_buf(),
        source,
    })?;
    let mut parts = SceneParts {
        source: path.to_path_buf(),
        ..SceneParts::default()
    };
    let mtl = match mtl {
        Ok(m) => m,
        Err(e) => {
            let unreadable = unreadable.into_inner();
            let why = if unreadable.is_empty() {
                e.to_string()
            } else {
                unreadable.join("; ")
            };
            parts.warnings.push(format!(
                "{}: material library not loaded ({why}); using grey diffuse",
                path.display()
            ));
            Vec::new()
        }
    };
    for m in &mtl {
        if let Some(map) = &m.normal_texture {
            parts.warnings.push(format!(
                "{}: material {:?}: bump/normal map {map:?} (map_Bump, bump) is not supported; \
                 rendered with the mesh's normals",
                path.display(),
                m.name
            ));
        }
        let material = convert_material(path, files, m, &mut parts.textures)?;
        parts.materials.push(material);
    }
    let default = parts.materials.len() as u32;
    parts
        .materials
        .push(Material::diffuse("default", Vec3::splat(DEFAULT_GREY)));
    // The objects, one after another, as the scene's flat triangles.
    let flat = &mut parts.mesh;
    for model in &models {
        let mesh = &model.mesh;
        let element = format!("object {:?}", model.name);
        let n = mesh.positions.len() / 3;
        let first = flat.positions.len();
        if first + n > u32::MAX as usize {
            return Err(SceneError::invalid(
                path,
                element,
                "the scene has more than 2^32 - 1 vertices",
            ));
        }
        let material = match mesh.material_id {
            Some(i) if i < mtl.len() => i as u32,
            Some(i) if !mtl.is_empty() => {
                return Err(SceneError::invalid(
                    path,
                    element,
                    format!("material {i} out of range ({} materials)", mtl.len()),
                ))
            }
            _ => default,
        };
        for (k, c) in mesh.positions.chunks_exact(3).enumerate() {
            let p = Vec3::new(c[0], c[1], c[2]);
            super::validate::position(p)
                .map_err(|r| SceneError::invalid(path, format!("{element}, vertex {k}"), r))?;
            flat.positions.push(p);
        }
        if mesh.normals.len() == 3 * n {
            flat.normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]).normalize_or_zero()),
            );
        } else {
            flat.normals.extend(std::iter::repeat_n(Vec3::ZERO, n));
        }
        if mesh.texcoords.len() == 2 * n {
            flat.uvs.extend(
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|c| Vec2::new(c[0], 1.0 - c[1])),
            );
        } else {
            flat.uvs.extend(std::iter::repeat_n(Vec2::ZERO, n));
        }
        for (k, t) in mesh.indices.chunks_exact(3).enumerate() {
            if t.iter().any(|&i| i as usize >= n) {
                return Err(SceneError::invalid(
                    path,
                    format!("{element}, face {k}"),
                    format!("vertex index out of range ({n} vertices)"),
                ));
            }
            let first = first as u32;
            flat.triangles
                .push([t[0] + first, t[1] + first, t[2] + first]);
            flat.triangle_materials.push(material);
        }
    }
    Scene::from_parts(parts)
}

fn convert_material(
    path: &Path,
    files: &Files,
    m: &tobj::Material,
    textures: &mut Vec<Texture>,
) -> Result<Material, SceneError> {
    let element = format!("material {:?}", m.name);
    let colour = |c: Option<[f32; 3]>, key: &str| -> Result<Vec3, SceneError> {
        let v = Vec3::from(c.unwrap_or([0.0; 3]));
        if v.is_finite() && v.min_element() >= 0.0 {
            Ok(v)
        } else {
            Err(SceneError::invalid(
                path,
                &element,
                format!("{key} {v} must be finite and non-negative"),
            ))
        }
    };
    let kd = match m.diffuse {
        Some(c) => colour(Some(c), "Kd")?,
        None => Vec3::splat(DEFAULT_GREY),
    };
    let ks = colour(m.specular, "Ks")?;
    let emission = colour(m.emissive, "Ke")?;
    let kd_texture = match &m.diffuse_texture {
        Some(file) => Some(TextureRef::new(load_texture(
            path, files, file, &element, textures,
        )?)),
        None => None,
    };
    let specular = ks.max_element() > 0.0 && !matches!(m.illumination_model, Some(0 | 1));
    let reflectance = if specular {
        let shininess = m.shininess.unwrap_or(1.0);
        if !(shininess.is_finite() && shininess >= 0.0) {
            return Err(SceneError::invalid(
                path,
                element,
                format!("Ns {shininess} must be finite and non-negative"),
            ));
        }
        Reflectance::Paper {
            model: PaperModel::BlinnPhong,
            kd,
            ks,
            alpha: 0.0,
            shininess,
            kd_texture,
            wetness: None,
            retro: None,
        }
    } else {
        Reflectance::Diffuse { kd, kd_texture }
    };
    Ok(Material {
        name: m.name.clone(),
        reflectance,
        emission,
        emission_texture: None,
        normal_map: None,
        alpha: Alpha::OPAQUE,
        double_sided: false,
        road: false,
    })
}

/// Decodes the `map_Kd` texture `file` of `material` (sRGB), read through `files`.
fn load_texture(
    path: &Path,
    files: &Files,
    file: &str,
    material: &str,
    textures: &mut Vec<Texture>,
) -> Result<TextureId, SceneError> {
    let element = format!("{material}, map_Kd {file:?}");
    let file_path = files.resolve(Path::new(file), &element)?;
    let bytes = files.read(&file_path, &element)?;
    let img = streaks_image::input::decode_image(&bytes, image::ImageFormat::from_path(file).ok())
        .map_err(|reason| SceneError::invalid(path, &element, reason))?;
    drop(bytes);
    let rgba = img.to_rgba8();
    let texture = Texture::from_rgba8(rgba.width(), rgba.height(), rgba.as_raw(), ColorSpace::Srgb)
        .ok_or_else(|| SceneError::invalid(path, &element, "empty image"))?;
    textures.push(texture);
    Ok((textures.len() - 1) as TextureId)
}

#[cfg(test)]
mod tests {
    use super::*;

    const OBJ: &str = "mtllib road.mtl
v 0 0 0
v 1 0 0
v 1 0 -1
v 0 0 -1
v 0 2 0
v 1 2 0
v 0 3 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 1 0
o road
usemtl wet
f 1/1/1 2/2/1 3/3/1 4/4/1
o lamp
usemtl glow
f 5 6 7
o kerb
usemtl plain
f 1 2 5
";

    const MTL: &str = "newmtl wet
Kd 0.1 0.1 0.1
Ks 0.6 0.6 0.6
Ns 200
illum 2
newmtl glow
Kd 0 0 0
Ke 4 3 2
newmtl plain
Kd 0.7 0.6 0.5
Ks 0.5 0.5 0.5
illum 1
";

    /// Loads `obj` (with `mtl` as `m.mtl` beside it) and returns the error message.
    fn obj_err(obj: &str, mtl: &str) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.obj");
        std::fs::write(&path, obj).unwrap();
        std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(err.contains("bad.obj"), "{err}");
        err
    }

    #[test]
    fn face_indices_out_of_range_are_errors() {
        let quad = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\n";
        for (face, what) in [
            (
                "f 1/-3 2/1 3/1",
                "texcoord index -3 is out of range (2 texcoords declared",
            ),
            (
                "f 1//-2 2//1 3//1",
                "normal index -2 is out of range (1 normals declared",
            ),
            ("f -4 -3 -2", "vertex index -4"),
            (
                "f 1/9223372036854775807 2/1 3/1",
                "texcoord index 9223372036854775807",
            ),
            ("f 1/0 2/1 3/1", "texcoord index 0"),
        ] {
            let err = obj_err(&format!("{quad}{face}\n"), "");
            assert!(
                err.contains("line 7") && err.contains(what),
                "{face}: {err}"
            );
        }
        // Relative indices within range load.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ok.obj");
        std::fs::write(&path, format!("{quad}f -3/-2/-1 -2/-1/-1 -1/-1/-1\n")).unwrap();
        assert_eq!(Scene::load(&path).unwrap().mesh.triangles.len(), 1);
    }

    #[test]
    fn an_mtl_colour_with_fewer_than_three_numbers_is_an_error() {
        for colour in ["Kd", "Ke 1", "Ks 1 1"] {
            let err = obj_err(
                "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                &format!("newmtl a\n{colour}\n"),
            );
            assert!(
                err.contains("mtllib \"m.mtl\", line 2") && err.contains("needs 3 numbers"),
                "{colour}: {err}"
            );
        }
    }

    #[test]
    fn loads_obj_with_mtl() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("street.obj");
        std::fs::write(&path, OBJ).unwrap();
        std::fs::write(dir.path().join("road.mtl"), MTL).unwrap();
        let scene = Scene::load(&path).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        assert_eq!(scene.mesh.triangles.len(), 4);
        assert!(scene.cameras.is_empty());
        let wet = &scene.materials[scene.mesh.triangle_materials[0] as usize];
        assert_eq!(wet.name, "wet");
        assert!(matches!(wet.reflectance, Reflectance::Paper {
            model: PaperModel::BlinnPhong, shininess, ks, ..
        } if shininess == 200.0 && ks == Vec3::splat(0.6)));
        let plain = &scene.materials[scene.mesh.triangle_materials[3] as usize];
        assert!(
            matches!(plain.reflectance, Reflectance::Diffuse { kd, kd_texture: None }
            if kd == Vec3::new(0.7, 0.6, 0.5))
        );
        let glow = &scene.materials[scene.mesh.triangle_materials[2] as usize];
        assert_eq!(glow.emission, Vec3::new(4.0, 3.0, 2.0));
        assert!(scene.lights.is_empty());
        assert_eq!(scene.light_sampler.emitters().emitter_of(2), Some((0, 0)));
        assert_eq!(scene.light_sampler.emitters().len(), 1);
        // The road faces up, with flipped v, and normals from the file.
        let h = scene
            .intersect(&crate::geometry::Ray::new(
                Vec3::new(0.75, 1.0, -0.5),
                -Vec3::Y,
            ))
            .unwrap();
        assert_eq!((h.ng, h.ns), (Vec3::Y, Vec3::Y));
        assert!(
            (h.attributes.uv[0] - Vec2::new(0.75, 0.5)).length() < 1e-5,
            "{}",
            h.attributes.uv[0]
        );
    }

    #[test]
    fn missing_mtl_is_a_warning() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("street.obj");
        std::fs::write(&path, OBJ).unwrap();
        let scene = Scene::load(&path).unwrap();
        // The missing library, and (nothing emits) the default environment.
        assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
        assert!(scene.warnings[0].contains("street.obj"));
        assert!(scene.warnings[1].ends_with(crate::scene::NO_LIGHT_WARNING));
        assert!(scene.lights.is_empty());
        assert!(scene.mesh.triangle_materials.iter().all(|&m| m == 0));
        assert!(
            matches!(scene.materials[0].reflectance, Reflectance::Diffuse { kd, .. }
            if kd == Vec3::splat(DEFAULT_GREY))
        );
    }

    /// One face of 500,000 vertices on a circle (a huge polygon): triangulated as a fan in
    /// linear time, and its slivers, which all hold the first vertex, get their BVH in about
    /// `n log n` (a million took 68 s before).
    #[test]
    fn huge_polygons_load_quickly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("disc.obj");
        let n = 500_000;
        let mut text = String::new();
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            text += &format!("v {} {} 0\n", a.cos(), a.sin());
        }
        text += "f";
        for i in 1..=n {
            text += &format!(" {i}");
        }
        text += "\n";
        std::fs::write(&path, text).unwrap();
        let start = std::time::Instant::now();
        let scene = Scene::load(&path).unwrap();
        let took = start.elapsed();
        assert!(took < std::time::Duration::from_secs(5), "{took:?}");
        assert_eq!(scene.mesh.triangles.len(), n - 2);
    }

    /// A vertex beyond the BVH's range is an error naming the object and the vertex.
    #[test]
    fn overflowing_positions_name_the_object() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("far.obj");
        std::fs::write(&path, "o far\nv 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("far.obj") && err.contains("object \"far\", vertex 1"),
            "{err}"
        );
    }

    #[test]
    fn malformed_obj_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.obj");
        std::fs::write(&path, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(err.contains("bad.obj"), "{err}");
        let err = Scene::load(&dir.path().join("none.obj"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("none.obj"), "{err}");
        // A map_Kd that does not exist names the material and the file.
        std::fs::write(
            &path,
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("m.mtl"),
            "newmtl a\nKd 1 1 1\nmap_Kd gone.png\n",
        )
        .unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("material \"a\"") && err.contains("gone.png"),
            "{err}"
        );
    }
}
