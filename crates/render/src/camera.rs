//! The pinhole camera of docs/design.md.
//!
//! A glTF perspective camera looks along its node's local -Z with local +Y up. Pixels: x to
//! the right, y down; pixel (i, j) covers [i, i+1) x [j, j+1). Focal length in pixels
//! `f = (H/2) / tan(yfov/2)`, principal point at the image centre.

use crate::geometry::Ray;
use glam::{Affine3A, Vec2, Vec3};

/// A perspective pinhole camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Name from the scene (the node's or the camera's), used by `--camera`.
    pub name: String,
    /// Rigid transform from camera space (looking along -Z, +Y up, +X right) to world space.
    pub world_from_camera: Affine3A,
    /// Vertical field of view in radians.
    pub yfov: f32,
    /// Aspect ratio (width / height) if the scene gives one.
    pub aspect_ratio: Option<f32>,
}

impl Camera {
    /// Focal length in pixels for an image `height` pixels tall.
    #[inline]
    pub fn focal_px(&self, height: u32) -> f32 {
        0.5 * height as f32 / (0.5 * self.yfov).tan()
    }

    /// Camera position in world space.
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.world_from_camera.translation.into()
    }

    /// The primary ray through film position `film` (continuous pixel coordinates, pixel
    /// centres at `i + 0.5`) of a `width` x `height` image.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, width: u32, height: u32) -> Ray {
        let f = self.focal_px(height);
        let x = film.x - 0.5 * width as f32;
        let y = 0.5 * height as f32 - film.y;
        let dir_cam = Vec3::new(x, y, -f).normalize();
        let dir = self
            .world_from_camera
            .transform_vector3(dir_cam)
            .normalize();
        Ray::new(self.position(), dir)
    }

    /// Projects a world point to continuous pixel coordinates; `None` behind the camera.
    #[inline]
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> Option<Vec2> {
        let pc = self.world_from_camera.inverse().transform_point3(p);
        if pc.z >= 0.0 {
            return None;
        }
        let f = self.focal_px(height);
        let depth = -pc.z;
        Some(Vec2::new(
            0.5 * width as f32 + f * pc.x / depth,
            0.5 * height as f32 - f * pc.y / depth,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn centre_ray_looks_down_minus_z_and_projection_round_trips() {
        let cam = Camera {
            name: "c".into(),
            world_from_camera: Affine3A::from_rotation_translation(
                Quat::from_rotation_y(0.3),
                Vec3::new(1.0, 1.5, 2.0),
            ),
            yfov: 0.8,
            aspect_ratio: None,
        };
        let (w, h) = (64, 48);
        let r = cam.generate_ray(Vec2::new(32.0, 24.0), w, h);
        let fwd = cam.world_from_camera.transform_vector3(-Vec3::Z);
        assert!((r.direction - fwd).length() < 1e-5);
        let px = Vec2::new(10.25, 40.5);
        let r = cam.generate_ray(px, w, h);
        let back = cam.project(r.at(7.0), w, h).unwrap();
        assert!((back - px).length() < 1e-3, "{back}");
    }
}
