"""emcee posterior of (b, x0, ln σ) for one movement or a pooled set.

Likelihood: ``s_i = progress(τ_i; b, x0) + ε_i``, ``ε_i ~ N(0, σ² / w_i)``
with ``w_i`` the frame's confidence.  Priors: uniform on the working ranges
``TIME_RANGE`` × ``WEIGHT_RANGE`` and uniform on ln σ in :data:`LOG_SIGMA_RANGE`
(scale-free noise prior).  :func:`log_probability` is this joint
log-posterior (white residuals), vectorised over walkers.

By default (``ar1=True``) the residuals ``√w_i·ε_i`` are not taken as
independent but as an AR(1) process along each movement with neighbouring
frame correlation ρ, uniform on :data:`RHO_RANGE` and sampled with (b, x0):
progress curves from fitted 3D joints have small but smooth, frame-to-frame
correlated errors, and an independent-noise likelihood then counts each
frame as new evidence and gives far too narrow intervals (see
:mod:`.likelihood` for the model and the measured figures).  White
residuals give a posterior of ρ near 0 and intervals close to the white
model's (median width ×1.0–1.25 on 24-frame curves: the price of not
knowing ρ; 90 % coverage with 5 mm joint jitter 91.7 % for b, 90.8 % for x0).

The sampler works on its exact marginal over ln σ (and over each movement's
free offset and end scale; :mod:`.likelihood`), so emcee explores (b, x0, ρ)
— or (b, x0) with ``ar1=False`` — only, and ln σ is drawn afterwards from
its exact conditional given each sample.  :func:`sample_posteriors` runs many posteriors
as independent ensembles inside one vectorised emcee sampler
(:mod:`.sampler`), which is how :func:`~.estimate.estimate_effort` samples a
phrase; :func:`sample_posterior` is the one-posterior case.

Convergence follows emcee's documentation (Autocorrelation analysis &
convergence): each chain is extended in blocks until it is longer than
:data:`N_TAU` integrated autocorrelation times and the τ estimate moved by
less than ``tau_rtol`` (5 %; the tutorial's example uses 1 %); burn-in is
2·max τ and thinning τ_min / 2.  A run that hits ``max_steps`` first is
returned with ``converged = False``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ..errors import EffortError
from ..notation.effort import TIME_RANGE, WEIGHT_RANGE
from .fit import fit_logistic_many
from .likelihood import LOG_SIGMA_RANGE, RHO_RANGE, Batch
from .sampler import N_TAU, run_groups

__all__ = [
    "LOG_SIGMA_RANGE",
    "N_TAU",
    "RHO_RANGE",
    "Posterior",
    "log_probability",
    "sample_posterior",
    "sample_posteriors",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Posterior:
    """Thinned posterior samples and the sampler's diagnostics.

    Attributes
    ----------
    samples : (M, 3) ndarray
        Columns b, x0, ln σ after burn-in and thinning.
    tau : (2,) or (3,) ndarray
        Integrated autocorrelation time of b, x0 [and ρ] (the sampled
        parameters; ln σ is drawn exactly given them), steps.
    acceptance : float
        Mean acceptance fraction over walkers.
    converged : bool
        Chain longer than ``N_TAU``·max τ with a stable τ estimate.
    steps : int
        Steps run per walker.
    start : (3,) ndarray
        Least-squares start point (b, x0, ln σ).
    rho : (M,) ndarray or None
        Samples of the residuals' frame-to-frame correlation ρ, row by row
        with `samples` (None for white residuals).
    stop : {"converged", "gave up", "budget"}
        Why sampling ended (:class:`.sampler.Chain`): "gave up" when the
        τ estimate asked for more steps than ``max_steps`` allows.
    """

    samples: np.ndarray
    tau: np.ndarray
    acceptance: float
    converged: bool
    steps: int
    start: np.ndarray
    rho: np.ndarray | None = None
    stop: str = "converged"

    def summary(self, column: int) -> dict:
        """``{"median": m, "ci90": [lo, hi]}`` of one parameter column."""
        lo, med, hi = np.percentile(self.samples[:, column], [5, 50, 95])
        return {"median": float(med), "ci90": [float(lo), float(hi)]}


def log_probability(theta, tau, s, weight, onehot=None):
    """Vectorised log-posterior (up to a constant).

    Parameters
    ----------
    theta : (W, 3) ndarray
        Walkers' (b, x0, ln σ).
    tau, s, weight : (N,) ndarray
        Data as in :func:`sample_posterior`.
    onehot : (N, G) ndarray, optional
        Movement membership of each sample.  When given, each movement's
        observed progress is ``c_g + k_g · s(τ)`` with its own offset and end
        scale (flat priors), marginalised analytically: progress is measured
        from the movement's noisy start direction and normalised by its noisy
        end, which otherwise shifts or stretches every sample of the movement
        alike.  None: ``c = 0, k = 1`` exactly.

    Returns
    -------
    (W,) ndarray
        −inf outside the prior box.
    """
    theta = np.atleast_2d(theta)
    b, x0, lns = theta[:, 0], theta[:, 1], theta[:, 2]
    inside = (
        (b > TIME_RANGE[0])
        & (b < TIME_RANGE[1])
        & (x0 > WEIGHT_RANGE[0])
        & (x0 < WEIGHT_RANGE[1])
        & (lns > LOG_SIGMA_RANGE[0])
        & (lns < LOG_SIGMA_RANGE[1])
    )
    out = np.full(theta.shape[0], -np.inf)
    if not inside.any():
        return out
    bi, xi, li = b[inside, None], x0[inside, None], lns[inside]
    # progress() inlined without its argument checks (the prior box already
    # guarantees b < 0, 0 < x0 < 1): this is the sampler's hot path
    lnx = np.log(xi)
    model = (1.0 + np.exp(-bi * lnx)) / (1.0 + np.exp(bi * (np.log(tau)[None, :] - lnx)))  # (W', N)
    if onehot is None:
        chi2 = np.sum(weight * (s - model) ** 2, axis=1)
        out[inside] = -0.5 * chi2 * np.exp(-2.0 * li) - tau.size * li
        return out
    # Gaussian integral over each (c_g, k_g): chi2 at their best values plus
    # the log-determinant of the 2x2 normal equations
    ws = weight * s
    if onehot.shape[1] == 1:  # one movement: matrix-vector products, (W', 1)
        s0, s_s, s_ss = np.sum(weight), np.sum(ws), ws @ s
        s_m, s_mm, s_sm = (model @ weight)[:, None], ((model * model) @ weight)[:, None], (model @ ws)[:, None]
    else:
        s0, s_s, s_ss = weight @ onehot, ws @ onehot, (ws * s) @ onehot  # (G,)
        wm = weight * model
        s_m, s_mm, s_sm = wm @ onehot, (wm * model) @ onehot, (ws * model) @ onehot  # (W', G)
    det = s0 * s_mm - s_m * s_m
    fit = (s_mm * s_s * s_s - 2.0 * s_m * s_s * s_sm + s0 * s_sm * s_sm) / det
    chi2 = np.sum(s_ss - fit, axis=1)
    dof = tau.size - 2 * onehot.shape[1]
    out[inside] = -0.5 * chi2 * np.exp(-2.0 * li) - dof * li - 0.5 * np.sum(np.log(det), axis=1)
    return out


#: Values of ρ tried for each posterior's starting point.
_RHO_GRID = np.linspace(RHO_RANGE[0] + 0.005, RHO_RANGE[1] - 0.005, 40)


def _rho_starts(batch: Batch, starts: np.ndarray) -> np.ndarray:
    """(G, 3) starts: each (b, x0) with the ρ of highest marginal density given it, from a grid."""
    lo, hi = batch.rho_range
    grid = np.linspace(lo + 0.005, hi - 0.005, _RHO_GRID.size)
    k = grid.size
    theta = np.column_stack([np.repeat(starts, k, axis=0), np.tile(grid, len(starts))])
    lp = batch.log_marginal(theta).reshape(len(starts), k)
    best = grid[np.argmax(np.where(np.isfinite(lp), lp, -np.inf), axis=1)]
    return np.column_stack([starts, best])


def sample_posteriors(
    datasets,
    rng: np.random.Generator | int | None,
    free_ends: bool = True,
    nwalkers: int = 16,
    block: int = 50,
    max_steps: int = 6000,
    tau_rtol: float = 0.05,
    ar1: bool = True,
    rho_range=RHO_RANGE,
) -> list:
    """Sample many independent posteriors of (b, x0, ln σ) together.

    Parameters
    ----------
    datasets : sequence of (tau, s, weight, groups)
        Per posterior: (N,) normalised time in (0, 1), progress, confidence
        (or None) and movement index of each sample (None: one movement;
        several movements share (b, x0, σ): a pooled estimate).
    rng : numpy.random.Generator or int
        Source of every random draw; required so runs are reproducible.
        Results depend on the whole list (one random stream drives it).
    free_ends : bool
        Give each movement a free offset and end scale, marginalised
        analytically; False pins s(0) = 0 and s(1) = 1 to the observed ends.
    nwalkers : int
        Walkers per posterior (even, ≥ 4; emcee advises ≥ 2 × the 2 or 3 sampled dimensions).
    block : int
        Steps between convergence checks.
    max_steps : int
        Give up (``converged = False``) after this many steps.
    tau_rtol : float
        Largest relative change of the τ estimate between checks for the
        chain to count as converged (emcee's tutorial uses 0.01; 0.05 is
        within the estimator's own noise at 50 τ).
    ar1 : bool
        AR(1) residuals along each movement with their correlation ρ
        marginalised (default); False: independent residuals.
    rho_range : (2,) tuple of float
        Uniform prior bounds of ρ: :data:`RHO_RANGE` (default), or
        :data:`~.likelihood.CAPTURE_RHO_RANGE` for a fitted capture.

    Returns
    -------
    list of Posterior
    """
    if rng is None:
        raise EffortError("sample_posteriors needs an explicit rng (numpy Generator or seed)")
    rng = np.random.default_rng(rng)
    datasets = list(datasets)
    if not datasets:
        return []
    batch = Batch(datasets, free_ends=free_ends, ar1=ar1, rho_range=rho_range)
    fits = fit_logistic_many([batch.dataset(g) for g in range(batch.n_groups)])
    starts, balls, start3 = [], [], []
    for fit in fits:
        # start inside the box even when the LSQ optimum sits on a range edge
        b0 = float(np.clip(fit.b, TIME_RANGE[0] + 0.02, TIME_RANGE[1] - 0.02))
        x00 = float(np.clip(fit.x0, WEIGHT_RANGE[0] + 0.005, WEIGHT_RANGE[1] - 0.005))
        lns0 = float(np.clip(np.log(max(fit.sigma, 1.5e-4)), LOG_SIGMA_RANGE[0] + 0.1, LOG_SIGMA_RANGE[1] - 0.1))
        starts.append((b0, x00))
        start3.append(np.array([b0, x00, lns0]))
        # a small ball: a tenth of the linearised posterior width, so that
        # walkers need not first contract (noise-free renders give widths of 1e-5)
        balls.append((min(0.01, 0.1 * fit.sd[0]), min(0.002, 0.1 * fit.sd[1])))
    if ar1:
        starts, balls = _rho_starts(batch, np.array(starts)), np.column_stack([balls, np.full(len(balls), 0.02)])
    chains = run_groups(
        batch, starts, balls, rng, nwalkers=nwalkers, block=block, max_steps=max_steps, tau_rtol=tau_rtol
    )
    out = []
    for g, ch in enumerate(chains):
        if not ch.converged:
            log.info("emcee did not converge in %d steps (%s; tau = %s)", ch.steps, ch.stop, np.round(ch.tau, 1))
        th = ch.samples()
        lns = batch.draw_log_sigma(g, th, rng)
        out.append(
            Posterior(
                samples=np.column_stack([th[:, :2], lns]),
                tau=np.asarray(ch.tau, dtype=float),
                acceptance=ch.acceptance,
                converged=ch.converged,
                steps=ch.steps,
                start=start3[g],
                rho=th[:, 2] if ar1 else None,
                stop=ch.stop,
            )
        )
    return out


def sample_posterior(
    tau,
    s,
    weight=None,
    rng: np.random.Generator | int | None = None,
    groups=None,
    free_ends: bool = True,
    nwalkers: int = 16,
    block: int = 50,
    max_steps: int = 6000,
    tau_rtol: float = 0.05,
    ar1: bool = True,
) -> Posterior:
    """Sample the posterior of (b, x0, ln σ) of one movement or one pooled set.

    Parameters
    ----------
    tau, s : (N,) array_like
        Normalised time in (0, 1) and progress of one movement, or of several
        movements concatenated (pooled estimate: one shared (b, x0, σ)).
    weight : (N,) array_like, optional
        Per-sample confidence in (0, 1].
    rng : numpy.random.Generator or int
        Source of every random draw; required.
    groups : (N,) array_like of int, optional
        Movement index of each sample when several are pooled (default: one
        movement).
    free_ends, nwalkers, block, max_steps, tau_rtol, ar1
        As for :func:`sample_posteriors`.

    Returns
    -------
    Posterior
    """
    if rng is None:
        raise EffortError("sample_posterior needs an explicit rng (numpy Generator or seed)")
    tau = np.asarray(tau, dtype=float)
    if groups is not None and np.shape(groups) != tau.shape:
        raise EffortError(f"groups must label each of the {tau.size} samples, got shape {np.shape(groups)}")
    (post,) = sample_posteriors(
        [(tau, s, weight, groups)],
        rng,
        free_ends=free_ends,
        nwalkers=nwalkers,
        block=block,
        max_steps=max_steps,
        tau_rtol=tau_rtol,
        ar1=ar1,
    )
    return post
