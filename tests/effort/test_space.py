"""Space estimation: whole limbs only, outward reach (eq. 5.6), noise, pooling."""

from fractions import Fraction

import numpy as np
import pytest

from capture2notation.effort import estimate_effort, progress_curve
from capture2notation.effort.fit import NO_SPACE, fit_space
from capture2notation.effort.pooled import curve_space, pooled_space
from capture2notation.notation import Score, Symbol
from capture2notation.notation.model import Effort
from synthetic.arcs import arc_motion, random_arm_score

FPS = 25.0
TAU = np.linspace(0.02, 0.98, 49)


def _arm_curves(space, noise=0.0, seed=3, n_moves=3):
    rng = np.random.default_rng(seed)
    score = random_arm_score(rng, n_moves, tempo=60, effort=Effort(-2.5, 0.5, space))
    joints = arc_motion(score, FPS)
    if noise:
        joints = joints + noise * rng.standard_normal(joints.shape)
    times = np.arange(joints.shape[0]) / FPS
    return [
        progress_curve(joints, None, times, s.part, score.seconds(s.start), score.seconds(s.end)) for s in score.symbols
    ]


@pytest.mark.parametrize("space", [0.0, 1.0])
def test_jittered_arm_interval_contains_the_truth(space):
    # 5 mm joint jitter (a capture's frame-to-frame noise) must neither fake
    # nor hide the radial modulation: the 90 % interval holds the truth
    est = pooled_space(_arm_curves(space, noise=0.005))
    assert est.ci90[0] - 1e-9 <= space <= est.ci90[1] + 1e-9
    assert abs(est.median - space) < 0.15


def test_head_movements_do_not_pull_pooled_space_to_direct():
    # the head keeps its distance from the neck whatever the Space: before
    # the fix its flat radial deviation was pooled and pulled S towards 1
    score = Score(
        symbols=(
            Symbol(Fraction(0), Fraction(1), "right_arm", "forward", "middle"),
            Symbol(Fraction(0), Fraction(1), "head", "right_forward", "high"),
            Symbol(Fraction(1), Fraction(1), "right_arm", "right", "high"),
            Symbol(Fraction(1), Fraction(1), "head", "left_forward", "high"),
        ),
        tempo=Fraction(60),
        effort=Effort(-2.5, 0.5, 0.0),
    )
    from synthetic.interpret import interpret

    joints = interpret(score, fps=FPS).joints()
    res = estimate_effort(joints, None, FPS, score, rng=0)
    heads = [m for m in res.movements if m.part == "head"]
    assert heads and all(m.space == NO_SPACE for m in heads)
    assert res.pooled.space.median < 0.05
    assert res.pooled.space.ci90[0] == 0.0


def test_bent_arms_reaching_outward_read_as_indirect():
    # rounded arms (bend=1 at both ends) reach outward (eq. 5.6) by only
    # (L − r)/r ≈ 3.5 % at S = 0; read against the inward 10 % they gave S ≈ 0.66
    from synthetic.interpret import interpret

    syms = []
    for k, (d, lv) in enumerate((("place", "high"), ("right", "middle"), ("forward", "middle"))):
        syms.append(Symbol(Fraction(k), Fraction(1), "right_arm", d, lv, bend=1))
    for space in (0.0, 0.5):
        score = Score(symbols=tuple(syms), tempo=Fraction(60), effort=Effort(-2.5, 0.5, space))
        joints = interpret(score, fps=FPS).joints()
        times = np.arange(joints.shape[0]) / FPS
        curves = [
            progress_curve(joints, None, times, s.part, score.seconds(s.start), score.seconds(s.end)) for s in syms[1:]
        ]  # the first starts from the straight rest pose
        for c in curves:
            assert c.shows_space and np.all(c.outward > 0.01)
            assert abs(curve_space(c).median - space) < 0.05
        assert abs(pooled_space(curves).median - space) < 0.05


def test_pooled_space_gives_each_movement_its_own_end_radii():
    # two direct movements whose end radii are off by different linear drifts
    # (a fit's bone-length or depth errors): a shared line would leave a bump
    y1 = 0.04 * TAU
    y2 = -0.04 * TAU + 0.02
    tau = np.concatenate([TAU, TAU])
    radial = np.concatenate([y1, y2]) + 1e-4 * np.random.default_rng(0).standard_normal(2 * TAU.size)
    groups = np.repeat([0, 1], TAU.size)
    est = fit_space(tau, radial, groups=groups)
    assert est.median > 0.95 and est.ci90[1] == 1.0


def test_outward_depth_must_match_tau():
    with pytest.raises(Exception, match="outward"):
        fit_space(TAU, 0.01 * np.sin(np.pi * TAU), outward=np.ones(3))
