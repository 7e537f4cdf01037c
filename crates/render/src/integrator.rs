//! Unidirectional path tracing with next-event estimation and multiple importance sampling.
//!
//! At every surface vertex the path tracer
//!
//! 1. adds the emission of the surface it hit (seen directly: in full; reached by a BSDF
//!    sample: weighted by the power heuristic against light sampling),
//! 2. samples one light with the [`LightSampler`] and one point or direction on it (next-event
//!    estimation): a point is tested with a shadow ray, a direction toward a compact emitter
//!    ([`crate::light::Visibility::FirstHit`]) with a closest-hit ray that must land on that
//!    emitter; area lights are weighted by the power heuristic against BSDF sampling, delta
//!    lights (point, spot, directional) cannot be hit by BSDF samples and are added unweighted,
//! 3. samples the BSDF for the next direction.
//!
//! A ray that escapes the scene adds the environment light's radiance
//! ([`crate::light::Environment`]) the way a hit emitter adds its emission: in full for a
//! camera ray or after a delta lobe, else weighted against the light choice's density of that
//! direction; next-event estimation samples the environment as one more choice of the
//! [`LightSampler`], with a shadow ray that must escape. A ray inside a volume adds nothing.
//!
//! `max_depth` has Mitsuba 3's meaning (`path.cpp`): the longest path, counted in segments
//! from the camera; 1 renders only emitters seen directly, 2 direct illumination, 3 one
//! indirect bounce, and so on; `u32::MAX` means no limit. Russian roulette uses Mitsuba's
//! survival rule, but from depth [`RR_DEPTH`] = 3 (Mitsuba's default is 5): from the
//! segment after the first indirect bounce on, a path survives with probability
//! `q = min(max component of the throughput, 0.95)` and its throughput is divided by `q`,
//! which keeps the estimate unbiased while ending paths whose contribution has become small.
//! On a night street the light of the second and later indirect bounces is about 1% of the
//! image and paths through them were a third of the work; starting at 3 instead of 5 took
//! 20-30% off a render's time and added under 0.5% to its error at equal samples
//! (docs/decisions/0009-russian-roulette-from-depth-3.md).
//!
//! Shading uses the interpolated shading normal's frame (through the material's normal map, if
//! any: [`crate::normal_map`]); a direction must also lie on the same side of the *geometric*
//! normal as of the shading normal (for both light samples and BSDF samples): above both for
//! reflection, below both for transmission, so that interpolated or perturbed normals never
//! let light leak through a surface (such samples are dropped, as Mitsuba drops them). On a
//! normal-mapped hit the diffuse part of the BSDF takes its cosine about the map's own normal,
//! softened by Cycles' bump shadowing, and the glossy and transmitted parts the corrected
//! normal's ([`crate::normal_map::MappedNormal`]). Surfaces reflect on both faces (the frame is flipped toward the viewer); emission is
//! one-sided unless the material is double-sided.
//!
//! Transmission (a transmissive glTF material, [`crate::bsdf::GltfPbr`]): a sampled direction
//! below the surface continues the path through it, from an origin offset to the side it
//! leaves from; next-event estimation evaluates the rough transmission toward lights behind a
//! thin-walled surface like any lobe (the light choice weighs them by irradiance alone, its
//! BSDF-aware share looking at reflection only). A smooth surface's transmission is a delta
//! lobe: light sampling cannot produce it, so an emitter hit after it counts in full (no MIS),
//! and shadow rays are not transmitted through glass (as in Cycles and Mitsuba: no
//! transparent shadows through a dielectric).
//!
//! Volumes (KHR_materials_volume, [`crate::material::Volume`]): each path carries the medium
//! it is in, none at the camera. Crossing the boundary of a material with a volume from its
//! front face (the side its winding's normal points to) enters the medium; crossing any such
//! boundary from its back face leaves it; along every segment inside, the throughput (and a
//! shadow ray's light) is multiplied by the Beer-Lambert transmittance of the segment's length.
//! Limits: one medium at a time (nested or overlapping volumes are not tracked: leaving an
//! inner volume puts the path in air, or in the fog), a camera inside a volume starts in air
//! (or fog), and the boundary must be closed and consistently wound.
//!
//! Fog ([`Scene::fog`], [`crate::medium::Fog`]; decisions/0030): it fills the space outside
//! the volumes, the camera and the lights included, and follows Mitsuba 3's `volpath`
//! (`volpath.cpp`). A path chooses one colour channel at its start (one random number, drawn
//! only when the scene has fog: fog-free renders are unchanged); every segment outside a volume
//! draws one more for an exact free flight in that channel
//! ([`crate::medium::Fog::sample_flight`]). A flight that passes the segment multiplies the
//! throughput by `T / T_c` (the environment, for an escaping ray, is then seen times its
//! transmittance to infinity: nothing through homogeneous fog); one that ends in the fog
//! multiplies it by `T sigma_s / (T_c sigma_t,c)` and makes a vertex there, which counts as a
//! bounce (`max_depth`) exactly as a surface vertex: next-event estimation with a light chosen
//! by irradiance alone ([`Receiver::in_medium`]), weighed by the Henyey-Greenstein phase
//! function and, for area lights and the environment, by the power heuristic against phase
//! sampling; then a phase-function sample for the next direction (its density is the MIS
//! density of an emitter the path hits next), and Russian roulette. It draws the same two 4D
//! samples a surface vertex draws. Shadow rays from surfaces and from the fog multiply by the
//! fog's analytic transmittance (to infinity for the environment). On the camera segment the
//! light of point and spot lights scattered once by the fog is estimated instead by
//! equiangular sampling (Kulla and Fajardo 2012, `equiangular_direct`: two more random numbers,
//! a full surface search and one shadow ray) over the part of the segment each light can
//! reach (a spot light's cone, `lit_interval`), which stays bounded where the ray passes close
//! to a lamp; collisions on that segment then leave these lights out of their next-event
//! estimate.
//!
//! Path regularisation ([`RenderSettings::regularize`], off by default; biased): a glossy
//! lobe seen after a diffuse or rough bounce is roughened, so that the light a small lamp
//! sends through the wet road to a facade or pavement is found by next-event estimation
//! rather than by the rare BSDF sample that hits the lamp (a firefly). The rule is Cycles'
//! "Filter Glossy" (`integrator/surface_shader.h`, `surface_shader_prepare_closures`; Kaplanyan
//! and Dachsbacher 2013 regularise paths the same way): each path keeps the smallest
//! density `min_ray_pdf` of the directions its BSDF samples chose (lobe choice included;
//! infinite at the camera, delta samples leave it unchanged, as Cycles' singular closures
//! report a density of 1e6), and at a vertex where `min_ray_pdf / filter_glossy < 1` every
//! glossy lobe is clamped from below to the microfacet alpha
//! `0.5 sqrt(1 - min_ray_pdf / filter_glossy)` ([`regularized_alpha`], [`FILTER_GLOSSY`] =
//! Blender's default 1; [`Bsdf::roughened`]). A Lambertian bounce (density `cos / pi <=
//! 1 / pi`) makes every later glossy lobe at least as rough as alpha 0.41; a sharp glossy
//! bounce (density far above 1) changes nothing. The roughened lobe is the vertex's BSDF for
//! everything at that vertex: next-event estimation, the light choice, BSDF sampling and both
//! MIS weights, so the estimator is consistent for the roughened scene. The first vertex is
//! never roughened, so the specular layer (camera, first glossy bounce, emitter) and every
//! path of up to one bounce are bit-identical with and without it; the cost is a bias in
//! indirect light (a blurred reflection of a lamp in the road seen from a facade).
//!
//! Determinism: each pixel sample draws its random numbers from the [`Sampler`] positioned by
//! `(pixel, sample index)` and the seed, never by thread; rows are rendered in parallel with
//! rayon, each pixel accumulated by one thread in sample order, so the image is bit-identical
//! whatever the thread count. The hot loop does not allocate.
//!
//! Adaptive sampling ([`RenderSettings::noise_target`], off by default): the image is cut into
//! tiles of [`ADAPTIVE_TILE`] x [`ADAPTIVE_TILE`] = 16 x 16 pixels (smaller at the right and
//! bottom edges); a tile stops taking samples, all its pixels together, once its estimated
//! relative standard error is below the target, `spp` being the cap. Rows of tiles are
//! rendered in parallel, each tile by one thread in rounds; which samples a tile takes depends
//! only on its own pixels' samples, so the image stays bit-identical whatever the thread count:
//! - round one takes [`ADAPTIVE_MIN_SPP`] = 16 samples in every pixel of the tile (or the cap,
//!   if smaller), each later round [`ADAPTIVE_BATCH`] = 8 more; after each round the tile's
//!   error is checked (`tile_relative_error`):
//!   `sqrt(mean_i(s_i^2 / n_i)) / max(mean_i(m_i), ADAPTIVE_DARK_FLOOR) < noise_target`, over
//!   the tile's pixels `i` with `n_i` kept samples of luminance mean `m_i` and sample variance
//!   `s_i^2` ([`crate::film::Pixel::mean_variance`]): the root mean square standard error of
//!   the tile's pixels relative to the tile's mean, the quantity `streaks compare` reports
//!   for a region (relative RMSE, normalised by the region's mean);
//! - [`ADAPTIVE_DARK_FLOOR`] = 1e-3 (linear luminance): a tile darker than that is measured
//!   against the floor, i.e. an absolute standard error of `noise_target * 1e-3`, far under one
//!   8-bit sRGB step at exposure 0; a black tile (zero variance) stops at the minimum instead of
//!   running to the cap.
//!
//! Why tiles, not pixels: stopping on an estimated variance is biased when the variance is
//! estimated from the very samples that are averaged. A pixel whose rare bright paths (a lamp
//! reflected through the wet road, a firefly) have not shown up in its first samples estimates
//! a small variance and stops, too dark; a pixel that did see one runs on and dilutes it. A rule
//! that judged each pixel by its own samples (this module's earlier rule)
//! made rainy_street 1.4 % darker overall and 1.8 % on the road, and the procedural streets up
//! to 2.9 % on the road. A tile's decision pools 256 pixels' samples: a rare path of one pixel
//! moves it by 1/256, and a kind of rare path that a region has (every pixel of a wet patch
//! sees the lamp now and then) is in the pooled variance long before the tile stops. Measured
//! against a pixel rule with the tile's pooled variance as a floor, Cycles-like dilation of
//! unconverged pixels, and pixel statistics without each pixel's largest sample
//! (docs/decisions/0013), the tile rule was the least biased for its cost; its price is that a
//! tile's pixels all take the same count. The bias left is within the noise of fixed-spp
//! renders on the measured streets, not zero (a rare path rare even at the tile's scale still
//! stops the tile early).
//!
//! With `noise_target = None` the loop is the fixed-spp loop, operation for operation (rows in
//! parallel, each pixel's samples in order), so fixed-spp images are unchanged.

//! Layers (all optional, [`Layers`]):
//! - `depth`: distance along the camera's -Z axis (view-space depth, the `Z` of Eq. 5) to the
//!   first hit of the pixel-centre ray; `inf` on a miss.
//! - `normal`: the first hit's shading normal for the pixel-centre ray, world space, flipped
//!   to face the camera; zero on a miss.
//! - `albedo`: the first hit's [`crate::bsdf::Bsdf::albedo`] for the pixel-centre ray.
//! - `material`: the index into [`Scene::materials`] of the pixel-centre ray's first hit
//!   ([`crate::film::NO_MATERIAL`] on a miss); with [`crate::material::Material::road`] it tells
//!   which pixels see the road surface first.
//! - `object`: the slot in [`Scene::objects`] of the pixel-centre ray's first hit (the same
//!   ray and rule as `material`; [`crate::scene::SKY_OBJECT`] on a miss): what the pixel sees,
//!   as a semantic class and an instance, for segmentation maps. A rain drop in front is not
//!   a hit here (see below): the `rain` layer says where drops cover the pixel.
//! - `specular`: the part of the pixel's radiance that reached the camera by exactly one
//!   reflection of an emitter off the glossy lobe at the first surface hit (the environment
//!   counts as an emitter: a glossy road's reflection of the sky is a streak too): the glossy part
//!   (`eval_lobes(..).glossy`) of the next-event estimate at the first hit, plus, for the BSDF
//!   sample from the first hit that hits an emitter directly, `L_e * glossy(wi) * cos / pdf`
//!   with the same MIS weight as in the beauty image. Using the glossy part of `f` at the
//!   sampled direction (rather than "the sample came from the glossy lobe") makes the layer an
//!   unbiased estimate of the single-glossy-bounce direct light, the same quantity the
//!   next-event part estimates. It is box-filtered like the beauty image; a streak mask is a
//!   threshold on it.
//! - `emission`: the part of the pixel's radiance that the camera ray's first segment met as
//!   emission or environment (in full, as the beauty image adds it; with fog, with the
//!   segment's pass weight), box-filtered like the beauty image: the light seen directly,
//!   which a denoiser leaves alone ([`crate::output::denoise`]).
//! - `spp`: the number of samples the pixel took (kept and dropped), `spp` everywhere unless
//!   adaptive sampling stopped its tile earlier.
//! - `rain`: the mean over the pixel's camera samples (kept and dropped) of the share of the
//!   shutter during which a rain drop was the ray's first hit (with a closed shutter, the
//!   share of samples whose first hit was a drop) ([`crate::rain`]).
//! - `fog`: the luminance of the fog's transmittance from the camera to the pixel-centre ray's
//!   first hit (to infinity on a miss; 1 without fog). With fog, the `specular` layer's light
//!   carries the fog's pass weights of its two segments, and light scattered by the fog is not
//!   in it.
//!
//! The first-hit layers (depth, normal, albedo, material, object) are taken at the reference time 0
//! from the camera where the scene puts it, and ignore rain drops
//! ([`Scene::intersect`] meets no drop): they are the ground truth of the scene behind the rain.
//!
//! Time ([`crate::motion`]): with the shutter open for a nonzero interval
//! ([`RenderJob::motion`]) and something moving (the rig, or rain drops in the camera's
//! view), each camera sample draws one more number after its film position,
//! its time `t` uniform over the shutter, and its ray starts at the camera moved by the rig's
//! velocity times `t`; every ray of the path carries `t`. With a closed shutter, or nothing
//! moving, nothing is drawn and the image is the one a renderer without time makes.
//!
//! Rain ([`crate::rain`]): the camera ray meets the drops of its camera's index
//! ([`crate::rain::CameraRain`], built at the start of the render), and a path that hit a drop
//! its way out of it ([`Scene::intersect_path`]); a drop hit is shaded as any smooth
//! dielectric surface, and where a path meets a drop from outside its next-event estimation
//! of a delta light (a shadow ray, the fog's transmittance) goes through the drop's
//! pixel-averaged scattering ([`crate::rain::glint_phase`]) instead. Other rays, shadow rays included, do not meet drops. Under an open
//! shutter (and [`crate::rain::RainEstimator::Swept`], the default) a camera sample first
//! finds the drops that cover its ray at some time of the shutter in front of the scene
//! ([`crate::rain::CameraRain::swept`]); with none it traces as a dry render does, drawing
//! nothing more. Otherwise it traces two paths from its one time variate `u`: the background
//! (no drop) at the `u`-quantile of the times no drop covers the ray, weighted by their share
//! `1 - c` of the shutter, and the drops at the `u`-quantile of their intervals laid end to
//! end, traced with every drop at that time (the nearest covering one is the first hit) and
//! weighted by the intervals' summed length over the shutter divided by how many intervals
//! hold that time. Both are unbiased parts of the time integral; the rain layer gets `c`.

use crate::bsdf::Bsdf;
use crate::camera::Camera;
use crate::film::{Film, Pixel};
use crate::geometry::{offset_ray_origin, Frame, Ray};
use crate::light::{Light, LightSample, LightSampler, Receiver, Visibility};
use crate::material::Volume;
use crate::medium::Fog;
use crate::motion::Motion;
use crate::rain::{CameraRain, RainPath};
use crate::sampling::{power_heuristic, Sampler};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;
use streaks_image::{luminance, RgbImage};
use streaks_settings::RenderSettings;

/// Depth from which Russian roulette may end a path (Mitsuba 3's `rr_depth`, whose default is
/// 5; see the module documentation for why 3).
pub const RR_DEPTH: u32 = 3;

/// A shadow ray stops this fraction short of the light point, so that it does not hit the
/// emitter it is aimed at.
const SHADOW_EPSILON: f32 = 1e-4;

/// Which layers to compute besides the beauty image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Layers {
    /// View-space depth of the pixel-centre ray's first hit.
    pub depth: bool,
    /// First-hit shading normal.
    pub normal: bool,
    /// First-hit albedo.
    pub albedo: bool,
    /// Single-glossy-bounce emitter light (streaks).
    pub specular: bool,
    /// First-hit material index of the pixel-centre ray.
    pub material: bool,
    /// First-hit object slot ([`Scene::objects`]) of the pixel-centre ray.
    pub object: bool,
    /// Samples taken per pixel (see adaptive sampling in the module documentation).
    pub spp: bool,
    /// Share of the camera samples whose first hit was a rain drop.
    pub rain: bool,
    /// The fog's transmittance to the pixel-centre ray's first hit.
    pub fog: bool,
    /// The light seen directly: the emission (or environment) the camera ray's first segment
    /// meets, box-filtered as the beauty image (a part of it, which a denoiser leaves alone).
    pub emission: bool,
}

/// One image to render: its size, seed and layers, and how to sample it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderJob {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Seed of the sampler.
    pub seed: u32,
    /// Extra layers.
    pub layers: Layers,
    /// Samples, adaptive sampling, path length and regularisation.
    pub settings: RenderSettings,
    /// The shutter interval and the rig's velocity ([`Motion::default`]: no motion blur).
    pub motion: Motion,
}

/// Adaptive sampling: the side of the square tiles of pixels that stop together (see the
/// module documentation).
pub const ADAPTIVE_TILE: u32 = 16;

/// Adaptive sampling: samples every pixel takes before its tile's error is first checked (or
/// the cap, if smaller; see the module documentation).
pub const ADAPTIVE_MIN_SPP: u32 = 16;

/// Adaptive sampling: samples per pixel between two checks of a tile's error.
pub const ADAPTIVE_BATCH: u32 = 8;

/// Adaptive sampling: the luminance below which a tile's standard error is measured against
/// this floor rather than its mean (so that black tiles stop; see the module documentation).
pub const ADAPTIVE_DARK_FLOOR: f32 = 1e-3;

/// Cycles' "Filter Glossy" value used by path regularisation: Blender's default
/// (`cycles.blur_glossy = 1.0`; the kernel's `filter_glossy` is its inverse).
pub const FILTER_GLOSSY: f32 = 1.0;

/// The smallest microfacet alpha that path regularisation lets a glossy lobe have at a vertex
/// whose path has so far chosen directions of smallest density `min_ray_pdf` (per steradian,
/// infinite for a camera ray): Cycles' `0.5 sqrt(1 - min_ray_pdf / filter_glossy)` when
/// `min_ray_pdf / filter_glossy < 1` (`surface_shader_prepare_closures` with
/// `kernel_data.integrator.filter_glossy = 1 / blur_glossy`), else `None` (no change). At most
/// 0.5.
#[inline]
pub fn regularized_alpha(min_ray_pdf: f32) -> Option<f32> {
    let blur_pdf = min_ray_pdf / FILTER_GLOSSY;
    (blur_pdf < 1.0).then(|| 0.5 * (1.0 - blur_pdf).sqrt())
}

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// Pixel samples traced (dropped ones included; with adaptive sampling, those actually
    /// taken).
    pub samples: u64,
    /// Rays traced (camera, continuation and shadow rays).
    pub rays: u64,
    /// Samples dropped because they were NaN or infinite.
    pub nonfinite_dropped: u64,
}

/// A rendered image with its requested layers.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOutput {
    /// Linear RGB radiance (denoised after [`crate::output::denoise`]).
    pub image: RgbImage,
    /// The render before denoising, when [`crate::output::denoise`] replaced `image`.
    pub raw: Option<RgbImage>,
    /// View-space depth per pixel, row-major (if requested).
    pub depth: Option<Vec<f32>>,
    /// Shading normals (if requested).
    pub normal: Option<RgbImage>,
    /// Albedo (if requested).
    pub albedo: Option<RgbImage>,
    /// Specular part (if requested).
    pub specular: Option<RgbImage>,
    /// The light seen directly, the part of `image` the camera ray's first segment met as
    /// emission or environment (if requested).
    pub emission: Option<RgbImage>,
    /// First-hit material index per pixel, row-major (if requested; see the module
    /// documentation).
    pub material: Option<Vec<u32>>,
    /// First-hit object slot ([`Scene::objects`]) per pixel, row-major (if requested; see
    /// the module documentation).
    pub object: Option<Vec<u32>>,
    /// Samples taken per pixel, row-major (if requested).
    pub spp: Option<Vec<u32>>,
    /// Share of each pixel's camera samples whose first hit was a rain drop, row-major (if
    /// requested).
    pub rain: Option<Vec<f32>>,
    /// The fog's transmittance (luminance) from the camera to the pixel-centre ray's first
    /// hit, row-major (if requested; 1 without fog).
    pub fog: Option<Vec<f32>>,
    /// Counters.
    pub stats: RenderStats,
}

/// Radiance and specular part of one camera path, and the number of rays it traced.
#[derive(Clone, Copy, Debug, Default)]
struct PathResult {
    radiance: Vec3,
    specular: Vec3,
    /// The part of `radiance` seen directly (the first segment's emitter or environment).
    emission: Vec3,
    rays: u64,
    /// Whether the camera ray's first hit was a rain drop.
    rain: bool,
}

/// Renders `camera`'s view of `scene` on the current rayon thread pool.
///
/// `progress` is called with increments of completed pixel samples (the total is
/// `width * height * spp`; under adaptive sampling a finished tile reports the samples its
/// pixels skipped as done too, so the total is reached).
pub fn render(
    scene: &Scene,
    camera: &Camera,
    job: &RenderJob,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderOutput {
    let start = Instant::now();
    let (width, height) = (job.width, job.height);
    let mut film = Film::new(width, height);
    let rays = AtomicU64::new(0);
    let forward = camera
        .world_from_camera
        .transform_vector3(-Vec3::Z)
        .normalize();
    let l = job.layers;
    let need_centre = l.depth || l.normal || l.albedo || l.material || l.object || l.fog;
    // The drops this camera sees, binned by pixel (none without rain).
    let rain = scene
        .rain
        .as_ref()
        .and_then(|r| CameraRain::build(&r.field, camera, width, height, &job.motion));
    let rain = rain.as_ref();

    match job.settings.noise_target {
        None => film.par_rows_mut().enumerate().for_each(|(y, row)| {
            let y = y as u32;
            let mut sampler = Sampler::new(job.seed);
            let mut row_rays = 0u64;
            for (x, pixel) in row.iter_mut().enumerate() {
                let x = x as u32;
                if need_centre {
                    row_rays += centre_ray(scene, camera, job, forward, (x, y), pixel);
                }
                for s in 0..job.settings.spp {
                    row_rays +=
                        take_sample(scene, camera, job, rain, &mut sampler, (x, y), s, pixel);
                }
            }
            rays.fetch_add(row_rays, Ordering::Relaxed);
            progress(width as u64 * job.settings.spp as u64);
        }),
        Some(target) => {
            film.par_bands_mut(ADAPTIVE_TILE)
                .enumerate()
                .for_each(|(band_index, band)| {
                    let y0 = band_index as u32 * ADAPTIVE_TILE;
                    let band_rows = band.len() as u32 / width.max(1);
                    let mut sampler = Sampler::new(job.seed);
                    let mut band_rays = 0u64;
                    let mut x0 = 0;
                    while x0 < width {
                        let tile = Tile {
                            x0,
                            y0,
                            width: ADAPTIVE_TILE.min(width - x0),
                            height: band_rows,
                        };
                        if need_centre {
                            for (x, y) in tile.pixels() {
                                let pixel = &mut band[((y - y0) * width + x) as usize];
                                band_rays += centre_ray(scene, camera, job, forward, (x, y), pixel);
                            }
                        }
                        band_rays += render_tile_adaptive(
                            scene,
                            camera,
                            job,
                            rain,
                            target,
                            &mut sampler,
                            tile,
                            band,
                        );
                        progress(tile.width as u64 * tile.height as u64 * job.settings.spp as u64);
                        x0 += ADAPTIVE_TILE;
                    }
                    rays.fetch_add(band_rays, Ordering::Relaxed);
                });
        }
    }

    let layers = job.layers;
    RenderOutput {
        image: film.image(),
        raw: None,
        depth: layers.depth.then(|| film.depth()),
        normal: layers.normal.then(|| film.normal()),
        albedo: layers.albedo.then(|| film.albedo()),
        specular: layers.specular.then(|| film.specular()),
        emission: layers.emission.then(|| film.emission()),
        material: layers.material.then(|| film.material()),
        object: layers.object.then(|| film.object()),
        spp: layers.spp.then(|| film.spp()),
        rain: layers.rain.then(|| film.rain()),
        fog: layers.fog.then(|| film.fog()),
        stats: RenderStats {
            seconds: start.elapsed().as_secs_f64(),
            samples: film.samples(),
            rays: rays.into_inner(),
            nonfinite_dropped: film.dropped(),
        },
    }
}

/// A rectangle of pixels rendered by one thread under adaptive sampling.
#[derive(Clone, Copy, Debug)]
struct Tile {
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
}

impl Tile {
    /// The tile's pixels, row by row.
    fn pixels(self) -> impl Iterator<Item = (u32, u32)> {
        (self.y0..self.y0 + self.height)
            .flat_map(move |y| (self.x0..self.x0 + self.width).map(move |x| (x, y)))
    }
}

/// The estimated relative standard error of a tile under adaptive sampling: the root mean
/// square of its pixels' standard errors (luminance) over the mean of their luminance,
/// `sqrt(mean(s_i^2 / n_i)) / max(mean(m_i), ADAPTIVE_DARK_FLOOR)`; infinite while a pixel has
/// fewer than two kept samples. Sums in `f64`, in the tile's pixel order.
fn tile_relative_error(pixels: impl Iterator<Item = Pixel>) -> f64 {
    let (mut variance, mut mean, mut n) = (0.0f64, 0.0f64, 0u32);
    for p in pixels {
        let Some(v) = p.mean_variance() else {
            return f64::INFINITY;
        };
        variance += v as f64;
        mean += p.lum_mean as f64;
        n += 1;
    }
    if n == 0 {
        return f64::INFINITY;
    }
    let n = n as f64;
    (variance / n).sqrt() / (mean / n).max(ADAPTIVE_DARK_FLOOR as f64)
}

/// Renders one tile of `band` (the rows from `tile.y0` on, `width` pixels each) under
/// adaptive sampling to `target`: rounds of samples for every pixel of the tile (the minimum,
/// then batches) until [`tile_relative_error`] is below the target or the cap is reached.
/// Returns the rays traced.
#[allow(clippy::too_many_arguments)]
fn render_tile_adaptive(
    scene: &Scene,
    camera: &Camera,
    job: &RenderJob,
    rain: Option<&CameraRain>,
    target: f32,
    sampler: &mut Sampler,
    tile: Tile,
    band: &mut [Pixel],
) -> u64 {
    let (width, cap) = (job.width, job.settings.spp);
    let index = |(x, y): (u32, u32)| ((y - tile.y0) * width + x) as usize;
    let mut rays = 0u64;
    let mut taken = 0u32;
    while taken < cap {
        let next = if taken == 0 {
            ADAPTIVE_MIN_SPP.min(cap)
        } else {
            (taken + ADAPTIVE_BATCH).min(cap)
        };
        for xy in tile.pixels() {
            let pixel = &mut band[index(xy)];
            for s in taken..next {
                rays += take_sample(scene, camera, job, rain, sampler, xy, s, pixel);
            }
        }
        taken = next;
        if taken < cap
            && tile_relative_error(tile.pixels().map(|xy| band[index(xy)])) < target as f64
        {
            break;
        }
    }
    rays
}

/// Fills the first-hit layers of pixel `(x, y)` from its centre ray; returns the rays traced.
#[inline]
fn centre_ray(
    scene: &Scene,
    camera: &Camera,
    job: &RenderJob,
    forward: Vec3,
    (x, y): (u32, u32),
    pixel: &mut Pixel,
) -> u64 {
    let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
    let ray = camera.generate_ray(centre, job.width, job.height);
    first_hit_layers(scene, &ray, camera.position(), forward, pixel);
    1
}

/// Takes sample `s` of pixel `(x, y)` into `pixel`; returns the rays traced.
#[inline]
#[allow(clippy::too_many_arguments)]
fn take_sample(
    scene: &Scene,
    camera: &Camera,
    job: &RenderJob,
    rain: Option<&CameraRain>,
    sampler: &mut Sampler,
    (x, y): (u32, u32),
    s: u32,
    pixel: &mut Pixel,
) -> u64 {
    sampler.start_pixel_sample((x, y), s);
    let film_pos = Vec2::new(x as f32, y as f32) + sampler.next_2d();
    let mut ray = camera.generate_ray(film_pos, job.width, job.height);
    // Only moving things need a time: the rig, or rain drops in view.
    if job.motion.is_blurred() && (job.motion.rig_velocity != Vec3::ZERO || rain.is_some()) {
        ray.time = job.motion.time(sampler.next_1d());
        ray.origin += job.motion.rig_velocity * ray.time;
    }
    let swept_estimator = scene
        .rain
        .as_ref()
        .is_some_and(|r| r.estimator == crate::rain::RainEstimator::Swept);
    let swept = match rain {
        Some(rain) if swept_estimator && job.motion.is_blurred() => {
            Some(swept_drops(scene, rain, &ray, job))
        }
        _ => None,
    };
    let Some(swept) = swept else {
        let path = trace_path(scene, ray, sampler, job, RainPath::camera(rain));
        if pixel.add_sample(path.radiance, path.specular) {
            pixel.emission += path.emission;
        }
        pixel.rain += f32::from(u8::from(path.rain));
        return path.rays;
    };
    if swept.is_empty() {
        let path = trace_path(scene, ray, sampler, job, RainPath::camera(None));
        if pixel.add_sample(path.radiance, path.specular) {
            pixel.emission += path.emission;
        }
        return path.rays;
    }
    // The time integral split on whether a drop covers the ray: the background (no drop) at
    // a time outside every drop's interval, weighted by that share of the shutter, and the
    // drops at a time over their intervals (counted with overlaps, so weighted by
    // their summed length over the number of intervals holding the time), traced with
    // every drop at that time (its first hit is the nearest drop there).
    let motion = &job.motion;
    let shutter = motion.close - motion.open;
    let u = ((ray.time - motion.open) / shutter).clamp(0.0, 1.0 - f32::EPSILON);
    let covered = swept.coverage(motion);
    let origin = ray.origin - motion.rig_velocity * ray.time;
    let mut background_ray = ray;
    background_ray.time = swept.time_outside(u, motion);
    background_ray.origin = origin + motion.rig_velocity * background_ray.time;
    let background = trace_path(scene, background_ray, sampler, job, RainPath::camera(None));
    let mut drop_ray = ray;
    // The same variate as the background's time: stratified over the pixel's samples (the
    // two paths' expectations add up, so their correlation biases nothing).
    drop_ray.time = swept.sample_time(u).unwrap_or(ray.time);
    drop_ray.origin = origin + motion.rig_velocity * drop_ray.time;
    // Russian roulette on the drops' path: traced with probability
    // `q = min(1, RAIN_ROULETTE * covered)` and divided by it (unbiased), so that the many rays
    // a far, thin drop grazes for a sliver of the shutter do not each pay a second path.
    let q = (RAIN_ROULETTE * covered).min(1.0);
    let drop = if sampler.next_1d() < q {
        trace_path(scene, drop_ray, sampler, job, RainPath::camera(rain))
    } else {
        PathResult::default()
    };
    let w = swept.total() / shutter / swept.covering(drop_ray.time).max(1) as f32 / q.max(1e-30);
    if pixel.add_sample(
        background.radiance * (1.0 - covered) + drop.radiance * w,
        background.specular * (1.0 - covered) + drop.specular * w,
    ) {
        pixel.emission += background.emission * (1.0 - covered) + drop.emission * w;
    }
    pixel.rain += covered;
    background.rays + drop.rays
}

/// Rain: the factor on a camera ray's covered share of the shutter that gives the probability
/// of tracing its drops' path (Russian roulette; see `take_sample`). 4 traces every ray a drop
/// covers for a quarter of the shutter or more (a near drop) and one in four of those covered
/// for 1/16 (a far, thin drop); the cost it saves is measured in docs/benchmarks.md
/// ("Weather").
const RAIN_ROULETTE: f32 = 4.0;

/// The drops that cover the camera ray `ray` (at its sample's time) during the shutter in
/// front of the scene ([`CameraRain::swept`]; the scene's surface found where the camera
/// stands in the middle of the shutter).
#[inline]
fn swept_drops(
    scene: &Scene,
    rain: &CameraRain,
    ray: &Ray,
    job: &RenderJob,
) -> crate::rain::SweptSet {
    let origin = ray.origin - job.motion.rig_velocity * ray.time;
    let mut set = rain.swept(origin, ray.direction);
    if !set.is_empty() {
        let mid = 0.5 * (job.motion.open + job.motion.close);
        let probe = Ray::new(origin + job.motion.rig_velocity * mid, ray.direction);
        if let Some(surface) = scene.intersect(&probe) {
            set.retain_nearer(surface.t);
        }
    }
    set
}

/// Fills the depth, normal, albedo, material, object and fog transmittance of `pixel` from
/// the pixel-centre ray.
fn first_hit_layers(scene: &Scene, ray: &Ray, origin: Vec3, forward: Vec3, pixel: &mut Pixel) {
    let found = scene.intersect(ray);
    if let Some(fog) = &scene.fog {
        let t = found.as_ref().map_or(f32::INFINITY, |h| h.t);
        pixel.fog = luminance(fog.transmittance(ray.origin, ray.direction, t));
    }
    if let Some(hit) = found {
        pixel.depth = (hit.p - origin).dot(forward);
        pixel.material = hit.material;
        pixel.object = hit.object;
        pixel.normal = if hit.ns.dot(ray.direction) > 0.0 {
            -hit.ns
        } else {
            hit.ns
        };
        let material = &scene.materials[hit.material as usize];
        pixel.albedo = material.bsdf_at(&hit.attributes, &scene.textures).albedo();
    }
}

/// Where the path stands when light arrives along its current ray (an emitter hit, or the
/// environment as the ray escapes), for [`Arrival::add`].
struct Arrival {
    /// Segments before the current one.
    depth: u32,
    /// Whether the current direction came from a delta lobe.
    prev_delta: bool,
    /// The BSDF-sampling density of the current direction.
    prev_bsdf_pdf: f32,
    /// The first hit's BSDF, frame and `wo`, for the specular layer.
    first_bsdf: Option<(Bsdf, Frame, Vec3)>,
    /// The product of the fog's pass weights of the path's segments (1 without fog), for the
    /// specular layer.
    fog_pass: Vec3,
}

impl Arrival {
    /// Adds radiance `le` arriving along direction `dir`: in full when seen by the camera or
    /// through a delta lobe, else weighted by the power heuristic against the light choice's
    /// density `light_pdf()` of the same direction; light reached by one BSDF sample from the
    /// first hit also goes, with the glossy part of that BSDF, to the specular layer.
    #[inline]
    fn add(
        &self,
        out: &mut PathResult,
        throughput: Vec3,
        le: Vec3,
        dir: Vec3,
        light_pdf: impl FnOnce() -> f32,
    ) {
        if self.depth == 0 || self.prev_delta {
            out.radiance += throughput * le;
            if self.depth == 0 {
                out.emission += throughput * le;
            }
        } else {
            let weight = power_heuristic(1.0, self.prev_bsdf_pdf, 1.0, light_pdf());
            out.radiance += throughput * le * weight;
            if let (1, Some((bsdf, frame, wo_local))) = (self.depth, self.first_bsdf) {
                let wi_local = frame.to_local(dir);
                let glossy = bsdf.eval_lobes(wo_local, wi_local).glossy;
                out.specular +=
                    self.fog_pass * (le * glossy * (wi_local.z * weight / self.prev_bsdf_pdf));
            }
        }
    }
}

/// Traces one camera path (see the module documentation).
fn trace_path(
    scene: &Scene,
    mut ray: Ray,
    sampler: &mut Sampler,
    job: &RenderJob,
    mut rain_path: RainPath,
) -> PathResult {
    let (max_depth, want_specular) = (job.settings.max_depth, job.layers.specular);
    let lights: &LightSampler = &scene.light_sampler;
    let mut out = PathResult::default();
    let mut throughput = Vec3::ONE;
    // Number of segments before the current one (Mitsuba's `depth`).
    let mut depth = 0u32;
    // The previous vertex and the BSDF-sampling density of the current direction, for MIS.
    let mut prev: Option<Receiver> = None;
    let mut prev_bsdf_pdf = 0.0f32;
    // Whether the current direction came from a delta lobe (no MIS: light sampling cannot
    // produce it).
    let mut prev_delta = false;
    // The medium the current segment travels in (KHR_materials_volume), if any.
    let mut medium: Option<Volume> = None;
    // At the first hit: the BSDF and frame, for the specular layer of a hit emitter.
    let mut first_bsdf: Option<(Bsdf, Frame, Vec3)> = None;
    // The smallest density of the directions chosen so far (path regularisation).
    let mut min_ray_pdf = f32::INFINITY;
    // The fog, the colour channel its free flights are sampled in (one per path, as in
    // Mitsuba's volpath; drawn only when there is fog) and the product of its pass weights.
    let fog = scene.fog.as_ref();
    let channel = match fog {
        Some(_) => ((sampler.next_1d() * 3.0) as usize).min(2),
        None => 0,
    };
    let mut fog_pass = Vec3::ONE;
    // Whether the fog's single scattering of point and spot lights along the camera segment
    // is estimated by equiangular sampling (see `equiangular_direct`) instead of at
    // collisions (later segments keep the collisions' estimate: a halo seen directly is what
    // needs it, and every equiangular segment costs a full surface search and a shadow ray).
    let equiangular = fog.is_some() && scene.lights.iter().any(|l| light_position(l).is_some());
    // Whether the current segment's point and spot lights were estimated that way.
    let mut along = false;

    while depth < max_depth {
        out.rays += 1;
        // A free flight through the fog, when the path is in it (outside every volume): its
        // distance is drawn first and the surfaces are searched only up to it (Mitsuba's
        // order; the search stops earlier when the fog stops the path).
        let (found, collision) = match (fog, medium) {
            (Some(fog), None) => {
                let u = sampler.next_1d();
                let t = fog.sample_distance(ray.origin, ray.direction, channel, u);
                // Equiangular sampling needs the whole segment; else the search may stop at t.
                along = equiangular && depth == 0 && depth + 1 < max_depth;
                let found = scene.intersect_path(
                    &Ray {
                        t_max: if along { ray.t_max } else { ray.t_max.min(t) },
                        ..ray
                    },
                    &mut rain_path,
                );
                let t_seg = found.as_ref().map_or(ray.t_max, |h| h.t);
                if along {
                    let u = sampler.next_2d();
                    out.rays += equiangular_direct(
                        scene,
                        fog,
                        &ray,
                        t_seg,
                        throughput,
                        u,
                        &mut out.radiance,
                    );
                }
                if t < t_seg {
                    (None, Some((fog, t)))
                } else {
                    let weight = fog.pass_weight(ray.origin, ray.direction, t_seg, channel);
                    throughput *= weight;
                    fog_pass *= weight;
                    (found, None)
                }
            }
            _ => (scene.intersect_path(&ray, &mut rain_path), None),
        };
        if let Some((fog, t)) = collision {
            throughput *= fog.collision_weight(ray.origin, ray.direction, t, channel);
            // 1-3 at a point of the fog: a vertex and a bounce like a surface's.
            if depth + 1 >= max_depth {
                break;
            }
            let p = ray.origin + ray.direction * t;
            let rx = Receiver::in_medium(p);
            out.rays += scatter_in_fog(
                scene,
                fog,
                &rx,
                -ray.direction,
                throughput,
                along,
                sampler,
                &mut out.radiance,
            );
            let [dx, dy, _, u_rr] = sampler.next_4d();
            let ps = fog.phase().sample(-ray.direction, Vec2::new(dx, dy));
            prev = Some(rx);
            prev_bsdf_pdf = ps.pdf;
            prev_delta = false;
            min_ray_pdf = min_ray_pdf.min(ps.pdf);
            ray = Ray::new(p, ps.wi).at_time(ray.time);
            depth += 1;
            if !survives_roulette(depth, &mut throughput, u_rr) {
                break;
            }
            continue;
        }
        // Where the path stands, for light arriving along this ray.
        let arrival = Arrival {
            depth,
            prev_delta,
            prev_bsdf_pdf,
            first_bsdf,
            fog_pass,
        };
        let Some(hit) = found else {
            // 1'. The environment, for a ray that escapes (not from inside a volume, whose
            // closed surface a ray cannot leave unseen; through the fog, its pass weight is
            // in the throughput).
            if let (Some(env), None) = (lights.environment(), medium) {
                let le = env.le(ray.direction);
                if le.max_element() > 0.0 {
                    arrival.add(&mut out, throughput, le, ray.direction, || {
                        prev.map_or(0.0, |rx| lights.pdf_environment(&rx, ray.direction))
                    });
                }
            }
            break;
        };
        let wo = -ray.direction;
        out.rain |= depth == 0 && hit.triangle == crate::rain::RAIN_TRIANGLE;
        if let Some(v) = medium {
            throughput *= v.transmittance(hit.t);
        }

        // 1. Emission of the surface hit.
        let le = scene.emitted_radiance(&hit, wo);
        if le.max_element() > 0.0 {
            arrival.add(&mut out, throughput, le, ray.direction, || {
                prev.map_or(0.0, |rx| lights.pdf_li(&rx, &hit))
            });
        }
        if depth + 1 >= max_depth {
            break;
        }

        // Shading frame, flipped toward the viewer; geometric normal on the same side.
        let material = &scene.materials[hit.material as usize];
        let front = hit.ng.dot(wo) >= 0.0;
        let mut bsdf = material.bsdf_at(&hit.attributes, &scene.textures);
        if !front {
            bsdf = bsdf.seen_from_back();
        }
        if job.settings.regularize {
            if let Some(alpha) = regularized_alpha(min_ray_pdf) {
                bsdf = bsdf.roughened(alpha);
            }
        }
        let ng = if front { hit.ng } else { -hit.ng };
        // The medium beyond the surface: entered through a volume's front face, left through
        // its back face; a transmitted direction travels in it, a reflected one in `medium`.
        let beyond = match material.volume() {
            Some(v) if bsdf.transmits() => front.then_some(v),
            _ => medium,
        };
        let medium_along = |wi_local_z: f32| if wi_local_z < 0.0 { beyond } else { medium };
        let ns = if hit.ns.dot(ng) < 0.0 {
            -hit.ns
        } else {
            hit.ns
        };
        // A normal-mapped hit's diffuse lobe follows the mapped normal (crate::normal_map).
        let mapped = hit.mapped.map(|m| if front { m } else { m.flipped() });
        let frame = Frame::from_normal(ns);
        if let Some(n) = hit.coat_normal {
            // A clear coat with its own normal: flipped toward the viewer as `ns` is.
            bsdf = bsdf.with_coat_normal(frame.to_local(if front { n } else { -n }));
        }
        let wo_local = frame.to_local(wo);
        if wo_local.z <= 0.0 {
            // The interpolated normal faces away from the viewer: no BSDF value either way.
            break;
        }

        // 2. Next-event estimation. A vertex draws two 4D samples, one for the light (point,
        // choice) and one for the BSDF (direction, lobe, roulette), always, so the dimensions
        // stay aligned.
        let [px, py, u_light, _] = sampler.next_4d();
        let u_point = Vec2::new(px, py);
        let rx = Receiver {
            p: hit.p,
            ng,
            frame,
            wo_local,
            bsdf,
        };
        if let Some(ls) = lights.sample_li(&scene.materials, &scene.textures, &rx, u_light, u_point)
        {
            if ls.delta && front && hit.triangle == crate::rain::RAIN_TRIANGLE {
                // A drop glints in a delta light, which its smooth surface cannot show (once,
                // where a path meets it from outside: the phase holds the light through it).
                out.rays += 1;
                let origin = crate::rain::offset_from_drop(hit.p, ng, ls.wi);
                let li = visible_li(scene, lights, origin, hit.p, &ls);
                let li = match (medium, fog) {
                    (Some(v), _) if ls.dist.is_finite() => li * v.transmittance(ls.dist),
                    (None, Some(fog)) => li * fog.transmittance(hit.p, ls.wi, ls.dist),
                    _ => li,
                };
                let phase = crate::rain::glint_phase(-ls.wi.dot(wo));
                out.radiance += throughput * li * (phase / ls.pdf);
            }
            let wi_local = frame.to_local(ls.wi);
            if wi_local.z * ng.dot(ls.wi) > 0.0 {
                // The BSDF's density of wi matters only for MIS against an area light.
                let (f, bsdf_pdf) = if ls.delta {
                    (bsdf.eval_lobes(wo_local, wi_local), 0.0)
                } else {
                    bsdf.eval_pdf(wo_local, wi_local)
                };
                let total = match mapped {
                    None => f.total(),
                    Some(m) => m.reweigh(f, ns, ls.wi, wi_local.z),
                };
                if total.max_element() > 0.0 {
                    let origin = offset_ray_origin(hit.p, ng, ls.wi);
                    out.rays += 1;
                    let li = visible_li(scene, lights, origin, hit.p, &ls);
                    let li = match (medium_along(wi_local.z), fog) {
                        (Some(v), _) if ls.dist.is_finite() => li * v.transmittance(ls.dist),
                        (None, Some(fog)) => li * fog.transmittance(hit.p, ls.wi, ls.dist),
                        _ => li,
                    };
                    if li.max_element() > 0.0 {
                        let weight = if ls.delta {
                            1.0
                        } else {
                            power_heuristic(1.0, ls.pdf, 1.0, bsdf_pdf)
                        };
                        let scale = li * (wi_local.z.abs() * weight / ls.pdf);
                        out.radiance += throughput * total * scale;
                        if depth == 0 && want_specular {
                            out.specular += throughput * f.glossy * scale;
                        }
                    }
                }
            }
        }

        // 3. BSDF sampling.
        let [dx, dy, u_lobe, u_rr] = sampler.next_4d();
        let u_dir = Vec2::new(dx, dy);
        let Some(bs) = bsdf.sample(wo_local, u_lobe, u_dir) else {
            break;
        };
        let wi = frame.to_world(bs.wi);
        if !(bs.pdf > 0.0 && bs.wi.z * ng.dot(wi) > 0.0) {
            break;
        }
        let f = match mapped {
            Some(m) if !bs.delta => m.reweigh(bsdf.eval_lobes(wo_local, bs.wi), ns, wi, bs.wi.z),
            _ => bs.f,
        };
        throughput *= f * (bs.wi.z.abs() / bs.pdf);
        if depth == 0 && want_specular {
            first_bsdf = Some((bsdf, frame, wo_local));
        }
        prev = Some(rx);
        prev_bsdf_pdf = bs.pdf;
        prev_delta = bs.delta;
        if !bs.delta {
            min_ray_pdf = min_ray_pdf.min(bs.pdf);
        }
        medium = medium_along(bs.wi.z);
        ray = Ray::new(scene.spawn_origin(&hit, ng, wi), wi).at_time(ray.time);
        depth += 1;

        if !survives_roulette(depth, &mut throughput, u_rr) {
            break;
        }
    }
    out
}

/// Russian roulette (Mitsuba's rule) after the path's `depth`-th bounce with `u_rr`: whether
/// the path goes on (its throughput divided by the survival probability); also `false` once
/// the throughput is zero.
#[inline]
fn survives_roulette(depth: u32, throughput: &mut Vec3, u_rr: f32) -> bool {
    if depth >= RR_DEPTH {
        let q = throughput.max_element().min(0.95);
        if u_rr >= q {
            return false;
        }
        *throughput /= q;
    }
    throughput.max_element() > 0.0
}

/// The light of sample `ls` that reaches `origin` (offset from the shading point `from`),
/// before any medium: `ls.li` if a shadow ray finds the way free (or, for a compact emitter,
/// the emission of the emitter a closest-hit ray lands on, if it is that one), else zero.
/// These rays meet only the scene's surfaces, which do not move, so they carry no time.
#[inline]
fn visible_li(
    scene: &Scene,
    lights: &LightSampler,
    origin: Vec3,
    from: Vec3,
    ls: &LightSample,
) -> Vec3 {
    match ls.visibility {
        Visibility::ShadowRay => {
            let t_max = if ls.dist.is_finite() {
                (ls.dist - (origin - from).length()) * (1.0 - SHADOW_EPSILON)
            } else {
                f32::INFINITY
            };
            let shadow = Ray {
                t_max,
                ..Ray::new(origin, ls.wi)
            };
            if scene.occluded(&shadow) {
                Vec3::ZERO
            } else {
                ls.li
            }
        }
        Visibility::FirstHit { emitter } => {
            let ray = Ray {
                t_max: ls.dist * (1.0 + 1e-4),
                ..Ray::new(origin, ls.wi)
            };
            match scene.intersect(&ray) {
                Some(h)
                    if lights
                        .emitters()
                        .emitter_of(h.triangle)
                        .is_some_and(|(e, _)| e == emitter as usize) =>
                {
                    scene.emitted_radiance(&h, -ls.wi)
                }
                _ => Vec3::ZERO,
            }
        }
    }
}

/// The position of a point or spot light and the luminance of its intensity; `None` for a
/// directional light.
#[inline]
fn light_position(light: &Light) -> Option<(Vec3, f32)> {
    match *light {
        Light::Point {
            position,
            intensity,
            ..
        }
        | Light::Spot {
            position,
            intensity,
            ..
        } => Some((position, luminance(intensity))),
        Light::Directional { .. } => None,
    }
}

/// The equiangular parameters of a light at `position` seen along the ray `o + t d`, `t` in
/// `[t0, t1]` (`t1` may be infinite): the distance `h` of the ray's closest approach (at least
/// 1e-4), its parameter `delta`, and the angle `theta_b - theta_a` the interval spans as seen
/// from the light (the angles under which its ends are seen, from the closest approach). One
/// arc tangent: with `x_a = t0 - delta` and `x_b = t1 - delta`, `tan(theta_b - theta_a) =
/// h (x_b - x_a) / (h^2 + x_a x_b)`, and `pi / 2 - theta_a = atan2(h, x_a)` for an unbounded
/// interval; [`equiangular_start`] gives `theta_a` for the light that is sampled.
#[inline]
fn equiangular_frame(o: Vec3, d: Vec3, (t0, t1): (f32, f32), position: Vec3) -> (f32, f32, f32) {
    let delta = (position - o).dot(d);
    let h = (position - (o + d * delta)).length().max(1e-4);
    let (xa, xb) = (t0 - delta, t1 - delta);
    let span = if t1.is_finite() {
        (h * (xb - xa)).atan2(h * h + xa * xb)
    } else {
        h.atan2(xa)
    };
    (h, delta, span)
}

/// `theta_a`, the angle under which the start `t0` of the interval is seen from the light, for
/// [`equiangular_frame`]'s `h` and `delta`.
#[inline]
fn equiangular_start(t0: f32, h: f32, delta: f32) -> f32 {
    (t0 - delta).atan2(h)
}

/// The part `[t0, t1]` of the segment `o + t d`, `t` in `[0, t_seg]`, that a light can
/// reach: all of it for a point light; for a spot light the part inside its outer cone,
/// widened by a thousandth of its cosine so rounding never cuts lit points off (the wider
/// part is unlit and adds nothing). `None` when no point of the segment is lit. Equiangular
/// sampling over the lit part alone: a headlight's beam seen from just behind the lamp (a
/// rig's own headlights, which every camera ray passes within a metre or two) would
/// otherwise draw most distances near the lamp, outside its beam.
#[inline]
fn lit_interval(light: &Light, o: Vec3, d: Vec3, t_seg: f32) -> Option<(f32, f32)> {
    let Light::Spot {
        position,
        direction: axis,
        cos_outer,
        ..
    } = *light
    else {
        return Some((0.0, t_seg));
    };
    // Inside the cone: g(t) = (x - p).a >= c |x - p|, i.e. g >= 0 and q(t) = g^2 - c^2
    // |x - p|^2 >= 0, a quadratic in t. A line meets a convex cone in one interval, and
    // whether t is inside changes only at the roots of q.
    let c = (cos_outer - 1e-3).max(0.0);
    let v = o - position;
    let (da, va) = (d.dot(axis), v.dot(axis));
    let c2 = c * c;
    let qa = da * da - c2 * d.length_squared();
    let qb = 2.0 * (da * va - c2 * d.dot(v));
    let qc = va * va - c2 * v.length_squared();
    let inside = |t: f32| {
        let g = va + t * da;
        g >= 0.0 && g * g >= c2 * (v + d * t).length_squared()
    };
    let mut cuts = [0.0f32; 4];
    let mut n = 0;
    let mut push = |t: f32| {
        if t > 0.0 && t < t_seg && t.is_finite() {
            cuts[n] = t;
            n += 1;
        }
    };
    if qa.abs() > 1e-12 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let r = disc.sqrt();
            push((-qb - r) / (2.0 * qa));
            push((-qb + r) / (2.0 * qa));
        }
    } else if qb != 0.0 {
        push(-qc / qb);
    }
    let cuts = &mut cuts[..n];
    cuts.sort_by(f32::total_cmp);
    // The pieces between 0, the roots and t_seg; the lit ones form one interval.
    let mut lit: Option<(f32, f32)> = None;
    let mut start = 0.0f32;
    for end in cuts.iter().copied().chain(std::iter::once(t_seg)) {
        let mid = if end.is_finite() {
            0.5 * (start + end)
        } else {
            2.0 * start + 1.0
        };
        if inside(mid) {
            lit = Some(lit.map_or((start, end), |(a, _)| (a, end)));
        }
        start = end;
    }
    lit
}

/// How many lights' weights [`equiangular_direct`]'s first walk keeps on the stack for its
/// second (the lights past them are weighed again).
const KEPT_EQUIANGULAR_WEIGHTS: usize = 64;

/// The fog's single scattering of the point and spot lights along one whole segment
/// (`ray` up to `t_seg`, in the fog), estimated by equiangular sampling (Kulla and Fajardo
/// 2012): a light is chosen in proportion to `I (theta_b - theta_a) / h`, the integral of its
/// `I / r^2` over the part of the segment it can light ([`lit_interval`]: a spot light's
/// cone), and a distance there with density proportional to `1 / r^2` toward it;
/// the estimate is `T(t) sigma_s(t) p(wo, wi) L_i T_light / (pmf pdf(t))`, bounded however
/// close the ray passes the light (a collision near a lamp would carry `1 / r^2`). It replaces
/// next-event estimation toward these lights at collisions ([`scatter_in_fog`]); directional
/// lights, emitter meshes and the environment stay there. `throughput` is the path's at the
/// segment's start; draws nothing (`u` is given); returns the rays traced. Walks the lights
/// twice, the second time reading the first walk's weights: no allocation.
#[allow(clippy::too_many_arguments)]
#[inline]
fn equiangular_direct(
    scene: &Scene,
    fog: &Fog,
    ray: &Ray,
    t_seg: f32,
    throughput: Vec3,
    u: Vec2,
    radiance: &mut Vec3,
) -> u64 {
    let (o, d) = (ray.origin, ray.direction);
    let weight = |light: &Light| {
        light_position(light).map_or(0.0, |(position, lum)| {
            let Some(lit) = lit_interval(light, o, d, t_seg) else {
                return 0.0;
            };
            let (h, _, span) = equiangular_frame(o, d, lit, position);
            let w = lum * span / h;
            if w.is_finite() && w > 0.0 {
                w
            } else {
                0.0
            }
        })
    };
    // The first walk keeps the weights of the first lights for the second (each costs two
    // arc tangents and the spot cone's interval).
    let mut kept = [0.0f32; KEPT_EQUIANGULAR_WEIGHTS];
    let mut total = 0.0f32;
    for (i, light) in scene.lights.iter().enumerate() {
        let w = weight(light);
        if let Some(k) = kept.get_mut(i) {
            *k = w;
        }
        total += w;
    }
    if !(total > 0.0 && total.is_finite()) {
        return 0;
    }
    let target = u.x * total;
    let (mut acc, mut chosen) = (0.0f32, None);
    for (i, light) in scene.lights.iter().enumerate() {
        let w = kept.get(i).copied().unwrap_or_else(|| weight(light));
        if w > 0.0 {
            chosen = Some((light, w));
            acc += w;
            if target < acc {
                break;
            }
        }
    }
    let Some((light, w)) = chosen else {
        return 0;
    };
    let (Some((position, _)), Some(lit)) =
        (light_position(light), lit_interval(light, o, d, t_seg))
    else {
        return 0;
    };
    let (h, delta, span) = equiangular_frame(o, d, lit, position);
    let a = equiangular_start(lit.0, h, delta);
    let t = (delta + h * (a + u.y * span).tan()).clamp(lit.0, lit.1);
    let off = t - delta;
    let pdf_t = h / (span * (h * h + off * off));
    let p = o + d * t;
    let Some(ls) = light.sample_li(p) else {
        return 0;
    };
    let phase = fog.phase().eval(-d, ls.wi);
    let li = visible_li(scene, &scene.light_sampler, p, p, &ls);
    if li.max_element() <= 0.0 {
        return 1;
    }
    let sigma_s = fog.sigma_t_at(p) * fog.albedo();
    let tr = fog.transmittance(o, d, t) * fog.transmittance(p, ls.wi, ls.dist);
    let estimate = throughput * tr * sigma_s * li * (phase * total / (w * pdf_t));
    if estimate.is_finite() {
        *radiance += estimate;
    }
    1
}

/// Next-event estimation at a collision with the fog at `rx.p` (a medium receiver): one light
/// sample, weighted by the phase function toward it and, unless it is a delta light, by the
/// power heuristic against phase sampling; the fog's transmittance on the shadow ray (to
/// infinity for the environment). With `positional_elsewhere`, a point or spot light chosen
/// adds nothing: [`equiangular_direct`] estimates their light along the whole segment. Draws
/// one 4D sample (light point and choice), as a surface vertex does; adds
/// `throughput`-weighted light to `radiance` and returns the rays traced.
#[allow(clippy::too_many_arguments)]
#[inline]
fn scatter_in_fog(
    scene: &Scene,
    fog: &Fog,
    rx: &Receiver,
    wo: Vec3,
    throughput: Vec3,
    positional_elsewhere: bool,
    sampler: &mut Sampler,
    radiance: &mut Vec3,
) -> u64 {
    let lights = &scene.light_sampler;
    let [px, py, u_light, _] = sampler.next_4d();
    let Some(ls) = lights.sample_li(
        &scene.materials,
        &scene.textures,
        rx,
        u_light,
        Vec2::new(px, py),
    ) else {
        return 0;
    };
    if positional_elsewhere && ls.delta && ls.dist.is_finite() {
        return 0;
    }
    let phase = fog.phase().eval(wo, ls.wi);
    if phase <= 0.0 || phase.is_nan() {
        return 0;
    }
    let li = visible_li(scene, lights, rx.p, rx.p, &ls);
    let li = if li.max_element() > 0.0 {
        li * fog.transmittance(rx.p, ls.wi, ls.dist)
    } else {
        li
    };
    if li.max_element() > 0.0 {
        let weight = if ls.delta {
            1.0
        } else {
            power_heuristic(1.0, ls.pdf, 1.0, phase)
        };
        *radiance += throughput * li * (phase * weight / ls.pdf);
    }
    1
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::light::Light;
    use crate::material::Material;
    use crate::medium::Fog;
    use crate::scene::SceneParts;
    use glam::{Affine3A, Quat};
    use std::f32::consts::PI;
    use streaks_image::color::luminance;

    pub(crate) fn camera(position: Vec3, pitch: f32, yfov: f32) -> Camera {
        Camera::perspective(
            "cam",
            Affine3A::from_rotation_translation(Quat::from_rotation_x(pitch), position),
            yfov,
            Some(1.5),
        )
    }

    /// A quad (two triangles) with the given corners, counter-clockwise seen from its front.
    pub(crate) fn quad(parts: &mut SceneParts, corners: [Vec3; 4], material: u32) {
        let base = parts.mesh.positions.len() as u32;
        parts.mesh.positions.extend_from_slice(&corners);
        parts.mesh.triangles.push([base, base + 1, base + 2]);
        parts.mesh.triangles.push([base, base + 2, base + 3]);
        parts.mesh.triangle_materials.extend([material, material]);
    }

    /// A 200 m floor at Y = 0 facing up, made of material 0.
    pub(crate) fn floor(parts: &mut SceneParts) {
        let s = 100.0;
        quad(
            parts,
            [
                Vec3::new(-s, 0.0, -s),
                Vec3::new(-s, 0.0, s),
                Vec3::new(s, 0.0, s),
                Vec3::new(s, 0.0, -s),
            ],
            0,
        );
    }

    fn settings(width: u32, height: u32, spp: u32, max_depth: u32) -> RenderJob {
        RenderJob {
            width,
            height,
            seed: 1,
            layers: Layers::default(),
            settings: RenderSettings::new(spp, max_depth),
            motion: Default::default(),
        }
    }

    /// The floor of diffuse reflectance `kd` under a point light of intensity `intensity` at
    /// `light_pos`: `(kd, light_pos, intensity, parts)`.
    fn lit_floor() -> (Vec3, Vec3, Vec3, SceneParts) {
        let kd = Vec3::new(0.5, 0.4, 0.3);
        let light_pos = Vec3::new(0.3, 2.0, -1.0);
        let intensity = Vec3::splat(10.0);
        let mut parts = SceneParts {
            materials: vec![Material::diffuse("floor", kd)],
            lights: vec![Light::Point {
                position: light_pos,
                intensity,
                range: None,
            }],
            ..Default::default()
        };
        floor(&mut parts);
        (kd, light_pos, intensity, parts)
    }

    #[test]
    fn diffuse_plane_under_point_light_matches_the_analytic_value() {
        let (kd, light_pos, intensity, parts) = lit_floor();
        let scene = Scene::from_parts(parts).unwrap();
        let cam = camera(Vec3::new(0.0, 1.5, 2.0), -0.6, 0.6);
        let (w, h) = (24, 16);
        let mut set = settings(w, h, 64, 2);
        set.layers.depth = true;
        set.layers.specular = true;
        let out = render(&scene, &cam, &set, &|_| {});
        assert_eq!(out.stats.samples, (w * h * 64) as u64);
        assert_eq!(out.stats.nonfinite_dropped, 0);
        // Radiance at film position `f`: I cos(theta) / r^2 * kd / pi.
        let analytic = |f: Vec2| {
            let ray = cam.generate_ray(f, w, h);
            let t = -ray.origin.y / ray.direction.y;
            let p = ray.at(t);
            let d = light_pos - p;
            intensity * kd * (d.y / d.length() / d.length_squared() / PI)
        };
        let k = 8;
        for y in 0..h {
            for x in 0..w {
                // The box filter's mean over the pixel, by a k x k grid.
                let mut expected = Vec3::ZERO;
                for i in 0..k {
                    for j in 0..k {
                        let o = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                        expected += analytic(Vec2::new(x as f32, y as f32) + o);
                    }
                }
                expected /= (k * k) as f32;
                let got = out.image.get(x, y);
                let err = ((got - expected) / expected).abs().max_element();
                assert!(err < 0.01, "pixel ({x}, {y}): {got} vs {expected}");
            }
        }
        // Depth of the pixel-centre ray along the camera axis; no glossy lobe, no specular.
        let fwd = cam.world_from_camera.transform_vector3(-Vec3::Z);
        let ray = cam.generate_ray(Vec2::new(3.5, 10.5), w, h);
        let z = (ray.at(-ray.origin.y / ray.direction.y) - ray.origin).dot(fwd);
        let depth = out.depth.unwrap()[10 * w as usize + 3];
        assert!((depth - z).abs() < 1e-4 * z, "{depth} vs {z}");
        assert!(out
            .specular
            .unwrap()
            .pixels
            .iter()
            .all(|s| *s == Vec3::ZERO));
        // max_depth 1: only emitters seen directly, so black.
        let out = render(&scene, &cam, &settings(w, h, 2, 1), &|_| {});
        assert!(out.image.pixels.iter().all(|p| *p == Vec3::ZERO));
    }

    /// A closed cube of half-size 1 around the origin whose walls face inward, are Lambertian of
    /// albedo `albedo` and emit `le` (one-sided, toward the inside).
    fn furnace_box(albedo: Vec3, le: Vec3) -> Scene {
        let mut wall = Material::diffuse("wall", albedo);
        wall.emission = le;
        let mut parts = SceneParts {
            materials: vec![wall],
            ..Default::default()
        };
        for axis in 0..3 {
            for side in [-1.0f32, 1.0] {
                // The face at coordinate `side` on `axis`; its two in-plane axes `u`, `v` are
                // ordered so that the winding's normal points inward (-side along `axis`).
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let (u, v) = if side > 0.0 { (u, v) } else { (v, u) };
                let corner = |a: f32, b: f32| {
                    let mut c = Vec3::ZERO;
                    c[axis] = side;
                    c[u] = a;
                    c[v] = b;
                    c
                };
                let corners = [
                    corner(-1.0, -1.0),
                    corner(-1.0, 1.0),
                    corner(1.0, 1.0),
                    corner(1.0, -1.0),
                ];
                let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
                debug_assert!(n[axis] * side < 0.0, "the wall faces inward");
                quad(&mut parts, corners, 0);
            }
        }
        Scene::from_parts(parts).unwrap()
    }

    /// The multi-bounce furnace: inside a closed box of albedo `a` whose walls all emit `Le`,
    /// the radiance in every direction is `L = Le + a L = Le / (1 - a)`. Every path vertex hits
    /// an emitter, so this checks emission, next-event estimation and BSDF sampling combined
    /// by MIS at every depth, and Russian roulette, against an exact answer.
    #[test]
    fn multi_bounce_furnace_gives_le_over_one_minus_albedo() {
        let le = Vec3::new(1.0, 0.5, 0.25);
        for a in [0.0f32, 0.5, 0.8] {
            let scene = furnace_box(Vec3::splat(a), le);
            let cam = camera(Vec3::new(0.1, -0.2, 0.3), 0.3, 1.2);
            let out = render(&scene, &cam, &settings(24, 16, 64, u32::MAX), &|_| {});
            let expected = le / (1.0 - a);
            let n = out.image.pixels.len() as f64;
            for c in 0..3 {
                let values: Vec<f64> = out.image.pixels.iter().map(|p| p[c] as f64).collect();
                let mean = values.iter().sum::<f64>() / n;
                let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
                let stderr = (var / n).sqrt();
                let want = expected[c] as f64;
                // Four standard errors, and a floor for the noiseless albedo-0 case.
                assert!(
                    (mean - want).abs() <= 4.0 * stderr + 1e-5 * want,
                    "albedo {a}, channel {c}: mean {mean} vs {want} (standard error {stderr})"
                );
                // Each pixel is an estimate of the same value.
                assert!(
                    values.iter().all(|v| (v - want).abs() < 0.25 * want),
                    "albedo {a}, channel {c}: a pixel off by more than 25%"
                );
            }
            if a == 0.0 {
                // Without reflection every pixel is exactly the emission seen directly.
                assert!(out
                    .image
                    .pixels
                    .iter()
                    .all(|p| (*p - le).abs().max_element() < 1e-6));
            }
        }
    }

    /// The emission layer is the light seen directly: in the furnace box (walls of albedo
    /// 0.5 emitting `Le`) every pixel's is exactly `Le`, the rest of the image (`Le a / (1 -
    /// a)` on average) is light that bounced; the layer is no part of the beauty image's sums.
    #[test]
    fn the_emission_layer_is_the_light_seen_directly() {
        let le = Vec3::new(1.0, 0.5, 0.25);
        let scene = furnace_box(Vec3::splat(0.5), le);
        let cam = camera(Vec3::new(0.1, -0.2, 0.3), 0.3, 1.2);
        let mut job = settings(12, 8, 16, u32::MAX);
        let plain = render(&scene, &cam, &job, &|_| {});
        job.layers.emission = true;
        let out = render(&scene, &cam, &job, &|_| {});
        assert_eq!(out.image, plain.image);
        assert!(plain.emission.is_none());
        let emission = out.emission.expect("the emission layer");
        for (e, p) in emission.pixels.iter().zip(&out.image.pixels) {
            assert!((*e - le).abs().max_element() < 1e-6, "{e}");
            assert!(p.cmpge(*e).all(), "{p} < {e}");
        }
    }

    /// A wall of emission `le` at z = -2 in front of a camera at the origin, whose front faces
    /// the camera if `facing`, and a floor of material 0.
    fn emitter_scene(le: Vec3, facing: bool, double_sided: bool) -> Scene {
        let mut wall = Material::diffuse("wall", Vec3::ZERO);
        wall.emission = le;
        wall.double_sided = double_sided;
        let mut parts = SceneParts {
            materials: vec![Material::diffuse("floor", Vec3::splat(0.5)), wall],
            ..Default::default()
        };
        let (a, b, c, d) = (
            Vec3::new(-50.0, -50.0, -2.0),
            Vec3::new(50.0, -50.0, -2.0),
            Vec3::new(50.0, 50.0, -2.0),
            Vec3::new(-50.0, 50.0, -2.0),
        );
        let corners = if facing { [a, b, c, d] } else { [a, d, c, b] };
        quad(&mut parts, corners, 1);
        Scene::from_parts(parts).unwrap()
    }

    #[test]
    fn emitter_seen_directly_has_exactly_its_radiance() {
        let le = Vec3::new(3.0, 2.0, 0.25);
        let cam = camera(Vec3::ZERO, 0.0, 0.8);
        for max_depth in [1, 2, 5] {
            let scene = emitter_scene(le, true, false);
            let mut set = settings(12, 8, 4, max_depth);
            set.layers.specular = true;
            let out = render(&scene, &cam, &set, &|_| {});
            for p in &out.image.pixels {
                assert!((*p - le).abs().max_element() < 1e-6, "{p}");
            }
            // A black emitter reflects nothing: no specular part.
            assert!(out
                .specular
                .unwrap()
                .pixels
                .iter()
                .all(|s| *s == Vec3::ZERO));
        }
        // Seen from behind: black if one-sided, `le` if double-sided.
        let out = render(
            &emitter_scene(le, false, false),
            &cam,
            &settings(6, 4, 2, 3),
            &|_| {},
        );
        assert!(out.image.pixels.iter().all(|p| *p == Vec3::ZERO));
        let out = render(
            &emitter_scene(le, false, true),
            &cam,
            &settings(6, 4, 2, 3),
            &|_| {},
        );
        assert!(out
            .image
            .pixels
            .iter()
            .all(|p| (*p - le).abs().max_element() < 1e-6));
    }

    #[test]
    fn mis_combines_light_and_bsdf_sampling_of_an_area_light() {
        // A diffuse floor under a huge one-sided emitting ceiling (facing down, 1 m above):
        // the floor's radiance is kd * L (the ceiling fills the hemisphere up to 1e-6).
        let (kd, le) = (Vec3::new(0.5, 0.25, 0.8), Vec3::new(2.0, 1.0, 0.5));
        let mut ceiling = Material::diffuse("ceiling", Vec3::ZERO);
        ceiling.emission = le;
        let mut parts = SceneParts {
            materials: vec![Material::diffuse("floor", kd), ceiling],
            ..Default::default()
        };
        floor(&mut parts);
        let s = 1000.0;
        quad(
            &mut parts,
            [
                Vec3::new(-s, 1.0, -s),
                Vec3::new(s, 1.0, -s),
                Vec3::new(s, 1.0, s),
                Vec3::new(-s, 1.0, s),
            ],
            1,
        );
        let scene = Scene::from_parts(parts).unwrap();
        let cam = camera(Vec3::new(0.0, 0.5, 0.0), -std::f32::consts::FRAC_PI_2, 0.5);
        let (w, h) = (12, 8);
        let out = render(&scene, &cam, &settings(w, h, 64, 2), &|_| {});
        let expected = kd * le;
        let mut mean = Vec3::ZERO;
        for p in &out.image.pixels {
            assert!(
                ((*p - expected) / expected).abs().max_element() < 0.1,
                "{p}"
            );
            mean += *p / (w * h) as f32;
        }
        let err = ((mean - expected) / expected).abs().max_element();
        assert!(err < 0.01, "{mean} vs {expected}");
    }

    #[test]
    fn non_finite_samples_are_dropped_and_counted() {
        let scene = emitter_scene(Vec3::new(f32::NAN, 1.0, 1.0), true, false);
        let cam = camera(Vec3::ZERO, 0.0, 0.8);
        let out = render(&scene, &cam, &settings(6, 4, 3, 3), &|_| {});
        assert_eq!(out.stats.nonfinite_dropped, 6 * 4 * 3);
        assert!(out.image.pixels.iter().all(|p| *p == Vec3::ZERO));
    }

    /// A glossy floor (tagged as the road), an emissive sign (above the view of the test
    /// camera, seen only in reflection; unlabelled) and two punctual lights, for the
    /// determinism and specular-layer tests.
    fn street(kd: Vec3, ks: Vec3) -> Scene {
        let mut sign = Material::diffuse("sign", Vec3::ZERO);
        sign.emission = Vec3::new(4.0, 2.0, 1.0);
        let road = Material::glossy_road("road", kd, ks, 0.15);
        let mut parts = SceneParts {
            materials: vec![road, sign],
            lights: vec![
                Light::Point {
                    position: Vec3::new(-1.0, 3.0, -6.0),
                    intensity: Vec3::splat(30.0),
                    range: None,
                },
                Light::Spot {
                    position: Vec3::new(2.0, 4.0, -10.0),
                    direction: -Vec3::Y,
                    intensity: Vec3::new(80.0, 60.0, 40.0),
                    cos_inner: 0.9,
                    cos_outer: 0.6,
                    range: Some(20.0),
                },
            ],
            ..Default::default()
        };
        floor(&mut parts);
        quad(
            &mut parts,
            [
                Vec3::new(-1.0, 5.4, -12.0),
                Vec3::new(1.0, 5.4, -12.0),
                Vec3::new(1.0, 6.6, -12.0),
                Vec3::new(-1.0, 6.6, -12.0),
            ],
            1,
        );
        parts.objects = crate::scene::base_table();
        parts.objects.push(crate::scene::SceneObject {
            class: Some(crate::class::Class::Road),
            instance: 0,
        });
        parts.mesh.triangle_objects = vec![2, 2, 1, 1];
        Scene::from_parts(parts).unwrap()
    }

    #[test]
    fn same_image_with_one_and_two_threads() {
        let scene = street(Vec3::splat(0.2), Vec3::splat(0.3));
        let cam = camera(Vec3::new(0.0, 1.5, 0.0), -0.1, 0.7);
        let mut set = settings(20, 12, 4, 4);
        set.layers = Layers {
            depth: true,
            normal: true,
            albedo: true,
            specular: true,
            material: true,
            object: true,
            spp: true,
            rain: true,
            fog: true,
            emission: true,
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| render(&scene, &cam, &set, &|_| {}))
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one.image, two.image);
        assert_eq!(one.specular, two.specular);
        assert_eq!(one.depth, two.depth);
        assert_eq!(one.material, two.material);
        assert!(one.image.pixels.iter().any(|p| p.max_element() > 0.0));
        // The material layer: the floor (material 0, the road) where the depth is finite
        // below the horizon, nothing where the centre ray misses.
        let material = one.material.as_ref().unwrap();
        let depth = one.depth.as_ref().unwrap();
        for (m, z) in material.iter().zip(depth) {
            assert_eq!(*m == crate::film::NO_MATERIAL, z.is_infinite(), "{m} {z}");
        }
        assert!(material.contains(&0));
        assert!(material.contains(&crate::film::NO_MATERIAL));
        assert!(scene.materials[0].road && !scene.materials[1].road);
        // The object layer, by the same ray: the floor's slot (the road) where the depth is
        // finite, the sky's on a miss.
        assert_eq!(one.object, two.object);
        let object = one.object.as_ref().unwrap();
        for (o, z) in object.iter().zip(depth) {
            let want = if z.is_finite() {
                2
            } else {
                crate::scene::SKY_OBJECT
            };
            assert_eq!(*o, want, "{z}");
        }
        assert!(object.contains(&2) && object.contains(&crate::scene::SKY_OBJECT));
        assert_eq!(scene.objects[2].class, Some(crate::class::Class::Road));
        // Asking for the layers does not change the image.
        set.layers = Layers::default();
        let plain = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| render(&scene, &cam, &set, &|_| {}));
        assert_eq!(plain.image, one.image);
        assert!(plain.material.is_none() && plain.object.is_none());
        // Another seed gives another image.
        set.seed = 2;
        let other = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| render(&scene, &cam, &set, &|_| {}));
        assert_ne!(one.image, other.image);
    }

    /// Renders on a pool of `threads` workers.
    fn render_on(threads: usize, scene: &Scene, cam: &Camera, set: &RenderJob) -> RenderOutput {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(scene, cam, set, &|_| {}))
    }

    #[test]
    fn adaptive_sampling_is_deterministic_and_respects_the_cap() {
        let scene = street(Vec3::splat(0.2), Vec3::splat(0.3));
        let cam = camera(Vec3::new(0.0, 1.5, 0.0), -0.1, 0.7);
        // Three rows of tiles, the last column of tiles 8 pixels wide; the top row of tiles
        // sees only the black sky (the horizon is near y = 17).
        let (w, h, cap) = (40, 48, 96);
        let mut set = settings(w, h, cap, 4);
        set.settings.noise_target = Some(0.02);
        set.layers.spp = true;
        set.layers.specular = true;
        set.layers.depth = true;
        let progress = AtomicU64::new(0);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| {
                render(&scene, &cam, &set, &|n| {
                    progress.fetch_add(n, Ordering::Relaxed);
                })
            });
        let two = render_on(2, &scene, &cam, &set);
        assert_eq!(one.image, two.image);
        assert_eq!(one.specular, two.specular);
        assert_eq!(one.spp, two.spp);
        assert_eq!(one.depth, two.depth);
        // The progress bar reaches its total although tiles stopped early.
        assert_eq!(progress.into_inner(), (w * h * cap) as u64);
        let spp = one.spp.as_ref().unwrap();
        let at = |x: u32, y: u32| spp[(y * w + x) as usize];
        let t = ADAPTIVE_TILE;
        for y in 0..h {
            for x in 0..w {
                let n = at(x, y);
                // Every count is the minimum plus whole batches, or the cap, and the same in
                // the whole tile.
                assert!(
                    (ADAPTIVE_MIN_SPP..=cap).contains(&n)
                        && ((n - ADAPTIVE_MIN_SPP) % ADAPTIVE_BATCH == 0 || n == cap),
                    "{n}"
                );
                assert_eq!(n, at(x / t * t, y / t * t), "pixel ({x}, {y})");
            }
        }
        // The sky (black) stops at the minimum; the lit road takes more samples.
        let depth = one.depth.as_ref().unwrap();
        assert!(depth[..(t * w) as usize].iter().all(|z| z.is_infinite()));
        assert_eq!(at(0, 0), ADAPTIVE_MIN_SPP);
        assert!(spp.iter().any(|&n| n > ADAPTIVE_MIN_SPP));
        assert_eq!(
            one.stats.samples,
            spp.iter().map(|&n| n as u64).sum::<u64>()
        );
        assert!(one.stats.samples < (w * h * cap) as u64);
        // Not the fixed-spp image, and the fixed-spp render's layer is the cap everywhere.
        set.settings.noise_target = None;
        let fixed = render_on(2, &scene, &cam, &set);
        assert_ne!(fixed.image, one.image);
        assert!(fixed.spp.unwrap().iter().all(|&n| n == cap));
        // A tile that ran to the cap has the fixed-spp render's pixels, bit for bit.
        let full = spp
            .iter()
            .position(|&n| n == cap)
            .expect("a tile runs to the cap");
        assert_eq!(fixed.image.pixels[full], one.image.pixels[full]);
        // A cap at or below the minimum is fixed-spp sampling, bit for bit.
        set.settings.spp = ADAPTIVE_MIN_SPP;
        let fixed = render_on(2, &scene, &cam, &set);
        set.settings.noise_target = Some(0.05);
        let capped = render_on(1, &scene, &cam, &set);
        assert_eq!(fixed.image, capped.image);
        assert_eq!(fixed.stats.samples, capped.stats.samples);
        assert_eq!(fixed.stats.rays, capped.stats.rays);
        set.settings.spp = 5;
        let small = render_on(1, &scene, &cam, &set);
        assert!(small.spp.unwrap().iter().all(|&n| n == 5));
    }

    #[test]
    fn tile_error_is_the_rms_standard_error_over_the_mean() {
        let pixel = |values: &[f32]| {
            let mut p = Pixel::default();
            for &v in values {
                p.add_sample(Vec3::splat(v), Vec3::ZERO);
            }
            p
        };
        // Variances of the means 1 (samples 1, 3) and 0 (2, 2); means 2 and 2.
        let err = tile_relative_error([pixel(&[1.0, 3.0]), pixel(&[2.0, 2.0])].into_iter());
        assert!((err - (0.5f64).sqrt() / 2.0).abs() < 1e-7, "{err}");
        // A pixel without an estimate keeps the tile going; black tiles stop.
        assert!(tile_relative_error([pixel(&[1.0]), pixel(&[2.0, 2.0])].into_iter()).is_infinite());
        assert_eq!(tile_relative_error([pixel(&[0.0, 0.0])].into_iter()), 0.0);
        // Below the dark floor the standard error is measured against the floor.
        let dim = tile_relative_error([pixel(&[1e-5, 3e-5])].into_iter());
        assert!(
            (dim - 1e-5 / ADAPTIVE_DARK_FLOOR as f64).abs() < 1e-9,
            "{dim}"
        );
    }

    #[test]
    fn adaptive_sampling_stops_flat_pixels_and_runs_noisy_ones_to_the_cap() {
        let le = Vec3::new(1.0, 0.5, 0.25);
        let cam = camera(Vec3::new(0.1, -0.2, 0.3), 0.3, 1.2);
        let (w, h, cap) = (12, 8, 64);
        let mut set = settings(w, h, cap, u32::MAX);
        set.layers.spp = true;
        // Albedo 0: every sample is exactly the emission, zero variance: all stop at the
        // minimum, however tight the target.
        set.settings.noise_target = Some(1e-6);
        let flat = render(&furnace_box(Vec3::ZERO, le), &cam, &set, &|_| {});
        assert!(flat
            .spp
            .as_ref()
            .unwrap()
            .iter()
            .all(|&n| n == ADAPTIVE_MIN_SPP));
        assert_eq!(flat.stats.samples, (w * h * ADAPTIVE_MIN_SPP) as u64);
        assert!(flat
            .image
            .pixels
            .iter()
            .all(|p| (*p - le).abs().max_element() < 1e-6));
        // Albedo 0.8: multiple bounces, a relative error of ~10% per pixel at 16 samples; a
        // target of 1e-3 is out of reach, so every pixel takes the cap and no more.
        let noisy_scene = furnace_box(Vec3::splat(0.8), le);
        let noisy = render(&noisy_scene, &cam, &set, &|_| {});
        assert!(noisy.spp.as_ref().unwrap().iter().all(|&n| n == cap));
        assert_eq!(noisy.stats.samples, (w * h * cap) as u64);
        // The pixels' spread at one sample each is the relative standard deviation of one
        // sample, `r`, so the tile's error after n samples is about `r / sqrt(n)`: a target of
        // `r / sqrt(30)` stops the tile in between (near 32 samples), and the estimate stays
        // close to Le / (1 - a).
        let one = render(&noisy_scene, &cam, &settings(w, h, 1, u32::MAX), &|_| {});
        let lum: Vec<f32> = one.image.pixels.iter().map(|p| luminance(*p)).collect();
        let m = lum.iter().sum::<f32>() / lum.len() as f32;
        let r =
            (lum.iter().map(|l| (l - m).powi(2)).sum::<f32>() / (lum.len() - 1) as f32).sqrt() / m;
        set.settings.noise_target = Some(r / 30f32.sqrt());
        let mid = render(&noisy_scene, &cam, &set, &|_| {});
        let spp = mid.spp.as_ref().unwrap();
        let mean_spp = spp.iter().map(|&n| n as f64).sum::<f64>() / spp.len() as f64;
        assert!(
            mean_spp > ADAPTIVE_MIN_SPP as f64 && mean_spp < cap as f64,
            "{mean_spp}"
        );
        let expected = luminance(le / 0.2);
        let mean = mid.image.pixels.iter().map(|p| luminance(*p)).sum::<f32>()
            / mid.image.pixels.len() as f32;
        assert!((mean / expected - 1.0).abs() < 0.03, "{mean} vs {expected}");
        // The same noisy furnace a million times dimmer, below the dark floor: the error is
        // measured against the floor, and every pixel stops at the minimum.
        let empty = furnace_box(Vec3::splat(0.8), le * 1e-6);
        let dark = render(&empty, &cam, &set, &|_| {});
        assert!(dark.spp.unwrap().iter().all(|&n| n == ADAPTIVE_MIN_SPP));
    }

    /// A wall of emission `le` at z = -2 in front of a camera at the origin (looking along
    /// -Z, field of view `yfov`), and in front of it, at z = -1, one square emitter of
    /// radiance `bright` per pixel of a `w` x `h` image, centred in the pixel's footprint and
    /// covering `1 / k^2` of it: every pixel's camera ray sees the bright square with
    /// probability exactly `1 / k^2` (the film maps a plane parallel to it uniformly).
    fn speckled_wall(le: Vec3, bright: Vec3, yfov: f32, (w, h): (u32, u32), k: f32) -> Scene {
        let mut wall = Material::diffuse("wall", Vec3::ZERO);
        wall.emission = le;
        let mut speck = Material::diffuse("speck", Vec3::ZERO);
        speck.emission = bright;
        let mut parts = SceneParts {
            materials: vec![wall, speck],
            ..Default::default()
        };
        let s = 50.0;
        quad(
            &mut parts,
            [
                Vec3::new(-s, -s, -2.0),
                Vec3::new(s, -s, -2.0),
                Vec3::new(s, s, -2.0),
                Vec3::new(-s, s, -2.0),
            ],
            0,
        );
        // Film pixel coordinates to the plane z = -1: x right, y down, focal length f.
        let f = 0.5 * h as f32 / (0.5 * yfov).tan();
        let at = |fx: f32, fy: f32| {
            Vec3::new((fx - 0.5 * w as f32) / f, (0.5 * h as f32 - fy) / f, -1.0)
        };
        let half = 0.5 / k;
        for y in 0..h {
            for x in 0..w {
                let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
                let corners = [
                    at(cx - half, cy + half),
                    at(cx + half, cy + half),
                    at(cx + half, cy - half),
                    at(cx - half, cy - half),
                ];
                quad(&mut parts, corners, 1);
            }
        }
        Scene::from_parts(parts).unwrap()
    }

    /// A rare bright path: every pixel sees a bright speck with probability 1/36 per sample
    /// on a flat wall. Two thirds of the pixels show no speck in their first 16 samples, so a
    /// rule that judged each pixel by its own samples would stop them there with a zero
    /// variance and the image would be far too dark; the tile's pooled error sees the specks
    /// of its other pixels, and the image mean stays within its noise of the exact value.
    #[test]
    fn adaptive_sampling_is_unbiased_on_a_rare_bright_path() {
        let (w, h, k) = (32, 32, 6.0);
        let (le, bright) = (Vec3::splat(0.5), Vec3::splat(50.0));
        let yfov = 0.8;
        let scene = speckled_wall(le, bright, yfov, (w, h), k);
        let cam = camera(Vec3::ZERO, 0.0, yfov);
        let cap = 512;
        let mut set = settings(w, h, cap, 1);
        set.layers.spp = true;
        set.settings.noise_target = Some(0.5);
        let out = render_on(2, &scene, &cam, &set);
        let p = 1.0 / (k * k);
        let expected = luminance(le) * (1.0 - p) + luminance(bright) * p;
        let lum: Vec<f64> = out
            .image
            .pixels
            .iter()
            .map(|c| luminance(*c) as f64)
            .collect();
        let n = lum.len() as f64;
        let mean = lum.iter().sum::<f64>() / n;
        let sd = (lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let stderr = sd / n.sqrt();
        assert!(
            (mean - expected as f64).abs() < 4.0 * stderr,
            "mean {mean} vs {expected} (standard error {stderr})"
        );
        // It did stop early: well below the cap on average.
        let spp = out.spp.unwrap();
        let mean_spp = spp.iter().map(|&s| s as f64).sum::<f64>() / n;
        assert!(mean_spp < 0.5 * cap as f64, "{mean_spp}");
    }

    #[test]
    fn specular_layer_is_the_glossy_direct_light() {
        let cam = camera(Vec3::new(0.0, 1.5, 0.0), -0.1, 0.7);
        let mut set = settings(16, 10, 8, 2);
        set.layers.specular = true;
        let progress = AtomicU64::new(0);
        // No diffuse lobe: at max depth 2 everything is single-glossy-bounce light.
        let out = render(&street(Vec3::ZERO, Vec3::splat(0.5)), &cam, &set, &|n| {
            progress.fetch_add(n, Ordering::Relaxed);
        });
        assert_eq!(progress.into_inner(), 16 * 10 * 8);
        let spec = out.specular.unwrap();
        let mut lit = 0;
        for (s, p) in spec.pixels.iter().zip(&out.image.pixels) {
            assert!(
                (*s - *p).abs().max_element() <= 1e-5 * p.max_element().max(1.0),
                "{s} {p}"
            );
            lit += (p.max_element() > 0.0) as usize;
        }
        assert!(lit > 0);
        // No glossy lobe: no specular part.
        let out = render(&street(Vec3::splat(0.5), Vec3::ZERO), &cam, &set, &|_| {});
        assert!(out
            .specular
            .unwrap()
            .pixels
            .iter()
            .all(|s| *s == Vec3::ZERO));
    }

    /// Path regularisation changes no path of the first bounce: with and without it, the
    /// specular layer (camera, road, emitter) is bit-identical, and so is the whole image at
    /// max depth 2 (direct light only); deeper paths (road, wall, road, lamp) change.
    #[test]
    fn regularisation_leaves_the_first_bounce_unchanged() {
        // The street with a diffuse wall beside the road, so that paths reach the glossy
        // road again after a diffuse bounce.
        let mut sign = Material::diffuse("sign", Vec3::ZERO);
        sign.emission = Vec3::new(40.0, 20.0, 10.0);
        let road = Material::glossy_road("road", Vec3::splat(0.1), Vec3::splat(0.5), 0.02);
        let mut parts = SceneParts {
            materials: vec![road, sign, Material::diffuse("wall", Vec3::splat(0.6))],
            lights: vec![Light::Point {
                position: Vec3::new(-1.0, 3.0, -6.0),
                intensity: Vec3::splat(30.0),
                range: None,
            }],
            ..Default::default()
        };
        floor(&mut parts);
        quad(
            &mut parts,
            [
                Vec3::new(-0.3, 0.2, -12.0),
                Vec3::new(0.3, 0.2, -12.0),
                Vec3::new(0.3, 0.5, -12.0),
                Vec3::new(-0.3, 0.5, -12.0),
            ],
            1,
        );
        quad(
            &mut parts,
            [
                Vec3::new(3.0, 0.0, 5.0),
                Vec3::new(3.0, 0.0, -30.0),
                Vec3::new(3.0, 8.0, -30.0),
                Vec3::new(3.0, 8.0, 5.0),
            ],
            2,
        );
        let scene = Scene::from_parts(parts).unwrap();
        let cam = camera(Vec3::new(0.0, 1.5, 0.0), -0.1, 0.7);
        let mut set = settings(24, 16, 8, 6);
        set.layers.specular = true;
        let plain = render(&scene, &cam, &set, &|_| {});
        set.settings.regularize = true;
        let reg = render(&scene, &cam, &set, &|_| {});
        assert_eq!(plain.specular, reg.specular);
        assert!(plain
            .specular
            .as_ref()
            .unwrap()
            .pixels
            .iter()
            .any(|p| p.max_element() > 0.0));
        assert_ne!(plain.image, reg.image);
        let mean =
            |o: &RenderOutput| o.image.pixels.iter().sum::<Vec3>() / o.image.pixels.len() as f32;
        let (a, b) = (mean(&plain), mean(&reg));
        assert!(
            ((a - b) / a).abs().max_element() < 0.2,
            "mean radiance {a} plain, {b} regularised"
        );
        set.settings.max_depth = 2;
        let plain2 = render(&scene, &cam, &set, &|_| {});
        set.settings.regularize = false;
        let reg2 = render(&scene, &cam, &set, &|_| {});
        assert_eq!(plain2.image, reg2.image);
        assert_eq!(plain2.specular, reg2.specular);
    }

    #[test]
    fn regularized_alpha_follows_cycles() {
        assert_eq!(regularized_alpha(f32::INFINITY), None);
        assert_eq!(regularized_alpha(1.0), None);
        assert_eq!(regularized_alpha(50.0), None);
        assert_eq!(regularized_alpha(0.0), Some(0.5));
        // After a Lambertian bounce at normal incidence (density 1 / pi).
        let a = regularized_alpha(std::f32::consts::FRAC_1_PI).unwrap();
        assert!((a - 0.5 * (1.0 - std::f32::consts::FRAC_1_PI).sqrt()).abs() < 1e-7);
        assert!((0.41..0.42).contains(&a), "{a}");
    }

    /// A glass box between the camera (on +Z, looking down -Z through a narrow field of view)
    /// and an emitting wall of radiance 1 at z = -3: 20 m wide, from z = -`thickness` to 0,
    /// its faces wound outward, smooth (roughness 0), white, transmission 1, with a volume of
    /// attenuation colour `attenuation` at 1 m if `volume`.
    fn glass_slab(thickness: f32, volume: Option<Vec3>) -> Scene {
        use crate::material::{GltfPbrParams, Reflectance, Volume};
        let mut wall = Material::diffuse("wall", Vec3::ZERO);
        wall.emission = Vec3::ONE;
        let mut glass = Material::diffuse("glass", Vec3::ONE);
        glass.reflectance = Reflectance::GltfPbr(GltfPbrParams {
            metallic: 0.0,
            roughness: 0.0,
            transmission: 1.0,
            volume: volume.map(|c| Volume::new(thickness, c, 1.0)),
            ..GltfPbrParams::default()
        });
        let mut parts = SceneParts {
            materials: vec![wall, glass],
            ..Default::default()
        };
        let (s, z0) = (10.0, -thickness);
        quad(
            &mut parts,
            [
                Vec3::new(-50.0, -50.0, -3.0),
                Vec3::new(50.0, -50.0, -3.0),
                Vec3::new(50.0, 50.0, -3.0),
                Vec3::new(-50.0, 50.0, -3.0),
            ],
            0,
        );
        // The box: every face counter-clockwise seen from outside.
        let c = |x: f32, y: f32, z: f32| Vec3::new(x * s, y * s, z);
        let faces = [
            [
                c(-1.0, -1.0, 0.0),
                c(1.0, -1.0, 0.0),
                c(1.0, 1.0, 0.0),
                c(-1.0, 1.0, 0.0),
            ],
            [
                c(-1.0, -1.0, z0),
                c(-1.0, 1.0, z0),
                c(1.0, 1.0, z0),
                c(1.0, -1.0, z0),
            ],
            [
                c(-1.0, -1.0, z0),
                c(1.0, -1.0, z0),
                c(1.0, -1.0, 0.0),
                c(-1.0, -1.0, 0.0),
            ],
            [
                c(-1.0, 1.0, z0),
                c(-1.0, 1.0, 0.0),
                c(1.0, 1.0, 0.0),
                c(1.0, 1.0, z0),
            ],
            [
                c(-1.0, -1.0, z0),
                c(-1.0, -1.0, 0.0),
                c(-1.0, 1.0, 0.0),
                c(-1.0, 1.0, z0),
            ],
            [
                c(1.0, -1.0, z0),
                c(1.0, 1.0, z0),
                c(1.0, 1.0, 0.0),
                c(1.0, -1.0, 0.0),
            ],
        ];
        for f in faces {
            quad(&mut parts, f, 1);
        }
        Scene::from_parts(parts).unwrap()
    }

    /// The mean radiance of a render of `scene` from z = 2 looking at -Z (normal incidence
    /// within 0.01 rad), and its standard error.
    fn slab_mean(scene: &Scene) -> (Vec3, f64) {
        let cam = camera(Vec3::new(0.0, 0.0, 2.0), 0.0, 0.02);
        let out = render(scene, &cam, &settings(12, 8, 256, u32::MAX), &|_| {});
        let n = out.image.pixels.len() as f64;
        let mean = out.image.pixels.iter().sum::<Vec3>() / n as f32;
        let var = out
            .image
            .pixels
            .iter()
            .map(|p| ((p.x - mean.x) as f64).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        (mean, (var / n).sqrt())
    }

    /// Through a smooth pane of two faces, with all inter-reflections between them, a pane
    /// transmits `(1 - F)^2 / (1 - F^2) = (1 - F) / (1 + F)` at normal incidence, F = 0.04: the
    /// same thin-walled (each face an interface without bending) and as a volume (refracting in
    /// and out; the radiance factors `1 / ior^2` and `ior^2` cancel). With absorption
    /// `tau = exp(-sigma_a d)` across the thickness d, Beer-Lambert inside:
    /// `T = (1 - F)^2 tau / (1 - F^2 tau^2)`.
    #[test]
    fn glass_slab_transmits_the_analytic_fraction() {
        let f = crate::bsdf::ior_f0(1.5);
        let clear = (1.0 - f) / (1.0 + f);
        for volume in [None, Some(Vec3::ONE)] {
            let (mean, err) = slab_mean(&glass_slab(0.05, volume));
            assert!(
                (mean - Vec3::splat(clear)).abs().max_element() < (4.0 * err as f32).max(2e-3),
                "volume {volume:?}: {mean} vs {clear} (standard error {err})"
            );
        }
        // attenuationColor (0.5, 0.8, 1) at 1 m, through 0.4 m.
        let colour = Vec3::new(0.5, 0.8, 1.0);
        let (mean, err) = slab_mean(&glass_slab(0.4, Some(colour)));
        let tau = colour.powf(0.4);
        let want = (1.0 - f) * (1.0 - f) * tau / (Vec3::ONE - f * f * tau * tau);
        assert!(
            (mean - want).abs().max_element() < (4.0 * err as f32).max(2e-3),
            "{mean} vs {want} (standard error {err})"
        );
    }

    /// The floor of [`floor`] made of `material` under `environment`, with `lights`.
    fn floor_under(
        material: Material,
        environment: crate::light::Environment,
        lights: Vec<Light>,
    ) -> Scene {
        let mut parts = SceneParts {
            materials: vec![material],
            lights,
            environment: Some(environment),
            ..Default::default()
        };
        floor(&mut parts);
        Scene::from_parts(parts).unwrap()
    }

    /// The mean pixel of a render.
    fn mean_pixel(out: &RenderOutput) -> Vec3 {
        out.image.pixels.iter().copied().sum::<Vec3>() / out.image.pixels.len() as f32
    }

    /// The furnace under the sky: a white-ish diffuse floor under a uniform environment of
    /// radiance 1 sees the whole upper hemisphere of it, so its radiance is its albedo; the
    /// sky seen directly is exactly 1, and the AOVs keep their miss values there.
    #[test]
    fn diffuse_floor_under_a_constant_environment_has_its_albedo() {
        use crate::light::Environment;
        let kd = Vec3::new(0.8, 0.5, 0.2);
        let env = Environment::constant(Vec3::ONE, 1.0).unwrap();
        let scene = floor_under(Material::diffuse("floor", kd), env, vec![]);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let cam = camera(Vec3::new(0.0, 1.5, 2.0), -0.6, 0.6);
        let out = render(&scene, &cam, &settings(24, 16, 64, 8), &|_| {});
        let mean = mean_pixel(&out);
        assert!(
            (mean - kd).abs().max_element() < 0.01 * kd.max_element(),
            "{mean} vs {kd}"
        );
        // Looking up: the sky only, exactly.
        let up = camera(Vec3::new(0.0, 1.5, 2.0), 1.2, 0.6);
        let mut set = settings(8, 6, 4, 8);
        set.layers.depth = true;
        set.layers.normal = true;
        let out = render(&scene, &up, &set, &|_| {});
        assert!(out.image.pixels.iter().all(|p| *p == Vec3::ONE));
        assert!(out.depth.unwrap().iter().all(|d| *d == f32::INFINITY));
        assert!(out.normal.unwrap().pixels.iter().all(|n| *n == Vec3::ZERO));
    }

    /// A map of one colour is the constant environment sampled another way (in proportion to
    /// sin theta): the same image within the noise, on a glossy floor (MIS of the map's
    /// sampling with the GGX lobe's) with a point light beside it (the share between the
    /// environment and the tree). The specular layer holds the sky's streak.
    #[test]
    fn a_uniform_map_lights_as_the_constant_environment_does() {
        use crate::light::{Environment, EnvironmentMap};
        let road = Material::glossy_road("road", Vec3::splat(0.1), Vec3::splat(0.5), 0.1);
        let lamp = vec![Light::Point {
            position: Vec3::new(0.5, 3.0, -3.0),
            intensity: Vec3::splat(3.0),
            range: None,
        }];
        let colour = Vec3::new(0.3, 0.4, 0.6);
        let constant = Environment::constant(colour, 1.0).unwrap();
        let image = RgbImage::from_fn(16, 9, |_, _| colour);
        let map = Environment::Map(Box::new(
            EnvironmentMap::new(std::path::Path::new("sky.exr"), &image, 1.0).unwrap(),
        ));
        let cam = camera(Vec3::new(0.0, 1.5, 2.0), -0.4, 0.6);
        let mut set = settings(24, 16, 256, 3);
        set.layers.specular = true;
        let a = render(
            &floor_under(road.clone(), constant, lamp.clone()),
            &cam,
            &set,
            &|_| {},
        );
        let b = render(&floor_under(road, map, lamp), &cam, &set, &|_| {});
        let (ma, mb) = (mean_pixel(&a), mean_pixel(&b));
        assert!(
            (ma - mb).abs().max_element() < 0.01 * ma.max_element(),
            "{ma} vs {mb}"
        );
        let spec = a.specular.unwrap();
        let spec_mean = spec.pixels.iter().copied().sum::<Vec3>() / spec.pixels.len() as f32;
        assert!(spec_mean.min_element() > 0.0 && spec_mean.max_element() < ma.max_element());
        // The sky's reflection is bluish, like the sky.
        assert!(spec_mean.z > spec_mean.x, "{spec_mean}");
    }

    /// Without any light the scene gets the default environment and one warning, which an
    /// environment set afterwards (a command's `--env`) takes away.
    #[test]
    fn a_scene_without_lights_is_lit_by_the_default_environment() {
        use crate::light::Environment;
        use crate::scene::{DEFAULT_ENVIRONMENT_RADIANCE, NO_LIGHT_WARNING};
        let mut parts = SceneParts {
            source: "dark.gltf".into(),
            materials: vec![Material::diffuse("floor", Vec3::splat(0.5))],
            ..Default::default()
        };
        floor(&mut parts);
        let mut scene = Scene::from_parts(parts.clone()).unwrap();
        assert_eq!(
            scene.warnings,
            vec![format!("dark.gltf: {NO_LIGHT_WARNING}")]
        );
        assert_eq!(
            scene.environment(),
            Some(&Environment::Constant {
                radiance: Vec3::splat(DEFAULT_ENVIRONMENT_RADIANCE)
            })
        );
        let cam = camera(Vec3::new(0.0, 1.5, 2.0), -0.6, 0.6);
        let out = render(&scene, &cam, &settings(12, 8, 16, 2), &|_| {});
        assert!(mean_pixel(&out).min_element() > 0.45);
        scene.set_environment(Environment::constant(Vec3::ONE, 0.5).unwrap());
        assert!(scene.warnings.is_empty());
        // A light of any kind is enough to go without.
        parts.lights.push(Light::Directional {
            direction: -Vec3::Y,
            irradiance: Vec3::ONE,
        });
        let lit = Scene::from_parts(parts).unwrap();
        assert!(lit.warnings.is_empty() && lit.environment().is_none());
    }

    /// A camera at the origin looking down -Z with a field of view so narrow that its one
    /// pixel is a single ray.
    fn pencil() -> Camera {
        camera(Vec3::ZERO, 0.0, 1e-4)
    }

    /// Single scattering toward the pencil camera, by the midpoint rule along its ray out to
    /// `t_end`: `int sigma_s(t) T(t) [int over the light of p(wo, wi) T(r) dE(r)] dt`, with
    /// `light(p)` giving the light's `(wi, r, irradiance)` pieces at `p`.
    fn single_scattering(
        fog: &Fog,
        t_end: f32,
        light: impl Fn(Vec3) -> Vec<(Vec3, f32, Vec3)>,
    ) -> Vec3 {
        let (o, d) = (Vec3::ZERO, -Vec3::Z);
        let steps = 4000;
        let h = t_end / steps as f32;
        let mut sum = Vec3::ZERO;
        for i in 0..steps {
            let t = (i as f32 + 0.5) * h;
            let p = o + d * t;
            let mut inscatter = Vec3::ZERO;
            for (wi, r, e) in light(p) {
                let phase = fog.phase().eval(-d, wi);
                inscatter += e * phase * fog.transmittance(p, wi, r);
            }
            sum += fog.sigma_t_at(p) * fog.albedo() * fog.transmittance(o, d, t) * inscatter * h;
        }
        sum
    }

    fn foggy_scene(parts: SceneParts, fog: Fog) -> Scene {
        Scene::from_parts(SceneParts {
            fog: Some(fog),
            ..parts
        })
        .unwrap()
    }

    /// The one-arc-tangent span of [`equiangular_frame`] is `theta_b - theta_a` computed in
    /// f64 from the two angles, to a few float roundings, for intervals before, around and
    /// after the closest approach, unbounded ones, and rays that pass the light within its
    /// 1e-4 floor; and `theta_a` plus the span reaches the interval's end.
    #[test]
    fn equiangular_span_is_the_difference_of_the_angles() {
        let mut rng = crate::sampling::Pcg32::new(11, 3);
        for k in 0..20_000 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 40.0 - 20.0;
            let d = Vec3::new(
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
            )
            .normalize();
            let t0 = rng.next_f32() * 30.0;
            let t1 = match k % 4 {
                0 => f32::INFINITY,
                _ => t0 + rng.next_f32() * 60.0 + 1e-3,
            };
            // Every fifth light sits on the ray's line (h at its floor).
            let position = if k % 5 == 0 {
                o + d * (rng.next_f32() * 80.0 - 10.0)
            } else {
                Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 40.0 - 20.0
            };
            let (h, delta, span) = equiangular_frame(o, d, (t0, t1), position);
            let (h64, delta64) = (h as f64, delta as f64);
            let a = (t0 as f64 - delta64).atan2(h64);
            let b = if t1.is_finite() {
                (t1 as f64 - delta64).atan2(h64)
            } else {
                std::f64::consts::FRAC_PI_2
            };
            let err = (span as f64 - (b - a)).abs();
            assert!(
                err <= 1e-5 * (b - a).max(1e-2),
                "{o} {d} {t0} {t1} {position}: {span} vs {}",
                b - a
            );
            let start = equiangular_start(t0, h, delta) as f64;
            assert!((start - a).abs() < 1e-6, "{start} vs {a}");
        }
    }

    /// A spot light's lit part of a segment holds every point of the segment inside its
    /// cone, and little else; a spot facing away from the segment lights none of it; a point
    /// light lights all of it.
    #[test]
    fn lit_interval_is_the_part_of_a_segment_inside_the_cone() {
        let mut rng = crate::sampling::Pcg32::new(5, 9);
        let mut lit_rays = 0;
        for k in 0..3000 {
            let dir = |r: &mut crate::sampling::Pcg32| {
                crate::sampling::square_to_uniform_sphere(r.next_2d())
            };
            let position = dir(&mut rng) * 3.0 * rng.next_f32();
            let axis = dir(&mut rng);
            let cos_outer = (0.1 + 1.4 * rng.next_f32()).cos();
            let light = Light::Spot {
                position,
                direction: axis,
                intensity: Vec3::ONE,
                cos_inner: 1.0,
                cos_outer,
                range: None,
            };
            let (o, d) = (dir(&mut rng) * 2.0, dir(&mut rng));
            let t_seg = if k % 2 == 0 { 20.0 } else { f32::INFINITY };
            let got = lit_interval(&light, o, d, t_seg);
            let inside = |t: f32| {
                let x = o + d * t - position;
                x.dot(axis) >= cos_outer * x.length()
            };
            let probe = 20.0f32.min(t_seg);
            let mut any = false;
            for i in 0..=2000 {
                let t = probe * i as f32 / 2000.0;
                if inside(t) {
                    any = true;
                    let (t0, t1) = got.unwrap_or_else(|| panic!("{k}: {t} is lit"));
                    assert!(
                        t >= t0 - 1e-3 && t <= t1 + 1e-3,
                        "{k}: {t} not in {t0}..{t1}"
                    );
                }
            }
            if let Some((t0, t1)) = got {
                assert!(0.0 <= t0 && t0 <= t1 && t1 <= t_seg, "{k}: {t0}..{t1}");
                lit_rays += usize::from(any);
                // The ends are on the (slightly widened) cone.
                let widened = |t: f32| {
                    let x = o + d * t - position;
                    x.dot(axis) >= (cos_outer - 2e-3).max(0.0) * x.length() - 1e-4
                };
                assert!(widened(t0) && (t1.is_infinite() || widened(t1)), "{k}");
            }
        }
        assert!(lit_rays > 300, "{lit_rays}");
        let away = Light::Spot {
            position: Vec3::ZERO,
            direction: Vec3::Z,
            intensity: Vec3::ONE,
            cos_inner: 1.0,
            cos_outer: 0.5f32.cos(),
            range: None,
        };
        assert_eq!(
            lit_interval(&away, Vec3::new(0.0, 1.0, -1.0), Vec3::NEG_Z, 50.0),
            None
        );
        // A rig's headlight seen from the camera just behind and above it: lit only from
        // where the ray enters the beam, metres ahead.
        let headlight = Light::Spot {
            position: Vec3::new(0.7, 0.65, -1.8),
            direction: Vec3::new(0.0, -0.052, -1.0).normalize(),
            intensity: Vec3::ONE,
            cos_inner: 0.12f32.cos(),
            cos_outer: 0.35f32.cos(),
            range: None,
        };
        let (t0, t1) =
            lit_interval(&headlight, Vec3::new(0.0, 1.3, 0.0), Vec3::NEG_Z, 100.0).expect("lit");
        assert!(t0 > 3.0 && t1 == 100.0, "{t0}..{t1}");
        let point = Light::Point {
            position: Vec3::ZERO,
            intensity: Vec3::ONE,
            range: None,
        };
        assert_eq!(
            lit_interval(&point, Vec3::Y, Vec3::X, 7.0),
            Some((0.0, 7.0))
        );
    }

    #[test]
    fn fog_scatters_point_and_spot_lights_into_a_ray_as_the_in_scattering_integral() {
        // A lamp above the ray, a weaker one beside it further on, a spot light whose beam
        // crosses the ray (a headlight's visible beam), and a directional light (which the
        // collisions' next-event estimation handles, not the equiangular one).
        let lights = [
            Light::Point {
                position: Vec3::new(0.0, 1.0, -3.0),
                intensity: Vec3::new(10.0, 8.0, 6.0),
                range: None,
            },
            Light::Point {
                position: Vec3::new(-1.0, 0.3, -8.0),
                intensity: Vec3::splat(2.0),
                range: None,
            },
            Light::Spot {
                position: Vec3::new(2.0, 0.5, -5.0),
                direction: Vec3::new(-1.0, -0.1, 0.2).normalize(),
                intensity: Vec3::new(30.0, 30.0, 20.0),
                cos_inner: 0.35f32.cos(),
                cos_outer: 0.5f32.cos(),
                range: None,
            },
            Light::Directional {
                direction: Vec3::new(0.3, -1.0, -0.2).normalize(),
                irradiance: Vec3::splat(0.5),
            },
        ];
        for (fog, spp) in [
            (
                Fog::homogeneous(Vec3::splat(0.1), Vec3::splat(0.8), 0.6).unwrap(),
                60_000,
            ),
            (
                Fog::new(
                    Vec3::new(0.05, 0.1, 0.2),
                    Vec3::new(0.9, 0.7, 0.5),
                    -0.3,
                    0.4,
                    0.5,
                )
                .unwrap(),
                150_000,
            ),
        ] {
            for n in [1, 4] {
                let parts = SceneParts {
                    lights: lights[..n].to_vec(),
                    ..Default::default()
                };
                let scene = foggy_scene(parts, fog);
                let out = render(&scene, &pencil(), &settings(1, 1, spp, 2), &|_| {});
                let got = out.image.get(0, 0);
                let expected = single_scattering(&fog, 200.0, |p| {
                    lights[..n]
                        .iter()
                        .filter_map(|l| l.sample_li(p))
                        .map(|ls| (ls.wi, ls.dist, ls.li))
                        .collect()
                });
                let err = ((got - expected) / expected).abs().max_element();
                assert!(err < 0.015, "{n} lights, {fog:?}: {got} vs {expected}");
            }
        }
    }

    #[test]
    fn fog_scatters_an_area_light_into_a_ray_with_mis() {
        // A square lamp facing down above the ray: small (light sampling wins the MIS) and
        // large and near (the phase function's samples that hit it carry much of the light).
        let le = Vec3::new(4.0, 3.0, 2.0);
        for (c, s, n) in [
            (Vec3::new(0.2, 1.0, -2.5), 0.25, 24),
            (Vec3::new(0.0, 0.6, -3.0), 3.0, 96),
        ] {
            let mut glow = Material::diffuse("glow", Vec3::ZERO);
            glow.emission = le;
            let mut parts = SceneParts {
                materials: vec![glow],
                ..Default::default()
            };
            quad(
                &mut parts,
                [
                    c + Vec3::new(-s, 0.0, -s),
                    c + Vec3::new(s, 0.0, -s),
                    c + Vec3::new(s, 0.0, s),
                    c + Vec3::new(-s, 0.0, s),
                ],
                0,
            );
            let fog = Fog::homogeneous(Vec3::new(0.2, 0.3, 0.4), Vec3::splat(0.9), 0.5).unwrap();
            let scene = foggy_scene(parts, fog);
            let out = render(&scene, &pencil(), &settings(1, 1, 100_000, 2), &|_| {});
            let got = out.image.get(0, 0);
            let expected = single_scattering(&fog, 60.0, |p| {
                let mut pieces = Vec::with_capacity(n * n);
                let da = (2.0 * s / n as f32).powi(2);
                for i in 0..n {
                    for j in 0..n {
                        let u = -s + (i as f32 + 0.5) * 2.0 * s / n as f32;
                        let v = -s + (j as f32 + 0.5) * 2.0 * s / n as f32;
                        let to = c + Vec3::new(u, 0.0, v) - p;
                        let r = to.length();
                        // The lamp faces down: its cosine toward p is (to.y / r).
                        let cos = (to.y / r).max(0.0);
                        pieces.push((to / r, r, le * (cos * da / (r * r))));
                    }
                }
                pieces
            });
            let err = ((got - expected) / expected).abs().max_element();
            assert!(err < 0.015, "lamp of side {}: {got} vs {expected}", 2.0 * s);
        }
    }

    #[test]
    fn absorbing_fog_dims_a_lit_floor_by_beer_lambert_both_ways() {
        let (kd, light_pos, intensity, parts) = lit_floor();
        let sigma = Vec3::new(0.05, 0.1, 0.2);
        let fog = Fog::homogeneous(sigma, Vec3::ZERO, 0.0).unwrap();
        let scene = foggy_scene(parts, fog);
        let cam = camera(Vec3::new(0.0, 1.5, 2.0), -0.6, 0.6);
        let (w, h) = (12, 8);
        let mut set = settings(w, h, 2000, 2);
        set.layers.fog = true;
        let out = render(&scene, &cam, &set, &|_| {});
        let k = 4;
        let (mut got, mut expected) = (Vec3::ZERO, Vec3::ZERO);
        for y in 0..h {
            for x in 0..w {
                got += out.image.get(x, y);
                for i in 0..k {
                    for j in 0..k {
                        let o = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                        let ray = cam.generate_ray(Vec2::new(x as f32, y as f32) + o, w, h);
                        let t = -ray.origin.y / ray.direction.y;
                        let p = ray.at(t);
                        let d = light_pos - p;
                        let tr = (-sigma * (t + d.length())).exp();
                        expected +=
                            intensity * kd * tr * (d.y / d.length() / d.length_squared() / PI)
                                / (k * k) as f32;
                    }
                }
            }
        }
        let err = ((got - expected) / expected).abs().max_element();
        assert!(err < 0.01, "{got} vs {expected}");
        // The fog layer: the transmittance's luminance to the centre ray's hit.
        let ray = cam.generate_ray(Vec2::new(5.5, 6.5), w, h);
        let t = -ray.origin.y / ray.direction.y;
        let layer = out.fog.unwrap()[(6 * w + 5) as usize];
        assert!(
            (layer - luminance((-sigma * t).exp())).abs() < 1e-5,
            "{layer}"
        );
    }

    #[test]
    fn a_scene_without_fog_has_a_fog_layer_of_one_and_draws_no_fog_numbers() {
        let scene = street(Vec3::splat(0.3), Vec3::splat(0.2));
        let cam = camera(Vec3::new(0.0, 1.5, 2.0), -0.3, 0.8);
        let mut set = settings(8, 6, 4, 4);
        let plain = render(&scene, &cam, &set, &|_| {});
        set.layers.fog = true;
        let with_layer = render(&scene, &cam, &set, &|_| {});
        assert!(with_layer.fog.unwrap().iter().all(|&f| f == 1.0));
        assert_eq!(plain.image, with_layer.image);
    }
}
