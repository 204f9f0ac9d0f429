"""Neagle's key-frame-preserving resampling (eq. 3.1) and naive decimation."""

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.compare.resample import as_rate, decimate, hold_map, in_between_frames, keyframe_resample
from capture2notation.errors import CompareError


def test_thesis_worked_example_1():
    # Neagle §3.2.4, Example 1: key frames 36 and 56 at 5 Hz from 25 Hz.
    assert in_between_frames(36, 56, 5, 25) == [41, 46, 51]


def test_thesis_worked_example_2():
    # Example 2: key frames 0 and 36, n = 7.2 rounded up to 8.
    assert in_between_frames(0, 36, 5, 25) == [5, 9, 14, 18, 23, 27, 32]


def test_whole_take_keeps_keys_and_examples():
    kept = keyframe_resample(57, [0, 36, 56], 5, 25)
    assert kept.tolist() == [0, 5, 9, 14, 18, 23, 27, 32, 36, 41, 46, 51, 56]


def test_thesis_rates_snap_to_divisors():
    assert as_rate(8.33) == Fraction(25, 3)
    assert as_rate(12.5) == Fraction(25, 2)
    assert as_rate("25/3") == Fraction(25, 3)
    assert as_rate(7) == Fraction(7)  # not near a divisor: left alone


def test_naive_decimation_loses_key_frames():
    kept = decimate(57, 5, 25)
    assert kept.tolist() == list(range(0, 57, 5))
    assert 36 not in kept and 56 not in kept  # the thesis' Figure 3.9 point
    assert decimate(10, 8.33).tolist() == [0, 3, 6, 9]


def test_full_rate_keeps_everything():
    assert keyframe_resample(30, [7, 19], 25, 25).tolist() == list(range(30))
    assert decimate(30, 25).tolist() == list(range(30))


def test_hold_map_repeats_last_kept_frame():
    assert hold_map(np.array([0, 3, 7]), 9).tolist() == [0, 0, 0, 3, 3, 3, 3, 7, 7]


def test_errors_name_the_bad_value():
    with pytest.raises(CompareError, match="36 then 36"):
        in_between_frames(36, 36, 5)
    with pytest.raises(CompareError, match="exceeds"):
        keyframe_resample(10, [], 50)
    with pytest.raises(CompareError, match="key frames must lie"):
        keyframe_resample(10, [12], 5)
    with pytest.raises(CompareError, match="not a number"):
        as_rate("fast")


@settings(max_examples=150, deadline=None)
@given(
    keys=st.lists(st.integers(0, 299), min_size=0, max_size=8),
    k=st.sampled_from([1, 2, 3, 5]),
)
def test_properties(keys, k):
    rate = Fraction(25, k)
    kept = keyframe_resample(300, keys, rate, 25)
    assert set(keys) <= set(kept.tolist())
    assert np.all(np.diff(kept) > 0)
    # n = ceil(N r / R) intervals over N frames: no gap exceeds R / r frames.
    assert np.diff(kept).max(initial=0) <= k
    # Never more frames than the naive rate plus one per key segment.
    assert len(kept) <= len(decimate(300, rate)) + len(set(keys)) + 2
