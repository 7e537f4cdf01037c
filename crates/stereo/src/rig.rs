//! The rectified stereo rig of DESIGN.md: two pinhole eyes with parallel axes.
//!
//! Conventions (all from DESIGN.md):
//! - World: right-handed, +Y up, metres; the road is the plane Y = 0.
//! - An eye looks along its local -Z with local +Y up and local +X to its right (glTF).
//! - Pixels: x right, y down; pixel (i, j) has its centre at (i + 0.5, j + 0.5); the principal
//!   point is the image centre (W/2, H/2); `f` is the focal length in pixels.
//! - The rig centre is the chosen camera. The left eye is at -b/2, the right eye at +b/2 along
//!   the rig's local +X; both have the rig's orientation and intrinsics.
//! - Disparity `d = x_left - x_right = f b / Z` pixels (Eq. 5), `Z` the depth along the optical
//!   axis (not the distance along the ray), positive in front of the rig.
//! - Road frame (the paper's): origin on the road below the rig centre, +Y up, +Z the camera's
//!   forward direction projected onto the road, +X to the camera's right. With Y up and Z
//!   forward, X to the right makes this frame **left-handed**: `road_from_world` is a rotation
//!   composed with a reflection (determinant -1). For a level camera the road frame's (X, Y, Z)
//!   are the eye's camera-space (x, y, -z) shifted down by the rig height.

use crate::error::StereoError;
use glam::{Affine3A, Vec2, Vec3};
use std::fmt;
use std::str::FromStr;

/// Pinhole intrinsics shared by both eyes; the principal point is the image centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    width: u32,
    height: u32,
    focal_px: f32,
}

impl Intrinsics {
    /// Intrinsics from an image size and a focal length in pixels; an error for a zero or
    /// overflowing (more than 2^31 pixels) size or a focal length that is not positive and finite.
    pub fn new(width: u32, height: u32, focal_px: f32) -> Result<Self, StereoError> {
        if width == 0 || height == 0 {
            return Err(StereoError::Intrinsics(format!(
                "image size {width}x{height} has a zero side"
            )));
        }
        if (width as u64) * (height as u64) > 1u64 << 31 {
            return Err(StereoError::Intrinsics(format!(
                "image size {width}x{height} has more than 2^31 pixels"
            )));
        }
        if !(focal_px.is_finite() && focal_px > 0.0) {
            return Err(StereoError::Intrinsics(format!(
                "focal length {focal_px} px must be positive and finite"
            )));
        }
        Ok(Self {
            width,
            height,
            focal_px,
        })
    }

    /// Intrinsics from a vertical field of view in radians (glTF `yfov`):
    /// `f = (H/2) / tan(yfov/2)`; `yfov` must lie in (0, pi).
    pub fn from_yfov(width: u32, height: u32, yfov: f32) -> Result<Self, StereoError> {
        if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
            return Err(StereoError::Intrinsics(format!(
                "vertical field of view {yfov} rad must lie in (0, pi)"
            )));
        }
        Self::new(width, height, 0.5 * height as f32 / (0.5 * yfov).tan())
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Focal length in pixels.
    pub fn focal_px(&self) -> f32 {
        self.focal_px
    }

    /// The principal point, the image centre (W/2, H/2).
    pub fn principal_point(&self) -> Vec2 {
        Vec2::new(0.5 * self.width as f32, 0.5 * self.height as f32)
    }

    /// The vertical field of view in radians, `2 atan(H / 2f)`.
    pub fn yfov(&self) -> f32 {
        2.0 * (0.5 * self.height as f32 / self.focal_px).atan()
    }
}

/// One eye of the rig.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Eye {
    /// The eye at -b/2 along the rig's +X.
    Left,
    /// The eye at +b/2 along the rig's +X.
    Right,
}

impl Eye {
    /// Both eyes, left first.
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];

    /// -1 for the left eye, +1 for the right one.
    pub fn sign(self) -> f32 {
        match self {
            Eye::Left => -1.0,
            Eye::Right => 1.0,
        }
    }

    /// `"left"` or `"right"` (used in file names).
    pub fn name(self) -> &'static str {
        match self {
            Eye::Left => "left",
            Eye::Right => "right",
        }
    }
}

impl fmt::Display for Eye {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Eye {
    type Err = StereoError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "left" => Ok(Eye::Left),
            "right" => Ok(Eye::Right),
            _ => Err(StereoError::Parameter {
                name: "eye",
                reason: format!("{s:?} is neither \"left\" nor \"right\""),
            }),
        }
    }
}

/// Checks that `a` is rigid: finite, with orthonormal, right-handed axes (tolerance 1e-3).
pub fn check_rigid(a: &Affine3A) -> Result<(), StereoError> {
    let m = a.matrix3;
    let cols = [
        Vec3::from(m.x_axis),
        Vec3::from(m.y_axis),
        Vec3::from(m.z_axis),
    ];
    if !(cols.iter().all(|c| c.is_finite()) && Vec3::from(a.translation).is_finite()) {
        return Err(StereoError::Pose("non-finite entries".into()));
    }
    for (i, c) in cols.iter().enumerate() {
        if (c.length() - 1.0).abs() > 1e-3 {
            return Err(StereoError::Pose(format!(
                "axis {i} has length {} (scaled transform)",
                c.length()
            )));
        }
    }
    let dots = [
        cols[0].dot(cols[1]),
        cols[1].dot(cols[2]),
        cols[0].dot(cols[2]),
    ];
    if dots.iter().any(|d| d.abs() > 1e-3) {
        return Err(StereoError::Pose(
            "axes are not orthogonal (sheared)".into(),
        ));
    }
    if m.determinant() < 0.0 {
        return Err(StereoError::Pose("axes are left-handed (mirrored)".into()));
    }
    Ok(())
}

/// A rectified stereo rig: intrinsics, baseline and the pose of the rig centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rig {
    intrinsics: Intrinsics,
    baseline: f32,
    world_from_rig: Affine3A,
}

impl Rig {
    /// The default baseline, 0.065 m (a human interocular distance, the paper's).
    pub const DEFAULT_BASELINE: f32 = 0.065;

    /// A rig; an error for a baseline that is not positive and finite or a pose that is not
    /// rigid. `world_from_rig` maps rig space (looking along -Z, +Y up, +X right) to the world.
    pub fn new(
        intrinsics: Intrinsics,
        baseline: f32,
        world_from_rig: Affine3A,
    ) -> Result<Self, StereoError> {
        if !(baseline.is_finite() && baseline > 0.0) {
            return Err(StereoError::Baseline(baseline));
        }
        check_rigid(&world_from_rig)?;
        Ok(Self {
            intrinsics,
            baseline,
            world_from_rig,
        })
    }

    /// The shared intrinsics.
    pub fn intrinsics(&self) -> &Intrinsics {
        &self.intrinsics
    }

    /// The baseline b in metres.
    pub fn baseline(&self) -> f32 {
        self.baseline
    }

    /// The pose of the rig centre.
    pub fn world_from_rig(&self) -> Affine3A {
        self.world_from_rig
    }

    /// Focal length in pixels.
    pub fn focal_px(&self) -> f32 {
        self.intrinsics.focal_px
    }

    /// The rig centre in world space.
    pub fn centre(&self) -> Vec3 {
        self.world_from_rig.translation.into()
    }

    /// The unit viewing direction (the rig's local -Z) in world space.
    pub fn forward(&self) -> Vec3 {
        self.world_from_rig.transform_vector3(-Vec3::Z).normalize()
    }

    /// Height of the rig centre above the road plane Y = 0.
    pub fn height(&self) -> f32 {
        self.centre().y
    }

    /// The pose of an eye: the rig's, translated by `sign * b/2` along the rig's local +X.
    pub fn world_from_eye(&self, eye: Eye) -> Affine3A {
        self.world_from_rig
            * Affine3A::from_translation(Vec3::X * (0.5 * eye.sign() * self.baseline))
    }

    /// One eye as a pinhole camera, with its inverse pose precomputed.
    pub fn eye(&self, eye: Eye) -> EyeCamera {
        let world_from_eye = self.world_from_eye(eye);
        EyeCamera {
            world_from_eye,
            eye_from_world: world_from_eye.inverse(),
            intrinsics: self.intrinsics,
        }
    }

    /// Disparity in pixels of a point at depth `z` (metres along the optical axis):
    /// `d = f b / z` (Eq. 5); infinite at `z = 0`, negative behind the rig.
    pub fn disparity_px(&self, z: f32) -> f32 {
        self.intrinsics.focal_px * self.baseline / z
    }

    /// Depth in metres of a disparity in pixels: `z = f b / d`; infinite at `d = 0`.
    pub fn depth_from_disparity_px(&self, d: f32) -> f32 {
        self.intrinsics.focal_px * self.baseline / d
    }

    /// A disparity in pixels as an angle in degrees of visual angle: `2 atan(d / 2f)`, the
    /// vergence angle of the two eyes' rays, exact for a point on the rig's midline.
    pub fn disparity_deg_from_px(&self, d: f32) -> f32 {
        (2.0 * (0.5 * d / self.intrinsics.focal_px).atan()).to_degrees()
    }

    /// The inverse of [`Rig::disparity_deg_from_px`]: `2 f tan(angle / 2)`.
    pub fn disparity_px_from_deg(&self, deg: f32) -> f32 {
        2.0 * self.intrinsics.focal_px * (0.5 * deg.to_radians()).tan()
    }

    /// The road frame below the rig centre; an error when the camera looks (almost) straight up
    /// or down, so that its forward direction has no horizontal part.
    pub fn road_frame(&self) -> Result<RoadFrame, StereoError> {
        let f = self.forward();
        let horizontal = Vec3::new(f.x, 0.0, f.z);
        if horizontal.length() < 1e-3 {
            return Err(StereoError::RoadFrame(format!(
                "the camera looks along {f}, (almost) vertically"
            )));
        }
        let z_axis = horizontal.normalize();
        let y_axis = Vec3::Y;
        // X to the camera's right: forward x up (for forward -Z this is +X).
        let x_axis = z_axis.cross(y_axis);
        let c = self.centre();
        Ok(RoadFrame {
            origin: Vec3::new(c.x, 0.0, c.z),
            x_axis,
            y_axis,
            z_axis,
        })
    }
}

/// One eye of the rig as a pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeCamera {
    /// Eye space (looking along -Z, +Y up) to world.
    pub world_from_eye: Affine3A,
    /// World to eye space.
    pub eye_from_world: Affine3A,
    /// The rig's intrinsics.
    pub intrinsics: Intrinsics,
}

impl EyeCamera {
    /// The eye's position in world space.
    pub fn position(&self) -> Vec3 {
        self.world_from_eye.translation.into()
    }

    /// A world point in eye space (looking along -Z).
    #[inline]
    pub fn to_eye(&self, p: Vec3) -> Vec3 {
        self.eye_from_world.transform_point3(p)
    }

    /// Depth of a world point along the optical axis (positive in front of the eye).
    #[inline]
    pub fn depth(&self, p: Vec3) -> f32 {
        -self.to_eye(p).z
    }

    /// Projects a world point to continuous pixel coordinates; `None` unless it is in front of
    /// the eye (depth > 1e-6 m).
    #[inline]
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let q = self.to_eye(p);
        let z = -q.z;
        // Also rejects NaN.
        if z.is_nan() || z <= 1e-6 {
            return None;
        }
        let c = self.intrinsics.principal_point();
        let f = self.intrinsics.focal_px;
        Some(Vec2::new(c.x + f * q.x / z, c.y - f * q.y / z))
    }

    /// The world point seen at continuous pixel coordinates `pixel` at depth `z` along the
    /// optical axis (the inverse of [`EyeCamera::project`]).
    #[inline]
    pub fn back_project(&self, pixel: Vec2, z: f32) -> Vec3 {
        let c = self.intrinsics.principal_point();
        let f = self.intrinsics.focal_px;
        let q = Vec3::new((pixel.x - c.x) * z / f, -(pixel.y - c.y) * z / f, -z);
        self.world_from_eye.transform_point3(q)
    }

    /// Unit world direction of the ray through continuous pixel coordinates `pixel`.
    #[inline]
    pub fn ray_direction(&self, pixel: Vec2) -> Vec3 {
        (self.back_project(pixel, 1.0) - self.position()).normalize()
    }
}

/// The paper's road frame, given by its origin and axes in world space. It is left-handed (see
/// the module documentation): converting goes through dot products with the axes, never
/// through a rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadFrame {
    /// Origin: the road point below the rig centre.
    pub origin: Vec3,
    /// Road +X (the camera's right, horizontal) in world space.
    pub x_axis: Vec3,
    /// Road +Y (world up).
    pub y_axis: Vec3,
    /// Road +Z (the camera's forward direction projected onto the road).
    pub z_axis: Vec3,
}

impl RoadFrame {
    /// Road coordinates of a world point.
    #[inline]
    pub fn road_from_world_point(&self, p: Vec3) -> Vec3 {
        self.road_from_world_vector(p - self.origin)
    }

    /// Road components of a world direction.
    #[inline]
    pub fn road_from_world_vector(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x_axis), v.dot(self.y_axis), v.dot(self.z_axis))
    }

    /// World position of a point given in road coordinates.
    #[inline]
    pub fn world_from_road_point(&self, q: Vec3) -> Vec3 {
        self.origin + self.world_from_road_vector(q)
    }

    /// World direction of a vector given in road components.
    #[inline]
    pub fn world_from_road_vector(&self, q: Vec3) -> Vec3 {
        q.x * self.x_axis + q.y * self.y_axis + q.z * self.z_axis
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    pub(crate) fn test_rig() -> Rig {
        let pose = Affine3A::from_rotation_translation(
            Quat::from_rotation_y(0.4) * Quat::from_rotation_x(-0.1),
            Vec3::new(2.0, 1.5, -3.0),
        );
        Rig::new(Intrinsics::from_yfov(640, 480, 0.7).unwrap(), 0.065, pose).unwrap()
    }

    #[test]
    fn projection_round_trips_in_both_eyes() {
        let rig = test_rig();
        for eye in Eye::BOTH {
            let cam = rig.eye(eye);
            for (px, z) in [
                (Vec2::new(0.5, 0.5), 2.0),
                (Vec2::new(320.0, 240.0), 15.0),
                (Vec2::new(600.25, 17.75), 80.0),
            ] {
                let p = cam.back_project(px, z);
                assert!((cam.depth(p) - z).abs() < 1e-4 * z, "{eye} {z}");
                let back = cam.project(p).unwrap();
                assert!((back - px).length() < 1e-3, "{eye} {px} -> {back}");
                let dir = cam.ray_direction(px);
                assert!((cam.position() + dir * (p - cam.position()).length() - p).length() < 1e-3);
            }
            // Behind the eye: no projection.
            let behind = cam
                .world_from_eye
                .transform_point3(Vec3::new(0.0, 0.0, 1.0));
            assert!(cam.project(behind).is_none());
        }
    }

    #[test]
    fn eyes_sit_on_the_rig_x_axis_and_disparity_is_f_b_over_z() {
        let rig = test_rig();
        let (l, r) = (rig.eye(Eye::Left), rig.eye(Eye::Right));
        let right_axis = rig.world_from_rig().transform_vector3(Vec3::X);
        assert!((r.position() - l.position() - right_axis * 0.065).length() < 1e-6);
        assert!(((l.position() + r.position()) * 0.5 - rig.centre()).length() < 1e-6);
        // A point seen by the left eye at depth Z appears f b / Z further left in the right eye.
        for z in [1.0f32, 7.5, 40.0] {
            let p = l.back_project(Vec2::new(200.0, 300.0), z);
            let (pl, pr) = (l.project(p).unwrap(), r.project(p).unwrap());
            let d = pl.x - pr.x;
            assert!(
                (d - rig.disparity_px(z)).abs() < 2e-3,
                "{d} vs {}",
                rig.disparity_px(z)
            );
            assert!((pl.y - pr.y).abs() < 1e-3, "rectified: same row");
            assert!((rig.depth_from_disparity_px(rig.disparity_px(z)) - z).abs() < 1e-4 * z);
        }
    }

    #[test]
    fn disparity_angles() {
        let rig = test_rig();
        let f = rig.focal_px();
        // A midline point at depth Z: vergence angle 2 atan(b / 2Z).
        let z = 10.0f32;
        let expect = (2.0 * (0.5 * 0.065 / z).atan()).to_degrees();
        let got = rig.disparity_deg_from_px(rig.disparity_px(z));
        assert!((got - expect).abs() < 1e-6, "{got} vs {expect}");
        assert!((rig.disparity_px_from_deg(got) - f * 0.065 / z).abs() < 1e-3);
        assert_eq!(rig.disparity_deg_from_px(0.0), 0.0);
        assert!(rig.depth_from_disparity_px(0.0).is_infinite());
    }

    #[test]
    fn road_frame_is_left_handed_below_the_rig() {
        let rig = test_rig();
        let road = rig.road_frame().unwrap();
        // Origin below the rig centre, at the rig height.
        let c = road.road_from_world_point(rig.centre());
        assert!(c.x.abs() < 1e-5 && c.z.abs() < 1e-5 && (c.y - 1.5).abs() < 1e-5);
        // Z is the forward direction made horizontal; X the camera's right made horizontal.
        let fwd = road.road_from_world_vector(rig.forward());
        assert!(fwd.x.abs() < 1e-5 && fwd.z > 0.0 && fwd.y < 0.0, "{fwd}");
        let right = road.road_from_world_vector(rig.world_from_rig().transform_vector3(Vec3::X));
        assert!(right.x > 0.99, "{right}");
        let det = glam::Mat3::from_cols(road.x_axis, road.y_axis, road.z_axis).determinant();
        assert!((det + 1.0).abs() < 1e-5, "left-handed: {det}");
        let p = Vec3::new(3.0, -0.2, 8.0);
        assert!((road.road_from_world_point(road.world_from_road_point(p)) - p).length() < 1e-5);
        // The glTF default camera (looking along -Z): road X = world X, road Z = world -Z.
        let level = Rig::new(
            *rig.intrinsics(),
            0.1,
            Affine3A::from_translation(Vec3::Y * 2.0),
        )
        .unwrap();
        let road = level.road_frame().unwrap();
        assert!((road.x_axis - Vec3::X).length() < 1e-6 && (road.z_axis + Vec3::Z).length() < 1e-6);
        // Looking straight down: no road frame.
        let down = Affine3A::from_rotation_translation(
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::Y,
        );
        assert!(Rig::new(*rig.intrinsics(), 0.1, down)
            .unwrap()
            .road_frame()
            .is_err());
    }

    #[test]
    fn bad_inputs_are_errors() {
        let intr = Intrinsics::new(64, 48, 50.0).unwrap();
        for b in [0.0, -0.1, f32::NAN, f32::INFINITY] {
            assert!(matches!(
                Rig::new(intr, b, Affine3A::IDENTITY),
                Err(StereoError::Baseline(_))
            ));
        }
        assert!(Intrinsics::new(0, 48, 50.0).is_err());
        assert!(Intrinsics::new(1 << 20, 1 << 20, 50.0).is_err());
        assert!(Intrinsics::new(64, 48, f32::NAN).is_err());
        assert!(Intrinsics::from_yfov(64, 48, 0.0).is_err());
        assert!(Intrinsics::from_yfov(64, 48, 4.0).is_err());
        let scaled = Affine3A::from_scale(Vec3::splat(2.0));
        assert!(Rig::new(intr, 0.1, scaled).is_err());
        let mirrored = Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        assert!(Rig::new(intr, 0.1, mirrored).is_err());
        assert!(Rig::new(intr, 0.1, Affine3A::from_translation(Vec3::NAN)).is_err());
        assert!("middle".parse::<Eye>().is_err());
        assert_eq!("right".parse::<Eye>().unwrap(), Eye::Right);
        let i = Intrinsics::from_yfov(640, 480, 0.7).unwrap();
        assert!((i.yfov() - 0.7).abs() < 1e-6);
    }
}
