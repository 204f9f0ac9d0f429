"""Flight: ``support air`` where both feet leave the floor, and the landing after it.

DESIGN.md ("Facing and turns", the ``.lab`` extension for ``support air``)
and ``docs/benchmarks/turns.md`` fix what is written:

* ``support air`` runs from the **take-off** frame (the last frame with a
  foot on the floor) to the **touchdown** frame (the first with one again);
  no foot is on the floor strictly between.
* The **landing** support starts at touchdown and ends where the pelvis
  comes to rest (a local minimum of its speed; at a frame of the beat grid
  for clean motion); its part is the feet on the floor at touchdown, its
  level the one held there (``low`` for a plié), its direction the landing
  feet's displacement from where they took off — a foot that was
  gesturing at take-off from beside the take-off foot, at the hips' width —
  in the body frame at take-off, ``place`` under half a step.
* The support before the flight arrives at the take-off frame.
* Spring forms are not written: they follow from the supports before and
  after (:func:`capture2notation.notation.facing.spring_form`).

The supports' own segmentation (:mod:`.supports`) reads the floor; this
module rewrites its movements around each flight found.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..body import body_frame, joint_index
from ..fitting.ground import DRIFT_WINDOW_S, GROUND_QUANTILE, running_quantile
from ..notation.directions import classify_indices
from ..notation.model import AIR, LEVELS
from .labels import DIRECTION_NAMES, SUPPORT_HEIGHT_M, FrameLabels, foot_points
from .movement import Movement
from .spans import true_runs
from .support_state import STEP_MIN_FRACTION, step_direction, support_state

__all__ = ["find_flights", "landing_rest", "with_flights"]

#: Shortest flight of clean motion, frames: one frame clear of the floor.
_MIN_CLEAN_FRAMES = 1
#: Shortest flight of measured motion, seconds: a jump of 5 cm of foot
#: clearance lasts 0.2 s; shorter gaps are contact flicker of a fit.
MIN_MEASURED_FLIGHT_S = 0.2
#: Longest stretch with a foot not seen that a flight is followed through,
#: seconds: the half turn of a 0.45-s spring hid a foot for 0.2 s on the
#: development renders.  A touch-down hidden in it is caught by the
#: pelvis, which cannot fall freely across a landing.
UNSEEN_BRIDGE_S = 0.3
#: Longest landing, seconds: a landing comes to rest within two beats at 60 bpm.
_MAX_LANDING_S = 2.0
#: A landing comes to rest at a pelvis speed minimum below this fraction of
#: its speed since touchdown (the plié's dip slows it to ~0.2 of it).
_REST_FRACTION = 0.1
#: Gravity, m/s².
GRAVITY_MS2 = 9.81
#: A flight's pelvis accelerates downwards by at least this fraction of g on
#: average (a ballistic pelvis: 1; a walk's pelvis: near 0 either way).
BALLISTIC_FRACTION = 0.5
_SUPPORT_PARTS = ("support", "right_support", "left_support")
#: Measured motion: a fitted jump's feet can float a few centimetres before
#: take-off and after the landing (its pliés), so both feet stay clear well
#: beyond the flight and the pelvis over all of it is not ballistic.  Its
#: core, where both feet clear this fraction of their highest, lies inside
#: the flight (a free fall spends 71 % of its time above half its height),
#: and a pelvis in free fall is ballistic over any part of its flight.
CORE_FRACTION = 0.5


def find_flights(
    joints: np.ndarray, fps: float, measured: bool, floor: float = 0.0, seen=None
) -> list[tuple[int, int]]:
    """``(take_off, touchdown)`` frames of every flight.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up (smoothed for measured motion).
    fps : float
    measured : bool
        Fitted or recorded motion: flights must last :data:`MIN_MEASURED_FLIGHT_S`.
    floor : float
        Floor height, metres.
    seen : (T, 2) array_like of bool, optional
        Right, left foot measured at each frame; a foot not seen counts as
        unknown, like a missing one.

    Returns
    -------
    list of (int, int)
        Frames; only flights with a foot on the floor before and after.
    """
    low, _ = foot_points(np.asarray(joints, float))
    ground = _local_floor(low, fps, floor) if measured else floor
    # Both feet clear of the floor; a frame with a foot not seen is unknown.
    clearance = np.min(np.stack([lo - ground for lo in low]), axis=0)
    clear = clearance >= SUPPORT_HEIGHT_M
    known = np.ones(clear.shape, bool) if seen is None else np.asarray(seen, bool).all(axis=1)
    air = clear & known
    # A spinning jump hides a foot for a few frames: next to frames seen in
    # the air, an unseen foot is taken where the fit puts it, and the
    # pelvis must then fall freely across the whole run (fitted feet that
    # float before a take-off would otherwise stretch a flight back into its
    # plié; two hops would not make one parabola).
    bridged = _bridged(air, clear & ~known, int(np.floor(UNSEEN_BRIDGE_S * fps + 1e-9)))
    shortest = max(_MIN_CLEAN_FRAMES, int(np.ceil(MIN_MEASURED_FLIGHT_S * fps))) if measured else _MIN_CLEAN_FRAMES
    out = []
    for a, b in true_runs(bridged):
        if _flight(joints, a - 1, b, shortest, fps):
            out.append((a - 1, b))
            continue
        # Not ballistic as a whole: its seen airborne runs, each on its own.
        runs = [(a + c - 1, a + d) for c, d in true_runs(air[a:b])]
        found = [(t0, t1) for t0, t1 in runs if _flight(joints, t0, t1, shortest, fps)]
        if not found and measured:
            # Or the jump at its core, the feet's floating pliés left out.
            c, d = _core(clearance[a:b])
            if _flight(joints, a + c - 1, a + d, shortest, fps):
                found = [(a + c - 1, a + d)]
        out += found
    return out


def _core(clearance: np.ndarray) -> tuple[int, int]:
    """The run ``[c, d)`` around the highest frame where `clearance` is at least :data:`CORE_FRACTION` of it."""
    peak = int(np.argmax(clearance))
    high = clearance >= CORE_FRACTION * clearance[peak]
    c, d = peak, peak + 1
    while c > 0 and high[c - 1]:
        c -= 1
    while d < high.size and high[d]:
        d += 1
    return c, d


def _flight(joints: np.ndarray, t0: int, t1: int, shortest: int, fps: float) -> bool:
    """Whether take-off `t0` and touchdown `t1` frame a flight: inside the clip, long enough, ballistic."""
    return t0 >= 0 and t1 < joints.shape[0] and t1 - t0 - 1 >= shortest and _ballistic(joints, t0, t1, fps)


def _bridged(air: np.ndarray, maybe: np.ndarray, longest: int) -> np.ndarray:
    """`air` (T,) with each run of `maybe` frames, at most `longest` long, that touches an airborne frame set."""
    out = air.copy()
    for a, b in true_runs(maybe):
        if b - a <= longest and ((a > 0 and air[a - 1]) or (b < air.size and air[b])):
            out[a:b] = True
    return out


def _local_floor(low, fps: float, floor: float) -> np.ndarray:
    """(T,) the floor measured feet stand on about each frame, never below `floor`.

    A low quantile (:data:`~capture2notation.fitting.ground.GROUND_QUANTILE`)
    of the lowest foot point over
    :data:`~capture2notation.fitting.ground.DRIFT_WINDOW_S`, longer than any
    jump.  Why: a single view's fitted feet float 2-11 cm above the clip's
    floor for seconds at a time (the camera's pitch, estimated from the
    person, couples their height to their depth), so against the clip's one
    floor both feet stayed "clear" from well before a take-off to well after
    the landing, and the flight's pelvis no longer looked ballistic.
    """
    lowest = np.fmin(np.asarray(low[0], float), np.asarray(low[1], float))  # NaN only where neither foot is
    if not np.isfinite(lowest).any():
        return np.full(lowest.shape, float(floor))
    width = max(3, int(round(DRIFT_WINDOW_S * fps)))
    t = np.arange(lowest.size)
    ok = np.isfinite(lowest)
    filled = np.interp(t, t[ok], lowest[ok])  # an unseen stretch takes its neighbours' floor
    run = (
        running_quantile(filled, width, GROUND_QUANTILE)
        if filled.size > width
        else np.full(filled.size, np.quantile(filled, GROUND_QUANTILE))
    )
    return np.maximum(float(floor), run)


def _ballistic(joints: np.ndarray, t0: int, t1: int, fps: float) -> bool:
    """Whether the pelvis falls freely between take-off `t0` and touchdown `t1`.

    Both feet can clear the floor's 3 cm for a frame or two in a quick step
    (the back foot's toe lifts as the front foot lands), or float a few
    centimetres above a floor found a little low; the pelvis then moves
    smoothly.  In flight it rises and falls on a parabola: over a flight of
    ``D`` seconds it peaks ``g D² / 8`` above the line from take-off to
    touchdown, so its mean vertical acceleration is ``−8 · rise / D²``,
    near −g.  The rise is what a fitted pelvis keeps best; its velocities
    at take-off and touchdown are smoothed away by the fit's priors.
    """
    z = joints[t0 : t1 + 1, joint_index("pelvis"), 2]
    if z.size < 3 or not np.isfinite(z).all():
        return True
    seconds = (z.size - 1) / fps
    line = np.linspace(z[0], z[-1], z.size)
    acc = -8.0 * float(np.max(z - line)) / seconds**2
    return bool(acc <= -BALLISTIC_FRACTION * GRAVITY_MS2)


def landing_rest(joints: np.ndarray, t1: int, fps: float, on_grid: np.ndarray | None) -> int:
    """First frame after touchdown `t1` where the pelvis comes to rest (a speed minimum): the landing's end."""
    p = joints[:, joint_index("pelvis")]
    s = np.linalg.norm(np.diff(p, axis=0), axis=-1) * fps  # interval i: frames i → i+1
    T = p.shape[0]
    last = min(T - 1, t1 + int(round(_MAX_LANDING_S * fps)))
    peak = 0.0
    for f in range(t1 + 1, last + 1):
        m = f - 1  # the interval arriving at f
        if m + 1 >= s.size:
            return T - 1
        peak = max(peak, float(s[m]))
        # A deep minimum: the dip of a plié absorbing the landing slows the
        # pelvis too, but only to a fifth of its touchdown speed.
        deep = s[m + 1] <= _REST_FRACTION * peak
        # The bottom of that dip (the pelvis stops sinking and rises again)
        # is no rest, however slow: a landing on the spot passes through it
        # at almost no speed.
        bottom = p[f, 2] < p[f - 1, 2] and p[min(f + 2, T - 1), 2] > p[f + 1, 2]
        if s[m + 1] <= 1e-9 or (deep and not bottom and s[m] >= s[m + 1] <= s[min(m + 2, s.size - 1)]):
            g = f + 1 if s[m + 1] > 1e-9 else f
            for cand in (g, g - 1, g + 1):
                if t1 < cand < T and (on_grid is None or on_grid[cand]):
                    return cand
    return last


def _landing_direction(joints: np.ndarray, t0: int, t1: int, feet: tuple[int, ...], height: float) -> str:
    """Where the landing feet came down relative to where they took off, in the body frame at take-off."""
    _, mids = foot_points(joints)
    low, _ = foot_points(joints)
    frame = body_frame(joints[t0 : t0 + 1])[0]
    on_floor = [bool(lo[t0] < SUPPORT_HEIGHT_M + 1e-9) for lo in low]
    hips = joints[t0, joint_index("right_hip")] - joints[t0, joint_index("left_hip")]
    width = float(np.hypot(hips[0], hips[1]))
    shifts = []
    for k in feet:
        if on_floor[k]:
            start = mids[k][t0]
        else:
            # A gesturing foot lands beside the take-off foot, at the hips' width.
            other = 1 - k
            side = 1.0 if k == 0 else -1.0  # right foot to the right
            start = mids[other][t0] + side * width * frame[0]
        shifts.append(mids[k][t1] - start)
    d = np.mean(shifts, axis=0)
    d[2] = 0.0
    if not np.linalg.norm(d) >= STEP_MIN_FRACTION * height:
        return "place"
    idx, _ = classify_indices((frame @ d)[None])
    name = DIRECTION_NAMES[int(idx[0])]
    return "place" if name == "place" else name


def with_flights(
    moves: list[Movement],
    labels: FrameLabels,
    joints: np.ndarray,
    fps: float,
    flights: list[tuple[int, int]],
    height: float,
    on_grid: np.ndarray | None = None,
) -> list[Movement]:
    """Support movements rewritten around each flight (see the module docstring).

    Parameters
    ----------
    moves : list of Movement
        Support movements (:func:`~.supports.support_movements`).
    labels : FrameLabels
        Their per-frame labels (feet contacts and levels).
    joints : (T, J, 3) ndarray
    fps : float
    flights : list of (int, int)
        :func:`find_flights`.
    height : float
        Body height, metres (a step is measured in heights).
    on_grid : (T,) ndarray of bool, optional
        Clean motion: the landing comes to rest on a grid frame.

    Returns
    -------
    list of Movement
        In time order.
    """
    if not flights:
        return moves
    part, level = support_state(labels, joints)
    low, _ = foot_points(joints)
    out = list(moves)
    for t0, t1 in flights:
        rest = landing_rest(joints, t1, fps, on_grid)
        kept = []
        for m in out:
            if m.end_frame <= t0 or m.start_frame >= rest:
                kept.append(m)
            elif m.start_frame < t0:
                # Arrives at the take-off: the state held there.
                p, lv = int(part[t0]), int(level[t0])
                if p >= 0:
                    step = step_direction(joints, labels, m.start_frame, t0, p, height)
                    kept.append(
                        Movement(_SUPPORT_PARTS[p], m.start_frame, t0, m.start_time, t0 / fps, step, LEVELS[lv])
                    )
                else:
                    # No foot on the floor by the labels (a fitted floor below
                    # the one the feet stand on there): a landing between two
                    # flights keeps its own reading, ended at the take-off.
                    kept.append(replace(m, end_frame=t0, end_time=min(m.end_time, t0 / fps)))
            elif m.end_frame > rest:
                kept.append(
                    Movement(m.part, rest, m.end_frame, rest / fps, m.end_time, m.direction, m.level, m.bend, m.amount)
                )
        feet = tuple(k for k in (0, 1) if low[k][t1] < SUPPORT_HEIGHT_M)
        at = np.array([low[0][t1], low[1][t1]], float)
        if not feet and np.isfinite(at).any():
            # Touchdown is where a foot reached the floor it stands on there
            # (:func:`_local_floor`); a fitted floor can lie below it.
            feet = (int(np.nanargmin(at)),)
        if not feet:
            out = kept
            continue
        landing_part = "support" if len(feet) == 2 else ("right_support", "left_support")[feet[0]]
        lv = int(level[rest]) if level[rest] >= 0 else int(np.max(labels.support_level[t1]))
        direction = _landing_direction(joints, t0, t1, feet, height)
        kept.append(Movement("support", t0, t1, t0 / fps, t1 / fps, AIR, ""))
        kept.append(Movement(landing_part, t1, rest, t1 / fps, rest / fps, direction, LEVELS[max(lv, 0)]))
        out = kept
    out.sort(key=lambda m: m.start_frame)
    # A support identical to the one just before it is no movement.
    deduped: list[Movement] = []
    for m in out:
        prev = deduped[-1] if deduped else None
        same = prev is not None and (prev.part, prev.level, prev.direction) == (m.part, m.level, m.direction)
        if same and m.direction == "place":
            continue
        deduped.append(m)
    return deduped
