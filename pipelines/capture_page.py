"""The capture's page, ``index.html``: the staff beside the video, to check a capture by eye.

The staff is inlined (the SVG of :mod:`capture2notation.notation.staff`, the
same drawing as ``staff.svg``) with a playhead line that follows the video:
the capture times frame ``k`` at ``k / fps`` seconds from the first frame and
beat ``t · tempo / 60`` at time ``t`` (:func:`capture2notation.quantise.tempo.snap`),
so beat 0 is the first frame and the video's ``currentTime`` maps to beats
with no offset.  The staff layout's :class:`~capture2notation.notation.staff_layout.StaffSpan`
places a beat on the page (long scores run on several staves, left to right).

Clicking a symbol on the staff, or its row in the symbol table, seeks the
videos to the symbol's first frame; the rows and symbols under the playhead
are highlighted, and the staff and the table scroll to keep them in view.
Every overlay the capture wrote is shown (``overlay.mp4``, and
``overlay_<camera>.mp4`` of a multi-camera capture): the first leads the
playhead, the others follow it.  A motion file has no video: a slider then
moves the playhead.

From :data:`SIDE_BY_SIDE_MIN_PX` wide up the staff and the videos sit side
by side, each column as tall as the window: the staff's column scrolls, so a
long staff never pushes the video off-screen.  Below that they are stacked.
The script is small, inline and dependency-free.
"""

from __future__ import annotations

import html
import json
import re
from pathlib import Path
from urllib.parse import quote

from capture2notation.notation.model import SYMBOL_UNCERTAIN_BELOW, Score
from capture2notation.notation.staff import staff_layout, svg_text

__all__ = ["SIDE_BY_SIDE_MIN_PX", "emotion_line", "index_html", "overlay_videos"]

#: Narrowest window, CSS pixels, with the staff and the video side by side (stacked below).
SIDE_BY_SIDE_MIN_PX = 1000
#: Colour of the playhead and of what lies under it (red: apart from the black and grey ink).
PLAYHEAD_COLOUR = "#d62728"
#: Least height of the staff-and-video row side by side, CSS pixels (room for a video and a few rows).
MIN_ROW_PX = 520
#: How far the playhead line reaches past the staff's outer columns on each side, pixels.
PLAYHEAD_OVERHANG_PX = 8.0

_OVERLAY = re.compile(r"overlay(_[A-Za-z0-9][\w.-]*)?\.mp4")


def overlay_videos(files: dict) -> list[str]:
    """The overlay videos among a capture's `files`, the leading one first.

    ``overlay.mp4`` leads when there is one; ``overlay_<camera>.mp4`` follow
    in name order.
    """
    names = sorted(n for n in files if _OVERLAY.fullmatch(n))
    return sorted(names, key=lambda n: n != "overlay.mp4")


def _num(x, places: int = 2) -> str:
    """`x` with at most `places` decimals, trailing zeros dropped (``2.5``, ``27.75``, ``3``)."""
    text = f"{float(x):.{places}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def _interval(d: dict) -> str:
    lo, hi = d["ci90"]
    return f"{d['median']:.2f} [{lo:.2f}, {hi:.2f}]"


def emotion_line(data: dict) -> str:
    """The emotion of an ``effort.json`` in words: the reading, or why it is not read."""
    if data.get("emotion_text"):
        return str(data["emotion_text"])
    emotion = data.get("emotion") or {}
    if not emotion:
        return "not read"
    return " · ".join(f"{k} {v:.0%}" for k, v in sorted(emotion.items(), key=lambda kv: -kv[1]))


def _effort_html(files: dict) -> str:
    """The Effort section: pooled estimate, emotion, plots."""
    if "effort.json" not in files:
        return ""
    data = json.loads(Path(files["effort.json"]).read_text(encoding="utf-8"))
    pooled = data.get("pooled") or {}
    rows = "".join(
        f"<tr><td>{name}</td><td>{_interval(pooled[key])}</td></tr>"
        for key, name in (("time", "Time b"), ("weight", "Weight x0"), ("space", "Space S"))
        if key in pooled
    )
    feelings = html.escape(emotion_line(data))
    converged = (
        "all converged"
        if all(m.get("converged") for m in data.get("movements", []))
        else ("some posteriors did not converge (see effort.json)")
    )
    plots = "".join(
        f'<img src="{name}" alt="{alt}">'
        for name, alt in (
            ("effort_progress.png", "progress curves with posterior bands"),
            ("effort_pooled.png", "pooled Effort posterior"),
        )
        if name in files
    )
    return f"""<h2>Laban Effort (median and 90 % interval)</h2>
<p>{pooled.get("n_movements", 0)} movements pooled, {converged}.</p>
<p class="emotion">Emotion: {feelings}.</p>
<table><tr><th>factor</th><th>estimate</th></tr>{rows}</table>
<div class="plots">{plots}</div>"""


def _first_frame(score: Score, beat, fps: float) -> int:
    """The frame at which a symbol starting at `beat` begins (nearest frame)."""
    return max(0, round(score.seconds(beat) * fps))


def _symbol_rows(score: Score, fps: float) -> str:
    """One ``<tr data-symbol=i>`` per symbol: start in beats, seconds and frames, then what it is."""
    out = []
    for i, s in enumerate(score.symbols):
        what = " ".join(x for x in (s.part, s.direction, s.level or "") if x)
        what += f" bend {s.bend}" if s.bend else ""
        what += f" amount={s.amount}" if s.amount is not None else ""
        conf = "" if s.confidence is None else f"{s.confidence:.2f}" + (" ?" if s.uncertain else "")
        cls = ' class="uncertain" title="uncertain"' if s.uncertain else ""
        out.append(
            f'<tr id="row-{i}" data-symbol="{i}"{cls}><td>{int(s.start // score.meter) + 1}</td>'
            f'<td title="{s.start}">{_num(s.start)}</td><td>{score.seconds(s.start):.2f}</td>'
            f"<td>{_first_frame(score, s.start, fps)}</td><td>{_num(s.duration)}</td>"
            f'<td class="what">{html.escape(what)}</td><td class="conf">{conf}</td></tr>'
        )
    return "\n".join(out)


def _staff(score: Score) -> tuple[str, list]:
    """The inline staff (``staff.svg``'s drawing with a playhead) and its staves as JSON rows.

    Returns
    -------
    str
        ``<svg id="staff">`` … with ``<line id="playhead">`` drawn last.
    list of list of float
        Per staff: first beat, last beat, left x, right x, y of the first
        beat, pixels per beat.
    """
    lay = staff_layout(score)
    svg = svg_text(lay)
    svg = svg[svg.index("<svg ") :].replace("<svg ", '<svg id="staff" ', 1)
    s0 = lay.staves[0]
    head = (
        f'<line id="playhead" x1="{s0.x_left - PLAYHEAD_OVERHANG_PX:.2f}" y1="{s0.y_first:.2f}" '
        f'x2="{s0.x_right + PLAYHEAD_OVERHANG_PX:.2f}" y2="{s0.y_first:.2f}" stroke="{PLAYHEAD_COLOUR}" '
        'stroke-width="2.5" stroke-linecap="round" pointer-events="none"/>'
    )
    svg = svg.replace("</svg>", head + "</svg>")
    staves = [[float(s.first), float(s.last), s.x_left, s.x_right, s.y_first, s.beat_height] for s in lay.staves]
    return svg, staves


def _videos(names: list[str]) -> str:
    if not names:
        return (
            "<p>No video: the input was a motion file. Move the playhead with the slider.</p>"
            '<input id="scrub" type="range" min="0" step="0.01" value="0" aria-label="time, seconds">'
        )
    figures = []
    for i, name in enumerate(names):
        role = "lead" if i == 0 else "follow"
        caption = f"{name} (the playhead follows it)" if i == 0 else name
        extra = " controls" if i == 0 else ""
        figures.append(
            f'<figure class="{role}"><video class="capture-video" src="{html.escape(quote(name))}"{extra} loop muted '
            f'playsinline preload="auto"></video><figcaption>{html.escape(caption)}</figcaption></figure>'
        )
    single = " single" if len(names) == 1 else ""
    return f'<div class="videos{single}">{"".join(figures)}</div>'


def _json_script(element_id: str, data) -> str:
    """`data` as a JSON ``<script>`` element (``</`` escaped so no text can end it early)."""
    text = json.dumps(data).replace("</", "<\\/")
    return f'<script type="application/json" id="{element_id}">{text}</script>'


def index_html(result) -> str:
    """The page of a capture: staff, videos and symbols side by side, then Effort and the files.

    Parameters
    ----------
    result : pipelines.capture.CaptureResult
        The capture (its score, motion frame rate, files, skipped outputs,
        tempo note, camera estimate and stage times).
    """
    score = result.score
    fps = float(result.motion.fps)
    n_uncertain = sum(s.uncertain for s in score.symbols)
    videos = overlay_videos(result.files)
    svg, staves = _staff(score)
    data = {
        "fps": fps,
        "tempo": float(score.tempo),
        "meter": score.meter,
        "frames": result.n_frames,
        "staves": staves,
        # start and end beat, and the time to seek to: the middle of the first frame.
        "symbols": [
            [float(s.start), float(s.end), (_first_frame(score, s.start, fps) + 0.5) / fps] for s in score.symbols
        ],
    }
    links = " · ".join(
        f'<a href="{html.escape(n)}">{html.escape(n)}</a>' for n in sorted(result.files) if n != "index.html"
    )
    tempo = f"{score.tempo} bpm{result.tempo_text}"
    skipped = "".join(f"<li>{html.escape(s)}</li>" for s in result.skipped)
    timing = ", ".join(f"{k} {v:.1f} s" for k, v in result.seconds.items())
    camera = ""
    if result.track is not None:
        est = result.camera_estimate
        said = est.line() if est is not None else "camera not estimated: the feet and body were seen in too few frames"
        used = (
            "the fit used the camera of the " + result.camera_source
            if result.camera_source.startswith("calibration")
            else "the fit estimated its own camera (no calibration given)"
        )
        camera = f"<p>{html.escape(said)}; {html.escape(used)}.</p>"
    summary = {"tempo": str(score.tempo), "symbols": len(score.symbols), "uncertain": n_uncertain}
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Capture: {html.escape(score.title)}</title>
<style>{_STYLE}</style></head><body>
<h1>Capture: {html.escape(score.title)}</h1>
<p>{result.n_frames} frames at {fps:g} fps · input: {html.escape(result.kind)} ·
tempo {html.escape(tempo)} · meter {score.meter} · {len(score.symbols)} symbols</p>
{camera}
<div class="row">
<div class="staff-pane" id="staff-pane">{svg}</div>
<div class="side">
{_videos(videos)}
<p id="now" class="clock" aria-live="off">beat 0 · bar 1 · 0.00 s · frame 0</p>
<p class="uncertain-count">{n_uncertain} of {len(score.symbols)} symbols uncertain (confidence below
{SYMBOL_UNCERTAIN_BELOW:g}: grey and dashed on the staff, grey with "?" in the table). Click a symbol or a
row to go there.</p>
<div class="table-box" id="table-box"><table class="symbols">
<thead><tr><th colspan="4" class="group">start</th><th rowspan="2">beats</th>
<th rowspan="2">symbol</th><th rowspan="2">conf.</th></tr>
<tr><th>bar</th><th>beat</th><th>s</th><th>frame</th></tr></thead>
<tbody>
{_symbol_rows(score, fps)}
</tbody></table></div>
</div></div>
{_effort_html(result.files)}
<h2>Files</h2><p>{links}</p>
{"<h2>Not written</h2><ul>" + skipped + "</ul>" if skipped else ""}
<p>Time: {html.escape(timing)}</p>
{_json_script("summary", summary)}
{_json_script("page-data", data)}
<script>{_SCRIPT}</script>
</body></html>
"""


_STYLE = f"""
* {{ box-sizing: border-box; }}
body {{ font-family: sans-serif; margin: 0 1.5em 1.5em; }}
h1 {{ margin: 0.5em 0 0.2em; font-size: 1.6em; }}
h1 + p, h1 + p + p {{ margin: 0.2em 0; }}
.row {{ display: flex; gap: 1.2em; align-items: stretch; height: calc(100vh - 1.5em); min-height: {MIN_ROW_PX}px;
  margin-top: 0.6em; }}
.staff-pane {{ flex: 0 1 auto; min-width: 0; overflow: auto; border: 1px solid #ccc; background: white; }}
.staff-pane svg {{ display: block; }}
.side {{ flex: 1 0 clamp(440px, 46%, 760px); min-width: 0; max-width: 960px; display: flex;
  flex-direction: column; }}
.videos {{ display: grid; gap: 0.3em 0.4em; grid-template-columns: repeat(3, 1fr); }}
.videos figure {{ margin: 0; }}
.videos figure.lead {{ grid-column: 1 / -1; }}
.videos video {{ display: block; width: 100%; object-fit: contain; background: #111; }}
.videos figure.lead video {{ max-height: 48vh; }}
.videos figure.follow video {{ max-height: 18vh; }}
.videos figcaption {{ font-size: 0.8em; color: #555; }}
.videos.single figcaption {{ display: none; }}
#scrub {{ width: 100%; }}
.clock {{ font-variant-numeric: tabular-nums; font-weight: bold; margin: 0.4em 0 0.2em; }}
.uncertain-count {{ margin: 0.2em 0 0.4em; font-size: 0.9em; }}
.table-box {{ flex: 1 1 8em; min-height: 8em; overflow: auto; border: 1px solid #ccc; }}
table {{ border-collapse: collapse; }}
td, th {{ padding: 0.1em 0.5em; border-bottom: 1px solid #ddd; text-align: left; }}
table.symbols td {{ white-space: nowrap; }}
table.symbols td.what {{ white-space: normal; }}
table.symbols {{ width: 100%; font-size: 0.85em; font-variant-numeric: tabular-nums; }}
table.symbols thead {{ position: sticky; top: 0; }}
table.symbols thead th {{ background: #f4f4f4; vertical-align: bottom; }}
table.symbols th.group {{ text-align: center; border-bottom: 1px solid #bbb; }}
table.symbols tbody tr {{ cursor: pointer; }}
table.symbols tbody tr:hover {{ background: #eef4ff; }}
tr.uncertain td {{ color: #777; font-style: italic; }}
tr.now td {{ background: #ffe9a8; }}
#staff g.symbol {{ cursor: pointer; }}
#staff g.symbol.now polygon {{ stroke: {PLAYHEAD_COLOUR}; stroke-width: 2.5; }}
.plots img {{ max-width: 48%; }}
@media (max-width: {SIDE_BY_SIDE_MIN_PX - 1}px) {{
  /* Stacked: the video, where the playhead is, the staff, then the symbols. */
  .row {{ flex-direction: column; gap: 0.4em; height: auto; min-height: 0; }}
  .side {{ display: contents; }}
  .videos {{ order: 1; }} .clock {{ order: 2; }} .staff-pane {{ order: 3; }}
  .uncertain-count {{ order: 4; }} .table-box {{ order: 5; }}
  .videos figure.lead video {{ max-height: 35vh; }}
  .staff-pane {{ flex: 0 0 auto; max-height: 55vh; }}
  .table-box {{ flex: 0 0 auto; max-height: 60vh; }}
}}
"""

# The playhead: time → beat → (staff, y); highlights, scrolling, seeking, followers in sync.
_SCRIPT = (
    """
(() => {
  const data = JSON.parse(document.getElementById("page-data").textContent);
  const videos = Array.from(document.querySelectorAll("video.capture-video"));
  const lead = videos[0] || null, followers = videos.slice(1);
  const scrub = document.getElementById("scrub");
  const head = document.getElementById("playhead");
  const pane = document.getElementById("staff-pane");
  const box = document.getElementById("table-box");
  const readout = document.getElementById("now");
  const rows = data.symbols.map((_, i) => document.getElementById("row-" + i));
  const glyphs = data.symbols.map((_, i) => document.getElementById("sym-" + i));
  const FOLLOW_DRIFT_S = 0.15;  // a follower further off than this is put back in step
  let shown = [];

  if (scrub) scrub.max = String(Math.max(data.frames - 1, 0) / data.fps);
  const now = () => (lead ? lead.currentTime : scrub ? Number(scrub.value) : 0);

  function place(beat) {
    const st = data.staves;
    let s = st[st.length - 1];
    for (const x of st) { if (beat < x[1]) { s = x; break; } }
    const b = Math.min(Math.max(beat, s[0]), s[1]);
    const y = s[4] - (b - s[0]) * s[5];
    head.setAttribute("x1", s[2] - OVERHANG); head.setAttribute("x2", s[3] + OVERHANG);
    head.setAttribute("y1", y); head.setAttribute("y2", y);
  }

  // Scroll `container` so `el` lies in the part of it on screen, at `frac` of that part's height.
  function keepInView(el, container, frac) {
    const c = container.getBoundingClientRect(), r = el.getBoundingClientRect();
    const top = Math.max(c.top, 0), bottom = Math.min(c.bottom, window.innerHeight);
    if (bottom - top < 48) return;  // the container is (nearly) off-screen: leave it
    if (r.top < top + 24 || r.bottom > bottom - 24) container.scrollTop += r.top - top - frac * (bottom - top);
    // Sideways (the staff's playhead spans one staff): centre it, or show its left end if wider.
    if (r.left < c.left || r.right > c.right) {
      container.scrollLeft += r.right - r.left < c.width ? (r.left + r.right - c.left - c.right) / 2 : r.left - c.left;
    }
  }

  function update(follow) {
    const t = now(), beat = t * data.tempo / 60;
    place(beat);
    const frame = Math.min(Math.floor(t * data.fps + 1e-6), Math.max(data.frames - 1, 0));
    const bar = Math.floor(beat / data.meter) + 1;
    readout.textContent = "beat " + beat.toFixed(2) + " · bar " + bar + " · " + t.toFixed(2) + " s · frame " + frame;
    const under = [];
    data.symbols.forEach((s, i) => { if (s[0] <= beat && beat < s[1]) under.push(i); });
    if (under.join() !== shown.join()) {
      shown.forEach(i => { rows[i].classList.remove("now"); glyphs[i] && glyphs[i].classList.remove("now"); });
      under.forEach(i => { rows[i].classList.add("now"); glyphs[i] && glyphs[i].classList.add("now"); });
      shown = under;
      if (follow && under.length) keepInView(rows[under[0]], box, 0.3);
    }
    if (follow) keepInView(head, pane, 0.6);
  }

  function seek(i) {
    const t = data.symbols[i][2];
    if (lead) lead.currentTime = t;  // the followers go with it on "seeking"
    else if (scrub) scrub.value = String(t);
    update(true);
  }

  function tick() { update(true); if (lead && !lead.paused) requestAnimationFrame(tick); }

  rows.forEach((r, i) => r.addEventListener("click", () => seek(i)));
  glyphs.forEach((g, i) => g && g.addEventListener("click", () => seek(i)));
  if (lead) {
    lead.addEventListener("play", () => { followers.forEach(v => v.play()); tick(); });
    lead.addEventListener("pause", () => followers.forEach(v => v.pause()));
    ["seeking", "seeked", "timeupdate", "loadedmetadata"].forEach(e => lead.addEventListener(e, () => update(true)));
    lead.addEventListener("timeupdate", () => followers.forEach(v => {
      if (Math.abs(v.currentTime - lead.currentTime) > FOLLOW_DRIFT_S) v.currentTime = lead.currentTime;
    }));
    lead.addEventListener("seeking", () => followers.forEach(v => { v.currentTime = lead.currentTime; }));
  }
  if (scrub) scrub.addEventListener("input", () => update(true));
  // Side by side, the row fills the rest of the first screen: staff, video and table all in view.
  const row = document.querySelector(".row");
  const wide = window.matchMedia("(min-width: WIDEpx)");
  function fit() {
    row.style.height = wide.matches ? Math.max(MINROW, window.innerHeight - row.offsetTop - 12) + "px" : "";
    update(true);
  }
  window.addEventListener("resize", fit);
  fit();
})();
""".replace("OVERHANG", f"{PLAYHEAD_OVERHANG_PX:g}")
    .replace("WIDE", str(SIDE_BY_SIDE_MIN_PX))
    .replace("MINROW", str(MIN_ROW_PX))
)
