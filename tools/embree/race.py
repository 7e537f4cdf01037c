"""Trace the BVH bench's rays with Intel Embree, on one thread, for the same rays per second.

`cargo bench --bench bvh -- coherent` with `STREAKS_BVH_RAYS_OUT=DIR` writes each street's
triangles and four of its ray sets to `DIR/<street>/` (see `write_rays` in benches/bvh.rs).
This script builds an Embree scene over the same triangles (embreex: Embree 4 from PyPI,
`pip install -r tools/embree/requirements.txt`) and traces each set one ray at a time
(`rtcIntersect1` in a compiled loop, closest hits), reporting million rays per second, the
best of `--repeats` runs, and the hit count against the one the bench wrote. The rays go through
embreex's loop in one call per set, so Python's overhead is per set, not per ray.

    python tools/embree/race.py DIR [--repeats 5]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

RAY_FLOATS = 7
TRIANGLE_FLOATS = 9


def load_street(folder: Path) -> tuple[np.ndarray, dict[str, tuple[np.ndarray, int]]]:
    """The street's triangles (n, 3, 3) and its ray sets: name -> (rays (m, 7), our hits)."""
    tris = np.fromfile(folder / "triangles.f32", dtype="<f4")
    if tris.size % TRIANGLE_FLOATS:
        raise ValueError(f"{folder / 'triangles.f32'}: not a whole number of triangles")
    sets = {}
    for path in sorted(folder.glob("*.f32")):
        if path.name == "triangles.f32":
            continue
        rays = np.fromfile(path, dtype="<f4")
        if rays.size % RAY_FLOATS:
            raise ValueError(f"{path}: not a whole number of rays")
        hits_file = path.with_suffix(".hits")
        ours = int(hits_file.read_text().strip()) if hits_file.exists() else -1
        sets[path.stem] = (rays.reshape(-1, RAY_FLOATS), ours)
    return tris.reshape(-1, 3, 3), sets


def race(folder: Path, repeats: int) -> list[str]:
    """One line per ray set: rays, Embree's best rays per second and hits, ours."""
    from embreex import mesh_construction, rtcore_scene

    tris, sets = load_street(folder)
    scene = rtcore_scene.EmbreeScene()
    mesh_construction.TriangleMesh(scene, tris.astype(np.float32))
    lines = []
    for name, (rays, ours) in sets.items():
        origins = np.ascontiguousarray(rays[:, 0:3])
        directions = np.ascontiguousarray(rays[:, 3:6])
        t_max = np.ascontiguousarray(rays[:, 6])
        # Embree's rays end at `tfar`; an infinite end is what the bench's primary rays have.
        best = float("inf")
        hits = 0
        for _ in range(repeats):
            start = time.perf_counter()
            ids = scene.run(origins, directions, dists=t_max.copy())
            best = min(best, time.perf_counter() - start)
            hits = int((ids >= 0).sum())
        lines.append(
            f"{folder.name}/{name}: {len(rays)} rays, Embree {len(rays) / best / 1e6:.2f} Mrays/s, "
            f"{hits} hits (ours {ours})"
        )
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", type=Path, help="STREAKS_BVH_RAYS_OUT of the bench")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    streets = sorted(p for p in args.dir.iterdir() if (p / "triangles.f32").exists())
    if not streets:
        print(f"race.py: no street under {args.dir} (run the bench with STREAKS_BVH_RAYS_OUT)")
        return 1
    # Embree's own threads (TBB) are not used by single-ray queries; this keeps the build's too.
    os.environ.setdefault("TBB_NUM_THREADS", "1")
    for street in streets:
        for line in race(street, args.repeats):
            print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
