"""Agreement beyond chance: the Poisson-binomial tail, κ and the same-piece verdict."""

from itertools import product

import numpy as np
import pytest
from scipy import stats

from capture2notation.compare.chance import (
    SAME_PIECE_KAPPA,
    chance_of_agreeing,
    poisson_binomial_sf,
    same_piece,
)


def test_poisson_binomial_tail_equals_the_binomial_for_equal_chances():
    for n, p in ((10, 0.2), (37, 0.55), (1, 0.9)):
        for k in range(n + 2):
            assert poisson_binomial_sf(k, np.full(n, p)) == pytest.approx(stats.binom.sf(k - 1, n, p), abs=1e-12)


def test_poisson_binomial_tail_equals_enumeration():
    p = np.array([0.1, 0.5, 0.33, 0.8, 0.05])
    for k in range(7):
        brute = sum(
            np.prod([q if x else 1 - q for q, x in zip(p, xs)]) for xs in product((0, 1), repeat=5) if sum(xs) >= k
        )
        assert poisson_binomial_sf(k, p) == pytest.approx(brute, abs=1e-12)


def test_chance_is_the_share_of_frames_in_the_target_class():
    codes = np.array([[1, 1, 2, 3], [0, 0, 0, -1]])
    np.testing.assert_allclose(chance_of_agreeing(np.array([1, -1]), codes), [0.5, 0.25])


def test_kappa_and_verdict():
    agree = np.r_[np.ones(16, bool), np.zeros(4, bool)]
    v = same_piece(agree, np.full(20, 0.25), 1.0, 1.0)
    assert v.kappa == pytest.approx((0.8 - 0.25) / 0.75) and v.same_piece and v.reason.startswith("the same piece")
    # Agreeing as often as chance predicts is not the same piece, however high the agreement.
    v = same_piece(np.r_[np.ones(18, bool), np.zeros(2, bool)], np.full(20, 0.9), 1.0, 1.0)
    assert v.kappa == pytest.approx(0.0, abs=1e-12) and v.kappa < SAME_PIECE_KAPPA and not v.same_piece
    assert "chance alone gives 90%" in v.reason
    # Perfect agreement over a tenth of the candidate's time is not the same piece either.
    v = same_piece(np.ones(20, bool), np.full(20, 0.2), 1.0, 0.1)
    assert not v.same_piece and "only 10% of the candidate's time" in v.reason
    assert not same_piece([], [], 0.0, 0.0).same_piece
