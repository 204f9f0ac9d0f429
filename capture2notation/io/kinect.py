"""Kinect v2 skeleton CSV, as recorded by Microsoft's LabanotationSuite KinectReader.

Format (no header; one body per row, comma-separated)::

    timestamp, x0, y0, z0, s0, x1, y1, z1, s1, ..., x24, y24, z24, s24

* ``timestamp``: the Kinect's relative time in 100-ns ticks (LabanEditor's
  ``kinect.py`` also accepts milliseconds for small values; so do we: a
  clip whose timestamps never exceed 10⁷ is read as milliseconds);
* 25 joints in the Kinect SDK v2 ``JointType`` order (:data:`KINECT_JOINTS`):
  position in metres, camera space (x to the sensor's left, y up, z away
  from the sensor), then the tracking state: 2 tracked, 1 inferred,
  0 not tracked.

Rows go onto a uniform frame grid at the median frame interval; dropped
frames become NaN rows with zero confidence (never interpolated).  Positions
are turned into our world frame (z up; the performer, facing the sensor,
then faces +y with their right on +x), see :func:`camera_to_world`.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ..atomic import write_text
from ..body import JOINTS, joint_index
from ..errors import MotionFileError

__all__ = [
    "KINECT_JOINTS",
    "KINECT_TO_JOINT",
    "TRACKING_CONFIDENCE",
    "camera_to_world",
    "kinect_points",
    "read_kinect_csv",
    "world_to_camera",
    "write_kinect_csv",
]

log = logging.getLogger(__name__)

#: Kinect SDK v2 ``JointType`` order (LabanEditor's names in comments).
KINECT_JOINTS: tuple[str, ...] = (
    "SpineBase",
    "SpineMid",
    "Neck",
    "Head",  # spineB spineM neck head
    "ShoulderLeft",
    "ElbowLeft",
    "WristLeft",
    "HandLeft",
    "ShoulderRight",
    "ElbowRight",
    "WristRight",
    "HandRight",
    "HipLeft",
    "KneeLeft",
    "AnkleLeft",
    "FootLeft",
    "HipRight",
    "KneeRight",
    "AnkleRight",
    "FootRight",
    "SpineShoulder",
    "HandTipLeft",
    "ThumbLeft",
    "HandTipRight",
    "ThumbRight",
)

#: Kinect joint -> (our joint or virtual point, confidence factor).  The
#: Kinect's SpineShoulder is the shoulder midpoint, i.e. our neck; its Head is
#: the centre of the head; SpineMid lies between our waist and chest and is
#: trusted less.  Neck, hands and thumbs have no counterpart.
KINECT_TO_JOINT: dict[str, tuple[str, float]] = {
    "SpineBase": ("pelvis", 1.0),
    "SpineMid": ("waist", 0.3),
    "SpineShoulder": ("neck", 1.0),
    "Head": ("head_centre", 1.0),
    **{
        f"{k}{s.title()}": (f"{s}_{o}", 1.0)
        for s in ("left", "right")
        for k, o in (
            ("Shoulder", "shoulder"),
            ("Elbow", "elbow"),
            ("Wrist", "wrist"),
            ("HandTip", "hand_tip"),
            ("Hip", "hip"),
            ("Knee", "knee"),
            ("Ankle", "ankle"),
            ("Foot", "toe"),
        )
    },
}

#: Confidence of each tracking state (0 not tracked, 1 inferred, 2 tracked).
TRACKING_CONFIDENCE = np.array([0.0, 0.3, 1.0])

_N = len(KINECT_JOINTS)
_TICKS_PER_SECOND = 1e7
_TICKS_THRESHOLD = 1e7  # LabanEditor: larger timestamps are Kinect ticks


def read_kinect_csv(path):
    """Read a Kinect v2 skeleton CSV.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    times : (T,) ndarray
        Seconds from the first row, on a uniform grid.
    positions : (T, 25, 3) ndarray
        Camera-space metres; NaN for untracked joints and dropped frames.
    confidence : (T, 25) ndarray
        From the tracking state (:data:`TRACKING_CONFIDENCE`).
    fps : float
        From the median interval between rows.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise MotionFileError(f"{path}: cannot read Kinect CSV: {exc.strerror}") from None
    stamps, rows = [], []
    for ln, line in enumerate(lines, 1):
        if not line.strip():
            continue
        fields = [f.strip() for f in line.split(",")]
        if fields and fields[-1] == "":
            fields = fields[:-1]  # trailing comma
        if len(fields) < 1 + 4 * _N:
            raise MotionFileError(
                f"{path}:{ln}: expected a timestamp and 25 joints x (x, y, z, state) = {1 + 4 * _N} fields, got {len(fields)}"
            )
        try:
            vals = np.array([float(f) for f in fields[: 1 + 4 * _N]])
        except ValueError:
            bad = next(f for f in fields if not _is_float(f))
            raise MotionFileError(
                f"{path}:{ln}: expected numbers, found {bad!r} (the file has no header line)"
            ) from None
        state = vals[1:].reshape(_N, 4)[:, 3]
        if np.any(~np.isin(state, (0, 1, 2))):
            j = int(np.nonzero(~np.isin(state, (0, 1, 2)))[0][0])
            raise MotionFileError(
                f"{path}:{ln}: tracking state of {KINECT_JOINTS[j]} is {float(state[j]):g}, expected 0, 1 or 2"
            )
        stamps.append(vals[0])
        rows.append(vals[1:].reshape(_N, 4))
    if not rows:
        raise MotionFileError(f"{path}: no skeleton rows")
    ticks = np.asarray(stamps)
    data = np.stack(rows)
    scale = 1.0 / _TICKS_PER_SECOND if ticks.max() > _TICKS_THRESHOLD else 1e-3
    t = (ticks - ticks[0]) * scale
    if np.any(np.diff(t) < 0):
        k = int(np.nonzero(np.diff(t) < 0)[0][0])
        raise MotionFileError(f"{path}: timestamps go backwards at data row {k + 2}")
    dt = np.diff(t)
    dt = dt[dt > 0]
    fps = 1.0 / float(np.median(dt)) if dt.size else 30.0
    idx = np.round(t * fps).astype(int)
    T = int(idx[-1]) + 1
    pos = np.full((T, _N, 3), np.nan)
    conf = np.zeros((T, _N))
    state = data[..., 3].astype(int)
    c = TRACKING_CONFIDENCE[state]
    xyz = np.where((state > 0)[..., None], data[..., :3], np.nan)
    pos[idx], conf[idx] = xyz, c  # a repeated grid slot keeps the later row
    if len(rows) < T:
        log.info("%s: %d dropped frames left as NaN", path, T - len(np.unique(idx)))
    return np.arange(T) / fps, pos, conf, fps


def _is_float(s: str) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False


def camera_to_world(points: np.ndarray) -> np.ndarray:
    """Kinect camera space (x sensor-left, y up, z away) to z-up axes.

    A performer facing the sensor faces −z; their right is the sensor's
    left (+x).  So world ``(x, y, z) = (x_k, −z_k, y_k)``: right-handed, z up,
    the performer facing +y.
    """
    p = np.asarray(points, float)
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def world_to_camera(points: np.ndarray) -> np.ndarray:
    """Inverse of :func:`camera_to_world`."""
    p = np.asarray(points, float)
    return np.stack([p[..., 0], p[..., 2], -p[..., 1]], axis=-1)


def kinect_points(positions: np.ndarray, confidence: np.ndarray):
    """Map Kinect joints onto ours (world axes, not yet floored).

    Returns
    -------
    points : (T, J, 3) ndarray
    conf : (T, J) ndarray
    head_centre : (T, 3) ndarray
    head_conf : (T,) ndarray
    """
    world = camera_to_world(positions)
    T = world.shape[0]
    points = np.full((T, len(JOINTS), 3), np.nan)
    conf = np.zeros((T, len(JOINTS)))
    head, head_c = None, None
    for k, (ours, w) in KINECT_TO_JOINT.items():
        i = KINECT_JOINTS.index(k)
        if ours == "head_centre":
            head, head_c = world[:, i], confidence[:, i] * w
            continue
        j = joint_index(ours)
        points[:, j] = world[:, i]
        conf[:, j] = confidence[:, i] * w
    return points, conf, head, head_c


def write_kinect_csv(path, times: np.ndarray, positions: np.ndarray, states: np.ndarray) -> Path:
    """Write a Kinect v2 skeleton CSV (for tests and exchange), atomically.

    Parameters
    ----------
    times : (T,) ndarray
        Seconds; written as 100-ns ticks offset by 10⁸ (so they read back as ticks).
    positions : (T, 25, 3) ndarray
        Camera-space metres, :data:`KINECT_JOINTS` order.
    states : (T, 25) ndarray of int
        Tracking states 0/1/2.
    """
    times = np.asarray(times, float)
    positions = np.asarray(positions, float)
    states = np.asarray(states).astype(int)
    if positions.shape != (len(times), _N, 3) or states.shape != (len(times), _N):
        raise MotionFileError(
            f"write_kinect_csv needs positions (T, 25, 3) and states (T, 25); got {positions.shape}, {states.shape}"
        )
    ticks = np.round(times * _TICKS_PER_SECOND).astype(np.int64) + 10**8
    out = []
    for t, p, s in zip(ticks, np.nan_to_num(positions), states):
        cells = [str(int(t))]
        for j in range(_N):
            cells += [f"{p[j, 0]:.6f}", f"{p[j, 1]:.6f}", f"{p[j, 2]:.6f}", str(int(s[j]))]
        out.append(",".join(cells))
    return write_text(path, "\n".join(out) + "\n")
