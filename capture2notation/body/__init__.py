"""Body model: the joint tree, proportions, extremes and forward kinematics."""

from .frames import body_cross, body_frame, front_of, key_frame, rotation_front, segment_vectors
from .kinematics import euler_to_matrix, forward_kinematics, global_rotations, matrix_to_euler
from .landmarks import landmarks_from_joints, landmarks_from_pose  # noqa: F401
from .skeleton import (
    BLAZEPOSE_LANDMARKS,
    BLAZEPOSE_TO_JOINT,
    JOINT_INDEX,
    JOINT_TO_BLAZEPOSE,
    JOINTS,
    PARENT,
    Body,
    joint_index,
)

__all__ = [
    "BLAZEPOSE_LANDMARKS",
    "BLAZEPOSE_TO_JOINT",
    "JOINTS",
    "JOINT_INDEX",
    "JOINT_TO_BLAZEPOSE",
    "PARENT",
    "Body",
    "body_cross",
    "body_frame",
    "euler_to_matrix",
    "forward_kinematics",
    "front_of",
    "global_rotations",
    "joint_index",
    "key_frame",
    "matrix_to_euler",
    "rotation_front",
    "segment_vectors",
]
