"""A pair drawn on top of itself takes its neighbours' order (:mod:`capture2notation.keypoints.overlap`)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from capture2notation.errors import KeypointError
from capture2notation.keypoints.overlap import OVERLAP_TORSO, correct_overlapping, overlapping
from capture2notation.keypoints.track import KeypointTrack

#: A dancer standing facing the camera, pixels: each landmark's horizontal
#: offset from the body's centre line (facing the camera, the left side is
#: on the image's right) and its height.  Torso (shoulders' to hips'
#: midpoint): 100 px, so pairs closer than 20 px overlap.
_OFFSET_Y = {
    11: (40, 100), 13: (60, 150), 15: (70, 200), 17: (72, 210), 19: (70, 212), 21: (66, 208),
    23: (20, 200), 25: (20, 280), 27: (20, 360), 29: (22, 370), 31: (18, 375),
}  # fmt: skip
_CX = 320.0


def _standing(n: int = 30) -> KeypointTrack:
    track = KeypointTrack.empty(n, 25.0, (640, 480), "blazepose")
    for left, (dx, y) in _OFFSET_Y.items():
        # Depth: the left side a little nearer, so a relabelling shows in z.
        track.xy[:, left] = (_CX + dx, y, -5.0)
        track.xy[:, left + 1] = (_CX - dx, y, 5.0)
        track.visibility[:, left] = 0.9
        track.visibility[:, left + 1] = 0.6
    track.xy[:, 0] = (_CX, 60, 0.0)
    track.visibility[:, 0] = 0.9
    track.world[:] = track.xy / 200.0
    track.identity_confidence[:] = 0.8
    return track


def _draw_pair(track, frames, left, right, gap_px) -> None:
    """Draw the pair `gap_px` apart about the body's centre line, left at +gap/2 (negative: crossed)."""
    for point, sign in ((left, 1.0), (right, -1.0)):
        track.xy[frames, point, 0] = _CX + sign * gap_px / 2


def test_an_overlapping_pair_drawn_crossed_takes_its_neighbours_order():
    clean = _standing()
    bad = _standing()
    frames = np.arange(10, 20)
    for left in (27, 29, 31):  # the ankles and the feet with them, drawn 6 px apart and crossed
        _draw_pair(bad, frames, left, left + 1, -6.0)
    fixed, relabelled = correct_overlapping(bad, np.zeros(len(bad)))
    np.testing.assert_array_equal(np.flatnonzero(relabelled["ankles"]), frames)
    assert not any(relabelled[name].any() for name in relabelled if name != "ankles")
    # The left ankle and foot are back on the left side, 6 px apart, their
    # visibility and depth going with them; nothing else moved.
    for left in (27, 29, 31):
        np.testing.assert_allclose(fixed.xy[frames, left, 0] - fixed.xy[frames, left + 1, 0], 6.0)
        np.testing.assert_array_equal(fixed.visibility[frames, left], clean.visibility[frames, left + 1])
        np.testing.assert_array_equal(fixed.xy[frames, left, 2], -bad.xy[frames, left + 1, 2])
    untouched = np.setdiff1d(np.arange(len(bad)), frames)
    np.testing.assert_array_equal(fixed.xy[untouched], bad.xy[untouched])
    np.testing.assert_array_equal(fixed.identity_confidence, bad.identity_confidence)
    assert np.all(bad.xy[frames, 27, 0] < bad.xy[frames, 28, 0])  # the input is not modified


def test_with_the_knees_overlapping_too_the_ankles_follow_the_hips():
    bad = _standing()
    frames = np.arange(5, 9)
    _draw_pair(bad, frames, 25, 26, 4.0)  # knees overlapping, the right way round: left alone
    _draw_pair(bad, frames, 27, 28, -8.0)
    fixed, relabelled = correct_overlapping(bad, np.zeros(len(bad)))
    assert not relabelled["knees"].any()
    np.testing.assert_array_equal(np.flatnonzero(relabelled["ankles"]), frames)
    assert np.all(fixed.xy[frames, 27, 0] > fixed.xy[frames, 28, 0])


def test_pairs_drawn_apart_and_side_on_views_are_left_alone():
    bad = _standing()
    frames = np.arange(10, 20)
    # A leg crossed over the other, drawn clearly apart: a real crossing.
    _draw_pair(bad, frames, 27, 28, -2.5 * OVERLAP_TORSO * 100.0)
    same, relabelled = correct_overlapping(bad, np.zeros(len(bad)))
    np.testing.assert_array_equal(same.xy, bad.xy)
    assert not any(v.any() for v in relabelled.values())
    # Side-on, or with the yaw unknown, near and far limbs overlap as a matter of course.
    _draw_pair(bad, frames, 27, 28, -6.0)
    for yaw in (90.0, -100.0, np.nan):
        same, _ = correct_overlapping(bad, np.full(len(bad), yaw))
        np.testing.assert_array_equal(same.xy, bad.xy)
    # Backing the camera the rule is the same: the order of the pair apart decides.
    fixed, _ = correct_overlapping(bad, np.full(len(bad), 180.0))
    assert np.all(fixed.xy[frames, 27, 0] > fixed.xy[frames, 28, 0])


def test_missing_points_empty_tracks_and_a_wrong_yaw():
    bad = _standing()
    bad.xy[3:6, 11:27] = np.nan  # ankles overlapping and crossed, every other pair missing
    _draw_pair(bad, np.arange(3, 6), 27, 28, -6.0)
    bad.xy[8, 28] = np.nan  # one ankle missing
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        same, _ = correct_overlapping(bad, np.zeros(len(bad)))
    np.testing.assert_array_equal(same.xy, bad.xy)
    empty = KeypointTrack.empty(0, 25.0, (640, 480), "blazepose")
    assert all(v.shape == (0,) for v in overlapping(empty, np.zeros(0)).values())
    nothing = KeypointTrack.empty(4, 25.0, (640, 480), "blazepose")
    assert not any(v.any() for v in overlapping(nothing, np.zeros(4)).values())
    with pytest.raises(KeypointError, match="one value per frame"):
        overlapping(bad, np.zeros(3))


@settings(max_examples=60, deadline=None)
@given(
    arrays(np.float64, (4, 33, 2), elements=st.floats(0, 640, allow_nan=False)),
    arrays(np.float64, (4,), elements=st.floats(-360, 360, allow_nan=False)),
)
def test_only_overlapping_pairs_move_and_twice_is_once(xy, yaw):
    track = KeypointTrack.empty(4, 25.0, (640, 480), "blazepose")
    track.xy[..., :2] = xy
    track.xy[..., 2] = 0.0
    once, relabelled = correct_overlapping(track, yaw)
    twice, again = correct_overlapping(once, yaw)
    np.testing.assert_array_equal(twice.xy, once.xy)
    assert not any(v.any() for v in again.values())
    # Each pair keeps its two points (possibly exchanged), so its gap's length.
    for left in range(11, 33, 2):
        gap = np.linalg.norm(track.xy[:, left, :2] - track.xy[:, left + 1, :2], axis=1)
        np.testing.assert_allclose(np.linalg.norm(once.xy[:, left, :2] - once.xy[:, left + 1, :2], axis=1), gap)
    torso = np.nanmedian(np.linalg.norm((xy[:, 11] + xy[:, 12]) / 2 - (xy[:, 23] + xy[:, 24]) / 2, axis=1))
    for name, (left, right) in {"shoulders": (11, 12), "knees": (25, 26), "ankles": (27, 28)}.items():
        apart = np.linalg.norm(xy[:, left] - xy[:, right], axis=1) >= OVERLAP_TORSO * torso
        assert not np.any(relabelled[name] & apart)
