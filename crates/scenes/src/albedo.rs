//! Albedo textures for the street's surfaces, so that stereo matching finds texture on the
//! road, poles, kerbs, sidewalks and facades: deterministic grey patterns (fine asphalt
//! grain, stone/plaster speckle, brick courses, vertical wood grain) from value noise and a
//! per-texel hash, written as 8-bit grey sRGB PNGs (the glTF baseColorTexture, whose linear
//! value multiplies the material's `kd`). Every pattern but asphalt tiles with repeat
//! wrapping. [`albedo_png`] also returns the texture's mean linear value, by which the caller
//! divides `kd` to keep the surface's mean colour.

use crate::wetness::{hash, tiling_noise};
use crate::Error;
use image::{GrayImage, ImageEncoder};
use streaks_image::color::srgb_oetf;

/// A grey albedo pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pattern {
    /// Fine, high-contrast asphalt grain: light aggregate chips (per texel and in 2-texel
    /// clusters) in dark binder.
    Asphalt,
    /// Stone, plaster or concrete speckle in three octaves.
    Stone,
    /// Running-bond brick courses, 16 x 4 texels per brick with 1-texel mortar joints.
    Brick,
    /// Wood grain: streaks along v (the pole's height), fine across u.
    Wood,
}

/// White noise in [0, 1) at texel (i, j).
fn white(i: u32, j: u32, seed: u32) -> f32 {
    (hash(seed ^ hash(i ^ hash(j))) >> 8) as f32 / (1u32 << 24) as f32
}

/// The pattern's linear value in (0, 1] at texel (i, j) of a `w` x `h` texture.
fn value(pattern: Pattern, i: u32, j: u32, (w, h): (u32, u32), seed: u32) -> f32 {
    let (x, y) = (i as f32 + 0.5, j as f32 + 0.5);
    // Tiling periods in lattice cells of a noise with cell size `cell` texels.
    let period = |cell: u32| ((w / cell) as i32, (h / cell) as i32);
    let noise = |cell: u32, s: u32| {
        tiling_noise(
            x / cell as f32,
            y / cell as f32,
            period(cell),
            seed.wrapping_add(s),
        )
    };
    match pattern {
        Pattern::Asphalt => {
            // Light aggregate chips (about 40 %) in dark binder.
            let chip = 0.6 * white(i, j, seed.wrapping_add(5)) + 0.4 * noise(2, 1) > 0.5;
            let shade = white(i, j, seed);
            if chip {
                0.55 + 0.45 * shade
            } else {
                0.06 + 0.14 * shade
            }
        }
        Pattern::Stone => {
            let n = 0.35 * noise(32, 1) + 0.35 * noise(8, 2) + 0.3 * white(i, j, seed);
            0.35 + 0.65 * n
        }
        Pattern::Brick => {
            let row = j / 4;
            let shifted = i + if row % 2 == 1 { 8 } else { 0 };
            let col = (shifted / 16) % (w / 16).max(1);
            if j % 4 == 3 || shifted % 16 == 15 {
                // Mortar: lighter.
                0.9 + 0.1 * white(i, j, seed)
            } else {
                let brick = white(col, row, seed.wrapping_add(7));
                0.35 + 0.3 * brick + 0.25 * white(i, j, seed) + 0.1 * noise(8, 3)
            }
        }
        Pattern::Wood => {
            let (px, py) = ((w / 4) as i32, (h / 64) as i32);
            let streak = tiling_noise(x / 4.0, y / 64.0, (px, py), seed.wrapping_add(1));
            let fine = white(i, j / 8, seed);
            0.3 + 0.7 * (0.6 * streak + 0.25 * fine + 0.15 * noise(16, 2))
        }
    }
}

/// Linear value to 8-bit sRGB (a texture's encoding, rounded to nearest: not a render's
/// development, which [`streaks_image::develop`] does).
fn encode_srgb(l: f32) -> u8 {
    (srgb_oetf(l.clamp(0.0, 1.0)) * 255.0).round() as u8
}

/// 8-bit sRGB to linear (the glTF loader's decoding).
fn decode_srgb(b: u8) -> f64 {
    let s = f64::from(b) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// The `w` x `h` grey sRGB PNG of `pattern` and its mean linear value (of the stored,
/// quantised texels).
pub fn albedo_png(
    pattern: Pattern,
    (w, h): (u32, u32),
    seed: u32,
) -> Result<(Vec<u8>, f64), Error> {
    let mut img = GrayImage::new(w, h);
    let mut sum = 0.0;
    for (i, j, p) in img.enumerate_pixels_mut() {
        let b = encode_srgb(value(pattern, i, j, (w, h), seed));
        sum += decode_srgb(b);
        p.0 = [b];
    }
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(img.as_raw(), w, h, image::ExtendedColorType::L8)
        .map_err(|e| Error::Texture(e.to_string()))?;
    Ok((png, sum / f64::from(w * h)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_have_contrast_and_sensible_means() {
        for pattern in [
            Pattern::Asphalt,
            Pattern::Stone,
            Pattern::Brick,
            Pattern::Wood,
        ] {
            let (png, mean) = albedo_png(pattern, (64, 64), 3).unwrap();
            assert!(mean > 0.3 && mean < 0.85, "{pattern:?}: mean {mean}");
            let img = image::load_from_memory(&png).unwrap().to_luma8();
            assert_eq!(img.dimensions(), (64, 64));
            // Neighbouring texels across u differ: texture for horizontal stereo matching.
            let diff: f64 = img
                .enumerate_pixels()
                .filter(|(i, _, _)| *i > 0)
                .map(|(i, j, p)| {
                    (decode_srgb(p.0[0]) - decode_srgb(img.get_pixel(i - 1, j).0[0])).abs()
                })
                .sum::<f64>()
                / (63.0 * 64.0);
            assert!(diff > 0.03 * mean, "{pattern:?}: mean |du| {diff}");
        }
    }

    #[test]
    fn tiling_patterns_wrap_without_a_seam() {
        // The step across the wrap (last column to first) is like an ordinary step.
        for pattern in [Pattern::Stone, Pattern::Wood] {
            let (w, h) = (64, 128);
            let v = |i, j| value(pattern, i, j, (w, h), 5);
            let wrap: f32 = (0..h).map(|j| (v(w - 1, j) - v(0, j)).abs()).sum();
            let inner: f32 = (0..h).map(|j| (v(w / 2 - 1, j) - v(w / 2, j)).abs()).sum();
            assert!(wrap < 2.0 * inner + 1.0, "{pattern:?}: {wrap} vs {inner}");
        }
    }

    #[test]
    fn srgb_round_trips() {
        for k in 0..=255u8 {
            assert_eq!(encode_srgb(decode_srgb(k) as f32), k);
        }
    }
}
