//! Triangle meshes in world coordinates built from simple solids (quads, boxes, vertical
//! cylinders, UV spheres). Every triangle is wound counter-clockwise seen from the side its
//! normals point to (the glTF front face), which matters for one-sided emitters.

use glam::{Vec2, Vec3};

/// An indexed triangle mesh with per-vertex normals and texture coordinates.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions (metres, world space).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (glTF convention: v down the image); [`Mesh::rect`],
    /// [`Mesh::cuboid`] and [`Mesh::cylinder`] give them in metres along the surface.
    pub uvs: Vec<Vec2>,
    /// Triangle vertex indices.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// An empty mesh.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Divides every texture coordinate by `metres` (texture coordinates in metres become
    /// tiles of a texture covering `metres` x `metres`).
    pub fn scale_uvs(&mut self, metres: f32) {
        for t in &mut self.uvs {
            *t /= metres;
        }
    }

    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.positions.push(p);
        self.normals.push(n.normalize());
        self.uvs.push(uv);
        (self.positions.len() - 1) as u32
    }

    /// Pushes triangle (a, b, c), swapping two vertices if needed so that its geometric
    /// normal points along `outward`.
    fn triangle(&mut self, a: u32, b: u32, c: u32, outward: Vec3) {
        let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
        if (pb - pa).cross(pc - pa).dot(outward) >= 0.0 {
            self.indices.extend([a, b, c]);
        } else {
            self.indices.extend([a, c, b]);
        }
    }

    /// A flat quad with corners `p` (in order around it) and texture coordinates `uv`,
    /// facing `normal`.
    pub fn quad_uv(&mut self, p: [Vec3; 4], uv: [Vec2; 4], normal: Vec3) {
        let i: Vec<u32> = (0..4).map(|k| self.vertex(p[k], normal, uv[k])).collect();
        self.triangle(i[0], i[1], i[2], normal);
        self.triangle(i[0], i[2], i[3], normal);
    }

    /// A rectangle centred at `c` spanned by half-axes `u` and `v`, facing `u x v`; texture
    /// coordinates in metres (u along `u`, v against `v`).
    pub fn rect(&mut self, c: Vec3, u: Vec3, v: Vec3) {
        let p = [c - u - v, c + u - v, c + u + v, c - u + v];
        let (lu, lv) = (2.0 * u.length(), 2.0 * v.length());
        let uv = [
            Vec2::new(0.0, lv),
            Vec2::new(lu, lv),
            Vec2::new(lu, 0.0),
            Vec2::ZERO,
        ];
        self.quad_uv(p, uv, u.cross(v).normalize());
    }

    /// A smooth `nu x nv` grid of quads: `at(i, j)` gives the vertex (position, normal,
    /// texture coordinates) at column `i` in `0..=nu` and row `j` in `0..=nv`; each triangle
    /// faces its vertices' mean normal. Tessellated surfaces (a crowned road, strips that
    /// follow a curve) are grids.
    pub fn grid(&mut self, nu: usize, nv: usize, at: impl Fn(usize, usize) -> (Vec3, Vec3, Vec2)) {
        let first = self.positions.len() as u32;
        for j in 0..=nv {
            for i in 0..=nu {
                let (p, n, uv) = at(i, j);
                self.vertex(p, n, uv);
            }
        }
        let id = |i: usize, j: usize| first + (j * (nu + 1) + i) as u32;
        for j in 0..nv {
            for i in 0..nu {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                let mean = |v: [u32; 3]| v.iter().map(|&k| self.normals[k as usize]).sum();
                let (n0, n1): (Vec3, Vec3) = (mean([a, b, c]), mean([a, c, d]));
                self.triangle(a, b, c, n0);
                self.triangle(a, c, d, n1);
            }
        }
    }

    /// An axis-aligned box from `min` to `max` with outward faces.
    pub fn cuboid(&mut self, min: Vec3, max: Vec3) {
        let c = (min + max) * 0.5;
        let h = (max - min) * 0.5;
        let (x, y, z) = (Vec3::X * h.x, Vec3::Y * h.y, Vec3::Z * h.z);
        self.rect(c + x, y, z);
        self.rect(c - x, z, y);
        self.rect(c + y, z, x);
        self.rect(c - y, x, z);
        self.rect(c + z, x, y);
        self.rect(c - z, y, x);
    }

    /// A vertical cylinder (smooth sides, flat top cap, open bottom) standing on `base`; side
    /// texture coordinates in metres (u around, v down from the top).
    pub fn cylinder(&mut self, base: Vec3, radius: f32, height: f32, segments: u32) {
        let top = base + Vec3::Y * height;
        let ring = |k: u32| {
            let a = std::f32::consts::TAU * (k % segments) as f32 / segments as f32;
            Vec3::new(a.cos(), 0.0, -a.sin())
        };
        for k in 0..segments {
            let (d0, d1) = (ring(k), ring(k + 1));
            let arc = std::f32::consts::TAU * radius / segments as f32;
            let (u0, u1) = (k as f32 * arc, (k + 1) as f32 * arc);
            let b0 = self.vertex(base + d0 * radius, d0, Vec2::new(u0, height));
            let b1 = self.vertex(base + d1 * radius, d1, Vec2::new(u1, height));
            let t1 = self.vertex(top + d1 * radius, d1, Vec2::new(u1, 0.0));
            let t0 = self.vertex(top + d0 * radius, d0, Vec2::new(u0, 0.0));
            let out = (d0 + d1).normalize();
            self.triangle(b0, b1, t1, out);
            self.triangle(b0, t1, t0, out);
        }
        let c = self.vertex(top, Vec3::Y, Vec2::splat(0.5));
        for k in 0..segments {
            let a = self.vertex(top + ring(k) * radius, Vec3::Y, Vec2::splat(0.5));
            let b = self.vertex(top + ring(k + 1) * radius, Vec3::Y, Vec2::splat(0.5));
            self.triangle(c, a, b, Vec3::Y);
        }
    }

    /// A UV sphere with `rings` latitude bands and `segments` longitude sectors, outward
    /// normals; the poles are single vertices (no degenerate triangles).
    pub fn sphere(&mut self, centre: Vec3, radius: f32, rings: u32, segments: u32) {
        let dir = |r: u32, s: u32| {
            let phi = std::f32::consts::PI * r as f32 / rings as f32;
            let th = std::f32::consts::TAU * (s % segments) as f32 / segments as f32;
            Vec3::new(phi.sin() * th.cos(), phi.cos(), -phi.sin() * th.sin())
        };
        let first = self.positions.len() as u32;
        let uv = |r: u32, s: u32| Vec2::new(s as f32 / segments as f32, r as f32 / rings as f32);
        let north = self.vertex(centre + Vec3::Y * radius, Vec3::Y, Vec2::new(0.5, 0.0));
        // Rings 1..rings-1, each with `segments` vertices.
        for r in 1..rings {
            for s in 0..segments {
                let d = dir(r, s);
                self.vertex(centre + d * radius, d, uv(r, s));
            }
        }
        let south = self.vertex(centre - Vec3::Y * radius, -Vec3::Y, Vec2::new(0.5, 1.0));
        let at = |r: u32, s: u32| first + 1 + (r - 1) * segments + s % segments;
        for s in 0..segments {
            let out = dir(1, s) + dir(1, s + 1);
            self.triangle(north, at(1, s), at(1, s + 1), out);
            let out = dir(rings - 1, s) + dir(rings - 1, s + 1);
            self.triangle(south, at(rings - 1, s + 1), at(rings - 1, s), out);
        }
        for r in 1..rings - 1 {
            for s in 0..segments {
                let out = dir(r, s) + dir(r + 1, s + 1);
                let (a, b, c, d) = (at(r, s), at(r, s + 1), at(r + 1, s + 1), at(r + 1, s));
                self.triangle(a, b, c, out);
                self.triangle(a, c, d, out);
            }
        }
    }
}

/// Solids for modelled objects (cars, street furniture): flat-shaded facets, prisms from a
/// side profile, cylinders along any axis, ellipsoids and flat polygons.
impl Mesh {
    /// One flat triangle with its geometric normal, wound to face `outward`; texture
    /// coordinates are the corners' positions projected on the triangle's plane (metres).
    pub fn facet(&mut self, p: [Vec3; 3], outward: Vec3) {
        let g = (p[1] - p[0]).cross(p[2] - p[0]);
        if g.length_squared() < 1e-16 {
            return;
        }
        let n = if g.dot(outward) >= 0.0 {
            g.normalize()
        } else {
            -g.normalize()
        };
        let u = (p[1] - p[0]).normalize();
        let v = n.cross(u);
        let i: Vec<u32> = p
            .iter()
            .map(|&q| self.vertex(q, n, Vec2::new((q - p[0]).dot(u), (q - p[0]).dot(v))))
            .collect();
        self.triangle(i[0], i[1], i[2], n);
    }

    /// A flat convex polygon (corners in order around it), one-sided, facing `normal`.
    pub fn polygon(&mut self, p: &[Vec3], normal: Vec3) {
        for k in 1..p.len().saturating_sub(1) {
            self.facet([p[0], p[k], p[k + 1]], normal);
        }
    }

    /// A closed prism: the convex polygon `profile` in the (z, y) plane (corners in order
    /// around it, any orientation) extruded across X from `-half_width(y)` to
    /// `+half_width(y)`. A half width that falls linearly with height gives a body's
    /// tumblehome; the sides stay planar. Facets face away from the solid's centroid.
    pub fn prism(&mut self, profile: &[Vec2], half_width: impl Fn(f32) -> f32) {
        let n = profile.len();
        if n < 3 {
            return;
        }
        let at = |k: usize, side: f32| {
            let q = profile[k % n];
            Vec3::new(side * half_width(q.y), q.y, q.x)
        };
        let centre = profile
            .iter()
            .fold(Vec3::ZERO, |c, q| c + Vec3::new(0.0, q.y, q.x))
            / n as f32;
        let face = |m: &mut Mesh, t: [Vec3; 3]| {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            m.facet(t, c - centre);
        };
        for side in [-1.0f32, 1.0] {
            for k in 1..n - 1 {
                face(self, [at(0, side), at(k, side), at(k + 1, side)]);
            }
        }
        for k in 0..n {
            let (a, b) = (at(k, -1.0), at(k + 1, -1.0));
            let (c, d) = (at(k + 1, 1.0), at(k, 1.0));
            face(self, [a, b, c]);
            face(self, [a, c, d]);
        }
    }

    /// A closed cylinder from `a` to `b` (smooth sides, flat caps at both ends), outward.
    pub fn cylinder_between(&mut self, a: Vec3, b: Vec3, radius: f32, segments: u32) {
        let axis = (b - a).normalize();
        let (e1, e2) = axis.any_orthonormal_pair();
        let dir = |k: u32| {
            let t = std::f32::consts::TAU * (k % segments) as f32 / segments as f32;
            e1 * t.cos() + e2 * t.sin()
        };
        let height = (b - a).length();
        for k in 0..segments {
            let (d0, d1) = (dir(k), dir(k + 1));
            let arc = std::f32::consts::TAU * radius / segments as f32;
            let (u0, u1) = (k as f32 * arc, (k + 1) as f32 * arc);
            let i0 = self.vertex(a + d0 * radius, d0, Vec2::new(u0, height));
            let i1 = self.vertex(a + d1 * radius, d1, Vec2::new(u1, height));
            let j1 = self.vertex(b + d1 * radius, d1, Vec2::new(u1, 0.0));
            let j0 = self.vertex(b + d0 * radius, d0, Vec2::new(u0, 0.0));
            let out = (d0 + d1).normalize();
            self.triangle(i0, i1, j1, out);
            self.triangle(i0, j1, j0, out);
        }
        for (c, n) in [(a, -axis), (b, axis)] {
            let ci = self.vertex(c, n, Vec2::ZERO);
            for k in 0..segments {
                let (d0, d1) = (dir(k), dir(k + 1));
                let p = self.vertex(c + d0 * radius, n, (d0 * radius).truncate());
                let q = self.vertex(c + d1 * radius, n, (d1 * radius).truncate());
                self.triangle(ci, p, q, n);
            }
        }
    }

    /// A closed ellipsoid with semi-axes `radii` along X, Y and Z (a [`Mesh::sphere`]
    /// stretched, normals transformed with it).
    pub fn ellipsoid(&mut self, centre: Vec3, radii: Vec3, rings: u32, segments: u32) {
        let first = self.positions.len();
        self.sphere(Vec3::ZERO, 1.0, rings, segments);
        for k in first..self.positions.len() {
            self.positions[k] = centre + self.positions[k] * radii;
            self.normals[k] = (self.normals[k] / radii).normalize();
        }
    }

    /// A flat one-sided disc of `segments` sides facing `normal`.
    pub fn disc(&mut self, centre: Vec3, normal: Vec3, radius: f32, segments: u32) {
        let (e1, e2) = normal.normalize().any_orthonormal_pair();
        let ring: Vec<Vec3> = (0..segments)
            .map(|k| {
                let t = std::f32::consts::TAU * k as f32 / segments as f32;
                centre + (e1 * t.cos() + e2 * t.sin()) * radius
            })
            .collect();
        self.polygon(&ring, normal);
    }

    /// Smallest and largest corner of the axis-aligned box around the vertices.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's geometric normal agrees with its vertex normals and has non-zero area.
    fn check_winding(m: &Mesh) {
        for t in m.indices.chunks(3) {
            let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let g = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(g.length() > 1e-9, "degenerate triangle {t:?}");
            for &i in t {
                assert!(
                    g.dot(m.normals[i as usize]) > 0.0,
                    "triangle {t:?} wound backwards"
                );
                assert!((m.normals[i as usize].length() - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn box_faces_point_outward() {
        let mut m = Mesh::new();
        let (min, max) = (Vec3::new(-1.0, 0.0, -2.0), Vec3::new(1.0, 3.0, 0.5));
        m.cuboid(min, max);
        check_winding(&m);
        assert_eq!(m.triangle_count(), 12);
        let c = (min + max) * 0.5;
        for t in m.indices.chunks(3) {
            let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let g = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(g.dot(p[0] - c) > 0.0);
        }
    }

    #[test]
    fn sphere_is_closed_outward_and_not_degenerate() {
        let mut m = Mesh::new();
        let c = Vec3::new(0.0, 2.0, -5.0);
        m.sphere(c, 0.3, 8, 12);
        check_winding(&m);
        assert_eq!(m.triangle_count(), 2 * 12 * (8 - 1));
        for t in m.indices.chunks(3) {
            let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let g = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(g.dot((p[0] + p[1] + p[2]) / 3.0 - c) > 0.0);
        }
        // Closed: every edge is used exactly twice, once in each direction.
        let mut edges = std::collections::HashMap::new();
        for t in m.indices.chunks(3) {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1));
        }
    }

    #[test]
    fn cylinder_sides_point_outward() {
        let mut m = Mesh::new();
        m.cylinder(Vec3::new(2.0, 0.0, 1.0), 0.1, 5.0, 10);
        check_winding(&m);
        assert_eq!(m.triangle_count(), 30);
    }

    #[test]
    fn rect_faces_u_cross_v() {
        let mut m = Mesh::new();
        m.rect(Vec3::ZERO, Vec3::Z, Vec3::X);
        check_winding(&m);
        assert!(m.normals.iter().all(|n| *n == Vec3::Y));
        // Texture coordinates in metres: 2 m along u, 2 m along v.
        assert_eq!(m.uvs[2], Vec2::new(2.0, 0.0));
        m.scale_uvs(4.0);
        assert_eq!(m.uvs[0], Vec2::new(0.0, 0.5));
    }
}
