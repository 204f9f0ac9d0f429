"""The performer's starting depth from the feet on the floor (:mod:`capture2notation.fitting.floor`)."""

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.fitting import Camera, FitOptions
from capture2notation.fitting.fit import _problem
from capture2notation.fitting.floor import floor_depth, support_depth
from capture2notation.fitting.start import initial_params as _initial_params

CAM = Camera.default((640, 480))
T = 20


def _pose(body, **angles):
    ang = np.zeros((T, len(JOINTS), 3))
    for name, value in angles.items():
        ang[:, joint_index(name)] = value
    root = np.tile(body.rest[0], (T, 1))
    root[:, 1] += np.linspace(-0.5, 0.5, T)  # walks away from / towards the camera
    return body.clip(ang), root


def _start_depth_error(synth, body_true, floor, **angles):
    ang, root = _pose(body_true, **angles)
    xy, conf, world, _ = synth.observe(ang, root, CAM, body=body_true)
    model, _, (names, tx, tc, tw), _ = _problem(xy, conf, world, Body(), CAM, FitOptions(), floor=floor)
    p0 = _initial_params(model, CAM, names, tx, tc, tw, floor=floor)
    return CAM.to_camera(p0[:, :3])[:, 2] - CAM.to_camera(root)[:, 2]


def test_a_foot_on_the_floor_gives_the_depth_of_the_pelvis_above_it():
    rng = np.random.default_rng(0)
    feet = np.stack([rng.uniform(-0.5, 0.5, T), rng.uniform(-1.0, 1.0, T), np.full(T, 0.02)], axis=1)
    px = CAM.project(feet)[:, None, None, :]  # one foot, one point
    depth = floor_depth(CAM, px, np.ones((T, 1, 1)), np.array([0.02]), 0.9)
    pelvis = feet + np.array([0.0, 0.0, 0.88])
    assert np.allclose(depth[:, 0], CAM.to_camera(pelvis)[:, 2], atol=1e-9)
    # A ray that never reaches the floor (above the horizon) gives no depth.
    sky = np.array([[[[320.0, 0.0]]]])
    assert np.isnan(floor_depth(CAM, sky, np.ones((1, 1, 1)), np.array([0.02]), 0.9)).all()


def test_the_supporting_foot_is_the_lower_one():
    size = np.full(10, 4.4)  # the image size says 10 % farther than the floor does
    feet = np.stack([np.full(10, 4.0), np.full(10, 4.0)], axis=1)
    low = np.zeros((10, 2))
    feet[5:, 1] = 5.5  # the left foot lifts forward: its ray meets the floor far behind it
    low[5:, 1] = -0.3
    assert np.allclose(support_depth(feet, low, size), 4.0)
    # No foot seen: the size depth, calibrated on the frames that have one.
    feet[7] = np.nan
    assert np.isclose(support_depth(feet, low, size)[7], 4.0)


def test_a_small_performer_starts_at_the_right_depth_with_a_known_camera(synth):
    # A 1.55 m dancer fitted with the default 1.70 m body: from its image
    # size it looks ~10 % (0.4 m) farther than it is; its feet say where it is.
    small = Body(height=1.55)
    size_err = _start_depth_error(synth, small, floor=False)
    floor_err = _start_depth_error(synth, small, floor=True)
    assert np.median(size_err) > 0.2
    assert np.max(np.abs(floor_err)) < 0.06


def test_a_raised_leg_does_not_move_the_start(synth):
    err = _start_depth_error(synth, Body(), floor=True, right_hip=(1.2, 0.0, 0.0))
    assert np.max(np.abs(err)) < 0.06
