"""summary.py's tables from a small made-up evaluate.sh folder."""

import json
import re
from pathlib import Path

from summary import INPUTS, PAIRS, tables


def errors(phantom: float, off: float) -> dict:
    """A method's errors by region, with the fields the tables read."""
    full = {"bad_2": 0.1, "density": 0.8, "bad_all": 0.3, "bad_2_filled": 0.15}
    return {
        "all": full,
        "road_surface": {"below_1px": phantom},
        "off_road": {"bad_2": off},
        "streak": {"bad_2": 0.5},
    }


def repair(recall_by_length: list, recall_by_contrast: list | None) -> dict:
    """The JSON of `streaks train-repair --evaluate` (old files have no recall bins)."""
    f = {
        "phantom_holes_sgm": 0.2,
        "phantom_holes": 0.03,
        "off_road_bad2_sgm": 0.2,
        "off_road_bad2": 0.07,
        "missing_or_wrong_sgm": 0.5,
        "missing_or_wrong": 0.48,
        "road_density_sgm": 0.7,
        "road_density": 0.6,
        "streak_mask": {"precision": 0.4, "recall": 0.5},
        "streak_level_precision": 0.75,
        "streak_level_recall": 0.6,
        "counts": {"streaks_true": 10},
    }
    if recall_by_contrast is not None:
        f["streak_recall_by_length"] = recall_by_length
        f["streak_recall_by_contrast"] = recall_by_contrast
    return f


def write(path: Path, value: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(value), encoding="utf-8")


def test_every_pairs_folder_and_the_recall_bins_are_tabled(tmp_path: Path) -> None:
    # Two pair benchmarks of different sets: both sets' pairs get rows.
    for folder, sample in (("bench-pairs", "hill_bend"), ("bench-pairs_e", "quay")):
        write(
            tmp_path / folder / "report.json",
            {
                "summary": [],
                "samples": [
                    {"id": sample, "results": [{"method": "sgm", "errors": errors(0.1, 0.02)}]}
                ],
            },
        )
    bins = [
        {"bin": "short", "streaks": 4, "recall": 0.5},
        {"bin": "medium", "streaks": 0, "recall": None},
        {"bin": "long", "streaks": 6, "recall": 1.0},
    ]
    contrast = [
        {"bin": "faint", "streaks": 2, "recall": 0.0},
        {"bin": "moderate", "streaks": 5, "recall": 0.6},
        {"bin": "bright", "streaks": 3, "recall": 1.0},
    ]
    write(tmp_path / "repair-heldback_e.json", repair(bins, contrast))
    # A file written before the bins: in the repair table, not in the recall table.
    write(tmp_path / "repair-quay.json", repair(bins, None))
    text = tables(tmp_path)
    assert "| hill_bend | sgm | 10.0 | 2.0 |" in text
    assert "| quay | sgm | 10.0 | 2.0 |" in text
    assert "| heldback_e | 20.0 -> 3.0 |" in text
    assert "| quay | 20.0 -> 3.0 |" in text
    assert "| heldback_e | 0.50 (4) / n/a / 1.00 (6) | 0.00 (2) / 0.60 (5) / 1.00 (3) |" in text
    recall_table = text.split("Streak-level recall by length")[1]
    assert "| quay |" not in recall_table


def test_every_scored_input_has_a_row() -> None:
    # Each folder that evaluate.sh scores (any SET) is one of summary.py's inputs or pairs.
    script = (Path(__file__).resolve().parents[1] / "evaluate.sh").read_text(encoding="utf-8")
    lists = re.findall(r"repairs=\(([^)]*)\)", script)
    assert len(lists) >= 6  # the first set and SET=b .. f
    names = {Path(entry).name for entry in " ".join(lists).split()}
    assert {"heldback_f", "other_config_f", "tramway", "forecourt"} <= names
    assert names <= set(INPUTS) | set(PAIRS)
