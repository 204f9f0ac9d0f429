"""Which way the body faces the camera, over a whole clip, from the image alone.

A single camera's depth is where a pose model errs most: BlazePose's world
landmarks of a turning dancer put the hips' depth order wrong for many
frames, and a 3D fit that follows them turns its hips the wrong way or
half way back.  Two image cues say which way the body faces without any
depth (the yaw θ, 0 facing the camera, +90° facing the image's right):

* **the feet**: toes lie ahead of heels, so the feet's mean toe-minus-heel
  image offset along x is ∝ sin θ (its sign is right on 99 % of frames more
  than 30° from facing or backing the camera, BlazePose on turning renders);
* **the shoulders and hips**: their left-minus-right image offset along x is
  ∝ cos θ (labels as corrected by :mod:`.identity`).

:func:`decode_yaw` decodes θ over the clip by Viterbi on a grid of yaw
(:data:`YAW_STEP_DEG`) × yaw rate (up to :data:`MAX_RATE_DEG_S`): the rate
changes smoothly (:data:`RATE_CHANGE_SD_DEG_S2`), so a pirouette keeps
turning through its side views, where the cues alone would let it turn
back.  Each cue is Gaussian about its expected value with a share of
outliers (:data:`CUE_OUTLIER_RATE`), in units of its value side-on or
facing the camera (:data:`FEET_SIDE_ON`, :data:`WIDTH_FACING`).
"""

from __future__ import annotations

import warnings

import numpy as np

from .identity import torso_and_order
from .track import KeypointTrack

__all__ = [
    "CUE_OUTLIER_RATE",
    "CUE_SD",
    "DECODE_FPS",
    "FEET_SIDE_ON",
    "MAX_RATE_DEG_S",
    "MIN_FEET_SEEN",
    "RATE_CHANGE_SD_DEG_S2",
    "WIDTH_FACING",
    "YAW_STEP_DEG",
    "decode_yaw",
]

#: Resolution of the yaw grid, degrees (an eighth of a turn is 9 steps).
YAW_STEP_DEG = 5.0
#: Fastest yaw rate searched, degrees per second: 2.8 turns a second, above
#: a quick pirouette's two (40° a frame at 25 fps).
MAX_RATE_DEG_S = 1000.0
#: Spread of the yaw rate's change, degrees per second squared: a
#: pirouette reaches its speed within about a fifth of a second (4° a frame
#: per frame at 25 fps; 2 and 8 measured worse on development renders).
RATE_CHANGE_SD_DEG_S2 = 2500.0
#: Frame rate the decoder runs at: faster clips are decoded on every n-th
#: frame (the grid's rate step is one yaw step a frame) and interpolated.
DECODE_FPS = 25.0
#: Spread of each cue about its expected value, in units of its full value.
CUE_SD = 0.35
#: Share of frames whose cue is unrelated to the yaw (a foot lifted and
#: pointed, a swapped label the identity decoder missed).
CUE_OUTLIER_RATE = 0.05
#: Share of the frames with a person that must show the feet: with fewer the
#: yaw's side (left or right of the camera) is unknown and none is decoded.
MIN_FEET_SEEN = 0.5
#: The feet cue of a body side-on to the camera, and the width cue of one
#: facing it, torso lengths (shoulders' middle to hips' middle): BlazePose's
#: heel-to-toe landmarks span 0.41 torso lengths side-on and its shoulders
#: and hips 0.55 facing the camera (medians, development renders; the
#: renderer's own landmarks 0.53 and 0.59).  Body proportions, not fitted
#: per clip: a dancer who never turns side-on has no side-on feet to scale by.
FEET_SIDE_ON = 0.41
WIDTH_FACING = 0.55

_HEELS, _TOES = (29, 30), (31, 32)


def _cues(track: KeypointTrack) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-frame feet (∝ sin θ) and width (∝ cos θ) cues in units of their full values, and the frames seen."""
    xy = np.asarray(track.xy, float)[:, :, :2]
    torso, seen, width = torso_and_order(xy)
    with warnings.catch_warnings():
        # Frames without feet average nothing (NaN): they carry no cue.
        warnings.simplefilter("ignore", RuntimeWarning)
        feet = np.nanmean(xy[:, list(_TOES), 0] - xy[:, list(_HEELS), 0], axis=1) / torso
    return feet / FEET_SIDE_ON, width / WIDTH_FACING, seen


def _log_cue(obs: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """(T, N) log-likelihood of each frame's cue for each yaw (0 where the cue is missing)."""
    r = (obs[:, None] - expected[None]) / CUE_SD
    ll = np.log((1.0 - CUE_OUTLIER_RATE) * np.exp(-0.5 * r**2) + CUE_OUTLIER_RATE)
    return np.where(np.isfinite(obs)[:, None], ll, 0.0)


def _viterbi(emit: np.ndarray, rates: np.ndarray, rate_change: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Best (yaw index, rate index) per frame of the yaw × rate chain.

    Parameters
    ----------
    emit : (T, N) ndarray
        Log-likelihood of each yaw bin.
    rates : (M,) int ndarray
        Yaw change per frame of each rate state, in yaw bins.
    rate_change : (2K+1,) ndarray
        Log-probability of the rate changing by -K..K rate states between frames.
    """
    T, N = emit.shape
    M, K = rates.size, (rate_change.size - 1) // 2
    n_idx = (np.arange(N)[:, None] - rates[None, :]) % N  # the yaw a state came from
    m_idx = np.arange(M)[None, :]
    delta = np.repeat(emit[0][:, None], M, axis=1)
    back_rate = np.zeros((T, N, M), np.int8)
    for t in range(1, T):
        best = np.full((N, M), -np.inf)
        arg = np.zeros((N, M), np.int8)
        for i, j in enumerate(range(-K, K + 1)):
            src = np.full((N, M), -np.inf)
            lo, hi = max(0, -j), min(M, M - j)
            src[:, lo:hi] = delta[:, lo + j : hi + j] + rate_change[i]
            better = src > best
            best = np.where(better, src, best)
            arg = np.where(better, i, arg)
        # A state (n, m) at t came from yaw n − rate(m) at t − 1.
        delta = best[n_idx, m_idx] + emit[t][:, None]
        back_rate[t] = arg[n_idx, m_idx]
    yaw, rate = np.zeros(T, int), np.zeros(T, int)
    yaw[-1], rate[-1] = np.unravel_index(int(np.argmax(delta)), delta.shape)
    for t in range(T - 1, 0, -1):
        yaw[t - 1] = (yaw[t] - rates[rate[t]]) % N
        rate[t - 1] = rate[t] + int(back_rate[t, yaw[t], rate[t]]) - K
    return yaw, rate


def decode_yaw(track: KeypointTrack) -> np.ndarray:
    """The body's yaw towards the camera in every frame, unwrapped over the clip.

    Parameters
    ----------
    track : KeypointTrack
        A track with left and right already decided
        (:func:`~.identity.correct_identity`; ``extract`` does it).

    Returns
    -------
    (T,) ndarray
        Degrees: 0 facing the camera, +90 facing the image's right, 180 the
        back to the camera; continuous through turns (two turns to the image's
        right end 720° above their start).  NaN in frames without a person,
        and everywhere when the feet are seen in fewer than
        :data:`MIN_FEET_SEEN` of them (a track without feet landmarks).
    """
    T = len(track)
    if T == 0:
        return np.zeros(0)
    feet, width, seen = _cues(track)
    if not seen.any() or np.isfinite(feet[seen]).mean() < MIN_FEET_SEEN:
        return np.full(T, np.nan)
    stride = max(1, int(round(float(track.fps) / DECODE_FPS)))
    keep = np.arange(0, T, stride)
    fps = float(track.fps) / stride
    grid = np.arange(0.0, 360.0, YAW_STEP_DEG)
    s, c = np.sin(np.radians(grid)), np.cos(np.radians(grid))
    emit = _log_cue(feet[keep], s) + _log_cue(width[keep], c)
    k_max = max(1, int(round(MAX_RATE_DEG_S / fps / YAW_STEP_DEG)))
    rates = np.arange(-k_max, k_max + 1)
    sd = RATE_CHANGE_SD_DEG_S2 / fps**2 / YAW_STEP_DEG  # rate states a frame
    K = max(1, int(np.ceil(2.0 * sd)))
    change = -0.5 * (np.arange(-K, K + 1) / max(sd, 1e-9)) ** 2
    change -= np.log(np.exp(change).sum())
    yaw_i, rate_i = _viterbi(emit, rates, change)
    unwrapped = grid[yaw_i[0]] + np.r_[0.0, np.cumsum(rates[rate_i[1:]] * YAW_STEP_DEG)]
    out = np.interp(np.arange(T), keep, unwrapped)
    return np.where(seen, out, np.nan)
