"""The virtual dancer's feet: a foot that lands and steps again stands on the floor in between."""

from fractions import Fraction as F

import numpy as np
import pytest

from capture2notation.body import Body, joint_index
from capture2notation.notation import Score, Symbol
from capture2notation.notation.model import Effort
from synthetic.interpret import interpret

BODY = Body()


def _contact(J, fps, foot):
    """DESIGN.md support of one foot per frame: lower of heel and toe within 3 cm, slower than 0.2 m/s."""
    ankle, toe = J[:, joint_index(f"{foot}_ankle")], J[:, joint_index(f"{foot}_toe")]
    low = np.minimum(ankle[:, 2], toe[:, 2])
    step = np.linalg.norm(np.diff(0.5 * (ankle + toe), axis=0), axis=-1) * fps
    speed = np.minimum(np.r_[np.inf, step], np.r_[step, np.inf])
    return (low < 0.03) & (speed < 0.2)


@pytest.mark.parametrize("fps", [12.5, 25.0, 30.0])
def test_a_closing_foot_stands_before_it_steps_again(fps):
    """Close on beat 3, step with the same foot from beat 3: the foot is on the
    floor and still at the close's end frame (the weight arrives there), and
    leaves it only afterwards."""
    syms = (
        Symbol(F(1), F(1), "right_support", "place", "middle"),
        Symbol(F(2), F(1), "left_leg", "forward", "middle"),
        Symbol(F(3), F(1), "support", "place", "middle"),
        Symbol(F(4), F(1), "left_support", "left", "middle"),
        Symbol(F(6), F(1), "right_arm", "forward", "middle"),
    )  # the step's landing is followed by a hold
    m = interpret(Score(syms, title="close then step", tempo=F(72), meter=4), fps=fps)
    J = m.joints()
    f3 = {s.start: f1 for s, f0, f1 in m.events if s.part == "support"}[F(3)]
    f4 = {s.start: f1 for s, f0, f1 in m.events if s.part == "left_support"}[F(4)]
    left = _contact(J, fps, "left")
    assert left[f3] and not left[f3 + 2]
    # It steps all the same: a step's length to the left, landing on the end frame.
    dx = J[f4, joint_index("left_ankle"), 0] - J[f3, joint_index("left_ankle"), 0]
    assert dx == pytest.approx(-0.18 * BODY.height, abs=1e-3)
    assert left[f4]


def test_a_step_from_rest_leaves_the_foot_on_the_first_frame():
    """A step on beat 0: the foot is still on frame 0 → 1 (nothing says how it moved before frame 0)."""
    syms = (Symbol(F(0), F(1), "right_support", "forward", "middle"), Symbol(F(1), F(1), "support", "place", "middle"))
    J = interpret(Score(syms, title="step", tempo=F(60), meter=4), fps=25.0).joints()
    a = J[:, joint_index("right_ankle")]
    assert np.linalg.norm(a[1] - a[0]) < 1e-9
    assert a[2, 2] - a[0, 2] > 0.005


def _sym(start, dur, part, direction, level, bend=0):
    return Symbol(F(start), F(dur), part, direction, level, bend)


@pytest.mark.parametrize("fps", [12.5, 25.0])
def test_a_gesturing_foot_leaves_the_floor_on_its_start(fps):
    """A leg gesture begins at its start (DESIGN.md): with a slow-starting
    Effort the logistic alone keeps the foot within 3 cm and slower than
    0.2 m/s for a fifth of the gesture; the dancer lifts it off at once."""
    score = Score(
        (
            _sym(0, 2, "right_support", "place", "middle"),
            _sym(2, 2, "left_leg", "forward", "middle", 1),
            _sym(4, 3 / 2, "support", "place", "middle"),
        ),
        tempo=F(92),
        meter=4,
        effort=Effort(time=-3.377, weight=0.671, space=0.928),
    )
    m = interpret(score, fps)
    sup = _contact(m.joints(), fps, "left")
    f0 = {s.part: f for s, f, _ in m.events}["left_leg"]
    assert sup[f0] and not sup[f0 + 1 : f0 + 4].any(), np.flatnonzero(sup)


def _leg_and_events(score, side: str):
    """Body-frame hip → ankle vectors of one leg, each symbol's (start, end) frames keyed part + start, T."""
    from capture2notation.body import body_frame, segment_vectors

    m = interpret(score, 25.0)
    J = m.joints()
    v = segment_vectors(J, f"{side}_hip", f"{side}_ankle", body_frame(J))
    return v, {s.part + str(s.start): (f0, f1) for s, f0, f1 in m.events}, len(J)


def _drift_deg(v: np.ndarray) -> float:
    """Largest angle (degrees) of the vectors `v` (N, 3) from the first."""
    return float(np.degrees(np.arctan2(np.linalg.norm(np.cross(v, v[0]), axis=-1), v @ v[0])).max())


def test_a_foot_released_by_a_step_holds_its_leg():
    """After a step onto the right foot the left foot is free and unnotated:
    its leg holds its body-frame pose while the right foot rises to relevé
    (it used to reach for the spot it left, drifting 2° — an unwritten
    gesture for the quantiser)."""
    score = Score(
        (
            _sym(0, F(1, 2), "right_support", "back", "middle"),
            _sym(F(1, 2), F(3, 2), "right_support", "place", "high"),
            _sym(2, 1, "left_leg", "left_forward", "low", 2),
            _sym(3, F(3, 2), "support", "place", "middle"),
        ),
        tempo=F(101),
        meter=4,
    )
    v, ends, _ = _leg_and_events(score, "left")
    a, b = ends["right_support0"][1], ends["left_leg2"][0]
    assert b - a > 10
    assert _drift_deg(v[a : b + 1]) < 1e-6


def test_a_foot_released_twice_holds_the_pose_of_its_latest_release():
    """Steps onto the left foot release the right one twice: each time the
    right leg holds the pose it had when that step ended (it used to take
    the first release's pose at the second, a 27° swing in one frame)."""
    score = Score(
        (
            _sym(0, F(1, 2), "left_support", "left_forward", "middle"),
            _sym(1, 1, "right_support", "right", "middle"),
            _sym(2, F(3, 4), "left_support", "left", "middle"),
            _sym(F(11, 4), F(5, 4), "left_arm", "forward", "middle"),
        ),
        tempo=F(76),
        meter=4,
    )
    v, ends, T = _leg_and_events(score, "right")
    for release, until in (("left_support0", "right_support1"), ("left_support2", None)):
        a = ends[release][1]
        b = ends[until][0] if until else T - 1
        assert b - a >= 5
        assert _drift_deg(v[a : b + 1]) < 1e-6, release


def test_a_heel_lowered_slowly_steps_at_once_at_low_frame_rates():
    """A foot whose heel comes down from relevé slower than 0.2 m/s already
    rests when its step starts: it does not rest a frame more (at 12.5 fps
    that left it supporting two frames before the step's end)."""
    score = Score(
        (
            _sym(0, F(3, 2), "right_support", "back", "middle"),
            _sym(F(3, 2), F(3, 2), "right_support", "place", "high"),
            _sym(3, F(1, 2), "left_leg", "right_forward", "low"),
            _sym(F(7, 2), F(3, 2), "support", "place", "middle"),
            _sym(5, F(1, 2), "right_support", "right", "middle"),
            _sym(5, 1, "right_arm", "forward", "middle"),
        ),
        tempo=F(108),
        meter=4,
    )
    fps = 12.5
    m = interpret(score, fps)
    sup = _contact(m.joints(), fps, "right")
    ((f0, f1),) = [(a, b) for x, a, b in m.events if x.part == "right_support" and x.direction == "right"]
    assert f1 - f0 == 3 and sup[f0] and not sup[f1 - 2] and sup[f1]


def _barre(support="right", hold=1, gestures=("left low", "place low"), tempo=72):
    """Weight onto one foot, one-beat free-leg gestures, a close, then a hold (an arm moves on)."""
    free = "left" if support == "right" else "right"
    syms = [
        Symbol(F(0), F(1), "support", "place", "middle"),
        Symbol(F(1), F(hold), f"{support}_support", "place", "middle"),
    ]
    t = 1 + hold
    for g in gestures:
        d, lv, *bend = g.replace("side", free).split()
        syms.append(Symbol(F(t), F(1), f"{free}_leg", d, lv, int(bend[0].split("=")[1]) if bend else 0))
        t += 1
    syms.append(Symbol(F(t), F(1), "support", "place", "middle"))
    syms.append(Symbol(F(t + 2), F(1), "right_arm", "forward", "middle"))
    return Score(tuple(syms), title="barre", tempo=F(tempo), meter=4), free


@pytest.mark.parametrize("fps", [12.5, 25.0, 30.0])
@pytest.mark.parametrize("before", ["back low", "forward middle bend=2", "side middle"])
def test_a_free_leg_at_place_low_hangs_straight_just_above_the_floor(fps, before):
    """Standing on one foot, a free leg brought to place low (bend 0) hangs
    straight with its foot just clear of the floor: not a support, not bent,
    not unreachable (the foot flexes instead of the knee bending)."""
    import warnings

    from capture2notation.notation.directions import bend_angle
    from synthetic.reach import UnreachableWarning

    score, free = _barre(gestures=(before, "place low"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnreachableWarning)
        m = interpret(score, fps=fps)
    J = m.joints()
    f1 = [e for s, _, e in m.events if s.part == f"{free}_leg"][-1]
    ankle, toe = J[f1, joint_index(f"{free}_ankle")], J[f1, joint_index(f"{free}_toe")]
    assert 0.03 < min(ankle[2], toe[2]) < 0.06
    knee = bend_angle(J[f1, joint_index(f"{free}_hip")], J[f1, joint_index(f"{free}_knee")], ankle)
    assert knee < 5.0
    assert not _contact(J, fps, free)[f1]


@pytest.mark.parametrize("fps", [12.5, 25.0, 30.0])
@pytest.mark.parametrize("last", ["place low", "side low", "forward middle bend=2"])
def test_a_closing_foot_lands_on_the_close_end_frame(fps, last):
    """The free foot closes beside the supporting one: it touches the floor
    (reads as supporting) first on the close's end frame, not before."""
    score, free = _barre(support="left", gestures=("forward low", last), tempo=96)
    m = interpret(score, fps=fps)
    J = m.joints()
    f0, f1 = [(a, b) for s, a, b in m.events if s.part == "support"][-1]
    c = _contact(J, fps, free)
    assert c[f1] and not c[f0:f1].any()
