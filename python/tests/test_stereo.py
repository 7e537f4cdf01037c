"""streaks.disparity and streaks.score: the benchmark's built-in methods give the map the
command gives on the same PNGs, and the scores follow their definitions on maps whose errors
are known exactly."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
import streaks
from conftest import generate
from streaks import io


@pytest.fixture(scope="module")
def sample_dir(streaks_bin: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("stereo") / "ds"
    return generate(streaks_bin, root, count=1, seed=4, size=(64, 40), spp=2) / "samples" / "000000"


def test_sgm_is_the_commands(sample_dir: Path, streaks_bin: str, tmp_path: Path) -> None:
    out = tmp_path / "d.pfm"
    subprocess.run(
        [streaks_bin, "disparity", str(sample_dir / "im0.png"), str(sample_dir / "im1.png")]
        + ["-o", str(out)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    command = io.read_pfm(out)
    command[~(np.isfinite(command) & (command > 0))] = np.inf
    ours = streaks.disparity(
        io.read_png(sample_dir / "im0.png"), io.read_png(sample_dir / "im1.png")
    )
    assert ours.dtype == np.float32 and ours.shape == (40, 64)
    np.testing.assert_array_equal(ours, command)
    assert np.isfinite(ours).mean() > 0.5


def test_the_methods_take_grey_and_float_images(sample_dir: Path) -> None:
    left = io.read_png(sample_dir / "im0.png")
    right = io.read_png(sample_dir / "im1.png")
    as_float = streaks.disparity(left / 255.0, right / 255.0, method="sgm-streaks")
    assert as_float.shape == (40, 64)
    lk = streaks.disparity(left, right, method="lk")
    assert np.isfinite(lk).mean() < np.isfinite(as_float).mean()
    with pytest.raises(ValueError, match="sgm, sgm-streaks, lk"):
        streaks.disparity(left, right, method="bm")
    with pytest.raises(TypeError, match="left must be a numpy array"):
        streaks.disparity(left.astype(np.int64), right)
    with pytest.raises(ValueError, match="H x W x 3"):
        streaks.disparity(left[..., :2], right[..., :2])


def test_scores_follow_their_definitions() -> None:
    truth = np.full((10, 20), 8.0, np.float32)
    truth[:2] = np.inf  # the sky: no ground truth
    road = np.zeros(truth.shape, bool)
    road[6:] = True  # 80 road pixels
    streak = np.zeros(truth.shape, bool)
    streak[6:, :5] = True  # 20 of them streak pixels
    estimate = truth.copy()
    estimate[streak] = 5.0  # the streak 3 px below the truth: a phantom hole
    estimate[2, :10] = np.inf  # 10 pixels without an estimate
    occlusion = np.zeros(truth.shape, bool)
    occlusion[:, 19] = True
    s = streaks.score(estimate, truth, streak_mask=streak, road_mask=road, occlusion=occlusion)
    truth_px, valid_px = 160, 150
    assert s["all"]["truth_pixels"] == truth_px and s["all"]["valid_pixels"] == valid_px
    assert s["all"]["mean_abs"] == pytest.approx(20 * 3 / valid_px)
    assert s["all"]["bad_2"] == pytest.approx(20 / valid_px)
    assert s["all"]["below_1px"] == pytest.approx(20 / truth_px)
    assert s["streak"]["mean_abs"] == pytest.approx(3.0)
    assert s["road"]["mean_abs"] == 0.0 and s["road"]["truth_pixels"] == 60
    assert s["phantom_hole_rate"] == pytest.approx(20 / 80)
    assert s["road_surface"]["below_1px"] == s["phantom_hole_rate"]
    assert s["non_occluded"]["truth_pixels"] == truth_px - 8
    bare = streaks.score(truth, truth)
    assert bare["all"]["mean_abs"] == 0.0 and bare["all"]["density"] == 1.0
    assert bare["streak"] is None and bare["road_surface"] is None
    assert bare["phantom_hole_rate"] is None
    with pytest.raises(streaks.StreaksError, match="size"):
        streaks.score(truth[:, :10].copy(), truth)
    with pytest.raises(TypeError, match="float disparity map"):
        streaks.score(np.zeros(truth.shape, np.uint8), truth)
