//! Optical flow and scene flow ground truth of the left eye, from one frame of a sequence to
//! the next, derived exactly from the geometry: no image is matched and no depth map is
//! interpolated.
//!
//! For each left pixel, with the frames' rigs `now` and `next`:
//!
//! 1. the ray through the pixel centre meets its first surface at `X` in the scene `now`
//!    ([`Surfaces::first_hit`]); nothing hit (the sky) leaves the flow undefined
//!    ([`FlowState::NoSurface`]);
//! 2. `X` belongs to the object `instance[pixel]` (0: the static world), which moves it to
//!    `X' = world_from_object(next) * object_from_world(now) * X` ([`ObjectMotion`]);
//! 3. the flow is `x' - x`, `x'` the projection of `X'` into the left eye `next` and `x` the
//!    pixel centre; the disparity change (SceneFlow's) is `f b / Z' - f b / Z`, `Z` and `Z'`
//!    the depths of `X` and `X'` along the optical axes of `now` and `next`;
//! 4. `X'` is occluded in `next` ([`FlowState::Occluded`]) when the ray from the left eye
//!    `next` towards it meets a surface of the scene `next` nearer than `|X' - C'|` by more
//!    than [`OCCLUSION_TOLERANCE`] (relative); it is out of view ([`FlowState::OutOfView`])
//!    when `x'` leaves the image or `X'` is behind the eye.
//!
//! The flow is that of the surfaces at the two frame times: rain drops and motion blur are not
//! part of it. The maths after the ray casts is in `f64`.

use crate::error::StereoError;
use crate::rig::{Eye, Rig};
use glam::{Affine3A, DAffine3, DVec2, DVec3, Vec2, Vec3};

/// Relative tolerance of the occlusion test: a surface nearer than `(1 - tol) |X' - C'|`
/// occludes `X'`.
pub const OCCLUSION_TOLERANCE: f64 = 1e-3;

/// A scene that rays can be cast into.
pub trait Surfaces {
    /// The distance along the unit `direction` from `origin` to the first surface, or `None`
    /// when the ray meets nothing.
    fn first_hit(&self, origin: Vec3, direction: Vec3) -> Option<f32>;
}

#[cfg(feature = "render")]
impl Surfaces for streaks_render::scene::Scene {
    fn first_hit(&self, origin: Vec3, direction: Vec3) -> Option<f32> {
        self.intersect(&streaks_render::geometry::Ray::new(origin, direction))
            .map(|h| h.t)
    }
}

/// What the flow of a pixel is, and its value in the flow mask PNG.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum FlowState {
    /// The pixel sees no surface (the sky): no flow.
    NoSurface = 0,
    /// The point moves out of the image or behind the eye.
    OutOfView = 64,
    /// The point stays in view but a nearer surface hides it in the next frame.
    Occluded = 128,
    /// The point is visible in both frames.
    Visible = 255,
}

impl FlowState {
    /// Every state.
    pub const ALL: [FlowState; 4] = [
        FlowState::NoSurface,
        FlowState::OutOfView,
        FlowState::Occluded,
        FlowState::Visible,
    ];

    /// Its value in the flow mask PNG.
    pub fn mask_value(self) -> u8 {
        self as u8
    }

    /// The state of a flow mask value; `None` for a value that is not one.
    pub fn from_mask_value(v: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.mask_value() == v)
    }

    /// Whether the pixel has a flow value in a KITTI `flow_occ`-style map: the point is in the
    /// next image, visible or occluded.
    pub fn has_flow(self) -> bool {
        matches!(self, FlowState::Visible | FlowState::Occluded)
    }
}

/// How the objects of a scene move from one frame to the next: for each instance id, the rigid
/// transform `world_from_object(next) * object_from_world(now)`; everything else (instance 0
/// and any instance not listed) stays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectMotion {
    moves: Vec<(u32, DAffine3)>,
}

impl ObjectMotion {
    /// No object moves.
    pub fn new() -> Self {
        Self::default()
    }

    /// Instance `instance` is at `world_from_object_now` now and at `world_from_object_next`
    /// in the next frame.
    pub fn insert(
        &mut self,
        instance: u32,
        world_from_object_now: Affine3A,
        world_from_object_next: Affine3A,
    ) {
        let now = to_f64(world_from_object_now);
        let next = to_f64(world_from_object_next);
        let m = next * now.inverse();
        match self.moves.iter_mut().find(|(i, _)| *i == instance) {
            Some(entry) => entry.1 = m,
            None => self.moves.push((instance, m)),
        }
    }

    /// The motion of a world point on instance `instance` (the identity for the static world).
    pub fn next_from_now(&self, instance: u32) -> DAffine3 {
        self.moves
            .iter()
            .find(|(i, _)| *i == instance)
            .map_or(DAffine3::IDENTITY, |(_, m)| *m)
    }
}

/// An `f32` affine transform in `f64`.
pub fn to_f64(a: Affine3A) -> DAffine3 {
    DAffine3::from_cols(
        Vec3::from(a.matrix3.x_axis).as_dvec3(),
        Vec3::from(a.matrix3.y_axis).as_dvec3(),
        Vec3::from(a.matrix3.z_axis).as_dvec3(),
        Vec3::from(a.translation).as_dvec3(),
    )
}

/// The left eye of a rig in `f64`: projection and rays.
#[derive(Clone, Copy, Debug)]
struct Pinhole {
    world_from_eye: DAffine3,
    eye_from_world: DAffine3,
    focal: f64,
    centre: DVec2,
}

impl Pinhole {
    fn left(rig: &Rig) -> Self {
        let world_from_eye = to_f64(rig.world_from_eye(Eye::Left));
        let i = rig.intrinsics();
        Self {
            world_from_eye,
            eye_from_world: world_from_eye.inverse(),
            focal: f64::from(i.focal_px()),
            centre: i.principal_point().as_dvec2(),
        }
    }

    fn position(&self) -> DVec3 {
        self.world_from_eye.translation
    }

    /// Depth along the optical axis (positive in front).
    fn depth(&self, p: DVec3) -> f64 {
        -self.eye_from_world.transform_point3(p).z
    }

    /// Continuous pixel coordinates of a point in front of the eye.
    fn project(&self, p: DVec3) -> Option<DVec2> {
        let q = self.eye_from_world.transform_point3(p);
        let z = -q.z;
        (z > 1e-9).then(|| {
            DVec2::new(
                self.centre.x + self.focal * q.x / z,
                self.centre.y - self.focal * q.y / z,
            )
        })
    }

    /// Unit world direction through continuous pixel coordinates.
    fn direction(&self, pixel: DVec2) -> DVec3 {
        let d = DVec3::new(
            (pixel.x - self.centre.x) / self.focal,
            -(pixel.y - self.centre.y) / self.focal,
            -1.0,
        );
        self.world_from_eye.transform_vector3(d).normalize()
    }
}

/// The left eye's flow from one frame to the next: per pixel (rows top to bottom) the flow
/// `(u, v)` in pixels, the disparity change in pixels and the [`FlowState`].
#[derive(Clone, Debug, PartialEq)]
pub struct FlowField {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// `x' - x` per pixel; `inf` where the point has no projection in the next frame (no
    /// surface, or behind the eye). Out-of-view points keep their value.
    pub flow: Vec<[f32; 2]>,
    /// `d(next) - d(now)` per pixel, pixels; `inf` where the flow is.
    pub disparity_change: Vec<f32>,
    /// What each pixel's flow is.
    pub state: Vec<FlowState>,
}

impl FlowField {
    /// The share of the pixels in each state, in [`FlowState::ALL`] order.
    pub fn shares(&self) -> [f64; 4] {
        let n = self.state.len().max(1) as f64;
        FlowState::ALL.map(|s| self.state.iter().filter(|&&x| x == s).count() as f64 / n)
    }
}

/// The exact forward flow of the left eye from the frame `now` to the frame `next` (see the
/// module documentation). `instance` is the left view's instance map of the frame `now`, one
/// id per pixel, rows top to bottom. An error when the two rigs' images differ in size or the
/// map does not have one id per pixel.
pub fn left_flow<S: Surfaces + ?Sized, T: Surfaces + ?Sized>(
    now: &Rig,
    next: &Rig,
    scene_now: &S,
    scene_next: &T,
    instance: &[u32],
    motion: &ObjectMotion,
) -> Result<FlowField, StereoError> {
    let (i0, i1) = (now.intrinsics(), next.intrinsics());
    if (i0.width(), i0.height()) != (i1.width(), i1.height()) {
        return Err(StereoError::Camera(format!(
            "the flow's two frames differ in size: {}x{} and {}x{}",
            i0.width(),
            i0.height(),
            i1.width(),
            i1.height()
        )));
    }
    let (w, h) = (i0.width() as usize, i0.height() as usize);
    if instance.len() != w * h {
        return Err(StereoError::Camera(format!(
            "the instance map has {} ids for {w}x{h} pixels",
            instance.len()
        )));
    }
    let (cam0, cam1) = (Pinhole::left(now), Pinhole::left(next));
    let fb0 = f64::from(now.focal_px()) * f64::from(now.baseline());
    let fb1 = f64::from(next.focal_px()) * f64::from(next.baseline());
    let mut out = FlowField {
        width: w,
        height: h,
        flow: vec![[f32::INFINITY; 2]; w * h],
        disparity_change: vec![f32::INFINITY; w * h],
        state: vec![FlowState::NoSurface; w * h],
    };
    let origin0 = cam0.position();
    let origin1 = cam1.position();
    for y in 0..h {
        for x in 0..w {
            let k = y * w + x;
            let pixel = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let dir = cam0.direction(pixel);
            let Some(t) = scene_now.first_hit(origin0.as_vec3(), dir.as_vec3()) else {
                continue;
            };
            let p = origin0 + dir * f64::from(t);
            let moved = motion.next_from_now(instance[k]).transform_point3(p);
            let Some(pixel1) = cam1.project(moved) else {
                out.state[k] = FlowState::OutOfView;
                continue;
            };
            let f = pixel1 - pixel;
            out.flow[k] = [f.x as f32, f.y as f32];
            out.disparity_change[k] = (fb1 / cam1.depth(moved) - fb0 / cam0.depth(p)) as f32;
            let inside = (0.0..w as f64).contains(&pixel1.x) && (0.0..h as f64).contains(&pixel1.y);
            out.state[k] = if !inside {
                FlowState::OutOfView
            } else if occluded(scene_next, origin1, moved) {
                FlowState::Occluded
            } else {
                FlowState::Visible
            };
        }
    }
    Ok(out)
}

/// Whether a surface of `scene` hides `p` from `eye`: the ray from `eye` towards `p` meets one
/// nearer than `(1 - OCCLUSION_TOLERANCE) |p - eye|`.
pub fn occluded<S: Surfaces + ?Sized>(scene: &S, eye: DVec3, p: DVec3) -> bool {
    let to = p - eye;
    let distance = to.length();
    scene
        .first_hit(eye.as_vec3(), (to / distance).as_vec3())
        .is_some_and(|t| f64::from(t) < distance * (1.0 - OCCLUSION_TOLERANCE))
}

/// The left eye's pixel-centre ray through continuous pixel coordinates `pixel` of `rig`:
/// origin and unit direction (the rays [`left_flow`] casts).
pub fn left_ray(rig: &Rig, pixel: Vec2) -> (Vec3, Vec3) {
    let cam = Pinhole::left(rig);
    (
        cam.position().as_vec3(),
        cam.direction(pixel.as_dvec2()).as_vec3(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::Intrinsics;
    use glam::{DMat3, Mat3};

    /// The plane Y = 0, seen from above.
    struct Ground;

    impl Surfaces for Ground {
        fn first_hit(&self, o: Vec3, d: Vec3) -> Option<f32> {
            let t = -o.y / d.y;
            (d.y < 0.0 && t > 0.0).then_some(t)
        }
    }

    /// A rig at `position` looking along -Z, pitched down by `pitch` radians.
    fn rig(position: Vec3, pitch: f32, w: u32, h: u32, f: f32) -> Rig {
        let pose = Affine3A::from_mat3_translation(Mat3::from_rotation_x(-pitch), position);
        Rig::new(Intrinsics::new(w, h, f).unwrap(), 0.3, pose).unwrap()
    }

    /// A static flat road and a rig moving straight forward: the road's flow is the plane's
    /// homography `H = K (R - t n^T / d) K^-1`, written here in the computer-vision camera
    /// frame (x right, y down, z forward) from the rig's height, pitch and the distance moved.
    #[test]
    fn road_flow_is_the_planes_homography() {
        let (w, h, f) = (96u32, 64u32, 80.0f32);
        let (height, pitch, step) = (1.4f64, 0.06f64, 1.25f64);
        let now = rig(Vec3::new(0.3, height as f32, 2.0), pitch as f32, w, h, f);
        // Forward along the rig's viewing direction projected on the road (world -Z).
        let next = rig(
            Vec3::new(0.3, height as f32, 2.0 - step as f32),
            pitch as f32,
            w,
            h,
            f,
        );
        let ids = vec![0u32; (w * h) as usize];
        let flow = left_flow(&now, &next, &Ground, &Ground, &ids, &ObjectMotion::new()).unwrap();
        // The left eye sits b/2 to the left on the rig's level x axis: same height.
        // CV frame: the world's down (0, -1, 0) is (0, cos p, -sin p)... derive directly:
        // camera axes in world: right = X, up' = R_x(-p) Y, forward = R_x(-p) (-Z).
        let (s, c) = pitch.sin_cos();
        let right = DVec3::X;
        let down = -DVec3::new(0.0, c, -s); // -(up axis)
        let forward = DVec3::new(0.0, -s, -c);
        // Rows of R_cv_from_world.
        let r = DMat3::from_cols(right, down, forward).transpose();
        let n = r * DVec3::new(0.0, -1.0, 0.0); // the plane's normal towards the ground
        let d = height; // distance from the camera to the plane along n
        let t = r * DVec3::new(0.0, 0.0, -step); // the camera's move, camera frame
        let k = DMat3::from_cols(
            DVec3::new(f64::from(f), 0.0, 0.0),
            DVec3::new(0.0, f64::from(f), 0.0),
            DVec3::new(f64::from(w) / 2.0, f64::from(h) / 2.0, 1.0),
        );
        // X' = X - t for a static point; on the plane n.X = d: X' = (I - t n^T / d) X.
        let outer = DMat3::from_cols(t * n.x, t * n.y, t * n.z);
        let hom = k * (DMat3::IDENTITY - outer / d) * k.inverse();
        let mut checked = 0;
        for y in 0..h as usize {
            for x in 0..w as usize {
                let i = y * w as usize + x;
                let p = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, 1.0);
                let q = hom * p;
                let expected = DVec2::new(q.x / q.z - p.x, q.y / q.z - p.y);
                // Above the horizon: no road, no flow.
                let horizon = f64::from(h) / 2.0 - f64::from(f) * pitch.tan();
                if p.y < horizon + 0.5 {
                    if p.y < horizon - 0.5 {
                        assert_eq!(flow.state[i], FlowState::NoSurface, "({x}, {y})");
                    }
                    continue;
                }
                let got = flow.flow[i];
                let err = (DVec2::new(f64::from(got[0]), f64::from(got[1])) - expected).length();
                assert!(err < 1e-3, "({x}, {y}): {got:?} vs {expected} ({err} px)");
                checked += 1;
            }
        }
        assert!(checked > (w * h / 3) as usize, "{checked} road pixels");
        // The road comes towards the rig: the flow points down, away from the focus of
        // expansion (the horizon's centre), and the disparity grows.
        let bottom = (h as usize - 1) * w as usize + w as usize / 4;
        assert!(flow.flow[bottom][1] > 0.5 && flow.flow[bottom][0] < 0.0);
        assert!(flow.disparity_change[bottom] > 0.0);
    }

    /// A box on a plane, seen head on from the origin.
    struct BoxOnWall {
        world_from_box: Affine3A,
        half: Vec3,
        wall_z: f32,
    }

    impl Surfaces for BoxOnWall {
        fn first_hit(&self, o: Vec3, d: Vec3) -> Option<f32> {
            // The slab test in the box's frame.
            let inv = self.world_from_box.inverse();
            let (lo, dl) = (inv.transform_point3(o), inv.transform_vector3(d));
            let t1 = (-self.half - lo) / dl;
            let t2 = (self.half - lo) / dl;
            let near = t1.min(t2).max_element();
            let far = t1.max(t2).min_element();
            let boxed = (near <= far && near > 0.0).then_some(near);
            let wall = (d.z < 0.0).then(|| (self.wall_z - o.z) / d.z);
            match (boxed, wall) {
                (Some(b), Some(w)) => Some(b.min(w)),
                (b, w) => b.or(w),
            }
        }
    }

    /// A box translating and yawing in front of a wall, a rig moving forward: on the box's
    /// front face the flow is the projection of the point moved by the test's own rotation and
    /// translation; on the wall it is the static world's; the wall the box moves over is
    /// occluded.
    #[test]
    fn a_moving_box_flows_with_its_motion_and_hides_the_wall() {
        let (w, h, f) = (80u32, 60u32, 70.0f32);
        let now = rig(Vec3::new(0.0, 0.0, 0.0), 0.0, w, h, f);
        let next = rig(Vec3::new(0.0, 0.0, -0.5), 0.0, w, h, f);
        let half = Vec3::new(1.0, 0.8, 0.5);
        let (yaw, shift) = (0.2f32, Vec3::new(1.2, 0.1, -0.3));
        let box_now = Affine3A::from_translation(Vec3::new(-0.5, 0.0, -8.0));
        let box_next = Affine3A::from_translation(Vec3::new(-0.5, 0.0, -8.0) + shift)
            * Affine3A::from_rotation_y(yaw);
        let scene_now = BoxOnWall {
            world_from_box: box_now,
            half,
            wall_z: -20.0,
        };
        let scene_next = BoxOnWall {
            world_from_box: box_next,
            ..scene_now
        };
        // The instance map: the box's pixels are those whose ray meets the front face z = -7.5
        // within the face (the test's own ray-plane intersection).
        let cam = rig(Vec3::ZERO, 0.0, w, h, f);
        let left = cam.world_from_eye(Eye::Left).translation;
        let face_hit = |x: usize, y: usize| -> Option<DVec3> {
            let px = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let dir = DVec3::new(
                (px.x - f64::from(w) / 2.0) / f64::from(f),
                -(px.y - f64::from(h) / 2.0) / f64::from(f),
                -1.0,
            );
            let o = Vec3::from(left).as_dvec3();
            let t = (-7.5 - o.z) / dir.z;
            let p = o + dir * t;
            ((p.x + 0.5).abs() < 0.99 && p.y.abs() < 0.79).then_some(p)
        };
        let mut ids = vec![0u32; (w * h) as usize];
        for y in 0..h as usize {
            for x in 0..w as usize {
                if face_hit(x, y).is_some() {
                    ids[y * w as usize + x] = 7;
                }
            }
        }
        let mut motion = ObjectMotion::new();
        motion.insert(7, box_now, box_next);
        let flow = left_flow(&now, &next, &scene_now, &scene_next, &ids, &motion).unwrap();
        // The test's own motion: rotate about the box centre by yaw, then shift.
        let centre = DVec3::new(-0.5, 0.0, -8.0);
        let (s, c) = f64::from(yaw).sin_cos();
        let rotate = |p: DVec3| {
            let q = p - centre;
            centre + DVec3::new(c * q.x + s * q.z, q.y, -s * q.x + c * q.z) + shift.as_dvec3()
        };
        let left_next = Vec3::from(next.world_from_eye(Eye::Left).translation).as_dvec3();
        let project = |p: DVec3| {
            let q = p - left_next;
            DVec2::new(
                f64::from(w) / 2.0 + f64::from(f) * q.x / -q.z,
                f64::from(h) / 2.0 - f64::from(f) * q.y / -q.z,
            )
        };
        let (mut on_box, mut on_wall, mut hidden) = (0, 0, 0);
        for y in 0..h as usize {
            for x in 0..w as usize {
                let i = y * w as usize + x;
                let px = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let got = DVec2::new(f64::from(flow.flow[i][0]), f64::from(flow.flow[i][1]));
                if let Some(p) = face_hit(x, y) {
                    let expected = project(rotate(p)) - px;
                    assert!(
                        (got - expected).length() < 1e-3,
                        "box ({x}, {y}): {got} vs {expected}"
                    );
                    on_box += 1;
                } else if flow.state[i] != FlowState::OutOfView {
                    // The wall: static, seen from 0.5 m nearer.
                    let o = Vec3::from(left).as_dvec3();
                    let dir = DVec3::new(
                        (px.x - f64::from(w) / 2.0) / f64::from(f),
                        -(px.y - f64::from(h) / 2.0) / f64::from(f),
                        -1.0,
                    );
                    let p = o + dir * ((-20.0 - o.z) / dir.z);
                    if scene_now
                        .first_hit(o.as_vec3(), dir.normalize().as_vec3())
                        .unwrap()
                        < 11.0
                    {
                        continue; // the box's side faces
                    }
                    let expected = project(p) - px;
                    assert!((got - expected).length() < 1e-3, "wall ({x}, {y})");
                    // Whether the moved box lies on the segment from the next eye to the wall
                    // point: sampled every centimetre against the box shrunk or grown by 3 cm.
                    let in_box = |q: DVec3, margin: f64| {
                        let r = q - centre - shift.as_dvec3();
                        let m = DVec3::new(c * r.x - s * r.z, r.y, s * r.x + c * r.z);
                        (m.abs() - half.as_dvec3() + DVec3::splat(margin)).max_element() < 0.0
                    };
                    let crosses = |margin: f64| {
                        (1..2000).any(|k| {
                            in_box(left_next + (p - left_next) * (k as f64 / 2000.0), margin)
                        })
                    };
                    if crosses(0.03) {
                        assert_eq!(flow.state[i], FlowState::Occluded, "wall ({x}, {y})");
                        hidden += 1;
                    } else if !crosses(-0.03) {
                        assert_eq!(flow.state[i], FlowState::Visible, "wall ({x}, {y})");
                        on_wall += 1;
                    }
                }
            }
        }
        assert!(
            on_box > 200 && on_wall > 500 && hidden > 20,
            "{on_box} {on_wall} {hidden}"
        );
    }

    /// An instance map of the wrong size and rigs of different sizes are errors.
    #[test]
    fn mismatched_inputs_are_errors() {
        let a = rig(Vec3::Y, 0.0, 8, 6, 10.0);
        let b = rig(Vec3::Y, 0.0, 8, 7, 10.0);
        let m = ObjectMotion::new();
        assert!(left_flow(&a, &b, &Ground, &Ground, &[0; 48], &m).is_err());
        assert!(left_flow(&a, &a, &Ground, &Ground, &[0; 47], &m).is_err());
        assert_eq!(FlowState::from_mask_value(128), Some(FlowState::Occluded));
        assert_eq!(FlowState::from_mask_value(1), None);
    }
}
