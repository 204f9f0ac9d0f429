"""Support movements of measured motion (fits, mocap): runs of the support state and their passes.

Measured joints (jitter above :data:`~.support_state.NOISY_POSITION_M`, or
fitted / recorded motion) have speeds as large as a plié's from the jitter
alone, so the movements are the changes of the mode-filtered support state
instead, timed by the Effort logistic fitted to the pelvis
(:func:`measured_support_movements`; a closing by its landing foot,
:mod:`.landing`, as the fitted pelvis lags).  A single-view fit also floats and
sinks the feet by centimetres and barely bends a knee seen from the front,
so there, in this order:

1. a foot flickering out of contact while the pelvis is not over the other
   foot keeps supporting (:func:`_balanced_contacts`);
2. pliés are read from the pelvis height (:func:`_pelvis_plie`);
3. grounded runs shorter than :data:`MIN_SUPPORT_S` are dropped, except
   the moment a free foot closes beside the standing one
   (:func:`_closings`);
4. a one-foot support that frees no foot (both stay on the floor while the
   fitted pelvis drifts over one of them) is a support on both
   (:func:`_feet_that_stay_down`), and a foot brushing the floor between two
   runs on the other foot takes no weight (:func:`_no_touch_downs`);
5. a middle level that a rise from plié to relevé only passes through is no
   symbol (:func:`_without_passages`);
6. a step must move the foot with the weight following
   (:func:`~.support_state.plausible_step`);
7. the flight of a step belongs to the step (:func:`_join_flights`), and a
   support not held is dropped or, when the next one leads on, merged into
   it (:func:`_drop_unheld`).
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from ..body import joint_index
from ..notation.model import LEVELS
from .labels import SUPPORT_SPEED_MS, FrameLabels, foot_points
from .movement import Movement
from .support_state import (
    OVER_FOOT_FRACTION,
    STEP_MIN_FRACTION,
    SUPPORT_PARTS,
    body_height,
    closing_place,
    fraction_along,
    mode_filter,
    smooth_positions,
    standing_foot_offset,
    step_direction,
    support_state,
)

__all__ = [
    "BALANCE_FOOT_M",
    "FLIGHT_GAP_S",
    "MIN_GROUNDED",
    "MIN_PELVIS_M",
    "MIN_SUPPORT_S",
    "PASSAGE_SPEED_MS",
    "PLIE_DROP_FRACTION",
    "measured_support_movements",
]


#: Noisy motion with feet on the floor in fewer frames than this fraction
#: writes no support symbols (see :func:`measured_support_movements`).  Even a
#: run of leaps lands for 0.1-0.3 s between flights of 0.3-0.5 s (a fifth
#: to a half of its frames; ``jesse_dance.bvh``: 10 %); feet found on the
#: floor less often than this mean the floor itself is wrong (the contact
#: decoder reads feet that never come within a few centimetres of it as in
#: the air, :data:`~.contact.MAX_HEIGHT_SD_M`).
MIN_GROUNDED = 0.05


#: Least pelvis displacement of a noisy support change, metres: a plié to
#: the DESIGN.md threshold (knees 30°) lowers it 2.8 cm, a relevé raises it
#: 5 cm, a weight transfer moves it 8-10 cm; contact flicker moves it not at all.
MIN_PELVIS_M = 0.025


#: Shortest grounded support state of noisy motion, seconds: shorter ones
#: are contact flicker (or a foot's flight within a step).
MIN_SUPPORT_S = 0.2


def _state_code(part, level):
    """One integer per support state (part and level indices, −1 in the air), for runs and mode filters."""
    return (part + 1) * 4 + (level + 1)


def _state_of(code: int) -> tuple[int, int]:
    """(part, level) of a :func:`_state_code`."""
    return code // 4 - 1, code % 4 - 1


def _runs(code: np.ndarray) -> list[tuple[int, int, int]]:
    """Runs of equal values: (value, first frame, last frame)."""
    edges = np.flatnonzero(np.diff(code)) + 1
    starts = np.r_[0, edges]
    ends = np.r_[edges - 1, len(code) - 1]
    return [(int(code[a]), int(a), int(b)) for a, b in zip(starts, ends)]


def measured_support_movements(labels: FrameLabels, joints: np.ndarray, fps: float) -> list:
    """Support movements of noisy motion, from changes of the support state.

    A centimetre of jitter makes the pelvis, knee and foot speeds as large
    as a plié's, so movements are not found from speed here.  Instead the
    support state (part, level) of the smoothed joints is mode-filtered over
    0.3 s and cut into grounded runs of at least :data:`MIN_SUPPORT_S` (a
    last run on both feet may be shorter: a closing that lands on the
    clip's last frame has nothing after it to hold); each
    change of state between consecutive runs is one movement, and so is a
    weight-bearing foot that left the floor and lands more than half a step
    (DESIGN.md step rule, :data:`STEP_MIN_FRACTION`) from under its hip (a
    step; a run on the other foot during a slow step's flight is still its
    own symbol).  The movement's start and arrival are those
    of the Effort logistic fitted to the pelvis's progress between the two
    runs (:mod:`.timing`): every support change moves the pelvis (down in a
    plié, up in a relevé, over the new support in a transfer or a step), so
    a change that moves it less than :data:`MIN_PELVIS_M` is contact
    flicker and writes nothing.
    """
    from .landing import closing_times
    from .timing import refine_times

    T = joints.shape[0]
    smooth = smooth_positions(joints, fps)
    labels = _balanced_contacts(labels, smooth, fps)
    part, level = support_state(labels, smooth)
    level = _pelvis_plie(part, level, smooth)
    grounded = float(np.mean(part >= 0))
    if grounded < MIN_GROUNDED:
        # Feet found on the floor this rarely mean the floor height is wrong,
        # and the supports would be invented.
        warnings.warn(
            f"feet on the floor in only {100 * grounded:.0f} % of {T} frames (even leaps land for "
            f"{100 * MIN_GROUNDED:.0f} % or more; is the floor height right? --floor sets it): "
            "no support symbols written",
            stacklevel=3,
        )
        return []
    w = max(3, int(round(0.3 * fps)) | 1)
    code = mode_filter(_state_code(part, level), w)
    # Held means seen in two frames at least: at 5 fps one frame is already
    # MIN_SUPPORT_S, and a state seen once is the fit's flicker (a squat's
    # rising foot leaves the contact band for one frame on its way down).
    min_len = max(2, int(round(MIN_SUPPORT_S * fps)))

    def held(c: int, a: int, b: int) -> bool:
        # Grounded runs held long enough.  The last may be short if it
        # stands on both feet: a closing that arrives on the clip's last
        # frame has nothing after it to hold (a single foot there is as
        # likely the fit's flicker).
        p, _ = _state_of(c)
        if p < 0:
            return False
        return b - a + 1 >= min_len or (b == T - 1 and p == 0)

    runs = [r for r in _runs(code) if held(*r)]
    lifted = _lifted(labels.supporting, smooth, fps)
    runs = _closings(runs, labels.supporting, lifted, smooth, min_len, level)
    runs = _feet_that_stay_down(runs, lifted, min_len)
    runs = _no_touch_downs(runs, lifted, min_len)
    runs, passed = _without_passages(runs, smooth[:, joint_index("pelvis"), 2], fps)
    height = body_height(smooth)
    offset = standing_foot_offset(smooth, labels.supporting)
    pelvis = joints[:, joint_index("pelvis")]
    out = []
    state = (0, LEVELS.index("middle"), "place")
    # The run the next movement leaves (before the first: standing from frame 0).
    prev_start, prev_end = 0, 0
    # Last frame each foot bore weight in a grounded run.
    bore = {0: 0, 1: 0}
    for c, a, b in runs:
        new_part, new_level = _state_of(c)
        # A step needs a flight: a weight-bearing foot off the floor between
        # the two runs (a swaying pelvis or a sliding fitted foot is no step).
        feet = {0: (0, 1), 1: (0,), 2: (1,)}[new_part]
        # Before the first grounded run nothing says where the feet were (a
        # fit finding the floor late), so that run is never a step.
        flew = bool(out) or prev_end > 0
        # A step onto one foot travels from where that foot last bore weight
        # (across the run on the other foot that carries its flight); a
        # closing (both feet) is judged from the run it leaves, whose pelvis
        # is already over the foot that stays.
        since = {f: min(prev_end, bore[f]) if new_part > 0 else prev_end for f in feet}
        flew = flew and any((~labels.supporting[since[f] : a + 1, f]).sum() >= 2 for f in feet)
        land = (a + b) // 2  # the smoothed foot is still landing at the run's first frame
        # A rise or a sinking on both feet is no step, however the fitted
        # feet slide in its course.
        flew = flew and a not in passed
        direction = step_direction(smooth, labels, prev_end, land, new_part, height, offset, since) if flew else "place"
        for f in feet:
            bore[f] = b
        new = (new_part, new_level, direction)
        if new[:2] == state[:2] and direction == "place":
            prev_start, prev_end = a, b
            continue
        # Window: from the middle of the hold left to the middle of this one.
        lo, hi = (prev_start + prev_end) // 2, min((a + b) // 2 + 1, T - 1)
        win = _pelvis_window(pelvis, lo, prev_end, a, hi, fps)
        if win is None:
            # A slow movement (a plié over two beats) moves the pelvis through
            # the inner halves of both holds: compare their outer halves.
            win = _pelvis_window(pelvis, prev_start, lo, hi, b, fps)
        if win is None:
            # The pelvis did not move: contact flicker, not a support change.
            continue
        ((t0, t1),) = refine_times([win])
        if new_part == 0 and state[0] > 0:
            # A closing arrives when the free foot lands: its own travel is
            # sharper (and on time) where the fitted pelvis lags.
            free = 2 - state[0]
            times = closing_times(
                smooth[:, joint_index(("right_ankle", "left_ankle")[free])],
                labels.supporting[:, free],
                min(prev_start, out[-1].start_frame if out else 0),
                a,
                fps,
            )
            t0, t1 = times if times is not None else (t0, t1)
        # Nothing arrives after the clip ends (the fitted curve may run past it).
        t1 = min(t1, (T - 1) / fps)
        start = int(np.clip(round(t0 * fps), 0, T - 1))
        end = int(np.clip(round(t1 * fps), start + 1, T - 1))
        state = new
        out.append(Movement(SUPPORT_PARTS[new_part], start, end, max(t0, 0.0), t1, direction, LEVELS[new_level], 0))
        prev_start, prev_end = a, b
    return _drop_unheld(_join_flights(out, smooth))


def _closings(runs: list, contact: np.ndarray, lifted: np.ndarray, joints: np.ndarray, min_len: int, level) -> list:
    """Grounded runs with a run on both feet where a free foot closes beside the standing one.

    A leg gesture that ends on the floor beside the standing foot is a
    closing: the weight arrives on both feet when that foot lands
    (DESIGN.md: a movement arrives at its end).  When the next support
    movement starts at once (the other foot leaves for a step), both feet
    stand for a frame or two only, below :data:`MIN_SUPPORT_S`, and the
    closing was lost: the gesture read as a leg returning to ``place low``
    and the support as the standing foot's.  A foot that was off the floor
    for at least `min_len` frames, lifted (:func:`_lifted`) on the way, and
    lands within half a step (:data:`~.support_state.STEP_MIN_FRACTION`) of
    its place beside the other foot (:func:`~.support_state.closing_place`)
    while the other stands for fewer than `min_len` frames, starts a run on
    both feet lasting while both stand, unless a run on both feet is already
    within `min_len` frames of it.  A foot landing farther away steps, and both
    feet standing longer leave the weight to the runs themselves.

    Parameters
    ----------
    runs : list of (code, first, last)
        Grounded runs held long enough (:func:`_runs` of :func:`_state_code`).
    contact : (T, 2) ndarray of bool
        Right, left foot on the floor, frame by frame (before any filtering).
    lifted : (T, 2) ndarray of bool
        :func:`_lifted`.
    joints : (T, J, 3) ndarray
        Smoothed joints.
    min_len : int
        Frames of a held run.
    level : (T,) ndarray of int
        Support level index per frame (middle where none).

    Returns
    -------
    list of (code, first, last)
    """
    contact = np.asarray(contact, bool)
    out = list(runs)
    if contact.shape[0] <= min_len:
        return out
    T = contact.shape[0]
    height = body_height(joints)
    # Landings: a foot down at f, off the floor for the min_len frames before,
    # the other foot down at f.
    down_before = np.cumsum(np.r_[np.zeros((1, 2), int), contact.astype(int)], axis=0)
    landing = np.zeros_like(contact)
    landing[min_len:] = (down_before[min_len:-1] - down_before[: T - min_len] == 0) & contact[min_len:]
    landing &= contact[:, ::-1]
    for f, k in zip(*np.nonzero(landing)):
        f, k = int(f), int(k)
        e = f - 1  # first frame of the foot's time off the floor
        while e > 0 and not contact[e - 1, k]:
            e -= 1
        if not lifted[e:f, k].any():
            continue
        ankle = joints[f, joint_index(("right_ankle", "left_ankle")[k])]
        if not np.linalg.norm((ankle - closing_place(joints, f, k))[:2]) < STEP_MIN_FRACTION * height:
            continue
        g = f
        while g + 1 < T and contact[g + 1].all():
            g += 1
        if g - f + 1 >= min_len or any(_state_of(c)[0] == 0 and a - min_len <= f <= b + min_len for c, a, b in out):
            # Both feet stood long enough for the runs to tell where the
            # weight went (a step the other foot stayed down for), or the
            # closing is there already.
            continue
        lv = int(level[f]) if level[f] >= 0 else LEVELS.index("middle")
        cut = []
        for c, a, b in out:
            if b < f or a > g:
                cut.append((c, a, b))
                continue
            if a < f:
                cut.append((c, a, f - 1))
            if b > g:
                cut.append((c, g + 1, b))
        out = sorted([*cut, (_state_code(0, lv), f, g)], key=lambda r: r[1])
    return out


#: Least vertical speed of the pelvis (m/s) through a middle-level run on
#: both feet that a rise from plié to relevé (or a sinking) only passes
#: through: 11-12 cm/s on the held-out phrases, against under 2 cm/s in
#: a held middle level.
PASSAGE_SPEED_MS = 0.05


def _without_passages(runs: list, pelvis_z: np.ndarray, fps: float) -> tuple[list, set]:
    """Drop the both-feet middle runs that a continuous rise or sinking passes through.

    From plié to relevé the knees straighten before the heels rise, so the
    support state passes through middle for a few frames (0.4 s in a
    two-beat rise); held for longer than :data:`MIN_SUPPORT_S`, that wrote
    a middle support between the low and the high one.  A run is a passage
    when it stands on both feet at middle level between a low and a high
    run on both feet and the pelvis keeps moving from the one towards the
    other through it (at :data:`PASSAGE_SPEED_MS` or faster).

    Returns
    -------
    runs : list of (code, first, last)
    passed : set of int
        First frames of the runs a passage was dropped before (their
        movement is a rise or a sinking, not a step).
    """
    low, middle, high = (LEVELS.index(x) for x in ("low", "middle", "high"))
    keep, passed = [], set()
    for i, run in enumerate(runs):
        c, a, b = run
        if 0 < i < len(runs) - 1 and _state_of(c) == (0, middle):
            before, after = _state_of(runs[i - 1][0]), _state_of(runs[i + 1][0])
            if {before, after} == {(0, low), (0, high)} and b > a:
                rising = after == (0, high)
                speed = (pelvis_z[b] - pelvis_z[a]) * fps / (b - a)
                if (speed if rising else -speed) >= PASSAGE_SPEED_MS:
                    passed.add(runs[i + 1][1])
                    continue
        keep.append(run)
    return keep, passed


def _lifted(contact: np.ndarray, joints: np.ndarray, fps: float) -> np.ndarray:
    """(T, 2) feet off the floor that are lifted or moving, not floating by a fit's error.

    A foot out of contact counts when it travels (a gesture, a step's
    flight: DESIGN.md's 0.2 m/s, horizontally) or stands higher than the
    other foot by more than :data:`BALANCE_FOOT_M`; a fitted foot in
    relevé rises and floats a few centimetres out of the contact band
    without either.
    """

    low, mid = foot_points(joints)
    out = ~np.asarray(contact, bool)
    for k in range(2):
        step = np.linalg.norm(np.diff(mid[k][:, :2], axis=0), axis=-1) * fps
        speed = np.r_[step, step[-1:]] if step.size else np.zeros(len(out))
        out[:, k] &= (speed >= SUPPORT_SPEED_MS) | (low[k] > low[1 - k] + BALANCE_FOOT_M)
    return out


def _feet_that_stay_down(runs: list, lifted: np.ndarray, min_len: int) -> list:
    """Grounded runs with a one-foot support that no foot left the floor for read as on both feet.

    DESIGN.md: a foot supports while it is on the floor and still.  The
    pelvis decides which of two grounded feet carry the weight
    (:func:`weight_bearing`), but a fitted pelvis drifts across the feet
    by several centimetres (along the camera's depth, which a 45° view
    mixes into the body's sideways axis) and crosses the quarter-way mark:
    a one-foot support written while both feet stood, typically for the
    last beats of a phrase.  A dancer's weight goes onto one foot to free
    the other, which then leaves the floor (a gesture, a step's flight);
    so a one-foot run is kept only if, since the last run on both feet, a
    foot was lifted (:func:`_lifted`) for at least `min_len` frames.

    Parameters
    ----------
    runs : list of (code, first, last)
        Grounded runs (:func:`_runs` of :func:`_state_code`).
    lifted : (T, 2) ndarray of bool
        Feet off the floor (:func:`_lifted`).
    min_len : int
        Frames off the floor that make a lift rather than flicker.

    Returns
    -------
    list of (code, first, last)
    """
    out = []
    since = 0  # first frame after the last run on both feet
    for c, a, b in runs:
        part, level = _state_of(c)
        if part == 0:
            since = b + 1
        elif np.all(np.asarray(lifted[since : b + 1], bool).sum(axis=0) < min_len):
            c = _state_code(0, level)
        out.append((c, a, b))
    return out


def _no_touch_downs(runs: list, lifted: np.ndarray, min_len: int) -> list:
    """A run on one foot between two on the other, which never left the floor, stays on the other.

    A low leg gesture passing by the standing foot (forward low to right
    low) touches the floor, and a fitted pelvis drifting towards it put the
    weight on it for a fifth of a second between two runs on the standing
    foot.  The weight cannot have gone over to the gesturing foot alone
    while the standing foot stayed down (lifted for fewer than `min_len`
    frames of the run, :func:`_lifted`): the run is the standing foot's.
    """
    out = list(runs)
    for i in range(1, len(runs) - 1):
        c, a, b = runs[i]
        part, level = _state_of(c)
        before, after = _state_of(runs[i - 1][0])[0], _state_of(runs[i + 1][0])[0]
        if part > 0 and before == after > 0 and before != part:
            standing = before - 1  # the foot of that one-foot support (0 right, 1 left)
            if np.asarray(lifted[a : b + 1, standing], bool).sum() < min_len:
                out[i] = (_state_code(before, level), a, b)
    return out


def _drop_unheld(moves: list) -> list:
    """Noisy support movements without a state that was left before it was reached.

    A ``place`` support movement (a weight shift, a change of level) that
    the next support movement starts before it arrives (their fitted
    logistics overlap) never held its state.  If that next one returns to
    the state before it, the fit swayed there and back — typically in the
    first frames of a clip, while the smoothed feet settle on the floor —
    and both are dropped.  Otherwise the two are one movement to the later
    state (a relevé lowering as its free foot closes: one ``support place
    middle``, not a change of level overlapping the closing), from the
    earlier start.  Steps are neither dropped nor merged.
    """
    out: list = []
    for m in moves:
        prev = out[-1] if out else None
        if prev is not None and m.start_time < prev.end_time and prev.direction == "place" == m.direction:
            before = (out[-2].part, out[-2].level) if len(out) > 1 else ("support", "middle")
            if (m.part, m.level) == before:
                out.pop()
                continue
            out[-1] = replace(m, start_frame=prev.start_frame, start_time=prev.start_time)
            continue
        out.append(m)
    return out


#: A weight transfer onto one foot that the other foot's step follows
#: within this many seconds (no hold between) is that step's flight.
FLIGHT_GAP_S = 0.5


def _join_flights(moves: list, joints: np.ndarray | None = None) -> list:
    """Support movements with each step's flight made part of the step.

    While one foot swings through a step the weight is on the other foot
    alone, and a slow step holds that state long enough to be a grounded
    run of its own: ``left_support place`` then ``right_support forward``.
    A notator writes the step from the moment the weight leaves: when the
    step onto the other foot follows within :data:`FLIGHT_GAP_S` (the
    pelvis never settled), the transfer is dropped and the step starts
    where it started.  But a transfer that brought the pelvis over its
    foot (:func:`_pelvis_over_foot`, given the smoothed `joints`) is a
    written weight transfer, however quickly a step follows it: a flight
    leaves the pelvis between the feet or carries it towards the step.
    """
    out: list = []
    for m in moves:
        prev = out[-1] if out else None
        if (
            prev is not None
            and m.direction != "place"
            and prev.direction == "place"
            and {prev.part, m.part} == {"right_support", "left_support"}
            and m.start_time - prev.end_time < FLIGHT_GAP_S
            and not (joints is not None and _pelvis_over_foot(joints, prev))
        ):
            out[-1] = replace(m, start_frame=prev.start_frame, start_time=prev.start_time)
            continue
        out.append(m)
    return out


def _pelvis_over_foot(joints: np.ndarray, move) -> bool:
    """Whether a one-foot support movement ends with the pelvis over its foot.

    The pelvis at the movement's arrival frame, along the line between the
    feet where they stood at its start: a stepping foot may already have
    moved at the arrival (and a fitted one shifts back before it leaves),
    which would put the line under a pelvis that never went over a foot.
    """
    T = joints.shape[0]
    a = int(np.clip(move.start_frame, 0, T - 1))
    f = int(np.clip(move.end_frame, 0, T - 1))
    fr, fl = joints[a, joint_index("right_ankle"), :2], joints[a, joint_index("left_ankle"), :2]
    if not float(np.sum((fl - fr) ** 2)) > 1e-6:
        return False
    u = float(fraction_along(joints[f, joint_index("pelvis"), :2], fr, fl))
    if move.part == "right_support":
        return u < OVER_FOOT_FRACTION
    return u > 1.0 - OVER_FOOT_FRACTION


#: A fitted foot counted off the floor while the pelvis is not over the
#: other foot supports after all when its lowest point is within this of the
#: other (supporting) foot's, metres.
BALANCE_FOOT_M = 0.08


#: Pelvis lowered below its standing height by this fraction of the body
#: height is a plié: knees bent 30° (DESIGN.md) lower a 1.70 m dancer's
#: pelvis 2.8 cm.
PLIE_DROP_FRACTION = 0.0165


def _distance_to_foot(joints: np.ndarray, p: np.ndarray, side: str) -> np.ndarray:
    """Horizontal distance, metres ``(T,)``, from points `p` ``(T, 2)`` to the `side` foot (ankle to toe)."""
    a = joints[:, joint_index(f"{side}_ankle"), :2]
    b = joints[:, joint_index(f"{side}_toe"), :2]
    with np.errstate(invalid="ignore"):
        u = np.clip(np.nan_to_num(fraction_along(p, a, b)), 0.0, 1.0)
    return np.linalg.norm(p - (a + u[:, None] * (b - a)), axis=-1)


def _balanced_contacts(labels: FrameLabels, joints: np.ndarray, fps: float) -> FrameLabels:
    """Contacts of measured feet, with a foot that flickers off the floor while it still carries weight put back.

    A fitted foot floats or sinks by a few centimetres (a relevé's toes
    rise 3-7 cm in a front view, a plié sinks the feet), so one foot of
    two can leave the 3 cm contact band while both stand: the support read
    as one foot (``right_support place high`` for a relevé).  But the
    weight can rest on one foot only with the pelvis over it
    (:func:`weight_bearing` asks for it within a quarter of the way to the
    other foot): a foot out of contact, slow, near the supporting foot's
    height (:data:`BALANCE_FOOT_M`) while the pelvis is not over the
    supporting foot supports too (between the feet, over the foot that
    left the floor, or behind both: a fitted foot floating in a plié or a
    squat).

    Parameters
    ----------
    labels : FrameLabels
    joints : (T, J, 3) ndarray
        Smoothed joints (:func:`smooth_positions`).
    fps : float

    Returns
    -------
    FrameLabels
        With the completed contacts (a restored foot at the other foot's level).
    """
    from .labels import with_supports

    sup = np.asarray(labels.supporting, bool)
    if sup.shape[0] < 2:
        return labels
    pelvis = joints[:, joint_index("pelvis"), :2]
    low, mid = foot_points(joints)
    # The weight rests on one foot alone only with the pelvis over it: within
    # OVER_FOOT_FRACTION of the feet's distance of that foot (heel to toe),
    # in any direction (a squat sits the pelvis 30 cm behind both feet: over
    # neither, whatever its projection on the line between them).
    apart = np.linalg.norm(mid[1][:, :2] - mid[0][:, :2], axis=-1)
    over_other = tuple(
        _distance_to_foot(joints, pelvis, side) < OVER_FOOT_FRACTION * apart for side in ("right", "left")
    )
    out = sup.copy()
    for k in range(2):
        step = np.linalg.norm(np.diff(mid[k], axis=0), axis=-1) * fps
        speed = np.r_[step[:1], np.fmin(step[1:], step[:-1]), step[-1:]] if step.size > 1 else np.zeros(len(sup))
        near = np.abs(low[k] - low[1 - k]) < BALANCE_FOOT_M
        not_balanced = ~over_other[1 - k]
        out[:, k] |= sup[:, 1 - k] & ~sup[:, k] & not_balanced & near & (speed < SUPPORT_SPEED_MS)
    if np.array_equal(out, sup):
        return labels
    # A restored foot stands at the level of the foot it shares the weight with.
    other = labels.support_level[:, ::-1]
    level = np.where(sup, labels.support_level, np.where(out, other, -1))
    return with_supports(labels, out, level)


def _pelvis_plie(part: np.ndarray, level: np.ndarray, joints: np.ndarray) -> np.ndarray:
    """Support levels of measured motion with pliés read from the pelvis height, not the knees.

    Seen from the front a fitted knee hardly bends in a plié (45° read as
    20-26°, standing 15°: the flexion is in depth), yet bends past 30° on
    a straight-legged landing; the pelvis drops as far as the dancer's (6 cm
    in a 45° plié).  A supported frame not in relevé is low exactly when its
    pelvis is :data:`PLIE_DROP_FRACTION` of the body height below the
    standing height (the knees bent 30°), taken as the 75th percentile of the
    pelvis height over the supported frames not in relevé: a phrase stands
    for at least a quarter of them.  Fewer than five such frames leave the
    levels alone.
    """
    z = joints[:, joint_index("pelvis"), 2]
    high, low = LEVELS.index("high"), LEVELS.index("low")
    flat = (part >= 0) & (level != high) & np.isfinite(z)
    if flat.sum() < 5:
        return level
    ref = float(np.percentile(z[flat], 75))
    drop = PLIE_DROP_FRACTION * body_height(joints)
    return np.where(flat, np.where(z < ref - drop, low, LEVELS.index("middle")), level)


def _pelvis_window(pelvis: np.ndarray, lo: int, a: int, b: int, hi: int, fps: float):
    """``(t, p, t0, t1)`` for :func:`~.timing.refine_times`: the pelvis's
    progress from its mean over [lo, a] to its mean over [b, hi] (the state
    changes between frames a and b); None when it moves less than
    :data:`MIN_PELVIS_M` or the window is too short."""
    before, after = pelvis[lo : a + 1], pelvis[b : hi + 1]
    # An empty or unmeasured half window has no mean to measure from.
    if hi - lo < 4 or not (np.isfinite(before).all(axis=1).any() and np.isfinite(after).all(axis=1).any()):
        return None
    p0 = np.nanmean(before, axis=0)
    p1 = np.nanmean(after, axis=0)
    d = p1 - p0
    n2 = float(d @ d)
    if not n2 > MIN_PELVIS_M**2:
        return None
    prog = (pelvis[lo : hi + 1] - p0) @ d / n2
    # The state changes somewhere mid-movement: start the fit from the
    # middles of the half windows on either side of the change.
    return np.arange(lo, hi + 1) / fps, prog, 0.5 * (lo + a) / fps, 0.5 * (b + hi) / fps
