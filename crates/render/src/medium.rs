//! The scene's fog ([`Fog`]): a participating medium that fills the space outside the objects.
//!
//! The fog has an extinction coefficient `sigma_t` (per metre, RGB) at the reference height
//! `y0`, a single-scattering albedo (`sigma_s = albedo sigma_t`, RGB) and a Henyey-Greenstein
//! phase function ([`crate::phase`]). Its density may fall off exponentially with height:
//! `sigma_t(p) = sigma_t exp(-k (p_y - y0))` with `k` = `height_falloff` (0: homogeneous).
//!
//! Along a ray `p(t) = o + t d` (`|d| = 1`) the optical depth is `sigma_t L(t)`, with the
//! density-weighted length ([`Fog::density_length`])
//!
//! `L(t) = rho(o) (1 - exp(-b t)) / b`, `rho(o) = exp(-k (o_y - y0))`, `b = k d_y`
//!
//! (`rho(o) t` when `b = 0`; `-expm1(-b t) / b` keeps it exact for small `b t`). To infinity,
//! `L = rho(o) / b` looking up (`b > 0`: the sky stays visible through the fog) and infinite
//! otherwise (a homogeneous fog hides the sky completely, as Mitsuba's unbounded `homogeneous`
//! medium does).
//!
//! Free-flight sampling ([`Fog::sample_flight`]) is exact for one colour channel `c`, chosen
//! once per path (Mitsuba 3's `volpath` rule): the distance is drawn from the density
//! `sigma_t,c(t) T_c(t)` by inverting `sigma_t,c L(t) = -ln(1 - u)` (`t = -ln(1 - s b) / b`
//! with `s = -ln(1 - u) / (sigma_t,c rho(o))`, through `log1p`); looking up, a draw past the
//! total optical depth escapes. The path's weight is Mitsuba's: `T(t) / T_c(t)` when it
//! passes the segment, `T(t) sigma_s(t) / (T_c(t) sigma_t,c(t))` at a collision; with grey
//! fog these are 1 and the albedo.

use crate::phase::HenyeyGreenstein;
use glam::Vec3;

/// The largest exponent the height falloff's density factor is allowed (so that a point far
/// below the reference height in a steep falloff has a huge but finite density).
const MAX_DENSITY_EXPONENT: f32 = 60.0;

/// An invalid fog parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FogError {
    /// An extinction coefficient that is negative or not finite.
    #[error("sigma_t must be finite and >= 0 (per metre), got {0}")]
    SigmaT(Vec3),
    /// An albedo outside [0, 1].
    #[error("albedo must lie in [0, 1], got {0}")]
    Albedo(Vec3),
    /// A phase asymmetry with `|g| >= 1`.
    #[error("g must lie in (-1, 1), got {0}")]
    G(f32),
    /// A negative or non-finite height falloff.
    #[error("height_falloff must be finite and >= 0 (per metre), got {0}")]
    HeightFalloff(f32),
    /// A non-finite reference height.
    #[error("reference_height must be finite (metres), got {0}")]
    ReferenceHeight(f32),
}

/// The scene's fog (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    sigma_t: Vec3,
    albedo: Vec3,
    phase: HenyeyGreenstein,
    height_falloff: f32,
    reference_height: f32,
}

/// What a free flight along one segment gave ([`Fog::sample_flight`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flight {
    /// The path collides with the fog at distance `t`, and its throughput is multiplied by
    /// `weight` (`T sigma_s / (T_c sigma_t,c)` there).
    Collision {
        /// Distance along the ray.
        t: f32,
        /// Factor on the path's throughput.
        weight: Vec3,
    },
    /// The path passes the whole segment; its throughput is multiplied by `weight`
    /// (`T / T_c` of the segment).
    Pass {
        /// Factor on the path's throughput.
        weight: Vec3,
    },
}

impl Fog {
    /// A fog with extinction `sigma_t` (per metre, at `reference_height`), single-scattering
    /// `albedo`, Henyey-Greenstein asymmetry `g` (Mitsuba's sign: > 0 forward) and density
    /// falling off with height as `exp(-height_falloff (y - reference_height))`.
    pub fn new(
        sigma_t: Vec3,
        albedo: Vec3,
        g: f32,
        height_falloff: f32,
        reference_height: f32,
    ) -> Result<Self, FogError> {
        if !(sigma_t.is_finite() && sigma_t.min_element() >= 0.0) {
            return Err(FogError::SigmaT(sigma_t));
        }
        if !(albedo.is_finite() && albedo.min_element() >= 0.0 && albedo.max_element() <= 1.0) {
            return Err(FogError::Albedo(albedo));
        }
        if g.is_nan() || g.abs() >= 1.0 {
            return Err(FogError::G(g));
        }
        if !(height_falloff.is_finite() && height_falloff >= 0.0) {
            return Err(FogError::HeightFalloff(height_falloff));
        }
        if !reference_height.is_finite() {
            return Err(FogError::ReferenceHeight(reference_height));
        }
        Ok(Self {
            sigma_t,
            albedo,
            phase: HenyeyGreenstein { g },
            height_falloff,
            reference_height,
        })
    }

    /// A fog of the same density everywhere.
    pub fn homogeneous(sigma_t: Vec3, albedo: Vec3, g: f32) -> Result<Self, FogError> {
        Self::new(sigma_t, albedo, g, 0.0, 0.0)
    }

    /// Extinction per metre at the reference height.
    #[inline]
    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_t
    }

    /// Single-scattering albedo.
    #[inline]
    pub fn albedo(&self) -> Vec3 {
        self.albedo
    }

    /// The phase function.
    #[inline]
    pub fn phase(&self) -> HenyeyGreenstein {
        self.phase
    }

    /// Exponential falloff of the density with height, per metre (0: homogeneous).
    #[inline]
    pub fn height_falloff(&self) -> f32 {
        self.height_falloff
    }

    /// The height at which the extinction is [`Fog::sigma_t`].
    #[inline]
    pub fn reference_height(&self) -> f32 {
        self.reference_height
    }

    /// The density factor `exp(-k (y - y0))` at height `y` (1 for homogeneous fog).
    #[inline]
    pub fn density(&self, y: f32) -> f32 {
        if self.height_falloff == 0.0 {
            1.0
        } else {
            (-self.height_falloff * (y - self.reference_height))
                .min(MAX_DENSITY_EXPONENT)
                .exp()
        }
    }

    /// Extinction per metre at point `p`.
    #[inline]
    pub fn sigma_t_at(&self, p: Vec3) -> Vec3 {
        self.sigma_t * self.density(p.y)
    }

    /// The integral of the density factor along `o + s d` for `s` in `[0, t]` (`d` unit;
    /// `t` may be infinite): the optical depth per unit of `sigma_t` (see the module
    /// documentation).
    #[inline]
    pub fn density_length(&self, o: Vec3, d: Vec3, t: f32) -> f32 {
        let a = self.density(o.y);
        let b = self.height_falloff * d.y;
        if t == f32::INFINITY {
            return if b > 0.0 { a / b } else { f32::INFINITY };
        }
        if b == 0.0 {
            a * t
        } else {
            -a * (-b * t).exp_m1() / b
        }
    }

    /// Optical depth along `o + s d`, `s` in `[0, t]` (`t` may be infinite).
    #[inline]
    pub fn optical_depth(&self, o: Vec3, d: Vec3, t: f32) -> Vec3 {
        let l = self.density_length(o, d, t);
        // A clear channel stays clear however long the ray (0 * inf would be NaN).
        Vec3::select(self.sigma_t.cmpeq(Vec3::ZERO), Vec3::ZERO, self.sigma_t * l)
    }

    /// Transmittance along `o + s d`, `s` in `[0, t]` (`t` may be infinite: the transmittance
    /// to the sky, 0 unless looking up through a fog that thins with height).
    #[inline]
    pub fn transmittance(&self, o: Vec3, d: Vec3, t: f32) -> Vec3 {
        let tau = self.optical_depth(o, d, t);
        Vec3::new((-tau.x).exp(), (-tau.y).exp(), (-tau.z).exp())
    }

    /// `T / T_c` for a density-weighted length `l`: `exp(-(sigma_t - sigma_t,c) l)`, 1 where a
    /// channel's extinction equals channel `c`'s (also for infinite `l`).
    #[inline]
    fn ratio_to_channel(&self, l: f32, channel: usize) -> Vec3 {
        let sc = self.sigma_t[channel];
        let r = |s: f32| if s == sc { 1.0 } else { (-(s - sc) * l).exp() };
        Vec3::new(r(self.sigma_t.x), r(self.sigma_t.y), r(self.sigma_t.z))
    }

    /// Samples the distance of a free flight along the ray `o + s d` in colour channel
    /// `channel` (0..3) with `u` in [0, 1): exact for that channel's extinction (see the
    /// module documentation); infinite when the flight never ends (a clear channel, or looking
    /// up through fog that thins with height past its total optical depth).
    #[inline]
    pub fn sample_distance(&self, o: Vec3, d: Vec3, channel: usize, u: f32) -> f32 {
        let sc = self.sigma_t[channel];
        let a = self.density(o.y);
        let b = self.height_falloff * d.y;
        if !(sc > 0.0 && a > 0.0) {
            return f32::INFINITY;
        }
        // The density-weighted length at which the flight ends.
        let s = -(-u).ln_1p() / (sc * a);
        if b == 0.0 {
            s
        } else {
            let x = s * b;
            if x >= 1.0 {
                f32::INFINITY
            } else {
                -(-x).ln_1p() / b
            }
        }
    }

    /// The weight `T / T_c` of a flight in channel `channel` that passes the segment `o + s d`,
    /// `s` in `[0, t]` (`t` may be infinite).
    #[inline]
    pub fn pass_weight(&self, o: Vec3, d: Vec3, t: f32, channel: usize) -> Vec3 {
        self.ratio_to_channel(self.density_length(o, d, t), channel)
    }

    /// The weight `T sigma_s / (T_c sigma_t,c)` of a flight in channel `channel` (whose
    /// extinction must be positive) that ends at distance `t` along `o + s d`.
    #[inline]
    pub fn collision_weight(&self, o: Vec3, d: Vec3, t: f32, channel: usize) -> Vec3 {
        let l = self.density_length(o, d, t);
        self.ratio_to_channel(l, channel) * self.albedo * (self.sigma_t / self.sigma_t[channel])
    }

    /// Samples a free flight along the segment `o + s d`, `s` in `[0, t_max]` (`t_max` may be
    /// infinite), in colour channel `channel` (0..3) with `u` in [0, 1) (see the module
    /// documentation): [`Fog::sample_distance`] with [`Fog::collision_weight`] or
    /// [`Fog::pass_weight`].
    #[inline]
    pub fn sample_flight(&self, o: Vec3, d: Vec3, t_max: f32, channel: usize, u: f32) -> Flight {
        let t = self.sample_distance(o, d, channel, u);
        if t < t_max {
            Flight::Collision {
                t,
                weight: self.collision_weight(o, d, t, channel),
            }
        } else {
            Flight::Pass {
                weight: self.pass_weight(o, d, t_max, channel),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    fn foggy(k: f32) -> Fog {
        Fog::new(
            Vec3::new(0.05, 0.08, 0.12),
            Vec3::new(0.9, 0.8, 0.95),
            0.7,
            k,
            1.5,
        )
        .unwrap()
    }

    /// The optical depth by the midpoint rule over `n` steps (to `t`, or far enough).
    fn quadrature(fog: &Fog, o: Vec3, d: Vec3, t: f32, n: usize) -> Vec3 {
        let h = t as f64 / n as f64;
        let mut sum = [0.0f64; 3];
        for i in 0..n {
            let p = o + d * ((i as f64 + 0.5) * h) as f32;
            let s = fog.sigma_t_at(p);
            for c in 0..3 {
                sum[c] += s[c] as f64 * h;
            }
        }
        Vec3::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
    }

    fn rays() -> Vec<(Vec3, Vec3)> {
        [
            (Vec3::new(0.0, 1.5, 0.0), Vec3::X),
            (Vec3::new(1.0, 0.2, -3.0), Vec3::new(0.3, 0.5, -0.8)),
            (Vec3::new(1.0, 7.0, -3.0), Vec3::new(-0.2, -0.6, 0.7)),
            (Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 1e-6, 1.0)),
        ]
        .into_iter()
        .map(|(o, d)| (o, d.normalize()))
        .collect()
    }

    #[test]
    fn optical_depth_matches_quadrature() {
        for k in [0.0, 0.02, 0.3, 2.0] {
            let fog = foggy(k);
            for (o, d) in rays() {
                for t in [0.01, 1.0, 12.0, 40.0] {
                    let exact = fog.optical_depth(o, d, t);
                    let numeric = quadrature(&fog, o, d, t, 20_000);
                    let err = (exact - numeric).abs().max_element();
                    assert!(
                        err <= 1e-4 * numeric.max_element() + 1e-9,
                        "k={k} o={o} d={d} t={t}: {exact} vs {numeric}"
                    );
                }
            }
        }
    }

    #[test]
    fn depth_to_infinity_is_finite_only_looking_up_through_thinning_fog() {
        let fog = foggy(0.3);
        let (o, up) = (Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 0.6, 0.8));
        let inf = fog.optical_depth(o, up, f32::INFINITY);
        let far = quadrature(&fog, o, up, 200.0, 200_000);
        assert!(
            (inf - far).abs().max_element() < 1e-4 * far.max_element(),
            "{inf} {far}"
        );
        assert_eq!(fog.transmittance(o, Vec3::X, f32::INFINITY), Vec3::ZERO);
        assert_eq!(
            fog.transmittance(o, -up, f32::INFINITY),
            Vec3::ZERO,
            "looking down"
        );
        let homogeneous = foggy(0.0);
        assert_eq!(homogeneous.transmittance(o, up, f32::INFINITY), Vec3::ZERO);
        // A clear channel stays clear.
        let clear = Fog::homogeneous(Vec3::new(0.0, 0.1, 0.1), Vec3::ONE, 0.0).unwrap();
        assert_eq!(clear.transmittance(o, up, f32::INFINITY).x, 1.0);
    }

    /// Kolmogorov-Smirnov: the flights' distances (collisions, and passes counted at
    /// `t_max`) against the exact cdf `1 - T_c(t)`.
    #[test]
    fn free_flights_follow_the_channel_transmittance() {
        let n = 20_000;
        for k in [0.0, 0.3] {
            let fog = foggy(k);
            for (o, d) in rays() {
                for channel in 0..3 {
                    let t_max = 25.0;
                    let mut rng = Pcg32::new(7, channel as u64);
                    let mut ts: Vec<f32> = (0..n)
                        .map(
                            |_| match fog.sample_flight(o, d, t_max, channel, rng.next_f32()) {
                                Flight::Collision { t, .. } => t,
                                Flight::Pass { .. } => t_max,
                            },
                        )
                        .collect();
                    ts.sort_by(f32::total_cmp);
                    let cdf = |t: f32| {
                        if t >= t_max {
                            1.0
                        } else {
                            1.0 - fog.transmittance(o, d, t)[channel]
                        }
                    };
                    let mut ks = 0.0f32;
                    for (i, &t) in ts.iter().enumerate() {
                        let f = cdf(t);
                        let lo = i as f32 / n as f32;
                        let hi = (i + 1) as f32 / n as f32;
                        let f_below = if t >= t_max {
                            1.0 - fog.transmittance(o, d, t_max)[channel]
                        } else {
                            f
                        };
                        ks = ks.max((f_below - lo).max(hi - f).max(0.0));
                        if t >= t_max {
                            break;
                        }
                    }
                    // The 0.1% critical value of the KS statistic: 1.95 / sqrt(n).
                    assert!(
                        ks < 1.95 / (n as f32).sqrt(),
                        "k={k} o={o} d={d} c={channel}: {ks}"
                    );
                }
            }
        }
    }

    /// The estimator's expectation: passes give `T(t_max)` and collisions the in-scattering
    /// density `sigma_s T` (here integrated against a test function), per channel, whatever
    /// the channel chosen.
    #[test]
    fn flight_weights_are_unbiased_in_every_channel() {
        let fog = foggy(0.3);
        let (o, d) = rays()[1];
        let t_max = 15.0;
        let f = |t: f32| 1.0 + 0.1 * t;
        let n = 400_000;
        // Expected: T(t_max) + int_0^t_max sigma_s(t) T(t) f(t) dt.
        let steps = 100_000;
        let h = t_max / steps as f32;
        let mut expected = fog.transmittance(o, d, t_max);
        for i in 0..steps {
            let t = (i as f32 + 0.5) * h;
            let p = o + d * t;
            expected += fog.sigma_t_at(p) * fog.albedo() * fog.transmittance(o, d, t) * (f(t) * h);
        }
        for channel in 0..3 {
            let mut rng = Pcg32::new(3, 11 + channel as u64);
            let mut sum = Vec3::ZERO;
            for _ in 0..n {
                sum += match fog.sample_flight(o, d, t_max, channel, rng.next_f32()) {
                    Flight::Collision { t, weight } => weight * f(t),
                    Flight::Pass { weight } => weight,
                };
            }
            let mean = sum / n as f32;
            let err = ((mean - expected) / expected).abs().max_element();
            assert!(err < 0.01, "channel {channel}: {mean} vs {expected}");
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        let (s, a) = (Vec3::splat(0.1), Vec3::splat(0.9));
        assert!(Fog::new(s, a, 0.5, 0.0, 0.0).is_ok());
        let neg = Vec3::new(-0.1, 0.1, 0.1);
        assert!(matches!(
            Fog::new(neg, a, 0.5, 0.0, 0.0),
            Err(FogError::SigmaT(_))
        ));
        let high = Vec3::splat(1.1);
        assert!(matches!(
            Fog::new(s, high, 0.5, 0.0, 0.0),
            Err(FogError::Albedo(_))
        ));
        assert!(matches!(Fog::new(s, a, 1.0, 0.0, 0.0), Err(FogError::G(_))));
        assert!(matches!(
            Fog::new(s, a, f32::NAN, 0.0, 0.0),
            Err(FogError::G(_))
        ));
        assert!(matches!(
            Fog::new(s, a, 0.5, -1.0, 0.0),
            Err(FogError::HeightFalloff(_))
        ));
        assert!(matches!(
            Fog::new(s, a, 0.5, 0.0, f32::INFINITY),
            Err(FogError::ReferenceHeight(_))
        ));
    }
}
