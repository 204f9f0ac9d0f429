"""Exact temporal smoothing of the root and the legs (a sparse banded solve).

The per-frame solver (:mod:`capture2notation.fitting.solver`) couples
neighbouring frames Jacobi-style, which lets strong temporal priors act only
slowly.  For the root and the legs that is not enough: a single view
measures the performer's depth only through the figure's image scale, so the
fitted depth wanders by centimetres from frame to frame and standing feet
appear to slide (a foot must be slower than 0.2 m/s to support, DESIGN.md).

This pass couples the *coupled* parameters ``x`` (root and the angles of
:data:`COUPLED`) over time exactly.  At the current solution each frame's
normal equations ``H_t, g_t`` (data + rest terms) are reduced to them by the
Schur complement over the other angles ``a``,

    S_t = H_xx − H_xa H_aa⁻¹ H_ax,   s_t = g_x − H_xa H_aa⁻¹ g_a,

so ``S_t`` is the precision with which frame ``t`` alone measures them
(high across the image, low in depth).  The correction ``δ`` minimises

    Σ_t ½ δ_tᵀ S_t δ_t + s_tᵀ δ_t + ½ Σ_t ‖Λ^½ Δ²(x + δ)_t‖²,

a sparse banded system of ``kT`` unknowns (with ``FitOptions.planted_speed``
also a heavy-tailed prior on the feet's speed, which the coupled parameters
alone move; :func:`_foot_speed_rows`), and the other angles follow by
the conditional Gauss–Newton step ``δa_t = −H_aa⁻¹ (g_a + H_ax δ_t)``.  The
root and legs therefore move only as much as each frame's evidence supports.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csc_matrix, diags, identity, kron
from scipy.sparse.linalg import spsolve

from ..body import JOINTS
from .model import PoseModel
from .solver import (
    CHUNK,
    FOOT_POINTS,
    FitOptions,
    Terms,
    _normal_equations,
    _prior_precision,
    _subset,
)

__all__ = ["COUPLED", "coupled_params", "smooth_root"]

#: Frame rate at which the priors' strengths are stated; a term per frame
#: pair is weighted by ``REFERENCE_FPS / fps`` so a prior means as much per
#: second at any rate.
REFERENCE_FPS = 25.0

#: Joints whose angles are smoothed together with the root: they carry the feet.
COUPLED = ("pelvis", "right_hip", "left_hip", "right_knee", "left_knee", "right_ankle", "left_ankle")


def coupled_params(model: PoseModel, joints: tuple[str, ...] = COUPLED) -> np.ndarray:
    """Indices of the root and of the angles of `joints` in the parameter vector."""
    ang = np.nonzero(np.isin(model.dof_joint, [JOINTS.index(j) for j in joints]))[0] + 3
    return np.concatenate([np.arange(3), ang])


def _second_difference(T: int):
    """(T−2, T) sparse second-difference operator."""
    return diags([np.ones(T - 2), -2.0 * np.ones(T - 2), np.ones(T - 2)], [0, 1, 2], shape=(T - 2, T))


def _foot_speed_rows(model: PoseModel, params: np.ndarray, cp: np.ndarray, fps: float, scale: float):
    """Whitened rows of the feet's speed prior, linearised at `params`.

    Each foot point's velocity between neighbouring frames has a Cauchy
    (Student-t, one degree of freedom) prior of scale `scale` m/s: mostly
    still, now and then moving at any speed.  Its negative log density
    ``log(1 + v²/c²)`` is applied by iteratively reweighted least squares,
    the quadratic ``½ w ‖v‖²`` with ``w = 2 / (c² + ‖v‖²)`` at the current
    velocity.  A foot that the views see still is held still in depth, which
    a single view measures only through the figure's image scale (a fit
    otherwise slides or lifts a standing foot along its line of sight); a
    foot the views see moving fast costs the fit almost nothing.  A foot
    moving slowly and mostly along the line of sight is held back too.

    Parameters
    ----------
    model : PoseModel
    params : (T, 3 + D) ndarray
    cp : (k,) ndarray
        Indices of the coupled parameters (the unknowns of the smoothing).
    fps : float
    scale : float
        The prior's scale, m/s.

    Returns
    -------
    B : (3 F (T − 1), k T) sparse matrix
        d(whitened velocity)/d(coupled parameters), ``F`` foot points.
    r0 : (3 F (T − 1),) ndarray
        Whitened velocities at `params`.
    """
    T = params.shape[0]
    k = len(cp)
    idx = np.array([model.index(n) for n in FOOT_POINTS])
    F = len(idx)
    pts = np.empty((T, F, 3))
    jac = np.empty((T, F, 3, k))
    for a in range(0, T, CHUNK):
        sl = slice(a, min(T, a + CHUNK))
        p, j = model.forward(params[sl], jacobian=True)
        pts[sl] = p[:, idx]
        jac[sl] = j[:, idx][..., cp]
    vel = (pts[1:] - pts[:-1]) * fps  # (T − 1, F, 3) m/s
    speed2 = np.nan_to_num(np.sum(vel**2, axis=-1), nan=np.inf)
    per_s = REFERENCE_FPS / fps if fps > 0 else 1.0
    sw = np.sqrt(2.0 * per_s / (scale**2 + speed2))[..., None]  # (T − 1, F, 1)
    r0 = np.nan_to_num(sw * vel).reshape(-1)
    after = np.nan_to_num(sw[..., None] * fps * jac[1:])  # (T − 1, F, 3, k)
    before = -np.nan_to_num(sw[..., None] * fps * jac[:-1])
    n_rows = 3 * F * (T - 1)
    rows = np.repeat(np.arange(n_rows), k)
    t = np.repeat(np.arange(T - 1), 3 * F * k)
    col = np.tile(np.arange(k), n_rows)
    B = csc_matrix(
        (
            np.concatenate([before.reshape(-1), after.reshape(-1)]),
            (np.concatenate([rows, rows]), np.concatenate([t * k + col, (t + 1) * k + col])),
        ),
        shape=(n_rows, k * T),
    )
    return B, r0


def smooth_root(
    model: PoseModel, params: np.ndarray, terms: Terms, fps: float, opt: FitOptions, joints: tuple[str, ...] = COUPLED
) -> np.ndarray:
    """One Gauss–Newton step of the root and leg trajectories under their smoothness prior.

    Parameters
    ----------
    model : PoseModel
    params : (T, 3 + D) ndarray
        Current solution; root in the first three columns, metres.
    terms : Terms
        Data terms of the fit.
    fps : float
        Frame rate; the prior's spreads (``opt.sigma_root_smooth`` metres,
        ``opt.sigma_leg_smooth`` radians, or the looser ``opt.sigma_smooth``,
        as half second differences at 25 fps) scale by ``25 / fps``.
    opt : FitOptions
    joints : tuple of str
        Joints whose angles are coupled with the root.

    Returns
    -------
    (T, 3 + D) ndarray
        New parameters (angles within the limits).  Unchanged when ``T < 3``.
    """
    T, n = params.shape
    if T < 3:
        return params
    smooth, rest = _prior_precision(model, fps, opt, T)
    # Coupled parameters: the root and the angles of `joints`, moved to the front.
    cp = coupled_params(model, joints)
    order = np.concatenate([cp, np.setdiff1d(np.arange(n), cp)])
    k = len(cp)
    S = np.empty((T, k, k))
    s = np.empty((T, k))
    X = np.empty((T, n - k, k + 1))
    for a in range(0, T, CHUNK):  # bounded memory on long clips
        sl = slice(a, min(T, a + CHUNK))
        _, H, g = _normal_equations(model, params[sl], _subset(terms, sl), opt, need_jac=True)
        H += np.diag(rest)
        g += rest * params[sl]
        H = H[:, order][:, :, order]
        g = g[:, order]
        Hra = H[:, :k, k:]
        # Haa⁻¹ [H_ar | g_a] in one batched solve.
        X[sl] = np.linalg.solve(
            H[:, k:, k:] + 1e-6 * np.eye(n - k), np.concatenate([Hra.transpose(0, 2, 1), g[:, k:, None]], axis=2)
        )
        S[sl] = H[:, :k, :k] - Hra @ X[sl][..., :k]
        s[sl] = g[:, :k] - (Hra @ X[sl][..., k:])[..., 0]
    # The temporal term (θ_t − (θ_{t−1} + θ_{t+1}) / 2) is half a second difference.
    prec = smooth[cp].copy()
    scale = REFERENCE_FPS / fps if fps > 0 else 1.0
    prec[:3] = np.maximum(prec[:3], 1.0 / (opt.sigma_root_smooth * scale) ** 2)
    prec[3:] = np.maximum(prec[3:], 1.0 / (opt.sigma_leg_smooth * scale) ** 2)
    lam = np.tile(0.25 * prec, T)
    D = _second_difference(T)
    DtD = kron((D.T @ D), identity(k)).tocsc().multiply(np.sqrt(lam)[:, None]).multiply(np.sqrt(lam)[None, :])
    idx = np.arange(k * T).reshape(T, k)
    rows = np.repeat(idx, k, axis=1).ravel()
    cols = np.tile(idx, (1, k)).ravel()
    blocks = csc_matrix((S.reshape(-1), (rows, cols)), shape=(k * T, k * T))
    x = params[:, cp].reshape(-1)
    # A tiny ridge keeps clips with unseen stretches (zero S_t, no trend) solvable.
    A = (blocks + DtD + 1e-9 * identity(k * T)).tocsc()
    rhs = -s.reshape(-1) - DtD @ x
    if opt.planted_speed > 0:
        B, r0 = _foot_speed_rows(model, params, cp, fps, opt.planted_speed)
        A = (A + B.T @ B).tocsc()
        rhs -= B.T @ r0
    delta = spsolve(A, rhs).reshape(T, k)
    out = params.copy()
    out[:, cp] += delta
    # The other angles' conditional step given the coupled ones (X[..., :k] = Haa⁻¹ H_ar).
    rest_idx = order[k:]
    out[:, rest_idx] -= X[..., k] + (X[..., :k] @ delta[..., None])[..., 0]
    out[:, 3:] = np.clip(out[:, 3:], model.lower[3:], model.upper[3:])
    return out
