"""streaks.dataset.open against a tiny dataset `streaks dataset generate` writes: the samples'
arrays are the numbers of their files, in id order, splits as `streaks dataset index` lists
them, and the errors name the dataset."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
import streaks
from streaks import io


@pytest.fixture(scope="module")
def dataset(streaks_bin: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("ds") / "ds"
    subprocess.run(
        [streaks_bin, "dataset", "generate", "-o", str(root), "--count", "3", "--seed", "1"]
        + ["--width", "32", "--height", "24", "--spp", "1", "--threads", "2"],
        check=True,
        capture_output=True,
        timeout=300,
    )
    return root


def test_samples_are_the_numbers_of_their_files(dataset: Path) -> None:
    ds = streaks.dataset.open(dataset)
    assert len(ds) == 3 and ds.ids == ["000000", "000001", "000002"]
    for i, sample_id in enumerate(ds.ids):
        sample = ds[i]
        folder = dataset / "samples" / sample_id
        assert sample["id"] == sample_id
        same = np.testing.assert_array_equal
        same(sample["left"], io.read_exr(folder / "im0.exr")["rgb"])
        same(sample["right"], io.read_exr(folder / "im1.exr")["rgb"])
        same(sample["disparity"], io.read_pfm(folder / "disp0.pfm"))
        same(sample["disparity_right"], io.read_pfm(folder / "disp1.pfm"))
        same(sample["depth"], io.read_pfm(folder / "depth0.pfm"))
        same(sample["streak_mask"], io.read_png(folder / "streaks0.png") == 255)
        same(sample["road_mask"], io.read_png(folder / "road0.png") == 255)
        assert sample["left"].shape == (24, 32, 3) and sample["streak_mask"].dtype == np.bool_
        assert sample["meta"]["rig"]["width"] == 32
    assert ds[-1]["id"] == "000002"
    with pytest.raises(IndexError, match="sample 3 out of range"):
        ds[3]


def test_splits_are_those_the_index_lists(dataset: Path) -> None:
    for split in ("train", "val", "test"):
        listed = (dataset / "splits" / f"{split}.txt").read_text().split()
        if listed:
            assert streaks.dataset.open(dataset, split=split).ids == sorted(listed)
        else:
            with pytest.raises(streaks.StreaksError):
                streaks.dataset.open(dataset, split=split)
    with pytest.raises(streaks.StreaksError, match="nope"):
        streaks.dataset.open(dataset, split="nope")


def test_a_folder_without_samples_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(streaks.StreaksError, match=str(tmp_path)):
        streaks.dataset.open(tmp_path)
