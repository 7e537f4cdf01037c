//! The street's surface materials: brick, plaster, concrete and stone walls, setts, paving
//! slabs and asphalt, each an albedo [`Pattern`] with a mean albedo in the range measured on
//! real surfaces; how such surfaces change when wet; dark window glass; and the tiling that
//! keeps a texture from repeating visibly over a facade.
//!
//! - **Albedo.** A surface's diffuse colour `kd` is drawn within its measured range
//!   ([`Surface::albedo`]) and divided by the texture's mean, so the textured surface's mean
//!   albedo is `kd`.
//! - **Wetness.** A wet porous surface darkens because light that enters the water film is
//!   partly reflected back down at the water-air interface and meets the surface again
//!   ([`wet_albedo`], Lekner and Dorf 1988), and its water film adds a smooth specular
//!   reflection ([`wet_paper`]).
//! - **Tiling.** [`scatter_uvs`] gives every quad of a mesh texture coordinates from its
//!   position in its plane plus its own random offset, quantised to the pattern's cell (a
//!   brick, a slab) so that joints stay aligned across neighbouring quads. A facade built
//!   from panels no wider than a tile then never shows the same texel twice at the tile's
//!   period.

use crate::albedo::{albedo_png, Pattern};
use crate::gltf_writer::{round7, Doc, Dryness, Material, PaperBsdf, Reflect};
use crate::mesh::Mesh;
use crate::wetness::hash;
use crate::Error;
use glam::{Vec2, Vec3};
use image::{ImageEncoder, RgbImage};

/// Refractive index of water.
pub const WATER_N: f64 = 1.333;
/// Reflectance of a water surface for diffuse (uniform hemispherical) illumination from the
/// air, the hemispherical average of Fresnel's reflectance at n = 1.333 (Lekner and Dorf
/// 1988 use 0.066 for water).
pub const WATER_R_EXTERNAL: f64 = 0.066;
/// Microfacet alpha of a water film on a wall or pavement: smooth, with the slight waviness
/// of a film that follows the surface.
pub const WATER_ALPHA: f64 = 0.03;

/// Reflectance of the water-air interface for diffuse light from inside the water:
/// `1 - (1 - r_external) / n^2` (the light inside beyond the critical angle is totally
/// reflected).
pub fn water_r_internal() -> f64 {
    1.0 - (1.0 - WATER_R_EXTERNAL) / (WATER_N * WATER_N)
}

/// The diffuse albedo of a surface of dry albedo `a` under a water film (Lekner, J. and
/// Dorf, M. C., "Why some things are darker when wet", Applied Optics 27(7), 1988):
/// `(1 - r_e) (1 - r_i) a / (1 - r_i a)`, with `r_e` the film's external and `r_i` its
/// internal diffuse reflectance. The film's own (specular) reflection `r_e` is not included:
/// [`wet_paper`] adds it as `ks`. A grey surface of albedo 0.3 drops to 0.17 when wet.
pub fn wet_albedo(a: f64) -> f64 {
    let ri = water_r_internal();
    (1.0 - WATER_R_EXTERNAL) * (1.0 - ri) * a / (1.0 - ri * a)
}

/// `material` at wetness `wetness` in [0, 1] (0 dry, 1 soaked with a continuous water
/// film): kd moves from dry towards [`wet_albedo`] (per channel), ks towards the film's
/// [`WATER_R_EXTERNAL`] when that is larger, and alpha geometrically towards the film's
/// [`WATER_ALPHA`]. Kerbs, markings, walls and pavements share this one law. Emitters and
/// non-paper materials are returned unchanged; the name gets a `_wet` suffix when wet.
pub fn wet_paper(material: &Material, wetness: f32) -> Material {
    let w = f64::from(wetness.clamp(0.0, 1.0));
    let mut m = material.clone();
    if w == 0.0 {
        return m;
    }
    if let Reflect::Paper { bsdf, kd, ks, .. } = &mut m.reflect {
        *kd = kd.map(|k| round7(k + (wet_albedo(k) - k) * w));
        *ks = ks.map(|k| round7(k + (WATER_R_EXTERNAL - k).max(0.0) * w));
        let wet_alpha = |a: f64| round7(a.powf(1.0 - w) * WATER_ALPHA.powf(w));
        match bsdf {
            PaperBsdf::Ggx { alpha } | PaperBsdf::Ward { alpha } => {
                *alpha = wet_alpha(*alpha).min(*alpha);
            }
            PaperBsdf::BlinnPhong { shininess } => {
                // Blinn-Phong s ~ 2 / alpha^2 - 2.
                let a = wet_alpha((2.0 / (*shininess + 2.0)).sqrt());
                *shininess = round7((2.0 / (a * a) - 2.0).max(*shininess));
            }
        }
        m.name = format!("{}_wet", m.name);
    }
    m
}

/// The bond of a brick wall.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Bond {
    /// Running (stretcher) bond: every brick shows its long side, courses offset by half.
    Stretcher,
    /// English bond: stretcher and header courses alternate.
    English,
    /// Flemish bond: stretchers and headers alternate within every course.
    Flemish,
}

/// A kind of surface with a texture and a measured albedo range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Surface {
    /// A brick wall.
    Brick(Bond),
    /// Painted or plain render (plaster) on a wall.
    Plaster,
    /// Cast concrete.
    Concrete,
    /// Dressed stone (ashlar) or stone cladding.
    Stone,
    /// Stone setts (cobbles) on a pavement or square.
    Setts,
    /// Concrete paving slabs.
    Slabs,
    /// Old asphalt with patches and tar seams.
    Asphalt,
}

impl Surface {
    /// Every wall surface.
    pub const WALLS: [Surface; 6] = [
        Surface::Brick(Bond::Stretcher),
        Surface::Brick(Bond::English),
        Surface::Brick(Bond::Flemish),
        Surface::Plaster,
        Surface::Concrete,
        Surface::Stone,
    ];

    /// A short name (texture file suffix and material name).
    pub fn name(self) -> &'static str {
        match self {
            Surface::Brick(Bond::Stretcher) => "brick_stretcher",
            Surface::Brick(Bond::English) => "brick_english",
            Surface::Brick(Bond::Flemish) => "brick_flemish",
            Surface::Plaster => "plaster",
            Surface::Concrete => "concrete",
            Surface::Stone => "stone",
            Surface::Setts => "setts",
            Surface::Slabs => "slabs",
            Surface::Asphalt => "asphalt",
        }
    }

    /// Its albedo pattern.
    pub fn pattern(self) -> Pattern {
        match self {
            Surface::Brick(Bond::Stretcher) => Pattern::Brick,
            Surface::Brick(Bond::English) => Pattern::EnglishBrick,
            Surface::Brick(Bond::Flemish) => Pattern::FlemishBrick,
            Surface::Plaster => Pattern::Plaster,
            Surface::Concrete => Pattern::Concrete,
            Surface::Stone => Pattern::Stone,
            Surface::Setts => Pattern::Setts,
            Surface::Slabs => Pattern::Slabs,
            Surface::Asphalt => Pattern::PatchedAsphalt,
        }
    }

    /// Texture size in texels (u, v): 256 x 256, but 240 wide for Flemish bond, whose
    /// stretcher-header unit is 24 texels.
    pub fn texels(self) -> (u32, u32) {
        match self {
            Surface::Brick(Bond::Flemish) => (240, 256),
            _ => (256, 256),
        }
    }

    /// Metres per texel: bricks 1.5 cm (a 16-texel stretcher with its joint is 24 cm, a
    /// course 6 cm), setts 0.625 cm (10 cm setts), slabs 1 cm (64 cm slabs), the others 2 cm.
    pub fn texel_m(self) -> f32 {
        match self {
            Surface::Brick(_) => 0.015,
            Surface::Setts => 0.00625,
            Surface::Slabs => 0.01,
            _ => 0.02,
        }
    }

    /// The size of one texture tile on the surface, metres (u, v).
    pub fn tile_m(self) -> Vec2 {
        let (w, h) = self.texels();
        Vec2::new(w as f32, h as f32) * self.texel_m()
    }

    /// The pattern's cell in texels (u, v): texture offsets are multiples of it so that
    /// joints line up across neighbouring quads (a brick and two courses, a sett and two
    /// rows, a slab, a formwork panel; one texel for patterns without joints).
    pub fn cell(self) -> (u32, u32) {
        match self {
            Surface::Brick(Bond::Flemish) => (24, 8),
            Surface::Brick(_) => (16, 8),
            Surface::Setts => (16, 32),
            Surface::Slabs | Surface::Concrete => (64, 64),
            _ => (1, 1),
        }
    }

    /// The range of mean (dry) albedo of real surfaces of this kind, from measurements:
    /// - brick 0.20-0.40, stone 0.20-0.35: Oke, T. R., "Boundary Layer Climates", 2nd ed.,
    ///   1987, Table 8.2 (radiative properties of urban materials);
    /// - asphalt 0.05-0.12: fresh asphalt about 0.05, aged and worn 0.10-0.12 (Pomerantz,
    ///   M. et al., "Examples of cooler reflective streets for urban heat-island mitigation",
    ///   LBNL-49283, 2003; Oke's table spans 0.05-0.20);
    /// - concrete 0.30-0.40: Portland cement concrete as built and weathered (Levinson, R.
    ///   and Akbari, H., "Effects of composition and exposure on the solar reflectance of
    ///   Portland cement concrete", Cement and Concrete Research 32, 2002);
    /// - concrete paving slabs 0.25-0.40, a little darker than walls from wear and dirt;
    /// - setts (granite) 0.15-0.30;
    /// - plaster and render 0.30-0.60: painted renders in the usual light, earthy colours
    ///   (Oke: whitewash 0.50-0.90, which the dirt of a city street lowers).
    pub fn albedo(self) -> [f64; 2] {
        match self {
            Surface::Brick(_) => [0.2, 0.4],
            Surface::Stone => [0.2, 0.35],
            Surface::Asphalt => [0.05, 0.12],
            Surface::Concrete => [0.3, 0.4],
            Surface::Slabs => [0.25, 0.4],
            Surface::Setts => [0.15, 0.3],
            Surface::Plaster => [0.3, 0.6],
        }
    }

    /// The dry surface's specular reflectance and microfacet alpha: rough dielectrics with
    /// a weak, broad sheen.
    pub fn dry_gloss(self) -> (f64, f64) {
        match self {
            Surface::Asphalt => (0.04, 0.35),
            Surface::Concrete | Surface::Slabs => (0.03, 0.4),
            Surface::Setts | Surface::Stone => (0.03, 0.3),
            Surface::Brick(_) | Surface::Plaster => (0.02, 0.45),
        }
    }

    /// The chromaticity of the surface's colour as linear RGB with luminance 1, chosen by
    /// `hue` in [0, 1): red, brown and yellow bricks; ochre, cream, grey and pink renders;
    /// grey concrete and stone; sandstone and granite.
    pub fn tint(self, hue: f64) -> [f64; 3] {
        let palette: &[[f64; 3]] = match self {
            Surface::Brick(_) => &[[1.9, 0.75, 0.5], [1.55, 0.9, 0.7], [1.3, 1.0, 0.6]],
            Surface::Plaster => &[
                [1.25, 1.0, 0.7],
                [1.1, 1.0, 0.85],
                [1.0, 1.0, 1.0],
                [1.3, 0.92, 0.85],
                [0.9, 1.02, 1.05],
            ],
            Surface::Concrete | Surface::Slabs | Surface::Asphalt => {
                &[[1.0, 1.0, 1.0], [1.05, 1.0, 0.92]]
            }
            Surface::Stone | Surface::Setts => &[[1.2, 1.0, 0.75], [1.0, 1.0, 1.0]],
        };
        let c = palette[((hue * palette.len() as f64) as usize).min(palette.len() - 1)];
        // Normalise to luminance 1 (Rec. 709 weights).
        let y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        c.map(|k| k / y)
    }
}

/// One surface's albedo texture added to a document.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texture {
    /// The surface.
    pub surface: Surface,
    /// Image index in the document ([`Doc::add_png`]).
    pub image: usize,
    /// The texture's mean linear value.
    pub mean: f64,
}

impl Texture {
    /// Generates `surface`'s texture with `seed` and adds it to `doc` as `NAME_SURFACE.png`.
    pub fn add(doc: &mut Doc, surface: Surface, seed: u32) -> Result<Self, Error> {
        let (png, mean) = albedo_png(surface.pattern(), surface.texels(), seed)?;
        Ok(Self {
            surface,
            image: doc.add_png(surface.name(), png),
            mean,
        })
    }

    /// A dry paper material of mean albedo `kd` (linear RGB) with this texture. glTF's
    /// base colour factor is at most 1, so a channel brighter than the texture's mean gets
    /// the texture as it is (its mean, within a few per cent for the drawn albedos).
    pub fn material(&self, name: &str, kd: [f64; 3]) -> Material {
        let (ks, alpha) = self.surface.dry_gloss();
        Material::paper(
            name,
            PaperBsdf::Ggx { alpha },
            kd.map(|k| round7((k / self.mean).min(1.0))),
            [ks; 3],
        )
        .with_albedo(self.image)
    }
}

/// Dark window glass: a black diffuse term and the smooth specular reflection of float
/// glass seen from the street (about 0.08 averaged over the street's grazing angles; 0.04
/// at normal incidence), so that windows mirror the lamps and the sky glow. Rain on the pane
/// leaves it a little rougher, not darker.
pub fn glass(name: &str, wetness: f32) -> Material {
    let alpha = 0.01 + 0.03 * f64::from(wetness.clamp(0.0, 1.0));
    Material::paper(
        name,
        PaperBsdf::Ggx {
            alpha: round7(alpha),
        },
        [0.008; 3],
        [0.08; 3],
    )
}

/// The sidewalk's material: `surface` (setts or slabs; any [`Surface`] works) of mean albedo
/// `kd` with the albedo texture `texture`, at wetness `wetness` (see [`wet_paper`]); when
/// wet, puddles too: a dryness map (`NAME_SURFACE_puddles.png`, the texture's size and
/// texture coordinates) is 0 (a water film, [`WATER_R_EXTERNAL`], [`WATER_ALPHA`]) in
/// puddles that cover more of the pavement the wetter it is, and 1 (the damp surface) elsewhere.
/// Returns the material; the caller applies [`scatter_uvs`] with `texture.surface` to its mesh.
pub fn sidewalk_material(
    doc: &mut Doc,
    texture: &Texture,
    kd: [f64; 3],
    wetness: f32,
    seed: u32,
) -> Result<Material, Error> {
    let damp = wet_paper(&texture.material("sidewalk", kd), wetness);
    if wetness <= 0.2 {
        return Ok(damp);
    }
    let (png, _) = puddle_png(
        texture.surface.texels(),
        texture.surface.tile_m(),
        wetness,
        seed,
    )?;
    let image = doc.add_png(&format!("{}_puddles", texture.surface.name()), png);
    let Reflect::Paper {
        bsdf: PaperBsdf::Ggx { alpha },
        ks,
        ..
    } = damp.reflect.clone()
    else {
        return Ok(damp);
    };
    let mut m = damp;
    if let Reflect::Paper {
        bsdf: PaperBsdf::Ggx { alpha: a },
        ks: k,
        ..
    } = &mut m.reflect
    {
        *a = WATER_ALPHA;
        *k = [WATER_R_EXTERNAL.max(ks[0]); 3];
    }
    Ok(m.with_dryness(Dryness {
        image,
        alpha_dry: alpha,
        ks_dry: ks,
    }))
}

/// The puddle share of a pavement at wetness `wetness`: none below 0.2, rising to 30 % when
/// soaked.
pub fn puddle_share(wetness: f32) -> f32 {
    (0.3 * (wetness - 0.2) / 0.8).clamp(0.0, 0.3)
}

/// The dryness map of a wet pavement tile of `size` texels covering `tile_m` metres: value
/// noise with ~0.8 m features thresholded so that [`puddle_share`] of it is water (w = 0),
/// with a soft 1-2 texel edge. Tiles with the texture (the noise wraps at the tile).
/// Returns the PNG and the measured puddle share.
pub fn puddle_png(
    (w, h): (u32, u32),
    tile_m: Vec2,
    wetness: f32,
    seed: u32,
) -> Result<(Vec<u8>, f32), Error> {
    let share = puddle_share(wetness);
    let cells = (
        (tile_m.x / 0.8).round().max(1.0) as i32,
        (tile_m.y / 0.8).round().max(1.0) as i32,
    );
    let field = |i: u32, j: u32| {
        let (x, y) = (
            (i as f32 + 0.5) / w as f32 * cells.0 as f32,
            (j as f32 + 0.5) / h as f32 * cells.1 as f32,
        );
        0.7 * crate::wetness::tiling_noise(x, y, cells, seed)
            + 0.3
                * crate::wetness::tiling_noise(
                    2.0 * x,
                    2.0 * y,
                    (2 * cells.0, 2 * cells.1),
                    seed ^ 0x51,
                )
    };
    // The threshold below which `share` of the texels lie.
    let mut values: Vec<f32> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| field(i, j))
        .collect();
    values.sort_by(f32::total_cmp);
    let k = ((share * values.len() as f32) as usize).min(values.len() - 1);
    let threshold = if share > 0.0 {
        values[k]
    } else {
        f32::NEG_INFINITY
    };
    let mut img = RgbImage::new(w, h);
    let mut wet = 0usize;
    for (i, j, p) in img.enumerate_pixels_mut() {
        let d = ((field(i, j) - threshold) / 0.01).clamp(0.0, 1.0);
        wet += usize::from(d < 0.5);
        p.0 = [0, (d * 255.0).round() as u8, 0];
    }
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(img.as_raw(), w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::Texture(e.to_string()))?;
    Ok((png, wet as f32 / (w * h) as f32))
}

/// Gives each quad (four consecutive vertices, as [`Mesh::quad_uv`], [`Mesh::rect`] and
/// [`Mesh::cuboid`] add them) of `mesh` texture coordinates in tiles of `surface`'s texture:
/// its vertices' positions in the quad's plane (u horizontal, v down; on horizontal quads u
/// along X and v along Z) divided by [`Surface::tile_m`], plus an offset drawn per quad from
/// `seed` and the quad's index, a whole number of [`Surface::cell`]s. Meshes whose vertex
/// count is not a multiple of four keep their last vertices' coordinates.
pub fn scatter_uvs(mesh: &mut Mesh, surface: Surface, seed: u32) {
    let tile = surface.tile_m();
    let (w, h) = surface.texels();
    let (cu, cv) = surface.cell();
    let (nu, nv) = ((w / cu).max(1), (h / cv).max(1));
    for (q, (pos, uvs)) in mesh
        .positions
        .chunks_exact(4)
        .zip(mesh.uvs.chunks_exact_mut(4))
        .enumerate()
    {
        let n = (pos[1] - pos[0]).cross(pos[2] - pos[0]);
        let (tu, tv) = if n.y.abs() > 0.9 * n.length() {
            (Vec3::X, Vec3::Z)
        } else {
            (Vec3::Y.cross(n).normalize_or_zero(), -Vec3::Y)
        };
        let r = hash(seed ^ hash(q as u32 ^ 0x2c1b_3c6d));
        let offset = Vec2::new(
            ((r % nu) * cu) as f32 / w as f32,
            (((r >> 16) % nv) * cv) as f32 / h as f32,
        );
        for (p, t) in pos.iter().zip(uvs.iter_mut()) {
            *t = Vec2::new(p.dot(tu) / tile.x, p.dot(tv) / tile.y) + offset;
        }
    }
}

/// A uniform number in [0, 1) from `seed` and `k` (for per-element choices in meshes).
pub fn unit(seed: u32, k: u32) -> f32 {
    (hash(seed ^ hash(k.wrapping_add(0x68e3_1da4))) >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn water_film_darkens_as_lekner_and_dorf_predict() {
        let ri = water_r_internal();
        // Reciprocity: 1 - r_i = (1 - r_e) / n^2.
        assert!((ri - 0.4744).abs() < 2e-3, "{ri}");
        // A white surface under water loses exactly the film's own reflection.
        assert!((wet_albedo(1.0) - (1.0 - WATER_R_EXTERNAL)).abs() < 1e-12);
        // Black stays black; a = 0.3 by hand: 0.934 * 0.5256 * 0.3 / (1 - 0.4744 * 0.3).
        assert_eq!(wet_albedo(0.0), 0.0);
        let by_hand = 0.934 * (1.0 - 0.474_4) * 0.3 / (1.0 - 0.474_4 * 0.3);
        assert!(
            (wet_albedo(0.3) - by_hand).abs() < 2e-3,
            "{}",
            wet_albedo(0.3)
        );
        // Dark surfaces darken relatively more than light ones (wet asphalt vs wet render).
        assert!(wet_albedo(0.08) / 0.08 < wet_albedo(0.5) / 0.5);
    }

    #[test]
    fn wet_paper_darkens_and_smooths_and_leaves_dry_alone() {
        let dry = Material::paper(
            "wall",
            PaperBsdf::Ggx { alpha: 0.4 },
            [0.3, 0.2, 0.1],
            [0.02; 3],
        );
        assert_eq!(wet_paper(&dry, 0.0), dry);
        let wet = wet_paper(&dry, 1.0);
        let Reflect::Paper {
            bsdf: PaperBsdf::Ggx { alpha },
            kd,
            ks,
            ..
        } = wet.reflect
        else {
            panic!("paper")
        };
        assert!((kd[0] - wet_albedo(0.3)).abs() < 1e-6);
        assert!((ks[0] - WATER_R_EXTERNAL).abs() < 1e-6);
        assert!((alpha - WATER_ALPHA).abs() < 1e-6);
        let emitter = Material::emitter("sign", [5.0; 3]);
        assert_eq!(wet_paper(&emitter, 1.0), emitter);
    }

    #[test]
    fn surfaces_have_their_measured_mean_albedo() {
        // kd is divided by the texture's mean: the rendered mean is the drawn albedo, which
        // lies in the measured range for every tint.
        let mut doc = Doc::new("t", "t");
        for s in
            Surface::WALLS
                .into_iter()
                .chain([Surface::Setts, Surface::Slabs, Surface::Asphalt])
        {
            let t = Texture::add(&mut doc, s, 7).unwrap();
            let (png, _) = albedo_png(s.pattern(), s.texels(), 7).unwrap();
            let img = image::load_from_memory(&png).unwrap().to_luma8();
            let texels: Vec<f64> = img.pixels().map(|p| srgb_to_linear(p.0[0])).collect();
            let measured = texels.iter().sum::<f64>() / texels.len() as f64;
            assert!((measured - t.mean).abs() < 1e-9, "{s:?}");
            for a in [s.albedo()[0], s.albedo()[1]] {
                for hue in [0.0, 0.5, 0.99] {
                    let kd = s.tint(hue).map(|c| c * a);
                    let m = t.material("m", kd);
                    let Reflect::Paper { kd: k, .. } = m.reflect else {
                        panic!()
                    };
                    let y = 0.2126 * k[0] + 0.7152 * k[1] + 0.0722 * k[2];
                    let mean = y * measured;
                    let [lo, hi] = s.albedo();
                    assert!(mean > lo - 1e-3 && mean < hi + 1e-3, "{s:?}: {mean}");
                }
            }
            // A texture with contrast: the standard deviation is at least 5 % of the mean.
            let var =
                texels.iter().map(|v| (v - measured).powi(2)).sum::<f64>() / texels.len() as f64;
            assert!(var.sqrt() > 0.05 * measured, "{s:?}: sd {}", var.sqrt());
        }
    }

    fn srgb_to_linear(b: u8) -> f64 {
        let s = f64::from(b) / 255.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    }

    #[test]
    fn puddles_cover_the_share_the_wetness_asks_for() {
        assert_eq!(puddle_share(0.1), 0.0);
        for wetness in [0.5f32, 1.0] {
            let (_, share) = puddle_png((128, 128), Vec2::splat(2.56), wetness, 3).unwrap();
            assert!(
                (share - puddle_share(wetness)).abs() < 0.02,
                "{wetness}: {share}"
            );
        }
    }

    #[test]
    fn scattered_uvs_keep_joints_aligned_and_vary_between_quads() {
        let s = Surface::Brick(Bond::Stretcher);
        let mut m = Mesh::new();
        for k in 0..8 {
            let z = -(k as f32) * 1.5;
            m.rect(Vec3::new(0.0, 2.0, z), Vec3::Z * 0.75, Vec3::Y);
        }
        scatter_uvs(&mut m, s, 9);
        let (w, h) = s.texels();
        let (cu, cv) = s.cell();
        let mut offsets = std::collections::BTreeSet::new();
        for (pos, uv) in m.positions.chunks_exact(4).zip(m.uvs.chunks_exact(4)) {
            for (p, t) in pos.iter().zip(uv) {
                // Texel coordinates minus the position's are whole cells.
                let du = t.x * w as f32 - p.z / s.texel_m();
                let dv = t.y * h as f32 - (-p.y) / s.texel_m();
                let (ru, rv) = (du / cu as f32, dv / cv as f32);
                assert!((ru - ru.round()).abs() < 1e-2 && (rv - rv.round()).abs() < 1e-2);
                offsets.insert((du.round() as i32, dv.round() as i32));
            }
        }
        assert!(offsets.len() >= 6, "{offsets:?}");
    }
}
