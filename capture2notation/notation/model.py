"""The notation object model: small frozen dataclasses with value equality.

Time is in beats as exact :class:`fractions.Fraction`; ``seconds = beats ×
60 / tempo``.  Vocabulary and meanings are those of ``../shared/DESIGN.md``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from fractions import Fraction
from types import MappingProxyType

from ..errors import NotationError
from .effort import EMOTIONS, PRESETS, Effort
from .limits import (
    MAX_BEATS,
    MAX_METER,
    MAX_NUMBER_CHARS,
    MAX_SCORE_SECONDS,
    MAX_SYMBOLS,
    MAX_TEMPO,
    MAX_TITLE_CHARS,
    MAX_TURN,
    MIN_TEMPO,
)

__all__ = [
    "AIR",
    "AXES",
    "BENDABLE_PARTS",
    "DIRECTIONS",
    "EMOTIONS",
    "GESTURE_PARTS",
    "LEVELS",
    "PARTS",
    "PART_MIDDLE_JOINT",
    "PART_SEGMENTS",
    "SUPPORT_PARTS",
    "SYMBOL_UNCERTAIN_BELOW",
    "TURN_DIRECTIONS",
    "TURN_PART",
    "TURN_STEP",
    "Effort",
    "Score",
    "Symbol",
    "as_fraction",
    "parse_number",
]

#: Gesture parts and the segment (bound joint, free joint) whose direction
#: they notate.
PART_SEGMENTS: MappingProxyType = MappingProxyType(
    {
        "right_arm": ("right_shoulder", "right_wrist"),
        "left_arm": ("left_shoulder", "left_wrist"),
        "right_upper_arm": ("right_shoulder", "right_elbow"),
        "right_forearm": ("right_elbow", "right_wrist"),
        "left_upper_arm": ("left_shoulder", "left_elbow"),
        "left_forearm": ("left_elbow", "left_wrist"),
        "right_leg": ("right_hip", "right_ankle"),
        "left_leg": ("left_hip", "left_ankle"),
        "right_thigh": ("right_hip", "right_knee"),
        "right_shin": ("right_knee", "right_ankle"),
        "left_thigh": ("left_hip", "left_knee"),
        "left_shin": ("left_knee", "left_ankle"),
        "head": ("neck", "head"),
        "chest": ("waist", "neck"),
    }
)
#: Whole limbs whose middle joint's bend a symbol can carry.
PART_MIDDLE_JOINT: MappingProxyType = MappingProxyType(
    {
        "right_arm": "right_elbow",
        "left_arm": "left_elbow",
        "right_leg": "right_knee",
        "left_leg": "left_knee",
    }
)
GESTURE_PARTS: tuple[str, ...] = tuple(PART_SEGMENTS)
SUPPORT_PARTS: tuple[str, ...] = ("support", "right_support", "left_support")
#: The turn column: a change of front of the whole body (DESIGN.md, "Facing
#: and turns"), drawn in the support column.
TURN_PART = "turn"
PARTS: tuple[str, ...] = GESTURE_PARTS + SUPPORT_PARTS + (TURN_PART,)
#: Turn directions: ``right`` clockwise seen from above, ``left`` counter-clockwise.
TURN_DIRECTIONS: tuple[str, ...] = ("right", "left")
#: Turn amounts are whole multiples of this many full turns (an eighth).
TURN_STEP = Fraction(1, 8)
#: The ``support`` direction with no foot on the floor (flight); it has no level.
AIR = "air"
#: Crosses of axes a score may be keyed to (DESIGN.md, "Cross of axes").
AXES: tuple[str, ...] = ("standard", "body")
BENDABLE_PARTS: frozenset = frozenset(PART_MIDDLE_JOINT)

#: Directions with their azimuth in degrees clockwise from forward
#: (``place`` has none).
DIRECTIONS: MappingProxyType = MappingProxyType(
    {
        "forward": 0.0,
        "right_forward": 45.0,
        "right": 90.0,
        "right_back": 135.0,
        "back": 180.0,
        "left_back": -135.0,
        "left": -90.0,
        "left_forward": -45.0,
        "place": None,
    }
)
LEVELS: tuple[str, ...] = ("high", "middle", "low")
MAX_BEND = 6
#: A symbol whose confidence is below this is uncertain: drawn grey and
#: hatched on the staff and listed as such (a coin toss between readings).
SYMBOL_UNCERTAIN_BELOW = 0.5


def as_fraction(value, what: str = "value") -> Fraction:
    """Exact fraction from an int, Fraction, or string such as ``'3/2'`` or ``'.5'``.

    Floats are accepted only when they are exactly representable in a
    limited denominator (e.g. 0.5, 0.25), never approximated silently.
    """
    if isinstance(value, Fraction):
        return value
    if isinstance(value, bool):
        raise NotationError(f"{what} must be a number, got {value!r}")
    if isinstance(value, int):
        return Fraction(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise NotationError(f"{what} {value!r} must be a finite number")
        f = Fraction(value).limit_denominator(10**6)
        if float(f) != value:
            raise NotationError(f"{what} {value!r} is not an exact fraction; give it as 'p/q'")
        return f
    if isinstance(value, str):
        return parse_number(value, what)
    raise NotationError(f"{what} must be a number or fraction, got {type(value).__name__}")


_NUMBER_RE = re.compile(r"[+-]?(?:[0-9]+/[0-9]+|[0-9]+\.?[0-9]*|\.[0-9]+)")


def parse_number(token: str, what: str = "value") -> Fraction:
    """Exact fraction from ``'3/2'``, ``'.50'``, ``'1.5'`` or ``'2'`` (surrounding blanks allowed).

    Exponents (``1e9``) and digit separators are refused: ``Fraction('1e100000000')``
    would build a hundred-million-digit integer.  Tokens longer than
    :data:`~capture2notation.notation.limits.MAX_NUMBER_CHARS` are refused
    for the same reason.

    Raises
    ------
    NotationError
        Naming `what`, the bad token and the expected forms.
    """
    token = token.strip()
    if len(token) > MAX_NUMBER_CHARS:
        raise NotationError(f"{what} {token[:20]!r}… is longer than {MAX_NUMBER_CHARS} characters")
    if not _NUMBER_RE.fullmatch(token):
        raise NotationError(f"{what} {token!r} is not a number; expected an exact beat count such as 2, 1/2 or .5")
    try:
        return Fraction(token)
    except ZeroDivisionError:
        raise NotationError(f"{what} {token!r} divides by zero") from None


def _check_beats(value: Fraction, what: str) -> None:
    if value > MAX_BEATS:
        raise NotationError(f"{what} {_short(value)} beats exceeds the limit of {MAX_BEATS} beats")


def _short(value: Fraction) -> str:
    text = str(value)
    return text if len(text) <= 24 else f"{float(value):.6g}"


@dataclass(frozen=True, order=False)
class Symbol:
    """One notation symbol: a part moves to (direction, level) over a span of beats.

    Three kinds share this one value type (DESIGN.md, "The score text format"):

    * a **gesture** or **support**: `part` moves to `direction` at `level`
      (a support with a direction other than ``place`` is a step of a normal
      length that way, relative to the current front);
    * a **turn** (``part="turn"``): the whole body turns `direction`
      (``right`` clockwise seen from above, ``left`` counter-clockwise) by
      `amount` full turns, a multiple of :data:`TURN_STEP`, over the span;
      it has no level;
    * **flight** (``part="support"``, ``direction="air"``): no foot bears
      weight over the span; it has no level.  Its spring form follows from
      the supports before and after (:func:`~capture2notation.notation.facing.spring_form`).

    Parameters
    ----------
    start : Fraction
        Beat at which the movement begins (0 … :data:`~.limits.MAX_BEATS`).
    duration : Fraction
        Beats until it arrives (> 0, at most :data:`~.limits.MAX_BEATS`).
    part : str
        One of :data:`PARTS`.
    direction : str
        One of :data:`DIRECTIONS`; :data:`TURN_DIRECTIONS` for a turn;
        :data:`AIR` for flight.
    level : str or None
        One of :data:`LEVELS`; None exactly for turns and flight.
    bend : int
        Bend degree 0–6 of the middle joint (elbow/knee), only for whole
        arms and legs; 0 is straight.
    amount : Fraction or None
        Full turns of a turn symbol (a positive multiple of 1/8, at most
        :data:`~.limits.MAX_TURN`); None for every other symbol.
    confidence : float or None
        How sure a capture is of this symbol, in [0, 1] (keypoint visibility
        and left/right identity, the fit's confidence, the angle's distance
        from a sector or level boundary); None for written scores (not
        assessed).  Metadata: symbols equal in everything else are equal.
    """

    start: Fraction
    duration: Fraction
    part: str
    direction: str
    level: str | None
    bend: int = 0
    amount: Fraction | None = None
    confidence: float | None = field(default=None, compare=False)

    def __post_init__(self):
        self._check_confidence()
        object.__setattr__(self, "start", as_fraction(self.start, "start"))
        object.__setattr__(self, "duration", as_fraction(self.duration, "duration"))
        if self.start < 0:
            raise NotationError(f"start {self.start} must be >= 0 beats")
        if self.duration <= 0:
            raise NotationError(f"duration {self.duration} must be > 0 beats")
        _check_beats(self.start, "start")
        _check_beats(self.duration, "duration")
        if self.part not in PARTS:
            raise NotationError(f"unknown part {self.part!r}; expected one of {' '.join(PARTS)}")
        if isinstance(self.bend, bool) or not isinstance(self.bend, int) or not 0 <= self.bend <= MAX_BEND:
            raise NotationError(f"bend {self.bend!r} must be an integer 0-{MAX_BEND}")
        if self.part == TURN_PART:
            self._check_turn()
            return
        if self.amount is not None:
            raise NotationError(f"amount={self.amount} belongs to turn symbols only, not {self.part}")
        if self.part == "support" and self.direction == AIR:
            if self.level is not None:
                raise NotationError(f"support air has no level, got {self.level!r}")
            if self.bend:
                raise NotationError(f"bend={self.bend} is not allowed on support air")
            return
        if self.direction not in DIRECTIONS:
            extra = f" ({AIR} on support only)" if self.direction == AIR else ""
            raise NotationError(f"unknown direction {self.direction!r}{extra}; expected one of {' '.join(DIRECTIONS)}")
        if self.level not in LEVELS:
            raise NotationError(f"unknown level {self.level!r}; expected one of {' '.join(LEVELS)}")
        if self.part in GESTURE_PARTS and self.direction == "place" and self.level == "middle":
            raise NotationError(
                f"{self.part}: 'place middle' has no direction for a gesture; use place high, place low or a direction"
            )
        if self.bend and self.part not in BENDABLE_PARTS:
            raise NotationError(
                f"bend={self.bend} is only allowed on {', '.join(sorted(BENDABLE_PARTS))}, not {self.part}"
            )

    def _check_confidence(self) -> None:
        c = self.confidence
        if c is None:
            return
        if isinstance(c, bool) or not isinstance(c, (int, float)) or not (0.0 <= float(c) <= 1.0):
            raise NotationError(f"confidence {c!r} must be a number in [0, 1] (or absent)")
        object.__setattr__(self, "confidence", float(c))

    @property
    def uncertain(self) -> bool:
        """The capture was not sure of this symbol (:data:`SYMBOL_UNCERTAIN_BELOW`)."""
        return self.confidence is not None and self.confidence < SYMBOL_UNCERTAIN_BELOW

    def _check_turn(self) -> None:
        if self.direction not in TURN_DIRECTIONS:
            raise NotationError(f"unknown turn direction {self.direction!r}; expected right or left")
        if self.level is not None:
            raise NotationError(f"a turn has no level, got {self.level!r}")
        if self.bend:
            raise NotationError(f"bend={self.bend} is not allowed on a turn")
        if self.amount is None:
            raise NotationError("a turn needs amount=F (full turns, a multiple of 1/8)")
        amount = as_fraction(self.amount, "amount")
        object.__setattr__(self, "amount", amount)
        if amount <= 0 or amount > MAX_TURN or (amount / TURN_STEP).denominator != 1:
            raise NotationError(
                f"amount {_short(amount)} must be a positive multiple of 1/8 of a turn, at most {MAX_TURN}"
            )

    @property
    def end(self) -> Fraction:
        """Beat at which the movement arrives."""
        return self.start + self.duration

    @property
    def is_support(self) -> bool:
        """A support symbol (flight included)."""
        return self.part in SUPPORT_PARTS

    @property
    def is_turn(self) -> bool:
        return self.part == TURN_PART

    @property
    def is_air(self) -> bool:
        """Flight: ``support air``."""
        return self.part == "support" and self.direction == AIR

    @property
    def signed_amount(self) -> Fraction:
        """Full turns clockwise (a left turn is negative); 0 for other symbols."""
        if self.amount is None:
            return Fraction(0)
        return self.amount if self.direction == "right" else -self.amount

    def sort_key(self):
        return (self.start, PARTS.index(self.part), self.duration)


@dataclass(frozen=True)
class Score:
    """A phrase of notation.

    Parameters
    ----------
    symbols : tuple of Symbol
        Kept sorted by (start, part order, duration); at most
        :data:`~.limits.MAX_SYMBOLS`.
    title : str
        One line, at most :data:`~.limits.MAX_TITLE_CHARS` characters.
    tempo : Fraction
        Beats per minute, within [:data:`~.limits.MIN_TEMPO`, :data:`~.limits.MAX_TEMPO`].
    meter : int
        Beats per measure (1 … :data:`~.limits.MAX_METER`).
    effort : Effort or None
        Explicit Effort; exclusive with `emotion`.
    emotion : str or None
        One of :data:`EMOTIONS`; its preset Effort applies (DESIGN.md table).
    axes : str
        The cross of axes directions are read in: ``"standard"`` (default)
        or ``"body"`` (DESIGN.md, "Cross of axes").

    Raises
    ------
    NotationError
        Out-of-range values, overlapping symbols of one part, or flight that
        overlaps a support symbol.  A score at most
        :data:`~.limits.MAX_SCORE_SECONDS` long at its tempo.
    """

    symbols: tuple = field(default_factory=tuple)
    title: str = ""
    tempo: Fraction = Fraction(60)
    meter: int = 4
    effort: Effort | None = None
    emotion: str | None = None
    axes: str = "standard"

    def __post_init__(self):
        syms = tuple(self.symbols)
        if len(syms) > MAX_SYMBOLS:
            raise NotationError(f"{len(syms)} symbols exceed the limit of {MAX_SYMBOLS} in one score")
        for s in syms:
            if not isinstance(s, Symbol):
                raise NotationError(f"score symbols must be Symbol objects, got {type(s).__name__}")
        object.__setattr__(self, "symbols", tuple(sorted(syms, key=Symbol.sort_key)))
        object.__setattr__(self, "tempo", as_fraction(self.tempo, "tempo"))
        if not MIN_TEMPO <= self.tempo <= MAX_TEMPO:
            raise NotationError(
                f"tempo {_short(self.tempo)} is outside {MIN_TEMPO}-{MAX_TEMPO} beats per minute"
                + (" (it must be > 0)" if self.tempo <= 0 else "")
            )
        if isinstance(self.meter, bool) or not isinstance(self.meter, int) or not 0 < self.meter <= MAX_METER:
            raise NotationError(f"meter {self.meter!r} must be a positive integer of at most {MAX_METER} beats")
        if not isinstance(self.title, str):
            raise NotationError(f"title must be a string, got {type(self.title).__name__}")
        if "\n" in self.title:
            raise NotationError("title must be a single line")
        if len(self.title) > MAX_TITLE_CHARS:
            raise NotationError(f"title of {len(self.title)} characters exceeds the limit of {MAX_TITLE_CHARS}")
        if self.effort is not None and self.emotion is not None:
            raise NotationError("a score carries either an effort or an emotion, not both")
        if self.emotion is not None and self.emotion not in EMOTIONS:
            raise NotationError(f"unknown emotion {self.emotion!r}; expected one of {' '.join(EMOTIONS)}")
        if self.axes not in AXES:
            raise NotationError(f"unknown axes {self.axes!r}; expected one of {' '.join(AXES)}")
        seconds = self.duration * 60 / self.tempo
        if seconds > MAX_SCORE_SECONDS:
            raise NotationError(
                f"the score lasts {float(seconds):.6g} s at {_short(self.tempo)} bpm, "
                f"more than the limit of {MAX_SCORE_SECONDS} s"
            )
        self._check_overlaps()

    def _check_overlaps(self):
        last_end: dict[str, Fraction] = {}
        for s in self.symbols:
            prev = last_end.get(s.part)
            if prev is not None and s.start < prev:
                raise NotationError(
                    f"{s.part}: symbol at beat {s.start} starts before the previous one ends at beat {prev}"
                )
            last_end[s.part] = s.end
        airs = [s for s in self.symbols if s.is_air]
        if airs:
            # Flight bears no weight: no support of either foot may overlap it
            # (a sweep over both kinds in start order, not every pair).
            sups = [s for s in self.symbols if s.part in ("right_support", "left_support")]
            events = sorted([(s.start, 0, s) for s in sups] + [(a.start, 1, a) for a in airs], key=lambda e: e[:2])
            last: dict[int, Symbol] = {}
            for _, kind, s in events:
                other = last.get(1 - kind)
                if other is not None and other.end > s.start:
                    foot, air = (s, other) if kind == 0 else (other, s)
                    raise NotationError(
                        f"{foot.part} at beat {foot.start}-{foot.end} overlaps support air at beat "
                        f"{air.start}-{air.end}; no foot bears weight in flight"
                    )
                if kind not in last or s.end > last[kind].end:
                    last[kind] = s

    @property
    def duration(self) -> Fraction:
        """Beats until the last symbol arrives (0 for an empty score)."""
        return max((s.end for s in self.symbols), default=Fraction(0))

    def seconds(self, beats) -> float:
        """Convert beats to seconds at this score's tempo."""
        return float(as_fraction(beats, "beats") * 60 / self.tempo)

    def for_part(self, part: str) -> tuple:
        """The symbols of one part, in time order."""
        if part not in PARTS:
            raise NotationError(f"unknown part {part!r}")
        return tuple(s for s in self.symbols if s.part == part)

    def resolved_effort(self) -> Effort:
        """The Effort that applies: explicit, else the emotion preset, else neutral."""
        if self.effort is not None:
            return self.effort
        if self.emotion is not None:
            return PRESETS[self.emotion].effort
        return Effort()

    def with_emotion(self, emotion: str) -> Score:
        """This score performed with an emotion preset: its Effort *and* tempo."""
        if emotion not in PRESETS:
            raise NotationError(f"unknown emotion {emotion!r}; expected one of {' '.join(EMOTIONS)}")
        return replace(self, emotion=emotion, effort=None, tempo=PRESETS[emotion].tempo)

    def replace(self, **changes) -> Score:
        return replace(self, **changes)

    @classmethod
    def from_symbols(cls, symbols: Iterable[Symbol], **kw) -> Score:
        return cls(symbols=tuple(symbols), **kw)
