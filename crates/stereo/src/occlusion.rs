//! Occlusion ground truth of a rectified pair: which pixels of one eye show a point the other
//! eye does not see.
//!
//! A left pixel whose centre ray meets a surface at depth `Z` with disparity `d` sees a point
//! that the right eye images at `x - d` (pixel coordinates, pixel `i` covering `[i, i + 1)`,
//! rows equal). The point is *occluded* in the right eye when that position falls outside
//! the right image (`x - d < 0`), or when the right eye sees something nearer there: both right
//! pixels whose centres bracket `x - d` (the one pixel when `x - d` is a pixel centre or within
//! half a pixel of the border) hold a depth nearer than `Z (1 - DEPTH_TOLERANCE)`. The right
//! eye is symmetric (`x + d`, `x + d >= W` out of view). Pixels without a surface (the sky,
//! `inf`) are never occluded.
//!
//! Why the two bracketing pixels: on a plane `1 / Z` is affine in the image, so of the two
//! pixel centres around `x - d` one is at least as far as the point itself, whatever the
//! plane's slant; a visible point on a smooth surface is therefore never called occluded by
//! sampling between pixel centres. Only a nearer surface covering both bracketing centres, or a
//! surface whose depth differs from its chord between two pixel centres by more than the
//! tolerance (far more curved than the road's crown, ruts or potholes over one pixel), makes a
//! pixel occluded. The tolerance, 0.1 % of the depth (the flow ground truth's occlusion test
//! uses the same), is well above the `f32` depths' rounding (1e-7 relative) and well below
//! the gap between two surfaces that hide one another at street scale (1 cm at 10 m).

use crate::error::StereoError;
use crate::rig::Eye;
use streaks_image::{ensure_same_size, GrayImage};

/// The relative depth difference above which the other eye's surface counts as nearer (see
/// the module documentation).
pub const DEPTH_TOLERANCE: f32 = 1e-3;

/// The occlusion mask of `eye`: 1 where the eye's pixel shows a point the other eye does not
/// see (hidden there or outside its image), 0 elsewhere (also where the pixel has no
/// surface). `depth` and `disparity` are the eye's view-space depth and disparity (`inf`: no
/// surface); `other_depth` is the other eye's depth. All three must have one size.
pub fn occlusion_mask(
    eye: Eye,
    depth: &GrayImage,
    disparity: &GrayImage,
    other_depth: &GrayImage,
) -> Result<GrayImage, StereoError> {
    ensure_same_size("the depth", depth.size(), "the disparity", disparity.size())?;
    ensure_same_size(
        "the depth",
        depth.size(),
        "the other eye's depth",
        other_depth.size(),
    )?;
    let (w, h) = depth.size();
    // The other eye's position of this eye's point: x - d from the left, x + d from the right.
    let sign = f64::from(eye.sign());
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        let row = y * w;
        let other = &other_depth.data[row..row + w];
        for x in 0..w {
            let (z, d) = (depth.data[row + x], disparity.data[row + x]);
            if !(z.is_finite() && d.is_finite()) {
                continue;
            }
            let at = x as f64 + 0.5 + sign * f64::from(d);
            if !occluded_at(at, z, other) {
                continue;
            }
            out[row + x] = 1.0;
        }
    }
    Ok(GrayImage::from_vec(w, h, out)?)
}

/// Whether a point at depth `z` seen at position `at` (pixel coordinates) of a row of the
/// other eye, whose depths are `other`, is hidden there or outside it.
fn occluded_at(at: f64, z: f32, other: &[f32]) -> bool {
    let w = other.len();
    if !(at >= 0.0 && at < w as f64) {
        return true;
    }
    // The pixel centres around `at`: i + 0.5 <= at < i + 1.5, clamped to the row.
    let s = at - 0.5;
    let i = s.floor();
    let frac = s - i;
    let mut bracket = [i as i64, i as i64 + 1];
    if frac == 0.0 {
        bracket[1] = bracket[0];
    }
    let limit = z * (1.0 - DEPTH_TOLERANCE);
    bracket
        .into_iter()
        .map(|j| other[j.clamp(0, w as i64 - 1) as usize])
        .all(|o| o < limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: usize = 80;
    const H: usize = 3;
    /// `f b`, pixel metres: the background at 10 m has disparity 6, the box at 5 m 12.
    const FB: f32 = 60.0;
    const Z_BACK: f32 = 10.0;
    const Z_BOX: f32 = 5.0;

    /// A fronto-parallel box at 5 m covering `[a, b)` of the left image's columns (rows
    /// `1..H`; row 0 is all background) in front of a wall at 10 m: each eye's depth and
    /// disparity, by the pinhole geometry of a rectified pair (the box covers
    /// `[a - f b / 5, b - f b / 5)` in the right image).
    fn scene(a: f64, b: f64) -> [(GrayImage, GrayImage); 2] {
        let d_box = f64::from(FB / Z_BOX);
        Eye::BOTH.map(|eye| {
            let shift = match eye {
                Eye::Left => 0.0,
                Eye::Right => d_box,
            };
            let mut depth = GrayImage::new(W, H, Z_BACK).unwrap();
            for y in 1..H {
                for x in 0..W {
                    let c = x as f64 + 0.5;
                    if c >= a - shift && c < b - shift {
                        depth.data[y * W + x] = Z_BOX;
                    }
                }
            }
            let disp = GrayImage::from_vec(W, H, depth.data.iter().map(|z| FB / z).collect());
            (depth, disp.unwrap())
        })
    }

    fn mask(eye: Eye, views: &[(GrayImage, GrayImage); 2]) -> GrayImage {
        let (i, o) = match eye {
            Eye::Left => (0, 1),
            Eye::Right => (1, 0),
        };
        occlusion_mask(eye, &views[i].0, &views[i].1, &views[o].0).unwrap()
    }

    /// The occluded pixels of a box in front of a wall are the analytic bands: in the left
    /// image the wall's pixels left of the box whose point the box hides from the right eye
    /// (centres in `[a - (d_box - d_wall), a)`) and those whose point is left of the right
    /// image (`x < d`); in the right image the band right of the box and `x + d >= W`.
    #[test]
    fn a_box_in_front_of_a_wall_hides_the_analytic_bands() {
        let (a, b) = (30.0, 50.0);
        let views = scene(a, b);
        let (d_back, d_box) = (f64::from(FB / Z_BACK), f64::from(FB / Z_BOX));
        let band = d_box - d_back;
        for eye in Eye::BOTH {
            let m = mask(eye, &views);
            for y in 0..H {
                for x in 0..W {
                    let c = x as f64 + 0.5;
                    let expected = match eye {
                        Eye::Left => {
                            let in_box = y > 0 && c >= a && c < b;
                            let d = if in_box { d_box } else { d_back };
                            c - d < 0.0 || y > 0 && c >= a - band && c < a
                        }
                        Eye::Right => {
                            let (ra, rb) = (a - d_box, b - d_box);
                            let in_box = y > 0 && c >= ra && c < rb;
                            let d = if in_box { d_box } else { d_back };
                            c + d >= W as f64 || y > 0 && c >= rb && c < rb + band
                        }
                    };
                    assert_eq!(
                        m.data[y * W + x] == 1.0,
                        expected,
                        "{eye} eye, pixel ({x}, {y})"
                    );
                }
            }
            // The bands have the widths the geometry says: 6 px each (row 0: only the 6
            // out-of-view pixels).
            let count = |y: usize| (0..W).filter(|&x| m.data[y * W + x] == 1.0).count();
            assert_eq!((count(0), count(1)), (6, 12), "{eye} eye");
        }
    }

    /// A slanted wall (disparity changing by a fraction of a pixel per column, so the other
    /// eye's position falls between pixel centres) hides nothing of itself: only the
    /// out-of-view pixels are occluded; the sky (`inf`) never is.
    #[test]
    fn a_slanted_plane_hides_nothing_of_itself() {
        // 1 / Z affine in x in both images: d(x) = 4 + 0.137 x in the left image; the right
        // image's point at column x_r has x_l = x_r + d, so d = (4 + 0.137 x_r) / (1 - 0.137).
        let (d0, s) = (4.0f64, 0.137f64);
        let left_d: Vec<f32> = (0..W).map(|x| (d0 + s * (x as f64 + 0.5)) as f32).collect();
        let right_d: Vec<f32> = (0..W)
            .map(|x| ((d0 + s * (x as f64 + 0.5)) / (1.0 - s)) as f32)
            .collect();
        let img = |d: &[f32]| GrayImage::from_vec(W, 1, d.to_vec()).unwrap();
        let depth = |d: &[f32]| img(&d.iter().map(|d| FB / d).collect::<Vec<_>>());
        let (ld, rd) = (img(&left_d), img(&right_d));
        let (lz, rz) = (depth(&left_d), depth(&right_d));
        let left = occlusion_mask(Eye::Left, &lz, &ld, &rz).unwrap();
        for (x, (&d, &m)) in left_d.iter().zip(&left.data).enumerate() {
            let out = (x as f64 + 0.5) - f64::from(d) < 0.0;
            assert_eq!(m == 1.0, out, "left pixel {x}");
        }
        let right = occlusion_mask(Eye::Right, &rz, &rd, &lz).unwrap();
        for (x, (&d, &m)) in right_d.iter().zip(&right.data).enumerate() {
            let out = (x as f64 + 0.5) + f64::from(d) >= W as f64;
            assert_eq!(m == 1.0, out, "right pixel {x}");
        }
        let sky = GrayImage::new(W, 1, f32::INFINITY).unwrap();
        let none = occlusion_mask(Eye::Left, &sky, &sky, &rz).unwrap();
        assert!(none.data.iter().all(|&m| m == 0.0));
    }

    #[test]
    fn maps_of_other_sizes_are_refused() {
        let a = GrayImage::new(4, 2, 1.0).unwrap();
        let b = GrayImage::new(3, 2, 1.0).unwrap();
        let err = occlusion_mask(Eye::Left, &a, &a, &b)
            .unwrap_err()
            .to_string();
        assert!(err.contains("other eye's depth"), "{err}");
    }
}
