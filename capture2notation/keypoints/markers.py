"""Coloured-marker keypoints: the renderer's marker style, gloves or tape.

Each marker is a :class:`MarkerSpec`: the BlazePose landmark it stands for and
an HSV range (OpenCV scale: H in [0, 180), S and V in [0, 256)).  Per frame
the image is thresholded per colour, connected blobs are measured
(``cv2.connectedComponentsWithStats``) and blob centroids are assigned to the
markers of that colour with :func:`scipy.optimize.linear_sum_assignment`,
minimising the distance to each marker's last position, so identities hold
when several markers share a colour.  A marker with no blob is NaN with
visibility 0.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from types import MappingProxyType

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment

from ..errors import KeypointError
from .blazepose import PoseEstimate
from .track import NUM_LANDMARKS, landmark_index

__all__ = [
    "MARKER_HSV",
    "MARKER_JOINTS",
    "MarkerSpec",
    "MarkerTracker",
    "default_markers",
    "detect_blobs",
    "read_marker_specs",
]


#: Joints that carry a marker.
MARKER_JOINTS: tuple[str, ...] = (
    "head",
    "neck",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "right_hand_tip",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "left_hand_tip",
    "right_hip",
    "right_knee",
    "right_ankle",
    "right_toe",
    "left_hip",
    "left_knee",
    "left_ankle",
    "left_toe",
)
#: OpenCV HSV (H in 0-179, S, V) of each marker: hue 10·((7·k) mod 18).
MARKER_HSV: MappingProxyType = MappingProxyType(
    {j: (10 * ((7 * k) % 18), 255, 255) for k, j in enumerate(MARKER_JOINTS)}
)


@dataclass(frozen=True)
class MarkerSpec:
    """One marker: which landmark it marks and which colours count as it.

    Attributes
    ----------
    landmark : int
        BlazePose landmark index (0–32).
    hsv_low, hsv_high : (3,) tuple of int
        Inclusive HSV bounds; ``hsv_low[0] > hsv_high[0]`` wraps round red.
    """

    landmark: int
    hsv_low: tuple[int, int, int]
    hsv_high: tuple[int, int, int]

    def __post_init__(self):
        if not 0 <= int(self.landmark) < NUM_LANDMARKS:
            raise KeypointError(f"marker landmark {self.landmark}, expected 0..{NUM_LANDMARKS - 1}")
        for name in ("hsv_low", "hsv_high"):
            v = tuple(int(x) for x in getattr(self, name))
            if len(v) != 3 or not (0 <= v[0] < 180 and 0 <= v[1] < 256 and 0 <= v[2] < 256):
                raise KeypointError(f"marker {self.landmark}: {name}={v}, expected (H<180, S<256, V<256)")
            object.__setattr__(self, name, v)

    @classmethod
    def from_colour(cls, landmark, bgr, hue_tol: int = 6, min_saturation: int = 80, min_value: int = 60) -> MarkerSpec:
        """A spec around a saturated BGR colour (``landmark`` may be a name or index)."""
        index = landmark_index(landmark) if isinstance(landmark, str) else int(landmark)
        pixel = np.uint8([[list(bgr)]])
        h = int(cv2.cvtColor(pixel, cv2.COLOR_BGR2HSV)[0, 0, 0])
        return cls(index, ((h - hue_tol) % 180, min_saturation, min_value), ((h + hue_tol) % 180, 255, 255))

    def mask(self, hsv: np.ndarray) -> np.ndarray:
        """(H, W) uint8 mask of pixels within the range."""
        lo, hi = self.hsv_low, self.hsv_high
        if lo[0] <= hi[0]:
            return cv2.inRange(hsv, lo, hi)
        # Hue wraps (reds): union of [lo, 179] and [0, hi].
        return cv2.inRange(hsv, lo, (179, hi[1], hi[2])) | cv2.inRange(hsv, (0, lo[1], lo[2]), hi)


def default_markers(hue_tol: int = 4) -> list[MarkerSpec]:
    """The marker set of :data:`MARKER_HSV` (what the renderer's ``markers`` style draws).

    Each rendered joint that is also a BlazePose landmark (shoulders, elbows,
    wrists, hand tips → index, hips, knees, ankles, toes → foot index; see
    ``capture2notation.body.skeleton.JOINT_TO_BLAZEPOSE``) becomes a spec of
    hue ± `hue_tol` (the renderer's hues are 10 apart); head and neck markers
    have no landmark slot and are ignored.
    """
    from ..body.skeleton import JOINT_TO_BLAZEPOSE

    specs = []
    for joint, (h, _s, _v) in MARKER_HSV.items():
        if joint in JOINT_TO_BLAZEPOSE:
            lo, hi = (int(h) - hue_tol) % 180, (int(h) + hue_tol) % 180
            specs.append(MarkerSpec(JOINT_TO_BLAZEPOSE[joint], (lo, 80, 60), (hi, 255, 255)))
    return specs


def read_marker_specs(path) -> list[MarkerSpec]:
    """Marker colours from a JSON file, for gloves or tape on real footage.

    The file holds a list of objects, each with ``"landmark"`` (BlazePose name
    or index) and either ``"hsv_low"`` / ``"hsv_high"`` (OpenCV HSV, H < 180)
    or ``"bgr"`` (a colour, matched at hue ± ``"hue_tol"``, default 6)::

        [{"landmark": "left_wrist", "hsv_low": [50, 80, 60], "hsv_high": [70, 255, 255]},
         {"landmark": "right_wrist", "bgr": [0, 0, 220]}]

    Raises
    ------
    KeypointError
        Unreadable file or a bad entry (the message names the entry).
    """
    import json
    from pathlib import Path

    path = Path(path)
    try:
        entries = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise KeypointError(f"{path}: cannot read marker colours: {exc}") from exc
    if not isinstance(entries, list) or not entries:
        raise KeypointError(f"{path}: expected a non-empty JSON list of markers")
    specs = []
    for k, e in enumerate(entries):
        try:
            lm = e["landmark"]
            index = landmark_index(lm) if isinstance(lm, str) else int(lm)
            if "bgr" in e:
                specs.append(MarkerSpec.from_colour(index, e["bgr"], hue_tol=int(e.get("hue_tol", 6))))
            else:
                specs.append(MarkerSpec(index, tuple(e["hsv_low"]), tuple(e["hsv_high"])))
        except (KeyError, TypeError, ValueError, KeypointError) as exc:
            raise KeypointError(
                f"{path}: marker entry {k} ({e!r}): {exc}; expected landmark and hsv_low/hsv_high or bgr"
            ) from exc
    return specs


def detect_blobs(mask: np.ndarray, min_area: int = 4, max_blobs: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Centroids and areas of the largest connected blobs of a mask.

    Returns
    -------
    centroids : (N, 2) ndarray
        Pixel x, y (pixel centres at integer coordinates).
    areas : (N,) ndarray
        Pixel counts, largest first.
    """
    _n, _labels, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
    areas = stats[1:, cv2.CC_STAT_AREA]
    keep = np.flatnonzero(areas >= min_area)
    keep = keep[np.argsort(-areas[keep])][:max_blobs]
    return centroids[1:][keep].astype(float), areas[keep].astype(float)


class MarkerTracker:
    """Detect markers frame by frame and keep their identities.

    Parameters
    ----------
    markers : sequence of MarkerSpec, optional
        Default :func:`default_markers`.
    min_area : int
        Smallest blob in pixels that counts as a marker.
    max_jump : float
        Largest move between frames (pixels) for a blob to keep an identity
        when the colour is shared; farther blobs only claim markers that
        have no history.
    """

    backend = "markers"

    def __init__(self, markers=None, min_area: int = 4, max_jump: float = 80.0):
        self.markers = list(default_markers() if markers is None else markers)
        if not self.markers:
            raise KeypointError("marker tracker needs at least one MarkerSpec")
        self.min_area = int(min_area)
        self.max_jump = float(max_jump)
        groups = defaultdict(list)  # markers sharing one colour range
        for spec in self.markers:
            groups[(spec.hsv_low, spec.hsv_high)].append(spec)
        self._groups = [(specs[0], [s.landmark for s in specs]) for specs in groups.values()]
        self.reset()

    def reset(self) -> None:
        """Forget the last positions."""
        self._last = np.full((NUM_LANDMARKS, 2), np.nan)

    def detect(self, image: np.ndarray) -> np.ndarray:
        """Marker positions in one BGR frame: (33, 2) pixels, NaN where unseen."""
        hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV)
        out = np.full((NUM_LANDMARKS, 2), np.nan)
        for spec, landmarks in self._groups:
            cents, _areas = detect_blobs(spec.mask(hsv), self.min_area, max_blobs=2 * len(landmarks) + 2)
            if len(cents) == 0:
                continue
            if len(landmarks) == 1 and not np.isfinite(self._last[landmarks[0]]).all():
                out[landmarks[0]] = cents[0]  # the largest blob
                continue
            prev = self._last[landmarks]  # (M, 2)
            dist = np.linalg.norm(prev[:, None, :] - cents[None, :, :], axis=-1)
            # No history: any blob will do, but a tracked marker nearby wins;
            # larger blobs are preferred through their rank.
            rank = np.arange(len(cents))[None, :] * 1e-3
            cost = np.where(np.isfinite(dist), dist, self.max_jump) + rank
            rows, cols = linear_sum_assignment(cost)
            for r, c in zip(rows, cols):
                if np.isfinite(dist[r, c]) and dist[r, c] > self.max_jump and len(landmarks) > 1:
                    continue
                out[landmarks[r]] = cents[c]
        return out

    def process(self, image: np.ndarray, t: float) -> PoseEstimate | None:
        """Next frame (same interface as :meth:`BlazePose.process`)."""
        pos = self.detect(image)
        seen = np.isfinite(pos).all(axis=1)
        self._last = np.where(seen[:, None], pos, self._last)
        if not seen.any():
            return None
        tracked = np.zeros(NUM_LANDMARKS, bool)
        tracked[[m.landmark for m in self.markers]] = True
        return PoseEstimate(
            xy=np.column_stack([pos, np.full(NUM_LANDMARKS, np.nan)]),
            visibility=seen.astype(float),
            presence=float(seen[tracked].mean()),
            world=np.full((NUM_LANDMARKS, 3), np.nan),
            aux=np.full((2, 2), np.nan),
            crop=np.full(5, np.nan),
        )
