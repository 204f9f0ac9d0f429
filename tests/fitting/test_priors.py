"""Depth from a single view: priors, floor contact, root smoothing and direction spread.

Each test builds BlazePose-like observations of a known pose (the `synth`
fixture of ``conftest.py``) and checks what the fit recovers, with explicit
tolerances.
"""

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.fitting import Camera, FitOptions, PoseModel, fit_keypoints
from capture2notation.fitting.fit import (
    TARGETS_2D,
    _floor_terms,
    _problem,
)
from capture2notation.fitting.solver import solve
from capture2notation.fitting.temporal import smooth_root
from capture2notation.fitting.uncertainty import direction_spread, spread_factor
from capture2notation.notation.model import PART_SEGMENTS
from capture2notation.quantise.labels import DIRECTION_NAMES, label_frames

T = 30
CAM = Camera.default((640, 480))


def _labels(joints, part):
    lab = label_frames(joints, 25.0)
    i = lab.index(part)
    return [(DIRECTION_NAMES[d], ("high", "middle", "low")[l]) for d, l in zip(lab.direction[:, i], lab.level[:, i])]


@pytest.mark.parametrize("rx, expected", [(np.pi / 2, ("forward", "middle")), (-np.pi / 4, ("back", "low"))])
def test_an_arm_pointing_at_or_away_from_the_camera_is_recovered_on_the_right_side(synth, rx, expected):
    # Seen from the front, forward-middle and back-low arms are short stubs in
    # the image; only the world landmarks say in front or behind.
    body = Body()
    ang, root = synth.held_pose(T, body, right_shoulder=(rx, 0.0, 0.0))
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=1.0, seed=5)
    world = world + np.random.default_rng(6).normal(0.0, 0.02, world.shape)
    res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world)
    got = _labels(res.joints, "right_arm")
    assert _labels(truth, "right_arm")[0] == expected
    assert np.mean([g == expected for g in got]) >= 0.9, got


def test_trunk_stays_upright_when_world_landmarks_lean_it_towards_the_camera(synth):
    # BlazePose's world landmarks of a front view put the shoulders 20-40°
    # towards the camera; the image says the trunk is upright.
    body = Body()
    ang, root = synth.held_pose(T, body, right_shoulder=(0.0, -1.2, 0.0), left_shoulder=(0.0, 1.2, 0.0))
    xy, conf, world, _ = synth.observe(ang, root, CAM, body, noise_px=1.0, seed=7)
    lean = np.radians(35.0)  # rotate the upper body about the hip axis, towards the camera (camera -z)
    c, s = np.cos(lean), np.sin(lean)
    upper = [
        lm
        for name, (lm, *_), _ in zip([t[0] for t in TARGETS_2D], [t[1] for t in TARGETS_2D], TARGETS_2D)
        if any(k in name for k in ("shoulder", "elbow", "wrist", "hand", "nose", "ear"))
    ]
    hip = 0.5 * (world[:, 23] + world[:, 24])
    rel = world[:, upper] - hip[:, None]
    y, z = rel[..., 1], rel[..., 2]  # camera y down, z away: up is -y, towards the camera is -z
    world[:, upper, 1] = hip[:, None, 1] + c * y + s * z
    world[:, upper, 2] = hip[:, None, 2] - s * y + c * z
    res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world)
    chest = label_frames(res.joints, 25.0)
    i = chest.index("chest")
    tilt = np.degrees(np.arccos(np.clip(chest.vectors[:, i, 2], -1, 1)))
    assert np.median(tilt) < 10.0, tilt
    assert np.mean(chest.direction[:, i] == DIRECTION_NAMES.index("place")) >= 0.95


def test_noisy_observations_of_a_dance_give_the_true_labels(synth):
    body = Body()
    ang, root = synth.make_motion(50, seed=11, body=body)
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=2.0, seed=12)
    world = world + np.random.default_rng(13).normal(0.0, 0.02, world.shape)
    res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world)
    lf, lt = label_frames(res.joints, 25.0), label_frames(truth, 25.0)
    cols = [lt.index(p) for p in PART_SEGMENTS]
    agree = (lf.direction[:, cols] == lt.direction[:, cols]) & (lf.level[:, cols] == lt.level[:, cols])
    # Measured 0.89-0.90 over noise seeds at the time of writing: frames passing
    # a sector boundary may differ, and this synthetic figure floats ~5 cm, which
    # the floor term resists.
    assert agree.mean() >= 0.85


def _standing_fit(synth, noise_px, options):
    body = Body()
    ang, root = synth.held_pose(40, body, right_shoulder=(1.2, 0.0, 0.0), left_elbow=(0.8, 0.0, 0.0))
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=noise_px, seed=21)
    world = world + np.random.default_rng(22).normal(0.0, 0.03, world.shape)
    return fit_keypoints(xy, conf, 25.0, camera=CAM, world=world, options=options), truth


def test_root_depth_of_a_still_figure_does_not_jitter(synth):
    still, _ = _standing_fit(synth, 2.0, FitOptions())
    loose, _ = _standing_fit(synth, 2.0, FitOptions(root_passes=0))

    def depth(r):
        return CAM.to_camera(r.root)[:, 2]

    jitter_still = np.median(np.abs(np.diff(depth(still), 2)))
    jitter_loose = np.median(np.abs(np.diff(depth(loose), 2)))
    # Measured 4.5 mm against 17 mm per frame² at the time of writing.
    assert jitter_still < 0.008  # metres per frame²
    assert jitter_still < 0.4 * jitter_loose


def test_standing_feet_stay_near_a_known_floor(synth):
    res, truth = _standing_fit(synth, 1.0, FitOptions())
    feet = [joint_index(n) for n in ("right_toe", "left_toe")]
    error = np.abs(res.joints[:, feet, 2].min(axis=1) - truth[:, feet, 2].min(axis=1))
    # The largest errors are the clip's first two frames (2.5-2.6 cm when
    # measured, under 1 cm from the third frame on).
    assert np.max(error) < 0.03 and np.median(error) < 0.01
    assert np.max(error[2:]) < 0.02


def _clean_observations(ang, root, body):
    model = PoseModel(body)
    pts = model.forward(model.params(ang, root))
    xy = np.full((len(ang), 33, 2), np.nan)
    conf = np.zeros((len(ang), 33))
    world = np.full((len(ang), 33, 3), np.nan)
    for name, lms, _ in TARGETS_2D:
        if len(lms) == 1:
            xy[:, lms[0]] = CAM.project(pts[:, model.index(name)])
            conf[:, lms[0]] = 1.0
            world[:, lms[0]] = (pts[:, model.index(name)] - root) @ CAM.R.T
    return xy, conf, world


def test_smooth_root_removes_depth_jitter_from_a_steady_walk():
    # A root moving at constant velocity has no second difference; depth
    # jitter added to it is what a single view leaves, and the pass removes it.
    body = Body()
    ang = np.zeros((T, len(JOINTS), 3))
    ang[:, joint_index("right_shoulder"), 1] = -0.8
    root = np.tile(body.rest[0], (T, 1))
    root[:, 0] += np.linspace(0.0, 0.3, T)
    xy, conf, _ = _clean_observations(ang, root, body)
    opt = FitOptions()
    model, terms, (names, _, tc, _), _ = _problem(xy, conf, None, body, CAM, opt)
    _floor_terms(model, terms, tc, names)
    params = model.params(ang, root)
    params[:, 1] += np.random.default_rng(3).normal(0.0, 0.01, T)  # world y is the default camera's depth
    out = smooth_root(model, params, terms, 25.0, opt)

    def jitter(p):
        return np.median(np.abs(np.diff(p[:, 1], 2)))

    assert jitter(out) < 0.3 * jitter(params)
    assert np.mean(np.linalg.norm(out[:, :3] - root, axis=1)) < 0.005
    assert np.all((out[:, 3:] >= model.lower[3:]) & (out[:, 3:] <= model.upper[3:]))


def test_direction_spread_follows_the_evidence(synth):
    # Through one camera a segment lying across the image has its depth set
    # only to second order (foreshortening), one seen end-on to first order;
    # world landmarks (a direction prior) narrow the spread of both.
    body = Body()
    ang, root = synth.held_pose(5, body, right_shoulder=(np.pi / 2, 0.0, 0.0), left_shoulder=(0.0, np.pi / 2, 0.0))
    xy, conf, world = _clean_observations(ang, root, body)
    opt = FitOptions()
    spreads = []
    for w in (None, world):
        model, terms, _, _ = _problem(xy, conf, w, body, CAM, opt)
        params, _ = solve(model, model.params(ang, root), terms, 25.0, opt, 5)
        spreads.append(direction_spread(model, params, terms, 25.0, opt))
    end_on, across = joint_index("right_elbow"), joint_index("left_elbow")
    alone, with_world = spreads
    assert np.all(alone[:, across] > 2.0 * alone[:, end_on])
    assert np.all(with_world[:, [end_on, across]] < alone[:, [end_on, across]])
    assert np.all(with_world[:, across] < 20.0)
    f = spread_factor(alone, 15.0)
    assert np.all((f > 0) & (f <= 1)) and np.all(f[:, across] < f[:, end_on])
