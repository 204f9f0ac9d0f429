"""A captured symbol's confidence: the model, score.json, LabanEditor JSON and the staff."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import pytest

from capture2notation.errors import NotationError, ScoreFormatError
from capture2notation.notation import Score, Symbol
from capture2notation.notation.formats import json_format, laban_editor
from capture2notation.notation.model import SYMBOL_UNCERTAIN_BELOW
from capture2notation.notation.staff import staff_layout, svg_text
from capture2notation.notation.staff_draw import UNCERTAIN_GREY


def _score() -> Score:
    return Score.from_symbols(
        [
            Symbol(0, 1, "right_upper_arm", "forward", "middle", confidence=0.9),
            Symbol(0, 1, "right_forearm", "forward", "high", confidence=0.25),
            Symbol(1, 1, "head", "right", "middle"),
            Symbol(1, 2, "left_arm", "left", "high", confidence=0.4),
        ],
        tempo=60,
    )


def test_confidence_is_checked_and_is_not_part_of_equality():
    assert Symbol(0, 1, "head", "forward", "high", confidence=0.2) == Symbol(0, 1, "head", "forward", "high")
    assert Symbol(0, 1, "head", "forward", "high", confidence=0.2).uncertain
    assert not Symbol(0, 1, "head", "forward", "high", confidence=SYMBOL_UNCERTAIN_BELOW).uncertain
    assert not Symbol(0, 1, "head", "forward", "high").uncertain  # not assessed is not uncertain
    for bad in (1.5, -0.1, float("nan"), True, "0.5"):
        with pytest.raises(NotationError, match="confidence"):
            Symbol(0, 1, "head", "forward", "high", confidence=bad)


def test_score_json_round_trips_confidence_and_old_files_read_none():
    score = _score()
    back = json_format.loads(json_format.dumps(score))
    assert back == score
    assert [s.confidence for s in back.symbols] == [s.confidence for s in score.symbols]
    data = json.loads(json_format.dumps(score))
    for item in data["symbols"]:
        item.pop("confidence", None)
    assert all(s.confidence is None for s in json_format.score_from_dict(data).symbols)


@pytest.mark.parametrize("bad", [1.2, -1, "0.5", True, None])
def test_score_json_refuses_a_bad_confidence(bad):
    data = json.loads(json_format.dumps(_score()))
    data["symbols"][0]["confidence"] = bad
    if bad is None:  # null: not assessed
        assert json_format.score_from_dict(data).symbols[0].confidence is None
        return
    with pytest.raises(ScoreFormatError, match=r"symbols\[0\]\.confidence"):
        json_format.score_from_dict(data)


def test_laban_editor_round_trips_confidence_per_segment():
    score = _score()
    text = laban_editor.dumps(score)
    back = laban_editor.loads(text)
    got = {s.part: s.confidence for s in back.symbols}  # one symbol per part in this score
    assert got["right_upper_arm"] == pytest.approx(0.9)
    assert got["right_forearm"] == pytest.approx(0.25)
    assert got["head"] is None
    # A whole arm's confidence goes to both of its segments.
    assert got["left_upper_arm"] == pytest.approx(0.4)
    assert got["left_forearm"] == pytest.approx(0.4)
    data = json.loads(text)
    for pose in next(iter(data.values())).values():
        pose.pop(laban_editor.CONFIDENCE_KEY, None)
    assert all(s.confidence is None for s in laban_editor.loads(json.dumps(data)).symbols)


@pytest.mark.parametrize("bad", [{"right elbow": "2"}, {"right elbow": 0.5}, {"nose": "0.5"}, ["0.5"]])
def test_laban_editor_refuses_a_bad_confidence(bad):
    data = json.loads(laban_editor.dumps(_score()))
    positions = next(iter(data.values()))
    positions["Position1"][laban_editor.CONFIDENCE_KEY] = bad
    with pytest.raises(ScoreFormatError, match="confidence"):
        laban_editor.loads(json.dumps(data))


def test_the_staff_draws_uncertain_symbols_grey_and_dashed():
    score = _score()
    root = ET.fromstring(svg_text(staff_layout(score)))
    groups = [g for g in root.iter("{http://www.w3.org/2000/svg}g") if "symbol" in g.get("class", "").split()]
    assert len(groups) == len(score.symbols)
    for g in groups:
        uncertain = "uncertain" in g.get("class", "").split()
        outline = next(p for p in g.iter("{http://www.w3.org/2000/svg}polygon"))
        conf = g.get("data-confidence")
        assert uncertain == (conf is not None and float(conf) < SYMBOL_UNCERTAIN_BELOW)
        assert (outline.get("stroke") == UNCERTAIN_GREY) == uncertain
        assert (outline.get("stroke-dasharray") is not None) == uncertain
    assert sum("uncertain" in g.get("class", "").split() for g in groups) == 2
