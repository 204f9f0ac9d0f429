"""Vectorised robust Levenberg–Marquardt shared by the 2D and 3D fits.

The problem, per frame ``t`` with parameters ``θ_t = [root, free angles]``
(:class:`~capture2notation.fitting.model.PoseModel`), is robust weighted least
squares over the data terms of :class:`Terms` (reprojection, segment
directions, 3D positions), a temporal smoothness term
``(θ_t − (θ_{t−1} + θ_{t+1}) / 2) / σ_t``, a weak pull to the rest pose
(twists a little firmer), and the joint limits as a box constraint
(projection after every step).  Huber's loss is applied by iteratively
reweighting.

All frames are solved together: one batched ``(T, n, n)`` solve per
iteration, each frame damping its own step and accepting it only when its
cost falls.  The temporal term is updated Jacobi-style from the neighbours'
current estimates, so each iteration is warm-started from the last and
information flows between frames; afterwards frames much worse than their
predecessor are solved again warm-started from the previous frame's pose.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..body import JOINTS
from ..errors import FittingError
from .camera import Camera
from .depth import DepthOptions
from .model import PoseModel
from .result import FitResult
from .spans import CONTEXT_S, SPAN_S

__all__ = ["FitOptions", "Terms", "ViewTerms", "rewarm", "solve", "to_result"]

_J = len(JOINTS)


@dataclass(frozen=True)
class FitOptions:
    """Weights and iteration counts of the fit.

    Attributes
    ----------
    sigma_2d : float
        Reprojection noise expressed at the performer's depth, metres.
    sigma_dir : float
        Noise of a world-landmark segment direction (unit-vector difference).
    sigma_3d : float
        Noise of a 3D joint position, metres.
    sigma_floor : float
        Spread of the lowest foot point's height about its standing height,
        metres, when the camera (hence the floor) is known; 0 switches the
        floor term off.  Through a known camera the floor ties a standing
        foot's depth to its image position, which the figure's image scale
        alone does poorly.  It assumes some foot is down (Huber's loss lets
        jumps go, at a cost): a figure floating above the floor is pulled
        down.
    sigma_smooth : float
        Second-difference noise of an angle at 25 fps, radians (scaled by
        ``25 / fps`` for other rates).
    sigma_root_smooth : float
        Second-difference noise of the root position at 25 fps, metres
        (a pelvis accelerating at 3 m/s² moves 5 mm per frame²; the default
        is looser, which kept more symbols on the whole path).  A single
        view measures the performer's depth only through the figure's
        image scale, so without this the depth wanders and standing feet
        slide.
    sigma_leg_smooth : float
        The same for the pelvis, hip, knee and ankle angles, radians, in the
        exact smoothing pass.  Firmer values (0.01–0.02) keep a standing
        foot under DESIGN.md's 0.2 m/s support speed at a pixel of keypoint
        noise, but smooth away the pauses that mark leg gestures: whole-path
        symbol agreement through BlazePose fell by 4–7 points.
    planted_speed : float
        Scale of the Cauchy prior on each foot point's speed in the exact
        smoothing pass, m/s (:func:`~capture2notation.fitting.temporal.
        _foot_speed_rows`); 0 switches it off.  Feet mostly stand still or
        move fast, so a heavy-tailed prior holds a planted foot where a
        single view's depth would let it slide, and lets a stepping or
        gesturing foot go.
    sigma_rest, sigma_twist : float
        Spread of the pull to the rest pose for swings and for twists, radians.
    sigma_spine_twist : float
        Spread of the pull of the waist's and chest's turns to zero, radians:
        the hips then face where the shoulders do unless the hips are seen
        to turn.  In a side view the hips are often hidden (a hanging arm
        covers the near one, the body the far one) and nothing else measures
        the pelvis's turn; it wandered 30–40° off, twisted against the
        shoulders, and took every leg direction (which is read in the hips'
        frame) with it.
    sigma_pelvis, sigma_trunk : float
        Spread of the pull of the pelvis, and of the waist and chest, to
        upright (their tilts, not the turns), radians.  A single view
        measures a trunk's tilt towards the camera poorly, and an unbounded
        pelvis pitch otherwise trades off against the hips: BlazePose's world
        landmarks lean the trunk 20–40° towards the camera in front views of
        the virtual dancer.
    huber : float
        Huber threshold in units of sigma.
    spread_deg : float
        Angular spread of a segment's direction (Laplace approximation,
        :mod:`~capture2notation.fitting.uncertainty`) that halves the
        confidence of the joint ending it; 0 leaves confidence to the
        landmarks and the reprojection error alone.
    iterations : int
        Levenberg–Marquardt iterations over all frames.
    root_passes, polish_iterations : int
        Passes of the exact smoothing of the root and legs
        (:func:`~capture2notation.fitting.temporal.smooth_root`), each
        followed by this many iterations of the other angles with those
        held.
    min_targets : int
        Frames with fewer usable targets are returned as NaN.
    min_confidence : float
        Landmarks below this confidence are ignored.
    span_s, context_s : float
        Seconds of a long clip fitted at once, and of context on each side
        (:mod:`~capture2notation.fitting.spans`: bounded memory).
    depth : DepthOptions or None
        Weights of the choice of each arm's side of the image plane
        (:mod:`~capture2notation.fitting.depth`) made before the solve when
        world landmarks are given; None leaves the side to the world
        landmarks and the starting pose.

    Notes
    -----
    Defaults were set on the built-in phrases and random scores rendered at
    640×480 (``benchmarks/bench_fitting.py --labels``): BlazePose's world
    landmarks give forearm and shin directions 15–20° off while its image
    landmarks are within 1–3°, so the world prior is kept loose
    (``sigma_dir``) and mostly decides in front / behind; a firm twist
    prior biased rounded arms by ~5°, so the rest-pose pull is only a
    tie-breaker.  The trunk priors cost ~3 mm MPJPE on clean keypoints
    of a figure that sways its waist by ±17°.  Per-frame label agreement
    through BlazePose is limited by its world landmarks, whose depth sign
    is right for only 60–90 % of even strongly foreshortened segments on
    these renders.
    """

    sigma_2d: float = 0.02
    sigma_dir: float = 0.18
    sigma_3d: float = 0.02
    sigma_floor: float = 0.02
    sigma_smooth: float = 0.08
    sigma_root_smooth: float = 0.02
    sigma_leg_smooth: float = 0.08
    planted_speed: float = 0.1
    sigma_rest: float = 4.0
    sigma_pelvis: float = 0.1
    sigma_trunk: float = 0.2
    sigma_twist: float = 2.0
    sigma_spine_twist: float = 0.3
    huber: float = 2.0
    spread_deg: float = 0.0
    iterations: int = 20
    root_passes: int = 1
    polish_iterations: int = 3
    min_targets: int = 6
    min_confidence: float = 0.1
    span_s: float = SPAN_S
    context_s: float = CONTEXT_S
    depth: DepthOptions | None = field(default_factory=DepthOptions)


@dataclass(frozen=True)
class ViewTerms:
    """Image targets in one more calibrated camera (multi-camera fits).

    Attributes
    ----------
    camera : Camera
    idx2 : (N,) ndarray of int
        Model point of each target.
    obs2 : (T, N, 2) ndarray
        Pixels (lens distortion removed); NaN where unseen.
    w2 : (T, N) ndarray
        Weights in [0, 1]; 0 where unseen.
    """

    camera: Camera
    idx2: np.ndarray
    obs2: np.ndarray
    w2: np.ndarray


@dataclass
class Terms:
    """Observations of one fit, already mapped to model points."""

    idx2: np.ndarray | None = None  # (N,) point index of image targets
    obs2: np.ndarray | None = None  # (T, N, 2) pixels
    w2: np.ndarray | None = None  # (T, N)
    camera: Camera | None = None
    pairs: np.ndarray | None = None  # (B, 2) point indices of measured directions
    dirs: np.ndarray | None = None  # (T, B, 3) unit directions (camera axes, or world for 3D)
    wd: np.ndarray | None = None  # (T, B)
    idx3: np.ndarray | None = None  # (N3,) point index of 3D targets
    obs3: np.ndarray | None = None  # (T, N3, 3)
    w3: np.ndarray | None = None  # (T, N3)
    floor_idx: np.ndarray | None = None  # (F,) point index of the feet's lowest points
    floor_z: np.ndarray | None = None  # (F,) their heights above the floor in a flat-footed stance, metres
    floor_w: np.ndarray | None = None  # (T,)
    views: tuple[ViewTerms, ...] = ()  # image targets in further cameras


#: Model points that can touch the floor.
FOOT_POINTS = ("right_toe", "left_toe", "right_heel", "left_heel", "right_ankle", "left_ankle")
#: Confidence of the best-seen foot point from which a frame gets the floor term.
FLOOR_SEEN = 0.5


def floor_terms(model: PoseModel, terms: Terms, seen: np.ndarray) -> None:
    """Set the floor-contact term of `terms`: some foot stands on the floor z = 0.

    A point's target is its height when standing flat on both feet, so flat
    feet, relevé (toes) and plié all satisfy it.

    Parameters
    ----------
    model : PoseModel
    terms : Terms
        Modified in place (``floor_idx``, ``floor_z``, ``floor_w``).
    seen : (T,) ndarray
        Confidence of the best-seen foot point per frame; frames under
        :data:`FLOOR_SEEN` get no floor term.
    """
    idx = np.array([model.index(n) for n in FOOT_POINTS])
    rest = model.forward(np.zeros((1, model.n_params)))[0]
    body = model.body
    lowest_rest = body.rest[[JOINTS.index("right_toe"), JOINTS.index("right_ankle")], 2].min()
    terms.floor_idx = idx
    terms.floor_z = rest[idx, 2] - rest[idx, 2].min() + lowest_rest
    terms.floor_w = np.where(np.asarray(seen) >= FLOOR_SEEN, 1.0, 0.0)


def _normal_equations(model: PoseModel, params, terms: Terms, opt: FitOptions, need_jac: bool):
    """Per-frame cost, and (if asked) Gauss-Newton ``H = JᵀWJ`` and ``g = JᵀWr``."""
    T, n = params.shape
    if need_jac:
        pts, jac = model.forward(params, jacobian=True)
    else:
        pts = model.forward(params)
    cost = np.zeros(T)
    k = opt.huber
    rows_J, rows_r = [], []

    def add(r, w, Jr):
        # r (T, N, d) in sigma units, w (T, N), Jr (T, N, d, n); Huber by IRLS.
        e = np.linalg.norm(r, axis=-1)
        cost[:] += np.sum(w * np.where(e <= k, 0.5 * e**2, k * e - 0.5 * k**2), axis=1)
        if need_jac:
            sw = np.sqrt(w * np.where(e <= k, 1.0, k / np.maximum(e, 1e-12)))[..., None]
            rows_r.append((sw * r).reshape(T, -1))
            rows_J.append((sw[..., None] * Jr).reshape(T, -1, n))

    def reprojection(cam: Camera, idx, obs2, w2):
        c = cam.to_camera(pts[:, idx])
        z = np.maximum(c[..., 2], 1e-3)
        f = np.array([cam.K[0, 0], cam.K[1, 1]])
        uv = c[..., :2] / z[..., None] * f + cam.K[:2, 2]
        depth = np.maximum(cam.to_camera(params[:, :3])[:, 2], 0.1)
        s = depth / (cam.focal * opt.sigma_2d)  # (T,) pixels -> sigma units
        r = (uv - np.nan_to_num(obs2)) * s[:, None, None]
        Jr = None
        if need_jac:
            # d(uv)/dp = f/z (R_row - c_row/z R_2), then chain with dp/dθ.
            dcam = cam.R @ jac[:, idx]  # (T, N, 3, n)
            duv = (dcam[:, :, :2] - (c[..., :2] / z[..., None])[..., None] * dcam[:, :, 2:3]) * (
                f[None, None, :, None] / z[..., None, None]
            )
            Jr = duv * s[:, None, None, None]
        add(r, w2, Jr)

    if terms.idx2 is not None:
        reprojection(terms.camera, terms.idx2, terms.obs2, terms.w2)
    for view in terms.views:
        reprojection(view.camera, view.idx2, view.obs2, view.w2)

    if terms.pairs is not None:
        a, b = terms.pairs[:, 0], terms.pairs[:, 1]
        Rc = terms.camera.R if terms.camera is not None else np.eye(3)
        d = (pts[:, b] - pts[:, a]) @ Rc.T
        ln = np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-9)
        m = d / ln
        r = (m - np.nan_to_num(terms.dirs)) / opt.sigma_dir
        Jr = None
        if need_jac:
            dd = Rc @ (jac[:, b] - jac[:, a])
            proj = (np.eye(3) - m[..., :, None] * m[..., None, :]) / (ln[..., None] * opt.sigma_dir)
            Jr = proj @ dd
        add(r, terms.wd, Jr)

    if terms.floor_idx is not None:
        # Some foot is on the floor: the lowest foot point (relative to its
        # height when standing flat) sits at its standing height.  Huber's
        # loss lets jumps go.
        z = pts[:, terms.floor_idx, 2] - terms.floor_z
        low = np.argmin(z, axis=1)
        r = np.take_along_axis(z, low[:, None], axis=1)[..., None] / opt.sigma_floor  # (T, 1, 1)
        Jr = None
        if need_jac:
            Jr = jac[np.arange(T), terms.floor_idx[low], 2][:, None, None, :] / opt.sigma_floor
        add(r, terms.floor_w[:, None], Jr)

    if terms.idx3 is not None:
        r = (pts[:, terms.idx3] - np.nan_to_num(terms.obs3)) / opt.sigma_3d
        Jr = jac[:, terms.idx3] / opt.sigma_3d if need_jac else None
        add(r, terms.w3, Jr)

    if need_jac:
        A = np.concatenate(rows_J, axis=1)  # (T, M, n) whitened Jacobian
        b = np.concatenate(rows_r, axis=1)
        At = A.transpose(0, 2, 1)
        return cost, At @ A, (At @ b[..., None])[..., 0]
    return cost


def _temporal_ref(params: np.ndarray) -> np.ndarray:
    """Mean of each frame's neighbours (a single neighbour at the ends)."""
    if params.shape[0] == 1:
        return params.copy()
    ref = np.empty_like(params)
    ref[1:-1] = 0.5 * (params[:-2] + params[2:])
    ref[0], ref[-1] = params[1], params[-2]
    return ref


def _prior_precision(model: PoseModel, fps: float, opt: FitOptions, T: int):
    """Diagonal precisions of the temporal and rest terms, ``(n,)`` each."""
    n = model.n_params
    # Per-frame changes shrink with the frame rate; linear (not quadratic)
    # scaling keeps high-rate mocap from being over-smoothed.
    scale = 25.0 / fps if fps > 0 else 1.0
    # The firm root and leg spreads act only in the exact pass
    # (:mod:`~capture2notation.fitting.temporal`): Jacobi coupling at that
    # weight would pin the trajectory to its start.
    smooth = np.full(n, 1.0 / (opt.sigma_smooth * scale) ** 2)
    if T == 1:
        smooth[:] = 0.0
    rest = np.full(n, 1.0 / opt.sigma_rest**2)
    rest[:3] = 0.0
    twist = (model.dof_axis == 2) & (model.dof_joint != 0)
    rest[3:][twist] = 1.0 / opt.sigma_twist**2
    # The pelvis may face any way, but it and the spine stay near upright.
    rest[3:][model.dof_joint == 0] = np.where(model.dof_axis[model.dof_joint == 0] == 2, 0.0, 1.0 / opt.sigma_pelvis**2)
    in_spine = np.isin(model.dof_joint, [JOINTS.index("waist"), JOINTS.index("chest")])
    rest[3:][in_spine & (model.dof_axis != 2)] = 1.0 / opt.sigma_trunk**2
    rest[3:][in_spine & (model.dof_axis == 2)] = 1.0 / opt.sigma_spine_twist**2
    return smooth, rest


#: Frames solved in one batch (memory ~ 0.1 MB per frame), and the overlap
#: between batches that keeps the temporal term continuous across them.
CHUNK, OVERLAP = 400, 16


def solve(
    model: PoseModel,
    params: np.ndarray,
    terms: Terms,
    fps: float,
    opt: FitOptions,
    iterations: int,
    frozen: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Solve long clips in overlapping chunks of :data:`CHUNK` frames; see :func:`solve_batch`."""
    T = params.shape[0]
    if T <= CHUNK:
        return solve_batch(model, params, terms, fps, opt, iterations, frozen)
    out = np.empty_like(params)
    cost = np.empty(T)
    start = 0
    while start < T:
        a = max(0, start - OVERLAP)
        b = min(T, start + CHUNK)
        init = params[a:b].copy()
        init[: start - a] = out[a:start]  # warm start from the previous chunk
        p, c = solve_batch(model, init, _subset(terms, slice(a, b)), fps, opt, iterations, frozen)
        # Keep the chunk's frames from `start` on; its first OVERLAP frames only
        # gave the temporal term context.
        out[start:b], cost[start:b] = p[start - a :], c[start - a :]
        start = b
    return out, cost


def solve_batch(
    model: PoseModel,
    params: np.ndarray,
    terms: Terms,
    fps: float,
    opt: FitOptions,
    iterations: int,
    frozen: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised Levenberg–Marquardt over all frames; returns (params, data cost per frame).

    The first two thirds of the iterations use a hundredth of the temporal
    weight, so frames converge on their own data first; Jacobi coupling with
    full weight would otherwise spread information one frame per iteration.
    Parameters listed in `frozen` (indices into the parameter vector) are
    held, and the temporal term has full weight from the start: the polish
    after :func:`~capture2notation.fitting.temporal.smooth_root`.
    """
    T, n = params.shape
    smooth_full, rest = _prior_precision(model, fps, opt, T)
    mu = np.full(T, 1e-2)
    lower, upper = model.lower, model.upper
    free = None if frozen is None else np.setdiff1d(np.arange(n), frozen)

    def total(p, ref, data):
        return data + 0.5 * np.sum(smooth * (p - ref) ** 2 + rest * p**2, axis=1)

    for it in range(iterations):
        smooth = smooth_full * (0.01 if it < (2 * iterations) // 3 and frozen is None else 1.0)
        ref = _temporal_ref(params)
        cost, H, g = _normal_equations(model, params, terms, opt, need_jac=True)
        H += np.diag(smooth + rest)
        g += smooth * (params - ref) + rest * params
        diag = np.einsum("tii->ti", H)
        A = H + (mu[:, None] * (diag + 1e-6))[:, :, None] * np.eye(n)
        if frozen is not None:
            step = np.zeros_like(params)
            step[:, free] = -np.linalg.solve(A[:, free][:, :, free], g[:, free, None])[..., 0]
        else:
            step = -np.linalg.solve(A, g[..., None])[..., 0]
        cand = np.clip(params + step, lower, upper)
        new = total(cand, ref, _normal_equations(model, cand, terms, opt, need_jac=False))
        better = new < total(params, ref, cost)
        params = np.where(better[:, None], cand, params)
        mu = np.where(better, mu / 3.0, np.minimum(mu * 4.0, 1e6))
    return params, _normal_equations(model, params, terms, opt, need_jac=False)


def rewarm(model, params, cost, terms, fps, opt, ratio=3.0, iterations=8):
    """Re-solve frames much worse than their predecessor, starting from its pose."""
    flagged = np.nonzero(cost[1:] > ratio * np.maximum(cost[:-1], 1.0))[0] + 1
    for t in flagged:  # only the few frames stuck in a poor local minimum
        if cost[t] <= ratio * max(cost[t - 1], 1.0):
            continue
        p1, c1 = solve_batch(model, params[t - 1 : t].copy(), _subset(terms, slice(t, t + 1)), fps, opt, iterations)
        if c1[0] < cost[t]:
            params[t], cost[t] = p1[0], c1[0]
    return params, cost


def _subset(terms: Terms, sl: slice) -> Terms:
    out = Terms(**terms.__dict__)
    for k in ("obs2", "w2", "dirs", "wd", "obs3", "w3", "floor_w"):
        v = getattr(terms, k)
        if v is not None:
            setattr(out, k, v[sl])
    out.views = tuple(ViewTerms(v.camera, v.idx2, v.obs2[sl], v.w2[sl]) for v in terms.views)
    return out


def pelvis_axis(model: PoseModel, axis: int) -> int:
    return int(np.nonzero((model.dof_joint == 0) & (model.dof_axis == axis))[0][0])


def fill(x: np.ndarray, fallback: float) -> np.ndarray:
    """Linear interpolation over NaN (constant at the ends)."""
    x = np.asarray(x, float)
    ok = np.isfinite(x)
    if not ok.any():
        return np.full_like(x, fallback)
    idx = np.arange(len(x))
    return np.interp(idx, idx[ok], x[ok])


def fill2(x: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    return np.stack([fill(x[:, k], fallback[k]) for k in range(x.shape[1])], axis=1)


def to_result(model, params, fps, times, conf, usable) -> FitResult:
    T = params.shape[0]
    angles = model.angles(params)
    # Pelvis turns are unbounded during the fit; report them in (-pi, pi].
    angles[:, 0] = np.angle(np.exp(1j * angles[:, 0]))
    joints = model.forward(params)[:, :_J]
    root = params[:, :3].copy()
    bad = ~usable
    joints[bad], angles[bad], root[bad] = np.nan, np.nan, np.nan
    conf = np.where(usable[:, None], np.clip(conf, 0.0, 1.0), 0.0)
    times = np.arange(T) / fps if times is None else np.asarray(times, float)
    if times.shape != (T,):
        raise FittingError(f"times must have shape ({T},), got {times.shape}")
    return FitResult(
        fps=float(fps),
        times=times,
        joints=joints,
        angles=angles,
        root=root,
        confidence=conf,
        offsets=model.offsets[:_J].copy(),
    )


def check_fps(fps):
    if not (np.isfinite(fps) and fps > 0):
        raise FittingError(f"fps must be a positive number, got {fps!r}")
