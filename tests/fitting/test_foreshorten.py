"""Out-of-plane amount of arm segments from their image length (:mod:`capture2notation.fitting.foreshorten`)."""

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.fitting import Camera, FitOptions, fit_keypoints
from capture2notation.fitting.depth import DepthOptions
from capture2notation.fitting.foreshorten import bound_depth, depth_band

CAM = Camera.default((640, 480))
T = 30


def test_band_of_an_image_length():
    lo, hi = depth_band(np.array([1.0, np.sqrt(0.5), 0.0, np.nan]), eps=0.1)
    # As long as the segment (or longer): within ~26 deg of the plane.
    assert lo[0] == 0.0 and np.isclose(hi[0], np.sqrt(1 - 0.81))
    # Foreshortened to 0.71: 45 deg, give or take the uncertainty.
    assert np.isclose(lo[1], np.sqrt(1 - 0.5 * 1.21)) and np.isclose(hi[1], np.sqrt(1 - 0.5 * 0.81))
    assert lo[2] == hi[2] == 1.0  # a point: straight along the ray
    assert lo[3] == 0.0 and hi[3] == 1.0  # unknown: anything


def test_bound_depth_keeps_sign_length_and_image_direction():
    d = np.array([[0.3, 0.0, -0.3], [0.0, 0.1, 0.05], [np.nan, 0.0, 0.0]])
    out = bound_depth(d, np.array([1.0, 0.5, 1.0]), eps=0.1)
    assert np.allclose(np.linalg.norm(out[:2], axis=1), np.linalg.norm(d[:2], axis=1))
    u = out[0] / np.linalg.norm(out[0])
    assert np.isclose(u[2], -np.sqrt(1 - 0.81)) and u[0] > 0 and abs(u[1]) < 1e-12
    u = out[1] / np.linalg.norm(out[1])
    assert u[2] > 0 and np.isclose(u[2], np.sqrt(1 - 0.25 * 1.21))  # raised to the band's bottom
    assert np.isnan(out[2, 0])


def test_world_landmarks_leaning_an_in_plane_forearm_at_the_camera_are_overruled(synth):
    # Arms straight out to the sides, in the image plane of a front camera;
    # the world landmarks lean both forearms 40 deg towards the camera (BlazePose
    # leans forearms that way).  The image length says the forearm is within
    # ~26 deg of the plane (10 % uncertainty), and the fit must follow it.
    body = Body()
    ang = np.zeros((T, len(JOINTS), 3))
    ang[:, joint_index("left_shoulder"), 1] = np.pi / 2
    ang[:, joint_index("right_shoulder"), 1] = -np.pi / 2
    ang, root = body.clip(ang), np.tile(body.rest[0], (T, 1))
    xy, conf, world, _ = synth.observe(ang, root, CAM)
    lean = np.deg2rad(40.0)
    for e, w, h in ((13, 15, 19), (14, 16, 20)):
        d = world[:, w] - world[:, e]
        horiz = d[:, :2] / np.linalg.norm(d[:, :2], axis=1, keepdims=True)
        leaned = np.concatenate([horiz * np.cos(lean), np.full((T, 1), -np.sin(lean))], axis=1)
        hand = world[:, h] - world[:, w]
        world[:, w] = world[:, e] + leaned * np.linalg.norm(d, axis=1, keepdims=True)
        world[:, h] = world[:, w] + hand

    def out_of_plane(band):
        res = fit_keypoints(xy, conf, 25.0, camera=CAM, world=world, options=FitOptions(depth=DepthOptions(band=band)))
        c = CAM.to_camera(res.joints)
        out = []
        for side in ("left", "right"):
            f = c[:, joint_index(f"{side}_wrist")] - c[:, joint_index(f"{side}_elbow")]
            out.append(np.degrees(np.arcsin(np.abs(f[:, 2]) / np.linalg.norm(f, axis=1))))
        return np.concatenate(out)

    assert np.median(out_of_plane(None)) > 30.0  # the world landmarks' lean survives without the band
    assert np.max(out_of_plane(0.1)) < 28.0
