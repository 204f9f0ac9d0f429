"""Turns: the dancer's front over time, and the turns that change it.

The front is the hips' (``front_of(body_frame(joints)[:, 1])``, DESIGN.md
"Facing and turns"), unwrapped.  A body turns continuously: it does not turn
half way round between two frames, so a frame-to-frame change of front near
180° is a front/back confusion of the capture (a video's depth ambiguity
mirrors the hips), and is folded back (:func:`continuous_front`).

Clean motion (the virtual dancer's truth, exactly held outside turns)
turns on every frame of a turn and not at all elsewhere: a turn is a window
of rotation speed, cut like a gesture (:func:`~.spans.movement_spans`), and
back-to-back turns part only at a grid frame where the front sits on an
eighth.

A measured front (fitted hips, mocap) wanders and swings about the
direction held.  The room directions held are decoded from it as a whole
(:func:`~.front_levels.decode_front_levels`: a stated noise model and a
prior on turns); a turn is a run of changes of direction the same way
(:func:`_measured_turns`), its span that of the front's movement about them.

The amount is the change of front in eighths, ``right`` for clockwise
(increasing front).  A turn's feet turn with it (:func:`_feet_turn_too`).
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
from scipy.signal import savgol_filter

from ..body import body_frame, front_of, joint_index
from ..notation.model import TURN_PART, TURN_STEP
from .front_levels import decode_front_levels
from .movement import Movement
from .spans import movement_spans, true_runs

__all__ = ["continuous_front", "turn_movements", "turned_so_far"]

#: Degrees in one eighth of a turn, the unit amounts are rounded to.
EIGHTH_DEG = 360.0 * float(TURN_STEP)
#: A frame-to-frame change of front larger than this (degrees) is a front/back
#: flip of the capture, not a turn: a fast pirouette (2 turns a second) turns
#: 29° a frame at 25 fps, far below; a mirrored pair of hips jumps ~180°.
FLIP_DEG = 120.0
#: A turn's feet turn too: one foot's heading changes by at least this
#: fraction of the hips' change (a pivoting foot turns with the body; hips
#: twisting over planted feet turn neither).
FEET_TURN_FRACTION = 0.5
#: Measured feet: a foot's heading over half a second of a hold wanders by
#: this much (degrees; median-based SD of fitted feet on development
#: captures, the dancer not turning), so it may fall short by as much.
FEET_HEADING_SD_DEG = 8.0
#: Clean motion: a front this near (degrees) a multiple of an eighth may end
#: one turn and start the next (numerical noise of the truth is ~1e-10°).
_ON_EIGHTH_DEG = 0.05
#: Clean motion: rotation slower than this (degrees per second) is a hold.
_CLEAN_SPEED_DEG_S = 1e-4
#: Measured motion: the (smoothed) front turning slower than this, degrees
#: per second, stands still.  A written eighth turn over two beats at 60 bpm
#: averages 22°/s; fitted hips wander by a few degrees per second standing still.
_LOW_SPEED_DEG_S = 8.0
#: Measured motion: two level changes the same way are two turns when the
#: front stands still for this long between them, seconds (half a second is
#: a beat at 120 bpm; a turn does not pause mid-way).
_HELD_S = 0.5
#: Measured motion: two turns the same way meet where the smoothed speed
#: falls below this fraction of the peaks on either side (a slow turn's
#: speed, read through the fit, wavers by half).
_SPLIT_RATIO = 0.2
#: Measured motion: a turn's start and arrival lie at most this far (seconds)
#: before its first and after its last change of room direction (half of a
#: four-beat turn at 60 bpm).
_RAMP_SEARCH_S = 2.0
#: Measured motion: smoothing window of the front, seconds (a beat and a
#: half at 150 bpm: 1 cm of jitter on the hips is ~6° of front per frame).
_SMOOTH_S = 0.6


def continuous_front(joints: np.ndarray) -> np.ndarray:
    """(T,) the hips' front, degrees clockwise from +y, unwrapped and continuous.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.

    Returns
    -------
    (T,) ndarray
        Degrees; missing frames are filled by linear interpolation from their
        neighbours (NaN throughout if no frame has hips).  Frame-to-frame
        steps beyond :data:`FLIP_DEG` are taken as the capture mirroring the
        hips (front and back confused) and folded by 180° — from that frame
        on, until the capture flips back.
    """
    raw = front_of(body_frame(np.asarray(joints, float))[:, 1])
    ok = np.isfinite(raw)
    if not ok.any():
        return raw
    t = np.arange(raw.size)
    a = np.interp(t, t[ok], raw[ok])
    step = np.diff(a)
    # Fold each step to (-180, 180] and then undo half turns: a front that
    # jumps by ~180° between frames is the same body seen from the other side.
    step = (step + 180.0) % 360.0 - 180.0
    flip = np.abs(step) > FLIP_DEG
    step = np.where(flip, step - np.sign(step) * 180.0, step)
    return a[0] + np.r_[0.0, np.cumsum(step)]


def _on_eighth(front: np.ndarray, origin: float) -> np.ndarray:
    r = (front - origin) / EIGHTH_DEG
    return np.abs(r - np.round(r)) * EIGHTH_DEG <= _ON_EIGHTH_DEG


def turn_movements(
    joints: np.ndarray,
    fps: float,
    measured: bool,
    on_grid: np.ndarray | None = None,
) -> list[Movement]:
    """The turns of a motion as movements of the ``turn`` part.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.
    fps : float
        Frames per second.
    measured : bool
        Fitted or recorded motion (the room directions held decoded from
        its front, :func:`_measured_turns`) rather than clean truth.
    on_grid : (T,) ndarray of bool, optional
        Clean motion: frames of the beat grid, where back-to-back turns may part.

    Returns
    -------
    list of Movement
        ``direction`` ``right``/``left``, ``level`` ``""`` (a turn has none),
        ``amount`` in full turns (a multiple of 1/8).
    """
    front = continuous_front(joints)
    T = front.size
    if T < 2 or not np.isfinite(front).any():
        return []
    feet = _feet_heading(joints)
    if measured:
        spans = _measured_turns(front, fps)
    else:
        spans = _clean_turns(front, fps, on_grid)
    # Measured feet are read over a hold's worth of frames either side.
    window = max(1, int(round(_HELD_S * fps))) if measured else 1
    noise = FEET_HEADING_SD_DEG if measured else 0.0
    out = []
    for k, (a, b, eighths) in enumerate(spans):
        # The feet are read no further than the turns either side: a turn
        # that meets its neighbour starts where the feet are still turning.
        lo = spans[k - 1][1] if k > 0 else 0
        hi = spans[k + 1][0] if k + 1 < len(spans) else T - 1
        if eighths == 0 or not _feet_turn_too(feet, a, b, EIGHTH_DEG * eighths, window, noise, lo, hi):
            continue
        out.append(
            Movement(
                TURN_PART,
                a,
                b,
                a / fps,
                b / fps,
                "right" if eighths > 0 else "left",
                "",
                amount=Fraction(abs(eighths)) * TURN_STEP,
            )
        )
    return out


def _clean_turns(front: np.ndarray, fps: float, on_grid: np.ndarray | None) -> list[tuple[int, int, int]]:
    """Clean motion's turns: ``(start frame, arrival frame, eighths)``, cut where the rotation stops."""
    T = front.size
    speed = np.abs(np.diff(front)) * fps
    origin = float(front[0])
    grid = np.ones(T, bool) if on_grid is None else np.asarray(on_grid, bool)
    eighth = _on_eighth(front, origin)

    def key(f: int, since: int) -> bool:
        return bool(grid[f] and eighth[f] and abs(front[f] - front[since]) >= EIGHTH_DEG / 2)

    # Every boundary must also be a speed minimum: a turn passes through
    # eighths mid-way (a quarter turn is on an eighth half way through).
    key.on_grid = on_grid is not None  # type: ignore[attr-defined]
    key.needs_minimum = lambda f: True  # type: ignore[attr-defined]
    spans = movement_spans(speed, _CLEAN_SPEED_DEG_S, _CLEAN_SPEED_DEG_S, 0.0, key_pose=key)
    return [(a, b + 1, int(round(float(front[b + 1] - front[a]) / EIGHTH_DEG))) for a, b in spans]


def _measured_turns(front: np.ndarray, fps: float) -> list[tuple[int, int, int]]:
    """Measured motion's turns: ``(start frame, arrival frame, eighths)``.

    The room directions held come from :func:`~.front_levels.decode_front_levels`;
    a turn is a run of level changes the same way, unless the front stands
    still between two of them for :data:`_HELD_S` or the turning all but
    stops (:func:`_split_at_pauses`) — a turn turns one way, so a change
    back starts another.  Its start and arrival are first those of the
    straight ramp between the fronts held before and after that fits the
    front best (:func:`_ramp`), then widened to where the front stands
    still, or to the slowest frame between it and a turn it runs into.
    """
    level = decode_front_levels(front, fps).level
    changes = np.flatnonzero(np.diff(level)) + 1
    if changes.size == 0:
        return []
    w = int(round(_SMOOTH_S * fps)) | 1
    smooth = savgol_filter(front, w, 2) if 5 <= w < front.size else front
    speed = np.abs(np.gradient(smooth)) * fps
    still = speed < _LOW_SPEED_DEG_S
    held = max(1, int(round(_HELD_S * fps)))
    groups = [[int(changes[0])]]
    for c in changes[1:].tolist():
        prev = groups[-1][-1]
        same_way = np.sign(level[c] - level[c - 1]) == np.sign(level[prev] - level[prev - 1])
        if same_way and not _pauses(still[prev:c], held):
            groups[-1].append(c)
        else:
            groups.append([c])
    groups = [part for g in groups for part in _split_at_pauses(g, speed, held)]
    # Turns that follow one another without the front standing still for
    # _HELD_S meet at the slowest frame between them.
    meets = [
        None if _pauses(still[g[-1] : h[0]], held) else g[-1] + int(np.argmin(speed[g[-1] : h[0]]))
        for g, h in itertools.pairwise(groups)
    ]
    out = []
    for i, g in enumerate(groups):
        lo = out[-1][1] if out else 0
        hi = groups[i + 1][0] - 1 if i + 1 < len(groups) else front.size - 1
        a, b = _ramp(front, lo, g[0], g[-1], hi, fps)
        # A turn eases in and out, beyond the ramp's corners: its ends lie
        # where the front stands still, or where it meets its neighbour.
        if i > 0 and meets[i - 1] is not None:
            a = min(meets[i - 1], g[0] - 1)
        else:
            while a > lo and speed[a - 1] >= _LOW_SPEED_DEG_S:
                a -= 1
        if i + 1 < len(groups) and meets[i] is not None:
            b = max(meets[i], g[-1])
        else:
            while b < hi and speed[b] >= _LOW_SPEED_DEG_S:
                b += 1
        out.append((a, b, int(level[g[-1]] - level[g[0] - 1])))
    return out


def _pauses(still: np.ndarray, held: int) -> bool:
    """Whether `still` (frames' bool) has a run of at least `held` frames: the front stood still between."""
    return any(b - a >= held for a, b in true_runs(still))


def _split_at_pauses(changes: list[int], speed: np.ndarray, reach: int) -> list[list[int]]:
    """A run of level changes the same way, split where the turning all but stops between two of them.

    Two turns the same way, one straight after the other, each ease out and
    in: the smoothed speed between them falls below :data:`_SPLIT_RATIO` of
    the peaks on either side (within `reach` frames of the run).
    """
    if len(changes) < 2:
        return [changes]
    lo, hi = max(0, changes[0] - reach), min(speed.size, changes[-1] + reach)
    best, where = 1.0, None
    for i in range(len(changes) - 1):
        a, b = changes[i], changes[i + 1]
        if b - a < 2:
            continue
        m = a + 1 + int(np.argmin(speed[a + 1 : b]))
        ratio = speed[m] / max(min(speed[lo:m].max(), speed[m:hi].max()), 1e-9)
        if ratio < min(best, _SPLIT_RATIO):
            best, where = ratio, i + 1
    if where is None:
        return [changes]
    return _split_at_pauses(changes[:where], speed, reach) + _split_at_pauses(changes[where:], speed, reach)


def _ramp(front: np.ndarray, lo: int, first: int, last: int, hi: int, fps: float) -> tuple[int, int]:
    """The start and arrival frames of a turn: the least-squares hold-ramp-hold through the front.

    The front is held at the median of frames ``lo..first - 1`` until the
    start ``s`` (``lo <= s < first``), moves at a constant rate to the median
    of frames ``last..hi``, reached at the arrival ``e`` (``last <= e <= hi``),
    and is held there.  Start and arrival lie at most :data:`_RAMP_SEARCH_S`
    from the turn's first and last level change.
    """
    reach = max(1, int(round(_RAMP_SEARCH_S * fps)))
    lo, hi = max(lo, first - reach), min(hi, last + reach)
    if hi <= last or first <= lo:
        return max(lo, first - 1), max(last, min(hi, last + 1))
    m0, m1 = float(np.median(front[lo:first])), float(np.median(front[last : hi + 1]))
    f = front[lo : hi + 1]
    t = np.arange(f.size, dtype=float)
    g = f - m0
    # Prefix sums: the squared error of each piece in O(1) for every (s, e).
    c1, ct, c2 = (np.r_[0.0, np.cumsum(x)] for x in (g, g * t, g * g))
    h2 = np.r_[0.0, np.cumsum((f - m1) ** 2)]
    s = np.arange(0, first - lo)[:, None]
    e = np.arange(last - lo, f.size)[None, :]
    d = (e - s).astype(float)
    delta = m1 - m0
    # Ramp frames s+1..e-1: g_t against delta * (t - s) / d.
    sg = c1[e] - c1[s + 1]
    sgt = ct[e] - ct[s + 1] - s * sg
    su2 = (d - 1) * d * (2 * d - 1) / 6.0
    ramp = (c2[e] - c2[s + 1]) - 2 * delta / d * sgt + (delta / d) ** 2 * su2
    cost = c2[s + 1] + ramp + (h2[-1] - h2[e])
    i, j = np.unravel_index(int(np.argmin(cost)), cost.shape)
    return lo + int(s[i, 0]), lo + int(e[0, j])


def _feet_heading(joints: np.ndarray) -> np.ndarray:
    """(T, 2) each foot's heading (ankle → toe seen from above), degrees clockwise from +y, unwrapped."""
    joints = np.asarray(joints, float)
    out = np.full((joints.shape[0], 2), np.nan)
    for k, side in enumerate(("right", "left")):
        d = joints[:, joint_index(f"{side}_toe")] - joints[:, joint_index(f"{side}_ankle")]
        a = np.arctan2(d[:, 0], d[:, 1])
        ok = np.isfinite(a) & (np.hypot(d[:, 0], d[:, 1]) > 1e-6)
        if ok.any():
            t = np.arange(a.size)
            out[:, k] = np.degrees(np.unwrap(np.interp(t, t[ok], a[ok])))
    return out


def _feet_turn_too(
    feet: np.ndarray,
    a: int,
    b: int,
    delta: float,
    window: int = 1,
    noise: float = 0.0,
    lo: int = 0,
    hi: int | None = None,
) -> bool:
    """Whether a foot turns with the hips between frames a and b (by :data:`FEET_TURN_FRACTION` of `delta`).

    A turn is the whole body's: the supporting foot pivots (or the feet turn
    in the air).  Hips that twist over planted feet turn neither.  Each
    foot's heading is its median over `window` frames up to `a` (from
    frame `lo` on) and from `b` (up to frame `hi`), and may fall short by
    `noise` degrees (measured feet).  Feet not measured: no veto.
    """
    hi = feet.shape[0] - 1 if hi is None else hi
    before = np.nanmedian(feet[max(min(lo, a), a - window + 1) : a + 1], axis=0)
    after = np.nanmedian(feet[b : max(b + 1, min(b + window, hi + 1))], axis=0)
    d = after - before
    if not np.isfinite(d).any():
        return True
    return bool(np.nanmax(np.sign(delta) * d) >= FEET_TURN_FRACTION * abs(delta) - noise)


def turned_so_far(joints: np.ndarray, fps: float, measured: bool, turns: list[Movement] | None = None) -> np.ndarray:
    """(T,) degrees the dancer has turned by each frame: the front, held still outside turns.

    Clean motion's front changes only inside turns, so it is the front
    itself (from frame 0).  A measured front wanders by a few degrees
    between turns; that wander is not a turn, so outside the turns of
    :func:`turn_movements` the value is held (the smoothed front inside them).
    `turns` are those measured turns when the caller has already read them
    (``turn_movements(joints, fps, measured=True)``).
    """
    front = continuous_front(joints)
    T = front.size
    if T == 0 or not np.isfinite(front).any():
        return np.zeros(T)
    if not measured:
        return front - front[0]
    w = int(round(_SMOOTH_S * fps)) | 1
    smooth = savgol_filter(front, w, 2) if w >= 5 and w < T else front
    out = np.zeros(T)
    held, done = 0.0, 0
    for m in turn_movements(joints, fps, measured=True) if turns is None else turns:
        a, b = m.start_frame, min(m.end_frame, T - 1)
        out[done:a] = held
        # Inside the turn: the smoothed front, continuous at its start.
        out[a : b + 1] = held + smooth[a : b + 1] - smooth[a]
        held, done = float(out[b]), b + 1
    out[done:] = held
    return out
