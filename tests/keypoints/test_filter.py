"""One-euro filter: MediaPipe's algorithm, invariants, NaN handling."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.keypoints.filter import LowPass, OneEuroFilter, object_scale


def _mediapipe_scalar(times, values, min_cutoff, beta, dcut, scale=1.0, freq=30.0):
    """one_euro_filter.cc for one signal."""

    def alpha(cutoff):
        te = 1.0 / freq
        tau = 1.0 / (2 * math.pi * cutoff)
        return 1.0 / (1.0 + tau / te)

    out, last_t, x_raw, x, dx = [], None, None, None, None
    for t, v in zip(times, values):
        if last_t is not None:
            freq = 1.0 / (t - last_t)
        last_t = t
        d = 0.0 if x_raw is None else (v - x_raw) * scale * freq
        dx = d if dx is None else alpha(dcut) * d + (1 - alpha(dcut)) * dx
        a = alpha(min_cutoff + beta * abs(dx))
        x = v if x is None else a * v + (1 - a) * x
        x_raw = v
        out.append(x)
    return np.array(out)


def test_matches_scalar_mediapipe_filter():
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.02, 0.05, 60))
    v = np.cumsum(rng.normal(0, 3, (60, 4, 3)), axis=0)
    f = OneEuroFilter(0.1, 40.0, 1.0)
    got = np.array([f(ti, vi, 0.01) for ti, vi in zip(t, v)])
    for idx in [(0, 0), (3, 2), (1, 1)]:
        ref = _mediapipe_scalar(t, v[:, idx[0], idx[1]], 0.1, 40.0, 1.0, scale=0.01)
        np.testing.assert_allclose(got[:, idx[0], idx[1]], ref, rtol=1e-12, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(s=st.floats(0.01, 100.0), seed=st.integers(0, 10_000))
def test_scale_equivariance(s, seed):
    """Filtering s·x with value_scale 1/s is s times filtering x (why MediaPipe scales)."""
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(0, 1, (30, 5)), axis=0)
    f1, f2 = OneEuroFilter(0.1, 40.0), OneEuroFilter(0.1, 40.0)
    a = np.array([f1(i / 30, xi, 1.0) for i, xi in enumerate(x)])
    b = np.array([f2(i / 30, s * xi, 1.0 / s) for i, xi in enumerate(x)])
    np.testing.assert_allclose(b, s * a, rtol=1e-9, atol=1e-9 * s)


def test_constant_is_kept_and_noise_is_reduced():
    rng = np.random.default_rng(2)
    f = OneEuroFilter(0.1, 40.0)
    const = [f(i / 30, np.full(3, 7.0)) for i in range(20)]
    np.testing.assert_allclose(const, 7.0)
    f.reset()
    noisy = 100 + rng.normal(0, 1.0, (300, 33))
    out = np.array([f(i / 30, v, 1 / 200) for i, v in enumerate(noisy)])
    # MediaPipe's pose parameters trade smoothing for lag: about half the jitter goes.
    assert out[100:].std(axis=0).mean() < 0.6 * noisy[100:].std(axis=0).mean()


def test_nan_gives_nan_and_restarts_that_signal():
    f = OneEuroFilter(0.1, 40.0)
    f(0.0, np.array([0.0, 0.0]))
    out = f(0.1, np.array([np.nan, 1.0]))
    assert np.isnan(out[0]) and np.isfinite(out[1])
    restart = f(0.2, np.array([50.0, 1.0]))
    assert restart[0] == 50.0  # no history: passes through, not pulled towards 0


def test_non_increasing_time_returns_input():
    f = OneEuroFilter(0.1, 40.0)
    f(1.0, np.array([0.0]))
    np.testing.assert_array_equal(f(1.0, np.array([5.0])), [5.0])


def test_bad_parameters_raise():
    with pytest.raises(ValueError, match="min_cutoff"):
        OneEuroFilter(0.0, 1.0)
    with pytest.raises(ValueError, match="alpha"):
        LowPass(0.0)


def test_low_pass_and_object_scale():
    lp = LowPass(0.1)
    assert lp(np.array([1.0]))[0] == 1.0
    assert lp(np.array([0.0]))[0] == pytest.approx(0.9)
    pts = np.array([[0.0, 0.0, 5.0], [10.0, 4.0, 1.0], [np.nan, np.nan, 0.0]])
    assert object_scale(pts) == pytest.approx(7.0)
    assert np.isnan(object_scale(np.full((3, 2), np.nan)))
