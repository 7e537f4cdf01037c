//! The rectified stereo rig of docs/design.md: two pinhole eyes with parallel axes.
//!
//! Conventions (all from docs/design.md):
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
//!
//! # One camera, two precisions
//!
//! [`Rig`] and its eyes ([`EyeCamera`]) work in `f32` world space with the full pose: they
//! render the pair and its ground truth. The analysis measures much smaller things (disparity
//! spans of 0.01 px, 0.008 degrees along a streak), so it works with [`RoadRig`]: the same
//! rig in `f64` road coordinates ([`Rig::road_rig`]), with its projection and ground points,
//! its horizon, elevation angles and disparities in pixels and degrees. The Eq. 4 model of the
//! analysis crate and its report both use it; nothing else computes these angles.
//!
//! # Angular disparity
//!
//! The paper's angular disparity is the difference of the angles under which the two eyes see
//! a point: its horizontal visual angle (Fick azimuth) in the left eye minus that in the right
//! eye. In an eye's camera frame a point `x` metres to the right of the eye at depth `z` along
//! the optical axis has azimuth `atan(x / z)`; at pixel column `u` that is `atan((u - c_x) / f)`.
//! So a point seen at `u_left` with pixel disparity `d` has the angular disparity
//! `atan((u_left - c_x) / f) - atan((u_left - d - c_x) / f)`
//! ([`RoadRig::angular_disparity_deg_px`]), the same number as from its position
//! ([`RoadRig::angular_disparity_deg`]). Straight ahead of the rig centre it is the vergence
//! angle `2 atan(b / 2Z)`; elsewhere it is not a function of the pixel disparity alone, which is
//! why there is no `d -> degrees` conversion without a column.

use crate::error::StereoError;
use glam::{Affine3A, DVec2, DVec3, Vec2, Vec3};
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

    /// The rig's attitude against world up (+Y), radians: the pitch of the optical axis below
    /// the horizon, `asin(-forward.y)`, and the roll about it, positive with the camera's
    /// right side down, `atan2(-right.y, up.y)` (the angles the generator mounts the rig with:
    /// roll about the view direction, then pitch about the level right axis).
    pub fn pitch_roll(&self) -> (f32, f32) {
        let m = self.world_from_rig.matrix3;
        let pitch = (-self.forward().y).clamp(-1.0, 1.0).asin();
        (pitch, (-m.x_axis.y).atan2(m.y_axis.y))
    }

    /// The rig in `f64` road coordinates, for the analysis: its centre at `(0, height, 0)`,
    /// pitched down by `asin(-forward.y)`, with the rig's focal length, principal point and
    /// baseline. The same errors as [`Rig::road_frame`]. The rig's roll is not represented:
    /// [`RoadRig`] keeps its eyes on the road frame's X axis, as a level horizon needs.
    pub fn road_rig(&self) -> Result<RoadRig, StereoError> {
        self.road_frame()?;
        let pitch = (-self.forward().y as f64).clamp(-1.0, 1.0).asin();
        let pp = self.intrinsics.principal_point();
        RoadRig::new(
            DVec3::new(0.0, self.height() as f64, 0.0),
            pitch,
            self.focal_px() as f64,
            DVec2::new(pp.x as f64, pp.y as f64),
            self.baseline as f64,
        )
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

/// A rectified rig in the road frame, in `f64`: two pinhole eyes `b` apart along the road
/// frame's X, centred on `centre`, both pitched down by `pitch` about that axis (no roll, no
/// yaw: the road frame's Z is the rig's forward direction made horizontal). Pixels as in the
/// module documentation. This is the camera of the analysis (see the module documentation for
/// why `f64`); [`Rig::road_rig`] makes it from a rig, [`RoadRig::new`] from numbers.
///
/// Camera coordinates, relative to an eye or the centre: `(right, up, depth along the optical
/// axis)`, so a point in front has positive depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadRig {
    centre: DVec3,
    pitch: f64,
    focal_px: f64,
    principal: DVec2,
    baseline: f64,
}

impl RoadRig {
    /// A checked rig: `centre` (the cyclopean eye, road coordinates) finite, `pitch` (radians,
    /// downward) inside (-pi/2, pi/2), `focal_px` positive and finite, `principal` finite,
    /// `baseline` (metres) positive and finite.
    pub fn new(
        centre: DVec3,
        pitch: f64,
        focal_px: f64,
        principal: DVec2,
        baseline: f64,
    ) -> Result<Self, StereoError> {
        if !centre.is_finite() {
            return Err(StereoError::Pose(format!(
                "the rig centre {centre} is not finite"
            )));
        }
        if !(pitch.is_finite() && pitch.abs() < std::f64::consts::FRAC_PI_2) {
            return Err(StereoError::Pose(format!(
                "the pitch {} degrees must lie in (-90, 90)",
                pitch.to_degrees()
            )));
        }
        if !(focal_px.is_finite() && focal_px > 0.0) {
            return Err(StereoError::Intrinsics(format!(
                "focal length {focal_px} px must be positive and finite"
            )));
        }
        if !principal.is_finite() {
            return Err(StereoError::Intrinsics(format!(
                "principal point {principal} is not finite"
            )));
        }
        if !(baseline.is_finite() && baseline > 0.0) {
            return Err(StereoError::Parameter {
                name: "baseline",
                reason: format!("{baseline} m must be positive and finite"),
            });
        }
        Ok(Self {
            centre,
            pitch,
            focal_px,
            principal,
            baseline,
        })
    }

    /// A level rig at `centre` with its principal point at pixel (0, 0): with `focal_px` 1 its
    /// pixels are the tangents of the visual angles.
    pub fn level(centre: DVec3, focal_px: f64, baseline: f64) -> Result<Self, StereoError> {
        Self::new(centre, 0.0, focal_px, DVec2::ZERO, baseline)
    }

    /// The rig centre (the cyclopean eye) in road coordinates; its Y is the rig height.
    pub fn centre(&self) -> DVec3 {
        self.centre
    }

    /// Downward pitch of the optical axis from the road's +Z, radians (0: level).
    pub fn pitch(&self) -> f64 {
        self.pitch
    }

    /// Focal length in pixels.
    pub fn focal_px(&self) -> f64 {
        self.focal_px
    }

    /// Principal point in pixels.
    pub fn principal(&self) -> DVec2 {
        self.principal
    }

    /// The baseline b in metres.
    pub fn baseline(&self) -> f64 {
        self.baseline
    }

    /// An eye's position: the centre moved by `sign * b/2` along the road's X.
    pub fn eye_position(&self, eye: Eye) -> DVec3 {
        self.centre + DVec3::X * (0.5 * eye.sign() as f64 * self.baseline)
    }

    /// The optical axis in road coordinates.
    pub fn forward(&self) -> DVec3 {
        DVec3::new(0.0, -self.pitch.sin(), self.pitch.cos())
    }

    /// The cameras' up axis in road coordinates.
    pub fn up(&self) -> DVec3 {
        DVec3::new(0.0, self.pitch.cos(), self.pitch.sin())
    }

    /// A road point in the centre's camera coordinates: (right, up, depth).
    pub fn to_camera(&self, p: DVec3) -> DVec3 {
        self.camera_from(self.centre, p)
    }

    /// `p` in the camera coordinates of a camera at `origin` with the rig's orientation.
    fn camera_from(&self, origin: DVec3, p: DVec3) -> DVec3 {
        let d = p - origin;
        DVec3::new(d.x, d.dot(self.up()), d.dot(self.forward()))
    }

    /// The pixel of camera coordinates `c`, or `None` unless `c` is in front (depth > 0).
    fn pixel(&self, c: DVec3) -> Option<DVec2> {
        (c.z > 0.0).then(|| {
            DVec2::new(
                self.principal.x + self.focal_px * c.x / c.z,
                self.principal.y - self.focal_px * c.y / c.z,
            )
        })
    }

    /// Where the rig centre (the cyclopean eye) sees road point `p`, or `None` if it is not in
    /// front.
    pub fn project(&self, p: DVec3) -> Option<DVec2> {
        self.pixel(self.to_camera(p))
    }

    /// Where `eye` sees road point `p`, or `None` if it is not in front.
    pub fn project_eye(&self, eye: Eye, p: DVec3) -> Option<DVec2> {
        self.pixel(self.camera_from(self.eye_position(eye), p))
    }

    /// The (unnormalised) road direction of the centre's ray through `pixel`; its component
    /// along the optical axis is 1.
    pub fn ray(&self, pixel: DVec2) -> DVec3 {
        let x = (pixel.x - self.principal.x) / self.focal_px;
        let y = -(pixel.y - self.principal.y) / self.focal_px;
        DVec3::X * x + self.up() * y + self.forward()
    }

    /// The road point (Y = 0) the centre sees through `pixel`, or `None` if the ray does not
    /// go down to the road (or the rig is not above it).
    pub fn ground_point(&self, pixel: DVec2) -> Option<DVec3> {
        let d = self.ray(pixel);
        if d.y >= 0.0 || self.centre.y <= 0.0 {
            return None;
        }
        let p = self.centre + d * (-self.centre.y / d.y);
        Some(DVec3::new(p.x, 0.0, p.z))
    }

    /// The image row of the horizon, `c_y - f tan(pitch)` (continuous pixel coordinates).
    pub fn horizon_row(&self) -> f64 {
        self.principal.y - self.focal_px * self.pitch.tan()
    }

    /// The angle below the horizon at which the rig centre sees `p`, degrees: the angle between
    /// the sight line and the horizontal plane, positive below the horizon.
    pub fn elevation_deg(&self, p: DVec3) -> f64 {
        let d = p - self.centre;
        (-d.y).atan2(d.x.hypot(d.z)).to_degrees()
    }

    /// The elevation below the horizon of the centre's ray through image row `y` at the
    /// principal column, degrees: `atan((y - c_y) / f) + pitch`, the
    /// [`RoadRig::elevation_deg`] of every point on that ray.
    pub fn row_elevation_deg(&self, y: f64) -> f64 {
        (((y - self.principal.y) / self.focal_px).atan() + self.pitch).to_degrees()
    }

    /// Eq. 5: the pixel disparity `x_left - x_right = f b / Z` of road point `p`, `Z` its depth
    /// along the optical axis. Infinite or negative if it is not in front.
    pub fn disparity_px(&self, p: DVec3) -> f64 {
        self.focal_px * self.baseline / self.to_camera(p).z
    }

    /// The depth along the optical axis of a pixel disparity, `f b / d` (infinite at 0).
    pub fn depth_from_disparity_px(&self, d: f64) -> f64 {
        self.focal_px * self.baseline / d
    }

    /// The angular disparity of road point `p`, degrees: its azimuth in the left eye minus that
    /// in the right eye (see the module documentation).
    pub fn angular_disparity_deg(&self, p: DVec3) -> f64 {
        let c = self.to_camera(p);
        let half = 0.5 * self.baseline;
        angular_disparity_deg(c.x + half, c.x - half, c.z)
    }

    /// The angular disparity, degrees, of a point the left eye sees at column `x_left` with
    /// pixel disparity `d` (so the right eye sees it at `x_left - d`): the same definition as
    /// [`RoadRig::angular_disparity_deg`], from pixels.
    pub fn angular_disparity_deg_px(&self, x_left: f64, d: f64) -> f64 {
        let cx = self.principal.x;
        angular_disparity_deg(x_left - cx, x_left - d - cx, self.focal_px)
    }
}

/// The angular disparity, degrees, of a point `left` and `right` to the right of the left and
/// the right eye at `depth` along their optical axes (metres, or pixels with `depth = f`): the
/// difference of its azimuths `atan(lateral / depth)` in the two eyes.
fn angular_disparity_deg(left: f64, right: f64, depth: f64) -> f64 {
    ((left / depth).atan() - (right / depth).atan()).to_degrees()
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

    /// A road rig with a 6.5 cm baseline, pitched down by `pitch_deg`.
    fn pitched(centre: DVec3, pitch_deg: f64, focal_px: f64, principal: DVec2) -> RoadRig {
        RoadRig::new(centre, pitch_deg.to_radians(), focal_px, principal, 0.065).unwrap()
    }

    /// A rig rolled about its view direction, then pitched about the level right axis, and
    /// yawed: its attitude gives back the pitch and roll, whatever the yaw.
    #[test]
    fn pitch_and_roll_come_back_from_the_pose() {
        for (pitch, roll, yaw) in [
            (0.05f32, -0.03f32, 0.0f32),
            (-0.1, 0.02, 1.2),
            (0.0, 0.0, -2.0),
        ] {
            let m = glam::Mat3::from_rotation_y(yaw)
                * glam::Mat3::from_rotation_x(-pitch)
                * glam::Mat3::from_rotation_z(-roll);
            let pose = Affine3A::from_mat3_translation(m, Vec3::new(1.0, 1.4, -3.0));
            let rig = Rig::new(Intrinsics::new(64, 48, 50.0).unwrap(), 0.2, pose).unwrap();
            let (p, r) = rig.pitch_roll();
            assert!(
                (p - pitch).abs() < 1e-5 && (r - roll).abs() < 1e-5,
                "{p} {r}"
            );
        }
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
        let road = rig.road_rig().unwrap();
        // A point straight ahead of the rig centre at depth Z: the vergence angle 2 atan(b / 2Z),
        // from its position and from its pixels alike.
        let z = 10.0f64;
        let p = road.centre() + road.forward() * z;
        let b = road.baseline();
        let expect = (2.0 * (0.5 * b / z).atan()).to_degrees();
        let got = road.angular_disparity_deg(p);
        assert!((got - expect).abs() < 1e-14, "{got} vs {expect}");
        let d = road.disparity_px(p);
        assert!((d - road.focal_px() * b / z).abs() < 1e-9);
        let xl = road.project_eye(Eye::Left, p).unwrap().x;
        assert!((road.angular_disparity_deg_px(xl, d) - expect).abs() < 1e-12);
        assert_eq!(road.angular_disparity_deg_px(xl, 0.0), 0.0);
        assert!(rig.depth_from_disparity_px(0.0).is_infinite());
        assert!(road.depth_from_disparity_px(0.0).is_infinite());
        assert!((road.depth_from_disparity_px(d) - z).abs() < 1e-9);
    }

    /// Off the rig's midline the angular disparity is the difference of the eyes' azimuths
    /// `atan((x - c_x) / f)`, not a function of the pixel disparity alone.
    #[test]
    fn angular_disparity_is_the_difference_of_the_eyes_azimuths() {
        let road = pitched(
            DVec3::new(0.2, 1.5, 0.0),
            3.0,
            1000.0,
            DVec2::new(640.0, 360.0),
        );
        let p = DVec3::new(-2.0, -1.0, 12.0);
        let (l, r) = (
            road.project_eye(Eye::Left, p).unwrap(),
            road.project_eye(Eye::Right, p).unwrap(),
        );
        assert!((l.y - r.y).abs() < 1e-9, "rectified: same row");
        assert!((road.disparity_px(p) - (l.x - r.x)).abs() < 1e-9);
        let az = |q: DVec2| ((q.x - 640.0) / 1000.0).atan().to_degrees();
        let deg = road.angular_disparity_deg(p);
        assert!((deg - (az(l) - az(r))).abs() < 1e-12);
        assert!((road.angular_disparity_deg_px(l.x, l.x - r.x) - deg).abs() < 1e-12);
        // The vergence formula 2 atan(d / 2f) holds on the midline only.
        let vergence = (2.0 * (0.5 * (l.x - r.x) / 1000.0f64).atan()).to_degrees();
        assert!((vergence - deg).abs() > 1e-5, "{vergence} vs {deg}");
        // Behind: negative disparity, no projection.
        assert!(road.disparity_px(DVec3::new(0.0, 0.0, -3.0)) < 0.0);
        assert!(road.project(DVec3::new(0.0, 0.0, -3.0)).is_none());
    }

    /// The f64 road rig sees what the f32 eyes see: the same pixels, the horizon where far
    /// level points project, and row elevations that are the elevations of the ground points.
    #[test]
    fn road_rig_agrees_with_the_eyes() {
        let rig = test_rig();
        let frame = rig.road_frame().unwrap();
        let road = rig.road_rig().unwrap();
        assert!((road.centre() - DVec3::new(0.0, 1.5, 0.0)).length() < 1e-6);
        assert!((road.pitch() - 0.1).abs() < 1e-6, "{}", road.pitch());
        for q in [
            Vec3::new(0.5, 0.0, 6.0),
            Vec3::new(-3.0, 4.0, 20.0),
            Vec3::new(1.0, -1.5, 12.0),
        ] {
            let world = frame.world_from_road_point(q);
            let dq = DVec3::new(q.x as f64, q.y as f64, q.z as f64);
            for eye in Eye::BOTH {
                let a = rig.eye(eye).project(world).unwrap();
                let b = road.project_eye(eye, dq).unwrap();
                assert!((a.x as f64 - b.x).abs() < 2e-3 && (a.y as f64 - b.y).abs() < 2e-3);
            }
            let depth = rig.eye(Eye::Left).depth(world) as f64;
            assert!((road.disparity_px(dq) - rig.disparity_px(depth as f32) as f64).abs() < 1e-3);
        }
        let far = road.project(DVec3::new(0.0, 1.5, 1e7)).unwrap();
        assert!(
            (far.y - road.horizon_row()).abs() < 1e-6,
            "{far} {}",
            road.horizon_row()
        );
        let cx = road.principal().x;
        for y in [300.5, 400.5, 479.5] {
            let g = road.ground_point(DVec2::new(cx, y)).unwrap();
            assert!((road.project(g).unwrap() - DVec2::new(cx, y)).length() < 1e-9);
            assert!((road.elevation_deg(g) - road.row_elevation_deg(y)).abs() < 1e-12);
        }
        let above = road.horizon_row() - 1.0;
        assert!(
            road.ground_point(DVec2::new(cx, above)).is_none(),
            "above the horizon"
        );
        // Off the principal column too.
        let road = pitched(
            DVec3::new(0.0, 1.5, 0.0),
            2.0,
            800.0,
            DVec2::new(400.0, 300.0),
        );
        let g = road.ground_point(DVec2::new(450.5, 400.5)).unwrap();
        let back = road.project(g).unwrap();
        assert!((back - DVec2::new(450.5, 400.5)).length() < 1e-9);
        assert!(
            road.ground_point(DVec2::new(400.0, 0.5)).is_none(),
            "above the horizon"
        );
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
        let c = DVec3::new(0.0, 1.5, 0.0);
        let new = |pitch_deg: f64, f: f64, b: f64| {
            RoadRig::new(c, f64::to_radians(pitch_deg), f, DVec2::ZERO, b)
        };
        assert!(matches!(new(95.0, 100.0, 0.1), Err(StereoError::Pose(_))));
        assert!(matches!(
            new(0.0, 0.0, 0.1),
            Err(StereoError::Intrinsics(_))
        ));
        assert!(matches!(
            new(0.0, 100.0, 0.0),
            Err(StereoError::Parameter { .. })
        ));
        assert!(RoadRig::new(DVec3::NAN, 0.0, 1.0, DVec2::ZERO, 0.1).is_err());
        assert!(RoadRig::new(c, 0.0, 1.0, DVec2::NAN, 0.1).is_err());
    }
}
