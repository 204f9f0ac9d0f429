"""The .lab score text format: exact round trips and line-naming errors."""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import ScoreFormatError
from capture2notation.notation import Effort, Score, Symbol, read, write
from capture2notation.notation.formats import lab

FIGURE = """\
title: Third port de bras
tempo: 64
meter: 4
effort: time=-2.42 weight=0.60 space=0     # optional; or   emotion: happy
# start  duration  part         direction      level    [bend=N]
0        4         support      place          middle
0        1         right_arm    forward        low      bend=1
1        1/2       right_arm    right          high
1        1         left_leg     left_forward   middle
"""

# --- reading ------------------------------------------------------------------


def test_design_example_reads_exactly():
    s = lab.loads(FIGURE, "x.lab")
    assert s.title == "Third port de bras"
    assert s.tempo == 64 and s.meter == 4
    assert s.effort == Effort(time=-2.42, weight=0.60, space=0.0)
    assert s.emotion is None
    assert set(s.symbols) == {
        Symbol(0, 4, "support", "place", "middle"),
        Symbol(0, 1, "right_arm", "forward", "low", 1),
        Symbol(1, Fraction(1, 2), "right_arm", "right", "high"),
        Symbol(1, 1, "left_leg", "left_forward", "middle"),
    }


@pytest.mark.parametrize(
    "token,value",
    [
        ("1/2", Fraction(1, 2)),
        (".50", Fraction(1, 2)),
        ("1.5", Fraction(3, 2)),
        ("2", Fraction(2)),
        ("0.125", Fraction(1, 8)),
        ("4/6", Fraction(2, 3)),
    ],
)
def test_beats_are_exact_fractions(token, value):
    s = lab.loads(f"{token} {token} head forward high\n")
    assert s.symbols[0].start == value and s.symbols[0].duration == value
    assert isinstance(s.symbols[0].start, Fraction)


def test_defaults_emotion_comments_and_crlf():
    text = "# leading comment\r\n\r\nemotion: sad   # a trailing comment\r\n0 1 head forward high # x\r\n"
    s = lab.loads(text)
    assert s.emotion == "sad" and s.effort is None
    assert s.title == "" and s.tempo == 60 and s.meter == 4
    assert s.symbols == (Symbol(0, 1, "head", "forward", "high"),)


def test_byte_order_mark_is_ignored():
    assert lab.loads("\ufefftitle: x\n0 1 head forward high\n").title == "x"


def test_title_keeps_hash_and_quoted_whitespace():
    assert lab.loads("title: No. #7 # not a comment\n").title == "No. #7 # not a comment"
    assert lab.loads('title: "  padded\\t "\n').title == "  padded\t "


def test_writer_is_canonical():
    text = lab.dumps(lab.loads(FIGURE))
    lines = text.splitlines()
    assert lines[:4] == [
        "title: Third port de bras",
        "tempo: 64",
        "meter: 4",
        "effort: time=-2.42 weight=0.6 space=0.0",
    ]
    assert lines[4].startswith("#") and lines[4].split()[1:6] == ["start", "duration", "part", "direction", "level"]
    rows = [ln.split() for ln in lines[5:]]
    assert rows[0] == ["0", "1", "right_arm", "forward", "low", "bend=1"]
    assert rows[2] == ["1", "1/2", "right_arm", "right", "high"]  # no bend=0
    assert lab.dumps(lab.loads(text)) == text


@settings(max_examples=100, deadline=None)
@given(st.from_type(Score))
def test_parse_write_parse_is_exact(score):
    text = lab.dumps(score)
    again = lab.loads(text, "gen.lab")
    assert again == score
    assert lab.dumps(again) == text


@settings(max_examples=25, deadline=None)
@given(st.from_type(Score))
def test_file_round_trip_through_front_door(tmp_path_factory, score):
    path = tmp_path_factory.mktemp("lab") / "score.lab"
    write(score, path)
    assert read(path) == score


# --- errors name the file, the line and the bad token ---------------------------

GOOD_HEAD = "title: t\n# comment\n\n0 1 head forward high\n"


@pytest.mark.parametrize(
    "bad_line,fragments",
    [
        ("0 1 right_arm fwd high", ["unknown direction 'fwd'", "forward right_forward"]),
        ("0 1 right_hand forward high", ["unknown part 'right_hand'", "right_arm"]),
        ("0 1 right_arm forward mid", ["unknown level 'mid'", "high middle low"]),
        ("x 1 right_arm forward high", ["start 'x'", "1/2"]),
        ("0 1/0 right_arm forward high", ["duration '1/0'"]),
        ("0 0 right_arm forward high", ["duration 0 must be > 0"]),
        ("0 1 right_arm forward", ["expected the columns", "got 4 column(s)"]),
        ("0 1 right_arm forward high bend=9", ["bend 9"]),
        ("0 1 right_arm forward high bend=x", ["bend 'x'"]),
        ("0 1 right_arm forward high bend=1 bend=2", ["bend is given twice"]),
        ("0 1 right_arm forward high twist=1", ["unexpected 'twist=1'", "bend=N"]),
        ("0 1 head forward high bend=2", ["only allowed on"]),
        ("0 1 right_arm place middle", ["place middle"]),
        ("tempo: fast", ["tempo 'fast'"]),
        ("tempo: 0", ["tempo '0' must be > 0"]),
        ("meter: 3.5", ["meter '3.5'"]),
        ("effort: time=-2 weight=0.5", ["missing space"]),
        ("effort: time=-2 weight=0.5 space=2", ["space=2.0", "working range"]),
        ("effort: time=-2 weight=0.5 space=nan", ["finite"]),
        ("effort: time=-2 mass=1 weight=0.5 space=1", ["'mass=1'"]),
        ("emotion: bored", ["unknown emotion 'bored'", "happy"]),
        ("colour: red", ["unknown header 'colour:'", "title:"]),
        ("tempo 64", ["header 'tempo' needs a colon"]),
        ("title: again", ["'title:' is given twice (first on line 1)"]),
    ],
)
def test_errors_name_file_line_and_token(bad_line, fragments):
    text = GOOD_HEAD + bad_line + "\n"
    with pytest.raises(ScoreFormatError) as info:
        lab.loads(text, "score.lab")
    msg = str(info.value)
    assert msg.startswith("score.lab:5: "), msg
    assert info.value.line == 5 and info.value.path == "score.lab"
    for frag in fragments:
        assert frag in msg, (frag, msg)


def test_bad_quoted_title_names_its_line():
    with pytest.raises(ScoreFormatError, match=r"^t.lab:2: .*JSON string literal"):
        lab.loads('# c\ntitle: "unterminated\n', "t.lab")


def test_overlap_names_the_later_line_and_the_earlier_one():
    text = "0 2 right_arm forward high\nemotion: happy\n1 1 right_arm right high\n"
    with pytest.raises(ScoreFormatError) as info:
        lab.loads(text, "o.lab")
    assert info.value.line == 3
    assert "line 1" in str(info.value) and "beat 2" in str(info.value)


def test_effort_and_emotion_together_rejected_at_the_later_line():
    with pytest.raises(ScoreFormatError) as info:
        lab.loads("emotion: happy\n\neffort: time=-2 weight=0.5 space=1\n", "e.lab")
    assert info.value.line == 3 and "not both" in str(info.value)


def test_front_door_errors(tmp_path):
    with pytest.raises(ScoreFormatError, match="cannot read score file"):
        read(tmp_path / "missing.lab")
    with pytest.raises(ScoreFormatError, match="cannot tell the score format"):
        read(tmp_path / "score.xyz")
    with pytest.raises(ScoreFormatError, match="unknown score format 'abc'"):
        write(Score(), tmp_path / "s.lab", format="abc")
    bad = tmp_path / "latin1.lab"
    bad.write_bytes("title: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ScoreFormatError, match="not UTF-8"):
        read(bad)
    # An explicit format overrides the file name.
    write(Score(title="x"), tmp_path / "score.txt", format="lab")
    assert read(tmp_path / "score.txt", format="lab").title == "x"


def test_failed_write_leaves_no_partial_file(tmp_path):
    target = tmp_path / "s.lab"
    with pytest.raises(ScoreFormatError):
        write("not a score", target)
    assert not target.exists()


def test_registry_dispatch_and_registration(tmp_path, monkeypatch):
    from capture2notation.notation import formats as registry

    assert registry.format_for("A/SCORE.LAB").name == "lab"
    assert registry.format_for("x.TXT").name == "wolofsky1974"
    assert registry.format_for("out/laban_editor.json").name == "laban_editor"  # longest ending wins
    assert registry.format_for("out/score.json").name == "json"
    assert set(registry.formats()) >= {"lab", "json", "wolofsky1974", "laban_editor"}
    # A new format is one explicit call; dumps/loads go through it.
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    registry.register_format(
        "lab_upper",
        (".ulab",),
        lambda text, path: lab.loads(text.lower(), path),
        lambda score: lab.dumps(score).upper(),
        "shouting .lab",
    )
    score = lab.loads(FIGURE)
    write(score, tmp_path / "s.ulab")
    assert (tmp_path / "s.ulab").read_text().startswith("TITLE: THIRD PORT DE BRAS")
    assert read(tmp_path / "s.ulab").symbols == score.symbols
    assert registry.loads(registry.dumps(score, "lab"), "lab") == score


_LAB_WORDS = st.sampled_from(
    [
        "title:",
        "tempo:",
        "meter:",
        "effort:",
        "emotion:",
        "happy",
        "time=-2",
        "weight=.5",
        "space=1",
        "0",
        "1",
        "1/2",
        ".5",
        "-1",
        "1/0",
        "nan",
        "1e9",
        "right_arm",
        "support",
        "forward",
        "place",
        "high",
        "middle",
        "low",
        "bend=2",
        "bend=",
        "#",
        '"',
        "\t",
        "\r",
        "x:",
    ]
)


@settings(max_examples=120, deadline=None)
@given(st.lists(st.lists(_LAB_WORDS | st.text(max_size=4), max_size=7).map(" ".join), max_size=6).map("\n".join))
def test_any_text_parses_or_raises_score_format_error(text):
    try:
        score = lab.loads(text, "fuzz.lab")
    except ScoreFormatError as exc:
        assert str(exc).startswith("fuzz.lab:")
    else:
        assert lab.loads(lab.dumps(score)) == score


# --- turns, flight, the key and the range guards ---------------------------------

TURNS = """\
axes: standard                # optional header: standard (default) | body
# start  duration  part           direction   level / keywords
4        1         turn           right       amount=1/2     # pivot clockwise half a turn
4        1         right_support  place       high           # ... on the right foot in relevé
6        1/2       support        air                        # both feet off the floor
13/2     1/2       left_support   forward     middle         # landing: a leap onto the left foot
"""


def test_design_turn_example_reads_and_writes_exactly():
    s = lab.loads(TURNS, "t.lab")
    assert s.axes == "standard"
    assert set(s.symbols) == {
        Symbol(4, 1, "turn", "right", None, amount=Fraction(1, 2)),
        Symbol(4, 1, "right_support", "place", "high"),
        Symbol(6, Fraction(1, 2), "support", "air", None),
        Symbol(Fraction(13, 2), Fraction(1, 2), "left_support", "forward", "middle"),
    }
    text = lab.dumps(s)
    assert "turn             right          amount=1/2" in text and "support          air" in text
    assert "axes:" not in text  # the default key is not written
    body = s.replace(axes="body")
    assert "axes: body" in lab.dumps(body) and lab.loads(lab.dumps(body)) == body


@pytest.mark.parametrize(
    "line,fragment",
    [
        ("0 1 turn right", "needs 'amount=F'"),
        ("0 1 turn right high", "unexpected 'high' in a turn"),
        ("0 1 turn right amount=1/2 amount=1", "amount is given twice"),
        ("0 1 turn up amount=1", "unknown turn direction 'up'"),
        ("0 1 turn right amount=1/3", "multiple of 1/8"),
        ("0 1 support air low", "flight has no level"),
        ("0 1 left_support air", "unknown direction 'air'"),
        ("0 1 head forward", "expected the columns"),
        ("axes: tilted", "unknown axes 'tilted'"),
    ],
)
def test_turn_and_flight_errors_name_the_line(line, fragment):
    with pytest.raises(ScoreFormatError, match=fragment) as info:
        lab.loads(f"tempo: 60\n{line}\n", "t.lab")
    assert str(info.value).startswith("t.lab:2: ")


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("tempo: 1e100000000\n", "tempo '1e100000000' is not a number"),
        ("tempo: 1/1000\n", "outside 10-400"),
        ("tempo: " + "9" * 5000 + "\n", "longer than 40"),
        ("1000000000 1 head forward high\n", "exceeds the limit of 24000 beats"),
        ("0 1e9 head forward high\n", "is not a number"),
        ("meter: 999\n", "exceeds the limit of 64"),
        ("meter: 10000000000\n", "not a positive whole number"),
        ("0 3601 head forward high\n", "more than the limit of 3600 s"),
    ],
)
def test_range_guards_fail_fast_with_one_line(text, fragment):
    with pytest.raises(ScoreFormatError, match=fragment) as info:
        lab.loads(text, "g.lab")
    assert "\n" not in str(info.value) and len(str(info.value)) <= 320


def test_size_and_symbol_count_guards(tmp_path, monkeypatch):
    big = tmp_path / "big.lab"
    big.write_bytes(b"# " + b"x" * (16 * 2**20) + b"\n")
    with pytest.raises(ScoreFormatError, match="exceed the limit of 16777216"):
        read(big)
    monkeypatch.setattr(lab, "MAX_SYMBOLS", 3)
    with pytest.raises(ScoreFormatError, match=r"g.lab:4: more than 3 symbols"):
        lab.loads("".join(f"{i} 1 head forward high\n" for i in range(5)), "g.lab")
