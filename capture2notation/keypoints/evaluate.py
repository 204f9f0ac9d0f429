"""Accuracy of a keypoint track against 2D ground truth (renders, fixtures).

PCK ("percentage of correct keypoints") counts a point as correct when it lies
within a radius of the truth — here a fraction of the person's height in
pixels.  A left/right swap is a frame where both points of a pair lie nearer
the opposite side's truth while the two truths are farther apart than the
radius (closer than that, a swap is not distinguishable from noise).
"""

from __future__ import annotations

import numpy as np

__all__ = ["PAIRS", "left_right_swaps", "pck", "person_height_px"]

#: The limb joints the issue scores, as (left, right) BlazePose indices.
PAIRS: dict[str, tuple[int, int]] = {
    "shoulder": (11, 12),
    "elbow": (13, 14),
    "wrist": (15, 16),
    "hip": (23, 24),
    "knee": (25, 26),
    "ankle": (27, 28),
}


def person_height_px(K: np.ndarray, R: np.ndarray, t: np.ndarray, pelvis: np.ndarray, height_m: float) -> np.ndarray:
    """Body height in pixels at the pelvis depth, ``f_y * H / z``, per frame.

    Parameters
    ----------
    K, R, t : camera intrinsics (3, 3), rotation (3, 3), translation (3,)
        with ``x_cam = R @ x_world + t``.
    pelvis : (T, 3) ndarray
        Pelvis positions, world metres.
    height_m : float
        Body height, metres.
    """
    z = (np.asarray(pelvis) @ np.asarray(R).T + np.asarray(t))[:, 2]
    return K[1, 1] * height_m / z


def _errors(xy: np.ndarray, truth: np.ndarray) -> np.ndarray:
    err = np.linalg.norm(np.asarray(xy)[..., :2] - np.asarray(truth)[..., :2], axis=-1)
    return np.where(np.isfinite(err), err, np.inf)  # a missing point is a miss


def pck(xy, truth, radius, visible=None, joints=None) -> dict[int, float]:
    """Fraction of frames each joint lies within `radius` of the truth.

    Parameters
    ----------
    xy : (T, K, >=2) ndarray
        Estimated pixel positions (NaN = missing, counted as wrong).
    truth : (T, K, 2) ndarray
        True pixel positions.
    radius : (T,) ndarray or float
        Pixel radius per frame.
    visible : (T, K) ndarray of bool, optional
        Count only frames where the joint is visible in the truth.
    joints : iterable of int, optional
        Joint indices (default all).

    Returns
    -------
    dict
        Joint index → PCK in [0, 1] (NaN when never visible).
    """
    err = _errors(xy, truth)
    radius = np.broadcast_to(np.asarray(radius, dtype=float), err.shape[:1])
    ok = err <= radius[:, None]
    vis = np.ones(err.shape, bool) if visible is None else np.asarray(visible, bool)
    out = {}
    for j in range(err.shape[1]) if joints is None else joints:
        n = vis[:, j].sum()
        out[int(j)] = float(ok[vis[:, j], j].mean()) if n else float("nan")
    return out


def left_right_swaps(xy, truth, radius, pairs=None) -> dict[str, np.ndarray]:
    """Frames where a left/right pair is swapped.

    Returns
    -------
    dict
        Pair name → (T,) bool array.
    """
    err = _errors(xy, truth)
    xy = np.asarray(xy)[..., :2]
    truth = np.asarray(truth)[..., :2]
    radius = np.broadcast_to(np.asarray(radius, dtype=float), err.shape[:1])
    out = {}
    for name, (left, right) in (PAIRS if pairs is None else pairs).items():
        apart = np.linalg.norm(truth[:, left] - truth[:, right], axis=-1) > radius
        cross_l = np.linalg.norm(xy[:, left] - truth[:, right], axis=-1) < err[:, left]
        cross_r = np.linalg.norm(xy[:, right] - truth[:, left], axis=-1) < err[:, right]
        out[name] = apart & cross_l & cross_r
    return out
