"""Easing functions τ → s of one movement (Cachola 1986 ch. 3; Neagle 2005 §5.4).

Every function maps normalised time ``tau`` in [0, 1] to normalised progress
``s`` in [0, 1] with s(0) = 0, s(1) = 1 and s non-decreasing.  Cachola's
LIG ANIMATE offers *linear*, *accelerate*, *decelerate* and *accelerate-
decelerate* between key frames; Neagle's virtual dancer uses the Laban
Effort logistic, which is :func:`capture2notation.notation.effort.progress`
(re-exported here, not re-implemented).
"""

from __future__ import annotations

from collections.abc import Callable
from types import MappingProxyType

import numpy as np

from capture2notation.errors import SyntheticError
from capture2notation.notation.effort import progress
from capture2notation.notation.model import Effort

__all__ = [
    "INTERPOLATIONS",
    "accelerate",
    "accelerate_decelerate",
    "decelerate",
    "easing",
    "effort_easing",
    "linear",
    "progress",
]


def _tau(tau) -> np.ndarray:
    return np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)


def linear(tau):
    """Constant speed: s = τ.

    Parameters
    ----------
    tau : array_like
        Normalised time, clipped to [0, 1].

    Returns
    -------
    ndarray
        Progress s, same shape as `tau`.
    """
    return _tau(tau)


def accelerate(tau):
    """Start at rest, speed up (ease-in): s = τ²."""
    t = _tau(tau)
    return t * t


def decelerate(tau):
    """Start at speed, slow to rest (ease-out): s = 1 − (1 − τ)²."""
    t = 1.0 - _tau(tau)
    return 1.0 - t * t


def accelerate_decelerate(tau):
    """Rest to rest (Cachola's ACCDCC): the cubic s = 3τ² − 2τ³, speed peaks at τ = ½."""
    t = _tau(tau)
    return t * t * (3.0 - 2.0 * t)


def effort_easing(effort: Effort) -> Callable[[np.ndarray], np.ndarray]:
    """The Laban Effort logistic of `effort` as an easing function.

    Parameters
    ----------
    effort : Effort
        Its ``time`` is the gradient b, its ``weight`` the centroid x0.

    Returns
    -------
    callable
        ``f(tau) -> s`` = :func:`progress` ``(tau, effort.time, effort.weight)``.
    """
    b, x0 = float(effort.time), float(effort.weight)

    def f(tau):
        return progress(tau, b, x0)

    f.__name__ = f"effort(b={b:g}, x0={x0:g})"
    return f


#: The four classic interpolations by name.
INTERPOLATIONS: MappingProxyType = MappingProxyType(
    {
        "linear": linear,
        "accelerate": accelerate,
        "decelerate": decelerate,
        "accelerate_decelerate": accelerate_decelerate,
    }
)


def easing(kind) -> Callable[[np.ndarray], np.ndarray]:
    """Resolve an interpolation given by name, Effort, or callable.

    Parameters
    ----------
    kind : str, Effort or callable
        A key of :data:`INTERPOLATIONS`, an :class:`Effort` (its logistic) or
        an easing function ``tau -> s``.
    """
    if callable(kind):
        return kind
    if isinstance(kind, Effort):
        return effort_easing(kind)
    if isinstance(kind, str) and kind in INTERPOLATIONS:
        return INTERPOLATIONS[kind]
    raise SyntheticError(
        f"unknown interpolation {kind!r}; expected one of {', '.join(INTERPOLATIONS)}, an Effort or a function tau -> s"
    )
