"""emcee posterior: log-probability, convergence reporting, reproducibility."""

import numpy as np
import pytest

from capture2notation.effort.posterior import (
    LOG_SIGMA_RANGE,
    log_probability,
    sample_posterior,
    sample_posteriors,
)
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress

TAU = np.arange(1, 25) / 25


def _data(b=-2.42, x0=0.6, sigma=0.01, seed=0):
    rng = np.random.default_rng(seed)
    return progress(TAU, b, x0) + sigma * rng.standard_normal(TAU.size)


def test_log_probability_is_the_gaussian_likelihood_of_the_model():
    s = _data()
    w = np.linspace(0.5, 1.0, TAU.size)
    theta = np.array([[-2.4, 0.58, np.log(0.02)], [-3.3, 0.45, np.log(0.05)]])
    lp = log_probability(theta, TAU, s, w)
    for row, got in zip(theta, lp):
        sig = np.exp(row[2])
        resid = s - progress(TAU, row[0], row[1])
        want = -0.5 * np.sum(w * resid**2) / sig**2 - TAU.size * np.log(sig)
        assert got == pytest.approx(want, rel=1e-10)


def test_outside_the_prior_box_is_impossible():
    s = _data()
    w = np.ones_like(TAU)
    theta = np.array([[-5.1, 0.5, -3.0], [-1.4, 0.5, -3.0], [-2.5, 0.96, -3.0], [-2.5, 0.5, LOG_SIGMA_RANGE[1] + 0.1]])
    assert np.all(np.isneginf(log_probability(theta, TAU, s, w)))


def test_posterior_contains_the_truth_and_reports_convergence():
    post = sample_posterior(TAU, _data(b=-3.51, x0=0.41, sigma=0.01), rng=3)
    assert post.converged
    assert post.steps >= 50 * post.tau.max()
    assert 0.15 < post.acceptance < 0.7
    b, x0 = post.summary(0), post.summary(1)
    assert b["median"] == pytest.approx(-3.51, abs=0.3)
    assert x0["median"] == pytest.approx(0.41, abs=0.03)
    assert b["ci90"][1] - b["ci90"][0] < 0.6
    sigma = np.exp(np.median(post.samples[:, 2]))
    assert sigma == pytest.approx(0.01, rel=0.5)


def test_same_seed_same_samples_and_short_runs_say_not_converged():
    s = _data()
    a = sample_posterior(TAU, s, rng=11, block=50, max_steps=50)
    b = sample_posterior(TAU, s, rng=11, block=50, max_steps=50)
    np.testing.assert_array_equal(a.samples, b.samples)
    assert not a.converged  # 50 steps cannot be 50 autocorrelation times
    with pytest.raises(EffortError, match="rng"):
        sample_posterior(TAU, s)


def test_ninety_percent_intervals_cover_the_truth_about_ninety_percent():
    # 20 intervals (b and x0 of 10 seeded data sets): calibrated ones miss
    # 2 on average; 7 or more misses has probability < 0.3 %.
    rng = np.random.default_rng(2005)
    hits = 0
    for _ in range(10):
        b, x0 = rng.uniform(-4.5, -1.8), rng.uniform(0.3, 0.8)
        s = progress(TAU, b, x0) + 0.015 * rng.standard_normal(TAU.size)
        post = sample_posterior(TAU, s, rng=rng)
        lo, hi = post.summary(0)["ci90"]
        lo2, hi2 = post.summary(1)["ci90"]
        hits += (lo < b < hi) + (lo2 < x0 < hi2)
    assert hits >= 20 - 6


def test_free_ends_are_marginalised_exactly():
    # against brute-force integration of the likelihood over offset c and scale k
    s = 0.01 + _data(sigma=0.02, seed=4) * 1.03
    w = np.linspace(0.6, 1.0, TAU.size)
    onehot = np.ones((TAU.size, 1))
    thetas = np.array([[-2.4, 0.6, np.log(0.02)], [-2.9, 0.5, np.log(0.03)]])
    k = np.linspace(0.8, 1.25, 901)
    c = np.linspace(-0.09, 0.11, 801)
    brute = []
    for b, x0, lns in thetas:
        sig = np.exp(lns)
        m = progress(TAU, b, x0)
        pred = c[:, None, None] + k[None, :, None] * m  # (C, K, N)
        chi2 = np.sum(w * (s - pred) ** 2, axis=2)
        like = np.exp(-0.5 * chi2 / sig**2) / sig**TAU.size
        brute.append(np.log(np.trapezoid(np.trapezoid(like, k, axis=1), c)))
    got = log_probability(thetas, TAU, s, w, onehot)
    # equal up to one constant (the flat priors' normaliser and 2π)
    assert got[0] - got[1] == pytest.approx(brute[0] - brute[1], abs=1e-4)


def test_pooled_groups_share_b_and_x0_but_not_the_ends():
    rng = np.random.default_rng(8)
    taus, ss, gs = [], [], []
    for g, k in enumerate((0.97, 1.0, 1.04)):
        taus.append(TAU)
        ss.append(0.02 * (g - 1) + k * progress(TAU, -3.0, 0.45) + 0.01 * rng.standard_normal(TAU.size))
        gs.append(np.full(TAU.size, g))
    post = sample_posterior(np.concatenate(taus), np.concatenate(ss), rng=rng, groups=np.concatenate(gs))
    lo, hi = post.summary(0)["ci90"]
    assert lo < -3.0 < hi and hi - lo < 0.4
    pinned = sample_posterior(np.concatenate(taus), np.concatenate(ss), rng=rng, free_ends=False)
    # pinning c = 0, k = 1 on shifted, mis-scaled movements inflates the noise estimate
    assert np.median(pinned.samples[:, 2]) > np.median(post.samples[:, 2]) + 0.5


def test_many_posteriors_at_once_each_cover_their_truth():
    rng = np.random.default_rng(21)
    truths = [(-2.2, 0.62), (-4.1, 0.33), (-3.0, 0.5), (-2.6, 0.75)]
    data = [(TAU, progress(TAU, b, x0) + 0.01 * rng.standard_normal(TAU.size), None, None) for b, x0 in truths]
    posts = sample_posteriors(data, rng=5)
    again = sample_posteriors(data, rng=5)
    assert len(posts) == len(truths)
    for (b, x0), post, twin in zip(truths, posts, again):
        np.testing.assert_array_equal(post.samples, twin.samples)
        assert post.converged and post.samples.shape[1] == 3
        assert post.summary(0)["median"] == pytest.approx(b, abs=0.3)
        assert post.summary(1)["median"] == pytest.approx(x0, abs=0.04)
        assert np.exp(np.median(post.samples[:, 2])) == pytest.approx(0.01, rel=0.5)
    assert sample_posteriors([], rng=0) == []
