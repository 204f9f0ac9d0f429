"""PCK and left/right swap metrics on constructed cases."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.keypoints.evaluate import left_right_swaps, pck, person_height_px


def test_pck_counts_within_radius_and_missing_as_wrong():
    truth = np.zeros((4, 2, 2))
    xy = np.zeros((4, 2, 2))
    xy[:, 0, 0] = [0.0, 4.9, 5.1, np.nan]  # joint 0: 2 of 4 within 5 px
    visible = np.array([[1, 1], [1, 1], [1, 1], [1, 0]], bool)
    got = pck(xy, truth, 5.0, visible)
    assert got[0] == pytest.approx(0.5) and got[1] == 1.0
    assert np.isnan(pck(xy, truth, 5.0, np.zeros((4, 2), bool))[0])


def test_swaps_need_both_points_crossed_and_separated_truths():
    truth = np.zeros((3, 33, 2))
    truth[:, 11], truth[:, 12] = (100.0, 50.0), (60.0, 50.0)
    xy = truth.copy()
    xy[1, 11], xy[1, 12] = truth[1, 12], truth[1, 11]  # frame 1 swapped
    xy[2, 11] = truth[2, 12]  # frame 2: only one point wrong -> not a swap
    swaps = left_right_swaps(xy, truth, 10.0)
    np.testing.assert_array_equal(swaps["shoulder"], [False, True, False])
    assert not left_right_swaps(xy, truth, 50.0)["shoulder"].any()  # truths closer than the radius


def test_person_height_is_focal_times_height_over_depth():
    K = np.diag([500.0, 600.0, 1.0])
    h = person_height_px(K, np.eye(3), np.array([0.0, 0.0, 4.0]), np.zeros((2, 3)), 1.7)
    np.testing.assert_allclose(h, 600 * 1.7 / 4.0)
