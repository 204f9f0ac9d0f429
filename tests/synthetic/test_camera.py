"""The pinhole camera: projection invariants and the preset viewpoints."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.body.landmarks import landmarks_from_pose
from capture2notation.errors import SyntheticError
from synthetic.render.camera import Camera

coord = st.floats(-5.0, 5.0, allow_nan=False)
point = st.tuples(coord, coord, coord)
sizes = st.tuples(st.integers(16, 2000), st.integers(16, 2000))


def _camera(pos, target, fov, size):
    pos, target = np.array(pos), np.array(target)
    d = target - pos
    # Keep away from degenerate set-ups: coincident points, looking straight up/down.
    if np.linalg.norm(d) < 0.1 or np.linalg.norm(d[:2]) < 0.05 * np.linalg.norm(d):
        return None
    return Camera.look_at(pos, target, fov, size)


@settings(max_examples=60, deadline=None)
@given(point, point, st.floats(10.0, 120.0), sizes, st.floats(0.1, 20.0))
def test_optical_axis_projects_to_principal_point(pos, target, fov, size, k):
    cam = _camera(pos, target, fov, size)
    if cam is None:
        return
    forward = cam.R[2]
    uv, z = cam.project(np.array(pos) + k * forward, return_depth=True)
    np.testing.assert_allclose(uv, cam.K[:2, 2], atol=1e-6 * max(size))
    np.testing.assert_allclose(z, k, rtol=1e-9)
    np.testing.assert_allclose(cam.project(target), [size[0] / 2, size[1] / 2], atol=1e-6 * max(size))


@settings(max_examples=60, deadline=None)
@given(
    point,
    point,
    st.floats(10.0, 120.0),
    sizes,
    st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    st.floats(0.05, 30.0),
)
def test_back_projection_round_trip(pos, target, fov, size, frac, depth):
    cam = _camera(pos, target, fov, size)
    if cam is None:
        return
    uv = np.array([size[0] / 2 * (1 + frac[0]), size[1] / 2 * (1 + frac[1])])
    ray = np.linalg.solve(cam.K, np.array([uv[0], uv[1], 1.0]))
    world = cam.R.T @ (ray * depth - cam.t)
    got, z = cam.project(world, return_depth=True)
    np.testing.assert_allclose(got, uv, atol=1e-6 * max(size))
    np.testing.assert_allclose(z, depth, rtol=1e-9)
    np.testing.assert_allclose(cam.depth(world), depth, rtol=1e-9)


@settings(max_examples=40, deadline=None)
@given(point, point, st.floats(10.0, 120.0), sizes)
def test_extrinsics_are_a_proper_rigid_transform(pos, target, fov, size):
    cam = _camera(pos, target, fov, size)
    if cam is None:
        return
    np.testing.assert_allclose(cam.R @ cam.R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(cam.R) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(cam.position, pos, atol=1e-9)
    np.testing.assert_allclose(cam.to_camera(pos), 0.0, atol=1e-9)
    # World up appears upwards in the image (OpenCV y points down).
    up = cam.project(np.array(target) + [0, 0, 0.01])
    assert up[1] < size[1] / 2


def test_points_behind_the_camera_are_nan():
    cam = Camera.look_at([0, 3, 1], [0, 0, 1], 40, (64, 48))
    uv, z = cam.project(np.array([[0, 4, 1], [0, 2, 1]]), return_depth=True)
    assert np.isnan(uv[0]).all() and z[0] < 0
    assert np.isfinite(uv[1]).all()


def test_front_view_sees_the_performers_right_on_the_image_left():
    cam = Camera.for_view("front", (640, 480))
    right, left = cam.project(np.array([[0.3, 0, 1.0], [-0.3, 0, 1.0]]))
    assert right[0] < 320 < left[0]
    assert cam.position[1] > 2.0 and abs(cam.position[0]) < 1e-9


def test_side_view_is_on_the_performers_right():
    cam = Camera.for_view("side", (640, 480))
    assert cam.position[0] > 2.0 and abs(cam.position[1]) < 1e-9
    # Seen from their right, the performer faces image right.
    fwd = cam.project(np.array([0.0, 0.5, 1.0]))
    assert fwd[0] > 320


def _extreme_poses(body):
    """Rest, arms overhead, arms out to the sides, a leg to each side, a leg forward high."""
    a = np.zeros((6, len(JOINTS), 3))
    a[1, joint_index("right_shoulder"), 0] = a[1, joint_index("left_shoulder"), 0] = np.pi
    a[2, joint_index("right_shoulder"), 1] = -np.pi / 2
    a[2, joint_index("left_shoulder"), 1] = np.pi / 2
    a[3, joint_index("right_hip"), 1] = np.radians(-60)
    a[4, joint_index("left_hip"), 1] = np.radians(60)
    a[5, joint_index("right_hip"), 0] = np.radians(110)
    return a, np.tile(body.rest[0], (6, 1))


@pytest.mark.parametrize("view", ["front", "45", "side"])
@pytest.mark.parametrize("size", [(640, 480), (220, 175), (1280, 720), (480, 640)])
def test_presets_frame_the_whole_body_with_a_margin(view, size):
    body = Body(1.70)
    angles, root = _extreme_poses(body)
    pts = landmarks_from_pose(angles, root, body)
    cam = Camera.for_view(view, size, body.height)
    uv = cam.project(pts)
    w, h = size
    margin = 0.03
    assert np.all(uv[..., 0] > margin * w) and np.all(uv[..., 0] < (1 - margin) * w)
    assert np.all(uv[..., 1] > margin * h) and np.all(uv[..., 1] < (1 - margin) * h)
    # ...and is not a speck: the standing body spans over 45 % of the image.
    span = uv[0, :, 1].max() - uv[0, :, 1].min()
    assert span > 0.45 * min(w, h)


def test_presets_scale_with_body_height():
    small = Camera.for_view("front", (640, 480), 1.0)
    tall = Camera.for_view("front", (640, 480), 2.0)
    np.testing.assert_allclose(tall.position, 2 * small.position, rtol=1e-12)


@pytest.mark.parametrize(
    "call",
    [
        lambda: Camera.for_view("top"),
        lambda: Camera.look_at([0, 1, 1], [0, 1, 1], 40, (64, 48)),
        lambda: Camera.look_at([0, 3, 1], [0, 0, 1], 0, (64, 48)),
        lambda: Camera.look_at([0, 3, 1], [0, 0, 1], 40, (8, 48)),
        lambda: Camera.look_at([0, 3, 1], [0, 0, 1], 40, (64.5, 48)),
        lambda: Camera.look_at([0, 0, 3], [0, 0, 0], 40, (64, 48)),
    ],
)
def test_bad_camera_parameters_raise(call):
    with pytest.raises(SyntheticError):
        call()


def test_in_image_uses_pixel_centres():
    cam = Camera.look_at([0, 3, 1], [0, 0, 1], 40, (64, 48))
    uv = np.array([[-0.5, 0.0], [63.49, 47.49], [63.5, 10.0], [10.0, -0.51], [np.nan, 3.0]])
    np.testing.assert_array_equal(cam.in_image(uv), [True, True, False, False, False])


def test_camera_rejects_a_matrix_that_is_not_a_rotation():
    with pytest.raises(SyntheticError, match="rotation"):
        Camera(np.eye(3), np.diag([1.0, 1.0, -1.0]), np.zeros(3), (64, 48))
