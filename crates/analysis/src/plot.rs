//! Plots for the analysis: lines, dashed lines, scatter points and arrows in data
//! coordinates, with a title, labelled axes and a legend, rendered with `plotters` and written
//! atomically to PNG (a temporary file beside the target, then a rename).
//!
//! Text uses DejaVu Sans, bundled in streaks-stereo (`crates/stereo/fonts/`, Bitstream Vera
//! licence alongside) and registered with plotters' `ab_glyph` backend, so no system font
//! libraries are needed.
//!
//! ```
//! use streaks_analysis::plot::{Plot, Series, BLUE};
//!
//! let plot = Plot::new("A line", "x (m)", "y (m)")
//!     .with(Series::line("y = x^2", BLUE, (0..=10).map(|i| (i as f64, (i * i) as f64)).collect()));
//! let image = plot.render()?;
//! assert_eq!((image.width(), image.height()), (1000, 700));
//! # Ok::<(), streaks_analysis::plot::PlotError>(())
//! ```

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
/// An axis range (low, high).
type Range = (f64, f64);

/// A pixel position in the backend.
type BackendCoord = (i32, i32);
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// What went wrong making a plot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// The plot has no points to set its axis ranges from.
    #[error("plot '{title}' has no data")]
    NoData {
        /// The plot's title.
        title: String,
    },
    /// A series has a NaN or infinite coordinate.
    #[error("series '{series}' of plot '{title}' has a non-finite point")]
    NonFinite {
        /// The plot's title.
        title: String,
        /// The series' label (empty if unlabelled).
        series: String,
    },
    /// An axis range that is empty, reversed or not finite, or an image size of zero.
    #[error("plot '{title}': {what}")]
    BadLayout {
        /// The plot's title.
        title: String,
        /// What is wrong.
        what: String,
    },
    /// The bundled font could not be registered with plotters.
    #[error("the bundled DejaVu Sans font could not be loaded")]
    Font,
    /// plotters failed while drawing.
    #[error("drawing plot '{title}': {reason}")]
    Draw {
        /// The plot's title.
        title: String,
        /// plotters' message.
        reason: String,
    },
    /// The PNG could not be written.
    #[error("writing plot {path}: {reason}")]
    Write {
        /// The target file.
        path: PathBuf,
        /// The I/O or encoder message.
        reason: String,
    },
}

/// An sRGB colour.
pub type Rgb = [u8; 3];
/// Red.
pub const RED: Rgb = [214, 39, 40];
/// Blue.
pub const BLUE: Rgb = [31, 119, 180];
/// Green.
pub const GREEN: Rgb = [44, 160, 44];
/// Orange.
pub const ORANGE: Rgb = [255, 127, 14];
/// Purple.
pub const PURPLE: Rgb = [148, 103, 189];
/// Grey.
pub const GREY: Rgb = [127, 127, 127];
/// Black.
pub const BLACK_RGB: Rgb = [0, 0, 0];

/// The shape of scatter points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// A filled circle.
    Circle,
    /// A diagonal cross.
    Cross,
    /// A filled triangle.
    Triangle,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// Solid polylines, `width` pixels wide.
    Line {
        /// Stroke width in pixels.
        width: u32,
    },
    /// Dashed polylines.
    Dashed {
        /// Stroke width in pixels.
        width: u32,
    },
    /// One marker per point.
    Points {
        /// The marker's shape.
        marker: Marker,
        /// Its size (radius) in pixels.
        size: u32,
    },
    /// Each path of two points is an arrow from the first to the second.
    Arrows {
        /// Stroke width in pixels.
        width: u32,
    },
}

/// A set of paths drawn the same way, with one legend entry (if labelled).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The legend text; `None` keeps the series out of the legend.
    pub label: Option<String>,
    /// The colour.
    pub color: Rgb,
    /// How it is drawn.
    pub mark: Mark,
    /// The paths in data coordinates (polylines, point sets, or arrows from-to).
    pub paths: Vec<Vec<(f64, f64)>>,
}

impl Series {
    /// One solid polyline.
    pub fn line(label: impl Into<String>, color: Rgb, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: Some(label.into()),
            color,
            mark: Mark::Line { width: 2 },
            paths: vec![points],
        }
    }

    /// One dashed polyline.
    pub fn dashed(label: impl Into<String>, color: Rgb, points: Vec<(f64, f64)>) -> Self {
        Self {
            mark: Mark::Dashed { width: 2 },
            ..Self::line(label, color, points)
        }
    }

    /// Separate straight segments, drawn solid.
    pub fn segments(
        label: impl Into<String>,
        color: Rgb,
        segments: impl IntoIterator<Item = ((f64, f64), (f64, f64))>,
    ) -> Self {
        Self {
            label: Some(label.into()),
            color,
            mark: Mark::Line { width: 2 },
            paths: segments.into_iter().map(|(a, b)| vec![a, b]).collect(),
        }
    }

    /// Scatter points.
    pub fn scatter(
        label: impl Into<String>,
        color: Rgb,
        marker: Marker,
        points: Vec<(f64, f64)>,
    ) -> Self {
        Self {
            label: Some(label.into()),
            color,
            mark: Mark::Points { marker, size: 6 },
            paths: vec![points],
        }
    }

    /// Arrows from the first point of each pair to the second.
    pub fn arrows(
        label: impl Into<String>,
        color: Rgb,
        arrows: impl IntoIterator<Item = ((f64, f64), (f64, f64))>,
    ) -> Self {
        Self {
            mark: Mark::Arrows { width: 2 },
            ..Self::segments(label, color, arrows)
        }
    }

    /// The same series drawn with another mark.
    pub fn with_mark(self, mark: Mark) -> Self {
        Self { mark, ..self }
    }

    /// The same series without a legend entry.
    pub fn unlabelled(self) -> Self {
        Self {
            label: None,
            ..self
        }
    }
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LegendAt {
    /// Top left corner of the plotting area.
    UpperLeft,
    /// Top right corner.
    UpperRight,
    /// Bottom left corner.
    LowerLeft,
    /// Bottom right corner.
    LowerRight,
    /// Middle of the right edge.
    MiddleRight,
}

/// A 2D plot: title, axis labels, ranges and series.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    /// The title above the plot.
    pub title: String,
    /// The x axis label (with units).
    pub x_label: String,
    /// The y axis label (with units).
    pub y_label: String,
    /// Image size in pixels (width, height).
    pub size: (u32, u32),
    /// The x range; `None` fits the data with a 5 % margin.
    pub x_range: Option<(f64, f64)>,
    /// The y range; `None` fits the data with a 5 % margin.
    pub y_range: Option<(f64, f64)>,
    /// Widen one range so that a unit is as long on both axes (angles look right).
    pub equal_aspect: bool,
    /// Where the legend goes.
    pub legend: LegendAt,
    /// The series, drawn in order.
    pub series: Vec<Series>,
}

/// Registers the bundled font (streaks-stereo's DejaVu Sans) as plotters' "sans-serif".
fn register_font() -> Result<(), PlotError> {
    streaks_stereo::font::register_sans_serif().map_err(|_| PlotError::Font)
}

const MARGIN: u32 = 20;
const X_LABEL_AREA: u32 = 60;
const Y_LABEL_AREA: u32 = 90;
const TITLE_SIZE: f64 = 30.0;

fn color(c: Rgb) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

impl Plot {
    /// An empty 1000 x 700 plot with fitted ranges and the legend at the upper right.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            size: (1000, 700),
            x_range: None,
            y_range: None,
            equal_aspect: false,
            legend: LegendAt::UpperRight,
            series: Vec::new(),
        }
    }

    /// Adds a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    fn layout_error(&self, what: impl Into<String>) -> PlotError {
        PlotError::BadLayout {
            title: self.title.clone(),
            what: what.into(),
        }
    }

    /// The axis ranges actually drawn, and checks of the data.
    fn ranges(&self, plot_px: (u32, u32)) -> Result<(Range, Range), PlotError> {
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for s in &self.series {
            for &(x, y) in s.paths.iter().flatten() {
                if !(x.is_finite() && y.is_finite()) {
                    return Err(PlotError::NonFinite {
                        title: self.title.clone(),
                        series: s.label.clone().unwrap_or_default(),
                    });
                }
                lo = (lo.0.min(x), lo.1.min(y));
                hi = (hi.0.max(x), hi.1.max(y));
            }
        }
        let fit = |lo: f64, hi: f64| {
            let pad = if hi > lo {
                0.05 * (hi - lo)
            } else {
                0.5 * lo.abs().max(1.0)
            };
            (lo - pad, hi + pad)
        };
        let no_data = || PlotError::NoData {
            title: self.title.clone(),
        };
        let x = match self.x_range {
            Some(r) => r,
            None if lo.0 <= hi.0 => fit(lo.0, hi.0),
            None => return Err(no_data()),
        };
        let y = match self.y_range {
            Some(r) => r,
            None if lo.1 <= hi.1 => fit(lo.1, hi.1),
            None => return Err(no_data()),
        };
        for (name, r) in [("x", x), ("y", y)] {
            if !(r.0.is_finite() && r.1.is_finite() && r.0 < r.1) {
                return Err(self.layout_error(format!("bad {name} range {r:?}")));
            }
        }
        if !self.equal_aspect {
            return Ok((x, y));
        }
        // Units per pixel on each axis; widen the axis with fewer units per pixel.
        let (ux, uy) = (
            (x.1 - x.0) / plot_px.0 as f64,
            (y.1 - y.0) / plot_px.1 as f64,
        );
        let widen = |r: (f64, f64), half: f64| {
            let c = 0.5 * (r.0 + r.1);
            (c - half, c + half)
        };
        Ok(if ux > uy {
            (x, widen(y, 0.5 * ux * plot_px.1 as f64))
        } else {
            (widen(x, 0.5 * uy * plot_px.0 as f64), y)
        })
    }

    /// Renders the plot into an RGB image.
    pub fn render(&self) -> Result<image::RgbImage, PlotError> {
        register_font()?;
        let (w, h) = self.size;
        if w < 2 * MARGIN + Y_LABEL_AREA + 50 || h < 2 * MARGIN + X_LABEL_AREA + 100 {
            return Err(self.layout_error(format!("image size {w} x {h} is too small")));
        }
        let mut buf = vec![255u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            self.draw(&root).map_err(|reason| PlotError::Draw {
                title: self.title.clone(),
                reason,
            })??;
            root.present().map_err(|e| PlotError::Draw {
                title: self.title.clone(),
                reason: e.to_string(),
            })?;
        }
        image::RgbImage::from_raw(w, h, buf).ok_or_else(|| self.layout_error("buffer size"))
    }

    /// Draws onto `root`; the outer error is plotters', the inner one ours.
    fn draw(
        &self,
        root: &DrawingArea<BitMapBackend<'_>, Shift>,
    ) -> Result<Result<(), PlotError>, String> {
        let e = |err: DrawingAreaErrorKind<_>| err.to_string();
        root.fill(&WHITE).map_err(e)?;
        let area = root
            .titled(&self.title, ("sans-serif", TITLE_SIZE).into_font())
            .map_err(e)?;
        let (aw, ah) = area.dim_in_pixel();
        let plot_px = (
            aw.saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1),
            ah.saturating_sub(2 * MARGIN + X_LABEL_AREA).max(1),
        );
        let (xr, yr) = match self.ranges(plot_px) {
            Ok(r) => r,
            Err(err) => return Ok(Err(err)),
        };
        let mut chart = ChartBuilder::on(&area)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .axis_desc_style(("sans-serif", 22))
            .label_style(("sans-serif", 18))
            .x_label_formatter(&|v| tick_label(*v, xr))
            .y_label_formatter(&|v| tick_label(*v, yr))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(210, 210, 210))
            .draw()
            .map_err(e)?;
        let mut labelled = false;
        for s in &self.series {
            let c = color(s.color);
            for (i, path) in s.paths.iter().enumerate() {
                let pts = path.iter().copied();
                let head = match (s.mark, path.as_slice()) {
                    (Mark::Arrows { width }, [from, to]) => arrow_head(
                        chart.backend_coord(from),
                        chart.backend_coord(to),
                        8.0 + 2.0 * width as f64,
                    ),
                    _ => None,
                };
                let anno = match s.mark {
                    Mark::Line { width } | Mark::Arrows { width } => {
                        chart.draw_series(LineSeries::new(pts, c.stroke_width(width)))
                    }
                    Mark::Dashed { width } => {
                        chart.draw_series(DashedLineSeries::new(pts, 10, 6, c.stroke_width(width)))
                    }
                    Mark::Points { marker, size } => {
                        match marker {
                            Marker::Circle => {
                                chart.draw_series(pts.map(|p| Circle::new(p, size, c.filled())))
                            }
                            Marker::Cross => chart
                                .draw_series(pts.map(|p| Cross::new(p, size, c.stroke_width(2)))),
                            Marker::Triangle => chart
                                .draw_series(pts.map(|p| TriangleMarker::new(p, size, c.filled()))),
                        }
                    }
                }
                .map_err(e)?;
                // One legend entry per series, attached to its first path.
                if let (0, Some(label)) = (i, &s.label) {
                    labelled = true;
                    let anno = anno.label(label.as_str());
                    match s.mark {
                        Mark::Line { width } | Mark::Arrows { width } => {
                            anno.legend(move |(x, y)| {
                                PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(width))
                            })
                        }
                        Mark::Dashed { width } => anno.legend(move |(x, y)| {
                            DashedPathElement::new(
                                vec![(x, y), (x + 24, y)],
                                6,
                                4,
                                c.stroke_width(width),
                            )
                        }),
                        Mark::Points { marker, size } => match marker {
                            Marker::Circle => anno
                                .legend(move |(x, y)| Circle::new((x + 12, y), size, c.filled())),
                            Marker::Cross => anno.legend(move |(x, y)| {
                                Cross::new((x + 12, y), size, c.stroke_width(2))
                            }),
                            Marker::Triangle => anno.legend(move |(x, y)| {
                                TriangleMarker::new((x + 12, y), size, c.filled())
                            }),
                        },
                    };
                }
                if let Some(head) = head {
                    root.draw(&Polygon::new(head, c.filled())).map_err(e)?;
                }
            }
        }
        if labelled {
            let pos = match self.legend {
                LegendAt::UpperLeft => SeriesLabelPosition::UpperLeft,
                LegendAt::UpperRight => SeriesLabelPosition::UpperRight,
                LegendAt::LowerLeft => SeriesLabelPosition::LowerLeft,
                LegendAt::LowerRight => SeriesLabelPosition::LowerRight,
                LegendAt::MiddleRight => SeriesLabelPosition::MiddleRight,
            };
            chart
                .configure_series_labels()
                .position(pos)
                .label_font(("sans-serif", 18))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(e)?;
        }
        Ok(Ok(()))
    }

    /// Renders the plot and writes it as PNG to `path`, atomically.
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        let img = self.render()?;
        streaks_image::png::write_png_buffer(path, &img).map_err(|e| PlotError::Write {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    }
}

/// A tick label: enough decimals for about ten ticks over `range`, and no "-0".
fn tick_label(v: f64, range: (f64, f64)) -> String {
    let step = (range.1 - range.0) / 10.0;
    let decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
    let text = format!("{v:.decimals$}");
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        text.trim_start_matches('-').to_string()
    } else {
        text
    }
}

/// The triangle of an arrow head at `to`, `len` pixels long, or `None` for a zero-length arrow.
fn arrow_head(from: BackendCoord, to: BackendCoord, len: f64) -> Option<Vec<BackendCoord>> {
    let (dx, dy) = ((to.0 - from.0) as f64, (to.1 - from.1) as f64);
    let n = dx.hypot(dy);
    if n < 1.0 {
        return None;
    }
    let (ux, uy) = (dx / n, dy / n);
    let (bx, by) = (to.0 as f64 - len * ux, to.1 as f64 - len * uy);
    let half = 0.45 * len;
    Some(vec![
        to,
        (
            (bx - half * uy).round() as i32,
            (by + half * ux).round() as i32,
        ),
        (
            (bx + half * uy).round() as i32,
            (by - half * ux).round() as i32,
        ),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Plot {
        Plot::new("test", "x (m)", "y (m)")
            .with(Series::line("line", RED, vec![(0.0, 0.0), (1.0, 2.0)]))
            .with(Series::scatter(
                "points",
                BLUE,
                Marker::Cross,
                vec![(0.5, 1.0)],
            ))
            .with(Series::arrows("arrow", GREEN, [((0.0, 2.0), (1.0, 0.0))]))
            .with(
                Series::segments("dashes", GREY, [((0.0, 1.0), (1.0, 1.0))])
                    .with_mark(Mark::Dashed { width: 1 }),
            )
    }

    #[test]
    fn renders_all_marks_and_writes_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.png");
        sample().write_png(&path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (1000, 700));
        for c in [RED, BLUE, GREEN, GREY] {
            assert!(img.pixels().any(|p| p.0 == c), "colour {c:?} drawn");
        }
        assert!(!path.with_extension("png.tmp").exists());
        // A folder that does not exist: an error naming the file, no stray temporary file.
        let bad = dir.path().join("missing").join("p.png");
        let err = sample().write_png(&bad).unwrap_err();
        assert!(err.to_string().contains("p.png"), "{err}");
    }

    #[test]
    fn bad_data_and_layout_are_errors() {
        let nan = Plot::new("t", "x", "y").with(Series::line("bad", RED, vec![(f64::NAN, 0.0)]));
        assert!(matches!(nan.render(), Err(PlotError::NonFinite { .. })));
        assert!(matches!(
            Plot::new("t", "x", "y").render(),
            Err(PlotError::NoData { .. })
        ));
        let mut reversed = sample();
        reversed.x_range = Some((1.0, 0.0));
        assert!(matches!(
            reversed.render(),
            Err(PlotError::BadLayout { .. })
        ));
        let mut tiny = sample();
        tiny.size = (10, 10);
        assert!(matches!(tiny.render(), Err(PlotError::BadLayout { .. })));
    }

    #[test]
    fn equal_aspect_widens_the_short_axis() {
        let mut p = sample();
        p.equal_aspect = true;
        let px = (800, 500);
        let (x, y) = p.ranges(px).unwrap();
        let ux = (x.1 - x.0) / px.0 as f64;
        let uy = (y.1 - y.0) / px.1 as f64;
        assert!((ux - uy).abs() < 1e-12 * ux);
        assert!(x.1 - x.0 > 1.1, "x widened to match y");
    }

    #[test]
    fn tick_labels() {
        assert_eq!(tick_label(-1e-17, (-0.3, 0.2)), "0.00");
        assert_eq!(tick_label(0.05, (-0.3, 0.2)), "0.05");
        assert_eq!(tick_label(-2.0, (-10.0, 10.0)), "-2");
    }
}
