"""The 33 BlazePose landmarks of a posed body.

Landmarks that are joints of the tree (shoulders, elbows, wrists, index tips,
hips, knees, ankles, foot index) are those joints; the others (face, pinky,
thumb, heel) ride on a joint: a rest offset rotated by that joint's global
rotation, i.e. they move with the segment the joint drives (the face with the
neck, the hand with the wrist, the heel with the ankle).
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np

from ..errors import BodyModelError
from .kinematics import forward_kinematics, global_rotations
from .skeleton import BLAZEPOSE_LANDMARKS, BLAZEPOSE_TO_JOINT, JOINTS, Body, joint_index

__all__ = ["LANDMARK_ATTACHMENTS", "attached_points", "landmarks_from_joints", "landmarks_from_pose"]

#: Landmarks that are not joints: (joint they ride on, rest position as
#: fractions of body height (x right, y forward, z up)), right side; the
#: left side mirrors x.  Face proportions after standard head anthropometry
#: (head height ≈ 0.13 H, eyes half-way down the head, ears level with them).
_RIGHT_REST: dict[str, tuple[str, tuple[float, float, float]]] = {
    "eye_inner": ("neck", (0.011, 0.050, 0.936)),
    "eye": ("neck", (0.020, 0.048, 0.937)),
    "eye_outer": ("neck", (0.029, 0.043, 0.936)),
    "ear": ("neck", (0.046, 0.000, 0.926)),
    "mouth": ("neck", (0.014, 0.051, 0.885)),  # BlazePose mouth_right
    "pinky": ("wrist", (0.119, -0.016, 0.402)),
    "thumb": ("wrist", (0.112, 0.030, 0.428)),
    "heel": ("ankle", (0.055, -0.030, 0.008)),
}
_NOSE = ("neck", (0.0, 0.063, 0.913))


def _attachments() -> dict[str, tuple[str, tuple[float, float, float]]]:
    out = {"nose": _NOSE}
    for side, sign in (("right", 1.0), ("left", -1.0)):
        for name, (joint, (x, y, z)) in _RIGHT_REST.items():
            lm = f"mouth_{side}" if name == "mouth" else f"{side}_{name}"
            j = joint if joint == "neck" else f"{side}_{joint}"
            out[lm] = (j, (sign * x, y, z))
    return out


#: For each landmark that is not a joint: (joint it rides on, rest position
#: in fractions of body height).
LANDMARK_ATTACHMENTS: MappingProxyType = MappingProxyType(_attachments())


def attached_points(
    joints: np.ndarray,
    rotations: np.ndarray,
    joint_ids,
    offsets: np.ndarray,
) -> np.ndarray:
    """Points rigidly attached to joints.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres.
    rotations : (T, J, 3, 3) ndarray
        Global rotations (:func:`~capture2notation.body.global_rotations`).
    joint_ids : (N,) array_like of int
        Joint each point rides on.
    offsets : (N, 3) ndarray
        Rest offset of each point from its joint, metres (world axes at rest).

    Returns
    -------
    (T, N, 3) ndarray
        ``joints[:, j] + rotations[:, j] @ offset`` per point.
    """
    ids = np.asarray(joint_ids, dtype=int)
    offsets = np.asarray(offsets, dtype=float)
    return joints[:, ids] + np.einsum("tnij,nj->tni", rotations[:, ids], offsets)


def landmarks_from_joints(joints: np.ndarray, rotations: np.ndarray, body: Body | None = None) -> np.ndarray:
    """BlazePose-33 landmarks from already-computed joints and global rotations.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres.
    rotations : (T, J, 3, 3) ndarray
        Global joint rotations.
    body : Body, optional
        Supplies the height and rest pose; default ``Body()``.

    Returns
    -------
    (T, 33, 3) ndarray
        World positions in BlazePose order, metres.
    """
    body = body or Body()
    joints = np.asarray(joints, dtype=float)
    if joints.ndim != 3 or joints.shape[1:] != (len(JOINTS), 3):
        raise BodyModelError(f"joints must have shape (T, {len(JOINTS)}, 3), got {joints.shape}")
    if rotations.shape != joints.shape[:2] + (3, 3):
        raise BodyModelError(f"rotations must have shape {joints.shape[:2] + (3, 3)}, got {rotations.shape}")
    out = np.empty((joints.shape[0], len(BLAZEPOSE_LANDMARKS), 3))
    for i, j in BLAZEPOSE_TO_JOINT.items():
        out[:, i] = joints[:, joint_index(j)]
    names = list(LANDMARK_ATTACHMENTS)
    ids = [joint_index(LANDMARK_ATTACHMENTS[n][0]) for n in names]
    rest = np.array([LANDMARK_ATTACHMENTS[n][1] for n in names]) * body.height
    pts = attached_points(joints, rotations, ids, rest - body.rest[ids])
    out[:, [BLAZEPOSE_LANDMARKS.index(n) for n in names]] = pts
    return out


def landmarks_from_pose(angles: np.ndarray, root: np.ndarray, body: Body | None = None) -> np.ndarray:
    """BlazePose-33 landmark positions of a posed body.

    Parameters
    ----------
    angles : (T, J, 3) ndarray
        Local Euler angles, radians.
    root : (T, 3) ndarray
        Pelvis position, metres.
    body : Body, optional
        Default ``Body()``.

    Returns
    -------
    (T, 33, 3) ndarray
        World positions in BlazePose order (nose = 0 … right_foot_index = 32),
        metres.
    """
    body = body or Body()
    joints = forward_kinematics(angles, root, body)
    return landmarks_from_joints(joints, global_rotations(angles, body), body)
