"""The interpreter: per-frame quantisation of its joints gives back exactly the score.

The read-back uses only the shared DESIGN.md thresholds
(:func:`classify_indices`, :func:`bend_degree`) on the forward-kinematics
joints, and the support conditions of DESIGN.md (lower of heel and toe
within 3 cm of the floor and the foot slower than 0.2 m/s — the slower of
the steps into and out of a frame, as the quantiser measures it; low = knee
bent more than 30°; high = heel raised).
"""

import itertools
import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from capture2notation.body import Body, global_rotations, joint_index, segment_vectors
from capture2notation.errors import SyntheticError
from capture2notation.notation import PART_MIDDLE_JOINT, PART_SEGMENTS, Effort, Score, Symbol
from capture2notation.notation.directions import bend_angle, bend_degree, canonical_vector, classify_indices
from capture2notation.notation.effort import progress
from capture2notation.notation.model import DIRECTIONS, LEVELS
from synthetic.interpret import STEP_LENGTH, UnreachableWarning, interpret, unreachable
from synthetic.phrases import PHRASE_NAMES, builtin_phrases, phrase
from synthetic.random_scores import random_score

BODY = Body()
FEET = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}
DIRS = list(DIRECTIONS)


def _j(name):
    return joint_index(name)


def _labels(J, part):
    """Per-frame (direction name, level name, bend degree) of a gesture part."""
    a, b = PART_SEGMENTS[part]
    d, lv = classify_indices(segment_vectors(J, a, b))
    bend = np.zeros(len(J), int)
    if part in PART_MIDDLE_JOINT:
        m = _j(PART_MIDDLE_JOINT[part])
        bend = np.asarray(bend_degree(bend_angle(J[:, _j(a)], J[:, m], J[:, _j(b)])), int)
    return [(DIRS[x], LEVELS[y], int(z)) for x, y, z in zip(d, lv, bend)]


def _readback(sym, J, f):
    return _labels(J[f : f + 1], sym.part)[0]


def _foot_height(J, foot):
    """Height of the lower of heel (ankle) and toe above their standing height, metres."""
    ha = J[:, _j(f"{foot}_ankle"), 2] - BODY.rest[_j(f"{foot}_ankle"), 2]
    ht = J[:, _j(f"{foot}_toe"), 2] - BODY.rest[_j(f"{foot}_toe"), 2]
    return np.minimum(ha, ht), ha


def _knee_bend(J, foot):
    return bend_angle(J[:, _j(f"{foot}_hip")], J[:, _j(f"{foot}_knee")], J[:, _j(f"{foot}_ankle")])


def _supports(J, fps, foot):
    """(T,) whether the foot supports and (T,) its level (DESIGN.md conditions)."""
    mid = 0.5 * (J[:, _j(f"{foot}_ankle")] + J[:, _j(f"{foot}_toe")])
    step = np.linalg.norm(np.diff(mid, axis=0), axis=-1) * fps
    speed = np.minimum(np.r_[np.inf, step], np.r_[step, 0.0])
    low = np.minimum(J[:, _j(f"{foot}_ankle"), 2], J[:, _j(f"{foot}_toe"), 2])
    sup = (low < 0.03) & (speed < 0.2)
    heel = _foot_height(J, foot)[1]
    level = np.where(_knee_bend(J, foot) > 30, "low", np.where(heel > 0.03, "high", "middle"))
    return sup, level


def _hold_parts(score):
    parts = ["head", "chest"]
    for side in ("right", "left"):
        if not any(s.part in (f"{side}_upper_arm", f"{side}_forearm") for s in score.symbols):
            parts.append(f"{side}_arm")
    return parts


def assert_round_trip(score, fps):
    """Every symbol of `score` reads back from the interpreted joints, on time.

    Gestures read back at their end frame and are still moving one frame
    before (they arrive within one frame); named feet support at the end
    frame at the symbol's level, and a foot off the floor during the symbol
    (a step, or a landing from a gesture) does not support two frames before
    its end (it arrives within one frame).  Head, chest and whole arms hold their last symbol
    (or the start pose) on every frame they do not move.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnreachableWarning)
        m = interpret(score, fps)
    J = m.joints()
    assert np.allclose(J[0], BODY.rest)  # the start pose
    assert len(m.events) == len(score.symbols)
    labels = {}
    for sym, f0, f1 in m.events:
        exact = float(sym.end * 60 / score.tempo) * fps
        assert abs(f1 - exact) <= 0.5 + 1e-9 and abs(f0 - float(sym.start * 60 / score.tempo) * fps) <= 0.5 + 1e-9
        if sym.is_turn or sym.is_air:
            # Turns and flight are checked in test_turns_flight.py.
            continue
        if not sym.is_support:
            if sym.part not in labels:
                labels[sym.part] = _labels(J, sym.part)
            assert labels[sym.part][f1] == (sym.direction, sym.level, sym.bend), (sym, f1)
            v = segment_vectors(J, *PART_SEGMENTS[sym.part])
            # A held arm may drift up to ~1° while the chest turns it against
            # the shoulder's extreme, and recover when its next symbol starts;
            # only a movement larger than that must still be moving.
            if f1 - f0 >= 2 and not np.allclose(v[f0], v[f1], atol=0.02):
                assert not np.allclose(v[f1 - 1], v[f1], atol=1e-6), (sym, "arrived early")
            continue
        for foot in FEET[sym.part]:
            sup, level = _supports(J, fps, foot)
            assert sup[f1] and level[f1] == sym.level, (sym, foot, sup[f1], level[f1])
            lifted = _foot_height(J, foot)[0][f0 + 1 : f1] >= 0.03
            if sym.direction != "place" or lifted.any():  # a step or a landing
                assert f1 - f0 < 3 or not sup[f1 - 2], (sym, foot, "the foot supports before it arrives")
            elif sup[f0]:  # a foot on the floor stays supporting
                assert sup[f0 : f1 + 1].all(), (sym, foot, "the foot stops supporting")
    for part in _hold_parts(score):
        own = [(s, f0, f1) for s, f0, f1 in m.events if s.part == part]
        start = ("place", "high" if part in ("head", "chest") else "low", 0)
        got = labels.get(part) or _labels(J, part)
        held, moving = [start] * m.n_frames, np.zeros(m.n_frames, bool)
        for s, f0, f1 in own:
            moving[f0 + 1 : f1 + 1] = True
            held[f1:] = [(s.direction, s.level, s.bend)] * (m.n_frames - f1)
        bad = [f for f in np.flatnonzero(~moving) if got[f] != held[f]]
        assert not bad, (part, bad[0], got[bad[0]], held[bad[0]])
    # Nothing goes through the floor.
    assert J[:, [_j("right_toe"), _j("left_toe"), _j("right_ankle"), _j("left_ankle")], 2].min() > -1e-6
    return m, J


@pytest.mark.parametrize("name", PHRASE_NAMES)
@pytest.mark.parametrize("fps", [25.0, 12.5, 30.0])
def test_builtin_phrases_round_trip(name, fps):
    assert_round_trip(builtin_phrases()[name], fps)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    fps=st.sampled_from([25.0, 30.0, 12.5, 50.0, 10.0]),
    split=st.booleans(),
    effort=st.booleans(),
)
def test_random_scores_round_trip(seed, fps, split, effort):
    score = random_score(np.random.default_rng(seed), n_beats=8, split_arms=split, random_effort=effort, fps=fps)
    assert_round_trip(score, fps)


def test_random_scores_include_legs_supports_and_steps():
    kinds = {"support": 0, "step": 0, "leg": 0}
    for seed in range(12):
        for s in random_score(np.random.default_rng(seed), n_beats=8).symbols:
            kinds["support"] += s.is_support
            kinds["step"] += s.is_support and s.direction != "place"
            kinds["leg"] += s.part.endswith("_leg")
    assert kinds["support"] >= 24 and kinds["step"] >= 2 and kinds["leg"] >= 6, kinds


def test_whole_limbs_arrive_on_the_canonical_vector_exactly_at_the_end_frame():
    m = interpret(phrase("port_de_bras"), 25.0)
    J = m.joints()
    for sym, f0, f1 in m.events:
        if sym.part not in ("right_arm", "left_arm", "head"):
            continue
        v = segment_vectors(J, *PART_SEGMENTS[sym.part])
        assert np.allclose(v[f1], canonical_vector(sym.direction, sym.level), atol=1e-6)
        if not np.allclose(v[f0], v[f1], atol=1e-4):
            assert not np.allclose(v[f1 - 1], v[f1], atol=1e-4)  # still moving one frame before
        if sym.part.endswith("arm"):
            assert _readback(sym, J, f1)[2] == sym.bend == 1


def _single_move(effort, target=("forward", "middle"), bend=0, fps=100.0):
    score = Score((Symbol(0, 2, "right_arm", *target, bend),), tempo=60, effort=effort)
    m = interpret(score, fps)
    return m, m.joints()


def test_progress_along_the_path_follows_the_effort_logistic():
    effort = Effort(time=-3.0, weight=0.4, space=1.0)
    m, J = _single_move(effort)
    w = J[:, _j("right_wrist")] - J[:, _j("right_shoulder")]
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    angle = np.arccos(np.clip(w @ np.array([0.0, 0.0, -1.0]), -1, 1))
    tau = np.arange(m.n_frames) / (m.n_frames - 1)
    assert np.allclose(angle / angle[-1], progress(tau, -3.0, 0.4), atol=1e-9)
    speed = np.linalg.norm(np.diff(J[:, _j("right_wrist")], axis=0), axis=-1)
    t_peak = (np.argmax(speed) + 0.5) / (m.n_frames - 1)
    assert 0.55 * 0.4 <= t_peak <= 0.4 + 0.02


def test_space_indirect_draws_the_hand_in_mid_movement():
    direct = _single_move(Effort(-2.0, 0.5, 1.0))[1]
    indirect = _single_move(Effort(-2.0, 0.5, 0.0))[1]
    r_d = np.linalg.norm(direct[:, _j("right_wrist")] - direct[:, _j("right_shoulder")], axis=-1)
    r_i = np.linalg.norm(indirect[:, _j("right_wrist")] - indirect[:, _j("right_shoulder")], axis=-1)
    assert np.ptp(r_d) < 1e-9
    mid = len(r_i) // 2
    assert r_i[mid] == pytest.approx(0.9 * r_d[mid], rel=1e-6)  # eq. 5.5 at tau = 1/2
    assert r_i[0] == pytest.approx(r_d[0]) and r_i[-1] == pytest.approx(r_d[-1])


def test_space_outward_reaches_out_when_the_limb_is_bent():
    syms = (Symbol(0, 1, "right_arm", "forward", "low", 2), Symbol(1, 1, "right_arm", "right", "middle", 2))
    r = []
    for space in (1.0, 0.0):
        J = interpret(Score(syms, tempo=60, effort=Effort(-2.0, 0.5, space)), 50.0).joints()
        r.append(np.linalg.norm(J[:, _j("right_wrist")] - J[:, _j("right_shoulder")], axis=-1))
    assert np.allclose(r[0][50:], r[0][50])  # direct: the bent arm keeps its reach
    assert r[1][75] > r[0][75] + 0.05  # indirect: out towards full reach mid-way (eq. 5.6)
    assert r[1][100] == pytest.approx(r[0][100])


def test_figure7_phrase_is_wolofskys_coded_input():
    from capture2notation.notation.formats import loads

    coded = "2 0.00 ANR 4.00 -\n2 0.00 ANL 1.00 -\n1 1.00 WLL 1.00 F\n1 2.00 WLL .50 LSM\n1 3.00 WLL 1.00 LSL\n0 4.00 - - -\n"
    assert loads(coded, "wolofsky1974").symbols == phrase("figure7").symbols


def test_arms_pass_through_place_high_and_low_without_flipping():
    syms = [
        Symbol(0, 1, "right_arm", "right", "middle", 1),
        Symbol(1, 1, "right_arm", "place", "high", 1),
        Symbol(2, 1, "right_arm", "left_forward", "high", 1),
        Symbol(3, 1, "right_arm", "place", "low", 1),
        Symbol(4, 1, "right_arm", "forward", "middle", 1),
    ]
    m = interpret(Score(tuple(syms), tempo=60), 50.0)
    G = global_rotations(m.angles)[:, _j("right_shoulder")]
    rel = np.einsum("tji,tjk->tik", G[:-1], G[1:])
    step = np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1) / 2, -1, 1))
    assert step.max() < 0.25  # a flip would turn the upper arm by ~pi in a frame
    # Elbows flex the anatomical way throughout.
    assert np.all(m.angles[:, _j("right_elbow"), 0] >= 0)


def test_unnotated_parts_hold_and_supports_move_the_root():
    m, J = assert_round_trip(phrase("figure7"), 25.0)
    for name in ("right_shoulder", "left_shoulder", "right_elbow", "neck", "waist"):
        assert np.all(m.angles[:, _j(name)] == 0.0)
    # The weight is over the right foot when the left leg starts to gesture.
    f = m.events[[s.part for s, _, _ in m.events].index("left_leg")][1]
    assert m.root[f, 0] == pytest.approx(J[f, _j("right_ankle"), 0], abs=1e-9)
    assert np.ptp(J[:, _j("right_ankle")], axis=0).max() < 1e-9  # the supporting foot never moves


def test_plie_releve_and_step():
    m, J = assert_round_trip(phrase("leg_phrase"), 25.0)
    ev = {(s.part, s.direction, s.level, s.start): (f0, f1) for s, f0, f1 in m.events}
    f_plie = ev[("support", "place", "low", 0)][1]
    assert _knee_bend(J, "right")[f_plie] == pytest.approx(45.0, abs=0.5)
    assert m.root[f_plie, 2] < BODY.rest[0, 2] - 0.03
    f_rel = ev[("support", "place", "high", 4)][1]
    assert _foot_height(J, "left")[1][f_rel] > 0.05 and m.root[f_rel, 2] > BODY.rest[0, 2] + 0.05
    f0, f1 = ev[("right_support", "forward", "middle", 12)]
    moved = J[f1, _j("right_ankle")] - J[f0, _j("right_ankle")]
    assert moved[1] == pytest.approx(STEP_LENGTH * BODY.height, abs=0.01) and abs(moved[0]) < 0.01
    assert m.root[f1, 1] == pytest.approx(J[f1, _j("right_ankle"), 1], abs=1e-6)  # the weight followed
    # The step arrives at the end of its symbol, like a gesture: the foot
    # leaves the floor on the first frame and lands on the last.
    sup, _ = _supports(J, 25.0, "right")
    assert sup[f0] and not sup[f0 + 1 : f1].any() and sup[f1]
    assert not np.allclose(m.root[f1 - 1], m.root[f1], atol=1e-4)  # the weight still moving


@pytest.mark.parametrize("fps", [25.0, 12.5, 50.0])
def test_steps_and_landings_arrive_within_one_frame_of_their_end(fps):
    syms = (
        Symbol(0, 1, "right_support", "forward", "middle"),
        Symbol(1, 1, "left_support", "forward", "middle"),
        Symbol(2, 1, "right_support", "right", "middle"),
        Symbol(3, 1, "left_leg", "forward", "low"),
        Symbol(4, 1, "support", "place", "middle"),
    )
    m, J = assert_round_trip(Score(syms, tempo=90), fps)
    for sym, _f0, f1 in m.events:
        if sym.part == "left_leg":
            continue
        foot = FEET[sym.part][0] if sym.part != "support" else "left"
        sup, _ = _supports(J, fps, foot)
        assert sup[f1] and not sup[f1 - 1 if fps < 40 else f1 - 2], (sym, fps)


def test_figure7_leg_sweeps_at_hip_height_within_the_extremes():
    """Forward middle → side middle passes the hip's rz extreme on the direct
    path (gimbal lock); the dancer keeps the leg at middle level all the way
    and never stops short to jump."""
    m, J = assert_round_trip(phrase("figure7"), 25.0)
    ev = {(s.direction, s.level): (f0, f1) for s, f0, f1 in m.events if s.part == "left_leg"}
    f0, f1 = ev[("left", "middle")]
    v = segment_vectors(J[f0 : f1 + 1], "left_hip", "left_ankle")
    elevation = np.degrees(np.arcsin(v[:, 2]))
    azimuth = np.degrees(np.arctan2(v[:, 0], v[:, 1]))
    assert np.all(np.abs(elevation) < 22.5)
    assert np.all(np.diff(azimuth) <= 1e-9) and azimuth[0] == pytest.approx(0, abs=1e-6)
    assert azimuth[-1] == pytest.approx(-90, abs=1e-6)
    lim = BODY.limits[_j("left_hip")]
    assert np.all(m.angles[:, _j("left_hip")] >= lim[:, 0] - 1e-12)


@pytest.mark.parametrize(
    "syms,names",
    [
        ((Symbol(0, 1, "head", "right", "middle"),), ("head right middle", "neck ry")),
        ((Symbol(0, 1, "chest", "back", "middle"),), ("chest back middle", "waist rx")),
        ((Symbol(0, 1, "chest", "forward", "middle"),), ("head place high (the start pose) cannot be held", "neck rx")),
        (
            (Symbol(0, 1, "left_support", "place", "middle"), Symbol(1, 1, "right_leg", "left", "middle")),
            ("right_leg left middle", "right_hip rz <= 60"),
        ),
    ],
)
def test_unreachable_symbols_warn_naming_the_symbol_and_the_extreme(syms, names):
    with pytest.warns(UnreachableWarning) as caught:
        m = interpret(Score(syms, tempo=60), 25.0)
    text = " | ".join(str(w.message) for w in caught)
    for name in names:
        assert name in text, text
    if "cannot be held" not in names[0]:
        assert [s for s, _ in unreachable(m)] == [syms[-1]]


def test_out_of_reach_symbols_warn_and_conflicts_raise():
    with pytest.warns(UnreachableWarning, match="head right low"):
        interpret(Score((Symbol(0, 1, "head", "right", "low"),)), 10)
    with pytest.raises(SyntheticError, match="overlaps"):
        interpret(Score((Symbol(0, 2, "right_arm", "forward", "low"), Symbol(1, 1, "right_forearm", "right", "low"))))
    with pytest.raises(SyntheticError, match="gesture and support at once"):
        interpret(Score((Symbol(0, 2, "right_support", "place", "low"), Symbol(1, 1, "right_leg", "forward", "low"))))
    with pytest.raises(SyntheticError, match="step on both feet"):
        interpret(Score((Symbol(0, 1, "support", "forward", "middle"),)))
    with pytest.raises(SyntheticError, match="fps"):
        interpret(Score(), 0)


def test_empty_score_is_the_start_pose():
    m = interpret(Score(), 25)
    assert m.n_frames == 1 and np.allclose(m.joints()[0], BODY.rest)


def test_random_scores_are_valid_and_reproducible():
    for seed in range(5):
        a = random_score(np.random.default_rng(seed), n_beats=6, parts=("right_arm", "legs", "head"))
        b = random_score(np.random.default_rng(seed), n_beats=6, parts=("right_arm", "legs", "head"))
        assert a == b
        assert a.duration <= 6
        for s in a.symbols:
            assert s.duration >= Fraction(1, 2) and (s.start * 4).denominator == 1 and (s.duration * 4).denominator == 1
            assert s.part in {"right_arm", "head", "left_leg", "right_leg"} | set(FEET)
        for part in {s.part for s in a.symbols}:
            seq = a.for_part(part)
            for x, y in itertools.pairwise(seq):
                assert x.end <= y.start
                if not x.is_support:
                    assert (x.direction, x.level, x.bend) != (y.direction, y.level, y.bend)
    assert random_score(np.random.default_rng(1)) != random_score(np.random.default_rng(2))
    with pytest.raises(SyntheticError, match="Generator"):
        random_score(1)


def test_weight_arrives_on_both_feet_before_the_next_support_moves_it():
    # DESIGN.md: a movement begins at its start.  `support` ending at beat 2
    # arrives on both feet; the transfer onto the left foot belongs to the
    # `left_support` starting then, even though the right leg gestures from 2.
    from capture2notation.compare.agreement import score_differences
    from capture2notation.quantise.segment import segment_motion

    score = Score(
        (
            Symbol(0, 1, "right_support", "place", "low"),
            Symbol(1, 1, "left_leg", "left_forward", "middle", 1),
            Symbol(2, 1, "support", "place", "middle"),
            Symbol(3, 1, "left_support", "place", "low"),
            Symbol(3, 1, "right_leg", "right", "low"),
        ),
        tempo=80,
    )
    fps = 25.0
    _, J = assert_round_trip(score, fps)
    f = round(3 * 60 / score.tempo * fps)
    pelvis, right, left = J[f, _j("pelvis"), 0], J[f, _j("right_ankle"), 0], J[f, _j("left_ankle"), 0]
    # Midway between the feet (the quantiser's "over a foot" is within a quarter of the way).
    assert (pelvis - right) / (left - right) == pytest.approx(0.5, abs=0.05)
    seg = segment_motion(J, fps, tempo=score.tempo)
    assert score_differences(score, seg.score) == []


@pytest.mark.parametrize("seed", [20260002, 20260010, 20260016])
def test_random_supports_hand_the_weight_on_at_their_end(seed):
    # At a beat where one support symbol ends and the next starts, the pelvis
    # is over the mean of the feet the ending symbol names (those not
    # gesturing since its start): the next symbol moves it only from there.
    score = random_score(np.random.default_rng(seed), n_beats=8, turns=True, springs=True, travel=True, axes="body")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        J = interpret(score, 25.0).joints()
    sups = [s for s in score.symbols if s.is_support and not s.is_air]
    airs = [s for s in score.symbols if s.is_air]
    feet = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}
    checked = 0
    for s in sups:
        if not any(x.start == s.end for x in sups) or any(a.end == s.start for a in airs):
            continue  # not handed on, or a landing (its own pelvis path)
        named = [
            f
            for f in feet[s.part]
            if not any(g.part == f"{f}_leg" and s.start <= g.start < s.end for g in score.symbols)
        ]
        f = round(float(s.end * 60 / score.tempo) * 25.0)
        mean = np.mean([J[f, _j(f"{n}_ankle"), :2] for n in named], axis=0)
        assert np.linalg.norm(J[f, _j("pelvis"), :2] - mean) < 0.01, (s, named)
        checked += 1
    assert checked >= 1
