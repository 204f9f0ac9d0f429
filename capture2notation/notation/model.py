"""The notation object model: small frozen dataclasses with value equality.

Time is in beats as exact :class:`fractions.Fraction`; ``seconds = beats ×
60 / tempo``.  Vocabulary and meanings are those of ``../shared/DESIGN.md``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from fractions import Fraction
from types import MappingProxyType

from ..errors import NotationError
from .effort import EMOTIONS, PRESETS, Effort

__all__ = [
    "BENDABLE_PARTS",
    "DIRECTIONS",
    "EMOTIONS",
    "GESTURE_PARTS",
    "LEVELS",
    "PARTS",
    "PART_MIDDLE_JOINT",
    "PART_SEGMENTS",
    "SUPPORT_PARTS",
    "Effort",
    "Score",
    "Symbol",
    "as_fraction",
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
PARTS: tuple[str, ...] = GESTURE_PARTS + SUPPORT_PARTS
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
        f = Fraction(value).limit_denominator(10**6)
        if float(f) != value:
            raise NotationError(f"{what} {value!r} is not an exact fraction; give it as 'p/q'")
        return f
    if isinstance(value, str):
        try:
            return Fraction(value.strip())
        except (ValueError, ZeroDivisionError):
            raise NotationError(f"{what} {value!r} is not a number or fraction like 3/2") from None
    raise NotationError(f"{what} must be a number or fraction, got {type(value).__name__}")


@dataclass(frozen=True, order=False)
class Symbol:
    """One notation symbol: a part moves to (direction, level) over a span of beats.

    Parameters
    ----------
    start : Fraction
        Beat at which the movement begins (>= 0).
    duration : Fraction
        Beats until it arrives (> 0).
    part : str
        One of :data:`PARTS`.
    direction : str
        One of :data:`DIRECTIONS`.
    level : str
        One of :data:`LEVELS`.
    bend : int
        Bend degree 0–6 of the middle joint (elbow/knee), only for whole
        arms and legs; 0 is straight.
    """

    start: Fraction
    duration: Fraction
    part: str
    direction: str
    level: str
    bend: int = 0

    def __post_init__(self):
        object.__setattr__(self, "start", as_fraction(self.start, "start"))
        object.__setattr__(self, "duration", as_fraction(self.duration, "duration"))
        if self.start < 0:
            raise NotationError(f"start {self.start} must be >= 0 beats")
        if self.duration <= 0:
            raise NotationError(f"duration {self.duration} must be > 0 beats")
        if self.part not in PARTS:
            raise NotationError(f"unknown part {self.part!r}; expected one of {' '.join(PARTS)}")
        if self.direction not in DIRECTIONS:
            raise NotationError(f"unknown direction {self.direction!r}; expected one of {' '.join(DIRECTIONS)}")
        if self.level not in LEVELS:
            raise NotationError(f"unknown level {self.level!r}; expected one of {' '.join(LEVELS)}")
        if self.part in GESTURE_PARTS and self.direction == "place" and self.level == "middle":
            raise NotationError(
                f"{self.part}: 'place middle' has no direction for a gesture; use place high, place low or a direction"
            )
        if isinstance(self.bend, bool) or not isinstance(self.bend, int) or not 0 <= self.bend <= MAX_BEND:
            raise NotationError(f"bend {self.bend!r} must be an integer 0-{MAX_BEND}")
        if self.bend and self.part not in BENDABLE_PARTS:
            raise NotationError(
                f"bend={self.bend} is only allowed on {', '.join(sorted(BENDABLE_PARTS))}, not {self.part}"
            )

    @property
    def end(self) -> Fraction:
        """Beat at which the movement arrives."""
        return self.start + self.duration

    @property
    def is_support(self) -> bool:
        return self.part in SUPPORT_PARTS

    def sort_key(self):
        return (self.start, PARTS.index(self.part), self.duration)


@dataclass(frozen=True)
class Score:
    """A phrase of notation.

    Parameters
    ----------
    symbols : tuple of Symbol
        Kept sorted by (start, part order, duration).
    title : str
    tempo : Fraction
        Beats per minute (> 0).
    meter : int
        Beats per measure (> 0).
    effort : Effort or None
        Explicit Effort; exclusive with `emotion`.
    emotion : str or None
        One of :data:`EMOTIONS`; its preset Effort applies (DESIGN.md table).
    """

    symbols: tuple = field(default_factory=tuple)
    title: str = ""
    tempo: Fraction = Fraction(60)
    meter: int = 4
    effort: Effort | None = None
    emotion: str | None = None

    def __post_init__(self):
        syms = tuple(self.symbols)
        for s in syms:
            if not isinstance(s, Symbol):
                raise NotationError(f"score symbols must be Symbol objects, got {type(s).__name__}")
        object.__setattr__(self, "symbols", tuple(sorted(syms, key=Symbol.sort_key)))
        object.__setattr__(self, "tempo", as_fraction(self.tempo, "tempo"))
        if self.tempo <= 0:
            raise NotationError(f"tempo {self.tempo} must be > 0 beats per minute")
        if isinstance(self.meter, bool) or not isinstance(self.meter, int) or self.meter <= 0:
            raise NotationError(f"meter {self.meter!r} must be a positive integer")
        if "\n" in self.title:
            raise NotationError("title must be a single line")
        if self.effort is not None and self.emotion is not None:
            raise NotationError("a score carries either an effort or an emotion, not both")
        if self.emotion is not None and self.emotion not in EMOTIONS:
            raise NotationError(f"unknown emotion {self.emotion!r}; expected one of {' '.join(EMOTIONS)}")
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
