"""Coloured joint markers on a grey silhouette, for colour-marker detectors.

Each marker is a flat disc of one fully saturated, fully bright colour; hues
are 10 OpenCV hue units (20°) apart and neighbouring joints get distant hues,
so a detector can threshold in HSV (the silhouette, wall and floor are grey,
saturation < 40).  A marker is drawn only where its joint is visible (the
truth sidecar's self-occlusion test), so what is drawn is what is true.
"""

from __future__ import annotations

from types import MappingProxyType

import cv2
import numpy as np

from capture2notation.keypoints.markers import MARKER_HSV, MARKER_JOINTS

from .camera import Camera
from .mannequin import SHIFT, capsule_outlines, fixed
from .scene import Pose, body_capsules, floor_background, point_visibility

__all__ = ["MARKER_COLOURS", "MARKER_HSV", "MARKER_JOINTS", "MARKER_RADIUS", "Markers"]


def _hsv_to_bgr(hsv) -> tuple[int, int, int]:
    px = np.array([[hsv]], np.uint8)
    return tuple(int(v) for v in cv2.cvtColor(px, cv2.COLOR_HSV2BGR)[0, 0])


#: (B, G, R) of each marker, from :data:`MARKER_HSV`.
MARKER_COLOURS: MappingProxyType = MappingProxyType({j: _hsv_to_bgr(v) for j, v in MARKER_HSV.items()})
#: Marker disc radius, fraction of body height.
MARKER_RADIUS = 0.022
_SILHOUETTE = (150, 150, 150)


class Markers:
    """Joint-marker renderer of a posed body seen by one camera.

    Parameters
    ----------
    pose : Pose
    camera : Camera

    Attributes
    ----------
    visible : (T, M) ndarray of bool
        Which markers (:data:`MARKER_JOINTS` order) are drawn per frame.
    """

    style = "markers"

    def __init__(self, pose: Pose, camera: Camera):
        self.pose, self.camera = pose, camera
        self.background = floor_background(camera, wall=(214, 214, 214), floor=(188, 190, 192), grid=(170, 172, 174))
        a, b, radii = body_capsules(pose)
        (ua, za), (ub, zb) = camera.project(a, True), camera.project(b, True)
        f = camera.K[1, 1]
        self._polys = fixed(capsule_outlines(ua, ub, radii[:, 0] * f / za, radii[:, 1] * f / zb))
        self._depth = 0.5 * (za + zb) - radii.mean(axis=1)
        pts = np.stack([pose.points[j] for j in MARKER_JOINTS], 1)
        uv, z = camera.project(pts, True)
        self.visible = point_visibility(camera, pts, a, b, radii)
        self._uv = fixed(uv)
        r = MARKER_RADIUS * pose.body.height * f / z
        self._r = np.round(np.maximum(r, 2.5) * (1 << SHIFT)).astype(np.int64)
        self._order = np.argsort(-z, axis=1)
        self._colours = [MARKER_COLOURS[j] for j in MARKER_JOINTS]

    def __len__(self) -> int:
        return self.pose.n_frames

    def frame(self, i: int) -> np.ndarray:
        """The image of frame `i`, (H, W, 3) uint8 BGR."""
        img = self.background.copy()
        for k in np.argsort(-self._depth[i], kind="stable"):
            cv2.fillConvexPoly(img, self._polys[i, k], _SILHOUETTE, cv2.LINE_AA, SHIFT)
        for m in self._order[i]:
            if self.visible[i, m]:
                cv2.circle(
                    img,
                    tuple(int(v) for v in self._uv[i, m]),
                    int(self._r[i, m]),
                    self._colours[m],
                    -1,
                    cv2.LINE_AA,
                    SHIFT,
                )
        return img
