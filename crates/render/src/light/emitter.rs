//! Emitters: what the light choice chooses between. A punctual light is an emitter of its own;
//! emissive triangles are grouped into emitter meshes, the connected pieces (shared vertex
//! positions) of each emissive material: a lamp's bulb, a lens, a window.
//!
//! [`Emitters::build`] makes the list once, when the scene is built. The same list is the
//! scene's lamps for everyone: the renderer samples it, and `rig.json` records it for the
//! analysis.
//!
//! An emissive triangle is an area light of radiance `emission` (times its texture), one-sided
//! (the front face, by the triangle's winding) unless its material is double-sided. A
//! triangle of a material that is not opaque emits where rays stop on it: light samples carry
//! `emission x stop probability` (zero in a masked-out hole, alpha on a `BLEND` surface,
//! [`crate::material::Alpha::stop_probability`]), which is what the rays that hit it find on
//! average. The power that chooses between triangles ignores alpha. An emitter
//! mesh is sampled one of two ways:
//!
//! - a compact mesh (area at least [`COMPACT_AREA_RATIO`]` pi r^2` for bounding radius `r`, a
//!   tessellated sphere lamp) seen from outside its bounding sphere: uniformly in the cone of
//!   directions that bounds it ([`Visibility::FirstHit`]: no sample is wasted on the back of
//!   the sphere);
//! - other meshes, or points inside the bounding sphere: a triangle chosen by power, then a
//!   point on it uniformly by area, the density converted to solid angle,
//!   `pdf = d^2 / (|cos theta_light| A)`.

use super::{Light, LightSample, Visibility};
use crate::geometry::{Frame, SurfaceHit, VertexAttributes};
use crate::material::Material;
use crate::sampling::{
    square_to_uniform_cone, square_to_uniform_cone_pdf, square_to_uniform_triangle,
    DiscreteDistribution,
};
use crate::texture::Texture;
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;
use std::f32::consts::PI;
use streaks_image::luminance;

/// An emitter mesh is sampled by its bounding cone when its area is at least this many times
/// `pi r^2` (r: its bounding radius): a closed, roughly round shape (a tessellated sphere has
/// about 4) fills its cone; a flat lens (at most 1) would waste most cone samples.
pub const COMPACT_AREA_RATIO: f32 = 2.0;

/// The triangles of a scene with their materials, as the emitters are built from them.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceMesh<'a> {
    /// World-space vertex positions.
    pub positions: &'a [Vec3],
    /// Texture coordinates, one per vertex.
    pub uvs: &'a [Vec2],
    /// The second texture coordinate set, one per vertex, or empty (`uvs` is read instead).
    pub uvs1: &'a [Vec2],
    /// Vertex colours, one per vertex, or empty (white).
    pub colors: &'a [Vec4],
    /// Vertex indices of each triangle.
    pub triangles: &'a [[u32; 3]],
    /// Material index of each triangle.
    pub triangle_materials: &'a [u32],
    /// The materials.
    pub materials: &'a [Material],
}

impl SurfaceMesh<'_> {
    /// Vertex positions of triangle `t`.
    #[inline]
    fn vertices(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|v| self.positions[v as usize])
    }

    /// The attributes of vertex `v`.
    #[inline]
    pub fn vertex_attributes(&self, v: usize) -> VertexAttributes {
        let uv = self.uvs[v];
        VertexAttributes {
            uv: [uv, self.uvs1.get(v).copied().unwrap_or(uv)],
            color: self.colors.get(v).copied().unwrap_or(Vec4::ONE),
        }
    }

    /// The attributes of triangle `t` at barycentrics `b` (the weights of its second and
    /// third vertices), interpolated linearly.
    #[inline]
    pub fn attributes_at(&self, t: usize, b: Vec2) -> VertexAttributes {
        let [i0, i1, i2] = self.triangles[t].map(|v| v as usize);
        let b0 = 1.0 - b.x - b.y;
        let uv0 = self.uvs[i0] * b0 + self.uvs[i1] * b.x + self.uvs[i2] * b.y;
        let uv1 = if self.uvs1.is_empty() {
            uv0
        } else {
            self.uvs1[i0] * b0 + self.uvs1[i1] * b.x + self.uvs1[i2] * b.y
        };
        let color = if self.colors.is_empty() {
            Vec4::ONE
        } else {
            self.colors[i0] * b0 + self.colors[i1] * b.x + self.colors[i2] * b.y
        };
        VertexAttributes {
            uv: [uv0, uv1],
            color,
        }
    }
}

/// One emissive triangle of an emitter mesh, with what sampling it needs.
#[derive(Clone, Copy, Debug, PartialEq)]
struct EmitterTriangle {
    /// Vertex positions.
    v: [Vec3; 3],
    /// Vertex attributes (texture coordinates, colour).
    attributes: [VertexAttributes; 3],
    /// Unit geometric normal from the winding.
    n: Vec3,
    /// Area.
    area: f32,
}

impl EmitterTriangle {
    fn new(v: [Vec3; 3], attributes: [VertexAttributes; 3]) -> Self {
        let cross = (v[1] - v[0]).cross(v[2] - v[0]);
        let len = cross.length();
        Self {
            v,
            attributes,
            n: cross / len,
            area: 0.5 * len,
        }
    }

    /// A point on the triangle, uniform by area, seen from `p`: `None` from behind a
    /// one-sided emitter, edge-on, or where the emission is black.
    #[inline]
    fn sample_li(
        &self,
        material: &Material,
        textures: &[Texture],
        p: Vec3,
        u: Vec2,
    ) -> Option<LightSample> {
        let b = square_to_uniform_triangle(u);
        let b0 = 1.0 - b.x - b.y;
        let q = b0 * self.v[0] + b.x * self.v[1] + b.y * self.v[2];
        let d = q - p;
        let dist2 = d.length_squared();
        let dist = dist2.sqrt();
        if self.area <= 0.0 || dist <= 0.0 {
            return None;
        }
        let wi = d / dist;
        let cos_light = -self.n.dot(wi);
        if cos_light.abs() < 1e-7 || (!material.double_sided && cos_light <= 0.0) {
            return None;
        }
        let [a0, a1, a2] = &self.attributes;
        let at = VertexAttributes {
            uv: [0, 1].map(|k| b0 * a0.uv[k] + b.x * a1.uv[k] + b.y * a2.uv[k]),
            color: b0 * a0.color + b.x * a1.color + b.y * a2.color,
        };
        let mut li = material.emission_at(&at, textures);
        if !material.alpha.is_opaque() {
            li *= material.alpha.stop_probability(&at, textures);
        }
        let pdf = dist2 / (cos_light.abs() * self.area);
        (pdf.is_finite() && li.max_element() > 0.0).then_some(LightSample {
            wi,
            dist,
            li,
            pdf,
            delta: false,
            visibility: Visibility::ShadowRay,
        })
    }

    /// The solid-angle density with which [`EmitterTriangle::sample_li`] from `p` returns the
    /// direction toward `hit`, a point on this triangle.
    #[inline]
    fn pdf_li(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        let d = hit.p - p;
        let dist2 = d.length_squared();
        let cos_light = hit.ng.dot(d).abs() / dist2.sqrt();
        if self.area <= 0.0 || cos_light <= 0.0 {
            return 0.0;
        }
        dist2 / (cos_light * self.area)
    }
}

/// Emissive triangles that share vertices and a material: a lamp's bulb, a lens, a window.
#[derive(Clone, Debug)]
pub struct MeshEmitter {
    /// Its triangles.
    triangles: Vec<EmitterTriangle>,
    /// The material they share.
    material: u32,
    /// Choice of triangle for area sampling, by power.
    distribution: DiscreteDistribution,
    /// Total power (luminance, W).
    power: f32,
    /// Total area (m^2).
    area: f32,
    /// Centre of its bounding sphere: the centre of its vertices' bounding box.
    centre: Vec3,
    /// Radius of its bounding sphere (slightly inflated, so the cone bounds every triangle).
    radius: f32,
    /// Whether it is sampled by its bounding cone from outside the bounding sphere.
    cone: bool,
    /// For a flat one-sided emitter: its plane `(n, n . v)`; points behind it get no light.
    front: Option<(Vec3, f32)>,
}

/// What the light choice chooses between.
#[derive(Clone, Debug)]
pub enum Emitter {
    /// A point, spot or directional light.
    Punctual(Light),
    /// Connected emissive triangles of one material.
    Mesh(MeshEmitter),
}

/// Where an emitter is, how big and how bright, as the light tree groups emitters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterBounds {
    /// Centre of its bounding sphere; `None` for a directional light.
    pub position: Option<Vec3>,
    /// Radius of its bounding sphere (0 for punctual lights).
    pub radius: f32,
    /// Power (luminance, W).
    pub power: f32,
    /// For a spot light, its beam: a group holding it weighs it by its intensity inside the
    /// beam rather than by its power spread over every direction.
    pub beam: Option<Beam>,
}

/// A spot light's beam, as the light tree bounds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beam {
    /// The unit direction it points along.
    pub axis: Vec3,
    /// The cosine of its outer cone's half-angle.
    pub cos_outer: f32,
    /// The luminance of its intensity (W/sr).
    pub intensity: f32,
}

/// The scene's emitters: its punctual lights (in file order), then its emitter meshes (in the
/// order of their first triangle), with the map from scene triangles to emitter meshes.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    list: Vec<Emitter>,
    /// For each scene triangle: `(emitter, index within the emitter)`, `u32::MAX` if none.
    emitter_of_triangle: Vec<(u32, u32)>,
}

/// Positive finite power, else 0.
#[inline]
pub(crate) fn clean_power(p: f32) -> f32 {
    if p.is_finite() {
        p.max(0.0)
    } else {
        0.0
    }
}

impl Emitters {
    /// Builds the emitters of `lights` and of the emissive triangles of `mesh`: every
    /// non-degenerate triangle of an emissive material belongs to the emitter mesh of its
    /// connected piece.
    pub fn build(lights: &[Light], mesh: SurfaceMesh<'_>) -> Self {
        let mut list: Vec<Emitter> = lights.iter().copied().map(Emitter::Punctual).collect();
        let mut emitter_of_triangle = vec![(u32::MAX, u32::MAX); mesh.triangles.len()];
        for group in group_emissive_triangles(mesh) {
            let Some(m) = MeshEmitter::new(mesh, &group) else {
                continue;
            };
            let e = list.len() as u32;
            for (k, &t) in group.iter().enumerate() {
                emitter_of_triangle[t as usize] = (e, k as u32);
            }
            list.push(Emitter::Mesh(m));
        }
        Self {
            list,
            emitter_of_triangle,
        }
    }

    /// The emitters.
    #[inline]
    pub fn list(&self) -> &[Emitter] {
        &self.list
    }

    /// Number of emitters.
    #[inline]
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether there are none.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Emitter `e`.
    #[inline]
    pub fn get(&self, e: usize) -> &Emitter {
        &self.list[e]
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

    /// Every emitter's bounds, for the light tree; `scene_radius` (of the scene's bounding
    /// sphere) gives a directional light its power.
    pub fn bounds(&self, scene_radius: f32) -> Vec<EmitterBounds> {
        self.list
            .iter()
            .map(|e| match e {
                Emitter::Mesh(m) => EmitterBounds {
                    position: Some(m.centre),
                    radius: m.radius,
                    power: m.power,
                    beam: None,
                },
                Emitter::Punctual(light) => EmitterBounds {
                    position: light.position(),
                    radius: 0.0,
                    power: clean_power(light.power(scene_radius)),
                    beam: match *light {
                        Light::Spot {
                            direction,
                            intensity,
                            cos_outer,
                            ..
                        } => Some(Beam {
                            axis: direction,
                            cos_outer,
                            intensity: clean_power(luminance(intensity)),
                        }),
                        _ => None,
                    },
                },
            })
            .collect()
    }
}

/// The non-degenerate triangles of emissive materials, grouped by material and shared vertex
/// positions (union-find), each group in triangle order, the groups in the order of their
/// first triangle.
fn group_emissive_triangles(mesh: SurfaceMesh<'_>) -> Vec<Vec<u32>> {
    let emissive: Vec<u32> = (0..mesh.triangles.len())
        .filter(|&t| {
            let [a, b, c] = mesh.vertices(t);
            mesh.materials[mesh.triangle_materials[t] as usize].is_emissive()
                && (b - a).cross(c - a) != Vec3::ZERO
        })
        .map(|t| t as u32)
        .collect();
    let mut parent: Vec<usize> = (0..emissive.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut first_at: HashMap<(u32, [u32; 3]), usize> = HashMap::new();
    for (k, &t) in emissive.iter().enumerate() {
        let material = mesh.triangle_materials[t as usize];
        for v in mesh.triangles[t as usize] {
            let key = (
                material,
                mesh.positions[v as usize].to_array().map(f32::to_bits),
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
    for (k, &t) in emissive.iter().enumerate() {
        let root = find(&mut parent, k);
        let g = *group_of_root.entry(root).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(t);
    }
    groups
}

impl MeshEmitter {
    /// Builds the emitter of the given emissive scene triangles (one material); `None` if
    /// none of them emits.
    fn new(mesh: SurfaceMesh<'_>, group: &[u32]) -> Option<Self> {
        let material_id = mesh.triangle_materials[group[0] as usize];
        let material = &mesh.materials[material_id as usize];
        let sides = if material.double_sided { 2.0 } else { 1.0 };
        let triangles: Vec<EmitterTriangle> = group
            .iter()
            .map(|&t| {
                let attributes =
                    mesh.triangles[t as usize].map(|v| mesh.vertex_attributes(v as usize));
                EmitterTriangle::new(mesh.vertices(t as usize), attributes)
            })
            .collect();
        let powers: Vec<f32> = triangles
            .iter()
            .map(|t| clean_power(sides * PI * t.area * luminance(material.emission)))
            .collect();
        let distribution = DiscreteDistribution::new(&powers)?;
        let (lo, hi) = triangles.iter().flat_map(|t| t.v).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(v), hi.max(v)),
        );
        let centre = 0.5 * (lo + hi);
        let radius = triangles
            .iter()
            .flat_map(|t| t.v)
            .map(|v| v.distance(centre))
            .fold(0.0f32, f32::max);
        // Inflate a little so that rounding never leaves a triangle outside the cone.
        let radius = radius * (1.0 + 1e-4) + 1e-6 * centre.abs().max_element();
        let area: f32 = triangles.iter().map(|t| t.area).sum();
        let n0 = triangles[0].n;
        let flat = triangles.iter().all(|t| {
            t.n.dot(n0) > 1.0 - 1e-5 && (t.v[0] - centre).dot(n0).abs() <= 1e-4 * radius.max(1e-6)
        });
        let front = (!material.double_sided && flat).then(|| (n0, n0.dot(centre)));
        Some(Self {
            triangles,
            material: material_id,
            distribution,
            power: powers.iter().sum(),
            area,
            centre,
            radius,
            cone: area >= COMPACT_AREA_RATIO * PI * radius * radius,
            front,
        })
    }

    /// Centre of its bounding sphere (the centre of its vertices' bounding box): where the
    /// light choice and `rig.json` place this lamp.
    #[inline]
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// Radius of its bounding sphere.
    #[inline]
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Total area (m^2).
    #[inline]
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Number of triangles.
    #[inline]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Index of its material in the scene.
    #[inline]
    pub fn material(&self) -> u32 {
        self.material
    }

    /// Total power (luminance of the flux, W): `pi A L` per emitting face.
    #[inline]
    pub fn power(&self) -> f32 {
        self.power
    }

    /// Whether it is sampled by its bounding cone (a compact mesh, see the module
    /// documentation) when seen from outside its bounding sphere.
    #[inline]
    pub fn samples_cone(&self) -> bool {
        self.cone
    }

    /// Whether it is flat and one-sided, so that points behind its plane get no light.
    #[inline]
    pub fn is_flat_one_sided(&self) -> bool {
        self.front.is_some()
    }

    /// For a flat one-sided emitter, its plane `(n, offset)`: a point `p` with
    /// `n . p <= offset` is behind it and gets no light.
    #[inline]
    pub(crate) fn front_plane(&self) -> Option<(Vec3, f32)> {
        self.front
    }

    /// The irradiance-like weight `power / (4 pi max(d, r)^2)`, zero behind a flat one-sided
    /// emitter: what the light choice's lanes compute for it (`super::lanes`), one at a time,
    /// for tests.
    #[cfg(test)]
    pub(crate) fn irradiance(&self, p: Vec3) -> f32 {
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

    /// The bounding cone seen from `p`, as its axis and `1 - cos` of its half-angle, when `p`
    /// is outside the bounding sphere and the emitter is sampled by its cone.
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

    /// A sample from `p` (see the module documentation); this emitter is number `emitter`,
    /// `u_tri` chooses the triangle for area sampling and `u` the point or direction.
    pub(crate) fn sample_li(
        &self,
        materials: &[Material],
        textures: &[Texture],
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
        let material = &materials[self.material as usize];
        let mut ls = self.triangles[k].sample_li(material, textures, p, u)?;
        ls.pdf *= pmf;
        Some(ls)
    }

    /// The density with which [`MeshEmitter::sample_li`] from `p` returns the direction to
    /// `hit`, a point on its triangle number `k`.
    pub(crate) fn pdf_li(&self, p: Vec3, k: usize, hit: &SurfaceHit) -> f32 {
        if let Some((_, one_minus_cos)) = self.cone_from(p) {
            return square_to_uniform_cone_pdf(Vec3::Z, one_minus_cos);
        }
        self.distribution.pmf(k) * self.triangles[k].pdf_li(p, hit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_scenes::{lamp_scene, normal, solid_angle, triangle_scene, vertices};
    use crate::scene::Scene;

    /// The emitter mesh number `e` of the scene.
    fn mesh(s: &Scene, e: usize) -> &MeshEmitter {
        match s.light_sampler.emitters().get(e) {
            Emitter::Mesh(m) => m,
            Emitter::Punctual(_) => panic!("emitter {e} is punctual"),
        }
    }

    /// A BLEND emitter's light samples carry emission x alpha (what the rays that hit it see
    /// on average), a MASK one's nothing in its holes and all of it elsewhere.
    #[test]
    fn light_samples_of_transparent_emitters_carry_their_coverage() {
        use crate::material::{Alpha, AlphaMode};
        let s = triangle_scene(false);
        for (mode, factor, want) in [
            (AlphaMode::Opaque, 0.3, 1.0),
            (AlphaMode::Blend, 0.3, 0.3),
            (AlphaMode::Mask { cutoff: 0.5 }, 0.3, 0.0),
            (AlphaMode::Mask { cutoff: 0.5 }, 0.6, 1.0),
        ] {
            let mut materials = s.materials.clone();
            materials[0].alpha = Alpha {
                mode,
                factor,
                texture: None,
            };
            let ls = mesh(&s, 0).sample_li(
                &materials,
                &s.textures,
                0,
                Vec3::ZERO,
                0.5,
                Vec2::splat(0.4),
            );
            let li = ls.map_or(Vec3::ZERO, |ls| ls.li);
            assert!(
                (li - Vec3::new(2.0, 1.0, 0.5) * want).length() < 1e-6,
                "{mode:?} {factor}: {li}"
            );
        }
    }

    #[test]
    fn triangle_sampling_density_matches_solid_angle_and_pdf_li() {
        let s = triangle_scene(false);
        assert_eq!(s.light_sampler.emitters().len(), 1);
        let m = mesh(&s, 0);
        assert!(!m.samples_cone() && m.triangle_count() == 1);
        let [a, b, c] = vertices(&s, 0);
        let p = Vec3::new(0.1, -0.2, -0.5);
        let omega = solid_angle(a - p, b - p, c - p);
        let sample = |s: &Scene, p: Vec3, u: Vec2| {
            let m = mesh(s, 0);
            m.sample_li(&s.materials, &s.textures, 0, p, 0.5, u)
        };
        // E[1 / pdf] over the sampled directions is the solid angle.
        let n = 64;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let ls = sample(&s, p, u).unwrap();
                assert!(!ls.delta && ls.visibility == Visibility::ShadowRay);
                assert_eq!(ls.li, Vec3::new(2.0, 1.0, 0.5));
                sum += 1.0 / ls.pdf as f64;
                // pdf_li at the sampled point agrees with the sample's pdf.
                let q = p + ls.wi * ls.dist;
                let hit = SurfaceHit {
                    t: ls.dist,
                    p: q,
                    ng: -Vec3::Z,
                    ns: -Vec3::Z,
                    mapped: None,
                    coat_normal: None,
                    attributes: VertexAttributes::from_uv(Vec2::ZERO),
                    triangle: 0,
                    material: 0,
                    object: crate::scene::UNLABELLED_OBJECT,
                };
                let pdf = m.pdf_li(p, 0, &hit);
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
        assert!(sample(&s, behind, Vec2::splat(0.3)).is_none());
        let s2 = triangle_scene(true);
        let ls = sample(&s2, behind, Vec2::splat(0.3));
        assert!(ls.is_some_and(|ls| ls.wi.z < 0.0));
    }

    #[test]
    fn emissive_triangles_are_grouped_into_emitters() {
        let point = Light::Point {
            position: Vec3::new(0.0, 5.0, 0.0),
            intensity: Vec3::splat(10.0),
            range: None,
        };
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, vec![point]);
        let emitters = s.light_sampler.emitters();
        // The point light, the sphere, two separate lenses.
        assert_eq!(emitters.len(), 4);
        assert!(matches!(emitters.get(0), Emitter::Punctual(l) if *l == point));
        let mut kinds: Vec<(usize, bool, bool)> = (1..4)
            .map(|e| {
                let m = mesh(&s, e);
                (m.triangle_count(), m.samples_cone(), m.is_flat_one_sided())
            })
            .collect();
        kinds.sort();
        assert_eq!(kinds[0], (2, false, true));
        assert_eq!(kinds[1], (2, false, true));
        assert!(kinds[2].0 > 300 && kinds[2].1 && !kinds[2].2, "{kinds:?}");
        // The lenses are centred on their quads, the sphere on its centre.
        let lenses: Vec<Vec3> = (1..4)
            .map(|e| mesh(&s, e))
            .filter(|m| m.triangle_count() == 2)
            .map(|m| m.centre())
            .collect();
        for c in [Vec3::new(4.0, 3.0, 0.0), Vec3::new(-4.0, 3.0, 0.0)] {
            assert!(lenses.iter().any(|l| l.distance(c) < 1e-5), "{lenses:?}");
        }
        // Every emissive triangle maps to a distinct slot of its emitter; nothing else maps.
        let mut slots = Vec::new();
        for (t, &material) in s.mesh.triangle_materials.iter().enumerate() {
            let found = emitters.emitter_of(t as u32);
            assert_eq!(found.is_some(), material != 0, "triangle {t}");
            if let Some((e, k)) = found {
                let m = mesh(&s, e);
                assert!(k < m.triangle_count() && m.material() == material);
                slots.push((e, k));
            }
        }
        let n = slots.len();
        slots.sort();
        slots.dedup();
        assert_eq!(slots.len(), n);
        assert_eq!(
            n,
            (1..4).map(|e| mesh(&s, e).triangle_count()).sum::<usize>()
        );
        assert_eq!(emitters.emitter_of(u32::MAX), None);
    }

    /// The cone samples that reach the sphere lamp cover exactly the solid angle of its
    /// silhouette: `E[1{hit} / pdf]` against the sum of the solid angles of the triangles that
    /// face the point (from afar, from close by, from just outside the bounding sphere).
    #[test]
    fn cone_samples_cover_the_lamp_silhouette_exactly() {
        let centre = Vec3::new(0.5, 2.0, -3.0);
        let s = lamp_scene(centre, 1.0, vec![]);
        let emitters = s.light_sampler.emitters();
        let e = crate::light::test_scenes::cone_emitter(&s.light_sampler);
        let m = mesh(&s, e);
        for p in [Vec3::ZERO, centre + Vec3::Z * 4.0, centre - Vec3::Z * 0.35] {
            let mut rng = crate::sampling::Pcg32::new(3, 4);
            let n = 200_000;
            let mut omega = 0.0f64;
            for _ in 0..n {
                let sample = m
                    .sample_li(&s.materials, &s.textures, e as u32, p, 0.5, rng.next_2d())
                    .unwrap();
                assert_eq!(
                    sample.visibility,
                    Visibility::FirstHit { emitter: e as u32 }
                );
                let hit = s.intersect(&crate::geometry::Ray::new(p, sample.wi));
                if let Some(h) =
                    hit.filter(|h| emitters.emitter_of(h.triangle).map(|x| x.0) == Some(e))
                {
                    assert!(s.emitted_radiance(&h, -sample.wi).x > 0.0);
                    omega += 1.0 / sample.pdf as f64;
                }
            }
            let omega = omega / n as f64;
            let mut exact = 0.0f64;
            for (t, &material) in s.mesh.triangle_materials.iter().enumerate() {
                let v = vertices(&s, t).map(|x| x - p);
                if material == 1 && normal(&s, t).dot(-v[0]) > 0.0 {
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
    fn bounds_place_every_emitter() {
        let sun = Light::Directional {
            direction: -Vec3::Y,
            irradiance: Vec3::ONE,
        };
        let s = lamp_scene(Vec3::new(0.0, 2.0, -3.0), 5.0, vec![sun]);
        let bounds = s.light_sampler.emitters().bounds(10.0);
        assert_eq!(bounds.len(), 4);
        assert_eq!(bounds[0].position, None);
        assert!((bounds[0].power - sun.power(10.0)).abs() < 1e-3);
        for (e, b) in bounds.iter().enumerate().skip(1) {
            let m = mesh(&s, e);
            assert_eq!(
                (b.position, b.radius, b.power),
                (Some(m.centre()), m.radius(), m.power())
            );
            // A one-sided mesh emits pi A L.
            let l = luminance(s.materials[m.material() as usize].emission);
            assert!((m.power() - PI * m.area() * l).abs() < 1e-4 * m.power());
        }
    }
}
