"""Many independent emcee ensembles advanced together in one vectorised sampler.

Each posterior ("group") of a :class:`.likelihood.Batch` gets its own
ensemble of walkers; one ``emcee.EnsembleSampler`` holds all of them, group
by group, and :class:`GroupedDEMove` — emcee's differential-evolution move
(Nelson et al. 2013) — draws each walker's proposal from its own group's
complementary half only, so the ensembles never mix and each is an ordinary
emcee ensemble of its own posterior.  The win is emcee's per-step overhead,
paid once for all groups, and one numpy evaluation of the log-probability
for every walker of every group.

Convergence is judged per group with emcee's integrated autocorrelation
time (its ``autocorr.integrated_time`` estimator, vectorised over groups by
:func:`integrated_time`).  The estimate costs a whole-chain FFT, so it is
not redone every block: after each estimate a group is next checked when
its chain reaches :data:`CHECK_AHEAD` × N_TAU × τ (then each time it has
grown by :data:`CHECK_STRIDE`), and
a group whose τ asks for more than the step budget after
:data:`GIVE_UP_MIN_STEPS` steps is given up (reported as such).  Chains are
kept in preallocated arrays grown by doubling.  A group is done
when its chain is longer than :data:`N_TAU` τ and τ moved by less than
``tau_rtol`` since the last check (emcee's "Saving & monitoring progress"
tutorial uses 100 τ and 1 %; its autocorrelation tutorial calls 50 τ
enough for a reliable estimate).  Done groups leave the sampler; the rest
run on until ``max_steps`` and are then reported as not converged.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import emcee
import numpy as np
import scipy.fft

from ..errors import EffortError
from .likelihood import Batch

__all__ = [
    "CHECK_AHEAD",
    "CHECK_STRIDE",
    "GIVE_UP_FACTOR",
    "GIVE_UP_MIN_STEPS",
    "MAX_DRAWS",
    "N_TAU",
    "Chain",
    "GroupedDEMove",
    "integrated_time",
    "run_groups",
]

#: Chain length required, in autocorrelation times (emcee docs: ≥ 50 τ).
N_TAU = 50
#: A group's τ is next estimated once its chain reaches this fraction of
#: N_TAU times the last estimate (τ grows as the chain explores, and a check
#: too late only costs a block): most checks need no FFT at all.
CHECK_AHEAD = 0.8
#: Once a chain is that long, τ is re-estimated each time the chain has
#: grown by this fraction (at least a block): a converging chain is found at
#: most this much late, and its τ estimates cost a few whole-chain FFTs
#: instead of one per block.
CHECK_STRIDE = 0.1
#: Give up on a posterior whose chain needs more than this many times the
#: step budget by its current τ estimate ...
GIVE_UP_FACTOR = 1.0
#: ... once it has run at least this many steps (shorter chains' τ
#: estimates are too noisy to act on).
GIVE_UP_MIN_STEPS = 1000
#: Most draws a chain returns after burn-in and thinning.  A converged
#: chain holds about W·steps/τ ≥ N_TAU·W = 800 effective draws (16 walkers);
#: beyond a few thousand, further draws are correlated copies that move a
#: 90 % interval by Monte Carlo noise only, yet every one costs a χ²
#: evaluation when its ln σ is drawn.
MAX_DRAWS = 2000
#: Largest FFT work array of :func:`integrated_time`, elements.
_FFT_CHUNK = 1 << 22


class GroupedDEMove(emcee.moves.Move):
    """emcee's DEMove within each of `n_groups` independent ensembles.

    Walkers are stored group-major, `nwalkers` per group.  Each step splits
    every group at random into two halves (the red-blue scheme of
    ``emcee.moves.RedBlueMove``) and proposes ``x + γ (c1 − c2)`` with c1 ≠ c2
    from the group's other half and ``γ = γ0 (1 + σ·N(0, 1))``.  Acceptance
    is vectorised; the log-probability is called directly with the proposals
    of all groups (group-major, ``nwalkers / 2`` rows per group), so it must
    be a vectorised function of that layout.

    Parameters
    ----------
    n_groups, nwalkers : int
        Ensembles and walkers per ensemble (even, ≥ 4).
    sigma : float
        Relative jitter of γ (emcee's default).
    gamma0 : float, optional
        Default ``2.38 / sqrt(2 ndim)``, as emcee's DEMove.
    """

    def __init__(self, n_groups: int, nwalkers: int, sigma: float = 1.0e-5, gamma0: float | None = None):
        if nwalkers < 4 or nwalkers % 2:
            raise EffortError(f"walkers per group must be even and >= 4, got {nwalkers}")
        self.n_groups, self.nwalkers = int(n_groups), int(nwalkers)
        self.sigma, self.gamma0 = float(sigma), gamma0

    def propose(self, model, state):
        """One red-blue update of every group; returns (state, accepted (G·W,) bool)."""
        rnd = model.random
        G, W = self.n_groups, self.nwalkers
        n, ndim = state.coords.shape
        if n != G * W:
            raise EffortError(f"expected {G}x{W} walkers, got {n}")
        g0 = self.gamma0 if self.gamma0 is not None else 2.38 / np.sqrt(2 * ndim)
        h = W // 2
        # flat walker indices of each group's two random halves, (G, h) each
        perm = np.argsort(rnd.rand(G, W), axis=1) + (W * np.arange(G))[:, None]
        halves = (perm[:, :h], perm[:, h:])
        base = (h * np.arange(G))[:, None]
        accepted = np.zeros(n, dtype=bool)
        coords, logp = state.coords, state.log_prob
        for split in (0, 1):
            mine, other = halves[split].ravel(), halves[1 - split].ravel()
            c = coords[other]  # (G·h, ndim), group-major
            i1 = rnd.randint(0, h, size=(G, h))
            i2 = (i1 + rnd.randint(1, h, size=(G, h))) % h  # a different walker of the same group
            gamma = g0 * (1.0 + self.sigma * rnd.randn(G * h, 1))
            q = coords[mine] + gamma * (c[(base + i1).ravel()] - c[(base + i2).ravel()])
            new = np.asarray(model.log_prob_fn(q), dtype=float)
            ok = new - logp[mine] > np.log(rnd.rand(G * h))
            walker = mine[ok]
            coords[walker] = q[ok]
            logp[walker] = new[ok]
            accepted[walker] = True
        return state, accepted


def integrated_time(x, c: float = 5.0) -> np.ndarray:
    """emcee's integrated autocorrelation time estimate, per group and parameter.

    Same estimator as ``emcee.autocorr.integrated_time(x[:, g], c=c, tol=0)``
    for each group g: the walkers' normalised autocorrelation functions
    averaged, summed over a window chosen by Sokal's rule with constant `c`.

    Parameters
    ----------
    x : (n_steps, G, W, ndim) array_like
        Chains of G ensembles of W walkers.
    c : float
        Window constant.

    Returns
    -------
    (G, ndim) ndarray
        NaN where a walker never moved.
    """
    x = np.asarray(x, dtype=float)
    n, G = x.shape[:2]
    out = np.empty((G, x.shape[3]))
    # zero padding to at least 2n makes the circular correlation linear;
    # emcee pads to a power of two, a 5-smooth length is as exact and up to 2x shorter
    m = scipy.fft.next_fast_len(2 * n, real=True)
    per_group = max(1, _FFT_CHUNK // (m * int(np.prod(x.shape[2:]))))
    for a in range(0, G, per_group):
        xs = x[:, a : a + per_group]
        f = scipy.fft.rfft(xs - xs.mean(axis=0), n=m, axis=0)
        acf = scipy.fft.irfft(f * np.conj(f), n=m, axis=0)[:n]
        with np.errstate(divide="ignore", invalid="ignore"):
            acf = acf / acf[0]
        taus = 2.0 * np.cumsum(acf.mean(axis=2), axis=0) - 1.0  # (n, g, ndim)
        inside = np.arange(n)[:, None, None] < c * taus
        window = np.where(inside.any(axis=0), np.argmin(inside, axis=0), n - 1)
        out[a : a + per_group] = np.take_along_axis(taus, window[None], axis=0)[0]
    return out


@dataclass(frozen=True)
class Chain:
    """One group's chain and diagnostics.

    Attributes
    ----------
    chain : (steps, W, ndim) ndarray
        θ = (b, x0[, ρ]) of every walker at every step.
    tau : (ndim,) ndarray
        Integrated autocorrelation time of each parameter, steps.
    acceptance : float
        Mean acceptance fraction of the group's walkers.
    converged : bool
    stop : {"converged", "gave up", "budget"}
        Why sampling ended: converged; given up early because even the
        (low-biased) τ estimate asked for more than the budget; the budget
        ran out.
    """

    chain: np.ndarray
    tau: np.ndarray
    acceptance: float
    converged: bool
    stop: str = "converged"

    @property
    def steps(self) -> int:
        return int(self.chain.shape[0])

    def samples(self) -> np.ndarray:
        """(M, ndim) after burn-in 2·max τ and thinning by min τ / 2 (emcee's tutorial), M ≤ MAX_DRAWS."""
        tau = self.tau[np.isfinite(self.tau) & (self.tau > 0)]
        tmax = float(tau.max()) if tau.size else self.steps / N_TAU
        tmin = float(tau.min()) if tau.size else 1.0
        burn = min(int(2 * tmax), self.steps // 2)
        walkers = self.chain.shape[1]
        thin = max(1, int(0.5 * tmin), -(-(self.steps - burn) * walkers // MAX_DRAWS))
        return self.chain[burn::thin].reshape(-1, self.chain.shape[-1])


def _walker_ball(start, ball, nwalkers, rng, bounds):
    """(W, ndim) walkers around `start` with per-parameter sd `ball`, inside the prior box (ndim, 2)."""
    p = start + ball * rng.standard_normal((nwalkers, start.size))
    margin = 1e-4 * (bounds[:, 1] - bounds[:, 0])
    return np.clip(p, bounds[:, 0] + margin, bounds[:, 1] - margin)


def run_groups(
    batch: Batch,
    starts,
    balls,
    rng: np.random.Generator,
    nwalkers: int = 16,
    block: int = 50,
    max_steps: int = 6000,
    tau_rtol: float = 0.05,
) -> list:
    """Sample every group of `batch` to convergence (or `max_steps`).

    Parameters
    ----------
    batch : Batch
    starts, balls : (G, batch.ndim) array_like
        Centre and per-parameter sd of each group's starting ball.
    rng : numpy.random.Generator
        Source of every draw (balls and emcee's moves).
    nwalkers : int
        Walkers per group (even, ≥ 4).
    block : int
        Steps between convergence checks.
    max_steps : int
        Steps after which the remaining groups stop, not converged.
    tau_rtol : float
        Largest relative change of τ between checks for convergence.

    Returns
    -------
    list of Chain
        One per group, in order.
    """
    G, W, D = batch.n_groups, int(nwalkers), batch.ndim
    starts, balls = np.asarray(starts, dtype=float), np.asarray(balls, dtype=float)
    if starts.shape != (G, D) or balls.shape != (G, D):
        raise EffortError(f"starts and balls must be ({G}, {D}), got {starts.shape} and {balls.shape}")
    if block < 1 or max_steps < 1:
        raise EffortError(f"block and max_steps must be >= 1, got {block} and {max_steps}")
    coords = np.concatenate([_walker_ball(starts[g], balls[g], W, rng, batch.bounds) for g in range(G)])
    logp = batch.log_marginal(coords)
    bad = ~np.isfinite(logp)
    if bad.any():
        # a walker of the ball on a degenerate spot: restart it on a sound walker of its group
        ok = ~bad.reshape(G, W)
        if not ok.any(axis=1).all():
            raise EffortError(
                f"posteriors {np.flatnonzero(~ok.any(axis=1)).tolist()}: every starting walker "
                "has zero probability (degenerate data?)"
            )
        for i in np.flatnonzero(bad):
            g = i // W
            j = g * W + int(rng.choice(np.flatnonzero(ok[g])))
            coords[i] = coords[j] * (1.0 + 1e-6 * rng.standard_normal(D))
        logp = batch.log_marginal(coords)
    random = np.random.RandomState(int(rng.integers(2**32)))
    active = list(range(G))
    store = {g: np.empty((min(4 * block, max_steps), W, D)) for g in active}  # grown by doubling
    accepted = np.zeros(G)
    old_tau = np.full((G, D), np.inf)
    next_check = np.full(G, block)  # step count at which each group's τ is next estimated
    result: dict[int, Chain] = {}
    steps = 0
    while active:
        n_a = len(active)
        run = min(block, max_steps - steps)
        sampler = emcee.EnsembleSampler(
            n_a * W,
            D,
            functools.partial(batch.log_marginal, groups=tuple(active)),
            vectorize=True,
            moves=GroupedDEMove(n_a, W),
        )
        sampler.random_state = random.get_state()
        state = sampler.run_mcmc(emcee.State(coords, log_prob=logp), run, progress=False, skip_initial_state_check=True)
        random.set_state(sampler.random_state)
        blk = sampler.get_chain().reshape(run, n_a, W, D)
        acc = sampler.backend.accepted.reshape(n_a, W).sum(axis=1)
        for j, g in enumerate(active):
            if store[g].shape[0] < steps + run:
                grown = np.empty((min(2 * store[g].shape[0], max_steps), W, D))
                grown[:steps] = store[g][:steps]
                store[g] = grown
            store[g][steps : steps + run] = blk[:, j]
            accepted[g] += acc[j]
        steps += run
        at_end = steps >= max_steps
        # τ (a whole-chain FFT) only for groups that may have converged by
        # now, judged from their last estimate, and at the budget's end
        due = [j for j, g in enumerate(active) if at_end or steps >= next_check[g]]
        finished = np.zeros(n_a, dtype=bool)
        if due:
            tau = integrated_time(np.stack([store[active[j]][:steps] for j in due], axis=1))
            for i, j in enumerate(due):
                g, t = active[j], tau[i]
                with np.errstate(invalid="ignore"):
                    ok = bool(
                        np.all(np.isfinite(t))
                        and steps >= N_TAU * np.max(t)
                        and np.all(np.abs(old_tau[g] - t) / t < tau_rtol)
                    )
                need = N_TAU * float(np.max(t)) if np.all(np.isfinite(t)) else np.inf
                # τ estimates of short chains are biased low, so a need that
                # exceeds the budget even so will not be met: stop now
                give_up = not ok and steps >= GIVE_UP_MIN_STEPS and need > GIVE_UP_FACTOR * max_steps
                if ok or give_up or at_end:
                    stop = "converged" if ok else ("gave up" if give_up else "budget")
                    result[g] = Chain(store[g][:steps].copy(), t, float(accepted[g] / (steps * W)), ok, stop)
                    del store[g]
                    finished[j] = True
                old_tau[g] = t
                # next estimate: once the chain nears 50 τ, and from then on
                # each time it has grown by CHECK_STRIDE (at least a block),
                # so that the FFTs of a long chain cost a bounded multiple of one
                soon = steps + max(block, -(-int(CHECK_STRIDE * steps) // block) * block)
                ahead = CHECK_AHEAD * need
                # (no finite τ yet, e.g. a walker that never moved: look again soon)
                late = np.isfinite(ahead) and steps < ahead
                next_check[g] = max(soon, int(ahead) // block * block) if late else soon
        keep = np.flatnonzero(~finished)
        coords = state.coords.reshape(n_a, W, D)[keep].reshape(-1, D)
        logp = state.log_prob.reshape(n_a, W)[keep].ravel()
        active = [active[j] for j in keep]
    return [result[g] for g in range(G)]
