"""Left/right consistency over time: undo the pose model's front/back flips.

A single image of a person is ambiguous up to a reflection in depth: the
same silhouette fits a body facing the camera and one facing away with left
and right exchanged.  BlazePose sometimes takes the wrong reading for a few
frames (e.g. a head turned away while the body faces the camera), which puts
every left landmark where the right one is.  In a video the previous frame
disambiguates: a body does not jump to its mirror image between frames, so
when the mirrored labelling of the current answer lies clearly nearer the
previous frame's landmarks than the answer as given, the answer is flipped
back — labels exchanged and depth reflected (the correction of exactly that
ambiguity).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MIRROR", "SWAP_PAIRS", "mirror_landmarks", "swap_evidence"]


def _mirror() -> np.ndarray:
    perm = np.arange(33)
    pairs = [(1, 4), (2, 5), (3, 6), (7, 8), (9, 10)] + [(k, k + 1) for k in range(11, 33, 2)]
    for a, b in pairs:
        perm[a], perm[b] = b, a
    return perm


#: Index permutation exchanging every left landmark with its right twin
#: (BlazePose order; the nose maps to itself).
MIRROR: np.ndarray = _mirror()

#: (left, right) pairs of the body (shoulders … feet) that decide a flip;
#: the face is left out, its points lie too close together to tell.
SWAP_PAIRS: np.ndarray = np.array([(k, k + 1) for k in range(11, 33, 2)])


def mirror_landmarks(values: np.ndarray, depth_axis: int | None = None) -> np.ndarray:
    """Exchange left and right landmarks, optionally reflecting depth.

    Parameters
    ----------
    values : (33, ...) ndarray
        Per-landmark values (positions, visibilities).
    depth_axis : int, optional
        Column of `values` holding depth relative to the hips (BlazePose's
        ``z``); negated when given.

    Returns
    -------
    (33, ...) ndarray
        A new array.
    """
    out = np.array(values, dtype=float)[MIRROR]
    if depth_axis is not None:
        out[:, depth_axis] = -out[:, depth_axis]
    return out


def swap_evidence(xy: np.ndarray, previous: np.ndarray, weight: np.ndarray | None = None) -> float:
    """How much nearer the previous frame the mirrored labelling is, pixels.

    Parameters
    ----------
    xy : (33, >=2) ndarray
        This frame's landmarks, pixels.
    previous : (33, >=2) ndarray
        The previous frame's (already consistent) landmarks, pixels.
    weight : (33,) ndarray, optional
        Per-landmark weights (e.g. visibility); default 1.

    Returns
    -------
    float
        ``cost(as given) - cost(mirrored)`` summed over :data:`SWAP_PAIRS`,
        where a pair's cost is the distance of its two points to the previous
        frame's points of the same label.  Positive: the mirrored reading
        fits the previous frame better; NaN when nothing is comparable.
    """
    cur = np.asarray(xy, dtype=float)[:, :2]
    prev = np.asarray(previous, dtype=float)[:, :2]
    w = np.ones(len(cur)) if weight is None else np.asarray(weight, dtype=float)
    left, right = SWAP_PAIRS[:, 0], SWAP_PAIRS[:, 1]
    same = np.linalg.norm(cur[left] - prev[left], axis=1) + np.linalg.norm(cur[right] - prev[right], axis=1)
    cross = np.linalg.norm(cur[left] - prev[right], axis=1) + np.linalg.norm(cur[right] - prev[left], axis=1)
    wp = np.minimum(w[left], w[right])
    ok = np.isfinite(same) & np.isfinite(cross) & np.isfinite(wp)
    if not ok.any():
        return float("nan")
    return float(np.sum(wp[ok] * (same[ok] - cross[ok])))
