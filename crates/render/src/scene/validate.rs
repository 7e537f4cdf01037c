//! Values checked against the glTF 2.0 specification and its extensions' JSON schemas, one
//! function per element kind: a value outside its range would otherwise render a silently
//! black or wrong image (a negative colour, an infinite intensity, a spot cone wider than a
//! hemisphere). Each returns the reason; the loader names the file and the element.
//!
//! Where the project departs from the schema it says so: a spot light's innerConeAngle may
//! equal its outerConeAngle (a hard edge; the schema asks for inner < outer).
//!
//! JSON has no NaN or infinity, but a number beyond `f32::MAX` (`1e39`) reads as infinity,
//! so every value is also checked to be finite.

use glam::Vec3;
use std::f32::consts::FRAC_PI_2;

/// The largest absolute world-space coordinate a vertex may have (a million kilometres, far
/// beyond any street): the BVH builder's box areas summed over many primitives stay finite in
/// `f32`, and the watertight triangle test still resolves metre-sized triangles at that
/// distance (at 1e18 obvhs' tree conversion failed its own assertions on a few hundred
/// overlapping boxes; at 1e15 rays missed such triangles).
pub const MAX_COORDINATE: f32 = 1e12;

/// Whether every component of `v` is finite and in `[lo, hi]`.
fn in_range(v: &[f32], lo: f32, hi: f32) -> bool {
    v.iter().all(|x| x.is_finite() && *x >= lo && *x <= hi)
}

/// A `name` of `value` in `[0, 1]` (each component), else the reason.
fn unit(name: &str, v: &[f32]) -> Result<(), String> {
    if in_range(v, 0.0, 1.0) {
        Ok(())
    } else {
        Err(format!("{name} {v:?} is not in [0, 1]"))
    }
}

/// A KHR_lights_punctual light: `color` in [0, 1], `intensity` finite and at least 0, `range`
/// (if given) finite and above 0, and for a spot light `0 <= innerConeAngle <=
/// outerConeAngle <= pi/2`.
pub fn light(l: &gltf::khr_lights_punctual::Light) -> Result<(), String> {
    unit("color", &l.color())?;
    let intensity = l.intensity();
    if !(intensity.is_finite() && intensity >= 0.0) {
        return Err(format!(
            "intensity {intensity} must be finite and at least 0"
        ));
    }
    if let Some(range) = l.range() {
        if !(range.is_finite() && range > 0.0) {
            return Err(format!("range {range} must be finite and above 0"));
        }
    }
    if let gltf::khr_lights_punctual::Kind::Spot {
        inner_cone_angle: inner,
        outer_cone_angle: outer,
    } = l.kind()
    {
        if !(inner.is_finite() && outer.is_finite())
            || inner < 0.0
            || inner > outer
            || outer > FRAC_PI_2
        {
            return Err(format!(
                "spot innerConeAngle {inner} and outerConeAngle {outer} must satisfy \
                 0 <= inner <= outer <= pi/2"
            ));
        }
    }
    Ok(())
}

/// A perspective camera: `yfov` in (0, pi), `znear` finite and above 0, `zfar` (if given)
/// above `znear` (an infinite one is no far plane, as an absent one is), `aspectRatio` (if given) finite and above 0.
pub fn perspective(p: &gltf::camera::Perspective) -> Result<(), String> {
    let yfov = p.yfov();
    if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
        return Err(format!("yfov {yfov} is not in (0, pi)"));
    }
    let znear = p.znear();
    if !(znear.is_finite() && znear > 0.0) {
        return Err(format!("znear {znear} must be finite and above 0"));
    }
    if let Some(zfar) = p.zfar() {
        if zfar.is_nan() || zfar <= znear {
            return Err(format!("zfar {zfar} must be above znear {znear}"));
        }
    }
    if let Some(a) = p.aspect_ratio() {
        if !(a.is_finite() && a > 0.0) {
            return Err(format!("aspectRatio {a} must be finite and above 0"));
        }
    }
    Ok(())
}

/// An orthographic camera: `xmag` and `ymag` finite and above 0 (the schema forbids 0 and
/// advises against negative values, which would mirror the image), `znear` finite and at
/// least 0, `zfar` above `znear`.
pub fn orthographic(o: &gltf::camera::Orthographic) -> Result<(), String> {
    for (name, v) in [("xmag", o.xmag()), ("ymag", o.ymag())] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("{name} {v} must be finite and above 0"));
        }
    }
    let (znear, zfar) = (o.znear(), o.zfar());
    if !(znear.is_finite() && znear >= 0.0) {
        return Err(format!("znear {znear} must be finite and at least 0"));
    }
    if zfar.is_nan() || zfar <= znear {
        return Err(format!("zfar {zfar} must be above znear {znear}"));
    }
    Ok(())
}

/// The core factors of a material: baseColorFactor, metallicFactor, roughnessFactor,
/// emissiveFactor and occlusionTexture.strength in [0, 1], alphaCutoff at least 0,
/// normalTexture.scale finite, and KHR_materials_emissive_strength's emissiveStrength finite
/// and at least 0. (The extensions' own factors are checked where they are read.)
pub fn material(m: &gltf::Material) -> Result<(), String> {
    let pbr = m.pbr_metallic_roughness();
    unit("baseColorFactor", &pbr.base_color_factor())?;
    unit("metallicFactor", &[pbr.metallic_factor()])?;
    unit("roughnessFactor", &[pbr.roughness_factor()])?;
    unit("emissiveFactor", &m.emissive_factor())?;
    if let Some(s) = m.emissive_strength() {
        if !(s.is_finite() && s >= 0.0) {
            return Err(format!(
                "KHR_materials_emissive_strength: emissiveStrength {s} must be finite and at \
                 least 0"
            ));
        }
    }
    if let Some(c) = m.alpha_cutoff() {
        if !(c.is_finite() && c >= 0.0) {
            return Err(format!("alphaCutoff {c} must be finite and at least 0"));
        }
    }
    if let Some(n) = m.normal_texture() {
        let scale = n.scale();
        if !scale.is_finite() {
            return Err(format!("normalTexture.scale {scale} is not finite"));
        }
    }
    if let Some(o) = m.occlusion_texture() {
        unit("occlusionTexture.strength", &[o.strength()])?;
    }
    Ok(())
}

/// A vertex position (in world space, or an instanced mesh's object space, whose
/// instances' boxes are checked in turn): finite and within [`MAX_COORDINATE`] of the
/// origin on every axis.
pub fn position(p: Vec3) -> Result<(), String> {
    if p.is_finite() && p.abs().max_element() <= MAX_COORDINATE {
        Ok(())
    } else {
        Err(format!(
            "position {p} is not finite or beyond {MAX_COORDINATE:e} on an axis (the BVH's \
             arithmetic would overflow)"
        ))
    }
}
