//! `meta.json` of a dataset sample: what it is, how it was rendered, its rig, lights and
//! statistics; and the render seed of a sample.

use crate::error::DatasetError;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::Path;
use streaks_settings::RenderSettings;
use streaks_stereo::rigfile::{LightRecord, PoseRecord};

/// The render seed of sample `index` of a dataset of seed `seed` (SplitMix64 of the pair, high
/// 32 bits): the right eye uses this + 1, as `render_pair` does.
pub fn render_seed(seed: u64, index: u64) -> u32 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(index)
        .wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 32) as u32
}

/// The rig as `meta.json` records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigMeta {
    /// Baseline in metres.
    pub baseline_m: f32,
    /// Focal length in pixels.
    pub focal_px: f32,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Principal point (this project's pixel coordinates: the image centre).
    pub principal_point: [f32; 2],
    /// The rig centre's pose (the scene camera).
    pub world_from_rig: PoseRecord,
    /// Height of the rig centre above the road, metres.
    pub rig_height_m: f32,
}

/// A sample's statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleStats {
    /// Share of the left view's pixels in the streak mask.
    pub streak_share: f64,
    /// The specular-luminance threshold of the streak mask.
    pub streak_threshold: f32,
    /// Share of the left view's pixels whose first hit is the road surface (`None`: the scene
    /// flags no road material).
    pub road_share: Option<f64>,
    /// Smallest finite disparity of the left view (`None`: none is finite).
    pub disparity_min: Option<f32>,
    /// Largest finite disparity of the left view.
    pub disparity_max: Option<f32>,
    /// Share of the left view's pixels with a finite disparity.
    pub valid_share: f64,
    /// Non-finite path samples dropped by the renderer (both eyes).
    pub nonfinite_dropped: u64,
}

/// How a sample was rendered: the dataset's render settings, the eyes' seeds and the samples
/// they took.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "RenderRecord", into = "RenderRecord")]
pub struct RenderMeta {
    /// The render settings (both eyes).
    pub settings: RenderSettings,
    /// Seed of the left eye.
    pub seed_left: u32,
    /// Seed of the right eye.
    pub seed_right: u32,
    /// Mean samples per pixel actually taken, left and right eye (`spp` at fixed spp; absent
    /// in samples written before the field existed).
    pub mean_spp: Option<[f64; 2]>,
}

/// `meta.json`'s `render` object as the file holds it: the render settings' fields with the
/// seeds among them, in this order (a flattened [`RenderSettings`] could not put the seeds
/// there, and the file's bytes stay as they were).
#[derive(Serialize, Deserialize)]
struct RenderRecord {
    /// Samples per pixel per eye.
    spp: u32,
    /// Longest path.
    max_depth: u32,
    /// Seed of the left eye.
    seed_left: u32,
    /// Seed of the right eye.
    seed_right: u32,
    /// Path regularisation (absent, `false`, in samples written before the field existed).
    #[serde(default)]
    regularize: bool,
    /// Adaptive sampling's target (`None`, also in samples written before the field existed:
    /// `spp` samples everywhere).
    #[serde(default)]
    noise_target: Option<f32>,
    /// Mean samples per pixel actually taken, left and right eye.
    #[serde(default)]
    mean_spp: Option<[f64; 2]>,
}

impl From<RenderRecord> for RenderMeta {
    fn from(r: RenderRecord) -> Self {
        Self {
            settings: RenderSettings {
                spp: r.spp,
                max_depth: r.max_depth,
                regularize: r.regularize,
                noise_target: r.noise_target,
            },
            seed_left: r.seed_left,
            seed_right: r.seed_right,
            mean_spp: r.mean_spp,
        }
    }
}

impl From<RenderMeta> for RenderRecord {
    fn from(m: RenderMeta) -> Self {
        let RenderSettings {
            spp,
            max_depth,
            regularize,
            noise_target,
        } = m.settings;
        Self {
            spp,
            max_depth,
            seed_left: m.seed_left,
            seed_right: m.seed_right,
            regularize,
            noise_target,
            mean_spp: m.mean_spp,
        }
    }
}

/// `meta.json` of a sample (no wall time: the file is the same on every run).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleMeta {
    /// The sample id (folder name).
    pub id: String,
    /// The sample index.
    pub index: u64,
    /// The dataset seed.
    pub seed: u64,
    /// The render seed of the left eye.
    pub render_seed: u32,
    /// The street (scene) the sample belongs to.
    pub street: u64,
    /// `train`, `val` or `test`.
    pub split: String,
    /// sha256 of the config's TOML.
    pub config_hash: String,
    /// The generator's version.
    pub generator_version: String,
    /// The scene camera that is the rig centre.
    pub camera: String,
    /// Exposure of the PNGs in stops.
    pub exposure_ev: f32,
    /// Whether `road0.png` was written.
    pub road_mask: bool,
    /// The generator's scene parameters.
    pub params: Value,
    /// The rig.
    pub rig: RigMeta,
    /// The scene's lights (as rig.json records them, with road-frame coordinates).
    pub lights: Vec<LightRecord>,
    /// Statistics.
    pub stats: SampleStats,
    /// Render settings.
    pub render: RenderMeta,
}

impl SampleMeta {
    /// Reads a sample's `meta.json`.
    pub fn load(path: &Path) -> Result<Self, DatasetError> {
        let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
            .map_err(|e| DatasetError::io("read", path, e))?;
        serde_json::from_str(&text).map_err(|source| DatasetError::Json {
            path: path.to_path_buf(),
            what: "a sample's meta.json".into(),
            source,
        })
    }

    /// The file's bytes (pretty JSON, a final newline).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut text = serde_json::to_string_pretty(self).expect("meta.json serialises");
        text.push('\n');
        text.into_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_seeds_differ_by_index_and_seed() {
        let seeds: Vec<u32> = (0..1000).map(|i| render_seed(0, i)).collect();
        let mut unique = seeds.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), seeds.len());
        assert_ne!(render_seed(1, 0), render_seed(0, 0));
        assert_ne!(render_seed(0, 1), render_seed(1, 0));
        assert_eq!(render_seed(5, 7), render_seed(5, 7));
    }

    /// The `render` object keeps its keys in the file's order (the seeds between the settings)
    /// and reads back equal; one from before `regularize`, `noise_target` and `mean_spp`
    /// existed reads as unregularised, fixed spp.
    #[test]
    fn render_meta_keeps_the_file_order_and_reads_old_files() {
        let meta = RenderMeta {
            settings: RenderSettings {
                regularize: true,
                noise_target: Some(0.1),
                ..RenderSettings::new(64, 8)
            },
            seed_left: 7,
            seed_right: 8,
            mean_spp: Some([20.5, 21.0]),
        };
        let text = serde_json::to_string(&meta).unwrap();
        assert_eq!(
            text,
            r#"{"spp":64,"max_depth":8,"seed_left":7,"seed_right":8,"regularize":true,"noise_target":0.1,"mean_spp":[20.5,21.0]}"#
        );
        assert_eq!(serde_json::from_str::<RenderMeta>(&text).unwrap(), meta);
        let old: RenderMeta =
            serde_json::from_str(r#"{"spp":4,"max_depth":8,"seed_left":1,"seed_right":2}"#)
                .unwrap();
        assert_eq!(
            old,
            RenderMeta {
                settings: RenderSettings::new(4, 8),
                seed_left: 1,
                seed_right: 2,
                mean_spp: None,
            }
        );
    }
}
