//! Statistics of the difference between two renders of the same scene (ours against Mitsuba's,
//! or two versions of ours), overall and per rectangular region.
//!
//! All statistics are over every pixel and every colour channel of a region, with `a` the
//! image under test and `b` the reference:
//!
//! - relative RMSE: `sqrt(mean((a - b)^2)) / mean(b)`;
//! - relative bias: `mean(a) / mean(b) - 1` (also per channel);
//! - the largest local difference: over the `block x block` tiles of the image, the tile with
//!   the largest `|mean_tile(a) - mean_tile(b)| / mean_image(b)` (normalised by the whole
//!   image's mean so that dark tiles do not dominate by division by a small number).
//!
//! # The noise test
//!
//! Given second renders `a2`, `b2` with other seeds, [`compare`] first averages `A = (a + a2)
//! / 2` and `B = (b + b2) / 2` and computes every statistic on `A`, `B`. It then estimates the
//! standard error of each region's mean from the seed-to-seed differences: pixels are rendered
//! independently, so `Var(mean_R(A)) = sum_p sigma_p^2 / (2 N^2)` (`N` values in the region,
//! `sigma_p^2` the variance of one value of one render), and `E[(a_p - a2_p)^2] = 2 sigma_p^2`,
//! hence `SE(mean_R(A)) = sqrt(sum_p (a_p - a2_p)^2) / (2 N)`, an estimate with `N` degrees
//! of freedom (values are channel means, so a pixel is one value). The test statistic is
//! `z = (mean_R(A) - mean_R(B)) / sqrt(SE_A^2 + SE_B^2)`; a region passes when `|z| <= k`
//! (`k` = 4 by default: a false alarm rate of 6e-5 per region when the renderers agree).
//! A bias that noise cannot explain is a real difference between the renderers.
//!
//! # Masked regions
//!
//! Besides rectangles, a region may be a mask ([`MaskRegion`]: the road pixels of a
//! dataset's `road0.png`, say); its statistics are the same, over the pixels it marks.
//!
//! # Fireflies
//!
//! A firefly is an isolated pixel more than [`FIREFLY_RATIO`] = 10 times brighter than its
//! neighbourhood: its luminance exceeds 10 times the median luminance of its 8 neighbours (5
//! at an edge, 3 at a corner; the mean of the two middle values for an even count), or of
//! 10^-3 times the reference's mean luminance where that is larger (so that specks in black
//! areas too dim to see do not count) ([`isolated_bright`]). Emitters seen directly (a lamp
//! of a pixel or two against the night sky) pass that test as well, so A's fireflies
//! ([`Fireflies`]) leave out every pixel within one pixel of an isolated bright pixel of the
//! reference B: those are features of the converged image (emitters, or B's own remaining
//! fireflies), not noise of A. The share is over all pixels of the image. With second
//! renders, fireflies are counted on the first render of each, not on the averages.

use crate::png::write_png_buffer;
use crate::stats::median_midpoint;
use crate::{ensure_same_size, luminance, ImageError, NamedRegion, Region, RgbImage, SizeMismatch};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Statistics of one region.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionStats {
    /// The region (the whole image for [`Comparison::overall`]).
    pub region: NamedRegion,
    /// Mean of A over pixels and channels.
    pub mean_a: f64,
    /// Mean of B over pixels and channels.
    pub mean_b: f64,
    /// `sqrt(mean((a - b)^2)) / mean(b)`.
    pub rel_rmse: f64,
    /// `mean(a) / mean(b) - 1`.
    pub rel_bias: f64,
    /// Relative bias of each channel (R, G, B).
    pub rel_bias_rgb: [f64; 3],
    /// Standard error of `mean_a - mean_b` from the seed-to-seed differences (noise test only).
    pub std_error: Option<f64>,
    /// `(mean_a - mean_b) / std_error` (noise test only).
    pub z: Option<f64>,
    /// `|z| <= k` (noise test only).
    pub passed: Option<bool>,
    /// Number of pixels in the region (a mask's marked pixels; its rectangle is the mask's
    /// bounding box).
    #[serde(default)]
    pub pixels: u64,
}

/// A region given by a mask: the pixels where `mask` is true (row-major, the image's size).
#[derive(Clone, Debug, PartialEq)]
pub struct MaskRegion {
    /// Its name.
    pub name: String,
    /// Width of the mask in pixels.
    pub width: u32,
    /// Height of the mask in pixels.
    pub height: u32,
    /// Which pixels belong to the region, row-major.
    pub mask: Vec<bool>,
}

/// How much brighter than its neighbourhood a pixel must be to be a firefly.
pub const FIREFLY_RATIO: f32 = 10.0;

/// The fireflies of A against the reference B (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fireflies {
    /// [`FIREFLY_RATIO`].
    pub ratio: f32,
    /// A's fireflies: its isolated bright pixels away from B's.
    pub count: u64,
    /// `count` over all pixels of the image.
    pub share: f64,
    /// Pixels left out: within one pixel of an isolated bright pixel of B.
    pub excluded: u64,
    /// Share of A's pixels that are isolated bright, none left out (emitters included).
    pub share_a_all: f64,
    /// Share of B's pixels that are isolated bright, none left out (emitters included).
    pub share_b_all: f64,
}

/// The tile with the largest difference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockDiff {
    /// Left column of the tile.
    pub x0: u32,
    /// Top row of the tile.
    pub y0: u32,
    /// Tile size (tiles at the right and bottom edges may be smaller).
    pub size: u32,
    /// Mean of A over the tile.
    pub mean_a: f64,
    /// Mean of B over the tile.
    pub mean_b: f64,
    /// `(mean_tile(a) - mean_tile(b)) / mean_image(b)`.
    pub rel_diff: f64,
}

/// The result of [`compare`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Whether A and B are the averages of two renders each (the noise test ran).
    pub noise_test: bool,
    /// The `k` of the noise test (`|z| <= k` passes).
    pub k: f64,
    /// The whole image.
    pub overall: RegionStats,
    /// The requested regions, in order, then the masked regions.
    pub regions: Vec<RegionStats>,
    /// The tile with the largest difference.
    pub largest_block: BlockDiff,
    /// A's fireflies against B.
    pub fireflies: Fireflies,
}

impl Comparison {
    /// Whether every region (and the whole image) passed the noise test; `None` without it.
    pub fn passed(&self) -> Option<bool> {
        std::iter::once(&self.overall)
            .chain(&self.regions)
            .map(|r| r.passed)
            .collect::<Option<Vec<bool>>>()
            .map(|v| v.iter().all(|&p| p))
    }

    /// A plain-text table of the statistics.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<12} {:>17} {:>12} {:>12} {:>10} {:>10}",
            "region", "pixels", "mean A", "mean B", "rel bias", "rel RMSE"
        );
        if self.noise_test {
            s.push_str(&format!(
                " {:>10} {:>8}  (|z| <= {})",
                "std err", "z", self.k
            ));
        }
        s.push('\n');
        for r in std::iter::once(&self.overall).chain(&self.regions) {
            let g = &r.region.region;
            let area = (g.x1 - g.x0) as u64 * (g.y1 - g.y0) as u64;
            let pixels = if r.pixels == area {
                format!("{},{}-{},{}", g.x0, g.y0, g.x1, g.y1)
            } else {
                format!("mask {} px", r.pixels)
            };
            s.push_str(&format!(
                "{:<12} {:>17} {:>12.5e} {:>12.5e} {:>+9.3}% {:>9.3}%",
                r.region.name,
                pixels,
                r.mean_a,
                r.mean_b,
                100.0 * r.rel_bias,
                100.0 * r.rel_rmse
            ));
            if let (Some(se), Some(z), Some(p)) = (r.std_error, r.z, r.passed) {
                s.push_str(&format!(
                    " {:>9.3}% {:>+8.2}  {}",
                    100.0 * se / r.mean_b,
                    z,
                    if p { "ok" } else { "FAIL" }
                ));
            }
            s.push('\n');
        }
        let b = &self.largest_block;
        s.push_str(&format!(
            "largest {}x{} block difference: {:+.3}% of the image mean at ({}, {}) \
             (A {:.5e}, B {:.5e})\n",
            b.size,
            b.size,
            100.0 * b.rel_diff,
            b.x0,
            b.y0,
            b.mean_a,
            b.mean_b
        ));
        let f = &self.fireflies;
        s.push_str(&format!(
            "fireflies (> {}x the neighbourhood median, away from B's): A {:.4}% ({} px, {} px \
             left out); all isolated bright pixels: A {:.4}%, B {:.4}%\n",
            f.ratio,
            100.0 * f.share,
            f.count,
            f.excluded,
            100.0 * f.share_a_all,
            100.0 * f.share_b_all
        ));
        s
    }
}

/// The images to compare: `a` under test, `b` the reference, optionally a second render of
/// each with another seed (both or neither) for the noise test.
#[derive(Clone, Copy, Debug)]
pub struct Inputs<'a> {
    /// Image under test.
    pub a: &'a RgbImage,
    /// Reference.
    pub b: &'a RgbImage,
    /// Second renders of A and B with other seeds.
    pub seconds: Option<(&'a RgbImage, &'a RgbImage)>,
}

/// Channel mean of a pixel.
#[inline]
fn grey(v: Vec3) -> f64 {
    (f64::from(v.x) + f64::from(v.y) + f64::from(v.z)) / 3.0
}

/// [`ensure_same_size`] of two renders.
fn check_size(
    first: &'static str,
    a: &RgbImage,
    second: &'static str,
    b: &RgbImage,
) -> Result<(), ImageError> {
    let size = |i: &RgbImage| (i.width as usize, i.height as usize);
    Ok(ensure_same_size(first, size(a), second, size(b))?)
}

/// Sums over a region, in f64.
#[derive(Default)]
struct Sums {
    n: u64,
    a: [f64; 3],
    b: [f64; 3],
    sq: f64,
    noise_a: f64,
    noise_b: f64,
}

/// A pixel of the (possibly averaged) inputs and its seed-to-seed differences.
#[inline]
fn pixel(inputs: &Inputs<'_>, i: usize) -> (Vec3, Vec3, f64, f64) {
    match inputs.seconds {
        None => (inputs.a.pixels[i], inputs.b.pixels[i], 0.0, 0.0),
        Some((a2, b2)) => {
            let (a, b) = (inputs.a.pixels[i], inputs.b.pixels[i]);
            (
                0.5 * (a + a2.pixels[i]),
                0.5 * (b + b2.pixels[i]),
                grey(a) - grey(a2.pixels[i]),
                grey(b) - grey(b2.pixels[i]),
            )
        }
    }
}

impl Sums {
    /// Adds pixel `i`.
    #[inline]
    fn add(&mut self, inputs: &Inputs<'_>, i: usize) {
        let (a, b, da, db) = pixel(inputs, i);
        self.n += 1;
        for c in 0..3 {
            self.a[c] += f64::from(a[c]);
            self.b[c] += f64::from(b[c]);
        }
        let d = a - b;
        self.sq += f64::from(d.x).powi(2) + f64::from(d.y).powi(2) + f64::from(d.z).powi(2);
        self.noise_a += da * da;
        self.noise_b += db * db;
    }
}

fn region_sums(inputs: &Inputs<'_>, r: &Region) -> Sums {
    let mut s = Sums::default();
    let w = inputs.a.width as usize;
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            s.add(inputs, y * w + x);
        }
    }
    s
}

fn region_stats(inputs: &Inputs<'_>, region: NamedRegion, k: f64) -> RegionStats {
    let s = region_sums(inputs, &region.region);
    stats_of(s, region, k, inputs.seconds.is_some())
}

/// The statistics of a masked region: over its marked pixels, with its bounding box as the
/// rectangle.
fn mask_stats(inputs: &Inputs<'_>, m: &MaskRegion, k: f64) -> Result<RegionStats, ImageError> {
    let (w, h) = (inputs.a.width, inputs.a.height);
    let size = (w as usize, h as usize);
    let mismatch = SizeMismatch {
        first: "A",
        first_size: size,
        second: "the mask",
        second_size: (m.width as usize, m.height as usize),
    };
    // A mask whose flags do not fill its size fits no image either.
    if mismatch.first_size != mismatch.second_size || m.mask.len() != size.0 * size.1 {
        return Err(mismatch.into());
    }
    let mut s = Sums::default();
    let mut bbox: Option<Region> = None;
    for (i, _) in m.mask.iter().enumerate().filter(|(_, &on)| on) {
        s.add(inputs, i);
        let (x, y) = (i % w as usize, i / w as usize);
        let b = bbox.get_or_insert(Region {
            x0: x,
            y0: y,
            x1: x + 1,
            y1: y + 1,
        });
        (b.x0, b.y0) = (b.x0.min(x), b.y0.min(y));
        (b.x1, b.y1) = (b.x1.max(x + 1), b.y1.max(y + 1));
    }
    let Some(region) = bbox else {
        return Err(ImageError::EmptyMask {
            name: m.name.clone(),
        });
    };
    let region = NamedRegion {
        name: m.name.clone(),
        region,
    };
    Ok(stats_of(s, region, k, inputs.seconds.is_some()))
}

fn stats_of(s: Sums, region: NamedRegion, k: f64, noise_test: bool) -> RegionStats {
    let n = s.n as f64;
    let mean_a = s.a.iter().sum::<f64>() / (3.0 * n);
    let mean_b = s.b.iter().sum::<f64>() / (3.0 * n);
    let rel_bias_rgb = [0, 1, 2].map(|c| s.a[c] / s.b[c] - 1.0);
    let (std_error, z, passed) = if noise_test {
        let se = (s.noise_a + s.noise_b).sqrt() / (2.0 * n);
        let z = (mean_a - mean_b) / se;
        // A zero standard error (no noise at all) passes only on exact agreement.
        let passed = if se > 0.0 {
            z.abs() <= k
        } else {
            mean_a == mean_b
        };
        (Some(se), Some(z), Some(passed))
    } else {
        (None, None, None)
    };
    RegionStats {
        region,
        mean_a,
        mean_b,
        rel_rmse: (s.sq / (3.0 * n)).sqrt() / mean_b,
        rel_bias: mean_a / mean_b - 1.0,
        rel_bias_rgb,
        std_error,
        z,
        passed,
        pixels: s.n,
    }
}

/// Whether each pixel of `img` is isolated bright: its luminance above `ratio` times the
/// larger of `floor` and the median luminance of its neighbours (see the module
/// documentation). Row-major.
pub fn isolated_bright(img: &RgbImage, ratio: f32, floor: f32) -> Vec<bool> {
    let (w, h) = (img.width as usize, img.height as usize);
    let lum: Vec<f32> = img.pixels.iter().map(|&p| luminance(p)).collect();
    let mut out = vec![false; w * h];
    let mut nb = [0f32; 8];
    for y in 0..h {
        for x in 0..w {
            let mut n = 0;
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let (xx, yy) = (x as i32 + dx, y as i32 + dy);
                    if (dx, dy) != (0, 0)
                        && xx >= 0
                        && yy >= 0
                        && (xx as usize) < w
                        && (yy as usize) < h
                    {
                        nb[n] = lum[yy as usize * w + xx as usize];
                        n += 1;
                    }
                }
            }
            let Some(median) = median_midpoint(&mut nb[..n]) else {
                continue;
            };
            out[y * w + x] = lum[y * w + x] > ratio * median.max(floor);
        }
    }
    out
}

/// A's fireflies against the reference `b` (same size; see the module documentation).
pub fn fireflies(a: &RgbImage, b: &RgbImage) -> Result<Fireflies, ImageError> {
    check_size("A", a, "B", b)?;
    let (w, h) = (a.width as usize, a.height as usize);
    let n = (w * h).max(1) as f64;
    let mean_b = b
        .pixels
        .iter()
        .map(|&p| f64::from(luminance(p)))
        .sum::<f64>()
        / n;
    let floor = (1e-3 * mean_b) as f32;
    let in_a = isolated_bright(a, FIREFLY_RATIO, floor);
    let in_b = isolated_bright(b, FIREFLY_RATIO, floor);
    let near_b = |x: usize, y: usize| {
        (y.saturating_sub(1)..(y + 2).min(h))
            .any(|yy| (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| in_b[yy * w + xx]))
    };
    let (mut count, mut excluded) = (0u64, 0u64);
    for y in 0..h {
        for x in 0..w {
            if near_b(x, y) {
                excluded += 1;
            } else if in_a[y * w + x] {
                count += 1;
            }
        }
    }
    let share = |m: &[bool]| m.iter().filter(|&&v| v).count() as f64 / n;
    Ok(Fireflies {
        ratio: FIREFLY_RATIO,
        count,
        share: count as f64 / n,
        excluded,
        share_a_all: share(&in_a),
        share_b_all: share(&in_b),
    })
}

/// Compares A with B over the whole image, the `regions` (unnamed ones are called
/// `region<i>`), and `block x block` tiles, and counts A's fireflies; `k` is the noise
/// test's threshold (used only with second renders).
pub fn compare(
    inputs: &Inputs<'_>,
    regions: &[NamedRegion],
    block: u32,
    k: f64,
) -> Result<Comparison, ImageError> {
    compare_masked(inputs, regions, &[], block, k)
}

/// [`compare`] with masked regions as well (after the rectangles in
/// [`Comparison::regions`]).
pub fn compare_masked(
    inputs: &Inputs<'_>,
    regions: &[NamedRegion],
    masks: &[MaskRegion],
    block: u32,
    k: f64,
) -> Result<Comparison, ImageError> {
    let (a, b) = (inputs.a, inputs.b);
    check_size("A", a, "B", b)?;
    if let Some((a2, b2)) = inputs.seconds {
        check_size("A", a, "A2", a2)?;
        check_size("A", a, "B2", b2)?;
    }
    let (width, height) = (a.width, a.height);
    let whole = NamedRegion {
        name: "image".into(),
        region: Region::whole(width as usize, height as usize),
    };
    whole
        .region
        .check_fits(&whole.name, width as usize, height as usize)?;
    let mut stats = Vec::with_capacity(regions.len());
    for (i, r) in regions.iter().enumerate() {
        let mut r = r.clone();
        if r.name.is_empty() {
            r.name = format!("region{i}");
        }
        r.region
            .check_fits(&r.name, width as usize, height as usize)?;
        stats.push(region_stats(inputs, r, k));
    }
    for m in masks {
        stats.push(mask_stats(inputs, m, k)?);
    }
    let overall = region_stats(inputs, whole, k);
    let block = block.max(1);
    let mut largest: Option<BlockDiff> = None;
    for y0 in (0..height).step_by(block as usize) {
        for x0 in (0..width).step_by(block as usize) {
            let tile = Region {
                x0: x0 as usize,
                y0: y0 as usize,
                x1: (x0 + block).min(width) as usize,
                y1: (y0 + block).min(height) as usize,
            };
            let s = region_sums(inputs, &tile);
            let n = 3.0 * s.n as f64;
            let (ma, mb) = (s.a.iter().sum::<f64>() / n, s.b.iter().sum::<f64>() / n);
            let rel_diff = (ma - mb) / overall.mean_b;
            if largest
                .as_ref()
                .is_none_or(|l| rel_diff.abs() > l.rel_diff.abs())
            {
                largest = Some(BlockDiff {
                    x0,
                    y0,
                    size: block,
                    mean_a: ma,
                    mean_b: mb,
                    rel_diff,
                });
            }
        }
    }
    Ok(Comparison {
        width,
        height,
        noise_test: inputs.seconds.is_some(),
        k,
        overall,
        regions: stats,
        // The image is not empty, so there is at least one tile.
        largest_block: largest.unwrap_or(BlockDiff {
            x0: 0,
            y0: 0,
            size: block,
            mean_a: 0.0,
            mean_b: 0.0,
            rel_diff: 0.0,
        }),
        fireflies: fireflies(a, b)?,
    })
}

/// The blue-white-red colour of a signed value `t` in [-1, 1] (clamped): blue for -1, white
/// for 0, red for +1, as 8-bit sRGB.
#[inline]
pub fn diverging_colour(t: f64) -> [u8; 3] {
    let t = t.clamp(-1.0, 1.0);
    let fade = (255.0 * (1.0 - t.abs())).round() as u8;
    if t >= 0.0 {
        [255, fade, fade]
    } else {
        [fade, fade, 255]
    }
}

/// The false-colour difference image: per pixel the signed relative difference
/// `d = (a - b) / ((a + b) / 2 + 0.01 mean(b))` of the channel means (the small offset keeps
/// black pixels from dividing by zero), mapped by [`diverging_colour`] with `d = +-scale` at
/// full red or blue.
pub fn diff_image(a: &RgbImage, b: &RgbImage, scale: f64) -> Result<image::RgbImage, ImageError> {
    check_size("A", a, "B", b)?;
    let n = b.pixels.len().max(1) as f64;
    let mean_b = b.pixels.iter().map(|&p| grey(p)).sum::<f64>() / n;
    let eps = 0.01 * mean_b.abs() + f64::MIN_POSITIVE;
    let mut img = image::RgbImage::new(a.width, a.height);
    for (px, (&pa, &pb)) in img.pixels_mut().zip(a.pixels.iter().zip(&b.pixels)) {
        let (ga, gb) = (grey(pa), grey(pb));
        let d = (ga - gb) / (0.5 * (ga + gb).abs() + eps);
        *px = image::Rgb(diverging_colour(d / scale));
    }
    Ok(img)
}

/// Writes [`diff_image`] as a PNG at `path` (through a temporary file and a rename).
pub fn write_diff_png(
    path: &Path,
    a: &RgbImage,
    b: &RgbImage,
    scale: f64,
) -> Result<(), ImageError> {
    write_png_buffer(path, &diff_image(a, b, scale)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3) -> RgbImage {
        RgbImage {
            width: w,
            height: h,
            pixels: (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| f(x, y))
                .collect(),
        }
    }

    /// splitmix64, for reproducible synthetic noise.
    struct Rng(u64);
    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        /// Uniform noise of standard deviation `sd`.
        fn noise(&mut self, sd: f64) -> f32 {
            ((self.uniform() - 0.5) * sd * 12f64.sqrt()) as f32
        }
    }

    #[test]
    fn known_bias_and_rmse() {
        let b = img(16, 8, |x, _| Vec3::new(1.0, 2.0, 3.0) * (1.0 + x as f32));
        let a = img(16, 8, |x, _| Vec3::new(1.1, 2.2, 3.3) * (1.0 + x as f32));
        let c = compare(
            &Inputs {
                a: &a,
                b: &b,
                seconds: None,
            },
            &[],
            8,
            4.0,
        )
        .unwrap();
        let o = &c.overall;
        assert!((o.rel_bias - 0.1).abs() < 1e-6, "{}", o.rel_bias);
        for r in o.rel_bias_rgb {
            assert!((r - 0.1).abs() < 1e-6);
        }
        // rmse = 0.1 sqrt(mean(b^2)) / mean(b), computed independently.
        let vals: Vec<f64> = b
            .pixels
            .iter()
            .flat_map(|p| p.to_array())
            .map(f64::from)
            .collect();
        let n = vals.len() as f64;
        let mean = vals.iter().sum::<f64>() / n;
        let rms = (vals.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        assert!((o.rel_rmse - 0.1 * rms / mean).abs() < 1e-6);
        assert!(c.passed().is_none());
        assert!(c.table().contains("+10.000%"), "{}", c.table());
    }

    #[test]
    fn regions_and_the_largest_block() {
        let b = img(32, 24, |_, _| Vec3::ONE);
        let a = img(32, 24, |x, y| {
            if (16..24).contains(&x) && (8..16).contains(&y) {
                Vec3::splat(3.0)
            } else {
                Vec3::ONE
            }
        });
        let regions: Vec<NamedRegion> = ["hot=16,8,24,16", "0,0,8,8"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let c = compare(
            &Inputs {
                a: &a,
                b: &b,
                seconds: None,
            },
            &regions,
            8,
            4.0,
        )
        .unwrap();
        assert_eq!(c.regions[0].region.name, "hot");
        assert!((c.regions[0].rel_bias - 2.0).abs() < 1e-12);
        assert!((c.regions[0].rel_rmse - 2.0).abs() < 1e-12);
        assert_eq!(c.regions[1].region.name, "region1");
        assert_eq!(c.regions[1].rel_bias, 0.0);
        assert!((c.overall.rel_bias - 2.0 * 64.0 / 768.0).abs() < 1e-12);
        let lb = &c.largest_block;
        assert_eq!((lb.x0, lb.y0, lb.size), (16, 8, 8));
        assert!((lb.rel_diff - 2.0).abs() < 1e-12);
        let json = serde_json::to_string(&c).unwrap();
        let back: Comparison = serde_json::from_str(&json).unwrap();
        assert_eq!(back, c);
    }

    #[test]
    fn size_mismatch_and_bad_regions_are_errors() {
        let a = img(4, 4, |_, _| Vec3::ONE);
        let b = img(4, 5, |_, _| Vec3::ONE);
        let err = compare(
            &Inputs {
                a: &a,
                b: &b,
                seconds: None,
            },
            &[],
            8,
            4.0,
        )
        .unwrap_err();
        assert_eq!(err.to_string(), "image sizes differ: A is 4x4, B is 4x5");
        let err = compare(
            &Inputs {
                a: &a,
                b: &a,
                seconds: Some((&a, &b)),
            },
            &[],
            8,
            4.0,
        )
        .unwrap_err();
        assert!(err.to_string().contains("B2 is 4x5"), "{err}");
        assert!(diff_image(&a, &b, 1.0).is_err());
        let outside: NamedRegion = "road=0,0,5,4".parse().unwrap();
        let err = compare(
            &Inputs {
                a: &a,
                b: &a,
                seconds: None,
            },
            &[outside],
            8,
            4.0,
        )
        .unwrap_err();
        assert!(err.to_string().contains("road"), "{err}");
        for bad in ["1,2,3", "a=1,2,x,4", "0,0,0,4", ""] {
            assert!(bad.parse::<NamedRegion>().is_err(), "{bad}");
        }
    }

    #[test]
    fn noise_test_estimates_the_standard_error_and_detects_bias() {
        let (w, h, sd, mu) = (64u32, 64u32, 0.2f64, 1.0f32);
        let mut rng = Rng(7);
        let mut render = |scale: f32| {
            let mut i = img(w, h, |_, _| Vec3::splat(mu * scale));
            for p in &mut i.pixels {
                *p += Vec3::splat(rng.noise(sd));
            }
            i
        };
        let (b1, b2) = (render(1.0), render(1.0));
        let (a1, a2) = (render(1.0), render(1.0));
        let same = Inputs {
            a: &a1,
            b: &b1,
            seconds: Some((&a2, &b2)),
        };
        let c = compare(&same, &[], 8, 4.0).unwrap();
        // True SE of mean(A) - mean(B): each is the mean of 2N values of variance sd^2.
        let n = f64::from(w * h);
        let true_se = (2.0 * sd * sd / (2.0 * n)).sqrt();
        let se = c.overall.std_error.unwrap();
        assert!((se / true_se - 1.0).abs() < 0.05, "{se} vs {true_se}");
        assert_eq!(c.passed(), Some(true), "{}", c.table());
        // A 2% bias is 2e-2 / 3.1e-3, about 6 standard errors: detected.
        let (a1, a2) = (render(1.02), render(1.02));
        let biased = Inputs {
            a: &a1,
            b: &b1,
            seconds: Some((&a2, &b2)),
        };
        let c = compare(&biased, &[], 8, 4.0).unwrap();
        assert_eq!(c.passed(), Some(false), "{}", c.table());
        assert!(c.table().contains("FAIL"));
    }

    /// A smooth image with three spikes in A: one 20x its neighbours (a firefly), one 5x (not
    /// one), and one where B has an emitter of one pixel (left out, with its neighbours).
    #[test]
    fn fireflies_are_isolated_pixels_away_from_the_references() {
        let base = |x: u32, y: u32| Vec3::splat(1.0 + 0.01 * (x + y) as f32);
        let lamp = (20, 5);
        let b = img(32, 16, |x, y| {
            if (x, y) == lamp {
                Vec3::splat(500.0)
            } else {
                base(x, y)
            }
        });
        let a = img(32, 16, |x, y| match (x, y) {
            (4, 4) => Vec3::splat(20.0),
            (10, 10) => Vec3::splat(5.0),
            (21, 5) => Vec3::splat(30.0),
            p if p == lamp => Vec3::splat(480.0),
            _ => base(x, y),
        });
        let f = fireflies(&a, &b).unwrap();
        assert_eq!((f.count, f.excluded), (1, 9), "{f:?}");
        let n = 32.0 * 16.0;
        assert_eq!(f.share, 1.0 / n);
        // A's isolated bright pixels, none left out: the firefly and the lamp (its neighbour
        // at 30 has the lamp among its neighbours, whose median stays about 1).
        assert_eq!(f.share_a_all, 3.0 / n);
        assert_eq!(f.share_b_all, 1.0 / n);
        let c = compare(
            &Inputs {
                a: &a,
                b: &b,
                seconds: None,
            },
            &[],
            8,
            4.0,
        )
        .unwrap();
        assert_eq!(c.fireflies, f);
        assert!(c.table().contains("fireflies"), "{}", c.table());
        // Specks in black far below the image's brightness are not fireflies; in a lit image
        // of the same black area they are.
        let dark = img(8, 8, |x, y| {
            if (x, y) == (3, 3) {
                Vec3::splat(1e-6)
            } else if x >= 6 {
                Vec3::splat(1.0)
            } else {
                Vec3::ZERO
            }
        });
        assert_eq!(fireflies(&dark, &dark).unwrap().share_a_all, 0.0);
        let speck = img(8, 8, |x, y| {
            if (x, y) == (3, 3) {
                Vec3::splat(0.1)
            } else if x >= 6 {
                Vec3::splat(1.0)
            } else {
                Vec3::ZERO
            }
        });
        let f = fireflies(&speck, &dark).unwrap();
        assert_eq!((f.count, f.share_a_all), (1, 1.0 / 64.0), "{f:?}");
    }

    #[test]
    fn masked_regions_average_their_pixels() {
        let b = img(8, 4, |_, _| Vec3::ONE);
        let a = img(8, 4, |x, _| Vec3::splat(if x % 2 == 0 { 2.0 } else { 1.0 }));
        let mask = MaskRegion {
            name: "even".into(),
            width: 8,
            height: 4,
            mask: (0..32).map(|i| i % 2 == 0 && i >= 8).collect(),
        };
        let inputs = Inputs {
            a: &a,
            b: &b,
            seconds: None,
        };
        let c = compare_masked(&inputs, &[], std::slice::from_ref(&mask), 8, 4.0).unwrap();
        let r = &c.regions[0];
        assert_eq!((r.region.name.as_str(), r.pixels), ("even", 12));
        assert_eq!(
            (
                r.region.region.x0,
                r.region.region.y0,
                r.region.region.x1,
                r.region.region.y1
            ),
            (0, 1, 7, 4)
        );
        assert!((r.rel_bias - 1.0).abs() < 1e-12);
        assert!(c.table().contains("mask 12 px"), "{}", c.table());
        let empty = MaskRegion {
            mask: vec![false; 32],
            ..mask.clone()
        };
        let err = compare_masked(&inputs, &[], &[empty], 8, 4.0).unwrap_err();
        assert_eq!(err.to_string(), "the mask even marks no pixel");
        let small = MaskRegion {
            width: 4,
            mask: vec![true; 16],
            ..mask
        };
        assert!(compare_masked(&inputs, &[], &[small], 8, 4.0).is_err());
    }

    #[test]
    fn diff_colours_are_signed() {
        assert_eq!(diverging_colour(0.0), [255, 255, 255]);
        assert_eq!(diverging_colour(2.0), [255, 0, 0]);
        assert_eq!(diverging_colour(-1.0), [0, 0, 255]);
        let b = img(3, 1, |_, _| Vec3::ONE);
        let a = img(3, 1, |x, _| Vec3::splat(x as f32));
        let d = diff_image(&a, &b, 0.5).unwrap();
        assert_eq!(d.get_pixel(0, 0).0, [0, 0, 255]);
        assert_eq!(d.get_pixel(1, 0).0, [255, 255, 255]);
        assert_eq!(d.get_pixel(2, 0).0, [255, 0, 0]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.png");
        write_diff_png(&path, &a, &b, 0.5).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgb8(), d);
    }
}
