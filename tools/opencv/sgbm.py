"""OpenCV's StereoSGBM as an external method of `streaks benchmark`.

    python tools/opencv/sgbm.py LEFT RIGHT OUT.pfm [--num-disparities 64] [--block-size 5]

reads a rectified pair (any image OpenCV reads; converted to grey), runs
``cv2.StereoSGBM`` with the parameters OpenCV's own stereo_match sample uses (P1 = 8 c b^2,
P2 = 32 c b^2, uniqueness 10, speckle filter 100 px / 32, disp12MaxDiff 1, mode SGBM_3WAY)
and writes the left view's disparity as a Middlebury PFM (little-endian, rows bottom to top).
StereoSGBM returns fixed-point disparities (16 x d, int16); they are divided by 16, and the
pixels it leaves invalid (below minDisparity) are written as inf, the PFM's "no value".

With `streaks benchmark`:

    streaks benchmark DATASET --method sgm \\
        --method-cmd "opencv-sgbm=python tools/opencv/sgbm.py {left} {right} {out}" -o OUT
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

Image = npt.NDArray[np.uint8]
Disparity = npt.NDArray[np.float32]


def read_grey(path: Path) -> Image:
    """The image at `path` as 8-bit grey; an error naming the file if OpenCV cannot read it."""
    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise ValueError(f"cannot read the image {path}")
    return np.asarray(img, dtype=np.uint8)


def sgbm(left: Image, right: Image, num_disparities: int = 64, block_size: int = 5) -> Disparity:
    """The left view's disparity by StereoSGBM, in pixels (float32, inf where invalid)."""
    if left.shape != right.shape:
        raise ValueError(f"the images differ in size: {left.shape} and {right.shape}")
    if num_disparities <= 0 or num_disparities % 16:
        raise ValueError(
            f"num_disparities must be a positive multiple of 16, not {num_disparities}"
        )
    if block_size < 1 or block_size % 2 == 0:
        raise ValueError(f"block_size must be odd, not {block_size}")
    channels = 1
    matcher = cv2.StereoSGBM_create(
        minDisparity=0,
        numDisparities=num_disparities,
        blockSize=block_size,
        P1=8 * channels * block_size**2,
        P2=32 * channels * block_size**2,
        disp12MaxDiff=1,
        uniquenessRatio=10,
        speckleWindowSize=100,
        speckleRange=32,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    )
    fixed = matcher.compute(left, right)
    disp = fixed.astype(np.float32) / 16.0
    # Invalid pixels are minDisparity - 1 (times 16); 0 is "no disparity" too.
    disp[fixed <= 0] = np.inf
    return disp


def write_pfm(path: Path, disp: Disparity) -> None:
    """Writes a one-channel Middlebury PFM: `Pf`, width height, scale -1 (little-endian), rows
    bottom to top. Written to a temporary file and renamed, so no partial file is left."""
    h, w = disp.shape
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "wb") as f:
        f.write(f"Pf\n{w} {h}\n-1\n".encode("ascii"))
        f.write(np.ascontiguousarray(disp[::-1], dtype="<f4").tobytes())
    tmp.replace(path)


def read_pfm(path: Path) -> Disparity:
    """Reads a one-channel PFM (either byte order) with rows top to bottom."""
    data = path.read_bytes()
    parts = data.split(b"\n", 3)
    if len(parts) < 4 or parts[0].strip() != b"Pf":
        raise ValueError(f"{path} is not a one-channel PFM")
    w, h = (int(v) for v in parts[1].split())
    scale = float(parts[2])
    dtype = "<f4" if scale < 0 else ">f4"
    values = np.frombuffer(parts[3], dtype=dtype, count=w * h).reshape(h, w)
    return values[::-1].astype(np.float32)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("left", type=Path)
    parser.add_argument("right", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--num-disparities", type=int, default=64)
    parser.add_argument("--block-size", type=int, default=5)
    args = parser.parse_args(argv)
    try:
        disp = sgbm(
            read_grey(args.left), read_grey(args.right), args.num_disparities, args.block_size
        )
        write_pfm(args.out, disp)
    except (ValueError, OSError) as e:
        print(f"sgbm.py: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
