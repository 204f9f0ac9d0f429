"""The beat of a sound track as tempo evidence (librosa: the optional ``audio`` extra)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from capture2notation.io.audio import SoundTrack
from capture2notation.quantise.beats import (
    LEVEL_WEIGHTS,
    BeatTrackerMissing,
    SoundBeats,
    sound_beats,
)
from synthetic.render.sound import click_track

RATE = 22050


def _clicks(bpm, beats, meter=4):
    return SoundTrack(click_track(bpm, meter, beats * 60.0 / bpm + 0.1), RATE, "clicks")


@pytest.mark.parametrize("bpm,beats", [(37, 5), (64, 5), (97, 8), (132, 12)])
def test_click_track_tempo_within_half_a_percent(bpm, beats):
    pytest.importorskip("librosa")
    found = sound_beats(_clicks(bpm, beats))
    assert found is not None and found.tempo == pytest.approx(bpm, rel=0.005)
    # The beats are the clicks, k·60/bpm from time 0 (the onset is a hop at most late).
    k = np.round(found.beat_times * bpm / 60.0)
    assert np.all(np.abs(found.beat_times - k * 60.0 / bpm) < 0.03)


@pytest.mark.slow
def test_click_tracks_of_every_dance_tempo():
    pytest.importorskip("librosa")
    for bpm in range(36, 151, 3):
        for beats in (4, 8):
            found = sound_beats(_clicks(bpm, beats))
            assert found is not None and found.tempo == pytest.approx(bpm, rel=0.01), (bpm, beats)


def test_no_steady_beat_is_none():
    pytest.importorskip("librosa")
    assert sound_beats(SoundTrack(np.zeros(3 * RATE, np.float32), RATE)) is None  # silence
    assert sound_beats(_clicks(60, 2)) is None  # two clicks are no beat
    # Seven clicks at random times in six seconds: four of them may fall
    # nearly regularly by chance, but rarely (5 of these 40 draws).
    one, found = click_track(60, 1, 0.05), 0
    for seed in range(40):
        x = np.zeros(6 * RATE + one.size, np.float32)
        for s in np.random.default_rng(seed).uniform(0, 6, 7):
            x[int(s * RATE) : int(s * RATE) + one.size] += one
        found += sound_beats(SoundTrack(x, RATE)) is not None
    assert found <= 8


def test_without_librosa_a_clear_message(monkeypatch):
    monkeypatch.setitem(sys.modules, "librosa", None)  # import librosa raises ImportError
    with pytest.raises(BeatTrackerMissing, match=r"pip install 'capture2notation\[audio\]'"):
        sound_beats(_clicks(60, 8))


def test_evidence_is_the_beat_or_half_or_double_it():
    beats = SoundBeats(tempo=80.0, relative_sd=0.005, beat_times=np.arange(8) * 0.75, irregularity=0.0)
    ll = beats.log_likelihood(np.array([40.0, 80.0, 160.0, 60.0, 100.0]))
    # Densities in log-tempo: the peaks stand in the ratio of the level weights.
    assert ll[1] - ll[0] == pytest.approx(np.log(LEVEL_WEIGHTS[1.0] / LEVEL_WEIGHTS[0.5]), abs=0.01)
    assert ll[1] > ll[0] and ll[1] > ll[2] and min(ll[0], ll[2]) > max(ll[3], ll[4]) + 5
    assert beats.refine(81.0) == 80.0 and beats.refine(39.0) == 40.0 and beats.refine(60.0) is None
