"""Camera calibration files (DESIGN.md, "Cameras and calibration files").

A calibration file is TOML: one table per camera under ``[cameras.NAME]``
and, optionally, the board it was made from under ``[board]``::

    # capture2notation camera calibration
    version = 1

    [board]
    kind = "charuco"
    squares = [7, 5]          # columns, rows
    square = 0.04             # square side, metres
    marker = 0.03             # marker side, metres
    dictionary = "DICT_4X4_250"

    [cameras.front]
    image_size = [640, 480]   # width, height, pixels
    K = [[660.0, 0.0, 320.0], [0.0, 660.0, 240.0], [0.0, 0.0, 1.0]]
    dist = [0.0, 0.0, 0.0, 0.0, 0.0]   # OpenCV (k1, k2, p1, p2, k3)
    R = [[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]]
    t = [0.0, 1.0, 4.0]       # x_cam = R @ x_world + t, metres
    rms_px = 0.21             # optional: reprojection error of the fit
    offset_s = 0.0            # optional: the clip starts this late, seconds

OpenCV's conventions throughout: ``x_cam = R @ x_world + t`` (camera x
right, y down, z forward), pixel = ``K · x_cam / z`` before distortion.  The
world is DESIGN.md's: metres, z up, the floor at z = 0.  A camera is named
by its clip's file stem, or by its folder for ``.../NAME/video.mp4``
(:func:`camera_name`), in calibration and capture alike.

:func:`read_calibration` accepts only what it can check: every error names
the file, the table and the bad value.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from ..atomic import write_text
from ..errors import CalibrationError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "FORMAT_VERSION",
    "Board",
    "Calibration",
    "CameraCalibration",
    "camera_name",
    "read_calibration",
    "write_calibration",
]

#: Version written into every file; files of another version are refused.
FORMAT_VERSION = 1
#: Largest |R Rᵀ − I| entry accepted as a rotation (TOML floats written with
#: 12 significant digits keep it near 1e-12).
_ROTATION_TOL = 1e-6
#: Image sides accepted, pixels (the renderer's own limits).
_SIZE_RANGE = (16, 16384)
#: Largest translation accepted, metres: a camera farther than this from the
#: world origin cannot see a performer.
_MAX_DISTANCE_M = 1000.0


def _fail(path, where: str, message: str) -> CalibrationError:
    return CalibrationError(f"{path}: [{where}] {message}" if where else f"{path}: {message}")


@dataclass(frozen=True)
class Board:
    """A ChArUco board (OpenCV's aruco module).

    Parameters
    ----------
    squares : (int, int)
        Squares along x and y (columns, rows), each at least 2.
    square : float
        Side of a chessboard square, metres.
    marker : float
        Side of an ArUco marker, metres (smaller than `square`).
    dictionary : str
        An OpenCV predefined dictionary name, e.g. ``"DICT_4X4_250"``.
    """

    squares: tuple[int, int] = (7, 5)
    square: float = 0.04
    marker: float = 0.03
    dictionary: str = "DICT_4X4_250"

    def __post_init__(self):
        sq = tuple(self.squares)
        if len(sq) != 2 or not all(isinstance(v, int) and not isinstance(v, bool) and v >= 2 for v in sq):
            raise CalibrationError(f"board squares {self.squares!r} must be two whole numbers >= 2")
        for name in ("square", "marker"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (0 < v < 10):
                raise CalibrationError(f"board {name} {v!r} must be a side in metres in (0, 10)")
        if not self.marker < self.square:
            raise CalibrationError(f"board marker {self.marker} m must be smaller than its square {self.square} m")
        if not (isinstance(self.dictionary, str) and self.dictionary.startswith("DICT_")):
            raise CalibrationError(f"board dictionary {self.dictionary!r} must be an OpenCV name like DICT_4X4_250")
        object.__setattr__(self, "squares", (int(sq[0]), int(sq[1])))
        object.__setattr__(self, "square", float(self.square))
        object.__setattr__(self, "marker", float(self.marker))


@dataclass(frozen=True, eq=False)
class CameraCalibration:
    """One calibrated camera.

    Parameters
    ----------
    name : str
        The camera's name (see :func:`camera_name`).
    image_size : (int, int)
        (width, height) in pixels of the images the calibration is for.
    K : (3, 3) ndarray
        Intrinsics, pixels.
    dist : (5,) ndarray
        OpenCV distortion ``(k1, k2, p1, p2, k3)``; zeros for none.
    R : (3, 3) ndarray
        World-to-camera rotation.
    t : (3,) ndarray
        World-to-camera translation, metres.
    rms_px : float
        Reprojection RMS of the calibration, pixels (NaN when unknown).
    offset_s : float
        The camera's clip starts this many seconds after the reference clock.
    """

    name: str
    image_size: tuple[int, int]
    K: np.ndarray
    dist: np.ndarray = field(default_factory=lambda: np.zeros(5))
    R: np.ndarray = field(default_factory=lambda: np.eye(3))
    t: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rms_px: float = math.nan
    offset_s: float = 0.0

    def __post_init__(self):
        where = f"cameras.{self.name}"
        if not isinstance(self.name, str) or not self.name.strip():
            raise CalibrationError(f"camera name {self.name!r} must be a non-empty string")
        size = tuple(self.image_size)
        if len(size) != 2 or not all(
            isinstance(v, (int, np.integer)) and not isinstance(v, bool) and _SIZE_RANGE[0] <= v <= _SIZE_RANGE[1]
            for v in size
        ):
            raise CalibrationError(f"[{where}] image_size {self.image_size!r} must be [width, height] in pixels")
        arrays = {"K": (3, 3), "dist": (5,), "R": (3, 3), "t": (3,)}
        for key, shape in arrays.items():
            a = np.array(getattr(self, key), dtype=float)
            if a.shape != shape:
                raise CalibrationError(f"[{where}] {key} must have shape {shape}, got {a.shape}")
            if not np.all(np.isfinite(a)):
                raise CalibrationError(f"[{where}] {key} must be finite, got {a.tolist()}")
            a.setflags(write=False)
            object.__setattr__(self, key, a)
        K = self.K
        if not (K[0, 0] > 0 and K[1, 1] > 0 and K[2, 2] == 1 and K[1, 0] == K[2, 0] == K[2, 1] == 0):
            raise CalibrationError(
                f"[{where}] K {K.tolist()} must be [[fx, s, cx], [0, fy, cy], [0, 0, 1]], fx, fy > 0"
            )
        err = float(np.max(np.abs(self.R @ self.R.T - np.eye(3))))
        if err > _ROTATION_TOL or np.linalg.det(self.R) < 0:
            raise CalibrationError(
                f"[{where}] R is not a rotation (|R Rᵀ − I| = {err:.2g}, det {np.linalg.det(self.R):.3g})"
            )
        if np.linalg.norm(self.t) > _MAX_DISTANCE_M:
            raise CalibrationError(f"[{where}] t {self.t.tolist()} puts the camera over {_MAX_DISTANCE_M:g} m away")
        for key in ("rms_px", "offset_s"):
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating)):
                raise CalibrationError(f"[{where}] {key} must be a number, got {v!r}")
        if not (math.isnan(self.rms_px) or 0 <= self.rms_px < 1e4):
            raise CalibrationError(f"[{where}] rms_px {self.rms_px!r} must be >= 0 pixels")
        if not (math.isfinite(self.offset_s) and abs(self.offset_s) < 3600):
            raise CalibrationError(f"[{where}] offset_s {self.offset_s!r} must be seconds within an hour")
        object.__setattr__(self, "image_size", (int(size[0]), int(size[1])))
        object.__setattr__(self, "rms_px", float(self.rms_px))
        object.__setattr__(self, "offset_s", float(self.offset_s))

    @property
    def centre(self) -> np.ndarray:
        """The camera's position in the world, metres, ``(3,)``."""
        return -self.R.T @ self.t

    def project(self, points) -> np.ndarray:
        """Pixels ``(..., 2)`` of world points ``(..., 3)``, with distortion (NaN behind the camera)."""
        import cv2

        pts = np.asarray(points, float)
        flat = pts.reshape(-1, 3)
        cam = flat @ self.R.T + self.t
        behind = cam[:, 2] <= 1e-9
        rvec = cv2.Rodrigues(self.R)[0]
        uv, _ = cv2.projectPoints(flat.reshape(-1, 1, 3), rvec, self.t, self.K, self.dist)
        uv = uv.reshape(-1, 2)
        uv[behind] = np.nan
        return uv.reshape(pts.shape[:-1] + (2,))

    def scaled_to(self, image_size) -> CameraCalibration:
        """The same camera for images resized to `image_size` (intrinsics scaled; distortion unchanged)."""
        w, h = (int(v) for v in image_size)
        sx, sy = w / self.image_size[0], h / self.image_size[1]
        K = self.K.copy()
        K[0] *= sx
        K[1] *= sy
        return CameraCalibration(self.name, (w, h), K, self.dist, self.R, self.t, self.rms_px, self.offset_s)


@dataclass(frozen=True)
class Calibration:
    """Every camera of a calibration file, and the board it was made from.

    Parameters
    ----------
    cameras : mapping of str to CameraCalibration
        By name.
    board : Board or None
    """

    cameras: MappingProxyType
    board: Board | None = None

    def __post_init__(self):
        cams = dict(self.cameras)
        if not cams:
            raise CalibrationError("a calibration needs at least one camera")
        for name, cam in cams.items():
            if not isinstance(cam, CameraCalibration) or cam.name != name:
                raise CalibrationError(f"camera {name!r} must be a CameraCalibration named {name!r}")
        object.__setattr__(self, "cameras", MappingProxyType(cams))

    @classmethod
    def of(cls, cameras, board: Board | None = None) -> Calibration:
        """A calibration from an iterable of cameras."""
        return cls(MappingProxyType({c.name: c for c in cameras}), board)

    def __getitem__(self, name: str) -> CameraCalibration:
        try:
            return self.cameras[name]
        except KeyError:
            raise CalibrationError(
                f"no camera {name!r} in the calibration (it has {', '.join(sorted(self.cameras))})"
            ) from None

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.cameras)


def camera_name(video) -> str:
    """The camera name of a clip: its folder for ``.../NAME/video.mp4``, else its file stem.

    The renderer writes one folder per camera (``OUT/front/video.mp4``), and
    a user's clips are usually named after their camera (``left.mp4``).
    """
    p = Path(video)
    if p.is_dir():
        return p.name
    return p.parent.name if p.stem == "video" and p.parent.name else p.stem


# --------------------------------------------------------------------------- reading


def _number(v, path, where: str, key: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise _fail(path, where, f"{key} must be a number, got {v!r}")
    return float(v)


def _matrix(table: dict, key: str, shape: tuple, path, where: str) -> np.ndarray:
    if key not in table:
        raise _fail(path, where, f"missing {key}")
    v = table[key]
    if len(shape) == 1:
        if not isinstance(v, list) or len(v) != shape[0]:
            raise _fail(path, where, f"{key} must be a list of {shape[0]} numbers, got {v!r}")
        return np.array([_number(x, path, where, key) for x in v])
    if not isinstance(v, list) or len(v) != shape[0] or not all(isinstance(r, list) and len(r) == shape[1] for r in v):
        raise _fail(path, where, f"{key} must be {shape[0]} rows of {shape[1]} numbers, got {v!r}")
    return np.array([[_number(x, path, where, key) for x in r] for r in v])


def _camera(name: str, table, path) -> CameraCalibration:
    where = f"cameras.{name}"
    if not isinstance(table, dict):
        raise _fail(path, where, f"expected a table, got {table!r}")
    known = {"image_size", "K", "dist", "R", "t", "rms_px", "offset_s"}
    for key in table:
        if key not in known:
            raise _fail(path, where, f"unknown key {key!r}; expected {', '.join(sorted(known))}")
    size = table.get("image_size")
    if not (
        isinstance(size, list) and len(size) == 2 and all(isinstance(v, int) and not isinstance(v, bool) for v in size)
    ):
        raise _fail(path, where, f"image_size must be [width, height] in whole pixels, got {size!r}")
    kw: dict[str, Any] = {
        "K": _matrix(table, "K", (3, 3), path, where),
        "R": _matrix(table, "R", (3, 3), path, where),
        "t": _matrix(table, "t", (3,), path, where),
        "dist": _matrix(table, "dist", (5,), path, where) if "dist" in table else np.zeros(5),
    }
    for key in ("rms_px", "offset_s"):
        if key in table:
            kw[key] = _number(table[key], path, where, key)
    try:
        return CameraCalibration(name, (size[0], size[1]), **kw)
    except CalibrationError as exc:
        raise CalibrationError(f"{path}: {exc}") from None


def read_calibration(path) -> Calibration:
    """Read a calibration TOML file.

    Raises
    ------
    CalibrationError
        Missing file, bad TOML, a wrong version, or a camera that is not a
        camera; the message names the file and the table.
    """
    path = Path(path)
    if not path.is_file():
        raise CalibrationError(f"{path}: no such calibration file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise CalibrationError(f"{path}: not a TOML file: {exc}") from None
    version = data.get("version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        raise _fail(path, "", f"version {version!r} is not {FORMAT_VERSION}")
    for key in data:
        if key not in ("version", "board", "cameras"):
            raise _fail(path, "", f"unknown table or key {key!r}; expected version, board, cameras")
    cams = data.get("cameras")
    if not isinstance(cams, dict) or not cams:
        raise _fail(path, "", "no [cameras.NAME] table")
    board = None
    if "board" in data:
        b = data["board"]
        if not isinstance(b, dict):
            raise _fail(path, "board", f"expected a table, got {b!r}")
        kind = b.get("kind", "charuco")
        if kind != "charuco":
            raise _fail(path, "board", f"kind {kind!r} is not charuco")
        unknown = set(b) - {"kind", "squares", "square", "marker", "dictionary"}
        if unknown:
            raise _fail(path, "board", f"unknown keys {', '.join(sorted(unknown))}")
        squares = b.get("squares", [7, 5])
        try:
            board = Board(
                tuple(squares) if isinstance(squares, list) else squares,
                b.get("square", 0.04),
                b.get("marker", 0.03),
                b.get("dictionary", "DICT_4X4_250"),
            )
        except CalibrationError as exc:
            raise _fail(path, "board", str(exc)) from None
    return Calibration.of([_camera(name, table, path) for name, table in cams.items()], board)


# --------------------------------------------------------------------------- writing


def _toml_key(name: str) -> str:
    bare = name.replace("_", "").replace("-", "").isalnum() and name.isascii()
    return name if bare else '"' + name.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _fmt(v: float) -> str:
    return repr(float(f"{float(v):.12g}"))


def _vector(a) -> str:
    return "[" + ", ".join(_fmt(v) for v in np.asarray(a).ravel()) + "]"


def _rows(a) -> str:
    return "[" + ", ".join(_vector(r) for r in np.asarray(a)) + "]"


def write_calibration(calibration: Calibration, path, comment: str = "") -> Path:
    """Write `calibration` as TOML, atomically; :func:`read_calibration` reads it back equal.

    Parameters
    ----------
    calibration : Calibration
    path : str or Path
    comment : str
        Extra ``#`` lines at the top (how it was made).
    """
    lines = ["# capture2notation camera calibration (DESIGN.md, 'Cameras and calibration files')"]
    lines += [f"# {c}" for c in comment.splitlines() if c.strip()]
    lines += [f"version = {FORMAT_VERSION}", ""]
    b = calibration.board
    if b is not None:
        lines += [
            "[board]",
            'kind = "charuco"',
            f"squares = [{b.squares[0]}, {b.squares[1]}]",
            f"square = {_fmt(b.square)}",
            f"marker = {_fmt(b.marker)}",
            f'dictionary = "{b.dictionary}"',
            "",
        ]
    for name, cam in calibration.cameras.items():
        lines += [
            f"[cameras.{_toml_key(name)}]",
            f"image_size = [{cam.image_size[0]}, {cam.image_size[1]}]",
            f"K = {_rows(cam.K)}",
            f"dist = {_vector(cam.dist)}",
            f"R = {_rows(cam.R)}",
            f"t = {_vector(cam.t)}",
        ]
        if math.isfinite(cam.rms_px):
            lines.append(f"rms_px = {_fmt(cam.rms_px)}")
        if cam.offset_s:
            lines.append(f"offset_s = {_fmt(cam.offset_s)}")
        lines.append("")
    return write_text(path, "\n".join(lines))
