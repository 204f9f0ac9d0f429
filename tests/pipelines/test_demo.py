"""``c2n demo``: the whole loop on a built-in phrase."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from capture2notation.compare.agreement import agreement_cells
from capture2notation.io.truth import read_truth
from capture2notation.notation.formats import read
from pipelines.cli import main
from pipelines.commands import demo as demo_mod
from synthetic.phrases import builtin_phrases


def _links(page: Path) -> list[str]:
    return re.findall(r'(?:href|src)="([^"#]+)"', page.read_text(encoding="utf-8"))


@pytest.mark.slow
@pytest.mark.model
def test_demo_closes_the_loop_on_the_port_de_bras(tmp_path, pose_model_path):
    (res,) = demo_mod.run_demo(tmp_path, phrases=("port_de_bras",), effort=False, progress=False)
    folder = tmp_path / "port_de_bras"
    original = builtin_phrases()["port_de_bras"]
    assert read(folder / "render" / "score.lab") == original
    assert read_truth(folder / "render" / "truth.npz").n_frames > 100
    captured = read(folder / "capture" / "score.lab")
    assert res.symbols == (len(original.symbols), len(captured.symbols))
    # The fitted limbs follow the dancer's: BlazePose + fit are within ~10° at 640x480.
    assert res.limb_error_deg < 10.0
    assert 0.0 <= res.symbol_agreement <= 1.0 and math.isfinite(res.mpjpe_mm)
    # The differences listed are exactly the cells the agreement misses.
    cells = agreement_cells(original, captured)
    assert len(res.differences) == sum(c.ref != c.cand for c in cells)
    assert res.symbol_agreement == pytest.approx(1.0 - len(res.differences) / len(cells))
    # Every page the demo writes links only to files that exist.
    for page in (tmp_path / "index.html", folder / "capture" / "index.html", folder / "score" / "report.html"):
        for link in _links(page):
            assert (page.parent / link).exists(), (page, link)


def test_demo_command_prints_the_figures_and_where_files_are(tmp_path, monkeypatch):
    calls = {}

    def fake_run(outdir, **kw):  # the loop itself is tested above; here the command's wiring
        calls.update(kw, outdir=outdir)
        return [
            demo_mod.DemoResult(p, Path(outdir) / p, (3, 4), 0.75, 0.25, (64.0, 64.0), 4.5, 120.0, {})
            for p in kw["phrases"]
        ]

    monkeypatch.setattr(demo_mod, "run_demo", fake_run)
    res = CliRunner().invoke(main, ["demo", "-o", str(tmp_path), "--phrase", "all", "--size", "80x60", "--no-effort"])
    assert res.exit_code == 0, res.output
    assert calls["size"] == (80, 60) and calls["effort"] is False and calls["phrases"] == demo_mod.DEMO_PHRASES
    for p in demo_mod.DEMO_PHRASES:
        assert f"{p}: symbol agreement 75%" in res.output
        assert str(tmp_path / p / "capture") in res.output
    assert str(tmp_path.resolve() / "index.html") in res.output


def test_demo_page_lists_where_each_capture_differs(tmp_path):
    diff = (("right_arm", 4.0, "right_forward low", "right low"),)
    results = [
        demo_mod.DemoResult("a", tmp_path / "a", (3, 3), 0.9, 0.0, (64.0, 64.0), 4.5, 120.0, {}, diff),
        demo_mod.DemoResult("b", tmp_path / "b", (3, 3), 1.0, 0.0, (64.0, 64.0), 4.5, 120.0, {}),
    ]
    page = demo_mod.index_html(results)
    assert "<h2>a: where the capture differs</h2>" in page
    assert "<td>right_arm</td><td>4</td><td>right_forward low</td><td>right low</td>" in page
    assert "<h2>b</h2><p>The captured score agrees with the original on every beat.</p>" in page


def test_demo_rejects_an_unknown_phrase(tmp_path):
    res = CliRunner().invoke(main, ["demo", "-o", str(tmp_path), "--phrase", "swan_lake"])
    assert res.exit_code == 2
    assert "swan_lake" in res.output and "port_de_bras" in res.output
