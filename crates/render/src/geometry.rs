//! Rays, shading frames and robust ray offsets.

use crate::normal_map::MappedNormal;
use glam::{Vec2, Vec3, Vec4};

/// A ray `origin + t * direction` for `t` in `[0, t_max)`; `direction` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (already offset off any surface it leaves).
    pub origin: Vec3,
    /// Unit direction.
    pub direction: Vec3,
    /// Largest parameter of interest (`f32::INFINITY` for an unbounded ray).
    pub t_max: f32,
    /// The instant the ray samples, seconds from the reference time 0 ([`crate::motion`]);
    /// rays a path spawns inherit it.
    pub time: f32,
}

impl Ray {
    /// A ray with unbounded extent.
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Self {
            origin,
            direction,
            t_max: f32::INFINITY,
            time: 0.0,
        }
    }

    /// The same ray at time `time`.
    #[inline]
    pub fn at_time(self, time: f32) -> Self {
        Self { time, ..self }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }
}

/// The vertex attributes materials read, interpolated at a surface point: the two texture
/// coordinate sets (`TEXCOORD_1` is `TEXCOORD_0` where the scene has no second set) and the
/// vertex colour `COLOR_0` (linear RGBA, white where the scene has none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexAttributes {
    /// `TEXCOORD_0` and `TEXCOORD_1`.
    pub uv: [Vec2; 2],
    /// `COLOR_0`, linear RGBA.
    pub color: Vec4,
}

impl VertexAttributes {
    /// The attributes of a point with texture coordinates `uv` (both sets) and no vertex
    /// colour (white).
    #[inline]
    pub fn from_uv(uv: Vec2) -> Self {
        Self {
            uv: [uv; 2],
            color: Vec4::ONE,
        }
    }
}

/// A ray's closest intersection with a scene's triangles (what [`crate::scene::Scene::intersect`]
/// returns).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// World position.
    pub p: Vec3,
    /// Unit geometric normal (from the winding, not flipped toward the ray).
    pub ng: Vec3,
    /// Unit interpolated shading normal (oriented to the same side as `ng`).
    pub ns: Vec3,
    /// Where a normal map set `ns`: the smooth and the mapped normal, for the diffuse lobe
    /// ([`crate::normal_map::MappedNormal`]); `None` elsewhere.
    pub mapped: Option<MappedNormal>,
    /// A clear-coated material's coat normal (unit, world space, on the side of `ng`) where it
    /// is not `ns`: through the coat's normal map (clearcoatNormalTexture), or the
    /// interpolated normal where only the base is normal mapped; `None` elsewhere.
    pub coat_normal: Option<Vec3>,
    /// Texture coordinates and vertex colour.
    pub attributes: VertexAttributes,
    /// Index of the scene's flat triangle, or [`crate::scene::INSTANCED_TRIANGLE`] for a
    /// triangle of an instanced mesh.
    pub triangle: u32,
    /// Material index.
    pub material: u32,
    /// The slot in [`crate::scene::Scene::objects`] of what the hit is part of (the
    /// unlabelled object for a rain drop).
    pub object: u32,
}

/// An orthonormal frame; `n` is the local +Z axis (the shading normal).
///
/// BSDFs work in this local frame: `cos(theta) = w.z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Local +X.
    pub s: Vec3,
    /// Local +Y.
    pub t: Vec3,
    /// Local +Z, the normal.
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit normal `n` (Duff et al. 2017, branchless ONB).
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let (s, t) = n.any_orthonormal_pair();
        Self { s, t, n }
    }

    /// World to local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local to world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Offsets a ray origin at surface point `p` with geometric normal `ng` to the side of `w`,
/// so that the new ray does not hit the surface it leaves (Wächter and Binder, Ray Tracing
/// Gems ch. 6: an integer ULP offset that scales with the magnitude of `p`).
#[inline]
pub fn offset_ray_origin(p: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let n = if ng.dot(w) < 0.0 { -ng } else { ng };
    let of_i = [
        (INT_SCALE * n.x) as i32,
        (INT_SCALE * n.y) as i32,
        (INT_SCALE * n.z) as i32,
    ];
    let pc = [p.x, p.y, p.z];
    let nc = [n.x, n.y, n.z];
    let mut out = [0.0f32; 3];
    for k in 0..3 {
        let bits = pc[k].to_bits() as i32;
        let moved = f32::from_bits((bits + if pc[k] < 0.0 { -of_i[k] } else { of_i[k] }) as u32);
        out[k] = if pc[k].abs() < ORIGIN {
            pc[k] + FLOAT_SCALE * nc[k]
        } else {
            moved
        };
    }
    Vec3::from_array(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_round_trip() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::Y,
        ] {
            let f = Frame::from_normal(n);
            let v = Vec3::new(0.2, -0.7, 0.5);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-6);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-6);
            assert!(f.s.dot(f.t).abs() < 1e-6 && f.s.cross(f.t).dot(n) > 0.999);
        }
    }

    #[test]
    fn offset_moves_to_the_right_side() {
        for p in [
            Vec3::ZERO,
            Vec3::new(1e4, 0.0, -3e3),
            Vec3::new(-0.01, 0.0, 12.0),
        ] {
            let up = offset_ray_origin(p, Vec3::Y, Vec3::Y);
            let down = offset_ray_origin(p, Vec3::Y, -Vec3::Y);
            assert!(up.y > p.y && down.y < p.y, "{p} -> {up} {down}");
        }
    }
}
