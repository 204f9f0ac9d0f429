"""Turns: the dancer's front over time, and the turns that change it.

The front is the hips' (``front_of(body_frame(joints)[:, 1])``, DESIGN.md
"Facing and turns"), unwrapped.  A body turns continuously: it does not turn
half way round between two frames, so a frame-to-frame change of front near
180° is a front/back confusion of the capture (a video's depth ambiguity
mirrors the hips), and is folded back (:func:`continuous_front`).

A turn is a window of rotation speed, cut like a gesture
(:func:`~.spans.movement_spans`): clean motion (the virtual dancer's truth,
exactly held outside turns) turns on every frame of a turn and not at all
elsewhere; back-to-back turns part only at a grid frame where the front
sits on an eighth.  Measured motion is smoothed and cut at speed minima,
and a measured turn must leave the front changed for half a second
(:data:`_HELD_S`): fitted hips swing out and back without the dancer turning.
The amount is the change of front rounded to eighths, ``right`` for
clockwise (increasing front); a change under half an eighth is no turn.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from scipy.signal import savgol_filter

from ..body import body_frame, front_of, joint_index
from ..notation.model import TURN_PART, TURN_STEP
from .movement import Movement
from .spans import movement_spans

__all__ = ["continuous_front", "turn_movements", "turned_so_far"]

#: Degrees in one eighth of a turn, the unit amounts are rounded to.
EIGHTH_DEG = 360.0 * float(TURN_STEP)
#: A frame-to-frame change of front larger than this (degrees) is a front/back
#: flip of the capture, not a turn: a fast pirouette (2 turns a second) turns
#: 29° a frame at 25 fps, far below; a mirrored pair of hips jumps ~180°.
FLIP_DEG = 120.0
#: A measured change of front must reach this many eighths (34°) to be a
#: turn: DESIGN.md's turn is at least an eighth, and a dancer's hips swing
#: 20-30° either way in a casual dance without the front changing; the
#: margin below 1 allows for the fit's ~10° error on a real eighth turn.
MIN_MEASURED_EIGHTHS = 0.75
#: A turn's feet turn too: one foot's heading changes by at least this
#: fraction of the hips' change (a pivoting foot turns with the body; hips
#: twisting over planted feet turn neither).
FEET_TURN_FRACTION = 0.5
#: Clean motion: a front this near (degrees) a multiple of an eighth may end
#: one turn and start the next (numerical noise of the truth is ~1e-10°).
_ON_EIGHTH_DEG = 0.05
#: Clean motion: rotation slower than this (degrees per second) is a hold.
_CLEAN_SPEED_DEG_S = 1e-4
#: Measured motion: hysteresis on the smoothed rotation speed, degrees per
#: second.  A written eighth turn over two beats at 60 bpm averages 22°/s;
#: fitted hips wander by a few degrees per second standing still.
_LOW_SPEED_DEG_S = 8.0
_HIGH_SPEED_DEG_S = 20.0
#: Measured motion: interior speed minima below this fraction of the
#: neighbouring peaks split two turns (at 0.35, 1 cm of jitter on the hips
#: split one half turn over two beats into 3/8 + 1/8).
_SPLIT_RATIO = 0.2
#: Measured motion: a turn changes the front for good, so the front over
#: this long after it (seconds) must differ from the front over this long
#: before it: fitted hips swing out and back 35-50° within half a second
#: (and a mirrored pair of hips turns half way and back), the dancer's
#: front not changing.  Half a second is a beat at 120 bpm.
_HELD_S = 0.5
#: Measured motion: a turn taken straight back is a swing of the fitted hips
#: only when it is smaller than this many eighths (67.5°): the fit's swings
#: measure 35-50°, while a quarter turn and straight back is danced.
SWING_MAX_EIGHTHS = 1.5
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
        Fitted or recorded motion (smoothed, cut at speed minima) rather
        than clean truth.
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
    if measured:
        w = int(round(_SMOOTH_S * fps)) | 1
        if w >= 5 and w < T:
            front = savgol_filter(front, w, 2)
        velocity = np.diff(front) * fps
        spans = _split_reversals(
            movement_spans(np.abs(velocity), _LOW_SPEED_DEG_S, _HIGH_SPEED_DEG_S, _SPLIT_RATIO), velocity, fps
        )
    else:
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
    feet = _feet_heading(joints)
    held = max(1, int(round(_HELD_S * fps)))
    out = []
    # Where the front was last held: a swing not taken for a turn does not
    # move it (the swing back must be measured from before the swing out).
    anchor, swing_end = 0, -(10**9)
    for i, (a, b) in enumerate(spans):
        if a - swing_end > held:
            anchor = a
        delta = float(front[b + 1] - front[a])
        eighths = int(round(delta / EIGHTH_DEG))
        if eighths == 0 or (measured and abs(delta) < MIN_MEASURED_EIGHTHS * EIGHTH_DEG):
            continue
        if measured and not _front_held(
            front, anchor, b + 1, delta, held, spans[i + 1] if i + 1 < len(spans) else None
        ):
            swing_end = b + 1
            continue
        if not _feet_turn_too(feet, a, b + 1, delta):
            continue
        out.append(
            Movement(
                TURN_PART,
                a,
                b + 1,
                a / fps,
                (b + 1) / fps,
                "right" if eighths > 0 else "left",
                "",
                amount=Fraction(abs(eighths)) * TURN_STEP,
            )
        )
    return out


def _split_reversals(spans: list[tuple[int, int]], velocity: np.ndarray, fps: float) -> list[tuple[int, int]]:
    """`spans` cut where the (smoothed) rotation turns back by a turn's worth: a turn turns one way.

    Without the cut, an eighth turn to the left run straight into two turns
    to the right is read as their net 15/8 to the right: the speed between
    them dips, but not below the split ratio of two so unequal peaks.  A
    stretch turning back by less than :data:`MIN_MEASURED_EIGHTHS` (the
    hips' wobble at the end of a turn) is no turn of its own and stays in.

    Parameters
    ----------
    spans : list of (a, b)
        Interval index ranges, inclusive.
    velocity : (N,) ndarray
        Smoothed rotation speed over each frame interval, degrees per second, signed.
    fps : float
    """
    least = MIN_MEASURED_EIGHTHS * EIGHTH_DEG
    out = []
    for a, b in spans:
        v = velocity[a : b + 1]
        starts = np.r_[0, np.flatnonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0) + 1]
        parts = [[int(lo), int(hi), float(v[lo:hi].sum()) / fps] for lo, hi in zip(starts, np.r_[starts[1:], v.size])]
        # Fold the smallest stretch into its neighbours until every one turns by a turn's worth.
        while len(parts) > 1:
            k = int(np.argmin([abs(p[2]) for p in parts]))
            if abs(parts[k][2]) >= least:
                break
            lo, hi = max(0, k - 1), min(len(parts), k + 2)
            parts[lo:hi] = [[parts[lo][0], parts[hi - 1][1], sum(p[2] for p in parts[lo:hi])]]
        out.extend((a + lo, a + hi - 1) for lo, hi, _ in parts)
    return out


def _front_held(front: np.ndarray, a: int, b: int, delta: float, window: int, following=None) -> bool:
    """Whether a measured turn from frame a to b leaves the front changed (see :data:`_HELD_S`).

    The median front over `window` frames after the turn must differ from
    the median over `window` frames before it by :data:`MIN_MEASURED_EIGHTHS`,
    the turn's way.  Another turn starting within the window (`following`,
    its span) ends it there, unless that turn only takes this one back (the
    front after both within the same margin of the front before) and this
    one is under :data:`SWING_MAX_EIGHTHS`: then the two are one swing out
    and back.
    """
    before = float(np.nanmedian(front[max(0, a - window + 1) : a + 1]))
    end = b + window
    if following is not None and following[0] < end:
        back = front[min(following[1] + 1, front.size - 1)] - before
        if abs(back) < MIN_MEASURED_EIGHTHS * EIGHTH_DEG and abs(delta) < SWING_MAX_EIGHTHS * EIGHTH_DEG:
            return False
        end = max(following[0], b + 1)
    after = float(np.nanmedian(front[b:end]))
    return bool(np.sign(delta) * (after - before) >= MIN_MEASURED_EIGHTHS * EIGHTH_DEG)


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


def _feet_turn_too(feet: np.ndarray, a: int, b: int, delta: float) -> bool:
    """Whether a foot turns with the hips between frames a and b (by :data:`FEET_TURN_FRACTION` of `delta`).

    A turn is the whole body's: the supporting foot pivots (or the feet turn
    in the air).  Hips that twist over feet that stay put are a movement
    of the pelvis, not a change of front.  Feet not measured: no veto.
    """
    d = feet[b] - feet[a]
    if not np.isfinite(d).any():
        return True
    return bool(np.nanmax(np.sign(delta) * d) >= FEET_TURN_FRACTION * abs(delta))


def turned_so_far(joints: np.ndarray, fps: float, measured: bool) -> np.ndarray:
    """(T,) degrees the dancer has turned by each frame: the front, held still outside turns.

    Clean motion's front changes only inside turns, so it is the front
    itself (from frame 0).  A measured front wanders by a few degrees
    between turns; that wander is not a turn, so outside the turns of
    :func:`turn_movements` the value is held (the smoothed front inside them).
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
    for m in turn_movements(joints, fps, measured=True):
        a, b = m.start_frame, min(m.end_frame, T - 1)
        out[done:a] = held
        # Inside the turn: the smoothed front, continuous at its start.
        out[a : b + 1] = held + smooth[a : b + 1] - smooth[a]
        held, done = float(out[b]), b + 1
    out[done:] = held
    return out
