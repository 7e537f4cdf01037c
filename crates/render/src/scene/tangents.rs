//! Vertex tangents for normal maps: a file's TANGENT attribute taken to world space, or
//! MikkTSpace tangents where a file has none.
//!
//! glTF 2.0 (section 3.7.2.1, `TANGENT`): XYZW, XYZ the unit tangent (the direction of
//! increasing u), W = +1 or -1 the handedness: `bitangent = cross(normal, tangent.xyz) * w`.
//! Where a primitive has no TANGENT, "client implementations SHOULD calculate tangents using
//! default MikkTSpace algorithms with the specified vertex positions, normals, and texture
//! coordinates associated with the normal texture"; where it has no NORMAL, flat normals are
//! used and a TANGENT, if any, "MUST be ignored". Tangents are generated here by
//! [`bevy_mikktspace`] (a safe, dependency-free port of Mikkelsen's reference code whose output
//! matches it bit for bit) from the world-space positions and normals and the uvs with v
//! flipped (`(u, 1 - v)`, as Blender, which bakes most such maps, hands glTF uvs to MikkTSpace):
//! glTF's v grows down the image while a normal map's +Y is up the image.
//!
//! MikkTSpace gives one tangent per triangle corner; corners that share a vertex get the same
//! tangent except where the triangles around it disagree (a uv mirror seam through the vertex,
//! or the face normals of a flat-shaded primitive). Such a vertex is duplicated, one copy per
//! distinct tangent, as glTF-Transform's unweld-generate-weld does.

use bevy_mikktspace::{Geometry, TangentSpace};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use std::collections::HashMap;

/// A file's object-space tangents in world space: XYZ by the model matrix (tangents lie in the
/// surface, so they transform as positions do, not by the inverse transpose as normals do),
/// normalised; W's sign flipped where the transform mirrors (negative determinant), since the
/// bitangent `M b` is then `-w cross(n', t')` for the transformed normal `n'` and tangent `t'`.
/// A zero or non-finite tangent stays zero (no normal mapping at that vertex).
pub(super) fn to_world(tangents: impl Iterator<Item = [f32; 4]>, world: Mat4) -> Vec<Vec4> {
    let m = Mat3::from_mat4(world);
    let mirror = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
    tangents
        .map(
            |t| match (m * Vec3::new(t[0], t[1], t[2])).try_normalize() {
                Some(xyz) if t[3].is_finite() => {
                    xyz.extend(if t[3] < 0.0 { -mirror } else { mirror })
                }
                _ => Vec4::ZERO,
            },
        )
        .collect()
}

/// The mesh of one primitive as MikkTSpace sees it, and the tangents it writes per corner.
struct Mesh<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    uvs: &'a [Vec2],
    triangles: &'a [[u32; 3]],
    corners: Vec<Vec4>,
}

impl Mesh<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.triangles[face][vert] as usize
    }
}

impl Geometry for Mesh<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let n = self.normals[self.vertex(face, vert)];
        if n != Vec3::ZERO {
            return n.to_array();
        }
        // Flat shading: the face normal by the winding.
        let [a, b, c] = self.triangles[face].map(|v| self.positions[v as usize]);
        (b - a).cross(c - a).normalize_or_zero().to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.uvs[self.vertex(face, vert)];
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent(&mut self, tangent: Option<TangentSpace>, face: usize, vert: usize) {
        let t = tangent.map_or(Vec4::ZERO, |t| Vec4::from(t.tangent_encoded()));
        self.corners[face * 3 + vert] = if t.is_finite() { t } else { Vec4::ZERO };
    }
}

/// The most triangles that may share one vertex (as MikkTSpace welds them: same position,
/// normal and uv) for MikkTSpace to run: it groups the triangles around a vertex by recursing
/// once per triangle, so a fan of 100,000 overflowed the stack. 4,096 levels take well under
/// a thread's 2 MB.
pub(super) const MAX_VALENCE: usize = 4096;

/// The largest number of triangle corners that share one vertex, vertices being welded by
/// position, normal and uv as MikkTSpace welds them.
fn max_valence(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    triangles: &[[u32; 3]],
) -> usize {
    let mut count: HashMap<[u32; 8], usize> = HashMap::new();
    let mut most = 0;
    for &v in triangles.iter().flatten() {
        let i = v as usize;
        let (p, n, uv) = (positions[i], normals[i], uvs[i]);
        let key = [p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y].map(f32::to_bits);
        let c = count.entry(key).or_insert(0);
        *c += 1;
        most = most.max(*c);
    }
    most
}

/// MikkTSpace tangents of one primitive (world-space `positions`; unit `normals`, zero where
/// the face normal is meant; the uvs of the normal texture; `triangles` indexing them): one
/// tangent per vertex, with vertices whose corners disagree duplicated. Returns the tangents
/// (one per vertex, the duplicates last) and, for each duplicate, the vertex it copies; the
/// corners of `triangles` are renumbered to the copies they use. A vertex shared by more than
/// [`MAX_VALENCE`] triangles is an error giving their number (nothing is generated).
pub(super) fn generate(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    triangles: &mut [[u32; 3]],
) -> Result<(Vec<Vec4>, Vec<u32>), usize> {
    let valence = max_valence(positions, normals, uvs, triangles);
    if valence > MAX_VALENCE {
        return Err(valence);
    }
    let mut mesh = Mesh {
        positions,
        normals,
        uvs,
        triangles,
        corners: vec![Vec4::ZERO; triangles.len() * 3],
    };
    // The crate's error type has no variants yet; were it to fail, every corner would keep a
    // zero tangent (no normal mapping), which is what the caller is told to expect.
    if bevy_mikktspace::generate_tangents(&mut mesh).is_err() {
        mesh.corners.fill(Vec4::ZERO);
    }
    let corners = mesh.corners;
    let n = positions.len();
    let mut tangents = vec![Vec4::ZERO; n];
    let mut assigned = vec![false; n];
    let mut copies = Vec::new();
    let mut copy_of: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    for (tri, corner) in triangles.iter_mut().zip(corners.chunks_exact(3)) {
        for (v, &t) in tri.iter_mut().zip(corner) {
            let i = *v as usize;
            if !assigned[i] {
                assigned[i] = true;
                tangents[i] = t;
            } else if tangents[i] != t {
                let key = (*v, t.to_array().map(f32::to_bits));
                *v = *copy_of.entry(key).or_insert_with(|| {
                    copies.push(i as u32);
                    tangents.push(t);
                    (tangents.len() - 1) as u32
                });
            }
        }
    }
    Ok((tangents, copies))
}

/// Appends to `values` (one per vertex) a copy of `values[i]` for each `i` in `copies`.
pub(super) fn extend_copies<T: Copy>(values: &mut Vec<T>, copies: &[u32]) {
    values.reserve(copies.len());
    for &i in copies {
        values.push(values[i as usize]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit quad in the plane z = 0 facing +Z, with uvs `uv(x, y)` at its corners.
    fn quad(uv: impl Fn(f32, f32) -> Vec2) -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let uvs = p.iter().map(|p| uv(p.x, p.y)).collect();
        (p, vec![Vec3::Z; 4], uvs, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn quad_tangent_is_dp_du_with_the_handedness_of_the_uvs() {
        // glTF uvs: u along +X, v down the image, so the image's up (+Y of a normal map) is +Y.
        let (p, n, uv, mut tris) = quad(|x, y| Vec2::new(x, 1.0 - y));
        let (t, copies) = generate(&p, &n, &uv, &mut tris).unwrap();
        assert!(copies.is_empty());
        for t in &t {
            assert!((*t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-6, "{t}");
            // bitangent = cross(n, t) w = +Y, the image's up.
            assert!((Vec3::Z.cross(t.truncate()) * t.w - Vec3::Y).length() < 1e-6);
        }
        // Mirrored in u: the tangent follows dP/du = -X and the handedness flips, so that the
        // bitangent still points up the image.
        let (p, n, uv, mut tris) = quad(|x, y| Vec2::new(1.0 - x, 1.0 - y));
        let (t, _) = generate(&p, &n, &uv, &mut tris).unwrap();
        for t in &t {
            assert!(
                (*t - Vec4::new(-1.0, 0.0, 0.0, -1.0)).length() < 1e-6,
                "{t}"
            );
            assert!((Vec3::Z.cross(t.truncate()) * t.w - Vec3::Y).length() < 1e-6);
        }
        // Rotated uvs (u along +Y): the tangent is +Y.
        let (p, n, uv, mut tris) = quad(|x, y| Vec2::new(y, x));
        let (t, _) = generate(&p, &n, &uv, &mut tris).unwrap();
        assert!((t[0].truncate() - Vec3::Y).length() < 1e-6, "{}", t[0]);
    }

    #[test]
    fn a_vertex_on_a_mirror_seam_is_split() {
        // Two quads side by side sharing the edge x = 1, uvs mirrored about it (u = 1 - |x - 1|).
        let p: Vec<Vec3> = [0.0, 1.0, 2.0]
            .into_iter()
            .flat_map(|x| [Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)])
            .collect();
        let uv: Vec<Vec2> = p
            .iter()
            .map(|p| Vec2::new(1.0 - (p.x - 1.0).abs(), 1.0 - p.y))
            .collect();
        let n = vec![Vec3::Z; 6];
        let mut tris = vec![[0, 2, 3], [0, 3, 1], [2, 4, 5], [2, 5, 3]];
        let (t, copies) = generate(&p, &n, &uv, &mut tris).unwrap();
        // The seam's two vertices are copied once each, for the right-hand quad.
        let mut sorted = copies.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, vec![2, 3]);
        assert_eq!(t.len(), 8);
        for (k, tri) in tris.iter().enumerate() {
            let (want_x, want_w) = if k < 2 { (1.0, 1.0) } else { (-1.0, -1.0) };
            for &v in tri {
                let t = t[v as usize];
                assert!(
                    (t - Vec4::new(want_x, 0.0, 0.0, want_w)).length() < 1e-5,
                    "triangle {k}: {t}"
                );
            }
        }
        let mut values: Vec<u32> = (0..6).collect();
        extend_copies(&mut values, &copies);
        assert_eq!(&values[6..], &copies[..]);
    }

    #[test]
    fn flat_primitives_use_face_normals() {
        // A tent: two faces meeting at the ridge x = 0, no normals.
        let p = vec![
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, -1.0),
        ];
        let uv = vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(0.5, 1.0),
            Vec2::new(0.5, 0.0),
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
        ];
        let mut tris = vec![[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]];
        let (t, copies) = generate(&p, &[Vec3::ZERO; 6], &uv, &mut tris).unwrap();
        // The ridge vertices get one tangent per face: along each face's slope.
        assert_eq!(copies.len(), 2);
        for (k, tri) in tris.iter().enumerate() {
            let want = if k < 2 {
                Vec3::new(1.0, 1.0, 0.0)
            } else {
                Vec3::new(1.0, -1.0, 0.0)
            }
            .normalize();
            for &v in tri {
                assert!((t[v as usize].truncate() - want).length() < 1e-5, "{k}");
            }
        }
    }

    #[test]
    fn file_tangents_follow_the_model_matrix_and_mirrors_flip_handedness() {
        let t = [
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, -1.0],
        ];
        // A non-uniform scale then a rotation: xyz by the matrix, normalised.
        let m = Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2)
            * Mat4::from_scale(Vec3::new(3.0, 1.0, 1.0));
        let w = to_world(t.into_iter(), m);
        assert!(
            (w[0] - Vec4::new(0.0, 1.0, 0.0, 1.0)).length() < 1e-6,
            "{}",
            w[0]
        );
        assert_eq!(w[1], Vec4::ZERO);
        assert!((w[2] - Vec4::new(-1.0, 0.0, 0.0, -1.0)).length() < 1e-6);
        // A mirror in x: the tangent is mirrored and the handedness flips, so that
        // w' cross(n', t') is the mirrored bitangent.
        let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let w = to_world(t.into_iter(), mirror);
        assert!((w[0] - Vec4::new(-1.0, 0.0, 0.0, -1.0)).length() < 1e-6);
        let (n, b) = (Vec3::Z, Vec3::Z.cross(Vec3::X));
        let (n2, b2) = (n, mirror.transform_vector3(b));
        assert!((n2.cross(w[0].truncate()) * w[0].w - b2).length() < 1e-6);
        assert!((w[2] - Vec4::new(0.0, 1.0, 0.0, 1.0)).length() < 1e-6);
    }

    /// A fan of 100,000 triangles around one vertex (which overflowed the stack in
    /// MikkTSpace's recursion) is refused with the count; one of MAX_VALENCE is generated,
    /// on a test thread's 2 MB stack.
    #[test]
    fn huge_fans_are_refused_and_fans_up_to_the_limit_generate() {
        let fan = |n: usize| {
            let mut p = vec![Vec3::ZERO];
            let mut tris = Vec::new();
            for i in 0..=n {
                let a = i as f32 / n as f32 * 6.0;
                p.push(Vec3::new(a.cos(), a.sin(), 0.0));
                if i > 0 {
                    tris.push([0, i as u32, i as u32 + 1]);
                }
            }
            let uv: Vec<Vec2> = p.iter().map(|q| q.truncate() * 0.5 + 0.5).collect();
            (p.clone(), vec![Vec3::Z; p.len()], uv, tris)
        };
        let (p, n, uv, mut tris) = fan(100_000);
        assert_eq!(generate(&p, &n, &uv, &mut tris).unwrap_err(), 100_000);
        let (p, n, uv, mut tris) = fan(MAX_VALENCE);
        let (t, _) = generate(&p, &n, &uv, &mut tris).unwrap();
        assert!(t.iter().all(|t| t.w.abs() == 1.0), "{:?}", &t[..3]);
    }
}
