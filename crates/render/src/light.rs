//! Lights: point, spot, directional, and emissive triangles as area lights; and the
//! [`LightSampler`] that picks one light per shading point for next-event estimation.
//!
//! Scene contract (DESIGN.md): for point and spot lights `color * intensity` is the radiant
//! intensity in W/sr (linear RGB, no photometric conversion); for directional lights it is the
//! irradiance; emissive triangles are area lights of radiance `emission`, one-sided (the front
//! face, by the triangle's winding) unless their material is double-sided.
//!
//! Conventions of [`Light::sample_li`] (pbrt's `SampleLi`): `wi` points from the shading point
//! toward the light, `li` is the radiance arriving along `-wi` and `pdf` is the solid-angle
//! density of `wi`. Delta lights (point, spot, directional) are flagged with `delta: true`,
//! their `pdf` is 1 and `li` is already the incident irradiance on a surface facing the light
//! (intensity / r^2, or the directional irradiance), so `f * li * cos / pdf` is the estimate
//! either way.
//!
//! `range` of punctual lights follows the KHR_lights_punctual specification's recommended
//! window: the inverse-square law times `clamp(1 - (d / range)^4, 0, 1)`, so that light fades
//! smoothly to exactly zero at `d = range` (an absent or zero range is infinite).
//!
//! Spot lights use the specification's falloff: with `c = cos(angle to the axis)`,
//! `t = clamp((c - cos_outer) / (cos_inner - cos_outer), 0, 1)` and the intensity is scaled by
//! `t * t`.
//!
//! A [`Light::Triangle`] is sampled uniformly by area and the density converted to solid angle,
//! `pdf = d^2 / (|cos theta_light| A)`. The [`LightSampler`] groups emissive triangles into
//! emitters and samples a compact emitter (a sphere lamp) by the cone of directions that bounds
//! it instead; see its documentation.

use crate::bsdf::{Bsdf, LuminanceEval};
use crate::geometry::Frame;
use crate::sampling::{
    luminance, square_to_uniform_cone, square_to_uniform_cone_pdf, square_to_uniform_triangle,
    DiscreteDistribution, ONE_MINUS_EPSILON,
};
use crate::scene::{Scene, SurfaceHit};
use glam::{Vec2, Vec3, Vec4};
use std::collections::{HashMap, VecDeque};
use std::f32::consts::PI;

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light.
    Point {
        /// World position.
        position: Vec3,
        /// Radiant intensity (W/sr), linear RGB.
        intensity: Vec3,
        /// glTF `range` (None = infinite).
        range: Option<f32>,
    },
    /// glTF spot light (smooth falloff between the inner and outer cone).
    Spot {
        /// World position.
        position: Vec3,
        /// Unit direction the spot points along (the node's local -Z), world space.
        direction: Vec3,
        /// Radiant intensity on the axis (W/sr).
        intensity: Vec3,
        /// cos(innerConeAngle).
        cos_inner: f32,
        /// cos(outerConeAngle).
        cos_outer: f32,
        /// glTF `range` (None = infinite).
        range: Option<f32>,
    },
    /// Directional light.
    Directional {
        /// Unit direction the light travels along (the node's local -Z), world space.
        direction: Vec3,
        /// Irradiance on a surface facing the light (W/m^2).
        irradiance: Vec3,
    },
    /// One emissive triangle of the scene; its radiance comes from its material.
    Triangle {
        /// Index into [`crate::scene::Scene::triangles`].
        triangle: u32,
    },
}

/// A sampled direction toward a light, see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Distance to the light point (`inf` for directional lights).
    pub dist: f32,
    /// Incident radiance (area lights) or irradiance (delta lights).
    pub li: Vec3,
    /// Solid-angle density of `wi` (1 for delta lights).
    pub pdf: f32,
    /// Whether the light is a delta light (not reachable by BSDF sampling: no MIS).
    pub delta: bool,
    /// How to test that the light arrives.
    pub visibility: Visibility,
}

/// The KHR_lights_punctual range window `clamp(1 - (d/range)^4, 0, 1)`; 1 without a range.
#[inline]
pub fn range_window(dist: f32, range: Option<f32>) -> f32 {
    match range {
        Some(r) if r > 0.0 => {
            let x = dist / r;
            (1.0 - (x * x) * (x * x)).clamp(0.0, 1.0)
        }
        _ => 1.0,
    }
}

/// The KHR_lights_punctual spot falloff `t^2`, `t = clamp((c - cos_outer)/(cos_inner - cos_outer), 0, 1)`,
/// for `cos_angle` = cosine between the spot axis and the direction to the lit point.
#[inline]
pub fn spot_falloff(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let width = cos_inner - cos_outer;
    let t = if width > 1e-7 {
        ((cos_angle - cos_outer) / width).clamp(0.0, 1.0)
    } else if cos_angle >= cos_outer {
        1.0
    } else {
        0.0
    };
    t * t
}

/// Vertex positions of a triangle.
#[inline]
fn triangle_vertices(scene: &Scene, triangle: u32) -> [Vec3; 3] {
    let [a, b, c] = scene.triangles[triangle as usize];
    [
        scene.positions[a as usize],
        scene.positions[b as usize],
        scene.positions[c as usize],
    ]
}

/// Radiance emitted from `hit` toward `wo` (unit, pointing away from the surface): the
/// material's emission on the front face (by winding), on both faces if it is double-sided,
/// zero otherwise.
#[inline]
pub fn emitted_radiance(scene: &Scene, hit: &SurfaceHit, wo: Vec3) -> Vec3 {
    let material = &scene.materials[hit.material as usize];
    if !material.is_emissive() || (!material.double_sided && hit.ng.dot(wo) <= 0.0) {
        return Vec3::ZERO;
    }
    material.emission_at(hit.uv, &scene.textures)
}

impl Light {
    /// Whether the light is a delta light (point, spot, directional).
    #[inline]
    pub fn is_delta(&self) -> bool {
        !matches!(self, Light::Triangle { .. })
    }

    /// Samples a direction from `p` toward the light with the 2D sample `u`; `None` when the
    /// light cannot illuminate `p` (outside the cone or the range, back face, degenerate).
    pub fn sample_li(&self, scene: &Scene, p: Vec3, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Triangle { triangle } => {
                let v = triangle_vertices(scene, triangle);
                let (n, area) = scene.triangle_normal_area(triangle);
                let b = square_to_uniform_triangle(u);
                let b0 = 1.0 - b.x - b.y;
                let q = b0 * v[0] + b.x * v[1] + b.y * v[2];
                let d = q - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                if area <= 0.0 || dist <= 0.0 {
                    return None;
                }
                let wi = d / dist;
                let cos_light = -n.dot(wi);
                let material =
                    &scene.materials[scene.triangle_materials[triangle as usize] as usize];
                if cos_light.abs() < 1e-7 || (!material.double_sided && cos_light <= 0.0) {
                    return None;
                }
                let [ia, ib, ic] = scene.triangles[triangle as usize];
                let uv = b0 * scene.uvs[ia as usize]
                    + b.x * scene.uvs[ib as usize]
                    + b.y * scene.uvs[ic as usize];
                let li = material.emission_at(uv, &scene.textures);
                let pdf = dist2 / (cos_light.abs() * area);
                (pdf.is_finite() && li.max_element() > 0.0).then_some(LightSample {
                    wi,
                    dist,
                    li,
                    pdf,
                    delta: false,
                    visibility: Visibility::ShadowRay,
                })
            }
            _ => self.sample_punctual(p),
        }
    }

    /// [`Light::sample_li`] of a point, spot or directional light, which needs no random
    /// numbers (the sample is the light's whole contribution); `None` for an emissive triangle.
    /// Always inlined: the light choice's weights call it for every punctual emitter, and a
    /// call returns the sample through memory, which stalls the luminance read after it.
    #[inline(always)]
    pub fn sample_punctual(&self, p: Vec3) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                intensity,
                range,
            } => punctual(p, position, intensity, range, 1.0),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
                range,
            } => {
                let cos_angle = direction.dot((p - position).normalize_or_zero());
                let falloff = spot_falloff(cos_angle, cos_inner, cos_outer);
                punctual(p, position, intensity, range, falloff)
            }
            Light::Directional {
                direction,
                irradiance,
            } => Some(LightSample {
                wi: -direction,
                dist: f32::INFINITY,
                li: irradiance,
                pdf: 1.0,
                delta: true,
                visibility: Visibility::ShadowRay,
            }),
            Light::Triangle { .. } => None,
        }
    }

    /// The solid-angle density with which [`Light::sample_li`] from `p` would return the
    /// direction toward `hit`, a point on this light (area lights; 0 for delta lights).
    pub fn pdf_li(&self, scene: &Scene, p: Vec3, hit: &SurfaceHit) -> f32 {
        match *self {
            Light::Triangle { triangle } => {
                let (_, area) = scene.triangle_normal_area(triangle);
                let d = hit.p - p;
                let dist2 = d.length_squared();
                let cos_light = hit.ng.dot(d).abs() / dist2.sqrt();
                if area <= 0.0 || cos_light <= 0.0 {
                    return 0.0;
                }
                dist2 / (cos_light * area)
            }
            _ => 0.0,
        }
    }

    /// Emitted power (luminance of the flux, W) used to choose lights: `4 pi I` for a point
    /// light, `2 pi (1 - (cos_inner + cos_outer)/2) I` for a spot (the cone's solid angle at
    /// the middle of the falloff), `pi A L` per emitting face of a triangle, and
    /// `pi r^2 E` for a directional light over the scene's bounding sphere of radius `r`.
    /// Ranges are ignored. A textured emitter counts with its untextured factor.
    pub fn power(&self, scene: &Scene) -> f32 {
        match *self {
            Light::Point { intensity, .. } => 4.0 * PI * luminance(intensity),
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * luminance(intensity),
            Light::Directional { irradiance, .. } => {
                let (_, r) = scene.bounding_sphere();
                PI * r * r * luminance(irradiance)
            }
            Light::Triangle { triangle } => {
                let (_, area) = scene.triangle_normal_area(triangle);
                let material =
                    &scene.materials[scene.triangle_materials[triangle as usize] as usize];
                let sides = if material.double_sided { 2.0 } else { 1.0 };
                sides * PI * area * luminance(material.emission)
            }
        }
    }
}

/// A point or spot light at `position` seen from `p`.
#[inline]
fn punctual(
    p: Vec3,
    position: Vec3,
    intensity: Vec3,
    range: Option<f32>,
    falloff: f32,
) -> Option<LightSample> {
    let d = position - p;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    let scale = falloff * range_window(dist, range);
    if dist <= 0.0 || scale <= 0.0 {
        return None;
    }
    Some(LightSample {
        wi: d / dist,
        dist,
        li: intensity * (scale / dist2),
        pdf: 1.0,
        delta: true,
        visibility: Visibility::ShadowRay,
    })
}

/// How the integrator decides whether a [`LightSample`] is visible.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// The sample is a point at `dist`: trace a shadow ray (any hit) up to it; `li` is the
    /// light's radiance there.
    ShadowRay,
    /// The sample is only a direction toward emitter `emitter` of the [`LightSampler`]
    /// (sampled uniformly in the cone that bounds it): trace a closest-hit ray; the light
    /// arrives if the ray first hits one of that emitter's triangles, with the radiance that
    /// triangle emits toward the shading point (`li` is zero until then; `dist` is the distance
    /// to the far side of the emitter's bounding sphere, beyond which the ray need not look).
    FirstHit {
        /// Index of the emitter among the sampler's emitters.
        emitter: u32,
    },
}

/// What the light sampler may know about the shading point: position, geometric normal,
/// shading frame, outgoing direction and BSDF. With few emitters the choice of light weighs
/// each by the BSDF toward it (see [`LightSampler`]).
#[derive(Clone, Copy, Debug)]
pub struct Receiver {
    /// Shading point.
    pub p: Vec3,
    /// Geometric normal, on the side of `wo`.
    pub ng: Vec3,
    /// Shading frame (normal on the side of `wo`).
    pub frame: Frame,
    /// Outgoing direction in the shading frame.
    pub wo_local: Vec3,
    /// BSDF at the point.
    pub bsdf: Bsdf,
}

/// Children per node of the light tree: the light choice weighs at most this many emitters or
/// groups of emitters at a time by the BSDF toward them (one BSDF evaluation each). Up to this
/// many emitters the tree is a single node.
pub const BRANCHING: usize = 16;

/// Lloyd iterations of the k-means that splits a node's emitters into groups.
const CLUSTER_ITERATIONS: usize = 16;

/// Share of the light choice made by irradiance alone when it is BSDF-aware (defensive
/// sampling: every emitter that can light the point keeps a positive probability even where
/// the BSDF toward its centre is zero).
const DEFENSIVE_SHARE: f32 = 0.1;

/// An emitter mesh is sampled by its bounding cone when its area is at least this many times
/// `pi r^2` (r: its bounding radius): a closed, roughly round shape (a tessellated sphere has
/// about 4) fills its cone; a flat lens (at most 1) would waste most cone samples.
const COMPACT_AREA_RATIO: f32 = 2.0;

/// What the sampler chooses between: one punctual light, or one emitter mesh.
#[derive(Clone, Debug)]
enum Emitter {
    /// A point, spot or directional light: index into `scene.lights`.
    Punctual(u32),
    /// Connected emissive triangles of one material.
    Mesh(MeshEmitter),
}

/// Emissive triangles that share vertices and a material: a lamp's bulb, a lens, a window.
#[derive(Clone, Debug)]
struct MeshEmitter {
    /// Indices into `scene.lights` of its [`Light::Triangle`]s.
    lights: Vec<u32>,
    /// Choice of triangle for area sampling, by power.
    distribution: DiscreteDistribution,
    /// Total power (luminance, W).
    power: f32,
    /// Centre of its bounding sphere.
    centre: Vec3,
    /// Radius of its bounding sphere (slightly inflated, so the cone bounds every triangle).
    radius: f32,
    /// Whether it is sampled by its bounding cone from outside the bounding sphere.
    cone: bool,
    /// For a flat one-sided emitter: its plane `(n, n . v)`; points behind it get no light.
    front: Option<(Vec3, f32)>,
}

/// A node of the light tree: at most [`BRANCHING`] children, each an emitter or a group.
#[derive(Clone, Debug)]
struct Node {
    children: Vec<Child>,
    /// `(node, slot)` of the group that points here; `None` for the root.
    parent: Option<(u32, u32)>,
}

/// A child of a light-tree [`Node`].
#[derive(Clone, Copy, Debug)]
enum Child {
    /// An emitter (index into `LightSampler::emitters`), weighed by its own `E` and `F`.
    Emitter(u32),
    /// Several emitters, weighed as one.
    Group(Group),
}

/// Emitters that the light choice weighs as one: by the irradiance their total power would
/// give from their bounding sphere, and by the BSDF toward their most powerful member.
#[derive(Clone, Copy, Debug)]
struct Group {
    /// The node whose children they are.
    node: u32,
    /// Centre of a sphere that bounds them (their bounding spheres for meshes).
    centre: Vec3,
    /// Its radius.
    radius: f32,
    /// Their total power (luminance, W).
    power: f32,
    /// Where the BSDF weight looks: the most powerful one's position (a lamp's bulb rather
    /// than the middle of a lamp and its neighbours).
    anchor: Vec3,
}

/// Chooses a light and a sample on it for next-event estimation, and gives the density of that
/// choice for multiple importance sampling.
///
/// Emissive triangles are grouped into emitters: the connected pieces (shared vertex
/// positions) of each emissive material. Point, spot and directional lights are emitters of
/// their own.
///
/// Which emitter: with at most [`BRANCHING`] emitters, in proportion to
/// `E_i (0.9 F_i / sum E F + 0.1 / sum E)`-style weights: `E_i` is the irradiance the emitter
/// would give at the point (intensity, spot falloff and range window over `d^2` for punctual
/// lights, the directional irradiance, `power / (4 pi max(d, r)^2)` for a mesh of bounding
/// radius `r`, zero behind a flat one-sided mesh) and `F_i` the luminance of the BSDF times the
/// cosine toward the emitter's centre. On a glossy wet road this sends the shadow rays of a
/// streak's pixels to the lamp that makes the streak. With more emitters (a street of lamps,
/// cars and windows), a light tree: they are grouped by position into at most [`BRANCHING`]
/// groups (k-means, power-weighted), and groups of more than [`BRANCHING`] again, down to
/// groups of at most [`BRANCHING`] emitters. The choice descends it: at each node the same
/// weights choose a child, a group's `E` from its total power over its bounding sphere and
/// its `F` toward its most powerful member (toward the middle of a lamp and its neighbours,
/// the glossy lobe would miss the lamp), an emitter's its own. Each node's weights are
/// computed once per choice, so the per-point cost is at most [`BRANCHING`] BSDF evaluations
/// per level (two levels for `rainy_street`'s 142 emitters).
///
/// Where on it: punctual lights by [`Light::sample_li`]; a compact emitter mesh (area at
/// least `2 pi r^2`, e.g. a tessellated sphere lamp) seen from outside its bounding sphere
/// uniformly in the cone of directions that bounds it ([`Visibility::FirstHit`]: no sample
/// is wasted on the back of the sphere); other meshes, or points inside the bounding sphere, by
/// choosing a triangle by power and a point on it uniformly by area.
///
/// Every choice is a deterministic function of the point, so [`LightSampler::sample_li`] and
/// [`LightSampler::pdf_li`] agree exactly, which MIS needs.
#[derive(Clone, Debug)]
pub struct LightSampler {
    /// The emitters.
    emitters: Vec<Emitter>,
    /// The light tree; the root first.
    nodes: Vec<Node>,
    /// The `(node, slot)` of each emitter in the tree.
    slot_of: Vec<(u32, u32)>,
    /// For each scene triangle: `(emitter, index within the emitter)`, `u32::MAX` if none.
    emitter_of_triangle: Vec<(u32, u32)>,
}

/// Positive finite power, else 0.
fn clean_power(p: f32) -> f32 {
    if p.is_finite() {
        p.max(0.0)
    } else {
        0.0
    }
}

/// Chooses index `i` with probability `w_i / sum` by inverting the cumulative sum at `u sum`
/// (`u` in [0, 1)): the first positive weight whose cumulative sum exceeds it (else the last
/// positive one), with `u` rescaled to [0, 1) within that weight.
fn choose_in(weights: impl IntoIterator<Item = f32>, sum: f32, u: f32) -> Option<(usize, f32)> {
    let target = u * sum;
    let mut acc = 0.0f32;
    let mut chosen = None;
    for (i, w) in weights.into_iter().enumerate() {
        if w > 0.0 {
            chosen = Some((i, acc, w));
            if target < acc + w {
                break;
            }
        }
        acc += w;
    }
    let (i, before, w) = chosen?;
    Some((i, ((target - before) / w).clamp(0.0, ONE_MINUS_EPSILON)))
}

/// Whether weights `E` summing to `e_sum` and `E F` summing to `ef_sum` can be chosen from.
fn mixture_valid(e_sum: f32, ef_sum: f32) -> bool {
    e_sum > 0.0 && e_sum.is_finite() && ef_sum.is_finite()
}

/// The probability of an item with weights `e` and `ef` under the mixture: by `E` alone with
/// probability [`DEFENSIVE_SHARE`] (all of it when every `E F` is 0), else by `E F`.
fn mixture_pmf(e: f32, ef: f32, e_sum: f32, ef_sum: f32) -> f32 {
    if !mixture_valid(e_sum, ef_sum) {
        0.0
    } else if ef_sum > 0.0 {
        DEFENSIVE_SHARE * e / e_sum + (1.0 - DEFENSIVE_SHARE) * ef / ef_sum
    } else {
        e / e_sum
    }
}

/// Chooses an item `(E, E F)` by [`mixture_pmf`] with `u`: `(index, u rescaled within it)`.
fn choose_mixture_iter(
    weights: impl Iterator<Item = (f32, f32)>,
    e_sum: f32,
    ef_sum: f32,
    u: f32,
) -> Option<(usize, f32)> {
    if !mixture_valid(e_sum, ef_sum) {
        return None;
    }
    let share = if ef_sum > 0.0 { DEFENSIVE_SHARE } else { 1.0 };
    if u < share {
        choose_in(weights.map(|(e, _)| e), e_sum, u / share)
    } else {
        choose_in(
            weights.map(|(_, ef)| ef),
            ef_sum,
            (u - share) / (1.0 - share),
        )
    }
}

/// [`choose_mixture_iter`] over two slices of weights.
fn choose_mixture(
    e_w: &[f32],
    ef_w: &[f32],
    e_sum: f32,
    ef_sum: f32,
    u: f32,
) -> Option<(usize, f32)> {
    choose_mixture_iter(
        e_w.iter().copied().zip(ef_w.iter().copied()),
        e_sum,
        ef_sum,
        u,
    )
}

/// Position, bounding radius and power (luminance) of each emitter; no position for
/// directional lights.
fn emitter_info(scene: &Scene, emitters: &[Emitter]) -> Vec<(Option<Vec3>, f32, f32)> {
    emitters
        .iter()
        .map(|e| match e {
            Emitter::Mesh(m) => (Some(m.centre), m.radius, m.power),
            Emitter::Punctual(i) => {
                let light = &scene.lights[*i as usize];
                let power = clean_power(light.power(scene));
                match *light {
                    Light::Point { position, .. } | Light::Spot { position, .. } => {
                        (Some(position), 0.0, power)
                    }
                    _ => (None, 0.0, power),
                }
            }
        })
        .collect()
}

/// Builds the light tree over the emitters (`info` from [`emitter_info`]): nodes (the root
/// first) and the `(node, slot)` of each emitter. A node's children are its emitters when they
/// are at most [`BRANCHING`]; else [`partition`]'s groups, one emitter each or a group with a
/// node of its own.
fn build_light_tree(info: &[(Option<Vec3>, f32, f32)]) -> (Vec<Node>, Vec<(u32, u32)>) {
    let mut nodes: Vec<Node> = Vec::new();
    let mut slot_of = vec![(0u32, 0u32); info.len()];
    // Breadth first: the nodes are made in the order their groups are queued, so a group's
    // node index is known when it is queued.
    let mut queue = VecDeque::from([(None, (0..info.len() as u32).collect::<Vec<u32>>())]);
    while let Some((parent, members)) = queue.pop_front() {
        let index = nodes.len() as u32;
        let groups = if members.len() <= BRANCHING {
            members.iter().map(|&e| vec![e]).collect()
        } else {
            partition(info, &members)
        };
        let mut children = Vec::with_capacity(groups.len());
        for (slot, group) in groups.into_iter().enumerate() {
            let slot = slot as u32;
            if let [e] = group[..] {
                slot_of[e as usize] = (index, slot);
                children.push(Child::Emitter(e));
            } else {
                let node = index + queue.len() as u32 + 1;
                children.push(Child::Group(group_bounds(info, &group, node)));
                queue.push_back((Some((index, slot)), group));
            }
        }
        nodes.push(Node { children, parent });
    }
    (nodes, slot_of)
}

/// The bounds of a group of emitters, whose children are node `node`.
fn group_bounds(info: &[(Option<Vec3>, f32, f32)], members: &[u32], node: u32) -> Group {
    let spheres: Vec<(Vec3, f32)> = members
        .iter()
        .filter_map(|&e| info[e as usize].0.map(|p| (p, info[e as usize].1)))
        .collect();
    let (lo, hi) = spheres.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &(p, r)| (lo.min(p - r), hi.max(p + r)),
    );
    let centre = if spheres.is_empty() {
        Vec3::ZERO
    } else {
        0.5 * (lo + hi)
    };
    let radius = spheres
        .iter()
        .map(|&(p, r)| p.distance(centre) + r)
        .fold(0.0f32, f32::max);
    let power = members.iter().map(|&e| info[e as usize].2).sum();
    let anchor = members
        .iter()
        .filter_map(|&e| info[e as usize].0.map(|p| (p, info[e as usize].2)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(centre, |(p, _)| p);
    Group {
        node,
        centre,
        radius,
        power,
        anchor,
    }
}

/// Splits more than [`BRANCHING`] emitters into at most [`BRANCHING`] non-empty groups:
/// directional lights alone (all in one when there are more than half as many) and the
/// others by position (the centres of meshes, the positions of point and spot lights) into
/// the remaining groups, by k-means weighted by power, started from the most powerful emitter
/// and then the farthest ones. When that makes a single group (lights at one position, or
/// only directional ones), consecutive runs of the input instead, so every level shrinks.
fn partition(info: &[(Option<Vec3>, f32, f32)], members: &[u32]) -> Vec<Vec<u32>> {
    let directional: Vec<u32> = members
        .iter()
        .copied()
        .filter(|&e| info[e as usize].0.is_none())
        .collect();
    let placed: Vec<(u32, Vec3, f32)> = members
        .iter()
        .filter_map(|&e| info[e as usize].0.map(|p| (e, p, info[e as usize].2)))
        .collect();
    // Directional lights have no position: each its own group while they are few, else all
    // in one (whose weight is then arbitrary but positive, which keeps the choice unbiased).
    let directional: Vec<Vec<u32>> = if directional.len() <= BRANCHING / 2 {
        directional.into_iter().map(|e| vec![e]).collect()
    } else {
        vec![directional]
    };
    let k = BRANCHING - directional.len();
    // Start: the most powerful emitter, then each time the one farthest from the centres.
    let mut centres: Vec<Vec3> = Vec::with_capacity(k);
    if let Some(&(_, p, _)) = placed.iter().max_by(|a, b| a.2.total_cmp(&b.2)) {
        centres.push(p);
    }
    while centres.len() < k.min(placed.len()) {
        let far = placed
            .iter()
            .map(|&(_, p, _)| {
                let d = centres
                    .iter()
                    .map(|c| c.distance_squared(p))
                    .fold(f32::INFINITY, f32::min);
                (p, d)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match far {
            Some((p, d)) if d > 0.0 => centres.push(p),
            _ => break,
        }
    }
    let nearest = |centres: &[Vec3], p: Vec3| {
        (0..centres.len())
            .min_by(|&a, &b| {
                centres[a]
                    .distance_squared(p)
                    .total_cmp(&centres[b].distance_squared(p))
            })
            .unwrap_or(0)
    };
    for _ in 0..CLUSTER_ITERATIONS {
        let mut sums = vec![(Vec3::ZERO, 0.0f32, Vec3::ZERO, 0usize); centres.len()];
        for &(_, p, power) in &placed {
            let s = &mut sums[nearest(&centres, p)];
            s.0 += p * power;
            s.1 += power;
            s.2 += p;
            s.3 += 1;
        }
        for (c, &(weighted, power, plain, n)) in centres.iter_mut().zip(&sums) {
            if power > 0.0 {
                *c = weighted / power;
            } else if n > 0 {
                *c = plain / n as f32;
            }
        }
    }
    let mut groups = vec![Vec::new(); centres.len()];
    for &(e, p, _) in &placed {
        groups[nearest(&centres, p)].push(e);
    }
    let groups: Vec<Vec<u32>> = groups
        .into_iter()
        .filter(|g| !g.is_empty())
        .chain(directional)
        .collect();
    if groups.len() > 1 {
        return groups;
    }
    members
        .chunks(members.len().div_ceil(BRANCHING))
        .map(<[u32]>::to_vec)
        .collect()
}

/// Groups the scene's [`Light::Triangle`]s by material and shared vertex positions (union-find).
fn group_triangle_lights(scene: &Scene) -> Vec<Vec<u32>> {
    let tri_lights: Vec<(u32, u32)> = scene
        .lights
        .iter()
        .enumerate()
        .filter_map(|(i, l)| match *l {
            Light::Triangle { triangle } => Some((i as u32, triangle)),
            _ => None,
        })
        .collect();
    let mut parent: Vec<usize> = (0..tri_lights.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut first_at: HashMap<(u32, [u32; 3]), usize> = HashMap::new();
    for (k, &(_, triangle)) in tri_lights.iter().enumerate() {
        let material = scene.triangle_materials[triangle as usize];
        for v in scene.triangles[triangle as usize] {
            let key = (
                material,
                scene.positions[v as usize].to_array().map(f32::to_bits),
            );
            let other = *first_at.entry(key).or_insert(k);
            let (a, b) = (find(&mut parent, k), find(&mut parent, other));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: Vec<Vec<u32>> = Vec::new();
    let mut group_of_root: HashMap<usize, usize> = HashMap::new();
    for (k, &(light, _)) in tri_lights.iter().enumerate() {
        let root = find(&mut parent, k);
        let g = *group_of_root.entry(root).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(light);
    }
    groups
}

impl MeshEmitter {
    /// Builds the emitter of the given triangle lights; `None` if none of them emits.
    fn new(scene: &Scene, lights: Vec<u32>) -> Option<Self> {
        let powers: Vec<f32> = lights
            .iter()
            .map(|&i| clean_power(scene.lights[i as usize].power(scene)))
            .collect();
        let distribution = DiscreteDistribution::new(&powers)?;
        let triangles: Vec<u32> = lights
            .iter()
            .map(|&i| match scene.lights[i as usize] {
                Light::Triangle { triangle } => triangle,
                _ => unreachable!("mesh emitters hold triangle lights only"),
            })
            .collect();
        let (lo, hi) = triangles
            .iter()
            .flat_map(|&t| triangle_vertices(scene, t))
            .fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), v| (lo.min(v), hi.max(v)),
            );
        let centre = 0.5 * (lo + hi);
        let radius = triangles
            .iter()
            .flat_map(|&t| triangle_vertices(scene, t))
            .map(|v| v.distance(centre))
            .fold(0.0f32, f32::max);
        // Inflate a little so that rounding never leaves a triangle outside the cone.
        let radius = radius * (1.0 + 1e-4) + 1e-6 * centre.abs().max_element();
        let area: f32 = triangles
            .iter()
            .map(|&t| scene.triangle_normal_area(t).1)
            .sum();
        let (n0, _) = scene.triangle_normal_area(triangles[0]);
        let one_sided =
            !scene.materials[scene.triangle_materials[triangles[0] as usize] as usize].double_sided;
        let flat = triangles.iter().all(|&t| {
            let (n, _) = scene.triangle_normal_area(t);
            n.dot(n0) > 1.0 - 1e-5
                && (triangle_vertices(scene, t)[0] - centre).dot(n0).abs()
                    <= 1e-4 * radius.max(1e-6)
        });
        let front = (one_sided && flat).then(|| (n0, n0.dot(centre)));
        Some(Self {
            lights,
            distribution,
            power: powers.iter().sum(),
            centre,
            radius,
            cone: area >= COMPACT_AREA_RATIO * PI * radius * radius,
            front,
        })
    }

    /// The irradiance-like weight `power / (4 pi max(d, r)^2)`, zero behind a flat one-sided
    /// emitter.
    #[inline]
    fn irradiance(&self, p: Vec3) -> f32 {
        if let Some((n, offset)) = self.front {
            if n.dot(p) <= offset {
                return 0.0;
            }
        }
        let d2 = (self.centre - p)
            .length_squared()
            .max(self.radius * self.radius);
        self.power / (4.0 * PI * d2)
    }

    /// `1 - cos` of the half-angle of the bounding cone seen from `p`, when `p` is outside the
    /// bounding sphere and the emitter is sampled by its cone.
    #[inline]
    fn cone_from(&self, p: Vec3) -> Option<(Vec3, f32)> {
        if !self.cone {
            return None;
        }
        let d = self.centre - p;
        let dist2 = d.length_squared();
        let r2 = self.radius * self.radius;
        if dist2 <= r2 * (1.0 + 1e-3) {
            return None;
        }
        let sin2 = r2 / dist2;
        // 1 - cos without cancellation for narrow cones.
        let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
        Some((d / dist2.sqrt(), one_minus_cos))
    }

    /// A sample from `p` (see [`LightSampler`]); `u_tri` chooses the triangle for area sampling.
    fn sample_li(
        &self,
        scene: &Scene,
        emitter: u32,
        p: Vec3,
        u_tri: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        if let Some((axis, one_minus_cos)) = self.cone_from(p) {
            let wi = Frame::from_normal(axis).to_world(square_to_uniform_cone(u, one_minus_cos));
            return Some(LightSample {
                wi,
                dist: (self.centre - p).length() + self.radius,
                li: Vec3::ZERO,
                pdf: square_to_uniform_cone_pdf(Vec3::Z, one_minus_cos),
                delta: false,
                visibility: Visibility::FirstHit { emitter },
            });
        }
        let (k, pmf) = self.distribution.sample(u_tri);
        let mut ls = scene.lights[self.lights[k] as usize].sample_li(scene, p, u)?;
        ls.pdf *= pmf;
        Some(ls)
    }

    /// The density with which [`MeshEmitter::sample_li`] from `p` returns the direction to
    /// `hit`, a point on its triangle number `k`.
    fn pdf_li(&self, scene: &Scene, p: Vec3, k: usize, hit: &SurfaceHit) -> f32 {
        if let Some((_, one_minus_cos)) = self.cone_from(p) {
            return square_to_uniform_cone_pdf(Vec3::Z, one_minus_cos);
        }
        self.distribution.pmf(k) * scene.lights[self.lights[k] as usize].pdf_li(scene, p, hit)
    }
}

impl LightSampler {
    /// Groups the emissive triangles into emitters and builds the power distribution.
    pub fn new(scene: &Scene) -> Self {
        let mut emitters: Vec<Emitter> = scene
            .lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.is_delta())
            .map(|(i, _)| Emitter::Punctual(i as u32))
            .collect();
        emitters.extend(
            group_triangle_lights(scene)
                .into_iter()
                .filter_map(|lights| MeshEmitter::new(scene, lights))
                .map(Emitter::Mesh),
        );
        let mut emitter_of_triangle = vec![(u32::MAX, u32::MAX); scene.triangles.len()];
        for (e, emitter) in emitters.iter().enumerate() {
            if let Emitter::Mesh(m) = emitter {
                for (k, &light) in m.lights.iter().enumerate() {
                    if let Light::Triangle { triangle } = scene.lights[light as usize] {
                        emitter_of_triangle[triangle as usize] = (e as u32, k as u32);
                    }
                }
            }
        }
        let (nodes, slot_of) = build_light_tree(&emitter_info(scene, &emitters));
        Self {
            emitters,
            nodes,
            slot_of,
            emitter_of_triangle,
        }
    }

    /// Number of emitters (punctual lights plus emitter meshes).
    pub fn emitter_count(&self) -> usize {
        self.emitters.len()
    }

    /// The irradiance-like weight `E_i` of emitter `e` at `p` (see [`LightSampler`]) and,
    /// when it is positive, the direction the BSDF weight looks in (toward a mesh's centre, a
    /// point or spot light, or against a directional light's direction). Always inlined: the
    /// per-point weights call it for every emitter.
    #[inline(always)]
    fn irradiance(&self, scene: &Scene, e: usize, p: Vec3) -> (f32, Vec3) {
        match &self.emitters[e] {
            Emitter::Mesh(m) => {
                let e = m.irradiance(p);
                if e > 0.0 {
                    (e, (m.centre - p).normalize_or_zero())
                } else {
                    (0.0, Vec3::ZERO)
                }
            }
            // A sample of a punctual light is its irradiance at p, and its direction.
            Emitter::Punctual(i) => match scene.lights[*i as usize].sample_punctual(p) {
                Some(ls) => (clean_power(luminance(ls.li)), ls.wi),
                None => (0.0, Vec3::ZERO),
            },
        }
    }

    /// The per-point weights `E_c` and `E_c F_c` of every child of `node`, with their sums
    /// (see [`LightSampler`]). `F_c` is the luminance of the BSDF times the cosine toward the
    /// child (0 below the shading or the geometric surface). First every child's `E_c` and
    /// direction, then the directions' normalisation, shading-frame coordinates and BSDF
    /// values four children at a time in SIMD lanes ([`LuminanceEval::eval4`]).
    #[inline]
    fn weights(
        &self,
        scene: &Scene,
        rx: &Receiver,
        f: &LuminanceEval,
        node: usize,
    ) -> ([f32; BRANCHING], [f32; BRANCHING], f32, f32) {
        let children = &self.nodes[node].children;
        let mut e_w = [0.0f32; BRANCHING];
        // The directions toward the children (not normalised), by coordinate; zero (so no
        // BSDF weight) unless the child lights the point.
        let mut dir = [[0.0f32; BRANCHING]; 3];
        for (c, child) in children.iter().enumerate() {
            let (e, d) = match child {
                Child::Emitter(i) => match self.irradiance(scene, *i as usize, rx.p) {
                    (e, wi) if e > 0.0 => (e, wi),
                    _ => continue,
                },
                Child::Group(g) => {
                    let d2 = (g.centre - rx.p).length_squared().max(g.radius * g.radius);
                    (clean_power(g.power / (4.0 * PI * d2)), g.anchor - rx.p)
                }
            };
            e_w[c] = e;
            [dir[0][c], dir[1][c], dir[2][c]] = d.to_array();
        }
        let n = children.len();
        let mut f_w = [0.0f32; BRANCHING];
        let mut cos_w = [0.0f32; BRANCHING];
        let (frame, ng) = (&rx.frame, rx.ng);
        for k in (0..n).step_by(4) {
            let [x, y, z] = dir.map(|d| Vec4::from_slice(&d[k..k + 4]));
            // `normalize_or_zero`, lane by lane.
            let r = Vec4::ONE / (x * x + y * y + z * z).sqrt();
            let r = Vec4::select(r.is_finite_mask() & r.cmpgt(Vec4::ZERO), r, Vec4::ZERO);
            let [x, y, z] = [x * r, y * r, z * r];
            // `Frame::to_local` and the geometric normal's side.
            let dot = |v: Vec3| x * v.x + y * v.y + z * v.z;
            let local = [dot(frame.s), dot(frame.t), dot(frame.n)];
            let lit = dot(ng).cmpgt(Vec4::ZERO) & local[2].cmpgt(Vec4::ZERO);
            let cos = Vec4::select(lit, local[2], Vec4::ZERO);
            f.eval4([local[0], local[1], cos])
                .write_to_slice(&mut f_w[k..k + 4]);
            cos.write_to_slice(&mut cos_w[k..k + 4]);
        }
        let mut ef_w = [0.0f32; BRANCHING];
        let (mut e_sum, mut ef_sum) = (0.0f32, 0.0f32);
        for c in 0..n {
            let e = e_w[c];
            if e > 0.0 {
                let ef = e * clean_power(f_w[c] * cos_w[c]);
                ef_w[c] = ef;
                e_sum += e;
                ef_sum += ef;
            }
        }
        (e_w, ef_w, e_sum, ef_sum)
    }

    /// Chooses an emitter for the receiver: `(emitter, probability, u rescaled within it)`.
    /// From the root down, a child of each node by the mixture of `E` and `E F`.
    #[inline]
    fn choose(&self, scene: &Scene, rx: &Receiver, u: f32) -> Option<(usize, f32, f32)> {
        let f = rx.bsdf.luminance_at(rx.wo_local);
        let (mut node, mut u, mut pmf) = (0, u, 1.0f32);
        loop {
            let (e_w, ef_w, e_sum, ef_sum) = self.weights(scene, rx, &f, node);
            let n = self.nodes[node].children.len();
            let (c, u_c) = choose_mixture(&e_w[..n], &ef_w[..n], e_sum, ef_sum, u)?;
            pmf *= mixture_pmf(e_w[c], ef_w[c], e_sum, ef_sum);
            u = u_c;
            match self.nodes[node].children[c] {
                Child::Emitter(e) => return (pmf > 0.0).then_some((e as usize, pmf, u)),
                Child::Group(g) => node = g.node as usize,
            }
        }
    }

    /// The probability that [`LightSampler::sample_li`] at the receiver chooses emitter `e`:
    /// the product of the choices on the way from the root to it.
    pub fn emitter_pmf(&self, scene: &Scene, rx: &Receiver, e: usize) -> f32 {
        let Some(&(node, slot)) = self.slot_of.get(e) else {
            return 0.0;
        };
        let f = rx.bsdf.luminance_at(rx.wo_local);
        let (mut node, mut slot, mut pmf) = (node as usize, slot as usize, 1.0f32);
        loop {
            let (e_w, ef_w, e_sum, ef_sum) = self.weights(scene, rx, &f, node);
            pmf *= mixture_pmf(e_w[slot], ef_w[slot], e_sum, ef_sum);
            match self.nodes[node].parent {
                Some((parent, s)) if pmf > 0.0 => (node, slot) = (parent as usize, s as usize),
                _ => return pmf,
            }
        }
    }

    /// Chooses an emitter with `u_light` and samples it with `u` (see [`LightSampler`]). The
    /// returned `pdf` includes the probability of the choice; `None` when nothing was sampled.
    pub fn sample_li(
        &self,
        scene: &Scene,
        rx: &Receiver,
        u_light: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let (e, pmf, reused) = self.choose(scene, rx, u_light)?;
        let mut ls = match &self.emitters[e] {
            Emitter::Punctual(i) => scene.lights[*i as usize].sample_li(scene, rx.p, u)?,
            Emitter::Mesh(m) => m.sample_li(scene, e as u32, rx.p, reused, u)?,
        };
        ls.pdf *= pmf;
        Some(ls)
    }

    /// The density (choice included) with which [`LightSampler::sample_li`] at the receiver
    /// returns the direction toward `hit`, a point on an emissive triangle; 0 if `hit` is not on
    /// an emitter.
    pub fn pdf_li(&self, scene: &Scene, rx: &Receiver, hit: &SurfaceHit) -> f32 {
        let Some((e, k)) = self.emitter_of(hit.triangle) else {
            return 0.0;
        };
        let Emitter::Mesh(m) = &self.emitters[e] else {
            return 0.0;
        };
        self.emitter_pmf(scene, rx, e) * m.pdf_li(scene, rx.p, k, hit)
    }

    /// The emitter of scene triangle `triangle` and the triangle's index within it, if it is
    /// emissive.
    #[inline]
    pub fn emitter_of(&self, triangle: u32) -> Option<(usize, usize)> {
        match self.emitter_of_triangle.get(triangle as usize) {
            Some(&(e, k)) if e != u32::MAX => Some((e as usize, k as usize)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::scene::SceneParts;

    /// A one-sided (or double-sided) emissive triangle plus a diffuse floor far away, and the
    /// given punctual lights.
    fn scene(double_sided: bool, lights: Vec<Light>) -> Scene {
        let mut emitter = Material::diffuse("lamp", Vec3::ZERO);
        emitter.emission = Vec3::new(2.0, 1.0, 0.5);
        emitter.double_sided = double_sided;
        Scene::from_parts(SceneParts {
            source: "test".into(),
            // Triangle in the plane z = 1 facing -Z (toward the origin), and a floor.
            positions: vec![
                Vec3::new(-0.5, -0.3, 1.0),
                Vec3::new(0.2, 0.6, 1.0),
                Vec3::new(0.7, -0.4, 1.0),
                Vec3::new(-10.0, -5.0, -10.0),
                Vec3::new(10.0, -5.0, -10.0),
                Vec3::new(0.0, -5.0, 10.0),
            ],
            triangles: vec![[0, 1, 2], [3, 5, 4]],
            triangle_materials: vec![0, 1],
            materials: vec![emitter, Material::diffuse("floor", Vec3::splat(0.5))],
            lights,
            ..Default::default()
        })
        .unwrap()
    }

    fn triangle_light(scene: &Scene) -> Light {
        *scene
            .lights
            .iter()
            .find(|l| matches!(l, Light::Triangle { .. }))
            .unwrap()
    }

    /// Solid angle of a triangle seen from the origin (Van Oosterom and Strackee 1983).
    fn solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f32 {
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c)).abs();
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * num.atan2(den)
    }

    #[test]
    fn spot_falloff_follows_the_gltf_spec() {
        let (ci, co) = (0.9f32, 0.7f32);
        assert_eq!(spot_falloff(1.0, ci, co), 1.0);
        assert_eq!(spot_falloff(0.9, ci, co), 1.0);
        assert!((spot_falloff(0.8, ci, co) - 0.25).abs() < 1e-5);
        assert!((spot_falloff(0.75, ci, co) - 0.0625).abs() < 1e-5);
        assert_eq!(spot_falloff(0.7, ci, co), 0.0);
        assert_eq!(spot_falloff(-1.0, ci, co), 0.0);
        // Equal cones: a hard edge.
        assert_eq!(spot_falloff(0.81, 0.8, 0.8), 1.0);
        assert_eq!(spot_falloff(0.79, 0.8, 0.8), 0.0);
    }

    #[test]
    fn range_window_is_the_recommended_one() {
        assert_eq!(range_window(3.0, None), 1.0);
        assert_eq!(range_window(3.0, Some(0.0)), 1.0);
        assert_eq!(range_window(0.0, Some(2.0)), 1.0);
        assert!((range_window(1.0, Some(2.0)) - (1.0 - 1.0 / 16.0)).abs() < 1e-6);
        assert_eq!(range_window(2.0, Some(2.0)), 0.0);
        assert_eq!(range_window(5.0, Some(2.0)), 0.0);
    }

    #[test]
    fn punctual_lights_give_intensity_over_r2() {
        let s = scene(false, vec![]);
        let p = Vec3::new(1.0, 2.0, 3.0);
        let point = Light::Point {
            position: p + Vec3::new(0.0, 2.0, 0.0),
            intensity: Vec3::new(8.0, 4.0, 2.0),
            range: Some(4.0),
        };
        let ls = point.sample_li(&s, p, Vec2::new(0.3, 0.7)).unwrap();
        assert!(ls.delta && ls.pdf == 1.0 && (ls.wi - Vec3::Y).length() < 1e-6);
        assert_eq!(ls.dist, 2.0);
        let window = 1.0 - (0.5f32).powi(4);
        assert!((ls.li - Vec3::new(2.0, 1.0, 0.5) * window).length() < 1e-5);
        assert!(point.sample_li(&s, p - Vec3::Y * 3.0, Vec2::ZERO).is_none());

        // A spot pointing down; points on its axis, at the middle of the falloff, outside.
        let spot = Light::Spot {
            position: Vec3::new(0.0, 4.0, 0.0),
            direction: -Vec3::Y,
            intensity: Vec3::splat(16.0),
            cos_inner: 0.9,
            cos_outer: 0.7,
            range: None,
        };
        let ls = spot.sample_li(&s, Vec3::ZERO, Vec2::ZERO).unwrap();
        assert!((ls.li - Vec3::ONE).length() < 1e-6);
        let off = Vec3::new(0.6, 4.0 - 0.8, 0.0); // cos = 0.8 at distance 1
        let ls = spot.sample_li(&s, off, Vec2::ZERO).unwrap();
        assert!(
            (ls.li - Vec3::splat(16.0 * 0.25)).length() < 1e-3,
            "{}",
            ls.li
        );
        assert!(spot
            .sample_li(&s, Vec3::new(4.0, 4.0, 0.0), Vec2::ZERO)
            .is_none());

        let sun = Light::Directional {
            direction: Vec3::new(0.0, -1.0, 0.0),
            irradiance: Vec3::splat(3.0),
        };
        let ls = sun.sample_li(&s, p, Vec2::ZERO).unwrap();
        assert!(ls.delta && ls.dist == f32::INFINITY && ls.wi == Vec3::Y);
    }

    #[test]
    fn triangle_sampling_density_matches_solid_angle_and_pdf_li() {
        let s = scene(false, vec![]);
        let light = triangle_light(&s);
        let [a, b, c] = s.triangles[0].map(|v| s.positions[v as usize]);
        let p = Vec3::new(0.1, -0.2, -0.5);
        let omega = solid_angle(a - p, b - p, c - p);
        // E[1 / pdf] over the sampled directions is the solid angle.
        let n = 64;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let ls = light.sample_li(&s, p, u).unwrap();
                assert!(!ls.delta);
                assert_eq!(ls.li, Vec3::new(2.0, 1.0, 0.5));
                sum += 1.0 / ls.pdf as f64;
                // pdf_li at the sampled point agrees with the sample's pdf.
                let q = p + ls.wi * ls.dist;
                let hit = SurfaceHit {
                    t: ls.dist,
                    p: q,
                    ng: -Vec3::Z,
                    ns: -Vec3::Z,
                    uv: Vec2::ZERO,
                    triangle: 0,
                    material: 0,
                };
                let pdf = light.pdf_li(&s, p, &hit);
                assert!((pdf - ls.pdf).abs() <= 1e-4 * ls.pdf, "{pdf} {}", ls.pdf);
            }
        }
        let estimate = sum / (n * n) as f64;
        assert!(
            (estimate - omega as f64).abs() < 2e-3 * omega as f64,
            "{estimate} vs {omega}"
        );
        // Emission is one-sided: nothing from behind, unless double-sided.
        let behind = Vec3::new(0.1, 0.0, 2.0);
        assert!(light.sample_li(&s, behind, Vec2::splat(0.3)).is_none());
        let s2 = scene(true, vec![]);
        let ls = triangle_light(&s2).sample_li(&s2, behind, Vec2::splat(0.3));
        assert!(ls.is_some_and(|ls| ls.wi.z < 0.0));
    }

    #[test]
    fn emitted_radiance_is_one_sided_unless_double_sided() {
        for double_sided in [false, true] {
            let s = scene(double_sided, vec![]);
            let hit = s
                .intersect(&crate::geometry::Ray::new(Vec3::ZERO, Vec3::Z))
                .unwrap();
            assert_eq!(
                emitted_radiance(&s, &hit, -Vec3::Z),
                Vec3::new(2.0, 1.0, 0.5)
            );
            let back = emitted_radiance(&s, &hit, Vec3::Z);
            assert_eq!(back != Vec3::ZERO, double_sided);
        }
    }

    /// A receiver at `p` on a surface facing +Y with the given BSDF, viewed from `wo`.
    fn receiver(p: Vec3, bsdf: Bsdf, wo: Vec3) -> Receiver {
        let frame = Frame::from_normal(Vec3::Y);
        Receiver {
            p,
            ng: Vec3::Y,
            frame,
            wo_local: frame.to_local(wo.normalize()),
            bsdf,
        }
    }

    /// Appends a UV sphere (outward winding) of `material` to `parts`.
    fn sphere(parts: &mut SceneParts, centre: Vec3, r: f32, material: u32) {
        let (rings, segments) = (12u32, 16u32);
        let base = parts.positions.len() as u32;
        for i in 0..=rings {
            let theta = PI * i as f32 / rings as f32;
            for j in 0..segments {
                let phi = 2.0 * PI * j as f32 / segments as f32;
                parts.positions.push(
                    centre
                        + r * Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.cos(),
                            theta.sin() * phi.sin(),
                        ),
                );
            }
        }
        let idx = |i: u32, j: u32| base + i * segments + j % segments;
        for i in 0..rings {
            for j in 0..segments {
                let (a, b, c, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1));
                for t in [[a, b, d], [a, d, c]] {
                    let [p0, p1, p2] = t.map(|v| parts.positions[v as usize]);
                    let n = (p1 - p0).cross(p2 - p0);
                    if n.length() > 1e-9 {
                        // Outward: flip if the winding faces the centre.
                        let t = if n.dot(p0 - centre) < 0.0 {
                            [t[0], t[2], t[1]]
                        } else {
                            t
                        };
                        parts.triangles.push(t);
                        parts.triangle_materials.push(material);
                    }
                }
            }
        }
    }

    /// A sphere lamp of radiance `le` at `centre` over a floor, plus two separate lens quads
    /// (one-sided, facing down), and the given punctual lights.
    fn lamp_scene(centre: Vec3, le: f32, punctual: Vec<Light>) -> Scene {
        let mut lamp = Material::diffuse("lamp", Vec3::ZERO);
        lamp.emission = Vec3::splat(le);
        let mut lens = Material::diffuse("lens", Vec3::ZERO);
        lens.emission = Vec3::splat(3.0);
        let mut parts = SceneParts {
            source: "test".into(),
            materials: vec![Material::diffuse("floor", Vec3::splat(0.5)), lamp, lens],
            lights: punctual,
            ..Default::default()
        };
        let quad = |parts: &mut SceneParts, c: Vec3, h: f32, up: bool, m: u32| {
            let b = parts.positions.len() as u32;
            parts.positions.extend([
                c + Vec3::new(-h, 0.0, -h),
                c + Vec3::new(h, 0.0, -h),
                c + Vec3::new(h, 0.0, h),
                c + Vec3::new(-h, 0.0, h),
            ]);
            // Counter-clockwise seen from above faces +Y.
            let (t0, t1) = if up {
                ([b, b + 3, b + 2], [b, b + 2, b + 1])
            } else {
                ([b, b + 1, b + 2], [b, b + 2, b + 3])
            };
            parts.triangles.extend([t0, t1]);
            parts.triangle_materials.extend([m, m]);
        };
        quad(&mut parts, Vec3::ZERO, 50.0, true, 0);
        sphere(&mut parts, centre, 0.3, 1);
        quad(&mut parts, Vec3::new(4.0, 3.0, 0.0), 0.2, false, 2);
        quad(&mut parts, Vec3::new(-4.0, 3.0, 0.0), 0.2, false, 2);
        Scene::from_parts(parts).unwrap()
    }

    /// Irradiance at `p` (normal `n`) from a uniformly emitting polygon of radiance 1
    /// (Lambert's formula: `E = 1/2 sum_i angle_i (n . unit(v_i x v_{i+1}))`).
    /// In f64: the terms cancel to a small sum for small, distant polygons.
    fn polygon_irradiance(p: Vec3, n: Vec3, verts: &[Vec3]) -> f64 {
        let (p, n) = (p.as_dvec3(), n.as_dvec3());
        let mut e = 0.0;
        for i in 0..verts.len() {
            let a = (verts[i].as_dvec3() - p).normalize();
            let b = (verts[(i + 1) % verts.len()].as_dvec3() - p).normalize();
            let angle = a.dot(b).clamp(-1.0, 1.0).acos();
            e += angle * n.dot(a.cross(b).normalize());
        }
        0.5 * e.abs()
    }

    /// Next-event estimate of the irradiance (`sum L cos / pdf`, emitter meshes only) at the
    /// receiver, resolving first-hit samples by tracing, with `n * n` stratified samples.
    fn estimate_irradiance(s: &Scene, ls: &LightSampler, rx: &Receiver, n: usize) -> f64 {
        let mut sum = 0.0f64;
        let mut rng = crate::sampling::Pcg32::new(7, 1);
        for _ in 0..n {
            for _ in 0..n {
                let u_light = rng.next_f32();
                let u = rng.next_2d();
                let Some(sample) = ls.sample_li(s, rx, u_light, u) else {
                    continue;
                };
                if sample.delta {
                    continue;
                }
                let li = match sample.visibility {
                    Visibility::ShadowRay => sample.li,
                    Visibility::FirstHit { emitter } => {
                        let ray = crate::geometry::Ray::new(rx.p + Vec3::Y * 1e-4, sample.wi);
                        match s.intersect(&ray) {
                            Some(h)
                                if ls.emitter_of(h.triangle).map(|x| x.0)
                                    == Some(emitter as usize) =>
                            {
                                // The density of the first-hit direction is what pdf_li says.
                                let pdf = ls.pdf_li(s, rx, &h);
                                assert!(
                                    (pdf - sample.pdf).abs() <= 1e-3 * sample.pdf,
                                    "{pdf} {}",
                                    sample.pdf
                                );
                                emitted_radiance(s, &h, -sample.wi)
                            }
                            _ => Vec3::ZERO,
                        }
                    }
                };
                sum += (li.x * sample.wi.dot(rx.ng).max(0.0) / sample.pdf) as f64;
            }
        }
        sum / (n * n) as f64
    }

    #[test]
    fn emissive_triangles_are_grouped_into_emitters() {
        let point = Light::Point {
            position: Vec3::new(0.0, 5.0, 0.0),
            intensity: Vec3::splat(10.0),
            range: None,
        };
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, vec![point]);
        let ls = LightSampler::new(&s);
        // The point light, the sphere, two separate lenses.
        assert_eq!(ls.emitter_count(), 4);
        let mut kinds = Vec::new();
        for e in &ls.emitters {
            if let Emitter::Mesh(m) = e {
                kinds.push((m.lights.len(), m.cone, m.front.is_some()));
            }
        }
        kinds.sort();
        assert_eq!(kinds[0], (2, false, true));
        assert_eq!(kinds[1], (2, false, true));
        assert!(kinds[2].0 > 300 && kinds[2].1 && !kinds[2].2, "{kinds:?}");
        // Every emissive triangle maps back to its emitter.
        for (i, l) in s.lights.iter().enumerate() {
            if let Light::Triangle { triangle } = *l {
                let (e, k) = ls.emitter_of(triangle).unwrap();
                let Emitter::Mesh(m) = &ls.emitters[e] else {
                    panic!()
                };
                assert_eq!(m.lights[k] as usize, i);
            }
        }
        assert_eq!(ls.emitter_of(0), None);
    }

    #[test]
    fn cone_sampling_of_a_sphere_lamp_gives_its_exact_irradiance() {
        let centre = Vec3::new(0.5, 2.0, -3.0);
        let s = lamp_scene(centre, 1.0, vec![]);
        let ls = LightSampler::new(&s);
        let p = Vec3::new(0.0, 0.0, 0.0);
        // Exact: the sum over the sphere triangles that face p (a convex polyhedron: they tile
        // its silhouette once).
        let mut exact = 0.0f64;
        for (t, &m) in s.triangle_materials.iter().enumerate() {
            if m == 1 {
                let v = triangle_vertices(&s, t as u32);
                let (n, _) = s.triangle_normal_area(t as u32);
                if n.dot(p - v[0]) > 0.0 {
                    exact += polygon_irradiance(p, Vec3::Y, &v);
                }
            }
        }
        // Lenses add a little; count them with their own exact irradiance.
        for c in [Vec3::new(4.0, 3.0, 0.0), Vec3::new(-4.0, 3.0, 0.0)] {
            let h = 0.2;
            let quad = [
                c + Vec3::new(-h, 0.0, -h),
                c + Vec3::new(h, 0.0, -h),
                c + Vec3::new(h, 0.0, h),
                c + Vec3::new(-h, 0.0, h),
            ];
            exact += 3.0 * polygon_irradiance(p, Vec3::Y, &quad);
        }
        for bsdf in [
            Bsdf::Diffuse(crate::bsdf::Diffuse {
                kd: Vec3::splat(0.5),
            }),
            Bsdf::Ggx(crate::bsdf::Ggx {
                kd: Vec3::splat(0.05),
                ks: Vec3::splat(0.5),
                alpha: 0.1,
            }),
        ] {
            let rx = receiver(p, bsdf, Vec3::new(0.0, 1.0, 6.0));
            let est = estimate_irradiance(&s, &ls, &rx, 256);
            assert!(
                (est - exact).abs() < 5e-3 * exact,
                "{bsdf:?}: {est} vs {exact}"
            );
        }
    }

    /// The cone samples that reach the sphere lamp cover exactly the solid angle of its
    /// silhouette: `E[1{hit} / pdf]` against the sum of the solid angles of the triangles that
    /// face the point (from afar, from close by, from just outside the bounding sphere).
    #[test]
    fn cone_samples_cover_the_lamp_silhouette_exactly() {
        let centre = Vec3::new(0.5, 2.0, -3.0);
        let s = lamp_scene(centre, 1.0, vec![]);
        let ls = LightSampler::new(&s);
        let e = (0..ls.emitter_count())
            .find(|&e| matches!(&ls.emitters[e], Emitter::Mesh(m) if m.cone))
            .unwrap();
        let Emitter::Mesh(m) = &ls.emitters[e] else {
            unreachable!()
        };
        for p in [Vec3::ZERO, centre + Vec3::Z * 4.0, centre - Vec3::Z * 0.35] {
            let mut rng = crate::sampling::Pcg32::new(3, 4);
            let n = 200_000;
            let mut omega = 0.0f64;
            for _ in 0..n {
                let sample = m.sample_li(&s, e as u32, p, 0.5, rng.next_2d()).unwrap();
                assert_eq!(
                    sample.visibility,
                    Visibility::FirstHit { emitter: e as u32 }
                );
                let hit = s.intersect(&crate::geometry::Ray::new(p, sample.wi));
                if let Some(h) = hit.filter(|h| ls.emitter_of(h.triangle).map(|x| x.0) == Some(e)) {
                    assert!(emitted_radiance(&s, &h, -sample.wi).x > 0.0);
                    omega += 1.0 / sample.pdf as f64;
                }
            }
            let omega = omega / n as f64;
            let mut exact = 0.0f64;
            for (t, &material) in s.triangle_materials.iter().enumerate() {
                let (normal, _) = s.triangle_normal_area(t as u32);
                let v = triangle_vertices(&s, t as u32).map(|x| x - p);
                if material == 1 && normal.dot(-v[0]) > 0.0 {
                    exact += solid_angle(v[0], v[1], v[2]) as f64;
                }
            }
            assert!(
                (omega / exact - 1.0).abs() < 1.5e-3,
                "{p}: {omega} vs {exact}"
            );
        }
    }

    #[test]
    fn emitter_choice_is_a_distribution_and_follows_the_bsdf() {
        let lights = vec![
            Light::Point {
                position: Vec3::new(3.0, 4.0, -10.0),
                intensity: Vec3::splat(40.0),
                range: None,
            },
            Light::Spot {
                position: Vec3::new(0.0, 4.0, 0.0),
                direction: -Vec3::Y,
                intensity: Vec3::splat(30.0),
                cos_inner: 0.9,
                cos_outer: 0.8,
                range: None,
            },
            Light::Directional {
                direction: -Vec3::Y,
                irradiance: Vec3::splat(0.01),
            },
        ];
        let s = lamp_scene(Vec3::new(-3.0, 2.0, -10.0), 50.0, lights);
        let ls = LightSampler::new(&s);
        let n_e = ls.emitter_count();
        assert_eq!(n_e, 6);
        let glossy = Bsdf::Ggx(crate::bsdf::Ggx {
            kd: Vec3::splat(0.02),
            ks: Vec3::splat(0.6),
            alpha: 0.05,
        });
        // Receivers on the mirror paths of the sphere and of the point light, seen from the eye.
        let eye = Vec3::new(0.0, 1.5, 0.0);
        let mirror = |l: Vec3| {
            let t = eye.y / (eye.y + l.y);
            eye + (Vec3::new(l.x, 0.0, l.z) - Vec3::new(eye.x, 0.0, eye.z)) * t - Vec3::Y * eye.y
        };
        let on_sphere = mirror(Vec3::new(-3.0, 2.0, -10.0));
        let on_point = mirror(Vec3::new(3.0, 4.0, -10.0));
        for (p, favoured) in [(on_sphere, 3usize), (on_point, 0usize)] {
            let rx = receiver(p, glossy, eye - p);
            let pmfs: Vec<f32> = (0..n_e).map(|e| ls.emitter_pmf(&s, &rx, e)).collect();
            let total: f32 = pmfs.iter().sum();
            assert!((total - 1.0).abs() < 1e-5, "{pmfs:?}");
            // The spot (emitter 1) lights its cone only, which holds the second point only.
            assert_eq!(pmfs[1] == 0.0, favoured == 3, "{pmfs:?}");
            // The lamp whose streak this is gets most of the samples.
            let favoured = if favoured == 3 {
                (0..n_e)
                    .find(|&e| matches!(&ls.emitters[e], Emitter::Mesh(m) if m.cone))
                    .unwrap()
            } else {
                favoured
            };
            assert!(pmfs[favoured] > 0.8, "{favoured} {pmfs:?}");
            // Sampling frequencies follow the pmf.
            let n = 20_000;
            let mut counts = vec![0usize; n_e];
            for k in 0..n {
                let u = (k as f32 + 0.5) / n as f32;
                let (e, pmf, reused) = ls.choose(&s, &rx, u).unwrap();
                assert!((pmf - pmfs[e]).abs() < 1e-6 && (0.0..1.0).contains(&reused));
                counts[e] += 1;
            }
            for e in 0..n_e {
                assert!((counts[e] as f32 / n as f32 - pmfs[e]).abs() < 1e-3, "{e}");
            }
        }
        // Below a one-sided lens nothing; above it (behind its front face), the lens gets 0.
        let above = receiver(Vec3::new(4.0, 3.5, 0.0), glossy, Vec3::Y);
        for e in 0..n_e {
            if let Emitter::Mesh(m) = &ls.emitters[e] {
                if m.front.is_some() && m.centre.x > 0.0 {
                    assert_eq!(ls.emitter_pmf(&s, &above, e), 0.0);
                }
            }
        }
    }

    /// Checks the light tree's structure: every node has at most `BRANCHING` children, every
    /// emitter is a leaf exactly once at its recorded slot, every group points to a node whose
    /// parent link points back, and every node but the root is reached. Returns the depth.
    fn check_tree(ls: &LightSampler) -> usize {
        let mut seen = vec![0; ls.emitter_count()];
        let mut reached = vec![0; ls.nodes.len()];
        reached[0] = 1;
        assert!(ls.nodes[0].parent.is_none());
        for (n, node) in ls.nodes.iter().enumerate() {
            assert!(!node.children.is_empty() && node.children.len() <= BRANCHING);
            for (slot, child) in node.children.iter().enumerate() {
                match *child {
                    Child::Emitter(e) => {
                        seen[e as usize] += 1;
                        assert_eq!(ls.slot_of[e as usize], (n as u32, slot as u32));
                    }
                    Child::Group(g) => {
                        reached[g.node as usize] += 1;
                        assert_eq!(
                            ls.nodes[g.node as usize].parent,
                            Some((n as u32, slot as u32))
                        );
                    }
                }
            }
        }
        assert!(seen.iter().all(|&k| k == 1), "{seen:?}");
        assert!(reached.iter().all(|&k| k == 1), "{reached:?}");
        let depth = |e: usize| {
            let mut node = ls.slot_of[e].0;
            let mut d = 1;
            while let Some((parent, _)) = ls.nodes[node as usize].parent {
                node = parent;
                d += 1;
            }
            d
        };
        (0..ls.emitter_count()).map(depth).max().unwrap_or(0)
    }

    /// Checks that the choice at `rx` is a distribution over exactly the emitters that light
    /// it, that `choose` returns `emitter_pmf`'s probabilities, and that its frequencies follow
    /// them.
    fn check_choice(s: &Scene, ls: &LightSampler, rx: &Receiver) {
        let n_e = ls.emitter_count();
        let pmfs: Vec<f32> = (0..n_e).map(|e| ls.emitter_pmf(s, rx, e)).collect();
        assert!((pmfs.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{pmfs:?}");
        for (e, pmf) in pmfs.iter().enumerate() {
            assert_eq!(*pmf > 0.0, ls.irradiance(s, e, rx.p).0 > 0.0, "{e}");
        }
        let n = 40_000;
        let mut counts = vec![0usize; n_e];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (e, pmf, reused) = ls.choose(s, rx, u).unwrap();
            assert!(
                (pmf - pmfs[e]).abs() <= 1e-6 * pmfs[e].max(1.0),
                "{e}: {pmf} {}",
                pmfs[e]
            );
            assert!((0.0..1.0).contains(&reused));
            counts[e] += 1;
        }
        for e in 0..n_e {
            assert!((counts[e] as f32 / n as f32 - pmfs[e]).abs() < 1e-3, "{e}");
        }
    }

    /// With more emitters than `BRANCHING`: a two-level tree, the choice is a distribution
    /// over every emitter that lights the point, sampling follows it, and next-event
    /// estimation of the irradiance from 40 point lights (whose exact value is a sum) is
    /// unbiased.
    #[test]
    fn many_emitters_are_chosen_by_cluster() {
        let positions: Vec<Vec3> = (0..40)
            .map(|i| {
                let i = i as f32;
                Vec3::new(
                    (i * 2.3) % 17.0 - 8.0,
                    2.0 + (i * 0.7) % 3.0,
                    -2.0 - (i * 1.9) % 23.0,
                )
            })
            .collect();
        let lights: Vec<Light> = positions
            .iter()
            .enumerate()
            .map(|(i, &position)| Light::Point {
                position,
                intensity: Vec3::splat(1.0 + (i % 7) as f32),
                range: None,
            })
            .collect();
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, lights.clone());
        let ls = LightSampler::new(&s);
        let n_e = ls.emitter_count();
        assert_eq!(n_e, 43);
        assert_eq!(check_tree(&ls), 2);

        let glossy = Bsdf::Ggx(crate::bsdf::Ggx {
            kd: Vec3::splat(0.3),
            ks: Vec3::splat(0.6),
            alpha: 0.1,
        });
        let p = Vec3::new(0.5, 0.0, -4.0);
        let rx = receiver(p, glossy, Vec3::new(0.0, 1.5, 0.0) - p);
        check_choice(&s, &ls, &rx);

        // Unbiased: f * L * cos / pdf over many choices against the exact sum over the lights.
        let diffuse = Bsdf::Diffuse(crate::bsdf::Diffuse { kd: Vec3::ONE });
        let rx = receiver(p, diffuse, Vec3::Y);
        let exact: f64 = lights
            .iter()
            .map(|l| {
                let ls = l.sample_li(&s, p, Vec2::ZERO).unwrap();
                f64::from(luminance(ls.li) * ls.wi.y.max(0.0))
            })
            .sum();
        let mut rng = crate::sampling::Pcg32::new(9, 2);
        let m = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..m {
            if let Some(sample) = ls.sample_li(&s, &rx, rng.next_f32(), rng.next_2d()) {
                if sample.delta {
                    sum += f64::from(luminance(sample.li) * sample.wi.y.max(0.0) / sample.pdf);
                }
            }
        }
        let est = sum / m as f64;
        assert!((est / exact - 1.0).abs() < 0.01, "{est} vs {exact}");
    }

    /// 400 point lights (a quarter of them at one spot, which k-means cannot split) make a
    /// tree of three levels or more, and the choice down it is still the distribution that
    /// `emitter_pmf` gives.
    #[test]
    fn a_deep_light_tree_chooses_by_its_pmf() {
        let lights: Vec<Light> = (0..400)
            .map(|i| {
                let f = i as f32;
                let position = if i % 4 == 0 {
                    Vec3::new(3.0, 4.0, -6.0)
                } else {
                    Vec3::new(
                        (f * 2.3) % 37.0 - 18.0,
                        2.0 + (f * 0.7) % 5.0,
                        -(f * 1.9) % 41.0,
                    )
                };
                Light::Point {
                    position,
                    intensity: Vec3::splat(1.0 + (i % 5) as f32),
                    range: None,
                }
            })
            .collect();
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, lights);
        let ls = LightSampler::new(&s);
        assert!(check_tree(&ls) >= 3);
        let glossy = Bsdf::Ggx(crate::bsdf::Ggx {
            kd: Vec3::splat(0.3),
            ks: Vec3::splat(0.6),
            alpha: 0.1,
        });
        let p = Vec3::new(0.5, 0.0, -4.0);
        check_choice(&s, &ls, &receiver(p, glossy, Vec3::new(2.0, 1.5, -1.0) - p));
    }

    /// Many directional lights (no positions) share a group, which splits into runs.
    #[test]
    fn many_directional_lights_share_a_cluster() {
        let lights: Vec<Light> = (0..BRANCHING + 4)
            .map(|i| Light::Directional {
                direction: Vec3::new(0.1 * i as f32, -1.0, 0.2).normalize(),
                irradiance: Vec3::splat(0.1),
            })
            .collect();
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, lights);
        let ls = LightSampler::new(&s);
        assert_eq!(check_tree(&ls), 3);
        let rx = receiver(
            Vec3::ZERO,
            Bsdf::Diffuse(crate::bsdf::Diffuse { kd: Vec3::ONE }),
            Vec3::Y,
        );
        let total: f32 = (0..ls.emitter_count())
            .map(|e| ls.emitter_pmf(&s, &rx, e))
            .sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
    }

    #[test]
    fn no_lights_no_samples() {
        let mut s = scene(false, vec![]);
        s.lights.clear();
        let rx = receiver(
            Vec3::ZERO,
            Bsdf::Diffuse(crate::bsdf::Diffuse { kd: Vec3::ONE }),
            Vec3::Y,
        );
        assert!(LightSampler::new(&s)
            .sample_li(&s, &rx, 0.5, Vec2::splat(0.5))
            .is_none());
    }
}
