"""Crop geometry: MediaPipe's ROI from auxiliary points and the crop warp."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.keypoints.blazepose import (
    crop_from_aux,
    crop_matrix,
    crop_to_tensor,
    decode_outputs,
    full_frame_crop,
    search_crops,
)

crops = st.tuples(st.floats(-200, 1200), st.floats(-200, 900), st.floats(20, 2000), st.floats(-np.pi, np.pi)).map(
    lambda c: np.array([c[0], c[1], c[2], c[2], c[3]])
)


def test_upright_person_has_zero_rotation_and_margin():
    # Point 34 straight above point 33 (image y down).
    crop = crop_from_aux(np.array([[300.0, 400.0], [300.0, 250.0]]))
    np.testing.assert_allclose(crop, [300, 400, 2 * 150 * 1.25, 2 * 150 * 1.25, 0.0], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(theta=st.floats(-3.0, 3.0), r=st.floats(10, 500))
def test_rotating_the_aux_points_rotates_the_crop(theta, r):
    """Turning the body clockwise by theta (in the image) turns the crop by theta."""
    c = np.array([500.0, 300.0])
    up = np.array([0.0, -r])
    rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    crop = crop_from_aux(np.array([c, c + rot @ up]))
    assert np.angle(np.exp(1j * (crop[4] - theta))) == pytest.approx(0.0, abs=1e-9)
    assert crop[2] == pytest.approx(2.5 * r)


@settings(max_examples=40, deadline=None)
@given(crop=crops, uv=st.tuples(st.floats(0, 1), st.floats(0, 1)))
def test_decode_inverts_the_warp(crop, uv):
    """A model output at uv maps to the image point the warp sent to uv."""
    raw = np.zeros((39, 5))
    raw[:, :2] = np.array(uv) * 256
    outputs = [raw.reshape(1, -1), np.ones((1, 1)), None, None, np.zeros((1, 117))]
    est = decode_outputs(outputs, crop, refine=False)
    m = crop_matrix(crop)
    back = m[:, :2] @ est.xy[0, :2] + m[:, 2]
    np.testing.assert_allclose(back, np.array(uv) * 256, atol=1e-6 * max(1.0, crop[2]))


def test_full_frame_letterbox_and_tensor_layout():
    img = np.zeros((100, 200, 3), np.uint8)
    img[:, :100] = (255, 0, 0)  # blue (BGR) left half
    img[:, 100:] = (0, 0, 255)  # red right half
    crop = full_frame_crop(200, 100)
    np.testing.assert_allclose(crop, [100, 50, 200, 200, 0])
    t = crop_to_tensor(img, crop, border=cv2.BORDER_CONSTANT)
    assert t.shape == (1, 3, 256, 256) and t.dtype == np.float32
    # RGB channel order, values in [0, 1], letterbox bands above and below.
    assert t[0, 2, 128, 30] == pytest.approx(1.0) and t[0, 0, 128, 30] == 0.0
    assert t[0, 0, 128, 220] == pytest.approx(1.0) and t[0, 2, 128, 220] == 0.0
    assert t[0, :, 10, :].max() == 0.0 and t[0, :, 250, :].max() == 0.0


def test_world_landmarks_rotate_with_the_crop():
    world = np.zeros((39, 3))
    world[0] = (0.0, -0.5, 0.1)  # 0.5 m "up" in the crop
    outputs = [np.zeros((1, 195)), np.ones((1, 1)), None, None, world.reshape(1, -1)]
    est = decode_outputs(outputs, np.array([0, 0, 100, 100, np.pi / 2]), refine=False)
    # Crop turned 90 degrees clockwise: crop-up is image +x.
    np.testing.assert_allclose(est.world[0], [0.5, 0.0, 0.1], atol=1e-12)


def test_degenerate_aux_points_give_an_unusable_crop():
    from capture2notation.keypoints.blazepose import _usable

    assert not _usable(crop_from_aux(np.array([[10.0, 10.0], [10.0, 10.0]])))
    assert not _usable(crop_from_aux(np.array([[np.nan, 10.0], [10.0, 10.0]])))
    assert _usable(crop_from_aux(np.array([[10.0, 100.0], [10.0, 60.0]])))


@given(st.integers(32, 4000), st.integers(32, 4000), st.floats(0.1, 1.0))
@settings(max_examples=200, deadline=None)
def test_search_crops_cover_the_frame_inside_it(width, height, scale):
    """Every searched crop lies inside the frame; together they cover it with half-side steps."""
    (crops,) = search_crops(width, height, scales=(scale,))
    side = scale * min(width, height)
    np.testing.assert_allclose(crops[:, 2:4], side)
    assert (crops[:, 4] == 0).all()
    lo, hi = crops[:, :2] - side / 2, crops[:, :2] + side / 2
    assert (lo >= -1e-6).all() and (hi <= np.array([width, height]) + 1e-6).all()
    for axis, extent in enumerate((width, height)):
        centres = np.unique(crops[:, axis].round(6))
        assert centres[0] - side / 2 < 1e-6 and centres[-1] + side / 2 > extent - 1e-6
        assert (np.diff(centres) <= 0.5 * side + 1e-6).all()
