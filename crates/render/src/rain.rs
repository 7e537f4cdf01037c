//! Rain in the air: falling water drops as a dedicated moving primitive.
//!
//! A scene's rain (`scenes[i].extras.streaks.rain = {"rate_mm_h": R, "seed": n, "radius": m}`,
//! [`RainParams`]) becomes explicit drops, water spheres of index [`WATER_IOR`] that fall at
//! their terminal speed during the shutter ([`crate::motion::Motion`]), so that each drop is a
//! motion-blurred streak of refracted and reflected light.
//!
//! - Sizes: Marshall and Palmer (1948), `N(D) = N0 exp(-Lambda D)` drops per m^3 per mm of
//!   diameter, `N0 = 8000 m^-3 mm^-1`, `Lambda = 4.1 R^-0.21 mm^-1` (R in mm/h), cut to
//!   diameters between [`D_MIN_MM`] = 0.5 mm and [`D_MAX_MM`] = 6 mm: drops below 0.5 mm are
//!   under a tenth of a pixel wide beyond a metre and make up most of the count but little of
//!   the look (the streaks), and drops break up above about 6 mm. The number density is the
//!   closed-form integral ([`number_density`]): 251, 634 and 1352 drops per m^3 at 1, 5 and
//!   25 mm/h. A diameter is drawn from the truncated exponential ([`sample_diameter`]).
//! - Speed: Gunn and Kinzer's (1949) measured terminal speeds through the fit of Atlas,
//!   Srivastava and Sekhon (1973), `v = 9.65 - 10.3 exp(-0.6 D)` m/s (D in mm), clamped at 0
//!   ([`terminal_speed`]): 2.0 m/s at 0.5 mm, 4.0 at 1 mm, 6.6 at 2 mm, 9.1 at 5 mm, within
//!   2 % of the measurements, at sea level. Drops fall straight down (-Y), no wind.
//! - Shape: spheres of diameter D. Real drops above about 1 mm are oblate (axis ratio 0.93 at
//!   2 mm, Beard and Chuang 1987) and oscillate; at the one or two pixels a drop is wide that
//!   changes little, and spheres keep the intersector exact and cheap.
//! - Where: the drops are placed once per scene and view ([`DropField::place`]), seeded by the
//!   rain's own seed only (never the render's), uniformly (a Poisson-like process of the
//!   Marshall-Palmer density) in the region a camera can see them: its view frustum from
//!   [`RAIN_NEAR`] = 0.5 m in front of it (a car's camera sits behind the windscreen; nearer
//!   drops would be on the glass) out to `radius` metres from it, widened on every side by a
//!   margin ([`RainView::margin`]: half a metre for the commands' rigs, which covers both eyes
//!   of any baseline up to a metre, plus how far the rig and the drops move during the
//!   shutter). Both eyes of a stereo pair and every sample of the image therefore see the same
//!   drops at their true positions. Rain beyond `radius` is left out: a drop there is far
//!   under a pixel wide and its streaks blend into a faint haze (the fog's job).
//! - How: a drop is `centre(t) = centre + v t` with `v = (0, -speed, 0)`, intersected exactly
//!   at the ray's time. Camera rays meet drops through a per-camera index ([`CameraRain`],
//!   built at the start of each render): for every pixel, a copy of each drop whose sphere,
//!   moving over the shutter relative to the moving camera, projects into it, so a camera ray
//!   tests the few drops of its own pixel; no triangles are made. Under an open shutter a
//!   camera ray does not meet the drops at one time: the drops that cover it at some time of
//!   the shutter ([`CameraRain::swept`], [`Drop::swept_interval`]: in the camera's frame the
//!   ray stands still and a drop's centre moves at its velocity less the rig's, so its
//!   distance from the ray is below the radius on one interval, a quadratic's roots) give the
//!   share of the shutter the ray sees rain, and the integrator traces the background outside
//!   those times and the drops inside them, each weighted by its share (Garg and Nayar 2007:
//!   a streak is `tau/T` of the drop's radiance plus `1 - tau/T` of the background's), so a
//!   drop is a continuous streak at any sample count ([`RainEstimator`]). A path that hit a drop tests
//!   that drop again to find its way out ([`RainPath`]); no other ray meets drops: they cast
//!   no shadow and are not seen in reflections (their extinction, 1e-3 to 3e-3 per metre, is
//!   the fog's domain). A BVH over the drops' swept boxes, tested by every ray, was 5-7 times
//!   slower than a dry render (docs/decisions/0034-rain-drops-seen-by-camera-rays.md).
//! - Glints: a smooth drop cannot show a point, spot or directional light by its reflection or
//!   refraction (a delta path never reaches a delta light), so where a path meets a drop from
//!   outside, the integrator adds next-event estimation of delta lights through the drop's
//!   pixel-averaged scattering, [`glint_phase`]: the geometric-optics intensity of a water
//!   sphere (external reflection and one refraction through it, van de Hulst 1957, ch. 12)
//!   over its disc (docs/decisions/0037-rain-drops-glint-in-delta-lights.md).

use crate::camera::{Camera, Projection};
use crate::geometry::Ray;
use crate::material::{GltfPbrParams, Material, Reflectance, Volume};
use crate::motion::Motion;
use crate::sampling::Pcg32;
use glam::{Affine3A, Vec2, Vec3};
use rayon::prelude::*;

/// Marshall-Palmer's intercept `N0`, drops per m^3 per mm of diameter.
pub const MP_N0: f64 = 8000.0;

/// The smallest drop diameter rendered, mm (see the module documentation).
pub const D_MIN_MM: f64 = 0.5;

/// The largest drop diameter rendered, mm (drops break up above it).
pub const D_MAX_MM: f64 = 6.0;

/// How far in front of the camera the drops start, metres.
pub const RAIN_NEAR: f32 = 0.5;

/// The margin around the view frustum the commands place drops in, metres: covers both eyes
/// of a rig whose baseline is up to a metre.
pub const RIG_MARGIN: f32 = 0.5;

/// The default `radius` of `extras.streaks.rain`, metres.
pub const DEFAULT_RADIUS: f32 = 20.0;

/// Index of refraction of water.
pub const WATER_IOR: f32 = 1.33;

/// The most drops one view may have (a rain rate and radius asking for more are an error, not
/// an out-of-memory abort): 20 million, about 0.8 GB with a camera's index.
pub const MAX_DROPS: usize = 20_000_000;

/// [`crate::geometry::SurfaceHit::triangle`] of a hit on a rain drop: no triangle of the
/// scene (and never an emitter's).
pub const RAIN_TRIANGLE: u32 = u32::MAX - 1;

/// The rain of a scene, as `extras.streaks.rain` gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RainParams {
    /// Rain rate, mm/h (above 0).
    pub rate_mm_h: f32,
    /// Seed of the drops' placement (0 by default).
    pub seed: u64,
    /// Drops are placed within this distance of the camera, metres (above 0).
    pub radius: f32,
}

impl RainParams {
    /// Checks the values; the key and the reason otherwise.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(self.rate_mm_h.is_finite() && self.rate_mm_h > 0.0 && self.rate_mm_h <= 500.0) {
            return Err((
                "rate_mm_h",
                format!(
                    "must be above 0 and at most 500 mm/h (got {})",
                    self.rate_mm_h
                ),
            ));
        }
        if !(self.radius.is_finite() && self.radius > RAIN_NEAR && self.radius <= 1000.0) {
            return Err((
                "radius",
                format!(
                    "must be above {RAIN_NEAR} m and at most 1000 m (got {})",
                    self.radius
                ),
            ));
        }
        Ok(())
    }

    /// Marshall-Palmer's slope `Lambda = 4.1 R^-0.21`, 1/mm.
    pub fn lambda(&self) -> f64 {
        mp_lambda(self.rate_mm_h as f64)
    }
}

/// Marshall-Palmer's slope `Lambda = 4.1 R^-0.21` for rain rate `rate` mm/h, 1/mm.
pub fn mp_lambda(rate: f64) -> f64 {
    4.1 * rate.powf(-0.21)
}

/// Drops per m^3 with diameters in `[D_MIN_MM, D_MAX_MM]` at rain rate `rate` mm/h:
/// `(N0 / Lambda) (exp(-Lambda D_min) - exp(-Lambda D_max))`.
pub fn number_density(rate: f64) -> f64 {
    let l = mp_lambda(rate);
    MP_N0 / l * ((-l * D_MIN_MM).exp() - (-l * D_MAX_MM).exp())
}

/// A diameter (mm) drawn from Marshall-Palmer's exponential truncated to
/// `[D_MIN_MM, D_MAX_MM]`, slope `lambda` (1/mm), by inverting its distribution function with
/// uniform `u` in `[0, 1)`.
#[inline]
pub fn sample_diameter(lambda: f64, u: f64) -> f64 {
    let span = 1.0 - (-lambda * (D_MAX_MM - D_MIN_MM)).exp();
    (D_MIN_MM - (1.0 - u * span).ln() / lambda).min(D_MAX_MM)
}

/// The density (per mm) of [`sample_diameter`]'s diameters.
pub fn diameter_pdf(lambda: f64, d: f64) -> f64 {
    if !(D_MIN_MM..=D_MAX_MM).contains(&d) {
        return 0.0;
    }
    let span = 1.0 - (-lambda * (D_MAX_MM - D_MIN_MM)).exp();
    lambda * (-lambda * (d - D_MIN_MM)).exp() / span
}

/// Terminal fall speed (m/s) of a drop of diameter `d_mm` mm at sea level: Atlas, Srivastava
/// and Sekhon's fit to Gunn and Kinzer, `9.65 - 10.3 exp(-0.6 D)`, clamped at 0.
#[inline]
pub fn terminal_speed(d_mm: f64) -> f64 {
    (9.65 - 10.3 * (-0.6 * d_mm).exp()).max(0.0)
}

/// The material of every drop: clear water, a smooth dielectric of index [`WATER_IOR`]
/// bounding a volume (so light refracts in and out), through the project's transmissive
/// glTF model.
pub fn water_material() -> Material {
    Material {
        reflectance: Reflectance::GltfPbr(GltfPbrParams {
            metallic: 0.0,
            roughness: 0.0,
            transmission: 1.0,
            ior: WATER_IOR,
            volume: Some(Volume::new(1.0, Vec3::ONE, f32::INFINITY)),
            ..GltfPbrParams::default()
        }),
        double_sided: true,
        ..Material::diffuse("rain drop (water)", Vec3::ZERO)
    }
}

/// One drop: its centre at time 0, its radius and its fall speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drop {
    /// Centre at the reference time 0, world space.
    pub centre: Vec3,
    /// Radius, metres.
    pub radius: f32,
    /// Fall speed (along -Y), m/s.
    pub speed: f32,
}

impl Drop {
    /// The centre at time `t`.
    #[inline]
    pub fn centre_at(&self, t: f32) -> Vec3 {
        Vec3::new(self.centre.x, self.centre.y - self.speed * t, self.centre.z)
    }

    /// The box `[min, max]` the drop sweeps over `[open, close]`.
    pub fn swept_box(&self, open: f32, close: f32) -> [Vec3; 2] {
        let (a, b) = (self.centre_at(open), self.centre_at(close));
        let r = Vec3::splat(self.radius);
        [a.min(b) - r, a.max(b) + r]
    }

    /// The nearest parameter in `(0, t_max)` where `ray` (at its time) meets the sphere, with
    /// the outward unit normal there; `None` if it does not. Computed about the centre so that
    /// it stays exact for a drop far from the origin.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec3)> {
        let c = self.centre_at(ray.time);
        let oc = ray.origin - c;
        let b = oc.dot(ray.direction);
        // r^2 - |oc - b d|^2: the squared half-chord, without the cancellation of b^2 - c.
        let f = oc - b * ray.direction;
        let r2 = self.radius * self.radius;
        let disc = r2 - f.dot(f);
        if disc < 0.0 {
            return None;
        }
        let half = disc.sqrt();
        let t = if -b - half > 0.0 {
            -b - half
        } else {
            -b + half
        };
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let n = (oc + t * ray.direction) / self.radius;
        Some((t, n.normalize_or(Vec3::Y)))
    }
}

/// The part of the shutter during which a drop covers a camera ray, from
/// [`Drop::swept_interval`] or [`CameraRain::swept`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweptHit {
    /// The drop.
    pub drop: Drop,
    /// When the drop starts to cover the ray, seconds (at least the shutter's opening).
    pub t0: f32,
    /// When it stops, seconds (at most the shutter's closing, above `t0`).
    pub t1: f32,
    /// Distance along the ray to the drop's centre at the middle of `[t0, t1]`, metres.
    pub depth: f32,
}

impl SweptHit {
    /// The share of the shutter `motion` during which the drop covers the ray,
    /// `(t1 - t0) / (close - open)`, in `(0, 1]`.
    #[inline]
    pub fn coverage(&self, motion: &Motion) -> f32 {
        ((self.t1 - self.t0) / (motion.close - motion.open)).clamp(0.0, 1.0)
    }

    /// The time in `[t0, t1)` for uniform `u` in `[0, 1)`.
    #[inline]
    pub fn time(&self, u: f32) -> f32 {
        self.t0 + u * (self.t1 - self.t0)
    }
}

impl Drop {
    /// The sub-interval of `motion`'s shutter during which this drop covers the camera ray
    /// that leaves `origin` (where the camera is at time 0; it moves at the rig's velocity)
    /// along unit `direction` (fixed: the camera keeps its orientation), with the depth of
    /// the drop's centre along the ray; `None` if the drop never covers it, or is behind the
    /// camera. In the camera's frame the ray stands still and the centre moves at the drop's
    /// velocity less the rig's, so its squared distance from the ray's line is a quadratic in
    /// time, below `radius^2` on one interval. Solved in f64: the perpendicular offset is a
    /// small difference of distances of tens of metres.
    #[inline]
    pub fn swept_interval(
        &self,
        origin: Vec3,
        direction: Vec3,
        motion: &Motion,
    ) -> Option<SweptHit> {
        let d = direction.as_dvec3();
        let q = (self.centre - origin).as_dvec3();
        let w = (Vec3::new(0.0, -self.speed, 0.0) - motion.rig_velocity).as_dvec3();
        let (qd, wd) = (q.dot(d), w.dot(d));
        let (qp, wp) = (q - qd * d, w - wd * d);
        let r = self.radius as f64;
        let (a, b, c) = (wp.dot(wp), qp.dot(wp), qp.dot(qp) - r * r);
        let (open, close) = (motion.open as f64, motion.close as f64);
        let (ta, tb) = if a <= 1e-12 * (b.abs() + c.abs()).max(1e-30) {
            // No motion across the ray: covered for the whole shutter or never.
            if c >= 0.0 {
                return None;
            }
            (open, close)
        } else {
            let disc = b * b - a * c;
            if disc <= 0.0 {
                return None;
            }
            let h = disc.sqrt();
            ((-b - h) / a, (-b + h) / a)
        };
        let (t0, t1) = (ta.max(open), tb.min(close));
        if t1 <= t0 {
            return None;
        }
        let depth = qd + wd * 0.5 * (t0 + t1);
        if depth <= r {
            return None;
        }
        Some(SweptHit {
            drop: *self,
            t0: t0 as f32,
            t1: (t1 as f32).max(t0 as f32),
            depth: depth as f32,
        })
    }
}

/// The most drops [`CameraRain::swept`] keeps for one camera ray (the nearest).
pub const MAX_SWEPT: usize = 16;

/// The drops that cover one camera ray during the shutter, each with its interval
/// ([`SweptHit`]): the [`MAX_SWEPT`] nearest, in no order. At a time in one or more
/// intervals the ray's first hit is the nearest of those drops; at any other time it meets
/// no drop. Fixed-size (no allocation per ray).
#[derive(Clone, Copy, Debug)]
pub struct SweptSet {
    /// The drops; the first `len` are valid.
    hits: [SweptHit; MAX_SWEPT],
    /// How many are valid.
    len: usize,
    /// How many more drops covered the ray than were kept (the farthest are left out).
    pub left_out: u32,
}

impl Default for SweptSet {
    fn default() -> Self {
        let none = SweptHit {
            drop: Drop {
                centre: Vec3::ZERO,
                radius: 0.0,
                speed: 0.0,
            },
            t0: 0.0,
            t1: 0.0,
            depth: f32::INFINITY,
        };
        SweptSet {
            hits: [none; MAX_SWEPT],
            len: 0,
            left_out: 0,
        }
    }
}

impl SweptSet {
    /// The drops.
    #[inline]
    pub fn hits(&self) -> &[SweptHit] {
        &self.hits[..self.len]
    }

    /// Whether no drop covers the ray.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds `hit`, keeping the [`MAX_SWEPT`] nearest.
    #[inline]
    pub fn push(&mut self, hit: SweptHit) {
        if self.len < MAX_SWEPT {
            self.hits[self.len] = hit;
            self.len += 1;
            return;
        }
        self.left_out += 1;
        let far = (0..MAX_SWEPT)
            .max_by(|&a, &b| self.hits[a].depth.total_cmp(&self.hits[b].depth))
            .unwrap_or(0);
        if hit.depth < self.hits[far].depth {
            self.hits[far] = hit;
        }
    }

    /// Keeps the drops nearer than `depth` (those in front of the scene's surface).
    #[inline]
    pub fn retain_nearer(&mut self, depth: f32) {
        let mut kept = 0;
        for i in 0..self.len {
            if self.hits[i].depth < depth {
                self.hits[kept] = self.hits[i];
                kept += 1;
            }
        }
        self.len = kept;
    }

    /// The sum of the drops' interval lengths, seconds (their union counted with overlaps).
    #[inline]
    pub fn total(&self) -> f32 {
        self.hits().iter().map(|h| h.t1 - h.t0).sum()
    }

    /// The intervals merged where they overlap, sorted: the times at which some drop covers
    /// the ray; returns them and their number.
    #[inline]
    fn merged(&self) -> ([(f32, f32); MAX_SWEPT], usize) {
        let mut iv = [(0.0f32, 0.0f32); MAX_SWEPT];
        for (slot, h) in iv.iter_mut().zip(self.hits()) {
            *slot = (h.t0, h.t1);
        }
        let n = self.len;
        iv[..n].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut m = 0;
        for i in 0..n {
            if m > 0 && iv[i].0 <= iv[m - 1].1 {
                iv[m - 1].1 = iv[m - 1].1.max(iv[i].1);
            } else {
                iv[m] = iv[i];
                m += 1;
            }
        }
        (iv, m)
    }

    /// The share of `motion`'s shutter during which some drop covers the ray (the union of
    /// the intervals), in `[0, 1]`.
    #[inline]
    pub fn coverage(&self, motion: &Motion) -> f32 {
        let (iv, m) = self.merged();
        let covered: f32 = iv[..m].iter().map(|(a, b)| b - a).sum();
        (covered / (motion.close - motion.open)).clamp(0.0, 1.0)
    }

    /// How many of the intervals contain time `t`.
    #[inline]
    pub fn covering(&self, t: f32) -> u32 {
        self.hits()
            .iter()
            .map(|h| u32::from(h.t0 <= t && t <= h.t1))
            .sum()
    }

    /// A time uniform over the union of the intervals counted with overlaps (a drop chosen
    /// with probability proportional to its interval's length, then a time uniform in it),
    /// from one uniform `u` in `[0, 1)`; `None` if the set is empty.
    #[inline]
    pub fn sample_time(&self, u: f32) -> Option<f32> {
        let mut rest = u * self.total();
        for h in self.hits() {
            let len = h.t1 - h.t0;
            if rest < len {
                return Some(h.t0 + rest);
            }
            rest -= len;
        }
        self.hits().last().map(|h| h.t1)
    }

    /// The time of `motion`'s shutter at which no drop covers the ray, uniform over those
    /// times, for uniform `u` in `[0, 1)` (`motion.time(u)` for an empty set).
    #[inline]
    pub fn time_outside(&self, u: f32, motion: &Motion) -> f32 {
        let (iv, m) = self.merged();
        let covered: f32 = iv[..m].iter().map(|(a, b)| b - a).sum();
        let free = (motion.close - motion.open - covered).max(0.0);
        let mut rest = u * free;
        let mut start = motion.open;
        for &(a, b) in &iv[..m] {
            let gap = (a - start).max(0.0);
            if rest < gap {
                return start + rest;
            }
            rest -= gap;
            start = start.max(b);
        }
        (start + rest).min(motion.close)
    }
}

/// What the drops are placed around: a perspective camera's frustum and the shutter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RainView {
    /// The camera's pose (rigid, camera looking along its -Z).
    pub world_from_camera: Affine3A,
    /// `tan` of half the horizontal and vertical fields of view.
    pub tan_half: Vec2,
    /// Metres the frustum is widened by on every side (the rig, beyond the one camera).
    pub margin: f32,
    /// The shutter and the rig's motion.
    pub motion: Motion,
}

impl RainView {
    /// The view of a `width` x `height` image of a perspective `camera` with the shutter of
    /// `motion`, widened by `margin` metres; `None` for an orthographic camera.
    pub fn of_camera(
        camera: &Camera,
        width: u32,
        height: u32,
        motion: Motion,
        margin: f32,
    ) -> Option<Self> {
        let Projection::Perspective { yfov, .. } = camera.projection else {
            return None;
        };
        let ty = (0.5 * yfov).tan();
        Some(RainView {
            world_from_camera: camera.world_from_camera,
            tan_half: Vec2::new(ty * width as f32 / height.max(1) as f32, ty),
            margin,
            motion,
        })
    }
}

/// A scene's drops, placed for one view (sorted along a Morton curve of their centres).
#[derive(Debug, Default)]
pub struct DropField {
    /// The drops.
    pub drops: Vec<Drop>,
}

/// Why drops could not be placed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RainError {
    /// The view is orthographic.
    #[error("rain needs a perspective camera (drops are placed in its view frustum)")]
    Orthographic,
    /// Too many drops.
    #[error(
        "{rate} mm/h within {radius} m makes about {count} drops, more than {MAX_DROPS}: \
         lower the radius"
    )]
    TooMany {
        /// The rain rate, mm/h.
        rate: f32,
        /// The radius, metres.
        radius: f32,
        /// The expected number of drops.
        count: u64,
    },
}

/// Depth slabs the frustum is filled in (each a box of candidates, rejected outside).
const SLABS: usize = 64;

impl DropField {
    /// Places the drops of `params` in `view`'s region (see the module documentation),
    /// seeded by `params.seed` alone, and builds their BVH over the shutter.
    pub fn place(params: &RainParams, view: &RainView) -> Result<DropField, RainError> {
        let density = number_density(params.rate_mm_h as f64);
        let lambda = params.lambda();
        let motion = view.motion;
        let drift = motion.max_abs_time()
            * (terminal_speed(D_MAX_MM) as f32 + motion.rig_velocity.length());
        let margin = view.margin + drift;
        let (near, far) = (RAIN_NEAR, params.radius);
        let half = |z: f32| view.tan_half * z + Vec2::splat(margin);
        // The candidates' boxes: slab k covers depths [z0, z1] and the frustum's cross-section
        // at z1 (the widest in the slab).
        let slab = |k: usize| {
            let z0 = near + (far - near) * k as f32 / SLABS as f32;
            let z1 = near + (far - near) * (k + 1) as f32 / SLABS as f32;
            (z0, z1, half(z1))
        };
        let expected: f64 = (0..SLABS)
            .map(|k| {
                let (z0, z1, h) = slab(k);
                density * (4.0 * h.x * h.y * (z1 - z0)) as f64
            })
            .sum();
        if expected > 2.0 * MAX_DROPS as f64 {
            return Err(RainError::TooMany {
                rate: params.rate_mm_h,
                radius: params.radius,
                count: expected as u64,
            });
        }
        let mut rng = Pcg32::new(params.seed, 0x7261_696e);
        let mut drops = Vec::new();
        for k in 0..SLABS {
            let (z0, z1, h) = slab(k);
            let mean = density * (4.0 * h.x * h.y * (z1 - z0)) as f64;
            // The mean count, rounded up or down at random so that it is right on average.
            let count = (mean + rng.next_f32() as f64).floor() as usize;
            for _ in 0..count {
                let [ux, uy] = rng.next_2d().to_array();
                let (uz, ud) = (rng.next_f32(), rng.next_f32());
                let z = z0 + (z1 - z0) * uz;
                let p = Vec2::new((2.0 * ux - 1.0) * h.x, (2.0 * uy - 1.0) * h.y);
                let inside =
                    p.abs().cmple(half(z)).all() && Vec3::new(p.x, p.y, z).length() <= far + margin;
                if !inside {
                    continue;
                }
                let d_mm = sample_diameter(lambda, ud as f64);
                drops.push(Drop {
                    centre: view
                        .world_from_camera
                        .transform_point3(Vec3::new(p.x, p.y, -z)),
                    radius: (0.5e-3 * d_mm) as f32,
                    speed: terminal_speed(d_mm) as f32,
                });
            }
        }
        if drops.len() > MAX_DROPS {
            return Err(RainError::TooMany {
                rate: params.rate_mm_h,
                radius: params.radius,
                count: drops.len() as u64,
            });
        }
        sort_spatially(&mut drops);
        Ok(DropField { drops })
    }

    /// The number of drops.
    pub fn len(&self) -> usize {
        self.drops.len()
    }

    /// Whether there are no drops.
    pub fn is_empty(&self) -> bool {
        self.drops.is_empty()
    }
}

/// Sorts `drops` along a Morton (Z-order) curve of their centres, so that drops near each
/// other in space are near each other in memory: the BVH's leaves then read neighbouring
/// drops, which matters with millions of them.
fn sort_spatially(drops: &mut [Drop]) {
    let Some([lo, hi]) = drops
        .iter()
        .map(|d| [d.centre, d.centre])
        .reduce(|[a, b], [c, d]| [a.min(c), b.max(d)])
    else {
        return;
    };
    let scale = 1023.0 / (hi - lo).max_element().max(1e-6);
    let key = |d: &Drop| {
        let q = ((d.centre - lo) * scale)
            .as_uvec3()
            .min(glam::UVec3::splat(1023));
        spread(q.x) | (spread(q.y) << 1) | (spread(q.z) << 2)
    };
    drops.sort_by_cached_key(key);
}

/// The bits of a 10-bit `v` spread to every third bit.
fn spread(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    (x | (x << 2)) & 0x0924_9249
}

/// A camera's view of the drops: for each bin of [`BIN`] x [`BIN`] pixels, a copy of every
/// drop whose sphere, moving over the shutter relative to the moving camera, projects into
/// it. A camera ray reads the drops of its own bin only (tens, not millions), in memory order.
/// Built by [`crate::integrator::render`] for the camera it renders.
#[derive(Debug)]
pub struct CameraRain {
    /// World to camera rotation.
    camera_from_world: glam::Mat3,
    /// Focal length in pixels.
    focal: f32,
    /// Image size in pixels.
    size: Vec2,
    /// Bins across and down.
    bins: (u32, u32),
    /// Where each bin's drops start in `drops` (one more entry than bins).
    starts: Vec<u32>,
    /// The bins' drops, bin after bin.
    drops: Vec<Drop>,
    /// The shutter and the rig's motion the index covers.
    motion: Motion,
}

/// The side of a [`CameraRain`] bin, pixels.
pub const BIN: u32 = 1;

impl CameraRain {
    /// The index of `field` as the perspective `camera` sees it in a `width` x `height` image
    /// over the shutter of `motion` (the camera moving at the rig's velocity); `None` for an
    /// orthographic camera or without drops.
    pub fn build(
        field: &DropField,
        camera: &Camera,
        width: u32,
        height: u32,
        motion: &Motion,
    ) -> Option<CameraRain> {
        let Projection::Perspective { yfov, .. } = camera.projection else {
            return None;
        };
        if field.is_empty() || width == 0 || height == 0 {
            return None;
        }
        let focal = 0.5 * height as f32 / (0.5 * yfov).tan();
        let camera_from_world = glam::Mat3::from(camera.world_from_camera.matrix3).transpose();
        let eye = camera.position();
        let size = Vec2::new(width as f32, height as f32);
        let bins = (width.div_ceil(BIN), height.div_ceil(BIN));
        // The bins a drop covers: the box of its sphere's projections at the shutter's two
        // ends, each seen from where the camera is then.
        let cover = |d: &Drop| -> [u32; 4] {
            const NONE: [u32; 4] = [u32::MAX; 4];
            let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
            for t in [motion.open, motion.close] {
                let c = camera_from_world * (d.centre_at(t) - eye - motion.rig_velocity * t);
                let (z, r) = (-c.z, d.radius);
                if z - r <= 1e-4 {
                    return NONE;
                }
                // The sphere lies in the box c +- r; over that box x / z is largest at the
                // near face when x + r > 0 and at the far face otherwise (likewise the least).
                let extreme = |v: f32, near_if_positive: bool| {
                    v / if (v > 0.0) == near_if_positive {
                        z - r
                    } else {
                        z + r
                    }
                };
                let (x0, x1) = (extreme(c.x - r, false), extreme(c.x + r, true));
                let (y0, y1) = (extreme(c.y - r, false), extreme(c.y + r, true));
                lo = lo.min(Vec2::new(
                    0.5 * size.x + focal * x0,
                    0.5 * size.y - focal * y1,
                ));
                hi = hi.max(Vec2::new(
                    0.5 * size.x + focal * x1,
                    0.5 * size.y - focal * y0,
                ));
            }
            if hi.x < 0.0 || hi.y < 0.0 || lo.x >= size.x || lo.y >= size.y {
                return NONE;
            }
            let b = BIN as f32;
            let (x0, y0) = ((lo.x / b).max(0.0) as u32, (lo.y / b).max(0.0) as u32);
            let x1 = ((hi.x / b) as u32).min(bins.0 - 1);
            let y1 = ((hi.y / b) as u32).min(bins.1 - 1);
            [x0, y0, x1, y1]
        };
        let covers: Vec<[u32; 4]> = field.drops.par_iter().map(cover).collect();
        let bin_count = (bins.0 * bins.1) as usize;
        let mut starts = vec![0u32; bin_count + 1];
        for &[x0, y0, x1, y1] in covers.iter().filter(|c| c[0] != u32::MAX) {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    starts[(y * bins.0 + x) as usize + 1] += 1;
                }
            }
        }
        for i in 0..bin_count {
            starts[i + 1] += starts[i];
        }
        let mut fill = starts.clone();
        let placeholder = Drop {
            centre: Vec3::ZERO,
            radius: 0.0,
            speed: 0.0,
        };
        let mut drops = vec![placeholder; starts[bin_count] as usize];
        for (d, &[x0, y0, x1, y1]) in field.drops.iter().zip(&covers) {
            if x0 == u32::MAX {
                continue;
            }
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let slot = &mut fill[(y * bins.0 + x) as usize];
                    drops[*slot as usize] = *d;
                    *slot += 1;
                }
            }
        }
        Some(CameraRain {
            camera_from_world,
            focal,
            size,
            bins,
            starts,
            drops,
            motion: *motion,
        })
    }

    /// How many drop copies the bins hold.
    pub fn entries(&self) -> usize {
        self.drops.len()
    }

    /// The drops of the bin the camera ray along `direction` falls in (none outside the
    /// image or behind the camera).
    #[inline]
    fn bin_drops(&self, direction: Vec3) -> &[Drop] {
        let d = self.camera_from_world * direction;
        if d.z >= 0.0 {
            return &[];
        }
        let film = Vec2::new(
            0.5 * self.size.x + self.focal * d.x / -d.z,
            0.5 * self.size.y - self.focal * d.y / -d.z,
        );
        if !(film.x >= 0.0 && film.y >= 0.0 && film.x < self.size.x && film.y < self.size.y) {
            return &[];
        }
        let (x, y) = (
            (film.x as u32 / BIN).min(self.bins.0 - 1),
            (film.y as u32 / BIN).min(self.bins.1 - 1),
        );
        let bin = (y * self.bins.0 + x) as usize;
        &self.drops[self.starts[bin] as usize..self.starts[bin + 1] as usize]
    }

    /// The drops that cover the camera ray from `origin` (where the camera is at time 0)
    /// along `direction` at some time of the shutter the index was built for
    /// ([`Drop::swept_interval`]): the [`MAX_SWEPT`] nearest.
    #[inline]
    pub fn swept(&self, origin: Vec3, direction: Vec3) -> SweptSet {
        let mut set = SweptSet::default();
        for drop in self.bin_drops(direction) {
            if let Some(hit) = drop.swept_interval(origin, direction, &self.motion) {
                set.push(hit);
            }
        }
        set
    }

    /// The nearest drop the camera ray `ray` (from the camera, at its time) meets before
    /// `t_max`: the parameter, the drop and its outward normal there.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Drop, Vec3)> {
        let mut best: Option<(f32, Drop, Vec3)> = None;
        let mut end = t_max;
        for drop in self.bin_drops(ray.direction) {
            if let Some((t, n)) = drop.intersect(ray, end) {
                end = t;
                best = Some((t, *drop, n));
            }
        }
        best
    }
}

/// Which drops the next ray of a path can meet: a camera ray those of its camera's
/// [`CameraRain`], a ray leaving a drop hit that drop (its way out, or nothing for a ray
/// leaving its outside), any other ray none (see the module documentation).
#[derive(Clone, Copy, Debug, Default)]
pub struct RainPath<'a> {
    /// The camera's index, for the camera ray (taken by the first query).
    pub camera: Option<&'a CameraRain>,
    /// The drop the previous ray hit.
    pub drop: Option<Drop>,
}

impl<'a> RainPath<'a> {
    /// The state of a camera path of a camera whose drops are `camera` (`None`: no rain).
    pub fn camera(camera: Option<&'a CameraRain>) -> Self {
        RainPath { camera, drop: None }
    }

    /// The state of a camera path that meets `drop` and no other (the drop path of the
    /// swept-drop estimator, [`CameraRain::swept`]).
    pub fn only(drop: Drop) -> Self {
        RainPath {
            camera: None,
            drop: Some(drop),
        }
    }

    /// The nearest drop the path's next ray meets before `t_max`, and the state for the ray
    /// after it.
    #[inline]
    pub fn intersect(&mut self, ray: &Ray, t_max: f32) -> Option<(f32, Drop, Vec3)> {
        let found = if let Some(camera) = self.camera.take() {
            camera.intersect(ray, t_max)
        } else if let Some(drop) = self.drop {
            drop.intersect(ray, t_max).map(|(t, n)| (t, drop, n))
        } else {
            None
        };
        self.drop = found.map(|f| f.1);
        found
    }
}

/// A scene's rain: its parameters, the index of the drops' material in the scene's materials,
/// and the drops placed for the view being rendered (none until
/// [`crate::scene::Scene::place_rain`]).
#[derive(Debug)]
pub struct Rain {
    /// What the scene asks for.
    pub params: RainParams,
    /// The drops' material ([`water_material`]) in the scene's materials.
    pub material: u32,
    /// The drops of the current view.
    pub field: DropField,
    /// How a camera sample meets the drops under an open shutter.
    pub estimator: RainEstimator,
}

/// How a camera sample under an open shutter meets the drops.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RainEstimator {
    /// The time integral per camera ray, split on the nearest drop that covers it during
    /// the shutter ([`CameraRain::swept`]): the background path with weight `1 - f` and the
    /// drop's path at a time in its interval with weight `f`, `f` the share of the shutter
    /// the drop covers the ray. A drop shows as a continuous streak at any sample count.
    #[default]
    Swept,
    /// Each sample sees the drops where they are at its one time. Unbiased too, but a drop
    /// covers a pixel for a few percent of the shutter, so at tens of samples its streak is
    /// a few bright specks; kept as the reference the swept estimator is tested against.
    TimeSampled,
}

/// A point offset off a drop's surface to the side of `w`, for a ray leaving it: a few
/// units in the last place of the position (whatever the drop's size, unlike the triangles'
/// integer offset, which can exceed a small drop's radius far from the origin).
#[inline]
pub fn offset_from_drop(p: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let side = if n.dot(w) < 0.0 { -n } else { n };
    let eps = 8.0 * f32::EPSILON * p.abs().max_element().max(1.0);
    p + eps * side
}

/// The unpolarised Fresnel reflectance of water seen from air (index [`WATER_IOR`]) at an
/// angle of incidence of cosine `cos_i`: the exact mean of the s and p reflectances, 1 at
/// grazing. (The drops' BSDF uses Schlick's approximation; the glint's phase function below
/// takes the exact value, which its energy tests check against.)
#[inline]
fn water_fresnel(cos_i: f64) -> f64 {
    let n = f64::from(WATER_IOR);
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t = (1.0 - cos_i * cos_i).max(0.0).sqrt() / n;
    let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
    let rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    let rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The deflection `2 (i - r)` of a ray entering a water sphere at incidence angle `i` and
/// leaving it after one refraction in and one out (`sin i = n sin r`), with its derivative in `i`.
#[inline]
fn refraction_deflection(i: f64) -> (f64, f64) {
    let n = f64::from(WATER_IOR);
    let r = (i.sin() / n).asin();
    (2.0 * (i - r), 2.0 - 2.0 * i.cos() / (n * r.cos()))
}

/// A sub-pixel water drop's *pixel-averaged* scattering of a collimated beam, per steradian:
/// lit with irradiance `E` at normal incidence, the drop's radiance averaged over its
/// projected disc toward a viewer at scattering angle `theta` (`cos_theta` = the light's
/// propagation direction dotted with the direction to the viewer) is `E * glint_phase(cos_theta)`.
///
/// Geometric optics of a sphere (van de Hulst, "Light scattering by small particles", 1957,
/// ch. 12): the intensity of the ray class `p` is `E a^2 |sin i cos i / (sin theta dtheta/di)|`
/// times its Fresnel factor, and dividing by the disc area `pi a^2` gives the average radiance.
/// Two classes: `p = 0`, external reflection (`i = (pi - theta) / 2`, `F(i) / (4 pi)`), and
/// `p = 1`, refraction in and out (`theta = 2 (i - r)`, factor `(1 - F(i))^2`, zero beyond
/// the grazing deflection of about 82.5 degrees). Unpolarised, no absorption, no higher
/// classes (`p = 2` makes the rainbow) and no diffraction. Integrated over the sphere it gives
/// the disc averages of `F` and `(1 - F)^2` (tested). A path that hits a drop adds this for
/// delta lights, which its refracted continuation cannot reach: as the hit point is uniform
/// over the drop's disc in the pixel, its expectation is the pixel average.
pub fn glint_phase(cos_theta: f32) -> f32 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let c = f64::from(cos_theta).clamp(-1.0, 1.0);
    // p = 0: cos i = cos((pi - theta) / 2) = sin(theta / 2).
    let p0 = water_fresnel(((1.0 - c) * 0.5).sqrt()) / (4.0 * PI);
    let theta = c.acos();
    let (theta_max, _) = refraction_deflection(FRAC_PI_2);
    let p1 = if theta >= theta_max {
        0.0
    } else if theta < 1e-6 {
        // The limit sin i / sin theta -> 1 / (dtheta/di at 0) = 1 / (2 (1 - 1/n)).
        let t = 1.0 - water_fresnel(1.0);
        let k = 1.0 - 1.0 / f64::from(WATER_IOR);
        t * t / (4.0 * PI * k * k)
    } else {
        // theta(i) is increasing and convex with slope 2 (1 - 1/n) at 0, so the chord start
        // lies right of the root and Newton's steps fall monotonically onto it.
        let k = 1.0 - 1.0 / f64::from(WATER_IOR);
        let mut i = (theta / (2.0 * k)).min(FRAC_PI_2);
        for _ in 0..8 {
            let (t, dt) = refraction_deflection(i);
            i = (i - (t - theta) / dt).clamp(0.0, FRAC_PI_2);
        }
        let (_, dt) = refraction_deflection(i);
        let t = 1.0 - water_fresnel(i.cos());
        t * t * i.sin() * i.cos() / (PI * theta.sin() * dt.abs())
    };
    (p0 + p1) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{chi_square_2d, ChiSquareConfig};
    use std::f64::consts::PI as PI64;

    #[test]
    fn marshall_palmer_number_density_matches_the_closed_form_and_the_survey_figures() {
        for (rate, want) in [(1.0, 251.0), (5.0, 634.0), (25.0, 1352.0)] {
            let n = number_density(rate);
            // The 6 mm cap removes a negligible tail from the survey's D > 0.5 mm figures.
            assert!((n - want).abs() < 1.5, "{rate} mm/h: {n} drops/m^3");
            // Against a plain numerical integral of N0 exp(-Lambda D).
            let l = mp_lambda(rate);
            let steps = 200_000;
            let h = (D_MAX_MM - D_MIN_MM) / steps as f64;
            let numeric: f64 = (0..steps)
                .map(|i| MP_N0 * (-l * (D_MIN_MM + (i as f64 + 0.5) * h)).exp() * h)
                .sum();
            assert!((numeric - n).abs() < 1e-6 * n, "{numeric} vs {n}");
        }
    }

    #[test]
    fn drop_diameters_follow_marshall_palmer_chi_square() {
        for rate in [1.0f64, 5.0, 25.0, 150.0] {
            let l = mp_lambda(rate);
            let config = ChiSquareConfig {
                cells: (64, 1),
                num_tests: 4,
                ..ChiSquareConfig::default()
            };
            let report = chi_square_2d(
                &format!("Marshall-Palmer diameters at {rate} mm/h"),
                &config,
                (D_MIN_MM, D_MAX_MM),
                (0.0, 1.0),
                |rng| {
                    let d = sample_diameter(l, rng.next_f32() as f64);
                    Some((d, rng.next_f32() as f64))
                },
                |d, _| diameter_pdf(l, d),
            );
            assert!(report.passed, "{report}");
            assert!((report.pdf_integral - 1.0).abs() < 1e-3, "{report}");
        }
    }

    #[test]
    fn terminal_speeds_are_gunn_and_kinzers_within_three_percent() {
        // Gunn and Kinzer (1949), as commonly tabulated.
        for (d, v) in [
            (0.5, 2.06),
            (1.0, 4.03),
            (2.0, 6.49),
            (3.0, 8.06),
            (4.0, 8.83),
            (5.0, 9.09),
        ] {
            let fit = terminal_speed(d);
            assert!((fit - v).abs() < 0.03 * v, "{d} mm: {fit} vs {v}");
        }
        assert_eq!(terminal_speed(0.05), 0.0);
    }

    /// A plain sphere test at the ray's time: march the ray in fine steps to the first point
    /// inside, for comparison.
    fn brute_force(drop: &Drop, ray: &Ray) -> Option<f32> {
        let c = drop.centre_at(ray.time);
        let steps = 200_000;
        let end = ray.t_max.min(10.0);
        let inside = |t: f32| (ray.at(t) - c).length() < drop.radius;
        let start_inside = inside(1e-6);
        (1..=steps)
            .map(|i| end * i as f32 / steps as f32)
            .find(|&t| inside(t) != start_inside)
    }

    #[test]
    fn swept_coverage_matches_a_brute_force_average_over_the_shutter() {
        let mut rng = Pcg32::new(11, 3);
        let mut partial = 0;
        let rand3 = |rng: &mut Pcg32| {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE
        };
        for case in 0..400 {
            let motion = Motion {
                open: -0.02 * rng.next_f32(),
                close: 0.02 * rng.next_f32(),
                rig_velocity: if case % 2 == 0 {
                    Vec3::ZERO
                } else {
                    15.0 * rand3(&mut rng)
                },
            };
            let origin = 10.0 * rand3(&mut rng);
            let direction = rand3(&mut rng).normalize_or(Vec3::NEG_Z);
            let d_mm = sample_diameter(mp_lambda(10.0), rng.next_f32() as f64);
            let (radius, speed) = ((0.5e-3 * d_mm) as f32, terminal_speed(d_mm) as f32);
            // A drop whose path crosses the ray near a random time around the shutter.
            let w = Vec3::new(0.0, -speed, 0.0) - motion.rig_velocity;
            let crossing = motion.time(1.4 * rng.next_f32() - 0.2);
            let depth = 0.6 + 19.0 * rng.next_f32();
            let centre = origin + depth * direction + 0.9 * radius * rand3(&mut rng) - w * crossing;
            let drop = Drop {
                centre,
                radius,
                speed,
            };
            let swept = drop.swept_interval(origin, direction, &motion);
            let f = swept.map_or(0.0, |h| h.coverage(&motion));
            // The share of many stratified times at which the ray meets the drop.
            let steps = 20_000;
            let met = (0..steps)
                .filter(|&k| {
                    let t = motion.time((k as f32 + 0.5) / steps as f32);
                    let mut ray = Ray::new(origin + motion.rig_velocity * t, direction);
                    ray.time = t;
                    drop.intersect(&ray, f32::INFINITY).is_some()
                })
                .count();
            let brute = met as f32 / steps as f32;
            assert!(
                (f - brute).abs() < 1e-3,
                "case {case}: coverage {f}, brute force {brute}, {swept:?}"
            );
            partial += usize::from(f > 0.01 && f < 0.99);
            if let Some(h) = swept {
                assert!(motion.open <= h.t0 && h.t0 < h.t1 && h.t1 <= motion.close);
                assert!((h.depth - depth).abs() < 3.0 * radius + w.length() * 0.05);
            }
        }
        assert!(partial > 100, "only {partial} partly covered cases");
    }

    #[test]
    fn swept_set_times_follow_their_densities_chi_square() {
        let motion = Motion::centred(0.02, Vec3::ZERO);
        let mut set = SweptSet::default();
        // Overlapping, nested and separate intervals, pushed out of order.
        for (t0, t1, depth) in [
            (0.002, 0.006, 3.0),
            (-0.008, -0.004, 1.0),
            (-0.005, 0.001, 2.0),
            (-0.003, -0.002, 5.0),
            (0.0085, 0.01, 4.0),
        ] {
            set.push(SweptHit {
                drop: SweptSet::default().hits[0].drop,
                t0,
                t1,
                depth,
            });
        }
        let covered = 0.009 + 0.004 + 0.0015;
        assert!((set.coverage(&motion) - covered / 0.02).abs() < 1e-5);
        assert_eq!(set.covering(-0.0045), 2);
        assert_eq!(set.covering(-0.0025), 2);
        assert_eq!(set.covering(0.007), 0);
        let total = set.total();
        let free = 0.02 - covered;
        let config = ChiSquareConfig {
            cells: (80, 1),
            num_tests: 2,
            ..ChiSquareConfig::default()
        };
        let range = (motion.open as f64, motion.close as f64);
        let inside = chi_square_2d(
            "times over the drops' intervals",
            &config,
            range,
            (0.0, 1.0),
            |rng| {
                Some((
                    set.sample_time(rng.next_f32())? as f64,
                    rng.next_f32() as f64,
                ))
            },
            |t, _| set.covering(t as f32) as f64 / total as f64,
        );
        assert!(inside.passed, "{inside}");
        assert!((inside.pdf_integral - 1.0).abs() < 2e-2, "{inside}");
        let outside = chi_square_2d(
            "times outside the drops' intervals",
            &config,
            range,
            (0.0, 1.0),
            |rng| {
                let t = set.time_outside(rng.next_f32(), &motion);
                assert_eq!(set.covering(t), 0, "time {t} is covered");
                Some((t as f64, rng.next_f32() as f64))
            },
            |t, _| f64::from(u8::from(set.covering(t as f32) == 0)) / free as f64,
        );
        assert!(outside.passed, "{outside}");
        assert!((outside.pdf_integral - 1.0).abs() < 2e-2, "{outside}");
        // Keeping the nearest: a full set drops its farthest for a nearer drop.
        let mut full = SweptSet::default();
        for k in 0..MAX_SWEPT + 3 {
            let mut h = set.hits()[0];
            h.depth = (MAX_SWEPT + 3 - k) as f32;
            full.push(h);
        }
        assert_eq!(full.left_out, 3);
        assert!(full.hits().iter().all(|h| h.depth <= MAX_SWEPT as f32));
    }

    #[test]
    fn swept_sets_of_a_street_view_rarely_fill_up() {
        // The shipped street's camera (45 degree yfov, 16:9) at 320x180, rain to 20 m.
        let camera = Camera::perspective("c", Affine3A::IDENTITY, 45f32.to_radians(), None);
        let (w, h) = (320u32, 180u32);
        for (rate, shutter) in [(1.0, 1.0 / 60.0), (25.0, 1.0 / 60.0), (25.0, 1.0 / 30.0)] {
            let motion = Motion::centred(shutter, Vec3::ZERO);
            let params = RainParams {
                rate_mm_h: rate,
                seed: 1,
                radius: DEFAULT_RADIUS,
            };
            let view = RainView::of_camera(&camera, w, h, motion, RIG_MARGIN).unwrap();
            let field = DropField::place(&params, &view).unwrap();
            let index = CameraRain::build(&field, &camera, w, h, &motion).unwrap();
            let (mut met, mut overlapped, mut full, mut covered) = (0, 0, 0, 0.0f64);
            let rays = w * h;
            for y in 0..h {
                for x in 0..w {
                    let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let ray = camera.generate_ray(film, w, h);
                    let set = index.swept(ray.origin, ray.direction);
                    met += u32::from(!set.is_empty());
                    let f = set.coverage(&motion);
                    covered += f as f64;
                    overlapped += u32::from(set.total() / shutter > f + 1e-6);
                    full += u32::from(set.left_out > 0);
                }
            }
            let share = |n: u32| n as f64 / rays as f64;
            eprintln!(
                "{rate} mm/h, 1/{:.0} s: {:.1} % of camera rays meet a swept drop, {:.2} % two \
                 at once, {:.4} % more than {MAX_SWEPT}; mean coverage {:.4}",
                1.0 / shutter,
                100.0 * share(met),
                100.0 * share(overlapped),
                100.0 * share(full),
                covered / rays as f64
            );
            assert!(share(full) < 1e-3, "{rate} mm/h: {full} rays fill the set");
        }
    }

    #[test]
    fn moving_sphere_intersection_agrees_with_brute_force_at_random_times() {
        let mut rng = Pcg32::new(7, 1);
        let mut hits = 0;
        for _ in 0..300 {
            let drop = Drop {
                centre: Vec3::new(2.0, 1.5, -3.0),
                radius: 0.05 + 0.2 * rng.next_f32(),
                speed: 9.0 * rng.next_f32(),
            };
            let time = 0.1 * (rng.next_f32() - 0.5);
            let target = drop.centre_at(time)
                + 0.35 * (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5);
            let origin = Vec3::new(0.0, 1.0, 0.0);
            let mut ray = Ray::new(origin, (target - origin).normalize());
            ray.time = time;
            let exact = drop.intersect(&ray, f32::INFINITY).map(|(t, _)| t);
            let brute = brute_force(&drop, &ray);
            match (exact, brute) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert!((a - b).abs() < 2e-4, "{a} vs {b}");
                    let (_, n) = drop.intersect(&ray, f32::INFINITY).unwrap();
                    let p = ray.at(a);
                    assert!((p - drop.centre_at(time) - n * drop.radius).length() < 1e-4);
                }
                (None, None) => {}
                // A grazing ray may touch the sphere between two steps of the march.
                (a, b) => {
                    let c = drop.centre_at(time);
                    let t = (c - origin).dot(ray.direction);
                    let miss = (ray.at(t) - c).length() - drop.radius;
                    assert!(miss.abs() < 1e-3, "{a:?} vs {b:?}, miss {miss}");
                }
            }
        }
        assert!(hits > 100, "only {hits} hits");
        // From inside (a ray leaving through the far side) the far root is taken.
        let drop = Drop {
            centre: Vec3::ZERO,
            radius: 1.0,
            speed: 0.0,
        };
        let (t, n) = drop.intersect(&Ray::new(Vec3::ZERO, Vec3::X), 5.0).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (n - Vec3::X).length() < 1e-6);
    }

    fn view() -> RainView {
        let camera = Camera::perspective(
            "c",
            Affine3A::from_translation(Vec3::new(0.0, 1.4, 0.0)),
            0.8,
            None,
        );
        RainView::of_camera(
            &camera,
            300,
            200,
            Motion::centred(1.0 / 60.0, Vec3::ZERO),
            0.5,
        )
        .unwrap()
    }

    #[test]
    fn placement_is_seeded_by_the_rain_alone_and_has_the_density() {
        let params = RainParams {
            rate_mm_h: 5.0,
            seed: 3,
            radius: 6.0,
        };
        let a = DropField::place(&params, &view()).unwrap();
        let b = DropField::place(&params, &view()).unwrap();
        assert_eq!(a.drops, b.drops);
        let other = DropField::place(&RainParams { seed: 4, ..params }, &view()).unwrap();
        assert_ne!(a.drops, other.drops);
        // Count the drops in a box well inside the region: density times volume.
        let v = view();
        let inv = v.world_from_camera.inverse();
        let in_box = a
            .drops
            .iter()
            .filter(|d| {
                let p = inv.transform_point3(d.centre);
                p.x.abs() < 0.5 && p.y.abs() < 0.5 && (-p.z) > 2.0 && (-p.z) < 5.0
            })
            .count() as f64;
        let want = number_density(5.0) * 3.0;
        assert!(
            (in_box - want).abs() < 4.0 * want.sqrt(),
            "{in_box} drops, {want} expected"
        );
        for d in &a.drops {
            let p = inv.transform_point3(d.centre);
            assert!(-p.z >= RAIN_NEAR && p.length() < 6.0 + 0.5 + 0.2);
            let dm = 2e3 * d.radius as f64;
            assert!((D_MIN_MM - 1e-4..=D_MAX_MM + 1e-4).contains(&dm));
        }
    }

    /// The nearest drop along `ray` by testing every drop of the field.
    fn every_drop(field: &DropField, ray: &Ray, t_max: f32) -> Option<(f32, Drop)> {
        let mut best: Option<(f32, Drop)> = None;
        for d in &field.drops {
            if let Some((t, _)) = d.intersect(ray, best.map_or(t_max, |b| b.0)) {
                best = Some((t, *d));
            }
        }
        best
    }

    #[test]
    fn the_camera_index_finds_what_testing_every_drop_finds() {
        let params = RainParams {
            rate_mm_h: 25.0,
            seed: 1,
            radius: 4.0,
        };
        let camera = Camera::perspective(
            "c",
            Affine3A::from_rotation_translation(
                glam::Quat::from_rotation_y(0.4),
                Vec3::new(1.0, 1.4, -2.0),
            ),
            0.8,
            None,
        );
        let (w, h) = (120, 80);
        // A shutter with the rig driving sideways and forward.
        let motion = Motion::centred(1.0 / 30.0, Vec3::new(3.0, 0.0, -8.0));
        let view = RainView::of_camera(&camera, w, h, motion, RIG_MARGIN).unwrap();
        let field = DropField::place(&params, &view).unwrap();
        assert!(field.len() > 1000, "{}", field.len());
        let index = CameraRain::build(&field, &camera, w, h, &motion).unwrap();
        let mut rng = Pcg32::new(5, 5);
        let (mut hits, mut aimed_hits) = (0, 0);
        for k in 0..40_000 {
            let time = motion.time(rng.next_f32());
            // Random rays, and rays aimed at a drop's centre at the ray's time.
            let film = if k % 2 == 0 {
                Vec2::new(w as f32 * rng.next_f32(), h as f32 * rng.next_f32())
            } else {
                let d = field.drops[(rng.next_u32() as usize) % field.len()];
                let eye = camera.position() + motion.rig_velocity * time;
                match camera.project(d.centre_at(time) - motion.rig_velocity * time, w, h) {
                    Some(p) if p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32 => {
                        let _ = eye;
                        p
                    }
                    _ => continue,
                }
            };
            let mut ray = camera.generate_ray(film, w, h);
            ray.origin += motion.rig_velocity * time;
            ray.time = time;
            let want = every_drop(&field, &ray, 50.0);
            let got = index.intersect(&ray, 50.0);
            assert_eq!(want.map(|w| w.1), got.map(|g| g.1), "ray {k}");
            if let (Some(a), Some(b)) = (want, got) {
                assert_eq!(a.0, b.0);
                hits += 1;
                aimed_hits += k % 2;
            }
        }
        assert!(
            hits > 500 && aimed_hits > 300,
            "{hits} hits, {aimed_hits} aimed"
        );
    }

    #[test]
    fn a_path_meets_the_drop_it_entered_on_its_way_out() {
        let drop = Drop {
            centre: Vec3::new(0.0, 0.0, -2.0),
            radius: 1e-3,
            speed: 4.0,
        };
        let field = DropField { drops: vec![drop] };
        let camera = Camera::perspective("c", Affine3A::IDENTITY, 0.5, None);
        let index = CameraRain::build(&field, &camera, 64, 64, &Motion::default()).unwrap();
        let mut path = RainPath::camera(Some(&index));
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        let (t, d, n) = path.intersect(&ray, f32::INFINITY).unwrap();
        assert!((t - (2.0 - 1e-3)).abs() < 1e-5 && d == drop && n.z > 0.99);
        // Refracted in: the next ray starts just inside and leaves through the far side.
        let p = ray.at(t);
        let inside = Ray::new(offset_from_drop(p, n, -Vec3::Z), -Vec3::Z);
        let (t2, _, n2) = path.intersect(&inside, f32::INFINITY).unwrap();
        assert!((t2 - 2e-3).abs() < 1e-4 && n2.z < -0.99, "{t2} {n2}");
        // Leaving outward: nothing more to meet, and after a miss no drop at all.
        let out = Ray::new(offset_from_drop(inside.at(t2), n2, -Vec3::Z), -Vec3::Z);
        assert!(path.intersect(&out, f32::INFINITY).is_none());
        assert!(path.intersect(&ray, f32::INFINITY).is_none());
    }

    /// `int_0^hi f(x) dx` by the midpoint rule on `steps` intervals.
    fn midpoint(hi: f64, steps: u32, f: impl Fn(f64) -> f64) -> f64 {
        let dx = hi / f64::from(steps);
        (0..steps).map(|k| f((f64::from(k) + 0.5) * dx) * dx).sum()
    }

    /// The disc average `int_0^{pi/2} g(i) 2 sin i cos i di` of `g` of the incidence angle.
    fn disc_average(g: impl Fn(f64) -> f64) -> f64 {
        midpoint(std::f64::consts::FRAC_PI_2, 200_000, |i| {
            g(i) * 2.0 * i.sin() * i.cos()
        })
    }

    /// `int f(cos theta) d omega` over the sphere of directions.
    fn sphere_integral(f: impl Fn(f32) -> f64) -> f64 {
        midpoint(PI64, 400_000, |t| f(t.cos() as f32) * 2.0 * PI64 * t.sin())
    }

    #[test]
    fn the_glints_phase_scatters_the_fresnel_shares_of_the_disc() {
        // p = 0 alone (i = (pi - theta) / 2) and the rest, p = 1.
        let p0 = |c: f32| water_fresnel(((1.0 - f64::from(c)) * 0.5).sqrt()) / (4.0 * PI64);
        let got0 = sphere_integral(p0);
        let got1 = sphere_integral(|c| f64::from(glint_phase(c)) - p0(c));
        let want0 = disc_average(|i| water_fresnel(i.cos()));
        let want1 = disc_average(|i| (1.0 - water_fresnel(i.cos())).powi(2));
        assert!(
            (got0 - want0).abs() < 1e-4 * want0,
            "p = 0: {got0} vs {want0}"
        );
        assert!(
            (got1 - want1).abs() < 1e-3 * want1,
            "p = 1: {got1} vs {want1}"
        );
        // Nearly all the light: what is left is the internal reflections (p >= 2).
        assert!(got0 + got1 > 0.9 && got0 + got1 < 1.0, "{}", got0 + got1);
    }

    #[test]
    fn the_glints_phase_has_its_analytic_limits() {
        let n = f64::from(WATER_IOR);
        let f0 = ((n - 1.0) / (n + 1.0)).powi(2);
        assert!((water_fresnel(1.0) - f0).abs() < 1e-12);
        assert!((water_fresnel(0.0) - 1.0).abs() < 1e-12);
        // Backscatter: only the external reflection at normal incidence.
        let back = f64::from(glint_phase(-1.0));
        assert!((back - f0 / (4.0 * PI64)).abs() < 1e-6 * back, "{back}");
        // Forward: the refracted limit, continuous with the angles next to it.
        let k = 1.0 - 1.0 / n;
        let fwd = (1.0 - f0).powi(2) / (4.0 * PI64 * k * k) + 1.0 / (4.0 * PI64);
        let got = f64::from(glint_phase(1.0));
        assert!((got - fwd).abs() < 1e-5 * fwd, "{got} vs {fwd}");
        let near = f64::from(glint_phase(1e-3f32.cos()));
        assert!((near - got).abs() < 1e-2 * got, "{near} vs {got}");
        // Beyond the grazing deflection only p = 0 is left; just before it p = 1 is not.
        let (theta_max, _) = refraction_deflection(std::f64::consts::FRAC_PI_2);
        assert!((theta_max.to_degrees() - 82.46).abs() < 0.05, "{theta_max}");
        let past = (theta_max + 1e-3).cos() as f32;
        let c = ((1.0 - f64::from(past)) * 0.5).sqrt();
        assert!((f64::from(glint_phase(past)) - water_fresnel(c) / (4.0 * PI64)).abs() < 1e-7);
        assert!(glint_phase((theta_max - 1e-2).cos() as f32) > glint_phase(past));
    }
}

#[cfg(test)]
mod render_tests {
    use super::*;
    use crate::integrator::tests::quad;
    use crate::integrator::{render, Layers, RenderJob};
    use crate::scene::{Scene, SceneParts};
    use streaks_settings::RenderSettings;

    /// The share of a pixel `[i, i+1)` lit by a half-plane whose edge sits at film position
    /// `s`, averaged over `s` uniform in `[s0, s1]` (the analytic motion blur of an edge).
    fn swept_share(i: f32, s0: f32, s1: f32) -> f32 {
        let steps = 10_000;
        (0..steps)
            .map(|k| {
                let s = s0 + (s1 - s0) * (k as f32 + 0.5) / steps as f32;
                (s - i).clamp(0.0, 1.0)
            })
            .sum::<f32>()
            / steps as f32
    }

    #[test]
    fn a_moving_rig_blurs_an_edge_by_the_analytic_swept_fraction() {
        // An emitter of radiance 1 on x < 0 at z = -2, seen by a camera moving along +X.
        let mut wall = Material::diffuse("wall", Vec3::ZERO);
        wall.emission = Vec3::ONE;
        let mut parts = SceneParts {
            materials: vec![wall],
            ..Default::default()
        };
        let z = -2.0;
        quad(
            &mut parts,
            [
                Vec3::new(-50.0, -50.0, z),
                Vec3::new(0.0, -50.0, z),
                Vec3::new(0.0, 50.0, z),
                Vec3::new(-50.0, 50.0, z),
            ],
            0,
        );
        let scene = Scene::from_parts(parts).unwrap();
        let (w, h, yfov) = (64u32, 16u32, 0.3f32);
        let camera = Camera::perspective("c", Affine3A::IDENTITY, yfov, None);
        let focal = 0.5 * h as f32 / (0.5 * yfov).tan();
        let (speed, shutter) = (10.0f32, 0.05f32);
        let job = |motion| RenderJob {
            width: w,
            height: h,
            seed: 2,
            layers: Layers::default(),
            settings: RenderSettings::new(512, 1),
            motion,
        };
        let blurred = render(
            &scene,
            &camera,
            &job(Motion::centred(shutter, Vec3::new(speed, 0.0, 0.0))),
            &|_| {},
        );
        let sharp = render(&scene, &camera, &job(Motion::default()), &|_| {});
        // The edge's film position moves from W/2 + a to W/2 - a.
        let a = focal * speed * 0.5 * shutter / -z;
        assert!(a > 4.0, "blur of {a} px");
        let mut worst = 0.0f32;
        for i in 0..w {
            let want = swept_share(i as f32, 0.5 * w as f32 - a, 0.5 * w as f32 + a);
            let got = blurred.image.get(i, 8).x;
            worst = worst.max((got - want).abs());
            let edge = if i < w / 2 { 1.0 } else { 0.0 };
            assert_eq!(sharp.image.get(i, 8).x, edge, "pixel {i} without blur");
        }
        assert!(worst < 0.01, "largest error {worst}");
    }

    /// A grey wall at depth `depth` in front of a camera at the origin, lit by an emissive
    /// ceiling 20 m up, with rain of `rate` mm/h within 4 m.
    fn wall_scene(depth: f32, rate: f32) -> Scene {
        let mut lamp = Material::diffuse("lamp", Vec3::ZERO);
        lamp.emission = Vec3::ONE;
        lamp.double_sided = true;
        let mut parts = SceneParts {
            materials: vec![Material::diffuse("wall", Vec3::splat(0.5)), lamp],
            ..Default::default()
        };
        let s = 30.0;
        quad(
            &mut parts,
            [
                Vec3::new(-s, -s, -depth),
                Vec3::new(s, -s, -depth),
                Vec3::new(s, s, -depth),
                Vec3::new(-s, s, -depth),
            ],
            0,
        );
        quad(
            &mut parts,
            [
                Vec3::new(-s, 20.0, s),
                Vec3::new(-s, 20.0, -s),
                Vec3::new(s, 20.0, -s),
                Vec3::new(s, 20.0, s),
            ],
            1,
        );
        let mut scene = Scene::from_parts(parts).unwrap();
        scene.set_rain(RainParams {
            rate_mm_h: rate,
            seed: 9,
            radius: 4.0,
        });
        scene
    }

    #[test]
    fn the_rain_layer_is_the_drops_cross_section_and_ground_truth_ignores_them() {
        let depth = 3.5;
        let mut scene = wall_scene(depth, 100.0);
        let camera = Camera::perspective("c", Affine3A::IDENTITY, 0.3, None);
        let (w, h) = (32, 24);
        let motion = Motion::centred(1.0 / 60.0, Vec3::ZERO);
        let drops = scene.place_rain(&camera, w, h, motion).unwrap();
        assert!(drops > 10_000, "{drops} drops");
        let job = RenderJob {
            width: w,
            height: h,
            seed: 1,
            layers: Layers {
                depth: true,
                rain: true,
                ..Layers::default()
            },
            settings: RenderSettings::new(64, 4),
            motion,
        };
        let out = render(&scene, &camera, &job, &|_| {});
        // Depth is the wall's everywhere: the drops are not in the ground truth.
        let forward_depth = out.depth.as_ref().unwrap();
        assert!(forward_depth.iter().all(|&d| (d - depth).abs() < 1e-4));
        // The share of camera rays that meet a drop first: 1 - exp(-sigma L), sigma the
        // drops' cross-section per volume, L the path through the rain (from 0.5 m to the
        // wall; the field of view is narrow, so L is nearly the same for every pixel).
        let lambda = mp_lambda(100.0);
        let steps = 10_000;
        let dd = (D_MAX_MM - D_MIN_MM) / steps as f64;
        let sigma: f64 = (0..steps)
            .map(|k| {
                let d = D_MIN_MM + (k as f64 + 0.5) * dd;
                MP_N0 * (-lambda * d).exp() * std::f64::consts::PI * (0.5e-3 * d).powi(2) * dd
            })
            .sum();
        let want = 1.0 - (-sigma * (depth - RAIN_NEAR) as f64).exp();
        let rain = out.rain.as_ref().unwrap();
        let got = rain.iter().map(|&r| r as f64).sum::<f64>() / rain.len() as f64;
        assert!(
            (got - want).abs() < 0.15 * want,
            "rain share {got}, cross-section predicts {want}"
        );
        // A dry render of the same scene: no drop, a zero layer.
        let mut dry = wall_scene(depth, 100.0);
        dry.rain = None;
        let out = render(&dry, &camera, &job, &|_| {});
        assert!(out.rain.unwrap().iter().all(|&r| r == 0.0));
    }

    /// Renders `scene` with its rain's estimator set to `estimator`.
    fn render_with(
        scene: &mut Scene,
        camera: &Camera,
        job: &RenderJob,
        estimator: RainEstimator,
    ) -> crate::integrator::RenderOutput {
        scene.rain.as_mut().unwrap().estimator = estimator;
        render(scene, camera, job, &|_| {})
    }

    #[test]
    fn the_swept_estimator_has_the_time_sampled_expectation() {
        // A black wall: the drops (showing the lit ceiling) stand out from the background.
        let black = |mut scene: Scene| {
            scene.materials[0] = Material::diffuse("wall", Vec3::ZERO);
            scene
        };
        let mut scene = black(wall_scene(3.5, 100.0));
        let camera = Camera::perspective("c", Affine3A::IDENTITY, 0.3, None);
        let (w, h) = (32, 24);
        let motion = Motion::centred(1.0 / 60.0, Vec3::new(0.5, 0.0, -2.0));
        scene.place_rain(&camera, w, h, motion).unwrap();
        let job = RenderJob {
            width: w,
            height: h,
            seed: 5,
            layers: Layers {
                rain: true,
                ..Layers::default()
            },
            settings: RenderSettings::new(256, 4),
            motion,
        };
        let swept = render_with(&mut scene, &camera, &job, RainEstimator::Swept);
        let sampled = render_with(&mut scene, &camera, &job, RainEstimator::TimeSampled);
        let mut dry = black(wall_scene(3.5, 100.0));
        dry.rain = None;
        let dry = render(&dry, &camera, &job, &|_| {});
        // Per pixel, both estimate the same expectation: the mean of their differences is
        // zero within its standard error (pixels are independent).
        let luminance = |o: &crate::integrator::RenderOutput| -> Vec<f64> {
            (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| o.image.get(x, y).dot(Vec3::ONE) as f64 / 3.0)
                .collect()
        };
        let (a, b, c) = (luminance(&swept), luminance(&sampled), luminance(&dry));
        let n = a.len() as f64;
        let stats = |d: Vec<f64>| {
            let mean = d.iter().sum::<f64>() / n;
            let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, (var / n).sqrt())
        };
        let (diff, se) = stats(a.iter().zip(&b).map(|(x, y)| x - y).collect());
        let (rain_effect, _) = stats(a.iter().zip(&c).map(|(x, y)| x - y).collect());
        let (ra, rb) = (swept.rain.unwrap(), sampled.rain.unwrap());
        let (ma, mb) = (
            ra.iter().sum::<f32>() / n as f32,
            rb.iter().sum::<f32>() / n as f32,
        );
        assert!(
            diff.abs() < 4.0 * se,
            "swept - time-sampled = {diff} (standard error {se})"
        );
        assert!(
            rain_effect.abs() > 4.0 * se,
            "the rain changes the mean by {rain_effect}, not measurably beyond {se}"
        );
        // The rain layers agree too.
        assert!((ma - mb).abs() < 0.1 * mb, "rain layer {ma} vs {mb}");
    }

    #[test]
    fn rain_hidden_behind_the_scene_changes_nothing() {
        // A wall nearer than the nearest drop: every drop is hidden, and the swept estimator
        // draws no number and traces nothing extra, so the render is the dry one bit for bit.
        let mut scene = wall_scene(0.45, 25.0);
        let camera = Camera::perspective("c", Affine3A::IDENTITY, 0.3, None);
        let (w, h) = (16, 12);
        let motion = Motion::centred(1.0 / 30.0, Vec3::new(0.0, 0.0, -3.0));
        assert!(scene.place_rain(&camera, w, h, motion).unwrap() > 100);
        let job = RenderJob {
            width: w,
            height: h,
            seed: 3,
            layers: Layers::default(),
            settings: RenderSettings::new(8, 4),
            motion,
        };
        let wet = render(&scene, &camera, &job, &|_| {});
        scene.rain = None;
        let dry = render(&scene, &camera, &job, &|_| {});
        assert_eq!(wet.image, dry.image);
    }

    #[test]
    fn both_eyes_of_a_rig_see_the_same_drops() {
        let mut scene = wall_scene(6.0, 25.0);
        let centre = Camera::perspective("c", Affine3A::IDENTITY, 0.6, None);
        let (w, h) = (96, 64);
        let motion = Motion::default();
        scene.place_rain(&centre, w, h, motion).unwrap();
        let field = &scene.rain.as_ref().unwrap().field;
        let eye = |x: f32| {
            Camera::perspective(
                "eye",
                Affine3A::from_translation(Vec3::new(x, 0.0, 0.0)),
                0.6,
                None,
            )
        };
        let (left, right) = (eye(-0.0325), eye(0.0325));
        let li = CameraRain::build(field, &left, w, h, &motion).unwrap();
        let ri = CameraRain::build(field, &right, w, h, &motion).unwrap();
        let mut seen = 0;
        for d in field.drops.iter().step_by(7) {
            let (Some(pl), Some(pr)) =
                (left.project(d.centre, w, h), right.project(d.centre, w, h))
            else {
                continue;
            };
            let inside = |p: Vec2| p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32;
            if !(inside(pl) && inside(pr)) {
                continue;
            }
            let (lray, rray) = (left.generate_ray(pl, w, h), right.generate_ray(pr, w, h));
            let l = li.intersect(&lray, 100.0).unwrap();
            let r = ri.intersect(&rray, 100.0).unwrap();
            // Each eye meets the drop where it is, or a drop in front of it.
            let tl = d.intersect(&lray, 100.0).unwrap().0;
            let tr = d.intersect(&rray, 100.0).unwrap().0;
            assert!(l.0 <= tl && r.0 <= tr, "an eye misses a drop in view");
            seen += usize::from(l.1 == *d && r.1 == *d);
        }
        assert!(seen > 200, "{seen} drops checked");
    }

    #[test]
    fn a_drop_in_one_pixel_glints_with_its_analytic_average_radiance() {
        // One drop of radius 1 cm 2 m in front of the camera, alone in a 1 x 1 image, lit by
        // a point light behind it (scattering angle about 18 degrees: p = 0 and p = 1).
        let (a, d) = (0.01f32, 2.0f32);
        let light = Vec3::new(0.0, 1.0, -5.0);
        let intensity = 100.0f32;
        let mut scene = Scene::from_parts(SceneParts {
            lights: vec![crate::light::Light::Point {
                position: light,
                intensity: Vec3::splat(intensity),
                range: None,
            }],
            ..Default::default()
        })
        .unwrap();
        scene.set_rain(RainParams {
            rate_mm_h: 1.0,
            seed: 0,
            radius: 4.0,
        });
        let centre = Vec3::new(0.0, 0.0, -d);
        scene.rain.as_mut().unwrap().field.drops = vec![Drop {
            centre,
            radius: a,
            speed: 0.0,
        }];
        let yfov = 0.05f32;
        let camera = Camera::perspective("c", Affine3A::IDENTITY, yfov, None);
        let job = RenderJob {
            width: 1,
            height: 1,
            seed: 3,
            layers: Layers::default(),
            settings: RenderSettings::new(1 << 18, 4),
            motion: Motion::default(),
        };
        let out = render(&scene, &camera, &job, &|_| {});
        let got = f64::from(out.image.get(0, 0).x);
        // The drop's share of the pixel (on the film plane) times E P(theta).
        let tan_alpha = (a / d).asin().tan() as f64;
        let half = (0.5 * yfov).tan() as f64;
        let share = std::f64::consts::PI * tan_alpha * tan_alpha / (4.0 * half * half);
        let to_light = light - centre;
        let e = f64::from(intensity / to_light.length_squared());
        let cos_theta = -to_light.normalize().dot(Vec3::Z);
        let want = share * e * f64::from(glint_phase(cos_theta));
        assert!(
            want > 0.0 && (got - want).abs() < 0.03 * want,
            "{got} vs {want}"
        );
        // Without the drop: black.
        scene.rain.as_mut().unwrap().field.drops.clear();
        let out = render(&scene, &camera, &job, &|_| {});
        assert_eq!(out.image.get(0, 0), Vec3::ZERO);
    }
}
