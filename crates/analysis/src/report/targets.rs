//! What to measure besides the streaks, picked from the ground-truth depth: thin vertical
//! objects ([`find_objects`]: poles, posts) and plain road ([`find_road`]), as in Fig. 8.

use super::input::RigView;
use streaks_image::{GrayImage, Region};

/// Height above the road of the ground-truth point at pixel `(x, y)`.
fn truth_road_y(depth: &GrayImage, view: &RigView, x: usize, y: usize) -> f32 {
    let z = depth.get(x, y);
    if !(z.is_finite() && z > 0.0) {
        return f32::NAN;
    }
    view.implied(x as f32 + 0.5, y as f32 + 0.5, z).y
}

/// A region picked from the ground truth: its bounding box, the per-row centres LK measures
/// at, and the window width that fits it.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Picked {
    /// The bounding box.
    pub region: Region,
    /// Per row: (row, left-image x).
    pub centres: Vec<(usize, f32)>,
    /// The LK window width.
    pub window: usize,
}

/// Narrowest and widest vertical object [`find_objects`] picks, pixels.
const OBJECT_WIDTH: (usize, usize) = (4, 32);

/// Thin vertical objects (poles, posts): in every row, the maximal runs of pixels more than
/// 0.1 m above the road whose ground-truth depth changes by less than 2 % from one pixel to the
/// next, [`OBJECT_WIDTH`] wide, 2 pixels or more from the border of both images. A column is
/// followed down while such a run holds it and its depth changes by less than 2 % from row to
/// row; the longest runs (at least `h / 12` and 12 rows) are picked, at least a tenth of the
/// image width apart. LK is centred on the object in every row, with a window 4 pixels wider
/// than its median width (odd, at most `max_window`): the object and its two edges, little of
/// the background behind it.
pub(super) fn find_objects(
    depth: &GrayImage,
    view: &RigView,
    count: usize,
    max_window: usize,
) -> Vec<Picked> {
    let (w, h) = (depth.width, depth.height);
    let near = |a: f32, b: f32| (a / b - 1.0).abs() < 0.02;
    // Per pixel: its row run's first and last column (usize::MAX when not an object pixel).
    let mut runs = vec![(usize::MAX, usize::MAX); w * h];
    for y in 0..h {
        let valid = |x: usize| {
            let z = depth.get(x, y);
            z.is_finite() && z > 0.0 && truth_road_y(depth, view, x, y) > 0.1
        };
        let mut x = 0;
        while x < w {
            if !valid(x) {
                x += 1;
                continue;
            }
            let x0 = x;
            x += 1;
            while x < w && valid(x) && near(depth.get(x, y), depth.get(x - 1, y)) {
                x += 1;
            }
            for r in &mut runs[y * w + x0..y * w + x] {
                *r = (x0, x - 1);
            }
        }
    }
    // Thin, and with its edges and 2 pixels beyond them inside both images (the right image
    // sees the object `f b / Z` pixels further left).
    let thin = |x: usize, y: usize| {
        let (a, b) = runs[y * w + x];
        a != usize::MAX
            && (OBJECT_WIDTH.0..=OBJECT_WIDTH.1).contains(&(b - a + 1))
            && a as f32 - 2.0 - view.rig.disparity_px(depth.get(x, y)) >= 0.0
            && b + 3 <= w
    };
    let min_rows = (h / 12).max(12);
    let mut found: Vec<(usize, usize, usize)> = Vec::new(); // (length, x, y0)
    for x in 0..w {
        let mut y = 0;
        while y < h {
            if !thin(x, y) {
                y += 1;
                continue;
            }
            let y0 = y;
            y += 1;
            while y < h && thin(x, y) && near(depth.get(x, y), depth.get(x, y - 1)) {
                y += 1;
            }
            if y - y0 >= min_rows {
                found.push((y - y0, x, y0));
            }
        }
    }
    found.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut picked: Vec<Picked> = Vec::new();
    for (len, x, y0) in found {
        if picked.len() == count {
            break;
        }
        if picked
            .iter()
            .any(|p| (p.region.centre_x() - x as f32).abs() <= 0.1 * w as f32)
        {
            continue;
        }
        let rows = y0..y0 + len;
        let centres: Vec<(usize, f32)> = rows
            .clone()
            .map(|y| {
                let (a, b) = runs[y * w + x];
                (y, 0.5 * (a + b + 1) as f32)
            })
            .collect();
        let mut widths: Vec<usize> = rows
            .clone()
            .map(|y| {
                let (a, b) = runs[y * w + x];
                b - a + 1
            })
            .collect();
        widths.sort_unstable();
        let window = ((widths[widths.len() / 2] + 4) | 1)
            .min(max_window | 1)
            .max(3);
        let x0 = rows.clone().map(|y| runs[y * w + x].0).min().unwrap_or(x);
        let x1 = rows.map(|y| runs[y * w + x].1 + 1).max().unwrap_or(x + 1);
        picked.push(Picked {
            region: Region {
                x0,
                x1,
                y0,
                y1: y0 + len,
            },
            centres,
            window,
        });
    }
    picked
}

/// Plain road, one measurement per row: among the pixels whose LK window (`half` either side)
/// lies on the road in the ground truth (within 2 cm of the plane at its centre and both ends),
/// inside the right image as well, and off the streak mask, the one whose window has the most
/// texture, the largest sum of the squared horizontal gradient of the prepared left image
/// averaged over 3 rows (against the noise). Lane markings and the asphalt's grain win over the smooth glow of the reflections.
/// Rows without such a pixel are skipped; `None` with fewer than 12 rows.
pub(super) fn find_road(
    depth: &GrayImage,
    mask: &GrayImage,
    img: &GrayImage,
    view: &RigView,
    half: usize,
) -> Option<Picked> {
    let (w, h) = (depth.width, depth.height);
    if w < 2 * half + 3 || h < 3 {
        return None;
    }
    let mut centres = Vec::new();
    let (mut gsum, mut msum) = (vec![0.0f64; w + 1], vec![0usize; w + 1]);
    for y in 0..h {
        let (ya, yb) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let avg = |x: usize| (img.get(x, ya) + img.get(x, y) + img.get(x, yb)) as f64 / 3.0;
        for x in 0..w {
            let g = if x > 0 && x + 1 < w {
                (avg(x + 1) - avg(x - 1)).powi(2)
            } else {
                0.0
            };
            gsum[x + 1] = gsum[x] + if g.is_finite() { g } else { 0.0 };
            msum[x + 1] = msum[x] + (mask.get(x, y) > 0.5) as usize;
        }
        let mut best: Option<(f64, usize)> = None;
        for x in half + 1..w - half - 1 {
            let (a, b) = (x - half, x + half + 1);
            if msum[b] != msum[a] {
                continue;
            }
            // On the road, and the window inside the right image too.
            let on_road = [a, x, b - 1]
                .iter()
                .all(|&xx| truth_road_y(depth, view, xx, y).abs() < 0.02)
                && a as f32 - view.rig.disparity_px(depth.get(a, y)) >= 0.0;
            let energy = gsum[b] - gsum[a];
            if on_road && best.is_none_or(|(e, _)| energy > e) {
                best = Some((energy, x));
            }
        }
        if let Some((_, x)) = best {
            centres.push((y, x as f32 + 0.5));
        }
    }
    if centres.len() < 12 {
        return None;
    }
    let xs = || centres.iter().map(|c| c.1 as usize);
    let region = Region {
        x0: xs().min()? - half,
        x1: xs().max()? + half + 1,
        y0: centres.first()?.0,
        y1: centres.last()?.0 + 1,
    };
    Some(Picked {
        region,
        centres,
        window: 2 * half + 1,
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use glam::{Affine3A, Vec3};
    use streaks_stereo::rig::{Intrinsics, Rig};

    /// A level rig 1.5 m above a road, and the ground-truth depth of a road that ends at the
    /// horizon (row 60 of 120) with the sky above.
    pub(in crate::report) fn level_rig(baseline: f32) -> (Rig, GrayImage) {
        let rig = Rig::new(
            Intrinsics::new(160, 120, 150.0).unwrap(),
            baseline,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let mut depth = GrayImage::new(160, 120, f32::INFINITY).unwrap();
        for y in 60..120 {
            for x in 0..160 {
                depth.set(x, y, 150.0 * 1.5 / (y as f32 + 0.5 - 60.0));
            }
        }
        (rig, depth)
    }

    #[test]
    fn thin_vertical_objects_are_found_in_the_ground_truth_with_a_window_to_fit() {
        let (rig, mut depth) = level_rig(0.065);
        let view = RigView::new(&rig).unwrap();
        // A wall 20 m away above the road, a 6 px pole 8 m away standing on the road, and a
        // pole at the left border (its match would leave the right image).
        for y in 0..120 {
            for x in 0..160 {
                let wall_ground = y as f32 + 0.5 - 60.0 > 150.0 * 1.5 / 20.0;
                if !wall_ground {
                    depth.set(x, y, 20.0);
                }
            }
        }
        let pole_bottom = (60.0 + 150.0 * 1.5 / 8.0) as usize; // row 88
        for y in 0..pole_bottom {
            for x in (100..106).chain(0..3) {
                depth.set(x, y, 8.0);
            }
        }
        let found = find_objects(&depth, &view, 3, 21);
        assert_eq!(found.len(), 1, "{found:?}");
        let p = &found[0];
        assert_eq!((p.region.x0, p.region.x1, p.region.y0), (100, 106, 0));
        // The rows more than 0.1 m above the road.
        assert!((p.region.y1 as i64 - 86).abs() <= 1, "{:?}", p.region);
        assert_eq!(p.window, 11);
        assert!(p.centres.iter().all(|c| c.1 == 103.0));
        // The widest pole is 32 pixels.
        for y in 0..pole_bottom {
            for x in 100..140 {
                depth.set(x, y, 8.0);
            }
        }
        assert!(find_objects(&depth, &view, 3, 21).is_empty());
    }
}
