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


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(
    tempo=st.integers(min_value=40, max_value=120),
    seed=st.integers(min_value=0, max_value=2**31 - 1),
)
def test_tempo_from_grid_times_with_one_beat_movements(tempo, seed):
    """Movements starting on whole beats, mostly one beat long, times within ±½ frame at 25 fps (a render)."""
    rng = np.random.default_rng(seed)
    beats, t, durations = 0.0, [], []
    spb = 60.0 / tempo
    for _ in range(8):
        dur = rng.choice([1.0, 1.0, 1.0, 0.5, 2.0])
        t += [beats * spb, (beats + dur) * spb]
        durations.append(dur * spb)
        beats = np.ceil(beats + dur) + rng.choice([0.0, 1.0])
    t = np.asarray(t) + rng.uniform(-0.02, 0.02, len(t))
    # Phrases of mostly half or double beats are inherently ambiguous (a
    # reading at another tempo fits as well); the claim is for one-beat movements.
    assume(np.median(durations) == spb)
    assert estimate_tempo(t, tolerance_s=0.024, durations=durations) == tempo


def test_too_few_times_need_a_given_tempo():
    with pytest.raises(QuantiseError, match="--tempo"):
        estimate_tempo([1.0])
