//! The environment light: radiance arriving from infinitely far away in every direction a ray
//! escapes the scene by, either a constant colour or an equirectangular linear-RGB map, times a
//! strength.
//!
//! # Direction mapping (exactly Mitsuba 3's `envmap` with an identity `to_world`)
//!
//! For a unit direction `d = (x, y, z)` travelling away from the scene (an escaping ray's own
//! direction):
//!
//! - `u = atan2(x, -z) / (2 pi)`, wrapped into `[0, 1)`; `v = acos(y) / pi`. Conversely
//!   `phi = 2 pi u`, `theta = pi v` and `d = (sin phi sin theta, cos theta, -cos phi sin theta)`.
//! - So +Y (the glTF world's up) is row 0, the top of the file, and -Y the last row; `u = 0`
//!   (the left edge) is -Z, `u = 1/4` is +X, `u = 1/2` (the centre column) is +Z and `u = 3/4`
//!   is -X. A glTF camera at rest (looking along -Z) faces the map's left/right seam, with +X
//!   to its right: the map is not mirrored when seen from inside.
//! - Columns are texel-centred and wrap: column `x` of a `W`-wide map sits at
//!   `u = (x + 1/2) / W`, and the continuous column is `u W - 1/2` modulo `W`. Rows are
//!   aligned to the corners: row `y` of an `H`-high map sits at `v = y / (H - 1)` (row 0 is
//!   exactly the zenith, row `H - 1` the nadir), the continuous row `v (H - 1)`, clamped.
//! - The radiance is the bilinear interpolation of the four texels around that point, times
//!   the strength (Mitsuba's `scale`). Texels are the EXR's linear RGB, unchanged.
//!
//! A map of one column or one row is used as if that column (row) were repeated: it has no
//! variation along that axis either way.
//!
//! # Sampling
//!
//! Next-event estimation samples a map in proportion to its luminance (Rec. 709 weights, as
//! Mitsuba's) over the `W x (H - 1)` cells whose corners are the texel centres (a cell's `u`
//! range is shifted by half a texel, as Mitsuba shifts its warp): a cell's weight is the mean
//! luminance of its four corner texels times its solid angle `(2 pi / W) (cos theta_0 - cos
//! theta_1)`. A row of cells is chosen from the marginal, a cell from that row's conditional,
//! and a direction uniformly in the cell's solid angle (uniform in `phi` and in `cos theta`),
//! so the density is `P(cell) / Omega(cell)`, bounded even at the poles. Mitsuba samples the
//! bilinear interpolant of the luminance times `sin theta` in `(u, v)` instead; only the
//! variance differs, the expected image is the same: every cell where the radiance is not
//! zero has a positive weight (a positive luminance at one of its corners), so the estimator
//! is unbiased. A constant environment is sampled uniformly over the sphere (`1 / (4 pi)`),
//! as Mitsuba's `constant` is.
//!
//! Building the map's distributions allocates; looking up, sampling and the density do not.

use crate::sampling::{
    square_to_uniform_sphere, square_to_uniform_sphere_pdf, DiscreteDistribution,
};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI, TAU};
use std::path::{Path, PathBuf};
use streaks_image::{luminance, ImageError, RgbImage};
use thiserror::Error;

/// The largest strength (or colour component) an environment accepts: far above any sky, small
/// enough that its radiance times a BSDF stays finite in `f32`.
pub const MAX_STRENGTH: f32 = 1.0e6;

/// The first four bytes of every OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Why an environment could not be made.
#[derive(Debug, Error)]
pub enum EnvironmentError {
    /// The map's file could not be read or decoded.
    #[error("environment map {path}")]
    Image {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: ImageError,
    },
    /// The map's file is not an OpenEXR file.
    #[error(
        "environment map {path}: not an OpenEXR file (an equirectangular linear-RGB .exr is \
         expected)"
    )]
    NotExr {
        /// The file.
        path: PathBuf,
    },
    /// A texel of the map is negative, NaN or infinite.
    #[error("environment map {path}: pixel ({x}, {y}) is {value:?}: radiance must be finite and not negative")]
    BadTexel {
        /// The file.
        path: PathBuf,
        /// Its column.
        x: u32,
        /// Its row (0 at the top).
        y: u32,
        /// Its RGB value.
        value: [f32; 3],
    },
    /// A strength or a colour is out of range.
    #[error("environment {what} {value}: must be finite and in [0, {MAX_STRENGTH:e}]")]
    OutOfRange {
        /// What it is (`strength`, `color`).
        what: &'static str,
        /// The value as given.
        value: String,
    },
}

/// Checks a strength or a colour component.
fn check_range(what: &'static str, values: &[f32]) -> Result<(), EnvironmentError> {
    if values
        .iter()
        .all(|v| v.is_finite() && (0.0..=MAX_STRENGTH).contains(v))
    {
        Ok(())
    } else {
        Err(EnvironmentError::OutOfRange {
            what,
            value: match values {
                [v] => format!("{v}"),
                _ => format!("{values:?}"),
            },
        })
    }
}

/// The light arriving from directions that escape the scene (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// The same radiance from every direction (Mitsuba's `constant`).
    Constant {
        /// Linear RGB radiance (the colour times the strength).
        radiance: Vec3,
    },
    /// An equirectangular map (Mitsuba's `envmap`).
    Map(Box<EnvironmentMap>),
}

/// An equirectangular linear-RGB environment map with its sampling distributions.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    /// The file it was read from (the Mitsuba exporter names it).
    path: PathBuf,
    /// The strength its texels are multiplied by.
    strength: f32,
    width: u32,
    height: u32,
    /// Row-major texels, row 0 at the top (+Y).
    texels: Vec<Vec3>,
    /// The marginal distribution of the `height - 1` rows of cells; `None` when the map is
    /// black.
    rows: Option<DiscreteDistribution>,
    /// Each row's conditional distribution of its `width` cells (empty when black).
    columns: Vec<DiscreteDistribution>,
    /// `cos(theta)` of each row of texels, `cos(pi y / (height - 1))`.
    cos_rows: Vec<f32>,
    /// The solid angle of a cell of each row of cells, `(2 pi / width) (cos theta_y - cos
    /// theta_(y+1))`.
    cell_solid_angles: Vec<f32>,
    /// The mean luminance of the radiance over the sphere, strength included.
    mean_luminance: f32,
}

/// The `(u, v)` of a direction (module documentation), `u` in `[0, 1)`, `v` in `[0, 1]`.
#[inline]
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = d.x.atan2(-d.z) * (0.5 * FRAC_1_PI);
    let u = u - u.floor();
    // `u - floor(u)` of a tiny negative value rounds to 1.
    let u = if u >= 1.0 { 0.0 } else { u };
    Vec2::new(u, d.y.clamp(-1.0, 1.0).acos() * FRAC_1_PI)
}

/// The direction of `(u, v)`: `(sin phi sin theta, cos theta, -cos phi sin theta)`.
#[inline]
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (sin_t, cos_t) = (PI * uv.y).sin_cos();
    let (sin_p, cos_p) = (TAU * uv.x).sin_cos();
    Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t)
}

impl Environment {
    /// A constant environment of colour `color` times `strength`.
    pub fn constant(color: Vec3, strength: f32) -> Result<Self, EnvironmentError> {
        check_range("color", &color.to_array())?;
        check_range("strength", &[strength])?;
        Ok(Self::Constant {
            radiance: color * strength,
        })
    }

    /// The map in the EXR file `path`, times `strength`: the file must be an OpenEXR file
    /// (checked by its first bytes) with `R`, `G`, `B` channels, finite and not negative.
    pub fn load_map(path: &Path, strength: f32) -> Result<Self, EnvironmentError> {
        check_range("strength", &[strength])?;
        let image_err = |source| EnvironmentError::Image {
            path: path.to_path_buf(),
            source,
        };
        let magic = streaks_image::input::read_file_prefix(path, 4).map_err(|e| {
            image_err(ImageError::Read {
                path: path.to_path_buf(),
                reason: e.to_string(),
            })
        })?;
        if magic != EXR_MAGIC {
            return Err(EnvironmentError::NotExr {
                path: path.to_path_buf(),
            });
        }
        let image = streaks_image::exr::read_exr_rgb(path).map_err(image_err)?;
        Ok(Self::Map(Box::new(EnvironmentMap::new(
            path, &image, strength,
        )?)))
    }

    /// The radiance arriving along `-d`, from direction `d` (unit) away from the scene.
    #[inline]
    pub fn le(&self, d: Vec3) -> Vec3 {
        match self {
            Self::Constant { radiance } => *radiance,
            Self::Map(m) => m.le(d),
        }
    }

    /// A direction sampled with `u`: `(d, radiance from d, solid-angle density)`; `None` when
    /// nothing can be sampled (a black map, a direction at a pole).
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        match self {
            Self::Constant { radiance } => {
                let d = square_to_uniform_sphere(u);
                Some((d, *radiance, square_to_uniform_sphere_pdf(d)))
            }
            Self::Map(m) => m.sample(u),
        }
    }

    /// The solid-angle density with which [`Environment::sample`] returns `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self {
            Self::Constant { .. } => square_to_uniform_sphere_pdf(d),
            Self::Map(m) => m.pdf(d),
        }
    }

    /// The mean over the sphere of the radiance's luminance: `pi` times it is the irradiance
    /// on a surface open to the whole sky (the light choice's estimate).
    pub fn mean_luminance(&self) -> f32 {
        match self {
            Self::Constant { radiance } => luminance(*radiance),
            Self::Map(m) => m.mean_luminance,
        }
    }

    /// The map, if it is one.
    pub fn map(&self) -> Option<&EnvironmentMap> {
        match self {
            Self::Map(m) => Some(m),
            Self::Constant { .. } => None,
        }
    }
}

impl EnvironmentMap {
    /// A map of the texels of `image` times `strength`, read from `path` (named in errors and
    /// by the Mitsuba exporter); every texel must be finite and not negative.
    pub fn new(path: &Path, image: &RgbImage, strength: f32) -> Result<Self, EnvironmentError> {
        check_range("strength", &[strength])?;
        let (w0, h0) = (image.width, image.height);
        for (i, c) in image.pixels.iter().enumerate() {
            if !(c.is_finite() && c.min_element() >= 0.0) {
                return Err(EnvironmentError::BadTexel {
                    path: path.to_path_buf(),
                    x: i as u32 % w0.max(1),
                    y: i as u32 / w0.max(1),
                    value: c.to_array(),
                });
            }
        }
        if w0 == 0 || h0 == 0 {
            return Err(EnvironmentError::Image {
                path: path.to_path_buf(),
                source: ImageError::Read {
                    path: path.to_path_buf(),
                    reason: "the map has no pixels".into(),
                },
            });
        }
        // One row or one column is repeated: the lookup needs two of each.
        let (width, height) = (w0.max(2), h0.max(2));
        let texels: Vec<Vec3> = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| image.get(x.min(w0 - 1), y.min(h0 - 1)))
            .collect();
        let (w, h) = (width as usize, height as usize);
        let lum = |x: usize, y: usize| f64::from(luminance(texels[y * w + x % w]));
        let cos_rows: Vec<f64> = (0..h)
            .map(|r| (std::f64::consts::PI * r as f64 / (h - 1) as f64).cos())
            .collect();
        let cell_solid_angles: Vec<f64> = (0..h - 1)
            .map(|j| std::f64::consts::TAU / w as f64 * (cos_rows[j] - cos_rows[j + 1]))
            .collect();
        let mut row_weights = Vec::with_capacity(h - 1);
        let mut columns = Vec::with_capacity(h - 1);
        let mut cell_weights = vec![0.0f32; w];
        let mut total = 0.0f64;
        for (j, &omega) in cell_solid_angles.iter().enumerate() {
            let mut row = 0.0f64;
            for (i, cw) in cell_weights.iter_mut().enumerate() {
                let mean = 0.25 * (lum(i, j) + lum(i + 1, j) + lum(i, j + 1) + lum(i + 1, j + 1));
                let weight = mean * omega;
                *cw = weight as f32;
                row += weight;
            }
            total += row;
            row_weights.push(row as f32);
            // A black row's conditional is never chosen; any valid one keeps the indices.
            columns.push(
                DiscreteDistribution::new(&cell_weights)
                    .or_else(|| DiscreteDistribution::new(&[1.0]))
                    .expect("a single positive weight is a distribution"),
            );
        }
        let rows = DiscreteDistribution::new(&row_weights);
        // The weights sum the mean luminance over each cell's solid angle: over 4 pi, the mean
        // over the sphere.
        let mean_luminance = (total / (4.0 * std::f64::consts::PI) * f64::from(strength)) as f32;
        Ok(Self {
            path: path.to_path_buf(),
            strength,
            width,
            height,
            texels,
            columns: if rows.is_some() { columns } else { Vec::new() },
            rows,
            cos_rows: cos_rows.iter().map(|&c| c as f32).collect(),
            cell_solid_angles: cell_solid_angles.iter().map(|&o| o as f32).collect(),
            mean_luminance,
        })
    }

    /// The file the map was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The strength its texels are multiplied by (Mitsuba's `scale`).
    pub fn strength(&self) -> f32 {
        self.strength
    }

    /// `(width, height)` of the map as used (a single row or column counts twice).
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The texels as an image (without the strength), as the lookup uses them.
    pub fn texels(&self) -> RgbImage {
        RgbImage {
            width: self.width,
            height: self.height,
            pixels: self.texels.clone(),
        }
    }

    #[inline]
    fn texel(&self, x: usize, y: usize) -> Vec3 {
        self.texels[y * self.width as usize + x]
    }

    /// The radiance from direction `d` (module documentation).
    #[inline]
    pub fn le(&self, d: Vec3) -> Vec3 {
        let uv = direction_to_uv(d);
        let (w, h) = (self.width as usize, self.height as usize);
        // Texel-centred, wrapping columns.
        let cx = uv.x * w as f32 - 0.5;
        let fx0 = cx.floor();
        let tx = cx - fx0;
        let x0 = (fx0 as isize).rem_euclid(w as isize) as usize;
        let x1 = (x0 + 1) % w;
        // Align-corners, clamped rows.
        let cy = (uv.y * (h - 1) as f32).clamp(0.0, (h - 1) as f32);
        let y0 = (cy.floor() as usize).min(h - 2);
        let ty = cy - y0 as f32;
        let top = self.texel(x0, y0) * (1.0 - tx) + self.texel(x1, y0) * tx;
        let bottom = self.texel(x0, y0 + 1) * (1.0 - tx) + self.texel(x1, y0 + 1) * tx;
        (top * (1.0 - ty) + bottom * ty) * self.strength
    }

    /// See [`Environment::sample`].
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let rows = self.rows.as_ref()?;
        let (j, _, uy) = rows.sample_reuse(u.y);
        let (i, _, ux) = self.columns[j].sample_reuse(u.x);
        let w = self.width as f32;
        // Cell i spans the texel centres i and i + 1: u shifted by half a texel.
        let mut su = (i as f32 + ux + 0.5) / w;
        if su >= 1.0 {
            su -= 1.0;
        }
        // Uniform in cos(theta) across the row of cells.
        let cos_t = self.cos_rows[j] - uy * (self.cos_rows[j] - self.cos_rows[j + 1]);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let (sin_p, cos_p) = (TAU * su).sin_cos();
        let d = Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t);
        // The density of the direction as `pdf` computes it, so MIS sees one value.
        let pdf = self.pdf(d);
        (pdf > 0.0).then(|| (d, self.le(d), pdf))
    }

    /// See [`Environment::pdf`].
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        let Some(rows) = self.rows.as_ref() else {
            return 0.0;
        };
        let uv = direction_to_uv(d);
        let (w, h1) = (self.width as usize, self.height as usize - 1);
        let su = uv.x * w as f32 - 0.5;
        let i = (su.floor() as isize).rem_euclid(w as isize) as usize;
        let j = ((uv.y * h1 as f32) as usize).min(h1 - 1);
        rows.pmf(j) * self.columns[j].pmf(i) / self.cell_solid_angles[j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{chi_square_2d, chi_square_sphere, ChiSquareConfig};

    /// A map from a function of the texel.
    fn map_of(w: u32, h: u32, f: impl FnMut(u32, u32) -> Vec3) -> EnvironmentMap {
        EnvironmentMap::new(Path::new("test.exr"), &RgbImage::from_fn(w, h, f), 1.0).unwrap()
    }

    /// A sun-like blob and a gradient, with a black band.
    fn structured(w: u32, h: u32) -> EnvironmentMap {
        map_of(w, h, |x, y| {
            let (dx, dy) = (x as f32 - 0.3 * w as f32, y as f32 - 0.25 * h as f32);
            let sun = 50.0 * (-(dx * dx + dy * dy) / 4.0).exp();
            let sky = if y == h / 2 {
                0.0
            } else {
                0.2 + 0.8 * y as f32 / h as f32
            };
            Vec3::new(sun + sky, sun + 0.5 * sky, sun + 0.2 + 0.1 * (x % 3) as f32)
        })
    }

    #[test]
    fn uv_mapping_is_mitsubas() {
        let close = |a: Vec2, b: Vec2| (a - b).abs().max_element() < 1e-6;
        assert!(close(direction_to_uv(Vec3::NEG_Z), Vec2::new(0.0, 0.5)));
        assert!(close(direction_to_uv(Vec3::X), Vec2::new(0.25, 0.5)));
        assert!(close(direction_to_uv(Vec3::Z), Vec2::new(0.5, 0.5)));
        assert!(close(direction_to_uv(Vec3::NEG_X), Vec2::new(0.75, 0.5)));
        // At the poles u is atan2(0, -0) = 1/2, as Mitsuba's; v is exact.
        assert!(direction_to_uv(Vec3::Y).y == 0.0);
        assert!(direction_to_uv(-Vec3::Y).y == 1.0);
        for k in 0..50 {
            let uv = Vec2::new(
                (k as f32 + 0.3) / 50.0,
                (k as f32 * 7.0 % 49.0 + 0.5) / 50.0,
            );
            let back = direction_to_uv(uv_to_direction(uv));
            assert!((back - uv).abs().max_element() < 1e-4, "{uv} {back}");
        }
    }

    /// Hand values at the four cardinal directions and the poles on a 4 x 3 map whose texels
    /// are all different: column x sits at u = (x + 1/2) / 4, row y at v = y / 2.
    #[test]
    fn lookup_follows_the_texel_conventions() {
        let texel = |x: u32, y: u32| Vec3::new(x as f32, y as f32, 1.0 + (x * 3 + y) as f32);
        let m = map_of(4, 3, texel);
        let mean = |a: Vec3, b: Vec3| 0.5 * (a + b);
        let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-5;
        // u = 0 (-Z) lies halfway between the last column and the first, on row 1.
        assert!(close(m.le(Vec3::NEG_Z), mean(texel(3, 1), texel(0, 1))));
        // u = 1/4 (+X) between columns 0 and 1; 1/2 (+Z) between 1 and 2; 3/4 (-X) 2 and 3.
        assert!(close(m.le(Vec3::X), mean(texel(0, 1), texel(1, 1))));
        assert!(close(m.le(Vec3::Z), mean(texel(1, 1), texel(2, 1))));
        assert!(close(m.le(Vec3::NEG_X), mean(texel(2, 1), texel(3, 1))));
        // Row 0 is +Y exactly, the last row -Y.
        let up = m.le(Vec3::Y);
        assert!(close(up, mean(texel(3, 0), texel(0, 0))), "{up}");
        assert!(close(m.le(-Vec3::Y), mean(texel(3, 2), texel(0, 2))));
        // A texel centre gives the texel: column 1 at u = 3/8, row 1 at the horizon.
        let d = uv_to_direction(Vec2::new(3.0 / 8.0, 0.5));
        assert!(close(m.le(d), texel(1, 1)));
        // Strength scales.
        let img = RgbImage::from_fn(4, 3, texel);
        let m2 = EnvironmentMap::new(Path::new("t.exr"), &img, 2.5).unwrap();
        assert!(close(m2.le(d), 2.5 * texel(1, 1)));
    }

    #[test]
    fn map_sampling_matches_its_density() {
        for (w, h) in [(16, 8), (7, 5), (1, 1), (64, 32)] {
            let env = Environment::Map(Box::new(structured(w, h)));
            let config = ChiSquareConfig {
                cells: (64, 128),
                samples: 400_000,
                num_tests: 4,
                max_depth: 12,
                ..ChiSquareConfig::default()
            };
            let r = chi_square_sphere(
                "environment map",
                &config,
                |rng| env.sample(rng.next_2d()).map(|(d, _, _)| d),
                |d| env.pdf(d),
            );
            assert!(r.passed, "{w}x{h}: {r}");
            assert!((r.pdf_integral - 1.0).abs() < 2e-3, "{w}x{h}: {r}");
            // Every sample carries the radiance and density of its direction.
            let mut rng = crate::sampling::Pcg32::new(5, 6);
            for _ in 0..1000 {
                if let Some((d, li, pdf)) = env.sample(rng.next_2d()) {
                    assert!((d.length() - 1.0).abs() < 1e-5);
                    assert_eq!(li, env.le(d));
                    assert_eq!(pdf, env.pdf(d));
                    assert!(pdf > 0.0 && pdf.is_finite());
                }
            }
        }
    }

    /// The same in `(u, v)`, where the cells of the map are visible: binning on a grid
    /// aligned with them catches a half-texel slip.
    #[test]
    fn map_sampling_matches_its_density_in_uv() {
        let m = structured(8, 5);
        let config = ChiSquareConfig {
            cells: (32, 16),
            samples: 200_000,
            ..ChiSquareConfig::default()
        };
        let r = chi_square_2d(
            "environment map in uv",
            &config,
            (0.0, 1.0),
            (0.0, 1.0),
            |rng| {
                m.sample(rng.next_2d()).map(|(d, _, _)| {
                    let uv = direction_to_uv(d);
                    (f64::from(uv.x), f64::from(uv.y))
                })
            },
            |u, v| {
                let d = uv_to_direction(Vec2::new(u as f32, v as f32));
                let sin_theta = (std::f64::consts::PI * v).sin();
                f64::from(m.pdf(d)) * 2.0 * std::f64::consts::PI.powi(2) * sin_theta
            },
        );
        assert!(r.passed, "{r}");
    }

    #[test]
    fn constant_sampling_is_uniform() {
        let env = Environment::constant(Vec3::new(1.0, 0.5, 0.25), 2.0).unwrap();
        let r = chi_square_sphere(
            "constant environment",
            &ChiSquareConfig::default(),
            |rng| env.sample(rng.next_2d()).map(|(d, _, _)| d),
            |d| env.pdf(d),
        );
        assert!(r.passed, "{r}");
        assert_eq!(env.le(Vec3::X), Vec3::new(2.0, 1.0, 0.5));
        assert!((env.mean_luminance() - luminance(Vec3::new(2.0, 1.0, 0.5))).abs() < 1e-6);
    }

    /// A map that is one bright band of rows: the irradiance on an upward surface is the
    /// band's radiance times the projected solid angle of the band, which the estimator
    /// `L cos / p` over the sampled directions must reproduce; and the mean luminance is the
    /// band's luminance times its share of the sphere.
    #[test]
    fn a_bright_band_gives_its_analytic_irradiance() {
        // 9 rows: rows at theta = k pi / 8. Row 2 (theta = pi/4) bright; with align-corners
        // rows and bilinear interpolation, the radiance is a tent in theta from pi/8 to 3pi/8.
        let (w, h) = (16u32, 9u32);
        let l = 3.0f32;
        let m = map_of(
            w,
            h,
            |_, y| if y == 2 { Vec3::splat(l) } else { Vec3::ZERO },
        );
        let env = Environment::Map(Box::new(m));
        // Exact: E = 2 pi int L(theta) cos sin dtheta, L a tent of height l on [pi/8, 3pi/8].
        let step = std::f64::consts::PI / 8.0;
        let tent = |t: f64| (1.0 - ((t - 2.0 * step) / step).abs()).max(0.0) * f64::from(l);
        let n = 20_000;
        let (mut exact_e, mut exact_mean) = (0.0f64, 0.0f64);
        for k in 0..n {
            let t = step + 2.0 * step * (k as f64 + 0.5) / n as f64;
            let dt = 2.0 * step / n as f64;
            exact_e += std::f64::consts::TAU * tent(t) * t.cos() * t.sin() * dt;
            exact_mean += std::f64::consts::TAU * tent(t) * t.sin() * dt;
        }
        exact_mean /= 4.0 * std::f64::consts::PI;
        let mut rng = crate::sampling::Pcg32::new(1, 2);
        let samples = 200_000;
        let mut est = 0.0f64;
        for _ in 0..samples {
            if let Some((d, li, pdf)) = env.sample(rng.next_2d()) {
                est += f64::from(li.x * d.y.max(0.0) / pdf);
            }
        }
        est /= samples as f64;
        assert!((est - exact_e).abs() < 1e-2 * exact_e, "{est} vs {exact_e}");
        // The mean luminance counts each cell at the mean of its corners times its solid
        // angle: an estimate (for the light choice), here 1.3 % low.
        let mean = f64::from(env.mean_luminance());
        assert!(
            (mean - exact_mean).abs() < 0.02 * exact_mean,
            "{mean} vs {exact_mean}"
        );
    }

    #[test]
    fn bad_values_are_errors_naming_the_file_and_the_pixel() {
        let img = RgbImage::from_fn(3, 2, |x, y| {
            if (x, y) == (2, 1) {
                Vec3::new(0.0, -1.0, 0.0)
            } else {
                Vec3::ONE
            }
        });
        let err = EnvironmentMap::new(Path::new("sky.exr"), &img, 1.0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("sky.exr") && err.contains("(2, 1)"), "{err}");
        let nan = RgbImage::from_fn(2, 2, |_, _| Vec3::NAN);
        assert!(EnvironmentMap::new(Path::new("sky.exr"), &nan, 1.0).is_err());
        for s in [-1.0, f32::NAN, f32::INFINITY, 2.0 * MAX_STRENGTH] {
            assert!(Environment::constant(Vec3::ONE, s).is_err(), "{s}");
            assert!(EnvironmentMap::new(Path::new("sky.exr"), &img, s).is_err());
        }
        assert!(Environment::constant(Vec3::new(1.0, -0.1, 0.0), 1.0).is_err());
    }

    #[test]
    fn files_that_are_not_exr_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("sky.png");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\nnot really").unwrap();
        let err = Environment::load_map(&png, 1.0).unwrap_err().to_string();
        assert!(
            err.contains("sky.png") && err.contains("not an OpenEXR"),
            "{err}"
        );
        let missing = dir.path().join("none.exr");
        let err = Environment::load_map(&missing, 1.0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("none.exr"), "{err}");
        // A real EXR round-trips.
        let exr = dir.path().join("sky.exr");
        let img = RgbImage::from_fn(4, 3, |x, y| Vec3::new(x as f32, y as f32, 0.5));
        streaks_image::exr::write_exr_rgb(&exr, &img).unwrap();
        let env = Environment::load_map(&exr, 2.0).unwrap();
        let d = uv_to_direction(Vec2::new(3.0 / 8.0, 0.5));
        assert!(
            (env.le(d) - 2.0 * Vec3::new(1.0, 1.0, 0.5))
                .abs()
                .max_element()
                < 1e-5
        );
        assert_eq!(env.map().unwrap().path(), exr.as_path());
    }

    #[test]
    fn a_black_map_samples_nothing() {
        let env = Environment::Map(Box::new(map_of(4, 4, |_, _| Vec3::ZERO)));
        assert!(env.sample(Vec2::splat(0.5)).is_none());
        assert_eq!(env.pdf(Vec3::X), 0.0);
        assert_eq!(env.mean_luminance(), 0.0);
    }
}
