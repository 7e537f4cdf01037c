//! The seed corpus: small real inputs (the repository's smallest scenes and a generated
//! dataset) and crafted ones that reach the readers' less common paths (a GLB with an
//! embedded image, `data:` URIs, sparse accessors, lights, OBJ polygons and MTL textures,
//! 16-bit and grey PNGs). `streaks-fuzz --write-seeds` writes them into `corpus/`.

use crate::files::{self, Part};
use crate::targets;
use glam::{Affine3A, Vec3};
use serde_json::{json, Value};
use std::io;
use std::path::Path;
use std::process::Command;
use streaks_dataset::files::{DATASET_JSON, MANIFEST, RIG};

/// A small PNG of `img`.
fn png<P, C>(img: &image::ImageBuffer<P, C>) -> Vec<u8>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    streaks_image::png::png_bytes(img).expect("cannot encode a seed PNG")
}

/// A 2 x 2 RGBA PNG.
fn texture() -> Vec<u8> {
    png(&image::RgbaImage::from_raw(
        2,
        2,
        vec![
            200, 30, 30, 255, 30, 200, 30, 128, 30, 30, 200, 255, 250, 250, 250, 0,
        ],
    )
    .expect("2 x 2 texels"))
}

/// The geometry of the crafted glTF scenes: a quad (two indexed triangles) with normals and
/// uvs, as one buffer, and its accessors and buffer views.
fn quad() -> (Vec<u8>, Value, Value) {
    let positions: [f32; 12] = [0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
    let normals: [f32; 12] = [0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.];
    let uvs: [f32; 8] = [0., 0., 1., 0., 1., 1., 0., 1.];
    let mut bytes: Vec<u8> = positions
        .iter()
        .chain(&normals)
        .chain(&uvs)
        .flat_map(|f| f.to_le_bytes())
        .collect();
    bytes.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    // Sparse substitution: vertex 2's uv becomes (0.5, 0.5).
    bytes.extend(2u16.to_le_bytes());
    bytes.extend([0.5f32, 0.5].iter().flat_map(|f| f.to_le_bytes()));
    let accessors = json!([
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2",
         "sparse": {"count": 1,
                    "indices": {"bufferView": 4, "componentType": 5123},
                    "values": {"bufferView": 5}}},
        {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
    ]);
    let views = json!([
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
        {"buffer": 0, "byteOffset": 96, "byteLength": 32},
        {"buffer": 0, "byteOffset": 128, "byteLength": 12},
        {"buffer": 0, "byteOffset": 140, "byteLength": 2},
        {"buffer": 0, "byteOffset": 142, "byteLength": 8}
    ]);
    (bytes, accessors, views)
}

/// A crafted glTF document around [`quad`]: a node hierarchy with a camera, a point and a
/// spot light, an emissive and a textured material; `buffer` is the buffer's JSON, `image`
/// the image's.
fn document(buffer: Value, image: Value, accessors: Value, views: Value) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength",
                           "KHR_texture_transform"],
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"name": "street", "children": [1, 2], "translation": [0.0, 0.0, -3.0]},
            {"name": "road", "mesh": 0, "rotation": [0.0, 0.0, 0.0, 1.0]},
            {"name": "lamp", "mesh": 1, "scale": [0.2, 0.2, 0.2], "translation": [0.0, 2.0, 0.0],
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "camera", "camera": 0, "translation": [0.5, 0.5, 2.0],
             "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.5}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.9, 0.8], "intensity": 5.0, "range": 10.0},
            {"type": "spot", "intensity": 20.0,
             "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}
        ]}},
        "meshes": [
            {"name": "road", "primitives": [{
                "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                "indices": 3, "material": 0}]},
            {"name": "lamp", "primitives": [{
                "attributes": {"POSITION": 0}, "indices": 3, "material": 1}]}
        ],
        "materials": [
            {"name": "asphalt",
             "pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
                 "extensions": {"KHR_texture_transform": {"scale": [2.0, 2.0]}}},
                 "roughnessFactor": 0.3},
             "doubleSided": true},
            {"name": "bulb", "emissiveFactor": [1.0, 0.8, 0.5],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 10.0}}}
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 33648, "wrapT": 10497}],
        "images": [image],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [buffer]
    })
}

/// A GLB: `json` (padded with spaces) and `bin` (padded with zeros) chunks.
pub fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (json_len, bin_len) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + json_len + 8 + bin_len;
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json_len as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.resize(20 + json_len, b' ');
    out.extend((bin_len as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out.resize(total, 0);
    out
}

/// Writes `data` as `dir/target/name`.
fn put(dir: &Path, target: &str, name: &str, data: &[u8]) -> io::Result<()> {
    let folder = dir.join(target);
    std::fs::create_dir_all(&folder)?;
    std::fs::write(folder.join(name), data)
}

/// A multi-file input of `main` and the named files.
fn bundle(main: &[u8], others: &[(&str, &[u8])]) -> Vec<u8> {
    let mut parts = vec![Part {
        name: None,
        bytes: main.to_vec(),
    }];
    parts.extend(others.iter().map(|(name, bytes)| Part {
        name: Some((*name).to_owned()),
        bytes: bytes.to_vec(),
    }));
    files::join(&parts)
}

/// Writes the seed corpus into `corpus` (`corpus/<target>/<name>`), reading the real scenes
/// from `repo` (the repository's root). The dataset seed is generated with the `streaks`
/// binary ([`targets::streaks_binary`]) and skipped, with a message, without it.
pub fn write_seeds(repo: &Path, corpus: &Path) -> io::Result<()> {
    use base64::encode;
    let (bin, accessors, views) = quad();
    let tex = texture();

    // glTF: everything in data: URIs; the same with scene.bin and texture.png beside it.
    let data_uri = document(
        json!({"byteLength": bin.len(),
               "uri": format!("data:application/octet-stream;base64,{}", encode(&bin))}),
        json!({"uri": format!("data:image/png;base64,{}", encode(&tex))}),
        accessors.clone(),
        views.clone(),
    );
    put(
        corpus,
        "gltf",
        "crafted-data-uris",
        serde_json::to_string_pretty(&data_uri)?.as_bytes(),
    )?;
    let external = document(
        json!({"byteLength": bin.len(), "uri": "scene.bin"}),
        json!({"uri": "texture.png"}),
        accessors.clone(),
        views.clone(),
    );
    put(
        corpus,
        "gltf",
        "crafted-external-files",
        &bundle(
            serde_json::to_string_pretty(&external)?.as_bytes(),
            &[("scene.bin", &bin), ("texture.png", &tex)],
        ),
    )?;
    for name in ["paper_fig6", "paper_fig2_ward"] {
        let gltf = std::fs::read(repo.join(format!("scenes/{name}.gltf")))?;
        let bin = std::fs::read(repo.join(format!("scenes/{name}.bin")))?;
        let bin_name = format!("{name}.bin");
        put(
            corpus,
            "gltf",
            &format!("scene-{name}"),
            &bundle(&gltf, &[(&bin_name, &bin)]),
        )?;
    }

    // GLB: the buffer and the image in the BIN chunk.
    let mut glb_bin = bin.clone();
    while glb_bin.len() % 4 != 0 {
        glb_bin.push(0);
    }
    let image_offset = glb_bin.len();
    glb_bin.extend(&tex);
    let mut glb_views = views.clone();
    glb_views
        .as_array_mut()
        .expect("views")
        .push(json!({"buffer": 0, "byteOffset": image_offset, "byteLength": tex.len()}));
    let glb_doc = document(
        json!({"byteLength": glb_bin.len()}),
        json!({"bufferView": 6, "mimeType": "image/png"}),
        accessors,
        glb_views,
    );
    put(
        corpus,
        "glb",
        "crafted-embedded",
        &glb(serde_json::to_string(&glb_doc)?.as_bytes(), &glb_bin),
    )?;

    // OBJ: a quad, a triangle and a pentagon, negative indices, an MTL with a texture and an
    // emitter.
    let obj = "mtllib scene.mtl\n\
        o road\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
        usemtl asphalt\nf 1/1/1 2/2/1 3/3/1 4/4/1\n\
        o lamp\nv 0 0 2\nv 1 0 2\nv 0 1 2\nv 2 2 2\nv 1 3 2\n\
        usemtl bulb\nf -5 -4 -3\nf -5 -4 -2 -1 -3\n";
    let mtl = "newmtl asphalt\nKd 0.2 0.2 0.2\nKs 0.5 0.5 0.5\nNs 200\nmap_Kd texture.png\n\
        newmtl bulb\nKd 0 0 0\nKe 10 8 5\n";
    put(
        corpus,
        "obj",
        "crafted-textured",
        &bundle(
            obj.as_bytes(),
            &[("scene.mtl", mtl.as_bytes()), ("texture.png", &tex)],
        ),
    )?;
    put(
        corpus,
        "obj",
        "crafted-no-mtl",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )?;

    // PNG: the colour types and depths a texture may have.
    put(corpus, "png", "rgba8", &tex)?;
    put(
        corpus,
        "png",
        "rgb8",
        &png(&image::RgbImage::from_fn(3, 2, |x, y| {
            image::Rgb([x as u8 * 80, y as u8 * 120, 7])
        })),
    )?;
    put(
        corpus,
        "png",
        "gray8",
        &png(&image::GrayImage::from_fn(4, 1, |x, _| {
            image::Luma([x as u8 * 60])
        })),
    )?;
    put(
        corpus,
        "png",
        "gray-alpha8",
        &png(&image::GrayAlphaImage::from_fn(2, 2, |x, y| {
            image::LumaA([x as u8 * 200, y as u8 * 200])
        })),
    )?;
    put(
        corpus,
        "png",
        "gray16",
        &png(&image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(
            2,
            2,
            |x, y| image::Luma([(x * 30000 + y * 1000) as u16]),
        )),
    )?;
    put(
        corpus,
        "png",
        "rgb16",
        &png(&image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_fn(
            2,
            1,
            |x, _| image::Rgb([x as u16 * 60000, 100, 65535]),
        )),
    )?;

    // EXR and PFM, as the project writes them.
    let scratch = tempfile::tempdir()?;
    let rgb = streaks_image::RgbImage::from_planes(
        3,
        2,
        [
            &[0.0, 0.5, 1.0, 2.0, 100.0, -1.0],
            &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
            &[1.0; 6],
        ],
    );
    let exr_path = scratch.path().join("a.exr");
    streaks_image::exr::write_exr_rgb(&exr_path, &rgb).map_err(io::Error::other)?;
    put(corpus, "exr", "rgb-3x2", &std::fs::read(&exr_path)?)?;
    write_exr_seeds(scratch.path(), corpus)?;
    let gray =
        streaks_image::GrayImage::from_vec(3, 2, vec![0.0, 1.5, f32::INFINITY, 4.0, 5.0, 6.0])
            .map_err(io::Error::other)?;
    let pfm_path = scratch.path().join("a.pfm");
    streaks_image::pfm::write_pfm(&pfm_path, &gray).map_err(io::Error::other)?;
    put(corpus, "pfm", "gray-3x2", &std::fs::read(&pfm_path)?)?;
    let mut colour = b"PF\n2 1\n1.0\n".to_vec();
    colour.extend(
        [0.5f32, 1.0, 2.0, 3.0, 4.0, 5.0]
            .iter()
            .flat_map(|f| f.to_be_bytes()),
    );
    put(corpus, "pfm", "colour-big-endian", &colour)?;

    // The rig file and calib.txt of a rig looking down the street.
    let intrinsics =
        streaks_stereo::rig::Intrinsics::new(64, 48, 50.0).map_err(io::Error::other)?;
    let pose = Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0));
    let rig = streaks_stereo::rig::Rig::new(intrinsics, 0.065, pose).map_err(io::Error::other)?;
    let rig_file = streaks_stereo::rigfile::RigFile::new(&rig, Vec::new());
    let rig_path = scratch.path().join(RIG);
    rig_file.save(&rig_path).map_err(io::Error::other)?;
    put(corpus, "rig", "rig", &std::fs::read(&rig_path)?)?;
    let calib = streaks_stereo::calib::MiddleburyCalib::of_rig(&rig, Some((1.0, 20.0)));
    put(corpus, "calib", "calib", calib.to_text().as_bytes())?;

    // The generator config: the documented default and a short one.
    put(
        corpus,
        "config",
        "default",
        streaks_scenes::procedural::DEFAULT_CONFIG_TOML.as_bytes(),
    )?;
    put(
        corpus,
        "config",
        "short",
        b"[dataset]\npairs_per_street = 2\n\n[rig]\nheight = [1.2, 1.6]\n",
    )?;

    // A dataset of one tiny sample, generated and indexed by the binary.
    match targets::streaks_binary() {
        Ok(binary) => {
            let dir = scratch.path().join("ds");
            let status = Command::new(binary)
                .args(["dataset", "generate", "--count", "1", "--width", "16"])
                .args(["--height", "8", "--spp", "1", "-o"])
                .arg(&dir)
                .status()?;
            if !status.success() {
                return Err(io::Error::other(format!(
                    "streaks dataset generate failed: {status}"
                )));
            }
            // The sample's scene (its textures are most of the bytes) is left out: the index
            // then reports the sample as corrupt, the rest is read as usual.
            let parts: Vec<Part> = files::split(&files::pack(&dir, DATASET_JSON)?)
                .into_iter()
                .filter(|p| !p.name.as_deref().is_some_and(|n| n.contains("/scene")))
                .collect();
            put(corpus, "dataset", "one-sample", &files::join(&parts))?;
            // The same with the scene left out of the manifest too: verifying it succeeds,
            // so mutations reach the comparison of every file with its hash.
            let mut verified = parts.clone();
            for part in &mut verified {
                if part.name.as_deref() == Some(MANIFEST) {
                    part.bytes = without_scene(&part.bytes)?;
                }
            }
            put(
                corpus,
                "dataset",
                "one-sample-verified",
                &files::join(&verified),
            )?;
            // Without a manifest: the first index writes it.
            let unindexed: Vec<Part> = parts
                .iter()
                .filter(|p| p.name.as_deref() != Some(MANIFEST))
                .cloned()
                .collect();
            put(
                corpus,
                "dataset",
                "one-sample-no-manifest",
                &files::join(&unindexed),
            )?;
            let info = parts[0].bytes.clone();
            put(corpus, "dataset", "dataset-json-only", &info)?;
        }
        Err(e) => eprintln!("no dataset seed: {e}"),
    }
    Ok(())
}

/// `manifest.jsonl` without the entries of the samples' scene files.
fn without_scene(manifest: &[u8]) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    for line in manifest.split(|&b| b == b'\n').filter(|l| !l.is_empty()) {
        let mut entry: serde_json::Value = serde_json::from_slice(line)?;
        if let Some(files) = entry.get_mut("files").and_then(|f| f.as_object_mut()) {
            files.retain(|name, _| !name.contains("/scene"));
        }
        serde_json::to_writer(&mut out, &entry)?;
        out.push(b'\n');
    }
    Ok(out)
}

/// EXRs of every compression the `exr` crate writes, in scan lines and in tiles, with half,
/// float and integer samples.
fn write_exr_seeds(scratch: &Path, corpus: &Path) -> io::Result<()> {
    use exr::prelude::*;
    let compressions = [
        ("uncompressed", Compression::Uncompressed),
        ("rle", Compression::RLE),
        ("zip1", Compression::ZIP1),
        ("zip16", Compression::ZIP16),
        ("piz", Compression::PIZ),
        ("pxr24", Compression::PXR24),
        ("b44", Compression::B44),
    ];
    for (name, compression) in compressions {
        for (blocks_name, blocks) in [
            ("lines", Blocks::ScanLines),
            ("tiles", Blocks::Tiles(Vec2(2, 2))),
        ] {
            let encoding = Encoding {
                compression,
                blocks,
                line_order: LineOrder::Increasing,
            };
            let layer = Layer::new(
                (5, 3),
                LayerAttributes::named("main"),
                encoding,
                SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                    (
                        f16::from_f32(x as f32 * 0.5),
                        y as f32 * 2.0,
                        (x + y) as u32,
                    )
                }),
            );
            let path = scratch.join("seed.exr");
            Image::from_layer(layer)
                .write()
                .to_file(&path)
                .map_err(io::Error::other)?;
            put(
                corpus,
                "exr",
                &format!("{name}-{blocks_name}"),
                &std::fs::read(&path)?,
            )?;
        }
    }
    Ok(())
}
