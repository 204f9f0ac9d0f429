"""The Effort logistic and Space modulation (Neagle eqs. 5.4-5.6)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress, progress_speed, space_radius

b_st = st.floats(-5.0, -1.5)
x0_st = st.floats(0.1, 0.9)


@settings(max_examples=60, deadline=None)
@given(b_st, x0_st)
def test_progress_endpoints_and_monotone(b, x0):
    tau = np.linspace(0, 1, 401)
    s = progress(tau, b, x0)
    assert s[0] == pytest.approx(0.0, abs=1e-12)
    assert s[-1] == pytest.approx(1.0, abs=1e-12)
    assert np.all(np.diff(s) >= -1e-12)


@settings(max_examples=40, deadline=None)
@given(st.floats(-5.0, -2.5), st.floats(0.3, 0.7))
def test_speed_peaks_near_x0(b, x0):
    tau = np.linspace(1e-4, 1, 20001)
    peak = tau[np.argmax(progress_speed(tau, b, x0))]
    # x0 is the centroid in log-time; ds/dtau itself peaks a little earlier, at
    # x0 * ((b - 1) / (b + 1)) ** (1 / b): within 30 % of x0 over this range.
    assert abs(peak - x0) <= 0.3 * x0
    assert peak == pytest.approx(x0 * ((b - 1) / (b + 1)) ** (1 / b), abs=2e-3)


def test_speed_matches_finite_difference():
    tau = np.linspace(0.05, 0.95, 50)
    h = 1e-6
    fd = (progress(tau + h, -3.0, 0.4) - progress(tau - h, -3.0, 0.4)) / (2 * h)
    np.testing.assert_allclose(progress_speed(tau, -3.0, 0.4), fd, rtol=1e-5)


def test_progress_rejects_bad_parameters():
    with pytest.raises(EffortError, match="negative"):
        progress(0.5, 2.0, 0.5)
    with pytest.raises(EffortError, match=r"\(0, 1\)"):
        progress(0.5, -2.0, 1.2)


def test_space_direct_leaves_radius_unchanged():
    tau = np.linspace(0, 1, 11)
    np.testing.assert_allclose(space_radius(0.5, 1.0, tau), 0.5)


def test_space_inward_is_ten_percent_at_mid_movement():
    r = space_radius(0.5, 0.0, np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(r, [0.5, 0.45, 0.5], atol=1e-12)
    half = space_radius(0.5, 0.5, 0.5)
    assert half == pytest.approx(0.475)


def test_space_outward_reaches_full_length_when_indirect():
    r = space_radius(0.5, 0.0, np.array([0.0, 0.5, 1.0]), outward=True, reach=0.6)
    np.testing.assert_allclose(r, [0.5, 0.6, 0.5], atol=1e-12)
    with pytest.raises(EffortError, match="reach"):
        space_radius(0.5, 0.0, 0.5, outward=True)
