"""Triangulation of keypoints from several calibrated cameras."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.errors import FittingError
from capture2notation.fitting.triangulate import (
    MAX_TWIST_DEG,
    MIRRORED_COS,
    OUTLIER_PX,
    SIDE_AMBIGUOUS_PX,
    SIDE_APART_DEG,
    find_offset,
    match_sides,
    triangulate,
)
from capture2notation.io.calibration import CameraCalibration
from synthetic.render.camera import Camera as RenderCamera

#: Keypoint noise of the synthetic views, pixels (1 sd per axis).
NOISE_PX = 1.0


def _cameras(azimuths_deg):
    cams = []
    for az in azimuths_deg:
        a = np.radians(az)
        pos = (4.0 * np.sin(a), 4.0 * np.cos(a), 1.2)
        rc = RenderCamera.look_at(pos, (0.0, 0.0, 1.0), 45.0, (640, 480))
        cams.append(CameraCalibration(f"c{az}", (640, 480), rc.K, np.zeros(5), rc.R, rc.t))
    return cams


def _views(cams, X, rng):
    uv = np.stack([c.project(X) for c in cams])
    return uv + rng.normal(0.0, NOISE_PX, uv.shape)


def _tolerance(cams, n_views: int) -> float:
    """Bound on the point error from the pixel noise alone, metres.

    One view's noise back-projects to NOISE_PX * depth / f across its ray
    (depth up to ~5 m here); two views at 45-90 degrees fix each axis to
    within sqrt(2) of that (1 / sin 45°); 4 sd covers the 99th percentile.
    """
    f = float(cams[0].K[0, 0])
    return 4.0 * NOISE_PX * 5.0 / f * np.sqrt(2.0) / np.sqrt(n_views / 2.0)


def test_three_views_with_an_outlier_view_recover_the_points():
    rng = np.random.default_rng(3)
    cams = _cameras([0, 45, 90])
    X = rng.uniform([-0.8, -0.8, 0.0], [0.8, 0.8, 1.8], (20, 33, 3))
    uv = _views(cams, X, rng)
    # One view mirrors a limb: points 11-16 land 60 px off (a swapped arm).
    uv[1, :, 11:17] += 60.0
    vis = np.ones(uv.shape[:3])
    P, _conf, used = triangulate(uv, vis, cams)
    err = np.linalg.norm(P - X, axis=-1)
    assert np.all(np.isfinite(P))
    assert np.percentile(err, 99) < _tolerance(cams, 2)
    assert not used[1, :, 11:17].any()  # the mirrored view is dropped there
    assert used[:, :, :11].all()  # and kept elsewhere
    assert OUTLIER_PX < 60.0  # the test's mirrored limb is an outlier by the named threshold


def _two_views(seed: int):
    """Front and side cameras, 10 frames of 33 random points, their pixels and full visibility."""
    rng = np.random.default_rng(seed)
    cams = _cameras([0, 90])
    X = rng.uniform([-0.8, -0.8, 0.0], [0.8, 0.8, 1.8], (10, 33, 3))
    uv = _views(cams, X, rng)
    return cams, X, uv, np.ones(uv.shape[:3])


def test_two_views_weight_by_visibility_and_lower_confidence_by_residual():
    cams, X, uv, vis = _two_views(4)
    vis[1, :, 5] = 0.0  # one view does not see point 5: no triangulation
    uv[0, :, 7] += 40.0  # a point off in one of two views
    P, conf, _ = triangulate(uv, vis, cams)
    good = [i for i in range(33) if i not in (5, 7)]
    assert np.percentile(np.linalg.norm(P[:, good] - X[:, good], axis=-1), 99) < _tolerance(cams, 2)
    assert np.all(np.isnan(P[:, 5])) and np.all(conf[:, 5] == 0)
    assert np.all(conf[:, 7] < 0.5 * np.median(conf[:, good]))


def test_a_view_of_low_visibility_still_votes_with_that_weight():
    # A keypoint model's visibility is a weight, not a gate: a point one view
    # rates 0.1 but places right is triangulated, on the better view's ray.
    cams, X, uv, vis = _two_views(7)
    vis[1, :, 3] = 0.1
    P, conf, used = triangulate(uv, vis, cams)
    assert np.all(used[:, :, 3])
    assert np.percentile(np.linalg.norm(P[:, 3] - X[:, 3], axis=-1), 99) < _tolerance(cams, 2)
    # Its confidence is the views' mean weight: lower than a point both see well.
    assert np.all(conf[:, 3] < 0.6) and np.all(conf[:, 3] > 0.0)


def test_one_camera_is_refused():
    cams = _cameras([0])
    with pytest.raises(FittingError, match="two cameras"):
        triangulate(np.zeros((1, 2, 33, 2)), np.ones((1, 2, 33)), cams)


def test_find_offset_recovers_a_late_start():
    rng = np.random.default_rng(5)
    motion = np.cumsum(rng.normal(0, 3, (120, 33, 2)), axis=0)
    ref = motion[:100]
    other = 0.5 * motion[7:107] + 40.0  # starts 7 frames later, another scale
    assert find_offset(ref, other, 20) == 7
    assert find_offset(other, ref, 20) == -7


def _symmetric_stance(T: int, rng) -> np.ndarray:
    """(T, 33, 3) landmarks of a dancer facing +y, legs mirror-symmetric about x = 0, swaying by a centimetre.

    Left landmarks (odd BlazePose indices from 11) on −x, right ones on +x:
    shoulders 18 cm, hips 10 cm, knees, ankles, heels and toes 10 cm from the
    midline; the left arm hangs, the right arm is raised forward.
    """
    X = np.zeros((T, 33, 3))
    X[:, 0] = (0.0, 0.08, 1.62)  # nose
    X[:, 1:11] = (0.0, 0.05, 1.65)
    heights = {
        11: 1.42,
        13: 1.12,
        15: 0.85,
        17: 0.80,
        19: 0.78,
        21: 0.80,
        23: 0.92,
        25: 0.50,
        27: 0.08,
        29: 0.03,
        31: 0.02,
    }
    half = {
        11: 0.18,
        13: 0.20,
        15: 0.21,
        17: 0.22,
        19: 0.22,
        21: 0.21,
        23: 0.10,
        25: 0.10,
        27: 0.10,
        29: 0.10,
        31: 0.10,
    }
    forward = {29: -0.05, 31: 0.12}
    for i, z in heights.items():
        for k, sign in ((i, -1.0), (i + 1, 1.0)):  # left, right
            X[:, k] = (sign * half[i], forward.get(i, 0.0), z)
    X[:, 14] = (0.18, 0.30, 1.42)  # right elbow, wrist and hand forward at shoulder height
    X[:, [16, 18, 20, 22]] = (0.18, 0.58, 1.42)
    return X + rng.normal(0.0, 0.01, (T, 1, 3))


def test_symmetric_cameras_keep_the_legs_of_a_symmetric_stance():
    """45° and −45° cameras: mirror-symmetric legs reproject as well with one view's legs swapped.

    The swapped rays meet on the plane between the cameras with the hips
    turned by 90° (one in front of the other); the trunk cannot twist so far
    (:data:`MAX_TWIST_DEG`), so the true labels must be kept and the
    triangulated hips stay on their sides.
    """
    rng = np.random.default_rng(11)
    cams = _cameras([45, -45])
    X = _symmetric_stance(40, rng)
    uv = _views(cams, X, rng)
    vis = np.ones(uv.shape[:3])
    uv2, _vis2, swapped = match_sides(uv, vis, cams)
    assert not swapped.any()
    P, _conf, _used = triangulate(uv2, vis, cams)
    assert np.all(P[:, 23, 0] < -0.05) and np.all(P[:, 24, 0] > 0.05)  # left hip on −x, right on +x
    assert MAX_TWIST_DEG < 90.0  # the mirrored labelling's 90° turn is beyond the named limit


def test_symmetric_cameras_keep_the_arms_the_head_faces_with():
    """Both arms hanging mirror-symmetric, seen from 45° and −45°: the swapped
    arms reproject as well, turned by 90° about the body's axis, and noise
    alone would pick between them frame by frame.  The head decides: the
    nose lies ahead of the ears, and the shoulders face where it looks
    (:data:`SIDE_AMBIGUOUS_PX`, :data:`SIDE_APART_DEG`)."""
    rng = np.random.default_rng(12)
    cams = _cameras([45, -45])
    X = _symmetric_stance(60, rng)
    X[:, [14, 16, 18, 20, 22]] = X[:, [13, 15, 17, 19, 21]] * np.array([-1.0, 1.0, 1.0])  # the right arm hangs too
    X[:, 7] = X[:, 0] + (-0.07, -0.09, 0.02)  # left ear
    X[:, 8] = X[:, 0] + (0.07, -0.09, 0.02)  # right ear
    uv = _views(cams, X, rng)
    vis = np.ones(uv.shape[:3])
    _uv2, _vis2, swapped = match_sides(uv, vis, cams)
    assert not swapped[:, :, 0].any()
    assert SIDE_AMBIGUOUS_PX > 2 * NOISE_PX and SIDE_APART_DEG < 90.0  # the tie and the 90° turn are within the limits


def test_a_body_mirrored_in_every_view_is_turned_back_by_its_head():
    """The keypoint model mirrors every view alike (a back view read as a front
    view): the rays meet on a mirror image whose shoulders face away from
    where the head looks (:data:`MIRRORED_COS`), and every view is relabelled."""
    rng = np.random.default_rng(13)
    cams = _cameras([0, 90])
    X = _symmetric_stance(30, rng)
    X[:, 7] = X[:, 0] + (-0.07, -0.09, 0.02)  # left ear
    X[:, 8] = X[:, 0] + (0.07, -0.09, 0.02)  # right ear
    uv = _views(cams, X, rng)
    mirrored = np.arange(33)
    for a in range(11, 33, 2):
        mirrored[[a, a + 1]] = a + 1, a
    mirrored[[7, 8]] = 8, 7
    uv = uv[:, :, mirrored]
    vis = np.ones(uv.shape[:3])
    uv2, _vis2, swapped = match_sides(uv, vis, cams)
    assert swapped.all()
    P, _conf, _used = triangulate(uv2, vis, cams)
    assert np.all(P[:, 16, 1] > 0.4) and np.all(P[:, 16, 0] > 0.1)  # the raised right wrist, ahead on the right
    assert np.cos(np.radians(90.0)) > MIRRORED_COS  # a head turned by a neck's reach is not a mirror
