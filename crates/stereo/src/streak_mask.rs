//! The streak mask: which pixels of a rendered view are specular streaks.
//!
//! The renderer's `specular` layer holds, per pixel, the radiance that reached the camera by one
//! glossy reflection of an emitter at the first hit. With `S` its luminance and `L` the
//! luminance of the whole pixel (Rec. 709 weights, linear), a pixel is a streak pixel when
//!
//! 1. `S > T`, `T = max(k * median(S over road pixels), q * P99.9(S over all pixels))`, and
//! 2. `S > s * L` (the specular reflection is the larger share of the pixel),
//!
//! with the defaults `k = 10`, `q = 0.05`, `s = 0.5` ([`StreakMaskParams`]). Road pixels are
//! those whose first hit faces up (geometric normal within 10 degrees of +Y); where there are none
//! the median is over all pixels. The median term keeps the faint glossy sheen of the whole wet
//! road out of the mask; the percentile term scales with the brightest streak, so the mask does not
//! depend on the exposure. A view without specular radiance has an empty mask (`S > 0` fails).

use crate::error::StereoError;
use streaks_image::stats::quantile;
use streaks_image::{ensure_same_size, GrayImage};

/// Parameters of the streak mask (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StreakMaskParams {
    /// `k`: multiple of the road pixels' median specular luminance.
    pub k_median: f32,
    /// `q`: fraction of the 99.9th percentile of specular luminance.
    pub fraction_of_p999: f32,
    /// `s`: least share of the pixel's luminance that must be specular.
    pub min_share: f32,
}

impl Default for StreakMaskParams {
    fn default() -> Self {
        Self {
            k_median: 10.0,
            fraction_of_p999: 0.05,
            min_share: 0.5,
        }
    }
}

/// The streak mask (1 for streak pixels, 0 elsewhere) and the threshold `T` it used, from the
/// specular and total luminance of a view and which pixels are road (`None`: all are).
pub fn streak_mask(
    specular: &GrayImage,
    total: &GrayImage,
    road: Option<&[bool]>,
    params: &StreakMaskParams,
) -> Result<(GrayImage, f32), StereoError> {
    ensure_same_size(
        "the specular luminance",
        specular.size(),
        "the total luminance",
        total.size(),
    )?;
    if let Some(r) = road {
        if r.len() != specular.data.len() {
            return Err(StereoError::Parameter {
                name: "road",
                reason: format!("{} flags for {} pixels", r.len(), specular.data.len()),
            });
        }
    }
    let p = params;
    if !(p.k_median >= 0.0 && p.fraction_of_p999 >= 0.0 && (0.0..=1.0).contains(&p.min_share)) {
        return Err(StereoError::Parameter {
            name: "streak mask",
            reason: format!("{p:?}: k and q must be >= 0 and s in [0, 1]"),
        });
    }
    let s = &specular.data;
    let road_values = road
        .filter(|r| r.iter().any(|&b| b))
        .map(|r| quantile(s.iter().zip(r).filter(|(_, &b)| b).map(|(&v, _)| v), 0.5));
    let median = road_values
        .unwrap_or_else(|| quantile(s.iter().copied(), 0.5))
        .unwrap_or(0.0);
    let p999 = quantile(s.iter().copied(), 0.999).unwrap_or(0.0);
    let threshold = (p.k_median * median).max(p.fraction_of_p999 * p999);
    let mut mask = GrayImage::new(specular.width, specular.height, 0.0)?;
    for ((m, &sv), &tv) in mask.data.iter_mut().zip(s).zip(&total.data) {
        if sv > threshold && sv > p.min_share * tv {
            *m = 1.0;
        }
    }
    Ok((mask, threshold))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_streak_on_a_glossy_road_is_found() {
        // 20x20: a faint sheen of 0.01 everywhere, a streak column x = 10 with 1.0, and a bright
        // lamp (total 50, specular 0) at the top.
        let (w, h) = (20, 20);
        let mut s = GrayImage::new(w, h, 0.01).unwrap();
        let mut t = GrayImage::new(w, h, 0.05).unwrap();
        for y in 5..20 {
            s.set(10, y, 1.0);
            t.set(10, y, 1.2);
        }
        s.set(10, 0, 0.0);
        t.set(10, 0, 50.0);
        // A pixel with strong specular but a larger diffuse share is not a streak.
        s.set(3, 15, 1.0);
        t.set(3, 15, 3.0);
        let road: Vec<bool> = (0..w * h).map(|i| i / w >= 4).collect();
        let (mask, thr) = streak_mask(&s, &t, Some(&road), &StreakMaskParams::default()).unwrap();
        assert!((thr - 0.1).abs() < 1e-6, "10 x the sheen median: {thr}");
        for y in 0..h {
            for x in 0..w {
                let streak = x == 10 && y >= 5;
                assert_eq!(mask.get(x, y) == 1.0, streak, "({x}, {y})");
            }
        }
        // No specular light: an empty mask.
        let zero = GrayImage::new(w, h, 0.0).unwrap();
        let (mask, _) = streak_mask(&zero, &t, None, &StreakMaskParams::default()).unwrap();
        assert!(mask.data.iter().all(|&m| m == 0.0));
    }

    #[test]
    fn bad_inputs_are_errors() {
        let a = GrayImage::new(4, 4, 0.0).unwrap();
        let b = GrayImage::new(4, 5, 0.0).unwrap();
        let p = StreakMaskParams::default();
        assert!(streak_mask(&a, &b, None, &p).is_err());
        assert!(streak_mask(&a, &a, Some(&[true; 3]), &p).is_err());
        let bad = StreakMaskParams {
            min_share: 2.0,
            ..p
        };
        assert!(streak_mask(&a, &a, None, &bad).is_err());
    }
}
