"""streaks.io: the project's readers against files written here by hand, byte by byte, from the
formats' rules (PFM: rows bottom first, the scale's sign the byte order; PNG: filtered rows
in zlib), and their errors."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
import streaks
from streaks import io


def _pfm(path: Path, magic: bytes, rows: list[list[float]], little: bool) -> None:
    """A PFM of `rows` (top first, each the row's values, channels interleaved)."""
    width = len(rows[0]) // (3 if magic == b"PF" else 1)
    order = "<" if little else ">"
    data = b"".join(struct.pack(f"{order}{len(r)}f", *r) for r in reversed(rows))
    scale = b"-1.0" if little else b"1.0"
    path.write_bytes(magic + b"\n%d %d\n" % (width, len(rows)) + scale + b"\n" + data)


def test_read_pfm_grey_in_both_byte_orders(tmp_path: Path) -> None:
    rows = [[1.0, 2.5, float("inf")], [-4.0, 0.0, 6.25]]
    for little in (True, False):
        path = tmp_path / f"d{int(little)}.pfm"
        _pfm(path, b"Pf", rows, little)
        got = io.read_pfm(path)
        assert got.dtype == np.float32 and got.shape == (2, 3)
        np.testing.assert_array_equal(got, np.array(rows, np.float32))


def test_read_pfm_colour(tmp_path: Path) -> None:
    rows = [[1, 2, 3, 4, 5, 6], [7, 8, 9, 10, 11, 12]]
    path = tmp_path / "c.pfm"
    _pfm(path, b"PF", [[float(v) for v in r] for r in rows], True)
    np.testing.assert_array_equal(io.read_pfm(path), np.array(rows, np.float32).reshape(2, 2, 3))


def _png(path: Path, rows: np.ndarray, colour_type: int, depth: int) -> None:
    """A PNG of `rows` (H x W or H x W x C samples), unfiltered rows."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    h, w = rows.shape[:2]
    ihdr = struct.pack(">IIBBBBB", w, h, depth, colour_type, 0, 0, 0)
    dtype = ">u2" if depth == 16 else "u1"
    raw = b"".join(b"\x00" + rows[y].astype(dtype).tobytes() for y in range(h))
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


def test_read_png_keeps_the_stored_samples(tmp_path: Path) -> None:
    grey = np.array([[0, 255, 7], [128, 1, 254]], np.uint8)
    _png(tmp_path / "g.png", grey, 0, 8)
    got = io.read_png(tmp_path / "g.png")
    assert got.dtype == np.uint8
    np.testing.assert_array_equal(got, grey)
    kitti = np.array([[0, 256 * 37 + 5], [65535, 1]], np.uint16)
    _png(tmp_path / "k.png", kitti, 0, 16)
    got = io.read_png(tmp_path / "k.png")
    assert got.dtype == np.uint16
    np.testing.assert_array_equal(got, kitti)
    rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    _png(tmp_path / "c.png", rgb, 2, 8)
    np.testing.assert_array_equal(io.read_png(tmp_path / "c.png"), rgb)


def test_read_exr_of_a_saved_pair(tmp_path: Path) -> None:
    scene = streaks.Scene.load(
        Path(__file__).resolve().parents[2] / "scenes/rainy_street_small.gltf"
    )
    pair = scene.render_pair(width=16, height=12, spp=1, threads=2)
    pair.save(tmp_path)
    exr = io.read_exr(tmp_path / "im0.exr")
    np.testing.assert_array_equal(exr["rgb"], pair.left)
    np.testing.assert_array_equal(exr["depth"], pair.depth)
    assert exr["normal"].shape == (12, 16, 3) and exr["object"].shape == (12, 16)


def test_errors_name_the_file_and_the_reason(tmp_path: Path) -> None:
    missing = tmp_path / "missing.pfm"
    with pytest.raises(streaks.StreaksError, match=str(missing)):
        io.read_pfm(missing)
    short = tmp_path / "short.pfm"
    short.write_bytes(b"Pf\n4 4\n-1.0\n" + bytes(8))
    with pytest.raises(streaks.StreaksError, match="short.pfm.*truncated data"):
        io.read_pfm(short)
    not_png = tmp_path / "x.png"
    not_png.write_bytes(b"GIF89a" + bytes(20))
    with pytest.raises(streaks.StreaksError, match="x.png.*not a PNG"):
        io.read_png(not_png)
    with pytest.raises(streaks.StreaksError, match="folder"):
        io.read_exr(tmp_path)
    empty = tmp_path / "e.exr"
    empty.write_bytes(b"")
    with pytest.raises(streaks.StreaksError, match="e.exr"):
        io.read_exr(empty)
