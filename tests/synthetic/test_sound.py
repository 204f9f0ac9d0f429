"""Sound for renders: the click track and muxing it (or a music file) into the mp4."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.errors import SyntheticError
from capture2notation.io.audio import read_audio, write_wav
from capture2notation.io.video import VideoWriter
from synthetic.render.sound import CLICK_AMPLITUDE, add_sound, click_track

RATE = 22050


@pytest.mark.parametrize("bpm,meter", [(60, 4), (97, 3), (132, 2)])
def test_a_click_on_every_beat_from_time_zero_the_first_of_each_measure_accented(bpm, meter):
    seconds = 9 * 60.0 / bpm + 0.2
    x = click_track(bpm, meter, seconds, RATE)
    assert x.dtype == np.float32 and x.size == round(seconds * RATE) and np.abs(x).max() <= 1
    # Click starts: a sample after silence (the envelope's first half-cycle rises from zero).
    loud = np.abs(x) > 1e-3
    starts = np.flatnonzero(loud & ~np.r_[False, loud[:-1]])
    starts = starts[np.r_[True, np.diff(starts) > 0.1 * RATE]]
    expected = np.round(np.arange(10) * 60.0 / bpm * RATE)
    assert starts.size == 10 and np.all(np.abs(starts - expected) <= 2)
    peaks = np.array([np.abs(x[s : s + int(0.05 * RATE)]).max() for s in starts])
    accented = np.arange(10) % meter == 0
    assert np.all(peaks[accented] > 0.8 * CLICK_AMPLITUDE[1]) and np.all(peaks[~accented] < CLICK_AMPLITUDE[0] + 1e-6)


def test_click_track_rejects_bad_arguments():
    for args, what in (((0, 4, 1.0), "tempo"), ((60, 0, 1.0), "meter"), ((60, 4, -1.0), "length")):
        with pytest.raises(SyntheticError, match=what):
            click_track(*args)


def _video(path, frames=50):
    with VideoWriter(path, 25.0, (64, 48)) as w:
        for _ in range(frames):
            w.write(np.zeros((48, 64, 3), np.uint8))
    return path


def test_add_sound_muxes_a_click_track_or_a_music_file(tmp_path):
    video = add_sound(_video(tmp_path / "v.mp4"), "click", 120, 4, 2.0)
    track = read_audio(video)
    assert track is not None and track.seconds == pytest.approx(2.0, abs=0.1)
    music = write_wav(tmp_path / "music.wav", 0.3 * np.sin(np.linspace(0, 2000, 5 * RATE)), RATE)
    track = read_audio(add_sound(_video(tmp_path / "w.mp4"), str(music), 120, 4, 2.0))
    assert track is not None and track.seconds == pytest.approx(2.0, abs=0.1)
    with pytest.raises(SyntheticError, match="no such file"):
        add_sound(_video(tmp_path / "x.mp4"), str(tmp_path / "none.mp3"), 120, 4, 2.0)
    (tmp_path / "frames").mkdir()
    with pytest.raises(SyntheticError, match="needs an mp4"):
        add_sound(tmp_path / "frames", "click", 120, 4, 2.0)
