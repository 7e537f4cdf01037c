//! The Mitsuba 3 cross-check scene: a wet GGX road, one emissive sphere lamp, one point
//! light, one diffuse wall and a camera named "cam", all within 20 m.

use crate::estimate::{intensity_for_peak, round_sig2, Brdf};
use crate::gltf_writer::{Doc, Light, LightKind, Material, PaperBsdf};
use crate::mesh::Mesh;
use crate::Error;
use glam::{DVec3, Vec3};

/// The road reflectance (ggx, kd 0.05, ks 0.5, alpha 0.1).
pub const ROAD: Brdf = Brdf::Ggx {
    kd: 0.05,
    ks: 0.5,
    alpha: 0.1,
};
/// Camera position.
pub const EYE: DVec3 = DVec3::new(0.0, 1.5, 0.0);
/// Point light position.
pub const POINT: DVec3 = DVec3::new(1.5, 3.0, -10.0);
/// Sphere lamp centre.
pub const SPHERE: DVec3 = DVec3::new(-1.5, 2.0, -11.0);
/// Sphere lamp radius.
pub const SPHERE_RADIUS: f64 = 0.15;

/// Builds the cross-check scene.
pub fn crosscheck() -> Result<Doc, Error> {
    let mut doc = Doc::new(
        "crosscheck",
        "Mitsuba 3 cross-check: ggx road, emissive sphere, point light, diffuse wall",
    );
    let road = Material::paper(
        "wet_road",
        PaperBsdf::Ggx { alpha: 0.1 },
        [0.05; 3],
        [0.5; 3],
    );
    let mut m = Mesh::new();
    m.rect(
        Vec3::new(0.0, 0.0, -7.0),
        Vec3::new(0.0, 0.0, 9.0),
        Vec3::new(10.0, 0.0, 0.0),
    );
    doc.add_mesh("road", &m, &road)?;
    let mut wall = Mesh::new();
    wall.rect(
        Vec3::new(0.0, 3.0, -16.0),
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(0.0, 3.0, 0.0),
    );
    doc.add_mesh("wall", &wall, &Material::diffuse("wall", [0.5; 3]))?;
    let i_point = intensity_for_peak(ROAD, EYE, POINT, 1.0);
    doc.add_light(&Light {
        name: "point".to_owned(),
        kind: LightKind::Point,
        color: [1.0; 3],
        intensity: i_point,
        position: POINT.as_vec3(),
        direction: Vec3::NEG_Z,
    });
    // A small sphere of radiance Le radiates like a point of intensity Le * pi R^2.
    let r = SPHERE_RADIUS;
    let le =
        round_sig2(intensity_for_peak(ROAD, EYE, SPHERE, 1.0) / (std::f64::consts::PI * r * r));
    let mut s = Mesh::new();
    s.sphere(SPHERE.as_vec3(), r as f32, 16, 24);
    doc.add_mesh(
        "sphere_lamp",
        &s,
        &Material::emitter("sphere_lamp", [le; 3]),
    )?;
    doc.add_camera(
        "cam",
        EYE.as_vec3(),
        Vec3::new(0.0, 0.8, -10.0),
        40.0,
        4.0 / 3.0,
    );
    Ok(doc)
}
