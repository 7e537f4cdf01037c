"""Tests of tools/streak_shift.py: the PFM reader and the two shifts."""

import math

import numpy as np
import pytest
from streak_shift import lk_shift, read_pfm, sgm_shift


def test_read_pfm_turns_the_rows_top_down(tmp_path):
    rows = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, math.inf]], dtype="<f4")
    path = tmp_path / "d.pfm"
    path.write_bytes(b"Pf\n3 2\n-1.0\n" + rows[::-1].tobytes())
    got = read_pfm(path)
    assert got.shape == (2, 3)
    assert got[0, 0] == 1.0 and math.isinf(got[1, 2])
    path.write_bytes(b"PF\n3 2\n-1.0\n")
    with pytest.raises(ValueError, match="one-channel"):
        read_pfm(path)


def streak(first, last, values):
    rows = [{"row": first + i, "measured_px": v} for i, v in enumerate(values)]
    return {"first_row": first, "last_row": last, "rows": rows}


def test_lk_shift_matches_streaks_by_their_rows():
    reference = {"streaks": [streak(10, 12, [5.0, 5.0, 5.0]), streak(40, 41, [2.0, 2.0])]}
    # The candidate finds them in the other order, one row shorter, and 0.1 px higher.
    candidate = {"streaks": [streak(40, 41, [2.1, 2.1]), streak(11, 12, [5.1, 5.1])]}
    s = lk_shift(reference, candidate)
    assert s.n == 4
    assert s.mean_abs == pytest.approx(0.1) and s.mean_signed == pytest.approx(0.1)
    assert lk_shift(reference, {"streaks": []}).n == 0


def test_sgm_shift_is_over_the_mask_where_both_have_values():
    ref = np.array([[1.0, 2.0], [3.0, math.inf]])
    cand = np.array([[1.5, 1.0], [9.0, 4.0]])
    mask = np.array([[True, True], [False, True]])
    s = sgm_shift(ref, cand, mask)
    assert s.n == 2
    assert s.mean_abs == pytest.approx(0.75) and s.mean_signed == pytest.approx(-0.25)
    with pytest.raises(ValueError, match="sizes differ"):
        sgm_shift(ref, cand[:1], mask)
