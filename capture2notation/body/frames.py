"""The body frame of DESIGN.md and limb-segment vectors expressed in it."""

from __future__ import annotations

import numpy as np

from ..errors import BodyModelError
from .skeleton import JOINTS, joint_index

__all__ = ["body_frame", "segment_vectors"]


def body_frame(joints: np.ndarray) -> np.ndarray:
    """Body frame at each instant.

    ``up`` is world +z; ``right`` is the horizontal part of
    (right hip − left hip), normalised; ``forward = up × right``.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres (NaN where unknown).

    Returns
    -------
    (T, 3, 3) ndarray
        Rows ``right``, ``forward``, ``up`` (world coordinates).  Frames where
        the hips are missing or coincide are NaN.
    """
    joints = _check(joints)
    d = joints[:, joint_index("right_hip")] - joints[:, joint_index("left_hip")]
    d = d.copy()
    d[:, 2] = 0.0
    n = np.linalg.norm(d, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        right = np.where(n > 1e-9, d / n, np.nan)
    up = np.broadcast_to(np.array([0.0, 0.0, 1.0]), right.shape)
    forward = np.cross(up, right)
    return np.stack([right, forward, up], axis=1)


def segment_vectors(joints: np.ndarray, a: str, b: str, frame: np.ndarray | None = None) -> np.ndarray:
    """Unit vector from joint `a` to joint `b`, in the body frame.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions.
    a, b : str
        Bound and free ends of the segment (joint names).
    frame : (T, 3, 3) ndarray, optional
        Precomputed :func:`body_frame`.

    Returns
    -------
    (T, 3) ndarray
        Components (right, forward, up); NaN where a joint is missing.
    """
    joints = _check(joints)
    if frame is None:
        frame = body_frame(joints)
    v = joints[:, joint_index(b)] - joints[:, joint_index(a)]
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        v = np.where(n > 1e-12, v / n, np.nan)
    return np.einsum("tij,tj->ti", frame, v)


def _check(joints: np.ndarray) -> np.ndarray:
    joints = np.asarray(joints, dtype=float)
    if joints.ndim != 3 or joints.shape[1:] != (len(JOINTS), 3):
        raise BodyModelError(f"joints must have shape (T, {len(JOINTS)}, 3), got {joints.shape}")
    return joints
