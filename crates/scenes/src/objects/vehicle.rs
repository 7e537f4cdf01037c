//! Vehicles as [`Model`]s: saloons, hatchbacks, estates, SUVs, panel vans and city buses,
//! each built from a [`VehicleSpec`] drawn by [`VehicleSpec::draw`].
//!
//! A body is a few closed prisms extruded across the car from side profiles: a lower body
//! with a sloped bonnet and a boot, cut out over the wheels, and a greenhouse with sloped
//! screens whose sides lean in (tumblehome). Windows are thin-walled transmissive glass
//! over a dark interior; the paint is glTF PBR under a clear coat; the wheels are closed
//! tyre cylinders with metal rims. Lamps are emitters (class [`Class::LightSource`]) with
//! punctual lights: headlights are spot lights forward, tail and brake lights small red spot
//! lights backwards. Dimensions are drawn from [`BodyType::ranges`], documented with the
//! cars they come from in `docs/decisions/0040-vehicles-and-furniture-as-models.md`.
//!
//! The model's frame: +X right, +Y up, -Z forward (the direction of travel), the origin on
//! the ground at the centre of the footprint.

use super::{led_rgb, ObjectsConfig, Paint, AMBER_NM, RED_NM};
use crate::gltf_writer::{Clearcoat, Light, LightKind, Material, Pbr, Transmission};
use crate::light_sources::{luminance, LightSource};
use crate::mesh::Mesh;
use crate::model::Model;
use glam::{Vec2, Vec3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use streaks_render::class::Class;

/// A body type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyType {
    /// Three-box saloon (sedan): bonnet, cabin, boot.
    Saloon,
    /// Two-box hatchback: a short body with a steep tailgate.
    Hatchback,
    /// Estate (station wagon): the roof runs to a near-vertical tailgate.
    Estate,
    /// Sport-utility vehicle: tall, high ground clearance, big wheels.
    Suv,
    /// Panel van: a short bonnet, a tall box body, windows only at the cab.
    Van,
    /// Rigid city bus: flat front, windows all along.
    Bus,
}

/// Ranges of a body type's dimensions, metres: `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyRanges {
    /// Overall length.
    pub length: [f32; 2],
    /// Overall width (without mirrors).
    pub width: [f32; 2],
    /// Overall height.
    pub height: [f32; 2],
    /// Tyre outer radius.
    pub wheel_radius: [f32; 2],
}

impl BodyType {
    /// Every body type.
    pub const ALL: [BodyType; 6] = [
        BodyType::Saloon,
        BodyType::Hatchback,
        BodyType::Estate,
        BodyType::Suv,
        BodyType::Van,
        BodyType::Bus,
    ];

    /// The TOML name.
    pub fn name(self) -> &'static str {
        match self {
            BodyType::Saloon => "saloon",
            BodyType::Hatchback => "hatchback",
            BodyType::Estate => "estate",
            BodyType::Suv => "suv",
            BodyType::Van => "van",
            BodyType::Bus => "bus",
        }
    }

    /// Typical dimensions of current European models of the type (see the module
    /// documentation for the sources).
    pub fn ranges(self) -> BodyRanges {
        let r = |length, width, height, wheel_radius| BodyRanges {
            length,
            width,
            height,
            wheel_radius,
        };
        match self {
            BodyType::Saloon => r([4.4, 4.95], [1.75, 1.87], [1.40, 1.50], [0.31, 0.34]),
            BodyType::Hatchback => r([3.55, 4.35], [1.62, 1.80], [1.42, 1.55], [0.29, 0.32]),
            BodyType::Estate => r([4.5, 4.95], [1.78, 1.87], [1.45, 1.55], [0.31, 0.34]),
            BodyType::Suv => r([4.3, 4.9], [1.80, 1.95], [1.60, 1.80], [0.34, 0.38]),
            BodyType::Van => r([4.9, 5.95], [1.95, 2.07], [1.95, 2.60], [0.33, 0.36]),
            BodyType::Bus => r([10.5, 12.2], [2.50, 2.55], [2.95, 3.20], [0.48, 0.52]),
        }
    }

    /// The semantic class (Cityscapes: a van with a continuous body is a car).
    pub fn class(self) -> Class {
        match self {
            BodyType::Bus => Class::Bus,
            _ => Class::Car,
        }
    }
}

/// What a vehicle is doing, which sets its lights.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// Parked at the kerb: every lamp off.
    Parked,
    /// Driving ahead of the camera: headlights and tail lights on, brake lights sometimes.
    Leading,
    /// Coming towards the camera: headlights and tail lights on.
    Oncoming,
}

/// A headlight pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Headlights {
    /// The lamp technology (its colour).
    pub source: LightSource,
    /// Luminous intensity of each lamp on its axis, in W/sr of luminance (candela / 683):
    /// the generator's `cars.headlight_intensity`.
    pub intensity: f64,
    /// Luminance of the lit lens, in W/(m^2 sr) of luminance (cd/m^2 / 683).
    pub lens_luminance: f64,
}

/// The lamps of a vehicle and their state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleLights {
    /// Headlights, `None` when off.
    pub headlights: Option<Headlights>,
    /// Each tail light's luminous intensity, candela (`None`: off).
    pub tail_cd: Option<f64>,
    /// Each brake light's luminous intensity, candela (`None`: not braking).
    pub brake_cd: Option<f64>,
}

impl VehicleLights {
    /// Every lamp off (a parked vehicle).
    pub const OFF: Self = Self {
        headlights: None,
        tail_cd: None,
        brake_cd: None,
    };
}

/// Everything that fixes one vehicle's model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleSpec {
    /// Body type.
    pub body: BodyType,
    /// Overall length, metres.
    pub length: f32,
    /// Overall width, metres.
    pub width: f32,
    /// Overall height, metres.
    pub height: f32,
    /// Tyre radius, metres.
    pub wheel_radius: f32,
    /// Paint colour (linear RGB base colour).
    pub paint: [f64; 3],
    /// Metallic paint (flakes: metallic 0.5 under the clear coat) rather than solid.
    pub metallic: bool,
    /// The lamps.
    pub lights: VehicleLights,
}

/// Where one vehicle's lights get their levels from (drawn once per street by the
/// generator, like the street lamps).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrafficLighting {
    /// Headlights of the moving vehicles.
    pub headlights: Headlights,
}

impl VehicleSpec {
    /// Draws a vehicle for `role`: body type, size within its ranges, paint and the lamps
    /// the role has on (brake lights with probability `config.brake_lights` when leading).
    pub fn draw(
        rng: &mut ChaCha8Rng,
        config: &ObjectsConfig,
        role: Role,
        lighting: &TrafficLighting,
    ) -> Self {
        let body = super::weighted(rng, &config.body_types);
        let r = body.ranges();
        let mut within = |x: [f32; 2]| rng.random_range(x[0]..=x[1]);
        let (length, width, height, wheel_radius) = (
            within(r.length),
            within(r.width),
            within(r.height),
            within(r.wheel_radius),
        );
        let paint: Paint = super::weighted(rng, &config.paints);
        let metallic = paint.can_be_metallic() && rng.random_bool(config.metallic_paint);
        let lights = match role {
            Role::Parked => VehicleLights::OFF,
            Role::Leading | Role::Oncoming => {
                let tail = super::uniform(rng, config.tail_light_cd);
                let brake = (role == Role::Leading && rng.random_bool(config.brake_lights))
                    .then(|| super::uniform(rng, config.brake_light_cd));
                VehicleLights {
                    headlights: Some(lighting.headlights),
                    tail_cd: Some(tail),
                    brake_cd: brake,
                }
            }
        };
        Self {
            body,
            length,
            width,
            height,
            wheel_radius,
            paint: paint.rgb(),
            metallic,
            lights,
        }
    }

    /// The shape parameters of the body type at this size.
    fn shape(&self) -> Shape {
        let (l, h) = (self.length, self.height);
        let r = self.wheel_radius;
        // (belt / height, bonnet / length, windscreen angle, boot / length, rear screen
        // angle, clearance, front overhang / length, rear overhang / length)
        let (belt, bonnet, screen, boot, rear, clearance, front, back) = match self.body {
            BodyType::Saloon => (0.64, 0.21, 30.0, 0.20, 32.0, 0.14, 0.19, 0.23),
            BodyType::Hatchback => (0.64, 0.2, 30.0, 0.025, 58.0, 0.14, 0.2, 0.16),
            BodyType::Estate => (0.63, 0.21, 30.0, 0.02, 75.0, 0.15, 0.19, 0.21),
            BodyType::Suv => (0.6, 0.22, 35.0, 0.02, 68.0, 0.2, 0.2, 0.2),
            BodyType::Van => (0.5, 0.13, 42.0, 0.005, 88.0, 0.18, 0.17, 0.2),
            BodyType::Bus => (0.36, 0.0, 84.0, 0.0, 88.0, 0.3, 0.22, 0.28),
        };
        let belt = h * belt;
        let run = |deg: f32| (h - belt) / deg.to_radians().tan();
        let s_ws = l / 2.0 - bonnet * l;
        let s_rb = -l / 2.0 + boot * l;
        Shape {
            belt,
            bonnet_front: if bonnet > 0.0 { belt - 0.12 } else { belt },
            s_ws,
            s_wt: s_ws - run(screen),
            s_rb,
            s_rt: s_rb + run(rear),
            clearance,
            arch_top: 2.0 * r + 0.05,
            axle_front: l / 2.0 - front * l,
            axle_rear: -l / 2.0 + back * l,
            tyre_width: match self.body {
                BodyType::Bus => 0.3,
                BodyType::Van | BodyType::Suv => 0.24,
                _ => 0.21,
            },
            tumblehome: match self.body {
                BodyType::Bus => 0.03,
                BodyType::Van => 0.08,
                _ => 0.14,
            },
        }
    }

    /// Builds the model (see the module documentation).
    pub fn build(&self) -> Model {
        let sh = self.shape();
        let (l, w, h) = (self.length, self.width, self.height);
        let class = self.body.class();
        let mut model = Model::new();
        // Lower body: the profile (z, y) = (-s, y) of bumpers, bonnet and boot.
        let p = |s: f32, y: f32| Vec2::new(-s, y);
        let c = sh.clearance;
        let mut lower = vec![
            p(-l / 2.0 + 0.15, c),
            p(l / 2.0 - 0.2, c),
            p(l / 2.0, c + 0.15),
        ];
        if self.body == BodyType::Bus {
            lower.extend([p(l / 2.0, sh.belt), p(-l / 2.0, sh.belt)]);
        } else {
            lower.extend([
                p(l / 2.0, sh.bonnet_front - 0.08),
                p(l / 2.0 - 0.12, sh.bonnet_front),
                p(sh.s_ws, sh.belt),
                p(sh.s_rb, sh.belt),
            ]);
            if sh.s_rb - (-l / 2.0) > 0.25 {
                lower.push(p(-l / 2.0 + 0.12, sh.belt - 0.04));
            }
            lower.push(p(-l / 2.0, sh.belt - 0.15));
        }
        lower.push(p(-l / 2.0, c + 0.12));
        let half = w / 2.0;
        let mut body = Mesh::new();
        // Above the wheel arches: full width.
        body.prism(&clip(&lower, 1, sh.arch_top, true), |_| half);
        // Below: full width between the arches and at the bumpers, narrow over the wheels
        // (inboard of the tyres), so the wheels show in the arches.
        let below = clip(&lower, 1, sh.arch_top, false);
        let arch = 1.15 * self.wheel_radius;
        let narrow = half - sh.tyre_width - 0.04;
        let mut cuts = vec![
            (f32::NEG_INFINITY, sh.axle_rear - arch, half),
            (sh.axle_rear - arch, sh.axle_rear + arch, narrow),
            (sh.axle_rear + arch, sh.axle_front - arch, half),
            (sh.axle_front - arch, sh.axle_front + arch, narrow),
            (sh.axle_front + arch, f32::INFINITY, half),
        ];
        cuts.retain(|(a, b, _)| b > a);
        for (a, b, hw) in cuts {
            // s in [a, b] is z in [-b, -a].
            let piece = clip(&clip(&below, 0, -b, true), 0, -a, false);
            if piece.len() >= 3 {
                body.prism(&piece, |_| hw);
            }
        }
        // The greenhouse: sloped screens, sides leaning in.
        let roof = h;
        let cabin = [
            p(sh.s_ws, sh.belt),
            p(sh.s_wt, roof),
            p(sh.s_rt, roof),
            p(sh.s_rb, sh.belt),
        ];
        let lean = sh.tumblehome;
        let hw_at =
            move |y: f32| half - 0.03 - lean * ((y - sh.belt) / (roof - sh.belt)).clamp(0.0, 1.0);
        body.prism(&cabin, hw_at);
        let paint = Material::pbr(
            "car_paint",
            Pbr {
                clearcoat: Some(Clearcoat {
                    factor: 1.0,
                    roughness: 0.03,
                }),
                ..if self.metallic {
                    Pbr::new(self.paint, 0.5, 0.3)
                } else {
                    Pbr::new(self.paint, 0.0, 0.4)
                }
            },
        );
        model.push("body", body, paint, class);

        // Windows: a dark interior 2 mm out of the greenhouse and glass 4 mm out.
        let mut interior = Mesh::new();
        let mut glass = Mesh::new();
        let face_x = |y: f32, side: f32| side * hw_at(y);
        let mut pane = |corners: &[Vec3], normal: Vec3, margin: f32| {
            let inset = inset(corners, margin);
            let at = |d: f32| inset.iter().map(|&q| q + normal * d).collect::<Vec<_>>();
            interior.polygon(&at(0.002), normal);
            glass.polygon(&at(0.004), normal);
        };
        // Windscreen and rear screen.
        let screen = |s0: f32, s1: f32| {
            [
                Vec3::new(-face_x(sh.belt, 1.0), sh.belt, -s0),
                Vec3::new(face_x(sh.belt, 1.0), sh.belt, -s0),
                Vec3::new(face_x(roof, 1.0), roof, -s1),
                Vec3::new(-face_x(roof, 1.0), roof, -s1),
            ]
        };
        let inside = Vec3::new(
            0.0,
            0.5 * (sh.belt + roof),
            -0.25 * (sh.s_ws + sh.s_wt + sh.s_rt + sh.s_rb),
        );
        let front = screen(sh.s_ws, sh.s_wt);
        let n_front = outward_normal(&front, inside);
        pane(&front, n_front, 0.07);
        if self.body != BodyType::Van {
            let back = screen(sh.s_rb, sh.s_rt);
            let n_back = outward_normal(&back, inside);
            pane(&back, n_back, 0.07);
        }
        // Side windows between s0 and s1 (split by pillars).
        let spans: Vec<(f32, f32)> = match self.body {
            BodyType::Van => vec![(sh.s_wt - 0.55, sh.s_ws)],
            BodyType::Bus => {
                let (a, b) = (-l / 2.0 + 0.4, sh.s_wt - 0.9);
                let n = ((b - a) / 1.45).round().max(1.0) as usize;
                (0..n)
                    .map(|k| {
                        let d = (b - a) / n as f32;
                        (a + k as f32 * d, a + (k + 1) as f32 * d)
                    })
                    .collect()
            }
            _ => {
                let mid = 0.5 * (sh.s_wt + sh.s_rt) - 0.05;
                vec![(sh.s_rb, mid), (mid, sh.s_ws)]
            }
        };
        for side in [-1.0f32, 1.0] {
            let side_normal = Vec3::new(side, lean / (roof - sh.belt), 0.0).normalize();
            for &(s0, s1) in &spans {
                let outline: Vec<Vec3> = clip(&clip(&cabin, 0, -s1, true), 0, -s0, false)
                    .iter()
                    .map(|q| Vec3::new(face_x(q.y, side), q.y, q.x))
                    .collect();
                if outline.len() >= 3 {
                    pane(&outline, side_normal, 0.05);
                }
            }
        }
        model.push(
            "interior",
            interior,
            Material::pbr("car_interior", Pbr::new([0.02; 3], 0.0, 0.6)),
            class,
        );
        let mut glass_material = Material::pbr(
            "car_glass",
            Pbr {
                transmission: Some(Transmission {
                    factor: 0.9,
                    ior: 1.52,
                    volume: None,
                }),
                ..Pbr::new([0.78, 0.84, 0.82], 0.0, 0.0)
            },
        );
        glass_material.double_sided = true;
        model.push("glass", glass, glass_material, class);

        // Wheels.
        let r = self.wheel_radius;
        let mut tyres = Mesh::new();
        let mut rims = Mesh::new();
        let outer = half - 0.02;
        for s in [sh.axle_front, sh.axle_rear] {
            for side in [-1.0f32, 1.0] {
                let centre = |x: f32| Vec3::new(side * x, r, -s);
                tyres.cylinder_between(centre(outer - sh.tyre_width), centre(outer), r, 20);
                rims.cylinder_between(centre(outer - 0.03), centre(outer + 0.004), 0.62 * r, 16);
            }
        }
        model.push(
            "tyres",
            tyres,
            Material::pbr("tyre_rubber", Pbr::new([0.025; 3], 0.0, 0.85)),
            class,
        );
        model.push(
            "rims",
            rims,
            Material::pbr("rim_alloy", Pbr::new([0.6, 0.6, 0.62], 1.0, 0.3)),
            class,
        );
        self.lamps(&mut model, &sh);
        model
    }

    fn lamps(&self, model: &mut Model, sh: &Shape) {
        let (l, w) = (self.length, self.width);
        let class = self.body.class();
        let lights = self.lights;
        // Headlamps on the front face, facing -Z.
        let head_y = match self.body {
            BodyType::Bus => 0.75,
            _ => (sh.bonnet_front - 0.14).max(sh.clearance + 0.3),
        };
        let (head_half, head_x) = (Vec2::new(0.15, 0.055), w / 2.0 - 0.27);
        let mut heads = Mesh::new();
        for side in [-1.0f32, 1.0] {
            let c = Vec3::new(side * head_x, head_y, -l / 2.0 - 0.003);
            heads.rect(c, Vec3::NEG_X * head_half.x, Vec3::Y * head_half.y);
            if let Some(hl) = lights.headlights {
                let color = hl.source.rgb();
                model.lights.push(Light {
                    name: format!("headlight_{}", side_name(side)),
                    kind: LightKind::Spot {
                        inner: 0.15,
                        outer: 0.4,
                    },
                    color,
                    intensity: hl.intensity / luminance(color),
                    position: c - Vec3::Z * 0.05,
                    direction: Vec3::new(0.0, -0.03, -1.0).normalize(),
                });
            }
        }
        match lights.headlights {
            Some(hl) => model.push(
                "headlamps",
                heads,
                Material::emitter(
                    "headlamp_lens",
                    hl.source.rgb_with_luminance(hl.lens_luminance),
                ),
                Class::LightSource,
            ),
            None => model.push(
                "headlamps",
                heads,
                Material::pbr("headlamp_glass", Pbr::new([0.05; 3], 0.0, 0.05)),
                class,
            ),
        }
        // Tail lights (outboard) and brake lights (inboard) on the rear face, facing +Z.
        let tail_y = match self.body {
            BodyType::Bus => 0.9,
            _ => sh.belt - 0.27,
        };
        let lens = Vec2::new(0.12, 0.045);
        let area = f64::from(4.0 * lens.x * lens.y);
        let tail_x = w / 2.0 - 0.2;
        let brake_x = tail_x - 2.0 * lens.x - 0.02;
        for (name, x, cd) in [
            ("tail_lights", tail_x, lights.tail_cd),
            ("brake_lights", brake_x, lights.brake_cd),
        ] {
            let mut m = Mesh::new();
            for side in [-1.0f32, 1.0] {
                let c = Vec3::new(side * x, tail_y, l / 2.0 + 0.003);
                m.rect(c, Vec3::X * lens.x, Vec3::Y * lens.y);
                if let Some(cd) = cd {
                    let color = led_rgb(RED_NM, 1.0);
                    model.lights.push(Light {
                        name: format!("{}_{}", &name[..name.len() - 1], side_name(side)),
                        kind: LightKind::Spot {
                            inner: 0.3,
                            outer: 0.9,
                        },
                        color: crate::light_sources::peak_one(color),
                        intensity: cd
                            / crate::gltf_writer::LUMENS_PER_WATT
                            / luminance(crate::light_sources::peak_one(color)),
                        position: c + Vec3::Z * 0.03,
                        direction: Vec3::new(0.0, -0.05, 1.0).normalize(),
                    });
                }
            }
            match cd {
                Some(cd) => model.push(
                    name,
                    m,
                    Material::emitter(
                        name,
                        led_rgb(RED_NM, cd / crate::gltf_writer::LUMENS_PER_WATT / area),
                    ),
                    Class::LightSource,
                ),
                None => model.push(
                    name,
                    m,
                    Material::pbr("rear_lens_off", Pbr::new([0.25, 0.01, 0.01], 0.0, 0.1)),
                    class,
                ),
            }
        }
        if self.body == BodyType::Bus {
            // The destination display above the windscreen, amber LEDs, lit when driving.
            let mut sign = Mesh::new();
            let y = self.height - 0.22;
            sign.rect(
                Vec3::new(0.0, y, -l / 2.0 - 0.01),
                Vec3::NEG_X * (w / 2.0 - 0.3),
                Vec3::Y * 0.12,
            );
            if lights.headlights.is_some() {
                model.push(
                    "destination",
                    sign,
                    Material::emitter("destination_display", led_rgb(AMBER_NM, 0.4)),
                    Class::LightSource,
                );
            } else {
                model.push(
                    "destination",
                    sign,
                    Material::pbr("display_off", Pbr::new([0.02; 3], 0.0, 0.2)),
                    class,
                );
            }
        }
    }
}

/// The body's derived shape, metres, with `s` the coordinate forward (`z = -s`).
#[derive(Clone, Copy, Debug)]
struct Shape {
    /// Height of the belt line (bottom of the side windows).
    belt: f32,
    /// Height of the bonnet's front edge.
    bonnet_front: f32,
    /// Windscreen base and top.
    s_ws: f32,
    s_wt: f32,
    /// Rear screen base and top.
    s_rb: f32,
    s_rt: f32,
    /// Ground clearance of the body.
    clearance: f32,
    /// Height of the wheel arches.
    arch_top: f32,
    /// Axles.
    axle_front: f32,
    axle_rear: f32,
    /// Tyre width.
    tyre_width: f32,
    /// How much narrower the roof is than the belt line, each side.
    tumblehome: f32,
}

fn side_name(side: f32) -> &'static str {
    if side < 0.0 {
        "left"
    } else {
        "right"
    }
}

/// The part of the convex polygon `poly` with coordinate `axis` (0: x, 1: y) above
/// (`keep_above`) or below `value` (Sutherland-Hodgman against one line).
pub(crate) fn clip(poly: &[Vec2], axis: usize, value: f32, keep_above: bool) -> Vec<Vec2> {
    let inside = |q: Vec2| (q[axis] >= value) == keep_above || q[axis] == value;
    let mut out = Vec::new();
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        if inside(a) {
            out.push(a);
        }
        if inside(a) != inside(b) {
            let t = (value - a[axis]) / (b[axis] - a[axis]);
            let mut q = a + (b - a) * t;
            q[axis] = value;
            out.push(q);
        }
    }
    out.dedup_by(|a, b| a.distance(*b) < 1e-5);
    if out.len() > 1 && out[0].distance(out[out.len() - 1]) < 1e-5 {
        out.pop();
    }
    out
}

/// The convex polygon `p` shrunk towards its centroid by about `margin`.
pub(crate) fn inset(p: &[Vec3], margin: f32) -> Vec<Vec3> {
    let c = p.iter().copied().sum::<Vec3>() / p.len() as f32;
    p.iter()
        .map(|&q| {
            let d = c - q;
            q + d.normalize_or_zero() * (1.4 * margin).min(0.5 * d.length())
        })
        .collect()
}

/// The normal of the planar polygon `p` pointing away from `inside`.
pub(crate) fn outward_normal(p: &[Vec3], inside: Vec3) -> Vec3 {
    let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
    if n.dot(p[0] - inside) >= 0.0 {
        n
    } else {
        -n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objects::checks::{assert_closed, assert_wound_with_normals, volume};
    use rand::SeedableRng;

    fn lighting() -> TrafficLighting {
        TrafficLighting {
            headlights: Headlights {
                source: LightSource::Halogen,
                intensity: 20.0,
                lens_luminance: 30.0,
            },
        }
    }

    /// Specs at both ends of every body type's ranges, lit and braking.
    fn extremes() -> Vec<VehicleSpec> {
        let mut v = Vec::new();
        for body in BodyType::ALL {
            let r = body.ranges();
            for k in 0..2 {
                v.push(VehicleSpec {
                    body,
                    length: r.length[k],
                    width: r.width[k],
                    height: r.height[k],
                    wheel_radius: r.wheel_radius[1 - k],
                    paint: Paint::Red.rgb(),
                    metallic: k == 0,
                    lights: VehicleLights {
                        headlights: Some(lighting().headlights),
                        tail_cd: Some(10.0),
                        brake_cd: Some(60.0),
                    },
                });
            }
        }
        v
    }

    /// Body, tyres and rims are closed solids facing outward; every part is wound with its
    /// normals; the vehicle stands on the ground and has the spec's size.
    #[test]
    fn vehicles_are_closed_on_the_ground_and_the_right_size() {
        for spec in extremes() {
            let m = spec.build();
            let what = |p: &str| format!("{:?} {}: {p}", spec.body, spec.length);
            for part in &m.parts {
                assert_wound_with_normals(&part.mesh, &what(&part.name));
                if ["body", "tyres", "rims"].contains(&part.name.as_str()) {
                    assert_closed(&part.mesh, &what(&part.name));
                    assert!(volume(&part.mesh) > 0.0, "{}", what(&part.name));
                }
            }
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for part in &m.parts {
                let (a, b) = part.mesh.bounds();
                lo = lo.min(a);
                hi = hi.max(b);
            }
            assert!(lo.y.abs() < 1e-3, "{}: min y {}", what("all"), lo.y);
            assert!(
                (hi.x - spec.width / 2.0).abs() < 1e-3 && (lo.x + spec.width / 2.0).abs() < 1e-3
            );
            let length = hi.z - lo.z;
            assert!(
                length >= spec.length && length < spec.length + 0.025,
                "{}: {length}",
                what("length")
            );
            assert!(
                hi.y >= spec.height - 1e-4 && hi.y < spec.height + 0.01,
                "{}: {}",
                what("height"),
                hi.y
            );
            // The wheels touch the ground.
            let tyres = m.parts.iter().find(|p| p.name == "tyres").unwrap();
            assert!(tyres.mesh.bounds().0.y.abs() < 1e-3);
        }
    }

    /// Drawn sizes lie within the documented ranges, and a draw is reproducible.
    #[test]
    fn draws_are_within_ranges_and_reproducible() {
        let config = ObjectsConfig::default();
        let mut seen = std::collections::BTreeSet::new();
        for seed in 0..200 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let a = VehicleSpec::draw(&mut rng, &config, Role::Leading, &lighting());
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let b = VehicleSpec::draw(&mut rng, &config, Role::Leading, &lighting());
            assert_eq!(a, b);
            let r = a.body.ranges();
            let inside = |x: f32, r: [f32; 2]| (r[0]..=r[1]).contains(&x);
            assert!(inside(a.length, r.length) && inside(a.width, r.width));
            assert!(inside(a.height, r.height) && inside(a.wheel_radius, r.wheel_radius));
            seen.insert(a.body);
        }
        assert_eq!(seen.len(), BodyType::ALL.len());
    }

    /// Headlights shine forward (-Z) from the front, tail and brake lights backwards from
    /// the back; their levels re-derive from the spec's candela.
    #[test]
    fn lights_point_where_the_car_faces() {
        for spec in extremes() {
            let m = spec.build();
            let names: Vec<&str> = m.lights.iter().map(|l| l.name.as_str()).collect();
            assert_eq!(m.lights.len(), 6, "{names:?}");
            for l in &m.lights {
                let LightKind::Spot { .. } = l.kind else {
                    panic!("{} is not a spot", l.name);
                };
                let y = l.intensity * luminance(l.color);
                if l.name.starts_with("headlight") {
                    assert!(l.direction.z < -0.99 && l.position.z < -spec.length / 2.0);
                    assert!((y - 20.0).abs() < 1e-6, "{y}");
                } else {
                    assert!(l.direction.z > 0.99 && l.position.z > spec.length / 2.0);
                    let cd = if l.name.starts_with("tail") {
                        10.0
                    } else {
                        60.0
                    };
                    assert!((y * crate::gltf_writer::LUMENS_PER_WATT - cd).abs() < 1e-6);
                }
            }
            // Lenses: the emitters face their way, and a tail lens of area A at luminance
            // L has the tail light's intensity L A.
            for part in m.parts.iter().filter(|p| p.class == Class::LightSource) {
                let n = part.mesh.normals[0];
                let e = part.material.emission.expect("a lit lens emits");
                match part.name.as_str() {
                    "headlamps" | "destination" => assert!(n.z < -0.99),
                    "tail_lights" | "brake_lights" => {
                        assert!(n.z > 0.99);
                        let area: f32 = part
                            .mesh
                            .indices
                            .chunks(3)
                            .map(|t| {
                                let [a, b, c] =
                                    [0, 1, 2].map(|k| part.mesh.positions[t[k] as usize]);
                                0.5 * (b - a).cross(c - a).length()
                            })
                            .sum();
                        let cd = luminance(e)
                            * f64::from(area / 2.0)
                            * crate::gltf_writer::LUMENS_PER_WATT;
                        let want = if part.name == "tail_lights" {
                            10.0
                        } else {
                            60.0
                        };
                        assert!((cd - want).abs() < 1e-3 * want, "{}: {cd}", part.name);
                    }
                    other => panic!("unexpected emitter {other}"),
                }
            }
        }
    }

    /// A parked vehicle has no lights and no emitters; an oncoming one has headlights and
    /// tail lights but no brake lights.
    #[test]
    fn roles_set_the_lights() {
        let config = ObjectsConfig::default();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let parked = VehicleSpec::draw(&mut rng, &config, Role::Parked, &lighting()).build();
        assert!(parked.lights.is_empty());
        assert!(parked.parts.iter().all(|p| p.material.emission.is_none()));
        assert!(parked.parts.iter().all(|p| p.class != Class::LightSource));
        let oncoming = VehicleSpec::draw(&mut rng, &config, Role::Oncoming, &lighting());
        assert!(oncoming.lights.brake_cd.is_none() && oncoming.lights.tail_cd.is_some());
        assert_eq!(oncoming.build().lights.len(), 4);
        let braking = (0..200)
            .filter(|_| {
                VehicleSpec::draw(&mut rng, &config, Role::Leading, &lighting())
                    .lights
                    .brake_cd
                    .is_some()
            })
            .count();
        assert!((35..90).contains(&braking), "{braking} of 200 braking");
    }
}
