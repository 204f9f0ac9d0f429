"""Least-squares fits: the logistic start point and the Space amplitude.

The least-squares logistic (b, x0) is only the starting point of the emcee
posterior (:mod:`.posterior`); Space has a linear model, so its posterior is
analytic (a Gaussian on the amplitude truncated by the uniform prior on S).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, special, stats

from ..errors import EffortError
from ..notation.effort import TIME_RANGE, WEIGHT_RANGE, progress

__all__ = [
    "INWARD_DEPTH",
    "MIN_OUTWARD_DEPTH",
    "NO_SPACE",
    "LogisticFit",
    "SpaceEstimate",
    "fit_logistic",
    "fit_logistic_many",
    "fit_space",
]

#: Depth of the inward Space modulation at S = 0 (Neagle eq. 5.5: 0.1·r).
INWARD_DEPTH = 0.1
#: Smallest mean outward depth (fraction of the radius, see
#: :attr:`.curves.ProgressCurve.outward`) for which an outward bulge is read
#: against eq. 5.6; a nearly straight limb has no outward room, and a bulge
#: there is noise or an inward model's sign error.
MIN_OUTWARD_DEPTH = 0.005


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


#: Space of a movement that cannot show it (head, chest, single segments
#: keep the free joint's distance): the uniform prior's median and 90 % interval.
NO_SPACE = SpaceEstimate(median=0.5, ci90=(0.05, 0.95), amplitude=float("nan"), amplitude_se=float("inf"))


def _truncnorm_summary(mu: float, sd: float, lo: float, hi: float, mass: float = 0.9):
    """Median and highest-density `mass` interval of N(mu, sd²) truncated to [lo, hi].

    The highest-density interval reaches the bound when the mode sits on it
    (an equal-tailed interval would then exclude the most probable values).
    """
    za, zb = (lo - mu) / sd, (hi - mu) / sd
    # Φ differences from the nearer tail keep their precision; scipy's
    # truncnorm (log-space, 100x slower) only where even that underflows
    flip = za > 0
    z_mass = special.ndtr(-za) - special.ndtr(-zb) if flip else special.ndtr(zb) - special.ndtr(za)
    if z_mass > 1e-12:
        if flip:

            def cdf(x):
                return (special.ndtr(-za) - special.ndtr(-(x - mu) / sd)) / z_mass

            median = mu - sd * special.ndtri(special.ndtr(-za) - 0.5 * z_mass)
        else:

            def cdf(x):
                return (special.ndtr((x - mu) / sd) - special.ndtr(za)) / z_mass

            median = mu + sd * special.ndtri(special.ndtr(za) + 0.5 * z_mass)
    else:
        dist = stats.truncnorm(za, zb, loc=mu, scale=sd)
        cdf, median = dist.cdf, dist.ppf(0.5)
        if not np.isfinite(median):  # all mass far beyond one end
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
        if cdf(b) - cdf(a) < mass:
            h_lo = h
        else:
            h_hi = h
    return float(a), float(np.clip(median, lo, hi)), float(b)


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


#: Starting points (b, x0) of the least-squares searches (as in fit_logistic).
_STARTS = ((-4.0, 0.35), (-4.0, 0.6), (-2.5, 0.35), (-2.5, 0.6))


def _model_and_jacobian(b, x0, logtau):
    """progress(τ; b, x0) and its partial derivatives in b and x0, elementwise (E,)."""
    lnx = np.log(x0)
    xb = np.exp(-b * lnx)  # x0^−b = (1/x0)^b
    amp = 1.0 + xb
    r = np.exp(b * (logtau - lnx))  # (τ/x0)^b
    inv = 1.0 / (1.0 + r)
    m = amp * inv
    # ds/dp = (da/dp)/(1 + r) − a (dr/dp)/(1 + r)²
    d_b = (-lnx * xb) * inv - m * inv * r * (logtau - lnx)
    d_x = (-b * xb / x0) * inv + m * inv * r * b / x0
    return m, d_b, d_x


def fit_logistic_many(datasets, iterations: int = 60, sd_floor_sigma: float = 1e-4) -> list:
    """:func:`fit_logistic` for many data sets at once (vectorised Levenberg–Marquardt).

    Every data set is fitted from the same four starts as :func:`fit_logistic`
    by a projected Levenberg–Marquardt iteration within the working ranges,
    all starts of all data sets advancing together; the best start wins.

    Parameters
    ----------
    datasets : sequence of (tau, s, weight)
        Per data set (N,) arrays as for :func:`fit_logistic` (weight may be None).
    iterations : int
        Levenberg–Marquardt iterations (it stops earlier once no step helps).
    sd_floor_sigma : float
        Smallest noise level assumed for the standard errors ``sd``.

    Returns
    -------
    list of LogisticFit
    """
    data = [_check(*d) for d in datasets]
    if not data:
        return []
    ns = np.array([d[0].size for d in data])
    logtau = np.log(np.concatenate([d[0] for d in data]))
    s = np.concatenate([d[1] for d in data])
    w = np.concatenate([d[2] for d in data])
    n_start = len(_STARTS)
    rows = np.arange(ns.size * n_start)  # row = data set · n_start + start
    offsets = np.concatenate([[0], np.cumsum(ns)])
    row_of = np.repeat(rows, np.repeat(ns, n_start))  # (E,)
    col = np.concatenate([np.tile(np.arange(offsets[g], offsets[g + 1]), n_start) for g in range(ns.size)])
    lt, ss, ww = logtau[col], s[col], w[col]
    lo = np.array([TIME_RANGE[0], WEIGHT_RANGE[0]])
    hi = np.array([TIME_RANGE[1], WEIGHT_RANGE[1]])
    p = np.tile(np.array(_STARTS, dtype=float), (ns.size, 1))  # (R, 2)

    def evaluate(p):
        m, db, dx = _model_and_jacobian(p[row_of, 0], p[row_of, 1], lt)
        r = m - ss
        nr = rows.size
        cost = 0.5 * np.bincount(row_of, ww * r * r, nr)
        jtj = np.stack([np.bincount(row_of, ww * a * c, nr) for a, c in ((db, db), (db, dx), (dx, dx))], axis=1)
        jtr = np.stack([np.bincount(row_of, ww * a * r, nr) for a in (db, dx)], axis=1)
        return cost, jtj, jtr

    cost, jtj, jtr = evaluate(p)
    lam = np.full(rows.size, 1e-3)
    for _ in range(iterations):
        a11, a12, a22 = jtj[:, 0] * (1 + lam), jtj[:, 1], jtj[:, 2] * (1 + lam)
        det = a11 * a22 - a12 * a12
        with np.errstate(divide="ignore", invalid="ignore"):
            step = (
                -np.column_stack([a22 * jtr[:, 0] - a12 * jtr[:, 1], a11 * jtr[:, 1] - a12 * jtr[:, 0]]) / det[:, None]
            )
        step = np.nan_to_num(step)
        trial = np.clip(p + step, lo + 1e-6, hi - 1e-6)
        c_new, jtj_new, jtr_new = evaluate(trial)
        better = c_new < cost
        if not better.any() and np.all(lam > 1e6):
            break
        p[better], cost[better] = trial[better], c_new[better]
        jtj[better], jtr[better] = jtj_new[better], jtr_new[better]
        lam = np.where(better, lam / 3.0, lam * 4.0)
    best = np.argmin(cost.reshape(ns.size, n_start), axis=1) + np.arange(ns.size) * n_start
    out = []
    for g, r in enumerate(best):
        mean_w = float(np.mean(data[g][2]))
        sigma = float(np.sqrt(2 * cost[r] / max(ns[g] - 2, 1) / mean_w))
        mat = np.array([[jtj[r, 0], jtj[r, 1]], [jtj[r, 1], jtj[r, 2]]])
        sd = (np.inf, np.inf)
        if np.linalg.cond(mat) < 1e12:
            var = max(sigma, sd_floor_sigma) ** 2 * mean_w * np.diag(np.linalg.inv(mat))
            sd = tuple(float(v) for v in np.sqrt(np.abs(var)))
        out.append(LogisticFit(b=float(p[r, 0]), x0=float(p[r, 1]), sigma=sigma, cost=float(cost[r]), sd=sd))
    return out


#: Grid of the AR(1) correlation ρ over which the Space regression is
#: marginalised (the uniform prior of :data:`.likelihood.RHO_RANGE`).
_RHO_GRID = np.linspace(-0.5, 0.99, 60)


#: Largest (ρ values × samples) work array of :func:`_ar1_regression`,
#: elements (about 16 MB per float array, whatever the phrase's length).
_RHO_CHUNK_ELEMENTS = 1 << 21


def _seg_sum(key, u, v, k: int, n_seg: int) -> np.ndarray:
    """Σ of u·v over each (ρ, movement) pair: (k, N) inputs -> (k, n_seg)."""
    return np.bincount(key, (u * v).ravel(), k * n_seg).reshape(k, n_seg)


def _through_line(zz, det, p1, p2, q1, q2) -> np.ndarray:
    """Σ over movements of pᵀ (ZᵀZ)⁻¹ q with ZᵀZ = [[zz0, zz1], [zz1, zz2]] per (ρ, movement): (k,)."""
    s11, s12, s22 = zz
    return np.sum((p1 * (s22 * q1 - s12 * q2) + p2 * (s11 * q2 - s12 * q1)) / det, axis=1)


def _ar1_regression(tau, a, y, w, groups=None):
    """Posterior mean and sd of β in ``y = β·a + c_g + d_g·τ + ε`` with AR(1) residuals.

    ``√w_i ε_i`` is AR(1) along each run of increasing τ within a movement,
    with correlation ``ρ^(Δτ/δ)`` between neighbours (δ the median step),
    σ unknown (prior 1/σ) and β, c_g, d_g flat; ρ is marginalised over
    :data:`_RHO_GRID` (uniform prior): a mixture of the per-ρ Student
    posteriors, summarised by its mean and standard deviation.

    Each movement's straight line (c_g, d_g) touches only its own samples
    and the AR(1) chain restarts at each movement, so the normal equations
    are block-diagonal but for β: the lines are eliminated movement by
    movement (2×2 Schur complements), which keeps time and memory linear in
    the number of samples — a dense design with two columns per movement
    grew with the square of the phrase's length (3.7 GB for a 240-s phrase).

    Parameters
    ----------
    tau, a, y, w : (N,) ndarray
        Normalised time, the regressor of β, the response and the weights.
    groups : (N,) ndarray of int, optional
        Movement of each sample (default: one movement).

    Returns
    -------
    mean, sd : float
    """
    n = tau.size
    seg = np.zeros(n, dtype=int) if groups is None else np.unique(groups, return_inverse=True)[1].ravel()
    n_seg = int(seg.max()) + 1
    step = np.diff(tau, prepend=-np.inf)
    first = (step <= 0) | np.r_[True, seg[1:] != seg[:-1]]
    delta = np.median(step[~first]) if np.any(~first) else 1.0
    expo = np.where(first, 0.0, step / delta)
    odd = np.round(expo) % 2 == 1
    sw = np.sqrt(w)
    cols = np.stack([sw, sw * tau, sw * a, sw * y])  # (4, N): line's two, β's, response
    prev = np.roll(cols, 1, axis=1)
    dof = max(n - 1 - 2 * n_seg, 1)
    chunk = max(1, _RHO_CHUNK_ELEMENTS // max(n, 1))
    logp, mean_k, var_k = [], [], []
    for r0 in range(0, _RHO_GRID.size, chunk):
        rho = _RHO_GRID[r0 : r0 + chunk, None]
        k = rho.shape[0]
        with np.errstate(divide="ignore", invalid="ignore"):  # first frames are replaced below
            phi = np.exp(expo[None, :] * np.log(np.abs(rho)))
        phi = np.where(first[None, :], 0.0, np.where((rho < 0) & odd[None, :], -phi, phi))  # (k, N)
        one_m_phi2 = 1.0 - phi * phi
        c = 1.0 / np.sqrt(one_m_phi2)
        z = c[:, None] * (cols[None] - phi[:, None] * prev[None])  # (k, 4, N), whitened
        key = (np.arange(k)[:, None] * n_seg + seg[None, :]).ravel()
        z1, z2, za, zy = z[:, 0], z[:, 1], z[:, 2], z[:, 3]
        zz = [_seg_sum(key, u, v, k, n_seg) for u, v in ((z1, z1), (z1, z2), (z2, z2))]
        u_a, v_a = _seg_sum(key, z1, za, k, n_seg), _seg_sum(key, z2, za, k, n_seg)
        u_y, v_y = _seg_sum(key, z1, zy, k, n_seg), _seg_sum(key, z2, zy, k, n_seg)
        det = zz[0] * zz[2] - zz[1] * zz[1]
        aa = np.sum(za * za, axis=1) - _through_line(zz, det, u_a, v_a, u_a, v_a)
        ay = np.sum(za * zy, axis=1) - _through_line(zz, det, u_a, v_a, u_y, v_y)
        yy = np.sum(zy * zy, axis=1) - _through_line(zz, det, u_y, v_y, u_y, v_y)
        coef = ay / aa
        rss = np.maximum(yy - ay * coef, 1e-300)
        logdet = np.sum(np.log(det), axis=1) + np.log(aa)
        # log p(y | ρ) with the coefficients and ln σ integrated out, up to a constant
        logp.append(-0.5 * logdet - 0.5 * dof * np.log(rss) - 0.5 * np.sum(np.log(one_m_phi2), axis=1))
        mean_k.append(coef)
        # the Student posterior's variance (dof > 2), else the Gaussian's
        var_k.append(rss / dof / aa * (dof / (dof - 2.0) if dof > 2 else 1.0))
    lp, mk, vk = np.concatenate(logp), np.concatenate(mean_k), np.concatenate(var_k)
    post = np.exp(lp - lp.max())
    post /= post.sum()
    mean = float(post @ mk)
    return mean, float(np.sqrt(post @ (vk + (mk - mean) ** 2)))


def fit_space(tau, radial, weight=None, outward=None, groups=None) -> SpaceEstimate:
    """Space from the radial deviation: ``radial ≈ c0 + c1·τ + A·sin(πτ)``.

    Eq. 5.5 pulls the extremity inward by ``(1 − S)·0.1·r·sin(πτ)``, so a
    direct movement (S = 1) has A = 0 and the most indirect one A = −0.1:
    ``S = 1 + A / 0.1``.  A limb bent at both ends reaches outward instead
    (eq. 5.6, ``(1 − S)·(L − r)·sin(πτ)`` with L the full reach): when the
    bulge is clearly outward and `outward` gives the depth ``L / r − 1`` per
    sample, the deviation is regressed on ``outward·sin(πτ)``, whose
    coefficient is ``1 − S``.  Without `outward` an outward bulge is read by
    its size against 0.1, as indirect as an inward one of the same depth.
    The residuals are AR(1) along each run of increasing τ, as in the
    logistic's likelihood (:mod:`.likelihood`); their correlation ρ is
    marginalised on a grid (:func:`_ar1_regression`).
    The straight-line terms absorb errors of the direct path's end radii;
    pooled movements (`groups`) each get their own, since their end errors
    differ while the Space is shared.
    The uniform prior on S ∈ [0, 1] truncates the Gaussian posterior.

    Parameters
    ----------
    tau, radial : (N,) array_like
        Normalised time and radial deviation ``r / r_direct − 1``.
    weight : (N,) array_like, optional
        Per-sample confidence.
    outward : (N,) array_like, optional
        Outward depth ``L / r_direct − 1`` (≥ 0) per sample
        (:attr:`.curves.ProgressCurve.outward`).
    groups : (N,) array_like of int, optional
        Movement index of each sample when several are pooled.
    """
    tau, y, w = _check(tau, radial, weight)
    if tau.size < 4:
        raise EffortError(f"need at least 4 samples to fit Space, got {tau.size}")
    bump = np.sin(np.pi * tau)
    g = None
    if groups is not None:
        g = np.asarray(groups)
        if g.shape != tau.shape:
            raise EffortError(f"groups must be shaped like tau {tau.shape}, got {g.shape}")
    amp, se = _ar1_regression(tau, bump, y, w, g)
    # floor: the dancer's own modulation is resolved to ~1e-3 of the radius
    # (S to 0.01); a noise-free render would otherwise give a zero-width interval
    se = float(max(se, 1e-3))
    clear_out = amp > 3.0 * se
    depth = None
    if outward is not None:
        depth = np.asarray(outward, dtype=float)
        if depth.shape != tau.shape or not np.all(np.isfinite(depth)):
            raise EffortError(f"outward depth must be finite and shaped like tau {tau.shape}, got {depth.shape}")
    if clear_out and depth is not None and np.average(depth * bump, weights=w) > MIN_OUTWARD_DEPTH:
        k, k_se = _ar1_regression(tau, depth * bump, y, w, g)
        # same floor as below: S resolved to 0.01
        mu, sd = 1.0 - k, float(max(k_se, 1e-3 / INWARD_DEPTH))
    else:
        # inward (eq. 5.5) is the model; noise about zero stays signed so
        # that a direct movement is not pushed below S = 1
        mu = 1.0 - abs(amp) / INWARD_DEPTH if clear_out else 1.0 + amp / INWARD_DEPTH
        sd = se / INWARD_DEPTH
    lo, med, hi = _truncnorm_summary(mu, sd, 0.0, 1.0)
    return SpaceEstimate(median=med, ci90=(lo, hi), amplitude=amp, amplitude_se=se)
