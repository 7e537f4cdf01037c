//! The KITTI 2015 view of a dataset sample, as KITTI's stereo loaders read it (RAFT-Stereo's
//! `KITTI` with the view's folder as root; torchvision's `Kitti2015Stereo` with a folder
//! holding it as `Kitti2015/`): `image_2` and `image_3` are copies of its 8-bit images,
//! `disp_occ_0` its left disparity as uint16 x 256, `disp_occ_1` its right view's (torchvision
//! reads it as the right disparity), `disp_noc_0` the left disparity of the pixels the right
//! eye sees too (0 where `occ0.png` says occluded), `calib_cam_to_cam/NNNNNN.txt` the
//! rectified projection matrices `P_rect_02` (the left eye, the reference) and `P_rect_03` as
//! KITTI writes them; and, as KITTI's semantics benchmark has them, `semantic` a copy of its
//! left label ids (`semantic0.png`) and `instance` its left instances as `labelId * 256 + k`
//! (uint16; `labelId * 256` for stuff).

use crate::error::DatasetError;
use crate::files::SampleDir;
use crate::layout::Layout;
use crate::segmentation::{MAX_INSTANCES_PER_CLASS, MAX_KITTI_INSTANCES_PER_CLASS};
use image::{ImageBuffer, Luma};
use std::path::Path;
use streaks_image::kitti::write_kitti_disparity;
use streaks_image::pfm::read_pfm;
use streaks_image::png::write_png_buffer;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::calib::MiddleburyCalib;
use streaks_stereo::rig::Eye;

/// Writes the KITTI view of sample `index` from the files of its folder `sample` (which may
/// still be the sample's temporary folder: its images, disparities, left occlusion mask,
/// `calib.txt` and segmentation maps); each file atomically.
pub fn write_kitti(layout: &Layout, index: u64, sample: &SampleDir) -> Result<(), DatasetError> {
    let k = layout.kitti(index);
    for (src, dst) in [
        (sample.png(Eye::Left), &k.image_2),
        (sample.png(Eye::Right), &k.image_3),
        (sample.semantic(Eye::Left), &k.semantic),
    ] {
        let bytes = std::fs::read(&src).map_err(|e| DatasetError::io("read", &src, e))?;
        create_parent(dst)?;
        write_bytes_atomically(dst, &bytes)?;
    }
    let disp0 = read_pfm(&sample.disparity(Eye::Left))?;
    create_parent(&k.disp_occ_0)?;
    write_kitti_disparity(&k.disp_occ_0, &disp0)?;
    let disp1 = read_pfm(&sample.disparity(Eye::Right))?;
    create_parent(&k.disp_occ_1)?;
    write_kitti_disparity(&k.disp_occ_1, &disp1)?;
    let occ_path = sample.occlusion(Eye::Left);
    let occ = GrayImage::load(&occ_path)?;
    DatasetError::check_size(&occ_path, occ.size(), disp0.size(), "the left disparity is")?;
    let mut noc = disp0;
    for (d, &o) in noc.data.iter_mut().zip(&occ.data) {
        if o >= 0.5 {
            *d = f32::INFINITY;
        }
    }
    create_parent(&k.disp_noc_0)?;
    write_kitti_disparity(&k.disp_noc_0, &noc)?;
    let calib = sample.load_calib()?;
    create_parent(&k.calib)?;
    write_bytes_atomically(&k.calib, kitti_calib(&calib).as_bytes())?;
    let ids = kitti_instances(&sample.instance(Eye::Left))?;
    create_parent(&k.instance)?;
    write_png_buffer(&k.instance, &ids)?;
    Ok(())
}

/// A number as C's `%e` writes it (KITTI's calibration files): six decimals, the exponent
/// signed and of at least two digits (`7.215377e+02`).
fn c_exponent(v: f64) -> String {
    let text = format!("{:.6e}", v + 0.0);
    let (mantissa, exp) = text.split_once('e').expect("{:e} has an exponent");
    let exp: i32 = exp.parse().expect("{:e}'s exponent is an integer");
    let sign = if exp < 0 { '-' } else { '+' };
    format!("{mantissa}e{sign}{:02}", exp.abs())
}

/// The text of `calib_cam_to_cam/NNNNNN.txt` for a rig with the Middlebury calibration
/// `calib`, in KITTI's format (`KEY: v v v ...`, `%e` numbers): for cameras 02 (the left eye,
/// the reference: no translation) and 03 (the right eye, `baseline` to its right), the
/// rectified image size `S_rect_0x`, rotation `R_rect_0x` (identity: the pair is rectified)
/// and projection `P_rect_0x = K [I | t]` with `P_rect_03[0][3] = -f baseline` (metres), so
/// that the baseline is `(P_rect_02[0][3] - P_rect_03[0][3]) / f` as KITTI's users compute
/// it. `K` has the focal length and principal point of `calib.txt` (pixel coordinates with
/// the top-left pixel's centre at (0, 0), as KITTI's).
pub fn kitti_calib(calib: &MiddleburyCalib) -> String {
    let (f, cx, cy) = (calib.focal_px, calib.cx, calib.cy);
    let baseline_m = calib.baseline_mm / 1000.0;
    let line = |key: String, values: &[f64]| {
        let v: Vec<String> = values.iter().map(|&v| c_exponent(v)).collect();
        format!("{key}: {}\n", v.join(" "))
    };
    let mut text = String::new();
    for (cam, tx) in [("02", 0.0), ("03", -f * baseline_m)] {
        text += &line(
            format!("S_rect_{cam}"),
            &[f64::from(calib.width), f64::from(calib.height)],
        );
        text += &line(
            format!("R_rect_{cam}"),
            &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        );
        text += &line(
            format!("P_rect_{cam}"),
            &[f, 0.0, cx, tx, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
        );
    }
    text
}

/// The instance map at `path` (`instance0.png`: `labelId`, or `labelId * 1000 + k`) in KITTI's
/// convention, `labelId * 256 + k`; an error naming the file when a `k` does not fit.
pub fn kitti_instances(path: &Path) -> Result<ImageBuffer<Luma<u16>, Vec<u16>>, DatasetError> {
    let bytes = std::fs::read(path).map_err(|e| DatasetError::io("read", path, e))?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| DatasetError::Invalid {
            path: path.to_path_buf(),
            reason: format!("is not a PNG: {e}"),
        })?
        .into_luma16();
    let per = MAX_INSTANCES_PER_CLASS as u16;
    let mut out = ImageBuffer::new(img.width(), img.height());
    for (o, p) in out.pixels_mut().zip(img.pixels()) {
        let v = p.0[0];
        let (label, k) = if v < per { (v, 0) } else { (v / per, v % per) };
        if u32::from(k) >= MAX_KITTI_INSTANCES_PER_CLASS {
            return Err(DatasetError::Invalid {
                path: path.to_path_buf(),
                reason: format!(
                    "object {k} of label {label} does not fit KITTI's labelId * 256 + k"
                ),
            });
        }
        *o = Luma([label * 256 + k]);
    }
    Ok(out)
}

/// Creates the folder `path` goes into (a view's folders are made as its files are written).
pub(crate) fn create_parent(path: &Path) -> Result<(), DatasetError> {
    if let Some(p) = path.parent() {
        std::fs::create_dir_all(p).map_err(|e| DatasetError::io("create the folder", p, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_as_c_writes_them() {
        assert_eq!(c_exponent(721.5377), "7.215377e+02");
        assert_eq!(c_exponent(-339.5242), "-3.395242e+02");
        assert_eq!(c_exponent(0.0), "0.000000e+00");
        assert_eq!(c_exponent(-0.0), "0.000000e+00");
        assert_eq!(c_exponent(2.745884e-3), "2.745884e-03");
        assert_eq!(c_exponent(1e120), "1.000000e+120");
    }

    /// The file holds what KITTI's users read from it: 12 numbers per `P_rect` row by row,
    /// `P[0][0]` the focal length, `P[0][2]`, `P[1][2]` the principal point, and the baseline
    /// `(P_rect_02[0][3] - P_rect_03[0][3]) / P_rect_03[0][0]`.
    #[test]
    fn the_calibration_gives_back_focal_length_principal_point_and_baseline() {
        let calib = MiddleburyCalib {
            focal_px: 512.25,
            cx: 319.5,
            cy: 191.5,
            doffs: 0.0,
            baseline_mm: 250.0,
            width: 640,
            height: 384,
            ndisp: 64,
            isint: false,
            vmin: 1.0,
            vmax: 40.0,
            dyavg: 0.0,
            dymax: 0.0,
        };
        let text = kitti_calib(&calib);
        let read = |key: &str| -> Vec<f64> {
            let line = text
                .lines()
                .find_map(|l| l.strip_prefix(&format!("{key}: ")))
                .unwrap_or_else(|| panic!("no {key} in {text}"));
            line.split(' ').map(|v| v.parse().unwrap()).collect()
        };
        let (p2, p3) = (read("P_rect_02"), read("P_rect_03"));
        assert_eq!(p2.len(), 12);
        assert_eq!(p3.len(), 12);
        assert_eq!([p2[0], p2[2], p2[5], p2[6]], [512.25, 319.5, 512.25, 191.5]);
        assert_eq!(p2[3], 0.0);
        let baseline = (p2[3] - p3[3]) / p3[0];
        assert!((baseline - 0.25).abs() < 1e-6, "{baseline}");
        assert_eq!(read("S_rect_03"), [640.0, 384.0]);
        assert!(text.contains("P_rect_03: 5.122500e+02 0.000000e+00 3.195000e+02 -1.280625e+02 "));
    }
}
