"""Exceptions: one root, one subclass per stage.

Every message names *where* (file, line, frame, parameter) and *what* was
expected, so a user can fix the input without reading the code.
"""

from __future__ import annotations

__all__ = [
    "AudioError",
    "BodyModelError",
    "C2NError",
    "CalibrationError",
    "CompareError",
    "EffortError",
    "FittingError",
    "KeypointError",
    "ModelError",
    "MotionFileError",
    "NotationError",
    "PipelineError",
    "QuantiseError",
    "ScoreFormatError",
    "SyntheticError",
    "VideoError",
]


class C2NError(Exception):
    """Root of every error raised on purpose by capture2notation."""


class BodyModelError(C2NError):
    """Bad joint name, angle array shape or body parameter."""


class NotationError(C2NError):
    """An invalid notation object (unknown part, direction, level, bend...)."""


class ScoreFormatError(NotationError):
    """A score file that cannot be parsed.

    Parameters
    ----------
    message : str
        What was wrong and what was expected.
    path : str or None
        The file, when known.
    line : int or None
        1-based line number, when known.

    A message longer than :data:`MAX_MESSAGE_CHARS` (a bad token quoted from
    a hostile file) is cut there, so the error stays one readable line.
    """

    #: Longest message kept, characters.
    MAX_MESSAGE_CHARS = 300

    def __init__(self, message: str, path: str | None = None, line: int | None = None):
        if len(message) > self.MAX_MESSAGE_CHARS:
            message = message[: self.MAX_MESSAGE_CHARS - 1] + "…"
        self.path = path
        self.line = line
        where = ""
        if path is not None:
            where = f"{path}:"
            if line is not None:
                where += f"{line}:"
            where += " "
        elif line is not None:
            where = f"line {line}: "
        super().__init__(where + message)


class SyntheticError(C2NError):
    """The virtual dancer cannot interpret, animate or render what it was given."""


class VideoError(C2NError):
    """Unreadable, empty or corrupt video / image folder."""


class AudioError(VideoError):
    """A sound track that cannot be decoded, written or muxed (a video's audio, or a music file)."""


class ModelError(C2NError):
    """The pose model cannot be fetched, converted, verified or loaded."""


class KeypointError(C2NError):
    """Keypoint extraction failed (no person, bad track file...)."""


class MotionFileError(C2NError):
    """A BVH, Kinect CSV or truth sidecar that cannot be read."""


class CalibrationError(C2NError):
    """A camera calibration that cannot be read, made or used (file, board, cameras)."""


class FittingError(C2NError):
    """3D fitting failed or its input is unusable."""


class QuantiseError(C2NError):
    """Segmentation / quantisation into symbols failed."""


class EffortError(C2NError):
    """Effort estimation failed or its input is unusable."""


class CompareError(C2NError):
    """Two performances cannot be compared (no overlap, no alignment...)."""


class PipelineError(C2NError):
    """An end-to-end job failed (bad configuration, missing inputs...)."""
