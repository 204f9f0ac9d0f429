"""The body frame of DESIGN.md and segment vectors."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, body_frame, forward_kinematics, joint_index, segment_vectors
from capture2notation.notation.directions import classify


def _rest(T=1):
    return forward_kinematics(np.zeros((T, len(JOINTS), 3)))


def test_rest_frame_is_world_axes():
    f = body_frame(_rest())[0]
    np.testing.assert_allclose(f, np.eye(3), atol=1e-12)


@settings(max_examples=50, deadline=None)
@given(st.floats(-np.pi, np.pi))
def test_turning_the_pelvis_turns_the_frame_but_not_the_directions(yaw):
    ang = np.zeros((1, len(JOINTS), 3))
    ang[0, joint_index("pelvis"), 2] = yaw
    ang[0, joint_index("right_shoulder"), 0] = np.pi / 2  # arm forward
    p = forward_kinematics(ang)
    f = body_frame(p)[0]
    assert np.allclose(f[2], [0, 0, 1])
    assert np.isclose(np.linalg.det(f), 1.0)
    v = segment_vectors(p, "right_shoulder", "right_wrist")[0]
    np.testing.assert_allclose(v, [0, 1, 0], atol=1e-9)
    assert classify(v) == ("forward", "middle")


def test_missing_hip_gives_nan_frame():
    p = _rest(2)
    p[1, joint_index("left_hip")] = np.nan
    f = body_frame(p)
    assert np.isfinite(f[0]).all() and np.isnan(f[1, :2]).all()


def test_rest_head_and_chest_are_place_high_and_limbs_place_low():
    p = _rest()
    for a, b, expect in [
        ("neck", "head", ("place", "high")),
        ("waist", "neck", ("place", "high")),
        ("right_shoulder", "right_wrist", ("place", "low")),
        ("left_hip", "left_ankle", ("place", "low")),
    ]:
        assert classify(segment_vectors(p, a, b)[0]) == expect


def test_body_proportions_scale_with_height():
    small, tall = Body(1.5), Body(1.9)
    ratio = tall.segment_length("right_shoulder", "right_elbow") / small.segment_length("right_shoulder", "right_elbow")
    assert ratio == np.float64(1.9 / 1.5) or abs(ratio - 1.9 / 1.5) < 1e-12
    assert abs(tall.rest[joint_index("head"), 2] - 1.9) < 1e-12
