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
//! The segmentation maps ([`EyeView::semantic`], [`EyeView::instance`]) are from the
//! `object` layer, the same pixel-centre ray: the class and instance of what it hits first
//! ([`streaks_render::scene::Scene::objects`], from the glTF nodes' `extras.streaks`), the
//! sky on a miss. The first-hit layers see through rain drops; the semantic map marks
//! [`Class::Rain`] where the `rain` layer's coverage is at least [`RAIN_COVERAGE`], and the
//! instance map keeps there the instance of the surface behind the rain (so that motion
//! ground truth built on it follows the surface).
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
use streaks_render::class::Class;
use streaks_render::integrator::{render, Layers, RenderJob, RenderOutput};
use streaks_render::light::{Emitter, Light};
use streaks_render::motion::Motion;
use streaks_render::scene::{Scene, SceneObject};
use streaks_sensor::{capture, Capture, SensorProfile};
use streaks_settings::RenderSettings;

/// A road pixel's first-hit normal is within this angle's cosine of +Y (10 degrees).
const ROAD_COS: f32 = 0.984_807_7;

/// The share of a pixel's camera samples whose first hit is a rain drop (the `rain` layer) from
/// which the semantic map calls the pixel [`Class::Rain`]: half, the majority rule of a
/// label.
pub const RAIN_COVERAGE: f32 = 0.5;

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
    /// Render the albedo and emission layers too (what the denoiser needs, [`denoise_pair`]).
    pub albedo: bool,
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
    /// The semantic label id ([`Class::id`]) per pixel, row-major: the class of the
    /// pixel-centre ray's first hit ([`Class::Unlabeled`] where no node labels it,
    /// [`Class::Sky`] on a miss), or [`Class::Rain`] where rain drops cover at least
    /// [`RAIN_COVERAGE`] of the pixel's samples.
    pub semantic: Vec<u8>,
    /// The `extras.streaks.instance` of the pixel-centre ray's first hit per pixel, row-major
    /// (0 for none and on a miss); under rain, the surface's behind it.
    pub instance: Vec<u32>,
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

    /// The 8-bit sRGB image as the eye's camera sees it: developed from the camera's raw DN
    /// when the view went through a camera model ([`expose_pair`]), else the render at
    /// `exposure_ev` stops ([`streaks_image::develop`]). The pair's and a sample's PNGs hold
    /// exactly these pixels.
    pub fn camera_image(&self, exposure_ev: f32) -> Result<image::RgbImage, StereoError> {
        Ok(match &self.sensor {
            Some(capture) => capture.develop(),
            None => streaks_image::develop(&self.output.image, exposure_ev)?,
        })
    }

    /// [`EyeView::camera_image`] at 16 bits: the same curve, rounded to 16 bits.
    pub fn camera_image16(
        &self,
        exposure_ev: f32,
    ) -> Result<image::ImageBuffer<image::Rgb<u16>, Vec<u16>>, StereoError> {
        Ok(match &self.sensor {
            Some(capture) => capture.develop16(),
            None => streaks_image::develop::develop16(&self.output.image, exposure_ev)?,
        })
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
            albedo: settings.albedo,
            specular: true,
            material: true,
            object: true,
            spp: false,
            rain: scene.rain.is_some(),
            fog: scene.fog.is_some(),
            emission: settings.albedo,
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
    let slots = output.object.as_ref().ok_or_else(|| missing("object"))?;
    let (semantic, instance) = segmentation(&scene.objects, slots, output.rain.as_deref());
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
        semantic,
        instance,
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

/// The semantic label ids and the instance ids of a render's `object` layer `slots` (indices
/// into `objects`, [`Scene::objects`]): each pixel's object's class id and instance, with
/// [`Class::Rain`] as the class where `rain` (the `rain` layer, if the render has one) is at
/// least [`RAIN_COVERAGE`]. A slot outside `objects` counts as unlabelled.
pub fn segmentation(
    objects: &[SceneObject],
    slots: &[u32],
    rain: Option<&[f32]>,
) -> (Vec<u8>, Vec<u32>) {
    let object = |s: u32| {
        objects
            .get(s as usize)
            .copied()
            .unwrap_or(SceneObject::UNLABELLED)
    };
    let semantic = slots
        .iter()
        .enumerate()
        .map(|(i, &s)| match rain.and_then(|r| r.get(i)) {
            Some(&c) if c >= RAIN_COVERAGE => Class::Rain.id(),
            _ => object(s).label().id(),
        })
        .collect();
    let instance = slots.iter().map(|&s| object(s).instance).collect();
    (semantic, instance)
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

/// Denoises both eyes' images ([`streaks_render::output::denoise`], guided by their albedo
/// and normal layers), after their ground truth and streak masks were taken from the render
/// and before a camera model exposes them: the raw renders stay in each
/// [`RenderOutput::raw`].
pub fn denoise_pair(
    views: &mut [EyeView; 2],
    denoiser: &streaks_image::denoise::Denoiser,
) -> Result<(), StereoError> {
    for (eye, view) in Eye::BOTH.into_iter().zip(views.iter_mut()) {
        streaks_render::output::denoise(&mut view.output, denoiser)
            .map_err(|e| StereoError::Render(format!("denoising the {eye} eye: {e}")))?;
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
    use crate::rig::Intrinsics;
    use glam::{Affine3A, Vec3};
    use streaks_render::material::Material;
    use streaks_render::scene::{base_table, SceneParts};

    /// Adds the axis-aligned box `[lo, hi]` (12 triangles, faces outward) of object slot
    /// `object`.
    fn cuboid(parts: &mut SceneParts, lo: Vec3, hi: Vec3, object: u32) {
        let base = parts.mesh.positions.len() as u32;
        for k in 0..8 {
            let pick = |bit: usize, a: f32, b: f32| if k & bit != 0 { b } else { a };
            parts.mesh.positions.push(Vec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            ));
        }
        // Quads by corner bits, counter-clockwise from outside.
        let quads = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        for [a, b, c, d] in quads {
            let v = |i: u32| base + i;
            parts.mesh.triangles.push([v(a), v(b), v(c)]);
            parts.mesh.triangles.push([v(a), v(c), v(d)]);
            parts.mesh.triangle_materials.extend([0, 0]);
            parts.mesh.triangle_objects.extend([object, object]);
        }
    }

    fn tagged(class: Class, instance: u32) -> SceneObject {
        SceneObject {
            class: Some(class),
            instance,
        }
    }

    const CAR_A: [Vec3; 2] = [Vec3::new(-2.5, 0.0, -10.0), Vec3::new(-0.5, 1.4, -8.0)];
    const CAR_B: [Vec3; 2] = [Vec3::new(0.5, 0.0, -10.0), Vec3::new(2.5, 1.4, -8.0)];
    const POLE: [Vec3; 2] = [Vec3::new(5.0, 0.0, -12.0), Vec3::new(5.6, 8.0, -11.4)];

    /// A road (a thin slab, slot 2), two cars of one class (instances 3 and 5, slots 3 and
    /// 4) and a pole (slot 5) under the sky.
    fn street() -> Scene {
        let mut parts = SceneParts {
            materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
            objects: base_table(),
            ..Default::default()
        };
        parts.objects.extend([
            tagged(Class::Road, 0),
            tagged(Class::Car, 3),
            tagged(Class::Car, 5),
            tagged(Class::Pole, 0),
        ]);
        cuboid(
            &mut parts,
            Vec3::new(-50.0, -1.0, -100.0),
            Vec3::new(50.0, 0.0, 10.0),
            2,
        );
        cuboid(&mut parts, CAR_A[0], CAR_A[1], 3);
        cuboid(&mut parts, CAR_B[0], CAR_B[1], 4);
        cuboid(&mut parts, POLE[0], POLE[1], 5);
        Scene::from_parts(parts).unwrap()
    }

    /// The projected rectangle `[min, max]` (pixel coordinates) of the front face (z = hi.z)
    /// of the box `[lo, hi]` seen by `eye`.
    fn front_face(rig: &Rig, eye: Eye, [lo, hi]: [Vec3; 2]) -> [glam::Vec2; 2] {
        let cam = rig.eye(eye);
        let a = cam.project(Vec3::new(lo.x, lo.y, hi.z)).unwrap();
        let b = cam.project(Vec3::new(hi.x, hi.y, hi.z)).unwrap();
        [a.min(b), a.max(b)]
    }

    /// Both eyes' maps against the analytic projection of the boxes' front faces: every
    /// pixel whose centre is half a pixel inside a car's face is that car (two instances of
    /// one class told apart), the pole's face is the pole, the row under a car is the road,
    /// and the top row (above the horizon, beside the pole) is the sky.
    #[test]
    fn segmentation_maps_match_the_projected_boxes() {
        let scene = street();
        let (w, h) = (96u32, 64u32);
        let rig = Rig::new(
            Intrinsics::new(w, h, 60.0).unwrap(),
            0.5,
            Affine3A::from_translation(Vec3::new(0.0, 1.6, 0.0)),
        )
        .unwrap();
        let settings = PairSettings {
            render: RenderSettings::new(1, 1),
            seed: 1,
            exposure_ev: 0.0,
            mask: StreakMaskParams::default(),
            motion: Motion::default(),
            albedo: false,
        };
        let views = render_pair(&scene, &rig, &settings, &|_| {}).unwrap();
        for (eye, view) in Eye::BOTH.into_iter().zip(&views) {
            let at = |x: u32, y: u32| {
                let i = (y * w + x) as usize;
                (view.semantic[i], view.instance[i])
            };
            let centre = |x: u32, y: u32| glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let inside = |[lo, hi]: [glam::Vec2; 2], p: glam::Vec2, m: f32| {
                p.cmpge(lo + m).all() && p.cmple(hi - m).all()
            };
            for (bx, want) in [
                (CAR_A, (Class::Car.id(), 3)),
                (CAR_B, (Class::Car.id(), 5)),
                (POLE, (Class::Pole.id(), 0)),
            ] {
                let face = front_face(&rig, eye, bx);
                let mut n = 0;
                for y in 0..h {
                    for x in 0..w {
                        if inside(face, centre(x, y), 0.5) {
                            assert_eq!(at(x, y), want, "{eye} eye, pixel ({x}, {y})");
                            n += 1;
                        }
                    }
                }
                assert!(n >= 20, "{eye} eye: {n} pixels inside {bx:?}");
                if bx != POLE {
                    // The row whose centre is at least a pixel below the bottom edge: road.
                    let y = (face[1].y + 1.0).ceil() as u32;
                    for x in (face[0].x.ceil() as u32 + 1)..(face[1].x.floor() as u32) {
                        assert_eq!(at(x, y), (Class::Road.id(), 0), "{eye} ({x}, {y})");
                    }
                }
            }
            assert_eq!(at(0, 0), (Class::Sky.id(), 0));
            assert_eq!(at(w / 2, 0), (Class::Sky.id(), 0));
            assert_eq!(view.semantic.len(), (w * h) as usize);
        }
    }

    /// Rain coverage of at least [`RAIN_COVERAGE`] makes the class rain and keeps the
    /// surface's instance; a slot outside the table is unlabelled.
    #[test]
    fn rain_coverage_sets_the_rain_class_and_keeps_the_instance() {
        let mut objects = base_table();
        objects.push(tagged(Class::Car, 9));
        let slots = [2, 2, 2, 0, 0, 1, 42];
        let rain = [0.0, 0.49, 0.5, 0.2, 1.0, 0.7, 0.0];
        let (semantic, instance) = segmentation(&objects, &slots, Some(&rain));
        let (car, sky, r) = (Class::Car.id(), Class::Sky.id(), Class::Rain.id());
        assert_eq!(semantic, [car, car, r, sky, r, r, Class::Unlabeled.id()]);
        assert_eq!(instance, [9, 9, 9, 0, 0, 0, 0]);
        let (dry, _) = segmentation(&objects, &slots, None);
        assert_eq!(dry, [car, car, car, sky, sky, 0, 0]);
    }

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
