//! The procedural night-street generator: varied rainy streets for stereo datasets, each
//! reproducible from `(config, seed, index)` alone.
//!
//! A [`GeneratorConfig`] (TOML; [`GeneratorConfig::default`] is the documented default, and
//! `config/default.toml` beside this crate is the same file with comments) gives a range for
//! every parameter of a [`Street`]: the road's lanes and widths, kerbs and pavements, facades
//! and their lit windows, street lamps (spacing, height, lens size, lamp type, intensity),
//! parked, leading and oncoming cars, traffic lights and signs, wetness (global level, the
//! puddle map's wet and dry specular, ripples as a normal map), the stereo rig (height,
//! lateral position, pitch, baseline, focal length), the PNG exposure, the night sky's glow
//! and the weather ([`crate::weather`]: rain, fog, sensor preset, exposure time, rig speed).
//!
//! Light levels are physical (see `docs/decisions/0030-physical-light-levels-in-the-generator.md`):
//! street luminaires of 8-26 klm, headlights of 7-27 kcd, lit windows and shop windows at the
//! luminances of real ones, an urban sky glow of 15-17 mag/arcsec^2; colours come from the
//! lamps' spectra ([`crate::light_sources`]) at a given luminance.
//!
//! [`sample`] turns `(config, seed, index)` into a [`SampleScene`]: a glTF document named
//! `scene`, the camera to render, the baseline and exposure, the street it belongs to and its
//! split. Samples `index` of one street share everything but the rig's position along the
//! road when `pairs_per_street > 1`, so the train/val/test split is by street. Random numbers
//! come from ChaCha8 streams seeded by a hash of `(seed, street)` for the street and of
//! `(seed, index)` for the rig, so changing one sample never moves another.

use crate::light_sources::{luminance, LightSource};
use crate::street::{Car, Ripples, Sign, Signal, Street, StreetStyle, TrafficLight};
use crate::weather::{Weather, WeatherConfig};
use crate::Error;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::Path;

/// The generator's version, written into datasets: it changes whenever the same
/// `(config, seed, index)` would give a different scene.
pub const GENERATOR_VERSION: &str = concat!(
    "streaks-scenes ",
    env!("CARGO_PKG_VERSION"),
    " procedural/5"
);

/// A closed range `[min, max]` of a real parameter, written `[min, max]` in TOML.
pub type Range = [f64; 2];

/// A closed range of a count, written `[min, max]` in TOML.
pub type CountRange = [u32; 2];

/// The road, pavements and buildings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreetConfig {
    /// Number of lanes (the driver is in the rightmost; lanes left of the centre carry
    /// oncoming traffic).
    pub lanes: CountRange,
    /// Lane width, metres.
    pub lane_width: Range,
    /// Kerb width and height, metres.
    pub kerb: Range,
    /// Pavement width from the kerb to the facades, metres.
    pub pavement: Range,
    /// Length of street modelled ahead of the driver, metres.
    pub length: Range,
    /// Length of one building block along the street, metres.
    pub block_length: Range,
    /// Height of a building block, metres.
    pub block_height: Range,
    /// Factor on the shipped facades' mean diffuse colours (brick, render, concrete).
    pub facade_brightness: Range,
    /// Share of the upper windows that are lit.
    pub lit_windows: Range,
    /// Share of the lit windows that are cool (fluorescent, LED) rather than warm.
    pub cool_windows: Range,
    /// Share of the ground-floor shop windows that are lit.
    pub lit_shops: Range,
    /// Luminance of a lit upper window, cd/m^2 (a curtained room or an office seen from the
    /// street).
    pub window_luminance: Range,
    /// Luminance of a lit shop window, cd/m^2.
    pub shop_luminance: Range,
    /// Probability that the street has telephone poles.
    pub poles: f64,
}

impl Default for StreetConfig {
    fn default() -> Self {
        Self {
            lanes: [2, 4],
            lane_width: [2.8, 3.7],
            kerb: [0.1, 0.18],
            pavement: [1.8, 4.5],
            length: [90.0, 160.0],
            block_length: [8.0, 25.0],
            block_height: [6.0, 20.0],
            facade_brightness: [0.6, 1.4],
            lit_windows: [0.05, 0.45],
            cool_windows: [0.0, 0.4],
            lit_shops: [0.1, 0.8],
            window_luminance: [5.0, 40.0],
            shop_luminance: [50.0, 300.0],
            poles: 0.5,
        }
    }
}

/// The street lamps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LampConfig {
    /// Distance between lamps on one side, metres.
    pub spacing: Range,
    /// Height of the light above the road, metres.
    pub height: Range,
    /// Half size of the lens across the road, metres (along the road it is half of that).
    pub lens: Range,
    /// Lamp types and their weights (one type per street): `low_pressure_sodium`,
    /// `high_pressure_sodium`, `led_2200k`, `led_2700k`, `led_3000k`, `led_4000k`
    /// ([`LightSource`]).
    pub types: BTreeMap<LightSource, f64>,
    /// Luminous intensity of a luminaire in its beam, in W/sr of luminance (candela / 683):
    /// a spot light straight down, uniform to 60 degrees from the nadir and fading out at
    /// 85, plus its lens (a downward Lambertian emitter of the same intensity at the nadir).
    pub intensity: Range,
    /// Probability of lamps on both sides (staggered) rather than on the right only.
    pub both_sides: f64,
}

impl Default for LampConfig {
    fn default() -> Self {
        Self {
            spacing: [20.0, 40.0],
            height: [5.0, 9.0],
            lens: [0.12, 0.35],
            types: BTreeMap::from([
                (LightSource::LowPressureSodium, 0.05),
                (LightSource::HighPressureSodium, 0.35),
                (LightSource::Led2200K, 0.05),
                (LightSource::Led2700K, 0.1),
                (LightSource::Led3000K, 0.25),
                (LightSource::Led4000K, 0.2),
            ]),
            intensity: [1.5, 5.0],
            both_sides: 0.6,
        }
    }
}

/// Cars and their lights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CarConfig {
    /// Parked cars along the kerbs, lights off.
    pub parked: CountRange,
    /// Cars ahead in the driver's direction: tail lights on, headlights on.
    pub ahead: CountRange,
    /// Oncoming cars: headlights (spot lights) on.
    pub oncoming: CountRange,
    /// Headlight luminous intensity on axis, in W/sr of luminance (candela / 683).
    pub headlight_intensity: Range,
    /// Headlight types and their weights (one type per street): `halogen`, `xenon`,
    /// `led_headlight` ([`LightSource`]).
    pub headlight_types: BTreeMap<LightSource, f64>,
}

impl Default for CarConfig {
    fn default() -> Self {
        Self {
            parked: [0, 6],
            ahead: [0, 2],
            oncoming: [0, 2],
            headlight_intensity: [10.0, 40.0],
            headlight_types: BTreeMap::from([
                (LightSource::Halogen, 0.5),
                (LightSource::Xenon, 0.15),
                (LightSource::LedHeadlight, 0.35),
            ]),
        }
    }
}

/// Traffic lights and road signs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrafficConfig {
    /// Traffic lights (red, amber or green at random).
    pub traffic_lights: CountRange,
    /// Signal radiant intensity on axis, W/sr (the spot light the lit signal casts; its lens
    /// is as bright as a 200 mm signal's, about 270 cd).
    pub signal_intensity: Range,
    /// Road signs on posts.
    pub signs: CountRange,
}

impl Default for TrafficConfig {
    fn default() -> Self {
        Self {
            traffic_lights: [0, 2],
            signal_intensity: [0.3, 1.2],
            signs: [0, 4],
        }
    }
}

/// Wetness of the road.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WetnessConfig {
    /// Global wetness in [0, 1]: 0.5 is the shipped streets' balance of puddles, wet
    /// asphalt and drier patches; 1 floods the road. With weather, the rain rate sets it
    /// within this range (the low end when dry, see [`Weather::wetness_level`]).
    pub level: Range,
    /// Asphalt diffuse reflectance.
    pub asphalt_kd: Range,
    /// Specular reflectance of standing water (the puddle map's w = 0).
    pub ks_wet: Range,
    /// GGX alpha of standing water.
    pub alpha_wet: Range,
    /// Specular reflectance of dry asphalt (w = 1).
    pub ks_dry: Range,
    /// GGX alpha of dry asphalt.
    pub alpha_dry: Range,
    /// Probability that rain ripples the road (a normal map); with weather, it ripples
    /// whenever rain falls.
    pub ripples: f64,
    /// Ripple strength (`normalTexture.scale`: the steepest slope); with weather, the rain
    /// rate sets it within this range ([`Weather::ripple_strength`]).
    pub ripple_strength: Range,
    /// Metres covered by one tile of the ripple map.
    pub ripple_tile: Range,
}

impl Default for WetnessConfig {
    fn default() -> Self {
        Self {
            level: [0.3, 0.9],
            asphalt_kd: [0.03, 0.07],
            ks_wet: [0.06, 0.12],
            alpha_wet: [0.01, 0.04],
            ks_dry: [0.03, 0.05],
            alpha_dry: [0.25, 0.45],
            ripples: 0.4,
            ripple_strength: [0.05, 0.25],
            ripple_tile: [0.6, 2.0],
        }
    }
}

/// The vehicle a rig is mounted on: how often it is drawn and how high it carries the rig.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MountConfig {
    /// Relative weight of this vehicle class among the rig's vehicles.
    pub weight: f64,
    /// Height of the rig centre above the road on this vehicle, metres.
    pub height: Range,
}

impl Default for MountConfig {
    fn default() -> Self {
        Self {
            weight: 1.0,
            height: [1.1, 1.5],
        }
    }
}

/// The stereo rig (its centre is the glTF camera `driver`), drawn once per street: a drive
/// keeps its vehicle, lane and mounting.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RigConfig {
    /// Weights of the lanes in the driving direction the rig drives in, the rightmost lane
    /// first; lanes the street does not have are dropped (a street always has one).
    pub lanes: Vec<f64>,
    /// The vehicle classes the rig is mounted on (`car`, `van`, `truck`, or any name), each
    /// with its weight and mounting height.
    pub vehicles: BTreeMap<String, MountConfig>,
    /// Offset from the lane centre to the right, metres.
    pub lateral: Range,
    /// Pitch below the horizon, degrees.
    pub pitch_deg: Range,
    /// Roll about the viewing direction, degrees (positive: clockwise as the camera sees it,
    /// the horizon's right end low).
    pub roll_deg: Range,
    /// Stereo baseline, metres.
    pub baseline: Range,
    /// Focal length as a 35 mm-equivalent (24 mm image height), mm: the vertical field of
    /// view is `2 atan(12 / f)`.
    pub focal_mm35: Range,
    /// Probability that the rig's vehicle drives with its dipped headlights on (a street's
    /// headlight type and intensity, see [`crate::drive::ego_headlights`]).
    pub headlights: f64,
}

impl Default for RigConfig {
    fn default() -> Self {
        let mount = |weight, height| MountConfig { weight, height };
        Self {
            lanes: vec![0.7, 0.3],
            vehicles: BTreeMap::from([
                ("car".to_owned(), mount(0.65, [1.1, 1.5])),
                ("van".to_owned(), mount(0.25, [1.6, 2.2])),
                ("truck".to_owned(), mount(0.1, [2.2, 3.0])),
            ]),
            lateral: [-0.3, 0.3],
            pitch_deg: [0.0, 4.0],
            roll_deg: [-2.0, 2.0],
            baseline: [0.1, 0.4],
            focal_mm35: [24.0, 45.0],
            headlights: 1.0,
        }
    }
}

/// A drive: the frame rate of a street's sequence and the speeds of the rig and of the
/// traffic. Frame `k` of a street is at time `k / fps` seconds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SequenceConfig {
    /// Frames per second.
    pub fps: f64,
    /// The rig's speed along its lane, km/h, drawn per street.
    pub speed_kmh: Range,
    /// Speed of each leading and oncoming car along its lane, km/h, drawn per car (parked
    /// cars stay).
    pub traffic_speed_kmh: Range,
}

impl Default for SequenceConfig {
    fn default() -> Self {
        Self {
            fps: 10.0,
            speed_kmh: [0.0, 50.0],
            traffic_speed_kmh: [10.0, 50.0],
        }
    }
}

/// The PNG exposure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExposureConfig {
    /// Exposure of the 8-bit images, stops.
    pub ev: Range,
}

impl Default for ExposureConfig {
    fn default() -> Self {
        Self { ev: [4.5, 6.5] }
    }
}

/// Shares of the streets in each split.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SplitConfig {
    /// Training share.
    pub train: f64,
    /// Validation share.
    pub val: f64,
    /// Test share.
    pub test: f64,
}

impl Default for SplitConfig {
    fn default() -> Self {
        Self {
            train: 0.8,
            val: 0.1,
            test: 0.1,
        }
    }
}

/// How samples group into streets and splits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DatasetConfig {
    /// Consecutive samples rendered from one street: the frames of a drive along it, at
    /// `[sequence]`'s frame rate.
    pub pairs_per_street: u32,
    /// Shares of the streets in the train, val and test splits.
    pub split: SplitConfig,
}

impl Default for DatasetConfig {
    fn default() -> Self {
        Self {
            pairs_per_street: 1,
            split: SplitConfig::default(),
        }
    }
}

/// The generator's configuration: a range for every parameter. Every table and key is
/// optional in the TOML file; what is left out keeps its default.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GeneratorConfig {
    /// Road, pavements and buildings.
    pub street: StreetConfig,
    /// Street lamps.
    pub lamps: LampConfig,
    /// Cars.
    pub cars: CarConfig,
    /// Traffic lights and signs.
    pub traffic: TrafficConfig,
    /// Wetness.
    pub wetness: WetnessConfig,
    /// The stereo rig.
    pub rig: RigConfig,
    /// PNG exposure.
    pub exposure: ExposureConfig,
    /// Streets and splits.
    pub dataset: DatasetConfig,
    /// Drives: frame rate and speeds.
    pub sequence: SequenceConfig,
    /// The night sky's glow, an environment light.
    pub sky: SkyConfig,
    /// Rain, fog, sensor, exposure time and motion.
    pub weather: WeatherConfig,
    /// The buildings along the street: storeys, setbacks, windows, balconies, shop fronts,
    /// wall materials.
    pub buildings: crate::buildings::BuildingsConfig,
    /// The road's layout (bends, grades, cross profile) and surface (potholes, ruts, tram
    /// tracks, crossings, paint).
    pub road: crate::road::RoadConfig,
    /// Vehicles and street furniture as models, and the user's own glTF assets.
    pub objects: crate::objects::ObjectsConfig,
}

/// The night sky's glow: a constant environment light of radiance `color * glow` (W/(m^2 sr)),
/// written in each sample's `scene.gltf` as `scenes[0].extras.streaks.environment`, so that
/// the sample is rendered with it and the file says so. The default is an overcast city sky
/// lit from below by its streets: 0.016-0.11 cd/m^2 (17 to 15 mag/arcsec^2, the range Puschnig
/// et al. 2014 measured over Vienna; clouds brighten a city's sky), orange-pink.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkyConfig {
    /// `false`: no environment is written (the sky is black).
    pub enabled: bool,
    /// The glow's radiance, drawn per street (times the colour, whose luminance is 0.79).
    pub glow: Range,
    /// Its linear RGB colour (a city's sodium-orange or a moonlit blue).
    pub color: [f64; 3],
}

impl Default for SkyConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            glow: [3e-5, 2e-4],
            color: [1.0, 0.75, 0.55],
        }
    }
}

/// The documented default config, with comments (the same values as
/// [`GeneratorConfig::default`]; a test checks it).
pub const DEFAULT_CONFIG_TOML: &str = include_str!("../config/default.toml");

impl GeneratorConfig {
    /// Parses a TOML config and checks its ranges; `origin` names the source in errors.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, Error> {
        let config: Self = toml::from_str(text).map_err(|e| Error::Config {
            origin: origin.to_owned(),
            reason: e.to_string(),
        })?;
        config.validate().map_err(|reason| Error::Config {
            origin: origin.to_owned(),
            reason,
        })?;
        Ok(config)
    }

    /// Reads and checks a TOML config file.
    pub fn from_toml_file(path: &Path) -> Result<Self, Error> {
        let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
            .map_err(|source| Error::Read {
                path: path.to_path_buf(),
                source,
            })?;
        let mut config = Self::from_toml_str(&text, &path.display().to_string())?;
        // Asset paths are relative to the config file.
        let dir = crate::objects::assets::config_dir(path);
        for a in &mut config.objects.assets {
            if a.path.is_relative() {
                a.path = dir.join(&a.path);
            }
        }
        Ok(config)
    }

    /// The config as TOML (every key, no comments).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_else(|e| format!("# cannot serialise the config: {e}\n"))
    }

    /// The config as JSON (for `dataset.json` and the samples' metadata).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }

    /// Checks every range (`min <= max`, finite, within physical bounds) and probability.
    pub fn validate(&self) -> Result<(), String> {
        let check = crate::check::Section("");
        let weights = |name: &str, w: &BTreeMap<LightSource, f64>| -> Result<(), String> {
            if w.is_empty() || w.values().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(format!(
                    "{name} must give at least one type, each with a weight >= 0"
                ));
            }
            if w.values().sum::<f64>() <= 0.0 {
                return Err(format!("{name}: the weights add up to 0"));
            }
            Ok(())
        };
        let s = &self.street;
        check.count("street.lanes", s.lanes, 8)?;
        if s.lanes[0] == 0 {
            return Err("street.lanes must be at least 1".into());
        }
        check.range("street.lane_width", s.lane_width, 2.0, 6.0)?;
        check.range("street.kerb", s.kerb, 0.02, 0.5)?;
        check.range("street.pavement", s.pavement, 0.5, 20.0)?;
        check.range("street.length", s.length, 30.0, 500.0)?;
        check.range("street.block_length", s.block_length, 3.0, 200.0)?;
        check.range("street.block_height", s.block_height, 2.5, 200.0)?;
        check.range("street.facade_brightness", s.facade_brightness, 0.0, 3.0)?;
        check.range("street.lit_windows", s.lit_windows, 0.0, 1.0)?;
        check.range("street.cool_windows", s.cool_windows, 0.0, 1.0)?;
        check.range("street.lit_shops", s.lit_shops, 0.0, 1.0)?;
        check.range("street.window_luminance", s.window_luminance, 0.0, 1e5)?;
        check.range("street.shop_luminance", s.shop_luminance, 0.0, 1e5)?;
        check.prob("street.poles", s.poles)?;
        let l = &self.lamps;
        check.range("lamps.spacing", l.spacing, 5.0, 500.0)?;
        check.range("lamps.height", l.height, 3.0, 20.0)?;
        check.range("lamps.lens", l.lens, 0.02, 1.0)?;
        weights("lamps.types", &l.types)?;
        check.range("lamps.intensity", l.intensity, 0.0, 1e6)?;
        check.prob("lamps.both_sides", l.both_sides)?;
        let c = &self.cars;
        check.count("cars.parked", c.parked, 40)?;
        check.count("cars.ahead", c.ahead, 8)?;
        check.count("cars.oncoming", c.oncoming, 8)?;
        check.range("cars.headlight_intensity", c.headlight_intensity, 0.0, 1e5)?;
        weights("cars.headlight_types", &c.headlight_types)?;
        let t = &self.traffic;
        check.count("traffic.traffic_lights", t.traffic_lights, 8)?;
        check.range("traffic.signal_intensity", t.signal_intensity, 0.0, 1e5)?;
        check.count("traffic.signs", t.signs, 20)?;
        let w = &self.wetness;
        check.range("wetness.level", w.level, 0.0, 1.0)?;
        check.range("wetness.asphalt_kd", w.asphalt_kd, 0.0, 1.0)?;
        check.range("wetness.ks_wet", w.ks_wet, 0.0, 1.0)?;
        check.range("wetness.alpha_wet", w.alpha_wet, 0.001, 1.0)?;
        check.range("wetness.ks_dry", w.ks_dry, 0.0, 1.0)?;
        check.range("wetness.alpha_dry", w.alpha_dry, 0.001, 1.0)?;
        check.prob("wetness.ripples", w.ripples)?;
        check.range("wetness.ripple_strength", w.ripple_strength, 0.0, 2.0)?;
        check.range("wetness.ripple_tile", w.ripple_tile, 0.05, 20.0)?;
        let r = &self.rig;
        if r.lanes.is_empty() || r.lanes.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(format!(
                "rig.lanes = {:?} must give at least one lane weight, each >= 0",
                r.lanes
            ));
        }
        if r.lanes[0] <= 0.0 {
            return Err(format!(
                "rig.lanes = {:?}: the rightmost lane's weight must be > 0 (every street has it)",
                r.lanes
            ));
        }
        if r.vehicles.is_empty() || r.vehicles.values().all(|m| m.weight <= 0.0) {
            return Err("rig.vehicles must give at least one vehicle with a weight > 0".into());
        }
        for (name, m) in &r.vehicles {
            if !(m.weight.is_finite() && m.weight >= 0.0) {
                return Err(format!(
                    "rig.vehicles.{name}.weight = {} must be >= 0",
                    m.weight
                ));
            }
            check.range(&format!("rig.vehicles.{name}.height"), m.height, 0.2, 10.0)?;
        }
        check.range("rig.lateral", r.lateral, -3.0, 3.0)?;
        check.range("rig.pitch_deg", r.pitch_deg, -30.0, 30.0)?;
        check.range("rig.roll_deg", r.roll_deg, -30.0, 30.0)?;
        check.range("rig.baseline", r.baseline, 0.001, 5.0)?;
        check.range("rig.focal_mm35", r.focal_mm35, 8.0, 400.0)?;
        check.prob("rig.headlights", r.headlights)?;
        let q = &self.sequence;
        if !(q.fps.is_finite() && (0.1..=1000.0).contains(&q.fps)) {
            return Err(format!("sequence.fps = {} must be in [0.1, 1000]", q.fps));
        }
        check.range("sequence.speed_kmh", q.speed_kmh, 0.0, 250.0)?;
        check.range(
            "sequence.traffic_speed_kmh",
            q.traffic_speed_kmh,
            0.0,
            250.0,
        )?;
        check.range("exposure.ev", self.exposure.ev, -20.0, 20.0)?;
        let d = &self.dataset;
        if d.pairs_per_street == 0 || d.pairs_per_street > 100 {
            return Err(format!(
                "dataset.pairs_per_street = {} must be in 1..=100",
                d.pairs_per_street
            ));
        }
        let sp = &d.split;
        for (name, v) in [("train", sp.train), ("val", sp.val), ("test", sp.test)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("dataset.split.{name} = {v} must be a share >= 0"));
            }
        }
        let sum = sp.train + sp.val + sp.test;
        if (sum - 1.0).abs() > 1e-6 {
            return Err(format!(
                "dataset.split shares add up to {sum}, not 1 (train {}, val {}, test {})",
                sp.train, sp.val, sp.test
            ));
        }
        self.weather.validate()?;
        self.buildings.validate()?;
        self.road.validate()?;
        self.objects.validate()?;
        {
            let sky = &self.sky;
            check.range("sky.glow", sky.glow, 0.0, 100.0)?;
            if !sky
                .color
                .iter()
                .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
            {
                return Err(format!(
                    "sky.color = {:?} must lie within [0, 1]",
                    sky.color
                ));
            }
        }
        Ok(())
    }
}

/// A dataset split.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Split {
    /// Training.
    Train,
    /// Validation.
    Val,
    /// Test (held back).
    Test,
}

impl Split {
    /// All splits, in file order.
    pub const ALL: [Split; 3] = [Split::Train, Split::Val, Split::Test];

    /// `train`, `val` or `test` (the names of `splits/*.txt`).
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Val => "val",
            Split::Test => "test",
        }
    }
}

impl std::fmt::Display for Split {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One dataset sample's scene, ready to write and render.
#[derive(Debug)]
pub struct SampleScene {
    /// The glTF document, named `scene` (`doc.write(dir)` writes `scene.gltf`, `scene.bin`
    /// and `scene_*.png`).
    pub doc: crate::gltf_writer::Doc,
    /// The camera node to render: the stereo rig's centre.
    pub camera: String,
    /// Stereo baseline, metres.
    pub baseline: f32,
    /// Exposure of the 8-bit images, stops.
    pub exposure_ev: f32,
    /// The street this sample belongs to (`index / pairs_per_street`).
    pub street: u64,
    /// The street's split.
    pub split: Split,
    /// Every drawn parameter, for `meta.json`.
    pub params: serde_json::Value,
    /// The drawn weather (`None` when the config's weather is disabled): its fog and rain are
    /// in the scene's extras; the sensor preset, exposure time and rig velocity are for the
    /// render and `meta.json`.
    pub weather: Option<Weather>,
    /// The frame of the street's drive this sample is (`index % pairs_per_street`).
    pub frame: u64,
    /// The frame's time in the drive, seconds (`frame / fps`).
    pub time_s: f64,
    /// The rig centre's world pose at the frame's time (the camera `driver`, before the
    /// glTF's rounding).
    pub world_from_rig: glam::Affine3A,
    /// The objects that move during the drive (leading and oncoming cars), with their poses at
    /// the frame's time.
    pub objects: Vec<crate::drive::MovingObject>,
}

/// Camera node name of generated streets.
pub const CAMERA: &str = "driver";

/// A 64-bit mix (SplitMix64's finaliser) of a seed, a stream tag and a number.
fn mix(seed: u64, tag: u64, n: u64) -> u64 {
    let mut z = seed
        .wrapping_add(tag.wrapping_mul(0x9e37_79b9_7f4a_7c15))
        .wrapping_add(n.wrapping_mul(0xbf58_476d_1ce4_e5b9));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

const STREET_STREAM: u64 = 1;
const RIG_STREAM: u64 = 2;
const SPLIT_STREAM: u64 = 3;
const SKY_STREAM: u64 = 4;
const WEATHER_STREAM: u64 = 5;
const CAMERA_STREAM: u64 = 6;
const MOTION_STREAM: u64 = 7;
const ROAD_STREAM: u64 = 8;
const OBJECTS_STREAM: u64 = 9;

/// The lamps' beam: a spot light straight down, full intensity to 60 degrees from the nadir,
/// none beyond 85 (a road luminaire's wide, cut-off distribution).
const LAMP_CONE_DEG: (f64, f64) = (60.0, 85.0);

/// Draws one key of `weights` (non-negative, positive sum) with one uniform number.
fn weighted<K: Copy>(rng: &mut ChaCha8Rng, weights: &BTreeMap<K, f64>) -> K {
    let i = crate::weather::pick(weights.values().copied(), rng.random::<f64>());
    *weights
        .keys()
        .nth(i)
        .expect("pick returns an index of the weights")
}

/// A number drawn uniformly in `r` (`r[0]`, without a draw, when the range is one value).
pub(crate) fn uniform(rng: &mut ChaCha8Rng, r: Range) -> f64 {
    if r[1] > r[0] {
        rng.random_range(r[0]..=r[1])
    } else {
        r[0]
    }
}

fn count(rng: &mut ChaCha8Rng, r: CountRange) -> u32 {
    rng.random_range(r[0]..=r[1])
}

/// Positions along the road from `start` towards `far` every `spacing` metres (at least
/// `start` itself).
fn along(start: f32, spacing: f32, far: f32) -> Vec<f32> {
    let mut z = start;
    let mut out = vec![start];
    z -= spacing;
    while z > far + 3.0 {
        out.push(z);
        z -= spacing;
    }
    out
}

/// Picks `n` positions in `[lo, hi]` (lo < hi <= 0) at least `gap` apart, or fewer if they
/// do not fit after a bounded number of tries.
fn spaced(rng: &mut ChaCha8Rng, n: u32, lo: f32, hi: f32, gap: f32) -> Vec<f32> {
    let mut out: Vec<f32> = Vec::new();
    let mut tries = 0;
    while (out.len() as u32) < n && tries < 50 * (n + 1) && hi > lo {
        tries += 1;
        let z = rng.random_range(lo..=hi);
        if out.iter().all(|o| (o - z).abs() >= gap) {
            out.push(z);
        }
    }
    out.sort_by(|a, b| b.total_cmp(a));
    out
}

/// Builds sample `index` of the dataset `(config, seed)`: frame `index % pairs_per_street`
/// of street `index / pairs_per_street` ([`street_frame`]).
pub fn sample(config: &GeneratorConfig, seed: u64, index: u64) -> Result<SampleScene, Error> {
    let per_street = u64::from(config.dataset.pairs_per_street.max(1));
    street_frame(config, seed, index / per_street, index % per_street)
}

/// The lane centres in the driving direction, rightmost first: the lanes whose centre is
/// right of (or on) the road's centre line.
fn driving_lanes(lanes: u32, lane_width: f32) -> Vec<f32> {
    let road_half = lanes as f32 * lane_width * 0.5;
    (0..lanes)
        .map(|i| road_half - (i as f32 + 0.5) * lane_width)
        .filter(|x| *x >= -1e-4)
        .collect()
}

/// Builds frame `frame` of street `street_id` of the dataset `(config, seed)`: the street at
/// time `frame / fps` with the rig and the moving cars where the drive puts them
/// ([`crate::drive`]). Any frame can be built, also beyond `pairs_per_street` (the flow of a
/// street's last sample needs the scene of the frame after it), and each from
/// `(config, seed, street, frame)` alone.
pub fn street_frame(
    config: &GeneratorConfig,
    seed: u64,
    street_id: u64,
    frame: u64,
) -> Result<SampleScene, Error> {
    config.validate().map_err(|reason| Error::Config {
        origin: "the generator config".into(),
        reason,
    })?;
    let per_street = u64::from(config.dataset.pairs_per_street.max(1));
    let index = street_id * per_street + frame;
    let mut rng = ChaCha8Rng::seed_from_u64(mix(seed, STREET_STREAM, street_id));
    let (mut street, mut params) = random_street(config, &mut rng, seed, street_id)?;
    // The rig, drawn once per street: a drive keeps its vehicle, lane and mounting.
    let mut rig_rng = ChaCha8Rng::seed_from_u64(mix(seed, RIG_STREAM, street_id));
    let rig = &config.rig;
    let vehicle = weighted(
        &mut rig_rng,
        &rig.vehicles
            .iter()
            .map(|(name, m)| (name.as_str(), m.weight))
            .collect(),
    );
    let height = uniform(&mut rig_rng, rig.vehicles[vehicle].height) as f32;
    let lanes = params["street"]["lanes"].as_u64().unwrap_or(1) as u32;
    let lane_width = params["street"]["lane_width"].as_f64().unwrap_or(3.0) as f32;
    let centres = driving_lanes(lanes, lane_width);
    let lane = crate::weather::pick(
        rig.lanes.iter().take(centres.len()).copied(),
        rig_rng.random::<f64>(),
    );
    let lateral = uniform(&mut rig_rng, rig.lateral) as f32;
    let pitch_deg = uniform(&mut rig_rng, rig.pitch_deg);
    let roll_deg = uniform(&mut rig_rng, rig.roll_deg);
    let baseline = uniform(&mut rig_rng, rig.baseline) as f32;
    let focal = uniform(&mut rig_rng, rig.focal_mm35);
    let yfov_deg = (2.0 * (12.0 / focal).atan()).to_degrees();
    let exposure_ev = uniform(&mut rig_rng, config.exposure.ev) as f32;
    let ego_lit = rig_rng.random::<f64>() < rig.headlights;
    // The drive's speeds in a stream of their own.
    let sq = &config.sequence;
    let mut motion_rng = ChaCha8Rng::seed_from_u64(mix(seed, MOTION_STREAM, street_id));
    let speed_kmh = uniform(&mut motion_rng, sq.speed_kmh);
    let drive = crate::drive::Drive {
        lateral: centres.get(lane).copied().unwrap_or(0.0) + lateral,
        start: 0.0,
        mount: crate::drive::mount(
            height,
            pitch_deg.to_radians() as f32,
            roll_deg.to_radians() as f32,
        ),
        speed_m_s: speed_kmh / 3.6,
    };
    let time = crate::drive::frame_time(frame, sq.fps);
    let road = street.road.clone();
    let world_from_rig = crate::drive::rig_pose_at(&road, &drive, time);
    let rig_velocity = crate::drive::rig_velocity_at(&road, &drive, time);
    let mut objects = Vec::new();
    let mut car_speeds = Vec::new();
    for (k, car) in street.cars.iter_mut().enumerate() {
        let speed_m_s = uniform(&mut motion_rng, sq.traffic_speed_kmh) / 3.6;
        car_speeds.push(if car.parked { 0.0 } else { speed_m_s });
        if car.parked {
            continue;
        }
        car.z = crate::drive::car_z_at(car, speed_m_s, time);
        let pose = crate::drive::car_pose(&road, car);
        objects.push(crate::drive::MovingObject {
            instance: car_instance(k),
            world_from_object: pose,
            bounds: street
                .car_models
                .get(k)
                .map_or(crate::drive::CAR_BOUNDS, |m| {
                    let (lo, hi) = m.bounds(glam::Affine3A::IDENTITY);
                    [lo, hi]
                }),
        });
    }
    let eye = Vec3::from(world_from_rig.translation);
    street.style.eye = eye;
    street.style.pitch_tan = pitch_deg.to_radians().tan() as f32;
    street.style.camera_pose = Some(world_from_rig);
    street.style.yfov_deg = yfov_deg;
    // The weather in its own streams: a config with weather draws every other parameter as
    // one without; the rain then sets the road's wetness and ripples.
    let weather = config.weather.enabled.then(|| {
        let mut street_rng = ChaCha8Rng::seed_from_u64(mix(seed, WEATHER_STREAM, street_id));
        let mut sample_rng = ChaCha8Rng::seed_from_u64(mix(seed, CAMERA_STREAM, index));
        let mut w = crate::weather::draw(&config.weather, &mut street_rng, &mut sample_rng);
        // Motion blur is the drive's own motion.
        w.rig_velocity = rig_velocity
            .to_array()
            .map(|v| crate::gltf_writer::round7(f64::from(v)));
        let wc = &config.wetness;
        street.style.wetness = w.wetness_level(wc.level) as f32;
        street.style.ripples = w
            .ripple_strength(wc.ripple_strength)
            .map(|strength| Ripples {
                strength: crate::gltf_writer::round7(strength),
                tile_m: uniform(&mut street_rng, wc.ripple_tile) as f32,
                seed: street_rng.random(),
            });
        params["wetness"]["level"] = json!(street.style.wetness);
        params["wetness"]["ripples"] = json!(street
            .style
            .ripples
            .map(|r| json!({"strength": r.strength, "tile_m": r.tile_m})));
        w
    });
    for (c, speed) in params["cars"]
        .as_array_mut()
        .into_iter()
        .flatten()
        .zip(&car_speeds)
    {
        c["speed_m_s"] = json!(speed);
    }
    let mut doc = street.build()?;
    if ego_lit {
        let st = &street.style;
        for light in crate::drive::ego_headlights(
            &road,
            &drive,
            time,
            st.headlight_color,
            st.headlight_intensity,
        ) {
            doc.add_light(&light);
        }
    }
    let sky = &config.sky;
    if sky.enabled && sky.glow[1] > 0.0 {
        // Its own stream: a config with a sky draws every other parameter as one without.
        let mut sky_rng = ChaCha8Rng::seed_from_u64(mix(seed, SKY_STREAM, street_id));
        let glow = uniform(&mut sky_rng, sky.glow);
        let color = sky.color.map(|c| crate::gltf_writer::round7(c * glow));
        doc.set_environment(json!({ "color": color }));
        params["sky"] = json!({
            "glow": glow,
            "color": color,
            "luminance_cd_m2": luminance(color) * crate::gltf_writer::LUMENS_PER_WATT,
        });
    }
    if let Some(w) = &weather {
        if let Some(fog) = w.fog_extras() {
            doc.set_scene_extra("fog", fog);
        }
        if let Some(rain) = w.rain_extras() {
            doc.set_scene_extra("rain", rain);
        }
        params["weather"] = json!(w);
    }
    let split = split_of(config, seed, street_id);
    params["rig"] = json!({
        "eye": eye.to_array(),
        "vehicle": vehicle,
        "height": height,
        "lane": lane,
        "lateral": lateral,
        "pitch_deg": pitch_deg,
        "roll_deg": roll_deg,
        "baseline": baseline,
        "focal_mm35": focal,
        "yfov_deg": yfov_deg,
        "headlights": ego_lit,
        "pair_in_street": frame,
    });
    params["sequence"] = json!({
        "frame": frame,
        "time_s": time,
        "fps": sq.fps,
        "speed_kmh": speed_kmh,
    });
    params["exposure_ev"] = json!(exposure_ev);
    Ok(SampleScene {
        doc,
        camera: CAMERA.to_owned(),
        baseline,
        exposure_ev,
        street: street_id,
        split,
        params,
        weather,
        frame,
        time_s: time,
        world_from_rig,
        objects,
    })
}

/// The instance id of car `k` of a street (ids are > 0; 0 is the static world).
pub fn car_instance(k: usize) -> u32 {
    k as u32 + 1
}

/// The split of street `street_id`: a uniform number from `(seed, street)` against the
/// config's cumulative shares.
fn split_of(config: &GeneratorConfig, seed: u64, street_id: u64) -> Split {
    let u = (mix(seed, SPLIT_STREAM, street_id) >> 11) as f64 / (1u64 << 53) as f64;
    let sp = &config.dataset.split;
    if u < sp.train {
        Split::Train
    } else if u < sp.train + sp.val {
        Split::Val
    } else {
        Split::Test
    }
}

/// Draws a street (everything but the rig) and its parameters as JSON.
fn random_street(
    config: &GeneratorConfig,
    rng: &mut ChaCha8Rng,
    seed: u64,
    street_id: u64,
) -> Result<(Street, serde_json::Value), Error> {
    let sc = &config.street;
    let lanes = count(rng, sc.lanes);
    let lane_width = uniform(rng, sc.lane_width) as f32;
    let road_half = lanes as f32 * lane_width * 0.5;
    let kerb = uniform(rng, sc.kerb) as f32;
    let pavement = uniform(rng, sc.pavement) as f32;
    let facade_x = road_half + kerb + pavement;
    let length = uniform(rng, sc.length) as f32;
    let (near, far) = (10.0f32, -length);
    // The driver keeps to the rightmost lane.
    let driver_lane_x = road_half - 0.5 * lane_width;

    // Lamps.
    let lc = &config.lamps;
    let spacing = uniform(rng, lc.spacing) as f32;
    let lamp_height = uniform(rng, lc.height) as f32;
    let lens = uniform(rng, lc.lens) as f32;
    let lamp_type = weighted(rng, &lc.types);
    let lamp_intensity = uniform(rng, lc.intensity);
    let both_sides = rng.random_bool(lc.both_sides);
    // The first lamp lies within one spacing ahead, and always on the modelled street.
    let first = -rng.random_range(3.0..=spacing.min(length - 5.0).max(3.5));
    let lamps_right = along(first, spacing, far);
    let lamps_left = if both_sides {
        along(first - 0.5 * spacing, spacing, far)
    } else {
        Vec::new()
    };
    // The light's colour at peak 1 and the intensity that gives it the drawn luminance; the
    // lens (2 lens x lens, facing down) at luminance I / area: as bright as the luminaire.
    let round7 = crate::gltf_writer::round7;
    let lamp_color = lamp_type.rgb().map(round7);
    let lamp_power = round7(lamp_intensity / luminance(lamp_color));
    let lens_area = 2.0 * f64::from(lens) * f64::from(lens);
    let lens_radiance = lamp_type
        .rgb_with_luminance(lamp_intensity / lens_area)
        .map(round7);

    // Cars: parked ones in the outer lanes by the kerbs, leading ones in the driver's lane,
    // oncoming ones in the lanes left of the centre.
    let cc = &config.cars;
    let headlight_intensity = uniform(rng, cc.headlight_intensity);
    let headlight_type = weighted(rng, &cc.headlight_types);
    let headlight_color = headlight_type.rgb().map(round7);
    let headlight_power = round7(headlight_intensity / luminance(headlight_color));
    let headlamp_radiance = headlight_type
        .rgb_with_luminance(luminance(StreetStyle::SHIPPED.headlamp_radiance))
        .map(round7);
    let paint = |rng: &mut ChaCha8Rng| -> [f64; 3] {
        const PAINTS: [[f64; 3]; 8] = [
            [0.2, 0.02, 0.02],
            [0.04, 0.06, 0.12],
            [0.5, 0.5, 0.5],
            [0.02, 0.02, 0.02],
            [0.6, 0.6, 0.62],
            [0.05, 0.12, 0.05],
            [0.3, 0.22, 0.05],
            [0.12, 0.12, 0.14],
        ];
        PAINTS[rng.random_range(0..PAINTS.len())]
    };
    let mut cars = Vec::new();
    let n_parked = count(rng, cc.parked);
    for side in [1.0f32, -1.0] {
        let n_side = if side > 0.0 {
            n_parked.div_ceil(2)
        } else {
            n_parked / 2
        };
        for z in spaced(rng, n_side, far + 15.0, -6.0, 6.0) {
            cars.push(Car {
                x: side * (road_half - 1.1),
                z,
                oncoming: rng.random_bool(0.5),
                color: paint(rng),
                headlights: false,
                parked: true,
            });
        }
    }
    // Leading cars keep to the driver's lane centre (parked ones are at its kerb edge).
    let ahead_x = driver_lane_x;
    let n_ahead = count(rng, cc.ahead);
    for z in spaced(rng, n_ahead, -70.0f32.max(far + 20.0), -12.0, 15.0) {
        cars.push(Car {
            x: ahead_x,
            z,
            oncoming: false,
            color: paint(rng),
            headlights: true,
            parked: false,
        });
    }
    if lanes >= 2 {
        let oncoming_x = -road_half + 0.5 * lane_width;
        let n_oncoming = count(rng, cc.oncoming);
        for z in spaced(rng, n_oncoming, -100.0f32.max(far + 20.0), -15.0, 15.0) {
            cars.push(Car {
                x: oncoming_x,
                z,
                oncoming: true,
                color: paint(rng),
                headlights: true,
                parked: false,
            });
        }
    }

    // Traffic lights and signs.
    let tc = &config.traffic;
    let signal_intensity = uniform(rng, tc.signal_intensity);
    let n_traffic_lights = count(rng, tc.traffic_lights);
    let traffic_lights: Vec<TrafficLight> = spaced(rng, n_traffic_lights, far + 20.0, -20.0, 20.0)
        .into_iter()
        .map(|z| TrafficLight {
            z,
            side: if rng.random_bool(0.75) { 1.0 } else { -1.0 },
            signal: [Signal::Red, Signal::Amber, Signal::Green][rng.random_range(0..3)],
        })
        .collect();
    let n_signs = count(rng, tc.signs);
    let signs: Vec<Sign> = spaced(rng, n_signs, far + 10.0, -8.0, 6.0)
        .into_iter()
        .map(|z| {
            const PLATES: [[f64; 3]; 4] = [
                [0.6, 0.05, 0.04],
                [0.03, 0.12, 0.45],
                [0.7, 0.7, 0.68],
                [0.7, 0.55, 0.03],
            ];
            Sign {
                z,
                side: if rng.random_bool(0.5) { 1.0 } else { -1.0 },
                height: rng.random_range(2.0..=2.6),
                half: rng.random_range(0.25..=0.4),
                color: PLATES[rng.random_range(0..PLATES.len())],
            }
        })
        .collect();

    // Poles and buildings.
    let poles = if rng.random_bool(sc.poles) {
        along(-rng.random_range(4.0..=20.0), 25.0, far)
    } else {
        Vec::new()
    };
    let mut blocks = Vec::new();
    let mut covered = 0.0f32;
    while covered < near - far + 20.0 {
        let len = uniform(rng, sc.block_length) as f32;
        let h = uniform(rng, sc.block_height) as f32;
        blocks.push((len, h));
        covered += len;
    }
    let brightness = uniform(rng, sc.facade_brightness);
    let facade_kd = StreetStyle::SHIPPED
        .facade_kd
        .map(|c| c.map(|k| crate::gltf_writer::round7((k * brightness).min(0.9))));
    let lit = uniform(rng, sc.lit_windows) as f32;
    let cool = uniform(rng, sc.cool_windows) as f32;
    let lit_shops = uniform(rng, sc.lit_shops) as f32;
    let lm = crate::gltf_writer::LUMENS_PER_WATT;
    let window_luminance = uniform(rng, sc.window_luminance);
    let shop_luminance = uniform(rng, sc.shop_luminance);
    let window_scale = round7(window_luminance / lm / luminance(crate::street::WINDOW_WARM));
    let shop_radiance = LightSource::Led3000K
        .rgb_with_luminance(shop_luminance / lm)
        .map(round7);

    // Wetness.
    let wc = &config.wetness;
    let wetness = uniform(rng, wc.level) as f32;
    let asphalt_kd = uniform(rng, wc.asphalt_kd);
    let wet = (uniform(rng, wc.ks_wet), uniform(rng, wc.alpha_wet));
    let dry = (uniform(rng, wc.ks_dry), uniform(rng, wc.alpha_dry));
    let ripples = rng.random_bool(wc.ripples).then(|| Ripples {
        strength: crate::gltf_writer::round7(uniform(rng, wc.ripple_strength)),
        tile_m: uniform(rng, wc.ripple_tile) as f32,
        seed: rng.random(),
    });
    let texture_seed: u32 = rng.random();
    let along_texels = ((near - far) * 6.4).max(64.0) as u32;

    let style = StreetStyle {
        road_half,
        lanes,
        kerb,
        facade_x,
        lamp_height,
        lamp_intensity: lamp_power,
        lamp_color,
        lens_half: (0.5 * lens, lens),
        lens_radiance,
        lamp_cone: Some((LAMP_CONE_DEG.0.to_radians(), LAMP_CONE_DEG.1.to_radians())),
        headlight_intensity: headlight_power,
        headlight_color,
        headlamp_radiance,
        signal_intensity,
        wetness,
        asphalt_kd,
        wet,
        dry,
        ripples,
        lit_windows: (lit * (1.0 - cool), lit),
        lit_shops,
        window_scale,
        shop_radiance: Some(shop_radiance),
        facade_kd,
        ..StreetStyle::SHIPPED
    };
    // The road in its own stream: a config with another road draws every other parameter as
    // this one.
    let mut road_rng = ChaCha8Rng::seed_from_u64(mix(seed, ROAD_STREAM, street_id));
    let drawn_road = config.road.draw(&mut road_rng, lanes, lane_width, far);
    let mut street = Street {
        name: "scene",
        description: format!(
            "Procedural rainy night street {street_id} of seed {seed} ({GENERATOR_VERSION})"
        ),
        near,
        far,
        lamps_right: lamps_right.clone(),
        lamps_left: lamps_left.clone(),
        poles: poles.clone(),
        cars: cars.clone(),
        traffic_lights: traffic_lights.clone(),
        signs: signs.clone(),
        blocks: blocks.clone(),
        windows: true,
        seed: texture_seed,
        texture: (64, along_texels.next_power_of_two().min(2048)),
        style,
        drawn_buildings: Some(crate::street::DrawnBuildings {
            config: config.buildings.clone(),
            // Derived rather than drawn, so that the draws after it keep their values.
            seed: u64::from(texture_seed) ^ 0x6275_696c_6469_6e67,
            window_cd: window_luminance,
            shop_cd: shop_luminance,
        }),
        road: drawn_road.road,
        features: drawn_road.features,
        car_models: Vec::new(),
        furniture: Vec::new(),
        lamp_models: Vec::new(),
    };
    // Nothing stands in a side street's mouth.
    {
        let f = &street.features;
        street.lamps_right.retain(|&z| !f.in_mouth(1.0, z, 1.0));
        street.lamps_left.retain(|&z| !f.in_mouth(-1.0, z, 1.0));
        street.poles.retain(|&z| !f.in_mouth(-1.0, z, 1.0));
        street.signs.retain(|s| !f.in_mouth(s.side, s.z, 1.0));
        street
            .traffic_lights
            .retain(|t| !f.in_mouth(t.side, t.z, 1.0));
        street
            .cars
            .retain(|c| !(c.parked && f.in_mouth(c.x.signum(), c.z, 3.0)));
    }
    // Car models and pavement furniture in their own stream.
    let mut objects_rng = ChaCha8Rng::seed_from_u64(mix(seed, OBJECTS_STREAM, street_id));
    let lighting = crate::objects::vehicle::TrafficLighting {
        headlights: crate::objects::vehicle::Headlights {
            source: headlight_type,
            intensity: headlight_intensity,
            lens_luminance: luminance(StreetStyle::SHIPPED.headlamp_radiance),
        },
    };
    let (_, mut objects_params) = crate::objects::placement::place(
        &config.objects,
        &mut objects_rng,
        &mut street,
        &lighting,
    )?;
    let car_models = objects_params
        .as_object_mut()
        .and_then(|o| o.remove("cars"))
        .unwrap_or_default();
    let params = json!({
        "generator": GENERATOR_VERSION,
        "street_id": street_id,
        "street": {
            "lanes": lanes,
            "lane_width": lane_width,
            "road_half_width": road_half,
            "kerb": kerb,
            "pavement": pavement,
            "length": length,
            "driver_lane_x": driver_lane_x,
            "block_lengths": blocks.iter().map(|b| b.0).collect::<Vec<_>>(),
            "facade_brightness": brightness,
            "lit_windows": lit,
            "cool_windows": cool,
            "lit_shops": lit_shops,
            "window_luminance_cd_m2": window_luminance,
            "shop_luminance_cd_m2": shop_luminance,
            "poles": street.poles,
        },
        "lamps": {
            "spacing": spacing,
            "height": lamp_height,
            "lens_half_size": lens,
            "type": lamp_type,
            "cct_k": lamp_type.cct(),
            "color": lamp_color,
            "intensity_w_sr": lamp_intensity,
            "intensity_cd": lamp_intensity * lm,
            "lens_radiance": lens_radiance,
            "right": street.lamps_right,
            "left": street.lamps_left,
        },
        "cars": street.cars.iter().zip(car_models.as_array().into_iter().flatten()).map(|(c, m)| json!({
            "x": c.x,
            "z": c.z,
            "kind": if c.parked { "parked" } else if c.oncoming { "oncoming" } else { "ahead" },
            "model": m,
        })).collect::<Vec<_>>(),
        "objects": objects_params,
        "headlight_intensity_w_sr": headlight_intensity,
        "headlight_type": headlight_type,
        "traffic_lights": street.traffic_lights.iter().map(|t| json!({
            "z": t.z, "side": t.side, "signal": t.signal,
        })).collect::<Vec<_>>(),
        "signal_intensity_w_sr": signal_intensity,
        "signs": street.signs.iter().map(|s| json!({
            "z": s.z, "side": s.side, "height": s.height, "half_size": s.half, "color": s.color,
        })).collect::<Vec<_>>(),
        "wetness": {
            "level": wetness,
            "asphalt_kd": asphalt_kd,
            "ks_wet": wet.0,
            "alpha_wet": wet.1,
            "ks_dry": dry.0,
            "alpha_dry": dry.1,
            "ripples": ripples.map(|r| json!({"strength": r.strength, "tile_m": r.tile_m})),
        },
        "road": drawn_road.params,
        "buildings": street.building_specs().iter().map(|(side, _, b)| json!({
            "side": side,
            "frontage": b.frontage,
            "storeys": b.storeys,
            "height": b.ground_height + b.storeys as f32 * b.storey_height,
            "depth": b.depth,
            "recess": b.recess,
            "bays": b.bays,
            "shop_front": b.shop.is_some(),
            "balconies": b.balconies.is_some(),
            "cornice": b.cornice,
            "wall": format!("{:?}", b.surface),
        })).collect::<Vec<_>>(),
    });
    Ok((street, params))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_toml_is_the_default_config() {
        let parsed = GeneratorConfig::from_toml_str(DEFAULT_CONFIG_TOML, "default.toml").unwrap();
        assert_eq!(parsed, GeneratorConfig::default());
        // And the serialised form reads back.
        let again = GeneratorConfig::from_toml_str(&parsed.to_toml(), "again").unwrap();
        assert_eq!(again, parsed);
    }

    /// The configs the docs' galleries are made with still read.
    #[test]
    fn gallery_configs_read() {
        for (name, text) in [
            ("dry", include_str!("../../../tools/gallery/dry.toml")),
            (
                "drizzle",
                include_str!("../../../tools/gallery/drizzle.toml"),
            ),
            ("heavy", include_str!("../../../tools/gallery/heavy.toml")),
            ("fog", include_str!("../../../tools/gallery/fog.toml")),
        ] {
            let c = GeneratorConfig::from_toml_str(text, name).unwrap();
            assert_eq!(c.sequence.speed_kmh, [28.8, 28.8], "{name}");
        }
    }

    #[test]
    fn partial_configs_keep_defaults_and_bad_ones_say_why() {
        let c = GeneratorConfig::from_toml_str("[lamps]\nspacing = [30, 30]\n", "x.toml").unwrap();
        assert_eq!(c.lamps.spacing, [30.0, 30.0]);
        assert_eq!(c.street, StreetConfig::default());
        for (text, needle) in [
            ("[lamps]\nspacing = [40, 30]\n", "lamps.spacing"),
            ("[lamps]\nspacng = [30, 40]\n", "spacng"),
            ("[dataset.split]\ntrain = 0.5\n", "add up"),
            ("[street]\nlanes = [0, 2]\n", "street.lanes"),
            ("[wetness]\nripples = 1.5\n", "wetness.ripples"),
            ("not toml at all", "x.toml"),
        ] {
            let e = GeneratorConfig::from_toml_str(text, "x.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle) && e.contains("x.toml"), "{text:?}: {e}");
        }
    }

    #[test]
    fn samples_are_reproducible_and_independent() {
        let config = GeneratorConfig::default();
        let gltf = |seed, index| {
            let s = sample(&config, seed, index).unwrap();
            let dir = tempfile::tempdir().unwrap();
            let files = s.doc.write(dir.path()).unwrap();
            files
                .iter()
                .map(|f| std::fs::read(f).unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(gltf(7, 3), gltf(7, 3));
        assert_ne!(gltf(7, 3), gltf(7, 4));
        assert_ne!(gltf(7, 3), gltf(8, 3));
    }

    #[test]
    fn streets_vary_over_the_documented_ranges() {
        let config = GeneratorConfig::default();
        let (mut lanes, mut ripples, mut parked, mut signals) = (
            std::collections::BTreeSet::new(),
            0,
            0,
            std::collections::BTreeSet::new(),
        );
        let mut baselines = Vec::new();
        for i in 0..40 {
            let mut rng = ChaCha8Rng::seed_from_u64(mix(1, STREET_STREAM, i));
            let (street, p) = random_street(&config, &mut rng, 1, i).unwrap();
            let lights = street.lamps_right.len()
                + street.lamps_left.len()
                + street.traffic_lights.len()
                + 2 * street.cars.iter().filter(|c| !c.parked).count();
            let baseline = sample(&config, 1, i).unwrap().baseline;
            lanes.insert(p["street"]["lanes"].as_u64().unwrap());
            ripples += usize::from(!p["wetness"]["ripples"].is_null());
            parked += p["cars"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|c| c["kind"] == "parked")
                .count();
            for t in p["traffic_lights"].as_array().unwrap() {
                signals.insert(t["signal"].as_str().unwrap().to_owned());
            }
            baselines.push(baseline);
            assert!((0.1..=0.4).contains(&baseline));
            let kind: LightSource = serde_json::from_value(p["lamps"]["type"].clone()).unwrap();
            assert!(config.lamps.types.contains_key(&kind), "{kind}");
            assert!(lights >= 2, "street {i}: {lights} lights");
        }
        assert_eq!(lanes.len(), 3, "{lanes:?}");
        assert!(
            ripples > 5 && ripples < 35,
            "{ripples} rippled streets of 40"
        );
        assert!(parked > 20, "{parked} parked cars in 40 streets");
        assert_eq!(signals.len(), 3, "{signals:?}");
        let spread = baselines.iter().fold(0.0f32, |m, b| m.max(*b))
            - baselines.iter().fold(1.0f32, |m, b| m.min(*b));
        assert!(spread > 0.2, "baselines spread {spread}");
    }

    #[test]
    fn pairs_of_a_street_share_it_and_its_split() {
        let mut config = GeneratorConfig::default();
        config.dataset.pairs_per_street = 3;
        let a = sample(&config, 5, 3).unwrap();
        let b = sample(&config, 5, 5).unwrap();
        let c = sample(&config, 5, 6).unwrap();
        assert_eq!((a.street, b.street, c.street), (1, 1, 2));
        assert_eq!(a.split, b.split);
        assert_eq!(a.params["street"], b.params["street"]);
        assert_eq!(a.params["lamps"], b.params["lamps"]);
        assert_ne!(a.params["rig"], b.params["rig"]);
    }

    #[test]
    fn splits_follow_the_shares() {
        let config = GeneratorConfig::default();
        let mut n = [0usize; 3];
        for index in 0..300u64 {
            let split = split_of(&config, 9, index);
            n[Split::ALL.iter().position(|s| *s == split).unwrap()] += 1;
        }
        // 80/10/10 of 300: binomial standard deviations about 7 and 5.
        assert!(n[0] > 210 && n[0] < 270, "{n:?}");
        assert!(n[1] > 12 && n[2] > 12, "{n:?}");
    }

    /// The scene's glTF as JSON and the sample's parameters and weather.
    fn read(config: &GeneratorConfig) -> (serde_json::Value, SampleScene) {
        let s = sample(config, 7, 3).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let files = s.doc.write(dir.path()).unwrap();
        let gltf = files
            .iter()
            .find(|f| f.extension().is_some_and(|e| e == "gltf"));
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(gltf.unwrap()).unwrap()).unwrap();
        (json, s)
    }

    /// A generated street's lamps are library designs (each counted in `meta.json`, each with
    /// its lights), its markings bead paint measuring the drawn `R_L`, and the rig's vehicle
    /// has its two headlights; with `rig.headlights = 0` it has none, and every other light
    /// is the same.
    #[test]
    fn generated_streets_have_lamp_designs_bead_paint_and_headlights() {
        let config = GeneratorConfig::default();
        let (gltf, s) = read(&config);
        let names: Vec<&str> = gltf["extensions"]["KHR_lights_punctual"]["lights"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["name"].as_str().unwrap())
            .collect();
        let designs = s.params["objects"]["lamp_designs"].as_object().unwrap();
        let lamps: u64 = designs.values().map(|v| v.as_u64().unwrap()).sum();
        let twin = designs.get("twin_arm").map_or(0, |v| v.as_u64().unwrap());
        let lamp_lights = names
            .iter()
            .filter(|n| n.starts_with("street_lamp_"))
            .count();
        assert!(lamps > 0);
        assert_eq!(lamp_lights as u64, lamps + twin, "{names:?}");
        let ego: Vec<_> = names
            .iter()
            .filter(|n| n.starts_with("ego_headlight_"))
            .collect();
        assert_eq!(ego.len(), 2, "{names:?}");
        assert_eq!(s.params["rig"]["headlights"], true);
        let paint = gltf["materials"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == "road_paint")
            .expect("painted markings");
        let rl = s.params["road"]["paint_rl_mcd"].as_f64().unwrap();
        let kr = paint["extras"]["streaks"]["kr"][0].as_f64().unwrap();
        let want = crate::gltf_writer::Beads::for_rl(rl).kr;
        assert!(rl > 0.0 && (kr - want).abs() < 1e-9, "{kr} vs {want}");
        let dark = GeneratorConfig {
            rig: RigConfig {
                headlights: 0.0,
                ..RigConfig::default()
            },
            ..GeneratorConfig::default()
        };
        let (gltf_dark, s_dark) = read(&dark);
        let dark_names: Vec<&str> = gltf_dark["extensions"]["KHR_lights_punctual"]["lights"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["name"].as_str().unwrap())
            .collect();
        let others: Vec<&&str> = names.iter().filter(|n| !n.starts_with("ego_")).collect();
        assert_eq!(dark_names.iter().collect::<Vec<_>>(), others);
        assert_eq!(s_dark.params["rig"]["headlights"], false);
        assert_eq!(s_dark.params["road"], s.params["road"]);
    }

    /// Removes `scenes[0].extras.streaks.KEY`.
    fn without(mut gltf: serde_json::Value, key: &str) -> serde_json::Value {
        if let Some(streaks) = gltf["scenes"][0]["extras"]["streaks"].as_object_mut() {
            streaks.remove(key);
            if streaks.is_empty() {
                gltf["scenes"][0]["extras"]
                    .as_object_mut()
                    .unwrap()
                    .remove("streaks");
            }
        }
        gltf
    }

    /// The sky glow is on by default and written in the scene's extras; it draws everything
    /// else as a config without it; bad skies say why.
    #[test]
    fn a_sky_glow_is_written_in_the_scene_and_changes_nothing_else() {
        let mut config = GeneratorConfig::default();
        config.weather.enabled = false;
        let (glowing, s) = read(&config);
        let env = &glowing["scenes"][0]["extras"]["streaks"]["environment"]["color"];
        let rgb: [f64; 3] = serde_json::from_value(env.clone()).unwrap();
        let cd_m2 = luminance(rgb) * 683.0;
        assert!((0.015..=0.12).contains(&cd_m2), "{rgb:?}: {cd_m2} cd/m^2");
        assert!(rgb[0] > rgb[1] && rgb[1] > rgb[2], "orange-pink: {rgb:?}");
        assert_eq!(s.params["sky"]["color"], json!(rgb));
        config.sky.enabled = false;
        let (dark, dark_s) = read(&config);
        assert!(dark["scenes"][0]["extras"].get("streaks").is_none());
        assert!(dark_s.params.get("sky").is_none());
        assert_eq!(without(glowing, "environment"), dark);
        let fixed = GeneratorConfig::from_toml_str(
            "[sky]\nglow = [0.01, 0.01]\ncolor = [1.0, 0.5, 0.25]\n[weather]\nenabled = false\n",
            "sky.toml",
        )
        .unwrap();
        let (gltf, _) = read(&fixed);
        assert_eq!(
            gltf["scenes"][0]["extras"]["streaks"]["environment"],
            json!({"color": [0.01, 0.005, 0.0025]})
        );
        for (text, needle) in [
            ("[sky]\nglow = [-1, 0.1]\n", "sky.glow"),
            ("[sky]\ncolor = [2, 0, 0]\n", "sky.color"),
        ] {
            let e = GeneratorConfig::from_toml_str(text, "x.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }

    /// Weather draws in its own streams: with it, every parameter but the road's wetness and
    /// ripples is the one drawn without it; its fog and rain are in the scene's extras as the
    /// scene contract has them, and the road's wetness follows the rain rate.
    #[test]
    fn weather_changes_only_the_wetness_and_writes_fog_and_rain() {
        let mut config = GeneratorConfig::default();
        // Rain and fog always, so the extras are there to check.
        config.weather.rain = vec![crate::weather::RainClass {
            name: "heavy".into(),
            probability: 1.0,
            mm_h: [20.0, 20.0],
        }];
        config.weather.fog.probability = 1.0;
        let (wet_gltf, wet) = read(&config);
        let mut plain_config = config.clone();
        plain_config.weather.enabled = false;
        let (dry_gltf, dry) = read(&plain_config);
        assert!(dry.weather.is_none() && dry.params.get("weather").is_none());
        let w = wet.weather.clone().unwrap();
        assert_eq!(w.rain_mm_h, 20.0);
        let streaks = &wet_gltf["scenes"][0]["extras"]["streaks"];
        assert_eq!(
            streaks["rain"],
            json!({"rate_mm_h": 20.0, "seed": w.rain_seed, "radius": config.weather.rain_radius})
        );
        let fog = w.fog.unwrap();
        assert_eq!(
            streaks["fog"],
            json!({"sigma_t": fog.sigma_t, "albedo": fog.albedo, "g": fog.g,
                   "height_falloff": fog.height_falloff})
        );
        // Every parameter but the wetness is the same.
        let strip = |p: &serde_json::Value| {
            let mut p = p.clone();
            let o = p.as_object_mut().unwrap();
            o.remove("weather");
            o.remove("wetness");
            p
        };
        assert_eq!(strip(&wet.params), strip(&dry.params));
        for key in ["asphalt_kd", "ks_wet", "alpha_wet", "ks_dry", "alpha_dry"] {
            assert_eq!(
                wet.params["wetness"][key], dry.params["wetness"][key],
                "{key}"
            );
        }
        let level = wet.params["wetness"]["level"].as_f64().unwrap();
        let expected = 0.3 + 0.6 * 20.0 / 23.0;
        assert!((level - expected).abs() < 1e-6, "{level} vs {expected}");
        assert!(!wet.params["wetness"]["ripples"].is_null());
        assert_eq!(
            (wet.baseline, wet.exposure_ev),
            (dry.baseline, dry.exposure_ev)
        );
        // The glTF differs from the dry one by the extras and the road (material, textures).
        let a = without(without(wet_gltf, "fog"), "rain");
        assert_eq!(a["scenes"][0]["extras"], dry_gltf["scenes"][0]["extras"]);
        assert_eq!(a["nodes"], dry_gltf["nodes"]);
        assert_eq!(a["extensions"], dry_gltf["extensions"]);
        // Pairs of a street share rain and fog; exposure and speed are per sample.
        config.dataset.pairs_per_street = 2;
        config.weather.rain = WeatherConfig::default().rain;
        let a = sample(&config, 3, 4).unwrap().weather.unwrap();
        let b = sample(&config, 3, 5).unwrap().weather.unwrap();
        assert_eq!(
            (a.rain_mm_h, a.fog, &a.sensor),
            (b.rain_mm_h, b.fog, &b.sensor)
        );
        assert_ne!(a.exposure_s, b.exposure_s);
        assert_ne!(a.rain_seed, b.rain_seed);
        let e = GeneratorConfig::from_toml_str("[weather.fog]\ng = [0.5, 1.5]\n", "x.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("weather.fog.g") && e.contains("x.toml"), "{e}");
        let e = GeneratorConfig::from_toml_str("[lamps.types]\nmercury = 1.0\n", "x.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("mercury"), "{e}");
    }

    /// Lights at physical levels: a lamp's luminance (Y of colour x intensity) is the drawn
    /// intensity, its lens is as bright as the luminaire over its area, and the lamp type's
    /// colour is the light's.
    #[test]
    fn lamps_carry_their_photometric_intensity() {
        let config = GeneratorConfig::default();
        for i in 0..20 {
            let s = sample(&config, 11, i).unwrap();
            let p = &s.params["lamps"];
            let kind: LightSource = serde_json::from_value(p["type"].clone()).unwrap();
            let i_y = p["intensity_w_sr"].as_f64().unwrap();
            assert!((1.5..=5.0).contains(&i_y));
            let color: [f64; 3] = serde_json::from_value(p["color"].clone()).unwrap();
            for c in 0..3 {
                assert!((color[c] - kind.rgb()[c]).abs() < 1e-6, "{kind}: {color:?}");
            }
            let lens: [f64; 3] = serde_json::from_value(p["lens_radiance"].clone()).unwrap();
            let half = p["lens_half_size"].as_f64().unwrap();
            let lens_intensity = luminance(lens) * 2.0 * half * half;
            assert!(
                (lens_intensity / i_y - 1.0).abs() < 1e-3,
                "{lens_intensity} vs {i_y}"
            );
        }
        // In the file: every street lamp a downward spot (a post-top lantern: a point light)
        // whose candela times its colour's luminance is the drawn intensity x 683.
        let (gltf, s) = read(&config);
        let i_cd = s.params["lamps"]["intensity_cd"].as_f64().unwrap();
        let lights = gltf["extensions"]["KHR_lights_punctual"]["lights"]
            .as_array()
            .unwrap();
        let lamps: Vec<_> = lights
            .iter()
            .filter(|l| l["name"].as_str().unwrap().starts_with("street_lamp_"))
            .collect();
        assert!(!lamps.is_empty());
        for l in lamps {
            if l["type"] == "spot" {
                let outer = l["spot"]["outerConeAngle"].as_f64().unwrap();
                assert!((outer.to_degrees() - 85.0).abs() < 1e-4, "{outer}");
            } else {
                assert_eq!(l["type"], "point");
            }
            let color: [f64; 3] = serde_json::from_value(l["color"].clone()).unwrap();
            let cd = l["intensity"].as_f64().unwrap() * luminance(color);
            assert!((cd / i_cd - 1.0).abs() < 1e-5, "{cd} cd vs {i_cd}");
        }
    }
}
