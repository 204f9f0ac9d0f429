"""Flight in the capture: ``support air`` where both feet leave the floor, and its landing."""

from __future__ import annotations

import numpy as np

import synthetic.random_scores as random_scores
from capture2notation.compare.agreement import score_differences
from capture2notation.notation.facing import springs
from capture2notation.notation.formats import loads
from capture2notation.quantise.flight import find_flights
from capture2notation.quantise.segment import segment_motion
from synthetic.interpret import interpret

FPS = 25.0


def test_random_springs_round_trip():
    # Reference: the written scores themselves.  Over seeds 101-110, 8 of 10
    # come back exact (the misses: a leap's back leg timed from the
    # take-off, a one-foot take-off read as two feet).
    exact, flights, found = 0, 0, 0
    for seed in range(101, 111):
        score = random_scores.random_score(np.random.default_rng(seed), n_beats=8, springs=True)
        seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo)
        exact += not score_differences(score, seg.score)
        written = [s for s, _ in springs(score)]
        flights += len(written)
        found += sum(s in set(seg.score.symbols) for s in written)
    assert exact >= 7
    assert flights >= 5 and found == flights


def _spring_frames(seed: int = 105):
    """A random score with springs, the dancer's joints, and each flight's (take-off, touchdown) frames."""
    score = random_scores.random_score(np.random.default_rng(seed), n_beats=8, springs=True)
    joints = interpret(score, fps=FPS).joints()
    frame = lambda b: int(np.floor(float(b) * 60 / float(score.tempo) * FPS + 0.5))  # noqa: E731
    return score, joints, [(frame(s.start), frame(s.end)) for s, _ in springs(score)]


def test_flights_need_both_feet_up_and_a_falling_pelvis():
    _, joints, want = _spring_frames()
    assert want and find_flights(joints, FPS, measured=False) == want
    # Lift the whole body steadily by 5 cm a frame: both feet leave the floor,
    # but nothing falls: no flight.
    lifted = joints + np.linspace(0.0, 2.0, len(joints))[:, None, None] * np.array([0.0, 0.0, 1.0])
    assert find_flights(lifted, FPS, measured=False) == []


def test_no_flight_in_walking():
    score = random_scores.random_score(np.random.default_rng(7), n_beats=8, travel=True)
    seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo)
    assert not any(s.is_air for s in seg.score.symbols)


def _pelvis_track(z: np.ndarray) -> np.ndarray:
    """(T, J, 3) joints with only the pelvis height set (what the flight test reads)."""
    from capture2notation.body import JOINTS, joint_index

    joints = np.zeros((len(z), len(JOINTS), 3))
    joints[:, joint_index("pelvis"), 2] = z
    return joints


def test_a_fitted_flight_is_ballistic_by_its_rise_though_its_ends_are_smoothed():
    from capture2notation.quantise.flight import _ballistic

    fps, n = 25.0, 13  # a 0.48-s flight, take-off to touchdown
    t = np.arange(n) / fps
    free = 0.96 + 0.5 * 9.81 * t * (t[-1] - t)  # rises g D² / 8 = 0.28 m
    # The fitted pelvis of a rendered jump through BlazePose (random score
    # 20261401, frames 27-39): it rises 0.21 m, but the fit's temporal priors
    # round off take-off and touchdown (1.2 and -0.65 m/s where the free fall
    # has ±2.4), so the velocities alone say it falls at only 0.43 g.
    fitted = np.array([0.962, 1.01, 1.084, 1.121, 1.158, 1.171, 1.158, 1.151, 1.138, 1.076, 1.025, 0.984, 0.958])
    assert _ballistic(_pelvis_track(free), 0, n - 1, fps)
    assert _ballistic(_pelvis_track(fitted), 0, n - 1, fps)
    # Feet floating a few centimetres above a floor found low, the pelvis
    # level or gliding: no flight.
    assert not _ballistic(_pelvis_track(np.full(n, 0.95)), 0, n - 1, fps)
    assert not _ballistic(_pelvis_track(np.linspace(0.9, 0.96, n)), 0, n - 1, fps)


def test_a_fitted_flight_is_found_with_the_feet_floating_above_a_low_floor():
    """A single view's fitted feet float several centimetres above the clip's
    floor for seconds (measured on renders: 2-11 cm).  Against that one floor
    both feet never touch it, so no take-off or landing could be seen; each
    flight is judged against the floor the feet stand on about then, and its
    landing is written though no foot comes within 3 cm of the low floor."""
    from capture2notation.quantise.support_state import smooth_positions

    score, clean, want = _spring_frames()
    rng = np.random.default_rng(5)
    floating = clean + rng.normal(0.0, 0.005, clean.shape)
    # the body floats 8 cm up for 1.2 s either side of each flight (a depth
    # error of the fit), standing on the floor elsewhere
    t = np.arange(len(clean))
    near = np.zeros(len(clean))
    for a, b in want:
        near = np.maximum(near, np.clip(1.0 - np.maximum(a - t, t - b) / (1.2 * FPS), 0.0, 1.0) * 2.0)
    floating[..., 2] += 0.08 * np.minimum(near, 1.0)[:, None]
    got = find_flights(smooth_positions(floating, FPS), FPS, measured=True)
    assert len(got) == len(want)
    for (a, b), (a0, b0) in zip(got, want, strict=True):
        assert abs(a - a0) <= 3 and abs(b - b0) <= 3
    seg = segment_motion(floating, FPS, tempo=score.tempo)
    airs = [s for s in seg.score.symbols if s.is_air]
    assert len(airs) == len(want)
    for air in airs:  # each flight is followed by its landing support
        assert any(s.is_support and not s.is_air and s.start == air.end for s in seg.score.symbols)


def test_a_leg_gesturing_through_a_flight_arrives_after_the_landing():
    # Reference: the written score.  The right leg gestures from the
    # take-off until the landing comes to rest (synthetic.flight: the landing
    # absorbs in a dip below its height and rests at its end); the bottom of
    # that dip, where the pelvis slows too, is not where the weight arrives,
    # so the leg's movement is not cut there.
    text = """tempo: 100
0     2    support       place     low
2     7/4  right_leg     left_back low
2     1    support       air
3     3/4  left_support  back      low
15/4  3/2  support       place     middle
"""
    score = loads(text, "lab")
    seg = segment_motion(interpret(score, fps=FPS).joints(), FPS, tempo=score.tempo)
    assert score_differences(score, seg.score) == []


def test_a_flight_is_followed_through_a_foot_hidden_mid_air():
    # A spinning jump hides a foot for a few frames: the flight is still one
    # flight with its own take-off and touchdown (before, each hidden frame
    # cut it, and its pieces were too short to count).
    _, joints, want = _spring_frames()
    seen = np.ones((len(joints), 2), bool)
    for a, b in want:
        mid = (a + b) // 2
        seen[mid - 1 : mid + 1, 0] = False  # right foot hidden for two frames
        seen[mid + 1 : mid + 3, 1] = False  # then the left for two
    assert find_flights(joints, FPS, measured=False, seen=seen) == want


def test_an_unseen_foot_makes_no_flight_and_a_hidden_landing_is_not_flown_through():
    _, joints, want = _spring_frames()
    # Feet unseen where they stand: no airborne frame seen, no flight.
    standing = np.ones((len(joints), 2), bool)
    standing[: want[0][0] - 2] = False
    got = find_flights(joints, FPS, measured=False, seen=standing)
    assert all(b > want[0][0] for _, b in got)
    # Two hops whose landing between them is hidden: the pelvis does not fall
    # freely across the landing, so the gap is not bridged into one flight.
    t = np.arange(40) / FPS
    hop = lambda t0, t1: np.where((t >= t0) & (t <= t1), 0.5 * 9.81 * (t - t0) * (t1 - t), 0.0)  # noqa: E731
    lift = hop(0.2, 0.6) + hop(0.76, 1.16)
    two = np.repeat(joints[:1], len(t), axis=0).copy()
    two[..., 2] += lift[:, None]
    from capture2notation.body import joint_index

    seen = np.ones((len(t), 2), bool)
    seen[15:20] = False  # the landing at 0.6-0.76 s (frames 15-19) unseen,
    pelvis = two[15:20, joint_index("pelvis"), 2].copy()
    two[15:20, :, 2] += 0.06  # and its feet fitted clear of the floor
    two[15:20, joint_index("pelvis"), 2] = pelvis
    got = find_flights(two, FPS, measured=False, seen=seen)
    assert all(b - a < 15 for a, b in got) and len(got) == 2


def test_a_fitted_jump_is_found_though_its_feet_float_in_the_plies():
    """A single view's fitted feet can stand a few centimetres up in the
    plié before a take-off and after a landing (a hop of a render through
    BlazePose: 3.5-4 cm for half a second either side).  Both feet then stay
    clear from the plié to the landing's, over which the pelvis is not
    ballistic; the flight is found at its core, where the feet are highest."""
    from capture2notation.body import joint_index
    from capture2notation.quantise.flight import CORE_FRACTION, _core

    _, clean, want = _spring_frames()
    feet = [joint_index(f"{side}_{end}") for side in ("right", "left") for end in ("ankle", "toe")]
    floating = clean.copy()
    pad = int(0.5 * FPS)
    for a, b in want:
        floating[max(0, a - pad) : a + 1, feet, 2] += 0.04
        floating[b : b + pad, feet, 2] += 0.04
    got = find_flights(floating, FPS, measured=True)
    assert len(got) == len(want)
    for (a, b), (a0, b0) in zip(got, want, strict=True):
        # Inside the written flight, by at most the part of a free fall
        # below CORE_FRACTION of its height at either end.
        assert a0 <= a and b <= b0 and (b - a) >= (1.0 - CORE_FRACTION) ** 0.5 * (b0 - a0) - 2
    # The core is the run about the highest frame, not any other high stretch.
    assert _core(np.array([0.0, 0.9, 0.1, 0.6, 1.0, 0.8, 0.2])) == (3, 6)
