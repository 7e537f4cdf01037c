//! The BVH: the only module that imports obvhs.
//!
//! obvhs builds a binary BVH over all of a scene's triangles (in parallel, PLOC with the
//! `medium_build` preset, step by step so that the build peaks below 300 bytes per triangle,
//! and with more of its nodes reinserted in scenes of fewer than a million triangles); the
//! project collapses it into its own wide BVH and walks that ([`wide`]): nodes of 8 children
//! (16 where the CPU has AVX-512) with uncompressed `f32` boxes laid out for one SIMD pass per
//! node, ordered traversal, and a conservative node test. The triangles are copied in leaf
//! order into an intersection-friendly layout, so traversal reads them contiguously; each slot
//! remembers the scene triangle it came from.
//!
//! Degenerate input: PLOC stalls on coincident or nested boxes (one merge per pass over all
//! nodes: quadratic time, and a chain as deep as the boxes are many). Runs of such boxes are
//! found before the build and given balanced subtrees (`Clusters`), and boxes piled on one
//! another everywhere (a huge fan's slivers) give a balanced tree in Morton order
//! (`MAX_OVERLAP`); 100,000 coincident triangles or a fan of a million build in well under a
//! second. Other scenes (all we ship) are built exactly as before.
//!
//! Watertight rays: the triangle test is Woop, Benthin and Wald's (2013), so a ray through an
//! edge or vertex that triangles share hits one of them (`intersect_triangle`), and the node
//! test widens each box's exit distance for rounding (Ize 2013), so no ray misses a box it
//! passes through: rays aimed at a closed mesh's vertices and edges, from inside it and from
//! its exact centre (whose coordinates lie on box faces), all hit it through the BVH (tested;
//! obvhs' compressed-node walk, which this replaced, lost 1,051 of 44,744 of them).
//!
//! The closest hit is the one with the smallest `t` and, among equal `t`, the lowest scene
//! triangle index, so it does not depend on the order the traversal meets triangles in, on
//! the node width or on the SIMD kernel: images are bit for bit the same on every CPU.
//!
//! Self-intersection: callers offset ray origins with
//! [`crate::geometry::offset_ray_origin`]; on top of that every query ignores hits with
//! `t <= t_min`, where `t_min = 16 * f32::EPSILON * max(1, largest absolute coordinate of the
//! scene)` (about two millionths of the scene's extent, e.g. 0.2 mm for a scene spanning
//! 100 m). Rays are assumed to have unit directions, so `t` is a distance.
//!
//! Alpha testing: triangles built as alpha-tested (those of materials with an alpha mode other
//! than opaque) are marked in a bit set by BVH slot; [`Accel::intersect_filtered`] and
//! [`Accel::occluded_filtered`] ask a caller's test about a hit on a marked triangle inside
//! the traversal, and skip it when the test says so, so the traversal goes on to what lies
//! behind. A scene without alpha-tested triangles has no bit set, and the filtered queries are
//! the plain ones.
//!
//! Instancing: an instanced mesh has its own [`Accel`] in object space, queried with a ray
//! taken into that space (`Accel::intersect_object`, `Accel::occluded_object`): the
//! direction is transformed but not renormalised, so `t` stays the world ray's parameter and
//! the scene's `t_min` applies unchanged. A [`Tlas`] over the instances' world boxes finds the
//! instances a ray may hit; each box's query runs the instance's BLAS traversal nested in the
//! TLAS traversal.
//!
//! Queries allocate nothing: traversal uses a fixed-size stack, which the build guarantees is
//! deep enough (`wide::STACK`).
//!
//! Shadow rays stop at their first hit ([`Accel::occluded`]).
//!
//! Rays are traced one at a time: docs/decisions/0006 measured packets of coherent rays (a whole
//! render gained 1-4 %, too little for the restructuring of the path loop they need), and says
//! where the packet traversal it measured can be found.

mod wide;

pub use wide::Kernel;

use crate::geometry::Ray;
use glam::{Vec2, Vec3, Vec3A, Vec3Swizzles};
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::PlocBuilder;
use obvhs::BvhBuildParams;
use wide::{TraceRay, Wide};

/// A wide BVH over the scene's triangles.
pub struct Accel {
    /// `None` when the scene has no triangles (every ray misses).
    tree: Option<Tree>,
    /// Triangles in BVH order (`tris[i]` is primitive slot `i`).
    tris: Vec<Triangle>,
    /// Scene triangle index of each slot.
    ids: Vec<u32>,
    /// Bit `i % 64` of word `i / 64` is set when slot `i` is alpha-tested; empty when no
    /// triangle is.
    alpha_tested: Vec<u64>,
    /// Hits at `t <= t_min` are ignored (see the module documentation).
    t_min: f32,
}

/// A closest hit found by [`Accel::intersect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelHit {
    /// Ray parameter.
    pub t: f32,
    /// Index of the scene triangle.
    pub triangle: u32,
    /// Barycentric weights of the triangle's second and third vertices (the first vertex has
    /// weight `1 - b.x - b.y`).
    pub barycentrics: Vec2,
}

impl std::fmt::Debug for Accel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Accel")
            .field("triangles", &self.tris.len())
            .field("nodes", &self.tree.as_ref().map_or(0, Tree::node_count))
            .field("t_min", &self.t_min)
            .finish()
    }
}

impl Accel {
    /// Builds the BVH over `triangles` (vertex indices into `positions`; all indices must be in
    /// range, which [`crate::scene::Scene::from_parts`] checks), none alpha-tested.
    pub fn build(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        Self::build_alpha_tested(positions, triangles, |_| false)
    }

    /// [`Accel::build`], with the triangles for which `alpha_tested(index)` is true marked
    /// for the filtered queries' test.
    pub fn build_alpha_tested(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        alpha_tested: impl Fn(usize) -> bool,
    ) -> Self {
        Self::build_with_width(
            positions,
            triangles,
            alpha_tested,
            Kernel::of_process().width(),
        )
    }

    /// [`Accel::build_alpha_tested`] with nodes of `width` children (8 or 16).
    fn build_with_width(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        alpha_tested: impl Fn(usize) -> bool,
        width: usize,
    ) -> Self {
        let max_coord = positions
            .iter()
            .fold(1.0f32, |m, p| m.max(p.abs().max_element()));
        let t_min = 16.0 * f32::EPSILON * max_coord;
        if triangles.is_empty() {
            return Self {
                tree: None,
                tris: Vec::new(),
                ids: Vec::new(),
                alpha_tested: Vec::new(),
                t_min,
            };
        }
        assert!(
            triangles.len() <= wide::MAX_PRIMITIVES,
            "{} triangles: a BVH holds at most {}",
            triangles.len(),
            wide::MAX_PRIMITIVES
        );
        let vertex = |i: u32| Vec3A::from(positions[i as usize]);
        let tree = build_tree(
            triangles.iter().map(|t| Aabb::from_points(&t.map(vertex))),
            reinsertion_ratio(triangles.len()),
            width,
        );
        let ids = tree.order().to_vec();
        let tris = ids
            .iter()
            .map(|&i| Triangle::new(triangles[i as usize].map(vertex)))
            .collect();
        let mut bits = vec![0u64; ids.len().div_ceil(64)];
        let mut any = false;
        for (slot, &t) in ids.iter().enumerate() {
            if alpha_tested(t as usize) {
                bits[slot / 64] |= 1 << (slot % 64);
                any = true;
            }
        }
        Self {
            tree: Some(tree),
            tris,
            ids,
            alpha_tested: if any { bits } else { Vec::new() },
            t_min,
        }
    }

    /// Hits at `t` at or below this are ignored (self-intersection guard).
    pub fn t_min(&self) -> f32 {
        self.t_min
    }

    /// Number of triangles in the BVH.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Approximate heap memory of the BVH and its triangle copies, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.tree.as_ref().map_or(0, Tree::memory_bytes)
            + std::mem::size_of_val(self.tris.as_slice())
            + std::mem::size_of_val(self.ids.as_slice())
            + std::mem::size_of_val(self.alpha_tested.as_slice())
    }

    /// Whether BVH slot `slot` holds an alpha-tested triangle (only called when some is).
    #[inline]
    fn is_alpha_tested(&self, slot: usize) -> bool {
        self.alpha_tested[slot / 64] & (1 << (slot % 64)) != 0
    }

    /// Raises [`Accel::t_min`] to `t_min` if that is larger: a scene whose instances reach
    /// farther than its own triangles guards all its hits with one distance.
    pub(crate) fn raise_t_min(&mut self, t_min: f32) {
        self.t_min = self.t_min.max(t_min);
    }

    /// Closest hit with `t_min < t < ray.t_max`.
    pub fn intersect(&self, ray: &Ray) -> Option<AccelHit> {
        self.closest::<false>(ray, self.t_min, |_, _| true)
    }

    /// Whether any triangle is hit with `t_min < t < ray.t_max` (any-hit query).
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.any::<false>(ray, self.t_min, |_, _| true)
    }

    /// [`Accel::intersect_filtered`] for a ray in this BVH's object space (an instanced
    /// mesh's): `ray.direction` need not be unit (it is the world direction through the
    /// inverse transform, so `t` is the world ray's), and hits at `t <= t_min` (the scene's)
    /// are ignored.
    #[inline]
    pub(crate) fn intersect_object(
        &self,
        ray: &Ray,
        t_min: f32,
        stops: impl FnMut(u32, Vec2) -> bool,
    ) -> Option<AccelHit> {
        if self.alpha_tested.is_empty() {
            self.closest::<false>(ray, t_min, stops)
        } else {
            self.closest::<true>(ray, t_min, stops)
        }
    }

    /// [`Accel::occluded_filtered`] for a ray in object space (see
    /// [`Accel::intersect_object`]).
    #[inline]
    pub(crate) fn occluded_object(
        &self,
        ray: &Ray,
        t_min: f32,
        stops: impl FnMut(u32, Vec2) -> bool,
    ) -> bool {
        if self.alpha_tested.is_empty() {
            self.any::<false>(ray, t_min, stops)
        } else {
            self.any::<true>(ray, t_min, stops)
        }
    }

    /// [`Accel::intersect`], where a hit on an alpha-tested triangle counts only if
    /// `stops(triangle, barycentrics)` says so (the closest hit that does is returned).
    #[inline]
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        stops: impl FnMut(u32, Vec2) -> bool,
    ) -> Option<AccelHit> {
        if self.alpha_tested.is_empty() {
            self.intersect(ray)
        } else {
            self.closest::<true>(ray, self.t_min, stops)
        }
    }

    /// [`Accel::occluded`], where a hit on an alpha-tested triangle counts only if
    /// `stops(triangle, barycentrics)` says so.
    #[inline]
    pub fn occluded_filtered(&self, ray: &Ray, stops: impl FnMut(u32, Vec2) -> bool) -> bool {
        if self.alpha_tested.is_empty() {
            self.occluded(ray)
        } else {
            self.any::<true>(ray, self.t_min, stops)
        }
    }

    /// Whether a hit on slot `id` counts: always without `FILTER`; with it, unless the slot
    /// is alpha-tested and `stops` rejects it.
    #[inline(always)]
    fn counts<const FILTER: bool>(
        &self,
        id: usize,
        b: Vec2,
        stops: &mut impl FnMut(u32, Vec2) -> bool,
    ) -> bool {
        !FILTER || !self.is_alpha_tested(id) || stops(self.ids[id], b)
    }

    /// The closest hit that [`Accel::counts`]; of hits at the same `t`, the one on the
    /// lowest scene triangle index, so that the answer does not depend on the order the
    /// traversal meets them in (nor on the BVH's width).
    #[inline(always)]
    fn closest<const FILTER: bool>(
        &self,
        ray: &Ray,
        t_min: f32,
        mut stops: impl FnMut(u32, Vec2) -> bool,
    ) -> Option<AccelHit> {
        self.closest_with(Kernel::of_process(), ray, t_min, &mut stops, FILTER)
    }

    /// [`Accel::closest`] with the traversal compiled for `kernel`.
    #[inline(always)]
    fn closest_with(
        &self,
        kernel: Kernel,
        ray: &Ray,
        t_min: f32,
        stops: &mut impl FnMut(u32, Vec2) -> bool,
        filter: bool,
    ) -> Option<AccelHit> {
        let tree = self.tree.as_ref()?;
        let (r, shear) = trace_ray(ray, t_min)?;
        let mut best = AccelHit {
            t: f32::INFINITY,
            triangle: u32::MAX,
            barycentrics: Vec2::ZERO,
        };
        let tris = &self.tris;
        tree.closest(kernel, &r, |slot, t_max| {
            let (t, b) = intersect_triangle(&tris[slot as usize], &shear, t_min, t_max);
            // `t <= t_max`: a hit at the current end replaces it if its triangle is lower.
            if t.is_finite() {
                let triangle = self.ids[slot as usize];
                let nearer = t < best.t || (t == best.t && triangle < best.triangle);
                let counts = if filter {
                    self.counts::<true>(slot as usize, b, stops)
                } else {
                    true
                };
                if nearer && counts {
                    best = AccelHit {
                        t,
                        triangle,
                        barycentrics: b,
                    };
                    return t;
                }
            }
            t_max
        });
        (best.t < r.t_max).then_some(best)
    }

    /// Whether any hit [`Accel::counts`].
    #[inline(always)]
    fn any<const FILTER: bool>(
        &self,
        ray: &Ray,
        t_min: f32,
        mut stops: impl FnMut(u32, Vec2) -> bool,
    ) -> bool {
        self.any_with(Kernel::of_process(), ray, t_min, &mut stops, FILTER)
    }

    /// [`Accel::any`] with the traversal compiled for `kernel`.
    #[inline(always)]
    fn any_with(
        &self,
        kernel: Kernel,
        ray: &Ray,
        t_min: f32,
        stops: &mut impl FnMut(u32, Vec2) -> bool,
        filter: bool,
    ) -> bool {
        let Some(tree) = self.tree.as_ref() else {
            return false;
        };
        let Some((r, shear)) = trace_ray(ray, t_min) else {
            return false;
        };
        let tris = &self.tris;
        tree.any(kernel, &r, |slot| {
            let (t, b) = intersect_triangle(&tris[slot as usize], &shear, t_min, r.t_max);
            t < r.t_max && (!filter || self.counts::<true>(slot as usize, b, stops))
        })
    }
}

/// The traversal's ray for `ray` with hits at `t <= t_min` ignored, and its shear for the
/// triangle test; `None` for a ray that cannot hit anything (not finite, or ending before
/// `t_min`).
#[inline(always)]
fn trace_ray(ray: &Ray, t_min: f32) -> Option<(TraceRay, Shear)> {
    if !(ray.origin.is_finite() && ray.direction.is_finite()) || ray.t_max.is_nan() {
        return None;
    }
    if ray.t_max <= t_min {
        return None;
    }
    // Adding +0.0 turns -0.0 into +0.0, so a zero component has one sign everywhere: the
    // node test's near plane and the shear's winding agree with it.
    let direction = Vec3A::from(ray.direction) + Vec3A::ZERO;
    let origin = Vec3A::from(ray.origin);
    Some((
        TraceRay::new(origin.to_array(), direction.to_array(), t_min, ray.t_max),
        Shear::new(origin, direction),
    ))
}

/// The wide BVH of the width the build chose.
#[derive(Clone, Debug)]
enum Tree {
    /// Nodes of 8 children (AVX2 and SSE kernels).
    Eight(Wide<8>),
    /// Nodes of 16 children (the AVX-512 kernel).
    Sixteen(Wide<16>),
}

impl Tree {
    /// `bvh2` collapsed into nodes of `width` children (16, or else 8).
    fn from_bvh2(bvh2: &Bvh2, width: usize) -> Self {
        if width == 16 {
            Self::Sixteen(Wide::from_bvh2(bvh2))
        } else {
            Self::Eight(Wide::from_bvh2(bvh2))
        }
    }

    /// The binary tree's primitive index of each slot.
    fn order(&self) -> &[u32] {
        match self {
            Self::Eight(w) => &w.order,
            Self::Sixteen(w) => &w.order,
        }
    }

    fn stack_need(&self) -> usize {
        match self {
            Self::Eight(w) => w.stack_need(),
            Self::Sixteen(w) => w.stack_need(),
        }
    }

    fn node_count(&self) -> usize {
        match self {
            Self::Eight(w) => w.node_count(),
            Self::Sixteen(w) => w.node_count(),
        }
    }

    fn memory_bytes(&self) -> usize {
        match self {
            Self::Eight(w) => w.memory_bytes(),
            Self::Sixteen(w) => w.memory_bytes(),
        }
    }

    /// [`Wide::closest`] with `kernel`.
    #[inline(always)]
    fn closest(&self, kernel: Kernel, ray: &TraceRay, visit: impl FnMut(u32, f32) -> f32) -> f32 {
        match self {
            Self::Eight(w) => wide::run(kernel, w, ray, wide::Closest(visit)),
            Self::Sixteen(w) => wide::run(kernel, w, ray, wide::Closest(visit)),
        }
    }

    /// [`Wide::any`] with `kernel`.
    #[inline(always)]
    fn any(&self, kernel: Kernel, ray: &TraceRay, visit: impl FnMut(u32) -> bool) -> bool {
        match self {
            Self::Eight(w) => wide::run(kernel, w, ray, wide::AnyHit(visit)),
            Self::Sixteen(w) => wide::run(kernel, w, ray, wide::AnyHit(visit)),
        }
    }
}

/// A top-level BVH: a wide BVH over boxes (the world bounds of a scene's instances), whose
/// queries call a closure for each box the ray enters, with the ray's current end.
pub struct Tlas {
    tree: Tree,
}

impl std::fmt::Debug for Tlas {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tlas")
            .field("boxes", &self.tree.order().len())
            .field("nodes", &self.tree.node_count())
            .finish()
    }
}

impl Tlas {
    /// The BVH over `boxes` (`[min, max]` corners); `None` when there are none.
    pub fn build(boxes: &[[Vec3; 2]]) -> Option<Self> {
        if boxes.is_empty() {
            return None;
        }
        let tree = build_tree(
            boxes
                .iter()
                .map(|[lo, hi]| Aabb::new(Vec3A::from(*lo), Vec3A::from(*hi))),
            reinsertion_ratio(boxes.len()),
            Kernel::of_process().width(),
        );
        Some(Self { tree })
    }

    /// Approximate heap memory of the BVH, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
    }

    /// Visits the boxes `ray` enters before its end, nearest first where the traversal order
    /// allows: `visit(box, t_max)` returns the parameter of the closest hit inside box `box`
    /// before `t_max` (infinity for none), which then becomes the ray's end. Whether any box
    /// reported a hit.
    #[inline]
    pub fn closest(&self, ray: &Ray, t_min: f32, mut visit: impl FnMut(u32, f32) -> f32) -> bool {
        let Some((r, _)) = trace_ray(ray, t_min) else {
            return false;
        };
        let ids = self.tree.order();
        let end = self.tree.closest(Kernel::of_process(), &r, |slot, t_max| {
            visit(ids[slot as usize], t_max).min(t_max)
        });
        end < r.t_max
    }

    /// Whether `visit(box)` says true for some box `ray` enters before its end (stopping at
    /// the first that does).
    #[inline]
    pub fn any(&self, ray: &Ray, t_min: f32, mut visit: impl FnMut(u32) -> bool) -> bool {
        let Some((r, _)) = trace_ray(ray, t_min) else {
            return false;
        };
        let ids = self.tree.order();
        self.tree
            .any(Kernel::of_process(), &r, |slot| visit(ids[slot as usize]))
    }
}

/// A triangle's three vertices as the scene gives them, by axis: `p[k]` holds the `k`
/// coordinates of the first, second and third vertex. The [watertight test](
/// intersect_triangle) needs the shared vertices of neighbouring triangles bit for bit, which
/// edges stored as differences (obvhs' `RtTriangle`) do not keep, and by axis it reads the
/// three vertices' coordinates along the ray's permuted axes as three loads.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    p: [Vec3A; 3],
}

impl Triangle {
    fn new(v: [Vec3A; 3]) -> Self {
        Self {
            p: [0, 1, 2].map(|k| Vec3A::new(v[0][k], v[1][k], v[2][k])),
        }
    }
}

/// What the watertight triangle test needs of a ray, computed once per ray (Woop, Benthin and
/// Wald 2013): the axis `z` its direction is largest along and the other two, `x` and `y`
/// (swapped where the direction's `z` is negative, which keeps the winding); the shear
/// `S_z = 1 / d_z`, `S_x = d_x S_z`, `S_y = d_y S_z` that makes the ray the `z` axis; and the
/// origin's coordinates on those axes.
#[derive(Clone, Copy, Debug)]
struct Shear {
    /// The axes `x`, `y`, `z` of the sheared frame (indices into world x, y, z).
    k: [usize; 3],
    /// `S_x`, `S_y`, `S_z`.
    s: [f32; 3],
    /// The ray origin's coordinates along `k`.
    o: [f32; 3],
}

impl Shear {
    #[inline(always)]
    fn new(origin: Vec3A, direction: Vec3A) -> Self {
        let (d, o) = (direction.to_array(), origin.to_array());
        let a = direction.abs();
        let kz = if a.x >= a.y {
            if a.x >= a.z {
                0
            } else {
                2
            }
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (kx, ky) = if d[kz] < 0.0 {
            ((kz + 2) % 3, (kz + 1) % 3)
        } else {
            ((kz + 1) % 3, (kz + 2) % 3)
        };
        // One division: any `S` serves, as long as every triangle sees the same.
        let sz = 1.0 / d[kz];
        Self {
            k: [kx, ky, kz],
            s: [d[kx] * sz, d[ky] * sz, sz],
            o: [o[kx], o[ky], o[kz]],
        }
    }
}

/// The watertight ray-triangle test of Woop, Benthin and Wald (2013), as Embree's robust mode
/// and pbrt-v4 use it. In the ray's sheared frame ([`Shear`]) the ray is the `z` axis: each
/// vertex relative to the origin becomes `(a_x - S_x a_z, a_y - S_y a_z, S_z a_z)`, and the
/// triangle's 2D edge functions `U`, `V`, `W` at the origin decide the hit: all of one sign.
/// Two triangles sharing an edge compute its function from the same transformed vertices, so
/// one gets exactly the negation of the other's and a ray through the edge hits one of them
/// (both, at an exact zero); an exact zero is recomputed in double precision, whose products
/// of two floats are exact, so its sign is right. Möller-Trumbore, which this replaced, let
/// one in eight rays aimed at a UV sphere's edges from inside pass between two triangles
/// (tested). The three vertices go through it together, one per lane.
///
/// Returns `t` and the barycentric weights `(V, W) / (U + V + W)` of the second and third
/// vertices; `t` is infinite for a miss, a ray parallel to the triangle, or a hit outside
/// `(t_min, t_max]`. Both sides count.
#[inline(always)]
fn intersect_triangle(tri: &Triangle, shear: &Shear, t_min: f32, t_max: f32) -> (f32, Vec2) {
    const MISS: (f32, Vec2) = (f32::INFINITY, Vec2::ZERO);
    let ([kx, ky, kz], [sx, sy, sz], [ox, oy, oz]) = (shear.k, shear.s, shear.o);
    // The three vertices' sheared coordinates, one vertex per lane.
    let z = tri.p[kz] - Vec3A::splat(oz);
    let x = (tri.p[kx] - Vec3A::splat(ox)) - Vec3A::splat(sx) * z;
    let y = (tri.p[ky] - Vec3A::splat(oy)) - Vec3A::splat(sy) * z;
    // (U, V, W) = (c_x b_y - c_y b_x, a_x c_y - a_y c_x, b_x a_y - b_y a_x).
    let (x1, y1) = (x.yzx(), y.yzx());
    let (x2, y2) = (x.zxy(), y.zxy());
    let mut uvw = x2 * y1 - y2 * x1;
    if uvw.cmpeq(Vec3A::ZERO).any() {
        let e = |i: usize, j: usize| {
            (f64::from(x[i]) * f64::from(y[j]) - f64::from(y[i]) * f64::from(x[j])) as f32
        };
        uvw = Vec3A::new(e(2, 1), e(0, 2), e(1, 0));
    }
    if uvw.cmplt(Vec3A::ZERO).any() && uvw.cmpgt(Vec3A::ZERO).any() {
        return MISS;
    }
    let det = uvw.x + uvw.y + uvw.z;
    if det == 0.0 {
        return MISS;
    }
    let inv_det = 1.0 / det;
    let t = uvw.dot(z * sz) * inv_det;
    if t > t_min && t <= t_max {
        (t, Vec2::new(uvw.y * inv_det, uvw.z * inv_det))
    } else {
        MISS
    }
}

/// obvhs' `medium_build` preset, which [`build_tree`] follows step by step.
const BUILD_PARAMS: BvhBuildParams = BvhBuildParams::medium_build();

/// How many nodes the reinsertion optimiser moves, at most: all of them up to this many
/// triangles, `BUILD_PARAMS`' 5% from twenty times as many on. A full pass gives street-size
/// scenes a better BVH for a build time that grows with the triangle count, so large scenes
/// keep the preset's share (docs/decisions/0012 has the measurements).
const REINSERTION_BUDGET: f32 = 50_000.0;

/// The reinsertion batch ratio for `triangles` triangles (see [`REINSERTION_BUDGET`]).
fn reinsertion_ratio(triangles: usize) -> f32 {
    (REINSERTION_BUDGET / triangles.max(1) as f32).clamp(BUILD_PARAMS.reinsertion_batch_ratio, 1.0)
}

/// The PLOC search distance of `BUILD_PARAMS` (`PlocSearchDistance::Medium` is 14 in obvhs
/// 0.4), a const generic of `build_ploc_from_leaves`.
const PLOC_SEARCH_DISTANCE: usize = 14;

/// Builds the wide BVH (nodes of `width` children) over primitives given by their bounding
/// boxes: obvhs' binary tree as its `build_cwbvh_from_tris` makes it with `medium_build`, but
/// with `reinsertion_ratio` as the reinsertion batch ratio and a lower peak memory (with the
/// preset's ratio the binary tree is the same; docs/decisions/0012 has the figures), then
/// collapsed ([`Wide::from_bvh2`]):
/// - the PLOC leaves are made straight from the boxes, without a triangle soup (48 bytes per
///   triangle) or a pre-sized builder (whose Morton buffer is twice what a 64-bit sort needs);
/// - the builder's buffers are freed before reinsertion, and the reinsertion's parent links
///   before the collapse.
fn build_tree(
    aabbs: impl ExactSizeIterator<Item = Aabb>,
    reinsertion_ratio: f32,
    width: usize,
) -> Tree {
    let mut bvh2 = build_bvh2(aabbs, reinsertion_ratio, false);
    let mut tree = Tree::from_bvh2(&bvh2, width);
    if tree.stack_need() > wide::STACK {
        // A chain too deep for the traversal's stack: a balanced tree in Morton order.
        bvh2 = build_bvh2_balanced(&bvh2, reinsertion_ratio);
        tree = Tree::from_bvh2(&bvh2, width);
    }
    tree
}

/// The binary tree of [`build_tree`] (with `balanced`, one cluster of everything, a balanced
/// tree in Morton order).
fn build_bvh2(
    aabbs: impl ExactSizeIterator<Item = Aabb>,
    reinsertion_ratio: f32,
    balanced: bool,
) -> Bvh2 {
    let mut total = Aabb::empty();
    let mut builder = PlocBuilder::new();
    builder.current_nodes = aabbs
        .enumerate()
        .map(|(i, aabb)| {
            total = total.union(&aabb);
            Bvh2Node::new(aabb, 1, i as u32)
        })
        .collect();
    let leaves = std::mem::take(&mut builder.current_nodes);
    // Boxes piled on one another (a huge fan's slivers, which all hold its centre; coincident
    // triangles) stall PLOC as the clusters do, but along no Morton run: a balanced tree in
    // Morton order instead.
    let piled = balanced || overlap(&leaves, &total) > MAX_OVERLAP;
    let mut bvh2 = ploc(&mut builder, &leaves, &total, reinsertion_ratio, piled);
    bvh2.parents = Vec::new();
    bvh2
}

/// The balanced binary tree over the primitives of `bvh2` (its leaves' boxes).
fn build_bvh2_balanced(bvh2: &Bvh2, reinsertion_ratio: f32) -> Bvh2 {
    let mut boxes = vec![Aabb::empty(); bvh2.primitive_indices.len()];
    for node in bvh2.nodes.iter().filter(|n| n.prim_count != 0) {
        let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
        for &p in &bvh2.primitive_indices[range] {
            boxes[p as usize] = *node.aabb();
        }
    }
    build_bvh2(boxes.into_iter(), reinsertion_ratio, true)
}

/// The BVH2 over the primitive boxes `leaves` (one primitive each) in the box `total`: PLOC
/// with [`Clusters`] expanded, or, with `balanced`, one cluster of everything; then the
/// reinsertion optimiser with `reinsertion_ratio` when there are no clusters.
fn ploc(
    builder: &mut PlocBuilder,
    leaves: &[Bvh2Node],
    total: &Aabb,
    reinsertion_ratio: f32,
    balanced: bool,
) -> Bvh2 {
    let count = leaves.len();
    let mut bvh2 = Bvh2::default();
    let clusters = Clusters::find(leaves, total, balanced);
    match &clusters {
        None => {
            bvh2.reset_for_reuse(count, Some((0..count as u32).collect()));
            builder.current_nodes = leaves.to_vec();
        }
        Some(c) => {
            let nodes = c.leaves(leaves);
            bvh2.reset_for_reuse(nodes.len(), Some(c.order.clone()));
            builder.current_nodes = nodes;
        }
    }
    if builder.current_nodes.len() == 1 {
        bvh2.nodes[0] = builder.current_nodes[0];
    } else {
        builder.build_ploc_from_leaves::<PLOC_SEARCH_DISTANCE, false>(
            &mut bvh2,
            *total,
            BUILD_PARAMS.sort_precision,
            BUILD_PARAMS.search_depth_threshold,
        );
    }
    builder.current_nodes = Vec::new();
    match clusters {
        None => ReinsertionOptimizer::default().run(&mut bvh2, reinsertion_ratio, None),
        // Reinsertion searches the whole of a cluster of coincident boxes for each of its
        // nodes (no bound prunes it): quadratic. The clusters' balanced subtrees are as good
        // as coincident primitives allow, so it is skipped.
        Some(c) => c.expand(&mut bvh2),
    }
    bvh2
}

/// The most the primitives' boxes may cover the scene's box, on average ([`overlap`]), for
/// PLOC to build the BVH. The scenes we ship cover it 1.6 to 5.4 times; a fan of 200,000
/// slivers, whose PLOC build takes seconds and grows with the square of their number
/// (68 s for a million), 16,000 times.
const MAX_OVERLAP: f64 = 256.0;

/// How many times, on average, the primitives' boxes cover the scene's box: the sum of their
/// half areas over the scene box's (1 for a tiling, the count for coincident boxes).
fn overlap(leaves: &[Bvh2Node], total: &Aabb) -> f64 {
    let sum: f64 = leaves.iter().map(|n| f64::from(n.aabb().half_area())).sum();
    let whole = f64::from(total.half_area());
    if whole > 0.0 {
        sum / whole
    } else {
        leaves.len() as f64
    }
}

/// Clusters smaller than this are left to PLOC (see [`Clusters`]).
const CLUSTER_MIN: usize = 64;

/// Runs of primitives that would stall PLOC, found before it runs: primitives whose boxes'
/// centres share one cell of PLOC's Morton grid (21 bits per axis over the scene's box:
/// identical or coincident triangles), and runs of the Morton order in which PLOC's first
/// pass merges nothing (boxes nested in one another along the curve, as triangles with one
/// centroid and growing sizes are), each of at least [`CLUSTER_MIN`] primitives.
///
/// PLOC merges two nodes only when each is the other's best neighbour. Among nodes with one
/// box every merge costs the same, each node's best is the farthest in its search window,
/// and only one pair per pass agrees; along nested boxes each node's best is its smaller
/// neighbour, and again one pair per pass merges. A run of `k` such primitives takes `k`
/// passes over all nodes (100,000 coincident triangles: minutes), and its subtree is a chain
/// `k` deep, which no fixed traversal stack holds. Each run is
/// instead one PLOC leaf, expanded afterwards into a balanced subtree
/// ([`Clusters::expand`]). A scene without such runs (every scene we ship) is built exactly
/// as before.
struct Clusters {
    /// The primitives in BVH slot order: those outside clusters first (in input order), then
    /// each cluster's, contiguously, in Morton order.
    order: Vec<u32>,
    /// Each cluster's range in `order`.
    ranges: Vec<std::ops::Range<u32>>,
    /// Every primitive's box, by input index.
    boxes: Vec<Aabb>,
}

impl Clusters {
    /// The clusters among the leaves `nodes` (one primitive each, `first_index` = input
    /// index) in the box `total`; `None` when there are none (the usual case). With
    /// `everything`, all primitives are one cluster (a balanced tree in Morton order).
    fn find(nodes: &[Bvh2Node], total: &Aabb, everything: bool) -> Option<Self> {
        if nodes.len() < CLUSTER_MIN.max(2) && !everything {
            return None;
        }
        // PLOC's own Morton code (obvhs' `sort_nodes_by_morton`, 64-bit precision), ties by
        // index as its stable radix sort leaves them.
        let scale = 1.0 / total.diagonal().as_dvec3();
        let offset = -total.min.as_dvec3() * scale;
        let mut keys: Vec<(u64, u32)> = nodes
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let c = n.aabb().center().as_dvec3() * scale + offset;
                (obvhs::ploc::morton::morton_encode_u64_unorm(c), i as u32)
            })
            .collect();
        keys.sort_unstable();
        let mut runs: Vec<std::ops::Range<usize>> = Vec::new();
        if everything {
            runs.push(0..keys.len());
        } else {
            let mut start = 0;
            for run in keys.chunk_by(|a, b| a.0 == b.0) {
                if run.len() >= CLUSTER_MIN {
                    runs.push(start..start + run.len());
                }
                start += run.len();
            }
            // PLOC's first pass (search distance 1): node i points at i - 1 when the merge
            // with it is cheaper than the one with i + 1, else at i + 1; two nodes pointing
            // at each other merge.
            let aabb = |k: usize| nodes[keys[k].1 as usize].aabb();
            let cost = |k: usize| aabb(k).union(aabb(k + 1)).half_area();
            let n = keys.len();
            let points_left = |k: usize| k + 1 == n || (k > 0 && cost(k - 1) < cost(k));
            let mut merged = vec![false; n];
            for k in 0..n - 1 {
                if !points_left(k) && points_left(k + 1) {
                    merged[k] = true;
                    merged[k + 1] = true;
                }
            }
            let mut start = 0;
            for run in merged.chunk_by(|a, b| a == b) {
                if !run[0] && run.len() >= CLUSTER_MIN {
                    runs.push(start..start + run.len());
                }
                start += run.len();
            }
            if runs.is_empty() {
                return None;
            }
            // Overlapping runs are one cluster.
            runs.sort_by_key(|r| r.start);
            let mut joined: Vec<std::ops::Range<usize>> = Vec::with_capacity(runs.len());
            for r in runs {
                match joined.last_mut() {
                    Some(last) if r.start < last.end => last.end = last.end.max(r.end),
                    _ => joined.push(r),
                }
            }
            runs = joined;
        }
        let mut in_cluster = vec![false; nodes.len()];
        for r in &runs {
            keys[r.clone()]
                .iter()
                .for_each(|&(_, i)| in_cluster[i as usize] = true);
        }
        let boxes: Vec<Aabb> = nodes.iter().map(|n| *n.aabb()).collect();
        let mut order: Vec<u32> = (0..nodes.len() as u32)
            .filter(|&i| !in_cluster[i as usize])
            .collect();
        let mut ranges = Vec::with_capacity(runs.len());
        for r in runs {
            let start = order.len() as u32;
            order.extend(keys[r].iter().map(|&(_, i)| i));
            ranges.push(start..order.len() as u32);
        }
        Some(Self {
            order,
            ranges,
            boxes,
        })
    }

    /// The union of the boxes of the primitives in slots `range` of `order`.
    fn bounds(&self, range: std::ops::Range<u32>) -> Aabb {
        self.order[range.start as usize..range.end as usize]
            .iter()
            .fold(Aabb::empty(), |b, &i| b.union(&self.boxes[i as usize]))
    }

    /// The PLOC leaves: one per primitive outside the clusters and one per cluster (several
    /// primitives), indexing `order`.
    fn leaves(&self, nodes: &[Bvh2Node]) -> Vec<Bvh2Node> {
        let singles = self
            .ranges
            .first()
            .map_or(self.order.len(), |r| r.start as usize);
        let mut leaves: Vec<Bvh2Node> = self.order[..singles]
            .iter()
            .enumerate()
            .map(|(slot, &i)| Bvh2Node::new(*nodes[i as usize].aabb(), 1, slot as u32))
            .collect();
        leaves.extend(
            self.ranges
                .iter()
                .map(|r| Bvh2Node::new(self.bounds(r.clone()), r.end - r.start, r.start)),
        );
        leaves
    }

    /// Replaces each cluster's leaf in `bvh` by a balanced subtree over its primitives (each
    /// inner node halves its range), one primitive per leaf; children keep following their
    /// parents in the node array.
    fn expand(&self, bvh: &mut Bvh2) {
        let old = std::mem::take(&mut bvh.nodes);
        let mut nodes = Vec::with_capacity(2 * self.order.len() - 1);
        nodes.push(old[0]);
        enum From {
            Node(usize),
            Slots(std::ops::Range<u32>),
        }
        let mut stack = vec![(0usize, From::Node(0))];
        let mut deepest = 0u32;
        while let Some((at, from)) = stack.pop() {
            let (children, first, second) = match from {
                From::Node(i) => {
                    let n = old[i];
                    if n.prim_count == 0 {
                        let c = n.first_index as usize;
                        (*n.aabb(), From::Node(c), From::Node(c + 1))
                    } else if n.prim_count == 1 {
                        nodes[at] = n;
                        continue;
                    } else {
                        let r = n.first_index..n.first_index + n.prim_count;
                        deepest = deepest.max(n.prim_count);
                        let mid = r.start + (r.end - r.start) / 2;
                        (
                            *n.aabb(),
                            From::Slots(r.start..mid),
                            From::Slots(mid..r.end),
                        )
                    }
                }
                From::Slots(r) if r.end - r.start == 1 => {
                    nodes[at] = Bvh2Node::new(self.bounds(r.clone()), 1, r.start);
                    continue;
                }
                From::Slots(r) => {
                    let mid = r.start + (r.end - r.start) / 2;
                    (
                        self.bounds(r.clone()),
                        From::Slots(r.start..mid),
                        From::Slots(mid..r.end),
                    )
                }
            };
            let k = nodes.len();
            nodes[at] = Bvh2Node::new(children, 0, k as u32);
            nodes.extend([Bvh2Node::default(); 2]);
            stack.push((k + 1, second));
            stack.push((k, first));
        }
        debug_assert_eq!(nodes.len(), 2 * self.order.len() - 1);
        bvh.nodes = nodes;
        // A cluster of k primitives adds at most ceil(log2 k) levels below its leaf.
        bvh.max_depth += (u32::BITS - deepest.leading_zeros()) as usize + 1;
        bvh.children_are_ordered_after_parents = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A xorshift64 generator of floats in [0, 1) from `seed`.
    pub(super) fn xorshift(mut seed: u64) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// `n` small random triangles (each inside a unit cube) scattered through a 20 m cube:
    /// positions and triangles for [`Accel::build`].
    pub(super) fn triangle_soup(
        n: u32,
        rnd: &mut impl FnMut() -> f32,
    ) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut positions = vec![];
        let mut triangles = vec![];
        for i in 0..n {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 20.0 - 10.0;
            for _ in 0..3 {
                positions.push(c + Vec3::new(rnd(), rnd(), rnd()) - 0.5);
            }
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        (positions, triangles)
    }

    /// The kernels this CPU runs.
    fn kernels() -> Vec<Kernel> {
        let mut k = vec![Kernel::Sse];
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                k.push(Kernel::Avx2);
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                k.push(Kernel::Avx512);
            }
        }
        k
    }

    /// The closest hit and whether anything is hit, by testing every triangle: the smallest
    /// `(t, triangle)` over `t_min < t < t_max`.
    fn brute_force(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        ray: &Ray,
        t_min: f32,
    ) -> Option<(u32, u32)> {
        let (r, shear) = trace_ray(ray, t_min)?;
        triangles
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let tri = Triangle::new(t.map(|v| Vec3A::from(positions[v as usize])));
                let t = intersect_triangle(&tri, &shear, t_min, r.t_max).0;
                (t < r.t_max).then_some((t.to_bits(), i as u32))
            })
            .min()
    }

    /// Every node width and every kernel this CPU has finds exactly the closest hit of
    /// testing all triangles (same `t` bits, same triangle), and the occlusion queries agree,
    /// on a soup of small random triangles crossed by random rays, some of them along the
    /// axes (zero direction components).
    #[test]
    fn every_width_and_kernel_finds_the_brute_force_hits() {
        let mut rnd = xorshift(0x2545_f491_4f6c_dd1d);
        let (positions, triangles) = triangle_soup(3000, &mut rnd);
        let accels = [8, 16].map(|w| Accel::build_with_width(&positions, &triangles, |_| false, w));
        let (mut hits, mut blocked) = (0, 0);
        for k in 0..6_000 {
            let origin = Vec3::new(rnd(), rnd(), rnd()) * 30.0 - 15.0;
            let mut direction = (Vec3::new(rnd(), rnd(), rnd()) - 0.5).normalize();
            if k % 5 == 0 {
                // Along a coordinate plane or axis.
                direction[k % 3] = 0.0;
                if k % 10 == 0 {
                    direction[(k + 1) % 3] = 0.0;
                }
                direction = direction.normalize_or(Vec3::X);
            }
            let t_max = if k % 2 == 0 {
                f32::INFINITY
            } else {
                8.0 * rnd()
            };
            let ray = Ray {
                origin,
                direction,
                t_max,
                time: 0.0,
            };
            let t_min = accels[0].t_min;
            let want = brute_force(&positions, &triangles, &ray, t_min);
            for accel in &accels {
                for kernel in kernels() {
                    let got = accel
                        .closest_with(kernel, &ray, t_min, &mut |_, _| true, false)
                        .map(|h| (h.t.to_bits(), h.triangle));
                    assert_eq!(got, want, "ray {k} {kernel:?} {:?}: {ray:?}", accel.tree);
                    let any = accel.any_with(kernel, &ray, t_min, &mut |_, _| true, false);
                    assert_eq!(any, want.is_some(), "ray {k} {kernel:?}: {ray:?}");
                }
            }
            hits += want.is_some() as u32;
            blocked += (want.is_some() && t_max.is_finite()) as u32;
        }
        // Both kinds of answer occur often.
        assert!((300..5_500).contains(&hits), "{hits} hits");
        assert!(blocked > 50, "{blocked} blocked");
    }

    /// Rays at a closed mesh's vertices and edges, from inside and from its exact centre
    /// (whose coordinates lie on the faces of its boxes), all hit it through the BVH, at
    /// both widths and with every kernel. obvhs' compressed-node walk lost 16 of the 3,382
    /// rays aimed at vertices and 1,035 of the 41,362 from the centre.
    #[test]
    fn rays_from_box_faces_do_not_miss_a_closed_mesh() {
        let (p, t) = uv_sphere(12, 16);
        let mut rnd = xorshift(23);
        let mut targets = p.clone();
        for tri in &t {
            for e in 0..3 {
                let (a, b) = (p[tri[e] as usize], p[tri[(e + 1) % 3] as usize]);
                for k in 1..8 {
                    targets.push(a.lerp(b, k as f32 / 8.0));
                }
            }
        }
        for width in [8, 16] {
            let accel = Accel::build_with_width(&p, &t, |_| false, width);
            for kernel in kernels() {
                let (mut lost, mut rays) = (0, 0);
                for k in 0..6 {
                    let origin =
                        (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * if k == 0 { 0.0 } else { 0.8 };
                    for &q in &targets {
                        let ray = Ray::new(origin, (q - origin).normalize());
                        rays += 1;
                        let hit =
                            accel.closest_with(kernel, &ray, accel.t_min, &mut |_, _| true, false);
                        let any =
                            accel.any_with(kernel, &ray, accel.t_min, &mut |_, _| true, false);
                        lost += (hit.is_none() || !any) as u32;
                    }
                }
                assert_eq!(
                    lost, 0,
                    "width {width} {kernel:?}: {lost} of {rays} rays lost"
                );
            }
        }
    }

    /// The step-by-step build makes exactly the binary tree of obvhs' own `medium_build` path
    /// (compared through obvhs' conversion of both to its compressed-wide BVH), on
    /// enough triangles for its parallel sort and cost passes. (From 500k triangles on, obvhs'
    /// own path folds the origin into the scene box, through a zero-filled scratch buffer of
    /// its pre-sized builder, which moves the Morton codes slightly; ours uses the true box.)
    #[test]
    fn build_matches_obvhs_medium_build() {
        assert!(matches!(
            BUILD_PARAMS.ploc_search_distance,
            obvhs::ploc::PlocSearchDistance::Medium
        ));
        let mut rng = crate::sampling::Pcg32::new(7, 1);
        let soup: Vec<obvhs::triangle::Triangle> = (0..400_000)
            .map(|_| {
                let c = Vec3A::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 100.0;
                let mut v = || c + Vec3A::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                obvhs::triangle::Triangle {
                    v0: v(),
                    v1: v(),
                    v2: v(),
                }
            })
            .collect();
        let ours = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
            &build_bvh2(
                soup.iter().map(|t| t.aabb()),
                BUILD_PARAMS.reinsertion_batch_ratio,
                false,
            ),
            BUILD_PARAMS.max_prims_per_leaf.clamp(1, 3),
            true,
            false,
        );
        assert_eq!(reinsertion_ratio(soup.len()), 0.125);
        assert_eq!(
            reinsertion_ratio(2_000_000),
            BUILD_PARAMS.reinsertion_batch_ratio
        );
        let theirs = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &soup,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        assert!(ours.primitive_indices == theirs.primitive_indices);
        assert!(ours.nodes == theirs.nodes, "node arrays differ");
        assert_eq!(ours.total_aabb, theirs.total_aabb);
    }

    #[test]
    fn empty_accel_misses() {
        let a = Accel::build(&[], &[]);
        let r = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!(a.intersect(&r).is_none());
        assert!(!a.occluded(&r));
    }

    /// A closed UV sphere, its triangles sharing edges and vertices bit for bit.
    fn uv_sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut p = vec![Vec3::Y, -Vec3::Y];
        for i in 1..rings {
            let theta = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..segments {
                let phi = std::f32::consts::TAU * j as f32 / segments as f32;
                p.push(Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ));
            }
        }
        let at = |i: u32, j: u32| 2 + (i - 1) * segments + j % segments;
        let mut t = Vec::new();
        for j in 0..segments {
            t.push([0, at(1, j + 1), at(1, j)]);
            t.push([1, at(rings - 1, j), at(rings - 1, j + 1)]);
            for i in 1..rings - 1 {
                let [a, b, c, d] = [at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)];
                t.push([a, b, d]);
                t.push([a, d, c]);
            }
        }
        (p, t)
    }

    /// Watertightness of the triangle test: every ray from a point inside a closed mesh
    /// toward one of its shared edges or vertices hits one of its triangles. With
    /// Möller-Trumbore, 51,400 of these 413,620 rays passed between two triangles.
    #[test]
    fn rays_through_shared_edges_and_vertices_hit_a_closed_mesh() {
        let (p, t) = uv_sphere(12, 16);
        let tris: Vec<Triangle> = t
            .iter()
            .map(|t| Triangle::new(t.map(|i| Vec3A::from(p[i as usize]))))
            .collect();
        let mut rnd = xorshift(17);
        let mut targets = p.clone();
        for tri in &t {
            for e in 0..3 {
                let (a, b) = (p[tri[e] as usize], p[tri[(e + 1) % 3] as usize]);
                for k in 1..40 {
                    targets.push(a.lerp(b, k as f32 / 40.0));
                }
            }
        }
        let t_min = 16.0 * f32::EPSILON;
        let (mut lost, mut rays) = (0, 0);
        for k in 0..10 {
            let origin = (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * if k == 0 { 0.0 } else { 0.8 };
            for &q in &targets {
                let (r, shear) =
                    trace_ray(&Ray::new(origin, (q - origin).normalize()), t_min).unwrap();
                rays += 1;
                if !tris.iter().any(|tri| {
                    intersect_triangle(tri, &shear, t_min, r.t_max)
                        .0
                        .is_finite()
                }) {
                    lost += 1;
                }
            }
        }
        assert_eq!(lost, 0, "{lost} of {rays} rays left the closed mesh");
    }

    #[test]
    fn barycentrics_weight_second_and_third_vertex() {
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let a = Accel::build(&p, &[[0, 1, 2]]);
        let target = Vec3::new(0.2, 0.3, 0.0);
        let r = Ray::new(target + Vec3::Z, -Vec3::Z);
        let h = a.intersect(&r).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
        let b = h.barycentrics;
        let q = p[0] * (1.0 - b.x - b.y) + p[1] * b.x + p[2] * b.y;
        assert!((q - target).length() < 1e-6, "{b}");
        // Axis-aligned rays with negative zeros hit too.
        let r = Ray::new(target + Vec3::Z, Vec3::new(-0.0, -0.0, -1.0));
        assert!(a.intersect(&r).is_some() && a.occluded(&r));
        // A ray starting on the surface does not hit it again.
        let r = Ray::new(target, Vec3::new(1.0, 0.0, 1e-3).normalize());
        assert!(a.intersect(&r).is_none());
    }
}

/// Degenerate and hostile geometry builds in about `n log n` and is hit where it is.
#[cfg(test)]
mod degenerate_tests {
    use super::*;
    use std::time::{Duration, Instant};

    /// Builds, checks the build took under `seconds` and the BVH is shallow, and returns it.
    fn build(label: &str, positions: &[Vec3], tris: &[[u32; 3]], seconds: u64) -> Accel {
        let start = Instant::now();
        let a = Accel::build(positions, tris);
        let took = start.elapsed();
        assert!(took < Duration::from_secs(seconds), "{label}: {took:?}");
        assert_eq!(a.triangle_count(), tris.len(), "{label}");
        a
    }

    /// The triangles `(0,0,0)`-ish of growing size `1 + i/1000`, all with centroid 0.
    fn same_centroid(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        let mut t = Vec::new();
        for i in 0..n {
            let s = 1.0 + i as f32 * 1e-3;
            p.extend([
                Vec3::new(-s, -s, 0.0),
                Vec3::new(2.0 * s, -s, 0.0),
                Vec3::new(-s, 2.0 * s, 0.0),
            ]);
            t.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        (p, t)
    }

    /// Before clusters, 5,000 coincident triangles took 0.9 s, 10,000 took 2.9 s (so 100,000
    /// about five minutes), and 10,000 coincident points overflowed the stack; 100,000 now
    /// take well under a second.
    #[test]
    fn coincident_triangles_build_quickly_and_are_hit() {
        let n = 100_000;
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let a = build("coincident", &p, &vec![[0, 1, 2]; n], 10);
        let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        assert!((a.intersect(&ray).unwrap().t - 1.0).abs() < 1e-6);
        assert!(a.occluded(&ray));
        let (p, t) = same_centroid(n as u32);
        let a = build("same centroid", &p, &t, 10);
        let ray = Ray::new(Vec3::new(0.1, 0.2, -2.0), Vec3::Z);
        assert!((a.intersect(&ray).unwrap().t - 2.0).abs() < 1e-6);
        // 50,000 coincident triangles among 50,000 scattered ones: the boxes cover the scene
        // a few times over on average, so only the cluster finds them.
        let mut rnd = super::tests::xorshift(5);
        let (mut p, mut t) = super::tests::triangle_soup(50_000, &mut rnd);
        let k = p.len() as u32;
        p.extend([
            Vec3::new(0.0, 0.0, 30.0),
            Vec3::new(0.5, 0.0, 30.0),
            Vec3::new(0.0, 0.5, 30.0),
        ]);
        t.extend(std::iter::repeat_n([k, k + 1, k + 2], 50_000));
        let a = build("coincident among others", &p, &t, 10);
        let ray = Ray::new(Vec3::new(0.1, 0.1, 31.0), -Vec3::Z);
        assert!((a.intersect(&ray).unwrap().t - 1.0).abs() < 1e-5);
        // Zero-area triangles: all at one point, or scattered; rays miss them.
        let a = build("points", &[Vec3::ONE], &vec![[0, 0, 0]; n], 10);
        assert!(a.intersect(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
        let p: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(i as f32 * 0.37 % 11.0, i as f32 * 0.71 % 13.0, 0.0))
            .collect();
        let t: Vec<[u32; 3]> = (0..n as u32).map(|i| [i, i, i]).collect();
        let a = build("scattered points", &p, &t, 10);
        assert!(a
            .intersect(&Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z))
            .is_none());
    }

    /// A fan of 1,000,000 slivers around one vertex (a huge polygon's triangulation): 68 s
    /// and growing with the square of the count before, under a second now; hit where it is.
    #[test]
    fn huge_fans_build_quickly_and_are_hit() {
        let n = 1_000_000u32;
        let mut p = vec![Vec3::ZERO];
        let mut t = Vec::new();
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            p.push(Vec3::new(a.cos(), a.sin(), 0.0));
            if i > 0 {
                t.push([0, i, i + 1]);
            }
        }
        let a = build("fan", &p, &t, 10);
        for target in [Vec3::new(0.3, 0.4, 0.0), Vec3::new(-0.5, -0.1, 0.0)] {
            let ray = Ray::new(target + Vec3::Z, -Vec3::Z);
            assert!(
                (a.intersect(&ray).unwrap().t - 1.0).abs() < 1e-6,
                "{target}"
            );
        }
        assert!(a
            .intersect(&Ray::new(Vec3::new(1.5, 0.0, 1.0), -Vec3::Z))
            .is_none());
    }

    /// Boxes nested along the Morton curve (one corner shared, growing): PLOC's first pass
    /// merges one pair per pass; they are one cluster.
    #[test]
    fn nested_boxes_build_quickly() {
        let n = 100_000u32;
        let mut p = Vec::new();
        let mut t = Vec::new();
        for i in 0..n {
            let s = 1.0 + i as f32 * 1e-2;
            p.extend([Vec3::ZERO, Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, s, s)]);
            t.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let a = build("nested", &p, &t, 10);
        // All in the plane y = z; (0.2, 0.1, 0.1) is on every triangle.
        let ray = Ray::new(
            Vec3::new(0.2, -0.9, 1.1),
            Vec3::new(0.0, 1.0, -1.0).normalize(),
        );
        let t = a.intersect(&ray).unwrap().t;
        assert!((t - std::f32::consts::SQRT_2).abs() < 1e-5, "{t}");
    }
}
