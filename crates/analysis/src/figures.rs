//! The paper's figures of the model, made from [`crate::model`] and drawn with
//! [`crate::plot`]. Lengths are in units of the light's depth `Z_L` (the paper's Fig. 4 gives
//! heights as fractions of it); the viewer stands at depth 0, everything in one X plane.
//!
//! - [`fig4`]: three lights at heights `Z_L/20`, `Z_L/10`, `3 Z_L/20`, a viewer at `Z_L/10`,
//!   and the locus of `L_virtual` below the road for ground points whose `h` is within 4
//!   degrees of vertical: three slightly slanted virtual columns.
//! - [`fig5`]: why they slant: for the lowest light, the rays light -> ground -> viewer at
//!   three ground points, the half vectors `h` there, and the virtual lights they imply.

use crate::model::{ColumnModel, ModelError, Reflection};
use crate::plot::{
    LegendAt, Mark, Marker, Plot, Series, BLACK_RGB, BLUE, GREEN, GREY, ORANGE, RED,
};
use glam::DVec3;

/// The viewer of both figures: height `Z_L/10`, depth 0.
const VIEWER: DVec3 = DVec3::new(0.0, 0.1, 0.0);

/// A point in the figures' (Z, Y) plane.
fn zy(p: DVec3) -> (f64, f64) {
    (p.z, p.y)
}

/// The road line from just behind the viewer to just past the lights.
fn road() -> Series {
    Series::line("road (Y = 0)", BLACK_RGB, vec![(-0.05, 0.0), (1.1, 0.0)])
}

fn viewer() -> Series {
    Series::scatter(
        "viewer (height Z_L/10)",
        BLACK_RGB,
        Marker::Triangle,
        vec![zy(VIEWER)],
    )
}

/// Fig. 4: three lights and their virtual light columns (tilt of `h` at most 4 degrees).
pub fn fig4() -> Result<Plot, ModelError> {
    let mut plot = Plot::new(
        "Fig. 4: virtual light columns (Eq. 4), ground points with h within 4° of vertical",
        "depth Z / Z_L",
        "height Y / Z_L",
    )
    .with(road())
    .with(viewer());
    plot.size = (1200, 800);
    plot.x_range = Some((-0.05, 1.1));
    plot.legend = LegendAt::LowerLeft;
    let mut mirrors = Vec::new();
    for (height, name, color) in [
        (0.05, "Z_L/20", RED),
        (0.10, "Z_L/10", BLUE),
        (0.15, "3 Z_L/20", GREEN),
    ] {
        let light = DVec3::new(0.0, height, 1.0);
        let model = ColumnModel::new(light, VIEWER)?;
        let locus = model.locus(Some(4.0), 200)?;
        plot = plot
            .with(Series::line(
                format!("light at height {name} and its virtual column"),
                color,
                locus.iter().map(|r| zy(r.virtual_light)).collect(),
            ))
            .with(Series::scatter("", color, Marker::Circle, vec![zy(light)]).unlabelled());
        mirrors.push((light.z, -light.y));
    }
    Ok(plot.with(Series::scatter(
        "mirror images (X_L, -Y_L, Z_L)",
        GREY,
        Marker::Cross,
        mirrors,
    )))
}

/// The three ground points of Fig. 5: the ends of the depth range where `h` is within 10
/// degrees of vertical (tilted enough to see), and the mirror point between them.
pub fn fig5_points() -> Result<[Reflection; 3], ModelError> {
    let model = ColumnModel::new(DVec3::new(0.0, 0.05, 1.0), VIEWER)?;
    let (near, far) = model.depth_range(Some(10.0))?;
    let zm = model.mirror_point().z;
    Ok([near, zm, far].map(|z| model.reflection_at(0.0, z)))
}

/// Fig. 5: the slant of the virtual column comes from the slant of `h`.
pub fn fig5() -> Result<Plot, ModelError> {
    let light = DVec3::new(0.0, 0.05, 1.0);
    let model = ColumnModel::new(light, VIEWER)?;
    let points = fig5_points()?;
    let column = model.locus(Some(10.0), 200)?;
    const H_LEN: f64 = 0.08;
    let mut plot = Plot::new(
        "Fig. 5: half vectors h that mirror the light to the viewer, and the virtual lights",
        "depth Z / Z_L",
        "height Y / Z_L",
    )
    .with(road())
    .with(viewer())
    .with(Series::scatter(
        "light (height Z_L/20)",
        RED,
        Marker::Circle,
        vec![zy(light)],
    ))
    .with(Series::line(
        "virtual column (h within 10° of vertical)",
        RED,
        column.iter().map(|r| zy(r.virtual_light)).collect(),
    ))
    .with(Series::segments(
        "rays light → X → viewer",
        ORANGE,
        points
            .iter()
            .flat_map(|r| [(zy(light), zy(r.ground)), (zy(r.ground), zy(VIEWER))]),
    ))
    .with(
        Series::segments(
            "sight line continued: X → L_virtual",
            GREY,
            points.iter().map(|r| (zy(r.ground), zy(r.virtual_light))),
        )
        .with_mark(Mark::Dashed { width: 2 }),
    )
    .with(
        Series::segments(
            "vertical at X",
            BLACK_RGB,
            points
                .iter()
                .map(|r| (zy(r.ground), zy(r.ground + H_LEN * DVec3::Y))),
        )
        .with_mark(Mark::Dashed { width: 1 }),
    )
    .with(Series::arrows(
        "half vector h at X",
        BLUE,
        points
            .iter()
            .map(|r| (zy(r.ground), zy(r.ground + H_LEN * r.h))),
    ))
    .with(Series::scatter(
        "L_virtual (Eq. 4)",
        RED,
        Marker::Cross,
        points.iter().map(|r| zy(r.virtual_light)).collect(),
    ));
    plot.size = (1400, 700);
    plot.equal_aspect = true;
    plot.legend = LegendAt::LowerLeft;
    Ok(plot)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fig5_points_slant_as_the_paper_says() {
        let [near, mirror, far] = fig5_points().unwrap();
        let image = DVec3::new(0.0, -0.05, 1.0);
        assert!(near.ground.z < mirror.ground.z && mirror.ground.z < far.ground.z);
        assert!((near.tilt_deg - 10.0).abs() < 1e-9 && (far.tilt_deg - 10.0).abs() < 1e-9);
        assert!((mirror.virtual_light - image).length() < 1e-12);
        // Near: h leans away from the viewer, L_virtual nearer and deeper below the road.
        assert!(near.h.z > 0.0);
        assert!(near.virtual_light.z < image.z && near.virtual_light.y < image.y);
        // Far: h leans towards the viewer, L_virtual farther and closer to the road.
        assert!(far.h.z < 0.0);
        assert!(far.virtual_light.z > image.z && far.virtual_light.y > image.y);
        assert!(far.virtual_light.y < 0.0);
    }

    #[test]
    fn figures_render_and_write() {
        let dir = tempfile::tempdir().unwrap();
        for (name, plot) in [("fig4", fig4().unwrap()), ("fig5", fig5().unwrap())] {
            let path = dir.path().join(format!("{name}.png"));
            plot.write_png(&path).unwrap();
            let img = image::open(&path).unwrap().to_rgb8();
            assert_eq!((img.width(), img.height()), plot.size);
            // Something red (a light or column) was drawn.
            assert!(img.pixels().any(|p| p.0 == RED), "{name}");
            assert!(!path.with_extension("png.tmp").exists());
        }
    }
}
