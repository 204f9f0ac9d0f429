"""Camera calibration from clips of a ChArUco board (issue 15).

:func:`calibrate_videos` finds the board in each camera's clip
(:mod:`.board`), fits intrinsics, extrinsics and a bundle adjustment
(:mod:`.solve`, :mod:`.bundle`) and fixes the world by the board laid on
the floor.  The result is a :class:`~capture2notation.io.calibration.Calibration`.
"""

from __future__ import annotations

from pathlib import Path

from ..io.calibration import Board, camera_name
from .board import (
    MIN_CORNERS,
    BoardDetections,
    cv_board,
    detect_clip,
    detect_image,
    detect_images,
    object_points,
)
from .solve import FLOOR_POSES, MAX_RMS_PX, CalibrationResult, calibrate_cameras, floor_frame

__all__ = [
    "FLOOR_POSES",
    "MAX_RMS_PX",
    "MIN_CORNERS",
    "BoardDetections",
    "CalibrationResult",
    "calibrate_cameras",
    "calibrate_videos",
    "cv_board",
    "detect_clip",
    "detect_image",
    "detect_images",
    "floor_frame",
    "object_points",
]


def calibrate_videos(
    videos, board: Board, origin=(0.0, 0.0, 0.0), floor: str = "standing", margin: float = 0.0, step: int = 1
) -> CalibrationResult:
    """Calibrate the cameras of `videos` (one clip per camera, synchronised).

    Parameters
    ----------
    videos : sequence of str or Path
        Each camera's clip of the board; a camera is named by
        :func:`~capture2notation.io.calibration.camera_name`.
    board : Board
    origin : (x, y, yaw)
    floor : {"standing", "lying"}
    margin : float
        Where and how the board stands on the floor at the clips' start
        (:func:`floor_frame`).
    step : int
        Examine every `step`-th frame.
    """
    paths = [Path(v) for v in videos]
    names = [camera_name(p) for p in paths]
    dets = [detect_clip(p, board, step) for p in paths]
    return calibrate_cameras(dets, names, board, origin, floor, margin)
