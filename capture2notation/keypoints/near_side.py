"""Left and right arm and leg from which side of the body is near the camera.

Side-on to the camera, one arm and one leg are near it and the others far,
half hidden behind the body.  The pose model often draws the near limb
under the far limb's label (and the far under the near's) while the body
itself is labelled right: a swap of one limb, which the whole-body
decoders (:mod:`.identity`, :func:`~.yaw.correct_mirrored`) cannot see, as
the torso's order is right.  Two things tell which limb is which without
the labels:

* **the yaw** decoded from the image (:mod:`.yaw`) says which side is near:
  facing the image's right (yaw +90°) the right side is;
* **the pose model's visibility** follows where a landmark is drawn, not
  its label: the near limb's landmarks are more visible than the far
  limb's (side-on, BlazePose's near elbow and wrist by 0.26–0.31 at the
  median on development renders, with the labels right or swapped alike;
  its depth, by contrast, follows the label and cannot tell).

:func:`decode_near_side` runs, for the arms (shoulder to hand) and for the
legs (knee to toe) separately, a two-state chain (this limb pair's labels
exchanged or not; swaps start rarely and last a few seconds) whose evidence
is the left-minus-right visibility against what the yaw expects side-on.
:func:`correct_near_side` exchanges the labels where a swap is more likely
than not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import KeypointError
from .identity import CUE_CORRELATION_S, mirror_frames
from .track import KeypointTrack

__all__ = [
    "LIMB_SWAP_EVERY_S",
    "LIMB_SWAP_MEAN_S",
    "NEAR_VISIBILITY",
    "SIDE_ON_SIN",
    "VISIBILITY_SD",
    "NearSide",
    "correct_near_side",
    "decode_near_side",
]

#: Left/right landmark pairs (BlazePose order) of each limb group, exchanged
#: together; the first ones are the landmarks whose visibility is the cue
#: (the hands' and feet's small points follow their wrist and ankle).
_GROUPS: dict[str, tuple[tuple[tuple[int, int], ...], int]] = {
    "arms": (((11, 12), (13, 14), (15, 16), (17, 18), (19, 20), (21, 22)), 3),
    "legs": (((25, 26), (27, 28), (29, 30), (31, 32)), 2),
}
#: How much more visible the near limb's landmarks are than the far limb's,
#: side-on (visibility, 0–1; development renders: 0.31 elbows, 0.26 wrists,
#: 0.15 knees, 0.10 ankles at the median), and the spread of one frame's
#: left-minus-right difference about it.
NEAR_VISIBILITY = 0.25
VISIBILITY_SD = 0.35
#: |sin yaw| from which the body counts as side-on (within ~32° of it): the
#: contrast falls from 0.25 at 60–90° from facing the camera to 0.05 at
#: 30–60° (development renders), so the cue grows from nothing here to its
#: full value side-on.
SIDE_ON_SIN = 0.85
#: A limb pair's labels exchange about once per this many seconds, and stay
#: exchanged this long on average (BlazePose, side-on development renders).
LIMB_SWAP_EVERY_S = 8.0
LIMB_SWAP_MEAN_S = 2.0


@dataclass(frozen=True)
class NearSide:
    """What :func:`decode_near_side` read of a clip.

    Attributes
    ----------
    swapped : dict of str to (T,) ndarray
        For ``"arms"`` and ``"legs"``: the posterior probability, per frame,
        that the pair's left and right labels are exchanged in the track.
    """

    swapped: dict


def _side_on(yaw: np.ndarray) -> np.ndarray:
    """(T,) how side-on the body is, signed: +1 the right side near the camera, −1 the left, 0 facing or backing it."""
    s = np.sin(np.radians(np.asarray(yaw, float)))
    amount = np.clip((np.abs(s) - SIDE_ON_SIN) / (1.0 - SIDE_ON_SIN), 0.0, 1.0)
    return np.nan_to_num(np.sign(s) * amount)


def _posterior(loglik: np.ndarray, fps: float) -> np.ndarray:
    """(T,) P(exchanged) of a sticky two-state chain with per-frame log-likelihoods (T, 2)."""
    start = 1.0 / max(1.0, LIMB_SWAP_EVERY_S * fps)
    end = 1.0 / max(1.0, LIMB_SWAP_MEAN_S * fps)
    A = np.array([[1.0 - start, start], [end, 1.0 - end]])
    e = np.exp(loglik - loglik.max(axis=1, keepdims=True))
    T = len(e)
    alpha = np.empty((T, 2))
    a = np.array([end, start]) / (start + end) * e[0]  # the stationary share
    alpha[0] = a / a.sum()
    for t in range(1, T):
        a = (alpha[t - 1] @ A) * e[t]
        alpha[t] = a / a.sum()
    out = np.empty(T)
    b = np.ones(2)
    for t in range(T - 1, -1, -1):
        p = alpha[t] * b
        out[t] = p[1] / p.sum()
        b = A @ (e[t] * b)
        b /= b.sum()
    return out


def decode_near_side(track: KeypointTrack, yaw) -> NearSide:
    """For the arms and the legs, the probability that their left/right labels are exchanged.

    Parameters
    ----------
    track : KeypointTrack
        A BlazePose track with the body's left and right decided
        (:func:`~.yaw.correct_mirrored`).
    yaw : (T,) array_like
        Degrees, 0 facing the camera, +90 facing the image's right
        (:func:`~.yaw.decode_yaw`); NaN where unknown (no evidence there).
    """
    yaw = np.asarray(yaw, float)
    T = len(track)
    if yaw.shape != (T,):
        raise KeypointError(f"yaw must have one value per frame ({T}), got shape {yaw.shape}")
    if T == 0:
        return NearSide({name: np.zeros(0) for name in _GROUPS})
    fps = float(track.fps)
    weight = min(1.0, 1.0 / (fps * CUE_CORRELATION_S))
    # Labels right: the right limb is the more visible where the right side is near.
    expected = NEAR_VISIBILITY * -_side_on(yaw)
    vis = np.nan_to_num(np.asarray(track.visibility, float))
    out = {}
    for name, (pairs, n_cue) in _GROUPS.items():
        d = np.mean([vis[:, left] - vis[:, right] for left, right in pairs[:n_cue]], axis=0)
        loglik = -0.5 * weight * np.stack([(d - expected) ** 2, (d + expected) ** 2], axis=1) / VISIBILITY_SD**2
        out[name] = _posterior(loglik, fps)
    return NearSide(out)


def correct_near_side(track: KeypointTrack, yaw) -> tuple[KeypointTrack, NearSide]:
    """The track with each limb pair relabelled where its labels are more likely exchanged than not.

    A relabelled limb takes its twin's landmarks (image, visibility and
    world; depth reflected: :func:`~.identity.mirror_frames` for that pair
    alone), and its frame's ``identity_confidence`` becomes at most the
    chain's probability of the exchange.

    Parameters
    ----------
    track, yaw
        As for :func:`decode_near_side`.

    Returns
    -------
    (KeypointTrack, NearSide)
        The relabelled track (the input is not modified) and the decoding.
    """
    decoding = decode_near_side(track, yaw)
    fixed = track
    for name, (pairs, _) in _GROUPS.items():
        p = decoding.swapped[name]
        swap = p > 0.5
        if swap.any():
            conf = np.asarray(fixed.identity_confidence, float)
            fixed = mirror_frames(fixed, swap, np.where(swap, np.fmin(conf, p), conf), pairs=pairs)
    return fixed, decoding
