"""Laban Effort in the notation (Neagle §5.4–5.5, DESIGN.md): the value, its model and the emotion presets.

The logistic :func:`progress` and the :func:`space_radius` modulation are
the meaning of an :class:`Effort`: the virtual dancer animates with them and
the estimator (:mod:`capture2notation.effort`) fits them, so they live with
the value they interpret, below both.  Afraid's space is not given by
Neagle; 0.5 is this project's assumption.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from types import MappingProxyType

import numpy as np

from ..errors import EffortError, NotationError

__all__ = [
    "EMOTIONS",
    "PRESETS",
    "SPACE_RANGE",
    "TIME_RANGE",
    "WEIGHT_RANGE",
    "Effort",
    "Preset",
    "progress",
    "progress_speed",
    "space_radius",
]

#: Working ranges of the estimator's uniform priors.
TIME_RANGE = (-5.0, -1.5)
WEIGHT_RANGE = (0.05, 0.95)
#: Space S: 0 indirect … 1 direct.
SPACE_RANGE = (0.0, 1.0)
#: Emotions with a preset (DESIGN.md table).
EMOTIONS: tuple[str, ...] = ("happy", "sad", "angry", "afraid")


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


@dataclass(frozen=True)
class Effort:
    """Laban Effort of the logistic interpolation (Neagle §5.4–5.5).

    Parameters
    ----------
    time : float
        Gradient b of the logistic, about −2 (sustained) to −4 (sudden);
        working range [−5, −1.5].
    weight : float
        Centroid x0 in (0, 1) where speed peaks: 0.3–0.4 heavy, 0.6–0.8 light.
    space : float
        S in [0, 1]: 1 direct, 0 indirect.
    """

    time: float = -2.0
    weight: float = 0.5
    space: float = 1.0

    def __post_init__(self):
        for name, (lo, hi) in (("time", TIME_RANGE), ("weight", WEIGHT_RANGE), ("space", SPACE_RANGE)):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not (lo <= v <= hi):
                raise NotationError(f"effort {name}={v!r} is outside its working range [{lo}, {hi}]")
            object.__setattr__(self, name, float(v))


@dataclass(frozen=True)
class Preset:
    """An emotion's Effort and tempo."""

    emotion: str
    effort: Effort
    tempo: Fraction


PRESETS: MappingProxyType = MappingProxyType(
    {
        "happy": Preset("happy", Effort(time=-2.42, weight=0.60, space=0.0), Fraction(80)),
        "sad": Preset("sad", Effort(time=-2.19, weight=0.52, space=0.0), Fraction(37)),
        "angry": Preset("angry", Effort(time=-3.51, weight=0.41, space=1.0), Fraction(79)),
        "afraid": Preset("afraid", Effort(time=-2.3, weight=0.52, space=0.5), Fraction(43)),
    }
)
