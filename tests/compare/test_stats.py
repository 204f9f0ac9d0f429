"""Sign tests laid out like Wolofsky's Table III."""

import numpy as np
import pytest

from capture2notation.compare.stats import sign_test, signs_from_differences
from capture2notation.errors import CompareError

# Rows of Wolofsky (1974) Table III whose totals are internally consistent:
# question -> (positive, negative, printed probability).  (Rows 1a, 5, 6b,
# 6f, 6i print probabilities that do not follow from their own counts.)
TABLE_III = {
    "1b": (17, 5, 0.008),
    "2": (11, 4, 0.059),
    "3": (17, 3, 0.001),
    "4": (14, 6, 0.058),
    "6a": (7, 5, 0.387),
    "6c": (10, 7, 0.315),
    "6d": (12, 6, 0.119),
    "6g": (14, 4, 0.015),
    "6k": (11, 3, 0.029),
    "6l": (6, 10, 0.227),
    "6m": (11, 9, 0.412),
    "6n": (11, 2, 0.011),
    "7a": (13, 10, 0.339),
    "7c": (20, 5, 0.002),
    "8": (15, 6, 0.039),
}


@pytest.mark.parametrize("question", sorted(TABLE_III))
def test_reproduces_table_iii(question):
    pos, neg, p = TABLE_III[question]
    signs = [1] * pos + [-1] * neg + [0] * 3  # ties are dropped
    row = sign_test(signs, question)
    assert (row.positive, row.negative, row.total, row.fewer) == (pos, neg, pos + neg, min(pos, neg))
    assert row.p == pytest.approx(p, abs=6e-4)
    assert row.significant == (p < 0.05)


def test_symmetric_in_sign():
    a = sign_test([1] * 9 + [-1] * 2)
    b = sign_test([-1] * 9 + [1] * 2)
    assert a.p == pytest.approx(b.p, rel=1e-12)


def test_all_ties_gives_nan_not_significant():
    row = sign_test([0, 0, 0])
    assert row.total == 0 and np.isnan(row.p) and not row.significant


def test_signs_from_differences_tolerance_and_nan():
    s = signs_from_differences([0.3, -0.05, np.nan, -0.4, 0.1], tolerance=0.1)
    assert s.tolist() == [1, 0, 0, -1, 0]


def test_bad_signs_rejected():
    with pytest.raises(CompareError, match="signs must be"):
        sign_test([2, 1], "q")
