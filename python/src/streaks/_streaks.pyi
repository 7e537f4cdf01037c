"""Type stubs of the native module streaks._streaks (crates/python)."""

from os import PathLike
from pathlib import Path
from typing import Any, TypedDict, final

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

__all__ = [
    "DEFAULT_BASELINE",
    "Dataset",
    "Pair",
    "Scene",
    "StreaksError",
    "disparity",
    "read_exr",
    "read_pfm",
    "read_png",
    "score",
]

_Path = str | PathLike[str]

DEFAULT_BASELINE: float
"""The default baseline of `Scene.render_pair`, metres."""

class _RenderOptions(TypedDict, total=False):
    """The keywords of `Scene.render` (the flags of `streaks render`), all optional."""

    width: int | None
    height: int | None
    spp: int
    max_depth: int
    seed: int
    camera: str | int | None
    threads: int | None
    exposure: float
    sensor: str | None
    regularize: bool
    noise_target: float | None
    shutter: float | None
    rig_velocity: tuple[float, float, float] | None
    denoise: bool

class _PairOptions(_RenderOptions, total=False):
    """The keywords of `Scene.render_pair` (the flags of `streaks stereo`), all optional."""

    baseline: float

class StreaksError(ValueError):
    """An error of the streaks library: a scene, image or option it cannot use. The message
    names the file (where there is one) and the reason."""

@final
class Scene:
    """A scene loaded from a .gltf, .glb or .obj file, ready to render."""

    @staticmethod
    def load(
        path: _Path,
        *,
        allow_outside_scene: bool = False,
        env: _Path | None = None,
        env_color: tuple[float, float, float] | None = None,
        env_strength: float | None = None,
    ) -> Scene:
        """Loads a scene with the checks for untrusted files of `streaks render`."""
    @property
    def path(self) -> Path:
        """The file the scene was loaded from."""
    @property
    def warnings(self) -> list[str]:
        """The warnings the loader gave."""
    @property
    def cameras(self) -> list[str]:
        """The names of the scene's cameras, in the order `camera=` numbers them."""
    def render(self, **options: Unpack[_RenderOptions]) -> dict[str, npt.NDArray[np.float32]]:
        """Renders one view: a dict of float32 arrays by EXR layer name (`rgb`, `depth`, ...)."""
    def render_pair(self, **options: Unpack[_PairOptions]) -> Pair:
        """Renders a rectified stereo pair with ground truth, as `streaks stereo` does."""

@final
class Pair:
    """A rendered stereo pair: images, ground truth and metadata as numpy arrays."""

    left: npt.NDArray[np.float32]
    """The left image, linear RGB, H x W x 3."""
    right: npt.NDArray[np.float32]
    """The right image, linear RGB, H x W x 3."""
    disparity: npt.NDArray[np.float32]
    """The left view's disparity in pixels, H x W, inf where there is none."""
    disparity_right: npt.NDArray[np.float32]
    """The right view's disparity in pixels (Middlebury disp1), H x W, inf where none."""
    depth: npt.NDArray[np.float32]
    """The left view's camera-space depth Z in metres, H x W, inf on a miss."""
    depth_right: npt.NDArray[np.float32]
    """The right view's depth."""
    streak_mask: npt.NDArray[np.bool_]
    """The left view's streak mask, H x W."""
    streak_mask_right: npt.NDArray[np.bool_]
    """The right view's streak mask."""
    road_mask: npt.NDArray[np.bool_]
    """The left view's road-surface mask, H x W (all False without a road material)."""
    road_mask_right: npt.NDArray[np.bool_]
    """The right view's road-surface mask."""
    occlusion: npt.NDArray[np.bool_]
    """The left pixels whose point the right eye does not see (hidden or outside), H x W."""
    occlusion_right: npt.NDArray[np.bool_]
    """The right pixels whose point the left eye does not see."""
    left_camera: npt.NDArray[np.uint8]
    """The left image as the camera sees it (8-bit sRGB, H x W x 3: im0.png's pixels)."""
    right_camera: npt.NDArray[np.uint8]
    """The right image as the camera sees it (im1.png's pixels)."""
    sensor: npt.NDArray[np.float32] | None
    """The left camera's raw DN (H x W x 3) with `sensor=`, else None."""
    sensor_right: npt.NDArray[np.float32] | None
    """The right camera's raw DN with `sensor=`, else None."""
    meta: dict[str, Any]
    """scene, camera, seed, rig (the rig.json record), settings, timings, stats."""
    def save(self, dir: _Path) -> Path:
        """Writes the pair as `streaks stereo -o DIR` does; returns the folder."""

def read_pfm(path: _Path) -> npt.NDArray[np.float32]:
    """Reads a PFM, top row first: H x W (Pf) or H x W x 3 (PF)."""

def read_png(path: _Path) -> npt.NDArray[np.uint8] | npt.NDArray[np.uint16]:
    """Reads a PNG as stored: uint8 or uint16, H x W or H x W x C."""

def read_exr(path: _Path) -> dict[str, npt.NDArray[np.float32]]:
    """Reads a renderer EXR as a dict of float32 arrays by layer."""

@final
class Dataset:
    """A dataset's samples (all, or one split's), in the order of their ids."""

    def __new__(cls, root: _Path, *, split: str | None = None) -> Dataset:
        """Opens the dataset in `root` (optionally one split: train, val, test)."""
    @property
    def ids(self) -> list[str]:
        """The sample ids (folder names), in order."""
    def __len__(self) -> int: ...
    def __getitem__(self, index: int, /) -> dict[str, Any]:
        """Sample `index` as a dict of arrays (left, right, disparity, ...), id and meta."""

def disparity(
    left: npt.NDArray[Any], right: npt.NDArray[Any], method: str = "sgm"
) -> npt.NDArray[np.float32]:
    """The left view's disparity by a built-in method of `streaks benchmark` (`sgm`,
    `sgm-streaks`, `lk`): float32 H x W, `inf` where there is no value. `left`, `right`: H x W x 3
    or H x W, uint8/uint16 (scaled to [0, 1]) or float."""

def score(
    estimate: npt.NDArray[np.floating[Any]],
    truth: npt.NDArray[np.floating[Any]],
    *,
    streak_mask: npt.NDArray[Any] | None = None,
    road_mask: npt.NDArray[Any] | None = None,
    occlusion: npt.NDArray[Any] | None = None,
) -> dict[str, Any]:
    """The benchmark's scores of `estimate` against `truth` by region (`all`, `streak`,
    `non_streak`, `road`, `off_road`, `road_surface`, `non_occluded`; None without their
    masks), each a dict (`mean_abs`, `bad_2`, `d1`, `density`, `below_1px`, ...), and
    `phantom_hole_rate`."""
