//! The virtual light column model of specular streaks (the paper's section III, Eq. 2 and
//! Eq. 4, and the proposition proved in its appendix), and the disparity it predicts along a
//! streak (section IV, Eq. 5).
//!
//! # Frame and conventions
//!
//! Everything is in the road frame of docs/design.md: metres, Y up, the road is the plane Y = 0,
//! Z points forward (from the viewer towards the light), X to the right. Eq. 4 uses only dot
//! products and reflections, so the frame's handedness does not matter. All maths is in `f64`
//! ([`glam::DVec3`]) so that the proposition's invariance holds to `f64` precision.
//!
//! For a ground point `X`, a viewer `X_V` and a point light `X_L`:
//!
//! - `v = (X_V - X)/|X_V - X|` and `l = (X_L - X)/|X_L - X|` point from `X` to the viewer and
//!   to the light; the half vector (Eq. 2) is `h = (v + l)/|v + l|` ([`half_vector`]): the
//!   only microfacet normal that mirrors the light into the viewer at `X`.
//! - The virtual light (Eq. 4) is `L_virtual = X + (I - 2 h h^T) L` with `L = X_L - X`
//!   ([`virtual_light`]): the light mirrored about the microfacet plane through `X`. The
//!   viewer sees the glint at `X` along the ray from `L_virtual`, so stereo places the
//!   glint at `L_virtual`.
//! - The tilt of `h` is its angle from the vertical `+Y` ([`tilt_deg`]). The paper's Fig. 4
//!   keeps only ground points whose tilt is below 4 degrees.
//!
//! # The locus (the `h_X = 0` family)
//!
//! The appendix proves the proposition for the ground points whose half vector has no X
//! component. With the viewer in the light's `X` plane these are the points `(X_L, 0, Z)`
//! straight between viewer and light; for a viewer at another `X` there is still exactly one
//! such point on each constant-depth line `(x, 0, Z)` ([`ColumnModel::plane_point`]), and by
//! the proposition its `L_virtual` is the same as for the viewer in the light's plane.
//! [`ColumnModel::locus`] samples this curve for depths between the viewer and the light,
//! optionally keeping only tilts up to a limit. Near the viewer `h` leans away from the viewer
//! (towards the light), which pulls `L_virtual` towards the viewer and deeper below the road;
//! far from the viewer `h` leans towards the viewer and `L_virtual` lies farther away and
//! closer to the road: the column slants (the paper's Fig. 5).
//!
//! [`ColumnModel::check_invariance`] checks the proposition numerically, faithfully to the
//! proof: for a ground point at depth `Z` and each viewer offset `s` along X, it finds the
//! point of the same constant-depth line `(x, 0, Z)` whose half vector for the moved viewer
//! has the same X component as the original `h`. When `h_X = 0` that half vector *is* `h`
//! (the proof's construction: the plane through `X` with normal `h` meets the road in the
//! constant-depth line, and all rays mirrored there pass through the viewer's line of motion),
//! and `L_virtual` is unchanged to rounding. When `h_X != 0` no point of the line has the
//! same `h`; the report gives the remaining angle between the half vectors and how far
//! `L_virtual` moves.
//!
//! # Disparity along a streak
//!
//! The disparities come from the stereo crate's camera model,
//! [`streaks_stereo::rig::RoadRig`]: a rectified pair of pinhole eyes `b` apart along X, centred
//! on the viewer, in `f64`. For a point at depth `Z_l` along the optical axis (Eq. 5) the pixel
//! disparity is `d = x_left - x_right = f b / Z_l`; the angular disparity is the difference of
//! the point's horizontal visual angles (azimuths) in the two eyes; for a point straight ahead
//! it is `2 atan(b / 2Z)`. [`streak_rows`] predicts them for every image row of a streak.
//!
//! # The paper's Fig. 6 configuration
//!
//! Light 15 m ahead at 1.5 m height, viewer (rig centre) at 1.5 m height, baseline 6.5 cm,
//! light and viewer in the same X plane. The paper says the disparity of the `L_virtual`
//! locus varies over about 0.007 degrees while the elevation angle spans nearly 9 degrees.
//! This model gives (pinned in this module's tests):
//!
//! | tilt filter | ground depths (m) | elevation below horizon (deg) | disparity of `L_virtual` (deg) |
//! |---|---|---|---|
//! | 4 deg (Fig. 4's) | 5.0424 .. 9.9576 | 16.5666 .. 8.5666, span **8.000** | 0.253446 .. 0.245666, range **0.007780** |
//! | 4.5 deg | 4.7972 .. 10.2028 | 17.3636 .. 8.3636, span **9.000** | range 0.008983 |
//! | 3.66 deg | 5.2182 .. 9.7818 | span 7.319 | range **0.007000** |
//!
//! (The light itself has 0.248281 degrees; the mirror point is at 7.5 m.) With the viewer
//! and the light at the same height the elevation span is exactly twice the tilt limit: `h`
//! bisects the two sight lines, so its tilt is half the difference of the elevations of the
//! ground point seen from the viewer and from the light, and by symmetry the far end's
//! elevation from the viewer is the near end's from the light. So no tilt filter gives both
//! of the paper's numbers: the 4 degree filter gives 0.0078 degrees (0.007 truncated to one
//! digit) over 8 degrees, "nearly 9 degrees" needs a filter of about 4.4 to 4.5 degrees
//! (0.0087 to 0.0090 degrees of disparity), and 0.007 degrees exactly needs 3.66 degrees
//! (7.3 degrees of elevation). The paper's Fig. 6 probably covers the rows of its rendered
//! streak rather than a tilt filter; its two numbers agree with the model to about 25 %.

use glam::{DVec2, DVec3};
use streaks_stereo::error::StereoError;
use streaks_stereo::rig::RoadRig;

/// What went wrong building or evaluating the model; each names the offending input.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// An input is NaN or infinite.
    #[error("{what} must be finite, got {value}")]
    NotFinite {
        /// Which input.
        what: &'static str,
        /// The value as given.
        value: String,
    },
    /// The light is on or below the road.
    #[error("the light must be above the road (Y > 0), got Y = {height}")]
    LightBelowRoad {
        /// The light's Y.
        height: f64,
    },
    /// The viewer is on or below the road.
    #[error("the viewer must be above the road (Y > 0), got Y = {height}")]
    ViewerBelowRoad {
        /// The viewer's Y.
        height: f64,
    },
    /// The viewer and the light are at the same depth: no ground points lie between them.
    #[error(
        "the viewer is at the light's depth (Z = {depth}); the light must be ahead of the viewer"
    )]
    ViewerAtLightDepth {
        /// The common Z.
        depth: f64,
    },
    /// The light is behind the viewer (the road frame's Z points from the viewer forwards).
    #[error("the light (Z = {light_z}) must be ahead of the viewer (Z = {viewer_z})")]
    LightBehindViewer {
        /// The light's Z.
        light_z: f64,
        /// The viewer's Z.
        viewer_z: f64,
    },
    /// A sample count of zero.
    #[error("the number of samples must be at least 1")]
    NoSamples,
    /// A tilt limit outside (0, 90) degrees.
    #[error("the maximum tilt of h must be in (0, 90) degrees, got {value}")]
    BadTilt {
        /// The limit as given.
        value: f64,
    },
    /// The stereo rig the disparities are measured with (a baseline that is not positive).
    #[error(transparent)]
    Rig(#[from] StereoError),
    /// A ground depth outside the interval between viewer and light.
    #[error("ground depth {depth} m is not between the viewer ({near} m) and the light ({far} m)")]
    DepthOutOfRange {
        /// The depth asked for.
        depth: f64,
        /// The viewer's depth.
        near: f64,
        /// The light's depth.
        far: f64,
    },
    /// The light's mirror image does not project into the camera (it is behind it).
    #[error("the light's mirror image is behind the camera; give the streak's column explicitly")]
    MirrorBehindCamera,
}

/// Checks that every component of `v` is finite.
fn finite3(what: &'static str, v: DVec3) -> Result<DVec3, ModelError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ModelError::NotFinite {
            what,
            value: format!("({}, {}, {})", v.x, v.y, v.z),
        })
    }
}

/// Checks that `v` is finite.
fn finite(what: &'static str, v: f64) -> Result<f64, ModelError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ModelError::NotFinite {
            what,
            value: v.to_string(),
        })
    }
}

/// Checks a tilt limit in degrees.
fn check_tilt(max_tilt_deg: Option<f64>) -> Result<Option<f64>, ModelError> {
    match max_tilt_deg {
        Some(t) if !(t > 0.0 && t < 90.0) => Err(ModelError::BadTilt { value: t }),
        t => Ok(t),
    }
}

/// The half vector of Eq. 2 at ground point `x`: the unit bisector of the directions from `x`
/// to the viewer and to the light. `None` only if those directions are opposite or a point
/// coincides with `x`.
pub fn half_vector(x: DVec3, viewer: DVec3, light: DVec3) -> Option<DVec3> {
    let v = (viewer - x).try_normalize()?;
    let l = (light - x).try_normalize()?;
    (v + l).try_normalize()
}

/// The virtual light of Eq. 4: `x + (I - 2 h h^T)(light - x)`, the light mirrored about the
/// plane through `x` with unit normal `h`.
pub fn virtual_light(x: DVec3, h: DVec3, light: DVec3) -> DVec3 {
    let l = light - x;
    x + l - 2.0 * h.dot(l) * h
}

/// The angle of a unit vector `h` from the vertical `+Y`, in degrees.
pub fn tilt_deg(h: DVec3) -> f64 {
    h.x.hypot(h.z).atan2(h.y).to_degrees()
}

/// Finds a zero of `f` in `[lo, hi]`, given `f(lo)` and `f(hi)` of opposite signs (or zero),
/// by bisection down to adjacent floating-point numbers.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let mut f_lo = f(lo);
    if f_lo == 0.0 {
        return lo;
    }
    if f(hi) == 0.0 {
        return hi;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        let f_mid = f(mid);
        if f_mid == 0.0 {
            return mid;
        }
        if (f_mid > 0.0) == (f_lo > 0.0) {
            lo = mid;
            f_lo = f_mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// One glint: a ground point, the microfacet normal that mirrors the light into the viewer
/// there, and the virtual light it implies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reflection {
    /// The ground point `X = (x, 0, z)`.
    pub ground: DVec3,
    /// The half vector `h` (Eq. 2), a unit vector.
    pub h: DVec3,
    /// The angle of `h` from the vertical, in degrees.
    pub tilt_deg: f64,
    /// `L_virtual` (Eq. 4).
    pub virtual_light: DVec3,
}

/// A point light above the road and a viewer, validated: the model of section III.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnModel {
    light: DVec3,
    viewer: DVec3,
}

impl ColumnModel {
    /// Checks the configuration: finite coordinates, light and viewer above the road, the
    /// light ahead of the viewer (larger Z).
    pub fn new(light: DVec3, viewer: DVec3) -> Result<Self, ModelError> {
        finite3("the light position", light)?;
        finite3("the viewer position", viewer)?;
        if light.y <= 0.0 {
            return Err(ModelError::LightBelowRoad { height: light.y });
        }
        if viewer.y <= 0.0 {
            return Err(ModelError::ViewerBelowRoad { height: viewer.y });
        }
        if light.z == viewer.z {
            return Err(ModelError::ViewerAtLightDepth { depth: light.z });
        }
        if light.z < viewer.z {
            return Err(ModelError::LightBehindViewer {
                light_z: light.z,
                viewer_z: viewer.z,
            });
        }
        Ok(Self { light, viewer })
    }

    /// The light's position.
    pub fn light(&self) -> DVec3 {
        self.light
    }

    /// The viewer's position.
    pub fn viewer(&self) -> DVec3 {
        self.viewer
    }

    /// The same light seen from another viewer.
    pub fn with_viewer(&self, viewer: DVec3) -> Result<Self, ModelError> {
        Self::new(self.light, viewer)
    }

    /// The glint at ground point `(x, 0, z)` (`x`, `z` finite; any ground point has a
    /// half vector because light and viewer are both above the road).
    pub fn reflection_at(&self, x: f64, z: f64) -> Reflection {
        let ground = DVec3::new(x, 0.0, z);
        // Light and viewer are strictly above the road, so v and l both have positive Y and
        // their sum cannot vanish; the fallback is unreachable for finite input.
        let h = half_vector(ground, self.viewer, self.light).unwrap_or(DVec3::Y);
        Reflection {
            ground,
            h,
            tilt_deg: tilt_deg(h),
            virtual_light: virtual_light(ground, h, self.light),
        }
    }

    /// The mirror point: where `h` is vertical and `L_virtual` is the light's mirror image
    /// `(X_L, -Y_L, Z_L)`, on the sight line from the viewer to that image.
    pub fn mirror_point(&self) -> DVec3 {
        let image = self.light * DVec3::new(1.0, -1.0, 1.0);
        let t = self.viewer.y / (self.viewer.y + self.light.y);
        let p = self.viewer + t * (image - self.viewer);
        DVec3::new(p.x, 0.0, p.z)
    }

    /// The point of the constant-depth line `(x, 0, z)` whose half vector has no X component
    /// (the family the appendix's proof covers). It lies between the viewer's and the light's
    /// X, and is `(X_L, 0, z)` when they share X.
    pub fn plane_point(&self, z: f64) -> DVec3 {
        let (xv, xl) = (self.viewer.x, self.light.x);
        if xv == xl {
            return DVec3::new(xl, 0.0, z);
        }
        // v_X + l_X is strictly decreasing in x, positive at min(xv, xl), negative at max.
        let (v, l) = (self.viewer, self.light);
        let g = |x: f64| {
            let p = DVec3::new(x, 0.0, z);
            (v.x - x) / (v - p).length() + (l.x - x) / (l - p).length()
        };
        DVec3::new(bisect(g, xv.min(xl), xv.max(xl)), 0.0, z)
    }

    /// The signed lean of the `h_X = 0` family's half vector at depth `z`, in degrees:
    /// positive when `h` leans towards the light (away from the viewer).
    fn plane_lean_deg(&self, z: f64) -> f64 {
        let p = self.plane_point(z);
        let r = self.reflection_at(p.x, p.z);
        r.h.z.atan2(r.h.y).to_degrees()
    }

    /// The ground depths of the locus: from the viewer's depth to the light's, narrowed to
    /// where the tilt of `h` is at most `max_tilt_deg` if given (the tilt is zero at the
    /// mirror point and grows monotonically towards both ends).
    pub fn depth_range(&self, max_tilt_deg: Option<f64>) -> Result<(f64, f64), ModelError> {
        let (near, far) = (self.viewer.z, self.light.z);
        let Some(max) = check_tilt(max_tilt_deg)? else {
            return Ok((near, far));
        };
        let zm = self.mirror_point().z;
        let lo = if self.plane_lean_deg(near) <= max {
            near
        } else {
            bisect(|z| self.plane_lean_deg(z) - max, near, zm)
        };
        let hi = if self.plane_lean_deg(far) >= -max {
            far
        } else {
            bisect(|z| self.plane_lean_deg(z) + max, zm, far)
        };
        Ok((lo, hi))
    }

    /// The locus of `L_virtual` for the `h_X = 0` family: `samples` ground depths equally
    /// spaced over [`Self::depth_range`], nearest first, both ends included except the
    /// viewer's own depth (then the samples are `lo + k (hi - lo) / samples`, k = 1..=samples).
    /// One sample is the mirror point.
    pub fn locus(
        &self,
        max_tilt_deg: Option<f64>,
        samples: usize,
    ) -> Result<Vec<Reflection>, ModelError> {
        if samples == 0 {
            return Err(ModelError::NoSamples);
        }
        let (lo, hi) = self.depth_range(max_tilt_deg)?;
        // The viewer's own depth is left out: L_virtual is then straight below the viewer,
        // at zero depth, and has no disparity.
        let skip_near = lo == self.viewer.z;
        let depth = |i: usize| {
            if samples == 1 {
                self.mirror_point().z
            } else if skip_near {
                lo + (hi - lo) * (i + 1) as f64 / samples as f64
            } else {
                lo + (hi - lo) * i as f64 / (samples - 1) as f64
            }
        };
        Ok((0..samples)
            .map(|i| {
                let p = self.plane_point(depth(i));
                self.reflection_at(p.x, p.z)
            })
            .collect())
    }

    /// The locus with what a stereo rig centred on the viewer (looking along +Z, level, eyes
    /// `baseline` apart along X) sees of it: elevation of each ground point and angular
    /// disparity of each `L_virtual` ([`RoadRig::elevation_deg`],
    /// [`RoadRig::angular_disparity_deg`]).
    pub fn locus_profile(
        &self,
        max_tilt_deg: Option<f64>,
        samples: usize,
        baseline: f64,
    ) -> Result<Vec<LocusPoint>, ModelError> {
        let rig = RoadRig::level(self.viewer, 1.0, baseline)?;
        Ok(self
            .locus(max_tilt_deg, samples)?
            .into_iter()
            .map(|r| LocusPoint::new(r, &rig))
            .collect())
    }

    /// Checks the proposition numerically for the ground point `(x, 0, z)` and each viewer
    /// offset `s` in `offsets` (viewer moved to `X_V + (s, 0, 0)`); see the module docs.
    pub fn check_invariance(
        &self,
        x: f64,
        z: f64,
        offsets: &[f64],
    ) -> Result<InvarianceReport, ModelError> {
        finite("the ground point's x", x)?;
        finite("the ground depth", z)?;
        if !(z >= self.viewer.z && z <= self.light.z) {
            return Err(ModelError::DepthOutOfRange {
                depth: z,
                near: self.viewer.z,
                far: self.light.z,
            });
        }
        let reference = self.reflection_at(x, z);
        let target = reference.h.x;
        let mut samples = Vec::with_capacity(offsets.len());
        for &s in offsets {
            finite("a viewer offset", s)?;
            let moved = self.with_viewer(self.viewer + DVec3::new(s, 0.0, 0.0))?;
            // h_X of the moved viewer along the line tends to +1 as x -> -inf and -1 as
            // x -> +inf, and |target| < 1: widen a bracket around x until the sign changes.
            let f = |xi: f64| moved.reflection_at(xi, z).h.x - target;
            let mut w = 1.0 + s.abs();
            let (mut lo, mut hi) = (x - w, x + w);
            while (f(lo) <= 0.0 || f(hi) >= 0.0) && w < 1e12 {
                w *= 2.0;
                lo = x - w;
                hi = x + w;
            }
            let xs = bisect(f, lo, hi);
            let r = moved.reflection_at(xs, z);
            let cos = r.h.dot(reference.h).clamp(-1.0, 1.0);
            // The angle from the cross product's length is accurate for tiny angles.
            let h_residual_deg = r.h.cross(reference.h).length().atan2(cos).to_degrees();
            samples.push(InvarianceSample {
                offset: s,
                reflection: r,
                h_residual_deg,
                deviation: (r.virtual_light - reference.virtual_light).length(),
            });
        }
        let max_deviation = samples.iter().map(|s| s.deviation).fold(0.0, f64::max);
        let max_h_residual_deg = samples.iter().map(|s| s.h_residual_deg).fold(0.0, f64::max);
        Ok(InvarianceReport {
            reference,
            samples,
            max_deviation,
            max_h_residual_deg,
        })
    }
}

/// One viewer offset of an invariance check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvarianceSample {
    /// The viewer's offset along X.
    pub offset: f64,
    /// The glint the moved viewer sees on the same constant-depth line.
    pub reflection: Reflection,
    /// The angle between its half vector and the reference one, degrees (0 when `h_X = 0`).
    pub h_residual_deg: f64,
    /// `|L_virtual - L_virtual(reference)|`, metres.
    pub deviation: f64,
}

/// The result of [`ColumnModel::check_invariance`].
#[derive(Debug, Clone, PartialEq)]
pub struct InvarianceReport {
    /// The glint seen by the unmoved viewer.
    pub reference: Reflection,
    /// One entry per viewer offset, in the order given.
    pub samples: Vec<InvarianceSample>,
    /// The largest `deviation`, metres.
    pub max_deviation: f64,
    /// The largest `h_residual_deg`.
    pub max_h_residual_deg: f64,
}

/// A locus point with what the viewer's stereo rig sees of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocusPoint {
    /// The glint.
    pub reflection: Reflection,
    /// Elevation angle below the horizon of the ground point seen from the rig centre, degrees
    /// ([`RoadRig::elevation_deg`]).
    pub elevation_deg: f64,
    /// Angular disparity of `L_virtual`, degrees ([`RoadRig::angular_disparity_deg`]).
    pub disparity_deg: f64,
    /// Pixel disparity of `L_virtual` (Eq. 5, [`RoadRig::disparity_px`]).
    pub disparity_px: f64,
}

impl LocusPoint {
    fn new(reflection: Reflection, rig: &RoadRig) -> Self {
        Self {
            reflection,
            elevation_deg: rig.elevation_deg(reflection.ground),
            disparity_deg: rig.angular_disparity_deg(reflection.virtual_light),
            disparity_px: rig.disparity_px(reflection.virtual_light),
        }
    }
}

/// One image row of a streak.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreakRow {
    /// The image row `j` (the pixel centre is at `y = j + 0.5`).
    pub row: u32,
    /// The glint at the ground point seen through the row at the streak's column, with its
    /// elevation and disparities.
    pub point: LocusPoint,
}

/// The model's prediction for every image row of a streak: for each row in `rows` the ground
/// point seen by the rig centre through `(column, row + 0.5)`, its glint (with the rig centre
/// as the viewer) and the disparities of its `L_virtual`. `column` defaults to where the
/// light's mirror image `(X_L, -Y_L, Z_L)` projects (the streak's centre line). Rows that do
/// not see the road between the viewer's and the light's depth, or whose tilt exceeds
/// `max_tilt_deg`, are left out. Off the light's X plane the ground points have `h_X != 0`.
pub fn streak_rows(
    light: DVec3,
    rig: &RoadRig,
    rows: std::ops::Range<u32>,
    column: Option<f64>,
    max_tilt_deg: Option<f64>,
) -> Result<Vec<StreakRow>, ModelError> {
    let model = ColumnModel::new(light, rig.centre())?;
    let max_tilt = check_tilt(max_tilt_deg)?;
    let column = match column {
        Some(c) => finite("the streak's column", c)?,
        None => {
            rig.project(light * DVec3::new(1.0, -1.0, 1.0))
                .ok_or(ModelError::MirrorBehindCamera)?
                .x
        }
    };
    let (near, far) = (model.viewer().z, model.light().z);
    let mut out = Vec::new();
    for row in rows {
        let Some(g) = rig.ground_point(DVec2::new(column, row as f64 + 0.5)) else {
            continue;
        };
        if g.z < near || g.z > far {
            continue;
        }
        let r = model.reflection_at(g.x, g.z);
        if max_tilt.is_some_and(|m| r.tilt_deg > m) {
            continue;
        }
        out.push(StreakRow {
            row,
            point: LocusPoint::new(r, rig),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig6() -> ColumnModel {
        ColumnModel::new(DVec3::new(0.0, 1.5, 15.0), DVec3::new(0.0, 1.5, 0.0)).unwrap()
    }

    fn span(values: impl Iterator<Item = f64> + Clone) -> f64 {
        values.clone().fold(f64::NEG_INFINITY, f64::max) - values.fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn h_is_a_unit_bisector() {
        let (x, v, l) = (
            DVec3::new(0.3, 0.0, 4.0),
            DVec3::new(-1.0, 1.4, 0.0),
            DVec3::new(2.0, 5.0, 20.0),
        );
        let h = half_vector(x, v, l).unwrap();
        assert!((h.length() - 1.0).abs() < 1e-15);
        let (vd, ld) = ((v - x).normalize(), (l - x).normalize());
        assert!((h.dot(vd) - h.dot(ld)).abs() < 1e-15, "equal angles");
        assert!(h.dot(vd.cross(ld)).abs() < 1e-15, "in the plane of v and l");
        // Mirroring l about h gives v: h is the microfacet normal of the reflection.
        let mirrored = 2.0 * h.dot(ld) * h - ld;
        assert!((mirrored - vd).length() < 1e-14);
        assert!(half_vector(x, x, l).is_none());
    }

    #[test]
    fn vertical_h_gives_the_mirror_image() {
        let m = ColumnModel::new(DVec3::new(0.7, 3.0, 25.0), DVec3::new(0.7, 1.2, 0.0)).unwrap();
        let p = m.mirror_point();
        let r = m.reflection_at(p.x, p.z);
        assert!(r.tilt_deg < 1e-6, "tilt {}", r.tilt_deg);
        assert!((r.virtual_light - DVec3::new(0.7, -3.0, 25.0)).length() < 1e-12);
        // And directly: Eq. 4 with h = +Y is the mirror image for any ground point.
        let lv = virtual_light(DVec3::new(5.0, 0.0, 3.0), DVec3::Y, m.light());
        assert!((lv - DVec3::new(0.7, -3.0, 25.0)).length() < 1e-14);
        // The mirror point is also the h_X = 0 point of its depth, for an off-plane viewer too.
        let m2 = m.with_viewer(DVec3::new(-2.0, 1.2, 0.0)).unwrap();
        let p2 = m2.mirror_point();
        assert!((m2.plane_point(p2.z) - p2).length() < 1e-12);
        assert!(m2.reflection_at(p2.x, p2.z).tilt_deg < 1e-6);
    }

    #[test]
    fn invariance_holds_to_rounding_for_the_hx0_family() {
        let offsets = [-3.0, -0.5, -0.0325, 0.0325, 0.5, 1.0, 7.0];
        for (light, viewer) in [
            (DVec3::new(0.0, 1.5, 15.0), DVec3::new(0.0, 1.5, 0.0)),
            (DVec3::new(2.0, 6.0, 40.0), DVec3::new(2.0, 1.2, 3.0)),
        ] {
            let m = ColumnModel::new(light, viewer).unwrap();
            for z in [viewer.z + 0.5, m.mirror_point().z, light.z - 0.5] {
                let rep = m.check_invariance(light.x, z, &offsets).unwrap();
                assert_eq!(rep.reference.h.x, 0.0);
                assert!(rep.max_deviation < 1e-12, "deviation {}", rep.max_deviation);
                assert!(rep.max_h_residual_deg < 1e-12);
                for s in &rep.samples {
                    // The proof's point: the ray from L_virtual through (X_L + t, 0, Z) meets
                    // the viewer's height at X_V + s, so t = s * (-L_y) / (Y_V - L_y).
                    let lv = rep.reference.virtual_light;
                    let t = s.offset * (-lv.y) / (viewer.y - lv.y);
                    assert!((s.reflection.ground.x - (light.x + t)).abs() < 1e-12);
                }
            }
            // An off-plane viewer's h_X = 0 point has the in-plane viewer's L_virtual.
            let moved = m.with_viewer(viewer + DVec3::new(1.7, 0.0, 0.0)).unwrap();
            let z = 0.5 * (viewer.z + light.z);
            let p = moved.plane_point(z);
            let a = moved.reflection_at(p.x, z).virtual_light;
            let b = m.reflection_at(light.x, z).virtual_light;
            assert!((a - b).length() < 1e-12);
        }
    }

    #[test]
    fn invariance_fails_off_the_hx0_family() {
        let m = fig6();
        // A ground point 0.5 m beside the light's plane at 6 m: h_X != 0.
        let rep = m
            .check_invariance(0.5, 6.0, &[-0.0325, 0.0325, 0.5])
            .unwrap();
        assert!(rep.reference.h.x.abs() > 1e-3);
        // Eye-sized offsets (half of a 6.5 cm baseline) already move L_virtual by 2.6 mm and
        // a 0.5 m offset by 4 cm (rounding is 1e-15 m); no point of the line reproduces h.
        assert!(rep.samples[0].deviation > 2e-3, "{:?}", rep.samples[0]);
        assert!(rep.samples[1].deviation > 2e-3, "{:?}", rep.samples[1]);
        assert!(rep.max_deviation > 0.03, "{}", rep.max_deviation);
        assert!(rep.max_h_residual_deg > 1e-3);
    }

    #[test]
    fn columns_slant_as_in_fig5() {
        let m = fig6();
        let image = DVec3::new(0.0, -1.5, 15.0);
        let zm = m.mirror_point().z;
        assert!((zm - 7.5).abs() < 1e-12);
        for r in m.locus(Some(4.0), 41).unwrap() {
            let (lv, z) = (r.virtual_light, r.ground.z);
            assert!(r.tilt_deg <= 4.0 + 1e-9);
            if z < zm - 1e-9 {
                assert!(r.h.z > 0.0, "near: h leans away from the viewer");
                assert!(
                    lv.y < image.y && lv.z < image.z,
                    "near: deeper and nearer {lv}"
                );
            } else if z > zm + 1e-9 {
                assert!(r.h.z < 0.0, "far: h leans towards the viewer");
                assert!(lv.y > image.y && lv.y < 0.0 && lv.z > image.z, "far {lv}");
            }
        }
    }

    #[test]
    fn tilt_filter_bounds_the_depth_range() {
        let m = fig6();
        let (lo, hi) = m.depth_range(Some(4.0)).unwrap();
        assert!((m.reflection_at(0.0, lo).tilt_deg - 4.0).abs() < 1e-9);
        assert!((m.reflection_at(0.0, hi).tilt_deg - 4.0).abs() < 1e-9);
        assert_eq!(m.depth_range(None).unwrap(), (0.0, 15.0));
        assert_eq!(m.locus(None, 1).unwrap()[0].ground.z, 7.5);
        let all = m.locus_profile(None, 3, 0.065).unwrap();
        let z: Vec<f64> = all.iter().map(|p| p.reflection.ground.z).collect();
        assert_eq!(z, [5.0, 10.0, 15.0], "the viewer's own depth is left out");
        assert!(all
            .iter()
            .all(|p| p.disparity_deg > 0.2 && p.disparity_deg < 0.3));
        assert!(matches!(m.locus(Some(4.0), 0), Err(ModelError::NoSamples)));
        assert!(matches!(
            m.locus(Some(0.0), 3),
            Err(ModelError::BadTilt { .. })
        ));
        assert!(matches!(
            m.locus(Some(f64::NAN), 3),
            Err(ModelError::BadTilt { .. })
        ));
    }

    #[test]
    fn fig6_disparity_range_and_elevation_span() {
        // The model is exact f64 geometry and the depth range comes from a bisection down to
        // adjacent floats, so the numbers are reproducible to about 1e-12 degrees; the
        // tolerances (half a unit of the last digit pinned) only absorb rounding in the
        // printed constants. Both curves are monotone in depth (checked with 401 samples), so
        // the ranges are the differences between the ends.
        let m = fig6();
        let check = |tilt: f64, near: f64, far: f64, elev: f64, disp: f64| {
            let pts = m.locus_profile(Some(tilt), 401, 0.065).unwrap();
            let e = span(pts.iter().map(|p| p.elevation_deg));
            let d = span(pts.iter().map(|p| p.disparity_deg));
            let (first, last) = (pts[0], pts[400]);
            assert_eq!(e, first.elevation_deg - last.elevation_deg);
            assert_eq!(d, first.disparity_deg - last.disparity_deg);
            assert!(
                (first.reflection.ground.z - near).abs() < 5e-5,
                "tilt {tilt}"
            );
            assert!((last.reflection.ground.z - far).abs() < 5e-5, "tilt {tilt}");
            assert!((e - elev).abs() < 5e-10, "tilt {tilt}: elevation span {e}");
            assert!((d - disp).abs() < 5e-10, "tilt {tilt}: disparity range {d}");
        };
        // Fig. 4's filter: 8 degrees exactly (twice the limit, equal heights), 0.00778 degrees.
        check(4.0, 5.0424, 9.9576, 8.0, 0.007779953);
        // "Nearly 9 degrees" of elevation needs a 4.5 degree filter.
        check(4.5, 4.7972, 10.2028, 9.0, 0.008982620);
        // And the light's own disparity lies inside the locus's range.
        let pts = m.locus_profile(Some(4.0), 2, 0.065).unwrap();
        let light = 2.0 * (0.0325f64 / 15.0).atan().to_degrees();
        assert!((light - 0.248281).abs() < 5e-7);
        assert!(pts[1].disparity_deg < light && light < pts[0].disparity_deg);
    }

    #[test]
    fn streak_rows_follow_the_locus() {
        let rig = RoadRig::new(
            DVec3::new(0.0, 1.5, 0.0),
            2f64.to_radians(),
            800.0,
            DVec2::new(400.0, 300.0),
            0.065,
        )
        .unwrap();
        let light = DVec3::new(0.0, 1.5, 15.0);
        let rows = streak_rows(light, &rig, 0..600, None, Some(4.0)).unwrap();
        assert!(rows.len() > 10);
        let m = ColumnModel::new(light, rig.centre()).unwrap();
        for s in &rows {
            // The light is in the viewer's X plane, so the streak column's ground points are
            // the h_X = 0 family: the same L_virtual as the locus at that depth.
            let lv = m
                .reflection_at(0.0, s.point.reflection.ground.z)
                .virtual_light;
            assert!(s.point.reflection.ground.x.abs() < 1e-9);
            assert!((s.point.reflection.virtual_light - lv).length() < 1e-9);
            assert!(s.point.reflection.tilt_deg <= 4.0);
        }
        // Rows go down the image as the ground point comes nearer.
        assert!(rows
            .windows(2)
            .all(|w| w[0].point.reflection.ground.z > w[1].point.reflection.ground.z));
        // An off-centre column sees ground points with h_X != 0.
        let off = streak_rows(light, &rig, 0..600, Some(500.0), None).unwrap();
        assert!(off.iter().all(|s| s.point.reflection.h.x.abs() > 1e-4));
    }

    #[test]
    fn bad_configurations_are_errors() {
        let v = DVec3::new(0.0, 1.5, 0.0);
        assert!(matches!(
            ColumnModel::new(DVec3::new(f64::NAN, 1.0, 5.0), v),
            Err(ModelError::NotFinite { .. })
        ));
        assert!(matches!(
            ColumnModel::new(DVec3::new(0.0, -1.0, 5.0), v),
            Err(ModelError::LightBelowRoad { .. })
        ));
        assert!(matches!(
            ColumnModel::new(DVec3::new(0.0, 1.0, 0.0), v),
            Err(ModelError::ViewerAtLightDepth { .. })
        ));
        assert!(matches!(
            ColumnModel::new(DVec3::new(0.0, 1.0, -5.0), v),
            Err(ModelError::LightBehindViewer { .. })
        ));
        assert!(matches!(
            ColumnModel::new(DVec3::new(0.0, 1.0, 5.0), DVec3::new(0.0, 0.0, 0.0)),
            Err(ModelError::ViewerBelowRoad { .. })
        ));
        let m = fig6();
        assert!(matches!(
            m.check_invariance(0.0, 20.0, &[1.0]),
            Err(ModelError::DepthOutOfRange { .. })
        ));
        assert!(matches!(
            m.locus_profile(None, 3, 0.0),
            Err(ModelError::Rig(StereoError::Parameter {
                name: "baseline",
                ..
            }))
        ));
    }
}
