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

__all__ = [
    "HYSTERESIS_DEG",
    "TRUNK_MAX_BIAS_DEG",
    "TRUNK_MAX_MARGIN_DEG",
    "depth_axes",
    "held_pose",
    "hold_frames",
    "keep_previous",
    "trunk_tilt_beyond_noise",
    "upright_trunk",
]

#: A part's clip-median direction within this of vertical is taken as a
#: fit's bias of the upright pose; farther, the dancer holds a real tilt.
TRUNK_MAX_BIAS_DEG = 35.0
#: Cap of the noise margin a measured trunk tilt must exceed, degrees.
TRUNK_MAX_MARGIN_DEG = 10.0
_UP = np.array([0.0, 0.0, 1.0])
#: Horizontal share of a line of sight below which a camera looks (nearly)
#: straight down or up: sin 10°, an overhead camera, whose depth is vertical.
_MIN_HORIZONTAL = 0.17


def upright_trunk(labels: FrameLabels, part: str, depth: np.ndarray | None = None) -> tuple[FrameLabels, float]:
    """`labels` with `part`'s vectors measured from the clip's own upright, and its noise margin.

    With one camera's line of sight (`depth`) the fit leans the chest in
    depth (measured on renders: the upright chest's fitted lean across the
    image is 0-3°, along the line of sight 3-21°).  The part (``chest``)
    is upright for much of a phrase (DESIGN.md: it starts upright), so the
    median lean in depth over the frames nearer vertical is taken as that
    bias and removed, frame by frame about the axis across the image; a
    median farther than :data:`TRUNK_MAX_BIAS_DEG` from vertical is a tilt
    held by the dancer and is left alone.  Only the lean in depth is
    corrected, so a phrase of mostly tilted chests (whose nearer-vertical
    frames are tilts too) is not rotated sideways by its own tilts.

    Without one (motion files, several cameras) the chest is measured in
    three dimensions and has no such bias: its vectors are left as they
    are.  Taking the clip's nearer-vertical median as the upright there
    read a phrase's most frequent tilt as upright (random scores: the
    chest column of the measured quantiser on the dancer's own joints with
    4 mm of jitter 69 % against 97 % as measured).

    The margin is the 90th percentile of the (corrected) tilt from
    vertical, capped at :data:`TRUNK_MAX_MARGIN_DEG`: a tilt symbol must
    exceed its threshold by it to be more than the trunk's own noise, which
    is not white — a fitted chest straightens by 20-25° whenever the arms
    rise — so a percentile, not a deviation, measures it.  Capped, a
    written tilt (45°) still clears threshold plus margin.

    Parameters
    ----------
    labels : FrameLabels
    part : str
        A single-vector part (``chest``, ``head``).
    depth : (T, 3) or (3,) ndarray, optional
        The camera's line of sight in the labels' body axes
        (:func:`depth_axes`); None when not one camera (motion files,
        several cameras).

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
    raw = np.degrees(np.arccos(np.clip(v[ok, 2], -1.0, 1.0)))
    if depth is None:
        return labels, _noise_margin(raw)
    # The upright pose: the median over the frames nearer vertical, so that
    # a written tilt held for a third of the phrase does not pull it over.
    near = raw <= np.percentile(raw, 60)
    m = np.median(v[ok][near], axis=0)
    m /= np.linalg.norm(m)
    if np.degrees(np.arccos(np.clip(m @ _UP, -1.0, 1.0))) > TRUNK_MAX_BIAS_DEG:
        return labels, 0.0
    vectors = labels.vectors.copy()
    d = np.broadcast_to(np.asarray(depth, dtype=float), v.shape)
    lean = np.arctan2(np.sum(v * d, axis=-1), v[:, 2])  # (T,) radians towards the camera's axis
    sel = lean[ok][near]
    bias = float(np.median(sel[np.isfinite(sel)])) if np.isfinite(sel).any() else 0.0
    vectors[:, col] = _lean_back(v, d, bias)
    tilt = np.degrees(np.arccos(np.clip(vectors[ok, col, 2], -1.0, 1.0)))
    return replace(labels, vectors=vectors), _noise_margin(tilt)


def _noise_margin(tilt_deg: np.ndarray) -> float:
    """The trunk's noise margin (degrees) from its tilts (see :func:`upright_trunk`)."""
    return min(TRUNK_MAX_MARGIN_DEG, float(np.percentile(tilt_deg, 90)))


def depth_axes(frame: np.ndarray, line_of_sight) -> np.ndarray:
    """A camera's horizontal line of sight in body axes at each frame.

    Parameters
    ----------
    frame : (T, 3, 3) ndarray
        Body frames (rows right, forward, up; :func:`~capture2notation.body.body_frame`).
    line_of_sight : (3,) array_like
        The camera's viewing axis in the world (z up).

    Returns
    -------
    (T, 3) ndarray or None
        Unit horizontal vectors (z = 0) in body axes, NaN where the frame
        is; None for a camera looking straight down or up (within
        :data:`_MIN_HORIZONTAL` of vertical), which sees no lean in depth.
    """
    los = np.asarray(line_of_sight, dtype=float).copy()
    los[2] = 0.0  # body up is world up: the lean in depth is about a horizontal axis
    n = np.linalg.norm(los)
    if not np.isfinite(n) or n < _MIN_HORIZONTAL * np.linalg.norm(line_of_sight):
        return None
    return frame @ (los / n)


def _lean_back(v: np.ndarray, d: np.ndarray, angle: float) -> np.ndarray:
    """Rotate unit vectors `v` (T, 3) by −`angle` (radians) in the plane of vertical and `d` (T, 3, horizontal)."""
    a = np.sum(v * d, axis=-1, keepdims=True)  # component along d
    z = v[:, 2:3]
    rest = v - a * d - z * _UP  # the component across the line of sight is kept
    c, s = np.cos(angle), np.sin(angle)
    return rest + (c * a - s * z) * d + (s * a + c * z) * _UP


def trunk_tilt_beyond_noise(v: np.ndarray, margin: float, depth: np.ndarray | None = None) -> float:
    """A held trunk vector's tilt from vertical less the fit's noise margin, degrees.

    Without a line of sight the whole tilt is reduced by `margin`.  With one
    (`depth`, horizontal, in the same body axes) only the tilt in depth is:
    the fit's trunk noise is a lean towards or away from the camera, and a
    lean across the image is measured (see :func:`upright_trunk`).

    Parameters
    ----------
    v : (3,) ndarray
        Held direction (need not be unit), body axes.
    margin : float
        Degrees (:func:`upright_trunk`).
    depth : (3,) ndarray, optional

    Returns
    -------
    float
        Degrees; a tilt symbol needs at least the tilt threshold.
    """
    v = np.asarray(v, dtype=float) / np.linalg.norm(v)
    if depth is None or not np.isfinite(depth).all():
        return float(np.degrees(np.arccos(np.clip(v[2], -1.0, 1.0)))) - margin
    along = float(v @ depth)
    across = float(np.linalg.norm(v - along * depth - v[2] * _UP))
    in_depth = max(abs(np.degrees(np.arctan2(along, v[2]))) - margin, 0.0)
    return float(np.hypot(np.degrees(np.arctan2(across, v[2])), in_depth))


#: Hysteresis of measured labels, degrees: a fitted limb direction is off by
#: 3-6° (more than that on a depth-ambiguous part), so a held pose within
#: this of the previous symbol's sector, or a bend within this of the
#: previous bend degree's band, keeps the previous symbol instead of flipping
#: on the fit's own error.
HYSTERESIS_DEG = 6.0


def held_pose(vectors: np.ndarray, bend_deg: np.ndarray | None, frames: slice) -> tuple[np.ndarray, float]:
    """Robust pose of one gesture column over the frames of a hold.

    The component-wise median (renormalised) and the median bend: a fitted
    hold flickers for a frame or two (a depth flip, a swapped limb) and a
    mean is pulled across a sector boundary by them, a median is not.

    Parameters
    ----------
    vectors : (T, 3) ndarray
        Unit body-frame vectors of the column; NaN where undefined.
    bend_deg : (T,) ndarray or None
        The column's bend β, degrees (limbs).
    frames : slice

    Returns
    -------
    v : (3,) ndarray
        Unit vector (NaN when no frame is defined).
    bend : float
        Degrees; NaN without a bend.
    """
    seg = vectors[frames]
    ok = np.isfinite(seg).all(axis=-1)
    if not ok.any():
        return np.full(3, np.nan), float("nan")
    v = np.median(seg[ok], axis=0)
    n = float(np.linalg.norm(v))
    v = v / n if n > 0 else np.full(3, np.nan)
    if bend_deg is None:
        return v, float("nan")
    b = bend_deg[frames]
    return v, float(np.median(b[np.isfinite(b)])) if np.isfinite(b).any() else float("nan")


def hold_frames(arrival: int, span_end: int, next_start: int, hold: int, T: int, min_frames: int = 3) -> slice:
    """Frames over which a measured movement's arrival pose is read.

    From the fitted arrival over up to `hold` frames of the hold, ending where
    the next movement of the part starts.  A fitted arrival later than that
    start (the logistic overshoots into a chained movement) would leave a
    single frame, or frames of the next movement: the hold then starts where
    the speed fell below its threshold (`span_end`).  At least `min_frames`
    frames are read, so that one flickering frame never decides a label.

    Parameters
    ----------
    arrival : int
        Frame of the fitted arrival.
    span_end : int
        First frame after the detected motion (speed below threshold).
    next_start : int
        First frame of the part's next movement (``T`` when none).
    hold : int
        Longest hold read, frames.
    T : int
        Number of frames.
    min_frames : int

    Returns
    -------
    slice
    """
    lo = arrival if arrival < next_start else min(span_end, arrival)
    hi = max(lo + min_frames, min(lo + hold, next_start + 1))
    hi = min(hi, T)
    lo = max(0, min(lo, hi - min_frames))
    return slice(lo, hi)


def _sector_label(v: np.ndarray) -> tuple[str, str]:
    from ..notation.directions import classify

    return classify(v)


def _toward(v: np.ndarray, c: np.ndarray, deg: float) -> np.ndarray:
    """`v` rotated towards `c` by `deg` degrees on their great circle (or onto `c` when nearer)."""
    ang = float(np.arccos(np.clip(v @ c, -1.0, 1.0)))
    step = np.radians(deg)
    if ang <= step or ang < 1e-9:
        return c.copy()
    w = c - (v @ c) * v
    w /= np.linalg.norm(w)
    return np.cos(step) * v + np.sin(step) * w


def keep_previous(
    v: np.ndarray,
    bend: float,
    label: tuple[str, str, int],
    previous: tuple[str, str, int],
    margin: float = HYSTERESIS_DEG,
) -> tuple[str, str, int]:
    """Label of a measured held pose with hysteresis against the part's previous symbol.

    The previous direction and level are kept when the pose lies within
    `margin` degrees of the previous symbol's sector (moving it `margin`
    degrees towards the previous canonical vector classifies it there), and
    the previous bend degree when β is within `margin` of its 30° band.  A
    pose well inside another sector changes the label as before.

    Parameters
    ----------
    v : (3,) ndarray
        Unit held vector.
    bend : float
        Held bend β, degrees (NaN: no bend).
    label : (direction, level, bend)
        The pose's own label.
    previous : (direction, level, bend)
        The part's previous symbol (its starting pose before any).
    margin : float
        Degrees.

    Returns
    -------
    (direction, level, bend)
    """
    from ..notation.directions import BEND_STEP_DEG, canonical_vector

    d, lv, k = label
    pd, plv, pk = previous
    if not pd or not np.isfinite(v).all():
        return label
    if (
        (d, lv) != (pd, plv)
        and not (pd == "place" and plv == "middle")
        and _sector_label(_toward(v, canonical_vector(pd, plv), margin)) == (pd, plv)
    ):
        d, lv = pd, plv
    if k != pk and pk >= 0 and np.isfinite(bend) and abs(bend - BEND_STEP_DEG * pk) < BEND_STEP_DEG / 2 + margin:
        k = pk
    return d, lv, k
