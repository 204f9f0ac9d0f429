"""How closely a captured score matches a reference score.

Two scores can say the same thing in different words, so both are first put
in a normal form (:func:`normalise`): a gesture symbol that moves a part to
where it already is (its default standing pose or its previous destination)
changes nothing and is dropped; an upper-arm and a forearm (thigh and shin)
symbol over the same span pointing the same way are the straight whole limb; so is a support symbol that keeps the same
feet at the same level in place, and overlapping per-foot supports
(Wolofsky's 1974 style, ``0 4 right_support`` with ``0 1 left_support``)
become the transition they describe (``0 1 right_support``).  The support parts (``support``,
``right_support``, ``left_support``) form one column, ``supports``, whose
state is (part, direction, level) — for flight (part, ``"air"``, spring
form), so a hop written as a leap disagrees.  Turns form the ``front``
column, whose state is the front a turn takes the dancer to (full turns
clockwise from the start, unwrapped): a half turn right and a half turn
left end facing the same way but not at the same front.

Comparison happens in *time*: a captured score may be written at another
tempo (an estimated tempo can be twice the written one, with every duration
doubled), and says the same thing when its symbols happen at the same
seconds.  So the candidate is first re-expressed at the reference's tempo
(:func:`at_tempo`: every beat × reference tempo / candidate tempo, exact
fractions), and every figure below is in reference beats.

* :func:`symbol_agreement` — direction + level per part per beat: at the
  centre of each reference beat, the destination written for each part
  (the last symbol that has started, else the default) must be equal.
* :func:`start_errors` — for each reference gesture symbol, the distance in
  reference beats to the nearest captured symbol of the same part with the
  same destination.
* :func:`score_differences` — exact comparison (start, duration, part,
  direction, level, bend) of the normal forms, in reference beats; empty
  when they are equal.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, replace
from fractions import Fraction

import numpy as np

from ..errors import CompareError
from ..notation.directions import canonical_vector, classify
from ..notation.facing import springs
from ..notation.model import GESTURE_PARTS, Score, Symbol

__all__ = [
    "DEFAULT_STATE",
    "Agreement",
    "Cell",
    "agreement_cells",
    "at_tempo",
    "compare_scores",
    "normalise",
    "score_differences",
    "start_errors",
    "state_at",
    "symbol_agreement",
]

#: Starting pose (DESIGN.md): limbs hang straight, head and chest upright,
#: both feet support at middle level.
DEFAULT_STATE: dict[str, tuple] = dict.fromkeys(GESTURE_PARTS, ("place", "low", 0))
DEFAULT_STATE.update({"head": ("place", "high", 0), "chest": ("place", "high", 0)})
#: The support column: standing on both feet, in place, middle level.
DEFAULT_SUPPORT = ("support", "place", "middle")


_SEGMENTS = {
    "right_arm": ("right_upper_arm", "right_forearm"),
    "left_arm": ("left_upper_arm", "left_forearm"),
    "right_leg": ("right_thigh", "right_shin"),
    "left_leg": ("left_thigh", "left_shin"),
}


def _join_straight_limbs(symbols) -> list:
    """Upper and lower segment symbols over one span, both the same way: a straight whole limb."""
    syms = list(symbols)
    index = {(s.start, s.duration, s.part): s for s in syms}
    drop, add = set(), []
    for limb, (up, low) in _SEGMENTS.items():
        for s in syms:
            if s.part != up:
                continue
            t = index.get((s.start, s.duration, low))
            if t is not None and (t.direction, t.level) == (s.direction, s.level):
                drop |= {id(s), id(t)}
                add.append(Symbol(s.start, s.duration, limb, s.direction, s.level, 0))
    return [s for s in syms if id(s) not in drop] + add


def _support_transitions(symbols) -> list:
    """Rewrite overlapping per-foot support symbols (Wolofsky's style: each
    foot's symbol lasts while it supports) as transitions: when one foot's
    symbol ends while the other's continues, the weight has moved onto the
    other foot over the ended symbol's span."""
    syms = list(symbols)
    feet = [s for s in syms if s.part in ("right_support", "left_support")]
    foot_ids = {id(s) for s in feet}
    out = [s for s in syms if id(s) not in foot_ids]
    # One foot's symbols never overlap, so the other foot's symbol that could
    # contain s is the last one starting at or before s (found by bisection).
    by_part = {
        p: sorted((t for t in feet if t.part == p), key=lambda t: t.start) for p in ("right_support", "left_support")
    }
    starts = {p: [t.start for t in ts] for p, ts in by_part.items()}
    used = set()
    for s in feet:
        if id(s) in used:
            continue
        other = "left_support" if s.part == "right_support" else "right_support"
        k = bisect.bisect_right(starts[other], s.start)
        if k == 0:
            continue
        t = by_part[other][k - 1]
        if s.end < t.end:
            # s ends first while t still supports: weight onto t's foot.
            used.add(id(s))
            if t.start < s.start:
                continue
            used.add(id(t))
            out.append(Symbol(s.start, s.duration, t.part, t.direction, t.level, 0))
    out += [s for s in feet if id(s) not in used]
    return out


def normalise(score: Score) -> Score:
    """The normal form of `score` used for comparison (see module docstring)."""
    state: dict[str, tuple | None] = dict(DEFAULT_STATE)
    out: list[Symbol] = []
    support = DEFAULT_SUPPORT
    for s in sorted(_support_transitions(_join_straight_limbs(score.symbols)), key=Symbol.sort_key):
        if s.is_turn:
            out.append(s)
            continue
        if s.is_support:
            key = (s.part, s.direction, s.level)
            if s.direction == "place" and key == support:
                continue
            support = key
            out.append(s)
            continue
        key = (s.direction, s.level, s.bend)
        if state.get(s.part) == key:
            continue
        state[s.part] = key
        # A limb's whole and segment states follow each other only when straight.
        for limb, (up, low) in _SEGMENTS.items():
            if s.part == limb:
                seg = key if s.bend == 0 else None
                state[up], state[low] = seg, seg
            elif s.part in (up, low):
                state[limb] = None
        out.append(s)
    return Score(symbols=tuple(out), title=score.title, tempo=score.tempo, meter=score.meter, axes=score.axes)


def at_tempo(score: Score, tempo) -> Score:
    """`score` written at another tempo: the same symbols at the same seconds.

    Parameters
    ----------
    score : Score
    tempo : Fraction or int
        Beats per minute (> 0) of the result.

    Returns
    -------
    Score
        Every start and duration multiplied by ``tempo / score.tempo``
        (exact fractions; off a coarse grid when the ratio is not a simple one).
    """
    tempo = Fraction(tempo)
    if tempo <= 0:
        raise CompareError(f"tempo must be > 0 beats per minute, got {tempo}")
    k = tempo / score.tempo
    if k == 1:
        return score
    syms = tuple(replace(s, start=s.start * k, duration=s.duration * k) for s in score.symbols)
    return score.replace(symbols=syms, tempo=tempo)


def state_at(score: Score, part: str, beats) -> list[tuple]:
    """Destination (direction, level) written for `part` at each beat.

    A limb and its two segments describe one body part, so their states
    follow each other: a whole-limb symbol also places both segments (each
    points the limb's way), and a segment symbol also moves the whole limb,
    whose direction is then that of shoulder → wrist (hip → ankle) with the
    two segments at their canonical vectors and the body model's lengths.

    Parameters
    ----------
    score : Score
        Normalised score.
    part : str
        A gesture part, ``"supports"`` for the support column or
        ``"front"`` for the turns.
    beats : sequence of Fraction
        Sorted sample beats.

    Returns
    -------
    list of tuple
        (direction, level) — (part, direction, level) for ``supports``, with
        the spring form as the level of flight; ``(front,)`` in full turns
        as text (``"1/2"``) for ``front`` — of the last symbol that has
        started at each beat, else the default.
    """
    cur: tuple
    if part == "front":
        turns = [s for s in score.symbols if s.is_turn]
        fronts, total = [], Fraction(0)
        for t in turns:
            total += t.signed_amount
            fronts.append(total)
        out, i = [], 0
        for b in beats:
            while i < len(turns) and turns[i].start <= b:
                i += 1
            out.append((str(fronts[i - 1] if i else Fraction(0)),))
        return out
    forms = {}
    if part == "supports":
        syms = [s for s in score.symbols if s.is_support]
        forms = {id(a): form for a, form in springs(score)}
        cur = DEFAULT_SUPPORT
    else:
        family = _FAMILY.get(part, (part,))
        syms = [s for s in score.symbols if s.part in family]
        cur = DEFAULT_STATE[part][:2]
        segs = {p: DEFAULT_STATE[p][:2] for p in family[1:]}
    out, i = [], 0
    for b in beats:
        while i < len(syms) and syms[i].start <= b:
            s = syms[i]
            i += 1
            if part == "supports":
                cur = (s.part, s.direction, (forms[id(s)] or "unlanded") if s.is_air else s.level)
            elif s.part == family[0]:
                cur = (s.direction, s.level)
                segs = dict.fromkeys(segs, cur)
            else:
                segs[s.part] = (s.direction, s.level)
                cur = segs[part] if part in segs else _limb_state(part, segs)
        out.append(cur)
    return out


def _limb_state(limb: str, segs: dict) -> tuple[str, str]:
    """(direction, level) of a whole limb whose segments point as `segs` says."""
    up, low = _SEGMENTS[limb]
    v = sum(_LENGTHS[limb][k] * canonical_vector(*segs[p]) for k, p in enumerate((up, low)))
    return classify(v)


def _family() -> dict[str, tuple[str, ...]]:
    """Parts whose symbols set each part's state: the part first, then the rest of its limb."""
    fam: dict[str, tuple[str, ...]] = {}
    for limb, (up, low) in _SEGMENTS.items():
        fam[limb] = (limb, up, low)
        fam[up] = (limb, up)
        fam[low] = (limb, low)
    return fam


def _limb_lengths() -> dict[str, tuple[float, float]]:
    from ..body import Body, joint_index

    lengths = np.linalg.norm(Body().offsets, axis=1)
    ends = {"arm": ("elbow", "wrist"), "leg": ("knee", "ankle")}
    return {
        f"{side}_{limb}": (
            float(lengths[joint_index(f"{side}_{ends[limb][0]}")]),
            float(lengths[joint_index(f"{side}_{ends[limb][1]}")]),
        )
        for side in ("right", "left")
        for limb in ends
    }


_FAMILY = _family()
_LENGTHS = _limb_lengths()


def _parts(ref: Score, cand: Score) -> list[str]:
    """Columns compared: every part either score moves, a limb's segments
    only where the reference writes them (a captured segment symbol is
    judged by where it takes its whole limb, not counted twice)."""
    written = {s.part for s in ref.symbols}
    columns = set()
    for part in written | {s.part for s in cand.symbols}:
        limb = _FAMILY.get(part, (part,))[0]
        columns.add(limb)
        if part in written:
            columns.add(part)
    parts = [p for p in DEFAULT_STATE if p in columns]
    if any(s.is_support for s in ref.symbols + cand.symbols):
        parts.append("supports")
    if any(s.is_turn for s in ref.symbols + cand.symbols):
        parts.append("front")
    return parts


@dataclass(frozen=True)
class Cell:
    """One (part, beat) cell of :func:`agreement_cells`.

    Attributes
    ----------
    part : str
        Column: a gesture part, ``"supports"`` or ``"front"``.
    beat : Fraction
        Sample time (the cell's centre), reference beats.
    ref, cand : tuple
        State written there by each score (see :func:`state_at`).
    """

    part: str
    beat: Fraction
    ref: tuple
    cand: tuple


def agreement_cells(ref: Score, cand: Score, step: Fraction = Fraction(1)) -> list[Cell]:
    """Every cell :func:`symbol_agreement` compares, with both scores' states.

    Parameters
    ----------
    ref, cand : Score
        As for :func:`symbol_agreement`.
    step : Fraction
        Sampling step in reference beats.

    Returns
    -------
    list of Cell
        Column by column, in time order; the cells where ``ref != cand``
        are what the agreement misses.
    """
    ref, cand = normalise(ref), normalise(at_tempo(cand, ref.tempo))
    end = max(ref.duration, cand.duration)
    n = math.ceil(end / step) if end > 0 else 0
    # Cell centres: a symbol starting a frame late (or a tempo a bpm off)
    # does not lose its whole cell; start errors are reported on their own.
    beats = [(k + Fraction(1, 2)) * step for k in range(n)]
    return [
        Cell(p, b, x, y)
        for p in _parts(ref, cand)
        for b, x, y in zip(beats, state_at(ref, p, beats), state_at(cand, p, beats))
    ]


def symbol_agreement(ref: Score, cand: Score, step: Fraction = Fraction(1)) -> float:
    """Fraction of (part, beat) cells where both scores write the same direction and level.

    The columns are the parts either score moves (a limb's segments only
    when the reference writes them: a captured forearm symbol counts through
    its whole arm, :func:`state_at`).  Each cell is sampled at its centre,
    so timing errors under half a step cost nothing here (see
    :func:`start_errors` for them).

    Parameters
    ----------
    ref, cand : Score
        Any scores (normalised here); `cand` is compared at the same seconds
        (:func:`at_tempo`), sampled on the reference's beats.
    step : Fraction
        Sampling step in reference beats (1 = per beat).

    Returns
    -------
    float
        In [0, 1]; 1.0 when neither score writes anything.
    """
    cells = agreement_cells(ref, cand, step)
    if not cells:
        return 1.0
    return sum(c.ref == c.cand for c in cells) / len(cells)


def start_errors(ref: Score, cand: Score) -> tuple[np.ndarray, int]:
    """Start-time errors of reference gesture and turn symbols, reference beats.

    Returns
    -------
    errors : (M,) ndarray
        |start difference| (reference beats, the candidate taken at the same
        seconds) to the nearest captured symbol of the same part with the
        same destination, for each matched reference symbol.
    unmatched : int
        Reference gesture symbols with no such captured symbol.
    """
    ref, cand = normalise(ref), normalise(at_tempo(cand, ref.tempo))
    index: dict[tuple, list] = {}
    for c in cand.symbols:
        index.setdefault(_what(c), []).append(c.start)
    for starts in index.values():
        starts.sort()
    errs, missing = [], 0
    for s in ref.symbols:
        if s.is_support:
            continue
        starts = index.get(_what(s), [])
        if not starts:
            missing += 1
            continue
        k = bisect.bisect_left(starts, s.start)
        errs.append(float(min(abs(starts[j] - s.start) for j in (k - 1, k) if 0 <= j < len(starts))))
    return np.asarray(errs, dtype=float), missing


@dataclass(frozen=True)
class Agreement:
    """Summary of :func:`compare_scores`.

    Attributes
    ----------
    symbol_agreement : float
        Direction + level per part per reference beat, in [0, 1].
    median_start_error : float
        Reference beats (NaN when nothing matched).
    matched, unmatched : int
        Reference gesture symbols with / without a captured counterpart.
    exact : bool
        The normal forms are identical at the same seconds (the tempi may
        differ: see `tempo_ratio`).
    tempo_ratio : Fraction
        Candidate tempo / reference tempo (1 when written at the same tempo).
    """

    symbol_agreement: float
    median_start_error: float
    matched: int
    unmatched: int
    exact: bool
    tempo_ratio: Fraction = Fraction(1)


def compare_scores(ref: Score, cand: Score, step: Fraction = Fraction(1)) -> Agreement:
    """All agreement figures of `cand` against `ref`, in time (reference beats).

    Parameters
    ----------
    ref, cand : Score
        Reference and candidate; their tempi may differ.
    step : Fraction
        Sampling step of the agreement, reference beats.

    Returns
    -------
    Agreement
    """
    if not isinstance(ref, Score) or not isinstance(cand, Score):
        raise CompareError(
            f"compare_scores needs two Score objects, got {type(ref).__name__} and {type(cand).__name__}"
        )
    errs, missing = start_errors(ref, cand)
    return Agreement(
        symbol_agreement=symbol_agreement(ref, cand, step),
        median_start_error=float(np.median(errs)) if errs.size else float("nan"),
        matched=int(errs.size),
        unmatched=int(missing),
        exact=not score_differences(ref, cand),
        tempo_ratio=cand.tempo / ref.tempo,
    )


def _what(s: Symbol) -> tuple:
    """What a symbol writes, without its time: (part, direction, level, amount)."""
    return (s.part, s.direction, s.level, s.amount)


def _key(s: Symbol) -> tuple:
    return (s.start, s.duration, s.part, s.direction, s.level, s.bend, s.amount)


def score_differences(ref: Score, cand: Score, supports: bool = True) -> list[str]:
    """Symbols in one normal form and not the other, as readable lines.

    Parameters
    ----------
    ref, cand : Score
        `cand` is compared at the same seconds (:func:`at_tempo`): a score
        and the same score at another tempo with every time scaled have no
        differences.
    supports : bool
        Include support symbols in the comparison.

    Returns
    -------
    list of str
        ``"missing: …"`` (in `ref` only) and ``"extra: …"`` (in `cand`
        only), times in reference beats.
    """
    a = {_key(s) for s in normalise(ref).symbols if supports or not s.is_support}
    b = {_key(s) for s in normalise(at_tempo(cand, ref.tempo)).symbols if supports or not s.is_support}

    def fmt(k):
        start, dur, part, d, lv, bend, amount = k
        return (
            f"{start} {dur} {part} {d} {lv or ''}".rstrip()
            + (f" bend={bend}" if bend else "")
            + (f" amount={amount}" if amount is not None else "")
        )

    return [f"missing: {fmt(k)}" for k in sorted(a - b, key=str)] + [f"extra: {fmt(k)}" for k in sorted(b - a, key=str)]
