"""The region-by-region comparison of a `streaks render` with a reference renderer's image.

Shared by the Mitsuba cross-check (`tools/mitsuba/crosscheck.py`) and the Blender/Cycles one
(`tools/blender/crosscheck.py`). The statistics themselves live in one place, `streaks compare`
(relative bias, relative RMSE and the noise test of tools/mitsuba/README.md, "The
statistics"): this module only turns regions given as fractions of the image into the pixel
rectangles `streaks compare` takes, runs it on two renders per renderer (two seeds), and prints
its JSON as a table with one line per region.

A region passes when its bias is within `k` standard errors (the noise test); the Blender check
adds its own criteria and writes them into each line (`passed`, and `result` for the table).
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]

#: A region: its name and (x0, y0, x1, y1) as fractions of the image, y down.
Region = tuple[str, tuple[float, float, float, float]]


def log(msg: str) -> None:
    """Prints a progress line on stderr."""
    print(msg, file=sys.stderr, flush=True)


def run(cmd: Sequence[object], stderr: list[str] | None = None) -> str:
    """Runs `cmd`, echoing it and its stderr (also appended to `stderr` line by line when
    given); exits with a message when it fails."""
    log("$ " + " ".join(str(c) for c in cmd))
    res = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if res.stderr.strip():
        log(res.stderr.rstrip())
    if stderr is not None:
        stderr.extend(res.stderr.splitlines())
    if res.returncode != 0:
        if res.stdout.strip():
            log(res.stdout.rstrip())
        raise SystemExit(f"command failed with exit code {res.returncode}: {cmd[0]} {cmd[1]}")
    return res.stdout


def find_streaks(arg: str | None) -> str:
    """The streaks binary: `arg`, else target/release or target/debug, else `streaks` on PATH."""
    if arg:
        return arg
    for profile in ("release", "debug"):
        cand = REPO / "target" / profile / "streaks"
        if cand.exists():
            return str(cand)
    found = shutil.which("streaks")
    if found:
        return found
    raise SystemExit("no streaks binary: build it (cargo build --release) or pass --streaks")


def pixel_region(name: str, frac: Sequence[float], w: int, h: int) -> str:
    """`name=x0,y0,x1,y1` in pixels (x1, y1 exclusive, at least one pixel wide) for
    `streaks compare --region`, from fractions of a `w` x `h` image."""
    x0, y0, x1, y1 = frac
    px = [round(x0 * w), round(y0 * h), round(x1 * w), round(y1 * h)]
    px[2] = max(px[2], px[0] + 1)
    px[3] = max(px[3], px[1] + 1)
    return f"{name}=" + ",".join(str(v) for v in px)


def parse_region(text: str) -> Region:
    """Parses `name=x0,y0,x1,y1` (fractions in [0, 1]) for argparse."""
    name, _, coords = text.rpartition("=")
    try:
        vals = tuple(float(v) for v in coords.split(","))
    except ValueError:
        vals = ()
    if len(vals) != 4 or not all(0.0 <= v <= 1.0 for v in vals):
        raise argparse.ArgumentTypeError(f"region {text!r}: need name=x0,y0,x1,y1 in [0, 1]")
    return (name or "region", (vals[0], vals[1], vals[2], vals[3]))


def compare(
    streaks: str,
    ours: tuple[Path, Path],
    reference: tuple[Path, Path],
    regions: Sequence[Region],
    width: int,
    height: int,
    k: float,
    diff_png: Path,
) -> dict[str, Any]:
    """Runs `streaks compare` with the noise test on two renders (two seeds) of each renderer and
    returns its JSON: `overall`, `regions` (each with `mean_a`, `mean_b`, `rel_bias`,
    `std_error`, `z`, `rel_rmse`, `passed`) and `largest_block`."""
    cmd: list[object] = [
        streaks, "compare", ours[0], reference[0], "--a2", ours[1], "--b2", reference[1],
        "--k", k, "--json", "--diff-png", diff_png,
    ]  # fmt: skip
    for name, frac in regions:
        cmd += ["--region", pixel_region(name, frac, width, height)]
    log("$ " + " ".join(str(c) for c in cmd))
    res = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if not res.stdout.strip():
        log(res.stderr)
        raise SystemExit("streaks compare produced no result")
    comparison: dict[str, Any] = json.loads(res.stdout)
    return comparison


def rows(comparison: dict[str, Any]) -> list[dict[str, Any]]:
    """The whole image's line followed by the regions' lines."""
    return [comparison["overall"], *comparison["regions"]]


def all_passed(comparison: dict[str, Any]) -> bool:
    """Whether every line passed."""
    return all(r["passed"] for r in rows(comparison))


def print_table(
    comparison: dict[str, Any], reference: str, diff_png: Path, ratio: bool = False
) -> None:
    """Prints one line per region: pixels, the two means, relative bias, its standard error, z,
    relative RMSE and the line's `result` (default ok/FAIL from `passed`; with `ratio`, also
    ours / reference), then the largest local difference. A z that is not a number (no noise:
    `streaks compare` writes null) prints as n/a."""
    extra = f" {'ratio':>7}" if ratio else ""
    print(
        f"{'region':<8} {'pixels':>16} {'ours':>11} {reference:>11} {'rel bias':>9} "
        f"{'std err':>8} {'z':>7} {'rel RMSE':>9}{extra}  result"
    )
    for r in rows(comparison):
        g = r["region"]
        extra = f" {r['mean_a'] / r['mean_b']:>7.4f}" if ratio else ""
        z = f"{r['z']:>+7.2f}" if isinstance(r["z"], float | int) else f"{'n/a':>7}"
        result = r.get("result", "ok" if r["passed"] else "FAIL")
        print(
            f"{g['name']:<8} {g['x0']:>3},{g['y0']:>3}-{g['x1']:>3},{g['y1']:>3}   "
            f"{r['mean_a']:>11.4e} {r['mean_b']:>11.4e} {100 * r['rel_bias']:>+8.2f}% "
            f"{100 * r['std_error'] / r['mean_b']:>7.2f}% {z} "
            f"{100 * r['rel_rmse']:>8.2f}%{extra}  {result}"
        )
    b = comparison["largest_block"]
    print(
        f"largest {b['size']}x{b['size']} block difference: {100 * b['rel_diff']:+.2f}% of the "
        f"image mean at ({b['x0']}, {b['y0']}); difference image {diff_png}"
    )
