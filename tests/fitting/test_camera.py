"""Pinhole camera: projection geometry, round trips and input errors."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import FittingError
from capture2notation.fitting import Camera


def test_default_camera_looks_at_the_performer_from_the_front():
    cam = Camera.default((640, 480), hfov_deg=60.0, distance=4.0, height=1.0)
    np.testing.assert_allclose(cam.centre, [0.0, 4.0, 1.0], atol=1e-12)
    # The point level with the camera on the performer's axis is the image centre.
    np.testing.assert_allclose(cam.project(np.array([0.0, 0.0, 1.0])), [320.0, 240.0], atol=1e-9)
    # The performer's right (+x) appears on the image's left; up is up.
    right = cam.project(np.array([0.5, 0.0, 1.0]))
    up = cam.project(np.array([0.0, 0.0, 1.5]))
    assert right[0] < 320.0 and up[1] < 240.0
    # Half the horizontal field of view reaches the image edge.
    edge = cam.project(np.array([-4.0 * np.tan(np.deg2rad(30.0)), 0.0, 1.0]))
    assert edge[0] == pytest.approx(640.0, abs=1e-6)


@settings(max_examples=30, deadline=None)
@given(x=st.floats(-2, 2), y=st.floats(-2, 2), z=st.floats(0, 2), fov=st.floats(30, 90))
def test_backproject_inverts_project(x, y, z, fov):
    cam = Camera.default((320, 240), hfov_deg=fov)
    p = np.array([x, y, z])
    depth = cam.to_camera(p)[2]
    np.testing.assert_allclose(cam.backproject(cam.project(p), depth), p, atol=1e-9)


def test_with_focal_and_from_truth():
    cam = Camera.default((640, 480))
    assert cam.with_focal(500.0).focal == 500.0
    truth = {"K": cam.K, "R": cam.R, "t": cam.t, "image_size": np.array([640, 480])}
    again = Camera.from_truth(truth)
    np.testing.assert_array_equal(again.K, cam.K)
    assert again.image_size == (640, 480)


def test_points_behind_the_camera_project_to_nan():
    cam = Camera.default((640, 480), distance=4.0)
    assert np.all(np.isnan(cam.project(np.array([0.0, 10.0, 1.0]))))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(K=np.eye(3), R=np.eye(3) * 2, t=np.zeros(3), image_size=(10, 10)), "rotation"),
        (dict(K=np.zeros((3, 3)), R=np.eye(3), t=np.zeros(3), image_size=(10, 10)), "focal"),
        (dict(K=np.eye(3), R=np.eye(3), t=np.zeros(2), image_size=(10, 10)), "t \\(3,\\)"),
        (dict(K=np.eye(3), R=np.eye(3), t=np.zeros(3), image_size=(0, 10)), "image_size"),
    ],
)
def test_bad_cameras_are_rejected(kwargs, message):
    with pytest.raises(FittingError, match=message):
        Camera(**kwargs)
    with pytest.raises(FittingError, match=r"missing|no camera field"):
        Camera.from_truth({"K": np.eye(3)})


def _distorted_calibration(dist):
    from capture2notation.io.calibration import Calibration, CameraCalibration

    cam = Camera.default((640, 480))
    return cam, Calibration.of(
        [CameraCalibration("front", (640, 480), cam.K, np.asarray(dist, float), cam.R, np.asarray(cam.t))]
    )


def test_undistorted_keypoints_are_the_pinhole_projection():
    """A calibrated lens (k1, k2 as `c2n calibrate` fits them) bends the
    keypoints; undistorted onto the same intrinsics they are where the fit's
    pinhole camera projects the same points (OpenCV's own projection as the
    reference), and a missing keypoint stays missing."""
    import cv2

    from capture2notation.fitting.camera import undistort_track
    from capture2notation.keypoints import KeypointTrack

    dist = [-0.11, 0.09, 0.0, 0.0, 0.0]
    cam, cal = _distorted_calibration(dist)
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(-1.0, 1.0, 66), rng.uniform(-0.3, 0.3, 66), rng.uniform(0.1, 1.8, 66)])
    rvec, _ = cv2.Rodrigues(cam.R)
    seen, _ = cv2.projectPoints(pts.reshape(-1, 1, 3), rvec, np.asarray(cam.t, float), cam.K, np.asarray(dist))
    track = KeypointTrack.empty(2, 25.0, (640, 480), backend="blazepose")
    xy = track.xy.copy()
    xy[..., :2] = seen.reshape(2, 33, 2)
    xy[1, 5, :2] = np.nan
    out = undistort_track(replace(track, xy=xy), cal, "front.mp4")
    pinhole = cam.project(pts).reshape(2, 33, 2)
    moved = np.nanmax(np.linalg.norm(xy[..., :2] - pinhole, axis=-1))
    assert moved > 2.0  # the lens moves them by pixels
    err = np.linalg.norm(out.xy[..., :2] - pinhole, axis=-1)
    assert np.nanmax(err) < 0.01 and np.isnan(out.xy[1, 5, :2]).all()


def test_a_distorted_camera_needs_undistorted_keypoints():
    cam, cal = _distorted_calibration([-0.11, 0.09, 0.0, 0.0, 0.0])
    with pytest.raises(FittingError, match="has lens distortion"):
        Camera.from_calibration(cal, "front.mp4", (640, 480))
    pinhole = Camera.from_calibration(cal, "front.mp4", (640, 480), undistorted=True)
    np.testing.assert_allclose(pinhole.K, cam.K)
