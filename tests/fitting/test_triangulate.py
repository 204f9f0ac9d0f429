"""Triangulation of keypoints from several calibrated cameras."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.errors import FittingError
from capture2notation.fitting.triangulate import OUTLIER_PX, find_offset, triangulate
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


def test_two_views_weight_by_visibility_and_lower_confidence_by_residual():
    rng = np.random.default_rng(4)
    cams = _cameras([0, 90])
    X = rng.uniform([-0.8, -0.8, 0.0], [0.8, 0.8, 1.8], (10, 33, 3))
    uv = _views(cams, X, rng)
    vis = np.ones(uv.shape[:3])
    vis[1, :, 5] = 0.0  # one view does not see point 5: no triangulation
    uv[0, :, 7] += 40.0  # a point off in one of two views
    P, conf, _ = triangulate(uv, vis, cams)
    good = [i for i in range(33) if i not in (5, 7)]
    assert np.percentile(np.linalg.norm(P[:, good] - X[:, good], axis=-1), 99) < _tolerance(cams, 2)
    assert np.all(np.isnan(P[:, 5])) and np.all(conf[:, 5] == 0)
    assert np.all(conf[:, 7] < 0.5 * np.median(conf[:, good]))


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
