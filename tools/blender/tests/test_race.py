"""Tests of tools/blender/race.py without Blender: its arguments."""

from pathlib import Path

import pytest
from race import parse_args

REPO = Path(__file__).resolve().parents[3]
SCENE = REPO / "scenes" / "rainy_street.gltf"


def test_defaults_and_choices(tmp_path):
    binary = tmp_path / "streaks"
    binary.write_text("")
    args = parse_args([str(SCENE), "--streaks", str(binary)])
    assert (args.width, args.height, args.spp, args.max_depth, args.runs) == (427, 240, 64, 8, 3)
    assert args.camera is None and args.json is None
    args = parse_args([str(SCENE), "--streaks", str(binary), "--spp", "16", "--camera", "driver"])
    assert args.spp == 16 and args.camera == "driver"


@pytest.mark.parametrize(
    "extra",
    [["--spp", "0"], ["--runs", "0"], ["--max-depth", "1"], ["--width", "-3"]],
)
def test_bad_arguments_exit(tmp_path, extra):
    binary = tmp_path / "streaks"
    binary.write_text("")
    with pytest.raises(SystemExit):
        parse_args([str(SCENE), "--streaks", str(binary), *extra])


def test_missing_files_exit(tmp_path):
    with pytest.raises(SystemExit):
        parse_args([str(tmp_path / "none.gltf"), "--streaks", str(tmp_path / "none")])
    binary = tmp_path / "streaks"
    binary.write_text("")
    with pytest.raises(SystemExit):
        parse_args([str(tmp_path / "none.gltf"), "--streaks", str(binary)])
