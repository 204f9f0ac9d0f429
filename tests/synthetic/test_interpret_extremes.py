"""Paths within the joint extremes and Euler tracks through gimbal lock."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, euler_to_matrix, joint_index
from capture2notation.notation import Effort, Score, Symbol
from synthetic.extremes import continuous_at_lock, keep_paths_within, nearest_at_lock
from synthetic.interpret import interpret
from synthetic.phrases import phrase

BODY = Body()
HIP = joint_index("left_hip")
LIM = BODY.limits[HIP]


@settings(max_examples=40, deadline=None)
@given(k=st.floats(-1.0, 1.0), ref=st.tuples(*[st.floats(-1.5, 1.5)] * 3), sign=st.sampled_from([1.0, -1.0]))
def test_nearest_at_lock_keeps_the_rotation(k, ref, sign):
    e = np.array([k, sign * np.pi / 2, 0.0])
    near = nearest_at_lock(e, np.array(ref), LIM)
    assert np.allclose(euler_to_matrix(near), euler_to_matrix(e), atol=1e-9)
    # Off the lock, the triple is returned unchanged.
    off = np.array([k, 0.3, 0.2])
    assert np.array_equal(nearest_at_lock(off, np.array(ref), LIM), off)


def test_keep_paths_within_straightens_a_path_that_leaves_the_box():
    T = 11
    angles = np.zeros((T, len(JOINTS), 3))
    # Both ends inside the left hip's box; the way out of it in rz.
    angles[:, HIP] = np.radians([90.0, 0.0, 0.0])
    angles[1:-1, HIP, 2] = np.radians(np.linspace(10, 90, T - 2))
    angles[-1, HIP] = np.radians([0.0, 90.0, 0.0])
    ends = angles[[0, -1], HIP].copy()
    sym = Symbol(0, 1, "left_leg", "left", "middle")
    keep_paths_within(angles, BODY, [(sym, 0, T - 1)], Effort(-2.0, 0.5, 1.0))
    a = angles[:, HIP]
    assert np.all(a >= LIM[:, 0] - 1e-12) and np.all(a <= LIM[:, 1] + 1e-12)
    assert np.allclose(euler_to_matrix(a[[0, -1]]), euler_to_matrix(ends), atol=1e-9)
    # A path inside the extremes is left alone.
    inside = np.zeros((T, len(JOINTS), 3))
    inside[:, HIP, 0] = np.radians(np.linspace(0, 90, T))
    before = inside.copy()
    keep_paths_within(inside, BODY, [(sym, 0, T - 1)], Effort(-2.0, 0.5, 1.0))
    assert np.array_equal(inside, before)


def test_euler_tracks_stay_continuous_through_the_hip_lock():
    m = interpret(phrase("figure7"), 25.0)
    a = m.angles[:, HIP]
    assert np.abs(np.abs(a[:, 1]) - np.pi / 2).min() < 1e-4  # the leg passes the lock
    assert np.degrees(np.abs(np.diff(a, axis=0))).max() < 20.0  # no jump in the numbers
    locked = np.zeros_like(m.angles)
    locked[:, HIP] = a
    copy = locked.copy()
    continuous_at_lock(copy, BODY)
    assert np.allclose(euler_to_matrix(copy[:, HIP]), euler_to_matrix(a), atol=1e-9)


@pytest.mark.parametrize("fps", [25.0, 12.5])
def test_chest_beyond_its_extremes_approaches_until_the_end(fps):
    """``chest forward middle`` is at the waist's and chest's extremes: the
    chest still moves on the frame before the end (it is not reached early
    and held), and arrives reading forward middle."""
    syms = (Symbol(0, 1, "chest", "forward", "middle"), Symbol(0, 1, "head", "forward", "middle"))
    m = interpret(Score(syms, tempo=60), fps)
    w, c = joint_index("waist"), joint_index("chest")
    f1 = m.events[0][2]
    assert not np.allclose(m.angles[f1 - 1, [w, c]], m.angles[f1, [w, c]], atol=1e-6)
