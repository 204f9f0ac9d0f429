"""Movement segmentation: joints over time → a :class:`~capture2notation.notation.Score`.

Each channel — a whole arm or leg (its bound → free vector and its reach),
the head, the chest, the supporting system (:mod:`.supports`) — has a speed
per frame interval.  Movements are runs of motion (:mod:`.spans`); each
becomes a symbol whose label is the part's pose where it arrives, its start
and duration snapped to the beat grid (tempo given, or :func:`estimate_tempo`).

Gestures (arms, legs, head, chest) are cut and labelled in :mod:`.gestures`,
in one of two regimes chosen from the measured jitter (clean or noisy motion).

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
from itertools import pairwise

import numpy as np

from ..body import body_frame
from ..errors import QuantiseError
from ..notation.model import AIR, Score, Symbol
from .contact import decode_contacts
from .flight import find_flights, with_flights
from .gestures import (
    CLEAN_NOISE_DEG,
    LIMBS,
    SINGLE_PARTS,
    channel,
    gesture_movements,
    grid_frames,
    has_exact_holds,
    noise_deg,
)
from .labels import FrameLabels, flat_foot_pitch, label_frames, support_frames, with_supports
from .measured import depth_axes
from .movement import Movement
from .params import SegmentParams
from .spans import movement_spans
from .support_state import NOISY_POSITION_M, body_height, position_noise, smooth_positions
from .supports import support_movements
from .supports_measured import MIN_GROUNDED
from .tempo import estimate_tempo_detail, snap
from .travel import unturn
from .turns import turn_movements, turned_so_far

__all__ = ["Movement", "SegmentParams", "Segmentation", "movement_spans", "segment", "segment_motion"]


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
    line_of_sight=None,
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
    line_of_sight : (3,) array_like, optional
        A single camera's viewing axis in the joints' world, for fitted
        video: the fit's trunk errs along it (:func:`~.measured.upright_trunk`).
        None for motion files and several cameras.

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
    measured = not has_exact_holds(labels, joints)
    # Turns are read from the motion as it is; supports and steps from the
    # motion with its turns undone about their pivots (:mod:`.travel`).
    # Measured turns never use the beat grid: read once, they serve every pass.
    turning = joints
    measured_turns = turn_movements(joints, fps, measured=True) if measured else None
    turned = turned_so_far(joints, fps, measured, measured_turns)
    # The camera's line of sight in body axes, from the body as it faces the camera.
    depth = None if line_of_sight is None or not measured else depth_axes(body_frame(joints), line_of_sight)
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
            gesture_movements(labels, joints, fps, params, measured=measured, depth=depth)
            + with_flights(
                support_movements(labels, joints, fps, params, movement_spans, measured=measured) if floor_seen else [],
                labels,
                joints,
                fps,
                flights,
                height,
            )
            + (measured_turns if measured else turn_movements(turning, fps, measured))
        )
        clean = not measured and all(noise_deg(labels.vectors[:, labels.index(p)]) <= CLEAN_NOISE_DEG for p in LIMBS)
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
            max(noise_deg(u) for u in channel(labels, joints, p)[0]) > CLEAN_NOISE_DEG
            for p in tuple(LIMBS) + SINGLE_PARTS
        )
    )
    if moves is None or not noisy:
        on_grid = grid_frames(T, fps, tempo, params.grid)
        turns = measured_turns if measured else turn_movements(turning, fps, measured, on_grid)
        ends = np.zeros(T, bool)
        ends[[min(m.end_frame, T - 1) for m in turns]] = True
        take_offs = np.zeros(T, bool)
        take_offs[[t0 for t0, _ in flights]] = True
        moves = (
            gesture_movements(labels, joints, fps, params, on_grid, measured, depth, flights)
            + with_flights(
                support_movements(
                    labels,
                    joints,
                    fps,
                    params,
                    movement_spans,
                    on_grid,
                    measured=measured,
                    turn_ends=ends,
                    take_offs=take_offs,
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


def segment(
    joints: np.ndarray, fps: float, tempo=None, meter: int = 4, params: SegmentParams | None = None, floor: float = 0.0
) -> Score:
    """The score of a motion (see :func:`segment_motion`)."""
    return segment_motion(joints, fps, tempo=tempo, meter=meter, params=params, floor=floor).score


def _merge_times(moves: list[Movement], params: SegmentParams, tempo: float) -> list[Movement]:
    """Pull key times of different parts that lie within the merge window onto their median.

    Times closer than the window are grouped (single linkage), and a group
    spanning more than the window is split at its widest gap until none
    does: chained neighbours could otherwise gather the key times of half a
    second of several parts, a movement's start and arrival among them, and
    collapse it to nothing.  A movement whose start and arrival would still
    meet keeps its own times.
    """
    if not moves:
        return moves
    window = min(params.merge_window_s, 0.45 * float(params.grid) * 60.0 / tempo)
    t = np.array([x for m in moves for x in (m.start_time, m.end_time)])
    order = np.argsort(t, kind="stable")
    ts = t[order]
    out_t = np.empty_like(t)
    for lo, hi in _groups(ts, window):
        out_t[order[lo:hi]] = np.median(ts[lo:hi])
    out = []
    for i, m in enumerate(moves):
        t0, t1 = float(out_t[2 * i]), float(out_t[2 * i + 1])
        collapsed = t1 <= t0 and m.start_time < m.end_time
        out.append(m if collapsed else replace(m, start_time=t0, end_time=t1))
    return out


def _groups(ts: np.ndarray, window: float) -> list[tuple[int, int]]:
    """Index ranges [lo, hi) of sorted times `ts` grouped as :func:`_merge_times` says."""
    cuts = [0, *(np.flatnonzero(np.diff(ts) > window) + 1).tolist(), ts.size]
    todo = list(pairwise(cuts))
    out = []
    while todo:
        lo, hi = todo.pop()
        if ts[hi - 1] - ts[lo] <= window:
            out.append((lo, hi))
            continue
        k = lo + 1 + int(np.argmax(np.diff(ts[lo:hi])))  # split at the widest gap
        todo += [(lo, k), (k, hi)]
    return out


def _symbols(moves: list[Movement], tempo: Fraction, grid: Fraction) -> list[Symbol]:
    """Movements snapped to the beat grid as symbols, none starting before what it must follow.

    A part's symbol starts no earlier than its previous one ends, and flight
    and a one-foot support (which cannot overlap: no foot bears weight in
    flight) no earlier than the other ends.
    """
    last_end: dict[str, Fraction] = {}
    out: list[Symbol] = []
    for m in sorted(moves, key=lambda m: (m.start_time, m.part)):
        start = snap(m.start_time, tempo, grid)
        end = snap(m.end_time, tempo, grid)
        air = m.direction == AIR and m.part == "support"
        after = [m.part] + (list(_ONE_FOOT) if air else [AIR] if m.part in _ONE_FOOT else [])
        start = max([start] + [last_end[k] for k in after if k in last_end])
        if end <= start:
            end = start + grid
        out.append(Symbol(start, end - start, m.part, m.direction, m.level or None, m.bend, m.amount))
        last_end[m.part] = end
        if air:
            last_end[AIR] = end
    return out


_ONE_FOOT = ("right_support", "left_support")
