"""Movements in a speed signal: hysteresis runs, split at speed minima or written poses.

Used by :mod:`.segment` (gestures) and :mod:`.supports` (the supporting
system).  Interval ``i`` of a speed signal spans frames ``i → i + 1``.
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["movement_spans", "true_runs"]

#: Speeds below this (degrees per second) are rounding noise of a hold, not
#: movement; a sudden Effort's first frame still moves far more.
_ZERO_SPEED = 1e-6
#: Split ratio of a noisy speed minimum where the part is near a written pose
#: (see :func:`movement_spans`).
NEAR_POSE_SPLIT_RATIO = 0.6
#: Clean motion: a grid frame on a written pose ends a movement only where
#: the speed slows (a local minimum) or kinks near it.  Two movements meet
#: where one progress curve ends and the next starts, so the speed's slope
#: jumps within a frame or two of the grid frame: the largest second
#: difference of the speed there (frames f - 1 to f + 2), over the speed
#: nearby, was at least 0.13 at each of the 86 such meetings without a
#: minimum in 450 random scores (with turns, springs, random Effort), while
#: a limb sweeping through a written pose on a grid frame passes it with a
#: smooth speed (at most 0.014 at the 5 such frames).
MIN_SPEED_KINK = 0.04
#: Frames about a grid frame (before, after) where a meeting's kink may lie.
_KINK_WINDOW = (1, 2)


def true_runs(mask) -> list[tuple[int, int]]:
    """``[start, end)`` frame ranges of each run of True in `mask` (T,) bool, in order."""
    edges = np.flatnonzero(np.diff(np.r_[0, np.asarray(mask, bool).astype(int), 0]))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def movement_spans(
    speed: np.ndarray,
    low: float,
    high: float,
    split_ratio: float,
    key_pose=None,
    near_pose=None,
    near_ratio: float = NEAR_POSE_SPLIT_RATIO,
) -> list[tuple[int, int]]:
    """Movements in a per-interval speed signal.

    Parameters
    ----------
    speed : (N,) ndarray
        Speed over each frame interval (interval i spans frames i → i+1);
        NaN counts as still.
    low, high : float
        Hysteresis thresholds: a run above `low` is a movement if it peaks
        above `high`.
    split_ratio : float
        See :class:`~.segment.SegmentParams`.
    key_pose : callable, optional
        ``key_pose(frame, since) -> bool`` with attribute ``on_grid`` (see
        :func:`~.gestures._key_pose_fn`).  When given (clean motion), a run is split at
        the local speed minima it accepts, however shallow, and never
        elsewhere — a limb passing near its turning axis slows down
        mid-movement without arriving anywhere.
    near_pose : (N + 1,) ndarray of bool, optional
        Noisy motion: frames where the part is near a written pose.  A
        minimum whose boundary frame is there splits when shallower than
        `near_ratio` (instead of `split_ratio`): smoothing over 0.3-0.6 s
        fills the dip between a half-beat movement and the next one that
        leaves at once, but the pose between them is a written one.  (A
        single movement's speed has one peak: its noisy dips are shallower,
        and only a 45° movement's mid-way pose lies far from any written one.)
    near_ratio : float

    Returns
    -------
    list of (a, b)
        Interval index ranges, inclusive: the movement leaves the pose of
        frame ``a`` and arrives at the pose of frame ``b + 1``.
    """
    s = np.nan_to_num(np.asarray(speed, dtype=float), nan=0.0)
    n = s.size
    above = s > low
    spans: list[tuple[int, int]] = []
    if not above.any():
        return spans
    runs = [(a, b - 1) for a, b in true_runs(above)]
    taken = np.zeros(n, bool)
    for a, b in runs:
        if s[a : b + 1].max() <= high:
            continue
        # Widen down the speed slope to the bracketing minima; a frame interval
        # with no motion at all (a hold) stops the walk.
        while a > 0 and not taken[a - 1] and _ZERO_SPEED < s[a - 1] <= s[a] and not above[a - 1]:
            a -= 1
        while b < n - 1 and _ZERO_SPEED < s[b + 1] <= s[b] and not above[b + 1]:
            b += 1
        taken[a : b + 1] = True
        if key_pose is None:
            for lo, hi in _split(s, a, b, split_ratio, high, near_pose, near_ratio):
                # Noisy motion: the walk down may run far into smoothed jitter,
                # so each movement keeps only where it exceeds a tenth of its peak.
                idx = np.flatnonzero(s[lo : hi + 1] >= 0.1 * s[lo : hi + 1].max())
                spans.append((lo + int(idx[0]), lo + int(idx[-1])))
        else:
            spans.extend(_split_at_key_poses(s, a, b, low, key_pose))
    return spans


def _split_at_key_poses(s: np.ndarray, a: int, b: int, low: float, key_pose) -> list[tuple[int, int]]:
    """Split [a, b] where the motion passes a written pose.

    With a beat grid every grid frame accepted by ``key_pose`` where the
    speed slows or kinks (:data:`MIN_SPEED_KINK`) is a boundary (those for
    which ``key_pose.needs_minimum(f)``, if given, is true only next to a
    local speed minimum: poses a movement may pass through mid-way; those
    for which ``key_pose.forced(f)`` is true always); without a grid, only
    such frames next to a local speed minimum (a
    minimum in interval m puts the boundary at frame m, the next movement's
    first interval, or m + 1, this movement's last).
    """
    cuts = []
    needs_minimum = getattr(key_pose, "needs_minimum", None)

    def slows(f: int) -> bool:
        # A local speed minimum in the interval just before or after f.
        return any(0 < m < s.size - 1 and s[m] <= s[m - 1] and s[m] <= s[m + 1] for m in (f - 1, f))

    def kinks(f: int) -> bool:
        # The speed's slope jumps near f (see MIN_SPEED_KINK).
        for g in range(max(2, f - _KINK_WINDOW[0]), min(s.size - 1, f + _KINK_WINDOW[1] + 1)):
            d2 = (s[g] - s[g - 1]) - 0.5 * ((s[g - 1] - s[g - 2]) + (s[g + 1] - s[g]))
            scale = float(np.max(s[g - 2 : g + 2]))
            if not scale > 0 or abs(d2) >= MIN_SPEED_KINK * scale:
                return True
        return f < 2 or f + 1 >= s.size  # at the signal's ends it cannot be told

    forced = getattr(key_pose, "forced", lambda f: False)

    def ends_here(f: int) -> bool:
        if forced(f):
            return True
        if needs_minimum is not None and needs_minimum(f):
            return slows(f)
        return slows(f) or kinks(f)

    if key_pose.on_grid:
        for f in range(a + 1, b + 1):
            if key_pose(f, cuts[-1] if cuts else a) and ends_here(f):
                cuts.append(f)
    else:
        for m in range(a + 1, b):
            if not (s[m] <= s[m - 1] and s[m] <= s[m + 1]):
                continue
            for f in (m, m + 1):
                if a < f <= b and (not cuts or f > cuts[-1]) and key_pose(f, cuts[-1] if cuts else a):
                    cuts.append(f)
                    break
    bounds = [a] + cuts + [b + 1]
    out = []
    start = None
    for lo, hi in itertools.pairwise(bounds):
        start = lo if start is None else start
        # A slow-starting movement (a sudden Effort) stays on its start pose
        # for a few frames: those pieces belong to the movement that follows.
        if s[lo:hi].max() > low:
            out.append((start, hi - 1))
            start = None
    if start is not None and out:
        out[-1] = (out[-1][0], b)
    return out


def _split(
    s: np.ndarray, a: int, b: int, ratio: float, high: float, near=None, near_ratio: float = 0.0
) -> list[tuple[int, int]]:
    """Split interval range [a, b] at its deepest qualifying interior minimum, recursively
    (`near`, `near_ratio`: see :func:`movement_spans`)."""
    if b - a < 2:
        return [(a, b)]
    seg = s[a : b + 1]
    i = np.arange(1, seg.size - 1)
    is_min = (seg[i] <= seg[i - 1]) & (seg[i] <= seg[i + 1])
    best, best_depth = None, None
    for k in i[is_min]:
        left, right = seg[:k].max(), seg[k + 1 :].max()
        if min(left, right) <= high:
            continue
        depth = seg[k] / min(left, right)
        # Interval k ends at frame a + k + 1, where the next movement would start.
        limit = near_ratio if near is not None and near[a + k + 1] else ratio
        if depth < max(ratio, limit) and (best_depth is None or depth < best_depth):
            best, best_depth = k, depth
    if best is None:
        return [(a, b)]
    m = a + int(best)
    # The minimum interval holds the boundary: it closes the first movement.
    return _split(s, a, m, ratio, high, near, near_ratio) + _split(s, m + 1, b, ratio, high, near, near_ratio)
