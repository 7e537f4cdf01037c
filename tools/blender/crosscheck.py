#!/usr/bin/env python3
"""Cross-check `streaks render` against Blender's Cycles on a scene built in Blender.

Builds one of the scenes of scenes.py with bpy, saves the .blend, exports it with Blender's glTF
exporter (default settings; cameras and punctual lights included), renders the .blend with
Cycles and the export with `streaks render`, each twice with two seeds, at the same resolution
and camera, and compares them region by region with the noise test of the Mitsuba cross-check
(tools/region_compare.py, `streaks compare`), plus a tolerance on the relative bias:

    target/blender-venv/bin/python tools/blender/crosscheck.py diffuse \
        --streaks target/release/streaks

Exits 0 when every gating region agrees (|z| <= k and |bias| <= tolerance), 1 otherwise.
Runs in a Python with `bpy` (pip install -r tools/blender/requirements.txt). See
tools/blender/README.md.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO / "tools"))
sys.path.insert(0, str(HERE))
import glb  # noqa: E402
from region_compare import (  # noqa: E402  (tools/ is not a package)
    Region,
    compare,
    find_streaks,
    log,
    print_table,
    run,
)

from scenes import NOISELESS_TOLERANCE, SCENES, SceneSpec, region_fractions  # noqa: E402

# streaks' warning for an extension it does not honour (crates/render/src/scene/extensions.rs).
UNHONOURED = re.compile(r"uses (\w+), which is not supported")


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line (see the module docs); sizes and spp default to the scene's own."""
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("scene", choices=sorted(SCENES), help="which scene of scenes.py")
    p.add_argument("--streaks", default=None, help="streaks binary (default: target/*/streaks)")
    p.add_argument("--out", type=Path, default=None, help="work folder (target/blender/<scene>)")
    p.add_argument("--width", type=int, default=None)
    p.add_argument("--height", type=int, default=None)
    p.add_argument("--spp", type=int, default=None, help="samples per pixel (both renderers)")
    p.add_argument(
        "--max-depth", type=int, default=None, help="longest path, Mitsuba's meaning (scene's)"
    )
    p.add_argument("--seeds", type=int, nargs=2, default=[1, 2], metavar=("S1", "S2"))
    p.add_argument("--k", type=float, default=4.0, help="fail when |bias| > k standard errors")
    p.add_argument(
        "--tolerance",
        type=float,
        default=None,
        help="fail when |relative bias| exceeds this fraction (default: the scene's, 0.02)",
    )
    p.add_argument(
        "--lambert",
        action="store_true",
        help="also compare the export's Lambert variant (materials exact, lights as exported)",
    )
    p.add_argument(
        "--uv-repeat",
        action="store_true",
        help="repeat textures by the meshes' UVs, not Mapping nodes (no KHR_texture_transform)",
    )
    p.add_argument("--json", type=Path, default=None, help="also write the comparison JSON here")
    args = p.parse_args(argv)
    spec = SCENES[args.scene]
    args.width = args.width or spec.width
    args.height = args.height or spec.height
    args.spp = args.spp or spec.spp
    args.max_depth = args.max_depth or spec.max_depth
    args.tolerance = spec.tolerance if args.tolerance is None else args.tolerance
    for name in ("width", "height", "spp"):
        if getattr(args, name) <= 0:
            p.error(f"--{name} must be positive")
    if args.max_depth < 2:
        p.error("--max-depth must be at least 2 (direct light)")
    if args.seeds[0] == args.seeds[1]:
        p.error("--seeds: the noise test needs two different seeds")
    return args


def regions_of(spec: SceneSpec, width: int, height: int) -> list[Region]:
    """The scene's regions as image fractions for `streaks compare`."""
    aspect = width / height
    return [(r.name, region_fractions(spec.camera, r, aspect)) for r in spec.regions]


def unhonoured_extensions(warnings: Sequence[str]) -> list[str]:
    """The extensions streaks warned it does not honour, sorted, each once."""
    return sorted({m.group(1) for w in warnings for m in UNHONOURED.finditer(w)})


def judge(spec: SceneSpec, comparison: dict[str, Any], tolerance: float, noise_gates: bool) -> bool:
    """Judges every line of `comparison` (the JSON of `streaks compare` with the noise test) and
    returns whether every gating region passed. A region passes when `|relative bias| <=
    tolerance` and, if `noise_gates`, its bias is within the noise (`passed` of streaks
    compare: `|z| <= k`); a noiseless region when `|relative bias| <= NOISELESS_TOLERANCE`.
    Non-gating lines (the whole image, regions with `gate=False`) are judged the same way but
    shown in brackets and not counted. Writes `noise_ok`, `within_tolerance`, `gates`,
    `passed` and `result` into each line."""
    specs = {r.name: r for r in spec.regions}
    ok = True
    for row in [comparison["overall"], *comparison["regions"]]:
        region = specs.get(row["region"]["name"])
        bias = abs(row["rel_bias"])
        row["noise_ok"] = bool(row["passed"])
        if region is not None and region.noiseless:
            row["within_tolerance"] = bias <= NOISELESS_TOLERANCE
            passed = row["within_tolerance"]
        else:
            row["within_tolerance"] = bias <= tolerance
            passed = row["within_tolerance"] and (row["noise_ok"] or not noise_gates)
        row["gates"] = region is not None and region.gate
        row["passed"] = passed
        word = "ok" if passed else "FAIL"
        if not row["noise_ok"] and not noise_gates and region is not None:
            word += " (z!)"
        row["result"] = word if row["gates"] else f"({word})"
        ok = ok and (passed or not row["gates"])
    return ok


def check_variant(
    args: argparse.Namespace,
    spec: SceneSpec,
    streaks: str,
    out: Path,
    glb: Path,
    variant: str,
    timings: dict[str, float],
) -> tuple[bool, dict[str, Any]]:
    """Renders `glb` with streaks (two seeds), compares with the Cycles renders in `out`, judges
    and prints the table; returns whether it passed and the comparison. `variant` "export" is
    the export as it is; "lambert" its Lambert variant (glb.py), where the noise always gates."""
    common = [
        "--width", args.width, "--height", args.height, "--spp", args.spp,
        "--max-depth", args.max_depth, "--camera", "cam",
    ]  # fmt: skip
    tag = "" if variant == "export" else f"_{variant}"
    warnings: list[str] = []
    ours = tuple(out / f"streaks{tag}_s{s}.exr" for s in args.seeds)
    for s, path in zip(args.seeds, ours, strict=True):
        t = time.time()
        run(
            [streaks, "render", glb, "-o", path, *common, "--seed", s],
            stderr=warnings,
        )
        timings[f"streaks {variant} seed {s}"] = time.time() - t
    unhonoured = unhonoured_extensions(warnings) if variant == "export" else []
    diff_png = out / f"diff{tag}.png"
    comparison = compare(
        streaks,
        (ours[0], ours[1]),
        (out / f"cycles_s{args.seeds[0]}.exr", out / f"cycles_s{args.seeds[1]}.exr"),
        regions_of(spec, args.width, args.height),
        args.width,
        args.height,
        args.k,
        diff_png,
    )
    passed = judge(spec, comparison, args.tolerance, noise_gates=not unhonoured)
    comparison["unhonoured_extensions"] = unhonoured
    print()
    print(
        f"{variant}: streaks render {glb.name}"
        + (" (materials as exact Lambertians, lights as exported)" if variant != "export" else "")
    )
    print_table(comparison, "cycles", diff_png, ratio=True)
    if unhonoured:
        print(
            f"NOTE: streaks does not honour {', '.join(unhonoured)}, which the export uses, so "
            "the two renders differ by design: the noise test is reported (z! where it fails) "
            f"but only the {100 * args.tolerance:g}% tolerance gates. It gates again as soon as "
            "streaks honours them."
        )
    criteria = f"{100 * args.tolerance:g}%" + ("" if unhonoured else " and the noise")
    print(f"agreement within {criteria}" if passed else f"DISAGREEMENT beyond {criteria}")
    return passed, comparison


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    spec = SCENES[args.scene]
    streaks = find_streaks(args.streaks)
    out = (args.out or REPO / "target" / "blender" / spec.name).resolve()
    out.mkdir(parents=True, exist_ok=True)

    import bpy  # type: ignore[import-not-found]  # noqa: PLC0415  (only where bpy exists)
    import build  # noqa: PLC0415  (imports bpy)

    timings: dict[str, float] = {}
    t = time.time()
    blend, glb_path = build.build(
        spec, out, args.width, args.height, args.spp, args.max_depth, not args.uv_repeat
    )
    timings["blender build + export"] = time.time() - t
    colours = build.colour_management()
    for s in args.seeds:
        t = time.time()
        build.render(out / f"cycles_s{s}.exr", s)
        timings[f"cycles seed {s}"] = time.time() - t
    variants = [("export", glb_path)]
    if args.lambert:
        doc, binary = glb.read_glb(glb_path.read_bytes())
        changed = glb.lambert_variant(doc, spec.materials)
        lambert_path = out / f"{spec.name}_lambert.glb"
        lambert_path.write_bytes(glb.write_glb(doc, binary))
        log(f"lambert variant: {', '.join(changed) or 'no material'} as exact Lambertians")
        variants.append(("lambert", lambert_path))

    print(
        f"scene {spec.name} ({blend.name}, exported {glb_path.name}), "
        f"{args.width}x{args.height}, {args.spp} spp x 2 seeds, max depth {args.max_depth}; "
        f"blender {bpy.app.version_string}"
    )
    print("  colour: " + ", ".join(f"{k} {v}" for k, v in colours.items()))
    for r in spec.regions:
        print(f"  region {r.name}: {r.note}{'' if r.gate else ' (reported, not gating)'}")
    results = {}
    passed = True
    for variant, path in variants:
        ok, comparison = check_variant(args, spec, streaks, out, path, variant, timings)
        passed = passed and ok
        results[variant] = comparison
    print()
    for k, v in timings.items():
        print(f"  {k}: {v:.1f} s")
    if args.json:
        results["colour_management"] = colours
        results["timings"] = timings
        args.json.write_text(json.dumps(results, indent=2))
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
