"""Fitting: 2D keypoints (or 3D joints) -> 3D joints, joint angles and confidences."""

from .camera import DEFAULT_DISTANCE, DEFAULT_HEIGHT, DEFAULT_HFOV_DEG, Camera
from .fit import fit_keypoints, fit_track, refine_focal
from .fit3d import fit_points3d
from .lengths import estimate_offsets
from .model import PoseModel
from .result import FitResult
from .solver import FitOptions

__all__ = [
    "Camera",
    "DEFAULT_DISTANCE",
    "DEFAULT_HEIGHT",
    "DEFAULT_HFOV_DEG",
    "FitOptions",
    "FitResult",
    "PoseModel",
    "estimate_offsets",
    "fit_keypoints",
    "fit_points3d",
    "fit_track",
    "refine_focal",
]
