//! Viewing a stereo pair: side-by-side for free-fusing and red-cyan anaglyphs, and the paper's
//! Fig. 7 treatment of photographs (grey level, histogram equalisation, a horizontal shift that
//! moves a chosen disparity to zero).

use crate::error::StereoError;
use std::path::Path;
use streaks_image::png::write_png_buffer;
use streaks_image::{ensure_pair_size, GrayImage};

/// [`ensure_same_size`] of the two views of a developed pair.
fn check_same_size(left: &image::RgbImage, right: &image::RgbImage) -> Result<(), StereoError> {
    let size = |i: &image::RgbImage| (i.width() as usize, i.height() as usize);
    Ok(ensure_pair_size(size(left), size(right))?)
}

/// The pair side by side, the left image on the left (for parallel free-fusing).
pub fn side_by_side(
    left: &image::RgbImage,
    right: &image::RgbImage,
) -> Result<image::RgbImage, StereoError> {
    check_same_size(left, right)?;
    let (w, h) = left.dimensions();
    let mut out = image::RgbImage::new(2 * w, h);
    for (x, y, p) in out.enumerate_pixels_mut() {
        *p = if x < w {
            *left.get_pixel(x, y)
        } else {
            *right.get_pixel(x - w, y)
        };
    }
    Ok(out)
}

/// A red-cyan anaglyph: red from the left image, green and blue from the right one (a colour
/// anaglyph; for grey pairs it is the usual grey anaglyph). View with the red filter on the
/// left eye.
pub fn anaglyph(
    left: &image::RgbImage,
    right: &image::RgbImage,
) -> Result<image::RgbImage, StereoError> {
    check_same_size(left, right)?;
    let mut out = right.clone();
    for (o, l) in out.pixels_mut().zip(left.pixels()) {
        o[0] = l[0];
    }
    Ok(out)
}

/// Writes the side-by-side view of a pair to `side_by_side_path` and its anaglyph to
/// `anaglyph_path` (the sample folder's names are the `streaks-dataset` crate's).
pub fn write_pair_views(
    side_by_side_path: &Path,
    anaglyph_path: &Path,
    left: &image::RgbImage,
    right: &image::RgbImage,
) -> Result<(), StereoError> {
    write_png_buffer(side_by_side_path, &side_by_side(left, right)?)?;
    write_png_buffer(anaglyph_path, &anaglyph(left, right)?)?;
    Ok(())
}

/// Histogram equalisation over 256 grey levels: values are clipped to [0, 1] and quantised to
/// 256 bins; each level maps to `(cdf(level) - cdf_min) / (N - cdf_min)`, `cdf_min` the count of
/// the darkest occupied level, so the output spans [0, 1]. A constant image stays constant (0).
pub fn equalize_histogram(img: &GrayImage) -> GrayImage {
    let level = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as usize;
    let mut hist = [0usize; 256];
    for &v in &img.data {
        hist[level(v)] += 1;
    }
    let mut cdf = [0usize; 256];
    let mut acc = 0;
    for (c, h) in cdf.iter_mut().zip(hist) {
        acc += h;
        *c = acc;
    }
    let n = img.data.len();
    let cdf_min = hist.iter().copied().find(|&h| h > 0).unwrap_or(0);
    let denom = (n - cdf_min).max(1) as f32;
    let map: Vec<f32> = cdf
        .iter()
        .map(|&c| c.saturating_sub(cdf_min) as f32 / denom)
        .collect();
    GrayImage {
        width: img.width,
        height: img.height,
        data: img.data.iter().map(|&v| map[level(v)]).collect(),
    }
}

/// Shifts an image horizontally by `shift` pixels toward the left (sub-pixel, linear
/// interpolation): `out(x, y) = img(x + shift, y)`, 0 where that falls outside. Applied to the
/// left image of a pair, it subtracts `shift` from every disparity `x_left - x_right`, so a
/// point of disparity `shift` ends with zero disparity (the paper's Fig. 7 treatment).
pub fn shift_horizontal(img: &GrayImage, shift: f32) -> Result<GrayImage, StereoError> {
    if !shift.is_finite() || shift.abs() >= img.width as f32 {
        return Err(StereoError::Parameter {
            name: "shift",
            reason: format!(
                "{shift} px must be finite and smaller than the image width {}",
                img.width
            ),
        });
    }
    let mut out = GrayImage::new(img.width, img.height, 0.0)?;
    for y in 0..img.height {
        for x in 0..img.width {
            let sx = x as f32 + shift;
            let x0 = sx.floor();
            let t = sx - x0;
            let at = |i: f32| {
                if i >= 0.0 && i < img.width as f32 {
                    img.get(i as usize, y)
                } else {
                    0.0
                }
            };
            out.set(x, y, at(x0) * (1.0 - t) + at(x0 + 1.0) * t);
        }
    }
    Ok(out)
}

/// The paper's Fig. 7 treatment of a photographed pair: grey level (already, for a
/// [`GrayImage`]), histogram equalisation of each image, then the left image shifted left by
/// `shift` pixels (see [`shift_horizontal`]) so points of disparity `shift` get zero disparity.
pub fn prepare_pair(
    left: &GrayImage,
    right: &GrayImage,
    shift: f32,
) -> Result<(GrayImage, GrayImage), StereoError> {
    ensure_pair_size(left.size(), right.size())?;
    let l = equalize_histogram(left);
    let l = if shift == 0.0 {
        l
    } else {
        shift_horizontal(&l, shift)?
    };
    Ok((l, equalize_histogram(right)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_by_side_and_anaglyph_take_the_right_channels() {
        let l = image::RgbImage::from_pixel(2, 1, image::Rgb([10, 20, 30]));
        let r = image::RgbImage::from_pixel(2, 1, image::Rgb([40, 50, 60]));
        let s = side_by_side(&l, &r).unwrap();
        assert_eq!(s.dimensions(), (4, 1));
        assert_eq!(s.get_pixel(1, 0).0, [10, 20, 30]);
        assert_eq!(s.get_pixel(2, 0).0, [40, 50, 60]);
        assert_eq!(anaglyph(&l, &r).unwrap().get_pixel(0, 0).0, [10, 50, 60]);
        let small = image::RgbImage::new(1, 1);
        assert!(matches!(
            anaglyph(&l, &small),
            Err(StereoError::SizeMismatch(_))
        ));
        assert!(side_by_side(&small, &l).is_err());
    }

    #[test]
    fn equalisation_spreads_levels_and_keeps_order() {
        // Levels crowded in [0.4, 0.5] spread over [0, 1].
        let data: Vec<f32> = (0..1000)
            .map(|i| 0.4 + 0.1 * (i % 100) as f32 / 99.0)
            .collect();
        let img = GrayImage::from_vec(100, 10, data).unwrap();
        let eq = equalize_histogram(&img);
        let (lo, hi) = eq
            .data
            .iter()
            .fold((1.0f32, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
        assert_eq!(lo, 0.0);
        assert_eq!(hi, 1.0);
        for w in img.data[..100].windows(2).zip(eq.data[..100].windows(2)) {
            assert!(w.0[1] >= w.0[0] && w.1[1] >= w.1[0], "monotone");
        }
        // Roughly uniform: half the pixels below 0.5.
        let below = eq.data.iter().filter(|&&v| v < 0.5).count();
        assert!((400..=600).contains(&below), "{below}");
        let flat = GrayImage::new(4, 4, 0.3).unwrap();
        assert!(equalize_histogram(&flat).data.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn shifting_the_left_image_moves_disparity_to_zero() {
        let ramp: Vec<f32> = (0..40).map(|i| i as f32).collect();
        let img = GrayImage::from_vec(20, 2, ramp).unwrap();
        let s = shift_horizontal(&img, 2.5).unwrap();
        assert!((s.get(3, 0) - 5.5).abs() < 1e-6);
        assert_eq!(s.get(19, 1), 0.0, "outside is black");
        let s = shift_horizontal(&img, -1.0).unwrap();
        assert_eq!(s.get(0, 0), 0.0);
        assert_eq!(s.get(5, 1), 24.0);
        assert!(shift_horizontal(&img, 30.0).is_err());
        assert!(shift_horizontal(&img, f32::NAN).is_err());
        // A feature at x = 12 in the left image and x = 9 in the right (disparity 3), shifted by 3.
        let mut l = GrayImage::new(20, 1, 0.0).unwrap();
        let mut r = GrayImage::new(20, 1, 0.0).unwrap();
        l.set(12, 0, 1.0);
        r.set(9, 0, 1.0);
        let (pl, pr) = prepare_pair(&l, &r, 3.0).unwrap();
        let argmax = |g: &GrayImage| {
            (0..20)
                .max_by(|&a, &b| g.get(a, 0).total_cmp(&g.get(b, 0)))
                .unwrap()
        };
        assert_eq!(argmax(&pl), argmax(&pr));
        assert!(prepare_pair(&l, &GrayImage::new(5, 1, 0.0).unwrap(), 0.0).is_err());
    }
}
