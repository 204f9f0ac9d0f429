"""Choice of each arm segment's side of the image plane (:mod:`capture2notation.fitting.depth`)."""

import numpy as np
import pytest

from capture2notation.body import Body, joint_index
from capture2notation.fitting import Camera, FitOptions, fit_keypoints
from capture2notation.fitting.depth import arm_candidates, viterbi

CAM = Camera.default((640, 480))
T = 30


def _depth_sign(joints, a, b):
    """Sign of the camera depth of segment a -> b per frame (+1 away from the camera)."""
    c = CAM.to_camera(joints)
    return np.sign(c[:, joint_index(b), 2] - c[:, joint_index(a), 2])


def test_one_candidate_is_the_true_arm_and_all_project_onto_the_same_pixels():
    rng = np.random.default_rng(0)
    S = CAM.to_camera(np.array([[0.2, 0.0, 1.4]] * 20))
    u = rng.normal(size=(20, 3))
    f = rng.normal(size=(20, 3))
    E = S + 0.3 * u / np.linalg.norm(u, axis=1, keepdims=True)
    W = E + 0.25 * f / np.linalg.norm(f, axis=1, keepdims=True)

    def px(p):
        return p[..., :2] / p[..., 2:] * CAM.focal + CAM.K[:2, 2]

    e_c, w_c = arm_candidates(CAM, S, px(E), px(W), 0.3, 0.25)
    err = np.linalg.norm(e_c - E[:, None], axis=-1) + np.linalg.norm(w_c - W[:, None], axis=-1)
    assert np.all(err.min(axis=1) < 1e-6)
    assert np.allclose(px(e_c), px(E)[:, None], atol=1e-6) and np.allclose(px(w_c), px(W)[:, None], atol=1e-6)
    assert np.allclose(np.linalg.norm(e_c - S[:, None], axis=-1), 0.3)
    # A wrist ray that misses the sphere about a wrong elbow gives its closest point.
    fore = np.linalg.norm(w_c - e_c, axis=-1)
    assert np.all(fore >= 0.25 - 1e-9)
    assert np.allclose(fore[np.arange(20), err.argmin(axis=1)], 0.25)


def test_viterbi_ignores_a_lone_frame_that_prefers_the_far_jump():
    unary = np.zeros((9, 2))
    unary[:, 1] = 1.0
    unary[4] = (1.0, 0.0)  # one frame's evidence says the other side
    pair = np.tile(np.array([[0.0, 5.0], [5.0, 0.0]]), (8, 1, 1))
    assert viterbi(unary, pair).tolist() == [0] * 9
    # With free switching, the lone frame gets its own state.
    assert viterbi(unary, np.zeros((8, 2, 2))).tolist() == [0] * 4 + [1] + [0] * 4


def test_an_arm_pointing_forward_stays_forward_when_the_world_depth_flips_in_some_frames(synth):
    # The world landmarks put the elbow and wrist behind the shoulder in every
    # third frame; continuity and the other frames must keep the arm in front,
    # without a depth flip between frames.
    body = Body()
    ang, root = synth.held_pose(T, body, right_shoulder=(1.3, 0.0, 0.0))
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=1.0, seed=3)
    world = world + np.random.default_rng(4).normal(0.0, 0.02, world.shape)
    bad = np.arange(T) % 3 == 1
    for lm in (14, 16, 20):  # right elbow, wrist, hand tip mirrored in depth about the shoulder
        world[bad, lm, 2] = 2 * world[bad, 12, 2] - world[bad, lm, 2]
    assert np.all(_depth_sign(truth, "right_shoulder", "right_wrist") < 0)  # towards the camera
    res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world)
    sign = _depth_sign(res.joints, "right_shoulder", "right_wrist")
    assert np.mean(sign < 0) >= 0.95, sign
    assert np.sum(np.diff(sign) != 0) == 0, sign


def test_a_bent_elbow_tells_the_forearm_side_when_world_depth_says_nothing(synth):
    # Upper arm hanging, forearm bent 90° forward (at the camera).  The world
    # landmarks are flattened onto the image plane, so only the elbow's one
    # bending direction says in front: the fit must put the hand in front.
    body = Body()
    ang, root = synth.held_pose(T, body, right_elbow=(1.5, 0.0, 0.0))
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=1.0, seed=8)
    world[:, [16, 20], 2] = world[:, [14], 2]
    assert np.all(_depth_sign(truth, "right_elbow", "right_wrist") < 0)
    res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world)
    fore = CAM.to_camera(res.joints[:, joint_index("right_wrist")]) - CAM.to_camera(
        res.joints[:, joint_index("right_elbow")]
    )
    towards = -fore[:, 2] / np.linalg.norm(fore, axis=1)
    assert np.mean(towards > 0.5) >= 0.9, towards  # at least 30° towards the camera
    # Without the choice the side is left to chance (measured: behind).
    off = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world, options=FitOptions(depth=None))
    fore_off = CAM.to_camera(off.joints[:, joint_index("right_wrist")]) - CAM.to_camera(
        off.joints[:, joint_index("right_elbow")]
    )
    assert np.mean(-fore_off[:, 2] / np.linalg.norm(fore_off, axis=1)) < np.mean(towards)


#: BlazePose landmarks of a right limb: its root, the points that move with
#: its middle joint, those that move with its end; and its two joints.
_LIMBS = {
    "arm": (12, [14, 16, 18, 20, 22], [16, 18, 20, 22], ("right_shoulder", "right_elbow", "right_wrist")),
    "leg": (24, [26, 28, 30, 32], [28, 30, 32], ("right_hip", "right_knee", "right_ankle")),
}


@pytest.mark.parametrize(
    "limb, pose, rest, seed",
    [
        ("arm", {"right_shoulder": (0.785, 0.0, 0.0)}, 12, 5),
        ("leg", {"right_hip": (0.6, 0.0, 0.0)}, 30, 6),
    ],
)
def test_the_landmarks_rest_offset_is_measured_on_the_hanging_limb_and_removed(limb, pose, rest, seed, synth):
    # The limb hangs for `rest` frames (DESIGN.md's starting pose), then
    # points forward low for 20.  The world landmarks keep half of its depth
    # and put the middle joint 0.4 of the first segment behind the root in
    # every pose, the end 0.4 of the second behind the middle joint
    # (BlazePose on our renders: about a quarter, with less of the depth):
    # read as they come they put the raised limb behind.  Seen from the
    # front a leg lifted forward keeps most of its image length, so its
    # frames count as hanging too; the standing ones outnumber them.
    from capture2notation.fitting.depth import DepthOptions

    root_lm, mid_lms, end_lms, (a, m, e) = _LIMBS[limb]
    body = Body()
    still, _ = synth.held_pose(rest, body)
    ahead, root = synth.held_pose(20, body, **pose)
    ang, root = np.concatenate([still, ahead]), np.concatenate([root[:1].repeat(rest, 0), root])
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=1.0, seed=seed)
    world[:, mid_lms, 2] = world[:, [root_lm], 2] + 0.5 * (world[:, mid_lms, 2] - world[:, [root_lm], 2])
    world[:, mid_lms, 2] += 0.4 * np.linalg.norm(body.offsets[joint_index(m)])
    world[:, end_lms, 2] += 0.4 * np.linalg.norm(body.offsets[joint_index(e)])
    assert np.all(_depth_sign(truth[rest:], a, m) < 0)

    def towards(options):
        res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world, options=options)
        return np.mean(_depth_sign(res.joints[rest:], a, m) < 0)

    assert towards(FitOptions(depth=DepthOptions(rest_offset=True))) >= 0.9
    assert towards(FitOptions()) <= 0.1  # measured: behind (the default, for unbiased landmarks)
