"""Score files: one front door, explicitly registered formats.

``read(path)`` and ``write(score, path)`` pick the format from the file name
(the longest registered name ending that matches) unless ``format=`` names it.
Every format is registered below by :func:`register_format`; nothing is
discovered implicitly.

========================  ========================================  =====  =====
format                    file names                                read   write
========================  ========================================  =====  =====
``lab``                   ``*.lab``                                 yes    yes
``json``                  ``*.json``                                yes    yes
``wolofsky1974``          ``*.w74``, ``*.txt``                      yes    no
``laban_editor``          ``*laban_editor.json``                    yes    yes
========================  ========================================  =====  =====
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

from ...errors import ScoreFormatError
from ..limits import MAX_SCORE_BYTES
from ..model import Score

__all__ = [
    "ScoreFormat",
    "dumps",
    "format_for",
    "formats",
    "loads",
    "read",
    "register_format",
    "write",
]


@dataclass(frozen=True)
class ScoreFormat:
    """A registered score format.

    Parameters
    ----------
    name : str
        Name used with ``format=``.
    suffixes : tuple of str
        File-name endings that select this format (case-insensitive), e.g.
        ``(".lab",)``; a longer ending wins over a shorter one.
    loads : callable or None
        ``loads(text, path) -> Score``; `path` (str or None) is only used in
        error messages.  None if the format cannot be read.
    dumps : callable or None
        ``dumps(score) -> str``.  None if the format cannot be written.
    description : str
        One line for error messages and listings.
    """

    name: str
    suffixes: tuple
    loads: Callable | None
    dumps: Callable | None
    description: str = ""


_REGISTRY: dict[str, ScoreFormat] = {}


def register_format(
    name: str,
    suffixes,
    loads: Callable | None = None,
    dumps: Callable | None = None,
    description: str = "",
) -> ScoreFormat:
    """Register (or replace) a score format; return its record."""
    fmt = ScoreFormat(name, tuple(s.lower() for s in suffixes), loads, dumps, description)
    _REGISTRY[name] = fmt
    return fmt


def formats() -> MappingProxyType:
    """Read-only view of the registered formats by name."""
    return MappingProxyType(_REGISTRY)


def format_for(path, format: str | None = None) -> ScoreFormat:
    """The format named by `format`, else the one whose suffix ends `path`'s name.

    Raises
    ------
    ScoreFormatError
        Unknown format name or unrecognised file name.
    """
    if format is not None:
        if format not in _REGISTRY:
            raise ScoreFormatError(
                f"unknown score format {format!r}; expected one of {' '.join(_REGISTRY)}",
                str(path) if path is not None else None,
            )
        return _REGISTRY[format]
    name = Path(path).name.lower()
    best, best_len = None, -1
    for fmt in _REGISTRY.values():
        for suffix in fmt.suffixes:
            if name.endswith(suffix) and len(suffix) > best_len:
                best, best_len = fmt, len(suffix)
    if best is None:
        known = " ".join(s for f in _REGISTRY.values() for s in f.suffixes)
        raise ScoreFormatError(
            f"cannot tell the score format from the file name; expected a name ending in one of "
            f"{known}, or pass format= one of {' '.join(_REGISTRY)}",
            str(path),
        )
    return best


def loads(text: str, format: str, path=None) -> Score:
    """Parse score `text` in the named `format` (`path` only labels errors)."""
    fmt = format_for(path, format)
    if fmt.loads is None:
        raise ScoreFormatError(f"the {fmt.name} format can be written but not read", path)
    return fmt.loads(text, None if path is None else str(path))


def dumps(score: Score, format: str) -> str:
    """Serialise `score` in the named `format`."""
    fmt = format_for(None, format)
    if fmt.dumps is None:
        raise ScoreFormatError(f"the {fmt.name} format ({fmt.description}) is read-only; write .lab or .json instead")
    return fmt.dumps(score)


def read(path, format: str | None = None) -> Score:
    """Read a score file.

    Parameters
    ----------
    path : str or Path
    format : str, optional
        A registered format name; by default chosen from the file name.

    Raises
    ------
    ScoreFormatError
        Unreadable file, unknown format, a file over
        :data:`~capture2notation.notation.limits.MAX_SCORE_BYTES`, or
        malformed content (the message names the file, the line and what
        was expected).
    """
    fmt = format_for(path, format)
    if fmt.loads is None:
        raise ScoreFormatError(f"the {fmt.name} format can be written but not read", str(path))
    try:
        size = Path(path).stat().st_size
        if size > MAX_SCORE_BYTES:
            raise ScoreFormatError(f"{size} bytes exceed the limit of {MAX_SCORE_BYTES} for a score file", str(path))
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ScoreFormatError(f"cannot read score file: {exc.strerror or exc}", str(path)) from None
    except UnicodeDecodeError as exc:
        raise ScoreFormatError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", str(path)) from None
    return fmt.loads(text, str(path))


def write(score: Score, path, format: str | None = None) -> Path:
    """Write `score` atomically to `path`; return the path.

    Raises
    ------
    ScoreFormatError
        Unknown or read-only format.
    """
    if not isinstance(score, Score):
        raise ScoreFormatError(f"write() needs a Score, got {type(score).__name__}", str(path))
    fmt = format_for(path, format)
    if fmt.dumps is None:
        raise ScoreFormatError(
            f"the {fmt.name} format ({fmt.description}) is read-only; write .lab or .json instead",
            str(path),
        )
    # Imported late: io may itself import the notation formats (truth sidecar).
    from ...atomic import write_text

    return write_text(path, fmt.dumps(score))


def _register_builtin() -> None:
    # The one explicit list of built-in formats (nothing is discovered).
    from . import json_format, lab, laban_editor, wolofsky1974

    register_format("lab", (".lab",), lab.loads, lab.dumps, "score text format of DESIGN.md")
    register_format("json", (".json",), json_format.loads, json_format.dumps, "JSON form of the score")
    register_format(
        "wolofsky1974",
        (".w74", ".txt"),
        wolofsky1974.loads,
        None,
        "Wolofsky 1974 coded input (Figure 7)",
    )
    register_format(
        "laban_editor",
        ("laban_editor.json",),
        laban_editor.loads,
        laban_editor.dumps,
        "LabanotationSuite LabanEditor score",
    )


_register_builtin()
