"""Support symbols: which feet carry the weight, at which level, and steps.

Per frame (DESIGN.md): a foot is *in contact* when it is within 3 cm of the
floor and slower than 0.2 m/s (:func:`~.labels.support_frames`).  Of the
feet in contact, those that carry the weight are found from the pelvis: with
both feet down, a pelvis over one foot (within a quarter of the way to the
other) puts the weight on that foot alone, otherwise on both.  The support
*part* is ``support`` (both), ``right_support`` or ``left_support``; its
level is that of the weight-bearing feet (low: knee bent > 30°, high: heel
raised; the lower of two unequal levels).

Support movements are found like gestures (:func:`~.segment.movement_spans`)
on a "support speed": the pelvis's speed in leg lengths (expressed in
degrees per second, as an angle seen from the foot) plus the knee-bend and
foot-pitch speeds of the feet in contact.  Each movement whose end state
differs from the state before it becomes one symbol; its direction is
``place`` unless a weight-bearing foot travelled more than half a step
(0.09 body heights) from under its hip — then the sector of that travel in
the body frame (a step).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.signal import savgol_filter

from ..body import joint_index
from ..notation.directions import bend_angle, classify_indices
from ..notation.model import LEVELS
from .labels import DIRECTION_NAMES, FrameLabels

__all__ = ["weight_bearing", "support_state", "support_movements", "STEP_MIN_FRACTION"]

#: A weight-bearing foot that moved farther than this fraction of the body
#: height from under its hip makes the support a step.
STEP_MIN_FRACTION = 0.09
_SUPPORT_PARTS = ("support", "right_support", "left_support")


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
    pelvis = joints[:, joint_index("pelvis"), :2]
    fr = 0.5 * (joints[:, joint_index("right_ankle"), :2] + joints[:, joint_index("right_toe"), :2])
    fl = 0.5 * (joints[:, joint_index("left_ankle"), :2] + joints[:, joint_index("left_toe"), :2])
    d = fl - fr
    n2 = np.sum(d * d, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.sum((pelvis - fr) * d, axis=-1) / n2
    both = contact.all(axis=1)
    wb = contact.copy()
    # Only when both feet are down does the pelvis decide between them.
    wb[:, 1] &= ~(both & (u < 0.25))
    wb[:, 0] &= ~(both & (u > 0.75))
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


def _support_speed(labels: FrameLabels, joints: np.ndarray, fps: float) -> np.ndarray:
    """Speed of the supporting system over each frame interval, degrees per second."""
    leg = np.nanmedian(
        np.linalg.norm(joints[:, joint_index("right_hip")] - joints[:, joint_index("right_ankle")], axis=-1)
    )
    pelvis = joints[:, joint_index("pelvis")] / max(float(leg), 1e-6)
    sig = [np.degrees(pelvis)]
    for k, side in enumerate(("right", "left")):
        knee = bend_angle(
            joints[:, joint_index(f"{side}_hip")], joints[:, joint_index(f"{side}_knee")], joints[:, joint_index(f"{side}_ankle")]
        )
        d = joints[:, joint_index(f"{side}_toe")] - joints[:, joint_index(f"{side}_ankle")]
        pitch = np.degrees(np.arctan2(-d[:, 2], np.hypot(d[:, 0], d[:, 1])))
        c = labels.supporting[:, k]
        sig.append(np.stack([np.where(c, knee, 0.0), np.where(c, pitch, 0.0)], axis=1))
    x = np.concatenate(sig, axis=1)
    return np.linalg.norm(np.diff(x, axis=0), axis=1) * fps


def _position_noise(joints: np.ndarray) -> float:
    """Jitter of the pelvis and feet, metres (lower quartile of the local-cubic residual; 0 when clean)."""
    idx = [joint_index(n) for n in ("pelvis", "right_ankle", "left_ankle")]
    p = joints[:, idx].reshape(joints.shape[0], -1)
    ok = np.isfinite(p).all(axis=1)
    if ok.sum() < 7:
        return 0.0
    r = np.abs(p[ok] - savgol_filter(p[ok], 5, 3, axis=0))
    return float(np.percentile(r, 25) / 0.23)


def _mode_filter(x: np.ndarray, width: int) -> np.ndarray:
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


def support_movements(labels: FrameLabels, joints: np.ndarray, fps: float, params, spans_fn,
                      on_grid: np.ndarray | None = None) -> list:
    """Support movements as :class:`~.segment.Movement` objects (see the module docstring).

    Noisy motion (jitter above 1 mm) is smoothed over 0.3 s first, and the
    support state is mode-filtered over 0.3 s, so contact flicker does not
    write symbols.
    """
    from .labels import support_frames
    from .segment import Movement

    T = joints.shape[0]
    noise = _position_noise(joints)
    noisy = noise > 1e-3
    if noisy and T > 9:
        w = max(5, int(round(0.3 * fps)) | 1)
        if T > w:
            filled = np.where(np.isfinite(joints), joints, np.nanmedian(joints, axis=0))
            joints = savgol_filter(filled, w, 2, axis=0)
            sup, lev = support_frames(joints, fps)
            labels = replace(labels, supporting=sup, support_level=lev)
    part, level = support_state(labels, joints)
    if noisy:
        w = max(3, int(round(0.3 * fps)) | 1)
        code = _mode_filter((part + 1) * 4 + (level + 1), w)
        part, level = code // 4 - 1, code % 4 - 1
    speed = _support_speed(labels, joints, fps)
    if noisy:
        low = max(params.min_speed_deg_s, 4.0 * float(np.nanpercentile(speed, 25)))
        high = max(params.peak_speed_deg_s, 2.0 * low)
        spans = spans_fn(speed, low, high, params.split_ratio)
    else:
        # Clean motion: any motion is a movement; back-to-back support
        # symbols part at grid frames with both feet down and the speed at a
        # local minimum (never mid-step, while a foot is in the air).
        spans = spans_fn(speed, 1e-4, 2e-4, params.split_ratio, key_pose=_support_cut_fn(labels, speed, on_grid))
    height = _body_height(joints)
    state = (0, LEVELS.index("middle"), "place")
    out = []
    for a, b in spans:
        end = min(b + 1, T - 1)
        # The state where the movement settles: the end frame, or the next
        # grounded one if the dancer is still in the air there.
        k = end
        while k < T - 1 and part[k] < 0:
            k += 1
        if part[k] < 0:
            continue
        direction = _step_direction(joints, labels, a, k, part[k], height)
        new = (int(part[k]), int(level[k]), direction)
        if new == state:
            continue
        state = new
        out.append(Movement(_SUPPORT_PARTS[new[0]], a, end, a / fps, (b + 1) / fps, direction, LEVELS[new[1]], 0))
    return out


def _support_cut_fn(labels: FrameLabels, speed: np.ndarray, on_grid: np.ndarray | None):
    """``(f, since) -> bool`` for :func:`~.segment.movement_spans`: frame f may part two support movements."""
    down = labels.supporting.all(axis=1)
    n = speed.size

    def key(f: int, since: int) -> bool:
        if not down[f] or (on_grid is not None and not on_grid[f]):
            return False
        # A deep local speed minimum in the interval just before or after f
        # (below a third of the peaks within a second on either side).
        w = 25
        for m in (f - 1, f):
            if 0 < m < n - 1 and speed[m] <= speed[m - 1] and speed[m] <= speed[m + 1]:
                left, right = speed[max(0, m - w) : m].max(), speed[m + 1 : m + 1 + w].max()
                if speed[m] <= 0.35 * min(left, right):
                    return True
        return False

    key.on_grid = on_grid is not None
    return key


def _body_height(joints: np.ndarray) -> float:
    """Body height from the leg length (hip → ankle is 0.491 of the height at rest)."""
    leg = np.nanmedian(
        np.linalg.norm(joints[:, joint_index("right_hip")] - joints[:, joint_index("right_knee")], axis=-1)
        + np.linalg.norm(joints[:, joint_index("right_knee")] - joints[:, joint_index("right_ankle")], axis=-1)
    )
    return float(leg) / (0.530 - 0.039)


def _step_direction(joints, labels: FrameLabels, a: int, k: int, part: int, height: float) -> str:
    """``place``, or the direction a weight-bearing foot stepped between frames a and k."""
    feet = {0: (0, 1), 1: (0,), 2: (1,)}[part]
    best, best_d = None, STEP_MIN_FRACTION * height
    R = None
    for f in feet:
        side = ("right", "left")[f]
        foot = joints[k, joint_index(f"{side}_ankle")]
        moved = np.linalg.norm((foot - joints[a, joint_index(f"{side}_ankle")])[:2])
        if moved < 0.05:
            continue
        rel = foot - joints[a, joint_index(f"{side}_hip")]
        rel[2] = 0.0
        dist = float(np.linalg.norm(rel))
        if dist > best_d:
            from ..body import body_frame

            R = body_frame(joints[a : a + 1])[0]
            best, best_d = R @ rel, dist
    if best is None:
        return "place"
    d, _ = classify_indices(best[None])
    name = DIRECTION_NAMES[int(d[0])]
    return "place" if name == "place" else name
