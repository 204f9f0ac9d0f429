"""Which feet carry the weight, at which level, and where a step goes: the per-frame reading.

Per frame (DESIGN.md): a foot is *in contact* when it is within 3 cm of the
floor and slower than 0.2 m/s (:func:`~.labels.support_frames`; measured
motion: :func:`~.contact.decode_contacts`).  Of the feet in contact, those
that carry the weight are found from the pelvis: with both feet down, a
pelvis over one foot (within a quarter of the way to the other) puts the
weight on that foot alone, otherwise on both.  The support *part* is
``support`` (both), ``right_support`` or ``left_support``; its level is that
of the weight-bearing feet (low: knee bent > 30°, high: heel raised; the
lower of two unequal levels).  A support's direction is ``place`` unless a
weight-bearing foot travelled more than half a step (0.09 body heights) from
under its hip: then the sector of that travel in the body frame (a step,
:func:`step_direction`).  Shared by the clean (:mod:`.supports`) and the
measured (:mod:`.supports_measured`) support segmentation, and by flights.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from ..body import joint_index
from ..notation.directions import classify_indices
from .labels import DIRECTION_NAMES, FrameLabels, foot_points

__all__ = [
    "NOISY_POSITION_M",
    "OVER_FOOT_FRACTION",
    "STEP_MIN_FRACTION",
    "STEP_PELVIS_FOLLOWS",
    "SUPPORT_PARTS",
    "body_height",
    "closing_place",
    "fraction_along",
    "mode_filter",
    "plausible_step",
    "position_noise",
    "smooth_positions",
    "standing_foot_offset",
    "step_direction",
    "support_speed",
    "support_state",
    "weight_bearing",
]


#: A weight-bearing foot that moved farther than this fraction of the body
#: height from under its hip makes the support a step.
STEP_MIN_FRACTION = 0.09


SUPPORT_PARTS = ("support", "right_support", "left_support")


#: Fraction of the way from one foot to the other within which the pelvis
#: is over the nearer foot (:func:`weight_bearing`).
OVER_FOOT_FRACTION = 0.25


def fraction_along(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """How far point `p` lies along the way from `a` to `b` (0 at `a`, 1 at `b`), by projection.

    Arrays ``(..., 2)`` (horizontal positions); NaN where `a` and `b` coincide.
    """
    d = b - a
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sum((p - a) * d, axis=-1) / np.sum(d * d, axis=-1)


def weight_bearing(joints: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """Feet that carry the weight.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
    contact : (T, 2) ndarray of bool
        Right, left foot in contact with the floor.

    Returns
    -------
    (T, 2) ndarray of bool
    """
    _, (fr, fl) = foot_points(joints)
    u = fraction_along(joints[:, joint_index("pelvis"), :2], fr[:, :2], fl[:, :2])
    both = contact.all(axis=1)
    wb = contact.copy()
    # Only when both feet are down does the pelvis decide between them.
    wb[:, 1] &= ~(both & (u < OVER_FOOT_FRACTION))
    wb[:, 0] &= ~(both & (u > 1.0 - OVER_FOOT_FRACTION))
    return wb


def support_state(labels: FrameLabels, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Support part and level at every frame.

    Returns
    -------
    part : (T,) ndarray of int
        Index into ``("support", "right_support", "left_support")``; −1 in
        the air (no foot in contact).
    level : (T,) ndarray of int
        Index into ``LEVELS``; −1 in the air.
    """
    wb = weight_bearing(joints, labels.supporting)
    lev = labels.support_level
    part = np.where(wb[:, 0] & wb[:, 1], 0, np.where(wb[:, 0], 1, np.where(wb[:, 1], 2, -1)))
    # Lower of the two levels (low > middle > high in index order).
    both_level = np.maximum(lev[:, 0], lev[:, 1])
    level = np.where(part == 0, both_level, np.where(part == 1, lev[:, 0], np.where(part == 2, lev[:, 1], -1)))
    return part, level


def support_speed(labels: FrameLabels, joints: np.ndarray, fps: float) -> np.ndarray:
    """Speed of the supporting system over each frame interval, degrees per second."""
    leg = np.nanmedian(
        np.linalg.norm(joints[:, joint_index("right_hip")] - joints[:, joint_index("right_ankle")], axis=-1)
    )
    pelvis = joints[:, joint_index("pelvis")] / max(float(leg), 1e-6)
    sig = [np.degrees(pelvis)]
    # Only the feet that carry the weight: a foot still on the floor as its
    # leg starts a gesture (or after the weight has left it) moves with the
    # free leg, not with the supporting system.
    bearing = weight_bearing(joints, labels.supporting)
    for k, side in enumerate(("right", "left")):
        # The hip-ankle distance, not the knee angle: the angle of a knee
        # straightening grows like the square root of the leg's shortening,
        # so its speed is unbounded at the start and end of every transfer
        # or rise and would hide the arrivals (and make false minima).
        reach = np.degrees(
            np.linalg.norm(joints[:, joint_index(f"{side}_hip")] - joints[:, joint_index(f"{side}_ankle")], axis=-1)
            / max(float(leg), 1e-6)
        )
        d = joints[:, joint_index(f"{side}_toe")] - joints[:, joint_index(f"{side}_ankle")]
        pitch = np.degrees(np.arctan2(-d[:, 2], np.hypot(d[:, 0], d[:, 1])))
        c = bearing[:, k]
        # Only over intervals the foot supports at both ends: a foot that
        # lands or lifts is no jump of the supporting system.
        both = c[1:] & c[:-1]
        sig.append(np.where(both[:, None], np.diff(np.stack([reach, pitch], axis=1), axis=0), 0.0))
    x = np.concatenate([np.diff(sig[0], axis=0)] + sig[1:], axis=1)
    return np.linalg.norm(x, axis=1) * fps


def smooth_positions(joints: np.ndarray, fps: float, window_s: float = 0.3) -> np.ndarray:
    """Savitzky–Golay smoothed joints (quadratic over `window_s`), for feet contacts of noisy motion.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        Metres; NaN where missing.
    fps : float
    window_s : float
        Window, seconds (at least 5 frames).

    Returns
    -------
    (T, J, 3) ndarray
        Smoothed; missing samples stay NaN (interpolated only to smooth
        their neighbours), and the input when it is shorter than the window.
    """
    joints = np.asarray(joints, dtype=float)
    T = joints.shape[0]
    w = max(5, int(round(window_s * fps)) | 1)
    if w >= T:
        return joints
    flat = joints.reshape(T, -1)
    bad = ~np.isfinite(flat)
    filled = flat.copy()
    if bad.any():
        idx = np.arange(T)
        for c in np.flatnonzero(bad.any(axis=0)):
            ok = ~bad[:, c]
            filled[:, c] = np.interp(idx, idx[ok], flat[ok, c]) if ok.any() else 0.0
    out = savgol_filter(filled, w, 2, axis=0)
    out[bad] = np.nan
    return out.reshape(joints.shape)


#: Jitter of the pelvis and feet (metres) above which motion counts as noisy.
NOISY_POSITION_M = 1e-3


def position_noise(joints: np.ndarray) -> float:
    """Jitter of the pelvis and feet, metres (lower quartile of the local-cubic residual; 0 when clean)."""
    idx = [joint_index(n) for n in ("pelvis", "right_ankle", "left_ankle")]
    p = joints[:, idx].reshape(joints.shape[0], -1)
    ok = np.isfinite(p).all(axis=1)
    if ok.sum() < 7:
        return 0.0
    r = np.abs(p[ok] - savgol_filter(p[ok], 5, 3, axis=0))
    return float(np.percentile(r, 25) / 0.23)


def mode_filter(x: np.ndarray, width: int) -> np.ndarray:
    """Most frequent value in a centred window of `width` frames (ties: the current value)."""
    if width < 3:
        return x
    h = width // 2
    pad = np.r_[np.full(h, x[0]), x, np.full(h, x[-1])]
    win = np.lib.stride_tricks.sliding_window_view(pad, width)
    vals = np.unique(x)
    counts = np.stack([(win == v).sum(axis=1) for v in vals], axis=1)
    best = vals[np.argmax(counts, axis=1)]
    keep = counts[np.arange(len(x)), np.searchsorted(vals, x)] == counts.max(axis=1)
    return np.where(keep, x, best)


def body_height(joints: np.ndarray) -> float:
    """Body height from the leg length (hip → ankle is 0.491 of the height at rest)."""
    leg = np.nanmedian(
        np.linalg.norm(joints[:, joint_index("right_hip")] - joints[:, joint_index("right_knee")], axis=-1)
        + np.linalg.norm(joints[:, joint_index("right_knee")] - joints[:, joint_index("right_ankle")], axis=-1)
    )
    return float(leg) / (0.530 - 0.039)


def standing_foot_offset(joints: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """(2, 3) horizontal offset of each ankle from its hip while both feet stand, metres (median).

    Standing, each foot is under its hip (DESIGN.md), so this is 0 for the
    dancer; a single-view fit places the feet several centimetres off in
    depth (10 cm behind the hips in a front view), which shortened a
    30 cm step forward under the half-step threshold.  Zero where no frame
    stands on both feet.
    """
    out = np.zeros((2, 3))
    both = np.asarray(contact, bool).all(axis=1)
    if both.sum() < 5:
        return out
    for f, side in enumerate(("right", "left")):
        d = joints[both, joint_index(f"{side}_ankle")] - joints[both, joint_index(f"{side}_hip")]
        out[f, :2] = np.nanmedian(d[:, :2], axis=0)
    return np.where(np.isfinite(out), out, 0.0)


#: Measured step: the pelvis follows the stepping foot by at least this
#: fraction of the foot's travel (the weight goes where the foot went).
STEP_PELVIS_FOLLOWS = 0.3


def plausible_step(joints: np.ndarray, f: int, a: int, k: int, height: float) -> bool:
    """Whether foot `f` (0 right, 1 left) stepped between frames a and k of measured motion.

    A fitted supporting foot that flickers off the floor while the pelvis
    pushes away from it looks, against its hip, like a step the other way
    (``right_support right`` during a step to the left).  A step moves the
    foot itself at least half a step (:data:`STEP_MIN_FRACTION` of the
    height), and the weight follows it (:data:`STEP_PELVIS_FOLLOWS`).
    """
    side = ("right", "left")[f]
    travel = (joints[k, joint_index(f"{side}_ankle")] - joints[a, joint_index(f"{side}_ankle")])[:2]
    dist = float(np.linalg.norm(travel))
    if not dist >= STEP_MIN_FRACTION * height:
        return False
    pelvis = (joints[k, joint_index("pelvis")] - joints[a, joint_index("pelvis")])[:2]
    return float(pelvis @ travel) / dist >= STEP_PELVIS_FOLLOWS * dist


def closing_place(joints: np.ndarray, frame: int, foot: int) -> np.ndarray:
    """(3,) where foot `foot` (0 right, 1 left) closes at `frame`: beside the other foot at the hips' spacing.

    A free foot comes down relative to the foot bearing the weight, wherever
    the pelvis stands over it: landing there is ``place`` (a closing), half a
    step (:data:`STEP_MIN_FRACTION`) or more away from it a step.
    """
    side, other = ("right", "left")[foot], ("left", "right")[foot]
    spacing = joints[frame, joint_index(f"{side}_hip")] - joints[frame, joint_index(f"{other}_hip")]
    return joints[frame, joint_index(f"{other}_ankle")] + spacing


def step_direction(
    joints,
    labels: FrameLabels,
    a: int,
    k: int,
    part: int,
    height: float,
    offset: np.ndarray | None = None,
    starts: dict | None = None,
    bearing: tuple[bool, bool] | None = None,
) -> str:
    """``place``, or the direction a weight-bearing foot stepped between frames a and k.

    `offset` (2, 3): each foot's standing offset from its hip in the
    measurement (:func:`standing_foot_offset`), removed first.  `starts`
    (foot index → frame; measured motion): where each foot's travel is
    measured from instead of `a` (the last frame it bore weight), and a
    foot steps only if :func:`plausible_step`.  `bearing` (right, left):
    the feet of the support before, when known; default: the feet
    ``labels`` find supporting at `a`.  A foot resting on the floor outside
    that support (the front foot left behind by a step back) takes the
    weight as a step when it lies a step from the closing place: the body
    travels there (DESIGN.md: a step moves the body a step length).
    """
    feet = {0: (0, 1), 1: (0,), 2: (1,)}[part]
    best, best_d = None, STEP_MIN_FRACTION * height
    R = None
    for f in feet:
        side = ("right", "left")[f]
        af = a if starts is None else starts.get(f, a)
        foot = joints[k, joint_index(f"{side}_ankle")]
        moved = np.linalg.norm((foot - joints[af, joint_index(f"{side}_ankle")])[:2])
        bore = labels.supporting[af] if bearing is None else np.asarray(bearing, bool)
        if moved < 0.05 and bore[f]:
            # A foot that bore weight where it stands did not step.  One
            # that was off the floor (left behind by the other foot's step)
            # may land a step away from the weight where it lifted.
            continue
        if starts is not None and not plausible_step(joints, f, af, k, height):
            continue
        if not bore[f] and bore[1 - f]:
            # A free foot comes down relative to the foot bearing the weight.
            rel = foot - closing_place(joints, af, f)
        else:
            rel = foot - joints[af, joint_index(f"{side}_hip")]
            if offset is not None:
                rel = rel - offset[f]
        rel[2] = 0.0
        dist = float(np.linalg.norm(rel))
        if dist > best_d:
            from ..body import body_frame

            R = body_frame(joints[af : af + 1])[0]
            best, best_d = R @ rel, dist
    if best is None:
        return "place"
    d, _ = classify_indices(best[None])
    name = DIRECTION_NAMES[int(d[0])]
    return "place" if name == "place" else name
