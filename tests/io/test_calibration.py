"""Calibration files: exact round trip, and one-line errors for anything else."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import C2NError, CalibrationError
from capture2notation.io.calibration import (
    Board,
    Calibration,
    CameraCalibration,
    camera_name,
    read_calibration,
    write_calibration,
)


def _rotation(rx, ry, rz) -> np.ndarray:
    import cv2

    return cv2.Rodrigues(np.array([rx, ry, rz], float))[0]


def _camera(name="front", f=660.0, rvec=(0.1, -0.2, 0.3), t=(0.0, 1.0, 4.0), dist=(0.0,) * 5) -> CameraCalibration:
    K = np.array([[f, 0.0, 320.0], [0.0, f * 1.01, 240.0], [0.0, 0.0, 1.0]])
    return CameraCalibration(name, (640, 480), K, np.array(dist), _rotation(*rvec), np.array(t), rms_px=0.21)


def test_write_read_round_trip(tmp_path):
    cal = Calibration.of(
        [_camera(), _camera("45", 800.0, (1.0, 0.5, -0.2), (0.5, 1.2, 3.0), (-0.1, 0.02, 0, 0, 0))],
        Board((7, 5), 0.04, 0.03, "DICT_4X4_250"),
    )
    path = write_calibration(cal, tmp_path / "cameras.toml", comment="made by a test")
    back = read_calibration(path)
    assert back.names == ("front", "45") and back.board == cal.board
    for name in cal.names:
        a, b = cal[name], back[name]
        assert a.image_size == b.image_size and a.rms_px == pytest.approx(b.rms_px)
        for key in ("K", "dist", "R", "t"):
            np.testing.assert_allclose(getattr(b, key), getattr(a, key), rtol=1e-11, atol=1e-12)


def test_projection_matches_the_pinhole_without_distortion():
    cam = _camera()
    X = np.array([[0.1, -0.2, 1.0], [0.3, 0.0, 0.2]])
    c = X @ cam.R.T + cam.t
    uv = (c[:, :2] / c[:, 2:]) * [cam.K[0, 0], cam.K[1, 1]] + cam.K[:2, 2]
    np.testing.assert_allclose(cam.project(X), uv, atol=1e-9)


def test_camera_names_follow_the_file_or_its_folder(tmp_path):
    assert camera_name("OUT/front/video.mp4") == "front"
    assert camera_name("clips/left.mp4") == "left"
    (tmp_path / "side").mkdir()
    assert camera_name(tmp_path / "side") == "side"


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("version = 2\n[cameras.a]\n", r"version 2"),
        ("version = 1\n", r"no \[cameras.NAME\]"),
        ("[cameras.a]\nimage_size = [640, 480]\n", r"\[cameras.a\] missing K"),
        ("[cameras.a]\nimage_size = [640]\nK = [[1,0,0],[0,1,0],[0,0,1]]\n", r"image_size"),
        (
            (
                "[cameras.a]\nimage_size = [640, 480]\nK = [[1,0,0],[0,1,0],[0,0,1]]\nR = [[2,0,0],[0,1,0],[0,0,1]]\n"
                "t = [0,0,0]\n"
            ),
            r"R is not a rotation",
        ),
        (
            (
                "[cameras.a]\nimage_size = [640, 480]\nK = [[-1,0,0],[0,1,0],[0,0,1]]\nR = [[1,0,0],[0,1,0],[0,0,1]]\n"
                "t = [0,0,0]\n"
            ),
            r"fx, fy > 0",
        ),
        (
            (
                "[cameras.a]\nimage_size = [640, 480]\nK = [[1,0,0],[0,1,0],[0,0,1]]\nR = [[1,0,0],[0,1,0],[0,0,1]]\n"
                "t = [nan,0,0]\n"
            ),
            r"t must be finite",
        ),
        ("[cameras.a]\nimage_size = [640, 480]\nfocal = 3\n", r"unknown key 'focal'"),
        ("[board]\nsquares = [1, 5]\n[cameras.a]\n", r"\[board\]"),
        ("this is = = not toml", r"not a TOML file"),
    ],
)
def test_bad_files_give_one_line_errors_naming_the_file(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(CalibrationError, match=match) as info:
        read_calibration(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_a_missing_camera_is_named():
    cal = Calibration.of([_camera()])
    with pytest.raises(CalibrationError, match=r"no camera 'side'.*front"):
        cal["side"]


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=300))
def test_any_text_reads_or_raises_calibration_error(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("cal") / "x.toml"
    path.write_text(text, encoding="utf-8")
    with contextlib.suppress(C2NError):
        read_calibration(path)


@settings(max_examples=100, deadline=None)
@given(
    f=st.floats(100, 5000),
    rvec=st.tuples(*[st.floats(-3.0, 3.0)] * 3),
    t=st.tuples(*[st.floats(-50, 50)] * 3),
    dist=st.tuples(*[st.floats(-1, 1)] * 5),
)
def test_any_camera_round_trips(tmp_path_factory, f, rvec, t, dist):
    cal = Calibration.of([_camera("c", f, rvec, t, dist)])
    back = read_calibration(write_calibration(cal, tmp_path_factory.mktemp("cal") / "c.toml"))["c"]
    for key in ("K", "dist", "R", "t"):
        np.testing.assert_allclose(getattr(back, key), getattr(cal["c"], key), rtol=1e-11, atol=1e-11)
