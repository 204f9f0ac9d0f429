"""The ``.lab`` score text format of DESIGN.md.

::

    title: Third port de bras
    tempo: 64
    meter: 4
    effort: time=-2.42 weight=0.6 space=0.0     # or   emotion: happy
    # start  duration  part         direction      level    [bend=N]
    0        4         support      place          middle
    0        1         right_arm    forward        low      bend=1

Rules
-----
* A header line is ``key: value`` with key one of ``title tempo meter effort
  emotion``, each at most once, anywhere in the file.  Defaults: empty title,
  tempo 60, meter 4, no effort, no emotion.
* ``#`` starts a comment, on its own line or after a symbol or a header
  value -- except on the ``title:`` line, whose value is the rest of the line
  verbatim (so titles may contain ``#``).  A title with surrounding
  whitespace, a carriage return or a leading ``"`` is written as a JSON
  string literal (``title: "  x "``), which the reader recognises.
* Starts and durations are exact beats: ``1``, ``1/2``, ``.50``, ``1.5``
  are all read as exact fractions.  ``bend=N`` is optional (0 when absent).
* Turns, flight and the key (DESIGN.md)::

      axes: body                       # optional header: standard (default) | body
      4    1    turn      right  amount=1/2    # half a turn clockwise
      6    1/2  support   air                  # no foot on the floor

  A turn's level column holds ``amount=F`` (full turns, a multiple of 1/8);
  ``support air`` has no level.  ``axes:`` is written only for a body key.
* Range guards (:mod:`capture2notation.notation.limits`): numbers at most
  40 characters and without exponents, at most 50,000 symbols, the text at
  most 16 MiB; the model checks tempo, meter, beats and the score's length.
* :func:`dumps` writes a canonical form (header, column comment, symbols in
  score order, fractions as ``p/q``, Effort floats with ``repr`` so they read
  back bit-for-bit), hence parse → write → parse is exact.
"""

from __future__ import annotations

import json
import math
import re
from fractions import Fraction
from typing import Any

from ...errors import NotationError, ScoreFormatError
from ..limits import MAX_METER, MAX_SCORE_BYTES, MAX_SYMBOLS, MAX_TEMPO, MIN_TEMPO
from ..model import AIR, AXES, DIRECTIONS, EMOTIONS, LEVELS, PARTS, TURN_PART, Effort, Score, Symbol, parse_number

__all__ = ["COLUMNS", "check_overlaps", "dumps", "format_fraction", "loads", "parse_fraction"]

#: The symbol columns, as named in the column comment the writer emits.
COLUMNS = "start duration part direction level [bend=N]"
HEADER_KEYS: tuple[str, ...] = ("title", "tempo", "meter", "effort", "emotion", "axes")
EFFORT_KEYS: tuple[str, ...] = ("time", "weight", "space")

_HEADER_RE = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*:(.*)$", re.DOTALL)
_BEND_RE = re.compile(r"^bend=(.*)$")
_AMOUNT_RE = re.compile(r"^amount=(.*)$")


def format_fraction(value: Fraction) -> str:
    """``'3/2'`` for a non-integer fraction, ``'4'`` for an integer one."""
    return str(Fraction(value))


def parse_fraction(token: str, what: str) -> Fraction:
    """Exact fraction from ``'3/2'``, ``'.50'``, ``'1.5'`` or ``'2'``.

    Raises
    ------
    NotationError
        Naming `what`, the bad token and the expected forms.
    """
    return parse_number(token, what)


def _strip_comment(text: str) -> str:
    return text.split("#", 1)[0].strip()


def _parse_title(value: str) -> str:
    value = value.strip()
    if value.startswith('"'):
        try:
            title = json.loads(value)
        except json.JSONDecodeError as exc:
            raise NotationError(
                f"title {value!r} starts with '\"' but is not a JSON string literal ({exc.msg})"
            ) from None
        if not isinstance(title, str):
            raise NotationError(f"title {value!r} must be a JSON string literal")
        return title
    return value


def _parse_tempo(value: str) -> Fraction:
    value = _strip_comment(value)
    tempo = parse_fraction(value, "tempo")
    if tempo <= 0:
        raise NotationError(f"tempo {value!r} must be > 0 beats per minute")
    if not MIN_TEMPO <= tempo <= MAX_TEMPO:
        raise NotationError(f"tempo {value!r} is outside {MIN_TEMPO}-{MAX_TEMPO} beats per minute")
    return tempo


def _parse_meter(value: str) -> int:
    value = _strip_comment(value)
    if not re.fullmatch(r"\+?[0-9]{1,9}", value) or int(value) <= 0:
        raise NotationError(f"meter {value!r} is not a positive whole number of beats per measure")
    if int(value) > MAX_METER:
        raise NotationError(f"meter {value!r} exceeds the limit of {MAX_METER} beats per measure")
    return int(value)


def _parse_effort(value: str) -> Effort:
    got: dict[str, float] = {}
    for token in _strip_comment(value).split():
        key, sep, num = token.partition("=")
        if not sep or key not in EFFORT_KEYS:
            raise NotationError(f"effort item {token!r} is not understood; expected time=B weight=X0 space=S")
        if key in got:
            raise NotationError(f"effort {key} is given twice")
        try:
            if len(num) > 40:
                raise ValueError
            x = float(num)
        except ValueError:
            raise NotationError(f"effort {key}={num!r} is not a number") from None
        if not math.isfinite(x):
            raise NotationError(f"effort {key}={num!r} must be a finite number")
        got[key] = x
    missing = [k for k in EFFORT_KEYS if k not in got]
    if missing:
        raise NotationError(f"effort is missing {' '.join(missing)}; expected time=B weight=X0 space=S")
    return Effort(**got)


def _parse_emotion(value: str) -> str:
    value = _strip_comment(value)
    if value not in EMOTIONS:
        raise NotationError(f"unknown emotion {value!r}; expected one of {' '.join(EMOTIONS)}")
    return value


def _parse_axes(value: str) -> str:
    value = _strip_comment(value)
    if value not in AXES:
        raise NotationError(f"unknown axes {value!r}; expected one of {' '.join(AXES)}")
    return value


_HEADER_PARSERS = {
    "title": _parse_title,
    "tempo": _parse_tempo,
    "meter": _parse_meter,
    "effort": _parse_effort,
    "emotion": _parse_emotion,
    "axes": _parse_axes,
}


def _parse_symbol(line: str) -> Symbol:
    tokens = _strip_comment(line).split()
    if tokens and tokens[0] in HEADER_KEYS:
        raise NotationError(f"header {tokens[0]!r} needs a colon, e.g. '{tokens[0]}: …'")
    if len(tokens) < 4:
        raise NotationError(f"expected the columns '{COLUMNS}', got {len(tokens)} column(s): {' '.join(tokens)!r}")
    start_t, dur_t, part, direction = tokens[:4]
    start = parse_fraction(start_t, "start")
    duration = parse_fraction(dur_t, "duration")
    if part not in PARTS:
        raise NotationError(f"unknown part {part!r}; expected one of {' '.join(PARTS)}")
    if part == TURN_PART:
        return _parse_turn(start, duration, direction, tokens[4:])
    if part == "support" and direction == AIR:
        if len(tokens) > 4:
            raise NotationError(f"unexpected {tokens[4]!r} after 'support air'; flight has no level")
        return Symbol(start, duration, part, AIR, None)
    if direction not in DIRECTIONS:
        raise NotationError(f"unknown direction {direction!r}; expected one of {' '.join(DIRECTIONS)}")
    if len(tokens) < 5:
        raise NotationError(f"expected the columns '{COLUMNS}', got {len(tokens)} column(s): {' '.join(tokens)!r}")
    level = tokens[4]
    if level not in LEVELS:
        raise NotationError(f"unknown level {level!r}; expected one of {' '.join(LEVELS)}")
    bend = None
    for extra in tokens[5:]:
        m = _BEND_RE.match(extra)
        if m is None:
            raise NotationError(f"unexpected {extra!r} after the level; expected only 'bend=N'")
        if bend is not None:
            raise NotationError(f"bend is given twice ({extra!r})")
        if not re.fullmatch(r"[0-9]{1,3}", m.group(1)):
            raise NotationError(f"bend {m.group(1)!r} is not a whole number; expected bend=0 … bend=6")
        bend = int(m.group(1))
    return Symbol(start, duration, part, direction, level, bend or 0)


def _parse_turn(start: Fraction, duration: Fraction, direction: str, extras: list[str]) -> Symbol:
    if direction not in ("right", "left"):
        raise NotationError(f"unknown turn direction {direction!r}; expected right or left")
    amount = None
    for extra in extras:
        m = _AMOUNT_RE.match(extra)
        if m is None:
            raise NotationError(f"unexpected {extra!r} in a turn; expected 'amount=F' (full turns, e.g. amount=1/2)")
        if amount is not None:
            raise NotationError(f"amount is given twice ({extra!r})")
        amount = parse_fraction(m.group(1), "amount")
    if amount is None:
        raise NotationError("a turn needs 'amount=F' after its direction (full turns, e.g. amount=1/2)")
    return Symbol(start, duration, TURN_PART, direction, None, amount=amount)


def loads(text: str, path: str | None = None) -> Score:
    """Parse ``.lab`` text into a :class:`Score`.

    Parameters
    ----------
    text : str
    path : str, optional
        Only used to name the file in error messages.

    Raises
    ------
    ScoreFormatError
        With the file, the 1-based line number, the bad token and what was
        expected.
    """
    if len(text) > MAX_SCORE_BYTES:
        raise ScoreFormatError(f"{len(text)} characters exceed the limit of {MAX_SCORE_BYTES} for a score", path)
    header: dict[str, tuple[object, int]] = {}
    rows: list[tuple[Symbol, int]] = []
    text = text.removeprefix("\ufeff")  # byte-order mark left by some editors
    for lineno, raw in enumerate(text.split("\n"), 1):
        line = raw[:-1] if raw.endswith("\r") else raw
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        try:
            m = _HEADER_RE.match(stripped)
            if m is not None:
                key = m.group(1)
                if key not in _HEADER_PARSERS:
                    raise NotationError(
                        f"unknown header {key + ':'!r}; expected one of {' '.join(k + ':' for k in HEADER_KEYS)}"
                    )
                if key in header:
                    raise NotationError(f"'{key}:' is given twice (first on line {header[key][1]})")
                header[key] = (_HEADER_PARSERS[key](m.group(2)), lineno)
            else:
                if len(rows) >= MAX_SYMBOLS:
                    raise NotationError(f"more than {MAX_SYMBOLS} symbols, the limit for one score")
                rows.append((_parse_symbol(stripped), lineno))
        except NotationError as exc:
            raise ScoreFormatError(str(exc), path, lineno) from None

    if "effort" in header and "emotion" in header:
        later = max(header["effort"][1], header["emotion"][1])
        raise ScoreFormatError("a score carries either 'effort:' or 'emotion:', not both", path, later)
    check_overlaps(rows, path)
    kw: dict[str, Any] = {key: value for key, (value, _) in header.items()}
    try:
        return Score(symbols=tuple(s for s, _ in rows), **kw)
    except NotationError as exc:
        raise ScoreFormatError(str(exc), path) from None


def check_overlaps(rows: list[tuple[Symbol, int]], path: str | None) -> None:
    """Raise, naming both lines, if a symbol starts before its part's previous one ends.

    Parameters
    ----------
    rows : list of (Symbol, int)
        Symbols with their 1-based line numbers, in any order.
    path : str or None
        File named in the error.

    Raises
    ------
    ScoreFormatError
        At the line of the later symbol.
    """
    last: dict[str, tuple[Symbol, int]] = {}
    for sym, lineno in sorted(rows, key=lambda r: (r[0].sort_key(), r[1])):
        prev = last.get(sym.part)
        if prev is not None and sym.start < prev[0].end:
            raise ScoreFormatError(
                f"{sym.part}: symbol at beat {sym.start} starts before the one on line "
                f"{prev[1]} ends at beat {prev[0].end}; expected one symbol at a time per part",
                path,
                lineno,
            )
        last[sym.part] = (sym, lineno)


def _format_title(title: str) -> str:
    if title != title.strip() or title.startswith('"') or "\r" in title:
        return json.dumps(title, ensure_ascii=False)
    return title


def dumps(score: Score) -> str:
    """Canonical ``.lab`` text of `score` (ends with a newline)."""
    title = _format_title(score.title)
    lines = [
        "title:" + (" " + title if title else ""),
        f"tempo: {format_fraction(score.tempo)}",
        f"meter: {score.meter}",
    ]
    if score.effort is not None:
        e = score.effort
        lines.append(f"effort: time={e.time!r} weight={e.weight!r} space={e.space!r}")
    if score.emotion is not None:
        lines.append(f"emotion: {score.emotion}")
    if score.axes != "standard":
        lines.append(f"axes: {score.axes}")
    lines.append(f"# {'start':<7} {'duration':<9} {'part':<16} {'direction':<14} {'level':<7} [bend=N]")
    for s in score.symbols:
        if s.amount is not None:
            level = f"amount={format_fraction(s.amount)}"
        else:
            level = s.level or ""
        row = (
            f"{format_fraction(s.start):<9} {format_fraction(s.duration):<9} {s.part:<16} {s.direction:<14} {level:<7}"
        )
        if s.bend:
            row += f" bend={s.bend}"
        lines.append(row.rstrip())
    return "\n".join(lines) + "\n"
