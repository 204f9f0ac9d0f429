"""Checks shared by the commands' options: finite numbers in range, output folders.

Each check fails with one line that names the option and the bad value
(click prints it as ``c2n: error: ...``, exit status 2) before any work
starts, so a typo never costs a long run or leaves files behind.
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import click

from capture2notation.errors import PipelineError
from capture2notation.notation.limits import MAX_TEMPO, MIN_TEMPO

__all__ = [
    "FPS",
    "TEMPO",
    "TEMPO_OR_NONE",
    "Number",
    "TempoOrNone",
    "check_outdir",
    "check_output_file",
    "score_format_or_fail",
]


class Number(click.ParamType):
    """A finite number within ``[low, high]`` (``(low, high]`` when `open_low`).

    Parameters
    ----------
    low, high : float
    unit : str
        Printed after the range in messages.
    open_low : bool
        Exclude `low` itself (a rate or a tolerance of 0 means nothing).
    """

    name = "number"

    def __init__(self, low: float, high: float, unit: str = "", *, open_low: bool = False):
        self.low, self.high, self.unit, self.open_low = float(low), float(high), unit, open_low

    def range_text(self) -> str:
        lo = "(" if self.open_low else "["
        return f"{lo}{self.low:g}, {self.high:g}]" + (f" {self.unit}" if self.unit else "")

    def convert(self, value, param, ctx):
        if isinstance(value, float) and not isinstance(value, bool):
            v = value
        else:
            try:
                v = float(str(value).strip())
            except ValueError:
                self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(v):
            self.fail(f"{value!r} is not a finite number; expected {self.range_text()}", param, ctx)
        if v < self.low or v > self.high or (self.open_low and v == self.low):
            self.fail(f"{value!r} is outside {self.range_text()}", param, ctx)
        return v


#: Beats per minute a score can have (:mod:`capture2notation.notation.limits`).
TEMPO = Number(float(MIN_TEMPO), float(MAX_TEMPO), "beats per minute")


class TempoOrNone(click.ParamType):
    """A tempo in :data:`TEMPO`'s range, or ``none`` (time written as it is: 60 bpm)."""

    name = "tempo"

    def convert(self, value, param, ctx):
        if isinstance(value, str) and value.strip().lower() == "none":
            return "none"
        try:
            return TEMPO.convert(value, param, ctx)
        except click.BadParameter as exc:
            self.fail(f"{exc.message}; or 'none' to write time as it is", param, ctx)


#: ``--tempo`` of a capture: beats per minute, or ``none``.
TEMPO_OR_NONE = TempoOrNone()
#: Frames per second of a video, a motion file or a rendered performance
#: (the readers' :data:`~capture2notation.io.limits.MAX_FPS`).
FPS = Number(0, 1000, "frames per second", open_low=True)


def _nearest_existing(path: Path) -> Path:
    p = path.absolute()
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def check_outdir(path, option: str = "-o") -> Path:
    """`path` if it is, or can be made, a folder this process can write to.

    Nothing is created: a command that fails later leaves no empty folder.

    Raises
    ------
    PipelineError
        The path is a file, lies below a file, or the nearest existing folder
        above it cannot be written.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise PipelineError(f"{option} {path}: is a file, not a folder")
    anchor = _nearest_existing(path)
    if not anchor.is_dir():
        raise PipelineError(f"{option} {path}: {anchor} is a file, so no folder can be made below it")
    _check_writable(anchor, option, path)
    return path


def check_output_file(path, option: str = "-o") -> Path:
    """`path` if a file can be written there (its folder exists or can be made, and is writable)."""
    path = Path(path)
    if path.is_dir():
        raise PipelineError(f"{option} {path}: is a folder, not a file")
    anchor = _nearest_existing(path.parent)
    if not anchor.is_dir():
        raise PipelineError(f"{option} {path}: {anchor} is a file, so no file can be made below it")
    _check_writable(anchor, option, path)
    return path


def _check_writable(folder: Path, option: str, path: Path) -> None:
    # Try it: permission bits say nothing for root or on a read-only mount.
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".c2n-write-test-")
    except OSError as exc:
        raise PipelineError(f"{option} {path}: cannot write in {folder} ({exc.strerror})") from None
    os.close(fd)
    os.unlink(probe)


def score_format_or_fail(path, others: str = "") -> None:
    """Refuse `path` unless its name tells a registered score format (a CLI-worded message).

    Parameters
    ----------
    others : str
        What else the command would have accepted, e.g. ``"a capture folder"``.
    """
    from capture2notation.errors import ScoreFormatError
    from capture2notation.notation.formats import format_for, formats

    try:
        format_for(path)
    except ScoreFormatError:
        endings = " ".join(s for f in formats().values() for s in f.suffixes)
        alternatives = f"{others}, or " if others else ""
        raise PipelineError(
            f"{path}: cannot tell what this file is from its name; expected {alternatives}a score file ending in {endings}"
        ) from None
