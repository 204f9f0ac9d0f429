"""Fitting known poses back from their (noisy, partial) observations."""

from types import SimpleNamespace

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import FittingError
from capture2notation.fitting import (
    Camera,
    FitOptions,
    FitResult,
    fit_keypoints,
    fit_points3d,
    fit_track,
)

T = 40


#: `synth.make_motion`'s figure sways its root while both feet follow: its
#: feet glide at 0.1-0.4 m/s all clip long, which the feet's speed prior
#: (planted or moving fast, ``FitOptions.planted_speed``) does not describe
#: and holds back by 2-3 cm.  Tests of the rest of the fit on it switch it off.
GLIDING = FitOptions(planted_speed=0.0)


@pytest.fixture(scope="module")
def scene(synth):
    body = Body()
    ang, root = synth.make_motion(T, seed=3, body=body)
    cam = Camera.default((640, 480))
    return body, ang, root, cam


def _mpjpe(a, b):
    return float(np.nanmean(np.linalg.norm(a - b, axis=-1)))


def test_clean_keypoints_with_world_landmarks_are_fitted_closely(scene, synth):
    body, ang, root, cam = scene
    xy, conf, world, truth = synth.observe(ang, root, cam, body)
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world, options=GLIDING)
    assert isinstance(res, FitResult)
    assert res.joints.shape == (T, len(JOINTS), 3) and res.confidence.shape == (T, len(JOINTS))
    assert _mpjpe(res.joints, truth) < 0.02
    assert np.median(synth.limb_direction_errors(res.joints, truth)) < 1.0
    # The output is self-consistent: FK of the angles with the clip's offsets gives the joints.
    from capture2notation.fitting import PoseModel

    model = PoseModel(body, res.offsets)
    np.testing.assert_allclose(
        model.forward(model.params(res.angles, res.root))[:, : len(JOINTS)], res.joints, atol=1e-9
    )
    assert np.all(res.confidence[:, joint_index("right_wrist")] > 0.8)


def test_noisy_keypoints_stay_within_a_few_degrees(scene, synth):
    body, ang, root, cam = scene
    xy, conf, world, truth = synth.observe(ang, root, cam, body, noise_px=3.0, seed=1)
    world = world + np.random.default_rng(2).normal(0.0, 0.02, world.shape)
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    # Most of the position error is depth: segment proportions come from noisy images.
    assert _mpjpe(res.joints, truth) < 0.08
    assert np.median(synth.limb_direction_errors(res.joints, truth)) < 5.0


def test_upper_arm_length_comes_from_its_side_on_frames(synth):
    # Arms to the side for a third of the clip, then forward low (towards the
    # camera, 45° down); the world landmarks keep a fifth of the arms' depth
    # (BlazePose's follow it with a slope of 0.1-0.4), so they call the
    # forward arms "flat", and their image lengths are 0.7 of the arm's.
    body = Body()
    side, _ = synth.held_pose(15, body, right_shoulder=(0.0, -1.57, 0.0), left_shoulder=(0.0, 1.57, 0.0))
    ahead, root = synth.held_pose(30, body, right_shoulder=(0.785, 0.0, 0.0), left_shoulder=(0.785, 0.0, 0.0))
    ang, root = np.concatenate([side, ahead]), np.concatenate([root[:15], root])
    cam = Camera.default((640, 480))
    xy, conf, world, truth = synth.observe(ang, root, cam, body)
    for shoulder, arm in ((12, [14, 16, 18, 20, 22]), (11, [13, 15, 17, 19, 21])):
        world[:, arm, 2] = world[:, [shoulder], 2] + 0.2 * (world[:, arm, 2] - world[:, [shoulder], 2])
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    upper = np.linalg.norm(res.offsets[joint_index("right_elbow")])
    assert upper == pytest.approx(np.linalg.norm(body.offsets[joint_index("right_elbow")]), rel=0.03)
    # The forward arms are fitted so.
    assert np.median(synth.limb_direction_errors(res.joints[15:], truth[15:])) < 5.0


def test_joint_limits_hold(scene, synth):
    body, ang, root, cam = scene
    xy, conf, world, _ = synth.observe(ang, root, cam, body, noise_px=8.0, seed=4)
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    lim = body.limits
    inside = (res.angles[:, 1:] >= lim[1:, :, 0] - 1e-9) & (res.angles[:, 1:] <= lim[1:, :, 1] + 1e-9)
    assert inside.all()


def test_missing_landmarks_lower_confidence_and_empty_frames_are_nan(scene, synth):
    body, ang, root, cam = scene
    xy, conf, world, truth = synth.observe(ang, root, cam, body)
    xy, conf, world = xy.copy(), conf.copy(), world.copy()
    # Right wrist (16) unseen in frames 10-19; nothing at all in frames 30-32.
    xy[10:20, 16] = np.nan
    conf[10:20, 16] = 0.0
    world[10:20, 16] = np.nan
    xy[30:33], conf[30:33], world[30:33] = np.nan, 0.0, np.nan
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world, options=GLIDING)
    rw = joint_index("right_wrist")
    assert np.all(res.confidence[10:20, rw] == 0.0)
    assert np.all(res.confidence[:10, rw] > 0.8)
    assert np.all(np.isnan(res.joints[30:33])) and np.all(res.confidence[30:33] == 0.0)
    assert np.all(np.isfinite(res.joints[:30]))
    # The rest of the body is still fitted well where observed.
    ok = np.r_[0:30, 33:T]
    assert _mpjpe(res.joints[ok], truth[ok]) < 0.03


def test_unknown_camera_uses_the_default_and_sets_the_floor(synth):
    body = Body()
    ang, root = synth.make_motion(30, seed=7, body=body)
    for leg in ("right_hip", "right_knee", "left_hip", "left_knee"):
        ang[:, joint_index(leg)] = 0.0  # feet stay on the floor
    cam = Camera.default((640, 480), hfov_deg=55.0)
    xy, conf, world, truth = synth.observe(ang, root, cam, body, noise_px=1.0)
    res = fit_keypoints(xy, conf, 25.0, world=world, image_size=(640, 480))

    def rel(j):
        return j - j[:, :1]

    assert _mpjpe(rel(res.joints), rel(truth)) < 0.04
    feet = [joint_index(f"{s}_{j}") for s in ("right", "left") for j in ("ankle", "toe")]
    assert np.max(np.abs(res.joints[:, feet, 2] - truth[:, feet, 2])) < 0.02
    with pytest.raises(FittingError, match="image_size"):
        fit_keypoints(xy, conf, 25.0, world=world)


def test_fit_track_reads_a_keypoint_track(scene, synth):
    body, ang, root, cam = scene
    xy, conf, world, truth = synth.observe(ang[:10], root[:10], cam, body)
    xyz = np.concatenate([xy, np.zeros((10, 33, 1))], axis=-1)
    presence = np.ones(10)
    presence[4] = 0.0  # no person found in frame 4
    track = SimpleNamespace(
        xy=xyz,
        visibility=conf,
        presence=presence,
        world=world,
        fps=25.0,
        times=np.arange(10) / 25.0,
        image_size=np.array([640, 480]),
    )
    res = fit_track(track, camera=cam)
    assert np.all(np.isnan(res.joints[4])) and np.all(res.confidence[4] == 0)
    ok = np.r_[0:4, 5:10]
    assert _mpjpe(res.joints[ok], truth[ok]) < 0.03
    np.testing.assert_allclose(res.times, track.times)


def test_3d_points_fit_recovers_the_pose(synth):
    body = Body(1.8)
    ang, root = synth.make_motion(30, seed=11, body=body)
    truth = forward_kinematics(ang, root, body)
    conf = np.ones(truth.shape[:2])
    res = fit_points3d(truth, conf, 25.0)
    assert _mpjpe(res.joints, truth) < 0.01
    assert np.median(synth.limb_direction_errors(res.joints, truth)) < 1.0


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: fit_keypoints(np.zeros((5, 17, 2)), np.ones((5, 17)), 25.0, image_size=(64, 48)), "33"),
        (lambda: fit_keypoints(np.zeros((5, 33, 2)), np.ones((5, 32)), 25.0, image_size=(64, 48)), "confidence"),
        (lambda: fit_keypoints(np.zeros((5, 33, 2)), np.ones((5, 33)), 0.0, image_size=(64, 48)), "fps"),
        (lambda: fit_keypoints(np.zeros((0, 33, 2)), np.ones((0, 33)), 25.0, image_size=(64, 48)), "no frames"),
        (lambda: fit_points3d(np.zeros((5, 3, 3)), np.ones((5, 3)), 25.0), "points"),
    ],
)
def test_bad_inputs_name_the_problem(call, message):
    with pytest.raises(FittingError, match=message):
        call()


def test_long_clips_are_solved_in_chunks_without_seams(monkeypatch, synth):
    from capture2notation.fitting import solver

    body = Body()
    ang, root = synth.make_motion(60, seed=13, body=body)
    cam = Camera.default((640, 480))
    xy, conf, world, truth = synth.observe(ang, root, cam, body, noise_px=1.0, seed=2)
    whole = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    monkeypatch.setattr(solver, "CHUNK", 25)
    monkeypatch.setattr(solver, "OVERLAP", 5)
    chunked = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    assert _mpjpe(chunked.joints, truth) < 0.03
    assert _mpjpe(chunked.joints, whole.joints) < 0.01
    # No jump at the chunk boundaries beyond the motion itself.
    step = np.linalg.norm(np.diff(chunked.joints, axis=0), axis=-1).max(axis=1)
    true_step = np.linalg.norm(np.diff(truth, axis=0), axis=-1).max(axis=1)
    assert np.all(step < true_step + 0.03)


@pytest.mark.parametrize("hfov", [45.0, 75.0])
def test_focal_length_is_refined_towards_the_true_one(hfov, synth):
    from capture2notation.fitting import refine_focal

    body = Body()
    ang, root = synth.make_motion(30, seed=2, body=body)
    cam = Camera.default((640, 480), hfov_deg=hfov, distance=3.0)
    xy, conf, world, _ = synth.observe(ang, root, cam, body, noise_px=1.0)
    got = refine_focal(xy, conf, 25.0, Camera.default((640, 480)), world=world)
    got_hfov = np.degrees(2 * np.arctan(320.0 / got.focal))
    assert abs(got_hfov - hfov) < 8.0
    # Without world landmarks focal length and distance trade off: the default stays.
    assert refine_focal(xy, conf, 25.0, Camera.default((640, 480))).focal == Camera.default((640, 480)).focal


def test_2d_landmarks_alone_are_lifted_to_a_plausible_pose(scene, synth):
    # The marker backend has no world landmarks: depth comes from the image
    # lengths of the segments and the front/back choice from the lifting rule.
    body, ang, root, cam = scene
    xy, conf, _, truth = synth.observe(ang, root, cam, body)
    res = fit_keypoints(xy, conf, 25.0, camera=cam)
    assert np.median(synth.limb_direction_errors(res.joints, truth)) < 6.0
    # Reprojection is faithful whatever the depth: the fit explains the image.
    proj = cam.project(res.joints[:, joint_index("right_wrist")])
    assert np.median(np.linalg.norm(proj - xy[:, 16], axis=1)) < 2.0


def test_arms_lowered_from_overhead_to_the_side_keep_one_branch(synth):
    # h4's port de bras: arms raised forward to overhead, then opened to the
    # side (rx 164° -> 90° with rz -90°).  Chosen frame by frame, the
    # starting angles jumped to the other Euler triple / another twist as
    # the elbow straightened, and the solve between the two branches pointed
    # the arm 15-35° off for a beat.
    body = Body()
    n = 50
    s = np.linspace(0.0, 1.0, n)[:, None]
    ang, root = synth.held_pose(n, body)
    ang[:, joint_index("right_shoulder")] = np.radians(
        np.array([164.0, 0.0, -91.0]) * (1 - s) + np.array([90.0, -30.0, -90.0]) * s
    )
    ang[:, joint_index("left_shoulder")] = ang[:, joint_index("right_shoulder")] * [1.0, -1.0, -1.0]
    # Slightly bent at the top, straight from a third of the way down.
    ang[:, joint_index("right_elbow"), 0] = ang[:, joint_index("left_elbow"), 0] = np.radians(
        np.clip(20.0 - 60.0 * s[:, 0], 0.0, None)
    )
    ang = body.clip(ang)
    cam = Camera.default((640, 480))
    xy, conf, world, truth = synth.observe(ang, root, cam, body)
    res = fit_keypoints(xy, conf, 25.0, camera=cam, world=world)
    errors = synth.limb_direction_errors(res.joints, truth)
    assert np.max(errors) < 3.0


def test_3d_floor_term_holds_jittery_standing_feet_nearer_the_floor():
    """Triangulated feet scatter by centimetres; ``floor=True`` holds the lowest foot at its standing height.

    Reference: the body standing still in its rest pose (feet on the floor
    by construction), every joint jittered by 3 cm (about a BlazePose
    two-view triangulation at 3.8 m).  The quantiser reads a foot within
    3 cm of its standing height as on the floor (DESIGN.md): more of the
    fitted foot heights must lie within it with the floor term than without,
    and their mean within 1 cm of the floor.
    """
    body = Body()
    T = 40
    truth = np.repeat(body.rest[None], T, axis=0)
    noisy = truth + np.random.default_rng(7).normal(0.0, 0.03, truth.shape)
    feet = [joint_index(n) for n in ("right_ankle", "left_ankle", "right_toe", "left_toe")]

    def heights(floor):
        res = fit_points3d(noisy, np.ones((T, len(JOINTS))), 25.0, floor=floor)
        return res.joints[:, feet, 2] - body.rest[feet, 2]

    floored, free = heights(True), heights(False)
    assert abs(np.mean(floored)) < 0.01
    assert np.mean(np.abs(floored) < 0.03) > np.mean(np.abs(free) < 0.03)


def test_an_unknown_rolled_camera_is_fitted_upright_given_its_roll(synth):
    """Through a phone rolled 6°, the default camera rolled as much fits the body as upright as an upright phone's."""
    from capture2notation.fitting.camera_estimate import pitch_roll
    from synthetic.render.camera import Camera as RenderCamera

    phone = RenderCamera.phone("front", (640, 480), height=1.1, pitch_deg=0.0, roll_deg=6.0, hfov_deg=60.0)
    cam = Camera(phone.K, phone.R, phone.t, (640, 480))
    assert pitch_roll(Camera.default((640, 480), roll_deg=6.0).R) == pytest.approx((0.0, 6.0), abs=1e-9)
    body = Body()
    ang, root = synth.make_motion(30, seed=7, body=body)
    xy, conf, world, truth = synth.observe(ang, root, cam, body, noise_px=1.0)

    def trunk_tilt_deg(joints):
        """Mean angle between the fitted and the true pelvis → neck directions."""
        a = joints[:, joint_index("neck")] - joints[:, 0]
        b = truth[:, joint_index("neck")] - truth[:, 0]
        cos = np.sum(a * b, -1) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
        return float(np.degrees(np.arccos(np.clip(cos, -1, 1))).mean())

    rolled = fit_keypoints(xy, conf, 25.0, world=world, image_size=(640, 480), roll_deg=6.0, options=GLIDING)
    level = fit_keypoints(xy, conf, 25.0, world=world, image_size=(640, 480), options=GLIDING)
    upright = RenderCamera.phone("front", (640, 480), height=1.1, pitch_deg=0.0, roll_deg=0.0, hfov_deg=60.0)
    xy0, conf0, world0, _ = synth.observe(ang, root, Camera(upright.K, upright.R, upright.t, (640, 480)), body, 1.0)
    reference = trunk_tilt_deg(
        fit_keypoints(xy0, conf0, 25.0, world=world0, image_size=(640, 480), options=GLIDING).joints
    )
    # Given its roll, the rolled camera's fit is as upright as an upright camera's; without it, off by most of 6°.
    assert trunk_tilt_deg(rolled.joints) < reference + 0.5
    assert trunk_tilt_deg(level.joints) > reference + 3.0
