//! Whether the road is the plane the analysis assumes.
//!
//! Eq. 4, the streak-centre model and every road-frame height of the report take the road to
//! be the plane `Y = 0` of the rig's road frame ([`streaks_stereo::rig::RoadFrame`]). A
//! sloped, crested, cambered or crowned road is not, and a prediction made on that plane is
//! then wrong by more than the effect it measures. [`RoadPlaneCheck`] measures how far the
//! actual road departs from the plane, from a sample's ground truth: the left view's depth and
//! road-surface mask give the road's 3-D points, within [`RANGE_M`] of the rig (horizontal
//! distance in the road frame). It reports their RMS and largest height above or below `Y = 0`
//! and the tilt of the plane fitted to them (least squares `Y = a X + b Z + c`), and calls the
//! assumption violated beyond [`HEIGHT_TOLERANCE_M`] or [`TILT_TOLERANCE_DEG`]. What the
//! analysis then does is docs/decisions/0048-eq4-skipped-off-the-road-plane.md.

use glam::{DVec3, Vec2};
use serde::Serialize;
use streaks_image::GrayImage;
use streaks_stereo::rig::{Eye, Rig};

/// Largest height of a road point above or below the plane `Y = 0` that still counts as on
/// it, metres (a kerb-side gutter or a drain's dip; a 1 % cross-fall over a 3.5 m lane is 3.5 cm).
pub const HEIGHT_TOLERANCE_M: f64 = 0.05;
/// Largest tilt of the fitted road plane against `Y = 0`, degrees.
pub const TILT_TOLERANCE_DEG: f64 = 1.0;
/// Road points farther than this from the rig (horizontal distance) are not looked at, metres:
/// the streaks the analysis measures lie within it.
pub const RANGE_M: f64 = 30.0;
/// Fewest road points for a check; with fewer there is none.
pub const MIN_POINTS: usize = 20;

/// How far a sample's road departs from the plane `Y = 0` of its road frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RoadPlaneCheck {
    /// Road points looked at (within [`RANGE_M`]).
    pub points: usize,
    /// RMS height of the road points above `Y = 0`, metres.
    pub rms_m: f64,
    /// Largest height above or below `Y = 0` (signed: negative below), metres.
    pub max_m: f64,
    /// Horizontal distance from the rig of the point with the largest height, metres.
    pub max_at_m: f64,
    /// Angle between the plane fitted to the points and `Y = 0`, degrees.
    pub tilt_deg: f64,
    /// Whether the road departs from the plane beyond [`HEIGHT_TOLERANCE_M`] or
    /// [`TILT_TOLERANCE_DEG`]: Eq. 4's predictions are then not made.
    pub violated: bool,
}

impl RoadPlaneCheck {
    /// The check over road points in road-frame coordinates (metres); the points farther than
    /// [`RANGE_M`] or not finite are left out. `None` with fewer than [`MIN_POINTS`] left, or
    /// when they do not span a plane (all on one line).
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Option<Self> {
        // Sums for the least-squares plane y = a x + b z + c, and the height statistics.
        let mut n = 0usize;
        let (mut sx, mut sz, mut sy) = (0.0, 0.0, 0.0);
        let (mut sxx, mut sxz, mut szz, mut sxy, mut szy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let mut syy = 0.0;
        let (mut max_m, mut max_at_m) = (0.0f64, 0.0);
        for p in points {
            let dist = p.x.hypot(p.z);
            if !p.is_finite() || dist > RANGE_M {
                continue;
            }
            n += 1;
            sx += p.x;
            sz += p.z;
            sy += p.y;
            sxx += p.x * p.x;
            sxz += p.x * p.z;
            szz += p.z * p.z;
            sxy += p.x * p.y;
            szy += p.z * p.y;
            syy += p.y * p.y;
            if p.y.abs() > max_m.abs() {
                (max_m, max_at_m) = (p.y, dist);
            }
        }
        if n < MIN_POINTS {
            return None;
        }
        // Normal equations, centred: [cxx cxz; cxz czz] [a b]^T = [cxy czy]^T.
        let nf = n as f64;
        let (mx, mz, my) = (sx / nf, sz / nf, sy / nf);
        let cxx = sxx / nf - mx * mx;
        let cxz = sxz / nf - mx * mz;
        let czz = szz / nf - mz * mz;
        let cxy = sxy / nf - mx * my;
        let czy = szy / nf - mz * my;
        let det = cxx * czz - cxz * cxz;
        if det.is_nan() || det <= 1e-12 * (cxx * czz).max(1e-300) {
            return None;
        }
        let a = (cxy * czz - czy * cxz) / det;
        let b = (czy * cxx - cxy * cxz) / det;
        let tilt_deg = a.hypot(b).atan().to_degrees();
        let violated = max_m.abs() > HEIGHT_TOLERANCE_M || tilt_deg > TILT_TOLERANCE_DEG;
        Some(Self {
            points: n,
            rms_m: (syy / nf).sqrt(),
            max_m,
            max_at_m,
            tilt_deg,
            violated,
        })
    }

    /// The check of a sample: the road points are the left eye's pixels in `road_mask`
    /// (above 0.5) with a finite positive `depth` (view-space Z, metres), back-projected
    /// through their centres into `rig`'s road frame. `None` when the rig has no road frame,
    /// the images' sizes differ from the rig's, or [`Self::from_points`] gives none.
    pub fn from_depth(depth: &GrayImage, road_mask: &GrayImage, rig: &Rig) -> Option<Self> {
        let road = rig.road_frame().ok()?;
        let eye = rig.eye(Eye::Left);
        let i = rig.intrinsics();
        let (w, h) = (i.width() as usize, i.height() as usize);
        if (depth.width, depth.height) != (w, h) || (road_mask.width, road_mask.height) != (w, h) {
            return None;
        }
        let points = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter_map(|(x, y)| {
                let z = depth.data[y * w + x];
                (road_mask.data[y * w + x] > 0.5 && z.is_finite() && z > 0.0).then(|| {
                    let p = eye.back_project(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), z);
                    road.road_from_world_point(p).as_dvec3()
                })
            });
        Self::from_points(points)
    }

    /// One line for a person: `road plane: RMS 0.012 m, max 0.031 m at 12.0 m, tilt 0.10
    /// deg (within 0.05 m and 1 deg)` or, when violated, `road-plane assumption violated: max
    /// 0.31 m at 25.0 m, tilt 2.10 deg; Eq. 4 predictions are not valid for this sample`.
    pub fn message(&self) -> String {
        if self.violated {
            format!(
                "road-plane assumption violated: max {:.2} m at {:.1} m, tilt {:.2} deg, RMS \
                 {:.3} m (tolerance {HEIGHT_TOLERANCE_M} m within {RANGE_M} m, \
                 {TILT_TOLERANCE_DEG} deg); Eq. 4 predictions are not valid for this sample",
                self.max_m, self.max_at_m, self.tilt_deg, self.rms_m
            )
        } else {
            format!(
                "road plane: RMS {:.3} m, max {:.3} m at {:.1} m, tilt {:.2} deg (within \
                 {HEIGHT_TOLERANCE_M} m and {TILT_TOLERANCE_DEG} deg)",
                self.rms_m, self.max_m, self.max_at_m, self.tilt_deg
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Vec3};
    use streaks_stereo::rig::Intrinsics;

    /// A level rig 1.4 m above the road at the origin looking down -Z, pitched 8 degrees
    /// down, and the depth map and road mask of the road surface `y = height(x, z)` seen by
    /// its left eye, found by marching each pixel's ray; the mask is the 7 m carriageway
    /// centred under the rig.
    fn rendered(height: impl Fn(f32, f32) -> f32) -> (GrayImage, GrayImage, Rig) {
        let (w, h) = (160u32, 100u32);
        let pose = Affine3A::from_translation(Vec3::new(0.0, 1.4, 0.0))
            * Affine3A::from_rotation_x(-8f32.to_radians());
        let rig = Rig::new(
            Intrinsics::from_yfov(w, h, 50f32.to_radians()).unwrap(),
            0.3,
            pose,
        )
        .unwrap();
        let eye = rig.eye(Eye::Left);
        let mut depth = GrayImage::new(w as usize, h as usize, 0.0).unwrap();
        let mut mask = GrayImage::new(w as usize, h as usize, 0.0).unwrap();
        for y in 0..h as usize {
            for x in 0..w as usize {
                let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                // March along view-space depth until the ray passes below the surface, then
                // bisect.
                let below = |z: f32| {
                    let p = eye.back_project(px, z);
                    p.y < height(p.x, p.z)
                };
                let (mut lo, mut hi) = (0.01f32, 0.01f32);
                while hi < 60.0 && !below(hi) {
                    lo = hi;
                    hi += 0.05;
                }
                if hi >= 60.0 {
                    depth.data[y * w as usize + x] = f32::INFINITY;
                    continue;
                }
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    if below(mid) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let z = 0.5 * (lo + hi);
                depth.data[y * w as usize + x] = z;
                // The carriageway, 7 m wide: the road mask.
                if eye.back_project(px, z).x.abs() <= 3.5 {
                    mask.data[y * w as usize + x] = 1.0;
                }
            }
        }
        (depth, mask, rig)
    }

    /// A flat road passes, with heights near zero.
    #[test]
    fn a_flat_road_passes() {
        let (d, m, rig) = rendered(|_, _| 0.0);
        let c = RoadPlaneCheck::from_depth(&d, &m, &rig).unwrap();
        assert!(!c.violated, "{c:?}");
        assert!(c.max_m.abs() < 0.005 && c.tilt_deg < 0.05, "{c:?}");
        assert!(c.points > 1000);
    }

    /// A road rising 3 degrees ahead fires, with its tilt measured and the height at 30 m
    /// about 30 tan 3 deg.
    #[test]
    fn a_sloped_road_fires() {
        let slope = 3f32.to_radians().tan();
        let (d, m, rig) = rendered(|_, z| -z * slope);
        let c = RoadPlaneCheck::from_depth(&d, &m, &rig).unwrap();
        assert!(c.violated, "{c:?}");
        assert!((c.tilt_deg - 3.0).abs() < 0.05, "{c:?}");
        assert!(
            c.max_m > 1.0 && c.max_m < RANGE_M * slope as f64 + 0.01,
            "{c:?}"
        );
        assert!(c.message().contains("road-plane assumption violated"));
    }

    /// A crowned road (a parabola 12 cm high over a 7 m carriageway, centred under the rig)
    /// has no tilt but its edges are 12 cm below the crown: it fires on height.
    #[test]
    fn a_crowned_road_fires_on_height() {
        let (d, m, rig) = rendered(|x, _| 0.12 * (1.0 - (x / 3.5).powi(2)) - 0.12);
        let c = RoadPlaneCheck::from_depth(&d, &m, &rig).unwrap();
        assert!(c.violated, "{c:?}");
        assert!(c.tilt_deg < 0.2, "{c:?}");
        assert!(c.max_m < -HEIGHT_TOLERANCE_M, "{c:?}");
    }

    /// Points off the range are not looked at; too few points or a line give no check.
    #[test]
    fn range_and_degenerate_points() {
        let grid = |y: f64| {
            (0..10).flat_map(move |i| {
                (0..10).map(move |k| DVec3::new(i as f64 - 5.0, y, -(k as f64) * 2.0))
            })
        };
        let c =
            RoadPlaneCheck::from_points(grid(0.0).chain([DVec3::new(0.0, 5.0, -40.0)])).unwrap();
        assert_eq!(c.points, 100);
        assert!(!c.violated && c.max_m == 0.0 && c.tilt_deg == 0.0);
        let c = RoadPlaneCheck::from_points(grid(0.06)).unwrap();
        assert!(c.violated && (c.rms_m - 0.06).abs() < 1e-12 && c.tilt_deg.abs() < 1e-9);
        assert!(RoadPlaneCheck::from_points(grid(0.0).take(MIN_POINTS - 1)).is_none());
        let line = (0..50).map(|k| DVec3::new(0.0, 0.0, -(k as f64)));
        assert!(RoadPlaneCheck::from_points(line).is_none());
    }
}
