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
from .limits import MAX_DURATION_S, MAX_FRAMES, check_duration

__all__ = [
    "KINECT_JOINTS",
    "KINECT_MAX_RANGE_M",
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


#: Metres: the farthest a Kinect v2 coordinate can be (its depth sensor sees
#: to about 8 m, 4.5 m in its specification); a larger value is corrupt.
KINECT_MAX_RANGE_M = 10.0


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
        Camera-space metres; NaN for untracked joints, dropped frames and
        coordinates that are not finite or beyond :data:`KINECT_MAX_RANGE_M`.
    confidence : (T, 25) ndarray
        From the tracking state (:data:`TRACKING_CONFIDENCE`); 0 where the position is NaN.
    fps : float
        From the median interval between rows.

    Raises
    ------
    MotionFileError
        A malformed row, a timestamp that is not finite or goes backwards, or
        a clip outside :mod:`capture2notation.io.limits` (rate, length);
        the message names the line and the value.
    """
    path = Path(path)
    stamps: list[float] = []
    rows: list[np.ndarray] = []
    lines_of: list[int] = []
    try:
        with open(path, "rb") as fh:
            for ln, raw in enumerate(fh, 1):
                line = raw.decode("utf-8", errors="replace")
                if not line.strip():
                    continue
                if len(rows) >= MAX_FRAMES:
                    raise MotionFileError(f"{path}:{ln}: more than {MAX_FRAMES} rows; longer than any dance this reads")
                ts, row = _parse_row(line, path, ln)
                stamps.append(ts)
                rows.append(row)
                lines_of.append(ln)
    except OSError as exc:
        raise MotionFileError(f"{path}: cannot read Kinect CSV: {exc.strerror}") from None
    if not rows:
        raise MotionFileError(f"{path}: no skeleton rows")
    ticks = np.asarray(stamps)
    data = np.stack(rows)
    back = np.nonzero(np.diff(ticks) < 0)[0]
    if back.size:
        k = int(back[0])
        raise MotionFileError(
            f"{path}:{lines_of[k + 1]}: timestamp {ticks[k + 1]:.15g} is earlier than the "
            f"{ticks[k]:.15g} of line {lines_of[k]}; rows must be in time order"
        )
    scale = 1.0 / _TICKS_PER_SECOND if ticks.max() > _TICKS_THRESHOLD else 1e-3
    t = (ticks - ticks[0]) * scale
    if t[-1] > MAX_DURATION_S:
        # Name the row where the clip first runs past the limit.
        k = int(np.argmax(t > MAX_DURATION_S))
        raise MotionFileError(
            f"{path}:{lines_of[k]}: timestamp {ticks[k]:.15g} is {t[k]:.3g} s after the first row; "
            f"a clip can last at most {MAX_DURATION_S / 3600:g} h"
        )
    dt = np.diff(t)
    dt = dt[dt > 0]
    if not dt.size and len(rows) > 1:
        raise MotionFileError(
            f"{path}: all {len(rows)} rows have the timestamp {ticks[0]:.15g}; expected increasing times"
        )
    fps = 1.0 / float(np.median(dt)) if dt.size else 30.0
    idx = np.round(t * fps).astype(int)
    T = int(idx[-1]) + 1
    problem = check_duration(T, fps)
    if problem is not None:
        raise MotionFileError(f"{path}: the rows' timestamps give {problem}")
    pos = np.full((T, _N, 3), np.nan)
    conf = np.zeros((T, _N))
    state = data[..., 3].astype(int)
    c = TRACKING_CONFIDENCE[state]
    xyz = data[..., :3]
    good = (state > 0) & np.all(np.abs(xyz) <= KINECT_MAX_RANGE_M, axis=-1)
    corrupt = (state > 0) & ~good
    if corrupt.any():
        r, j = (int(v[0]) for v in np.nonzero(corrupt))
        log.warning(
            "%s:%d: %s is at %s: %d tracked positions are not finite or beyond %g m; read as not tracked",
            path,
            lines_of[r],
            KINECT_JOINTS[j],
            np.array2string(xyz[r, j], precision=4),
            int(corrupt.sum()),
            KINECT_MAX_RANGE_M,
        )
    pos[idx] = np.where(good[..., None], xyz, np.nan)  # a repeated grid slot keeps the later row
    conf[idx] = np.where(good, c, 0.0)
    if len(rows) < T:
        log.info("%s: %d dropped frames left as NaN", path, T - len(np.unique(idx)))
    return np.arange(T) / fps, pos, conf, fps


def _parse_row(line: str, path: Path, ln: int) -> tuple[float, np.ndarray]:
    """(timestamp, (25, 4) joints) of one CSV line."""
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
        raise MotionFileError(f"{path}:{ln}: expected numbers, found {bad!r} (the file has no header line)") from None
    if not np.isfinite(vals[0]):
        raise MotionFileError(f"{path}:{ln}: timestamp is {fields[0]!r}; expected a finite number")
    joints = vals[1:].reshape(_N, 4)
    state = joints[:, 3]
    if np.any(~np.isin(state, (0, 1, 2))):
        j = int(np.nonzero(~np.isin(state, (0, 1, 2)))[0][0])
        raise MotionFileError(
            f"{path}:{ln}: tracking state of {KINECT_JOINTS[j]} is {float(state[j]):g}, expected 0, 1 or 2"
        )
    return float(vals[0]), joints


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
