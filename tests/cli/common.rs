//! Helpers for the end-to-end tests: a fresh folder per test, the real executable, tiny scenes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh temporary folder in which one test runs the command.
pub struct TestDir {
    dir: tempfile::TempDir,
}

impl TestDir {
    /// A new empty folder.
    pub fn new() -> Self {
        Self {
            dir: tempfile::tempdir().expect("cannot create a temporary folder"),
        }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// A path inside the folder.
    pub fn join(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// Generates the 6-sample 96x64 dataset `ds` at 4 spp, not denoised on any machine (the
    /// tests are about pipelines, and at 4 spp the denoiser smooths the tiny streaks), keeping
    /// `outputs` (the default groups without), and returns its non-empty splits, the one with
    /// the most samples first (splits are drawn per street).
    pub fn tiny_dataset(&self, outputs: Option<&str>) -> Vec<&'static str> {
        self.generate_tiny("ds", "6", None, outputs);
        let mut splits: Vec<(usize, &str)> = ["train", "val", "test"]
            .into_iter()
            .map(|s| {
                let text = std::fs::read_to_string(self.join("ds/splits").join(format!("{s}.txt")))
                    .unwrap_or_default();
                (text.split_whitespace().count(), s)
            })
            .filter(|(n, _)| *n > 0)
            .collect();
        splits.sort();
        splits.reverse();
        splits.into_iter().map(|(_, s)| s).collect()
    }

    /// Generates a dataset of `count` 96x64 samples at 4 spp without denoising into
    /// `folder`, of `seed` if given, keeping `outputs` (the default groups without).
    pub fn generate_tiny(
        &self,
        folder: &str,
        count: &str,
        seed: Option<&str>,
        outputs: Option<&str>,
    ) {
        let mut args = vec![
            "dataset",
            "generate",
            "-o",
            folder,
            "--count",
            count,
            "--width",
            "96",
            "--height",
            "64",
            "--spp",
            "4",
            "--denoise",
            "off",
        ];
        if let Some(s) = seed {
            args.extend(["--seed", s]);
        }
        if let Some(o) = outputs {
            args.extend(["--outputs", o]);
        }
        self.streaks(&args).assert_success();
    }

    /// Runs `streaks ARGS` in this folder (CI=true: no progress bar).
    pub fn streaks(&self, args: &[&str]) -> Run {
        let output = Command::new(env!("CARGO_BIN_EXE_streaks"))
            .args(args)
            .current_dir(self.path())
            .env("CI", "true")
            .output()
            .expect("cannot run the streaks executable");
        Run { output }
    }

    /// Names of the files in a folder of this test, sorted.
    pub fn files_in(&self, sub: &str) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(self.join(sub))
            .map(|entries| {
                entries
                    .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        names
    }

    /// Writes `flat.toml`, a generator config whose streets are straight, level and flat,
    /// without trees, and returns its path (as a string for the command line): tests that
    /// need a road plane or an open sky use it.
    pub fn write_flat_street_config(&self) -> String {
        let path = self.join("flat.toml");
        std::fs::write(
            &path,
            "[road]\ncurve = 0.0\nhill = 0.0\ngrade = [0.0, 0.0]\n\
             cross_fall = [0.0, 0.0]\ncrown = [0.0, 0.0]\n[objects]\ntrees = [0.0, 0.0]\n",
        )
        .unwrap();
        path.display().to_string()
    }

    /// Writes `scene.gltf` + `scene.bin`: a 10 m x 10 m diffuse floor at Y = 0 (front face up),
    /// a point light of intensity 20 W/sr (13660 cd) 2 m above its centre, a small emissive quad facing
    /// the camera, and a camera (aspect 1.5) at (0, 1, 4) tilted 0.1 rad down.
    pub fn write_tiny_gltf(&self) -> PathBuf {
        // Floor: 4 vertices; emitter quad at z = -3, y in [1.5, 2], facing +Z.
        let positions: [[f32; 3]; 8] = [
            [-5.0, 0.0, -5.0],
            [5.0, 0.0, -5.0],
            [5.0, 0.0, 5.0],
            [-5.0, 0.0, 5.0],
            [-0.5, 1.5, -3.0],
            [0.5, 1.5, -3.0],
            [0.5, 2.0, -3.0],
            [-0.5, 2.0, -3.0],
        ];
        let floor: [u16; 6] = [0, 2, 1, 0, 3, 2];
        let quad: [u16; 6] = [4, 5, 6, 4, 6, 7];
        let mut bin = Vec::new();
        for p in positions {
            for c in p {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        for i in floor.iter().chain(quad.iter()) {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        std::fs::write(self.join("scene.bin"), &bin).unwrap();
        let json = format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "point", "color": [1, 1, 1], "intensity": 13660}}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2, 3]}}],
  "nodes": [
    {{"mesh": 0, "name": "floor"}},
    {{"mesh": 1, "name": "sign"}},
    {{"camera": 0, "name": "cam", "translation": [0, 1, 4], "rotation": [-0.049979, 0, 0, 0.99875]}},
    {{"name": "lamp", "translation": [0, 2, 0], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1}}}}],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 2, "material": 1}}]}}
  ],
  "materials": [
    {{"name": "road", "pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 1}},
      "extras": {{"streaks": {{"bsdf": "ggx", "kd": [0.3, 0.3, 0.3], "ks": [0.2, 0.2, 0.2], "alpha": 0.1}}}}}},
    {{"name": "sign", "emissiveFactor": [1, 0.5, 0.2], "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 4}}}},
      "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}}}}
  ],
  "buffers": [{{"uri": "scene.bin", "byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 96, "target": 34962}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 12, "target": 34963}},
    {{"buffer": 0, "byteOffset": 108, "byteLength": 12, "target": 34963}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-5, 0, -5], "max": [5, 2, 5]}},
    {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
            len = bin.len()
        );
        let path = self.join("scene.gltf");
        std::fs::write(&path, json).unwrap();
        path
    }
}

/// The result of one run of the command.
pub struct Run {
    /// Exit status and captured streams.
    pub output: Output,
}

impl Run {
    /// Standard error as text.
    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    /// Panics with the captured stderr unless the run succeeded.
    pub fn assert_success(&self) -> &Self {
        assert!(
            self.output.status.success(),
            "streaks failed: {}",
            self.stderr()
        );
        self
    }

    /// Panics unless the run failed with an `error:` message containing `needle`.
    pub fn assert_failure_mentioning(&self, needle: &str) -> &Self {
        let err = self.stderr();
        assert!(!self.output.status.success(), "streaks succeeded: {err}");
        assert!(
            err.contains("error") && err.contains(needle),
            "the message does not mention {needle:?}: {err}"
        );
        assert!(!err.contains("panicked"), "streaks panicked: {err}");
        self
    }
}

/// Whether Intel Open Image Denoise can be loaded, for the denoising tests: without it they
/// are skipped (saying so), unless STREAKS_REQUIRE_OIDN is set (as CI does), which fails them.
pub fn denoiser_available() -> bool {
    match streaks_image::denoise::Denoiser::load() {
        Ok(_) => true,
        Err(e) => {
            assert!(std::env::var_os("STREAKS_REQUIRE_OIDN").is_none(), "{e}");
            eprintln!("skipped: {e}");
            false
        }
    }
}
