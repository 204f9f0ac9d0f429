"""Triangulate image keypoints seen by two or more calibrated cameras.

Per landmark and frame, a confidence-weighted direct linear transform (DLT,
Hartley & Zisserman §12.2) on undistorted, normalised image coordinates;
each view's two rows are scaled by its keypoint visibility, however low: a
keypoint model's visibility is not a reliability (BlazePose rates arm
landmarks in front of the body 0.05-0.3 that lie within a few pixels of the
truth), and a low-weight view still fixes the depth along the other view's
ray, while the two rays' residual judges the point.  A view whose
reprojection error exceeds :data:`OUTLIER_PX` is dropped when at least three
views see the point (a hidden or mirrored limb in one view), the worst one
first; with two views the reprojection residual lowers the point's
confidence instead (there is no majority to tell which view is wrong).  A
point seen by fewer than two views is NaN with zero confidence.

:func:`landmarks_to_joints` maps the 33 triangulated landmarks onto our joint
tree (and the model's virtual points) for :func:`~.fit3d.fit_points3d`.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import median_filter

from ..body import JOINTS, joint_index
from ..body.skeleton import BLAZEPOSE_TO_JOINT
from ..errors import FittingError

__all__ = [
    "LANDMARK_TARGETS",
    "MEASURED_JOINTS",
    "OUTLIER_PX",
    "RESIDUAL_PX",
    "SIDE_GROUPS",
    "find_offset",
    "landmarks_to_joints",
    "match_sides",
    "triangulate",
    "undistorted_pixels",
]

#: Reprojection error, pixels, above which one of three or more views is an
#: outlier: BlazePose's keypoint noise on a 640x480 dancer is a few pixels,
#: a mirrored or hidden limb tens of pixels.
OUTLIER_PX = 15.0
#: Reprojection residual, pixels, at which a two-view point's confidence
#: halves (Cauchy weight ``1 / (1 + (r / RESIDUAL_PX)²)``).
RESIDUAL_PX = 8.0
#: Landmarks the fit takes as virtual points (model names, BlazePose indices).
_VIRTUAL = {"nose": 0, "left_ear": 7, "right_ear": 8, "left_heel": 29, "right_heel": 30}


def _normalised(uv: np.ndarray, cam) -> np.ndarray:
    """Undistorted normalised coordinates ``(..., 2)`` of pixels ``(..., 2)`` (NaN kept)."""
    import cv2

    flat = uv.reshape(-1, 2)
    ok = np.all(np.isfinite(flat), axis=1)
    out = np.full(flat.shape, np.nan)
    if ok.any():
        pts = cv2.undistortPoints(flat[ok].reshape(-1, 1, 2).astype(np.float64), cam.K, cam.dist)
        out[ok] = pts.reshape(-1, 2)
    return out.reshape(uv.shape)


def undistorted_pixels(uv: np.ndarray, cam) -> np.ndarray:
    """Pixels ``(..., 2)`` as `cam`'s pinhole part would see them (lens distortion removed; NaN kept)."""
    K = np.asarray(cam.K, float)
    return _normalised(uv, cam) * np.array([K[0, 0], K[1, 1]]) + K[:2, 2]


#: ``(BlazePose landmark index, model point name)`` of every landmark the fit
#: takes: our joints' and the virtual points'.
LANDMARK_TARGETS: tuple[tuple[int, str], ...] = tuple(
    sorted({**BLAZEPOSE_TO_JOINT, **{i: n for n, i in _VIRTUAL.items()}}.items())
)


def _dlt(xn: np.ndarray, w: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Weighted DLT: xn (V, M, 2) normalised points, w (V, M), P (V, 3, 4) -> (M, 3) (NaN under 2 views)."""
    V, M = w.shape
    x = np.nan_to_num(xn)
    rows = np.empty((M, 2 * V, 4))
    for v in range(V):
        rows[:, 2 * v] = w[v, :, None] * (x[v, :, 0, None] * P[v, 2] - P[v, 0])
        rows[:, 2 * v + 1] = w[v, :, None] * (x[v, :, 1, None] * P[v, 2] - P[v, 1])
    X = np.full((M, 3), np.nan)
    enough = np.sum(w > 0, axis=0) >= 2
    if enough.any():
        _, _, vt = np.linalg.svd(rows[enough])
        h = vt[:, -1]
        with np.errstate(divide="ignore", invalid="ignore"):
            X[enough] = h[:, :3] / h[:, 3:4]
    return X


def triangulate(uv, visibility, cameras) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangulate keypoints of V calibrated views.

    Parameters
    ----------
    uv : (V, T, N, 2) ndarray
        Pixels per view, frame and point; NaN where unseen.
    visibility : (V, T, N) ndarray
        In [0, 1]; the DLT weight of each view (0: no vote).
    cameras : sequence of V CameraCalibration
        ``capture2notation.io.calibration`` cameras (K, dist, R, t).

    Returns
    -------
    points : (T, N, 3) ndarray
        World positions, metres; NaN where fewer than two views see a point.
    confidence : (T, N) ndarray
        In [0, 1]: the mean weight of the views used, lowered by the
        reprojection residual; 0 where NaN.
    used : (V, T, N) ndarray of bool
        Which views each point was triangulated from.
    """
    uv = np.asarray(uv, float)
    vis = np.asarray(visibility, float)
    V = len(cameras)
    if uv.ndim != 4 or uv.shape[0] != V or uv.shape[-1] != 2 or vis.shape != uv.shape[:3]:
        raise FittingError(
            f"triangulate needs uv (V, T, N, 2) and visibility (V, T, N) for {V} cameras; got {uv.shape}, {vis.shape}"
        )
    if V < 2:
        raise FittingError(f"triangulation needs at least two cameras, got {V}")
    T, N = uv.shape[1:3]
    M = T * N
    xn = np.stack([_normalised(uv[v], cameras[v]).reshape(M, 2) for v in range(V)])
    P = np.stack([np.hstack([c.R, np.asarray(c.t).reshape(3, 1)]) for c in cameras])
    w = np.where(np.all(np.isfinite(xn), axis=-1), np.clip(np.nan_to_num(vis.reshape(V, M)), 0, 1), 0.0)
    X = _dlt(xn, w, P)
    err = _reprojection(X, uv.reshape(V, M, 2), cameras, w > 0)
    # Drop the worst view of a point while it is an outlier and two views remain.
    for _ in range(V - 2):
        n_views = np.sum(w > 0, axis=0)
        worst = np.argmax(np.where(w > 0, err, -1.0), axis=0)
        bad = (n_views >= 3) & (np.take_along_axis(err, worst[None], 0)[0] > OUTLIER_PX)
        if not bad.any():
            break
        w[worst[bad], np.nonzero(bad)[0]] = 0.0
        X[bad] = _dlt(xn[:, bad], w[:, bad], P)
        err[:, bad] = _reprojection(X[bad], uv.reshape(V, M, 2)[:, bad], cameras, w[:, bad] > 0)
    used = w > 0
    n_used = np.maximum(used.sum(axis=0), 1)
    mean_w = w.sum(axis=0) / n_used
    rms = np.sqrt(np.sum(np.where(used, err, 0.0) ** 2, axis=0) / n_used)
    conf = mean_w / (1.0 + (rms / RESIDUAL_PX) ** 2)
    ok = np.all(np.isfinite(X), axis=1) & (used.sum(axis=0) >= 2)
    X[~ok] = np.nan
    conf = np.where(ok, conf, 0.0)
    return X.reshape(T, N, 3), conf.reshape(T, N), used.reshape(V, T, N)


def _reprojection(X: np.ndarray, uv: np.ndarray, cameras, used: np.ndarray) -> np.ndarray:
    """Pixel error (V, M) of points X (M, 3) against uv (V, M, 2); 0 where a view is unused."""
    err = np.zeros(used.shape)
    fin = np.all(np.isfinite(X), axis=1)
    for v, cam in enumerate(cameras):
        e = np.full(X.shape[0], 1e6)
        if fin.any():
            e[fin] = np.linalg.norm(cam.project(X[fin]) - uv[v, fin], axis=-1)
        # An untriangulated point counts as far off, without overflowing its square.
        err[v] = np.where(used[v], np.nan_to_num(e, nan=1e6, posinf=1e6), 0.0)
    return err


#: Left/right BlazePose landmark pairs that a keypoint model confuses together
#: (a side view often labels the whole near leg as the far one).
SIDE_GROUPS: dict[str, tuple[tuple[int, int], ...]] = {
    "arms": ((11, 12), (13, 14), (15, 16), (17, 18), (19, 20), (21, 22)),
    "legs": ((23, 24), (25, 26), (27, 28), (29, 30), (31, 32)),
}


#: Frames of the running median over which a view's left/right choice is made
#: (0.2 s at 25 fps: legs crossing make single frames ambiguous).
SIDE_MEDIAN_FRAMES = 5


def _group_error(uv, vis, cameras) -> tuple[np.ndarray, np.ndarray]:
    """Mean reprojection error (T,) of points triangulated from `uv` (V, T, n, 2), large where none,
    and the vector (T, 3) from the first point to the second (NaN where either is missing)."""
    P, _, used = triangulate(uv, vis, cameras)
    err = np.zeros(P.shape[:2])
    n = np.zeros(P.shape[:2])
    for v, cam in enumerate(cameras):
        e = np.linalg.norm(cam.project(P) - uv[v], axis=-1)
        ok = used[v] & np.isfinite(e)
        err += np.where(ok, e, 0.0)
        n += ok
    mean = np.where(n.sum(axis=1) > 0, err.sum(axis=1) / np.maximum(n.sum(axis=1), 1), 1e6)
    return mean, P[:, 1] - P[:, 0]


#: Largest angle, degrees, seen from above, between the hips' left → right
#: line and the shoulders': the trunk twists by 40-50° at most.  Two
#: cameras placed symmetrically about the performer (45° and −45°) see a
#: front-facing stance almost mirror-symmetric, and the swapped legs' rays
#: meet too (reprojecting as well as the true ones) but with the hips turned
#: by 90°, one in front of the other; this catches that labelling.
MAX_TWIST_DEG = 60.0


def _horizontal_cos(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cosine (T,) of the angle between vectors (T, 3) seen from above (NaN where undefined)."""
    a, b = a[:, :2], b[:, :2]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sum(a * b, axis=1) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))


def _swap_frames(keep: np.ndarray, swap: np.ndarray) -> np.ndarray:
    """Frames (T,) of bool where the swapped labels reproject better, over a running median.

    A limb's label does not flicker: the median of the error difference over
    :data:`SIDE_MEDIAN_FRAMES` frames decides.
    """
    return median_filter(swap - keep, size=SIDE_MEDIAN_FRAMES, mode="nearest") < 0


#: Difference of two labellings' mean reprojection errors, pixels, under
#: which reprojection does not decide between them: a few pixels of keypoint
#: noise.  Two cameras placed symmetrically about a dancer facing between
#: them see her swapped labels triangulate almost as well, turned by 90°.
SIDE_AMBIGUOUS_PX = 6.0


#: Angle, degrees, seen from above, by which two labellings must turn the
#: shoulders apart for the head to decide between them: a side view sees
#: both shoulders at one place, and its labellings differ by little.
SIDE_APART_DEG = 60.0


def _forward(left_to_right: np.ndarray) -> np.ndarray:
    """Horizontal forward (T, 3) of a body whose left → right vector is given (up × that vector)."""
    out = np.zeros_like(left_to_right)
    out[:, 0], out[:, 1] = -left_to_right[:, 1], left_to_right[:, 0]
    return out


#: Least horizontal offset of the nose from the ears' midpoint, metres, for
#: the head to overrule the keypoint model's own labels: about 9 cm when
#: upright, less as the head tilts up or down.
HEAD_MIN_M = 0.04


def _head_and_shoulders(uv, vis, cameras, min_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Where the head faces, and the shoulders' left → right vector, triangulated.

    Returns
    -------
    head : (T, 3) ndarray
        The nose's offset from the ears' midpoint; NaN under `min_m` seen
        from above.  Unchanged by swapping the ears' labels in either view:
        the nose has none, and the two ear points keep their midpoint.
        Where the ears are not both triangulated, from the shoulders'
        midpoint.
    shoulders : (T, 3) ndarray
        Right shoulder minus left shoulder.
    """
    P, _, _ = triangulate(uv[:, :, [0, 7, 8, 11, 12]], vis[:, :, [0, 7, 8, 11, 12]], cameras)
    h = P[:, 0] - 0.5 * (P[:, 1] + P[:, 2])
    # Each ear seen by one camera only (two cameras either side of the face,
    # a pose model that leaves hidden points out): the shoulders' midpoint,
    # which a relabelling moves little, stands in for the ears'.
    h = np.where(np.isfinite(h), h, P[:, 0] - 0.5 * (P[:, 3] + P[:, 4]))
    # A head tilted far up or down says little about where it faces.
    head = np.where(np.linalg.norm(h[:, :2], axis=1, keepdims=True) >= min_m, h, np.nan)
    return head, P[:, 4] - P[:, 3]


def _group_labels(pairs) -> tuple[np.ndarray, np.ndarray]:
    """A group's landmark indices, and the same with left and right exchanged."""
    return np.array([i for ab in pairs for i in ab]), np.array([i for a, b in pairs for i in (b, a)])


def _relabel(uv, vis, v: int, frames, idx, alt) -> None:
    """Exchange left and right of one group in view `v` at `frames`, in place."""
    uv[v][np.ix_(frames, idx)] = uv[v][np.ix_(frames, alt)]
    vis[v][np.ix_(frames, idx)] = vis[v][np.ix_(frames, alt)]


def match_sides(uv, visibility, cameras) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Relabel left and right in each view to agree with the first view, per frame and limb group.

    A keypoint model seeing a dancer from the side often swaps the legs
    (or arms) as a whole; triangulating a swapped view against a right one
    puts both limbs between them.  For each view after the first, each
    group of :data:`SIDE_GROUPS` and each frame, the labelling whose
    two-view triangulation with the first view reprojects closer is kept.
    Two cameras placed symmetrically about a front-facing dancer cannot tell
    swapped limbs by reprojection (the swapped rays meet too, the body
    turned by 90°), so two priors decide where it cannot: for the arms,
    where the labellings reproject within :data:`SIDE_AMBIGUOUS_PX` of each
    other and turn the shoulders at least :data:`SIDE_APART_DEG` apart, the
    one whose shoulders face where the head looks (the nose ahead of the
    ears' midpoint, which no relabelling moves); for the legs, only
    labellings whose hips (the group's first pair) turn with the shoulders
    (the arms' first pair, decided first) within :data:`MAX_TWIST_DEG` seen
    from above.  Last, where the keypoint model mirrored the first view
    too, every view is relabelled (:func:`_unmirror`).

    Parameters
    ----------
    uv : (V, T, 33, 2) ndarray
    visibility : (V, T, 33) ndarray
    cameras : sequence of V CameraCalibration

    Returns
    -------
    uv, visibility : relabelled copies
    swapped : (V, T, G) ndarray of bool
        Where a view's group was relabelled.
    """
    uv = np.array(uv, float)
    vis = np.array(visibility, float)
    V, T = uv.shape[:2]
    swapped = np.zeros((V, T, len(SIDE_GROUPS)), bool)
    for v in range(1, V):
        pair = [cameras[0], cameras[v]]
        for g, pairs in enumerate(SIDE_GROUPS.values()):
            idx, alt = _group_labels(pairs)
            keep, v_keep = _group_error(
                np.stack([uv[0][:, idx], uv[v][:, idx]]), np.stack([vis[0][:, idx], vis[v][:, idx]]), pair
            )
            swap, v_swap = _group_error(
                np.stack([uv[0][:, idx], uv[v][:, alt]]), np.stack([vis[0][:, idx], vis[v][:, alt]]), pair
            )
            if g == 0:
                # Where reprojection cannot tell, the shoulders face where the head does.
                tie = np.abs(swap - keep) < SIDE_AMBIGUOUS_PX
                head, _ = _head_and_shoulders(uv[[0, v]], vis[[0, v]], pair)
                c_keep = _horizontal_cos(_forward(v_keep), head)
                c_swap = _horizontal_cos(_forward(v_swap), head)
                # ... and only where the two labellings turn the shoulders apart.
                apart = _horizontal_cos(v_keep, v_swap) < np.cos(np.radians(SIDE_APART_DEG))
                decided = tie & apart & np.isfinite(c_keep) & np.isfinite(c_swap)
                keep = np.where(decided, 1.0 - c_keep, keep)
                swap = np.where(decided, 1.0 - c_swap, swap)
                shoulders = np.where(_swap_frames(keep, swap)[:, None], v_swap, v_keep)
            else:
                # The hips turn with the shoulders (the arms group, decided first).
                limit = np.cos(np.radians(MAX_TWIST_DEG))
                keep = np.where(_horizontal_cos(v_keep, shoulders) < limit, 1e6, keep)
                swap = np.where(_horizontal_cos(v_swap, shoulders) < limit, 1e6, swap)
            frames = _swap_frames(keep, swap)
            _relabel(uv, vis, v, frames, idx, alt)
            swapped[v, :, g] = frames
    if V >= 2:
        _unmirror(uv, vis, cameras, swapped)
    return uv, vis, swapped


#: Cosine of the angle, seen from above, between the shoulders' forward and
#: the head's under which (the head turned more than 135° from the
#: shoulders, far past a neck's reach of about 80°) the body is mirrored.
MIRRORED_COS = -0.7


def _unmirror(uv, vis, cameras, swapped) -> None:
    """Swap left and right in every view where the triangulated body is mirrored, in place.

    Matching makes the views agree with the first view, so where the keypoint
    model mirrored the first view (a back view read as a front view) every
    view is mirrored alike, and the rays meet on a mirror image.  Its
    shoulders then face away from where the head looks (the nose ahead of
    the ears' midpoint, which no relabelling moves); its hips turn with its
    shoulders, so both groups are swapped, in every view.
    """
    head, shoulders = _head_and_shoulders(uv, vis, cameras, HEAD_MIN_M)
    cos = _horizontal_cos(_forward(shoulders), head)
    score = np.where(np.isfinite(cos), cos - MIRRORED_COS, 0.0)
    frames = median_filter(score, size=SIDE_MEDIAN_FRAMES, mode="nearest") < 0
    if not frames.any():
        return
    for g, pairs in enumerate(SIDE_GROUPS.values()):
        idx, alt = _group_labels(pairs)
        for v in range(uv.shape[0]):
            _relabel(uv, vis, v, frames, idx, alt)
            swapped[v, frames, g] = ~swapped[v, frames, g]


#: (J,) bool: the joints :func:`landmarks_to_joints` measures, those a
#: landmark is and the pelvis (the hips' midpoint).  The trunk's inner joints
#: and the head never are: the fit places them from the shoulders, hips,
#: nose and ears.
MEASURED_JOINTS = np.array([name == "pelvis" or name in BLAZEPOSE_TO_JOINT.values() for name in JOINTS])


def landmarks_to_joints(points, confidence) -> tuple[np.ndarray, np.ndarray, dict]:
    """Our joints and the model's virtual points from 33 triangulated BlazePose landmarks.

    Parameters
    ----------
    points : (T, 33, 3) ndarray
    confidence : (T, 33) ndarray

    Returns
    -------
    joints : (T, J, 3) ndarray
        Landmark joints (shoulders … toes); the pelvis at the hips' midpoint
        (where the model puts it); the trunk and head NaN (the fit places
        them from the shoulders, hips, nose and ears).
    conf : (T, J) ndarray
    virtual : dict
        ``name -> ((T, 3) positions, (T,) confidence)`` for nose, ears, heels.
    """
    points = np.asarray(points, float)
    confidence = np.asarray(confidence, float)
    T = points.shape[0]
    joints = np.full((T, len(JOINTS), 3), np.nan)
    conf = np.zeros((T, len(JOINTS)))
    for lm, name in BLAZEPOSE_TO_JOINT.items():
        j = joint_index(name)
        joints[:, j], conf[:, j] = points[:, lm], confidence[:, lm]
    rh, lh = joint_index("right_hip"), joint_index("left_hip")
    joints[:, 0] = 0.5 * (joints[:, rh] + joints[:, lh])
    conf[:, 0] = np.minimum(conf[:, rh], conf[:, lh])
    conf = np.where(np.all(np.isfinite(joints), axis=-1), conf, 0.0)
    virtual = {name: (points[:, i], confidence[:, i]) for name, i in _VIRTUAL.items()}
    return joints, conf, virtual


def find_offset(reference, other, max_lag: int) -> int:
    """Frames by which `other` starts later than `reference`, from their motion.

    Parameters
    ----------
    reference, other : (T, N, 2) ndarray
        Keypoint pixels of two views (NaN where unseen).
    max_lag : int
        Largest lag searched, frames.

    Returns
    -------
    int
        The lag maximising the cross-correlation of the two views' vertical
        image velocities, landmark by landmark (cameras stand level, so a
        rise or fall looks alike from every side, while sideways motion
        does not), each view scaled by its own spread (the views see the
        movement at different sizes), summed over the overlap (so a short
        overlap needs the stronger evidence); ``other[i]`` shows the moment
        of ``reference[i + lag]``.  On a short clip with little movement it
        can be off by several frames (docs/benchmarks/multiview.md).
    """

    def velocity(xy):
        d = np.diff(np.asarray(xy, float)[..., 1], axis=0)
        d = np.where(np.isfinite(d), d, 0.0)
        return d / (d.std() + 1e-9)

    a, b = velocity(reference), velocity(other)
    best, best_r = 0, -np.inf
    for lag in range(-max_lag, max_lag + 1):
        x = a[lag:] if lag >= 0 else a[: a.shape[0] + lag]
        y = b[: b.shape[0] - lag] if lag >= 0 else b[-lag:]
        n = min(x.shape[0], y.shape[0])
        if n < 10:
            continue
        r = float(np.sum(x[:n] * y[:n]))
        if r > best_r:
            best, best_r = lag, r
    return best
