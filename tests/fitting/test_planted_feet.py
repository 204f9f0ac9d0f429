"""The feet's speed prior of the exact smoothing pass (``FitOptions.planted_speed``).

A single view measures depth only through the figure's image scale, so a
fit can slide a standing foot towards or away from the camera; the prior
holds a foot that the views see still, and lets a foot they see moving go.
"""

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.fitting import Camera, FitOptions, PoseModel, fit_keypoints
from capture2notation.fitting.solver import FOOT_POINTS
from capture2notation.fitting.temporal import _foot_speed_rows, coupled_params

CAM = Camera.default((640, 480))
FPS = 25.0
#: DESIGN.md: a foot supports only while slower than this, m/s.
SUPPORT_SPEED = 0.2


def _kick(T=40):
    """A standing figure lifting its right leg forward over frames 15–25, left foot planted."""
    body = Body()
    ang = np.zeros((T, len(JOINTS), 3))
    lift = np.clip((np.arange(T) - 15) / 10.0, 0.0, 1.0)
    ang[:, joint_index("right_hip"), 0] = 0.9 * (3 * lift**2 - 2 * lift**3)  # smooth 0 → 0.9 rad
    root = np.tile(body.rest[0], (T, 1))
    return body, body.clip(ang), root


def test_the_rows_are_the_linearised_weighted_velocities():
    body, ang, root = _kick(12)
    model = PoseModel(body)
    params = model.params(ang, root)
    params[:, 1] += np.random.default_rng(0).normal(0.0, 0.01, len(params))
    cp = coupled_params(model)
    B, r0 = _foot_speed_rows(model, params, cp, FPS, 0.05)
    step = np.random.default_rng(1).normal(0.0, 1e-6, (len(params), len(cp)))
    moved = params.copy()
    moved[:, cp] += step
    # The velocities at the moved parameters, whitened with the weights of `params`.
    idx = [model.index(n) for n in FOOT_POINTS]
    v0 = np.diff(model.forward(params)[:, idx], axis=0) * FPS
    v1 = np.diff(model.forward(moved)[:, idx], axis=0) * FPS
    w = np.sqrt(2.0 / (0.05**2 + np.sum(v0**2, axis=-1)))[..., None]
    np.testing.assert_allclose(r0, (w * v0).ravel(), rtol=1e-12)
    np.testing.assert_allclose(B @ step.ravel(), (w * (v1 - v0)).ravel(), atol=1e-9, rtol=1e-4)


def test_a_planted_foot_stays_planted_and_a_kicking_foot_still_kicks(synth):
    body, ang, root = _kick(50)
    xy, conf, world, truth = synth.observe(ang, root, CAM, body, noise_px=1.0, seed=1)
    world = world + np.random.default_rng(11).normal(0.0, 0.03, world.shape)
    left, right = joint_index("left_ankle"), joint_index("right_ankle")

    def fitted(planted):
        return fit_keypoints(xy, conf, FPS, camera=CAM, world=world, options=FitOptions(planted_speed=planted)).joints

    held, loose = fitted(FitOptions().planted_speed), fitted(0.0)

    def speed(j):
        return np.linalg.norm(np.diff(j[:, left], axis=0), axis=1) * FPS

    # A pixel of keypoint noise moves a free fit's standing foot faster than
    # a support may move on most frames; held by the prior, it is slower.
    assert np.median(speed(loose)) > SUPPORT_SPEED
    assert np.median(speed(held)) < SUPPORT_SPEED
    # The kick is kept: the right ankle travels as it truly does (~0.6 m), to 5 cm.
    moved, true_moved = held[-1, right] - held[0, right], truth[-1, right] - truth[0, right]
    assert np.linalg.norm(true_moved) > 0.5
    assert np.linalg.norm(moved - true_moved) < 0.05
