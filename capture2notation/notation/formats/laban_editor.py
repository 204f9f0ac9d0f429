"""LabanotationSuite's LabanEditor score (``laban_editor.json``).

The format of Microsoft's LabanotationSuite (``GestureAuthoringTools/
LabanEditor``): one named score of key poses ("positions")::

    {"NAME": {"Position0": {"start time": ["0"], "duration": ["0"],
                            "head": ["Place", "High"],
                            "right elbow": ["Place", "Low"], "right wrist": ["Place", "Low"],
                            "left elbow": ["Place", "Low"], "left wrist": ["Place", "Low"],
                            "rotation": ["ToLeft", "0"]},
              "Position1": {...}}}

"elbow" is the direction of the upper arm (shoulder → elbow) and "wrist" that
of the forearm (elbow → wrist); directions are ``Forward``, ``Right
Forward``, ``Right``, ``Right Backward``, ``Backward``, ``Left Backward``,
``Left``, ``Left Forward``, ``Place``; levels ``High``, ``Normal``, ``Low``.
All values are strings, as the suite writes them; times are milliseconds.

Writing
-------
Position 0 is the state at time 0 (the starting pose of DESIGN.md unless a
symbol says otherwise); then one position per distinct time at which an arm
or head symbol arrives, holding every part's state at that time.
``duration`` is the time in ms since the previous position (the suite's own
exporter writes placeholders ``"1"``/``"-1"`` there and its viewer uses only
the start times).  Legs, chest and supports have no column in this format.

``rotation`` is ``[ToRight|ToLeft, degrees]``: the front at that position,
in degrees from the starting front, clockwise for ``ToRight``.  That is how
the suite's own gesture library uses the field (``MSRAbotChatSimulation/
data/LabanotationLibrary``: "beat rotate" writes 0, 30, −30, 0 and "deictic
me rotate l" 10, 60, 60, 0 — a front held and returned to, not increments;
negative ``ToRight`` values are fronts to the left); its exporter always
writes ``["ToLeft", "0"]``, which we write for front 0 as well.  Positions
are added at the start and end of every turn, so each turn's span survives.

A whole-arm symbol with bend k is split into upper arm and forearm with a
simple, documented convention: both segments taken of equal length, the
elbow bends by β = 30°·k in the plane spanned by the arm's direction v and
the body's forward axis (or, when the arm points forward or back, the axis
towards the body's midline), the upper arm turning β/2 away from that axis
and the forearm β/2 towards it, so that shoulder → wrist stays along v.  Each
segment is then classified with the shared thresholds
(:func:`~capture2notation.notation.directions.classify`).  With bend 0 both
segments take the arm's direction and level.

A captured symbol's confidence is written in the position where it
arrives, ``"confidence": {"right elbow": "0.412", ...}`` (a whole arm's on
both of its fields); files without it read as not assessed.

Reading
-------
Positions become symbols of ``right_upper_arm``, ``right_forearm``,
``left_upper_arm``, ``left_forearm`` and ``head``: a part whose state
differs from the previous position moves from that position's time to this
one.  A change of ``rotation`` between positions becomes a turn over the
same span, the fronts rounded to the nearest eighth of a turn (the suite
writes 30° or 60°; our turns are eighths), measured from the first
position's rotation.  Times become beats at tempo 60 (1 beat = 1000 ms) and
the title is the score's name.  Range guards: the text at most 16 MiB,
numbers at most 40 characters, at most 50,000 positions.
"""

from __future__ import annotations

import json
import math
import re
from fractions import Fraction
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ...errors import NotationError, ScoreFormatError
from ..directions import BEND_STEP_DEG, canonical_vector, classify
from ..facing import front_lookup
from ..limits import MAX_NUMBER_CHARS, MAX_SYMBOLS
from ..model import TURN_PART, TURN_STEP, Score, Symbol
from .json_format import load_json

__all__ = [
    "CONFIDENCE_KEY",
    "DIRECTION_NAMES",
    "LEVEL_NAMES",
    "arm_segments",
    "dumps",
    "loads",
    "score_to_laban_editor",
    "write_laban_editor",
]

DIRECTION_NAMES: MappingProxyType = MappingProxyType(
    {
        "forward": "Forward",
        "right_forward": "Right Forward",
        "right": "Right",
        "right_back": "Right Backward",
        "back": "Backward",
        "left_back": "Left Backward",
        "left": "Left",
        "left_forward": "Left Forward",
        "place": "Place",
    }
)
LEVEL_NAMES: MappingProxyType = MappingProxyType({"high": "High", "middle": "Normal", "low": "Low"})
_DIRECTION_BACK = {v: k for k, v in DIRECTION_NAMES.items()}
_LEVEL_BACK = {v: k for k, v in LEVEL_NAMES.items()}

#: Suite field → (our segment part, whole-limb part, segment role).
#: A position's optional object of the confidence (``"0.812"``) of each
#: field whose symbol arrives there; the suite ignores keys it does not know.
CONFIDENCE_KEY = "confidence"
_FIELDS = (
    ("head", "head", None, None),
    ("right elbow", "right_upper_arm", "right_arm", 0),
    ("right wrist", "right_forearm", "right_arm", 1),
    ("left elbow", "left_upper_arm", "left_arm", 0),
    ("left wrist", "left_forearm", "left_arm", 1),
)
#: Starting pose of DESIGN.md for the parts this format carries.
_START = {
    "head": ("place", "high"),
    "right_upper_arm": ("place", "low"),
    "right_forearm": ("place", "low"),
    "left_upper_arm": ("place", "low"),
    "left_forearm": ("place", "low"),
}
_ROTATION_WORDS = {"ToRight": 1, "ToLeft": -1}
_ANY_ARM_OR_HEAD = frozenset(
    {"head", "right_arm", "left_arm", "right_upper_arm", "right_forearm", "left_upper_arm", "left_forearm"}
)


def arm_segments(part: str, direction: str, level: str, bend: int) -> tuple[tuple[str, str], tuple[str, str]]:
    """Upper-arm and forearm (direction, level) of a whole-arm symbol.

    Parameters
    ----------
    part : {'right_arm', 'left_arm'}
    direction, level : str
        The arm's (shoulder → wrist) direction and level.
    bend : int
        Bend degree 0–6 (β = 30° per degree).

    Returns
    -------
    upper, fore : tuple of (direction, level)
        See the module docstring for the bending convention.
    """
    if bend == 0:
        return (direction, level), (direction, level)
    v = canonical_vector(direction, level)
    forward = np.array([0.0, 1.0, 0.0])
    n = forward - np.dot(forward, v) * v
    if np.linalg.norm(n) < 0.5:
        # Arm along the forward/back axis: the elbow bends towards the midline.
        inward = np.array([-1.0 if part == "right_arm" else 1.0, 0.0, 0.0])
        n = inward - np.dot(inward, v) * v
    n = n / np.linalg.norm(n)
    half = np.radians(bend * BEND_STEP_DEG) / 2.0
    upper = np.cos(half) * v - np.sin(half) * n
    fore = np.cos(half) * v + np.sin(half) * n
    return classify(upper), classify(fore)


def _ms(beats: Fraction, tempo: Fraction) -> int:
    return int(round(beats * 60000 / tempo))


def score_to_laban_editor(score: Score, name: str | None = None) -> dict:
    """The LabanEditor dict of `score` (see the module docstring).

    Parameters
    ----------
    score : Score
    name : str, optional
        Key of the score; default the title, or ``"score"`` if it is empty.
    """
    relevant = [s for s in score.symbols if s.part in _ANY_ARM_OR_HEAD]
    turns = [s for s in score.symbols if s.is_turn]
    times = sorted({Fraction(0)} | {s.end for s in relevant} | {t for s in turns for t in (s.start, s.end)})
    # Apply symbols in order of arrival; a later symbol on a segment wins.
    events = sorted(relevant, key=lambda s: (s.end, s.start))
    state = dict(_START)
    front_at = front_lookup(score)
    positions: dict = {}
    k = 0
    prev_ms = 0
    for t in times:
        arrived: dict[str, float] = {}  # segment -> confidence of the symbol arriving here
        while k < len(events) and events[k].end <= t:
            s = events[k]
            if s.part in ("right_arm", "left_arm"):
                side = s.part.split("_")[0]
                upper, fore = arm_segments(s.part, s.direction, s.level, s.bend)
                state[f"{side}_upper_arm"], state[f"{side}_forearm"] = upper, fore
                segments = [f"{side}_upper_arm", f"{side}_forearm"]
            else:
                state[s.part] = (s.direction, s.level)
                segments = [s.part]
            for seg in segments:
                arrived.pop(seg, None)
                if s.confidence is not None:
                    arrived[seg] = s.confidence
            k += 1
        ms = _ms(t, score.tempo)
        pose: dict[str, object] = {"start time": [str(ms)], "duration": [str(ms - prev_ms)]}
        for field, part, _, _ in _FIELDS:
            d, lv = state[part]
            pose[field] = [DIRECTION_NAMES[d], LEVEL_NAMES[lv]]
        pose["rotation"] = _rotation(front_at(t))
        conf = {field: f"{arrived[part]:.3f}" for field, part, _, _ in _FIELDS if part in arrived}
        if conf:
            pose[CONFIDENCE_KEY] = conf
        positions[f"Position{len(positions)}"] = pose
        prev_ms = ms
    return {name or score.title or "score": positions}


def _rotation(front: Fraction) -> list[str]:
    """``[ToRight|ToLeft, degrees]`` of a front in full turns clockwise."""
    deg = abs(front) * 360
    text = str(deg.numerator) if deg.denominator == 1 else repr(float(deg))
    return ["ToRight" if front > 0 else "ToLeft", text]


def dumps(score: Score, name: str | None = None) -> str:
    """LabanEditor JSON text of `score`."""
    return json.dumps(score_to_laban_editor(score, name), ensure_ascii=False, indent=2) + "\n"


def write_laban_editor(score: Score, path, name: str | None = None) -> Path:
    """Write `score` atomically as a LabanEditor JSON file; return the path.

    Parameters
    ----------
    score : Score
    path : str or Path
        Usually ``OUTDIR/laban_editor.json``.
    name : str, optional
        Score name inside the file; default the title, else the file stem
        (the suite names a score after its file).
    """
    from ...atomic import write_text

    return write_text(path, dumps(score, name or score.title or Path(path).stem))


def _pair(value, where: str, path) -> tuple[str, str]:
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(x, str) for x in value)):
        raise ScoreFormatError(f"{where}: expected [Direction, Level] strings, got {_show(value)}", path)
    d, lv = value
    if d not in _DIRECTION_BACK:
        raise ScoreFormatError(f"{where}: unknown direction {d!r}; expected one of {', '.join(_DIRECTION_BACK)}", path)
    if lv not in _LEVEL_BACK:
        raise ScoreFormatError(f"{where}: unknown level {lv!r}; expected one of {', '.join(_LEVEL_BACK)}", path)
    return _DIRECTION_BACK[d], _LEVEL_BACK[lv]


def _time_ms(value, where: str, path) -> int:
    raw = value[0] if isinstance(value, list) and len(value) == 1 else value
    bad = ScoreFormatError(f"{where}: expected [milliseconds] as a whole number, got {_show(value)}", path)
    if isinstance(raw, bool) or not isinstance(raw, (str, int)):
        raise bad
    text = str(raw).strip() if isinstance(raw, str) else None
    if text is not None and (len(text) > MAX_NUMBER_CHARS or not re.fullmatch(r"[+-]?[0-9]+", text)):
        raise bad
    return int(raw)


def _front_eighths(value, where: str, path) -> int:
    """Front of a ``rotation`` field in eighths of a turn clockwise (nearest)."""
    bad = f"{where}: expected [ToRight|ToLeft, degrees], got {_show(value)}"
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(x, str) for x in value)):
        raise ScoreFormatError(bad, path)
    word, deg_text = value
    if word not in _ROTATION_WORDS or len(deg_text) > MAX_NUMBER_CHARS:
        raise ScoreFormatError(bad, path)
    try:
        deg = float(deg_text)
    except ValueError:
        raise ScoreFormatError(bad, path) from None
    if not math.isfinite(deg):
        raise ScoreFormatError(bad, path)
    return round(_ROTATION_WORDS[word] * deg / float(360 * TURN_STEP))


def _confidences(value, where: str, path) -> dict[str, float]:
    """Segment → confidence from a position's ``confidence`` object (see the module docstring)."""
    by_field = {field: part for field, part, _, _ in _FIELDS}
    if not isinstance(value, dict):
        raise ScoreFormatError(f'{where}: expected {{field: "0.xyz"}}, got {_show(value)}', path)
    out = {}
    for field, text in value.items():
        if field not in by_field:
            raise ScoreFormatError(
                f"{where}: unknown field {_show(field)}; expected one of {', '.join(by_field)}", path
            )
        ok = isinstance(text, str) and len(text) <= MAX_NUMBER_CHARS and re.fullmatch(r"[0-9]*\.?[0-9]+", text)
        c = float(text) if ok else math.nan
        if not 0.0 <= c <= 1.0:
            raise ScoreFormatError(f"{where}.{field}: expected a number in [0, 1] as a string, got {_show(text)}", path)
        out[by_field[field]] = c
    return out


def _show(value) -> str:
    try:
        text = json.dumps(value, ensure_ascii=False)
    except (TypeError, ValueError, RecursionError):
        text = type(value).__name__
    return text if len(text) <= 60 else text[:57] + "..."


def loads(text: str, path: str | None = None) -> Score:
    """Parse LabanEditor JSON into a score of arm-segment and head symbols.

    Raises
    ------
    ScoreFormatError
        Naming the JSON path (``NAME.Position3.right elbow``) and what was
        expected.
    """
    data = load_json(text, path)
    if not isinstance(data, dict) or len(data) != 1 or not isinstance(next(iter(data.values())), dict):
        raise ScoreFormatError('expected one score: {name: {"Position0": {...}, ...}}', path)
    name, positions = next(iter(data.items()))
    if len(positions) > MAX_SYMBOLS:
        raise ScoreFormatError(f"{len(positions)} positions exceed the limit of {MAX_SYMBOLS} in one score", path)
    label = json.dumps(name, ensure_ascii=False)[1:-1][:60]  # one line, whatever the name holds
    poses = []
    for key, pose in positions.items():
        where = f"{label}.{json.dumps(key, ensure_ascii=False)[1:-1][:60]}"
        if not isinstance(pose, dict):
            raise ScoreFormatError(f"{where}: expected an object", path)
        if "start time" not in pose:
            raise ScoreFormatError(f"{where}.start time: missing", path)
        ms = _time_ms(pose["start time"], f"{where}.start time", path)
        state = {}
        for field, part, _, _ in _FIELDS:
            if field in pose:
                state[part] = _pair(pose[field], f"{where}.{field}", path)
        front = _front_eighths(pose["rotation"], f"{where}.rotation", path) if "rotation" in pose else None
        conf = _confidences(pose[CONFIDENCE_KEY], f"{where}.{CONFIDENCE_KEY}", path) if CONFIDENCE_KEY in pose else {}
        poses.append((ms, where, state, front, conf))
    poses.sort(key=lambda p: p[0])
    symbols = []
    prev_ms, current = 0, dict(_START)
    front0 = next((p[3] for p in poses if p[3] is not None), 0)
    current_front = front0
    for ms, where, state, front, conf in poses:
        changes: list[tuple[str, tuple[str, str] | int]] = [
            (part, target) for part, target in state.items() if target != current[part]
        ]
        if front is not None and front != current_front:
            changes.append((TURN_PART, front))
        for part, target in changes:
            if ms <= prev_ms:
                raise ScoreFormatError(
                    f"{where}: {part} changes at {ms} ms with no time to move since {prev_ms} ms", path
                )
            start, dur = Fraction(prev_ms, 1000), Fraction(ms - prev_ms, 1000)
            try:
                if isinstance(target, int):
                    delta = (target - current_front) * TURN_STEP
                    direction = "right" if delta > 0 else "left"
                    symbols.append(Symbol(start, dur, TURN_PART, direction, None, amount=abs(delta)))
                    current_front = target
                else:
                    symbols.append(Symbol(start, dur, part, *target, confidence=conf.get(part)))
                    current[part] = target
            except NotationError as exc:
                raise ScoreFormatError(f"{where}: {exc}", path) from None
        prev_ms = ms
    try:
        return Score(symbols=tuple(symbols), title=str(name).replace("\n", " "), tempo=Fraction(60), meter=4)
    except NotationError as exc:
        raise ScoreFormatError(str(exc), path) from None
