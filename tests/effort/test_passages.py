"""A long clip's Effort in passages (capture2notation.effort.passages)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.effort.passages import consensus, passage_index, thinned
from capture2notation.effort.posterior import Posterior
from capture2notation.errors import EffortError


def _gaussian_posterior(rng, mean, sd, n=4000, converged=True) -> Posterior:
    samples = rng.normal(mean, sd, size=(n, 3))
    return Posterior(
        samples=samples[:, :3],
        tau=np.array([10.0, 12.0, 8.0]),
        acceptance=0.4,
        converged=converged,
        steps=1000,
        start=np.asarray(mean, float),
        rho=rng.normal(0.5, 0.05, n),
        stop="converged" if converged else "budget",
    )


def test_passages_follow_the_window_starts_and_leave_none_empty():
    starts = [0.0, 50.0, 119.0, 121.0, 500.0, 510.0]
    np.testing.assert_array_equal(passage_index(starts, 120.0), [0, 0, 0, 1, 2, 2])
    assert passage_index([], 120.0).size == 0
    with pytest.raises(EffortError, match="passage_s"):
        passage_index(starts, 0.0)


@settings(deadline=None)
@given(st.lists(st.floats(0, 1e5), min_size=1, max_size=200), st.floats(1.0, 1000.0))
def test_passage_numbers_are_consecutive_and_ordered_in_time(starts, passage_s):
    idx = passage_index(starts, passage_s)
    assert set(idx.tolist()) == set(range(idx.max() + 1))
    order = np.argsort(starts, kind="stable")
    assert np.all(np.diff(idx[order]) >= 0)


def test_thinned_keeps_evenly_spaced_rows_and_the_diagnostics():
    post = _gaussian_posterior(np.random.default_rng(0), (-3.0, 0.5, -4.0), 0.1, n=1536)
    thin = thinned(post, 500)
    assert thin.samples.shape == (500, 3) and thin.rho.shape == (500,)
    np.testing.assert_array_equal(thin.samples[0], post.samples[0])
    np.testing.assert_array_equal(thin.samples[-1], post.samples[-1])
    assert thin.tau is post.tau and thin.converged and thin.steps == 1000
    # a few hundredths of the interval's width (Monte Carlo error of 500 draws)
    width = np.subtract(*np.percentile(post.samples[:, 0], [95, 5]))
    assert abs(thin.summary(0)["median"] - post.summary(0)["median"]) < 0.05 * width
    assert thinned(post, 5000) is post


def test_consensus_of_gaussian_passages_is_their_product():
    # The product of independent Gaussian posteriors N(m_k, s_k²) is Gaussian
    # with precision Σ 1/s_k² and mean Σ (m_k / s_k²) / Σ 1/s_k².
    rng = np.random.default_rng(1)
    means = [(-3.0, 0.45, -4.0), (-2.6, 0.50, -3.8), (-3.2, 0.55, -4.1)]
    sds = [0.2, 0.3, 0.25]
    posts = [_gaussian_posterior(rng, m, s) for m, s in zip(means, sds)]
    out = consensus(posts, np.random.default_rng(2))
    prec = np.array([1 / s**2 for s in sds])
    mean = (np.array(means) * prec[:, None]).sum(0) / prec.sum()
    sd = 1 / np.sqrt(prec.sum())
    np.testing.assert_allclose(out.samples.mean(0), mean, atol=4 * sd / np.sqrt(4000) + 0.01)
    np.testing.assert_allclose(out.samples.std(0), sd, rtol=0.1)
    assert out.samples.shape == (4000, 3) and out.rho.shape == (4000,)
    assert out.steps == 3000 and out.converged and out.stop == "converged"


def test_consensus_keeps_the_prior_box_and_reports_an_unconverged_passage():
    rng = np.random.default_rng(3)
    posts = [
        _gaussian_posterior(rng, (-4.99, 0.5, -4.0), 0.05),
        _gaussian_posterior(rng, (-4.9, 0.5, -4.0), 0.05, converged=False),
    ]
    out = consensus(posts, np.random.default_rng(4))
    assert out.samples[:, 0].min() >= -5.0
    assert not out.converged and out.stop == "budget"


def test_consensus_of_one_passage_is_itself_and_of_none_an_error():
    post = _gaussian_posterior(np.random.default_rng(5), (-3.0, 0.5, -4.0), 0.1)
    assert consensus([post], np.random.default_rng(6)) is post
    with pytest.raises(EffortError, match="at least one"):
        consensus([], np.random.default_rng(6))
