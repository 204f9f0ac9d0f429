"""How well each frame determines each segment's direction (Laplace approximation).

At the solution, the inverse of a frame's Gauss–Newton Hessian (data terms
and the rest-pose prior; not the temporal term, so a frame is judged on its
own evidence) is the covariance ``Σ_t`` of its parameters.  The unit
direction ``u = d / |d|`` of the segment from joint ``p`` to joint ``j``
moves by ``∂u/∂θ = (I − u uᵀ)(J_j − J_p) / |d|``, so its angular spread is

    σ_t,j = sqrt(trace(∂u/∂θ Σ_t ∂u/∂θᵀ))   (radians).

Through one camera a segment lying across the image has its depth fixed
only to second order (its image length shrinks with the cosine of the tilt),
so without world landmarks its spread is large; a segment seen end-on is
fixed to first order, up to the in-front / behind ambiguity that a local
approximation cannot see.  With ``FitOptions.spread_deg > 0`` the fit turns
the spread into a factor of the output confidence.  It is off by default:
on BlazePose keypoints of the virtual dancer it did not separate right from
wrong labels better than the landmark confidences already do, because the
world landmarks' depth errors are biases rather than the noise the prior
assumes.
"""

from __future__ import annotations

import numpy as np

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

__all__ = ["direction_spread", "spread_factor"]

_J = len(JOINTS)


def direction_spread(model: PoseModel, params: np.ndarray, terms: Terms, fps: float, opt: FitOptions) -> np.ndarray:
    """Angular spread (degrees) of the segment ending at each joint, per frame.

    Parameters
    ----------
    model : PoseModel
    params : (T, 3 + D) ndarray
        The solution.
    terms : Terms
    fps : float
    opt : FitOptions

    Returns
    -------
    (T, J) ndarray
        Degrees; 0 for the root (no segment).
    """
    T = params.shape[0]
    _, rest = _prior_precision(model, fps, opt, T)
    parents = model.parents[:_J]
    child = np.arange(1, _J)
    out = np.zeros((T, _J))
    for a in range(0, T, CHUNK):  # bounded memory on long clips
        sl = slice(a, min(T, a + CHUNK))
        _, H, _ = _normal_equations(model, params[sl], _subset(terms, sl), opt, need_jac=True)
        H += np.diag(rest + 1e-6)
        cov = np.linalg.inv(H)  # (t, n, n)
        pts, jac = model.forward(params[sl], jacobian=True)
        d = pts[:, child] - pts[:, parents[child]]  # (t, J-1, 3)
        ln = np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-9)
        u = d / ln
        proj = (np.eye(3) - u[..., :, None] * u[..., None, :]) / ln[..., None]
        du = proj @ (jac[:, child] - jac[:, parents[child]])  # (t, J-1, 3, n)
        var = np.einsum("tkin,tnm,tkim->tk", du, cov, du)
        out[sl, 1:] = np.degrees(np.sqrt(np.maximum(var, 0.0)))
    return out


def spread_factor(spread_deg: np.ndarray, scale_deg: float) -> np.ndarray:
    """Confidence factor ``1 / (1 + (σ / scale)²)`` in (0, 1] of an angular spread."""
    return 1.0 / (1.0 + (np.asarray(spread_deg, float) / scale_deg) ** 2)
