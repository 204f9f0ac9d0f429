"""Supports of noisy motion: contacts from smoothed joints, state changes, no symbols from jitter."""

from __future__ import annotations

import warnings
from fractions import Fraction as F

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.compare.agreement import normalise
from capture2notation.notation.effort import progress
from capture2notation.quantise.labels import label_frames, with_supports
from capture2notation.quantise.segment import segment_motion
from capture2notation.quantise.support_state import smooth_positions

FPS = 25.0


def _plie(tempo=60.0, start=1.0, dur=1.0, beats=4.0):
    """Both feet down, a plié (knees 90°) from `start` over `dur` beats, then held."""
    body = Body()
    spb = 60.0 / tempo
    T = int(round(beats * spb * FPS)) + 1
    t = np.arange(T) / FPS
    s = progress((t - start * spb) / (dur * spb), -2.5, 0.5)
    s[t < start * spb] = 0.0
    a = np.zeros((T, len(JOINTS), 3))
    for side in ("right", "left"):
        a[:, joint_index(f"{side}_hip"), 0] = np.radians(45) * s
        a[:, joint_index(f"{side}_knee"), 0] = np.radians(-90) * s
        a[:, joint_index(f"{side}_ankle"), 0] = np.radians(45) * s
    leg = body.segment_length("right_hip", "right_knee") + body.segment_length("right_knee", "right_ankle")
    root = np.tile(body.rest[0], (T, 1))
    # Knees bent 90° with 45° at hip and ankle: the hip comes down so the feet stay flat.
    root[:, 2] -= leg * (1 - np.cos(np.radians(45) * s))
    return forward_kinematics(a, root)


def _supports(score):
    return [s for s in normalise(score).symbols if s.is_support]


@pytest.mark.parametrize("sigma", [0.01, 0.02])
def test_jitter_alone_writes_no_symbol(sigma):
    """Standing still with 1-2 cm of jitter per coordinate: nothing moves, nothing is written."""
    rng = np.random.default_rng(4)
    still = forward_kinematics(np.zeros((150, len(JOINTS), 3)))
    seg = segment_motion(still + rng.normal(0.0, sigma, still.shape), FPS, tempo=60)
    assert normalise(seg.score).symbols == ()


@pytest.mark.parametrize("seed", [0, 1])
def test_plie_with_jitter_is_one_support_symbol_on_the_grid(seed):
    joints = _plie()
    clean = segment_motion(joints, FPS, tempo=60).score
    assert [(s.start, s.duration, s.part, s.level) for s in _supports(clean)] == [(1, 1, "support", "low")]
    noisy = joints + np.random.default_rng(seed).normal(0.0, 0.01, joints.shape)
    sup = _supports(segment_motion(noisy, FPS, tempo=60).score)
    assert len(sup) == 1
    (s,) = sup
    assert (s.part, s.direction, s.level) == ("support", "place", "low")
    assert abs(s.start - 1) <= F(1, 4) and abs(s.end - 2) <= F(1, 4)


def test_feet_off_the_floor_write_no_supports_and_say_so():
    """A floor 10 cm too low (as an unknown floor in a fit can be): no invented supports."""
    rng = np.random.default_rng(2)
    joints = _plie()
    joints[..., 2] += 0.10
    noisy = joints + rng.normal(0.0, 0.01, joints.shape)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        score = segment_motion(noisy, FPS, tempo=60).score
    assert not _supports(score)
    assert any("floor" in str(w.message) for w in caught)


def test_smoothing_keeps_missing_samples_missing():
    rng = np.random.default_rng(0)
    j = forward_kinematics(np.zeros((40, len(JOINTS), 3))) + rng.normal(0.0, 0.01, (40, len(JOINTS), 3))
    j[10:13, joint_index("right_wrist")] = np.nan
    s = smooth_positions(j, FPS)
    assert np.isnan(s[10:13, joint_index("right_wrist")]).all()
    assert np.isfinite(np.delete(s, joint_index("right_wrist"), axis=1)).all()
    # Smoothing removes most of the jitter of a still pose.
    rest = forward_kinematics(np.zeros((1, len(JOINTS), 3)))[0]
    ok = np.isfinite(s).all(axis=-1)
    assert np.std((s - rest)[ok]) < 0.6 * np.std((j - rest)[np.isfinite(j).all(axis=-1)])
    assert smooth_positions(j[:3], FPS) is not None and smooth_positions(j[:3], FPS).shape == (3, len(JOINTS), 3)


def test_with_supports_rewrites_the_support_columns():
    lab = label_frames(forward_kinematics(np.zeros((4, len(JOINTS), 3))), FPS)
    sup = np.array([[True, True], [True, False], [False, False], [True, True]])
    lev = np.array([[1, 1], [2, -1], [-1, -1], [0, 2]])
    out = with_supports(lab, sup, lev)
    c = {p: out.index(p) for p in ("support", "right_support", "left_support")}
    assert out.level[:, c["support"]].tolist() == [1, -1, -1, -1]  # unequal levels at frame 3
    assert out.level[:, c["right_support"]].tolist() == [1, 2, -1, 0]
    assert out.direction[:, c["left_support"]].tolist()[2] == -1
    assert out.support_level.tolist() == lev.tolist()
    # Gesture columns untouched.
    assert np.array_equal(out.direction[:, : c["support"]], lab.direction[:, : c["support"]])


# --- Truth round trip of the support column (virtual dancer → quantiser) ---

from capture2notation.notation import Score, Symbol  # noqa: E402
from synthetic.interpret import UnreachableWarning, interpret  # noqa: E402
from synthetic.phrases import phrase  # noqa: E402
from synthetic.random_scores import random_score  # noqa: E402

#: Support phrases (start, duration, part, direction, level), each with the
#: case it guards.
SUPPORT_CASES = {
    # (a) both feet, then a transfer onto one foot: starts at 1, not 0.
    "transfer": ["0 1 support place middle", "1 4 right_support place middle"],
    # (a) in context: a transfer, the free leg gestures at once, a closing.
    "transfer_gesture_close": [
        "0 1 support place middle",
        "1 1 right_support place middle",
        "2 1 left_leg forward middle",
        "3 1 support place middle",
    ],
    # (b) a step, then a closing: two symbols, not one.
    "step_close": ["1 1 right_support forward middle", "2 1 support place middle"],
    # (c) a closing immediately followed by a step of the closing foot.
    "close_then_step": [
        "1 1 right_support place middle",
        "2 1 left_leg forward middle",
        "3 1 support place middle",
        "4 1 left_support left middle",
        "5 1 support place middle",
    ],
    # A walk from the first frame, each foot landing and the other stepping at once.
    "walk": [
        "0 1 right_support forward middle",
        "1 1 left_support forward middle",
        "2 1 right_support forward middle",
        "3 1 support place middle",
    ],
    "plie_releve_middle": ["0 2 support place low", "2 2 support place high", "4 2 support place middle"],
    "releve_on_one_foot": ["0 2 right_support place high", "2 1 left_leg left low", "3 2 support place middle"],
    # A step back, then the weight forward onto the front foot, which never
    # moved: the body travels a step forward (DESIGN.md), so it is a step.
    "step_back_then_forward_onto_the_front_foot": [
        "0 3/2 support place high",
        "3/2 1 left_support back middle",
        "5/2 3/4 right_support forward middle",
        "13/4 3/2 right_support place high",
    ],
    "side_steps_then_plie": [
        "1 1/2 right_support right middle",
        "3/2 1 support place middle",
        "5/2 1 left_support left middle",
        "7/2 1 support place low",
    ],
}


def _score(lines, tempo):
    syms = []
    for line in lines:
        start, dur, part, direction, level = line.split()
        syms.append(Symbol(F(start), F(dur), part, direction, level))
    # An arm gesture two beats after the supports: the dancer's motion then
    # has exact holds, as every real phrase does (clean-motion quantising).
    end = max(s.end for s in syms)
    syms.append(Symbol(end + 2, F(1), "right_arm", "forward", "middle"))
    return Score(tuple(syms), title="supports", tempo=F(tempo), meter=4)


def _truth_supports(score, fps):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UnreachableWarning)
        joints = interpret(score, fps=fps).joints()
    unreachable = [str(w.message) for w in caught if issubclass(w.category, UnreachableWarning)]
    return _supports(segment_motion(joints, fps, tempo=score.tempo).score), unreachable


@pytest.mark.parametrize("tempo", [60, 120])
@pytest.mark.parametrize("name", sorted(SUPPORT_CASES))
def test_support_phrases_round_trip_exactly_from_truth(name, tempo):
    score = _score(SUPPORT_CASES[name], tempo)
    got, unreachable = _truth_supports(score, FPS)
    assert unreachable == []
    assert got == _supports(score)


@pytest.mark.parametrize("fps", [12.5, 30.0])
@pytest.mark.parametrize("name", ["step_close", "close_then_step", "plie_releve_middle"])
def test_support_phrases_round_trip_at_other_frame_rates(name, fps):
    score = _score(SUPPORT_CASES[name], 90)
    got, unreachable = _truth_supports(score, fps)
    assert unreachable == []
    assert got == _supports(score)


def test_leg_phrase_supports_round_trip_exactly():
    score = phrase("leg_phrase")
    got, unreachable = _truth_supports(score, FPS)
    assert unreachable == []
    assert got == _supports(score)
    # Spelled out, the cases (a) and (b) of the phrase.
    assert (F(8), F(1), "right_support") in [(s.start, s.duration, s.part) for s in got]
    assert [(s.start, s.part, s.direction) for s in got if s.start >= 12] == [
        (F(12), "right_support", "forward"),
        (F(13), "support", "place"),
    ]


def test_random_scores_with_supports_round_trip_their_support_column():
    rng = np.random.default_rng(20261201)
    n, exact, count = 6, 0, 0
    for i in range(n):
        score = random_score(rng, n_beats=8, random_effort=bool(i % 2))
        want = _supports(score)
        count += len(want)
        got, _ = _truth_supports(score, FPS)
        exact += got == want
    assert count >= 6  # the draws do exercise supports
    assert exact == n


# Barre exercises: the weight onto one foot (held 1-4 beats), one-beat
# gestures of the free leg ("side" = the free leg's own side), a close.
# Before the fixes a free leg at ``place low`` beside the supporting foot
# bent its knee to clear the floor (unreachable, read ``bend=2``), the close
# that followed touched down mid-way (``support`` read half a beat early),
# at 12.5 fps a leg unbending from ``forward middle bend=2`` to ``place
# low`` was split where its thigh and shin passed written directions, and a
# knee bent by Space mid-gesture made the leg read as noisy motion.
_BARRE = {
    "b01": (
        72,
        "right",
        1,
        "",
        ("forward low", "side low", "back low", "side middle", "side low", "forward middle bend=2", "place low"),
    ),
    "b02": (
        96,
        "left",
        2,
        "",
        ("forward low", "side low", "back low", "side middle", "side low", "forward middle bend=2", "place low"),
    ),
    "b03": (
        56,
        "right",
        1,
        "",
        ("side low", "forward low", "side middle", "back low", "forward middle bend=2", "side low"),
    ),
    "b04": (
        120,
        "left",
        2,
        "",
        ("side low", "back low", "forward middle bend=2", "side middle", "forward low", "side low"),
    ),
    "b05": (64, "right", 1, "", ("forward low", "forward middle bend=2")),
    "b06": (88, "left", 2, "", ("back low", "side middle", "place low")),
    "b07": (80, "right", 1, "", ("side low", "back low", "forward low", "side low")),
    "b08": (108, "left", 2, "", ("forward middle bend=2", "side low", "back low", "place low")),
    "b09": (
        60,
        "right",
        1,
        "",
        ("back low", "side low", "forward low", "forward middle bend=2", "place low", "side middle"),
    ),
    "b10": (100, "left", 2, "", ("side middle", "forward low", "back low", "side low", "forward middle bend=2")),
    "b11": (
        84,
        "right",
        4,
        "emotion: happy",
        ("side low", "place low", "forward low", "forward middle bend=2", "side middle", "place low"),
    ),
    "b12": (
        112,
        "left",
        2,
        "effort: time=-3.5 weight=0.41 space=1",
        ("place low", "back low", "side low", "forward middle bend=2", "side low"),
    ),
    # Indirect Space and light Effort: the knee bends and straightens within
    # every gesture, which at 12.5 fps once made the leg's motion look noisy.
    "b13": (
        113,
        "right",
        1,
        "effort: time=-2.2 weight=0.7 space=0.5",
        ("side middle", "place low", "forward low", "place low"),
    ),
    "b14": (96, "left", 1, "emotion: happy", ("place low", "back low", "place low", "side low", "place low")),
}


def _barre_score(name):
    from capture2notation.notation.formats.lab import loads

    tempo, support, hold, effort, gestures = _BARRE[name]
    free = "left" if support == "right" else "right"
    lines = [
        f"title: barre {name}",
        f"tempo: {tempo}",
        "meter: 4",
        effort,
        "0 1 support place middle",
        f"1 {hold} {support}_support place middle",
    ]
    t = 1 + hold
    for g in gestures:
        lines.append(f"{t} 1 {free}_leg {g.replace('side', free)}")
        t += 1
    lines.append(f"{t} 1 support place middle")
    return loads("\n".join(line for line in lines if line) + "\n")


@pytest.mark.parametrize("fps", [25.0, 12.5, 30.0])
@pytest.mark.parametrize("name", sorted(_BARRE))
def test_barre_exercise_round_trips_exactly(name, fps):
    """Truth joints of a barre exercise quantise back to its score, and the dancer reaches every symbol."""
    from capture2notation.compare.agreement import score_differences
    from synthetic.interpret import interpret
    from synthetic.reach import UnreachableWarning

    score = _barre_score(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnreachableWarning)
        joints = interpret(score, fps=fps).joints()
    assert score_differences(score, segment_motion(joints, fps, tempo=score.tempo).score) == []


@pytest.mark.parametrize("pelvis_x", [0.0, 0.08])
def test_a_floating_foot_under_the_pelvis_still_bears_weight(pelvis_x):
    """Only the left foot is read on the floor (the fitted right foot floats
    3 cm up, as fitted feet do in a plié), but the pelvis is between the feet
    or over the right foot, never over the left: the weight cannot rest on
    the left foot alone, so the right foot supports too.  Over the left foot
    the one-foot support stands."""
    from capture2notation.quantise.supports_measured import _balanced_contacts

    T = 20
    joints = np.repeat(Body().rest[None], T, axis=0).copy()
    joints[:, [joint_index("right_ankle"), joint_index("right_toe")], 2] += 0.03
    joints[:, joint_index("pelvis"), 0] = pelvis_x  # the right foot is at x > 0 (DESIGN.md)
    labels = label_frames(joints, 25.0)
    sup = np.tile([False, True], (T, 1))
    level = np.where(sup, 1, -1)
    out = _balanced_contacts(with_supports(labels, sup, level), joints, 25.0)
    assert np.asarray(out.supporting).all()
    right_x = joints[0, joint_index("right_ankle"), 0]
    left_x = joints[0, joint_index("left_ankle"), 0]
    joints[:, joint_index("pelvis"), 0] = left_x - 0.1 * (left_x - right_x)  # over the left foot
    over_left = _balanced_contacts(with_supports(labels, sup, level), joints, 25.0)
    assert not np.asarray(over_left.supporting)[:, 0].any()


def test_a_squat_sitting_back_behind_both_feet_stands_on_both():
    """A squat sits the pelvis 30 cm behind the feet (the trunk leans forward
    to keep the balance over them).  With the right foot set 10 cm ahead of
    the left, the pelvis projects onto the line between the feet beyond the
    left foot, yet it is over neither foot: a fitted right foot floating out
    of contact still bears weight (``pose_squats.mp4`` wrote
    ``left_support low`` for each squat)."""
    from capture2notation.quantise.supports_measured import _balanced_contacts

    T = 20
    joints = np.repeat(Body().rest[None], T, axis=0).copy()
    joints[:, [joint_index("right_ankle"), joint_index("right_toe")], 1] += 0.10
    joints[:, [joint_index("right_ankle"), joint_index("right_toe")], 2] += 0.03
    joints[:, joint_index("pelvis"), :2] = [0.0, -0.30]
    labels = label_frames(joints, 25.0)
    sup = np.tile([False, True], (T, 1))
    out = _balanced_contacts(with_supports(labels, sup, np.where(sup, 0, -1)), joints, 25.0)
    assert np.asarray(out.supporting).all()
    # Its level is the standing foot's (low here, a plié).
    assert (np.asarray(out.support_level) == 0).all()


def test_a_pelvis_window_without_frames_on_one_side_is_no_window():
    # The state's change may come after the window's end (b > hi) or over
    # frames the capture lost: no progress can be measured, and no warning.
    import warnings

    from capture2notation.quantise.supports_measured import _pelvis_window

    pelvis = np.column_stack([np.linspace(0.0, 0.5, 20), np.zeros(20), np.full(20, 0.9)])
    lost = pelvis.copy()
    lost[12:] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _pelvis_window(pelvis, 0, 5, 15, 12, 25.0) is None
        assert _pelvis_window(lost, 0, 5, 12, 19, 25.0) is None
        assert _pelvis_window(pelvis, 0, 5, 12, 19, 25.0) is not None
