"""staff.svg as a user sees it: a turn, a front sign and a jump, drawn by headless Chromium.

The staff is inlined in a page whose probe script reports, once loaded, the
on-screen box of every turn sign, front sign and flight; the screenshot must
show ink inside each box (the elements are drawn, not only present).
"""

from __future__ import annotations

import json
import re
import subprocess

import cv2
import numpy as np
import pytest

from capture2notation.notation import render_staff
from capture2notation.notation.formats import lab

pytestmark = [
    pytest.mark.slow,
    pytest.mark.browser,
]

SCORE = lab.loads("""\
title: turn, front, jump
tempo: 60
0 2 support place middle
2 1 right_support place high
2 1 turn right amount=1/2
2 1 left_leg forward low bend=2
3 1 support place middle
4 1 support place low
5 1/2 support air
11/2 1 support place low
0 2 right_arm right middle
""")

PROBE = """<script>
window.addEventListener("load", () => {
  const box = el => { const r = el.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; };
  const q = s => Array.from(document.querySelectorAll(s)).map(box);
  const out = document.createElement("pre");
  out.id = "c2n-probe";
  out.textContent = JSON.stringify({
    turns: q("g.part-turn"), fronts: q("g.front-sign"), springs: q("g[data-spring] text.spring"),
    rooms: Array.from(document.querySelectorAll("g.front-sign")).map(g => g.getAttribute("data-room")),
    forms: Array.from(document.querySelectorAll("g[data-spring]")).map(g => g.getAttribute("data-spring")),
  });
  document.body.appendChild(out);
});
</script>"""


def test_turn_front_sign_and_jump_are_drawn_in_chromium(tmp_path, chromium):
    svg = render_staff(SCORE, tmp_path / "staff.svg")
    inline = re.sub(r"^<\?xml[^>]*\?>", "", svg.read_text(encoding="utf-8"))
    page = tmp_path / "staff.html"
    page.write_text(f"<!doctype html><html><body style='margin:0'>{inline}{PROBE}</body></html>", encoding="utf-8")
    common = chromium("--virtual-time-budget=5000", "--hide-scrollbars", "--force-device-scale-factor=1")
    dom = subprocess.run(common + ["--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=120)
    m = re.search(r'<pre id="c2n-probe">(.*?)</pre>', dom.stdout, re.S)
    assert m, f"probe did not run; chromium said: {dom.stderr[-500:]}"
    found = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    assert len(found["turns"]) == 1 and len(found["fronts"]) == 1 and len(found["springs"]) == 1
    assert found["rooms"] == ["back"] and found["forms"] == ["jump"]
    shot = tmp_path / "staff.png"
    subprocess.run(
        common + ["--window-size=800,900", f"--screenshot={shot}", page.as_uri()], capture_output=True, timeout=120
    )
    img = cv2.imread(str(shot), cv2.IMREAD_GRAYSCALE)
    assert img is not None
    for name in ("turns", "fronts", "springs"):
        x, y, w, h = (int(round(v)) for v in found[name][0])
        assert w > 3 and h > 3, f"{name} has no size on screen"
        crop = img[max(y, 0) : y + h, max(x, 0) : x + w]
        assert crop.size and np.mean(crop < 100) > 0.03, f"no ink where the {name} should be drawn"
