"""Joints no two cameras saw, filled from one view's fit (:mod:`capture2notation.fitting.multiview`)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.fitting.multiview import (
    FILL_CONTEXT_S,
    MONO_WEIGHT,
    fill_from_view,
    fill_view,
    fill_windows,
    filled,
)

#: Metres: a one-view fit's error along its line of sight (its depth comes
#: from the body's size), the case the fill must not carry over.
DEPTH_ERROR_M = 0.12


def _standing(T: int, rng: np.random.Generator) -> np.ndarray:
    return np.repeat(Body().rest[None], T, axis=0) + rng.normal(0.0, 0.003, (T, len(JOINTS), 3))


def test_a_monocular_fill_lands_on_the_triangulated_body_not_at_its_own_depth():
    rng = np.random.default_rng(3)
    T = 20
    truth = _standing(T, rng)
    left_arm = [joint_index(n) for n in ("left_shoulder", "left_elbow", "left_wrist", "left_hand_tip")]
    joints, jconf = truth.copy(), np.ones((T, len(JOINTS)))
    joints[:, left_arm], jconf[:, left_arm] = np.nan, 0.0  # the side camera cannot see the far arm
    missing = jconf == 0
    # The front camera's own fit: the right shape, 12 cm too far away, and
    # above the floor by the `floor` the triangulated joints were moved by.
    floor = 0.05
    mono = SimpleNamespace(
        joints=truth + np.array([0.0, DEPTH_ERROR_M, floor]) + rng.normal(0.0, 0.005, truth.shape),
        confidence=np.full((T, len(JOINTS)), 0.9),
    )
    out, conf = filled(joints, jconf, missing, mono, floor)
    err = np.linalg.norm(out[:, left_arm] - truth[:, left_arm], axis=-1)
    # The shape's own noise (5 mm per coordinate), not the fit's depth.
    assert np.median(err) < 0.015 and err.max() < 0.03
    np.testing.assert_array_equal(out[~missing], joints[~missing])
    np.testing.assert_allclose(conf[missing], MONO_WEIGHT * 0.9)


def test_a_frame_with_nothing_triangulated_keeps_the_monocular_fit():
    rng = np.random.default_rng(4)
    truth = _standing(3, rng)
    joints, jconf = np.full_like(truth, np.nan), np.zeros(truth.shape[:2])
    mono = SimpleNamespace(joints=truth + 0.1, confidence=np.ones(truth.shape[:2]))
    out, _ = filled(joints, jconf, jconf == 0, mono, 0.0)
    np.testing.assert_allclose(out, truth + 0.1)


def test_the_fill_comes_from_the_view_that_sees_the_missing_joints():
    T = 5
    missing = np.zeros((T, len(JOINTS)), bool)
    missing[:, joint_index("left_wrist")] = True
    front, side = np.ones((T, 33)), np.ones((T, 33))
    side[:, 15] = 0.0  # BlazePose's left wrist, hidden from the side
    assert fill_view([side, front], missing) == 1


def test_the_monocular_fit_covers_the_missing_frames_and_a_second_about_them():
    fps, T = 25.0, 400
    missing = np.zeros((T, len(JOINTS)), bool)
    missing[100:104, joint_index("left_wrist")] = True
    missing[130:131, joint_index("left_elbow")] = True  # within a second of the first run: merged
    missing[390:, joint_index("right_ankle")] = True  # at the clip's end: clipped
    pad = int(np.ceil(FILL_CONTEXT_S * fps))
    assert fill_windows(missing, fps) == [slice(100 - pad, 131 + pad), slice(390 - pad, T)]
    windows = fill_windows(missing, fps)
    covered = np.zeros(T, bool)
    for w in windows:
        covered[w] = True
    assert covered[missing.any(axis=1)].all()
    assert fill_windows(np.zeros((T, len(JOINTS)), bool), fps) == []


def test_the_fill_fits_only_the_chosen_view_over_its_windows():
    rng = np.random.default_rng(5)
    fps, T = 25.0, 300
    truth = _standing(T, rng)
    wrist = joint_index("left_wrist")
    missing = np.zeros((T, len(JOINTS)), bool)
    missing[150:153, wrist] = True
    joints, jconf = truth.copy(), np.ones((T, len(JOINTS)))
    joints[missing], jconf[missing] = np.nan, 0.0
    front, side = np.ones((T, 33)), np.ones((T, 33))
    side[:, 15] = 0.0  # BlazePose's left wrist, hidden from the side
    calls = []

    def fit_window(view, frames):
        calls.append((view, frames))
        return SimpleNamespace(joints=truth[frames], confidence=np.full((frames.stop - frames.start, len(JOINTS)), 0.8))

    view, out, conf = fill_from_view(joints, jconf, missing, 0.0, [side, front], fps, fit_window)
    assert view == 1
    assert calls == [(1, w) for w in fill_windows(missing, fps)] and len(calls) == 1
    np.testing.assert_allclose(out[missing], truth[missing], atol=0.02)
    np.testing.assert_array_equal(out[~missing], joints[~missing])
    np.testing.assert_allclose(conf[missing], MONO_WEIGHT * 0.8)
