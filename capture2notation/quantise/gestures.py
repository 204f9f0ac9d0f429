"""Gesture movements of the arms, legs, head and chest: each channel's runs of motion, cut and labelled.

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
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import numpy as np
from scipy.signal import savgol_filter

from ..body import joint_index
from ..notation.model import LEVELS, PART_MIDDLE_JOINT, PART_SEGMENTS
from .flight import landing_rest
from .labels import DIRECTION_NAMES, FrameLabels
from .measured import held_pose, hold_frames, keep_previous, trunk_tilt_beyond_noise, upright_trunk
from .movement import Movement
from .params import SegmentParams
from .spans import _ZERO_SPEED, movement_spans
from .timing import progress_signal, refine_times

__all__ = [
    "CLEAN_NOISE_DEG",
    "LIMBS",
    "SINGLE_PARTS",
    "channel",
    "gesture_movements",
    "grid_frames",
    "has_exact_holds",
    "noise_deg",
]

# Gesture channels: part, segment label columns (upper, lower) or single.
LIMBS = {
    "right_arm": ("right_upper_arm", "right_forearm"),
    "left_arm": ("left_upper_arm", "left_forearm"),
    "right_leg": ("right_thigh", "right_shin"),
    "left_leg": ("left_thigh", "left_shin"),
}
SINGLE_PARTS = ("head", "chest")
_DEFAULT = {"head": ("place", "high"), "chest": ("place", "high")}
_FOOT = {"right_leg": 0, "left_leg": 1}
#: Jitter (degrees per frame) below which motion counts as clean (the
#: virtual dancer's truth measures ≤ 0.02°, optical mocap ≥ 0.1°): not
#: smoothed, and split only at exactly written poses.
CLEAN_NOISE_DEG = 0.05
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


def noise_deg(u: np.ndarray) -> float:
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
    if not per[0].size:
        return np.zeros(0)
    stacked = np.stack(per)
    # an interval where nothing was measured has no speed (NaN), not a warning
    seen = np.isfinite(stacked).any(axis=0)
    out = np.full(stacked.shape[1:], np.nan)
    out[seen] = np.nanmax(stacked[:, seen], axis=0)
    return out * fps


def _scalar_noise(x: np.ndarray) -> float:
    """Jitter of a scalar series (degrees), as :func:`noise_deg`."""
    x = x[np.isfinite(x)]
    if x.size < 7:
        return 0.0
    # Lower quartile of |N(0, 0.72 σ)| is 0.23 σ.
    return float(np.percentile(np.abs(x - savgol_filter(x, 5, 3)), 25) / 0.23)


def _smooth_scalar(x: np.ndarray, window: int) -> np.ndarray:
    if window < 5 or x.size <= window or not np.isfinite(x).all():
        return x
    return savgol_filter(x, window, 2)


def channel(labels: FrameLabels, joints: np.ndarray, part: str) -> tuple[list, list, list]:
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
    if part not in LIMBS:
        return vec, [], []
    a, b = PART_SEGMENTS[part]
    m = PART_MIDDLE_JOINT[part]
    ja, jm, jb = joints[:, joint_index(a)], joints[:, joint_index(m)], joints[:, joint_index(b)]
    full = np.nanmedian(np.linalg.norm(jm - ja, axis=-1)) + np.nanmedian(np.linalg.norm(jb - jm, axis=-1))
    reach = np.linalg.norm(jb - ja, axis=-1) / full
    return vec, [np.degrees(reach)], [labels.bend_deg[:, labels.index(part)]]


def _lands_after(down: np.ndarray, end_f: int, hold: int) -> bool:
    """Whether a measured foot whose movement arrives at frame `end_f` lands within `hold` frames of it.

    A noisy movement's arrival is the fitted logistic's, which runs a few
    frames ahead of or behind the foot's contact (DESIGN.md's 3 cm and
    0.2 m/s, read from smoothed feet, which slow down late): a leg closing
    to the floor was written as a ``place low`` gesture just before its
    foot landed.  A foot in contact at any frame of the hold after the
    arrival (the hold the pose is read over) has landed, including a closing
    that arrives on the clip's last frame with no hold after it.
    """
    return bool(np.asarray(down[end_f : end_f + hold + 1], bool).any())


def _label_at(labels: FrameLabels, col: int, frames: slice) -> tuple[str, str, int]:
    """Label of a gesture column from its median pose over `frames` (robust to jitter and flicker)."""
    from ..notation.directions import bend_degree, classify_indices

    v, bd = held_pose(labels.vectors[:, col], labels.bend_deg[:, col], frames)
    d, lv = classify_indices(v[None])
    if d[0] < 0:
        return "", "", -1
    bend = int(bend_degree(bd)) if np.isfinite(bd) else 0
    return DIRECTION_NAMES[d[0]], LEVELS[lv[0]], bend


def _tilt_beyond_noise(labels: FrameLabels, col: int, frames: slice, margin: float, depth) -> float:
    """Tilt of a column's held vector over `frames` beyond the fit's trunk noise, degrees."""
    v, _ = held_pose(labels.vectors[:, col], None, frames)
    d = None
    if depth is not None and np.ndim(depth) == 2:
        rows = np.asarray(depth)[frames]
        rows = rows[np.isfinite(rows).all(axis=1)]  # no body frame, no line of sight: judged as without one
        d = rows.mean(axis=0) if len(rows) else None
    elif depth is not None:
        d = np.asarray(depth, float)
    return trunk_tilt_beyond_noise(v, margin, None if d is None else d / np.linalg.norm(d))


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
    cols = [labels.index(part)] + [labels.index(p) for p in LIMBS.get(part, ())]
    if part in LIMBS:
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
    key.needs_minimum = lambda f: bool(pair_only[f])
    key.forced = lambda f: bool(forced[f])
    return key


#: A weight arrival is a minimum of the pelvis's speed below this fraction of
#: the speed it reached since the previous arrival: each support movement is
#: one smooth push that starts and ends at (or near) rest.
ARRIVAL_DEPTH = 0.5


def _weight_arrivals(
    joints: np.ndarray, supporting: np.ndarray, flights, fps: float, on_grid: np.ndarray | None
) -> np.ndarray:
    """(T,) bool: frames where the weight arrives (clean motion).

    The pelvis moves with the supports only, each support movement in one
    smooth push: it comes to rest, or — a support following back to back,
    which starts from rest — slows to a minimum of its speed, where a
    support movement arrives.  That may be the very frame a leg gesture
    starts.  The weight arrives on a foot: in the air (`supporting`, (T, 2),
    no foot) the pelvis's slowest frame is the top of its flight.  After
    each of `flights` ((take-off, touchdown) frames) the landing arrives
    where :func:`~.flight.landing_rest` says, not at the bottom of the dip
    with which it absorbs the fall.
    """
    step = np.linalg.norm(np.diff(joints[:, joint_index("pelvis")], axis=0), axis=-1)
    out = np.zeros(len(joints), bool)
    if step.size == 0:
        return out
    nxt = np.r_[step[1:], 0.0]
    after = np.r_[step[2:], np.inf, np.inf]
    out[1:] = (step > 1e-9) & (nxt < step) & (nxt <= after)
    for _, touchdown in flights:
        rest = landing_rest(joints, touchdown, fps, on_grid)
        out[touchdown:rest] = False
        out[rest] = True
    # A push that arrives slows to a fraction of its peak; a shallow dip is
    # not one (the unturned pelvis of a fast pirouette wobbles by a few cm/s).
    speed, last = np.r_[step, 0.0], 0  # at rest after the clip
    for f in np.flatnonzero(out):
        if not speed[f] < ARRIVAL_DEPTH * speed[last:f].max(initial=0.0):
            out[f] = False
        else:
            last = f
    return out & np.asarray(supporting, bool).any(axis=1)


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
    elif noise <= CLEAN_NOISE_DEG:
        # Clean motion is left alone so movement boundaries stay on their frames.
        return 0
    else:
        w = max(5, int(round(0.3 * fps)))
        while w < 0.6 * fps and _noise_speed(noise, fps, w) > 15.0:
            w += 2
    return w + (1 - w % 2) if w > 0 else 0


def grid_frames(T: int, fps: float, tempo: Fraction, grid: Fraction) -> np.ndarray:
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
    upper, lower = (labels.index(p) for p in LIMBS[part])
    u = labels.vectors[:, upper]
    d2, lv2, _ = _label_at(labels, lower, frames)
    if not d2 or (d2 == "place" and lv2 == "middle"):
        return None
    if float(_angle_deg(u[start_f], u[end_f])) < 0.5 * params.min_amplitude_deg:
        return [(LIMBS[part][1], d2, lv2)]
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
    return [(LIMBS[part][0], d1, lv1), (LIMBS[part][1], d2, lv2)]


def has_exact_holds(labels: FrameLabels, joints: np.ndarray, min_intervals: int = 3) -> bool:
    """Whether some part (or the pelvis) both moves and holds exactly still (≥ `min_intervals` frame intervals).

    The virtual dancer's truth holds a pose exactly (its vectors repeat to
    the last bit), whereas fitted or recorded motion is never exactly still
    however smooth its fit: a fitted capture can measure under 0.05° of
    frame-to-frame jitter and would otherwise be taken for clean motion.
    """
    steps = [
        _angle_deg(u[:-1], u[1:]) for u in (labels.vectors[:, labels.index(p)] for p in tuple(LIMBS) + SINGLE_PARTS)
    ]
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


def gesture_movements(
    labels: FrameLabels,
    joints: np.ndarray,
    fps: float,
    params: SegmentParams,
    on_grid: np.ndarray | None = None,
    measured: bool = False,
    depth: np.ndarray | None = None,
    flights=(),
) -> list[Movement]:
    """The gesture movements of the arms, legs, head and chest (module docstring).

    Parameters
    ----------
    labels : FrameLabels
    joints : (T, J, 3) ndarray
        World joints, metres, z up.
    fps : float
    params : SegmentParams
    on_grid : (T,) ndarray of bool, optional
        Frames on the beat grid (clean motion parts only there).
    measured : bool
        Fitted or motion-captured joints (never exactly still).
    depth : (T, 3) ndarray, optional
        One camera's horizontal line of sight in body axes
        (:func:`~.measured.depth_axes`): a measured chest's lean is then
        corrected and judged in depth only (:func:`~.measured.upright_trunk`).
    flights : sequence of (int, int)
        Take-off and touchdown frames of each flight
        (:func:`~.flight.find_flights`).

    Returns
    -------
    list of Movement
    """
    out: list[Movement] = []
    T = labels.direction.shape[0]
    # Noisy poses are averaged over up to this long a hold after the arrival.
    hold = max(1, int(round(_HOLD_S * fps)))
    all_labels = labels
    for part in tuple(LIMBS) + SINGLE_PARTS:
        labels, margin = all_labels, 0.0
        if measured and part == "chest":
            # A fitted chest leans by a bias of its own (see .measured).
            labels, margin = upright_trunk(all_labels, part, depth)
        whole = labels.index(part)
        u_list, reach, bend_list = channel(labels, joints, part)
        noise = max([noise_deg(u) for u in u_list] + [_scalar_noise(x) for x in bend_list])
        # Truth-like motion (exact holds) is clean when its directions are:
        # a knee or elbow that bends and straightens within every movement
        # (Space, the floor) at a low frame rate leaves the bend a local
        # cubic's residual of a fraction of a degree, jitter or not.
        clean = params.smooth_s is None and not measured and max(noise_deg(u) for u in u_list) <= CLEAN_NOISE_DEG
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
        arrivals = (
            _weight_arrivals(joints, labels.supporting, flights, fps, on_grid) if clean and part in _FOOT else None
        )
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
                or (not clean and _lands_after(labels.supporting[:, _FOOT[part]], end_f, hold))
            ):
                # A leg that arrives on the floor is a support, not a gesture.
                state = ("place", "low", 0)
                continue
            if part in LIMBS:
                segs = _limb_symbols(labels, part, start_f, end_f, frames, params, clean)
                if segs is not None:
                    out.extend(Movement(p, start_f, end_f, t0, t1, d, lv, 0) for p, d, lv in segs)
                    state = ("", "", -1)
                    continue
            d, lv, bend = _label_at(labels, whole, frames)
            if not d or (d == "place" and lv == "middle"):
                continue
            if part not in LIMBS:
                bend = 0
                if margin and _tilt_beyond_noise(labels, whole, frames, margin, depth) < _TILT_DEG:
                    # Within the fit's own trunk noise of upright.
                    d, lv = _DEFAULT[part]
            if not clean:
                pose = held_pose(labels.vectors[:, whole], labels.bend_deg[:, whole] if part in LIMBS else None, frames)
                if _same_pose(pose, last_pose, state, params):
                    # Arrived within the fit's error of the last written pose:
                    # a label change would only be a boundary crossed by it.
                    continue
                if part in LIMBS or not margin:
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


def _hold_mean(values: np.ndarray):
    """Mean over a hold's frames (axis 0), NaN where none was measured (no warning: a hold may be unseen)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(values, axis=0)


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
        p0, p1 = _hold_mean(u[pre]), _hold_mean(u[post])
        p0, p1 = p0 / np.linalg.norm(p0), p1 / np.linalg.norm(p1)
        amp = float(_angle_deg(p0, p1))
        if np.isfinite(amp) and amp > weight:
            best, weight = progress_signal(u[lo : hi + 1], p0, p1), amp
    for x in x_list:
        x0, x1 = _hold_mean(x[pre]), _hold_mean(x[post])
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
