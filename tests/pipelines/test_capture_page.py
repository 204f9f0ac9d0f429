"""The capture page's HTML (no browser): the inline staff, the playhead, the videos, the table."""

from __future__ import annotations

import json
import re
from fractions import Fraction
from html.parser import HTMLParser
from types import SimpleNamespace

import pytest

from capture2notation.notation.formats import lab
from capture2notation.notation.staff import staff_layout, svg_text
from pipelines.capture_page import SIDE_BY_SIDE_MIN_PX, index_html, overlay_videos

SCORE = lab.loads("""\
title: page <test>
tempo: 90
meter: 2
0 1 right_arm right middle
1 3/2 left_arm forward high
5/2 1/2 right_support place low
17 1 right_arm place low
""")
FPS = 30.0


class Elements(HTMLParser):
    """Every start tag with its attributes, and the text of the ``<script>`` elements by id."""

    def __init__(self, text: str):
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict]] = []
        self.scripts: dict[str, str] = {}
        self._script: str | None = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag == "script":
            self._script = dict(attrs).get("id", "")

    def handle_endtag(self, tag):
        if tag == "script":
            self._script = None

    def handle_data(self, data):
        if self._script is not None:
            self.scripts[self._script] = self.scripts.get(self._script, "") + data

    def find(self, tag: str, **attrs) -> list[dict]:
        return [a for t, a in self.tags if t == tag and all(a.get(k) == v for k, v in attrs.items())]


def result(files=(), skipped=(), score=SCORE, track=None, **kw):
    """A CaptureResult's fields the page reads."""
    return SimpleNamespace(
        score=score,
        files={n: f"/nowhere/{n}" for n in files},
        motion=SimpleNamespace(fps=FPS),
        n_frames=700,
        kind="video" if track is not None else "bvh",
        tempo_text=" (given)",
        skipped=tuple(skipped),
        seconds={"read": 0.5},
        track=track,
        camera_estimate=None,
        camera_source="",
        **kw,
    )


def test_overlay_videos_lead_with_overlay_mp4_then_cameras_by_name():
    files = dict.fromkeys(("overlay_side.mp4", "staff.svg", "overlay_front.mp4", "overlay.mp4", "overlay.mp4x"))
    assert overlay_videos(files) == ["overlay.mp4", "overlay_front.mp4", "overlay_side.mp4"]
    assert overlay_videos({"overlay_b.mp4": 0, "overlay_a.mp4": 0}) == ["overlay_a.mp4", "overlay_b.mp4"]
    assert overlay_videos({"score.lab": 0}) == []


def test_every_overlay_is_a_video_and_the_first_leads():
    page = Elements(index_html(result(["overlay.mp4", "overlay_side.mp4", "staff.svg"], track=object())))
    videos = page.find("video")
    assert [v["src"] for v in videos] == ["overlay.mp4", "overlay_side.mp4"]
    assert all(v["class"] == "capture-video" for v in videos)
    assert "controls" in videos[0] and "controls" not in videos[1]
    assert not page.find("input", id="scrub")


def test_a_motion_file_page_has_a_slider_instead_of_a_video():
    text = index_html(result(["staff.svg"], skipped=["overlay.mp4: no video (motion file input)"]))
    page = Elements(text)
    assert not page.find("video") and page.find("input", id="scrub", type="range")
    assert "No video: the input was a motion file" in text
    assert "<h2>Not written</h2><ul><li>overlay.mp4: no video (motion file input)</li></ul>" in text


def test_the_inline_staff_is_staff_svg_with_a_playhead_at_beat_0():
    text = index_html(result())
    lay = staff_layout(SCORE)
    drawing = svg_text(lay)
    drawing = drawing[drawing.index("<svg ") : drawing.rindex("</svg>")]
    inline = re.search(r'<svg id="staff" (.*?)</svg>', text, re.S).group(1)
    assert inline.startswith(drawing.removeprefix("<svg "))
    heads = Elements(text).find("line", id="playhead")
    assert len(heads) == 1
    # Beat 0 is the staff's first double line: the lowest horizontal line of the first staff.
    y0 = max(y0 for x0, y0, x1, y1, _ in lay.lines if y0 == y1 and x0 < lay.staves[0].x_right) - 4.0
    assert float(heads[0]["y1"]) == pytest.approx(y0) == float(heads[0]["y2"])
    assert float(heads[0]["x1"]) < lay.staves[0].x_left and float(heads[0]["x2"]) > lay.staves[0].x_right
    # Every symbol is a clickable group the script finds by id.
    for i in range(len(SCORE.symbols)):
        assert f'id="sym-{i}"' in inline


def test_rows_give_start_in_bars_beats_seconds_and_frames():
    page = Elements(index_html(result()))
    rows = page.find("tr")
    by_symbol = {int(r["data-symbol"]): r for r in rows if "data-symbol" in r}
    assert sorted(by_symbol) == list(range(len(SCORE.symbols)))
    text = index_html(result())
    for i, s in enumerate(SCORE.symbols):
        seconds = float(s.start) * 60 / 90
        cells = re.search(rf'<tr id="row-{i}" data-symbol="{i}"[^>]*>(.*?)</tr>', text).group(1)
        values = re.findall(r"<td[^>]*>(.*?)</td>", cells)
        bar, beat, sec, frame, beats, what = values[:6]
        assert int(bar) == int(s.start) // 2 + 1
        assert Fraction(beat) == s.start and Fraction(beats) == s.duration
        assert float(sec) == pytest.approx(seconds, abs=0.005)
        assert int(frame) == round(seconds * FPS)
        assert what.startswith(f"{s.part} {s.direction}")


def test_page_data_maps_time_to_the_staff():
    page = Elements(index_html(result()))
    data = json.loads(page.scripts["page-data"])
    assert data["fps"] == FPS and data["tempo"] == 90 and data["meter"] == 2 and data["frames"] == 700
    # 18 beats at meter 2 is 9 measures: two staves of 8 measures (16 beats).
    assert [s[:2] for s in data["staves"]] == [[0, 16], [16, 18]]
    for (b0, b1, seek), s in zip(data["symbols"], SCORE.symbols, strict=True):
        assert (b0, b1) == (float(s.start), float(s.end))
        # The seek lands in the middle of the symbol's first frame.
        first = round(float(s.start) * 60 / 90 * FPS)
        assert seek == pytest.approx((first + 0.5) / FPS)
    summary = json.loads(page.scripts["summary"])
    assert summary == {"tempo": "90", "symbols": 4, "uncertain": 0}


def test_script_text_cannot_close_its_element():
    from pipelines.capture_page import _json_script

    out = _json_script("x", {"t": "</script><b>"})
    assert "</script><b>" not in out.removesuffix("</script>")
    assert json.loads(Elements(out).scripts["x"]) == {"t": "</script><b>"}


def test_layout_is_side_by_side_from_1000_px_and_stacked_below():
    text = index_html(result())
    assert SIDE_BY_SIDE_MIN_PX == 1000
    assert f"@media (max-width: {SIDE_BY_SIDE_MIN_PX - 1}px)" in text
    assert f'matchMedia("(min-width: {SIDE_BY_SIDE_MIN_PX}px)")' in text
    assert "OVERHANG" not in text and "MINROW" not in text and "WIDE" not in text
