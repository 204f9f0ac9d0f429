"""Fit the body model to measured 3D joint positions (BVH mocap, Kinect skeletons).

Data terms: joint positions ``‖p_i(θ_t) − X_i‖ / σ_3d`` and the directions of
the measured segments (so differences between the source's and our segment
lengths do not bend the fit), solved by :func:`~capture2notation.fitting.solver.solve`.
"""

from __future__ import annotations

import numpy as np

from ..body import JOINTS, Body
from ..errors import FittingError
from .ik import initial_angles
from .lengths import estimate_offsets
from .model import PoseModel
from .result import FitResult
from .solver import FOOT_POINTS, FitOptions, Terms, check_fps, fill2, floor_terms, rewarm, solve, to_result

__all__ = ["fit_points3d"]

_J = len(JOINTS)


def fit_points3d(
    points,
    confidence,
    fps: float,
    body: Body | None = None,
    times=None,
    virtual: dict[str, np.ndarray] | None = None,
    options: FitOptions | None = None,
    floor: bool = False,
) -> FitResult:
    """Fit joint angles to measured 3D joint positions (mocap, Kinect).

    Parameters
    ----------
    points : (T, J, 3) ndarray
        Positions of our joints in the world frame (z up, metres); NaN where
        the source has no such joint or did not track it.
    confidence : (T, J) ndarray
        In [0, 1].
    fps : float
    body : Body, optional
        Proportions for segments the source does not measure.
    times : (T,) ndarray, optional
    virtual : dict, optional
        Extra measured points by model virtual-point name (e.g.
        ``"head_centre"``) -> ``((T, 3) positions, (T,) confidence)``.
    options : FitOptions, optional
    floor : bool
        The floor is known to be z = 0 (calibrated cameras, the floor found
        from the feet): the fit's lowest foot point is held at its standing
        height with :attr:`FitOptions.sigma_floor` (Huber: jumps go), as the
        one-view fit's is through a known camera.  Triangulated feet scatter
        by centimetres; a support is judged against the floor by less.

    Returns
    -------
    FitResult
        Joints are the model's (per-clip segment lengths), consistent with
        the angles.
    """
    # Positions constrain every segment directly: fewer iterations converge,
    # and the trunk's tilt is measured, so it needs no pull to upright.
    opt = options or FitOptions(iterations=12, sigma_pelvis=4.0, sigma_trunk=4.0)
    check_fps(fps)
    body = body or Body()
    points = np.asarray(points, float)
    conf = np.asarray(confidence, float)
    if points.ndim != 3 or points.shape[1:] != (_J, 3) or conf.shape != points.shape[:2]:
        raise FittingError(
            f"fit_points3d needs points (T, {_J}, 3) and confidence (T, {_J}); got {points.shape}, {conf.shape}"
        )
    conf = np.where(np.all(np.isfinite(points), axis=-1), np.clip(np.nan_to_num(conf), 0, 1), 0.0)
    model = PoseModel(body, estimate_offsets(points, conf, body))
    idx = list(range(_J))
    obs = [points]
    w = [conf]
    for name, (pos, c) in (virtual or {}).items():
        pos = np.asarray(pos, float)
        c = np.where(np.all(np.isfinite(pos), axis=-1), np.asarray(c, float), 0.0)
        idx.append(model.index(name))
        obs.append(pos[:, None])
        w.append(c[:, None])
    terms = Terms(idx3=np.array(idx), obs3=np.concatenate(obs, 1), w3=np.concatenate(w, 1))
    # Directions make the solve insensitive to differences in segment lengths.
    pairs, dirs, wd = [], [], []
    for j in range(1, _J):
        p = body.parents[j]
        d = points[:, j] - points[:, p]
        ln = np.linalg.norm(d, axis=-1, keepdims=True)
        ok = np.isfinite(ln[:, 0]) & (ln[:, 0] > 1e-6)
        pairs.append((p, j))
        dirs.append(np.where(ok[:, None], d / np.where(ok[:, None], ln, 1.0), np.nan))
        wd.append(np.where(ok, np.minimum(conf[:, j], conf[:, p]), 0.0))
    terms.pairs, terms.dirs, terms.wd = np.array(pairs), np.stack(dirs, 1), np.stack(wd, 1)
    if floor and opt.sigma_floor > 0:
        feet = [JOINTS.index(n) for n in FOOT_POINTS if n in JOINTS]
        floor_terms(model, terms, conf[:, feet].max(axis=1))
    params0 = np.zeros((points.shape[0], model.n_params))
    pel = points[:, 0]
    params0[:, :3] = fill2(pel, fallback=body.rest[0])
    ang = initial_angles(np.where((conf > 0)[..., None], points, np.nan), model)
    ang[:, 0] = np.unwrap(ang[:, 0], axis=0)  # the pelvis turns freely: keep it continuous
    params0[:, 3:] = ang[:, model.dof_joint, model.dof_axis]
    params, cost = solve(model, params0, terms, fps, opt, opt.iterations)
    params, cost = rewarm(model, params, cost, terms, fps, opt)
    usable = np.sum(conf >= opt.min_confidence, axis=1) >= min(opt.min_targets, 4)
    err = np.linalg.norm(model.forward(params)[:, :_J] - points, axis=-1) / opt.sigma_3d
    quality = 1.0 / (1.0 + (np.nan_to_num(err, nan=np.inf) / 3.0) ** 2)
    jc = conf * quality
    # Joints the source never measures are only as good as their neighbours.
    missing = conf.max(axis=0) == 0
    for j in np.nonzero(missing)[0]:
        jc[:, j] = jc[:, body.parents[j]] * 0.5 if body.parents[j] >= 0 else 0.0
    return to_result(model, params, fps, times, jc, usable)
