"""AR(1) residuals: exact against a dense Gaussian, and honest intervals under correlated noise."""

import numpy as np
import pytest
from scipy import linalg

from capture2notation.effort.fit import fit_space
from capture2notation.effort.likelihood import CAPTURE_RHO_RANGE, RHO_RANGE, Batch
from capture2notation.effort.posterior import sample_posteriors
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress

TAU = np.arange(1, 25) / 25
#: a missing frame (τ = 10/25): the gap correlates as ρ²
GAPPED = np.delete(TAU, 9)


def _ar1(rng, n, rho, sigma):
    """(n,) stationary AR(1) noise with neighbour correlation `rho` and sd `sigma`."""
    e = np.empty(n)
    e[0] = rng.standard_normal()
    for i in range(1, n):
        e[i] = rho * e[i - 1] + np.sqrt(1 - rho**2) * rng.standard_normal()
    return sigma * e


def _dense(theta, tau, s, w, free_ends):
    """χ² and log-determinants by dense generalised least squares (σ = 1)."""
    b, x0, rho = theta
    lag = np.abs(tau[:, None] - tau[None, :]) / np.median(np.diff(tau))
    corr = np.sign(rho) ** np.round(lag) * np.abs(rho) ** lag
    cov = corr / np.sqrt(np.outer(w, w))
    m = progress(tau, b, x0)
    inv = linalg.inv(cov)
    logdet_r = np.linalg.slogdet(corr)[1]
    if not free_ends:
        r = s - m
        return r @ inv @ r, logdet_r
    x = np.column_stack([np.ones_like(tau), m])
    gram = x.T @ inv @ x
    beta = linalg.solve(gram, x.T @ inv @ s)
    r = s - x @ beta
    return r @ inv @ r, np.linalg.slogdet(gram)[1] + logdet_r


@pytest.mark.parametrize("free_ends", [True, False])
@pytest.mark.parametrize("rho", [0.85, 0.3, -0.4])
def test_whitened_chi2_and_determinants_equal_the_dense_gaussian(rho, free_ends):
    rng = np.random.default_rng(3)
    s = progress(GAPPED, -3.0, 0.5) + 0.02 * rng.standard_normal(GAPPED.size)
    w = rng.uniform(0.4, 1.0, GAPPED.size)
    theta = np.array([[-2.8, 0.55, rho], [-3.5, 0.45, rho]])
    batch = Batch([(GAPPED, s, w, None)], free_ends=free_ends, ar1=True)
    chi2, logdet = batch.chi2(theta)
    for i, th in enumerate(theta):
        want_chi2, want_logdet = _dense(th, GAPPED, s, w, free_ends)
        assert chi2[i] == pytest.approx(want_chi2, rel=1e-8)
        assert logdet[i] == pytest.approx(want_logdet, rel=1e-8, abs=1e-8)


def test_rho_zero_is_the_white_likelihood():
    rng = np.random.default_rng(4)
    tau = np.concatenate([TAU, GAPPED])
    mov = np.r_[np.zeros(TAU.size, int), np.ones(GAPPED.size, int)]
    s = progress(tau, -2.5, 0.6) + 0.01 * rng.standard_normal(tau.size)
    theta = np.array([[-2.4, 0.6], [-3.1, 0.5]])
    white = Batch([(tau, s, None, mov)]).log_marginal(theta)
    ar1 = Batch([(tau, s, None, mov)], ar1=True).log_marginal(np.column_stack([theta, [0.0, 0.0]]))
    np.testing.assert_allclose(ar1, white, rtol=1e-12)
    with pytest.raises(Exception, match="theta"):
        Batch([(tau, s, None, mov)], ar1=True).log_marginal(theta)  # ρ column missing


def _coverage(rho, sigma, n_sets, ar1, seed):
    rng = np.random.default_rng(seed)
    truths = np.column_stack([rng.uniform(-4.2, -2.0, n_sets), rng.uniform(0.35, 0.7, n_sets)])
    data = [(TAU, progress(TAU, b, x0) + _ar1(rng, TAU.size, rho, sigma), None, None) for b, x0 in truths]
    posts = sample_posteriors(data, rng=seed + 1, ar1=ar1)
    hits, widths = [], []
    for (b, x0), post in zip(truths, posts):
        for col, truth in ((0, b), (1, x0)):
            lo, hi = post.summary(col)["ci90"]
            hits.append(lo <= truth <= hi)
            widths.append(hi - lo)
    return np.mean(hits), np.array(widths), posts


def test_ar1_intervals_cover_correlated_noise_and_white_ones_do_not():
    # 40 movements x 2 parameters: a true 90 % rate lands in [0.81, 0.97] 95 % of the time
    cover, _, posts = _coverage(0.5, 0.01, 40, True, 10)
    assert 0.80 <= cover <= 0.98
    assert all(p.converged for p in posts)
    # ρ is recovered: median over movements of the posterior median
    assert np.median([np.median(p.rho) for p in posts]) == pytest.approx(0.5, abs=0.15)
    naive, _, _ = _coverage(0.5, 0.01, 40, False, 10)
    assert naive < 0.75  # independent-noise intervals are too narrow on the same data


def test_white_noise_intervals_stay_calibrated_under_the_ar1_model():
    cover, w_ar1, posts = _coverage(0.0, 0.01, 30, True, 20)
    white, w_white, _ = _coverage(0.0, 0.01, 30, False, 20)
    assert 0.83 <= cover <= 1.0 and 0.83 <= white <= 1.0
    # the price of not knowing ρ on 24 frames: intervals up to ~1/4 wider, never narrower
    assert 0.95 <= np.median(w_ar1 / w_white) <= 1.3
    assert abs(np.median([np.median(p.rho) for p in posts])) < 0.2
    assert all(RHO_RANGE[0] <= p.rho.min() and p.rho.max() <= RHO_RANGE[1] for p in posts)


def test_space_interval_widens_with_correlated_radial_noise():
    rng = np.random.default_rng(7)
    tau = np.arange(1, 50) / 50
    truth = -0.05 * np.sin(np.pi * tau)  # S = 0.5
    hits_ar, hits_white = [], []
    for _ in range(40):
        noise = _ar1(rng, tau.size, 0.9, 0.01)
        est = fit_space(tau, truth + noise)
        hits_ar.append(est.ci90[0] <= 0.5 <= est.ci90[1])
        # the same data with the correlation destroyed (shuffled noise) is white
        white = fit_space(tau, truth + rng.permutation(noise))
        hits_white.append(white.ci90[0] <= 0.5 <= white.ci90[1])
    assert 0.78 <= np.mean(hits_ar) <= 1.0
    assert np.mean(hits_white) >= 0.78


def test_the_capture_prior_of_rho_covers_smooth_noise_of_short_movements():
    """AR(1) noise of ρ 0.9 on 24 samples: the default prior's intervals cover ~66 % (too narrow: one
    short movement hardly measures a high ρ); with CAPTURE_RHO_RANGE, a true 90 % rate (40 movements x
    2 parameters lands in [0.81, 0.97] 95 % of the time)."""
    rng = np.random.default_rng(12)
    tau = np.arange(1, 25) / 25
    truths = np.column_stack([rng.uniform(-4.2, -2.0, 40), rng.uniform(0.35, 0.7, 40)])
    data = [(tau, progress(tau, b, x0) + _ar1(rng, tau.size, 0.9, 0.01), None, None) for b, x0 in truths]
    posts = sample_posteriors(data, rng=13, rho_range=CAPTURE_RHO_RANGE)
    hits = [
        p.summary(col)["ci90"][0] <= truth <= p.summary(col)["ci90"][1]
        for (b, x0), p in zip(truths, posts)
        for col, truth in ((0, b), (1, x0))
    ]
    assert 0.80 <= np.mean(hits) <= 0.98
    assert all(CAPTURE_RHO_RANGE[0] <= p.rho.min() and p.rho.max() <= CAPTURE_RHO_RANGE[1] for p in posts)


def test_rho_range_is_checked():
    with pytest.raises(EffortError, match="rho_range"):
        Batch([(TAU, TAU, None, None)], ar1=True, rho_range=(0.5, 1.0))


def test_every_row_of_a_batch_on_an_irregular_grid_equals_the_dense_gaussian():
    # bin-averaged curves (high frame rates) have uneven steps: most entries
    # then take φ = ρ^(Δτ/δ), the rest φ = ρ; several posteriors and several
    # walkers per posterior, each row with its own ρ
    rng = np.random.default_rng(8)
    grids = [np.sort(rng.uniform(0.02, 0.98, n)) for n in (17, 30, 9)]
    data = [
        (t, progress(t, -2.6, 0.5) + 0.02 * rng.standard_normal(t.size), rng.uniform(0.5, 1, t.size)) for t in grids
    ]
    batch = Batch([(t, s, w, None) for t, s, w in data], ar1=True)
    theta = np.array(
        [
            [-2.5, 0.52, 0.9],
            [-3.1, 0.47, 0.35],
            [-2.0, 0.6, 0.7],
            [-4.0, 0.4, 0.05],
            [-2.7, 0.5, 0.97],
            [-1.8, 0.7, 0.5],
        ]
    )
    chi2, logdet = batch.chi2(theta)  # two rows per posterior, group-major
    for i, th in enumerate(theta):
        t, s, w = data[i // 2]
        want_chi2, want_logdet = _dense(th, t, s, w, True)
        assert chi2[i] == pytest.approx(want_chi2, rel=1e-7)
        assert logdet[i] == pytest.approx(want_logdet, rel=1e-7, abs=1e-7)
