"""The capture's page as a user sees it: headless Chromium at 1,000 and 1,400 px.

A short colour-marker render (12 beats at 120 bpm, one beat a measure so the
staff runs on two staves) is captured; a copy of its ``index.html`` gets a
probe script appended that, once the video has loaded, seeks the video to a
time on the second staff, clicks a row of the symbol table, and reports the
playhead, the highlighted rows and symbols, the followers' times and the
on-screen boxes (as each seek starts: headless Chromium's virtual time does not
wait for frames to decode).  The same page is screenshot (after the probe has run) and
the screenshot must show the playhead's red on the staff.

The playhead is checked against the staff's own drawing: at a symbol's first
frame it lies on the foot of that symbol's outline (the glyph geometry, not
the beat → pixel map the page script uses).
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

from capture2notation.atomic import write_text
from capture2notation.notation.formats import loads
from pipelines.capture import capture
from pipelines.capture_page import PLAYHEAD_COLOUR, index_html

pytestmark = [
    pytest.mark.slow,
    pytest.mark.browser,
]

SCORE = """\
tempo: 120
0 2 right_arm right middle
2 2 right_arm place low
4 2 left_arm left high
6 2 left_arm place low
8 2 right_arm right high
10 2 right_arm place low
"""
TEMPO = 120
FPS = 25
#: Half a frame in staff pixels (48 px a beat): how far a seek to a frame's middle may lie past a symbol's foot.
HALF_FRAME_PX = 0.5 / FPS * TEMPO / 60 * 48
#: Stroke half-widths and rounding between the outline's box and the playhead's y, pixels.
DRAW_TOL_PX = 1.5
#: A time on the second staff (beats 8-16 with one beat a measure): beat 9.
SEEK_S = 9 * 60 / TEMPO

PROBE = """<script>
window.addEventListener("load", async () => {
  const out = {};
  const videos = Array.from(document.querySelectorAll("video.capture-video"));
  const v = videos[0];
  const head = document.getElementById("playhead");
  const pane = document.getElementById("staff-pane");
  const rect = el => { const r = el.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
  const state = () => ({
    t: v.currentTime, x1: +head.getAttribute("x1"), x2: +head.getAttribute("x2"), y: +head.getAttribute("y1"),
    head: rect(head), pane: rect(pane), followers: videos.slice(1).map(f => f.currentTime),
    rows: Array.from(document.querySelectorAll("tr.now")).map(r => +r.dataset.symbol),
    glyphs: Array.from(document.querySelectorAll("#staff g.symbol.now")).map(g => g.id),
    clock: document.getElementById("now").textContent,
  });
  // The page moves the playhead as a seek starts ("seeking"): a decoded frame is not waited for.
  const seeking = () => new Promise(res => v.addEventListener("seeking", res, {once: true}));
  try {
    await Promise.all(videos.map(el => el.readyState >= 1 ? null
      : new Promise(res => el.addEventListener("loadedmetadata", res, {once: true}))));
    out.start = state();
    let started = seeking();
    v.currentTime = SEEK_S;
    await started;
    out.seek = state();
    started = seeking();
    document.getElementById("row-ROW").click();
    await started;
    out.click = state();
    const bb = document.querySelector("#sym-ROW polygon.outline").getBBox();
    out.outline = [bb.x, bb.y, bb.x + bb.width, bb.y + bb.height];
    out.video = rect(v);
    out.viewport = [window.innerWidth, window.innerHeight];
    out.staffWidth = document.getElementById("staff").getBoundingClientRect().width;
  } catch (e) { out.error = String(e); }
  const pre = document.createElement("pre");
  pre.id = "c2n-probe";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""

SCRUB_PROBE = """<script>
window.addEventListener("load", () => {
  const head = document.getElementById("playhead"), scrub = document.getElementById("scrub");
  const y0 = +head.getAttribute("y1");
  scrub.value = "1"; scrub.dispatchEvent(new Event("input"));
  const y1 = +head.getAttribute("y1");
  document.getElementById("row-1").click();
  const pre = document.createElement("pre");
  pre.id = "c2n-probe";
  pre.textContent = JSON.stringify({y0: y0, y1: y1, scrub: +scrub.value, max: +scrub.max,
    rows: Array.from(document.querySelectorAll("tr.now")).map(r => +r.dataset.symbol)});
  document.body.appendChild(pre);
});
</script>"""


def run_probe(page: Path, probe: str, tmp_path: Path, chromium, width: int, height: int) -> tuple[dict, np.ndarray]:
    """Open a copy of `page` with `probe` appended; return the probe's report and a screenshot (BGR)."""
    copy = page.with_name(f"probe_{width}_{page.name}")
    copy.write_text(page.read_text(encoding="utf-8").replace("</body>", probe + "</body>"), encoding="utf-8")
    common = chromium(
        "--hide-scrollbars",
        "--force-device-scale-factor=1",
        "--autoplay-policy=no-user-gesture-required",
        "--virtual-time-budget=8000",
        f"--window-size={width},{height}",
    )
    dom = subprocess.run(common + ["--dump-dom", copy.as_uri()], capture_output=True, text=True, timeout=60)
    m = re.search(r'<pre id="c2n-probe">(.*?)</pre>', dom.stdout, re.S)
    assert m, f"probe did not report; chromium said: {dom.stderr[-500:]}"
    found = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<"))
    assert "error" not in found, found["error"]
    shot = tmp_path / f"{page.parent.name}_{width}.png"
    subprocess.run(common + [f"--screenshot={shot}", copy.as_uri()], capture_output=True, timeout=60)
    image = cv2.imread(str(shot))
    assert image is not None, f"no screenshot at {width} px"
    return found, image


def _playhead_pixels(image: np.ndarray, box: list) -> int:
    """Pixels of the playhead's colour inside `box` (left, top, right, bottom) of a BGR screenshot."""
    rgb = np.array([int(PLAYHEAD_COLOUR[i : i + 2], 16) for i in (1, 3, 5)])
    l, t, r, b = (max(int(round(v)), 0) for v in box)
    crop = image[t:b, l:r, ::-1].astype(int)
    return int((np.abs(crop - rgb).max(axis=2) <= 40).sum())


@pytest.fixture(scope="module")
def captured(tmp_path_factory):
    """A marker render captured at one beat a measure, with a second (copied) camera's overlay."""
    from synthetic import render

    root = tmp_path_factory.mktemp("page")
    render.render_score(loads(SCORE, "lab"), root / "r", fps=FPS, size=(320, 240), style="markers", progress=False)
    res = capture(
        root / "r" / "video.mp4", root / "c", backend="markers", tempo=TEMPO, meter=1, progress=False, effort=False
    )
    # A multi-camera capture writes one overlay per camera: the page shows them all.
    side = root / "c" / "overlay_side.mp4"
    shutil.copy(root / "c" / "overlay.mp4", side)
    res = replace(res, files={**res.files, "overlay_side.mp4": side})
    write_text(root / "c" / "index.html", index_html(res))
    return res, root


@pytest.mark.parametrize("width,height", [(1000, 760), (1400, 900)])
def test_playhead_follows_the_video_and_rows_seek_it(captured, tmp_path, chromium, width, height):
    res, _ = captured
    symbols = res.score.symbols
    # The row to click: a symbol on the second staff.
    k = next(i for i, s in enumerate(symbols) if s.start >= 8)
    probe = PROBE.replace("SEEK_S", f"{SEEK_S:g}").replace("ROW", str(k))
    found, image = run_probe(res.outdir / "index.html", probe, tmp_path, chromium, width, height)
    start, seek, click = found["start"], found["seek"], found["click"]

    # Seeking moves the playhead up the first staff's beats onto the second staff (to the right).
    assert start["t"] == 0 and seek["t"] == pytest.approx(SEEK_S, abs=1e-3)
    assert seek["x1"] > start["x2"], "beat 9 is on the second staff, right of the first"
    assert seek["clock"].startswith("beat 9.00 · bar 10 · 4.50 s · frame 112")
    under = [i for i, s in enumerate(symbols) if s.start <= 9 < s.end]
    assert seek["rows"] == under and seek["glyphs"] == [f"sym-{i}" for i in under]
    # Followers play in step.
    assert seek["followers"] == [pytest.approx(SEEK_S, abs=0.05)]

    # Clicking the row seeks to the symbol's first frame; the playhead lies on its foot.
    first_frame = round(res.score.seconds(symbols[k].start) * FPS)
    assert click["t"] == pytest.approx((first_frame + 0.5) / FPS, abs=1e-3)
    assert click["followers"] == [pytest.approx(click["t"], abs=0.05)]
    assert k in click["rows"] and f"sym-{k}" in click["glyphs"]
    x0, _, x1, foot = found["outline"]
    assert click["x1"] <= x0 and click["x2"] >= x1, "the playhead spans the clicked symbol's column"
    assert foot - DRAW_TOL_PX - HALF_FRAME_PX <= click["y"] <= foot + DRAW_TOL_PX

    # The staff pane scrolled to keep the playhead on screen; the video is on screen beside it.
    vw, vh = found["viewport"]
    pl, pt, pr, pb = click["pane"]
    hl, ht, hr, hb = click["head"]
    assert pt <= ht and hb <= min(pb, vh) and pl <= hl and hr <= pr, "the whole playhead is in view"
    left, top, right, bottom = found["video"]
    assert left >= 0 and right <= vw and top >= 0 and bottom <= vh, f"video box {found['video']} off {vw}x{vh}"
    assert left >= pr, "the video is beside the staff, not under it"
    assert found["staffWidth"] > pr - pl, "the two-staff score is wider than its pane, which scrolls"

    # The screenshot shows the playhead's red inside the staff pane.
    assert image.shape[1] == width
    assert _playhead_pixels(image, click["pane"]) >= 100


def test_motion_file_page_has_a_slider_for_the_playhead(captured, tmp_path, chromium):
    _, root = captured
    res = capture(root / "r" / "truth.npz", tmp_path / "m", tempo=TEMPO, meter=1, progress=False, effort=False)
    found, image = run_probe(res.outdir / "index.html", SCRUB_PROBE, tmp_path, chromium, 1000, 760)
    # One second is two beats: the playhead moves up (y falls) by two beats of 48 px.
    assert found["y0"] - found["y1"] == pytest.approx(2 * 48, abs=0.01)
    assert found["max"] == pytest.approx((res.n_frames - 1) / FPS, abs=0.01)
    first_frame = round(res.score.seconds(res.score.symbols[1].start) * FPS)
    assert found["scrub"] == pytest.approx((first_frame + 0.5) / FPS, abs=0.01) and 1 in found["rows"]
    assert _playhead_pixels(image, [0, 0, 600, 760]) >= 100
