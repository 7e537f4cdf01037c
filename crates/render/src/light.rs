//! Lights: point, spot, directional, and emissive triangles as area lights; and the
//! [`LightSampler`] that picks one light per shading point for next-event estimation.
//!
//! Scene contract (DESIGN.md): for point and spot lights `color * intensity` is the radiant
//! intensity in W/sr (linear RGB, no photometric conversion); for directional lights it is the
//! irradiance; emissive triangles are area lights of radiance `emission`, one-sided (the front
//! face, by the triangle's winding) unless their material is double-sided.
//!
//! Conventions of [`Light::sample_li`] (pbrt's `SampleLi`): `wi` points from the shading point
//! toward the light, `li` is the radiance arriving along `-wi` and `pdf` is the solid-angle
//! density of `wi`. Delta lights (point, spot, directional) are flagged with `delta: true`,
//! their `pdf` is 1 and `li` is already the incident irradiance on a surface facing the light
//! (intensity / r^2, or the directional irradiance), so `f * li * cos / pdf` is the estimate
//! either way.
//!
//! `range` of punctual lights follows the KHR_lights_punctual specification's recommended
//! window: the inverse-square law times `clamp(1 - (d / range)^4, 0, 1)`, so that light fades
//! smoothly to exactly zero at `d = range` (an absent or zero range is infinite).
//!
//! Spot lights use the specification's falloff: with `c = cos(angle to the axis)`,
//! `t = clamp((c - cos_outer) / (cos_inner - cos_outer), 0, 1)` and the intensity is scaled by
//! `t * t`.
//!
//! Triangles are sampled uniformly by area and the density converted to solid angle,
//! `pdf = d^2 / (|cos theta_light| A)`.

use crate::sampling::{luminance, square_to_uniform_triangle, DiscreteDistribution};
use crate::scene::{Scene, SurfaceHit};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light.
    Point {
        /// World position.
        position: Vec3,
        /// Radiant intensity (W/sr), linear RGB.
        intensity: Vec3,
        /// glTF `range` (None = infinite).
        range: Option<f32>,
    },
    /// glTF spot light (smooth falloff between the inner and outer cone).
    Spot {
        /// World position.
        position: Vec3,
        /// Unit direction the spot points along (the node's local -Z), world space.
        direction: Vec3,
        /// Radiant intensity on the axis (W/sr).
        intensity: Vec3,
        /// cos(innerConeAngle).
        cos_inner: f32,
        /// cos(outerConeAngle).
        cos_outer: f32,
        /// glTF `range` (None = infinite).
        range: Option<f32>,
    },
    /// Directional light.
    Directional {
        /// Unit direction the light travels along (the node's local -Z), world space.
        direction: Vec3,
        /// Irradiance on a surface facing the light (W/m^2).
        irradiance: Vec3,
    },
    /// One emissive triangle of the scene; its radiance comes from its material.
    Triangle {
        /// Index into [`crate::scene::Scene::triangles`].
        triangle: u32,
    },
}

/// A sampled direction toward a light, see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Distance to the light point (`inf` for directional lights).
    pub dist: f32,
    /// Incident radiance (area lights) or irradiance (delta lights).
    pub li: Vec3,
    /// Solid-angle density of `wi` (1 for delta lights).
    pub pdf: f32,
    /// Whether the light is a delta light (not reachable by BSDF sampling: no MIS).
    pub delta: bool,
}

/// The KHR_lights_punctual range window `clamp(1 - (d/range)^4, 0, 1)`; 1 without a range.
#[inline]
pub fn range_window(dist: f32, range: Option<f32>) -> f32 {
    match range {
        Some(r) if r > 0.0 => {
            let x = dist / r;
            (1.0 - (x * x) * (x * x)).clamp(0.0, 1.0)
        }
        _ => 1.0,
    }
}

/// The KHR_lights_punctual spot falloff `t^2`, `t = clamp((c - cos_outer)/(cos_inner - cos_outer), 0, 1)`,
/// for `cos_angle` = cosine between the spot axis and the direction to the lit point.
#[inline]
pub fn spot_falloff(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let width = cos_inner - cos_outer;
    let t = if width > 1e-7 {
        ((cos_angle - cos_outer) / width).clamp(0.0, 1.0)
    } else if cos_angle >= cos_outer {
        1.0
    } else {
        0.0
    };
    t * t
}

/// Vertex positions of a triangle.
#[inline]
fn triangle_vertices(scene: &Scene, triangle: u32) -> [Vec3; 3] {
    let [a, b, c] = scene.triangles[triangle as usize];
    [
        scene.positions[a as usize],
        scene.positions[b as usize],
        scene.positions[c as usize],
    ]
}

/// Radiance emitted from `hit` toward `wo` (unit, pointing away from the surface): the
/// material's emission on the front face (by winding), on both faces if it is double-sided,
/// zero otherwise.
#[inline]
pub fn emitted_radiance(scene: &Scene, hit: &SurfaceHit, wo: Vec3) -> Vec3 {
    let material = &scene.materials[hit.material as usize];
    if !material.is_emissive() || (!material.double_sided && hit.ng.dot(wo) <= 0.0) {
        return Vec3::ZERO;
    }
    material.emission_at(hit.uv, &scene.textures)
}

impl Light {
    /// Whether the light is a delta light (point, spot, directional).
    #[inline]
    pub fn is_delta(&self) -> bool {
        !matches!(self, Light::Triangle { .. })
    }

    /// Samples a direction from `p` toward the light with the 2D sample `u`; `None` when the
    /// light cannot illuminate `p` (outside the cone or the range, back face, degenerate).
    pub fn sample_li(&self, scene: &Scene, p: Vec3, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                intensity,
                range,
            } => punctual(p, position, intensity, range, 1.0),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
                range,
            } => {
                let cos_angle = direction.dot((p - position).normalize_or_zero());
                let falloff = spot_falloff(cos_angle, cos_inner, cos_outer);
                punctual(p, position, intensity, range, falloff)
            }
            Light::Directional {
                direction,
                irradiance,
            } => Some(LightSample {
                wi: -direction,
                dist: f32::INFINITY,
                li: irradiance,
                pdf: 1.0,
                delta: true,
            }),
            Light::Triangle { triangle } => {
                let v = triangle_vertices(scene, triangle);
                let (n, area) = scene.triangle_normal_area(triangle);
                let b = square_to_uniform_triangle(u);
                let b0 = 1.0 - b.x - b.y;
                let q = b0 * v[0] + b.x * v[1] + b.y * v[2];
                let d = q - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                if area <= 0.0 || dist <= 0.0 {
                    return None;
                }
                let wi = d / dist;
                let cos_light = -n.dot(wi);
                let material =
                    &scene.materials[scene.triangle_materials[triangle as usize] as usize];
                if cos_light.abs() < 1e-7 || (!material.double_sided && cos_light <= 0.0) {
                    return None;
                }
                let [ia, ib, ic] = scene.triangles[triangle as usize];
                let uv = b0 * scene.uvs[ia as usize]
                    + b.x * scene.uvs[ib as usize]
                    + b.y * scene.uvs[ic as usize];
                let li = material.emission_at(uv, &scene.textures);
                let pdf = dist2 / (cos_light.abs() * area);
                (pdf.is_finite() && li.max_element() > 0.0).then_some(LightSample {
                    wi,
                    dist,
                    li,
                    pdf,
                    delta: false,
                })
            }
        }
    }

    /// The solid-angle density with which [`Light::sample_li`] from `p` would return the
    /// direction toward `hit`, a point on this light (area lights; 0 for delta lights).
    pub fn pdf_li(&self, scene: &Scene, p: Vec3, hit: &SurfaceHit) -> f32 {
        match *self {
            Light::Triangle { triangle } => {
                let (_, area) = scene.triangle_normal_area(triangle);
                let d = hit.p - p;
                let dist2 = d.length_squared();
                let cos_light = hit.ng.dot(d).abs() / dist2.sqrt();
                if area <= 0.0 || cos_light <= 0.0 {
                    return 0.0;
                }
                dist2 / (cos_light * area)
            }
            _ => 0.0,
        }
    }

    /// Emitted power (luminance of the flux, W) used to choose lights: `4 pi I` for a point
    /// light, `2 pi (1 - (cos_inner + cos_outer)/2) I` for a spot (the cone's solid angle at
    /// the middle of the falloff), `pi A L` per emitting face of a triangle, and
    /// `pi r^2 E` for a directional light over the scene's bounding sphere of radius `r`.
    /// Ranges are ignored. A textured emitter counts with its untextured factor.
    pub fn power(&self, scene: &Scene) -> f32 {
        match *self {
            Light::Point { intensity, .. } => 4.0 * PI * luminance(intensity),
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * luminance(intensity),
            Light::Directional { irradiance, .. } => {
                let (_, r) = scene.bounding_sphere();
                PI * r * r * luminance(irradiance)
            }
            Light::Triangle { triangle } => {
                let (_, area) = scene.triangle_normal_area(triangle);
                let material =
                    &scene.materials[scene.triangle_materials[triangle as usize] as usize];
                let sides = if material.double_sided { 2.0 } else { 1.0 };
                sides * PI * area * luminance(material.emission)
            }
        }
    }
}

/// A point or spot light at `position` seen from `p`.
#[inline]
fn punctual(
    p: Vec3,
    position: Vec3,
    intensity: Vec3,
    range: Option<f32>,
    falloff: f32,
) -> Option<LightSample> {
    let d = position - p;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    let scale = falloff * range_window(dist, range);
    if dist <= 0.0 || scale <= 0.0 {
        return None;
    }
    Some(LightSample {
        wi: d / dist,
        dist,
        li: intensity * (scale / dist2),
        pdf: 1.0,
        delta: true,
    })
}

/// Chooses the light for next-event estimation.
///
/// Strategy: proportional to each light's [`Light::power`] (pbrt's `PowerLightSampler`). A
/// street has a few bright lamps and many dim emissive triangles (windows, signs); choosing
/// by power spends the shadow rays where the light is, while uniform choice would waste most
/// of them on dim emitters. The choice ignores the shading point today; [`LightSampler::sample`]
/// and [`LightSampler::pmf`] take it anyway so that a spatial strategy (a light BVH or
/// per-region distributions) can replace this one without touching the integrator.
#[derive(Clone, Debug)]
pub struct LightSampler {
    /// Power distribution over `scene.lights` (`None`: no light emits).
    distribution: Option<DiscreteDistribution>,
    /// For each scene triangle, the index of its `Light::Triangle` (`u32::MAX`: none).
    light_of_triangle: Vec<u32>,
}

impl LightSampler {
    /// Builds the power distribution of `scene.lights`.
    pub fn new(scene: &Scene) -> Self {
        let powers: Vec<f32> = scene
            .lights
            .iter()
            .map(|l| {
                let p = l.power(scene);
                if p.is_finite() {
                    p.max(0.0)
                } else {
                    0.0
                }
            })
            .collect();
        let mut light_of_triangle = vec![u32::MAX; scene.triangles.len()];
        for (i, light) in scene.lights.iter().enumerate() {
            if let Light::Triangle { triangle } = *light {
                light_of_triangle[triangle as usize] = i as u32;
            }
        }
        Self {
            distribution: DiscreteDistribution::new(&powers),
            light_of_triangle,
        }
    }

    /// Picks a light for shading point `p` with `u` in [0, 1): `(light index, probability)`;
    /// `None` when the scene has no light with positive power.
    #[inline]
    pub fn sample(&self, p: Vec3, u: f32) -> Option<(usize, f32)> {
        let _ = p;
        let (i, pmf) = self.distribution.as_ref()?.sample(u);
        (pmf > 0.0).then_some((i, pmf))
    }

    /// The probability that [`LightSampler::sample`] at `p` picks light `light`.
    #[inline]
    pub fn pmf(&self, p: Vec3, light: usize) -> f32 {
        let _ = p;
        self.distribution.as_ref().map_or(0.0, |d| d.pmf(light))
    }

    /// The light index of emissive triangle `triangle`, if it is one.
    #[inline]
    pub fn light_of_triangle(&self, triangle: u32) -> Option<usize> {
        match self.light_of_triangle.get(triangle as usize) {
            Some(&i) if i != u32::MAX => Some(i as usize),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::scene::SceneParts;

    /// A one-sided (or double-sided) emissive triangle plus a diffuse floor far away, and the
    /// given punctual lights.
    fn scene(double_sided: bool, lights: Vec<Light>) -> Scene {
        let mut emitter = Material::diffuse("lamp", Vec3::ZERO);
        emitter.emission = Vec3::new(2.0, 1.0, 0.5);
        emitter.double_sided = double_sided;
        Scene::from_parts(SceneParts {
            source: "test".into(),
            // Triangle in the plane z = 1 facing -Z (toward the origin), and a floor.
            positions: vec![
                Vec3::new(-0.5, -0.3, 1.0),
                Vec3::new(0.2, 0.6, 1.0),
                Vec3::new(0.7, -0.4, 1.0),
                Vec3::new(-10.0, -5.0, -10.0),
                Vec3::new(10.0, -5.0, -10.0),
                Vec3::new(0.0, -5.0, 10.0),
            ],
            triangles: vec![[0, 1, 2], [3, 5, 4]],
            triangle_materials: vec![0, 1],
            materials: vec![emitter, Material::diffuse("floor", Vec3::splat(0.5))],
            lights,
            ..Default::default()
        })
        .unwrap()
    }

    fn triangle_light(scene: &Scene) -> Light {
        *scene
            .lights
            .iter()
            .find(|l| matches!(l, Light::Triangle { .. }))
            .unwrap()
    }

    /// Solid angle of a triangle seen from the origin (Van Oosterom and Strackee 1983).
    fn solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f32 {
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c)).abs();
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * num.atan2(den)
    }

    #[test]
    fn spot_falloff_follows_the_gltf_spec() {
        let (ci, co) = (0.9f32, 0.7f32);
        assert_eq!(spot_falloff(1.0, ci, co), 1.0);
        assert_eq!(spot_falloff(0.9, ci, co), 1.0);
        assert!((spot_falloff(0.8, ci, co) - 0.25).abs() < 1e-5);
        assert!((spot_falloff(0.75, ci, co) - 0.0625).abs() < 1e-5);
        assert_eq!(spot_falloff(0.7, ci, co), 0.0);
        assert_eq!(spot_falloff(-1.0, ci, co), 0.0);
        // Equal cones: a hard edge.
        assert_eq!(spot_falloff(0.81, 0.8, 0.8), 1.0);
        assert_eq!(spot_falloff(0.79, 0.8, 0.8), 0.0);
    }

    #[test]
    fn range_window_is_the_recommended_one() {
        assert_eq!(range_window(3.0, None), 1.0);
        assert_eq!(range_window(3.0, Some(0.0)), 1.0);
        assert_eq!(range_window(0.0, Some(2.0)), 1.0);
        assert!((range_window(1.0, Some(2.0)) - (1.0 - 1.0 / 16.0)).abs() < 1e-6);
        assert_eq!(range_window(2.0, Some(2.0)), 0.0);
        assert_eq!(range_window(5.0, Some(2.0)), 0.0);
    }

    #[test]
    fn punctual_lights_give_intensity_over_r2() {
        let s = scene(false, vec![]);
        let p = Vec3::new(1.0, 2.0, 3.0);
        let point = Light::Point {
            position: p + Vec3::new(0.0, 2.0, 0.0),
            intensity: Vec3::new(8.0, 4.0, 2.0),
            range: Some(4.0),
        };
        let ls = point.sample_li(&s, p, Vec2::new(0.3, 0.7)).unwrap();
        assert!(ls.delta && ls.pdf == 1.0 && (ls.wi - Vec3::Y).length() < 1e-6);
        assert_eq!(ls.dist, 2.0);
        let window = 1.0 - (0.5f32).powi(4);
        assert!((ls.li - Vec3::new(2.0, 1.0, 0.5) * window).length() < 1e-5);
        assert!(point.sample_li(&s, p - Vec3::Y * 3.0, Vec2::ZERO).is_none());

        // A spot pointing down; points on its axis, at the middle of the falloff, outside.
        let spot = Light::Spot {
            position: Vec3::new(0.0, 4.0, 0.0),
            direction: -Vec3::Y,
            intensity: Vec3::splat(16.0),
            cos_inner: 0.9,
            cos_outer: 0.7,
            range: None,
        };
        let ls = spot.sample_li(&s, Vec3::ZERO, Vec2::ZERO).unwrap();
        assert!((ls.li - Vec3::ONE).length() < 1e-6);
        let off = Vec3::new(0.6, 4.0 - 0.8, 0.0); // cos = 0.8 at distance 1
        let ls = spot.sample_li(&s, off, Vec2::ZERO).unwrap();
        assert!(
            (ls.li - Vec3::splat(16.0 * 0.25)).length() < 1e-3,
            "{}",
            ls.li
        );
        assert!(spot
            .sample_li(&s, Vec3::new(4.0, 4.0, 0.0), Vec2::ZERO)
            .is_none());

        let sun = Light::Directional {
            direction: Vec3::new(0.0, -1.0, 0.0),
            irradiance: Vec3::splat(3.0),
        };
        let ls = sun.sample_li(&s, p, Vec2::ZERO).unwrap();
        assert!(ls.delta && ls.dist == f32::INFINITY && ls.wi == Vec3::Y);
    }

    #[test]
    fn triangle_sampling_density_matches_solid_angle_and_pdf_li() {
        let s = scene(false, vec![]);
        let light = triangle_light(&s);
        let [a, b, c] = s.triangles[0].map(|v| s.positions[v as usize]);
        let p = Vec3::new(0.1, -0.2, -0.5);
        let omega = solid_angle(a - p, b - p, c - p);
        // E[1 / pdf] over the sampled directions is the solid angle.
        let n = 64;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let ls = light.sample_li(&s, p, u).unwrap();
                assert!(!ls.delta);
                assert_eq!(ls.li, Vec3::new(2.0, 1.0, 0.5));
                sum += 1.0 / ls.pdf as f64;
                // pdf_li at the sampled point agrees with the sample's pdf.
                let q = p + ls.wi * ls.dist;
                let hit = SurfaceHit {
                    t: ls.dist,
                    p: q,
                    ng: -Vec3::Z,
                    ns: -Vec3::Z,
                    uv: Vec2::ZERO,
                    triangle: 0,
                    material: 0,
                };
                let pdf = light.pdf_li(&s, p, &hit);
                assert!((pdf - ls.pdf).abs() <= 1e-4 * ls.pdf, "{pdf} {}", ls.pdf);
            }
        }
        let estimate = sum / (n * n) as f64;
        assert!(
            (estimate - omega as f64).abs() < 2e-3 * omega as f64,
            "{estimate} vs {omega}"
        );
        // Emission is one-sided: nothing from behind, unless double-sided.
        let behind = Vec3::new(0.1, 0.0, 2.0);
        assert!(light.sample_li(&s, behind, Vec2::splat(0.3)).is_none());
        let s2 = scene(true, vec![]);
        let ls = triangle_light(&s2).sample_li(&s2, behind, Vec2::splat(0.3));
        assert!(ls.is_some_and(|ls| ls.wi.z < 0.0));
    }

    #[test]
    fn emitted_radiance_is_one_sided_unless_double_sided() {
        for double_sided in [false, true] {
            let s = scene(double_sided, vec![]);
            let hit = s
                .intersect(&crate::geometry::Ray::new(Vec3::ZERO, Vec3::Z))
                .unwrap();
            assert_eq!(
                emitted_radiance(&s, &hit, -Vec3::Z),
                Vec3::new(2.0, 1.0, 0.5)
            );
            let back = emitted_radiance(&s, &hit, Vec3::Z);
            assert_eq!(back != Vec3::ZERO, double_sided);
        }
    }

    #[test]
    fn selection_pmf_is_proportional_to_power() {
        let point = Light::Point {
            position: Vec3::ZERO,
            intensity: Vec3::splat(2.0),
            range: None,
        };
        let spot = Light::Spot {
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            intensity: Vec3::splat(30.0),
            cos_inner: 0.9,
            cos_outer: 0.8,
            range: Some(3.0),
        };
        let sun = Light::Directional {
            direction: -Vec3::Y,
            irradiance: Vec3::splat(0.01),
        };
        let dark = Light::Point {
            position: Vec3::ZERO,
            intensity: Vec3::ZERO,
            range: None,
        };
        let s = scene(false, vec![point, spot, sun, dark]);
        let (_, r) = s.bounding_sphere();
        let (_, area) = s.triangle_normal_area(0);
        let expected = [
            4.0 * PI * 2.0,
            2.0 * PI * (1.0 - 0.85) * 30.0,
            PI * r * r * 0.01,
            0.0,
            PI * area * luminance(Vec3::new(2.0, 1.0, 0.5)),
        ];
        assert_eq!(s.lights.len(), expected.len());
        let total: f32 = expected.iter().sum();
        let sampler = LightSampler::new(&s);
        for (i, e) in expected.iter().enumerate() {
            assert!(
                (sampler.pmf(Vec3::ZERO, i) - e / total).abs() < 1e-5,
                "light {i}"
            );
        }
        // Sampling frequencies follow the pmf; the dark light is never chosen.
        let n = 10_000;
        let mut counts = [0usize; 5];
        for k in 0..n {
            let (i, pmf) = sampler
                .sample(Vec3::ZERO, (k as f32 + 0.5) / n as f32)
                .unwrap();
            assert_eq!(pmf, sampler.pmf(Vec3::ZERO, i));
            counts[i] += 1;
        }
        for (i, e) in expected.iter().enumerate() {
            assert!(
                (counts[i] as f32 / n as f32 - e / total).abs() < 2e-3,
                "light {i}"
            );
        }
        assert_eq!(sampler.light_of_triangle(0), Some(4));
        assert_eq!(sampler.light_of_triangle(1), None);
    }

    #[test]
    fn no_lights_no_samples() {
        let mut s = scene(false, vec![]);
        s.lights.clear();
        assert!(LightSampler::new(&s).sample(Vec3::ZERO, 0.5).is_none());
    }
}
