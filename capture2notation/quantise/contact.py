"""Which feet touch the floor, decoded over the whole clip (measured motion).

DESIGN.md's per-frame rule (within 3 cm of the floor, slower than 0.2 m/s)
is exact for clean motion but fails on measured motion: at 100 fps a
millimetre of mocap jitter is already 0.1-0.2 m/s, and a fitted or
drifting foot floats by centimetres.  Here each foot is a two-state hidden
Markov chain (air, floor) decoded by Viterbi:

* **foot height** ``h`` (its lowest point above the floor): on the floor
  ``h ~ N(μ, σ_h)``, the clip's own level and scatter of that foot's
  grounded frames (:func:`decode_contacts` re-estimates them from its own
  decoding: a fitted foot's points sit a few centimetres above the sole it
  stands on, by a bias of the keypoints and the body model, not of the
  dance), ``|μ| ≤`` :data:`MAX_FLOOR_OFFSET_M` and ``σ_h`` in
  [:data:`MIN_HEIGHT_SD_M`, :data:`MAX_HEIGHT_SD_M`]; in the air ``h`` is
  exponential above the floor with scale :data:`AIR_HEIGHT_SCALE_M` (a
  foot below the floor is read at the floor);
* **foot speed** ``v`` (of its middle, from positions smoothed over
  :data:`~.supports.smooth_positions`'s window): on the floor half-normal
  with scale :data:`FLOOR_SPEED_SD_MS` (sliding, pivoting, residual
  jitter), in the air half-normal with :data:`AIR_SPEED_SD_MS` (a swinging
  leg);
* **transitions** from the mean durations of a stance
  (:data:`MEAN_STANCE_S`) and of a foot's flight in a step
  (:data:`MEAN_FLIGHT_S`): a geometric dwell with those means.

The grounded level and scatter are fitted by Viterbi training
(:data:`_ROUNDS` rounds of decoding, then re-estimating them from the
frames decoded on the floor): with the floor's level fixed at zero, a
fitted foot standing 3 cm up on its own bias was read in the air in a fifth
of its grounded frames and half its relevés.

A foot that is not seen (its confidence below the tracker's floor) has no
floor evidence: it is decoded in the air, so no support is invented for it.
"""

from __future__ import annotations

import numpy as np

from .labels import foot_points

__all__ = [
    "AIR_HEIGHT_SCALE_M",
    "AIR_SPEED_SD_MS",
    "FLOOR_SPEED_SD_MS",
    "MAX_FLOOR_OFFSET_M",
    "MAX_HEIGHT_SD_M",
    "MEAN_FLIGHT_S",
    "MEAN_STANCE_S",
    "MIN_HEIGHT_SD_M",
    "decode_contacts",
]

#: Metres: least standard deviation of a grounded foot's height (the body
#: model's foot points against a real sole, and the floor fit's own scatter).
MIN_HEIGHT_SD_M = 0.015
#: Metres: the scale of a free foot's height above the floor (a step lifts
#: the foot 5-15 cm, a gesture higher).
AIR_HEIGHT_SCALE_M = 0.1
#: m/s: scale of a grounded foot's speed (smoothed positions: a pivot or a
#: slide moves it a few cm/s, fitted feet slide by up to 10 cm/s, and the
#: smoothing window spreads a hop's touch-down over 0.2-0.5 m/s).
FLOOR_SPEED_SD_MS = 0.25
#: m/s: scale of a free foot's speed (a step swings the foot at 1-3 m/s).
AIR_SPEED_SD_MS = 1.0
#: Seconds: mean duration of a foot's stance (a step a beat at 60-180 bpm
#: holds each foot 0.3-1 s; a standing foot much longer).
MEAN_STANCE_S = 0.8
#: Seconds: mean duration of a foot's flight in a step (0.2-0.5 s).
MEAN_FLIGHT_S = 0.3
#: Metres: largest standard deviation of a grounded foot's height believed.
#: A clip whose lowest foot heights scatter more than this about the floor
#: does not stand on that floor (a floor guessed 10 cm low, a figure lying
#: down): its feet are read in the air rather than the floor stretched to
#: reach them.
MAX_HEIGHT_SD_M = 0.04
#: Metres: largest level of a grounded foot's points above (or below) the
#: floor believed.  BlazePose's ankle and toe points on a flat foot sit 1-3 cm
#: above the fitted sole; a foot that hovers higher is gesturing.
MAX_FLOOR_OFFSET_M = 0.03
#: Quantile of the clip's foot heights whose spread about the floor
#: starts ``σ_h`` (the lower half: grounded frames dominate it).
_SPREAD_QUANTILE = 0.25
#: Rounds of decoding and re-estimating each foot's grounded level and scatter.
_ROUNDS = 3


def _log_half_normal(x: np.ndarray, sd: float) -> np.ndarray:
    return np.log(np.sqrt(2.0 / np.pi) / sd) - 0.5 * (x / sd) ** 2


def _viterbi(loglik: np.ndarray, logA: np.ndarray, log0: np.ndarray) -> np.ndarray:
    """Most likely state path, ``loglik (T, S)``, ``logA (S, S)`` from → to."""
    T, S = loglik.shape
    back = np.zeros((T, S), int)
    score = log0 + loglik[0]
    for t in range(1, T):
        cand = score[:, None] + logA
        back[t] = np.argmax(cand, axis=0)
        score = cand[back[t], np.arange(S)] + loglik[t]
    path = np.zeros(T, int)
    path[-1] = int(np.argmax(score))
    for t in range(T - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path


def _foot_terms(h: np.ndarray, v: np.ndarray, ok: np.ndarray, level: float, sd_h: float):
    """Per-frame log-likelihoods ``(air, floor)`` of one foot, ``(T,)`` each."""
    hh = np.where(ok, h, 0.0)
    vv = np.where(ok, v, 0.0)
    ll_floor = (
        -0.5 * ((hh - level) / sd_h) ** 2 - np.log(sd_h * np.sqrt(2 * np.pi)) + _log_half_normal(vv, FLOOR_SPEED_SD_MS)
    )
    ll_air = (
        -np.maximum(hh, 0.0) / AIR_HEIGHT_SCALE_M - np.log(AIR_HEIGHT_SCALE_M) + _log_half_normal(vv, AIR_SPEED_SD_MS)
    )
    # An unseen foot gives no evidence of the floor: it stays in the air.
    return np.where(ok, ll_air, 0.0), np.where(ok, ll_floor, -np.inf)


def _floor_fit(h: np.ndarray, grounded: np.ndarray) -> tuple[float, float]:
    """A foot's grounded level and scatter, metres, from its grounded heights `h`."""
    if grounded.sum() < 2:
        return 0.0, MIN_HEIGHT_SD_M
    g = h[grounded]
    level = float(np.clip(np.median(g), -MAX_FLOOR_OFFSET_M, MAX_FLOOR_OFFSET_M))
    sd = float(np.sqrt(np.mean((g - level) ** 2)))
    return level, float(np.clip(sd, MIN_HEIGHT_SD_M, MAX_HEIGHT_SD_M))


def decode_contacts(joints: np.ndarray, fps: float, floor: float = 0.0, seen: np.ndarray | None = None) -> np.ndarray:
    """Feet on the floor at every frame, by Viterbi over the clip.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up (smoothed measured motion).
    fps : float
        Frames per second.
    floor : float
        Floor height, metres.
    seen : (T, 2) ndarray of bool, optional
        Right, left foot seen by the capture (default: wherever finite).

    Returns
    -------
    (T, 2) ndarray of bool
        Right, left foot on the floor.
    """
    joints = np.asarray(joints, float)
    T = joints.shape[0]
    # After the clip the body holds its last pose (DESIGN.md: a part with no
    # symbol holds its position), as the per-frame rule assumes by taking
    # the last frame as still.  Without those held frames a foot landing on
    # the clip's last frames never pays the cost of entering a stance.
    hold = max(1, int(round(MEAN_FLIGHT_S * fps)))
    joints = np.concatenate([joints, np.repeat(joints[-1:], hold, axis=0)]) if T else joints
    if seen is not None:
        seen = np.asarray(seen, bool)
        seen = np.concatenate([seen, np.repeat(seen[-1:], hold, axis=0)]) if T else seen
    n = joints.shape[0]
    lows, mids = foot_points(joints)
    out = np.zeros((n, 2), bool)
    stay_floor = 1.0 - 1.0 / max(2.0, MEAN_STANCE_S * fps)
    stay_air = 1.0 - 1.0 / max(2.0, MEAN_FLIGHT_S * fps)
    logA = np.log(np.array([[stay_air, 1 - stay_air], [1 - stay_floor, stay_floor]]))
    log0 = np.log(np.array([0.5, 0.5]))
    for k in range(2):
        h = np.asarray(lows[k], float) - floor
        mid = np.asarray(mids[k], float)
        v = np.zeros(n)
        if n > 1:
            step = np.linalg.norm(np.diff(mid, axis=0), axis=-1) * fps
            v[1:-1] = 0.5 * (step[:-1] + step[1:])
            v[0], v[-1] = step[0], step[-1]
        ok = np.isfinite(h) & np.isfinite(v)
        if seen is not None:
            ok &= seen[:, k]
        if not ok.any():
            continue
        # The first guess: level 0, the scatter of the lowest quarter about the floor.
        low_h = h[ok][h[ok] <= np.quantile(h[ok], _SPREAD_QUANTILE)]
        level, sd_h = 0.0, float(np.clip(np.sqrt(np.mean(low_h**2)), MIN_HEIGHT_SD_M, MAX_HEIGHT_SD_M))
        for _ in range(_ROUNDS):
            path = _viterbi(np.column_stack(_foot_terms(h, v, ok, level, sd_h)), logA, log0) == 1
            level, sd_h = _floor_fit(h, path & ok)
        out[:, k] = path
    return out[:T]
