"""The score agreement metric: normal form, per-beat agreement, start errors."""

from __future__ import annotations


import numpy as np
import pytest

from capture2notation.errors import CompareError
from capture2notation.notation.model import Score, Symbol
from capture2notation.quantise.agreement import (
    compare_scores,
    normalise,
    score_differences,
    start_errors,
    symbol_agreement,
)

REF = Score(
    symbols=(
        Symbol(0, 4, "support", "place", "middle"),
        Symbol(0, 1, "right_arm", "place", "low"),  # no-op: already hanging
        Symbol(1, 1, "right_arm", "forward", "middle"),
        Symbol(2, 2, "right_arm", "right", "high", bend=1),
        Symbol(1, 2, "head", "forward", "high"),
    ),
    tempo=60,
)


def test_normal_form_drops_no_ops():
    n = normalise(REF)
    parts = [s.part for s in n.symbols]
    assert parts.count("right_arm") == 2
    assert "support" not in parts  # standing on both feet is the starting pose
    assert normalise(n) == n
    steps = Score(
        symbols=(
            Symbol(0, 1, "right_support", "place", "middle"),
            Symbol(1, 1, "right_support", "place", "middle"),  # no change
            Symbol(2, 1, "right_support", "forward", "middle"),  # a step is never a no-op
            Symbol(3, 1, "support", "place", "low"),
        ),
        tempo=60,
    )
    assert [(s.start, s.part) for s in normalise(steps).symbols] == [
        (0, "right_support"), (2, "right_support"), (3, "support")
    ]


def test_identical_scores_agree_fully():
    a = compare_scores(REF, REF)
    assert a.symbol_agreement == 1.0 and a.exact and a.unmatched == 0 and a.median_start_error == 0.0


def test_shifted_symbol_costs_one_beat_cell_and_its_start_error():
    cand = Score(
        symbols=(
            Symbol(1, 1, "right_arm", "forward", "middle"),
            Symbol(3, 1, "right_arm", "right", "high", bend=1),  # one beat late
            Symbol(1, 2, "head", "forward", "high"),
            Symbol(1, 2, "support", "place", "low"),
        ),
        tempo=60,
    )
    # Columns: right_arm, head, supports over beats 0..3 → 12 cells; the late
    # arm differs at beat 2 and the plié (absent from REF) at beats 1, 2, 3.
    assert symbol_agreement(REF, cand) == pytest.approx(8 / 12)
    errs, missing = start_errors(REF, cand)
    assert sorted(errs.tolist()) == [0.0, 0.0, 1.0] and missing == 0
    diffs = score_differences(REF, cand)
    assert "missing: 2 2 right_arm right high bend=1" in diffs
    assert "extra: 3 1 right_arm right high bend=1" in diffs


def test_wrong_level_is_unmatched():
    cand = Score(symbols=(Symbol(1, 1, "right_arm", "forward", "low"),), tempo=60)
    errs, missing = start_errors(REF, cand)
    assert missing == 3 and errs.size == 0
    assert np.isnan(compare_scores(REF, cand).median_start_error)


def test_compare_needs_scores():
    with pytest.raises(CompareError, match="Score"):
        compare_scores(REF, "score.lab")
