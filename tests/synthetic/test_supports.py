"""The virtual dancer's feet: a foot that lands and steps again stands on the floor in between."""

from fractions import Fraction as F

import numpy as np
import pytest

from capture2notation.body import Body, joint_index
from capture2notation.notation import Score, Symbol
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
    syms = (Symbol(F(1), F(1), "right_support", "place", "middle"), Symbol(F(2), F(1), "left_leg", "forward", "middle"),
            Symbol(F(3), F(1), "support", "place", "middle"), Symbol(F(4), F(1), "left_support", "left", "middle"),
            Symbol(F(6), F(1), "right_arm", "forward", "middle"))  # the step's landing is followed by a hold
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
