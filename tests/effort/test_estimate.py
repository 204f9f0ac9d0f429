"""estimate_effort end to end on reference arcs; effort.json and c2n effort."""

import json
from fractions import Fraction

import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.body import joint_index
from capture2notation.effort import estimate_effort, progress, write_effort
from capture2notation.errors import EffortError
from capture2notation.notation import Score, Symbol, write
from capture2notation.notation.model import Effort
from synthetic.arcs import arc_motion, random_arm_score

FIELDS = {"part", "start", "duration", "time", "weight", "space", "tau", "acceptance", "converged"}


@pytest.fixture(scope="module")
def angry():
    """Three angry-like arm movements plus a held support, 4 mm joint noise."""
    eff = Effort(time=-3.51, weight=0.41, space=1.0)
    score = random_arm_score(np.random.default_rng(4), 3, tempo=79, effort=eff)
    score = score.replace(symbols=score.symbols + (Symbol(0, 4, "support", "place", "middle"),))
    joints = arc_motion(score, 25.0)
    joints = joints + 0.004 * np.random.default_rng(5).standard_normal(joints.shape)
    result = estimate_effort(joints, None, 25.0, score, rng=1)
    return score, joints, result


def test_movements_pooled_and_emotion(angry):
    _score, _, res = angry
    assert len(res.movements) == 3  # the support symbol bears no Effort
    assert all(m.posterior.converged for m in res.movements)
    b = res.pooled.posterior.summary(0)
    x0 = res.pooled.posterior.summary(1)
    assert b["median"] == pytest.approx(-3.51, abs=0.3)
    assert x0["median"] == pytest.approx(0.41, abs=0.03)
    assert res.pooled.space.median > 0.8
    assert res.tempo == 79
    assert sum(res.emotion.values()) == pytest.approx(1.0)
    assert max(res.emotion, key=res.emotion.get) == "angry"
    assert set(res.parts) == {"right_arm"} and res.parts["right_arm"].n_movements == 3


def test_effort_json_has_the_issue_fields(angry, tmp_path):
    _, _, res = angry
    paths = write_effort(res, tmp_path, plots=True, rng=0)
    data = json.loads(paths["json"].read_text())
    assert len(data["movements"]) == 3
    for m in data["movements"]:
        assert set(m) >= FIELDS
        assert m["time"]["ci90"][0] <= m["time"]["median"] <= m["time"]["ci90"][1]
        assert 0 <= m["space"]["ci90"][0] <= m["space"]["ci90"][1] <= 1
        # AR(1) residual correlation: 4 mm joint noise is white
        assert -0.5 <= m["residual_rho"]["ci90"][0] < 0.0 < m["residual_rho"]["ci90"][1] <= 0.99
    assert FIELDS - {"part", "start", "duration"} | {"tempo"} <= set(data["pooled"])
    assert set(data["emotion"]) == {"happy", "sad", "angry", "afraid"}
    for key in ("progress", "pooled"):
        assert paths[key].stat().st_size > 10_000
        assert paths[key].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_results_do_not_depend_on_worker_count():
    score = random_arm_score(np.random.default_rng(9), 2, tempo=60, effort=Effort(-2.5, 0.55, 1.0))
    joints = arc_motion(score, 25.0) + 0.003 * np.random.default_rng(2).standard_normal((1, 1, 1))
    kw = {"block": 50, "max_steps": 100}
    one = estimate_effort(joints, None, 25.0, score, rng=7, sampler_kw=kw)
    two = estimate_effort(joints, None, 25.0, score, rng=7, workers=2, sampler_kw=kw)
    for a, b in zip(one.movements, two.movements):
        np.testing.assert_array_equal(a.posterior.samples, b.posterior.samples)
    assert not any(m.posterior.converged for m in one.movements)  # 100 steps: honestly unconverged
    assert json.dumps(one.to_dict()) == json.dumps(two.to_dict())


def test_chunked_sampling_keeps_order_and_does_not_depend_on_workers(monkeypatch):
    from capture2notation.effort import estimate as est

    monkeypatch.setattr(est, "CHUNK", 2)  # 4 movements + pooled sets: several chunks
    score = random_arm_score(np.random.default_rng(3), 4, tempo=90, effort=Effort(-3.2, 0.45, 1.0))
    joints = arc_motion(score, 25.0) + 0.003 * np.random.default_rng(6).standard_normal((1, 1, 1))
    kw = {"block": 50, "max_steps": 150}
    one = estimate_effort(joints, None, 25.0, score, rng=2, sampler_kw=kw)
    two = estimate_effort(joints, None, 25.0, score, rng=2, workers=2, sampler_kw=kw)
    assert json.dumps(one.to_dict()) == json.dumps(two.to_dict())
    # each movement's posterior belongs to its own curve (order kept through the chunks)
    for m in one.movements:
        med = np.median(m.curve.s[np.abs(m.curve.tau - 0.5) < 0.1])
        assert abs(med - progress(0.5, m.posterior.summary(0)["median"], m.posterior.summary(1)["median"])) < 0.05


def test_unmeasurable_movements_are_skipped_with_a_reason():
    score = Score(
        symbols=(Symbol(0, 1, "right_arm", "forward", "middle"), Symbol(3, 2, "left_arm", "right", "high")),
        tempo=Fraction(60),
    )
    joints = arc_motion(score, 25.0)[:60]  # the second movement runs past the capture
    joints[:, joint_index("left_wrist")] = np.nan
    res = estimate_effort(joints, None, 25.0, score, rng=0)
    assert len(res.movements) == 1
    assert res.skipped[0]["part"] == "left_arm" and "outside the capture" in res.skipped[0]["reason"]
    assert res.pooled is not None and res.parts == {}
    with pytest.raises(EffortError, match="rng"):
        estimate_effort(joints, None, 25.0, score, rng=None)


def test_c2n_effort_command(angry, tmp_path):
    from pipelines.cli import main

    score, joints, _ = angry
    t = np.arange(len(joints)) / 25.0
    conf = np.ones(joints.shape[:2])
    np.savez(tmp_path / "capture.npz", joints=joints, confidence=conf, fps=np.float64(25.0), times=t)
    write(score, tmp_path / "score.lab")
    out = CliRunner().invoke(main, ["effort", str(tmp_path), "--workers", "1", "--no-plots"])
    assert out.exit_code == 0, out.output
    data = json.loads((tmp_path / "effort.json").read_text())
    assert data["pooled"]["tempo"] == 79
    assert "angry" in out.output
    (tmp_path / "capture.npz").unlink()
    out = CliRunner().invoke(main, ["effort", str(tmp_path)])
    assert out.exit_code == 2 and "capture.npz" in out.output


def test_a_long_clip_in_passages_keeps_the_phrase_effort():
    # Eight movements of one Effort sampled in passages of about two
    # movements: each passage pooled, the phrase their consensus, which must
    # still hold the performed Effort (as the one-passage estimate does).
    from capture2notation.effort.passages import KEEP_DRAWS

    eff = Effort(time=-3.2, weight=0.45, space=1.0)
    score = random_arm_score(np.random.default_rng(11), 8, tempo=90, effort=eff)
    joints = arc_motion(score, 25.0)
    joints = joints + 0.004 * np.random.default_rng(12).standard_normal(joints.shape)
    whole = estimate_effort(joints, None, 25.0, score, rng=3)
    parts = estimate_effort(joints, None, 25.0, score, rng=3, passage_s=float(score.seconds(2)))
    assert not whole.passages and len(parts.passages) >= 3
    assert sum(p.pooled.n_movements for p in parts.passages) == len(parts.movements) == 8
    assert all(m.posterior.samples.shape[0] <= KEEP_DRAWS for m in parts.movements)
    for res in (whole, parts):
        b, x0 = res.pooled.posterior.summary(0), res.pooled.posterior.summary(1)
        assert b["ci90"][0] <= eff.time <= b["ci90"][1]
        assert x0["ci90"][0] <= eff.weight <= x0["ci90"][1]
    data = parts.to_dict()
    assert len(data["passages"]) == len(parts.passages)
    assert data["passages"][0]["start_s"] < data["passages"][-1]["start_s"]


def test_chunks_share_the_work_evenly_whatever_the_job_order(monkeypatch):
    # one large pooled set and many small movements: the pooled set gets a
    # chunk's worth of work to itself, not a round-robin share of movements on top
    from capture2notation.effort import estimate as est

    seen = []
    monkeypatch.setattr(
        est, "_sample_job", lambda args: seen.append([len(d[0]) for d in args[0]]) or [None] * len(args[0])
    )
    jobs = [(np.zeros(20),)] * 11 + [(np.zeros(200),)]
    out = est._sample_all(jobs, np.random.default_rng(0), 1, {}, chunk=6)
    assert len(out) == 12 and len(seen) == 2
    loads = sorted(sum(c) for c in seen)
    assert loads == [200, 220]  # round-robin would give 120 and 300
