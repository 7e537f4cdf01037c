//! Punctual lights (KHR_lights_punctual): point, spot and directional.
//!
//! Units: a [`Light`] is radiometric, its intensity in W/sr (point, spot) and its irradiance in
//! W/m^2 (directional), linear RGB. The glTF loader converts KHR_lights_punctual's photometric
//! units (candela, lux) with [`LUMINOUS_EFFICACY`], as Blender's glTF importer does (docs/design.md).
//!
//! `range` follows the specification's recommended window: the inverse-square law times
//! `clamp(1 - (d / range)^4, 0, 1)`, so that light fades smoothly to exactly zero at
//! `d = range` (an absent or zero range is infinite).
//!
//! Spot lights use the specification's falloff: with `c = cos(angle to the axis)`,
//! `t = clamp((c - cos_outer) / (cos_inner - cos_outer), 0, 1)` and the intensity is scaled by
//! `t * t`.
//!
//! A punctual light is a delta light: its sample needs no random numbers and is its whole
//! contribution (see [`super::LightSample`]).

use super::{LightSample, Visibility};
use glam::Vec3;
use std::f32::consts::PI;
use streaks_image::luminance;

/// Lumens per watt between KHR_lights_punctual's photometric units and the renderer's
/// radiometric ones: a point light of `I` candela has the radiant intensity `I / 683` W/sr, a
/// directional light of `E` lux the irradiance `E / 683` W/m^2. Blender's glTF importer divides
/// by the same number (`PBR_WATTS_TO_LUMENS`) and its exporter multiplies by it.
pub const LUMINOUS_EFFICACY: f32 = 683.0;

/// A punctual light source.
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

impl Light {
    /// The light as seen from `p`: the direction toward it, the incident irradiance on a
    /// surface facing it, and a shadow ray's length; `None` when it cannot illuminate `p`
    /// (outside the cone or the range, or at `p` itself). Always inlined: the light choice
    /// weighs every punctual emitter of a tree node by it.
    #[inline(always)]
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                intensity,
                range,
            } => toward(p, position, intensity, range, 1.0),
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
                toward(p, position, intensity, range, falloff)
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
                visibility: Visibility::ShadowRay,
            }),
        }
    }

    /// The light's position; `None` for a directional light.
    #[inline]
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(position),
            Light::Directional { .. } => None,
        }
    }

    /// Emitted power (luminance of the flux, W) used to choose lights: `4 pi I` for a point
    /// light, `2 pi (1 - (cos_inner + cos_outer)/2) I` for a spot (the cone's solid angle at
    /// the middle of the falloff), and `pi r^2 E` for a directional light over the scene's
    /// bounding sphere of radius `scene_radius`. Ranges are ignored.
    pub fn power(&self, scene_radius: f32) -> f32 {
        match *self {
            Light::Point { intensity, .. } => 4.0 * PI * luminance(intensity),
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * luminance(intensity),
            Light::Directional { irradiance, .. } => {
                PI * scene_radius * scene_radius * luminance(irradiance)
            }
        }
    }
}

/// A point or spot light at `position` seen from `p`.
#[inline]
fn toward(
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
        visibility: Visibility::ShadowRay,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let p = Vec3::new(1.0, 2.0, 3.0);
        let point = Light::Point {
            position: p + Vec3::new(0.0, 2.0, 0.0),
            intensity: Vec3::new(8.0, 4.0, 2.0),
            range: Some(4.0),
        };
        let ls = point.sample_li(p).unwrap();
        assert!(ls.delta && ls.pdf == 1.0 && (ls.wi - Vec3::Y).length() < 1e-6);
        assert_eq!(ls.dist, 2.0);
        let window = 1.0 - (0.5f32).powi(4);
        assert!((ls.li - Vec3::new(2.0, 1.0, 0.5) * window).length() < 1e-5);
        assert!(point.sample_li(p - Vec3::Y * 3.0).is_none());

        // A spot pointing down; points on its axis, at the middle of the falloff, outside.
        let spot = Light::Spot {
            position: Vec3::new(0.0, 4.0, 0.0),
            direction: -Vec3::Y,
            intensity: Vec3::splat(16.0),
            cos_inner: 0.9,
            cos_outer: 0.7,
            range: None,
        };
        let ls = spot.sample_li(Vec3::ZERO).unwrap();
        assert!((ls.li - Vec3::ONE).length() < 1e-6);
        let off = Vec3::new(0.6, 4.0 - 0.8, 0.0); // cos = 0.8 at distance 1
        let ls = spot.sample_li(off).unwrap();
        assert!(
            (ls.li - Vec3::splat(16.0 * 0.25)).length() < 1e-3,
            "{}",
            ls.li
        );
        assert!(spot.sample_li(Vec3::new(4.0, 4.0, 0.0)).is_none());

        let sun = Light::Directional {
            direction: Vec3::new(0.0, -1.0, 0.0),
            irradiance: Vec3::splat(3.0),
        };
        let ls = sun.sample_li(p).unwrap();
        assert!(ls.delta && ls.dist == f32::INFINITY && ls.wi == Vec3::Y);
        assert_eq!(sun.position(), None);
        assert_eq!(spot.position(), Some(Vec3::new(0.0, 4.0, 0.0)));
    }

    #[test]
    fn power_is_the_flux_used_to_choose_lights() {
        let point = Light::Point {
            position: Vec3::ZERO,
            intensity: Vec3::ONE,
            range: Some(1.0),
        };
        assert!((point.power(10.0) - 4.0 * PI).abs() < 1e-5);
        let sun = Light::Directional {
            direction: -Vec3::Y,
            irradiance: Vec3::splat(2.0),
        };
        assert!((sun.power(3.0) - PI * 9.0 * 2.0).abs() < 1e-4);
    }
}
