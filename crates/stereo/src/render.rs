//! Rendering a rectified stereo pair with ground truth (feature `render`).
//!
//! The scene is loaded once (one BVH) and both eyes are path-traced from it. Ground truth
//! comes from the renderer's `depth` layer, the camera-space depth `Z` of the first hit of each
//! pixel's centre ray (`inf` on a miss): the disparity of that pixel is `d = f b / Z` pixels
//! (`inf` on a miss). For the right view this is the Middlebury `disp1` convention: the pixel's
//! match in the left view is at `x + d`. The streak masks use the `specular` layer (see
//! [`crate::streak_mask`]) with road pixels from the `normal` layer. The road-surface mask
//! ([`EyeView::road_surface`]) is from the `material` layer: the pixels whose centre ray hits a
//! material of the scene contract's road (`extras.streaks.road: true`) first.
//!
//! The left eye is rendered with the given seed and the right eye with `seed + 1`, so that
//! the two views' sampling noise is independent and cannot pull a matcher toward zero disparity.
//!
//! Through a camera model ([`expose_pair`], `--sensor`), each eye gets its raw capture
//! ([`EyeView::sensor`]) with its own noise seed (the eye's render seed); the ground truth and
//! the streak masks stay those of the render.
//!
//! The views are written into a sample folder by the `streaks-dataset` crate (its `write`
//! module), which names every file.
//!
//! The rendered-scene tests (ground truth against an analytic road plane, and the disparity
//! of a rendered textured plane measured with the project's Lucas-Kanade estimator) are in
//! `tests/cli/stereo.rs`.

use crate::error::StereoError;
use crate::rig::{Eye, Intrinsics, Rig, RoadFrame};
use crate::rigfile::{LightRecord, Placed};
use crate::streak_mask::{streak_mask, StreakMaskParams};
use streaks_image::GrayImage;
use streaks_render::camera::Camera;
use streaks_render::integrator::{render, Layers, RenderJob, RenderOutput};
use streaks_render::light::{Emitter, Light};
use streaks_render::motion::Motion;
use streaks_render::scene::Scene;
use streaks_sensor::{capture, Capture, SensorProfile};
use streaks_settings::RenderSettings;

/// A road pixel's first-hit normal is within this angle's cosine of +Y (10 degrees).
const ROAD_COS: f32 = 0.984_807_7;

/// The rig of a scene camera: the camera is the rig centre, its `yfov` gives the focal length
/// for an image of `height` pixels (`f = (H/2) / tan(yfov/2)`). An orthographic camera is an
/// error: a rectified pair's disparity `f b / Z` needs a pinhole.
pub fn rig_from_camera(
    camera: &Camera,
    width: u32,
    height: u32,
    baseline: f32,
) -> Result<Rig, StereoError> {
    let Some(yfov) = camera.yfov() else {
        return Err(StereoError::Camera(format!(
            "a stereo pair needs a perspective camera; camera {:?} is orthographic",
            camera.name
        )));
    };
    let intrinsics = Intrinsics::from_yfov(width, height, yfov)?;
    Rig::new(intrinsics, baseline, camera.world_from_camera).map_err(|e| match e {
        StereoError::Pose(reason) => {
            StereoError::Pose(format!("camera {:?}: {reason}", camera.name))
        }
        other => other,
    })
}

/// One eye of `rig` as a renderer camera (same pose, field of view and aspect ratio).
pub fn eye_camera(rig: &Rig, eye: Eye) -> Camera {
    let i = rig.intrinsics();
    Camera::perspective(
        format!("{eye} eye"),
        rig.world_from_eye(eye),
        i.yfov(),
        Some(i.width() as f32 / i.height() as f32),
    )
}

/// How to render a pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSettings {
    /// How each eye is sampled (the same for both).
    pub render: RenderSettings,
    /// Seed of the left eye (the right eye uses `seed + 1`).
    pub seed: u32,
    /// Exposure of the PNGs in stops.
    pub exposure_ev: f32,
    /// The streak-mask definition.
    pub mask: StreakMaskParams,
    /// The shutter and the rig's motion (the same for both eyes).
    pub motion: Motion,
}

/// One rendered eye with its ground truth.
#[derive(Clone, Debug)]
pub struct EyeView {
    /// The renderer's output (beauty image with `depth`, `normal` and `specular` layers).
    pub output: RenderOutput,
    /// Camera-space depth `Z` of each pixel's first hit (`inf` on a miss).
    pub depth: GrayImage,
    /// Ground-truth disparity `f b / Z` in pixels (`inf` on a miss).
    pub disparity: GrayImage,
    /// Which pixels see an upward-facing surface (the road for the streak mask).
    pub road: Vec<bool>,
    /// Which pixels' centre ray hits a road material
    /// ([`streaks_render::material::Material::road`]) first; all `false` when the scene flags
    /// none ([`scene_has_road`]).
    pub road_surface: Vec<bool>,
    /// The streak mask (1 = streak).
    pub streak_mask: GrayImage,
    /// The specular-luminance threshold the mask used.
    pub streak_threshold: f32,
    /// The eye's raw capture through a camera model ([`expose_pair`]); `None` for the render
    /// alone.
    pub sensor: Option<Capture>,
}

impl EyeView {
    /// [`EyeView::road_surface`] as an image: 1 on road-surface pixels, 0 elsewhere (written
    /// 0/255 by [`GrayImage::save_png`]).
    pub fn road_surface_mask(&self) -> Result<GrayImage, StereoError> {
        let data = self
            .road_surface
            .iter()
            .map(|&b| f32::from(u8::from(b)))
            .collect();
        Ok(GrayImage::from_vec(
            self.disparity.width,
            self.disparity.height,
            data,
        )?)
    }
}

/// Renders one eye and derives its ground truth and streak mask.
pub fn render_eye(
    scene: &Scene,
    rig: &Rig,
    eye: Eye,
    settings: &PairSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<EyeView, StereoError> {
    settings
        .render
        .check()
        .map_err(|e| StereoError::Parameter {
            name: e.name(),
            reason: e.reason(),
        })?;
    let i = rig.intrinsics();
    let (w, h) = (i.width(), i.height());
    let job = RenderJob {
        width: w,
        height: h,
        seed: eye_seed(settings.seed, eye),
        layers: Layers {
            depth: true,
            normal: true,
            albedo: false,
            specular: true,
            material: true,
            spp: false,
            rain: scene.rain.is_some(),
            fog: scene.fog.is_some(),
        },
        settings: settings.render,
        motion: settings.motion,
    };
    let output = render(scene, &eye_camera(rig, eye), &job, progress);
    let missing =
        |what: &str| StereoError::Render(format!("the renderer returned no {what} layer"));
    let z = output.depth.clone().ok_or_else(|| missing("depth"))?;
    let normals = output.normal.as_ref().ok_or_else(|| missing("normal"))?;
    let specular = output
        .specular
        .as_ref()
        .ok_or_else(|| missing("specular"))?;
    let materials = output
        .material
        .as_ref()
        .ok_or_else(|| missing("material"))?;
    let road_surface = road_surface(scene, materials);
    let (wu, hu) = (w as usize, h as usize);
    let disparity: Vec<f32> = z
        .iter()
        .map(|&z| {
            if z.is_finite() && z > 0.0 {
                rig.disparity_px(z)
            } else {
                f32::INFINITY
            }
        })
        .collect();
    let road: Vec<bool> = normals
        .pixels
        .iter()
        .zip(&z)
        .map(|(n, z)| z.is_finite() && n.y > ROAD_COS)
        .collect();
    let (streak_mask, streak_threshold) = streak_mask(
        &GrayImage::luminance_of(specular)?,
        &GrayImage::luminance_of(&output.image)?,
        Some(&road),
        &settings.mask,
    )?;
    Ok(EyeView {
        depth: GrayImage::from_vec(wu, hu, z)?,
        disparity: GrayImage::from_vec(wu, hu, disparity)?,
        road,
        road_surface,
        streak_mask,
        streak_threshold,
        output,
        sensor: None,
    })
}

/// Which pixels of a render's `material` layer ([`RenderOutput::material`]) see a road
/// material ([`streaks_render::material::Material::road`]) first.
pub fn road_surface(scene: &Scene, materials: &[u32]) -> Vec<bool> {
    materials
        .iter()
        .map(|&m| scene.materials.get(m as usize).is_some_and(|m| m.road))
        .collect()
}

/// Whether any material of `scene` is the road surface of the scene contract
/// (`extras.streaks.road: true`); without one, [`EyeView::road_surface`] is empty of road.
pub fn scene_has_road(scene: &Scene) -> bool {
    scene.materials.iter().any(|m| m.road)
}

/// The render seed of `eye` for a pair of seed `seed`: `seed` left, `seed + 1` right.
pub fn eye_seed(seed: u32, eye: Eye) -> u32 {
    match eye {
        Eye::Left => seed,
        Eye::Right => seed.wrapping_add(1),
    }
}

/// Exposes both rendered eyes of `rig` through the camera `profile` ([`EyeView::sensor`]):
/// the radiance times `2^scene_ev`, each eye's noise drawn from its render seed
/// ([`eye_seed`] of `seed`), so the two eyes' noise is independent.
pub fn expose_pair(
    views: &mut [EyeView; 2],
    rig: &Rig,
    profile: &SensorProfile,
    seed: u32,
    scene_ev: f32,
) -> Result<(), StereoError> {
    for (eye, view) in Eye::BOTH.into_iter().zip(views.iter_mut()) {
        let raw = capture(
            profile,
            &view.output.image,
            f64::from(rig.focal_px()),
            f64::from(scene_ev),
            u64::from(eye_seed(seed, eye)),
        )
        .map_err(|e| StereoError::Render(format!("the {eye} eye's sensor: {e}")))?;
        view.sensor = Some(raw);
    }
    Ok(())
}

/// Renders both eyes (left first) with one `progress` over both: it receives increments of
/// pixel samples, `2 * width * height * spp` in all.
pub fn render_pair(
    scene: &Scene,
    rig: &Rig,
    settings: &PairSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<[EyeView; 2], StereoError> {
    let left = render_eye(scene, rig, Eye::Left, settings, progress)?;
    let right = render_eye(scene, rig, Eye::Right, settings, progress)?;
    Ok([left, right])
}

/// The scene's emitters as `rig.json` records, exactly the renderer's
/// ([`streaks_render::light::Emitters`]): point, spot and directional lights as they are, then
/// each emitter mesh (connected emissive triangles of one material: a lamp) with the centre
/// the renderer uses for it.
pub fn light_records(scene: &Scene, road: Option<&RoadFrame>) -> Vec<LightRecord> {
    let emitters = scene.light_sampler.emitters();
    emitters
        .list()
        .iter()
        .map(|emitter| match emitter {
            Emitter::Punctual(Light::Point {
                position,
                intensity,
                range,
            }) => LightRecord::Point {
                position: Placed::point(*position, road),
                intensity: (*intensity).into(),
                range: *range,
            },
            Emitter::Punctual(Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
                range,
            }) => LightRecord::Spot {
                position: Placed::point(*position, road),
                direction: Placed::vector(*direction, road),
                intensity: (*intensity).into(),
                cos_inner: *cos_inner,
                cos_outer: *cos_outer,
                range: *range,
            },
            Emitter::Punctual(Light::Directional {
                direction,
                irradiance,
            }) => LightRecord::Directional {
                direction: Placed::vector(*direction, road),
                irradiance: (*irradiance).into(),
            },
            Emitter::Mesh(m) => {
                let material = &scene.materials[m.material() as usize];
                LightRecord::Emissive {
                    centroid: Placed::point(m.centre(), road),
                    area: m.area(),
                    triangles: m.triangle_count(),
                    radiance: material.emission.into(),
                    material: material.name.clone(),
                }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Vec3};

    #[test]
    fn bad_inputs_are_errors() {
        let cam = Camera::perspective("c", Affine3A::from_scale(Vec3::splat(2.0)), 0.5, None);
        let e = rig_from_camera(&cam, 64, 48, 0.065).unwrap_err();
        assert!(e.to_string().contains("\"c\""), "{e}");
        let cam = Camera {
            world_from_camera: Affine3A::IDENTITY,
            ..cam
        };
        assert!(matches!(
            rig_from_camera(&cam, 64, 48, 0.0),
            Err(StereoError::Baseline(_))
        ));
        assert!(rig_from_camera(&cam, 0, 48, 0.065).is_err());
        let ortho = Camera::orthographic("flat", Affine3A::IDENTITY, 1.0, 1.0);
        let e = rig_from_camera(&ortho, 64, 48, 0.065)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a stereo pair needs a perspective camera; camera \"flat\" is orthographic"),
            "{e}"
        );
        let rig = rig_from_camera(&cam, 64, 48, 0.065).unwrap();
        let eye = eye_camera(&rig, Eye::Right);
        assert!((eye.focal_px(48).unwrap() - rig.focal_px()).abs() < 1e-3);
        let p = Vec3::new(0.3, -0.2, -4.0);
        let a = eye.project(p, 64, 48).unwrap();
        let b = rig.eye(Eye::Right).project(p).unwrap();
        assert!((a - b).length() < 1e-3, "{a} {b}");
    }
}
