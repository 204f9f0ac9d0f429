"""The interpreter: quantising its joints gives back exactly the score.

The read-back uses only the shared DESIGN.md thresholds
(:func:`classify`, :func:`bend_degree`) on the forward-kinematics joints, and
the support conditions of DESIGN.md (foot within 3 cm of the floor and
slower than 0.2 m/s; low = knee bent more than 30°; high = heel raised).
"""

import warnings
from fractions import Fraction

import numpy as np
import pytest

from capture2notation.body import Body, global_rotations, joint_index, segment_vectors
from capture2notation.effort.model import progress
from capture2notation.errors import SyntheticError
from capture2notation.notation import PART_MIDDLE_JOINT, PART_SEGMENTS, Effort, Score, Symbol, classify
from capture2notation.notation.directions import bend_angle, bend_degree, canonical_vector
from synthetic.interpret import STEP_LENGTH, UnreachableWarning, interpret
from synthetic.phrases import PHRASE_NAMES, builtin_phrases, phrase
from synthetic.random_scores import random_score

BODY = Body()
FEET = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}


def _j(name):
    return joint_index(name)


def _readback(sym, J, f):
    """(direction, level, bend) of a gesture symbol's part at frame f."""
    a, b = PART_SEGMENTS[sym.part]
    d, lv = classify(segment_vectors(J[f : f + 1], a, b)[0])
    bend = 0
    if sym.part in PART_MIDDLE_JOINT:
        m = _j(PART_MIDDLE_JOINT[sym.part])
        bend = int(bend_degree(bend_angle(J[f, _j(a)], J[f, m], J[f, _j(b)])))
    return d, lv, bend


def _foot_height(J, foot):
    """Height of the lower of heel (ankle) and toe above their standing height, metres."""
    ha = J[:, _j(f"{foot}_ankle"), 2] - BODY.rest[_j(f"{foot}_ankle"), 2]
    ht = J[:, _j(f"{foot}_toe"), 2] - BODY.rest[_j(f"{foot}_toe"), 2]
    return np.minimum(ha, ht), ha


def _knee_bend(J, foot):
    return bend_angle(J[:, _j(f"{foot}_hip")], J[:, _j(f"{foot}_knee")], J[:, _j(f"{foot}_ankle")])


def assert_round_trip(score, fps):
    """Every symbol of `score` reads back from the interpreted joints."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnreachableWarning)
        m = interpret(score, fps)
    J = m.joints()
    assert np.allclose(J[0], BODY.rest)  # the start pose
    assert len(m.events) == len(score.symbols)
    for sym, f0, f1 in m.events:
        # Arrival within one frame of the symbol's end.
        exact = float(sym.end * 60 / score.tempo) * fps
        assert abs(f1 - exact) <= 0.5 + 1e-9 and abs(f0 - float(sym.start * 60 / score.tempo) * fps) <= 0.5 + 1e-9
        if not sym.is_support:
            assert _readback(sym, J, f1) == (sym.direction, sym.level, sym.bend), (sym, f1)
            continue
        for foot in FEET[sym.part]:
            h, heel = _foot_height(J, foot)
            toe = J[:, _j(f"{foot}_toe")]
            speed = np.linalg.norm(toe[f1] - toe[max(f1 - 1, 0)]) * fps
            assert abs(h[f1]) < 0.03 and speed < 0.2, (sym, foot, h[f1], speed)
            knee = _knee_bend(J, foot)[f1]
            level = "low" if knee > 30 else ("high" if heel[f1] > 0.03 else "middle")
            assert level == sym.level, (sym, foot, knee, heel[f1])
    # Nothing goes through the floor.
    assert J[:, [_j("right_toe"), _j("left_toe"), _j("right_ankle"), _j("left_ankle")], 2].min() > -1e-6
    return m, J


@pytest.mark.parametrize("name", PHRASE_NAMES)
@pytest.mark.parametrize("fps", [25.0, 12.5])
def test_builtin_phrases_round_trip(name, fps):
    assert_round_trip(builtin_phrases()[name], fps)


@pytest.mark.parametrize("seed", range(10))
def test_random_scores_round_trip(seed):
    rng = np.random.default_rng(seed)
    score = random_score(rng, n_beats=8, split_arms=seed % 3 == 1, random_effort=seed % 2 == 0)
    assert_round_trip(score, (25.0, 30.0, 12.5)[seed % 3])


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
            for x, y in zip(seq, seq[1:]):
                assert x.end <= y.start
                if not x.is_support:
                    assert (x.direction, x.level, x.bend) != (y.direction, y.level, y.bend)
    assert random_score(np.random.default_rng(1)) != random_score(np.random.default_rng(2))
    with pytest.raises(SyntheticError, match="Generator"):
        random_score(1)
