"""Reading the project's files into numpy arrays, with the project's readers (the checks for
hostile files included: regular files only, sizes checked from the header first).

- `read_pfm(path)`: a PFM (disparity, depth, fog), top row first; float32 `H x W` (`Pf`) or
  `H x W x 3` (`PF`), values as stored (`inf` stays `inf`).
- `read_png(path)`: a PNG as stored, `uint8` or `uint16`, `H x W` for grey, `H x W x C`
  otherwise (masks are 0/255 grey; KITTI disparity is `uint16`, disparity x 256).
- `read_exr(path)`: a renderer EXR as a dict of float32 arrays by layer (`rgb`, `depth`,
  `normal`, `albedo`, `specular`, ...).

Every reader raises `streaks.StreaksError` naming the file and the reason.
"""

from streaks._streaks import read_exr, read_pfm, read_png

__all__ = ["read_exr", "read_pfm", "read_png"]
