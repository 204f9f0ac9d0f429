"""Easing functions: endpoints, monotonicity, where the speed peaks."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import SyntheticError
from capture2notation.notation.model import Effort
from synthetic.interpolate import INTERPOLATIONS, easing, effort_easing

TAU = np.linspace(0.0, 1.0, 2001)

efforts = st.builds(
    Effort,
    time=st.floats(-5.0, -1.5),
    weight=st.floats(0.1, 0.9),
    space=st.floats(0.0, 1.0),
)


def _all_easings():
    return list(INTERPOLATIONS.values()) + [effort_easing(Effort(-2.42, 0.6, 0.0)), effort_easing(Effort(-3.51, 0.41))]


@pytest.mark.parametrize("f", _all_easings(), ids=lambda f: f.__name__)
def test_endpoints_and_monotone(f):
    s = f(TAU)
    assert s[0] == pytest.approx(0.0, abs=1e-12)
    assert s[-1] == pytest.approx(1.0, abs=1e-12)
    assert np.all(np.diff(s) >= -1e-12)
    # Out-of-range times are clipped, not extrapolated.
    assert f(np.array([-0.5, 1.5])) == pytest.approx([0.0, 1.0], abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(efforts)
def test_effort_logistic_endpoints_monotone(effort):
    s = effort_easing(effort)(TAU)
    assert s[0] == pytest.approx(0.0, abs=1e-9)
    assert s[-1] == pytest.approx(1.0, abs=1e-9)
    assert np.all(np.diff(s) >= -1e-12)


def _peak(f):
    speed = np.gradient(f(TAU), TAU)
    return TAU[np.argmax(speed)]


@settings(max_examples=40, deadline=None)
@given(st.floats(-5.0, -2.0), st.floats(0.15, 0.85))
def test_effort_speed_peaks_near_weight(b, x0):
    """Speed peaks a little before x0 (Neagle's centroid) over the emotions' range of b."""
    t_peak = _peak(effort_easing(Effort(b, x0)))
    assert 0.55 * x0 - 2e-3 <= t_peak <= x0 + 2e-3


def test_effort_peak_scales_with_weight_and_sharpens_with_time():
    heavy, light = _peak(effort_easing(Effort(-3.0, 0.3))), _peak(effort_easing(Effort(-3.0, 0.7)))
    assert light / heavy == pytest.approx(0.7 / 0.3, rel=0.02)
    sustained, sudden = _peak(effort_easing(Effort(-1.5, 0.5))), _peak(effort_easing(Effort(-5.0, 0.5)))
    assert sustained < sudden <= 0.5 + 1e-3


def test_classic_speed_profiles():
    assert np.ptp(np.gradient(INTERPOLATIONS["linear"](TAU), TAU)) < 1e-9
    assert _peak(INTERPOLATIONS["accelerate"]) == pytest.approx(1.0, abs=1e-3)
    assert _peak(INTERPOLATIONS["decelerate"]) == pytest.approx(0.0, abs=1e-3)
    assert _peak(INTERPOLATIONS["accelerate_decelerate"]) == pytest.approx(0.5, abs=1e-3)
    # Rest to rest: zero speed at both ends.
    f = INTERPOLATIONS["accelerate_decelerate"]
    assert (f(1e-4) / 1e-4) < 1e-3 and ((1 - f(1 - 1e-4)) / 1e-4) < 1e-3


def test_easing_resolves_names_efforts_callables():
    assert easing("linear") is INTERPOLATIONS["linear"]
    e = Effort(-2.19, 0.52)
    assert easing(e)(0.52) == pytest.approx(effort_easing(e)(0.52))
    f = lambda t: t  # noqa: E731
    assert easing(f) is f
    with pytest.raises(SyntheticError, match="unknown interpolation 'cubic'"):
        easing("cubic")
