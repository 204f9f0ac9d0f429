"""Colour markers: detection accuracy, identities, unseen markers, renderer set."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from capture2notation.body.skeleton import JOINT_TO_BLAZEPOSE
from capture2notation.errors import KeypointError
from capture2notation.keypoints import extract_frames
from capture2notation.keypoints.markers import MarkerSpec, MarkerTracker, detect_blobs

GREEN = MarkerSpec.from_colour("left_wrist", (0, 200, 0))
MAGENTA_L = MarkerSpec.from_colour("left_ankle", (200, 0, 200))
MAGENTA_R = MarkerSpec.from_colour("right_ankle", (200, 0, 200))
RED = MarkerSpec.from_colour("nose", (0, 0, 220))


def _disc(img, xy, colour, r=6.0):
    """Anti-aliased disc at a sub-pixel centre (pixel centres at integers)."""
    shift = 4
    c = tuple(round(v * (1 << shift)) for v in xy)
    cv2.circle(img, c, int(r * (1 << shift)), colour, -1, cv2.LINE_AA, shift)


def _scene(points, size=(160, 120)):
    img = np.full((size[1], size[0], 3), 128, np.uint8)  # grey: saturation 0
    for xy, colour in points:
        _disc(img, xy, colour)
    return img


def test_subpixel_centres():
    rng = np.random.default_rng(3)
    errs = []
    for _ in range(20):
        p, q = rng.uniform(15, 105, 2), rng.uniform(15, 105, 2) + (20, 0)
        img = _scene([(p, (0, 200, 0)), (q, (0, 0, 220))])
        pos = MarkerTracker([GREEN, RED]).detect(img)
        errs += [np.linalg.norm(pos[15] - p), np.linalg.norm(pos[0] - q)]
    assert np.median(errs) <= 0.25 and max(errs) <= 0.6


def test_red_hue_wraps_around():
    assert RED.hsv_low[0] > RED.hsv_high[0]  # red straddles H = 0
    img = _scene([((50.0, 60.0), (40, 0, 220))])  # a red leaning to magenta
    hsv = cv2.cvtColor(img, cv2.COLOR_BGR2HSV)
    cents, _ = detect_blobs(RED.mask(hsv))
    np.testing.assert_allclose(cents[0], (50, 60), atol=0.3)


def test_shared_colour_keeps_identities_while_moving():
    """Two markers of one colour keep their landmark while they move and cross in y."""
    frames, truth = [], []
    for t in range(8):
        left, right = np.array([40.0, 20 + 10 * t]), np.array([110.0, 90 - 10 * t])
        frames.append(_scene([(left, (200, 0, 200)), (right, (200, 0, 200))]))
        truth.append((left, right))
    tracker = MarkerTracker([MAGENTA_L, MAGENTA_R])
    tracker._last[27], tracker._last[28] = truth[0]  # identities known at the start
    for img, (left, right) in zip(frames, truth):
        r = tracker.process(img, 0.0)
        np.testing.assert_allclose(r.xy[27, :2], left, atol=0.5)
        np.testing.assert_allclose(r.xy[28, :2], right, atol=0.5)


def test_unseen_markers_are_nan_with_zero_visibility():
    both = _scene([((40.0, 40.0), (0, 200, 0)), ((100.0, 60.0), (0, 0, 220))])
    only_red = _scene([((100.0, 60.0), (0, 0, 220))])
    nothing = _scene([])
    track = extract_frames([both, only_red, nothing], fps=10, backend="markers", markers=[GREEN, RED])
    assert track.backend == "markers"
    assert track.visibility[0, 15] == 1 and track.visibility[1, 15] == 0
    assert np.isnan(track.xy[1, 15]).all() and np.isfinite(track.xy[1, 0, :2]).all()
    np.testing.assert_allclose(track.presence, [1.0, 0.5, 0.0])
    assert np.isnan(track.xy[2]).all() and np.isnan(track.world).all()
    # Landmarks without a marker are always missing.
    assert np.isnan(track.xy[:, 11]).all() and (track.visibility[:, 11] == 0).all()


def test_bad_specs_are_rejected():
    with pytest.raises(KeypointError, match="landmark 40"):
        MarkerSpec(40, (0, 0, 0), (10, 255, 255))
    with pytest.raises(KeypointError, match="hsv_high"):
        MarkerSpec(0, (0, 0, 0), (200, 255, 255))
    with pytest.raises(KeypointError, match="at least one"):
        MarkerTracker([])


def _marker_render_case(demo_pose, view, n_frames=10):
    from synthetic import render

    pose = demo_pose(n_frames)
    cam = render.Camera.for_view(view, (640, 480), pose.body.height)
    truth = render.truth_fields(pose, cam)
    markers = render.make_renderer(pose, cam, "markers")
    drawn = np.zeros((len(markers), 33), bool)  # which landmarks' markers are drawn
    for k, joint in enumerate(render.MARKER_JOINTS):
        if joint in JOINT_TO_BLAZEPOSE:
            drawn[:, JOINT_TO_BLAZEPOSE[joint]] = markers.visible[:, k]
    truth["drawn"] = drawn
    return [markers.frame(i) for i in range(len(markers))], pose.fps, truth


@pytest.mark.parametrize("view", ["front", "side"])
def test_renderer_markers_median_error(demo_pose, view):
    """The renderer's marker style: median error <= 2 px on the visible markers."""
    frames, fps, truth = _marker_render_case(demo_pose, view)
    tracker = MarkerTracker()  # the renderer's colours by default
    track = extract_frames(frames, fps, backend="markers", estimator=tracker)
    idx = [m.landmark for m in tracker.markers]
    vis = truth["visibility"][:, idx] > 0
    err = np.linalg.norm(track.xy[:, idx, :2] - truth["keypoints"][:, idx], axis=-1)
    assert np.isfinite(err[vis]).mean() >= 0.98  # visible markers are found
    err = np.where(np.isfinite(err), err, np.inf)[vis]  # a missed marker counts as a miss
    assert np.median(err) <= 2.0  # measured ~0.07 px
    assert np.percentile(err, 95) <= 2.0  # measured ~0.3 px
    # Markers that are not drawn (self-occluded) must not be reported.
    assert np.isnan(track.xy[:, idx, 0][~truth["drawn"][:, idx]]).all()


def test_extract_frames_rejects_bad_input():
    with pytest.raises(KeypointError, match="openpose"):
        extract_frames([np.zeros((8, 8, 3), np.uint8)], 10, backend="openpose")
    with pytest.raises(KeypointError, match="no frames"):
        extract_frames([], 10, backend="markers", markers=[GREEN])
    frames = [np.zeros((8, 8, 3), np.uint8), np.zeros((9, 8, 3), np.uint8)]
    with pytest.raises(KeypointError, match=r"frame 1 is 8x9, expected 8x8"):
        extract_frames(frames, 10, backend="markers", markers=[GREEN])


def test_held_frames_are_read_once_and_repeat_their_keypoints():
    """A frame identical to the one before is not read again; a changed one is, even if it repeats an older one."""
    a = _scene([((40.0, 40.0), (0, 200, 0))])
    b = _scene([((90.0, 70.0), (0, 200, 0))])
    tracker = MarkerTracker([GREEN])
    calls = []
    process = tracker.process
    tracker.process = lambda img, t: calls.append(t) or process(img, t)
    frames = [a, a.copy(), a, b, b, a]
    track = extract_frames(frames, 10, backend="markers", estimator=tracker)
    np.testing.assert_allclose(calls, [0.0, 0.3, 0.5])
    np.testing.assert_allclose(track.xy[:3, 15, :2], [[40.0, 40.0]] * 3, atol=0.5)
    np.testing.assert_allclose(track.xy[3:5, 15, :2], [[90.0, 70.0]] * 2, atol=0.5)
    np.testing.assert_allclose(track.xy[5, 15, :2], [40.0, 40.0], atol=0.5)
    np.testing.assert_allclose(track.times, np.arange(6) / 10)
