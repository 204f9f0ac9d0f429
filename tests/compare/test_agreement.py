"""The score agreement metric: normal form, per-beat agreement, start errors."""

from __future__ import annotations

from fractions import Fraction as F

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.compare.agreement import (
    agreement_cells,
    at_tempo,
    compare_scores,
    normalise,
    score_differences,
    start_errors,
    state_at,
    symbol_agreement,
)
from capture2notation.errors import CompareError
from capture2notation.notation.model import Score, Symbol

REF = Score(
    symbols=(
        Symbol(0, 4, "support", "place", "middle"),
        Symbol(0, 1, "right_arm", "place", "low"),  # no-op: already hanging
        Symbol(1, 1, "right_arm", "forward", "middle"),
        Symbol(2, 2, "right_arm", "right", "high", bend=1),
        Symbol(1, 2, "head", "forward", "high"),
    ),
    tempo=60,
)


def test_normal_form_drops_no_ops():
    n = normalise(REF)
    parts = [s.part for s in n.symbols]
    assert parts.count("right_arm") == 2
    assert "support" not in parts  # standing on both feet is the starting pose
    assert normalise(n) == n
    steps = Score(
        symbols=(
            Symbol(0, 1, "right_support", "place", "middle"),
            Symbol(1, 1, "right_support", "place", "middle"),  # no change
            Symbol(2, 1, "right_support", "forward", "middle"),  # a step is never a no-op
            Symbol(3, 1, "support", "place", "low"),
        ),
        tempo=60,
    )
    assert [(s.start, s.part) for s in normalise(steps).symbols] == [
        (0, "right_support"),
        (2, "right_support"),
        (3, "support"),
    ]


def test_identical_scores_agree_fully():
    a = compare_scores(REF, REF)
    assert a.symbol_agreement == 1.0 and a.exact and a.unmatched == 0 and a.median_start_error == 0.0


def test_agreement_cells_name_what_the_agreement_misses():
    cand = Score(
        symbols=(
            Symbol(1, 1, "right_arm", "forward", "middle"),
            Symbol(2, 2, "right_arm", "right", "middle", bend=1),
            Symbol(1, 2, "head", "forward", "high"),
        ),
        tempo=60,
    )
    cells = agreement_cells(REF, cand)
    wrong = [(c.part, c.beat, c.ref, c.cand) for c in cells if c.ref != c.cand]
    assert wrong == [
        ("right_arm", F(5, 2), ("right", "high"), ("right", "middle")),
        ("right_arm", F(7, 2), ("right", "high"), ("right", "middle")),
    ]
    assert symbol_agreement(REF, cand) == pytest.approx(1 - len(wrong) / len(cells))


def test_limb_and_segment_states_follow_each_other():
    # A bent knee at beat 1, then the straight whole leg at beat 2: from beat 2
    # the shin points the leg's way again, and the leg's own state at beat 1
    # is the direction of hip → ankle with the shin bent back.
    score = normalise(
        Score(
            symbols=(
                Symbol(0, 1, "right_leg", "right", "low"),
                Symbol(1, 1, "right_shin", "back", "low"),
                Symbol(2, 1, "right_leg", "forward", "low"),
            ),
            tempo=60,
        )
    )
    beats = [F(1, 2), F(3, 2), F(5, 2)]
    assert state_at(score, "right_shin", beats) == [("right", "low"), ("back", "low"), ("forward", "low")]
    assert state_at(score, "right_thigh", beats) == [("right", "low")] * 2 + [("forward", "low")]
    assert state_at(score, "right_leg", beats) == [("right", "low"), ("right_back", "low"), ("forward", "low")]
    # The same movement written as segments or as the whole straight limb agrees.
    split = Score(
        symbols=(
            Symbol(0, 1, "right_thigh", "right", "low"),
            Symbol(0, 1, "right_shin", "right", "low"),
            Symbol(1, 1, "right_upper_arm", "forward", "middle"),
            Symbol(1, 1, "right_forearm", "forward", "middle"),
        ),
        tempo=60,
    )
    whole = Score(
        symbols=(Symbol(0, 1, "right_leg", "right", "low"), Symbol(1, 1, "right_arm", "forward", "middle")), tempo=60
    )
    assert symbol_agreement(whole, split) == 1.0
    # A stray forearm symbol is one wrong arm cell per beat, not an arm and a forearm column.
    ref = whole.replace(symbols=whole.symbols + (Symbol(2, 1, "right_leg", "place", "low"),))
    stray = ref.replace(symbols=ref.symbols + (Symbol(2, 1, "right_forearm", "place", "high"),))
    # Columns right_arm, right_leg over beats 0..2: the forearm raised to
    # the vertical takes the arm forward high at beat 2 instead of forward middle.
    assert symbol_agreement(ref, stray) == pytest.approx(5 / 6)


def test_shifted_symbol_costs_one_beat_cell_and_its_start_error():
    cand = Score(
        symbols=(
            Symbol(1, 1, "right_arm", "forward", "middle"),
            Symbol(3, 1, "right_arm", "right", "high", bend=1),  # one beat late
            Symbol(1, 2, "head", "forward", "high"),
            Symbol(1, 2, "support", "place", "low"),
        ),
        tempo=60,
    )
    # Columns: right_arm, head, supports over beats 0..3 → 12 cells; the late
    # arm differs at beat 2 and the plié (absent from REF) at beats 1, 2, 3.
    assert symbol_agreement(REF, cand) == pytest.approx(8 / 12)
    errs, missing = start_errors(REF, cand)
    assert sorted(errs.tolist()) == [0.0, 0.0, 1.0] and missing == 0
    diffs = score_differences(REF, cand)
    assert "missing: 2 2 right_arm right high bend=1" in diffs
    assert "extra: 3 1 right_arm right high bend=1" in diffs


def test_wrong_level_is_unmatched():
    cand = Score(symbols=(Symbol(1, 1, "right_arm", "forward", "low"),), tempo=60)
    errs, missing = start_errors(REF, cand)
    assert missing == 3 and errs.size == 0
    assert np.isnan(compare_scores(REF, cand).median_start_error)


def test_compare_needs_scores():
    with pytest.raises(CompareError, match="Score"):
        compare_scores(REF, "score.lab")


def test_same_score_at_another_tempo_agrees_fully():
    # Twice the tempo with every time doubled: the same movements at the same seconds.
    fast = at_tempo(REF, 2 * REF.tempo)
    assert fast.tempo == 120 and [s.start for s in fast.symbols] == [0, 0, 2, 2, 4]
    a = compare_scores(REF, fast)
    assert a.symbol_agreement == 1.0 and a.exact and a.median_start_error == 0.0 and a.unmatched == 0
    assert a.tempo_ratio == 2
    assert score_differences(REF, fast) == [] and score_differences(fast, REF) == []
    # The same beats at another tempo are other seconds: a real difference.
    same_beats = REF.replace(tempo=2 * REF.tempo)
    b = compare_scores(REF, same_beats)
    assert not b.exact and b.symbol_agreement < 1.0
    # Start errors are in reference beats: the arm's second symbol (beat 2) sits at beat 1.
    errs, missing = start_errors(REF, same_beats)
    assert missing == 0 and sorted(errs.tolist()) == pytest.approx([0.5, 0.5, 1.0])


_PARTS = ("right_arm", "left_arm", "head")
_DIRS = ("forward", "right", "left", "back", "place")


@st.composite
def _scores(draw):
    syms = []
    for part in _PARTS:
        t = F(0)
        for _ in range(draw(st.integers(0, 4))):
            t += F(draw(st.integers(0, 4)), 4)
            dur = F(draw(st.integers(1, 8)), 4)
            d = draw(st.sampled_from(_DIRS))
            lv = draw(st.sampled_from(("high", "low") if d == "place" else ("high", "middle", "low")))
            syms.append(Symbol(t, dur, part, d, lv))
            t += dur
    # Up to 130 bpm: times 3 stays within the 400 bpm a score may have.
    return Score(symbols=tuple(syms), tempo=draw(st.integers(40, 130)))


@settings(max_examples=60, deadline=None)
@given(score=_scores(), ratio=st.sampled_from([F(1, 2), F(2), F(3), F(3, 2), F(64, 106)]))
def test_agreement_is_in_time_not_in_beats(score, ratio):
    """Invariant: re-expressing a score at any tempo changes none of the figures."""
    other = at_tempo(score, score.tempo * ratio)
    assert at_tempo(other, score.tempo) == score  # exact fractions: a lossless round trip
    a = compare_scores(score, other)
    assert a.symbol_agreement == 1.0 and a.exact and a.tempo_ratio == ratio
    assert a.unmatched == 0 and (a.matched == 0 or a.median_start_error == 0.0)
    # Both directions sample the same seconds.
    assert compare_scores(other, score).symbol_agreement == 1.0


def test_agreement_samples_reference_beats():
    """A candidate at twice the tempo with one symbol a candidate beat late is
    half a reference beat late: it costs the reference-beat cells it covers."""
    ref = Score(
        symbols=(Symbol(1, 1, "right_arm", "forward", "middle"), Symbol(3, 1, "right_arm", "right", "middle")), tempo=60
    )
    cand = Score(
        symbols=(Symbol(2, 2, "right_arm", "forward", "middle"), Symbol(6, 2, "right_arm", "right", "middle")),
        tempo=120,
    )
    assert compare_scores(ref, cand).exact
    late = Score(
        symbols=(Symbol(3, 2, "right_arm", "forward", "middle"), Symbol(6, 2, "right_arm", "right", "middle")),
        tempo=120,
    )
    a = compare_scores(ref, late)
    # Sampled at the centres of reference beats 0..3 (0.5, 1.5, …) the late
    # start at 1.5 is in time; per half beat, the cell 1-1.5 differs.
    assert a.symbol_agreement == 1.0 and not a.exact
    assert compare_scores(ref, late, step=F(1, 2)).symbol_agreement == pytest.approx(7 / 8)
    assert a.median_start_error == pytest.approx(0.25)  # median of 0.5 and 0 reference beats
    with pytest.raises(CompareError, match="tempo"):
        at_tempo(ref, 0)


def test_front_and_spring_forms_are_compared():
    from capture2notation.compare.agreement import agreement_cells
    from capture2notation.notation.formats import lab

    base = (
        "tempo: 60\n0 1 right_support place low\n0 1 left_leg forward low\n1 1/2 support air\n"
        "3/2 1/2 {lander}_support place low\n2 1 turn {way} amount=1/2\n"
    )
    ref = lab.loads(base.format(lander="right", way="right"))
    assert compare_scores(ref, ref).exact and compare_scores(ref, ref).symbol_agreement == 1.0
    # A leap instead of a hop: the support column disagrees during the flight.
    leap = lab.loads(base.format(lander="left", way="right"))
    cells = [c for c in agreement_cells(ref, leap, step=F(1, 2)) if c.ref != c.cand]
    assert ("supports", ("support", "air", "hop"), ("support", "air", "leap")) in [
        (c.part, c.ref, c.cand) for c in cells
    ]
    # Half a turn the other way ends facing the same way, but not at the same front.
    other = lab.loads(base.format(lander="right", way="left"))
    bad = [c for c in agreement_cells(ref, other) if c.ref != c.cand]
    assert {c.part for c in bad} == {"front"} and bad[-1].ref == ("1/2",) and bad[-1].cand == ("-1/2",)
    assert not compare_scores(ref, other).exact
    # At another tempo, turns keep their amounts.
    doubled = tuple(
        Symbol(s.start * 2, s.duration * 2, s.part, s.direction, s.level, s.bend, s.amount) for s in ref.symbols
    )
    assert compare_scores(ref, ref.replace(tempo=120, symbols=doubled)).exact
