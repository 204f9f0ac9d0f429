"""The shaded mannequin: capsule limbs, a clothed torso, a head with a face.

Made to look like a person to a pose model at little cost: a shirt and
trousers of different colours, loose elbow-length sleeves whose cuff marks
the elbow even when the upper arm points at the camera, skin-coloured
forearms, hands and head,
trousers ending just above the ankle and dark shoes (heel, instep, toes)
just below it so the leg visibly meets the foot at the ankle joint, hair at
the back of the head and a face (eyes, brows, nose, mouth, ears) that turns
with the head so front and back are told apart; the hair covers the face
only when the head faces away from the camera.  Shading is three nested, light-shifted layers of each shape
(dark rim, body colour, highlight): no per-pixel work.

All geometry is computed for every frame at once; :meth:`Mannequin.frame`
only sorts the parts by depth (painter's algorithm) and calls OpenCV.
"""

from __future__ import annotations

import cv2
import numpy as np

from capture2notation.body import joint_index
from capture2notation.body.landmarks import attached_points

from .camera import Camera
from .scene import CAPSULES, HEAD_RADII, Pose, body_capsules, floor_background

__all__ = ["PALETTE", "Mannequin", "capsule_outlines", "fixed"]

SHIFT = 4  # OpenCV fixed-point bits for sub-pixel anti-aliased drawing
_ONE = 1 << SHIFT
#: Direction towards the light in the image (upper left), unit vector.
LIGHT = np.array([-0.42, -0.91]) / np.hypot(0.42, 0.91)
#: Shading layers: (radius scale, shift towards the light in radii, colour gain).
LAYERS = ((1.0, 0.0, 0.60), (0.80, 0.14, 0.88), (0.40, 0.40, 1.12))
_HULL_LAYERS = LAYERS[:2] + ((0.55, 0.30, 1.08),)

#: Colours (B, G, R).
PALETTE: dict[str, tuple[int, int, int]] = {
    "skin": (120, 160, 214),
    "shirt": (70, 64, 186),
    "trousers": (92, 62, 44),
    "shoes": (38, 36, 40),
    "hair": (28, 40, 62),
    "eye_white": (236, 240, 242),
    "iris": (50, 40, 30),
    "mouth": (70, 70, 160),
    "brow": (30, 38, 52),
    "shadow": (160, 166, 172),
}
_PART_COLOUR = {
    "neck": "skin",
    "head": "skin",
    "shoulders": "shirt",
    "chest": "shirt",
    "belly": "shirt",
    "pelvis": "trousers",
    "hips": "trousers",
    "upper_arm": "shirt",
    "forearm": "skin",
    "hand": "skin",
    "fingers": "skin",
    "thumb": "skin",
    "thigh": "trousers",
    "shin": "trousers",
    "lower_leg": "skin",
    "foot": "shoes",
    "instep": "shoes",
    "toes": "shoes",
}
#: Drawn radii (fractions of body height) that differ from the body volume of
#: :data:`~.scene.CAPSULES`, which the truth's visibility keeps using: the
#: sleeve is a loose cylinder standing off the upper arm, so it ends at the
#: elbow in a cuff wider than the forearm.  With a sleeve as thin as the arm,
#: an upper arm pointing at the camera (arm to the side seen from the side)
#: vanished into the shirt of the torso behind it, the skin forearm read as
#: the whole arm and BlazePose put the elbow half-way up it (side view: right
#: elbow PCK 0.89, detected 6 px high on average).
_DRAWN_RADII = {"upper_arm": (0.036, 0.036)}
# Drawn otherwise: the torso capsules as clothed hulls, the head as ellipses.
_HULL_PARTS = {"shoulders", "chest", "belly", "pelvis", "hips", "head"}

# Torso rings: (joint they ride on, height, half-width, half-depth), fractions
# of body height, in the rest pose.
_SHIRT_RINGS = (
    ("chest", 0.842, 0.040, 0.035),
    ("chest", 0.826, 0.105, 0.045),
    ("chest", 0.800, 0.132, 0.050),
    ("chest", 0.735, 0.105, 0.068),
    ("waist", 0.640, 0.086, 0.058),
    ("waist", 0.610, 0.088, 0.058),
)
_TROUSER_RINGS = (
    ("waist", 0.615, 0.089, 0.059),
    ("pelvis", 0.535, 0.108, 0.070),
    ("pelvis", 0.470, 0.098, 0.062),
)
_RING_POINTS = 10
# V-neck of the shirt: collar corners and the point of the V (rest, fractions of H).
_COLLAR = ((-0.046, 0.040, 0.836), (0.046, 0.040, 0.836), (0.0, 0.062, 0.766))
# Head ellipses: (scale, shift towards the light in semi-axes).
_HEAD_LAYERS = ((1.0, 0.0), (0.86, 0.10), (0.45, 0.35))
_FACE_POINTS = (
    "left_eye",
    "right_eye",
    "nose",
    "mouth_left",
    "mouth_right",
    "left_ear",
    "right_ear",
    "left_eye_inner",
    "right_eye_inner",
    "left_eye_outer",
    "right_eye_outer",
)


def fixed(p: np.ndarray) -> np.ndarray:
    """Pixel coordinates as OpenCV fixed-point integers (:data:`SHIFT` bits)."""
    return np.round(np.clip(np.nan_to_num(p, nan=-1e4), -3e4, 3e4) * _ONE).astype(np.int32)


def capsule_outlines(p0: np.ndarray, p1: np.ndarray, r0: np.ndarray, r1: np.ndarray, n_arc: int = 7) -> np.ndarray:
    """Convex outline of 2D capsules (two circles and their outer tangents).

    Parameters
    ----------
    p0, p1 : (..., 2) ndarray
        End centres, pixels.
    r0, r1 : (...) ndarray
        End radii, pixels.
    n_arc : int
        Points per end arc.

    Returns
    -------
    (..., 2 * n_arc, 2) ndarray
        Polygon vertices in order.
    """
    d = p1 - p0
    length = np.linalg.norm(d, axis=-1)
    # One circle swallows the other: draw the bigger circle.
    swallow = length <= np.abs(r1 - r0) + 1e-6
    big_first = r0 >= r1
    p0 = np.where((swallow & ~big_first)[..., None], p1, p0)
    p1 = np.where((swallow & big_first)[..., None], p0, p1)
    rmax = np.maximum(r0, r1)
    r0 = np.where(swallow, rmax, r0)
    r1 = np.where(swallow, rmax, r1)
    d = p1 - p0
    length = np.linalg.norm(d, axis=-1)
    safe = length > 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        ux = np.where(safe, d[..., 0] / length, 1.0)
        uy = np.where(safe, d[..., 1] / length, 0.0)
        sphi = np.where(safe, np.clip((r0 - r1) / length, -0.999, 0.999), 0.0)
    phi = np.arcsin(sphi)
    k = np.linspace(0.0, 1.0, n_arc)
    # Angles relative to the axis direction: the tangent points lie at ±(90° − φ).
    a0 = (np.pi / 2 - phi)[..., None] + k * (np.pi + 2 * phi)[..., None]
    a1 = (3 * np.pi / 2 + phi)[..., None] + k * (np.pi - 2 * phi)[..., None]
    ang = np.concatenate([a0, a1], axis=-1)
    base = np.arctan2(uy, ux)[..., None]
    rad = np.concatenate([np.repeat(r0[..., None], n_arc, -1), np.repeat(r1[..., None], n_arc, -1)], -1)
    cx = np.concatenate([np.repeat(p0[..., :1], n_arc, -1), np.repeat(p1[..., :1], n_arc, -1)], -1)
    cy = np.concatenate([np.repeat(p0[..., 1:], n_arc, -1), np.repeat(p1[..., 1:], n_arc, -1)], -1)
    return np.stack([cx + rad * np.cos(base + ang), cy + rad * np.sin(base + ang)], axis=-1)


def _gain(colour, g: float) -> tuple[int, int, int]:
    c = np.asarray(colour, float)
    if g > 1.0:  # highlights go towards white rather than saturating
        c = c + (255.0 - c) * (g - 1.0) * 1.6
    else:
        c = c * g
    return tuple(int(v) for v in np.clip(c, 0, 255))


def _unsided(name: str) -> str:
    """``right_upper_arm`` → ``upper_arm``."""
    for side in ("right_", "left_"):
        if name.startswith(side):
            return name[len(side) :]
    return name


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v)
    return v / n if n > 1e-9 else np.array([0.0, -1.0])


def _ellipse_params(cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Semi-axes (…, 2) and angle (…) degrees of 2D covariance-shaped ellipses."""
    w, v = np.linalg.eigh(cov)
    axes = np.sqrt(np.maximum(w, 1e-9))
    angle = np.degrees(np.arctan2(v[..., 1, 1], v[..., 0, 1]))
    return axes[..., ::-1], angle  # major first, angle of the major axis


class Mannequin:
    """Shaded-capsule renderer of a posed body seen by one camera.

    Parameters
    ----------
    pose : Pose
    camera : Camera
    """

    style = "mannequin"

    def __init__(self, pose: Pose, camera: Camera):
        self.pose, self.camera = pose, camera
        h = camera.size[1]
        self.background = floor_background(camera, line_width=max(1, round(h / 480)))
        a, b, radii = body_capsules(pose)
        (ua, za), (ub, zb) = camera.project(a, True), camera.project(b, True)
        f = camera.K[1, 1]
        names = [c[0] for c in CAPSULES]
        H = pose.body.height
        radii = np.array([_DRAWN_RADII.get(_unsided(n), r) for n, r in zip(names, radii / H)]) * H
        ra, rb = radii[:, 0] * f / za, radii[:, 1] * f / zb
        keep = [i for i, n in enumerate(names) if n not in _HULL_PARTS]
        # Colours per capsule and shading layer, precomputed for the draw loop.
        self._limb_colour = [[_gain(PALETTE[_PART_COLOUR[_unsided(names[i])]], g) for _, _, g in LAYERS] for i in keep]
        # Painter's key: the nearest point of the capsule's axis middle.
        self._limb_depth = 0.5 * (za + zb)[:, keep] - 0.5 * (radii[keep, 0] + radii[keep, 1])
        grow = np.maximum(ra, rb)[:, keep, None, None]
        self._limb_polys = [
            fixed(capsule_outlines(ua[:, keep], ub[:, keep], ra[:, keep] * sc, rb[:, keep] * sc) + sh * LIGHT * grow)
            for sc, sh, _ in LAYERS
        ]
        self._hulls = [self._hull_points(_SHIRT_RINGS), self._hull_points(_TROUSER_RINGS)]
        chest, pelvis = joint_index("chest"), joint_index("pelvis")
        self._hull_depth = np.stack([camera.depth(pose.joints[:, chest]), camera.depth(pose.joints[:, pelvis])], 1)
        self._hull_colour = [[_gain(PALETTE[c], g) for _, _, g in _HULL_LAYERS] for c in ("shirt", "trousers")]
        self._head = self._head_geometry()
        self._collar, self._collar_seen = self._collar_geometry()
        self._collar_colour = _gain(PALETTE["skin"], 0.9)
        skin, hair = PALETTE["skin"], PALETTE["hair"]
        self._head_colours = {
            "skin": skin,
            "skin_rim": _gain(skin, 0.62),
            "skin_light": _gain(skin, 1.08),
            "hair": hair,
            "hair_rim": _gain(hair, 0.62),
            "ear": _gain(skin, 0.8),
            "nose_rim": _gain(skin, 0.72),
            "nose": _gain(skin, 0.98),
        }
        self._shadow = self._shadow_polygons()

    # ---------------------------------------------------------------- geometry
    def _hull_points(self, rings) -> tuple[np.ndarray, np.ndarray]:
        """Projected ring points (T, N, 2) and their centroid (T, 2)."""
        pose, H = self.pose, self.pose.body.height
        ang = np.linspace(0, 2 * np.pi, _RING_POINTS, endpoint=False)
        pts, ids = [], []
        for joint, z, hw, hd in rings:
            j = joint_index(joint)
            rest = np.stack([hw * np.cos(ang), hd * np.sin(ang), np.full_like(ang, z)], 1) * H
            pts.append(rest - pose.body.rest[j])
            ids += [j] * _RING_POINTS
        offsets = np.concatenate(pts)
        world = pose.joints[:, ids] + np.einsum("tnij,nj->tni", pose.rotations[:, ids], offsets)
        uv = self.camera.project(world)
        return uv, np.nanmean(uv, axis=1)

    def _head_geometry(self) -> dict:
        """Everything the head needs, per frame, as OpenCV fixed-point Python ints."""
        pose, cam = self.pose, self.camera
        H, f = pose.body.height, cam.K[1, 1]
        axes = pose.head_axes()  # (T,3,3) rows right, forward, up
        radii = np.array(HEAD_RADII) * H
        centre = pose.points["head_centre"]
        # Hair: an ellipsoid set back and up, so it caps the head seen from the
        # front and covers it seen from behind.
        hair_centre = centre - 0.14 * radii[1] * axes[:, 1] + 0.13 * radii[2] * axes[:, 2]
        out = {}
        for key, c, r in (("skin", centre, radii), ("hair", hair_centre, radii * (1.06, 1.0, 0.97))):
            uv, z = cam.project(c, True)
            # Silhouette of the ellipsoid: its covariance through the local
            # (affine) projection at its centre.
            J = f / z[:, None, None] * cam.R[None, :2]  # (T,2,3)
            M = J @ (np.swapaxes(axes, 1, 2) * r)
            half, angle = _ellipse_params(M @ np.swapaxes(M, 1, 2))
            for scale, shift in _HEAD_LAYERS:
                out[(key, scale)] = (
                    fixed(uv + shift * half[:, :1] * LIGHT).tolist(),
                    fixed(np.maximum(half * scale, 0.5)).tolist(),
                    angle.tolist(),
                )
        to_cam = cam.position - centre
        to_cam /= np.linalg.norm(to_cam, axis=1, keepdims=True)
        out["depth"] = cam.depth(centre) - radii[1]
        s = f / cam.depth(centre) * H  # pixels per body height
        out["thin"] = np.maximum(1, np.round(0.007 * s)).astype(int).tolist()
        pts = {n: cam.project(pose.points[n]) for n in _FACE_POINTS}
        # Outward normals of the features decide which ones face the camera.
        cos = {
            n: np.sum((pose.points[n] - centre) * to_cam, 1) / np.linalg.norm(pose.points[n] - centre, axis=1)
            for n in _FACE_POINTS
        }
        side = np.sum(axes[:, 0] * to_cam, axis=1)  # > 0: the right ear is seen
        facing_cos = np.sum(axes[:, 1] * to_cam, axis=1)
        facing = facing_cos > -0.3
        # The hair covers the face only when the head faces away.  (Ordering
        # the two ellipsoids by centre depth put the hair, which sits higher,
        # over the face of a head tilted back and seen from below: the pose
        # model then read the body as seen from behind.)
        out["hair_on_top"] = (facing_cos < -0.3).tolist()
        r = np.maximum(1.0, 0.016 * s)
        ear_axes = fixed(np.stack([0.6 * r, r], 1)).tolist()
        out["ears"] = [
            ((side > -0.35) & (cos["right_ear"] > -0.35)).tolist(),
            fixed(pts["right_ear"]).tolist(),
            ear_axes,
            ((side < 0.35) & (cos["left_ear"] > -0.35)).tolist(),
            fixed(pts["left_ear"]).tolist(),
            ear_axes,
        ]
        up = pts["left_eye"] + pts["right_eye"] - pts["mouth_left"] - pts["mouth_right"]
        up /= np.maximum(np.linalg.norm(up, axis=1, keepdims=True), 1e-9)
        out["eyes"] = []
        for side_name in ("left", "right"):
            inner, outer = pts[f"{side_name}_eye_inner"], pts[f"{side_name}_eye_outer"]
            half = np.maximum(1.0, 0.5 * np.linalg.norm(outer - inner, axis=1))
            d = outer - inner
            brow = up * 1.1 * half[:, None]
            out["eyes"].append(
                (
                    (facing & (cos[f"{side_name}_eye"] > 0.1)).tolist(),
                    fixed(pts[f"{side_name}_eye"]).tolist(),
                    fixed(np.stack([half, 0.55 * half], 1)).tolist(),
                    np.degrees(np.arctan2(d[:, 1], d[:, 0])).tolist(),
                    np.round(np.maximum(0.8, 0.45 * half) * _ONE).astype(int).tolist(),
                    fixed(inner + brow).tolist(),
                    fixed(outer + 0.8 * brow).tolist(),
                )
            )
        # The nose: a small tapered capsule from its root to its tip, which
        # rounds the profile (a nose standing further out of the head measured
        # slightly worse with BlazePose at the body joints).
        (r_uv, r_z), (t_uv, t_z) = cam.project(pose.points["nose_root"], True), cam.project(pose.points["nose"], True)
        out["nose"] = (facing & (cos["nose"] > -0.25)).tolist()
        out["nose_polys"] = [
            fixed(capsule_outlines(r_uv, t_uv, sc * 0.008 * H * f / r_z, sc * 0.011 * H * f / t_z)) for sc in (1.0, 0.6)
        ]
        out["mouth"] = (facing & (np.maximum(cos["mouth_left"], cos["mouth_right"]) > 0.0)).tolist()
        out["mouth_pts"] = (fixed(pts["mouth_left"]).tolist(), fixed(pts["mouth_right"]).tolist())
        return out

    def _collar_geometry(self) -> tuple[np.ndarray, list]:
        """A V-neck at the front of the shirt (a front/back cue), (T, 3, 2) fixed points, seen flags."""
        pose, H = self.pose, self.pose.body.height
        chest = joint_index("chest")
        rest = np.array(_COLLAR) * H - pose.body.rest[chest]
        world = attached_points(pose.joints, pose.rotations, [chest] * 3, rest)
        front = pose.rotations[:, chest, :, 1]  # the chest's forward axis
        to_cam = self.camera.position - world.mean(axis=1)
        cos = np.sum(front * to_cam, 1) / np.linalg.norm(to_cam, axis=1)
        return fixed(self.camera.project(world)), (cos > 0.15).tolist()

    def _shadow_polygons(self) -> np.ndarray:
        H = self.pose.body.height
        ang = np.linspace(0, 2 * np.pi, 20, endpoint=False)
        root = self.pose.root
        ring = np.stack([0.22 * H * np.cos(ang), 0.14 * H * np.sin(ang), np.zeros_like(ang)], 1)
        world = np.concatenate([root[:, None, :2] + ring[None, :, :2], np.zeros((len(root), 20, 1))], axis=2)
        return fixed(self.camera.project(world))

    # ----------------------------------------------------------------- drawing
    def __len__(self) -> int:
        return self.pose.n_frames

    def frame(self, i: int) -> np.ndarray:
        """The image of frame `i`, (H, W, 3) uint8 BGR."""
        img = self.background.copy()
        cv2.fillPoly(img, [self._shadow[i]], PALETTE["shadow"], cv2.LINE_AA, SHIFT)
        n_limbs = self._limb_depth.shape[1]
        depth = np.concatenate([self._limb_depth[i], self._hull_depth[i], [self._head["depth"][i]]])
        for k in np.argsort(-depth, kind="stable"):
            if k < n_limbs:
                for colour, polys in zip(self._limb_colour[k], self._limb_polys):
                    cv2.fillConvexPoly(img, polys[i, k], colour, cv2.LINE_AA, SHIFT)
            elif k < n_limbs + 2:
                self._draw_hull(img, i, k - n_limbs)
            else:
                self._draw_head(img, i)
        return img

    def _draw_hull(self, img, i: int, which: int) -> None:
        uv, centre = self._hulls[which]
        pts = uv[i]
        if not np.isfinite(pts).all():
            return
        hull = cv2.convexHull(pts.astype(np.float32)).reshape(-1, 2)
        c = centre[i]
        size = np.sqrt(cv2.contourArea(hull) + 1.0)
        for (sc, sh, _), colour in zip(_HULL_LAYERS, self._hull_colour[which]):
            poly = c + (hull - c) * sc + sh * 0.5 * size * LIGHT
            cv2.fillConvexPoly(img, np.rint(poly * _ONE).astype(np.int32), colour, cv2.LINE_AA, SHIFT)
        if which == 0 and self._collar_seen[i]:
            cv2.fillConvexPoly(img, self._collar[i], self._collar_colour, cv2.LINE_AA, SHIFT)

    def _ellipse(self, img, key: str, scale: float, i: int, colour) -> None:
        centre, half, angle = (
            self._head[(key, scale)][0][i],
            self._head[(key, scale)][1][i],
            self._head[(key, scale)][2][i],
        )
        cv2.ellipse(img, centre, half, angle, 0, 360, colour, -1, cv2.LINE_AA, SHIFT)

    def _draw_head(self, img, i: int) -> None:
        hd, col = self._head, self._head_colours
        hair_on_top = hd["hair_on_top"][i]
        order = ("skin", "hair") if hair_on_top else ("hair", "skin")
        for key in order:
            self._ellipse(img, key, 1.0, i, col[key + "_rim"])
            self._ellipse(img, key, 0.86, i, col[key])
        if not hair_on_top:
            # Hair behind: the face shows; its highlight sits on the forehead side.
            self._ellipse(img, "skin", 0.45, i, col["skin_light"])
        show_r, c_r, a_r, show_l, c_l, a_l = hd["ears"]
        for show, c, a in ((show_r, c_r, a_r), (show_l, c_l, a_l)):
            if show[i]:
                cv2.ellipse(img, c[i], a[i], 0, 0, 360, col["ear"], -1, cv2.LINE_AA, SHIFT)
        thin = hd["thin"][i]
        for show, c, half, ang, iris, b0, b1 in hd["eyes"]:
            if show[i]:
                cv2.ellipse(img, c[i], half[i], ang[i], 0, 360, PALETTE["eye_white"], -1, cv2.LINE_AA, SHIFT)
                cv2.circle(img, c[i], iris[i], PALETTE["iris"], -1, cv2.LINE_AA, SHIFT)
                cv2.line(img, b0[i], b1[i], PALETTE["brow"], thin, cv2.LINE_AA, SHIFT)
        if hd["nose"][i]:
            for poly, colour in zip(hd["nose_polys"], (col["nose_rim"], col["nose"])):
                cv2.fillConvexPoly(img, poly[i], colour, cv2.LINE_AA, SHIFT)
        if hd["mouth"][i]:
            cv2.line(img, hd["mouth_pts"][0][i], hd["mouth_pts"][1][i], PALETTE["mouth"], thin, cv2.LINE_AA, SHIFT)
