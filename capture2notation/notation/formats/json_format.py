"""The JSON form of a score: the same content as ``.lab``, for machines.

::

    {"format": "capture2notation.score", "version": 1,
     "title": "Figure 7", "tempo": 60, "meter": 4,
     "effort": {"time": -2.42, "weight": 0.6, "space": 0.0} | null,
     "emotion": "happy" | null,
     "symbols": [{"start": "1/2", "duration": "1", "part": "left_leg",
                  "direction": "forward", "level": "middle", "bend": 0}, ...]}

Beats (``start``, ``duration``) are written as exact ``"p/q"`` strings; the
tempo as an integer when whole, else ``"p/q"``.  The reader also accepts
integers and exactly representable floats (0.5) for beats and tempo, and
``bend`` may be omitted (0).  ``format``/``version`` are written for
identification and checked only if present.  Schema errors name the JSON
path of the bad value, e.g. ``symbols[3].direction``.
"""

from __future__ import annotations

import json
import math
from fractions import Fraction
from typing import Any, NoReturn

from ...errors import NotationError, ScoreFormatError
from ..model import EMOTIONS, Effort, Score, Symbol, as_fraction
from .lab import format_fraction

__all__ = ["FORMAT_TAG", "VERSION", "dumps", "loads", "score_from_dict", "score_to_dict"]

FORMAT_TAG = "capture2notation.score"
VERSION = 1
_TOP_KEYS = frozenset({"format", "version", "title", "tempo", "meter", "effort", "emotion", "symbols"})
_SYMBOL_KEYS = ("start", "duration", "part", "direction", "level", "bend")


def _tempo_json(tempo: Fraction):
    return int(tempo) if tempo.denominator == 1 else format_fraction(tempo)


def score_to_dict(score: Score) -> dict:
    """Plain JSON-serialisable dict of `score` (see the module docstring)."""
    e = score.effort
    return {
        "format": FORMAT_TAG,
        "version": VERSION,
        "title": score.title,
        "tempo": _tempo_json(score.tempo),
        "meter": score.meter,
        "effort": None if e is None else {"time": e.time, "weight": e.weight, "space": e.space},
        "emotion": score.emotion,
        "symbols": [
            {
                "start": format_fraction(s.start),
                "duration": format_fraction(s.duration),
                "part": s.part,
                "direction": s.direction,
                "level": s.level,
                "bend": s.bend,
            }
            for s in score.symbols
        ],
    }


class _Where:
    """Raise ScoreFormatError naming the file and the JSON path."""

    def __init__(self, path: str | None):
        self.path = path

    def fail(self, jpath: str, message: str) -> NoReturn:
        raise ScoreFormatError(f"{jpath}: {message}" if jpath else message, self.path)


def _fraction(value, jpath: str, where: _Where) -> Fraction:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        where.fail(jpath, f"expected a number or a 'p/q' string, got {json.dumps(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        where.fail(jpath, f"expected a finite number, got {value!r}")
    try:
        return as_fraction(value, "value")
    except NotationError as exc:
        where.fail(jpath, str(exc))


def _symbol(item, jpath: str, where: _Where) -> Symbol:
    if not isinstance(item, dict):
        where.fail(jpath, f"expected an object with {', '.join(_SYMBOL_KEYS)}, got {json.dumps(item)}")
    for key in item:
        if key not in _SYMBOL_KEYS:
            where.fail(f"{jpath}.{key}", f"unknown key; expected one of {' '.join(_SYMBOL_KEYS)}")
    for key in _SYMBOL_KEYS[:5]:
        if key not in item:
            where.fail(f"{jpath}.{key}", "missing")
    start = _fraction(item["start"], f"{jpath}.start", where)
    duration = _fraction(item["duration"], f"{jpath}.duration", where)
    for key in ("part", "direction", "level"):
        if not isinstance(item[key], str):
            where.fail(f"{jpath}.{key}", f"expected a string, got {json.dumps(item[key])}")
    bend = item.get("bend", 0)
    if isinstance(bend, bool) or not isinstance(bend, int):
        where.fail(f"{jpath}.bend", f"expected a whole number 0-6, got {json.dumps(bend)}")
    try:
        return Symbol(start, duration, item["part"], item["direction"], item["level"], bend)
    except NotationError as exc:
        # Point at the field the model complained about when it is clear.
        msg = str(exc)
        for key in ("part", "direction", "level", "bend", "start", "duration"):
            if msg.startswith((f"unknown {key}", f"{key} ", f"{key}=")):
                where.fail(f"{jpath}.{key}", msg)
        where.fail(jpath, msg)


def score_from_dict(data, path: str | None = None) -> Score:
    """Build a :class:`Score` from the dict of :func:`score_to_dict`.

    Parameters
    ----------
    data : dict
    path : str, optional
        Names the file in error messages.

    Raises
    ------
    ScoreFormatError
        Naming the JSON path of the bad value and what was expected.
    """
    where = _Where(path)
    if not isinstance(data, dict):
        where.fail("", f"expected a JSON object at the top level, got {type(data).__name__}")
    for key in data:
        if key not in _TOP_KEYS:
            where.fail(key, f"unknown key; expected one of {' '.join(sorted(_TOP_KEYS))}")
    if "format" in data and data["format"] != FORMAT_TAG:
        where.fail("format", f"expected {FORMAT_TAG!r}, got {json.dumps(data['format'])}")
    if "version" in data and data["version"] != VERSION:
        where.fail("version", f"unsupported version {json.dumps(data['version'])}; expected {VERSION}")
    kw: dict[str, Any] = {}
    title = data.get("title", "")
    if not isinstance(title, str) or "\n" in title:
        where.fail("title", f"expected a one-line string, got {json.dumps(title)}")
    kw["title"] = title
    if "tempo" in data:
        kw["tempo"] = _fraction(data["tempo"], "tempo", where)
        if kw["tempo"] <= 0:
            where.fail("tempo", f"must be > 0 beats per minute, got {json.dumps(data['tempo'])}")
    if "meter" in data:
        m = data["meter"]
        if isinstance(m, bool) or not isinstance(m, int) or m <= 0:
            where.fail("meter", f"expected a positive whole number of beats, got {json.dumps(m)}")
        kw["meter"] = m
    effort = data.get("effort")
    if effort is not None:
        if not isinstance(effort, dict):
            where.fail("effort", f"expected an object {{time, weight, space}} or null, got {json.dumps(effort)}")
        vals = {}
        for key in ("time", "weight", "space"):
            v = effort.get(key)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                where.fail(f"effort.{key}", f"expected a number, got {json.dumps(v)}")
            vals[key] = float(v)
        for key in effort:
            if key not in vals:
                where.fail(f"effort.{key}", "unknown key; expected time weight space")
        try:
            kw["effort"] = Effort(**vals)
        except NotationError as exc:
            where.fail("effort", str(exc))
    emotion = data.get("emotion")
    if emotion is not None:
        if emotion not in EMOTIONS:
            where.fail(
                "emotion",
                f"unknown emotion {json.dumps(emotion)}; expected one of {' '.join(EMOTIONS)} or null",
            )
        kw["emotion"] = emotion
    symbols = data.get("symbols", [])
    if not isinstance(symbols, list):
        where.fail("symbols", f"expected a list, got {type(symbols).__name__}")
    syms = tuple(_symbol(item, f"symbols[{i}]", where) for i, item in enumerate(symbols))
    try:
        return Score(symbols=syms, **kw)
    except NotationError as exc:
        where.fail("symbols" if "starts before" in str(exc) else "", str(exc))


def loads(text: str, path: str | None = None) -> Score:
    """Parse JSON score text (errors name the file and the JSON path or line)."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ScoreFormatError(f"invalid JSON: {exc.msg} (column {exc.colno})", path, exc.lineno) from None
    return score_from_dict(data, path)


def dumps(score: Score) -> str:
    """Indented JSON text of `score` (ends with a newline)."""
    return json.dumps(score_to_dict(score), ensure_ascii=False, indent=1) + "\n"
