"""Measured-motion labels that must not flip on a few degrees of fit error.

A slightly different drawing of the same dancer moves fitted limb
directions by 3-6°; symbols decided by one frame, or by a pose a degree
past a sector or bend boundary, flipped with it.  Truth-like motions with a
fit's correlated wobble and bias added; no BlazePose.
"""

from __future__ import annotations

import numpy as np
from quantise_motions import arm_angles, build_motion
from scipy.ndimage import gaussian_filter1d

from capture2notation.body import JOINTS, joint_index
from capture2notation.compare.agreement import normalise
from capture2notation.quantise.measured import hold_frames, keep_previous
from capture2notation.quantise.segment import segment_motion

FPS = 25.0


def _correlated(shape, sigma_m, seed, width_frames=4.0):
    rng = np.random.default_rng(seed)
    n = gaussian_filter1d(rng.normal(0.0, 1.0, shape), width_frames, axis=0)
    return n * (sigma_m / n.std())


def test_a_bend_just_past_its_band_keeps_the_previous_bend_degree():
    """An arm to the side with the elbow bent 12° (bend 0), then lowered with
    it at 17-18° (just past the 15° boundary of bend 1): the fit's few
    degrees, not a new bend — one arm symbol's bend flipped between renders."""
    moves = [
        (1, 1, "right_shoulder", arm_angles("right", "middle")),
        (1, 1, "right_elbow", np.radians([12.0, 0.0, 0.0])),
        (3, 1, "right_shoulder", arm_angles("right", "low")),
        (3, 1, "right_elbow", np.radians([18.0, 0.0, 0.0])),
    ]
    joints, _ = build_motion(moves, 72, beats=6)
    for seed in (0, 1):
        noisy = joints + _correlated(joints.shape, 0.004, seed)
        arm = [
            (s.direction, s.level, s.bend)
            for s in normalise(segment_motion(noisy, FPS, tempo=72).score).symbols
            if s.part == "right_arm"
        ]
        assert arm == [("right", "middle", 0), ("right", "low", 0)], arm


def test_a_fit_settling_on_one_foot_in_the_first_frames_writes_no_support():
    """The first fitted frames put the weight on one foot (the other floats
    a few centimetres, the pelvis leans over the first) and settle on both
    within a quarter of a second: that was written as ``left_support`` at
    beat 0, standing for the whole phrase in the comparison."""
    tempo = 64.0
    moves = [(1, 1, "right_shoulder", arm_angles("right", "middle")), (3, 1, "right_shoulder", np.zeros(3))]
    joints, _ = build_motion(moves, tempo, beats=5)
    T = len(joints)
    fade = np.clip(1.0 - np.arange(T) / 7.0, 0.0, 1.0)
    right_foot = [joint_index(n) for n in ("right_ankle", "right_toe")]
    settled = joints.copy()
    settled[:, right_foot, 2] += 0.06 * fade[:, None]
    body = [j for j in range(len(JOINTS)) if j not in right_foot and not JOINTS[j].startswith("left_")]
    left_x = joints[0, joint_index("left_ankle"), 0] - joints[0, joint_index("pelvis"), 0]
    settled[:, body, 0] += left_x * fade[:, None]
    for seed in (0, 1):
        noisy = settled + _correlated(joints.shape, 0.004, seed)
        sup = [s for s in normalise(segment_motion(noisy, FPS, tempo=tempo).score).symbols if s.is_support]
        assert sup == [], sup


def test_hysteresis_keeps_a_label_only_near_its_boundary():
    """Within the margin of the previous sector the previous label stays; well inside another, it changes."""
    az = np.radians(-25.0)  # 2.5° past forward high's boundary at −22.5°
    v = np.array([np.sin(az) * np.cos(np.pi / 4), np.cos(az) * np.cos(np.pi / 4), np.sin(np.pi / 4)])
    assert keep_previous(v, np.nan, ("left_forward", "high", 0), ("forward", "high", 0)) == ("forward", "high", 0)
    az = np.radians(-40.0)
    v = np.array([np.sin(az) * np.cos(np.pi / 4), np.cos(az) * np.cos(np.pi / 4), np.sin(np.pi / 4)])
    assert keep_previous(v, np.nan, ("left_forward", "high", 0), ("forward", "high", 0)) == ("left_forward", "high", 0)
    assert keep_previous(v, 17.0, ("left_forward", "high", 1), ("left_forward", "high", 0))[2] == 0
    assert keep_previous(v, 25.0, ("left_forward", "high", 1), ("left_forward", "high", 0))[2] == 1


def test_a_fitted_arrival_past_the_next_start_reads_the_hold_before_it():
    """The logistic's arrival overshooting into a chained movement left a one-frame hold."""
    assert hold_frames(72, 62, 70, 10, 200) == slice(62, 71)
    assert hold_frames(50, 48, 200, 10, 200) == slice(50, 60)
    assert hold_frames(198, 196, 200, 10, 200) == slice(197, 200)
