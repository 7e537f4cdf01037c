"""Tests of tools/blender/crosscheck.py without Blender: arguments, warnings, judging."""

import pytest
from crosscheck import judge, parse_args, regions_of, unhonoured_extensions

from scenes import DIFFUSE, SCENES


def test_defaults_come_from_the_scene():
    args = parse_args(["diffuse"])
    assert (args.width, args.height, args.spp) == (DIFFUSE.width, DIFFUSE.height, DIFFUSE.spp)
    assert args.max_depth == DIFFUSE.max_depth and args.tolerance == DIFFUSE.tolerance
    assert args.seeds == [1, 2] and args.k == 4.0 and not args.lambert
    args = parse_args(["wet_street", "--spp", "16", "--tolerance", "0.05", "--uv-repeat"])
    assert args.spp == 16 and args.tolerance == 0.05 and args.uv_repeat


@pytest.mark.parametrize(
    "argv",
    [["nosuchscene"], ["diffuse", "--seeds", "3", "3"], ["diffuse", "--spp", "-1"],
     ["diffuse", "--max-depth", "1"]],
)  # fmt: skip
def test_bad_arguments_exit(argv):
    with pytest.raises(SystemExit):
        parse_args(argv)


def test_unhonoured_extensions_are_read_from_streaks_warnings():
    warnings = [
        'warning: a.glb: material "floor" (0) uses KHR_materials_specular, which is not '
        "supported: its specular strength ...",
        'warning: a.glb: material "wall" (1) uses KHR_materials_specular, which is not supported',
        'warning: a.glb: material "glass" (4) uses KHR_materials_transmission, which is not '
        "supported: rendered as an opaque surface",
        "rendered 160x120 at 64 spp",
    ]
    assert unhonoured_extensions(warnings) == [
        "KHR_materials_specular",
        "KHR_materials_transmission",
    ]
    assert unhonoured_extensions([]) == []


def test_regions_of_gives_fractions_for_every_region():
    regions = regions_of(DIFFUSE, 160, 120)
    assert [name for name, _ in regions] == [r.name for r in DIFFUSE.regions]
    assert all(0 <= v <= 1 for _, box in regions for v in box)


def _row(name, rel_bias, noise_ok):
    return {"region": {"name": name}, "rel_bias": rel_bias, "passed": noise_ok}


def _comparison(rows):
    return {"overall": _row("image", 0.0, True), "regions": rows}


def test_judge_needs_tolerance_and_noise():
    ok = _comparison([_row("point", 0.001, True), _row("spot", -0.019, True)])
    assert judge(DIFFUSE, ok, 0.02, noise_gates=True)
    beyond_noise = _comparison([_row("point", 0.001, False)])
    assert not judge(DIFFUSE, beyond_noise, 0.02, noise_gates=True)
    assert beyond_noise["regions"][0]["result"] == "FAIL"
    beyond_tolerance = _comparison([_row("point", 0.03, True)])
    assert not judge(DIFFUSE, beyond_tolerance, 0.02, noise_gates=True)


def test_judge_without_the_noise_gate_marks_what_the_noise_test_says():
    c = _comparison([_row("point", 0.01, False)])
    assert judge(DIFFUSE, c, 0.02, noise_gates=False)
    assert c["regions"][0]["result"] == "ok (z!)"
    assert c["regions"][0]["noise_ok"] is False and c["regions"][0]["within_tolerance"]


def test_noiseless_regions_are_judged_on_a_small_tolerance_only():
    # The panel seen directly: no noise, so streaks compare's own verdict means nothing.
    assert judge(DIFFUSE, _comparison([_row("panel", 0.0005, False)]), 0.02, noise_gates=True)
    assert not judge(DIFFUSE, _comparison([_row("panel", 0.005, True)]), 0.02, noise_gates=True)


def test_non_gating_lines_are_reported_but_not_counted():
    spec = SCENES["spot_blend"]
    c = _comparison([_row("spot_pen", -0.5, False), _row("point", 0.0, True)])
    c["overall"] = _row("image", -0.04, False)
    assert judge(spec, c, 0.02, noise_gates=True)
    assert c["regions"][0]["result"] == "(FAIL)" and c["overall"]["result"] == "(FAIL)"
