"""Which room direction a measured dancer faces, frame by frame: the front held on eighths.

A dancer's front is held on a room direction between turns, and the room's
directions are eighths of a turn apart (DESIGN.md, "Facing and turns").  A
measured front (fitted hips, mocap) wanders about the direction held and
swings out and back with the hips.  :func:`decode_front_levels` reads the
directions held as a hidden chain over eighths (the levels), decoded by
Viterbi:

* **noise model**: the measured front is Gaussian about the level's
  direction (:data:`FRONT_SD_DEG`), and its errors last
  :data:`ERROR_CORRELATION_S`: each frame counts as that fraction of an
  independent reading, so a fit that errs the same way for a second is two
  pieces of evidence, not 25.  No outliers: a stretch the fit mirrored is
  indistinguishable from a turn in the front alone, and is followed;
* **prior**: turns start rarely (:data:`TURNS_PER_S`), last about
  :data:`TURN_MEAN_S`, go one way, and each eighth more is half as likely
  (:data:`EXTRA_EIGHTH_COST`).  A swing of the hips out and back must pay
  for two turns and does not earn them; an eighth turn held for a second
  or more does, even when the fit reads it 15° short;
* **origin**: the room's directions are the eighths nearest the fronts held,
  their circular mean over eighths (the camera need not be square to the
  room).

Measured on development captures (BlazePose, 3D fit, random scores with
turns, front view), the fitted front's error while the dancer held still had
a standard deviation of 10° (median-based 7.4°), 1 % beyond 35°, and an
integrated autocorrelation time of 15 frames at 25 fps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import QuantiseError
from ..keypoints.yaw import MAX_RATE_DEG_S

__all__ = [
    "ERROR_CORRELATION_S",
    "EXTRA_EIGHTH_COST",
    "FRONT_SD_DEG",
    "TURNS_PER_S",
    "TURN_MEAN_S",
    "FrontLevels",
    "decode_front_levels",
]

#: Degrees between two room directions.
_EIGHTH_DEG = 45.0
#: Standard deviation of a measured front about the direction held, degrees
#: (the fit's 10°, see the module docstring).
FRONT_SD_DEG = 10.0
#: How long a measured front's error lasts, seconds: frames closer than this
#: are one reading (the fit's errors' autocorrelation time, 15 frames at 25 fps).
ERROR_CORRELATION_S = 0.5
#: Prior rate of turns, per second: one every two seconds.  Starting one
#: costs ``-log(TURNS_PER_S / fps / 2)`` (either way).
TURNS_PER_S = 0.5
#: Prior mean length of a turn, seconds (a beat at 60 bpm).
TURN_MEAN_S = 1.0
#: Cost of each eighth a turn turns, nats: each more eighth half as likely.
EXTRA_EIGHTH_COST = float(np.log(2.0))
#: Levels kept either side of the one nearest the measured front, eighths
#: (a frame 135° from the front held costs more than starting a turn); also
#: the most a turn may move in one frame (at 25 fps the fastest turn the
#: yaw decoder follows, ``MAX_RATE_DEG_S``, is 60° a frame; below 8 fps the
#: band is the limit).
_BAND = 3
#: The dancer starts on the room direction nearest the median front over
#: this long from the first frame, seconds (five frames at 25 fps).
_START_S = 0.2
#: Fronts turning slower than this (degrees per second) weigh in the origin:
#: the directions held, not the ones passed through.
_HELD_SPEED_DEG_S = 20.0


@dataclass(frozen=True)
class FrontLevels:
    """The room directions a front is held on.

    Attributes
    ----------
    level : (T,) ndarray of int
        Eighths from the origin at each frame.
    origin_deg : float
        The direction of level 0, degrees clockwise from +y (the measured
        front's units).
    """

    level: np.ndarray
    origin_deg: float

    def direction_deg(self) -> np.ndarray:
        """(T,) the held direction at each frame, degrees."""
        return self.origin_deg + _EIGHTH_DEG * self.level


def _origin(front: np.ndarray, fps: float) -> float:
    """The room's direction nearest the fronts held: their circular mean over eighths, degrees."""
    speed = np.abs(np.gradient(front)) * fps if front.size > 1 else np.zeros(front.size)
    w = (speed < _HELD_SPEED_DEG_S).astype(float)
    if w.sum() == 0:
        w[:] = 1.0
    phase = np.exp(1j * np.radians(front) * (360.0 / _EIGHTH_DEG))
    mean = np.sum(w * phase)
    start = float(np.median(front[: max(1, int(round(_START_S * fps)))]))
    if abs(mean) < 1e-9:
        return start
    o = float(np.degrees(np.angle(mean))) * _EIGHTH_DEG / 360.0
    # Level 0 is the direction nearest where the dancer starts.
    return o + _EIGHTH_DEG * round((start - o) / _EIGHTH_DEG)


def decode_front_levels(front, fps: float) -> FrontLevels:
    """The most probable room direction held at each frame of a measured front.

    The hidden state is the level (eighths from the origin) and whether the
    dancer holds it, turns right (the level may only rise) or turns left
    (it may only fall).  Starting a turn is rare (:data:`TURNS_PER_S`); a
    turn lasts :data:`TURN_MEAN_S` on average and each eighth it turns
    costs :data:`EXTRA_EIGHTH_COST` more; the chain starts on level 0.

    Parameters
    ----------
    front : (T,) array_like
        Unwrapped front, degrees (:func:`~.turns.continuous_front`); finite.
    fps : float
        Frames per second.

    Returns
    -------
    FrontLevels
    """
    f = np.asarray(front, float)
    if f.ndim != 1 or not np.isfinite(f).all():
        bad = "not one-dimensional" if f.ndim != 1 else f"not finite at frame {int(np.flatnonzero(~np.isfinite(f))[0])}"
        raise QuantiseError(f"a front to decode must be a finite (T,) series of degrees: {bad}")
    if not np.isfinite(fps) or fps <= 0:
        raise QuantiseError(f"fps must be a positive number, got {fps!r}")
    T = f.size
    if T == 0:
        return FrontLevels(np.zeros(0, int), 0.0)
    origin = _origin(f, fps)
    # Levels further than _BAND eighths from the front are never on the path
    # (a frame there costs as much as a turn): each frame keeps a band.
    reach = min(_BAND, int(np.ceil(MAX_RATE_DEG_S / fps / _EIGHTH_DEG)))
    # The band follows the front as fast as a turn can, so some state of
    # each frame is reachable from the last (a front jumping further is
    # followed as fast as the chain allows).
    nearest = np.round((f - origin) / _EIGHTH_DEG).astype(int)
    base = np.empty(T, int)
    base[0] = nearest[0]
    for t in range(1, T):
        base[t] = base[t - 1] + min(reach, max(-reach, int(nearest[t] - base[t - 1])))
    band = np.arange(-_BAND, _BAND + 1)
    W = band.size
    resid = f[:, None] - (origin + _EIGHTH_DEG * (base[:, None] + band[None, :]))
    # Each frame is a fraction of an independent reading (ERROR_CORRELATION_S).
    emit = 0.5 * (resid / FRONT_SD_DEG) ** 2 / max(1.0, ERROR_CORRELATION_S * fps)
    p_start = min(0.5, TURNS_PER_S / fps)
    p_end = min(0.5, 1.0 / (TURN_MEAN_S * fps))
    start, stay = -np.log(p_start / 2.0), -np.log1p(-p_start)
    end, keep = -np.log(p_end), -np.log1p(-p_end)
    # acc[regime, j]: regimes hold, right, left; band index j.
    acc = np.full((3, W), np.inf)
    zero = int(np.clip(_BAND - base[0], 0, W - 1))
    acc[0, zero], acc[1:, zero] = emit[0, zero], start + emit[0, zero]
    back_regime = np.zeros((T, 3, W), np.int8)
    back_move = np.zeros((T, 3, W), np.int8)
    for t in range(1, T):
        d = int(base[t] - base[t - 1])
        new = np.empty((3, W))
        # Holding level l: it was held, or a turn ended on it.
        hold = np.stack([_shifted(acc[0], d) + stay, _shifted(acc[1], d) + end, _shifted(acc[2], d) + end])
        back_regime[t, 0] = np.argmin(hold, axis=0)
        new[0] = np.min(hold, axis=0)
        for regime, sign in ((1, 1), (2, -1)):
            # A turn starts from a hold or goes on, moving s eighths its way this frame.
            fresh, going = acc[0] + start, acc[regime] + keep
            src = np.minimum(fresh, going)
            via = np.where(fresh < going, 0, regime).astype(np.int8)
            cand = np.stack([_shifted(src, d - sign * m) + EXTRA_EIGHTH_COST * m for m in range(reach + 1)])
            best = np.argmin(cand, axis=0)
            back_move[t, regime] = best
            prev = np.clip(np.arange(W) + d - sign * best, 0, W - 1)
            back_regime[t, regime] = via[prev]
            new[regime] = np.min(cand, axis=0)
        acc = new + emit[t][None, :]
    path = np.empty(T, int)
    regime, j = np.unravel_index(int(np.argmin(acc)), acc.shape)
    level = int(base[-1] + band[j])
    for t in range(T - 1, -1, -1):
        path[t] = level
        if t == 0:
            break
        j = level - base[t] + _BAND
        r_prev = int(back_regime[t, regime, j])
        if regime == 1:
            level -= int(back_move[t, regime, j])
        elif regime == 2:
            level += int(back_move[t, regime, j])
        regime = r_prev
    return FrontLevels(path, origin)


def _shifted(x: np.ndarray, k: int) -> np.ndarray:
    """``y[j] = x[j + k]`` where that index exists, else +inf."""
    y = np.full(x.shape, np.inf)
    if abs(k) < x.size:
        if k >= 0:
            y[: x.size - k] = x[k:]
        else:
            y[-k:] = x[: x.size + k]
    return y
