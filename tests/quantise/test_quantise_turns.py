"""Turns and the score's key in the capture: the front over time, turn symbols, body-keyed labels."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import synthetic.random_scores as random_scores
from capture2notation.body import body_frame, front_of, joint_index
from capture2notation.compare.agreement import score_differences
from capture2notation.notation.model import Score, Symbol
from capture2notation.quantise.segment import segment_motion
from capture2notation.quantise.turns import continuous_front, turn_movements
from synthetic.interpret import interpret

FPS = 25.0


def _turn_score(turns, tempo=60, axes="standard"):
    """Stand on both feet and turn slowly: `turns` is ``(start, duration, direction, amount)``."""
    syms = [
        Symbol(Fraction(s), Fraction(d), "turn", direction, None, amount=Fraction(a)) for s, d, direction, a in turns
    ]
    end = max(s + d for s, d, *_ in turns)
    syms.append(Symbol(Fraction(end), Fraction(1), "right_arm", "forward", "middle"))
    return Score(symbols=tuple(syms), tempo=Fraction(tempo), axes=axes)


def test_continuous_front_folds_mirrored_hips_back():
    # A body seen from the wrong side has its hips mirrored: the raw front
    # jumps by 180°; the continuous front must follow the real turn.
    score = _turn_score([(0, 4, "right", "1/2")])
    motion = interpret(score, fps=FPS)
    joints = motion.joints()
    truth = motion.front
    mirrored = joints.copy()
    r, l = joint_index("right_hip"), joint_index("left_hip")
    frames = slice(40, 70)  # part way through the turn and after
    mirrored[frames, r], mirrored[frames, l] = joints[frames, l], joints[frames, r]
    raw = front_of(body_frame(mirrored)[:, 1])
    assert np.max(np.abs(raw - truth)) > 150.0  # the flip is there
    got = continuous_front(mirrored)
    np.testing.assert_allclose(got - got[0], truth - truth[0], atol=1e-6)


@pytest.mark.parametrize(
    "turns",
    [
        [(0, 2, "right", "1/8")],
        [(0, 4, "left", "1/2")],
        [(0, 2, "right", "1/4"), (2, 2, "left", "1/4")],
    ],
)
def test_clean_turns_come_back_with_amount_direction_and_span(turns):
    score = _turn_score(turns)
    joints = interpret(score, fps=FPS).joints()
    got = turn_movements(joints, FPS, measured=False, on_grid=np.ones(joints.shape[0], bool))
    want = [(round(s * FPS), round((s + d) * FPS), direction, Fraction(a)) for s, d, direction, a in turns]
    assert [(m.start_frame, m.end_frame, m.direction, m.amount) for m in got] == want


def test_measured_turn_is_found_through_jitter():
    score = _turn_score([(0, 2, "right", "1/2")])
    joints = interpret(score, fps=FPS).joints()
    rng = np.random.default_rng(3)
    noisy = joints + rng.normal(0.0, 0.01, joints.shape)  # 1 cm per coordinate
    got = turn_movements(noisy, FPS, measured=True)
    assert [(m.direction, m.amount) for m in got] == [("right", Fraction(1, 2))]
    # Start and arrival within a few frames of the written span (0 to 50).
    assert abs(got[0].start_frame - 0) <= 5 and abs(got[0].end_frame - 50) <= 5


def test_no_turn_is_written_for_a_dancer_who_does_not_turn():
    score = Score(symbols=(Symbol(Fraction(0), Fraction(2), "right_arm", "right", "high"),), tempo=Fraction(60))
    joints = interpret(score, fps=FPS).joints()
    assert turn_movements(joints, FPS, measured=False) == []


def test_body_keyed_random_scores_round_trip_exactly():
    rng = np.random.default_rng(1414)
    for _ in range(3):
        score = random_scores.random_score(rng, n_beats=8, axes="body")
        seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo, axes="body")
        assert seg.score.axes == "body"
        assert score_differences(score, seg.score) == []


def test_written_turns_round_trip_on_two_feet():
    score = _turn_score([(0, 2, "right", "1/4"), (3, 2, "left", "3/8")], tempo=90)
    seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo)
    assert score_differences(score, seg.score) == []
