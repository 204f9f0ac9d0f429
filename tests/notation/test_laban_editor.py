"""LabanotationSuite's LabanEditor JSON (laban_editor.json)."""

from __future__ import annotations

import json
from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import ScoreFormatError
from capture2notation.notation import LEVELS, Score, Symbol, read, write
from capture2notation.notation.directions import SECTOR_DIRECTIONS
from capture2notation.notation.formats import format_for, lab
from capture2notation.notation.formats import laban_editor as le

FIELDS = ["start time", "duration", "head", "right elbow", "right wrist", "left elbow", "left wrist", "rotation"]
SUITE_DIRECTIONS = {
    "Forward",
    "Right Forward",
    "Right",
    "Right Backward",
    "Backward",
    "Left Backward",
    "Left",
    "Left Forward",
    "Place",
}

PHRASE = lab.loads("""\
title: port de bras
tempo: 120
0 1 right_arm right middle
0 2 head forward high
1 1 left_arm place high
2 1 right_arm forward low bend=1
0 4 support place middle
""")


def _mirror(name: str) -> str:
    return name.replace("right", "@").replace("left", "right").replace("@", "left")


def test_layout_times_and_vocabulary():
    d = le.score_to_laban_editor(PHRASE)
    assert list(d) == ["port de bras"]
    positions = d["port de bras"]
    # Position0 = start; then every distinct arrival of an arm/head symbol (beats 1, 2, 3).
    assert list(positions) == ["Position0", "Position1", "Position2", "Position3"]
    assert [p["start time"] for p in positions.values()] == [["0"], ["500"], ["1000"], ["1500"]]
    assert [p["duration"] for p in positions.values()] == [["0"], ["500"], ["500"], ["500"]]
    for p in positions.values():
        assert list(p) == FIELDS
        assert p["rotation"] == ["ToLeft", "0"]
        for f in FIELDS[2:7]:
            assert p[f][0] in SUITE_DIRECTIONS and p[f][1] in {"High", "Normal", "Low"}
    p0, p1, p2, p3 = positions.values()
    assert p0["head"] == ["Place", "High"] and p0["right elbow"] == ["Place", "Low"]
    assert p1["right elbow"] == p1["right wrist"] == ["Right", "Normal"]
    assert p1["head"] == ["Place", "High"]  # the head symbol has not arrived yet
    assert p2["head"] == ["Forward", "High"] and p2["left wrist"] == ["Place", "High"]
    assert p2["right elbow"] == ["Right", "Normal"]  # held
    assert p3["right wrist"] == ["Forward", "Low"]  # bend 1 keeps the arm's direction


@pytest.mark.parametrize("side", ["right_arm", "left_arm"])
@pytest.mark.parametrize("direction", list(SECTOR_DIRECTIONS) + ["place"])
@pytest.mark.parametrize("level", LEVELS)
def test_arm_segments_bend_rules(side, direction, level):
    if direction == "place" and level == "middle":
        return
    # Straight or slightly bent (15° either side of the sector centre) arms
    # keep the arm's direction and level in both segments.
    for bend in (0, 1):
        assert le.arm_segments(side, direction, level, bend) == ((direction, level), (direction, level))
    # Mirror symmetry between the right and the left arm.
    for bend in range(7):
        upper, fore = le.arm_segments(side, direction, level, bend)
        m_upper, m_fore = le.arm_segments(_mirror(side), _mirror(direction), level, bend)
        assert (m_upper, m_fore) == ((_mirror(upper[0]), upper[1]), (_mirror(fore[0]), fore[1]))
    # A deep bend separates the two segments.
    upper, fore = le.arm_segments(side, direction, level, 4)
    assert upper != fore


def test_hanging_arm_bends_forearm_forward():
    upper, fore = le.arm_segments("right_arm", "place", "low", 3)
    assert upper == ("back", "low") and fore == ("forward", "low")


def _collapsed(positions: dict):
    """(ms, state) of the positions where the state changes."""
    out, last = [], None
    for p in positions.values():
        word, deg = p["rotation"]
        front = round((1 if word == "ToRight" else -1) * float(deg) / 45)  # eighths, as the reader rounds
        state = (*(tuple(p[f]) for f in FIELDS[2:7]), front)
        if state != last:
            out.append((int(p["start time"][0]), state))
            last = state
    return out


@settings(max_examples=40, deadline=None)
@given(st.from_type(Score))
def test_write_read_write_keeps_the_key_poses(score):
    text = le.dumps(score)
    back = le.loads(text, "x.json")
    assert {s.part for s in back.symbols} <= {
        "head",
        "right_upper_arm",
        "right_forearm",
        "left_upper_arm",
        "left_forearm",
        "turn",
    }
    original = next(iter(json.loads(text).values()))
    again = next(iter(le.score_to_laban_editor(back).values()))
    # Read at tempo 60 (1 beat = 1000 ms), so the times come back exactly.
    assert back.tempo == 60
    assert _collapsed(original) == _collapsed(again)


def test_front_door_picks_laban_editor_by_name(tmp_path):
    path = tmp_path / "laban_editor.json"
    assert format_for(path).name == "laban_editor"
    write(PHRASE, path)
    data = json.loads(path.read_text())
    assert list(data) == ["port de bras"]
    back = read(path)
    assert Symbol(0, Fraction(1, 2), "right_upper_arm", "right", "middle") in back.symbols
    assert Symbol(Fraction(1, 2), Fraction(1, 2), "head", "forward", "high") in back.symbols
    out = le.write_laban_editor(Score(), tmp_path / "empty.json")
    assert list(json.loads(out.read_text())) == ["empty"]


@pytest.mark.parametrize(
    "mutate,fragment",
    [
        (lambda p: p["Position1"].update({"head": ["Up", "High"]}), "Position1.head: unknown direction 'Up'"),
        (lambda p: p["Position1"].update({"left wrist": ["Left", "Mid"]}), "Position1.left wrist: unknown level 'Mid'"),
        (
            lambda p: p["Position2"].update({"right elbow": "Left"}),
            "Position2.right elbow: expected [Direction, Level]",
        ),
        (lambda p: p["Position1"].update({"start time": ["soon"]}), "Position1.start time: expected [milliseconds]"),
        (lambda p: p["Position1"].pop("start time"), "Position1.start time: missing"),
        (lambda p: p["Position1"].update({"right wrist": ["Place", "Normal"]}), "place middle"),
    ],
)
def test_reader_errors_name_the_json_path(mutate, fragment):
    d = le.score_to_laban_editor(PHRASE)
    mutate(d["port de bras"])
    with pytest.raises(ScoreFormatError) as info:
        le.loads(json.dumps(d), "laban_editor.json")
    assert str(info.value).startswith("laban_editor.json: ") and fragment in str(info.value), str(info.value)


def test_rotation_is_the_front_at_each_position():
    score = lab.loads("tempo: 60\n0 1 turn right amount=1/4\n1 2 turn left amount=3/4\n1 2 right_arm right middle\n")
    positions = next(iter(le.score_to_laban_editor(score).values())).values()
    # Positions at every turn's start and end: 0, 1 s and 3 s.
    assert [(p["start time"][0], p["rotation"]) for p in positions] == [
        ("0", ["ToLeft", "0"]),
        ("1000", ["ToRight", "90"]),
        ("3000", ["ToLeft", "180"]),
    ]
    back = le.loads(le.dumps(score), "x.json")
    assert [s for s in back.symbols if s.is_turn] == [s for s in score.symbols if s.is_turn]


def test_suite_library_rotations_read_as_turns():
    # MSRAbotChatSimulation's "beat rotate": fronts 0, 30, -30, 0 degrees (ToRight),
    # rounded to eighths: 1/8 right, 1/4 left, 1/8 right.
    pose = {"head": ["Forward", "Normal"]}
    doc = {
        "beat rotate": {
            f"Position{i}": {"start time": [t], "duration": ["0"], "rotation": ["ToRight", deg], **pose}
            for i, (t, deg) in enumerate([("1", "0"), ("500", "30"), ("1500", "-30"), ("2500", "0")])
        }
    }
    turns = [(s.start, s.duration, s.direction, s.amount) for s in le.loads(json.dumps(doc)).symbols if s.is_turn]
    assert turns == [
        (Fraction(1, 1000), Fraction(499, 1000), "right", Fraction(1, 8)),
        (Fraction(1, 2), Fraction(1), "left", Fraction(1, 4)),
        (Fraction(3, 2), Fraction(1), "right", Fraction(1, 8)),
    ]


@pytest.mark.parametrize(
    "rotation,fragment",
    [(["Up", "0"], '"Up"'), (["ToRight", "nan"], '"nan"'), (["ToLeft", 5], "5")],
)
def test_bad_rotation_names_the_field(rotation, fragment):
    doc = {"s": {"Position0": {"start time": ["0"], "rotation": rotation}}}
    with pytest.raises(
        ScoreFormatError, match=r"s\.Position0\.rotation: expected \[ToRight\|ToLeft, degrees\], got .*" + fragment
    ):
        le.loads(json.dumps(doc), "x.json")
