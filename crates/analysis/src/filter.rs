//! One-dimensional sliding-window filters of grey images, along rows or along columns:
//! median, mean and maximum, with windows clipped at the image's sides (a border pixel's
//! window is shorter, never padded). Streak detection ([`crate::detect`]) and the learned
//! streak classifier ([`crate::streak_classifier`]) are built on them.

use streaks_image::GrayImage;

/// Along which axis a filter slides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// Along each row (a horizontal window).
    Rows,
    /// Along each column (a vertical window).
    Columns,
}

/// `img` transposed (width and height swapped).
pub fn transpose(img: &GrayImage) -> GrayImage {
    let (w, h) = (img.width, img.height);
    let mut data = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            data[x * h + y] = img.data[y * w + x];
        }
    }
    GrayImage {
        width: h,
        height: w,
        data,
    }
}

/// Applies `row_filter` (which maps one row to its filtered values) along `axis`.
fn along(img: &GrayImage, axis: Axis, mut row_filter: impl FnMut(&[f32], &mut [f32])) -> GrayImage {
    let run = |img: &GrayImage, f: &mut dyn FnMut(&[f32], &mut [f32])| {
        let mut out = img.clone();
        for (row, o) in img
            .data
            .chunks_exact(img.width)
            .zip(out.data.chunks_exact_mut(img.width))
        {
            f(row, o);
        }
        out
    };
    match axis {
        Axis::Rows => run(img, &mut row_filter),
        Axis::Columns => transpose(&run(&transpose(img), &mut row_filter)),
    }
}

/// The median of each pixel's window `[i - r, i + r]` along `axis` (the upper median of an
/// even count at the sides). Values are compared with `total_cmp`.
pub fn median(img: &GrayImage, axis: Axis, r: usize) -> GrayImage {
    sorted_window(img, axis, r, |_| true, |w| w[w.len() / 2])
}

/// The `q`-quantile (0 to 1, the nearest rank below: `q = 0.5` is the lower median of an
/// even count) of the **finite** values in each pixel's window `[i - r, i + r]` along
/// `axis`; `inf` where the window holds none. Disparity maps mark "no value" with `inf`,
/// which this skips.
pub fn finite_quantile(img: &GrayImage, axis: Axis, r: usize, q: f32) -> GrayImage {
    let q = q.clamp(0.0, 1.0);
    sorted_window(
        img,
        axis,
        r,
        |v| v.is_finite(),
        |w| {
            if w.is_empty() {
                f32::INFINITY
            } else {
                w[((w.len() - 1) as f32 * q) as usize]
            }
        },
    )
}

/// Slides a window `[i - r, i + r]` along `axis`, keeping the values `keep` accepts sorted
/// (insertion and removal by binary search), and writes `pick(sorted window)` per pixel.
fn sorted_window(
    img: &GrayImage,
    axis: Axis,
    r: usize,
    keep: impl Fn(f32) -> bool,
    pick: impl Fn(&[f32]) -> f32,
) -> GrayImage {
    let mut window: Vec<f32> = Vec::with_capacity(2 * r + 1);
    let pos = |win: &[f32], v: f32| win.partition_point(|&u| u.total_cmp(&v).is_lt());
    along(img, axis, |row, out| {
        let n = row.len();
        window.clear();
        let (mut lo, mut hi) = (0usize, 0usize); // the window is row[lo..hi]
        for (i, o) in out.iter_mut().enumerate() {
            let (want_lo, want_hi) = (i.saturating_sub(r), (i + r + 1).min(n));
            while hi < want_hi {
                let v = row[hi];
                if keep(v) {
                    window.insert(pos(&window, v), v);
                }
                hi += 1;
            }
            while lo < want_lo {
                if keep(row[lo]) {
                    let k = pos(&window, row[lo]);
                    window.remove(k);
                }
                lo += 1;
            }
            *o = pick(&window);
        }
    })
}

/// The mean of each pixel's window `[i - r, i + r]` along `axis` (prefix sums in `f64`).
pub fn mean(img: &GrayImage, axis: Axis, r: usize) -> GrayImage {
    let mut prefix = Vec::new();
    along(img, axis, |row, out| {
        prefix.clear();
        prefix.push(0.0f64);
        for &v in row {
            prefix.push(prefix.last().copied().unwrap_or(0.0) + v as f64);
        }
        let n = row.len();
        for (i, o) in out.iter_mut().enumerate() {
            let (a, b) = (i.saturating_sub(r), (i + r + 1).min(n));
            *o = ((prefix[b] - prefix[a]) / (b - a) as f64) as f32;
        }
    })
}

/// The maximum of each pixel's window `[i - r, i + r]` along `axis`.
pub fn max(img: &GrayImage, axis: Axis, r: usize) -> GrayImage {
    along(img, axis, |row, out| {
        let n = row.len();
        for (i, o) in out.iter_mut().enumerate() {
            let (a, b) = (i.saturating_sub(r), (i + r + 1).min(n));
            *o = row[a..b].iter().copied().fold(f32::NEG_INFINITY, f32::max);
        }
    })
}

/// The running maximum along each column from the top row down: each pixel's value is the
/// largest at or above it.
pub fn max_above(img: &GrayImage) -> GrayImage {
    let mut out = img.clone();
    let w = img.width;
    for y in 1..img.height {
        let (prev, cur) = out.data.split_at_mut(y * w);
        for (c, &p) in cur[..w].iter_mut().zip(&prev[(y - 1) * w..]) {
            *c = c.max(p);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> GrayImage {
        let data = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        GrayImage::from_vec(w, h, data).unwrap()
    }

    /// Brute force: the window's values along the axis, sorted.
    fn window(im: &GrayImage, axis: Axis, x: usize, y: usize, r: usize) -> Vec<f32> {
        let mut v: Vec<f32> = match axis {
            Axis::Rows => (x.saturating_sub(r)..(x + r + 1).min(im.width))
                .map(|i| im.get(i, y))
                .collect(),
            Axis::Columns => (y.saturating_sub(r)..(y + r + 1).min(im.height))
                .map(|j| im.get(x, j))
                .collect(),
        };
        v.sort_by(f32::total_cmp);
        v
    }

    #[test]
    fn filters_match_brute_force_along_both_axes() {
        // A pseudo-random image with repeated values (ties in the median's window).
        let im = img(23, 17, |x, y| ((x * 7919 + y * 104729) % 13) as f32 - 4.0);
        for axis in [Axis::Rows, Axis::Columns] {
            for r in [0, 1, 4, 30] {
                let (md, mn, mx) = (median(&im, axis, r), mean(&im, axis, r), max(&im, axis, r));
                for y in 0..im.height {
                    for x in 0..im.width {
                        let w = window(&im, axis, x, y, r);
                        assert_eq!(
                            md.get(x, y),
                            w[w.len() / 2],
                            "median {axis:?} r {r} ({x}, {y})"
                        );
                        let m = w.iter().sum::<f32>() / w.len() as f32;
                        assert!((mn.get(x, y) - m).abs() < 1e-5, "mean {axis:?} r {r}");
                        assert_eq!(mx.get(x, y), *w.last().unwrap(), "max {axis:?} r {r}");
                    }
                }
            }
        }
    }

    #[test]
    fn finite_quantile_skips_no_values_and_matches_brute_force() {
        // Every third value is `inf` (no value); a row of only `inf` gives `inf`.
        let im = img(19, 7, |x, y| {
            if (x + 2 * y) % 3 == 0 || y == 6 {
                f32::INFINITY
            } else {
                ((x * 31 + y * 17) % 11) as f32
            }
        });
        for axis in [Axis::Rows, Axis::Columns] {
            for r in [0, 2, 9] {
                for q in [0.0, 0.5, 0.75, 1.0] {
                    let out = finite_quantile(&im, axis, r, q);
                    for y in 0..im.height {
                        for x in 0..im.width {
                            let w: Vec<f32> = window(&im, axis, x, y, r)
                                .into_iter()
                                .filter(|v| v.is_finite())
                                .collect();
                            let want = if w.is_empty() {
                                f32::INFINITY
                            } else {
                                w[((w.len() - 1) as f32 * q) as usize]
                            };
                            assert_eq!(out.get(x, y), want, "{axis:?} r {r} q {q} ({x}, {y})");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn transpose_twice_is_identity_and_max_above_is_a_running_maximum() {
        let im = img(5, 3, |x, y| {
            (x as f32 - 2.0).powi(2) * if y == 1 { 2.0 } else { 1.0 }
        });
        assert_eq!(transpose(&transpose(&im)), im);
        let t = transpose(&im);
        assert_eq!((t.width, t.height, t.get(2, 4)), (3, 5, im.get(4, 2)));
        let a = max_above(&im);
        for x in 0..5 {
            assert_eq!(a.get(x, 0), im.get(x, 0));
            assert_eq!(a.get(x, 2), im.get(x, 1), "row 1 is the brightest");
        }
    }
}
