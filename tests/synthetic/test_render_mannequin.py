"""The mannequin reads like a person where pose models look: head and feet.

Pixel checks at projected body points: a wrong draw order or a missing part
changes the colour found there.
"""

from __future__ import annotations

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from synthetic.render import Camera, Pose, make_renderer
from synthetic.render.mannequin import PALETTE

BODY = Body(1.70)
H = BODY.height


def _pose(**set_angles):
    a = np.zeros((1, len(JOINTS), 3))
    for name, v in set_angles.items():
        a[:, joint_index(name)] = v
    return Pose(a, BODY.rest[None, 0].copy(), BODY, 25.0)


def _patch(img, uv, r=2):
    u, v = np.round(uv).astype(int)
    return img[v - r : v + r + 1, u - r : u + r + 1].reshape(-1, 3).mean(axis=0)


def test_head_tilted_back_shows_its_face_from_below():
    """Port de bras: head back and turned, 45° camera below eye level.

    Ordering hair and face by the depth of their centres painted the hair
    (which sits higher) over the face here; BlazePose then read the whole
    body as seen from behind.
    """
    cam = Camera.for_view("45", (640, 480), H)
    neck = np.radians([-35.0, 30.0, -10.0])
    facing, away = _pose(neck=neck), _pose(neck=neck, pelvis=(0.0, 0.0, np.pi))
    for pose, expect_face in ((facing, True), (away, False)):
        img = make_renderer(pose, cam, "mannequin").frame(0)
        eyes = 0.5 * (pose.points["left_eye"][0] + pose.points["right_eye"][0])
        centre = 0.7 * eyes + 0.3 * pose.points["nose"][0]  # on the cheeks, between eyes and nose
        bgr = _patch(img, cam.project(centre))
        hair = np.linalg.norm(bgr - PALETTE["hair"])
        skin = np.linalg.norm(bgr - PALETTE["skin"])
        assert (skin < hair) == expect_face, (expect_face, bgr.round())


def _material(bgr: np.ndarray) -> np.ndarray:
    """Per pixel (N, 3) BGR: 't' trousers (blue), 's' skin, 'k' shoe (dark grey), '.' other."""
    b, r = bgr[:, 0].astype(int), bgr[:, 2].astype(int)
    out = np.full(len(bgr), ".")
    out[b > r + 15] = "t"
    out[(r > b + 40) & (r > 100)] = "s"
    out[(bgr.max(axis=1).astype(int) - bgr.min(axis=1) < 12) & (bgr.sum(axis=1) < 250)] = "k"
    return out


def test_the_leg_meets_the_shoe_at_the_ankle_joint():
    """Down the leg through the ankle: trousers, a bare ankle (where the camera
    sees under the hem), then the shoe.

    The truth ankle (the body's ankle joint) lies where the leg meets the
    foot in the image, where a person would mark it: between the hem and the
    shoe, give or take 0.015 H.  (Trousers down over the shoe, as the
    mannequin had, hid that junction and BlazePose's ankle landed 9 px above
    the truth.)
    """
    pose = _pose()
    ankle = pose.points["right_ankle"][0]
    for view in ("front", "45", "side"):
        cam = Camera.for_view(view, (640, 480), H)
        img = make_renderer(pose, cam, "mannequin").frame(0)
        (u0, v0), (_, v1) = cam.project(ankle + [0.0, 0.0, 0.10 * H]), cam.project(ankle - [0.0, 0.0, 0.03 * H])
        rows = np.arange(int(v0), int(v1) + 1)
        seq = _material(img[rows, round(u0)])
        text = "".join(seq)
        trousers, skin, shoe = (rows[seq == m] for m in "tsk")
        assert len(trousers) and len(shoe), (view, text)
        assert trousers.max() < shoe.min(), (view, text)
        if view != "front":  # seen from the front the instep covers the bare ankle
            assert len(skin) and trousers.max() < skin.min() and skin.max() < shoe.min(), (view, text)
        px_per_h = cam.K[1, 1] * H / cam.depth(ankle)
        tol = 0.015 * px_per_h
        assert trousers.max() - tol <= cam.project(ankle)[1] <= shoe.min() + tol, (view, cam.project(ankle)[1], text)


def _is_shirt(bgr) -> bool:
    b, g, r = bgr
    return r > g + 60 and r > b + 40


def test_the_sleeve_ends_at_the_elbow_in_a_cuff_wider_than_the_forearm():
    """A hanging arm seen from the front: the sleeve stands off the arm and stops at the elbow.

    A sleeve as thin as the arm left nothing of the upper arm to see when it
    pointed at the camera in the side view; BlazePose then put the elbow
    half-way up the forearm.
    """
    cam = Camera.for_view("front", (640, 480), H)
    pose = _pose()
    img = make_renderer(pose, cam, "mannequin").frame(0)
    elbow, shoulder = pose.points["right_elbow"][0], pose.points["right_shoulder"][0]
    down = (elbow - shoulder) / np.linalg.norm(elbow - shoulder)
    side = np.cross(down, cam.position - elbow)
    side /= np.linalg.norm(side)
    for sign in (1.0, -1.0):
        # Between the forearm's radius (0.026 H) and the sleeve's (0.036 H).
        out = sign * 0.031 * H * side
        assert _is_shirt(_patch(img, cam.project(elbow - 0.015 * H * down + out), r=1))
        assert not _is_shirt(_patch(img, cam.project(elbow + 0.05 * H * down + out), r=1))
