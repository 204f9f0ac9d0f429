"""The Labanotation staff drawing (staff.svg / PNG)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import NotationError
from capture2notation.notation import Score, Symbol
from capture2notation.notation.formats import lab
from capture2notation.notation.staff import render_staff, staff_layout, svg_text, symbol_outline

SVG = "{http://www.w3.org/2000/svg}"

PHRASE = lab.loads("""\
title: Figure 7 <&> $test\x01
tempo: 60
meter: 2
0 4 right_support place middle
0 1 left_support place middle
1 1 left_leg forward middle
2 1/2 left_leg left middle
3 1 left_leg left low
0 2 right_arm right high bend=2
1 3 head forward high
2 1 chest right_back middle
""")


def _symbol_groups(root):
    return [g for g in root.iter(f"{SVG}g") if "symbol" in g.get("class", "").split()]


def _polygon_y_extent(g) -> float:
    """Summed vertical extent of a symbol's outline pieces, pixels."""
    total = 0.0
    for poly in g.findall(f"{SVG}polygon"):
        pts = np.array([[float(v) for v in p.split(",")] for p in poly.get("points").split()])
        total += pts[:, 1].max() - pts[:, 1].min()
    return total


def test_svg_parses_and_has_one_group_per_symbol(tmp_path):
    out = render_staff(PHRASE, tmp_path / "staff.svg", tmp_path / "staff.png")
    root = ET.parse(out).getroot()
    assert root.tag == f"{SVG}svg"
    groups = _symbol_groups(root)
    assert len(groups) == len(PHRASE.symbols)
    assert sorted(g.get("id") for g in groups) == sorted(f"sym-{i}" for i in range(len(PHRASE.symbols)))
    for g in groups:
        s = PHRASE.symbols[int(g.get("id").split("-")[1])]
        assert g.get("data-part") == s.part and g.get("data-direction") == s.direction
        assert g.get("data-level") == s.level and int(g.get("data-bend")) == s.bend
        assert Fraction(g.get("data-start")) == s.start and Fraction(g.get("data-duration")) == s.duration
    # XML specials are escaped, characters XML forbids replaced, '$' is not maths.
    assert any(t.text == "Figure 7 <&> $test\ufffd" for t in root.iter(f"{SVG}text"))
    png = (tmp_path / "staff.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


@settings(max_examples=20, deadline=None)
@given(st.from_type(Score), st.sampled_from([None, 1, 2, 8]))
def test_vertical_extent_is_proportional_to_duration(score, measures_per_staff):
    lay = staff_layout(score, beat_height=40.0, measures_per_staff=measures_per_staff)
    root = ET.fromstring(svg_text(lay).encode())
    groups = _symbol_groups(root)
    assert len(groups) == len(score.symbols)
    for g in groups:
        dur = Fraction(g.get("data-duration"))
        if g.get("data-direction") == "air":  # flight is a gap: no outline
            assert g.find(f"{SVG}polygon") is None and g.find(f"{SVG}text").text
            continue
        assert _polygon_y_extent(g) == pytest.approx(40.0 * float(dur), abs=0.02)


def test_time_runs_bottom_to_top_and_sides():
    lay = staff_layout(PHRASE)
    by_part = {}
    for g in lay.glyphs:
        by_part.setdefault(g.symbol.part, []).append(g)
    legs = sorted(by_part["left_leg"], key=lambda g: g.symbol.start)
    # Later symbols are higher on the page (smaller y).
    assert legs[0].foot[1] > legs[1].foot[1] > legs[2].foot[1]
    centre = np.mean([g.centre[0] for g in by_part["right_support"] + by_part["left_support"]])
    assert by_part["right_arm"][0].pieces[0][:, 0].min() > centre > by_part["left_leg"][0].pieces[0][:, 0].max()
    # Column order outwards on the right: support, leg, body, arm, head.
    x = {p: by_part[p][0].centre[0] for p in ("right_support", "chest", "right_arm", "head")}
    assert x["right_support"] < x["chest"] < x["right_arm"] < x["head"]


TURNING = lab.loads("""\
title: turns and springs
tempo: 60
0 2 support place middle
2 1 right_support place high
2 1 turn right amount=1/2
2 1 left_leg forward low
3 1 support place low
4 1/2 support air
9/2 1 support place low
11/2 1/2 right_support place low
6 1/2 support air
13/2 1/2 left_support forward low
6 2 right_leg back middle
7 1 turn left amount=1/4
""")


def test_turns_sit_in_the_support_column_of_their_foot():
    lay = staff_layout(TURNING, column_width=30.0)
    turns = [g for g in lay.glyphs if g.symbol.is_turn]
    centre = lay.glyphs[0].centre[0]  # `support` spans both columns, centred on the centre line
    on_right, on_left = turns
    # Half a turn on the right foot in relevé: inner half of the right support column,
    # the relevé keeping the outer half; its pin points down (half a turn).
    xr = on_right.pieces[0][:, 0]
    rel = next(g for g in lay.glyphs if g.symbol.part == "right_support" and g.symbol.level == "high")
    assert centre < xr.min() and xr.max() <= rel.pieces[0][:, 0].min() + 1e-9
    assert on_right.pin == pytest.approx(180.0) and on_right.label == "R 1/2"
    # A quarter turn left on the left foot: the whole left support column, pin to the left.
    xl = on_left.pieces[0][:, 0]
    assert xl.max() < centre and xl.max() - xl.min() == pytest.approx(30.0 * (1 - 2 * 0.12))
    assert on_left.pin == pytest.approx(270.0) and on_left.label == "L 1/4"
    # Right turns slant down to the right: their right corners are the lower ones (larger y).
    pts = on_right.pieces[0]
    assert pts[pts[:, 0].argmax(), 1] > pts[pts[:, 0].argmin(), 1]


def test_a_front_sign_follows_every_turn(tmp_path):
    lay = staff_layout(TURNING)
    assert [(f.front, f.room) for f in lay.fronts] == [(Fraction(1, 2), "back"), (Fraction(1, 4), "right")]
    turns = [g for g in lay.glyphs if g.symbol.is_turn]
    for f, g in zip(lay.fronts, turns):
        staff_left = min(p[:, 0].min() for gl in lay.glyphs for p in gl.pieces)
        assert f.centre[0] < staff_left  # beside the staff
        top = min(p[:, 1].min() for p in g.pieces)
        assert f.centre[1] == pytest.approx(top - f.size / 2 - 2)  # just after the turn ends
    assert lay.fronts[0].pin == pytest.approx(180.0) and lay.fronts[1].pin == pytest.approx(90.0)
    root = ET.parse(render_staff(TURNING, tmp_path / "t.svg", tmp_path / "t.png")).getroot()
    signs = [g for g in root.iter(f"{SVG}g") if g.get("class") == "front-sign"]
    assert [g.get("data-room") for g in signs] == ["back", "right"]


def test_flight_is_a_gap_named_by_its_spring_form(tmp_path):
    root = ET.parse(render_staff(TURNING, tmp_path / "t.svg")).getroot()
    airs = [g for g in _symbol_groups(root) if g.get("data-direction") == "air"]
    assert [g.get("data-spring") for g in airs] == ["jump", "leap"]
    for g in airs:
        assert g.find(f"{SVG}polygon") is None
        assert g.find(f"{SVG}text").text == g.get("data-spring")


def test_levels_and_bend_marks(tmp_path):
    root = ET.parse(render_staff(PHRASE, tmp_path / "s.svg")).getroot()
    for g in _symbol_groups(root):
        poly = g.find(f"{SVG}polygon")
        level = g.get("data-level")
        fill = poly.get("fill")
        assert fill == {"high": "url(#hatch)", "middle": "white", "low": "black"}[level]
        assert (g.find(f"{SVG}circle") is not None) == (level == "middle")
        bend = g.find(f"{SVG}text")
        assert (bend is not None) == (g.get("data-bend") != "0")
        if bend is not None:
            assert bend.text == "\u00d72"


@pytest.mark.parametrize(
    "direction,n_vertices", [("place", 4), ("forward", 6), ("back", 6), ("right_forward", 4), ("left_back", 4)]
)
def test_shapes_fill_their_box(direction, n_vertices):
    pts = symbol_outline(direction, 10.0, 200.0, 40.0, 100.0, "right")
    assert len(pts) == n_vertices
    assert pts[:, 0].min() == 10.0 and pts[:, 0].max() == 40.0
    assert pts[:, 1].min() == 100.0 and pts[:, 1].max() == 200.0


def test_side_symbols_point_sideways():
    short = symbol_outline("right", 0.0, 30.0, 30.0, 0.0, "right")
    assert len(short) == 3 and tuple(short[1]) == (30.0, 15.0)  # apex at the right, mid-height
    long = symbol_outline("left", 0.0, 300.0, 30.0, 0.0, "left")
    assert len(long) == 4 and long[:, 0].min() == 0.0
    assert set(map(tuple, long[long[:, 0] == 30.0])) == {(30.0, 300.0), (30.0, 0.0)}  # straight edge outside


def test_bar_lines_follow_the_meter():
    score = Score(symbols=(Symbol(0, 7, "head", "forward", "high"),), meter=3)
    lay = staff_layout(score, beat_height=10.0)
    widths = {round(x1 - x0) for x0, y0, x1, y1, _ in lay.lines if y0 == y1}
    bars = [ln for ln in lay.lines if ln[1] == ln[3] and round(ln[2] - ln[0]) == max(widths)]
    # 3 measures of 3 beats: double lines at 0 and 9 (2 each) + bar lines at 3 and 6.
    assert len(bars) == 6
    numbers = [t[2] for t in lay.texts if t[2].isdigit()]
    assert numbers == ["1", "2", "3"]


def test_long_scores_continue_on_further_staves():
    score = Score(symbols=(Symbol(0, 3, "head", "forward", "high"), Symbol(3, 6, "right_arm", "right", "low")), meter=2)
    one = staff_layout(score, beat_height=10.0, measures_per_staff=None)
    two = staff_layout(score, beat_height=10.0, measures_per_staff=2)  # 5 measures -> 3 staves
    assert two.height < one.height and two.width > one.width
    verticals = [ln for ln in two.lines if ln[0] == ln[2]]
    assert len(verticals) == 3 * 3  # three staves of three lines
    arm = next(g for g in two.glyphs if g.symbol.part == "right_arm")
    # Beats 3-9 cross the breaks at beats 4 and 8: pieces of 1, 4 and 1 beats.
    assert [round(p[:, 1].max() - p[:, 1].min(), 6) for p in arm.pieces] == [10.0, 40.0, 10.0]
    assert arm.pieces[0][:, 0].min() < arm.pieces[1][:, 0].min() < arm.pieces[2][:, 0].min()
    assert [t[2] for t in two.texts if t[2].isdigit()] == ["1", "2", "3", "4", "5"]
    with pytest.raises(NotationError):
        staff_layout(score, measures_per_staff=0)


def test_staff_spans_place_beats_where_they_are_drawn():
    """Each staff's span puts a beat on the tick or bar line drawn for it, and a symbol's foot on its start."""
    score = Score(symbols=(Symbol(0, 3, "head", "forward", "high"), Symbol(5, 4, "right_arm", "right", "low")), meter=2)
    lay = staff_layout(score, beat_height=10.0, measures_per_staff=2)  # 5 measures: beats 0-4, 4-8, 8-10
    assert [(s.first, s.last) for s in lay.staves] == [(0, 4), (4, 8), (8, 10)]
    for span in lay.staves:
        across = [ln for ln in lay.lines if ln[1] == ln[3] and span.x_left <= ln[0] and ln[2] <= span.x_right]
        for b in range(int(span.first), int(span.last) + 1):
            assert any(abs(ln[1] - span.y(b)) < 1e-9 for ln in across), (span, b)
        centre = [ln for ln in lay.lines if ln[0] == ln[2] and span.x_left < ln[0] < span.x_right]
        assert len(centre) == 3  # the staff's three lines lie between its outer edges
    arm = next(g for g in lay.glyphs if g.symbol.part == "right_arm")
    assert arm.foot[1] == pytest.approx(lay.staves[1].y(5))
    assert lay.staves[1].x_left < arm.foot[0] < lay.staves[1].x_right


def test_empty_score_still_draws_a_staff(tmp_path):
    root = ET.parse(render_staff(Score(), tmp_path / "e.svg")).getroot()
    assert _symbol_groups(root) == []
    assert len(list(root.iter(f"{SVG}line"))) > 3


def test_a_long_staff_continues_on_png_pages_that_tile_it(tmp_path):
    import cv2

    from capture2notation.notation.staff import PAGE_STAVES, png_pages

    # one arm gesture a beat for 19 staves of one measure: three pages
    n = 2 * PAGE_STAVES + 3
    syms = tuple(Symbol(Fraction(b), Fraction(1), "right_arm", "forward", "high") for b in range(n * 2))
    score = Score.from_symbols(syms, tempo=Fraction(60), meter=2)
    lay = staff_layout(score, measures_per_staff=1)
    assert len(lay.staves) == n
    render_staff(score, tmp_path / "s.svg", tmp_path / "s.png", measures_per_staff=1)
    pages = png_pages(tmp_path / "s.png", 3)
    assert [p.name for p in pages] == ["s.png", "s-2.png", "s-3.png"]
    assert not (tmp_path / "s-4.png").exists()
    images = [cv2.imread(str(p), cv2.IMREAD_GRAYSCALE) for p in pages]
    # the pages tile the staff's width (a pixel of rounding each) at its height
    assert abs(sum(im.shape[1] for im in images) - lay.width) <= len(images)
    assert all(im.shape[0] == round(lay.height) for im in images)
    # every page carries ink: its staves' lines and symbols (white is 255)
    for im in images:
        assert (im < 128).mean() > 0.01
