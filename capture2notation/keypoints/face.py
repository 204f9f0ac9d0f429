"""Is a face seen at the head?  A label-free cue of a body facing the camera.

A pose model draws a person seen from behind as if facing the camera: its
face landmarks sit on the back of the head, its left and right are
exchanged, and the feet and the depth order follow that reading.  What it
does not do is make a face appear in the pixels.  A face detector run on
the head says what the image itself shows: on BlazePose's head region of
turning renders it finds a face (frontal or profile) in 42–51 % of the
frames with the body within 30° of facing the camera, 39–43 % between 30°
and 60°, 7–16 % side-on, and in 0–1 % of 1,443 frames with the back
within 60° of the camera (two development sets; ``docs/benchmarks.md``,
fifteenth session).

The detector is OpenCV's Viola–Jones cascades that ship with OpenCV
(frontal face and profile face, the profile one run on the image and on its
mirror image, as it finds faces turned one way only), run on a square crop
about the head scaled by the torso, so a face has the same size in it
whatever the person's size in the frame.  :class:`FaceDetector` gives 1 (a
face), 0 (none) or NaN (no person, or no head and torso landmarks to place
the crop).
"""

from __future__ import annotations

import cv2
import numpy as np

from .identity import torso_and_order

__all__ = ["CROP_PX", "CROP_TORSO_LENGTHS", "FACE_EVERY_S", "FaceDetector", "head_crop"]

#: A face is looked for every this many seconds (every third frame at
#: 25 fps): its misses last about 0.3 s (:data:`~.yaw.FACE_CORRELATION_S`),
#: and looking every frame, every other or every third frame read the yaw
#: equally well on the development renders (96.9 / 96.9 / 96.9 % and
#: 96.8 / 96.6 / 96.8 % of frames within 22.5°) at up to three times the cost.
FACE_EVERY_S = 0.12

#: Side of the square head crop, pixels, and its side in torso lengths
#: (shoulders' middle to hips' middle in the image): a head is about half
#: a torso length tall, so the cascades' face box spans 30–65 px of the
#: crop, inside the search (:data:`_MIN_FACE_PX`–:data:`_MAX_FACE_PX`).
CROP_PX = 96
CROP_TORSO_LENGTHS = 1.0
#: Search sizes, pixels of the crop.  Faces are found at 30–44 px on a real
#: person (the squat video of the fixtures) and 42–65 px on the renders'
#: mannequin; below 28 px the search costs most (the smallest windows are
#: the most numerous) and found no more (5 ms a look from 20 px, 3.3 ms from
#: 28 px); one larger than three quarters of the crop is not a face at the head.
_MIN_FACE_PX = 28
_MAX_FACE_PX = 72
#: Detector settings: OpenCV's defaults (scale step 1.1, three overlapping
#: detections to accept one).
_SCALE_STEP = 1.1
_MIN_NEIGHBOURS = 3
#: Landmarks of the head (nose, eyes, ears, mouth).
_HEAD = slice(0, 11)


class FaceDetector:
    """OpenCV's frontal and profile face cascades on a crop about the head.

    Loads the two cascades shipped with OpenCV once; call it on each frame.
    """

    def __init__(self):
        self._frontal = _cascade("haarcascade_frontalface_alt2.xml")
        self._profile = _cascade("haarcascade_profileface.xml")

    def __call__(self, image: np.ndarray, xy: np.ndarray) -> float:
        """1.0 if a face is found at the head, 0.0 if not, NaN if the head cannot be placed.

        Parameters
        ----------
        image : (H, W, 3) uint8 ndarray or (H, W) uint8 ndarray
            The frame (BGR or grey).
        xy : (33, 2+) ndarray
            The frame's BlazePose landmarks, pixels (NaN where missing).
        """
        crop = head_crop(image, xy)
        if crop is None:
            return float("nan")
        kwargs = dict(
            scaleFactor=_SCALE_STEP,
            minNeighbors=_MIN_NEIGHBOURS,
            minSize=(_MIN_FACE_PX, _MIN_FACE_PX),
            maxSize=(_MAX_FACE_PX, _MAX_FACE_PX),
        )
        for cascade, img in ((self._frontal, crop), (self._profile, crop), (self._profile, crop[:, ::-1].copy())):
            if len(cascade.detectMultiScale(img, **kwargs)):
                return 1.0
        return 0.0


def _cascade(name: str) -> cv2.CascadeClassifier:
    cascade = cv2.CascadeClassifier(cv2.data.haarcascades + name)
    if cascade.empty():  # a broken OpenCV install; the message says which file
        raise RuntimeError(f"OpenCV face cascade {name} could not be loaded from {cv2.data.haarcascades}")
    return cascade


def head_crop(image: np.ndarray, xy: np.ndarray) -> np.ndarray | None:
    """The (CROP_PX, CROP_PX) grey crop centred on the head landmarks, or None.

    Its side is :data:`CROP_TORSO_LENGTHS` torso lengths, so the face has
    the same size in the crop however near the person stands.
    """
    xy = np.asarray(xy, float)[:, :2]
    head = xy[_HEAD]
    head = head[np.isfinite(head).all(axis=1)]
    torso = torso_and_order(xy[None])[0][0]
    if head.shape[0] == 0 or not np.isfinite(torso) or torso <= 1.0:
        return None
    grey = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    cx, cy = np.median(head, axis=0)
    scale = CROP_PX / (CROP_TORSO_LENGTHS * torso)
    warp = np.array([[scale, 0.0, CROP_PX / 2 - cx * scale], [0.0, scale, CROP_PX / 2 - cy * scale]])
    return cv2.warpAffine(grey, warp, (CROP_PX, CROP_PX), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
