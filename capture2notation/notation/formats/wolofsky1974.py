"""Wolofsky's 1974 coded input (LABAN program, Figure 7), read only.

Five whitespace-separated columns per line::

    type  start  part  duration  code
    2     0.00   ANR   4.00      -
    1     2.00   WLL   .50       LSM
    0     4.00   -     -         -

* ``type``: 2 support, 1 gesture, 0 end of input (later lines are ignored).
* ``start``/``duration``: beats, read as exact decimals (``.50`` = 1/2).
* ``part``: ``WLL``/``WRL`` whole left/right leg, ``WLA``/``WRA`` whole
  left/right arm (gestures); ``ANL``/``ANR`` left/right ankle (supports).
  These are the codes the thesis defines in its text; its numbered body-part
  table (Figure 6) survives only as a drawing, so no other codes are guessed.
* ``code``: direction ``F B RS LS RDF LDF RDB LDB P`` followed by an
  optional level ``H``/``M``/``L`` (middle when absent); ``-`` for a support
  means place middle (standing on that foot).  Several codes in one entry
  (Wolofsky's "intermediate positions") have no symbol in our model and are
  rejected.

The coded input carries no tempo, meter or title; this reader uses tempo 60
beats per minute, meter 4 and the file's stem as the title (the thesis reads
the tempo separately, with the cine rate); range guards as for ``.lab``
(numbers at most 40 characters, at most 50,000 symbols, 16 MiB).  Blank lines, ``#`` comments and a
leading column-heading line starting with ``Type`` are skipped.  Writing this
format is not supported: scores are written as ``.lab`` or ``.json``.
"""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path
from types import MappingProxyType

from ...errors import NotationError, ScoreFormatError
from ..limits import MAX_SCORE_BYTES, MAX_SYMBOLS, MAX_TITLE_CHARS
from ..model import Score, Symbol
from .lab import check_overlaps, parse_fraction

__all__ = ["DEFAULT_METER", "DEFAULT_TEMPO", "DIRECTION_CODES", "LEVEL_CODES", "PART_CODES", "loads"]

DEFAULT_TEMPO = Fraction(60)
DEFAULT_METER = 4

#: 1974 body-part codes → (our part, movement type that may use it).
PART_CODES: MappingProxyType = MappingProxyType(
    {
        "WLL": ("left_leg", 1),
        "WRL": ("right_leg", 1),
        "WLA": ("left_arm", 1),
        "WRA": ("right_arm", 1),
        "ANL": ("left_support", 2),
        "ANR": ("right_support", 2),
    }
)
DIRECTION_CODES: MappingProxyType = MappingProxyType(
    {
        "F": "forward",
        "B": "back",
        "RS": "right",
        "LS": "left",
        "RDF": "right_forward",
        "LDF": "left_forward",
        "RDB": "right_back",
        "LDB": "left_back",
        "P": "place",
    }
)
LEVEL_CODES: MappingProxyType = MappingProxyType({"H": "high", "M": "middle", "L": "low", "": "middle"})
_CODE_RE = re.compile(r"^(RDF|LDF|RDB|LDB|RS|LS|F|B|P)([HML]?)$")
_TYPES = {"0": "end", "1": "gesture", "2": "support"}


def _direction_level(code: str) -> tuple[str, str]:
    m = _CODE_RE.match(code)
    if m is None:
        raise NotationError(
            f"unknown direction/level code {code!r}; expected one of "
            f"{' '.join(DIRECTION_CODES)} followed by an optional H, M or L"
        )
    return DIRECTION_CODES[m.group(1)], LEVEL_CODES[m.group(2)]


def _symbol(tokens: list[str]) -> Symbol:
    mtype, start_t, part_code, dur_t, *codes = tokens
    if part_code not in PART_CODES:
        raise NotationError(f"unknown body-part code {part_code!r}; expected one of {' '.join(PART_CODES)}")
    part, allowed = PART_CODES[part_code]
    if int(mtype) != allowed:
        kind = "support (type 2)" if allowed == 2 else "gesture (type 1)"
        raise NotationError(f"{part_code} is a {kind}, but the line has type {mtype}")
    start = parse_fraction(start_t, "start")
    duration = parse_fraction(dur_t, "duration")
    if len(codes) > 1:
        raise NotationError(
            f"several codes {' '.join(codes)!r} (an intermediate position) cannot be represented; "
            "expected one direction/level code"
        )
    code = codes[0]
    if code == "-":
        if allowed != 2:
            raise NotationError(f"'-' is only valid for supports; {part_code} needs a direction code")
        direction, level = "place", "middle"
    else:
        direction, level = _direction_level(code)
    return Symbol(start, duration, part, direction, level)


def loads(text: str, path: str | None = None) -> Score:
    """Parse 1974 coded input into a :class:`Score`.

    Raises
    ------
    ScoreFormatError
        Naming the file, the line, the bad token and what was expected.
    """
    if len(text) > MAX_SCORE_BYTES:
        raise ScoreFormatError(f"{len(text)} characters exceed the limit of {MAX_SCORE_BYTES} for a score", path)
    rows: list[tuple[Symbol, int]] = []
    seen_data = False
    text = text.removeprefix("\ufeff")  # byte-order mark left by some editors
    for lineno, raw in enumerate(text.split("\n"), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        tokens = line.split()
        if not seen_data and tokens[0].lower() == "type":
            continue
        seen_data = True
        try:
            if tokens[0] not in _TYPES:
                raise NotationError(
                    f"unknown movement type {tokens[0]!r}; expected 2 (support), 1 (gesture) or 0 (end)"
                )
            if tokens[0] == "0":
                break
            if len(tokens) < 5:
                raise NotationError(
                    f"expected the columns 'type start part duration code', got {len(tokens)}: {line!r}"
                )
            if len(rows) >= MAX_SYMBOLS:
                raise NotationError(f"more than {MAX_SYMBOLS} symbols, the limit for one score")
            rows.append((_symbol(tokens), lineno))
        except NotationError as exc:
            raise ScoreFormatError(str(exc), path, lineno) from None
    check_overlaps(rows, path)
    title = Path(path).stem.replace("\n", " ")[:MAX_TITLE_CHARS] if path else ""
    try:
        return Score(symbols=tuple(s for s, _ in rows), title=title, tempo=DEFAULT_TEMPO, meter=DEFAULT_METER)
    except NotationError as exc:
        raise ScoreFormatError(str(exc), path) from None
