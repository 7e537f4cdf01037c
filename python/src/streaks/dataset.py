"""Reading a dataset that `streaks dataset generate` wrote, sample by sample, as numpy arrays.

`open(root, split=None)` returns a sequence of samples (`len`, indexing): each a dict with
`left`, `right` (float32 H x W x 3, linear), `disparity`, `disparity_right`, `depth` (float32
H x W, `inf` where there is no value: mask it before a loss), `streak_mask`, `road_mask` (bool
H x W; no `road_mask` when the scene flags no road), `id` and `meta` (the sample's
meta.json). The file names are the dataset crate's and the files are read with the project's
readers, which raise `streaks.StreaksError` naming the file.
"""

from __future__ import annotations

from os import PathLike

from streaks._streaks import Dataset


def open(root: str | PathLike[str], split: str | None = None) -> Dataset:
    """The samples of the dataset in `root`: all complete ones, or those of `split`
    (`train`, `val`, `test`, as `streaks dataset index` listed them)."""
    return Dataset(root, split=split)


__all__ = ["Dataset", "open"]
