"""``c2n render`` from the command line (small images, few frames)."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.io.truth import read_truth
from capture2notation.notation.formats import read
from pipelines.cli import main

SCORE = """title: cli test
tempo: 240
meter: 4
0  1  right_arm  forward  middle
1  1  right_arm  place    high
0  2  left_arm   left     middle  bend=1
"""


def _frames(path):
    cap = cv2.VideoCapture(str(path))
    n, shape = 0, None
    while True:
        ok, f = cap.read()
        if not ok:
            break
        n, shape = n + 1, f.shape
    cap.release()
    return n, shape


@pytest.fixture
def score_file(tmp_path):
    p = tmp_path / "phrase.lab"
    p.write_text(SCORE)
    return p


def test_render_writes_video_truth_and_score(tmp_path, score_file):
    out = tmp_path / "out"
    res = CliRunner().invoke(
        main,
        [
            "render",
            str(score_file),
            "-o",
            str(out),
            "--fps",
            "10",
            "--size",
            "96x72",
            "--view",
            "side",
            "--style",
            "markers",
        ],
    )
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in out.iterdir()) == ["camera.toml", "score.lab", "truth.npz", "video.mp4"]
    truth = read_truth(out / "truth.npz")
    n, shape = _frames(out / "video.mp4")
    # 2 beats at 240 bpm = 0.5 s at 10 fps: frames 0…5.
    assert truth.n_frames == n == 6 and shape == (72, 96, 3)
    assert truth.image_size == (96, 72) and truth.fps == 10.0
    assert (truth.view, truth.style) == ("side", "markers")
    assert read(out / "score.lab") == read(score_file)
    assert json.loads(truth.score)["title"] == "cli test"
    assert json.loads(truth.effort) == {"time": -2.0, "weight": 0.5, "space": 1.0}
    # The right arm ends straight up: its wrist is the highest landmark in the last frame.
    assert np.argmax(truth.landmarks3d[-1, :, 2]) in (16, 18, 20, 22)


def test_render_with_an_emotion_takes_its_tempo_and_effort(tmp_path, score_file):
    out = tmp_path / "sad"
    res = CliRunner().invoke(
        main,
        [
            "render",
            str(score_file),
            "-o",
            str(out),
            "--fps",
            "5",
            "--size",
            "64x48",
            "--style",
            "stick",
            "--emotion",
            "sad",
        ],
    )
    assert res.exit_code == 0, res.output
    truth = read_truth(out / "truth.npz")
    # 2 beats at sad's 37 bpm = 3.24 s at 5 fps.
    assert truth.n_frames == round(2 * 60 / 37 * 5) + 1
    assert json.loads(truth.effort)["time"] == pytest.approx(-2.19)
    assert read(out / "score.lab").emotion == "sad"


def test_render_png_frames_match_the_truth(tmp_path, score_file):
    out = tmp_path / "png"
    res = CliRunner().invoke(
        main, ["render", str(score_file), "-o", str(out), "--fps", "4", "--size", "64x48", "--png"]
    )
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in out.iterdir()) == ["camera.toml", "frames", "score.lab", "truth.npz"]
    frames = sorted((out / "frames").iterdir())
    assert len(frames) == read_truth(out / "truth.npz").n_frames == 3
    assert cv2.imread(str(frames[0])).shape == (48, 64, 3)


@pytest.mark.parametrize(
    "args, words",
    [
        (["--size", "640by480"], ["--size", "640by480", "WIDTHxHEIGHT"]),
        (["--size", "8x8"], ["--size", "16-8192"]),
        (["--view", "top"], ["--view", "top", "front"]),
        (["--style", "cartoon"], ["--style", "cartoon", "mannequin"]),
        (["--emotion", "bored"], ["--emotion", "bored", "happy"]),
        (["--fps", "0"], ["--fps"]),
    ],
)
def test_bad_options_give_one_line_errors(tmp_path, score_file, args, words):
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["render", str(score_file), "-o", str(out), *args])
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("c2n: error:")
    for w in words:
        assert w in lines[0]
    assert not out.exists()


def test_missing_or_malformed_score_names_the_file(tmp_path):
    bad = tmp_path / "bad.lab"
    bad.write_text("tempo: 60\n0 1 right_arm sideways middle\n")
    for path in (tmp_path / "missing.lab", bad):
        res = CliRunner().invoke(main, ["render", str(path), "-o", str(tmp_path / "o")])
        assert res.exit_code == 2
        assert res.output.count("\n") == 1 and path.name in res.output


def test_render_views_writes_every_camera(score_file, tmp_path):
    from capture2notation.io.calibration import read_calibration

    out = tmp_path / "mv"
    r = CliRunner().invoke(main, ["render", str(score_file), "-o", str(out), "--views", "front,45", "--size", "64x48"])
    assert r.exit_code == 0, r.output
    cams = read_calibration(out / "cameras.toml")
    assert cams.names == ("front", "45")
    for name in cams.names:
        truth = read_truth(out / name / "truth.npz")
        assert truth.view == name
        np.testing.assert_allclose(cams[name].R, truth.R, atol=1e-9)
        assert _frames(out / name / "video.mp4")[0] == truth.n_frames
    # the same performance from both cameras
    a, b = read_truth(out / "front" / "truth.npz"), read_truth(out / "45" / "truth.npz")
    np.testing.assert_array_equal(a.joints, b.joints)
    assert not (out / "calibration").exists()


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--views", "front"], "two or more"),
        (["--views", "front,front"], "two or more"),
        (["--views", "front,top"], "--views 'top'"),
        (["--views", "front,45", "--view", "side"], "give one of them"),
        (["--views", "front,45", "--pitch", "5"], "--pitch"),
        (["--calibration-clip"], "--calibration-clip needs --views"),
    ],
)
def test_render_views_bad_options_are_one_line_errors(score_file, tmp_path, args, expected):
    r = CliRunner().invoke(main, ["render", str(score_file), "-o", str(tmp_path / "o"), "--size", "64x48", *args])
    assert r.exit_code == 2
    assert len(r.output.strip().splitlines()) == 1 and expected in r.output, r.output
