"""How sure a capture is of each symbol it wrote: a probability from a stated model.

A symbol's confidence is the product of two factors, each in [0, 1]:

* **measurement**: the fit's confidence (T, J) of the joints that define
  the symbol (the part's segment ends, a bendable limb's middle joint; the
  legs for supports, the hips for turns) over the frames where the symbol
  arrives and holds — low where the keypoints were hidden or their left and
  right could not be told apart (the capture passes
  ``FitResult.labelled_confidence()``: the track's identity confidence on
  every sided joint);
* **direction**: the probability that the limb's true direction lies in the
  symbol's own cell (its 45° sector and its level, DESIGN.md) given the
  measured held direction, under this model of the fit's error: the
  measured unit vector is the true one plus a Gaussian error, of
  :data:`ANGLE_SD_DEG` across the image and :data:`DEPTH_SD_DEG` along the
  camera's line of sight (a single camera measures depth worst; for a
  motion file or several cameras the error is isotropic), both widened
  by the held direction's own spread over the hold (the fit's jitter,
  measured per symbol); with a single camera the body frame's yaw error
  :data:`FRAME_YAW_SD_DEG` adds to the azimuth's.  For the small angles
  involved the elevation and the azimuth errors are independent normals
  along the sphere's two tangents, so the probability is the product of two normal interval
  probabilities — exact to first order in the error, and 0.5 at a boundary;
* for a **turn**, where one view's front was decoded from the image
  (``FitResult.front_readings``): the posterior probability of the front
  as decoded against its mirror image over the turn's frames,
  :func:`turn_probability`.  The mirror image turns the other way, and the
  decoder tells the two apart only by the shoulders' and hips' order,
  which a missed left/right swap reverses: a turn it cannot tell from its
  mirror image is marked uncertain rather than guessed.

A symbol whose confidence is below
:data:`~capture2notation.notation.model.SYMBOL_UNCERTAIN_BELOW` (0.5: the
symbol is more likely wrong than right) is uncertain (drawn grey and
hatched, listed as such).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.special import ndtr

from ..body import body_frame, joint_index, segment_vectors
from ..errors import QuantiseError
from ..notation.model import DIRECTIONS, PART_MIDDLE_JOINT, PART_SEGMENTS, Score, Symbol

__all__ = [
    "ANGLE_SD_DEG",
    "DEPTH_SD_DEG",
    "FRAME_YAW_SD_DEG",
    "HOLD_S",
    "LEVEL_BOUNDARY_DEG",
    "SECTOR_HALF_DEG",
    "direction_probability",
    "score_confidence",
    "symbol_margin_deg",
    "turn_probability",
]

#: Frames after a symbol's arrival that show its held pose, seconds (a
#: quarter of a second: the pose the quantiser labels, before the next move).
HOLD_S = 0.25
#: Standard error (degrees) of a fitted limb's direction across the image
#: (and in every direction for a motion file or several cameras): the
#: angular error of a limb fitted through BlazePose, ~6° (the figure the
#: previous linear margin of 12° was set at twice of).
ANGLE_SD_DEG = 6.0
#: Standard error (degrees) of a fitted limb's direction along one camera's
#: line of sight: a single view sees depth only through BlazePose's world
#: landmarks and bone lengths, about three times worse than across the image
#: (docs/benchmarks/identity.md: most wrong symbols are depth errors, an arm
#: behind the body read in front).
DEPTH_SD_DEG = 18.0
#: Standard error (degrees) of the body frame's yaw: the frame's forward is
#: square to the hips' line (~0.2 m), whose ends a single view places in
#: depth only to a few centimetres, and a yaw error turns every azimuth with
#: it.  10° together with the two above makes the mean confidence equal
#: the share of right symbols on development renders (0.42 against 0.40,
#: seeds 7700–7709, 474 symbols; docs/benchmarks/confidence.md).
FRAME_YAW_SD_DEG = 10.0
#: The azimuth's error grows as 1 / cos(elevation) towards the vertical;
#: capped here (degrees), beyond which the azimuth is simply unknown.
_AZIMUTH_SD_CAP_DEG = 180.0
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


def _normal_interval(lo: float, hi: float, x: float, sd: float) -> float:
    """P(lo < x + e < hi) for e ~ N(0, sd²)."""
    return float(ndtr((hi - x) / sd) - ndtr((lo - x) / sd))


def direction_probability(held: np.ndarray, direction: str, level: str, depth: np.ndarray | None = None) -> float:
    """Probability that a limb's true direction lies in the cell (`direction`, `level`), given its held direction.

    Parameters
    ----------
    held : (H, 3) ndarray
        Body-frame vectors (right, forward, up) of the limb over the frames
        of the symbol's hold, any length; NaN rows are skipped.
    direction, level : str
        The symbol's cell (DESIGN.md's sectors and levels).
    depth : (H, 3) ndarray, optional
        The camera's line of sight in the same body frames (unit); None
        when there is no single camera (isotropic error).

    Returns
    -------
    float
        In [0, 1]; 0 when no frame of `held` is measured.  The model is the
        module docstring's: Gaussian angular error of :data:`ANGLE_SD_DEG`
        across, :data:`DEPTH_SD_DEG` along the line of sight, plus the
        held vectors' own median angular spread, independent along the
        elevation and azimuth tangents of the mean direction.
    """
    v = np.asarray(held, dtype=float)
    n = np.linalg.norm(v, axis=-1)
    ok = np.isfinite(n) & (n > 1e-9)
    if not ok.any():
        return 0.0
    u = v[ok] / n[ok, None]
    m = np.median(u, axis=0)
    m = m / np.linalg.norm(m) if np.linalg.norm(m) > 1e-9 else u[0]
    jitter = float(np.degrees(np.median(np.arccos(np.clip(u @ m, -1.0, 1.0)))))
    el = float(np.degrees(np.arcsin(np.clip(m[2], -1.0, 1.0))))
    az = float(np.degrees(np.arctan2(m[0], m[1])))
    hn = np.hypot(m[0], m[1])
    h = np.array([m[0], m[1], 0.0]) / hn if hn > 1e-9 else np.array([0.0, 1.0, 0.0])
    sin_el, cos_el = np.sin(np.radians(el)), np.cos(np.radians(el))
    t_el = np.array([-sin_el * h[0], -sin_el * h[1], cos_el])  # towards higher elevation
    t_az = np.array([h[1], -h[0], 0.0])  # towards larger azimuth

    d = None
    if depth is not None:
        dd = np.asarray(depth, dtype=float)[ok]
        dd = dd[np.isfinite(dd).all(axis=-1)]
        if len(dd):
            d = np.median(dd, axis=0)
            d = d / np.linalg.norm(d) if np.linalg.norm(d) > 1e-9 else None

    def sd_along(t: np.ndarray) -> float:
        across = ANGLE_SD_DEG**2
        along = across if d is None else across + (DEPTH_SD_DEG**2 - across) * float(t @ d) ** 2
        return float(np.sqrt(along + jitter**2))

    sd_el = sd_along(t_el)
    if direction == "place":
        lo, hi = (PLACE_BOUNDARY_DEG, np.inf) if level == "high" else (-np.inf, -PLACE_BOUNDARY_DEG)
        return _normal_interval(lo, hi, el, sd_el)
    lo, hi = {
        "high": (LEVEL_BOUNDARY_DEG, PLACE_BOUNDARY_DEG),
        "middle": (-LEVEL_BOUNDARY_DEG, LEVEL_BOUNDARY_DEG),
        "low": (-PLACE_BOUNDARY_DEG, -LEVEL_BOUNDARY_DEG),
    }[level]
    p_level = _normal_interval(lo, hi, el, sd_el)
    sd_az = min(
        _AZIMUTH_SD_CAP_DEG, float(np.hypot(sd_along(t_az) / max(cos_el, 1e-6), 0.0 if d is None else FRAME_YAW_SD_DEG))
    )
    off = (az - float(DIRECTIONS[direction]) + 180.0) % 360.0 - 180.0
    p_sector = _normal_interval(-SECTOR_HALF_DEG, SECTOR_HALF_DEG, off, sd_az)
    return p_level * p_sector


def turn_probability(readings: np.ndarray) -> float:
    """Probability that a turn was read the right way round, from the front's two readings over its frames.

    Parameters
    ----------
    readings : (n, 2) ndarray
        Per frame of the turn, the posterior probability of the front as
        decoded and of its mirror image (``FitResult.front_readings``); NaN
        rows carry nothing.

    Returns
    -------
    float
        The decoded reading's share of the two summed over the frames; 0.5
        where no frame tells them apart.
    """
    readings = np.nan_to_num(np.asarray(readings, dtype=float).reshape(-1, 2))
    total = float(readings.sum())
    if total <= 1e-9:
        return 0.5
    return float(readings[:, 0].sum()) / total


def score_confidence(
    score: Score,
    joints: np.ndarray,
    fps: float,
    confidence: np.ndarray | None = None,
    line_of_sight: np.ndarray | None = None,
    front_readings: np.ndarray | None = None,
) -> Score:
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
    line_of_sight : (3,) ndarray, optional
        The single camera's viewing axis in world coordinates (its sign is
        irrelevant); None for motion files and several cameras.
    front_readings : (T, 2) ndarray, optional
        ``FitResult.front_readings``; None where the capture did not decode
        the front from the image (turns then rest on the hips' confidence
        alone).

    Returns
    -------
    Score
        The same symbols (equal as notation) with ``confidence`` in [0, 1].
    """
    joints = np.asarray(joints, dtype=float)
    T = joints.shape[0]
    if front_readings is not None and np.shape(front_readings) != (T, 2):
        raise QuantiseError(f"front_readings must have shape ({T}, 2), got {np.shape(front_readings)}")
    if confidence is None:
        confidence = np.isfinite(joints).all(axis=-1).astype(float)
    conf = np.nan_to_num(np.asarray(confidence, dtype=float))
    tempo = float(score.tempo)
    frame = body_frame(joints)
    depth = None
    if line_of_sight is not None:
        los = np.asarray(line_of_sight, dtype=float)
        depth = frame @ (los / np.linalg.norm(los))  # (T, 3): the line of sight in body axes
    vectors = {part: segment_vectors(joints, a, b, frame) for part, (a, b) in PART_SEGMENTS.items()}
    out = []
    for s in score.symbols:
        w = _window(s, tempo, fps, T)
        if (
            s.part in PART_SEGMENTS
            and T
            and s.direction in DIRECTIONS
            and (s.direction, s.level) != ("place", "middle")
        ):
            names = [*PART_SEGMENTS[s.part], *([PART_MIDDLE_JOINT[s.part]] if s.part in PART_MIDDLE_JOINT else [])]
            angle = direction_probability(vectors[s.part][w], s.direction, s.level, None if depth is None else depth[w])
        else:
            names = (
                list(_TURN_JOINTS if s.is_turn else _SUPPORT_JOINTS)
                if s.part not in PART_SEGMENTS
                else list(PART_SEGMENTS[s.part])
            )
            angle = 1.0
            if s.is_turn and front_readings is not None and T:
                a = min(max(int(round(float(s.start) * 60.0 / tempo * fps)), 0), T - 1)
                b = min(max(int(round(float(s.end) * 60.0 / tempo * fps)), a + 1), T)
                angle = turn_probability(front_readings[a:b])
        idx = [joint_index(n) for n in names]
        measured = float(np.mean(np.min(conf[w][:, idx], axis=1))) if T else 0.0
        out.append(replace(s, confidence=round(float(np.clip(measured * angle, 0.0, 1.0)), 3)))
    return replace(score, symbols=tuple(out))
