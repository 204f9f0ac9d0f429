"""The notation object model: Symbol, Score, Effort and exact time."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import NotationError
from capture2notation.notation import EMOTIONS, PARTS, Effort, Score, Symbol
from capture2notation.notation.model import as_fraction


@pytest.mark.parametrize(
    "value,expected",
    [
        (3, Fraction(3)),
        ("3/2", Fraction(3, 2)),
        (".5", Fraction(1, 2)),
        (" 1.25 ", Fraction(5, 4)),
        (0.5, Fraction(1, 2)),
        (Fraction(7, 3), Fraction(7, 3)),
    ],
)
def test_as_fraction_is_exact(value, expected):
    got = as_fraction(value)
    assert got == expected and isinstance(got, Fraction)


@pytest.mark.parametrize("value", [True, "abc", "1/0", 3.141592653589793, None, [1]])
def test_as_fraction_rejects(value):
    with pytest.raises(NotationError):
        as_fraction(value, "start")


def test_symbol_normalises_times_to_fractions():
    s = Symbol("1/2", 1, "right_arm", "forward", "high")
    assert s.start == Fraction(1, 2) and isinstance(s.duration, Fraction)
    assert s.end == Fraction(3, 2) and not s.is_support
    assert Symbol(0, 1, "support", "place", "middle").is_support


@pytest.mark.parametrize(
    "kwargs,fragment",
    [
        (dict(start=-1), "start -1 must be >= 0"),
        (dict(duration=0), "duration 0 must be > 0"),
        (dict(part="tail"), "unknown part 'tail'"),
        (dict(direction="up"), "unknown direction 'up'"),
        (dict(level="mid"), "unknown level 'mid'"),
        (dict(direction="place", level="middle"), "place middle"),
        (dict(bend=7), "bend 7"),
        (dict(bend=True), "bend True"),
        (dict(bend=1.0), "bend 1.0"),
        (dict(part="head", bend=1), "only allowed on"),
    ],
)
def test_symbol_validation(kwargs, fragment):
    fields = dict(start=0, duration=1, part="right_arm", direction="forward", level="high", bend=0)
    fields.update(kwargs)
    with pytest.raises(NotationError, match=fragment):
        Symbol(**fields)


def test_support_place_middle_is_valid():
    for part in ("support", "left_support", "right_support"):
        assert Symbol(0, 1, part, "place", "middle").level == "middle"


def test_frozen_and_hashable():
    s = Symbol(0, 1, "head", "forward", "high")
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.start = Fraction(1)
    assert len({s, Symbol(Fraction(0), Fraction(1), "head", "forward", "high")}) == 1


@settings(max_examples=30, deadline=None)
@given(st.from_type(Score), st.randoms(use_true_random=False))
def test_score_order_does_not_depend_on_input_order(score, rnd):
    shuffled = list(score.symbols)
    rnd.shuffle(shuffled)
    again = Score(
        symbols=tuple(shuffled),
        title=score.title,
        tempo=score.tempo,
        meter=score.meter,
        effort=score.effort,
        emotion=score.emotion,
        axes=score.axes,
    )
    assert again == score
    keys = [s.sort_key() for s in score.symbols]
    assert keys == sorted(keys)
    assert score.duration == max((s.end for s in score.symbols), default=0)
    for part in PARTS:
        assert all(s.part == part for s in score.for_part(part))
    assert sum(len(score.for_part(p)) for p in PARTS) == len(score.symbols)


def test_overlap_within_a_part_is_rejected_across_parts_allowed():
    a = Symbol(0, 2, "right_arm", "forward", "high")
    with pytest.raises(NotationError, match="starts before"):
        Score(symbols=(a, Symbol(1, 1, "right_arm", "right", "high")))
    Score(symbols=(a, Symbol(1, 1, "left_arm", "left", "high")))
    Score(symbols=(a, Symbol(2, 1, "right_arm", "right", "high")))  # touching is fine


@pytest.mark.parametrize(
    "kwargs,fragment",
    [
        (dict(tempo=0), "tempo 0 is outside 10-400 .*must be > 0"),
        (dict(tempo=9), "tempo 9 is outside 10-400"),
        (dict(tempo=401), "tempo 401 is outside"),
        (dict(meter=65), "at most 64"),
        (dict(axes="tilted"), "unknown axes 'tilted'"),
        (dict(title="x" * 1001), "exceeds the limit of 1000"),
        (dict(symbols=(Symbol(0, 3600, "head", "forward", "high"),), tempo=59), "more than the limit of 3600 s"),
        (dict(meter=0), "meter 0"),
        (dict(meter=True), "meter True"),
        (dict(title="a\nb"), "single line"),
        (dict(effort=Effort(), emotion="happy"), "not both"),
        (dict(emotion="bored"), "unknown emotion"),
        (dict(symbols=("x",)), "Symbol objects"),
    ],
)
def test_score_validation(kwargs, fragment):
    with pytest.raises(NotationError, match=fragment):
        Score(**kwargs)


def test_seconds_follow_tempo_exactly():
    score = Score(tempo=Fraction(80))
    assert score.seconds(Fraction(4)) == pytest.approx(3.0, abs=1e-12)
    assert Score(tempo=120).seconds("1/2") == pytest.approx(0.25, abs=1e-12)


def test_effort_resolution_and_emotion_presets():
    assert Score().resolved_effort() == Effort()
    e = Effort(time=-3.0, weight=0.4, space=0.2)
    assert Score(effort=e).resolved_effort() == e
    for emotion in EMOTIONS:
        s = Score(tempo=60).with_emotion(emotion)
        assert s.emotion == emotion and s.effort is None
        assert s.resolved_effort() == Score(emotion=emotion).resolved_effort()
    happy = Score().with_emotion("happy")
    assert happy.tempo == 80 and happy.resolved_effort() == Effort(time=-2.42, weight=0.60, space=0.0)
    assert Score().with_emotion("sad").tempo == 37
    with pytest.raises(NotationError, match="unknown emotion"):
        Score().with_emotion("bored")


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(time=-1.0),
        dict(time=-5.5),
        dict(weight=0.0),
        dict(weight=0.99),
        dict(space=-0.1),
        dict(space=1.5),
        dict(time=float("nan")),
        dict(time="fast"),
    ],
)
def test_effort_working_ranges(kwargs):
    with pytest.raises(NotationError, match="effort"):
        Effort(**kwargs)


def test_effort_edges_are_inside_and_stored_as_float():
    e = Effort(time=-5, weight=0.05, space=1)
    assert e.time == -5.0 and isinstance(e.time, float) and isinstance(e.space, float)


@pytest.mark.parametrize(
    "kwargs,fragment",
    [
        (dict(direction="up"), "unknown turn direction 'up'"),
        (dict(level="high"), "a turn has no level"),
        (dict(amount=None), "needs amount"),
        (dict(amount=Fraction(1, 3)), "multiple of 1/8"),
        (dict(amount=0), "multiple of 1/8"),
        (dict(amount=33), "at most 32"),
        (dict(bend=1), "not allowed on a turn"),
    ],
)
def test_turn_validation(kwargs, fragment):
    fields = dict(start=0, duration=1, part="turn", direction="right", level=None, amount=Fraction(1, 2)) | kwargs
    with pytest.raises(NotationError, match=fragment):
        Symbol(**fields)


def test_turns_and_flight_are_level_less_symbols():
    t = Symbol(0, 1, "turn", "left", None, amount="3/8")
    assert t.is_turn and not t.is_support and t.amount == Fraction(3, 8) and t.signed_amount == Fraction(-3, 8)
    a = Symbol(1, "1/2", "support", "air", None)
    assert a.is_air and a.is_support and a.signed_amount == 0
    for bad, fragment in [
        (dict(part="right_support"), "unknown direction 'air'"),
        (dict(level="low"), "support air has no level"),
        (dict(amount=1), "belongs to turn symbols only"),
    ]:
        with pytest.raises(NotationError, match=fragment):
            Symbol(**(dict(start=0, duration=1, part="support", direction="air", level=None) | bad))
    with pytest.raises(NotationError, match="unknown level None"):
        Symbol(0, 1, "head", "forward", None)


def test_no_foot_support_overlaps_flight():
    air = Symbol(2, 1, "support", "air", None)
    Score(symbols=(Symbol(0, 2, "right_support", "place", "low"), air, Symbol(3, 1, "left_support", "place", "low")))
    with pytest.raises(NotationError, match="overlaps support air"):
        Score(symbols=(Symbol(1, "3/2", "right_support", "place", "low"), air))


@pytest.mark.parametrize(
    "value,fragment",
    [("1e100000000", "not a number"), ("1_000", "not a number"), ("9" * 41, "longer than 40"), ("1/0", "divides")],
)
def test_number_tokens_are_guarded(value, fragment):
    with pytest.raises(NotationError, match=fragment):
        as_fraction(value, "start")


def test_beats_are_bounded():
    from capture2notation.notation.limits import MAX_BEATS

    Symbol(MAX_BEATS - 1, 1, "head", "forward", "high")
    with pytest.raises(NotationError, match="exceeds the limit"):
        Symbol(10**9, 1, "head", "forward", "high")
    with pytest.raises(NotationError, match="exceeds the limit"):
        Symbol(0, MAX_BEATS + 1, "head", "forward", "high")
    with pytest.raises(NotationError, match="finite"):
        as_fraction(float("inf"), "start")
