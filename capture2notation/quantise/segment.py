"""Movement segmentation: joints over time → a :class:`~capture2notation.notation.Score`.

Each channel — a whole arm or leg (its bound → free vector and its reach),
the head, the chest, the supporting system (:mod:`.supports`) — has a speed
per frame interval.  Movements are runs of motion (:mod:`.spans`); each
becomes a symbol whose label is the part's pose where it arrives, its start
and duration snapped to the beat grid (tempo given, or :func:`estimate_tempo`).

Two regimes, chosen from the measured jitter:

Clean motion (the virtual dancer's truth: exact holds, directions jittering ≤ 0.05°/frame)
    Not smoothed.  A hold is exactly still, so any motion belongs to a
    movement, and back-to-back movements part only where the part is exactly
    (0.05°) on a written pose — a canonical direction and a bend of 30°
    steps — at a frame of the beat grid, having moved ≥ 5° since the last
    boundary (a limb's two segments on written directions, the whole limb
    on none, only at a speed minimum: a whole-limb movement can pass
    through such a pose).  Speed minima alone are not trusted: a limb turning about a
    fixed axis slows down mid-way, and the Space modulation makes the reach
    dip and recover.  This recovers the written symbols exactly whenever the
    dancer reaches its written poses.

Noisy motion (fitted, mocap)
    Savitzky–Golay smoothing over 0.3–0.6 s (wider for more jitter); a
    movement exceeds the jitter's 99th-percentile speed and peaks above
    ``peak_speed_deg_s`` (hysteresis), splits at interior minima deeper than
    ``split_ratio`` (shallower ones too where the part passes near a written
    pose, :data:`_NEAR_POSE_DEG`: smoothing fills the dip between chained
    half-beat movements), must move ``min_amplitude_deg``.  Its start and arrival
    are those of the Effort logistic fitted to its raw progress
    (:mod:`.timing`) — a speed threshold cuts a fifth to a third off each
    end — and it must last :data:`_MIN_MOVE_S` or hold its arrival pose for
    :data:`_HOLD_S` (quicker swings that do not hold are glitches of the
    fit); its label is the median pose over up to :data:`_HOLD_S` of
    the hold after the arrival (:func:`~.measured.hold_frames`), and it is
    written only when that label differs from the part's previous one —
    with hysteresis (:func:`~.measured.keep_previous`: a pose within a few
    degrees of the previous symbol's sector or bend band keeps it) and not
    when the held pose is within :data:`_SAME_POSE_DEG` of the last written
    one (a label change there is only a boundary crossed by the fit's error).  Key times of different parts
    within ``merge_window_s`` are pulled together.  A fitted chest is read
    from its own upright and must tilt past the fit's trunk noise
    (:func:`~.measured.upright_trunk`).  Feet contacts come from
    smoothed joints (:func:`~.supports.smooth_positions`).

Whole limb or segments
    Arms and legs are written as whole limbs (``right_arm`` …) with the bend
    degree of the elbow / knee, unless the segments move independently: the
    upper segment stays still while the lower one moves (a ``right_forearm`` /
    ``right_shin`` symbol), or — clean motion — the bent limb arrives with
    both segments nearer their written directions than the whole limb is to
    its own (``upper_arm`` + ``forearm`` symbols over one span).  A whole-limb
    symbol puts the whole limb exactly on its direction; its segments are
    almost never both on written directions.  :func:`~capture2notation.compare.agreement.normalise`
    treats an upper + lower pair pointing one way as the straight whole limb.

Supports
    See :mod:`.supports`: the weight-bearing feet and their level; a
    weight-bearing foot that travelled is a step.  Legs write gestures only
    while their foot is off the floor (a leg that lands is part of a support).
    Clean motion also parts a leg's motion where the weight arrives (the
    pelvis comes to rest or to a speed minimum on a grid frame), and a leg
    that arrives there on no written pose was carried by the weight
    transfer (a foot a step left behind): no gesture is written for it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np
from scipy.signal import savgol_filter

from ..body import joint_index
from ..errors import QuantiseError
from ..notation.model import LEVELS, PART_MIDDLE_JOINT, PART_SEGMENTS, Score, Symbol
from .contact import decode_contacts
from .flight import find_flights, with_flights
from .labels import DIRECTION_NAMES, FrameLabels, flat_foot_pitch, label_frames, support_frames, with_supports
from .measured import held_pose, hold_frames, keep_previous, upright_trunk
from .movement import Movement
from .spans import _ZERO_SPEED, movement_spans
from .supports import MIN_GROUNDED, NOISY_POSITION_M, body_height, position_noise, smooth_positions, support_movements
from .tempo import estimate_tempo_detail, snap
from .timing import progress_signal, refine_times
from .travel import unturn
from .turns import turn_movements, turned_so_far

__all__ = ["Movement", "SegmentParams", "Segmentation", "movement_spans", "segment", "segment_motion"]


@dataclass(frozen=True)
class SegmentParams:
    """Tuning of :func:`segment`.

    Parameters
    ----------
    grid : Fraction
        Beat grid for starts and durations (default ¼ beat).
    smooth_s : float or None
        Savitzky–Golay window, seconds; ``None`` chooses it from the measured
        jitter (none for clean, e.g. synthetic, motion; 0.3–0.6 s otherwise,
        with thresholds above the jitter's speed).  Setting it forces the
        noisy-motion path.
    min_speed_deg_s : float
        Floor of the low (onset) speed threshold of noisy motion, degrees per
        second (clean motion: any motion at all).
    peak_speed_deg_s : float
        A movement must peak above this speed, degrees per second.
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
    min_amplitude_deg: float = 10.0
    split_ratio: float = 0.35
    merge_window_s: float = 0.3


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
    tempo_runner_up : Fraction or None
        When estimated: the best other reading (usually half or double).
    tempo_confidence : float
        When estimated: probability that the tempo is within 4 % of
        `tempo`; NaN when the tempo was given.
    tempo_source : str
        What set the tempo: ``"given"``, ``"no beat"`` (nothing to estimate
        it from: 60 bpm, one beat a second) or, when estimated, what it was
        estimated from (``"the movements"``, ``"the sound track and the movements"``).
    """

    score: Score
    movements: tuple
    key_frames: np.ndarray
    tempo: Fraction
    tempo_estimated: bool
    labels: FrameLabels = field(repr=False)
    tempo_runner_up: Fraction | None = None
    tempo_confidence: float = float("nan")
    tempo_source: str = "given"


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
#: Jitter (degrees per frame) below which motion counts as clean (the
#: virtual dancer's truth measures ≤ 0.02°, optical mocap ≥ 0.1°): not
#: smoothed, and split only at exactly written poses.
_CLEAN_NOISE_DEG = 0.05
#: Shortest noisy movement, seconds (start to arrival of the fitted
#: logistic): half a beat at 150 bpm; anything quicker is a glitch of the
#: fit (a flip of depth, a swapped limb), not a dance movement.
_MIN_MOVE_S = 0.2
#: A noisy part this near (degrees) a written direction may end a movement
#: at a shallow speed minimum (:func:`~.spans.movement_spans`): two thirds
#: of the 22.5° to a sector boundary, where a 45° movement's mid-way pose lies.
_NEAR_POSE_DEG = 15.0
#: Tilt from vertical where a trunk part leaves place high (DESIGN.md).
_TILT_DEG = 22.5
#: Held noisy poses nearer than this (degrees) to the part's last written
#: pose are that pose: about twice a fitted limb's direction error (3-6°).
_SAME_POSE_DEG = 10.0
#: Longest hold after a noisy arrival over which the pose is averaged, seconds.
_HOLD_S = 0.4


def _angle_deg(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between unit vectors along the last axis, degrees (precise near 0)."""
    c = np.linalg.norm(np.cross(u, v), axis=-1)
    d = np.sum(u * v, axis=-1)
    return np.degrees(np.arctan2(c, d))


def _noise_deg(u: np.ndarray) -> float:
    """Frame-to-frame jitter of unit vectors (T, 3), degrees (robust; ~0 when clean).

    The residual from a local cubic (Savitzky–Golay, 5 frames) is zero in a
    hold and small in smooth motion, but white noise of σ per tangent
    coordinate leaves a Rayleigh-distributed residual of scale 0.72 σ.  Its
    lower quartile (0.55 σ for noise) ignores the kinks of sudden movements,
    which are never more than a fraction of the frames.
    """
    ok = np.isfinite(u).all(axis=-1)
    if ok.sum() < 7:
        return 0.0
    v = u[ok]
    r = np.linalg.norm(v - savgol_filter(v, 5, 3, axis=0), axis=-1)
    return float(np.degrees(np.percentile(r, 25)) / 0.55)


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


def _interval_speed(u_list: list[np.ndarray], x_list: list[np.ndarray], fps: float) -> np.ndarray:
    """Largest angular speed of the vectors and rate of the scalars over each interval, degrees per second."""
    per = [_angle_deg(u[:-1], u[1:]) for u in u_list] + [np.abs(np.diff(x)) for x in x_list]
    return np.nanmax(np.stack(per), axis=0) * fps if per[0].size else np.zeros(0)


def _scalar_noise(x: np.ndarray) -> float:
    """Jitter of a scalar series (degrees), as :func:`_noise_deg`."""
    x = x[np.isfinite(x)]
    if x.size < 7:
        return 0.0
    # Lower quartile of |N(0, 0.72 σ)| is 0.23 σ.
    return float(np.percentile(np.abs(x - savgol_filter(x, 5, 3)), 25) / 0.23)


def _smooth_scalar(x: np.ndarray, window: int) -> np.ndarray:
    if window < 5 or x.size <= window or not np.isfinite(x).all():
        return x
    return savgol_filter(x, window, 2)


def _channel(labels: FrameLabels, joints: np.ndarray, part: str) -> tuple[list, list, list]:
    """Signals whose change is a movement of `part`.

    Returns
    -------
    vectors : list of (T, 3) ndarray
        The part's bound → free unit vector.
    reach : list of (T,) ndarray
        Limbs: bound-to-free distance over the straight limb's length, as an
        angle in degrees (radians × 180/π).  It follows the extremity
        smoothly, whereas the bend angle — and the segments — swing at
        unbounded speed as a limb straightens under the Space modulation.
    bend : list of (T,) ndarray
        Limbs: the bend β in degrees.
    """
    vec = [labels.vectors[:, labels.index(part)]]
    if part not in _LIMBS:
        return vec, [], []
    a, b = PART_SEGMENTS[part]
    m = PART_MIDDLE_JOINT[part]
    ja, jm, jb = joints[:, joint_index(a)], joints[:, joint_index(m)], joints[:, joint_index(b)]
    full = np.nanmedian(np.linalg.norm(jm - ja, axis=-1)) + np.nanmedian(np.linalg.norm(jb - jm, axis=-1))
    reach = np.linalg.norm(jb - ja, axis=-1) / full
    return vec, [np.degrees(reach)], [labels.bend_deg[:, labels.index(part)]]


def _floor_seen(feet_seen) -> bool:
    """Whether the capture saw a foot often enough to find the floor; warns when not.

    A foot the capture never saw (a Kinect's inferred feet, feet out of the
    frame) cannot show where the floor is, so no support is written for it:
    leg gestures only.  The bar is :data:`~.supports.MIN_GROUNDED`, the least
    fraction of frames a dance stands on the floor.
    """
    if feet_seen is None:
        return True
    seen = np.asarray(feet_seen, bool)
    fraction = float(np.mean(seen.any(axis=1))) if seen.size else 0.0
    if fraction >= MIN_GROUNDED:
        return True
    warnings.warn(
        f"the floor is never seen (a foot tracked in only {100 * fraction:.0f} % of {len(seen)} frames): "
        "leg gestures only, no support symbols",
        stacklevel=3,
    )
    return False


def segment_motion(
    joints: np.ndarray,
    fps: float,
    tempo=None,
    meter: int = 4,
    params: SegmentParams | None = None,
    floor: float = 0.0,
    title: str = "",
    tempo_evidence=None,
    axes: str = "standard",
    feet_seen=None,
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
    tempo_evidence : TempoEvidence, optional
        Evidence on the tempo besides the movements (a sound track's beats,
        :mod:`capture2notation.quantise.beats`), when it is estimated.
    axes : str
        The score's key: ``"standard"`` or ``"body"`` (arms and head read in
        the body cross of axes, :func:`~.labels.label_frames`).
    feet_seen : (T, 2) array_like of bool, optional
        Right, left foot measured by the capture at each frame (default:
        wherever finite).  A foot not seen is never taken to bear weight.

    Returns
    -------
    Segmentation
    """
    params = params or SegmentParams()
    labels = label_frames(joints, fps, floor, axes=axes)
    T = labels.direction.shape[0]
    if T < 2:
        raise QuantiseError(f"need at least 2 frames to segment a motion, got {T}")
    joints = np.asarray(joints, dtype=float)
    # Measured motion (fits, mocap) is never exactly still, however smooth.
    measured = not _has_exact_holds(labels, joints)
    # Turns are read from the motion as it is; supports and steps from the
    # motion with its turns undone about their pivots (:mod:`.travel`).
    turning, turned = joints, turned_so_far(joints, fps, measured)
    if np.any(turned != 0.0):
        joints = unturn(joints, turned, labels.supporting)
        labels = label_frames(joints, fps, floor, axes=axes)
    noisy_feet = measured or position_noise(joints) > NOISY_POSITION_M
    if noisy_feet:
        # Jitter of a centimetre is 0.5 m/s frame to frame: feet would never
        # be "slower than 0.2 m/s" (DESIGN.md).  Contacts come from smoothed
        # joints, for the supports and for the legs alike.
        smoothed = smooth_positions(joints, fps)
        # Feet on the floor decoded over the whole clip: the per-frame rule
        # loses a standing foot to a few millimetres of jitter at 100 fps.
        contact = decode_contacts(smoothed, fps, floor, feet_seen)
        # Measured feet carry a pitch bias of their own: relevé is a heel
        # raised from the capture's own flat foot, not from the model's.
        flat = flat_foot_pitch(smoothed, contact) if measured else None
        labels = with_supports(labels, *support_frames(smoothed, fps, floor, flat_pitch=flat, contact=contact))
    # Flight from the feet's heights (smoothed when measured), before the supports are written.
    flights = find_flights(smoothed if noisy_feet else joints, fps, measured, floor, seen=feet_seen)
    floor_seen = _floor_seen(feet_seen)
    height = body_height(joints)
    estimated = tempo_was_none = tempo is None
    moves, detail = None, None
    if estimated:
        moves = (
            _gesture_movements(labels, joints, fps, params, measured=measured)
            + with_flights(
                support_movements(labels, joints, fps, params, movement_spans, measured=measured) if floor_seen else [],
                labels,
                joints,
                fps,
                flights,
                height,
            )
            + turn_movements(turning, fps, measured)
        )
        clean = not measured and all(_noise_deg(labels.vectors[:, labels.index(p)]) <= _CLEAN_NOISE_DEG for p in _LIMBS)
        # Gestures set the tempo when there are a few of them: support
        # movements are cut at speed minima (clean) or fitted to the pelvis
        # (noisy), a frame or more off their beats, and steps arrive early
        # (the foot lands first).
        timed = [m for m in moves if not m.part.endswith("support")]
        timed = timed if len(timed) >= 4 else moves
        times = np.array([t for m in timed for t in (m.start_time, m.end_time)])
        # Fitted starts and arrivals carry different timing biases (a heavy,
        # late-peaking Effort is fitted with a late arrival): groups 0 and 1.
        groups = np.tile([0, 1], len(timed))
        if len(moves) == 0 and tempo_evidence is None:
            # Nothing moves: the (empty) score needs some tempo; say so, invent nothing else.
            warnings.warn("no movement found: the tempo cannot be estimated, writing 60 bpm", stacklevel=2)
            tempo, estimated = Fraction(60), False
        else:
            gestures = [m.end_time - m.start_time for m in moves if not m.part.endswith("support")]
            # Clean key times are within half a frame of their grid time;
            # measured ones (fitted logistic, noisy) within a frame or two.
            tol = (0.3 if clean else 2.0) / fps
            detail = estimate_tempo_detail(
                times,
                params.grid,
                tolerance_s=tol,
                durations=gestures or None,
                groups=groups,
                max_offset_s=0.0 if clean else 3.0 / fps,
                evidence=tempo_evidence,
                measured=not clean,
            )
            tempo = detail.tempo
    tempo = Fraction(tempo).limit_denominator(1000) if not isinstance(tempo, Fraction) else tempo
    if tempo <= 0:
        raise QuantiseError(f"tempo must be > 0 beats per minute, got {tempo}")
    # With the beat grid known, clean motion is cut only on its frames;
    # noisy motion never uses the grid, so its first pass stands.
    noisy = noisy_feet and (
        measured
        or params.smooth_s is not None
        or all(
            max(_noise_deg(u) for u in _channel(labels, joints, p)[0]) > _CLEAN_NOISE_DEG
            for p in tuple(_LIMBS) + _SINGLE
        )
    )
    if moves is None or not noisy:
        on_grid = _grid_frames(T, fps, tempo, params.grid)
        turns = turn_movements(turning, fps, measured, on_grid)
        ends = np.zeros(T, bool)
        ends[[min(m.end_frame, T - 1) for m in turns]] = True
        moves = (
            _gesture_movements(labels, joints, fps, params, on_grid, measured)
            + with_flights(
                support_movements(
                    labels, joints, fps, params, movement_spans, on_grid, measured=measured, turn_ends=ends
                )
                if floor_seen
                else [],
                labels,
                joints,
                fps,
                flights,
                height,
                None if noisy else on_grid,
            )
            + turns
        )
    moves.sort(key=lambda m: (m.start_time, m.part))
    merged = _merge_times(moves, params, float(tempo))
    symbols = _symbols(merged, tempo, params.grid)
    key_frames = np.unique(np.r_[0, [min(m.end_frame, T - 1) for m in moves]].astype(int))
    score = Score(symbols=tuple(symbols), title=title, tempo=tempo, meter=meter, axes=axes)
    if detail is None:
        source = "no beat" if tempo_was_none else "given"
        return Segmentation(score, tuple(moves), key_frames, tempo, estimated, labels, tempo_source=source)
    return Segmentation(
        score,
        tuple(moves),
        key_frames,
        tempo,
        estimated,
        labels,
        tempo_runner_up=detail.runner_up,
        tempo_confidence=detail.confidence,
        tempo_source=detail.source,
    )


def _lands_at_end(down: np.ndarray, end_f: int, hold: int) -> bool:
    """Whether a measured foot whose movement arrives at frame `end_f` lands as the clip ends.

    A closing that arrives on the last frame has no hold after it: the
    smoothed foot is still above DESIGN.md's 0.2 m/s until then and is in
    contact on the last frame alone (nothing follows it,
    :func:`~.labels.support_frames`).  A foot in contact there, its
    movement's fitted arrival within a hold (`hold` frames) of the end, has
    landed.
    """
    return bool(down[-1]) and end_f >= len(down) - 1 - hold


def segment(
    joints: np.ndarray, fps: float, tempo=None, meter: int = 4, params: SegmentParams | None = None, floor: float = 0.0
) -> Score:
    """The score of a motion (see :func:`segment_motion`)."""
    return segment_motion(joints, fps, tempo=tempo, meter=meter, params=params, floor=floor).score


def _label_at(labels: FrameLabels, col: int, frames: slice) -> tuple[str, str, int]:
    """Label of a gesture column from its median pose over `frames` (robust to jitter and flicker)."""
    from ..notation.directions import bend_degree, classify_indices

    v, bd = held_pose(labels.vectors[:, col], labels.bend_deg[:, col], frames)
    d, lv = classify_indices(v[None])
    if d[0] < 0:
        return "", "", -1
    bend = int(bend_degree(bd)) if np.isfinite(bd) else 0
    return DIRECTION_NAMES[d[0]], LEVELS[lv[0]], bend


def _tilt_deg(labels: FrameLabels, col: int, frames: slice) -> float:
    """Angle of a column's median vector over `frames` from vertical, degrees."""
    v, _ = held_pose(labels.vectors[:, col], None, frames)
    return float(np.degrees(np.arccos(np.clip(v[2] / np.linalg.norm(v), -1.0, 1.0))))


def _off_canonical_deg(labels: FrameLabels, col: int, frames: slice) -> float:
    """Angle from the median vector of a column to its label's canonical vector, degrees."""
    from ..notation.directions import canonical_vector

    v, _ = held_pose(labels.vectors[:, col], None, frames)
    d, lv, _ = _label_at(labels, col, frames)
    if not d or (d == "place" and lv == "middle"):
        return float("inf")
    c = canonical_vector(d, lv)
    return float(_angle_deg(v / np.linalg.norm(v), c))


def _off_canonical_series(v: np.ndarray) -> np.ndarray:
    """Angle from each vector (T, 3) to the canonical vector of its own label, degrees."""
    from ..notation.directions import canonical_vector, classify_indices

    d, lv = classify_indices(v)
    table = np.full((len(DIRECTION_NAMES), len(LEVELS), 3), np.nan)
    for i, name in enumerate(DIRECTION_NAMES):
        for k, level in enumerate(LEVELS):
            if not (name == "place" and level == "middle"):
                table[i, k] = canonical_vector(name, level)
    c = table[np.clip(d, 0, None), np.clip(lv, 0, None)]
    out = _angle_deg(v, c)
    return np.where((d < 0) | ~np.isfinite(out), np.inf, out)


def _key_pose_fn(
    labels: FrameLabels,
    part: str,
    on_grid: np.ndarray | None = None,
    tol: float = 0.05,
    min_change: float = 5.0,
    arrivals: np.ndarray | None = None,
):
    """``(f, since) -> bool``: frame f can end a movement.

    The part must be exactly where some symbol would put it, f must be a
    grid frame (when `on_grid` is given: the frame a renderer gives a grid
    time), and the pose must be at least `min_change` degrees from its pose
    at frame `since` (a movement arrives somewhere new).  A limb sweeping
    through a written direction mid-movement rarely does all of these.
    Frames flagged in `arrivals` (T,) — a leg's: where the weight arrives —
    end a movement on a grid frame whatever the pose."""
    cols = [labels.index(part)] + [labels.index(p) for p in _LIMBS.get(part, ())]
    if part in _LIMBS:
        whole = _off_canonical_series(labels.vectors[:, cols[0]])
        bend = labels.bend_deg[:, cols[0]]
        bend_ok = np.abs(bend - 30.0 * np.round(bend / 30.0)) < tol
        up, low = (_off_canonical_series(labels.vectors[:, c]) for c in cols[1:])
        ok = ((whole < tol) & bend_ok) | ((up < tol) & (low < tol))
        # Both segments on written directions with the whole limb on none:
        # a whole-limb movement (great circle, bend changing with it) can
        # pass exactly through such a pose mid-way, e.g. a leg unbending
        # from forward middle bend 2 to place low has its thigh forward
        # middle and shin forward low a quarter of the way; only a movement
        # that slows there arrives (see :func:`~.spans.movement_spans`).
        pair_only = ok & ~((whole < tol) & bend_ok)
    else:
        bend = None
        ok = _off_canonical_series(labels.vectors[:, cols[0]]) < tol
        pair_only = np.zeros_like(ok)
    if on_grid is not None:
        ok = ok & on_grid

    forced = np.zeros_like(ok) if arrivals is None else arrivals & (True if on_grid is None else on_grid)

    def key(f: int, since: int) -> bool:
        if forced[f]:
            return True
        if not ok[f]:
            return False
        change = max(float(_angle_deg(labels.vectors[f, c], labels.vectors[since, c])) for c in cols)
        if bend is not None:
            change = max(change, abs(float(bend[f] - bend[since])))
        return change >= min_change

    key.on_grid = on_grid is not None
    key.needs_minimum = lambda f: bool(pair_only[f] and not forced[f])
    return key


def _weight_arrivals(joints: np.ndarray) -> np.ndarray:
    """(T,) bool: frames where the weight arrives (clean motion).

    The pelvis moves with the supports only, each support movement in one
    smooth push: it comes to rest, or — a support following back to back,
    which starts from rest — slows to a minimum of its speed, where a
    support movement arrives.  That may be the very frame a leg gesture
    starts.
    """
    step = np.linalg.norm(np.diff(joints[:, joint_index("pelvis")], axis=0), axis=-1)
    out = np.zeros(len(joints), bool)
    if step.size == 0:
        return out
    nxt = np.r_[step[1:], 0.0]
    after = np.r_[step[2:], np.inf, np.inf]
    out[1:] = (step > 1e-9) & (nxt < step) & (nxt <= after)
    return out


def _noise_speed(noise: float, fps: float, window: int) -> float:
    """Speed (deg/s) that jitter of `noise` degrees per frame exceeds 1 % of the
    time after Savitzky–Golay smoothing over `window` frames (measured on
    simulated jitter: 2.0, 1.25, 0.95 × noise × fps for windows 5, 7, 9)."""
    w = max(window, 1)
    c = 2.0 * (5.0 / w) ** 1.4 if w >= 5 else 4.0
    return c * noise * fps


def _smoothing_window(noise: float, fps: float, params: SegmentParams) -> int:
    """Odd smoothing window, frames: none for clean motion, else ≥ 0.3 s and
    widened (up to 0.6 s) until jitter stays below about 15°/s."""
    if params.smooth_s is not None:
        w = int(round(params.smooth_s * fps))
    elif noise <= _CLEAN_NOISE_DEG:
        # Clean motion is left alone so movement boundaries stay on their frames.
        return 0
    else:
        w = max(5, int(round(0.3 * fps)))
        while w < 0.6 * fps and _noise_speed(noise, fps, w) > 15.0:
            w += 2
    return w + (1 - w % 2) if w > 0 else 0


def _grid_frames(T: int, fps: float, tempo: Fraction, grid: Fraction) -> np.ndarray:
    """(T,) bool: frames nearest to a grid time (round half up, as a renderer times a beat)."""
    step = float(grid) * 60.0 / float(tempo) * fps  # frames per grid step
    k = np.arange(int(np.ceil((T - 1) / step)) + 2)
    f = np.floor(k * step + 0.5 + 1e-9).astype(int)
    out = np.zeros(T, bool)
    out[f[f < T]] = True
    return out


def _limb_symbols(
    labels: FrameLabels, part: str, start_f: int, end_f: int, frames: slice, params: SegmentParams, clean: bool
):
    """Segment symbols for a limb movement, or None when the whole limb is written.

    The whole limb is written (with its bend) unless the segments move
    independently: the upper segment stays still while the lower one moves
    (a forearm / shin symbol), or — clean motion only — the bent limb arrives
    with both segments nearer their written directions than the whole limb
    is to its own (upper-arm and forearm symbols over the same span; a
    whole-limb symbol puts the whole limb exactly on its direction).

    Returns
    -------
    list of (part, direction, level) or None
    """
    whole = labels.index(part)
    upper, lower = (labels.index(p) for p in _LIMBS[part])
    u = labels.vectors[:, upper]
    d2, lv2, _ = _label_at(labels, lower, frames)
    if not d2 or (d2 == "place" and lv2 == "middle"):
        return None
    if float(_angle_deg(u[start_f], u[end_f])) < 0.5 * params.min_amplitude_deg:
        return [(_LIMBS[part][1], d2, lv2)]
    if not clean:
        return None
    bend = float(np.nanmean(labels.bend_deg[frames, whole]))
    # A bent whole limb almost never has both segments on written directions,
    # so segments nearer their written directions than the whole limb is to
    # its own mean the segments were written.
    segs_off = max(_off_canonical_deg(labels, upper, frames), _off_canonical_deg(labels, lower, frames))
    if bend < 0.05 or not segs_off < _off_canonical_deg(labels, whole, frames):
        return None
    d1, lv1, _ = _label_at(labels, upper, frames)
    return [(_LIMBS[part][0], d1, lv1), (_LIMBS[part][1], d2, lv2)]


def _has_exact_holds(labels: FrameLabels, joints: np.ndarray, min_intervals: int = 3) -> bool:
    """Whether some part (or the pelvis) both moves and holds exactly still (≥ `min_intervals` frame intervals).

    The virtual dancer's truth holds a pose exactly (its vectors repeat to
    the last bit), whereas fitted or recorded motion is never exactly still
    however smooth its fit: a fitted capture can measure under 0.05° of
    frame-to-frame jitter and would otherwise be taken for clean motion.
    """
    steps = [_angle_deg(u[:-1], u[1:]) for u in (labels.vectors[:, labels.index(p)] for p in tuple(_LIMBS) + _SINGLE)]
    # The pelvis too (metres → millimetres): a plié moves little else.
    pelvis = 1e3 * np.linalg.norm(np.diff(joints[:, joint_index("pelvis")], axis=0), axis=-1)
    steps.append(pelvis)
    if any(np.sum(st < 1e-9) >= min_intervals and np.nanmax(st, initial=0.0) > 0.01 for st in steps):
        return True
    # Supports back to back to the end move the pelvis and legs all the
    # time; then an unnotated part that holds to the last bit while the
    # weight moves (no fit keeps a limb exactly still) shows the motion clean.
    return bool(
        np.nanmax(pelvis, initial=0.0) > 0.01
        and len(pelvis) >= min_intervals
        and any(bool(np.all(st < 1e-9)) for st in steps[:-1])
    )


def _gesture_movements(
    labels: FrameLabels,
    joints: np.ndarray,
    fps: float,
    params: SegmentParams,
    on_grid: np.ndarray | None = None,
    measured: bool = False,
) -> list[Movement]:
    out: list[Movement] = []
    T = labels.direction.shape[0]
    # Noisy poses are averaged over up to this long a hold after the arrival.
    hold = max(1, int(round(_HOLD_S * fps)))
    all_labels = labels
    for part in tuple(_LIMBS) + _SINGLE:
        labels, margin = all_labels, 0.0
        if measured and part == "chest":
            # A fitted chest leans by a bias of its own (see .measured).
            labels, margin = upright_trunk(all_labels, part)
        whole = labels.index(part)
        u_list, reach, bend_list = _channel(labels, joints, part)
        noise = max([_noise_deg(u) for u in u_list] + [_scalar_noise(x) for x in bend_list])
        # Truth-like motion (exact holds) is clean when its directions are:
        # a knee or elbow that bends and straightens within every movement
        # (Space, the floor) at a low frame rate leaves the bend a local
        # cubic's residual of a fraction of a degree, jitter or not.
        clean = params.smooth_s is None and not measured and max(_noise_deg(u) for u in u_list) <= _CLEAN_NOISE_DEG
        # Clean motion: the smooth reach, split at written poses only; noisy
        # motion: the bend itself (smoothed), split at deep speed minima.
        x_list = reach if clean else bend_list
        # The logistic is fitted to the raw signals: smoothing would spread the movement.
        raw_u, raw_x = u_list, x_list
        w = _smoothing_window(noise, fps, params)
        if w:
            u_list = [_smooth(u, w) for u in u_list]
            x_list = [_smooth_scalar(x, w) for x in x_list]
        if clean:
            # Without noise a hold is exactly still, so any motion belongs to a
            # movement (the Space modulation can nearly stop one mid-way);
            # written poses, not thresholds, separate movements.
            low, high = 100 * _ZERO_SPEED, 200 * _ZERO_SPEED
        else:
            low = max(params.min_speed_deg_s, _noise_speed(noise, fps, w))
            high = max(params.peak_speed_deg_s, 2.0 * low)
        speed = _interval_speed(u_list, x_list, fps)
        if part in _FOOT:
            # A leg whose foot supports is part of the support (a plié bends
            # the knee): it gestures only between leaving and reaching the floor.
            down = labels.supporting[:, _FOOT[part]]
            speed = np.where(down[:-1] & down[1:], 0.0, speed)
        arrivals = _weight_arrivals(joints) if clean and part in _FOOT else None
        key = _key_pose_fn(labels, part, on_grid, arrivals=arrivals) if clean else None
        # Noisy motion: a shallower minimum parts two movements where the
        # part passes within _NEAR_POSE_DEG of a written pose.
        near = None if clean else _off_canonical_series(u_list[0]) < _NEAR_POSE_DEG
        spans = movement_spans(speed, low, high, params.split_ratio, key_pose=key, near_pose=near)
        state = _DEFAULT.get(part, ("place", "low")) + (0,)
        # Noisy motion: the held pose of the part's last written symbol.
        last_pose = None
        for i, (a, b) in enumerate(spans):
            start_f, end_f = a, min(b + 1, T - 1)
            nxt = spans[i + 1][0] if i + 1 < len(spans) else T
            moved = max(
                [float(_angle_deg(u[start_f], u[end_f])) for u in u_list]
                + [abs(float(x[end_f] - x[start_f])) for x in bend_list]
            )
            if not moved >= params.min_amplitude_deg:
                continue
            # The movement leaves frame a's pose and arrives at frame b + 1's.
            t0, t1 = a / fps, (b + 1) / fps
            if clean:
                # Clean motion is exactly on its pose at the arrival frame.
                frames = slice(end_f, end_f + 1)
            else:
                # Noisy motion: the logistic's start and arrival, and the pose
                # averaged over the hold that follows the arrival.
                t0, t1 = _fitted_times(raw_u, raw_x, spans, i, fps, t0, t1)
                if t1 - t0 < _MIN_MOVE_S and nxt - (b + 1) < hold:
                    # A limb does not swing tens of degrees in a few frames
                    # and back: a glitch of the measurement.  A quick
                    # movement that arrives and holds its pose is a movement
                    # (half a beat at 96 bpm is fitted as quick as 0.17 s).
                    continue
                # Nothing arrives after the clip ends (the fitted curve may run past it).
                t1 = min(t1, (T - 1) / fps)
                end_f = min(max(int(round(t1 * fps)), start_f + 1), T - 1)
                frames = hold_frames(end_f, b + 1, nxt, hold, T)
            if arrivals is not None and arrivals[end_f] and not _key_pose_fn(labels, part)(end_f, start_f):
                # Clean motion: a free leg that arrives with the weight and on
                # no written pose was carried by the weight transfer (a foot
                # a step left behind), not a gesture.
                continue
            if part in _FOOT and (
                labels.supporting[end_f, _FOOT[part]]
                or (not clean and _lands_at_end(labels.supporting[:, _FOOT[part]], end_f, hold))
            ):
                # A leg that arrives on the floor is a support, not a gesture.
                state = ("place", "low", 0)
                continue
            if part in _LIMBS:
                segs = _limb_symbols(labels, part, start_f, end_f, frames, params, clean)
                if segs is not None:
                    out.extend(Movement(p, start_f, end_f, t0, t1, d, lv, 0) for p, d, lv in segs)
                    state = ("", "", -1)
                    continue
            d, lv, bend = _label_at(labels, whole, frames)
            if not d or (d == "place" and lv == "middle"):
                continue
            if part not in _LIMBS:
                bend = 0
                if margin and _tilt_deg(labels, whole, frames) < _TILT_DEG + margin:
                    # Within the fit's own trunk noise of upright.
                    d, lv = _DEFAULT[part]
            if not clean:
                pose = held_pose(
                    labels.vectors[:, whole], labels.bend_deg[:, whole] if part in _LIMBS else None, frames
                )
                if _same_pose(pose, last_pose, state, params):
                    # Arrived within the fit's error of the last written pose:
                    # a label change would only be a boundary crossed by it.
                    continue
                if part in _LIMBS or not margin:
                    d, lv, bend = keep_previous(pose[0], pose[1], (d, lv, bend), state)
            if (d, lv, bend) == state:
                continue
            state = (d, lv, bend)
            last_pose = None if clean else pose
            out.append(Movement(part, start_f, end_f, t0, t1, d, lv, bend))
    return out


def _same_pose(pose: tuple, last: tuple | None, state: tuple, params: SegmentParams) -> bool:
    """Whether a measured held `pose` ``(v, β)`` is the part's last written pose within the fit's error.

    `last` is the held pose of the last written symbol, or None: then the
    state's canonical pose (the starting pose) stands in, with its bend.
    Directions closer than ``min_amplitude_deg`` and bends within half a
    bend step are one pose (DESIGN.md's bend degrees are 30° apart).
    """
    from ..notation.directions import BEND_STEP_DEG, canonical_vector

    v, bend = pose
    if last is None:
        d, lv, k = state
        if not d or (d == "place" and lv == "middle"):
            return False
        last = (canonical_vector(d, lv), BEND_STEP_DEG * k)
    if not (np.isfinite(v).all() and np.isfinite(last[0]).all()):
        return False
    if float(_angle_deg(v, last[0])) >= _SAME_POSE_DEG:
        return False
    return not (np.isfinite(bend) and np.isfinite(last[1]) and abs(bend - last[1]) >= BEND_STEP_DEG / 2)


def _progress_window(u_list: list, x_list: list, spans: list, i: int, fps: float):
    """``(t, p, t0, t1)`` of span `i` for :func:`~.timing.refine_times`, or None.

    The window runs from the previous movement's arrival (at most the
    movement's own length earlier) to the next one's start; departure and
    arrival poses are the means over the outer halves of the holds.  The
    progress is that of the signal that changes most (a vector's angle or
    the bend, both in degrees).
    """
    a, b = spans[i]
    T = u_list[0].shape[0]
    pad = max(3, b + 1 - a)
    lo = max(spans[i - 1][1] + 1 if i > 0 else 0, a - pad)
    hi = min(spans[i + 1][0] if i + 1 < len(spans) else T - 1, b + 1 + pad)
    pre = slice(lo, max(lo + 1, (lo + a) // 2 + 1))
    post = slice(min(hi, (b + 1 + hi + 1) // 2), hi + 1)
    best, weight = None, 0.0
    for u in u_list:
        p0, p1 = np.nanmean(u[pre], axis=0), np.nanmean(u[post], axis=0)
        p0, p1 = p0 / np.linalg.norm(p0), p1 / np.linalg.norm(p1)
        amp = float(_angle_deg(p0, p1))
        if np.isfinite(amp) and amp > weight:
            best, weight = progress_signal(u[lo : hi + 1], p0, p1), amp
    for x in x_list:
        x0, x1 = np.nanmean(x[pre]), np.nanmean(x[post])
        amp = abs(float(x1 - x0))
        if np.isfinite(amp) and amp > weight:
            best, weight = (x[lo : hi + 1] - x0) / (x1 - x0), amp
    if best is None or hi - lo < 4:
        return None
    return np.arange(lo, hi + 1) / fps, best, a / fps, (b + 1) / fps


def _fitted_times(u_list: list, x_list: list, spans: list, i: int, fps: float, t0: float, t1: float):
    """Start and arrival of noisy span `i` from the Effort logistic (:mod:`.timing`);
    the detected (`t0`, `t1`) when there is no window to fit."""
    win = _progress_window(u_list, x_list, spans, i, fps)
    if win is None:
        return t0, t1
    ((f0, f1),) = refine_times([win])
    return max(f0, 0.0), f1


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
        out.append(Symbol(start, end - start, m.part, m.direction, m.level or None, m.bend, m.amount))
        last_end[m.part] = end
    return out
