//! One function per reader: each takes the fuzzer's bytes, reads them as the project does
//! (through a file in a scratch folder where the reader takes a path) and returns what came
//! of it. A panic, an abort, a hang or an allocation bomb is a finding; an error is not.

use crate::files;
use std::cell::RefCell;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use streaks_dataset::files::{CALIB, DATASET_JSON, RIG};

/// What a target made of an input: `Ok`, or the reader's error message. The stable runner
/// keeps inputs whose message is of a new kind, a cheap stand-in for coverage.
pub type Outcome = Result<(), String>;

/// A fuzz target.
pub struct Target {
    /// Its name: the folder of its corpus, regressions and artifacts, and the cargo-fuzz
    /// target's name.
    pub name: &'static str,
    /// Reads one input.
    pub run: fn(&[u8]) -> Outcome,
    /// Whether inputs are several files ([`files`]) rather than one file's bytes.
    pub multi_file: bool,
    /// Tokens of the format that the mutator inserts.
    pub dictionary: &'static [&'static str],
}

/// Tokens of glTF JSON.
const GLTF_WORDS: &[&str] = &[
    "\"uri\": \"data:application/octet-stream;base64,\"",
    "\"uri\": \"scene.bin\"",
    "\"uri\": \"../scene.bin\"",
    "\"uri\": \"/dev/zero\"",
    "\"uri\": \"file:///etc/passwd\"",
    "\"uri\": \"%FF.bin\"",
    "\"byteStride\": 4",
    "\"byteOffset\": 4294967295",
    "\"count\": 4294967295",
    "\"sparse\": {\"count\": 1, \"indices\": {\"bufferView\": 0, \"componentType\": 5125}, \"values\": {\"bufferView\": 0}}",
    "\"children\": [0]",
    "\"children\": [0, 0]",
    "\"nodes\": [0, 0, 0]",
    "\"mesh\": 0",
    "\"camera\": 0",
    "\"scale\": [1e30, 1e30, 1e30]",
    "\"translation\": [NaN, 0, 0]",
    "\"matrix\": [0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,0]",
    "\"componentType\": 5126",
    "\"componentType\": 5121",
    "\"type\": \"VEC3\"",
    "\"type\": \"MAT4\"",
    "\"mode\": 0",
    "\"indices\": 0",
    "\"KHR_lights_punctual\"",
    "\"type\": \"spot\", \"spot\": {\"innerConeAngle\": 2, \"outerConeAngle\": 7}",
    "\"intensity\": -1",
    "\"emissiveFactor\": [1e39, 1, 1]",
    "\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 1e30}",
    "\"EXT_meshopt_compression\"",
    "\"KHR_draco_mesh_compression\"",
    "\"extensionsRequired\": [\"KHR_draco_mesh_compression\"]",
    "\"EXT_mesh_gpu_instancing\": {\"attributes\": {\"TRANSLATION\": 0}}",
    "\"KHR_texture_transform\": {\"scale\": [0, 0]}",
    "\"mimeType\": \"image/jpeg\"",
    "\"bufferView\": 0",
    "-1",
    "4294967296",
    "1e309",
];

/// Tokens of OBJ and MTL.
const OBJ_WORDS: &[&str] = &[
    "v 1e38 1e38 1e38\n",
    "v 0 0 0\n",
    "vt 0 0\n",
    "vn 0 0 1\n",
    "f 1 2 3\n",
    "f -1 -2 -3\n",
    "f 1/1/1 2/2/2 3/3/3\n",
    "f 4294967295 1 2\n",
    "f 1 2 3 4 5 6 7 8 9 10 11 12\n",
    "o x\n",
    "g x\n",
    "s 1\n",
    "mtllib scene.mtl\n",
    "mtllib ../scene.mtl\n",
    "mtllib /dev/zero\n",
    "usemtl m\n",
    "newmtl m\n",
    "Kd 1 1 1\n",
    "Ke 1e30 1 1\n",
    "Ns -1\n",
    "Ni 0\n",
    "d 0.5\n",
    "illum 2\n",
    "map_Kd texture.png\n",
    "map_Kd /dev/zero\n",
    "map_bump -bm 1e30 texture.png\n",
    "norm texture.png\n",
];

/// Tokens of PNG chunks.
const PNG_WORDS: &[&str] = &[
    "IHDR",
    "IDAT",
    "IEND",
    "PLTE",
    "tRNS",
    "gAMA",
    "sRGB",
    "iCCP",
    "acTL",
    "fcTL",
    "fdAT",
    "\u{7f}\u{7f}\u{7f}\u{7f}",
];

/// Tokens of EXR headers.
const EXR_WORDS: &[&str] = &[
    "channels\0chlist\0",
    "compression\0compression\0",
    "dataWindow\0box2i\0",
    "displayWindow\0box2i\0",
    "lineOrder\0lineOrder\0",
    "pixelAspectRatio\0float\0",
    "screenWindowCenter\0v2f\0",
    "screenWindowWidth\0float\0",
    "tiles\0tiledesc\0",
    "chunkCount\0int\0",
    "R\0",
    "G\0",
    "B\0",
    "A\0",
    "\u{7f}\u{7f}\u{7f}\u{7f}",
];

/// Tokens of PFM headers.
const PFM_WORDS: &[&str] = &[
    "PF\n",
    "Pf\n",
    "-1.0\n",
    "1.0\n",
    "0\n",
    "65536 65536\n",
    "nan\n",
];

/// Tokens of the rig file (JSON).
const RIG_WORDS: &[&str] = &[
    "\"width\": 4294967295",
    "\"height\": 0",
    "\"focal_px\": 1e39",
    "\"baseline\": -1",
    "\"principal_point\": [NaN, 0]",
    "\"world_from_rig\"",
    "\"lights\": []",
    "\"road_frame\": null",
    "1e308",
    "-0",
];

/// Tokens of the generator config (TOML).
const CONFIG_WORDS: &[&str] = &[
    "[dataset]\n",
    "[rig]\n",
    "pairs_per_street = 4294967295\n",
    "= [1e308, 1e308]\n",
    "= [0, 1e30]\n",
    "= [-1, 0]\n",
    "= nan\n",
    "= inf\n",
    "= 18446744073709551615\n",
    "= [5, 1]\n",
    "= 1.0\n",
];

/// Tokens of Middlebury's calib.txt.
const CALIB_WORDS: &[&str] = &[
    "cam0=[1e30 0 2; 0 1 2; 0 0 1]\n",
    "cam1=[NaN 0 2; 0 1 2; 0 0 1]\n",
    "doffs=0\n",
    "baseline=-1\n",
    "width=4294967296\n",
    "height=0\n",
    "ndisp=-1\n",
    "vmin=inf\n",
    "vmax=1e309\n",
    "dyavg=0\n",
    "dymax=0\n",
    "isint=0\n",
];

/// Tokens of dataset.json, meta.json and manifest.jsonl.
const DATASET_WORDS: &[&str] = &[
    "\"count\": 0",
    "\"count\": 18446744073709551615",
    "\"width\": 4294967295",
    "\"spp\": 0",
    "\"split\": \"../x\"",
    "\"sha256\": \"\"",
    "\"format\": \"streaks-dataset/1\"",
    "\n--8<-- samples/000000/meta.json\n",
    "\n--8<-- samples/.tmp-000000-1/x\n",
    "\n--8<-- samples/999999/meta.json\n",
    "\n--8<-- manifest.jsonl\n",
    "\n--8<-- splits/train.txt\n",
    "000000",
];

/// Every target, in the order `--all` runs them.
pub const TARGETS: &[Target] = &[
    Target {
        name: "gltf",
        run: gltf,
        multi_file: true,
        dictionary: GLTF_WORDS,
    },
    Target {
        name: "glb",
        run: glb,
        multi_file: true,
        dictionary: GLTF_WORDS,
    },
    Target {
        name: "obj",
        run: obj,
        multi_file: true,
        dictionary: OBJ_WORDS,
    },
    Target {
        name: "png",
        run: png,
        multi_file: false,
        dictionary: PNG_WORDS,
    },
    Target {
        name: "exr",
        run: exr,
        multi_file: false,
        dictionary: EXR_WORDS,
    },
    Target {
        name: "pfm",
        run: pfm,
        multi_file: false,
        dictionary: PFM_WORDS,
    },
    Target {
        name: "rig",
        run: rig,
        multi_file: false,
        dictionary: RIG_WORDS,
    },
    Target {
        name: "config",
        run: config,
        multi_file: false,
        dictionary: CONFIG_WORDS,
    },
    Target {
        name: "calib",
        run: calib,
        multi_file: false,
        dictionary: CALIB_WORDS,
    },
    Target {
        name: "dataset",
        run: dataset,
        multi_file: true,
        dictionary: DATASET_WORDS,
    },
];

/// The target called `name`.
pub fn find(name: &str) -> Option<&'static Target> {
    TARGETS.iter().find(|t| t.name == name)
}

thread_local! {
    /// This thread's scratch folder, made on first use in the system's temporary folder (the
    /// stable runner points `TMPDIR` at a folder it removes, since a child that ends with
    /// `exit` or an abort does not remove its own).
    static SCRATCH: RefCell<Option<tempfile::TempDir>> = const { RefCell::new(None) };
}

/// Runs `f` on an empty folder `in` inside this thread's scratch folder, holding `data`'s
/// files: those of a multi-file input ([`files`]), the main one named `main`, or else `data`
/// as the file `main`.
fn with_files<R>(data: &[u8], main: &str, multi_file: bool, f: impl FnOnce(&Path) -> R) -> R {
    let dir = SCRATCH.with(|s| {
        let mut s = s.borrow_mut();
        if s.is_none() {
            let made = tempfile::Builder::new()
                .prefix("streaks-fuzz-")
                .tempdir()
                .expect("cannot make a scratch folder for the fuzz inputs");
            *s = Some(made);
        }
        s.as_ref().map(|d| d.path().join("in")).unwrap_or_default()
    });
    // A previous input's files (or a process it started) must not leak into this one.
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("cannot make the scratch folder");
    if multi_file {
        files::write(data, &dir, main).expect("cannot write the input's files");
    } else {
        std::fs::write(dir.join(main), data).expect("cannot write the input");
    }
    f(&dir)
}

/// An error as an outcome.
fn message(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// A glTF 2.0 JSON file (`scene.gltf`) and the files it names, loaded as a scene.
pub fn gltf(data: &[u8]) -> Outcome {
    scene(data, "scene.gltf")
}

/// A binary glTF (`scene.glb`) and any files it names, loaded as a scene.
pub fn glb(data: &[u8]) -> Outcome {
    scene(data, "scene.glb")
}

/// An OBJ (`scene.obj`) with its MTL and textures, loaded as a scene.
pub fn obj(data: &[u8]) -> Outcome {
    scene(data, "scene.obj")
}

/// Loads the scene file `main` of a multi-file input.
fn scene(data: &[u8], main: &str) -> Outcome {
    with_files(data, main, true, |dir| {
        streaks_render::scene::Scene::load(&dir.join(main))
            .map(|_| ())
            .map_err(message)
    })
}

/// A PNG texture, decoded as the renderer decodes a glTF material's base colour texture: the
/// bytes are `texture.png` beside a one-triangle glTF ([`png_scene`]) that uses it.
pub fn png(data: &[u8]) -> Outcome {
    with_files(data, "texture.png", false, |dir| {
        std::fs::write(dir.join("scene.gltf"), png_scene("texture.png"))
            .expect("cannot write the scene");
        streaks_render::scene::Scene::load(&dir.join("scene.gltf"))
            .map(|_| ())
            .map_err(message)
    })
}

/// A one-triangle glTF (geometry in a `data:` URI) whose material's base colour is the image
/// at `uri`.
pub fn png_scene(uri: &str) -> String {
    let floats: [f32; 15] = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, // positions
        0.0, 0.0, 1.0, 0.0, 0.0, 1.0, // uvs
    ];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "TEXCOORD_0": 1},
            "material": 0
        }]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": uri}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24}
        ],
        "buffers": [{
            "byteLength": bytes.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64::encode(&bytes))
        }]
    })
    .to_string()
}

/// An OpenEXR image read as the project reads renders and references (`R`, `G`, `B`).
pub fn exr(data: &[u8]) -> Outcome {
    with_files(data, "image.exr", false, |dir| {
        streaks_image::exr::read_exr_rgb(&dir.join("image.exr"))
            .map(|_| ())
            .map_err(message)
    })
}

/// A PFM disparity or depth map.
pub fn pfm(data: &[u8]) -> Outcome {
    with_files(data, "image.pfm", false, |dir| {
        streaks_image::pfm::read_pfm(&dir.join("image.pfm"))
            .map(|_| ())
            .map_err(message)
    })
}

/// A stereo pair's rig file (`rig.json`), read and checked.
pub fn rig(data: &[u8]) -> Outcome {
    with_files(data, RIG, false, |dir| {
        let file = streaks_stereo::rigfile::RigFile::load(&dir.join(RIG)).map_err(message)?;
        file.rig().map(|_| ()).map_err(message)
    })
}

/// The dataset generator's TOML config, read, checked, and used for one sample's scene (the
/// first thing `streaks dataset generate` does with it).
pub fn config(data: &[u8]) -> Outcome {
    use streaks_scenes::procedural::{sample, GeneratorConfig};
    with_files(data, "config.toml", false, |dir| {
        let config = GeneratorConfig::from_toml_file(&dir.join("config.toml")).map_err(message)?;
        sample(&config, 0, 0).map(|_| ()).map_err(message)
    })
}

/// A Middlebury `calib.txt`.
pub fn calib(data: &[u8]) -> Outcome {
    with_files(data, CALIB, false, |dir| {
        streaks_stereo::calib::MiddleburyCalib::load(&dir.join(CALIB))
            .map(|_| ())
            .map_err(message)
    })
}

/// How long the two `streaks dataset index` runs on one input may take together before the
/// target reports a hang (under the runner's per-input limit, so that the child process is
/// always reaped).
pub const DATASET_TIME_LIMIT: Duration = Duration::from_millis(1500);

/// A dataset folder (`dataset.json` with any `manifest.jsonl`, `splits/` and `samples/` files),
/// checked by the `streaks dataset index` command twice: as given (which verifies the files
/// against `manifest.jsonl`, or writes it the first time) and then with `--rebuild` (which
/// checks the samples and writes the manifest and splits again). The dataset readers live in
/// the binary, so this target runs it (found by [`streaks_binary`]). A panic, a crash or a run
/// longer than [`DATASET_TIME_LIMIT`] panics here, so the runner reports it; the outcome is
/// the first run's error, else the second's.
pub fn dataset(data: &[u8]) -> Outcome {
    let binary = streaks_binary().unwrap_or_else(|e| panic!("{e}"));
    with_files(data, DATASET_JSON, true, |dir| {
        let deadline = Instant::now() + DATASET_TIME_LIMIT;
        let verified = index(&binary, dir, &[], deadline);
        let rebuilt = index(&binary, dir, &["--rebuild"], deadline);
        verified.and(rebuilt)
    })
}

/// Runs `streaks dataset index EXTRA DIR`: `Ok` if it succeeded, its last line if it failed
/// with status 1; panics on anything else (a crash, or still running at `deadline`).
fn index(binary: &Path, dir: &Path, extra: &[&str], deadline: Instant) -> Outcome {
    let log = dir.with_file_name("index.log");
    let mut child = Command::new(binary)
        .args(["dataset", "index"])
        .args(extra)
        .arg(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).expect("cannot make the log file"))
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", binary.display()));
    let command = format!("streaks dataset index {}", extra.join(" "));
    let command = command.trim_end();
    let status = loop {
        if let Some(status) = child.try_wait().expect("cannot wait for streaks") {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("hang: {command} ran past the {DATASET_TIME_LIMIT:?} the index runs share");
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let mut stderr = String::new();
    let _ = std::fs::File::open(&log).and_then(|mut f| f.read_to_string(&mut stderr));
    match status.code() {
        Some(0) => Ok(()),
        Some(1) => Err(stderr.lines().last().unwrap_or("").to_owned()),
        _ => {
            // The command's own panic, if any, first: the runner tells findings apart by it.
            let lines: Vec<&str> = stderr.lines().collect();
            let cause = lines
                .iter()
                .position(|l| l.contains("panicked at "))
                .map(|i| {
                    let place = lines[i].split("panicked at ").nth(1).unwrap_or("");
                    format!("panicked at {place} {}", lines.get(i + 1).unwrap_or(&""))
                })
                .unwrap_or_else(|| status.to_string());
            panic!("{command} {cause}\n{}", tail(&stderr))
        }
    }
}

/// The last 20 lines of `text`.
fn tail(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(20)..].join("\n")
}

/// The `streaks` binary the dataset target runs: `$STREAKS` if set, else the one beside this
/// executable (`target/debug/streaks` for `cargo run -p streaks-fuzz`).
pub fn streaks_binary() -> Result<PathBuf, String> {
    if let Some(path) = std::env::var_os("STREAKS") {
        return Ok(PathBuf::from(path));
    }
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this executable: {e}"))?;
    let beside = exe.with_file_name(format!("streaks{}", std::env::consts::EXE_SUFFIX));
    if beside.is_file() {
        Ok(beside)
    } else {
        Err(format!(
            "the dataset target runs the streaks binary, and there is none at {} \
             (build it with `cargo build --bin streaks`, or set STREAKS to its path)",
            beside.display()
        ))
    }
}
