//! Scenes and checks shared by the light tests.

use super::{Emitter, LightSampler, LightTree, Node, Receiver, Visibility, BRANCHING};
use crate::bsdf::Bsdf;
use crate::geometry::{Frame, Ray};
use crate::light::Light;
use crate::material::Material;
use crate::scene::{Scene, SceneParts, TriangleMesh};
use glam::Vec3;
use std::f32::consts::PI;

/// A one-sided (or double-sided) emissive triangle in the plane z = 1 facing -Z (toward the
/// origin), of radiance (2, 1, 0.5), plus a diffuse floor far away.
pub fn triangle_scene(double_sided: bool) -> Scene {
    let mut emitter = Material::diffuse("lamp", Vec3::ZERO);
    emitter.emission = Vec3::new(2.0, 1.0, 0.5);
    emitter.double_sided = double_sided;
    Scene::from_parts(SceneParts {
        source: "test".into(),
        mesh: TriangleMesh {
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
            ..TriangleMesh::default()
        },
        materials: vec![emitter, Material::diffuse("floor", Vec3::splat(0.5))],
        ..Default::default()
    })
    .unwrap()
}

/// Solid angle of a triangle seen from the origin (Van Oosterom and Strackee 1983).
pub fn solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// A receiver at `p` on a surface facing +Y with the given BSDF, viewed from `wo`.
pub fn receiver(p: Vec3, bsdf: Bsdf, wo: Vec3) -> Receiver {
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
pub fn sphere(parts: &mut SceneParts, centre: Vec3, r: f32, material: u32) {
    let (rings, segments) = (12u32, 16u32);
    let base = parts.mesh.positions.len() as u32;
    for i in 0..=rings {
        let theta = PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = 2.0 * PI * j as f32 / segments as f32;
            parts.mesh.positions.push(
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
                let [p0, p1, p2] = t.map(|v| parts.mesh.positions[v as usize]);
                let n = (p1 - p0).cross(p2 - p0);
                if n.length() > 1e-9 {
                    // Outward: flip if the winding faces the centre.
                    let t = if n.dot(p0 - centre) < 0.0 {
                        [t[0], t[2], t[1]]
                    } else {
                        t
                    };
                    parts.mesh.triangles.push(t);
                    parts.mesh.triangle_materials.push(material);
                }
            }
        }
    }
}

/// A sphere lamp (material 1) of radiance `le` at `centre` over a floor (material 0), plus two
/// separate lens quads of radiance 3 (material 2, one-sided, facing down) at x = 4 and x = -4,
/// and the given punctual lights.
pub fn lamp_scene(centre: Vec3, le: f32, punctual: Vec<Light>) -> Scene {
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
        let b = parts.mesh.positions.len() as u32;
        parts.mesh.positions.extend([
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
        parts.mesh.triangles.extend([t0, t1]);
        parts.mesh.triangle_materials.extend([m, m]);
    };
    quad(&mut parts, Vec3::ZERO, 50.0, true, 0);
    sphere(&mut parts, centre, 0.3, 1);
    quad(&mut parts, Vec3::new(4.0, 3.0, 0.0), 0.2, false, 2);
    quad(&mut parts, Vec3::new(-4.0, 3.0, 0.0), 0.2, false, 2);
    Scene::from_parts(parts).unwrap()
}

/// The index of the first emitter mesh sampled by its cone (the sphere lamp of
/// [`lamp_scene`]).
pub fn cone_emitter(ls: &LightSampler) -> usize {
    (0..ls.emitters().len())
        .find(|&e| matches!(ls.emitters().get(e), Emitter::Mesh(m) if m.samples_cone()))
        .unwrap()
}

/// Vertex positions of scene triangle `t`.
pub fn vertices(s: &Scene, t: usize) -> [Vec3; 3] {
    s.mesh.triangles[t].map(|v| s.mesh.positions[v as usize])
}

/// Unit normal (from the winding) of scene triangle `t`.
pub fn normal(s: &Scene, t: usize) -> Vec3 {
    let [a, b, c] = vertices(s, t);
    (b - a).cross(c - a).normalize()
}

/// Irradiance at `p` (normal `n`) from a uniformly emitting polygon of radiance 1
/// (Lambert's formula: `E = 1/2 sum_i angle_i (n . unit(v_i x v_{i+1}))`).
/// In f64: the terms cancel to a small sum for small, distant polygons.
pub fn polygon_irradiance(p: Vec3, n: Vec3, verts: &[Vec3]) -> f64 {
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
/// receiver, resolving first-hit samples by tracing, with `n * n` samples.
pub fn estimate_irradiance(s: &Scene, rx: &Receiver, n: usize) -> f64 {
    let ls = &s.light_sampler;
    let mut sum = 0.0f64;
    let mut rng = crate::sampling::Pcg32::new(7, 1);
    for _ in 0..n {
        for _ in 0..n {
            let u_light = rng.next_f32();
            let u = rng.next_2d();
            let Some(sample) = ls.sample_li(&s.materials, &s.textures, rx, u_light, u) else {
                continue;
            };
            if sample.delta {
                continue;
            }
            let li = match sample.visibility {
                Visibility::ShadowRay => sample.li,
                Visibility::FirstHit { emitter } => {
                    let ray = Ray::new(rx.p + Vec3::Y * 1e-4, sample.wi);
                    match s.intersect(&ray) {
                        Some(h)
                            if ls.emitters().emitter_of(h.triangle).map(|x| x.0)
                                == Some(emitter as usize) =>
                        {
                            // The density of the first-hit direction is what pdf_li says.
                            let pdf = ls.pdf_li(rx, &h);
                            assert!(
                                (pdf - sample.pdf).abs() <= 1e-3 * sample.pdf,
                                "{pdf} {}",
                                sample.pdf
                            );
                            s.emitted_radiance(&h, -sample.wi)
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

/// Checks a light tree's structure: every group has 1 to `BRANCHING` children, every emitter
/// is a leaf exactly once at its recorded node, every node but the root's children has the
/// group whose range holds it as its parent, and every node is reached once from the root.
/// Returns the depth.
pub fn check_tree(tree: &LightTree, emitters: usize) -> usize {
    let nodes = tree.nodes();
    let mut seen = vec![0; emitters];
    let mut reached = vec![0; nodes.len()];
    assert!(tree.root().len() <= BRANCHING);
    for n in tree.root() {
        reached[n] += 1;
        assert_eq!(tree.parent(n), None);
    }
    for (n, node) in nodes.iter().enumerate() {
        match *node {
            Node::Emitter(e) => {
                seen[e as usize] += 1;
                assert_eq!(tree.node_of_emitter(e as usize), Some(n));
            }
            Node::Group(g) => {
                assert!(g.len >= 1 && g.len as usize <= BRANCHING);
                for c in g.children() {
                    reached[c] += 1;
                    assert_eq!(tree.parent(c), Some(n));
                    assert_eq!(tree.siblings(c), g.children());
                }
            }
        }
    }
    assert!(seen.iter().all(|&k| k == 1), "{seen:?}");
    assert!(reached.iter().all(|&k| k == 1), "{reached:?}");
    let depth = |e: usize| {
        let mut node = tree.node_of_emitter(e).unwrap();
        let mut d = 1;
        while let Some(parent) = tree.parent(node) {
            node = parent;
            d += 1;
        }
        d
    };
    (0..emitters).map(depth).max().unwrap_or(0)
}
