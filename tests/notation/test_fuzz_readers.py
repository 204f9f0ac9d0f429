"""Fuzzing every score reader: success or a one-line ScoreFormatError, nothing else.

Inputs are valid files (random scores with turns, flight and both keys,
written by the format's own writer) mutated token by token and line by line
with hostile values — numbers with huge exponents or digit counts, tiny and
huge tempos and starts, deep nesting, wrong JSON types, truncation — plus
free text.  A reader must either return a score (which then round-trips
through its writer where there is one) or raise
:class:`~capture2notation.errors.ScoreFormatError` naming the file, in one
line.  The default tier draws a few hundred inputs per reader; the slow tier
10,000 per reader (issue 16).
"""

from __future__ import annotations

import copy
import json
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from capture2notation.errors import ScoreFormatError
from capture2notation.notation import EMOTIONS, GESTURE_PARTS, Effort, Score, Symbol
from capture2notation.notation.formats import json_format, lab, laban_editor, wolofsky1974

FAST = settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
SLOW = settings(max_examples=10_000, deadline=None, suppress_health_check=list(HealthCheck))

#: Tokens that have broken readers before or sit on a limit.
NASTY = (
    "1e100000000",
    "9" * 45,
    "9" * 5000,
    "1/" + "9" * 39,
    "-1",
    "0",
    "-0",
    "1/0",
    "0/0",
    "nan",
    "inf",
    "-inf",
    "1e9",
    "1000000000",
    "24000",
    "24001",
    "3600",
    "1/1000",
    "400",
    "401",
    "10",
    "9",
    ".",
    "/",
    "1_0",
    "0x10",
    "amount=1/2",
    "amount=1e9",
    "amount=33",
    "amount=",
    "air",
    "turn",
    "right",
    "left",
    "body",
    "standard",
    "axes:",
    "tempo:",
    "meter:",
    "bend=9",
    "bend=99999999999",
    "support",
    "right_support",
    "high",
    "\x00",
    "\ufeff",
    "é",
    "#",
    ":",
    '"',
    "\r",
    "\t",
)
NASTY_JSON = (
    None,
    True,
    0,
    -1,
    10**5000,
    1e308,
    1e-300,
    0.1,
    "",
    "1e100000000",
    "9" * 5000,
    "1/3",
    "turn",
    "air",
    "support",
    "right",
    "body",
    [],
    {},
    [[[[[[]]]]]],
    ["ToRight", "1e400"],
    ["ToLeft", "-5"],
    ["Forward"],
    ["Place", "Middle"],
)


def _base_scores() -> list[Score]:
    """Valid scores to mutate: a seeded spread of parts, turns, flight, keys and headers.

    Built once (drawing a fresh hypothesis score per input would cost more than
    the reader itself); the mutations supply the variety.
    """
    rng = np.random.default_rng(16)
    out = [Score()]
    for k in range(40):
        syms, t = [], Fraction(0)
        for _ in range(int(rng.integers(1, 10))):
            dur = Fraction(int(rng.integers(1, 9)), int(rng.choice([1, 2, 4, 8])))
            kind = int(rng.integers(4))
            if kind == 0:
                amount = Fraction(int(rng.integers(1, 17)), 8)
                syms.append(Symbol(t, dur, "turn", ("right", "left")[k % 2], None, amount=amount))
            elif kind == 1:
                syms.append(Symbol(t, dur, "support", "air", None))
                t += dur
                syms.append(Symbol(t, dur, ("support", "right_support", "left_support")[k % 3], "forward", "low"))
            else:
                part = GESTURE_PARTS[int(rng.integers(len(GESTURE_PARTS)))]
                syms.append(Symbol(t, dur, part, "right_forward", ("high", "low")[k % 2]))
            t += dur
        extra = {}
        if k % 3 == 1:
            extra["effort"] = Effort(time=-2.5, weight=0.4, space=0.5)
        elif k % 3 == 2:
            extra["emotion"] = EMOTIONS[k % len(EMOTIONS)]
        out.append(
            Score(
                tuple(syms),
                title=f"fuzz {k}",
                tempo=Fraction(int(rng.integers(10, 401))),
                meter=int(rng.integers(1, 13)),
                axes=("standard", "body")[k % 2],
                **extra,
            )
        )
    return out


BASES = _base_scores()


def _mutate_text(draw, text: str) -> str:
    lines = text.split("\n")
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["token", "token", "delete", "insert", "duplicate", "truncate", "chars"]))
        i = draw(st.integers(0, max(len(lines) - 1, 0)))
        if op == "token" and lines:
            toks = lines[i].split()
            if toks:
                toks[draw(st.integers(0, len(toks) - 1))] = draw(st.sampled_from(NASTY) | st.text(max_size=6))
                lines[i] = " ".join(toks)
        elif op == "delete" and lines:
            del lines[i]
        elif op == "insert":
            words = draw(st.lists(st.sampled_from(NASTY) | st.text(max_size=5), max_size=7))
            lines.insert(i, " ".join(words))
        elif op == "duplicate" and lines:
            lines.insert(i, lines[i])
        elif op == "truncate" and lines:
            lines[i] = lines[i][: draw(st.integers(0, len(lines[i])))]
        elif op == "chars" and lines:
            lines[i] += draw(st.text(max_size=8))
    return "\n".join(lines)


@st.composite
def lab_texts(draw):
    if draw(st.integers(0, 9)) == 0:
        return draw(st.text(max_size=200))
    return _mutate_text(draw, lab.dumps(draw(st.sampled_from(BASES))))


@st.composite
def w74_texts(draw):
    rows = []
    for _ in range(draw(st.integers(0, 6))):
        rows.append(
            " ".join(
                [
                    draw(st.sampled_from(["0", "1", "2", "3"])),
                    draw(st.sampled_from(["0", "1.00", ".50", "2", "3.5"])),
                    draw(st.sampled_from(["WLL", "WRL", "WLA", "WRA", "ANL", "ANR", "XX"])),
                    draw(st.sampled_from(["1.00", ".50", "4", "0"])),
                    draw(st.sampled_from(["F", "B", "RS", "LDB", "PH", "LSL", "-", "Q"])),
                ]
            )
        )
    return _mutate_text(draw, "\n".join(rows + ["0 4.00 - - -"]))


def _paths(node, prefix=()):
    """Every (path, value) of a JSON tree, to a depth of 12."""
    yield prefix, node
    if len(prefix) >= 12:
        return
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, prefix + (i,))


def _mutate_tree(draw, tree):
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p, _ in _paths(tree) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = tree
        for k in path[:-1]:
            parent = parent[k]
        op = draw(st.sampled_from(["replace", "replace", "delete", "nest"]))
        if op == "delete":
            del parent[path[-1]]
        elif op == "nest":
            depth = draw(st.sampled_from([2, 50, 5000]))
            value = parent[path[-1]]
            for _ in range(depth):
                value = [value]
            parent[path[-1]] = value
        else:
            # A copy: later mutations must not change the shared constants.
            parent[path[-1]] = copy.deepcopy(draw(st.sampled_from(NASTY_JSON) | st.text(max_size=6) | st.integers()))
    return tree


def _json_text(draw, tree) -> str:
    try:
        text = json.dumps(tree)
    except (RecursionError, ValueError):
        text = "[" * 200_000  # deeper than any reader recurses
    if draw(st.integers(0, 9)) == 0:
        text = text[: draw(st.integers(0, len(text)))]
    return text.replace('"1e400"', "1e400", 1) if draw(st.booleans()) else text


@st.composite
def json_texts(draw):
    tree = json_format.score_to_dict(draw(st.sampled_from(BASES)))
    return _json_text(draw, _mutate_tree(draw, tree))


@st.composite
def laban_editor_texts(draw):
    tree = laban_editor.score_to_laban_editor(draw(st.sampled_from(BASES)))
    return _json_text(draw, _mutate_tree(draw, tree))


def _check(loads, dumps, text: str) -> None:
    try:
        score = loads(text, "fuzz.in")
    except ScoreFormatError as exc:
        message = str(exc)
        assert message.startswith("fuzz.in") and "\n" not in message and len(message) <= 320, message
        return
    assert isinstance(score, Score)
    if dumps is not None:
        assert loads(dumps(score), None) == score


@FAST
@given(lab_texts())
def test_lab_reader(text):
    _check(lab.loads, lab.dumps, text)


@FAST
@given(json_texts())
def test_json_reader(text):
    _check(json_format.loads, json_format.dumps, text)


@FAST
@given(laban_editor_texts())
def test_laban_editor_reader(text):
    _check(laban_editor.loads, None, text)


@FAST
@given(w74_texts())
def test_wolofsky1974_reader(text):
    _check(wolofsky1974.loads, None, text)


@pytest.mark.slow
@SLOW
@given(lab_texts())
def test_lab_reader_10k(text):
    _check(lab.loads, lab.dumps, text)


@pytest.mark.slow
@SLOW
@given(json_texts())
def test_json_reader_10k(text):
    _check(json_format.loads, json_format.dumps, text)


@pytest.mark.slow
@SLOW
@given(laban_editor_texts())
def test_laban_editor_reader_10k(text):
    _check(laban_editor.loads, None, text)


@pytest.mark.slow
@SLOW
@given(w74_texts())
def test_wolofsky1974_reader_10k(text):
    _check(wolofsky1974.loads, None, text)
