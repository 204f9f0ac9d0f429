"""Calibration from in-process board images: the cameras come back; bad inputs get one-line errors.

Tolerances: the issue's targets (RMS ≤ 0.5 px, orientation ≤ 0.5°) for
what the fast tier's short, uncompressed sequences reach too; camera
centres to 2 cm here (the slow tier checks the 1-cm target on the rendered
clips, see tests/calibrate/test_calibrate_clips.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from capture2notation.calibrate import (
    MAX_RMS_PX,
    BoardDetections,
    calibrate_cameras,
    detect_images,
    floor_frame,
)
from capture2notation.errors import CalibrationError
from synthetic.render.board_clip import BOARD, FLOOR_MARGIN, _BoardImage, board_frame, board_path, floor_origin
from synthetic.render.camera import Camera
from synthetic.render.scene import floor_background

VIEWS = ("front", "45")


def _angle_deg(Ra, Rb) -> float:
    return math.degrees(math.acos(np.clip((np.trace(Ra @ Rb.T) - 1) / 2, -1.0, 1.0)))


@pytest.fixture(scope="module")
def scene():
    """Two cameras' detections of the board: 8 frames on the floor, then one frame per pose (16 poses, for speed)."""
    cams = [Camera.for_view(v, (640, 480)) for v in VIEWS]
    rng = np.random.default_rng(3)
    path = board_path(cams, rng, n_poses=16)
    image = _BoardImage(BOARD)
    poses = [(path.R[0], path.p[0])] * 8 + list(zip(path.R[1:], path.p[1:]))
    dets = []
    for cam in cams:
        bg = floor_background(cam).astype(float)
        frames = ((i, board_frame(cam, [pose], bg, image, rng)) for i, pose in enumerate(poses))
        dets.append(detect_images(frames, BOARD, f"{VIEWS[len(dets)]}.mp4", 25.0, cam.size))
    return cams, dets


def _calibrate(cams, dets):
    return calibrate_cameras(dets, list(VIEWS), BOARD, floor_origin(cams), "standing", FLOOR_MARGIN * BOARD.square)


def test_calibration_recovers_the_rendered_cameras(scene):
    cams, dets = scene
    res = _calibrate(cams, dets)
    for name, cam in zip(VIEWS, cams):
        est = res.calibration[name]
        assert res.rms_px[name] <= 0.5
        assert est.rms_px == pytest.approx(res.rms_px[name])
        assert np.linalg.norm(est.centre - cam.position) <= 0.02
        assert _angle_deg(est.R, cam.R) <= 0.5
        assert est.K[0, 0] == pytest.approx(cam.K[0, 0], rel=0.01)
        assert est.image_size == cam.size


def test_floor_frame_puts_the_standing_board_upright_on_the_floor():
    M, o = floor_frame(BOARD, (0.0, 0.0, 0.0), "standing", 0.06)
    w, h = BOARD.squares[0] * BOARD.square, BOARD.squares[1] * BOARD.square
    bottom_mid = M @ np.array([w / 2, h, 0.0]) + o
    top_mid = M @ np.array([w / 2, 0.0, 0.0]) + o
    np.testing.assert_allclose(bottom_mid, [0.0, 0.0, 0.06], atol=1e-12)
    np.testing.assert_allclose(top_mid, [0.0, 0.0, 0.06 + h], atol=1e-12)
    np.testing.assert_allclose(-M[:, 2], [0.0, 1.0, 0.0], atol=1e-12)  # the face looks along +y
    assert np.linalg.det(M) == pytest.approx(1.0)
    M, o = floor_frame(BOARD, (1.0, 2.0, 90.0), "lying")
    np.testing.assert_allclose(M @ np.array([w / 2, h / 2, 0.0]) + o, [1.0, 2.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(M[:, 2], [0.0, 0.0, -1.0], atol=1e-12)  # face up
    with pytest.raises(CalibrationError, match="--floor"):
        floor_frame(BOARD, (0, 0, 0), "hanging")


def test_cameras_that_never_see_the_board_together_are_refused(scene):
    cams, (a, b) = scene
    later = BoardDetections(b.source, b.image_size, b.fps, b.n_frames, b.frames + 1000, b.ids, b.corners)
    with pytest.raises(CalibrationError, match=r"45\.mp4: camera 45 never sees the board in the same frame as front"):
        _calibrate(cams, [a, later])


def test_a_fit_above_the_limit_is_refused(scene):
    cams, (a, b) = scene
    rng = np.random.default_rng(5)
    noisy = [c + rng.normal(0, 3 * MAX_RMS_PX, c.shape) for c in b.corners]
    bad = BoardDetections(b.source, b.image_size, b.fps, b.n_frames, b.frames, b.ids, noisy)
    with pytest.raises(CalibrationError, match=r"45\.mp4: camera 45's reprojection RMS is [\d.]+ px, above"):
        _calibrate(cams, [a, bad])


def test_one_camera_or_repeated_names_are_refused(scene):
    _cams, (a, b) = scene
    with pytest.raises(CalibrationError, match="two or more clips"):
        calibrate_cameras([a], ["front"], BOARD)
    with pytest.raises(CalibrationError, match="same camera name"):
        calibrate_cameras([a, b], ["front", "front"], BOARD)


def test_clips_of_different_frame_rates_are_refused(scene):
    cams, (a, b) = scene
    slow = BoardDetections(b.source, b.image_size, 12.5, b.n_frames, b.frames, b.ids, b.corners)
    with pytest.raises(CalibrationError, match=r"45\.mp4: frame rate 12\.5 fps differs from front\.mp4's 25 fps"):
        _calibrate(cams, [a, slow])
