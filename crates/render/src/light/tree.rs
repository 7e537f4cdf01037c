//! The light tree: emitters grouped by position, so that the light choice weighs at most
//! [`BRANCHING`] emitters or groups at a time however many there are.
//!
//! Up to [`BRANCHING`] emitters the tree is one level: the root's children are the emitters.
//! With more (a street of lamps, cars and windows), they are split into at most [`BRANCHING`]
//! groups by power-weighted k-means on their positions, and groups of more than
//! [`BRANCHING`] again, down to groups of at most [`BRANCHING`] emitters.
//!
//! Like pbrt-v4's `LightBVHNode` array and psychopath's light tree, the tree is one flat array
//! of [`Node`]s: the root's children first, then each group's children, contiguous, in
//! breadth-first order; a group names its children by an index range. Nothing is allocated per
//! node, and a walk down the tree reads consecutive nodes.

use super::emitter::EmitterBounds;
use glam::Vec3;
use std::collections::VecDeque;
use std::f32::consts::PI;
use std::ops::Range;

/// Children per node of the light tree: the light choice weighs at most this many emitters or
/// groups of emitters at a time by the BSDF toward them. Up to this many emitters the tree is
/// a single level.
pub const BRANCHING: usize = 16;

/// Lloyd iterations of the k-means that splits a group of emitters.
const CLUSTER_ITERATIONS: usize = 16;

/// A node of the light tree: an emitter, or a group of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Node {
    /// An emitter (an index into the scene's emitters), weighed by its own irradiance and BSDF.
    Emitter(u32),
    /// Several emitters, weighed as one.
    Group(Group),
}

/// Emitters that the light choice weighs as one: by the irradiance their power would give
/// from their bounding sphere (their spot lights' intensity only inside their beams, see
/// [`GroupBeam`]), and by the BSDF toward their most powerful member.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Group {
    /// Its children: `first..first + len` in [`LightTree::nodes`].
    pub first: u32,
    /// How many children it has (at most [`BRANCHING`]).
    pub len: u32,
    /// Centre of a sphere that bounds its emitters (their bounding spheres for meshes).
    pub centre: Vec3,
    /// Its radius.
    pub radius: f32,
    /// Their total power (luminance, W).
    pub power: f32,
    /// The power its weight spreads over every direction (luminance, W): its emitters'
    /// without their spot lights, whose intensity is in `beam`; or with `4 pi I` for each
    /// spot light when their beams together are wider than a hemisphere.
    pub isotropic_power: f32,
    /// The spot lights' beams bounded as one, when they are no wider than a hemisphere.
    pub beam: Option<GroupBeam>,
    /// Where the BSDF weight looks: the most powerful one's position (a lamp's bulb rather
    /// than the middle of a lamp and its neighbours).
    pub anchor: Vec3,
}

/// A cone that holds every beam of a group's spot lights, with their summed intensity: a
/// point in it may see all of them at full intensity, a point outside (by more than the
/// group's angular radius) none. Weighing a grouped spot light by its power over `4 pi`
/// instead made a headlight's group 44 times too faint in its own beam (a 0.28 sr cone), and
/// a window pane mirroring the headlight chose it with probability 0.005 to 0.05.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroupBeam {
    /// Unit axis (the intensity-weighted mean of the spots' axes).
    pub axis: Vec3,
    /// Cosine of its half-angle (at most 90 degrees).
    pub cos: f32,
    /// Sine of its half-angle.
    pub sin: f32,
    /// The spot lights' summed intensity (luminance, W/sr).
    pub intensity: f32,
}

impl Group {
    /// Its children's indices in [`LightTree::nodes`].
    #[inline]
    pub fn children(&self) -> Range<usize> {
        self.first as usize..(self.first + self.len) as usize
    }
}

/// No parent: a child of the root.
const ROOT: u32 = u32::MAX;

/// The light tree over a scene's emitters (see the module documentation).
#[derive(Clone, Debug, Default)]
pub struct LightTree {
    /// Every node; the root's children are `0..root_len`.
    nodes: Vec<Node>,
    /// How many children the root has.
    root_len: u32,
    /// For each node, the group node whose child it is ([`ROOT`] for the root's children).
    parent: Vec<u32>,
    /// For each emitter, its node.
    node_of_emitter: Vec<u32>,
}

impl LightTree {
    /// Builds the tree over emitters with the given bounds (breadth first: a group's children
    /// get their place in the array when the group is made, so nothing is patched later).
    pub fn build(bounds: &[EmitterBounds]) -> Self {
        let mut tree = Self {
            node_of_emitter: vec![0; bounds.len()],
            ..Self::default()
        };
        let root = split(bounds, &(0..bounds.len() as u32).collect::<Vec<u32>>());
        tree.root_len = root.len() as u32;
        // Groups whose nodes are placed, with their parent: the next one popped holds the
        // nodes that come next in the array.
        let mut queue = VecDeque::from([(ROOT, root)]);
        let mut next = tree.root_len;
        while let Some((parent, groups)) = queue.pop_front() {
            for group in groups {
                let index = tree.nodes.len() as u32;
                tree.parent.push(parent);
                if let [e] = group[..] {
                    tree.node_of_emitter[e as usize] = index;
                    tree.nodes.push(Node::Emitter(e));
                } else {
                    let children = split(bounds, &group);
                    let len = children.len() as u32;
                    tree.nodes
                        .push(Node::Group(group_bounds(bounds, &group, next, len)));
                    next += len;
                    queue.push_back((index, children));
                }
            }
        }
        debug_assert_eq!(next as usize, tree.nodes.len());
        tree
    }

    /// Every node (see [`LightTree`]).
    #[inline]
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The root's children's indices.
    #[inline]
    pub fn root(&self) -> Range<usize> {
        0..self.root_len as usize
    }

    /// The indices of the nodes among which `node` was chosen: its siblings and itself.
    #[inline]
    pub fn siblings(&self, node: usize) -> Range<usize> {
        match self.parent(node) {
            Some(parent) => match self.nodes[parent] {
                Node::Group(g) => g.children(),
                Node::Emitter(_) => unreachable!("a parent is a group"),
            },
            None => self.root(),
        }
    }

    /// The group node whose child `node` is; `None` for the root's children.
    #[inline]
    pub fn parent(&self, node: usize) -> Option<usize> {
        match self.parent[node] {
            ROOT => None,
            p => Some(p as usize),
        }
    }

    /// The node of emitter `e`.
    #[inline]
    pub fn node_of_emitter(&self, e: usize) -> Option<usize> {
        self.node_of_emitter.get(e).map(|&n| n as usize)
    }
}

/// The children of a node with the given emitters: each emitter on its own when they are at
/// most [`BRANCHING`], else [`partition`]'s groups.
fn split(bounds: &[EmitterBounds], members: &[u32]) -> Vec<Vec<u32>> {
    if members.len() <= BRANCHING {
        members.iter().map(|&e| vec![e]).collect()
    } else {
        partition(bounds, members)
    }
}

/// The bounds of a group of emitters whose `len` children start at node `first`.
fn group_bounds(bounds: &[EmitterBounds], members: &[u32], first: u32, len: u32) -> Group {
    let spheres: Vec<(Vec3, f32)> = members
        .iter()
        .filter_map(|&e| {
            let b = &bounds[e as usize];
            b.position.map(|p| (p, b.radius))
        })
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
    let power = members.iter().map(|&e| bounds[e as usize].power).sum();
    let (isotropic_power, beam) = group_beam(bounds, members);
    let anchor = members
        .iter()
        .filter_map(|&e| {
            let b = &bounds[e as usize];
            b.position.map(|p| (p, b.power))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(centre, |(p, _)| p);
    Group {
        first,
        len,
        centre,
        radius,
        power,
        isotropic_power,
        beam,
        anchor,
    }
}

/// The isotropic power and the bounding beam of a group's emitters (see [`GroupBeam`]).
fn group_beam(bounds: &[EmitterBounds], members: &[u32]) -> (f32, Option<GroupBeam>) {
    let beams = || members.iter().filter_map(|&e| bounds[e as usize].beam);
    let isotropic: f32 = members
        .iter()
        .map(|&e| &bounds[e as usize])
        .filter(|b| b.beam.is_none())
        .map(|b| b.power)
        .sum();
    let intensity: f32 = beams().map(|b| b.intensity).sum();
    if intensity <= 0.0 {
        return (isotropic, None);
    }
    let axis = beams()
        .fold(Vec3::ZERO, |a, b| a + b.intensity * b.axis)
        .normalize_or_zero();
    // The widest angle from the axis that a member's outer cone reaches, widened by a
    // milliradian against rounding at the edge.
    let half_angle = beams()
        .map(|b| axis.dot(b.axis).clamp(-1.0, 1.0).acos() + b.cos_outer.clamp(-1.0, 1.0).acos())
        .fold(0.0f32, f32::max)
        + 1e-3;
    if axis == Vec3::ZERO || half_angle > 0.5 * PI {
        return (isotropic + 4.0 * PI * intensity, None);
    }
    let (sin, cos) = half_angle.sin_cos();
    let beam = GroupBeam {
        axis,
        cos,
        sin,
        intensity,
    };
    (isotropic, Some(beam))
}

/// Splits more than [`BRANCHING`] emitters into at most [`BRANCHING`] non-empty groups:
/// directional lights alone (all in one when there are more than half as many) and the
/// others by position (the centres of meshes, the positions of point and spot lights) into
/// the remaining groups, by k-means weighted by power, started from the most powerful emitter
/// and then the farthest ones. When that makes a single group (lights at one position, or
/// only directional ones), consecutive runs of the input instead, so every level shrinks.
fn partition(bounds: &[EmitterBounds], members: &[u32]) -> Vec<Vec<u32>> {
    let directional: Vec<u32> = members
        .iter()
        .copied()
        .filter(|&e| bounds[e as usize].position.is_none())
        .collect();
    let placed: Vec<(u32, Vec3, f32)> = members
        .iter()
        .filter_map(|&e| {
            let b = &bounds[e as usize];
            b.position.map(|p| (e, p, b.power))
        })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_scenes::check_tree;

    fn point(p: Vec3, power: f32) -> EmitterBounds {
        EmitterBounds {
            position: Some(p),
            radius: 0.0,
            power,
            beam: None,
        }
    }

    #[test]
    fn few_emitters_make_one_level() {
        let bounds: Vec<EmitterBounds> = (0..BRANCHING)
            .map(|i| point(Vec3::X * i as f32, 1.0))
            .collect();
        let tree = LightTree::build(&bounds);
        assert_eq!(tree.root(), 0..BRANCHING);
        assert_eq!(check_tree(&tree, BRANCHING), 1);
        assert!(tree
            .nodes()
            .iter()
            .enumerate()
            .all(|(i, n)| *n == Node::Emitter(i as u32)));
        let empty = LightTree::build(&[]);
        assert!(empty.root().is_empty() && empty.nodes().is_empty());
    }

    #[test]
    fn groups_bound_their_members() {
        // Two streets of lamps far apart, one much brighter lamp in each.
        let bounds: Vec<EmitterBounds> = (0..60)
            .map(|i| {
                let street = if i % 2 == 0 { -50.0 } else { 50.0 };
                let power = if i < 2 { 100.0 } else { 1.0 };
                EmitterBounds {
                    position: Some(Vec3::new(street, 5.0, i as f32)),
                    radius: 0.25,
                    power,
                    beam: None,
                }
            })
            .collect();
        let tree = LightTree::build(&bounds);
        assert_eq!(check_tree(&tree, bounds.len()), 2);
        let members = |g: &Group| -> Vec<usize> {
            g.children()
                .map(|c| match tree.nodes()[c] {
                    Node::Emitter(e) => e as usize,
                    Node::Group(_) => panic!("a two-level tree"),
                })
                .collect()
        };
        for node in tree.nodes() {
            if let Node::Group(g) = node {
                let m = members(g);
                let power: f32 = m.iter().map(|&e| bounds[e].power).sum();
                assert!((g.power - power).abs() < 1e-4);
                for &e in &m {
                    let b = bounds[e];
                    let p = b.position.unwrap();
                    assert!(p.distance(g.centre) + b.radius <= g.radius * (1.0 + 1e-6));
                }
                let strongest = m
                    .iter()
                    .max_by(|a, b| bounds[**a].power.total_cmp(&bounds[**b].power))
                    .unwrap();
                assert_eq!(g.anchor, bounds[*strongest].position.unwrap());
            }
        }
    }

    #[test]
    fn lights_at_one_spot_are_cut_into_runs() {
        let bounds: Vec<EmitterBounds> = (0..40).map(|_| point(Vec3::ONE, 1.0)).collect();
        let tree = LightTree::build(&bounds);
        assert_eq!(check_tree(&tree, 40), 2);
        assert_eq!(tree.root().len(), 14); // runs of ceil(40 / 16) = 3
    }
}
