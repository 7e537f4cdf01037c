#!/usr/bin/env python3
"""Cross-check `streaks render` against Mitsuba 3 on one scene.

Exports the scene with `streaks export-mitsuba`, renders it with Mitsuba (llvm_ad_rgb when
Debian's libLLVM 19 is available, else scalar_rgb) and with `streaks render` at the same
settings, each twice with two seeds, and runs `streaks compare` with the noise test: per region,
the relative bias of ours against Mitsuba's and the number of standard errors it amounts to.

    python3 tools/mitsuba/crosscheck.py scenes/crosscheck.gltf --spp 64 \
        --region road=0,0.55,1,1 --region wall=0.6,0.1,0.95,0.5

Regions are fractions of the image (x0,y0,x1,y1 in [0, 1], y down). `--ci` uses the
crosscheck scene's regions and settings and exits non-zero when the renderers disagree beyond
their noise. See tools/mitsuba/README.md.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))
from region_compare import (  # noqa: E402  (tools/ is not a package)
    all_passed,
    compare,
    find_streaks,
    log,
    parse_region,
    print_table,
    run,
)

# Regions of scenes/crosscheck.gltf as fractions of the image (x0, y0, x1, y1), y down: the
# road below the wall's base, the streaks of the sphere lamp (left) and of the point light
# (right), and the wall right of the lamp (the lamp itself is a few saturated pixels).
CROSSCHECK_REGIONS = {
    "road": (0.0, 0.6, 1.0, 1.0),
    "streak": (0.3, 0.62, 0.48, 1.0),
    "streak_pt": (0.62, 0.62, 0.8, 1.0),
    "wall": (0.45, 0.05, 1.0, 0.5),
}

LLVM_CANDIDATES = [
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
    "/usr/lib/aarch64-linux-gnu/libLLVM.so.19.1",
    "/usr/lib/llvm-19/lib/libLLVM.so.19.1",
]


def import_mitsuba(variant: str):
    """Imports mitsuba with `variant` ('auto': llvm_ad_rgb if libLLVM 19 is found)."""
    if variant in ("auto", "llvm_ad_rgb") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        for cand in LLVM_CANDIDATES:
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                break
    try:
        import mitsuba as mi
    except ImportError as e:
        raise SystemExit(
            f"cannot import mitsuba ({e}): pip install -r tools/mitsuba/requirements.txt"
        ) from e
    choices = ["llvm_ad_rgb", "scalar_rgb"] if variant == "auto" else [variant]
    for v in choices:
        try:
            mi.set_variant(v)
            return mi, v
        except Exception as e:  # the LLVM backend raises when libLLVM is missing
            log(f"mitsuba variant {v} unavailable: {e}")
    raise SystemExit(f"no usable mitsuba variant among {choices}")


def main() -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument(
        "scene", nargs="?", type=Path, help="glTF scene (default with --ci: scenes/crosscheck.gltf)"
    )
    p.add_argument(
        "--out", type=Path, default=None, help="work folder (default: target/crosscheck/<scene>)"
    )
    p.add_argument(
        "--streaks", default=None, help="streaks binary (default: target/release or target/debug)"
    )
    p.add_argument("--width", type=int, default=160)
    p.add_argument("--height", type=int, default=120)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--max-depth", type=int, default=4)
    p.add_argument("--camera", default=None)
    p.add_argument("--seeds", type=int, nargs=2, default=[1, 2], metavar=("S1", "S2"))
    p.add_argument(
        "--region",
        type=parse_region,
        action="append",
        default=[],
        help="name=x0,y0,x1,y1 as fractions of the image; repeatable",
    )
    p.add_argument("--k", type=float, default=4.0, help="fail when |bias| > k standard errors")
    p.add_argument("--variant", default="auto", choices=["auto", "llvm_ad_rgb", "scalar_rgb"])
    p.add_argument(
        "--ci",
        action="store_true",
        help="the CI check: crosscheck scene, its regions, camera cam; exit 1 on disagreement",
    )
    p.add_argument("--json", type=Path, default=None, help="also write the comparison JSON here")
    args = p.parse_args()

    if args.ci:
        args.scene = args.scene or REPO / "scenes" / "crosscheck.gltf"
        args.camera = args.camera or "cam"
        if not args.region:
            args.region = list(CROSSCHECK_REGIONS.items())
    if args.scene is None:
        p.error("a scene is required (or --ci)")
    if not args.scene.exists():
        raise SystemExit(f"no such scene: {args.scene}")
    streaks = find_streaks(args.streaks)
    out = args.out or REPO / "target" / "crosscheck" / args.scene.stem
    out.mkdir(parents=True, exist_ok=True)

    common = [
        "--width",
        args.width,
        "--height",
        args.height,
        "--spp",
        args.spp,
        "--max-depth",
        args.max_depth,
    ]
    if args.camera:
        common += ["--camera", args.camera]

    mdir = out / "mitsuba"
    run([streaks, "export-mitsuba", args.scene, "-o", mdir, *common, "--seed", args.seeds[0]])

    mi, variant = import_mitsuba(args.variant)
    timings = {}
    t = time.time()
    mscene = mi.load_file(str(mdir / "scene.xml"))
    for s in args.seeds:
        t = time.time()
        img = mi.render(mscene, seed=s, spp=args.spp)
        mi.Bitmap(img).write(str(out / f"mitsuba_s{s}.exr"))
        timings[f"mitsuba ({variant}) seed {s}"] = time.time() - t
    for s in args.seeds:
        t = time.time()
        run([streaks, "render", args.scene, "-o", out / f"streaks_s{s}.exr", *common, "--seed", s])
        timings[f"streaks seed {s}"] = time.time() - t

    s1, s2 = args.seeds
    diff_png = out / "diff.png"
    comparison = compare(
        streaks,
        (out / f"streaks_s{s1}.exr", out / f"streaks_s{s2}.exr"),
        (out / f"mitsuba_s{s1}.exr", out / f"mitsuba_s{s2}.exr"),
        args.region,
        args.width,
        args.height,
        args.k,
        diff_png,
    )
    if args.json:
        args.json.write_text(json.dumps(comparison, indent=2))

    print(
        f"scene {args.scene}, {args.width}x{args.height}, {args.spp} spp x 2 seeds, "
        f"max depth {args.max_depth}, mitsuba {mi.__version__} {variant}"
    )
    for k, v in timings.items():
        print(f"  {k}: {v:.1f} s")
    print_table(comparison, "mitsuba", diff_png)
    passed = all_passed(comparison)
    print("agreement within noise" if passed else f"DISAGREEMENT beyond {args.k} standard errors")
    return 0 if passed or not args.ci else 1


if __name__ == "__main__":
    sys.exit(main())
