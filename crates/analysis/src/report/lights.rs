//! Which scene light makes a streak ([`match_light`]): the one whose mirror image lies on the
//! streak's axis and would make the strongest streak.

use super::input::RigView;
use crate::detect::Streak;
use glam::DVec3;
use serde::Serialize;
use streaks_image::luminance;
use streaks_stereo::rigfile::LightRecord;

/// The light a streak was matched to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MatchedLight {
    /// Index into rig.json's lights.
    pub index: usize,
    /// Its kind (`point`, `spot`, `emissive`).
    pub kind: String,
    /// Position in the road frame (metres).
    pub road: [f64; 3],
    /// Where its mirror image projects in the left image.
    pub mirror_px: [f64; 2],
    /// Horizontal distance from the streak's axis at the mirror image's row, pixels.
    pub distance_px: f64,
}

/// A light's kind, road-frame position and strength (radiant intensity, luminance; an emissive
/// group's radiance times its area).
fn light_position(light: &LightRecord) -> Option<(&'static str, [f32; 3], f64)> {
    let lum = |c: [f32; 3]| luminance(c.into()) as f64;
    match light {
        LightRecord::Point {
            position,
            intensity,
            ..
        } => position.road.map(|p| ("point", p, lum(*intensity))),
        LightRecord::Spot {
            position,
            intensity,
            ..
        } => position.road.map(|p| ("spot", p, lum(*intensity))),
        LightRecord::Emissive {
            centroid,
            radiance,
            area,
            ..
        } => centroid
            .road
            .map(|p| ("emissive", p, lum(*radiance) * *area as f64)),
        LightRecord::Directional { .. } => None,
    }
}

/// The light that makes a streak: among the lights whose mirror image `(X, -Y, Z)` projects
/// within `tolerance` pixels of the streak's axis (at the mirror image's row, or the streak's
/// first row if the mirror image is above it), whose own image is above the streak's first
/// row and whose mirror image is not below its last row, the one with the strongest predicted
/// streak: strength over the squared distance from the camera to the mirror image (a faint
/// light that happens to line up does not win over the lamp that makes the streak).
pub(super) fn match_light(
    streak: &Streak,
    lights: &[LightRecord],
    view: &RigView,
    tolerance: f32,
) -> Option<MatchedLight> {
    let cam = &view.camera;
    let mut best: Option<(f64, MatchedLight)> = None;
    for (index, light) in lights.iter().enumerate() {
        let Some((kind, p, strength)) = light_position(light) else {
            continue;
        };
        let p = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        if p.y <= 0.0 || p.z <= 0.0 {
            continue;
        }
        let virt = DVec3::new(p.x, -p.y, p.z);
        let Some(mirror) = cam.project(virt) else {
            continue;
        };
        let Some(lamp) = cam.project(p) else { continue };
        // The streak hangs below the light: its first row is below the light's image, and the
        // mirror image is not below the streak's last row.
        if lamp.y > streak.first_row as f64 + 0.5 || mirror.y > streak.last_row as f64 + 4.0 {
            continue;
        }
        // Left-image x: the cyclopean x plus half the disparity of the virtual light.
        let half = 0.5 * cam.disparity_px(virt);
        let row = mirror.y.max(streak.first_row as f64);
        let axis = streak.axis_a as f64 + streak.axis_b as f64 * row;
        let distance = (axis - (mirror.x + half)).abs();
        let predicted = strength / (virt - cam.centre()).length_squared();
        if distance <= tolerance as f64 && best.as_ref().is_none_or(|b| predicted > b.0) {
            best = Some((
                predicted,
                MatchedLight {
                    index,
                    kind: kind.into(),
                    road: p.to_array(),
                    mirror_px: [mirror.x + half, mirror.y],
                    distance_px: distance,
                },
            ));
        }
    }
    best.map(|b| b.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Vec3};
    use streaks_stereo::rig::{Intrinsics, Rig};

    #[test]
    fn streaks_are_matched_to_the_light_whose_mirror_image_is_on_their_axis() {
        let rig = Rig::new(
            Intrinsics::new(320, 240, 300.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let view = RigView::new(&rig).unwrap();
        let road = rig.road_frame().unwrap();
        let light_i = |x: f32, y: f32, z: f32, i: f32| LightRecord::Point {
            // World -Z is road +Z for a rig looking along -Z.
            position: streaks_stereo::rigfile::Placed::point(Vec3::new(x, y, -z), Some(&road)),
            intensity: [i; 3],
            range: None,
        };
        let light = |x: f32, y: f32, z: f32| light_i(x, y, z, 1.0);
        let lights = vec![light(-3.0, 5.0, 30.0), light(1.0, 4.0, 20.0)];
        // The second light's mirror image (1, -4, 20) seen from (0, 1.5, 0): x = 160 + 15,
        // y = 120 + 300 * 5.5 / 20 = 202.5. A vertical streak through it.
        let streak = Streak {
            first_row: 150,
            last_row: 220,
            centres: (150..=220).map(|y| (y, 175.5)).collect(),
            axis_a: 175.5,
            axis_b: 0.0,
            peak: 1.0,
            elongation: 10.0,
            pixels: 500,
        };
        let m = match_light(&streak, &lights, &view, 4.0).expect("matched");
        assert_eq!(m.index, 1);
        assert!(m.distance_px < 1.5, "{m:?}");
        assert!((m.mirror_px[1] - 202.5).abs() < 1e-3);
        // A second light in the same column farther away (mirror image at x 175, y 175): the
        // one with the stronger predicted streak wins, whichever lines up more closely.
        for (i, want) in [(0.01f32, 1usize), (100.0, 2)] {
            let mut lights = lights.clone();
            lights.push(light_i(1.5, 4.0, 30.0, i));
            let m = match_light(&streak, &lights, &view, 4.0).expect("matched");
            assert_eq!(m.index, want, "intensity {i}: {m:?}");
        }
        // Too far from every axis: no match.
        let off = Streak {
            axis_a: 260.0,
            ..streak
        };
        assert!(match_light(&off, &lights, &view, 4.0).is_none());
    }
}
