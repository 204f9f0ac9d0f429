"""The command line's terminal output: one line per error or warning, sparse progress in logs,
output folders checked before work starts and left untouched by a failed capture."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.notation.formats import read
from pipelines.cli import main

_MOCAP = "bvh/test_mocapbank.bvh"


def _run(*args):
    r = CliRunner().invoke(main, [str(a) for a in args])
    return r.exit_code, r.stdout, r.stderr


def _one_error(code, out, err, *words):
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("c2n: error: "), err
    assert "Traceback" not in err and "format=" not in err
    for w in words:
        assert w in lines[0], (w, lines[0])


def _bvh_with(fixture_path, tmp_path, old, new):
    text = fixture_path(_MOCAP).read_text()
    path = tmp_path / "bad.bvh"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    "old, new, words",
    [
        ("Frames:\t455", "Frames:\t0", [":118: Frames is '0'"]),
        ("Frames:\t455", "Frames:\tinf", [":118: Frames is 'inf'"]),
        ("Frames:\t455", "Frames:\tnan", [":118: Frames is 'nan'"]),
        ("Frames:\t455", "Frames:\t-1e308", [":118: Frames is '-1e308'"]),
        ("Frames:\t455", "Frames:\t-1", [":118: Frames is '-1'"]),
        ("Frames:\t455", "Frames:\t2.7", [":118: Frames is '2.7'"]),
        ("CHANNELS 3 Zrotation", "CHANNELS nan Zrotation", [":9: CHANNELS count of Chest is 'nan'"]),
        ("Frame Time:\t0.033333", "Frame Time:\t1e-300", [":119: Frame Time 1e-300 s"]),
        ("OFFSET -0.1728 10.2870", "OFFSET nan 10.2870", [":8: OFFSET of Chest is nan"]),
    ],
)
def test_a_bad_bvh_is_one_line_exit_2_and_leaves_no_folder(fixture_path, tmp_path, old, new, words):
    path = _bvh_with(fixture_path, tmp_path, old, new)
    out = tmp_path / "out"
    _one_error(*_run("capture", path, "-o", out, "--no-effort"), str(path), *words)
    assert not out.exists() and not list(tmp_path.glob(".out*"))


@pytest.mark.parametrize("ts, words", [("nan", [":6: timestamp is 'nan'"]), ("1000000000000000", ["1e+15"])])
def test_a_bad_kinect_timestamp_is_one_line_exit_2(fixture_path, tmp_path, ts, words):
    lines = fixture_path("kinect/joints.csv").read_text().splitlines()
    cells = lines[5].split(",")
    cells[0] = ts
    lines[5] = ",".join(cells)
    path = tmp_path / "k.csv"
    path.write_text("\n".join(lines) + "\n")
    _one_error(*_run("capture", path, "-o", tmp_path / "o", "--no-effort"), str(path), *words)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e-300", "0", "1e9"])
def test_bad_tempo_is_one_line_exit_2(fixture_path, tmp_path, value):
    code, out, err = _run("capture", fixture_path(_MOCAP), "-o", tmp_path / "o", "--tempo", value)
    _one_error(code, out, err, "capture: Invalid value for '--tempo'", repr(value), "[10, 400] beats per minute")
    assert not (tmp_path / "o").exists()


def test_output_below_a_regular_file_is_refused_before_any_work(fixture_path, tmp_path):
    (tmp_path / "afile").write_text("x")
    code, out, err = _run("capture", fixture_path(_MOCAP), "-o", tmp_path / "afile" / "sub", "--no-effort")
    _one_error(code, out, err, "-o", "afile is a file, so no folder can be made below it")
    code, out, err = _run("score", fixture_path(_MOCAP), fixture_path(_MOCAP), "-o", tmp_path / "afile" / "s")
    _one_error(code, out, err, "afile is a file")


def _read_only_folder(tmp_path) -> Path:
    if os.geteuid() != 0:
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        return ro
    # Root writes through permission bits; /sys refuses new files even to root.
    if not Path("/sys").is_dir() or _can_create("/sys"):
        pytest.skip("running as root and no read-only folder to try")
    return Path("/sys")


def _can_create(folder) -> bool:
    try:
        (Path(folder) / ".c2n-probe").touch()
    except OSError:
        return False
    (Path(folder) / ".c2n-probe").unlink()
    return True


def test_output_in_a_read_only_folder_is_refused_before_any_work(fixture_path, tmp_path):
    ro = _read_only_folder(tmp_path)
    code, out, err = _run("capture", fixture_path(_MOCAP), "-o", ro / "out", "--no-effort")
    _one_error(code, out, err, "-o", f"cannot write in {ro}", "Permission denied")


def test_library_warnings_are_one_log_line_without_source_paths(fixture_path, tmp_path):
    text = fixture_path(_MOCAP).read_text().splitlines()
    m = text.index("MOTION")
    row = text[m + 3].split()
    row[5] = "nan"
    text[m + 3] = " ".join(row)
    path = tmp_path / "nan.bvh"
    path.write_text("\n".join(text) + "\n")
    code, out, err = _run("capture", path, "-o", tmp_path / "o", "--no-effort")
    assert code == 0, err
    assert err.splitlines()[0] == (
        f"c2n: warning: {path}:120: Hips Yrotation is nan: 1 channel values are not finite or out of range; "
        "what they move is missing (NaN, confidence 0) in 1 of 455 frames"
    )
    assert "Warning:" not in err and ".py:" not in err and "Traceback" not in err
    assert "19 symbols" in out or "symbols from 455 frames" in out


@pytest.mark.filterwarnings("default:the floor is never seen")  # shown, as for a user (not an error)
def test_python_warnings_are_routed_through_logging(fixture_path, tmp_path):
    # The Kinect clip's feet are only inferred (confidence 0.3): the
    # quantiser's UserWarning that no floor is seen, as the terminal shows it.
    code, _out, err = _run("capture", fixture_path("kinect/joints.csv"), "-o", tmp_path / "o", "--no-effort")
    assert code == 0, err
    warned = [line for line in err.splitlines() if "floor" in line]
    assert len(warned) == 1 and warned[0].startswith(
        "c2n: warning: the floor is never seen (a foot tracked in only 0 % of 377 frames)"
    ), err
    assert "UserWarning" not in err and ".py:" not in err
    # numpy's own RuntimeWarnings (an all-NaN slice) are diagnostics, shown with -v only.
    assert "All-NaN" not in err


def test_a_truncated_video_says_how_many_frames_were_read(tmp_path):
    import cv2

    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(4):
        cv2.imwrite(str(folder / f"{i:03d}.png"), np.full((48, 64, 3), 40 * i, np.uint8))
    (folder / "004.png").write_bytes(b"cut short")
    code, out, err = _run("keypoints", folder, "--backend", "markers", "-o", tmp_path / "t.npz")
    assert code == 0, err
    (line,) = [w for w in err.splitlines() if w.startswith("c2n: warning:")]
    assert "stopped at frame 4" in line and "using the 4 frames read before it" in line
    assert "4 frames" in out


def test_a_failed_capture_leaves_nothing_behind(fixture_path, tmp_path, monkeypatch):
    """A failure after the motion is read (here: drawing the staff) removes what the run wrote:
    no new folder, and an existing folder keeps its old files as they were."""
    import capture2notation.notation.staff as staff

    def broken(*a, **k):
        raise OSError(28, "No space left on device", "staff.svg")

    monkeypatch.setattr(staff, "render_staff", broken)
    new = tmp_path / "new"
    code, out, err = _run("capture", fixture_path(_MOCAP), "-o", new, "--no-effort")
    _one_error(code, out, err, "staff.svg: No space left on device")
    assert not new.exists()
    old = tmp_path / "old"
    old.mkdir()
    (old / "score.lab").write_text("previous run")
    code, out, err = _run("capture", fixture_path(_MOCAP), "-o", old, "--no-effort")
    assert code == 2
    assert [p.name for p in old.iterdir()] == ["score.lab"] and (old / "score.lab").read_text() == "previous run"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old"]


def test_progress_is_a_sparse_line_when_stderr_is_not_a_terminal(capsys, monkeypatch):
    import capture2notation.progress as progress

    assert list(progress.progress(range(50), desc="keypoints (markers)", unit="frame")) == list(range(50))
    err = capsys.readouterr().err
    assert err == "keypoints (markers): 50/50 frames (100 %), 0 s\n"  # one line at the end, no bar
    monkeypatch.setattr(progress, "LINE_INTERVAL_S", 0.0)
    with progress.progress(total=3, desc="fit", unit="frame") as bar:
        for _ in range(3):
            bar.update()
    lines = capsys.readouterr().err.splitlines()
    assert lines[:3] == ["fit: 1/3 frames (33 %), 0 s", "fit: 2/3 frames (67 %), 0 s", "fit: 3/3 frames (100 %), 0 s"]
    assert not any("\r" in line for line in lines)


def test_progress_is_a_bar_on_a_terminal(monkeypatch):
    import sys

    from tqdm import tqdm

    import capture2notation.progress as progress

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    bar = progress.progress(total=3, desc="x")
    assert isinstance(bar, tqdm)
    bar.close()


@pytest.mark.filterwarnings("default:feet on the floor in only")  # the 30 cm low floor: shown, as for a user
def test_floor_option_takes_auto_or_a_height_and_names_a_bad_value(fixture_path, tmp_path):
    """``--floor auto`` is the default (the floor found from the feet: the
    fixture dance writes supports); a height moves it (30 cm below the file's
    lowest joint: the feet never reach it, no support); anything else is one
    line naming the option and the value, exit 2."""
    from capture2notation.io.bvh import parse_bvh, read_bvh_points

    path = fixture_path("bvh/test_mocapbank.bvh")
    points, _conf, _head, _fps = read_bvh_points(parse_bvh(path), None, where=path)
    lowest = float(np.nanmin(points[..., 2]))
    code, _out, err = _run("capture", path, "-o", tmp_path / "a", "--no-effort", "--tempo", 120, "--floor", "auto")
    assert code == 0, err
    auto = read(tmp_path / "a" / "score.lab")
    assert [s for s in auto.symbols if s.is_support and s.level is not None]
    code, _out, err = _run(
        "capture", path, "-o", tmp_path / "b", "--no-effort", "--tempo", 120, "--floor", f"{lowest - 0.30:.4f}"
    )
    assert code == 0, err
    low = read(tmp_path / "b" / "score.lab")
    assert not [s for s in low.symbols if s.is_support and s.level is not None]
    code, _out, err = _run("capture", path, "-o", tmp_path / "c", "--floor", "ground")
    assert code == 2
    line = [x for x in err.splitlines() if x.strip()]
    assert len(line) == 1 and "--floor" in line[0] and "'ground'" in line[0] and "auto" in line[0], err
    assert "Traceback" not in err
    code, _out, err = _run("capture", "--help")
    assert "--floor auto|HEIGHT_M" in " ".join(err.split() + _out.split())


def test_python_dash_m_runs_the_command_line():
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-m", "pipelines.cli", "--help"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "capture" in r.stdout and "Usage:" in r.stdout
