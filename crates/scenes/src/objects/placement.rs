//! Where the generator puts a street's objects: a model for every car (a body type, size, paint
//! and lamps by its role, or one of the user's assets for a parked car), trees, bus stops,
//! bollards and the user's furniture on the pavements, clear of the lamps, poles, signs and
//! traffic lights already there, and a design for every street lamp (cobra, post top, twin
//! arm; `lamp_designs`) standing where the street put it, in the street's lamp light.
//!
//! Everything is drawn from one seeded stream per street, so that a config without objects
//! draws every other parameter as one with them.

use super::assets::{AssetPool, AssetRole};
use super::furniture::{BollardSpec, BusStopSpec, LampDesign, LampLight, StreetLampSpec, TreeSpec};
use super::vehicle::{Role, TrafficLighting, VehicleSpec};
use super::ObjectsConfig;
use crate::model::Model;
use crate::procedural::uniform;
use crate::street::{Furniture, Street};
use crate::Error;
use glam::Affine3A;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::Path;

/// Gap kept between two cars in one lane, metres.
const CAR_GAP: f32 = 0.8;

/// Draws the models of `street`'s cars and its pavement furniture into `street`
/// ([`Street::car_models`], [`Street::furniture`]); a car that would overlap the one before it
/// in its lane (a bus is 12 m long) is left out. Returns, per kept car, its index in the cars
/// given, and the parameters of what was drawn (the counts placed, per car its model, and each used
/// asset's path, license and attribution).
pub fn place(
    config: &ObjectsConfig,
    rng: &mut ChaCha8Rng,
    street: &mut Street,
    lighting: &TrafficLighting,
) -> Result<(Vec<usize>, Value), Error> {
    let pool = if config.assets.is_empty() {
        AssetPool::default()
    } else {
        AssetPool::load(config, Path::new(""))?
    };
    let mut assets_used: Vec<Value> = Vec::new();
    let mut use_asset = |a: &super::assets::Asset| {
        let p = a.params();
        if !assets_used.contains(&p) {
            assets_used.push(p);
        }
        a.model.clone()
    };

    // Cars.
    let mut kept = Vec::new();
    let mut models: Vec<Model> = Vec::new();
    let mut car_params = Vec::new();
    let mut spans: Vec<(f32, f32, f32)> = Vec::new(); // (x, z0, z1) of the kept cars
    for (k, car) in street.cars.iter().enumerate() {
        let role = if car.parked {
            Role::Parked
        } else if car.oncoming {
            Role::Oncoming
        } else {
            Role::Leading
        };
        let asset = (role == Role::Parked)
            .then(|| pool.pick(rng, AssetRole::ParkedCar))
            .flatten();
        let (model, param) = match asset {
            Some(a) => (use_asset(a), json!({"asset": a.params()["path"]})),
            None => {
                let spec = VehicleSpec::draw(rng, config, role, lighting);
                let param = json!({
                    "body": spec.body,
                    "length": spec.length,
                    "width": spec.width,
                    "height": spec.height,
                    "metallic": spec.metallic,
                    "braking": spec.lights.brake_cd.is_some(),
                });
                (spec.build(), param)
            }
        };
        let (lo, hi) = model.bounds(Affine3A::IDENTITY);
        let (z0, z1) = (car.z + lo.z, car.z + hi.z);
        let clear = spans
            .iter()
            .all(|&(x, a, b)| (x - car.x).abs() > 1.5 || z1 + CAR_GAP < a || b + CAR_GAP < z0);
        if clear {
            spans.push((car.x, z0, z1));
            kept.push(k);
            models.push(model);
            car_params.push(param);
        }
    }
    street.cars = kept.iter().map(|&k| street.cars[k]).collect();
    street.car_models = models;

    // Pavement furniture, per side, clear of what stands there already.
    let st = &street.style;
    let (h, kerb) = (st.road_half, st.kerb);
    let pavement = st.facade_x - (h + kerb);
    let length = street.near - street.far;
    let mut furniture = Vec::new();
    let (mut trees, mut stops, mut bollards, mut others) = (0, 0, 0, 0);
    for side in [1.0f32, -1.0] {
        let mut taken: Vec<(f32, f32)> = Vec::new(); // (z, half extent along the road)
        let lamps = if side > 0.0 {
            &street.lamps_right
        } else {
            &street.lamps_left
        };
        taken.extend(lamps.iter().map(|&z| (z, 3.0)));
        if side < 0.0 {
            taken.extend(street.poles.iter().map(|&z| (z, 1.0)));
        }
        taken.extend(
            street
                .traffic_lights
                .iter()
                .filter(|t| t.side == side)
                .map(|t| (t.z, 1.0)),
        );
        taken.extend(
            street
                .signs
                .iter()
                .filter(|s| s.side == side)
                .map(|s| (s.z, 1.0)),
        );
        let (lo, hi) = (street.far + 8.0, -2.0f32);
        let free = |taken: &mut Vec<(f32, f32)>, rng: &mut ChaCha8Rng, half: f32| {
            for _ in 0..40 {
                let z = rng.random_range(lo.min(hi)..=hi);
                if taken.iter().all(|&(t, e)| (t - z).abs() > e + half + 0.5)
                    && !street.features.in_mouth(side, z, half + 0.5)
                {
                    taken.push((z, half));
                    return Some(z);
                }
            }
            None
        };
        // A bus stop, its open side to the road, where the pavement leaves room to pass.
        if rng.random_bool(config.bus_stops) {
            let (model, depth, half) = match pool.pick(rng, AssetRole::BusStop) {
                Some(a) => {
                    let m = use_asset(a);
                    let (lo, hi) = m.bounds(Affine3A::IDENTITY);
                    (m, hi.z - lo.z, 0.5 * (hi.x - lo.x))
                }
                None => {
                    let spec = BusStopSpec::draw(rng, config);
                    (spec.build(), spec.depth, 0.5 * spec.length)
                }
            };
            if pavement >= depth + 1.0 {
                if let Some(z) = free(&mut taken, rng, half) {
                    furniture.push(Furniture {
                        name: format!("bus_stop_{stops}"),
                        model,
                        x: side * (h + kerb + 0.4 + 0.5 * depth),
                        z,
                    });
                    stops += 1;
                }
            }
        }
        // Trees by the kerb, where the pavement is wide enough.
        let n_trees = (uniform(rng, config.trees) * f64::from(length) / 100.0).round() as usize;
        for _ in 0..n_trees {
            let model = match pool.pick(rng, AssetRole::Tree) {
                Some(a) => use_asset(a),
                None => TreeSpec::draw(rng).build(),
            };
            if pavement < 2.4 {
                continue;
            }
            if let Some(z) = free(&mut taken, rng, 2.0) {
                furniture.push(Furniture {
                    name: format!("tree_{trees}"),
                    model,
                    x: side * (h + kerb + 0.8),
                    z,
                });
                trees += 1;
            }
        }
        // Bollards: beside every crossing, and scattered.
        let n_bollards =
            (uniform(rng, config.bollards) * f64::from(length) / 100.0).round() as usize;
        let at_crossings: Vec<f32> = street
            .features
            .crosswalks
            .iter()
            .flat_map(|c| [c.z - 0.5 * c.length - 0.5, c.z + 0.5 * c.length + 0.5])
            .collect();
        for k in 0..at_crossings.len() + n_bollards {
            let model = match pool.pick(rng, AssetRole::Bollard) {
                Some(a) => use_asset(a),
                None => BollardSpec::draw(rng).build(),
            };
            let z = match at_crossings.get(k) {
                Some(&z) => Some(z),
                None => free(&mut taken, rng, 0.2),
            };
            if let Some(z) = z {
                furniture.push(Furniture {
                    name: format!("bollard_{bollards}"),
                    model,
                    x: side * (h + kerb + 0.3),
                    z,
                });
                bollards += 1;
            }
        }
        // The user's own furniture (benches, bins, planters), against the procedural
        // builder's weight of 1, which places nothing: two places per side.
        for _ in 0..2 {
            if let Some(a) = pool.pick(rng, AssetRole::Furniture) {
                let model = use_asset(a);
                let (lo, hi) = model.bounds(Affine3A::IDENTITY);
                let depth = hi.z - lo.z;
                if pavement < depth + 1.0 {
                    continue;
                }
                if let Some(z) = free(&mut taken, rng, 0.5 * (hi.x - lo.x)) {
                    furniture.push(Furniture {
                        name: format!("furniture_{others}"),
                        model,
                        x: side * (st.facade_x - 0.3 - 0.5 * depth),
                        z,
                    });
                    others += 1;
                }
            }
        }
    }
    street.furniture = furniture;

    // The street lamps' designs, last in the stream: every draw above keeps its value.
    let light = LampLight::from(&street.style);
    // The library's lens is `lens x lens/2` half sizes: the same area as the street's square.
    let lens = std::f32::consts::SQRT_2 * street.style.lens_half.1;
    // The lights stand `lamp_height` above the road, the posts on the pavement.
    let height = street.style.lamp_height - street.style.kerb;
    let mut designs: BTreeMap<LampDesign, usize> = BTreeMap::new();
    street.lamp_models = (0..street.lamps_right.len() + street.lamps_left.len())
        .map(|_| {
            let spec = StreetLampSpec::draw(rng, config, height, lens, Some(light));
            *designs.entry(spec.design).or_default() += 1;
            spec.build()
        })
        .collect();
    Ok((
        kept,
        json!({
            "cars": car_params,
            "trees_placed": trees,
            "bus_stops_placed": stops,
            "bollards_placed": bollards,
            "furniture_placed": others,
            "lamp_designs": designs,
            "assets": assets_used,
        }),
    ))
}
