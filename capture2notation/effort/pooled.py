"""Pooled Effort: one (b, x0, σ) shared by several movements.

A performer keeps one Effort quality across a phrase (Neagle animates every
movement of a phrase with one preset), so pooling the movements of a body
part, or of the whole phrase, sharpens the estimate.  The likelihood is the
product of the movements' likelihoods, i.e. :func:`.posterior.sample_posterior`
on the concatenated samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EffortError
from .curves import ProgressCurve
from .fit import SpaceEstimate, fit_space
from .posterior import Posterior, sample_posterior

__all__ = ["PooledEffort", "pool_curves", "pooled_posterior"]


@dataclass(frozen=True)
class PooledEffort:
    """Pooled posterior of a group of movements.

    Attributes
    ----------
    label : str
        ``"phrase"`` or the body part.
    n_movements : int
    posterior : Posterior
        Shared (b, x0, ln σ).
    space : SpaceEstimate
        Shared Space amplitude over the group.
    """

    label: str
    n_movements: int
    posterior: Posterior
    space: SpaceEstimate


def pool_curves(curves) -> tuple:
    """Concatenate the curves' (tau, s, weight, radial), each (ΣN,), plus the movement index (ΣN,) int."""
    curves = list(curves)
    if not curves:
        raise EffortError("cannot pool zero movements")
    for c in curves:
        if not isinstance(c, ProgressCurve):
            raise EffortError(f"pooling needs ProgressCurve objects, got {type(c).__name__}")
    cat = [np.concatenate([getattr(c, f) for c in curves]) for f in ("tau", "s", "weight", "radial")]
    groups = np.concatenate([np.full(c.tau.size, i) for i, c in enumerate(curves)])
    return (*cat, groups)


def pooled_posterior(curves, label: str, rng, **kw) -> PooledEffort:
    """Sample the shared posterior of `curves`.

    Parameters
    ----------
    curves : sequence of ProgressCurve
    label : str
        Name of the group (``"phrase"`` or a part).
    rng : numpy.random.Generator or int
    **kw
        Passed to :func:`.posterior.sample_posterior`.
    """
    curves = list(curves)
    tau, s, w, radial, groups = pool_curves(curves)
    post = sample_posterior(tau, s, w, rng=rng, groups=groups, **kw)
    return PooledEffort(label=label, n_movements=len(curves), posterior=post, space=fit_space(tau, radial, w))
