//! Scenes from untrusted sources: the files a scene names stay inside its folder unless
//! reading outside is allowed, special files are never opened for reading, and counts and
//! sizes read from a file are checked against the bytes that back them before anything is
//! reserved. Each hostile file is tiny and built here, in a fresh folder; each must fail
//! within a second with an error naming the scene file, the element and what is wrong.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use streaks_image::input::png_header;
use streaks_render::scene::{LoadOptions, Scene, SceneError};

/// One triangle's positions, as little-endian floats.
fn triangle() -> Vec<u8> {
    [0.0f32, 0.0, -1.0, 1.0, 0.0, -1.0, 0.0, 1.0, -1.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// The triangle in base64, as a data URI.
fn data_uri() -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::encode(triangle())
    )
}

/// A scene with one triangle and a camera whose buffer 0 is `uri` of `length` bytes.
fn doc(uri: &str, length: u64) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, -1], "max": [1, 1, -1]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"uri": uri, "byteLength": length}],
    })
}

/// Writes `doc` as `scene.gltf` in `dir`.
fn write(dir: &Path, doc: &Value) -> PathBuf {
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(doc).unwrap()).unwrap();
    path
}

/// A fresh folder holding `scene/` (where scenes go) and, beside it, `secret.bin` (the
/// triangle) and `secret.mtl`, outside the scene's folder.
fn folders() -> (tempfile::TempDir, PathBuf) {
    let root = tempfile::tempdir().unwrap();
    let scene = root.path().join("scene");
    std::fs::create_dir(&scene).unwrap();
    std::fs::write(root.path().join("secret.bin"), triangle()).unwrap();
    std::fs::write(root.path().join("secret.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    (root, scene)
}

/// Loads `path` with `options`, which must fail within a second; returns the error.
fn refused(path: &Path, options: &LoadOptions) -> SceneError {
    refused_within(path, options, Duration::from_secs(1))
}

/// Loads `path` with `options`, which must fail within `limit`; returns the error.
fn refused_within(path: &Path, options: &LoadOptions, limit: Duration) -> SceneError {
    let start = Instant::now();
    let result = Scene::load_with(path, options);
    let elapsed = start.elapsed();
    assert!(elapsed < limit, "{}: took {elapsed:?}", path.display());
    match result {
        Ok(_) => panic!("{}: loaded", path.display()),
        Err(e) => e,
    }
}

fn allow() -> LoadOptions {
    LoadOptions {
        allow_outside: true,
        ..LoadOptions::default()
    }
}

/// Asserts that `err` (with its causes, as the command prints them) names every one of
/// `parts`.
fn names(err: &SceneError, parts: &[&str]) {
    let mut text = err.to_string();
    let mut cause = std::error::Error::source(err);
    while let Some(c) = cause {
        text = format!("{text}: {c}");
        cause = c.source();
    }
    for p in parts {
        assert!(text.contains(p), "{p:?} not in: {text}");
    }
}

fn mkfifo(path: &Path) {
    let made = std::process::Command::new("mkfifo").arg(path).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
}

#[test]
fn uris_outside_the_folder_are_refused_unless_allowed() {
    let (root, dir) = folders();
    std::fs::create_dir(dir.join("sub")).unwrap();
    let secret = root.path().join("secret.bin");
    let cases = [
        ("../secret.bin".to_string(), "leaves the folder"),
        ("sub/../../secret.bin".to_string(), "leaves the folder"),
        ("..%2Fsecret.bin".to_string(), "leaves the folder"),
        (secret.display().to_string(), "absolute path"),
        (format!("file://{}", secret.display()), "file: URI"),
    ];
    for (uri, why) in &cases {
        let path = write(&dir, &doc(uri, 36));
        let err = refused(&path, &LoadOptions::default());
        assert!(matches!(err, SceneError::OutsideFolder { .. }), "{err}");
        names(&err, &["scene.gltf", "buffer 0", why]);
        // Allowed explicitly, each is read.
        let scene = Scene::load_with(&path, &allow()).unwrap_or_else(|e| panic!("{uri}: {e}"));
        assert_eq!(scene.mesh.triangles.len(), 1);
    }
    // Inside the folder, `..` that stays inside is fine.
    std::fs::write(dir.join("tri.bin"), triangle()).unwrap();
    Scene::load(&write(&dir, &doc("sub/../tri.bin", 36))).unwrap();
    // Other schemes are refused even when reading outside is allowed.
    let path = write(&dir, &doc("https://example.com/tri.bin", 36));
    names(&refused(&path, &allow()), &["buffer 0", "scheme \"https\""]);
}

#[test]
fn a_symbolic_link_out_of_the_folder_is_refused_unless_allowed() {
    let (root, dir) = folders();
    std::os::unix::fs::symlink(root.path().join("secret.bin"), dir.join("link.bin")).unwrap();
    let path = write(&dir, &doc("link.bin", 36));
    let err = refused(&path, &LoadOptions::default());
    names(
        &err,
        &["scene.gltf", "buffer 0", "link.bin", "symbolic link"],
    );
    Scene::load_with(&path, &allow()).unwrap();
    // A link inside the folder is fine.
    std::fs::write(dir.join("tri.bin"), triangle()).unwrap();
    std::os::unix::fs::symlink("tri.bin", dir.join("inside.bin")).unwrap();
    Scene::load(&write(&dir, &doc("inside.bin", 36))).unwrap();
}

#[test]
fn special_files_are_refused_even_when_reading_outside_is_allowed() {
    let (_root, dir) = folders();
    mkfifo(&dir.join("pipe.bin"));
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.bin")).unwrap();
    std::fs::create_dir(dir.join("folder.bin")).unwrap();
    for (uri, what) in [
        ("pipe.bin", "FIFO"),
        ("zero.bin", "character device"),
        ("/dev/zero", "character device"),
        ("folder.bin", "folder"),
    ] {
        let path = write(&dir, &doc(uri, 36));
        let err = refused(&path, &allow());
        names(
            &err,
            &["scene.gltf", "buffer 0", uri, what, "not a regular file"],
        );
        if uri != "/dev/zero" {
            names(&refused(&path, &LoadOptions::default()), &[what]);
        }
    }
    // The scene file itself.
    let fifo = dir.join("pipe.gltf");
    mkfifo(&fifo);
    names(&refused(&fifo, &allow()), &["pipe.gltf", "FIFO"]);
}

#[test]
fn obj_material_libraries_and_maps_stay_inside_the_folder() {
    let (root, dir) = folders();
    let obj = |mtllib: &str| {
        let path = dir.join("scene.obj");
        std::fs::write(
            &path,
            format!("mtllib {mtllib}\nv 0 0 -1\nv 1 0 -1\nv 0 1 -1\nusemtl m\nf 1 2 3\n"),
        )
        .unwrap();
        path
    };
    let path = obj("../secret.mtl");
    names(
        &refused(&path, &LoadOptions::default()),
        &["scene.obj", "mtllib", "../secret.mtl", "leaves the folder"],
    );
    let scene = Scene::load_with(&path, &allow()).unwrap();
    assert_eq!(scene.materials[0].name, "m");
    // /dev/zero as the material library: refused as absolute, and as a device when allowed
    // or reached through a link.
    let path = obj("/dev/zero");
    names(
        &refused(&path, &LoadOptions::default()),
        &["mtllib", "absolute path"],
    );
    names(&refused(&path, &allow()), &["mtllib", "character device"]);
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.mtl")).unwrap();
    names(
        &refused(&obj("zero.mtl"), &allow()),
        &["mtllib", "zero.mtl", "character device"],
    );
    // A texture map that leaves the folder.
    std::fs::write(root.path().join("secret.png"), b"not read").unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl m\nKd 1 1 1\nmap_Kd ../secret.png\n",
    )
    .unwrap();
    names(
        &refused(&obj("m.mtl"), &LoadOptions::default()),
        &[
            "scene.obj",
            "material \"m\", map_Kd",
            "../secret.png",
            "leaves the folder",
        ],
    );
    // A missing library is still only a warning.
    let scene = Scene::load(&obj("missing.mtl")).unwrap();
    assert!(
        scene.warnings.iter().any(|w| w.contains("missing.mtl")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn a_buffer_claiming_more_than_its_file_holds_is_refused_before_reading() {
    let (_root, dir) = folders();
    std::fs::write(dir.join("tri.bin"), triangle()).unwrap();
    for (uri, length) in [
        ("tri.bin".to_string(), 4u64 << 30),
        ("tri.bin".to_string(), 1 << 40),
        (data_uri(), 4 << 30),
    ] {
        let err = refused(&write(&dir, &doc(&uri, length)), &LoadOptions::default());
        names(&err, &["scene.gltf", "buffer 0"]);
    }
}

/// Adds accessor 1 (to the triangle's NORMAL) to `d`.
fn with_normal_accessor(mut d: Value, accessor: Value) -> Value {
    d["accessors"].as_array_mut().unwrap().push(accessor);
    d["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(1);
    d
}

#[test]
fn sparse_and_viewless_accessors_claiming_huge_counts_are_refused() {
    let (_root, dir) = folders();
    let uri = data_uri();
    let sparse = |count: u64, sparse_count: u64| {
        json!({"componentType": 5126, "count": count, "type": "VEC3",
               "sparse": {"count": sparse_count,
                          "indices": {"bufferView": 0, "componentType": 5125},
                          "values": {"bufferView": 0}}})
    };
    for (accessor, why) in [
        // A million zeros (12 MB) backed by nothing.
        (sparse(1_000_000, 1), "no bufferView"),
        // 2^31 of them (24 GiB of floats): refused by the scene's budget of vertex data
        // before the accessor is even read.
        (sparse(1 << 31, 1), "16 times the"),
        // 2^30 substitutions from a 36-byte view.
        (sparse(3, 1 << 30), "sparse count"),
        (sparse(1 << 31, 1 << 30), "16 times the"),
    ] {
        let d = with_normal_accessor(doc(&uri, 36), accessor);
        let err = refused(&write(&dir, &d), &LoadOptions::default());
        names(&err, &["scene.gltf", "NORMAL (accessor 1)", why]);
    }
}

#[test]
fn compressed_views_claiming_huge_decoded_sizes_are_refused() {
    let (_root, dir) = folders();
    // A meshopt view of 2^30 16-byte vertices from 36 compressed bytes.
    let mut d = doc(&data_uri(), 36);
    d["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
    d["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    let meshopt = |count: u64, compressed: u64, mode: &str| {
        json!({"buffer": 0, "byteLength": count * 16, "byteStride": 16,
               "extensions": {"EXT_meshopt_compression": {
                   "buffer": 0, "byteLength": compressed, "byteStride": 16,
                   "count": count, "mode": mode}}})
    };
    d["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(meshopt(1 << 30, 36, "ATTRIBUTES"));
    let err = refused(&write(&dir, &d), &LoadOptions::default());
    names(&err, &["scene.gltf", "bufferView 1", "compressed bytes"]);
    // Within what the bytes could hold, but over the scene's budget of decoded bytes.
    let small = LoadOptions {
        max_decoded_bytes: 1024,
        ..LoadOptions::default()
    };
    d["bufferViews"][1] = meshopt(2048, 36, "ATTRIBUTES");
    let err = refused(&write(&dir, &d), &small);
    names(&err, &["bufferView 1", "limit of 1024"]);
    // byteLength disagreeing with count * byteStride.
    d["bufferViews"][1]["byteLength"] = json!(16);
    names(
        &refused(&write(&dir, &d), &small),
        &["bufferView 1", "byteLength is 16"],
    );
}

/// An unsigned LEB128 varint, as Draco writes counts.
fn varint(mut v: u64) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let byte = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            out.push(byte);
            return out;
        }
        out.push(byte | 0x80);
    }
}

#[test]
fn a_draco_stream_claiming_huge_counts_is_refused() {
    let (_root, dir) = folders();
    for (faces, points) in [(400_000_000u64, 3u64), (1, 1 << 40), (1 << 40, 1 << 40)] {
        // Draco 2.2, a triangular mesh, sequential connectivity, no flags; then the counts
        // and raw (uncompressed) connectivity, and nothing else.
        let mut stream = b"DRACO\x02\x02\x01\x00\x00\x00".to_vec();
        stream.extend(varint(faces));
        stream.extend(varint(points));
        stream.push(1);
        stream.extend([0u8; 16]);
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::encode(&stream)
        );
        let d = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_draco_mesh_compression"],
            "extensionsRequired": ["KHR_draco_mesh_compression"],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                "extensions": {"KHR_draco_mesh_compression": {
                    "bufferView": 0, "attributes": {"POSITION": 0}}}}]}],
            "accessors": [
                {"componentType": 5126, "count": points, "type": "VEC3"},
                {"componentType": 5125, "count": faces * 3, "type": "SCALAR"}
            ],
            "bufferViews": [{"buffer": 0, "byteLength": stream.len()}],
            "buffers": [{"uri": uri, "byteLength": stream.len()}],
        });
        let err = refused(&write(&dir, &d), &LoadOptions::default());
        names(&err, &["scene.gltf", "KHR_draco_mesh_compression"]);
    }
}

#[test]
fn images_claiming_huge_sizes_are_refused_from_their_header() {
    let (_root, dir) = folders();
    std::fs::write(dir.join("tri.bin"), triangle()).unwrap();
    std::fs::write(dir.join("big.png"), png_header(100_000, 100_000, 8)).unwrap();
    let mut d = doc("tri.bin", 36);
    d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    d["textures"] = json!([{"source": 0}]);
    d["images"] = json!([{"uri": "big.png"}]);
    d["meshes"][0]["primitives"][0]["material"] = json!(0);
    let err = refused(&write(&dir, &d), &LoadOptions::default());
    names(&err, &["scene.gltf", "image 0", "big.png", "100000x100000"]);
    // The same image embedded as a data URI.
    d["images"][0]["uri"] = json!(format!(
        "data:image/png;base64,{}",
        base64::encode(png_header(100_000, 100_000, 8))
    ));
    names(
        &refused(&write(&dir, &d), &LoadOptions::default()),
        &["image 0", "100000x100000"],
    );
    // And as an OBJ's map_Kd.
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 1 1\nmap_Kd big.png\n").unwrap();
    let obj = dir.join("scene.obj");
    std::fs::write(
        &obj,
        "mtllib m.mtl\nv 0 0 -1\nv 1 0 -1\nv 0 1 -1\nusemtl m\nf 1 2 3\n",
    )
    .unwrap();
    names(
        &refused(&obj, &LoadOptions::default()),
        &["scene.obj", "map_Kd", "big.png", "100000x100000"],
    );
}

#[test]
fn an_accessor_read_by_very_many_primitives_is_refused_before_memory_runs_out() {
    let (_root, dir) = folders();
    // 50,000 vertices (600 kB) read by 400 primitives: 240 MB of positions alone.
    let vertices = 50_000usize;
    let bin: Vec<u8> = (0..vertices * 3)
        .flat_map(|i| ((i % 7) as f32).to_le_bytes())
        .collect();
    std::fs::write(dir.join("big.bin"), &bin).unwrap();
    let mut d = doc("big.bin", bin.len() as u64);
    d["bufferViews"][0]["byteLength"] = json!(bin.len());
    d["accessors"][0] = json!({"bufferView": 0, "componentType": 5126, "count": vertices,
        "type": "VEC3", "min": [0, 0, 0], "max": [6, 6, 6]});
    d["meshes"][0]["primitives"] = json!(vec![json!({"attributes": {"POSITION": 0}}); 400]);
    // The loader reads primitives until the vertex budget runs out, which takes longer than
    // the refusals above; the bound leaves room for a busy machine and still catches the
    // unbounded read, which took minutes.
    let err = refused_within(
        &write(&dir, &d),
        &LoadOptions::default(),
        Duration::from_secs(10),
    );
    names(&err, &["scene.gltf", "POSITION (accessor 0)", "16 times"]);
    // One primitive reads it fine.
    d["meshes"][0]["primitives"] = json!([{"attributes": {"POSITION": 0}}]);
    Scene::load(&write(&dir, &d)).unwrap();
}
