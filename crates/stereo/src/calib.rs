//! `calib.txt` in the Middlebury 2014 format, for a rectified [`Rig`].
//!
//! ```text
//! cam0=[f 0 cx; 0 f cy; 0 0 1]
//! cam1=[f 0 cx+doffs; 0 f cy; 0 0 1]
//! doffs=0
//! baseline=65
//! width=640
//! height=384
//! ndisp=96
//! isint=0
//! vmin=1.5
//! vmax=83.2
//! dyavg=0
//! dymax=0
//! ```
//!
//! `baseline` is in millimetres, `f`, `cx`, `cy` in pixels with Middlebury's (and OpenCV's)
//! pixel coordinates, where the centre of the top-left pixel is (0, 0): the rig's principal point
//! (the image centre, `(W/2, H/2)` in this project's coordinates where pixel centres are at
//! `i + 0.5`) is therefore `cx = (W - 1) / 2`, `cy = (H - 1) / 2`. Both eyes share the
//! intrinsics, so `doffs = 0` and `Z = f * baseline / (d + doffs)`. `ndisp` is the smallest
//! multiple of 16 above the largest disparity, `vmin`/`vmax` the range of the finite disparities,
//! `dyavg`/`dymax` the vertical disparity (0: rectified by construction).

use crate::error::StereoError;
use crate::rig::Rig;
use std::path::Path;

/// The contents of a Middlebury 2014 `calib.txt` (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MiddleburyCalib {
    /// Focal length in pixels (both eyes).
    pub focal_px: f64,
    /// Principal point x of the left camera (Middlebury pixel coordinates).
    pub cx: f64,
    /// Principal point y (both cameras).
    pub cy: f64,
    /// x-difference of the principal points (`cx1 - cx0`).
    pub doffs: f64,
    /// Baseline in millimetres.
    pub baseline_mm: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// A bound on the disparity, a multiple of 16.
    pub ndisp: u32,
    /// Whether the disparities are integers.
    pub isint: bool,
    /// Smallest finite disparity.
    pub vmin: f64,
    /// Largest finite disparity.
    pub vmax: f64,
    /// Mean vertical disparity.
    pub dyavg: f64,
    /// Largest vertical disparity.
    pub dymax: f64,
}

/// The smallest multiple of 16 strictly above `max_disparity` (16 at least).
pub fn ndisp_above(max_disparity: f64) -> u32 {
    let m = if max_disparity.is_finite() {
        max_disparity.max(0.0)
    } else {
        0.0
    };
    ((m / 16.0).floor() as u32 + 1).saturating_mul(16)
}

/// The `f64` whose shortest decimal form is that of `x` (so that `0.2_f32` is written 0.2, not
/// 0.20000000298023224).
fn decimal(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(x as f64)
}

impl MiddleburyCalib {
    /// The calibration of `rig` whose finite disparities span `range` (`None`: no finite
    /// disparity, written as 0 and 0).
    pub fn of_rig(rig: &Rig, range: Option<(f32, f32)>) -> Self {
        let i = rig.intrinsics();
        let pp = i.principal_point();
        let (vmin, vmax) = range.map_or((0.0, 0.0), |(a, b)| (decimal(a), decimal(b)));
        Self {
            focal_px: decimal(rig.focal_px()),
            cx: decimal(pp.x) - 0.5,
            cy: decimal(pp.y) - 0.5,
            doffs: 0.0,
            baseline_mm: decimal(rig.baseline() * 1000.0),
            width: i.width(),
            height: i.height(),
            ndisp: ndisp_above(vmax),
            isint: false,
            vmin,
            vmax,
            dyavg: 0.0,
            dymax: 0.0,
        }
    }

    /// The depth in metres of a disparity of `d` pixels: `f * baseline / (d + doffs)`.
    pub fn depth_m(&self, d: f64) -> f64 {
        self.focal_px * self.baseline_mm / 1000.0 / (d + self.doffs)
    }

    /// The file's text (one `key=value` per line, in Middlebury's order).
    pub fn to_text(&self) -> String {
        let f = self.focal_px;
        format!(
            "cam0=[{f} 0 {cx}; 0 {f} {cy}; 0 0 1]\ncam1=[{f} 0 {cx1}; 0 {f} {cy}; 0 0 1]\n\
             doffs={doffs}\nbaseline={b}\nwidth={w}\nheight={h}\nndisp={n}\nisint={int}\n\
             vmin={vmin}\nvmax={vmax}\ndyavg={dyavg}\ndymax={dymax}\n",
            cx = self.cx,
            cy = self.cy,
            cx1 = self.cx + self.doffs,
            doffs = self.doffs,
            b = self.baseline_mm,
            w = self.width,
            h = self.height,
            n = self.ndisp,
            int = self.isint as u8,
            vmin = self.vmin,
            vmax = self.vmax,
            dyavg = self.dyavg,
            dymax = self.dymax,
        )
    }

    /// Parses the text of a `calib.txt` (Middlebury's own files included: `vmin`, `vmax`,
    /// `dyavg` and `dymax` may be absent and are then 0); the error says which line is wrong.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut values = std::collections::BTreeMap::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            let (key, value) = line
                .split_once('=')
                .ok_or_else(|| format!("line {}: {line:?} is not key=value", n + 1))?;
            values.insert(key.trim().to_owned(), value.trim().to_owned());
        }
        let get = |key: &str| {
            values
                .get(key)
                .ok_or_else(|| format!("no {key}= line"))
                .map(String::as_str)
        };
        let number = |key: &str, default: Option<f64>| -> Result<f64, String> {
            match (values.get(key), default) {
                (None, Some(d)) => Ok(d),
                _ => get(key)?
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("{key}={} is not a number", get(key).unwrap_or(""))),
            }
        };
        let integer = |key: &str| -> Result<u32, String> {
            get(key)?
                .parse::<u32>()
                .map_err(|_| format!("{key}={} is not a whole number", get(key).unwrap_or("")))
        };
        let cam0 = camera_matrix(get("cam0")?).map_err(|e| format!("cam0: {e}"))?;
        let cam1 = camera_matrix(get("cam1")?).map_err(|e| format!("cam1: {e}"))?;
        let doffs = number("doffs", None)?;
        if cam0[0] != cam1[0] || cam0[2] != cam1[2] {
            return Err(format!(
                "cam0 and cam1 differ in f or cy ({cam0:?}, {cam1:?}): not a rectified pair"
            ));
        }
        if ((cam1[1] - cam0[1]) - doffs).abs() > 1e-3 * doffs.abs().max(1.0) {
            return Err(format!(
                "doffs={doffs} is not cam1's cx {} minus cam0's cx {}",
                cam1[1], cam0[1]
            ));
        }
        Ok(Self {
            focal_px: cam0[0],
            cx: cam0[1],
            cy: cam0[2],
            doffs,
            baseline_mm: number("baseline", None)?,
            width: integer("width")?,
            height: integer("height")?,
            ndisp: integer("ndisp")?,
            isint: match get("isint")? {
                "0" => false,
                "1" => true,
                other => return Err(format!("isint={other} is not 0 or 1")),
            },
            vmin: number("vmin", Some(0.0))?,
            vmax: number("vmax", Some(0.0))?,
            dyavg: number("dyavg", Some(0.0))?,
            dymax: number("dymax", Some(0.0))?,
        })
    }

    /// Writes the file (atomically).
    pub fn save(&self, path: &Path) -> Result<(), StereoError> {
        Ok(streaks_image::write_bytes_atomically(
            path,
            self.to_text().as_bytes(),
        )?)
    }

    /// Reads and parses a file.
    pub fn load(path: &Path) -> Result<Self, StereoError> {
        let err = |reason: String| StereoError::CalibFile {
            path: path.to_path_buf(),
            reason,
        };
        let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
            .map_err(|e| err(e.to_string()))?;
        Self::parse(&text).map_err(err)
    }
}

/// `f`, `cx`, `cy` of `[f 0 cx; 0 f cy; 0 0 1]`.
fn camera_matrix(text: &str) -> Result<[f64; 3], String> {
    let inner = text
        .strip_prefix('[')
        .and_then(|t| t.strip_suffix(']'))
        .ok_or_else(|| format!("{text:?} is not [a b c; d e f; g h i]"))?;
    let rows: Vec<Vec<f64>> = inner
        .split(';')
        .map(|row| {
            row.split_whitespace()
                .map(|v| {
                    v.parse::<f64>()
                        .map_err(|_| format!("{v:?} is not a number"))
                })
                .collect()
        })
        .collect::<Result<_, _>>()?;
    match rows.as_slice() {
        [r0, r1, r2]
            if r0.len() == 3
                && r1.len() == 3
                && r2 == &[0.0, 0.0, 1.0]
                && r0[1] == 0.0
                && r1[0] == 0.0
                && r0[0] == r1[1]
                && r0[0] > 0.0 =>
        {
            Ok([r0[0], r0[2], r1[2]])
        }
        _ => Err(format!(
            "{text:?} is not a camera matrix [f 0 cx; 0 f cy; 0 0 1] with f > 0"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::Intrinsics;
    use glam::{Affine3A, Vec3};

    #[test]
    fn a_rig_round_trips_and_gives_depth_from_disparity() {
        let rig = Rig::new(
            Intrinsics::new(64, 40, 50.0).unwrap(),
            0.2,
            Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
        let calib = MiddleburyCalib::of_rig(&rig, Some((0.5, 33.25)));
        assert_eq!((calib.cx, calib.cy), (31.5, 19.5));
        assert_eq!(calib.ndisp, 48);
        assert_eq!(calib.baseline_mm, 200.0);
        let text = calib.to_text();
        assert!(
            text.starts_with("cam0=[50 0 31.5; 0 50 19.5; 0 0 1]\n"),
            "{text}"
        );
        assert!(
            text.contains("\nndisp=48\nisint=0\nvmin=0.5\nvmax=33.25\n"),
            "{text}"
        );
        assert_eq!(MiddleburyCalib::parse(&text).unwrap(), calib);
        let z = 7.0f32;
        let d = rig.disparity_px(z) as f64;
        assert!(
            (calib.depth_m(d) - 7.0).abs() < 1e-5,
            "{}",
            calib.depth_m(d)
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("calib.txt");
        calib.save(&path).unwrap();
        assert_eq!(MiddleburyCalib::load(&path).unwrap(), calib);
    }

    #[test]
    fn middlebury_files_parse_and_bad_ones_say_why() {
        let text = "cam0=[3997.684 0 1176.728; 0 3997.684 1011.728; 0 0 1]\n\
                    cam1=[3997.684 0 1307.839; 0 3997.684 1011.728; 0 0 1]\n\
                    doffs=131.111\nbaseline=193.001\nwidth=2964\nheight=1988\nndisp=280\n\
                    isint=0\nvmin=31\nvmax=257\ndyavg=0.918\ndymax=1.516\n";
        let c = MiddleburyCalib::parse(text).unwrap();
        assert_eq!((c.width, c.ndisp, c.doffs), (2964, 280, 131.111));
        let bad = text.replace("ndisp=280", "ndisp=many");
        assert!(MiddleburyCalib::parse(&bad).unwrap_err().contains("ndisp"));
        let bad = text.replace("doffs=131.111", "doffs=3");
        assert!(MiddleburyCalib::parse(&bad).unwrap_err().contains("doffs"));
        let bad = text.replace(
            "0 3997.684 1011.728; 0 0 1]\ndoffs",
            "0 3 1011.728; 0 0 1]\ndoffs",
        );
        assert!(MiddleburyCalib::parse(&bad).unwrap_err().contains("cam1"));
        assert!(MiddleburyCalib::parse("width=3")
            .unwrap_err()
            .contains("cam0"));
        assert_eq!(ndisp_above(0.0), 16);
        assert_eq!(ndisp_above(16.0), 32);
        assert_eq!(ndisp_above(15.9), 16);
        assert_eq!(ndisp_above(f64::NAN), 16);
        let err = MiddleburyCalib::load(Path::new("/no/such/calib.txt")).unwrap_err();
        assert!(err.to_string().contains("/no/such/calib.txt"), "{err}");
    }
}
