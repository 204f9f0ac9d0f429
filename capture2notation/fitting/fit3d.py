"""Fit the body model to measured 3D joint positions (BVH mocap, Kinect skeletons, triangulated keypoints).

Data terms: joint positions ``‖p_i(θ_t) − X_i‖ / σ_3d`` and the directions of
the measured segments (so differences between the source's and our segment
lengths do not bend the fit), solved by :func:`~capture2notation.fitting.solver.solve`.

Points triangulated from calibrated cameras can be refined against the
cameras' own keypoints (``views``): the model's segment lengths and joint
limits then judge the views.  Two views of a hidden or mislabelled limb give
a point between the right ray and the wrong one, with no majority to vote
the wrong one out; fitted to the images, a limb of fixed length whose
projection one view measures well keeps to that view, and each keypoint's
weight falls with its distance from the fitted pose (Cauchy's noise model,
scale :data:`VIEW_SCALE_PX`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..body import JOINTS, Body
from ..errors import FittingError
from .ik import initial_angles
from .lengths import estimate_offsets
from .model import PoseModel
from .result import FitResult
from .solver import (
    FOOT_POINTS,
    FitOptions,
    Terms,
    ViewTerms,
    check_fps,
    fill2,
    floor_terms,
    rewarm,
    solve,
    to_result,
)

__all__ = ["VIEW_3D_WEIGHT", "VIEW_ROUNDS", "VIEW_SCALE_PX", "fit_points3d"]

_J = len(JOINTS)

#: Scale of the Cauchy weight ``1 / (1 + (e / VIEW_SCALE_PX)²)`` of a view's
#: keypoint at reprojection error ``e`` from the fitted pose, pixels:
#: BlazePose's keypoint noise on a 640×480 dancer is a few pixels, a hidden
#: limb's guess or a mirrored label tens.
VIEW_SCALE_PX = 15.0
#: Reweighting rounds of the fit to the views (iteratively reweighted least
#: squares: each round's weights come from the previous round's pose).
VIEW_ROUNDS = 3
#: Iterations of the solver per round.
VIEW_ITERATIONS = 6
#: Weight of the triangulated points and their directions while fitting to
#: the views, relative to before: they keep the pose where no view is
#: trusted, but carry the disagreement of the views they came from.
VIEW_3D_WEIGHT = 0.1


def _view_weights(model: PoseModel, params: np.ndarray, views) -> tuple[ViewTerms, ...]:
    """Each view's targets weighted by visibility × Cauchy weight of the current reprojection error."""
    pts = model.forward(params)
    out = []
    for cam, idx, uv, vis in views:
        e = np.linalg.norm(cam.project(pts[:, idx]) - uv, axis=-1)
        w = vis / (1.0 + (e / VIEW_SCALE_PX) ** 2)
        out.append(ViewTerms(cam, idx, uv, np.where(np.isfinite(w), w, 0.0)))
    return tuple(out)


def fit_points3d(
    points,
    confidence,
    fps: float,
    body: Body | None = None,
    times=None,
    virtual: dict[str, np.ndarray] | None = None,
    options: FitOptions | None = None,
    floor: bool = False,
    views=None,
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
    views : sequence of (Camera, (T, N, 2) ndarray, (T, N) ndarray, sequence of str), optional
        The cameras the points were triangulated from, with their keypoints
        (pixels, lens distortion removed; NaN where unseen), visibilities in
        [0, 1] and the model point each keypoint measures (a joint or a
        virtual point): the fit is refined against them (module docstring).

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
    if views:
        params = _fit_views(model, params, terms, views, fps, opt)
    usable = np.sum(conf >= opt.min_confidence, axis=1) >= min(opt.min_targets, 4)
    err = np.linalg.norm(model.forward(params)[:, :_J] - points, axis=-1) / opt.sigma_3d
    quality = 1.0 / (1.0 + (np.nan_to_num(err, nan=np.inf) / 3.0) ** 2)
    jc = conf * quality
    # Joints the source never measures are only as good as their neighbours.
    missing = conf.max(axis=0) == 0
    for j in np.nonzero(missing)[0]:
        jc[:, j] = jc[:, body.parents[j]] * 0.5 if body.parents[j] >= 0 else 0.0
    return to_result(model, params, fps, times, jc, usable)


def _fit_views(model: PoseModel, params, terms: Terms, views, fps: float, opt: FitOptions) -> np.ndarray:
    """`params` refined against the views' keypoints (module docstring)."""
    T = params.shape[0]
    prepared = []
    for v, (cam, uv, vis, names) in enumerate(views):
        uv = np.asarray(uv, float)
        vis = np.asarray(vis, float)
        if uv.shape != (T, len(names), 2) or vis.shape != uv.shape[:2]:
            raise FittingError(
                f"view {v}: keypoints must be (T={T}, {len(names)}, 2) with visibility (T, {len(names)}); "
                f"got {uv.shape}, {vis.shape}"
            )
        idx = np.array([model.index(n) for n in names])
        seen = np.all(np.isfinite(uv), axis=-1)
        prepared.append((cam, idx, np.where(seen[..., None], uv, np.nan), np.where(seen, np.clip(vis, 0, 1), 0.0)))
    wd = None if terms.wd is None else terms.wd * VIEW_3D_WEIGHT
    for _ in range(VIEW_ROUNDS):
        views = _view_weights(model, params, prepared)
        refit = replace(terms, w3=terms.w3 * VIEW_3D_WEIGHT, wd=wd, views=views)
        params, _ = solve(model, params, refit, fps, opt, VIEW_ITERATIONS, frozen=np.zeros(0, int))
    return params
