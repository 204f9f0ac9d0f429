"""Video input (files and image folders) and an atomic video writer.

Frames are streamed one at a time, so memory stays constant whatever the
length.  Timestamps come from the container (``CAP_PROP_POS_MSEC``) when it
gives increasing values, else from the frame index and frame rate.  A file
that ends early or has a frame that cannot be decoded yields the frames read
so far and a :class:`TruncatedVideoWarning` saying how many frames were read
and which one failed; a file with no readable frame, or one whose frame rate
or size no camera has (:mod:`capture2notation.io.limits`), raises
:class:`~capture2notation.errors.VideoError`.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np

from ..atomic import atomic_path
from ..errors import VideoError
from .limits import MAX_FPS, MAX_IMAGE_SIDE

__all__ = [
    "IMAGE_EXTENSIONS",
    "VIDEO_EXTENSIONS",
    "Frame",
    "TruncatedVideoWarning",
    "VideoInfo",
    "VideoWriter",
    "iter_frames",
    "probe",
]

VIDEO_EXTENSIONS = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".webm")
IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
DEFAULT_FOLDER_FPS = 30.0


class TruncatedVideoWarning(RuntimeWarning):
    """A video ended, or a frame failed to decode, before its declared length."""


@dataclass(frozen=True)
class Frame:
    """One decoded frame.

    Attributes
    ----------
    index : int
        0-based frame number in the source.
    time : float
        Timestamp, seconds from the start.
    image : (H, W, 3) uint8 ndarray
        BGR pixels (OpenCV order).
    """

    index: int
    time: float
    image: np.ndarray


@dataclass(frozen=True)
class VideoInfo:
    """What a video source declares about itself.

    Attributes
    ----------
    path : Path
    fps : float
        Frames per second (declared by the container, or given for folders).
    frame_count : int
        Declared number of frames (may be wrong for damaged files).
    width, height : int
        Frame size in pixels.
    """

    path: Path
    fps: float
    frame_count: int
    width: int
    height: int

    @property
    def image_size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return (self.width, self.height)


def _folder_images(path: Path) -> list[Path]:
    return sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_EXTENSIONS and p.is_file())


def _open_capture(path: Path) -> cv2.VideoCapture:
    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        cap.release()
        raise VideoError(
            f"{path}: OpenCV cannot open this video (not a video, or damaged or cut short); "
            "expected an mp4/avi/mov file or an image folder"
        )
    return cap


def probe(path, fps: float | None = None) -> VideoInfo:
    """Describe a video file or image folder without decoding it all.

    Parameters
    ----------
    path : str or Path
        Video file or folder of images (sorted by name).
    fps : float, optional
        Frame rate of an image folder (default 30), or an override for a file
        whose container declares none.

    Raises
    ------
    VideoError
        Missing path, unopenable file, empty folder or unreadable first image.
    """
    path = Path(path)
    if not path.exists():
        raise VideoError(f"{path}: no such video file or image folder")
    if path.is_dir():
        images = _folder_images(path)
        if not images:
            raise VideoError(f"{path}: image folder has no {'/'.join(IMAGE_EXTENSIONS)} files")
        first = cv2.imread(str(images[0]), cv2.IMREAD_COLOR)
        if first is None:
            raise VideoError(f"{images[0]}: cannot decode image (frame 0 of folder {path})")
        rate = DEFAULT_FOLDER_FPS if fps is None else float(fps)
        return _checked(VideoInfo(path, rate, len(images), first.shape[1], first.shape[0]), "given")
    cap = _open_capture(path)
    try:
        declared = cap.get(cv2.CAP_PROP_FPS)
        rate = float(fps) if fps is not None else float(declared)
        count = cap.get(cv2.CAP_PROP_FRAME_COUNT)
        info = VideoInfo(
            path,
            rate,
            int(count) if np.isfinite(count) and count > 0 else 0,  # 0: not declared
            int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)),
            int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)),
        )
        return _checked(info, "given" if fps is not None else "declared by the container")
    finally:
        cap.release()


def _checked(info: VideoInfo, whose: str) -> VideoInfo:
    """`info` if its frame rate and size can be a camera's; a one-line VideoError otherwise."""
    if not (np.isfinite(info.fps) and 0 < info.fps <= MAX_FPS):
        raise VideoError(
            f"{info.path}: frame rate {info.fps!r} ({whose}) is not a video's; expected 0-{MAX_FPS:g} fps "
            "(give the rate with --fps-override)"
        )
    if not (1 <= info.width <= MAX_IMAGE_SIDE and 1 <= info.height <= MAX_IMAGE_SIDE):
        raise VideoError(f"{info.path}: frame size {info.width}x{info.height} is not a video's (1-{MAX_IMAGE_SIDE} px)")
    return info


def _iter_folder(info: VideoInfo, start: int, stop: int | None) -> Iterator[Frame]:
    images = _folder_images(info.path)[start:stop]
    for offset, file in enumerate(images):
        index = start + offset
        image = cv2.imread(str(file), cv2.IMREAD_COLOR)
        if image is None or image.shape[:2] != (info.height, info.width):
            problem = "cannot be decoded" if image is None else f"has size {image.shape[1]}x{image.shape[0]}"
            _stop_early(info.path, index, f"image {file.name} {problem} (expected {info.width}x{info.height})")
            return
        yield Frame(index, index / info.fps, image)


def _stop_early(path: Path, index: int, why: str) -> None:
    if index == 0:
        raise VideoError(f"{path}: no frame could be read: {why}")
    warnings.warn(
        f"{path}: stopped at frame {index} ({why}); using the {index} frames read before it",
        TruncatedVideoWarning,
        stacklevel=3,
    )


def _iter_file(info: VideoInfo, start: int, stop: int | None) -> Iterator[Frame]:
    cap = _open_capture(info.path)
    try:
        if start:
            cap.set(cv2.CAP_PROP_POS_FRAMES, start)
        index = start
        last_time = -np.inf
        while stop is None or index < stop:
            ok, image = cap.read()
            if not ok or image is None:
                if index < info.frame_count:
                    _stop_early(
                        info.path, index, f"frame cannot be decoded; the file declares {info.frame_count} frames"
                    )
                elif index == 0:
                    raise VideoError(f"{info.path}: no frame could be read")
                return
            msec = cap.get(cv2.CAP_PROP_POS_MSEC)
            # Container timestamps keep variable frame rates exact; fall back to
            # index / fps when the backend reports nothing sensible.
            t = msec / 1000.0 if np.isfinite(msec) and msec / 1000.0 > last_time else index / info.fps
            last_time = t
            yield Frame(index, t, image)
            index += 1
    finally:
        cap.release()


def iter_frames(path, *, fps: float | None = None, start: int = 0, stop: int | None = None) -> Iterator[Frame]:
    """Stream the frames of a video file or image folder.

    Parameters
    ----------
    path : str or Path
        Video file (mp4/avi/mov/...) or folder of images sorted by name.
    fps : float, optional
        Frame rate for image folders (default 30) or to override the container.
    start, stop : int
        Frame range ``[start, stop)``.

    Yields
    ------
    Frame
        ``index``, ``time`` (s) and BGR ``image`` (H, W, 3) uint8.

    Warns
    -----
    TruncatedVideoWarning
        The source ends before its declared length or a frame cannot be
        decoded; the message says how many frames were read and names the
        first bad one.

    Raises
    ------
    VideoError
        No frame at all can be read.
    """
    info = probe(path, fps=fps)
    if start < 0 or (stop is not None and stop < start):
        raise VideoError(f"{path}: bad frame range start={start}, stop={stop}; expected 0 <= start <= stop")
    if info.path.is_dir():
        yield from _iter_folder(info, start, stop)
    else:
        yield from _iter_file(info, start, stop)


class VideoWriter:
    """Write BGR frames to a video file atomically (the file appears on close).

    ``.mp4`` is written as H.264 (yuv420p, ``+faststart``) through the ffmpeg
    that `imageio-ffmpeg` ships, because that is what web browsers play (the
    capture's ``index.html`` embeds the overlay); OpenCV's own ``mp4v`` is the
    fallback for odd frame sizes, which yuv420p cannot hold.  ``.avi`` uses
    ``MJPG``.

    Parameters
    ----------
    path : str or Path
        Output file (``.mp4``, ``.m4v``, ``.mov`` or ``.avi``).
    fps : float
        Frame rate.
    size : (int, int)
        (width, height) of every frame.

    Examples
    --------
    >>> with VideoWriter("out.mp4", 25, (640, 480)) as w:  # doctest: +SKIP
    ...     w.write(frame)
    """

    _FOURCC: ClassVar[dict[str, str]] = {".avi": "MJPG", ".mp4": "mp4v", ".mov": "mp4v", ".m4v": "mp4v"}

    def __init__(self, path, fps: float, size: tuple[int, int]):
        self.path = Path(path)
        self.fps = float(fps)
        self.size = (int(size[0]), int(size[1]))
        self.frames_written = 0
        self._ctx: Any = None  # the atomic_path context while open
        self._writer: Any = None  # cv2.VideoWriter (AVI, odd sizes)
        self._ffmpeg: Any = None  # imageio-ffmpeg's H.264 generator

    def __enter__(self) -> VideoWriter:
        suffix = self.path.suffix.lower()
        if suffix not in self._FOURCC:
            raise VideoError(
                f"{self.path}: cannot write video with extension {suffix!r}; expected one of {sorted(self._FOURCC)}"
            )
        self._ctx = atomic_path(self.path)
        tmp = self._ctx.__enter__()
        if suffix != ".avi" and self.size[0] % 2 == 0 and self.size[1] % 2 == 0:
            self._ffmpeg = _h264_writer(tmp, self.fps, self.size)
            return self
        self._writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter.fourcc(*self._FOURCC[suffix]), self.fps, self.size)
        if not self._writer.isOpened():
            self._ctx.__exit__(VideoError, None, None)
            raise VideoError(
                f"{self.path}: OpenCV cannot open a video writer ({self._FOURCC[suffix]}, {self.fps} fps, {self.size})"
            )
        return self

    def write(self, image: np.ndarray) -> None:
        """Append one BGR (H, W, 3) uint8 frame of the declared size."""
        if image.shape[:2] != (self.size[1], self.size[0]):
            raise VideoError(
                f"{self.path}: frame {self.frames_written} has size {image.shape[1]}x{image.shape[0]}, "
                f"expected {self.size[0]}x{self.size[1]}"
            )
        frame = np.ascontiguousarray(image, dtype=np.uint8)
        if self._ffmpeg is not None:
            self._ffmpeg.send(frame)
        else:
            self._writer.write(frame)
        self.frames_written += 1

    def __exit__(self, exc_type, exc, tb):
        if self._ffmpeg is not None:
            self._ffmpeg.close()
        else:
            self._writer.release()
        return self._ctx.__exit__(exc_type, exc, tb)


def _h264_writer(path: Path, fps: float, size: tuple[int, int]):
    """A started imageio-ffmpeg generator encoding BGR frames to H.264 at `path`."""
    import imageio_ffmpeg

    gen = imageio_ffmpeg.write_frames(
        str(path),
        size,
        fps=fps,
        codec="libx264",
        pix_fmt_in="bgr24",
        pix_fmt_out="yuv420p",
        macro_block_size=1,
        ffmpeg_log_level="error",
        # veryfast keeps encoding well above the capture's frame rate; faststart
        # moves the index to the front so a browser can play while loading.
        output_params=["-preset", "veryfast", "-movflags", "+faststart"],
    )
    gen.send(None)
    return gen
