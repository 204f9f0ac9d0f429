"""The floor of a motion file, from its lowest foot points over time.

A motion file's floor is not where its numbers say: BVH files put their
origin anywhere (a root offset, a unit we guessed), a Kinect sensor is
tilted towards the floor so its "up" axis leans by its pitch, and inertial
mocap (Rokoko, Xsens) lets the root height drift by tens of centimetres in a
few seconds.  The evidence for the floor is the lowest foot point of each
frame: whenever a foot bears weight it rests there, and a dancer stands far
more than they fly.

The model (:func:`fit_floor`) is a plane ``z = a x + b y + c(t)``: a fixed
tilt ``(a, b)`` (the sensor's pitch and roll) and a height ``c(t)`` that may
drift slowly.  The tilt is fitted by asymmetric iteratively reweighted least
squares on the lowest foot points (points above the plane by more than
:data:`AIR_M` are feet in the air and lose their weight; points below keep
it), and kept only when the feet spread far enough on the floor to show it.
The height is a running low quantile (:data:`GROUND_QUANTILE`) of the
levelled lowest points over :data:`DRIFT_WINDOW_S` (longer than any flight
of a jump), kept constant unless it drifts by more than :data:`DRIFT_MIN_M`.

Without a time axis (``fps=None``: a video fit, whose feet scatter by
centimetres about the floor they stand on) a low quantile sits a fraction
of that scatter *below* the floor, and every standing foot floats above
it.  There the height is the mean of a two-part mixture fitted by EM
(:func:`ground_height`): grounded points normal about the floor, feet in
the air exponentially above it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body import Body, joint_index
from ..errors import MotionFileError

__all__ = [
    "AIR_M",
    "DRIFT_MIN_M",
    "DRIFT_WINDOW_S",
    "GROUND_QUANTILE",
    "MAX_TILT_DEG",
    "MIN_SPREAD_M",
    "MIN_TILT_DEG",
    "FloorFit",
    "fit_floor",
    "ground_height",
    "level_points",
    "running_quantile",
]

#: Foot joints whose lowest point (less its rest height) is the floor evidence.
FOOT_JOINTS = ("right_ankle", "left_ankle", "right_toe", "left_toe")
#: Metres above the fitted plane beyond which a lowest foot point is a foot in
#: the air (a jump, both feet off the floor): a little more than a relevé
#: lifts the toe joint (2-3 cm) plus mocap jitter.
AIR_M = 0.05
#: Quantile of the lowest foot points taken as the floor: the standing foot's
#: lowest point scatters about the floor with the capture's jitter, and the
#: rarer flights only lift points, so a low quantile sits at the floor
#: without following the few glitches below it (the 2nd percentile did).
GROUND_QUANTILE = 0.2
#: Seconds of the running window for a drifting floor height: longer than the
#: flight of any jump (< 1 s), short enough to follow inertial drift
#: (≈ 0.1 m/s at worst).
DRIFT_WINDOW_S = 2.0
#: Metres the running floor height must range over before it is taken to
#: drift (below: one constant height; the window's own scatter is ≈ 1 cm).
DRIFT_MIN_M = 0.03
#: Metres the feet must spread over the floor (5th-95th percentile, in the
#: direction of the tilt) before a tilt is fitted: a dancer standing in
#: place shows no tilt.
MIN_SPREAD_M = 0.5
#: Degrees of the largest tilt believed (a Kinect on a table pitches 0-30°
#: but its SDK already corrects most of it; more is a figure lying down).
MAX_TILT_DEG = 20.0
#: Degrees of the least tilt believed: a drifting height along the path
#: mimics 1-1.5° (a 25 cm drift under a 1.5 m walk), and so does the
#: body model's foot against a real one; below it the floor is level.
MIN_TILT_DEG = 2.0
#: Metres: least scatter of grounded foot points believed by
#: :func:`ground_height` (the body model's sole against a real one).
MIN_GROUND_SD_M = 0.005
#: Metres: the first guess of the mixture's height scale of feet in the air
#: (a step lifts a foot 5-15 cm); EM then fits it.
AIR_SCALE_M = 0.1
#: EM iterations of :func:`ground_height` (settles in 10-20 on video fits).
_EM_STEPS = 50
#: IRLS iterations of the tilt fit (converges in 3-5 on every fixture).
_IRLS_STEPS = 10
#: Rounds of tilt, then drift (two settle a drift of 25 cm under a 1.5 m walk).
_ALTERNATIONS = 3


@dataclass(frozen=True)
class FloorFit:
    """A fitted floor ``z = slope · (x, y) + height(t)``.

    Attributes
    ----------
    slope : (2,) ndarray
        dz/dx, dz/dy of the floor (0, 0 when level).
    height : (T,) ndarray
        Floor height below the origin at each frame, metres.
    drifts : bool
        True when the height varies over the clip (inertial drift).
    ground_fraction : float
        Fraction of frames whose lowest foot point lies within :data:`AIR_M`
        of the floor (the frames a foot may bear weight).
    """

    slope: np.ndarray
    height: np.ndarray
    drifts: bool
    ground_fraction: float

    @property
    def tilt_deg(self) -> float:
        """Angle between the floor and the horizontal, degrees."""
        return float(np.degrees(np.arctan(np.hypot(*self.slope))))


def _lowest_points(points: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Per frame, the lowest foot point less its rest height, ``(T, 3)`` (NaN where no foot)."""
    feet = [joint_index(n) for n in FOOT_JOINTS]
    rest = Body().rest[feet, 2]
    z = np.where(ok[:, feet], points[:, feet, 2] - rest[None, :], np.inf)
    k = np.argmin(z, axis=1)
    T = points.shape[0]
    low = points[np.arange(T), np.asarray(feet)[k]].copy()
    low[:, 2] = z[np.arange(T), k]
    low[~np.isfinite(low[:, 2])] = np.nan
    return low


def ground_height(z: np.ndarray) -> float:
    """The floor under lowest foot points ``z`` (metres, ``(N,)``, finite), by EM.

    A mixture: a fraction ``w`` of the points rest on the floor, ``N(c,
    σ)``; the others are feet in the air, ``c + Exp(λ)`` above it.  Started
    from the :data:`GROUND_QUANTILE` quantile; ``c`` is the grounded points'
    weighted mean, so a scatter of several centimetres about the floor
    (fitted feet) does not pull it down as a low quantile is.
    """
    z = np.asarray(z, float)
    c = float(np.quantile(z, GROUND_QUANTILE))
    sd = max(MIN_GROUND_SD_M, float(np.std(z[z <= np.quantile(z, 0.5)])))
    lam, w = AIR_SCALE_M, 0.8
    for _ in range(_EM_STEPS):
        pg = w * np.exp(-0.5 * ((z - c) / sd) ** 2) / (sd * np.sqrt(2 * np.pi))
        above = z > c
        pa = np.where(above, (1 - w) * np.exp(-np.where(above, z - c, 0.0) / lam) / lam, 0.0)
        r = pg / np.maximum(pg + pa, 1e-300)
        if r.sum() < 1.0:
            break
        c_new = float(np.sum(r * z) / r.sum())
        sd = max(MIN_GROUND_SD_M, float(np.sqrt(np.sum(r * (z - c_new) ** 2) / r.sum())))
        lam = max(MIN_GROUND_SD_M, float(np.sum((1 - r) * np.maximum(z - c_new, 0.0)) / max((1 - r).sum(), 1e-9)))
        w = float(np.clip(r.mean(), 0.05, 0.99))
        done = abs(c_new - c) < 1e-5
        c = c_new
        if done:
            break
    return c


def _fit_tilt(low: np.ndarray) -> np.ndarray:
    """Slope (a, b) of the floor through the lowest points, by asymmetric IRLS."""
    xy, z = low[:, :2], low[:, 2]
    A = np.column_stack([xy, np.ones(len(z))])
    c = np.quantile(z, GROUND_QUANTILE)
    coef = np.array([0.0, 0.0, c])
    w = np.ones(len(z))
    for _ in range(_IRLS_STEPS):
        r = z - A @ coef
        # Points well above the plane are feet in the air; below it, floor.
        w = np.where(r > AIR_M, 0.0, 1.0 / np.maximum(1.0, np.abs(r) / (AIR_M / 2)))
        if w.sum() < 3:
            return np.zeros(2)
        sw = np.sqrt(w)
        coef = np.linalg.lstsq(A * sw[:, None], z * sw, rcond=None)[0]
    slope = coef[:2]
    g = xy[w > 0]
    d = slope / (np.hypot(*slope) or 1.0)
    along = g @ d
    spread = np.subtract(*np.percentile(along, [95, 5])) if along.size else 0.0
    tilt = np.degrees(np.arctan(np.hypot(*slope)))
    if spread < MIN_SPREAD_M or not MIN_TILT_DEG <= tilt <= MAX_TILT_DEG:
        return np.zeros(2)
    return slope


def running_quantile(x: np.ndarray, width: int, q: float) -> np.ndarray:
    """Running `q` quantile of `x` over `width` frames (NaN ignored, edges shrink)."""
    T = len(x)
    h = width // 2
    out = np.full(T, np.nan)
    # A strided step keeps this O(T · width / step) on long files; the
    # result is then interpolated, the height drifting slowly anyway.
    step = max(1, width // 20)
    idx = np.arange(0, T, step)
    vals = np.array([np.nanquantile(x[max(0, i - h) : i + h + 1], q) for i in idx])
    out[:] = np.interp(np.arange(T), idx, vals)
    return out


def fit_floor(points: np.ndarray, ok: np.ndarray, fps: float | None, tilt: bool = True) -> FloorFit:
    """Fit the floor under a motion from its lowest foot points.

    Parameters
    ----------
    points : (T, J, 3) ndarray
        Our joints, z up, metres (NaN where missing).
    ok : (T, J) ndarray of bool
        Joints tracked.
    fps : float or None
        Frames per second (for the drift window); None fits one constant
        height (no time axis to drift along).
    tilt : bool
        Fit the floor's tilt (a pitched sensor); False keeps it level, for
        joints whose vertical is already known (a fit through a camera,
        where a tilt read off the fitted feet is their depth error).

    Returns
    -------
    FloorFit

    Raises
    ------
    MotionFileError
        No foot is ever tracked.
    """
    low = _lowest_points(np.asarray(points, float), np.asarray(ok, bool))
    good = np.isfinite(low).all(axis=1)
    if not good.any():
        raise MotionFileError("no foot (ankle or toe) is ever tracked: cannot find the floor")
    width = max(3, int(round(DRIFT_WINDOW_S * fps))) if fps is not None else len(low)
    # Tilt and drift are fitted in turn: a drift seen as a tilt (or the
    # reverse) leaves a residual the other then takes up.
    slope = np.zeros(2)
    base = np.zeros(int(good.sum()))
    z = np.full(len(low), np.nan)
    run = None
    for _ in range(_ALTERNATIONS):
        resid = low[good].copy()
        resid[:, 2] -= base
        slope = _fit_tilt(resid) if tilt else np.zeros(2)
        z[good] = low[good, 2] - low[good, :2] @ slope
        run = running_quantile(z, width, GROUND_QUANTILE) if good.sum() > width else None
        if run is None or float(np.nanmax(run) - np.nanmin(run)) <= DRIFT_MIN_M:
            break
        base = run[good]
    const = float(np.quantile(z[good], GROUND_QUANTILE)) if fps is not None else ground_height(z[good])
    drifts = run is not None and float(np.nanmax(run) - np.nanmin(run)) > DRIFT_MIN_M
    height = run if drifts and run is not None else np.full(len(z), const)
    with np.errstate(invalid="ignore"):
        ground = float(np.mean((z - height)[good] < AIR_M))
    return FloorFit(
        slope=np.asarray(slope, float), height=np.asarray(height, float), drifts=drifts, ground_fraction=ground
    )


def level_points(p: np.ndarray, floor: FloorFit) -> np.ndarray:
    """Points ``(T, ..., 3)`` moved so the fitted floor is z = 0.

    The tilt is removed by a rotation about the origin (lengths kept), then
    each frame's floor height is subtracted.
    """
    p = np.asarray(p, float)
    a, b = floor.slope
    n = np.array([-a, -b, 1.0])
    n /= np.linalg.norm(n)
    # Rotation taking the floor normal n to +z (Rodrigues about n × z).
    v = np.cross(n, [0.0, 0.0, 1.0])
    s, c = np.linalg.norm(v), n[2]
    if s < 1e-12:
        R = np.eye(3)
    else:
        vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        R = np.eye(3) + vx + vx @ vx * ((1 - c) / s**2)
    out = p @ R.T
    # After rotating, the plane z = a x + b y + h sits at z' = h cos(tilt).
    shape = (p.shape[0],) + (1,) * (p.ndim - 1)
    out[..., 2] -= (floor.height * c).reshape(shape)[..., 0]
    return out
