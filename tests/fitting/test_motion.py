"""read_motion: one motion form from BVH, Kinect CSV and truth sidecars."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import MotionFileError
from capture2notation.fitting import FitResult
from capture2notation.fitting.motion import MotionData, normalise_world, read_motion
from capture2notation.io.truth import write_truth


def _truth_fields(T=6, order=None):
    body = Body(1.65)
    rng = np.random.default_rng(0)
    ang = body.clip(rng.normal(0, 0.3, (T, len(JOINTS), 3)))
    root = np.tile(body.rest[0], (T, 1))
    joints = forward_kinematics(ang, root, body)
    names = np.array(JOINTS)
    if order is not None:
        names, joints, ang = names[order], joints[:, order], ang[:, order]
    return dict(
        fps=25.0,
        times=np.arange(T) / 25.0,
        joint_names=names,
        joints=joints,
        angles=ang,
        root=root,
        landmarks3d=np.zeros((T, 33, 3)),
        keypoints=np.zeros((T, 33, 2)),
        visibility=np.ones((T, 33)),
        K=np.eye(3),
        R=np.eye(3),
        t=np.zeros(3),
        image_size=np.array([64, 48]),
        score="{}",
        effort="{}",
        view="front",
        style="stick",
        body_height=1.65,
    )


def test_truth_sidecar_becomes_motion_data_in_our_joint_order(tmp_path):
    f = _truth_fields()
    order = np.random.default_rng(1).permutation(len(JOINTS))
    write_truth(tmp_path / "truth.npz", **_truth_fields(order=order))
    m = read_motion(tmp_path / "truth.npz")
    assert isinstance(m, MotionData) and isinstance(m, FitResult) and m.source == "truth"
    np.testing.assert_array_equal(m.joints, f["joints"])
    np.testing.assert_array_equal(m.angles, f["angles"])
    assert np.all(m.confidence == 1.0) and m.fps == 25.0


@pytest.mark.parametrize("rel", ["bvh/test_mocapbank.bvh", "bvh/jesse_dance.bvh"])
def test_bvh_fixtures_give_plausible_grounded_figures(fixture_path, rel):
    m = read_motion(fixture_path(rel))
    assert m.source == "bvh" and np.all(np.isfinite(m.joints))
    stand = np.nanmax(m.joints[..., 2], axis=1) - np.nanmin(m.joints[..., 2], axis=1)
    assert 1.2 <= np.percentile(stand, 90) <= 2.2
    feet = [joint_index(n) for n in ("right_ankle", "left_ankle", "right_toe", "left_toe")]
    lowest = np.min(m.joints[:, feet, 2], axis=1)
    assert abs(np.percentile(lowest, 2)) < 0.03  # the floor is where the feet are
    assert np.median(m.joints[:, joint_index("head"), 2] - lowest) > 1.1  # mostly upright
    # Starts at the origin facing +y (right hip on +x).
    assert np.hypot(*m.joints[0, 0, :2]) < 0.05
    d = m.joints[0, joint_index("right_hip")] - m.joints[0, joint_index("left_hip")]
    assert d[0] > 0 and abs(d[1]) < 0.3 * d[0]
    assert np.median(m.confidence) > 0.7


def test_normalise_world_moves_floor_origin_and_facing():
    body = Body()
    T = 3
    ang = np.zeros((T, len(JOINTS), 3))
    ang[:, 0, 2] = np.pi / 2  # facing -x
    root = np.tile(body.rest[0] + [1.0, 2.0, 0.3], (T, 1))
    pts = forward_kinematics(ang, root, body)
    out, (extra,) = normalise_world(pts, np.ones(pts.shape[:2]), [pts[:, 0]])
    np.testing.assert_allclose(
        out, forward_kinematics(np.zeros_like(ang), np.tile(body.rest[0], (T, 1)), body), atol=1e-9
    )
    np.testing.assert_allclose(extra, out[:, 0])


def test_unknown_and_missing_files_are_reported(tmp_path):
    (tmp_path / "take.trc").write_text("x")
    with pytest.raises(MotionFileError, match=r"unknown motion file type '\.trc'"):
        read_motion(tmp_path / "take.trc")
    with pytest.raises(MotionFileError, match="no such motion file"):
        read_motion(tmp_path / "absent.bvh")
