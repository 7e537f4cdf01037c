"""PyTorch access to a dataset that `streaks dataset generate` wrote.

`StereoDataset(root, split=..., transform=...)` is a `torch.utils.data.Dataset` whose items are
dicts of tensors, ready for a `DataLoader` and a loss:

- `left`, `right`: float32, 3 x H x W. With `images="camera"` (the default) the images as the
  sample's camera sees them (`im0.png`, `im1.png`: noise, glare and the sensor's tone curve),
  scaled to [0, 1]; with `images="linear"` the exact render's linear radiance (the EXRs);
- `disparity`, `disparity_right`: float32, H x W, pixels, **0 where there is no value**;
- `valid`, `valid_right`: bool, H x W, where the disparity has a value (finite and positive).
  A loss must be taken over `valid` only: the files' `inf` (sky) never reaches a tensor;
- `noc`, `noc_right`: bool, H x W, valid and seen by both eyes (not occluded): the pixels a
  network can match, as KITTI's `disp_noc` (equal to `valid` when the dataset kept no
  occlusion masks);
- `streak_mask`, `road_mask`: bool, H x W, the left view's specular streaks and road surface
  (`road_mask` all False, and `has_road` False, when the scene flags no road);
- `id`: the sample's id.

The numbers are those of `streaks.dataset.open(root)[i]` (`streaks.dataset.training_arrays`
does the conversion in numpy). `transform`, when given, is called on each item dict and its
result returned. Needs PyTorch (`pip install './python[torch]'`).
"""

from __future__ import annotations

from collections.abc import Callable
from os import PathLike
from typing import Any

try:
    import torch
    from torch.utils.data import Dataset as _TorchDataset
except ImportError as e:  # pragma: no cover - only without torch
    raise ImportError(
        "streaks.torch needs PyTorch: pip install torch (or './python[torch]')"
    ) from e

from streaks import dataset as _dataset


class StereoDataset(_TorchDataset[dict[str, Any]]):
    """The samples of a streaks dataset (all, or one split's) as dicts of tensors."""

    def __init__(
        self,
        root: str | PathLike[str],
        split: str | None = None,
        transform: Callable[[dict[str, Any]], Any] | None = None,
        images: str = "camera",
    ) -> None:
        """Opens the dataset in `root` (see `streaks.dataset.open`); `images` is `"camera"`
        or `"linear"` (see the module documentation)."""
        if images not in _dataset.IMAGES:
            raise ValueError(f"images must be one of {_dataset.IMAGES}, got {images!r}")
        self.samples = _dataset.open(root, split=split)
        self.transform = transform
        self.images = images

    def __len__(self) -> int:
        """The number of samples."""
        return len(self.samples)

    def __getitem__(self, index: int) -> Any:
        """Sample `index` as a dict of tensors (and its `id`), through `transform`."""
        arrays = _dataset.training_arrays(self.samples[index], images=self.images)
        item: dict[str, Any] = {
            k: torch.from_numpy(v) if not isinstance(v, (str, bool)) else v
            for k, v in arrays.items()
        }
        return self.transform(item) if self.transform is not None else item


__all__ = ["StereoDataset"]
