"""The fidelity study under abuse: corrupt or foreign cache files, bad config values, Ctrl-C, kill."""

import json
import logging
import os
import signal
import subprocess
import sys
import time

import pytest
from click.testing import CliRunner

from pipelines.cli import main
from pipelines.fidelity.config import StudyConfig
from pipelines.fidelity.runner import run_study


def test_corrupt_and_foreign_cache_files_are_rerun_with_a_warning(tmp_path, caplog, tiny_study):
    cfg = StudyConfig(**tiny_study)
    run_study(cfg, tmp_path, workers=1, progress=False)
    text = (tmp_path / "results.csv").read_text()
    files = sorted((tmp_path / "cache").glob("*.json"))
    assert len(files) == 12
    other = json.loads(files[5].read_text())
    files[0].write_text("{not json")  # torn or garbage
    files[1].write_text("[1, 2, 3]")  # valid JSON, not a row
    files[2].write_text('{"phrase": "figure7"}')  # a dict, not a whole row
    files[3].write_text(json.dumps(other))  # another job's row under this job's name
    files[4].write_bytes(b"\xff\xfe\x00")  # not even text
    caplog.set_level(logging.WARNING, logger="pipelines.fidelity.runner")
    again = run_study(cfg, tmp_path, workers=1, progress=False)
    assert again.summary["jobs"]["ran"] == 5 and again.summary["jobs"]["cached"] == 7
    warned = [r.getMessage() for r in caplog.records if "rerunning its job" in r.getMessage()]
    assert len(warned) == 5
    assert sum("not a result row" in w for w in warned) == 2 and sum("another job" in w for w in warned) == 1
    assert (tmp_path / "results.csv").read_text() == text  # rerun gives the same rows
    # A row of another configuration (another seed) under this study's names is rerun too.
    seeded = StudyConfig(**{**tiny_study, "seed": 1})
    mine = run_study(seeded, tmp_path / "s1", workers=1, progress=False)
    assert mine.summary["jobs"]["ran"] == 12
    for f, g in zip(sorted((tmp_path / "s1" / "cache").glob("*.json")), sorted((tmp_path / "cache").glob("*.json"))):
        f.write_text(g.read_text())
    assert run_study(seeded, tmp_path / "s1", workers=1, progress=False).summary["jobs"]["ran"] == 12


@pytest.mark.parametrize(
    "toml, words",
    [
        ('takes = "3"', ["takes", "'3'"]),
        ("takes = 1", ["takes", "1"]),
        ("seed = 1.5", ["seed", "1.5"]),
        ('views = "front"', ["views", "'front'"]),
        ("image_sizes = [[320, 0]]", ["image_sizes", "[320, 0]", "(320, 0)"]),
        ("frame_rates = [25, true]", ["frame_rates", "True"]),
        ("noise = [-1]", ["noise", "-1"]),
        ('capture = ["video", "kinect"]', ["capture", "'kinect'"]),
        ("compression = [101]", ["compression", "101"]),
        ("baseline = 3", ["baseline", "3"]),
        ('[baseline]\nview = "top"', ["baseline.view", "'top'"]),
        ('[baseline]\nimage_size = "640x480"', ["baseline.image_size", "'640x480'"]),
    ],
)
def test_a_wrongly_typed_config_value_is_one_line_naming_key_and_value(tmp_path, toml, words):
    p = tmp_path / "study.toml"
    p.write_text(toml + "\n")
    r = CliRunner().invoke(main, ["fidelity-study", "--config", str(p), "-o", str(tmp_path / "out")])
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.output
    assert str(p) in lines[0] and words[0] in lines[0]
    assert any(w in lines[0] for w in words[1:]), lines[0]


@pytest.mark.parametrize(
    "args, words", [(["--capture", "video,bogus"], ["capture", "'bogus'"]), (["--seed", "-1"], ["--seed", "-1"])]
)
def test_a_bad_command_line_value_is_one_line(tmp_path, args, words):
    r = CliRunner().invoke(main, ["fidelity-study", *args, "-o", str(tmp_path / "out")])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1, r.output
    assert all(w in r.output for w in words), r.output


# --- signals: a real c2n process with two local workers ---------------------------------------

#: Keypoint jobs (about a second each): 1 phrase x 2 emotions x (2 takes x 2 rates + 2 training) = 12.
SIGNAL_STUDY = """phrases = ["figure7"]
emotions = ["happy", "sad"]
takes = 2
training_takes = 2
capture = "keypoints"
frame_rates = [25, 5]
resampling = ["keyframe"]
image_sizes = [[320, 240]]
views = ["front"]
cameras = []
compression = [0]
noise = [0]
bootstrap = 3
[baseline]
frame_rate = 25
image_size = [320, 240]
view = "front"
"""
TOTAL = 12
#: Seconds the tests wait for a process before calling it hung (a guard, not a measurement).
HANG_S = 120


def _cached(cache):
    """Finished cache entries: pathlib's glob also matches the hidden temporary file of a write in progress."""
    return [f for f in cache.glob("*.json") if not f.name.startswith(".")]


def _start(tmp_path):
    (tmp_path / "study.toml").write_text(SIGNAL_STUDY)
    # Ctrl-C live as in a terminal: a shell's background job (CI run with `&`)
    # passes SIGINT on ignored, and Python then never raises KeyboardInterrupt
    live = "import signal; signal.signal(signal.SIGINT, signal.default_int_handler)"
    cmd = [sys.executable, "-c", f"{live}; from pipelines.cli import main; main()", "fidelity-study"]
    cmd += ["--config", str(tmp_path / "study.toml"), "--workers", "2", "-o", str(tmp_path / "out")]
    # A session of its own, as a terminal's job: Ctrl-C reaches its whole process group.
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    cache = tmp_path / "out" / "cache"
    deadline = time.monotonic() + HANG_S
    while len(_cached(cache)) < 2:
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            pytest.fail(f"the study never cached 2 jobs: {proc.communicate()[1][-2000:]}")
        time.sleep(0.05)
    return proc, cache


def _children(pid: int) -> list[int]:
    kids = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    stat = f.read()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                kids.append(int(d))
    return kids


def _running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"  # a zombie computes nothing; it only waits to be reaped


def _wait_gone(pids, seconds=HANG_S) -> list[int]:
    deadline = time.monotonic() + seconds
    while any(_running(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    return [p for p in pids if _running(p)]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.filterwarnings("ignore:feet on the floor")  # the segmenter's note on a short phrase, not our subject
def test_ctrl_c_stops_keeps_finished_jobs_and_a_rerun_reuses_them(tmp_path, tiny_study):
    proc, cache = _start(tmp_path)
    workers = _children(proc.pid)
    os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does
    _out, err = proc.communicate(timeout=HANG_S)
    assert proc.returncode == 128 + signal.SIGINT, err[-2000:]
    kept = {f.name: f.read_text() for f in _cached(cache)}
    # Stopped, not drained: the jobs still queued were never run.
    assert 2 <= len(kept) < TOTAL
    last = err.strip().splitlines()[-1]
    assert "interrupted by SIGINT" in last and f"{len(kept)} of {TOTAL} jobs" in last and "again to resume" in last
    assert "Traceback" not in err
    assert len(workers) == 2 and not _wait_gone(workers, 10)
    res = run_study(StudyConfig(**{**tiny_study, "capture": "keypoints"}), tmp_path / "out", workers=2, progress=False)
    assert res.summary["jobs"]["cached"] == len(kept) and res.summary["jobs"]["ran"] == TOTAL - len(kept)
    assert all((cache / name).read_text() == text for name, text in kept.items())


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_killing_the_parent_leaves_no_worker_behind(tmp_path, sig):
    proc, cache = _start(tmp_path)
    workers = _children(proc.pid)
    assert len(workers) == 2
    os.kill(proc.pid, sig)  # the parent only: no handler sees SIGKILL
    proc.wait(timeout=HANG_S)
    assert not _wait_gone(workers), "orphaned workers still running"
    assert all(json.loads(f.read_text())["job"] == f.stem for f in _cached(cache))


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:feet on the floor")
def test_two_capture_paths_are_run_and_compared_per_condition(tmp_path, tiny_study):
    from pipelines.fidelity import run_fidelity_study
    from pipelines.fidelity.report import capture_comparison

    cfg = StudyConfig(**{**tiny_study, "capture": ("truth", "keypoints")})
    res = run_fidelity_study(cfg, tmp_path, workers=1, progress=False)
    assert list(res.by_capture) == ["truth", "keypoints"] and res.summary["capture"] == "truth"
    assert res.summary["other_captures"]["keypoints"]["jobs"]["total"] == 12
    rows = (tmp_path / "results.csv").read_text().splitlines()
    col = rows[0].split(",").index("capture")
    assert sorted({r.split(",")[col] for r in rows[1:]}) == ["keypoints", "truth"] and len(rows) == 1 + 24
    lines, cols = capture_comparison(res.by_capture)
    assert len(lines) == 2 and "symbol_accuracy [truth]" in cols and "symbol_accuracy [keypoints]" in cols
    # Each side is the mean of that path's own rows for the condition.
    base = [r for r in res.by_capture["keypoints"][0] if r["factor"] == "baseline" and r["split"] == "test"]
    assert lines[0]["symbol_accuracy [keypoints]"] == pytest.approx(
        sum(r["symbol_accuracy"] for r in base) / len(base), rel=1e-12
    )
    html = (tmp_path / "report.html").read_text()
    assert "Capture paths compared" in html and "mpjpe" not in cols
