"""``c2n capture``: motion files and videos → notation files."""

from __future__ import annotations

import csv
import itertools
import json
import shutil
import sys
from dataclasses import replace
from fractions import Fraction as F
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.body import JOINTS, Body
from capture2notation.compare.agreement import score_differences
from capture2notation.errors import PipelineError
from capture2notation.io.truth import write_truth
from capture2notation.notation import read, write
from capture2notation.notation.model import Score, Symbol
from capture2notation.quantise.labels import LABEL_PARTS
from pipelines.capture import capture
from pipelines.capture_input import input_kind
from pipelines.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "quantise"))
from quantise_motions import arm_angles, build_motion

TEMPO = 72
MOVES = [
    (1, 1, "right_shoulder", arm_angles("right", "middle")),
    (2, F(1, 2), "left_shoulder", arm_angles("forward", "high")),
    (3, 1, "right_shoulder", np.zeros(3)),
]
EXPECTED = Score(
    symbols=(
        Symbol(1, 1, "right_arm", "right", "middle"),
        Symbol(2, F(1, 2), "left_arm", "forward", "high"),
        Symbol(3, 1, "right_arm", "place", "low"),
    ),
    tempo=TEMPO,
)


@pytest.fixture
def sidecar(tmp_path):
    """A truth sidecar of an FK motion (camera fields are placeholders: not used for motion input)."""
    joints, angles = build_motion(MOVES, TEMPO)
    T = joints.shape[0]
    path = tmp_path / "in" / "truth.npz"
    write_truth(
        path,
        fps=25.0, times=np.arange(T) / 25.0, joint_names=np.asarray(JOINTS), joints=joints, angles=angles,
        root=joints[:, 0], landmarks3d=np.full((T, 33, 3), np.nan), keypoints=np.full((T, 33, 2), np.nan),
        visibility=np.zeros((T, 33)), K=np.eye(3), R=np.eye(3), t=np.zeros(3), image_size=np.array([64, 48]),
        score="{}", effort="{}", view="front", style="stick", body_height=Body().height,
    )  # fmt: skip
    return path


def test_truth_sidecar_capture_writes_every_file(sidecar, tmp_path):
    out = tmp_path / "out"
    res = capture(sidecar, out, tempo=TEMPO, progress=False, effort=False)
    assert res.kind == "truth" and res.score.tempo == TEMPO
    for name in (
        "score.lab",
        "score.json",
        "laban_editor.json",
        "benesh.json",
        "labels.csv",
        "staff.svg",
        "staff.png",
        "capture.npz",
        "index.html",
    ):
        assert (out / name).is_file(), name
    assert score_differences(EXPECTED, read(out / "score.lab")) == []
    assert score_differences(EXPECTED, read(out / "score.json")) == []
    rows = list(csv.DictReader((out / "labels.csv").open()))
    assert len(rows) == res.n_frames * len(LABEL_PARTS)
    ben = json.loads((out / "benesh.json").read_text())
    assert [p["frame"] for p in ben["poses"]] == res.segmentation.key_frames.tolist()
    with np.load(out / "capture.npz") as z:
        assert z["joints"].shape == (res.n_frames, len(JOINTS), 3)
        assert z["confidence"].shape == (res.n_frames, len(JOINTS))
        assert float(z["fps"]) == 25.0
        assert np.all(np.isnan(z["keypoints"]))  # no video: no keypoints, none invented
        assert str(z["input_kind"]) == "truth"
    page = (out / "index.html").read_text()
    assert '<svg id="staff"' in page and 'href="staff.svg"' in page and "motion file" in page
    assert any("overlay.mp4" in s for s in res.skipped)
    # Nothing half-written is left behind.
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_estimated_tempo_and_fps_override(sidecar, tmp_path):
    res = capture(sidecar, tmp_path / "o", progress=False, effort=False)
    assert res.segmentation.tempo_estimated and res.score.tempo == TEMPO
    assert res.segmentation.tempo_source == "the movements"
    assert 0.5 < res.segmentation.tempo_confidence <= 1.0
    page = (tmp_path / "o" / "index.html").read_text()
    assert f"{TEMPO} bpm (estimated from the movements, " in page and "give --tempo to fix it" in page
    # Played twice as fast, the same frames are twice the tempo.
    res2 = capture(sidecar, tmp_path / "o2", fps_override=50.0, tempo=2 * TEMPO, progress=False, effort=False)
    assert score_differences(EXPECTED, res2.score.replace(tempo=TEMPO)) == []


def test_tempo_note_says_what_set_the_tempo():
    from types import SimpleNamespace

    from pipelines.capture import tempo_note

    seg = SimpleNamespace(tempo_estimated=True, tempo_confidence=0.85, tempo_runner_up=72, tempo_source="the movements")
    assert tempo_note(seg) == " (estimated from the movements, 85% sure; else 72 bpm; give --tempo to fix it)"
    assert "; no sound track;" in tempo_note(seg, "no sound track")
    given = SimpleNamespace(tempo_estimated=False, tempo_source="given")
    assert tempo_note(given) == " (given)"
    for source in ("none", "no beat"):
        note = tempo_note(SimpleNamespace(tempo_estimated=False, tempo_source=source))
        assert "one beat a second" in note and "given" not in note and "%" not in note


def test_tempo_none_writes_seconds_and_says_so(sidecar, tmp_path):
    res = capture(sidecar, tmp_path / "o", tempo="none", progress=False, effort=False)
    assert res.score.tempo == 60 and not res.segmentation.tempo_estimated
    assert res.segmentation.tempo_source == "none"
    # One beat a second: every start in beats is its time in seconds (the
    # movements of MOVES start at beats 1, 2, 3 of 72 bpm).
    starts = sorted(float(s.start) for s in res.score.symbols)
    assert np.allclose(starts, [b * 60 / TEMPO for b in (1, 2, 3)], atol=0.26)
    page = (tmp_path / "o" / "index.html").read_text()
    assert "--tempo none: one beat a second" in page
    r = CliRunner().invoke(main, ["capture", str(sidecar), "-o", str(tmp_path / "c"), "--tempo", "none", "--no-effort"])
    assert r.exit_code == 0, r.output
    assert "tempo 60 bpm (not estimated, --tempo none" in r.output and "(given)" not in r.output
    r = CliRunner().invoke(main, ["capture", str(sidecar), "-o", str(tmp_path / "d"), "--tempo", "fast"])
    assert r.exit_code == 2 and "'--tempo': 'fast' is not a number" in r.output and "'none'" in r.output


@pytest.mark.filterwarnings("default:no movement found")
def test_still_motion_says_no_beat_was_found_not_given(tmp_path):
    """Nothing moves (a truncated clip, a still dancer): 60 bpm, said to be no beat, never "(given)"."""
    joints, angles = build_motion([], TEMPO, beats=4)
    T = joints.shape[0]
    path = tmp_path / "still" / "truth.npz"
    write_truth(
        path,
        fps=25.0, times=np.arange(T) / 25.0, joint_names=np.asarray(JOINTS), joints=joints, angles=angles,
        root=joints[:, 0], landmarks3d=np.full((T, 33, 3), np.nan), keypoints=np.full((T, 33, 2), np.nan),
        visibility=np.zeros((T, 33)), K=np.eye(3), R=np.eye(3), t=np.zeros(3), image_size=np.array([64, 48]),
        score="{}", effort="{}", view="front", style="stick", body_height=Body().height,
    )  # fmt: skip
    # The command line reports the library's warning as one logged line.
    r = CliRunner().invoke(main, ["capture", str(path), "-o", str(tmp_path / "c"), "--no-effort"])
    assert r.exit_code == 0, r.output
    assert "c2n: warning:" in r.output and "no movement found" in r.output
    assert "tempo 60 bpm (no beat found: one beat a second" in r.output and "(given)" not in r.output


def test_command_line(sidecar, tmp_path):
    runner = CliRunner()
    r = runner.invoke(main, ["capture", str(sidecar), "-o", str(tmp_path / "c"), "--tempo", str(TEMPO), "--no-effort"])
    assert r.exit_code == 0, r.output
    assert "3 symbols" in r.output and "given" in r.output
    bad = tmp_path / "notes.txt"
    bad.write_text("hello")
    r = runner.invoke(main, ["capture", str(bad), "-o", str(tmp_path / "d")])
    assert r.exit_code == 2 and "unknown input type '.txt'" in r.output
    r = runner.invoke(main, ["capture", str(sidecar), "-o", str(tmp_path / "e"), "--grid", "x"])
    assert r.exit_code == 2 and "--grid" in r.output


def test_a_bad_tempo_is_named(tmp_path):
    with pytest.raises(PipelineError, match="--tempo"):
        capture(tmp_path / "x.bvh", tmp_path / "o", tempo=-1, progress=False)


@pytest.fixture(scope="module")
def marker_render(tmp_path_factory):
    """A colour-marker render of a right-arm raise, 320x240 (video, truth.npz, camera.toml)."""
    from capture2notation.notation.formats import loads
    from synthetic import render

    out = tmp_path_factory.mktemp("markers") / "r"
    score = loads("tempo: 90\n0 1 right_arm right middle\n1 1 right_arm place low\n", "lab")
    render.render_score(score, out, fps=25, size=(320, 240), view="front", style="markers", progress=False)
    return out


@pytest.mark.parametrize("calibrated", [False, True])
def test_rendered_video_through_markers_backend(marker_render, calibrated, tmp_path):
    """The video path: render (colour markers) → keypoints → fit → notation files and overlay.

    A corrupt ``truth.npz`` beside the video shows the capture never opens it
    (DESIGN.md, "What a capture may know"): the camera is estimated, or comes
    from the calibration file named explicitly.
    """
    clip = tmp_path / "clip"
    clip.mkdir()
    shutil.copy(marker_render / "video.mp4", clip / "video.mp4")
    (clip / "truth.npz").write_bytes(b"not a sidecar")
    calibration = marker_render / "camera.toml" if calibrated else None
    res = capture(
        clip / "video.mp4",
        tmp_path / "c",
        backend="markers",
        tempo=90,
        progress=False,
        effort=False,
        calibration=calibration,
    )
    assert res.kind == "video" and res.track is not None
    assert (tmp_path / "c" / "overlay.mp4").stat().st_size > 0
    with np.load(tmp_path / "c" / "capture.npz") as z:
        assert str(z["input_kind"]) == "video"
        assert z["keypoints"].shape == (res.n_frames, 33, 3)
        assert (
            np.isfinite(z["keypoints"][:, 16, :2]).all(axis=1).mean() > 0.9
        )  # right wrist marker seen (no depth from markers)
    # The arm's raise is found at the right time.
    arm = [s for s in res.score.symbols if s.part == "right_arm"]
    assert arm and arm[0].start == 0 and arm[0].level == "middle"
    assert 'src="overlay.mp4"' in (tmp_path / "c" / "index.html").read_text()


def test_a_saved_keypoint_track_gives_the_video_capture(marker_render, tmp_path):
    """``c2n keypoints`` then ``c2n capture TRACK.npz``: the video's score, without reading the video again."""
    from capture2notation.keypoints import extract

    track = extract(marker_render / "video.mp4", backend="markers", progress=False)
    saved = track.save(tmp_path / "track.npz")
    assert input_kind(saved) == "keypoints" and input_kind(marker_render / "truth.npz") == "truth"
    from_video = capture(
        marker_render / "video.mp4", tmp_path / "v", backend="markers", tempo=90, progress=False, effort=False
    )
    res = capture(saved, tmp_path / "k", tempo=90, progress=False, effort=False)
    assert res.kind == "keypoints" and res.n_frames == from_video.n_frames
    assert res.score.symbols == from_video.score.symbols
    assert not (tmp_path / "k" / "overlay.mp4").exists()
    assert any(s.startswith("overlay.mp4: no video (keypoints input)") for s in res.skipped)


def test_render_writes_its_camera_as_a_calibration(marker_render):
    from capture2notation.io.calibration import read_calibration
    from capture2notation.io.truth import read_truth

    cal = read_calibration(marker_render / "camera.toml")
    truth = read_truth(marker_render / "truth.npz")
    (cam,) = cal.cameras.values()
    assert cam.name == "r" and cam.image_size == (320, 240)
    np.testing.assert_allclose(cam.K, truth.K, rtol=1e-9)
    np.testing.assert_allclose(cam.R, truth.R, atol=1e-9)
    np.testing.assert_allclose(cam.t, truth.t, atol=1e-9)


def test_a_calibration_that_does_not_describe_the_clip_is_refused(marker_render, tmp_path):
    from capture2notation.errors import FittingError
    from capture2notation.io.calibration import Calibration, read_calibration, write_calibration

    (cam,) = read_calibration(marker_render / "camera.toml").cameras.values()
    small = tmp_path / "small.toml"
    write_calibration(Calibration.of([cam.scaled_to((160, 120))]), small)
    with pytest.raises(FittingError, match=r"320x240 but camera 'r' is calibrated for 160x120"):
        capture(
            marker_render / "video.mp4",
            tmp_path / "a",
            backend="markers",
            tempo=90,
            progress=False,
            effort=False,
            overlay=False,
            calibration=small,
        )
    two = tmp_path / "two.toml"
    other = replace(cam, name="left")
    write_calibration(Calibration.of([other, replace(cam, name="right")]), two)
    with pytest.raises(FittingError, match=r"no camera 'r' in the calibration \(it has left, right\)"):
        capture(
            marker_render / "video.mp4",
            tmp_path / "b",
            backend="markers",
            tempo=90,
            progress=False,
            effort=False,
            overlay=False,
            calibration=two,
        )
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_a_calibration_is_for_video_only(sidecar, tmp_path):
    with pytest.raises(PipelineError, match="a camera is for video input, not a truth file"):
        capture(sidecar, tmp_path / "o", tempo=90, progress=False, effort=False, calibration=tmp_path / "x.toml")


@pytest.mark.parametrize("rel", ["bvh/test_mocapbank.bvh", "bvh/jesse_dance.bvh"])
def test_bvh_fixtures_give_a_score_and_a_staff(fixture_path, rel, tmp_path):
    """Both fixture dances stand on a floor found from their feet (the library's
    warnings are errors here: no "is the floor height right?"), so their
    landings and weight changes are written as supports, not leg gestures.
    ``jesse_dance.bvh`` is inertial mocap whose floor drifts 10-15 cm between
    hops: a floor read as one constant height wrote no support at all."""
    res = capture(fixture_path(rel), tmp_path / "o", tempo=120, progress=False, effort=False)
    assert res.kind == "bvh" and len(res.score.symbols) >= 3
    grounded = [s for s in res.score.symbols if s.is_support and s.level is not None]
    assert len(grounded) >= 2, res.score
    assert read(tmp_path / "o" / "score.lab") == res.score
    svg = (tmp_path / "o" / "staff.svg").read_text()
    assert svg.startswith("<svg") or "<svg" in svg[:200]
    assert (tmp_path / "o" / "staff.png").stat().st_size > 1000


def test_a_kinect_recording_of_the_port_de_bras_gives_its_score(tmp_path):
    """The dancer's port de bras, written as a Kinect v2 CSV (sensor 2.5 m away,
    0.8 m up, 30 Hz), captures back to its arm and head symbols."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "io"))
    from test_kinect import _kinect_rows

    from capture2notation.compare.agreement import compare_scores
    from capture2notation.fitting import PoseModel
    from capture2notation.io.kinect import write_kinect_csv
    from synthetic.interpret import interpret
    from synthetic.phrases import phrase

    score = phrase("port_de_bras")
    motion = interpret(score, fps=30.0)
    model = PoseModel(motion.body)
    pts = model.forward(model.params(motion.angles, motion.root))
    T = pts.shape[0]
    csv_path = write_kinect_csv(
        tmp_path / "take.csv", np.arange(T) / 30.0, _kinect_rows(model, pts), np.full((T, 25), 2)
    )
    res = capture(csv_path, tmp_path / "o", tempo=score.tempo, progress=False, effort=False)
    assert res.kind == "kinect" and (tmp_path / "o" / "staff.svg").exists()
    a = compare_scores(score, res.score)
    # Measured 1.0 (direction + level per part per beat); the rounded arms'
    # bend and the last beat's timing differ slightly: Kinect has no hand tip.
    assert a.symbol_agreement >= 0.95, score_differences(score, res.score)


def _clicked_render(tmp_path, tempo=90):
    from capture2notation.notation.formats import loads
    from synthetic import render

    score = loads(
        f"tempo: {tempo}\n0 1 right_arm right middle\n1 1 right_arm place low\n2 1 left_arm left middle\n"
        "3 1 left_arm place low\n4 1 right_arm forward high\n5 1 right_arm place low\n",
        "lab",
    )
    render.render_score(
        score, tmp_path / "r", fps=25, size=(320, 240), view="front", style="markers", progress=False, audio="click"
    )
    return tmp_path / "r" / "video.mp4"


@pytest.mark.slow
def test_tempo_from_a_click_track(tmp_path):
    """A render with a click track: the sound's beat sets the tempo, and the page says so."""
    pytest.importorskip("librosa")
    video = _clicked_render(tmp_path, tempo=97)
    # The renderer's camera, passed as a user with a calibration would: the
    # marker figure has no world landmarks to estimate the camera and floor
    # from, and this test is about the sound, not the floor.
    cal = video.parent / "camera.toml"
    res = capture(
        video, tmp_path / "c", backend="markers", progress=False, effort=False, overlay=False, calibration=cal
    )
    assert res.score.tempo == 97 and res.segmentation.tempo_source == "the sound track and the movements"
    assert "estimated from the sound track and the movements" in (tmp_path / "c" / "index.html").read_text()
    # --tempo none ignores the sound: one beat a second.
    none = capture(
        video,
        tmp_path / "n",
        backend="markers",
        tempo="none",
        progress=False,
        effort=False,
        overlay=False,
        calibration=cal,
    )
    assert none.score.tempo == 60 and none.segmentation.tempo_source == "none"


def test_without_librosa_the_capture_says_how_to_read_the_sound(tmp_path, monkeypatch):
    video = _clicked_render(tmp_path)
    monkeypatch.setitem(sys.modules, "librosa", None)
    res = capture(video, tmp_path / "c", backend="markers", progress=False, effort=False, overlay=False)
    assert res.segmentation.tempo_source == "the movements"
    assert "pip install 'capture2notation[audio]'" in res.tempo_text


def test_render_command_line_audio_options(tmp_path):
    score = tmp_path / "p.lab"
    score.write_text("tempo: 120\n0 1 right_arm right middle\n")
    runner = CliRunner()
    r = runner.invoke(main, ["render", str(score), "-o", str(tmp_path / "a"), "--size", "64x48", "--audio", "click"])
    assert r.exit_code == 0, r.output
    assert "with a click track" in r.output
    from capture2notation.io.audio import read_audio

    assert read_audio(tmp_path / "a" / "video.mp4") is not None
    r = runner.invoke(main, ["render", str(score), "-o", str(tmp_path / "b"), "--png", "--audio", "click"])
    assert r.exit_code == 2 and "--png" in r.output
    r = runner.invoke(main, ["render", str(score), "-o", str(tmp_path / "c"), "--audio", str(tmp_path / "no.mp3")])
    assert r.exit_code == 2 and "no such file" in r.output


def test_one_movement_is_no_beat_and_says_so(tmp_path):
    """One movement from the first frame: a single key time, no beat to find."""
    joints, angles = build_motion([(0, 1, "right_shoulder", arm_angles("right", "middle"))], TEMPO, beats=3)
    T = joints.shape[0]
    path = tmp_path / "one" / "truth.npz"
    write_truth(
        path,
        fps=25.0, times=np.arange(T) / 25.0, joint_names=np.asarray(JOINTS), joints=joints, angles=angles,
        root=joints[:, 0], landmarks3d=np.full((T, 33, 3), np.nan), keypoints=np.full((T, 33, 2), np.nan),
        visibility=np.zeros((T, 33)), K=np.eye(3), R=np.eye(3), t=np.zeros(3), image_size=np.array([64, 48]),
        score="{}", effort="{}", view="front", style="stick", body_height=Body().height,
    )  # fmt: skip
    res = capture(path, tmp_path / "c", progress=False, effort=False)
    assert res.score.tempo == 60 and res.segmentation.tempo_source == "no beat"
    assert res.tempo_text.startswith(" (no beat found: one beat a second")
    assert [s.part for s in res.score.symbols] == ["right_arm"]


@pytest.mark.slow
@pytest.mark.parametrize("rel", ["mediapipe/pose_squats.mp4", "bvh/jesse_dance.bvh", "bvh/test_mocapbank.bvh"])
def test_emotion_not_read_outside_the_port_de_bras(rel, fixture_path, tmp_path):
    """A squat video and the fixture BVH dances are no port de bras: the emotion is not read, with reasons."""
    out = tmp_path / "c"
    r = CliRunner().invoke(main, ["capture", str(fixture_path(rel)), "-o", str(out)])
    assert r.exit_code == 0, r.output
    data = json.loads((out / "effort.json").read_text(encoding="utf-8"))
    assert data["emotion"] is None and not data["emotion_read"]
    assert data["emotion_domain"]["reasons"]
    assert "emotion: not read: " in r.output
    assert "Emotion: not read: " in (out / "index.html").read_text(encoding="utf-8")


@pytest.mark.filterwarnings("default:the floor is never seen")
def test_feet_never_seen_write_no_supports_and_say_so(fixture_path, tmp_path):
    """The Kinect clip's feet are inferred by the sensor (confidence 0.3), never
    tracked: no floor can be found from them, so no support (and no flight) is
    invented; the run says so in one warning."""
    with pytest.warns(UserWarning, match=r"the floor is never seen \(a foot tracked in only 0 % of 377 frames\)"):
        res = capture(fixture_path("kinect/joints.csv"), tmp_path / "o", tempo=100, progress=False, effort=False)
    assert not [s for s in res.score.symbols if s.is_support]


def test_floor_option_moves_the_floor_of_a_motion_file(fixture_path, tmp_path):
    """``--floor`` replaces the floor found from the feet (a height in the
    file's own coordinates once read): given 30 cm below the file's lowest
    joint, the dancer's feet stay 30 cm clear of it and no support is written;
    given at that lowest joint, the feet reach z = 0."""
    from capture2notation.io.bvh import parse_bvh, read_bvh_points

    path = fixture_path("bvh/test_mocapbank.bvh")
    points, _conf, _head, _fps = read_bvh_points(parse_bvh(path), None, where=path)
    lowest = float(np.nanmin(points[..., 2]))
    with pytest.warns(UserWarning, match="feet on the floor in only"):
        clear = capture(path, tmp_path / "a", tempo=120, progress=False, effort=False, floor=lowest - 0.30)
    assert float(np.nanmin(np.asarray(clear.motion.joints)[..., 2])) == pytest.approx(0.30, abs=0.05)
    assert not [s for s in clear.score.symbols if s.is_support and s.level is not None]
    at = capture(path, tmp_path / "b", tempo=120, progress=False, effort=False, floor=lowest)
    assert float(np.nanmin(np.asarray(at.motion.joints)[..., 2])) == pytest.approx(0.0, abs=0.05)


@pytest.mark.slow
@pytest.mark.filterwarnings("default:the floor is never seen")
def test_a_video_whose_feet_are_out_of_frame_writes_no_supports(fixture_path, tmp_path):
    """The squats video cut off at mid-thigh: the feet are never in the image,
    so the floor cannot be seen.  The capture says so in one warning and
    writes the arms and legs it sees, never an invented support."""
    import cv2

    src = cv2.VideoCapture(str(fixture_path("mediapipe/pose_squats.mp4")))
    fps = src.get(cv2.CAP_PROP_FPS)
    frames = []
    while True:
        ok, frame = src.read()
        if not ok:
            break
        frames.append(frame)
    src.release()
    height, width = frames[0].shape[:2]
    cut = int(0.55 * height)  # below the hips, above the knees at full depth
    video = tmp_path / "no_feet.mp4"
    out = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"mp4v"), fps, (width, cut))
    for frame in frames:
        out.write(frame[:cut])
    out.release()
    with pytest.warns(UserWarning, match=r"the floor is never seen \(a foot tracked in only 0 % of 65 frames\)"):
        res = capture(video, tmp_path / "o", tempo=60, progress=False, effort=False, overlay=False)
    assert res.score.symbols
    assert not [s for s in res.score.symbols if s.is_support]


@pytest.mark.slow
def test_squats_stand_on_both_feet(fixture_path, tmp_path):
    """``pose_squats.mp4``: a woman squats three times (knees past 100°) with
    both feet flat on the floor throughout.  Each squat is one low support
    on both feet and a return to middle: never a support on one foot, never
    a leg gesture (issue 13)."""
    res = capture(
        fixture_path("mediapipe/pose_squats.mp4"), tmp_path / "o", tempo=60, progress=False, effort=False, overlay=False
    )
    supports = [s for s in res.score.symbols if s.is_support]
    assert [(s.part, s.direction) for s in supports] == [("support", "place")] * len(supports), supports
    levels = [s.level for s in supports]
    assert levels.count("low") == 3, levels
    # Low and middle alternate: each squat is one low support.
    assert all(a != b for a, b in itertools.pairwise(levels)), levels
    assert not [s for s in res.score.symbols if s.part.endswith("_leg")]


def test_an_overlay_that_fails_beside_the_notation_fails_the_capture_and_leaves_nothing(
    marker_render, tmp_path, monkeypatch
):
    # the overlay is written in a thread while the notation files are made:
    # its error must still reach the caller, after the thread is joined, and
    # the staging folder must go
    from capture2notation.errors import KeypointError
    from capture2notation.keypoints import overlay

    def broken(video, track, out, fps=None, stop=None):
        raise KeypointError(f"{video}: frame 3 is 10x10, the track was made on 640x480")

    monkeypatch.setattr(overlay, "write_overlay", broken)
    with pytest.raises(KeypointError, match="frame 3"):
        capture(marker_render / "video.mp4", tmp_path / "c", backend="markers", tempo=90, progress=False, effort=False)
    assert not (tmp_path / "c").exists()
    assert not list(tmp_path.glob(".c.partial-*"))


def test_fitted_captures_take_the_fitted_capture_prior_for_effort(tmp_path, monkeypatch):
    """Video, keypoint tracks and several cameras are fitted to a pose model's
    keypoints, whose joint error is smooth: their Effort takes
    ``CAPTURE_RHO_RANGE``; motion files keep the default prior.  ``c2n
    effort DIR`` reads which from ``capture.npz`` (an older file without
    ``input_kind``: fitted when it holds keypoints)."""
    import importlib

    from capture2notation.effort.likelihood import CAPTURE_RHO_RANGE
    from pipelines.capture import effort_sampler_options
    from pipelines.capture_input import is_fitted

    assert [is_fitted(k) for k in ("video", "keypoints", "multiview")] == [True, True, True]
    assert [is_fitted(k) for k in ("bvh", "kinect", "truth")] == [False, False, False]
    assert effort_sampler_options(True) == {"rho_range": CAPTURE_RHO_RANGE}
    assert effort_sampler_options(False) == {}

    command = importlib.import_module("pipelines.commands.effort")
    T = 30
    base = {"joints": np.zeros((T, len(JOINTS), 3)), "fps": np.float64(25.0)}
    cases = {
        "video": ({"input_kind": np.asarray("video")}, True),
        "bvh": ({"input_kind": np.asarray("bvh")}, False),
        "old video": ({"keypoints": np.ones((T, 33, 3))}, True),
        "old motion file": ({"keypoints": np.full((T, 33, 3), np.nan)}, False),
        "bare": ({}, False),
    }
    for name, (extra, fitted) in cases.items():
        np.savez(tmp_path / f"{name}.npz", **base, **extra)
        assert command.load_capture(tmp_path / f"{name}.npz")["fitted"] is fitted, name

    seen = {}

    def fake_estimate(*args, sampler_kw=None, **kwargs):
        seen["sampler_kw"] = sampler_kw
        raise RuntimeError("stop here")

    monkeypatch.setattr(command, "estimate_effort", fake_estimate)
    folder = tmp_path / "cap"
    folder.mkdir()
    np.savez(folder / "capture.npz", **base, input_kind=np.asarray("keypoints"))
    write(EXPECTED, folder / "score.lab")
    with pytest.raises(RuntimeError, match="stop here"):
        command.run_effort(folder, workers=1, plots=False)
    assert seen["sampler_kw"] == {"rho_range": CAPTURE_RHO_RANGE}
