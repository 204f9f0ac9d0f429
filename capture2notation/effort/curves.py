"""Progress curves of one movement from 3D joints (DESIGN.md, Effort model).

For a symbol of a gesture part, the moving extremity (the part's free joint)
travels relative to its bound joint: arm → wrist about the shoulder, leg →
ankle about the hip, upper arm → elbow, forearm → wrist about the elbow, head →
head about the neck (:data:`~capture2notation.notation.PART_SEGMENTS`).

The normalised progress ``s`` is measured on the direction of
(free − bound), which keeps the Space modulation (it changes only the
distance from the bound joint) out of Time and Weight; the distance is used
on its own for Space, as the radial deviation from the direct path.
Measures of progress along the direction's path:

* ``"circle"`` (default): the angle turned about the axis of the circle the
  direction traces (a plane fitted through the unit directions).  Exact for
  any rotation about a fixed axis — the virtual dancer swings a limb's frame
  about one axis, which moves the limb on a small circle when the frame
  twists — and for great circles; noise gives zero-mean errors.  When the
  fitted plane is ill-determined (short or noisy paths) it falls back to the
  great circle through the start and end directions.
* ``"chord"``: the angle from the start direction, divided by the angle
  between start and end.  Exact for a great-circle swing only.
* ``"arc"``: the angular arc length travelled, divided by the total.  Exact
  for any path traversed at a speed proportional to ds/dτ, but noise adds
  up along the path (a positive bias where the extremity is slow), so it
  suits clean data only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body import JOINTS
from ..errors import EffortError
from ..notation.model import PART_MIDDLE_JOINT, PART_SEGMENTS

__all__ = [
    "END_DROP",
    "MAX_CURVE_POINTS",
    "MAX_EXTEND",
    "MIN_ANGLE_DEG",
    "MIN_FRAMES",
    "MIN_TURN_COS",
    "MOVING_FRACTION",
    "NOISE_SIGMAS",
    "REACH_MARGIN",
    "SNAP_S",
    "START_FRACTION",
    "ProgressCurve",
    "limb_reach",
    "part_constants",
    "progress_curve",
    "refine_window",
    "resample_curve",
]

#: A movement whose direction turns by less than this is "held" (no curve).
MIN_ANGLE_DEG = 5.0
#: Fewest interior frames for a curve (the model has two shape parameters).
MIN_FRAMES = 4
#: Largest distance, seconds, at which a window end is moved onto a frame:
#: half a frame of the virtual dancer's 25 Hz source, which starts and ends
#: movements on the nearest frame.
SNAP_S = 0.5 / 25.0
#: Fraction of the straight limb's length an outward Space modulation
#: reaches (eq. 5.6's "full reach"): a fully straight limb is a singular pose,
#: so the virtual dancer (``synthetic.limbs.apply_move``) stops 0.1 % short.
REACH_MARGIN = 0.999
#: Window refinement (:func:`refine_window`): an edge is moved outward only
#: over frames where the extremity turns faster than this fraction of the
#: movement's peak angular speed inside the given window.
MOVING_FRACTION = 0.1
#: The start is followed down its (monotone) rising flank to this fraction of
#: the peak speed, or to the jitter floor (:func:`_speed_noise`) if higher.
#: 0: the logistic starts from rest, and a level cut off its slow first part
#: biases b (a start 3 frames late of 50 reads b = −3.4 as −2.9); a hold, the
#: previous movement's stop (speed rising outward) or a corner of the path
#: ends the flank.
START_FRACTION = 0.0
#: Largest outward move of each window edge, as a fraction of the window's
#: duration (a captured symbol rarely misses more than a quarter beat of a
#: 1-beat movement at either end).
MAX_EXTEND = 0.5
#: At a movement's end the logistic stops with finite speed (or the next
#: movement starts from rest), so the speed drops suddenly: an end is not
#: moved over a frame whose speed is below this fraction of the previous one.
END_DROP = 0.5


@dataclass(frozen=True)
class ProgressCurve:
    """Observed progress of one movement.

    Attributes
    ----------
    part : str
        Gesture part of the symbol.
    t_start, t_end : float
        Window of the movement, seconds.
    tau : (N,) ndarray
        Normalised time of the interior frames, in (0, 1).
    s : (N,) ndarray
        Normalised progress at those frames (0 at τ = 0, 1 at τ = 1).
    weight : (N,) ndarray
        Per-frame confidence in (0, 1] (min over the two joints); weights the
        likelihood (variance ∝ 1 / weight).
    radial : (N,) ndarray
        Radial deviation ``r / r_direct − 1`` of the extremity's distance from
        the bound joint against the direct path (distance interpolated
        between the endpoints in step with the progress).
    angle : float
        Total angle turned by the segment's direction, radians.
    outward : (N,) ndarray or None
        Radial deviation the outward modulation (eq. 5.6) reaches at full
        depth, ``reach / r_direct − 1`` (≥ 0), for whole limbs; None for
        parts whose free joint keeps its distance from the bound joint (head,
        chest, single segments), which cannot show Space.
    """

    part: str
    t_start: float
    t_end: float
    tau: np.ndarray
    s: np.ndarray
    weight: np.ndarray
    radial: np.ndarray
    angle: float
    outward: np.ndarray | None = None

    @property
    def shows_space(self) -> bool:
        """True for whole limbs, whose reach the Space modulation changes."""
        return self.outward is not None


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between unit vectors (N, 3) row by row, radians; atan2 stays accurate for tiny angles."""
    cross = np.linalg.norm(np.cross(a, b), axis=1)
    return np.arctan2(cross, np.einsum("ij,ij->i", np.broadcast_to(a, b.shape), b))


def _snap(t: float, times: np.ndarray, tol: float) -> float:
    """Time of the frame nearest `t` (ties to the later frame) if within `tol` s, else `t`."""
    k = int(np.clip(np.searchsorted(times, t), 1, times.size - 1))
    near = float(times[k] if times[k] - t <= t - times[k - 1] + 1e-9 else times[k - 1])
    return near if abs(near - t) <= tol + 1e-9 else float(t)


def _circle_angle(u: np.ndarray) -> np.ndarray:
    """Angle turned about the axis of the circle through unit vectors `u` (N, 3), from u[0]; radians (N,)."""
    centre = u.mean(axis=0)
    _, sv, vt = np.linalg.svd(u - centre, full_matrices=False)
    normal = vt[2]
    # a plane through a short or noisy path is ill-determined: use the great
    # circle through the ends instead
    if not (sv[1] > 4.0 * sv[2] and sv[1] > 0.02 * sv[0]):
        normal = np.cross(u[0], u[-1])
        normal /= np.linalg.norm(normal)
    inplane = u - np.outer(u @ normal, normal)
    e1 = inplane[0] / np.linalg.norm(inplane[0])
    e2 = np.cross(normal, e1)
    phi = np.unwrap(np.arctan2(inplane @ e2, inplane @ e1))
    return phi * np.sign(phi[-1])


def _endpoint(t, times, rel, conf, ok, where, inward: int):
    """Segment vector at time `t` from the two nearest valid frames inside the window.

    The logistic's speed jumps at a movement's end (the part stops or a new
    movement starts), so the end is extrapolated from inside the window
    rather than interpolated across it; `inward` is +1 at the start (frames
    at or after `t`) and −1 at the end (frames at or before `t`).

    Returns (vector (3,), confidence) or raises EffortError naming the frames.
    """
    dt = float(np.median(np.diff(times))) if times.size > 1 else 1.0
    tol = 1e-6 * dt
    side = (times >= t - tol) if inward > 0 else (times <= t + tol)
    cand = np.flatnonzero(ok & side)
    cand = cand[np.argsort(np.abs(times[cand] - t))][:2]
    if cand.size < 2 or np.abs(times[cand] - t).max() > 2.5 * dt:
        raise EffortError(
            f"{where}: no valid frame within {2.5 * dt:.3f} s of t={t:.3f} s to fix the movement's "
            f"{'start' if inward > 0 else 'end'}"
        )
    i0, i1 = cand
    if abs(times[i0] - t) <= tol:
        return rel[i0], conf[i0]
    w = (t - times[i0]) / (times[i1] - times[i0])
    return (1 - w) * rel[i0] + w * rel[i1], min(conf[i0], conf[i1])


def _interval_speed(u: np.ndarray, good: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Angular speed (rad/s) of unit directions `u` (T, 3) over each frame interval (T−1,).

    Unsmoothed: a smoothing kernel would spread a movement's abrupt stop
    into the next interval and move exact (truth) windows.  Intervals
    touching an invalid frame get NaN (never bridged).
    """
    speed = _angle(u[:-1], u[1:]) / np.diff(times)
    return np.where(good[:-1] & good[1:], speed, np.nan)


#: An edge moves over a step only if the path does not turn by more than
#: 45° there (cosine between successive displacements): within a movement
#: the extremity's path is smooth, between two movements it has a corner.
MIN_TURN_COS = np.cos(np.radians(45.0))
#: Jitter-driven speed is ignored up to this many of its standard deviations
#: (``refine_window``): a 2-D Gaussian's norm exceeds 3 sd with p ≈ 1 %.
NOISE_SIGMAS = 3.0


def _speed_noise(u: np.ndarray, good: np.ndarray, dt: float) -> float:
    """Speed (rad/s) up to which frame-to-frame jitter of directions `u` (T, 3) explains a step.

    The jitter σ (rad, per tangent component) is read from the third
    differences of the direction, whose jitter part has sd √20·σ per
    component while a smooth movement adds almost nothing (jerk·Δt³; second
    differences would count a fast movement's acceleration as noise);
    robust median, the norm of a 2-D Gaussian having median 1.177 sd.  A
    step's jitter has sd √2·σ per component; :data:`NOISE_SIGMAS` of it,
    divided by the frame step, is returned (≈ 0 for noise-free data).
    """
    ok = good[3:] & good[2:-1] & good[1:-2] & good[:-3]
    if not ok.any():
        return 0.0
    d3 = np.linalg.norm(u[3:] - 3.0 * u[2:-1] + 3.0 * u[1:-2] - u[:-3], axis=1)[ok]
    sigma = float(np.median(d3)) / (1.177 * np.sqrt(20.0))
    return NOISE_SIGMAS * np.sqrt(2.0) * sigma / dt


def refine_window(
    joints: np.ndarray,
    confidence: np.ndarray | None,
    times: np.ndarray,
    part: str,
    t_start: float,
    t_end: float,
    bounds: tuple = (-np.inf, np.inf),
    joint_names=JOINTS,
    moving: float = MOVING_FRACTION,
    max_extend: float = MAX_EXTEND,
    noise: float | None = None,
) -> tuple:
    """Move a movement window's edges outward to where the extremity really starts and stops.

    Windows of a *captured* score (symbol start and end quantised from the
    fitted joints) are often cut short or shifted by a fraction of a beat; a
    progress curve measured from a late start or to an early end looks more
    linear (b less negative) and shifts x0.  The extremity's own motion says
    where the movement is, so each edge is moved outward over the frames on
    which the segment's direction is still clearly turning as part of this
    movement:

    * start: back over frame intervals whose angular speed exceeds
      :data:`START_FRACTION` × the peak speed inside the window *and* keeps
      falling outward (the
      rising flank of this movement; a hold or the previous movement's
      abrupt stop ends it);
    * end: forward over intervals faster than `moving` × peak, without a
      sudden drop (below :data:`END_DROP` of the previous interval: the
      logistic stops with finite speed, or the next movement starts from
      rest) and, after the first step, without rising again (a new
      movement);
    * both: only where the path turns by less than 45° from one step to
      the next (:data:`MIN_TURN_COS`): a boundary between movements is a
      corner of the extremity's path.

    Edges never move inward: the logistic starts from rest (ds/dτ = 0 at
    τ = 0), so a slow start is indistinguishable from a hold by speed, and
    only the score can place it.  A window taken from a clean render
    (truth score) is therefore left unchanged: before its start the part
    holds or the previous movement stops abruptly, after its end the speed
    drops suddenly.  Speeds are frame to frame (unsmoothed); missing frames
    stop the search; jitter is kept from moving an edge by a speed floor
    estimated from the data (:func:`_speed_noise`).  An edge between frames starts the search from the
    nearest frame inside the window.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres; NaN where missing.
    confidence : (T, J) ndarray or None
        Per-frame confidence; frames with 0 are invalid.
    times : (T,) ndarray
        Frame times, seconds.
    part : str
        Gesture part (key of ``PART_SEGMENTS``).
    t_start, t_end : float
        Window from the score, seconds.
    bounds : (float, float)
        Limits no edge may cross, seconds (e.g. the middle of the
        neighbouring movements of the same part).
    joint_names : sequence of str
    moving : float
        Fraction of the peak speed above which an end is moved outward.
    max_extend : float
        Largest move of each edge, as a fraction of ``t_end − t_start``.
    noise : float, optional
        The jitter speed floor, rad/s (:func:`part_constants`), when the
        arrays are a slice of a longer clip: the floor is the whole clip's.
        Default: estimated from the given frames.

    Returns
    -------
    t_start, t_end : float
        Refined window, seconds (the given values where nothing moved).
    """
    names = list(joint_names)
    if part not in PART_SEGMENTS or not all(j in names for j in PART_SEGMENTS[part]):
        return float(t_start), float(t_end)
    bound, free = (names.index(j) for j in PART_SEGMENTS[part])
    times = np.asarray(times, dtype=float)
    rel = np.asarray(joints, dtype=float)[:, free] - np.asarray(joints, dtype=float)[:, bound]
    good = np.all(np.isfinite(rel), axis=1)
    if confidence is not None:
        conf = np.nan_to_num(np.asarray(confidence, dtype=float), nan=0.0)
        good &= np.minimum(conf[:, free], conf[:, bound]) > 0
    norm = np.linalg.norm(np.nan_to_num(rel), axis=1)
    good &= norm > 1e-6
    if times.size < 3 or good.sum() < 3:
        return float(t_start), float(t_end)
    u = np.nan_to_num(rel) / np.where(norm > 1e-6, norm, 1.0)[:, None]
    speed = _interval_speed(u, good, times)  # (T-1,), interval k = [times[k], times[k+1]]
    dt = float(np.median(np.diff(times)))
    if noise is None:
        noise = _speed_noise(u, good, dt)
    tol = 1e-6 * dt
    # the nearest frames inside the window (the edges themselves when snapped)
    i0 = int(np.searchsorted(times, t_start - tol))
    i1 = int(np.searchsorted(times, t_end + tol)) - 1
    on0 = 0 < i0 < i1
    on1 = i0 < i1 < times.size - 1
    inside = speed[i0 : max(i1, i0)]
    if inside.size == 0 or not np.any(np.isfinite(inside)):
        return float(t_start), float(t_end)
    # cosine between successive steps' displacements (T-2,): a movement's
    # path is smooth, a boundary between two movements is a corner
    step = np.diff(u, axis=0)
    step /= np.maximum(np.linalg.norm(step, axis=1, keepdims=True), 1e-12)
    turn = np.einsum("ij,ij->i", step[:-1], step[1:])
    peak = float(np.nanmax(inside))
    # jitter alone must not move an edge: both floors at least NOISE_SIGMAS
    # noise levels above the speed that frame-to-frame jitter gives
    floor = max(moving * peak, noise)
    floor0 = max(START_FRACTION * peak, noise)
    reach = max_extend * (t_end - t_start)
    lo = max(t_start - reach, bounds[0])
    hi = min(t_end + reach, bounds[1])
    new0, new1 = float(t_start), float(t_end)
    if on0:
        k = i0 - 1  # interval ending at the edge
        # the rising flank may be followed far down (the logistic starts from
        # rest): its monotone fall, not a speed level, marks this movement
        while (
            k >= 0 and times[k] >= lo - tol and speed[k] > floor0 and speed[k] < speed[k + 1] and turn[k] > MIN_TURN_COS
        ):
            k -= 1
        new0 = min(float(times[k + 1]), new0) if k + 1 < i0 else new0
    if on1:
        k = i1  # interval starting at the edge
        while (
            k < speed.size
            and times[k + 1] <= hi + tol
            and speed[k] > floor
            and speed[k] >= END_DROP * speed[k - 1]
            and (k == i1 or speed[k] <= speed[k - 1])
            and turn[k - 1] > MIN_TURN_COS
        ):
            k += 1
        new1 = max(float(times[k]), new1) if k > i1 else new1
    return new0, new1


def limb_reach(joints: np.ndarray, ok: np.ndarray, bound: int, middle: int, free: int) -> float:
    """Length of the straight limb bound → middle → free, metres (NaN if unmeasured).

    The median of each segment's length over the valid frames `ok` (T,)
    bool: fitted skeletons keep per-clip bone lengths, and the median shrugs
    off frames where a joint is lost.
    """
    upper = np.linalg.norm(joints[:, middle] - joints[:, bound], axis=1)
    lower = np.linalg.norm(joints[:, free] - joints[:, middle], axis=1)
    good = ok & np.isfinite(upper) & np.isfinite(lower)
    if not good.any():
        return float("nan")
    return float(np.median(upper[good]) + np.median(lower[good]))


def progress_curve(
    joints: np.ndarray,
    confidence: np.ndarray | None,
    times: np.ndarray,
    part: str,
    t_start: float,
    t_end: float,
    joint_names=JOINTS,
    method: str = "circle",
    snap: float = SNAP_S,
    reach: float | None = None,
) -> ProgressCurve | None:
    """Progress curve of `part` over the window [t_start, t_end] seconds.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres; NaN where missing.
    confidence : (T, J) ndarray or None
        Per-frame confidence in [0, 1]; frames with 0 (or NaN positions) are
        dropped, never filled.  None means all ones.
    times : (T,) ndarray
        Frame times, seconds, increasing.
    part : str
        A gesture part (key of ``PART_SEGMENTS``).
    t_start, t_end : float
        Movement window, seconds.
    joint_names : sequence of str
        Names of the J joints.
    method : {"circle", "chord", "arc"}
        Measure of progress (module docstring).
    snap : float
        Move a window end onto the nearest frame (ties to the later one) when
        that frame is within `snap` seconds, as the virtual dancer places a
        movement's key frames (``synthetic.interpret.beat_frame``); other
        ends (e.g. in decimated captures) are extrapolated from the nearest
        frames inside the window.  0 disables snapping.
    reach : float, optional
        The straight limb's length, metres (:func:`part_constants`), when
        the arrays are a slice of a longer clip.  Default: measured on the
        given frames (:func:`limb_reach`).

    Returns
    -------
    ProgressCurve or None
        None when the segment turns by less than :data:`MIN_ANGLE_DEG`
        (a held part has no progress to measure).

    Raises
    ------
    EffortError
        Unknown part, bad shapes, or too few valid frames in the window.
    """
    where = f"{part} movement {t_start:.3f}-{t_end:.3f} s"
    if method not in ("circle", "chord", "arc"):
        raise EffortError(f"progress method must be 'circle', 'chord' or 'arc', got {method!r}")
    if part not in PART_SEGMENTS:
        raise EffortError(f"{where}: part {part!r} has no moving extremity; expected one of {', '.join(PART_SEGMENTS)}")
    joints = np.asarray(joints, dtype=float)
    times = np.asarray(times, dtype=float)
    if joints.ndim != 3 or joints.shape[2] != 3 or joints.shape[0] != times.shape[0]:
        raise EffortError(f"joints must be (T, J, 3) with T = len(times) = {times.shape[0]}, got {joints.shape}")
    if not t_end > t_start:
        raise EffortError(f"{where}: window must have t_end > t_start")
    names = list(joint_names)
    bound, free = (names.index(j) if j in names else -1 for j in PART_SEGMENTS[part])
    if bound < 0 or free < 0:
        raise EffortError(f"{where}: joints {PART_SEGMENTS[part]} not among the capture's joint names")
    rel = joints[:, free] - joints[:, bound]
    if confidence is None:
        conf = np.ones(times.shape[0])
    else:
        confidence = np.asarray(confidence, dtype=float)
        if confidence.shape != joints.shape[:2]:
            raise EffortError(f"confidence must be (T, J) = {joints.shape[:2]}, got {confidence.shape}")
        conf = np.minimum(confidence[:, free], confidence[:, bound])
    conf = np.nan_to_num(conf, nan=0.0)
    ok = np.all(np.isfinite(rel), axis=1) & (conf > 0) & (np.linalg.norm(np.nan_to_num(rel), axis=1) > 1e-6)

    if snap > 0:
        t_start, t_end = _snap(t_start, times, snap), _snap(t_end, times, snap)
        if not t_end > t_start:
            raise EffortError(f"{where}: shorter than one frame")
    v0, _ = _endpoint(t_start, times, rel, conf, ok, where, +1)
    v1, _ = _endpoint(t_end, times, rel, conf, ok, where, -1)
    duration = t_end - t_start
    tau_all = (times - t_start) / duration
    inner = ok & (tau_all > 1e-9) & (tau_all < 1 - 1e-9)
    idx = np.flatnonzero(inner)
    if idx.size < MIN_FRAMES:
        raise EffortError(f"{where}: only {idx.size} valid frames inside the movement, need at least {MIN_FRAMES}")
    path = np.vstack([v0, rel[idx], v1])  # (N+2, 3)
    radius = np.linalg.norm(path, axis=1)
    u = path / radius[:, None]
    if np.degrees(_angle(u[:1], u[-1:])[0]) < MIN_ANGLE_DEG:
        return None
    if method == "arc":
        arc = np.concatenate([[0.0], np.cumsum(_angle(u[:-1], u[1:]))])
    elif method == "chord":
        arc = _angle(u[:1], u)
    else:
        arc = _circle_angle(u)
    total = float(arc[-1])
    s = arc / total
    r_direct = radius[0] + (radius[-1] - radius[0]) * s
    radial = radius / r_direct - 1.0
    outward = None
    middle = names.index(PART_MIDDLE_JOINT[part]) if PART_MIDDLE_JOINT.get(part) in names else -1
    if middle >= 0:
        if reach is None:
            reach = limb_reach(joints, ok, bound, middle, free)
        reach = REACH_MARGIN * reach
        # a limb already straight at both ends (or an unmeasured reach) has
        # no outward room: depth 0, and Space is read from inward pulls only
        outward = np.maximum(np.nan_to_num(reach / r_direct[1:-1] - 1.0, nan=0.0), 0.0)
    return ProgressCurve(
        part=part,
        t_start=float(t_start),
        t_end=float(t_end),
        tau=tau_all[idx],
        s=s[1:-1],
        weight=conf[idx],
        radial=radial[1:-1],
        angle=total,
        outward=outward,
    )


def part_constants(joints, confidence, times, part: str, joint_names=JOINTS) -> tuple:
    """Whole-clip quantities of one part that its movements share: (jitter speed floor, limb reach).

    :func:`refine_window` and :func:`progress_curve` read them from the
    arrays they are given; computed once here, every movement can be
    measured on a slice of frames around its own window, so measuring M
    movements of a T-frame clip costs O(T), not O(M·T).

    Returns
    -------
    noise : float or None
        :func:`_speed_noise` over the whole clip, rad/s (None: part unknown).
    reach : float or None
        :func:`limb_reach`, metres (None for parts without a middle joint).
    """
    names = list(joint_names)
    if part not in PART_SEGMENTS or not all(j in names for j in PART_SEGMENTS[part]):
        return None, None
    bound, free = (names.index(j) for j in PART_SEGMENTS[part])
    joints = np.asarray(joints, dtype=float)
    times = np.asarray(times, dtype=float)
    rel = joints[:, free] - joints[:, bound]
    fin = np.all(np.isfinite(rel), axis=1)
    if confidence is None:
        conf = np.ones(times.shape[0])
    else:
        c = np.nan_to_num(np.asarray(confidence, dtype=float), nan=0.0)
        conf = np.minimum(c[:, free], c[:, bound])
    norm = np.linalg.norm(np.nan_to_num(rel), axis=1)
    good = fin & (conf > 0) & (norm > 1e-6)
    noise = None
    if times.size >= 3 and good.sum() >= 3:
        u = np.nan_to_num(rel) / np.where(norm > 1e-6, norm, 1.0)[:, None]
        noise = _speed_noise(u, good, float(np.median(np.diff(times))))
    reach = None
    middle = names.index(PART_MIDDLE_JOINT[part]) if PART_MIDDLE_JOINT.get(part) in names else -1
    if middle >= 0:
        reach = limb_reach(joints, good, bound, middle, free)
    return noise, reach


#: Largest number of samples a movement's curve keeps (:func:`resample_curve`):
#: the posterior's cost is proportional to it, so capping it makes Effort's
#: cost independent of the frame rate.  48 keeps every 25-fps movement of up
#: to two beats at 60 bpm (≤ 49 interior frames) as measured.
MAX_CURVE_POINTS = 48


def _equal_bins(tau: np.ndarray, m: int) -> tuple[np.ndarray, int]:
    """Bin index of each sample, and the number of bins: runs of `m` consecutive samples.

    Bins never span a gap of lost frames (a step over 1.5 times the median);
    a run of samples is cut into ceil(len / m) nearly equal blocks.
    """
    steps = np.diff(tau)
    breaks = np.flatnonzero(steps > 1.5 * np.median(steps)) + 1 if steps.size else np.array([], int)
    k = np.empty(tau.size, dtype=int)
    n_bins = 0
    for run in np.split(np.arange(tau.size), breaks):
        for block in np.array_split(run, -(-run.size // m)):
            k[block] = n_bins
            n_bins += 1
    return k, n_bins


def resample_curve(curve: ProgressCurve, n_points: int = MAX_CURVE_POINTS) -> ProgressCurve:
    """The curve averaged over runs of m consecutive frames, m = ceil(N / `n_points`) (unchanged when N ≤ `n_points`).

    Each bin holds the confidence-weighted means of its frames' τ, progress,
    radial and outward deviation, and the sum of their confidences divided
    by the fullest bin's frame count (a bin of k white-noise frames is worth
    k of them; weights stay in (0, 1]).  The likelihood's AR(1) correlation
    ρ is per median sample step (:class:`.likelihood.Batch`), so after
    resampling it is the correlation between neighbouring bins: the model
    follows the new spacing without a change.  That holds only if the bins
    are alike: bins of equal width in τ held one or two frames each for a
    curve of 49–95 frames (a two-beat movement at 60 bpm, 25 fps), spaced
    irregularly and weighted 0.5 or 1 as if the noise were white, and the
    90 % intervals of such movements covered 82 %.  So every bin takes
    the same number of frames (a run's blocks differ by at most one), and a
    bin never spans lost frames: the AR(1) chain spans the gap as it does a
    gap of frames.

    Parameters
    ----------
    curve : ProgressCurve
    n_points : int
        Most samples kept (≥ 4, :data:`MIN_FRAMES`); a gap of lost frames
        may add a bin.

    Returns
    -------
    ProgressCurve
    """
    if n_points < MIN_FRAMES:
        raise EffortError(f"a curve needs at least {MIN_FRAMES} points, got n_points={n_points}")
    n = curve.tau.size
    if n <= n_points:
        return curve
    # Every bin holds at least one sample.
    k, n_bins = _equal_bins(curve.tau, -(-n // n_points))
    count = np.bincount(k, minlength=n_bins)
    w = curve.weight
    wsum = np.bincount(k, w, n_bins)

    def mean(v):
        return np.bincount(k, w * v, n_bins) / wsum

    return ProgressCurve(
        part=curve.part,
        t_start=curve.t_start,
        t_end=curve.t_end,
        tau=mean(curve.tau),
        s=mean(curve.s),
        weight=wsum / count.max(),
        radial=mean(curve.radial),
        angle=curve.angle,
        outward=None if curve.outward is None else mean(curve.outward),
    )
