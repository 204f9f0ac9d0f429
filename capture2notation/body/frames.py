"""The body frames of DESIGN.md (the standard and the body cross of axes), the front,
and limb-segment vectors expressed in a frame."""

from __future__ import annotations

import numpy as np

from ..errors import BodyModelError
from .skeleton import JOINTS, joint_index

__all__ = ["body_cross", "body_frame", "front_of", "key_frame", "rotation_front", "segment_vectors"]

#: The crosses of axes (DESIGN.md, "Cross of axes").
AXES = ("standard", "body")


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


def body_cross(joints: np.ndarray) -> np.ndarray:
    """The body cross of axes at each instant (LabanotationSuite's Kinect frame).

    ``forward`` is the normal of the plane through both shoulders and the
    mid-spine (our ``waist``, Kinect's SpineMid), pointing to the body's
    front: ``(waist − right shoulder) × (left shoulder − right shoulder)``;
    ``left`` is the shoulder line (right → left shoulder); ``up = forward ×
    left`` runs along the torso.  As in the suite's
    ``labanProcessor.calculate_base_rotation``.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres.

    Returns
    -------
    (T, 3, 3) ndarray
        Rows ``right`` (= −left), ``forward``, ``up``; NaN where the three
        points are missing or collinear.
    """
    joints = _check(joints)
    r = joints[:, joint_index("right_shoulder")]
    v1 = joints[:, joint_index("left_shoulder")] - r
    v2 = joints[:, joint_index("waist")] - r
    forward = np.cross(v2, v1)
    with np.errstate(invalid="ignore", divide="ignore"):
        nf = np.linalg.norm(forward, axis=-1, keepdims=True)
        nl = np.linalg.norm(v1, axis=-1, keepdims=True)
        forward = np.where(nf > 1e-12, forward / nf, np.nan)
        left = np.where(nl > 1e-12, v1 / nl, np.nan)
    up = np.cross(forward, left)
    return np.stack([-left, forward, up], axis=1)


def key_frame(joints: np.ndarray, axes: str = "standard") -> np.ndarray:
    """:func:`body_frame` (``axes="standard"``) or :func:`body_cross` (``"body"``)."""
    if axes == "standard":
        return body_frame(joints)
    if axes == "body":
        return body_cross(joints)
    raise BodyModelError(f"unknown axes {axes!r}; expected one of {' '.join(AXES)}")


def front_of(forward: np.ndarray) -> np.ndarray:
    """Unwrapped front, degrees clockwise seen from above from the room's +y.

    Parameters
    ----------
    forward : (T, 3) ndarray
        A forward direction per frame (e.g. the pelvis's +y, or the body
        frame's ``forward``); its horizontal part is used.

    Returns
    -------
    (T,) ndarray
        ``atan2(x, y)`` in degrees, unwrapped through full turns (two right
        pirouettes end at +720, not 0); NaN where `forward` is missing or
        vertical (the unwrapping bridges such frames).
    """
    forward = np.asarray(forward, dtype=float)
    a = np.arctan2(forward[:, 0], forward[:, 1])
    bad = ~np.isfinite(a) | (np.hypot(forward[:, 0], forward[:, 1]) < 1e-9)
    out = np.full(a.shape, np.nan)
    ok = ~bad
    if ok.any():
        out[ok] = np.degrees(np.unwrap(a[ok]))
    return out


def rotation_front(rotations: np.ndarray) -> np.ndarray:
    """(T,) unwrapped front (:func:`front_of`) of the pelvis's global rotations (T, 3, 3)."""
    return front_of(np.asarray(rotations, dtype=float)[:, :, 1])


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
