"""The camera from the person: focal length, height, pitch, roll and the floor.

One robust least-squares estimate over the whole clip, from what a pose
model gives for each frame: the 33 image landmarks (pixels) and the world
landmarks (metres, hip-centred, in the camera's axes; BlazePose's
``pose_world_landmarks``).

Model and noise
---------------
* **Focal length** ``f`` (square pixels, principal point at the image
  centre).  Each frame's world landmarks ``W`` placed at an unknown
  translation ``T`` project to the image landmarks:
  ``u = cx + f (Wx + Tx) / (Wz + Tz)``, ``v`` likewise.  For a given ``f``
  every ``T`` is linear least squares; ``f`` minimises the robust (Cauchy,
  scale :data:`PIXEL_SIGMA`) sum of pixel residuals over the clip, tempered
  by the frames a pose model's error persists (:data:`BLOCK_FRAMES`), plus
  a prior on the field of view (:data:`PRIOR_HFOV_DEG`: phones).  Only the
  body's depth extent (perspective) tells ``f`` from distance, so this is
  the weakest of the estimates; its spread is a bootstrap over blocks of
  frames (:data:`BOOTSTRAP`), which keeps the errors' correlation in time.
* **Scale**: world landmarks are rescaled so that the median leg (hip →
  knee → ankle) is the body model's for `body_height`: every length, the
  camera height among them, is in units of the assumed body height.
* **Floor**: the up direction ``n`` in camera axes (pitch, roll) and the
  camera height ``h`` make the floor ``n · P + h = 0``.  Residuals: each
  frame's lowest foot point (heels and toes, along ``n``) lies at its rest
  height above the floor (noise :data:`FLOOR_SIGMA_M`, soft-L1 so that
  frames with both feet off the floor count little), and the body's balance
  axis is vertical (noise :data:`AXIS_SIGMA_DEG`).  A body standing still
  keeps its centre of mass over its base of support, so the axis runs from
  the supporting ankle (the lower foot in the image; the middle of both
  ankles when the feet stand level, :data:`LEVEL_FEET_FRACTION`) to the
  middle of the hips.  The trunk is no such axis: a dancer tilts the chest
  for whole phrases (random scores' trunks lean 26° at the median, their
  balance axes 5°).
  Their spread is the larger of the Gauss–Newton covariance ``s² (JᵀJ)⁻¹``
  at the solution and the same block bootstrap as the focal length's (each
  resample with its own focal length): the
  model's own errors (a phrase that leans one way for seconds, a foot that
  rests off the floor) persist over many frames, which the Gauss–Newton
  spread, treating every frame as independent, cannot see.  Errors of the
  pose model that hold for the whole clip (its world landmarks hardly
  follow the camera's pitch) are added in quadrature
  (:data:`POSE_PITCH_SD_DEG`, :data:`POSE_ROLL_SD_DEG`).

Conventions: pitch is positive when the camera looks up, roll positive when
it is turned clockwise seen from behind (:func:`pitch_roll`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.optimize import least_squares

from ..body import Body, joint_index
from ..errors import FittingError

__all__ = [
    "POSE_PITCH_SD_DEG",
    "POSE_ROLL_SD_DEG",
    "PRIOR_HFOV_DEG",
    "CameraEstimate",
    "estimate_camera",
    "pitch_roll",
    "up_vector",
]

#: Image noise of a landmark, pixels (BlazePose on 640×480 renders: a few px).
PIXEL_SIGMA = 4.0
#: Spread of a contact foot point about its rest height, metres (shoe, sock,
#: the pose model's placement of heel and toe).
FLOOR_SIGMA_M = 0.03
#: Spread of the balance axis about the vertical, degrees (the axis of the
#: virtual dancer's random scores: 5.4° at the median, 6.9° at the 90th
#: percentile; and the pose model's error).
AXIS_SIGMA_DEG = 6.0
#: Standard deviation of the pose model's own pitch, degrees, persistent over
#: a clip and added to the pitch's spread (and, through the dancer's
#: distance, to the height's).  Its world landmarks hardly follow the
#: camera's pitch: on 64 development phone renders the balance axis in them
#: leant by 0.8 × the camera's pitch + 5.7° (r = 0.93), which the clip's
#: frames, resampled, cannot show.  The value makes the stated spreads cover
#: the errors at their nominal rate on those renders (7°) and on level
#: cameras (4°).
POSE_PITCH_SD_DEG = 6.0
#: The same for the roll, degrees: a dancer's lean across the image that
#: lasts for the clip (1.5-1.9° on the same renders).
POSE_ROLL_SD_DEG = 1.5
#: Both feet stand when their lowest image points lie within this fraction of
#: the leg's image length of each other: the base of support is then between
#: the ankles (a wide stance's legs lean 5-10° each, the axis between them none).
LEVEL_FEET_FRACTION = 0.05
#: Horizontal fields of view searched, degrees (phones: 50-80; margin both ways).
HFOV_RANGE_DEG = (30.0, 110.0)
#: Prior on the horizontal field of view, degrees: mean and sd of a normal
#: spanning the phones people film with (50-80°, issue 13) at ±1.5 sd.  The
#: person's perspective says little about the focal length (a few percent of
#: the landmarks' cost between 30° and the true 52° on random scores), so
#: without a prior the estimate wandered to the narrow end.
PRIOR_HFOV_DEG = (65.0, 10.0)
#: Focal lengths tried, log-spaced over HFOV_RANGE_DEG (0.9 % apart; a
#: parabola through the best three refines far below the estimate's spread).
FOCAL_GRID = 193
#: Focal lengths whose frame costs are computed at once (bounds the working
#: array to FOCAL_CHUNK × MAX_FRAMES × 33 × 3 floats, 19 MB).
FOCAL_CHUNK = 40
#: Bootstrap resamples of frame blocks for the spreads of the focal length, height, pitch and roll.
BOOTSTRAP = 24
#: Frames per bootstrap block (about a second at 25 fps: errors persist that long).
BLOCK_FRAMES = 25
#: Landmarks seen at least this visibility enter the estimate.
MIN_VISIBILITY = 0.5
#: Fewest usable frames for an estimate.
MIN_FRAMES = 10
#: Most frames entering the estimate; a longer clip's usable frames are
#: subsampled evenly across it.  Its errors are BlazePose's biases, which
#: more frames of the same clip do not average away, so the cost (one focal
#: search per bootstrap resample) and memory stay bounded for hours of video.
MAX_FRAMES = 600

_HIPS, _SHOULDERS, _ANKLES = (23, 24), (11, 12), (27, 28)
_LEG = ((23, 25, 27), (24, 26, 28))  # hip, knee, ankle (left, right)
_FOOT = (29, 30, 31, 32)  # heels, toes


@dataclass(frozen=True)
class CameraEstimate:
    """A camera estimated from the person, with one standard deviation each.

    Attributes
    ----------
    focal_px, focal_sd_px : float
        Focal length, pixels.
    hfov_deg : float
        Horizontal field of view from the focal length, degrees.
    height_m, height_sd_m : float
        Camera centre above the floor, metres.
    pitch_deg, pitch_sd_deg, roll_deg, roll_sd_deg : float
        Degrees (see the module docstring for the signs).
    up : (3,) tuple of float
        The world's up direction in camera axes (the floor's normal).
    frames : int
        Frames used (at most :data:`MAX_FRAMES`, evenly spread over the clip).
    contacts : int
        Frames whose lowest foot point was within 2 sd of the floor.
    focal_resolved : bool
        False when the best focal length lies at an end of the searched
        fields of view (:data:`HFOV_RANGE_DEG`): the person's perspective
        did not determine it, and its bootstrap spread (0 when every
        resample runs to the same end) says nothing; the height and the
        floor, which scale with it, are then uncertain by as much.
    """

    focal_px: float
    focal_sd_px: float
    hfov_deg: float
    height_m: float
    height_sd_m: float
    pitch_deg: float
    pitch_sd_deg: float
    roll_deg: float
    roll_sd_deg: float
    up: tuple
    frames: int
    contacts: int
    focal_resolved: bool = True

    def as_dict(self) -> dict:
        """Plain fields (for ``capture.npz`` and JSON)."""
        d = asdict(self)
        d["up"] = list(self.up)
        return d

    def K(self, image_size) -> np.ndarray:
        """Intrinsics (3, 3) for images of `image_size` (width, height)."""
        w, h = image_size
        return np.array([[self.focal_px, 0.0, w / 2], [0.0, self.focal_px, h / 2], [0.0, 0.0, 1.0]])

    def line(self) -> str:
        """One line a person reads."""
        lens = (
            f"{self.hfov_deg:.0f}° field of view (focal {self.focal_px:.0f} ± {self.focal_sd_px:.0f} px)"
            if self.focal_resolved
            else f"field of view not resolved from the person (its fit runs to the searched limit, {self.hfov_deg:.0f}°)"
        )
        return (
            f"camera estimated: {lens}, "
            f"{self.height_m:.2f} ± {self.height_sd_m:.2f} m high, pitch {self.pitch_deg:+.1f} ± {self.pitch_sd_deg:.1f}°, "
            f"roll {self.roll_deg:+.1f} ± {self.roll_sd_deg:.1f}° ({self.contacts} of {self.frames} frames on the floor)"
        )


def up_vector(pitch: float, roll: float) -> np.ndarray:
    """The world's up direction in camera axes (x right, y down, z forward), radians in."""
    cp = np.cos(pitch)
    return np.array([-np.sin(roll) * cp, -np.cos(roll) * cp, np.sin(pitch)])


def pitch_roll(R) -> tuple[float, float]:
    """(pitch, roll) in degrees of a world-to-camera rotation `R` (world z up)."""
    u = np.asarray(R, float) @ np.array([0.0, 0.0, 1.0])
    return float(np.degrees(np.arcsin(np.clip(u[2], -1, 1)))), float(np.degrees(np.arctan2(-u[0], -u[1])))


def _moments(uv: np.ndarray, W: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(T, 10) per-frame weighted sums from which every focal length's translations follow.

    The projection's normal equations (:func:`_translations`) are polynomials
    in ``f`` whose coefficients are these sums over the landmarks, so a
    focal search costs one pass over the landmarks, not one per candidate.
    """
    x, y = uv[..., 0], uv[..., 1]
    r2 = x * x + y * y
    terms = (1.0, x, y, r2, x * W[..., 2], W[..., 0], y * W[..., 2], W[..., 1], r2 * W[..., 2])
    terms += (x * W[..., 0] + y * W[..., 1],)
    return np.stack([np.sum(w * t, axis=1) for t in terms], axis=-1)


def _translations(f, m: np.ndarray) -> np.ndarray:
    """Per-frame translations for focal length(s) `f`: the weighted linear least squares of the projection.

    Each landmark (x, y centred pixels, weight w) gives ``f Tx − x Tz = x Wz − f Wx``
    and ``f Ty − y Tz = y Wz − f Wy``.

    Parameters
    ----------
    f : float or (F,) ndarray
        Focal length(s), pixels.
    m : (T, 10) ndarray
        :func:`_moments` of the frames.

    Returns
    -------
    (T, 3) or (F, T, 3) ndarray
        Metres, camera axes.
    """
    f = np.asarray(f, float)[..., None]  # (F, 1) or (1,)
    s0, sx, sy, sr, xwz, wx, ywz, wy, rwz, xy_w = np.moveaxis(m, -1, 0)
    A = np.zeros(np.broadcast_shapes(f.shape, s0.shape) + (3, 3))
    A[..., 0, 0] = A[..., 1, 1] = f * f * s0
    A[..., 0, 2] = A[..., 2, 0] = -f * sx
    A[..., 1, 2] = A[..., 2, 1] = -f * sy
    A[..., 2, 2] = sr
    A += 1e-9 * np.eye(3)
    b = np.stack([f * xwz - f * f * wx, f * ywz - f * f * wy, f * xy_w - rwz], -1)
    return np.linalg.solve(A, b[..., None])[..., 0]


def _frame_costs(focals: np.ndarray, uv, W, w, m) -> np.ndarray:
    """(F, T) robust reprojection cost of each frame at each focal length (Cauchy, scale :data:`PIXEL_SIGMA`)."""
    out = np.empty((len(focals), len(uv)))
    for i in range(0, len(focals), FOCAL_CHUNK):
        f = focals[i : i + FOCAL_CHUNK, None, None]
        P = W + _translations(focals[i : i + FOCAL_CHUNK], m)[:, :, None]  # (F, T, K, 3)
        z = np.where(P[..., 2] > 1e-3, P[..., 2], np.nan)
        r = np.hypot(f * P[..., 0] / z - uv[..., 0], f * P[..., 1] / z - uv[..., 1]) / PIXEL_SIGMA
        out[i : i + FOCAL_CHUNK] = np.sum(w * np.log1p(np.where(np.isfinite(r), r, 1e3) ** 2), axis=-1)
    return out


def _focal_grid(width: float) -> np.ndarray:
    """Candidate focal lengths (pixels), log-spaced over :data:`HFOV_RANGE_DEG`."""
    lo, hi = (0.5 * width / np.tan(np.radians(a) / 2) for a in HFOV_RANGE_DEG[::-1])
    return np.geomspace(lo, hi, FOCAL_GRID)


def _hfov_prior(grid: np.ndarray, width: float) -> np.ndarray:
    """Negative log prior (:data:`PRIOR_HFOV_DEG`) of each candidate focal length."""
    hfov = np.degrees(2 * np.arctan(0.5 * width / grid))
    mean, sd = PRIOR_HFOV_DEG
    return 0.5 * ((hfov - mean) / sd) ** 2


def _best_focal(grid: np.ndarray, costs: np.ndarray, prior: np.ndarray | float = 0.0) -> tuple[float, bool]:
    """The focal length of least posterior cost, and whether it lies inside the searched range.

    `costs` is the landmarks' robust cost summed over frames; frames are
    not independent (a pose model's errors persist about a second), so it
    is tempered by :data:`BLOCK_FRAMES` before the `prior` (negative log)
    is added.  The vertex of the parabola (in log f) through the best grid
    point and its neighbours; a minimum at an end of the grid is that end.
    """
    costs = np.asarray(costs, float) / BLOCK_FRAMES + prior
    i = int(np.argmin(costs))
    if i == 0 or i == len(grid) - 1:
        return float(grid[i]), False
    c0, c1, c2 = costs[i - 1 : i + 2]
    curv = c0 - 2.0 * c1 + c2
    step = 0.5 * (c0 - c2) / curv if curv > 0 else 0.0
    h = np.log(grid[1] / grid[0])
    return float(grid[i] * np.exp(np.clip(step, -1.0, 1.0) * h)), True


def _rest_heights(body: Body) -> tuple[float, np.ndarray]:
    """Body model's leg length (metres) and the rest heights of heel, heel, toe, toe."""
    rest = body.rest
    hip, knee, ankle = (joint_index(f"right_{n}") for n in ("hip", "knee", "ankle"))
    leg = float(np.linalg.norm(rest[hip] - rest[knee]) + np.linalg.norm(rest[knee] - rest[ankle]))
    heel = 0.008 * body.height  # LANDMARK_ATTACHMENTS' heel
    toe = float(rest[joint_index("right_toe"), 2])
    return leg, np.array([heel, heel, toe, toe])


def _base_of_support(uv: np.ndarray, feet_seen: np.ndarray) -> np.ndarray:
    """(T, 2) weights of the left and right ankle in the base of support.

    The foot whose lowest seen point is lower in the image carries the body
    (1, 0 or 0, 1); feet level within :data:`LEVEL_FEET_FRACTION` of the
    leg's image length share it (½, ½).

    Parameters
    ----------
    uv : (T, 33, 2) ndarray
        Image landmarks, pixels (y down).
    feet_seen : (T, 4) ndarray of bool
        Heels and toes (:data:`_FOOT`: left heel, right heel, left toe, right toe) seen.
    """
    v = np.where(feet_seen, uv[:, list(_FOOT), 1], -np.inf)
    left, right = np.maximum(v[:, 0], v[:, 2]), np.maximum(v[:, 1], v[:, 3])
    leg_px = np.mean([np.linalg.norm(uv[:, hip] - uv[:, ankle], axis=-1) for hip, _, ankle in _LEG], axis=0)
    level = np.abs(left - right) <= LEVEL_FEET_FRACTION * leg_px
    w_left = np.where(level, 0.5, (left > right).astype(float))
    return np.column_stack([w_left, 1.0 - w_left])


def estimate_camera(xy, visibility, world, image_size, body_height: float | None = None, seed: int = 0):
    """Estimate the camera from a clip's image and world landmarks.

    Parameters
    ----------
    xy : (T, 33, >=2) ndarray
        Image landmarks, pixels.
    visibility : (T, 33) ndarray
        In [0, 1].
    world : (T, 33, 3) ndarray
        World landmarks, metres, hip-centred, camera axes (NaN when missing).
    image_size : (width, height)
    body_height : float, optional
        Assumed performer height, metres (default ``Body().height``).
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    CameraEstimate or None
        None when fewer than :data:`MIN_FRAMES` frames show the body and feet.
    """
    body = Body() if body_height is None else Body(height=float(body_height))
    xy = np.asarray(xy, float)[..., :2]
    vis = np.asarray(visibility, float)
    W = np.asarray(world, float)
    if xy.ndim != 3 or W.shape != xy.shape[:2] + (3,) or vis.shape != xy.shape[:2]:
        raise FittingError(f"estimate_camera: xy {xy.shape}, visibility {vis.shape}, world {W.shape} do not agree")
    w_img, h_img = (float(v) for v in image_size)
    seen = (vis >= MIN_VISIBILITY) & np.isfinite(xy).all(-1) & np.isfinite(W).all(-1)
    frames = np.flatnonzero(
        seen[:, list(_FOOT)].any(1) & seen[:, list(_HIPS + _SHOULDERS + _ANKLES)].all(1) & (seen.sum(1) >= 8)
    )
    if len(frames) < MIN_FRAMES:
        return None
    if len(frames) > MAX_FRAMES:
        frames = frames[np.linspace(0, len(frames) - 1, MAX_FRAMES).round().astype(int)]
    uv = xy[frames] - np.array([w_img / 2, h_img / 2])
    wts = seen[frames].astype(float)
    Wf = np.where(seen[frames][..., None], W[frames], 0.0)
    leg_model, foot_rest = _rest_heights(body)
    legs = [
        np.linalg.norm(Wf[:, a] - Wf[:, b], axis=-1) + np.linalg.norm(Wf[:, b] - Wf[:, c], axis=-1) for a, b, c in _LEG
    ]
    leg_ok = np.concatenate([lg[seen[frames][:, list(s)].all(1)] for lg, s in zip(legs, _LEG)])
    if len(leg_ok) >= MIN_FRAMES:
        Wf = Wf * (leg_model / float(np.median(leg_ok)))

    # Every frame's cost at every candidate focal length, once: the clip's
    # cost and each bootstrap resample's are then weighted sums of its rows.
    m = _moments(uv, Wf, wts)
    grid = _focal_grid(w_img)
    costs = _frame_costs(grid, uv, Wf, wts, m)
    prior = _hfov_prior(grid, w_img)
    f, resolved = _best_focal(grid, costs.sum(1), prior)
    rng = np.random.default_rng(seed)
    n_blocks = max(1, len(frames) // BLOCK_FRAMES)
    blocks = np.array_split(np.arange(len(frames)), n_blocks)
    boot, picks = [], []
    for _ in range(BOOTSTRAP if n_blocks > 1 else 0):
        pick = np.concatenate([blocks[i] for i in rng.integers(0, n_blocks, n_blocks)])
        picks.append(pick)
        boot.append(_best_focal(grid, costs @ np.bincount(pick, minlength=len(frames)), prior)[0])
    f_sd = float(np.std(boot, ddof=1)) if len(boot) > 1 else float("nan")

    feet_seen = seen[frames][:, list(_FOOT)]
    sigma_axis = np.radians(AXIS_SIGMA_DEG)

    base = _base_of_support(uv, feet_seen)

    def placed(focal):
        """The clip's foot points and unit balance axes, camera axes, for a focal length."""
        P = Wf + _translations(focal, m)[:, None]
        axis = 0.5 * (P[:, 23] + P[:, 24]) - np.einsum("tk,tkd->td", base, P[:, list(_ANKLES)])
        return P[:, list(_FOOT)], axis / np.linalg.norm(axis, axis=-1, keepdims=True)

    def residuals(p, feet, axes, rows=slice(None)):
        n = up_vector(p[0], p[1])
        heights = feet[rows] @ n + p[2] - foot_rest  # each foot point's height above its rest height
        heights = np.where(feet_seen[rows], heights, np.inf)
        lowest = heights.min(1)
        tilt = np.cross(axes[rows], n)  # sine of the balance axis's angle from the vertical
        return np.concatenate([lowest / FLOOR_SIGMA_M, tilt.ravel() / sigma_axis])

    def solve(p0, feet, axes, rows=slice(None)):
        return least_squares(
            residuals, p0, args=(feet, axes, rows), loss="cauchy", f_scale=1.0, x_scale=[0.1, 0.1, 0.5]
        )

    feet, axes = placed(f)
    # Start: a level camera, its height from the lowest foot points along −y.
    h0 = float(np.median(np.nanmax(np.where(feet_seen, feet[..., 1], np.nan), 1)))
    sol = solve([0.0, 0.0, h0], feet, axes)
    J = sol.jac
    s2 = 2.0 * float(sol.cost) / max(J.shape[0] - J.shape[1], 1)
    try:
        cov = np.linalg.inv(J.T @ J) * s2
        sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        sd = np.full(3, np.nan)
    if len(picks) > 1:
        # Each resample with its own focal length: the height scales with it.
        spread = np.std([solve(sol.x, *placed(fb), pick).x for fb, pick in zip(boot, picks)], axis=0, ddof=1)
        sd = np.fmax(sd, spread)
    # The pose model's errors that hold for the whole clip, which no
    # resampling of its frames shows; a pitch error moves the floor under
    # the dancer by the dancer's distance times it.
    distance = float(np.median(np.linalg.norm(feet[feet_seen], axis=-1)))
    sys_pitch, sys_roll = np.radians(POSE_PITCH_SD_DEG), np.radians(POSE_ROLL_SD_DEG)
    sd = np.hypot(sd, [sys_pitch, sys_roll, distance * sys_pitch])
    pitch, roll, height = (float(v) for v in sol.x)
    contacts = int(np.sum(np.abs(residuals(sol.x, feet, axes)[: len(frames)]) < 2.0))
    return CameraEstimate(
        focal_px=float(f),
        focal_sd_px=f_sd,
        hfov_deg=float(np.degrees(2 * np.arctan(0.5 * w_img / f))),
        height_m=height,
        height_sd_m=float(sd[2]),
        pitch_deg=float(np.degrees(pitch)),
        pitch_sd_deg=float(np.degrees(sd[0])),
        roll_deg=float(np.degrees(roll)),
        roll_sd_deg=float(np.degrees(sd[1])),
        up=tuple(float(v) for v in up_vector(pitch, roll)),
        frames=len(frames),
        contacts=contacts,
        focal_resolved=resolved,
    )
