"""Pinhole camera for fitting.

OpenCV convention (ARCHITECTURE.md): ``x_cam = R @ x_world + t`` with camera
x right, y down, z forward; pixels ``u = fx·x/z + cx``, ``v = fy·y/z + cy``.

A known camera comes only from a calibration file the user names
(:meth:`Camera.from_calibration`; DESIGN.md, "What a capture may know").
Otherwise the camera is :meth:`Camera.default`: upright and level, in front of the
performer (on +y, looking towards −y) at :data:`DEFAULT_DISTANCE` and
:data:`DEFAULT_HEIGHT`, with a horizontal field of view of
:data:`DEFAULT_HFOV_DEG`; the fitter refines the focal length from the data
(:func:`capture2notation.fitting.fit.refine_focal`) and the floor from the feet.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import FittingError

__all__ = ["DEFAULT_DISTANCE", "DEFAULT_HEIGHT", "DEFAULT_HFOV_DEG", "Camera", "calibrated_camera", "undistort_track"]

#: Largest distortion coefficient the pinhole fit ignores: at 1e-3 a point at
#: the image corner moves by well under a pixel at phone resolutions.
_MAX_IGNORED_DISTORTION = 1e-3
#: Default horizontal field of view, degrees (a phone's main camera is 65-75°
#: in landscape; rehearsal footage is often zoomed a little).
DEFAULT_HFOV_DEG = 60.0
#: Default distance of the camera from the performer, metres.
DEFAULT_DISTANCE = 4.0
#: Default height of the camera's centre above the floor, metres.
DEFAULT_HEIGHT = 1.0


@dataclass(frozen=True, eq=False)
class Camera:
    """A pinhole camera.

    Parameters
    ----------
    K : (3, 3) ndarray
        Intrinsics, pixels.
    R : (3, 3) ndarray
        World-to-camera rotation.
    t : (3,) ndarray
        World-to-camera translation, metres.
    image_size : (2,) tuple of int
        (width, height), pixels.
    """

    K: np.ndarray
    R: np.ndarray
    t: np.ndarray
    image_size: tuple[int, int]

    def __post_init__(self):
        K = np.asarray(self.K, float)
        R = np.asarray(self.R, float)
        t = np.asarray(self.t, float).reshape(-1)
        if K.shape != (3, 3) or R.shape != (3, 3) or t.shape != (3,):
            raise FittingError(f"camera needs K (3,3), R (3,3), t (3,); got {K.shape}, {R.shape}, {t.shape}")
        if not (np.all(np.isfinite(K)) and np.all(np.isfinite(R)) and np.all(np.isfinite(t))):
            raise FittingError("camera K, R and t must be finite")
        if not np.allclose(R @ R.T, np.eye(3), atol=1e-5):
            raise FittingError(f"camera R is not a rotation matrix: R @ R.T = {np.round(R @ R.T, 4).tolist()}")
        if K[0, 0] <= 0 or K[1, 1] <= 0:
            raise FittingError(f"camera focal lengths must be positive, got fx={K[0, 0]}, fy={K[1, 1]}")
        size = tuple(int(v) for v in self.image_size)
        if len(size) != 2 or min(size) <= 0:
            raise FittingError(f"image_size must be (width, height) > 0, got {self.image_size!r}")
        for k, v in (("K", K), ("R", R), ("t", t), ("image_size", size)):
            object.__setattr__(self, k, v)

    @classmethod
    def default(
        cls,
        image_size,
        hfov_deg: float = DEFAULT_HFOV_DEG,
        distance: float = DEFAULT_DISTANCE,
        height: float = DEFAULT_HEIGHT,
        roll_deg: float = 0.0,
    ) -> Camera:
        """Level camera on +y looking at the origin (DESIGN.md's front view).

        Parameters
        ----------
        image_size : (width, height)
            Pixels.
        hfov_deg : float
            Horizontal field of view, degrees, in (1, 179).
        distance, height : float
            Camera position ``(0, distance, height)`` in metres.
        roll_deg : float
            Turn about the optical axis, degrees, positive clockwise seen from
            behind the camera (the convention of
            :func:`~capture2notation.fitting.camera_estimate.pitch_roll`), in
            [-45, 45]; 0 is upright.
        """
        if not 1.0 < hfov_deg < 179.0:
            raise FittingError(f"hfov_deg must be in (1, 179) degrees, got {hfov_deg}")
        if not -45.0 <= roll_deg <= 45.0:
            raise FittingError(f"roll_deg must be in [-45, 45] degrees, got {roll_deg}")
        w, h = (int(v) for v in image_size)
        f = 0.5 * w / np.tan(np.deg2rad(hfov_deg) / 2)
        K = np.array([[f, 0.0, w / 2], [0.0, f, h / 2], [0.0, 0.0, 1.0]])
        # Camera x = world -x, camera y (down) = world -z, camera z = world -y.
        R = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]])
        c, s = np.cos(np.radians(roll_deg)), np.sin(np.radians(roll_deg))
        R = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) @ R
        centre = np.array([0.0, distance, height])
        return cls(K, R, -R @ centre, (w, h))

    @classmethod
    def from_truth(cls, truth) -> Camera:
        """Camera of a truth sidecar (a ``Truth`` or a mapping with ``K``, ``R``, ``t``, ``image_size``)."""

        def get(name):
            if hasattr(truth, name):
                return getattr(truth, name)
            try:
                return truth[name]
            except (KeyError, TypeError):
                raise FittingError(f"truth sidecar has no camera field {name!r}") from None

        return cls(get("K"), get("R"), get("t"), tuple(int(v) for v in np.asarray(get("image_size")).tolist()))

    @classmethod
    def from_calibration(cls, calibration, video, image_size, undistorted: bool = False) -> Camera:
        """The camera of `video` in a calibration (``capture2notation.io.calibration``).

        Parameters
        ----------
        calibration : Calibration
            As read by :func:`~capture2notation.io.calibration.read_calibration`.
        video : str or Path
            The clip; with several cameras in the calibration, its camera is the
            one named :func:`~capture2notation.io.calibration.camera_name` of it.
            A calibration of one camera is that clip's camera whatever its name.
        image_size : (int, int)
            (width, height) of the clip's frames, pixels; must equal the
            calibration's (a calibration of other images does not describe them).
        undistorted : bool
            The clip's keypoints have had the lens distortion removed
            (:func:`undistort_track`); only then is a camera with distortion
            accepted, as its pinhole part.

        Raises
        ------
        FittingError
            No camera of that name, or other image sizes.  Distortion is not
            modelled by the fit: a calibration with distortion is refused
            unless the keypoints were undistorted.
        """
        cam = calibrated_camera(calibration, video)
        name = cam.name
        size = tuple(int(v) for v in image_size)
        if tuple(cam.image_size) != size:
            raise FittingError(
                f"{video}: frames are {size[0]}x{size[1]} but camera {name!r} is calibrated for "
                f"{cam.image_size[0]}x{cam.image_size[1]}"
            )
        if not undistorted and np.any(np.abs(cam.dist) > _MAX_IGNORED_DISTORTION):
            raise FittingError(
                f"{video}: camera {name!r} has lens distortion {np.round(cam.dist, 4).tolist()}; "
                "undistort the keypoints first (undistort_track; the fit models a pinhole camera)"
            )
        return cls(np.asarray(cam.K), np.asarray(cam.R), np.asarray(cam.t), size)

    def with_focal(self, f: float) -> Camera:
        """The same camera with focal length `f` pixels (both axes)."""
        K = self.K.copy()
        K[0, 0] = K[1, 1] = float(f)
        return Camera(K, self.R, self.t, self.image_size)

    @property
    def focal(self) -> float:
        """Mean focal length, pixels."""
        return float(0.5 * (self.K[0, 0] + self.K[1, 1]))

    @property
    def centre(self) -> np.ndarray:
        """Camera position in the world, metres, ``(3,)``."""
        return -self.R.T @ self.t

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """World points ``(..., 3)`` to camera coordinates ``(..., 3)``."""
        return np.asarray(points, float) @ self.R.T + self.t

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates ``(..., 2)`` of world points ``(..., 3)`` (NaN behind the camera)."""
        c = self.to_camera(points)
        z = np.where(c[..., 2] > 1e-6, c[..., 2], np.nan)
        u = self.K[0, 0] * c[..., 0] / z + self.K[0, 2]
        v = self.K[1, 1] * c[..., 1] / z + self.K[1, 2]
        return np.stack([u, v], axis=-1)

    def backproject(self, uv: np.ndarray, depth: np.ndarray) -> np.ndarray:
        """World points ``(..., 3)`` at camera depth `depth` (metres) under pixels `uv` ``(..., 2)``."""
        uv = np.asarray(uv, float)
        depth = np.asarray(depth, float)
        x = (uv[..., 0] - self.K[0, 2]) / self.K[0, 0] * depth
        y = (uv[..., 1] - self.K[1, 2]) / self.K[1, 1] * depth
        c = np.stack([x, y, depth], axis=-1)
        return (c - self.t) @ self.R


def calibrated_camera(calibration, video):
    """The calibration's camera of `video`: its only camera, or the one named after the clip.

    Parameters
    ----------
    calibration : Calibration
    video : str or Path
        Named by :func:`~capture2notation.io.calibration.camera_name`.

    Returns
    -------
    CameraCalibration

    Raises
    ------
    FittingError
        The calibration has several cameras and none of that name.
    """
    from ..errors import CalibrationError
    from ..io.calibration import camera_name

    names = calibration.names
    name = names[0] if len(names) == 1 else camera_name(video)
    try:
        return calibration[name]
    except CalibrationError as exc:
        raise FittingError(f"{video}: {exc}") from None


def undistort_track(track, calibration, video):
    """`track` with its pixels as the calibration's pinhole camera would see them.

    The fit projects through a pinhole (:class:`Camera`); a calibrated lens's
    distortion is removed from the keypoints instead (OpenCV's
    ``undistortPoints`` onto the same intrinsics), as multi-camera systems
    do before triangulating.  Missing keypoints stay NaN; a camera without
    distortion returns `track` unchanged.

    Parameters
    ----------
    track : KeypointTrack
    calibration : Calibration
    video : str or Path
        The clip, naming its camera (:func:`calibrated_camera`).

    Returns
    -------
    KeypointTrack
    """
    import cv2

    cam = calibrated_camera(calibration, video)
    dist = np.asarray(cam.dist, float)
    if not np.any(dist != 0.0):
        return track
    xy = np.array(track.xy, dtype=float, copy=True)
    uv = xy[..., :2].reshape(-1, 2)
    ok = np.all(np.isfinite(uv), axis=1)
    if ok.any():
        K = np.asarray(cam.K, float)
        out = cv2.undistortPoints(uv[ok].reshape(-1, 1, 2), K, dist, P=K)
        uv[ok] = out.reshape(-1, 2)
    xy[..., :2] = uv.reshape(xy.shape[:-1] + (2,))
    return replace(track, xy=xy)
