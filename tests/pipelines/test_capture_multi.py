"""Capture from two calibrated cameras: geometry, the fit, bad input, and the whole path."""

from __future__ import annotations

import os
import shutil

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from capture2notation.errors import PipelineError
from capture2notation.fitting.fit3d import fit_points3d
from capture2notation.fitting.triangulate import landmarks_to_joints, triangulate
from capture2notation.io.calibration import Calibration, read_calibration, write_calibration
from capture2notation.io.truth import read_truth
from pipelines.capture import capture
from pipelines.cli import main
from synthetic import builtin_phrases
from synthetic.render import render_score

VIEWS = ("front", "side")
#: DESIGN.md / issue 15's MPJPE target for calibrated cameras, metres.
MPJPE_TARGET_M = 0.03


def _render(root, size, style="markers"):
    score = builtin_phrases()["figure7"]
    cams = []
    for v in VIEWS:
        render_score(score, root / v, fps=25.0, size=size, view=v, style=style, progress=False)
        (cam,) = read_calibration(root / v / "camera.toml").cameras.values()
        cams.append(cam)
    write_calibration(Calibration.of(cams), root / "cameras.toml")
    return score, root


@pytest.fixture(scope="module")
def two_views(tmp_path_factory):
    return _render(tmp_path_factory.mktemp("two_views"), (320, 240))


def test_perfect_keypoints_of_two_views_fit_within_the_target(two_views):
    """The renderer's own landmarks (exact pixels) seen by both cameras: triangulation + 3D fit."""
    _, root = two_views
    cal = read_calibration(root / "cameras.toml")
    truths = [read_truth(root / v / "truth.npz") for v in VIEWS]
    uv = np.stack([np.asarray(t.keypoints, float) for t in truths])
    vis = np.ones(uv.shape[:3])
    points, conf, _ = triangulate(uv, vis, [cal[v] for v in VIEWS])
    joints, jconf, virtual = landmarks_to_joints(points, conf)
    fit = fit_points3d(joints, jconf, truths[0].fps, virtual=virtual)
    err = np.linalg.norm(np.asarray(fit.joints) - np.asarray(truths[0].joints), axis=-1)
    assert float(np.nanmean(err)) < MPJPE_TARGET_M


@pytest.mark.parametrize("chunk", [None, 24])
def test_a_view_that_misplaces_an_arm_is_outvoted_by_the_bones_and_the_other_view(two_views, chunk, monkeypatch):
    """The side view puts the left arm 12 px too low for a stretch (a hidden arm's
    guess; at 320×240 about 6 cm).  Triangulated, the two rays meet nowhere and
    the fit to the points lands between them; fitted to the views' keypoints,
    the arm of fixed length keeps to the front view, which sees it right.
    `chunk`: the solver's batches as a long clip's (each view's targets cut alike)."""
    import importlib

    from capture2notation.body import joint_index

    if chunk:
        monkeypatch.setattr(importlib.import_module("capture2notation.fitting.solver"), "CHUNK", chunk)
    from capture2notation.fitting import Camera
    from capture2notation.fitting.triangulate import LANDMARK_TARGETS

    _, root = two_views
    cal = read_calibration(root / "cameras.toml")
    cams = [cal[v] for v in VIEWS]
    truths = [read_truth(root / v / "truth.npz") for v in VIEWS]
    uv = np.stack([np.asarray(t.keypoints, float) for t in truths])
    vis = np.ones(uv.shape[:3])
    T = uv.shape[1]
    bad = slice(T // 4, T // 2)
    uv[1, bad, [13, 15, 17, 19, 21], 1] += 12.0  # left elbow, wrist and hand points, downwards
    points, conf, _ = triangulate(uv, vis, cams)
    joints, jconf, virtual = landmarks_to_joints(points, conf)
    lm = np.array([i for i, _ in LANDMARK_TARGETS])
    names = [n for _, n in LANDMARK_TARGETS]
    views = [
        (Camera(np.asarray(c.K), np.asarray(c.R), np.asarray(c.t), c.image_size), uv[v][:, lm], vis[v][:, lm], names)
        for v, c in enumerate(cams)
    ]
    truth = np.asarray(truths[0].joints)[bad, joint_index("left_wrist")]

    def wrist_error(fit):
        return float(np.median(np.linalg.norm(np.asarray(fit.joints)[bad, joint_index("left_wrist")] - truth, axis=-1)))

    points_only = wrist_error(fit_points3d(joints, jconf, truths[0].fps, virtual=virtual))
    with_views = wrist_error(fit_points3d(joints, jconf, truths[0].fps, virtual=virtual, views=views))
    assert points_only > MPJPE_TARGET_M  # the injected error matters
    assert with_views < 0.5 * points_only and with_views < MPJPE_TARGET_M


def test_two_view_marker_capture_writes_every_output(two_views, tmp_path):
    _, root = two_views
    res = capture(
        [root / v / "video.mp4" for v in VIEWS], tmp_path / "out", backend="markers", tempo=60,
        calibration=root / "cameras.toml", progress=False, effort=False,
    )  # fmt: skip
    assert res.kind == "multiview"
    for v in VIEWS:
        assert (tmp_path / "out" / f"overlay_{v}.mp4").is_file()
        assert f"overlay_{v}.mp4" in res.files
    page = (tmp_path / "out" / "index.html").read_text()
    assert all(f'src="overlay_{v}.mp4"' in page for v in VIEWS)
    assert res.n_frames == read_truth(root / "front" / "truth.npz").n_frames


def test_a_failed_fit_leaves_no_overlays_drawn_beside_it(two_views, tmp_path, monkeypatch):
    # The overlays are drawn while the fit runs: a fit that fails must not
    # leave their scratch folder or a partial output behind.
    import importlib

    from capture2notation.errors import FittingError

    _, root = two_views
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(scratch))

    def fail(*args, **kwargs):
        raise FittingError("no joint was seen by two cameras at once")

    monkeypatch.setattr(importlib.import_module("capture2notation.fitting.multiview"), "fit_views", fail)
    with pytest.raises(PipelineError, match="two cameras"):
        capture(
            [root / v / "video.mp4" for v in VIEWS], tmp_path / "out", backend="markers", tempo=60,
            calibration=root / "cameras.toml", progress=False, effort=False,
        )  # fmt: skip
    assert list(scratch.iterdir()) == []
    assert not (tmp_path / "out").exists()


def test_closing_the_view_files_stops_an_overlay_being_drawn(tmp_path, monkeypatch):
    # Ctrl-C during a long fit: the overlays drawn beside it give up within
    # a frame instead of decoding the rest of an hour's clip.
    import importlib
    import threading

    from capture2notation.io.video import Frame
    from capture2notation.keypoints import KeypointTrack
    from pipelines.capture_multi import ViewFiles

    overlay = importlib.import_module("capture2notation.keypoints.overlay")
    n, drawn, started = 100_000, [], threading.Event()

    def frames(video, fps=None, stop=None):
        for i in range(n):
            drawn.append(i)
            started.set()
            yield Frame(i, i / 25.0, np.zeros((48, 64, 3), np.uint8))

    monkeypatch.setattr(overlay, "iter_frames", frames)
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    track = KeypointTrack.empty(n, 25.0, (64, 48), backend="markers")
    views = ViewFiles(["front", "side"], [tmp_path / "a.mp4", tmp_path / "b.mp4"], [track, track], overlay=True)
    started.wait()
    views.close()
    assert len(drawn) < n // 10
    assert list(tmp_path.iterdir()) == []


def test_the_keypoints_of_every_view_show_one_progress(two_views, tmp_path, capsys):
    # The views run on threads side by side; one count covers them all
    # (a line in a log, a bar on a terminal).
    _, root = two_views
    capture(
        [root / v / "video.mp4" for v in VIEWS], tmp_path / "out", backend="markers", tempo=60,
        calibration=root / "cameras.toml", progress=True, effort=False, overlay=False,
    )  # fmt: skip
    n = read_truth(root / "front" / "truth.npz").n_frames
    assert f"keypoints (markers, 2 clips): {2 * n}/{2 * n} frames (100 %)" in capsys.readouterr().err


def test_the_spine_is_placed_by_the_fit_not_by_one_views_guess(two_views, tmp_path, monkeypatch):
    """Exact keypoints from both views: every landmark joint is triangulated, and the
    waist and chest, which no landmark measures, come out where the dancer's are
    (one view's monocular fit of them had put the waist 7 cm off here, 5 cm on
    random scores)."""
    from dataclasses import replace

    import pipelines.capture_multi as cm
    from capture2notation.body import joint_index
    from synthetic.identity_errors import truth_track

    _, root = two_views

    def exact_tracks(videos, *args, **kwargs):
        # Exact pixels, but no world landmarks: one view's fit must guess depth.
        tracks = [truth_track(dict(np.load(v.parent / "truth.npz"))) for v in videos]
        return [replace(t, world=np.full_like(t.world, np.nan), backend="blazepose") for t in tracks]

    monkeypatch.setattr(cm, "_keypoints", exact_tracks)
    res = capture(
        [root / v / "video.mp4" for v in VIEWS], tmp_path / "out", tempo=60,
        calibration=root / "cameras.toml", progress=False, effort=False, overlay=False,
    )  # fmt: skip
    truth = np.asarray(read_truth(root / "front" / "truth.npz").joints)
    got = np.asarray(res.motion.joints)
    for name in ("waist", "chest"):
        j = joint_index(name)
        err = np.linalg.norm(got[:, j] - truth[: len(got), j], axis=-1)
        assert float(np.nanmedian(err)) < 0.01, name


def _copy_frames(src, dst, fps=None, n=None):
    """Re-encode `src` to `dst` at `fps` (default its own), keeping its first `n` frames."""
    cap = cv2.VideoCapture(str(src))
    rate = fps or cap.get(cv2.CAP_PROP_FPS)
    w, h = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
    os.makedirs(dst.parent, exist_ok=True)
    out = cv2.VideoWriter(str(dst), cv2.VideoWriter_fourcc(*"mp4v"), rate, (w, h))
    i = 0
    while n is None or i < n:
        ok, frame = cap.read()
        if not ok:
            break
        out.write(frame)
        i += 1
    cap.release()
    out.release()
    return dst


def _run(videos, cal, out):
    return capture([str(v) for v in videos], out, backend="markers", tempo=60, calibration=cal,
                   progress=False, effort=False)  # fmt: skip


def test_bad_inputs_name_the_file_and_the_mismatch(two_views, tmp_path):
    _, root = two_views
    front, side, cal = root / "front" / "video.mp4", root / "side" / "video.mp4", root / "cameras.toml"
    other = shutil.copy(side, tmp_path / "other.mp4")
    with pytest.raises(PipelineError, match=r"other\.mp4.*no camera 'other'"):
        _run([front, other], cal, tmp_path / "a")
    big = Calibration.of([c.scaled_to((640, 480)) for c in read_calibration(cal).cameras.values()])
    write_calibration(big, tmp_path / "big.toml")
    with pytest.raises(PipelineError, match=r"front.video\.mp4.*320x240.*640x480"):
        _run([front, side], tmp_path / "big.toml", tmp_path / "b")
    slow = _copy_frames(side, tmp_path / "rate" / "side" / "video.mp4", fps=12.5)
    with pytest.raises(PipelineError, match=r"rate.side.video\.mp4.*12\.5 fps differs.*25 fps"):
        _run([front, slow], cal, tmp_path / "c")
    short = _copy_frames(side, tmp_path / "short" / "side" / "video.mp4", n=50)
    with pytest.raises(PipelineError, match=r"short.side.video\.mp4: 50 frames but .*front.video\.mp4 has 101"):
        _run([front, short], cal, tmp_path / "d")
    with pytest.raises(PipelineError, match="calibration"):
        capture([str(front), str(side)], tmp_path / "e", backend="markers", progress=False)
    assert not (tmp_path / "a").exists() and not (tmp_path / "d").exists()


def test_command_line_mismatch_is_one_line_exit_2(two_views, tmp_path):
    _, root = two_views
    other = shutil.copy(root / "side" / "video.mp4", tmp_path / "other.mp4")
    r = CliRunner().invoke(
        main,
        ["capture", str(root / "front" / "video.mp4"), str(other), "-o", str(tmp_path / "c"), "--backend", "markers",
         "--calibration", str(root / "cameras.toml"), "--no-effort", "--tempo", "60"],
    )  # fmt: skip
    assert r.exit_code == 2, r.output
    errors = [ln for ln in r.output.splitlines() if "error" in ln]
    assert len(errors) == 1 and errors[0].startswith("c2n: error:") and "other.mp4" in errors[0]


@pytest.mark.slow
def test_two_view_blazepose_capture_of_a_phrase_agrees_with_its_score(tmp_path):
    """Front + side, BlazePose, 640x480, the renders' cameras given: Figure 7."""
    from capture2notation.compare.agreement import compare_scores

    score, root = _render(tmp_path, (640, 480), style="mannequin")
    res = capture(
        [root / v / "video.mp4" for v in VIEWS], tmp_path / "out", tempo=score.tempo,
        calibration=root / "cameras.toml", progress=False, effort=False, overlay=False,
    )  # fmt: skip
    # Issue 15: one view reaches at best 80 % (front) on whole phrases; a second camera must beat that.
    assert compare_scores(score, res.score).symbol_agreement > 0.80
    # And its joints must be nearer the truth than the front camera's alone (calibrated likewise).
    one = capture(
        root / "front" / "video.mp4", tmp_path / "one", tempo=score.tempo, calibration=root / "cameras.toml",
        progress=False, effort=False, overlay=False,
    )  # fmt: skip
    truth = np.asarray(read_truth(root / "front" / "truth.npz").joints)

    def mpjpe(m):
        return float(np.nanmean(np.linalg.norm(np.asarray(m.motion.joints) - truth, axis=-1)))

    assert mpjpe(res) < mpjpe(one)
