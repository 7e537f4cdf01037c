//! Buildings as [`Model`]s: a block with a street facade of storeys, recessed windows with
//! frames, mullions and sills, balconies with railings, shop fronts with lit or dark glass,
//! awnings and lit sign bands, cornices and parapets, drawn from [`BuildingsConfig`] by
//! [`BuildingSpec::draw`] and built by [`facade`].
//!
//! The model's frame: the lot line (the street edge of the plot) is the plane x = 0, the
//! facade faces -X (the road is on the model's left), the frontage runs along Z from
//! `-frontage / 2` to `frontage / 2`, the ground is y = 0 and the block extends to +X. The
//! other side of the street takes the same model turned half a turn about Y ([`placement`]).
//!
//! Walls are built from panels no wider than a bay, each with its own texture offset
//! ([`scatter_uvs`]), so the wall texture does not repeat visibly. Windows are real openings:
//! their reveals, the recessed glass and the frames in front of it catch highlights.

use crate::gltf_writer::{round7, Class, Doc, Material, LUMENS_PER_WATT};
use crate::light_sources::{luminance, LightSource};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::procedural::{uniform, CountRange, Range};
use crate::surfaces::{glass, scatter_uvs, unit, wet_paper, Bond, Surface, Texture};
use crate::Error;
use glam::{Affine3A, Quat, Vec3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The material of a facade's walls, as the config weighs them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WallMaterial {
    /// Brick, in one of three bonds (drawn uniformly).
    Brick,
    /// Render (plaster), painted.
    Plaster,
    /// Cast concrete.
    Concrete,
    /// Stone.
    Stone,
}

/// The distribution of buildings along a street (TOML `[buildings]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BuildingsConfig {
    /// Height of an upper storey, floor to floor, metres.
    pub storey_height: Range,
    /// Height of the ground floor, metres (taller: shops, entrances).
    pub ground_floor_height: Range,
    /// Number of storeys above the ground floor.
    pub storeys: CountRange,
    /// Depth of the block from its front to its back, metres.
    pub depth: Range,
    /// Probability that the whole frontage is recessed behind the lot line.
    pub recess: f64,
    /// How far a recessed frontage lies behind the lot line, metres.
    pub recess_depth: Range,
    /// Probability that the top one or two storeys are set back (a terrace in front).
    pub upper_setback: f64,
    /// How far the upper storeys are set back, metres.
    pub upper_setback_depth: Range,
    /// Width of a bay (window spacing, centre to centre), metres.
    pub bay_width: Range,
    /// Width of a window, metres (at most the bay less 0.5 m of wall).
    pub window_width: Range,
    /// Height of a window, metres (at most the storey less 1 m).
    pub window_height: Range,
    /// Depth of the window reveal, from the wall to the glass, metres.
    pub window_depth: Range,
    /// Probability that the windows have a mullion and a transom.
    pub mullions: f64,
    /// Probability that a building has balconies.
    pub balconies: f64,
    /// Probability that the ground floor is a shop front.
    pub shop_fronts: f64,
    /// Probability that a shop front has awnings.
    pub awnings: f64,
    /// Probability that a shop front's sign band is lit.
    pub lit_signs: f64,
    /// Luminance of a lit sign, cd/m^2.
    pub sign_luminance: Range,
    /// Probability of a cornice at the roof and a string course above the ground floor.
    pub cornice: f64,
    /// Relative weights of the wall materials.
    pub materials: BTreeMap<WallMaterial, f64>,
}

impl Default for BuildingsConfig {
    fn default() -> Self {
        Self {
            storey_height: [2.8, 3.5],
            ground_floor_height: [3.2, 4.5],
            storeys: [1, 6],
            depth: [8.0, 14.0],
            recess: 0.15,
            recess_depth: [0.5, 2.5],
            upper_setback: 0.2,
            upper_setback_depth: [1.5, 3.0],
            bay_width: [2.2, 3.8],
            window_width: [0.8, 1.6],
            window_height: [1.2, 1.9],
            window_depth: [0.1, 0.3],
            mullions: 0.5,
            balconies: 0.35,
            shop_fronts: 0.6,
            awnings: 0.4,
            lit_signs: 0.6,
            sign_luminance: [100.0, 600.0],
            cornice: 0.6,
            materials: BTreeMap::from([
                (WallMaterial::Brick, 0.35),
                (WallMaterial::Plaster, 0.35),
                (WallMaterial::Concrete, 0.15),
                (WallMaterial::Stone, 0.15),
            ]),
        }
    }
}

impl BuildingsConfig {
    /// Checks every value; the error names the key (`buildings.storeys`, ...).
    pub fn validate(&self) -> Result<(), String> {
        let check = crate::check::Section("buildings");
        check.range("storey_height", self.storey_height, 2.4, 6.0)?;
        check.range("ground_floor_height", self.ground_floor_height, 2.6, 8.0)?;
        check.count("storeys", self.storeys, 40)?;
        check.range("depth", self.depth, 3.0, 100.0)?;
        check.prob("recess", self.recess)?;
        check.range("recess_depth", self.recess_depth, 0.0, 10.0)?;
        check.prob("upper_setback", self.upper_setback)?;
        check.range("upper_setback_depth", self.upper_setback_depth, 0.5, 10.0)?;
        if self.upper_setback_depth[1] > self.depth[0] - 2.0 {
            return Err(format!(
                "buildings.upper_setback_depth = {:?} must leave 2 m of the shallowest block \
                 (depth from {} m)",
                self.upper_setback_depth, self.depth[0]
            ));
        }
        check.range("bay_width", self.bay_width, 1.2, 10.0)?;
        check.range("window_width", self.window_width, 0.3, 9.0)?;
        check.range("window_height", self.window_height, 0.3, 5.0)?;
        check.range("window_depth", self.window_depth, 0.02, 1.0)?;
        check.prob("mullions", self.mullions)?;
        check.prob("balconies", self.balconies)?;
        check.prob("shop_fronts", self.shop_fronts)?;
        check.prob("awnings", self.awnings)?;
        check.prob("lit_signs", self.lit_signs)?;
        check.range("sign_luminance", self.sign_luminance, 0.0, 1e5)?;
        check.prob("cornice", self.cornice)?;
        let w = &self.materials;
        if w.is_empty() || w.values().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(
                "buildings.materials must give at least one material, each with a weight >= 0"
                    .into(),
            );
        }
        if w.values().sum::<f64>() <= 0.0 {
            return Err("buildings.materials: the weights add up to 0".into());
        }
        Ok(())
    }
}

/// A shop front on the ground floor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShopFront {
    /// Whether the shop's interior is lit (the glass emits) or dark (reflective glass).
    pub lit: bool,
    /// Whether the bays have awnings.
    pub awning: bool,
    /// Colour of the awnings' fabric (linear RGB).
    pub awning_kd: [f64; 3],
    /// The sign band's lit lettering, its radiance (linear RGB, W/(m^2 sr)); `None`: a
    /// painted, unlit sign.
    pub sign: Option<[f64; 3]>,
}

/// Balconies on the upper storeys.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balconies {
    /// Every `stride`-th bay has one (1 or 2), starting with the first.
    pub stride: u32,
    /// How far they project from the wall, metres.
    pub projection: f32,
    /// Railings of vertical bars (`true`) or solid panels.
    pub bars: bool,
}

/// Everything that makes one building, drawn by [`BuildingSpec::draw`]; [`facade`] builds
/// it (the same spec always gives the same model).
#[derive(Clone, Debug, PartialEq)]
pub struct BuildingSpec {
    /// Length along the street, metres.
    pub frontage: f32,
    /// Depth from the front wall to the back, metres.
    pub depth: f32,
    /// Ground floor height, metres.
    pub ground_height: f32,
    /// Height of each upper storey, metres.
    pub storey_height: f32,
    /// Number of upper storeys.
    pub storeys: u32,
    /// Distance of the front wall behind the lot line (x = 0), metres.
    pub recess: f32,
    /// The top `n` storeys set back by `d` metres: `(n, d)`.
    pub upper_setback: Option<(u32, f32)>,
    /// Number of bays (window columns) across the frontage.
    pub bays: u32,
    /// Window width, metres.
    pub window_width: f32,
    /// Window height, metres.
    pub window_height: f32,
    /// Reveal depth (wall to glass), metres.
    pub window_depth: f32,
    /// Windows have a mullion and a transom.
    pub mullions: bool,
    /// Balconies, if any.
    pub balconies: Option<Balconies>,
    /// The ground floor's shop front, if it is one (else windows and a door).
    pub shop: Option<ShopFront>,
    /// A cornice at the roof and a string course above the ground floor.
    pub cornice: bool,
    /// The wall surface.
    pub surface: Surface,
    /// The wall's mean albedo (linear RGB).
    pub wall_kd: [f64; 3],
    /// Frames, sills, cornices and balcony slabs (linear RGB).
    pub trim_kd: [f64; 3],
    /// Share of the upper windows that are lit.
    pub lit: f32,
    /// Share of the lit windows that are cool rather than warm.
    pub cool: f32,
    /// Seed of the per-window choices (lit or dark) and texture offsets.
    pub seed: u32,
}

/// How lit windows, shops and signs look, and how wet the facades are: shared by the
/// buildings of a street.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    /// The wall textures added to the document.
    pub textures: Vec<Texture>,
    /// Radiance of a lit warm window (linear RGB, W/(m^2 sr)).
    pub warm_window: [f64; 3],
    /// Radiance of a lit cool window.
    pub cool_window: [f64; 3],
    /// Radiance of a lit shop window.
    pub shop_window: [f64; 3],
    /// Wetness of the street in [0, 1] ([`wet_paper`]).
    pub wetness: f32,
}

impl Palette {
    /// Adds one texture per wall surface that `specs` use (seeded by `seed`) to `doc`;
    /// windows of luminance `window_cd` (cd/m^2, warm 2700 K, cool 4000 K) and shop windows
    /// of `shop_cd` (3000 K); facades at `wetness`.
    pub fn new(
        doc: &mut Doc,
        specs: &[BuildingSpec],
        seed: u32,
        (window_cd, shop_cd): (f64, f64),
        wetness: f32,
    ) -> Result<Self, Error> {
        let mut textures: Vec<Texture> = Vec::new();
        for s in specs {
            if !textures.iter().any(|t| t.surface == s.surface) {
                let k = textures.len() as u32;
                textures.push(Texture::add(doc, s.surface, seed.wrapping_add(k))?);
            }
        }
        let rgb = |source: LightSource, cd: f64| {
            source.rgb_with_luminance(cd / LUMENS_PER_WATT).map(round7)
        };
        Ok(Self {
            textures,
            warm_window: rgb(LightSource::Led2700K, window_cd),
            cool_window: rgb(LightSource::Led4000K, window_cd),
            shop_window: rgb(LightSource::Led3000K, shop_cd),
            wetness,
        })
    }
}

/// Saturated sign colours (linear RGB): neon red, blue, green, warm white, amber.
const SIGN_COLOURS: [[f64; 3]; 5] = [
    [1.0, 0.05, 0.04],
    [0.1, 0.3, 1.0],
    [0.1, 1.0, 0.25],
    [1.0, 0.85, 0.7],
    [1.0, 0.45, 0.05],
];

/// Awning fabrics (linear RGB): dark green, wine red, navy, striped-looking beige, grey.
const AWNING_COLOURS: [[f64; 3]; 5] = [
    [0.03, 0.12, 0.05],
    [0.2, 0.02, 0.03],
    [0.02, 0.04, 0.14],
    [0.45, 0.38, 0.25],
    [0.12, 0.12, 0.12],
];

/// Frame and trim colours (linear RGB): white, cream, dark grey, dark green, brown.
const TRIM_COLOURS: [[f64; 3]; 5] = [
    [0.7, 0.7, 0.68],
    [0.6, 0.55, 0.42],
    [0.05, 0.05, 0.05],
    [0.03, 0.08, 0.05],
    [0.1, 0.06, 0.03],
];

impl BuildingSpec {
    /// Draws a building of `frontage` metres from `config`, with `lit` of its upper
    /// windows lit (of which `cool` are cool) and signs and shops lit with the street's
    /// probabilities. Bays divide the frontage evenly; windows fit their bays and storeys.
    pub fn draw(
        rng: &mut ChaCha8Rng,
        config: &BuildingsConfig,
        frontage: f32,
        (lit, cool, lit_shops): (f32, f32, f32),
    ) -> Self {
        let f = |rng: &mut ChaCha8Rng, r: Range| uniform(rng, r) as f32;
        let depth = f(rng, config.depth);
        let ground_height = f(rng, config.ground_floor_height);
        let storey_height = f(rng, config.storey_height);
        let storeys = rng.random_range(config.storeys[0]..=config.storeys[1]);
        let recess = if rng.random_bool(config.recess) {
            f(rng, config.recess_depth)
        } else {
            0.0
        };
        let upper_setback = (rng.random_bool(config.upper_setback) && storeys >= 2).then(|| {
            (
                rng.random_range(1..=2.min(storeys - 1)),
                f(rng, config.upper_setback_depth),
            )
        });
        let bay = f(rng, config.bay_width);
        let bays = ((frontage - 0.6) / bay).floor().max(1.0) as u32;
        let bay = (frontage - 0.6) / bays as f32;
        let window_width = f(rng, config.window_width).min(bay - 0.5).max(0.3);
        let window_height = f(rng, config.window_height)
            .min(storey_height - 1.0)
            .max(0.3);
        let window_depth = f(rng, config.window_depth);
        let mullions = rng.random_bool(config.mullions);
        let balconies = (rng.random_bool(config.balconies) && storeys > 0).then(|| Balconies {
            stride: rng.random_range(1..=2),
            projection: rng.random_range(0.8..=1.4),
            bars: rng.random_bool(0.5),
        });
        let shop = rng.random_bool(config.shop_fronts).then(|| {
            let lit_shop = rng.random::<f32>() < lit_shops;
            let awning = rng.random_bool(config.awnings);
            let awning_kd = AWNING_COLOURS[rng.random_range(0..AWNING_COLOURS.len())];
            let sign_lit = rng.random_bool(config.lit_signs);
            let colour = SIGN_COLOURS[rng.random_range(0..SIGN_COLOURS.len())];
            let cd = uniform(rng, config.sign_luminance);
            let sign = sign_lit.then(|| {
                let y = luminance(colour);
                colour.map(|c| round7(c * cd / LUMENS_PER_WATT / y))
            });
            ShopFront {
                lit: lit_shop,
                awning,
                awning_kd,
                sign,
            }
        });
        let cornice = rng.random_bool(config.cornice);
        let keys: Vec<WallMaterial> = config.materials.keys().copied().collect();
        let material =
            keys[crate::weather::pick(config.materials.values().copied(), rng.random::<f64>())];
        let surface = match material {
            WallMaterial::Brick => Surface::Brick(
                [Bond::Stretcher, Bond::English, Bond::Flemish][rng.random_range(0..3)],
            ),
            WallMaterial::Plaster => Surface::Plaster,
            WallMaterial::Concrete => Surface::Concrete,
            WallMaterial::Stone => Surface::Stone,
        };
        let [lo, hi] = surface.albedo();
        let albedo = rng.random_range(lo..=hi);
        let wall_kd = surface
            .tint(rng.random::<f64>())
            .map(|c| round7((c * albedo).min(0.95)));
        let trim_kd = TRIM_COLOURS[rng.random_range(0..TRIM_COLOURS.len())];
        Self {
            frontage,
            depth,
            ground_height,
            storey_height,
            storeys,
            recess,
            upper_setback,
            bays,
            window_width,
            window_height,
            window_depth,
            mullions,
            balconies,
            shop,
            cornice,
            surface,
            wall_kd,
            trim_kd,
            lit,
            cool,
            seed: rng.random(),
        }
    }

    /// Height of the top of the walls (without parapet), metres.
    pub fn wall_height(&self) -> f32 {
        self.ground_height + self.storeys as f32 * self.storey_height
    }

    /// Height of the parapet above the walls, metres.
    pub fn parapet(&self) -> f32 {
        if self.cornice {
            0.9
        } else {
            0.4
        }
    }

    /// Overall height, metres.
    pub fn height(&self) -> f32 {
        self.wall_height() + self.parapet()
    }

    /// The front wall's x at height `y` (the recess, plus the setback for the upper storeys).
    pub fn front_x(&self, y: f32) -> f32 {
        match self.upper_setback {
            Some((n, d)) if y >= self.setback_y(n) => self.recess + d,
            _ => self.recess,
        }
    }

    /// Height at which the top `n` storeys begin.
    fn setback_y(&self, n: u32) -> f32 {
        self.wall_height() - n as f32 * self.storey_height
    }
}

/// The pose that places a building's model with its lot line at `x = side * lot_x` and its
/// frontage centred on `z`: on the right of the road (`side` > 0) as modelled, on the left
/// turned half a turn about Y so that it faces +X.
pub fn placement(side: f32, lot_x: f32, z: f32) -> Affine3A {
    if side >= 0.0 {
        Affine3A::from_translation(Vec3::new(lot_x, 0.0, z))
    } else {
        Affine3A::from_rotation_translation(
            Quat::from_rotation_y(std::f32::consts::PI),
            Vec3::new(-lot_x, 0.0, z),
        )
    }
}

/// The meshes of a facade, one per material and class.
#[derive(Default)]
struct Parts {
    wall: Mesh,
    trim: Mesh,
    glass: Mesh,
    warm: Mesh,
    cool: Mesh,
    shop: Mesh,
    sign: Mesh,
    door: Mesh,
    roof: Mesh,
    railing: Mesh,
    awning: Mesh,
    streaks: Mesh,
}

/// A quad on a plane x = const facing -X, spanning z in [z0, z1] and y in [y0, y1].
fn front_quad(m: &mut Mesh, x: f32, (z0, z1): (f32, f32), (y0, y1): (f32, f32)) {
    if z1 - z0 > 1e-4 && y1 - y0 > 1e-4 {
        m.rect(
            Vec3::new(x, 0.5 * (y0 + y1), 0.5 * (z0 + z1)),
            Vec3::Z * 0.5 * (z1 - z0),
            Vec3::Y * 0.5 * (y1 - y0),
        );
    }
}

/// A box from `min` to `max` without its back face (x = max.x, against the wall) and its
/// bottom: the visible faces of a projection from a wall facing -X.
fn ledge(m: &mut Mesh, min: Vec3, max: Vec3) {
    let c = (min + max) * 0.5;
    let h = (max - min) * 0.5;
    let (x, y, z) = (Vec3::X * h.x, Vec3::Y * h.y, Vec3::Z * h.z);
    m.rect(c - x, z, y);
    m.rect(c + y, z, x);
    m.rect(c - y, x, z);
    m.rect(c + z, x, y);
    m.rect(c - z, y, x);
}

/// A window opening in a wall at x = `xf`: z in [z0, z1], y in [y0, y1], with reveals of
/// depth `d` (wall material), the glass at the back, a frame and optional mullion and
/// transom 4 cm in front of the glass.
struct Opening {
    z: (f32, f32),
    y: (f32, f32),
}

impl Opening {
    fn reveals(&self, m: &mut Mesh, xf: f32, d: f32) {
        let ((z0, z1), (y0, y1)) = (self.z, self.y);
        let (hw, hh, hd) = (0.5 * (z1 - z0), 0.5 * (y1 - y0), 0.5 * d);
        let (xc, yc, zc) = (xf + hd, 0.5 * (y0 + y1), 0.5 * (z0 + z1));
        // Jambs face into the opening, the head faces down, the sill up.
        m.rect(Vec3::new(xc, yc, z0), Vec3::X * hd, Vec3::Y * hh);
        m.rect(Vec3::new(xc, yc, z1), Vec3::Y * hh, Vec3::X * hd);
        m.rect(Vec3::new(xc, y1, zc), Vec3::X * hd, Vec3::Z * hw);
        m.rect(Vec3::new(xc, y0, zc), Vec3::Z * hw, Vec3::X * hd);
    }

    fn frame(&self, m: &mut Mesh, x: f32, mullions: bool) {
        let ((z0, z1), (y0, y1)) = (self.z, self.y);
        let f = 0.06;
        front_quad(m, x, (z0, z1), (y0, y0 + f));
        front_quad(m, x, (z0, z1), (y1 - f, y1));
        front_quad(m, x, (z0, z0 + f), (y0 + f, y1 - f));
        front_quad(m, x, (z1 - f, z1), (y0 + f, y1 - f));
        if mullions {
            let zc = 0.5 * (z0 + z1);
            let yt = y0 + 0.7 * (y1 - y0);
            front_quad(m, x, (zc - 0.03, zc + 0.03), (y0 + f, y1 - f));
            front_quad(m, x, (z0 + f, zc - 0.03), (yt - 0.03, yt + 0.03));
            front_quad(m, x, (zc + 0.03, z1 - f), (yt - 0.03, yt + 0.03));
        }
    }
}

/// A band of front wall at x = `xf` from y0 to y1 across z in [z0, z1], with `holes`
/// (openings within the band, sorted by z, not overlapping) left open.
fn wall_band(m: &mut Mesh, xf: f32, (z0, z1): (f32, f32), (y0, y1): (f32, f32), holes: &[Opening]) {
    let mut z = z0;
    for h in holes {
        front_quad(m, xf, (z, h.z.0), (y0, y1));
        front_quad(m, xf, h.z, (y0, h.y.0));
        front_quad(m, xf, h.z, (h.y.1, y1));
        z = h.z.1;
    }
    front_quad(m, xf, (z, z1), (y0, y1));
}

/// Builds the building `spec` in its model frame (see the module documentation) with the
/// street's `palette`. Classes: walls, glass, frames, roof, awnings and doors are
/// [`Class::Building`], railings [`Class::Fence`], lit windows, shop windows and signs
/// [`Class::LightSource`]. Fails if the palette has no texture for the spec's surface.
pub fn facade(spec: &BuildingSpec, palette: &Palette) -> Result<Model, Error> {
    let texture = palette
        .textures
        .iter()
        .find(|t| t.surface == spec.surface)
        .ok_or_else(|| Error::Scene {
            scene: "building".into(),
            element: spec.surface.name().into(),
            reason: "the palette has no texture for this wall surface".into(),
        })?;
    let mut p = Parts::default();
    let half = 0.5 * spec.frontage;
    let bay = spec.frontage / spec.bays as f32;
    let back = spec.recess + spec.depth;
    let top = spec.wall_height();
    let mut window = 0u32;
    let mut pick = |seed: u32| {
        window += 1;
        unit(seed, window)
    };

    // Ground floor.
    let g = spec.ground_height;
    let x0 = spec.recess;
    if let Some(shop) = &spec.shop {
        // Shop windows in every bay between 0.25 m piers, a sign band above.
        let glass_top = g - 0.95;
        let holes: Vec<Opening> = (0..spec.bays)
            .map(|b| {
                let zc = -half + (b as f32 + 0.5) * bay;
                Opening {
                    z: (zc - 0.5 * bay + 0.25, zc + 0.5 * bay - 0.25),
                    y: (0.45, glass_top),
                }
            })
            .collect();
        wall_band(&mut p.wall, x0, (-half, half), (0.0, g), &holes);
        for h in &holes {
            h.reveals(&mut p.wall, x0, 0.15);
            let target = if shop.lit { &mut p.shop } else { &mut p.glass };
            front_quad(target, x0 + 0.15, h.z, h.y);
            h.frame(&mut p.trim, x0 + 0.11, false);
            if shop.awning {
                awning(&mut p.awning, x0, h.z, glass_top);
            }
        }
        // The sign band: a fascia board 8 cm proud of the wall; lit lettering on it.
        let (s0, s1) = (g - 0.85, g - 0.3);
        ledge(
            &mut p.trim,
            Vec3::new(x0 - 0.08, s0, -half + 0.2),
            Vec3::new(x0, s1, half - 0.2),
        );
        if shop.sign.is_some() {
            let mut z = -half + 0.6;
            let mut k = 0;
            while z < half - 1.0 && k < 40 {
                let w = 0.18 + 0.2 * pick(spec.seed ^ 0x51);
                front_quad(
                    &mut p.sign,
                    x0 - 0.081,
                    (z, (z + w).min(half - 0.6)),
                    (s0 + 0.12, s1 - 0.1),
                );
                z += w
                    + 0.08
                    + if pick(spec.seed ^ 0x52) < 0.2 {
                        0.35
                    } else {
                        0.0
                    };
                k += 1;
            }
        }
    } else {
        // Windows and a door in the middle bay.
        let door = spec.bays / 2;
        let holes: Vec<Opening> = (0..spec.bays)
            .map(|b| {
                let zc = -half + (b as f32 + 0.5) * bay;
                if b == door {
                    let w = 0.5 * spec.window_width.clamp(1.0, 1.8);
                    Opening {
                        z: (zc - w, zc + w),
                        y: (0.0, 2.3),
                    }
                } else {
                    let hw = 0.5 * spec.window_width;
                    let y0 = (g - spec.window_height) * 0.55;
                    Opening {
                        z: (zc - hw, zc + hw),
                        y: (y0, y0 + spec.window_height),
                    }
                }
            })
            .collect();
        wall_band(&mut p.wall, x0, (-half, half), (0.0, g), &holes);
        for (b, h) in holes.iter().enumerate() {
            if b as u32 == door {
                h.reveals(&mut p.wall, x0, 0.25);
                front_quad(&mut p.door, x0 + 0.25, h.z, h.y);
            } else {
                window_in(&mut p, spec, palette, h, x0, &mut pick);
            }
        }
    }
    if spec.cornice {
        // String course above the ground floor.
        ledge(
            &mut p.trim,
            Vec3::new(x0 - 0.06, g - 0.1, -half),
            Vec3::new(x0, g + 0.12, half),
        );
    }

    // Upper storeys.
    for s in 0..spec.storeys {
        let y = g + s as f32 * spec.storey_height;
        let xf = spec.front_x(y + 0.01);
        let balcony = spec.balconies.filter(|_| xf == spec.recess);
        let holes: Vec<Opening> = (0..spec.bays)
            .map(|b| {
                let zc = -half + (b as f32 + 0.5) * bay;
                let hw = 0.5 * spec.window_width;
                let has_balcony = balcony.is_some_and(|bal| b % bal.stride == 0);
                let y0 = if has_balcony {
                    y + 0.05
                } else {
                    y + 0.5 * (spec.storey_height - spec.window_height).max(0.2) + 0.2
                };
                let y1 = (y0 + spec.window_height + if has_balcony { 0.6 } else { 0.0 })
                    .min(y + spec.storey_height - 0.25);
                Opening {
                    z: (zc - hw, zc + hw),
                    y: (y0, y1),
                }
            })
            .collect();
        wall_band(
            &mut p.wall,
            xf,
            (-half, half),
            (y, y + spec.storey_height),
            &holes,
        );
        for (b, h) in holes.iter().enumerate() {
            window_in(&mut p, spec, palette, h, xf, &mut pick);
            if let Some(bal) = balcony.filter(|bal| b as u32 % bal.stride == 0) {
                balcony_at(&mut p, bal, xf, (h.z.0 - 0.35, h.z.1 + 0.35), y);
            }
        }
    }

    // The setback's terrace and its parapet, the roof, the cornice and parapet.
    if let Some((n, d)) = spec.upper_setback {
        let ys = spec.setback_y(n);
        let (xa, xb) = (spec.recess, spec.recess + d);
        p.roof.rect(
            Vec3::new(0.5 * (xa + xb), ys, 0.0),
            Vec3::Z * half,
            Vec3::X * 0.5 * (xb - xa),
        );
        p.railing.cuboid(
            Vec3::new(xa, ys, -half),
            Vec3::new(xa + 0.04, ys + 1.0, half),
        );
    }
    let xt = spec.front_x(top - 0.01);
    let parapet = spec.parapet();
    front_quad(&mut p.wall, xt, (-half, half), (top, top + parapet));
    if spec.cornice {
        ledge(
            &mut p.trim,
            Vec3::new(xt - 0.35, top - 0.25, -half),
            Vec3::new(xt, top + 0.1, half),
        );
    }
    // Coping on the parapet, and the roof.
    ledge(
        &mut p.trim,
        Vec3::new(xt - 0.05, top + parapet, -half),
        Vec3::new(back, top + parapet + 0.08, half),
    );
    p.roof.rect(
        Vec3::new(0.5 * (xt + back), top, 0.0),
        Vec3::Z * half,
        Vec3::X * 0.5 * (back - xt),
    );

    // Sides (seen over lower neighbours and across gaps) and the back.
    for (side, sign) in [(-half, -1.0f32), (half, 1.0)] {
        let mut side_wall = |xa: f32, y0: f32, y1: f32| {
            let c = Vec3::new(0.5 * (xa + back), 0.5 * (y0 + y1), side);
            let (u, v) = (Vec3::X * 0.5 * (back - xa), Vec3::Y * 0.5 * (y1 - y0));
            // Faces +Z on the +Z side: X x Y = Z.
            if sign > 0.0 {
                p.wall.rect(c, u, v);
            } else {
                p.wall.rect(c, v, u);
            }
        };
        match spec.upper_setback {
            Some((n, d)) => {
                let ys = spec.setback_y(n);
                side_wall(spec.recess, 0.0, ys);
                side_wall(spec.recess + d, ys, top + parapet);
            }
            None => side_wall(spec.recess, 0.0, top + parapet),
        }
    }
    p.wall.rect(
        Vec3::new(back, 0.5 * (top + parapet), 0.0),
        Vec3::Y * 0.5 * (top + parapet),
        Vec3::Z * half,
    );

    // Materials.
    let wet = palette.wetness;
    let wall = wet_paper(&texture.material("wall", spec.wall_kd), wet);
    scatter_uvs(&mut p.wall, spec.surface, spec.seed);
    scatter_uvs(&mut p.streaks, spec.surface, spec.seed);
    let trim = wet_paper(
        &Material::paper(
            "trim",
            crate::gltf_writer::PaperBsdf::Ggx { alpha: 0.3 },
            spec.trim_kd,
            [0.04; 3],
        ),
        wet,
    );
    let mut model = Model::new();
    let parts: [(&str, Mesh, Material, Class); 12] = [
        ("wall", p.wall, wall.clone(), Class::Building),
        (
            "rain_streaks",
            p.streaks,
            wet_paper(&wall, 1.0),
            Class::Building,
        ),
        ("trim", p.trim, trim.clone(), Class::Building),
        (
            "glass",
            p.glass,
            glass("window_glass", wet),
            Class::Building,
        ),
        (
            "door",
            p.door,
            wet_paper(&Material::diffuse("door", [0.04, 0.03, 0.02]), wet),
            Class::Building,
        ),
        (
            "roof",
            p.roof,
            wet_paper(&Material::diffuse("roof", [0.08, 0.08, 0.08]), wet),
            Class::Building,
        ),
        (
            "awnings",
            p.awning,
            Material {
                double_sided: true,
                ..wet_paper(
                    &Material::diffuse("awning", spec.shop.map_or([0.1; 3], |s| s.awning_kd)),
                    wet,
                )
            },
            Class::Building,
        ),
        (
            "railings",
            p.railing,
            wet_paper(
                &Material::paper(
                    "railing",
                    crate::gltf_writer::PaperBsdf::Ggx { alpha: 0.2 },
                    [0.02; 3],
                    [0.2; 3],
                ),
                wet,
            ),
            Class::Fence,
        ),
        (
            "windows_warm",
            p.warm,
            Material::emitter("window_warm", palette.warm_window),
            Class::LightSource,
        ),
        (
            "windows_cool",
            p.cool,
            Material::emitter("window_cool", palette.cool_window),
            Class::LightSource,
        ),
        (
            "shop_windows",
            p.shop,
            Material::emitter("shop_window", palette.shop_window),
            Class::LightSource,
        ),
        (
            "sign",
            p.sign,
            Material::emitter("sign", spec.shop.and_then(|s| s.sign).unwrap_or([0.0; 3])),
            Class::LightSource,
        ),
    ];
    for (name, mesh, material, class) in parts {
        if !mesh.indices.is_empty() {
            model.push(name, mesh, material, class);
        }
    }
    Ok(model)
}

/// A window in `h` of a wall at `xf`: reveals, glass (dark or lit), frame, a sill below
/// (unless it reaches the floor) and, on a wet street, rain streaks under the sill.
fn window_in(
    p: &mut Parts,
    spec: &BuildingSpec,
    palette: &Palette,
    h: &Opening,
    xf: f32,
    pick: &mut impl FnMut(u32) -> f32,
) {
    let d = spec.window_depth;
    h.reveals(&mut p.wall, xf, d);
    let lit = pick(spec.seed) < spec.lit;
    let cool = pick(spec.seed ^ 0x9e37) < spec.cool;
    let target = match (lit, cool) {
        (false, _) => &mut p.glass,
        (true, false) => &mut p.warm,
        (true, true) => &mut p.cool,
    };
    front_quad(target, xf + d, h.z, h.y);
    h.frame(&mut p.trim, xf + d - 0.04, spec.mullions);
    let floor = (h.y.0 - spec.ground_height).rem_euclid(spec.storey_height) < 0.1;
    if !floor {
        // A sill 6 cm proud and 5 cm thick, 5 cm wider than the opening each side.
        let (z0, z1) = (h.z.0 - 0.05, h.z.1 + 0.05);
        ledge(
            &mut p.trim,
            Vec3::new(xf - 0.06, h.y.0 - 0.05, z0),
            Vec3::new(xf, h.y.0, z1),
        );
        if palette.wetness > 0.3 {
            // Dirty water runs off the sill's ends and drip edge: two to four streaks.
            let n = 2 + (pick(spec.seed ^ 0x77) * 3.0) as u32;
            for k in 0..n {
                let t = (k as f32 + 0.5 + 0.6 * (pick(spec.seed ^ 0x78) - 0.5)) / n as f32;
                let z = z0 + 0.1 + t * (z1 - z0 - 0.2);
                let w = 0.04 + 0.08 * pick(spec.seed ^ 0x79);
                let len = (0.3 + 0.9 * pick(spec.seed ^ 0x7a)) * palette.wetness;
                let y1 = h.y.0 - 0.05;
                let y0 = (y1 - len)
                    .max(y1 - 0.9 * (h.y.0 - spec.ground_height).rem_euclid(spec.storey_height));
                front_quad(
                    &mut p.streaks,
                    xf - 0.003,
                    (z - 0.5 * w, z + 0.5 * w),
                    (y0, y1),
                );
            }
        }
    }
}

/// A balcony at floor height `y` in front of a wall at `xf`, across z in `z`: a slab and a
/// railing (bars or a solid panel) around its three open sides.
fn balcony_at(p: &mut Parts, bal: Balconies, xf: f32, (z0, z1): (f32, f32), y: f32) {
    let xo = xf - bal.projection;
    ledge(
        &mut p.trim,
        Vec3::new(xo, y - 0.18, z0),
        Vec3::new(xf, y, z1),
    );
    let rail = 1.0;
    if bal.bars {
        // Top rail, bottom rail and bars every 0.3 m on the front; rails on the sides.
        p.railing.cuboid(
            Vec3::new(xo, y + rail - 0.04, z0),
            Vec3::new(xo + 0.04, y + rail, z1),
        );
        p.railing.cuboid(
            Vec3::new(xo, y + 0.08, z0),
            Vec3::new(xo + 0.03, y + 0.11, z1),
        );
        let n = ((z1 - z0) / 0.3).floor().max(1.0) as u32;
        for k in 0..=n {
            let z = z0 + 0.02 + k as f32 * (z1 - z0 - 0.04) / n as f32;
            post(
                &mut p.railing,
                Vec3::new(xo + 0.02, y, z),
                0.012,
                rail - 0.04,
            );
        }
        for z in [z0, z1 - 0.04] {
            p.railing.cuboid(
                Vec3::new(xo, y + rail - 0.04, z),
                Vec3::new(xf, y + rail, z + 0.04),
            );
        }
    } else {
        p.railing
            .cuboid(Vec3::new(xo, y, z0), Vec3::new(xo + 0.04, y + rail, z1));
        for z in [z0, z1 - 0.04] {
            p.railing
                .cuboid(Vec3::new(xo, y, z), Vec3::new(xf, y + rail, z + 0.04));
        }
    }
}

/// A square post of half width `r` and height `h` standing on `base` (four sides, no caps).
fn post(m: &mut Mesh, base: Vec3, r: f32, h: f32) {
    let c = base + Vec3::Y * 0.5 * h;
    let (x, y, z) = (Vec3::X * r, Vec3::Y * 0.5 * h, Vec3::Z * r);
    m.rect(c + x, y, z);
    m.rect(c - x, z, y);
    m.rect(c + z, x, y);
    m.rect(c - z, y, x);
}

/// An awning over a shop window spanning `z` on a wall at `x0`: its fabric slopes 1.1 m out
/// and 0.55 m down from `y_top`, with a 0.2 m valance (one sheet: the awning's material is
/// double-sided).
fn awning(m: &mut Mesh, x0: f32, (z0, z1): (f32, f32), y_top: f32) {
    let (out, drop, val) = (1.1, 0.55, 0.2);
    let a = Vec3::new(x0, y_top, z0);
    let b = Vec3::new(x0, y_top, z1);
    let c = Vec3::new(x0 - out, y_top - drop, z1);
    let d = Vec3::new(x0 - out, y_top - drop, z0);
    let up = (b - a).cross(d - a).normalize();
    let up = if up.y > 0.0 { up } else { -up };
    let uv = [glam::Vec2::ZERO; 4];
    m.quad_uv([a, b, c, d], uv, up);
    let dv = Vec3::new(0.0, -val, 0.0);
    m.quad_uv([d, c, c + dv, d + dv], uv, Vec3::NEG_X);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn specs(n: usize, frontage: f32) -> Vec<BuildingSpec> {
        let config = BuildingsConfig::default();
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        (0..n)
            .map(|_| BuildingSpec::draw(&mut rng, &config, frontage, (0.3, 0.3, 0.5)))
            .collect()
    }

    fn palette(doc: &mut Doc, specs: &[BuildingSpec], wetness: f32) -> Palette {
        Palette::new(doc, specs, 5, (20.0, 150.0), wetness).unwrap()
    }

    #[test]
    fn the_default_config_validates_and_bad_values_are_named() {
        BuildingsConfig::default().validate().unwrap();
        let c = BuildingsConfig {
            balconies: 1.5,
            ..Default::default()
        };
        assert!(c.validate().unwrap_err().contains("buildings.balconies"));
        let c = BuildingsConfig {
            storeys: [5, 2],
            ..Default::default()
        };
        assert!(c.validate().unwrap_err().contains("buildings.storeys"));
        let mut c = BuildingsConfig::default();
        c.materials.clear();
        assert!(c.validate().unwrap_err().contains("buildings.materials"));
        let e = toml::from_str::<BuildingsConfig>("balcony = 0.5").unwrap_err();
        assert!(e.to_string().contains("balcony"), "{e}");
    }

    #[test]
    fn dimensions_fall_within_the_config() {
        let c = BuildingsConfig::default();
        let within = |v: f32, r: Range| v as f64 >= r[0] - 1e-5 && v as f64 <= r[1] + 1e-5;
        for s in specs(200, 17.0) {
            assert!(within(s.ground_height, c.ground_floor_height));
            assert!(within(s.storey_height, c.storey_height));
            assert!((c.storeys[0]..=c.storeys[1]).contains(&s.storeys));
            assert!(within(s.depth, c.depth));
            assert!(s.recess == 0.0 || within(s.recess, c.recess_depth));
            if let Some((n, d)) = s.upper_setback {
                assert!(n >= 1 && n < s.storeys && within(d, c.upper_setback_depth));
            }
            let bay = s.frontage / s.bays as f32;
            assert!(bay >= c.bay_width[0] as f32 - 1e-4 || s.bays == 1, "{bay}");
            assert!(bay <= 2.0 * c.bay_width[1] as f32);
            assert!(s.window_width <= c.window_width[1] as f32 && s.window_width <= bay - 0.5);
            assert!(s.window_height <= c.window_height[1] as f32);
            assert!(s.window_height <= s.storey_height - 1.0);
            let [lo, hi] = s.surface.albedo();
            let y = luminance(s.wall_kd);
            assert!(y > lo - 1e-3 && y < hi + 1e-3, "{:?} {y}", s.surface);
        }
    }

    /// Every triangle of `model` with its part's class, in the model's frame.
    fn triangles(model: &Model) -> Vec<([Vec3; 3], Class, String)> {
        model
            .parts
            .iter()
            .flat_map(|p| {
                p.mesh.indices.chunks(3).map(move |t| {
                    (
                        [0, 1, 2].map(|k| p.mesh.positions[t[k] as usize]),
                        p.class,
                        p.name.clone(),
                    )
                })
            })
            .collect()
    }

    /// The first hit of the ray `o + t d` (Moller-Trumbore), its distance and the index.
    fn first_hit(tris: &[([Vec3; 3], Class, String)], o: Vec3, d: Vec3) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        for (i, (t, _, _)) in tris.iter().enumerate() {
            let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
            let pv = d.cross(e2);
            let det = e1.dot(pv);
            if det.abs() < 1e-9 {
                continue;
            }
            let s = o - t[0];
            let u = s.dot(pv) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let dist = e2.dot(q) / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0 && best.is_none_or(|b| dist < b.0)
            {
                best = Some((dist, i));
            }
        }
        best
    }

    #[test]
    fn the_facade_is_closed_towards_the_street_and_faces_it() {
        let all = specs(12, 14.0);
        let mut doc = Doc::new("t", "t");
        let pal = palette(&mut doc, &all, 0.8);
        for s in &all {
            let model = facade(s, &pal).unwrap();
            let tris = triangles(&model);
            // Rays from the street towards +X on a grid over the facade (off the panel
            // edges): each meets a face that faces the street.
            let (n_z, n_y) = (47, 61);
            for i in 0..n_z {
                for j in 0..n_y {
                    let z = -0.5 * s.frontage + (i as f32 + 0.5) / n_z as f32 * s.frontage;
                    let y = 0.013 + (j as f32 + 0.5) / n_y as f32 * (s.height() - 0.03);
                    let o = Vec3::new(-5.0, y, z);
                    let (_, k) = first_hit(&tris, o, Vec3::X)
                        .unwrap_or_else(|| panic!("{s:?}: a hole at y {y} z {z}"));
                    let t = tris[k].0;
                    let n = (t[1] - t[0]).cross(t[2] - t[0]);
                    assert!(n.x < 0.0, "{}: back face first at y {y} z {z}", tris[k].2);
                }
            }
        }
    }

    #[test]
    fn windows_lie_inside_their_walls() {
        let all = specs(30, 21.0);
        let mut doc = Doc::new("t", "t");
        let pal = palette(&mut doc, &all, 0.0);
        for s in &all {
            let model = facade(s, &pal).unwrap();
            let mut panes = 0;
            for part in &model.parts {
                if ![
                    "glass",
                    "windows_warm",
                    "windows_cool",
                    "shop_windows",
                    "door",
                ]
                .contains(&part.name.as_str())
                {
                    continue;
                }
                for p in &part.mesh.positions {
                    panes += 1;
                    let front = s.front_x(p.y.min(s.wall_height() - 0.01));
                    // Behind the wall's face, in front of the back; within the frontage and
                    // below the roof.
                    assert!(p.x > front + 0.05 && p.x < s.recess + s.depth, "{p}");
                    assert!(p.z.abs() < 0.5 * s.frontage - 0.1, "{p}");
                    assert!(p.y >= 0.0 && p.y < s.wall_height(), "{p}");
                }
                // The panes face the street.
                assert!(part.mesh.normals.iter().all(|n| n.x < -0.99));
            }
            assert!(panes >= 4 * s.bays as usize);
        }
    }

    #[test]
    fn classes_follow_the_scene_contract_and_the_budget_holds() {
        let all = specs(60, 20.0);
        let mut doc = Doc::new("t", "t");
        let pal = palette(&mut doc, &all, 0.7);
        let (mut worst, mut total) = (0, 0);
        for s in &all {
            let model = facade(s, &pal).unwrap();
            for p in &model.parts {
                let emits = p.material.emission.is_some();
                assert_eq!(emits, p.class == Class::LightSource, "{}", p.name);
                if p.name == "railings" {
                    assert_eq!(p.class, Class::Fence);
                }
            }
            let n: usize = model.parts.iter().map(|p| p.mesh.triangle_count()).sum();
            worst = worst.max(n);
            total += n;
        }
        println!(
            "20 m blocks: {} triangles on average, {worst} at most",
            total / all.len()
        );
        assert!(worst < 6000, "a 20 m block has {worst} triangles");
    }

    #[test]
    fn the_same_spec_gives_the_same_bytes() {
        let write = || {
            let all = specs(6, 15.0);
            let mut doc = Doc::new("row", "row");
            let pal = palette(&mut doc, &all, 0.6);
            for (k, s) in all.iter().enumerate() {
                let m = facade(s, &pal).unwrap();
                doc.add_model(
                    &format!("b{k}"),
                    &m,
                    placement(1.0, 6.0, -15.0 * k as f32),
                    None,
                )
                .unwrap();
            }
            let dir = tempfile::tempdir().unwrap();
            let files = doc.write(dir.path()).unwrap();
            files
                .iter()
                .map(|f| std::fs::read(f).unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(write(), write());
    }

    #[test]
    fn the_left_side_faces_the_road() {
        for side in [1.0f32, -1.0] {
            let pose = placement(side, 6.0, -20.0);
            let n = pose.transform_vector3(Vec3::NEG_X);
            // The facade's normal points towards the road's centre line x = 0.
            assert!((n.x + side).abs() < 1e-6, "{side}: {n}");
            let p = pose.transform_point3(Vec3::ZERO);
            assert!((p.x - side * 6.0).abs() < 1e-5 && (p.z + 20.0).abs() < 1e-5);
        }
    }

    /// The correlation of the wall's albedo with itself `tiles` texture tiles further along
    /// the street, on the facade plane rasterised every 2 cm along z and 10 cm up: with the
    /// wall's own texture coordinates (`scattered`) or with coordinates continuous over the
    /// wall, the position divided by the tile (the box facades' tiling).
    fn tile_correlation(surface: Surface, scattered: bool, tiles: f32) -> f64 {
        let mut s = specs(1, 20.0).remove(0);
        s.surface = surface;
        s.recess = 0.0;
        s.upper_setback = None;
        let mut doc = Doc::new("t", "t");
        let pal = palette(&mut doc, std::slice::from_ref(&s), 0.0);
        let model = facade(&s, &pal).unwrap();
        let wall = model.parts.iter().find(|p| p.name == "wall").unwrap();
        let (w, h) = surface.texels();
        let (png, _) = crate::albedo::albedo_png(surface.pattern(), (w, h), 5).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_luma8();
        let tile = surface.tile_m();
        let m = &wall.mesh;
        // The wall's triangles in the plane x = 0, facing the street.
        let tris: Vec<[usize; 3]> = m
            .indices
            .chunks(3)
            .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
            .filter(|t| {
                t.iter()
                    .all(|&k| m.positions[k].x.abs() < 1e-4 && m.normals[k].x < -0.99)
            })
            .collect();
        let (nz, ny) = (
            (s.frontage / 0.02) as usize,
            (s.wall_height() / 0.1) as usize,
        );
        let mut grid = vec![None; nz * ny];
        for t in &tris {
            let p = t.map(|k| glam::Vec2::new(m.positions[k].z, m.positions[k].y));
            let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            let d = (p[1] - p[0]).perp_dot(p[2] - p[0]);
            for j in 0..ny {
                let y = (j as f32 + 0.5) * 0.1;
                if y < lo.y || y > hi.y {
                    continue;
                }
                for i in 0..nz {
                    let z = -0.5 * s.frontage + (i as f32 + 0.5) * 0.02;
                    if z < lo.x || z > hi.x {
                        continue;
                    }
                    let q = glam::Vec2::new(z, y);
                    let b1 = (q - p[0]).perp_dot(p[2] - p[0]) / d;
                    let b2 = (p[1] - p[0]).perp_dot(q - p[0]) / d;
                    if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 {
                        continue;
                    }
                    let uv = if scattered {
                        m.uvs[t[0]] * (1.0 - b1 - b2) + m.uvs[t[1]] * b1 + m.uvs[t[2]] * b2
                    } else {
                        glam::Vec2::new(z / tile.x, -y / tile.y)
                    };
                    let ti = ((uv.x.rem_euclid(1.0) * w as f32) as u32).min(w - 1);
                    let tj = ((uv.y.rem_euclid(1.0) * h as f32) as u32).min(h - 1);
                    grid[j * nz + i] = Some(f64::from(img.get_pixel(ti, tj).0[0]));
                }
            }
        }
        let lag = (tiles * tile.x / 0.02).round() as usize;
        let pairs: Vec<(f64, f64)> = (0..ny)
            .flat_map(|j| (0..nz - lag).map(move |i| (j, i)))
            .filter_map(|(j, i)| Some((grid[j * nz + i]?, grid[j * nz + i + lag]?)))
            .collect();
        assert!(pairs.len() > 10_000, "{}", pairs.len());
        let n = pairs.len() as f64;
        let (ma, mb) = (
            pairs.iter().map(|p| p.0).sum::<f64>() / n,
            pairs.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let cov = pairs.iter().map(|p| (p.0 - ma) * (p.1 - mb)).sum::<f64>();
        let va = pairs.iter().map(|p| (p.0 - ma).powi(2)).sum::<f64>();
        let vb = pairs.iter().map(|p| (p.1 - mb).powi(2)).sum::<f64>();
        cov / (va * vb).sqrt()
    }

    /// The repetition of a wall's texture: its correlation at one tile along the street in
    /// excess of that at half a tile (a whole number of bricks, slabs or formwork panels, so
    /// the joints align at both lags and only the repetition of the texels themselves counts).
    fn repetition(surface: Surface, scattered: bool) -> f64 {
        tile_correlation(surface, scattered, 1.0) - tile_correlation(surface, scattered, 0.5)
    }

    #[test]
    fn the_wall_texture_does_not_repeat_at_its_tile() {
        for surface in Surface::WALLS {
            let (new, old) = (repetition(surface, true), repetition(surface, false));
            println!(
                "{}: repetition {new:.3} (continuous tiling {old:.3}); correlation at one tile \
                 {:.3} ({:.3})",
                surface.name(),
                tile_correlation(surface, true, 1.0),
                tile_correlation(surface, false, 1.0)
            );
            assert!(
                old > 0.15,
                "{surface:?}: the continuous tiling repeats: {old}"
            );
            assert!(new.abs() < 0.1, "{surface:?}: {new}");
        }
    }
}
