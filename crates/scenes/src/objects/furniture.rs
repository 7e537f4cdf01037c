//! Street furniture as [`Model`]s: street lamps of three designs, utility poles, trees,
//! signs on posts, traffic lights, bus stops, bollards and lit shop signs. Each has a spec
//! drawn by its `draw` and built by its `build`; frames as in [`crate::objects`] (the foot
//! of the post at the origin, what is shown to traffic facing -Z).

use super::{led_rgb, uniform, weighted, ObjectsConfig, AMBER_NM, GREEN_NM, RED_NM};
use crate::gltf_writer::{Light, LightKind, Material, Pbr, Transmission, Volume};
use crate::light_sources::{luminance, peak_one, LightSource};
use crate::mesh::Mesh;
use crate::model::{transformed, Model};
use crate::street::Signal;
use glam::{Affine3A, Vec2, Vec3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use streaks_render::class::Class;

/// Painted steel (lamp posts, traffic light poles, sign posts).
fn painted_metal(name: &str, grey: f64) -> Material {
    Material::pbr(name, Pbr::new([grey; 3], 0.0, 0.45))
}

/// Galvanised steel.
fn galvanised() -> Material {
    Material::pbr("galvanised_steel", Pbr::new([0.55, 0.56, 0.57], 1.0, 0.45))
}

/// A street lamp design.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LampDesign {
    /// A post with one arm reaching over the road and a flat luminaire (the common road
    /// light).
    Cobra,
    /// A lantern on top of a shorter post (town centres, residential streets).
    PostTop,
    /// A post with two arms, one luminaire each way (central reservations).
    TwinArm,
}

/// A street lamp's light, in the generator's units (as [`crate::street::StreetStyle`] has
/// them for the street's lamps).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LampLight {
    /// Colour, max component 1.
    pub color: [f64; 3],
    /// Radiant intensity, W/sr, times `color` (the luminous intensity is
    /// `intensity * luminance(color)` W/sr of luminance).
    pub intensity: f64,
    /// `None`: a point light; `Some((inner, outer))`: a spot light straight down with these
    /// cone angles (radians).
    pub cone: Option<(f64, f64)>,
    /// Radiance of the lit lens, W/(m^2 sr).
    pub lens_radiance: [f64; 3],
}

impl From<&crate::street::StreetStyle> for LampLight {
    /// The light of a street's lamps as the street draws it (`lamp_color`,
    /// `lamp_intensity`, `lamp_cone`, `lens_radiance`).
    fn from(st: &crate::street::StreetStyle) -> Self {
        Self {
            color: st.lamp_color,
            intensity: st.lamp_intensity,
            cone: st.lamp_cone,
            lens_radiance: st.lens_radiance,
        }
    }
}

/// A street lamp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StreetLampSpec {
    /// The design.
    pub design: LampDesign,
    /// Height of the light above the foot of the post, metres.
    pub height: f32,
    /// Reach of the arm from the post (cobra, twin arm), metres.
    pub outreach: f32,
    /// Half size of the lens (along the arm, across it), metres.
    pub lens_half: (f32, f32),
    /// The light, `None` when the lamp is off.
    pub light: Option<LampLight>,
}

impl StreetLampSpec {
    /// Draws a lamp of the street's `height`, lens half size `lens` (across; along is half)
    /// and `light`: the design from `config.lamp_designs`, the outreach 0.6-2.0 m.
    pub fn draw(
        rng: &mut ChaCha8Rng,
        config: &ObjectsConfig,
        height: f32,
        lens: f32,
        light: Option<LampLight>,
    ) -> Self {
        let design = weighted(rng, &config.lamp_designs);
        let outreach = rng.random_range(0.6f32..=2.0);
        let height = match design {
            // Lanterns stand lower than road lights.
            LampDesign::PostTop => height.min(rng.random_range(3.5f32..=5.0)),
            _ => height,
        };
        Self {
            design,
            height,
            outreach,
            lens_half: (0.5 * lens, lens),
            light,
        }
    }

    /// Builds the lamp: post and arms `Pole`, luminaire housing `StreetFurniture`, the lit
    /// lens `LightSource`, and one light per luminaire.
    pub fn build(&self) -> Model {
        let mut model = Model::new();
        let h = self.height;
        let mut post = Mesh::new();
        let mut housing = Mesh::new();
        let mut lens = Mesh::new();
        let mut lights = Vec::new();
        match self.design {
            LampDesign::PostTop => {
                post.cylinder_between(Vec3::ZERO, Vec3::Y * (h - 0.3), 0.07, 12);
                post.cylinder_between(Vec3::ZERO, Vec3::Y * 0.8, 0.12, 12);
                // The lantern: a glowing band (the lens) under a roof.
                lens.cylinder_between(Vec3::Y * (h - 0.3), Vec3::Y * (h + 0.1), 0.2, 12);
                housing.cylinder_between(Vec3::Y * (h + 0.1), Vec3::Y * (h + 0.18), 0.28, 12);
                housing.cylinder_between(Vec3::Y * (h + 0.18), Vec3::Y * (h + 0.3), 0.06, 8);
                lights.push(Vec3::Y * h);
            }
            LampDesign::Cobra | LampDesign::TwinArm => {
                let top = h + 0.4;
                post.cylinder_between(Vec3::ZERO, Vec3::Y * top, 0.08, 12);
                let arms: &[f32] = if self.design == LampDesign::TwinArm {
                    &[-1.0, 1.0]
                } else {
                    &[-1.0]
                };
                for &dir in arms {
                    let end = Vec3::new(0.0, h + 0.2, dir * self.outreach);
                    post.cylinder_between(Vec3::Y * (top - 0.15), end, 0.035, 8);
                    // A flat luminaire around the lens, 5 cm wider on each side.
                    let (lz, lx) = (self.lens_half.0 + 0.05, self.lens_half.1 + 0.05);
                    let c = Vec3::new(0.0, h, dir * (self.outreach + lz - 0.1));
                    let profile = [
                        Vec2::new(c.z - lz, h + 0.002),
                        Vec2::new(c.z + lz, h + 0.002),
                        Vec2::new(c.z + 0.8 * lz, h + 0.2),
                        Vec2::new(c.z - 0.8 * lz, h + 0.2),
                    ];
                    housing.prism(&profile, |y| lx - 0.3 * (y - h));
                    // rect(c, X, Z) faces X x Z = -Y: down.
                    lens.rect(c, Vec3::X * self.lens_half.1, Vec3::Z * self.lens_half.0);
                    lights.push(c - Vec3::Y * 0.05);
                }
            }
        }
        model.push("post", post, painted_metal("lamp_post", 0.08), Class::Pole);
        model.push(
            "housing",
            housing,
            painted_metal("luminaire", 0.12),
            Class::StreetFurniture,
        );
        match self.light {
            Some(l) => {
                model.push(
                    "lens",
                    lens,
                    Material::emitter("lamp_lens", l.lens_radiance),
                    Class::LightSource,
                );
                for (k, &p) in lights.iter().enumerate() {
                    model.lights.push(Light {
                        name: format!("lamp_{k}"),
                        kind: match l.cone {
                            Some((inner, outer)) if self.design != LampDesign::PostTop => {
                                LightKind::Spot { inner, outer }
                            }
                            _ => LightKind::Point,
                        },
                        color: l.color,
                        intensity: l.intensity,
                        position: p,
                        direction: Vec3::NEG_Y,
                    });
                }
            }
            None => model.push(
                "lens",
                lens,
                Material::pbr("lamp_lens_off", Pbr::new([0.3; 3], 0.0, 0.1)),
                Class::StreetFurniture,
            ),
        }
        model
    }
}

/// A wooden telephone or utility pole with a cross-arm and insulators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UtilityPoleSpec {
    /// Height above ground, metres (7-11).
    pub height: f32,
    /// Radius at the foot, metres.
    pub radius: f32,
    /// Length of the cross-arm, metres.
    pub crossarm: f32,
}

impl UtilityPoleSpec {
    /// Draws a pole.
    pub fn draw(rng: &mut ChaCha8Rng) -> Self {
        Self {
            height: rng.random_range(7.0..=11.0),
            radius: rng.random_range(0.11..=0.16),
            crossarm: rng.random_range(1.4..=2.2),
        }
    }

    /// Builds it, all `Pole`.
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let h = self.height;
        let mut wood = Mesh::new();
        wood.cylinder_between(Vec3::ZERO, Vec3::Y * h, self.radius, 12);
        let arm_y = h - 0.6;
        wood.cuboid(
            Vec3::new(-self.crossarm / 2.0, arm_y - 0.05, -0.12 - self.radius),
            Vec3::new(self.crossarm / 2.0, arm_y + 0.05, -self.radius),
        );
        m.push(
            "pole",
            wood,
            Material::pbr("pole_wood", Pbr::new([0.12, 0.085, 0.055], 0.0, 0.8)),
            Class::Pole,
        );
        let mut ins = Mesh::new();
        for x in [-0.42, 0.0, 0.42] {
            let x = x * self.crossarm;
            let base = Vec3::new(x, arm_y + 0.05, -0.06 - self.radius);
            ins.cylinder_between(base, base + Vec3::Y * 0.14, 0.035, 8);
        }
        m.push(
            "insulators",
            ins,
            Material::pbr("porcelain", Pbr::new([0.7, 0.7, 0.68], 0.0, 0.15)),
            Class::Pole,
        );
        m
    }
}

/// A street tree: a trunk and a crown of overlapping ellipsoids.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeSpec {
    /// Height of the trunk to the crown's base, metres.
    pub trunk_height: f32,
    /// Trunk radius, metres.
    pub trunk_radius: f32,
    /// The crown's clusters: centre and semi-axes, metres.
    pub clusters: Vec<(Vec3, Vec3)>,
    /// Leaf colour (linear RGB).
    pub leaves: [f64; 3],
}

impl TreeSpec {
    /// Draws a tree of 4-7 m with 4-7 clusters.
    pub fn draw(rng: &mut ChaCha8Rng) -> Self {
        let trunk_height = rng.random_range(1.8f32..=3.0);
        let crown = rng.random_range(1.4f32..=2.6);
        let n = rng.random_range(4..=7);
        let clusters = (0..n)
            .map(|k| {
                let a = std::f32::consts::TAU * (k as f32 + rng.random_range(0.0..0.6)) / n as f32;
                let r = if k == 0 { 0.0 } else { 0.55 * crown };
                let radii = Vec3::new(
                    rng.random_range(0.55..=0.8) * crown,
                    rng.random_range(0.45..=0.7) * crown,
                    rng.random_range(0.55..=0.8) * crown,
                );
                let y = trunk_height + radii.y + rng.random_range(0.0..=0.6) * crown;
                (Vec3::new(r * a.cos(), y, r * a.sin()), radii)
            })
            .collect();
        let g = rng.random_range(0.8..=1.2);
        Self {
            trunk_height,
            trunk_radius: rng.random_range(0.1..=0.2),
            clusters,
            leaves: [0.04 * g, 0.09 * g, 0.025 * g],
        }
    }

    /// Builds it, all `Vegetation`: about 100 triangles per cluster.
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let mut trunk = Mesh::new();
        let top = self
            .clusters
            .iter()
            .map(|c| c.0.y)
            .fold(self.trunk_height, f32::max);
        trunk.cylinder_between(Vec3::ZERO, Vec3::Y * top, self.trunk_radius, 10);
        m.push(
            "trunk",
            trunk,
            Material::pbr("bark", Pbr::new([0.07, 0.05, 0.035], 0.0, 0.9)),
            Class::Vegetation,
        );
        let mut crown = Mesh::new();
        for &(c, r) in &self.clusters {
            crown.ellipsoid(c, r, 6, 10);
        }
        m.push(
            "crown",
            crown,
            Material::pbr("leaves", Pbr::new(self.leaves, 0.0, 0.7)),
            Class::Vegetation,
        );
        m
    }
}

/// What a road sign says, which fixes its shape and colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SignKind {
    /// A white disc with a red ring.
    Prohibitory,
    /// A blue disc with a white border.
    Mandatory,
    /// A white triangle with a red border.
    Warning,
    /// A blue rectangle with a white border.
    Information,
    /// A red octagon with a white border.
    Stop,
}

/// A road sign on a post.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignSpec {
    /// What it says.
    pub kind: SignKind,
    /// Half size of the plate (radius of a disc), metres.
    pub half: f32,
    /// Height of the plate's centre, metres.
    pub height: f32,
}

impl SignSpec {
    /// Draws a sign: any kind, 0.3-0.45 m half size, centre 2.0-2.6 m up.
    pub fn draw(rng: &mut ChaCha8Rng) -> Self {
        const KINDS: [SignKind; 5] = [
            SignKind::Prohibitory,
            SignKind::Mandatory,
            SignKind::Warning,
            SignKind::Information,
            SignKind::Stop,
        ];
        Self {
            kind: KINDS[rng.random_range(0..KINDS.len())],
            half: rng.random_range(0.3..=0.45),
            height: rng.random_range(2.0..=2.6),
        }
    }

    /// The plate's outline in its plane (x right, y up, about its centre) and the border
    /// and face colours.
    fn outline(&self) -> (Vec<Vec2>, [f64; 3], [f64; 3]) {
        let white = [0.75, 0.75, 0.73];
        let red = [0.55, 0.03, 0.03];
        let blue = [0.02, 0.08, 0.4];
        let poly = |n: u32, phase: f32, r: f32| {
            (0..n)
                .map(|k| {
                    let a = phase + std::f32::consts::TAU * k as f32 / n as f32;
                    Vec2::new(r * a.cos(), r * a.sin())
                })
                .collect::<Vec<_>>()
        };
        let h = self.half;
        match self.kind {
            SignKind::Prohibitory => (poly(24, 0.0, h), red, white),
            SignKind::Mandatory => (poly(24, 0.0, h), white, blue),
            SignKind::Warning => (poly(3, std::f32::consts::FRAC_PI_2, h * 1.15), red, white),
            SignKind::Information => (
                vec![
                    Vec2::new(-h, -0.75 * h),
                    Vec2::new(h, -0.75 * h),
                    Vec2::new(h, 0.75 * h),
                    Vec2::new(-h, 0.75 * h),
                ],
                white,
                blue,
            ),
            SignKind::Stop => (poly(8, std::f32::consts::PI / 8.0, h), white, red),
        }
    }

    /// Builds it: the plate (`TrafficSign`, a thin closed slab with its face 1 mm in front)
    /// and the post (`Pole`).
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let (outline, border, face) = self.outline();
        let (post_r, t) = (0.035, 0.01);
        let z_back = -post_r - 0.01;
        let mut post = Mesh::new();
        post.cylinder_between(Vec3::ZERO, Vec3::Y * (self.height + self.half), post_r, 10);
        m.push("post", post, galvanised(), Class::Pole);
        let plate = plate(&outline, self.height, z_back - t, z_back);
        m.push(
            "plate",
            plate,
            Material::pbr("sign_border", Pbr::new(border, 0.0, 0.35)),
            Class::TrafficSign,
        );
        let inner: Vec<Vec3> = super::vehicle::inset(
            &outline
                .iter()
                .map(|q| Vec3::new(q.x, self.height + q.y, z_back - t - 0.001))
                .collect::<Vec<_>>(),
            0.12 * self.half,
        );
        let mut f = Mesh::new();
        f.polygon(&inner, Vec3::NEG_Z);
        m.push(
            "face",
            f,
            Material::pbr("sign_face", Pbr::new(face, 0.0, 0.35)),
            Class::TrafficSign,
        );
        m
    }
}

/// A closed slab with the convex `outline` (x, y about `(0, centre_y)`) between `z0` and
/// `z1`.
fn plate(outline: &[Vec2], centre_y: f32, z0: f32, z1: f32) -> Mesh {
    // A prism extrudes its (z, y) profile across X; turning it by a quarter about Y maps
    // its X onto Z.
    let profile: Vec<Vec2> = outline
        .iter()
        .map(|q| Vec2::new(q.x, centre_y + q.y))
        .collect();
    let mut m = Mesh::new();
    let half = 0.5 * (z1 - z0);
    m.prism(&profile, |_| half);
    // (x, y, z) -> (z, y, -x), then move to the slab's middle.
    let turn = Affine3A::from_translation(Vec3::Z * 0.5 * (z0 + z1))
        * Affine3A::from_rotation_y(std::f32::consts::FRAC_PI_2);
    transformed(&m, turn)
}

/// A traffic light on a pole: a head of three 200 mm lenses facing -Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrafficLightSpec {
    /// Height of the head's bottom, metres.
    pub height: f32,
    /// Which lens is lit.
    pub signal: Signal,
    /// Luminous intensity of the lit signal on its axis, W/sr of luminance (the generator's
    /// `traffic.signal_intensity`); `None`: dark.
    pub intensity: Option<f64>,
}

/// Radius of a signal lens, metres (200 mm signals).
pub const SIGNAL_LENS_RADIUS: f32 = 0.1;

impl TrafficLightSpec {
    /// Draws a traffic light with `intensity` (from the street's traffic config).
    pub fn draw(rng: &mut ChaCha8Rng, intensity: f64) -> Self {
        Self {
            height: rng.random_range(2.4..=3.0),
            signal: [Signal::Red, Signal::Amber, Signal::Green][rng.random_range(0..3)],
            intensity: Some(intensity),
        }
    }

    /// Builds it: pole `Pole`, head and dark lenses `TrafficLight`, the lit lens
    /// `LightSource` with a spot light forward and slightly down.
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let (hw, hh, depth) = (0.17, 0.9, 0.25);
        let y0 = self.height;
        let mut pole = Mesh::new();
        pole.cylinder_between(Vec3::ZERO, Vec3::Y * (y0 + 0.2), 0.07, 12);
        m.push("pole", pole, painted_metal("signal_pole", 0.1), Class::Pole);
        let mut head = Mesh::new();
        let front = -0.06 - depth;
        head.cuboid(Vec3::new(-hw, y0, front), Vec3::new(hw, y0 + hh, -0.06));
        let r = SIGNAL_LENS_RADIUS;
        let rows = [
            (Signal::Red, y0 + hh - 0.15, RED_NM),
            (Signal::Amber, y0 + hh / 2.0, AMBER_NM),
            (Signal::Green, y0 + 0.15, GREEN_NM),
        ];
        for &(_, y, _) in &rows {
            // Visors over each lens.
            head.cuboid(
                Vec3::new(-r - 0.02, y + r, front - 0.18),
                Vec3::new(r + 0.02, y + r + 0.01, front),
            );
        }
        m.push(
            "head",
            head,
            painted_metal("signal_head", 0.02),
            Class::TrafficLight,
        );
        let area = f64::from(std::f32::consts::PI * r * r);
        for (signal, y, nm) in rows {
            let mut lens = Mesh::new();
            let c = Vec3::new(0.0, y, front - 0.002);
            lens.disc(c, Vec3::NEG_Z, r, 16);
            let name = format!("lens_{}", signal_name(signal));
            match self.intensity.filter(|_| signal == self.signal) {
                Some(i) => {
                    m.push(
                        &name,
                        lens,
                        Material::emitter(&name, led_rgb(nm, i / area)),
                        Class::LightSource,
                    );
                    let color = peak_one(led_rgb(nm, 1.0));
                    m.lights.push(Light {
                        name: format!("signal_{}", signal_name(signal)),
                        kind: LightKind::Spot {
                            inner: 0.3,
                            outer: 0.7,
                        },
                        color,
                        intensity: i / luminance(color),
                        position: c - Vec3::Z * 0.05,
                        direction: Vec3::new(0.0, -0.1, -1.0).normalize(),
                    });
                }
                None => {
                    let dark = led_rgb(nm, 1.0).map(|c| (0.08 * c).min(0.3));
                    m.push(
                        &name,
                        lens,
                        Material::pbr(&format!("{name}_off"), Pbr::new(dark, 0.0, 0.1)),
                        Class::TrafficLight,
                    );
                }
            }
        }
        m
    }
}

fn signal_name(s: Signal) -> &'static str {
    match s {
        Signal::Red => "red",
        Signal::Amber => "amber",
        Signal::Green => "green",
    }
}

/// A bus shelter: posts, a roof, glass panels at the back and one end, a bench, and a lit
/// advert panel at the other end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BusStopSpec {
    /// Length along the kerb (X), metres.
    pub length: f32,
    /// Depth (Z), metres.
    pub depth: f32,
    /// Height of the roof, metres.
    pub height: f32,
    /// Luminance of the lit advert, cd/m^2 (`None`: unlit).
    pub advert_cd_m2: Option<f64>,
}

impl BusStopSpec {
    /// Draws a shelter with its advert lit at a shop sign's luminance.
    pub fn draw(rng: &mut ChaCha8Rng, config: &ObjectsConfig) -> Self {
        Self {
            length: rng.random_range(3.0..=5.0),
            depth: rng.random_range(1.2..=1.6),
            height: rng.random_range(2.3..=2.6),
            advert_cd_m2: Some(uniform(rng, config.shop_sign_luminance)),
        }
    }

    /// Builds it: frame, roof, bench and glass `StreetFurniture`, the lit advert
    /// `LightSource`. The open side faces -Z.
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let (hl, hd, h) = (self.length / 2.0, self.depth / 2.0, self.height);
        let mut frame = Mesh::new();
        for x in [-hl + 0.05, hl - 0.05] {
            for z in [-hd + 0.05, hd - 0.05] {
                frame.cuboid(
                    Vec3::new(x - 0.04, 0.0, z - 0.04),
                    Vec3::new(x + 0.04, h, z + 0.04),
                );
            }
        }
        frame.cuboid(
            Vec3::new(-hl - 0.1, h, -hd - 0.15),
            Vec3::new(hl + 0.1, h + 0.12, hd + 0.05),
        );
        // The bench along the back.
        frame.cuboid(
            Vec3::new(-hl + 0.4, 0.42, hd - 0.45),
            Vec3::new(hl - 0.9, 0.47, hd - 0.1),
        );
        frame.cuboid(
            Vec3::new(-0.05, 0.0, hd - 0.3),
            Vec3::new(0.05, 0.42, hd - 0.2),
        );
        m.push(
            "frame",
            frame,
            painted_metal("shelter_frame", 0.06),
            Class::StreetFurniture,
        );
        // 10 mm toughened glass as closed slabs (glass with a volume).
        let mut glass = Mesh::new();
        glass.cuboid(
            Vec3::new(-hl + 0.09, 0.1, hd - 0.055),
            Vec3::new(hl - 0.09, h - 0.05, hd - 0.045),
        );
        glass.cuboid(
            Vec3::new(-hl + 0.045, 0.1, -hd + 0.3),
            Vec3::new(-hl + 0.055, h - 0.05, hd - 0.09),
        );
        let toughened = Pbr {
            transmission: Some(Transmission {
                factor: 1.0,
                ior: 1.52,
                volume: Some(Volume {
                    thickness: 0.01,
                    attenuation_color: [0.85, 0.93, 0.9],
                    attenuation_distance: 0.1,
                }),
            }),
            ..Pbr::new([1.0; 3], 0.0, 0.02)
        };
        m.push(
            "glass",
            glass,
            Material::pbr("shelter_glass", toughened),
            Class::StreetFurniture,
        );
        // The advert: a box at the +X end, lit on both faces (facing -X and +X).
        let (x, t) = (hl - 0.05, 0.06);
        let mut cabinet = Mesh::new();
        cabinet.cuboid(
            Vec3::new(x - t, 0.2, -hd + 0.3),
            Vec3::new(x + t, 2.0, hd - 0.09),
        );
        m.push(
            "advert_cabinet",
            cabinet,
            painted_metal("advert_cabinet", 0.06),
            Class::StreetFurniture,
        );
        let mut faces = Mesh::new();
        let (zc, zh) = (
            0.5 * (0.3 - hd + hd - 0.09) - 0.0,
            0.5 * (self.depth - 0.39) - 0.05,
        );
        for side in [-1.0f32, 1.0] {
            // rect(c, u, v) faces u x v = -side Z x Y = side X.
            faces.rect(
                Vec3::new(x + side * (t + 0.002), 1.1, zc),
                Vec3::Z * -side * zh,
                Vec3::Y * 0.8,
            );
        }
        match self.advert_cd_m2 {
            Some(cd) => m.push(
                "advert",
                faces,
                Material::emitter(
                    "advert",
                    LightSource::Led4000K
                        .rgb_with_luminance(cd / crate::gltf_writer::LUMENS_PER_WATT)
                        .map(crate::gltf_writer::round7),
                ),
                Class::LightSource,
            ),
            None => m.push(
                "advert",
                faces,
                Material::pbr("advert_unlit", Pbr::new([0.3, 0.3, 0.32], 0.0, 0.2)),
                Class::StreetFurniture,
            ),
        }
        m
    }
}

/// A bollard: a post with a domed cap and a reflective band.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BollardSpec {
    /// Height of the shaft, metres.
    pub height: f32,
    /// Radius, metres.
    pub radius: f32,
    /// Steel (true) or painted black.
    pub steel: bool,
}

impl BollardSpec {
    /// Draws a bollard of 0.8-1.0 m.
    pub fn draw(rng: &mut ChaCha8Rng) -> Self {
        Self {
            height: rng.random_range(0.8..=1.0),
            radius: rng.random_range(0.05..=0.1),
            steel: rng.random_bool(0.5),
        }
    }

    /// Builds it, all `Pole`.
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let mut shaft = Mesh::new();
        shaft.cylinder_between(Vec3::ZERO, Vec3::Y * self.height, self.radius, 12);
        shaft.ellipsoid(
            Vec3::Y * self.height,
            Vec3::new(self.radius, 0.6 * self.radius, self.radius),
            4,
            12,
        );
        let material = if self.steel {
            Material::pbr("bollard_steel", Pbr::new([0.6, 0.6, 0.62], 1.0, 0.35))
        } else {
            painted_metal("bollard_black", 0.02)
        };
        m.push("shaft", shaft, material, Class::Pole);
        let mut band = Mesh::new();
        let y = self.height - 0.15;
        band.cylinder_between(Vec3::Y * y, Vec3::Y * (y + 0.06), self.radius + 0.003, 12);
        m.push(
            "band",
            band,
            Material::pbr("reflective_band", Pbr::new([0.7, 0.7, 0.7], 0.0, 0.25)),
            Class::Pole,
        );
        m
    }
}

/// A lit shop sign on a wall: a box whose front is lit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShopSignSpec {
    /// Width, metres.
    pub width: f32,
    /// Height of the sign, metres.
    pub sign_height: f32,
    /// Height of its bottom above the ground, metres.
    pub mount: f32,
    /// Luminance of the lit face, cd/m^2 (`None`: off).
    pub luminance: Option<f64>,
    /// The light's colour (max component 1).
    pub color: [f64; 3],
}

impl ShopSignSpec {
    /// Draws a sign 1.5-5 m wide at 2.6-3.4 m, in a white, warm or coloured light.
    pub fn draw(rng: &mut ChaCha8Rng, config: &ObjectsConfig) -> Self {
        let color = match rng.random_range(0..5) {
            0 => LightSource::Led4000K.rgb(),
            1 => LightSource::Led3000K.rgb(),
            2 => peak_one(led_rgb(RED_NM, 1.0)),
            3 => peak_one(led_rgb(AMBER_NM, 1.0)),
            _ => peak_one(led_rgb(GREEN_NM, 1.0)),
        };
        Self {
            width: rng.random_range(1.5..=5.0),
            sign_height: rng.random_range(0.4..=0.8),
            mount: rng.random_range(2.6..=3.4),
            luminance: Some(uniform(rng, config.shop_sign_luminance)),
            color: color.map(crate::gltf_writer::round7),
        }
    }

    /// Builds it: the box `Building` (part of the shop front), its back on the wall `z = 0`,
    /// the lit face `LightSource` facing -Z. The origin is the foot of the wall under it.
    pub fn build(&self) -> Model {
        let mut m = Model::new();
        let (hw, y0, y1, d) = (
            self.width / 2.0,
            self.mount,
            self.mount + self.sign_height,
            0.15,
        );
        let mut case = Mesh::new();
        case.cuboid(Vec3::new(-hw, y0, -d), Vec3::new(hw, y1, 0.0));
        m.push(
            "case",
            case,
            painted_metal("sign_case", 0.05),
            Class::Building,
        );
        let mut face = Mesh::new();
        let c = Vec3::new(0.0, 0.5 * (y0 + y1), -d - 0.002);
        face.rect(
            c,
            Vec3::NEG_X * (hw - 0.05),
            Vec3::Y * (0.5 * self.sign_height - 0.05),
        );
        match self.luminance {
            Some(cd) => {
                let y = cd / crate::gltf_writer::LUMENS_PER_WATT / luminance(self.color);
                m.push(
                    "face",
                    face,
                    Material::emitter(
                        "shop_sign",
                        self.color.map(|c| crate::gltf_writer::round7(c * y)),
                    ),
                    Class::LightSource,
                );
            }
            None => m.push(
                "face",
                face,
                Material::pbr(
                    "shop_sign_off",
                    Pbr::new(self.color.map(|c| 0.5 * c), 0.0, 0.3),
                ),
                Class::Building,
            ),
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objects::checks::{assert_closed, assert_wound_with_normals, volume};
    use rand::SeedableRng;

    fn lamp_light() -> LampLight {
        LampLight {
            color: [1.0, 0.8, 0.5],
            intensity: 3.0,
            cone: Some((1.0, 1.4)),
            lens_radiance: [40.0, 30.0, 20.0],
        }
    }

    /// One of each piece (every lamp design), from seeded draws.
    fn pieces(seed: u64) -> Vec<(String, Model)> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let config = ObjectsConfig::default();
        let mut v = Vec::new();
        for design in [LampDesign::Cobra, LampDesign::PostTop, LampDesign::TwinArm] {
            let mut spec = StreetLampSpec::draw(&mut rng, &config, 7.0, 0.2, Some(lamp_light()));
            spec.design = design;
            v.push((format!("{design:?}"), spec.build()));
        }
        v.push(("pole".into(), UtilityPoleSpec::draw(&mut rng).build()));
        v.push(("tree".into(), TreeSpec::draw(&mut rng).build()));
        v.push(("sign".into(), SignSpec::draw(&mut rng).build()));
        v.push((
            "traffic_light".into(),
            TrafficLightSpec::draw(&mut rng, 0.5).build(),
        ));
        v.push((
            "bus_stop".into(),
            BusStopSpec::draw(&mut rng, &config).build(),
        ));
        v.push(("bollard".into(), BollardSpec::draw(&mut rng).build()));
        v
    }

    /// Posts, housings, plates, heads, trunks, crowns, frames and glass slabs are closed and
    /// face outward; each piece stands on the ground.
    #[test]
    fn furniture_is_closed_and_on_the_ground() {
        for seed in 0..4 {
            for (name, m) in pieces(seed) {
                let mut lo = f32::INFINITY;
                for p in &m.parts {
                    let what = format!("{name}/{}", p.name);
                    assert_wound_with_normals(&p.mesh, &what);
                    let one_sided = ["lens_red", "lens_amber", "lens_green", "face", "advert"];
                    let lamp_lens = p.name == "lens" && name != "PostTop";
                    if !one_sided.contains(&p.name.as_str()) && !lamp_lens {
                        assert_closed(&p.mesh, &what);
                        assert!(volume(&p.mesh) > 0.0, "{what}");
                    }
                    lo = lo.min(p.mesh.bounds().0.y);
                }
                assert!(lo.abs() < 1e-4, "{name}: min y {lo}");
            }
        }
    }

    /// Classes: posts are poles, the tree is vegetation, the lit parts are light sources.
    #[test]
    fn furniture_classes() {
        for (name, m) in pieces(1) {
            let classes: Vec<Class> = m.parts.iter().map(|p| p.class).collect();
            let want: &[Class] = match name.as_str() {
                "tree" => &[Class::Vegetation],
                "pole" | "bollard" => &[Class::Pole],
                "sign" => &[Class::Pole, Class::TrafficSign],
                "traffic_light" => &[Class::Pole, Class::TrafficLight, Class::LightSource],
                "bus_stop" => &[Class::StreetFurniture, Class::LightSource],
                _ => &[Class::Pole, Class::StreetFurniture, Class::LightSource],
            };
            for c in &classes {
                assert!(want.contains(c), "{name}: {c:?}");
            }
            for p in &m.parts {
                assert_eq!(
                    p.material.emission.is_some(),
                    p.class == Class::LightSource,
                    "{name}/{}",
                    p.name
                );
            }
        }
    }

    /// The traffic light's lit lens faces -Z, casts its spot forward and down, and its
    /// intensity re-derives from the spec: spot `I`, lens luminance `I / area`.
    #[test]
    fn traffic_light_signal_levels() {
        for signal in [Signal::Red, Signal::Amber, Signal::Green] {
            let spec = TrafficLightSpec {
                height: 2.6,
                signal,
                intensity: Some(0.5),
            };
            let m = spec.build();
            assert_eq!(m.lights.len(), 1);
            let l = &m.lights[0];
            assert!(l.direction.z < -0.9 && l.direction.y < 0.0);
            assert!((l.intensity * luminance(l.color) - 0.5).abs() < 1e-6);
            let lit: Vec<_> = m
                .parts
                .iter()
                .filter(|p| p.class == Class::LightSource)
                .collect();
            assert_eq!(lit.len(), 1);
            assert!(lit[0].mesh.normals.iter().all(|n| n.z < -0.999));
            let r = f64::from(SIGNAL_LENS_RADIUS);
            // A 16-gon of circumradius r has area 8 r^2 sin(pi / 8).
            let area = 8.0 * r * r * (std::f64::consts::PI / 8.0).sin();
            let i = luminance(lit[0].material.emission.unwrap()) * area;
            let disc = std::f64::consts::PI * r * r;
            assert!((i - 0.5 * area / disc).abs() < 1e-4, "{i}");
        }
    }

    /// A lamp's lights hang under its lenses, which face down; the cobra reaches forward.
    #[test]
    fn lamps_light_down_from_their_lenses() {
        for (name, m) in pieces(2).into_iter().take(3) {
            assert!(!m.lights.is_empty(), "{name}");
            for l in &m.lights {
                assert_eq!(l.direction, Vec3::NEG_Y);
                assert!(
                    (l.position.y - 7.0).abs() < 0.1 || name == "PostTop",
                    "{name}"
                );
            }
            if name == "Cobra" {
                assert!(m.lights[0].position.z < -0.5);
                let lens = m.parts.iter().find(|p| p.name == "lens").unwrap();
                assert!(lens.mesh.normals.iter().all(|n| n.y < -0.999));
            }
        }
    }

    /// A tree keeps a moderate triangle count.
    #[test]
    fn trees_are_light() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..20 {
            let m = TreeSpec::draw(&mut rng).build();
            let tris: usize = m.parts.iter().map(|p| p.mesh.triangle_count()).sum();
            assert!(tris <= 1000, "{tris}");
        }
    }

    /// The sign's face is in front of its plate, facing -Z.
    #[test]
    fn sign_faces_forward() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for _ in 0..10 {
            let m = SignSpec::draw(&mut rng).build();
            let face = m.parts.iter().find(|p| p.name == "face").unwrap();
            let plate = m.parts.iter().find(|p| p.name == "plate").unwrap();
            assert!(face.mesh.normals.iter().all(|n| n.z < -0.999));
            assert!(face.mesh.bounds().1.z < plate.mesh.bounds().0.z + 1e-6);
        }
    }
}
