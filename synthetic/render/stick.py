"""Wolofsky's plotter look: thin black lines on white paper, a circle for the head.

Wolofsky (1974) drew Labanotation as stick figures on a pen plotter; this
style keeps that look (on a faint floor grid so depth still reads).
"""

from __future__ import annotations

import cv2
import numpy as np

from capture2notation.body import JOINTS, PARENT

from .camera import Camera
from .mannequin import SHIFT, fixed
from .scene import HEAD_RADII, Pose, floor_background

__all__ = ["STICK_BONES", "Stick"]

#: Line segments of the figure (joint pairs); the neck → head bone stops at
#: the chin, where the head circle begins.
STICK_BONES: tuple[tuple[str, str], ...] = tuple(
    (PARENT[j], j) for j in JOINTS if PARENT[j] is not None and j != "head"
) + (("neck", "chin"),)


class Stick:
    """Stick-figure renderer of a posed body seen by one camera.

    Parameters
    ----------
    pose : Pose
    camera : Camera
    """

    style = "stick"

    def __init__(self, pose: Pose, camera: Camera):
        self.pose, self.camera = pose, camera
        h = camera.size[1]
        self.background = floor_background(
            camera, wall=(255, 255, 255), floor=(246, 246, 246), grid=(222, 222, 222), line_width=1
        )
        a = np.stack([pose.points[p] for p, _ in STICK_BONES], 1)
        b = np.stack([pose.points[c] for _, c in STICK_BONES], 1)
        self._lines = fixed(np.stack([camera.project(a), camera.project(b)], axis=2))  # (T,B,2,2)
        centre = pose.points["head_centre"]
        uv, z = camera.project(centre, True)
        self._head = fixed(uv)
        radius = HEAD_RADII[2] * 0.9 * pose.body.height * camera.K[1, 1] / z
        self._radius = np.round(np.maximum(radius, 1.0) * (1 << SHIFT)).astype(np.int64)
        self._width = max(1, round(h / 300))

    def __len__(self) -> int:
        return self.pose.n_frames

    def frame(self, i: int) -> np.ndarray:
        """The image of frame `i`, (H, W, 3) uint8 BGR."""
        img = self.background.copy()
        cv2.polylines(img, list(self._lines[i]), False, (0, 0, 0), self._width, cv2.LINE_AA, SHIFT)
        cv2.circle(
            img, tuple(int(v) for v in self._head[i]), int(self._radius[i]), (0, 0, 0), self._width, cv2.LINE_AA, SHIFT
        )
        return img
