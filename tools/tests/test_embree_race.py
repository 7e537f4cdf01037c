"""The Embree race's reader of the BVH bench's files (tools/embree/race.py), without Embree."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

RACE = Path(__file__).resolve().parents[1] / "embree" / "race.py"


def load_race():
    # Loaded by path: tools/blender/race.py is another module named `race`.
    spec = importlib.util.spec_from_file_location("embree_race", RACE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_street(folder: Path, triangles: int, rays: int, hits: int) -> None:
    folder.mkdir(parents=True)
    np.arange(triangles * 9, dtype="<f4").tofile(folder / "triangles.f32")
    np.arange(rays * 7, dtype="<f4").tofile(folder / "primary.f32")
    (folder / "primary.hits").write_text(f"{hits}\n")


def test_reads_triangles_rays_and_hit_counts(tmp_path: Path) -> None:
    race = load_race()
    write_street(tmp_path / "street", triangles=2, rays=3, hits=2)
    tris, sets = race.load_street(tmp_path / "street")
    assert tris.shape == (2, 3, 3)
    assert tris[1, 0, 0] == 9.0
    rays, ours = sets["primary"]
    assert rays.shape == (3, 7) and ours == 2
    assert rays[2, 6] == 20.0


def test_truncated_files_are_refused_with_their_name(tmp_path: Path) -> None:
    race = load_race()
    write_street(tmp_path / "street", triangles=1, rays=1, hits=0)
    np.arange(10, dtype="<f4").tofile(tmp_path / "street" / "primary.f32")
    with pytest.raises(ValueError, match="primary.f32"):
        race.load_street(tmp_path / "street")


def test_an_empty_folder_is_an_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    race = load_race()
    assert race.main([str(tmp_path)]) == 1
    assert "no street" in capsys.readouterr().out
