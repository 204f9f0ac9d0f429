"""Direction, level and bend: the thresholds shared by renderer and quantiser.

A clean render round-trips exactly because :func:`canonical_vector` (symbol →
pose) and :func:`classify` (pose → symbol) use the same sectors.
"""

from __future__ import annotations

import numpy as np

from ..errors import NotationError
from .model import DIRECTIONS

__all__ = [
    "BEND_STEP_DEG",
    "LEVEL_THRESHOLD_DEG",
    "PLACE_THRESHOLD_DEG",
    "SECTOR_DIRECTIONS",
    "azimuth_elevation",
    "bend_angle",
    "bend_degree",
    "canonical_vector",
    "classify",
    "classify_indices",
]

#: The eight sector directions in index order (azimuth = 45° × index,
#: wrapped to (−180, 180]).
SECTOR_DIRECTIONS: tuple[str, ...] = (
    "forward",
    "right_forward",
    "right",
    "right_back",
    "back",
    "left_back",
    "left",
    "left_forward",
)
LEVEL_THRESHOLD_DEG = 22.5
PLACE_THRESHOLD_DEG = 67.5
BEND_STEP_DEG = 30.0
_LEVEL_ELEVATION = {"high": 45.0, "middle": 0.0, "low": -45.0}


def azimuth_elevation(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth and elevation of body-frame vectors.

    Parameters
    ----------
    v : (..., 3) ndarray
        Components (right, forward, up); need not be unit length.

    Returns
    -------
    azimuth, elevation : (...) ndarray
        Degrees; azimuth clockwise from forward in (−180, 180], elevation in
        [−90, 90].  NaN where `v` is NaN or zero.
    """
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        up = np.where(n > 0, v[..., 2] / n, np.nan)
    az = np.degrees(np.arctan2(v[..., 0], v[..., 1]))
    az = np.where(az <= -180.0, az + 360.0, az)
    el = np.degrees(np.arcsin(np.clip(up, -1.0, 1.0)))
    az = np.where(np.isnan(el), np.nan, az)
    return az, el


def classify_indices(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised :func:`classify` returning integer codes.

    Returns
    -------
    direction, level : (...) ndarray of int
        Direction index into ``list(DIRECTIONS)`` (8 = place) and level index
        into ``("high", "middle", "low")``; −1 where `v` is undefined.
    """
    az, el = azimuth_elevation(v)
    # Sector k covers (45k − 22.5, 45k + 22.5]; ceil puts the upper edge in.
    sector = np.mod(np.ceil((np.nan_to_num(az) - 22.5) / 45.0), 8).astype(int)
    level = np.where(el > LEVEL_THRESHOLD_DEG, 0, np.where(el < -LEVEL_THRESHOLD_DEG, 2, 1))
    place = np.abs(el) > PLACE_THRESHOLD_DEG
    direction = np.where(place, 8, sector)
    bad = np.isnan(el)
    return np.where(bad, -1, direction), np.where(bad, -1, level)


def classify(v) -> tuple[str, str]:
    """Direction and level of one body-frame vector (DESIGN.md thresholds).

    Parameters
    ----------
    v : (3,) array_like
        Components (right, forward, up).

    Returns
    -------
    (direction, level) : tuple of str
    """
    d, l = classify_indices(np.asarray(v, dtype=float)[None])
    if d[0] < 0:
        raise NotationError(f"cannot classify undefined vector {np.asarray(v).tolist()}")
    return list(DIRECTIONS)[d[0]], ("high", "middle", "low")[l[0]]


def canonical_vector(direction: str, level: str) -> np.ndarray:
    """Unit body-frame vector of a symbol: sector centre at its level's elevation.

    High is +45°, middle 0°, low −45°; place high/low are straight up/down.
    """
    if direction not in DIRECTIONS:
        raise NotationError(f"unknown direction {direction!r}")
    if level not in _LEVEL_ELEVATION:
        raise NotationError(f"unknown level {level!r}")
    if direction == "place":
        if level == "middle":
            raise NotationError("'place middle' has no direction vector")
        return np.array([0.0, 0.0, 1.0 if level == "high" else -1.0])
    az = np.radians(DIRECTIONS[direction])
    el = np.radians(_LEVEL_ELEVATION[level])
    return np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])


def bend_angle(a: np.ndarray, m: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bend β = 180° − interior angle at the middle joint `m`, degrees.

    Parameters
    ----------
    a, m, b : (..., 3) ndarray
        Positions of the bound end, middle joint and free end.
    """
    u = np.asarray(a, float) - m
    w = np.asarray(b, float) - m
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.sum(u * w, axis=-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(w, axis=-1))
    return 180.0 - np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def bend_degree(beta_deg: np.ndarray) -> np.ndarray:
    """Bend degree k = round(β / 30°), clipped to 0…6 (−1 where β is NaN)."""
    beta = np.asarray(beta_deg, dtype=float)
    k = np.clip(np.floor(np.nan_to_num(beta) / BEND_STEP_DEG + 0.5), 0, 6).astype(int)
    return np.where(np.isnan(beta), -1, k)
