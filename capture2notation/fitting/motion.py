"""Motion from files: BVH, Kinect v2 CSV and truth sidecars, all in one form.

Every source lands in :class:`MotionData` — the fields of a
:class:`~capture2notation.fitting.FitResult` plus ``source`` — in our world
frame (z up, metres, floor z = 0, the performer starting at the origin and
facing +y).  Sources that only give joint positions in their own skeleton
(BVH, Kinect) are mapped onto our joints by name and then fitted with
:func:`~capture2notation.fitting.fit_points3d`, so ``joints`` and ``angles``
are consistent (per-clip segment lengths in ``offsets``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..body import JOINTS, Body, joint_index
from ..errors import MotionFileError
from ..io.bvh import parse_bvh, read_bvh_points, read_own_bvh
from ..io.kinect import kinect_points, read_kinect_csv
from .fit3d import fit_points3d
from .ground import FloorFit, fit_floor, level_points
from .model import PoseModel
from .result import FitResult

__all__ = [
    "MEASURED_FOR_LABELS",
    "MotionData",
    "floor_height",
    "joints_for_labels",
    "motion_from_truth",
    "normalise_world",
    "read_motion",
]


@dataclass(frozen=True, eq=False)
class MotionData(FitResult):
    """A motion read from a file (fields of :class:`FitResult`).

    Attributes
    ----------
    source : str
        ``"bvh"``, ``"kinect"`` or ``"truth"``.
    measured : (T, J, 3) ndarray or None
        Kinect: the file's own joint positions on our joint names, in the
        fit's world frame (NaN where the file has none or lost track).  The
        retargeted fit keeps our bone lengths and joint limits and moves a
        hanging upper arm by 20-30°; labels are read from these.
    """

    source: str = ""
    measured: np.ndarray | None = None


#: Joints whose measured positions (Kinect) are read instead of the fit's:
#: the body cross (shoulders, mid-spine) and the arms.  Legs and feet keep
#: the fit (its floor, foot pitch and bone lengths are what the supports are
#: read from), and so does the head (the sensor's Head point sits at the
#: skull's centre, not where our head joint is).
MEASURED_FOR_LABELS = (
    "waist",
    "right_shoulder",
    "left_shoulder",
    "right_elbow",
    "left_elbow",
    "right_wrist",
    "left_wrist",
)


def joints_for_labels(motion: MotionData) -> np.ndarray:
    """(T, J, 3) the joints a motion file is written from: the fit, with
    :data:`MEASURED_FOR_LABELS` taken from the file where it measured them.

    LabanotationSuite reads a Kinect capture's arms from the sensor's own
    positions; so do we (on its sample, 100 % of its per-frame arm labels
    in the body key, against 54-85 % from the retargeted fit).
    """
    joints = np.asarray(motion.joints, float)
    if motion.measured is None:
        return joints
    out = joints.copy()
    idx = [joint_index(n) for n in MEASURED_FOR_LABELS]
    m = np.asarray(motion.measured, float)[:, idx]
    out[:, idx] = np.where(np.isfinite(m), m, out[:, idx])
    return out


def read_motion(
    path, joint_map: dict | None = None, body: Body | None = None, floor: float | None = None
) -> MotionData:
    """Read a motion file, dispatching on its extension.

    Parameters
    ----------
    path : str or Path
        ``.bvh`` (any common skeleton), ``.csv`` (Kinect v2 skeleton CSV,
        LabanotationSuite format) or ``.npz`` (truth sidecar).
    joint_map : dict, optional
        BVH only: source joint name -> our joint name, overriding the name table.
    body : Body, optional
        Proportions for segments the source does not measure (default ``Body()``).
    floor : float, optional
        The floor's height, metres, in the file's coordinates once read (z
        up, the reader's units): when the user knows it.  By default it is
        fitted to the feet (:func:`normalise_world`).

    Returns
    -------
    MotionData
    """
    path = Path(path)
    if not path.is_file():
        raise MotionFileError(f"{path}: no such motion file")
    ext = path.suffix.lower()
    if ext == ".bvh":
        skel = parse_bvh(path)
        own = None if joint_map else read_own_bvh(skel)
        if own is not None:  # our skeleton: angles are exact, already in our world frame
            return _own_motion(skel.fps, *own)
        points, conf, head, fps = read_bvh_points(skel, joint_map, where=path)
        head_c = None if head is None else np.ones(len(head))
        return _fit(points, conf, head, head_c, fps, None, body, "bvh", floor=floor)
    if ext == ".csv":
        times, pos, kconf, fps = read_kinect_csv(path)
        points, conf, head, head_c = kinect_points(pos, kconf)
        if not np.any(conf > 0):
            raise MotionFileError(f"{path}: no tracked joints in any row")
        return _fit(points, conf, head, head_c, fps, times, body, "kinect", keep_points=True, floor=floor)
    if ext == ".npz":
        return motion_from_truth(path)
    raise MotionFileError(f"{path}: unknown motion file type {ext!r}; expected .bvh, .csv (Kinect v2) or .npz (truth)")


def _own_motion(fps, angles, root, offsets) -> MotionData:
    model = PoseModel(Body(), offsets)
    joints = model.forward(model.params(angles, root))[:, : len(JOINTS)]
    T = angles.shape[0]
    return MotionData(
        fps=fps,
        times=np.arange(T) / fps,
        joints=joints,
        angles=angles,
        root=root,
        confidence=np.all(np.isfinite(joints), axis=-1).astype(float),
        offsets=offsets,
        source="bvh",
    )


def _fit(
    points, conf, head, head_c, fps, times, body, source, keep_points: bool = False, floor: float | None = None
) -> MotionData:
    extra = [] if head is None else [head]
    points, extra = normalise_world(points, conf, extra, fps=fps, floor=floor)
    virtual = {} if head is None else {"head_centre": (extra[0], head_c)}
    res = fit_points3d(points, conf, fps, body=body, times=times, virtual=virtual)
    measured = None
    if keep_points and points.shape == res.joints.shape:
        measured = np.where((np.asarray(conf) > 0)[..., None], points, np.nan)
    return MotionData(**{k: getattr(res, k) for k in res.__dataclass_fields__}, source=source, measured=measured)


def motion_from_truth(path) -> MotionData:
    """A truth sidecar as :class:`MotionData` (confidence 1 wherever joints are finite)."""
    from ..io.truth import read_truth

    tr = read_truth(path)
    names = [str(n) for n in np.asarray(tr.joint_names).tolist()]
    J = len(JOINTS)
    T = tr.times.shape[0]
    order = []
    for name in JOINTS:
        if name not in names:
            raise MotionFileError(f"{path}: truth sidecar has no joint {name!r} (it has {', '.join(names)})")
        order.append(names.index(name))
    joints = np.asarray(tr.joints, float)[:, order]
    angles = np.asarray(tr.angles, float)[:, order]
    conf = np.all(np.isfinite(joints), axis=-1).astype(float)
    body = Body(float(tr.body_height))
    return MotionData(
        fps=float(tr.fps),
        times=np.asarray(tr.times, float),
        joints=joints,
        angles=angles,
        root=np.asarray(tr.root, float).reshape(T, 3),
        confidence=conf.reshape(T, J),
        offsets=np.array(body.offsets),
        source="truth",
    )


def floor_height(points: np.ndarray, confidence: np.ndarray) -> float:
    """Height of the floor under triangulated joints, metres: the 2nd percentile of each frame's lowest foot point.

    The multi-camera capture's floor (measured there against a median; motion
    files use the grounded fit of :func:`~.ground.fit_floor` instead).

    Parameters
    ----------
    points : (T, J, 3) ndarray
        Our joints, z up, metres (NaN where missing).
    confidence : (T, J) ndarray

    Raises
    ------
    MotionFileError
        No ankle or toe is ever measured.
    """
    points = np.asarray(points, float)
    ok = (np.asarray(confidence, float) > 0) & np.all(np.isfinite(points), axis=-1)
    feet = [joint_index(n) for n in ("right_ankle", "left_ankle", "right_toe", "left_toe")]
    rest = Body().rest
    fz = np.where(ok[:, feet], points[:, feet, 2] - rest[feet, 2], np.nan)
    if not np.any(np.isfinite(fz)):
        raise MotionFileError("no foot (ankle or toe) is ever tracked: cannot find the floor")
    return float(
        np.nanpercentile(np.nanmin(np.where(np.isfinite(fz), fz, np.inf), axis=1)[np.any(np.isfinite(fz), axis=1)], 2)
    )


def normalise_world(points: np.ndarray, confidence: np.ndarray, extra=(), fps: float | None = None, floor=None):
    """Floor at z = 0, start at the origin, initially facing +y.

    Parameters
    ----------
    points : (T, J, 3) ndarray
        Our joints, z up, metres (NaN where missing).
    confidence : (T, J) ndarray
    extra : sequence of (T, 3) ndarray
        Other points to move with the body.
    fps : float, optional
        Frames per second: with it the floor may drift with time (inertial
        mocap); without, one tilted plane.
    floor : float, optional
        The floor's height in the file's own (z-up, metre) coordinates, when
        the user knows it (``c2n capture --floor``); found from the feet
        otherwise.

    Returns
    -------
    points : (T, J, 3) ndarray
    extra : list of (T, 3) ndarray

    Notes
    -----
    The floor is fitted to the lowest foot point of every frame
    (:func:`~capture2notation.fitting.ground.fit_floor`: a tilt for a
    pitched sensor, a height that may drift) and levelled to z = 0; the
    facing is the horizontal right-hip − left-hip direction (shoulders if
    the hips are missing), median over the first second of valid frames.
    """
    points = np.asarray(points, float)
    conf = np.asarray(confidence, float)
    ok = (conf > 0) & np.all(np.isfinite(points), axis=-1)
    if floor is None:
        fit = fit_floor(points, ok, fps)
    else:
        fit = FloorFit(slope=np.zeros(2), height=np.full(len(points), float(floor)), drifts=False, ground_fraction=1.0)
    points = level_points(points, fit)
    extra = [level_points(np.asarray(e, float)[:, None], fit)[:, 0] for e in extra]
    right = None
    for a, b in (("right_hip", "left_hip"), ("right_shoulder", "left_shoulder")):
        ia, ib = joint_index(a), joint_index(b)
        both = np.nonzero(ok[:, ia] & ok[:, ib])[0]
        if both.size:
            first = both[: max(1, min(both.size, 30))]
            d = np.median(points[first, ia] - points[first, ib], axis=0)
            if np.hypot(d[0], d[1]) > 1e-6:
                right = d
                break
    if right is None:
        raise MotionFileError("neither the hips nor the shoulders are ever tracked: cannot find the facing")
    yaw = np.arctan2(right[1], right[0])  # rotate by -yaw so right -> +x
    c, s = np.cos(-yaw), np.sin(-yaw)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    pel = joint_index("pelvis")
    start_frames = np.nonzero(ok[:, pel])[0]
    centre = points[start_frames[0], pel] if start_frames.size else np.nanmean(points[0], axis=0)
    shift = np.array([centre[0], centre[1], 0.0])

    def move(p):
        return (np.asarray(p, float) - shift) @ Rz.T

    return move(points), [move(e) for e in extra]
