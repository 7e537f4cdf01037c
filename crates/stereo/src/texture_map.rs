//! The ground-plane texture map of the paper's Fig. 3: an image resampled onto road
//! coordinates (X, Z).
//!
//! Each map cell is a road point `(X, 0, Z)` (road frame of [`crate::rig`]: X right, Z forward);
//! it is taken to the world, projected through one eye of the rig and the image is sampled there
//! bilinearly. This is the image-to-ground homography; for a level rig of height `h` it is the
//! paper's `(x, y) <-> (f X / Z, f h / Z)` (x, y from the principal point, y down), and for a
//! pitched rig it is the same homography with the pitch folded in. Cells outside the view (or
//! behind the eye) have no value.
//!
//! The map's row 0 is the far edge (`Z` largest) and column 0 the left edge (`X` smallest), so
//! the picture is the road seen from above with the rig at the bottom. [`plot_texture_map`] draws
//! it with axes in metres (plotters, the committed DejaVu Sans font through `ab_glyph`, so no
//! system fonts are needed).

use crate::error::StereoError;
use crate::rig::{Eye, Rig};
use glam::{Vec2, Vec3};
use plotters::prelude::*;
use std::path::Path;
use streaks_image::png::write_png_buffer;
use streaks_image::{ensure_same_size, GrayImage};

/// Largest map, in cells.
const MAX_CELLS: usize = 1 << 26;

/// The region and resolution of a texture map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSpec {
    /// Road X range (metres), `min < max`.
    pub x_range: (f32, f32),
    /// Road Z range (metres), `min < max`.
    pub z_range: (f32, f32),
    /// Cell size (metres).
    pub resolution: f32,
    nx: usize,
    nz: usize,
}

impl MapSpec {
    /// A map spec; an error for empty or non-finite ranges, a resolution that is not positive,
    /// or more than 2^26 cells.
    pub fn new(
        x_range: (f32, f32),
        z_range: (f32, f32),
        resolution: f32,
    ) -> Result<Self, StereoError> {
        let bad = |name, reason: String| Err(StereoError::Parameter { name, reason });
        for (name, (a, b)) in [("x-range", x_range), ("z-range", z_range)] {
            if !(a.is_finite() && b.is_finite() && a < b) {
                return bad(name, format!("{a},{b} must be finite with min < max"));
            }
        }
        if !(resolution.is_finite() && resolution > 0.0) {
            return bad("resolution", format!("{resolution} m must be positive"));
        }
        let cells = |(a, b): (f32, f32)| ((b - a) / resolution).round().max(1.0);
        let (nx, nz) = (cells(x_range), cells(z_range));
        if nx * nz > MAX_CELLS as f32 {
            return bad(
                "resolution",
                format!("{nx} x {nz} cells is more than 2^26; use a coarser resolution"),
            );
        }
        Ok(Self {
            x_range,
            z_range,
            resolution,
            nx: nx as usize,
            nz: nz as usize,
        })
    }

    /// Number of columns (cells along X).
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Number of rows (cells along Z).
    pub fn nz(&self) -> usize {
        self.nz
    }

    /// Road (X, Z) of the centre of cell (column `i`, row `j`); row 0 is the far edge.
    pub fn cell_centre(&self, i: usize, j: usize) -> (f32, f32) {
        (
            self.x_range.0 + (i as f32 + 0.5) * self.resolution,
            self.z_range.1 - (j as f32 + 0.5) * self.resolution,
        )
    }
}

/// A texture map: one [`GrayImage`] per channel of the source image, NaN outside the view.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMap {
    /// Its region and resolution.
    pub spec: MapSpec,
    /// The channels (1 for grey, 3 for RGB), `nx` x `nz` each.
    pub channels: Vec<GrayImage>,
}

/// Resamples `channels` (an image seen by `eye` of `rig`, the rig's size) onto the road.
pub fn texture_map(
    channels: &[GrayImage],
    rig: &Rig,
    eye: Eye,
    spec: &MapSpec,
) -> Result<TextureMap, StereoError> {
    let intr = rig.intrinsics();
    let (w, h) = (intr.width() as usize, intr.height() as usize);
    for c in channels {
        ensure_same_size(
            "the texture-mapped image",
            c.size(),
            "the rig's image",
            (w, h),
        )?;
    }
    let road = rig.road_frame()?;
    let cam = rig.eye(eye);
    let mut out = channels
        .iter()
        .map(|_| GrayImage::new(spec.nx, spec.nz, f32::NAN))
        .collect::<Result<Vec<_>, _>>()?;
    for j in 0..spec.nz {
        for i in 0..spec.nx {
            let (x, z) = spec.cell_centre(i, j);
            let p = road.world_from_road_point(Vec3::new(x, 0.0, z));
            let Some(px) = cam.project(p) else { continue };
            for (o, c) in out.iter_mut().zip(channels) {
                if let Some(v) = c.sample_bilinear(px.x, px.y) {
                    o.set(i, j, v);
                }
            }
        }
    }
    Ok(TextureMap {
        spec: *spec,
        channels: out,
    })
}

/// Where a road point (X, 0, Z) appears in `eye`'s image (the homography used by
/// [`texture_map`]); `None` behind the eye or without a road frame.
pub fn road_to_pixel(rig: &Rig, eye: Eye, x: f32, z: f32) -> Option<Vec2> {
    let road = rig.road_frame().ok()?;
    rig.eye(eye)
        .project(road.world_from_road_point(Vec3::new(x, 0.0, z)))
}

/// Colour of cells outside the view.
const OUTSIDE: [u8; 3] = [40, 40, 64];

/// Draws `map` as a PNG with its axes labelled in metres (X across, Z up, the rig at the
/// bottom), the values clipped to [0, 1], out-of-view cells dark blue-grey.
pub fn plot_texture_map(map: &TextureMap, path: &Path, title: &str) -> Result<(), StereoError> {
    crate::font::register_sans_serif()?;
    let spec = &map.spec;
    let (nx, nz) = (spec.nx, spec.nz);
    // Magnify small maps (nearest cell) so the labels fit.
    let scale = (400usize.div_ceil(nx.min(nz))).clamp(1, 8);
    let (pw, ph) = (nx * scale, nz * scale);
    let (left, bottom, top, right) = (80usize, 55usize, 40usize, 25usize);
    let margin_left = 30usize;
    let (cw, ch) = (pw + margin_left + left + right, ph + bottom + top);
    let mut buf = vec![255u8; cw * ch * 3];
    let plot_err = |e: String| StereoError::Parameter {
        name: "plot",
        reason: e,
    };
    let (xr, yr) = {
        let root = BitMapBackend::with_buffer(&mut buf, (cw as u32, ch as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin_top(8)
            .margin_left(margin_left as u32)
            .margin_right(right as u32)
            .x_label_area_size(bottom as u32)
            .y_label_area_size(left as u32)
            .build_cartesian_2d(
                spec.x_range.0..spec.x_range.1,
                spec.z_range.0..spec.z_range.1,
            )
            .map_err(|e| plot_err(e.to_string()))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("X (m), road frame")
            .y_desc("Z (m), road frame")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| plot_err(e.to_string()))?;
        let range = chart.plotting_area().get_pixel_range();
        root.present().map_err(|e| plot_err(e.to_string()))?;
        range
    };
    // Fill the plotting area with the map (nearest cell).
    let (x0, x1, y0, y1) = (xr.start.max(0), xr.end, yr.start.max(0), yr.end);
    let (aw, ah) = ((x1 - x0).max(1) as f32, (y1 - y0).max(1) as f32);
    for py in y0..y1.min(ch as i32) {
        let j = (((py - y0) as f32 + 0.5) / ah * nz as f32) as usize;
        for px in x0..x1.min(cw as i32) {
            let i = (((px - x0) as f32 + 0.5) / aw * nx as f32) as usize;
            let (i, j) = (i.min(nx - 1), j.min(nz - 1));
            let rgb = match map.channels.len() {
                3 => [0, 1, 2].map(|c| map.channels[c].get(i, j)),
                _ => [map.channels[0].get(i, j); 3],
            };
            let o = (py as usize * cw + px as usize) * 3;
            if rgb.iter().any(|v| v.is_nan()) {
                buf[o..o + 3].copy_from_slice(&OUTSIDE);
            } else {
                for c in 0..3 {
                    buf[o + c] = (rgb[c].clamp(0.0, 1.0) * 255.0).round() as u8;
                }
            }
        }
    }
    let img = image::RgbImage::from_raw(cw as u32, ch as u32, buf)
        .ok_or_else(|| plot_err("canvas size".into()))?;
    Ok(write_png_buffer(path, &img)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::Intrinsics;
    use glam::{Affine3A, Quat};

    /// A synthetic image of a checkerboard road (0.5 m cells), as `eye` of `rig` sees it,
    /// supersampled 4x4 per pixel; the sky is 0.5.
    fn checkerboard_view(rig: &Rig, eye: Eye) -> GrayImage {
        let intr = rig.intrinsics();
        let (w, h) = (intr.width() as usize, intr.height() as usize);
        let road = rig.road_frame().unwrap();
        let cam = rig.eye(eye);
        let mut img = GrayImage::new(w, h, 0.5).unwrap();
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for s in 0..16 {
                    let px = Vec2::new(
                        x as f32 + (s % 4) as f32 / 4.0 + 0.125,
                        y as f32 + (s / 4) as f32 / 4.0 + 0.125,
                    );
                    let d = cam.ray_direction(px);
                    let o = cam.position();
                    acc += if d.y < -1e-6 {
                        let q = road.road_from_world_point(o + d * (-o.y / d.y));
                        let cell = (q.x / 0.5).floor() as i64 + (q.z / 0.5).floor() as i64;
                        if cell.rem_euclid(2) == 0 {
                            1.0
                        } else {
                            0.0
                        }
                    } else {
                        0.5
                    };
                }
                img.set(x, y, acc / 16.0);
            }
        }
        img
    }

    /// Lengths of the runs of equal thresholded values along a line of cells, without the
    /// partial runs at both ends.
    fn inner_runs(values: impl Iterator<Item = f32>) -> Vec<usize> {
        let bits: Vec<bool> = values.map(|v| v > 0.5).collect();
        let mut runs = vec![];
        let mut n = 1;
        for w in bits.windows(2) {
            if w[0] == w[1] {
                n += 1;
            } else {
                runs.push(n);
                n = 1;
            }
        }
        runs.remove(0);
        runs
    }

    #[test]
    fn checkerboard_ground_maps_to_square_cells() {
        // A pitched-down, yawed rig 1.5 m above the road.
        let pose = Affine3A::from_rotation_translation(
            Quat::from_rotation_y(0.2) * Quat::from_rotation_x(-0.15),
            Vec3::new(0.3, 1.5, 0.0),
        );
        let rig = Rig::new(Intrinsics::from_yfov(320, 240, 0.9).unwrap(), 0.065, pose).unwrap();
        let img = checkerboard_view(&rig, Eye::Left);
        let spec = MapSpec::new((-2.0, 2.0), (3.0, 7.0), 0.05).unwrap();
        assert_eq!((spec.nx(), spec.nz()), (80, 80));
        let map = texture_map(&[img], &rig, Eye::Left, &spec).unwrap();
        let m = &map.channels[0];
        // The board is laid out in road coordinates; the map must reproduce it cell for cell.
        let mut agree = 0;
        let mut total = 0;
        for j in 0..spec.nz() {
            for i in 0..spec.nx() {
                let v = m.get(i, j);
                if v.is_nan() {
                    continue;
                }
                let (x, z) = spec.cell_centre(i, j);
                total += 1;
                let cell = (x / 0.5).floor() as i64 + (z / 0.5).floor() as i64;
                let expect = if cell.rem_euclid(2) == 0 { 1.0 } else { 0.0 };
                if (v - expect).abs() < 0.5 {
                    agree += 1;
                }
            }
        }
        assert!(total > 3000, "most of the map is in view: {total}");
        assert!(agree as f32 > 0.97 * total as f32, "{agree} of {total}");
        // Square cells: runs along X (a row) and along Z (a column) are all 10 map cells long.
        let row: Vec<usize> = inner_runs((0..spec.nx()).map(|i| m.get(i, 70)));
        let col: Vec<usize> = inner_runs((0..spec.nz()).map(|j| m.get(40, j)));
        assert!(row.len() >= 4 && col.len() >= 4, "{row:?} {col:?}");
        for r in row.iter().chain(&col) {
            assert!((9..=11).contains(r), "runs {row:?} (X) and {col:?} (Z)");
        }
    }

    #[test]
    fn level_rig_matches_the_papers_homography() {
        let h = 1.5;
        let rig = Rig::new(
            Intrinsics::new(640, 480, 500.0).unwrap(),
            0.065,
            Affine3A::from_translation(Vec3::new(0.0, h, 0.0)),
        )
        .unwrap();
        let f = 500.0;
        for (x, z) in [(1.0f32, 5.0f32), (-3.0, 20.0), (0.0, 40.0)] {
            // The left eye is b/2 to the left: X relative to it is x + b/2.
            let px = road_to_pixel(&rig, Eye::Left, x, z).unwrap();
            let expect = Vec2::new(320.0 + f * (x + 0.0325) / z, 240.0 + f * h / z);
            assert!((px - expect).length() < 1e-3, "{px} vs {expect}");
        }
    }

    #[test]
    fn bad_specs_and_sizes_are_errors() {
        assert!(MapSpec::new((1.0, -1.0), (2.0, 40.0), 0.05).is_err());
        assert!(MapSpec::new((-1.0, 1.0), (2.0, f32::NAN), 0.05).is_err());
        assert!(MapSpec::new((-1.0, 1.0), (2.0, 40.0), 0.0).is_err());
        assert!(MapSpec::new((-1e4, 1e4), (0.0, 1e4), 0.01).is_err());
        let rig = Rig::new(
            Intrinsics::new(64, 48, 50.0).unwrap(),
            0.1,
            Affine3A::from_translation(Vec3::Y),
        )
        .unwrap();
        let spec = MapSpec::new((-1.0, 1.0), (2.0, 4.0), 0.5).unwrap();
        let img = GrayImage::new(10, 10, 0.0).unwrap();
        assert!(matches!(
            texture_map(&[img], &rig, Eye::Left, &spec),
            Err(StereoError::SizeMismatch(_))
        ));
    }

    #[test]
    fn plot_writes_a_labelled_png() {
        let rig = Rig::new(
            Intrinsics::new(64, 48, 50.0).unwrap(),
            0.1,
            Affine3A::from_translation(Vec3::Y),
        )
        .unwrap();
        let img = GrayImage::new(64, 48, 0.8).unwrap();
        let spec = MapSpec::new((-2.0, 2.0), (2.0, 10.0), 0.1).unwrap();
        let map = texture_map(&[img], &rig, Eye::Left, &spec).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("map.png");
        plot_texture_map(&map, &p, "test").unwrap();
        let png = image::open(&p).unwrap().to_rgb8();
        assert!(png.width() > 40 * 8 && png.height() > 80 * 5);
        // Both the in-view value (0.8 -> 204) and the out-of-view colour appear.
        assert!(png.pixels().any(|p| p.0 == [204, 204, 204]));
        assert!(png.pixels().any(|p| p.0 == OUTSIDE));
    }
}
