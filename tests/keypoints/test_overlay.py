"""The skeleton drawn on its video (:mod:`capture2notation.keypoints.overlay`)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from capture2notation.errors import KeypointError
from capture2notation.io.video import VideoWriter
from capture2notation.keypoints import KeypointTrack
from capture2notation.keypoints.overlay import write_overlay


@pytest.fixture
def clip(tmp_path):
    path = tmp_path / "clip.mp4"
    with VideoWriter(path, 25.0, (64, 48)) as w:
        for i in range(10):
            w.write(np.full((48, 64, 3), 20 * i, np.uint8))
    return path


def test_an_overlay_has_every_frame_of_its_track(clip, tmp_path):
    from capture2notation.io.video import probe

    track = KeypointTrack.empty(10, 25.0, (64, 48), backend="markers")
    out = write_overlay(clip, track, tmp_path / "overlay.mp4")
    assert probe(out).frame_count == 10


def test_a_stopped_overlay_leaves_no_file(clip, tmp_path):
    # A capture interrupted while its overlay is drawn on another thread.
    stop = threading.Event()
    stop.set()
    track = KeypointTrack.empty(10, 25.0, (64, 48), backend="markers")
    with pytest.raises(KeypointError, match="stopped at frame 0"):
        write_overlay(clip, track, tmp_path / "overlay.mp4", stop=stop)
    assert list(tmp_path.iterdir()) == [clip]
