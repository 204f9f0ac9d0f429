"""Segmentation of forward-kinematics motions into symbols (no virtual dancer needed)."""

from __future__ import annotations

from fractions import Fraction as F

import numpy as np
import pytest
from quantise_motions import arm_angles, build_motion

from capture2notation.body import Body
from capture2notation.compare.agreement import compare_scores, score_differences
from capture2notation.errors import QuantiseError
from capture2notation.notation.model import LEVELS, Score, Symbol
from capture2notation.quantise.segment import SegmentParams, segment, segment_motion
from capture2notation.quantise.spans import movement_spans

TEMPO = 64
# An arm phrase: out to forward middle, up to forward high over half a beat,
# straight on (no pause) to the right, a pause, and down again over two beats.
MOVES = [
    (1, 1, "right_shoulder", arm_angles("forward", "middle")),
    (2, F(1, 2), "right_shoulder", arm_angles("forward", "high")),
    (F(5, 2), 1, "right_shoulder", arm_angles("right", "middle")),
    (5, 2, "right_shoulder", np.zeros(3)),
    (F(3, 2), F(3, 2), "left_shoulder", arm_angles("left_forward", "low")),
    (2, 1, "neck", np.radians((-45.0, 0.0, 0.0))),  # rx < 0 tips an upright segment forward
]
EXPECTED = Score(
    symbols=(
        Symbol(1, 1, "right_arm", "forward", "middle"),
        Symbol(2, F(1, 2), "right_arm", "forward", "high"),
        Symbol(F(5, 2), 1, "right_arm", "right", "middle"),
        Symbol(5, 2, "right_arm", "place", "low"),
        Symbol(F(3, 2), F(3, 2), "left_arm", "left_forward", "low"),
        Symbol(2, 1, "head", "forward", "high"),
    ),
    tempo=TEMPO,
)


def _gestures(score):
    return Score(symbols=tuple(s for s in score.symbols if not s.is_support), tempo=score.tempo)


@pytest.mark.parametrize("fps", [25.0, 30.0, 50.0])
@pytest.mark.parametrize("effort", [(-2.0, 0.5), (-4.0, 0.35), (-2.4, 0.7)])
def test_clean_motion_captures_exactly_its_symbols(fps, effort):
    joints, _ = build_motion(MOVES, TEMPO, fps=fps, b=effort[0], x0=effort[1])
    score = segment(joints, fps, tempo=TEMPO)
    assert score_differences(EXPECTED, _gestures(score)) == []
    # Standing still on both feet throughout: the starting pose, no support symbol.
    assert not [s for s in score.symbols if s.is_support]


def test_elbow_only_movement_is_a_forearm_symbol():
    moves = [
        (1, 1, "right_shoulder", arm_angles("forward", "middle")),
        (3, 1, "right_elbow", np.radians((90.0, 0.0, 0.0))),
    ]
    joints, _ = build_motion(moves, 60)
    score = _gestures(segment(joints, 25.0, tempo=60))
    assert [(s.start, s.duration, s.part, s.direction, s.level) for s in score.symbols] == [
        (
            1,
            1,
            "right_arm",
            "forward",
            "middle",
        ),
        (3, 1, "right_forearm", "place", "high"),
    ]


def test_bent_whole_arm_carries_its_bend_degree():
    # Forward middle with the elbow bent 60°: the upper arm is lowered by the
    # angle gamma between it and the shoulder → wrist line.
    body = Body()
    l1, l2 = body.segment_length("right_shoulder", "right_elbow"), body.segment_length("right_elbow", "right_wrist")
    beta = np.radians(60.0)
    gamma = np.arctan2(l2 * np.sin(beta), l1 + l2 * np.cos(beta))
    moves = [(1, 1, "right_shoulder", (np.pi / 2 - gamma, 0, 0)), (1, 1, "right_elbow", (beta, 0, 0))]
    joints, _ = build_motion(moves, 60)
    (s,) = _gestures(segment(joints, 25.0, tempo=60)).symbols
    assert (s.part, s.direction, s.level, s.bend, s.start, s.duration) == ("right_arm", "forward", "middle", 2, 1, 1)


def test_noisy_motion_still_agrees():
    rng = np.random.default_rng(7)
    joints, _ = build_motion(MOVES, TEMPO)
    noisy = joints + rng.normal(0.0, 0.008, joints.shape)  # 8 mm per coordinate
    seg = segment_motion(noisy, 25.0, tempo=TEMPO)
    a = compare_scores(EXPECTED, _gestures(seg.score), step=F(1, 4))
    assert a.symbol_agreement >= 0.9
    assert a.unmatched <= 1
    assert a.median_start_error <= 0.25


def test_estimated_tempo_recovers_the_written_one():
    joints, _ = build_motion(MOVES, TEMPO)
    seg = segment_motion(joints, 25.0)
    assert seg.tempo_estimated
    assert seg.tempo == TEMPO
    assert score_differences(EXPECTED, _gestures(seg.score)) == []


def test_key_frames_are_the_arrivals():
    joints, _ = build_motion(MOVES, TEMPO)
    seg = segment_motion(joints, 25.0, tempo=TEMPO)
    spb = 60 / TEMPO
    arrivals = sorted({round(float(s.end) * spb * 25) for s in EXPECTED.symbols})
    assert seg.key_frames[0] == 0
    for f in arrivals:
        assert np.min(np.abs(seg.key_frames - f)) <= 1


def test_movement_spans_hysteresis_and_split():
    s = np.zeros(40)
    s[5:10] = [1, 30, 60, 30, 1]  # one movement
    s[20:31] = [2, 40, 80, 40, 5, 0.5, 5, 40, 80, 40, 2]  # two back to back
    s[35] = 15  # a blip below the peak threshold
    spans = movement_spans(s, low=3.0, high=20.0, split_ratio=0.35)
    # Split at the 0.5 minimum; each movement keeps where it exceeds 10 % of its peak.
    assert spans == [(6, 8), (21, 23), (27, 29)]


def test_movement_spans_on_clean_motion_cut_at_written_poses():
    s = np.zeros(20)
    s[2:12] = [1e-3, 5, 20, 30, 20, 6, 0.5, 25, 30, 10]
    calls = []

    def key(f, since):
        calls.append(f)
        return f == 8  # the pose after interval 7 is written

    key.on_grid = True
    assert movement_spans(s, low=1e-4, high=2e-4, split_ratio=0.35, key_pose=key) == [(2, 7), (8, 11)]
    assert 8 in calls


def test_a_written_pose_passed_on_a_grid_frame_ends_a_movement_only_where_the_speed_kinks():
    """Clean motion: two progress curves meet with a jump in the speed's slope; one curve sweeps on smoothly."""
    from capture2notation.notation.effort import progress

    def curve(frames, degrees):
        """Speed (degrees per second at 25 fps) over each interval of one movement's progress curve."""
        return np.diff(progress(np.linspace(0.0, 1.0, frames + 1), -3.0, 0.45)) * degrees * 25.0

    one = curve(30, 180.0)  # one sweep of 180° over 30 frames
    two = np.r_[curve(15, 135.0), curve(15, 45.0)]  # 135° then 45°, back to back
    pad = np.zeros(3)

    def key_at(frame):
        def key(f, since):
            return f == frame

        key.on_grid = True
        return key

    # The sweep passes a written pose at frame 3 + 15 without a kink: one movement.
    smooth = np.r_[pad, one, pad]
    assert movement_spans(smooth, low=1e-4, high=2e-4, split_ratio=0.35, key_pose=key_at(18)) == [(3, 32)]
    # A movement ends at frame 18 and the next starts there from rest: two.
    met = np.r_[pad, two, pad]
    assert movement_spans(met, low=1e-4, high=2e-4, split_ratio=0.35, key_pose=key_at(18)) == [(3, 17), (18, 32)]


def test_too_short_or_bad_input():
    with pytest.raises(QuantiseError, match="at least 2 frames"):
        segment(np.zeros((1, 21, 3)), 25.0, tempo=60)
    joints, _ = build_motion(MOVES[:1], 60)
    with pytest.raises(QuantiseError, match="tempo"):
        segment(joints, 25.0, tempo=-3)


def test_still_motion_gives_an_empty_score():
    joints, _ = build_motion([(1, 1, "right_shoulder", np.zeros(3))], 60)
    score = segment(joints, 25.0, tempo=60, params=SegmentParams())
    assert score.symbols == ()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_noisy_movements_start_on_their_beats_and_keep_the_tempo(seed):
    """8 mm of jitter: the speed threshold alone started movements a quarter
    beat late and read 64 bpm as about 100; the fitted logistic puts starts
    on their beats and the estimate within 2 bpm."""
    rng = np.random.default_rng(seed)
    joints, _ = build_motion(MOVES, TEMPO)
    noisy = joints + rng.normal(0.0, 0.008, joints.shape)
    a = compare_scores(EXPECTED, _gestures(segment_motion(noisy, 25.0, tempo=TEMPO).score))
    assert a.median_start_error == 0.0 and a.unmatched == 0
    seg = segment_motion(noisy, 25.0)
    assert seg.tempo_estimated and abs(seg.tempo - TEMPO) <= 2
    # Compared in time, the estimated-tempo score still agrees per beat.
    assert compare_scores(EXPECTED, _gestures(seg.score)).symbol_agreement >= 0.9


def test_smooth_measured_motion_is_not_taken_for_the_dancer_truth():
    """A fit can be smoother than the clean-motion jitter limit (0.05°/frame)
    yet never exactly still: it must take the measured path (fitted timing,
    contacts from smoothed feet), not wait for exactly written poses."""
    from capture2notation.quantise.gestures import has_exact_holds as _has_exact_holds
    from capture2notation.quantise.labels import label_frames

    joints, _ = build_motion(MOVES, TEMPO)
    assert _has_exact_holds(label_frames(joints, 25.0), joints)
    smooth = joints + np.random.default_rng(0).normal(0.0, 1e-5, joints.shape)  # 0.01 mm
    assert not _has_exact_holds(label_frames(smooth, 25.0), smooth)
    a = compare_scores(EXPECTED, _gestures(segment_motion(smooth, 25.0, tempo=TEMPO).score))
    assert a.symbol_agreement == 1.0 and a.unmatched == 0 and a.median_start_error == 0.0


def test_quick_measured_movement_that_holds_is_kept():
    """Half a beat at 96 bpm straight after another movement: the fitted
    logistic makes it 0.17 s, under the glitch limit, and it was dropped
    although the arm then holds its new pose for two beats (a whole-path
    phrase lost a fifth of its cells).  A glitch swings and comes back."""
    moves = [
        (0, 1, "right_shoulder", arm_angles("right", "middle")),
        (1, F(1, 2), "right_shoulder", arm_angles("forward", "middle")),
        (4, 1, "right_shoulder", np.zeros(3)),
    ]
    expected = Score(
        symbols=(
            Symbol(0, 1, "right_arm", "right", "middle"),
            Symbol(1, F(1, 2), "right_arm", "forward", "middle"),
            Symbol(4, 1, "right_arm", "place", "low"),
        ),
        tempo=96,
    )
    # A sudden Effort: the fitted reference logistic is quickest on it.
    joints, _ = build_motion(moves, 96, b=-4.0, x0=0.35)
    agree = []
    for seed, sigma in ((0, 0.008), (1, 0.008), (1, 0.015), (2, 0.015)):
        noisy = joints + np.random.default_rng(seed).normal(0.0, sigma, joints.shape)
        a = compare_scores(expected, _gestures(segment_motion(noisy, 25.0, tempo=96).score))
        agree.append(a.symbol_agreement)
        assert a.unmatched == 0
    assert np.mean(agree) >= 0.95


def _pitch_toes(joints: np.ndarray, deg: float) -> np.ndarray:
    """Joints with both toes pitched `deg` further down about their ankles (toes kept on the floor)."""
    from scipy.spatial.transform import Rotation

    from capture2notation.body import joint_index

    out = joints.copy()
    for side in ("right", "left"):
        a, t = joint_index(f"{side}_ankle"), joint_index(f"{side}_toe")
        d = out[:, t] - out[:, a]
        # Pitch down about the horizontal axis across the foot (z × foot: toe down).
        axis = np.cross([0.0, 0.0, 1.0], d)
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        out[:, t] = out[:, a] + Rotation.from_rotvec(axis * np.radians(deg)).apply(d)
    # A fitted foot still stands on the floor: raise the body onto its toes.
    lift = joints[:, joint_index("right_toe"), 2] - out[:, joint_index("right_toe"), 2]
    return out + lift[:, None, None] * np.array([0.0, 0.0, 1.0])


def test_measured_flat_feet_pitched_down_are_not_releve():
    """A front-view fit pitches flat feet 10-20° further down than the body
    model's rest pose (13-24° over 32 whole-path clips): measured against the
    model's pitch every standing frame read as relevé (``support place high``
    written at beat 0 of Wolofsky's Figure 7).  The relevé threshold is taken
    from the capture's own flat feet."""
    # The left leg gestures forward and back: the right foot alone supports, then both.
    joints, _ = build_motion(
        [(1, 1, "left_hip", np.radians((40.0, 0.0, 0.0))), (3, 1, "left_hip", np.zeros(3))], 60, beats=5
    )
    for bias in (12.0, 18.0):
        noisy = _pitch_toes(joints, bias) + np.random.default_rng(0).normal(0.0, 0.005, joints.shape)
        seg = segment_motion(noisy, 25.0, tempo=60)
        levels = seg.labels.support_level[seg.labels.supporting]
        # Every frame of a supporting foot stands flat: middle level.
        assert levels.size > 0.6 * seg.labels.supporting.size  # the left foot is lifted 2 beats of 5
        assert (levels == LEVELS.index("middle")).all()
        assert not [x for x in seg.score.symbols if x.is_support and x.level == "high"]
        assert [(x.part, x.direction, x.level) for x in seg.score.symbols if not x.is_support] == [
            ("left_leg", "forward", "low")
        ]


def test_flat_foot_pitch_is_the_lower_decile_of_contacts():
    from capture2notation.quantise.labels import flat_foot_pitch, support_frames

    high, middle = LEVELS.index("high"), LEVELS.index("middle")

    joints, _ = build_motion([(1, 1, "right_shoulder", arm_angles("right", "middle"))], 60, beats=4)
    biased = _pitch_toes(joints, 15.0)
    contact, _ = support_frames(biased, 25.0)
    flat = flat_foot_pitch(biased, contact)
    rest = flat_foot_pitch(joints, contact)
    np.testing.assert_allclose(flat - rest, 15.0, atol=0.5)
    # Raised 20° from the capture's own flat foot is relevé; the model's rest pitch reads it all as relevé.
    raised = _pitch_toes(joints, 35.0)
    assert (support_frames(raised, 25.0, flat_pitch=flat)[1] == high).all()
    assert (support_frames(biased, 25.0, flat_pitch=flat)[1] == middle).all()
    assert (support_frames(biased, 25.0)[1] == high).all()


def test_key_times_chained_over_half_a_second_do_not_collapse_a_flight():
    """Found on a fresh render (seed 98210): six parts arriving 0.08 s apart
    chained every key time from the take-off to the landing into one group
    of the merge window, so the flight got a zero span and its landing
    support overlapped it (the capture raised NotationError)."""
    from capture2notation.notation.model import Score
    from capture2notation.quantise.movement import Movement
    from capture2notation.quantise.params import SegmentParams
    from capture2notation.quantise.segment import _merge_times, _symbols

    fps, tempo = 25.0, F(62)
    moves = [
        Movement("support", 24, 36, 0.96, 1.44, "air", ""),
        Movement("right_support", 36, 86, 1.44, 3.44, "place", "middle"),
    ]
    parts = ["right_arm", "left_arm", "head", "chest", "right_leg", "left_leg"]
    for k, part in enumerate(parts):
        t = 1.0 + 0.08 * k
        moves.append(Movement(part, int(t * fps) - 10, int(t * fps), t - 0.4, t, "forward", "middle"))
    merged = _merge_times(moves, SegmentParams(), float(tempo))
    window = 0.45 * float(SegmentParams().grid) * 60.0 / float(tempo)
    for m in merged:
        assert m.end_time > m.start_time
    flight = next(m for m in merged if m.direction == "air")
    assert flight.end_time - flight.start_time > window
    Score(symbols=tuple(_symbols(merged, tempo, SegmentParams().grid)), tempo=tempo)  # valid: no overlap


def test_flight_and_one_foot_support_snapped_onto_each_other_do_not_overlap():
    from capture2notation.notation.model import Score
    from capture2notation.quantise.movement import Movement
    from capture2notation.quantise.segment import _symbols

    # the support's start and the flight's end snap to different beats
    moves = [
        Movement("support", 0, 10, 1.00, 1.12, "air", ""),
        Movement("left_support", 8, 40, 1.05, 2.0, "place", "middle"),
    ]
    syms = _symbols(moves, F(60), F(1, 4))
    air, sup = syms
    assert sup.start >= air.end
    Score(symbols=tuple(syms), tempo=F(60))
