"""Per-clip segment lengths.

A clip is one performer, so every segment has one length for the whole clip:
the median over confident frames of the distance between the two measured
ends, averaged over the left and right sides.  Segments that are never
measured (e.g. pelvis → waist) take the body model's proportion scaled by the
median ratio of the measured segments to the model, so the figure stays in
proportion.  Offsets keep the rest directions of :class:`~capture2notation.body.Body`
and only change length.
"""

from __future__ import annotations

import numpy as np

from ..body import JOINTS, Body
from ..errors import FittingError

__all__ = ["estimate_offsets", "offsets_from_ratios", "scale_of"]

_MIN_FRAMES = 3
_MIN_CONF = 0.5
# Ratios to the model outside this band are taken as measurement failures.
_RATIO_BAND = (0.5, 2.0)


#: With ``relative=True`` a segment may differ from the model's proportion by
#: at most this factor (keypoint models' world landmarks are not exact).
RELATIVE_BAND = (0.85, 1.15)


def estimate_offsets(
    points: np.ndarray, confidence: np.ndarray, body: Body | None = None, relative: bool = False
) -> np.ndarray:
    """Per-clip joint offsets from measured 3D joint positions.

    Parameters
    ----------
    points : (T, J, 3) ndarray
        Measured positions of the joints of :data:`~capture2notation.body.JOINTS`
        (any frame, any origin: only distances are used), metres; NaN where
        not measured.
    confidence : (T, J) ndarray
        Per-point confidence in [0, 1]; below 0.5 a point is not used.
    body : Body, optional
        Model proportions (default ``Body()``).
    relative : bool
        Keep the body's overall size (its height) and take only the
        proportions from the data, each within :data:`RELATIVE_BAND`: for
        sources whose scale is unreliable (BlazePose world landmarks come out
        up to ~20 % small, and a wrong size turns into a wrong depth).

    Returns
    -------
    (J, 3) ndarray
        Offsets of each joint from its parent, metres (root row zero).
    """
    body = body or Body()
    points = np.asarray(points, float)
    conf = np.asarray(confidence, float)
    J = len(JOINTS)
    if points.ndim != 3 or points.shape[1:] != (J, 3) or conf.shape != points.shape[:2]:
        raise FittingError(
            f"estimate_offsets needs points (T, {J}, 3) and confidence (T, {J}); got {points.shape}, {conf.shape}"
        )
    base = np.linalg.norm(body.offsets, axis=1)
    parents = body.parents
    ok = (conf >= _MIN_CONF) & np.all(np.isfinite(points), axis=-1)
    ratio = np.full(J, np.nan)
    for j in range(1, J):
        p = parents[j]
        both = ok[:, j] & ok[:, p]
        if both.sum() < _MIN_FRAMES or base[j] <= 0:
            continue
        ratio[j] = np.median(np.linalg.norm(points[both, j] - points[both, p], axis=1)) / base[j]
    return offsets_from_ratios(ratio, body, relative)


def offsets_from_ratios(
    ratio: np.ndarray, body: Body | None = None, relative: bool = False, scale_from: np.ndarray | None = None
) -> np.ndarray:
    """Offsets from measured length ratios to the model (NaN = not measured).

    Parameters
    ----------
    ratio : (J,) ndarray
        Measured length of the segment ending at each joint over the model's.
    body : Body, optional
    relative : bool
        See :func:`estimate_offsets`.
    scale_from : (J,) ndarray of bool, optional
        Segments whose ratios set the figure's overall scale (their median);
        all measured ones by default.  The others are still scaled by it.

    Returns
    -------
    (J, 3) ndarray
    """
    body = body or Body()
    ratio = np.asarray(ratio, float).copy()
    ratio[~((ratio >= _RATIO_BAND[0]) & (ratio <= _RATIO_BAND[1]))] = np.nan
    ratio = _symmetrise(ratio)
    measured = ratio[np.isfinite(ratio) & (True if scale_from is None else np.asarray(scale_from, bool))]
    overall = float(np.median(measured)) if measured.size else 1.0
    ratio = np.where(np.isfinite(ratio), ratio, overall)
    if relative:
        ratio = np.clip(ratio / overall, *RELATIVE_BAND)
    ratio[0] = 0.0
    return body.offsets * ratio[:, None]


def scale_of(offsets: np.ndarray, body: Body | None = None) -> float:
    """Height (metres) of the standing figure with these offsets (head top above the lowest toe/ankle)."""
    body = body or Body()
    rest = np.zeros((len(JOINTS), 3))
    for j in range(1, len(JOINTS)):
        rest[j] = rest[body.parents[j]] + offsets[j]
    return float(rest[:, 2].max() - rest[:, 2].min())


def _symmetrise(ratio: np.ndarray) -> np.ndarray:
    """Average left and right segment ratios (a performer is symmetric enough)."""
    out = ratio.copy()
    for j, name in enumerate(JOINTS):
        if name.startswith("right_"):
            k = JOINTS.index("left_" + name[6:])
            pair = ratio[[j, k]]
            if np.any(np.isfinite(pair)):
                out[j] = out[k] = np.nanmean(pair)
    return out
