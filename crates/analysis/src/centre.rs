//! The streak-centre model: where along each image row a streak is brightest, in each eye, and
//! the disparity that gives. It explains why measured streak disparity is flat (the paper's
//! Fig. 6) where Eq. 4's locus is not.
//!
//! # The model
//!
//! Every image row of a rectified, roll-free rig sees one line of the road parallel to X, at a
//! depth `z` that is the same for both eyes (they differ only along X). Along that line the
//! glint at ground point `X = (x, 0, z)` needs the microfacet normal `h(x)` (Eq. 2, for that
//! eye and the light), and an isotropic microfacet distribution `D(h)` (GGX, Beckmann, Ward,
//! Blinn-Phong) is largest where `h` is closest to the normal `+Y`. So the row's brightest
//! point, the streak's centre in that eye, is the `x` that maximises `h_y(x)`
//! ([`row_peak`]). (The BRDF's other factors, Fresnel, shadowing and the cosines, vary slowly
//! along the row and move the peak by far less; they are ignored.) Its disparity is the
//! difference of the columns at which the two eyes see their own peaks ([`CentreModel::row`]).
//!
//! # Why it is flat
//!
//! Take the vertical plane `P_e` through the eye `E` and the light's vertical line (the line
//! through `X_L` along `Y`). For a ground point `X` in `P_e`, both `v = E - X` and `l = X_L - X`
//! lie in `P_e`, so `h` does too: its only horizontal component lies along `P_e`, and moving
//! `X` out of the plane adds a horizontal component across it. When the row's line crosses
//! `P_e` at right angles (eye and light in one X plane) the plane is a mirror symmetry of the
//! row, so `h_y` is stationary exactly on it. Otherwise the peak lies near it
//! ([`CentreRow::plane_offset`]): in the paper's Fig. 6 each eye is 3.25 cm to the side of the
//! light's X plane and its peak is off its plane by at most 12 micrometres (zero at the
//! mirror point); for a lamp 3 m to the side and 15 m ahead, by millimetres.
//!
//! Every point of `P_e` is seen by that eye along the image of the light's vertical line,
//! because `P_e` contains the eye: the whole plane projects to one image line, and for a level
//! rig that is the column of the light itself. So each eye sees its streak centre, row after
//! row, on the image of the light's vertical line: for a level rig the light's own column, and
//! the disparity of the streak centre is the light's own disparity `f b / Z_L` on every row: a
//! column of light at the light's depth, not at the depths of Eq. 4's virtual lights. (For a
//! rig pitched down by `p` the vertical line's image leans towards the nadir's vanishing point,
//! `f cot p` pixels below the principal point, and the disparity scales with the row's distance
//! from it: by under 1 % over a streak at 2 degrees of pitch.)
//!
//! # Where it departs from Eq. 4
//!
//! Eq. 4 mirrors the light about the one microfacet plane that reflects it into the rig
//! centre at a ground point; its virtual light's depth slides with the half vector's slant
//! (the paper's Fig. 5), from nearer than the light at the near end of the streak to farther
//! at the far end. The two models agree only at the mirror point, where `h` is vertical and
//! Eq. 4's virtual light is the light's mirror image, at the light's depth. In the paper's
//! Fig. 6 configuration (f = 1058 px, where Eq. 4's 0.0078 degrees are 0.144 px) over the
//! 4-degree tilt range, Eq. 4's disparity falls by 0.144 px from the near end to the far
//! end; the streak-centre model's falls by 0.0074 px (from 4.5896 to 4.5822 px, the light's
//! being 4.5847), nineteen times less, because the peaks leave their planes by those
//! micrometres; the rendered streak's measured span is 0.009 px. (Tests pin these numbers.)

use crate::model::{half_vector, tilt_deg, virtual_light, ColumnModel, ModelError};
use glam::DVec3;
use streaks_stereo::rig::{Eye, RoadRig};

/// The `x` of the ground line `(x, 0, z)` whose half vector (for `eye` and `light`) is
/// closest to the vertical: the streak's centre in that row for an isotropic microfacet
/// distribution. `h_y(x)` is unimodal along the line (it falls off on both sides of the
/// peak), but flat at its top, so comparing values finds the peak to only about 1e-8 of the
/// bracket: a golden-section search brackets it, then bisection on the sign of the central
/// difference `h_y(x + d) - h_y(x - d)` pins it to about 1e-12 m.
pub fn row_peak(eye: DVec3, light: DVec3, z: f64) -> f64 {
    let h_y = |x: f64| {
        half_vector(DVec3::new(x, 0.0, z), eye, light)
            .map(|h| h.y)
            .unwrap_or(f64::NEG_INFINITY)
    };
    let reach = 2.0 * (light.z - eye.z).abs() + (light.x - eye.x).abs() + 1.0;
    let (mut a, mut b) = (eye.x.min(light.x) - reach, eye.x.max(light.x) + reach);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (h_y(c), h_y(d));
    while (b - a).abs() > 1e-5 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = h_y(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = h_y(d);
        }
    }
    let slope = |x: f64| h_y(x + 1e-5) - h_y(x - 1e-5);
    let (mut lo, mut hi) = (a - 1e-5, b + 1e-5);
    if !(slope(lo) > 0.0 && slope(hi) < 0.0) {
        return 0.5 * (a + b);
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        if slope(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// One image row (one ground depth) of the streak-centre model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentreRow {
    /// The ground line's depth `z` (road frame).
    pub ground_z: f64,
    /// The left eye's streak centre on that line, `x`.
    pub left_x: f64,
    /// The right eye's streak centre, `x`.
    pub right_x: f64,
    /// The angle of the left eye's peak half vector from the vertical, degrees.
    pub tilt_deg: f64,
    /// Elevation below the horizon of the left peak seen from the rig centre, degrees.
    pub elevation_deg: f64,
    /// Pixel disparity of the streak centre: the left eye's column of its peak minus the right
    /// eye's column of its own peak.
    pub disparity_px: f64,
    /// Angular disparity of the streak centre, degrees (left azimuth minus right azimuth).
    pub disparity_deg: f64,
    /// Distance of the left peak from the vertical plane through the left eye and the light's
    /// vertical line, metres (see the module documentation).
    pub plane_offset: f64,
    /// Eq. 4's pixel disparity for the same depth (the rig centre's `h_X = 0` point), for
    /// comparison.
    pub eq4_disparity_px: f64,
    /// Eq. 4's angular disparity, degrees.
    pub eq4_disparity_deg: f64,
}

/// The streak-centre model of one point light for one stereo rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentreModel {
    column: ColumnModel,
    rig: RoadRig,
}

/// Distance of ground point `p` from the vertical plane through `eye` and the vertical line of
/// `light` (horizontal distance from the line through their ground projections).
fn plane_distance(p: DVec3, eye: DVec3, light: DVec3) -> f64 {
    let (a, b) = (
        glam::DVec2::new(eye.x, eye.z),
        glam::DVec2::new(light.x, light.z),
    );
    let q = glam::DVec2::new(p.x, p.z);
    let d = (b - a).normalize_or_zero();
    (q - a).perp_dot(d).abs()
}

impl CentreModel {
    /// The model for `light` seen by `rig` (road frame); the same checks as Eq. 4's
    /// [`ColumnModel::new`] with the rig centre as the viewer.
    pub fn new(light: DVec3, rig: RoadRig) -> Result<Self, ModelError> {
        Ok(Self {
            column: ColumnModel::new(light, rig.centre())?,
            rig,
        })
    }

    /// Eq. 4's model for the same light and rig centre.
    pub fn column(&self) -> &ColumnModel {
        &self.column
    }

    /// The row of ground depth `z` (between the rig and the light).
    pub fn row(&self, z: f64) -> CentreRow {
        let light = self.column.light();
        let (le, re) = (
            self.rig.eye_position(Eye::Left),
            self.rig.eye_position(Eye::Right),
        );
        let (lx, rx) = (row_peak(le, light, z), row_peak(re, light, z));
        let (lp, rp) = (DVec3::new(lx, 0.0, z), DVec3::new(rx, 0.0, z));
        let h = half_vector(lp, le, light).unwrap_or(DVec3::Y);
        let (cl, cr) = (
            self.rig.project_eye(Eye::Left, lp),
            self.rig.project_eye(Eye::Right, rp),
        );
        let disparity_px = match (cl, cr) {
            (Some(a), Some(b)) => a.x - b.x,
            _ => f64::NAN,
        };
        // Azimuths in each eye's camera frame: lateral offset over depth along the axis.
        let azimuth = |p: DVec3, eye: DVec3| {
            let d = p - eye;
            let depth = d.dot(self.rig.forward());
            d.x.atan2(depth)
        };
        let disparity_deg = (azimuth(lp, le) - azimuth(rp, re)).to_degrees();
        let centre_point = self.column.plane_point(z);
        let r = self.column.reflection_at(centre_point.x, centre_point.z);
        let lv = virtual_light(r.ground, r.h, light);
        CentreRow {
            ground_z: z,
            left_x: lx,
            right_x: rx,
            tilt_deg: tilt_deg(h),
            elevation_deg: self.rig.elevation_deg(lp),
            disparity_px,
            disparity_deg,
            plane_offset: plane_distance(lp, le, light),
            eq4_disparity_px: self.rig.disparity_px(lv),
            eq4_disparity_deg: self.rig.angular_disparity_deg(lv),
        }
    }

    /// Rows at `samples` ground depths equally spaced over Eq. 4's
    /// [`ColumnModel::depth_range`] (same tilt filter, same sampling as
    /// [`ColumnModel::locus`]), nearest first.
    pub fn rows(
        &self,
        max_tilt_deg: Option<f64>,
        samples: usize,
    ) -> Result<Vec<CentreRow>, ModelError> {
        Ok(self
            .column
            .locus(max_tilt_deg, samples)?
            .into_iter()
            .map(|r| self.row(r.ground.z))
            .collect())
    }

    /// The light's own pixel disparity `f b / Z_L` (what the model predicts on every row when
    /// the peaks lie in their eyes' planes).
    pub fn light_disparity_px(&self) -> f64 {
        self.rig.disparity_px(self.column.light())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn span(v: impl Iterator<Item = f64> + Clone) -> f64 {
        v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
    }

    /// The paper's Fig. 6: light 15 m ahead at 1.5 m, rig at 1.5 m, b = 6.5 cm.
    fn fig6(focal: f64) -> CentreModel {
        let rig = RoadRig::level(DVec3::new(0.0, 1.5, 0.0), focal, 0.065).unwrap();
        CentreModel::new(DVec3::new(0.0, 1.5, 15.0), rig).unwrap()
    }

    #[test]
    fn peak_maximises_h_y_by_brute_force() {
        for (eye, light, z) in [
            (DVec3::new(0.0, 1.5, 0.0), DVec3::new(0.0, 1.5, 15.0), 6.0),
            (
                DVec3::new(-0.03, 1.2, 0.0),
                DVec3::new(3.0, 6.0, 30.0),
                12.0,
            ),
            (DVec3::new(1.0, 1.4, 2.0), DVec3::new(-4.0, 5.0, 25.0), 20.0),
        ] {
            let x = row_peak(eye, light, z);
            let hy = |x: f64| half_vector(DVec3::new(x, 0.0, z), eye, light).unwrap().y;
            let best = (-20000..=20000)
                .map(|k| k as f64 * 1e-3)
                .max_by(|a, b| hy(*a).total_cmp(&hy(*b)))
                .unwrap();
            assert!((x - best).abs() < 2e-3, "{x} vs brute force {best}");
            assert!(hy(x) >= hy(x + 1e-4) && hy(x) >= hy(x - 1e-4));
        }
    }

    #[test]
    fn symmetric_peaks_lie_on_the_light_plane() {
        // Eye and light in one X plane: the peak is exactly below the line joining them.
        let (eye, light) = (DVec3::new(0.4, 1.3, 0.0), DVec3::new(0.4, 5.0, 20.0));
        for z in [2.0, 5.0, 9.0, 15.0] {
            assert!((row_peak(eye, light, z) - 0.4).abs() < 1e-8);
        }
    }

    #[test]
    fn fig6_centre_disparity_is_the_lights_and_flat() {
        let m = fig6(1058.0);
        let rows = m.rows(Some(4.0), 41).unwrap();
        let d_light = m.light_disparity_px();
        for r in &rows {
            assert!(
                (r.disparity_px - d_light).abs() < 0.006,
                "{r:?} vs {d_light}"
            );
            assert!(r.plane_offset < 1.2e-5, "{r:?}");
        }
        let centre_span = span(rows.iter().map(|r| r.disparity_px));
        let eq4_span = span(rows.iter().map(|r| r.eq4_disparity_px));
        assert!(
            (centre_span - 0.0074).abs() < 0.0002,
            "centre span {centre_span} px"
        );
        assert!(
            (eq4_span - 0.1437).abs() < 0.0005,
            "Eq. 4 span {eq4_span} px"
        );
        // Eq. 4's span in degrees over the 4-degree filter, as pinned in model.rs.
        let eq4_deg = span(rows.iter().map(|r| r.eq4_disparity_deg));
        assert!((eq4_deg - 0.007780).abs() < 2e-6, "{eq4_deg}");
        // The two agree at the mirror point (7.5 m).
        let mid = m.row(7.5);
        assert!(
            (mid.disparity_px - mid.eq4_disparity_px).abs() < 1e-6,
            "{mid:?}"
        );
    }

    #[test]
    fn off_plane_lamps_stay_nearly_flat() {
        // A street lamp 3 m to the side and 15 m ahead, 5 m up; a pitched rig.
        let rig = RoadRig::new(
            DVec3::new(0.0, 1.3, 0.0),
            2f64.to_radians(),
            800.0,
            DVec2::new(320.0, 192.0),
            0.3,
        )
        .unwrap();
        let m = CentreModel::new(DVec3::new(3.0, 5.0, 15.0), rig).unwrap();
        let rows = m.rows(Some(6.0), 30).unwrap();
        let offsets: Vec<f64> = rows.iter().map(|r| r.plane_offset).collect();
        let max_offset = offsets.iter().fold(0.0f64, |a, b| a.max(*b));
        assert!(
            max_offset > 1e-4 && max_offset < 0.1,
            "plane offset {max_offset} m"
        );
        let centre = span(rows.iter().map(|r| r.disparity_px));
        let eq4 = span(rows.iter().map(|r| r.eq4_disparity_px));
        assert!(
            centre < 0.2 * eq4,
            "centre span {centre} px vs Eq. 4 {eq4} px"
        );
        let d_light = m.light_disparity_px();
        for r in &rows {
            assert!(
                (r.disparity_px - d_light).abs() < 0.05 * d_light,
                "{r:?} vs {d_light}"
            );
        }
    }
}
