"""The starting pose of the 2D fit: each frame's first parameters and the clip's proportions.

The solver (:mod:`~capture2notation.fitting.solver`) refines a pose it is
given; this module gives it one.  The root starts under the hips at a depth
from the figure's image size or, with a known camera, from the feet on the
floor (:mod:`~capture2notation.fitting.floor`); the pelvis faces as the hips
(or shoulders) say; the joint angles come from the keypoint model's world
landmarks in closed form, or from the 2D landmarks lifted onto their rays
(:func:`lift`).  The per-clip segment proportions come from the segments'
back-projected image lengths (:func:`image_offsets`).
"""

from __future__ import annotations

import numpy as np

from ..body import JOINTS, Body, joint_index
from .camera import Camera
from .floor import FLOOR_POINTS, floor_depth, support_depth
from .ik import initial_angles
from .lengths import offsets_from_ratios
from .model import PoseModel
from .solver import fill, fill2, pelvis_axis

__all__ = ["SKIP_DIRECTIONS", "image_offsets", "initial_params", "world_weights"]

_J = len(JOINTS)

#: Limbs whose middle joint may be hidden (a leg raised straight at the camera
#: hides its knee behind the foot): where the middle target has no world
#: position, the direction root → end (weight) stands in for the two segments'
#: directions, so the limb keeps the evidence of which side it points to.
SKIP_DIRECTIONS: tuple[tuple[str, str, str, float], ...] = tuple(
    (f"{s}_{a}", f"{s}_{m}", f"{s}_{b}", 1.0)
    for s in ("right", "left")
    for a, m, b in (("hip", "knee", "ankle"), ("shoulder", "elbow", "wrist"))
)

#: Weight of a world target placed by :func:`_impute_hips` (:mod:`.fit`) rather than measured.
IMPUTED_WEIGHT = 0.7


def world_weights(tc, tw) -> np.ndarray:
    """(T, N) confidence of the world targets: the landmarks', or :data:`IMPUTED_WEIGHT` where imputed."""
    have = np.all(np.isfinite(tw), axis=2)
    return np.where(have, np.where(tc > 0, tc, IMPUTED_WEIGHT), 0.0)


def image_offsets(names, tx, tc, tw, camera: Camera, body: Body, floor: bool = False) -> np.ndarray:
    """Per-clip proportions from the image lengths of the segments.

    A segment's two ends put back on their pixels' rays at their depths
    (pelvis depth + world landmark depth, :func:`_backprojected_lengths`)
    are its length apart when those depths are right, and its length
    foreshortened when the landmarks flatten it.  With world landmarks, the
    frames where they call the segment flat (depth component under 0.25 of
    the length) give the median length; without, the 90th percentile over
    the clip does.  The upper arms take the longer of that and the long end
    of all their frames (:func:`_upper_arm_length`: the landmarks call many a
    foreshortened arm flat, which measured them 10-15 % short on our
    renders) and the forearms their proportion to it; neither sets the
    figure's scale.  Only the proportions are kept (``relative=True`` in
    :func:`~capture2notation.fitting.lengths.offsets_from_ratios`), so the
    lengths agree with where the keypoint model puts its landmarks (a BlazePose
    ankle sits above our ankle joint) while the size stays the body's.
    """
    model0 = PoseModel(body)
    depth = camera.to_camera(initial_params(model0, camera, names, tx, tc, tw, pose=False, floor=floor)[:, :3])[:, 2]
    ratio = np.full(_J, np.nan)
    base = np.linalg.norm(body.offsets, axis=1)
    for j, name in enumerate(JOINTS):
        p = body.parents[j]
        if p < 0 or name not in names or JOINTS[p] not in names or base[j] <= 0:
            continue
        a, b = names.index(JOINTS[p]), names.index(name)
        metres = _backprojected_lengths(camera, tx, tw, depth, a, b)
        ok = (tc[:, a] >= 0.5) & (tc[:, b] >= 0.5) & np.isfinite(metres)
        if tw is not None:
            d = tw[:, b] - tw[:, a]
            ok &= np.abs(d[:, 2]) < 0.25 * np.linalg.norm(d, axis=1)
        if ok.sum() < 3:
            continue
        ratio[j] = (np.median(metres[ok]) if tw is not None else np.percentile(metres[ok], 90)) / base[j]
    scale_from = np.isfinite(ratio)
    for side in ("right", "left"):
        upper = _upper_arm_length(
            camera, tx, tc, tw, depth, names.index(f"{side}_shoulder"), names.index(f"{side}_elbow")
        )
        elbow, wrist = JOINTS.index(f"{side}_elbow"), JOINTS.index(f"{side}_wrist")
        if np.isfinite(upper):
            ratio[elbow] = np.nanmax([ratio[elbow], upper / base[elbow]])
        # The image model's wrist slides along the hand with the pose (up the
        # hand of a hanging arm, out along an extended one): the forearm keeps
        # the body's proportion to the upper arm.
        ratio[wrist] = ratio[elbow]
        scale_from[[elbow, wrist]] = False
    return offsets_from_ratios(ratio, body, relative=True, scale_from=scale_from)


def _upper_arm_length(camera: Camera, tx, tc, tw, depth, a: int, b: int) -> float:
    """Length of an upper arm (metres) from the long end of its back-projected lengths.

    Each end is put back on its pixel's ray at the pelvis depth plus its
    world landmark's depth (the pelvis depth alone without landmarks).  The
    landmarks' depth differences are too small on a foreshortened arm (and
    call it flat), which only shortens this length, so the long end of it —
    the 90th percentile less what the keypoints' jitter adds to it — is the
    arm seen side on.  The landmarks' depth noise lengthens every frame
    (by its variance, in quadrature), which is taken out first.  NaN with
    fewer than 3 confident frames.
    """
    length = _backprojected_lengths(camera, tx, tw, depth, a, b)
    if tw is not None:
        dz = np.where(np.isfinite(length), tw[:, b, 2] - tw[:, a, 2], np.nan)
        length = np.sqrt(np.maximum(length**2 - _jitter(dz) ** 2, 0.0))
    ok = (tc[:, a] >= 0.5) & (tc[:, b] >= 0.5) & np.isfinite(length)
    if ok.sum() < 3:
        return float("nan")
    return float(np.percentile(length[ok], 90) - 1.28 * _jitter(np.where(ok, length, np.nan)))


def _backprojected_lengths(camera: Camera, tx, tw, depth, a: int, b: int) -> np.ndarray:
    """(T,) distance (metres) between targets `a` and `b` put back on their pixels' rays.

    Each at the pelvis depth `depth` plus its world landmark's depth, or at
    the pelvis depth alone without world landmarks.
    """
    za, zb = (depth, depth) if tw is None else (depth + tw[:, a, 2], depth + tw[:, b, 2])
    return np.linalg.norm(camera.backproject(tx[:, a], za) - camera.backproject(tx[:, b], zb), axis=-1)


def _jitter(x: np.ndarray) -> float:
    """Standard deviation of the frame-to-frame noise of a smooth series (NaN-tolerant).

    From second differences, which a motion smooth at the frame rate hardly
    moves: white noise of spread s spreads them by s·√6.  The median
    absolute deviation keeps a fast movement's few large steps out.
    """
    d2 = np.diff(np.asarray(x, float), n=2)
    d2 = d2[np.isfinite(d2)]
    if d2.size < 3:
        return 0.0
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / np.sqrt(6.0))


def _floor_start_depth(model: PoseModel, cam: Camera, names, tx, tc, tw, size_depth, rest) -> np.ndarray:
    """(T,) starting depth from the feet on the floor (:mod:`~capture2notation.fitting.floor`).

    The lower foot (world targets `tw`, else the image) stands on the floor;
    frames whose feet are not seen keep the image-size depth `size_depth`,
    calibrated against the floor's.
    """
    idx = np.array([[model.index(n) for n in foot] for foot in FLOOR_POINTS])
    cols = np.array([[names.index(n) for n in foot] for foot in FLOOR_POINTS])
    lowest = model.body.rest[[joint_index("right_toe"), joint_index("right_ankle")], 2].min()
    base = rest[idx, 2].min()
    heights = (rest[idx, 2] - base + lowest).mean(axis=1)
    shift = None
    if tw is not None:
        down = cam.R @ np.array([0.0, 0.0, -1.0])  # camera-aligned world targets
        lowness = np.mean(tw[:, cols] @ down, axis=2)  # NaN unless both points are seen
        # The body model stands its pelvis above the ankles, behind the
        # foot's centre by this much along the foot.
        ankles = np.array([model.index(f"{foot[0].split('_')[0]}_ankle") for foot in FLOOR_POINTS])
        back = float(np.mean(rest[idx, 1].mean(axis=1) - rest[ankles, 1]))
        along = (tw[:, cols[:, 1]] - tw[:, cols[:, 0]]) @ cam.R  # heel -> toe, world axes
        along[..., 2] = 0.0
        n = np.linalg.norm(along, axis=-1, keepdims=True)
        shift = -back * np.where(n > 1e-6, along / np.maximum(n, 1e-6), np.nan)  # a foot seen end-on: no shift
    else:
        lowness = np.mean(tx[:, cols][..., 1], axis=2)
    feet = floor_depth(cam, tx[:, cols], tc[:, cols], heights, float(lowest - base), shift)
    return support_depth(feet, lowness, size_depth)


def initial_params(
    model: PoseModel, cam: Camera, names, tx, tc, tw, pose: bool = True, floor: bool = False
) -> np.ndarray:
    """Starting parameters of every frame.

    The root is under the hip midpoint at a depth from the feet on the floor
    when `floor` (a known camera), else from the figure's image scale; the
    pelvis faces as the hips say; with `pose`, the joint angles
    come from :func:`~capture2notation.fitting.ik.initial_angles` on the
    world landmarks, or on the 2D landmarks lifted by :func:`lift`.
    """
    T = tx.shape[0]
    n = model.n_params
    params = np.zeros((T, n))
    pel_px = tx[:, names.index("pelvis")]
    neck_px = tx[:, names.index("neck")]
    rest = model.forward(np.zeros((1, n)))[0]
    f = cam.focal
    # Depth from lengths seen in the image: foreshortening only shortens, so
    # use a low quantile of the per-segment estimates.
    segs = [
        ("pelvis", "neck"),
        ("right_hip", "right_knee"),
        ("left_hip", "left_knee"),
        ("right_knee", "right_ankle"),
        ("left_knee", "left_ankle"),
        ("right_shoulder", "right_elbow"),
        ("left_shoulder", "left_elbow"),
    ]
    est = []
    for a, b in segs:
        L = np.linalg.norm(rest[model.index(b)] - rest[model.index(a)])
        lpx = np.linalg.norm(tx[:, names.index(b)] - tx[:, names.index(a)], axis=-1)
        est.append(np.where(lpx > 2.0, f * L / lpx, np.nan))
    est = np.stack(est, 1)
    depth = np.full(T, np.nan)
    seen = np.any(np.isfinite(est), axis=1)
    if seen.any():
        depth[seen] = np.nanquantile(est[seen], 0.3, axis=1)
    if floor:
        depth = _floor_start_depth(model, cam, names, tx, tc, tw, depth, rest)
    depth = fill(depth, fallback=float(np.linalg.norm(cam.centre)))
    centre = np.where(np.isfinite(pel_px), pel_px, neck_px)
    centre = fill2(centre, fallback=np.array(cam.K[:2, 2]))
    root = cam.backproject(centre, depth)
    params[:, :3] = root
    # Yaw: the forward direction faces the camera unless the hips say otherwise.
    to_cam = cam.centre[None, :] - root
    yaw = np.arctan2(-to_cam[:, 0], to_cam[:, 1])
    ir, il = names.index("right_hip"), names.index("left_hip")
    if tw is not None:
        yaw = _world_yaw(names, tc, tw, cam, yaw)
    else:
        seen = tx[:, ir] - tx[:, il]
        right_model = np.stack([np.cos(yaw), np.sin(yaw), np.zeros(T)], 1)
        expect = cam.project(root + 0.1 * right_model) - cam.project(root)
        flip = np.sum(seen * expect, axis=1) < 0
        yaw = np.where(flip, yaw + np.pi, yaw)
    yaw = np.unwrap(fill(yaw, fallback=0.0))
    params[:, 3 + pelvis_axis(model, 2)] = yaw
    if not pose:
        return params
    if tw is not None:
        # World landmarks give 3D directions: start from their closed-form pose.
        pts = np.full((T, _J, 3), np.nan)
        cw = world_weights(tc, tw)
        for i, name in enumerate(names):
            if name in JOINTS:
                pts[:, joint_index(name)] = np.where((cw[:, i] > 0)[:, None], tw[:, i] @ cam.R, np.nan)
        # A hidden knee or elbow (the limb points at the camera) starts on the
        # straight line from its root to its end, so the limb starts on the
        # side the world landmarks give rather than hanging.
        for a, mid, b, _ in SKIP_DIRECTIONS:
            ia, im, ib = joint_index(a), joint_index(mid), joint_index(b)
            la, lb = (np.linalg.norm(model.offsets[model.index(n)]) for n in (mid, b))
            miss = ~np.all(np.isfinite(pts[:, im]), axis=1)
            pts[miss, im] = pts[miss, ia] + la / (la + lb) * (pts[miss, ib] - pts[miss, ia])
    else:
        pts = lift(model, cam, names, tx, tc, root, yaw)
    ang = initial_angles(pts, model)
    have = np.all(np.isfinite(pts[:, [joint_index("right_hip"), joint_index("left_hip")]]), axis=(1, 2))
    ang[~have, 0] = 0.0
    ang[~have, 0, 2] = yaw[~have]
    ang[:, 0] = np.unwrap(ang[:, 0], axis=0)  # the pelvis turns freely: keep it continuous
    params[:, 3:] = ang[:, model.dof_joint, model.dof_axis]
    return params


def _world_yaw(names, tc, tw, cam: Camera, default: np.ndarray) -> np.ndarray:
    """(T,) starting pelvis yaw from the world targets, radians.

    The hips' line where both hips have world targets; else the shoulders'
    line (the trunk seldom twists far); else the horizontal direction from
    the hip-centred origin to the one seen shoulder (off by the trunk's
    sideways lean only); frames with none of these take the yaw of their
    neighbours in time, and `default` only when the clip has none at all.
    A side view often hides both hips (a hanging arm covers the near one),
    and facing the camera, the old default there, started the pelvis 90° off.
    """
    il, ir = names.index("left_hip"), names.index("right_hip")
    sl, sr = names.index("left_shoulder"), names.index("right_shoulder")
    shown = (tc > 0) & np.all(np.isfinite(tw), axis=2)
    cands = (
        (tw[:, ir] - tw[:, il], np.all(np.isfinite(tw[:, [il, ir]]), axis=(1, 2))),
        (tw[:, sr] - tw[:, sl], shown[:, sr] & shown[:, sl]),
        (tw[:, sr], shown[:, sr]),
        (-tw[:, sl], shown[:, sl]),
    )
    yaw = np.full(len(default), np.nan)
    for vec, ok in cands:
        right_w = np.nan_to_num(vec) @ cam.R  # camera axes -> world
        ok = ok & np.isnan(yaw) & (np.hypot(right_w[:, 0], right_w[:, 1]) > 1e-6)
        yaw[ok] = np.arctan2(right_w[ok, 1], right_w[ok, 0])
    ok = np.isfinite(yaw)
    if not ok.any():
        return default
    yaw[ok] = np.unwrap(yaw[ok])
    return fill(yaw, fallback=0.0)


#: Chains lifted from 2D, parent target before child (see :func:`lift`).
_LIFT_CHAIN = (
    ("pelvis", "neck"),
    ("neck", "right_shoulder"),
    ("neck", "left_shoulder"),
    ("pelvis", "right_hip"),
    ("pelvis", "left_hip"),
) + tuple(
    (f"{s}_{a}", f"{s}_{b}")
    for s in ("right", "left")
    for a, b in (
        ("shoulder", "elbow"),
        ("elbow", "wrist"),
        ("wrist", "hand_tip"),
        ("hip", "knee"),
        ("knee", "ankle"),
        ("ankle", "toe"),
    )
)


def lift(model: PoseModel, cam: Camera, names, tx, tc, root, yaw) -> np.ndarray:
    """3D joints from 2D landmarks alone, for the starting pose.

    Walking down the tree from the pelvis (at `root`), each joint is put on
    its pixel's ray at the model's segment length from its parent; of the two
    solutions the one in front of the performer is taken (dancers gesture
    forward far more than backward), the closest point of the ray when the
    image segment is longer than the model's, and for shins, which bend
    either way.

    Returns
    -------
    (T, J, 3) ndarray
        World positions, NaN where a landmark is missing.
    """
    T = tx.shape[0]
    rest = model.forward(np.zeros((1, model.n_params)))[0]
    Kinv = np.linalg.inv(cam.K)
    forward = np.stack([-np.sin(yaw), np.cos(yaw), np.zeros(T)], axis=1)
    towards_camera = (forward @ cam.R.T)[:, 2] < 0  # forward points at the camera
    cam_pts = {"pelvis": cam.to_camera(root)}
    for a, b in _LIFT_CHAIN:
        pa = cam_pts.get(a)
        if pa is None:
            continue
        ib = names.index(b)
        ray = np.concatenate([tx[:, ib], np.ones((T, 1))], axis=1) @ Kinv.T
        L = np.linalg.norm(rest[model.index(b)] - rest[model.index(a)])
        rr = np.sum(ray * ray, axis=1)
        rp = np.sum(ray * pa, axis=1)
        disc = rp**2 - rr * (np.sum(pa * pa, axis=1) - L**2)
        root_d = np.sqrt(np.maximum(disc, 0.0))
        # Lift only clearly foreshortened segments (image length under 0.8 of
        # the model's): near the image plane the sign is a guess and the depth
        # is mostly noise.  A knee bends either way (plié back, gesture
        # forward), so shins are never lifted: the fit chooses.
        l2 = np.sum((ray * (rp / rr)[:, None] - pa) ** 2, axis=1)
        clear = l2 < (0.8 * L) ** 2
        root_d = np.where(clear & (not b.endswith("_ankle")), root_d, 0.0)
        lam = np.where(towards_camera, rp - root_d, rp + root_d) / rr
        pb = ray * lam[:, None]
        pb[tc[:, ib] <= 0] = np.nan
        cam_pts[b] = pb
    pts = np.full((T, _J, 3), np.nan)
    for name, c in cam_pts.items():
        pts[:, joint_index(name)] = (c - cam.t) @ cam.R
    return pts
