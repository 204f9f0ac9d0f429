"""Fit the body model to 2D keypoints (BlazePose landmarks, plus world landmarks).

Data terms (see :mod:`capture2notation.fitting.solver` for the solver):

* reprojection: ``c_i · ρ(‖π(p_i(θ_t)) − x_i‖ · Z_t / (f σ_2d))`` for each
  image landmark with confidence ``c_i`` (pixels turned into metres at the
  performer's depth ``Z_t``, so the weights do not depend on image size);
* world prior: the directions of segments measured by the keypoint model's
  world landmarks (camera-aligned axes), ``‖R d/|d| − u‖ / σ_dir`` — this is
  what resolves the depth ambiguity of a single view; the same landmarks give
  the per-clip segment lengths (the pelvis → neck direction pulls little:
  BlazePose leans the trunk 20–40° towards the camera);
* floor (known camera only): the lowest foot point stands at its standing
  height, z = 0 being the floor, which ties the figure's depth to where its
  feet meet the floor in the image; the starting depth comes from there too
  (:mod:`~capture2notation.fitting.floor`), since the figure's image size
  misjudges it by 0.2–0.4 m through BlazePose and the arms' foreshortening
  is judged at that depth.

Priors: joint limits, a pull of the trunk to upright, and temporal
smoothness — loose and Jacobi-coupled in the main solve, then firm and exact
for the root and legs (:mod:`~capture2notation.fitting.temporal`).

Missing or low-confidence landmarks carry zero or small weight and lower the
output confidence of the joints they measure; frames with too few landmarks
are returned as NaN with zero confidence rather than invented.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..body import JOINTS, Body
from ..errors import FittingError, MotionFileError
from .camera import DEFAULT_HFOV_DEG, Camera
from .depth import DepthOptions, choose_arm_depths, remove_leg_rest_offsets
from .ground import fit_floor, level_points
from .model import PoseModel
from .result import FitResult
from .solver import (
    FOOT_POINTS,
    FitOptions,
    Terms,
    check_fps,
    floor_terms,
    rewarm,
    solve,
    to_result,
)
from .spans import PROPORTION_FRAMES, spread_frames, stitch, track_spans
from .start import SKIP_DIRECTIONS, image_offsets, initial_params, world_weights
from .temporal import coupled_params, smooth_root
from .uncertainty import direction_spread, spread_factor

__all__ = ["TARGETS_2D", "fit_keypoints", "fit_track", "refine_focal"]

_J = len(JOINTS)

#: Image targets: model point -> BlazePose landmarks averaged to measure it,
#: and the relative weight of its reprojection term (head and heel points of
#: the model are approximate, so they pull less).
TARGETS_2D: tuple[tuple[str, tuple[int, ...], float], ...] = (
    ("pelvis", (23, 24), 0.0),  # duplicate of the hips in 2D; used for directions
    ("neck", (11, 12), 0.0),  # likewise of the shoulders
    ("right_shoulder", (12,), 1.0),
    ("right_elbow", (14,), 1.0),
    ("right_wrist", (16,), 1.0),
    ("right_hand_tip", (20,), 0.5),
    ("left_shoulder", (11,), 1.0),
    ("left_elbow", (13,), 1.0),
    ("left_wrist", (15,), 1.0),
    ("left_hand_tip", (19,), 0.5),
    ("right_hip", (24,), 1.0),
    ("right_knee", (26,), 1.0),
    ("right_ankle", (28,), 1.0),
    ("right_toe", (32,), 0.7),
    ("left_hip", (23,), 1.0),
    ("left_knee", (25,), 1.0),
    ("left_ankle", (27,), 1.0),
    ("left_toe", (31,), 0.7),
    ("nose", (0,), 0.3),
    ("left_ear", (7,), 0.3),
    ("right_ear", (8,), 0.3),
    ("right_heel", (30,), 0.5),
    ("left_heel", (29,), 0.5),
)

#: Segments whose measured direction constrains depth (pairs of target names, weight).
_DIRECTIONS: tuple[tuple[str, str, float], ...] = (
    ("pelvis", "neck", 0.2),  # BlazePose leans the trunk towards the camera: a hint only
    ("left_hip", "right_hip", 1.0),
    ("left_shoulder", "right_shoulder", 1.0),
    ("right_shoulder", "right_elbow", 1.0),
    ("right_elbow", "right_wrist", 1.0),
    ("right_wrist", "right_hand_tip", 0.3),
    ("left_shoulder", "left_elbow", 1.0),
    ("left_elbow", "left_wrist", 1.0),
    ("left_wrist", "left_hand_tip", 0.3),
    ("right_hip", "right_knee", 1.0),
    ("right_knee", "right_ankle", 1.0),
    ("right_ankle", "right_toe", 0.5),
    ("left_hip", "left_knee", 1.0),
    ("left_knee", "left_ankle", 1.0),
    ("left_ankle", "left_toe", 0.5),
    ("neck", "nose", 0.3),
    ("left_ear", "right_ear", 0.3),
)

#: Trunk directions used where the other shoulder is hidden: (from, to, the
#: other shoulder, weight) — see :func:`_direction_terms`.
_HALF_TRUNK: tuple[tuple[str, str, str, float], ...] = (
    ("pelvis", "right_shoulder", "left_shoulder", 0.3),
    ("pelvis", "left_shoulder", "right_shoulder", 0.3),
)

#: Joints measured by other joints' targets (for the output confidence).
_DERIVED_CONF = {
    "waist": ("pelvis", "neck"),
    "chest": ("pelvis", "neck"),
    "head": ("nose", "left_ear", "right_ear"),
}


# --------------------------------------------------------------------------- 2D fitting


def _targets_from_landmarks(xy, conf, world, opt):
    """Average landmarks into model targets.

    Returns names (N,), xy (T,N,2), conf (T,N), world (T,N,3) or None.
    """
    names = [t[0] for t in TARGETS_2D]
    T = xy.shape[0]
    N = len(names)
    tx = np.full((T, N, 2), np.nan)
    tc = np.zeros((T, N))
    tw = None if world is None else np.full((T, N, 3), np.nan)
    for i, (_, lms, _) in enumerate(TARGETS_2D):
        lms = list(lms)
        c = np.min(conf[:, lms], axis=1)
        ok = (c >= opt.min_confidence) & np.all(np.isfinite(xy[:, lms]), axis=(1, 2))
        tx[ok, i] = xy[ok][:, lms].mean(axis=1)
        tc[:, i] = np.where(ok, c, 0.0)
        if world is not None:
            okw = ok & np.all(np.isfinite(world[:, lms]), axis=(1, 2))
            tw[okw, i] = world[okw][:, lms].mean(axis=1)
    if tw is not None:
        _impute_hips(names, tw)
    return names, tx, tc, tw


def _impute_hips(names, tw) -> None:
    """Place unseen pelvis and hip world targets from the hip-centred origin, in place.

    World landmarks are hip-centred: the midpoint of the hips is the origin
    in every frame whether or not the hips are seen.  So the pelvis target is
    the origin, and a hip the image does not show (a thigh raised towards the
    camera hides it) is the mirror of the other.  Without them the thigh,
    whose knee alone is seen, would lose its world direction, the only
    evidence of which side of the image plane it points to.
    """
    framed = np.any(np.isfinite(tw), axis=(1, 2))
    ip, il, ir = names.index("pelvis"), names.index("left_hip"), names.index("right_hip")
    have = np.all(np.isfinite(tw), axis=2)
    for a, b in ((il, ir), (ir, il)):
        miss = ~have[:, a] & have[:, b]
        tw[miss, a] = -tw[miss, b]
    miss = ~have[:, ip] & framed
    tw[miss, ip] = 0.0


def _impute_shoulders(model: PoseModel, cam: Camera, params: np.ndarray, names, tc, tw) -> np.ndarray:
    """World targets for hidden shoulders whose arm is seen, from the starting pose.

    An arm raised straight at the camera hides its shoulder behind the elbow
    and hand; without a shoulder the upper arm has no world direction and the
    depth choice of :mod:`~capture2notation.fitting.depth` skips the arm, so
    the fit settles on whichever side of the image plane the solver reaches
    first (the mirror image half the time).  The trunk of the starting pose
    (hips, upright prior) places the shoulder to within a few centimetres,
    far less than an upper arm, so it stands in: hip-centred, camera-aligned
    like the world landmarks.

    Returns
    -------
    (T, N, 3) ndarray
        A copy of `tw` with the imputed shoulders.
    """
    tw = tw.copy()
    pts = model.forward(params)
    pelvis = pts[:, model.index("pelvis")]
    have = np.all(np.isfinite(tw), axis=2)
    framed = np.any(have, axis=1)
    for side in ("right", "left"):
        i_s, i_e = names.index(f"{side}_shoulder"), names.index(f"{side}_elbow")
        miss = framed & ~have[:, i_s] & (tc[:, i_e] > 0) & have[:, i_e]
        tw[miss, i_s] = (pts[miss, model.index(f"{side}_shoulder")] - pelvis[miss]) @ cam.R.T
    return tw


def _direction_terms(names, tc, tw):
    """Unit directions of segments from target world positions; (B,2) name pairs, (T,B,3), (T,B)."""
    pairs, dirs, w = [], [], []
    cw = world_weights(tc, tw)
    for a, b, wt in _DIRECTIONS:
        ia, ib = names.index(a), names.index(b)
        d = tw[:, ib] - tw[:, ia]
        ln = np.linalg.norm(d, axis=-1, keepdims=True)
        ok = np.isfinite(ln[:, 0]) & (ln[:, 0] > 1e-6)
        u = np.where(ok[:, None], d / np.where(ok[:, None], ln, 1.0), np.nan)
        pairs.append((a, b))
        dirs.append(u)
        w.append(np.where(ok, wt * np.minimum(cw[:, ia], cw[:, ib]), 0.0))
    # One shoulder hidden: no shoulder line and no neck, so nothing else
    # measures the trunk's turn about the vertical (a side view hides the
    # hips too); the seen shoulder's direction from the hip-centred origin
    # does, give or take the trunk's lean.
    have = np.all(np.isfinite(tw), axis=2)
    for a, b, other, wt in _HALF_TRUNK:
        ia, ib, io = names.index(a), names.index(b), names.index(other)
        d = tw[:, ib] - tw[:, ia]
        ln = np.linalg.norm(d, axis=-1, keepdims=True)
        ok = np.isfinite(ln[:, 0]) & (ln[:, 0] > 1e-6) & (tc[:, ib] > 0) & ~(have[:, io] & (tc[:, io] > 0))
        pairs.append((a, b))
        dirs.append(np.where(ok[:, None], d / np.where(ok[:, None], ln, 1.0), np.nan))
        w.append(np.where(ok, wt * np.minimum(cw[:, ia], cw[:, ib]), 0.0))
    for a, mid, b, wt in SKIP_DIRECTIONS:
        ia, im, ib = names.index(a), names.index(mid), names.index(b)
        d = tw[:, ib] - tw[:, ia]
        ln = np.linalg.norm(d, axis=-1, keepdims=True)
        ok = np.isfinite(ln[:, 0]) & (ln[:, 0] > 1e-6) & (cw[:, im] <= 0)
        pairs.append((a, b))
        dirs.append(np.where(ok[:, None], d / np.where(ok[:, None], ln, 1.0), np.nan))
        w.append(np.where(ok, wt * np.minimum(cw[:, ia], cw[:, ib]), 0.0))
    return pairs, np.stack(dirs, 1), np.stack(w, 1)


def _check_2d(xy, confidence, world):
    xy = np.asarray(xy, float)
    if xy.ndim != 3 or xy.shape[1] != 33 or xy.shape[2] < 2:
        raise FittingError(f"keypoints must have shape (T, 33, 2), got {xy.shape}")
    image_z = xy[..., 2] if xy.shape[2] > 2 else None
    xy = xy[..., :2]
    conf = np.asarray(confidence, float)
    if conf.shape != xy.shape[:2]:
        raise FittingError(f"confidence must have shape {xy.shape[:2]}, got {conf.shape}")
    conf = np.where(np.isfinite(conf), np.clip(conf, 0.0, 1.0), 0.0)
    if world is not None:
        world = np.asarray(world, float)
        if world.shape != xy.shape[:2] + (3,):
            raise FittingError(f"world landmarks must have shape {xy.shape[:2] + (3,)}, got {world.shape}")
    if xy.shape[0] == 0:
        raise FittingError("no frames to fit (T = 0)")
    return xy, conf, world, image_z


def fit_keypoints(
    xy,
    confidence,
    fps: float,
    camera: Camera | None = None,
    world=None,
    body: Body | None = None,
    times=None,
    image_size=None,
    options: FitOptions | None = None,
    roll_deg: float = 0.0,
) -> FitResult:
    """Fit 3D joint angles to a track of 2D BlazePose landmarks.

    Parameters
    ----------
    xy : (T, 33, 2) ndarray
        Landmark pixel coordinates; NaN where missing.
    confidence : (T, 33) ndarray
        Per-landmark confidence (visibility) in [0, 1].
    fps : float
        Frame rate, frames per second.
    camera : Camera, optional
        Known camera (e.g. from a truth sidecar).  Default:
        :meth:`Camera.default` for `image_size` with the focal length refined
        from the data, and the floor set from the lowest feet.
    world : (T, 33, 3) ndarray, optional
        World landmarks, metres, camera-aligned axes (hip-centred, +x image
        right, +y down, +z away from the camera); give the segment directions
        that resolve depth and the per-clip segment lengths.
    body : Body, optional
        Proportions when no world landmarks give lengths (default ``Body()``).
    times : (T,) ndarray, optional
        Seconds (default ``arange(T) / fps``).
    image_size : (width, height), optional
        Needed when `camera` is None.
    options : FitOptions, optional
    roll_deg : float
        Without `camera`: the default camera's roll about its optical axis,
        degrees (:meth:`Camera.default`; e.g. from
        :func:`~.camera_estimate.estimate_camera`, which reads it from the
        body's balance axis across the image to about a degree).

    Returns
    -------
    FitResult
    """
    opt = options or FitOptions()
    xy, conf, world, image_z = _check_2d(xy, confidence, world)
    check_fps(fps)
    body = body or Body()
    set_floor = camera is None
    if camera is None:
        if image_size is None:
            raise FittingError("fit_keypoints needs a camera or the image_size (width, height) for a default camera")
        start = Camera.default(image_size, roll_deg=roll_deg)
        camera = refine_focal(xy, conf, fps, start, world=world, body=body, options=opt)
    known = not set_floor
    # The camera and the figure's proportions belong to the whole clip; the
    # rest is fitted span by span (:mod:`.spans`: bounded memory).
    sel = spread_frames(xy.shape[0], PROPORTION_FRAMES)
    names, tx, tc, tw = _targets_from_landmarks(xy[sel], conf[sel], None if world is None else world[sel], opt)
    offsets = image_offsets(names, tx, tc, tw, camera, body, known)
    times = np.arange(xy.shape[0]) / fps if times is None else np.asarray(times, float)
    if times.shape != xy.shape[:1]:
        raise FittingError(f"times must have shape ({xy.shape[0]},), got {times.shape}")
    spans = track_spans(xy.shape[0], fps, opt.span_s, opt.context_s)
    rest = None
    if len(spans) > 1:
        # The rest offsets too (the pose model's bias for this figure):
        # measured once on the frames spread over the clip.
        rest = {}
        iz = None if image_z is None else image_z[sel]
        wsel = None if world is None else world[sel]
        _prepared(xy[sel], conf[sel], wsel, iz, fps, body, camera, known, offsets, opt, rest)
    parts = []
    for a, b, _, _ in spans:
        iz = None if image_z is None else image_z[a:b]
        wb = None if world is None else world[a:b]
        parts.append(_fit_span(xy[a:b], conf[a:b], wb, iz, fps, times[a:b], body, camera, known, offsets, opt, rest))
    result = stitch(parts, spans)
    return _floored(result) if set_floor else result


def _fit_span(xy, conf, world, image_z, fps, times, body, camera, known, offsets, opt, rest=None) -> FitResult:
    """Fit frames with the clip's camera, proportions and rest offsets (see :func:`fit_keypoints`)."""
    model, terms, names, tx, tc, use2, params0 = _prepared(
        xy, conf, world, image_z, fps, body, camera, known, offsets, opt, rest
    )
    params, cost = solve(model, params0, terms, fps, opt, opt.iterations)
    params, cost = rewarm(model, params, cost, terms, fps, opt)
    for _ in range(opt.root_passes):
        params = smooth_root(model, params, terms, fps, opt)
        params, cost = solve(model, params, terms, fps, opt, opt.polish_iterations, frozen=coupled_params(model))
    usable = np.sum(tc[:, use2] >= opt.min_confidence, axis=1) >= opt.min_targets
    # Per-target fit quality from the remaining reprojection error (sigma units).
    pts = model.forward(params)
    uv = camera.project(pts[:, terms.idx2])
    depth = np.maximum(camera.to_camera(params[:, :3])[:, 2], 0.1)
    err = np.linalg.norm(uv - tx[:, use2], axis=-1) * (depth / (camera.focal * opt.sigma_2d))[:, None]
    quality = np.ones_like(tc)
    quality[:, use2] = 1.0 / (1.0 + (np.nan_to_num(err, nan=np.inf) / 3.0) ** 2)
    target_conf = tc * quality
    joint_conf = _joint_confidence(names, target_conf)
    if opt.spread_deg > 0:
        # A joint is only as sure as the direction of the segment it ends.
        joint_conf *= spread_factor(direction_spread(model, params, terms, fps, opt), opt.spread_deg)
    return to_result(model, params, fps, times, joint_conf, usable)


def _prepared(xy, conf, world, image_z, fps, body, camera, known, offsets, opt, rest):
    """The fit's model, data terms and starting parameters of some frames.

    The world targets' depths are chosen and their rest offsets removed
    here (:mod:`.depth`); `rest` holds the clip's offsets (filled when
    empty, see :func:`~.depth.remove_leg_rest_offsets`).

    Returns
    -------
    model, terms, names, tx (T, N, 2), tc (T, N), use2 (N,), params0 (T, P)
    """
    model, terms, (names, tx, tc, tw), use2 = _problem(xy, conf, world, body, camera, opt, floor=known, offsets=offsets)
    if known and opt.sigma_floor > 0:
        _floor_terms(model, terms, tc, names)
    params0 = initial_params(model, camera, names, tx, tc, tw, floor=known)
    if tw is not None:
        tw = _impute_shoulders(model, camera, params0, names, tc, tw)
        if opt.depth is not None:
            # Decide which side of the image plane each arm segment lies on
            # before the continuous solve, which only refines the side it
            # starts on.
            tw, _ = choose_arm_depths(model, camera, params0, names, tx, tc, tw, image_z, fps, opt.depth, rest)
            if opt.depth.rest_offset:
                tw = remove_leg_rest_offsets(model, camera, params0, names, tx, tc, tw, rest)
        _, terms.dirs, terms.wd = _direction_terms(names, tc, tw)
        params0 = initial_params(model, camera, names, tx, tc, tw, floor=known)
    return model, terms, names, tx, tc, use2, params0


def _floor_terms(model: PoseModel, terms: Terms, tc: np.ndarray, names) -> None:
    """Add the floor-contact term to `terms` (known camera: the floor is z = 0).

    Frames whose feet are not seen get no floor term (:func:`~.solver.floor_terms`).
    """
    floor_terms(model, terms, tc[:, [names.index(n) for n in FOOT_POINTS]].max(axis=1))


def _joint_confidence(names, tconf) -> np.ndarray:
    """(T, J) joint confidence from per-target confidence (T, N)."""
    T = tconf.shape[0]
    out = np.zeros((T, _J))
    for j, name in enumerate(JOINTS):
        if name in names:
            out[:, j] = tconf[:, names.index(name)]
        elif name in _DERIVED_CONF:
            cols = [names.index(n) for n in _DERIVED_CONF[name]]
            agg = np.max if name == "head" else np.min
            out[:, j] = agg(tconf[:, cols], axis=1)
    return out


def _floored(res: FitResult) -> FitResult:
    """The clip levelled so the floor its feet stand on is z = 0 (:func:`~.ground.fit_floor`).

    Without a known camera the fit's floor is its own guess.  DESIGN.md's
    floor is where the feet rest longest, so its height is fitted to the
    lowest foot points of the whole clip (a low quantile, not the lowest
    glitch), as for a motion file; it stays level (the fitted feet's depth
    errors would read as a tilt: limb errors doubled on random scores).
    """
    ok = (np.asarray(res.confidence) > 0) & np.all(np.isfinite(res.joints), axis=-1)
    try:
        floor = fit_floor(res.joints, ok, None, tilt=False)
    except MotionFileError:
        return res  # no foot ever seen: the floor stays the fit's own
    return res.replace(joints=level_points(res.joints, floor), root=level_points(res.root[:, None], floor)[:, 0])


def refine_focal(
    xy,
    confidence,
    fps,
    camera: Camera,
    world=None,
    body=None,
    options: FitOptions | None = None,
    hfovs=(40.0, 50.0, 60.0, 70.0, 85.0),
    max_frames: int = 24,
) -> Camera:
    """Choose the focal length that best explains the data.

    Fits up to `max_frames` evenly spaced frames for each candidate horizontal
    field of view and keeps the one with the lowest robust cost (a parabola
    through the best three refines it).  With 2D landmarks only, focal length
    and distance trade off and the default (``DEFAULT_HFOV_DEG``) is kept.

    Returns
    -------
    Camera
        `camera` with the refined focal length.
    """
    opt = options or FitOptions()
    if world is None:
        return camera
    T = xy.shape[0]
    sel = np.unique(np.linspace(0, T - 1, min(T, max_frames)).round().astype(int))
    w = camera.image_size[0]
    costs = []
    quick = FitOptions(**{**opt.__dict__, "iterations": 10})
    for h in hfovs:
        cam = camera.with_focal(0.5 * w / np.tan(np.deg2rad(h) / 2))
        res_cost = _quick_cost(xy[sel], confidence[sel], fps, cam, world[sel], body, quick)
        costs.append(res_cost)
    costs = np.asarray(costs)
    if not np.all(np.isfinite(costs)):
        return camera.with_focal(0.5 * w / np.tan(np.deg2rad(DEFAULT_HFOV_DEG) / 2))
    i = int(np.argmin(costs))
    h = hfovs[i]
    if 0 < i < len(hfovs) - 1:
        x, y = np.asarray(hfovs[i - 1 : i + 2]), costs[i - 1 : i + 2]
        a, b, _ = np.polyfit(x, y, 2)
        if a > 0:
            h = float(np.clip(-b / (2 * a), x[0], x[2]))
    return camera.with_focal(0.5 * w / np.tan(np.deg2rad(h) / 2))


def _quick_cost(xy, conf, fps, cam, world, body, opt) -> float:
    """Total robust cost of fitting a few frames with camera `cam`."""
    model, terms, (names, tx, tc, tw), _ = _problem(xy, conf, world, body or Body(), cam, opt)
    p0 = initial_params(model, cam, names, tx, tc, tw)
    # The frames are far apart in time: a tiny rate switches the temporal term off.
    _, cost = solve(model, p0, terms, 1e-6, opt, opt.iterations)
    return float(np.sum(cost))


def _problem(xy, conf, world, body: Body, camera: Camera, opt: FitOptions, floor: bool = False, offsets=None):
    """Model with the clip's segment lengths and the data terms of a 2D fit.

    `offsets` (J, 3) are the clip's proportions when already measured
    (:func:`~.start.image_offsets`), else they are measured on these frames.

    Returns
    -------
    model : PoseModel
    terms : Terms
    targets : (names, xy (T,N,2), conf (T,N), world (T,N,3) or None)
    use2 : (N,) bool
        Targets with a reprojection term.
    """
    names, tx, tc, tw = _targets_from_landmarks(xy, conf, world, opt)
    if offsets is None:
        offsets = image_offsets(names, tx, tc, tw, camera, body, floor)
    model = PoseModel(body, offsets)
    w_targets = np.array([t[2] for t in TARGETS_2D])
    use2 = w_targets > 0
    terms = Terms(
        camera=camera,
        idx2=np.array([model.index(nm) for nm in np.array(names)[use2]]),
        obs2=tx[:, use2],
        w2=tc[:, use2] * w_targets[use2],
    )
    if tw is not None:
        pairs, dirs, wd = _direction_terms(names, tc, tw)
        terms.pairs = np.array([[model.index(a), model.index(b)] for a, b in pairs])
        terms.dirs, terms.wd = dirs, wd
    return model, terms, (names, tx, tc, tw), use2


def fit_track(
    track,
    camera: Camera | None = None,
    body: Body | None = None,
    options: FitOptions | None = None,
    roll_deg: float = 0.0,
) -> FitResult:
    """Fit a :class:`~capture2notation.keypoints.KeypointTrack`.

    Parameters
    ----------
    track : KeypointTrack
        Uses ``xy (T, 33, ≥2)``, ``visibility (T, 33)``, ``presence (T,)``,
        ``world (T, 33, 3)`` (optional), ``fps``, ``times``, ``image_size``.
    camera : Camera, optional
        Known camera; default a :meth:`Camera.default` refined from the data.
    body, options, roll_deg : optional
        Passed to :func:`fit_keypoints`.  Without `options`, a BlazePose
        track has its world landmarks' rest offset removed
        (``DepthOptions(rest_offset=True)``).

    Returns
    -------
    FitResult
        With the track's ``identity_confidence`` (where it was assessed)
        beside the joints' own confidence.
    """
    xy = np.asarray(track.xy, float)
    vis = np.asarray(track.visibility, float)
    presence = getattr(track, "presence", None)
    if presence is not None:
        vis = vis * np.clip(np.nan_to_num(np.asarray(presence, float)), 0, 1)[:, None]
    world = getattr(track, "world", None)
    if world is not None:
        world = np.asarray(world, float)
        if not np.any(np.isfinite(world)):
            world = None
    if options is None and getattr(track, "backend", None) == "blazepose":
        # BlazePose's world landmarks give a straight hanging limb a depth
        # of its own (:mod:`~capture2notation.fitting.depth`).
        options = FitOptions(depth=DepthOptions(rest_offset=True))
    result = fit_keypoints(
        xy,
        vis,
        float(track.fps),
        camera=camera,
        world=world,
        body=body,
        times=getattr(track, "times", None),
        image_size=tuple(np.asarray(track.image_size).tolist()),
        options=options,
        roll_deg=roll_deg,
    )
    ident = getattr(track, "identity_confidence", None)
    if ident is None or not np.any(np.isfinite(ident)):
        return result
    return replace(result, identity_confidence=np.asarray(ident, dtype=float))
