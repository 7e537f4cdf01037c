//! One sample: build its scene, render the pair, write every file into a temporary folder and
//! publish it with one rename.

use super::layout::{sample_id, Layout, ROAD_MASK, SAMPLE_FILES, SCENE_GLTF};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Instant;
use streaks_image::develop;
use streaks_image::kitti::write_kitti_disparity;
use streaks_image::pfm::write_pfm;
use streaks_image::png::write_png_buffer;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_render::output::write_exr;
use streaks_render::scene::Scene;
use streaks_scenes::procedural::{sample, GeneratorConfig, GENERATOR_VERSION};
use streaks_stereo::calib::MiddleburyCalib;
use streaks_stereo::render::{
    light_records, render_pair, rig_from_camera, scene_has_road, PairSettings,
};
use streaks_stereo::rigfile::{LightRecord, PoseRecord};
use streaks_stereo::streak_mask::StreakMaskParams;

/// What every sample of a dataset shares.
#[derive(Clone, Debug)]
pub struct SampleSettings {
    /// The generator config.
    pub config: GeneratorConfig,
    /// sha256 of the config's TOML.
    pub config_hash: String,
    /// The dataset seed.
    pub seed: u64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel per eye.
    pub spp: u32,
    /// Longest path.
    pub max_depth: u32,
    /// Path regularisation.
    pub regularize: bool,
    /// Adaptive sampling's target (`None`: `spp` everywhere).
    pub noise_target: Option<f64>,
}

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

/// The render settings of a sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderMeta {
    /// Samples per pixel per eye.
    pub spp: u32,
    /// Longest path.
    pub max_depth: u32,
    /// Seed of the left eye.
    pub seed_left: u32,
    /// Seed of the right eye.
    pub seed_right: u32,
    /// Path regularisation (absent, `false`, in samples written before the field existed).
    #[serde(default)]
    pub regularize: bool,
    /// Adaptive sampling's target (`None`, also in samples written before the field existed:
    /// `spp` samples everywhere).
    #[serde(default)]
    pub noise_target: Option<f64>,
    /// Mean samples per pixel actually taken, left and right eye (`spp` at fixed spp; absent
    /// in samples written before the field existed).
    #[serde(default)]
    pub mean_spp: Option<[f64; 2]>,
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
    pub fn load(path: &Path) -> Result<Self> {
        let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
            .with_context(|| format!("cannot read {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("{} does not parse", path.display()))
    }
}

/// What one rendered sample reports.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Statistics.
    pub stats: SampleStats,
    /// Whether the scene had a road material.
    pub road_mask: bool,
    /// Seconds from scene building to publishing.
    pub seconds: f64,
}

/// Whether sample `index` is published and has all its files (a cheap check: the files are
/// there; `streaks dataset index` checks their contents).
pub fn is_complete(layout: &Layout, index: u64) -> bool {
    let dir = layout.sample_dir(index);
    let present = |name: &str| dir.join(name).is_file();
    if !SAMPLE_FILES.iter().all(|f| present(f)) || !present(SCENE_GLTF) {
        return false;
    }
    match SampleMeta::load(&dir.join("meta.json")) {
        Ok(meta) => meta.index == index && (!meta.road_mask || present(ROAD_MASK)),
        Err(_) => false,
    }
}

/// Removes sample `index`'s temporary folders (`.tmp-NNNNNN-*`) and returns them. Call it
/// only while holding the sample's lock ([`Layout::sample_lock`]): every run renders a sample
/// under that lock, so then no live run owns such a folder and they are all stale.
pub fn remove_stale_tmp(layout: &Layout, index: u64) -> Result<Vec<PathBuf>> {
    let prefix = Layout::tmp_prefix(index);
    let dir = layout.samples_dir();
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Ok(Vec::new());
    };
    let mut removed = Vec::new();
    for entry in entries {
        let entry = entry.with_context(|| format!("cannot list {}", dir.display()))?;
        if entry.file_name().to_string_lossy().starts_with(&prefix) {
            let path = entry.path();
            let is_dir = std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir());
            if is_dir {
                std::fs::remove_dir_all(&path)
            } else {
                std::fs::remove_file(&path)
            }
            .with_context(|| format!("cannot remove the stale folder {}", path.display()))?;
            removed.push(path);
        }
    }
    Ok(removed)
}

/// Writes the KITTI view of a sample from its folder `dir` (image_2 and image_3 are copies of
/// im0.png and im1.png, disp_occ_0 is disp0 as uint16 x 256); each file atomically.
pub fn write_kitti(layout: &Layout, index: u64, dir: &Path, disp0: &GrayImage) -> Result<()> {
    let k = layout.kitti(index);
    for (src, dst) in [("im0.png", &k.image_2), ("im1.png", &k.image_3)] {
        let bytes = std::fs::read(dir.join(src)).with_context(|| format!("cannot read {src}"))?;
        create_parent(dst)?;
        write_bytes_atomically(dst, &bytes)?;
    }
    create_parent(&k.disp_occ_0)?;
    write_kitti_disparity(&k.disp_occ_0, disp0)?;
    Ok(())
}

fn create_parent(path: &Path) -> Result<()> {
    if let Some(p) = path.parent() {
        std::fs::create_dir_all(p)
            .with_context(|| format!("cannot create the folder {}", p.display()))?;
    }
    Ok(())
}

/// Renders sample `index` into a temporary folder, writes its KITTI files and publishes it as
/// `samples/NNNNNN/` (see the module documentation). The caller holds the sample's lock. `warn` receives the scene loader's
/// warnings. Without a road material in the scene, `road0.png` is not written
/// ([`Rendered::road_mask`] and `meta.json` say so).
pub fn render_sample(
    layout: &Layout,
    settings: &SampleSettings,
    index: u64,
    warn: &dyn Fn(String),
) -> Result<Rendered> {
    let start = Instant::now();
    let id = sample_id(index);
    remove_stale_tmp(layout, index)?;
    let tmp = layout.tmp_dir(index);
    std::fs::create_dir_all(&tmp)
        .with_context(|| format!("cannot create the folder {}", tmp.display()))?;
    let result = write_sample(layout, settings, index, &tmp, warn);
    let rendered = match result {
        Ok(r) => r,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&tmp);
            return Err(e.context(format!("sample {id}")));
        }
    };
    let dest = layout.sample_dir(index);
    if let Err(e) = std::fs::rename(&tmp, &dest) {
        let _ = std::fs::remove_dir_all(&tmp);
        // Another writer of the same index published first: its sample is the same.
        if !is_complete(layout, index) {
            return Err(e).with_context(|| {
                format!("cannot publish {} as {}", tmp.display(), dest.display())
            });
        }
    }
    Ok(Rendered {
        seconds: start.elapsed().as_secs_f64(),
        ..rendered
    })
}

/// Builds, renders and writes sample `index` into `dir`, and writes its KITTI files.
fn write_sample(
    layout: &Layout,
    settings: &SampleSettings,
    index: u64,
    dir: &Path,
    warn: &dyn Fn(String),
) -> Result<Rendered> {
    let s = sample(&settings.config, settings.seed, index)
        .context("the procedural generator failed")?;
    s.doc
        .write(dir)
        .with_context(|| format!("cannot write the scene into {}", dir.display()))?;
    let gltf = dir.join(SCENE_GLTF);
    let scene =
        Scene::load(&gltf).with_context(|| format!("cannot load the scene {}", gltf.display()))?;
    for w in &scene.warnings {
        warn(format!("sample {}: {w}", sample_id(index)));
    }
    let camera = scene
        .camera(Some(&s.camera))
        .with_context(|| format!("in the scene {}", gltf.display()))?;
    let rig = rig_from_camera(camera, settings.width, settings.height, s.baseline)
        .with_context(|| format!("the stereo rig of {}", gltf.display()))?;
    let seed = render_seed(settings.seed, index);
    let pair = PairSettings {
        spp: settings.spp,
        noise_target: settings.noise_target.map(|rel| rel as f32),
        max_depth: settings.max_depth,
        seed,
        exposure_ev: s.exposure_ev,
        mask: StreakMaskParams::default(),
        regularize: settings.regularize,
    };
    let views = render_pair(&scene, &rig, &pair, &|_| {})?;
    let [left, right] = &views;

    for (n, view) in views.iter().enumerate() {
        write_exr(&dir.join(format!("im{n}.exr")), &view.output)?;
        let img = develop(&view.output.image, s.exposure_ev)?;
        write_png_buffer(&dir.join(format!("im{n}.png")), &img)?;
        write_pfm(&dir.join(format!("disp{n}.pfm")), &view.disparity)?;
    }
    write_pfm(&dir.join("depth0.pfm"), &left.depth)?;
    left.streak_mask.save_png(&dir.join("streaks0.png"))?;
    let has_road = scene_has_road(&scene);
    if has_road {
        left.road_surface_mask()?.save_png(&dir.join(ROAD_MASK))?;
    }

    let pixels = left.disparity.data.len().max(1) as f64;
    let finite: Vec<f32> = left
        .disparity
        .data
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .collect();
    let range = finite
        .iter()
        .copied()
        .fold(None, |r: Option<(f32, f32)>, d| {
            Some(r.map_or((d, d), |(a, b)| (a.min(d), b.max(d))))
        });
    MiddleburyCalib::of_rig(&rig, range).save(&dir.join("calib.txt"))?;

    let count = |flags: &mut dyn Iterator<Item = bool>| flags.filter(|&b| b).count() as f64;
    let stats = SampleStats {
        streak_share: count(&mut left.streak_mask.data.iter().map(|&m| m > 0.0)) / pixels,
        streak_threshold: left.streak_threshold,
        road_share: has_road.then(|| count(&mut left.road_surface.iter().copied()) / pixels),
        disparity_min: range.map(|r| r.0),
        disparity_max: range.map(|r| r.1),
        valid_share: finite.len() as f64 / pixels,
        nonfinite_dropped: left.output.stats.nonfinite_dropped
            + right.output.stats.nonfinite_dropped,
    };
    let i = rig.intrinsics();
    let pp = i.principal_point();
    let meta = SampleMeta {
        id: sample_id(index),
        index,
        seed: settings.seed,
        render_seed: seed,
        street: s.street,
        split: s.split.name().to_owned(),
        config_hash: settings.config_hash.clone(),
        generator_version: GENERATOR_VERSION.to_owned(),
        camera: s.camera.clone(),
        exposure_ev: s.exposure_ev,
        road_mask: has_road,
        params: s.params.clone(),
        rig: RigMeta {
            baseline_m: rig.baseline(),
            focal_px: rig.focal_px(),
            width: i.width(),
            height: i.height(),
            principal_point: [pp.x, pp.y],
            world_from_rig: PoseRecord::from_affine(&rig.world_from_rig()),
            rig_height_m: rig.height(),
        },
        lights: light_records(&scene, rig.road_frame().ok().as_ref()),
        stats: stats.clone(),
        render: RenderMeta {
            spp: settings.spp,
            max_depth: settings.max_depth,
            seed_left: seed,
            seed_right: seed.wrapping_add(1),
            regularize: settings.regularize,
            noise_target: settings.noise_target,
            mean_spp: Some([left, right].map(|v| v.output.stats.samples as f64 / pixels)),
        },
    };
    let mut text = serde_json::to_string_pretty(&meta)?;
    text.push('\n');
    write_bytes_atomically(&dir.join("meta.json"), text.as_bytes())?;
    write_kitti(layout, index, dir, &left.disparity)?;
    Ok(Rendered {
        stats,
        road_mask: has_road,
        seconds: 0.0,
    })
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
}
