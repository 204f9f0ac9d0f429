"""KeypointTrack: contract shapes, .npz round trip, clear errors."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.errors import KeypointError
from capture2notation.keypoints import LANDMARK_NAMES, KeypointTrack, landmark_index


def _track(t=5, seed=0):
    rng = np.random.default_rng(seed)
    tr = KeypointTrack.empty(t, 25.0, (640, 480), "blazepose")
    tr.xy[1:] = rng.uniform(0, 480, (t - 1, 33, 3))
    tr.visibility[1:] = rng.uniform(0, 1, (t - 1, 33))
    tr.presence[1:] = 0.9
    tr.world[1:] = rng.normal(0, 0.5, (t - 1, 33, 3))
    tr.crops[1:] = (320, 240, 400, 400, 0.1)
    return tr


def test_round_trip(tmp_path):
    tr = _track()
    path = tr.save(tmp_path / "track.npz")
    back = KeypointTrack.load(path)
    for name in ("times", "image_size", "xy", "visibility", "presence", "world", "crops"):
        np.testing.assert_array_equal(getattr(back, name), getattr(tr, name))
    assert back.fps == 25.0 and back.backend == "blazepose" and len(back) == 5
    assert back.names == LANDMARK_NAMES
    # Missing frame 0 stays NaN with zero visibility (never zeros).
    assert np.isnan(back.xy[0]).all() and (back.visibility[0] == 0).all()


def test_save_leaves_no_temporary_files(tmp_path):
    _track().save(tmp_path / "t.npz")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.npz"]


def test_bad_shapes_are_named():
    tr = _track()
    with pytest.raises(KeypointError, match=r"'xy'.*\(5, 33, 3\)"):
        KeypointTrack(25.0, tr.times, (640, 480), tr.xy[:, :20], tr.visibility, tr.presence, tr.world, tr.crops)
    with pytest.raises(KeypointError, match="visibility outside"):
        KeypointTrack(25.0, tr.times, (640, 480), tr.xy, tr.visibility + 2, tr.presence, tr.world, tr.crops)
    with pytest.raises(KeypointError, match="fps"):
        KeypointTrack(0.0, tr.times, (640, 480), tr.xy, tr.visibility, tr.presence, tr.world, tr.crops)


def test_load_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, xy=np.zeros(3))
    with pytest.raises(KeypointError, match=r"bad\.npz.*missing fields"):
        KeypointTrack.load(bad)
    with pytest.raises(KeypointError, match="nothere"):
        KeypointTrack.load(tmp_path / "nothere.npz")


def test_landmark_index():
    assert landmark_index("left_wrist") == 15 and landmark_index("right_foot_index") == 32
    with pytest.raises(KeypointError, match="left_wirst"):
        landmark_index("left_wirst")


def test_the_face_cue_round_trips_and_older_tracks_read_it_as_not_assessed(tmp_path):
    from dataclasses import replace

    tr = replace(_track(), face=np.array([np.nan, 1.0, 0.0, np.nan, 1.0]))
    back = KeypointTrack.load(tr.save(tmp_path / "face.npz"))
    np.testing.assert_array_equal(back.face, tr.face)
    older = tmp_path / "older.npz"
    with np.load(tmp_path / "face.npz") as data:
        np.savez(older, **{k: data[k] for k in data.files if k not in ("face", "identity_confidence")})
    old = KeypointTrack.load(older)
    assert np.isnan(old.face).all() and np.isnan(old.identity_confidence).all()
    with pytest.raises(KeypointError, match="face outside"):
        replace(tr, face=np.full(5, 2.0))


def test_frames_cuts_every_per_frame_field():
    from dataclasses import replace

    tr = replace(_track(), face=np.arange(5) / 4.0, identity_confidence=np.full(5, 0.5))
    part = tr.frames(slice(1, 4))
    assert len(part) == 3
    for name in ("times", "xy", "visibility", "presence", "world", "crops", "face", "identity_confidence"):
        np.testing.assert_array_equal(getattr(part, name), getattr(tr, name)[1:4])
    assert part.fps == tr.fps and part.backend == tr.backend
