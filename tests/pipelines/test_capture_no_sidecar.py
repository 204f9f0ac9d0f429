"""A capture never reads a file because it lies beside the video; --calibration gives the camera."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

import capture2notation.fitting as fitting
from capture2notation.errors import CalibrationError, PipelineError
from capture2notation.io.calibration import Calibration, CameraCalibration, read_calibration, write_calibration
from capture2notation.io.truth import read_truth
from capture2notation.notation.formats import loads
from pipelines.capture import capture
from pipelines.cli import main
from synthetic import render

SCORE = "tempo: 90\n0 1 right_arm right middle\n1 1 right_arm place low\n"
SIZE = (320, 240)


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A short marker render: ``front/video.mp4``, ``truth.npz``, ``camera.toml``."""
    out = tmp_path_factory.mktemp("cal") / "front"
    render.render_score(loads(SCORE, "lab"), out, fps=25, size=SIZE, view="front", style="markers", progress=False)
    return out


@pytest.fixture
def cameras_seen(monkeypatch):
    """The `camera` argument of every fit_track call."""
    seen = []
    real = fitting.fit_track

    def spy(track, *a, **kw):
        seen.append(kw.get("camera"))
        return real(track, *a, **kw)

    monkeypatch.setattr(fitting, "fit_track", spy)
    return seen


def _capture(video, out, **kw):
    return capture(video, out, backend="markers", tempo=90, progress=False, effort=False, overlay=False, **kw)


def test_render_writes_its_true_camera_as_a_calibration(rendered):
    cal = read_calibration(rendered / "camera.toml")
    truth = read_truth(rendered / "truth.npz")
    assert cal.names == ("front",)  # camera_name of front/video.mp4
    cam = cal["front"]
    assert cam.image_size == SIZE
    np.testing.assert_allclose(cam.K, truth.K, rtol=1e-9)
    np.testing.assert_allclose(cam.R, truth.R, atol=1e-9)
    np.testing.assert_allclose(cam.t, truth.t, atol=1e-9)


def test_capture_never_reads_a_truth_sidecar_beside_the_video(rendered, tmp_path, cameras_seen, monkeypatch):
    video_dir = tmp_path / "front"
    video_dir.mkdir()
    (video_dir / "video.mp4").write_bytes((rendered / "video.mp4").read_bytes())
    (video_dir / "truth.npz").write_bytes(b"not an npz: reading this would fail")
    (video_dir / "camera.toml").write_text("not toml [[[")  # nor a calibration lying beside it
    opened = []
    real_load = np.load

    def watch(path, *a, **kw):
        opened.append(str(path))
        return real_load(path, *a, **kw)

    monkeypatch.setattr(np, "load", watch)
    res = _capture(video_dir / "video.mp4", tmp_path / "c")
    assert res.kind == "video" and len(res.score.symbols) > 0
    assert not any(p.endswith("truth.npz") for p in opened)
    assert cameras_seen == [None]  # the fitting stage estimates the camera


def test_calibration_file_gives_the_camera(rendered, tmp_path, cameras_seen):
    _capture(rendered / "video.mp4", tmp_path / "c", calibration=rendered / "camera.toml")
    (cam,) = cameras_seen
    truth = read_truth(rendered / "truth.npz")
    np.testing.assert_allclose(cam.K, truth.K, rtol=1e-9)
    np.testing.assert_allclose(cam.t, truth.t, atol=1e-9)
    assert cam.image_size == SIZE


def _write(path, name, size):
    cam = CameraCalibration(
        name=name, image_size=size, K=np.diag([300.0, 300.0, 1.0]) + [[0, 0, 160], [0, 0, 120], [0, 0, 0]]
    )
    return write_calibration(Calibration.of([cam]), path)


def test_calibration_is_checked_before_the_keypoints_and_only_for_video(rendered, tmp_path, monkeypatch):
    import capture2notation.keypoints as keypoints

    monkeypatch.setattr(keypoints, "extract", lambda *a, **kw: pytest.fail("keypoints read before the calibration"))
    (tmp_path / "broken.toml").write_text("version = [")
    with pytest.raises(CalibrationError, match=r"broken\.toml"):
        _capture(rendered / "video.mp4", tmp_path / "c", calibration=tmp_path / "broken.toml")
    with pytest.raises(PipelineError, match=r"--calibration.*video input"):
        capture(rendered / "truth.npz", tmp_path / "t", calibration=rendered / "camera.toml", progress=False)


def test_command_line_mismatch_is_one_line_exit_2(rendered, tmp_path):
    bad = _write(tmp_path / "cal.toml", "front", (640, 480))
    r = CliRunner().invoke(
        main,
        ["capture", str(rendered / "video.mp4"), "-o", str(tmp_path / "c"), "--backend", "markers",
         "--calibration", str(bad), "--no-effort", "--tempo", "90"],
    )  # fmt: skip
    assert r.exit_code == 2, r.output
    errors = [ln for ln in r.output.splitlines() if "error" in ln]  # the progress line may precede it
    assert len(errors) == 1 and errors[0].startswith("c2n: error:") and "640x480" in errors[0]
