//! The generator's weather: rain rate, fog, the camera's sensor preset and exposure time,
//! each drawn from a documented distribution ([`WeatherConfig`], the `[weather]`
//! table of the generator config), and what the rain does to the road.
//!
//! [`draw`] turns a config and two random streams (one per street: rain, fog, sensor; one per
//! sample: exposure, the rain drops' seed) into a [`Weather`]; the rig's velocity, for the
//! motion blur, is the drive's ([`crate::drive`]). The procedural generator
//! writes its fog and rain into the scene's extras (`scenes[0].extras.streaks.fog` and
//! `.rain`, the renderer's scene contract), drives the road's wetness from the rain rate
//! ([`Weather::wetness_level`], [`Weather::ripple_strength`]) and returns the draw for
//! `meta.json`.

use crate::procedural::{uniform, Range};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::BTreeMap;

/// One class of the rain-rate mix: drawn with `probability`, then uniformly in `mm_h`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RainClass {
    /// The class's name, recorded in `meta.json` (`dry`, `drizzle`, ...).
    pub name: String,
    /// Probability of the class (the classes' probabilities add up to 1).
    pub probability: f64,
    /// Rain rate, mm/h.
    pub mm_h: Range,
}

impl RainClass {
    fn new(name: &str, probability: f64, mm_h: Range) -> Self {
        Self {
            name: name.to_owned(),
            probability,
            mm_h,
        }
    }
}

/// Fog: how often, and the medium's parameters (`scenes[0].extras.streaks.fog`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FogConfig {
    /// Probability that a street is foggy.
    pub probability: f64,
    /// Extinction coefficient at road level, 1/m (grey: the same in R, G and B; Koschmieder's
    /// meteorological visibility is `3.912 / sigma_t`).
    pub sigma_t: Range,
    /// Single-scattering albedo.
    pub albedo: Range,
    /// Henyey-Greenstein asymmetry (positive: forward scattering, Mitsuba's convention).
    pub g: Range,
    /// Exponential falloff of the density with height, 1/m (0: homogeneous).
    pub height_falloff: Range,
}

impl Default for FogConfig {
    fn default() -> Self {
        Self {
            probability: 0.2,
            sigma_t: [0.005, 0.04],
            albedo: [0.9, 1.0],
            g: [0.7, 0.9],
            height_falloff: [0.0, 0.2],
        }
    }
}

/// The `[weather]` table: distributions of rain, fog, sensor, exposure and motion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WeatherConfig {
    /// `false`: no weather is drawn or written (no rain, no fog; the road's wetness is drawn
    /// from `[wetness]` alone; `meta.json` has no weather record).
    pub enabled: bool,
    /// The rain-rate mix, one class per entry.
    pub rain: Vec<RainClass>,
    /// Rain drops are placed within this distance of the rig, metres.
    pub rain_radius: f64,
    /// Fog.
    pub fog: FogConfig,
    /// Sensor presets (`streaks render --sensor NAME`) and their weights.
    pub sensor: BTreeMap<String, f64>,
    /// Exposure (shutter) time, seconds.
    pub exposure_s: Range,
}

impl Default for WeatherConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            rain: vec![
                RainClass::new("dry", 0.3, [0.0, 0.0]),
                RainClass::new("drizzle", 0.3, [0.5, 2.0]),
                RainClass::new("moderate", 0.25, [2.0, 10.0]),
                RainClass::new("heavy", 0.15, [10.0, 50.0]),
            ],
            rain_radius: 12.0,
            fog: FogConfig::default(),
            sensor: BTreeMap::from([
                ("automotive_hdr".to_owned(), 0.7),
                ("automotive_linear".to_owned(), 0.3),
            ]),
            exposure_s: [1.0 / 120.0, 1.0 / 30.0],
        }
    }
}

/// A drawn fog (grey).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fog {
    /// Extinction coefficient at road level, 1/m.
    pub sigma_t: f64,
    /// Single-scattering albedo.
    pub albedo: f64,
    /// Henyey-Greenstein asymmetry.
    pub g: f64,
    /// Density falloff with height, 1/m.
    pub height_falloff: f64,
}

/// One sample's drawn weather.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Weather {
    /// The rain class drawn (`dry`, `drizzle`, ...).
    pub rain_class: String,
    /// Rain rate, mm/h (0: no rain in the air).
    pub rain_mm_h: f64,
    /// Seed of the rain drops' placement.
    pub rain_seed: u32,
    /// Radius around the rig within which drops are placed, metres.
    pub rain_radius: f64,
    /// The fog, if any.
    pub fog: Option<Fog>,
    /// The sensor preset.
    pub sensor: String,
    /// Exposure time, seconds.
    pub exposure_s: f64,
    /// The rig's velocity in world space, m/s: the drive's ([`crate::drive::rig_velocity_at`];
    /// [`draw`] leaves it at rest and the generator sets it).
    pub rig_velocity: [f64; 3],
}

/// Rain rate at which the road's wetness is halfway from its driest to its wettest, mm/h.
pub const WETNESS_HALF_RATE_MM_H: f64 = 3.0;
/// Rain rate at which the ripples are halfway to their strongest, mm/h.
pub const RIPPLE_HALF_RATE_MM_H: f64 = 8.0;

/// The share `s(R) = R / (R + R_half)` of the way from the weakest to the strongest effect at
/// rain rate `R`: 0 when dry, 1/2 at `R_half`, towards 1 in a downpour; monotone.
fn saturating(mm_h: f64, half: f64) -> f64 {
    mm_h / (mm_h + half)
}

impl Weather {
    /// The road's global wetness at this rain rate: `level[0]` (the config's driest: a road
    /// drying after rain, puddles left) at 0 mm/h, rising monotonically as
    /// `level[0] + (level[1] - level[0]) R / (R + 3 mm/h)` to `level[1]` (flooding).
    pub fn wetness_level(&self, level: Range) -> f64 {
        level[0] + (level[1] - level[0]) * saturating(self.rain_mm_h, WETNESS_HALF_RATE_MM_H)
    }

    /// The ripple map's strength at this rain rate (`None` when no rain falls: the puddles are
    /// still): `strength[0] + (strength[1] - strength[0]) R / (R + 8 mm/h)`.
    pub fn ripple_strength(&self, strength: Range) -> Option<f64> {
        (self.rain_mm_h > 0.0).then(|| {
            strength[0]
                + (strength[1] - strength[0]) * saturating(self.rain_mm_h, RIPPLE_HALF_RATE_MM_H)
        })
    }

    /// `scenes[0].extras.streaks.fog`, if there is fog.
    pub fn fog_extras(&self) -> Option<serde_json::Value> {
        self.fog.map(|f| {
            json!({
                "sigma_t": f.sigma_t,
                "albedo": f.albedo,
                "g": f.g,
                "height_falloff": f.height_falloff,
            })
        })
    }

    /// `scenes[0].extras.streaks.rain`, if rain falls.
    pub fn rain_extras(&self) -> Option<serde_json::Value> {
        (self.rain_mm_h > 0.0).then(|| {
            json!({
                "rate_mm_h": self.rain_mm_h,
                "seed": self.rain_seed,
                "radius": self.rain_radius,
            })
        })
    }
}

/// Index drawn from `weights` (non-negative, positive sum) with `u` uniform in [0, 1): the
/// first whose cumulative weight exceeds `u` times the total (the last positive one if
/// rounding leaves none).
pub(crate) fn pick(weights: impl Iterator<Item = f64> + Clone, u: f64) -> usize {
    let total: f64 = weights.clone().sum();
    let mut acc = 0.0;
    let mut last = 0;
    for (i, w) in weights.enumerate() {
        if w > 0.0 {
            last = i;
            acc += w;
            if u * total < acc {
                return i;
            }
        }
    }
    last
}

/// Rounds to 7 decimals, so the scene file's numbers read back as written.
fn r7(x: f64) -> f64 {
    crate::gltf_writer::round7(x)
}

/// Draws a sample's weather: rain, fog and sensor from `street` (the street's stream: every
/// pair of a street has the same weather), exposure and the drops' seed from `sample`; the
/// rig's velocity is left at rest for the generator to set.
pub fn draw(config: &WeatherConfig, street: &mut ChaCha8Rng, sample: &mut ChaCha8Rng) -> Weather {
    let class = &config.rain[pick(
        config.rain.iter().map(|c| c.probability),
        street.random::<f64>(),
    )];
    let rain_mm_h = r7(uniform(street, class.mm_h));
    let foggy = street.random::<f64>() < config.fog.probability;
    let fc = &config.fog;
    let fog_draw = Fog {
        sigma_t: r7(uniform(street, fc.sigma_t)),
        albedo: r7(uniform(street, fc.albedo)),
        g: r7(uniform(street, fc.g)),
        height_falloff: r7(uniform(street, fc.height_falloff)),
    };
    let sensor_names: Vec<&String> = config.sensor.keys().collect();
    let sensor = sensor_names[pick(config.sensor.values().copied(), street.random::<f64>())];
    let exposure_s = r7(uniform(sample, config.exposure_s));
    let rain_seed: u32 = sample.random();
    Weather {
        rain_class: class.name.clone(),
        rain_mm_h,
        rain_seed,
        rain_radius: config.rain_radius,
        fog: foggy.then_some(fog_draw),
        sensor: sensor.clone(),
        exposure_s,
        rig_velocity: [0.0; 3],
    }
}

impl WeatherConfig {
    /// Checks every value; the error names the key (`weather.fog.g`, ...).
    pub fn validate(&self) -> Result<(), String> {
        let check = crate::check::Section("weather");
        if self.rain.is_empty() {
            return Err("weather.rain must list at least one class".into());
        }
        let mut sum = 0.0;
        for (i, c) in self.rain.iter().enumerate() {
            check.prob(
                &format!("rain[{i}] ({}).probability", c.name),
                c.probability,
            )?;
            check.range(&format!("rain[{i}] ({}).mm_h", c.name), c.mm_h, 0.0, 500.0)?;
            sum += c.probability;
        }
        if (sum - 1.0).abs() > 1e-6 {
            return Err(format!("weather.rain probabilities add up to {sum}, not 1"));
        }
        if !(self.rain_radius.is_finite() && (1.0..=500.0).contains(&self.rain_radius)) {
            return Err(format!(
                "weather.rain_radius = {} must be in [1, 500] m",
                self.rain_radius
            ));
        }
        let f = &self.fog;
        check.prob("fog.probability", f.probability)?;
        check.range("fog.sigma_t", f.sigma_t, 0.0, 10.0)?;
        check.range("fog.albedo", f.albedo, 0.0, 1.0)?;
        check.range("fog.g", f.g, -0.99, 0.99)?;
        check.range("fog.height_falloff", f.height_falloff, 0.0, 10.0)?;
        if self.sensor.is_empty() {
            return Err("weather.sensor must name at least one preset".into());
        }
        for (name, w) in &self.sensor {
            if name.is_empty() || !(w.is_finite() && *w >= 0.0) {
                return Err(format!(
                    "weather.sensor.{name} = {w}: a preset needs a name and a weight >= 0"
                ));
            }
        }
        if self.sensor.values().sum::<f64>() <= 0.0 {
            return Err("weather.sensor weights add up to 0".into());
        }
        check.range("exposure_s", self.exposure_s, 1e-5, 1.0)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn draws(config: &WeatherConfig, n: u64) -> Vec<Weather> {
        (0..n)
            .map(|i| {
                let mut street = ChaCha8Rng::seed_from_u64(i);
                let mut sample = ChaCha8Rng::seed_from_u64(i + 1_000_000);
                draw(config, &mut street, &mut sample)
            })
            .collect()
    }

    /// The default mix: each rain class with its probability (binomial 4-sigma bounds over
    /// 2000 draws), fog in a fifth, both sensors, values inside their ranges.
    #[test]
    fn defaults_give_the_documented_mix() {
        let config = WeatherConfig::default();
        config.validate().unwrap();
        let all = draws(&config, 2000);
        let n = all.len() as f64;
        for class in &config.rain {
            let k = all.iter().filter(|w| w.rain_class == class.name).count() as f64;
            let sd = (n * class.probability * (1.0 - class.probability)).sqrt();
            assert!(
                (k - n * class.probability).abs() < 4.0 * sd,
                "{}: {k} of {n}",
                class.name
            );
            for w in all.iter().filter(|w| w.rain_class == class.name) {
                assert!((class.mm_h[0]..=class.mm_h[1]).contains(&w.rain_mm_h));
            }
        }
        let foggy = all.iter().filter(|w| w.fog.is_some()).count() as f64;
        assert!((foggy - 0.2 * n).abs() < 4.0 * (n * 0.16).sqrt(), "{foggy}");
        for f in all.iter().filter_map(|w| w.fog) {
            assert!((0.005..=0.04).contains(&f.sigma_t) && (0.7..=0.9).contains(&f.g));
        }
        let hdr = all.iter().filter(|w| w.sensor == "automotive_hdr").count() as f64;
        assert!((hdr - 0.7 * n).abs() < 4.0 * (n * 0.21).sqrt(), "{hdr}");
        assert!(all.iter().any(|w| w.sensor == "automotive_linear"));
        for w in &all {
            assert!((1.0 / 120.0..=1.0 / 30.0 + 1e-7).contains(&w.exposure_s));
            assert_eq!(w.rig_velocity, [0.0; 3]);
            assert_eq!(w.rain_extras().is_some(), w.rain_mm_h > 0.0);
        }
    }

    /// Wetness and ripples rise with the rain rate; a dry street keeps the driest level and
    /// still water.
    #[test]
    fn wetness_rises_monotonically_with_rain() {
        let mut w = draws(&WeatherConfig::default(), 1).remove(0);
        let mut last = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for rate in [0.0, 0.1, 0.5, 2.0, 3.0, 10.0, 50.0, 200.0] {
            w.rain_mm_h = rate;
            let level = w.wetness_level([0.3, 0.9]);
            let ripple = w.ripple_strength([0.05, 0.25]);
            assert!(
                (0.3..=0.9).contains(&level) && level > last.0,
                "{rate}: {level}"
            );
            if rate == 0.0 {
                assert_eq!((level, ripple), (0.3, None));
            } else {
                let r = ripple.unwrap();
                assert!((0.05..0.25).contains(&r) && r > last.1, "{rate}: {r}");
                last.1 = r;
            }
            if rate == WETNESS_HALF_RATE_MM_H {
                assert!((level - 0.6).abs() < 1e-12);
            }
            last.0 = level;
        }
    }

    #[test]
    fn bad_values_are_named() {
        for (edit, needle) in [
            (
                (|c: &mut WeatherConfig| c.rain[0].probability = 0.5) as fn(&mut WeatherConfig),
                "add up",
            ),
            (
                |c| c.rain[1].mm_h = [2.0, 1.0],
                "weather.rain[1] (drizzle).mm_h",
            ),
            (|c| c.rain.clear(), "weather.rain"),
            (|c| c.fog.g = [0.5, 1.5], "weather.fog.g"),
            (|c| c.fog.sigma_t = [-1.0, 0.1], "weather.fog.sigma_t"),
            (|c| c.fog.probability = 2.0, "weather.fog.probability"),
            (|c| c.sensor.clear(), "weather.sensor"),
            (|c| c.exposure_s = [0.0, 0.1], "weather.exposure_s"),
            (|c| c.rain_radius = 0.0, "weather.rain_radius"),
        ] {
            let mut c = WeatherConfig::default();
            edit(&mut c);
            let e = c.validate().unwrap_err();
            assert!(e.contains(needle), "{needle}: {e}");
        }
    }

    #[test]
    fn pick_follows_the_weights() {
        let w = [0.0, 1.0, 0.0, 3.0];
        assert_eq!(pick(w.iter().copied(), 0.0), 1);
        assert_eq!(pick(w.iter().copied(), 0.2499), 1);
        assert_eq!(pick(w.iter().copied(), 0.25), 3);
        assert_eq!(pick(w.iter().copied(), 0.999_999), 3);
    }
}
