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

__all__ = ["MIN_ANGLE_DEG", "MIN_FRAMES", "REACH_MARGIN", "SNAP_S", "ProgressCurve", "limb_reach", "progress_curve"]

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
        raise EffortError(
            f"{where}: only {idx.size} valid frames inside the movement, need at least {MIN_FRAMES}"
        )
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
        reach = REACH_MARGIN * limb_reach(joints, ok, bound, middle, free)
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
