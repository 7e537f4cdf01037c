#!/usr/bin/env python3
"""Race `streaks render` against Blender's Cycles at equal samples on a glTF scene as Blender's
glTF importer reads it (the "against Cycles" target of docs/benchmarks.md:
`scenes/rainy_street.gltf`).

Blender imports the scene once (`bpy.ops.import_scene.gltf`, the importer's defaults) and the
scene camera is made the active one; Cycles gets the cross-check's settings (build.py,
`cycles_settings`: CPU, no denoising, no clamping, no adaptive sampling, a one-pixel box filter,
black world, `max_depth - 2` bounces) at the same size and spp as ours. Then the two render
`--runs` times each, alternating (Cycles, ours, ours, Cycles, ...) so that load from other
processes falls on both alike, each run with its own seed:

- Cycles' time is `bpy.ops.render.render` in this process: its scene synchronisation, BVH build
  and rendering, but not Blender's start-up or the import (a measure generous to Cycles);
- ours is the whole `streaks render` process: loading the glTF, building the BVH and the light
  tree, rendering and writing the EXR.

Both use every core (Cycles' threads "auto", ours rayon's default). The script prints each
run's time, the medians and their ratio ours / Cycles, and with `--json` writes them.

    target/blender-venv/bin/python tools/blender/race.py scenes/rainy_street.gltf \
        --streaks target/release/streaks --width 427 --height 240 --spp 64 --runs 3

Needs a Python with `bpy` (pip install -r tools/blender/requirements.txt).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("scene", type=Path, help="a .gltf or .glb scene with a camera")
    p.add_argument("--streaks", type=Path, required=True, help="the streaks binary (release)")
    p.add_argument("--camera", help="the glTF camera's name (default: the first)")
    p.add_argument("--width", type=int, default=427)
    p.add_argument("--height", type=int, default=240)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument(
        "--max-depth",
        type=int,
        default=8,
        help="Mitsuba's meaning (Cycles gets max_depth - 2 bounces)",
    )
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--out", type=Path, default=Path("target/blender/race"), help="work folder")
    p.add_argument("--json", type=Path, help="write the times and the ratio here")
    args = p.parse_args(argv)
    for name in ("width", "height", "spp", "runs"):
        if getattr(args, name) < 1:
            p.error(f"--{name} must be at least 1")
    if args.max_depth < 2:
        p.error("--max-depth must be at least 2 (direct light)")
    if not args.scene.is_file():
        p.error(f"{args.scene}: no such file")
    if not args.streaks.is_file():
        p.error(f"{args.streaks}: no such file (cargo build --release)")
    return args


def import_scene(scene: Path, camera: str | None) -> str:
    """Imports `scene` into an empty Blender scene and makes its camera (`camera`, or the
    first) the active one; returns the camera's name."""
    import bpy
    from build import black_world, reset

    reset()
    bpy.ops.import_scene.gltf(filepath=str(scene.resolve()))
    cameras = [o for o in bpy.context.scene.objects if o.type == "CAMERA"]
    if not cameras:
        raise SystemExit(f"{scene}: Blender's importer found no camera")
    if camera is not None:
        named = [o for o in cameras if o.name == camera or o.data.name == camera]
        if not named:
            names = ", ".join(o.name for o in cameras)
            raise SystemExit(f"{scene}: no camera {camera!r} (Blender has {names})")
        cameras = named
    bpy.context.scene.camera = cameras[0]
    black_world()
    return cameras[0].name


def race(args: argparse.Namespace) -> dict[str, object]:
    from build import cycles_settings, render

    args.out.mkdir(parents=True, exist_ok=True)
    camera = import_scene(args.scene, args.camera)
    cycles_settings(args.width, args.height, args.spp, args.max_depth)
    ours_cmd = [
        str(args.streaks),
        "render",
        str(args.scene),
        "--width",
        str(args.width),
        "--height",
        str(args.height),
        "--spp",
        str(args.spp),
        "--max-depth",
        str(args.max_depth),
    ] + (["--camera", args.camera] if args.camera else [])
    times: dict[str, list[float]] = {"cycles": [], "streaks": []}
    for k in range(args.runs):
        order = ["cycles", "streaks"] if k % 2 == 0 else ["streaks", "cycles"]
        for who in order:
            t = time.perf_counter()
            if who == "cycles":
                render(args.out / f"cycles_{k}.exr", seed=k)
            else:
                cmd = ours_cmd + ["--seed", str(k), "-o", str(args.out / f"streaks_{k}.exr")]
                done = subprocess.run(cmd, capture_output=True, text=True)
                if done.returncode != 0:
                    raise SystemExit(
                        f"streaks failed ({done.returncode}): {' '.join(cmd)}\n{done.stderr}"
                    )
            times[who].append(time.perf_counter() - t)
            print(f"run {k}: {who} {times[who][-1]:.2f} s", file=sys.stderr, flush=True)
    cycles = statistics.median(times["cycles"])
    ours = statistics.median(times["streaks"])
    return {
        "scene": str(args.scene),
        "camera": camera,
        "width": args.width,
        "height": args.height,
        "spp": args.spp,
        "max_depth": args.max_depth,
        "times_s": times,
        "median_cycles_s": cycles,
        "median_streaks_s": ours,
        "ratio_streaks_over_cycles": ours / cycles,
    }


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    result = race(args)
    cycles, ours = result["median_cycles_s"], result["median_streaks_s"]
    print(
        f"{result['scene']} {args.width}x{args.height} {args.spp} spp, max depth {args.max_depth}: "
        f"Cycles median {cycles:.2f} s, streaks median {ours:.2f} s, "
        f"ratio {result['ratio_streaks_over_cycles']:.3f}"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
