"""How far denoising moves the paper's streak disparities: a candidate pair against a reference.

    python tools/streak_shift.py REFERENCE CANDIDATE [CANDIDATE ...]

Each folder is a `streaks stereo --analyze` output with `sgm.pfm`, the SGM disparity of its
PNGs (`streaks disparity im0.png im1.png -o sgm.pfm`). The reference is a converged render;
the candidates are, say, the same pair at 64 spp raw and denoised. For each candidate it
prints

- per-row LK: the streaks of the reference's `analysis/report.json` matched to the
  candidate's by their rows (the candidate streak overlapping most), and over the rows both
  measured, the mean absolute and the mean signed difference of `measured_px`;
- SGM on the streak pixels: over the reference's ground-truth streak mask (`streaks0.png`,
  where both maps have a value), the mean absolute and mean signed difference.

`tools/denoise_streaks.sh` renders the pairs and runs this (docs/benchmarks.md, "Denoising").
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np


def read_pfm(path: Path) -> np.ndarray:
    """A one-channel PFM (`Pf`) as rows top to bottom (the file stores them bottom up)."""
    with path.open("rb") as f:
        header = f.readline().strip()
        if header != b"Pf":
            raise ValueError(f"{path}: not a one-channel PFM ({header!r})")
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        dtype = "<f4" if scale < 0 else ">f4"
        data = np.frombuffer(f.read(width * height * 4), dtype=dtype)
    if data.size != width * height:
        raise ValueError(f"{path}: {data.size} values for {width}x{height}")
    return data.reshape(height, width)[::-1].astype(np.float64)


@dataclass(frozen=True)
class Shift:
    """Mean absolute and mean signed difference (candidate minus reference) over `n` values."""

    mean_abs: float
    mean_signed: float
    n: int


def shift_of(diffs: np.ndarray) -> Shift:
    """The [`Shift`] of a set of differences (NaN means for none)."""
    if diffs.size == 0:
        return Shift(float("nan"), float("nan"), 0)
    return Shift(float(np.mean(np.abs(diffs))), float(np.mean(diffs)), int(diffs.size))


def lk_shift(reference: dict[str, Any], candidate: dict[str, Any]) -> Shift:
    """Per-row LK disparity of the candidate's streaks against the reference's: each reference
    streak against the candidate streak whose rows overlap it most, over their common rows."""
    diffs: list[float] = []
    for ref in reference["streaks"]:
        best, overlap = None, 0
        for cand in candidate["streaks"]:
            o = min(ref["last_row"], cand["last_row"]) - max(ref["first_row"], cand["first_row"])
            if o + 1 > overlap:
                best, overlap = cand, o + 1
        if best is None:
            continue
        by_row = {r["row"]: r["measured_px"] for r in best["rows"]}
        diffs += [by_row[r["row"]] - r["measured_px"] for r in ref["rows"] if r["row"] in by_row]
    return shift_of(np.asarray(diffs, dtype=np.float64))


def sgm_shift(reference: np.ndarray, candidate: np.ndarray, mask: np.ndarray) -> Shift:
    """SGM disparity of the candidate against the reference on the mask's pixels where both
    have a value."""
    if reference.shape != candidate.shape or reference.shape != mask.shape:
        raise ValueError(f"sizes differ: {reference.shape}, {candidate.shape}, {mask.shape}")
    ok = mask & np.isfinite(reference) & np.isfinite(candidate)
    return shift_of(candidate[ok] - reference[ok])


def load(folder: Path) -> tuple[dict[str, Any], np.ndarray]:
    """A folder's analysis report and SGM disparity."""
    report = json.loads((folder / "analysis" / "report.json").read_text())
    return report, read_pfm(folder / "sgm.pfm")


def main(argv: list[str] | None = None) -> int:
    """Prints one line per candidate; returns the exit status."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("reference", type=Path)
    p.add_argument("candidates", type=Path, nargs="+")
    args = p.parse_args(argv)
    from PIL import Image  # only to read the mask: the tests need no Pillow

    ref_report, ref_sgm = load(args.reference)
    mask = np.asarray(Image.open(args.reference / "streaks0.png").convert("L")) > 127
    print(f"reference {args.reference}: {len(ref_report['streaks'])} streaks, "
          f"{int(mask.sum())} streak pixels")  # fmt: skip
    for folder in args.candidates:
        report, sgm = load(folder)
        lk, dense = lk_shift(ref_report, report), sgm_shift(ref_sgm, sgm, mask)
        print(
            f"{folder}: LK {lk.mean_abs:.3f} px (signed {lk.mean_signed:+.3f}, {lk.n} rows); "
            f"SGM on streaks {dense.mean_abs:.3f} px (signed {dense.mean_signed:+.3f}, "
            f"{dense.n} pixels)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
