"""A pinhole perspective camera in the OpenCV convention.

World frame (DESIGN.md): right-handed, metres, z up, floor at z = 0, the
performer at the origin facing +y with their right on +x.  Camera frame
(OpenCV): x right, y down, z forward along the optical axis, so that

    x_cam = R @ x_world + t,    [u, v, 1]ᵀ ∝ K @ x_cam.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from capture2notation.errors import SyntheticError

__all__ = ["VIEWS", "Camera", "look_at_rotation"]

#: Named viewpoints: azimuth of the camera around the performer, degrees
#: clockwise seen from above, from the performer's front (+y) towards their
#: right (+x); ``-45`` is half-way round towards their left (the 45° / −45°
#: camera pair of a two-camera capture).
VIEWS: dict[str, float] = {"front": 0.0, "45": 45.0, "side": 90.0, "-45": -45.0}

# Extent of the space a performance may fill, as fractions of body height,
# relative to the starting pelvis: arms overhead reach 1.26 H above the floor,
# an arm or a leg held to the side 0.56 H from the centre line.  The margins
# leave room for a little travel of the root.
_TOP = 1.32
_BOTTOM = -0.06
_HALF_WIDTH = 0.72
_DEPTH_MARGIN = 0.35  # the nearest body part may be this much closer than the centre
_EYE_HEIGHT = 0.62  # camera height, fraction of body height: floor and horizon both visible
_DEFAULT_FOV_Y = 40.0
#: Least angle, degrees, between the frame's edge and the space a performance
#: fills that a pitched camera must leave (below it the head or feet are cut).
_MIN_MARGIN_DEG = 3.0


def look_at_rotation(position, target, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """World-to-camera rotation of a camera at `position` looking at `target`.

    Parameters
    ----------
    position, target : (3,) array_like
        World coordinates, metres.
    up : (3,) array_like
        World direction that should appear upwards in the image.

    Returns
    -------
    (3, 3) ndarray
        Rows are the camera's x (right), y (down) and z (forward) axes in
        world coordinates.
    """
    position = np.asarray(position, dtype=float)
    forward = np.asarray(target, dtype=float) - position
    n = np.linalg.norm(forward)
    if not np.isfinite(n) or n < 1e-9:
        raise SyntheticError(f"camera position {position.tolist()} coincides with its target")
    forward /= n
    right = np.cross(forward, np.asarray(up, dtype=float))
    rn = np.linalg.norm(right)
    if rn < 1e-9:
        raise SyntheticError(f"camera looks along its up vector {list(up)}; choose another up")
    right /= rn
    down = np.cross(forward, right)
    return np.stack([right, down, forward])


@dataclass(frozen=True, eq=False)
class Camera:
    """Intrinsics and extrinsics of a pinhole camera.

    Parameters
    ----------
    K : (3, 3) ndarray
        Intrinsic matrix (focal lengths and principal point in pixels).
    R : (3, 3) ndarray
        World-to-camera rotation.
    t : (3,) ndarray
        World-to-camera translation, metres: ``x_cam = R @ x_world + t``.
    size : (int, int)
        Image (width, height) in pixels.
    """

    K: np.ndarray
    R: np.ndarray
    t: np.ndarray
    size: tuple
    position: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        K = np.array(self.K, dtype=float)
        R = np.array(self.R, dtype=float)
        t = np.array(self.t, dtype=float)
        if K.shape != (3, 3) or R.shape != (3, 3) or t.shape != (3,):
            raise SyntheticError(f"camera K, R, t must be (3,3), (3,3), (3,); got {K.shape}, {R.shape}, {t.shape}")
        if not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0:
            raise SyntheticError("camera R must be a proper rotation matrix")
        w, h = _check_size(self.size)
        for name, value in (("K", K), ("R", R), ("t", t)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "size", (w, h))
        pos = -R.T @ t
        pos.setflags(write=False)
        object.__setattr__(self, "position", pos)

    @classmethod
    def look_at(cls, position, target, fov_y_deg: float, size, up=(0.0, 0.0, 1.0)) -> Camera:
        """Camera at `position` looking at `target` with a vertical field of view.

        Parameters
        ----------
        position, target : (3,) array_like
            World coordinates, metres.
        fov_y_deg : float
            Vertical field of view, degrees, in (0, 180).
        size : (int, int)
            Image (width, height), pixels; square pixels, principal point at
            the image centre.
        """
        if not 0.0 < float(fov_y_deg) < 180.0:
            raise SyntheticError(f"vertical field of view {fov_y_deg!r} deg must lie in (0, 180)")
        w, h = _check_size(size)
        f = 0.5 * h / np.tan(np.radians(fov_y_deg) / 2.0)
        K = np.array([[f, 0.0, w / 2.0], [0.0, f, h / 2.0], [0.0, 0.0, 1.0]])
        R = look_at_rotation(position, target, up)
        t = -R @ np.asarray(position, dtype=float)
        return cls(K, R, t, (w, h))

    @classmethod
    def for_view(
        cls,
        view: str = "front",
        size=(640, 480),
        body_height: float = 1.70,
        fov_y_deg: float = _DEFAULT_FOV_Y,
    ) -> Camera:
        """A preset viewpoint that frames a performer standing at the origin.

        The distance is chosen so that the whole body fits with a margin
        whatever it does in place: arms overhead, an arm or leg held out to
        the side, a little travel of the pelvis.

        Parameters
        ----------
        view : {"front", "45", "side", "-45"}
            ``front``: on +y looking back at the performer; ``45``: half-way
            round towards the performer's right; ``side``: from the
            performer's right (+x); ``-45``: half-way round towards their left.
        size : (int, int)
            Image (width, height), pixels.
        body_height : float
            Performer's height, metres.
        fov_y_deg : float
            Vertical field of view, degrees.
        """
        if view not in VIEWS:
            raise SyntheticError(f"unknown view {view!r}; expected one of {', '.join(VIEWS)}")
        if not (np.isfinite(body_height) and body_height > 0):
            raise SyntheticError(f"body height {body_height!r} m must be positive")
        w, h = _check_size(size)
        H = float(body_height)
        half_fy = np.radians(fov_y_deg) / 2.0
        half_fx = np.arctan(np.tan(half_fy) * w / h)
        half_height = 0.5 * (_TOP - _BOTTOM) * H
        centre_z = 0.5 * (_TOP + _BOTTOM) * H
        # The camera is a little below the frame centre and tilts up; the
        # frame must hold the extent at the nearest depth the body can reach.
        dist = max(half_height / np.tan(half_fy), _HALF_WIDTH * H / np.tan(half_fx)) + _DEPTH_MARGIN * H
        az = np.radians(VIEWS[view])
        position = np.array([dist * np.sin(az), dist * np.cos(az), _EYE_HEIGHT * H])
        target = np.array([0.0, 0.0, centre_z])
        return cls.look_at(position, target, fov_y_deg, (w, h))

    @classmethod
    def phone(
        cls,
        view: str = "front",
        size=(640, 480),
        body_height: float = 1.70,
        height: float | None = None,
        pitch_deg: float = 0.0,
        roll_deg: float = 0.0,
        hfov_deg: float | None = None,
    ) -> Camera:
        """A phone on a tripod or a table: set height, pitch, roll and field of view.

        The camera stands on the `view`'s azimuth at `height` above the
        floor, its optical axis turned towards the performer, pitched by
        `pitch_deg` (positive looks up) and rolled by `roll_deg` about the
        optical axis (positive turns the camera clockwise, seen from behind
        it).  Its distance is the nearest at which the space a performance
        fills stays in the frame.

        Parameters
        ----------
        view : {"front", "45", "side", "-45"}
        size : (int, int)
            Image (width, height), pixels.
        body_height : float
            Performer's height, metres.
        height : float, optional
            Camera centre above the floor, metres (default: the preset's).
        pitch_deg, roll_deg : float
            Degrees.
        hfov_deg : float, optional
            Horizontal field of view, degrees (default: the preset's).

        Raises
        ------
        SyntheticError
            A camera that cannot frame the performer (e.g. pitched down from
            below the head so far that the head is always cut off).
        """
        if view not in VIEWS:
            raise SyntheticError(f"unknown view {view!r}; expected one of {', '.join(VIEWS)}")
        w, h = _check_size(size)
        H = float(body_height)
        cam_h = _EYE_HEIGHT * H if height is None else float(height)
        half_fy0 = np.radians(_DEFAULT_FOV_Y) / 2.0
        half_fx = np.arctan(np.tan(half_fy0) * w / h) if hfov_deg is None else np.radians(float(hfov_deg)) / 2.0
        half_fy = np.arctan(np.tan(half_fx) * h / w)
        # Roll turns the frame: keep the space inside the rotated frame's inscribed margin.
        shrink = 1.0 / (1.0 + np.sin(abs(np.radians(roll_deg))) * max(w, h) / min(w, h))
        half_up = np.arctan(np.tan(half_fy) * shrink) + np.radians(pitch_deg)
        half_down = np.arctan(np.tan(half_fy) * shrink) - np.radians(pitch_deg)
        if min(half_up, half_down) < np.radians(_MIN_MARGIN_DEG):
            raise SyntheticError(
                f"a camera {cam_h:g} m high pitched {pitch_deg:g}° with a {np.degrees(2 * half_fx):.0f}° "
                "horizontal field of view cannot frame the whole performer"
            )
        top, bottom = _TOP * H - cam_h, cam_h - _BOTTOM * H
        need = [_HALF_WIDTH * H / np.tan(np.arctan(np.tan(half_fx) * shrink))]
        need.append(top / np.tan(half_up) if top > 0 else 0.0)
        need.append(bottom / np.tan(half_down) if bottom > 0 else 0.0)
        dist = max(need) + _DEPTH_MARGIN * H
        az = np.radians(VIEWS[view])
        position = np.array([dist * np.sin(az), dist * np.cos(az), cam_h])
        flat = look_at_rotation(position, np.array([0.0, 0.0, cam_h]))
        right, forward = flat[0], flat[2]
        p, r = np.radians(pitch_deg), np.radians(roll_deg)
        forward = np.cos(p) * forward + np.sin(p) * np.array([0.0, 0.0, 1.0])
        down = np.cross(forward, right)
        right, down = np.cos(r) * right + np.sin(r) * down, -np.sin(r) * right + np.cos(r) * down
        R = np.stack([right, down, forward])
        f = 0.5 * w / np.tan(half_fx)
        K = np.array([[f, 0.0, w / 2.0], [0.0, f, h / 2.0], [0.0, 0.0, 1.0]])
        return cls(K, R, -R @ position, (w, h))

    # ------------------------------------------------------------------ maths
    def to_camera(self, points) -> np.ndarray:
        """World points in camera coordinates.

        Parameters
        ----------
        points : (..., 3) array_like
            World coordinates, metres.

        Returns
        -------
        (..., 3) ndarray
            Camera coordinates (x right, y down, z forward), metres.
        """
        p = np.asarray(points, dtype=float)
        return p @ self.R.T + self.t

    def depth(self, points) -> np.ndarray:
        """Distance along the optical axis, metres, shape ``points.shape[:-1]``."""
        p = np.asarray(points, dtype=float)
        return p @ self.R[2] + self.t[2]

    def project(self, points, return_depth: bool = False):
        """Pixel coordinates of world points.

        Parameters
        ----------
        points : (..., 3) array_like
            World coordinates, metres.
        return_depth : bool
            Also return the camera depth.

        Returns
        -------
        uv : (..., 2) ndarray
            Pixel (x right, y down); NaN for points at or behind the camera
            centre (depth <= 0).
        depth : (...) ndarray
            Only if `return_depth`.
        """
        c = self.to_camera(points)
        z = c[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            zz = np.where(z > 1e-9, z, np.nan)
            u = self.K[0, 0] * c[..., 0] / zz + self.K[0, 1] * c[..., 1] / zz + self.K[0, 2]
            v = self.K[1, 1] * c[..., 1] / zz + self.K[1, 2]
        uv = np.stack([u, v], axis=-1)
        return (uv, z) if return_depth else uv

    def pixel_scale(self, depth) -> np.ndarray:
        """Pixels per metre of a fronto-parallel length at `depth` metres."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.K[1, 1] / np.asarray(depth, dtype=float)

    def in_image(self, uv) -> np.ndarray:
        """True where pixel coordinates ``(..., 2)`` fall inside the image.

        Pixel centres are at integer coordinates (OpenCV), so the image
        covers [−0.5, width − 0.5) × [−0.5, height − 0.5); NaN is outside.
        """
        uv = np.asarray(uv, dtype=float)
        w, h = self.size
        with np.errstate(invalid="ignore"):
            return (uv[..., 0] >= -0.5) & (uv[..., 0] < w - 0.5) & (uv[..., 1] >= -0.5) & (uv[..., 1] < h - 0.5)


def _check_size(size) -> tuple[int, int]:
    try:
        w, h = (int(s) for s in size)
        ok = all(float(s) == int(s) for s in size)
    except (TypeError, ValueError):
        raise SyntheticError(f"image size must be (width, height) in pixels, got {size!r}") from None
    if not ok or w < 16 or h < 16 or w > 8192 or h > 8192:
        raise SyntheticError(f"image size {size!r} must be whole pixels, each 16-8192")
    return w, h
