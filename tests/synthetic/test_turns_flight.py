"""The virtual dancer's turns, flight, travel and body key (issue 14 item 2)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from capture2notation.body import body_cross, body_frame, joint_index, segment_vectors
from capture2notation.io.truth import read_truth, write_truth
from capture2notation.notation.directions import classify
from capture2notation.notation.facing import front_changes, springs
from capture2notation.notation.formats import lab
from synthetic import interpret, random_score
from synthetic.flight import GRAVITY
from synthetic.interpret import beat_frame
from synthetic.render.camera import Camera
from synthetic.render.job import truth_fields
from synthetic.render.scene import Pose
from synthetic.supports import STEP_LENGTH

FPS = 25.0
# DESIGN.md: a foot supports within 3 cm of the floor and slower than 0.2 m/s.
SUPPORT_HEIGHT, SUPPORT_SPEED = 0.03, 0.2

PHRASE = lab.loads("""\
tempo: 60
0 2 support place middle
2 1 right_support place high
2 1 turn right amount=1/2
2 1 left_leg forward low bend=2
3 1 support place middle
4 1 support place low
5 1/2 support air
11/2 1 support place low
13/2 1/2 right_support place low
13/2 1/2 left_leg back low
7 1/2 support air
15/2 1/2 left_support forward low
15/2 3/2 right_leg back middle
9 1 turn left amount=1/4
""")


def _frame(beat, score=PHRASE):
    return beat_frame(beat, score.tempo, FPS)


def _feet(J):
    """Per foot: (T,) lowest height and (T, 3) centre (midpoint of ankle and toe)."""
    out = {}
    for foot in ("right", "left"):
        a, t = J[:, joint_index(f"{foot}_ankle")], J[:, joint_index(f"{foot}_toe")]
        out[foot] = (np.minimum(a[:, 2], t[:, 2]), 0.5 * (a + t))
    return out


@pytest.fixture(scope="module")
def motion():
    return interpret(PHRASE, fps=FPS)  # any UnreachableWarning fails the test (warnings are errors)


def test_a_pirouette_spins_on_the_supporting_foot(motion):
    J = motion.joints()
    f0, f1 = _frame(2), _frame(3)
    _, centre = _feet(J)["right"]
    speed = np.linalg.norm(np.diff(centre[f0 : f1 + 1, :2], axis=0), axis=-1) * FPS
    assert speed.max() < SUPPORT_SPEED  # the foot's centre stays put: it keeps supporting
    front = motion.front
    assert front[f0] == pytest.approx(0.0, abs=1e-9) and front[f1] == pytest.approx(180.0, abs=1e-9)
    assert np.all(np.diff(front[f0 : f1 + 1]) >= 0)  # clockwise all the way
    # The body faces the back of the room after it: the hips' right is world −x.
    assert body_frame(J[f1 + 1 : f1 + 2])[0, 0] @ [1.0, 0.0, 0.0] == pytest.approx(-1.0, abs=1e-6)


def test_flight_is_ballistic_with_no_foot_on_the_floor(motion):
    J = motion.joints()
    feet = _feet(J)
    for a, b in ((5, Fraction(11, 2)), (7, Fraction(15, 2))):
        fa, fb = _frame(a), _frame(b)
        inside = slice(fa + 1, fb)
        assert min(feet[f][0][inside].min() for f in feet) > SUPPORT_HEIGHT
        z = motion.root[fa : fb + 1, 2]
        assert np.diff(z, 2) * FPS**2 == pytest.approx(-GRAVITY, abs=1e-6)
        # Touchdown: the landing foot on the floor at the flight's end.
        assert min(feet[f][0][fb] for f in feet) < SUPPORT_HEIGHT


def test_landing_absorbs_into_plie_and_rests(motion):
    J = motion.joints()
    fe = _frame(Fraction(13, 2))  # the jump's landing (support place low) ends
    for side in ("right", "left"):
        hip, knee, ankle = (J[fe, joint_index(f"{side}_{j}")] for j in ("hip", "knee", "ankle"))
        u, v = hip - knee, ankle - knee
        bend = 180.0 - np.degrees(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v)))
        assert bend > 30.0  # DESIGN.md: plié (support level low)
    assert np.linalg.norm(motion.root[fe] - motion.root[fe - 1]) * FPS < 0.05


def test_spring_forms_of_the_phrase():
    assert [f for _, f in springs(PHRASE)] == ["jump", "leap"]


def test_steps_travel_relative_to_the_front():
    score = lab.loads("tempo: 60\n0 2 turn right amount=1/4\n2 1 right_support forward middle\n")
    m = interpret(score, fps=FPS)
    J = m.joints()
    ankle = J[:, joint_index("right_ankle")]
    moved = ankle[-1] - ankle[_frame(2, score)]
    # Facing world +x after a quarter turn right: a forward step goes +x, a step length.
    assert moved[0] == pytest.approx(STEP_LENGTH * m.body.height, rel=1e-6)
    assert abs(moved[1]) < 1e-6


def test_a_turn_on_both_feet_pivots_about_their_midpoint_though_one_lifts_as_it_ends():
    # The turn is done on both feet; the relevé on the left and the right
    # leg's gesture begin as it ends (DESIGN.md: a movement begins at its
    # start), so the feet slide round their midpoint (synthetic.turning).
    # Pivoting on the left foot alone swung the right one at 0.4 m/s.
    score = lab.loads("tempo: 101\n0 2 turn left amount=1/4\n2 2 left_support place high\n2 2 right_leg right low\n")
    J = interpret(score, fps=FPS).joints()
    centre = {
        side: 0.5 * (J[:, joint_index(f"{side}_ankle")] + J[:, joint_index(f"{side}_toe")])[:, :2]
        for side in ("right", "left")
    }
    during = slice(0, _frame(2, score) + 1)
    mid = 0.5 * (centre["right"] + centre["left"])[during]
    assert np.abs(mid - mid[0]).max() < 1e-6
    # Both feet slide alike, each at half the speed of the one swung before.
    speed = {k: np.linalg.norm(np.diff(v[during], axis=0), axis=1) * FPS for k, v in centre.items()}
    np.testing.assert_allclose(speed["right"], speed["left"], atol=1e-6)


def test_body_key_arms_follow_the_torso():
    text = "tempo: 60\n0 2 chest forward high\n2 2 right_arm forward middle\n"
    standard, body = lab.loads(text), lab.loads("axes: body\n" + text)
    for score, key, want in ((standard, body_frame, ("forward", "middle")), (body, body_cross, ("forward", "middle"))):
        J = interpret(score, fps=FPS).joints()
        v = segment_vectors(J[-1:], "right_shoulder", "right_wrist", key(J[-1:]))[0]
        assert classify(v) == want
    # The body-keyed arm tilts with the chest (45° forward): in the standard cross it reads low.
    Jb = interpret(body, fps=FPS).joints()
    v = segment_vectors(Jb[-1:], "right_shoulder", "right_wrist")[0]
    assert classify(v) == ("forward", "low")


def test_truth_sidecar_carries_the_front(tmp_path, motion):
    pose = Pose.from_motion(motion)
    fields = truth_fields(pose, Camera.for_view("front", (320, 240), motion.body.height), score_json="{}")
    write_truth(tmp_path / "truth.npz", **fields)
    truth = read_truth(tmp_path / "truth.npz")
    assert truth.front is not None and truth.front.shape == (motion.n_frames,)
    np.testing.assert_allclose(truth.front, motion.front, atol=1e-9)
    assert truth.front[-1] == pytest.approx(90.0, abs=1e-6)  # half right, then a quarter left


def _check_random(seed: int, counts: dict) -> None:
    rng = np.random.default_rng(seed)
    axes = ("standard", "body")[seed % 2]
    score = random_score(rng, n_beats=12, turns=True, springs=True, travel=True, axes=axes)
    m = interpret(score, fps=FPS)  # UnreachableWarning would be an error here
    pose = Pose.from_motion(m)
    front = truth_fields(pose, Camera.for_view("front", (320, 240), m.body.height))["front"]
    for turn, written in front_changes(score):
        f1 = min(beat_frame(turn.end, score.tempo, FPS), m.n_frames - 1)
        assert front[f1] == pytest.approx(float(written) * 360.0, abs=1.0)
        counts.setdefault("amounts", set()).add(turn.amount)
        counts.setdefault("directions", set()).add(turn.direction)
    for _, form in springs(score):
        counts.setdefault("forms", set()).add(form)
    counts["steps"] = counts.get("steps", 0) + sum(
        s.is_support and s.direction not in ("place", "air") for s in score.symbols
    )
    counts.setdefault("axes", set()).add(score.axes)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_scores_with_turns_springs_and_travel(seed):
    _check_random(seed, {})


@pytest.mark.slow
def test_thirty_random_scores_cover_turns_springs_travel_and_keys():
    counts: dict = {}
    for seed in range(30):
        _check_random(seed, counts)
    assert counts["forms"] == {"jump", "hop", "leap", "assemblé", "sissonne"}
    assert counts["directions"] == {"right", "left"}
    assert min(counts["amounts"]) == Fraction(1, 8) and max(counts["amounts"]) >= Fraction(3, 2)
    assert counts["steps"] >= 30 and counts["axes"] == {"standard", "body"}


@pytest.mark.parametrize("seed", [20300008, 20320023])
def test_a_low_flight_keeps_both_feet_off_the_floor(seed):
    """Under 0.35 s in the air the pelvis rises about 12 cm: a fully pointed foot would brush the floor."""
    score = random_score(np.random.default_rng(seed), n_beats=8, turns=True, springs=True, travel=True, axes="body")
    J = interpret(score, fps=FPS).joints()
    feet = _feet(J)
    flights = [s for s in score.symbols if s.is_air]
    assert flights and any(float(s.duration) * 60 / float(score.tempo) < 0.35 for s in flights)
    for s in flights:
        fa, fb = _frame(s.start, score), _frame(s.end, score)
        assert min(feet[f][0][fa + 1 : fb].min() for f in feet) > SUPPORT_HEIGHT
