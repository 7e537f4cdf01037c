//! A showroom for looking at the objects: every body type and every furniture piece lined
//! up on a dark ground under one street lamp, with a camera at a three-quarter view. The
//! night version has the vehicles' lamps on (one car turned away, braking); the day version
//! has every lamp off and a grey sky (an environment light) to judge the shapes.
//! `cargo run -p streaks-scenes --example showroom -- DIR` writes both.

use super::furniture::{
    BollardSpec, BusStopSpec, LampDesign, LampLight, ShopSignSpec, SignKind, SignSpec,
    StreetLampSpec, TrafficLightSpec, TreeSpec, UtilityPoleSpec,
};
use super::vehicle::{BodyType, Headlights, VehicleLights, VehicleSpec};
use super::Paint;
use crate::gltf_writer::{Class, Doc, Material, Pbr, Tag};
use crate::light_sources::{luminance, LightSource};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::street::Signal;
use crate::Error;
use glam::{Affine3A, Vec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The showroom at night (`night`) or in daylight.
pub fn showroom(night: bool) -> Result<Doc, Error> {
    let name = if night {
        "showroom_night"
    } else {
        "showroom_day"
    };
    let mut doc = Doc::new(
        name,
        "Every vehicle body type and furniture piece in a line-up",
    );
    let mut ground = Mesh::new();
    ground.rect(Vec3::new(-5.0, 0.0, 0.0), Vec3::Z * 50.0, Vec3::X * 50.0);
    doc.add_tagged_mesh(
        "ground",
        &ground,
        &Material::pbr("asphalt", Pbr::new([0.05; 3], 0.0, 0.6)),
        Tag::stuff(Class::Road),
    )?;
    let mut instance = 0u32;
    let mut place = |doc: &mut Doc, name: &str, m: &Model, pose: Affine3A| {
        instance += 1;
        doc.add_model(name, m, pose, Some(instance))
    };
    let lit = |on: bool| {
        if on {
            VehicleLights {
                headlights: Some(Headlights {
                    source: LightSource::LedHeadlight,
                    intensity: 20.0,
                    lens_luminance: luminance([30.0, 28.5, 25.5]),
                }),
                tail_cd: Some(12.0),
                brake_cd: None,
            }
        } else {
            VehicleLights::OFF
        }
    };
    // Vehicles along X, facing -Z (towards the camera).
    let paints = [
        Paint::Red,
        Paint::White,
        Paint::Blue,
        Paint::Silver,
        Paint::Grey,
        Paint::Yellow,
    ];
    let mut x = 0.0f32;
    for (k, body) in BodyType::ALL.into_iter().enumerate() {
        let r = body.ranges();
        let mid = |a: [f32; 2]| 0.5 * (a[0] + a[1]);
        let spec = VehicleSpec {
            body,
            length: mid(r.length),
            width: mid(r.width),
            height: mid(r.height),
            wheel_radius: mid(r.wheel_radius),
            paint: paints[k].rgb(),
            metallic: k % 2 == 1,
            lights: lit(night),
        };
        x += 0.5 * spec.width + 1.2;
        place(
            &mut doc,
            body.name(),
            &spec.build(),
            Affine3A::from_translation(Vec3::new(x, 0.0, 0.5 * spec.length - 2.5)),
        )?;
        x += 0.5 * spec.width + 1.2;
    }
    // A saloon turned away, braking.
    let away = VehicleSpec {
        body: BodyType::Saloon,
        length: 4.6,
        width: 1.8,
        height: 1.45,
        wheel_radius: 0.32,
        paint: Paint::Black.rgb(),
        metallic: false,
        lights: VehicleLights {
            brake_cd: night.then_some(80.0),
            ..lit(night)
        },
    };
    place(
        &mut doc,
        "saloon_away",
        &away.build(),
        Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_y(std::f32::consts::PI),
            Vec3::new(-2.5, 0.0, -4.0),
        ),
    )?;
    // Furniture in a row behind, facing -Z.
    let light = night.then_some(LampLight {
        color: LightSource::Led3000K.rgb(),
        intensity: 3.0 / luminance(LightSource::Led3000K.rgb()),
        cone: Some((60f64.to_radians(), 85f64.to_radians())),
        lens_radiance: LightSource::Led3000K.rgb_with_luminance(3.0 / 0.08),
    });
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut pieces: Vec<(&str, Model)> = Vec::new();
    for (name, design) in [
        ("cobra_lamp", LampDesign::Cobra),
        ("post_top_lamp", LampDesign::PostTop),
        ("twin_arm_lamp", LampDesign::TwinArm),
    ] {
        let spec = StreetLampSpec {
            design,
            height: if design == LampDesign::PostTop {
                4.5
            } else {
                7.0
            },
            outreach: 1.2,
            lens_half: (0.1, 0.2),
            light,
        };
        pieces.push((name, spec.build()));
    }
    pieces.push(("utility_pole", UtilityPoleSpec::draw(&mut rng).build()));
    pieces.push(("tree", TreeSpec::draw(&mut rng).build()));
    for (k, kind) in [
        SignKind::Prohibitory,
        SignKind::Warning,
        SignKind::Information,
        SignKind::Stop,
    ]
    .into_iter()
    .enumerate()
    {
        let spec = SignSpec {
            kind,
            half: 0.35,
            height: 2.2 + 0.1 * k as f32,
        };
        pieces.push(("sign", spec.build()));
    }
    let tl = TrafficLightSpec {
        height: 2.6,
        signal: Signal::Red,
        intensity: night.then_some(0.5),
    };
    pieces.push(("traffic_light", tl.build()));
    let stop = BusStopSpec {
        length: 4.0,
        depth: 1.4,
        height: 2.5,
        advert_cd_m2: night.then_some(300.0),
    };
    pieces.push(("bus_stop", stop.build()));
    for _ in 0..3 {
        pieces.push(("bollard", BollardSpec::draw(&mut rng).build()));
    }
    let mut x = -44.0f32;
    for (name, m) in &pieces {
        let step = if *name == "bus_stop" {
            3.0
        } else if *name == "bollard" {
            0.8
        } else {
            1.6
        };
        x += step;
        place(
            &mut doc,
            name,
            m,
            Affine3A::from_translation(Vec3::new(x, 0.0, 4.0)),
        )?;
        x += step;
    }
    // A wall with a lit shop sign at the back.
    let mut wall = Mesh::new();
    wall.cuboid(Vec3::new(-48.0, 0.0, 12.0), Vec3::new(34.0, 6.0, 13.0));
    doc.add_tagged_mesh(
        "wall",
        &wall,
        &Material::pbr("render", Pbr::new([0.3, 0.28, 0.25], 0.0, 0.8)),
        Tag::stuff(Class::Building),
    )?;
    let sign = ShopSignSpec {
        width: 4.0,
        sign_height: 0.6,
        mount: 3.0,
        luminance: night.then_some(400.0),
        color: LightSource::Led4000K.rgb(),
    };
    place(
        &mut doc,
        "shop_sign",
        &sign.build(),
        Affine3A::from_translation(Vec3::new(-6.0, 0.0, 12.0)),
    )?;
    if !night {
        doc.set_environment(serde_json::json!({ "color": [0.25, 0.25, 0.27] }));
    }
    let target = Vec3::new(-6.0, 1.5, 4.0);
    doc.add_camera(
        "showroom",
        Vec3::new(-6.0, 9.0, -34.0),
        target,
        55.0,
        16.0 / 9.0,
    );
    // Close-ups: the cars from the front right, the furniture row, the braking car's back.
    let cars = Vec3::new(9.0, 0.8, -1.0);
    doc.add_camera("cars", Vec3::new(16.0, 2.2, -9.0), cars, 40.0, 16.0 / 9.0);
    let row = Vec3::new(-22.0, 2.8, 4.0);
    doc.add_camera(
        "furniture",
        Vec3::new(-24.0, 2.0, -7.0),
        row,
        60.0,
        16.0 / 9.0,
    );
    let back = Vec3::new(-2.5, 0.8, -4.0);
    doc.add_camera(
        "braking",
        Vec3::new(-4.5, 1.6, -11.0),
        back,
        35.0,
        16.0 / 9.0,
    );
    Ok(doc)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both showrooms load in the renderer without warnings, with the lights written and
    /// every node tagged.
    #[test]
    fn showrooms_load_in_the_renderer() {
        for night in [true, false] {
            let doc = showroom(night).unwrap();
            let dir = tempfile::tempdir().unwrap();
            let files = doc.write(dir.path()).unwrap();
            let scene = streaks_render::scene::Scene::load(&files[0]).unwrap();
            assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
            // Night: 6 vehicles x 4 + the braking car's 6, 4 lamps, a signal.
            let want = if night { 24 + 6 + 4 + 1 } else { 0 };
            let punctual = scene
                .lights
                .iter()
                .filter(|l| {
                    matches!(
                        l,
                        streaks_render::light::Light::Point { .. }
                            | streaks_render::light::Light::Spot { .. }
                    )
                })
                .count();
            assert_eq!(punctual, want, "night {night}");
            let (gdoc, _, _) = gltf::import(&files[0]).unwrap();
            for node in gdoc.nodes().filter(|n| n.mesh().is_some()) {
                let extras = node
                    .extras()
                    .as_ref()
                    .map(|e| e.get().to_owned())
                    .unwrap_or_default();
                assert!(extras.contains("\"class\""), "{:?} untagged", node.name());
            }
        }
    }
}
