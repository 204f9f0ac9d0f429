"""A long clip's Effort in passages: memory bounded, cost linear in its length.

A pooled posterior (a part's or the phrase's movements sharing one
(b, x0, σ), :mod:`.pooled`) holds every sample of its movements for every
walker, so pooling a whole rehearsal at once takes memory and time per step
in proportion to its length: an hour of movements is about 700 k samples.
A clip longer than :data:`PASSAGE_S` is therefore sampled passage by
passage, each passage with its own pooled part and phrase posteriors, and
the clip's pooled posteriors are the passages' combined by consensus Monte
Carlo (Scott et al. 2016, "Bayes and big data: the consensus Monte Carlo
algorithm"): with the uniform priors of :mod:`.posterior` the clip's
posterior is the product of the passages', and each passage's is taken as
Gaussian to combine their draws, precision-weighted.  The Space of a pooled
group is a linear estimate over its curves, computed for the whole clip at
once (:func:`.pooled.pooled_space`).

Each movement's posterior keeps at most :data:`KEEP_DRAWS` draws once it is
summarised for a long clip: its median and 90 % interval move by a few
hundredths of their width, and an hour's movements fit in memory.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import EffortError
from ..notation.effort import TIME_RANGE, WEIGHT_RANGE
from .likelihood import LOG_SIGMA_RANGE, RHO_RANGE
from .posterior import Posterior

__all__ = ["KEEP_DRAWS", "PASSAGE_S", "consensus", "passage_index", "thinned"]

#: Seconds of movements pooled at once (windows starting in the same
#: passage): about 500 movements of a dense phrase, a few hundred MB.
PASSAGE_S = 120.0
#: Draws kept per movement posterior in a clip of several passages.
KEEP_DRAWS = 500
#: Added to each passage's covariance diagonal before inverting it (the
#: square of a thousandth of the narrowest parameter range): a posterior
#: squeezed to a point still has a finite precision.
_RIDGE = 1e-6


def passage_index(starts, passage_s: float = PASSAGE_S) -> np.ndarray:
    """Passage of each movement from its window's start, seconds: (M,) int from 0, no empty passage.

    Raises
    ------
    EffortError
        On a non-positive passage length.
    """
    if not (np.isfinite(passage_s) and passage_s > 0):
        raise EffortError(f"passage_s must be > 0 seconds, got {passage_s!r}")
    starts = np.asarray(starts, dtype=float)
    if starts.size == 0:
        return np.zeros(0, dtype=int)
    raw = np.floor((starts - starts.min()) / passage_s).astype(int)
    _, index = np.unique(raw, return_inverse=True)
    return index.reshape(-1)


def thinned(post: Posterior, keep: int = KEEP_DRAWS) -> Posterior:
    """`post` with at most `keep` draws, evenly spaced along its thinned chains (deterministic)."""
    n = post.samples.shape[0]
    if n <= keep:
        return post
    rows = np.linspace(0, n - 1, keep).round().astype(int)
    return replace(post, samples=post.samples[rows], rho=None if post.rho is None else post.rho[rows])


def consensus(posteriors, rng: np.random.Generator) -> Posterior:
    """One posterior from independent passages' posteriors of the same parameters.

    Parameters
    ----------
    posteriors : sequence of Posterior
        Each passage's (b, x0, ln σ [, ρ]) draws.
    rng : numpy.random.Generator
        Pairs the passages' draws.

    Returns
    -------
    Posterior
        Draws ``θ = (Σ W_k)⁻¹ Σ W_k θ_k`` with ``W_k`` the inverse covariance
        of passage k's draws, as many as the smallest passage has, kept in
        the prior's box; τ is the largest of the passages', acceptance their
        mean, steps their sum, converged only if all are.
    """
    posts = list(posteriors)
    if not posts:
        raise EffortError("consensus needs at least one posterior")
    if len(posts) == 1:
        return posts[0]
    with_rho = all(p.rho is not None for p in posts)
    m = min(p.samples.shape[0] for p in posts)
    if m < 2:
        raise EffortError("consensus needs at least two draws per posterior")
    draws, weights = [], []
    for p in posts:
        rows = rng.choice(p.samples.shape[0], size=m, replace=False)
        theta = p.samples[rows]
        if with_rho:
            theta = np.column_stack([theta, p.rho[rows]])
        cov = np.atleast_2d(np.cov(theta, rowvar=False)) + _RIDGE * np.eye(theta.shape[1])
        w = np.linalg.inv(cov)
        draws.append(theta)
        weights.append(w)
    total = np.sum(weights, axis=0)
    combined = np.linalg.solve(total, np.sum([th @ w.T for th, w in zip(draws, weights)], axis=0).T).T
    box = [TIME_RANGE, WEIGHT_RANGE, LOG_SIGMA_RANGE] + ([RHO_RANGE] if with_rho else [])
    lo, hi = (np.array([b[i] for b in box], dtype=float) for i in (0, 1))
    combined = np.clip(combined, lo, hi)
    stops = [p.stop for p in posts]
    return Posterior(
        samples=combined[:, :3],
        tau=np.max([np.asarray(p.tau, float) for p in posts], axis=0),
        acceptance=float(np.mean([p.acceptance for p in posts])),
        converged=all(p.converged for p in posts),
        steps=int(sum(p.steps for p in posts)),
        start=np.mean([p.start for p in posts], axis=0),
        rho=combined[:, 3] if with_rho else None,
        stop="converged" if all(s == "converged" for s in stops) else next(s for s in stops if s != "converged"),
    )
