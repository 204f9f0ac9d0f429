"""The whole-clip left/right and front/back decoder, on the virtual dancer's
truth keypoints with the pose model's identity errors put in
(:mod:`synthetic.identity_errors`)."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.body import Body
from capture2notation.keypoints.identity import (
    IDENTITY_UNCERTAIN_BELOW,
    correct_identity,
    decode_identity,
    toes_minus_heels,
)
from capture2notation.keypoints.swap import MIRROR
from capture2notation.keypoints.track import KeypointTrack
from synthetic.identity_errors import facing_camera, truth_track, with_identity_errors
from synthetic.interpret import interpret
from synthetic.random_scores import random_score
from synthetic.render.camera import Camera
from synthetic.render.job import truth_fields
from synthetic.render.scene import Pose

#: The issue's bar: frames with the right identity after correction.
RIGHT_IDENTITY = 0.99


def _clip(seed: int, n_beats: int = 16):
    rng = np.random.default_rng(seed)
    score = random_score(rng, n_beats=n_beats, turns=True, fps=25.0)
    pose = Pose.from_motion(interpret(score, 25.0, Body()))
    camera = Camera.for_view("front", (640, 480), pose.body.height)
    fields = truth_fields(pose, camera)
    return truth_track(fields), facing_camera(fields["front"], camera.R), rng, _off_side(fields["front"], camera.R)


def _off_side(front_deg, R, band_deg: float = 15.0):
    # Frames more than `band_deg` from side-on, where facing is defined beyond the noise.
    a = np.radians(front_deg)
    fwd = np.stack([np.sin(a), np.cos(a), np.zeros_like(a)], 1) @ np.asarray(R).T
    return np.degrees(np.arcsin(np.clip(np.abs(fwd[:, 2]), 0, 1))) > band_deg


def _turning_clip():
    # A clip that turns through back views (the draw is deterministic in its seed).
    for seed in range(500, 540):
        track, facing, rng, off = _clip(seed)
        if 20 <= (~facing).sum() <= 0.7 * len(facing):
            return track, facing, rng, off
    pytest.fail("no random score with back views in 40 seeds")


def test_long_swap_and_back_views_read_as_front_are_corrected():
    track, facing, rng, off = _turning_clip()
    d = track.times[-1]
    bad, sim = with_identity_errors(track, facing, rng, swaps=((0.2 * d, 0.6 * d),))
    assert sim.swapped.mean() > 0.2  # the errors are there to correct
    fixed, res = correct_identity(bad)
    assert np.mean(res.swapped == sim.swapped) >= RIGHT_IDENTITY
    assert np.mean((res.facing == np.where(facing, 1, -1))[off]) >= RIGHT_IDENTITY
    # The corrected landmarks are the true ones (to the simulated noise).
    right = res.swapped == sim.swapped
    err = np.linalg.norm(fixed.xy[right, 11:, :2] - track.xy[right, 11:, :2], axis=-1)
    assert np.nanmedian(err) < 5.0
    assert fixed.identity_confidence.shape == (len(bad),)
    assert np.all((fixed.identity_confidence >= 0) & (fixed.identity_confidence <= 1))


def test_a_clean_track_is_left_as_it_is():
    track, facing, rng, _ = _turning_clip()
    clean, _ = with_identity_errors(track, facing, rng, back_as_front=False)
    res = decode_identity(clean)
    assert np.mean(~res.swapped) >= RIGHT_IDENTITY
    assert np.mean(res.confidence >= IDENTITY_UNCERTAIN_BELOW) >= RIGHT_IDENTITY


@pytest.mark.parametrize("seed", [506, 508])
def test_a_fast_clean_spin_is_not_read_as_a_swap(seed):
    # Every other frame of a clean turning clip: the dancer spins twice as
    # fast.  Compared with the previous frame as it stands, a landmark that
    # moved far can lie nearer its twin's place; predicted at constant
    # velocity, it does not (these two draws were read as swapped when each
    # frame was compared with the one before).
    track, facing, _, _ = _clip(seed)
    assert (~facing).sum() >= 20  # the spin passes through back views
    fast = track.frames(slice(None, None, 2))
    res = decode_identity(fast)
    assert not res.swapped.any()


def test_the_front_stays_continuous_through_turns():
    track, facing, rng, _ = _turning_clip()
    bad, _ = with_identity_errors(track, facing, rng)
    res = decode_identity(bad)
    truth = np.where(facing, 1, -1)
    # As many changes of facing as the body really makes (no 180-degree flips between frames).
    assert abs(int(np.sum(res.facing[1:] != res.facing[:-1])) - int(np.sum(truth[1:] != truth[:-1]))) <= 2


def test_missing_frames_have_zero_confidence_and_stay_missing():
    track, facing, rng, _ = _turning_clip()
    bad, _ = with_identity_errors(track, facing, rng)
    bad.xy[10:20] = np.nan
    bad.world[10:20] = np.nan
    bad.visibility[10:20] = 0.0
    fixed, res = correct_identity(bad)
    assert np.all(res.confidence[10:20] == 0) and not res.swapped[10:20].any()
    assert np.all(np.isnan(fixed.xy[10:20]))


def test_identity_confidence_round_trips_and_old_tracks_read_nan(tmp_path):
    t = KeypointTrack.empty(4, 25.0, (64, 48), "blazepose")
    t.identity_confidence = np.array([1.0, 0.5, 0.0, np.nan])
    back = KeypointTrack.load(t.save(tmp_path / "k.npz"))
    np.testing.assert_array_equal(back.identity_confidence, t.identity_confidence)
    old = {k: v for k, v in np.load(tmp_path / "k.npz").items() if k != "identity_confidence"}
    np.savez(tmp_path / "old.npz", **old)
    assert np.all(np.isnan(KeypointTrack.load(tmp_path / "old.npz").identity_confidence))


def test_identity_confidence_out_of_range_is_refused():
    from capture2notation.errors import KeypointError

    t = KeypointTrack.empty(2, 25.0, (64, 48), "blazepose")
    with pytest.raises(KeypointError, match="identity_confidence"):
        KeypointTrack(**{**t.__dict__, "identity_confidence": np.array([0.5, 1.5])})


def test_identity_confidence_lowers_only_sided_joints(still_fit):
    from capture2notation.body import JOINTS

    fit = still_fit(np.ones((3, len(JOINTS))), [0.25, np.nan, 1.0])
    out = fit.labelled_confidence()
    np.testing.assert_allclose(fit.confidence, 1.0)  # the measurement itself is not lowered
    sided = [i for i, n in enumerate(JOINTS) if n.startswith(("left_", "right_"))]
    middle = [i for i, n in enumerate(JOINTS) if i not in sided]
    np.testing.assert_allclose(out[0, sided], 0.25)
    np.testing.assert_allclose(out[0, middle], 1.0)
    np.testing.assert_allclose(out[1:], 1.0)


def test_toes_minus_heels_by_hand_and_label_free():
    xy = np.full((3, 33, 2), np.nan)
    # Frame 0: both feet, toes 10 px right of and 4 px below the heels; frame 1: the left foot only.
    xy[0, [29, 30]] = [[100.0, 200.0], [120.0, 202.0]]
    xy[0, [31, 32]] = [[110.0, 204.0], [130.0, 206.0]]
    xy[1, 29], xy[1, 31] = [50.0, 60.0], [40.0, 70.0]
    got = toes_minus_heels(xy, np.array([2.0, 10.0, 1.0]))
    np.testing.assert_allclose(got[0], [5.0, 2.0])
    np.testing.assert_allclose(got[1], [-1.0, 1.0])
    assert np.all(np.isnan(got[2]))  # no foot seen
    np.testing.assert_allclose(toes_minus_heels(xy[:, MIRROR], np.array([2.0, 10.0, 1.0])), got)
