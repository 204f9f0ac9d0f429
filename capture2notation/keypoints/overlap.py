"""A left/right pair drawn on top of itself takes its order from its neighbours.

Where the pose model loses a pair (the shoulders of a back view read as
side-on, feet together, a knee behind the other), it draws the pair's two
points within a few pixels of each other, and which of them carries the
left label is then noise: the points drift across each other while the
body's own left and right stay where they were.  The whole-body decoders
(:mod:`.identity`, :func:`~.yaw.correct_mirrored`) take the body's left
and right from all pairs together and so cannot see one such pair.

Such a pair's order carries no information of its own, so
:func:`correct_overlapping` gives it the image order of the nearest pair
in the body drawn apart (the shoulders' from the hips' and elbows', a
knee's from the hips' and ankles', an ankle's from the knees'): where the
nearest well-drawn pair has its left point on one side of its right, the
overlapping pair is labelled the same way round.  An arm or a leg crossing
the body's midline breaks that order, but only where the pair really
overlaps in the image, which is exactly where either labelling lies within
the noise.  Side-on to the camera the near and far limbs overlap in the
image as a matter of course and their order is not their neighbours', so
there nothing is changed (:mod:`.near_side` reads them there).
"""

from __future__ import annotations

import numpy as np

from ..errors import KeypointError
from .identity import mirror_frames
from .near_side import SIDE_ON_SIN
from .track import KeypointTrack

__all__ = ["OVERLAP_TORSO", "correct_overlapping", "overlapping"]

#: A pair whose two points lie closer than this in the image (torso
#: lengths, shoulders' to hips' midpoint) is overlapping.  BlazePose's
#: landmark error is about 0.07 torso lengths at the median (front-view
#: development renders, each point against the nearer of its own and its
#: twin's truth), so the vector between a pair's points carries about
#: √2 × 0.07 = 0.1 of noise; a pair closer than twice that cannot be told
#: apart.
OVERLAP_TORSO = 0.2

#: (left, right) landmark pairs (BlazePose order) that are judged, each with
#: the landmarks exchanged along with it (a hand's and a foot's small points
#: follow the wrist and the ankle).
_PAIRS: dict[str, tuple[tuple[int, int], ...]] = {
    "shoulders": ((11, 12),),
    "elbows": ((13, 14),),
    "wrists": ((15, 16), (17, 18), (19, 20), (21, 22)),
    "hips": ((23, 24),),
    "knees": ((25, 26),),
    "ankles": ((27, 28), (29, 30), (31, 32)),
}
#: Each pair's neighbours, nearest first (breadth first through the body:
#: the torso's pairs before the limbs').
_NEAREST: dict[str, tuple[str, ...]] = {
    "shoulders": ("hips", "elbows", "knees", "wrists", "ankles"),
    "elbows": ("shoulders", "wrists", "hips", "knees", "ankles"),
    "wrists": ("elbows", "shoulders", "hips", "knees", "ankles"),
    "hips": ("shoulders", "knees", "elbows", "ankles", "wrists"),
    "knees": ("hips", "ankles", "shoulders", "elbows", "wrists"),
    "ankles": ("knees", "hips", "shoulders", "elbows", "wrists"),
}


def _torso_px(xy: np.ndarray) -> float:
    """The clip's median torso length, pixels (midpoints: unaffected by the labels)."""
    shoulders = 0.5 * (xy[:, 11, :2] + xy[:, 12, :2])
    hips = 0.5 * (xy[:, 23, :2] + xy[:, 24, :2])
    length = np.linalg.norm(shoulders - hips, axis=1)
    return float(np.nanmedian(length)) if np.isfinite(length).any() else float("nan")


def overlapping(track: KeypointTrack, yaw) -> dict[str, np.ndarray]:
    """For each pair, the frames where it overlaps and is drawn the other way round from its nearest neighbour apart.

    Parameters
    ----------
    track : KeypointTrack
        A BlazePose track with the body's left and right decided.
    yaw : (T,) array_like
        Degrees, 0 facing the camera, +90 facing the image's right
        (:func:`~.yaw.decode_yaw`); side-on frames (``|sin yaw| ≥``
        :data:`~.near_side.SIDE_ON_SIN`) and frames of unknown yaw (NaN)
        are left alone.

    Returns
    -------
    dict of str to (T,) bool ndarray
        Pair name (``"shoulders"``, ``"elbows"``, ``"wrists"``, ``"hips"``,
        ``"knees"``, ``"ankles"``) → frames to exchange its labels in.
    """
    yaw = np.asarray(yaw, float)
    T = len(track)
    if yaw.shape != (T,):
        raise KeypointError(f"yaw must have one value per frame ({T}), got shape {yaw.shape}")
    xy = np.asarray(track.xy, float)
    if T == 0:
        return {name: np.zeros(0, bool) for name in _PAIRS}
    # NaN yaw compares False: unknown counts as side-on.
    judged = np.abs(np.sin(np.radians(yaw))) < SIDE_ON_SIN
    gap = {name: xy[:, pairs[0][1], :2] - xy[:, pairs[0][0], :2] for name, pairs in _PAIRS.items()}
    with np.errstate(invalid="ignore"):
        apart_px = OVERLAP_TORSO * _torso_px(xy)
        length = {name: np.linalg.norm(g, axis=1) for name, g in gap.items()}
        # A NaN point is neither overlapping nor apart.
        apart = {name: d >= apart_px for name, d in length.items()}
        out = {}
        for name in _PAIRS:
            todo = judged & (length[name] < apart_px)
            exchange = np.zeros(T, bool)
            for other in _NEAREST[name]:
                here = todo & apart[other]
                exchange |= here & (np.einsum("ij,ij->i", gap[name], gap[other]) < 0)
                todo &= ~here
            out[name] = exchange
    return out


def correct_overlapping(track: KeypointTrack, yaw) -> tuple[KeypointTrack, dict[str, np.ndarray]]:
    """The track with each overlapping pair labelled the same way round as its nearest pair apart.

    A relabelled pair takes its twin's landmarks (image, visibility and
    world; depth reflected: :func:`~.identity.mirror_frames` for that pair
    alone); ``identity_confidence`` is unchanged (it is the body's).

    Parameters
    ----------
    track, yaw
        As for :func:`overlapping`.

    Returns
    -------
    (KeypointTrack, dict)
        The relabelled track (the input is not modified) and the frames
        relabelled, per pair (:func:`overlapping`).
    """
    frames = overlapping(track, yaw)
    fixed = track
    for name, exchange in frames.items():
        if exchange.any():
            fixed = mirror_frames(fixed, exchange, np.asarray(fixed.identity_confidence, float), pairs=_PAIRS[name])
    return fixed, frames
