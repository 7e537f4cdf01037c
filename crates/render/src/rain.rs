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
//! - How: a drop is `centre(t) = centre + v t` with `v = (0, -speed, 0)`; the drops' boxes,
//!   each swept over the shutter interval, are the leaves of their own BVH (the same obvhs
//!   CWBVH the instances' top level uses, [`crate::accel::Tlas`]), and a leaf is an exact
//!   ray-sphere test at the ray's time. No triangles are made.

use crate::accel::Tlas;
use crate::camera::{Camera, Projection};
use crate::geometry::Ray;
use crate::material::{GltfPbrParams, Material, Reflectance, Volume};
use crate::motion::Motion;
use crate::sampling::Pcg32;
use glam::{Affine3A, Vec2, Vec3};

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
/// an out-of-memory abort): 20 million, about 1.2 GB with the BVH.
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

/// A scene's drops for one view, and their BVH.
#[derive(Debug, Default)]
pub struct DropField {
    /// The drops.
    pub drops: Vec<Drop>,
    /// The BVH over their swept boxes (`None` without drops).
    bvh: Option<Tlas>,
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
        Ok(DropField::new(drops, motion.open, motion.close))
    }

    /// A field of the given drops with their BVH over the shutter `[open, close]`.
    pub fn new(drops: Vec<Drop>, open: f32, close: f32) -> DropField {
        let boxes: Vec<[Vec3; 2]> = drops.iter().map(|d| d.swept_box(open, close)).collect();
        let bvh = Tlas::build(&boxes);
        DropField { drops, bvh }
    }

    /// The number of drops.
    pub fn len(&self) -> usize {
        self.drops.len()
    }

    /// Whether there are no drops.
    pub fn is_empty(&self) -> bool {
        self.drops.is_empty()
    }

    /// Approximate heap memory of the drops and their BVH, in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.drops.as_slice())
            + self.bvh.as_ref().map_or(0, Tlas::memory_bytes)
    }

    /// The nearest drop `ray` meets before `ray.t_max` at its time: the parameter, the drop's
    /// index and the outward normal.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, u32, Vec3)> {
        let bvh = self.bvh.as_ref()?;
        let mut best: Option<(f32, u32, Vec3)> = None;
        bvh.closest(ray, 0.0, |i, t_max| {
            match self.drops[i as usize].intersect(ray, t_max) {
                Some((t, n)) => {
                    best = Some((t, i, n));
                    t
                }
                None => f32::INFINITY,
            }
        });
        best
    }

    /// Whether a drop blocks `ray` before `ray.t_max` at its time.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let Some(bvh) = &self.bvh else {
            return false;
        };
        bvh.any(ray, 0.0, |i| {
            self.drops[i as usize].intersect(ray, ray.t_max).is_some()
        })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{chi_square_2d, ChiSquareConfig};

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

    #[test]
    fn the_field_finds_the_drop_a_ray_is_aimed_at_at_its_time() {
        let params = RainParams {
            rate_mm_h: 25.0,
            seed: 1,
            radius: 4.0,
        };
        let field = DropField::place(&params, &view()).unwrap();
        assert!(field.len() > 1000);
        let origin = Vec3::new(0.0, 1.4, 0.0);
        for (k, d) in field.drops.iter().enumerate().step_by(97) {
            let time = 1.0 / 200.0;
            let mut ray = Ray::new(origin, (d.centre_at(time) - origin).normalize());
            ray.time = time;
            let (t, _, _) = field.intersect(&ray).expect("aimed at a drop");
            let aimed = (d.centre_at(time) - origin).length() - d.radius;
            // The drop aimed at, or one in front of it.
            assert!(t <= aimed + 1e-4, "drop {k}: {t} vs {aimed}");
            assert!(field.occluded(&ray));
            // The drop falls out of the ray's way when the ray is at another time.
            let mut later = ray;
            later.time = -1.0 / 200.0;
            if d.speed * 0.01 > 2.5 * d.radius {
                assert!(d.intersect(&later, f32::INFINITY).is_none(), "drop {k}");
            }
        }
    }
}
