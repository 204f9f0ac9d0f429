"""Progress curves from 3D joints: exact on clean arcs, robust to gaps."""

from fractions import Fraction

import numpy as np
import pytest

from capture2notation.body import joint_index
from capture2notation.effort.curves import progress_curve
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress
from capture2notation.notation.model import Effort, Score, Symbol
from synthetic.arcs import arc_motion


def _one_move(effort, fps=25.0, tempo=60, beats=2, snap=True):
    score = Score(symbols=(Symbol(0, beats, "right_arm", "right", "high"),), tempo=Fraction(tempo), effort=effort)
    joints = arc_motion(score, fps, snap=snap)
    return score, joints, np.arange(len(joints)) / fps


@pytest.mark.parametrize("method", ["circle", "chord", "arc"])
def test_clean_arc_recovers_the_logistic(method):
    eff = Effort(time=-3.2, weight=0.42, space=1.0)
    score, joints, t = _one_move(eff)
    c = progress_curve(joints, None, t, "right_arm", 0.0, score.seconds(2), method=method)
    assert c.tau.min() > 0 and c.tau.max() < 1
    np.testing.assert_allclose(c.s, progress(c.tau, -3.2, 0.42), atol=1e-9)
    np.testing.assert_allclose(c.radial, 0.0, atol=1e-9)
    # place low -> right high: 135 degrees
    assert np.degrees(c.angle) == pytest.approx(135.0, abs=1e-6)


@pytest.mark.parametrize("snap", [True, False])
def test_window_not_on_the_frame_grid(snap):
    # tempo 37 puts the movement's end between frames: snapped like the
    # virtual dancer it is exact, else the end is extrapolated from inside
    eff = Effort(time=-2.19, weight=0.52, space=1.0)
    score, joints, t = _one_move(eff, tempo=37, beats=1, snap=snap)
    t1 = score.seconds(1)
    assert abs(t1 * 25 - round(t1 * 25)) > 0.1
    c = progress_curve(joints, None, t, "right_arm", 0.0, t1, snap=0.02 if snap else 0.0)
    np.testing.assert_allclose(c.s, progress(c.tau, -2.19, 0.52), atol=1e-9 if snap else 2e-3)


def test_space_shows_as_inward_radial_deviation():
    score, joints, t = _one_move(Effort(time=-2.5, weight=0.5, space=0.0))
    c = progress_curve(joints, None, t, "right_arm", 0.0, score.seconds(2))
    np.testing.assert_allclose(c.radial, -0.1 * np.sin(np.pi * c.tau), atol=1e-9)


def test_missing_frames_are_dropped_not_filled():
    score, joints, t = _one_move(Effort(time=-2.5, weight=0.5, space=1.0))
    conf = np.ones(joints.shape[:2])
    wrist = joint_index("right_wrist")
    joints = joints.copy()
    joints[10:14, wrist] = np.nan
    conf[10:14, wrist] = 0.0
    conf[20, wrist] = 0.0  # position present but zero confidence: dropped too
    c = progress_curve(joints, conf, t, "right_arm", 0.0, score.seconds(2))
    kept = np.round(c.tau * 50).astype(int)
    assert not set(kept) & {10, 11, 12, 13, 20}
    assert c.tau.size == 49 - 5
    np.testing.assert_allclose(c.s, progress(c.tau, -2.5, 0.5), atol=1e-9)


def test_held_part_gives_no_curve_and_bad_input_raises():
    _score, joints, t = _one_move(Effort())
    still = np.repeat(joints[:1], len(t), axis=0)
    assert progress_curve(still, None, t, "right_arm", 0.0, 1.0) is None
    with pytest.raises(EffortError, match="support"):
        progress_curve(joints, None, t, "support", 0.0, 1.0)
    with pytest.raises(EffortError, match="confidence"):
        progress_curve(joints, np.ones((3, 3)), t, "right_arm", 0.0, 1.0)
    gap = joints.copy()
    gap[:, joint_index("right_wrist")] = np.nan
    with pytest.raises(EffortError, match="no valid frame"):
        progress_curve(gap, None, t, "right_arm", 0.0, 1.0)


def test_small_circle_swing_is_exact_with_the_circle_measure():
    # a frame turning about a fixed axis moves a twisted limb on a small circle
    from scipy.spatial.transform import Rotation

    from capture2notation.body import JOINTS

    axis = np.array([0.3, 0.5, 0.81])
    axis /= np.linalg.norm(axis)
    u0 = np.array([0.0, 0.0, -1.0])
    fps, n = 25.0, 26
    tau = np.arange(n) / (n - 1)
    s_true = progress(tau, -2.6, 0.55)
    u = Rotation.from_rotvec(np.outer(s_true * np.radians(150), axis)).apply(u0)
    joints = np.zeros((n, len(JOINTS), 3))
    joints[:, JOINTS.index("right_wrist")] = 0.6 * u
    t = np.arange(n) / fps
    circ = progress_curve(joints, None, t, "right_arm", 0.0, t[-1])
    np.testing.assert_allclose(circ.s, progress(circ.tau, -2.6, 0.55), atol=1e-9)
    chord = progress_curve(joints, None, t, "right_arm", 0.0, t[-1], method="chord")
    assert np.abs(chord.s - progress(chord.tau, -2.6, 0.55)).max() > 0.01


def test_decimated_capture_is_not_snapped_to_far_frames():
    # at 5 Hz the nearest kept frame may be 0.1 s from the window end: that is
    # no dancer rounding, so the end is extrapolated instead
    eff = Effort(time=-2.19, weight=0.52, space=1.0)
    score, joints, t = _one_move(eff, tempo=37, beats=2, snap=False)
    kept = np.arange(0, len(t), 5)
    t1 = score.seconds(2)
    c = progress_curve(joints[kept], None, t[kept], "right_arm", 0.0, t1)
    assert c.t_end == pytest.approx(t1)
    np.testing.assert_allclose(c.s, progress(c.tau, -2.19, 0.52), atol=0.02)
