"""Vectorised marginal likelihood of (b, x0[, ρ]) for a batch of independent posteriors.

The model of :mod:`.posterior`: ``s_i = c_g + k_g·progress(τ_i; b, x0) + ε_i``,
one (b, x0, σ) per *posterior* and one free offset ``c_g`` and end scale
``k_g`` per *movement* g of it (flat priors), or ``c = 0, k = 1`` when the
ends are pinned.

Residual model.  ``z_i = √w_i·ε_i`` (w_i the frame's confidence) is either
white, ``z_i ~ N(0, σ²)`` (``ar1=False``), or a stationary AR(1) process
along each movement (``ar1=True``, the default of :mod:`.posterior`):
``z_i = φ_i z_{i−1} + √(1 − φ_i²)·σ·η_i`` with ``φ_i = ρ^(Δτ_i/δ)``, δ the
movement's median sampling step, so ρ is the correlation of neighbouring
frames and a missing frame (Δτ = 2δ) correlates as ρ².  Why: progress curves
from fitted 3D joints (BlazePose + fitting) have residuals as small as
joint jitter but correlated from frame to frame (lag-1 autocorrelation
0.56–0.88 measured, ≈ 0 for jitter); treating them as independent made the
90 % intervals cover the truth ~22 % of the time.  AR(1) is the simplest
model with a testable correlation parameter and an exact, O(N) likelihood on
an irregular grid: the whitening ``u_i = (z_i − φ_i z_{i−1}) / √(1 − φ_i²)``
(``u_first = z_first``) turns it into the white model, with the Jacobian
``−½ Σ log(1 − φ_i²)``.  Being linear in the data and in the model, the
whitening keeps every nuisance integral below exact.  ρ, uniform on
:data:`RHO_RANGE`, is a third sampled parameter (marginalised, not
plugged in: its uncertainty from 25-frame movements is ±0.1, which matters
near ρ = 0.9 where the interval width scales as √((1 + ρ)/(1 − ρ))).
White residuals give ρ ≈ 0 and the white model's intervals.

Limits (measured, ``benchmarks/calibrate_effort.py --blazepose 30``): the
AR(1) model doubles the 90 % coverage of b through BlazePose (23 → 46 %;
x0 23 → 36 %), but not to 90 %: most of the capture path's error in the
progress curve is a smooth warp that another (b, x0, offset, scale) fits
to within the residual noise, so no residual model can see it (the
intervals would have to be ~3.7× wider for b, ~5.8× for x0).  That needs
a capture-path discrepancy prior of calibrated size, or less distortion
from the 3D fitting.

The nuisance parameters are integrated out analytically, so the sampler
moves in two (white) or three (AR(1)) dimensions only:

* (c_g, k_g): a Gaussian integral — χ² at their best values plus
  ½·log det of each movement's 2×2 normal equations;
* ln σ, uniform on :data:`LOG_SIGMA_RANGE`: with ``a = dof/2``,
  ``∫ σ^(−2a) exp(−χ²/2σ²) d ln σ ∝ χ²^(−a) [P(a, χ²/2σ_min²) − P(a, χ²/2σ_max²)]``
  (P the regularised lower incomplete gamma function), exact including the
  prior's truncation, which matters for noise-free renders.

:class:`Batch` holds the data of many posteriors ("groups") flattened once,
so one call evaluates every walker of every group in a few numpy passes:
the rows of θ are group-major with the same number of walkers per group.
"""

from __future__ import annotations

import numpy as np
from scipy import special

from ..errors import EffortError
from ..notation.effort import TIME_RANGE, WEIGHT_RANGE

__all__ = ["CAPTURE_RHO_RANGE", "LOG_SIGMA_RANGE", "RHO_RANGE", "Batch", "log_gammainc", "log_gammaincc"]

#: Uniform prior bounds of ln σ (σ from 1e-4 to 0.5 in units of progress).
LOG_SIGMA_RANGE = (np.log(1e-4), np.log(0.5))
#: Uniform prior bounds of the AR(1) correlation ρ of neighbouring frames.
#: Negative values are kept so that white residuals get a posterior centred
#: on ρ = 0 (a prior cut at 0 pushes it to ρ ≈ 0.15 and widens the intervals
#: of white noise by ~15 %: measured 96 % coverage instead of 90 %); 0.99
#: keeps the process stationary over a movement.
RHO_RANGE = (-0.5, 0.99)
#: Uniform prior bounds of ρ for a fitted capture, whose joint error is known
#: to be smooth: the residuals of progress curves from BlazePose fits have a
#: lag-1 autocorrelation of 0.56–0.88 (measured, module docstring).  Why a
#: prior and not the data: one movement of 12–48 samples hardly measures a
#: high ρ — its offset, end scale and (b, x0) absorb the slow part of the
#: error — so under :data:`RHO_RANGE` its ρ posterior leans low and the
#: intervals come out narrow (AR(1) noise of ρ 0.9 laid directly on the
#: model curve, 24 samples: 66 % of 90 % intervals cover; ρ 0.5: 90 %).
#: A hierarchical ρ shared by a capture's movements does not help, since
#: each movement's likelihood of ρ leans low alike (measured: coverage fell).
CAPTURE_RHO_RANGE = (0.5, 0.99)
#: Below this a regularised incomplete gamma value is taken from its series.
_TINY = 1e-280
#: 1 / (2 σ²) at the small-σ and large-σ ends of the prior.
_HALF_INV_VAR = 0.5 * np.exp(-2.0 * np.asarray(LOG_SIGMA_RANGE))


def _log_regularised(value, tail, a, x):
    """log of `value(a, x)` (scipy's P or Q), with ``tail(a, x)`` where the value is below :data:`_TINY`."""
    a, x = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(x, dtype=float))
    v = value(a, x)
    out = np.empty(a.shape)
    big = v > _TINY
    out[big] = np.log(v[big])
    if not big.all():
        out[~big] = tail(a[~big], x[~big])
    return out


def _log_lower_series(a, x):
    """log P(a, x) from its series, for x below a (where P underflows)."""
    with np.errstate(divide="ignore"):
        lead = a * np.log(x) - x - special.gammaln(a + 1.0)
    # underflow needs x < a, so the terms shrink at least geometrically
    term = np.ones_like(x)
    total = np.ones_like(x)
    for k in range(1, 80):
        term = term * x / (a + k)
        total += term
    return lead + np.log(total)


def log_gammainc(a, x):
    """log P(a, x), the regularised lower incomplete gamma function, without underflow.

    Parameters
    ----------
    a, x : array_like
        Shape (> 0) and argument (≥ 0), broadcast together.

    Returns
    -------
    ndarray
        ``log P(a, x)``; where P underflows (x far below a) the series
        ``P = x^a e^−x / Γ(a+1) · Σ_k x^k / ((a+1)…(a+k))`` is summed in logs.
    """
    return _log_regularised(special.gammainc, _log_lower_series, a, x)


def _log_sigma_integral(chi2: np.ndarray, a: np.ndarray) -> np.ndarray:
    """log ∫ σ^(−2a) exp(−χ²/2σ²) d ln σ over LOG_SIGMA_RANGE, up to a per-`a` constant."""
    u0 = chi2 * _HALF_INV_VAR[0]  # the small-σ end
    u1 = chi2 * _HALF_INV_VAR[1]
    p0, p1 = special.gammainc(a, u0), special.gammainc(a, u1)
    with np.errstate(divide="ignore"):
        out = -a * np.log(chi2)
    usual = (p0 > _TINY) & (p1 < 0.5)  # σ well inside the prior: the plain difference is accurate
    out[usual] += np.log(p0[usual] - p1[usual])
    if usual.all():
        return out
    rest = ~usual
    a, u0, u1 = a[rest], u0[rest], u1[rest]
    lp0 = log_gammainc(a, u0)
    # P(a, u1) / P(a, u0) <= 1; when both are near 1 use the upper tails instead
    near_one = special.gammaincc(a, u1) < 0.5
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = np.exp(log_gammainc(a, u1) - lp0)
        diff_log = lp0 + np.log1p(-np.minimum(ratio, 1.0))
        # a fit far worse than σ's upper end allows: Q(a, u1) − Q(a, u0) in
        # logs, where both may underflow (finite, so the sampler is led back)
        lq1, lq0 = log_gammaincc(a[near_one], u1[near_one]), log_gammaincc(a[near_one], u0[near_one])
        diff_log[near_one] = lq1 + np.log1p(-np.exp(np.minimum(lq0 - lq1, 0.0)))
    out[rest] += diff_log
    return out


#: Terms of the continued fraction of :func:`log_gammaincc` (it converges
#: within a few dozen where it is used, x > a + 1).
_CF_TERMS = 200


def _log_upper_fraction(a, x):
    """log Q(a, x) from its continued fraction by Lentz's method, for x > a + 1 (where Q underflows)."""
    tiny = 1e-300
    b = x + 1.0 - a
    c = np.full_like(x, 1.0 / tiny)
    d = 1.0 / b
    h = d.copy()
    for i in range(1, _CF_TERMS):
        an = -i * (i - a)
        b = b + 2.0
        d = an * d + b
        d = np.where(np.abs(d) < tiny, tiny, d)
        c = b + an / c
        c = np.where(np.abs(c) < tiny, tiny, c)
        d = 1.0 / d
        step = d * c
        h = h * step
        if np.all(np.abs(step - 1.0) < 1e-15):
            break
    return -x + a * np.log(x) - special.gammaln(a) + np.log(h)


def log_gammaincc(a, x):
    """log Q(a, x), the regularised upper incomplete gamma function, without underflow.

    Parameters
    ----------
    a, x : array_like
        Shape (> 0) and argument (≥ 0), broadcast together.

    Returns
    -------
    ndarray
        ``log Q(a, x)``; where Q underflows (x far above a) from the continued
        fraction ``Q = e^−x x^a / Γ(a) · 1/(x + 1 − a − 1·(1 − a)/(x + 3 − a − …))``
        evaluated by Lentz's method (Numerical Recipes, ``gcf``).
    """
    return _log_regularised(special.gammaincc, _log_upper_fraction, a, x)


def _run_sums(lay: dict, *terms):
    """Each (E,) term summed over the layout's (walker, movement) runs: one (combos,) array per term."""
    starts = lay["run_starts"]
    return tuple(np.add.reduceat(t, starts) for t in terms)


class Batch:
    """Data of G independent posteriors, flattened for vectorised evaluation.

    Parameters
    ----------
    datasets : sequence of (tau, s, weight, movement) tuples
        Per posterior: (N,) normalised time in (0, 1), progress, confidence
        (> 0) and the movement index of each sample (None: one movement).
        Each movement's samples are taken in the given order, which should
        be time order: the AR(1) chain links each sample to the previous
        one of its movement, and restarts wherever τ does not increase
        (several series given as one movement).
    free_ends : bool
        Marginalise a free offset and end scale per movement; False pins
        ``c = 0, k = 1``.
    ar1 : bool
        AR(1) residuals along each movement, with their correlation ρ a
        third column of θ; False: white residuals, θ is (b, x0).
    rho_range : (2,) tuple of float
        Uniform prior bounds of ρ (:data:`RHO_RANGE`; :data:`CAPTURE_RHO_RANGE`
        for a fitted capture's smooth error).

    Attributes
    ----------
    n_groups : int
    ndim : int
        Columns of θ: 2, or 3 with ρ.
    bounds : (ndim, 2) ndarray
        Uniform prior box of θ.
    dof : (G,) ndarray
        Residual degrees of freedom: samples minus 2 per movement when the
        ends are free.
    """

    def __init__(self, datasets, free_ends: bool = True, ar1: bool = False, rho_range=RHO_RANGE):
        taus, ss, ws, segs, grp, firsts, expos = [], [], [], [], [], [], []
        seg_group, n_seg = [], 0
        for g, (tau, s, w, mov) in enumerate(datasets):
            tau = np.asarray(tau, dtype=float)
            s = np.asarray(s, dtype=float)
            w = np.ones_like(tau) if w is None else np.asarray(w, dtype=float)
            mov = np.zeros(tau.size, dtype=int) if mov is None else np.asarray(mov)
            if not (tau.ndim == 1 and tau.shape == s.shape == w.shape == mov.shape):
                raise EffortError(
                    f"posterior {g}: tau, s, weight and movement labels must be equal 1-D arrays, got "
                    f"{tau.shape}, {s.shape}, {w.shape}, {mov.shape}"
                )
            if tau.size < 3 or np.any((tau <= 0) | (tau >= 1)) or not np.all(np.isfinite(s)) or np.any(w <= 0):
                raise EffortError(
                    f"posterior {g}: need >= 3 samples with tau in (0, 1), finite progress and weight > 0"
                )
            _, local = np.unique(mov, return_inverse=True)
            distinct = [np.unique(tau[local == j]).size for j in range(local.max() + 1)]
            if min(distinct) < 3:
                raise EffortError(f"posterior {g}: each movement needs samples at >= 3 distinct times, got {distinct}")
            # movement by movement, in the given order: the AR(1) chain runs
            # along each run of increasing τ (a pooled set concatenates series)
            order = np.argsort(local, kind="stable")
            tau, s, w, local = tau[order], s[order], w[order], local[order]
            step = np.diff(tau, prepend=0.0)
            first = np.r_[True, local[1:] != local[:-1]] | (step <= 0)
            delta = np.ones(local.max() + 1)
            for j in range(delta.size):
                inner = step[(local == j) & ~first]
                delta[j] = np.median(inner) if inner.size else 1.0
            firsts.append(first)
            expos.append(np.where(first, 0.0, step / delta[local]))
            taus.append(tau)
            ss.append(s)
            ws.append(w)
            segs.append(n_seg + local)
            grp.append(np.full(tau.size, g))
            seg_group += [g] * (local.max() + 1)
            n_seg += local.max() + 1
        if not taus:
            raise EffortError("a batch needs at least one posterior")
        self.n_groups = len(taus)
        self.free_ends = bool(free_ends)
        self.ar1 = bool(ar1)
        self.ndim = 3 if self.ar1 else 2
        lo, hi = (float(v) for v in rho_range)
        if not -1.0 < lo < hi < 1.0:
            raise EffortError(f"rho_range must satisfy -1 < lo < hi < 1, got {tuple(rho_range)}")
        self.rho_range = (lo, hi)
        box = [TIME_RANGE, WEIGHT_RANGE] + ([self.rho_range] if self.ar1 else [])
        self.bounds = np.array(box, dtype=float)
        self._first = np.concatenate(firsts)
        self._expo = np.concatenate(expos)
        self._logtau = np.log(np.concatenate(taus))
        self._s = np.concatenate(ss)
        self._w = np.concatenate(ws)
        self._seg = np.concatenate(segs)
        self._grp = np.concatenate(grp)
        self._seg_group = np.asarray(seg_group)
        self._samples_of = [np.flatnonzero(self._grp == g) for g in range(self.n_groups)]
        self._segs_of = [np.flatnonzero(self._seg_group == g) for g in range(self.n_groups)]
        ws_ = self._w * self._s
        self._s0 = np.bincount(self._seg, self._w, n_seg)
        self._ss = np.bincount(self._seg, ws_, n_seg)
        self._sss = np.bincount(self._seg, ws_ * self._s, n_seg)
        n = np.bincount(self._grp, minlength=self.n_groups).astype(float)
        nseg = np.bincount(self._seg_group, minlength=self.n_groups)
        self.dof = n - 2.0 * nseg if self.free_ends else n
        if np.any(self.dof < 1):
            raise EffortError(f"posteriors {np.flatnonzero(self.dof < 1).tolist()} have fewer samples than free ends")
        self._layouts: dict = {}

    def dataset(self, g: int):
        """(tau, s, weight) of posterior `g`, each (N_g,)."""
        i = self._samples_of[g]
        return np.exp(self._logtau[i]), self._s[i], self._w[i]

    def _layout(self, groups: tuple, k: int, cache: bool = True) -> dict:
        """Index arrays pairing each of the k walkers of `groups` with its group's samples."""
        key = (groups, k)
        if not cache or key not in self._layouts:
            rows, cols, combo_row, combo_seg, keys = [], [], [], [], []
            r0 = c0 = 0
            for g in groups:
                idx, sg = self._samples_of[g], self._segs_of[g]
                r = r0 + np.arange(k)
                rows.append(np.repeat(r, idx.size))
                cols.append(np.tile(idx, k))
                # one "combo" per (walker, movement): where the segment sums go
                local = np.searchsorted(sg, self._seg[idx])
                keys.append(c0 + (np.arange(k)[:, None] * sg.size + local[None, :]).ravel())
                combo_row.append(np.repeat(r, sg.size))
                combo_seg.append(np.tile(sg, k))
                r0 += k
                c0 += k * sg.size
            rows, cols = np.concatenate(rows), np.concatenate(cols)
            combo = np.concatenate(keys)
            lay = {
                "logtau": self._logtau[cols],
                "w": self._w[cols],
                "ws": self._w[cols] * self._s[cols],
                # each (walker, movement) combo is one run of consecutive
                # entries, in key order: sums over combos are np.add.reduceat
                "run_starts": np.flatnonzero(np.r_[True, combo[1:] != combo[:-1]]),
                "combo_row": np.concatenate(combo_row),
                "combo_seg": np.concatenate(combo_seg),
                "a": np.repeat(0.5 * self.dof[list(groups)], k),
                # entries per θ row: rows are runs, so np.repeat(v, counts) is v[rows]
                "counts": np.repeat([self._samples_of[g].size for g in groups], k),
            }
            if self.ar1:
                sw, prev = np.sqrt(self._w), np.maximum(cols - 1, 0)
                first = self._first[cols]
                expo = self._expo[cols]
                # φ = ρ one sampling step after the previous frame; after a
                # gap (expo ≠ 1) φ = ρ^expo, computed for those entries only
                irregular = np.flatnonzero(~first & (expo != 1.0))
                lay.update(
                    first=np.flatnonzero(first),
                    irregular=irregular,
                    irr_expo=expo[irregular],
                    irr_odd=np.round(expo[irregular]) % 2 == 1,
                    irr_rows=rows[irregular],
                    n_regular=np.bincount(rows, ~first & (expo == 1.0), r0),
                    sw=sw[cols],
                    sws=sw[cols] * self._s[cols],
                    sw_prev=np.where(first, 0.0, sw[prev]),
                    sws_prev=np.where(first, 0.0, sw[prev] * self._s[prev]),
                )
            if not cache:
                return lay
            self._layouts[key] = lay
            if len(self._layouts) > 64:  # active sets shrink as groups converge
                self._layouts.pop(next(iter(self._layouts)))
        return self._layouts[key]

    def _check_theta(self, theta, groups):
        groups = tuple(range(self.n_groups)) if groups is None else tuple(int(g) for g in groups)
        theta = np.asarray(theta, dtype=float)
        if theta.ndim != 2 or theta.shape[1] != self.ndim or theta.shape[0] % len(groups):
            raise EffortError(
                f"theta must be ({len(groups)}·k, {self.ndim}) for {len(groups)} groups, got {theta.shape}"
            )
        return theta, groups

    def chi2(self, theta, groups=None, cache: bool = True):
        """Minimum (whitened) χ² over the free ends, and the log-determinants.

        Parameters
        ----------
        theta : (len(groups)·k, ndim) ndarray
            (b, x0[, ρ]) rows, group-major, k rows per group, inside the prior box.
        groups : sequence of int, optional
            The groups the rows belong to (default: all, in order).
        cache : bool
            Keep the index arrays for further calls with the same layout
            (the sampler's case); False for one-off evaluations.

        Returns
        -------
        chi2, logdet : (rows,) ndarray
            ``logdet`` is Σ log det of the free ends' normal equations plus,
            with AR(1) residuals, ``Σ log(1 − φ_i²)`` (the log-determinant of
            the residuals' correlation matrix).
        """
        theta, groups = self._check_theta(theta, groups)
        return self._chi2(theta, groups, cache)

    def _chi2(self, theta, groups: tuple, cache: bool = True):
        """:meth:`chi2` of checked input (the sampler's hot path)."""
        k = theta.shape[0] // len(groups)
        lay = self._layout(groups, k, cache)
        b, lnx = theta[:, 0], np.log(theta[:, 1])
        # progress() without its checks: s = (1 + x0^−b) / (1 + τ^b · x0^−b),
        # per-row factors spread to the row's entries with np.repeat
        e = np.exp(-b * lnx)
        counts = lay["counts"]
        m = np.repeat(1.0 + e, counts) / (1.0 + np.exp(np.repeat(b, counts) * lay["logtau"]) * np.repeat(e, counts))
        if self.ar1:
            return self._chi2_ar1(theta, lay, m)
        wm = lay["w"] * m
        s_m, s_mm, s_sm = _run_sums(lay, wm, wm * m, lay["ws"] * m)
        seg = lay["combo_seg"]
        return self._fit_ends(theta.shape[0], lay, self._s0[seg], self._ss[seg], self._sss[seg], s_m, s_mm, s_sm)

    def _chi2_ar1(self, theta, lay, m):
        """:meth:`chi2` with AR(1) residuals: whiten data, offset basis and model, then as white.

        Each whitened entry is ``(x_i − φ_i x_{i−1}) / √(1 − φ_i²)``; the sums
        below carry the factor ``1 / (1 − φ_i²)`` once instead of scaling
        every whitened vector.
        """
        rows = theta.shape[0]
        rho = theta[:, 2]
        phi = np.repeat(rho, lay["counts"])
        irr = lay["irregular"]
        if irr.size:
            # ρ < 0: the sign alternates frame by frame, so a gap of n frames has ρ^n
            r = phi[irr]
            p = np.abs(r) ** lay["irr_expo"]
            phi[irr] = np.where((r < 0) & lay["irr_odd"], -p, p)
        phi[lay["first"]] = 0.0  # a movement's first frame: nothing before it
        inv = 1.0 / (1.0 - phi * phi)
        # log det of the correlation matrix: Σ log(1 − φ²), per row
        logdet_ar = lay["n_regular"] * np.log1p(-rho * rho)
        if irr.size:
            logdet_ar += np.bincount(lay["irr_rows"], np.log1p(-(phi[irr] ** 2)), rows)
        f = lay["sw"] * m
        # the entry before each one is the previous frame of the same movement
        # (entries are walker-major, movement by movement in time order); on a
        # movement's first frame φ = 0 and the wrapped value is not used
        df = f.copy()
        df[1:] -= phi[1:] * f[:-1]
        yd = lay["sws"] - phi * lay["sws_prev"]
        iy = inv * yd
        if self.free_ends:
            ad = lay["sw"] - phi * lay["sw_prev"]
            ia = inv * ad
            s_ss, s_sm, s_mm, s0, s_s, s_m = _run_sums(lay, iy * yd, iy * df, inv * df * df, ia * ad, ia * yd, ia * df)
        else:
            s_ss, s_sm, s_mm = _run_sums(lay, iy * yd, iy * df, inv * df * df)
            s0 = s_s = s_m = None
        chi2, logdet = self._fit_ends(rows, lay, s0, s_s, s_ss, s_m, s_mm, s_sm)
        return chi2, logdet + logdet_ar

    def _fit_ends(self, rows, lay, s0, s_s, s_ss, s_m, s_mm, s_sm):
        """χ² at the best free ends (or pinned ends) from the per-(walker, movement) sums."""
        if self.free_ends:
            det = s0 * s_mm - s_m * s_m
            # det <= 0 only by rounding on a flat model: NaN, rejected by log_marginal
            with np.errstate(invalid="ignore", divide="ignore"):
                fit = (s_mm * s_s * s_s - 2.0 * s_m * s_s * s_sm + s0 * s_sm * s_sm) / det
                logdet = np.bincount(lay["combo_row"], np.log(det), rows)
            chi2 = np.bincount(lay["combo_row"], s_ss - fit, rows)
        else:
            chi2 = np.bincount(lay["combo_row"], s_ss - 2.0 * s_sm + s_mm, rows)
            logdet = np.zeros(rows)
        # rounding can leave a perfect fit's χ² at or just below zero
        return np.maximum(chi2, 1e-300), logdet

    def log_marginal(self, theta, groups=None) -> np.ndarray:
        """log p(θ | data) up to a per-group constant, −inf outside the prior box.

        Parameters
        ----------
        theta : (len(groups)·k, ndim) ndarray
            Group-major (b, x0[, ρ]) rows, k per group.
        groups : sequence of int, optional
            Default: all groups, in order.

        Returns
        -------
        (rows,) ndarray
        """
        theta, groups = self._check_theta(theta, groups)
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        inside = np.all((theta > lo) & (theta < hi), axis=1)
        safe = theta
        if not inside.all():
            # evaluate every row (keeps the layout regular); outside rows are
            # moved into the box first and discarded after
            safe = np.clip(theta, lo + 1e-6, hi - 1e-6)
        chi2, logdet = self._chi2(safe, groups)
        a = self._layout(groups, theta.shape[0] // len(groups))["a"]
        with np.errstate(invalid="ignore"):
            out = _log_sigma_integral(chi2, a) - 0.5 * logdet
        # a degenerate model (det <= 0 by rounding) is rejected, never accepted
        out[~inside | np.isnan(out)] = -np.inf
        return out

    def draw_log_sigma(self, g: int, theta, rng: np.random.Generator) -> np.ndarray:
        """Exact draws of ln σ given each θ row of posterior `g`: (M,) from (M, ndim).

        Given θ, ``u = χ²/2σ²`` is Gamma(a, 1) truncated to the prior's
        range of σ; it is drawn by inverting the truncated CDF.
        """
        theta = np.asarray(theta, dtype=float)
        # in row chunks of about a million (walker, sample) pairs
        step = max(1, (1 << 20) // self._samples_of[g].size)
        chi2 = np.concatenate(
            [self.chi2(theta[i : i + step], (g,), cache=False)[0] for i in range(0, theta.shape[0], step)]
        )
        a = 0.5 * self.dof[g]
        lo, hi = np.exp(2.0 * np.asarray(LOG_SIGMA_RANGE))
        u0, u1 = chi2 / (2.0 * lo), chi2 / (2.0 * hi)
        p0, p1 = special.gammainc(a, u0), special.gammainc(a, u1)
        v = rng.uniform(size=chi2.size)
        u = special.gammaincinv(a, p1 + v * (p0 - p1))
        # where P(a, u0) underflows the density is ∝ u^(a−1) on (0, u0]
        tiny = p0 < _TINY
        u[tiny] = u0[tiny] * v[tiny] ** (1.0 / a)
        u = np.clip(u, u1, u0)
        return 0.5 * np.log(chi2 / (2.0 * u))
