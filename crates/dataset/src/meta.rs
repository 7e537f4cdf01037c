//! `meta.json` of a dataset sample: what it is, how it was rendered, its rig, lights and
//! statistics; and the render seed of a sample.

use crate::error::DatasetError;
use crate::segmentation::InstanceRecord;
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
    /// Pitch of the optical axis below the horizon, degrees (absent in samples written
    /// before the field existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_deg: Option<f32>,
    /// Roll about the optical axis, degrees, positive with the camera's right side down
    /// (absent in samples written before the field existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_deg: Option<f32>,
}

/// A sample as a frame of its street's drive: its time, the left camera's and the rig's world
/// poses, the KITTI odometry pose and the flow's statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SequenceMeta {
    /// The frame's number in the street's drive (0 first).
    pub frame: u64,
    /// The frame's time, seconds (`frame / fps`).
    pub time_s: f64,
    /// Frames per second.
    pub fps: f64,
    /// The left camera's world pose, a 4x4 matrix row by row (the project's camera axes: x
    /// right, y up, looking along -z).
    pub world_from_left: [[f64; 4]; 4],
    /// The rig centre's world pose, a 4x4 matrix row by row.
    pub world_from_rig: [[f64; 4]; 4],
    /// The left camera's pose in the left camera frame of the street's first frame, KITTI
    /// odometry style: the top 3x4 of the matrix row by row, camera axes x right, y down, z
    /// forward (the line of `poses.txt`).
    pub kitti_pose: [f64; 12],
    /// Share of the left pixels whose flow is visible, occluded, out of view and without a
    /// surface (the flow mask's classes).
    pub flow_shares: FlowShares,
}

/// Shares of the left pixels by flow class.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlowShares {
    /// Visible in the next frame.
    pub visible: f64,
    /// Occluded in the next frame.
    pub occluded: f64,
    /// Out of the next frame's view.
    pub out_of_view: f64,
    /// No surface (the sky).
    pub no_surface: f64,
}

/// A rigid pose as a 4x4 matrix, row by row.
pub fn matrix_rows(pose: &glam::DAffine3) -> [[f64; 4]; 4] {
    let m = glam::DMat4::from(*pose).transpose();
    [
        m.x_axis.to_array(),
        m.y_axis.to_array(),
        m.z_axis.to_array(),
        m.w_axis.to_array(),
    ]
}

/// The KITTI odometry pose of a camera at `world_from_camera` relative to the camera of the
/// first frame at `world_from_first` (both in the project's camera axes: x right, y up,
/// looking along -z): `S first_from_world world_from_camera S` with `S = diag(1, -1, -1)`,
/// which turns the axes into KITTI's (x right, y down, z forward); the top 3x4, row by row.
pub fn kitti_pose(
    world_from_first: &glam::DAffine3,
    world_from_camera: &glam::DAffine3,
) -> [f64; 12] {
    let s = glam::DAffine3::from_scale(glam::DVec3::new(1.0, -1.0, -1.0));
    let rows = matrix_rows(&(s * world_from_first.inverse() * *world_from_camera * s));
    let mut out = [0.0; 12];
    for (r, row) in rows.iter().take(3).enumerate() {
        out[4 * r..4 * r + 4].copy_from_slice(row);
    }
    out
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

/// A sample's fog as `meta.json` records it (the scene's `extras.streaks.fog`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FogMeta {
    /// Extinction coefficient at road level, 1/m.
    pub sigma_t: f64,
    /// Single-scattering albedo.
    pub albedo: f64,
    /// Henyey-Greenstein asymmetry.
    pub g: f64,
    /// Density falloff with height, 1/m (0: homogeneous).
    pub height_falloff: f64,
}

/// A sample's weather and camera as the generator drew them: rain, fog, the sensor preset,
/// the exposure time and the rig's velocity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeatherMeta {
    /// The rain class drawn (`dry`, `drizzle`, `moderate`, `heavy`, or a config's own).
    pub rain_class: String,
    /// Rain rate, mm/h (0: no rain falls).
    pub rain_mm_h: f64,
    /// Seed of the rain drops (the scene's `extras.streaks.rain.seed`).
    pub rain_seed: u32,
    /// The fog, or `null`.
    pub fog: Option<FogMeta>,
    /// The sensor preset's name.
    pub sensor: String,
    /// Exposure (shutter) time, seconds.
    pub exposure_s: f64,
    /// The rig's velocity in world space, m/s.
    pub rig_velocity: [f64; 3],
}

/// A condition a sample was rendered in, from its `meta.json` ([`SampleMeta::conditions`]); a
/// sample can be in several (rain, fog and noise), and `dry` is neither rain nor fog.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Condition {
    /// No rain falls and there is no fog.
    Dry,
    /// Rain falls: `weather.rain_mm_h > 0`.
    Rain,
    /// The scene has fog: `weather.fog` is not `null`.
    Fog,
    /// The camera's auto-exposure gain is above its preset's: [`WeatherMeta::gain_ev`] >
    /// [`NOISE_GAIN_EV`] with a preset that has noise ([`PresetNoise`]).
    Noise,
}

impl Condition {
    /// Every condition, in the order reports list them.
    pub const ALL: [Condition; 4] = [
        Condition::Dry,
        Condition::Rain,
        Condition::Fog,
        Condition::Noise,
    ];

    /// Its name in reports (`dry`, `rain`, `fog`, `noise`).
    pub fn name(self) -> &'static str {
        match self {
            Condition::Dry => "dry",
            Condition::Rain => "rain",
            Condition::Fog => "fog",
            Condition::Noise => "noise",
        }
    }
}

/// The gain above which a sample is in [`Condition::Noise`], stops: a shutter time shorter than
/// the sensor preset's own (10 ms for both automotive presets) makes the auto exposure raise
/// the gain by `log2(preset exposure / exposure)`, and the relative shot noise by half of that
/// in stops. With the default shutter times (1/120 to 1/30 s) the gain spans -1.74 to +0.26
/// stops, so any gain above the preset's, 0 stops, is the noisy end (about 7 % of samples).
pub const NOISE_GAIN_EV: f64 = 0.0;

/// What [`Condition::Noise`] needs to know of a sensor preset (the caller looks it up by the
/// preset's name: `streaks_sensor::SensorProfile::preset`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PresetNoise {
    /// The preset's own shutter time, seconds (the one its development is set for).
    pub exposure_s: f64,
    /// Whether the preset has any noise (shot or read noise; the `ideal` preset has none).
    pub noisy: bool,
}

impl WeatherMeta {
    /// The auto-exposure gain of the sample's camera above its sensor `preset`'s, stops:
    /// `log2(preset exposure_s / exposure_s)`, as the generator develops the image
    /// (`src/dataset/sample.rs`). `None` without the preset (unknown to this version) or when
    /// it has no noise at all.
    pub fn gain_ev(&self, preset: Option<PresetNoise>) -> Option<f64> {
        let p = preset.filter(|p| p.noisy)?;
        (self.exposure_s > 0.0).then(|| (p.exposure_s / self.exposure_s).log2())
    }

    /// The conditions of a sample with this weather and the sensor `preset` it names, in
    /// [`Condition::ALL`]'s order: `rain` when rain falls, `fog` when there is fog, `dry` when
    /// neither, and `noise` when the gain is above [`NOISE_GAIN_EV`].
    pub fn conditions(&self, preset: Option<PresetNoise>) -> Vec<Condition> {
        let rain = self.rain_mm_h > 0.0;
        let fog = self.fog.is_some();
        let noise = self.gain_ev(preset).is_some_and(|g| g > NOISE_GAIN_EV);
        [
            (Condition::Dry, !rain && !fog),
            (Condition::Rain, rain),
            (Condition::Fog, fog),
            (Condition::Noise, noise),
        ]
        .into_iter()
        .filter_map(|(c, on)| on.then_some(c))
        .collect()
    }
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
    /// Whether the images were denoised (false in samples written before the field existed).
    pub denoised: bool,
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
    /// Whether the images were denoised.
    #[serde(default)]
    denoised: bool,
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
            denoised: r.denoised,
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
            denoised: m.denoised,
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
    /// The weather the generator drew (`None`: the config had none, or the sample was written
    /// before the field existed; the file then has no `weather` key).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather: Option<WeatherMeta>,
    /// The objects of the instance maps: each `(class, k)` of `instanceN.png`'s
    /// `labelId * 1000 + k` with the scene's instance id ([`crate::segmentation`]). `None`
    /// (no key) in samples written before the segmentation maps, which have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instances: Option<Vec<InstanceRecord>>,
    /// The sample as a frame of its street's drive (`None`: written before sequences
    /// existed; the file then has no `sequence` key, and the sample no flow files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<SequenceMeta>,
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

    /// The conditions the sample was rendered in ([`WeatherMeta::conditions`]); a sample
    /// without a weather record (a config without `[weather]`: no rain, no fog, the render
    /// without a camera's noise) is `dry` only.
    /// `preset` gives a sensor preset's [`PresetNoise`] by its name (`None`: unknown).
    pub fn conditions(&self, preset: impl Fn(&str) -> Option<PresetNoise>) -> Vec<Condition> {
        self.weather
            .as_ref()
            .map_or_else(|| vec![Condition::Dry], |w| w.conditions(preset(&w.sensor)))
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

    /// A sample's meta.json with a weather record reads back equal; one without the key (an
    /// old file, or a config without weather) reads as `None` and is written without it.
    /// A camera that moved 2 m forward and turned left by 90 degrees, in KITTI axes: its
    /// position is z = +2 (forward), its x axis (right) is the first camera's +z (forward),
    /// its z axis (forward) the first camera's -x (left), its y axis (down) unchanged.
    #[test]
    fn kitti_poses_are_relative_to_the_first_camera_in_kittis_axes() {
        use glam::{DAffine3, DVec3};
        let first = DAffine3::from_translation(DVec3::new(5.0, 1.2, -3.0));
        let turned = DAffine3::from_translation(DVec3::new(5.0, 1.2, -5.0))
            * DAffine3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let p = kitti_pose(&first, &turned);
        let expected = [0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0];
        for (a, b) in p.iter().zip(expected) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
        let same = kitti_pose(&turned, &turned);
        assert_eq!(
            same,
            [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        );
        assert_eq!(matrix_rows(&first)[0], [1.0, 0.0, 0.0, 5.0]);
    }

    #[test]
    fn conditions_follow_rain_fog_and_the_gain() {
        let fog = FogMeta {
            sigma_t: 0.02,
            albedo: 0.95,
            g: 0.8,
            height_falloff: 0.1,
        };
        let weather = |rain_mm_h: f64, fog: Option<FogMeta>, exposure_s: f64| WeatherMeta {
            rain_class: "x".into(),
            rain_mm_h,
            rain_seed: 1,
            fog,
            sensor: "automotive_hdr".into(),
            exposure_s,
            rig_velocity: [0.0; 3],
        };
        // Both automotive presets expose 10 ms.
        let automotive = Some(PresetNoise {
            exposure_s: 0.01,
            noisy: true,
        });
        use Condition::*;
        // 20 ms is 1 stop below the preset's gain, 5 ms 1 stop above.
        let w = weather(0.0, None, 0.02);
        assert_eq!(w.gain_ev(automotive), Some(-1.0));
        assert_eq!(w.conditions(automotive), vec![Dry]);
        let w = weather(0.0, None, 0.005);
        assert_eq!(w.gain_ev(automotive), Some(1.0));
        assert_eq!(w.conditions(automotive), vec![Dry, Noise]);
        // Exactly the preset's shutter: no gain, no noise condition.
        assert_eq!(weather(0.5, None, 0.01).conditions(automotive), vec![Rain]);
        assert_eq!(
            weather(0.0, Some(fog), 0.03).conditions(automotive),
            vec![Fog]
        );
        assert_eq!(
            weather(30.0, Some(fog), 1.0 / 120.0).conditions(automotive),
            vec![Rain, Fog, Noise]
        );
        // A noise-free or unknown preset is never noisy.
        let ideal = Some(PresetNoise {
            exposure_s: 0.01,
            noisy: false,
        });
        let short = weather(0.0, None, 0.001);
        assert_eq!(
            (short.gain_ev(ideal), short.conditions(ideal)),
            (None, vec![Dry])
        );
        assert_eq!(short.gain_ev(None), None);
        assert_eq!(
            Condition::ALL.map(Condition::name),
            ["dry", "rain", "fog", "noise"]
        );
        assert_eq!(serde_json::to_string(&Noise).unwrap(), "\"noise\"");
    }

    #[test]
    fn weather_round_trips_and_old_files_read() {
        let weather = WeatherMeta {
            rain_class: "heavy".into(),
            rain_mm_h: 22.5,
            rain_seed: 99,
            fog: Some(FogMeta {
                sigma_t: 0.02,
                albedo: 0.95,
                g: 0.8,
                height_falloff: 0.1,
            }),
            sensor: "automotive_hdr".into(),
            exposure_s: 0.02,
            rig_velocity: [0.0, 0.0, -8.0],
        };
        let text = serde_json::to_string(&weather).unwrap();
        assert_eq!(
            text,
            r#"{"rain_class":"heavy","rain_mm_h":22.5,"rain_seed":99,"fog":{"sigma_t":0.02,"albedo":0.95,"g":0.8,"height_falloff":0.1},"sensor":"automotive_hdr","exposure_s":0.02,"rig_velocity":[0.0,0.0,-8.0]}"#
        );
        assert_eq!(serde_json::from_str::<WeatherMeta>(&text).unwrap(), weather);
        let clear: WeatherMeta = serde_json::from_str(
            r#"{"rain_class":"dry","rain_mm_h":0.0,"rain_seed":1,"fog":null,"sensor":"automotive_linear","exposure_s":0.01,"rig_velocity":[0,0,0]}"#,
        )
        .unwrap();
        assert_eq!(clear.fog, None);

        let mut meta: serde_json::Value = serde_json::json!({
            "id": "000000", "index": 0, "seed": 1, "render_seed": 2, "street": 0,
            "split": "train", "config_hash": "x", "generator_version": "g", "camera": "driver",
            "exposure_ev": 6.0, "road_mask": true, "params": {},
            "rig": {"baseline_m": 0.2, "focal_px": 100.0, "width": 8, "height": 8,
                    "principal_point": [4.0, 4.0],
                    "world_from_rig": {"position": [0.0, 1.0, 0.0], "x_axis": [1.0, 0.0, 0.0],
                                       "y_axis": [0.0, 1.0, 0.0], "z_axis": [0.0, 0.0, 1.0]},
                    "rig_height_m": 1.0},
            "lights": [],
            "stats": {"streak_share": 0.0, "streak_threshold": 1.0, "road_share": null,
                      "disparity_min": null, "disparity_max": null, "valid_share": 1.0,
                      "nonfinite_dropped": 0},
            "render": {"spp": 4, "max_depth": 8, "seed_left": 2, "seed_right": 3},
        });
        let old: SampleMeta = serde_json::from_value(meta.clone()).unwrap();
        assert_eq!(old.weather, None);
        assert_eq!(old.conditions(|_| None), vec![Condition::Dry]);
        assert!(!String::from_utf8(old.to_bytes())
            .unwrap()
            .contains("weather"));
        meta["weather"] = serde_json::to_value(&weather).unwrap();
        let new: SampleMeta = serde_json::from_value(meta).unwrap();
        assert_eq!(new.weather.as_ref(), Some(&weather));
        // 20 ms on a 10 ms preset: 1 stop below its gain, not noisy.
        let preset = |name: &str| {
            assert_eq!(name, "automotive_hdr");
            Some(PresetNoise {
                exposure_s: 0.01,
                noisy: true,
            })
        };
        assert_eq!(
            new.conditions(preset),
            vec![Condition::Rain, Condition::Fog]
        );
        let again: SampleMeta = serde_json::from_slice(&new.to_bytes()).unwrap();
        assert_eq!(again, new);
    }

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
            denoised: true,
        };
        let text = serde_json::to_string(&meta).unwrap();
        assert_eq!(
            text,
            r#"{"spp":64,"max_depth":8,"seed_left":7,"seed_right":8,"regularize":true,"noise_target":0.1,"mean_spp":[20.5,21.0],"denoised":true}"#
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
                denoised: false,
            }
        );
    }
}
