"""Rendering the virtual dancer: camera, three styles, frame writers, truth sidecar.

``render_score(score, outdir)`` performs a score and writes
``video.mp4``, ``truth.npz`` and ``score.lab``; ``render_frames(pose, camera,
style)`` yields frames for callers that want them in memory.
"""

from .camera import VIEWS, Camera
from .job import (
    STYLES,
    make_renderer,
    render_frames,
    render_motion,
    render_pose,
    render_score,
    truth_fields,
)
from .mannequin import Mannequin
from .markers import MARKER_COLOURS, MARKER_HSV, MARKER_JOINTS, Markers
from .scene import Pose, landmark_visibility, point_visibility
from .stick import Stick
from .video import open_writer

__all__ = [
    "MARKER_COLOURS",
    "MARKER_HSV",
    "MARKER_JOINTS",
    "STYLES",
    "VIEWS",
    "Camera",
    "Mannequin",
    "Markers",
    "Pose",
    "Stick",
    "landmark_visibility",
    "make_renderer",
    "open_writer",
    "point_visibility",
    "render_frames",
    "render_motion",
    "render_pose",
    "render_score",
    "truth_fields",
]
