"""Corrections the measured-motion path of :mod:`.segment` makes to fitted signals.

A single-view fit sees little depth, and its errors are not white: a
fitted chest leans 15-30° towards the camera for whole phrases, which the
DESIGN.md thresholds (forward high from 22.5°) read as chest symbols the
dancer never made.  These helpers measure such biases on the clip itself
and express the signals relative to them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .labels import FrameLabels

__all__ = ["TRUNK_MAX_BIAS_DEG", "TRUNK_MAX_MARGIN_DEG", "upright_trunk"]

#: A part's clip-median direction within this of vertical is taken as a
#: fit's bias of the upright pose; farther, the dancer holds a real tilt.
TRUNK_MAX_BIAS_DEG = 35.0
#: Cap of the noise margin a measured trunk tilt must exceed, degrees.
TRUNK_MAX_MARGIN_DEG = 10.0
_UP = np.array([0.0, 0.0, 1.0])


def _rotation_to_up(v: np.ndarray) -> np.ndarray:
    """(3, 3) rotation taking unit vector `v` onto +z about their common perpendicular (Rodrigues)."""
    axis = np.cross(v, _UP)
    s, c = float(np.linalg.norm(axis)), float(v @ _UP)
    if s < 1e-12:
        return np.eye(3)
    k = axis / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def upright_trunk(labels: FrameLabels, part: str) -> tuple[FrameLabels, float]:
    """`labels` with `part`'s vectors measured from the clip's own upright, and its noise margin.

    The part (``chest``) is upright most of a phrase (DESIGN.md: it starts
    upright, and a written tilt is held for a few beats at most), so the
    median of its direction over the clip is where the fit puts the upright
    pose; it is rotated onto vertical.  A median farther than
    :data:`TRUNK_MAX_BIAS_DEG` from vertical is a tilt held by the dancer and
    is left alone.  The margin is the 90th percentile of the corrected tilt
    from vertical, capped at :data:`TRUNK_MAX_MARGIN_DEG`: a tilt symbol must
    exceed its threshold by it to be more than the fit's own trunk noise,
    which is not white — a fitted chest straightens by 20-25° whenever the
    arms rise — so a percentile, not a deviation, measures it.  Capped, a
    written tilt (45°) still clears threshold plus margin.

    Parameters
    ----------
    labels : FrameLabels
    part : str
        A single-vector part (``chest``, ``head``).

    Returns
    -------
    labels : FrameLabels
        A copy with the part's vectors corrected (directions and levels of
        the other parts untouched).
    margin : float
        Degrees.
    """
    col = labels.index(part)
    v = labels.vectors[:, col]
    ok = np.isfinite(v).all(axis=-1)
    if ok.sum() < 5:
        return labels, 0.0
    # The upright pose: the median over the frames nearer vertical, so that
    # a written tilt held for a third of the phrase does not pull it over.
    raw = np.degrees(np.arccos(np.clip(v[ok, 2], -1.0, 1.0)))
    m = np.median(v[ok][raw <= np.percentile(raw, 60)], axis=0)
    m /= np.linalg.norm(m)
    if np.degrees(np.arccos(np.clip(m @ _UP, -1.0, 1.0))) > TRUNK_MAX_BIAS_DEG:
        return labels, 0.0
    R = _rotation_to_up(m)
    vectors = labels.vectors.copy()
    vectors[:, col] = v @ R.T
    tilt = np.degrees(np.arccos(np.clip(vectors[ok, col, 2], -1.0, 1.0)))
    margin = min(TRUNK_MAX_MARGIN_DEG, float(np.percentile(tilt, 90)))
    return replace(labels, vectors=vectors), margin
