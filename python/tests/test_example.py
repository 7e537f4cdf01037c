"""examples/python/phantom_holes.py runs as the docs show it (at a tiny size): it renders,
scores every method, and its phantom-hole column is the mean that streaks.score gives."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from types import ModuleType

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "python" / "phantom_holes.py"
TINY = ["--pairs", "2", "--width", "64", "--height", "40", "--spp", "2"]


def _example() -> ModuleType:
    spec = importlib.util.spec_from_file_location("phantom_holes", EXAMPLE)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _rows(out: str) -> dict[str, list[float]]:
    rows = {}
    for line in out.splitlines():
        m = re.match(r"^(sgm-streaks|sgm|block-matching)\s+(.*)$", line)
        if m:
            rows[m.group(1)] = [float(v) for v in re.findall(r"-?\d+\.\d+|nan", m.group(2))]
    return rows


def test_the_example_scores_the_built_in_methods(capsys: pytest.CaptureFixture[str]) -> None:
    assert _example().main([*TINY, "--no-torch"]) == 0
    rows = _rows(capsys.readouterr().out)
    assert set(rows) == {"sgm", "sgm-streaks"}
    for epe, bad2, _streak_epe, holes, s_per_mp in rows.values():
        assert 0 <= epe < 64 and 0 <= bad2 <= 100 and 0 <= holes <= 100 and s_per_mp > 0


def test_the_example_runs_a_torch_method_on_batches(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("torch", reason="PyTorch is not installed (pip install torch)")
    assert _example().main(TINY) == 0
    rows = _rows(capsys.readouterr().out)
    assert set(rows) == {"sgm", "sgm-streaks", "block-matching"}
