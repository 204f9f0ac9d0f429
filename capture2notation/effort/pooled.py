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
from .fit import NO_SPACE, SpaceEstimate, fit_space
from .posterior import Posterior, sample_posterior

__all__ = ["PooledEffort", "curve_space", "pool_curves", "pooled_posterior", "pooled_space"]


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


def curve_space(curve: ProgressCurve) -> SpaceEstimate:
    """Space of one movement; :data:`.fit.NO_SPACE` for parts that cannot show it."""
    if not curve.shows_space:
        return NO_SPACE
    return fit_space(curve.tau, curve.radial, curve.weight, curve.outward)


def pooled_space(curves) -> SpaceEstimate:
    """Shared Space of `curves`, from the whole limbs among them only.

    A head or single-segment movement keeps its radius whatever the Space
    (the dancer modulates the reach of whole limbs), so pooling its flat
    radial deviation would pull every phrase towards S = 1.

    Returns :data:`.fit.NO_SPACE` when no whole limb moved.
    """
    limbs = [c for c in curves if c.shows_space]
    if not limbs:
        return NO_SPACE
    tau, _, w, radial, groups = pool_curves(limbs)
    return fit_space(tau, radial, w, np.concatenate([c.outward for c in limbs]), groups)


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
    tau, s, w, _, groups = pool_curves(curves)
    post = sample_posterior(tau, s, w, rng=rng, groups=groups, **kw)
    return PooledEffort(label=label, n_movements=len(curves), posterior=post, space=pooled_space(curves))
