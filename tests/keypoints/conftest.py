"""Keypoint-stage fixtures: one onnxruntime session per test session (the model comes from
``pose_model_path`` in ``tests/conftest.py``)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def blazepose_session(pose_model_path):
    """One onnxruntime session shared by all model tests."""
    from capture2notation.keypoints.blazepose import make_session

    return make_session(pose_model_path, threads=2)


@pytest.fixture
def blazepose(blazepose_session):
    """A fresh tracker reusing the shared session."""
    from capture2notation.keypoints.blazepose import BlazePose

    return BlazePose(session=blazepose_session)


def _demo_pose(n_frames: int = 12, fps: float = 25.0):
    """Arms raise (one sideways, one forward), elbows bend, one leg lifts.

    A ``synthetic.render.scene.Pose``; angles follow ARCHITECTURE.md (rx > 0
    swings a hanging limb forward, ry > 0 towards the performer's left).
    """
    import numpy as np

    from capture2notation.body import JOINTS, Body
    from capture2notation.body.skeleton import joint_index
    from synthetic.render import scene

    a = np.zeros((n_frames, len(JOINTS), 3))
    s = np.linspace(0.0, 1.0, n_frames)
    a[:, joint_index("right_shoulder"), 1] = -1.2 * s
    a[:, joint_index("left_shoulder"), 0] = 1.0 * s
    a[:, joint_index("right_elbow"), 0] = 1.2 * s
    a[:, joint_index("left_elbow"), 0] = 0.8 * s
    a[:, joint_index("right_hip"), 0] = 0.5 * s
    a[:, joint_index("right_knee"), 0] = -0.8 * s
    a[:, joint_index("left_hip"), 1] = 0.3 * s
    root = np.zeros((n_frames, 3))
    root[:, 2] = Body().rest[0, 2]
    return scene.Pose(a, root, Body(), fps)


@pytest.fixture
def demo_pose():
    """Factory: ``demo_pose(n_frames, fps)`` → a small deterministic dancer pose."""
    return _demo_pose
