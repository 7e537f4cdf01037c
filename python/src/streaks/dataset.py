"""Reading a dataset that `streaks dataset generate` wrote, sample by sample, as numpy arrays.

`open(root, split=None)` returns a sequence of samples (`len`, indexing): each a dict with
`left`, `right` (float32 H x W x 3, linear, from the EXRs), `left_camera`, `right_camera`
(the 8-bit PNGs as the sample's camera sees them, H x W x 3; `left_camera16`,
`right_camera16` the same at 16 bits where the dataset keeps `images16`), `disparity`,
`disparity_right`, `depth`, `depth_right` (float32 H x W, `inf` where there is no value: mask
it before a loss), `streak_mask`, `road_mask`, `occlusion`, `occlusion_right` (bool H x W;
`occlusion` marks the pixels the other eye does not see), `id` and `meta` (the sample's
meta.json). An array whose files the dataset did not keep (`dataset generate --outputs`) is
absent, and so is `road_mask` when the scene flags no road. The file names are the dataset
crate's and the files are read with the project's readers, which raise `streaks.StreaksError`
naming the file.

`training_arrays(sample)` turns such a sample into what a training loop wants: channels first,
images in floats, no `inf` anywhere and explicit valid masks (`streaks.torch` wraps it).
"""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from typing import Any

import numpy as np

from streaks._streaks import Dataset, Pair

IMAGES = ("camera", "linear")
"""The images `training_arrays` can take: the camera's PNGs or the linear render."""


def open(root: str | PathLike[str], split: str | None = None) -> Dataset:
    """The samples of the dataset in `root`: all complete ones, or those of `split`
    (`train`, `val`, `test`, as `streaks dataset index` listed them)."""
    return Dataset(root, split=split)


def _image(sample: Mapping[str, Any], eye: str, images: str) -> np.ndarray:
    """An eye's image as float32 3 x H x W: the camera's PNG scaled to [0, 1] by its bit
    depth, or the linear render as stored."""
    key = f"{eye}_camera" if images == "camera" else eye
    if images == "camera" and f"{key}16" in sample:
        key = f"{key}16"  # the same image at 16 bits, where the dataset keeps it
    if key not in sample:
        kept = "the PNG images" if images == "camera" else "the EXR images"
        raise KeyError(
            f"sample {sample.get('id')} has no {key!r}: the dataset did not keep {kept} "
            f"(dataset generate --outputs); use images={IMAGES[1 - IMAGES.index(images)]!r}"
        )
    img = np.asarray(sample[key])
    if images == "camera":
        scale = float(np.iinfo(img.dtype).max)
        img = img.astype(np.float32) / np.float32(scale)
    return np.ascontiguousarray(img.transpose(2, 0, 1), dtype=np.float32)


def _disparity(sample: Mapping[str, Any], key: str) -> tuple[np.ndarray, np.ndarray]:
    """A disparity map with 0 where it has no value, and the bool mask of where it has one."""
    d = np.asarray(sample[key], dtype=np.float32)
    valid = np.isfinite(d) & (d > 0)
    return np.where(valid, d, np.float32(0)), valid


PAIR_ARRAYS = (
    "left",
    "right",
    "left_camera",
    "right_camera",
    "disparity",
    "disparity_right",
    "depth",
    "depth_right",
    "streak_mask",
    "road_mask",
    "occlusion",
    "occlusion_right",
)
"""The arrays a `streaks.Pair` shares with a dataset sample, under the same names."""


def sample_of(pair: Pair) -> dict[str, Any]:
    """A pair rendered in-process as a dataset sample: its arrays under the sample's names
    (`PAIR_ARRAYS`), `id` (`seedN`) and `meta`; `road_mask` left out when no pixel sees a
    road material (as a sample of a scene that flags no road leaves it out)."""
    sample: dict[str, Any] = {name: getattr(pair, name) for name in PAIR_ARRAYS}
    if not sample["road_mask"].any():
        del sample["road_mask"]
    sample["id"] = f"seed{pair.meta['seed']}"
    sample["meta"] = pair.meta
    return sample


def training_arrays(sample: Mapping[str, Any] | Pair, images: str = "camera") -> dict[str, Any]:
    """A sample of `open(...)` (or a `streaks.Pair`) as a training loop takes it: `left`,
    `right` float32 3 x H x W (`images="camera"`: the PNGs in [0, 1], the 16-bit ones where
    the dataset keeps them; `"linear"`: the EXRs' radiance); `disparity`, `disparity_right`
    float32 H x W with 0 where there is no value and bool `valid`, `valid_right` beside them;
    `noc`, `noc_right` (valid and not occluded; as `valid` without occlusion masks);
    `streak_mask`, `road_mask` and `has_road`; `id`. Nothing it returns holds `inf` or
    NaN."""
    if images not in IMAGES:
        raise ValueError(f"images must be one of {IMAGES}, got {images!r}")
    if isinstance(sample, Pair):
        sample = sample_of(sample)
    disparity, valid = _disparity(sample, "disparity")
    disparity_right, valid_right = _disparity(sample, "disparity_right")
    shape = disparity.shape
    occlusion = np.asarray(sample.get("occlusion", np.zeros(shape, bool)), dtype=bool)
    occlusion_right = np.asarray(sample.get("occlusion_right", np.zeros(shape, bool)), dtype=bool)
    has_road = "road_mask" in sample
    return {
        "left": _image(sample, "left", images),
        "right": _image(sample, "right", images),
        "disparity": disparity,
        "disparity_right": disparity_right,
        "valid": valid,
        "valid_right": valid_right,
        "noc": valid & ~occlusion,
        "noc_right": valid_right & ~occlusion_right,
        "streak_mask": np.asarray(sample["streak_mask"], dtype=bool),
        "road_mask": np.asarray(sample["road_mask"], dtype=bool)
        if has_road
        else np.zeros(shape, bool),
        "has_road": has_road,
        "id": str(sample["id"]),
    }


__all__ = ["IMAGES", "PAIR_ARRAYS", "Dataset", "open", "sample_of", "training_arrays"]
