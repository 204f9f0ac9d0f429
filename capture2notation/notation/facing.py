"""Facing, turns and flight as a score implies them (DESIGN.md, "Facing and turns").

Pure functions of a :class:`~capture2notation.notation.model.Score`, shared
by the score formats (the JSON ``spring`` field, LabanEditor's
``rotation``), the staff (front signs, spring forms) and the virtual dancer.

* The **front** is counted in full turns clockwise from the starting front
  (unwrapped: two right pirouettes end at +2); a turn symbol adds its signed
  amount over its span.
* The **room direction** of a front is its eighth of a turn modulo one turn,
  named like limb directions (``forward`` = the starting front, ``right``
  a quarter turn clockwise …).
* The **spring form** of a flight (``support air``) follows from the feet on
  the floor before it and the feet its landing names: jump 2→2, hop 1→same
  foot, leap 1→other, assemblé 1→2, sissonne 2→1.

Feet on the floor before a flight are those named by the latest support
symbols ending at or before its start (both feet when there is none: the
start pose), less a foot whose leg gestures after them (a gesture lifts the
foot).  The landing is every support symbol starting where the flight ends;
without one the form is undefined (None), e.g. a clip that ends in the air.
"""

from __future__ import annotations

from fractions import Fraction

from .model import SUPPORT_PARTS, TURN_STEP, Score, Symbol

__all__ = [
    "FOOT_OF_SUPPORT",
    "ROOM_DIRECTIONS",
    "SPRING_FORMS",
    "feet_before",
    "feet_landing",
    "front_at",
    "front_changes",
    "room_direction",
    "spring_form",
    "springs",
]

#: Feet named by each support part.
FOOT_OF_SUPPORT = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}
#: The five spring forms, in the order of DESIGN.md.
SPRING_FORMS: tuple[str, ...] = ("jump", "hop", "leap", "assemblé", "sissonne")
#: Room directions by eighths of a turn clockwise from the starting front.
ROOM_DIRECTIONS: tuple[str, ...] = (
    "forward",
    "right_forward",
    "right",
    "right_back",
    "back",
    "left_back",
    "left",
    "left_forward",
)
_LEG_PARTS = {foot: (f"{foot}_leg", f"{foot}_thigh", f"{foot}_shin") for foot in ("right", "left")}


def front_at(score: Score, beat) -> Fraction:
    """Front at `beat`, full turns clockwise from the start (turns in progress count in part).

    A turn in progress is counted linearly over its span; notation does not
    say how a turn is eased, so only the fronts between turns are exact.
    """
    beat = Fraction(beat)
    total = Fraction(0)
    for s in score.symbols:
        if not s.is_turn or s.start >= beat:
            continue
        part = min(Fraction(1), (beat - s.start) / s.duration)
        total += part * s.signed_amount
    return total


def front_changes(score: Score) -> list[tuple[Symbol, Fraction]]:
    """Each turn symbol with the front (full turns clockwise, unwrapped) once it has ended.

    Returns
    -------
    list of (Symbol, Fraction)
        In score order.  Overlapping turns (not a notation one writes) add up.
    """
    turns = [s for s in score.symbols if s.is_turn]
    out = []
    for t in turns:
        front = sum((u.signed_amount for u in turns if u.end <= t.end), Fraction(0))
        out.append((t, front))
    return out


def room_direction(front) -> str:
    """Room direction faced at `front` (full turns clockwise), to the nearest eighth."""
    eighths = round(Fraction(front) / TURN_STEP)
    return ROOM_DIRECTIONS[eighths % 8]


def feet_before(score: Score, beat) -> frozenset:
    """Feet on the floor just before `beat` (see the module docstring)."""
    beat = Fraction(beat)
    prior = [s for s in score.symbols if s.is_support and not s.is_air and s.end <= beat]
    if prior:
        t_ref = max(s.end for s in prior)
        named = {f for s in prior if s.end == t_ref for f in FOOT_OF_SUPPORT[s.part]}
    else:
        t_ref, named = Fraction(0), {"right", "left"}
    lifted = {
        foot
        for foot, legs in _LEG_PARTS.items()
        for s in score.symbols
        if s.part in legs and s.start < beat and s.end > t_ref
    }
    return frozenset(named - lifted)


def feet_landing(score: Score, air: Symbol) -> frozenset:
    """Feet named by the support symbols that start where flight `air` ends."""
    return frozenset(
        f
        for s in score.symbols
        if s.part in SUPPORT_PARTS and not s.is_air and s.start == air.end
        for f in FOOT_OF_SUPPORT[s.part]
    )


def spring_form(score: Score, air: Symbol) -> str | None:
    """The spring form of flight `air` in `score`, or None when it has no landing.

    Returns
    -------
    str or None
        One of :data:`SPRING_FORMS`; None without a landing or with no foot on
        the floor before (flight straight after flight).
    """
    before, after = feet_before(score, air.start), feet_landing(score, air)
    if not before or not after:
        return None
    if len(before) == 2:
        return "jump" if len(after) == 2 else "sissonne"
    if len(after) == 2:
        return "assemblé"
    return "hop" if before == after else "leap"


def springs(score: Score) -> list[tuple[Symbol, str | None]]:
    """Every flight of `score` with its spring form, in score order."""
    return [(s, spring_form(score, s)) for s in score.symbols if s.is_air]
