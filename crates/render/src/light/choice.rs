//! The light choice: which emitter a shading point sends its shadow ray to, and the density of
//! that choice for multiple importance sampling.
//!
//! At a node of the [light tree](super::tree) a child `c` is chosen with probability
//! `0.01 E_c / sum E + 0.99 E_c F_c / sum E F` (all by `E` when every `E F` is 0): `E_c` is the
//! irradiance the child would give at the point and `F_c` the luminance of the BSDF times the
//! cosine toward it (zero below the shading or the geometric surface). The 1% share by `E`
//! alone is defensive sampling: every emitter that can light the point keeps a positive
//! probability even where the BSDF toward its centre is zero. On a glossy wet road the
//! mixture sends a streak's shadow rays to the lamp that makes the streak. A point in the fog
//! ([`Receiver::in_medium`]) has no BSDF to weigh by: its choice goes by `E` alone.
//!
//! The share is small because every shadow ray it sends elsewhere is wasted in a streak pixel,
//! and what it guards against is mostly covered otherwise: a punctual light's `F` is exact,
//! an emitter mesh that `F` misses is found by BSDF sampling (and weighed by MIS), and a
//! sharp lobe's view of a group by the cone rule below. A share of 10% cost the `crosscheck`
//! road 1.7x its variance at 64 spp, and lowering it made no scene noisier
//! (docs/decisions/0008). At a transmissive BSDF the share stays 10%: its
//! `F` leaves out the transmission, so a light behind it has this share alone.
//!
//! - An emitter's `E`: intensity, spot falloff and range window over `d^2` for point and spot
//!   lights, the irradiance for a directional light, `power / (4 pi max(d, r)^2)` for a mesh of
//!   bounding radius `r` (zero behind a flat one-sided mesh); its `F` looks toward the light or
//!   the mesh's centre.
//! - A group's `E`: its total power over its bounding sphere, the same way, except for its
//!   spot lights, whose summed intensity counts only where the point may lie in their beams
//!   ([`super::tree::GroupBeam`]); its `F` looks toward its most powerful member (toward the
//!   middle of a lamp and its neighbours, the glossy lobe would miss the lamp).
//! - A sharp glossy lobe sees little of a group that way when what it mirrors is a weaker
//!   member: a window pane (GGX alpha 0.02) reflecting one street light of a cluster. So for a
//!   BSDF with a glossy lobe, a bounded child (group or emitter mesh) whose bounding cone holds
//!   the lobe's mirror direction, and spans more than four times the lobe's solid angle
//!   (`rho / peak`, its reflectance over its peak `f cos`), gets at least `F = rho / Omega`:
//!   the lobe's reflectance spread over the cone's solid angle `Omega`, its mean over the cone.
//!   On a procedural street this took the choice of such a light from 0.0004 to 0.002-0.005
//!   and the image's relative RMSE at 64 spp from 1.1 to 0.6; on `rainy_street` the road's
//!   fell by 30 %. A cone not that much wider than the lobe keeps its anchor's `F`: the
//!   anchor then lies in the lobe. (Raising every cone that holds the mirror direction made
//!   a rough lens seen at grazing send its shadow rays to groups rather than to its bulb 0.1 m
//!   away; docs/decisions/0016-sharp-lobes-see-past-the-anchor.md.)
//!
//! The environment light ([`Environment`]), when the scene has one, is one more choice beside
//! the tree, made first: it is chosen with probability `E_env / (E_env + E_tree)`, held within
//! [`ENVIRONMENT_SHARE_BOUNDS`], where `E_env` is `pi` times its mean luminance (the irradiance
//! it gives a surface open to the whole sky) and `E_tree` the sum of the `E` of the tree's root
//! children at the point (everything when the tree is empty or gives nothing there). The
//! bounds keep either side sampled however wrong the estimate is (neither counts occlusion):
//! a lamp under a bright sky, the sky in a lamp's shadow. The tree's choices are then scaled
//! by the rest. Without an environment nothing changes.
//!
//! The choice descends the tree from the root, one child per level, weighing a node's children
//! once: at most `BRANCHING` (16) BSDF evaluations per level, all of a node's children in SIMD
//! lanes, 4, 8 or 16 at a time (the crate's `light::child_weights`). Every choice is a deterministic
//! function of the point, so [`LightSampler::sample_li`] and [`LightSampler::pdf_li`] agree
//! exactly, which MIS needs.

use super::child_weights::{BsdfWeight, TreeLanes, Weights};
use super::emitter::{Emitter, Emitters, SurfaceMesh};
use super::environment::Environment;
use super::tree::{LightTree, Node};
use super::{Light, LightSample, Receiver, Visibility};
use crate::bsdf::Bsdf;
use crate::geometry::SurfaceHit;
use crate::material::Material;
use crate::sampling::ONE_MINUS_EPSILON;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::ops::Range;

/// The least and the most of the light choice the environment gets when the scene has other
/// lights too (see the module documentation): the defensive share either way.
pub const ENVIRONMENT_SHARE_BOUNDS: (f32, f32) = (DEFENSIVE_SHARE, 1.0 - DEFENSIVE_SHARE);

/// Share of the light choice made by irradiance alone when it is BSDF-aware (defensive
/// sampling, see the module documentation).
const DEFENSIVE_SHARE: f32 = 0.01;

/// [`DEFENSIVE_SHARE`] at a transmissive BSDF ([`Bsdf::transmits`]): its `F` leaves out the
/// transmission (see [`crate::bsdf::LuminanceEval`]), so a light behind it, a point light
/// especially (which BSDF sampling never hits), is reached through this share alone.
const TRANSMISSIVE_DEFENSIVE_SHARE: f32 = 0.1;

/// The defensive share of the choice at a receiver with BSDF `bsdf`.
#[inline]
fn defensive_share(bsdf: &Bsdf) -> f32 {
    if bsdf.transmits() {
        TRANSMISSIVE_DEFENSIVE_SHARE
    } else {
        DEFENSIVE_SHARE
    }
}

/// Chooses an emitter and a sample on it for next-event estimation (see the module
/// documentation). Built once per scene, with the scene.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    emitters: Emitters,
    tree: LightTree,
    /// The tree's sibling sets in lanes, for the weights.
    lanes: TreeLanes,
    /// The environment light, if any: one more choice beside the tree.
    environment: Option<Environment>,
}

/// What [`LightSampler`]'s choice chose.
enum Choice {
    /// The environment, with this probability.
    Environment(f32),
    /// Emitter `.0` with probability `.1`, and `u` rescaled within it (`.2`).
    Emitter(usize, f32, f32),
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
/// probability `share` (the [`defensive_share`]; all of it when every `E F` is 0), else by
/// `E F`.
fn mixture_pmf(e: f32, ef: f32, e_sum: f32, ef_sum: f32, share: f32) -> f32 {
    if !mixture_valid(e_sum, ef_sum) {
        0.0
    } else if ef_sum > 0.0 {
        share * e / e_sum + (1.0 - share) * ef / ef_sum
    } else {
        e / e_sum
    }
}

/// Chooses an item by [`mixture_pmf`] with `u`: `(index, u rescaled within it)`.
fn choose_mixture(
    e_w: &[f32],
    ef_w: &[f32],
    e_sum: f32,
    ef_sum: f32,
    u: f32,
    share: f32,
) -> Option<(usize, f32)> {
    if !mixture_valid(e_sum, ef_sum) {
        return None;
    }
    let share = if ef_sum > 0.0 { share } else { 1.0 };
    if u < share {
        choose_in(e_w.iter().copied(), e_sum, u / share)
    } else {
        choose_in(ef_w.iter().copied(), ef_sum, (u - share) / (1.0 - share))
    }
}

impl LightSampler {
    /// Builds the emitters of `lights` and of the emissive triangles of `mesh`, and the light
    /// tree over them; `scene_radius` is the radius of the scene's bounding sphere (a
    /// directional light's power is its irradiance over that disc).
    pub fn new(lights: &[Light], mesh: SurfaceMesh<'_>, scene_radius: f32) -> Self {
        let emitters = Emitters::build(lights, mesh);
        let tree = LightTree::build(&emitters.bounds(scene_radius));
        let lanes = TreeLanes::build(&tree, &emitters);
        Self {
            emitters,
            tree,
            lanes,
            environment: None,
        }
    }

    /// Sets (or removes) the environment light; the emitters and the tree stay as they are.
    pub fn set_environment(&mut self, environment: Option<Environment>) {
        self.environment = environment;
    }

    /// The environment light, if any.
    #[inline]
    pub fn environment(&self) -> Option<&Environment> {
        self.environment.as_ref()
    }

    /// The probability that the choice at the receiver is the environment: 0 without one (see
    /// the module documentation).
    #[inline]
    fn environment_share(&self, rx: &Receiver) -> f32 {
        if self.environment.is_none() {
            return 0.0;
        }
        let e_tree = if self.emitters.is_empty() {
            0.0
        } else {
            self.weights(rx, &BsdfWeight::new(rx), self.tree.root()).2
        };
        self.environment_share_given(e_tree)
    }

    /// [`LightSampler::environment_share`] given `e_tree`, the sum of the `E` of the tree's
    /// root children at the point (0 when the tree is empty).
    #[inline]
    fn environment_share_given(&self, e_tree: f32) -> f32 {
        let Some(env) = &self.environment else {
            return 0.0;
        };
        let e_env = PI * env.mean_luminance();
        if !(e_env > 0.0 && e_env.is_finite()) {
            return 0.0;
        }
        if !(e_tree > 0.0 && e_tree.is_finite()) {
            return 1.0;
        }
        let (lo, hi) = ENVIRONMENT_SHARE_BOUNDS;
        (e_env / (e_env + e_tree)).clamp(lo, hi)
    }

    /// The density (choice included) with which [`LightSampler::sample_li`] at the receiver
    /// returns direction `wi` toward the environment; 0 without one.
    pub fn pdf_environment(&self, rx: &Receiver, wi: Vec3) -> f32 {
        match &self.environment {
            Some(env) => {
                let share = self.environment_share(rx);
                if share > 0.0 {
                    share * env.pdf(wi)
                } else {
                    0.0
                }
            }
            None => 0.0,
        }
    }

    /// The emitters (punctual lights first, then the emitter meshes).
    #[inline]
    pub fn emitters(&self) -> &Emitters {
        &self.emitters
    }

    /// The light tree over the emitters.
    #[inline]
    pub fn tree(&self) -> &LightTree {
        &self.tree
    }

    /// The weights `E_c` and `E_c F_c` of the nodes `nodes` (one node's children), with their
    /// sums, in SIMD lanes ([`super::child_weights`]).
    #[inline]
    fn weights(&self, rx: &Receiver, w: &BsdfWeight, nodes: Range<usize>) -> Weights {
        self.lanes.weights(rx, w, nodes)
    }

    /// Chooses an emitter for the receiver: `(emitter, probability, u rescaled within it)`.
    /// From the root down, a child of each node by the mixture of `E` and `E F`.
    #[inline]
    fn choose(&self, rx: &Receiver, u: f32) -> Option<Choice> {
        if self.environment.is_some() && self.emitters.is_empty() {
            let share = self.environment_share_given(0.0);
            return (share > 0.0).then_some(Choice::Environment(share));
        }
        let f = BsdfWeight::new(rx);
        let share = defensive_share(&rx.bsdf);
        let (mut nodes, mut u, mut pmf) = (self.tree.root(), u, 1.0f32);
        let mut at_root = self.environment.is_some();
        loop {
            let (e_w, ef_w, e_sum, ef_sum) = self.weights(rx, &f, nodes.clone());
            if at_root {
                // The environment first, from the root's weights.
                at_root = false;
                let env = self.environment_share_given(e_sum);
                if u < env {
                    return Some(Choice::Environment(env));
                }
                u = ((u - env) / (1.0 - env)).min(ONE_MINUS_EPSILON);
                pmf = 1.0 - env;
            }
            let n = nodes.len();
            let (c, u_c) = choose_mixture(&e_w[..n], &ef_w[..n], e_sum, ef_sum, u, share)?;
            pmf *= mixture_pmf(e_w[c], ef_w[c], e_sum, ef_sum, share);
            u = u_c;
            match self.tree.nodes()[nodes.start + c] {
                Node::Emitter(e) => {
                    return (pmf > 0.0).then_some(Choice::Emitter(e as usize, pmf, u));
                }
                Node::Group(g) => nodes = g.children(),
            }
        }
    }

    /// The probability that [`LightSampler::sample_li`] at the receiver chooses emitter `e`:
    /// the product of the choices on the way from the root to it.
    pub fn emitter_pmf(&self, rx: &Receiver, e: usize) -> f32 {
        let Some(mut node) = self.tree.node_of_emitter(e) else {
            return 0.0;
        };
        let f = BsdfWeight::new(rx);
        let share = defensive_share(&rx.bsdf);
        let mut pmf = 1.0f32;
        loop {
            let siblings = self.tree.siblings(node);
            let slot = node - siblings.start;
            let (e_w, ef_w, e_sum, ef_sum) = self.weights(rx, &f, siblings);
            pmf *= mixture_pmf(e_w[slot], ef_w[slot], e_sum, ef_sum, share);
            match self.tree.parent(node) {
                Some(parent) if pmf > 0.0 => node = parent,
                // At the root: what the environment leaves (its share from the same weights).
                None if self.environment.is_some() => {
                    return pmf * (1.0 - self.environment_share_given(e_sum));
                }
                _ => return pmf,
            }
        }
    }

    /// Chooses an emitter (or the environment) with `u_light` and samples it with `u` (see the
    /// module documentation); `materials` and `textures` are the scene's, for the emission of
    /// an area sample. The returned `pdf` includes the probability of the choice; `None` when
    /// nothing was sampled. An environment sample is a direction: `dist` is infinite, and its
    /// shadow ray must escape the scene.
    pub fn sample_li(
        &self,
        materials: &[Material],
        textures: &[Texture],
        rx: &Receiver,
        u_light: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let (e, pmf, reused) = match self.choose(rx, u_light)? {
            Choice::Environment(share) => {
                let (wi, li, pdf) = self.environment.as_ref()?.sample(u)?;
                return Some(LightSample {
                    wi,
                    dist: f32::INFINITY,
                    li,
                    pdf: pdf * share,
                    delta: false,
                    visibility: Visibility::ShadowRay,
                });
            }
            Choice::Emitter(e, pmf, reused) => (e, pmf, reused),
        };
        let mut ls = match self.emitters.get(e) {
            Emitter::Punctual(light) => light.sample_li(rx.p)?,
            Emitter::Mesh(m) => m.sample_li(materials, textures, e as u32, rx.p, reused, u)?,
        };
        ls.pdf *= pmf;
        Some(ls)
    }

    /// The density (choice included) with which [`LightSampler::sample_li`] at the receiver
    /// returns the direction toward `hit`, a point on an emissive triangle; 0 if `hit` is not on
    /// an emitter.
    pub fn pdf_li(&self, rx: &Receiver, hit: &SurfaceHit) -> f32 {
        let Some((e, k)) = self.emitters.emitter_of(hit.triangle) else {
            return 0.0;
        };
        let Emitter::Mesh(m) = self.emitters.get(e) else {
            return 0.0;
        };
        self.emitter_pmf(rx, e) * m.pdf_li(rx.p, k, hit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Diffuse, Ggx};
    use crate::light::test_scenes::{
        check_tree, cone_emitter, estimate_irradiance, lamp_scene, normal, polygon_irradiance,
        receiver, vertices,
    };
    use crate::light::BRANCHING;
    use crate::material::Material;
    use crate::scene::{Scene, SceneParts, TriangleMesh};
    use glam::Vec3;
    use streaks_image::luminance;

    #[test]
    fn cone_sampling_of_a_sphere_lamp_gives_its_exact_irradiance() {
        let centre = Vec3::new(0.5, 2.0, -3.0);
        let s = lamp_scene(centre, 1.0, vec![]);
        let p = Vec3::new(0.0, 0.0, 0.0);
        // Exact: the sum over the sphere triangles that face p (a convex polyhedron: they tile
        // its silhouette once).
        let mut exact = 0.0f64;
        for (t, &m) in s.mesh.triangle_materials.iter().enumerate() {
            if m == 1 {
                let v = vertices(&s, t);
                if normal(&s, t).dot(p - v[0]) > 0.0 {
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
            Bsdf::Diffuse(Diffuse {
                kd: Vec3::splat(0.5),
            }),
            Bsdf::Ggx(Ggx {
                kd: Vec3::splat(0.05),
                ks: Vec3::splat(0.5),
                alpha: 0.1,
            }),
        ] {
            let rx = receiver(p, bsdf, Vec3::new(0.0, 1.0, 6.0));
            let est = estimate_irradiance(&s, &rx, 256);
            assert!(
                (est - exact).abs() < 5e-3 * exact,
                "{bsdf:?}: {est} vs {exact}"
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
        let ls = &s.light_sampler;
        let n_e = ls.emitters().len();
        assert_eq!(n_e, 6);
        let glossy = Bsdf::Ggx(Ggx {
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
            let pmfs: Vec<f32> = (0..n_e).map(|e| ls.emitter_pmf(&rx, e)).collect();
            let total: f32 = pmfs.iter().sum();
            assert!((total - 1.0).abs() < 1e-5, "{pmfs:?}");
            // The spot (emitter 1) lights its cone only, which holds the second point only.
            assert_eq!(pmfs[1] == 0.0, favoured == 3, "{pmfs:?}");
            // The lamp whose streak this is gets all the samples but about the defensive
            // share: a shadow ray sent elsewhere is one the streak pixel wastes (with a 10 %
            // share this was 0.936 and 0.970).
            let favoured = if favoured == 3 {
                cone_emitter(ls)
            } else {
                favoured
            };
            assert!(pmfs[favoured] > 0.99, "{favoured} {pmfs:?}");
            // Sampling frequencies follow the pmf.
            let n = 20_000;
            let mut counts = vec![0usize; n_e];
            for k in 0..n {
                let u = (k as f32 + 0.5) / n as f32;
                let Some(Choice::Emitter(e, pmf, reused)) = ls.choose(&rx, u) else {
                    panic!("no emitter chosen")
                };
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
            if let Emitter::Mesh(m) = ls.emitters().get(e) {
                if m.is_flat_one_sided() && m.centre().x > 0.0 {
                    assert_eq!(ls.emitter_pmf(&above, e), 0.0);
                }
            }
        }
    }

    /// A light behind the surface has no `F`, so only the defensive share reaches it: 1 % of
    /// the choice at an opaque BSDF (it cannot light the point), 10 % at a transmissive one,
    /// whose transmission `F` leaves out and which BSDF sampling cannot carry to a point light.
    #[test]
    fn a_light_behind_a_transmissive_surface_keeps_the_larger_defensive_share() {
        let lights = vec![
            Light::Point {
                position: Vec3::new(0.0, 3.0, -6.0),
                intensity: Vec3::splat(40.0),
                range: None,
            },
            Light::Point {
                position: Vec3::new(0.5, -2.0, 0.5),
                intensity: Vec3::splat(40.0),
                range: None,
            },
        ];
        let s = lamp_scene(Vec3::new(-3.0, 2.0, -10.0), 50.0, lights);
        let ls = &s.light_sampler;
        let p = Vec3::new(0.0, 0.5, 0.0);
        let wo = Vec3::new(0.0, 2.5, 6.0);
        let opaque = Bsdf::Ggx(Ggx {
            kd: Vec3::splat(0.02),
            ks: Vec3::splat(0.6),
            alpha: 0.05,
        });
        let pane = Bsdf::GltfPbr(crate::bsdf::GltfPbr {
            transmission: 1.0,
            thin_walled: true,
            roughness: 0.05,
            ..Default::default()
        });
        assert!(!opaque.transmits() && pane.transmits());
        let behind = |bsdf| ls.emitter_pmf(&receiver(p, bsdf, wo), 1);
        let (at_opaque, at_pane) = (behind(opaque), behind(pane));
        assert!(at_opaque > 0.0 && at_opaque < 0.01, "{at_opaque}");
        assert!(
            (at_pane / at_opaque - 10.0).abs() < 1e-3,
            "{at_pane} {at_opaque}"
        );
        for bsdf in [opaque, pane] {
            check_choice(ls, &receiver(p, bsdf, wo));
        }
    }

    /// Whether emitter `e` lights `p`, by the emitter's own light (not the choice's lanes):
    /// a punctual light's sample, a mesh's irradiance-like weight.
    fn lights_point(ls: &LightSampler, e: usize, p: Vec3) -> bool {
        match ls.emitters().get(e) {
            Emitter::Mesh(m) => m.irradiance(p) > 0.0,
            Emitter::Punctual(light) => light.sample_li(p).is_some_and(|s| luminance(s.li) > 0.0),
        }
    }

    /// Checks that the choice at `rx` is a distribution over exactly the emitters that light
    /// it, that `choose` returns `emitter_pmf`'s probabilities, and that its frequencies follow
    /// them.
    fn check_choice(ls: &LightSampler, rx: &Receiver) {
        let n_e = ls.emitters().len();
        let pmfs: Vec<f32> = (0..n_e).map(|e| ls.emitter_pmf(rx, e)).collect();
        assert!((pmfs.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{pmfs:?}");
        for (e, pmf) in pmfs.iter().enumerate() {
            assert_eq!(*pmf > 0.0, lights_point(ls, e, rx.p), "{e}");
        }
        let n = 40_000;
        let mut counts = vec![0usize; n_e];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let Some(Choice::Emitter(e, pmf, reused)) = ls.choose(rx, u) else {
                panic!("no emitter chosen")
            };
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
        let ls = &s.light_sampler;
        let n_e = ls.emitters().len();
        assert_eq!(n_e, 43);
        assert_eq!(check_tree(ls.tree(), n_e), 2);

        let glossy = Bsdf::Ggx(Ggx {
            kd: Vec3::splat(0.3),
            ks: Vec3::splat(0.6),
            alpha: 0.1,
        });
        let p = Vec3::new(0.5, 0.0, -4.0);
        let rx = receiver(p, glossy, Vec3::new(0.0, 1.5, 0.0) - p);
        check_choice(ls, &rx);
        // A point in the fog sees every light, below it too, and chooses by irradiance alone.
        check_choice(ls, &Receiver::in_medium(p));
        check_choice(ls, &Receiver::in_medium(Vec3::new(0.5, 6.0, -4.0)));

        // Unbiased: f * L * cos / pdf over many choices against the exact sum over the lights.
        let diffuse = Bsdf::Diffuse(Diffuse { kd: Vec3::ONE });
        let rx = receiver(p, diffuse, Vec3::Y);
        let exact: f64 = lights
            .iter()
            .map(|l| {
                let ls = l.sample_li(p).unwrap();
                f64::from(luminance(ls.li) * ls.wi.y.max(0.0))
            })
            .sum();
        let mut rng = crate::sampling::Pcg32::new(9, 2);
        let m = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..m {
            let u = (rng.next_f32(), rng.next_2d());
            if let Some(sample) = ls.sample_li(&s.materials, &s.textures, &rx, u.0, u.1) {
                if sample.delta {
                    sum += f64::from(luminance(sample.li) * sample.wi.y.max(0.0) / sample.pdf);
                }
            }
        }
        let est = sum / m as f64;
        assert!((est / exact - 1.0).abs() < 0.01, "{est} vs {exact}");
    }

    /// 40 point lights along a street, 2-5 m high over 23 m, of seven intensities (1 to 61),
    /// the weakest every seventh: more than [`BRANCHING`], so a two-level tree of groups.
    fn street_lights() -> Vec<Light> {
        (0..40)
            .map(|i| {
                let f = i as f32;
                Light::Point {
                    position: Vec3::new(
                        (f * 2.3) % 17.0 - 8.0,
                        2.0 + (f * 0.7) % 3.0,
                        -2.0 - (f * 1.9) % 23.0,
                    ),
                    intensity: Vec3::splat(1.0 + 10.0 * (i % 7) as f32),
                    range: None,
                }
            })
            .collect()
    }

    /// A sharp glossy lobe (a window pane) that mirrors a weak point light of a group whose
    /// most powerful member lies elsewhere still sends most of its shadow rays to that light:
    /// the group's weight holds the lobe's mean over the group's cone, not only its value
    /// toward the group's anchor (which is nearly zero for so sharp a lobe).
    #[test]
    fn a_sharp_lobe_finds_a_weak_light_in_a_group() {
        let lights = street_lights();
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, lights.clone());
        let ls = &s.light_sampler;
        assert_eq!(check_tree(ls.tree(), ls.emitters().len()), 2);
        let glass = Bsdf::Ggx(Ggx {
            kd: Vec3::ZERO,
            ks: Vec3::splat(0.04),
            alpha: 0.02,
        });
        // Every weakest light (intensity 1), each seen in the pane by its mirror direction.
        let mut pmfs = Vec::new();
        for (e, light) in lights.iter().enumerate().filter(|(i, _)| i % 7 == 0) {
            let Light::Point { position, .. } = *light else {
                unreachable!()
            };
            let p = Vec3::new(position.x + 0.7, 0.0, position.z + 6.0);
            let to_light = (position - p).normalize();
            let rx = receiver(p, glass, Vec3::new(-to_light.x, to_light.y, -to_light.z));
            let pmf = ls.emitter_pmf(&rx, e);
            assert!(pmf > 0.2, "light {e}: {pmf}");
            check_choice(ls, &rx);
            pmfs.push(pmf);
        }
        // Weighed toward each group's anchor, these were 0.81, 0.07, 0.04, 0.21, 0.007, 0.10.
        assert_eq!(pmfs.len(), 6);
        assert!(pmfs.iter().filter(|&&p| p > 0.6).count() >= 5, "{pmfs:?}");
    }

    /// A lobe not much narrower than a group's cone is weighed toward the group's anchor
    /// alone, whether or not the cone holds its mirror direction: the anchor then lies in the
    /// lobe, and the lobe's mean over the cone would put the group's lights where the lobe
    /// peaks. (On `rainy_street` that mean, given to every cone holding a rough lens's mirror
    /// direction, took shadow rays from the bulb 0.1 m away, which gives nearly all of the
    /// lens's light: its choice fell from 0.68 to 0.28.) A sharp lobe's groups still get it.
    #[test]
    fn only_a_lobe_much_narrower_than_a_cone_looks_past_the_anchor() {
        let lights = street_lights();
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, lights);
        let ls = &s.light_sampler;
        let lobe = |alpha| {
            Bsdf::Ggx(Ggx {
                kd: Vec3::ZERO,
                ks: Vec3::splat(0.04),
                alpha,
            })
        };
        let (mut anchored, mut raised) = ([0usize; 2], [0usize; 2]);
        for (k, alpha) in [1.0, 0.02].into_iter().enumerate() {
            for i in 0..200 {
                let f = i as f32;
                let p = Vec3::new((f * 1.3) % 9.0 - 4.0, 0.0, -(f * 0.9) % 20.0);
                let wo = Vec3::new((f * 0.37) % 1.0 - 0.5, 0.05 + (f * 0.13) % 1.0, 1.0);
                let rx = receiver(p, lobe(alpha), wo);
                let w = BsdfWeight::new(&rx);
                let f_at = rx.bsdf.luminance_at(rx.wo_local);
                let root = ls.tree().root();
                let (e_w, ef_w, _, _) = ls.weights(&rx, &w, root.clone());
                for (c, node) in ls.tree().nodes()[root].iter().enumerate() {
                    let Node::Group(g) = node else { continue };
                    if e_w[c] <= 0.0 {
                        continue;
                    }
                    let wi = rx.frame.to_local((g.anchor - p).normalize());
                    let toward_anchor = if wi.z > 0.0 {
                        f_at.eval(wi) * wi.z
                    } else {
                        0.0
                    };
                    let f = ef_w[c] / e_w[c];
                    if (f - toward_anchor).abs() <= 1e-4 * toward_anchor.max(1e-6) {
                        anchored[k] += 1;
                    } else {
                        assert!(
                            f > toward_anchor,
                            "alpha {alpha}, {p}: {f} < {toward_anchor}"
                        );
                        raised[k] += 1;
                    }
                }
            }
        }
        assert_eq!(
            raised[0], 0,
            "alpha 1: {anchored:?} anchored, {raised:?} raised"
        );
        assert!(
            raised[1] > 20,
            "alpha 0.02: {anchored:?} anchored, {raised:?} raised"
        );
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
        let ls = &s.light_sampler;
        assert!(check_tree(ls.tree(), ls.emitters().len()) >= 3);
        let glossy = Bsdf::Ggx(Ggx {
            kd: Vec3::splat(0.3),
            ks: Vec3::splat(0.6),
            alpha: 0.1,
        });
        let p = Vec3::new(0.5, 0.0, -4.0);
        check_choice(ls, &receiver(p, glossy, Vec3::new(2.0, 1.5, -1.0) - p));
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
        let ls = &s.light_sampler;
        assert_eq!(check_tree(ls.tree(), ls.emitters().len()), 3);
        let rx = receiver(
            Vec3::ZERO,
            Bsdf::Diffuse(Diffuse { kd: Vec3::ONE }),
            Vec3::Y,
        );
        let total: f32 = (0..ls.emitters().len())
            .map(|e| ls.emitter_pmf(&rx, e))
            .sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
    }

    #[test]
    fn no_lights_no_samples() {
        let s = Scene::from_parts(SceneParts {
            source: "dark".into(),
            mesh: TriangleMesh {
                positions: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
                triangles: vec![[0, 2, 1]],
                triangle_materials: vec![0],
                ..TriangleMesh::default()
            },
            materials: vec![Material::diffuse("floor", Vec3::splat(0.5))],
            ..SceneParts::default()
        })
        .unwrap();
        assert!(s.light_sampler.emitters().is_empty());
        let rx = receiver(
            Vec3::ZERO,
            Bsdf::Diffuse(Diffuse { kd: Vec3::ONE }),
            Vec3::Y,
        );
        // Without its default environment (a scene without lights gets one), nothing.
        let mut ls = s.light_sampler.clone();
        assert!(ls.environment().is_some());
        ls.set_environment(None);
        let sample = ls.sample_li(&s.materials, &s.textures, &rx, 0.5, Vec2::splat(0.5));
        assert!(sample.is_none());
        assert_eq!(ls.emitter_pmf(&rx, 0), 0.0);
    }

    /// With an environment, the choice is a distribution over the emitters and the
    /// environment: the emitters' probabilities and the environment's share sum to 1, an
    /// environment sample's density is `pdf_environment` of its direction, and its share
    /// follows the estimate `pi L / (pi L + E_tree)` within the bounds.
    #[test]
    fn the_environment_is_one_more_choice() {
        use crate::light::Environment;
        let mut s = lamp_scene(Vec3::new(-3.0, 2.0, -10.0), 50.0, vec![]);
        let rx = receiver(
            Vec3::ZERO,
            Bsdf::Diffuse(Diffuse {
                kd: Vec3::splat(0.5),
            }),
            Vec3::Y,
        );
        for radiance in [1e-3f32, 0.3, 1e3] {
            s.set_environment(Environment::constant(Vec3::splat(radiance), 1.0).unwrap());
            let ls = &s.light_sampler;
            let share = ls.environment_share(&rx);
            let (lo, hi) = ENVIRONMENT_SHARE_BOUNDS;
            assert!((lo..=hi).contains(&share), "{share}");
            let emitters: f32 = (0..ls.emitters().len())
                .map(|e| ls.emitter_pmf(&rx, e))
                .sum();
            assert!(
                (emitters + share - 1.0).abs() < 1e-5,
                "{emitters} + {share}"
            );
            let n = 4000;
            let mut env_samples = 0;
            for k in 0..n {
                let u_light = (k as f32 + 0.5) / n as f32;
                let u = Vec2::new((k as f32 * 0.618_034).fract(), 0.3);
                if let Some(l) = ls.sample_li(&s.materials, &s.textures, &rx, u_light, u) {
                    if l.dist == f32::INFINITY {
                        env_samples += 1;
                        assert_eq!(l.pdf, ls.pdf_environment(&rx, l.wi));
                        assert!((l.pdf - share / (4.0 * PI)).abs() < 1e-6 * l.pdf.max(1.0));
                        assert_eq!(l.visibility, Visibility::ShadowRay);
                    }
                }
            }
            assert!(
                (env_samples as f32 / n as f32 - share).abs() < 2e-3,
                "{env_samples}"
            );
        }
        // A brighter sky takes a larger share.
        let share_of = |s: &mut Scene, l: f32| {
            s.set_environment(Environment::constant(Vec3::splat(l), 1.0).unwrap());
            s.light_sampler.environment_share(&rx)
        };
        assert!(share_of(&mut s, 0.01) < share_of(&mut s, 0.1));
        // Alone, the environment is the whole choice.
        let mut parts = SceneParts {
            materials: vec![Material::diffuse("floor", Vec3::splat(0.5))],
            ..Default::default()
        };
        parts.mesh.positions = vec![Vec3::ZERO, Vec3::X, Vec3::Z];
        parts.mesh.triangles = vec![[0, 2, 1]];
        parts.mesh.triangle_materials = vec![0];
        let alone = Scene::from_parts(parts).unwrap();
        assert_eq!(alone.light_sampler.environment_share(&rx), 1.0);
    }
}
