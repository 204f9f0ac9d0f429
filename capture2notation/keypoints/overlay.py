"""Draw a keypoint track's skeleton on its video, so a person can check it."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ..errors import KeypointError
from ..io.video import VideoWriter, iter_frames
from .track import KeypointTrack

__all__ = ["POSE_CONNECTIONS", "draw_skeleton", "write_overlay"]

#: BlazePose skeleton edges (MediaPipe's POSE_CONNECTIONS).
POSE_CONNECTIONS: tuple[tuple[int, int], ...] = (
    (0, 1), (1, 2), (2, 3), (3, 7), (0, 4), (4, 5), (5, 6), (6, 8), (9, 10),
    (11, 12), (11, 13), (13, 15), (15, 17), (15, 19), (15, 21), (17, 19),
    (12, 14), (14, 16), (16, 18), (16, 20), (16, 22), (18, 20), (11, 23),
    (12, 24), (23, 24), (23, 25), (24, 26), (25, 27), (26, 28), (27, 29),
    (28, 30), (29, 31), (30, 32), (27, 31), (28, 32),
)  # fmt: skip

# Performer's left in orange, right in blue, middle in white (BGR).
_LEFT, _RIGHT, _MID = (0, 140, 255), (255, 120, 0), (230, 230, 230)


def _side(i: int) -> tuple[int, int, int]:
    if i == 0:
        return _MID
    return _LEFT if i in (1, 2, 3, 7, 9) or (i >= 11 and i % 2 == 1) else _RIGHT


def draw_skeleton(image: np.ndarray, xy: np.ndarray, visibility: np.ndarray, min_visibility: float = 0.5) -> np.ndarray:
    """Return a copy of a BGR frame with the skeleton drawn on it.

    Parameters
    ----------
    image : (H, W, 3) uint8 ndarray
    xy : (33, >=2) ndarray
        Pixel positions (NaN = missing).
    visibility : (33,) ndarray
        Points below `min_visibility` are drawn hollow, missing ones not at all.
    """
    out = image.copy()
    scale = max(1, round(max(image.shape[:2]) / 400))
    pts = np.asarray(xy, dtype=float)[:, :2]
    ok = np.isfinite(pts).all(axis=1)
    for a, b in POSE_CONNECTIONS:
        if ok[a] and ok[b]:
            colour = _side(b) if _side(a) == _side(b) else _MID
            cv2.line(
                out,
                tuple(np.round(pts[a]).astype(int)),
                tuple(np.round(pts[b]).astype(int)),
                colour,
                scale,
                cv2.LINE_AA,
            )
    for i in np.flatnonzero(ok):
        filled = -1 if visibility[i] >= min_visibility else scale
        cv2.circle(out, tuple(np.round(pts[i]).astype(int)), 2 * scale, _side(i), filled, cv2.LINE_AA)
    return out


def write_overlay(video, track: KeypointTrack, out, fps: float | None = None, stop=None) -> Path:
    """Write `video` with `track` drawn on it to `out` (atomically).

    Parameters
    ----------
    video : str or Path
    track : KeypointTrack
    out : str or Path
    fps : float, optional
        The frame rate the track was made at, if not the video's.
    stop : threading.Event, optional
        Set from another thread to give up (an interrupted capture): no
        file is left at `out`.

    Raises
    ------
    KeypointError
        The track and the video differ in frame size, or `stop` was set.
    """
    w, h = (int(v) for v in track.image_size)
    with VideoWriter(out, track.fps, (w, h)) as writer:
        for frame in iter_frames(video, fps=fps, stop=len(track)):
            if stop is not None and stop.is_set():
                raise KeypointError(f"{out}: overlay stopped at frame {frame.index}")
            if frame.image.shape[:2] != (h, w):
                raise KeypointError(
                    f"{video}: frame {frame.index} is {frame.image.shape[1]}x{frame.image.shape[0]}, "
                    f"the track was made on {w}x{h}"
                )
            writer.write(draw_skeleton(frame.image, track.xy[frame.index], track.visibility[frame.index]))
    return Path(out)
