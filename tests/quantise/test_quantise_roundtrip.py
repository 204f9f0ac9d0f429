"""Truth round trip: the virtual dancer's joints quantise back to their score.

The interpreter (``synthetic.interpret``) performs a score; quantising its
truth joints with the tempo given must give back the same symbols (in the
normal form of :mod:`capture2notation.quantise.agreement`).
"""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.quantise.agreement import compare_scores, score_differences
from capture2notation.quantise.segment import segment_motion

interpret_mod = pytest.importorskip("synthetic.interpret")
phrases = pytest.importorskip("synthetic.phrases")
random_scores = pytest.importorskip("synthetic.random_scores")


def _capture(score, fps=25.0, tempo="given"):
    joints = interpret_mod.interpret(score, fps=fps).joints()
    return segment_motion(joints, fps, tempo=score.tempo if tempo == "given" else None)


def test_port_de_bras_captures_exactly_with_given_and_estimated_tempo():
    score = phrases.phrase("port_de_bras")
    assert score_differences(score, _capture(score).score) == []
    seg = _capture(score, tempo="estimated")
    assert seg.tempo == score.tempo
    assert score_differences(score, seg.score) == []


def test_figure7_captures_exactly():
    score = phrases.phrase("figure7")
    assert score_differences(score, _capture(score).score) == []


def test_leg_phrase_captures_exactly():
    """Plié, rise and relevé back to back (the knees straighten exactly at
    each arrival and bend again: a kink, not a speed minimum, must still part
    the supports), a transfer onto one foot, a gesture, a close, a step."""
    score = phrases.phrase("leg_phrase")
    assert score_differences(score, _capture(score).score) == []


@pytest.mark.parametrize("parts,split", [(("right_arm", "left_arm"), False), (("right_arm", "left_arm", "head"), False),
                                         (("right_arm", "left_arm"), True)])
def test_random_scores_capture_back(parts, split):
    rng = np.random.default_rng(20261122)
    n, exact = 8, 0
    for i in range(n):
        score = random_scores.random_score(rng, n_beats=8, parts=parts, split_arms=split, random_effort=bool(i % 2))
        seg = _capture(score)
        exact += not score_differences(score, seg.score)
        a = compare_scores(score, seg.score)
        assert a.symbol_agreement >= 0.9, (i, score_differences(score, seg.score))
    # A few draws leave the dancer a fraction of a degree off a written pose
    # (joint extremes, Space modulation); the rest must be exact.
    assert exact >= n - 2
