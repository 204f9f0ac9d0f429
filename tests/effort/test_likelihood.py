"""Marginal likelihood of (b, x0): exact against brute-force integration, batch layout, ln σ draws."""

import numpy as np
import pytest
from scipy import special

from capture2notation.effort.likelihood import Batch, log_gammainc
from capture2notation.effort.posterior import LOG_SIGMA_RANGE, log_probability
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress

TAU = np.arange(1, 25) / 25
THETA = np.array([[-2.4, 0.6], [-2.45, 0.61], [-3.0, 0.5]])


def _brute_marginal(theta, tau, s, w, onehot):
    """log ∫ exp(log_probability) d ln σ over the prior, by the midpoint rule.

    (The prior's bounds themselves are excluded, so the trapezoid rule would
    be only first-order accurate.)
    """
    edges = np.linspace(*LOG_SIGMA_RANGE, 20_001)
    lns, h = 0.5 * (edges[1:] + edges[:-1]), edges[1] - edges[0]
    out = []
    for b, x0 in theta:
        lp = log_probability(np.column_stack([np.full(lns.size, b), np.full(lns.size, x0), lns]), tau, s, w, onehot)
        top = lp.max()
        out.append(top + np.log(h * np.sum(np.exp(lp - top))))
    return np.array(out)


@pytest.mark.parametrize(("sigma", "free_ends"), [(0.02, True), (1e-6, True), (0.02, False)])
def test_marginal_is_the_integral_of_the_joint_posterior_over_log_sigma(sigma, free_ends):
    # sigma = 1e-6 lies below the prior's 1e-4: the truncation of the ln σ prior matters
    rng = np.random.default_rng(1)
    tau = np.concatenate([TAU, TAU[::2]])
    mov = np.concatenate([np.zeros(TAU.size, int), np.ones(TAU[::2].size, int)])
    s = progress(tau, -2.4, 0.6) + sigma * rng.standard_normal(tau.size)
    w = np.linspace(0.5, 1.0, tau.size)
    onehot = (mov[:, None] == np.arange(2)[None]).astype(float) if free_ends else None
    want = _brute_marginal(THETA, tau, s, w, onehot)
    got = Batch([(tau, s, w, mov)], free_ends=free_ends).log_marginal(THETA)
    # equal up to one constant per posterior
    np.testing.assert_allclose(np.diff(got), np.diff(want), rtol=0, atol=1e-4)


def test_log_gammainc_matches_scipy_and_does_not_underflow():
    a = np.array([5.0, 50.0, 1200.0])
    x = np.array([2.0, 40.0, 1100.0])
    np.testing.assert_allclose(log_gammainc(a, x), np.log(special.gammainc(a, x)), rtol=1e-12)
    # far below the mode: leading terms of the series
    tiny = log_gammainc(20.0, 1e-30)
    assert tiny == pytest.approx(20 * np.log(1e-30) - special.gammaln(21.0), rel=1e-12)
    # P(1200, 300) ≈ 1e-330 underflows in scipy; against a log-space quadrature
    t = np.linspace(1e-9, 300.0, 2_000_001)
    logf = 1199.0 * np.log(t) - t
    want = special.logsumexp(logf) + np.log(t[1] - t[0]) - special.gammaln(1200.0)
    assert special.gammainc(1200.0, 300.0) == 0.0
    assert log_gammainc(1200.0, 300.0) == pytest.approx(want, rel=1e-5)


def test_batch_groups_are_evaluated_independently():
    rng = np.random.default_rng(3)
    sets = []
    for n, b, x0, n_mov in ((14, -2.2, 0.6, 1), (31, -3.8, 0.35, 1), (40, -2.9, 0.5, 3)):
        tau = np.sort(rng.uniform(0.02, 0.98, n))
        s = progress(tau, b, x0) + 0.01 * rng.standard_normal(n)
        sets.append((tau, s, rng.uniform(0.4, 1.0, n), rng.integers(0, n_mov, n)))
    k = 5
    theta = np.column_stack([rng.uniform(-4.5, -2.0, 3 * k), rng.uniform(0.3, 0.7, 3 * k)])
    theta[2] = (-5.5, 0.5)  # outside the prior box
    batch = Batch(sets)
    together = batch.log_marginal(theta)
    alone = np.concatenate([Batch([d]).log_marginal(theta[g * k : (g + 1) * k]) for g, d in enumerate(sets)])
    np.testing.assert_allclose(together, alone, rtol=1e-12)
    assert np.isneginf(together[2]) and np.isfinite(np.delete(together, 2)).all()
    # a subset of groups, in another order, gives the same rows
    sub = batch.log_marginal(np.concatenate([theta[2 * k :], theta[:k]]), groups=(2, 0))
    np.testing.assert_allclose(sub, np.concatenate([together[2 * k :], together[:k]]), rtol=1e-12)


def test_log_sigma_draws_follow_the_conditional():
    rng = np.random.default_rng(4)
    s = progress(TAU, -3.0, 0.45) + 0.01 * rng.standard_normal(TAU.size)
    batch = Batch([(TAU, s, None, None)])
    theta = np.tile([[-3.0, 0.45]], (20_000, 1))
    lns = batch.draw_log_sigma(0, theta, rng)
    chi2, _ = batch.chi2(theta[:1])
    # χ²/2σ² ~ Gamma(dof/2, 1) (the prior's bounds are far away here)
    u = chi2[0] / (2 * np.exp(2 * lns))
    assert np.mean(u) == pytest.approx(batch.dof[0] / 2, rel=0.02)
    assert np.var(u) == pytest.approx(batch.dof[0] / 2, rel=0.06)
    # noise-free data: σ piles up at the prior's lower bound but never leaves it
    clean = Batch([(TAU, progress(TAU, -3.0, 0.45), None, None)])
    lns = clean.draw_log_sigma(0, theta[:500], rng)
    assert lns.min() >= LOG_SIGMA_RANGE[0] - 1e-9
    assert np.median(lns) < LOG_SIGMA_RANGE[0] + 0.1


def test_bad_input_names_the_posterior():
    with pytest.raises(EffortError, match="posterior 1"):
        Batch([(TAU, TAU, None, None), (TAU, TAU[:-1], None, None)])
    with pytest.raises(EffortError, match="tau in"):
        Batch([(np.r_[0.0, TAU], np.r_[0.0, TAU], None, None)])
    with pytest.raises(EffortError, match="3 distinct times"):
        Batch([(np.full(10, 0.5), np.full(10, 0.4), None, None)])  # one instant: no curve to fit
    with pytest.raises(EffortError, match="at least one"):
        Batch([])
    with pytest.raises(EffortError, match="theta"):
        Batch([(TAU, TAU, None, None)]).log_marginal(np.zeros((3, 3)))


def test_sigma_integral_of_rows_in_every_regime_equals_each_row_alone():
    # a batch mixing rows whose σ sits well inside the prior with rows below
    # its lower end (a near-perfect fit) and above its upper end: each row's
    # value must not depend on which other rows share the call
    from capture2notation.effort.likelihood import _log_sigma_integral

    a = np.full(5, 11.0)
    chi2 = np.array([0.05, 1e-9, 3e-300, 40.0, 0.3])
    together = _log_sigma_integral(chi2, a)
    alone = np.array([_log_sigma_integral(chi2[i : i + 1], a[i : i + 1])[0] for i in range(chi2.size)])
    np.testing.assert_allclose(together, alone, rtol=1e-12)
    # the integral itself, by quadrature over ln σ (a = 11, χ² = 0.05 and 40),
    # up to the per-a constant ½ Γ(a) 2^a that the sampler drops
    const = np.log(0.5) + special.gammaln(a[0]) + a[0] * np.log(2.0)
    for i in (0, 3):
        lns = np.linspace(*LOG_SIGMA_RANGE, 400_001)
        f = -2 * a[i] * lns - chi2[i] / (2 * np.exp(2 * lns))
        top = f.max()  # trapezoid rule: the integrand of χ² = 40 peaks at the prior's end
        want = top + np.log(np.trapezoid(np.exp(f - top), lns))
        assert together[i] + const == pytest.approx(want, abs=1e-4)


def test_log_gammaincc_matches_scipy_and_does_not_underflow():
    from capture2notation.effort.likelihood import log_gammaincc

    a = np.array([5.0, 50.0, 1200.0])
    x = np.array([20.0, 90.0, 1500.0])
    np.testing.assert_allclose(log_gammaincc(a, x), np.log(special.gammaincc(a, x)), rtol=1e-12)
    # below 1e-280 the continued fraction is used: against scipy where it still has a value ...
    assert log_gammaincc(1200.0, 3000.0) == pytest.approx(np.log(special.gammaincc(1200.0, 3000.0)), rel=1e-9)
    # ... and against a log-space quadrature where scipy underflows
    assert special.gammaincc(1200.0, 3500.0) == 0.0
    t = np.linspace(3500.0, 3900.0, 2_000_001)
    logf = 1199.0 * np.log(t) - t
    top = logf.max()
    want = top + np.log(np.trapezoid(np.exp(logf - top), t)) - special.gammaln(1200.0)
    assert log_gammaincc(1200.0, 3500.0) == pytest.approx(want, rel=1e-7)
    # far out: the leading term e^−x x^(a−1) / Γ(a)
    assert log_gammaincc(11.0, 1e5) == pytest.approx(-1e5 + 10 * np.log(1e5) - special.gammaln(11.0), abs=1e-3)


def test_a_fit_far_worse_than_the_largest_sigma_keeps_a_finite_density():
    # garbage progress (a mis-fitted limb) must not leave every walker at
    # zero probability: the density falls off, finitely, towards worse fits
    tau = np.arange(1, 12) / 12
    s = np.array([0.2, 0.0, -2.0, -0.6, -0.8, -15.0, -37.5, -37.7, -6.7, -9.4, 4.4])
    batch = Batch([(tau, s, None, None)], ar1=True)
    lp = batch.log_marginal(np.array([[-3.0, 0.5, r] for r in (-0.4, 0.0, 0.5, 0.9)]))
    assert np.all(np.isfinite(lp))
