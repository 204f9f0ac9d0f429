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


def test_a_measured_turn_straight_into_the_other_way_is_two_turns():
    # An eighth to the left run straight into two turns to the right: the
    # speed between them hardly dips next to the pirouette's, but a turn
    # turns one way (read as one, it was their net 15/8 to the right).
    score = _turn_score([(0, 1, "left", "1/8"), (1, 2, "right", "2")])
    joints = interpret(score, fps=FPS).joints()
    noisy = joints + np.random.default_rng(3).normal(0.0, 0.01, joints.shape)
    got = turn_movements(noisy, FPS, measured=True)
    assert [(m.direction, m.amount) for m in got] == [("left", Fraction(1, 8)), ("right", Fraction(2))]
    assert abs(got[0].end_frame - 25) <= 3


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


@pytest.mark.parametrize("amount, landing", [("1", "left"), ("1/4", "forward")])
def test_a_landing_after_a_turn_in_the_air_keeps_its_written_direction(amount, landing):
    # The pelvis flies straight along the front it took off with while the
    # body turns about it; undoing the turn frame by frame about the flying
    # pelvis curled its path (a full turn's travel came back to 'place').
    from capture2notation.notation.formats import lab

    score = lab.loads(
        f"tempo: 85\n0 1 support place low\n1 1/2 support air\n1 1/2 turn right amount={amount}\n"
        f"3/2 1/2 left_support {landing} low\n2 1 support place middle\n"
    )
    seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo)
    landed = [s for s in seg.score.symbols if s.part == "left_support"]
    assert [(s.start, s.direction, s.level) for s in landed] == [(Fraction(3, 2), landing, "low")]


@pytest.mark.parametrize(
    "text",
    [
        # A leap whose back leg gestures from the take-off: the top of the
        # flight (the pelvis's slowest frame) is no arrival of the weight.
        (
            "tempo: 85\n0 1 support place low\n1 1 right_leg left_back low\n1 1/2 support air\n"
            "3/2 1/2 left_support left low\n2 1 support place middle\n"
        ),
        # A pirouette on the left foot while the right leg opens: the unturned
        # pelvis wobbles in the fast turn, which is no arrival either.
        (
            "tempo: 101\n0 2 turn left amount=1/4\n2 2 left_support place high\n2 2 right_leg right low\n"
            "2 2 turn left amount=15/8\n4 3/2 support place middle\n"
        ),
        # After a hop that turns and lands on the right foot with the pelvis
        # over it, the free left foot closes beside it: 'place', not a step.
        (
            "tempo: 86\n0 2 left_leg forward low\n0 2 right_support place low\n2 1/2 support air\n"
            "2 1/2 turn right amount=1/4\n5/2 3/4 right_support forward low\n13/4 3/2 support place middle\n"
        ),
        # A jump landing on the spot sinks below its plié and rises to it:
        # the bottom of that dip, passed at almost no speed, is no rest.
        (
            "tempo: 77\n0 2 support place low\n2 1/2 support air\n5/2 3/4 support place low\n"
            "13/4 1 support place middle\n"
        ),
        # A hop sprung from a plié on one foot beside a gesture: that support
        # arrives at the take-off (its span once ran on to the landing).
        (
            "tempo: 112\n0 2 left_leg right_back low\n0 2 right_support place low\n2 3/4 support air\n"
            "11/4 1/2 support place low\n13/4 3/2 support place middle\n"
        ),
    ],
)
def test_leaps_pirouettes_landings_and_a_closing_foot_round_trip_exactly(text):
    from capture2notation.notation.formats import lab

    score = lab.loads(text)
    seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo)
    assert score_differences(score, seg.score) == []


def test_kinect_body_key_reproduces_labanotationsuite_labels(fixture_path):
    """LabanotationSuite's per-frame arm labels (an independent reference) from ``--axes body``."""
    import json

    from capture2notation.fitting.motion import joints_for_labels, read_motion
    from capture2notation.notation.model import LEVELS
    from capture2notation.quantise.labels import DIRECTION_NAMES, label_frames

    motion = read_motion(fixture_path("kinect/joints.csv"))
    ref = json.loads(fixture_path("kinect/joints.labanotationsuite_labels.json").read_text())["frames"]
    ticks = np.array([r["timestamp"] for r in ref], float) * 1e-7
    rows = [int(np.argmin(np.abs((motion.times - motion.times[0]) - (t - ticks[0])))) for t in ticks]
    agree = {}
    for axes in ("body", "standard"):
        lab = label_frames(joints_for_labels(motion), motion.fps, axes=axes)
        same = []
        for r, f in zip(ref, rows):
            for side in ("right", "left"):
                for seg, part in (("elbow", "upper_arm"), ("wrist", "forearm")):
                    p = lab.index(f"{side}_{part}")
                    d, lv = r[f"{side} {seg}"]
                    theirs = (
                        d.lower().replace(" ", "").replace("backward", "back"),
                        lv.lower().replace("normal", "middle"),
                    )
                    same.append(
                        (DIRECTION_NAMES[lab.direction[f, p]].replace("_", ""), LEVELS[lab.level[f, p]]) == theirs
                    )
        agree[axes] = float(np.mean(same))
    assert agree["body"] >= 0.97
    # The standard key reads the arms against gravity, not the leaning torso.
    assert agree["standard"] < 0.9


def test_turn_and_jump_phrase_captures_exactly_with_estimated_tempo():
    import synthetic.phrases as phrases

    score = phrases.phrase("turn_and_jump")
    seg = segment_motion(interpret(score, fps=FPS).joints(), FPS)
    assert seg.tempo == score.tempo
    assert score_differences(score, seg.score) == []


@pytest.mark.parametrize("seed", [3, 4])
def test_a_measured_swing_out_and_back_is_no_turn_but_a_held_one_is(seed):
    """Fitted hips swing 45° out and back within half a second (measured on
    renders of a dancer who never turns), the feet with them: the front has
    not changed, so no turn is written.  The same eighth turn held for two
    beats before turning back is two turns."""
    rng = np.random.default_rng(seed)
    swing = interpret(_turn_score([(0, 0.5, "right", "1/8"), (0.5, 0.5, "left", "1/8")], tempo=120), fps=FPS)
    joints = swing.joints()
    assert turn_movements(joints + rng.normal(0.0, 0.01, joints.shape), FPS, measured=True) == []
    held = interpret(_turn_score([(0, 1, "right", "1/8"), (3, 1, "left", "1/8")], tempo=60), fps=FPS)
    joints = held.joints()
    got = turn_movements(joints + rng.normal(0.0, 0.01, joints.shape), FPS, measured=True)
    assert [(m.direction, m.amount) for m in got] == [("right", Fraction(1, 8)), ("left", Fraction(1, 8))]


@pytest.mark.parametrize("seed", [3, 4])
def test_a_quarter_turn_and_straight_back_is_two_turns(seed):
    """Larger than any swing of fitted hips (SWING_MAX_EIGHTHS): danced, written."""
    rng = np.random.default_rng(seed)
    joints = interpret(_turn_score([(0, 1, "right", "1/4"), (1, 1, "left", "1/4")], tempo=120), fps=FPS).joints()
    got = turn_movements(joints + rng.normal(0.0, 0.01, joints.shape), FPS, measured=True)
    assert [(m.direction, m.amount) for m in got] == [("right", Fraction(1, 4)), ("left", Fraction(1, 4))]


@pytest.mark.parametrize("seed", [3, 4])
def test_two_measured_turns_the_same_way_back_to_back_are_two_turns(seed):
    """A quarter turn straight into a half turn, both right: the turning all but stops between them."""
    rng = np.random.default_rng(seed)
    joints = interpret(_turn_score([(0, 2, "right", "1/4"), (2, 2, "right", "1/2")]), fps=FPS).joints()
    got = turn_movements(joints + rng.normal(0.0, 0.01, joints.shape), FPS, measured=True)
    assert [(m.direction, m.amount) for m in got] == [("right", Fraction(1, 4)), ("right", Fraction(1, 2))]
    assert abs(got[0].end_frame - 50) <= 5 and abs(got[1].start_frame - 50) <= 5


@pytest.mark.parametrize("seed", [3, 4])
def test_a_slow_measured_eighth_turn_is_written(seed):
    """An eighth over four beats at 60 bpm (11°/s), through jitter."""
    rng = np.random.default_rng(seed)
    joints = interpret(_turn_score([(1, 4, "left", "1/8")]), fps=FPS).joints()
    got = turn_movements(joints + rng.normal(0.0, 0.01, joints.shape), FPS, measured=True)
    assert [(m.direction, m.amount) for m in got] == [("left", Fraction(1, 8))]


def test_feet_are_read_no_further_back_than_the_turn_before():
    """A turn that meets the one before starts where the feet are still
    turning: read from there, an eighth right straight after a turn left
    looks as if the feet turned the other way; read from where the turn
    before arrives, they turned with the hips."""
    from capture2notation.quantise.turns import _feet_turn_too

    heading = np.r_[np.linspace(300.0, 0.0, 16), np.linspace(0.0, 45.0, 11)[1:], np.full(15, 45.0)]
    feet = np.stack([heading, heading], axis=1)
    a, b = 15, 25  # the eighth right: from the frame the turn left arrives to its own arrival
    assert not _feet_turn_too(feet, a, b, 45.0, window=12, noise=8.0)
    assert _feet_turn_too(feet, a, b, 45.0, window=12, noise=8.0, lo=15)
    # Twisting hips over planted feet still do not turn.
    assert not _feet_turn_too(np.zeros_like(feet), a, b, 45.0, window=12, noise=8.0, lo=15)
