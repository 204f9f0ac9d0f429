"""Grouped emcee ensembles: autocorrelation estimator, independence of the groups, convergence flags."""

import emcee
import numpy as np
import pytest

from capture2notation.effort.likelihood import Batch
from capture2notation.effort.sampler import (
    CHECK_STRIDE,
    MAX_DRAWS,
    N_TAU,
    Chain,
    GroupedDEMove,
    integrated_time,
    run_groups,
)
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress

TAU = np.arange(1, 25) / 25


def test_integrated_time_is_emcees_estimator_per_group():
    rng = np.random.default_rng(0)
    # AR(1) chains with different correlation per group
    n, G, W = 900, 3, 6
    x = np.zeros((n, G, W, 2))
    phi = np.array([0.2, 0.8, 0.95])[None, :, None, None]
    eps = rng.standard_normal(x.shape)
    for t in range(1, n):
        x[t] = phi[0] * x[t - 1] + eps[t]
    got = integrated_time(x)
    want = np.array([emcee.autocorr.integrated_time(x[:, g], tol=0) for g in range(G)])
    np.testing.assert_allclose(got, want, rtol=1e-10)
    assert got[0, 0] < got[1, 0] < got[2, 0]


def _batch(truths, sigma=0.01, seed=1):
    rng = np.random.default_rng(seed)
    return Batch([(TAU, progress(TAU, b, x0) + sigma * rng.standard_normal(TAU.size), None, None) for b, x0 in truths])


def test_groups_never_mix_and_each_converges_to_its_own_posterior():
    truths = [(-2.0, 0.7), (-4.2, 0.35), (-3.0, 0.5)]
    batch = _batch(truths)
    chains = run_groups(batch, truths, np.full((3, 2), 0.01), np.random.default_rng(2))
    for (b, x0), ch in zip(truths, chains):
        assert ch.converged and ch.steps >= N_TAU * ch.tau.max()
        assert 0.15 < ch.acceptance < 0.8
        smp = ch.samples()
        # every sample of a group stays near its own truth (the others are > 0.8 away in b)
        assert np.all(np.abs(smp[:, 0] - b) < 0.7)
        assert np.median(smp[:, 1]) == pytest.approx(x0, abs=0.05)


def test_a_posterior_in_a_batch_matches_it_sampled_alone():
    truths = [(-2.6, 0.55), (-3.9, 0.4)]
    batch = _batch(truths, seed=5)
    together = run_groups(batch, truths, np.full((2, 2), 0.01), np.random.default_rng(3))[0].samples()
    alone = run_groups(_batch(truths[:1], seed=5), truths[:1], np.full((1, 2), 0.01), np.random.default_rng(4))[
        0
    ].samples()
    for col in (0, 1):
        lo, hi = np.percentile(alone[:, col], [5, 95])
        # medians agree to a small fraction of the 90 % width; widths to 20 %
        assert np.median(together[:, col]) == pytest.approx(np.median(alone[:, col]), abs=0.15 * (hi - lo))
        w = np.subtract(*np.percentile(together[:, col], [95, 5]))
        assert w == pytest.approx(hi - lo, rel=0.2)


def test_short_runs_are_reported_unconverged_and_bad_settings_refused():
    batch = _batch([(-2.5, 0.5)])
    (ch,) = run_groups(batch, [(-2.5, 0.5)], [(0.01, 0.002)], np.random.default_rng(0), block=40, max_steps=60)
    assert not ch.converged and ch.steps == 60
    with pytest.raises(EffortError, match="even"):
        GroupedDEMove(1, 7)
    with pytest.raises(EffortError, match="starts"):
        run_groups(batch, [(-2.5, 0.5), (-3, 0.5)], [(0.01, 0.002)], np.random.default_rng(0))


def test_a_walker_started_on_a_zero_probability_spot_is_moved_onto_a_sound_one():
    batch = _batch([(-2.5, 0.5)])
    plain = batch.log_marginal
    calls = []

    def first_call_rejects_walker_3(theta, groups=None):
        out = plain(theta, groups)
        if not calls:
            calls.append(theta.copy())
            out[3] = -np.inf
        return out

    batch.log_marginal = first_call_rejects_walker_3
    (ch,) = run_groups(batch, [(-2.5, 0.5)], [(0.01, 0.002)], np.random.default_rng(1), max_steps=50)
    start = calls[0]
    moved = ch.chain[0, 3]
    # walker 3 restarted next to one of the other starting walkers
    assert np.min(np.abs(np.delete(start, 3, axis=0) - moved).max(axis=1)) < 0.05
    assert np.all(np.isfinite(ch.chain))


def test_a_posterior_with_no_sound_starting_walker_is_refused_by_name():
    batch = _batch([(-2.5, 0.5), (-3.0, 0.4)])
    plain = batch.log_marginal

    def second_group_impossible(theta, groups=None):
        out = plain(theta, groups)
        out[len(out) // 2 :] = -np.inf
        return out

    batch.log_marginal = second_group_impossible
    with pytest.raises(EffortError, match=r"posteriors \[1\]: every starting walker"):
        run_groups(batch, [(-2.5, 0.5), (-3.0, 0.4)], np.full((2, 2), 0.01), np.random.default_rng(1))


def test_a_long_chain_returns_at_most_max_draws_spread_over_all_of_it():
    steps, W = 6000, 16
    chain = np.arange(steps, dtype=float)[:, None, None] * np.ones((1, W, 2))
    ch = Chain(chain, tau=np.array([4.0, 6.0]), acceptance=0.3, converged=True)
    smp = ch.samples()
    assert smp.shape[0] <= MAX_DRAWS and smp.shape[0] > 0.9 * MAX_DRAWS
    # burn-in 2·max τ = 12 steps, then evenly through to the chain's end
    assert smp[:, 0].min() == 12 and smp[:, 0].max() > steps - 60
    short = Chain(chain[:200], tau=np.array([4.0, 6.0]), acceptance=0.3, converged=True).samples()
    assert short.shape[0] == (200 - 12) // 2 * W  # short chains keep emcee's thinning by τ_min / 2


def test_convergence_is_checked_at_most_every_stride_of_the_chain_once_it_is_long():
    # a chain whose τ keeps growing with it (never 50 τ long) is re-estimated
    # about log(steps)/log(1 + stride) times, not once per block
    from capture2notation.effort import sampler

    batch = _batch([(-2.5, 0.5)])
    calls = []
    plain = sampler.integrated_time

    def counting(x, c=5.0):
        calls.append(x.shape[0])
        return np.full((x.shape[1], x.shape[3]), x.shape[0] / 40.0)  # needs 1.25x its length

    sampler.integrated_time = counting
    try:
        (ch,) = sampler.run_groups(
            batch, [(-2.5, 0.5)], [(0.01, 0.002)], np.random.default_rng(0), block=10, max_steps=2000
        )
    finally:
        sampler.integrated_time = plain
    assert not ch.converged and ch.stop == "gave up"
    assert calls[-1] > 1000  # given up once 50 τ exceeded the budget, after the minimum
    gaps = np.diff(calls)
    assert np.all(gaps >= np.maximum(10, np.floor(CHECK_STRIDE * np.array(calls[:-1]))))
    assert len(calls) < np.log(calls[-1] / 10) / np.log(1 + CHECK_STRIDE) + 5  # per block: > 100
