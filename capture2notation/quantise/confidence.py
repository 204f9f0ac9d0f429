"""How sure a capture is of each symbol it wrote.

A symbol's confidence is the product of two factors, each in [0, 1]:

* **measurement**: the fit's confidence (T, J) of the joints that define
  the symbol (the part's segment ends, a bendable limb's middle joint; the
  legs for supports, the hips for turns) over the frames where the symbol
  arrives and holds — low where the keypoints were hidden or their left and
  right could not be told apart (``KeypointTrack.identity_confidence``
  is multiplied into every sided joint by ``fit_track``);
* **margin**: how far the held direction lies from the nearest boundary
  of its sector or level (DESIGN.md's 22.5° sectors and levels), against
  :data:`MARGIN_FULL_DEG`: a limb 2° from a boundary is as likely to be the
  neighbouring symbol as this one.

A symbol whose confidence is below
:data:`~capture2notation.notation.model.SYMBOL_UNCERTAIN_BELOW` is
uncertain (drawn grey and hatched, listed as such).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..body import body_frame, joint_index, segment_vectors
from ..notation.model import PART_MIDDLE_JOINT, PART_SEGMENTS, Score, Symbol

__all__ = [
    "HOLD_S",
    "LEVEL_BOUNDARY_DEG",
    "MARGIN_FULL_DEG",
    "SECTOR_HALF_DEG",
    "score_confidence",
    "symbol_margin_deg",
]

#: Frames after a symbol's arrival that show its held pose, seconds (a
#: quarter of a second: the pose the quantiser labels, before the next move).
HOLD_S = 0.25
#: A direction this far (degrees) from every boundary is certain as far as
#: the angle goes; closer, the margin factor falls linearly to 0.  About
#: twice the angular error of a fitted limb through BlazePose.
MARGIN_FULL_DEG = 12.0
#: DESIGN.md: eight 45° sectors; levels at ±22.5°; place beyond ±67.5°.
SECTOR_HALF_DEG = 22.5
LEVEL_BOUNDARY_DEG = 22.5
PLACE_BOUNDARY_DEG = 67.5
#: Joints that carry a support (both legs) and a turn (the hips).
_SUPPORT_JOINTS = ("right_hip", "right_knee", "right_ankle", "left_hip", "left_knee", "left_ankle")
_TURN_JOINTS = ("pelvis", "right_hip", "left_hip")


def symbol_margin_deg(v: np.ndarray) -> np.ndarray:
    """Angular distance (degrees) of body-frame unit vectors from the nearest sector or level boundary.

    Parameters
    ----------
    v : (N, 3) ndarray
        Components (right, forward, up), unit length.

    Returns
    -------
    (N,) ndarray
        The smaller of the elevation's distance to its level (or place)
        boundaries and the azimuth's distance to its sector boundaries as
        an angle on the sphere (shrinking with cos elevation); NaN where
        `v` is missing.
    """
    v = np.asarray(v, dtype=float)
    elev = np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    az = np.degrees(np.arctan2(v[:, 0], v[:, 1]))
    level_margin = np.min(
        np.abs(
            elev[:, None] - np.array([-PLACE_BOUNDARY_DEG, -LEVEL_BOUNDARY_DEG, LEVEL_BOUNDARY_DEG, PLACE_BOUNDARY_DEG])
        ),
        axis=1,
    )
    within = np.abs((az + SECTOR_HALF_DEG) % (2 * SECTOR_HALF_DEG) - SECTOR_HALF_DEG)  # 0 at a sector centre
    az_margin = (SECTOR_HALF_DEG - within) * np.cos(np.radians(elev))
    place = np.abs(elev) > PLACE_BOUNDARY_DEG  # a place symbol has no sector
    return np.where(place, level_margin, np.minimum(level_margin, az_margin))


def _window(symbol: Symbol, tempo: float, fps: float, T: int) -> slice:
    end_f = int(round(float(symbol.end) * 60.0 / tempo * fps))
    hold = max(1, int(round(HOLD_S * fps)))
    lo = min(max(end_f, 0), T - 1)
    return slice(lo, min(T, lo + hold))


def score_confidence(score: Score, joints: np.ndarray, fps: float, confidence: np.ndarray | None = None) -> Score:
    """`score` with every symbol's confidence set (see the module docstring).

    Parameters
    ----------
    score : Score
        A captured score (its beats map to seconds of the clip from 0).
    joints : (T, J, 3) ndarray
        The motion it was read from, world metres, z up.
    fps : float
        Frames per second.
    confidence : (T, J) ndarray, optional
        The fit's joint confidence; default 1 where a joint is measured.

    Returns
    -------
    Score
        The same symbols (equal as notation) with ``confidence`` in [0, 1].
    """
    joints = np.asarray(joints, dtype=float)
    T = joints.shape[0]
    if confidence is None:
        confidence = np.isfinite(joints).all(axis=-1).astype(float)
    conf = np.nan_to_num(np.asarray(confidence, dtype=float))
    tempo = float(score.tempo)
    frame = body_frame(joints)
    vectors = {part: segment_vectors(joints, a, b, frame) for part, (a, b) in PART_SEGMENTS.items()}
    out = []
    for s in score.symbols:
        w = _window(s, tempo, fps, T)
        if s.part in PART_SEGMENTS:
            names = [*PART_SEGMENTS[s.part], *([PART_MIDDLE_JOINT[s.part]] if s.part in PART_MIDDLE_JOINT else [])]
            margins = symbol_margin_deg(vectors[s.part][w]) if T else np.array([np.nan])
            margin = float(np.median(margins[np.isfinite(margins)])) if np.isfinite(margins).any() else np.nan
            angle = float(np.clip(margin / MARGIN_FULL_DEG, 0.0, 1.0)) if np.isfinite(margin) else 0.0
        else:
            names = list(_TURN_JOINTS if s.is_turn else _SUPPORT_JOINTS)
            angle = 1.0
        idx = [joint_index(n) for n in names]
        measured = float(np.mean(np.min(conf[w][:, idx], axis=1))) if T else 0.0
        out.append(replace(s, confidence=round(float(np.clip(measured * angle, 0.0, 1.0)), 3)))
    return replace(score, symbols=tuple(out))
