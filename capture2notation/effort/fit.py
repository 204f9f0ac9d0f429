"""Least-squares fits: the logistic start point and the Space amplitude.

The least-squares logistic (b, x0) is only the starting point of the emcee
posterior (:mod:`.posterior`); Space has a linear model, so its posterior is
analytic (a Gaussian on the amplitude truncated by the uniform prior on S).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

from ..errors import EffortError
from .model import TIME_RANGE, WEIGHT_RANGE, progress

__all__ = ["LogisticFit", "SpaceEstimate", "fit_logistic", "fit_space", "INWARD_DEPTH"]

#: Depth of the inward Space modulation at S = 0 (Neagle eq. 5.5: 0.1·r).
INWARD_DEPTH = 0.1


@dataclass(frozen=True)
class LogisticFit:
    """Weighted least-squares logistic: time b, weight x0, residual sigma.

    ``sd`` holds the linearised standard errors of (b, x0) at the optimum,
    for a noise level of at least ``sd_floor_sigma`` (used to size the
    sampler's starting ball); ``inf`` where the Jacobian is singular.
    """

    b: float
    x0: float
    sigma: float
    cost: float
    sd: tuple = (np.inf, np.inf)


@dataclass(frozen=True)
class SpaceEstimate:
    """Posterior of Space S ∈ [0, 1]: a truncated Gaussian.

    Attributes
    ----------
    median : float
    ci90 : tuple of float
        5 % and 95 % quantiles.
    amplitude, amplitude_se : float
        Fitted coefficient of sin(πτ) in the radial deviation and its
        standard error.
    """

    median: float
    ci90: tuple
    amplitude: float
    amplitude_se: float


def _check(tau, y, weight):
    tau = np.asarray(tau, dtype=float)
    y = np.asarray(y, dtype=float)
    w = np.ones_like(tau) if weight is None else np.asarray(weight, dtype=float)
    if tau.shape != y.shape or w.shape != tau.shape or tau.ndim != 1:
        raise EffortError(f"tau, values and weight must be equal 1-D arrays, got {tau.shape}, {y.shape}, {w.shape}")
    if tau.size < 3:
        raise EffortError(f"need at least 3 samples to fit a movement, got {tau.size}")
    if not (np.all(np.isfinite(tau)) and np.all(np.isfinite(y)) and np.all(w > 0)):
        raise EffortError("samples must be finite with positive weight (drop missing frames first)")
    return tau, y, w


def fit_logistic(tau, s, weight=None, sd_floor_sigma: float = 1e-4) -> LogisticFit:
    """Weighted least-squares (b, x0) of s(τ) within the working ranges.

    Parameters
    ----------
    tau, s : (N,) array_like
        Normalised time in (0, 1) and observed progress.
    weight : (N,) array_like, optional
        Per-sample confidence (> 0).
    sd_floor_sigma : float
        Smallest noise level assumed for the standard errors ``sd``.

    Returns
    -------
    LogisticFit
        Best of a small grid of starts (the cost surface has shallow valleys
        near the range edges).
    """
    tau, s, w = _check(tau, s, weight)
    sw = np.sqrt(w)
    lo = np.array([TIME_RANGE[0], WEIGHT_RANGE[0]])
    hi = np.array([TIME_RANGE[1], WEIGHT_RANGE[1]])

    def resid(p):
        return sw * (progress(tau, p[0], p[1]) - s)

    best = None
    for b0 in (-4.0, -2.5):
        for x00 in (0.35, 0.6):
            r = optimize.least_squares(resid, [b0, x00], bounds=(lo, hi), x_scale=[1.0, 0.1])
            if best is None or r.cost < best.cost:
                best = r
    n = tau.size
    sigma = float(np.sqrt(2 * best.cost / max(n - 2, 1) / np.mean(w)))
    jtj = best.jac.T @ best.jac
    sd = (np.inf, np.inf)
    if np.linalg.cond(jtj) < 1e12:
        var = max(sigma, sd_floor_sigma) ** 2 * np.mean(w) * np.diag(np.linalg.inv(jtj))
        sd = tuple(float(v) for v in np.sqrt(np.abs(var)))
    return LogisticFit(b=float(best.x[0]), x0=float(best.x[1]), sigma=sigma, cost=float(best.cost), sd=sd)


def fit_space(tau, radial, weight=None) -> SpaceEstimate:
    """Space from the radial deviation: ``radial ≈ A·sin(πτ)``, ``S = 1 + A / 0.1``.

    Eq. 5.5 pulls the extremity inward by ``(1 − S)·0.1·r·sin(πτ)``, so a
    direct movement (S = 1) has A = 0 and the most indirect one A = −0.1.
    The uniform prior on S ∈ [0, 1] truncates the Gaussian posterior of A;
    an outward bulge (A > 0) is read by its size, as indirect as an inward
    one of the same depth.

    Parameters
    ----------
    tau, radial : (N,) array_like
        Normalised time and radial deviation ``r / r_direct − 1``.
    weight : (N,) array_like, optional
        Per-sample confidence.
    """
    tau, y, w = _check(tau, radial, weight)
    x = np.sin(np.pi * tau)
    sxx = np.sum(w * x * x)
    amp = float(np.sum(w * x * y) / sxx)
    resid = y - amp * x
    dof = max(tau.size - 1, 1)
    s2 = np.sum(w * resid**2) / dof
    # floor: 3D positions are never better than ~1e-4 relative, and a
    # noise-free render would otherwise give a zero-width interval
    se = float(max(np.sqrt(s2 / sxx), 1e-4))
    mu = 1.0 - abs(amp) / INWARD_DEPTH
    sd = se / INWARD_DEPTH
    a, b = (0.0 - mu) / sd, (1.0 - mu) / sd
    dist = stats.truncnorm(a, b, loc=mu, scale=sd)
    lo, med, hi = (float(np.clip(q, 0.0, 1.0)) for q in dist.ppf([0.05, 0.5, 0.95]))
    return SpaceEstimate(median=med, ci90=(lo, hi), amplitude=amp, amplitude_se=se)
