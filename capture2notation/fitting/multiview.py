"""The body's motion from the keypoints of two or more calibrated cameras.

Left and right made to agree across the views
(:func:`~.triangulate.match_sides`), a visibility-weighted triangulation
(:func:`~.triangulate.triangulate`), the floor from where the triangulated
feet rest (:func:`~.motion.floor_height`), then :func:`~.fit3d.fit_points3d`
to the triangulated joints, refined against every view's own keypoints.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from types import SimpleNamespace

import numpy as np

from ..body import JOINTS
from ..body.skeleton import JOINT_TO_BLAZEPOSE
from ..errors import C2NError, FittingError
from .camera import Camera
from .fit3d import fit_points3d
from .motion import floor_height
from .result import FitResult, labelled_confidence
from .triangulate import (
    LANDMARK_TARGETS,
    MEASURED_JOINTS,
    landmarks_to_joints,
    match_sides,
    triangulate,
    undistorted_pixels,
)

__all__ = ["FILL_CONTEXT_S", "MONO_WEIGHT", "fill_from_view", "fill_view", "fill_windows", "filled", "fit_views"]

log = logging.getLogger(__name__)

#: Weight of a joint taken from one view's monocular fit where the other
#: views do not see it: depth from one view is the weak direction, so the
#: fit's priors and the triangulated neighbours count for more.
MONO_WEIGHT = 0.3

#: Seconds of motion either side of the frames a monocular fit fills: its
#: smoothness and depth priors need the motion around them.  Two cameras
#: rarely both lose a joint (BlazePose places every landmark in every view:
#: a minute of two-camera video had 4 such frames), so the fit covers those
#: stretches only, not the clip.
FILL_CONTEXT_S = 1.0

#: (J,) BlazePose landmark of each joint, -1 for joints no landmark is.
_LANDMARK_OF = np.array([JOINT_TO_BLAZEPOSE.get(name, -1) for name in JOINTS])


def fill_view(visibility, missing) -> int:
    """The view whose keypoints see the `missing` joints best (summed visibility).

    Parameters
    ----------
    visibility : sequence of V (T, 33) ndarrays
        Each view's landmark visibilities (NaN counts as 0).
    missing : (T, J) ndarray of bool
        Joints no two views saw.
    """
    has = _LANDMARK_OF >= 0
    seen = [float(np.sum(missing[:, has] * np.nan_to_num(np.asarray(v)[:, _LANDMARK_OF[has]]))) for v in visibility]
    return int(np.argmax(seen))


def fill_windows(missing, fps: float) -> list[slice]:
    """The frame ranges a monocular fit must cover to fill `missing`.

    Each run of frames with a missing joint, widened by
    :data:`FILL_CONTEXT_S` each side (within the clip); overlapping ranges
    merged.

    Parameters
    ----------
    missing : (T, J) ndarray of bool
    fps : float

    Returns
    -------
    list of slice
        In frame order, disjoint.
    """
    need = np.asarray(missing, bool).any(axis=1)
    T = need.size
    pad = int(np.ceil(FILL_CONTEXT_S * fps))
    edges = np.flatnonzero(np.diff(np.r_[0, need.astype(int), 0]))
    out: list[slice] = []
    for a, b in zip(edges[::2], edges[1::2]):
        lo, hi = max(0, int(a) - pad), min(T, int(b) + pad)
        if out and lo <= out[-1].stop:
            out[-1] = slice(out[-1].start, hi)
        else:
            out.append(slice(lo, hi))
    return out


def filled(joints, jconf, missing, mono: FitResult, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """`joints` and `jconf` (T, J) with the `missing` joints taken from a monocular fit.

    `mono` is in the cameras' world; `floor` (metres) is subtracted from it as
    from the triangulated joints.  One view's fit knows the body's shape far
    better than where it stands along the line of sight (its depth comes
    from the body's size: 5-15 cm off), so each frame of it is first moved
    onto the triangulated joints: by the median offset of the joints both
    have (none: left where it is).  A filled joint's confidence is
    :data:`MONO_WEIGHT` × the monocular fit's.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        Triangulated joints, metres, the floor at z = 0 (NaN where missing).
    jconf : (T, J) ndarray
    missing : (T, J) ndarray of bool
        Joints to fill.
    mono : FitResult
        Or any object with its ``joints`` (T, J, 3) and ``confidence``
        (T, J): NaN and 0 where it was not fitted.
    floor : float
        Metres.

    Returns
    -------
    joints : (T, J, 3) ndarray
    jconf : (T, J) ndarray
    """
    joints = np.asarray(joints, float)
    mj = np.asarray(mono.joints, float) - np.array([0.0, 0.0, floor])
    both = (np.asarray(jconf) > 0) & np.all(np.isfinite(mj), axis=-1) & np.all(np.isfinite(joints), axis=-1)
    offset = np.zeros((len(mj), 3))
    for t in np.flatnonzero(both.any(axis=1)):
        offset[t] = np.median(joints[t, both[t]] - mj[t, both[t]], axis=0)
    mj = mj + offset[:, None]
    fill = missing & np.all(np.isfinite(mj), axis=-1)
    joints = np.where(fill[..., None], mj, joints)
    return joints, np.where(fill, MONO_WEIGHT * np.asarray(mono.confidence), jconf)


def fill_from_view(joints, jconf, missing, floor: float, visibility, fps: float, fit_window: Callable):
    """Fill the `missing` joints from one view's monocular fit over the frames that need it.

    The view is :func:`fill_view`'s; it is fitted over each of
    :func:`fill_windows`'s ranges (no more: two cameras rarely both lose a
    joint) and placed on the triangulated joints by :func:`filled`.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        Triangulated joints, metres, the floor at z = 0 (NaN where missing).
    jconf : (T, J) ndarray
    missing : (T, J) ndarray of bool
    floor : float
        Metres subtracted from the triangulated joints (the fit is in the cameras' world).
    visibility : sequence of V (T, 33) ndarrays
        Each view's landmark visibilities.
    fps : float
    fit_window : callable
        ``fit_window(view, frames) -> FitResult`` (or any object with
        ``joints`` (n, J, 3) and ``confidence`` (n, J)): that view's
        monocular fit of the frames of the slice `frames`, in the cameras' world.

    Returns
    -------
    view : int
        The view used.
    joints : (T, J, 3) ndarray
    jconf : (T, J) ndarray
    """
    view = fill_view(visibility, missing)
    # NaN and 0 outside the windows: filled() leaves those frames as they are.
    mono = SimpleNamespace(joints=np.full(np.shape(joints), np.nan), confidence=np.zeros(np.shape(jconf)))
    for w in fill_windows(missing, fps):
        fit = fit_window(view, w)
        mono.joints[w], mono.confidence[w] = fit.joints, labelled_confidence(fit)
    return (view, *filled(joints, jconf, missing, mono, floor))


def fit_views(
    uv,
    visibility,
    cameras,
    fps: float,
    times=None,
    fill: Callable | None = None,
) -> tuple[FitResult, float]:
    """Fit the body to 33 BlazePose landmarks seen by calibrated cameras.

    Parameters
    ----------
    uv : (V, T, 33, 2) ndarray
        Pixels per view (lens distortion included, as the camera saw them);
        NaN where a view has no keypoint.
    visibility : (V, T, 33) ndarray
        In [0, 1]: each view's weight for each keypoint.
    cameras : sequence of V CameraCalibration
    fps : float
    times : (T,) ndarray, optional
        Seconds; default ``arange(T) / fps``.
    fill : callable, optional
        ``fill(joints, conf, missing, floor) -> (joints, conf)`` supplies the
        landmark joints no two views saw (``missing``, (T, J) bool), in the
        floor-shifted world, e.g. from one view's monocular fit
        (:func:`fill_view`, :func:`filled`); without it
        they are left to the fit's skeleton (confidence 0).  The trunk and
        head are never filled: a guess of them would pull the fit's spine.

    Returns
    -------
    motion : FitResult
        In the cameras' world with the floor moved to z = 0.
    floor : float
        The floor's height in the cameras' world, metres.

    Raises
    ------
    FittingError
        No joint seen by two cameras at once, or no floor in the data.
    """
    uv = np.asarray(uv, float)
    vis = np.asarray(visibility, float)
    uv, vis, swapped = match_sides(uv, vis, cameras)
    if swapped.any():
        log.info("capture: left/right relabelled in %.0f %% of view-frames", 100 * swapped.any(-1).mean())
    points, conf, _used = triangulate(uv, vis, cameras)
    joints, jconf, virtual = landmarks_to_joints(points, conf)
    if not np.any(jconf > 0):
        raise FittingError("no joint was seen by two cameras at once (no person, or wrong calibration?)")
    # DESIGN.md: the floor comes from where the triangulated feet rest (a
    # monocular fill is too loose in depth to set it), not from the
    # calibration's zero (BlazePose's foot points sit above the sole).
    try:
        floor = floor_height(joints, jconf)
    except C2NError as exc:
        raise FittingError(str(exc)) from None
    joints[..., 2] -= floor
    virtual = {k: (p - np.array([0.0, 0.0, floor]), c) for k, (p, c) in virtual.items()}
    # Only joints a landmark measures can be missing: filling the spine and
    # head from one view's fit would pull them to that fit's guess (with
    # exact keypoints of random scores: the waist 5 cm off, the chest
    # leaning 6° forward on average).
    missing = (jconf == 0) & MEASURED_JOINTS[None, :]
    if fill is not None and missing.any():
        joints, jconf = fill(joints, jconf, missing, floor)
    T = uv.shape[1]
    times = np.arange(T) / fps if times is None else np.asarray(times, float)
    # The cameras' own keypoints judge the triangulated points: a limb one
    # view sees well keeps to that view (fit3d's module docstring).
    targets = np.array([i for i, _ in LANDMARK_TARGETS])
    names = [n for _, n in LANDMARK_TARGETS]
    views = [
        (
            Camera(np.asarray(c.K), np.asarray(c.R), np.asarray(c.t) + floor * np.asarray(c.R)[:, 2], c.image_size),
            undistorted_pixels(uv[v][:, targets], c),
            vis[v][:, targets],
            names,
        )
        for v, c in enumerate(cameras)
    ]
    # The floor is now z = 0: the fit holds the lowest foot there, as the
    # one-view fit does through a known camera (triangulated feet jitter by
    # centimetres, about the quantiser's 3-cm support threshold).
    motion = fit_points3d(joints, jconf, fps, times=times, virtual=virtual, floor=True, views=views)
    return motion, float(floor)
