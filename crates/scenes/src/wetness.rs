//! The road's dryness map: deterministic value noise (fixed seed) shaped into puddles (w = 0),
//! ordinary wet asphalt (w ~ 0.2) and drier patches (w -> 1), with wetter gutters along the
//! kerbs and drier wheel tracks, as on a real street after rain; where the wheel tracks are
//! worn into ruts, they hold water instead. Stored in the green channel
//! of an RGB PNG (the material's metallicRoughnessTexture; see scenes/README.md).

use crate::Error;
use image::{ImageEncoder, RgbImage};

/// Dryness w of ordinary wet asphalt (between puddles and dry patches).
pub const WET_ROAD_W: f32 = 0.2;

/// A 32-bit integer hash (Chris Wellons' "lowbias32").
pub fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Lattice value in [0, 1) at integer point (i, j) for `seed`.
fn lattice(i: i32, j: i32, seed: u32) -> f32 {
    let h = hash(seed ^ hash((i as u32) ^ hash(j as u32)));
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth value noise in [0, 1) with a quintic fade between lattice points.
pub fn value_noise(x: f32, y: f32, seed: u32) -> f32 {
    noise(x, y, seed, |i| i, |j| j)
}

/// [`value_noise`] that repeats with periods `(px, py)` (lattice cells) in x and y, for
/// tiling textures.
pub fn tiling_noise(x: f32, y: f32, (px, py): (i32, i32), seed: u32) -> f32 {
    noise(
        x,
        y,
        seed,
        |i| i.rem_euclid(px.max(1)),
        |j| j.rem_euclid(py.max(1)),
    )
}

fn noise(
    x: f32,
    y: f32,
    seed: u32,
    wrap_x: impl Fn(i32) -> i32,
    wrap_y: impl Fn(i32) -> i32,
) -> f32 {
    let (xi, yi) = (x.floor(), y.floor());
    let (fx, fy) = (x - xi, y - yi);
    let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v) = (fade(fx), fade(fy));
    let (i, j) = (xi as i32, yi as i32);
    let a = lattice(wrap_x(i), wrap_y(j), seed);
    let b = lattice(wrap_x(i + 1), wrap_y(j), seed);
    let c = lattice(wrap_x(i), wrap_y(j + 1), seed);
    let d = lattice(wrap_x(i + 1), wrap_y(j + 1), seed);
    let top = a + (b - a) * u;
    let bottom = c + (d - c) * u;
    top + (bottom - top) * v
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// How wet a road is: the global wetness, the lanes whose wheel tracks are drier, and how deep
/// those tracks are rutted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wetness {
    /// Global wetness in [0, 1]: 0.5 is the shipped streets' balance; 1 floods the road
    /// (puddles everywhere but the wheel tracks), 0 leaves only the gutters wet.
    pub level: f32,
    /// Number of lanes across the road (equal widths).
    pub lanes: u32,
    /// Depth of the ruts in the wheel tracks, metres ([`crate::road::RoadFeatures`]): from 0
    /// (the tracks drier than the asphalt around them) to 1 cm and more (water stands in them,
    /// as in the gutters).
    pub ruts: f32,
}

impl Wetness {
    /// The shipped streets' wetness: two lanes, level 0.5, no ruts.
    pub const SHIPPED: Self = Self {
        level: 0.5,
        lanes: 2,
        ruts: 0.0,
    };
}

/// Dryness w in [0, 1] at road position (x across, z along; metres) for a road of half
/// width `half_width` with `wet.lanes` equal lanes.
pub fn dryness(x: f32, z: f32, half_width: f32, seed: u32, wet: Wetness) -> f32 {
    let n = 0.6 * value_noise(x / 2.5, z / 4.0, seed)
        + 0.3 * value_noise(x / 1.0, z / 1.4, seed.wrapping_add(1))
        + 0.1 * value_noise(x / 0.35, z / 0.35, seed.wrapping_add(2));
    // Wheel tracks 0.8 m either side of each lane centre are drier, unless rutted.
    let lanes = wet.lanes.max(1);
    let lane_width = 2.0 * half_width / lanes as f32;
    let track_dist = (0..lanes)
        .map(|k| -half_width + (k as f32 + 0.5) * lane_width)
        .flat_map(|c| [c - 0.8, c + 0.8])
        .map(|t| (x - t).abs())
        .fold(f32::INFINITY, f32::min);
    let track = (-(track_dist / 0.35).powi(2)).exp();
    // Water collects in the gutters along the kerbs.
    let gutter = (-((half_width - x.abs()) / 0.6).powi(2)).exp();
    // Wetness shifts the noise against the fixed thresholds below (no shift at 0.5).
    let shift = 0.5 * (0.5 - wet.level.clamp(0.0, 1.0));
    let rutted = (wet.ruts / 0.01).clamp(0.0, 1.0);
    let s = n + (0.22 - 0.57 * rutted) * track - 0.3 * gutter + shift;
    WET_ROAD_W * smoothstep(0.33, 0.37, s) + (1.0 - WET_ROAD_W) * smoothstep(0.56, 0.8, s)
}

/// The `w` x `h` pixel dryness map of a road spanning x in [-half_width, half_width] and z in
/// [z_far, z_near]: row 0 is the near end (v = 0), column 0 is x = -half_width.
/// Returns the PNG bytes and the fractions of puddle (w < 0.05) and dry (w > 0.6) pixels.
pub fn dryness_png(
    half_width: f32,
    z_near: f32,
    z_far: f32,
    (w, h): (u32, u32),
    seed: u32,
    wet: Wetness,
) -> Result<(Vec<u8>, f32, f32), Error> {
    let mut img = RgbImage::new(w, h);
    let (mut puddle, mut dry) = (0usize, 0usize);
    for (i, j, p) in img.enumerate_pixels_mut() {
        let x = -half_width + (i as f32 + 0.5) / w as f32 * 2.0 * half_width;
        let z = z_near - (j as f32 + 0.5) / h as f32 * (z_near - z_far);
        let d = dryness(x, z, half_width, seed, wet);
        puddle += usize::from(d < 0.05);
        dry += usize::from(d > 0.6);
        p.0 = [0, (d * 255.0).round() as u8, 0];
    }
    let n = (w * h) as f32;
    Ok((encode_rgb_png(&img)?, puddle as f32 / n, dry as f32 / n))
}

fn encode_rgb_png(img: &RgbImage) -> Result<Vec<u8>, Error> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| Error::Texture(e.to_string()))?;
    Ok(png)
}

/// Texels across the square ripple normal map.
pub const RIPPLE_TEXELS: u32 = 256;

/// A tiling tangent-space normal map of rain ripples (`size` x `size` texels, glTF's
/// convention: RGB = (n + 1) / 2 with +X along u, +Y along v and +Z out of the surface).
/// The height field is three octaves of tiling value noise, from ripples a quarter of the
/// tile across down to a sixteenth; its slopes are normalised so that the steepest texel
/// has slope 1 before `normalTexture.scale` (the ripples' strength) scales X and Y.
pub fn ripple_normal_png(size: u32, seed: u32) -> Result<Vec<u8>, Error> {
    let n = size.max(8);
    let height = |i: i64, j: i64| -> f32 {
        let (x, y) = (
            i.rem_euclid(i64::from(n)) as f32,
            j.rem_euclid(i64::from(n)) as f32,
        );
        [(4, 0.6f32), (8, 0.3), (16, 0.1)]
            .into_iter()
            .enumerate()
            .map(|(o, (cells, amp))| {
                let s = cells as f32 / n as f32;
                amp * tiling_noise(x * s, y * s, (cells, cells), seed.wrapping_add(o as u32))
            })
            .sum()
    };
    let mut slopes = Vec::with_capacity((n * n) as usize);
    let mut steepest = 0.0f32;
    for j in 0..i64::from(n) {
        for i in 0..i64::from(n) {
            let dx = 0.5 * (height(i + 1, j) - height(i - 1, j));
            let dy = 0.5 * (height(i, j + 1) - height(i, j - 1));
            steepest = steepest.max(dx.hypot(dy));
            slopes.push((dx, dy));
        }
    }
    let k = if steepest > 0.0 { 1.0 / steepest } else { 0.0 };
    let img = RgbImage::from_fn(n, n, |i, j| {
        let (dx, dy) = slopes[(j * n + i) as usize];
        // Image rows run down while v runs up the texture in glTF's tangent frame only by
        // convention of the map; the ripples are isotropic, so the sign does not matter.
        let v = glam::Vec3::new(-dx * k, -dy * k, 1.0).normalize();
        let enc = |c: f32| ((c * 0.5 + 0.5) * 255.0).round().clamp(0.0, 255.0) as u8;
        image::Rgb([enc(v.x), enc(v.y), enc(v.z)])
    });
    encode_rgb_png(&img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_continuous_and_in_range() {
        let mut prev = value_noise(0.0, 0.3, 7);
        for k in 1..2000 {
            let x = k as f32 * 0.01;
            let v = value_noise(x, 0.3, 7);
            assert!((0.0..1.0).contains(&v));
            assert!((v - prev).abs() < 0.05, "jump at {x}");
            prev = v;
        }
        assert_ne!(value_noise(0.5, 0.5, 1), value_noise(0.5, 0.5, 2));
    }

    #[test]
    fn road_has_puddles_wet_and_dry_patches() {
        let (png, puddle, dry) =
            dryness_png(3.5, 10.0, -60.0, (64, 512), 4, Wetness::SHIPPED).unwrap();
        assert!(puddle > 0.03 && puddle < 0.4, "puddles {puddle}");
        assert!(dry > 0.03 && dry < 0.5, "dry {dry}");
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (64, 512));
        assert!(img.pixels().all(|p| p.0[0] == 0 && p.0[2] == 0));
        // Gutters are wetter than wheel tracks on average.
        let mean_at = |x: f32| {
            (0..400)
                .map(|k| dryness(x, -k as f32 * 0.15, 3.5, 4, Wetness::SHIPPED))
                .sum::<f32>()
                / 400.0
        };
        assert!(mean_at(3.4) < mean_at(2.55));
    }

    /// Unrutted wheel tracks are drier than the asphalt between them; rutted ones hold water:
    /// wetter than it, and mostly puddles.
    #[test]
    fn rutted_wheel_tracks_hold_water() {
        let mean_at = |x: f32, ruts: f32| {
            let wet = Wetness {
                ruts,
                ..Wetness::SHIPPED
            };
            (0..400)
                .map(|k| dryness(x, -k as f32 * 0.15, 3.5, 4, wet))
                .sum::<f32>()
                / 400.0
        };
        // The right lane's centre is x = 1.75; its wheel tracks are at 0.95 and 2.55.
        let (track, between) = (2.55, 1.75);
        assert!(mean_at(track, 0.0) > mean_at(between, 0.0));
        assert!(mean_at(track, 0.015) < mean_at(between, 0.015));
        assert!(mean_at(track, 0.015) < 0.5 * mean_at(track, 0.0));
    }

    #[test]
    fn wetness_moves_puddles_and_dry_patches() {
        let share = |level: f32| {
            let wet = Wetness {
                level,
                lanes: 3,
                ruts: 0.0,
            };
            let (_, puddle, dry) = dryness_png(5.0, 10.0, -60.0, (64, 512), 9, wet).unwrap();
            (puddle, dry)
        };
        let (soaked, damp, drying) = (share(0.9), share(0.5), share(0.1));
        assert!(
            soaked.0 > damp.0 && damp.0 > drying.0,
            "{soaked:?} {damp:?} {drying:?}"
        );
        assert!(
            soaked.1 < damp.1 && damp.1 < drying.1,
            "{soaked:?} {damp:?} {drying:?}"
        );
    }

    #[test]
    fn ripple_map_tiles_and_is_unit_normals() {
        let png = ripple_normal_png(64, 3).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (64, 64));
        let dec = |p: &image::Rgb<u8>| p.0.map(|c| f32::from(c) / 255.0 * 2.0 - 1.0);
        let mut tilted = 0;
        for p in img.pixels() {
            let [x, y, z] = dec(p);
            assert!(
                (x * x + y * y + z * z - 1.0).abs() < 0.03 && z > 0.5,
                "{:?}",
                p.0
            );
            tilted += usize::from(x.hypot(y) > 0.2);
        }
        assert!(tilted > 64, "only {tilted} tilted texels");
        // The map wraps: the first and last columns differ as little as neighbours do.
        let step = |a: (u32, u32), b: (u32, u32)| {
            let (p, q) = (dec(img.get_pixel(a.0, a.1)), dec(img.get_pixel(b.0, b.1)));
            (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0f32, f32::max)
        };
        let seam = (0..64)
            .map(|j| step((63, j), (0, j)))
            .fold(0.0f32, f32::max);
        let inner = (0..64)
            .map(|j| step((31, j), (32, j)))
            .fold(0.0f32, f32::max);
        assert!(seam < 2.0 * inner + 0.05, "seam {seam} inner {inner}");
    }
}
