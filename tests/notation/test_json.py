"""The JSON form of a score: exact round trip, schema errors name the JSON path."""

from __future__ import annotations

import json
from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import ScoreFormatError
from capture2notation.notation import Score, read, score_from_dict, score_to_dict, write
from capture2notation.notation.formats import json_format, lab

FIGURE = """\
title: Third port de bras
tempo: 64
meter: 4
effort: time=-2.42 weight=0.60 space=0
0        4         support      place          middle
0        1         right_arm    forward        low      bend=1
1        1/2       right_arm    right          high
1        1         left_leg     left_forward   middle
"""


@settings(max_examples=100, deadline=None)
@given(st.from_type(Score))
def test_dict_and_text_round_trips_are_exact(score):
    d = score_to_dict(score)
    assert score_from_dict(json.loads(json.dumps(d))) == score
    assert json_format.loads(json_format.dumps(score)) == score
    # The two forms carry the same content.
    assert lab.loads(lab.dumps(json_format.loads(json_format.dumps(score)))) == score


def test_dict_layout():
    d = score_to_dict(lab.loads(FIGURE))
    assert d["tempo"] == 64 and d["meter"] == 4 and d["emotion"] is None
    assert d["effort"] == {"time": -2.42, "weight": 0.6, "space": 0.0}
    assert d["symbols"][2] == {
        "start": "1",
        "duration": "1/2",
        "part": "right_arm",
        "direction": "right",
        "level": "high",
        "bend": 0,
    }
    half = score_to_dict(lab.loads("tempo: 129/2\n"))
    assert half["tempo"] == "129/2"


def test_lenient_numbers_are_exact():
    s = score_from_dict(
        {
            "tempo": 60.5,
            "symbols": [{"start": 0.25, "duration": "3/2", "part": "head", "direction": "forward", "level": "high"}],
        }
    )
    assert s.tempo == Fraction(121, 2)
    assert s.symbols[0].start == Fraction(1, 4) and s.symbols[0].bend == 0


def test_front_door_by_extension(tmp_path):
    s = lab.loads(FIGURE)
    write(s, tmp_path / "score.json")
    assert json.loads((tmp_path / "score.json").read_text())["format"] == "capture2notation.score"
    assert read(tmp_path / "score.json") == s


def _sym(**over):
    d = {"start": "0", "duration": "1", "part": "head", "direction": "forward", "level": "high"}
    d.update(over)
    return d


@pytest.mark.parametrize(
    "data,where,fragment",
    [
        (
            {"symbols": [_sym(), _sym(start="2"), _sym(start="3"), _sym(start="4", direction="fwd")]},
            "symbols[3].direction",
            "unknown direction 'fwd'",
        ),
        ({"symbols": [_sym(part="tail")]}, "symbols[0].part", "unknown part 'tail'"),
        ({"symbols": [_sym(level=3)]}, "symbols[0].level", "expected a string"),
        ({"symbols": [_sym(start="x")]}, "symbols[0].start", "'x'"),
        ({"symbols": [_sym(duration=3.14159265358979)]}, "symbols[0].duration", "not an exact fraction"),
        ({"symbols": [_sym(bend=True)]}, "symbols[0].bend", "whole number"),
        ({"symbols": [_sym(bend=2)]}, "symbols[0].bend", "only allowed on"),
        ({"symbols": [{"start": "0"}]}, "symbols[0].duration", "missing"),
        ({"symbols": [_sym(colour="red")]}, "symbols[0].colour", "unknown key"),
        ({"symbols": [_sym(duration="2"), _sym(start="1")]}, "symbols", "starts before"),
        ({"symbols": {}}, "symbols", "expected a list"),
        ({"tempo": "fast"}, "tempo", "'fast'"),
        ({"tempo": -3}, "tempo", "must be > 0"),
        ({"meter": 2.5}, "meter", "positive whole number"),
        ({"effort": {"time": -2, "weight": 0.5}}, "effort.space", "expected a number"),
        ({"effort": {"time": -9, "weight": 0.5, "space": 1}}, "effort", "working range"),
        ({"emotion": "bored"}, "emotion", "unknown emotion"),
        ({"title": 5}, "title", "one-line string"),
        ({"format": "other"}, "format", "expected"),
        ({"tempi": 60}, "tempi", "unknown key"),
    ],
)
def test_schema_errors_name_the_json_path(data, where, fragment):
    with pytest.raises(ScoreFormatError) as info:
        score_from_dict(data, "score.json")
    msg = str(info.value)
    assert msg.startswith(f"score.json: {where}: "), msg
    assert fragment in msg, msg


def test_invalid_json_names_the_line():
    with pytest.raises(ScoreFormatError) as info:
        json_format.loads('{\n "title": "x",\n oops\n}', "s.json")
    assert info.value.line == 3 and str(info.value).startswith("s.json:3: invalid JSON")


_json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-5, 5)
    | st.floats(allow_nan=False)
    | st.text(max_size=5)
    | st.sampled_from(["1/2", "head", "forward", "high", "place", "happy"]),
    lambda inner: (
        st.lists(inner, max_size=3)
        | st.dictionaries(
            st.sampled_from(["start", "duration", "part", "direction", "level", "bend", "time", "x"]), inner, max_size=4
        )
    ),
    max_leaves=12,
)


@settings(max_examples=120, deadline=None)
@given(
    st.dictionaries(
        st.sampled_from(["title", "tempo", "meter", "effort", "emotion", "symbols", "format"]), _json_values, max_size=6
    )
)
def test_any_dict_builds_or_raises_score_format_error(data):
    try:
        score = score_from_dict(data, "fuzz.json")
    except ScoreFormatError as exc:
        assert str(exc).startswith("fuzz.json:")
    else:
        assert score_from_dict(score_to_dict(score)) == score


def test_turns_flight_and_key_in_json():
    s = lab.loads(
        "axes: body\n0 1 right_support place low\n0 1 left_leg forward low\n0 1 turn left amount=3/8\n"
        "1 1/2 support air\n3/2 1/2 left_support forward low\n"
    )
    d = json_format.score_to_dict(s)
    assert d["version"] == 2 and d["axes"] == "body"
    turn = next(x for x in d["symbols"] if x["part"] == "turn")
    assert turn["amount"] == "3/8" and turn["level"] is None and "spring" not in turn
    air = next(x for x in d["symbols"] if x["direction"] == "air")
    assert air["spring"] == "leap" and air["level"] is None and "amount" not in air
    assert json_format.score_from_dict(d) == s
    # A spring form that the supports contradict is refused, naming the field.
    air["spring"] = "hop"
    with pytest.raises(ScoreFormatError, match=r"symbols\[\d\]\.spring: \"hop\" does not match .* leap"):
        json_format.score_from_dict(d, "s.json")
    # Version 1 files (no turns, no key) still read.
    v1 = {
        "version": 1,
        "symbols": [{"start": 0, "duration": 1, "part": "head", "direction": "forward", "level": "high"}],
    }
    assert json_format.score_from_dict(v1).axes == "standard"


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("[" * 100000 + "]" * 100000, "nested too deeply"),
        ('{"tempo": ' + "9" * 5000 + "}", "invalid JSON"),
        ('{"tempo": "1e100000000"}', "tempo: .*not a number"),
        ('{"tempo": 1e-300}', "not an exact fraction"),
        ('{"tempo": 0.5}', "outside 10-400"),
        (
            '{"symbols": [{"start": 1e9, "duration": 1, "part": "head", "direction": "forward", "level": "high"}]}',
            "exceeds the limit",
        ),
        (
            '{"symbols": [{"start": 0, "duration": 1, "part": "turn", "direction": "right", "level": null}]}',
            "needs amount",
        ),
    ],
)
def test_json_guards_fail_with_one_line(text, fragment):
    with pytest.raises(ScoreFormatError, match=fragment) as info:
        json_format.loads(text, "g.json")
    assert "\n" not in str(info.value)
