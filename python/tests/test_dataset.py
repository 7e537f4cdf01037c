"""streaks.dataset.open against a tiny dataset `streaks dataset generate` writes: the samples'
arrays are the numbers of their files, in id order, splits as `streaks dataset index` lists
them, and the errors name the dataset."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import streaks
from conftest import generate
from streaks import io


@pytest.fixture(scope="module")
def dataset(streaks_bin: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("ds") / "ds"
    return generate(streaks_bin, root, count=3, seed=1, size=(32, 24))


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
        same(sample["depth_right"], io.read_pfm(folder / "depth1.pfm"))
        same(sample["occlusion"], io.read_png(folder / "occ0.png") == 255)
        same(sample["occlusion_right"], io.read_png(folder / "occ1.png") == 255)
        same(sample["left_camera"], io.read_png(folder / "im0.png"))
        same(sample["right_camera"], io.read_png(folder / "im1.png"))
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


def test_training_arrays_hold_no_inf_and_say_where_values_are(dataset: Path) -> None:
    ds = streaks.dataset.open(dataset)
    for i in range(len(ds)):
        sample = ds[i]
        t = streaks.dataset.training_arrays(sample)
        h, w = sample["disparity"].shape
        assert t["left"].shape == t["right"].shape == (3, h, w)
        assert t["left"].dtype == np.float32
        # The camera's PNG scaled to [0, 1], channels first.
        np.testing.assert_array_equal(
            t["left"], sample["left_camera"].transpose(2, 0, 1).astype(np.float32) / 255
        )
        for key, truth in (("", "disparity"), ("_right", "disparity_right")):
            d, valid = t[f"disparity{key}"], t[f"valid{key}"]
            assert np.isfinite(d).all() and not np.isnan(d).any()
            expected_valid = np.isfinite(sample[truth]) & (sample[truth] > 0)
            np.testing.assert_array_equal(valid, expected_valid)
            assert (~valid).any(), "the street's camera sees the sky"
            np.testing.assert_array_equal(d[valid], sample[truth][valid])
            assert (d[~valid] == 0).all()
        np.testing.assert_array_equal(t["noc"], t["valid"] & ~sample["occlusion"])
        np.testing.assert_array_equal(t["noc_right"], t["valid_right"] & ~sample["occlusion_right"])
        assert t["has_road"] and t["id"] == sample["id"]
        linear = streaks.dataset.training_arrays(sample, images="linear")
        np.testing.assert_array_equal(linear["left"], sample["left"].transpose(2, 0, 1))
    with pytest.raises(ValueError, match="images must be one of"):
        streaks.dataset.training_arrays(ds[0], images="srgb")


def test_a_dataset_keeps_only_its_outputs(streaks_bin: str, tmp_path: Path) -> None:
    root = generate(
        streaks_bin, tmp_path / "few", count=1, seed=2, size=(32, 24),
        extra=("--outputs", "images,gt"),
    )  # fmt: skip
    sample = streaks.dataset.open(root)[0]
    assert {"left_camera", "right_camera", "disparity", "occlusion"} <= sample.keys()
    assert not {"left", "right", "streak_mask", "road_mask"} & sample.keys()
    t = streaks.dataset.training_arrays(
        {**sample, "streak_mask": np.zeros(sample["disparity"].shape, bool)}
    )
    assert t["left"].shape == (3, 24, 32)
    with pytest.raises(KeyError, match="did not keep the EXR images"):
        streaks.dataset.training_arrays(sample, images="linear")


def test_images16_reach_the_training_arrays(streaks_bin: str, tmp_path: Path) -> None:
    root = generate(
        streaks_bin, tmp_path / "wide", count=1, seed=2, size=(32, 24),
        extra=("--outputs", "images,images16,gt,masks"),
    )  # fmt: skip
    sample = streaks.dataset.open(root)[0]
    wide = sample["left_camera16"]
    assert wide.dtype == np.uint16 and wide.shape == (24, 32, 3)
    assert np.abs(wide / 257.0 - sample["left_camera"]).max() <= 0.5
    t = streaks.dataset.training_arrays(sample)
    np.testing.assert_array_equal(
        t["left"], wide.transpose(2, 0, 1).astype(np.float32) / np.float32(65535)
    )


def test_the_torch_dataset_gives_tensors_a_loss_can_take(dataset: Path) -> None:
    torch = pytest.importorskip("torch", reason="PyTorch is not installed (pip install torch)")
    from streaks.torch import StereoDataset
    from torch.utils.data import DataLoader

    ds = StereoDataset(dataset)
    assert len(ds) == 3
    batch = next(iter(DataLoader(ds, batch_size=2)))
    assert batch["left"].shape == (2, 3, 24, 32) and batch["left"].dtype == torch.float32
    assert batch["valid"].dtype == torch.bool and batch["id"] == ["000000", "000001"]
    assert torch.isfinite(batch["disparity"]).all()
    sample = streaks.dataset.open(dataset)[1]
    valid = np.isfinite(sample["disparity"])
    np.testing.assert_array_equal(batch["valid"][1].numpy(), valid)
    np.testing.assert_array_equal(batch["disparity"][1].numpy()[valid], sample["disparity"][valid])
    flipped = StereoDataset(dataset, transform=lambda item: item["left"].flip(-1))
    assert torch.equal(flipped[0], ds[0]["left"].flip(-1))
    with pytest.raises(ValueError, match="images must be one of"):
        StereoDataset(dataset, images="srgb")
