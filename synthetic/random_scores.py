"""Random valid scores for property tests of the whole round trip.

:func:`random_score` draws a phrase that the virtual dancer can perform
exactly.  Guarantees (each is checked by ``tests/synthetic``):

* a valid :class:`Score` (it passes the model's own validation): times on a
  ¼-beat grid, every duration ≥ ½ beat, no two symbols of one part overlap;
* per limb, a whole-limb symbol never overlaps its segment symbols, and upper
  and lower segments (``split_arms=True``) move together over the same span;
* a leg never gestures while its foot is notated as supporting;
* consecutive symbols of a part differ (a new direction, level or bend), so
  every symbol is a visible movement;
* reachable: every gesture direction is within the joint extremes (no arm
  through the torso behind-low, no leg higher than the hip allows, no
  gesture leg down at place low where it would stand on the floor; the head
  within the neck's range of the chest, moving whenever the chest moves).
  This is *verified*: the draw is interpreted at the caller's frame rate
  (:data:`VERIFY_FPS` by default) and redrawn (same generator stream) until
  no :class:`~synthetic.interpret.UnreachableWarning` is raised (end poses,
  paths within the extremes, holds, supports), so quantising the
  interpreted joints gives back exactly the symbols.  No arm symbol ends
  while the chest moves, and leg gestures never end while the weight
  shifts.  A foot's speed near the 0.2 m/s support threshold depends on the
  frame rate, so verify at the rate the score will be performed at
  (property-tested at 10–50 fps).

Supports follow a dancer's logic: both feet (plié, middle, relevé), a
weight transfer onto one foot followed by gestures of the free leg and a
closing onto both feet (after a step onto that foot, a change of level
there: the weight is on it already), or a step (``right_support forward middle`` …).
A change of support level takes at least :data:`LEVEL_CHANGE_S` seconds (a
heel moving faster does not read as supporting), and the foot that has
just landed from a step or a closing keeps the weight for the next symbol
(a foot lifted again on its landing frame never reads as supporting).
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import numpy as np

from capture2notation.errors import SyntheticError
from capture2notation.notation.model import Effort, Score, Symbol

__all__ = ["ARM_TARGETS", "CHEST_TARGETS", "DEFAULT_PARTS", "HEAD_TARGETS", "random_score"]

#: Parts drawn by default; ``"legs"`` stands for supports plus leg gestures.
DEFAULT_PARTS: tuple[str, ...] = ("right_arm", "left_arm", "head", "chest", "legs")

_SECTORS = ("forward", "right_forward", "right", "right_back", "back", "left_back", "left", "left_forward")


def _mirror(direction: str) -> str:
    if direction.startswith("right"):
        return "left" + direction[5:]
    if direction.startswith("left"):
        return "right" + direction[4:]
    return direction


def _arm_targets() -> tuple:
    """(direction, level, bend) for the right arm: everything but through the torso."""
    out = []
    for d in _SECTORS + ("place",):
        for lv in ("high", "middle", "low"):
            if (d == "place" and lv == "middle") or d == "left_back" or (d, lv) in {("back", "low"), ("left", "low")}:
                continue
            out += [(d, lv, b) for b in (0, 1, 2)]
    return tuple(out)


def _leg_targets() -> tuple:
    """(direction, level, bend) for the right leg, within the hip's extremes."""
    out = []
    for d in ("forward", "right_forward", "left_forward"):
        # High legs straight only: a bent knee lifts the thigh past the hip's 135°.
        out += [(d, "high", 0)] + [(d, lv, b) for lv in ("middle", "low") for b in (0, 1, 2)]
    for d in ("right", "right_back"):
        out += [(d, lv, b) for lv in ("middle", "low") for b in (0, 1)]
    out += [("back", "middle", 0), ("back", "low", 0), ("back", "low", 1)]
    out += [("left", "low", 0), ("left_back", "low", 0)]
    return tuple(out)


#: Targets of the right arm (the left arm mirrors them).
ARM_TARGETS: tuple = _arm_targets()
LEG_TARGETS: tuple = _leg_targets()
#: Head: upright, tilted 45° any way, bowed forward.
HEAD_TARGETS: tuple = (("place", "high", 0),) + tuple((d, "high", 0) for d in _SECTORS) + (("forward", "middle", 0),)


def _chest_targets() -> tuple:
    """The head's targets that the waist and chest reach exactly.

    ``chest back high`` (the spine arches to about 40° within the waist's
    and chest's extensions) and ``chest forward middle`` (about 76° of
    flexion) are approached only (:func:`synthetic.trunk.chest_reach`): the
    chest arrives a few degrees off its written direction, still in the
    symbol's sector (so :mod:`synthetic.reach` raises nothing), but a
    quantiser parting back-to-back movements at exactly written poses can
    no longer see the arrival.
    """
    from capture2notation.body import Body
    from capture2notation.notation.directions import canonical_vector

    from .trunk import chest_reach

    reach = chest_reach(Body())
    return tuple(
        t
        for t in HEAD_TARGETS
        if np.allclose(reach(canonical_vector(t[0], t[1])[None])[0], canonical_vector(t[0], t[1]), atol=1e-9)
    )


#: Chest: the head's targets within the trunk's extremes.
CHEST_TARGETS: tuple = _chest_targets()
_DURATIONS = tuple(Fraction(n, 4) for n in (2, 3, 4, 6, 8))
#: Frame rate at which a draw is verified (support speeds need a real rate).
VERIFY_FPS = 25.0
#: Shortest change of support level, seconds.
LEVEL_CHANGE_S = 0.7
_GAPS = tuple(Fraction(n, 4) for n in (0, 0, 1, 2, 4))


def _pick(rng, seq, avoid=None):
    choices = [x for x in seq if x != avoid]
    return choices[int(rng.integers(len(choices)))]


def _side(target, part):
    d, lv, b = target
    return (_mirror(d) if part.startswith("left") else d), lv, b


def _moving(symbols, beat) -> bool:
    """Whether any of `symbols` is mid-movement at `beat`."""
    return any(s.start < beat < s.end for s in symbols)


def _gesture_track(rng, part, targets, t0, t1, with_bend=True, chest=()):
    """Symbols of one part between beats t0 and t1, with random holds.

    No symbol ends while the `chest` moves: the arms hang from the chest, so
    their reach at arrival then does not depend on the frame rate.
    """
    out, t, last = [], Fraction(t0), None
    while True:
        t += _GAPS[int(rng.integers(len(_GAPS)))]
        dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
        if t + dur > t1:
            return out
        if _moving(chest, t + dur):
            t += dur
            continue
        d, lv, b = _side(_pick(rng, targets, last), part)
        last = _side((d, lv, b), part)
        out.append(Symbol(t, dur, part, d, lv, b if with_bend else 0))
        t += dur


def _head_ok(target, chest_dir) -> bool:
    """Whether the neck can hold head `target` over a chest pointing `chest_dir`.

    Within 40° of the chest (the neck bends 45° sideways), or a bow of the
    head to the horizontal over an upright chest (the neck bows 90°).
    """
    from capture2notation.notation.directions import canonical_vector

    h = canonical_vector(target[0], target[1])
    if h @ chest_dir >= np.cos(np.radians(40)):
        return True
    return target[:2] == ("forward", "middle") and chest_dir[2] > 1 - 1e-9


def _head_track(rng, chest, t1):
    """Head symbols that the neck can hold whatever the chest does.

    The head's direction is in the body frame, so a tilted chest leaves the
    neck less range.  The head moves with every chest movement (same span),
    to a target the neck can hold over the chest's new direction, so no head
    hold is ever carried off by the chest; between chest movements it moves
    freely within the neck's range.
    """
    from capture2notation.notation.directions import canonical_vector

    out, last = [], None
    chest = sorted(chest, key=lambda c: c.start)
    up = np.array([0.0, 0.0, 1.0])
    # Gaps between chest movements, each with the chest's direction then.
    spans, t, c_dir = [], Fraction(0), up
    for c in chest:
        spans.append((t, c.start, c_dir, None))
        c_dir = canonical_vector(c.direction, c.level)
        spans.append((c.start, c.end, c_dir, c))
        t = c.end
    spans.append((t, Fraction(t1), c_dir, None))

    def draw(start, dur, c_dir):
        nonlocal last
        ok = [x for x in HEAD_TARGETS if x != last and _head_ok(x, c_dir)]
        if not ok:
            return  # only the head's present direction suits: it holds
        d, lv, _ = ok[int(rng.integers(len(ok)))]
        last = (d, lv, 0)
        out.append(Symbol(start, dur, "head", d, lv))

    for start, end, c_dir, c in spans:
        if c is not None:
            draw(c.start, c.duration, c_dir)
            continue
        t = start
        while True:
            t += _GAPS[int(rng.integers(len(_GAPS)))]
            dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
            if t + dur > end:
                break
            draw(t, dur, c_dir)
            t += dur
    return out


def _split_arm_track(rng, side, t0, t1, chest=()):
    """Upper arm and forearm symbols over the same spans (elbow bend ≤ 120°)."""
    out, t, last = [], Fraction(t0), None
    upper = [x for x in ARM_TARGETS if x[2] == 0]
    from capture2notation.notation.directions import canonical_vector

    while True:
        t += _GAPS[int(rng.integers(len(_GAPS)))]
        dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
        if t + dur > t1:
            return out
        if _moving(chest, t + dur):
            t += dur
            continue
        u = _pick(rng, upper, last)
        v1 = canonical_vector(u[0], u[1])
        fore = [x for x in upper if np.degrees(np.arccos(np.clip(canonical_vector(x[0], x[1]) @ v1, -1, 1))) <= 120]
        f = _pick(rng, fore)
        last = u
        (ud, ul, _), (fd, fl, _) = _side(u, side), _side(f, side)
        out.append(Symbol(t, dur, f"{side}_upper_arm", ud, ul))
        out.append(Symbol(t, dur, f"{side}_forearm", fd, fl))
        t += dur


def _other(foot: str) -> str:
    return "left" if foot == "right" else "right"


#: Flight time of a random spring, seconds: long enough to see (issue 14
#: asks captures to find flights of 0.3 s and more), low enough to be a
#: dancer's (a 0.6 s flight rises 0.44 m).
FLIGHT_S = (0.3, 0.6)
#: Fastest turn on both feet, radians per second: each foot slides round the
#: feet's midpoint (0.094 m away for a 1.70 m dancer) at under 0.14 m/s,
#: slower than DESIGN.md's 0.2 m/s support speed.
SWIVEL_RAD_S = 1.4
#: Turns of a random pirouette (on one foot, in relevé) and of a turn in the
#: air, in eighths of a turn (1/8 … 2 turns; 1/4 … 1 turn in the air).
PIROUETTE_EIGHTHS = (1, 16)
AIR_TURN_EIGHTHS = (2, 4, 8)
#: Steps of a random walk (travel).
WALK_STEPS = (2, 4)
_SPRING_FORMS = ("jump", "hop", "leap", "assemblé", "sissonne")


def _free_leg_targets(side: str) -> list:
    """Low gestures of a free leg (retiré-like lifts and low extensions), for `side`."""
    return [_side(x, side) for x in LEG_TARGETS if x[1] == "low"]


def _pirouette(rng, t, end, slow, landed):
    """A turn on one foot rising into relevé, the free leg lifted, then a closing."""
    foot = ("right", "left")[int(rng.integers(2))] if landed is None else landed
    free = _other(foot)
    d = slow[int(rng.integers(len(slow)))]
    close = slow[0]
    if t + d + close > end:
        return None
    amount = Fraction(int(rng.integers(PIROUETTE_EIGHTHS[0], PIROUETTE_EIGHTHS[1] + 1)), 8)
    turn = ("right", "left")[int(rng.integers(2))]
    leg = _pick(rng, _free_leg_targets(free))
    syms = [
        Symbol(t, d, f"{foot}_support", "place", "high"),
        Symbol(t, d, "turn", turn, None, amount=amount),
        Symbol(t, d, f"{free}_leg", *leg),
        Symbol(t + d, close, "support", "place", "middle"),
    ]
    return syms, t + d + close, free


def _swivel(rng, t, end, bpm):
    """A slow turn on both feet (an eighth or a quarter)."""
    amount = Fraction(int(rng.integers(1, 3)), 8)
    least = float(amount) * 2 * np.pi / SWIVEL_RAD_S
    durs = [d for d in _DURATIONS if float(d * 60 / bpm) >= least]
    if not durs:
        return None
    d = durs[int(rng.integers(len(durs)))]
    if t + d > end:
        return None
    return [Symbol(t, d, "turn", ("right", "left")[int(rng.integers(2))], None, amount=amount)], t + d


def _spring(rng, t, end, bpm, slow, landed, level_now, turns):
    """One spring of a random form: preparation in plié, flight, landing in plié, recovery.

    Returns None when it does not fit before `end`.  A two-foot take-off
    needs both feet standing (no foot a step has just released).
    """
    form = _SPRING_FORMS[int(rng.integers(len(_SPRING_FORMS)))]
    flights = [Fraction(n, 4) for n in range(2, 9) if FLIGHT_S[0] <= float(Fraction(n, 4) * 60 / bpm) <= FLIGHT_S[1]]
    if not flights:
        return None
    fd = flights[int(rng.integers(len(flights)))]
    land = Fraction(int(rng.integers(2, 5)), 4)
    prep = slow[int(rng.integers(len(slow)))]
    recover = slow[0]
    syms = []
    foot = ("right", "left")[int(rng.integers(2))] if landed is None else landed
    free = _other(foot)
    if form in ("jump", "sissonne"):
        if level_now != "low":
            syms.append(Symbol(t, prep, "support", "place", "low"))
            t += prep
    else:
        syms.append(Symbol(t, prep, f"{foot}_support", "place", "low"))
        syms.append(Symbol(t, prep, f"{free}_leg", *_pick(rng, _free_leg_targets(free))))
        t += prep
    ta, tb = t, t + fd
    te = tb + land
    if te + recover > end:
        return None
    syms.append(Symbol(ta, fd, "support", "air", None))
    if turns and int(rng.integers(2)):
        k = AIR_TURN_EIGHTHS[int(rng.integers(len(AIR_TURN_EIGHTHS)))]
        syms.append(Symbol(ta, fd, "turn", ("right", "left")[int(rng.integers(2))], None, amount=Fraction(k, 8)))
    two = ("place", "forward", "back", "right", "left")
    if form in ("jump", "assemblé"):
        syms.append(Symbol(tb, land, "support", two[int(rng.integers(len(two)))], "low"))
        syms.append(Symbol(te, recover, "support", "place", "middle"))
        return syms, te + recover, None
    lander = {"hop": foot, "leap": free, "sissonne": foot}[form]
    other = _other(lander)
    one = ("place", "forward", "back", lander)
    syms.append(Symbol(tb, land, f"{lander}_support", one[int(rng.integers(len(one)))], "low"))
    if form != "hop":
        # The leg that does not land extends in the air and holds until the closing.
        syms.append(Symbol(ta, fd + land, f"{other}_leg", *_pick(rng, _free_leg_targets(other))))
    syms.append(Symbol(te, recover, "support", "place", "middle"))
    return syms, te + recover, other


def _walk(rng, t, end, landed):
    """Travel: a few steps of alternating feet, forward, back, sideways or diagonally."""
    foot = ("right", "left")[int(rng.integers(2))] if landed is None else _other(landed)
    syms = []
    for _ in range(int(rng.integers(WALK_STEPS[0], WALK_STEPS[1] + 1))):
        d = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
        if t + d > end:
            break
        ways = ("forward", "back", foot, f"{foot}_forward", f"{foot}_back")
        syms.append(Symbol(t, d, f"{foot}_support", ways[int(rng.integers(len(ways)))], "middle"))
        t += d
        landed, foot = foot, _other(foot)
    return (syms, t, landed) if syms else None


def _legs_track(rng, n_beats, bpm, turns=False, springs=False, travel=False):
    """Supports and leg gestures: weight transfers, free-leg gestures, steps.

    A change of support level lasts at least :data:`LEVEL_CHANGE_S` seconds
    at `bpm` (the fastest tempo of the score),
    so the feet stay slower than DESIGN.md's 0.2 m/s support threshold (a
    heel dropped from relevé to plié faster no longer reads as supporting).
    After a step or a closing, the foot that has just landed keeps the
    weight: the next support names it, or the other foot steps (released
    at once, a foot that has just landed would never rest).
    """
    out, t, end = [], Fraction(0), Fraction(n_beats)
    slow = [d for d in _DURATIONS if d * 60 / bpm >= LEVEL_CHANGE_S] or [max(_DURATIONS)]
    landed = None  # a foot that has just landed: it keeps the weight next
    released = None  # the foot a step left off the floor
    level_now = "middle"  # support level on both feet
    extras = [k for k, on in (("pirouette", turns), ("swivel", turns), ("spring", springs), ("walk", travel)) if on]
    while True:
        if extras and rng.random() < 0.5:
            kind = extras[int(rng.integers(len(extras)))]
            if kind == "pirouette":
                got = _pirouette(rng, t, end, slow, landed)
            elif kind == "swivel":
                got = _swivel(rng, t, end, bpm) if released is None else None
                got = None if got is None else (*got, None)
            elif kind == "spring":
                got = None if released is not None else _spring(rng, t, end, bpm, slow, landed, level_now, turns)
            else:
                got = _walk(rng, t, end, landed)
            if got is None:
                if t + max(_DURATIONS) > end:
                    return out
                continue
            syms, t, landed = got
            out += syms
            released = _other(landed) if kind == "walk" else None
            level_now = "middle" if kind != "swivel" else level_now
            continue
        kind = ("both", "single", "step")[int(rng.choice(3, p=(0.35, 0.45, 0.2)))]
        dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
        if kind in ("both", "single"):
            dur = slow[int(rng.integers(len(slow)))]
        if kind == "both":
            if t + dur > end:
                return out
            level_now = ("low", "middle", "high")[int(rng.integers(3))]
            out.append(Symbol(t, dur, "support", "place", level_now))
            t += dur
        elif kind == "step":
            # After a step the other foot steps (a walk): the foot just
            # landed bears the weight meanwhile.
            foot = ("right", "left")[int(rng.integers(2))] if landed is None else _other(landed)
            d = ("forward", "back", foot)[int(rng.integers(3))]
            if t + dur > end:
                return out
            out.append(Symbol(t, dur, f"{foot}_support", d, "middle"))
            t += dur
            level_now = "middle"
            landed, released = foot, _other(foot)
            continue
        else:
            foot = ("right", "left")[int(rng.integers(2))] if landed is None else landed
            free = _other(foot)
            close = slow[0]
            gestures = []
            g_t, last = t + dur, None
            for _ in range(1 + int(rng.integers(2))):
                g_dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
                if g_t + g_dur + close > end:
                    break
                target = _side(_pick(rng, LEG_TARGETS, last), free)
                last = _side(target, free)
                gestures.append(Symbol(g_t, g_dur, f"{free}_leg", *target))
                g_t += g_dur
            if not gestures:
                return out
            level = ("low", "middle", "high")[int(rng.integers(3))]
            if released is not None and level == "middle":
                # Just stepped onto `foot` (at middle level): the weight is
                # there already, so a middle support would show nothing.
                level = ("low", "high")[int(rng.integers(2))]
            out.append(Symbol(t, dur, f"{foot}_support", "place", level))
            out += gestures
            out.append(Symbol(g_t, close, "support", "place", "middle"))
            t = g_t + close
            level_now = "middle"
            landed, released = free, None  # the free foot has just closed
            continue
        # On both feet: a foot a step released has just closed.
        landed, released = released, None


def random_score(
    rng: np.random.Generator,
    n_beats: int = 8,
    parts=DEFAULT_PARTS,
    split_arms: bool = False,
    tempo=None,
    random_effort: bool = False,
    max_tries: int = 50,
    fps: float = VERIFY_FPS,
    *,
    turns: bool = False,
    springs: bool = False,
    travel: bool = False,
    axes: str = "standard",
) -> Score:
    """Draw a random valid, renderable score (see the module docstring).

    Parameters
    ----------
    rng : numpy.random.Generator
        The only source of randomness.
    n_beats : int
        Symbols end at or before this beat (>= 2).
    parts : iterable of str
        Any of ``right_arm left_arm head chest legs``.
    split_arms : bool
        Notate arms by ``upper_arm`` + ``forearm`` pairs instead of whole arms.
    tempo : int or Fraction, optional
        Beats per minute; default drawn from 60-120.
    random_effort : bool
        Draw an Effort (time in [−4, −2], weight in [0.35, 0.7], space in
        [0, 1]) into the header; otherwise the score has none (neutral).
    max_tries : int
        Redraws allowed before giving up.
    fps : float
        Frame rate at which the draw is verified: the one it will be
        performed at (a foot's speed near DESIGN.md's 0.2 m/s support
        threshold depends on the frame rate through finite differences).
    turns : bool
        With ``"legs"``: pirouettes on one foot rising into relevé, the free
        leg lifted (1/8 … 2 turns, either way), slow turns on both feet (an
        eighth or a quarter, under :data:`SWIVEL_RAD_S`), and with `springs`
        turns in the air (a quarter, half or whole turn).
    springs : bool
        With ``"legs"``: springs of the five forms (jump, hop, leap,
        assemblé, sissonne), from a plié into flight of
        :data:`FLIGHT_S` seconds, landing in plié (in place or a step's
        length away), then rising or closing.
    travel : bool
        With ``"legs"``: walks of :data:`WALK_STEPS` steps of alternating
        feet, forward, back, sideways or diagonally (relative to the front).
    axes : {"standard", "body"}
        The score's key (arms and head read in the body cross for ``"body"``).

    With none of `turns`, `springs`, `travel` and the standard key, the draw
    is the same as before they existed (same generator stream).

    Returns
    -------
    Score

    Raises
    ------
    SyntheticError
        Bad arguments, or no reachable draw in `max_tries`.
    """
    from .interpret import UnreachableWarning, interpret

    if not isinstance(rng, np.random.Generator):
        raise SyntheticError(f"random_score needs a numpy.random.Generator, got {type(rng).__name__}")
    if int(n_beats) < 2:
        raise SyntheticError(f"n_beats must be >= 2, got {n_beats}")
    known = {"right_arm", "left_arm", "head", "chest", "legs"}
    parts = tuple(parts)
    if not set(parts) <= known:
        raise SyntheticError(f"unknown parts {sorted(set(parts) - known)}; expected some of {sorted(known)}")
    # Supports are timed for the fastest tempo that may be drawn (the tempo
    # is drawn after the symbols, keeping the arms' and head's draws); turns
    # and springs are timed in seconds, so with them the tempo comes first.
    extended = turns or springs or travel
    legs_bpm = Fraction(120) if tempo is None else Fraction(tempo)
    for _ in range(int(max_tries)):
        early_bpm = None
        if extended and tempo is None:
            early_bpm = Fraction(int(rng.integers(60, 121)))
            legs_bpm = early_bpm
        syms: list = []
        chest: list = []
        if "chest" in parts:
            chest = _gesture_track(rng, "chest", CHEST_TARGETS, 0, n_beats, False)
        for p in parts:
            if p == "chest":
                syms += chest
            elif p == "head":
                syms += _head_track(rng, chest, n_beats)
            elif p == "legs":
                syms += _legs_track(rng, n_beats, legs_bpm, turns=turns, springs=springs, travel=travel)
            elif p in ("right_arm", "left_arm") and split_arms:
                syms += _split_arm_track(rng, p.split("_")[0], 0, n_beats, chest)
            elif p in ("right_arm", "left_arm"):
                syms += _gesture_track(rng, p, ARM_TARGETS, 0, n_beats, chest=chest)
        if early_bpm is not None:
            bpm = early_bpm
        else:
            bpm = Fraction(int(rng.integers(60, 121))) if tempo is None else Fraction(tempo)
        effort = None
        if random_effort:
            effort = Effort(
                time=round(float(rng.uniform(-4.0, -2.0)), 3),
                weight=round(float(rng.uniform(0.35, 0.7)), 3),
                space=round(float(rng.uniform(0.0, 1.0)), 3),
            )
        if not syms:
            continue
        score = Score(tuple(syms), title="random", tempo=bpm, meter=4, effort=effort, axes=axes)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UnreachableWarning)
            interpret(score, fps=fps)
        if not any(issubclass(w.category, UnreachableWarning) for w in caught):
            return score
    raise SyntheticError(f"no reachable random score in {max_tries} draws (n_beats={n_beats}, parts={parts})")
