//! The flow ground truth of a dataset sample: the scene of the next frame of its street's
//! drive is built (never rendered), loaded, and the left eye's exact flow from this frame to
//! that one is derived from both scenes and the moving objects' poses
//! ([`streaks_stereo::flow::left_flow`]).
//!
//! Which pixel sees which moving object comes from the rendered left view's instance map (the
//! glTF's `extras.streaks.instance` of the pixel-centre ray's first hit, [`moving_ids`]), so a
//! car's flow ends exactly at its silhouette. The re-derivation test, which does not render, takes
//! the moving object whose bounds hold the first hit instead.

use anyhow::{Context, Result};
use std::path::Path;
use streaks_render::scene::Scene;
use streaks_scenes::drive::MovingObject;
use streaks_scenes::procedural::{street_frame, GeneratorConfig, SampleScene};
use streaks_stereo::flow::{left_flow, FlowField, ObjectMotion};
use streaks_stereo::render::rig_from_camera;
use streaks_stereo::rig::Rig;

/// The folder inside a sample's temporary folder where the next frame's scene is written to
/// be loaded; removed before the sample is published.
pub const NEXT_FRAME_DIR: &str = "next_frame";

/// One frame of a drive, built and loaded: its generated scene, the loaded scene and its rig.
pub struct Frame {
    /// What the generator built.
    pub sample: SampleScene,
    /// The scene as the renderer loaded it.
    pub scene: Scene,
    /// The rig of its camera.
    pub rig: Rig,
}

/// Writes `sample`'s scene into `dir` (created), loads it and makes its rig at the image
/// size; `dir` may be removed afterwards.
pub fn load_frame(sample: SampleScene, dir: &Path, width: u32, height: u32) -> Result<Frame> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    sample
        .doc
        .write(dir)
        .with_context(|| format!("cannot write the scene into {}", dir.display()))?;
    let gltf = dir.join(streaks_dataset::files::SCENE_GLTF);
    let scene =
        Scene::load(&gltf).with_context(|| format!("cannot load the scene {}", gltf.display()))?;
    let camera = scene
        .camera(Some(&sample.camera))
        .with_context(|| format!("in the scene {}", gltf.display()))?;
    let rig = rig_from_camera(camera, width, height, sample.baseline)
        .with_context(|| format!("the stereo rig of {}", gltf.display()))?;
    Ok(Frame { sample, scene, rig })
}

/// Builds and loads frame `frame + 1` of the street of `now` (in the folder `dir`, which is
/// removed again).
pub fn next_frame(
    config: &GeneratorConfig,
    seed: u64,
    now: &SampleScene,
    dir: &Path,
    width: u32,
    height: u32,
) -> Result<Frame> {
    let next = street_frame(config, seed, now.street, now.frame + 1)
        .context("the procedural generator failed on the next frame")?;
    let frame = load_frame(next, dir, width, height);
    let _ = std::fs::remove_dir_all(dir);
    frame
}

/// How the moving objects of `now` move to `next` (matched by instance id; an object that is
/// not in `next` is an error).
pub fn object_motion(now: &SampleScene, next: &SampleScene) -> Result<ObjectMotion> {
    let mut motion = ObjectMotion::new();
    for o in &now.objects {
        let Some(n) = next.objects.iter().find(|n| n.instance == o.instance) else {
            anyhow::bail!(
                "object {} of frame {} is not in frame {}",
                o.instance,
                now.frame,
                next.frame
            );
        };
        motion.insert(o.instance, o.world_from_object, n.world_from_object);
    }
    Ok(motion)
}

/// A rendered instance map (the scene's instance ids per pixel) with every id that is not
/// one of `objects` (the static world's: parked cars, traffic lights) set to 0.
pub fn moving_ids(instances: &[u32], objects: &[MovingObject]) -> Vec<u32> {
    instances
        .iter()
        .map(|&id| {
            if objects.iter().any(|o| o.instance == id) {
                id
            } else {
                0
            }
        })
        .collect()
}

/// The left eye's flow from the frame `now` to the frame `next`, with `ids` the moving object
/// each pixel of `now`'s left view sees (0: the static world).
pub fn frame_flow(now: &Frame, next: &Frame, ids: &[u32]) -> Result<FlowField> {
    let motion = object_motion(&now.sample, &next.sample)?;
    Ok(left_flow(
        &now.rig,
        &next.rig,
        &now.scene,
        &next.scene,
        ids,
        &motion,
    )?)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use glam::{Vec2, Vec3};
    use streaks_stereo::flow::{left_ray, Surfaces};

    /// The instance of the moving object a world point lies on, 0 for the static world.
    pub(crate) fn instance_at(objects: &[MovingObject], p: Vec3) -> u32 {
        objects
            .iter()
            .find(|o| o.contains(p))
            .map_or(0, |o| o.instance)
    }

    /// An instance map of the left view of `rig` in `scene` without rendering: per pixel (rows
    /// top to bottom) the moving object whose bounds hold the pixel-centre ray's first hit, 0
    /// otherwise.
    pub(crate) fn instance_map(rig: &Rig, scene: &Scene, objects: &[MovingObject]) -> Vec<u32> {
        let i = rig.intrinsics();
        let (w, h) = (i.width() as usize, i.height() as usize);
        let mut out = vec![0u32; w * h];
        if objects.is_empty() {
            return out;
        }
        for y in 0..h {
            for x in 0..w {
                let (o, d) = left_ray(rig, Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
                if let Some(t) = scene.first_hit(o, d) {
                    out[y * w + x] = instance_at(objects, o + d * t);
                }
            }
        }
        out
    }
    use streaks_stereo::flow::{FlowState, OCCLUSION_TOLERANCE};
    use streaks_stereo::rig::Eye;

    /// What [`rederive`] checked.
    #[derive(Debug, Default)]
    pub struct Rederived {
        /// Visible pixels checked, of them on moving objects.
        pub visible: usize,
        /// Visible pixels on moving objects.
        pub moving: usize,
        /// Occluded pixels checked.
        pub occluded: usize,
        /// Visible pixels whose disparity was re-derived in the right view.
        pub disparity: usize,
    }

    /// Re-derives the flow of sample `index` of `(config, seed)` at `width x height` from the
    /// two frames' scenes, independently of [`left_flow`]'s loop: for every `step`-th pixel
    /// with a visible flow, the ray from the next frame's left eye through `x + flow` meets
    /// the same instance at `|X' - C'|` within 1e-3 (relative), and the disparity change is
    /// `f b / Z' - f b / Z`; every occluded pixel checked fails that test. The disparity
    /// `f b / Z` re-derives in the right view: `X` projects to the same row at `x - f b / Z`,
    /// and where the right eye sees it, its ray through that pixel meets `X`. Works for any
    /// config, so that it can run on any road layout and traffic.
    pub fn rederive(
        config: &GeneratorConfig,
        seed: u64,
        index: u64,
        (width, height): (u32, u32),
        step: usize,
    ) -> Result<Rederived> {
        let dir = tempfile::tempdir()?;
        let s = streaks_scenes::procedural::sample(config, seed, index)?;
        let now = load_frame(s, &dir.path().join("now"), width, height)?;
        let next = next_frame(
            config,
            seed,
            &now.sample,
            &dir.path().join("next"),
            width,
            height,
        )?;
        let ids = instance_map(&now.rig, &now.scene, &now.sample.objects);
        let flow = frame_flow(&now, &next, &ids)?;
        let mut report = Rederived::default();
        let (w, h) = (width as usize, height as usize);
        let eye0 = now.rig.eye(Eye::Left);
        let eye1 = next.rig.eye(Eye::Left);
        let c1 = eye1.position().as_dvec3();
        let fb0 = f64::from(now.rig.focal_px() * now.rig.baseline());
        let fb1 = f64::from(next.rig.focal_px() * next.rig.baseline());
        for k in (0..w * h).step_by(step) {
            let state = flow.state[k];
            if !matches!(state, FlowState::Visible | FlowState::Occluded) {
                continue;
            }
            let pixel = Vec2::new((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
            // X from this frame's pixel-centre ray (the flow's own, so that a silhouette pixel
            // meets the same surface) and its object's poses, as the generator placed them.
            let (o0, dir0) = left_ray(&now.rig, pixel);
            let t0 = now.scene.first_hit(o0, dir0).expect("a flow has a hit");
            let p = (o0 + dir0 * t0).as_dvec3();
            let id = instance_at(&now.sample.objects, p.as_vec3());
            let moved = match now.sample.objects.iter().find(|o| o.instance == id) {
                Some(o) => {
                    let n = next
                        .sample
                        .objects
                        .iter()
                        .find(|n| n.instance == id)
                        .expect("the object is in the next frame");
                    let local = o.world_from_object.inverse().transform_point3(p.as_vec3());
                    n.world_from_object.transform_point3(local).as_dvec3()
                }
                None => p,
            };
            let distance = (moved - c1).length();
            // The ray through x' = x + flow.
            let x1 = pixel + Vec2::from(flow.flow[k]);
            let dir1 = eye1.ray_direction(x1);
            let t1 = next.scene.first_hit(eye1.position(), dir1);
            let agrees = t1.is_some_and(|t| {
                let hit = eye1.position() + dir1 * t;
                (f64::from(t) - distance).abs() <= 1e-3 * distance
                    && instance_at(&next.sample.objects, hit) == id
            });
            if state == FlowState::Occluded {
                assert!(
                    t1.is_some_and(|t| f64::from(t) < distance * (1.0 - OCCLUSION_TOLERANCE)),
                    "pixel {k}: occluded, but nothing nearer on its ray"
                );
                assert!(!agrees, "pixel {k}: occluded, but re-derived as visible");
                report.occluded += 1;
                continue;
            }
            assert!(
                agrees,
                "pixel {k} (instance {id}): the ray through x' meets {t1:?}, X' is at {distance}"
            );
            let z0 = f64::from(eye0.depth(p.as_vec3()));
            let right = now.rig.eye(Eye::Right);
            let xr = right
                .project(p.as_vec3())
                .expect("X is in front of the right eye");
            let d = f64::from(pixel.x - xr.x);
            assert!(
                (d - fb0 / z0).abs() <= 1e-3 * (fb0 / z0).max(1.0) && (xr.y - pixel.y).abs() < 1e-2,
                "pixel {k}: X projects to {xr} in the right view, disparity {d} vs {}",
                fb0 / z0
            );
            let dir_r = right.ray_direction(xr);
            let seen = (p - right.position().as_dvec3()).length();
            if let Some(t) = now.scene.first_hit(right.position(), dir_r) {
                if (f64::from(t) - seen).abs() <= 1e-3 * seen {
                    report.disparity += 1;
                }
            }
            let z1 = f64::from(eye1.depth(moved.as_vec3()));
            let change = fb1 / z1 - fb0 / z0;
            let got = f64::from(flow.disparity_change[k]);
            assert!(
                (got - change).abs() <= 1e-3 * change.abs().max(1.0),
                "pixel {k}: disparity change {got} vs {change}"
            );
            report.visible += 1;
            report.moving += usize::from(id != 0);
        }
        Ok(report)
    }

    /// A drive with leading and oncoming traffic on today's street.
    pub fn traffic_config() -> GeneratorConfig {
        let mut config = GeneratorConfig::default();
        config.dataset.pairs_per_street = 4;
        config.cars.ahead = [2, 2];
        config.cars.oncoming = [2, 2];
        config.sequence.speed_kmh = [40.0, 50.0];
        config.weather.enabled = false;
        config
    }

    /// The generated drive's flow re-derives exactly, on the static world and on moving cars,
    /// and its occluded pixels fail the re-derivation.
    #[test]
    fn generated_flow_rederives_exactly() {
        let config = traffic_config();
        let (mut visible, mut moving, mut occluded) = (0, 0, 0);
        for index in [1u64, 3, 6] {
            let r = rederive(&config, 21, index, (96, 54), 3).unwrap();
            visible += r.visible;
            moving += r.moving;
            occluded += r.occluded;
        }
        assert!(visible > 1000, "{visible} visible pixels checked");
        assert!(moving > 10, "{moving} pixels on moving cars checked");
        let _ = occluded;
    }

    /// The same on a road that bends, climbs over a crest, falls across and is crowned, with
    /// potholes and tracks: the rig and the cars follow the road, and the flow and disparity
    /// still re-derive exactly.
    #[test]
    fn flow_rederives_exactly_on_curved_sloped_roads() {
        let mut config = traffic_config();
        let road = &mut config.road;
        road.curve = 1.0;
        road.radius = [60.0, 90.0];
        road.curve_start = [0.0, 10.0];
        road.hill = 1.0;
        road.grade = [0.04, 0.06];
        road.grade_change = [-0.08, -0.06];
        road.vertical_curve_start = [10.0, 20.0];
        road.cross_fall = [0.01, 0.02];
        road.crown = [0.02, 0.03];
        road.potholes = [3, 3];
        road.tracks = 1.0;
        let (mut visible, mut moving, mut disparity) = (0, 0, 0);
        for index in [1u64, 6] {
            let s = streaks_scenes::procedural::sample(&config, 5, index).unwrap();
            let r = &s.params["road"];
            assert!(r["curvature"].as_f64().unwrap().abs() > 1.0 / 91.0, "{r}");
            let rep = rederive(&config, 5, index, (96, 54), 3).unwrap();
            visible += rep.visible;
            moving += rep.moving;
            disparity += rep.disparity;
        }
        assert!(visible > 1000, "{visible} visible pixels checked");
        assert!(moving > 10, "{moving} pixels on moving cars checked");
        assert!(
            disparity > 500,
            "{disparity} disparities re-derived in the right view"
        );
    }
}
