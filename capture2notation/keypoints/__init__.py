"""Keypoints from frames: BlazePose (ONNX, onnxruntime) or coloured markers.

Entry points: :func:`extract` (video file or image folder),
:func:`extract_frames` (any iterable of frames), :class:`KeypointTrack`
(``save`` / ``load`` as ``.npz``).  The model is fetched and converted on
first use (:mod:`.model`); heavy modules load lazily.
"""

from .extract import BACKENDS, extract, extract_frames
from .track import LANDMARK_NAMES, NUM_LANDMARKS, KeypointTrack, landmark_index

__all__ = [
    "BACKENDS",
    "LANDMARK_NAMES",
    "NUM_LANDMARKS",
    "KeypointTrack",
    "extract",
    "extract_frames",
    "landmark_index",
]
