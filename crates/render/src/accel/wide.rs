//! The wide BVH the traversal walks: obvhs' binary tree collapsed into nodes of `W` children
//! (8 for AVX2, 16 for AVX-512), each child's box stored as uncompressed `f32` planes laid out
//! by plane (`min_x` of all children, then `min_y`, ...), so that one node test is six loads,
//! six subtractions, six multiplications and a few minima and maxima over all `W` lanes.
//!
//! The node test is conservative (Ize 2013, as pbrt-v4's `Bounds3::IntersectP`): each slab's
//! exit distance is scaled up by `1 + 2 gamma(3)`, the relative error of `(plane - origin) *
//! (1 / direction)` in `f32`, so a ray whose true path enters a box is never told it missed it
//! by rounding. A direction component of zero gives an infinite reciprocal, and a ray whose
//! origin lies on that slab's plane gives `0 * inf = NaN`: the minima and maxima keep the
//! running bound where a lane is NaN (x86's `minps`/`maxps` rule, written out as comparisons),
//! so such a slab does not restrict the ray, which is right for a ray running inside the plane.
//!
//! Traversal is ordered: the children a ray enters are taken nearest first, the others pushed
//! with their entry distances and dropped when popped beyond the closest hit so far. Any-hit
//! queries (shadow rays) stop at the first hit and do not sort.
//!
//! The same source is compiled three times (plain, `avx2`, `avx512f`: [`Kernel`]) and the
//! compiler vectorises the node test over the `W` lanes; every lane does the same IEEE
//! operations in the same order (no fused multiply-add), so hits do not depend on the kernel.
//! They do not depend on the width either: the closest hit is the smallest `(t, triangle)`,
//! whatever order the boxes are visited in (the callers' tie-break on the triangle index).

use obvhs::bvh2::Bvh2;
use std::mem::MaybeUninit;

/// Children per leaf entry, at most: a binary subtree of up to this many primitives is one
/// leaf entry (its primitives tested one after another) when the node has no free lane for it.
const LEAF_MAX: u32 = 3;

/// A child entry is a leaf when this bit is set: bits 28 to 30 hold the primitive count minus
/// one, bits 0 to 27 the first primitive slot.
const LEAF: u32 = 1 << 31;
const LEAF_SHIFT: u32 = 28;
const SLOT_MASK: u32 = (1 << LEAF_SHIFT) - 1;

/// The most primitives a wide BVH holds (the slot bits of a leaf entry).
pub(super) const MAX_PRIMITIVES: usize = 1 << LEAF_SHIFT;

/// Entries of the traversal stack. The build checks that no path needs more
/// ([`Wide::stack_need`]); a tree that would (a pathological chain) is rebuilt balanced.
pub(super) const STACK: usize = 256;

/// `1 + 2 gamma(3)` rounded up, with `gamma(n) = n eps / (1 - n eps)` and `eps = 2^-24`: the
/// factor that widens a slab's exit distance for rounding (pbrt-v4).
const ROBUST: f32 = 1.000_000_4;

/// One node: the boxes and entries of its `W` children. Unused lanes have an empty box
/// (`min = +inf`, `max = -inf`), which no ray enters.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node<const W: usize> {
    /// `min_x`, `min_y`, `min_z`, `max_x`, `max_y`, `max_z` of each child.
    planes: [[f32; W]; 6],
    /// Each child's entry: a node index, or a leaf ([`LEAF`]).
    child: [u32; W],
}

impl<const W: usize> Node<W> {
    const EMPTY: Self = Self {
        planes: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        child: [0; W],
    };
}

/// A ray as the node test needs it: origin, reciprocal direction, which plane of each axis is
/// entered first (by the direction's sign), and the interval of `t` it looks in.
#[derive(Clone, Copy, Debug)]
pub(super) struct TraceRay {
    origin: [f32; 3],
    inv: [f32; 3],
    /// Plane index (into [`Node::planes`]) of the plane of each axis the ray enters by.
    near: [usize; 3],
    /// Plane index of the plane of each axis the ray leaves by.
    far: [usize; 3],
    /// Hits at or before this are not wanted.
    pub(super) t_min: f32,
    /// Hits at or beyond this are not wanted.
    pub(super) t_max: f32,
}

impl TraceRay {
    /// The ray from `origin` along `direction` (finite, the direction without negative
    /// zeros) looking in `(t_min, t_max)`.
    #[inline(always)]
    pub(super) fn new(origin: [f32; 3], direction: [f32; 3], t_min: f32, t_max: f32) -> Self {
        let inv = direction.map(|d| 1.0 / d);
        let near = [0, 1, 2].map(|k| if direction[k] < 0.0 { 3 + k } else { k });
        let far = [0, 1, 2].map(|k| if direction[k] < 0.0 { k } else { 3 + k });
        Self {
            origin,
            inv,
            near,
            far,
            t_min,
            t_max,
        }
    }
}

/// `max(x, acc)`, keeping `acc` where `x` is NaN (`maxps`' rule).
#[inline(always)]
fn max_keep(x: f32, acc: f32) -> f32 {
    if x > acc {
        x
    } else {
        acc
    }
}

/// `min(x, acc)`, keeping `acc` where `x` is NaN (`minps`' rule).
#[inline(always)]
fn min_keep(x: f32, acc: f32) -> f32 {
    if x < acc {
        x
    } else {
        acc
    }
}

/// The node test: for each child, the distance at which `ray` enters its box (into `near`)
/// and whether it does before `t_max` (bit `i` of the result).
#[inline(always)]
fn test_node<const W: usize>(
    node: &Node<W>,
    ray: &TraceRay,
    t_max: f32,
    near: &mut [f32; W],
) -> u32 {
    let [ox, oy, oz] = ray.origin;
    let [ix, iy, iz] = ray.inv;
    let (nx, ny, nz) = (
        &node.planes[ray.near[0]],
        &node.planes[ray.near[1]],
        &node.planes[ray.near[2]],
    );
    let (fx, fy, fz) = (
        &node.planes[ray.far[0]],
        &node.planes[ray.far[1]],
        &node.planes[ray.far[2]],
    );
    let mut enters = [false; W];
    for i in 0..W {
        let t0 = max_keep(
            (nz[i] - oz) * iz,
            max_keep((ny[i] - oy) * iy, max_keep((nx[i] - ox) * ix, ray.t_min)),
        );
        let t1 = min_keep(
            (fz[i] - oz) * iz,
            min_keep(
                (fy[i] - oy) * iy,
                min_keep((fx[i] - ox) * ix, f32::INFINITY),
            ),
        );
        let t1 = min_keep(t1 * ROBUST, t_max);
        near[i] = t0;
        enters[i] = t0 <= t1;
    }
    let mut mask = 0u32;
    for (i, &e) in enters.iter().enumerate() {
        mask |= (e as u32) << i;
    }
    mask
}

/// A traversal stack entry: a child entry and the distance at which the ray enters it.
#[derive(Clone, Copy)]
struct Entry {
    child: u32,
    near: f32,
}

/// A fixed stack of [`STACK`] entries, not initialised (a query allocates nothing and
/// clears nothing).
struct Stack {
    entries: [MaybeUninit<Entry>; STACK],
    len: usize,
}

impl Stack {
    #[inline(always)]
    fn new() -> Self {
        Self {
            entries: [const { MaybeUninit::uninit() }; STACK],
            len: 0,
        }
    }

    #[inline(always)]
    fn push(&mut self, e: Entry) {
        // The build bounds every path's pushes by `STACK` (`Wide::stack_need`); the index
        // check stays as the guarantee.
        self.entries[self.len] = MaybeUninit::new(e);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Entry> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were written by `push`.
        Some(unsafe { self.entries[self.len].assume_init() })
    }

    /// Sorts the entries from `base` up so that the nearest is on top (popped first).
    #[inline(always)]
    fn sort_from(&mut self, base: usize) {
        for i in base + 1..self.len {
            // SAFETY: entries below `len` were written by `push`.
            let e = unsafe { self.entries[i].assume_init() };
            let mut j = i;
            while j > base {
                // SAFETY: as above.
                let prev = unsafe { self.entries[j - 1].assume_init() };
                if prev.near >= e.near {
                    break;
                }
                self.entries[j] = MaybeUninit::new(prev);
                j -= 1;
            }
            self.entries[j] = MaybeUninit::new(e);
        }
    }
}

/// The leaf entry's primitive slots.
#[inline(always)]
fn leaf_slots(entry: u32) -> std::ops::Range<u32> {
    let first = entry & SLOT_MASK;
    let count = ((entry & !LEAF) >> LEAF_SHIFT) + 1;
    first..first + count
}

/// A wide BVH: nodes of `W` children over primitive slots `0..order.len()`.
#[derive(Clone, Debug)]
pub(super) struct Wide<const W: usize> {
    nodes: Vec<Node<W>>,
    /// The root's entry (a leaf when the whole tree is one).
    root: u32,
    /// The binary tree's primitive index of each slot: leaves hold consecutive slots.
    pub(super) order: Vec<u32>,
}

impl<const W: usize> Wide<W> {
    /// Collapses `bvh2` (whose leaves hold one primitive each, or a few) into `W`-wide nodes:
    /// each node opens the child with the largest surface area until it has `W` children or
    /// only leaves are left; a remaining child subtree of at most [`LEAF_MAX`] primitives
    /// becomes a leaf entry, a larger one a node of its own.
    pub(super) fn from_bvh2(bvh2: &Bvh2) -> Self {
        assert!(W <= 32, "a node's hit mask has 32 bits");
        let n = bvh2.nodes.len();
        let mut order = Vec::with_capacity(bvh2.primitive_indices.len());
        // Primitives below each binary node (children may come before or after parents).
        let mut count = vec![0u32; n];
        let mut post = Vec::with_capacity(n);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            post.push(i);
            let node = &bvh2.nodes[i];
            if node.prim_count == 0 {
                let c = node.first_index as usize;
                stack.extend([c, c + 1]);
            }
        }
        for &i in post.iter().rev() {
            let node = &bvh2.nodes[i];
            count[i] = if node.prim_count == 0 {
                let c = node.first_index as usize;
                count[c] + count[c + 1]
            } else {
                node.prim_count
            };
        }
        drop(post);
        // Appends the primitives of binary subtree `i` to `order`; the leaf entry over them.
        let gather = |i: usize, order: &mut Vec<u32>| -> u32 {
            let first = order.len() as u32;
            let mut stack = vec![i];
            while let Some(i) = stack.pop() {
                let node = &bvh2.nodes[i];
                if node.prim_count == 0 {
                    let c = node.first_index as usize;
                    stack.extend([c + 1, c]);
                } else {
                    let p =
                        node.first_index as usize..(node.first_index + node.prim_count) as usize;
                    order.extend_from_slice(&bvh2.primitive_indices[p]);
                }
            }
            let k = order.len() as u32 - first;
            // Binary leaves hold one primitive each (`super::ploc` expands its clusters).
            assert!(
                (1..=1 << (31 - LEAF_SHIFT)).contains(&k),
                "a leaf entry of {k} primitives"
            );
            LEAF | ((k - 1) << LEAF_SHIFT) | first
        };
        let is_small = |i: usize| count[i] <= LEAF_MAX;
        let root_node = &bvh2.nodes[0];
        if root_node.prim_count != 0 || is_small(0) {
            let root = gather(0, &mut order);
            return Self {
                nodes: Vec::new(),
                root,
                order,
            };
        }
        let mut nodes: Vec<Node<W>> = vec![Node::EMPTY];
        // (binary node, wide node it becomes)
        let mut todo = vec![(0usize, 0usize)];
        while let Some((b, w)) = todo.pop() {
            let c = bvh2.nodes[b].first_index as usize;
            let mut kids: Vec<usize> = vec![c, c + 1];
            while kids.len() < W {
                // The inner child with the largest surface area.
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|&(_, &k)| bvh2.nodes[k].prim_count == 0)
                    .max_by(|a, b| {
                        let area = |k: usize| bvh2.nodes[k].aabb().half_area();
                        area(*a.1).total_cmp(&area(*b.1))
                    })
                    .map(|(at, _)| at);
                let Some(at) = open else { break };
                let k = kids.swap_remove(at);
                let c = bvh2.nodes[k].first_index as usize;
                kids.extend([c, c + 1]);
            }
            let mut node = Node::EMPTY;
            for (lane, &k) in kids.iter().enumerate() {
                let aabb = bvh2.nodes[k].aabb();
                for axis in 0..3 {
                    node.planes[axis][lane] = aabb.min[axis];
                    node.planes[3 + axis][lane] = aabb.max[axis];
                }
                node.child[lane] = if bvh2.nodes[k].prim_count != 0 || is_small(k) {
                    gather(k, &mut order)
                } else {
                    nodes.push(Node::EMPTY);
                    let at = nodes.len() - 1;
                    todo.push((k, at));
                    at as u32
                };
            }
            nodes[w] = node;
        }
        nodes.shrink_to_fit();
        Self {
            nodes,
            root: 0,
            order,
        }
    }

    /// The most stack entries a traversal can need: over all root-to-leaf paths, the sum of
    /// each node's children but the one descended into.
    pub(super) fn stack_need(&self) -> usize {
        if self.root & LEAF != 0 {
            return 1;
        }
        let mut worst = 0;
        let mut stack = vec![(self.root as usize, 1usize)];
        while let Some((i, depth)) = stack.pop() {
            let node = &self.nodes[i];
            let children = node.planes[0].iter().filter(|v| v.is_finite()).count();
            let need = depth + children.saturating_sub(1);
            worst = worst.max(need);
            for lane in 0..children {
                let c = node.child[lane];
                if c & LEAF == 0 {
                    stack.push((c as usize, need));
                }
            }
        }
        worst
    }

    /// Heap memory of the nodes and the slot order, in bytes.
    pub(super) fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice()) + std::mem::size_of_val(self.order.as_slice())
    }

    /// The number of nodes.
    pub(super) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Closest-hit traversal: `visit(slot, t_max)` tests a primitive against the ray's current
    /// end and returns the new end (smaller where it hit, or equal); the final end.
    #[inline(always)]
    pub(super) fn closest(&self, ray: &TraceRay, mut visit: impl FnMut(u32, f32) -> f32) -> f32 {
        let mut t_max = ray.t_max;
        let mut stack = Stack::new();
        stack.push(Entry {
            child: self.root,
            near: ray.t_min,
        });
        let mut near = [0.0f32; W];
        while let Some(entry) = stack.pop() {
            if entry.near > t_max {
                continue;
            }
            let mut child = entry.child;
            loop {
                if child & LEAF != 0 {
                    for slot in leaf_slots(child) {
                        t_max = visit(slot, t_max);
                    }
                    break;
                }
                let node = &self.nodes[child as usize];
                let mut mask = test_node(node, ray, t_max, &mut near);
                if mask == 0 {
                    break;
                }
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    child = node.child[first];
                    continue;
                }
                let base = stack.len;
                stack.push(Entry {
                    child: node.child[first],
                    near: near[first],
                });
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack.push(Entry {
                        child: node.child[i],
                        near: near[i],
                    });
                }
                stack.sort_from(base);
                // The nearest goes on at once.
                child = match stack.pop() {
                    Some(e) => e.child,
                    None => break,
                };
            }
        }
        t_max
    }

    /// Any-hit traversal: whether `visit(slot)` says true for some primitive whose box the
    /// ray enters (stopping at the first).
    #[inline(always)]
    pub(super) fn any(&self, ray: &TraceRay, mut visit: impl FnMut(u32) -> bool) -> bool {
        let mut stack = Stack::new();
        stack.push(Entry {
            child: self.root,
            near: ray.t_min,
        });
        let mut near = [0.0f32; W];
        while let Some(entry) = stack.pop() {
            let mut child = entry.child;
            loop {
                if child & LEAF != 0 {
                    for slot in leaf_slots(child) {
                        if visit(slot) {
                            return true;
                        }
                    }
                    break;
                }
                let node = &self.nodes[child as usize];
                let mut mask = test_node(node, ray, ray.t_max, &mut near);
                if mask == 0 {
                    break;
                }
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack.push(Entry {
                        child: node.child[i],
                        near: near[i],
                    });
                }
                child = node.child[first];
            }
        }
        false
    }
}

/// The compilation of the traversal a query runs: the widest the process's
/// [`crate::simd::level`] allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// The build's baseline (SSE on x86-64).
    Sse,
    /// Compiled for AVX2.
    Avx2,
    /// Compiled for AVX-512F.
    Avx512,
}

impl Kernel {
    /// The process's kernel (`STREAKS_SIMD` caps it; see [`crate::simd`]).
    pub fn of_process() -> Self {
        static KERNEL: std::sync::OnceLock<Kernel> = std::sync::OnceLock::new();
        *KERNEL.get_or_init(|| match crate::simd::level() {
            crate::simd::SimdLevel::Sse => Self::Sse,
            crate::simd::SimdLevel::Avx2 => Self::Avx2,
            crate::simd::SimdLevel::Avx512 => Self::Avx512,
        })
    }

    /// The node width that suits the kernel: 16 lanes fill one AVX-512 register, 8 one AVX2
    /// register (and two SSE registers).
    pub fn width(self) -> usize {
        match self {
            Self::Avx512 => 16,
            Self::Sse | Self::Avx2 => 8,
        }
    }
}

/// A walk of a [`Wide`] BVH with its leaf visit, which [`run`] compiles for a kernel.
pub(super) trait Walk<const W: usize> {
    /// What the walk returns.
    type Output;
    /// Walks `wide` with `ray`.
    fn walk(self, wide: &Wide<W>, ray: &TraceRay) -> Self::Output;
}

/// [`Wide::closest`] with its visit.
pub(super) struct Closest<F>(pub F);

impl<const W: usize, F: FnMut(u32, f32) -> f32> Walk<W> for Closest<F> {
    type Output = f32;
    #[inline(always)]
    fn walk(self, wide: &Wide<W>, ray: &TraceRay) -> f32 {
        wide.closest(ray, self.0)
    }
}

/// [`Wide::any`] with its visit.
pub(super) struct AnyHit<F>(pub F);

impl<const W: usize, F: FnMut(u32) -> bool> Walk<W> for AnyHit<F> {
    type Output = bool;
    #[inline(always)]
    fn walk(self, wide: &Wide<W>, ray: &TraceRay) -> bool {
        wide.any(ray, self.0)
    }
}

/// `walk` compiled for `kernel` (the baseline where the CPU lacks it).
#[inline(always)]
pub(super) fn run<const W: usize, K: Walk<W>>(
    kernel: Kernel,
    wide: &Wide<W>,
    ray: &TraceRay,
    walk: K,
) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2")]
        unsafe fn avx2<const W: usize, K: Walk<W>>(
            wide: &Wide<W>,
            ray: &TraceRay,
            walk: K,
        ) -> K::Output {
            walk.walk(wide, ray)
        }
        #[target_feature(enable = "avx512f")]
        unsafe fn avx512<const W: usize, K: Walk<W>>(
            wide: &Wide<W>,
            ray: &TraceRay,
            walk: K,
        ) -> K::Output {
            walk.walk(wide, ray)
        }
        match kernel {
            Kernel::Avx512 if std::arch::is_x86_feature_detected!("avx512f") => {
                // SAFETY: the CPU has AVX-512F (checked just above).
                return unsafe { avx512(wide, ray, walk) };
            }
            Kernel::Avx2 if std::arch::is_x86_feature_detected!("avx2") => {
                // SAFETY: the CPU has AVX2 (checked just above).
                return unsafe { avx2(wide, ray, walk) };
            }
            _ => {}
        }
    }
    let _ = kernel;
    walk.walk(wide, ray)
}
