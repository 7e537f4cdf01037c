//! Rendering a rectified stereo pair with ground truth (feature `render`).
//!
//! The scene is loaded once (one BVH) and both eyes are path-traced from it. Ground truth
//! comes from the renderer's `depth` layer, the camera-space depth `Z` of the first hit of each
//! pixel's centre ray (`inf` on a miss): the disparity of that pixel is `d = f b / Z` pixels
//! (`inf` on a miss). For the right view this is the Middlebury `disp1` convention: the pixel's
//! match in the left view is at `x + d`. The streak masks use the `specular` layer (see
//! [`crate::streak_mask`]) with road pixels from the `normal` layer.
//!
//! The left eye is rendered with the given seed and the right eye with `seed + 1`, so that
//! the two views' sampling noise is independent and cannot pull a matcher toward zero disparity.
//!
//! Files written by [`write_pair`] into the output folder: `left.exr`, `right.exr` (linear,
//! with `depth`, `normal` and `specular` layers), `left.png`, `right.png` (sRGB with the
//! exposure), `side_by_side.png`, `anaglyph.png`, `disparity_left.pfm`, `depth_left.pfm`,
//! `disparity_right.pfm`, `depth_right.pfm`, `streak_mask_left.png`, `streak_mask_right.png`
//! and `rig.json`.

use crate::error::StereoError;
use crate::image::GrayImage;
use crate::pair::write_pair_views;
use crate::pfm::write_pfm;
use crate::rig::{Eye, Intrinsics, Rig, RoadFrame};
use crate::rigfile::{LightRecord, Placed, RigFile};
use crate::streak_mask::{streak_mask, StreakMaskParams};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;
use streaks_render::camera::Camera;
use streaks_render::integrator::{render, Layers, RenderOutput, RenderSettings};
use streaks_render::light::Light;
use streaks_render::output::{to_srgb8, write_exr, write_png, RgbImage};
use streaks_render::scene::Scene;

/// A road pixel's first-hit normal is within this angle's cosine of +Y (10 degrees).
const ROAD_COS: f32 = 0.984_807_7;

/// The rig of a scene camera: the camera is the rig centre, its `yfov` gives the focal length
/// for an image of `height` pixels (`f = (H/2) / tan(yfov/2)`).
pub fn rig_from_camera(
    camera: &Camera,
    width: u32,
    height: u32,
    baseline: f32,
) -> Result<Rig, StereoError> {
    let intrinsics = Intrinsics::from_yfov(width, height, camera.yfov)?;
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
    Camera {
        name: format!("{eye} eye"),
        world_from_camera: rig.world_from_eye(eye),
        yfov: i.yfov(),
        aspect_ratio: Some(i.width() as f32 / i.height() as f32),
    }
}

/// How to render a pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Longest path (Mitsuba's meaning).
    pub max_depth: u32,
    /// Seed of the left eye (the right eye uses `seed + 1`).
    pub seed: u32,
    /// Exposure of the PNGs in stops.
    pub exposure_ev: f32,
    /// The streak-mask definition.
    pub mask: StreakMaskParams,
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
    /// Which pixels see an upward-facing surface (the road).
    pub road: Vec<bool>,
    /// The streak mask (1 = streak).
    pub streak_mask: GrayImage,
    /// The specular-luminance threshold the mask used.
    pub streak_threshold: f32,
}

fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
}

fn luminance_image(img: &RgbImage) -> Result<GrayImage, StereoError> {
    Ok(GrayImage::from_vec(
        img.width as usize,
        img.height as usize,
        img.pixels.iter().map(|&p| luminance(p)).collect(),
    )?)
}

/// Renders one eye and derives its ground truth and streak mask.
pub fn render_eye(
    scene: &Scene,
    rig: &Rig,
    eye: Eye,
    settings: &PairSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<EyeView, StereoError> {
    if settings.spp == 0 || settings.max_depth == 0 {
        return Err(StereoError::Parameter {
            name: "spp/max-depth",
            reason: "both must be at least 1".into(),
        });
    }
    let i = rig.intrinsics();
    let (w, h) = (i.width(), i.height());
    let render_settings = RenderSettings {
        width: w,
        height: h,
        spp: settings.spp,
        max_depth: settings.max_depth,
        seed: match eye {
            Eye::Left => settings.seed,
            Eye::Right => settings.seed.wrapping_add(1),
        },
        layers: Layers {
            depth: true,
            normal: true,
            albedo: false,
            specular: true,
        },
    };
    let output = render(scene, &eye_camera(rig, eye), &render_settings, progress);
    let missing =
        |what: &str| StereoError::Render(format!("the renderer returned no {what} layer"));
    let z = output.depth.clone().ok_or_else(|| missing("depth"))?;
    let normals = output.normal.as_ref().ok_or_else(|| missing("normal"))?;
    let specular = output
        .specular
        .as_ref()
        .ok_or_else(|| missing("specular"))?;
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
        &luminance_image(specular)?,
        &luminance_image(&output.image)?,
        Some(&road),
        &settings.mask,
    )?;
    Ok(EyeView {
        depth: GrayImage::from_vec(wu, hu, z)?,
        disparity: GrayImage::from_vec(wu, hu, disparity)?,
        road,
        streak_mask,
        streak_threshold,
        output,
    })
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

/// The scene's lights as `rig.json` records: point, spot and directional lights as they are;
/// emissive triangles grouped into lamps (triangles of one material that share vertex
/// positions), each with its area-weighted centroid.
pub fn light_records(scene: &Scene, road: Option<&RoadFrame>) -> Vec<LightRecord> {
    let mut out = Vec::new();
    let mut emissive = Vec::new();
    for light in &scene.lights {
        match *light {
            Light::Point {
                position,
                intensity,
                range,
            } => out.push(LightRecord::Point {
                position: Placed::point(position, road),
                intensity: intensity.into(),
                range,
            }),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
                range,
            } => out.push(LightRecord::Spot {
                position: Placed::point(position, road),
                direction: Placed::vector(direction, road),
                intensity: intensity.into(),
                cos_inner,
                cos_outer,
                range,
            }),
            Light::Directional {
                direction,
                irradiance,
            } => out.push(LightRecord::Directional {
                direction: Placed::vector(direction, road),
                irradiance: irradiance.into(),
            }),
            Light::Triangle { triangle } => emissive.push(triangle as usize),
        }
    }
    out.extend(emissive_groups(scene, &emissive, road));
    out
}

/// Union-find root with path halving.
fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

fn emissive_groups(scene: &Scene, tris: &[usize], road: Option<&RoadFrame>) -> Vec<LightRecord> {
    let valid: Vec<usize> = tris
        .iter()
        .copied()
        .filter(|&t| t < scene.triangles.len())
        .collect();
    let mut parent: Vec<usize> = (0..valid.len()).collect();
    // Triangles touching the same vertex position with the same material are one lamp.
    let mut first_at: HashMap<([u32; 3], u32), usize> = HashMap::new();
    for (k, &t) in valid.iter().enumerate() {
        let material = scene.triangle_materials.get(t).copied().unwrap_or(u32::MAX);
        for &v in &scene.triangles[t] {
            let p = scene.positions[v as usize];
            let key = ([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()], material);
            let other = *first_at.entry(key).or_insert(k);
            let (a, b) = (find(&mut parent, k), find(&mut parent, other));
            parent[a] = b;
        }
    }
    // Accumulate per root, in order of first appearance.
    let mut order: Vec<usize> = Vec::new();
    let mut acc: HashMap<usize, (Vec3, f32, usize, u32)> = HashMap::new();
    for (k, &t) in valid.iter().enumerate() {
        let root = find(&mut parent, k);
        let [a, b, c] = scene.triangles[t].map(|v| scene.positions[v as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        let material = scene.triangle_materials.get(t).copied().unwrap_or(u32::MAX);
        let e = acc.entry(root).or_insert_with(|| {
            order.push(root);
            (Vec3::ZERO, 0.0, 0, material)
        });
        e.0 += area * (a + b + c) / 3.0;
        e.1 += area;
        e.2 += 1;
    }
    order
        .into_iter()
        .map(|root| {
            let (weighted, area, n, material) = acc[&root];
            let m = scene.materials.get(material as usize);
            LightRecord::Emissive {
                centroid: Placed::point(weighted / area.max(f32::MIN_POSITIVE), road),
                area,
                triangles: n,
                radiance: m.map(|m| m.emission.into()).unwrap_or([0.0; 3]),
                material: m.map(|m| m.name.clone()).unwrap_or_default(),
            }
        })
        .collect()
}

fn output_err(e: impl std::fmt::Display) -> StereoError {
    StereoError::Render(e.to_string())
}

/// Writes a rendered pair and its ground truth into `dir` (which must exist); see the module
/// documentation for the files.
pub fn write_pair(
    dir: &Path,
    scene: &Scene,
    rig: &Rig,
    views: &[EyeView; 2],
    exposure_ev: f32,
) -> Result<(), StereoError> {
    let mut srgb = Vec::with_capacity(2);
    for (eye, view) in Eye::BOTH.into_iter().zip(views) {
        let name = eye.name();
        write_exr(&dir.join(format!("{name}.exr")), &view.output).map_err(output_err)?;
        let img = &view.output.image;
        write_png(&dir.join(format!("{name}.png")), img, exposure_ev).map_err(output_err)?;
        srgb.push(
            image::RgbImage::from_raw(img.width, img.height, to_srgb8(img, exposure_ev))
                .ok_or_else(|| output_err("image size does not match its pixels"))?,
        );
        write_pfm(&dir.join(format!("disparity_{name}.pfm")), &view.disparity)?;
        write_pfm(&dir.join(format!("depth_{name}.pfm")), &view.depth)?;
        view.streak_mask
            .save_png(&dir.join(format!("streak_mask_{name}.png")))?;
    }
    write_pair_views(dir, &srgb[0], &srgb[1])?;
    let road = rig.road_frame().ok();
    RigFile::new(rig, light_records(scene, road.as_ref())).save(&dir.join("rig.json"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Affine3A;
    use std::path::PathBuf;

    /// Writes a glTF scene: a camera at `camera` (looking along -Z, pitched by `pitch`
    /// radians), one quad (4 corners, with UVs) carrying `texture` as its baseColorTexture (or
    /// a plain grey), and a directional light shining along `light_dir`.
    fn write_scene(
        dir: &Path,
        camera: Vec3,
        pitch: f32,
        yfov: f32,
        corners: [Vec3; 4],
        texture: Option<&image::RgbImage>,
        light_dir: Vec3,
    ) -> PathBuf {
        let mut bin: Vec<u8> = Vec::new();
        for c in corners {
            for v in c.to_array() {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
        for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
            for v in uv {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        std::fs::write(dir.join("scene.bin"), &bin).unwrap();
        let (lo, hi) = corners.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(a, b), &c| (a.min(c), b.max(c)),
        );
        let mut material = serde_json::json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}});
        let mut extra = serde_json::json!({});
        if let Some(tex) = texture {
            tex.save(dir.join("texture.png")).unwrap();
            material["pbrMetallicRoughness"]["baseColorFactor"] =
                serde_json::json!([1.0, 1.0, 1.0, 1.0]);
            material["pbrMetallicRoughness"]["baseColorTexture"] = serde_json::json!({"index": 0});
            extra = serde_json::json!({
                "textures": [{"source": 0, "sampler": 0}],
                "images": [{"uri": "texture.png"}],
                "samplers": [{"magFilter": 9729, "minFilter": 9729}]
            });
        }
        // The light's node rotation: local -Z onto light_dir.
        let q = glam::Quat::from_rotation_arc(-Vec3::Z, light_dir.normalize());
        let cq = glam::Quat::from_rotation_x(pitch);
        let mut gltf = serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 3.0}]}},
            "scene": 0,
            "scenes": [{"nodes": [0, 1, 2]}],
            "nodes": [
                {"mesh": 0},
                {"camera": 0, "name": "cam", "translation": camera.to_array(), "rotation": cq.to_array()},
                {"rotation": q.to_array(), "extensions": {"KHR_lights_punctual": {"light": 0}}}
            ],
            "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.01, "aspectRatio": 4.0 / 3.0}}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
            "materials": [material],
            "buffers": [{"uri": "scene.bin", "byteLength": bin.len()}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 48},
                {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                {"buffer": 0, "byteOffset": 80, "byteLength": 12}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
            ]
        });
        if let serde_json::Value::Object(extra) = extra {
            for (k, v) in extra {
                gltf[k] = v;
            }
        }
        let path = dir.join("scene.gltf");
        std::fs::write(&path, serde_json::to_string_pretty(&gltf).unwrap()).unwrap();
        path
    }

    fn settings(spp: u32) -> PairSettings {
        PairSettings {
            spp,
            max_depth: 2,
            seed: 7,
            exposure_ev: 0.0,
            mask: StreakMaskParams::default(),
        }
    }

    #[test]
    fn road_plane_disparity_matches_the_analytic_plane() {
        let dir = tempfile::tempdir().unwrap();
        let h = 1.5f32;
        let road = [
            Vec3::new(-50.0, 0.0, 10.0),
            Vec3::new(50.0, 0.0, 10.0),
            Vec3::new(50.0, 0.0, -200.0),
            Vec3::new(-50.0, 0.0, -200.0),
        ];
        let path = write_scene(
            dir.path(),
            Vec3::new(0.0, h, 0.0),
            0.0,
            0.6,
            road,
            None,
            Vec3::new(0.0, -1.0, -0.2),
        );
        let scene = Scene::load(&path).unwrap();
        let cam = scene.camera(None).unwrap();
        let rig = rig_from_camera(cam, 64, 48, 0.065).unwrap();
        let views = render_pair(&scene, &rig, &settings(1), &|_| {}).unwrap();
        let f = rig.focal_px();
        let cy = 24.0;
        let mut checked = 0;
        for (eye, view) in Eye::BOTH.into_iter().zip(&views) {
            for y in 0..48 {
                for x in 0..64 {
                    let d = view.disparity.get(x, y);
                    let yc = y as f32 + 0.5 - cy;
                    if yc <= 0.0 {
                        assert!(d.is_infinite(), "{eye} sky ({x}, {y}): {d}");
                        continue;
                    }
                    // A level rig of height h sees the road at Z = f h / (y - cy): d = b (y - cy) / h.
                    let z = f * h / yc;
                    if z > 190.0 {
                        continue;
                    }
                    let expect = 0.065 * yc / h;
                    assert!(
                        (d - expect).abs() < 1e-4 * expect.max(1.0),
                        "{eye} ({x}, {y}): {d} vs {expect}"
                    );
                    assert!(view.road[y * 64 + x]);
                    checked += 1;
                }
            }
        }
        assert!(checked > 2000, "{checked}");
        // Write the whole pair and read a few files back.
        write_pair(dir.path(), &scene, &rig, &views, 0.0).unwrap();
        for name in [
            "left.exr",
            "right.exr",
            "left.png",
            "right.png",
            "side_by_side.png",
            "anaglyph.png",
            "disparity_left.pfm",
            "depth_left.pfm",
            "streak_mask_left.png",
            "streak_mask_right.png",
            "rig.json",
        ] {
            assert!(dir.path().join(name).exists(), "{name}");
        }
        let disp = crate::pfm::read_pfm(&dir.path().join("disparity_left.pfm")).unwrap();
        assert_eq!(disp, views[0].disparity);
        let file = RigFile::load(&dir.path().join("rig.json")).unwrap();
        assert_eq!(file.rig().unwrap().intrinsics(), rig.intrinsics());
        assert!(matches!(file.lights[0], LightRecord::Directional { .. }));
        let sbs = image::open(dir.path().join("side_by_side.png")).unwrap();
        assert_eq!((sbs.width(), sbs.height()), (128, 48));
    }

    /// Sub-pixel horizontal shift `d` with `right(x) = left(x + d)` over a region, by 1D
    /// Lucas-Kanade: Gauss-Newton on the sum of squared differences, the left image resampled
    /// with cubic (Catmull-Rom) interpolation along rows.
    fn lk_disparity(
        left: &GrayImage,
        right: &GrayImage,
        xs: std::ops::Range<usize>,
        ys: std::ops::Range<usize>,
        d0: f32,
    ) -> f32 {
        let sample = |row: usize, x: f32| -> (f32, f32) {
            let i = x.floor();
            let t = x - i;
            let p =
                |k: f32| left.get((i + k).clamp(0.0, (left.width - 1) as f32) as usize, row) as f64;
            let (p0, p1, p2, p3) = (p(-1.0), p(0.0), p(1.0), p(2.0));
            let t = t as f64;
            let v = p1
                + 0.5
                    * t
                    * (p2 - p0
                        + t * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3
                            + t * (3.0 * (p1 - p2) + p3 - p0)));
            let g = 0.5 * (p2 - p0)
                + t * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3)
                + 1.5 * t * t * (3.0 * (p1 - p2) + p3 - p0);
            (v as f32, g as f32)
        };
        let mut d = d0 as f64;
        for _ in 0..20 {
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for y in ys.clone() {
                for x in xs.clone() {
                    let (v, g) = sample(y, x as f32 + d as f32);
                    let r = (right.get(x, y) - v) as f64;
                    num += g as f64 * r;
                    den += (g as f64) * (g as f64);
                }
            }
            let step = num / den;
            d += step;
            if step.abs() < 1e-6 {
                break;
            }
        }
        d as f32
    }

    #[test]
    fn rendered_fronto_parallel_plane_has_disparity_f_b_over_z() {
        let dir = tempfile::tempdir().unwrap();
        // A smooth procedural texture: sinusoids with periods of 16-50 image pixels at 5 m.
        let n = 256u32;
        let tex = image::RgbImage::from_fn(n, n, |i, j| {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            let tau = std::f32::consts::TAU;
            let s = 0.5
                + 0.18 * (tau * 6.0 * u).sin()
                + 0.12 * (tau * 11.0 * u + 1.0).sin()
                + 0.08 * (tau * 17.0 * u + 2.0).sin()
                + 0.1 * (tau * 5.0 * v).sin();
            let g = (s.clamp(0.0, 1.0) * 255.0).round() as u8;
            image::Rgb([g, g, g])
        });
        let z = 5.0f32;
        let plane = [
            Vec3::new(-3.0, -3.0, -z),
            Vec3::new(3.0, -3.0, -z),
            Vec3::new(3.0, 3.0, -z),
            Vec3::new(-3.0, 3.0, -z),
        ];
        let path = write_scene(
            dir.path(),
            Vec3::ZERO,
            0.0,
            0.5,
            plane,
            Some(&tex),
            -Vec3::Z,
        );
        let scene = Scene::load(&path).unwrap();
        let rig = rig_from_camera(scene.camera(None).unwrap(), 160, 120, 0.065).unwrap();
        let views = render_pair(&scene, &rig, &settings(16), &|_| {}).unwrap();
        let expect = rig.disparity_px(z);
        // Ground truth first: the whole view sees the plane at depth Z.
        for v in &views {
            assert!(v
                .disparity
                .data
                .iter()
                .all(|&d| (d - expect).abs() < 1e-3 * expect));
        }
        let lum = |v: &EyeView| luminance_image(&v.output.image).unwrap();
        let (l, r) = (lum(&views[0]), lum(&views[1]));
        // right(x) = left(x + d): measured away from the borders.
        let d = lk_disparity(&l, &r, 16..144, 10..110, 0.0);
        assert!(
            (d - expect).abs() < 0.05,
            "measured {d} px, f b / Z = {expect} px"
        );
    }

    #[test]
    fn bad_inputs_are_errors() {
        let cam = Camera {
            name: "c".into(),
            world_from_camera: Affine3A::from_scale(Vec3::splat(2.0)),
            yfov: 0.5,
            aspect_ratio: None,
        };
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
        let rig = rig_from_camera(&cam, 64, 48, 0.065).unwrap();
        let eye = eye_camera(&rig, Eye::Right);
        assert!((eye.focal_px(48) - rig.focal_px()).abs() < 1e-3);
        let p = Vec3::new(0.3, -0.2, -4.0);
        let a = eye.project(p, 64, 48).unwrap();
        let b = rig.eye(Eye::Right).project(p).unwrap();
        assert!((a - b).length() < 1e-3, "{a} {b}");
    }
}
