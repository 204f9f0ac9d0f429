"""BlazePose through onnxruntime against MediaPipe's own reference results."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from capture2notation.keypoints import extract, extract_frames

pytestmark = pytest.mark.model


def test_pose_jpg_within_mediapipe_tolerance(fixture_path, blazepose):
    """All 33 landmarks within 15 px per coordinate, world within 0.2 m."""
    expected = json.loads(fixture_path("mediapipe/pose_expected.json").read_text())
    image = cv2.imread(str(fixture_path("mediapipe/pose.jpg")))
    est = blazepose.estimate_image(image)
    assert est.presence > 0.9
    px_err = np.abs(est.xy[:, :2] - np.array(expected["pixel_xy"]))
    world_err = np.abs(est.world - np.array(expected["world_xyz_m"]))
    worst = int(np.argmax(px_err.max(axis=1)))
    assert px_err.max() <= 15.0, f"landmark {expected['landmark_names'][worst]} off by {px_err[worst]} px"
    assert world_err.max() <= 0.2, f"world landmarks off by up to {world_err.max():.3f} m"
    # Measured: 6.9 px and 0.08 m; a regression in the crop loop shows here first.
    assert np.median(px_err) <= 4.0


def test_pose_squats_error_distribution(fixture_path, blazepose):
    """>= 95 % of coordinates within 31 px (tfjs tolerance), median <= 8 px."""
    expected = np.array(json.loads(fixture_path("mediapipe/pose_squats.full.json").read_text()))
    track = extract(fixture_path("mediapipe/pose_squats.mp4"), estimator=blazepose)
    assert len(track) == expected.shape[0] == 65
    assert track.fps == pytest.approx(5.0) and tuple(track.image_size) == (720, 1280)
    err = np.abs(track.xy[:, :, :2] - expected[:, :, :2]).ravel()
    assert np.isfinite(err).all()
    within = (err <= 31.0).mean()
    q = np.percentile(err, [50, 90, 95, 99])
    assert within >= 0.95, f"only {within:.1%} within 31 px; percentiles 50/90/95/99 = {q}"
    assert q[0] <= 8.0, f"median {q[0]:.2f} px"
    # Relative depth z uses MediaPipe's scale (z * image width): same slope.
    slope = np.polyfit(expected[:, :, 2].ravel(), track.xy[:, :, 2].ravel(), 1)[0]
    assert 0.85 <= slope <= 1.15, f"z slope {slope:.3f} against MediaPipe's"  # measured 0.96
    # Hip-centred world landmarks agree too (no MediaPipe tolerance; ours: 0.2 m at p95).
    world = np.array(json.loads(fixture_path("mediapipe/pose_squats_3d.full.json").read_text()))
    assert np.percentile(np.abs(track.world - world), 95) <= 0.2


def test_lost_person_is_reacquired(fixture_path, blazepose):
    """A blank frame gives NaN + zero confidence; the person is found again after it."""
    image = cv2.imread(str(fixture_path("mediapipe/pose.jpg")))
    blank = np.full_like(image, 127)
    track = extract_frames([image, image, blank, image], fps=10.0, estimator=blazepose)
    assert np.isnan(track.xy[2]).all() and (track.visibility[2] == 0).all() and track.presence[2] == 0
    assert np.isnan(track.crops[2]).all()
    ref = blazepose.estimate_image(image)
    for t in (0, 1, 3):
        assert track.presence[t] > 0.9
        assert np.abs(track.xy[t, :, :2] - ref.xy[:, :2]).max() < 15.0


def test_tracking_follows_a_moving_person(fixture_path, blazepose):
    """Shift the photo 12 px per frame: the tracked crop must follow it."""
    image = cv2.imread(str(fixture_path("mediapipe/pose.jpg")))
    shifts = np.arange(6) * 12.0
    frames = [
        cv2.warpAffine(image, np.float32([[1, 0, s], [0, 1, 0]]), image.shape[1::-1], borderMode=cv2.BORDER_REPLICATE)
        for s in shifts
    ]
    track = extract_frames(frames, fps=30.0, estimator=blazepose, smooth=False)
    hips = track.xy[:, 23:25, 0].mean(axis=1)
    np.testing.assert_allclose(hips - hips[0], shifts, atol=6.0)


def _small_in_corner(image, factor):
    """`image` shrunk by `factor` into the bottom-right corner of a grey frame of its size."""
    small = cv2.resize(image, None, fx=factor, fy=factor, interpolation=cv2.INTER_AREA)
    frame = np.full_like(image, 200)
    h, w = small.shape[:2]
    H, W = image.shape[:2]
    frame[H - h - 5 : H - 5, W - w - 5 : W - 5] = small
    return frame, np.array([W - w - 5, H - h - 5], dtype=float)


def test_small_person_found_by_searching_crops(fixture_path, blazepose):
    """A person a fifth of the frame's height is missed by the whole frame and found by the search."""
    image = cv2.imread(str(fixture_path("mediapipe/pose.jpg")))
    ref = blazepose.estimate_image(image).xy[:, :2]
    frame, offset = _small_in_corner(image, 0.35)
    assert blazepose.estimate_image(frame, search=False).presence < 0.5
    est = blazepose.estimate_image(frame)
    assert est.presence > 0.9
    # MediaPipe's own tolerance on pose.jpg is 15 px at full size; scaled, ~5 px.
    err = np.linalg.norm(est.xy[:, :2] - (ref * 0.35 + offset), axis=1)
    assert np.median(err) < 5.0


def test_search_runs_at_a_bounded_rate(fixture_path, blazepose_session):
    """While nobody is in the frame, crops are searched once per SEARCH_INTERVAL_S, not every frame."""
    from capture2notation.keypoints.blazepose import SEARCH_INTERVAL_S, BlazePose, search_crops

    calls = []

    class Counting:
        def __init__(self, session):
            self._session = session

        def get_inputs(self):
            return self._session.get_inputs()

        def run(self, *args, **kwargs):
            calls.append(1)
            return self._session.run(*args, **kwargs)

    est = BlazePose(session=Counting(blazepose_session))
    image = cv2.imread(str(fixture_path("mediapipe/pose.jpg")))
    blank = np.full_like(image, 127)
    fps, seconds = 10.0, 2.0
    n = int(fps * seconds)
    track = extract_frames([blank + (i % 2) for i in range(n)], fps=fps, estimator=est)
    assert (track.presence == 0).all()
    per_search = sum(len(c) for c in search_crops(image.shape[1], image.shape[0]))
    searches = int(np.ceil(seconds / SEARCH_INTERVAL_S))
    assert len(calls) == n + searches * per_search
