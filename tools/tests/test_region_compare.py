"""Tests of tools/region_compare.py: regions, pixel rectangles, the table."""

import argparse

import pytest
from region_compare import all_passed, find_streaks, parse_region, pixel_region, print_table


def test_parse_region_reads_name_and_fractions():
    assert parse_region("road=0,0.6,1,1") == ("road", (0.0, 0.6, 1.0, 1.0))
    assert parse_region("0,0,0.5,0.5") == ("region", (0.0, 0.0, 0.5, 0.5))


@pytest.mark.parametrize("text", ["road=0,0,1", "road=0,0,1,1.5", "road=a,b,c,d", "road="])
def test_parse_region_rejects_bad_regions(text):
    with pytest.raises(argparse.ArgumentTypeError):
        parse_region(text)


def test_pixel_region_rounds_and_keeps_one_pixel():
    assert pixel_region("a", (0.0, 0.6, 1.0, 1.0), 160, 120) == "a=0,72,160,120"
    # A region thinner than a pixel still covers one.
    assert pixel_region("b", (0.5, 0.5, 0.501, 0.5), 160, 120) == "b=80,60,81,61"


def test_find_streaks_prefers_the_argument():
    assert find_streaks("/some/streaks") == "/some/streaks"


def _row(name, mean_a, mean_b, z, passed):
    return {
        "region": {"name": name, "x0": 0, "y0": 0, "x1": 10, "y1": 10},
        "mean_a": mean_a,
        "mean_b": mean_b,
        "rel_bias": mean_a / mean_b - 1.0,
        "std_error": 0.01 * mean_b,
        "z": z,
        "rel_rmse": 0.1,
        "passed": passed,
    }


def _comparison():
    return {
        "overall": _row("image", 1.0, 1.0, 0.0, True),
        "regions": [_row("road", 1.01, 1.0, 1.0, True), _row("lamp", 2.0, 2.0, None, True)],
        "largest_block": {"size": 8, "rel_diff": 0.01, "x0": 0, "y0": 8},
    }


def test_print_table_prints_one_line_per_region(capsys, tmp_path):
    comparison = _comparison()
    comparison["regions"][0]["result"] = "ok (z!)"
    print_table(comparison, "cycles", tmp_path / "diff.png", ratio=True)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == [
        "region", "pixels", "ours", "cycles", "rel", "bias", "std", "err", "z", "rel", "RMSE",
        "ratio", "result",
    ]  # fmt: skip
    assert lines[1].startswith("image") and lines[1].endswith("ok")
    assert "+1.00%" in lines[2] and "1.0100" in lines[2] and lines[2].endswith("ok (z!)")
    assert "n/a" in lines[3]  # a null z (no noise)
    assert lines[4].startswith("largest 8x8 block difference: +1.00%")


def test_the_mitsuba_table_has_no_ratio_column(capsys, tmp_path):
    print_table(_comparison(), "mitsuba", tmp_path / "diff.png")
    header = capsys.readouterr().out.splitlines()[0]
    assert "mitsuba" in header and "ratio" not in header


def test_all_passed_needs_every_line():
    comparison = _comparison()
    assert all_passed(comparison)
    comparison["regions"][1]["passed"] = False
    assert not all_passed(comparison)
