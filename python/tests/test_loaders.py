"""torchvision's own stereo loaders read a dataset's KITTI 2015 and SceneFlow views unchanged:
the images are the sample's camera PNGs and the disparities its ground truth (KITTI's to its
1/256 px quantisation, SceneFlow's exactly, 0 on the sky). Skipped where torchvision is not
installed (it needs PyTorch: pip install torch torchvision); the dataset tests check the same
files by the loaders' documented rules everywhere."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import streaks
from conftest import generate

datasets = pytest.importorskip("torchvision.datasets", reason="torchvision is not installed")


@pytest.fixture(scope="module")
def dataset(streaks_bin: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("loaders") / "ds"
    return generate(streaks_bin, root, count=3, seed=5, size=(48, 32))


def test_torchvision_reads_the_kitti_view(dataset: Path, tmp_path: Path) -> None:
    # torchvision looks for ROOT/Kitti2015/training (docs/datasets.md says so).
    (tmp_path / "Kitti2015").symlink_to(dataset / "kitti")
    kitti = datasets.Kitti2015Stereo(str(tmp_path), split="train")
    ours = streaks.dataset.open(dataset)
    assert len(kitti) == len(ours) == 3
    for i in range(3):
        left, right, disparity = kitti[i][:3]
        sample = ours[i]
        np.testing.assert_array_equal(np.asarray(left), sample["left_camera"])
        np.testing.assert_array_equal(np.asarray(right), sample["right_camera"])
        truth = sample["disparity"]
        has = disparity[0] > 0
        np.testing.assert_array_equal(has, np.isfinite(truth) & (np.round(truth * 256) >= 1))
        assert np.abs(disparity[0][has] - truth[has]).max() <= 0.5 / 256 + 1e-6


def test_torchvision_reads_the_sceneflow_view(dataset: Path) -> None:
    flying = datasets.SceneFlowStereo(str(dataset), variant="FlyingThings3D", pass_name="clean")
    ours = streaks.dataset.open(dataset)
    by_image = {ours[i]["left_camera"].tobytes(): ours[i] for i in range(len(ours))}
    assert len(flying) == 3
    for i in range(3):
        left, right, disparity = flying[i][:3]
        sample = by_image[np.asarray(left).tobytes()]
        np.testing.assert_array_equal(np.asarray(right), sample["right_camera"])
        truth = sample["disparity"]
        sky = ~np.isfinite(truth)
        np.testing.assert_array_equal(disparity[0][~sky], truth[~sky])
        assert (disparity[0][sky] == 0).all()
