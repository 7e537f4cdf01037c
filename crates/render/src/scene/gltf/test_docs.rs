//! glTF documents for the loader's tests: a builder of buffers and accessors, the test scene,
//! writers of embedded, external and GLB files, and helpers shared by the tests of several files.

use crate::light::Light;
use crate::material::{GltfPbrParams, PaperModel, Reflectance};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use serde_json::{json, Value};
use std::f32::consts::FRAC_1_SQRT_2;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A glTF document under construction: one binary buffer, views and accessors.
#[derive(Default)]
pub(super) struct Doc {
    pub(super) bin: Vec<u8>,
    pub(super) views: Vec<Value>,
    pub(super) accessors: Vec<Value>,
}

impl Doc {
    pub(super) fn view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    pub(super) fn floats(&mut self, data: &[f32], ty: &str, width: usize) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let mut acc = json!({"bufferView": view, "componentType": 5126,
            "count": data.len() / width, "type": ty});
        if ty == "VEC3" {
            let col = |k: usize| data.iter().skip(k).step_by(3).copied();
            let min: Vec<f32> = (0..3).map(|k| col(k).fold(f32::MAX, f32::min)).collect();
            let max: Vec<f32> = (0..3).map(|k| col(k).fold(f32::MIN, f32::max)).collect();
            acc["min"] = json!(min);
            acc["max"] = json!(max);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    pub(super) fn indices(&mut self, data: &[u16]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors
            .push(json!({"bufferView": view, "componentType": 5123,
            "count": data.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }
}

/// The test document ([`test_doc`]) with `value` as `scenes[0].extras.streaks.<key>`, and its
/// buffer: how the scene-level extras (environment, fog, rain) are tested.
pub(super) fn test_doc_with_streaks_extra(key: &str, value: Value) -> (Value, Vec<u8>) {
    let (mut doc, bin) = test_doc();
    doc["scenes"][0]["extras"] = serde_json::json!({ "streaks": { key: value } });
    (doc, bin)
}

/// The test scene: a quad (indexed, normals, uvs) under a TRS parent and a matrix child, a
/// non-indexed emissive triangle without normals, a camera, and three punctual lights.
pub(super) fn test_doc() -> (Value, Vec<u8>) {
    let mut d = Doc::default();
    let quad_pos = d.floats(&[0., 0., 0., 0., 0., 1., 1., 0., 1., 1., 0., 0.], "VEC3", 3);
    let quad_nrm = d.floats(&[0., 1., 0.].repeat(4), "VEC3", 3);
    let quad_uv = d.floats(&[0., 0., 0., 1., 1., 1., 1., 0.], "VEC2", 2);
    let quad_idx = d.indices(&[0, 1, 2, 0, 2, 3]);
    let tri_pos = d.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3", 3);
    let s = FRAC_1_SQRT_2;
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 2, 3, 4, 5, 6]}],
        "nodes": [
            {"name": "parent", "translation": [0, 1, 0], "scale": [2, 2, 2], "children": [1]},
            {"name": "child", "mesh": 0,
             "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 10,0,0,1]},
            {"name": "lamp", "mesh": 1, "translation": [0, 0, -3]},
            {"name": "cam_node", "camera": 0, "translation": [0, 2, 5], "scale": [3, 3, 3],
             "rotation": [0, s, 0, s]},
            {"name": "bulb", "translation": [1, 2, 3],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "spot", "translation": [0, 5, 0], "rotation": [-s, 0, 0, s],
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 2}}}
        ],
        "meshes": [
            {"name": "quad", "primitives": [{"attributes":
                {"POSITION": quad_pos, "NORMAL": quad_nrm, "TEXCOORD_0": quad_uv},
                "indices": quad_idx, "material": 0}]},
            {"name": "tri", "primitives": [{"attributes": {"POSITION": tri_pos}, "material": 1}]}
        ],
        "materials": [
            {"name": "asphalt", "extras": {"streaks": {"bsdf": "ggx", "kd": [0.1, 0.1, 0.1],
                "ks": [0.5, 0.5, 0.5], "alpha": 0.05}}},
            {"name": "glow", "emissiveFactor": [1, 0.5, 0], "doubleSided": true,
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}],
        // Candela and lux: 10 W/sr, 3 W/sr and 2 W/m^2 at 683 lm/W.
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.25], "intensity": 6830, "range": 20},
            {"type": "spot", "intensity": 2049, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
            {"type": "directional", "intensity": 1366}
        ]}},
        "buffers": [{"byteLength": d.bin.len()}],
        "bufferViews": d.views,
        "accessors": d.accessors
    });
    (doc, d.bin)
}

pub(super) fn write_embedded(dir: &Path, mut doc: Value, bin: &[u8]) -> PathBuf {
    doc["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::encode(bin)
    ));
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    path
}

pub(super) fn write_external(dir: &Path, mut doc: Value, bin: &[u8]) -> PathBuf {
    doc["buffers"][0]["uri"] = json!("scene data.bin");
    std::fs::write(dir.join("scene data.bin"), bin).unwrap();
    let path = dir.join("external.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

pub(super) fn write_glb(dir: &Path, doc: &Value, bin: &[u8]) -> PathBuf {
    let mut json = serde_json::to_vec(doc).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(&bin);
    let path = dir.join("scene.glb");
    std::fs::write(&path, out).unwrap();
    path
}

pub(super) fn approx(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

pub(super) fn check_test_scene(scene: &Scene) {
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // Quad: world = T(0,1,0) S(2) T(10,0,0).
    assert_eq!(scene.mesh.triangles.len(), 3);
    assert!(approx(scene.mesh.positions[2], Vec3::new(22.0, 1.0, 2.0)));
    assert!(approx(scene.mesh.positions[0], Vec3::new(20.0, 1.0, 0.0)));
    assert!(approx(scene.mesh.normals[1], Vec3::Y));
    assert_eq!(scene.mesh.uvs[2], Vec2::new(1.0, 1.0));
    // The emissive triangle has face normals (stored as zero) and sits at z = -3.
    assert_eq!(scene.mesh.normals[5], Vec3::ZERO);
    assert!(approx(scene.mesh.positions[5], Vec3::new(1.0, 0.0, -3.0)));
    // A ray down onto the quad hits it with the right uv and normal.
    let hit = scene
        .intersect(&crate::geometry::Ray::new(
            Vec3::new(21.0, 5.0, 0.5),
            -Vec3::Y,
        ))
        .expect("hits the quad");
    assert!((hit.t - 4.0).abs() < 1e-5 && approx(hit.ng, Vec3::Y) && approx(hit.ns, Vec3::Y));
    assert!(
        (hit.attributes.uv[0] - Vec2::new(0.5, 0.25)).length() < 1e-5,
        "{}",
        hit.attributes.uv[0]
    );
    assert_eq!(scene.materials[hit.material as usize].name, "asphalt");
    // The triangle: ng = +Z from its winding, ns falls back to ng.
    let hit = scene
        .intersect(&crate::geometry::Ray::new(
            Vec3::new(0.2, 0.2, 1.0),
            -Vec3::Z,
        ))
        .unwrap();
    assert!(approx(hit.ng, Vec3::Z) && approx(hit.ns, Vec3::Z));
    // Materials.
    let Reflectance::Paper {
        model, ks, alpha, ..
    } = &scene.materials[0].reflectance
    else {
        panic!("asphalt is not a paper material")
    };
    assert_eq!((*model, *alpha), (PaperModel::Ggx, 0.05));
    assert!(approx(*ks, Vec3::splat(0.5)));
    let glow = &scene.materials[1];
    assert!(approx(glow.emission, Vec3::new(5.0, 2.5, 0.0)) && glow.double_sided);
    assert!(matches!(
        glow.reflectance,
        Reflectance::GltfPbr(GltfPbrParams { metallic: 1.0, .. })
    ));
    // Camera: named after the node, scale removed, looking along world -X.
    let cam = scene.camera(None).unwrap();
    assert_eq!(cam.name, "cam_node");
    assert_eq!(scene.camera(Some("cam_node")).unwrap().name, "cam_node");
    assert!((cam.yfov().unwrap() - 0.7).abs() < 1e-6 && cam.aspect_ratio() == Some(1.5));
    assert!(approx(cam.position(), Vec3::new(0.0, 2.0, 5.0)));
    let fwd = cam.world_from_camera.transform_vector3(-Vec3::Z);
    assert!(approx(fwd, -Vec3::X), "{fwd}");
    assert!((cam.world_from_camera.matrix3.determinant() - 1.0).abs() < 1e-5);
    let err = scene.camera(Some("nope")).unwrap_err().to_string();
    assert!(
        err.contains("nope") && err.contains("\"cam_node\""),
        "{err}"
    );
    // Lights: three punctual ones; emitters: those and the emissive triangle.
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(
        scene.lights[0],
        Light::Point {
            position: Vec3::new(1.0, 2.0, 3.0),
            intensity: Vec3::new(10.0, 5.0, 2.5),
            range: Some(20.0)
        }
    );
    let Light::Spot {
        position,
        direction,
        cos_inner,
        cos_outer,
        range,
        ..
    } = scene.lights[1]
    else {
        panic!("not a spot")
    };
    assert!(approx(position, Vec3::new(0.0, 5.0, 0.0)) && approx(direction, -Vec3::Y));
    assert!((cos_inner - 0.2f32.cos()).abs() < 1e-6 && (cos_outer - 0.5f32.cos()).abs() < 1e-6);
    assert_eq!(range, None);
    assert!(
        matches!(scene.lights[2], Light::Directional { direction, irradiance }
        if approx(direction, -Vec3::Z) && approx(irradiance, Vec3::splat(2.0)))
    );
    let emitters = scene.light_sampler.emitters();
    assert_eq!(emitters.len(), 4);
    assert_eq!(emitters.emitter_of(2), Some((3, 0)));
}

/// Loads `doc` (embedded) and returns the error message; panics if it loads.
pub(super) fn load_err(doc: Value, bin: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = write_embedded(dir.path(), doc, bin);
    let err = Scene::load(&path).expect_err("should fail").to_string();
    assert!(err.contains("scene.gltf"), "no file name in: {err}");
    err
}

/// A 1x1 PNG of `rgb` as a data URI (a tiny embedded texture).
pub(super) fn png_uri(rgb: [u8; 3]) -> String {
    let png = png_bytes(1, 1, vec![rgb[0], rgb[1], rgb[2], 255]);
    format!("data:image/png;base64,{}", base64::encode(png))
}

/// A `width` x `height` PNG of the RGBA bytes `texels`.
pub(super) fn png_bytes(width: u32, height: u32, texels: Vec<u8>) -> Vec<u8> {
    let mut png = Vec::new();
    image::RgbaImage::from_raw(width, height, texels)
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// A temporary folder holding that PNG as `name`.
pub(super) fn png_file(name: &str, width: u32, height: u32, texels: Vec<u8>) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(name), png_bytes(width, height, texels)).unwrap();
    dir
}

/// The test document with a normal texture on the quad's material ("asphalt") that tilts
/// the normal by `theta` toward +X of tangent space; the quad's tangent space is: tangent
/// +X (u), bitangent -Z (up the image: glTF's v grows along +Z), normal +Y.
pub(super) fn normal_mapped_doc(theta: f32, scale: f32) -> (Value, Vec<u8>) {
    let (mut doc, bin) = test_doc();
    let texel = |x: f32| (255.0 * (x + 1.0) / 2.0).round() as u8;
    doc["images"] = json!([{"uri": png_uri([texel(theta.sin()), 128, texel(theta.cos())])}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"][0]["normalTexture"] = json!({"index": 0, "scale": scale});
    (doc, bin)
}

pub(super) fn load_doc(doc: Value, bin: &[u8]) -> Scene {
    let dir = tempfile::tempdir().unwrap();
    Scene::load(&write_embedded(dir.path(), doc, bin)).unwrap()
}

/// The shading normal of a ray straight down onto the quad.
pub(super) fn quad_normal(scene: &Scene) -> Vec3 {
    let ray = crate::geometry::Ray::new(Vec3::new(21.0, 5.0, 0.5), -Vec3::Y);
    scene.intersect(&ray).unwrap().ns
}

/// Appends `bytes` to the buffer as an accessor of `count` elements of `kind` ("VEC3") and
/// `component_type` (5126: float); returns its index.
pub(super) fn add_accessor(
    doc: &mut Value,
    bin: &mut Vec<u8>,
    bytes: &[u8],
    (component_type, count, kind): (u32, usize, &str),
) -> usize {
    let offset = bin.len();
    bin.extend(bytes);
    // Each view starts on a 4-byte boundary.
    bin.resize(bin.len().next_multiple_of(4), 0);
    let views = doc["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}));
    let view = views.len() - 1;
    let accessors = doc["accessors"].as_array_mut().unwrap();
    accessors.push(json!({"bufferView": view, "componentType": component_type,
        "count": count, "type": kind}));
    let index = accessors.len() - 1;
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    index
}

/// Appends `values` to the buffer as a float VEC3 accessor; returns its index.
pub(super) fn add_vec3s(doc: &mut Value, bin: &mut Vec<u8>, values: &[f32]) -> usize {
    let bytes: Vec<u8> = values.iter().flat_map(|f| f.to_le_bytes()).collect();
    add_accessor(doc, bin, &bytes, (5126, values.len() / 3, "VEC3"))
}

/// Gives the quad a TANGENT attribute of `t` at every vertex.
pub(super) fn add_tangent(doc: &mut Value, bin: &mut Vec<u8>, t: [f32; 4]) {
    let offset = bin.len();
    bin.extend(t.repeat(4).iter().flat_map(|f| f.to_le_bytes()));
    let views = doc["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 64}));
    let view = views.len() - 1;
    let accessors = doc["accessors"].as_array_mut().unwrap();
    accessors.push(
        json!({"bufferView": view, "componentType": 5126, "count": 4,
        "type": "VEC4"}),
    );
    doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(accessors.len() - 1);
    doc["buffers"][0]["byteLength"] = json!(bin.len());
}

/// A box of 24 vertices (flat normals, uvs, one TANGENT per face) with a normal-mapped
/// material, and a quad in front of it whose COLOR_0 alpha runs from 0 to 1 along x under
/// an alphaMode MASK material: the primitives of the mesh the instancing tests place.
pub(super) fn box_mesh(d: &mut Doc) -> Value {
    let faces = [
        (Vec3::X, Vec3::Z),
        (-Vec3::X, Vec3::Y),
        (Vec3::Y, Vec3::X),
        (-Vec3::Y, Vec3::Z),
        (Vec3::Z, Vec3::Y),
        (-Vec3::Z, Vec3::X),
    ];
    let (mut pos, mut nrm, mut uv, mut tan, mut idx) = (vec![], vec![], vec![], vec![], vec![]);
    for (f, (n, t)) in faces.into_iter().enumerate() {
        let b = n.cross(t);
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            pos.extend((0.5 * (n + x * t + y * b)).to_array());
            nrm.extend(n.to_array());
            uv.extend([(x + 1.0) / 2.0 + f as f32, (y + 1.0) / 2.0]);
            tan.extend(t.extend(1.0).to_array());
        }
        let o = 4 * f as u16;
        idx.extend([o, o + 1, o + 2, o, o + 2, o + 3]);
    }
    let pos = d.floats(&pos, "VEC3", 3);
    let nrm = d.floats(&nrm, "VEC3", 3);
    let uv = d.floats(&uv, "VEC2", 2);
    let tan = d.floats(&tan, "VEC4", 4);
    let idx = d.indices(&idx);
    let quad = d.floats(
        &[
            -0.5, -0.5, 0.8, 0.5, -0.5, 0.8, 0.5, 0.5, 0.8, -0.5, 0.5, 0.8,
        ],
        "VEC3",
        3,
    );
    let col = d.floats(
        &[[1., 1., 1., 0.], [1.; 4], [1.; 4], [1., 1., 1., 0.]].concat(),
        "VEC4",
        4,
    );
    let quad_idx = d.indices(&[0, 1, 2, 0, 2, 3]);
    json!([
        {"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv, "TANGENT": tan},
         "indices": idx, "material": 0},
        {"attributes": {"POSITION": quad, "COLOR_0": col}, "indices": quad_idx, "material": 1}
    ])
}

/// A document placing the box mesh ([`box_mesh`]) by `locals` (TRS node properties) under
/// a rotated, translated parent: with `share`, every node references the one mesh;
/// otherwise each has its own copy of it (the same primitives), so it is flattened.
pub(super) fn placed_boxes(locals: &[Value], share: bool) -> (Value, Vec<u8>) {
    let mut d = Doc::default();
    let prims = box_mesh(&mut d);
    let children: Vec<usize> = (1..=locals.len()).collect();
    let mut nodes = vec![boxes_parent(&children)];
    for (i, local) in locals.iter().enumerate() {
        let mut n = local.clone();
        n["mesh"] = json!(if share { 0 } else { i });
        nodes.push(n);
    }
    let copies = if share { 1 } else { locals.len() };
    boxes_doc(
        d,
        json!(nodes),
        json!(vec![json!({"name": "box", "primitives": prims}); copies]),
    )
}

/// The parent node of the placed boxes, rotated, translated and scaled.
pub(super) fn boxes_parent(children: &[usize]) -> Value {
    json!({"name": "parent", "translation": [0.5, 1, -2],
        "rotation": [0.2, 0.3, 0.1, 0.927], "scale": [1, 1.5, 1], "children": children})
}

/// The document of the box tests: scene 0 is node 0, the given nodes and meshes, the
/// box's materials and normal texture, and `d`'s buffer.
pub(super) fn boxes_doc(d: Doc, nodes: Value, meshes: Value) -> (Value, Vec<u8>) {
    let doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [
            {"name": "painted", "normalTexture": {"index": 0, "scale": 0.8}},
            {"name": "fence", "alphaMode": "MASK", "doubleSided": true}
        ],
        "images": [{"uri": png_uri([200, 100, 230])}],
        "textures": [{"source": 0}],
        "buffers": [{"byteLength": d.bin.len()}],
        "bufferViews": d.views,
        "accessors": d.accessors
    });
    (doc, d.bin)
}

/// Placements with rotations, non-uniform and negative (mirroring) scales.
pub(super) fn box_placements() -> Vec<Value> {
    vec![
        json!({}),
        json!({"translation": [2.5, 0, 0], "rotation": [0, 0.6, 0, 0.8]}),
        json!({"translation": [-2.5, 0.5, 0], "scale": [1, 2, 0.5]}),
        json!({"translation": [0, 2.5, 0.5], "scale": [-1, 1, 1],
               "rotation": [0.28, 0, 0.96, 0]}),
        json!({"translation": [0, -2.5, 0], "scale": [1.5, -0.7, -1.2],
               "rotation": [0.5, 0.5, 0.5, 0.5]}),
        json!({"matrix": [0.8, 0.3, 0, 0, -0.3, 1.2, 0.2, 0, 0.1, 0, -0.9, 0, 1, 1, 2, 1]}),
    ]
}

/// Casts `n` random rays at both scenes and checks that they agree: the same hit or miss
/// (but for a few rays grazing an edge), with the same parameter, point, normals, uv,
/// colour and material up to float rounding, and the same shadow-ray answer. Returns the
/// number of hits.
pub(super) fn assert_same_hits(a: &Scene, b: &Scene, n: usize) -> usize {
    use crate::geometry::Ray;
    let mut rng = crate::sampling::Pcg32::new(5, 3);
    let mut v = |s: f32| {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 * s - Vec3::splat(s)
    };
    let (mut hits, mut mismatches) = (0, 0);
    for k in 0..n {
        let origin = v(9.0);
        let target = v(3.5) + Vec3::new(0.5, 1.0, -2.0);
        let mut ray = Ray::new(origin, (target - origin).normalize());
        if k % 3 == 0 {
            ray.t_max = (target - origin).length();
        }
        match (a.intersect(&ray), b.intersect(&ray)) {
            (None, None) => {}
            (Some(x), Some(y)) => {
                hits += 1;
                let close = |p: Vec3, q: Vec3, tol: f32| (p - q).length() <= tol;
                assert!(
                    (x.t - y.t).abs() <= 1e-4 * x.t.max(1.0),
                    "ray {k}: {x:?} {y:?}"
                );
                assert!(close(x.p, y.p, 1e-4), "ray {k}: {x:?} {y:?}");
                assert!(close(x.ng, y.ng, 1e-4), "ray {k}: {x:?} {y:?}");
                assert!(close(x.ns, y.ns, 1e-3), "ray {k}: {x:?} {y:?}");
                let [u, w] = [0, 1].map(|s| (x.attributes.uv[s] - y.attributes.uv[s]).length());
                assert!(u < 1e-4 && w < 1e-4, "ray {k}: {x:?} {y:?}");
                assert!((x.attributes.color - y.attributes.color).length() < 1e-4);
                assert_eq!(
                    a.materials[x.material as usize].name,
                    b.materials[y.material as usize].name
                );
                assert_eq!(
                    a.objects[x.object as usize], b.objects[y.object as usize],
                    "ray {k}"
                );
            }
            _ => mismatches += 1,
        }
        if a.occluded(&ray) != b.occluded(&ray) {
            mismatches += 1;
        }
    }
    assert!(mismatches <= n / 500, "{mismatches} mismatches in {n} rays");
    hits
}

/// The error loading `doc` (with buffer `bin`) gives, checked to name the file and to
/// come within a second.
pub(super) fn error(doc: Value, bin: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = write_embedded(dir.path(), doc, bin);
    let start = Instant::now();
    let err = Scene::load(&path).expect_err("should fail").to_string();
    assert!(
        start.elapsed() < Duration::from_secs(1),
        "{err}: {:?}",
        start.elapsed()
    );
    assert!(err.contains("scene.gltf"), "no file name in: {err}");
    err
}

/// The test scene with `value` at the JSON pointer `pointer` (its parent must exist).
pub(super) fn with(pointer: &str, value: Value) -> (Value, Vec<u8>) {
    let (mut doc, bin) = test_doc();
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let parent = doc
        .pointer_mut(parent)
        .unwrap_or_else(|| panic!("{pointer}"));
    match key.parse::<usize>() {
        Ok(i) if parent.is_array() => parent[i] = value,
        _ => parent[key] = value,
    }
    (doc, bin)
}

/// Each `(pointer, value, words)`: the test scene with that value fails naming `words`.
pub(super) fn rejects(cases: &[(&str, Value, &[&str])]) {
    for (pointer, value, words) in cases {
        let (doc, bin) = with(pointer, value.clone());
        let err = error(doc, &bin);
        for w in *words {
            assert!(err.contains(w), "{pointer} = {value}: {w:?} not in: {err}");
        }
    }
}

/// A chain of `depth` nodes, each listing the next twice, above a node placing mesh
/// `mesh`: 2^depth placements of it.
pub(super) fn doubling_dag(doc: &mut Value, depth: usize, mesh: usize) {
    let base = doc["nodes"].as_array().unwrap().len();
    let nodes = doc["nodes"].as_array_mut().unwrap();
    for i in 0..depth {
        nodes.push(json!({"name": format!("d{i}"), "children": [base + i + 1, base + i + 1]}));
    }
    nodes.push(json!({"name": "leaf", "mesh": mesh}));
    doc["scenes"][0]["nodes"] = json!([base]);
}
