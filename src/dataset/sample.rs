//! One sample: build its scene, render the pair, write every file into a temporary folder and
//! publish it with one rename.

use anyhow::{Context, Result};
use glam::Vec3;
use glam::{DAffine3, DVec3};
use std::path::Path;
use std::time::Instant;
use streaks_dataset::files::{SampleDir, SCENE_GLTF};
use streaks_dataset::layout::{sample_id, Layout};
use streaks_dataset::meta::{
    kitti_pose, matrix_rows, render_seed, FlowShares, FogMeta, RenderMeta, RigMeta, SampleMeta,
    SampleStats, SequenceMeta, WeatherMeta,
};
use streaks_dataset::outputs::Output;
use streaks_dataset::settings::Settings;
use streaks_dataset::verify::write_views as write_dataset_views;
use streaks_dataset::write::{
    disparity_range, instance_numbering, write_calib, write_flow, write_views, GroundTruth,
};
use streaks_image::png::write_png_buffer;
use streaks_image::write_bytes_atomically;
use streaks_render::motion::Motion;
use streaks_render::scene::Scene;
use streaks_scenes::procedural::{sample, street_frame, GeneratorConfig, GENERATOR_VERSION};
use streaks_sensor::SensorProfile;
use streaks_stereo::flow::to_f64;
use streaks_stereo::render::{
    denoise_pair, expose_pair, light_records, render_pair, rig_from_camera, scene_has_road,
    PairSettings,
};
use streaks_stereo::rig::Eye;
use streaks_stereo::rigfile::PoseRecord;
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
    /// How the samples are rendered (as `dataset.json` records it).
    pub settings: Settings,
    /// The denoiser, when [`Settings::denoise`].
    pub denoiser: Option<std::sync::Arc<streaks_image::denoise::Denoiser>>,
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
    /// The bytes it takes on disk: its folder's files and its files of the KITTI and
    /// SceneFlow views.
    pub bytes: u64,
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
    layout.remove_stale_tmp(index)?;
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
        if !layout.is_complete(index, &settings.settings.outputs) {
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

/// The camera of a sample with weather: the sensor preset `name` with the drawn shutter time
/// `exposure_s`, developed as the preset develops its own shutter time (its `develop_ev` raised
/// by `log2(preset exposure / exposure_s)`: the camera's auto exposure keeps the image's
/// brightness by gain, so a shorter shutter shows as more noise and less motion blur, not as a
/// darker image).
fn sample_sensor(name: &str, exposure_s: f64) -> Result<SensorProfile> {
    let mut profile = SensorProfile::preset(name)
        .with_context(|| format!("the sample's sensor preset {name:?}"))?;
    profile.develop_ev += (profile.exposure_s / exposure_s).log2();
    profile.exposure_s = exposure_s;
    Ok(profile)
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
    let mut scene =
        Scene::load(&gltf).with_context(|| format!("cannot load the scene {}", gltf.display()))?;
    for w in &scene.warnings {
        warn(format!("sample {}: {w}", sample_id(index)));
    }
    let camera = scene
        .camera(Some(&s.camera))
        .with_context(|| format!("in the scene {}", gltf.display()))?
        .clone();
    let render = &settings.settings;
    // The camera's shutter (the drawn exposure time) and the rig's motion over it.
    let motion = s.weather.as_ref().map_or(Motion::default(), |w| {
        Motion::centred(
            w.exposure_s as f32,
            Vec3::from(w.rig_velocity.map(|v| v as f32)),
        )
    });
    scene
        .place_rain(&camera, render.width, render.height, motion)
        .with_context(|| format!("the rain of the scene {}", gltf.display()))?;
    let rig = rig_from_camera(&camera, render.width, render.height, s.baseline)
        .with_context(|| format!("the stereo rig of {}", gltf.display()))?;
    let seed = render_seed(settings.seed, index);
    let pair = PairSettings {
        render: render.render,
        seed,
        exposure_ev: s.exposure_ev,
        mask: StreakMaskParams::default(),
        motion,
        albedo: settings.denoiser.is_some(),
    };
    let mut views = render_pair(&scene, &rig, &pair, &|_| {})?;
    if let Some(d) = &settings.denoiser {
        denoise_pair(&mut views, d)?;
        if !render.keep_raw {
            for v in &mut views {
                v.output.raw = None;
            }
        }
    }
    if let Some(weather) = &s.weather {
        let profile = sample_sensor(&weather.sensor, weather.exposure_s)?;
        // The generator's lights are physical: the radiance goes to the sensor unscaled.
        expose_pair(&mut views, &rig, &profile, seed, 0.0)?;
    }
    let [left, right] = &views;

    let files = SampleDir::new(dir);
    write_views(&files, &scene, &views, s.exposure_ev, GroundTruth::Left)?;
    if render.outputs.has(Output::Images16) {
        for (eye, view) in Eye::BOTH.into_iter().zip(&views) {
            write_png_buffer(&files.png16(eye), &view.camera_image16(s.exposure_ev)?)?;
        }
    }
    let instances = instance_numbering(&files, &scene)?.records().to_vec();
    // The flow to the next frame of the drive: its scene built and loaded, never rendered.
    let next = super::flow::next_frame(
        &settings.config,
        settings.seed,
        &s,
        &dir.join(super::flow::NEXT_FRAME_DIR),
        render.width,
        render.height,
    )?;
    let now = super::flow::Frame {
        sample: s,
        scene,
        rig,
    };
    let ids = super::flow::moving_ids(&left.instance, &now.sample.objects);
    let flow = super::flow::frame_flow(&now, &next, &ids)?;
    write_flow(&files, &flow)?;
    let super::flow::Frame {
        sample: s,
        scene,
        rig,
    } = now;
    let has_road = scene_has_road(&scene);

    let pixels = left.disparity.data.len().max(1) as f64;
    let range = disparity_range(left);
    write_calib(&files, &rig, left)?;

    let count = |flags: &mut dyn Iterator<Item = bool>| flags.filter(|&b| b).count() as f64;
    let stats = SampleStats {
        streak_share: count(&mut left.streak_mask.data.iter().map(|&m| m > 0.0)) / pixels,
        streak_threshold: left.streak_threshold,
        road_share: has_road.then(|| count(&mut left.road_surface.iter().copied()) / pixels),
        disparity_min: range.map(|r| r.0),
        disparity_max: range.map(|r| r.1),
        valid_share: left.disparity.data.iter().filter(|d| d.is_finite()).count() as f64 / pixels,
        nonfinite_dropped: left.output.stats.nonfinite_dropped
            + right.output.stats.nonfinite_dropped,
    };
    let i = rig.intrinsics();
    let pp = i.principal_point();
    let (pitch, roll) = rig.pitch_roll();
    let world_from_left = to_f64(rig.world_from_eye(Eye::Left));
    // The first frame's left camera, from the generator's pose of it (the rendered camera is
    // the glTF's, rounded to 1e-7).
    let first = if s.frame == 0 {
        world_from_left
    } else {
        let rig0 = street_frame(&settings.config, settings.seed, s.street, 0)?.world_from_rig;
        to_f64(rig0)
            * DAffine3::from_translation(DVec3::new(-0.5 * f64::from(rig.baseline()), 0.0, 0.0))
    };
    let shares = flow.shares();
    let sequence = SequenceMeta {
        frame: s.frame,
        time_s: s.time_s,
        fps: settings.config.sequence.fps,
        world_from_left: matrix_rows(&world_from_left),
        world_from_rig: matrix_rows(&to_f64(rig.world_from_rig())),
        kitti_pose: kitti_pose(&first, &world_from_left),
        flow_shares: FlowShares {
            no_surface: shares[0],
            out_of_view: shares[1],
            occluded: shares[2],
            visible: shares[3],
        },
    };
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
            pitch_deg: Some(pitch.to_degrees()),
            roll_deg: Some(roll.to_degrees()),
        },
        lights: light_records(&scene, rig.road_frame().ok().as_ref()),
        stats: stats.clone(),
        render: RenderMeta {
            settings: render.render,
            seed_left: seed,
            seed_right: seed.wrapping_add(1),
            mean_spp: Some([left, right].map(|v| v.output.stats.samples as f64 / pixels)),
            denoised: settings.denoiser.is_some(),
        },
        weather: s.weather.as_ref().map(|w| WeatherMeta {
            rain_class: w.rain_class.clone(),
            rain_mm_h: w.rain_mm_h,
            rain_seed: w.rain_seed,
            fog: w.fog.map(|f| FogMeta {
                sigma_t: f.sigma_t,
                albedo: f.albedo,
                g: f.g,
                height_falloff: f.height_falloff,
            }),
            sensor: w.sensor.clone(),
            exposure_s: w.exposure_s,
            rig_velocity: w.rig_velocity,
        }),
        instances: Some(instances),
        sequence: Some(sequence),
    };
    write_bytes_atomically(&files.meta(), &meta.to_bytes())?;
    let outputs = &render.outputs;
    write_dataset_views(layout, index, &meta, &files, outputs)?;
    // The groups not kept go, now that the views are made from them.
    let mut paths: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .and_then(|entries| entries.map(|e| e.map(|e| e.path())).collect())
        .with_context(|| format!("cannot list {}", dir.display()))?;
    let mut kept = Vec::with_capacity(paths.len());
    for p in paths.drain(..) {
        let name = p.file_name().unwrap_or_default().to_string_lossy();
        if outputs.keeps(&name) {
            kept.push(p);
        } else {
            std::fs::remove_file(&p).with_context(|| format!("cannot remove {}", p.display()))?;
        }
    }
    let mut paths = kept;
    let views = layout.view_files(index, &meta.split, meta.street, outputs);
    paths.extend(views.into_iter().map(|(_, p)| p));
    let mut bytes = 0;
    for p in paths {
        bytes += std::fs::metadata(&p)
            .with_context(|| format!("cannot read {}", p.display()))?
            .len();
    }
    Ok(Rendered {
        stats,
        road_mask: has_road,
        seconds: 0.0,
        bytes,
    })
}
