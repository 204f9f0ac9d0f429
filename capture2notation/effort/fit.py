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

__all__ = ["INWARD_DEPTH", "LogisticFit", "SpaceEstimate", "fit_logistic", "fit_space"]

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


def _truncnorm_summary(mu: float, sd: float, lo: float, hi: float, mass: float = 0.9):
    """Median and highest-density `mass` interval of N(mu, sd²) truncated to [lo, hi].

    The highest-density interval reaches the bound when the mode sits on it
    (an equal-tailed interval would then exclude the most probable values).
    """
    dist = stats.truncnorm((lo - mu) / sd, (hi - mu) / sd, loc=mu, scale=sd)
    if not np.isfinite(dist.ppf(0.5)):  # all mass far beyond one end
        v = float(np.clip(mu, lo, hi))
        return v, v, v
    mode = float(np.clip(mu, lo, hi))
    # widen a symmetric-in-density window [mode - h, mode + h] ∩ [lo, hi]
    h_lo, h_hi = 0.0, hi - lo
    for _ in range(60):
        h = 0.5 * (h_lo + h_hi)
        a, b = max(mu - h, lo), min(mu + h, hi)
        if mode in (lo, hi):
            a, b = (lo, min(lo + h, hi)) if mode == lo else (max(hi - h, lo), hi)
        if dist.cdf(b) - dist.cdf(a) < mass:
            h_lo = h
        else:
            h_hi = h
    return float(a), float(dist.ppf(0.5)), float(b)


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
    """Space from the radial deviation: ``radial ≈ c0 + c1·τ + A·sin(πτ)``, ``S = 1 − |A| / 0.1``.

    Eq. 5.5 pulls the extremity inward by ``(1 − S)·0.1·r·sin(πτ)``, so a
    direct movement (S = 1) has A = 0 and the most indirect one A = −0.1.
    The straight-line terms absorb errors of the direct path's end radii.
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
    if tau.size < 4:
        raise EffortError(f"need at least 4 samples to fit Space, got {tau.size}")
    x = np.column_stack([np.ones_like(tau), tau, np.sin(np.pi * tau)])
    sw = np.sqrt(w)
    coef, *_ = np.linalg.lstsq(x * sw[:, None], y * sw, rcond=None)
    resid = y - x @ coef
    s2 = np.sum(w * resid**2) / max(tau.size - 3, 1)
    cov = np.linalg.pinv((x * w[:, None]).T @ x)
    amp = float(coef[2])
    # floor: the dancer's own modulation is resolved to ~1e-3 of the radius
    # (S to 0.01); a noise-free render would otherwise give a zero-width interval
    se = float(max(np.sqrt(s2 * cov[2, 2]), 1e-3))
    # inward (eq. 5.5) is the model; a clear outward bulge (eq. 5.6, bent
    # limbs) is read by its depth, but noise about zero stays signed so that
    # a direct movement is not pushed below S = 1
    mu = 1.0 - abs(amp) / INWARD_DEPTH if amp > 3.0 * se else 1.0 + amp / INWARD_DEPTH
    sd = se / INWARD_DEPTH
    lo, med, hi = _truncnorm_summary(mu, sd, 0.0, 1.0)
    return SpaceEstimate(median=med, ci90=(lo, hi), amplitude=amp, amplitude_se=se)
