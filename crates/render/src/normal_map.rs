//! Tangent-space normal maps (glTF `normalTexture`): the shading normal at a hit from the
//! interpolated normal, the vertex tangent and a texel, and the rule that keeps a perturbed
//! normal from making a lit surface black.
//!
//! # The perturbation (glTF 2.0, section 3.9.3 and `material.normalTexture`)
//!
//! The texture is linear (not sRGB). A texel `c` encodes the tangent-space normal
//! `n_t = normalize((2 c.rgb - 1) * (scale, scale, 1))`: +X along the tangent (increasing u),
//! +Y along the bitangent (up in the image, that is decreasing glTF v), +Z along the normal.
//! The frame at a hit is the interpolated normal `N`, the interpolated tangent made orthogonal
//! to it (Gram-Schmidt, as pbrt-v4's `NormalMap`) `T`, and `B = w * cross(N, T)` with the
//! tangent's handedness `w` (glTF's `bitangent = cross(normal, tangent.xyz) * tangent.w`). The
//! shading normal is `n_t.x T + n_t.y B + n_t.z N`. The frame is orthonormal, so the angle
//! between the shading normal and `N` is exactly the angle that `n_t` encodes. (Bakers that
//! follow MikkTSpace to the letter use the unnormalised interpolated frame; the two differ by
//! second-order terms in the interpolation across a triangle.)
//!
//! A vertex without a tangent (a zero tangent: the primitive had no texture coordinates, or
//! MikkTSpace found no tangent space for a degenerate triangle) is not normal mapped.
//!
//! # Keeping light where it belongs
//!
//! The integrator uses the shading normal's frame for the BSDF and cosines, and accepts a
//! direction only if it lies on the viewer's side of the *geometric* normal as well (so no
//! light comes through a surface from behind, whatever the shading normal). A tilted normal
//! can still face away from the viewer at grazing angles, which would leave the surface black
//! there (the integrator ends a path whose `wo` is below the shading hemisphere). So the
//! perturbed normal goes through [`valid_reflection_normal`], Blender Cycles' rule
//! (`ensure_valid_specular_reflection`; Schüssler et al., "Microfacet-based normal mapping for
//! robust Monte Carlo path tracing", 2017, describe the artefact and a costlier fix): if the mirror reflection of `wo` about the shading normal would go below the surface, the
//! normal is tilted back toward the geometric normal, in the plane of the two, just far enough
//! that the reflection lies slightly above the surface. Then `wo` is always above the shading
//! hemisphere and the shading normal is unchanged wherever it was already valid. The rule is
//! applied to normal-mapped hits only: interpolated vertex normals are left as they are, so
//! scenes without normal maps render exactly as before.
//!
//! # Diffuse lobes: the mapped normal itself, with Cycles' bump shadowing
//!
//! Cycles (Blender 5.0, `svm/closure.h` and `closure/bsdf.h`) gives the corrected normal to
//! the specular closures only; the diffuse closure keeps the normal map's own normal, and its
//! value is softened by `bump_shadowing_term` (on by default: the material's "Bump Map
//! Correction"). A grey Lambertian road with a normal map of round bumps, lit from above and
//! seen at grazing angles, is 11% brighter under the lamp than in Cycles when the diffuse lobe
//! uses the corrected normal (the bumps facing away from the camera are tilted toward the
//! light), and within 1% of it with Cycles' rule (`tools/blender`, scene `road_lambert`). So a
//! normal-mapped hit carries a [`MappedNormal`], and the integrator weights the diffuse part
//! of the BSDF by [`MappedNormal::diffuse_cosine`] in place of the shading frame's cosine:
//!
//! - `max(0, n_map . wi)`, Lambert's cosine about the mapped normal;
//! - zero where `wi` and `n_map` lie on opposite sides of the smooth (interpolated, unmapped)
//!   normal `n_s` (`(n_s . wi) (n_s . n_map) (n_map . wi) < 0`: light from behind the smooth
//!   surface);
//! - times the shadowing of Conty Estevez et al., "A Microfacet-Based Shadowing Function to
//!   Solve the Bump Terminator Problem" (Ray Tracing Gems, 2019), which Cycles uses: Smith's
//!   GGX masking `G1(|n_s . wi|)` with `alpha^2 = min(tan^2(theta_d) / 8, 1)`, `theta_d` the
//!   angle between `n_s` and `n_map`. It darkens light arriving at grazing angles to the smooth
//!   surface on strongly tilted normals, and is 1 where the map is flat.
//!
//! The glossy lobes keep the corrected normal's frame, as Cycles' do. Directions are still
//! sampled about the shading frame, so the diffuse light from directions below the corrected
//! normal but above the mapped one (a thin wedge near the corrected normal's horizon, on
//! facets that face away from the viewer) is not gathered.

use crate::bsdf::LobeValues;
use crate::texture::{Texture, TextureRef};
use glam::{Vec2, Vec3, Vec4};

/// A material's tangent-space normal map (glTF `normalTexture`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalMap {
    /// The linear RGB texture, with its coordinate set, sampler and transform.
    pub texture: TextureRef,
    /// `normalTexture.scale`: multiplies the X and Y of the decoded normal.
    pub scale: f32,
}

impl NormalMap {
    /// The unit tangent-space normal a texel encodes, `normalize((2 c - 1) * (scale, scale,
    /// 1))` (glTF 2.0); +Z where that is zero.
    #[inline]
    pub fn tangent_space_normal(&self, texel: Vec4) -> Vec3 {
        let n = (texel.truncate() * 2.0 - Vec3::ONE) * Vec3::new(self.scale, self.scale, 1.0);
        n.try_normalize().unwrap_or(Vec3::Z)
    }

    /// The shading normal at the texture coordinates `uv` (both sets): the tangent-space normal of the texel there in the frame of
    /// the unit normal `n` and the tangent `tangent` (xyz: direction, need not be unit or
    /// orthogonal to `n`; w: handedness, negative for a mirrored frame). `n` itself where the
    /// tangent is zero or parallel to `n`.
    #[inline]
    pub fn perturb(&self, n: Vec3, tangent: Vec4, uv: [Vec2; 2], textures: &[Texture]) -> Vec3 {
        let t = tangent.truncate();
        let Some(t) = (t - n * n.dot(t)).try_normalize() else {
            return n;
        };
        if textures.get(self.texture.texture as usize).is_none() {
            return n;
        }
        let b = n.cross(t) * if tangent.w < 0.0 { -1.0 } else { 1.0 };
        let nt = self.tangent_space_normal(self.texture.sample(uv, textures));
        (t * nt.x + b * nt.y + n * nt.z)
            .try_normalize()
            .unwrap_or(n)
    }
}

/// The normals of a normal-mapped hit that the diffuse lobe needs (see the module
/// documentation), both unit and on the side of the geometric normal, as `SurfaceHit::ns`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MappedNormal {
    /// The interpolated vertex normal before the map (Cycles' `sd->N`).
    pub smooth: Vec3,
    /// The normal map's normal, before [`valid_reflection_normal`].
    pub mapped: Vec3,
}

impl MappedNormal {
    /// The cosine factor of a diffuse lobe toward `wi` (unit, world space): `max(0, mapped .
    /// wi)` times Cycles' `bump_shadowing_term` for diffuse closures (see the module
    /// documentation); 0 for light from behind the smooth surface.
    #[inline]
    pub fn diffuse_cosine(&self, wi: Vec3) -> f32 {
        let cos_mapped = self.mapped.dot(wi);
        let cos_smooth_wi = self.smooth.dot(wi);
        let cos_d = self.smooth.dot(self.mapped);
        if cos_mapped <= 0.0 || cos_smooth_wi * cos_d < 0.0 {
            return 0.0;
        }
        let (cos_i, cos_d) = (cos_smooth_wi.abs(), cos_d.abs());
        if cos_d >= 1.0 || cos_i >= 1.0 {
            return cos_mapped;
        }
        if cos_i < 1e-6 {
            return 0.0;
        }
        let alpha2 = (0.125 * (1.0 / (cos_d * cos_d) - 1.0)).clamp(0.0, 1.0);
        let tan2_i = 1.0 / (cos_i * cos_i) - 1.0;
        let lambda = 0.5 * ((1.0 + alpha2 * tan2_i).sqrt() - 1.0);
        cos_mapped / (1.0 + lambda)
    }

    /// The BRDF value `f` (its lobes, evaluated in the frame of the corrected shading normal
    /// `n`) reweighted so that `result * (n . wi)` is Cycles' contribution toward `wi`: the
    /// glossy part where [`MappedNormal::glossy_visible`], plus the transmitted part (below
    /// the surface, about the corrected normal too; the integrator checks its side), plus the
    /// diffuse part times [`MappedNormal::diffuse_cosine`] `/ (n . wi)`. `cos_n = n . wi`, not
    /// 0 (negative for a transmitted `wi`, where the diffuse part is 0).
    #[inline]
    pub fn reweigh(&self, f: LobeValues, n: Vec3, wi: Vec3, cos_n: f32) -> Vec3 {
        let glossy = if self.glossy_visible(n, wi) {
            f.glossy
        } else {
            Vec3::ZERO
        };
        glossy + f.transmission + f.diffuse * (self.diffuse_cosine(wi) / cos_n)
    }

    /// The same normals seen from the other face (both negated).
    #[inline]
    pub fn flipped(self) -> Self {
        Self {
            smooth: -self.smooth,
            mapped: -self.mapped,
        }
    }

    /// Whether a glossy lobe about the shading normal `n` (the corrected one) may reflect
    /// toward `wi`: not when `wi` and `n` lie on opposite sides of the smooth surface (Cycles'
    /// test for every closure's evaluation).
    #[inline]
    pub fn glossy_visible(&self, n: Vec3, wi: Vec3) -> bool {
        self.smooth.dot(wi) * self.smooth.dot(n) * n.dot(wi) >= 0.0
    }
}

/// The shading normal `n` (unit; it may even point below the surface), tilted toward the
/// geometric normal `ng` (unit, on the side of `wo`) just enough that the mirror reflection of `wo` (unit, pointing away from the surface)
/// about it lies at least `min(0.9 wo.ng, 0.01)` above the surface; `n` itself when it already
/// does. Cycles' `ensure_valid_specular_reflection` (see the module documentation): in the
/// frame with `ng` as Z and `n` in the X-Z plane, the new normal `(sqrt(1 - z^2), 0, z)`
/// solves `2 (n'.wo) z - wo.z = threshold`, a quadratic in `z^2`; of its roots the one whose
/// reflection is valid and shallower is taken, and `ng` when neither is.
pub fn valid_reflection_normal(ng: Vec3, wo: Vec3, n: Vec3) -> Vec3 {
    let iz = wo.dot(ng);
    let threshold = (0.9 * iz).min(0.01);
    let r = 2.0 * n.dot(wo) * n - wo;
    // Above the surface, with a valid reflection (then `n.wo > 0` too: were it not, the
    // reflection would be at most `-wo.ng` high).
    if n.dot(ng) > 0.0 && r.dot(ng) >= threshold {
        return n;
    }
    let Some(x) = (n - n.dot(ng) * ng).try_normalize() else {
        return ng;
    };
    let ix = wo.dot(x);
    let (ix2, iz2) = (ix * ix, iz * iz);
    let a = ix2 + iz2;
    if a <= 0.0 {
        return ng;
    }
    let b = (ix2 * (a - threshold * threshold)).max(0.0).sqrt();
    let c = iz * threshold + a;
    let fac = 0.5 / a;
    let (z2_1, z2_2) = (fac * (b + c), fac * (c - b));
    let valid = |z2: f32| z2 > 1e-5 && z2 <= 1.0 + 1e-5;
    let normal = |z2: f32| Vec2::new((1.0 - z2).max(0.0).sqrt(), z2.max(0.0).sqrt());
    // The reflection's height above the surface for the local normal `m`.
    let height = |m: Vec2| 2.0 * (m.x * ix + m.y * iz) * m.y - iz;
    let m = match (valid(z2_1), valid(z2_2)) {
        (true, true) => {
            let (m1, m2) = (normal(z2_1), normal(z2_2));
            let (r1, r2) = (height(m1), height(m2));
            if r1 >= 1e-5 && r2 >= 1e-5 {
                if r1 < r2 {
                    m1
                } else {
                    m2
                }
            } else if r1 > r2 {
                m1
            } else {
                m2
            }
        }
        (true, false) => normal(z2_1),
        (false, true) => normal(z2_2),
        (false, false) => return ng,
    };
    (x * m.x + ng * m.y).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::ColorSpace;

    #[test]
    fn diffuse_cosine_is_lambert_where_flat_and_follows_cycles_bump_shadowing() {
        // A flat map: the mapped normal is the smooth one, the factor is Lambert's cosine.
        let flat = MappedNormal {
            smooth: Vec3::Z,
            mapped: Vec3::Z,
        };
        for wi in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.8, 0.6)] {
            assert!((flat.diffuse_cosine(wi) - wi.z).abs() < 1e-6);
        }
        assert_eq!(flat.diffuse_cosine(Vec3::new(0.6, 0.0, -0.8)), 0.0);
        // A normal tilted by 45 degrees toward +X: alpha^2 = tan^2(45) / 8 = 1/8.
        let d = std::f32::consts::FRAC_1_SQRT_2;
        let tilted = MappedNormal {
            smooth: Vec3::Z,
            mapped: Vec3::new(d, 0.0, d),
        };
        // Light along the mapped normal: cos_i = 1/sqrt2, tan^2 = 1, lambda = (sqrt(9/8) - 1)/2.
        let wi = Vec3::new(d, 0.0, d);
        let lambda = 0.5 * ((1.0f32 + 0.125).sqrt() - 1.0);
        assert!((tilted.diffuse_cosine(wi) - 1.0 / (1.0 + lambda)).abs() < 1e-5);
        // Light straight down the smooth normal: no shadowing (tan = 0), cosine 1/sqrt2.
        assert!((tilted.diffuse_cosine(Vec3::Z) - d).abs() < 1e-6);
        // Light below the smooth surface but above the mapped normal: zero (no leak).
        let below = Vec3::new(0.99, 0.0, -0.141).normalize();
        assert!(tilted.mapped.dot(below) > 0.0);
        assert_eq!(tilted.diffuse_cosine(below), 0.0);
        // Never more than the plain cosine, and it falls toward grazing light.
        let mut last = f32::INFINITY;
        for k in 0..=8 {
            let theta = k as f32 * 0.19;
            let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
            let g = tilted.diffuse_cosine(wi) / tilted.mapped.dot(wi).max(1e-9);
            assert!(g <= 1.0 + 1e-6 && g <= last + 1e-6, "theta {theta}: {g}");
            last = g;
        }
        // Glossy lobes: visible on the smooth side, not through it.
        assert!(tilted.glossy_visible(Vec3::Z, Vec3::Z));
        assert!(!tilted.glossy_visible(tilted.mapped, below));
    }

    fn constant(c: Vec4) -> Texture {
        Texture::from_rgba(1, 1, vec![c], ColorSpace::Linear).unwrap()
    }

    #[test]
    fn flat_texel_leaves_the_normal_and_scale_scales_xy() {
        let map = NormalMap {
            texture: TextureRef::new(0),
            scale: 1.0,
        };
        assert_eq!(
            map.tangent_space_normal(Vec4::new(0.5, 0.5, 1.0, 1.0)),
            Vec3::Z
        );
        let n = Vec3::new(0.0, 0.6, 0.8);
        let flat = [constant(Vec4::new(0.5, 0.5, 1.0, 1.0))];
        let t = Vec4::new(1.0, 0.0, 0.0, 1.0);
        assert!((map.perturb(n, t, [Vec2::ZERO; 2], &flat) - n).length() < 1e-7);
        // scale multiplies x and y before normalisation: (2c - 1) = (0.5, -0.25, 1).
        let c = Vec4::new(0.75, 0.375, 1.0, 1.0);
        for scale in [0.0f32, 0.5, 1.0, 2.0] {
            let m = NormalMap {
                texture: TextureRef::new(0),
                scale,
            };
            let got = m.tangent_space_normal(c);
            let want = Vec3::new(0.5 * scale, -0.25 * scale, 1.0).normalize();
            assert!(
                (got - want).length() < 1e-6,
                "scale {scale}: {got} vs {want}"
            );
        }
        // A texel of exactly (0.5, 0.5, 0.5) has no direction: the normal stays.
        assert_eq!(
            map.tangent_space_normal(Vec4::new(0.5, 0.5, 0.5, 1.0)),
            Vec3::Z
        );
    }

    /// A texel encoding a normal tilted by `theta` toward +X (or +Y) tilts the shading normal by
    /// `theta` toward the tangent (or the bitangent, which the handedness flips).
    #[test]
    fn tilted_texel_tilts_the_shading_normal_by_its_angle() {
        let map = NormalMap {
            texture: TextureRef::new(0),
            scale: 1.0,
        };
        let n = Vec3::Y;
        // Tangent along +X but not orthogonal to n: Gram-Schmidt keeps only its +X part.
        let tangent = Vec4::new(2.0, 0.7, 0.0, 1.0);
        for theta in [0.1f32, 0.5, 1.0] {
            let enc = |v: Vec3| (v + Vec3::ONE) * 0.5;
            let tex = [constant(
                enc(Vec3::new(theta.sin(), 0.0, theta.cos())).extend(1.0),
            )];
            let got = map.perturb(n, tangent, [Vec2::ZERO; 2], &tex);
            assert!((got.dot(n).acos() - theta).abs() < 1e-5, "{theta}: {got}");
            assert!(got.x > 0.0 && got.z.abs() < 1e-6);
            // Along the bitangent B = w cross(N, T): cross(Y, X) = -Z.
            let tex = [constant(
                enc(Vec3::new(0.0, theta.sin(), theta.cos())).extend(1.0),
            )];
            for w in [1.0f32, -1.0] {
                let got = map.perturb(n, tangent.truncate().extend(w), [Vec2::ZERO; 2], &tex);
                assert!((got.dot(n).acos() - theta).abs() < 1e-5);
                assert!((got.z + w * theta.sin()).abs() < 1e-5, "w {w}: {got}");
            }
        }
        // No tangent, no perturbation.
        let tex = [constant(Vec4::new(1.0, 0.5, 0.5, 1.0))];
        assert_eq!(map.perturb(n, Vec4::ZERO, [Vec2::ZERO; 2], &tex), n);
    }

    #[test]
    fn valid_reflection_normal_lifts_the_reflection_above_the_surface() {
        let ng = Vec3::Z;
        let mut lifted = 0;
        for i in 0..40 {
            for j in 0..40 {
                // Viewer from nearly straight down to grazing; normals tilted up to 80 degrees.
                let a = 0.02 + 1.5 * i as f32 / 40.0;
                let wo = Vec3::new(a.sin(), 0.0, a.cos());
                let (b, phi) = (1.4 * j as f32 / 40.0, 0.37 * j as f32);
                let n = Vec3::new(b.sin() * phi.cos(), b.sin() * phi.sin(), b.cos());
                let m = valid_reflection_normal(ng, wo, n);
                assert!((m.length() - 1.0).abs() < 1e-5);
                let r = 2.0 * m.dot(wo) * m - wo;
                let threshold = (0.9 * wo.z).min(0.01);
                assert!(r.z >= threshold - 1e-4, "wo {wo} n {n}: m {m}, r {r}");
                assert!(m.dot(wo) > 0.0, "wo below the shading hemisphere");
                let reflects = (2.0 * n.dot(wo) * n - wo).z >= threshold;
                if reflects {
                    assert_eq!(m, n, "a valid normal is unchanged");
                } else {
                    lifted += 1;
                    // Tilted back in the plane of n and ng.
                    assert!(m.cross(n).dot(ng).abs() < 1e-4 || n.cross(ng).length() < 1e-6);
                }
            }
        }
        assert!(lifted > 100, "{lifted}");
        // The geometric normal itself is always valid.
        let wo = Vec3::new(0.99, 0.0, 0.141).normalize();
        assert_eq!(valid_reflection_normal(ng, wo, ng), ng);
    }
    /// Render-level checks: a normal-mapped floor (material 0, a constant normal map of
    /// `texel`, tangent +X) of albedo `kd`, with `extra` materials, lights and quads.
    mod render {
        use super::*;
        use crate::camera::Camera;
        use crate::integrator::{self, render, Layers, RenderJob};
        use integrator::tests::quad;
        use streaks_settings::RenderSettings;

        fn camera(position: Vec3, pitch: f32) -> Camera {
            integrator::tests::camera(position, pitch, 0.6)
        }

        use crate::light::Light;
        use crate::material::Material;
        use crate::scene::{Scene, SceneParts};

        fn settings(spp: u32, max_depth: u32) -> RenderJob {
            RenderJob {
                width: 12,
                height: 8,
                seed: 3,
                layers: Layers::default(),
                settings: RenderSettings::new(spp, max_depth),
                motion: Default::default(),
            }
        }

        /// The floor (200 m at y = 0, facing up) with or without the normal map, and
        /// whatever `add` puts in.
        fn scene(texel: Option<Vec4>, kd: Vec3, add: impl Fn(&mut SceneParts)) -> Scene {
            let mut floor = Material::diffuse("floor", kd);
            let mut parts = SceneParts::default();
            if let Some(c) = texel {
                floor.normal_map = Some(NormalMap {
                    texture: TextureRef::new(0),
                    scale: 1.0,
                });
                parts.textures.push(constant(c));
            }
            parts.materials.push(floor);
            integrator::tests::floor(&mut parts);
            add(&mut parts);
            if texel.is_some() {
                // A tangent not orthogonal to the normal: only its +X part counts.
                parts.mesh.tangents =
                    vec![Vec4::new(1.0, 0.3, 0.0, 1.0); parts.mesh.positions.len()];
            }
            Scene::from_parts(parts).unwrap()
        }

        /// A one-sided emitting ceiling of radiance `le`, 1 m up, 2 km wide, facing down.
        fn ceiling(parts: &mut SceneParts, le: Vec3) {
            let mut sky = Material::diffuse("sky", Vec3::ZERO);
            sky.emission = le;
            parts.materials.push(sky);
            let s = 1000.0;
            let m = parts.materials.len() as u32 - 1;
            quad(
                parts,
                [
                    Vec3::new(-s, 1.0, -s),
                    Vec3::new(s, 1.0, -s),
                    Vec3::new(s, 1.0, s),
                    Vec3::new(-s, 1.0, s),
                ],
                m,
            );
        }

        fn encode(n: Vec3) -> Vec4 {
            ((n + Vec3::ONE) * 0.5).extend(1.0)
        }

        /// A flat map (exactly (0.5, 0.5, 1), a float texture) changes nothing, bit for bit, on
        /// this floor: `2 * 0.5 - 1 = 0` exactly, the normal is `0 T + 0 B + 1 N` with N = +Y,
        /// whose normalisation is exact. (An 8-bit "flat" texel, 128/255, is 0.0039 off and
        /// tilts the normal by 0.3 degrees; a normal that is not axis-aligned may move by an
        /// ulp in the normalisation.)
        #[test]
        fn flat_normal_map_leaves_the_image_unchanged() {
            let add = |p: &mut SceneParts| {
                p.lights.push(Light::Point {
                    position: Vec3::new(0.5, 2.0, -3.0),
                    intensity: Vec3::splat(10.0),
                    range: None,
                });
                ceiling(p, Vec3::splat(0.2));
            };
            let kd = Vec3::new(0.5, 0.4, 0.3);
            let plain = scene(None, kd, add);
            let flat = scene(Some(Vec4::new(0.5, 0.5, 1.0, 1.0)), kd, add);
            let cam = camera(Vec3::new(0.0, 0.8, 1.0), -0.5);
            let a = render(&plain, &cam, &settings(8, 4), &|_| {});
            let b = render(&flat, &cam, &settings(8, 4), &|_| {});
            assert!(a.image.pixels.iter().all(|p| p.max_element() > 0.0));
            assert_eq!(a.image, b.image);
        }

        /// White furnace style: a white floor under a uniform sky of radiance L reflects
        /// `L / pi` times the integral over the upper hemisphere of the diffuse cosine
        /// ([`MappedNormal::diffuse_cosine`]) when its normal map tilts the normal by theta:
        /// without the bump shadowing that is `(1 + cos theta) / 2`, the sky's part of the
        /// tilted cosine lobe (directions below the geometric surface are never taken, so no
        /// energy is created and none comes from below); the shadowing takes a little more.
        #[test]
        fn tilted_white_floor_under_a_uniform_sky_conserves_energy() {
            let le = Vec3::new(1.0, 0.5, 0.25);
            let theta = 0.6f32;
            let tilted = Vec3::new(theta.sin(), 0.0, theta.cos());
            let texel = encode(tilted);
            let s = scene(Some(texel), Vec3::ONE, |p| ceiling(p, le));
            // Looking straight down: the mirror direction of wo is valid, the normal stays.
            let down = camera(Vec3::new(0.0, 0.5, 0.0), -std::f32::consts::FRAC_PI_2);
            let out = render(&s, &down, &settings(256, 2), &|_| {});
            // The floor's normal is +Y; the quadrature is in a frame with it as +Z.
            let m = MappedNormal {
                smooth: Vec3::Z,
                mapped: tilted,
            };
            let (nt, np) = (400, 800);
            let mut integral = 0.0f64;
            for i in 0..nt {
                let t = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
                for j in 0..np {
                    let p = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                    let w = Vec3::new(
                        (t.sin() * p.cos()) as f32,
                        (t.sin() * p.sin()) as f32,
                        t.cos() as f32,
                    );
                    integral += m.diffuse_cosine(w) as f64 * t.sin();
                }
            }
            integral *= std::f64::consts::FRAC_PI_2 / nt as f64 * std::f64::consts::TAU
                / np as f64
                / std::f64::consts::PI;
            let unshadowed = (1.0 + theta.cos()) / 2.0;
            assert!(integral < unshadowed as f64 && integral > 0.9 * unshadowed as f64);
            let want = le * integral as f32;
            let n = out.image.pixels.len() as f32;
            let mean = out.image.pixels.iter().fold(Vec3::ZERO, |a, p| a + *p / n);
            let err = ((mean - want) / want).abs().max_element();
            assert!(err < 0.01, "{mean} vs {want}");
            // From any angle the floor never reflects more than the sky gives.
            for pitch in [-1.2f32, -0.6, -0.2] {
                let cam = camera(Vec3::new(0.0, 0.5, 0.0), pitch);
                let out = render(&s, &cam, &settings(64, 2), &|_| {});
                let mean = out.image.pixels.iter().fold(Vec3::ZERO, |a, p| a + *p / n);
                assert!(
                    mean.cmple(le * 1.01).all() && mean.cmpgt(le * 0.3).all(),
                    "pitch {pitch}: {mean} vs {le}"
                );
            }
        }

        /// A light below the floor never reaches its top, however the normal map tilts the
        /// shading normal toward it; and a normal tilted away from a grazing viewer does not
        /// leave the lit floor black.
        #[test]
        fn no_light_leaks_through_and_grazing_views_stay_lit() {
            // Tilted by 1.2 rad toward +X, where the light sits just below the floor.
            let texel = encode(Vec3::new(1.2f32.sin(), 0.0, 1.2f32.cos()));
            let below = |p: &mut SceneParts| {
                p.lights.push(Light::Point {
                    position: Vec3::new(3.0, -0.05, -2.0),
                    intensity: Vec3::splat(100.0),
                    range: None,
                });
            };
            let s = scene(Some(texel), Vec3::ONE, below);
            let cam = camera(Vec3::new(0.0, 1.0, 0.0), -0.6);
            let out = render(&s, &cam, &settings(8, 4), &|_| {});
            assert!(out.image.pixels.iter().all(|p| *p == Vec3::ZERO));
            // The camera looks along -Z at a grazing angle and the normals lean away from it
            // (toward -Z): most of wo is below the tilted hemisphere, yet every pixel is lit.
            // (Tangent-space +Y is the bitangent cross(N, T) = cross(+Y, +X) = -Z.)
            let texel = encode(Vec3::new(0.0, 1.0f32.sin(), 1.0f32.cos()));
            let s = scene(Some(texel), Vec3::splat(0.5), |p| ceiling(p, Vec3::ONE));
            let cam = camera(Vec3::new(0.0, 0.2, 0.0), -0.35);
            let mut set = settings(16, 2);
            set.layers.normal = true;
            let out = render(&s, &cam, &set, &|_| {});
            assert!(
                out.image.pixels.iter().all(|p| p.min_element() > 0.05),
                "a black pixel"
            );
            // Where the viewer was below the tilted hemisphere (the upper rows), the shading
            // normal was bent back toward the geometric normal; nowhere is it tilted further.
            let normals = out.normal.unwrap();
            assert!(normals.pixels.iter().all(|n| n.y > 1.0f32.cos() - 1e-3));
            assert!(normals.pixels[..12]
                .iter()
                .all(|n| n.y > 1.0f32.cos() + 0.1));
        }
    }
}
