"""Wolofsky's 1974 coded input (Figure 7)."""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import ScoreFormatError
from capture2notation.notation import Symbol, read, write
from capture2notation.notation.formats import wolofsky1974

# Figure 7 as printed in the thesis (tab-separated, with its column heading).
FIGURE_7 = (
    "Type of Movement\tStarting Time\tBodypart\tDuration\tDirection/Level\n"
    "2\t0.00\tANR\t4.00\t-\n"
    "2\t0.00\tANL\t1.00\t-\n"
    "1\t1.00\tWLL\t1.00\tF\n"
    "1\t2.00\tWLL\t.50\tLSM\n"
    "1\t3.00\tWLL\t1.00\tLSL\n"
    "0\t4.00\t-\t-\t-\n"
)


def test_figure_7_phrase():
    s = wolofsky1974.loads(FIGURE_7)
    # "On the first beat the left leg goes to forward hip level, taking one
    # beat; on the second to the left side at hip level in half a beat; on
    # the third it lowers by 45 degrees over a whole beat."
    assert set(s.symbols) == {
        Symbol(Fraction(0), Fraction(4), "right_support", "place", "middle"),
        Symbol(Fraction(0), Fraction(1), "left_support", "place", "middle"),
        Symbol(Fraction(1), Fraction(1), "left_leg", "forward", "middle"),
        Symbol(Fraction(2), Fraction(1, 2), "left_leg", "left", "middle"),
        Symbol(Fraction(3), Fraction(1), "left_leg", "left", "low"),
    }
    assert len(s.symbols) == 5
    assert s.tempo == wolofsky1974.DEFAULT_TEMPO == 60 and s.meter == 4
    assert s.effort is None and s.emotion is None


def test_front_door_and_read_only(tmp_path):
    p = tmp_path / "figure7.w74"
    p.write_text(FIGURE_7)
    s = read(p)
    assert s.title == "figure7" and len(s.symbols) == 5
    assert read(tmp_path / "figure7.w74", format="wolofsky1974") == s
    with pytest.raises(ScoreFormatError, match="read-only"):
        write(s, tmp_path / "out.w74")
    with pytest.raises(ScoreFormatError, match="read-only"):
        write(s, tmp_path / "out.lab", format="wolofsky1974")
    assert not (tmp_path / "out.w74").exists()


@pytest.mark.parametrize(
    "code,direction,level",
    [
        ("F", "forward", "middle"),
        ("BH", "back", "high"),
        ("RDFL", "right_forward", "low"),
        ("LDB", "left_back", "middle"),
        ("RS", "right", "middle"),
        ("PH", "place", "high"),
        ("LDFM", "left_forward", "middle"),
        ("RDBH", "right_back", "high"),
    ],
)
def test_codes(code, direction, level):
    s = wolofsky1974.loads(f"1 0 WRA 1 {code}\n")
    assert s.symbols == (Symbol(0, 1, "right_arm", direction, level),)


def test_lines_after_end_are_ignored():
    s = wolofsky1974.loads("1 0 WLA 1 F\n0 1 - - -\n1 0 nonsense\n")
    assert len(s.symbols) == 1


@pytest.mark.parametrize(
    "line,fragment",
    [
        ("1 1.00 WLL 1.00 FWD", "unknown direction/level code 'FWD'"),
        ("1 1.00 XYZ 1.00 F", "unknown body-part code 'XYZ'"),
        ("3 1.00 WLL 1.00 F", "unknown movement type '3'"),
        ("2 1.00 WLL 1.00 -", "WLL is a gesture (type 1)"),
        ("1 1.00 ANL 1.00 F", "ANL is a support (type 2)"),
        ("1 1.00 WLL 1.00 -", "only valid for supports"),
        ("1 1.00 WLL 1.00 P", "place middle"),
        ("1 1.00 WLL", "expected the columns"),
        ("1 x WLL 1.00 F", "start 'x'"),
        ("1 1.00 WLL 1.00 F LS", "intermediate position"),
        ("1 0.50 ANR 1.00 -", "ANR is a support"),
    ],
)
def test_errors_name_line_and_token(line, fragment):
    text = "2\t0.00\tANR\t4.00\t-\n# comment\n" + line + "\n"
    with pytest.raises(ScoreFormatError) as info:
        wolofsky1974.loads(text, "phrase.w74")
    assert str(info.value).startswith("phrase.w74:3: "), str(info.value)
    assert fragment in str(info.value)


def test_overlap_names_both_lines():
    with pytest.raises(ScoreFormatError) as info:
        wolofsky1974.loads("1 0 WLL 2 F\n1 1 WLL 1 B\n", "p.w74")
    assert info.value.line == 2 and "line 1" in str(info.value)


_CODES = {v: k for k, v in wolofsky1974.DIRECTION_CODES.items()}
_GESTURES = {"WLL": "left_leg", "WRL": "right_leg", "WLA": "left_arm", "WRA": "right_arm"}


@st.composite
def coded_phrases(draw):
    """Coded input lines and the symbols they must give (quarter-beat decimals)."""
    lines, expected = [], []
    free: dict[str, Fraction] = {}
    for _ in range(draw(st.integers(0, 8))):
        code = draw(st.sampled_from(sorted(wolofsky1974.PART_CODES)))
        part, mtype = wolofsky1974.PART_CODES[code]
        start = free.get(part, Fraction(0)) + Fraction(draw(st.integers(0, 8)), 4)
        dur = Fraction(draw(st.integers(1, 8)), 4)
        if mtype == 2:
            text, direction, level = "-", "place", "middle"
        else:
            direction = draw(st.sampled_from(sorted(_CODES)))
            level = draw(st.sampled_from(["high", "low"] if direction == "place" else ["high", "middle", "low"]))
            letter = {"high": "H", "middle": draw(st.sampled_from(["M", ""])), "low": "L"}[level]
            text = _CODES[direction] + letter
        fmt = draw(st.sampled_from(["{:.2f}", "{:g}"]))
        s_txt = fmt.format(float(start)).lstrip("0") or "0"
        lines.append(f"{mtype}\t{s_txt}\t{code}\t{fmt.format(float(dur))}\t{text}")
        expected.append(Symbol(start, dur, part, direction, level))
        free[part] = start + dur
    rnd = draw(st.randoms(use_true_random=False))
    rnd.shuffle(lines)
    return "\n".join(lines + ["0 99 - - -"]) + "\n", expected


@settings(max_examples=100, deadline=None)
@given(coded_phrases())
def test_generated_coded_input_parses_to_its_symbols(case):
    text, expected = case
    assert sorted(wolofsky1974.loads(text).symbols, key=Symbol.sort_key) == sorted(expected, key=Symbol.sort_key)


@settings(max_examples=120, deadline=None)
@given(
    st.lists(
        st.lists(
            st.sampled_from(
                [
                    "0",
                    "1",
                    "2",
                    "3",
                    ".5",
                    "1.00",
                    "x",
                    "WLL",
                    "ANR",
                    "WXX",
                    "-",
                    "F",
                    "LSM",
                    "PH",
                    "P",
                    "RDBL",
                    "Type",
                    "#",
                ]
            )
            | st.text(max_size=3),
            max_size=6,
        ).map(" ".join),
        max_size=6,
    ).map("\n".join)
)
def test_any_text_parses_or_raises_score_format_error(text):
    try:
        wolofsky1974.loads(text, "fuzz.w74")
    except ScoreFormatError as exc:
        assert str(exc).startswith("fuzz.w74:")
