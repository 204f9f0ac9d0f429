"""``c2n keypoints`` and ``c2n models`` end to end on small inputs."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.io.video import VideoWriter
from capture2notation.keypoints import KeypointTrack
from capture2notation.keypoints import model as pm
from pipelines.cli import main


def _video_of(image, path, n=4, fps=10.0):
    h, w = image.shape[:2]
    with VideoWriter(path, fps, (w, h)) as wr:
        for _ in range(n):
            wr.write(image)
    return path


@pytest.mark.model
def test_keypoints_command_writes_track_and_overlay(fixture_path, pose_model_path, tmp_path):
    image = cv2.resize(cv2.imread(str(fixture_path("mediapipe/pose.jpg"))), (500, 334))
    video = _video_of(image, tmp_path / "in.avi")
    out, overlay = tmp_path / "track.npz", tmp_path / "overlay.avi"
    result = CliRunner().invoke(
        main, ["keypoints", str(video), "-o", str(out), "--overlay", str(overlay), "--model", str(pose_model_path)]
    )
    assert result.exit_code == 0, result.output
    track = KeypointTrack.load(out)
    assert len(track) == 4 and track.backend == "blazepose" and tuple(track.image_size) == (500, 334)
    assert (track.presence > 0.9).all() and np.isfinite(track.xy[:, :, :2]).all()
    cap = cv2.VideoCapture(str(overlay))
    ok, first = cap.read()
    cap.release()
    assert ok and first.shape == (334, 500, 3)
    assert np.abs(first.astype(int) - image.astype(int)).max() > 100  # something was drawn


def test_keypoints_command_markers_backend_on_image_folder(tmp_path):
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(3):
        img = np.full((60, 80, 3), 128, np.uint8)
        cv2.circle(img, (20 + 10 * i, 30), 5, (0, 200, 0), -1)
        cv2.imwrite(str(folder / f"{i:02d}.png"), img)
    out = tmp_path / "m.npz"
    spec_free = CliRunner().invoke(
        main, ["keypoints", str(folder), "-o", str(out), "--backend", "markers", "--fps", "12"]
    )
    # The default marker set is the renderer's (green = hue 60 is its left shoulder).
    assert spec_free.exit_code == 0, spec_free.output
    track = KeypointTrack.load(out)
    assert track.fps == 12.0 and track.backend == "markers"
    np.testing.assert_allclose(track.xy[:, 11, 0], [20, 30, 40], atol=0.5)


def test_unreadable_video_is_a_one_line_error(tmp_path):
    bad = tmp_path / "bad.mp4"
    bad.write_bytes(b"nope")
    result = CliRunner().invoke(main, ["keypoints", str(bad), "-o", str(tmp_path / "t.npz"), "--backend", "markers"])
    assert result.exit_code == 2
    assert "c2n: error:" in result.output and "bad.mp4" in result.output
    assert not (tmp_path / "t.npz").exists()


def test_models_path_without_cache_says_what_to_run(tmp_path, monkeypatch):
    monkeypatch.setenv(pm.ENV_CACHE, str(tmp_path))
    monkeypatch.delenv(pm.ENV_MODEL, raising=False)
    result = CliRunner().invoke(main, ["models", "path"])
    assert result.exit_code == 2 and "c2n models fetch" in result.output


@pytest.mark.model
def test_models_verify(pose_model_path):
    result = CliRunner().invoke(main, ["models", "verify", "--model", str(pose_model_path)])
    assert result.exit_code == 0 and "ok (sha256" in result.output


def test_markers_from_a_json_file(tmp_path):
    """Real footage: gloves of configurable colours, given as HSV ranges or BGR colours."""
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(2):
        img = np.full((60, 80, 3), 128, np.uint8)
        cv2.circle(img, (20, 20 + 10 * i), 5, (0, 0, 220), -1)  # red glove: right wrist
        cv2.circle(img, (60, 30), 5, (220, 0, 0), -1)  # blue glove: left wrist
        cv2.imwrite(str(folder / f"{i}.png"), img)
    spec = tmp_path / "gloves.json"
    spec.write_text(
        '[{"landmark": "right_wrist", "bgr": [0, 0, 220]},'
        ' {"landmark": 15, "hsv_low": [110, 80, 60], "hsv_high": [130, 255, 255]}]'
    )
    out = tmp_path / "g.npz"
    result = CliRunner().invoke(
        main, ["keypoints", str(folder), "-o", str(out), "--backend", "markers", "--markers", str(spec)]
    )
    assert result.exit_code == 0, result.output
    track = KeypointTrack.load(out)
    np.testing.assert_allclose(track.xy[:, 16, :2], [[20, 20], [20, 30]], atol=0.5)
    np.testing.assert_allclose(track.xy[:, 15, :2], [[60, 30], [60, 30]], atol=0.5)
    spec.write_text('[{"landmark": "left_wirst", "bgr": [0, 0, 220]}]')
    bad = CliRunner().invoke(
        main, ["keypoints", str(folder), "-o", str(out), "--backend", "markers", "--markers", str(spec)]
    )
    assert bad.exit_code == 2 and "marker entry 0" in bad.output and "left_wirst" in bad.output
