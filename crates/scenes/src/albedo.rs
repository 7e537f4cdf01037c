//! Albedo textures for the street's surfaces, so that stereo matching finds texture on the
//! road, poles, kerbs, sidewalks and facades: deterministic grey patterns (fine asphalt
//! grain, patched asphalt with tar seams, stone speckle, setts, paving slabs, brick in three
//! bonds, weathered plaster, formwork concrete, vertical wood grain) from value noise and a
//! per-texel hash, written as 8-bit grey sRGB PNGs (the glTF baseColorTexture, whose linear
//! value multiplies the material's `kd`). Every pattern but asphalt tiles with repeat
//! wrapping. [`crate::surfaces`] gives them measured albedos and non-repeating tiling. [`albedo_png`] also returns the texture's mean linear value, by which the caller
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
    /// Asphalt grain (as [`Pattern::Asphalt`]) with the wear of an old road: darker, finer
    /// repair patches on a 64-texel grid and meandering black tar seams (sealed cracks).
    PatchedAsphalt,
    /// Stone setts (cobbles) 16 x 16 texels in rows offset by half a sett, domed (darker at
    /// their edges), each its own tone, in dark 2-texel joints.
    Setts,
    /// Paving slabs 64 x 64 texels with 1-texel joints, each slab its own tone and speckle,
    /// some stained.
    Slabs,
    /// English bond brick: courses of stretchers (16 x 4 texels) alternating with courses
    /// of headers (8 x 4), 1-texel mortar joints.
    EnglishBrick,
    /// Flemish bond brick: stretchers (16 texels) and headers (8) alternating in every course,
    /// each course shifted by 12 texels; the texture's width must be a multiple of 24.
    FlemishBrick,
    /// Plaster or render, weathered: smooth low-contrast trowel texture, vertical dirt
    /// runs and blotchy stains.
    Plaster,
    /// Cast concrete: fine pores and speckle on formwork panels of 64 x 64 texels, with
    /// darker panel joints and tie holes.
    Concrete,
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
        Pattern::PatchedAsphalt => {
            let grain = value(Pattern::Asphalt, i, j, (w, h), seed);
            // A repair patch in one 64-texel cell of seven: fresh, finer and darker binder.
            let (ci, cj) = (i / 64, j / 64);
            let cell = hash(seed ^ hash(ci ^ hash(cj.wrapping_add(0x5bd1))));
            let (pi, pj) = (i % 64, j % 64);
            let (x0, y0) = (4 + cell % 12, 4 + (cell >> 4) % 12);
            let (x1, y1) = (40 + (cell >> 8) % 20, 40 + (cell >> 12) % 20);
            let patched = cell % 7 == 0 && (x0..x1).contains(&pi) && (y0..y1).contains(&pj);
            // Tar seams: where smooth noise crosses one level, a line about 2 texels wide.
            let seam = (noise(32, 9) - 0.5).abs() < 0.012;
            if seam {
                0.03 + 0.02 * white(i, j, seed.wrapping_add(3))
            } else if patched {
                0.6 * grain + 0.04
            } else {
                grain
            }
        }
        Pattern::Setts => {
            let row = j / 16;
            let shifted = i + if row % 2 == 1 { 8 } else { 0 };
            let (col, pi, pj) = (shifted / 16 % (w / 16).max(1), shifted % 16, j % 16);
            if pi < 2 || pj < 2 {
                // Joints: dark sand and grit.
                0.12 + 0.08 * white(i, j, seed)
            } else {
                let (dx, dy) = ((pi as f32 - 8.5) / 7.0, (pj as f32 - 8.5) / 7.0);
                let dome = 1.0 - 0.35 * (dx * dx + dy * dy).min(1.0);
                let tone = white(col, row, seed.wrapping_add(7));
                dome * (0.45 + 0.3 * tone + 0.15 * white(i, j, seed) + 0.1 * noise(4, 4))
            }
        }
        Pattern::Slabs => {
            let (col, row) = (i / 64, j / 64);
            if i % 64 == 63 || j % 64 == 63 {
                0.25 + 0.1 * white(i, j, seed)
            } else {
                let tone = white(col, row, seed.wrapping_add(7));
                let stain = if hash(seed ^ hash(col ^ hash(row.wrapping_add(77)))) % 5 == 0 {
                    0.75 + 0.25 * noise(16, 6)
                } else {
                    1.0
                };
                stain * (0.5 + 0.2 * tone + 0.15 * noise(8, 2) + 0.15 * white(i, j, seed))
            }
        }
        Pattern::EnglishBrick | Pattern::FlemishBrick => {
            let row = j / 4;
            // (brick index, position in the brick, brick length) along the course.
            let (brick, at, len) = if pattern == Pattern::EnglishBrick {
                if row % 2 == 0 {
                    (i / 16, i % 16, 16)
                } else {
                    // Headers, shifted by a quarter stretcher (the queen closer), wrapping.
                    let s = i + 4;
                    ((s / 8) % (w / 8).max(1), s % 8, 8)
                }
            } else {
                let s = (i + if row % 2 == 1 { 12 } else { 0 }) % w.max(1);
                let (unit, k) = (s / 24, s % 24);
                if k < 16 {
                    (2 * unit, k, 16)
                } else {
                    (2 * unit + 1, k - 16, 8)
                }
            };
            if j % 4 == 3 || at == len - 1 {
                0.9 + 0.1 * white(i, j, seed)
            } else {
                let b = white(brick, row, seed.wrapping_add(7));
                // Headers (burnt ends) are darker.
                let burnt = if len == 8 { 0.8 } else { 1.0 };
                burnt * (0.35 + 0.3 * b + 0.25 * white(i, j, seed) + 0.1 * noise(8, 3))
            }
        }
        Pattern::Plaster => {
            let trowel = 0.5 * noise(32, 1) + 0.3 * noise(8, 2) + 0.2 * white(i, j, seed);
            // Dirt runs: noise stretched 16x along v, kept only where it is high.
            let (px, py) = ((w / 4).max(1) as i32, (h / 64).max(1) as i32);
            let run = tiling_noise(x / 4.0, y / 64.0, (px, py), seed.wrapping_add(11));
            let runs = ((run - 0.6) / 0.4).max(0.0);
            let stain = ((noise(64, 12) - 0.55) / 0.45).max(0.0);
            (0.8 + 0.2 * trowel) * (1.0 - 0.35 * runs) * (1.0 - 0.3 * stain)
        }
        Pattern::Concrete => {
            let (pi, pj) = (i % 64, j % 64);
            let joint = pi == 0 || pj == 0;
            let tie = [16u32, 48].iter().any(|&c| pi.abs_diff(c) <= 1)
                && [16u32, 48].iter().any(|&c| pj.abs_diff(c) <= 1);
            let pore = white(i, j, seed.wrapping_add(13)) > 0.985;
            let base = 0.6 + 0.15 * noise(32, 1) + 0.1 * noise(4, 2) + 0.15 * white(i, j, seed);
            if tie || pore {
                0.3 * base
            } else if joint {
                0.75 * base
            } else {
                base
            }
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
        // The step across the wrap (last column to first) is like the step across the middle
        // (also a joint of setts, slabs and formwork panels, whose cells divide half the width).
        for pattern in [
            Pattern::Stone,
            Pattern::Wood,
            Pattern::Plaster,
            Pattern::Concrete,
            Pattern::Setts,
            Pattern::Slabs,
            Pattern::PatchedAsphalt,
        ] {
            let (w, h) = (128, 128);
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
