"""Beat-grid snapping and tempo estimation from key times."""

from __future__ import annotations

from fractions import Fraction as F

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from capture2notation.errors import QuantiseError
from capture2notation.quantise.tempo import estimate_tempo, snap


def test_snap_rounds_to_the_nearest_grid_point():
    # 60 bpm: one beat per second; grid 1/4 beat.
    assert snap(1.0, 60, F(1, 4)) == 1
    assert snap(1.12, 60, F(1, 4)) == 1
    assert snap(1.13, 60, F(1, 4)) == F(5, 4)
    assert snap(-0.3, 60, F(1, 4)) == 0
    assert snap(0.75, 120, F(1, 2)) == F(3, 2)
    with pytest.raises(QuantiseError, match="grid"):
        snap(1.0, 60, F(0))


def _phrase(tempo, seed, jitter=0.02):
    """Key times and durations (seconds) of movements on whole beats, mostly one beat long,
    times within ±`jitter` s (a render at 25 fps is within ±½ frame)."""
    rng = np.random.default_rng(seed)
    beats, t, durations = 0.0, [], []
    spb = 60.0 / tempo
    for _ in range(8):
        dur = rng.choice([1.0, 1.0, 1.0, 0.5, 2.0])
        t += [beats * spb, (beats + dur) * spb]
        durations.append(dur * spb)
        beats = np.ceil(beats + dur) + rng.choice([0.0, 1.0])
    return np.asarray(t) + rng.uniform(-jitter, jitter, len(t)), np.asarray(durations)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(
    tempo=st.integers(min_value=40, max_value=120),
    seed=st.integers(min_value=0, max_value=2**31 - 1),
)
def test_tempo_from_grid_times_with_one_beat_movements(tempo, seed):
    """Three quarters of the movements last one beat: the written tempo, exactly."""
    t, durations = _phrase(tempo, seed)
    # Phrases of mostly half or double beats are inherently ambiguous (a
    # reading at another tempo fits as well); the claim is for one-beat movements.
    assume(np.mean(np.isclose(durations, 60.0 / tempo)) >= 0.75)
    assert estimate_tempo(t, tolerance_s=0.012, durations=durations) == tempo


@settings(max_examples=60, deadline=None)
@given(
    tempo=st.integers(min_value=40, max_value=120),
    seed=st.integers(min_value=0, max_value=2**31 - 1),
)
def test_estimated_tempo_is_the_written_one_or_an_equivalent_one(tempo, seed):
    """Whatever the durations, the estimate is the tempo or a factor of two
    away, and then every key time is still on its ¼-beat grid (the same
    movements at the same seconds: accepted, see :func:`estimate_tempo`)."""
    t, durations = _phrase(tempo, seed)
    est = estimate_tempo(t, tolerance_s=0.012, durations=durations)
    assert est / tempo in (1, 2, F(1, 2))
    q = 60.0 / float(est) / 4
    assert np.all(np.abs(t - q * np.round(t / q)) <= 0.02 + 1e-9)


def test_tempo_from_noisy_times_of_a_whole_beat_phrase():
    """Port de bras timing (64 bpm, one-beat movements) with a frame of timing
    error and a spurious movement: not 106 bpm (the old estimator's reading
    of threshold-cut movements), not half or double; a frame of jitter over
    five beats leaves ±1 bpm."""
    rng = np.random.default_rng(3)
    spb = 60.0 / 64
    beats = np.array([0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 1, 2, 2, 3, 4, 5], float)
    t = beats * spb + rng.normal(0.0, 0.04, beats.size)
    t = np.r_[t, 2.61, 2.93]  # a spurious movement off the grid
    durations = np.full(8, spb) + rng.normal(0.0, 0.05, 8)
    assert abs(estimate_tempo(t, tolerance_s=0.04, durations=durations) - 64) <= 1


def test_too_few_times_need_a_given_tempo():
    with pytest.raises(QuantiseError, match="--tempo"):
        estimate_tempo([1.0])
