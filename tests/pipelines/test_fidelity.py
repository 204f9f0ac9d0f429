"""The fidelity study: configuration, grid, one job, determinism, resuming, Dask."""

import numpy as np
import pytest

from capture2notation.errors import PipelineError
from pipelines.fidelity.conditions import (
    Condition,
    Job,
    Performance,
    build_conditions,
    phrase_complexity,
    take_variation,
)
from pipelines.fidelity.config import StudyConfig, load_config, quick
from pipelines.fidelity.measure import builtin_scores, capture, kept_frames, measure, perform
from pipelines.fidelity.runner import run_condition, run_study


def test_config_from_toml_and_errors(tmp_path):
    p = tmp_path / "study.toml"
    p.write_text('seed = 7\nframe_rates = [25, 8.33]\nimage_sizes = [[220, 175]]\n[baseline]\nview = "side"\n')
    cfg = load_config(p)
    assert cfg.seed == 7 and cfg.frame_rates == (25, 8.33) and cfg.image_sizes == ((220, 175),)
    assert cfg.baseline["view"] == "side" and cfg.baseline["image_size"] == (640, 480)
    p.write_text("sede = 7\n")
    with pytest.raises(PipelineError, match=r"unknown setting.*sede"):
        load_config(p)
    p.write_text("seed = [\n")
    with pytest.raises(PipelineError, match="not valid TOML"):
        load_config(p)
    with pytest.raises(PipelineError, match="takes"):
        StudyConfig(takes=1)
    with pytest.raises(PipelineError, match=r"views .*'top'"):
        StudyConfig(views=("top",))
    for bad in ("front", "front+front", "front+top", ""):
        with pytest.raises(PipelineError, match=r"cameras .*two or more views"):
            StudyConfig(cameras=(bad,))


def test_default_grid_one_factor_at_a_time():
    conds = build_conditions(StudyConfig())
    assert conds[0].factor == "baseline"
    assert len({c.params() for c in conds}) == len(conds)  # no duplicate recordings
    rates = {(c.frame_rate, c.resampling) for c in conds if c.factor in ("frame_rate", "baseline")}
    assert rates == {
        ("25", "keyframe"),
        ("25/2", "keyframe"),
        ("25/2", "naive"),
        ("25/3", "keyframe"),
        ("25/3", "naive"),
        ("5", "keyframe"),
        ("5", "naive"),
    }
    # 1 baseline + 6 reduced rates + 3 other sizes + 2 other views + 3 camera sets + 2 compressions + 2 noises
    assert len(conds) == 19
    assert [c.views for c in conds if c.factor == "cameras"] == [
        ("front", "side"),
        ("45", "-45"),
        ("front", "45", "side"),
    ]
    q = build_conditions(quick(StudyConfig(), ("a", "b", "c")))
    assert len(q) < len(conds)


def test_complexity_and_take_variation():
    scores = builtin_scores()
    comp = phrase_complexity(scores)
    # Terciles of the phrases by complexity: each class occurs.
    assert set(comp.values()) == {"easy", "medium", "hard"} and len(comp) == len(scores)
    p = Performance("figure7", comp["figure7"], "sad", 0, "test")
    a, b = take_variation(p, 0), take_variation(p, 0)
    assert a == b
    other = take_variation(Performance("figure7", comp["figure7"], "sad", 1, "test"), 0)
    assert other != a
    assert 30 < float(a["tempo"]) < 45  # sad's 37 bpm, varied by a few percent


def perfect_capture(motion, kept, cond, rng):
    """A capture that sees the kept frames exactly."""
    j = motion.joints()
    out = np.full_like(j, np.nan)
    out[kept] = j[kept]
    conf = np.zeros(j.shape[:2])
    conf[kept] = 1.0
    return out, conf


def cond(rate, method):
    return Condition("frame_rate", rate, method, 320, 240, "front", 0, 0.0)


def test_keyframe_resampling_keeps_key_poses_exactly():
    perf = Performance("port_de_bras", "hard", "happy", 0, "test")
    full = run_condition(Job(cond("25", "keyframe"), perf), 0, perfect_capture, bootstrap=0)
    assert full["error"] == ""
    assert full["symbol_accuracy"] == 1.0 and full["mpjpe_mm"] == pytest.approx(0.0, abs=1e-9)
    assert full["timing_error_s"] == pytest.approx(0.0, abs=1e-9)
    kf = run_condition(Job(cond("5", "keyframe"), perf), 0, perfect_capture, bootstrap=0)
    naive = run_condition(Job(cond("5", "naive"), perf), 0, perfect_capture, bootstrap=0)
    assert kf["angle_error_deg"] == pytest.approx(0.0, abs=1e-6)  # key frames are never culled
    assert naive["angle_error_deg"] > 1.0
    assert kf["kept_frames"] < full["kept_frames"] / 3


def test_failed_capture_is_reported_not_invented():
    def blind(motion, kept, cond_, rng):
        j = motion.joints()
        return np.full_like(j, np.nan), np.zeros(j.shape[:2])

    row = run_condition(Job(cond("25", "keyframe"), Performance("figure7", "medium", "sad", 0, "test")), 0, blind)
    assert "no joint" in row["error"] and "symbol_accuracy" not in row


def test_kept_frames_contain_key_frames():
    score, motion = perform(Performance("figure7", "medium", "angry", 0, "test"), 0, 25.0)
    kept = kept_frames(cond("25/3", "keyframe"), score, motion.n_frames, motion.fps)
    ends = {e[2] for e in motion.events}
    assert ends <= set(kept.tolist()) | {motion.n_frames}


def test_same_seed_same_results_and_resume(tmp_path, tiny_study):
    cfg = StudyConfig(**tiny_study)
    a = run_study(cfg, tmp_path / "a", workers=1, progress=False)
    text = (tmp_path / "a" / "results.csv").read_text()
    jobs = {k: v for k, v in a.summary["jobs"].items() if k != "job_seconds"}
    assert jobs == {"total": 12, "ran": 12, "cached": 0, "failed": 0}
    assert len(text.strip().splitlines()) == 13
    again = run_study(cfg, tmp_path / "a", workers=1, progress=False)
    assert again.summary["jobs"]["ran"] == 0 and again.summary["jobs"]["cached"] == 12
    assert (tmp_path / "a" / "results.csv").read_text() == text
    b = run_study(cfg, tmp_path / "b", workers=2, progress=False)
    assert (tmp_path / "b" / "results.csv").read_text() == text
    assert b.summary["experiment1"][0]["n"] == 2 * 3 + 1 * 2  # 2 same pairs x3, 1 different pair x2
    # Another seed gives other takes and other jitter.
    job = Job(build_conditions(cfg)[0], Performance("figure7", "medium", "sad", 0, "test"))
    r0, r1 = run_condition(job, 0, "truth", bootstrap=0), run_condition(job, 1, "truth", bootstrap=0)
    assert r0["tempo_true"] != r1["tempo_true"] and r0["mpjpe_mm"] != r1["mpjpe_mm"]


@pytest.mark.slow
def test_dask_cluster_gives_the_same_results(tmp_path, tiny_study):
    distributed = pytest.importorskip("dask.distributed")
    cfg = StudyConfig(**{**tiny_study, "emotions": ("happy", "angry"), "frame_rates": (25,)})
    run_study(cfg, tmp_path / "local", workers=1, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        dask = run_study(cfg, tmp_path / "dask", scheduler=cl.scheduler_address, progress=False)
    assert dask.summary["jobs"]["ran"] == 8
    assert (tmp_path / "dask" / "results.csv").read_text() == (tmp_path / "local" / "results.csv").read_text()


def test_unreachable_scheduler_is_a_one_line_error(tmp_path, tiny_study):
    cfg = StudyConfig(**tiny_study)
    with pytest.raises(PipelineError, match="Dask scheduler"):
        run_study(cfg, tmp_path, scheduler="tcp://127.0.0.1:9", progress=False, connect_timeout=2)


def _line(factor, condition, accuracy, percent, trials=72):
    return {
        "factor": factor,
        "condition": condition,
        "jobs": 6,
        "failed": 0,
        "symbol_accuracy": accuracy,
        "angle_error_deg": 5.0,
        "timing_error_s": 0.05,
        "percent_correct": percent,
        "trials": trials,
    }


def test_conclusions_judge_the_observer_against_the_experts_with_a_binomial_test():
    from pipelines.fidelity.report import conclusions

    base = "25 Hz keyframe, 640x480, front, q=none, noise=0"
    table = [
        _line("baseline", base, 0.90, 80.0),
        # 55 of 72 (76.4 %) is below 78.70 % but well within chance: sufficient.
        _line("view", "25 Hz keyframe, 640x480, 45, q=none, noise=0", 0.88, 100 * 55 / 72),
        # 45 of 72 (62.5 %): p ≈ 0.001 below the experts: not sufficient.
        _line("view", "25 Hz keyframe, 640x480, side, q=none, noise=0", 0.90, 100 * 45 / 72),
        # Symbols 10 points below the baseline: not sufficient whatever the observer.
        _line("noise", "25 Hz keyframe, 640x480, front, q=none, noise=5", 0.80, 90.0),
    ]
    text = " ".join(conclusions(table, {}))
    assert "Viewpoint: sufficient — front, 45. Not sufficient — side (symbols 90%, observer 62 %)" in text
    assert "Pixel noise: sufficient — noise=0. Not sufficient — noise=5" in text


def test_a_scheduler_without_dask_says_which_extra(tmp_path, tiny_study, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if not installed
    cfg = StudyConfig(**tiny_study)
    with pytest.raises(PipelineError, match=r"capture2notation\[cluster\]"):
        run_study(cfg, tmp_path, scheduler="tcp://127.0.0.1:9", progress=False, connect_timeout=2)


def test_jobs_are_scheduled_longest_first_by_beats_and_pixels():
    """Longer phrases first; on the video path larger images first; the keypoint path ignores the image size."""
    from dataclasses import replace

    from pipelines.fidelity.runner import _job_cost

    scores = builtin_scores()
    by_beats = sorted(scores, key=lambda n: float(scores[n].duration))
    short, long_ = by_beats[0], by_beats[-1]
    small = cond("25", "keyframe")
    large = replace(small, width=1280, height=720)

    def job(phrase, c):
        return Job(c, Performance(phrase, "medium", "sad", 0, "test"))

    assert _job_cost("video", job(short, large), scores) > _job_cost("video", job(short, small), scores)
    assert _job_cost("keypoints", job(short, large), scores) == _job_cost("keypoints", job(short, small), scores)
    assert _job_cost("keypoints", job(long_, small), scores) > _job_cost("keypoints", job(short, small), scores)


@pytest.mark.parametrize("noise", [0.0, 4.0])
def test_video_path_holds_kept_frames_and_noises_every_frame(monkeypatch, noise):
    """The frames written for the capture: one per source frame, a held frame repeats its image unless noised."""
    from capture2notation.body import JOINTS
    from pipelines.fidelity import measure as measure_mod

    written, seen = [], {}

    class Writer:
        def __init__(self, path, fps, size):
            seen["size"] = size

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def write(self, img):
            written.append(img.astype(int))

    def fake_capture(video, outdir, **kw):
        seen["threads"] = kw["threads"]
        outdir.mkdir()
        J, T = len(JOINTS), len(written)
        np.savez(outdir / "capture.npz", joints=np.zeros((T, J, 3)), confidence=np.ones((T, J)))

    monkeypatch.setattr("capture2notation.io.video.VideoWriter", Writer)
    monkeypatch.setattr("pipelines.capture.capture", fake_capture)
    score, motion = perform(Performance("figure7", "medium", "happy", 0, "test"), 0, 25.0)
    c = Condition("frame_rate", "5", "naive", 160, 120, "front", 0, noise)
    kept = kept_frames(c, score, motion.n_frames, motion.fps)
    joints, conf = measure_mod.capture("video", motion, kept, c, np.random.default_rng(0), threads=1)
    assert len(written) == motion.n_frames and seen == {"size": (160, 120), "threads": 1}
    held = sorted(set(range(1, motion.n_frames)) - set(kept.tolist()))
    diffs = [np.abs(written[i] - written[i - 1]).mean() for i in held]
    if noise == 0:
        assert max(diffs) == 0.0
    else:  # mean |difference| of two independent N(0, 4²) pixels is 4·2/√π ≈ 4.5 (less where clipped)
        assert 3.5 < float(np.mean(diffs)) < 5.0
    assert conf[kept].all() and not conf[held].any() and np.isnan(joints[held]).all()


@pytest.mark.slow
def test_video_path_reads_the_smallest_default_size_with_an_odd_height(pose_model_path):
    """220×175 (the default grid's smallest size) cannot be H.264 yuv420p; the job still runs."""
    c = Condition("image_size", "25", "keyframe", 220, 175, "front", 0, 0.0)
    row = run_condition(Job(c, Performance("figure7", "medium", "happy", 0, "test")), 0, "video", bootstrap=0)
    assert row["error"] == ""
    assert np.isfinite(row["angle_error_deg"]) and 0.0 <= row["symbol_accuracy"] <= 1.0


def test_auto_capture_is_the_video_path_beside_keypoints_and_quick_keeps_it_fast():
    from pipelines.fidelity.runner import resolve_capture

    assert resolve_capture("auto") == ("video", "keypoints")
    assert quick(StudyConfig(), ("a", "b")).capture == "keypoints"
    assert quick(StudyConfig(capture=("auto", "truth")), ("a", "b")).capture == ("keypoints", "truth")
    assert quick(StudyConfig(capture="video"), ("a", "b")).capture == "video"


@pytest.mark.parametrize("mode", ["truth", "keypoints"])
def test_a_second_camera_buys_the_depth_one_side_view_lacks(mode):
    """The same take seen from the side, and from the side and the front at once
    (calibrated, triangulated): the limb angles of the side view alone are off
    by tens of degrees on the keypoint path, two cameras bring them near the
    front view's."""
    perf = Performance("figure7", "medium", "happy", 0, "test")
    score, motion = perform(perf, 3, 25.0)
    errors = {}
    for view in ("front", "side", "front+side"):
        cond = Condition("cameras", "25", "keyframe", 640, 480, view, 0, 0.0)
        kept = kept_frames(cond, score, motion.n_frames, 25.0)
        joints, conf = capture(mode, motion, kept, cond, np.random.default_rng(0))
        errors[view] = measure(score, motion, joints, conf, kept, np.random.default_rng(0), 0)["angle_error_deg"]
    # Pixel jitter of 1 px moves a limb by about a degree; the side view's depth
    # guesses by far more.
    assert errors["front+side"] < 5.0
    if mode == "keypoints":
        assert errors["side"] > 2 * errors["front+side"]


def test_conclusions_say_what_more_cameras_buy_in_limb_angle():
    from pipelines.fidelity.report import conclusions

    base = "25 Hz keyframe, 640x480, front, q=none, noise=0"
    two = dict(_line("cameras", "25 Hz keyframe, 640x480, front+side, q=none, noise=0", 0.95, 80.0))
    two["angle_error_deg"] = 2.5
    text = " ".join(conclusions([_line("baseline", base, 0.90, 80.0), two], {}))
    assert "Calibrated cameras: sufficient — front, front+side." in text
    assert "Limb angle error: front 5.0°, front+side 2.5°" in text
