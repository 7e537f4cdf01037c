//! A drive along a street: where the stereo rig and the moving cars are at a time.
//!
//! Frame `k` of a street's sequence is at time `k / fps` seconds ([`frame_time`]). The rig
//! follows its lane at a constant speed with a fixed mounting (height, pitch, roll:
//! [`Drive`]); leading and oncoming cars follow theirs at their own speeds; parked cars stay.
//! Every pose is a rigid `world_from_local` transform: the rig's local frame looks along -Z
//! with +Y up (the glTF camera's), a car's is its model frame (+X right, +Y up, -Z forward,
//! the origin on the ground at the centre of its footprint, see [`crate::model`]).
//!
//! Each pose is one call to the road's frame function, [`Road::pose`]: the pose of a frame
//! standing on the road's surface at a lateral offset and a distance along the road, so that
//! the rig and the cars follow its curves, climb its grades and lean with its cross-fall.

use crate::gltf_writer::{Light, LightKind};
use crate::model::transformed_light;
use crate::road::Road;
use crate::street::Car;
use glam::{Affine3A, Mat3, Vec3};

/// The rig's mounting on its vehicle: height of the rig centre above the road, pitch below the
/// horizon and roll (positive: the camera's right side down), as the local pose of the rig in
/// the road frame of its lane ([`Road::pose`]).
pub fn mount(height: f32, pitch_rad: f32, roll_rad: f32) -> Affine3A {
    let rotation = Mat3::from_rotation_x(-pitch_rad) * Mat3::from_rotation_z(-roll_rad);
    Affine3A::from_mat3_translation(rotation, Vec3::new(0.0, height, 0.0))
}

/// The rig's drive: its lateral position (lane centre plus offset), its mounting, and its
/// speed along the lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Metres right of the road's centre line.
    pub lateral: f32,
    /// Where the rig is along the road at time 0, metres.
    pub start: f64,
    /// The rig in its lane's road frame ([`mount`]).
    pub mount: Affine3A,
    /// Speed along the lane, m/s.
    pub speed_m_s: f64,
}

/// The time of frame `frame` at `fps` frames per second, seconds.
pub fn frame_time(frame: u64, fps: f64) -> f64 {
    frame as f64 / fps
}

/// The rig centre's world pose at `time` (seconds): looking along its local -Z, +Y up.
pub fn rig_pose_at(road: &Road, drive: &Drive, time: f64) -> Affine3A {
    road.pose(drive.lateral, drive.start + drive.speed_m_s * time, false) * drive.mount
}

/// The rig vehicle's dipped headlights at `time`: two spot lights 1.4 m apart, 1.8 m ahead of
/// the rig and at about half its height (0.6 m on a car, up to 1.2 m on a truck), aimed 3
/// degrees down its lane with a 20 degree cone, named `ego_headlight_0` and `_1`. What they
/// light most is the road just ahead, seen from behind them: the wet asphalt's mirror sends
/// their light away from the camera, and bead paint sends it back.
pub fn ego_headlights(
    road: &Road,
    drive: &Drive,
    time: f64,
    color: [f64; 3],
    intensity: f64,
) -> [Light; 2] {
    let lane = road.pose(drive.lateral, drive.start + drive.speed_m_s * time, false);
    let height = (0.5 * drive.mount.translation.y).clamp(0.6, 1.2);
    std::array::from_fn(|j| {
        let side = if j == 0 { -0.7 } else { 0.7 };
        transformed_light(
            &Light {
                name: format!("ego_headlight_{j}"),
                kind: LightKind::Spot {
                    inner: 0.12,
                    outer: 0.35,
                },
                color,
                intensity,
                position: Vec3::new(side, height, -1.8),
                direction: Vec3::new(0.0, -0.052, -1.0).normalize(),
            },
            lane,
        )
    })
}

/// The rig's velocity in world space at `time`, m/s: its speed along the lane's direction.
pub fn rig_velocity_at(road: &Road, drive: &Drive, time: f64) -> Vec3 {
    let lane = road.pose(drive.lateral, drive.start + drive.speed_m_s * time, false);
    lane.transform_vector3(Vec3::NEG_Z) * drive.speed_m_s as f32
}

/// Where along the road (straight frame Z, as [`Car::z`]) a car is at `time` (seconds) when it
/// drives at `speed_m_s` along its lane from where `car` puts it at time 0 (a parked car stays
/// there).
pub fn car_z_at(car: &Car, speed_m_s: f64, time: f64) -> f32 {
    let moved = if car.parked { 0.0 } else { speed_m_s * time };
    let direction = if car.oncoming { -1.0 } else { 1.0 };
    -(f64::from(-car.z) + direction * moved) as f32
}

/// A car's world pose: its model frame on the road at its lane offset [`Car::x`] and
/// straight-frame [`Car::z`], facing its direction of travel. The street draws it there.
pub fn car_pose(road: &Road, car: &Car) -> Affine3A {
    road.pose(car.x, f64::from(-car.z), car.oncoming)
}

/// The bounds of a generated car in its model frame, metres (body, cabin, the wheels 2 cm
/// proud of the body's sides and the lamp lenses 2 mm proud of its ends).
pub const CAR_BOUNDS: [Vec3; 2] = [Vec3::new(-0.92, 0.0, -2.21), Vec3::new(0.92, 1.45, 2.21)];

/// An object that moves during a drive: its instance id (the `extras.streaks.instance` of its
/// nodes), its world pose at the frame's time and its bounds in its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovingObject {
    /// The object's instance id (> 0).
    pub instance: u32,
    /// Its world pose at the frame's time.
    pub world_from_object: Affine3A,
    /// Its bounds in its own frame (min, max).
    pub bounds: [Vec3; 2],
}

impl MovingObject {
    /// Whether the world point `p` lies on this object: within its bounds (grown by 1 cm) and
    /// above the ground it stands on (1 mm up, so that the road under it is not counted).
    pub fn contains(&self, p: Vec3) -> bool {
        let q = self.world_from_object.inverse().transform_point3(p);
        let grow = Vec3::splat(0.01);
        q.cmpge(self.bounds[0] - grow).all()
            && q.cmple(self.bounds[1] + grow).all()
            && q.y > self.bounds[0].y + 1e-3
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    /// A rig at speed v covers v / fps per frame along -Z, at its mounting height, looking
    /// down by the pitch with its right side lowered by the roll.
    #[test]
    fn the_rig_drives_along_its_lane_at_its_mounting() {
        let (pitch, roll) = (3f32.to_radians(), 1.5f32.to_radians());
        let drive = Drive {
            lateral: 1.7,
            start: 2.0,
            mount: mount(1.3, pitch, roll),
            speed_m_s: 12.5,
        };
        let t = frame_time(3, 10.0);
        assert!((t - 0.3).abs() < 1e-12);
        let road = Road::straight();
        let pose = rig_pose_at(&road, &drive, t);
        let expected_z = -(2.0 + 12.5 * 0.3) as f32;
        assert!(close(
            pose.translation.into(),
            Vec3::new(1.7, 1.3, expected_z)
        ));
        let forward = pose.transform_vector3(Vec3::NEG_Z);
        assert!(close(forward, Vec3::new(0.0, -pitch.sin(), -pitch.cos())));
        // Rolled about the view direction, then pitched about the level right axis: the right
        // axis is R_x(-p) (cos r, -sin r, 0).
        let right = pose.transform_vector3(Vec3::X);
        let expected = Vec3::new(
            roll.cos(),
            -roll.sin() * pitch.cos(),
            roll.sin() * pitch.sin(),
        );
        assert!(right.dot(forward).abs() < 1e-6);
        assert!(close(right, expected), "{right} vs {expected}");
        assert!(close(
            rig_velocity_at(&road, &drive, t),
            Vec3::new(0.0, 0.0, -12.5)
        ));
    }

    /// Leading cars move away along -Z, oncoming ones towards +Z facing the rig, parked ones
    /// stay; an oncoming car's model -Z (its front) points along world +Z.
    #[test]
    fn cars_follow_their_lanes() {
        let car = |oncoming, parked| Car {
            x: -2.0,
            z: -30.0,
            oncoming,
            color: [0.5; 3],
            headlights: true,
            parked,
        };
        let road = Road::straight();
        let pose_at = |c: &Car| {
            let moved = Car {
                z: car_z_at(c, 10.0, 0.5),
                ..*c
            };
            car_pose(&road, &moved)
        };
        let at = |c: &Car| Vec3::from(pose_at(c).translation);
        assert!(close(at(&car(false, false)), Vec3::new(-2.0, 0.0, -35.0)));
        assert!(close(at(&car(true, false)), Vec3::new(-2.0, 0.0, -25.0)));
        assert!(close(at(&car(true, true)), Vec3::new(-2.0, 0.0, -30.0)));
        let front = pose_at(&car(true, false)).transform_vector3(Vec3::NEG_Z);
        assert!(close(front, Vec3::Z));
    }

    /// The rig's headlights ride with it: ahead of the camera, below it, either side of its
    /// lane, aimed down the lane at the road a few tens of metres ahead; on a truck higher.
    #[test]
    fn ego_headlights_ride_with_the_rig() {
        let road = Road::straight();
        let drive = Drive {
            lateral: 1.5,
            start: 0.0,
            mount: mount(1.3, 0.02, 0.0),
            speed_m_s: 10.0,
        };
        let lights = ego_headlights(&road, &drive, 0.5, [1.0; 3], 2000.0);
        let eye = Vec3::from(rig_pose_at(&road, &drive, 0.5).translation);
        for (j, l) in lights.iter().enumerate() {
            assert_eq!(l.name, format!("ego_headlight_{j}"));
            let d = l.position - eye;
            assert!(
                (d.z + 1.8).abs() < 1e-5 && (d.x.abs() - 0.7).abs() < 1e-5,
                "{d}"
            );
            assert!((l.position.y - 0.65).abs() < 1e-5, "{}", l.position);
            // The beam's axis meets the road 12.5 m ahead of the lamps.
            let t = l.position.y / -l.direction.y;
            let ground = l.position + t * l.direction;
            assert!((ground.z - (l.position.z - 12.5)).abs() < 0.1, "{ground}");
            assert!((ground.x - l.position.x).abs() < 1e-5);
        }
        assert!(lights[0].position.x < lights[1].position.x);
        let truck = Drive {
            mount: mount(2.8, 0.02, 0.0),
            ..drive
        };
        let high = ego_headlights(&road, &truck, 0.5, [1.0; 3], 2000.0);
        assert!((high[0].position.y - 1.2).abs() < 1e-5);
    }

    /// A point on a moving car is on it, the road below it and a point beside it are not.
    #[test]
    fn a_moving_object_contains_its_points_only() {
        let o = MovingObject {
            instance: 3,
            world_from_object: Road::straight().pose(2.0, 20.0, true),
            bounds: CAR_BOUNDS,
        };
        assert!(o.contains(Vec3::new(2.5, 0.8, -21.5)));
        assert!(!o.contains(Vec3::new(2.5, 0.0, -21.5)));
        assert!(!o.contains(Vec3::new(3.5, 0.8, -21.5)));
        assert!(!o.contains(Vec3::new(2.5, 0.8, -23.0)));
    }
}
