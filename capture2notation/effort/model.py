"""The Laban Effort model of one movement (Neagle §5.4–5.5, DESIGN.md).

Pure functions shared by the virtual dancer (which animates with them) and the
estimator (which fits them).
"""

from __future__ import annotations

import numpy as np

from ..errors import EffortError

__all__ = ["TIME_RANGE", "WEIGHT_RANGE", "progress", "progress_speed", "space_radius"]

#: Working ranges of the estimator's uniform priors.
TIME_RANGE = (-5.0, -1.5)
WEIGHT_RANGE = (0.05, 0.95)


def progress(tau, b, x0):
    """Normalised progress s(τ) = a / (1 + (τ/x0)^b), a = 1 + (1/x0)^b.

    Parameters
    ----------
    tau : array_like
        Normalised time, clipped to [0, 1].
    b : float or array_like
        Time (gradient), negative: ≈ −2 sustained … ≈ −4 sudden.
    x0 : float or array_like
        Weight (centroid), in (0, 1).

    Returns
    -------
    ndarray
        s with s(0) = 0 and s(1) = 1, increasing; broadcast of the inputs.
    """
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    b = np.asarray(b, dtype=float)
    x0 = np.asarray(x0, dtype=float)
    if np.any(b >= 0):
        raise EffortError(f"time b must be negative, got {b}")
    if np.any((x0 <= 0) | (x0 >= 1)):
        raise EffortError(f"weight x0 must lie in (0, 1), got {x0}")
    a = 1.0 + x0 ** (-b)  # (1/x0)^b
    with np.errstate(divide="ignore", over="ignore"):
        # (τ/x0)^b = exp(b (ln τ − ln x0)); τ = 0 gives +inf and so s = 0.
        r = np.exp(b * (np.log(tau) - np.log(x0)))
    return a / (1.0 + r)


def progress_speed(tau, b, x0):
    """ds/dτ of :func:`progress` (same broadcasting), for diagnostics."""
    tau = np.clip(np.asarray(tau, dtype=float), 1e-12, 1.0)
    b = np.asarray(b, dtype=float)
    x0 = np.asarray(x0, dtype=float)
    a = 1.0 + x0 ** (-b)
    r = (tau / x0) ** b
    return -a * b * r / (tau * (1.0 + r) ** 2)


def space_radius(r, space, tau, outward: bool = False, reach=None):
    """Distance of the extremity from its bound joint during a movement.

    Inward (Neagle eq. 5.5): ``l = r − (1 − S)·0.1·r·sin(πτ)``.  Outward
    (eq. 5.6, ``l = r + (1 − S)(L − r)``, given by Neagle for the half-way
    pose) is spread over the movement the same way as eq. 5.5:
    ``l = r + (1 − S)·(L − r)·sin(πτ)`` with ``L`` the full reach, so the
    path starts and ends on the key poses.

    Parameters
    ----------
    r : array_like
        Direct-path distance, metres.
    space : float
        S in [0, 1]; 1 (direct) leaves `r` unchanged.
    tau : array_like
        Normalised time in [0, 1].
    outward : bool
        Use eq. 5.6 instead of 5.5.
    reach : float, optional
        Full reach (straight limb), required when `outward`.
    """
    if not 0.0 <= float(space) <= 1.0:
        raise EffortError(f"space S must lie in [0, 1], got {space}")
    r = np.asarray(r, dtype=float)
    bump = np.sin(np.pi * np.clip(np.asarray(tau, dtype=float), 0.0, 1.0))
    if not outward:
        return r - (1.0 - space) * 0.1 * r * bump
    if reach is None:
        raise EffortError("outward space modulation needs the limb's full reach")
    return r + (1.0 - space) * (np.maximum(float(reach), r) - r) * bump
