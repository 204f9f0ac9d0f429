"""The room direction held, decoded from a measured front (:mod:`capture2notation.quantise.front_levels`)."""

from __future__ import annotations

import hypothesis.extra.numpy as hnp
import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, settings

from capture2notation.errors import QuantiseError
from capture2notation.keypoints.yaw import MAX_RATE_DEG_S
from capture2notation.quantise.front_levels import (
    _BAND,
    ERROR_CORRELATION_S,
    FRONT_SD_DEG,
    decode_front_levels,
)

FPS = 25.0


def _fit_noise(rng, n, fps=FPS, sd=FRONT_SD_DEG, corr_s=ERROR_CORRELATION_S):
    """(n,) AR(1) errors with the stated SD and correlation time: the module's own noise model."""
    a = np.exp(-1.0 / (corr_s * fps))
    e = np.zeros(n)
    e[0] = rng.normal(0.0, sd)
    for t in range(1, n):
        e[t] = a * e[t - 1] + rng.normal(0.0, sd * np.sqrt(1 - a * a))
    return e


def _ease(n):
    """(n,) a smooth 0 → 1 progress over n frames (the dancer's turns ease in and out)."""
    u = np.linspace(0.0, 1.0, n)
    return u * u * (3 - 2 * u)


@pytest.mark.parametrize("seed", range(5))
def test_a_held_front_with_fit_noise_stays_on_its_direction(seed):
    rng = np.random.default_rng(seed)
    front = 30.0 + _fit_noise(rng, int(20 * FPS))
    got = decode_front_levels(front, FPS)
    assert np.all(got.level == 0)
    # The room's direction is the one held (within the noise's standard error).
    assert abs(got.origin_deg - 30.0) <= FRONT_SD_DEG


@pytest.mark.parametrize("seed", range(3))
def test_an_eighth_turn_the_fit_reads_short_is_still_an_eighth(seed):
    """The fit under-reads an eighth turn as 30° (development captures: 30–65°), held two seconds."""
    rng = np.random.default_rng(seed)
    front = np.r_[np.zeros(50), 30.0 * _ease(13), np.full(50, 30.0)] + rng.normal(0.0, 3.0, 113)
    got = decode_front_levels(front, FPS)
    assert got.level[0] == 0 and got.level[-1] == 1
    assert np.all(np.diff(got.level) >= 0)


@pytest.mark.parametrize("seed", range(3))
def test_hips_swinging_out_and_back_hold_the_direction(seed):
    """45° out and back within half a second, as fitted hips swing: no room direction changes."""
    rng = np.random.default_rng(seed)
    swing = 45.0 * np.sin(np.linspace(0.0, np.pi, 13))
    front = np.r_[np.zeros(50), swing, np.zeros(50)] + rng.normal(0.0, 3.0, 113)
    assert np.all(decode_front_levels(front, FPS).level == 0)


@pytest.mark.parametrize("fps", [10.0, 25.0, 100.0])
def test_a_fast_double_turn_is_followed_at_any_frame_rate(fps):
    """Two turns in 0.8 s (900°/s at its peak) either side of one-second holds."""
    n = int(round(0.8 * fps))
    hold = np.zeros(int(fps))
    front = np.r_[hold, -720.0 * _ease(n), hold - 720.0]
    level = decode_front_levels(front, fps).level
    assert level[0] == 0 and level[-1] == -16
    assert np.all(np.diff(level) <= 0)


def test_the_room_directions_are_those_of_the_holds_not_of_the_camera():
    """A dancer square to a room the camera sees at 20°: holds at 20°, 65°, 110° are levels 0, 1, 2."""
    front = np.r_[np.full(50, 20.0), 20 + 45 * _ease(13), np.full(50, 65.0), 65 + 45 * _ease(13), np.full(50, 110.0)]
    got = decode_front_levels(front, FPS)
    assert got.origin_deg == pytest.approx(20.0, abs=0.5)
    assert (got.level[25], got.level[88], got.level[-1]) == (0, 1, 2)
    np.testing.assert_allclose(got.direction_deg()[[25, 88, -1]], [20.0, 65.0, 110.0], atol=0.5)


def test_an_empty_front_has_no_levels():
    got = decode_front_levels(np.zeros(0), FPS)
    assert got.level.shape == (0,)


@settings(max_examples=200, deadline=None)
@given(
    front=hnp.arrays(np.float64, st.integers(1, 120), elements=st.floats(-5000.0, 5000.0)),
    fps=st.floats(5.0, 200.0),
)
def test_any_finite_front_decodes_to_whole_eighths_reached_at_the_fastest_turn(front, fps):
    got = decode_front_levels(front, fps)
    assert got.level.shape == front.shape and got.level.dtype.kind == "i"
    assert np.isfinite(got.origin_deg)
    # No frame moves faster than the decoder follows (MAX_RATE_DEG_S, in eighths a frame).
    reach = min(_BAND, np.ceil(MAX_RATE_DEG_S / fps / 45.0))
    assert np.all(np.abs(np.diff(got.level)) <= reach)


@pytest.mark.parametrize(
    ("front", "fps", "says"),
    [
        (np.array([0.0, np.nan, 3.0]), FPS, "frame 1"),
        (np.zeros((3, 2)), FPS, "one-dimensional"),
        (np.zeros(3), 0.0, "fps"),
        (np.zeros(3), float("nan"), "fps"),
    ],
)
def test_a_bad_front_or_frame_rate_is_a_quantise_error_naming_it(front, fps, says):
    with pytest.raises(QuantiseError, match=says):
        decode_front_levels(front, fps)
