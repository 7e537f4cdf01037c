//! The light choice's weights of a tree node's children, computed in SIMD lanes: all 16
//! children in one AVX-512 pass, 8 at a time in AVX2, 4 in SSE ([`crate::simd`] chooses).
//!
//! [`TreeLanes`] holds, for every set of siblings of the [light tree](super::tree) (the root's
//! children, and each group's), a structure-of-arrays copy of what their weights need: a
//! [`NodeLanes`], built once with the scene. One formula covers every kind of child, so that
//! no lane branches:
//!
//! - `E`, the irradiance-like weight: `scale / max(d^2, r^2)` for groups and emitter meshes
//!   (`scale` = power / 4 pi, `r` the bounding radius; zero behind a flat one-sided mesh's
//!   plane), plus for a group with spot lights their summed intensity over `max(d^2, r^2)`
//!   where the point may lie in their beams ([`super::tree::GroupBeam`]: within the beam's
//!   half-angle plus the group's angular radius `asin(r / d)` of its axis, or inside the
//!   group's sphere), `scale * falloff * window / d^2` for point and spot lights (`scale` = the
//!   luminance of the intensity; the spot's KHR_lights_punctual falloff and the range window,
//!   1 where absent), `scale` itself for a directional light (the luminance of its irradiance);
//!   zero unless positive and finite;
//! - the direction the BSDF weight `F` looks in: toward a group's most powerful member, a
//!   mesh's centre or a punctual light, or against a directional light's direction;
//! - then, as before the lanes, the direction's shading-frame coordinates, the side tests and
//!   [`LuminanceEval`]'s value, and `E F` with `F` = the BSDF's luminance times the cosine;
//! - for a BSDF with a glossy lobe ([`BsdfWeight`], made once per choice), `F` of a group or
//!   mesh whose bounding cone holds the lobe's mirror direction and is more than
//!   [`SHARP_LOBE_CONE_RATIO`] times as wide as the lobe is at least the lobe's reflectance
//!   over the cone's solid angle (see [`super::choice`]).
//!
//! A set skips the terms that are the identity for all of its children (no range window
//! without a range, no spot falloff without spots, ...: [`Holds`]), and `F` where no child
//! gives `E > 0`, with the same bits as computing them.
//!
//! The sums `sum E` and `sum E F` are taken child by child in order, so the weights and the
//! choice are bit for bit the same at every width (tested on every width this CPU has).

use super::emitter::{Emitter, Emitters};
use super::receiver::Receiver;
use super::tree::{LightTree, Node, BRANCHING};
use super::Light;
use crate::bsdf::numbers::{Wide, WideLanes};
use crate::bsdf::LuminanceEval;
use crate::simd::{level, SimdLevel};
use glam::Vec3;
use std::f32::consts::PI;
use std::ops::Range;
use streaks_image::luminance;

/// The weights `E_c` and `E_c F_c` of a node's children (zero past the last child), with their
/// sums.
pub(crate) type Weights = ([f32; BRANCHING], [f32; BRANCHING], f32, f32);

/// One value per child slot (unused slots hold a value that gives `E = 0`).
type Slots = [f32; BRANCHING];

/// A set of siblings of the light tree, by field, for the lanes (see the module
/// documentation). Slots past the last child have `scale = 0`, so `E = 0`.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(crate) struct NodeLanes {
    /// Where `E` is measured from: a group's or mesh's bounding-sphere centre, a light's
    /// position (unused for directional lights).
    pos: [Slots; 3],
    /// Where the BSDF weight looks: a point (group anchor, mesh centre, light position), or
    /// for a directional light the unit direction toward it.
    look: [Slots; 3],
    /// Squared bounding radius (0 for punctual lights).
    radius2: Slots,
    /// `E`'s numerator (see the module documentation).
    scale: Slots,
    /// A flat one-sided mesh's plane `(n, offset)`: lit where `n . p > offset`; else
    /// `(0, -inf)`, lit everywhere.
    plane: [Slots; 4],
    /// A spot light's axis (the direction it points along).
    axis: [Slots; 3],
    /// A spot light's `cos(outerConeAngle)`.
    cos_outer: Slots,
    /// A spot light's `cos_inner - cos_outer` (1 elsewhere).
    cone_width: Slots,
    /// A light's `range` (infinite without one).
    range: Slots,
    /// A group's spot lights' summed intensity (0 without any: see [`super::tree::GroupBeam`];
    /// the beam's axis is in `axis`).
    beam_scale: Slots,
    /// Cosine of a group's beam's half-angle.
    beam_cos: Slots,
    /// Sine of a group's beam's half-angle.
    beam_sin: Slots,
    /// 1 for point and spot lights.
    punctual: Slots,
    /// 1 for spot lights.
    spot: Slots,
    /// 1 for spot lights whose cones are equal (a hard edge).
    hard_edge: Slots,
    /// 1 for directional lights.
    directional: Slots,
    /// Which kinds of child the set holds.
    holds: Holds,
}

/// Which kinds of child a sibling set holds. The weights skip the terms that are the identity
/// for every child of the set (a set of emitter meshes and groups without spot lights has no
/// spot falloff, range window or beam; a set without groups or directional lights looks at
/// `F` from where it measures `E`), with the same bits as computing them.
#[derive(Clone, Copy, Debug, Default)]
struct Holds {
    /// Point or spot lights.
    punctual: bool,
    /// Spot lights.
    spot: bool,
    /// Lights with a `range`.
    range: bool,
    /// Groups with spot lights (a [`super::tree::GroupBeam`]).
    beam: bool,
    /// Flat one-sided meshes.
    plane: bool,
    /// Directional lights.
    directional: bool,
    /// Groups (whose `F` looks at their anchor, not at their centre).
    group: bool,
    /// Groups or meshes (a bounding radius, for the glossy lobe's mean over their cone).
    bounded: bool,
}

impl NodeLanes {
    /// The lanes of the children `nodes` of one node of `tree`.
    fn build(tree: &LightTree, emitters: &Emitters, nodes: Range<usize>) -> Self {
        let mut l = NodeLanes {
            pos: [[0.0; BRANCHING]; 3],
            look: [[0.0; BRANCHING]; 3],
            radius2: [0.0; BRANCHING],
            scale: [0.0; BRANCHING],
            plane: [
                [0.0; BRANCHING],
                [0.0; BRANCHING],
                [0.0; BRANCHING],
                [f32::NEG_INFINITY; BRANCHING],
            ],
            axis: [[0.0; BRANCHING]; 3],
            cos_outer: [0.0; BRANCHING],
            cone_width: [1.0; BRANCHING],
            range: [f32::INFINITY; BRANCHING],
            beam_scale: [0.0; BRANCHING],
            beam_cos: [1.0; BRANCHING],
            beam_sin: [0.0; BRANCHING],
            punctual: [0.0; BRANCHING],
            spot: [0.0; BRANCHING],
            hard_edge: [0.0; BRANCHING],
            directional: [0.0; BRANCHING],
            holds: Holds::default(),
        };
        let set3 = |a: &mut [Slots; 3], c: usize, v: glam::Vec3| {
            [a[0][c], a[1][c], a[2][c]] = v.to_array();
        };
        for (c, node) in tree.nodes()[nodes].iter().enumerate() {
            match *node {
                Node::Group(g) => {
                    l.holds.group = true;
                    l.holds.bounded = true;
                    set3(&mut l.pos, c, g.centre);
                    set3(&mut l.look, c, g.anchor);
                    l.radius2[c] = g.radius * g.radius;
                    l.scale[c] = g.isotropic_power / (4.0 * PI);
                    if let Some(b) = g.beam {
                        l.holds.beam = true;
                        set3(&mut l.axis, c, b.axis);
                        l.beam_scale[c] = b.intensity;
                        l.beam_cos[c] = b.cos;
                        l.beam_sin[c] = b.sin;
                    }
                }
                Node::Emitter(e) => match emitters.get(e as usize) {
                    Emitter::Mesh(m) => {
                        l.holds.bounded = true;
                        set3(&mut l.pos, c, m.centre());
                        set3(&mut l.look, c, m.centre());
                        l.radius2[c] = m.radius() * m.radius();
                        l.scale[c] = m.power() / (4.0 * PI);
                        if let Some((n, offset)) = m.front_plane() {
                            l.holds.plane = true;
                            let [x, y, z] = n.to_array();
                            [l.plane[0][c], l.plane[1][c], l.plane[2][c]] = [x, y, z];
                            l.plane[3][c] = offset;
                        }
                    }
                    Emitter::Punctual(light) => match *light {
                        Light::Point {
                            position,
                            intensity,
                            range,
                        } => {
                            set3(&mut l.pos, c, position);
                            set3(&mut l.look, c, position);
                            l.scale[c] = luminance(intensity);
                            l.range[c] = range_or_infinite(range);
                            l.punctual[c] = 1.0;
                            l.holds.punctual = true;
                            l.holds.range |= l.range[c].is_finite();
                        }
                        Light::Spot {
                            position,
                            direction,
                            intensity,
                            cos_inner,
                            cos_outer,
                            range,
                        } => {
                            set3(&mut l.pos, c, position);
                            set3(&mut l.look, c, position);
                            set3(&mut l.axis, c, direction);
                            l.scale[c] = luminance(intensity);
                            l.range[c] = range_or_infinite(range);
                            l.punctual[c] = 1.0;
                            l.spot[c] = 1.0;
                            l.holds.punctual = true;
                            l.holds.spot = true;
                            l.holds.range |= l.range[c].is_finite();
                            l.cos_outer[c] = cos_outer;
                            // `spot_falloff`'s cases: a smooth ramp, or a hard edge.
                            let width = cos_inner - cos_outer;
                            if width > 1e-7 {
                                l.cone_width[c] = width;
                            } else {
                                l.hard_edge[c] = 1.0;
                            }
                        }
                        Light::Directional {
                            direction,
                            irradiance,
                        } => {
                            set3(&mut l.look, c, -direction);
                            l.scale[c] = luminance(irradiance);
                            l.directional[c] = 1.0;
                            l.holds.directional = true;
                        }
                    },
                },
            }
        }
        l
    }

    /// The weights of the first `n` children at the receiver, `L::WIDTH` children at a time
    /// (see the module documentation).
    #[inline(always)]
    fn weights_in<L: WideLanes>(&self, n: usize, rx: &Receiver, w: &BsdfWeight) -> Weights {
        let mut e_w = [0.0f32; BRANCHING];
        let mut ef_w = [0.0f32; BRANCHING];
        let p = rx.p.to_array();
        let (frame, ng) = (&rx.frame, rx.ng);
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let lobe = w.peak.map(|g| {
            (
                g.mirror.to_array().map(L::splat),
                L::splat(g.peak_over_ratio),
                L::splat(g.reflectance_over_2pi),
            )
        });
        let f = &w.f;
        let h = self.holds;
        for k in (0..n).step_by(L::WIDTH) {
            let at = |s: &Slots| L::load(&s[k..]);
            let flag = |s: &Slots| at(s).gt(zero);

            // E. Each term the set's children do not need is skipped ([`Holds`]): where it
            // is skipped it would be the identity (a window of 1 without a range, a falloff
            // of 1 without spots, no beam's intensity to add).
            let sp = [L::splat(p[0]), L::splat(p[1]), L::splat(p[2])];
            let d = [
                at(&self.pos[0]) - sp[0],
                at(&self.pos[1]) - sp[1],
                at(&self.pos[2]) - sp[2],
            ];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let dist = d2.sqrt();
            let scale = at(&self.scale);
            let r2 = at(&self.radius2);
            // The cosine of the direction from the light to the point with a spot's axis
            // (or a group beam's).
            let cos = if h.spot || h.beam {
                -(at(&self.axis[0]) * d[0] + at(&self.axis[1]) * d[1] + at(&self.axis[2]) * d[2])
                    / dist
            } else {
                zero
            };
            // A group's beam: the point may see its spots if its direction from the centre
            // (`cos` to the axis, as for a spot) is within the beam's half-angle plus the
            // group's angular radius `asin(r / d)`, or if it is inside the group's sphere.
            let bounded = if h.beam {
                let sin_r2 = (r2 / d2).saturate();
                let edge =
                    at(&self.beam_cos) * (one - sin_r2).sqrt() - at(&self.beam_sin) * sin_r2.sqrt();
                let edge = L::select(r2.ge(d2), L::splat(-2.0), edge);
                let in_beam = cos.ge(edge);
                scale + L::select(in_beam, at(&self.beam_scale), zero)
            } else {
                scale
            };
            let e = if h.punctual || h.directional {
                let window = if h.range {
                    let x = dist / at(&self.range);
                    (one - (x * x) * (x * x)).saturate()
                } else {
                    one
                };
                let falloff = if h.spot {
                    let cos_outer = at(&self.cos_outer);
                    let t = L::select(
                        flag(&self.hard_edge),
                        L::select(cos.ge(cos_outer), one, zero),
                        ((cos - cos_outer) / at(&self.cone_width)).saturate(),
                    );
                    L::select(flag(&self.spot), t * t, one)
                } else {
                    one
                };
                L::select(
                    flag(&self.punctual),
                    scale * (falloff * window) / d2,
                    L::select(flag(&self.directional), scale, bounded / d2.max(r2)),
                )
            } else {
                bounded / d2.max(r2)
            };
            let e = if h.plane {
                let front = at(&self.plane[0]) * p[0]
                    + at(&self.plane[1]) * p[1]
                    + at(&self.plane[2]) * p[2];
                L::select(front.gt(at(&self.plane[3])) & e.positive_finite(), e, zero)
            } else {
                L::select(e.positive_finite(), e, zero)
            };
            e.store(&mut e_w[k..]);
            if !L::any(e.gt(zero)) {
                // No child lights the point: `E F` is 0 whatever `F` is.
                zero.store(&mut ef_w[k..]);
                continue;
            }

            // The direction F looks in, normalised (`normalize_or_zero`, lane by lane): `d`
            // itself where the children look where they are measured from.
            let [x, y, z, r] = if h.group || h.directional {
                let directional = flag(&self.directional);
                let look = [at(&self.look[0]), at(&self.look[1]), at(&self.look[2])];
                let x = L::select(directional, look[0], look[0] - sp[0]);
                let y = L::select(directional, look[1], look[1] - sp[1]);
                let z = L::select(directional, look[2], look[2] - sp[2]);
                [x, y, z, one / (x * x + y * y + z * z).sqrt()]
            } else {
                [d[0], d[1], d[2], one / dist]
            };
            let r = L::select(r.positive_finite(), r, zero);
            let [x, y, z] = [x * r, y * r, z * r];
            // `Frame::to_local` and the geometric normal's side.
            let local = [
                x * frame.s.x + y * frame.s.y + z * frame.s.z,
                x * frame.t.x + y * frame.t.y + z * frame.t.z,
                x * frame.n.x + y * frame.n.y + z * frame.n.z,
            ];
            let geometric = x * ng.x + y * ng.y + z * ng.z;
            let lit = geometric.gt(zero) & local[2].gt(zero);
            let fc = if L::any(lit) {
                let cos = L::select(lit, local[2], zero);
                f.eval_lanes([local[0], local[1], cos]) * cos
            } else {
                // Every child is below the surface: `f cos` is 0 (the glossy lobe's mean over
                // a bounded child's cone may still raise it below).
                zero
            };
            let fc = match lobe {
                // A bounded child (group or mesh) whose cone holds the glossy lobe's mirror
                // direction and is much wider than the lobe: at least the lobe's mean over
                // the cone. With `t = sqrt(d^2 - r^2)` the tangent length (0 inside the
                // sphere), the cone's half-angle has `cos = t / dist`: it holds the mirror
                // direction `m` when `d.m >= t`, and the lobe's mean over it,
                // `rho (1 + cos) / sin^2` (with `rho` over 2 pi), is `rho (d^2 + t dist) / r^2`,
                // or `rho` inside the sphere. One division, where the angles' sines and
                // cosines took three.
                Some((m, peak_over_ratio, rho)) if h.bounded => {
                    let t = (d2 - r2).max(zero).sqrt();
                    let dm = d[0] * m[0] + d[1] * m[1] + d[2] * m[2];
                    let mean = rho * ((d2 + t * dist) / r2).max(one);
                    let holds =
                        dm.ge(t) & peak_over_ratio.gt(mean) & r2.gt(zero) & dist.positive_finite();
                    fc.max(L::select(holds, mean, zero))
                }
                _ => fc,
            };
            let fc = L::select(fc.positive_finite(), fc, zero);
            (e * fc).store(&mut ef_w[k..]);
        }
        let (mut e_sum, mut ef_sum) = (0.0f32, 0.0f32);
        for c in 0..n {
            e_sum += e_w[c];
            ef_sum += ef_w[c];
        }
        (e_w, ef_w, e_sum, ef_sum)
    }

    /// [`NodeLanes::weights_in`] in AVX2's eight lanes.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn weights_avx2(&self, n: usize, rx: &Receiver, w: &BsdfWeight) -> Weights {
        self.weights_in::<Wide<8>>(n, rx, w)
    }

    /// [`NodeLanes::weights_in`] in AVX-512's sixteen lanes.
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn weights_avx512(&self, n: usize, rx: &Receiver, w: &BsdfWeight) -> Weights {
        self.weights_in::<Wide<16>>(n, rx, w)
    }

    /// The weights of the first `n` children at the receiver, at SIMD level `simd` (which the
    /// CPU must have: [`crate::simd::level`] is always one it has), at most as wide as `n`
    /// needs (two children in 16 lanes would pay for 14 empty ones), and in SSE for a BSDF
    /// whose lanes call the C library ([`LuminanceEval::calls_libm`]): the same bits either
    /// way.
    #[inline]
    fn weights_at(&self, simd: SimdLevel, n: usize, rx: &Receiver, w: &BsdfWeight) -> Weights {
        let needed = match n {
            _ if w.f.calls_libm() => SimdLevel::Sse,
            0..=4 => SimdLevel::Sse,
            5..=8 => SimdLevel::Avx2,
            _ => SimdLevel::Avx512,
        };
        let simd = simd.min(needed);
        match simd {
            // SAFETY: `simd` is a level the CPU has.
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx512 => unsafe { self.weights_avx512(n, rx, w) },
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx2 => unsafe { self.weights_avx2(n, rx, w) },
            _ => self.weights_in::<glam::Vec4>(n, rx, w),
        }
    }
}

/// What the weights need of a receiver's BSDF, made once per light choice (not once per
/// level of the tree): its [`LuminanceEval`] and, for a glossy lobe, [`GlossyPeak`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct BsdfWeight {
    /// `luminance(f(wo, wi))` for any `wi`.
    pub(crate) f: LuminanceEval,
    /// The glossy lobe's peak, if the BSDF has a glossy lobe.
    peak: Option<GlossyPeak>,
}

/// How many times the lobe's solid angle a bounded child's cone must span before its `F`
/// looks past its anchor ([`GlossyPeak`]). The lobe's solid angle is taken as `rho / peak`
/// (its reflectance over its peak `f cos`), the cone's as `2 pi (1 - cos theta)`, so the
/// test is `peak / SHARP_LOBE_CONE_RATIO > rho / Omega`. In a cone as wide as the lobe, an
/// anchor inside the cone lies inside the lobe and sees it; only a cone several lobes wide
/// can hold the lobe where its anchor does not look. Without this test, a rough lens seen at
/// grazing (GGX alpha 1) raised nearby groups in its mirror direction above the bulb 0.1 m
/// away that lights it, and `rainy_street`'s lamp heads got noisier; with a ratio of 1 they
/// got back only a third of that (docs/decisions/0016-sharp-lobes-see-past-the-anchor.md).
const SHARP_LOBE_CONE_RATIO: f32 = 4.0;

/// A glossy lobe seen from `wo`, for the weight of a bounded child (group or emitter mesh):
/// its mirror direction, `f cos` there over [`SHARP_LOBE_CONE_RATIO`], and its reflectance.
#[derive(Clone, Copy, Debug)]
struct GlossyPeak {
    /// The mirror direction of `wo` about the shading normal, world space.
    mirror: Vec3,
    /// The glossy lobe's `luminance(f) cos` toward it (its diffuse part left out: a
    /// diffuse-dominated surface keeps its weight toward the anchor), over
    /// [`SHARP_LOBE_CONE_RATIO`]: a cone's mean below it raises the child.
    peak_over_ratio: f32,
    /// The luminance of the lobe's reflectance over `2 pi`.
    reflectance_over_2pi: f32,
}

impl BsdfWeight {
    /// The receiver's BSDF, as the weights need it.
    #[inline]
    pub(crate) fn new(rx: &Receiver) -> Self {
        let f = rx.bsdf.luminance_at(rx.wo_local);
        let peak = f.has_glossy().then(|| {
            let wo = rx.wo_local;
            let m = Vec3::new(-wo.x, -wo.y, wo.z);
            GlossyPeak {
                mirror: rx.frame.to_world(m),
                peak_over_ratio: f.eval_glossy(m) * m.z / SHARP_LOBE_CONE_RATIO,
                reflectance_over_2pi: f.glossy_reflectance() / (2.0 * PI),
            }
        });
        Self { f, peak }
    }
}

/// A light's `range`, infinite when it has none (or a non-positive one, which
/// [`super::range_window`] ignores too).
fn range_or_infinite(range: Option<f32>) -> f32 {
    match range {
        Some(r) if r > 0.0 => r,
        _ => f32::INFINITY,
    }
}

/// Every sibling set of a light tree as [`NodeLanes`] (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct TreeLanes {
    /// One per sibling set: the root's children first, then each group's.
    sets: Vec<NodeLanes>,
    /// For each node of the tree, the index of its sibling set in `sets`.
    set_of_node: Vec<u32>,
}

impl TreeLanes {
    /// The lanes of every sibling set of `tree`, whose leaves index `emitters`.
    pub(crate) fn build(tree: &LightTree, emitters: &Emitters) -> Self {
        let mut lanes = Self {
            sets: Vec::new(),
            set_of_node: vec![0; tree.nodes().len()],
        };
        let groups = tree.nodes().iter().filter_map(|n| match n {
            Node::Group(g) => Some(g.children()),
            Node::Emitter(_) => None,
        });
        for range in std::iter::once(tree.root()).chain(groups) {
            let set = lanes.sets.len() as u32;
            lanes.set_of_node[range.clone()].fill(set);
            lanes.sets.push(NodeLanes::build(tree, emitters, range));
        }
        lanes
    }

    /// The weights of the sibling set `nodes` (the root's children or a group's) at the
    /// receiver, with `w` its BSDF ([`BsdfWeight::new`]).
    #[inline]
    pub(crate) fn weights(&self, rx: &Receiver, w: &BsdfWeight, nodes: Range<usize>) -> Weights {
        self.weights_at_level(level(), rx, w, nodes)
    }

    /// [`TreeLanes::weights`] at SIMD level `simd`, which the CPU must have.
    #[inline]
    pub(crate) fn weights_at_level(
        &self,
        simd: SimdLevel,
        rx: &Receiver,
        w: &BsdfWeight,
        nodes: Range<usize>,
    ) -> Weights {
        if nodes.is_empty() {
            return ([0.0; BRANCHING], [0.0; BRANCHING], 0.0, 0.0);
        }
        let set = &self.sets[self.set_of_node[nodes.start] as usize];
        set.weights_at(simd, nodes.len(), rx, w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bsdf, Diffuse, Ggx, Ward};
    use crate::light::test_scenes::{lamp_scene, receiver};
    use crate::light::LightSampler;
    use crate::sampling::Pcg32;
    use glam::Vec3;

    /// Lights of every kind, about a street: points with and without a range, spots with soft
    /// and hard edges, and directional lights; with a sphere lamp and its lenses from
    /// `lamp_scene`, more than [`BRANCHING`] emitters, so a two-level tree.
    fn mixed_sampler() -> crate::scene::Scene {
        let mut lights = Vec::new();
        for i in 0..30 {
            let f = i as f32;
            let position = Vec3::new(
                (f * 2.3) % 17.0 - 8.0,
                1.0 + (f * 0.7) % 4.0,
                -(f * 1.9) % 29.0,
            );
            let intensity = Vec3::new(1.0 + (i % 5) as f32, 2.0, 0.5 + (i % 3) as f32);
            lights.push(match i % 5 {
                0 => Light::Point {
                    position,
                    intensity,
                    range: None,
                },
                1 => Light::Point {
                    position,
                    intensity,
                    range: Some(3.0 + f % 4.0),
                },
                2 => Light::Spot {
                    position,
                    direction: Vec3::new(0.2, -1.0, -0.3).normalize(),
                    intensity,
                    cos_inner: 0.95,
                    cos_outer: 0.7,
                    range: None,
                },
                3 => Light::Spot {
                    position,
                    direction: Vec3::new(-0.1, -1.0, 0.4).normalize(),
                    intensity,
                    cos_inner: 0.8,
                    cos_outer: 0.8,
                    range: Some(9.0),
                },
                _ => Light::Directional {
                    direction: Vec3::new(0.3, -1.0, 0.1).normalize(),
                    irradiance: intensity * 0.01,
                },
            });
        }
        lamp_scene(Vec3::new(0.0, 3.0, -5.0), 4.0, lights)
    }

    /// The levels this CPU runs.
    fn levels() -> Vec<SimdLevel> {
        [SimdLevel::Sse, SimdLevel::Avx2, SimdLevel::Avx512]
            .into_iter()
            .filter(|&l| l <= SimdLevel::of_cpu())
            .collect()
    }

    /// Every width this CPU has gives the same weights, bit for bit, at random receivers of
    /// every BSDF model, for every sibling set of a two-level tree of mixed emitters.
    #[test]
    fn every_width_gives_the_same_weights() {
        let scene = mixed_sampler();
        let ls: &LightSampler = &scene.light_sampler;
        let tree = ls.tree();
        let lanes = TreeLanes::build(tree, ls.emitters());
        let mut sets = vec![tree.root()];
        sets.extend(tree.nodes().iter().filter_map(|n| match n {
            Node::Group(g) => Some(g.children()),
            Node::Emitter(_) => None,
        }));
        assert!(sets.len() > 1, "a two-level tree");
        // The same sets computing every term, as if each held every kind of child.
        let mut every_term = lanes.clone();
        for set in &mut every_term.sets {
            set.holds = Holds {
                punctual: true,
                spot: true,
                range: true,
                beam: true,
                plane: true,
                directional: true,
                group: true,
                bounded: true,
            };
        }
        // Sets that skip terms: the groups' sets have no group among their children (their
        // `F` looks where `E` is measured from), some have no spot light or no range. (Sets
        // of meshes alone, which skip every punctual term, are in the street of
        // docs/decisions/0055-light-choice-lanes-skip-and-the-tree-stays.md, rendered the same
        // to the bit.)
        let h = |s: &NodeLanes| s.holds;
        let skipping = lanes.sets.iter().filter(|s| !h(s).group).count();
        assert!(skipping > 0 && skipping < lanes.sets.len(), "{skipping}");
        assert!(lanes.sets.iter().any(|s| !h(s).spot || !h(s).range));
        let models = [
            Bsdf::Diffuse(Diffuse {
                kd: Vec3::splat(0.5),
            }),
            Bsdf::Ggx(Ggx {
                kd: Vec3::splat(0.05),
                ks: Vec3::splat(0.6),
                alpha: 0.1,
            }),
            Bsdf::Ward(Ward {
                kd: Vec3::splat(0.05),
                ks: Vec3::splat(0.6),
                alpha: 0.2,
            }),
        ];
        let mut rng = Pcg32::new(4, 1);
        let centres: Vec<Vec3> = tree
            .nodes()
            .iter()
            .filter_map(|n| match n {
                Node::Group(g) => Some(g.centre),
                Node::Emitter(_) => None,
            })
            .collect();
        let mut positive = 0;
        for i in 0..300 {
            let p = Vec3::new(
                rng.next_f32() * 20.0 - 10.0,
                rng.next_f32() * 0.5,
                -rng.next_f32() * 30.0,
            );
            let wo = Vec3::new(
                rng.next_f32() - 0.5,
                rng.next_f32() + 0.05,
                rng.next_f32() - 0.5,
            );
            // Every other receiver sees a group's centre in its mirror direction (the cone
            // term of a glossy lobe).
            let wo = match centres.get(i % (2 * centres.len().max(1)) / 2) {
                Some(&c) if i % 2 == 1 => {
                    let d = (c - p).normalize();
                    Vec3::new(-d.x, d.y, -d.z)
                }
                _ => wo,
            };
            for bsdf in models {
                let rx = receiver(p, bsdf, wo);
                let f = BsdfWeight::new(&rx);
                for set in &sets {
                    let want = lanes.weights_at_level(SimdLevel::Sse, &rx, &f, set.clone());
                    positive += want.0.iter().filter(|&&e| e > 0.0).count();
                    let bits = |w: &Weights| {
                        (
                            w.0.map(f32::to_bits),
                            w.1.map(f32::to_bits),
                            w.2.to_bits(),
                            w.3.to_bits(),
                        )
                    };
                    for level in levels() {
                        let got = lanes.weights_at_level(level, &rx, &f, set.clone());
                        assert_eq!(bits(&got), bits(&want), "{level:?} at {p}");
                        // The terms a set skips change no bit.
                        let full = every_term.weights_at_level(level, &rx, &f, set.clone());
                        assert_eq!(bits(&full), bits(&want), "{level:?} at {p}, every term");
                    }
                }
            }
        }
        assert!(positive > 1000, "{positive}");
    }

    /// Each emitter's lane `E` is its irradiance-like weight computed one at a time: a
    /// punctual light's incident luminance (spot falloff and range window included), a
    /// mesh's `power / (4 pi max(d, r)^2)` (zero behind a one-sided lens), to rounding, and
    /// zero exactly where those are zero (so the choice is unbiased: it reaches every emitter
    /// that lights the point).
    #[test]
    fn lane_weights_are_the_emitters_irradiance() {
        let scene = mixed_sampler();
        let ls: &LightSampler = &scene.light_sampler;
        let tree = ls.tree();
        let lanes = TreeLanes::build(tree, ls.emitters());
        let bsdf = Bsdf::Diffuse(Diffuse {
            kd: Vec3::splat(0.5),
        });
        let mut rng = Pcg32::new(8, 3);
        let (mut lit, mut dark) = (0, 0);
        for _ in 0..500 {
            let p = Vec3::new(
                rng.next_f32() * 20.0 - 10.0,
                rng.next_f32() * 4.0,
                -rng.next_f32() * 30.0,
            );
            let rx = receiver(p, bsdf, Vec3::Y);
            let f = BsdfWeight::new(&rx);
            for e in 0..ls.emitters().len() {
                let node = tree.node_of_emitter(e).unwrap();
                let siblings = tree.siblings(node);
                let slot = node - siblings.start;
                let got = lanes.weights(&rx, &f, siblings).0[slot];
                let want = match ls.emitters().get(e) {
                    Emitter::Mesh(m) => m.irradiance(p),
                    Emitter::Punctual(light) => light.sample_li(p).map_or(0.0, |s| luminance(s.li)),
                };
                if want > 0.0 {
                    lit += 1;
                    // Near a spot's outer cone or a range's end the falloff is a difference
                    // of nearly equal numbers, and the lanes' cosine (from the unnormalised
                    // offset) rounds differently from the light's own.
                    assert!(
                        (got / want - 1.0).abs() < 1e-3,
                        "{e} at {p}: {got} vs {want}"
                    );
                } else {
                    dark += 1;
                    assert_eq!(got, 0.0, "{e} at {p}");
                }
            }
        }
        assert!(lit > 1000 && dark > 100, "{lit} lit, {dark} dark");
    }

    /// A group of spot lights is weighed by their intensity where it may lie in their beams:
    /// in front of a cluster of headlights its `E` is at least what its members give there
    /// (their intensity over the squared distance), not their power spread over `4 pi`, which
    /// is 44 times less for these 0.28 sr beams; behind them it is zero.
    #[test]
    fn a_group_of_spot_lights_is_weighed_by_its_beams() {
        let spot = |x: f32| Light::Spot {
            position: Vec3::new(x, 0.7, 0.0),
            direction: Vec3::Z,
            intensity: Vec3::splat(20.0),
            cos_inner: 0.99,
            cos_outer: 0.92,
            range: None,
        };
        // Two clusters of 20 headlights each: more than BRANCHING emitters, so groups.
        let lights: Vec<Light> = (0..40)
            .map(|i| spot(if i < 20 { -20.0 } else { 20.0 } + (i % 20) as f32 * 0.05))
            .collect();
        let scene = lamp_scene(Vec3::new(0.0, 30.0, -50.0), 0.0, lights);
        let ls: &LightSampler = &scene.light_sampler;
        let tree = ls.tree();
        let lanes = TreeLanes::build(tree, ls.emitters());
        let bsdf = Bsdf::Diffuse(Diffuse {
            kd: Vec3::splat(0.5),
        });
        // The root's child that holds the first headlight, and its members' exact `E`.
        let group = tree.root().find(|&c| match tree.nodes()[c] {
            Node::Group(g) => g.children().any(|n| tree.nodes()[n] == Node::Emitter(0)),
            Node::Emitter(_) => false,
        });
        let group = group.expect("the headlights are grouped");
        let Node::Group(g) = tree.nodes()[group] else {
            unreachable!()
        };
        assert!(g.beam.is_some() && g.isotropic_power == 0.0, "{g:?}");
        let slot = group - tree.root().start;
        let members_e = |p: Vec3| -> f32 {
            g.children()
                .map(|n| match tree.nodes()[n] {
                    Node::Emitter(e) => match ls.emitters().get(e as usize) {
                        Emitter::Punctual(l) => l.sample_li(p).map_or(0.0, |s| luminance(s.li)),
                        Emitter::Mesh(_) => 0.0,
                    },
                    Node::Group(_) => 0.0,
                })
                .sum()
        };
        for (p, lit) in [
            (Vec3::new(-19.5, 0.0, 30.0), true),
            (Vec3::new(-15.0, 0.0, 12.0), true),
            (Vec3::new(-19.5, 0.0, -30.0), false),
            (Vec3::new(-19.5, 40.0, 1.0), false),
        ] {
            let rx = receiver(p, bsdf, Vec3::Y);
            let f = BsdfWeight::new(&rx);
            let e = lanes.weights(&rx, &f, tree.root()).0[slot];
            let want = members_e(p);
            if lit {
                let spread = g.power / (4.0 * PI) / (g.centre - p).length_squared();
                assert!(
                    want > 0.0 && e >= 0.9 * want && e > 20.0 * spread,
                    "{p}: {e} vs {want}"
                );
            } else {
                assert_eq!((e, want), (0.0, 0.0), "{p}");
            }
        }
    }
}
