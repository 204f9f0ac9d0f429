"""DTW / tempo alignment and the comparison metrics."""

from fractions import Fraction

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, forward_kinematics, joint_index
from capture2notation.compare.align import align_dtw, align_tempo, dtw, limb_features
from capture2notation.compare.metrics import (
    agreement_by_part,
    angle_between,
    compare_movements,
    effort_differences,
    key_frames,
    mpjpe,
    pa_mpjpe,
    procrustes_align,
)
from capture2notation.errors import CompareError
from capture2notation.notation import Score, Symbol


def arm_raise(progress):
    """Joints with the right arm swung forward by progress·90° (progress in [0, 1])."""
    progress = np.asarray(progress, float)
    angles = np.zeros((len(progress), len(JOINTS), 3))
    angles[:, joint_index("right_shoulder"), 0] = progress * np.pi / 2
    angles[:, joint_index("left_shoulder"), 1] = -progress * np.pi / 4  # left arm out to the left side
    return forward_kinematics(angles)


def test_dtw_recovers_a_known_warp():
    t = np.linspace(0, 1, 40)
    ref = arm_raise(np.sin(np.pi * t) ** 2)
    # Candidate: the same movement with a slow start (time warped by t^2).
    tc = np.linspace(0, 1, 55)
    cand = arm_raise(np.sin(np.pi * tc**2) ** 2)
    al = align_dtw(ref, cand)
    assert al.path[0].tolist() == [0, 0] and al.path[-1].tolist() == [39, 54]
    assert np.all(np.diff(al.path, axis=0) >= 0)
    # At the peak (t = 0.5) the candidate is at tc = sqrt(0.5).
    peak = al.candidate_frame([20])[0] / 54
    assert peak == pytest.approx(np.sqrt(0.5), abs=0.06)
    assert al.cost < 0.01


def test_dtw_identity_is_diagonal_and_free():
    ref = arm_raise(np.linspace(0, 1, 25))
    al = align_dtw(ref, ref)
    assert np.array_equal(al.path[:, 0], al.path[:, 1])
    assert al.cost == pytest.approx(0.0, abs=1e-12)


def test_dtw_matches_plain_recursion():
    rng = np.random.default_rng(3)
    c = rng.random((7, 9))
    path, total = dtw(c)
    acc = np.full((8, 10), np.inf)
    acc[0, 0] = 0
    for i in range(7):
        for j in range(9):
            acc[i + 1, j + 1] = c[i, j] + min(acc[i, j], acc[i, j + 1], acc[i + 1, j])
    assert total == pytest.approx(acc[7, 9], rel=1e-12)
    assert c[path[:, 0], path[:, 1]].sum() == pytest.approx(total, rel=1e-12)


def test_dtw_rejects_nan():
    with pytest.raises(CompareError, match="NaN"):
        dtw(np.array([[0.0, np.nan]]))


def test_tempo_alignment_maps_same_beats():
    al = align_tempo(50, 200, ref_tempo=120, cand_tempo=60, fps_ref=25, fps_cand=50)
    # reference frame 25 = 1 s = 2 beats; candidate reaches beat 2 at 2 s = frame 100.
    assert al.candidate_frame([25])[0] == 100


def test_limb_features_unit_vectors():
    f = limb_features(arm_raise([0.0, 1.0]))
    assert f.shape == (2, 6, 3)
    np.testing.assert_allclose(np.linalg.norm(f, axis=-1), 1.0, atol=1e-9)
    np.testing.assert_allclose(f[0, 0], [0, 0, -1], atol=1e-9)  # right arm hangs
    np.testing.assert_allclose(f[1, 0], [0, 1, 0], atol=1e-9)  # then points forward


def test_mpjpe_of_translation_and_nan():
    a = arm_raise([0.3, 0.6])
    b = a + np.array([0.03, 0.0, 0.04])
    np.testing.assert_allclose(mpjpe(a, b), 0.05, atol=1e-12)
    b[0, 3] = np.nan
    np.testing.assert_allclose(mpjpe(a, b), 0.05, atol=1e-12)
    b[1] = np.nan
    assert np.isnan(mpjpe(a, b)[1])


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), scale=st.floats(0.5, 2.0))
def test_procrustes_undoes_similarity_transforms(seed, scale):
    rng = np.random.default_rng(seed)
    ref = arm_raise(rng.random(3))
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    cand = scale * ref @ q.T + rng.normal(size=3)
    np.testing.assert_allclose(pa_mpjpe(ref, cand), 0.0, atol=1e-9)


def test_procrustes_rotation_agrees_with_scipy():
    rng = np.random.default_rng(7)
    ref = arm_raise([0.4])
    cand = ref + rng.normal(scale=0.05, size=ref.shape)
    ours = procrustes_align(ref, cand, scale=False)[0]
    x = cand[0] - cand[0].mean(0)
    y = ref[0] - ref[0].mean(0)
    rot, _ = scipy.linalg.orthogonal_procrustes(x, y)
    np.testing.assert_allclose(ours, x @ rot + ref[0].mean(0), atol=1e-9)


def test_angle_between_precise_near_zero():
    assert angle_between([1, 0, 0], [1, 1e-9, 0]) == pytest.approx(np.degrees(1e-9), rel=1e-6)
    assert angle_between([1, 0, 0], [-1, 0, 0]) == pytest.approx(180.0)


def score_arm():
    return Score(
        symbols=(Symbol(0, 1, "right_arm", "forward", "middle"), Symbol(0, 2, "support", "place", "middle")),
        tempo=Fraction(60),
    )


def test_compare_movements_verdicts():
    score = score_arm()
    t = np.arange(26) / 25.0  # 1 beat = 1 s at 60 bpm; arrival at frame 25
    ref = arm_raise(np.clip(t, 0, 1))
    assert key_frames(score, 25, 26).tolist() == [25, 25]
    # Candidate arrives 0.4 s late (frame 35) at 25 fps.
    tc = np.arange(40) / 25.0
    cand = arm_raise(np.clip(tc / 1.4, 0, 1))
    res = compare_movements(score, ref, cand, pose_frames=[35, 35], arrival_frames=[35, 35], fps_ref=25, fps_cand=25)
    arm, sup = res
    assert arm.agree and arm.cand_direction == "forward" and arm.cand_level == "middle"
    assert arm.timing_offset == pytest.approx(0.4)
    assert arm.verdict == "late"
    assert arm.angle_error == pytest.approx(0.0, abs=1e-6)
    assert sup.verdict == "n/a"
    # Read at frame 20 (arm at 57°, elevation −33°: level low) the symbol disagrees.
    res = compare_movements(score, ref, cand, [20, 20], [25, 25], 25, 25)
    assert res[0].verdict == "pose" and res[0].cand_level == "low"
    assert res[0].pose_error == pytest.approx(90 - 90 * 20 / 35, abs=0.5)
    table = agreement_by_part(res)
    assert table == {"right_arm": {"n": 1, "agree": 0, "bend_agree": 0, "fraction": 0.0}}


def test_effort_differences_interval():
    d = effort_differences(
        {"time": (-3.0, -3.4, -2.6), "weight": (0.5, 0.5, 0.5)},
        {"time": (-2.4, -2.5, -2.3), "weight": (0.4, 0.35, 0.45)},
    )
    assert d["time"]["difference"] == pytest.approx(-0.6)
    assert (d["time"]["lo"], d["time"]["hi"]) == pytest.approx((-1.1, -0.1))
    assert not d["time"]["consistent"]
    assert d["weight"]["consistent"] is False and d["weight"]["lo"] == pytest.approx(0.05)


# --- windowed, open-ended alignment (c2n score) -----------------------------------------------


def _phrase_joints(seed=1, beats=12, fps=25.0):
    from synthetic import random_score
    from synthetic.interpret import interpret

    return interpret(random_score(np.random.default_rng(seed), n_beats=beats), fps=fps).joints()


def test_windowed_alignment_of_a_performance_with_itself_is_the_diagonal():
    from capture2notation.compare.align import align_performances

    j = _phrase_joints()
    al = align_performances(j, j, 25.0)
    np.testing.assert_array_equal(al.path, np.stack([np.arange(len(j))] * 2, axis=1))
    assert al.cost == 0.0 and al.ref_span == (0, len(j) - 1) and al.cand_span == (0, len(j) - 1)


@pytest.mark.parametrize("shift_s", [1.0, -1.0, 1.8])
def test_windowed_alignment_finds_a_time_shift(shift_s):
    from capture2notation.compare.align import align_performances

    j = _phrase_joints()
    k = int(round(abs(shift_s) * 25))
    cand = np.concatenate([np.repeat(j[:1], k, 0), j]) if shift_s > 0 else j[k:]
    al = align_performances(j, cand, 25.0)
    # Every reference frame after the shift lands exactly `k` frames later (earlier).
    moving = al.path[al.path[:, 0] >= k]
    np.testing.assert_array_equal(moving[:, 1] - moving[:, 0], np.sign(shift_s) * k)


def test_windowed_alignment_cannot_match_a_movement_far_outside_its_time():
    """The reference's phrase appears in the candidate only after 20 s of standing: far outside
    the window (2 s + 25 % of the elapsed time), so nothing of it is matched there."""
    from capture2notation.compare.align import MAX_DRIFT, MAX_LAG_S, align_performances

    j = _phrase_joints()
    cand = np.concatenate([np.repeat(j[:1], 500, 0), j])
    al = align_performances(j, cand, 25.0)
    t_ref, t_cand = al.path[:, 0] / 25.0, al.path[:, 1] / 25.0
    assert np.all(np.abs(t_cand - t_ref) <= MAX_LAG_S + MAX_DRIFT * t_ref + 1 / 25.0)
    assert al.cand_span[1] < 500  # the copy of the phrase (frames 500 on) stays unmatched


def test_windowed_alignment_decimates_fast_sources_without_moving_the_match():
    from capture2notation.compare.align import align_performances

    j = _phrase_joints(fps=100.0)
    cand = np.concatenate([np.repeat(j[:1], 100, 0), j])  # 1 s at 100 Hz
    al = align_performances(j, cand, 100.0)
    moving = al.path[al.path[:, 0] >= 100]
    assert np.all(np.abs(moving[:, 1] - moving[:, 0] - 100) <= 2)  # within the 40-ms decimation


def test_tempo_alignment_leaves_beats_the_candidate_never_reaches_unmatched():
    al = align_tempo(100, 30, ref_tempo=60, cand_tempo=60, fps_ref=25, fps_cand=25)
    assert al.ref_span == (0, 29) and not al.matched([30])[0] and al.matched([29])[0]
