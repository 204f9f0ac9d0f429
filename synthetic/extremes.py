"""Keep every movement's path within the joint extremes.

The dancer moves a limb along the direct path (a great circle of its
direction, :mod:`synthetic.limbs`) and the head along the great circle of
its direction (:mod:`synthetic.trunk`).  The extremes (Cachola's joint
limits, :data:`capture2notation.body.LIMITS_DEG`) are a box in each joint's
Euler angles, and a direct path between two poses inside the box may leave
it on the way — e.g. Figure 7's leg from forward middle to the side at
middle level passes the hip's rz extreme, since near the hip's gimbal lock
the leg's sideways swing shows up as rz.  Clipping there would make the limb
stop short, then jump.

:func:`keep_paths_within` straightens such a movement: its joints move
linearly in Euler angles (with the Effort progress), and a straight line
between two points of a box stays in the box.  The pose still arrives
exactly at the symbol's end.
"""

from __future__ import annotations

import numpy as np

from capture2notation.body import Body, joint_index
from capture2notation.notation.effort import progress
from capture2notation.notation.model import Effort

__all__ = ["CLIP_TOL", "PART_JOINTS", "continuous_at_lock", "keep_paths_within", "nearest_at_lock"]

#: Joints whose extremes bound each part's movement.
PART_JOINTS = {
    "head": ("neck",),
    "chest": ("waist", "chest"),
    **{f"{s}_arm": (f"{s}_shoulder", f"{s}_elbow") for s in ("right", "left")},
    **{f"{s}_upper_arm": (f"{s}_shoulder",) for s in ("right", "left")},
    **{f"{s}_forearm": (f"{s}_shoulder", f"{s}_elbow") for s in ("right", "left")},
    **{f"{s}_leg": (f"{s}_hip", f"{s}_knee") for s in ("right", "left")},
    **{f"{s}_thigh": (f"{s}_hip",) for s in ("right", "left")},
    **{f"{s}_shin": (f"{s}_hip", f"{s}_knee") for s in ("right", "left")},
    "support": ("right_hip", "right_knee", "right_ankle", "left_hip", "left_knee", "left_ankle"),
    "right_support": ("right_hip", "right_knee", "right_ankle"),
    "left_support": ("left_hip", "left_knee", "left_ankle"),
    "turn": ("pelvis",),
}
#: |ry| this close to 90° (radians) is a gimbal lock (matrix_to_euler's
#: test, |sin ry| > 1 − 1e-9, in angle).
_LOCK_TOL = 1e-4
#: Clipping smaller than this (radians) is rounding, not an extreme reached.
CLIP_TOL = np.radians(0.5)


def nearest_at_lock(e: np.ndarray, ref: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Euler triple of the same rotation as `e`, nearest `ref` within `limits`.

    Away from gimbal lock the triple within the extremes is unique and `e`
    is returned.  At ``ry = ±90°`` only ``rx ∓ rz`` matters, so
    ``(rx + k, ry, rz ± k)`` is the same rotation for every k.

    Parameters
    ----------
    e, ref : (3,) ndarray
        Euler angles, radians.
    limits : (3, 2) ndarray
        (min, max) per angle, radians.

    Returns
    -------
    (3,) ndarray
    """
    if abs(abs(e[1]) - np.pi / 2) > _LOCK_TOL:
        return e
    sgn = 1.0 if e[1] > 0 else -1.0
    k = np.linspace(-np.pi, np.pi, 721)
    cand = np.stack([e[0] + k, np.full_like(k, e[1]), e[2] + sgn * k], axis=1)
    lo, hi = limits[:, 0], limits[:, 1]
    excess = np.sum(np.maximum(lo - cand, 0) + np.maximum(cand - hi, 0), axis=1)
    return cand[np.argmin(1e3 * excess + np.sum((cand - ref) ** 2, axis=1))]


def _clip_amount(angles: np.ndarray, body: Body, js, frames) -> np.ndarray:
    """(n,) largest clipping (radians) among joints `js` at `frames`."""
    a = angles[frames][:, js]
    lim = body.limits[js]
    return np.abs(a - np.clip(a, lim[..., 0], lim[..., 1])).max(axis=(1, 2))


def keep_paths_within(angles: np.ndarray, body: Body, events, eff: Effort) -> np.ndarray:
    """Straighten gesture paths that leave the extremes.

    Parameters
    ----------
    angles : (T, J, 3) ndarray
        Euler angles asked for, radians (not yet clipped); updated in place.
    body : Body
    events : iterable of (Symbol, int, int)
        Symbols with their start and end frames.
    eff : Effort
        Progress along a straightened path follows ``s(τ)`` (time, weight).

    Returns
    -------
    (T, J, 3) ndarray
        `angles`.

    Notes
    -----
    A movement is straightened when its joints are clipped (by more than
    :data:`CLIP_TOL`) on the way or at its end: clipped at the end, the
    direct path would reach the extreme early and stop there.  Its end frame
    keeps its clipped rotation (another Euler triple of it at a gimbal
    lock).  What the ends themselves cannot reach is
    :mod:`synthetic.reach`'s to report.
    """
    for sym, f0, f1 in events:
        if sym.is_support or sym.is_turn or f1 <= f0 + 1:
            continue
        js = [joint_index(n) for n in PART_JOINTS[sym.part]]
        way = np.arange(f0 + 1, f1)
        end = _clip_amount(angles, body, js, [f1])[0]
        if end <= CLIP_TOL and _clip_amount(angles, body, js, way).max() <= CLIP_TOL:
            continue
        lim = body.limits[js]
        a = np.clip(angles[f0, js], lim[..., 0], lim[..., 1])
        b = np.clip(angles[f1, js], lim[..., 0], lim[..., 1])
        for i in range(len(js)):
            b[i] = nearest_at_lock(b[i], a[i], lim[i])
            a[i] = nearest_at_lock(a[i], b[i], lim[i])
        s = progress((way - f0) / (f1 - f0), eff.time, eff.weight)
        angles[way[:, None], js] = a + s[:, None, None] * (b - a)
        # The end frame takes the lock's chosen triple (same rotation) where
        # it was within the extremes; where not, it keeps what was asked, so
        # that the reach check can name the extreme (the motion clips it to b).
        inside = np.abs(angles[f1, js] - np.clip(angles[f1, js], lim[..., 0], lim[..., 1])).max(axis=-1) <= 1e-12
        angles[f1, js] = np.where(inside[:, None], b, angles[f1, js])
    return angles


def _lock_shift(e, ref, limits):
    """Shift k with ``(rx + k, ry, rz ± k)`` nearest `ref` within `limits` (0 if `e` is not locked)."""
    near = nearest_at_lock(e, ref, limits)
    return float(near[0] - e[0])


def continuous_at_lock(angles: np.ndarray, body: Body) -> np.ndarray:
    """Make joint-angle tracks continuous through gimbal locks.

    At ``|ry| = 90°`` a rotation has a line of Euler triples,
    ``(rx + k, ry, rz ± k)``, and
    :func:`~capture2notation.body.matrix_to_euler` puts the whole turn in
    ``rx``; a limb arriving at or leaving a lock (a leg to the side at middle
    level) would then jump in its numbers, though not in its pose.  Over each
    run of locked frames the shift k slides linearly from the one nearest
    the frame before the run to the one nearest the frame after it, so the
    numbers move continuously while every frame keeps its rotation.

    Parameters
    ----------
    angles : (T, J, 3) ndarray
        Euler angles, radians; updated in place.
    body : Body

    Returns
    -------
    (T, J, 3) ndarray
        `angles`.
    """
    T = len(angles)
    locked = np.abs(np.abs(angles[..., 1]) - np.pi / 2) < _LOCK_TOL
    for j in np.flatnonzero(locked.any(axis=0)):
        idx = np.flatnonzero(locked[:, j])
        lim = body.limits[j]
        # Runs of consecutive locked frames (rare: only they are visited).
        for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):
            t0, t1 = run[0], run[-1]
            e = angles[run, j].copy()
            ka = _lock_shift(e[0], angles[t0 - 1, j] if t0 > 0 else np.zeros(3), lim)
            kb = _lock_shift(e[-1], angles[t1 + 1, j], lim) if t1 + 1 < T else ka
            k = ka + (kb - ka) * (np.arange(len(run)) / max(len(run) - 1, 1))
            sgn = np.where(e[:, 1] > 0, 1.0, -1.0)
            shifted = e + np.stack([k, np.zeros_like(k), sgn * k], axis=1)
            inside = np.all((shifted >= lim[:, 0] - 1e-12) & (shifted <= lim[:, 1] + 1e-12), axis=1)
            angles[run, j] = np.where(inside[:, None], shifted, e)
    return angles
