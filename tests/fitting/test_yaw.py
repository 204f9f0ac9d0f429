"""Turning a one-view fit to the yaw the image shows (:mod:`capture2notation.fitting.yaw`)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import Body, body_frame, forward_kinematics, front_of, joint_index
from capture2notation.errors import FittingError
from capture2notation.fitting import Camera, FitResult
from capture2notation.fitting.yaw import front_from_yaw, turned_to


def _result(synth, T=40, seed=3):
    body = Body()
    angles, root = synth.make_motion(T, seed, body=body)
    joints = forward_kinematics(angles, root, body)
    return FitResult(25.0, np.arange(T) / 25.0, joints, angles, root, np.ones(joints.shape[:2])), body


def test_facing_the_camera_is_the_front_towards_it():
    cam = Camera.default((640, 480))  # on +y, looking along -y
    got = front_from_yaw([0.0, 90.0, 180.0, 270.0], cam.R)
    # The image's right is the world's -x for this camera: front -90 (clockwise from +y).
    np.testing.assert_allclose(got, [0.0, -90.0, -180.0, -270.0], atol=1e-9)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-25.0, 25.0), min_size=2, max_size=30), st.floats(-10.0, 10.0))
def test_front_follows_the_yaw_step_for_step(steps, roll):
    # A camera rolled or not: the front turns by the yaw's steps the other way round.
    yaw = np.cumsum(np.r_[0.0, steps])
    front = front_from_yaw(yaw, Camera.default((640, 480), roll_deg=roll).R)
    np.testing.assert_allclose(np.diff(front), -np.diff(yaw), atol=1e-6)


def test_turned_body_faces_the_target_and_keeps_its_pose(synth):
    res, body = _result(synth)
    rng = np.random.default_rng(0)
    target = rng.uniform(-400.0, 400.0, res.n_frames)
    out = turned_to(res, target)
    front = front_of(body_frame(out.joints)[:, 1])
    np.testing.assert_allclose((front - target + 180.0) % 360.0 - 180.0, 0.0, atol=1e-6)
    # The pelvis stays; every limb keeps its place in the body's own frame.
    np.testing.assert_array_equal(out.root, res.root)
    rel = lambda r: np.einsum("tij,tkj->tki", body_frame(r.joints), r.joints - r.root[:, None])  # noqa: E731
    np.testing.assert_allclose(rel(out), rel(res), atol=1e-9)
    # The angles still give the joints.
    np.testing.assert_allclose(forward_kinematics(out.angles, out.root, body), out.joints, atol=1e-9)
    others = [i for i in range(out.angles.shape[1]) if i != joint_index("pelvis")]
    np.testing.assert_array_equal(out.angles[:, others], res.angles[:, others])


def test_missing_target_frames_are_left_alone(synth):
    res, _ = _result(synth, T=10)
    target = np.full(10, np.nan)
    target[3] = 90.0
    out = turned_to(res, target)
    keep = np.arange(10) != 3
    np.testing.assert_allclose(out.joints[keep], res.joints[keep], atol=1e-12)


def test_bad_shapes_are_refused(synth):
    res, _ = _result(synth, T=5)
    with pytest.raises(FittingError, match=r"front_deg must have shape \(5,\)"):
        turned_to(res, np.zeros(4))
    with pytest.raises(FittingError, match=r"R must have shape \(3, 3\)"):
        front_from_yaw([0.0], np.eye(2))
    down = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]])  # optical axis straight down
    with pytest.raises(FittingError, match="straight up or down"):
        front_from_yaw([0.0], down)


def test_the_image_yaw_is_sure_of_each_turn_on_exact_keypoints():
    # The virtual dancer's exact keypoints: the decoder's posterior, carried
    # on the turned fit, prefers each turn as read to its mirror image.
    from capture2notation.fitting.yaw import with_image_yaw
    from capture2notation.notation.model import SYMBOL_UNCERTAIN_BELOW
    from capture2notation.quantise.confidence import turn_probability
    from synthetic.identity_errors import truth_track
    from synthetic.interpret import interpret
    from synthetic.random_scores import random_score
    from synthetic.render.camera import Camera as RenderCamera
    from synthetic.render.job import truth_fields
    from synthetic.render.scene import Pose

    score = random_score(np.random.default_rng(500), n_beats=16, turns=True, fps=25.0)
    motion = interpret(score, 25.0, Body())
    pose = Pose.from_motion(motion)
    camera = RenderCamera.for_view("front", (640, 480), pose.body.height)
    track = truth_track(truth_fields(pose, camera))
    joints = np.asarray(pose.joints, float)[: len(track)]
    T = joints.shape[0]
    fit = FitResult(25.0, np.arange(T) / 25.0, joints, np.zeros_like(joints), joints[:, 0], np.ones(joints.shape[:2]))
    out = with_image_yaw(fit, track, camera)
    assert out.front_readings.shape == (T, 2)
    turns = [s for s in score.symbols if s.is_turn]
    assert turns
    per_s = 60.0 / float(score.tempo) * 25.0
    for s in turns:
        a, b = round(float(s.start) * per_s), round(float(s.end) * per_s)
        assert turn_probability(out.front_readings[a:b]) > SYMBOL_UNCERTAIN_BELOW, (s.direction, s.amount)
