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

a sparse banded system of ``kT`` unknowns, and the other angles follow by
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
    FitOptions,
    Terms,
    _normal_equations,
    _prior_precision,
    _subset,
)

__all__ = ["COUPLED", "coupled_params", "smooth_root"]

#: Joints whose angles are smoothed together with the root: they carry the feet.
COUPLED = ("pelvis", "right_hip", "left_hip", "right_knee", "left_knee", "right_ankle", "left_ankle")


def coupled_params(model: PoseModel, joints: tuple[str, ...] = COUPLED) -> np.ndarray:
    """Indices of the root and of the angles of `joints` in the parameter vector."""
    ang = np.nonzero(np.isin(model.dof_joint, [JOINTS.index(j) for j in joints]))[0] + 3
    return np.concatenate([np.arange(3), ang])


def _second_difference(T: int):
    """(T−2, T) sparse second-difference operator."""
    return diags([np.ones(T - 2), -2.0 * np.ones(T - 2), np.ones(T - 2)], [0, 1, 2], shape=(T - 2, T))


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
    scale = 25.0 / fps if fps > 0 else 1.0
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
    delta = spsolve(A, -s.reshape(-1) - DtD @ x).reshape(T, k)
    out = params.copy()
    out[:, cp] += delta
    # The other angles' conditional step given the coupled ones (X[..., :k] = Haa⁻¹ H_ar).
    rest_idx = order[k:]
    out[:, rest_idx] -= X[..., k] + (X[..., :k] @ delta[..., None])[..., 0]
    out[:, 3:] = np.clip(out[:, 3:], model.lower[3:], model.upper[3:])
    return out
