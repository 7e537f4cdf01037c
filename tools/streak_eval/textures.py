"""Procedural textures of the outside streets (no bpy): asphalt, a puddle roughness map,
pavement flags and three facades, as 8-bit arrays, and a small PNG writer.

They are made here, not taken from the generator (crates/scenes), so that the evaluation
streets do not share the generator's look. Every texture tiles seamlessly: the noise is white
noise filtered in the Fourier domain (periodic by construction) and the patterns have whole
periods per tile. Row 0 is the top of the image, as a PNG stores it.
"""

from __future__ import annotations

import struct
import zlib
from functools import partial
from pathlib import Path

import numpy as np


def periodic_noise(n: int, scale_px: float, rng: np.random.Generator) -> np.ndarray:
    """An n x n field of zero mean and unit standard deviation, smooth over about `scale_px`
    pixels, that tiles seamlessly (white noise low-passed by a Gaussian in frequency)."""
    white = rng.standard_normal((n, n))
    f = np.fft.fftfreq(n)
    fx, fy = np.meshgrid(f, f)
    sigma_f = 1.0 / (2.0 * np.pi * max(scale_px, 1e-6))
    gain = np.exp(-(fx * fx + fy * fy) / (2.0 * sigma_f * sigma_f))
    field = np.real(np.fft.ifft2(np.fft.fft2(white) * gain))
    field -= field.mean()
    std = field.std()
    return field / std if std > 0 else field


def linear_to_srgb8(linear: np.ndarray) -> np.ndarray:
    """Linear values in [0, 1] as 8-bit sRGB (IEC 61966-2-1)."""
    c = np.clip(linear, 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.round(s * 255.0).astype(np.uint8)


def asphalt_albedo(
    n: int = 256,
    seed: int = 1,
    level: float = 0.045,
    stone_px: float = 1.5,
    stone_cut: float = 1.3,
    tint: tuple[float, float, float] = (0.97, 0.98, 1.03),
) -> np.ndarray:
    """Wet asphalt's base colour (n x n x 3, sRGB): dark binder (linear albedo about `level`)
    with grain (one-pixel speckle), lighter stones of about `stone_px` pixels (where the stone
    noise exceeds `stone_cut` standard deviations) and a slow patchiness, times `tint`."""
    rng = np.random.default_rng(seed)
    base = level * np.exp(0.18 * periodic_noise(n, n / 10.0, rng))
    grain = 1.0 + 0.35 * rng.standard_normal((n, n))
    stones = periodic_noise(n, stone_px, rng)
    stone_mask = np.clip((stones - stone_cut) * 2.0, 0.0, 1.0)
    value = base * grain * (1.0 + 1.6 * stone_mask)
    rgb = np.stack([value * tint[0], value * tint[1], value * tint[2]], axis=-1)
    return linear_to_srgb8(rgb)


def metallic_roughness(rough: np.ndarray) -> np.ndarray:
    """glTF's metallicRoughness image (n x n x 3) of a roughness field: roughness in G (clipped
    to [0, 1]), metallic 0 in B, R unused (255)."""
    out = np.empty((*rough.shape, 3), dtype=np.uint8)
    out[..., 0] = 255
    out[..., 1] = np.round(np.clip(rough, 0.0, 1.0) * 255.0).astype(np.uint8)
    out[..., 2] = 0
    return out


def puddles(
    n: int, rng: np.random.Generator, blobs_per_tile: float, share: float, rim: float
) -> np.ndarray:
    """Where water stands (n x n, 0 dry .. 1 puddle): smooth blobs about n / `blobs_per_tile`
    pixels across over about `share` of the area, with soft rims `rim` wide in the noise."""
    blobs = periodic_noise(n, n / blobs_per_tile, rng)
    threshold = np.quantile(blobs, 1.0 - share)
    return np.clip((blobs - threshold) / rim, 0.0, 1.0)


def puddle_roughness(
    n: int = 256,
    seed: int = 2,
    wet: float = 0.13,
    puddle: float = 0.05,
    share: float = 0.3,
    blobs_per_tile: float = 12.0,
) -> np.ndarray:
    """glTF's metallicRoughness image (n x n x 3): roughness in G, metallic 0 in B, R unused
    (255). Wet asphalt of roughness about `wet` with a little noise, and puddles (about
    `share` of the area, smooth blobs of about n / `blobs_per_tile` pixels with soft rims) of
    roughness `puddle`."""
    rng = np.random.default_rng(seed)
    t = puddles(n, rng, blobs_per_tile, share, rim=0.25)  # 0 asphalt .. 1 puddle
    rough = wet * (1.0 + 0.15 * periodic_noise(n, 2.0, rng))
    rough = rough * (1.0 - t) + puddle * t
    return metallic_roughness(rough)


def paving(
    n: int = 128,
    seed: int = 3,
    flags: int = 4,
    level: float = 0.16,
    spread: float = 0.04,
    stains: float = 0.0,
) -> np.ndarray:
    """Pavement flags or concrete panels (n x n x 3, sRGB): `flags` x `flags` square slabs of
    concrete of shades about `level` (standard deviation `spread`) with dark joints; with
    `stains` > 0, dark oil and tyre stains (soft blobs about n / 6 pixels across, up to 45 %
    darker) over about that share of the area."""
    rng = np.random.default_rng(seed)
    cell = n // flags
    shade = level + spread * rng.standard_normal((flags, flags))
    value = np.kron(shade, np.ones((cell, cell)))
    value = value * (1.0 + 0.12 * periodic_noise(n, 1.0, rng))
    v, u = np.mgrid[0:n, 0:n]
    joint = ((u % cell) < 2) | ((v % cell) < 2)
    value = np.where(joint, 0.04, value)
    if stains > 0.0:
        value = value * (1.0 - 0.45 * puddles(n, rng, 6.0, stains, rim=0.6))
    return linear_to_srgb8(np.stack([value, value, value * 0.96], axis=-1))


def _windows(n: int, per_row: int, rows: int, width: float, height: float) -> np.ndarray:
    """A mask of dark window panes: `rows` x `per_row` windows per tile, each `width` x
    `height` of its cell (fractions), its sill in the lower third."""
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    cu = (u * per_row / n) % 1.0
    cv = (v * rows / n) % 1.0
    return (np.abs(cu - 0.5) < width / 2) & (np.abs(cv - 0.45) < height / 2)


def facade_panels(n: int = 256, seed: int = 4) -> np.ndarray:
    """A facade of large cladding panels (n x n x 3, sRGB): a 4 x 2 grid of panels of
    different grey-green tints with light seams, and a ribbon window per storey."""
    rng = np.random.default_rng(seed)
    nx, ny = 4, 2
    tint = 0.25 + 0.06 * rng.standard_normal((ny, nx))
    value = np.kron(tint, np.ones((n // ny, n // nx)))
    value = value * (1.0 + 0.05 * periodic_noise(n, 3.0, rng))
    v, u = np.mgrid[0:n, 0:n]
    seam = ((u % (n // nx)) < 2) | ((v % (n // ny)) < 2)
    value = np.where(seam, 0.5, value)
    ribbon = ((v % (n // ny)) > n // ny * 0.35) & ((v % (n // ny)) < n // ny * 0.7)
    rgb = np.stack([value * 0.9, value, value * 0.95], axis=-1)
    rgb[ribbon] = (0.015, 0.02, 0.025)
    return linear_to_srgb8(rgb)


def facade_plaster(
    n: int = 256,
    seed: int = 5,
    colour: tuple[float, float, float] = (1.0, 0.78, 0.52),
    per_row: int = 3,
    rows: int = 2,
) -> np.ndarray:
    """A rendered (plastered) facade (n x n x 3, sRGB): plaster (ochre by default, times
    `colour`) with blotchy weathering and fine roughcast noise, `rows` rows of `per_row`
    windows per tile."""
    rng = np.random.default_rng(seed)
    value = 0.42 * np.exp(0.12 * periodic_noise(n, n / 8.0, rng))
    value = value * (1.0 + 0.08 * rng.standard_normal((n, n)))
    rgb = np.stack([value * colour[0], value * colour[1], value * colour[2]], axis=-1)
    rgb[_windows(n, per_row, rows, 0.42, 0.5)] = (0.02, 0.02, 0.022)
    return linear_to_srgb8(rgb)


def facade_blocks(
    n: int = 256,
    seed: int = 6,
    courses: int = 8,
    per_course: int = 4,
    colour: tuple[float, float, float] = (1.0, 1.0, 0.97),
    shade: float = 0.3,
    mortar: tuple[float, float, float] | None = None,
    windows: bool = True,
) -> np.ndarray:
    """Blocks or bricks in running bond (n x n x 3, sRGB): `courses` courses of `per_course`
    blocks per tile, each block its own shade about `shade` (times `colour`), mortar joints
    (0.5 times `colour`, or the linear colour `mortar`), one row of square windows (unless
    `windows` is false). The defaults: grey concrete blocks, 8 courses of 4."""
    rng = np.random.default_rng(seed)
    ch, bw = n // courses, n // per_course
    v, u = np.mgrid[0:n, 0:n]
    course = v // ch
    shifted = (u + (course % 2) * (bw // 2)) % n
    block = shifted // bw
    shades = shade + 0.05 * rng.standard_normal((courses, per_course))
    value = shades[course, block] * (1.0 + 0.1 * periodic_noise(n, 1.2, rng))
    joint = ((v % ch) < 2) | ((shifted % bw) < 2)
    value = np.where(joint, 0.5, value)
    rgb = np.stack([value * colour[0], value * colour[1], value * colour[2]], axis=-1)
    if mortar is not None:
        rgb[joint] = mortar
    if windows:
        rgb[_windows(n, 2, 1, 0.4, 0.35)] = (0.02, 0.02, 0.02)
    return linear_to_srgb8(rgb)


def lawn(n: int = 128, seed: int = 7) -> np.ndarray:
    """Mown grass seen at night (n x n x 3, sRGB): dark green with blade-scale speckle and
    slow patches of lighter and browner turf."""
    rng = np.random.default_rng(seed)
    patches = periodic_noise(n, n / 6.0, rng)
    value = 0.07 * np.exp(0.25 * patches) * (1.0 + 0.4 * rng.standard_normal((n, n)))
    brown = np.clip(0.5 + 0.3 * periodic_noise(n, n / 10.0, rng), 0.0, 1.0)
    rgb = np.stack([value * (0.45 + 0.5 * brown), value, value * 0.3], axis=-1)
    return linear_to_srgb8(rgb)


def wood(n: int = 256, seed: int = 8, colour: tuple[float, float, float] = (0.5, 0.3, 0.15)):
    """Wood grain along the image's x axis (n x n x 3, sRGB): rings as wavy stripes (a whole
    number of them per tile), knots of slow noise, fine fibre noise; linear albedo about
    `colour`."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    warp = 3.0 * periodic_noise(n, n / 8.0, rng)
    rings = 0.5 + 0.5 * np.sin(2.0 * np.pi * (v * 14.0 / n) + warp)
    fibre = 1.0 + 0.12 * periodic_noise(n, 0.7, rng)
    value = (0.75 + 0.35 * rings) * fibre
    rgb = np.stack([value * colour[0], value * colour[1], value * colour[2]], axis=-1)
    return linear_to_srgb8(rgb)


def book_spines(n: int = 256, seed: int = 9, books: int = 14) -> np.ndarray:
    """A row of book spines (n x n x 3, sRGB): `books` vertical strips of random widths and
    cloth colours across the tile, each with a light title band and noise of the cloth."""
    rng = np.random.default_rng(seed)
    widths = rng.uniform(0.5, 1.5, books)
    edges = np.round(np.concatenate([[0.0], np.cumsum(widths)]) / widths.sum() * n).astype(int)
    colours = rng.uniform(0.04, 0.5, (books, 3))
    v, u = np.mgrid[0:n, 0:n]
    book = np.searchsorted(edges, u, side="right") - 1
    rgb = colours[book] * (1.0 + 0.1 * periodic_noise(n, 1.0, rng))[..., None]
    band_lo = rng.uniform(0.15, 0.6, books)
    band = (v / n > band_lo[book]) & (v / n < band_lo[book] + 0.12)
    letters = periodic_noise(n, 1.2, rng) > 0.3
    rgb[band & ~letters] = 0.7
    rgb[band & letters] = 0.08
    gap = np.isin(u, edges[1:-1])
    rgb[gap] = 0.01
    return linear_to_srgb8(rgb)


def wallpaper(n: int = 256, seed: int = 10) -> np.ndarray:
    """A patterned wallpaper (n x n x 3, sRGB): a diamond lattice of 8 x 8 motifs per tile,
    dots at the lattice points, faded by slow blotches, on a pale blue-grey ground."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    a = 2.0 * np.pi * 8.0 / n
    lattice = np.abs(np.sin(a * (u + v) / 2.0)) * np.abs(np.sin(a * (u - v) / 2.0))
    dots = (np.cos(a * u) * np.cos(a * v)) > 0.85
    fade = 1.0 + 0.1 * periodic_noise(n, n / 6.0, rng)
    value = (0.35 + 0.2 * lattice) * fade
    rgb = np.stack([value * 0.85, value * 0.9, value], axis=-1)
    rgb[dots] = (0.5, 0.2, 0.12)
    return linear_to_srgb8(rgb)


def setts(
    n: int = 256,
    seed: int = 31,
    rows: int = 10,
    per_row: int = 5,
    colour: tuple[float, float, float] = (1.0, 0.97, 0.93),
    shade: float = 0.11,
) -> np.ndarray:
    """Granite setts in stretcher bond (n x n x 3, sRGB): `rows` courses of `per_row` stones
    per tile, each its own shade about `shade` (times `colour`), with a mica speckle, darker
    worn edges and dark joints (4 % of the stone's size)."""
    rng = np.random.default_rng(seed)
    ch, bw = n / rows, n / per_row
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    course = np.floor(v / ch).astype(int)
    shifted = (u + (course % 2) * bw / 2.0) % n
    stone = np.floor(shifted / bw).astype(int)
    shades = shade * np.exp(0.25 * rng.standard_normal((rows, per_row)))
    value = shades[course, stone] * (1.0 + 0.3 * rng.standard_normal((n, n)))
    # distance to the stone's edge, in fractions of its height: darker (worn, dirty) edges
    fv, fu = (v % ch) / ch, (shifted % bw) / bw
    edge = np.minimum(np.minimum(fv, 1.0 - fv), np.minimum(fu, 1.0 - fu) * bw / ch)
    value = value * (0.6 + 0.4 * np.clip(edge / 0.15, 0.0, 1.0))
    joint = edge < 0.04
    value = np.where(joint, 0.025, value)
    rgb = np.stack([value * colour[0], value * colour[1], value * colour[2]], axis=-1)
    return linear_to_srgb8(rgb)


def setts_roughness(
    n: int = 256,
    seed: int = 32,
    rows: int = 10,
    per_row: int = 5,
    stone: float = 0.2,
    joint: float = 0.05,
) -> np.ndarray:
    """The metallicRoughness image of wet setts laid as `setts` (same `rows`, `per_row`): the
    stones' tops at roughness about `stone` (each stone its own), the water-filled joints and
    the stones' worn edges smoother, towards `joint`; G roughness, B metallic 0, R 255."""
    rng = np.random.default_rng(seed)
    ch, bw = n / rows, n / per_row
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    course = np.floor(v / ch).astype(int)
    shifted = (u + (course % 2) * bw / 2.0) % n
    block = np.floor(shifted / bw).astype(int)
    per_stone = stone * np.exp(0.2 * rng.standard_normal((rows, per_row)))
    fv, fu = (v % ch) / ch, (shifted % bw) / bw
    edge = np.minimum(np.minimum(fv, 1.0 - fv), np.minimum(fu, 1.0 - fu) * bw / ch)
    t = np.clip(edge / 0.12, 0.0, 1.0)
    rough = per_stone[course, block] * (1.0 + 0.1 * periodic_noise(n, 1.5, rng))
    rough = joint + (rough - joint) * t
    return metallic_roughness(rough)


def dry_roughness(n: int = 256, seed: int = 33, mean: float = 0.72, spread: float = 0.08):
    """The metallicRoughness image of a dry road: roughness about `mean` everywhere, slow
    patches and grain of `spread` (no puddles, nothing below mean - 3 spread); G roughness,
    B metallic 0, R 255."""
    rng = np.random.default_rng(seed)
    field = 0.6 * periodic_noise(n, n / 12.0, rng) + 0.8 * periodic_noise(n, 1.0, rng)
    rough = mean + spread * np.clip(field, -3.0, 3.0)
    return metallic_roughness(rough)


def board_concrete(n: int = 256, seed: int = 34, boards: int = 8, level: float = 0.3):
    """Board-marked concrete (n x n x 3, sRGB): `boards` horizontal formwork boards per tile,
    each a slightly different shade about `level` with its grain along x, thin joints
    between boards and a grid of tie holes, and slow water staining."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    bh = n / boards
    board = np.floor(v / bh).astype(int)
    shades = level * (1.0 + 0.06 * rng.standard_normal(boards))
    grain = np.sin(2.0 * np.pi * (v * 3.0 * boards / n) + 2.0 * periodic_noise(n, n / 16.0, rng))
    stain = np.exp(0.15 * periodic_noise(n, n / 5.0, rng))
    value = shades[board] * (1.0 + 0.04 * grain) * stain
    value = value * (1.0 + 0.06 * periodic_noise(n, 0.8, rng))
    value = np.where((v % bh) < 1.5, 0.6 * value, value)
    holes = ((u - n / 8.0) % (n / 4.0)) ** 2 + ((v - bh / 2.0) % (2.0 * bh) - 0.0) ** 2 < 9.0
    value = np.where(holes, 0.05, value)
    return linear_to_srgb8(np.stack([value, value * 0.99, value * 0.95], axis=-1))


def shopfronts(n: int = 256, seed: int = 35, shops: int = 2) -> np.ndarray:
    """A terrace's ground floor and upper storey (n x n x 3, sRGB): `shops` shop fronts per
    tile, each a painted fascia (its own colour) over a dark glazed window and a door, on
    painted brick above with two sash windows per shop."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    cell = n / shops
    shop = np.floor(u / cell).astype(int)
    fu = (u % cell) / cell
    fv = v / n  # 0 at the top of the tile
    paints = rng.uniform(0.05, 0.45, (shops, 3))
    wall = 0.35 * (1.0 + 0.08 * periodic_noise(n, 1.0, rng))
    courses = (v % (n / 32.0)) < 1.0
    rgb = np.stack([wall * 0.95, wall * 0.9, wall * 0.85], axis=-1)
    rgb[courses] *= 0.7
    upper = (fv > 0.1) & (fv < 0.38) & (np.abs((fu * 2.0) % 1.0 - 0.5) < 0.22)
    rgb[upper] = (0.02, 0.022, 0.025)
    fascia = (fv > 0.5) & (fv < 0.58) & (fu > 0.03) & (fu < 0.97)
    rgb[fascia] = paints[shop][fascia]
    glass = (fv > 0.6) & (fv < 0.92) & (fu > 0.06) & (fu < 0.66)
    rgb[glass] = (0.015, 0.018, 0.02)
    door = (fv > 0.6) & (fu > 0.72) & (fu < 0.9)
    rgb[door] = paints[shop][door] * 0.5
    return linear_to_srgb8(rgb)


def large_slabs(n: int = 256, seed: int = 61, across: int = 2, along: int = 3) -> np.ndarray:
    """Large granite-like paving slabs (n x n x 3, sRGB): `across` x `along` slabs per tile,
    each its own grey with a fine speckle (dark crystals, light quartz) and narrow dark
    joints; a running bond (every other row shifted by half a slab)."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    ch, cw = n / along, n / across
    row = np.floor(v / ch).astype(int)
    shifted = (u + (row % 2) * cw / 2.0) % n
    col = np.floor(shifted / cw).astype(int)
    shade = 0.13 + 0.035 * rng.standard_normal((along, across))
    value = shade[row, col]
    speckle = rng.standard_normal((n, n))
    value = value * (1.0 + 0.25 * np.clip(speckle, -2.0, 2.0))
    value = value * np.exp(0.1 * periodic_noise(n, n / 6.0, rng))
    joint = ((v % ch) < 1.5) | ((shifted % cw) < 1.5)
    value = np.where(joint, 0.03, value)
    return linear_to_srgb8(np.stack([value * 0.98, value, value * 1.03], axis=-1))


def slabs_roughness(
    n: int = 256, seed: int = 62, across: int = 2, along: int = 3, wet: float = 0.09
) -> np.ndarray:
    """The metallicRoughness image of `large_slabs`' laying (G roughness, B metallic 0): each
    slab wet at about `wet` (its own, +-25 %), water standing in the joints (0.03)."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    ch, cw = n / along, n / across
    row = np.floor(v / ch).astype(int)
    shifted = (u + (row % 2) * cw / 2.0) % n
    col = np.floor(shifted / cw).astype(int)
    each = wet * (1.0 + 0.25 * rng.uniform(-1.0, 1.0, (along, across)))
    rough = each[row, col] * (1.0 + 0.1 * periodic_noise(n, 1.5, rng))
    joint = ((v % ch) < 2.0) | ((shifted % cw) < 2.0)
    rough = np.where(joint, 0.03, rough)
    return metallic_roughness(rough)


def lit_windows(
    n: int = 256,
    seed: int = 63,
    per_row: int = 6,
    rows: int = 4,
    lit: float = 0.35,
    colour: tuple[float, float, float] = (0.55, 0.5, 0.45),
) -> np.ndarray:
    """An apartment block's facade for the far bank (n x n x 3, sRGB): a plain wall of
    `colour` with `rows` x `per_row` windows per tile, about `lit` of them a pale yellow
    albedo (curtains; the windows that glow are emissive boxes in the scene) and the rest
    dark."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    wall = 0.3 * np.exp(0.12 * periodic_noise(n, n / 8.0, rng))
    rgb = np.stack([wall * colour[0], wall * colour[1], wall * colour[2]], axis=-1) / 0.5
    panes = _windows(n, per_row, rows, 0.45, 0.5)
    iu = np.floor(u * per_row / n).astype(int)
    iv = np.floor(v * rows / n).astype(int)
    on = rng.uniform(size=(rows, per_row)) < lit
    lit_px = panes & on[iv, iu]
    rgb[panes] = (0.02, 0.02, 0.025)
    rgb[lit_px] = (0.8, 0.62, 0.3)
    return linear_to_srgb8(rgb)


def cobbles_roughness(
    n: int = 256,
    seed: int = 101,
    rows: int = 16,
    per_row: int = 8,
    stone: float = 0.3,
    joint: float = 0.07,
    puddle: float = 0.03,
    share: float = 0.2,
    blobs_per_tile: float = 8.0,
) -> np.ndarray:
    """The metallicRoughness image of wet cobbles laid as `setts` with the same `rows` and
    `per_row`, rough-ish stones (about `stone`, each its own) with wetter joints (towards
    `joint`), and standing water over about `share` of the area (smooth blobs about n /
    `blobs_per_tile` pixels across, roughness `puddle`) where the paving has sunk; G roughness,
    B metallic 0, R 255."""
    rng = np.random.default_rng(seed)
    base = setts_roughness(n, seed + 1, rows, per_row, stone, joint)[..., 1] / 255.0
    t = puddles(n, rng, blobs_per_tile, share, rim=0.3)
    rough = base * (1.0 - t) + puddle * t
    return metallic_roughness(rough)


def write_png(path: Path, pixels: np.ndarray) -> None:
    """Writes an 8-bit grey (h x w) or RGB (h x w x 3) array as a PNG (row 0 at the top)."""
    pixels = np.asarray(pixels)
    if pixels.dtype != np.uint8:
        raise ValueError("write_png takes uint8 pixels")
    if pixels.ndim == 2:
        colour_type, channels = 0, 1
    elif pixels.ndim == 3 and pixels.shape[2] == 3:
        colour_type, channels = 2, 3
    else:
        raise ValueError(f"write_png takes h x w or h x w x 3, not {pixels.shape}")
    h, w = pixels.shape[:2]
    rows = pixels.reshape(h, w * channels)
    raw = b"".join(b"\x00" + rows[i].tobytes() for i in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", w, h, 8, colour_type, 0, 0, 0)
    png = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )
    Path(path).write_bytes(png)


#: The textures of the outside streets: name -> (maker, whether it holds colour (sRGB) rather
#: than data). The first set (hill_bend, crossing, tabletop) uses the first six; the second
#: set (roundabout, avenue, shelf) the next ten, made with other seeds and patterns; the third set
#: (underpass, hillside, daylight_street) the next fourteen, again new seeds and patterns; the
#: fourth (bridge, square) the next eleven, new seeds and three new patterns (large slabs,
#: their wet roughness, blocks of flats with lit windows); the fifth (quay, arterial) the next
#: ten; the sixth (tramway, forecourt) the last thirteen, new seeds and stained concrete
#: panels (`paving` with `stains`).
TEXTURES = {
    "asphalt": (asphalt_albedo, True),
    "puddles": (puddle_roughness, False),
    "paving": (paving, True),
    "panels": (facade_panels, True),
    "plaster": (facade_plaster, True),
    "blocks": (facade_blocks, True),
    # second set
    "asphalt_b": (
        partial(
            asphalt_albedo,
            seed=21,
            level=0.055,
            stone_px=2.5,
            stone_cut=1.0,
            tint=(1.02, 1.0, 0.96),
        ),
        True,
    ),
    "puddles_b": (
        partial(puddle_roughness, seed=22, wet=0.15, puddle=0.04, share=0.25, blobs_per_tile=8.0),
        False,
    ),
    "puddles_strong": (
        partial(puddle_roughness, seed=23, wet=0.12, puddle=0.02, share=0.55, blobs_per_tile=5.0),
        False,
    ),
    "paving_b": (partial(paving, seed=24, flags=8), True),
    "bricks": (
        partial(
            facade_blocks,
            seed=25,
            courses=32,
            per_course=8,
            colour=(1.0, 0.42, 0.28),
            shade=0.22,
            mortar=(0.3, 0.29, 0.27),
            windows=False,
        ),
        True,
    ),
    "render_b": (
        partial(facade_plaster, seed=26, colour=(0.78, 0.84, 0.9), per_row=4, rows=3),
        True,
    ),
    "lawn": (lawn, True),
    "wood": (wood, True),
    "spines": (book_spines, True),
    "wallpaper": (wallpaper, True),
    # third set (underpass, hillside, daylight_street)
    "asphalt_c": (
        partial(
            asphalt_albedo,
            seed=41,
            level=0.05,
            stone_px=2.0,
            stone_cut=1.15,
            tint=(0.98, 1.0, 1.02),
        ),
        True,
    ),
    "puddles_c": (
        partial(puddle_roughness, seed=42, wet=0.11, puddle=0.03, share=0.35, blobs_per_tile=10.0),
        False,
    ),
    "setts": (setts, True),
    "setts_wet": (setts_roughness, False),
    "concrete_c": (board_concrete, True),
    "asphalt_hill": (
        partial(
            asphalt_albedo, seed=47, level=0.04, stone_px=1.2, stone_cut=1.5, tint=(1.0, 0.99, 0.97)
        ),
        True,
    ),
    "puddles_hill": (
        partial(puddle_roughness, seed=46, wet=0.16, puddle=0.05, share=0.15, blobs_per_tile=16.0),
        False,
    ),
    "shopfronts": (shopfronts, True),
    "sandstone": (
        partial(
            facade_blocks,
            seed=49,
            courses=16,
            per_course=4,
            colour=(1.0, 0.86, 0.66),
            shade=0.4,
            mortar=(0.3, 0.28, 0.25),
        ),
        True,
    ),
    "render_c": (
        partial(facade_plaster, seed=50, colour=(1.0, 0.86, 0.82), per_row=2, rows=3),
        True,
    ),
    "asphalt_dry": (
        partial(
            asphalt_albedo, seed=51, level=0.11, stone_px=1.5, stone_cut=1.1, tint=(1.0, 1.0, 1.0)
        ),
        True,
    ),
    "dry_rough": (dry_roughness, False),
    "paving_c": (partial(paving, seed=53, flags=16), True),
    "leaves_c": (partial(lawn, seed=54), True),
    # fourth set (bridge, square)
    "asphalt_d": (
        partial(
            asphalt_albedo,
            seed=71,
            level=0.042,
            stone_px=1.8,
            stone_cut=1.25,
            tint=(0.99, 0.99, 1.0),
        ),
        True,
    ),
    "puddles_d": (
        partial(puddle_roughness, seed=72, wet=0.12, puddle=0.035, share=0.3, blobs_per_tile=7.0),
        False,
    ),
    "asphalt_sq": (
        partial(
            asphalt_albedo, seed=73, level=0.06, stone_px=1.0, stone_cut=1.4, tint=(1.0, 0.98, 0.95)
        ),
        True,
    ),
    "puddles_sq": (
        partial(puddle_roughness, seed=74, wet=0.14, puddle=0.03, share=0.2, blobs_per_tile=20.0),
        False,
    ),
    "slabs": (large_slabs, True),
    "slabs_wet": (slabs_roughness, False),
    "parapet_d": (partial(board_concrete, seed=75, boards=4, level=0.22), True),
    "far_flats": (lit_windows, True),
    "far_flats_b": (
        partial(lit_windows, seed=76, per_row=4, rows=5, lit=0.5, colour=(0.5, 0.42, 0.36)),
        True,
    ),
    "shopfronts_d": (partial(shopfronts, seed=77, shops=3), True),
    "render_d": (
        partial(facade_plaster, seed=78, colour=(0.86, 0.9, 0.8), per_row=3, rows=4),
        True,
    ),
    # fifth set (quay, arterial)
    "cobbles_e": (
        partial(setts, seed=102, rows=16, per_row=8, colour=(0.9, 0.95, 1.0), shade=0.08),
        True,
    ),
    "cobbles_wet_e": (cobbles_roughness, False),
    "flags_e": (partial(paving, seed=103, flags=8, n=256), True),
    "quay_stone_e": (
        partial(
            facade_blocks,
            seed=104,
            courses=4,
            per_course=2,
            colour=(0.85, 0.88, 0.9),
            shade=0.2,
            mortar=(0.06, 0.06, 0.06),
            windows=False,
        ),
        True,
    ),
    "warehouse_e": (
        partial(
            facade_blocks,
            seed=105,
            courses=32,
            per_course=8,
            colour=(0.9, 0.62, 0.36),
            shade=0.2,
            mortar=(0.22, 0.2, 0.18),
        ),
        True,
    ),
    "far_quay_e": (
        partial(lit_windows, seed=106, per_row=8, rows=6, lit=0.3, colour=(0.42, 0.44, 0.5)),
        True,
    ),
    "asphalt_e": (
        partial(
            asphalt_albedo,
            seed=107,
            level=0.038,
            stone_px=1.3,
            stone_cut=1.2,
            tint=(1.0, 1.0, 1.02),
        ),
        True,
    ),
    "puddles_e": (
        partial(puddle_roughness, seed=108, wet=0.1, puddle=0.025, share=0.22, blobs_per_tile=4.0),
        False,
    ),
    "barrier_e": (partial(board_concrete, seed=109, boards=2, level=0.35), True),
    "verge_e": (partial(lawn, seed=110), True),
    # sixth set (tramway, forecourt)
    "asphalt_f": (
        partial(
            asphalt_albedo,
            seed=121,
            level=0.048,
            stone_px=1.6,
            stone_cut=1.2,
            tint=(1.0, 0.99, 0.98),
        ),
        True,
    ),
    "puddles_f": (
        partial(puddle_roughness, seed=122, wet=0.14, puddle=0.03, share=0.28, blobs_per_tile=9.0),
        False,
    ),
    "flags_f": (partial(paving, seed=123, n=192, flags=6, level=0.2, spread=0.05), True),
    "shopfronts_f": (partial(shopfronts, seed=124, shops=4), True),
    "render_f": (
        partial(facade_plaster, seed=125, colour=(0.95, 0.9, 0.75), per_row=4, rows=2),
        True,
    ),
    "bricks_f": (
        partial(
            facade_blocks,
            seed=126,
            courses=32,
            per_course=4,
            colour=(0.75, 0.45, 0.35),
            shade=0.25,
            mortar=(0.35, 0.33, 0.3),
        ),
        True,
    ),
    "concrete_f": (
        partial(paving, seed=127, n=256, flags=2, level=0.3, spread=0.03, stains=0.2),
        True,
    ),
    "concrete_wet_f": (
        partial(puddle_roughness, seed=128, wet=0.2, puddle=0.035, share=0.35, blobs_per_tile=5.0),
        False,
    ),
    "asphalt_road_f": (
        partial(
            asphalt_albedo,
            seed=129,
            level=0.04,
            stone_px=2.2,
            stone_cut=1.3,
            tint=(0.98, 0.99, 1.02),
        ),
        True,
    ),
    "puddles_road_f": (
        partial(puddle_roughness, seed=130, wet=0.12, puddle=0.025, share=0.3, blobs_per_tile=6.0),
        False,
    ),
    "cladding_f": (partial(facade_panels, seed=131), True),
    "field_f": (partial(lawn, seed=132), True),
    "houses_f": (
        partial(lit_windows, seed=133, per_row=3, rows=2, lit=0.4, colour=(0.6, 0.55, 0.5)),
        True,
    ),
    # seventh set (toll plaza, close)
    "asphalt_g": (
        partial(
            asphalt_albedo,
            seed=161,
            level=0.05,
            stone_px=1.8,
            stone_cut=1.25,
            tint=(0.99, 1.0, 1.02),
        ),
        True,
    ),
    "puddles_g": (
        partial(puddle_roughness, seed=162, wet=0.11, puddle=0.03, share=0.25, blobs_per_tile=7.0),
        False,
    ),
    "booth_g": (partial(facade_panels, seed=163), True),
    "verge_g": (partial(lawn, seed=164), True),
    "asphalt_close_g": (
        partial(
            asphalt_albedo,
            seed=165,
            level=0.042,
            stone_px=1.3,
            stone_cut=1.4,
            tint=(1.02, 1.0, 0.97),
        ),
        True,
    ),
    "puddles_close_g": (
        partial(puddle_roughness, seed=166, wet=0.16, puddle=0.02, share=0.4, blobs_per_tile=4.0),
        False,
    ),
    "garden_wall_g": (
        partial(
            facade_blocks,
            seed=167,
            courses=32,
            per_course=8,
            colour=(0.8, 0.5, 0.38),
            shade=0.28,
            mortar=(0.4, 0.38, 0.35),
            windows=False,
        ),
        True,
    ),
    "houses_g": (
        partial(facade_plaster, seed=168, colour=(0.9, 0.92, 0.95), per_row=2, rows=2),
        True,
    ),
    "flags_g": (partial(paving, seed=169, n=160, flags=5, level=0.18), True),
    "hedge_g": (partial(lawn, seed=170), True),
    # eighth set (bus station, car park deck)
    "asphalt_h": (
        partial(
            asphalt_albedo,
            seed=191,
            level=0.046,
            stone_px=2.0,
            stone_cut=1.15,
            tint=(1.0, 1.0, 1.0),
        ),
        True,
    ),
    "puddles_h": (
        partial(puddle_roughness, seed=192, wet=0.12, puddle=0.025, share=0.22, blobs_per_tile=6.0),
        False,
    ),
    "platform_h": (partial(paving, seed=193, n=192, flags=4, level=0.22, spread=0.03), True),
    "arcade_h": (partial(shopfronts, seed=194, shops=3), True),
    "offices_h": (
        partial(lit_windows, seed=195, per_row=5, rows=3, lit=0.25, colour=(0.5, 0.52, 0.55)),
        True,
    ),
    "deck_h": (
        partial(paving, seed=196, n=256, flags=4, level=0.24, spread=0.025, stains=0.3),
        True,
    ),
    "deck_wet_h": (
        partial(puddle_roughness, seed=197, wet=0.18, puddle=0.03, share=0.3, blobs_per_tile=7.0),
        False,
    ),
    "parapet_h": (partial(board_concrete, seed=198, boards=3, level=0.28), True),
    "skyline_h": (
        partial(lit_windows, seed=199, per_row=8, rows=6, lit=0.3, colour=(0.45, 0.45, 0.5)),
        True,
    ),
    # ninth set (hotel frontage, tunnel portal)
    "asphalt_i": (
        partial(
            asphalt_albedo,
            seed=221,
            level=0.048,
            stone_px=1.6,
            stone_cut=1.2,
            tint=(1.0, 0.99, 0.98),
        ),
        True,
    ),
    "puddles_i": (
        partial(puddle_roughness, seed=222, wet=0.13, puddle=0.022, share=0.26, blobs_per_tile=5.0),
        False,
    ),
    "drive_i": (
        partial(setts, seed=223, rows=12, per_row=6, colour=(1.0, 0.9, 0.86), shade=0.14),
        True,
    ),
    "drive_wet_i": (
        partial(cobbles_roughness, seed=224, rows=12, per_row=6, stone=0.22, joint=0.06),
        False,
    ),
    "hotel_i": (
        partial(lit_windows, seed=225, per_row=4, rows=3, lit=0.45, colour=(0.62, 0.56, 0.46)),
        True,
    ),
    "showroom_i": (partial(facade_panels, seed=226), True),
    "flags_i": (partial(paving, seed=227, n=224, flags=7, level=0.19, spread=0.035), True),
    "asphalt_pass_i": (
        partial(
            asphalt_albedo,
            seed=228,
            level=0.04,
            stone_px=1.4,
            stone_cut=1.35,
            tint=(0.98, 0.99, 1.02),
        ),
        True,
    ),
    "puddles_pass_i": (
        partial(puddle_roughness, seed=229, wet=0.12, puddle=0.03, share=0.18, blobs_per_tile=9.0),
        False,
    ),
    "tunnel_damp_i": (partial(dry_roughness, seed=230, mean=0.32, spread=0.06), False),
    "lining_i": (partial(paving, seed=231, n=256, flags=8, level=0.5, spread=0.03), True),
    "portal_i": (partial(board_concrete, seed=232, boards=5, level=0.26), True),
    "slope_i": (partial(lawn, seed=233), True),
}


def write_all(folder: Path) -> dict[str, Path]:
    """Writes every texture of `TEXTURES` as `folder/<name>.png`; returns the paths."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = {}
    for name, (make, _) in TEXTURES.items():
        paths[name] = folder / f"{name}.png"
        write_png(paths[name], make())
    return paths
