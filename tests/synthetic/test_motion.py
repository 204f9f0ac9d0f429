"""Motion, key framing and the laws of Cachola's motion algebra."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, euler_to_matrix
from capture2notation.errors import SyntheticError
from synthetic.motion import Keyframe, Motion, euler_near, keyframed, synchronize

BODY = Body()
J = len(JOINTS)


def _motion(seed: int, n: int, fps: float = 25.0) -> Motion:
    """A smooth random motion inside the extremes, walking a little."""
    rng = np.random.default_rng(seed)
    lo, hi = BODY.limits[..., 0], BODY.limits[..., 1]
    a, b = rng.uniform(lo, hi), rng.uniform(lo, hi)
    w = np.linspace(0, 1, n)[:, None, None]
    angles = a + w * (b - a)
    root = BODY.rest[0] + np.cumsum(rng.normal(0, 0.01, (n, 3)), axis=0)
    return Motion(fps, angles, root, BODY)


motions = st.builds(_motion, st.integers(0, 10**6), st.integers(1, 12))
joint_subsets = st.sets(st.sampled_from(JOINTS), min_size=1, max_size=J - 1)


@settings(max_examples=30, deadline=None)
@given(motions, motions)
def test_repetition_is_repeated_concatenation(a, b):
    ab = a + b
    assert (3 * (a + b)).allclose(ab + ab + ab)
    assert (ab * 3).allclose(3 * ab)
    assert (1 * a).allclose(a)
    assert (3 * ab).n_frames == 3 * (a.n_frames + b.n_frames)


@settings(max_examples=30, deadline=None)
@given(motions, motions, motions)
def test_concatenation_is_associative_and_continues_the_path(a, b, c):
    assert ((a + b) + c).allclose(a + (b + c))
    ab = a + b
    # b starts (horizontally) where a ended; its own shape is kept.
    assert np.allclose(ab.root[a.n_frames, :2], a.root[-1, :2])
    assert np.allclose(np.diff(ab.root[a.n_frames :], axis=0), np.diff(b.root, axis=0))
    assert np.array_equal(ab.angles[a.n_frames :], b.angles)


@settings(max_examples=30, deadline=None)
@given(motions, joint_subsets)
def test_strip_then_synchronize_restores(m, keep):
    rest = set(JOINTS) - keep
    part, other = m.strip(keep), m.strip(rest)
    assert np.all(np.isnan(part.angles[:, [JOINTS.index(j) for j in rest]]))
    assert synchronize(part, other).allclose(m)
    assert synchronize(other, part).allclose(m)


def test_synchronize_rejects_overlap_and_holds_shorter_motions():
    m = _motion(1, 6)
    with pytest.raises(SyntheticError, match="joint 'right_elbow' is animated by both"):
        synchronize(m.strip(["right_elbow", "chest"]), m.strip(["right_elbow"]))
    short = _motion(2, 3).strip(["left_knee"])
    merged = synchronize(m.strip(set(JOINTS) - {"left_knee"}), short)
    k = JOINTS.index("left_knee")
    assert merged.n_frames == 6
    assert np.allclose(merged.angles[3:, k], short.angles[-1, k])


def test_stripped_joints_have_no_position():
    m = _motion(3, 4).strip(["pelvis", "waist", "chest", "right_shoulder"])
    pos = m.joints()
    assert np.all(np.isfinite(pos[:, JOINTS.index("right_elbow")]))  # placed by the shoulder
    assert np.all(np.isnan(pos[:, JOINTS.index("right_wrist")]))  # its elbow is absent


@settings(max_examples=30, deadline=None)
@given(motions)
def test_reversal_twice_restores(m):
    r = m.scale_frames(-1)
    assert np.array_equal(r.angles, m.angles[::-1]) and np.array_equal(r.root, m.root[::-1])
    assert r.scale_frames(-1).allclose(m)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10**6), st.integers(2, 10), st.sampled_from([2, 3, -2]))
def test_scale_frames_stretches_between_original_frames(seed, n, k):
    m = _motion(seed, n)
    s = m.scale_frames(k)
    assert s.n_frames == (n - 1) * abs(k) + 1
    orig = s.angles[:: abs(k)] if k > 0 else s.angles[::-1][:: abs(k)]
    assert np.allclose(orig, m.angles)
    # In-betweens turn half-way from one original frame to the next (the
    # pelvis, whose range is a full turn, is never clipped).
    if k == 2:
        R = euler_to_matrix(s.angles[:, 0])
        a, mid, b = R[0:-1:2], R[1::2], R[2::2]
        d1, d2 = _angle_between(a, mid), _angle_between(mid, b)
        assert np.allclose(d1, d2, atol=1e-6)
        assert np.allclose(d1, _angle_between(a, b) / 2, atol=1e-6)


def _angle_between(a, b):
    c = (np.trace(np.swapaxes(a, -1, -2) @ b, axis1=-2, axis2=-1) - 1) / 2
    return np.arccos(np.clip(c, -1, 1))


def test_scale_extremes_scales_about_neutral_within_limits():
    m = _motion(4, 5)
    assert m.scale_extremes(1.0).allclose(m)
    assert np.allclose(m.scale_extremes(0.0).angles, 0.0)
    half = m.scale_extremes(0.5)
    assert np.allclose(half.angles, m.angles * 0.5)
    big = m.scale_extremes(10.0)
    assert np.all(big.angles >= BODY.limits[..., 0] - 1e-12) and np.all(big.angles <= BODY.limits[..., 1] + 1e-12)


def test_motion_enforces_extremes_and_checks_shapes():
    angles = np.zeros((2, J, 3))
    angles[:, JOINTS.index("right_elbow"), 0] = np.radians(300)
    angles[:, JOINTS.index("right_knee"), 0] = np.radians(30)  # knees do not hyperextend
    m = Motion(25, angles, np.zeros((2, 3)))
    assert m.angles[0, JOINTS.index("right_elbow"), 0] == pytest.approx(np.radians(155))
    assert m.angles[0, JOINTS.index("right_knee"), 0] == 0.0
    assert m.times == pytest.approx([0.0, 0.04])
    assert m.joints().shape == (2, J, 3)
    with pytest.raises(SyntheticError, match=r"root must have shape \(2, 3\)"):
        Motion(25, angles, np.zeros((3, 3)))
    with pytest.raises(SyntheticError, match="fps must be a positive number"):
        Motion(0, angles, np.zeros((2, 3)))


def test_rest_motion_stands_at_rest_pose():
    m = Motion.rest(3)
    assert np.allclose(m.joints(), BODY.rest)


def test_keyframed_reaches_keys_with_each_interpolation():
    elbow = np.radians([90.0, 0.0, 0.0])
    keys = {
        "right_elbow": [Keyframe(10, elbow, "accelerate_decelerate"), Keyframe(20, (0.0, 0.0, 0.0), "linear")],
        "left_shoulder": [Keyframe(0, (0.2, 0.0, 0.0)), Keyframe(8, (0.4, 0.0, 0.0), "accelerate")],
    }
    m = keyframed(keys, n_frames=25)
    e = m.angles[:, JOINTS.index("right_elbow"), 0]
    assert e[0] == 0.0 and e[10] == pytest.approx(np.pi / 2) and e[20] == 0.0 and np.all(e[20:] == 0.0)
    assert e[5] == pytest.approx(np.pi / 4)  # accelerate-decelerate is symmetric
    assert e[15] == pytest.approx(np.pi / 4)  # linear half-way
    s = m.angles[:, JOINTS.index("left_shoulder"), 0]
    assert s[0] == pytest.approx(0.2) and s[8] == pytest.approx(0.4)
    assert s[4] == pytest.approx(0.2 + 0.2 * 0.25)  # accelerate: s = tau^2
    assert np.all(m.angles[:, JOINTS.index("right_knee")] == 0.0)  # no keys: neutral
    with pytest.raises(SyntheticError, match="frames must increase"):
        keyframed({"neck": [Keyframe(5, (0, 0, 0)), Keyframe(3, (0, 0, 0))]})


def test_euler_near_picks_the_representation_inside_the_extremes():
    j = JOINTS.index("right_shoulder")
    a = np.radians([190.0, -10.0, 20.0])  # flexion beyond 180 is a different Euler branch
    e = euler_near(euler_to_matrix(a), 0.0, BODY.limits[j])
    assert np.allclose(euler_to_matrix(e), euler_to_matrix(a))
    assert np.all(e >= BODY.limits[j, :, 0] - 1e-12) and np.all(e <= BODY.limits[j, :, 1] + 1e-12)
    near = euler_near(euler_to_matrix(a), a)
    assert np.allclose(near, a)
