//! Realistic rainy night streets: a two-lane road (X in [-3.5, 3.5], running along -Z from the
//! driver at Z = 0) with a wet/dry dryness map, lane markings, kerbs, sidewalks, street lamps,
//! telephone poles, cars, a traffic light and building facades with lit windows.
//! [`Street::full`] is `rainy_street`; [`Street::small`] is `rainy_street_small` for tests.

use crate::albedo::{albedo_png, Pattern};
use crate::buildings::{facade, placement, BuildingSpec, BuildingsConfig, Palette};
use crate::estimate::Brdf;
use crate::gltf_writer::{
    quantise, round7, Class, Doc, Dryness, Light, LightKind, Material, NormalTexture, PaperBsdf,
    Tag,
};
use crate::mesh::Mesh;
use crate::model::{transformed, transformed_light, Model};
use crate::road::{Road, RoadFeatures, GAUGE, RAIL_GROOVE, RAIL_HEAD};
use crate::wetness::{dryness_png, ripple_normal_png, Wetness, RIPPLE_TEXELS};
use crate::Error;
use glam::{Affine3A, Vec2, Vec3};

/// Half width of the carriageway (two 3.5 m lanes).
pub const ROAD_HALF: f32 = 3.5;
/// Kerb width and height.
pub const KERB: f32 = 0.15;
/// X of the building facades.
pub const FACADE_X: f32 = 6.5;
/// Driver's eye.
pub const EYE: Vec3 = Vec3::new(1.35, 1.25, 0.0);
/// Height of the street lamps' light.
pub const LAMP_H: f32 = 5.9;
/// Street lamp radiant intensity (W/sr).
pub const LAMP_INTENSITY: f64 = 250.0;
/// Headlight radiant intensity on axis (W/sr).
pub const HEADLIGHT_INTENSITY: f64 = 20.0;
/// Red signal light radiant intensity on axis (W/sr).
pub const SIGNAL_INTENSITY: f64 = 60.0;
/// Radiance of a lit warm window (before [`StreetStyle::window_scale`]), W/(m^2 sr).
pub const WINDOW_WARM: [f64; 3] = [1.6, 1.2, 0.7];
/// Radiance of a lit cool window (before [`StreetStyle::window_scale`]), W/(m^2 sr).
pub const WINDOW_COOL: [f64; 3] = [0.8, 0.95, 1.2];
/// Size in texels of the tiling albedo textures (stone, brick, wood).
pub const TILE_TEXELS: u32 = 256;
/// Metres covered by one tile on small objects (poles, kerbs): 1 cm per texel.
pub const TILE_FINE: f32 = 2.56;
/// Metres covered by one tile on large surfaces (sidewalks, facades): 2 cm per texel.
pub const TILE_COARSE: f32 = 5.12;
/// Texels of the road's albedo texture across the carriageway (2.7 cm each).
pub const ROAD_ALBEDO_ACROSS: u32 = 256;

/// Asphalt: wet (w = 0, puddle) and dry (w = 1) parameters.
pub const ASPHALT_KD: f64 = 0.04;
/// Specular reflectance of standing water (w = 0).
pub const ASPHALT_KS_WET: f64 = 0.1;
/// Alpha of standing water (w = 0).
pub const ASPHALT_ALPHA_WET: f64 = 0.02;
/// Specular reflectance of dry asphalt (w = 1).
pub const ASPHALT_KS_DRY: f64 = 0.04;
/// Alpha of dry asphalt (w = 1).
pub const ASPHALT_ALPHA_DRY: f64 = 0.35;

/// The asphalt's reflectance at dryness `w` (the linear mix of the scene contract).
pub fn asphalt_at(w: f64) -> Brdf {
    Brdf::Ggx {
        kd: ASPHALT_KD,
        ks: ASPHALT_KS_WET + (ASPHALT_KS_DRY - ASPHALT_KS_WET) * w,
        alpha: ASPHALT_ALPHA_WET + (ASPHALT_ALPHA_DRY - ASPHALT_ALPHA_WET) * w,
    }
}

/// A car: centre (x, z), and whether it faces +Z (towards the driver).
#[derive(Clone, Copy, Debug)]
pub struct Car {
    /// Centre across the road.
    pub x: f32,
    /// Centre along the road.
    pub z: f32,
    /// Faces the driver (oncoming) rather than driving away.
    pub oncoming: bool,
    /// Body colour.
    pub color: [f64; 3],
    /// Whether its headlights are spot lights (lenses are emissive unless parked).
    pub headlights: bool,
    /// Parked with its lights off: no emissive lenses, no spot lights.
    pub parked: bool,
}

/// What a traffic light shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    /// Red lit.
    Red,
    /// Amber lit.
    Amber,
    /// Green lit.
    Green,
}

/// A traffic light on a sidewalk, facing the driver.
#[derive(Clone, Copy, Debug)]
pub struct TrafficLight {
    /// Z along the road.
    pub z: f32,
    /// +1 for the right (+X) sidewalk, -1 for the left.
    pub side: f32,
    /// Which lens is lit (and has a spot light).
    pub signal: Signal,
}

/// A road sign: a post on a sidewalk with a square plate facing the driver.
#[derive(Clone, Copy, Debug)]
pub struct Sign {
    /// Z along the road.
    pub z: f32,
    /// +1 for the right (+X) sidewalk, -1 for the left.
    pub side: f32,
    /// Height of the plate's centre.
    pub height: f32,
    /// Half size of the plate.
    pub half: f32,
    /// Diffuse colour of the plate (linear).
    pub color: [f64; 3],
}

/// Rain ripples on the road: a tiling normal map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ripples {
    /// `normalTexture.scale` (slope of the ripples).
    pub strength: f64,
    /// Metres covered by one tile of the map.
    pub tile_m: f32,
    /// Noise seed of the map.
    pub seed: u32,
}

/// The continuous parameters of a street: sizes, lamps, wetness, windows and the driver's
/// camera. [`StreetStyle::SHIPPED`] is the shipped scenes'; the procedural generator
/// ([`crate::procedural`]) draws them from its config.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StreetStyle {
    /// Half width of the carriageway.
    pub road_half: f32,
    /// Number of lanes (dashed lines between them; the outer edge lines are solid).
    pub lanes: u32,
    /// Kerb width and height.
    pub kerb: f32,
    /// X of the building facades (the far edge of the pavements).
    pub facade_x: f32,
    /// Height of the street lamps' light (the lamp head sits just above it).
    pub lamp_height: f32,
    /// Street lamp radiant intensity (W/sr) times [`StreetStyle::lamp_color`].
    pub lamp_intensity: f64,
    /// Street lamp colour (max component 1).
    pub lamp_color: [f64; 3],
    /// Half size of the lamp lens (along the road, across it).
    pub lens_half: (f32, f32),
    /// Radiance of the lamp lens.
    pub lens_radiance: [f64; 3],
    /// The lamps' beam: `None`, a point light (the shipped streets); `Some((inner, outer))`,
    /// a spot light pointing straight down with these glTF cone angles (radians).
    pub lamp_cone: Option<(f64, f64)>,
    /// Headlight radiant intensity on axis (W/sr) times [`StreetStyle::headlight_color`].
    pub headlight_intensity: f64,
    /// Headlight colour (max component 1).
    pub headlight_color: [f64; 3],
    /// Radiance of a lit headlamp lens.
    pub headlamp_radiance: [f64; 3],
    /// Traffic signal radiant intensity on axis (W/sr).
    pub signal_intensity: f64,
    /// Global wetness in [0, 1]: 0.5 is the shipped streets' balance of puddles, wet asphalt
    /// and drier patches; 1 floods the road, 0 dries it.
    pub wetness: f32,
    /// Asphalt diffuse reflectance.
    pub asphalt_kd: f64,
    /// Specular reflectance and alpha of standing water (dryness 0).
    pub wet: (f64, f64),
    /// Specular reflectance and alpha of dry asphalt (dryness 1).
    pub dry: (f64, f64),
    /// Rain ripples on the road, if any.
    pub ripples: Option<Ripples>,
    /// Shares of the upper windows that are lit warm, and lit at all (warm or cool):
    /// `(warm, lit)` with `warm <= lit`.
    pub lit_windows: (f32, f32),
    /// Share of the shop windows that are lit.
    pub lit_shops: f32,
    /// Factor on the radiance of the lit upper windows (warm and cool).
    pub window_scale: f64,
    /// Radiance of the lit shop windows: `None`, they are lit warm windows (the shipped
    /// streets); `Some`, their own emitter `shop_window` of this radiance.
    pub shop_radiance: Option<[f64; 3]>,
    /// Mean diffuse colour of the three facade materials (brick, render, concrete).
    pub facade_kd: [[f64; 3]; 3],
    /// The driver's camera (the stereo rig's centre): eye position.
    pub eye: Vec3,
    /// Camera pitch: tangent of the angle below the horizon.
    pub pitch_tan: f32,
    /// The camera's full world pose (looking along its local -Z, +Y up), which replaces `eye`
    /// and `pitch_tan` when set: a rig with roll, or one driving along the road.
    pub camera_pose: Option<glam::Affine3A>,
    /// Vertical field of view in degrees.
    pub yfov_deg: f64,
}

impl StreetStyle {
    /// The shipped streets' style.
    pub const SHIPPED: Self = Self {
        road_half: ROAD_HALF,
        lanes: 2,
        kerb: KERB,
        facade_x: FACADE_X,
        lamp_height: LAMP_H,
        lamp_intensity: LAMP_INTENSITY,
        lamp_color: [1.0, 0.78, 0.5],
        lens_half: (0.12, 0.25),
        lens_radiance: [40.0, 30.0, 18.0],
        lamp_cone: None,
        headlight_intensity: HEADLIGHT_INTENSITY,
        headlight_color: [1.0, 0.95, 0.85],
        headlamp_radiance: [30.0, 28.5, 25.5],
        signal_intensity: SIGNAL_INTENSITY,
        wetness: 0.5,
        asphalt_kd: ASPHALT_KD,
        wet: (ASPHALT_KS_WET, ASPHALT_ALPHA_WET),
        dry: (ASPHALT_KS_DRY, ASPHALT_ALPHA_DRY),
        ripples: None,
        lit_windows: (0.22, 0.3),
        lit_shops: 0.5,
        window_scale: 1.0,
        shop_radiance: None,
        facade_kd: [[0.16, 0.09, 0.07], [0.3, 0.28, 0.24], [0.18, 0.18, 0.19]],
        eye: EYE,
        pitch_tan: 0.035,
        camera_pose: None,
        yfov_deg: 45.0,
    };
}

/// The layout of a street scene.
#[derive(Clone, Debug)]
pub struct Street {
    /// Scene name.
    pub name: &'static str,
    /// Description written to the glTF.
    pub description: String,
    /// Z of the road's near end (behind the driver).
    pub near: f32,
    /// Z of the road's far end.
    pub far: f32,
    /// Z of the street lamps on the right (+X) side.
    pub lamps_right: Vec<f32>,
    /// Z of the street lamps on the left side.
    pub lamps_left: Vec<f32>,
    /// Z of the telephone poles (left sidewalk).
    pub poles: Vec<f32>,
    /// Cars.
    pub cars: Vec<Car>,
    /// Traffic lights.
    pub traffic_lights: Vec<TrafficLight>,
    /// Road signs.
    pub signs: Vec<Sign>,
    /// Building blocks per side as (length along Z, height), from the near end.
    pub blocks: Vec<(f32, f32)>,
    /// Whether facades get windows.
    pub windows: bool,
    /// Noise seed of the dryness map.
    pub seed: u32,
    /// Dryness map size in pixels (across, along the road); powers of two. The road's
    /// albedo texture has [`ROAD_ALBEDO_ACROSS`] x twice as many.
    pub texture: (u32, u32),
    /// Sizes, lamps, wetness, windows and the camera.
    pub style: StreetStyle,
    /// Buildings drawn from a config ([`crate::buildings`]) on the blocks' frontages; `None`,
    /// the shipped streets' boxes with flat windows.
    pub drawn_buildings: Option<DrawnBuildings>,
    /// Where the street's straight frame lies in the world: curves, grades, cross profile.
    /// Everything above is laid out in the straight frame and bent onto it.
    pub road: Road,
    /// Potholes, ruts, tracks, crossings and the markings' paint.
    pub features: RoadFeatures,
    /// Models of the cars, one per [`Street::cars`] entry, drawn at each car's pose with its
    /// instance id; empty: the cars are boxes.
    pub car_models: Vec<Model>,
    /// Street furniture on the pavements (trees, bus stops, bollards, the user's assets).
    pub furniture: Vec<Furniture>,
    /// Models of the street lamps, one per lamp of [`Street::lamps_right`] then
    /// [`Street::lamps_left`], each standing where that lamp's post is and reaching over the
    /// road, with its lights; empty: the lamps are the shipped streets' boxes.
    pub lamp_models: Vec<Model>,
}

/// A model standing on a pavement: its foot at straight-frame `(x, z)`, on the pavement.
#[derive(Clone, Debug)]
pub struct Furniture {
    /// Node name prefix.
    pub name: String,
    /// The model (its -Z, the side it shows to traffic, is turned to face the road).
    pub model: Model,
    /// Across the road, metres (straight frame X; the sign gives the side).
    pub x: f32,
    /// Along the road (straight frame Z).
    pub z: f32,
}

/// How a street's buildings are drawn from a [`BuildingsConfig`]: one [`BuildingSpec`] per
/// block frontage (the lengths of [`Street::blocks`]), from a generator seeded by `seed`, lit
/// with the street's window and shop shares.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawnBuildings {
    /// The distribution of the buildings.
    pub config: BuildingsConfig,
    /// Seed of the draw and of the wall textures.
    pub seed: u64,
    /// Luminance of a lit upper window, cd/m^2.
    pub window_cd: f64,
    /// Luminance of a lit shop window, cd/m^2.
    pub shop_cd: f64,
}

/// A tiling albedo image in a [`Doc`] and its mean linear value.
#[derive(Clone, Copy, Debug)]
struct Albedo {
    image: usize,
    mean: f64,
}

impl Albedo {
    fn new(
        doc: &mut Doc,
        suffix: &str,
        pattern: Pattern,
        size: (u32, u32),
        seed: u32,
    ) -> Result<Self, Error> {
        let (png, mean) = albedo_png(pattern, size, seed)?;
        Ok(Self {
            image: doc.add_png(suffix, png),
            mean,
        })
    }

    /// A paper material whose albedo is this texture times `kd / mean` (mean colour `kd`).
    fn paper(&self, name: &str, bsdf: PaperBsdf, kd: [f64; 3], ks: [f64; 3]) -> Material {
        Material::paper(name, bsdf, kd.map(|k| round7(k / self.mean)), ks).with_albedo(self.image)
    }
}

/// The street's tiling albedo textures.
#[derive(Clone, Copy, Debug)]
struct Albedos {
    stone: Albedo,
    brick: Albedo,
    wood: Albedo,
}

impl Street {
    /// `rainy_street`: 160 m of street, ten lamps, two cars, a traffic light, facades.
    pub fn full() -> Self {
        Self {
            name: "rainy_street",
            description: "Rainy night street: wet two-lane road with puddles, street lamps, \
                          cars, a traffic light, poles and facades"
                .into(),
            near: 10.0,
            far: -150.0,
            lamps_right: vec![-12.0, -40.0, -68.0, -96.0, -124.0],
            lamps_left: vec![-26.0, -54.0, -82.0, -110.0, -138.0],
            poles: vec![-8.0, -33.0, -58.0, -83.0, -108.0, -133.0],
            cars: vec![
                Car {
                    x: 1.75,
                    z: -24.0,
                    oncoming: false,
                    color: [0.2, 0.02, 0.02],
                    headlights: true,
                    parked: false,
                },
                Car {
                    x: -1.75,
                    z: -45.0,
                    oncoming: true,
                    color: [0.04, 0.06, 0.12],
                    headlights: true,
                    parked: false,
                },
            ],
            traffic_lights: vec![TrafficLight {
                z: -60.0,
                side: 1.0,
                signal: Signal::Red,
            }],
            signs: Vec::new(),
            blocks: vec![
                (14.0, 12.0),
                (9.0, 9.0),
                (20.0, 15.0),
                (12.0, 10.0),
                (16.0, 18.0),
                (11.0, 9.0),
                (18.0, 13.0),
                (22.0, 16.0),
                (15.0, 10.0),
                (23.0, 14.0),
            ],
            windows: true,
            seed: 2024,
            texture: (64, 1024),
            style: StreetStyle::SHIPPED,
            drawn_buildings: None,
            road: Road::straight(),
            features: RoadFeatures::default(),
            car_models: Vec::new(),
            furniture: Vec::new(),
            lamp_models: Vec::new(),
        }
    }

    /// `rainy_street_small`: 65 m of street, two lamps and a traffic light (3 lights), one
    /// car with emissive tail lights, a few blocks; for tests and CI.
    pub fn small() -> Self {
        Self {
            name: "rainy_street_small",
            description: "Small rainy street for tests: two lamps, a traffic light, one car".into(),
            near: 5.0,
            far: -60.0,
            lamps_right: vec![-15.0],
            lamps_left: vec![-32.0],
            poles: vec![-10.0, -40.0],
            cars: vec![Car {
                x: 1.75,
                z: -20.0,
                oncoming: false,
                color: [0.2, 0.02, 0.02],
                headlights: false,
                parked: false,
            }],
            traffic_lights: vec![TrafficLight {
                z: -45.0,
                side: 1.0,
                signal: Signal::Red,
            }],
            signs: Vec::new(),
            blocks: vec![(25.0, 10.0), (20.0, 14.0), (20.0, 9.0)],
            windows: false,
            seed: 2024,
            texture: (64, 512),
            style: StreetStyle::SHIPPED,
            drawn_buildings: None,
            road: Road::straight(),
            features: RoadFeatures::default(),
            car_models: Vec::new(),
            furniture: Vec::new(),
            lamp_models: Vec::new(),
        }
    }

    /// Builds the scene.
    pub fn build(&self) -> Result<Doc, Error> {
        let mut doc = Doc::new(self.name, &self.description);
        let tile = (TILE_TEXELS, TILE_TEXELS);
        let tex = Albedos {
            stone: Albedo::new(&mut doc, "stone", Pattern::Stone, tile, self.seed + 11)?,
            brick: Albedo::new(&mut doc, "brick", Pattern::Brick, tile, self.seed + 12)?,
            wood: Albedo::new(&mut doc, "wood", Pattern::Wood, tile, self.seed + 13)?,
        };
        self.road(&mut doc, &tex)?;
        self.lamps(&mut doc, &tex)?;
        self.poles(&mut doc, &tex)?;
        let st = &self.style;
        for (k, car) in self.cars.iter().enumerate() {
            match self.car_models.get(k) {
                Some(model) => doc.add_model(
                    &format!("car_{k}"),
                    model,
                    crate::drive::car_pose(&self.road, car),
                    Some(crate::procedural::car_instance(k)),
                )?,
                None => add_car(self, &mut doc, k, car)?,
            }
        }
        for f in &self.furniture {
            self.add_standing(&mut doc, &f.name, &f.model, f.x, f.z)?;
        }
        for (k, t) in self.traffic_lights.iter().enumerate() {
            add_traffic_light(self, &mut doc, k, t)?;
        }
        if !self.signs.is_empty() {
            add_signs(self, &mut doc, &self.signs)?;
        }
        self.buildings(&mut doc, &tex)?;
        match st.camera_pose {
            Some(pose) => doc.add_camera_pose("driver", pose, st.yfov_deg, 16.0 / 9.0),
            None => doc.add_camera(
                "driver",
                st.eye,
                st.eye + Vec3::new(0.0, -st.pitch_tan, -1.0),
                st.yfov_deg,
                16.0 / 9.0,
            ),
        }
        Ok(doc)
    }

    fn road(&self, doc: &mut Doc, tex: &Albedos) -> Result<(), Error> {
        let st = &self.style;
        let wet = Wetness {
            level: st.wetness,
            lanes: st.lanes,
            ruts: self.features.rut_depth,
        };
        let (png, _, _) = dryness_png(
            st.road_half,
            self.near,
            self.far,
            self.texture,
            self.seed,
            wet,
        )?;
        let image = doc.add_png("dryness", png);
        // The albedo shares the dryness map's texture coordinates (the whole carriageway).
        let grain = Albedo::new(
            doc,
            "asphalt",
            Pattern::Asphalt,
            (ROAD_ALBEDO_ACROSS, 2 * self.texture.1),
            self.seed + 10,
        )?;
        let mut asphalt = grain
            .paper(
                "wet_asphalt",
                PaperBsdf::Ggx { alpha: st.wet.1 },
                [st.asphalt_kd; 3],
                [st.wet.0; 3],
            )
            .with_dryness(Dryness {
                image,
                alpha_dry: st.dry.1,
                ks_dry: [st.dry.0; 3],
            })
            .as_road();
        let (h, n, f) = (st.road_half, self.near, self.far);
        if let Some(r) = st.ripples {
            let png = ripple_normal_png(RIPPLE_TEXELS, r.seed)?;
            let image = doc.add_png("ripples", png);
            // The road's (u, v) spans the carriageway: repeat the tile to r.tile_m metres.
            let tiles = [
                f64::from(round7q(2.0 * h / r.tile_m)),
                f64::from(round7q((n - f) / r.tile_m)),
            ];
            asphalt = asphalt.with_normal(NormalTexture {
                image,
                scale: r.strength,
                tiles,
            });
        }
        let p = self.features.paint;
        let mut paint = Material::paper(
            "road_paint",
            PaperBsdf::Ggx { alpha: p.alpha },
            [p.kd; 3],
            [p.ks; 3],
        );
        if p.rl_mcd > 0.0 {
            paint = paint.with_beads(crate::gltf_writer::Beads::for_rl(p.rl_mcd));
        }
        let stone = tex.stone.paper(
            "kerb_granite",
            PaperBsdf::Ggx { alpha: 0.25 },
            [0.22; 3],
            [0.04; 3],
        );
        let pavement = tex.stone.paper(
            "wet_pavement",
            PaperBsdf::Ggx { alpha: 0.12 },
            [0.1; 3],
            [0.06; 3],
        );
        if !(self.road.is_straight() && self.features.is_plain()) {
            return self.shaped_road(doc, [&asphalt, &paint, &stone, &pavement]);
        }
        let mut road = Mesh::new();
        road.quad_uv(
            [
                Vec3::new(-h, 0.0, n),
                Vec3::new(h, 0.0, n),
                Vec3::new(h, 0.0, f),
                Vec3::new(-h, 0.0, f),
            ],
            [
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 1.0),
            ],
            Vec3::Y,
        );
        doc.add_tagged_mesh("road", &road, &asphalt, Tag::stuff(Class::Road))?;

        // Markings: a dashed centre line (3 m dashes, 9 m gaps) and solid edge lines, 2 mm
        // above the asphalt.
        let mut marks = Mesh::new();
        let y = 0.002;
        for k in 1..st.lanes.max(1) {
            let x = -h + k as f32 * (2.0 * h / st.lanes as f32);
            let mut z = n - 2.0;
            while z - 3.0 > f {
                marks.rect(Vec3::new(x, y, z - 1.5), Vec3::Z * 1.5, Vec3::X * 0.06);
                z -= 12.0;
            }
        }
        for side in [-1.0f32, 1.0] {
            marks.rect(
                Vec3::new(side * (h - 0.2), y, (n + f) * 0.5),
                Vec3::Z * (n - f) * 0.5,
                Vec3::X * 0.06,
            );
        }
        doc.add_tagged_mesh("lane_markings", &marks, &paint, Tag::stuff(Class::Marking))?;

        // Kerbs and sidewalks (top at 0.15 m) up to the facades.
        let mut kerbs = Mesh::new();
        let mut walks = Mesh::new();
        for side in [-1.0f32, 1.0] {
            let (a, b) = (side * h, side * (h + st.kerb));
            kerbs.cuboid(Vec3::new(a.min(b), 0.0, f), Vec3::new(a.max(b), st.kerb, n));
            let (c, d) = (side * (h + st.kerb), side * st.facade_x);
            walks.rect(
                Vec3::new((c + d) * 0.5, st.kerb, (n + f) * 0.5),
                Vec3::Z * (n - f) * 0.5,
                Vec3::X * (d - c).abs() * 0.5,
            );
        }
        kerbs.scale_uvs(TILE_FINE);
        walks.scale_uvs(TILE_COARSE);
        doc.add_tagged_mesh("kerbs", &kerbs, &stone, Tag::stuff(Class::Sidewalk))?;
        doc.add_tagged_mesh("sidewalks", &walks, &pavement, Tag::stuff(Class::Sidewalk))?;
        Ok(())
    }

    /// The carriageway, markings, tracks, kerbs and pavements of a road that is curved, sloped
    /// or crowned, or has potholes, ruts, tracks, crossings or worn paint: every long surface a
    /// grid over the same stations ([`RoadFeatures::stations`]), laid out in the straight frame
    /// and bent onto [`Street::road`]. The materials are `[asphalt, paint, kerb, pavement]`.
    fn shaped_road(&self, doc: &mut Doc, materials: [&Material; 4]) -> Result<(), Error> {
        let [asphalt, paint, stone, pavement] = materials;
        let st = &self.style;
        let feat = &self.features;
        let (h, n, f) = (st.road_half, self.near, self.far);
        let zs = feat.stations(n, f, 1.0);
        let depth = |x: f32, z: f32| feat.depth(x, z, h, st.lanes);
        // The surface's normal in the straight frame (the bowl's and ruts' slopes).
        let normal = |x: f32, z: f32| {
            let e = 0.01;
            let dx = (depth(x + e, z) - depth(x - e, z)) / (2.0 * e);
            let dz = (depth(x, z + e) - depth(x, z - e)) / (2.0 * e);
            Vec3::new(dx, 1.0, dz).normalize()
        };
        // The stations strictly between z0 > z1, with both ends.
        let between = |z0: f32, z1: f32| -> Vec<f32> {
            let mut v = vec![z0];
            v.extend(
                zs.iter()
                    .copied()
                    .filter(|z| *z < z0 - 1e-3 && *z > z1 + 1e-3),
            );
            v.push(z1);
            v
        };
        // A strip on the carriageway from x0 to x1 and z0 down to z1, `lift` above it.
        let strip = |m: &mut Mesh, x: [f32; 2], z0: f32, z1: f32, lift: f32| {
            let rows = between(z0, z1);
            m.grid(1, rows.len() - 1, |i, j| {
                let (x, z) = (x[i], rows[j]);
                (
                    Vec3::new(x, lift - depth(x, z), z),
                    normal(x, z),
                    Vec2::new(x, z),
                )
            });
        };

        // The carriageway, 20 cm across for the crown, ruts and potholes.
        let cols = (2.0 * h / 0.2).ceil() as usize;
        let mut road = Mesh::new();
        road.grid(cols, zs.len() - 1, |i, j| {
            let (x, z) = (-h + 2.0 * h * i as f32 / cols as f32, zs[j]);
            (
                Vec3::new(x, -depth(x, z), z),
                normal(x, z),
                Vec2::new((x + h) / (2.0 * h), (n - z) / (n - f)),
            )
        });
        self.add_bent(doc, "road", &road, asphalt, Tag::stuff(Class::Road))?;

        // Water in the potholes: flat, 1 cm below the rim's lowest point.
        let mut water = Mesh::new();
        for p in &feat.potholes {
            let rim: Vec<Vec3> = (0..=32)
                .map(|k| {
                    let phi = std::f32::consts::TAU * k as f32 / 32.0;
                    let r = 0.98 * p.rim(phi);
                    let (x, z) = (p.x + r * phi.cos(), p.z + r * phi.sin());
                    self.road.world(Vec3::new(x, -depth(x, z), z))
                })
                .collect();
            let level = rim.iter().map(|q| q.y).fold(f32::INFINITY, f32::min) - 0.01;
            let mut fan = vec![self.road.world(Vec3::new(p.x, 0.0, p.z))];
            fan.extend(rim);
            for q in &mut fan {
                q.y = level;
            }
            water.polygon(&fan, Vec3::Y);
        }
        if !water.indices.is_empty() {
            let still = Material::paper(
                "pothole_water",
                PaperBsdf::Ggx { alpha: st.wet.1 },
                [st.asphalt_kd; 3],
                [st.wet.0; 3],
            )
            .as_road();
            doc.add_tagged_mesh("pothole_water", &water, &still, Tag::stuff(Class::Road))?;
        }

        // Markings, worn away in 25 cm pieces: lane dividers (3 m dashes, 9 m gaps), edge
        // lines, zebra bars (50 cm wide, 50 cm apart).
        let mut marks = Mesh::new();
        let mut piece = 0u32;
        let mut painted = |m: &mut Mesh, x: [f32; 2], z0: f32, z1: f32| {
            let pieces = ((z0 - z1) / 0.25).ceil().max(1.0) as usize;
            let len = (z0 - z1) / pieces as f32;
            for k in 0..pieces {
                piece += 1;
                if f64::from(hash01(piece, self.seed ^ 0x7061_696e)) >= feat.paint.wear {
                    let a = z0 - k as f32 * len;
                    strip(m, x, a, a - len, 0.002);
                }
            }
        };
        let crossing = |z: f32, margin: f32| {
            feat.crosswalks
                .iter()
                .any(|c| (z - c.z).abs() < 0.5 * c.length + margin)
        };
        for k in 1..st.lanes.max(1) {
            let x = -h + k as f32 * (2.0 * h / st.lanes as f32);
            let mut z = n - 2.0;
            while z - 3.0 > f {
                if !crossing(z, 1.0) && !crossing(z - 3.0, 1.0) {
                    painted(&mut marks, [x - 0.06, x + 0.06], z, z - 3.0);
                }
                z -= 12.0;
            }
        }
        for side in [-1.0f32, 1.0] {
            let x = side * (h - 0.2);
            for rows in self.runs(&zs, side) {
                let (a, b) = (rows[0], rows[rows.len() - 1]);
                painted(&mut marks, [x - 0.06, x + 0.06], a, b);
            }
        }
        for c in &feat.crosswalks {
            let mut x = -h + 0.5;
            while x + 0.5 <= h - 0.4 {
                painted(
                    &mut marks,
                    [x, x + 0.5],
                    c.z + 0.5 * c.length,
                    c.z - 0.5 * c.length,
                );
                x += 1.0;
            }
        }
        if !marks.indices.is_empty() {
            self.add_bent(
                doc,
                "lane_markings",
                &marks,
                paint,
                Tag::stuff(Class::Marking),
            )?;
        }

        // Tram tracks: grooved rails flush with the road, standard gauge.
        if !feat.tracks.is_empty() {
            let (mut heads, mut grooves) = (Mesh::new(), Mesh::new());
            for &xt in &feat.tracks {
                for side in [-1.0f32, 1.0] {
                    let inner = xt + side * 0.5 * GAUGE;
                    let head = [inner, inner + side * RAIL_HEAD];
                    let groove = [inner - side * RAIL_GROOVE, inner];
                    strip(
                        &mut heads,
                        [head[0].min(head[1]), head[0].max(head[1])],
                        n,
                        f,
                        0.001,
                    );
                    strip(
                        &mut grooves,
                        [groove[0].min(groove[1]), groove[0].max(groove[1])],
                        n,
                        f,
                        0.001,
                    );
                }
            }
            let steel = Material::paper(
                "rail_steel",
                PaperBsdf::Ggx { alpha: 0.08 },
                [0.04; 3],
                [0.55; 3],
            );
            let gap = Material::paper(
                "rail_groove",
                PaperBsdf::Ggx { alpha: 0.3 },
                [0.01; 3],
                [0.02; 3],
            );
            self.add_bent(
                doc,
                "rail_heads",
                &heads,
                &steel,
                Tag::stuff(Class::RailTrack),
            )?;
            self.add_bent(
                doc,
                "rail_grooves",
                &grooves,
                &gap,
                Tag::stuff(Class::RailTrack),
            )?;
        }

        // Kerbs (dropped beside the crossings) and pavements up to the facades, open at the
        // side streets' mouths.
        let kerb = |z: f32| feat.kerb_at(st.kerb, z);
        let mut kerbs = Mesh::new();
        let mut walks = Mesh::new();
        for side in [-1.0f32, 1.0] {
            let (a, b) = (side * h, side * (h + st.kerb));
            let (c, d) = (side * (h + st.kerb), side * st.facade_x);
            for rows in self.runs(&zs, side) {
                let ys = |m: &mut Mesh, x: [f32; 2]| {
                    let (x0, x1) = (x[0].min(x[1]), x[0].max(x[1]));
                    m.grid(1, rows.len() - 1, |i, j| {
                        let x = [x0, x1][i];
                        (
                            Vec3::new(x, kerb(rows[j]), rows[j]),
                            Vec3::Y,
                            Vec2::new(x, rows[j]),
                        )
                    });
                };
                ys(&mut kerbs, [a, b]);
                ys(&mut walks, [c, d]);
                // The kerb's face towards the road.
                kerbs.grid(1, rows.len() - 1, |i, j| {
                    let y = [0.0, kerb(rows[j])][i];
                    (
                        Vec3::new(a, y, rows[j]),
                        Vec3::X * -side,
                        Vec2::new(y, rows[j]),
                    )
                });
            }
        }

        // The side streets: carriageway, a stop line, kerbs and pavements along them.
        let mut side_road = Mesh::new();
        let mut marks_side = Mesh::new();
        for jn in &feat.junctions {
            let side = jn.side;
            let (z0, z1) = jn.mouth();
            let rows = between(z0, z1);
            let far_x = st.facade_x + jn.length;
            side_road.grid(1, rows.len() - 1, |i, j| {
                let x = side * [h, far_x][i];
                (
                    Vec3::new(x, 0.0, rows[j]),
                    Vec3::Y,
                    Vec2::new((x + h) / (2.0 * h), (n - rows[j]) / (n - f)),
                )
            });
            let stop = side * (h + 0.6);
            strip(
                &mut marks_side,
                [stop.min(stop + side * 0.3), stop.max(stop + side * 0.3)],
                z0,
                z1,
                0.002,
            );
            for (edge, out) in [(z0, 1.0f32), (z1, -1.0)] {
                // Kerb face (towards the side street), kerb top and pavement, along X.
                let (x0, x1) = (side * h, side * far_x);
                let (xa, xb) = (x0.min(x1), x0.max(x1));
                kerbs.quad_uv(
                    [
                        Vec3::new(xa, 0.0, edge),
                        Vec3::new(xb, 0.0, edge),
                        Vec3::new(xb, st.kerb, edge),
                        Vec3::new(xa, st.kerb, edge),
                    ],
                    [
                        Vec2::new(xa, 0.0),
                        Vec2::new(xb, 0.0),
                        Vec2::new(xb, st.kerb),
                        Vec2::new(xa, st.kerb),
                    ],
                    Vec3::Z * -out,
                );
                let (f0, f1) = (side * st.facade_x, side * far_x);
                let (fa, fb) = (f0.min(f1), f0.max(f1));
                let (k0, k1) = (edge, edge + out * st.kerb);
                let (w0, w1) = (k1, edge + out * jn.pavement);
                for (m, za, zb, xs) in [
                    (&mut kerbs, k0, k1, [fa, fb]),
                    (&mut walks, w0, w1, [fa, fb]),
                ] {
                    m.quad_uv(
                        [
                            Vec3::new(xs[0], st.kerb, za),
                            Vec3::new(xs[1], st.kerb, za),
                            Vec3::new(xs[1], st.kerb, zb),
                            Vec3::new(xs[0], st.kerb, zb),
                        ],
                        [
                            Vec2::new(xs[0], za),
                            Vec2::new(xs[1], za),
                            Vec2::new(xs[1], zb),
                            Vec2::new(xs[0], zb),
                        ],
                        Vec3::Y,
                    );
                }
            }
        }
        if !side_road.indices.is_empty() {
            self.add_bent(
                doc,
                "side_roads",
                &side_road,
                asphalt,
                Tag::stuff(Class::Road),
            )?;
        }
        if !marks_side.indices.is_empty() {
            self.add_bent(
                doc,
                "stop_lines",
                &marks_side,
                paint,
                Tag::stuff(Class::Marking),
            )?;
        }
        kerbs.scale_uvs(TILE_FINE);
        walks.scale_uvs(TILE_COARSE);
        self.add_bent(doc, "kerbs", &kerbs, stone, Tag::stuff(Class::Sidewalk))?;
        self.add_bent(
            doc,
            "sidewalks",
            &walks,
            pavement,
            Tag::stuff(Class::Sidewalk),
        )?;
        Ok(())
    }

    /// The runs of `zs` (stations, descending) on side `side` outside the side streets'
    /// mouths, each with at least two stations.
    fn runs(&self, zs: &[f32], side: f32) -> Vec<Vec<f32>> {
        let mut out: Vec<Vec<f32>> = Vec::new();
        let mut run: Vec<f32> = Vec::new();
        for w in zs.windows(2) {
            let mid = 0.5 * (w[0] + w[1]);
            if self.features.in_mouth(side, mid, 0.0) {
                if run.len() >= 2 {
                    out.push(std::mem::take(&mut run));
                }
                run.clear();
                continue;
            }
            if run.is_empty() {
                run.push(w[0]);
            }
            run.push(w[1]);
        }
        if run.len() >= 2 {
            out.push(run);
        }
        out
    }

    /// Adds `mesh`, laid out in the straight frame, bent onto the road.
    fn add_bent(
        &self,
        doc: &mut Doc,
        name: &str,
        mesh: &Mesh,
        material: &Material,
        tag: Tag,
    ) -> Result<(), Error> {
        doc.add_tagged_mesh(name, &self.road.bend_mesh(mesh), material, tag)
    }

    /// `light`, placed in the straight frame, on the road.
    fn bent_light(&self, light: Light) -> Light {
        let (position, direction) = self.road.bend_ray(light.position, light.direction);
        Light {
            position,
            direction,
            ..light
        }
    }

    /// The height of the pavement at `z` (the kerb's, dropped beside crossings).
    fn pavement_y(&self, z: f32) -> f32 {
        self.features.kerb_at(self.style.kerb, z)
    }

    fn lamps(&self, doc: &mut Doc, tex: &Albedos) -> Result<(), Error> {
        let metal = tex.stone.paper(
            "painted_metal",
            PaperBsdf::Ggx { alpha: 0.3 },
            [0.06; 3],
            [0.05; 3],
        );
        let st = &self.style;
        // The visible lens is a marker; the light is the point light 10 cm below it.
        let lens = Material::emitter("lamp_lens", st.lens_radiance);
        // Everything of the lamp head is placed relative to the light's height.
        let up = st.lamp_height - LAMP_H;
        let (kerb, half) = (st.kerb, st.road_half);
        let mut poles = Mesh::new();
        let mut lenses = Mesh::new();
        let sides = self
            .lamps_right
            .iter()
            .map(|&z| (1.0f32, z))
            .chain(self.lamps_left.iter().map(|&z| (-1.0f32, z)));
        if !self.lamp_models.is_empty() {
            for (k, ((side, z), model)) in sides.zip(&self.lamp_models).enumerate() {
                self.add_standing(
                    doc,
                    &format!("street_lamp_{k}"),
                    model,
                    side * (half + kerb + 0.5),
                    z,
                )?;
            }
            return Ok(());
        }
        for (k, (side, z)) in sides.enumerate() {
            let pole_x = side * (half + kerb + 0.5);
            let head_x = side * (half - 0.9);
            let base = self.pavement_y(z);
            poles.cylinder(Vec3::new(pole_x, base, z), 0.09, (6.5 + up) - base, 12);
            let (a, b) = (pole_x, head_x);
            poles.cuboid(
                Vec3::new(a.min(b), 6.3 + up, z - 0.05),
                Vec3::new(a.max(b), 6.4 + up, z + 0.05),
            );
            // The head is at least 60 x 30 cm, and 5 cm (across) and 3 cm (along) wider than
            // the lens on each side.
            let lx = 0.3f32.max(st.lens_half.1 + 0.05);
            let lz = 0.15f32.max(st.lens_half.0 + 0.03);
            let head_min = Vec3::new(head_x - lx, 6.0 + up, z - lz);
            let head_max = Vec3::new(head_x + lx, 6.3 + up, z + lz);
            poles.cuboid(head_min, head_max);
            lenses.rect(
                Vec3::new(head_x, 5.999 + up, z),
                Vec3::Z * st.lens_half.0,
                Vec3::X * st.lens_half.1,
            );
            doc.add_light(&self.bent_light(Light {
                name: format!("street_lamp_{k}"),
                kind: match st.lamp_cone {
                    None => LightKind::Point,
                    Some((inner, outer)) => LightKind::Spot { inner, outer },
                },
                color: st.lamp_color,
                intensity: st.lamp_intensity,
                position: Vec3::new(head_x, st.lamp_height, z),
                direction: Vec3::NEG_Y,
            }));
        }
        if poles.indices.is_empty() {
            return Ok(());
        }
        poles.scale_uvs(TILE_FINE);
        self.add_bent(doc, "lamp_posts", &poles, &metal, Tag::stuff(Class::Pole))?;
        // rect(c, Z, X) faces Z x X = +Y; the lens must face down.
        flip(&mut lenses);
        self.add_bent(
            doc,
            "lamp_lenses",
            &lenses,
            &lens,
            Tag::stuff(Class::LightSource),
        )?;
        Ok(())
    }

    /// Adds `model` standing level on the pavement at straight-frame `(x, z)`, its -Z (the
    /// side it shows to traffic, a lamp's arm) turned towards the road.
    fn add_standing(
        &self,
        doc: &mut Doc,
        name: &str,
        model: &Model,
        x: f32,
        z: f32,
    ) -> Result<(), Error> {
        let ground = self.road.world(Vec3::new(x, self.pavement_y(z), z)).y;
        let face = glam::Quat::from_rotation_y(x.signum() * std::f32::consts::FRAC_PI_2);
        let pose = self.road.level_pose(f64::from(-z), ground)
            * Affine3A::from_rotation_translation(face, Vec3::new(x, 0.0, z));
        doc.add_model(name, model, pose, None)
    }

    fn poles(&self, doc: &mut Doc, tex: &Albedos) -> Result<(), Error> {
        let wood = tex.wood.paper(
            "wet_wood",
            PaperBsdf::Ggx { alpha: 0.35 },
            [0.1, 0.07, 0.045],
            [0.03; 3],
        );
        let mut m = Mesh::new();
        let st = &self.style;
        let x = -(st.road_half + st.kerb + 0.9);
        for &z in &self.poles {
            m.cylinder(Vec3::new(x, self.pavement_y(z), z), 0.13, 9.0, 12);
            m.cuboid(
                Vec3::new(x - 0.9, 8.3, z - 0.06),
                Vec3::new(x + 0.9, 8.42, z + 0.06),
            );
        }
        m.scale_uvs(TILE_FINE);
        if !self.poles.is_empty() {
            self.add_bent(doc, "telephone_poles", &m, &wood, Tag::stuff(Class::Pole))?;
        }
        Ok(())
    }

    /// The block frontages on the side `side` (+1 right, -1 left) from the near end towards
    /// the far end, as `(k, z0, z1)` with `z0 > z1`: block `k`'s frontage, its length taken
    /// from block `k + 3` on the left so that the two sides do not line up; the last one is cut
    /// at the far end, and a side street's gap ([`crate::road::Junction::gap`]) cuts the ones it
    /// crosses.
    fn frontages(&self, side: f32) -> Vec<(usize, f32, f32)> {
        let mut out = Vec::new();
        let mut z0 = self.near;
        for k in 0..self.blocks.len() {
            let len = if side < 0.0 {
                self.blocks[(k + 3) % self.blocks.len()].0
            } else {
                self.blocks[k].0
            };
            let z1 = (z0 - len).max(self.far);
            out.push((k, z0, z1));
            z0 = z1;
            if z0 <= self.far {
                break;
            }
        }
        // A side street's mouth and pavements leave a gap.
        for j in self.features.junctions.iter().filter(|j| j.side == side) {
            let (g0, g1) = j.gap();
            out = out
                .into_iter()
                .flat_map(|(k, a, b)| {
                    let mut pieces = Vec::new();
                    if a > g0 {
                        pieces.push((k, a, b.max(g0)));
                    }
                    if b < g1 {
                        pieces.push((k, a.min(g1), b));
                    }
                    pieces
                })
                .filter(|(_, a, b)| a > b)
                .collect();
        }
        out
    }

    /// The buildings [`Street::drawn_buildings`] draws, as `(side, (z0, z1), spec)`: one per
    /// block frontage longer than 1 m ([`Street::frontages`]), right side first; none for a
    /// street of boxes.
    pub fn building_specs(&self) -> Vec<(f32, (f32, f32), BuildingSpec)> {
        use rand::SeedableRng;
        let Some(drawn) = &self.drawn_buildings else {
            return Vec::new();
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(drawn.seed);
        let (warm, lit) = self.style.lit_windows;
        let cool = if lit > 0.0 { 1.0 - warm / lit } else { 0.0 };
        let mut rows = Vec::new();
        for side in [1.0f32, -1.0] {
            for (_, z0, z1) in self.frontages(side) {
                let frontage = z0 - z1;
                if frontage > 1.0 {
                    let spec = BuildingSpec::draw(
                        &mut rng,
                        &drawn.config,
                        frontage,
                        (lit, cool, self.style.lit_shops),
                    );
                    rows.push((side, (z0, z1), spec));
                }
            }
        }
        rows
    }

    /// The buildings on both sides as drawn models ([`crate::buildings`]): block frontages
    /// from [`Street::blocks`] as the boxes have them (the left side offset by three blocks),
    /// each a [`BuildingSpec`] placed with its lot line on the facade line.
    fn drawn_buildings(&self, doc: &mut Doc, drawn: &DrawnBuildings) -> Result<(), Error> {
        let rows = self.building_specs();
        let specs: Vec<BuildingSpec> = rows.iter().map(|r| r.2.clone()).collect();
        let palette = Palette::new(
            doc,
            &specs,
            drawn.seed as u32,
            (drawn.window_cd, drawn.shop_cd),
            self.style.wetness,
        )?;
        for (k, (side, (z0, z1), spec)) in rows.iter().enumerate() {
            let model = facade(spec, &palette)?;
            // Level on its lot at the frontage's lowest ground (it sinks into the pavement
            // where the road climbs), turned to the road's heading at its middle, and moved
            // back off the pavement where the facade line curves towards the road.
            let fx = self.style.facade_x;
            let x = side * fx;
            let (s0, s1) = (f64::from(-z0), f64::from(-z1));
            let lift = self.road.lowest_ground(x, s0, s1);
            let z = 0.5 * (z0 + z1);
            let mut on_road = self.road.level_pose(f64::from(-z), lift);
            if !self.road.is_straight() {
                let inverse = on_road.inverse();
                let intrusion = (0..=8)
                    .map(|i| {
                        let s = s0 + (s1 - s0) * f64::from(i) / 8.0;
                        let w = self.road.world(Vec3::new(x, 0.0, -s as f32));
                        side * inverse.transform_point3(w).x - fx
                    })
                    .fold(0.0f32, f32::max);
                on_road *= Affine3A::from_translation(Vec3::X * side * intrusion);
            }
            doc.add_model(
                &format!("building_{k}"),
                &model,
                on_road * placement(*side, fx, z),
                None,
            )?;
        }
        Ok(())
    }

    fn buildings(&self, doc: &mut Doc, tex: &Albedos) -> Result<(), Error> {
        let st = &self.style;
        // Drawn buildings replace the boxes on both sides; the block closing the far end stays.
        let sides: &[f32] = match &self.drawn_buildings {
            Some(drawn) => {
                self.drawn_buildings(doc, drawn)?;
                &[]
            }
            None => &[1.0, -1.0],
        };
        let facades = [
            tex.brick.paper(
                "facade_brick",
                PaperBsdf::Ggx { alpha: 0.4 },
                st.facade_kd[0],
                [0.02; 3],
            ),
            tex.stone.paper(
                "facade_render",
                PaperBsdf::Ggx { alpha: 0.4 },
                st.facade_kd[1],
                [0.02; 3],
            ),
            tex.stone.paper(
                "facade_concrete",
                PaperBsdf::Ggx { alpha: 0.4 },
                st.facade_kd[2],
                [0.02; 3],
            ),
        ];
        let facade_x = st.facade_x;
        let (warm_share, lit_share) = st.lit_windows;
        let glass = Material::paper(
            "window_glass",
            PaperBsdf::Ggx { alpha: 0.02 },
            [0.01; 3],
            [0.3; 3],
        );
        let lit = |c: [f64; 3]| c.map(|c| round7(c * st.window_scale));
        let warm = Material::emitter("window_warm", lit(WINDOW_WARM));
        let cool = Material::emitter("window_cool", lit(WINDOW_COOL));
        let shop = Material::emitter("shop_window", st.shop_radiance.unwrap_or_default());
        let mut by_material: Vec<Mesh> = vec![Mesh::new(); 3];
        let (mut dark, mut lit_warm, mut lit_cool) = (Mesh::new(), Mesh::new(), Mesh::new());
        let mut lit_shop = Mesh::new();
        let mut counter = 0u32;
        for &side in sides {
            for (k, z0, z1) in self.frontages(side) {
                let height = self.blocks[k].1;
                let (xa, xb) = (side * facade_x, side * (facade_x + 10.0));
                by_material[k % 3].cuboid(
                    Vec3::new(xa.min(xb), 0.0, z1),
                    Vec3::new(xa.max(xb), height, z0),
                );
                if self.windows {
                    // 1.2 x 1.5 m windows on a 3 m grid, 1 cm in front of the facade,
                    // facing the road; ground floors get wide shop windows.
                    let x = side * (facade_x - 0.01);
                    let normal_u = Vec3::Z * side; // u x v = Z x Y * side = -X * side
                    let mut zc = z0 - 2.0;
                    while zc > z1 + 1.5 {
                        let mut yc = 4.5;
                        while yc + 1.5 < height {
                            counter += 1;
                            let h = hash01(counter, self.seed);
                            let target = if h < warm_share {
                                &mut lit_warm
                            } else if h < lit_share {
                                &mut lit_cool
                            } else {
                                &mut dark
                            };
                            target.rect(Vec3::new(x, yc, zc), normal_u * 0.6, Vec3::Y * 0.75);
                            yc += 3.0;
                        }
                        zc -= 3.0;
                    }
                    let mut zc = z0 - 3.5;
                    while zc > z1 + 3.0 {
                        counter += 1;
                        let target = if hash01(counter, self.seed) >= st.lit_shops {
                            &mut dark
                        } else if st.shop_radiance.is_some() {
                            &mut lit_shop
                        } else {
                            &mut lit_warm
                        };
                        target.rect(Vec3::new(x, 1.5, zc), normal_u * 1.3, Vec3::Y * 0.9);
                        zc -= 5.0;
                    }
                }
            }
        }
        // A block closes each side street.
        for j in &self.features.junctions {
            let (g0, g1) = j.gap();
            let x0 = j.side * (facade_x + j.length);
            let x1 = x0 + j.side * 10.0;
            by_material[1].cuboid(
                Vec3::new(x0.min(x1), 0.0, g1 - 6.0),
                Vec3::new(x0.max(x1), 14.0, g0 + 6.0),
            );
        }
        // A block across the far end closes the street.
        let end = self.far;
        by_material[0].cuboid(
            Vec3::new(-facade_x - 10.0, 0.0, end - 10.0),
            Vec3::new(facade_x + 10.0, 16.0, end),
        );
        if self.windows {
            for ix in -4..=4 {
                for iy in 0..4 {
                    counter += 1;
                    let target = if hash01(counter, self.seed) < lit_share {
                        &mut lit_warm
                    } else {
                        &mut dark
                    };
                    target.rect(
                        Vec3::new(ix as f32 * 3.0, 4.5 + iy as f32 * 3.0, end + 0.01),
                        Vec3::X * 0.6,
                        Vec3::Y * 0.75,
                    );
                }
            }
        }
        for (k, m) in by_material.iter_mut().enumerate() {
            m.scale_uvs(TILE_COARSE);
            if !m.indices.is_empty() {
                self.add_bent(
                    doc,
                    &format!("buildings_{k}"),
                    m,
                    &facades[k],
                    Tag::stuff(Class::Building),
                )?;
            }
        }
        for (name, m, mat) in [
            ("windows_dark", &dark, &glass),
            ("windows_lit_warm", &lit_warm, &warm),
            ("windows_lit_cool", &lit_cool, &cool),
            ("shop_windows_lit", &lit_shop, &shop),
        ] {
            if !m.indices.is_empty() {
                self.add_bent(doc, name, m, mat, Tag::stuff(Class::Building))?;
            }
        }
        Ok(())
    }
}

/// `x` rounded to 2^-16 (for tiling factors written to the file).
fn round7q(x: f32) -> f32 {
    quantise(x, 16)
}

/// A deterministic pseudo-random number in [0, 1) for window `k`.
fn hash01(k: u32, seed: u32) -> f32 {
    let mut x = k.wrapping_mul(0x9e37_79b9) ^ seed;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Reverses every triangle and normal of `m` (turns it to face the other way).
fn flip(m: &mut Mesh) {
    for t in m.indices.chunks_mut(3) {
        t.swap(1, 2);
    }
    for n in &mut m.normals {
        *n = -*n;
    }
}

/// A car: body, cabin and wheels as boxes; headlights (spot lights and emissive lenses) at
/// the front, emissive red tail lights at the back; a parked car's lenses are unlit.
///
/// On a straight road the car is modelled in place; on any other it is modelled at the origin
/// facing -Z and placed with its pose on the road ([`crate::drive::car_pose`]).
fn add_car(street: &Street, doc: &mut Doc, k: usize, car: &Car) -> Result<(), Error> {
    let st = &street.style;
    let place = (!street.road.is_straight()).then(|| crate::drive::car_pose(&street.road, car));
    let local = Car {
        x: 0.0,
        z: 0.0,
        oncoming: false,
        ..*car
    };
    let car = if place.is_some() { &local } else { car };
    let put = |m: &Mesh| match place {
        Some(pose) => transformed(m, pose),
        None => m.clone(),
    };
    let dir = if car.oncoming { 1.0f32 } else { -1.0 }; // direction the car faces, along Z
    let instance = crate::procedural::car_instance(k);
    let (body_tag, lamp_tag) = (
        Tag::object(Class::Car, instance),
        Tag::object(Class::LightSource, instance),
    );
    let (x, z) = (car.x, car.z);
    let paint = Material::paper(
        &format!("car_paint_{k}"),
        PaperBsdf::Ggx { alpha: 0.05 },
        car.color,
        [0.3; 3],
    );
    let rubber = Material::paper("tyre", PaperBsdf::Ggx { alpha: 0.4 }, [0.02; 3], [0.02; 3]);
    let mut body = Mesh::new();
    body.cuboid(
        Vec3::new(x - 0.9, 0.3, z - 2.2),
        Vec3::new(x + 0.9, 1.0, z + 2.2),
    );
    // The cabin sits towards the back.
    let cz = z - dir * 0.3;
    body.cuboid(
        Vec3::new(x - 0.8, 1.0, cz - 1.2),
        Vec3::new(x + 0.8, 1.45, cz + 1.2),
    );
    doc.add_tagged_mesh(&format!("car_{k}_body"), &put(&body), &paint, body_tag)?;
    let mut wheels = Mesh::new();
    for sx in [-1.0f32, 1.0] {
        for sz in [-1.0f32, 1.0] {
            let (wx, wz) = (x + sx * 0.8, z + sz * 1.4);
            wheels.cuboid(
                Vec3::new(wx - 0.12, 0.0, wz - 0.32),
                Vec3::new(wx + 0.12, 0.62, wz + 0.32),
            );
        }
    }
    doc.add_tagged_mesh(&format!("car_{k}_wheels"), &put(&wheels), &rubber, body_tag)?;
    let front = z + dir * 2.2;
    let back = z - dir * 2.2;
    let mut heads = Mesh::new();
    let mut tails = Mesh::new();
    for (j, sx) in [-1.0f32, 1.0].into_iter().enumerate() {
        let hx = x + sx * 0.6;
        heads.rect(
            Vec3::new(hx, 0.72, front + dir * 0.002),
            Vec3::X * dir * 0.15,
            Vec3::Y * 0.06,
        );
        tails.rect(
            Vec3::new(hx + sx * 0.1, 0.85, back - dir * 0.002),
            Vec3::X * -dir * 0.1,
            Vec3::Y * 0.06,
        );
        if !car.headlights || car.parked {
            continue;
        }
        let light = Light {
            name: format!("car_{k}_headlight_{j}"),
            kind: LightKind::Spot {
                inner: 0.15,
                outer: 0.4,
            },
            color: st.headlight_color,
            intensity: st.headlight_intensity,
            position: Vec3::new(hx, 0.72, front + dir * 0.05),
            direction: Vec3::new(0.0, -0.03, dir),
        };
        doc.add_light(&match place {
            Some(pose) => transformed_light(&light, pose),
            None => light,
        });
    }
    let (head_lens, tail_lens) = if car.parked {
        (
            Material::paper(
                "headlamp_glass",
                PaperBsdf::Ggx { alpha: 0.02 },
                [0.02; 3],
                [0.3; 3],
            ),
            Material::paper(
                "tail_light_off",
                PaperBsdf::Ggx { alpha: 0.05 },
                [0.12, 0.01, 0.01],
                [0.1; 3],
            ),
        )
    } else {
        (
            Material::emitter("headlamp_lens", st.headlamp_radiance),
            Material::emitter("tail_light", [6.0, 0.3, 0.15]),
        )
    };
    doc.add_tagged_mesh(
        &format!("car_{k}_headlamps"),
        &put(&heads),
        &head_lens,
        lamp_tag,
    )?;
    doc.add_tagged_mesh(
        &format!("car_{k}_tail_lights"),
        &put(&tails),
        &tail_lens,
        lamp_tag,
    )?;
    Ok(())
}

/// Traffic light `k` on a sidewalk, facing the driver: the lit signal has an emissive lens
/// and a spot light, the other two lenses are dark. The first one keeps the shipped scenes'
/// names (`traffic_light`, `signal_red`, ...); later ones get the index appended.
fn add_traffic_light(
    street: &Street,
    doc: &mut Doc,
    k: usize,
    t: &TrafficLight,
) -> Result<(), Error> {
    let st = &street.style;
    let z = t.z;
    let x = t.side * (st.road_half + st.kerb + 0.6);
    let suffix = if k == 0 {
        String::new()
    } else {
        format!("_{k}")
    };
    let mut m = Mesh::new();
    m.cylinder(Vec3::new(x, street.pavement_y(z), z), 0.07, 3.2, 12);
    m.cuboid(
        Vec3::new(x - 0.17, 3.2, z - 0.25),
        Vec3::new(x + 0.17, 4.2, z),
    );
    // Traffic lights are numbered after the cars' instance ids.
    let signal_instance = 1000 + k as u32;
    street.add_bent(
        doc,
        &format!("traffic_light{suffix}"),
        &m,
        &Material::paper(
            "traffic_light_housing",
            PaperBsdf::Ggx { alpha: 0.3 },
            [0.02; 3],
            [0.04; 3],
        ),
        Tag::object(Class::TrafficLight, signal_instance),
    )?;
    // (signal, name, height, lit radiance, dark radiance, spot colour)
    let lenses = [
        (
            Signal::Red,
            "red",
            3.95,
            [40.0, 2.0, 0.8],
            [0.15, 0.0, 0.0],
            [1.0, 0.05, 0.02],
        ),
        (
            Signal::Amber,
            "amber",
            3.7,
            [40.0, 16.0, 0.0],
            [0.15, 0.08, 0.0],
            [1.0, 0.4, 0.0],
        ),
        (
            Signal::Green,
            "green",
            3.45,
            [0.0, 30.0, 15.0],
            [0.0, 0.12, 0.06],
            [0.0, 1.0, 0.5],
        ),
    ];
    let mut lit_height = 3.95;
    let mut spot_color = [1.0, 0.05, 0.02];
    for (signal, name, y, lit, dark, color) in lenses {
        let name = format!("signal_{name}{suffix}");
        let radiance = if signal == t.signal {
            lit_height = y;
            spot_color = color;
            lit
        } else {
            dark
        };
        let mut q = Mesh::new();
        q.rect(Vec3::new(x, y, z + 0.002), Vec3::X * 0.1, Vec3::Y * 0.1);
        street.add_bent(
            doc,
            &name,
            &q,
            &Material::emitter(&name, radiance),
            Tag::object(Class::LightSource, signal_instance),
        )?;
    }
    let light_name = match t.signal {
        Signal::Red => "red",
        Signal::Amber => "amber",
        Signal::Green => "green",
    };
    doc.add_light(&street.bent_light(Light {
        name: format!("signal_{light_name}_light{suffix}"),
        kind: LightKind::Spot {
            inner: 0.3,
            outer: 0.7,
        },
        color: spot_color,
        intensity: st.signal_intensity,
        position: Vec3::new(x, lit_height, z + 0.06),
        direction: Vec3::new(-0.05 * t.side, -0.1, 1.0),
    }));
    Ok(())
}

/// Road signs: a grey post and a plate 2 cm in front of it, facing the driver (+Z).
fn add_signs(street: &Street, doc: &mut Doc, signs: &[Sign]) -> Result<(), Error> {
    let st = &street.style;
    let mut posts = Mesh::new();
    for (k, s) in signs.iter().enumerate() {
        let x = s.side * (st.road_half + st.kerb + 0.4);
        posts.cylinder(
            Vec3::new(x, street.pavement_y(s.z), s.z),
            0.04,
            s.height + s.half,
            8,
        );
        let mut plate = Mesh::new();
        // rect(c, u, v) faces u x v = X x Y = +Z: towards the driver.
        plate.rect(
            Vec3::new(x, s.height, s.z + 0.06),
            Vec3::X * s.half,
            Vec3::Y * s.half,
        );
        let name = format!("sign_{k}");
        let plate_material =
            Material::paper(&name, PaperBsdf::Ggx { alpha: 0.25 }, s.color, [0.08; 3]);
        street.add_bent(
            doc,
            &name,
            &plate,
            &plate_material,
            Tag::stuff(Class::TrafficSign),
        )?;
    }
    let metal = Material::paper(
        "sign_post",
        PaperBsdf::Ggx { alpha: 0.3 },
        [0.15; 3],
        [0.05; 3],
    );
    street.add_bent(doc, "sign_posts", &posts, &metal, Tag::stuff(Class::Pole))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimate::peak_radiance;
    use crate::wetness::WET_ROAD_W;
    use glam::DVec3;

    #[test]
    fn lamp_streaks_are_bright_but_sensible() {
        // A lamp 40 m ahead over ordinary wet asphalt gives a streak peak of order 1.
        let brdf = asphalt_at(f64::from(WET_ROAD_W));
        let eye = EYE.as_dvec3();
        let lamp = DVec3::new(f64::from(ROAD_HALF) - 0.9, f64::from(LAMP_H), -40.0);
        let l = peak_radiance(brdf, eye, lamp, LAMP_INTENSITY);
        println!("lamp 40 m ahead, w = 0.2: peak {l}");
        assert!(l > 0.5 && l < 5.0, "peak {l}");
    }

    #[test]
    fn full_street_is_moderate_and_small_is_small() {
        let full = Street::full().build().unwrap();
        assert!(full.triangle_count() < 50_000);
        assert!(full.light_count() >= 10);
        let small = Street::small().build().unwrap();
        assert!(small.triangle_count() < 2_000, "{}", small.triangle_count());
        assert!((2..=3).contains(&small.light_count()));
    }

    /// A side street cuts the right frontage and the right kerb's runs at its mouth, leaves
    /// the left side as it was, and brings its own carriageway and stop line.
    #[test]
    fn a_junction_opens_the_street() {
        let mut s = Street::small();
        s.features.junctions.push(crate::road::Junction {
            z: -30.0,
            side: 1.0,
            width: 7.0,
            pavement: 2.0,
            length: 15.0,
        });
        let (g0, g1) = s.features.junctions[0].gap();
        let right = s.frontages(1.0);
        assert!(right.len() > Street::small().frontages(1.0).len());
        for (_, a, b) in right {
            assert!(b >= g0 - 1e-4 || a <= g1 + 1e-4, "{a}..{b} crosses the gap");
        }
        assert_eq!(s.frontages(-1.0), Street::small().frontages(-1.0));
        let zs = s.features.stations(s.near, s.far, 1.0);
        let runs = s.runs(&zs, 1.0);
        assert_eq!(runs.len(), 2);
        for z in runs.iter().flatten() {
            assert!(*z >= -26.5 - 1e-4 || *z <= -33.5 + 1e-4, "kerb at {z}");
        }
        assert_eq!(s.runs(&zs, -1.0), vec![zs.clone()]);
        let dir = tempfile::tempdir().unwrap();
        s.build().unwrap().write(dir.path()).unwrap();
        let gltf: serde_json::Value = serde_json::from_slice(
            &std::fs::read(dir.path().join("rainy_street_small.gltf")).unwrap(),
        )
        .unwrap();
        let names: Vec<&str> = gltf["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|m| m["name"].as_str())
            .collect();
        assert!(
            names.contains(&"side_roads") && names.contains(&"stop_lines"),
            "{names:?}"
        );
    }

    #[test]
    fn flip_reverses_winding() {
        let mut m = Mesh::new();
        m.rect(Vec3::ZERO, Vec3::Z, Vec3::X);
        flip(&mut m);
        let p = [0, 1, 2].map(|k| m.positions[m.indices[k] as usize]);
        assert!((p[1] - p[0]).cross(p[2] - p[0]).y < 0.0);
        assert_eq!(m.normals[0], Vec3::NEG_Y);
    }
}
