//! The cameras of docs/design.md: a pinhole (perspective) camera or an orthographic one, and
//! the default camera that frames a scene which has none.
//!
//! A glTF camera looks along its node's local -Z with local +Y up. Pixels: x to the right,
//! y down; pixel (i, j) covers [i, i+1) x [j, j+1).
//!
//! - Perspective: focal length in pixels `f = (H/2) / tan(yfov/2)`, principal point at the
//!   image centre; every ray starts at the eye (znear is not used: nothing is clipped).
//! - Orthographic: `xmag` and `ymag` are the half-width and half-height of the view in metres
//!   (the glTF specification's `r` and `t`). Pixels are square: one pixel is
//!   `s = max(2 xmag / W, 2 ymag / H)` metres, so an image whose aspect ratio differs from
//!   `xmag / ymag` shows the whole `2 xmag` x `2 ymag` rectangle and more along the other axis
//!   (the specification says not to stretch). The ray of film position `(x, y)` starts on the
//!   camera plane at `((x - W/2) s, (H/2 - y) s, 0)` in camera space and runs along -Z; as for
//!   perspective cameras, znear is not used (geometry behind the camera plane is not seen).
//! - The default camera ([`Camera::framing`]) is the glTF sample viewer's: see there.

use crate::geometry::Ray;
use glam::{Affine3A, BVec3, Quat, Vec2, Vec3};

/// How a camera maps film positions to rays: the closed set of glTF's camera types.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// A pinhole camera.
    Perspective {
        /// Vertical field of view in radians.
        yfov: f32,
        /// Aspect ratio (width / height) if the scene gives one.
        aspect_ratio: Option<f32>,
    },
    /// An orthographic camera (parallel rays along -Z).
    Orthographic {
        /// Half the width of the view in metres (glTF's `xmag`), above 0.
        xmag: f32,
        /// Half the height of the view in metres (glTF's `ymag`), above 0.
        ymag: f32,
    },
}

/// A camera: a name, a rigid pose and a [`Projection`].
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Name from the scene (the node's or the camera's), used by `--camera`.
    pub name: String,
    /// Rigid transform from camera space (looking along -Z, +Y up, +X right) to world space.
    pub world_from_camera: Affine3A,
    /// Perspective or orthographic, with its parameters.
    pub projection: Projection,
}

/// The default camera's vertical field of view: the glTF sample viewer's 45 degrees.
pub const FRAMING_YFOV: f32 = std::f32::consts::FRAC_PI_4;

/// The name of the default camera ([`Camera::framing`]).
pub const FRAMING_NAME: &str = "default";

/// How far above the horizon the default camera looks down at the scene: 25 degrees, so that
/// a flat model lying in the XZ plane (the ground of a street, TwoSidedPlane) is seen and not
/// edge-on, while a model facing +Z is foreshortened by only cos 25 = 0.91.
pub const FRAMING_ELEVATION: f32 = 25.0 * std::f32::consts::PI / 180.0;

/// What the command says when it uses the default camera.
pub const FRAMING_WARNING: &str = "scene has no camera: framed its bounds from +Z, 25 degrees \
     above the horizon, with a 45 degree field of view";

impl Camera {
    /// A perspective camera.
    pub fn perspective(
        name: impl Into<String>,
        world_from_camera: Affine3A,
        yfov: f32,
        aspect_ratio: Option<f32>,
    ) -> Camera {
        Camera {
            name: name.into(),
            world_from_camera,
            projection: Projection::Perspective { yfov, aspect_ratio },
        }
    }

    /// An orthographic camera of half-extents `xmag` x `ymag` metres.
    pub fn orthographic(
        name: impl Into<String>,
        world_from_camera: Affine3A,
        xmag: f32,
        ymag: f32,
    ) -> Camera {
        Camera {
            name: name.into(),
            world_from_camera,
            projection: Projection::Orthographic { xmag, ymag },
        }
    }

    /// The default camera for a scene of bounding box `bounds` (`[min, max]`, as
    /// [`union_bounds`] makes it), for an image of aspect ratio `aspect` (width / height): the
    /// glTF sample viewer's distance rule, seen from [`FRAMING_ELEVATION`] above the horizon
    /// and moved back so that all of the box is in view.
    ///
    /// A perspective camera of [`FRAMING_YFOV`] with +Y up in the plane of its view, looking
    /// along `-Z` pitched down by the elevation (from `+Z` and above). In the camera's axes
    /// the box's eight corners span `w` across and `h` up the view; the camera sits on the
    /// axis through the box's centre at `D = max(h/2 / tan(yfov/2), w/2 / tan(xfov/2))`
    /// (`xfov = 2 atan(aspect tan(yfov/2))`) in front of the plane that touches the box's
    /// nearest corner. The viewer takes `D` from the box's centre, with `m = max(w, h)` for
    /// both terms, looking straight along -Z with `xfov = yfov * aspect`: that cuts the front
    /// of deep scenes at the image's edge and sees a flat model lying in the XZ plane
    /// edge-on. Measured from the nearest plane, that plane's `w` x `h` rectangle fills the
    /// limiting axis exactly and everything behind it is smaller, so every point of the box
    /// is in view and in front of the camera. A degenerate box (a point) is framed as a box
    /// of size 1.
    pub fn framing(bounds: [Vec3; 2], aspect: f32) -> Camera {
        let [lo, hi] = bounds;
        let centre = 0.5 * (lo + hi);
        let rotation = Quat::from_rotation_x(-FRAMING_ELEVATION);
        let to_camera = rotation.inverse();
        // The box's corners about its centre, in the camera's axes.
        let (mut span, mut near) = (Vec2::ZERO, 0.0f32);
        for k in 0..8 {
            let corner = Vec3::select(BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo);
            let c = to_camera * (corner - centre);
            span = span.max(c.truncate().abs());
            near = near.max(c.z);
        }
        if !span.is_finite() || span.max_element() <= 0.0 {
            span = Vec2::splat(0.5);
        }
        let tan_half_y = (0.5 * FRAMING_YFOV).tan();
        let tan_half_x = aspect * tan_half_y;
        let distance = (span.y / tan_half_y).max(span.x / tan_half_x);
        let position = centre + rotation * Vec3::new(0.0, 0.0, near + distance);
        Camera::perspective(
            FRAMING_NAME,
            Affine3A::from_rotation_translation(rotation, position),
            FRAMING_YFOV,
            Some(aspect),
        )
    }

    /// The vertical field of view in radians of a perspective camera.
    #[inline]
    pub fn yfov(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective { yfov, .. } => Some(yfov),
            Projection::Orthographic { .. } => None,
        }
    }

    /// Whether this is an orthographic camera.
    #[inline]
    pub fn is_orthographic(&self) -> bool {
        matches!(self.projection, Projection::Orthographic { .. })
    }

    /// The aspect ratio (width / height) the image should have when no size is given: a
    /// perspective camera's `aspectRatio` if the scene gives one, an orthographic camera's
    /// `xmag / ymag`.
    #[inline]
    pub fn aspect_ratio(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective { aspect_ratio, .. } => aspect_ratio,
            Projection::Orthographic { xmag, ymag } => Some(xmag / ymag),
        }
    }

    /// Focal length in pixels of a perspective camera for an image `height` pixels tall.
    #[inline]
    pub fn focal_px(&self, height: u32) -> Option<f32> {
        self.yfov().map(|yfov| focal(yfov, height))
    }

    /// The size of one (square) pixel in metres of an orthographic camera for a `width` x
    /// `height` image: `max(2 xmag / W, 2 ymag / H)`.
    #[inline]
    pub fn pixel_metres(&self, width: u32, height: u32) -> Option<f32> {
        match self.projection {
            Projection::Orthographic { xmag, ymag } => Some(ortho_pixel(xmag, ymag, width, height)),
            Projection::Perspective { .. } => None,
        }
    }

    /// Camera position in world space (an orthographic camera's: the centre of its plane).
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.world_from_camera.translation.into()
    }

    /// The primary ray through film position `film` (continuous pixel coordinates, pixel
    /// centres at `i + 0.5`) of a `width` x `height` image.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, width: u32, height: u32) -> Ray {
        match self.projection {
            Projection::Perspective { yfov, .. } => {
                let f = focal(yfov, height);
                let x = film.x - 0.5 * width as f32;
                let y = 0.5 * height as f32 - film.y;
                let dir_cam = Vec3::new(x, y, -f).normalize();
                let dir = self
                    .world_from_camera
                    .transform_vector3(dir_cam)
                    .normalize();
                Ray::new(self.position(), dir)
            }
            Projection::Orthographic { xmag, ymag } => {
                let s = ortho_pixel(xmag, ymag, width, height);
                let x = (film.x - 0.5 * width as f32) * s;
                let y = (0.5 * height as f32 - film.y) * s;
                let origin = self
                    .world_from_camera
                    .transform_point3(Vec3::new(x, y, 0.0));
                let dir = self
                    .world_from_camera
                    .transform_vector3(Vec3::NEG_Z)
                    .normalize();
                Ray::new(origin, dir)
            }
        }
    }

    /// Projects a world point to continuous pixel coordinates; `None` behind the camera (for
    /// an orthographic camera: behind or on its plane).
    #[inline]
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> Option<Vec2> {
        let pc = self.world_from_camera.inverse().transform_point3(p);
        if pc.z >= 0.0 {
            return None;
        }
        let (w2, h2) = (0.5 * width as f32, 0.5 * height as f32);
        match self.projection {
            Projection::Perspective { yfov, .. } => {
                let f = focal(yfov, height);
                let depth = -pc.z;
                Some(Vec2::new(w2 + f * pc.x / depth, h2 - f * pc.y / depth))
            }
            Projection::Orthographic { xmag, ymag } => {
                let s = ortho_pixel(xmag, ymag, width, height);
                Some(Vec2::new(w2 + pc.x / s, h2 - pc.y / s))
            }
        }
    }
}

/// `f = (H/2) / tan(yfov/2)`.
#[inline]
fn focal(yfov: f32, height: u32) -> f32 {
    0.5 * height as f32 / (0.5 * yfov).tan()
}

/// Metres per pixel of an orthographic view: the larger of the two axes' needs.
#[inline]
fn ortho_pixel(xmag: f32, ymag: f32, width: u32, height: u32) -> f32 {
    (2.0 * xmag / width as f32).max(2.0 * ymag / height as f32)
}

/// The bounds the default camera frames: the union of the boxes `[min, max]` (the loaded
/// primitives' world-space bounding boxes). The glTF sample viewer first replaces each box by
/// the cube of half-size its half-diagonal, which keeps a model in view while the user orbits
/// it; a camera that does not orbit frames the boxes themselves, and a tall or flat model
/// fills the image instead of a third of it. `None` without boxes.
pub fn union_bounds(boxes: impl IntoIterator<Item = [Vec3; 2]>) -> Option<[Vec3; 2]> {
    boxes
        .into_iter()
        .filter(|[lo, hi]| lo.cmple(*hi).all())
        .reduce(|[a, b], [c, d]| [a.min(c), b.max(d)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_down_minus_z_and_projection_round_trips() {
        let cam = Camera::perspective(
            "c",
            Affine3A::from_rotation_translation(
                Quat::from_rotation_y(0.3),
                Vec3::new(1.0, 1.5, 2.0),
            ),
            0.8,
            None,
        );
        let (w, h) = (64, 48);
        let r = cam.generate_ray(Vec2::new(32.0, 24.0), w, h);
        let fwd = cam.world_from_camera.transform_vector3(-Vec3::Z);
        assert!((r.direction - fwd).length() < 1e-5);
        let px = Vec2::new(10.25, 40.5);
        let r = cam.generate_ray(px, w, h);
        let back = cam.project(r.at(7.0), w, h).unwrap();
        assert!((back - px).length() < 1e-3, "{back}");
    }

    fn ortho() -> Camera {
        Camera::orthographic(
            "o",
            Affine3A::from_rotation_translation(
                Quat::from_euler(glam::EulerRot::YXZ, 0.4, -0.3, 0.1),
                Vec3::new(-1.0, 2.0, 3.0),
            ),
            2.0,
            1.0,
        )
    }

    #[test]
    fn orthographic_rays_are_parallel_start_on_the_plane_and_round_trip() {
        let cam = ortho();
        let (w, h) = (80, 40);
        let fwd = cam.world_from_camera.transform_vector3(Vec3::NEG_Z);
        let to_cam = cam.world_from_camera.inverse();
        for px in [
            Vec2::new(0.0, 0.0),
            Vec2::new(40.0, 20.0),
            Vec2::new(79.5, 3.25),
        ] {
            let r = cam.generate_ray(px, w, h);
            assert!((r.direction - fwd).length() < 1e-6);
            let o = to_cam.transform_point3(r.origin);
            assert!(o.z.abs() < 1e-5, "{o}");
            let back = cam.project(r.at(5.0), w, h).unwrap();
            assert!((back - px).length() < 1e-3, "{back} vs {px}");
        }
        // The corners of the film are the corners of the 2 xmag x 2 ymag rectangle.
        let c = to_cam.transform_point3(cam.generate_ray(Vec2::ZERO, w, h).origin);
        assert!((c - Vec3::new(-2.0, 1.0, 0.0)).length() < 1e-5, "{c}");
        let c = to_cam.transform_point3(cam.generate_ray(Vec2::new(80.0, 40.0), w, h).origin);
        assert!((c - Vec3::new(2.0, -1.0, 0.0)).length() < 1e-5, "{c}");
        assert!(cam.project(cam.position() + fwd * -0.1, w, h).is_none());
        assert_eq!(cam.aspect_ratio(), Some(2.0));
        assert_eq!(cam.yfov(), None);
    }

    #[test]
    fn orthographic_pixels_stay_square_when_the_aspect_differs() {
        let cam = ortho(); // 4 m x 2 m
        let to_cam = cam.world_from_camera.inverse();
        let corner = |w, h| to_cam.transform_point3(cam.generate_ray(Vec2::ZERO, w, h).origin);
        // Square image: x (the larger half-extent) wins, y grows to 2 m.
        assert!((corner(40, 40) - Vec3::new(-2.0, 2.0, 0.0)).length() < 1e-5);
        // Very wide image (8:1, the view 2:1): y wins, the half-width grows to 8 m.
        let c = corner(160, 20);
        assert!((c - Vec3::new(-8.0, 1.0, 0.0)).length() < 1e-4, "{c}");
        assert_eq!(cam.pixel_metres(160, 20), Some(0.1));
    }

    #[test]
    fn union_bounds_unite_the_boxes() {
        assert_eq!(union_bounds([]), None);
        let b = union_bounds([
            [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0)],
            [Vec3::splat(10.0), Vec3::splat(10.0)],
            [Vec3::ONE, Vec3::ZERO],
        ])
        .unwrap();
        assert_eq!(b, [Vec3::ZERO, Vec3::splat(10.0)]);
    }

    /// The default camera frames known boxes: every corner of the bounds projects inside the
    /// image, the corners' projections fill most of the limiting axis (the box is not lost in
    /// the distance), the camera looks down at the elevation, and a flat square lying in the
    /// XZ plane covers a good part of the image instead of being seen edge-on.
    #[test]
    fn framing_sees_the_whole_box_and_fills_the_image() {
        let boxes = [
            [Vec3::new(-1.0, 2.0, -3.0), Vec3::new(1.0, 3.0, -2.0)],
            [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0)],
            [Vec3::new(5.0, -1.0, -40.0), Vec3::new(6.0, 1.0, 2.0)],
        ];
        for [lo, hi] in boxes {
            for (aspect, w, h) in [(4.0 / 3.0, 640, 480), (0.5, 200, 400), (3.0, 600, 200)] {
                let bounds = union_bounds([[lo, hi]]).unwrap();
                let cam = Camera::framing(bounds, aspect);
                assert_eq!(cam.yfov(), Some(FRAMING_YFOV));
                let forward = cam.world_from_camera.transform_vector3(-Vec3::Z);
                assert!(
                    (forward.y + FRAMING_ELEVATION.sin()).abs() < 1e-5,
                    "{forward}"
                );
                let [blo, bhi] = bounds;
                let (mut min, mut max) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
                for k in 0..8 {
                    let p = Vec3::select(BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), bhi, blo);
                    let px = cam.project(p, w, h).expect("in front");
                    assert!(
                        (0.0..=w as f32).contains(&px.x) && (0.0..=h as f32).contains(&px.y),
                        "{lo} {hi}, aspect {aspect}: corner {p} at {px}"
                    );
                    (min, max) = (min.min(px), max.max(px));
                }
                let fill = ((max.x - min.x) / w as f32).max((max.y - min.y) / h as f32);
                assert!(fill > 0.6, "{lo} {hi}, aspect {aspect}: fills {fill}");
            }
        }
        // The flat square (the second box) is seen from above.
        let [lo, hi] = boxes[1];
        let cam = Camera::framing(union_bounds([[lo, hi]]).unwrap(), 4.0 / 3.0);
        let corners = [
            lo,
            Vec3::new(hi.x, 0.0, lo.z),
            hi,
            Vec3::new(lo.x, 0.0, hi.z),
        ];
        let px: Vec<Vec2> = corners
            .iter()
            .map(|&p| cam.project(p, 640, 480).unwrap())
            .collect();
        let far_edge = px[0].y.max(px[1].y);
        let near_edge = px[2].y.min(px[3].y);
        assert!(near_edge - far_edge > 0.1 * 480.0, "{px:?}");
    }

    #[test]
    fn framing_stays_outside_a_deep_scene() {
        // Two small boxes 100 m apart along Z: the viewer's distance would put the camera
        // between them.
        let bounds = union_bounds([
            [Vec3::splat(-0.5), Vec3::splat(0.5)],
            [Vec3::new(-0.5, -0.5, -100.5), Vec3::new(0.5, 0.5, -99.5)],
        ])
        .unwrap();
        let cam = Camera::framing(bounds, 1.0);
        assert!(cam.position().z > bounds[1].z, "{}", cam.position());
        for p in [Vec3::ZERO, Vec3::new(0.0, 0.0, -100.0)] {
            assert!(cam.project(p, 100, 100).is_some());
        }
    }

    /// An orthographic render of an analytic case: an emissive rectangle facing the camera
    /// covers exactly the pixels its size in metres predicts, at depth 1 everywhere.
    #[test]
    fn orthographic_render_fills_exactly_the_expected_pixels() {
        use crate::integrator::{render, Layers, RenderJob};
        use crate::material::Material;
        use crate::scene::{Scene, SceneParts};
        let mut glow = Material::diffuse("glow", Vec3::ZERO);
        glow.emission = Vec3::splat(2.0);
        let mut parts = SceneParts {
            materials: vec![glow],
            ..SceneParts::default()
        };
        // 1.2 m x 0.5 m at z = -1, seen by a 4 m x 2 m view of 40 x 20 pixels (0.1 m each):
        // columns 15..27, rows 8..13.
        crate::integrator::tests::quad(
            &mut parts,
            [
                Vec3::new(-0.5, -0.3, -1.0),
                Vec3::new(0.7, -0.3, -1.0),
                Vec3::new(0.7, 0.2, -1.0),
                Vec3::new(-0.5, 0.2, -1.0),
            ],
            0,
        );
        let scene = Scene::from_parts(parts).unwrap();
        let cam = Camera::orthographic("o", Affine3A::IDENTITY, 2.0, 1.0);
        let job = RenderJob {
            width: 40,
            height: 20,
            seed: 1,
            layers: Layers {
                depth: true,
                ..Layers::default()
            },
            settings: streaks_settings::RenderSettings::new(16, 1),
            motion: Default::default(),
        };
        let out = render(&scene, &cam, &job, &|_| {});
        let depth = out.depth.as_ref().unwrap();
        let mut lit = 0;
        for y in 0..20u32 {
            for x in 0..40u32 {
                let inside = (15..27).contains(&x) && (8..13).contains(&y);
                let v = out.image.get(x, y).x;
                let d = depth[(y * 40 + x) as usize];
                if inside {
                    lit += 1;
                    assert!((v - 2.0).abs() < 1e-5, "({x}, {y}) = {v}");
                    assert!((d - 1.0).abs() < 1e-5, "depth ({x}, {y}) = {d}");
                } else {
                    assert_eq!(v, 0.0, "({x}, {y})");
                    assert!(d.is_infinite() || d == 0.0, "depth ({x}, {y}) = {d}");
                }
            }
        }
        assert_eq!(lit, 12 * 5);
    }
}
