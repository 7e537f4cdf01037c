//! Writing a rendered pair into a sample folder (feature `render`): the one writer of a
//! sample's images and ground truth, for `streaks stereo`, `streaks dataset generate` and
//! `streaks paper` alike.

use crate::error::DatasetError;
use crate::files::SampleDir;
use crate::segmentation::{InstanceNumbering, MAX_INSTANCES_PER_CLASS};
use image::RgbImage;
use streaks_image::kitti::write_kitti_flow;
use streaks_image::pfm::{write_pfm, write_pfm_rgb};
use streaks_image::png::write_png_buffer;
use streaks_image::GrayImage;
use streaks_render::output::write_exr_with_sensor;
use streaks_render::scene::Scene;
use streaks_stereo::calib::MiddleburyCalib;
use streaks_stereo::flow::FlowField;
use streaks_stereo::occlusion::occlusion_mask;
use streaks_stereo::pair::write_pair_views;
use streaks_stereo::render::{light_records, scene_has_road, EyeView};
use streaks_stereo::rig::{Eye, Rig};
use streaks_stereo::rigfile::RigFile;

/// Which views get their streak and road masks written (depth, disparity and occlusion are
/// written for both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroundTruth {
    /// The left view's only (a dataset sample: `streaks0.png`, `road0.png`).
    Left,
    /// Both views' (a `streaks stereo` folder: also `streaks1.png`, `road1.png`).
    Both,
}

/// Writes both views of a rendered pair into `files` (whose folder must exist): per eye the
/// EXR with its layers (and the `sensor` layer of a view exposed through a camera model), the
/// 8-bit sRGB PNG (at `exposure_ev` stops, or developed from the camera's DN) and the ground-truth
/// disparity, the rain mask (when the scene has rain) and the fog's transmittance (when it
/// has fog), the segmentation maps ([`write_segmentation`]), the depth and the occlusion mask
/// ([`occlusion_mask`]); the streak mask and (when the scene flags a road material)
/// road-surface mask of the views `truth` says.
/// Returns the two sRGB images.
pub fn write_views(
    files: &SampleDir,
    scene: &Scene,
    views: &[EyeView; 2],
    exposure_ev: f32,
    truth: GroundTruth,
) -> Result<[RgbImage; 2], DatasetError> {
    let has_road = scene_has_road(scene);
    let mut srgb = Vec::with_capacity(2);
    for ((eye, view), other) in Eye::BOTH.into_iter().zip(views).zip(views.iter().rev()) {
        let raw = view.sensor.as_ref();
        write_exr_with_sensor(&files.exr(eye), &view.output, raw.map(|c| &c.dn))?;
        let img = view.camera_image(exposure_ev)?;
        write_png_buffer(&files.png(eye), &img)?;
        srgb.push(img);
        write_pfm(&files.disparity(eye), &view.disparity)?;
        let (w, h) = (view.disparity.width, view.disparity.height);
        if let Some(rain) = &view.output.rain {
            GrayImage::from_vec(w, h, rain.clone())?.save_png(&files.rain_mask(eye))?;
        }
        if let Some(fog) = &view.output.fog {
            write_pfm(&files.fog(eye), &GrayImage::from_vec(w, h, fog.clone())?)?;
        }
        write_pfm(&files.depth(eye), &view.depth)?;
        occlusion_mask(eye, &view.depth, &view.disparity, &other.depth)?
            .save_png(&files.occlusion(eye))?;
        if eye == Eye::Left || truth == GroundTruth::Both {
            view.streak_mask.save_png(&files.streak_mask(eye))?;
            if has_road {
                view.road_surface_mask()?.save_png(&files.road_mask(eye))?;
            }
        }
    }
    write_segmentation(files, scene, views)?;
    let [left, right]: [RgbImage; 2] = srgb.try_into().expect("two views");
    Ok([left, right])
}

/// The numbering of `scene`'s objects in its instance maps
/// ([`crate::segmentation::InstanceNumbering`]); too many objects of one class is an error
/// naming the sample folder `files`.
pub fn instance_numbering(
    files: &SampleDir,
    scene: &Scene,
) -> Result<InstanceNumbering, DatasetError> {
    InstanceNumbering::new(&scene.objects).map_err(|reason| DatasetError::Invalid {
        path: files.path().to_path_buf(),
        reason,
    })
}

/// Writes each view's semantic map (`semantic0.png`, [`EyeView::semantic`], 8-bit) and
/// instance map (`instance0.png`, 16-bit Cityscapes instance ids from the view's `object`
/// layer and [`instance_numbering`]); see [`crate::segmentation`].
pub fn write_segmentation(
    files: &SampleDir,
    scene: &Scene,
    views: &[EyeView; 2],
) -> Result<(), DatasetError> {
    let numbering = instance_numbering(files, scene)?;
    for (eye, view) in Eye::BOTH.into_iter().zip(views) {
        let (w, h) = (view.disparity.width as u32, view.disparity.height as u32);
        let missing = |what: &str| DatasetError::Invalid {
            path: files.semantic(eye),
            reason: format!("the {eye} view has no {what}"),
        };
        let semantic = image::GrayImage::from_raw(w, h, view.semantic.clone())
            .ok_or_else(|| missing("semantic map of its size"))?;
        write_png_buffer(&files.semantic(eye), &semantic)?;
        let slots = view
            .output
            .object
            .as_ref()
            .ok_or_else(|| missing("object layer"))?;
        let ids = numbering.map(&scene.objects, slots, MAX_INSTANCES_PER_CLASS);
        let instance = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, ids)
            .ok_or_else(|| missing("object layer of its size"))?;
        write_png_buffer(&files.instance(eye), &instance)?;
    }
    Ok(())
}

/// Writes a rendered pair as `streaks stereo -o DIR` does into `dir` (which must exist): both
/// views with their ground truth ([`write_views`], [`GroundTruth::Both`]), `side_by_side.png`,
/// `anaglyph.png`, `rig.json` and `calib.txt` ([`write_calib`]).
pub fn write_pair(
    dir: &std::path::Path,
    scene: &Scene,
    rig: &Rig,
    views: &[EyeView; 2],
    exposure_ev: f32,
) -> Result<(), DatasetError> {
    let files = SampleDir::new(dir);
    let [left, right] = write_views(&files, scene, views, exposure_ev, GroundTruth::Both)?;
    write_pair_views(&files.side_by_side(), &files.anaglyph(), &left, &right)?;
    let road = rig.road_frame().ok();
    RigFile::new(rig, light_records(scene, road.as_ref())).save(&files.rig_json())?;
    write_calib(&files, rig, &views[0])
}

/// Writes the left view's flow to the next frame into `files`: `flow0.png` (KITTI flow_occ
/// style: a value where the point is in the next image, visible or occluded), `flow0.pfm`
/// (u, v, 0; `inf` where the point has no projection), `dispchange0.pfm` and `flowmask0.png`
/// (the [`FlowState`] of each pixel).
pub fn write_flow(files: &SampleDir, flow: &FlowField) -> Result<(), DatasetError> {
    let (w, h) = (flow.width, flow.height);
    let kitti: Vec<Option<[f32; 2]>> = flow
        .flow
        .iter()
        .zip(&flow.state)
        .map(|(f, s)| s.has_flow().then_some(*f))
        .collect();
    write_kitti_flow(&files.flow_png(), w, h, &kitti)?;
    let rgb = streaks_image::RgbImage {
        width: w as u32,
        height: h as u32,
        pixels: flow
            .flow
            .iter()
            .map(|f| {
                let z = if f[0].is_finite() { 0.0 } else { f32::INFINITY };
                glam::Vec3::new(f[0], f[1], z)
            })
            .collect(),
    };
    write_pfm_rgb(&files.flow_pfm(), &rgb)?;
    write_pfm(
        &files.disparity_change(),
        &GrayImage::from_vec(w, h, flow.disparity_change.clone())?,
    )?;
    let mask: Vec<u8> = flow.state.iter().map(|s| s.mask_value()).collect();
    let img = image::GrayImage::from_raw(w as u32, h as u32, mask).ok_or_else(|| {
        DatasetError::Invalid {
            path: files.flow_mask(),
            reason: format!("{w}x{h} flow mask of {} pixels", flow.state.len()),
        }
    })?;
    write_png_buffer(&files.flow_mask(), &img)?;
    Ok(())
}

/// The range `(min, max)` of a view's finite ground-truth disparities; `None` when there is
/// none.
pub fn disparity_range(view: &EyeView) -> Option<(f32, f32)> {
    view.disparity
        .data
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(None, |r: Option<(f32, f32)>, d| {
            Some(r.map_or((d, d), |(a, b)| (a.min(d), b.max(d))))
        })
}

/// Writes `calib.txt`, the Middlebury 2014 calibration of `rig`, with the left view's
/// [`disparity_range`] as `vmin` and `vmax` (0 and 0 when it has none).
pub fn write_calib(files: &SampleDir, rig: &Rig, left: &EyeView) -> Result<(), DatasetError> {
    MiddleburyCalib::of_rig(rig, disparity_range(left)).save(&files.calib())?;
    Ok(())
}
