"""Per-frame geometry shared by every style: posed body, body volume, visibility, floor.

Everything here is computed for all frames at once with numpy; the styles'
draw loops only call OpenCV primitives.  The body volume is a set of capsules
(a segment with a radius at each end) that approximates the drawn mannequin;
it decides which landmarks the camera sees (self-occlusion), whatever style
draws the frames, so the truth sidecar does not depend on the style.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from capture2notation.body import (
    BLAZEPOSE_LANDMARKS,
    JOINTS,
    Body,
    forward_kinematics,
    global_rotations,
    joint_index,
)
from capture2notation.body.landmarks import attached_points, landmarks_from_joints
from capture2notation.errors import SyntheticError

from .camera import Camera

__all__ = [
    "CAPSULES",
    "EXTRA_POINTS",
    "FACE_LANDMARKS",
    "Pose",
    "body_capsules",
    "floor_background",
    "landmark_visibility",
    "point_visibility",
]

#: Points of the body surface / volume that are neither joints nor landmarks:
#: (joint they ride on, rest position as fractions of body height).
EXTRA_POINTS: dict[str, tuple[str, tuple[float, float, float]]] = {
    "head_centre": ("neck", (0.0, 0.005, 0.925)),
    "chin": ("neck", (0.0, 0.012, 0.865)),
    "neck_base": ("chest", (0.0, 0.0, 0.834)),  # above the neck joint: the neck ends inside the collar
    "nose_root": ("neck", (0.0, 0.054, 0.929)),
    # The trousers end just above the ankle joint and the shoe just below it,
    # so the leg meets the foot at the ankle in every view (with a bare strip
    # where the camera sees under the hem), where a person would mark it.
    # Trousers down over the shoe hid that junction from the pose model.
    "right_hem": ("right_knee", (0.055, 0.0, 0.080)),
    "left_hem": ("left_knee", (-0.055, 0.0, 0.080)),
    "right_heel_top": ("right_ankle", (0.055, -0.020, 0.021)),
    "right_instep": ("right_ankle", (0.055, 0.028, 0.025)),
    "left_heel_top": ("left_ankle", (-0.055, -0.020, 0.021)),
    "left_instep": ("left_ankle", (-0.055, 0.028, 0.025)),
    "right_ball": ("right_ankle", (0.055, 0.085, 0.018)),
    "left_ball": ("left_ankle", (-0.055, 0.085, 0.018)),
    "right_toe_top": ("right_ankle", (0.055, 0.112, 0.013)),
    "left_toe_top": ("left_ankle", (-0.055, 0.112, 0.013)),
    "right_hand_mid": ("right_wrist", (0.117, 0.004, 0.432)),
    "left_hand_mid": ("left_wrist", (-0.117, 0.004, 0.432)),
}

#: Head ellipsoid semi-axes (right, forward, up), fractions of body height.
HEAD_RADII = (0.046, 0.058, 0.070)

#: The body volume: (name, end a, end b, radius at a, radius at b); ends are
#: joints, landmarks or :data:`EXTRA_POINTS`; radii are fractions of body height.
CAPSULES: tuple[tuple[str, str, str, float, float], ...] = (
    ("neck", "neck_base", "chin", 0.030, 0.028),
    ("head", "head_centre", "head_centre", 0.064, 0.064),
    ("shoulders", "right_shoulder", "left_shoulder", 0.048, 0.048),
    ("chest", "chest", "neck", 0.088, 0.070),
    ("belly", "waist", "chest", 0.080, 0.088),
    ("pelvis", "pelvis", "waist", 0.085, 0.080),
    ("hips", "right_hip", "left_hip", 0.062, 0.062),
    ("right_upper_arm", "right_shoulder", "right_elbow", 0.034, 0.027),
    ("right_forearm", "right_elbow", "right_wrist", 0.026, 0.019),
    ("right_hand", "right_wrist", "right_hand_mid", 0.019, 0.022),
    ("right_fingers", "right_hand_mid", "right_hand_tip", 0.017, 0.010),
    ("right_thumb", "right_wrist", "right_thumb", 0.011, 0.008),
    ("left_upper_arm", "left_shoulder", "left_elbow", 0.034, 0.027),
    ("left_forearm", "left_elbow", "left_wrist", 0.026, 0.019),
    ("left_hand", "left_wrist", "left_hand_mid", 0.019, 0.022),
    ("left_fingers", "left_hand_mid", "left_hand_tip", 0.017, 0.010),
    ("left_thumb", "left_wrist", "left_thumb", 0.011, 0.008),
    ("right_thigh", "right_hip", "right_knee", 0.055, 0.036),
    ("right_shin", "right_knee", "right_hem", 0.035, 0.027),
    ("right_lower_leg", "right_hem", "right_ankle", 0.023, 0.020),
    ("right_foot", "right_heel_top", "right_ball", 0.021, 0.019),
    ("right_instep", "right_instep", "right_ball", 0.019, 0.018),
    ("right_toes", "right_ball", "right_toe_top", 0.020, 0.012),
    ("left_thigh", "left_hip", "left_knee", 0.055, 0.036),
    ("left_shin", "left_knee", "left_hem", 0.035, 0.027),
    ("left_lower_leg", "left_hem", "left_ankle", 0.023, 0.020),
    ("left_foot", "left_heel_top", "left_ball", 0.021, 0.019),
    ("left_instep", "left_instep", "left_ball", 0.019, 0.018),
    ("left_toes", "left_ball", "left_toe_top", 0.020, 0.012),
)

_CHUNK = 256  # frames per block in the visibility test

#: Landmarks on the surface of the head: seen only when they face the camera.
FACE_LANDMARKS: tuple[str, ...] = BLAZEPOSE_LANDMARKS[:11]  # nose … mouth_right


@dataclass(frozen=True, eq=False)
class Pose:
    """A posed body over time with everything the renderer derives from it.

    Parameters
    ----------
    angles : (T, J, 3) ndarray
        Local Euler angles, radians.
    root : (T, 3) ndarray
        Pelvis position, metres.
    body : Body
    fps : float
        Frames per second.

    Attributes
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres.
    rotations : (T, J, 3, 3) ndarray
        Global joint rotations.
    landmarks : (T, 33, 3) ndarray
        BlazePose landmarks, world metres.
    points : dict of str to (T, 3) ndarray
        Joints, landmarks and :data:`EXTRA_POINTS` by name.
    """

    angles: np.ndarray
    root: np.ndarray
    body: Body = field(default_factory=Body)
    fps: float = 25.0
    joints: np.ndarray = field(init=False, repr=False)
    rotations: np.ndarray = field(init=False, repr=False)
    landmarks: np.ndarray = field(init=False, repr=False)
    points: dict = field(init=False, repr=False)

    def __post_init__(self):
        angles = np.asarray(self.angles, dtype=float)
        root = np.asarray(self.root, dtype=float)
        if angles.ndim != 3 or angles.shape[1:] != (len(JOINTS), 3) or angles.shape[0] < 1:
            raise SyntheticError(f"angles must have shape (T>=1, {len(JOINTS)}, 3), got {angles.shape}")
        if root.shape != (angles.shape[0], 3):
            raise SyntheticError(f"root must have shape ({angles.shape[0]}, 3), got {root.shape}")
        bad = ~np.isfinite(angles).all(axis=(1, 2)) | ~np.isfinite(root).all(axis=1)
        if bad.any():
            raise SyntheticError(f"pose is not finite at frame {int(np.flatnonzero(bad)[0])}")
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise SyntheticError(f"fps must be positive, got {self.fps!r}")
        joints = forward_kinematics(angles, root, self.body)
        rot = global_rotations(angles, self.body)
        lms = landmarks_from_joints(joints, rot, self.body)
        names = list(EXTRA_POINTS)
        ids = [joint_index(EXTRA_POINTS[n][0]) for n in names]
        rest = np.array([EXTRA_POINTS[n][1] for n in names]) * self.body.height
        extra = attached_points(joints, rot, ids, rest - self.body.rest[ids])
        points = {n: joints[:, i] for i, n in enumerate(JOINTS)}
        points.update({n: lms[:, i] for i, n in enumerate(BLAZEPOSE_LANDMARKS)})
        points.update({n: extra[:, i] for i, n in enumerate(names)})
        for name, value in (
            ("angles", angles),
            ("root", root),
            ("joints", joints),
            ("rotations", rot),
            ("landmarks", lms),
            ("points", points),
        ):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "fps", float(self.fps))

    @classmethod
    def from_motion(cls, motion) -> Pose:
        """From anything with ``angles``, ``root``, ``body`` and ``fps`` (a ``Motion``)."""
        return cls(np.asarray(motion.angles), np.asarray(motion.root), motion.body, float(motion.fps))

    @property
    def n_frames(self) -> int:
        return self.angles.shape[0]

    @property
    def times(self) -> np.ndarray:
        """(T,) seconds of each frame."""
        return np.arange(self.n_frames) / self.fps

    def head_axes(self) -> np.ndarray:
        """(T, 3, 3) head axes: rows right, forward, up (world), from the neck rotation."""
        return np.swapaxes(self.rotations[:, joint_index("neck")], 1, 2)


def body_capsules(pose: Pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The body volume of :data:`CAPSULES` at every frame.

    Returns
    -------
    a, b : (T, P, 3) ndarray
        Capsule end points, world metres.
    radii : (P, 2) ndarray
        Radius at each end, metres.
    """
    a = np.stack([pose.points[c[1]] for c in CAPSULES], axis=1)
    b = np.stack([pose.points[c[2]] for c in CAPSULES], axis=1)
    radii = np.array([(c[3], c[4]) for c in CAPSULES]) * pose.body.height
    return a, b, radii


def point_visibility(
    camera: Camera,
    points: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    radii: np.ndarray,
    tolerance: float = 0.01,
) -> np.ndarray:
    """Whether each point is seen: inside the image and not hidden by the body volume.

    A capsule hides a point when it covers the point's pixel with its front
    surface nearer the camera than the point, unless the point lies inside
    that capsule (a joint is inside its own limbs: they do not hide it).

    Parameters
    ----------
    camera : Camera
    points : (T, N, 3) ndarray
        World points, metres.
    a, b : (T, P, 3) ndarray
        Capsule ends; `radii` (P, 2) metres.
    tolerance : float
        Metres a point may lie outside a capsule and still count as inside it.

    Returns
    -------
    (T, N) ndarray of bool
    """
    if len(points) > _CHUNK:  # bound the (T, N, P) temporaries on long takes
        return np.concatenate(
            [
                point_visibility(camera, points[i : i + _CHUNK], a[i : i + _CHUNK], b[i : i + _CHUNK], radii, tolerance)
                for i in range(0, len(points), _CHUNK)
            ]
        )
    pc = camera.to_camera(points)  # (T,N,3)
    ac, bc = camera.to_camera(a), camera.to_camera(b)
    f = camera.K[1, 1]
    zp = pc[..., 2]
    ok = zp > 1e-6
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = pc[..., :2] / zp[..., None] * f  # focal-plane pixels (principal point irrelevant here)
        ua = ac[..., :2] / ac[..., 2:3] * f
        ub = bc[..., :2] / bc[..., 2:3] * f
    # Closest point on each projected capsule axis to each projected point.
    d = (ub - ua)[:, None]  # (T,1,P,2)
    rel = uv[:, :, None] - ua[:, None]  # (T,N,P,2)
    dd = np.sum(d * d, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.clip(np.where(dd > 1e-12, np.sum(rel * d, axis=-1) / dd, 0.0), 0.0, 1.0)
    dist2 = np.linalg.norm(rel - s[..., None] * d, axis=-1)
    r = radii[:, 0] + s * (radii[:, 1] - radii[:, 0])  # (T,N,P) metres
    # Depth of the axis point under the pixel (perspective-correct along the segment).
    za, zb = ac[..., 2][:, None], bc[..., 2][:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        z_axis = 1.0 / ((1.0 - s) / za + s / zb)
    covers = dist2 < r * f / z_axis
    front = z_axis - r
    # Inside its own capsule, measured in 3D.
    seg = (b - a)[:, None]
    rel3 = points[:, :, None] - a[:, None]
    ss = np.sum(seg * seg, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s3 = np.clip(np.where(ss > 1e-12, np.sum(rel3 * seg, axis=-1) / ss, 0.0), 0.0, 1.0)
    d3 = np.linalg.norm(rel3 - s3[..., None] * seg, axis=-1)
    inside = d3 <= radii[:, 0] + s3 * (radii[:, 1] - radii[:, 0]) + tolerance
    hidden = np.any(covers & (front < zp[..., None] - tolerance) & ~inside, axis=-1)
    uvpix = camera.project(points)
    return ok & ~hidden & camera.in_image(uvpix)


def landmark_visibility(pose: Pose, camera: Camera) -> np.ndarray:
    """Visibility of the 33 BlazePose landmarks, (T, 33) of 0.0 / 1.0.

    Face landmarks lie on the head's surface: they are also hidden when they
    face away from the camera.
    """
    a, b, radii = body_capsules(pose)
    # The head capsule would count every face point as inside it; face points
    # use the facing test against the head instead.
    vis = point_visibility(camera, pose.landmarks, a, b, radii)
    face = [BLAZEPOSE_LANDMARKS.index(n) for n in FACE_LANDMARKS]
    centre = pose.points["head_centre"][:, None]
    p = pose.landmarks[:, face]
    to_cam = camera.position - p
    out = p - centre
    cos = np.sum(out * to_cam, axis=-1) / (np.linalg.norm(out, axis=-1) * np.linalg.norm(to_cam, axis=-1))
    # Profile views still show the nose and the near eye, as a pose model reports them.
    facing = cos > -0.25
    vis[:, face] &= facing
    return vis.astype(float)


def floor_background(
    camera: Camera,
    wall=(236, 232, 226),
    floor=(196, 204, 212),
    grid=(170, 178, 186),
    spacing: float = 0.5,
    extent: float = 6.0,
    line_width: int = 1,
) -> np.ndarray:
    """The empty stage: wall above the horizon, floor plane with a grid below.

    Parameters
    ----------
    camera : Camera
    wall, floor, grid : (B, G, R) tuples
    spacing, extent : float
        Grid spacing and half-size, metres.
    line_width : int
        Grid line thickness, pixels.

    Returns
    -------
    (H, W, 3) uint8 ndarray
    """
    w, h = camera.size
    img = np.empty((h, w, 3), np.uint8)
    img[:] = wall
    # The floor: a very large square on z = 0, clipped at the near plane, so
    # that its far edge lies on (practically) the horizon.
    big = extent * 50
    corners = np.array([[-big, -big, 0], [big, -big, 0], [big, big, 0], [-big, big, 0]], float)
    _fill_world_polygon(img, camera, corners, floor)
    ticks = np.arange(-extent, extent + 1e-9, spacing)
    for x in ticks:
        _world_line(img, camera, (x, -extent, 0.0), (x, extent, 0.0), grid, line_width)
        _world_line(img, camera, (-extent, x, 0.0), (extent, x, 0.0), grid, line_width)
    return img


def _clip_near(p0, p1, near=0.05):
    """Clip a camera-space segment to depth >= near; None if wholly behind."""
    z0, z1 = p0[2], p1[2]
    if z0 < near and z1 < near:
        return None
    if z0 < near:
        p0 = p0 + (p1 - p0) * (near - z0) / (z1 - z0)
    elif z1 < near:
        p1 = p1 + (p0 - p1) * (near - z1) / (z0 - z1)
    return p0, p1


def _cam_to_pix(camera: Camera, pc: np.ndarray) -> np.ndarray:
    return (pc @ camera.K.T)[..., :2] / pc[..., 2:3]


def _world_line(img, camera: Camera, p0, p1, colour, width) -> None:
    seg = _clip_near(camera.to_camera(np.array(p0)), camera.to_camera(np.array(p1)))
    if seg is None:
        return
    q = np.round(_cam_to_pix(camera, np.array(seg)) * 16).astype(np.int64)
    lim = 2**20
    if np.any(np.abs(q) > lim):  # let OpenCV clip, but keep the integers in range
        q = np.clip(q, -lim, lim)
    cv2.line(img, tuple(map(int, q[0])), tuple(map(int, q[1])), colour, width, cv2.LINE_AA, 4)


def _fill_world_polygon(img, camera: Camera, corners: np.ndarray, colour) -> None:
    """Fill a planar convex world polygon, clipped against the near plane."""
    pc = camera.to_camera(corners)
    out = []
    near = 0.05
    for i in range(len(pc)):
        p, q = pc[i], pc[(i + 1) % len(pc)]
        if p[2] >= near:
            out.append(p)
        if (p[2] >= near) != (q[2] >= near):
            out.append(p + (q - p) * (near - p[2]) / (q[2] - p[2]))
    if len(out) < 3:
        return
    pix = _cam_to_pix(camera, np.array(out))
    # Points just beyond the near plane project millions of pixels away: cut
    # the polygon to a frame around the image (clamping each coordinate
    # instead bends its edges, and a camera pitched up saw the floor drawn
    # above the horizon).
    pix = _clip_to_box(pix, -_FILL_MARGIN_PX, np.array(camera.size, float) + _FILL_MARGIN_PX)
    if len(pix) < 3:
        return
    cv2.fillPoly(img, [np.round(pix * 16).astype(np.int32)], colour, cv2.LINE_AA, 4)


#: Margin (pixels) around the image to which filled polygons are cut.
_FILL_MARGIN_PX = 64.0


def _clip_to_box(poly: np.ndarray, lo, hi) -> np.ndarray:
    """A convex polygon ``(N, 2)`` cut to the box ``lo <= p <= hi`` (Sutherland–Hodgman)."""
    lo = np.broadcast_to(np.asarray(lo, float), (2,))
    hi = np.broadcast_to(np.asarray(hi, float), (2,))
    pts = [np.asarray(p, float) for p in poly]
    for axis in (0, 1):
        for bound, inside in ((lo[axis], lambda v, b: v >= b), (hi[axis], lambda v, b: v <= b)):
            kept = []
            for i, p in enumerate(pts):
                q = pts[(i + 1) % len(pts)]
                if inside(p[axis], bound):
                    kept.append(p)
                if inside(p[axis], bound) != inside(q[axis], bound):
                    kept.append(p + (q - p) * (bound - p[axis]) / (q[axis] - p[axis]))
            pts = kept
            if not pts:
                return np.empty((0, 2))
    return np.array(pts)
