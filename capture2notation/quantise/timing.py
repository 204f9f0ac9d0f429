"""When a measured movement really starts and arrives: the Effort logistic fitted to its progress.

A noisy movement is found where its speed clears the jitter
(:mod:`.spans`), but the Effort logistic of DESIGN.md,
``s(τ) = a / (1 + (τ/x0)^b)``, leaves and approaches its key poses slowly:
``s ∝ τ^|b|`` near the start, so a sudden movement (b ≈ −4) covers 3 % of
its path in its first fifth.  The speed threshold therefore cuts a fifth to
a third off every movement, late starts and early arrivals by a fixed
fraction of the duration — which reads a 64 bpm phrase as 106 bpm and puts
starts a quarter beat late.

Here the movement's normalised progress ``p(t)`` from its departure pose to
its arrival pose is fitted with the logistic over the hold-to-hold window
around it, giving the start ``t0`` and arrival ``t1`` where the curve leaves
0 and reaches 1.  The curve's Effort is fixed at :data:`REFERENCE_EFFORT`,
in the middle of the emotion presets (b −2.2 … −3.5, x0 0.41 … 0.60): on
the virtual dancer's truth joints with 1 cm jitter and random Efforts
(b −2 … −4) this gives starts and arrivals with a median bias under half
a frame and a median absolute deviation of about a frame (the threshold:
2 frames late, MAD 2), where fitting b and x0 per movement or pooled per
phrase widened movements by a frame on each side (the free tails trade
off against t0 and t1).  An Effort far from the reference biases the
fitted times by up to 2-3 frames (tests/quantise/test_quantise_timing.py).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..notation.effort import progress, progress_speed

__all__ = ["B_RANGE", "REFERENCE_EFFORT", "X0_RANGE", "fit_movement_times", "progress_signal", "refine_times"]

#: Working ranges of the Effort time b and weight x0 (DESIGN.md, widened a little).
B_RANGE = (-6.0, -1.2)
X0_RANGE = (0.2, 0.85)
#: (b, x0) of the curve fitted by :func:`refine_times`.
REFERENCE_EFFORT = (-2.5, 0.5)


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between unit vectors along the last axis, radians (precise near 0)."""
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def progress_signal(u: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Progress of unit vectors from `p0` to `p1` along the great circle.

    Parameters
    ----------
    u : (N, 3) ndarray
        Unit vectors over time.
    p0, p1 : (3,) ndarray
        Departure and arrival directions (unit).

    Returns
    -------
    (N,) ndarray
        0 at `p0`, 1 at `p1`; ``(∠(u, p0) − ∠(u, p1) + Θ) / 2Θ`` with Θ = ∠(p0, p1),
        which — unlike ∠(u, p0)/Θ alone — is not biased upwards by jitter near `p0`.
    """
    theta = float(_angle(p0, p1))
    if theta <= 0:
        return np.zeros(len(u))
    return (_angle(u, p0) - _angle(u, p1) + theta) / (2.0 * theta)


def _model(t: np.ndarray, t0: float, t1: float, b: float, x0: float) -> np.ndarray:
    return progress((t - t0) / max(t1 - t0, 1e-6), b, x0)


def fit_movement_times(t, p, t0, t1, b=None, x0=None, scale: float | None = None):
    """Fit the Effort logistic to one movement's progress.

    Parameters
    ----------
    t : (N,) ndarray
        Seconds, covering the hold before, the movement and the hold after.
    p : (N,) ndarray
        Progress (0 departure pose, 1 arrival pose); NaN ignored.
    t0, t1 : float
        Initial start and arrival (seconds), e.g. where the speed cleared the jitter.
    b, x0 : float, optional
        Fix the Effort time and weight; free (within :data:`B_RANGE`,
        :data:`X0_RANGE`) when omitted.
    scale : float, optional
        Residual scale of the robust (soft L1) loss, progress units; by
        default twice the jitter of `p` (at least 0.05), so only outliers
        beyond the jitter lose weight.

    Returns
    -------
    t0, t1, b, x0 : float
        Fitted start and arrival (seconds) and Effort.
    rms : float
        Root mean square residual, progress units.
    """
    ok = np.isfinite(p)
    t, p = np.asarray(t, float)[ok], np.asarray(p, float)[ok]
    if scale is None:
        # White jitter σ gives second differences of median |Δ²p| ≈ 1.65 σ.
        sigma = float(np.median(np.abs(np.diff(p, 2)))) / 1.65 if p.size > 3 else 0.0
        scale = max(0.05, 2.0 * sigma)
    free = b is None
    lo_t, hi_t = float(t[0]), float(t[-1])
    span = max(t1 - t0, 1e-3)
    # The true start lies before the detected one and the arrival after, by
    # at most the movement's own length (a slow tail); never outside the window.
    lb = [max(lo_t - span, t0 - span), t1 - 0.5 * span]
    ub = [t0 + 0.25 * span, min(hi_t + span, t1 + span)]
    x_init = [t0 - 0.15 * span, t1 + 0.1 * span]
    if free:
        lb += [B_RANGE[0], X0_RANGE[0]]
        ub += [B_RANGE[1], X0_RANGE[1]]
        x_init += [-2.8, 0.5]

    def resid(x):
        bb, xx = (x[2], x[3]) if free else (b, x0)
        return _model(t, x[0], x[1], bb, xx) - p

    def jac(x):
        # ds/dτ · dτ/d(t0, t1), τ = (t − t0)/(t1 − t0); flat outside [0, 1].
        d = max(x[1] - x[0], 1e-6)
        tau = (t - x[0]) / d
        ds = np.where((tau > 0) & (tau < 1), progress_speed(np.clip(tau, 1e-9, 1.0), b, x0), 0.0)
        return np.stack([ds * (tau - 1.0) / d, -ds * tau / d], axis=1)

    x_init = np.clip(x_init, np.asarray(lb) + 1e-9, np.asarray(ub) - 1e-9)
    # A tenth of a millisecond is far below a frame: no need to iterate further.
    res = least_squares(
        resid,
        x_init,
        jac="2-point" if free else jac,
        bounds=(lb, ub),
        loss="soft_l1",
        f_scale=scale,
        x_scale="jac",
        xtol=1e-4 / max(span, 1e-3),
        ftol=1e-6,
    )
    bb, xx = (float(res.x[2]), float(res.x[3])) if free else (float(b), float(x0))
    rms = float(np.sqrt(np.mean(resid(res.x) ** 2)))
    return float(res.x[0]), float(res.x[1]), bb, xx, rms


def refine_times(windows, b: float = REFERENCE_EFFORT[0], x0: float = REFERENCE_EFFORT[1]) -> np.ndarray:
    """Start and arrival times of movements, fitted with one Effort.

    Parameters
    ----------
    windows : list of (t, p, t0, t1)
        Per movement: times (N,), progress (N,), detected start and arrival
        (seconds).
    b, x0 : float
        Effort time and weight of the fitted curve (see the module docstring).

    Returns
    -------
    (M, 2) ndarray
        Fitted start and arrival of each movement, seconds.
    """
    if not windows:
        return np.zeros((0, 2))
    return np.array([fit_movement_times(*win, b=b, x0=x0)[:2] for win in windows])
