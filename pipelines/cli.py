"""The ``c2n`` command line.

Each sub-command lives in its own module under :mod:`pipelines.commands` and
is registered here explicitly, so ``c2n --help`` lists exactly what exists.
"""

from __future__ import annotations

import importlib
import logging
import sys

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
)


class _Group(click.Group):
    """Turns library errors into one-line messages instead of tracebacks."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except C2NError as exc:
            click.echo(f"c2n: error: {exc}", err=True)
            sys.exit(2)


@click.group(cls=_Group)
@click.version_option(__version__, prog_name="c2n")
@click.option("-v", "--verbose", count=True, help="More log output (-vv for debug).")
def main(verbose: int) -> None:
    """capture2notation: dance on video or motion capture → dance notation."""
    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")


for _module, _attr in _COMMANDS:
    main.add_command(getattr(importlib.import_module(f"pipelines.commands.{_module}"), _attr))
