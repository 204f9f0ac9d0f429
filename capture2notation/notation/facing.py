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

import bisect
import itertools
from fractions import Fraction

from .model import TURN_STEP, Score, Symbol

__all__ = [
    "FOOT_OF_SUPPORT",
    "ROOM_DIRECTIONS",
    "SPRING_FORMS",
    "Intervals",
    "SupportIndex",
    "feet_before",
    "feet_landing",
    "front_at",
    "front_changes",
    "front_lookup",
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


class Intervals:
    """Spans of beats, asked whether any overlaps a given span (in O(log n)).

    Parameters
    ----------
    spans : iterable of (start, end)
        Any order; spans may overlap one another.
    """

    def __init__(self, spans):
        spans = sorted(spans)
        self.starts = [a for a, _ in spans]
        self.max_end = list(itertools.accumulate((b for _, b in spans), max))

    def overlaps(self, start, end) -> bool:
        """Whether a span with ``s < end`` and ``e > start`` exists."""
        k = bisect.bisect_left(self.starts, end)
        return k > 0 and self.max_end[k - 1] > start


def _turns(score: Score) -> tuple[list[Symbol], list[Fraction]]:
    """Turns in time order with the front once each has ended (turns never overlap)."""
    turns = [s for s in score.symbols if s.is_turn]
    return turns, list(itertools.accumulate((t.signed_amount for t in turns), initial=Fraction(0)))[1:]


def front_at(score: Score, beat) -> Fraction:
    """Front at `beat`, full turns clockwise from the start (turns in progress count in part).

    A turn in progress is counted linearly over its span; notation does not
    say how a turn is eased, so only the fronts between turns are exact.
    """
    return front_lookup(score)(beat)


def front_lookup(score: Score):
    """``beat -> front`` for many beats of one score (sorted turns, bisection)."""
    turns, fronts = _turns(score)
    starts = [t.start for t in turns]

    def at(beat) -> Fraction:
        beat = Fraction(beat)
        k = bisect.bisect_left(starts, beat)  # turns starting before `beat`
        if k == 0:
            return Fraction(0)
        t, before = turns[k - 1], fronts[k - 2] if k >= 2 else Fraction(0)
        part = min(Fraction(1), (beat - t.start) / t.duration)
        return before + part * t.signed_amount

    return at


def front_changes(score: Score) -> list[tuple[Symbol, Fraction]]:
    """Each turn symbol with the front (full turns clockwise, unwrapped) once it has ended.

    Returns
    -------
    list of (Symbol, Fraction)
        In score order.
    """
    turns, fronts = _turns(score)
    return list(zip(turns, fronts))


def room_direction(front) -> str:
    """Room direction faced at `front` (full turns clockwise), to the nearest eighth."""
    eighths = round(Fraction(front) / TURN_STEP)
    return ROOM_DIRECTIONS[eighths % 8]


class SupportIndex:
    """The supports and leg gestures of a score, indexed once for many queries.

    :meth:`before` is :func:`feet_before`, :meth:`landing` the feet a
    landing at a beat names, :meth:`form` :func:`spring_form` — each in
    O(log n) after an O(n log n) build.
    """

    def __init__(self, score: Score):
        sups = sorted((s for s in score.symbols if s.is_support and not s.is_air), key=lambda s: s.end)
        self.ends = [s.end for s in sups]
        self.named: dict[Fraction, set] = {}
        self.starting: dict[Fraction, set] = {}
        for s in sups:
            self.named.setdefault(s.end, set()).update(FOOT_OF_SUPPORT[s.part])
            self.starting.setdefault(s.start, set()).update(FOOT_OF_SUPPORT[s.part])
        self.legs = {
            foot: Intervals((s.start, s.end) for s in score.symbols if s.part in parts)
            for foot, parts in _LEG_PARTS.items()
        }

    def before(self, beat) -> frozenset:
        beat = Fraction(beat)
        k = bisect.bisect_right(self.ends, beat)
        if k:
            t_ref = self.ends[k - 1]
            named = self.named[t_ref]
        else:
            t_ref, named = Fraction(0), {"right", "left"}
        # A leg gesture begun before `beat` and still going after the support lifts its foot.
        lifted = {foot for foot, legs in self.legs.items() if legs.overlaps(t_ref, beat)}
        return frozenset(named - lifted)

    def landing(self, beat) -> frozenset:
        return frozenset(self.starting.get(Fraction(beat), ()))

    def form(self, air: Symbol) -> str | None:
        before, after = self.before(air.start), self.landing(air.end)
        if not before or not after:
            return None
        if len(before) == 2:
            return "jump" if len(after) == 2 else "sissonne"
        if len(after) == 2:
            return "assemblé"
        return "hop" if before == after else "leap"


def feet_before(score: Score, beat) -> frozenset:
    """Feet on the floor just before `beat` (see the module docstring)."""
    return SupportIndex(score).before(beat)


def feet_landing(score: Score, air: Symbol) -> frozenset:
    """Feet named by the support symbols that start where flight `air` ends."""
    return SupportIndex(score).landing(air.end)


def spring_form(score: Score, air: Symbol) -> str | None:
    """The spring form of flight `air` in `score`, or None when it has no landing.

    Returns
    -------
    str or None
        One of :data:`SPRING_FORMS`; None without a landing or with no foot on
        the floor before (flight straight after flight).  For every flight of
        a score at once, :func:`springs` indexes the score only once.
    """
    return SupportIndex(score).form(air)


def springs(score: Score) -> list[tuple[Symbol, str | None]]:
    """Every flight of `score` with its spring form, in score order."""
    index = SupportIndex(score)
    return [(s, index.form(s)) for s in score.symbols if s.is_air]
