#!/usr/bin/env python3
"""Race `streaks render` against Mitsuba 3 on the same scene, as whole processes.

The scene is exported once with `streaks export-mitsuba` (same resolution, spp, max depth and
camera). Then each renderer renders it `--runs` times, alternating (ours, Mitsuba, Mitsuba,
ours, ...) so that load from other processes falls on both alike, each run with its own seed.
Every run is a whole process: Mitsuba's time includes Python start-up, `import mitsuba`, scene
loading and its LLVM JIT compilation; ours includes scene loading and the BVH build.

A converged reference is rendered by `--ref-renderer` (default: streaks) at `--ref-spp`, as two
renders of half the spp with seeds 1000 and 1001 (kept in the work folder and reused). Their
average is the reference; their difference measures the reference's own noise. Against it the
script reports, on the road region (`--region`, fractions of the image, y down):

- time ratio at equal spp: median t_ours / median t_mitsuba;
- MSE of each renderer (mean over runs, pixels and channels; divided by mean(ref)^2, so it is a
  squared relative RMSE), minus the reference's own noise (Var(ref pixel) = E[(a - b)^2] / 4):
  with a fast-converging renderer the reference's noise would otherwise dominate its MSE. The
  raw MSE is reported too;
- the equal-error time ratio (t_ours * MSE_ours) / (t_mitsuba * MSE_mitsuba): below 1 means we
  reach Mitsuba's error in less time (MSE falls as 1/time for an unbiased renderer);
- each renderer's relative bias mean(run) / mean(ref) - 1 with its standard error from the
  spread of the runs and the reference's own standard error (sqrt(sum (a - b)^2) / (2 N)),
  and z = bias / standard error (|z| < 3: bias within noise).

Usage:
    python3 tools/mitsuba/race.py scenes/crosscheck.gltf --camera cam --region road=0,0.7,1,1 \
        --width 320 --height 240 --spp 64 --max-depth 4 --runs 3 \
        --ref-renderer mitsuba --ref-spp 4096

Needs mitsuba (pip install -r tools/mitsuba/requirements.txt) and, for llvm_ad_rgb, Debian's
libllvm19 (DRJIT_LIBLLVM_PATH is set from the usual locations when unset).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LLVM_CANDIDATES = [
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
    "/usr/lib/llvm-19/lib/libLLVM.so.19.1",
]


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def set_llvm_path() -> None:
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        for cand in LLVM_CANDIDATES:
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                return


def mitsuba_worker(xml: str, out: str, spp: int, seed: int, variant: str) -> None:
    """The Mitsuba process of one run: load, render, write the EXR."""
    set_llvm_path()
    import mitsuba as mi

    mi.set_variant(variant)
    scene = mi.load_file(xml)
    img = mi.render(scene, spp=spp, seed=seed)
    tmp = out + ".tmp.exr"
    mi.util.write_bitmap(tmp, img, write_async=False)
    os.replace(tmp, out)


def timed(cmd: list[str]) -> float:
    """Runs `cmd` as a whole process and returns its wall-clock seconds; exits on failure."""
    t = time.perf_counter()
    res = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    elapsed = time.perf_counter() - t
    if res.returncode != 0:
        log(res.stdout + res.stderr)
        raise SystemExit(f"failed ({res.returncode}): {' '.join(str(c) for c in cmd)}")
    return elapsed


def find_streaks(arg: str | None) -> str:
    if arg:
        return arg
    cand = REPO / "target" / "release" / "streaks"
    if cand.exists():
        return str(cand)
    raise SystemExit("no release streaks binary: cargo build --release --bin streaks, or --streaks")


def parse_region(text: str) -> tuple[str, tuple[float, ...]]:
    name, _, coords = text.rpartition("=")
    vals = tuple(float(v) for v in coords.split(","))
    if (
        len(vals) != 4
        or not all(0.0 <= v <= 1.0 for v in vals)
        or vals[0] >= vals[2]
        or vals[1] >= vals[3]
    ):
        raise argparse.ArgumentTypeError(f"region {text!r}: need name=x0,y0,x1,y1 in [0, 1]")
    return (name or "region", vals)


def main() -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("scene", type=Path, nargs="?", help="glTF or OBJ scene")
    p.add_argument("--camera", default=None)
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=240)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--max-depth", type=int, default=4)
    p.add_argument("--runs", type=int, default=3, help="runs per renderer (seeds 1..runs)")
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--ref-renderer", choices=["streaks", "mitsuba"], default="streaks")
    p.add_argument(
        "--region",
        type=parse_region,
        default=("road", (0.0, 0.6, 1.0, 1.0)),
        help="name=x0,y0,x1,y1 in image fractions (default road=0,0.6,1,1)",
    )
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument(
        "--streaks", default=None, help="streaks binary (default target/release/streaks)"
    )
    p.add_argument(
        "--exporter",
        default=None,
        help="streaks binary that runs export-mitsuba (default: the --streaks one)",
    )
    p.add_argument(
        "--out", type=Path, default=None, help="work folder (default target/race/<scene>)"
    )
    p.add_argument("--json", type=Path, default=None, help="also write the results here")
    p.add_argument(
        "--mitsuba-worker",
        nargs=5,
        metavar=("XML", "OUT", "SPP", "SEED", "VARIANT"),
        help=argparse.SUPPRESS,
    )
    args = p.parse_args()
    if args.mitsuba_worker:
        xml, out, spp, seed, variant = args.mitsuba_worker
        mitsuba_worker(xml, out, int(spp), int(seed), variant)
        return 0
    if args.scene is None:
        p.error("the scene is required")
    if args.runs < 2:
        raise SystemExit("--runs must be at least 2 (the bias's standard error needs a spread)")

    set_llvm_path()
    import mitsuba as mi
    import numpy as np

    mi.set_variant("scalar_rgb")  # only to read EXRs here; the runs use --variant

    streaks = find_streaks(args.streaks)
    out = args.out or REPO / "target" / "race" / args.scene.stem
    out.mkdir(parents=True, exist_ok=True)
    common = ["--width", args.width, "--height", args.height, "--max-depth", args.max_depth]
    cam = ["--camera", args.camera] if args.camera else []
    xml_dir = out / "mitsuba"
    if xml_dir.exists():
        shutil.rmtree(xml_dir)
    timed(
        [
            args.exporter or streaks,
            "export-mitsuba",
            args.scene,
            "-o",
            xml_dir,
            "--spp",
            args.spp,
            *common,
            *cam,
        ]
    )
    xml = xml_dir / "scene.xml"

    def ours(spp: int, seed: int, path: Path) -> list:
        return [
            streaks,
            "render",
            args.scene,
            "-o",
            path,
            "--spp",
            spp,
            "--seed",
            seed,
            *common,
            *cam,
        ]

    def theirs(spp: int, seed: int, path: Path) -> list:
        return [sys.executable, __file__, "--mitsuba-worker", xml, path, spp, seed, args.variant]

    def load(path: Path):
        return np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]

    # The reference is two renders of half the spp each (seeds 1000 and 1001): their average is
    # the reference, and their difference measures the reference's own noise, which would
    # otherwise inflate both renderers' MSE and hide a bias behind an unknown reference error.
    half = max(args.ref_spp // 2, 1)
    ref_paths = [out / f"ref_{args.ref_renderer}_{half}spp_seed{seed}.exr" for seed in (1000, 1001)]
    make = ours if args.ref_renderer == "streaks" else theirs
    for seed, path in zip((1000, 1001), ref_paths, strict=True):
        if not path.exists():
            log(f"reference: {args.ref_renderer}, {half} spp, seed {seed} ...")
            t = timed(make(half, seed, path))
            log(f"reference half took {t:.1f} s")
    ref_a, ref_b = (load(path) for path in ref_paths)

    _, (x0, y0, x1, y1) = args.region
    h, w = ref_a.shape[:2]
    ys = slice(round(y0 * h), max(round(y1 * h), round(y0 * h) + 1))
    xs = slice(round(x0 * w), max(round(x1 * w), round(x0 * w) + 1))
    ref_a, ref_b = ref_a[ys, xs], ref_b[ys, xs]
    ref_r = 0.5 * (ref_a + ref_b)
    ref_mean = float(ref_r.mean())
    if not ref_mean > 0:
        raise SystemExit(f"the reference is black in region {args.region[0]}")
    # Var(ref pixel) = E[(a - b)^2] / 4 for the average of two independent halves; the
    # standard error of the region mean is sqrt(sum (a - b)^2) / (2 N).
    diff2 = (ref_a - ref_b) ** 2
    ref_noise_mse = float(diff2.mean()) / 4.0 / ref_mean**2
    ref_se = float(np.sqrt(diff2.sum())) / (2.0 * diff2.size) / ref_mean

    results = {
        "ours": {"times": [], "mse": [], "means": []},
        "mitsuba": {"times": [], "mse": [], "means": []},
    }
    for run in range(args.runs):
        seed = run + 1
        order = ["ours", "mitsuba"] if run % 2 == 0 else ["mitsuba", "ours"]
        for who in order:
            path = out / f"{who}_{args.spp}spp_seed{seed}.exr"
            t = timed((ours if who == "ours" else theirs)(args.spp, seed, path))
            img = load(path)[ys, xs]
            r = results[who]
            r["times"].append(t)
            r["mse"].append(float(((img - ref_r) ** 2).mean()) / ref_mean**2)
            r["means"].append(float(img.mean()))
            log(f"run {run + 1} {who}: {t:.2f} s, relative RMSE {r['mse'][-1] ** 0.5:.3f}")

    summary = {}
    for who, r in results.items():
        bias = statistics.mean(r["means"]) / ref_mean - 1.0
        se_runs = statistics.stdev(r["means"]) / (len(r["means"]) ** 0.5) / ref_mean
        se = (se_runs**2 + ref_se**2) ** 0.5
        raw = statistics.mean(r["mse"])
        # The renderer's own MSE: the raw MSE against the reference minus the reference's noise.
        own = max(raw - ref_noise_mse, 0.0)
        summary[who] = {
            "median_seconds": statistics.median(r["times"]),
            "mse_relative_raw": raw,
            "mse_relative": own,
            "rmse_relative": own**0.5,
            "bias_relative": bias,
            "bias_standard_error": se,
            "bias_z": bias / se if se > 0 else float("inf"),
            **r,
        }
    so, sm = summary["ours"], summary["mitsuba"]
    report = {
        "scene": str(args.scene),
        "width": args.width,
        "height": args.height,
        "spp": args.spp,
        "max_depth": args.max_depth,
        "mitsuba_variant": args.variant,
        "mitsuba_version": mi.__version__,
        "reference": {
            "renderer": args.ref_renderer,
            "spp": args.ref_spp,
            "paths": [str(p) for p in ref_paths],
            "noise_mse_relative": ref_noise_mse,
            "mean_standard_error": ref_se,
        },
        "region": {"name": args.region[0], "fractions": args.region[1]},
        "time_ratio_equal_spp": so["median_seconds"] / sm["median_seconds"],
        "equal_error_time_ratio": (so["median_seconds"] * so["mse_relative"])
        / (sm["median_seconds"] * sm["mse_relative"]),
        "equal_error_time_ratio_raw": (so["median_seconds"] * so["mse_relative_raw"])
        / (sm["median_seconds"] * sm["mse_relative_raw"]),
        "ours": so,
        "mitsuba": sm,
    }
    print(
        f"{args.scene.name} {args.width}x{args.height}, {args.spp} spp, "
        f"max depth {args.max_depth}, {args.runs} runs each; "
        f"mitsuba {mi.__version__} {args.variant}; reference "
        f"{args.ref_renderer} {args.ref_spp} spp; region {args.region[0]}"
    )
    print(
        f"reference noise: relative RMSE {ref_noise_mse**0.5:.4f}, mean standard error {ref_se:.5f}"
        " (subtracted from the MSEs below; included in z)"
    )
    print(f"{'':8} {'median s':>9} {'rel RMSE':>9} {'raw RMSE':>9} {'rel bias':>9} {'z':>6}")
    for who in ("ours", "mitsuba"):
        s = summary[who]
        print(
            f"{who:8} {s['median_seconds']:9.3f} {s['rmse_relative']:9.4f} "
            f"{s['mse_relative_raw'] ** 0.5:9.4f} {s['bias_relative']:+9.4f} {s['bias_z']:6.2f}"
        )
    print(f"time ratio at equal spp (ours/mitsuba): {report['time_ratio_equal_spp']:.3f}")
    print(
        "equal-error time ratio (t*MSE ours / t*MSE mitsuba): "
        f"{report['equal_error_time_ratio']:.3f}"
        f" (raw, reference noise not subtracted: {report['equal_error_time_ratio_raw']:.3f})"
    )
    if args.json:
        args.json.write_text(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
