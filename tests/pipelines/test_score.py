"""``c2n score``: loading either side, alignment, metrics, summary and report."""

import json
from fractions import Fraction

import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.errors import PipelineError
from capture2notation.notation import formats
from pipelines.cli import main
from pipelines.score import compare_sides, load_side, run_score
from synthetic.interpret import interpret

PHRASE = """title: test phrase
tempo: 60
meter: 4
# start duration part direction level
0 1 right_arm forward middle
1 1 right_arm right high
0 2 left_arm left middle
2 1 head right_forward high
"""


@pytest.fixture
def lab(tmp_path):
    p = tmp_path / "phrase.lab"
    p.write_text(PHRASE)
    return p


def test_score_against_itself_is_perfect(lab, tmp_path):
    summ = run_score(lab, lab, tmp_path / "out")
    assert summ["alignment"]["method"] == "tempo"
    assert summ["symbol_agreement"] == 1.0
    assert summ["mpjpe_mm"] == pytest.approx(0.0, abs=1e-6)
    assert summ["pa_mpjpe_mm"] == pytest.approx(0.0, abs=1e-6)
    assert summ["verdicts"] == {"match": 4}
    assert all(t["total"] == 0 for t in summ["sign_tests"][:1])  # no timing differences at all
    assert summ["effort_differences"]["time"]["consistent"]
    on_disk = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert on_disk["symbol_agreement"] == 1.0
    html = (tmp_path / "out" / "report.html").read_text()
    assert "plots/key_poses.png" in html and (tmp_path / "out" / "plots" / "key_poses.png").stat().st_size > 1000


def test_slower_candidate_is_late_but_same_symbols(lab, tmp_path):
    slow = tmp_path / "slow.lab"
    slow.write_text(PHRASE.replace("tempo: 60", "tempo: 40"))
    cand, ref = load_side(slow), load_side(lab)
    res = compare_sides(cand, ref)
    gest = [m for m in res["movements"] if m.verdict != "n/a"]
    assert all(m.agree for m in gest)
    # Tempo 40 vs 60: each arrival at beat b comes 0.5·b s later.
    for m in gest:
        beat = float(ref.score.symbols[m.index].end)
        assert m.timing_offset == pytest.approx(0.5 * beat, abs=0.09)
    late = res["sign_tests"][0]
    assert late.positive == len(gest) and late.negative == 0
    assert res["effort"]["tempo"]["difference"] == pytest.approx(-20.0)


def test_capture_directory_uses_dtw(lab, tmp_path):
    score = formats.read(lab)
    motion = interpret(score.replace(tempo=Fraction(50)), fps=25)
    cap = tmp_path / "cap"
    cap.mkdir()
    j = motion.joints()
    rng = np.random.default_rng(0)
    noisy = j + rng.normal(scale=0.005, size=j.shape)
    np.savez(cap / "capture.npz", joints=noisy, confidence=np.ones(j.shape[:2]), fps=np.float64(25.0))
    formats.write(score.replace(tempo=Fraction(50)), cap / "score.lab")
    side = load_side(cap)
    assert side.kind == "capture" and side.joints.shape == j.shape
    res = compare_sides(side, load_side(lab))
    assert res["alignment"].method == "dtw"
    gest = [m for m in res["movements"] if m.verdict != "n/a"]
    assert np.mean([m.agree for m in gest]) >= 0.75
    assert np.nanmean(res["pa_mpjpe_mm"]) < 30.0


def test_missing_input_is_a_one_line_error(lab, tmp_path):
    with pytest.raises(PipelineError, match="no such file"):
        load_side(tmp_path / "nope.lab")
    r = CliRunner().invoke(main, ["score", str(lab), str(tmp_path), "-o", str(tmp_path / "o")])
    assert r.exit_code == 2 and "c2n: error:" in r.output


def test_cli_score(lab, tmp_path):
    r = CliRunner().invoke(main, ["score", str(lab), str(lab), "-o", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    assert "symbol agreement 100%" in r.output


def test_truth_sidecar_against_its_score(lab, tmp_path):
    from synthetic.render import job

    out = job.render_score(formats.read(lab), tmp_path / "render", size=(96, 72), style="stick", progress=False)
    truth = load_side(out / "truth.npz")
    assert truth.kind == "truth" and truth.score is not None
    res = compare_sides(truth, load_side(lab))
    gest = [m for m in res["movements"] if m.verdict != "n/a"]
    assert all(m.verdict == "match" for m in gest)
    assert np.nanmax(res["pa_mpjpe_mm"]) < 1.0
