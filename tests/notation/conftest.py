"""Hypothesis strategy for random valid scores, shared by the notation tests.

Registered for :class:`Score`, so a test asks for ``st.from_type(Score)``
(no cross-module test imports, whatever pytest's import mode).
"""

from __future__ import annotations

from fractions import Fraction

from hypothesis import strategies as st

from capture2notation.notation import DIRECTIONS, EMOTIONS, GESTURE_PARTS, LEVELS, PARTS, Effort, Score, Symbol
from capture2notation.notation.model import AXES, BENDABLE_PARTS, TURN_PART

beats = st.fractions(min_value=0, max_value=16, max_denominator=12)
durations = st.fractions(min_value=Fraction(1, 12), max_value=8, max_denominator=12)


@st.composite
def symbol_fields(draw, part):
    direction = draw(st.sampled_from(list(DIRECTIONS)))
    levels = [lv for lv in LEVELS if not (part in GESTURE_PARTS and direction == "place" and lv == "middle")]
    level = draw(st.sampled_from(levels))
    bend = draw(st.integers(0, 6)) if part in BENDABLE_PARTS else 0
    return direction, level, bend


@st.composite
def scores(draw, max_symbols: int = 12):
    """Random valid scores: per part, non-overlapping symbols at fraction times."""
    n = draw(st.integers(0, max_symbols))
    next_free: dict[str, Fraction] = {}
    symbols = []
    for _ in range(n):
        part = draw(st.sampled_from(PARTS))
        start = next_free.get(part, Fraction(0)) + draw(beats)
        duration = draw(durations)
        if part == TURN_PART:
            direction = draw(st.sampled_from(["right", "left"]))
            amount = Fraction(draw(st.integers(1, 24)), 8)
            symbols.append(Symbol(start, duration, part, direction, None, amount=amount))
        elif part == "support" and draw(st.integers(0, 3)) == 0:
            # Flight: no foot support may overlap it, so it starts after them all.
            start = max([start] + [v for k, v in next_free.items() if k.endswith("support")])
            symbols.append(Symbol(start, duration, part, "air", None))
            for k in ("right_support", "left_support"):
                next_free[k] = max(next_free.get(k, Fraction(0)), start + duration)
        else:
            direction, level, bend = draw(symbol_fields(part))
            if part.endswith("_support"):
                # ... and no foot support may overlap an earlier flight.
                start = max(start, next_free.get("support", Fraction(0)))
            symbols.append(Symbol(start, duration, part, direction, level, bend))
        next_free[part] = start + duration
    which = draw(st.sampled_from(["none", "effort", "emotion"]))
    effort = emotion = None
    if which == "effort":
        effort = Effort(
            time=draw(st.floats(-5.0, -1.5)),
            weight=draw(st.floats(0.05, 0.95)),
            space=draw(st.floats(0.0, 1.0)),
        )
    elif which == "emotion":
        emotion = draw(st.sampled_from(EMOTIONS))
    title = draw(st.text(max_size=30).filter(lambda t: "\n" not in t))
    tempo = draw(st.fractions(min_value=10, max_value=300, max_denominator=8))
    meter = draw(st.integers(1, 12))
    axes = draw(st.sampled_from(AXES))
    return Score(
        symbols=tuple(symbols), title=title, tempo=tempo, meter=meter, effort=effort, emotion=emotion, axes=axes
    )


st.register_type_strategy(Score, scores())
