"""Prints the figures of `evaluate.sh` as Markdown tables: per input and method the phantom
holes, off-road and overall bad-2, density, bad-or-missing share and bad-2 after KITTI's fill
of the missing values (from `streaks benchmark`'s report.json), the held-back split by
condition, and the repair's own figures with its streak mask's scores and its
streak-level recall by length and contrast (from `streaks train-repair --evaluate`).

    python3 tools/streak_eval/summary.py OUT
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

INPUTS = [
    "heldback",
    "other_config",
    "dry_config",
    "heldback_b",
    "heldback_c",
    "other_config_c",
    "heldback_d",
    "other_config_d",
    "heldback_e",
    "other_config_e",
    "heldback_f",
    "other_config_f",
    "heldback_g",
    "other_config_g",
    "heldback_h",
    "other_config_h",
    "heldback_i",
    "other_config_i",
]
PAIRS = [
    "hill_bend",
    "crossing",
    "tabletop",
    "roundabout",
    "avenue",
    "shelf",
    "underpass",
    "hillside",
    "daylight_street",
    "bridge",
    "square",
    "quay",
    "arterial",
    "tramway",
    "forecourt",
    "toll_plaza",
    "close",
    "bus_station",
    "car_park_deck",
    "hotel_front",
    "tunnel_portal",
]


def pct(region: dict[str, Any] | None, key: str) -> str:
    """A share of a region's errors as a percentage, or n/a without the region."""
    if region is None or key not in region:
        return "n/a"
    return f"{100 * region[key]:.1f}"


def row(name: str, method: str, errors: dict[str, Any]) -> str:
    """One table row of a method's errors by region."""
    surface, off, full = errors.get("road_surface"), errors.get("off_road"), errors["all"]
    cells = [
        name,
        method,
        pct(surface, "below_1px"),
        pct(off, "bad_2"),
        pct(full, "bad_2"),
        pct(full, "density"),
        pct(full, "bad_all"),
        pct(full, "bad_2_filled"),
        pct(errors.get("streak"), "bad_2"),
    ]
    return "| " + " | ".join(cells) + " |"


HEADER = (
    "| input | method | phantom holes % | off-road bad-2 % | bad-2 % | density % "
    "| bad or missing % | bad-2 filled % | streak bad-2 % |\n"
    "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
)


def breakdown_rows(name: str, summary: list[dict[str, Any]]) -> list[str]:
    """Rows of the phantom holes and off-road bad-2 by distance, and the streak bad-2 by
    streak length, per method (n/a for an empty bin)."""
    out = []
    for s in summary:
        b = s.get("breakdown") or {}
        cells = []
        for key, field in (
            ("road_surface_by_distance", "below_1px"),
            ("off_road_by_distance", "bad_2"),
            ("streak_length", "bad_2"),
        ):
            cells.append(
                " / ".join(
                    pct(x["errors"], field) if x.get("errors") else "n/a" for x in b.get(key) or []
                )
                or "n/a"
            )
        out.append(f"| {name} | {s['method']} | " + " | ".join(cells) + " |")
    return out


BREAKDOWN_HEADER = (
    "| input | method | phantom holes % at 0-10 / 10-20 / 20-40 / 40+ m "
    "| off-road bad-2 % at 0-10 / 10-20 / 20-40 / 40+ m "
    "| streak bad-2 % of short / medium / long streaks |\n| --- | --- | --- | --- | --- |"
)


def tables(out: Path) -> str:
    """The Markdown of every table."""
    lines = [HEADER]
    conditions = []
    breakdown = [BREAKDOWN_HEADER]
    for name in INPUTS:
        path = out / f"bench-{name}" / "report.json"
        if not path.is_file():
            continue
        report = json.loads(path.read_text(encoding="utf-8"))
        for s in report["summary"]:
            lines.append(row(f"{name} ({len(report['samples'])})", s["method"], s["errors"]))
        breakdown += breakdown_rows(name, report["summary"])
        for c in report.get("by_condition") or []:
            for s in c["summary"]:
                label = f"{name}: {c['condition']} ({c['samples']})"
                conditions.append(row(label, s["method"], s["errors"]))
    for path in sorted(out.glob("bench-pairs*/report.json")):
        report = json.loads(path.read_text(encoding="utf-8"))
        for sample in report["samples"]:
            for r in sample["results"]:
                if r.get("errors"):
                    lines.append(row(sample["id"], r["method"], r["errors"]))
    text = "\n".join(lines)
    if len(breakdown) > 1:
        text += "\n\nBy distance and streak length:\n\n" + "\n".join(breakdown)
    if conditions:
        text += "\n\nBy condition:\n\n" + "\n".join([HEADER, *conditions])
    repair = [
        "| input | phantom holes % (sgm -> repaired) | off-road bad-2 % | missing or wrong % "
        "| road density % | streak mask P / R (pixels) | P / R (streaks) | streaks |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    recall = [
        "| input | streak-level recall of short / medium / long streaks "
        "| of faint / moderate / bright streaks |",
        "| --- | --- | --- |",
    ]
    for name in [*INPUTS, *PAIRS]:
        path = out / f"repair-{name}.json"
        if not path.is_file():
            continue
        f = json.loads(path.read_text(encoding="utf-8"))
        mask = f["streak_mask"]
        repair.append(
            f"| {name} | {100 * f['phantom_holes_sgm']:.1f} -> {100 * f['phantom_holes']:.1f} "
            f"| {100 * f['off_road_bad2_sgm']:.1f} -> {100 * f['off_road_bad2']:.1f} "
            f"| {100 * f['missing_or_wrong_sgm']:.1f} -> {100 * f['missing_or_wrong']:.1f} "
            f"| {100 * f['road_density_sgm']:.1f} -> {100 * f['road_density']:.1f} "
            f"| {mask['precision']:.3f} / {mask['recall']:.3f} "
            f"| {f['streak_level_precision']:.3f} / {f['streak_level_recall']:.3f} "
            f"| {f['counts']['streaks_true']} |"
        )
        if "streak_recall_by_length" in f:
            cells = [
                " / ".join(
                    "n/a" if b["recall"] is None else f"{b['recall']:.2f} ({b['streaks']})"
                    for b in f[key]
                )
                for key in ("streak_recall_by_length", "streak_recall_by_contrast")
            ]
            recall.append(f"| {name} | " + " | ".join(cells) + " |")
    text += "\n\nThe repair's own figures:\n\n" + "\n".join(repair) + "\n"
    if len(recall) > 2:
        text += (
            "\nStreak-level recall by length (short below 5 % of the height, long from 20 %) "
            "and by contrast (the streak's mean luminance less that beside it, in 8-bit code "
            "values: faint below 10, bright from 40), with the number of truth streaks:\n\n"
            + "\n".join(recall)
            + "\n"
        )
    return text


def main() -> None:
    """Prints the tables of the folder given as the argument."""
    if len(sys.argv) != 2:
        sys.exit("usage: summary.py OUT (the folder evaluate.sh wrote)")
    out = Path(sys.argv[1])
    if not out.is_dir():
        sys.exit(f"{out}: not a folder")
    print(tables(out))


if __name__ == "__main__":
    main()
