"""The truth sidecar ``truth.npz`` written beside every rendered video.

Fields (ARCHITECTURE.md, "Truth sidecar"); T frames, J joints:

==============  ===========  ==================================================
field           shape        meaning
==============  ===========  ==================================================
fps             ()           frames per second
times           (T,)         seconds
joint_names     (J,)         joint names (str)
joints          (T, J, 3)    world joint positions, metres (z up, floor z = 0)
angles          (T, J, 3)    local Euler angles, radians
root            (T, 3)       pelvis position, metres
landmarks3d     (T, 33, 3)   world positions of the 33 BlazePose landmarks
keypoints       (T, 33, 2)   their pixel projections
visibility      (T, 33)      1 visible, 0 self-occluded or off-image
K               (3, 3)       camera intrinsics
R               (3, 3)       world-to-camera rotation
t               (3,)         ``x_cam = R @ x_world + t`` (OpenCV camera)
image_size      (2,)         (width, height), pixels
score           ()           JSON text of the score
effort          ()           JSON text of the Effort
view            ()           viewpoint name
style           ()           rendering style
body_height     ()           metres
front           (T,)         optional: the unwrapped front, degrees clockwise
                             seen from above from the room's +y (a right half
                             turn ends at +180, two right pirouettes at +720);
                             absent in sidecars written before turns
==============  ===========  ==================================================

Stored with ``numpy.savez`` without pickles (strings as unicode arrays).
"""

from __future__ import annotations

import zipfile
import zlib
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import MotionFileError
from .limits import MAX_FPS, MAX_FRAMES, MAX_IMAGE_SIDE, MAX_JOINTS, MAX_TRUTH_TEXT, MIN_FPS

__all__ = ["OPTIONAL_FIELDS", "TRUTH_FIELDS", "Truth", "read_truth", "write_truth"]

# name -> shape pattern: ints are fixed sizes, "T"/"J" are shared free sizes,
# None marks a text scalar.
TRUTH_FIELDS: dict[str, tuple | None] = {
    "fps": (),
    "times": ("T",),
    "joint_names": ("J",),
    "joints": ("T", "J", 3),
    "angles": ("T", "J", 3),
    "root": ("T", 3),
    "landmarks3d": ("T", 33, 3),
    "keypoints": ("T", 33, 2),
    "visibility": ("T", 33),
    "K": (3, 3),
    "R": (3, 3),
    "t": (3,),
    "image_size": (2,),
    "score": None,
    "effort": None,
    "view": None,
    "style": None,
    "body_height": (),
}
#: Fields a sidecar may lack (older sidecars); None in :class:`Truth` then.
OPTIONAL_FIELDS: dict[str, tuple] = {"front": ("T",)}
_TEXT = {"joint_names"} | {k for k, v in TRUTH_FIELDS.items() if v is None}
#: Largest size each free dimension may have.
_FREE_LIMITS = {"T": MAX_FRAMES, "J": MAX_JOINTS}
#: Metres: the body heights :class:`~capture2notation.body.Body` accepts.
BODY_HEIGHT_RANGE = (0.3, 3.0)
#: What reading a damaged zip or ``.npy`` member can raise (zlib, zipfile,
#: numpy's header parser, an encrypted or unsupported member).
_ZIP_ERRORS = (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, NotImplementedError, RuntimeError)


@dataclass(frozen=True, eq=False)
class Truth:
    """Contents of a truth sidecar (see the module docstring for the fields)."""

    fps: float
    times: np.ndarray
    joint_names: tuple
    joints: np.ndarray
    angles: np.ndarray
    root: np.ndarray
    landmarks3d: np.ndarray
    keypoints: np.ndarray
    visibility: np.ndarray
    K: np.ndarray
    R: np.ndarray
    t: np.ndarray
    image_size: tuple
    score: str
    effort: str
    view: str
    style: str
    body_height: float
    front: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return int(self.times.shape[0])


def _validate(arrays: dict, where: str) -> dict:
    """Check names, dtypes and shapes; return normalised arrays."""
    missing = [k for k in TRUTH_FIELDS if k not in arrays]
    extra = [k for k in arrays if k not in TRUTH_FIELDS and k not in OPTIONAL_FIELDS]
    if missing:
        raise MotionFileError(f"{where}: truth sidecar lacks field(s) {', '.join(missing)}")
    if extra:
        raise MotionFileError(f"{where}: unknown truth field(s) {', '.join(extra)}; expected {', '.join(TRUTH_FIELDS)}")
    sizes: dict[str, int] = {}
    out = {}
    for name, pattern in TRUTH_FIELDS.items():
        value = arrays[name]
        if name in _TEXT:
            arr = np.asarray(value)
            if arr.dtype.kind not in "UO" and not (arr.dtype.kind == "S"):
                raise MotionFileError(f"{where}: field {name} must be text, got dtype {arr.dtype}")
            arr = arr.astype(str)
            if pattern is None and arr.shape != ():
                raise MotionFileError(f"{where}: field {name} must be a single string, got shape {arr.shape}")
        else:
            try:
                arr = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise MotionFileError(f"{where}: field {name} must be numeric, got {type(value).__name__}") from None
        if pattern is not None:
            if arr.ndim != len(pattern):
                raise MotionFileError(f"{where}: field {name} has shape {arr.shape}, expected {_fmt(pattern)}")
            for dim, want in zip(arr.shape, pattern):
                if isinstance(want, str):
                    if sizes.setdefault(want, dim) != dim:
                        raise MotionFileError(
                            f"{where}: field {name} has shape {arr.shape}, expected {_fmt(pattern)} "
                            f"with {want} = {sizes[want]} as in the other fields"
                        )
                elif dim != want:
                    raise MotionFileError(f"{where}: field {name} has shape {arr.shape}, expected {_fmt(pattern)}")
        out[name] = arr
    for free, limit in _FREE_LIMITS.items():
        if sizes.get(free, 0) > limit:
            raise MotionFileError(f"{where}: {free} = {sizes[free]} is more than the {limit} a truth sidecar may hold")
    for name in _TEXT:
        longest = max((len(v) for v in np.atleast_1d(out[name]).ravel()), default=0)
        if longest > MAX_TRUTH_TEXT:
            raise MotionFileError(f"{where}: field {name} holds {longest} characters, more than {MAX_TRUTH_TEXT}")
    if not (MIN_FPS <= out["fps"] <= MAX_FPS):
        raise MotionFileError(
            f"{where}: field fps is {out['fps']}; expected a frame rate in {MIN_FPS:g}-{MAX_FPS:g} Hz"
        )
    lo, hi = BODY_HEIGHT_RANGE
    if not (lo <= out["body_height"] <= hi):
        raise MotionFileError(f"{where}: field body_height is {out['body_height']}; expected {lo:g}-{hi:g} m")
    times = out["times"]
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) < 0):
        raise MotionFileError(f"{where}: field times must be finite seconds in increasing order")
    for name in ("K", "R", "t"):
        if not np.all(np.isfinite(out[name])):
            raise MotionFileError(f"{where}: field {name} has values that are not finite")
    size = out["image_size"]
    if not (np.all(size == np.round(size)) and np.all((size >= 1) & (size <= MAX_IMAGE_SIDE))):
        raise MotionFileError(
            f"{where}: field image_size is {size.tolist()}; expected (width, height), whole pixels 1-{MAX_IMAGE_SIDE}"
        )
    for name, pattern in OPTIONAL_FIELDS.items():
        if name in arrays:
            try:
                arr = np.asarray(arrays[name], dtype=float)
            except (TypeError, ValueError):
                raise MotionFileError(f"{where}: field {name} must be numeric") from None
            if arr.shape != (sizes.get("T", -1),):
                raise MotionFileError(f"{where}: field {name} has shape {arr.shape}, expected {_fmt(pattern)}")
            out[name] = arr
    vis = out["visibility"]
    if np.any((vis < 0) | (vis > 1) | np.isnan(vis)):
        raise MotionFileError(f"{where}: field visibility must lie in [0, 1]")
    return out


def _load_npz(path: Path) -> dict:
    """The arrays of a ``.npz``, each member's header checked before its data is read.

    Member shapes must fit :data:`TRUTH_FIELDS` within the limits, so a
    small file that declares huge arrays is refused without allocating them.
    """
    try:
        zf = zipfile.ZipFile(path)
    except FileNotFoundError:
        raise MotionFileError(f"{path}: truth sidecar not found") from None
    except _ZIP_ERRORS as exc:
        raise MotionFileError(f"{path}: not a readable truth sidecar (.npz): {exc}") from None
    arrays = {}
    with zf:
        for info in zf.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
            if (name not in TRUTH_FIELDS and name not in OPTIONAL_FIELDS) or name in arrays:
                what = "repeated" if name in arrays else "unknown"
                raise MotionFileError(
                    f"{path}: {what} truth field {name!r}; expected each of {', '.join(TRUTH_FIELDS)} once"
                    f" (optionally {', '.join(OPTIONAL_FIELDS)})"
                )
            try:
                with zf.open(info) as fh:
                    shape, dtype = _npy_header(fh)
                    _check_header(name, shape, dtype, str(path))
                with zf.open(info) as fh:
                    arrays[name] = np.lib.format.read_array(fh, allow_pickle=False)
            except MotionFileError:
                raise
            except _ZIP_ERRORS as exc:
                raise MotionFileError(f"{path}: field {name} cannot be read: {exc}") from None
    return arrays


def _npy_header(fh) -> tuple[tuple, np.dtype]:
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        shape, _, dtype = np.lib.format.read_array_header_1_0(fh)
    elif version in ((2, 0), (3, 0)):
        shape, _, dtype = np.lib.format.read_array_header_2_0(fh)
    else:
        raise ValueError(f"unsupported .npy version {version}")
    return shape, dtype


def _check_header(name: str, shape: tuple, dtype: np.dtype, where: str) -> None:
    """Refuse a member whose declared dtype or size no truth field can have."""
    text = name in _TEXT
    if dtype.hasobject or dtype.kind not in ("USa" if text else "biuf"):
        raise MotionFileError(f"{where}: field {name} has dtype {dtype}, expected {'text' if text else 'numbers'}")
    pattern = TRUTH_FIELDS[name] if name in TRUTH_FIELDS else OPTIONAL_FIELDS[name]
    if pattern is None:
        pattern = ()
    elif name == "joint_names":
        pattern = ("J",)
    if len(shape) != len(pattern):
        raise MotionFileError(f"{where}: field {name} has shape {shape}, expected {_fmt(pattern)}")
    for dim, want in zip(shape, pattern):
        limit = _FREE_LIMITS[want] if isinstance(want, str) else want
        if not 0 <= dim <= limit:
            raise MotionFileError(f"{where}: field {name} has shape {shape}, expected {_fmt(pattern)} within {limit}")
    if text and dtype.itemsize > 4 * MAX_TRUTH_TEXT:
        raise MotionFileError(f"{where}: field {name} is longer than {MAX_TRUTH_TEXT} characters")


def _fmt(pattern) -> str:
    return "(" + ", ".join(str(p) for p in pattern) + ("," if len(pattern) == 1 else "") + ")"


def write_truth(path, **fields_) -> Path:
    """Validate and atomically write a truth sidecar.

    Parameters
    ----------
    path : str or Path
        Destination, normally ``OUTDIR/truth.npz``.
    **fields_
        Every field of :data:`TRUTH_FIELDS`, optionally those of
        :data:`OPTIONAL_FIELDS`, no others (text fields as str).

    Returns
    -------
    Path

    Raises
    ------
    MotionFileError
        A field is missing, unknown or has the wrong shape (names the file and field).
    """
    path = Path(path)
    arrays = _validate(fields_, str(path))
    with atomic_path(path, suffix=".npz") as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    return path


def read_truth(path) -> Truth:
    """Read and validate a truth sidecar.

    Raises
    ------
    MotionFileError
        Unreadable file, missing field or wrong shape (names the file and field).
    """
    path = Path(path)
    arrays = _load_npz(path)
    a = _validate(arrays, str(path))
    kw = {}
    for f in fields(Truth):
        if f.name in OPTIONAL_FIELDS and f.name not in a:
            continue
        v = a[f.name]
        if f.name in ("fps", "body_height"):
            v = float(v)
        elif f.name == "joint_names":
            v = tuple(str(s) for s in v)
        elif f.name == "image_size":
            v = (int(v[0]), int(v[1]))
        elif f.name in _TEXT:
            v = str(v)
        else:
            v.setflags(write=False)
        kw[f.name] = v
    return Truth(**kw)
