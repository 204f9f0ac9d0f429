"""The body model: forward kinematics, Euler round trips, joint extremes."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from capture2notation.body import JOINTS, Body, euler_to_matrix, forward_kinematics, joint_index, matrix_to_euler
from capture2notation.errors import BodyModelError

BODY = Body()
J = len(JOINTS)
angle_arrays = st.integers(1, 6).flatmap(
    lambda t: arrays(np.float64, (t, J, 3), elements=st.floats(-np.pi, np.pi, allow_nan=False))
)


def _pos(name, angles=None, body=BODY):
    if angles is None:
        angles = np.zeros((1, J, 3))
    return forward_kinematics(angles, body=body)[0, joint_index(name)]


def test_rest_pose_is_the_rest_table():
    assert np.allclose(forward_kinematics(np.zeros((3, J, 3))), BODY.rest)
    # Limbs hang straight down; head and chest are upright.
    for a, b in (("right_shoulder", "right_wrist"), ("left_hip", "left_ankle"), ("waist", "head")):
        v = BODY.rest[joint_index(b)] - BODY.rest[joint_index(a)]
        assert np.allclose(v[:2], 0.0)


@settings(max_examples=40, deadline=None)
@given(angle_arrays)
def test_fk_keeps_segment_lengths_and_is_vectorised(angles):
    pos = forward_kinematics(angles)
    parents = BODY.parents
    for j in range(1, J):
        d = np.linalg.norm(pos[:, j] - pos[:, parents[j]], axis=-1)
        assert np.allclose(d, np.linalg.norm(BODY.offsets[j]), atol=1e-9)
    one_by_one = np.stack([forward_kinematics(angles[t : t + 1])[0] for t in range(len(angles))])
    assert np.allclose(pos, one_by_one)


@settings(max_examples=40, deadline=None)
@given(angle_arrays)
def test_root_translation_moves_every_joint(angles):
    shift = np.array([0.3, -0.2, 0.05])
    root = np.tile(BODY.rest[0] + shift, (len(angles), 1))
    assert np.allclose(forward_kinematics(angles, root), forward_kinematics(angles) + shift)


@settings(max_examples=100, deadline=None)
@given(arrays(np.float64, (5, 3), elements=st.floats(-np.pi, np.pi, allow_nan=False)))
def test_euler_round_trip(a):
    m = euler_to_matrix(a)
    assert np.allclose(m @ np.swapaxes(m, -1, -2), np.eye(3), atol=1e-12)
    back = matrix_to_euler(m)
    assert np.allclose(euler_to_matrix(back), m, atol=1e-9)
    assert np.all(np.abs(back[:, 1]) <= np.pi / 2 + 1e-12)
    # Away from gimbal lock, angles in the principal ranges come back exactly.
    inside = np.abs(a[:, 1]) < np.pi / 2 - 1e-3
    assert np.allclose(back[inside], a[inside], atol=1e-7)


def test_euler_round_trip_at_gimbal_lock():
    a = np.array([[0.3, np.pi / 2, -0.4], [0.1, -np.pi / 2, 0.2]])
    assert np.allclose(euler_to_matrix(matrix_to_euler(euler_to_matrix(a))), euler_to_matrix(a), atol=1e-9)


def test_sign_conventions_of_the_architecture():
    rad = np.radians
    angles = np.zeros((1, J, 3))
    angles[0, joint_index("right_shoulder"), 0] = rad(90)  # rx > 0: hanging limb forward
    wrist = _pos("right_wrist", angles) - _pos("right_shoulder", angles)
    assert wrist[1] > 0.3 and abs(wrist[2]) < 1e-9
    angles[:] = 0
    angles[0, joint_index("right_shoulder"), 1] = rad(45)  # ry > 0: towards the left (−x)
    assert (_pos("right_wrist", angles) - _pos("right_shoulder", angles))[0] < -0.2
    angles[:] = 0
    angles[0, joint_index("right_knee"), 0] = rad(-90)  # knee flexion: shin goes back
    assert (_pos("right_ankle", angles) - _pos("right_knee", angles))[1] < -0.3
    angles[:] = 0
    angles[0, joint_index("neck"), 0] = rad(-45)  # upright segment: rx < 0 bows forward
    assert (_pos("head", angles) - _pos("neck", angles))[1] > 0.1


def test_extremes_allow_anatomical_and_forbid_reverse_bends():
    lim = np.degrees(BODY.limits)
    el, kn = joint_index("right_elbow"), joint_index("left_knee")
    assert lim[el, 0, 0] == 0 and lim[el, 0, 1] > 90  # elbows flex with rx > 0 only
    assert lim[kn, 0, 1] == 0 and lim[kn, 0, 0] < -90  # knees flex with rx < 0 only
    # Trunk and neck bend further forward (rx < 0) than back.
    for name in ("waist", "neck"):
        lo, hi = lim[joint_index(name), 0]
        assert -lo > hi
    # Figure 7's phrase needs the free leg to the side at middle level.
    assert lim[joint_index("left_hip"), 1, 1] >= 90 and lim[joint_index("right_hip"), 1, 0] <= -90


def test_neck_bows_the_head_to_the_horizontal():
    """DESIGN.md's ``head forward middle`` (a head bowed to the horizontal) is
    within the neck's extreme; bending back to the horizontal is not."""
    angles = np.zeros((1, J, 3))
    angles[0, joint_index("neck"), 0] = BODY.limits[joint_index("neck"), 0, 0]
    v = _pos("head", angles) - _pos("neck", angles)
    assert np.degrees(np.arcsin(v[2] / np.linalg.norm(v))) == pytest.approx(0.0, abs=1e-9) and v[1] > 0
    angles[0, joint_index("neck"), 0] = BODY.limits[joint_index("neck"), 0, 1]
    v = _pos("head", angles) - _pos("neck", angles)
    assert np.degrees(np.arcsin(v[2] / np.linalg.norm(v))) > 22.5  # still reads high


def test_left_extremes_mirror_the_right():
    for name in ("shoulder", "elbow", "hip", "knee", "ankle"):
        r, l = BODY.limits[joint_index("right_" + name)], BODY.limits[joint_index("left_" + name)]
        assert np.allclose(l[0], r[0])
        assert np.allclose(l[1:], -r[1:, ::-1])


@settings(max_examples=40, deadline=None)
@given(angle_arrays)
def test_clip_enforces_extremes_and_is_idempotent(angles):
    c = BODY.clip(angles * 3)
    assert np.all(c >= BODY.limits[..., 0]) and np.all(c <= BODY.limits[..., 1])
    assert np.array_equal(BODY.clip(c), c)
    inside = (angles >= BODY.limits[..., 0]) & (angles <= BODY.limits[..., 1])
    assert np.array_equal(BODY.clip(angles)[inside], angles[inside])


def test_scaled_extremes_and_bodies():
    half = Body(limit_scale=0.5)
    assert np.allclose(half.limits, np.sort(BODY.limits * 0.5, axis=-1))
    tall = Body(height=2.0)
    assert np.allclose(tall.rest, BODY.rest * 2.0 / 1.70)
    assert tall.segment_length("right_hip", "right_knee") == pytest.approx(0.245 * 2.0)
    with pytest.raises(BodyModelError, match="height"):
        Body(height=-1.0)
    with pytest.raises(BodyModelError, match=r"angles must have shape \(T, 21, 3\)"):
        forward_kinematics(np.zeros((2, 5, 3)))
