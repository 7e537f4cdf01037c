//! The road's layout: where a street's straight frame lies in the world, and what is on and in
//! its surface (potholes, ruts, tram tracks, crosswalks, the paint).
//!
//! A street is built in a straight frame: X across (metres right of the centre line), Y up, and
//! -Z along the road, `s = -z` metres from the origin where the rig starts. A [`Road`] maps that
//! frame onto a road that curves (piecewise-linear curvature: straights, clothoid transitions
//! and arcs), climbs and falls (piecewise-linear grade: parabolic crests and sags, the vertical
//! curves of road design) and slopes across (a cross-fall and a crowned carriageway):
//!
//! `W(x, y, z) = C(s) + x N(s) + (y + E(s) + P(x)) Y`
//!
//! with the centre line `C(s) = ∫ (sin θ, 0, -cos θ) ds`, its right normal
//! `N = (cos θ, 0, sin θ)` at the heading `θ(s) = ∫ κ ds` (positive curvature turns right), the
//! elevation `E(s) = ∫ g ds` and the cross profile `P(x)` (flat beyond the carriageway's edges,
//! so that pavements stay level across). Vertical lines stay vertical, as walls and posts do;
//! the ground follows the road. Static meshes are bent vertex by vertex ([`Road::bend_mesh`],
//! normals by the map's Jacobian), rigid things are placed with a pose: cars and the rig on the
//! road's surface ([`Road::pose`]), buildings level on their lot ([`Road::level_pose`]). A
//! straight, level, flat road ([`Road::is_straight`]) maps every point to itself exactly, so
//! the shipped streets do not change.

use crate::mesh::Mesh;
use crate::procedural::{uniform, CountRange, Range};
use glam::{Affine3A, DMat3, DVec3, Mat3, Vec2, Vec3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The layout of a road: its curvature and grade along it and its cross profile. Knots are
/// `[s, value]` with `s` in metres along the road, sorted by `s`; between knots the value is
/// linear, before the first and after the last it is constant; no knots is zero.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RoadLayout {
    /// Curvature knots `[s, κ]`, κ in 1/m (positive: the road turns right). A ramp from 0 to
    /// `1/R` is a clothoid transition into an arc of radius `R`.
    pub curvature: Vec<[f64; 2]>,
    /// Grade knots `[s, g]`, g the rise per metre along the road. A ramp from one grade to a
    /// lower one is a parabolic crest, to a higher one a sag.
    pub grade: Vec<[f64; 2]>,
    /// Cross-fall of the carriageway, the fall per metre to the right (negative: to the left).
    pub cross_fall: f64,
    /// Crown: the parabolic fall from the centre line, as the slope at each edge.
    pub crown: f64,
    /// Half width of the carriageway, metres (the crown's and cross-fall's extent).
    pub half_width: f64,
}

/// `∫_0^s f` for the piecewise-linear `f` of `knots` (constant outside them).
fn integral(knots: &[[f64; 2]], s: f64) -> f64 {
    // G(t) = ∫_{s0}^t f, with s0 the first knot; the answer is G(s) - G(0).
    let g = |t: f64| -> f64 {
        let Some(first) = knots.first() else {
            return 0.0;
        };
        if t <= first[0] {
            return first[1] * (t - first[0]);
        }
        let mut acc = 0.0;
        for w in knots.windows(2) {
            let ([a, fa], [b, fb]) = (w[0], w[1]);
            if t <= b {
                let ft = if b > a {
                    fa + (fb - fa) * (t - a) / (b - a)
                } else {
                    fb
                };
                return acc + 0.5 * (fa + ft) * (t - a);
            }
            acc += 0.5 * (fa + fb) * (b - a);
        }
        let last = knots[knots.len() - 1];
        acc + last[1] * (t - last[0])
    };
    g(s) - g(0.0)
}

/// The piecewise-linear `f` of `knots` at `s`.
fn value(knots: &[[f64; 2]], s: f64) -> f64 {
    let (Some(first), Some(last)) = (knots.first(), knots.last()) else {
        return 0.0;
    };
    if s <= first[0] {
        return first[1];
    }
    for w in knots.windows(2) {
        let ([a, fa], [b, fb]) = (w[0], w[1]);
        if s <= b {
            return if b > a {
                fa + (fb - fa) * (s - a) / (b - a)
            } else {
                fb
            };
        }
    }
    last[1]
}

/// Gauss–Legendre nodes and weights on [-1, 1], four points (exact for degree 7).
const GL4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
    (-0.339_981_043_584_856_26, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_26, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
];

/// First and last station of the centre line's table, metres along the road.
const TABLE: (i32, i32) = (-400, 1200);

/// A road: its [`RoadLayout`] with the centre line tabulated every metre.
#[derive(Clone, Debug, PartialEq)]
pub struct Road {
    layout: RoadLayout,
    /// `C(s)` as (x, z) at `s = TABLE.0, TABLE.0 + 1, ...`.
    centre: Vec<[f64; 2]>,
}

impl Default for Road {
    fn default() -> Self {
        Self::straight()
    }
}

impl Road {
    /// The straight, level, flat road: the identity map.
    pub fn straight() -> Self {
        Self::new(RoadLayout::default())
    }

    /// The road of `layout`.
    pub fn new(layout: RoadLayout) -> Self {
        let mut road = Self {
            layout,
            centre: Vec::new(),
        };
        if !road.is_straight() {
            // C(0) = 0: integrate out from the origin both ways.
            let n = (TABLE.1 - TABLE.0) as usize + 1;
            let zero = (-TABLE.0) as usize;
            let mut c = vec![[0.0; 2]; n];
            for k in zero + 1..n {
                let s = f64::from(TABLE.0) + k as f64;
                let d = road.chord(s - 1.0, s);
                c[k] = [c[k - 1][0] + d[0], c[k - 1][1] + d[1]];
            }
            for k in (0..zero).rev() {
                let s = f64::from(TABLE.0) + k as f64;
                let d = road.chord(s + 1.0, s);
                c[k] = [c[k + 1][0] + d[0], c[k + 1][1] + d[1]];
            }
            road.centre = c;
        }
        road
    }

    /// The layout.
    pub fn layout(&self) -> &RoadLayout {
        &self.layout
    }

    /// Whether the road is straight, level and flat (the map is the identity).
    pub fn is_straight(&self) -> bool {
        let l = &self.layout;
        let zero = |k: &[[f64; 2]]| k.iter().all(|[_, v]| *v == 0.0);
        zero(&l.curvature) && zero(&l.grade) && l.cross_fall == 0.0 && l.crown == 0.0
    }

    /// Heading θ at `s`, radians (0: along -Z; positive: turned towards +X).
    pub fn heading(&self, s: f64) -> f64 {
        integral(&self.layout.curvature, s)
    }

    /// Curvature at `s`, 1/m.
    pub fn curvature(&self, s: f64) -> f64 {
        value(&self.layout.curvature, s)
    }

    /// Grade at `s`, rise per metre.
    pub fn grade(&self, s: f64) -> f64 {
        value(&self.layout.grade, s)
    }

    /// Elevation of the centre line at `s` above the origin's, metres.
    pub fn elevation(&self, s: f64) -> f64 {
        integral(&self.layout.grade, s)
    }

    /// The cross profile's height at `x` metres right of the centre line (flat beyond the
    /// edges), and its slope.
    pub fn profile(&self, x: f64) -> (f64, f64) {
        let l = &self.layout;
        let h = l.half_width.max(1e-6);
        let xc = x.clamp(-h, h);
        let y = -l.cross_fall * xc - l.crown * xc * xc / (2.0 * h);
        let slope = if x.abs() <= h {
            -l.cross_fall - l.crown * xc / h
        } else {
            0.0
        };
        (y, slope)
    }

    /// `∫_a^b (sin θ, -cos θ) ds` in panels of at most 1 m.
    fn chord(&self, a: f64, b: f64) -> [f64; 2] {
        let panels = ((b - a).abs().ceil() as usize).max(1);
        let h = (b - a) / panels as f64;
        let mut acc = [0.0; 2];
        for p in 0..panels {
            let mid = a + (p as f64 + 0.5) * h;
            for (node, weight) in GL4 {
                let th = self.heading(mid + 0.5 * h * node);
                acc[0] += 0.5 * h * weight * th.sin();
                acc[1] -= 0.5 * h * weight * th.cos();
            }
        }
        acc
    }

    /// The centre line at `s` as (x, z).
    pub fn centre(&self, s: f64) -> [f64; 2] {
        if self.is_straight() {
            return [0.0, -s];
        }
        let k = (s.floor() as i64).clamp(i64::from(TABLE.0), i64::from(TABLE.1));
        let base = self.centre[(k - i64::from(TABLE.0)) as usize];
        let d = self.chord(k as f64, s);
        [base[0] + d[0], base[1] + d[1]]
    }

    /// The world point of the straight frame's `p`.
    pub fn world(&self, p: Vec3) -> Vec3 {
        if self.is_straight() {
            return p;
        }
        self.world_f64(p.as_dvec3()).as_vec3()
    }

    fn world_f64(&self, p: DVec3) -> DVec3 {
        let s = -p.z;
        let c = self.centre(s);
        let th = self.heading(s);
        let y = p.y + self.elevation(s) + self.profile(p.x).0;
        DVec3::new(c[0] + p.x * th.cos(), y, c[1] + p.x * th.sin())
    }

    /// The map's Jacobian at the straight frame's `p` (columns: d/dx, d/dy, d/dz).
    fn jacobian(&self, p: DVec3) -> DMat3 {
        let s = -p.z;
        let th = self.heading(s);
        let along = DVec3::new(th.sin(), 0.0, -th.cos());
        let across = DVec3::new(th.cos(), self.profile(p.x).1, th.sin());
        let d_ds = along * (1.0 - self.curvature(s) * p.x) + DVec3::Y * self.grade(s);
        DMat3::from_cols(across, DVec3::Y, -d_ds)
    }

    /// `mesh` bent onto the road: positions through [`Road::world`], normals by the inverse
    /// transpose of its Jacobian. Long faces must be tessellated finely enough to follow the
    /// curve (the map is exact at vertices only).
    pub fn bend_mesh(&self, mesh: &Mesh) -> Mesh {
        if self.is_straight() {
            return mesh.clone();
        }
        let mut out = mesh.clone();
        for (p, n) in out.positions.iter_mut().zip(&mut out.normals) {
            let q = p.as_dvec3();
            let cof = self.jacobian(q).inverse().transpose();
            *n = (cof * n.as_dvec3()).normalize_or_zero().as_vec3();
            *p = self.world_f64(q).as_vec3();
        }
        out
    }

    /// A point and a direction of the straight frame (a light's) on the road.
    pub fn bend_ray(&self, position: Vec3, direction: Vec3) -> (Vec3, Vec3) {
        if self.is_straight() {
            return (position, direction);
        }
        let q = position.as_dvec3();
        let d = self.jacobian(q) * direction.as_dvec3();
        (self.world(position), d.normalize_or_zero().as_vec3())
    }

    /// The pose of a frame standing on the road's surface `lateral` metres right of the centre
    /// line and `along` metres along it: its local -Z is the direction of travel, +Y the
    /// surface's normal, +X the right of travel; turned half a turn about its Y when `reverse`
    /// (oncoming traffic).
    pub fn pose(&self, lateral: f32, along: f64, reverse: bool) -> Affine3A {
        let p = DVec3::new(f64::from(lateral), 0.0, -along);
        let j = self.jacobian(p);
        let forward = (-j.z_axis).normalize();
        let up = j.x_axis.cross(-j.z_axis).normalize();
        let right = forward.cross(up);
        let (r, f) = if reverse {
            (-right, -forward)
        } else {
            (right, forward)
        };
        let rotation = Mat3::from_cols(r.as_vec3(), up.as_vec3(), (-f).as_vec3());
        let origin = if self.is_straight() {
            Vec3::new(lateral, 0.0, -(along as f32))
        } else {
            self.world_f64(p).as_vec3()
        };
        Affine3A::from_mat3_translation(rotation, origin)
    }

    /// The rigid, level pose that carries the straight frame around the centre-line point
    /// `along` metres along the road onto the road, with that point at height `height`: turned
    /// about Y to the road's heading, not tilted. Buildings stand on it.
    pub fn level_pose(&self, along: f64, height: f32) -> Affine3A {
        if self.is_straight() && height == 0.0 {
            return Affine3A::IDENTITY;
        }
        let th = self.heading(along);
        let c = self.centre(along);
        let rotation = Mat3::from_rotation_y(-th as f32);
        let to = Vec3::new(c[0] as f32, height, c[1] as f32);
        Affine3A::from_translation(to)
            * Affine3A::from_mat3(rotation)
            * Affine3A::from_translation(Vec3::new(0.0, 0.0, along as f32))
    }

    /// The lowest ground height (world Y of the straight frame's `y = 0`) at `x` over
    /// `s` in `[s0, s1]`, sampled every metre and at the ends.
    pub fn lowest_ground(&self, x: f32, s0: f64, s1: f64) -> f32 {
        let (a, b) = (s0.min(s1), s0.max(s1));
        let n = ((b - a).ceil() as usize).max(1);
        (0..=n)
            .map(|k| {
                let s = a + (b - a) * k as f64 / n as f64;
                self.world(Vec3::new(x, 0.0, -s as f32)).y
            })
            .fold(f32::INFINITY, f32::min)
    }
}

/// A pothole: a bowl in the carriageway, `depth` deep at its centre, its rim the curve
/// `radius (1 + wobble(φ))`, holding water up to 1 cm below the rim's lowest point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pothole {
    /// Centre across the road (straight frame X), metres.
    pub x: f32,
    /// Centre along the road (straight frame Z), metres.
    pub z: f32,
    /// Mean rim radius, metres.
    pub radius: f32,
    /// Depth at the centre, metres.
    pub depth: f32,
    /// Phases of the rim's 3- and 5-lobed wobble, radians.
    pub phase: [f32; 2],
}

impl Pothole {
    /// The rim radius towards angle `phi` (radians, from +X towards +Z).
    pub fn rim(&self, phi: f32) -> f32 {
        self.radius
            * (1.0
                + 0.15 * (3.0 * phi + self.phase[0]).sin()
                + 0.08 * (5.0 * phi + self.phase[1]).sin())
    }

    /// How far below the road the bowl is at (x, z): `depth (1 - t^2)` inside, with `t` the
    /// distance from the centre over the rim radius that way.
    pub fn depth_at(&self, x: f32, z: f32) -> f32 {
        let d = Vec2::new(x - self.x, z - self.z);
        let r = d.length();
        if r >= 1.3 * self.radius {
            return 0.0;
        }
        let t = r / self.rim(d.y.atan2(d.x));
        if t >= 1.0 {
            0.0
        } else {
            self.depth * (1.0 - t * t)
        }
    }
}

/// A zebra crossing: white bars along the road across the whole carriageway, the kerbs dropped
/// beside it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Crosswalk {
    /// Centre along the road (straight frame Z), metres.
    pub z: f32,
    /// Length of the bars along the road, metres.
    pub length: f32,
}

/// A side street joining at a T junction (or, with one at the same place on the other side, at
/// a crossroads): its carriageway leaves the main road's edge at a right angle (in the straight
/// frame), with kerbs and pavements along it and a block closing it; the main road's kerb,
/// pavement, edge line and buildings leave the mouth open.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Junction {
    /// Centre of the mouth along the road (straight frame Z), metres.
    pub z: f32,
    /// Side: 1 right, -1 left.
    pub side: f32,
    /// Width of the side street's carriageway, metres.
    pub width: f32,
    /// Width of its pavements, metres.
    pub pavement: f32,
    /// How far it is modelled beyond the main street's facade line, metres.
    pub length: f32,
}

impl Junction {
    /// The mouth's extent along the main road, `(z0, z1)` with `z0 > z1`.
    pub fn mouth(&self) -> (f32, f32) {
        (self.z + 0.5 * self.width, self.z - 0.5 * self.width)
    }

    /// The gap in the main street's frontage: the mouth and the side street's pavements.
    pub fn gap(&self) -> (f32, f32) {
        let half = 0.5 * self.width + self.pavement;
        (self.z + half, self.z - half)
    }
}

/// The road markings' paint.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Paint {
    /// Diffuse reflectance.
    pub kd: f64,
    /// Specular reflectance (higher when wet).
    pub ks: f64,
    /// GGX roughness (lower when wet).
    pub alpha: f64,
    /// Share of the paint worn away, in 25 cm pieces.
    pub wear: f64,
    /// The glass beads' coefficient of retroreflected luminance `R_L` as the paint is (wet
    /// or dry), mcd m^-2 lx^-1 at EN 1436's geometry; 0: no beads.
    #[serde(default)]
    pub rl_mcd: f64,
}

impl Paint {
    /// The shipped streets' paint.
    pub const SHIPPED: Self = Self {
        kd: 0.55,
        ks: 0.05,
        alpha: 0.15,
        wear: 0.0,
        rl_mcd: 0.0,
    };
}

/// What is on and in the road's surface besides the asphalt.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoadFeatures {
    /// Potholes holding water.
    pub potholes: Vec<Pothole>,
    /// Depth of the ruts worn in each lane's wheel paths, metres.
    pub rut_depth: f32,
    /// Centres across the road of tram tracks (standard gauge), metres.
    pub tracks: Vec<f32>,
    /// Zebra crossings.
    pub crosswalks: Vec<Crosswalk>,
    /// The markings' paint.
    pub paint: Paint,
    /// Side streets.
    pub junctions: Vec<Junction>,
}

impl Default for RoadFeatures {
    fn default() -> Self {
        Self {
            junctions: Vec::new(),
            potholes: Vec::new(),
            rut_depth: 0.0,
            tracks: Vec::new(),
            crosswalks: Vec::new(),
            paint: Paint::SHIPPED,
        }
    }
}

/// Standard track gauge (between the rails' inner faces), metres.
pub const GAUGE: f32 = 1.435;
/// Width of a rail's head, metres.
pub const RAIL_HEAD: f32 = 0.06;
/// Width of a grooved rail's groove, metres.
pub const RAIL_GROOVE: f32 = 0.04;
/// Height of a dropped kerb at a crossing, metres.
pub const DROPPED_KERB: f32 = 0.02;
/// Length of the ramp from a kerb down to a dropped kerb, metres.
pub const KERB_RAMP: f32 = 1.0;

impl RoadFeatures {
    /// Whether the surface has nothing but the shipped streets' markings.
    pub fn is_plain(&self) -> bool {
        *self == Self::default()
    }

    /// How far below the level surface the carriageway is at (x, z) (ruts and potholes),
    /// for a road of `lanes` lanes `half` metres either side of the centre line.
    pub fn depth(&self, x: f32, z: f32, half: f32, lanes: u32) -> f32 {
        let mut d = 0.0;
        if self.rut_depth > 0.0 && x.abs() < half {
            let width = 2.0 * half / lanes.max(1) as f32;
            let lane = ((x + half) / width)
                .floor()
                .clamp(0.0, lanes.max(1) as f32 - 1.0);
            let centre = -half + (lane + 0.5) * width;
            // The wheel tracks of the dryness map (crate::wetness), which then hold water.
            for wheel in [-0.8f32, 0.8] {
                let t = (x - centre - wheel) / 0.28;
                d += self.rut_depth * (-t * t).exp();
            }
        }
        for p in &self.potholes {
            d += p.depth_at(x, z);
        }
        d
    }

    /// Whether `z` on side `side` lies in a side street's mouth (no kerb, no pavement), widened
    /// by `margin` metres.
    pub fn in_mouth(&self, side: f32, z: f32, margin: f32) -> bool {
        self.junctions.iter().any(|j| {
            let (a, b) = j.mouth();
            j.side == side && z < a + margin && z > b - margin
        })
    }

    /// The kerb's height at `z` for a street whose kerbs are `kerb` high: dropped to
    /// [`DROPPED_KERB`] beside each crossing, with [`KERB_RAMP`] ramps.
    pub fn kerb_at(&self, kerb: f32, z: f32) -> f32 {
        let mut h = kerb;
        for c in &self.crosswalks {
            let d = (z - c.z).abs() - 0.5 * c.length;
            let t = (d / KERB_RAMP).clamp(0.0, 1.0);
            h = h.min(DROPPED_KERB + (kerb - DROPPED_KERB).max(0.0) * t);
        }
        h
    }

    /// The Z stations every long strip of the street shares, from `near` down to `far`: every
    /// `step` metres, 20 cm apart over potholes, and at the kerb ramps' ends. Strips with the
    /// same stations meet without cracks once bent.
    pub fn stations(&self, near: f32, far: f32, step: f32) -> Vec<f32> {
        let mut z = Vec::new();
        let n = ((near - far) / step).ceil().max(1.0) as usize;
        for k in 0..=n {
            z.push(near + (far - near) * k as f32 / n as f32);
        }
        for p in &self.potholes {
            let r = 1.3 * p.radius;
            let m = (2.0 * r / 0.2).ceil() as usize;
            for k in 0..=m {
                z.push(p.z - r + 2.0 * r * k as f32 / m as f32);
            }
        }
        for j in &self.junctions {
            let (a, b) = j.mouth();
            let (c, d) = j.gap();
            z.extend([a, b, c, d]);
        }
        for c in &self.crosswalks {
            for d in [0.0, KERB_RAMP] {
                let e = 0.5 * c.length + d;
                z.extend([c.z - e, c.z + e]);
            }
            let m = (c.length / 0.5).ceil() as usize;
            for k in 0..=m {
                z.push(c.z - 0.5 * c.length + c.length * k as f32 / m as f32);
            }
        }
        z.retain(|v| *v <= near && *v >= far);
        z.sort_by(|a, b| b.total_cmp(a));
        z.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
        z
    }
}

/// The distribution of road layouts and surfaces (TOML `[road]`): each street draws one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoadConfig {
    /// Probability that the street bends (left or right, equally often).
    pub curve: f64,
    /// Radius of the bend's arc, metres.
    pub radius: Range,
    /// Where the bend's clothoid transition starts, metres ahead of the rig.
    pub curve_start: Range,
    /// Length of the clothoid transition from the straight into the arc, metres.
    pub transition: Range,
    /// Probability that the grade changes ahead (a crest or a sag).
    pub hill: f64,
    /// Grade at the rig, rise per metre.
    pub grade: Range,
    /// Grade after the vertical curve less the grade before it (negative: a crest).
    pub grade_change: Range,
    /// Where the vertical curve starts, metres ahead of the rig.
    pub vertical_curve_start: Range,
    /// Length of the vertical curve, metres.
    pub vertical_curve_length: Range,
    /// Cross-fall, the fall per metre to the right (negative: to the left).
    pub cross_fall: Range,
    /// Crown, the fall at each edge of the carriageway per metre.
    pub crown: Range,
    /// Number of potholes holding water.
    pub potholes: CountRange,
    /// A pothole's mean radius, metres.
    pub pothole_radius: Range,
    /// A pothole's depth, metres.
    pub pothole_depth: Range,
    /// Depth of the ruts in the wheel paths, metres.
    pub rut_depth: Range,
    /// Probability of tram tracks (one in each direction's innermost lane).
    pub tracks: f64,
    /// Number of side streets joining at a T junction.
    pub junctions: CountRange,
    /// Width of a side street's carriageway, metres.
    pub junction_width: Range,
    /// Probability that a side street continues across the main street: a crossroads.
    pub crossroads: f64,
    /// Number of zebra crossings.
    pub crosswalks: CountRange,
    /// Length of a crossing's bars along the road, metres.
    pub crosswalk_length: Range,
    /// Diffuse reflectance of the markings' paint.
    pub paint_albedo: Range,
    /// Share of the paint worn away.
    pub paint_wear: Range,
    /// How wet the paint is, 0 (dry, matte) to 1 (a film of water: glossy).
    pub paint_wet: Range,
    /// The paint's glass beads: their coefficient of retroreflected luminance `R_L` when dry,
    /// mcd m^-2 lx^-1 (EN 1436; 0: no beads). Water over the beads takes up to three
    /// quarters of it: `R_L = R_L,dry (1 - 0.75 wet)`.
    pub paint_rl_mcd: Range,
}

impl Default for RoadConfig {
    fn default() -> Self {
        Self {
            curve: 0.6,
            radius: [60.0, 400.0],
            curve_start: [5.0, 60.0],
            transition: [10.0, 40.0],
            hill: 0.6,
            grade: [-0.06, 0.06],
            grade_change: [-0.08, 0.08],
            vertical_curve_start: [10.0, 60.0],
            vertical_curve_length: [30.0, 100.0],
            cross_fall: [-0.02, 0.02],
            crown: [0.0, 0.03],
            potholes: [0, 4],
            pothole_radius: [0.2, 0.6],
            pothole_depth: [0.04, 0.09],
            rut_depth: [0.0, 0.015],
            tracks: 0.15,
            junctions: [0, 2],
            junction_width: [5.5, 8.0],
            crossroads: 0.4,
            crosswalks: [0, 2],
            crosswalk_length: [3.0, 5.0],
            paint_albedo: [0.3, 0.65],
            paint_wear: [0.0, 0.4],
            paint_wet: [0.0, 1.0],
            paint_rl_mcd: [100.0, 300.0],
        }
    }
}

/// A street's drawn road: its map, its surface, and the drawn values (for `meta.json`).
#[derive(Clone, Debug)]
pub struct DrawnRoad {
    /// The map from the straight frame to the world.
    pub road: Road,
    /// Potholes, ruts, tracks, crossings, paint.
    pub features: RoadFeatures,
    /// The drawn values by config name.
    pub params: serde_json::Value,
}

impl RoadConfig {
    /// Checks every range and probability.
    pub fn validate(&self) -> Result<(), String> {
        let check = crate::check::Section("road");
        check.prob("curve", self.curve)?;
        // Tighter than 40 m and the buildings' backs (up to ~25 m out) fold over.
        check.range("radius", self.radius, 40.0, 1e5)?;
        check.range("curve_start", self.curve_start, -50.0, 500.0)?;
        check.range("transition", self.transition, 0.0, 500.0)?;
        check.prob("hill", self.hill)?;
        check.range("grade", self.grade, -0.15, 0.15)?;
        check.range("grade_change", self.grade_change, -0.2, 0.2)?;
        check.range(
            "vertical_curve_start",
            self.vertical_curve_start,
            -50.0,
            500.0,
        )?;
        check.range(
            "vertical_curve_length",
            self.vertical_curve_length,
            1.0,
            1000.0,
        )?;
        check.range("cross_fall", self.cross_fall, -0.08, 0.08)?;
        check.range("crown", self.crown, 0.0, 0.08)?;
        check.count("potholes", self.potholes, 50)?;
        check.range("pothole_radius", self.pothole_radius, 0.05, 1.5)?;
        check.range("pothole_depth", self.pothole_depth, 0.0, 0.3)?;
        check.range("rut_depth", self.rut_depth, 0.0, 0.05)?;
        check.prob("tracks", self.tracks)?;
        check.count("junctions", self.junctions, 6)?;
        check.range("junction_width", self.junction_width, 3.0, 20.0)?;
        check.prob("crossroads", self.crossroads)?;
        check.count("crosswalks", self.crosswalks, 10)?;
        check.range("crosswalk_length", self.crosswalk_length, 1.0, 10.0)?;
        check.range("paint_albedo", self.paint_albedo, 0.0, 1.0)?;
        check.range("paint_wear", self.paint_wear, 0.0, 1.0)?;
        check.range("paint_wet", self.paint_wet, 0.0, 1.0)?;
        check.range("paint_rl_mcd", self.paint_rl_mcd, 0.0, 2000.0)
    }

    /// Draws a street's road for a carriageway of `lanes` lanes `lane_width` wide, modelled
    /// down to `far` (straight frame Z); potholes and crossings lie ahead of the rig.
    pub fn draw(&self, rng: &mut ChaCha8Rng, lanes: u32, lane_width: f32, far: f32) -> DrawnRoad {
        let half = lanes as f32 * lane_width * 0.5;
        let mut layout = RoadLayout {
            half_width: f64::from(half),
            ..RoadLayout::default()
        };
        let mut params = serde_json::Map::new();
        let curved = rng.random_bool(self.curve);
        let turn = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let radius = uniform(rng, self.radius);
        let start = uniform(rng, self.curve_start);
        let transition = uniform(rng, self.transition);
        if curved {
            layout.curvature = vec![[start, 0.0], [start + transition, turn / radius]];
            params.insert("curvature".into(), json!(turn / radius));
            params.insert("radius".into(), json!(radius));
            params.insert("curve_start".into(), json!(start));
            params.insert("transition".into(), json!(transition));
        } else {
            params.insert("curvature".into(), json!(0.0));
        }
        let grade = uniform(rng, self.grade);
        let hill = rng.random_bool(self.hill);
        let change = uniform(rng, self.grade_change);
        let v_start = uniform(rng, self.vertical_curve_start);
        let v_len = uniform(rng, self.vertical_curve_length);
        layout.grade = if hill {
            params.insert("grade_change".into(), json!(change));
            params.insert("vertical_curve_start".into(), json!(v_start));
            params.insert("vertical_curve_length".into(), json!(v_len));
            vec![[v_start, grade], [v_start + v_len, grade + change]]
        } else {
            vec![[0.0, grade]]
        };
        params.insert("grade".into(), json!(grade));
        layout.cross_fall = uniform(rng, self.cross_fall);
        layout.crown = uniform(rng, self.crown);
        params.insert("cross_fall".into(), json!(layout.cross_fall));
        params.insert("crown".into(), json!(layout.crown));

        let mut features = RoadFeatures::default();
        // Potholes ahead of the rig, clear of the kerbs.
        let ahead = (far + 10.0, -4.0f32.min(far + 12.0));
        for _ in 0..rng.random_range(self.potholes[0]..=self.potholes[1]) {
            let radius = uniform(rng, self.pothole_radius) as f32;
            let reach = (half - 1.3 * radius - 0.3).max(0.0);
            features.potholes.push(Pothole {
                x: rng.random_range(-reach..=reach),
                z: rng.random_range(ahead.0.min(ahead.1)..=ahead.1.max(ahead.0)),
                radius,
                depth: uniform(rng, self.pothole_depth) as f32,
                phase: [
                    rng.random_range(0.0..std::f32::consts::TAU),
                    rng.random_range(0.0..std::f32::consts::TAU),
                ],
            });
        }
        params.insert("potholes".into(), json!(features.potholes.len()));
        features.rut_depth = uniform(rng, self.rut_depth) as f32;
        params.insert("rut_depth".into(), json!(features.rut_depth));
        if rng.random_bool(self.tracks) {
            // The lane centres nearest the centre line on either side (or on it).
            let centres: Vec<f32> = (0..lanes)
                .map(|i| -half + (i as f32 + 0.5) * lane_width)
                .collect();
            let on = centres.iter().copied().find(|x| x.abs() < 1e-3);
            features.tracks = match on {
                Some(x) => vec![x],
                None => [
                    centres
                        .iter()
                        .copied()
                        .filter(|x| *x < 0.0)
                        .fold(f32::MIN, f32::max),
                    centres
                        .iter()
                        .copied()
                        .filter(|x| *x > 0.0)
                        .fold(f32::MAX, f32::min),
                ]
                .into_iter()
                .filter(|x| x.abs() < half)
                .collect(),
            };
        }
        params.insert("tracks".into(), json!(features.tracks.len()));
        let n_junctions = rng.random_range(self.junctions[0]..=self.junctions[1]);
        for _ in 0..n_junctions {
            let width = uniform(rng, self.junction_width) as f32;
            let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let pavement = rng.random_range(1.5f32..=3.0);
            let lo = (far + 30.0).max(-100.0);
            let z = rng.random_range(lo.min(-15.0)..=-15.0);
            let across = rng.random_bool(self.crossroads);
            // Keep junctions 30 m apart; a crossroads is a side street on either side.
            if features.junctions.iter().all(|j| (j.z - z).abs() > 30.0) {
                let j = Junction {
                    z,
                    side,
                    width,
                    pavement,
                    length: 15.0,
                };
                features.junctions.push(j);
                if across {
                    features.junctions.push(Junction { side: -side, ..j });
                }
            }
        }
        params.insert("junctions".into(), json!(features.junctions.len()));
        let n_cross = rng.random_range(self.crosswalks[0]..=self.crosswalks[1]);
        for _ in 0..n_cross {
            let length = uniform(rng, self.crosswalk_length) as f32;
            let lo = (far + 15.0).max(-90.0);
            let z = rng.random_range(lo.min(-8.0)..=-8.0);
            // Keep crossings 20 m apart and clear of the junctions' mouths.
            let clear = features.crosswalks.iter().all(|c| (c.z - z).abs() > 20.0)
                && features
                    .junctions
                    .iter()
                    .all(|j| (j.z - z).abs() > 0.5 * (j.width + length) + j.pavement + 1.0);
            if clear {
                features.crosswalks.push(Crosswalk { z, length });
            }
        }
        params.insert("crosswalks".into(), json!(features.crosswalks.len()));
        let kd = uniform(rng, self.paint_albedo);
        let wear = uniform(rng, self.paint_wear);
        let wet = uniform(rng, self.paint_wet);
        let rl_dry = uniform(rng, self.paint_rl_mcd);
        let rl = crate::gltf_writer::round7(rl_dry * (1.0 - 0.75 * wet));
        features.paint = Paint {
            kd: crate::gltf_writer::round7(kd),
            ks: crate::gltf_writer::round7(0.04 + 0.06 * wet),
            alpha: crate::gltf_writer::round7(0.3 - 0.25 * wet),
            wear,
            rl_mcd: rl,
        };
        params.insert("paint_albedo".into(), json!(kd));
        params.insert("paint_wear".into(), json!(wear));
        params.insert("paint_wet".into(), json!(wet));
        params.insert("paint_rl_mcd".into(), json!(rl));
        DrawnRoad {
            road: Road::new(layout),
            features,
            params: serde_json::Value::Object(params),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curved() -> Road {
        Road::new(RoadLayout {
            curvature: vec![[20.0, 0.0], [50.0, 1.0 / 80.0]],
            grade: vec![[10.0, 0.05], [70.0, -0.04]],
            cross_fall: 0.01,
            crown: 0.02,
            half_width: 3.5,
        })
    }

    /// The straight road maps every point to itself, and its poses are the old straight ones.
    #[test]
    fn the_straight_road_is_the_identity() {
        let road = Road::straight();
        let p = Vec3::new(1.25, 0.7, -37.3);
        assert_eq!(road.world(p), p);
        let pose = road.pose(1.5, 20.0, false);
        assert_eq!(Vec3::from(pose.translation), Vec3::new(1.5, 0.0, -20.0));
        assert!((pose.transform_vector3(Vec3::NEG_Z) - Vec3::NEG_Z).length() < 1e-6);
        let back = road.pose(-1.5, 20.0, true);
        assert!((back.transform_vector3(Vec3::NEG_Z) - Vec3::Z).length() < 1e-6);
        assert!(road.level_pose(12.0, 0.0) == Affine3A::IDENTITY);
    }

    /// On an arc of radius R reached by a clothoid of length L, the heading is L/(2R) at the
    /// arc's start and grows by 1/R per metre on it; the centre line keeps unit speed.
    #[test]
    fn clothoid_into_arc_has_the_right_heading_and_unit_speed() {
        let road = curved();
        let (r, l) = (80.0, 30.0);
        assert!(road.heading(20.0).abs() < 1e-12);
        assert!((road.heading(50.0) - l / (2.0 * r)).abs() < 1e-12);
        assert!((road.heading(60.0) - l / (2.0 * r) - 10.0 / r).abs() < 1e-12);
        for s in [-30.0, 0.5, 25.3, 49.9, 120.0, 700.0] {
            let (a, b) = (road.centre(s), road.centre(s + 1e-3));
            let speed = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt() / 1e-3;
            assert!((speed - 1.0).abs() < 1e-6, "speed {speed} at {s}");
        }
        // On the arc the centre line keeps its distance R from the arc's centre.
        let th = road.heading(60.0);
        let c = road.centre(60.0);
        let o = [c[0] + r * th.cos(), c[1] + r * th.sin()];
        for s in [55.0, 80.0, 130.0] {
            let q = road.centre(s);
            let d = ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2)).sqrt();
            assert!((d - r).abs() < 1e-6, "distance {d} at {s}");
        }
    }

    /// The elevation is the grade's integral: a parabola over the vertical curve.
    #[test]
    fn a_crest_is_a_parabola() {
        let road = curved();
        assert!((road.elevation(10.0) - 0.5).abs() < 1e-12);
        // Over [10, 70] the grade falls linearly from 0.05 to -0.04.
        let e = |s: f64| 0.5 + 0.05 * (s - 10.0) - 0.09 * (s - 10.0).powi(2) / 120.0;
        for s in [20.0, 40.0, 70.0] {
            assert!((road.elevation(s) - e(s)).abs() < 1e-12);
        }
        assert!((road.elevation(100.0) - e(70.0) + 0.04 * 30.0).abs() < 1e-12);
        assert!((road.elevation(-10.0) + 0.5).abs() < 1e-12);
    }

    /// The Jacobian the normals and poses use is the map's derivative (finite differences).
    #[test]
    fn the_jacobian_is_the_derivative() {
        let road = curved();
        for p in [
            DVec3::new(2.0, 0.3, -35.0),
            DVec3::new(-4.0, 1.0, -60.0),
            DVec3::new(9.0, 0.0, -5.0),
        ] {
            let j = road.jacobian(p);
            let e = 1e-5;
            for (axis, col) in [
                (DVec3::X, j.x_axis),
                (DVec3::Y, j.y_axis),
                (DVec3::Z, j.z_axis),
            ] {
                let fd = (road.world_f64(p + axis * e) - road.world_f64(p - axis * e)) / (2.0 * e);
                assert!((fd - col).length() < 1e-6, "{fd} vs {col} at {p}");
            }
        }
    }

    /// A pose stands on the surface: its origin is the mapped point, its up the surface normal
    /// and its forward the lane's tangent.
    #[test]
    fn a_pose_stands_on_the_surface() {
        let road = curved();
        for (x, s) in [(1.7f32, 40.0f64), (-1.7, 65.0)] {
            let pose = road.pose(x, s, false);
            let here = road.world(Vec3::new(x, 0.0, -s as f32));
            assert!((Vec3::from(pose.translation) - here).length() < 1e-5);
            let ahead = road.world(Vec3::new(x, 0.0, -(s + 0.01) as f32));
            let tangent = (ahead - here).normalize();
            let forward = pose.transform_vector3(Vec3::NEG_Z);
            assert!(forward.dot(tangent) > 1.0 - 1e-5);
            let side = road.world(Vec3::new(x + 0.01, 0.0, -s as f32)) - here;
            let up = pose.transform_vector3(Vec3::Y);
            assert!(up.dot(side.normalize()).abs() < 1e-4);
            assert!(up.dot(tangent).abs() < 1e-4);
            assert!(up.y > 0.99);
        }
    }

    /// With crossroads certain, every side street has its twin across the main street.
    #[test]
    fn crossroads_have_side_streets_on_both_sides() {
        use rand::SeedableRng;
        let config = RoadConfig {
            junctions: [2, 2],
            crossroads: 1.0,
            ..RoadConfig::default()
        };
        for seed in 0..8 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let f = config.draw(&mut rng, 2, 3.5, -150.0).features;
            assert!(!f.junctions.is_empty() && f.junctions.len() % 2 == 0);
            for pair in f.junctions.chunks(2) {
                assert_eq!((pair[0].z, pair[0].side), (pair[1].z, -pair[1].side));
            }
        }
    }

    /// Kerbs drop beside a crossing and ramp back; the stations include the ramp ends.
    #[test]
    fn kerbs_drop_at_crossings() {
        let f = RoadFeatures {
            crosswalks: vec![Crosswalk {
                z: -30.0,
                length: 4.0,
            }],
            ..RoadFeatures::default()
        };
        assert_eq!(f.kerb_at(0.15, -30.0), DROPPED_KERB);
        assert_eq!(f.kerb_at(0.15, -32.0), DROPPED_KERB);
        assert!((f.kerb_at(0.15, -32.5) - 0.085).abs() < 1e-6);
        assert_eq!(f.kerb_at(0.15, -40.0), 0.15);
        let z = f.stations(10.0, -100.0, 1.0);
        assert!(z.iter().any(|v| (v + 33.0).abs() < 1e-4));
        assert!(z.windows(2).all(|w| w[0] > w[1]));
    }
}
