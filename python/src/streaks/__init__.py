"""streaks: render rainy night streets in stereo from Python.

Load a scene once and render views or rectified stereo pairs in-process, as numpy arrays with
the numbers the `streaks stereo` command writes::

    import streaks

    scene = streaks.Scene.load("scenes/rainy_street_small.gltf")
    pair = scene.render_pair(width=320, height=240, spp=16, seed=0)
    valid = np.isfinite(pair.disparity)  # inf where a pixel sees no surface

`streaks.disparity` runs the benchmark's built-in stereo methods and `streaks.score` scores a
disparity map as `streaks benchmark` does (EPE, bad-N, D1, the phantom-hole rate).
`streaks.dataset` reads a generated dataset and `streaks.torch` wraps it for PyTorch.
`streaks.io` reads the project's files (PFM, PNG, EXR) with the project's readers, and
`streaks.ray` generates datasets on a Ray cluster (the `streaks-ray` command). See
docs/python.md.
"""

from streaks import dataset, io
from streaks._streaks import DEFAULT_BASELINE, Pair, Scene, StreaksError, disparity, score

__version__ = "0.1.0"

__all__ = [
    "DEFAULT_BASELINE",
    "Pair",
    "Scene",
    "StreaksError",
    "dataset",
    "disparity",
    "io",
    "score",
]
