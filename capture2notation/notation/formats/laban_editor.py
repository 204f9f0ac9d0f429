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
the start times).  ``rotation`` is always ``["ToLeft", "0"]``: we do not
notate turns.  Legs, chest and supports have no column in this format.

A whole-arm symbol with bend k is split into upper arm and forearm with a
simple, documented convention: both segments taken of equal length, the
elbow bends by β = 30°·k in the plane spanned by the arm's direction v and
the body's forward axis (or, when the arm points forward or back, the axis
towards the body's midline), the upper arm turning β/2 away from that axis
and the forearm β/2 towards it, so that shoulder → wrist stays along v.  Each
segment is then classified with the shared thresholds
(:func:`~capture2notation.notation.directions.classify`).  With bend 0 both
segments take the arm's direction and level.

Reading
-------
Positions become symbols of ``right_upper_arm``, ``right_forearm``,
``left_upper_arm``, ``left_forearm`` and ``head``: a part whose state
differs from the previous position moves from that position's time to this
one.  Times become beats at tempo 60 (1 beat = 1000 ms) and the title is the
score's name.
"""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ...errors import NotationError, ScoreFormatError
from ..directions import BEND_STEP_DEG, canonical_vector, classify
from ..model import Score, Symbol

__all__ = [
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
_ROTATION = ["ToLeft", "0"]
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
    times = sorted({Fraction(0)} | {s.end for s in relevant})
    # Apply symbols in order of arrival; a later symbol on a segment wins.
    events = sorted(relevant, key=lambda s: (s.end, s.start))
    state = dict(_START)
    positions: dict = {}
    k = 0
    prev_ms = 0
    for t in times:
        while k < len(events) and events[k].end <= t:
            s = events[k]
            if s.part in ("right_arm", "left_arm"):
                side = s.part.split("_")[0]
                upper, fore = arm_segments(s.part, s.direction, s.level, s.bend)
                state[f"{side}_upper_arm"], state[f"{side}_forearm"] = upper, fore
            else:
                state[s.part] = (s.direction, s.level)
            k += 1
        ms = _ms(t, score.tempo)
        pose = {"start time": [str(ms)], "duration": [str(ms - prev_ms)]}
        for field, part, _, _ in _FIELDS:
            d, lv = state[part]
            pose[field] = [DIRECTION_NAMES[d], LEVEL_NAMES[lv]]
        pose["rotation"] = list(_ROTATION)
        positions[f"Position{len(positions)}"] = pose
        prev_ms = ms
    return {name or score.title or "score": positions}


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
        raise ScoreFormatError(f"{where}: expected [Direction, Level] strings, got {json.dumps(value)}", path)
    d, lv = value
    if d not in _DIRECTION_BACK:
        raise ScoreFormatError(f"{where}: unknown direction {d!r}; expected one of {', '.join(_DIRECTION_BACK)}", path)
    if lv not in _LEVEL_BACK:
        raise ScoreFormatError(f"{where}: unknown level {lv!r}; expected one of {', '.join(_LEVEL_BACK)}", path)
    return _DIRECTION_BACK[d], _LEVEL_BACK[lv]


def _time_ms(value, where: str, path) -> int:
    raw = value[0] if isinstance(value, list) and len(value) == 1 else value
    try:
        return int(str(raw))
    except ValueError:
        raise ScoreFormatError(
            f"{where}: expected [milliseconds] as a whole number, got {json.dumps(value)}", path
        ) from None


def loads(text: str, path: str | None = None) -> Score:
    """Parse LabanEditor JSON into a score of arm-segment and head symbols.

    Raises
    ------
    ScoreFormatError
        Naming the JSON path (``NAME.Position3.right elbow``) and what was
        expected.
    """
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ScoreFormatError(f"invalid JSON: {exc.msg} (column {exc.colno})", path, exc.lineno) from None
    if not isinstance(data, dict) or len(data) != 1 or not isinstance(next(iter(data.values())), dict):
        raise ScoreFormatError('expected one score: {name: {"Position0": {...}, ...}}', path)
    name, positions = next(iter(data.items()))
    poses = []
    for key, pose in positions.items():
        where = f"{name}.{key}"
        if not isinstance(pose, dict):
            raise ScoreFormatError(f"{where}: expected an object", path)
        if "start time" not in pose:
            raise ScoreFormatError(f"{where}.start time: missing", path)
        ms = _time_ms(pose["start time"], f"{where}.start time", path)
        state = {}
        for field, part, _, _ in _FIELDS:
            if field in pose:
                state[part] = _pair(pose[field], f"{where}.{field}", path)
        poses.append((ms, where, state))
    poses.sort(key=lambda p: p[0])
    symbols = []
    prev_ms, current = 0, dict(_START)
    for ms, where, state in poses:
        for part, target in state.items():
            if target == current[part]:
                continue
            if ms <= prev_ms:
                raise ScoreFormatError(
                    f"{where}: {part} changes at {ms} ms with no time to move since {prev_ms} ms", path
                )
            try:
                symbols.append(Symbol(Fraction(prev_ms, 1000), Fraction(ms - prev_ms, 1000), part, *target))
            except NotationError as exc:
                raise ScoreFormatError(f"{where}: {exc}", path) from None
            current[part] = target
        prev_ms = ms
    try:
        return Score(symbols=tuple(symbols), title=str(name).replace("\n", " "), tempo=Fraction(60), meter=4)
    except NotationError as exc:
        raise ScoreFormatError(str(exc), path) from None
