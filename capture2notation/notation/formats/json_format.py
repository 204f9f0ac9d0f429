"""The JSON form of a score: the same content as ``.lab``, for machines.

::

    {"format": "capture2notation.score", "version": 2,
     "title": "Figure 7", "tempo": 60, "meter": 4,
     "effort": {"time": -2.42, "weight": 0.6, "space": 0.0} | null,
     "emotion": "happy" | null,
     "axes": "standard" | "body",
     "symbols": [{"start": "1/2", "duration": "1", "part": "left_leg",
                  "direction": "forward", "level": "middle", "bend": 0},
                 {"start": "4", "duration": "1", "part": "turn",
                  "direction": "right", "level": null, "bend": 0, "amount": "1/2"},
                 {"start": "6", "duration": "1/2", "part": "support",
                  "direction": "air", "level": null, "bend": 0, "spring": "leap"}, ...]}

Beats (``start``, ``duration``) are written as exact ``"p/q"`` strings; the
tempo as an integer when whole, else ``"p/q"``.  The reader also accepts
integers and exactly representable floats (0.5) for beats and tempo, and
``bend`` may be omitted (0).  A captured symbol carries its
``confidence`` in [0, 1] (optional; absent or null: not assessed).  ``format``/``version`` are written for
identification and checked only if present (versions 1 and 2 are read;
version 1 has no turns, flight or ``axes``).  A turn's ``amount`` is full
turns as ``"p/q"``; a flight's ``spring`` is its spring form
(:func:`~capture2notation.notation.facing.spring_form`, null without a
landing), written for readers and, when present, checked against the
supports on reading.  Schema errors name the JSON path of the bad value,
e.g. ``symbols[3].direction``.  Range guards: the text at most 16 MiB
(:data:`~capture2notation.notation.limits.MAX_SCORE_BYTES`), nesting
deeper than Python's JSON reader allows and integers longer than its
4,300 digits are refused with a one-line error.
"""

from __future__ import annotations

import json
import math
from fractions import Fraction
from typing import Any, NoReturn

from ...errors import NotationError, ScoreFormatError
from ..facing import springs
from ..limits import MAX_SCORE_BYTES, MAX_SYMBOLS
from ..model import AXES, EMOTIONS, Effort, Score, Symbol, as_fraction
from .lab import format_fraction

__all__ = ["FORMAT_TAG", "VERSION", "dumps", "load_json", "loads", "score_from_dict", "score_to_dict"]

FORMAT_TAG = "capture2notation.score"
VERSION = 2
_READ_VERSIONS = (1, 2)
_TOP_KEYS = frozenset({"format", "version", "title", "tempo", "meter", "effort", "emotion", "axes", "symbols"})
_SYMBOL_KEYS = ("start", "duration", "part", "direction", "level", "bend", "amount", "spring", "confidence")
#: Decimals of a written confidence (a probability; more is noise).
CONFIDENCE_DECIMALS = 3
_REQUIRED_KEYS = ("start", "duration", "part", "direction")


def _tempo_json(tempo: Fraction):
    return int(tempo) if tempo.denominator == 1 else format_fraction(tempo)


def score_to_dict(score: Score) -> dict:
    """Plain JSON-serialisable dict of `score` (see the module docstring)."""
    e = score.effort
    forms = {a.start: form for a, form in springs(score)}  # flights never overlap: one per start
    return {
        "format": FORMAT_TAG,
        "version": VERSION,
        "title": score.title,
        "tempo": _tempo_json(score.tempo),
        "meter": score.meter,
        "effort": None if e is None else {"time": e.time, "weight": e.weight, "space": e.space},
        "emotion": score.emotion,
        "axes": score.axes,
        "symbols": [_symbol_dict(forms, s) for s in score.symbols],
    }


def _symbol_dict(forms: dict, s: Symbol) -> dict:
    out: dict[str, Any] = {
        "start": format_fraction(s.start),
        "duration": format_fraction(s.duration),
        "part": s.part,
        "direction": s.direction,
        "level": s.level,
        "bend": s.bend,
    }
    if s.amount is not None:
        out["amount"] = format_fraction(s.amount)
    if s.is_air:
        out["spring"] = forms[s.start]
    if s.confidence is not None:
        out["confidence"] = round(s.confidence, CONFIDENCE_DECIMALS)
    return out


class _Where:
    """Raise ScoreFormatError naming the file and the JSON path."""

    def __init__(self, path: str | None):
        self.path = path

    def fail(self, jpath: str, message: str) -> NoReturn:
        raise ScoreFormatError(f"{jpath}: {message}" if jpath else message, self.path)


def _fraction(value, jpath: str, where: _Where) -> Fraction:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        where.fail(jpath, f"expected a number or a 'p/q' string, got {_show(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        where.fail(jpath, f"expected a finite number, got {value!r}")
    try:
        return as_fraction(value, "value")
    except NotationError as exc:
        where.fail(jpath, str(exc))


def _symbol(item, jpath: str, where: _Where) -> Symbol:
    if not isinstance(item, dict):
        where.fail(jpath, f"expected an object with {', '.join(_SYMBOL_KEYS)}, got {_show(item)}")
    for key in item:
        if key not in _SYMBOL_KEYS:
            where.fail(f"{jpath}.{_key(key)}", f"unknown key; expected one of {' '.join(_SYMBOL_KEYS)}")
    for key in _REQUIRED_KEYS:
        if key not in item:
            where.fail(f"{jpath}.{key}", "missing")
    start = _fraction(item["start"], f"{jpath}.start", where)
    duration = _fraction(item["duration"], f"{jpath}.duration", where)
    for key in ("part", "direction"):
        if not isinstance(item[key], str):
            where.fail(f"{jpath}.{key}", f"expected a string, got {_show(item[key])}")
    levelless = item["part"] == "turn" or (item["part"] == "support" and item["direction"] == "air")
    if "level" not in item and not levelless:
        where.fail(f"{jpath}.level", "missing")
    level = item.get("level")
    if not (isinstance(level, str) or (level is None and levelless)):
        want = "null (turns and flight have no level)" if levelless else "a string"
        where.fail(f"{jpath}.level", f"expected {want}, got {_show(level)}")
    bend = item.get("bend", 0)
    if isinstance(bend, bool) or not isinstance(bend, int):
        where.fail(f"{jpath}.bend", f"expected a whole number 0-6, got {_show(bend)}")
    amount = None
    if item.get("amount") is not None:
        amount = _fraction(item["amount"], f"{jpath}.amount", where)
    confidence = item.get("confidence")
    if confidence is not None and (
        isinstance(confidence, bool)
        or not isinstance(confidence, (int, float))
        or not math.isfinite(confidence)
        or not 0 <= confidence <= 1
    ):
        where.fail(f"{jpath}.confidence", f"expected a number in [0, 1] or null, got {_show(confidence)}")
    try:
        return Symbol(start, duration, item["part"], item["direction"], level, bend, amount, confidence)
    except NotationError as exc:
        # Point at the field the model complained about when it is clear.
        msg = str(exc)
        for key in ("part", "direction", "level", "bend", "start", "duration", "amount"):
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
            where.fail(_key(key), f"unknown key; expected one of {' '.join(sorted(_TOP_KEYS))}")
    if "format" in data and data["format"] != FORMAT_TAG:
        where.fail("format", f"expected {FORMAT_TAG!r}, got {_show(data['format'])}")
    if "version" in data and (isinstance(data["version"], bool) or data["version"] not in _READ_VERSIONS):
        where.fail("version", f"unsupported version {_show(data['version'])}; expected 1 or {VERSION}")
    kw: dict[str, Any] = {}
    title = data.get("title", "")
    if not isinstance(title, str) or "\n" in title:
        where.fail("title", f"expected a one-line string, got {_show(title)}")
    kw["title"] = title
    if "tempo" in data:
        kw["tempo"] = _fraction(data["tempo"], "tempo", where)
        if kw["tempo"] <= 0:
            where.fail("tempo", f"must be > 0 beats per minute, got {_show(data['tempo'])}")
    if "meter" in data:
        m = data["meter"]
        if isinstance(m, bool) or not isinstance(m, int) or m <= 0:
            where.fail("meter", f"expected a positive whole number of beats, got {_show(m)}")
        kw["meter"] = m
    effort = data.get("effort")
    if effort is not None:
        if not isinstance(effort, dict):
            where.fail("effort", f"expected an object {{time, weight, space}} or null, got {_show(effort)}")
        vals = {}
        for key in ("time", "weight", "space"):
            v = effort.get(key)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                where.fail(f"effort.{key}", f"expected a number, got {_show(v)}")
            try:
                vals[key] = float(v)
            except OverflowError:
                where.fail(f"effort.{key}", f"expected a finite number, got {_show(v)}")
        for key in effort:
            if key not in vals:
                where.fail(f"effort.{_key(key)}", "unknown key; expected time weight space")
        try:
            kw["effort"] = Effort(**vals)
        except NotationError as exc:
            where.fail("effort", str(exc))
    emotion = data.get("emotion")
    if emotion is not None:
        if emotion not in EMOTIONS:
            where.fail(
                "emotion",
                f"unknown emotion {_show(emotion)}; expected one of {' '.join(EMOTIONS)} or null",
            )
        kw["emotion"] = emotion
    axes = data.get("axes", "standard")
    if axes not in AXES:
        where.fail("axes", f"unknown axes {_show(axes)}; expected one of {' '.join(AXES)}")
    kw["axes"] = axes
    symbols = data.get("symbols", [])
    if not isinstance(symbols, list):
        where.fail("symbols", f"expected a list, got {type(symbols).__name__}")
    if len(symbols) > MAX_SYMBOLS:
        where.fail("symbols", f"{len(symbols)} symbols exceed the limit of {MAX_SYMBOLS} in one score")
    syms = tuple(_symbol(item, f"symbols[{i}]", where) for i, item in enumerate(symbols))
    try:
        score = Score(symbols=syms, **kw)
    except NotationError as exc:
        msg = str(exc)
        where.fail("symbols" if "starts before" in msg or "overlaps" in msg else _field_of(msg), msg)
    forms = {a.start: form for a, form in springs(score)}
    for i, item in enumerate(symbols):
        if "spring" in item and item["spring"] is not None:
            sym = syms[i]
            if not sym.is_air:
                where.fail(f"symbols[{i}].spring", "only support air has a spring form")
            got = forms[sym.start]
            if item["spring"] != got:
                where.fail(
                    f"symbols[{i}].spring",
                    f"{_show(item['spring'])} does not match the supports before and after, which make a "
                    f"{got or 'flight without landing'}",
                )
    return score


def _field_of(msg: str) -> str:
    for key in ("tempo", "meter", "title", "axes"):
        if msg.startswith(key):
            return key
    return ""


def _key(key: str) -> str:
    return key if len(key) <= 40 else key[:37] + "..."


def _show(value) -> str:
    """Short JSON text of a bad value for an error message."""
    try:
        text = json.dumps(value, ensure_ascii=False)
    except (TypeError, ValueError, RecursionError):
        text = type(value).__name__
    return text if len(text) <= 60 else text[:57] + "..."


def loads(text: str, path: str | None = None) -> Score:
    """Parse JSON score text (errors name the file and the JSON path or line)."""
    return score_from_dict(load_json(text, path), path)


def load_json(text: str, path: str | None = None):
    """Decoded JSON `text`, every failure a one-line :class:`ScoreFormatError`.

    Guards what :func:`json.loads` lets through: text over
    :data:`~capture2notation.notation.limits.MAX_SCORE_BYTES`, nesting that
    exhausts the recursion limit, integers over Python's digit limit.
    """
    if len(text) > MAX_SCORE_BYTES:
        raise ScoreFormatError(f"{len(text)} characters exceed the limit of {MAX_SCORE_BYTES} for a score", path)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ScoreFormatError(f"invalid JSON: {exc.msg} (column {exc.colno})", path, exc.lineno) from None
    except RecursionError:
        raise ScoreFormatError("JSON nested too deeply to be a score", path) from None
    except ValueError as exc:  # e.g. an integer beyond the int-string conversion limit
        raise ScoreFormatError(f"invalid JSON: {str(exc).splitlines()[0][:120]}", path) from None


def dumps(score: Score) -> str:
    """Indented JSON text of `score` (ends with a newline)."""
    return json.dumps(score_to_dict(score), ensure_ascii=False, indent=1) + "\n"
