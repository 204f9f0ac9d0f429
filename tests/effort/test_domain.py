"""The port-de-bras domain of the emotion presets: read inside it, 'not read' with a reason outside."""

from __future__ import annotations

from fractions import Fraction as F

import numpy as np
import pytest

from capture2notation.body import JOINTS
from capture2notation.effort import estimate_effort
from capture2notation.effort.domain import (
    ANKLE_RANGE_MAX,
    EFFORT_DISTANCE_MAX,
    PELVIS_RISE_MAX,
    PELVIS_TRAVEL_MAX,
    body_checks,
    effort_check,
    emotion_domain,
    score_checks,
)
from capture2notation.effort.emotion import SPREAD, features
from capture2notation.notation.effort import PRESETS
from capture2notation.notation.model import Score, Symbol
from synthetic.interpret import interpret
from synthetic.phrases import phrase
from synthetic.port_de_bras import random_port_de_bras

FPS = 25.0


@pytest.fixture(scope="module")
def standing():
    """(T, J, 3) joints of a port de bras (arms only; the dancer stands still)."""
    score = random_port_de_bras(np.random.default_rng(4), 4, tempo=60)
    return interpret(score, fps=FPS).joints()


def _checks(checks):
    return {c.name: c for c in checks}


def test_standing_port_de_bras_passes_the_body_checks(standing):
    c = _checks(body_checks(standing, None, JOINTS))
    assert all(v.ok for v in c.values()), [v.reason for v in c.values()]


def test_a_squat_fails_on_the_pelvis(standing):
    # sink everything above the ankles by 0.35 m and back, twice: a squat
    t = np.arange(standing.shape[0]) / FPS
    dip = 0.35 * 0.5 * (1 - np.cos(2 * np.pi * t / 2.0))
    j = standing.copy()
    above = [i for i, n in enumerate(JOINTS) if not n.endswith(("ankle", "toe"))]
    j[:, above, 2] -= dip[:, None]
    c = _checks(body_checks(j, None, JOINTS))
    assert not c["pelvis_rise"].ok and c["pelvis_rise"].value > PELVIS_RISE_MAX
    assert "pelvis rises" in c["pelvis_rise"].reason and "heights" in c["pelvis_rise"].reason
    assert c["feet"].ok


def test_a_walk_fails_on_travel_and_feet(standing):
    j = standing.copy()
    j[:, :, 1] += 1.2 * np.linspace(0.0, 1.0, j.shape[0])[:, None]  # 1.2 m forward
    c = _checks(body_checks(j, None, JOINTS))
    assert not c["pelvis_travel"].ok and c["pelvis_travel"].value > PELVIS_TRAVEL_MAX
    assert not c["feet"].ok and c["feet"].value > ANKLE_RANGE_MAX


def test_unmeasured_joints_fail_rather_than_pass(standing):
    conf = np.ones(standing.shape[:2])
    conf[:, [JOINTS.index("left_ankle"), JOINTS.index("right_ankle")]] = 0.0
    c = _checks(body_checks(standing, conf, JOINTS))
    assert not c["feet"].ok and "not measured" in c["feet"].reason


def test_score_checks_tempo_lengths_and_parts():
    leg = phrase("figure7")
    c = _checks(score_checks(leg, ["left_leg"] * 3))
    assert not c["leg_share"].ok and not c["arm_share"].ok and not c["arm_movements"].ok
    pdb = random_port_de_bras(np.random.default_rng(1), 4, tempo=150)
    c = _checks(score_checks(pdb, ["right_arm", "left_arm"] * 4))
    assert not c["tempo"].ok and "150 bpm" in c["tempo"].reason
    assert c["arm_share"].ok and c["leg_share"].ok and c["movement_beats"].ok
    slow = Score(symbols=(Symbol(F(0), F(8), "right_arm", "forward", "high"),), tempo=F(60))
    assert not _checks(score_checks(slow, ["right_arm"]))["movement_beats"].ok


def test_effort_far_from_every_preset_is_outside():
    p = PRESETS["angry"]
    near = effort_check(features(p.effort.time, p.effort.weight, p.effort.space, 79.0), np.zeros(4), SPREAD)
    assert near.ok and near.value < 0.1
    # the ballet mocap reading: weight 0.09, far below every preset's 0.41-0.60
    far = effort_check(features(-3.5, 0.09, 1.0, 79.0), np.zeros(4), SPREAD)
    assert not far.ok and far.value > EFFORT_DISTANCE_MAX


def test_a_preset_port_de_bras_is_read_as_its_emotion():
    p = PRESETS["angry"]
    score = random_port_de_bras(np.random.default_rng(11), 3, tempo=p.tempo, effort=p.effort)
    res = estimate_effort(interpret(score, fps=FPS).joints(), None, FPS, score, rng=0, per_movement=False)
    assert res.domain.inside, res.domain.reasons
    assert max(res.emotion, key=res.emotion.get) == "angry"
    d = res.to_dict()
    assert d["emotion_read"] and d["emotion_domain"]["inside"] and d["emotion_text"].startswith("angry")


def test_a_leg_phrase_is_not_read_and_says_why():
    score = phrase("leg_phrase")
    res = estimate_effort(interpret(score, fps=FPS).joints(), None, FPS, score, rng=0, per_movement=False)
    assert res.emotion is None and not res.domain.inside
    d = res.to_dict()
    assert d["emotion"] is None and not d["emotion_read"]
    assert d["emotion_text"].startswith("not read: ") and "legs gesture" in d["emotion_text"]
    assert any(not c["ok"] for c in d["emotion_domain"]["checks"])


def test_no_pooled_effort_is_outside():
    dom = emotion_domain(Score(tempo=F(60)), [], np.zeros((10, len(JOINTS), 3)), None, JOINTS)
    assert not dom.inside and "no pooled Effort" in "; ".join(dom.reasons)


@pytest.mark.parametrize(
    ("seed", "travel"),
    [(1601, False), (1602, False), (1603, True)],
)
def test_random_scores_outside_the_port_de_bras_are_not_read(seed, travel):
    """Tai chi-like random phrases (arms, legs and chest at 40 bpm with a random Effort) and a random
    walk are not what the presets describe: no emotion, and a reason."""
    from synthetic.random_scores import random_score

    rng = np.random.default_rng(seed)
    parts = ("right_arm", "left_arm", "chest", "legs")
    score = random_score(rng, n_beats=8, parts=parts, tempo=F(40), random_effort=True, travel=travel, fps=FPS)
    res = estimate_effort(interpret(score, fps=FPS).joints(), None, FPS, score, rng=seed, per_movement=False)
    assert res.emotion is None and not res.domain.inside
    assert res.to_dict()["emotion_text"].startswith("not read: ")
