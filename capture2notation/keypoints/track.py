"""The keypoint track: what every keypoint backend returns, saved as ``.npz``.

Fields follow ARCHITECTURE.md "Keypoint track".  Missing values are NaN with
visibility 0, never zeros.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import KeypointError

__all__ = ["LANDMARK_NAMES", "NUM_LANDMARKS", "KeypointTrack", "landmark_index"]

#: The 33 BlazePose landmarks in model order (nose = 0 … right_foot_index = 32).
LANDMARK_NAMES: tuple[str, ...] = (
    "nose", "left_eye_inner", "left_eye", "left_eye_outer", "right_eye_inner",
    "right_eye", "right_eye_outer", "left_ear", "right_ear", "mouth_left",
    "mouth_right", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow",
    "left_wrist", "right_wrist", "left_pinky", "right_pinky", "left_index",
    "right_index", "left_thumb", "right_thumb", "left_hip", "right_hip",
    "left_knee", "right_knee", "left_ankle", "right_ankle", "left_heel",
    "right_heel", "left_foot_index", "right_foot_index",
)  # fmt: skip
NUM_LANDMARKS = len(LANDMARK_NAMES)

_FIELDS = ("fps", "times", "image_size", "xy", "visibility", "presence", "world", "crops", "backend")
#: Fields an older track may lack (read as NaN: not assessed).
_OPTIONAL = ("identity_confidence", "face")


def landmark_index(name: str) -> int:
    """Index of a BlazePose landmark by name (raises :class:`KeypointError`)."""
    try:
        return LANDMARK_NAMES.index(name)
    except ValueError:
        raise KeypointError(f"unknown landmark {name!r}; expected one of {', '.join(LANDMARK_NAMES)}") from None


@dataclass
class KeypointTrack:
    """2D (+ relative depth) keypoints per frame, from BlazePose or colour markers.

    Attributes
    ----------
    fps : float
        Frame rate of the source video, frames per second.
    times : (T,) ndarray
        Frame timestamps, seconds.
    image_size : (2,) ndarray
        (width, height) in pixels.
    xy : (T, 33, 3) ndarray
        Pixel x, pixel y and relative depth z (BlazePose: z in the same pixel
        scale as x, smaller = closer; markers: NaN).
    visibility : (T, 33) ndarray
        Probability in [0, 1] that the point is visible; 0 when missing.
    presence : (T,) ndarray
        Probability that a person is present (markers: fraction of markers seen).
    world : (T, 33, 3) ndarray
        MediaPipe world landmarks, metres, hip-centred, +x image right, +y down,
        −z towards the camera (NaN for the marker backend).
    crops : (T, 5) ndarray
        Region the model looked at: centre x, centre y, width, height (pixels)
        and rotation (radians, clockwise in the image); NaN when unused.
    backend : str
        ``"blazepose"`` or ``"markers"``.
    identity_confidence : (T,) ndarray
        Probability in [0, 1] that the frame's left/right labels are right
        (:func:`~capture2notation.keypoints.identity.correct_identity`); NaN
        where not assessed, 0 where no person was seen.  Optional in the
        ``.npz`` (older tracks read as NaN).
    face : (T,) ndarray
        1 where a face detector found a face at the head, 0 where it found
        none, NaN where not assessed (:mod:`~capture2notation.keypoints.face`;
        a label-free cue of facing the camera).  Optional in the ``.npz``.
    """

    fps: float
    times: np.ndarray
    image_size: np.ndarray
    xy: np.ndarray
    visibility: np.ndarray
    presence: np.ndarray
    world: np.ndarray
    crops: np.ndarray
    backend: str = "blazepose"
    names: tuple[str, ...] = field(default=LANDMARK_NAMES, repr=False)
    identity_confidence: np.ndarray | None = field(default=None, repr=False)
    face: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        self.fps = float(self.fps)
        self.times = np.asarray(self.times, dtype=float)
        self.image_size = np.asarray(self.image_size, dtype=int)
        self.xy = np.asarray(self.xy, dtype=float)
        self.visibility = np.asarray(self.visibility, dtype=float)
        self.presence = np.asarray(self.presence, dtype=float)
        self.world = np.asarray(self.world, dtype=float)
        self.crops = np.asarray(self.crops, dtype=float)
        self.backend = str(self.backend)
        n = self.times.shape[0] if self.times.ndim == 1 else 0
        ident = np.full(n, np.nan) if self.identity_confidence is None else self.identity_confidence
        self.identity_confidence = np.asarray(ident, dtype=float)
        self.face = np.asarray(np.full(n, np.nan) if self.face is None else self.face, dtype=float)
        self.validate()

    def validate(self) -> None:
        """Check shapes and ranges; raise :class:`KeypointError` naming the field."""
        t = self.times.shape[0] if self.times.ndim == 1 else -1
        k = len(self.names)
        expected = {
            "times": (t,),
            "image_size": (2,),
            "xy": (t, k, 3),
            "visibility": (t, k),
            "presence": (t,),
            "world": (t, k, 3),
            "crops": (t, 5),
            "identity_confidence": (t,),
            "face": (t,),
        }
        for name, shape in expected.items():
            got = getattr(self, name).shape
            if got != shape:
                raise KeypointError(f"keypoint track field {name!r} has shape {got}, expected {shape}")
        if not np.isfinite(self.fps) or self.fps <= 0:
            raise KeypointError(f"keypoint track fps {self.fps}, expected a positive number")
        vis = self.visibility[np.isfinite(self.visibility)]
        if vis.size and (vis.min() < 0 or vis.max() > 1):
            raise KeypointError(f"keypoint track visibility outside [0, 1]: [{vis.min()}, {vis.max()}]")
        for name in _OPTIONAL:
            v = getattr(self, name)[np.isfinite(getattr(self, name))]
            if v.size and (v.min() < 0 or v.max() > 1):
                raise KeypointError(f"keypoint track {name} outside [0, 1]: [{v.min()}, {v.max()}]")

    def __len__(self) -> int:
        return int(self.times.shape[0])

    def frames(self, index) -> KeypointTrack:
        """The track cut to `index` (a slice or frame indices) along time."""
        per_frame = ("times", "xy", "visibility", "presence", "world", "crops") + _OPTIONAL
        return replace(self, **{name: np.asarray(getattr(self, name))[index] for name in per_frame})

    @classmethod
    def empty(cls, n_frames: int, fps: float, image_size, backend: str, times=None) -> KeypointTrack:
        """A track of `n_frames` with every value missing (NaN, visibility 0)."""
        k = NUM_LANDMARKS
        times = np.arange(n_frames) / float(fps) if times is None else times
        return cls(
            fps=fps,
            times=times,
            image_size=image_size,
            xy=np.full((n_frames, k, 3), np.nan),
            visibility=np.zeros((n_frames, k)),
            presence=np.zeros(n_frames),
            world=np.full((n_frames, k, 3), np.nan),
            crops=np.full((n_frames, 5), np.nan),
            backend=backend,
        )

    def save(self, path) -> Path:
        """Write the track atomically to an ``.npz`` file; return its path."""
        path = Path(path)
        arrays = {name: getattr(self, name) for name in _FIELDS}
        arrays["backend"] = np.array(self.backend)
        arrays["names"] = np.array(self.names)
        for name in _OPTIONAL:
            arrays[name] = getattr(self, name)
        with (
            atomic_path(path, suffix=".npz") as tmp,
            open(tmp, "wb") as f,
        ):  # a file object stops numpy appending ".npz"
            np.savez_compressed(f, **arrays)
        return path

    @classmethod
    def load(cls, path) -> KeypointTrack:
        """Read a track written by :meth:`save`.

        Raises
        ------
        KeypointError
            Missing file, missing field or wrong shapes (the message names them).
        """
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as data:
                missing = [f for f in _FIELDS if f not in data.files]
                if missing:
                    raise KeypointError(f"{path}: not a keypoint track, missing fields {missing}")
                values = {f: data[f] for f in _FIELDS}
                names = tuple(str(n) for n in data["names"]) if "names" in data.files else LANDMARK_NAMES
                values.update({f: data[f] for f in _OPTIONAL if f in data.files})
        except (OSError, ValueError) as exc:
            raise KeypointError(f"{path}: cannot read keypoint track: {exc}") from exc
        values["fps"] = float(values["fps"])
        values["backend"] = str(values["backend"])
        try:
            return cls(**values, names=names)
        except KeypointError as exc:
            raise KeypointError(f"{path}: {exc}") from exc
