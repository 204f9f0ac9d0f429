"""Side views: hidden shoulders and hidden hips must not cost the arm's side or the hips' facing.

Seen from the performer's right (the study's side camera), an arm raised
straight at the camera hides its shoulder behind the elbow and hand, and a
hanging arm hides the near hip while the body hides the far one.  With the
shoulder unseen the upper arm had no world direction and the arm's depth
was left to the solver (fitted pointing away, ~160° off); with both hips
unseen nothing held the pelvis's turn, which wandered 20–40° away from the
shoulders' and turned every leg direction (read in the hips' frame) with it.
"""

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.body.frames import body_frame
from capture2notation.fitting import Camera, FitOptions, fit_keypoints

T = 30


def _side_camera(body: Body) -> Camera:
    """640×480 camera on the performer's right (+x) looking at the pelvis, 4 m away."""
    f = 0.5 * 640 / np.tan(np.radians(30.0))
    K = np.array([[f, 0.0, 320.0], [0.0, f, 240.0], [0.0, 0.0, 1.0]])
    # Camera axes in world coordinates: x right (world +y), y down, z forward (world −x).
    R = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
    centre = np.array([4.0, 0.0, body.rest[0, 2]])
    return Camera(K, R, -R @ centre, (640, 480))


def _observe(synth, body, cam, hidden, **angles):
    ang = np.zeros((T, len(JOINTS), 3))
    for name, value in angles.items():
        ang[:, joint_index(name)] = value
    ang = body.clip(ang)
    root = np.tile(body.rest[0], (T, 1))
    xy, conf, world, truth = synth.observe(ang, root, cam, body, noise_px=0.5, seed=3)
    world = world + np.random.default_rng(4).normal(0.0, 0.03, world.shape)
    for lm in hidden:
        xy[:, lm], conf[:, lm], world[:, lm] = np.nan, 0.0, np.nan
    return xy, conf, world, truth


def _angle(u, v):
    cos = np.sum(u * v, -1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_an_arm_raised_at_the_camera_with_its_shoulders_hidden_points_at_the_camera(synth):
    # Right arm to the side at shoulder height, pointing at the camera; both
    # shoulder landmarks hidden (the near one behind the arm, the far one
    # behind the body), as in the leg phrase's side view.
    body = Body()
    cam = _side_camera(body)
    xy, conf, world, truth = _observe(
        synth, body, cam, hidden=(11, 12), right_shoulder=(0.0, -1.45, 0.0), right_elbow=(0.2, 0.0, 0.0)
    )
    upper_t = truth[:, joint_index("right_elbow")] - truth[:, joint_index("right_shoulder")]
    assert np.all(upper_t[:, 0] > 0.2)  # towards the camera
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    for a, b in (("right_shoulder", "right_elbow"), ("right_elbow", "right_wrist")):
        ia, ib = joint_index(a), joint_index(b)
        err = _angle(res.joints[:, ib] - res.joints[:, ia], truth[:, ib] - truth[:, ia])
        assert np.median(err) < 20.0, (a, b, err)
        assert np.max(err) < 35.0, (a, b, err)


def test_hidden_hips_face_where_the_shoulders_face(synth):
    # Left leg raised to the front, both hips and the far shoulder hidden:
    # only the near shoulder and the legs say where the hips face.
    body = Body()
    cam = _side_camera(body)
    xy, conf, world, truth = _observe(synth, body, cam, hidden=(11, 23, 24), left_hip=(1.2, 0.0, 0.0))
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    fwd_t, fwd_f = body_frame(truth)[:, 1], body_frame(res.joints)[:, 1]
    err = _angle(fwd_f, fwd_t)
    assert np.median(err) < 10.0, err
    assert np.max(err) < 20.0, err


def _study_side_fit(phrase: str, options=None):
    """The fidelity study's keypoint path in the side view: exact pixels, 3 cm world noise, hidden points NaN."""
    from pathlib import Path

    from capture2notation.notation.formats import read
    from synthetic.interpret import interpret
    from synthetic.render.camera import Camera as RenderCamera
    from synthetic.render.scene import Pose, landmark_visibility

    root = Path(__file__).resolve().parents[2]
    motion = interpret(read(root / "synthetic" / "phrases" / f"{phrase}.lab"))
    cam = RenderCamera.for_view("side", (640, 480), motion.body.height)
    pose = Pose.from_motion(motion)
    lm, vis = pose.landmarks, landmark_visibility(pose, cam)
    uv = cam.project(lm)
    uv[vis == 0] = np.nan
    hip = 0.5 * (lm[:, 23] + lm[:, 24])
    world = (lm - hip[:, None]) @ cam.R.T + np.random.default_rng(0).normal(0.0, 0.03, lm.shape)
    world[vis == 0] = np.nan
    res = fit_keypoints(
        uv, vis, motion.fps, camera=Camera(cam.K, cam.R, cam.t, (640, 480)), world=world, options=options
    )
    return motion.joints(), res.joints


def _part_errors(truth, fitted, part):
    from capture2notation.compare.metrics import angle_between, part_vectors

    return angle_between(part_vectors(truth, (part,)), part_vectors(fitted, (part,)))[:, 0]


def test_figure7_side_view_keeps_the_hips_facing_with_both_hips_hidden():
    # The right hip is hidden by the hanging arm all clip long, the left by
    # the body: the left leg's rond de jambe was read 28° off in the median
    # (60° at worst) because the pelvis turned away from the shoulders.
    # The leg's last rond de jambe moves its foot mostly along the line of
    # sight, slowly, with the ankle hidden: the feet's speed prior holds it
    # back (worst frame ~25°), so it is off here to see the hips alone.
    truth, fitted = _study_side_fit("figure7", FitOptions(planted_speed=0.0))
    err = _part_errors(truth, fitted, "left_leg")
    assert np.nanmedian(err) < 8.0, err
    assert np.nanmax(err) < 20.0, err


def test_leg_phrase_side_view_keeps_the_arm_at_the_camera_with_its_shoulder_hidden():
    # The right arm held to the side points at the camera and hides both
    # shoulders from frame ~30 on; it was fitted pointing away (155° median).
    truth, fitted = _study_side_fit("leg_phrase")
    err = _part_errors(truth, fitted, "right_arm")
    assert np.nanmedian(err) < 15.0, err
    assert np.nanpercentile(err, 90) < 30.0, err
