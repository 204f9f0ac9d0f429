"""Left and right limbs side-on from the pose model's visibility (:mod:`capture2notation.keypoints.near_side`)."""

from __future__ import annotations

import numpy as np
import pytest

import capture2notation.keypoints.near_side as near_side_module
from capture2notation.body import Body
from capture2notation.errors import KeypointError
from capture2notation.keypoints.near_side import correct_near_side, decode_near_side
from capture2notation.keypoints.track import KeypointTrack
from capture2notation.keypoints.yaw import decode_yaw
from synthetic.identity_errors import truth_track
from synthetic.interpret import interpret
from synthetic.random_scores import random_score
from synthetic.render.camera import Camera
from synthetic.render.job import truth_fields
from synthetic.render.scene import Pose

_LEFT_ARM = [11, 13, 15, 17, 19, 21]
_RIGHT_ARM = [12, 14, 16, 18, 20, 22]


def _side_on_track(view: str = "side"):
    """Exact keypoints of a dancer who never turns, with BlazePose's near/far visibility.

    From the ``side`` camera the dancer faces the image's right (yaw +90°):
    the right limbs are near and drawn more visible than the left.
    """
    score = random_score(np.random.default_rng(2), n_beats=16, turns=False, fps=25.0)
    pose = Pose.from_motion(interpret(score, 25.0, Body()))
    track = truth_track(truth_fields(pose, Camera.for_view(view, (640, 480), pose.body.height)))
    track.visibility[:, 11:33:2] = 0.6  # left, far
    track.visibility[:, 12:33:2] = 0.9  # right, near
    return track


def _swap_arms(track, frames):
    # The pose model's limb swap: the arms' labels exchanged; image, world
    # and visibility follow where each landmark is drawn.
    for values in (track.xy, track.world, track.visibility):
        left = values[frames][:, _LEFT_ARM].copy()
        values[np.ix_(frames, _LEFT_ARM)] = values[frames][:, _RIGHT_ARM]
        values[np.ix_(frames, _RIGHT_ARM)] = left


def test_a_swapped_arm_pair_side_on_is_relabelled(monkeypatch):
    clean = _side_on_track()
    yaw = decode_yaw(clean)
    assert np.nanmedian(yaw) == pytest.approx(90.0, abs=10.0)
    bad = _side_on_track()
    frames = np.flatnonzero((bad.times >= 2.0) & (bad.times < 4.0))
    _swap_arms(bad, frames)
    fixed, decoding = correct_near_side(bad, yaw)
    right = np.all(np.isclose(fixed.xy[:, _LEFT_ARM, :2], clean.xy[:, _LEFT_ARM, :2], equal_nan=True), axis=(1, 2))
    assert right[frames].mean() >= 0.95 and right.mean() >= 0.97
    assert np.all(decoding.swapped["legs"] < 0.5)
    # A relabelled frame is no surer than the chain.
    moved = decoding.swapped["arms"] > 0.5
    assert np.all(fixed.identity_confidence[moved] <= decoding.swapped["arms"][moved] + 1e-12)
    # Without the visibility contrast nothing tells the limbs apart.
    monkeypatch.setattr(near_side_module, "NEAR_VISIBILITY", 0.0)
    unfixed, _ = correct_near_side(bad, yaw)
    np.testing.assert_array_equal(unfixed.xy, bad.xy)


def test_a_clean_track_and_a_body_facing_the_camera_are_left_alone():
    clean = _side_on_track()
    same, decoding = correct_near_side(clean, decode_yaw(clean))
    np.testing.assert_array_equal(same.xy, clean.xy)
    assert all(np.all(p < 0.5) for p in decoding.swapped.values())
    # Facing the camera no side is near: a visibility contrast says nothing.
    front = _side_on_track("front")
    _swap_arms(front, np.arange(len(front)))
    same, _ = correct_near_side(front, decode_yaw(front))
    np.testing.assert_array_equal(same.xy, front.xy)


def test_the_yaw_must_match_the_track():
    track = _side_on_track()
    with pytest.raises(KeypointError, match="one value per frame"):
        decode_near_side(track, np.zeros(3))
    empty = decode_near_side(KeypointTrack.empty(0, 25.0, (640, 480), "blazepose"), np.zeros(0))
    assert all(p.shape == (0,) for p in empty.swapped.values())
