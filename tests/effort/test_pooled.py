"""Pooling movements: concatenation with movement labels, shared posterior."""

import numpy as np
import pytest

from capture2notation.effort.curves import ProgressCurve
from capture2notation.effort.pooled import pool_curves, pooled_posterior
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress


def _curve(n, seed, b=-2.8, x0=0.5, space=0.5):
    rng = np.random.default_rng(seed)
    tau = np.arange(1, n) / n
    s = progress(tau, b, x0) + 0.01 * rng.standard_normal(tau.size)
    radial = -(1 - space) * 0.1 * np.sin(np.pi * tau) + 0.001 * rng.standard_normal(tau.size)
    return ProgressCurve("right_arm", 0.0, 1.0, tau, s, np.ones_like(tau), radial, 1.0)


def test_pool_curves_labels_each_movement():
    tau, s, w, radial, groups = pool_curves([_curve(10, 0), _curve(20, 1)])
    assert tau.shape == s.shape == w.shape == radial.shape == groups.shape == (9 + 19,)
    np.testing.assert_array_equal(np.bincount(groups), [9, 19])
    with pytest.raises(EffortError, match="zero"):
        pool_curves([])
    with pytest.raises(EffortError, match="ProgressCurve"):
        pool_curves([np.arange(3)])


def test_pooled_posterior_is_sharper_than_one_movement():
    curves = [_curve(25, k) for k in range(4)]
    one = pooled_posterior(curves[:1], "right_arm", rng=0)
    four = pooled_posterior(iter(curves), "phrase", rng=0)  # any iterable
    assert four.n_movements == 4 and four.label == "phrase"
    width = [np.subtract(*p.posterior.summary(0)["ci90"][::-1]) for p in (one, four)]
    assert width[1] < 0.75 * width[0]
    assert four.posterior.summary(0)["median"] == pytest.approx(-2.8, abs=0.15)
    assert four.space.median == pytest.approx(0.5, abs=0.05)
