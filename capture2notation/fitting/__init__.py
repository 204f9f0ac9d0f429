"""Fitting: keypoints or 3D joints -> joint angles of the body model, 3D joints, confidences.

* :func:`fit_track` / :func:`fit_keypoints` — 2D BlazePose landmarks (plus
  world landmarks) seen by a :class:`Camera` (known from a truth sidecar, or
  a default one refined from the data) -> :class:`FitResult`;
* :func:`fit_points3d` — measured 3D joints (BVH, Kinect) -> :class:`FitResult`;
* :func:`read_motion` — a BVH, Kinect CSV or truth sidecar -> :class:`MotionData`
  (read by :mod:`capture2notation.io`, retargeted onto our skeleton here);
* :class:`FitOptions` — weights and iterations; :class:`PoseModel` — the
  solver's parametrisation, FK and Jacobian; :func:`estimate_offsets` —
  per-clip segment lengths; :func:`direction_spread` — how well each frame
  determines each segment's direction.
"""

from .camera import DEFAULT_DISTANCE, DEFAULT_HEIGHT, DEFAULT_HFOV_DEG, Camera
from .fit import fit_keypoints, fit_track, refine_focal
from .fit3d import fit_points3d
from .lengths import estimate_offsets
from .model import PoseModel
from .motion import MotionData, motion_from_truth, normalise_world, read_motion
from .result import FitResult
from .solver import FitOptions
from .uncertainty import direction_spread

__all__ = [
    "DEFAULT_DISTANCE",
    "DEFAULT_HEIGHT",
    "DEFAULT_HFOV_DEG",
    "Camera",
    "FitOptions",
    "FitResult",
    "MotionData",
    "PoseModel",
    "direction_spread",
    "estimate_offsets",
    "fit_keypoints",
    "fit_points3d",
    "fit_track",
    "motion_from_truth",
    "normalise_world",
    "read_motion",
    "refine_focal",
]
