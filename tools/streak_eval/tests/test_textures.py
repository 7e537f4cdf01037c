"""The outside streets' textures and light levels (no bpy)."""

import functools
import math
import struct
import zlib

import numpy as np
import pytest
from levels import (
    crown,
    eased_grade,
    hill_profile,
    luminance,
    radiance_for_luminance,
    ramp_grade,
    smoothstep,
    watts_for_candela,
    watts_for_lux,
)
from textures import (
    TEXTURES,
    asphalt_albedo,
    board_concrete,
    book_spines,
    cobbles_roughness,
    dry_roughness,
    facade_blocks,
    facade_plaster,
    large_slabs,
    lawn,
    lit_windows,
    paving,
    periodic_noise,
    puddle_roughness,
    setts,
    setts_roughness,
    shopfronts,
    slabs_roughness,
    wallpaper,
    wood,
    write_all,
    write_png,
)


def srgb8_to_linear(c: np.ndarray) -> np.ndarray:
    s = c.astype(np.float64) / 255.0
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


def read_png(data: bytes) -> tuple[int, int, int, bytes]:
    """Width, height, colour type and the filtered scanlines of a PNG written by write_png."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        tag = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length : pos + 12 + length])
        assert crc == zlib.crc32(tag + body)
        if tag == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        pos += 12 + length
    assert header is not None
    return header[0], header[1], header[3], zlib.decompress(idat)


def test_png_round_trip(tmp_path):
    pixels = np.arange(5 * 7 * 3, dtype=np.uint8).reshape(5, 7, 3)
    write_png(tmp_path / "a.png", pixels)
    w, h, colour_type, raw = read_png((tmp_path / "a.png").read_bytes())
    assert (w, h, colour_type) == (7, 5, 2)
    rows = np.frombuffer(raw, dtype=np.uint8).reshape(5, 1 + 7 * 3)
    assert (rows[:, 0] == 0).all()
    assert (rows[:, 1:].reshape(5, 7, 3) == pixels).all()


def test_png_refuses_floats(tmp_path):
    with pytest.raises(ValueError):
        write_png(tmp_path / "a.png", np.zeros((2, 2, 3)))


def test_noise_is_normalised_and_periodic():
    f = periodic_noise(64, 3.0, np.random.default_rng(0))
    assert abs(f.mean()) < 1e-9 and abs(f.std() - 1.0) < 1e-9
    # across the wrap-around edge the field changes no more than between interior rows
    interior = np.abs(np.diff(f, axis=0)).mean()
    seam = np.abs(f[0] - f[-1]).mean()
    assert seam < 1.5 * interior


def test_asphalt_is_dark_and_grainy():
    lin = srgb8_to_linear(asphalt_albedo(128, seed=1)).mean(axis=-1)
    assert 0.03 < lin.mean() < 0.08
    # grain: neighbouring pixels differ by a good share of the mean (texture for matching)
    assert np.abs(np.diff(lin, axis=1)).mean() > 0.2 * lin.mean()


def test_puddle_roughness_range_and_share():
    img = puddle_roughness(128, seed=2, wet=0.13, puddle=0.05, share=0.3)
    rough = img[..., 1] / 255.0
    assert (img[..., 2] == 0).all() and (img[..., 0] == 255).all()
    assert rough.min() >= 0.04 and rough.max() <= 0.2
    puddles = (rough < 0.07).mean()
    assert 0.1 < puddles < 0.35


def test_facades_have_windows():
    img = facade_blocks(128, seed=6)
    lin = srgb8_to_linear(img).mean(axis=-1)
    assert (lin < 0.03).mean() > 0.05  # dark panes
    assert lin.mean() > 0.15  # a lit wall between them


def test_write_all(tmp_path):
    paths = write_all(tmp_path)
    assert set(paths) == set(TEXTURES)
    for p in paths.values():
        assert p.stat().st_size < 200_000


def test_light_levels():
    # 2400 cd of a warm LED: the exporter's P / (4 pi) * 683 * luminance gives it back
    colour = (1.0, 0.71, 0.42)
    p = watts_for_candela(2400.0, colour)
    assert math.isclose(p / (4 * math.pi) * 683 * luminance(colour), 2400.0)
    assert math.isclose(radiance_for_luminance(683.0, (1.0, 1.0, 1.0)), 1.0)


def test_road_shapes():
    assert smoothstep(-1) == 0 and smoothstep(2) == 1 and smoothstep(0.5) == 0.5
    assert hill_profile(0.0) == 0.0
    rise = hill_profile(60.0) - hill_profile(0.0)
    assert 2.0 <= rise <= 3.0
    grades = np.diff([hill_profile(s) for s in np.arange(0.0, 120.0, 1.0)])
    assert grades.max() > 0.05 and grades.min() < -0.05  # climbs, then falls past the crest
    assert crown(0.0, 4.0, 0.08) == 0.08 and crown(4.0, 4.0, 0.08) == 0.0


FIRST_SET = ("asphalt", "puddles", "paving", "panels", "plaster", "blocks")


@functools.cache
def made() -> dict[str, np.ndarray]:
    """Every texture, made once for the tests that compare them."""
    return {name: make() for name, (make, _) in TEXTURES.items()}


def assert_new(names, earlier) -> None:
    """The textures `names` are 8-bit RGB and none equals one of `earlier` of its size."""
    for name in names:
        img = made()[name]
        assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
        for old in earlier:
            if made()[old].shape == img.shape:
                assert not np.array_equal(made()[old], img), (name, old)


def test_second_set_differs_from_the_first():
    second = [name for name in TEXTURES if name not in FIRST_SET]
    assert len(second) >= 8
    assert_new(second, FIRST_SET)


def test_first_set_defaults_unchanged():
    # the options added for the second set leave the first set's textures as they were
    assert np.array_equal(asphalt_albedo(64, seed=1), asphalt_albedo(64, 1, 0.045, 1.5, 1.3))
    assert np.array_equal(facade_blocks(64, seed=6), facade_blocks(64, 6, 8, 4))
    assert np.array_equal(facade_plaster(64, seed=5), facade_plaster(64, 5, per_row=3, rows=2))


def test_second_set_asphalt_and_puddles():
    make, colour = TEXTURES["asphalt_b"]
    lin = srgb8_to_linear(make(128)).mean(axis=-1)
    assert colour and 0.03 < lin.mean() < 0.1
    strong = TEXTURES["puddles_strong"][0](128)[..., 1] / 255.0
    assert 0.4 < (strong < 0.04).mean() < 0.7  # more than half the road a mirror-like puddle
    assert strong.min() >= 0.015
    # fewer, larger puddles than the first set's: its blobs cover more pixels each
    assert not TEXTURES["puddles_b"][1] and not TEXTURES["puddles_strong"][1]


def test_bricks_have_no_windows_and_are_red():
    lin = srgb8_to_linear(TEXTURES["bricks"][0]())
    assert (lin.mean(axis=-1) < 0.03).mean() < 0.02
    assert lin[..., 0].mean() > 1.5 * lin[..., 2].mean()


def test_new_patterns():
    g = srgb8_to_linear(lawn(64))
    assert g[..., 1].mean() > g[..., 2].mean() and g[..., 1].mean() > g[..., 0].mean()
    w = srgb8_to_linear(wood(64)).mean(axis=-1)
    # grain along x: rows vary less than columns
    assert np.abs(np.diff(w, axis=1)).mean() < np.abs(np.diff(w, axis=0)).mean()
    b = srgb8_to_linear(book_spines(128, books=10))
    assert (b.mean(axis=-1) < 0.02).any()  # the gaps between books
    assert len(np.unique(b[5, :, 0])) >= 6  # several books across a row
    p = srgb8_to_linear(wallpaper(64))
    assert p.std() > 0.03 and p.mean() > 0.2


@pytest.mark.parametrize("name", ["lawn", "wood", "spines", "wallpaper"])
def test_new_textures_tile(name):
    lin = srgb8_to_linear(TEXTURES[name][0]()).mean(axis=-1)
    # across the wrap-around edge no larger jumps than between interior neighbours
    for axis in (0, 1):
        inner = np.abs(np.diff(lin, axis=axis)).mean()
        seam = np.abs(np.take(lin, 0, axis) - np.take(lin, -1, axis)).mean()
        assert seam < 3.0 * inner + 0.01


def test_eased_grade():
    assert eased_grade(0.0, -0.04, 14.0, 12.0) == 0.0
    assert math.isclose(eased_grade(10.0, -0.04, 14.0, 12.0), -0.4)
    end = eased_grade(26.0, -0.04, 14.0, 12.0)
    assert math.isclose(end, -0.04 * (14.0 + 6.0))
    assert eased_grade(40.0, -0.04, 14.0, 12.0) == end  # level after the easing
    ys = np.arange(0.0, 40.0, 0.25)
    grades = np.diff([eased_grade(y, -0.04, 14.0, 12.0) for y in ys]) / 0.25
    assert grades.min() >= -0.0401 and grades.max() <= 1e-12
    assert np.abs(np.diff(grades)).max() < 0.002  # the grade changes smoothly


THIRD_SET = (
    "asphalt_c",
    "puddles_c",
    "setts",
    "setts_wet",
    "concrete_c",
    "asphalt_hill",
    "puddles_hill",
    "shopfronts",
    "sandstone",
    "render_c",
    "asphalt_dry",
    "dry_rough",
    "paving_c",
    "leaves_c",
)


def test_setts_and_their_wet_joints():
    lin = srgb8_to_linear(setts(128)).mean(axis=-1)
    assert (lin < 0.03).mean() > 0.03  # the dark joints
    assert 0.04 < lin.mean() < 0.2
    rough = setts_roughness(128)[..., 1] / 255.0
    # the same laying: the joints of the albedo are where the roughness is lowest
    joints = lin < 0.03
    assert rough[joints].mean() < rough[~joints].mean()
    assert rough.min() >= 0.04 and rough.max() <= 0.5  # each stone its own, about 0.2


def test_dry_road_is_rough_everywhere():
    img = dry_roughness(128)
    rough = img[..., 1] / 255.0
    assert (img[..., 2] == 0).all() and (img[..., 0] == 255).all()
    assert rough.min() >= 0.45 and abs(rough.mean() - 0.72) < 0.03
    make, colour = TEXTURES["asphalt_dry"]
    lin = srgb8_to_linear(make(128)).mean(axis=-1)
    assert colour and 0.08 < lin.mean() < 0.2  # lighter than the wet streets' asphalt
    assert not TEXTURES["dry_rough"][1] and not TEXTURES["setts_wet"][1]


def test_third_set_patterns():
    c = srgb8_to_linear(board_concrete(128)).mean(axis=-1)
    # horizontal boards: the shade changes more down the image than along it
    assert np.abs(np.diff(c.mean(axis=1))).mean() > np.abs(np.diff(c.mean(axis=0))).mean()
    shop = srgb8_to_linear(shopfronts(128))
    assert (shop.mean(axis=-1) < 0.03).mean() > 0.15  # glazing and upper windows
    assert shop.std(axis=-1).max() > 0.05  # the painted fascias have a colour


def test_sun_and_ramp():
    sun = (1.0, 0.87, 0.8)
    assert math.isclose(watts_for_lux(60000.0, sun) * 683.0 * luminance(sun), 60000.0)
    assert ramp_grade(0.0, 0.03, 0.09, 35.0) == 0.0
    assert math.isclose(ramp_grade(-2.0, 0.03, 0.09, 35.0), -0.06)
    ss = np.arange(0.0, 80.0, 0.25)
    grades = np.diff([ramp_grade(s, 0.03, 0.09, 35.0) for s in ss]) / 0.25
    assert abs(grades[0] - 0.03) < 1e-3 and abs(grades[-1] - 0.09) < 1e-9
    assert np.all(np.diff(grades) >= -1e-12)  # the grade only rises
    assert math.isclose(ramp_grade(35.0, 0.03, 0.09, 35.0), 0.03 * 35.0 + 0.06 * 17.5)


FOURTH_SET = (
    "asphalt_d",
    "puddles_d",
    "asphalt_sq",
    "puddles_sq",
    "slabs",
    "slabs_wet",
    "parapet_d",
    "far_flats",
    "far_flats_b",
    "shopfronts_d",
    "render_d",
)


def test_large_slabs_and_their_wet_joints():
    lin = srgb8_to_linear(large_slabs(128)).mean(axis=-1)
    joints = lin < 0.035
    assert 0.02 < joints.mean() < 0.2  # narrow joints between large slabs
    assert 0.05 < lin[~joints].mean() < 0.25
    rough = slabs_roughness(128)[..., 1] / 255.0
    # the same laying: water stands in the albedo's joints
    assert rough[joints].mean() < rough[~joints].mean()
    assert rough.min() >= 0.02 and rough.max() <= 0.16
    assert not TEXTURES["slabs_wet"][1] and TEXTURES["slabs"][1]


def test_lit_windows():
    img = srgb8_to_linear(lit_windows(128))
    lit = (img[..., 0] > 0.6) & (img[..., 2] < 0.4)
    dark = img.mean(axis=-1) < 0.03
    assert lit.mean() > 0.01 and dark.mean() > 0.02


FIFTH_SET = (
    "cobbles_e",
    "cobbles_wet_e",
    "flags_e",
    "quay_stone_e",
    "warehouse_e",
    "far_quay_e",
    "asphalt_e",
    "puddles_e",
    "barrier_e",
    "verge_e",
)


def test_cobbles_rough_with_puddles():
    img = cobbles_roughness(128)
    rough = img[..., 1] / 255.0
    assert (img[..., 2] == 0).all() and (img[..., 0] == 255).all()
    assert 0.05 < (rough < 0.05).mean() < 0.4  # standing water and wet joints
    assert np.median(rough) > 0.2  # the stones rough-ish
    assert not TEXTURES["cobbles_wet_e"][1] and TEXTURES["cobbles_e"][1]


SIXTH_SET = (
    "asphalt_f",
    "puddles_f",
    "flags_f",
    "shopfronts_f",
    "render_f",
    "bricks_f",
    "concrete_f",
    "concrete_wet_f",
    "asphalt_road_f",
    "puddles_road_f",
    "cladding_f",
    "field_f",
    "houses_f",
)


def test_stained_concrete_panels():
    plain = paving(128, seed=127, flags=2, level=0.3, spread=0.03)
    stained = paving(128, seed=127, flags=2, level=0.3, spread=0.03, stains=0.2)
    lin_plain = srgb8_to_linear(plain).mean(axis=-1)
    lin = srgb8_to_linear(stained).mean(axis=-1)
    assert np.all(lin <= lin_plain + 1e-12)  # stains only darken
    darker = lin < 0.8 * lin_plain
    assert 0.05 < darker.mean() < 0.35  # about a fifth of the area
    assert 0.15 < np.median(lin) < 0.45  # light concrete, not asphalt
    # the options leave the earlier flags as they were
    assert np.array_equal(paving(64, seed=3), paving(64, 3, 4, 0.16, 0.04, 0.0))


SEVENTH_SET = (
    "asphalt_g",
    "puddles_g",
    "booth_g",
    "verge_g",
    "asphalt_close_g",
    "puddles_close_g",
    "garden_wall_g",
    "houses_g",
    "flags_g",
    "hedge_g",
)


def test_garden_wall_has_no_windows_and_large_puddles():
    lin = srgb8_to_linear(TEXTURES["garden_wall_g"][0]())
    assert (lin.mean(axis=-1) < 0.03).mean() < 0.02
    rough = TEXTURES["puddles_close_g"][0]()[..., 1] / 255.0
    assert 0.3 < (rough < 0.04).mean() < 0.5  # large puddles over about two fifths
    assert not TEXTURES["puddles_close_g"][1] and not TEXTURES["puddles_g"][1]


EIGHTH_SET = (
    "asphalt_h",
    "puddles_h",
    "platform_h",
    "arcade_h",
    "offices_h",
    "deck_h",
    "deck_wet_h",
    "parapet_h",
    "skyline_h",
)


def test_car_park_deck_is_stained_wet_concrete():
    lin = srgb8_to_linear(TEXTURES["deck_h"][0]()).mean(axis=-1)
    assert 0.12 < np.median(lin) < 0.4  # light concrete, not asphalt
    rough = TEXTURES["deck_wet_h"][0]()[..., 1] / 255.0
    assert 0.15 < (rough < 0.06).mean() < 0.45  # standing water over about a third
    assert not TEXTURES["deck_wet_h"][1] and not TEXTURES["puddles_h"][1]


NINTH_SET = (
    "asphalt_i",
    "puddles_i",
    "drive_i",
    "drive_wet_i",
    "hotel_i",
    "showroom_i",
    "flags_i",
    "asphalt_pass_i",
    "puddles_pass_i",
    "tunnel_damp_i",
    "lining_i",
    "portal_i",
    "slope_i",
)


def test_tunnel_lining_is_light_and_its_road_damp():
    lin = srgb8_to_linear(TEXTURES["lining_i"][0]()).mean(axis=-1)
    assert 0.35 < np.median(lin) < 0.65  # light wall panels, brighter than any facade
    damp = TEXTURES["tunnel_damp_i"][0]()[..., 1] / 255.0
    wet = TEXTURES["puddles_pass_i"][0]()[..., 1] / 255.0
    assert damp.min() > 0.1 and np.median(damp) > 2.0 * np.median(wet)  # no puddles inside
    assert not TEXTURES["tunnel_damp_i"][1] and not TEXTURES["drive_wet_i"][1]


@pytest.mark.parametrize(
    "new_set",
    [THIRD_SET, FOURTH_SET, FIFTH_SET, SIXTH_SET, SEVENTH_SET, EIGHTH_SET, NINTH_SET],
    ids=["third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth"],
)
def test_a_later_set_differs_from_every_other_texture(new_set):
    names = list(TEXTURES)
    start = names.index(new_set[0])
    assert names[start : start + len(new_set)] == list(new_set)
    assert_new(new_set, [name for name in TEXTURES if name not in new_set])
