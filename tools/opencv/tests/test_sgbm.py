"""Tests of the OpenCV StereoSGBM baseline (tools/opencv/sgbm.py) on a synthetic pair."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import sgbm  # noqa: E402

SHIFT = 7


def textured_pair(w: int = 160, h: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """A random-texture left image and the right image it gives at a constant disparity."""
    rng = np.random.default_rng(3)
    base = rng.integers(0, 256, size=(h, w + SHIFT), dtype=np.uint8)
    base = cv2.GaussianBlur(base, (3, 3), 0)
    # A point at left x is at right x - SHIFT: d = x_left - x_right = SHIFT.
    left = base[:, :w].copy()
    right = base[:, SHIFT:].copy()
    return left, right


def test_constant_shift_is_found_and_written_as_pfm(tmp_path: Path) -> None:
    left, right = textured_pair()
    cv2.imwrite(str(tmp_path / "l.png"), left)
    cv2.imwrite(str(tmp_path / "r.png"), right)
    out = tmp_path / "d.pfm"
    assert sgbm.main([str(tmp_path / "l.png"), str(tmp_path / "r.png"), str(out)]) == 0
    disp = sgbm.read_pfm(out)
    assert disp.shape == left.shape
    valid = np.isfinite(disp)
    # The left border (x < numDisparities) has no match: invalid, written as inf.
    assert not valid[:, :8].any()
    assert valid[:, 80:-10].mean() > 0.95
    assert abs(float(np.median(disp[valid])) - SHIFT) < 0.25
    assert not (disp[valid] <= 0).any()
    # The file is a little-endian Middlebury PFM, rows bottom to top.
    head = out.read_bytes()[:20]
    assert head.startswith(b"Pf\n160 96\n-1\n")
    raw = np.frombuffer(out.read_bytes()[len(b"Pf\n160 96\n-1\n") :], dtype="<f4")
    assert np.array_equal(raw.reshape(96, 160)[::-1], disp, equal_nan=True)


def test_fixed_point_is_divided_by_16() -> None:
    left, right = textured_pair()
    disp = sgbm.sgbm(left, right)
    finite = disp[np.isfinite(disp)]
    # Sub-pixel values in sixteenths.
    assert np.allclose(finite * 16, np.round(finite * 16))
    assert (np.abs(finite - SHIFT) < 1).mean() > 0.9


def test_bad_input_is_a_clear_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "none.png"
    assert sgbm.main([str(missing), str(missing), str(tmp_path / "d.pfm")]) == 1
    assert "none.png" in capsys.readouterr().err
    assert not (tmp_path / "d.pfm").exists()
    left, right = textured_pair()
    with pytest.raises(ValueError, match="differ in size"):
        sgbm.sgbm(left, right[:, :-1])
    with pytest.raises(ValueError, match="multiple of 16"):
        sgbm.sgbm(left, right, num_disparities=20)
