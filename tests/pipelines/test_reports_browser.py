"""The reports as a user sees them: opened in headless Chromium, every plot loaded.

Chromium is driven from the command line (``--dump-dom``, ``--screenshot``).
A copy of each report gets a probe script appended that lists, once the page
has loaded, every ``<img>`` with its natural size; a plot that failed to load
has width 0.
"""

import json
import re
import subprocess
from pathlib import Path

import pytest

from pipelines.fidelity import StudyConfig, run_fidelity_study
from pipelines.score import run_score

pytestmark = [
    pytest.mark.slow,
    pytest.mark.browser,
]

PROBE = """<script>
window.addEventListener("load", () => {
  const imgs = Array.from(document.images).map(i => [i.getAttribute("src"), i.complete, i.naturalWidth, i.naturalHeight]);
  const out = document.createElement("pre");
  out.id = "c2n-probe";
  out.textContent = JSON.stringify({imgs: imgs, title: document.title, h2: document.querySelectorAll("h2").length});
  document.body.appendChild(out);
});
</script>"""


def open_in_chromium(report: Path, tmp_path: Path, chromium) -> dict:
    """Load `report` (with the probe) in headless Chromium; return the probe's findings."""
    probe = report.with_name("probe_" + report.name)
    probe.write_text(report.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"), encoding="utf-8")
    common = chromium("--disable-quic", "--virtual-time-budget=10000")
    dom = subprocess.run(common + ["--dump-dom", probe.as_uri()], capture_output=True, text=True, timeout=120)
    m = re.search(r'<pre id="c2n-probe">(.*?)</pre>', dom.stdout, re.S)
    assert m, f"probe did not run; chromium said: {dom.stderr[-500:]}"
    found = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    shot = tmp_path / (report.stem + ".png")
    subprocess.run(
        common + ["--window-size=1200,2400", f"--screenshot={shot}", report.as_uri()], capture_output=True, timeout=120
    )
    found["screenshot_bytes"] = shot.stat().st_size if shot.exists() else 0
    return found


def check_all_images(found: dict, expected: set[str]):
    srcs = {src for src, *_ in found["imgs"]}
    assert expected <= srcs, f"missing plots: {expected - srcs}"
    for src, complete, w, h in found["imgs"]:
        assert complete and w > 100 and h > 100, f"plot {src} did not load ({w}x{h})"
    assert found["screenshot_bytes"] > 20_000  # a rendered page, not a blank one


def test_score_report_in_chromium(tmp_path, chromium):
    lab = tmp_path / "p.lab"
    lab.write_text("tempo: 60\n0 1 right_arm forward middle\n1 1 left_arm left high\n")
    slow = tmp_path / "slow.lab"
    slow.write_text("tempo: 45\n0 1 right_arm forward middle\n1 1 left_arm left middle\n")
    run_score(slow, lab, tmp_path / "score")
    found = open_in_chromium(tmp_path / "score" / "report.html", tmp_path, chromium)
    check_all_images(found, {"plots/key_poses.png", "plots/errors.png", "plots/effort.png"})
    assert found["title"].startswith("Score:") and found["h2"] >= 4


def test_fidelity_report_in_chromium(tmp_path, chromium):
    cfg = StudyConfig(
        phrases=("figure7",),
        emotions=("happy", "sad"),
        takes=2,
        training_takes=2,
        capture="truth",
        frame_rates=(25, 5),
        resampling=("naive",),
        image_sizes=((220, 175), (640, 480)),
        views=("front",),
        cameras=("front+side",),
        compression=(0,),
        noise=(0.0,),
        bootstrap=3,
    )
    run_fidelity_study(cfg, tmp_path / "study", workers=1, progress=False)
    found = open_in_chromium(tmp_path / "study" / "report.html", tmp_path, chromium)
    check_all_images(
        found,
        {
            "plots/fig313_complexity.png",
            "plots/fig314_same_pairs.png",
            "plots/fig315_different_pairs.png",
            "plots/fig316_frame_rate.png",
            "plots/recovery_frame_rate.png",
            "plots/factor_image_size.png",
            "plots/factor_cameras.png",
        },
    )
    html = (tmp_path / "study" / "report.html").read_text()
    assert "78.70" in html and "Conclusions" in html
