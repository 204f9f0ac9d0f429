"""The ``c2n`` command line.

Each sub-command lives in its own module under :mod:`pipelines.commands` and
is registered here explicitly, so ``c2n --help`` lists exactly what exists.

What reaches the terminal is one line per event: ``c2n: error: ...`` (exit
status 2) for a library error, a bad option or an operating-system error;
``c2n: warning: ...`` for the library's warnings (Python's ``warnings`` are
routed through :mod:`logging`, without source paths); third-party numeric
warnings only with ``-v``.
"""

from __future__ import annotations

import importlib
import logging
import os
import sys
import warnings

import click

from capture2notation import __version__
from capture2notation.errors import C2NError

# (module under pipelines.commands, attribute holding the click command)
_COMMANDS: tuple[tuple[str, str], ...] = (
    ("render", "render"),
    ("demo", "demo"),
    ("keypoints", "keypoints"),
    ("models", "models"),
    ("effort", "effort"),
    ("score", "score"),
    ("fidelity", "fidelity_study"),
    ("capture", "capture"),
    ("calibrate", "calibrate"),
)

#: Packages whose warnings are addressed to the user.
_OUR_PACKAGES = ("capture2notation", "synthetic", "pipelines")

log = logging.getLogger("c2n")


def _one_line(text: str) -> str:
    return " ".join(part.strip() for part in str(text).splitlines() if part.strip())


class _StderrHandler(logging.Handler):
    """Writes records to whatever ``sys.stderr`` is at the time (click's test runner swaps it)."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            click.echo(self.format(record), err=True)
        except Exception:  # as logging.StreamHandler: a handler reports its failure, never raises
            self.handleError(record)


class _OneLineFormatter(logging.Formatter):
    """``c2n: warning: message`` on one line (the logger's name too with ``-vv``)."""

    def __init__(self, names: bool):
        super().__init__()
        self.names = names

    def format(self, record: logging.LogRecord) -> str:
        who = f"{record.name}: " if self.names else ""
        return f"c2n: {record.levelname.lower()}: {who}{_one_line(record.getMessage())}"


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """`warnings.showwarning` for the command line: one log line, no source path.

    The library's own warnings (and any ``UserWarning``) are warnings; other
    categories from third parties (numpy's ``RuntimeWarning`` on an all-NaN
    slice, deprecations) are diagnostics, shown with ``-v``.
    """
    ours = category.__module__.split(".")[0] in _OUR_PACKAGES or issubclass(category, UserWarning)
    log.log(logging.WARNING if ours else logging.INFO, "%s", message)


def _fail(message: str) -> None:
    click.echo(f"c2n: error: {_one_line(message)}", err=True)
    sys.exit(2)


class _Group(click.Group):
    """Turns library, option and operating-system errors into one-line messages."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except C2NError as exc:
            _fail(str(exc))
        except click.UsageError as exc:
            name = f"{exc.ctx.info_name}: " if exc.ctx is not None else ""
            _fail(f"{name}{exc.format_message()} (see --help)")
        except OSError as exc:
            where = f"{exc.filename}: " if exc.filename else ""
            _fail(f"{where}{exc.strerror or exc}")
        except MemoryError:
            _fail("out of memory; try a shorter clip or fewer frames")


def setup_logging(verbose: int) -> None:
    """One-line log records on stderr; Python warnings routed into them."""
    handler = _StderrHandler()
    handler.setFormatter(_OneLineFormatter(names=verbose >= 2))
    root = logging.getLogger()
    for h in list(root.handlers):
        if isinstance(h, _StderrHandler):  # ours from an earlier call (tests invoke main repeatedly)
            root.removeHandler(h)
    root.addHandler(handler)
    root.setLevel(logging.WARNING - 10 * min(verbose, 2))
    warnings.showwarning = _show_warning
    if verbose < 2:
        # FFmpeg inside OpenCV prints its own lines ("moov atom not found",
        # "partial file") on a damaged video; the VideoError or the truncation
        # warning says the same in one line.
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")


@click.group(cls=_Group)
@click.version_option(__version__, prog_name="c2n")
@click.option("-v", "--verbose", count=True, help="More log output (-vv for debug).")
def main(verbose: int) -> None:
    """capture2notation: dance on video or motion capture → dance notation."""
    setup_logging(verbose)


for _module, _attr in _COMMANDS:
    main.add_command(getattr(importlib.import_module(f"pipelines.commands.{_module}"), _attr))


if __name__ == "__main__":  # ``python -m pipelines.cli`` as well as the ``c2n`` script
    main()
