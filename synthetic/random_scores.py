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
  within 40° of the chest).  This is *verified*: the draw is interpreted and
  redrawn (same generator stream) until no
  :class:`~synthetic.interpret.UnreachableWarning` is raised, so quantising
  the interpreted joints gives back exactly the symbols.  No arm or head
  symbol ends while the chest moves, and leg gestures never end while the
  weight shifts, so the check holds at any frame rate.

Supports follow a dancer's logic: both feet (plié, middle, relevé), a
weight transfer onto one foot followed by gestures of the free leg and a
closing onto both feet, or a step (``right_support forward middle`` …).
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import numpy as np

from capture2notation.errors import SyntheticError
from capture2notation.notation.model import Effort, Score, Symbol

__all__ = ["random_score", "DEFAULT_PARTS", "ARM_TARGETS", "HEAD_TARGETS", "CHEST_TARGETS"]

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
        out += [(d, "high", b) for b in (0, 1)] + [(d, lv, b) for lv in ("middle", "low") for b in (0, 1, 2)]
    for d in ("right", "right_back"):
        out += [(d, lv, b) for lv in ("middle", "low") for b in (0, 1)]
    out += [("back", "middle", 0), ("back", "low", 0), ("back", "low", 1)]
    out += [("left", "low", 0), ("left_back", "low", 0)]
    return tuple(out)


#: Targets of the right arm (the left arm mirrors them).
ARM_TARGETS: tuple = _arm_targets()
LEG_TARGETS: tuple = _leg_targets()
#: Head and chest: upright, tilted 45° any way, bowed forward.
HEAD_TARGETS: tuple = (("place", "high", 0),) + tuple((d, "high", 0) for d in _SECTORS) + (("forward", "middle", 0),)
CHEST_TARGETS: tuple = HEAD_TARGETS
_DURATIONS = tuple(Fraction(n, 4) for n in (2, 3, 4, 6, 8))
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


def _head_track(rng, chest, t1):
    """Head symbols that the neck can reach from wherever the chest is then.

    The head's direction is in the body frame, so a tilted chest leaves the
    neck less range: each head target lies within 40° of the chest's
    direction at the head's arrival, and no head movement ends while the
    chest is moving.
    """
    from capture2notation.notation.directions import canonical_vector

    def chest_dir(beat):
        if _moving(chest, beat):
            return None
        d = np.array([0.0, 0.0, 1.0])
        for c in chest:
            if c.end <= beat:
                d = canonical_vector(c.direction, c.level)
        return d

    out, t, last = [], Fraction(0), None
    while True:
        t += _GAPS[int(rng.integers(len(_GAPS)))]
        dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
        if t + dur > t1:
            return out
        c = chest_dir(t + dur)
        if c is None:
            t += dur
            continue
        ok = [x for x in HEAD_TARGETS if x != last and canonical_vector(x[0], x[1]) @ c >= np.cos(np.radians(40))]
        if not ok:
            t += dur
            continue
        d, lv, _ = ok[int(rng.integers(len(ok)))]
        last = (d, lv, 0)
        out.append(Symbol(t, dur, "head", d, lv))
        t += dur


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


def _legs_track(rng, n_beats):
    """Supports and leg gestures: weight transfers, free-leg gestures, steps."""
    out, t, end = [], Fraction(0), Fraction(n_beats)
    while True:
        kind = ("both", "single", "step")[int(rng.choice(3, p=(0.35, 0.45, 0.2)))]
        dur = _DURATIONS[int(rng.integers(len(_DURATIONS)))]
        if kind == "both":
            if t + dur > end:
                return out
            out.append(Symbol(t, dur, "support", "place", ("low", "middle", "high")[int(rng.integers(3))]))
            t += dur
        elif kind == "step":
            foot = ("right", "left")[int(rng.integers(2))]
            d = ("forward", "back", foot)[int(rng.integers(3))]
            if t + dur > end:
                return out
            out.append(Symbol(t, dur, f"{foot}_support", d, "middle"))
            t += dur
        else:
            foot = ("right", "left")[int(rng.integers(2))]
            free = "left" if foot == "right" else "right"
            close = Fraction(1)
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
            out.append(Symbol(t, dur, f"{foot}_support", "place", level))
            out += gestures
            out.append(Symbol(g_t, close, "support", "place", "middle"))
            t = g_t + close


def random_score(
    rng: np.random.Generator,
    n_beats: int = 8,
    parts=DEFAULT_PARTS,
    split_arms: bool = False,
    tempo=None,
    random_effort: bool = False,
    max_tries: int = 50,
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
    for _ in range(int(max_tries)):
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
                syms += _legs_track(rng, n_beats)
            elif p in ("right_arm", "left_arm") and split_arms:
                syms += _split_arm_track(rng, p.split("_")[0], 0, n_beats, chest)
            elif p in ("right_arm", "left_arm"):
                syms += _gesture_track(rng, p, ARM_TARGETS, 0, n_beats, chest=chest)
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
        score = Score(tuple(syms), title="random", tempo=bpm, meter=4, effort=effort)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UnreachableWarning)
            interpret(score, fps=8.0)
        if not any(issubclass(w.category, UnreachableWarning) for w in caught):
            return score
    raise SyntheticError(f"no reachable random score in {max_tries} draws (n_beats={n_beats}, parts={parts})")
