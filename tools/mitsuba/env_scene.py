#!/usr/bin/env python3
"""Write scenes/crosscheck.gltf lit by an environment map only, for a Mitsuba cross-check of the
environment light (Mitsuba's `envmap`: the direction mapping, the texel convention, the
sampling and its MIS with the BSDFs).

The scene keeps the crosscheck scene's glossy wet road (ggx, alpha 0.1), its diffuse wall and
its camera, drops the point light and the sphere lamp, and names `sky.exr` in
`scenes[0].extras.streaks.environment`. The map (64 x 32, linear RGB, written with Mitsuba's
Bitmap) has structure: a sky gradient brighter toward the horizon, a dim ground, and a small
sun-like blob 15 degrees above the horizon just right of -Z, next to the map's left/right seam,
which the road reflects as a streak toward the camera.

    python3 tools/mitsuba/env_scene.py target/env
    python3 tools/mitsuba/crosscheck.py target/env/env_crosscheck.gltf --camera cam \\
        --width 160 --height 120 --spp 64 --max-depth 4 --region top=0,0,1,0.06 \\
        --region wall=0.1,0.1,0.9,0.45 --region road=0,0.62,1,1 --region streak=0.35,0.7,0.65,1

See tools/mitsuba/README.md for the result.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
WIDTH, HEIGHT = 64, 32
# The sun: its direction's (u, v) (u = 0 is -Z, v = 0 is +Y), radius in texels and radiance.
SUN_UV = (0.02, (90.0 - 15.0) / 180.0)
SUN_RADIUS = 1.5
SUN_RADIANCE = (60.0, 50.0, 35.0)


def sky_texel(x: int, y: int) -> tuple[float, float, float]:
    """The map's texel (x, y): texel centres at u = (x + 1/2) / W, v = y / (H - 1)."""
    u, v = (x + 0.5) / WIDTH, y / (HEIGHT - 1)
    if v < 0.5:
        t = v / 0.5  # 0 at the zenith, 1 at the horizon
        r, g, b = 0.05 + 0.25 * t, 0.1 + 0.3 * t, 0.4 + 0.2 * t
    else:
        r, g, b = 0.04, 0.03, 0.02
    du = (u - SUN_UV[0] + 0.5) % 1.0 - 0.5  # wrapped across the seam
    d2 = (du * WIDTH) ** 2 + ((v - SUN_UV[1]) * (HEIGHT - 1)) ** 2
    w = math.exp(-d2 / (2 * SUN_RADIUS**2))
    return r + w * SUN_RADIANCE[0], g + w * SUN_RADIANCE[1], b + w * SUN_RADIANCE[2]


def write_sky(path: Path) -> None:
    """Writes the map as an RGB float32 EXR with Mitsuba's Bitmap."""
    import mitsuba as mi
    import numpy as np

    mi.set_variant("scalar_rgb")
    texels = np.array(
        [[sky_texel(x, y) for x in range(WIDTH)] for y in range(HEIGHT)], dtype=np.float32
    )
    mi.Bitmap(texels, mi.Bitmap.PixelFormat.RGB).write(str(path))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", type=Path, help="folder for env_crosscheck.gltf, its .bin and sky.exr")
    args = p.parse_args()
    scene = json.loads((REPO / "scenes" / "crosscheck.gltf").read_text())
    names = {n.get("name"): i for i, n in enumerate(scene["nodes"])}
    keep = [names["road"], names["wall"], names["cam"]]
    scene["scenes"][0]["nodes"] = keep
    scene["scenes"][0]["extras"] = {
        "description": "crosscheck road and wall lit by sky.exr only",
        "streaks": {"environment": {"uri": "sky.exr", "strength": 1.0}},
    }
    args.out.mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "scenes" / "crosscheck.bin", args.out / "crosscheck.bin")
    write_sky(args.out / "sky.exr")
    (args.out / "env_crosscheck.gltf").write_text(json.dumps(scene, indent=1))
    print(args.out / "env_crosscheck.gltf")


if __name__ == "__main__":
    main()
