//! Synthetic stereo pairs and streak images with known answers, for validating the estimators
//! ([`crate::lk`], [`crate::sgm`], [`crate::detect`]) and for benchmarks.
//!
//! A pair is rendered from a smooth random texture (value noise with quintic interpolation,
//! three octaves) that can be evaluated at any real position, so a surface can be shifted by
//! an exact sub-pixel disparity. The background is a plane whose disparity changes linearly
//! from the top row to the bottom row (like a road: slanted, constant along each row); boxes in
//! front of it carry constant disparities. The right image sees, at each pixel, the front-most
//! surface (largest disparity), so occlusions are physically consistent. Pixels are sampled at
//! their centres; disparity follows docs/design.md: `d = x_left - x_right`.

use std::path::Path;
use streaks_dataset::SampleDir;
use streaks_image::pfm::write_pfm;
use streaks_image::{GrayImage, ImageError};
use streaks_stereo::rig::Eye;

/// A fronto-parallel rectangle in front of the background, in left-image pixel indices
/// (half-open `[x0, x1) x [y0, y1)`), with a constant disparity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SynthBox {
    /// First column (left image).
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
    /// Disparity in pixels (should exceed the background's, as a box is in front of it).
    pub disparity: f32,
}

/// A synthetic stereo scene: a slanted background plane, boxes, and camera differences.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthScene {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Background disparity on the top row (pixel centre y = 0.5).
    pub disparity_top: f32,
    /// Background disparity on the bottom row; rows in between are interpolated linearly.
    pub disparity_bottom: f32,
    /// Boxes in front of the background (later boxes are drawn over earlier ones).
    pub boxes: Vec<SynthBox>,
    /// Right-image gain (exposure difference): `right = gain * texture + offset`.
    pub gain: f32,
    /// Right-image offset.
    pub offset: f32,
    /// Standard deviation of the Gaussian noise added to both images (texture is in [0, 1]).
    pub noise: f32,
    /// Seed of the texture and of the noise.
    pub seed: u64,
}

/// A rendered pair with the left image's ground-truth disparity.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthPair {
    /// Left image.
    pub left: GrayImage,
    /// Right image.
    pub right: GrayImage,
    /// Ground-truth disparity of every left pixel (`d = x_left - x_right`).
    pub disparity: GrayImage,
}

impl SynthPair {
    /// A fronto-parallel textured plane at the constant disparity `d`: left `T(x, y)`, right
    /// `gain T(x + d, y) + offset` (an exposure difference), with the texture of `seed`.
    /// An error for a zero size.
    pub fn shifted(
        width: usize,
        height: usize,
        seed: u64,
        d: f32,
        gain: f32,
        offset: f32,
    ) -> Result<Self, ImageError> {
        let t = Texture::new(seed);
        let mut left = GrayImage::new(width, height, 0.0)?;
        let mut right = GrayImage::new(width, height, 0.0)?;
        for y in 0..height {
            for x in 0..width {
                let (xc, yc) = (x as f32 + 0.5, y as f32 + 0.5);
                left.set(x, y, t.at(xc, yc));
                right.set(x, y, gain * t.at(xc + d, yc) + offset);
            }
        }
        Ok(Self {
            left,
            right,
            disparity: GrayImage::new(width, height, d)?,
        })
    }

    /// Writes the two views (`im0.png`, `im1.png`: 16-bit grey, values clipped to [0, 1])
    /// and the left view's disparity (`disp0.pfm`) into `dir`, in the sample layout
    /// ([`SampleDir`]) that `streaks stereo` writes.
    pub fn save(&self, dir: &Path) -> Result<(), ImageError> {
        let sample = SampleDir::new(dir);
        for (eye, img) in [(Eye::Left, &self.left), (Eye::Right, &self.right)] {
            let path = sample.png(eye);
            let buf = ::image::ImageBuffer::<::image::Luma<u16>, Vec<u16>>::from_fn(
                img.width as u32,
                img.height as u32,
                |x, y| {
                    let v = img.get(x as usize, y as usize).clamp(0.0, 1.0);
                    ::image::Luma([(v * 65535.0).round() as u16])
                },
            );
            streaks_image::png::write_png_buffer(&path, &buf)?;
        }
        write_pfm(&sample.disparity(Eye::Left), &self.disparity)
    }
}

impl SynthScene {
    /// A textured scene of the given size: with `s = min(width / 64, 8)`, a background sloping
    /// from `s` to `4 s` pixels of disparity, and three boxes at larger, non-integer
    /// disparities (up to `7 s + 0.25`, so at most 56.25). No noise and
    /// no exposure difference (set `gain`, `offset`, `noise` to add them).
    pub fn textured(width: usize, height: usize, seed: u64) -> Self {
        let (w, h) = (width as f32, height as f32);
        let bx = |fx0: f32, fy0: f32, fx1: f32, fy1: f32, d: f32| SynthBox {
            x0: (fx0 * w) as usize,
            y0: (fy0 * h) as usize,
            x1: (fx1 * w) as usize,
            y1: (fy1 * h) as usize,
            disparity: d,
        };
        let s = (w / 64.0).min(8.0);
        Self {
            width,
            height,
            disparity_top: s,
            disparity_bottom: 4.0 * s,
            boxes: vec![
                bx(0.15, 0.15, 0.40, 0.45, 5.0 * s + 0.37),
                bx(0.55, 0.20, 0.85, 0.55, 6.5 * s + 0.81),
                bx(0.30, 0.60, 0.60, 0.85, 7.0 * s + 0.25),
            ],
            gain: 1.0,
            offset: 0.0,
            noise: 0.0,
            seed,
        }
    }

    /// The background disparity of row `y` (a pixel index).
    pub fn background_disparity(&self, y: usize) -> f32 {
        let t = if self.height > 1 {
            y as f32 / (self.height - 1) as f32
        } else {
            0.0
        };
        self.disparity_top + t * (self.disparity_bottom - self.disparity_top)
    }

    /// Renders the pair; an error for a zero size.
    pub fn render(&self) -> Result<SynthPair, ImageError> {
        let (w, h) = (self.width, self.height);
        let mut left = GrayImage::new(w, h, 0.0)?;
        let mut right = GrayImage::new(w, h, 0.0)?;
        let mut disparity = GrayImage::new(w, h, 0.0)?;
        let bg = Texture::new(self.seed);
        let fg: Vec<Texture> = (0..self.boxes.len())
            .map(|i| {
                Texture::new(self.seed ^ (0x9e37_79b9_7f4a_7c15u64.wrapping_mul(i as u64 + 1)))
            })
            .collect();
        let mut rng = SplitMix(self.seed.wrapping_add(0x5eed));
        for y in 0..h {
            let dbg = self.background_disparity(y);
            let yc = y as f32 + 0.5;
            for x in 0..w {
                let xc = x as f32 + 0.5;
                // Left: the last box containing the pixel, else the background.
                let (mut v, mut d) = (bg.at(xc, yc), dbg);
                for (b, t) in self.boxes.iter().zip(&fg) {
                    if (b.x0..b.x1).contains(&x) && (b.y0..b.y1).contains(&y) {
                        (v, d) = (t.at(xc + 1000.0, yc), b.disparity);
                    }
                }
                left.set(x, y, v + self.noise * rng.gaussian());
                disparity.set(x, y, d);
                // Right: the front-most surface whose left position x_r + d lies in it.
                let (mut rv, mut rd) = (bg.at(xc + dbg, yc), dbg);
                for (b, t) in self.boxes.iter().zip(&fg) {
                    let xl = xc + b.disparity;
                    if b.disparity > rd
                        && xl >= b.x0 as f32
                        && xl < b.x1 as f32
                        && (b.y0..b.y1).contains(&y)
                    {
                        (rv, rd) = (t.at(xl + 1000.0, yc), b.disparity);
                    }
                }
                right.set(
                    x,
                    y,
                    self.gain * rv + self.offset + self.noise * rng.gaussian(),
                );
            }
        }
        Ok(SynthPair {
            left,
            right,
            disparity,
        })
    }
}

/// A smooth random texture in [0, 1]: three octaves of value noise (periods 24, 12 and 6
/// pixels) with quintic interpolation, so it is C2 and can be shifted by any real amount.
#[derive(Clone, Copy, Debug)]
pub struct Texture {
    seed: u64,
}

impl Texture {
    /// The texture of a seed.
    pub fn new(seed: u64) -> Self {
        Self { seed }
    }

    /// The value at the real position (x, y).
    pub fn at(&self, x: f32, y: f32) -> f32 {
        let mut v = 0.0;
        let mut total = 0.0;
        for (octave, (period, weight)) in [(24.0f32, 0.4f32), (12.0, 0.35), (6.0, 0.25)]
            .into_iter()
            .enumerate()
        {
            v += weight * self.noise(x / period, y / period, octave as u64);
            total += weight;
        }
        v / total
    }

    fn lattice(&self, i: i64, j: i64, octave: u64) -> f32 {
        let mut h = self.seed ^ octave.wrapping_mul(0xa076_1d64_78bd_642f);
        h ^= (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        h = SplitMix(h).next_u64();
        h ^= (j as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
        (SplitMix(h).next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn noise(&self, x: f32, y: f32, octave: u64) -> f32 {
        let (fx, fy) = (x.floor(), y.floor());
        let (i, j) = (fx as i64, fy as i64);
        let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v) = (fade(x - fx), fade(y - fy));
        let a = self.lattice(i, j, octave);
        let b = self.lattice(i + 1, j, octave);
        let c = self.lattice(i, j + 1, octave);
        let d = self.lattice(i + 1, j + 1, octave);
        let top = a + u * (b - a);
        let bottom = c + u * (d - c);
        top + v * (bottom - top)
    }
}

/// SplitMix64: a tiny, well-mixed generator for reproducible test data.
#[derive(Clone, Copy, Debug)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform number in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A standard normal number (Box-Muller).
    pub fn gaussian(&mut self) -> f32 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_image_is_the_left_shifted_by_the_disparity() {
        let scene = SynthScene {
            boxes: vec![],
            disparity_top: 3.0,
            disparity_bottom: 3.0,
            ..SynthScene::textured(64, 8, 1)
        };
        let pair = scene.render().unwrap();
        // An integer disparity: right(x) == left(x + 3).
        for y in 0..8 {
            for x in 0..60 {
                assert!((pair.right.get(x, y) - pair.left.get(x + 3, y)).abs() < 1e-6);
            }
        }
        assert!(pair.disparity.data.iter().all(|&d| d == 3.0));
    }

    #[test]
    fn boxes_occlude_the_background() {
        let scene = SynthScene::textured(128, 64, 2);
        let pair = scene.render().unwrap();
        let b = scene.boxes[0];
        assert_eq!(pair.disparity.get(b.x0, b.y0), b.disparity);
        assert_eq!(pair.disparity.get(0, 0), scene.disparity_top);
        let spread = pair
            .left
            .data
            .iter()
            .fold((1.0f32, 0.0f32), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        assert!(spread.0 >= 0.0 && spread.1 <= 1.0 && spread.1 - spread.0 > 0.5);
    }

    #[test]
    fn saved_pairs_load_back() {
        let dir = tempfile::tempdir().unwrap();
        let pair = SynthScene::textured(40, 20, 4).render().unwrap();
        pair.save(dir.path()).unwrap();
        let sample = SampleDir::open(dir.path()).unwrap();
        assert!(!sample.is_old_pair_layout());
        assert!(SampleDir::is_pair(dir.path()));
        let left = GrayImage::load(&sample.png(Eye::Left)).unwrap();
        assert!(left
            .data
            .iter()
            .zip(&pair.left.data)
            .all(|(a, b)| (a - b).abs() < 1e-4));
        let d = streaks_image::pfm::read_pfm(&sample.disparity(Eye::Left)).unwrap();
        assert_eq!(d, pair.disparity);
        assert!(pair.save(&dir.path().join("missing")).is_err());
    }

    /// Writes a megapixel pair for trying the commands: `STREAKS_SYNTH_DIR=/tmp/synth cargo
    /// test -p streaks-analysis -- --ignored write_megapixel_pair`.
    #[test]
    #[ignore]
    fn write_megapixel_pair() {
        let dir = std::env::var("STREAKS_SYNTH_DIR").unwrap_or_else(|_| "/tmp/synth".into());
        let dir = Path::new(&dir);
        std::fs::create_dir_all(dir).unwrap();
        let scene = SynthScene {
            gain: 0.8,
            noise: 0.005,
            ..SynthScene::textured(1280, 800, 21)
        };
        scene.render().unwrap().save(dir).unwrap();
    }

    #[test]
    fn openexr_images_load_as_linear_luminance() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("l.exr");
        let img =
            ::image::Rgb32FImage::from_fn(4, 2, |x, _| ::image::Rgb([x as f32 * 2.5, 0.0, 0.0]));
        img.save(&path).unwrap();
        let gray = GrayImage::load(&path).unwrap();
        // Rec. 709 red weight times the stored (linear) value.
        assert!((gray.get(3, 1) - 0.212_671 * 7.5).abs() < 1e-5, "{gray:?}");
    }
}
