"""Frame writers: an mp4 file (H.264 through ``capture2notation.io.video``) or a folder of PNG images.

Both are atomic: frames go to a temporary file / folder beside the target,
renamed into place only when the writer closes without an error, so a failed
or interrupted render never leaves a half-written video.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import cv2
import numpy as np

from capture2notation.errors import SyntheticError, VideoError
from capture2notation.io.video import VideoWriter

__all__ = ["FrameWriter", "Mp4Writer", "PngFolderWriter", "open_writer"]


class FrameWriter:
    """Context manager that writes (H, W, 3) uint8 BGR frames of one size.

    Subclasses implement ``_open``, ``_write`` and ``_close(ok)``.
    """

    def __init__(self, path, fps: float, size):
        self.path = Path(path)
        if not (np.isfinite(fps) and fps > 0):
            raise SyntheticError(f"{self.path}: fps must be positive, got {fps!r}")
        self.fps = float(fps)
        self.size = (int(size[0]), int(size[1]))
        self.count = 0

    def __enter__(self):
        self._open()
        return self

    def __exit__(self, exc_type, exc, tb):
        self._close(ok=exc_type is None)
        return False

    def write(self, frame: np.ndarray) -> None:
        """Append one frame; raise if its size differs from the writer's."""
        if frame.shape != (self.size[1], self.size[0], 3) or frame.dtype != np.uint8:
            raise SyntheticError(
                f"{self.path}: frame {self.count} has shape {frame.shape} {frame.dtype}, "
                f"expected ({self.size[1]}, {self.size[0]}, 3) uint8"
            )
        self._write(frame)
        self.count += 1


class Mp4Writer(FrameWriter):
    """mp4 video through :class:`capture2notation.io.video.VideoWriter`.

    That is H.264 (browser-playable, and what rehearsal footage usually is)
    for even frame sizes and OpenCV's ``mp4v`` otherwise; the file appears
    atomically when the writer closes without an error.
    """

    def _open(self):
        self._vw = VideoWriter(self.path, self.fps, self.size).__enter__()

    def _write(self, frame):
        self._vw.write(frame)

    def _close(self, ok: bool):
        err = VideoError(f"{self.path}: no frames were written") if ok and self.count == 0 else None
        if ok and err is None:
            self._vw.__exit__(None, None, None)
            return
        # Leaving with an exception removes the temporary file (and returns False).
        self._vw.__exit__(VideoError, err or VideoError(f"{self.path}: render failed"), None)
        if err is not None:
            raise err


class PngFolderWriter(FrameWriter):
    """A folder of ``frame_000000.png`` … images (replaced as a whole on success)."""

    def _open(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._tmp = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.", dir=self.path.parent))
        # mkdtemp makes a private (0700) folder; the result is an ordinary one.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self._tmp, 0o777 & ~umask)

    def _write(self, frame):
        name = self._tmp / f"frame_{self.count:06d}.png"
        if not cv2.imwrite(str(name), frame):
            raise VideoError(f"{name}: OpenCV could not write the PNG frame {self.count}")

    def _close(self, ok: bool):
        if not ok or self.count == 0:
            shutil.rmtree(self._tmp, ignore_errors=True)
            if ok:
                raise VideoError(f"{self.path}: no frames were written")
            return
        old = None
        if self.path.exists():
            # A folder cannot be renamed over a non-empty one: move the old aside first.
            old = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.old.", dir=self.path.parent))
            os.replace(self.path, old / "x")
        os.replace(self._tmp, self.path)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def open_writer(path, fps: float, size) -> FrameWriter:
    """A writer chosen from `path`: ``*.mp4`` → mp4, anything else → PNG folder.

    Parameters
    ----------
    path : str or Path
        Target video file or folder.
    fps : float
        Frames per second (stored in the mp4).
    size : (int, int)
        Frame (width, height), pixels.
    """
    path = Path(path)
    if path.suffix.lower() == ".mp4":
        return Mp4Writer(path, fps, size)
    if path.suffix:
        raise SyntheticError(f"{path}: unsupported video suffix {path.suffix!r}; expected .mp4 or a folder name")
    return PngFolderWriter(path, fps, size)
