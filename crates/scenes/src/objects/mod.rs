//! Objects of the street as [`Model`](crate::model::Model)s: vehicles ([`vehicle`]),
//! street furniture ([`furniture`]) and the user's own glTF assets ([`assets`]).
//!
//! Every builder is a pure function from a spec to a model, and every spec is drawn from a
//! seeded `ChaCha8Rng` by a `draw` function with the [`ObjectsConfig`], so an object is
//! reproducible from `(config, seed, index)` like the rest of a sample.
//!
//! Frames: a model is built in its own frame, metres, +X right, +Y up, -Z forward, the
//! origin on the ground at the centre of its footprint (for furniture on a post, the foot
//! of the post). "Forward" is a vehicle's direction of travel, and for furniture the side it
//! shows to traffic (a sign's face, a traffic light's lenses, a lamp's arm reaching over
//! the road, a bus stop's open side): to face a driver looking down -Z, turn it by half a
//! turn about Y.
//!
//! Light levels are physical, as in the rest of the generator: punctual lights in W/sr of
//! luminance (candela / 683) times a colour from [`crate::light_sources`], emitters in
//! W/(m^2 sr) of luminance.

pub mod assets;
pub mod furniture;
pub mod placement;
pub mod vehicle;

use crate::light_sources::{rgb_with_luminance, spectrum_xyz, Spectrum};
use crate::procedural::Range;
use assets::AssetEntry;
use furniture::LampDesign;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use vehicle::BodyType;

/// Peak wavelength of a red LED (tail, brake and red signal lights), nm.
pub const RED_NM: f64 = 625.0;
/// Peak wavelength of an amber LED (indicators, amber signals, bus displays), nm.
pub const AMBER_NM: f64 = 592.0;
/// Peak wavelength of a green signal LED (cyan-green, as road signals are), nm.
pub const GREEN_NM: f64 = 505.0;

/// Linear sRGB of a narrow-band LED peaking at `nm` (one of [`RED_NM`], [`AMBER_NM`],
/// [`GREEN_NM`]) with luminance `y` (clipped to the gamut like the sodium line).
pub fn led_rgb(nm: f64, y: f64) -> [f64; 3] {
    const RED: [(f64, f64); 1] = [(RED_NM, 1.0)];
    const AMBER: [(f64, f64); 1] = [(AMBER_NM, 1.0)];
    const GREEN: [(f64, f64); 1] = [(GREEN_NM, 1.0)];
    let lines: &'static [(f64, f64)] = if nm == RED_NM {
        &RED
    } else if nm == AMBER_NM {
        &AMBER
    } else {
        &GREEN
    };
    rgb_with_luminance(spectrum_xyz(Spectrum::Lines(lines)), y).map(crate::gltf_writer::round7)
}

/// A car paint colour. The default weights follow the colour shares of new cars in
/// Europe (Axalta's Global Automotive Color Popularity Report 2022: white about a third,
/// then black, grey and silver, blue and red under a tenth each).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Paint {
    /// White.
    White,
    /// Black.
    Black,
    /// Mid grey.
    Grey,
    /// Silver (always metallic when metallic paint is drawn).
    Silver,
    /// Dark blue.
    Blue,
    /// Red.
    Red,
    /// Beige or brown.
    Brown,
    /// Dark green.
    Green,
    /// Yellow or gold.
    Yellow,
}

impl Paint {
    /// Linear RGB base colour (the albedo of the paint under its clear coat).
    pub fn rgb(self) -> [f64; 3] {
        match self {
            Paint::White => [0.80, 0.80, 0.78],
            Paint::Black => [0.012, 0.012, 0.014],
            Paint::Grey => [0.16, 0.16, 0.17],
            Paint::Silver => [0.50, 0.51, 0.53],
            Paint::Blue => [0.02, 0.05, 0.22],
            Paint::Red => [0.45, 0.02, 0.02],
            Paint::Brown => [0.25, 0.16, 0.08],
            Paint::Green => [0.03, 0.12, 0.05],
            Paint::Yellow => [0.70, 0.45, 0.03],
        }
    }

    /// Whether the paint may be metallic (white and black are solid here).
    pub fn can_be_metallic(self) -> bool {
        !matches!(self, Paint::White | Paint::Black)
    }
}

/// How the generator draws vehicles and furniture: the `[objects]` table of the generator
/// config. Densities are per 100 m of street side.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ObjectsConfig {
    /// Body types and their weights: `saloon`, `hatchback`, `estate`, `suv`, `van`, `bus`.
    pub body_types: BTreeMap<BodyType, f64>,
    /// Paint colours and their weights.
    pub paints: BTreeMap<Paint, f64>,
    /// Probability that a paint that can be metallic is.
    pub metallic_paint: f64,
    /// Probability that a leading vehicle is braking.
    pub brake_lights: f64,
    /// Luminous intensity of each tail light, candela (UN ECE R7: 4-17 cd on axis).
    pub tail_light_cd: Range,
    /// Luminous intensity of each brake light, candela.
    pub brake_light_cd: Range,
    /// Street lamp designs and their weights: `cobra`, `post_top`, `twin_arm`.
    pub lamp_designs: BTreeMap<LampDesign, f64>,
    /// Trees per 100 m of street side.
    pub trees: Range,
    /// Probability of a bus stop on a street side.
    pub bus_stops: f64,
    /// Bollards per 100 m of street side.
    pub bollards: Range,
    /// Luminance of a lit shop sign, cd/m^2.
    pub shop_sign_luminance: Range,
    /// The user's glTF assets added to the pool.
    pub assets: Vec<AssetEntry>,
}

impl Default for ObjectsConfig {
    fn default() -> Self {
        Self {
            body_types: BTreeMap::from([
                (BodyType::Saloon, 0.25),
                (BodyType::Hatchback, 0.3),
                (BodyType::Estate, 0.15),
                (BodyType::Suv, 0.2),
                (BodyType::Van, 0.07),
                (BodyType::Bus, 0.03),
            ]),
            paints: BTreeMap::from([
                (Paint::White, 0.3),
                (Paint::Black, 0.18),
                (Paint::Grey, 0.17),
                (Paint::Silver, 0.1),
                (Paint::Blue, 0.09),
                (Paint::Red, 0.08),
                (Paint::Brown, 0.03),
                (Paint::Green, 0.03),
                (Paint::Yellow, 0.02),
            ]),
            metallic_paint: 0.6,
            brake_lights: 0.3,
            tail_light_cd: [5.0, 20.0],
            brake_light_cd: [40.0, 100.0],
            lamp_designs: BTreeMap::from([
                (LampDesign::Cobra, 0.6),
                (LampDesign::PostTop, 0.25),
                (LampDesign::TwinArm, 0.15),
            ]),
            trees: [0.0, 8.0],
            bus_stops: 0.2,
            bollards: [0.0, 4.0],
            shop_sign_luminance: [100.0, 600.0],
            assets: Vec::new(),
        }
    }
}

impl ObjectsConfig {
    /// Checks every range, probability and weight table, and each asset entry (not the
    /// files: [`assets::AssetPool::load`] reads them).
    pub fn validate(&self) -> Result<(), String> {
        let check = crate::check::Section("objects");
        check_weights("body_types", &self.body_types)?;
        check_weights("paints", &self.paints)?;
        check_weights("lamp_designs", &self.lamp_designs)?;
        check.prob("metallic_paint", self.metallic_paint)?;
        check.prob("brake_lights", self.brake_lights)?;
        check.range("tail_light_cd", self.tail_light_cd, 0.0, 1e3)?;
        check.range("brake_light_cd", self.brake_light_cd, 0.0, 1e4)?;
        check.range("trees", self.trees, 0.0, 100.0)?;
        check.prob("bus_stops", self.bus_stops)?;
        check.range("bollards", self.bollards, 0.0, 200.0)?;
        check.range("shop_sign_luminance", self.shop_sign_luminance, 0.0, 1e5)?;
        for (k, a) in self.assets.iter().enumerate() {
            a.validate()
                .map_err(|e| format!("objects.assets[{k}] ({}): {e}", a.path.display()))?;
        }
        Ok(())
    }
}

/// Checks a weight table: at least one entry, every weight finite and >= 0, a positive sum.
fn check_weights<K>(name: &str, w: &BTreeMap<K, f64>) -> Result<(), String> {
    if w.is_empty() || w.values().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(format!(
            "objects.{name} must give at least one entry, each with a weight >= 0"
        ));
    }
    if w.values().sum::<f64>() <= 0.0 {
        return Err(format!("objects.{name}: the weights add up to 0"));
    }
    Ok(())
}

/// A key of `weights` drawn with probability proportional to its weight, with one uniform
/// number (as the generator draws its lamp types; the table must pass
/// [`ObjectsConfig::validate`]).
pub fn weighted<K: Copy>(rng: &mut ChaCha8Rng, weights: &BTreeMap<K, f64>) -> K {
    let i = crate::weather::pick(weights.values().copied(), rng.random::<f64>());
    *weights
        .keys()
        .nth(i)
        .expect("pick returns an index of the weights")
}

pub(crate) use crate::procedural::uniform;

pub mod showroom;

#[cfg(test)]
pub(crate) mod checks {
    //! Checks shared by the objects' tests.
    use crate::mesh::Mesh;
    use glam::Vec3;
    use std::collections::HashMap;

    fn key(p: Vec3) -> [i64; 3] {
        (p * 1e4).round().as_i64vec3().to_array()
    }

    /// Every edge of `m`, by position, is used once in each direction: the mesh is closed
    /// and consistently wound (several touching or overlapping closed solids pass).
    pub fn assert_closed(m: &Mesh, what: &str) {
        let mut edges: HashMap<([i64; 3], [i64; 3]), i32> = HashMap::new();
        for t in m.indices.chunks(3) {
            for k in 0..3 {
                let a = key(m.positions[t[k] as usize]);
                let b = key(m.positions[t[(k + 1) % 3] as usize]);
                *edges.entry((a, b)).or_default() += 1;
                *edges.entry((b, a)).or_default() -= 1;
            }
        }
        let open = edges.values().filter(|&&n| n != 0).count();
        assert_eq!(open, 0, "{what}: {open} unmatched edge directions");
    }

    /// The enclosed volume (divergence theorem): positive when the faces point outward.
    pub fn volume(m: &Mesh) -> f32 {
        m.indices
            .chunks(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Every triangle agrees with its vertex normals (the front face is the shaded one).
    pub fn assert_wound_with_normals(m: &Mesh, what: &str) {
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let g = (b - a).cross(c - a);
            for &i in t {
                assert!(
                    g.dot(m.normals[i as usize]) > 0.0,
                    "{what}: triangle {a} {b} {c} against its normals"
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default config is valid (`default.toml`'s `[objects]` is the default: the
    /// generator config's test).
    #[test]
    fn the_default_is_valid() {
        ObjectsConfig::default().validate().unwrap();
    }

    #[test]
    fn bad_values_are_named() {
        let c = ObjectsConfig {
            brake_lights: 1.5,
            ..Default::default()
        };
        let e = c.validate().unwrap_err();
        assert!(e.contains("objects.brake_lights"), "{e}");
        let mut c = ObjectsConfig::default();
        c.paints.clear();
        assert!(c.validate().unwrap_err().contains("objects.paints"));
        let e = toml::from_str::<ObjectsConfig>("trees = [1.0, 2.0]\nfoo = 1\n").unwrap_err();
        assert!(e.to_string().contains("foo"), "{e}");
    }

    /// Weighted draws follow the weights.
    #[test]
    fn weighted_draws_follow_the_weights() {
        use rand::SeedableRng;
        let w = BTreeMap::from([(1u8, 1.0), (2u8, 3.0), (3u8, 0.0)]);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 4000;
        let twos = (0..n).filter(|_| weighted(&mut rng, &w) == 2).count();
        assert!((2800..3200).contains(&twos), "{twos}");
        assert!((0..100).all(|_| weighted(&mut rng, &w) != 3));
    }

    /// A narrow-band LED's colour carries the asked luminance; red has no blue.
    #[test]
    fn led_colours() {
        let red = led_rgb(RED_NM, 2.0);
        assert!((crate::light_sources::luminance(red) - 2.0).abs() < 1e-5);
        assert!(red[0] > 5.0 * red[1] && red[2] == 0.0, "{red:?}");
        let green = led_rgb(GREEN_NM, 1.0);
        assert!(green[1] > green[0], "{green:?}");
    }
}
