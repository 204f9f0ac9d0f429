"""Movement segmentation: joints over time → a :class:`~capture2notation.notation.Score`.

Each channel (a whole arm or leg, the head, the chest, each supporting foot)
has an angular speed per frame interval.  A movement is a run of intervals
where that speed exceeds a low threshold and peaks above a high one
(hysteresis), widened outward while the speed keeps falling (so its ends sit
at the speed minima that bracket it) and split at deep interior minima
(back-to-back movements: the virtual dancer's logistic starts from zero
speed).  Its symbol is the part's label where it arrives; its start and
duration are snapped to the beat grid.

Whole limb or segments
    Arms and legs are written as whole limbs (``right_arm`` …) with the
    bend degree of the elbow / knee.  A movement is written with segment parts
    instead (``right_forearm`` / ``right_shin``) when the upper segment stays
    still (its own angular displacement below ``min_amplitude_deg``) while
    the lower one moves, i.e. when the two segments move independently; the
    limb is then described by its segments until a whole-limb movement moves
    both again.

Supports
    See :mod:`.supports`: the weight-bearing feet and their level, segmented
    on the pelvis's and the supporting legs' speed; a weight-bearing foot
    that travelled is a step.  Legs write gestures only while their foot is
    off the floor (a leg that lands is part of a support).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np
from scipy.signal import savgol_filter

from ..errors import QuantiseError
from ..notation.model import LEVELS, Score, Symbol
from .labels import DIRECTION_NAMES, FrameLabels, label_frames
from .supports import support_movements
from .tempo import estimate_tempo, snap

__all__ = ["SegmentParams", "Movement", "Segmentation", "movement_spans", "segment", "segment_motion"]


@dataclass(frozen=True)
class SegmentParams:
    """Tuning of :func:`segment`.

    Parameters
    ----------
    grid : Fraction
        Beat grid for starts and durations (default ¼ beat).
    smooth_s : float or None
        Savitzky–Golay window, seconds; ``None`` chooses it from the noise
        (no smoothing for clean, e.g. synthetic, motion), 0 disables.
    min_speed_deg_s : float
        Floor of the low (onset) speed threshold, degrees per second.
    peak_speed_deg_s : float
        A movement must peak above this speed, degrees per second.
    noise_k : float
        Thresholds are at least this many noise speeds.
    min_amplitude_deg : float
        Smallest angular displacement that counts as a movement, degrees.
    split_ratio : float
        An interior speed minimum below this fraction of the smaller of the
        peaks on either side splits a run into two movements.
    merge_window_s : float
        Key times of different parts closer than this are merged (their
        median), capped at 0.45 grid steps so distinct grid points never merge.
    """

    grid: Fraction = Fraction(1, 4)
    smooth_s: float | None = None
    min_speed_deg_s: float = 2.0
    peak_speed_deg_s: float = 20.0
    noise_k: float = 4.0
    min_amplitude_deg: float = 10.0
    split_ratio: float = 0.35
    merge_window_s: float = 0.3


@dataclass(frozen=True)
class Movement:
    """One detected movement of one part, in frames and seconds.

    ``start_time`` / ``end_time`` are the estimated instants the movement
    begins and arrives (seconds); ``end_frame`` is the first frame at the
    arrival pose.
    """

    part: str
    start_frame: int
    end_frame: int
    start_time: float
    end_time: float
    direction: str
    level: str
    bend: int = 0


@dataclass(frozen=True)
class Segmentation:
    """Everything :func:`segment_motion` found.

    Attributes
    ----------
    score : Score
    movements : tuple of Movement
        Before snapping, in time order.
    key_frames : (K,) ndarray of int
        Sorted frames where some movement arrives (plus frame 0).
    tempo : Fraction
    tempo_estimated : bool
    labels : FrameLabels
    """

    score: Score
    movements: tuple
    key_frames: np.ndarray
    tempo: Fraction
    tempo_estimated: bool
    labels: FrameLabels = field(repr=False)


# Gesture channels: part, segment label columns (upper, lower) or single.
_LIMBS = {
    "right_arm": ("right_upper_arm", "right_forearm"),
    "left_arm": ("left_upper_arm", "left_forearm"),
    "right_leg": ("right_thigh", "right_shin"),
    "left_leg": ("left_thigh", "left_shin"),
}
_SINGLE = ("head", "chest")
_DEFAULT = {"head": ("place", "high"), "chest": ("place", "high")}
_FOOT = {"right_leg": 0, "left_leg": 1}
#: Speeds below this (degrees per second) are rounding noise of a hold, not
#: movement; a sudden Effort's first frame still moves far more.
_ZERO_SPEED = 1e-6


def _angle_deg(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between unit vectors along the last axis, degrees (precise near 0)."""
    c = np.linalg.norm(np.cross(u, v), axis=-1)
    d = np.sum(u * v, axis=-1)
    return np.degrees(np.arctan2(c, d))


def _noise_deg(u: np.ndarray) -> float:
    """Frame-to-frame jitter of unit vectors (T, 3), degrees (robust; ~0 when clean).

    The residual from a local cubic (Savitzky–Golay, 5 frames) is tiny for
    smooth motion, however fast, and about 0.72 σ for white noise of σ per
    coordinate; its median ignores the few kinks where movements start or stop.
    """
    ok = np.isfinite(u).all(axis=-1)
    if ok.sum() < 7:
        return 0.0
    v = u[ok]
    r = np.linalg.norm(v - savgol_filter(v, 5, 3, axis=0), axis=-1)
    return float(np.degrees(np.median(r)) / 0.72)


def _smooth(u: np.ndarray, window: int) -> np.ndarray:
    """Savitzky–Golay smoothing of unit vectors (T, 3), renormalised."""
    if window < 5 or u.shape[0] <= window:
        return u
    filled = u.copy()
    bad = ~np.isfinite(filled).all(axis=-1)
    if bad.all():
        return u
    if bad.any():
        idx = np.arange(len(u))
        for k in range(3):
            filled[bad, k] = np.interp(idx[bad], idx[~bad], u[~bad, k])
    s = savgol_filter(filled, window, 2, axis=0)
    s /= np.linalg.norm(s, axis=-1, keepdims=True)
    s[bad] = np.nan
    return s


def movement_spans(speed: np.ndarray, low: float, high: float, split_ratio: float) -> list[tuple[int, int]]:
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
        See :class:`SegmentParams`.

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
    edges = np.flatnonzero(np.diff(np.r_[0, above.astype(int), 0]))
    runs = [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2])]
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
        spans.extend(_split(s, a, b, split_ratio, high))
    return spans


def _split(s: np.ndarray, a: int, b: int, ratio: float, high: float) -> list[tuple[int, int]]:
    """Split interval range [a, b] at its deepest qualifying interior minimum, recursively."""
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
        if depth < ratio and (best_depth is None or depth < best_depth):
            best, best_depth = k, depth
    if best is None:
        return [(a, b)]
    m = a + int(best)
    # The minimum interval holds the boundary: it closes the first movement.
    return _split(s, a, m, ratio, high) + _split(s, m + 1, b, ratio, high)


def _thresholds(u_list: list[np.ndarray], fps: float, params: SegmentParams, smoothed: bool) -> tuple[float, float]:
    noise = max(_noise_deg(u) for u in u_list)
    # Jitter of σ degrees per frame gives speeds of order σ·fps (less after smoothing).
    noise_speed = noise * fps * (0.35 if smoothed else 1.0)
    low = max(params.min_speed_deg_s, params.noise_k * noise_speed)
    high = max(params.peak_speed_deg_s, 2.0 * low)
    return low, high


def _window(u_list: list[np.ndarray], fps: float, params: SegmentParams) -> int:
    if params.smooth_s is not None:
        w = int(round(params.smooth_s * fps))
    else:
        # Clean motion (jitter below a tenth of a degree) is left alone so
        # movement boundaries stay on their frames.
        noisy = max(_noise_deg(u) for u in u_list) > 0.1
        w = int(round(0.2 * fps)) if noisy else 0
    return w + (1 - w % 2) if w > 0 else 0


def _interval_speed(u_list: list[np.ndarray], fps: float) -> np.ndarray:
    per = [_angle_deg(u[:-1], u[1:]) for u in u_list]
    return np.nanmax(np.stack(per), axis=0) * fps if per[0].size else np.zeros(0)


def segment_motion(
    joints: np.ndarray,
    fps: float,
    tempo=None,
    meter: int = 4,
    params: SegmentParams | None = None,
    floor: float = 0.0,
    title: str = "",
) -> Segmentation:
    """Segment a motion into notation symbols.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up, floor at `floor`.
    fps : float
        Frames per second.
    tempo : number or Fraction, optional
        Beats per minute; estimated from the key times when omitted.
    meter : int
        Beats per measure written to the score.
    params : SegmentParams, optional
    floor : float
        Floor height, metres.
    title : str

    Returns
    -------
    Segmentation
    """
    params = params or SegmentParams()
    labels = label_frames(joints, fps, floor)
    T = labels.direction.shape[0]
    if T < 2:
        raise QuantiseError(f"need at least 2 frames to segment a motion, got {T}")
    joints = np.asarray(joints, dtype=float)
    moves = _gesture_movements(labels, fps, params) + support_movements(labels, joints, fps, params, movement_spans)
    moves.sort(key=lambda m: (m.start_time, m.part))
    times = np.array([t for m in moves for t in (m.start_time, m.end_time)])
    estimated = tempo is None
    if estimated and len(moves) == 0:
        # Nothing moves: the (empty) score needs some tempo; say so, invent nothing else.
        warnings.warn("no movement found: the tempo cannot be estimated, writing 60 bpm", stacklevel=2)
        tempo, estimated = Fraction(60), False
    if estimated:
        gestures = [m.end_time - m.start_time for m in moves if not m.part.endswith("support")]
        tempo = estimate_tempo(times, params.grid, durations=gestures or None)
    tempo = Fraction(tempo).limit_denominator(1000) if not isinstance(tempo, Fraction) else tempo
    if tempo <= 0:
        raise QuantiseError(f"tempo must be > 0 beats per minute, got {tempo}")
    merged = _merge_times(moves, params, float(tempo))
    symbols = _symbols(merged, tempo, params.grid)
    key_frames = np.unique(np.r_[0, [min(m.end_frame, T - 1) for m in moves]].astype(int))
    score = Score(symbols=tuple(symbols), title=title, tempo=tempo, meter=meter)
    return Segmentation(score, tuple(moves), key_frames, tempo, estimated, labels)


def segment(joints: np.ndarray, fps: float, tempo=None, meter: int = 4, params: SegmentParams | None = None, floor: float = 0.0) -> Score:
    """The score of a motion (see :func:`segment_motion`)."""
    return segment_motion(joints, fps, tempo=tempo, meter=meter, params=params, floor=floor).score


def _label_at(labels: FrameLabels, col: int, frames: slice) -> tuple[str, str, int]:
    """Label of a gesture column from its mean vector over `frames` (robust to jitter)."""
    from ..notation.directions import bend_degree, classify_indices

    v = np.nanmean(labels.vectors[frames, col], axis=0)
    d, lv = classify_indices(v[None])
    if d[0] < 0:
        return "", "", -1
    bd = labels.bend_deg[frames, col]
    bend = int(bend_degree(np.nanmean(bd))) if np.isfinite(bd).any() else 0
    return DIRECTION_NAMES[d[0]], LEVELS[lv[0]], bend


def _off_canonical_deg(labels: FrameLabels, col: int, frames: slice) -> float:
    """Angle from the mean vector of a column to its label's canonical vector, degrees."""
    from ..notation.directions import canonical_vector

    v = np.nanmean(labels.vectors[frames, col], axis=0)
    d, lv, _ = _label_at(labels, col, frames)
    if not d or (d == "place" and lv == "middle"):
        return float("inf")
    c = canonical_vector(d, lv)
    return float(_angle_deg(v / np.linalg.norm(v), c))


def _upper_written(labels: FrameLabels, upper: int, whole: int, frames: slice, tol: float = 2.0) -> bool:
    """True when the upper segment, not the whole limb, ends on a canonical direction.

    A whole-limb symbol puts the bound → free vector exactly on its canonical
    vector; an upper-arm / thigh symbol puts the upper segment there instead.
    Noisy motion rarely meets either, and then the whole limb is written.
    """
    return _off_canonical_deg(labels, upper, frames) < tol and _off_canonical_deg(labels, whole, frames) > 2 * tol


def _gesture_movements(labels: FrameLabels, fps: float, params: SegmentParams) -> list[Movement]:
    out: list[Movement] = []
    T = labels.direction.shape[0]
    hold = max(1, int(round(0.1 * fps)))
    for part in tuple(_LIMBS) + _SINGLE:
        cols = [labels.index(p) for p in _LIMBS.get(part, (part,))]
        whole = labels.index(part)
        u_list = [labels.vectors[:, c] for c in cols]
        w = _window(u_list, fps, params)
        if w:
            u_list = [_smooth(u, w) for u in u_list]
        low, high = _thresholds(u_list, fps, params, bool(w))
        speed = _interval_speed(u_list, fps)
        spans = movement_spans(speed, low, high, params.split_ratio)
        state = _DEFAULT.get(part, ("place", "low")) + (0,)
        for i, (a, b) in enumerate(spans):
            start_f, end_f = a, min(b + 1, T - 1)
            nxt = spans[i + 1][0] if i + 1 < len(spans) else T
            frames = slice(end_f, max(end_f + 1, min(end_f + hold, nxt + 1)))
            moved = [float(_angle_deg(u[start_f], u[end_f])) for u in u_list]
            if np.nanmax(moved) < params.min_amplitude_deg:
                continue
            if part in _FOOT and labels.supporting[end_f, _FOOT[part]]:
                # A leg that arrives on the floor is a support, not a gesture.
                state = ("place", "low", 0)
                continue
            # The movement leaves frame a's pose and arrives at frame b + 1's.
            t0, t1 = a / fps, (b + 1) / fps
            if part in _LIMBS and moved[0] < params.min_amplitude_deg:
                # Upper segment still, lower one moving: segments move independently.
                lower = cols[1]
                d, lv, _ = _label_at(labels, lower, frames)
                if d:
                    out.append(Movement(_LIMBS[part][1], start_f, end_f, t0, t1, d, lv, 0))
                    state = ("", "", -1)
                continue
            d, lv, bend = _label_at(labels, whole, frames)
            if not d or (d == "place" and lv == "middle"):
                continue
            if part in _LIMBS and bend > 0 and _upper_written(labels, cols[0], whole, frames):
                # The upper segment, not the whole limb, arrives on a written
                # direction: an upper-arm / thigh symbol (the lower one carried).
                d, lv, _ = _label_at(labels, cols[0], frames)
                out.append(Movement(_LIMBS[part][0], start_f, end_f, t0, t1, d, lv, 0))
                bends = labels.bend_deg[[start_f, end_f], whole]
                if abs(bends[1] - bends[0]) > 15.0:
                    # The elbow / knee changed too: both segments notated over the span.
                    d2, lv2, _ = _label_at(labels, cols[1], frames)
                    out.append(Movement(_LIMBS[part][1], start_f, end_f, t0, t1, d2, lv2, 0))
                state = ("", "", -1)
                continue
            if part not in _LIMBS:
                bend = 0
            if (d, lv, bend) == state:
                continue
            state = (d, lv, bend)
            out.append(Movement(part, start_f, end_f, t0, t1, d, lv, bend))
    return out


def _merge_times(moves: list[Movement], params: SegmentParams, tempo: float) -> list[Movement]:
    """Pull key times of different parts that lie within the merge window onto their median."""
    if not moves:
        return moves
    window = min(params.merge_window_s, 0.45 * float(params.grid) * 60.0 / tempo)
    t = np.array([x for m in moves for x in (m.start_time, m.end_time)])
    order = np.argsort(t)
    ts = t[order]
    cluster = np.r_[0, np.cumsum(np.diff(ts) > window)]
    out_t = np.empty_like(t)
    for c in np.unique(cluster):
        sel = cluster == c
        out_t[order[sel]] = np.median(ts[sel])
    return [replace(m, start_time=float(out_t[2 * i]), end_time=float(out_t[2 * i + 1])) for i, m in enumerate(moves)]


def _symbols(moves: list[Movement], tempo: Fraction, grid: Fraction) -> list[Symbol]:
    last_end: dict[str, Fraction] = {}
    out: list[Symbol] = []
    for m in sorted(moves, key=lambda m: (m.start_time, m.part)):
        start = snap(m.start_time, tempo, grid)
        end = snap(m.end_time, tempo, grid)
        start = max(start, last_end.get(m.part, Fraction(0)))
        if end <= start:
            end = start + grid
        out.append(Symbol(start, end - start, m.part, m.direction, m.level, m.bend))
        last_end[m.part] = end
    return out
