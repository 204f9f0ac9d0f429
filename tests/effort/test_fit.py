"""Least-squares logistic and the Space amplitude."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.effort.fit import fit_logistic, fit_logistic_many, fit_space
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress

TAU = np.arange(1, 30) / 30


@settings(max_examples=25, deadline=None)
@given(b=st.floats(-4.8, -1.6), x0=st.floats(0.2, 0.85))
def test_noise_free_logistic_is_recovered(b, x0):
    f = fit_logistic(TAU, progress(TAU, b, x0))
    assert f.b == pytest.approx(b, abs=1e-3)
    assert f.x0 == pytest.approx(x0, abs=1e-4)
    assert f.sigma < 1e-4


def test_noisy_fit_sigma_matches_the_noise():
    rng = np.random.default_rng(7)
    tau = np.linspace(0.01, 0.99, 400)
    s = progress(tau, -2.8, 0.5) + 0.02 * rng.standard_normal(tau.size)
    f = fit_logistic(tau, s)
    assert f.sigma == pytest.approx(0.02, rel=0.1)
    assert f.b == pytest.approx(-2.8, abs=0.15)
    assert f.x0 == pytest.approx(0.5, abs=0.01)


def test_many_fits_at_once_equal_one_at_a_time():
    rng = np.random.default_rng(11)
    sets = []
    for n, sigma in ((12, 0.0), (29, 0.01), (45, 0.03), (20, 0.003), (33, 0.05)):
        tau = np.sort(rng.uniform(0.01, 0.99, n))
        b, x0 = rng.uniform(-4.8, -1.6), rng.uniform(0.2, 0.9)
        sets.append((tau, progress(tau, b, x0) + sigma * rng.standard_normal(n), rng.uniform(0.5, 1.0, n)))
    for many, (tau, s, w) in zip(fit_logistic_many(sets), sets):
        one = fit_logistic(tau, s, w)
        assert many.cost <= one.cost * (1 + 1e-6) + 1e-20
        assert many.b == pytest.approx(one.b, abs=2e-3)
        assert many.x0 == pytest.approx(one.x0, abs=5e-4)
        assert many.sigma == pytest.approx(one.sigma, rel=1e-3, abs=1e-9)
        assert many.sd == pytest.approx(one.sd, rel=0.02)
    assert fit_logistic_many([]) == []


@pytest.mark.parametrize("space", [0.0, 0.3, 0.5, 1.0])
def test_space_from_the_inward_modulation(space):
    rng = np.random.default_rng(1)
    radial = -(1 - space) * 0.1 * np.sin(np.pi * TAU) + 0.002 * rng.standard_normal(TAU.size)
    est = fit_space(TAU, radial)
    assert est.median == pytest.approx(space, abs=0.05)
    lo, hi = est.ci90
    assert 0.0 <= lo <= est.median <= hi <= 1.0
    assert lo - 0.02 <= space <= hi + 0.02


def test_space_far_outside_the_prior_stays_finite():
    est = fit_space(TAU, -0.5 * np.sin(np.pi * TAU))  # five times the deepest inward pull
    assert est.median == pytest.approx(0.0, abs=1e-3)
    assert np.all(np.isfinite(est.ci90))


def test_bad_samples_raise():
    with pytest.raises(EffortError, match="finite"):
        fit_logistic(TAU, np.where(TAU > 0.5, np.nan, TAU))
    with pytest.raises(EffortError, match="at least 3"):
        fit_space(TAU[:2], TAU[:2])
