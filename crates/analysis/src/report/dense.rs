//! The dense disparity: the search range that covers the scene ([`disparity_range`]), the
//! point cloud it implies in the road frame ([`for_each_point`], [`DenseSummary`]) and its
//! score against the ground truth, split by the streak mask ([`dense_accuracy`]).

use super::input::{RigView, StereoInput};
use super::ReportError;
use crate::sgm::{compare_disparity_where, DisparityErrors, SgmError};
use glam::{DVec2, Vec3};
use serde::Serialize;
use streaks_image::stats::quantile_below;
use streaks_image::{ensure_same_size, GrayImage};

/// Summary of the dense disparity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DenseSummary {
    /// Disparity range searched.
    pub range: (i32, i32),
    /// Share of pixels with a valid disparity.
    pub density: f64,
    /// Valid streak pixels whose implied point is more than 0.1 m below the road.
    pub streak_pixels_below_road: usize,
    /// Valid streak pixels.
    pub streak_pixels: usize,
    /// Valid non-streak pixels more than 0.1 m below the road.
    pub other_pixels_below_road: usize,
    /// The dense disparity scored against the ground truth, when the input has it.
    pub accuracy: Option<DenseAccuracy>,
}

/// The dense disparity scored against the ground-truth disparity: bad-2.0 (the share of the
/// estimated pixels off by more than 2 px), mean absolute error and the share of pixels with
/// an estimate ([`DisparityErrors`]), over every pixel that sees a surface and separately over
/// the streak pixels and the others. Streak pixels are expected to be wrong: stereo sees the
/// virtual light there, not the road.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DenseAccuracy {
    /// The mask that tells streak pixels from the others: `renderer` (the input's
    /// `streak_mask_left.png`) or `detector` (the analysis' own, when the input has none).
    pub streak_mask: &'static str,
    /// Every pixel with a ground truth.
    pub all: DisparityErrors,
    /// The streak pixels.
    pub streak: DisparityErrors,
    /// The other pixels.
    pub non_streak: DisparityErrors,
}

/// Bad-2.0, mean absolute error and density of `dense` against `truth`, overall and split by
/// `streak_mask` (a pixel is a streak pixel when its mask value exceeds 0.5).
pub fn dense_accuracy(
    dense: &GrayImage,
    truth: &GrayImage,
    streak_mask: &GrayImage,
    mask_name: &'static str,
) -> Result<DenseAccuracy, ReportError> {
    ensure_same_size(
        "the streak mask",
        streak_mask.size(),
        "the ground truth",
        truth.size(),
    )
    .map_err(SgmError::from)?;
    let on = |i: usize| streak_mask.data[i] > 0.5;
    Ok(DenseAccuracy {
        streak_mask: mask_name,
        all: compare_disparity_where(dense, truth, 2.0, |_| true)?,
        streak: compare_disparity_where(dense, truth, 2.0, on)?,
        non_streak: compare_disparity_where(dense, truth, 2.0, |i| !on(i))?,
    })
}

/// The disparity range that covers the scene, searched by SGM and by LK's integer search: up
/// to the largest ground-truth disparity (or that of the road at the bottom row), plus a
/// margin, within what the matcher allows.
pub(super) fn disparity_range(input: &StereoInput, view: &RigView) -> i32 {
    let truth_max = input
        .truth_disparity
        .as_ref()
        .and_then(|t| quantile_below(t.data.iter().copied(), 0.995))
        .map(f64::from);
    let cam = &view.camera;
    let bottom = cam
        .ground_point(DVec2::new(
            cam.principal().x,
            input.left.height as f64 - 0.5,
        ))
        .map(|g| cam.disparity_px(g));
    let d = truth_max.or(bottom).unwrap_or(64.0);
    ((d * 1.2).ceil() as i32 + 4).clamp(16, 256)
}

/// Calls `f(x, y, is_streak, road point)` for every valid pixel of the dense disparity.
pub(super) fn for_each_point(
    dense: &GrayImage,
    mask: &GrayImage,
    view: &RigView,
    mut f: impl FnMut(usize, usize, bool, Vec3),
) {
    for y in 0..dense.height {
        for x in 0..dense.width {
            let d = dense.get(x, y);
            if d.is_finite() && d > 0.0 {
                let z = view.rig.depth_from_disparity_px(d);
                let p = view.implied(x as f32 + 0.5, y as f32 + 0.5, z);
                f(x, y, mask.get(x, y) > 0.0, p);
            }
        }
    }
}

/// Counts the valid pixels of `dense` and those whose implied point is more than 0.1 m below
/// the road, streak pixels and others apart.
pub(super) fn summarize_dense(
    dense: &GrayImage,
    mask: &GrayImage,
    view: &RigView,
    max: i32,
    accuracy: Option<DenseAccuracy>,
) -> DenseSummary {
    let (mut valid, mut streak, mut streak_below, mut other_below) = (0usize, 0, 0, 0);
    for_each_point(dense, mask, view, |_, _, is_streak, p| {
        valid += 1;
        let below = p.y < -0.1;
        if is_streak {
            streak += 1;
            streak_below += below as usize;
        } else {
            other_below += below as usize;
        }
    });
    DenseSummary {
        range: (0, max),
        density: valid as f64 / dense.data.len().max(1) as f64,
        streak_pixels_below_road: streak_below,
        streak_pixels: streak,
        other_pixels_below_road: other_below,
        accuracy,
    }
}

#[cfg(test)]
mod tests {
    use super::super::{analyze, summary_table, AnalyzeParams};
    use super::*;
    use crate::synth::SynthScene;
    use glam::Affine3A;
    use streaks_stereo::rig::{Intrinsics, Rig};

    /// The paper's point in miniature: a box drawn at a larger disparity than the surface it
    /// lies on (as a streak shows the virtual light, not the road). SGM follows the image, so
    /// against the surface's ground truth the "streak" pixels are bad and the others good.
    #[test]
    fn dense_disparity_is_scored_against_the_truth_split_by_the_streak_mask() {
        let mut scene = SynthScene::textured(160, 120, 5);
        scene.boxes.truncate(1);
        scene.noise = 0.0;
        let b = scene.boxes[0];
        let pair = scene.render().unwrap();
        let mut truth = pair.disparity.clone();
        let mut mask = GrayImage::new(160, 120, 0.0).unwrap();
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                truth.set(x, y, scene.background_disparity(y));
                mask.set(x, y, 1.0);
            }
        }
        let rig = Rig::new(
            Intrinsics::new(160, 120, 150.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let mut input = StereoInput {
            left: pair.left,
            right: pair.right,
            rig,
            lights: Vec::new(),
            truth_disparity: Some(truth),
            truth_depth: None,
            truth_streak_mask: Some(mask),
            truth_road_mask: None,
        };
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        let acc = a.report.dense.accuracy.expect("scored against the truth");
        eprintln!("{acc:?}");
        assert_eq!(acc.streak_mask, "renderer");
        let box_pixels = (b.x1 - b.x0) * (b.y1 - b.y0);
        assert_eq!(acc.streak.truth_pixels, box_pixels);
        assert_eq!(acc.all.truth_pixels, 160 * 120);
        assert_eq!(acc.non_streak.truth_pixels, 160 * 120 - box_pixels);
        assert!(acc.non_streak.bad < 0.05, "{:?}", acc.non_streak);
        assert!(acc.non_streak.mean_abs < 0.5, "{:?}", acc.non_streak);
        assert!(acc.non_streak.density > 0.8, "{:?}", acc.non_streak);
        assert!(acc.streak.bad > 0.8, "{:?}", acc.streak);
        assert!(acc.streak.mean_abs > 4.0, "{:?}", acc.streak);
        assert!(acc.all.bad > acc.non_streak.bad && acc.all.bad < acc.streak.bad);
        let table = summary_table(&a.report);
        assert!(
            table.contains("bad-2.0") && table.contains("non-streak"),
            "{table}"
        );
        // Without its own mask the analysis splits by the detector's; without a truth there is
        // no score.
        input.truth_streak_mask = None;
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        assert_eq!(a.report.dense.accuracy.unwrap().streak_mask, "detector");
        input.truth_disparity = None;
        let a = analyze(&input, &AnalyzeParams::default()).unwrap();
        assert!(a.report.dense.accuracy.is_none());
    }
}
