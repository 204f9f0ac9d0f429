"""The starting pose's one-rotation helpers agree with the vectorised kinematics they shadow."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from capture2notation.body import Body, euler_to_matrix, joint_index
from capture2notation.fitting.ik import (
    _euler_in_limits,
    _euler_in_limits_1,
    _rotation_1,
    _swing_from,
)

angle = st.floats(-np.pi, np.pi, allow_nan=False)
triple = st.tuples(angle, angle, angle)


@given(triple)
def test_one_rotation_matches_euler_to_matrix(e):
    np.testing.assert_allclose(_rotation_1(e), euler_to_matrix(np.array(e)), atol=1e-12)


@given(triple, st.sampled_from(["right_shoulder", "left_hip", "neck"]))
def test_one_triple_in_limits_matches_the_vectorised_choice(e, joint):
    lim = Body().limits[joint_index(joint)]
    R = euler_to_matrix(np.array(e))
    np.testing.assert_allclose(_euler_in_limits_1(R.tolist(), lim.tolist()), _euler_in_limits(R, lim), atol=1e-9)


@given(triple, triple)
def test_the_swing_points_the_segment_at_u_and_stays_a_rotation(e, f):
    u = -euler_to_matrix(np.array(f))[:, 2]
    R = np.array(_swing_from(_rotation_1(e), u.tolist()))
    # Nearly parallel directions give the swing's axis from a cross product
    # of norm ~1e-8: double precision leaves about sqrt(eps) ~ 1e-8 of error.
    np.testing.assert_allclose(-R[:, 2], u, atol=1e-7)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-9)


def test_the_swing_onto_the_opposite_direction_is_half_a_turn():
    R = _rotation_1((0.3, -0.2, 1.0))
    u = [R[0][2], R[1][2], R[2][2]]  # the segment's own direction reversed
    S = np.array(_swing_from(R, u))
    np.testing.assert_allclose(-S[:, 2], u, atol=1e-9)
    np.testing.assert_allclose(S @ S.T, np.eye(3), atol=1e-9)
