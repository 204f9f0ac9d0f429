"""Renderer: landmarks, self-occlusion, the three styles, frame writers, truth output."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import (
    BLAZEPOSE_LANDMARKS,
    BLAZEPOSE_TO_JOINT,
    JOINTS,
    Body,
    forward_kinematics,
    joint_index,
)
from capture2notation.body.landmarks import landmarks_from_pose
from capture2notation.errors import SyntheticError
from capture2notation.io.truth import read_truth
from synthetic.render import (
    MARKER_COLOURS,
    MARKER_HSV,
    MARKER_JOINTS,
    Camera,
    Pose,
    landmark_visibility,
    make_renderer,
    open_writer,
    point_visibility,
    render_pose,
)
from synthetic.render.scene import FACE_LANDMARKS, body_capsules

BODY = Body(1.70)
LM = {n: i for i, n in enumerate(BLAZEPOSE_LANDMARKS)}
SIZE = (160, 120)


def _pose(n=1, **set_angles):
    """Rest pose with some angles set: ``joint=(rx, ry, rz)``; pelvis at its rest height."""
    a = np.zeros((n, len(JOINTS), 3))
    for name, v in set_angles.items():
        a[:, joint_index(name)] = v
    return Pose(a, np.tile(BODY.rest[0], (n, 1)), BODY, 25.0)


# ----------------------------------------------------------------- landmarks
def test_landmarks_at_rest_are_mirror_symmetric_and_joints_are_joints():
    pose = _pose()
    lm = pose.landmarks[0]
    for name, i in LM.items():
        if name.startswith("left_"):
            j = LM["right_" + name[5:]]
        elif name == "mouth_left":
            j = LM["mouth_right"]
        else:
            continue
        np.testing.assert_allclose(lm[i] * [-1, 1, 1], lm[j], atol=1e-12)
    for i, joint in BLAZEPOSE_TO_JOINT.items():
        np.testing.assert_allclose(lm[i], pose.joints[0, joint_index(joint)], atol=1e-12)
    # The face is in front of the head (+y), above the shoulders; heels behind the ankles.
    assert lm[LM["nose"], 1] > 0.05 and lm[LM["nose"], 2] > lm[LM["left_shoulder"], 2] + 0.1
    assert lm[LM["left_heel"], 1] < lm[LM["left_ankle"], 1] - 0.02


@settings(max_examples=25, deadline=None)
@given(st.floats(-np.pi, np.pi), st.tuples(*[st.floats(-2.0, 2.0)] * 3), st.integers(0, 2**31 - 1))
def test_landmarks_move_rigidly_with_the_whole_body(yaw, shift, seed):
    rng = np.random.default_rng(seed)
    a = BODY.clip(rng.uniform(-0.8, 0.8, size=(1, len(JOINTS), 3)))
    a[0, 0] = 0.0
    root = BODY.rest[0][None]
    base = landmarks_from_pose(a, root, BODY)[0]
    b = a.copy()
    b[0, 0, 2] = yaw
    moved = landmarks_from_pose(b, root + np.array(shift), BODY)[0]
    c, s = np.cos(yaw), np.sin(yaw)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    expect = (base - root) @ Rz.T + root + np.array(shift)
    np.testing.assert_allclose(moved, expect, atol=1e-9)


def test_face_landmarks_turn_with_the_head():
    turned = _pose(neck=(0.0, 0.0, np.pi / 2))  # head turned to the performer's left
    nose = turned.landmarks[0, LM["nose"]] - turned.points["head_centre"][0]
    assert nose[0] < -0.08 and abs(nose[1]) < 0.02


# ----------------------------------------------------------------- visibility
HEELS = [LM["left_heel"], LM["right_heel"]]


def test_front_view_sees_everything_at_rest_but_the_heels():
    cam = Camera.for_view("front", SIZE, BODY.height)
    vis = landmark_visibility(_pose(), cam)
    assert vis.shape == (1, 33)
    assert np.delete(vis[0], HEELS).all() and not vis[0, HEELS].any()  # heels are behind the ankles


def test_back_view_hides_the_face_but_not_the_ears():
    pose = _pose(pelvis=(0.0, 0.0, np.pi))  # the whole body turned to face away
    vis = landmark_visibility(pose, Camera.for_view("front", SIZE, BODY.height))[0]
    for name in ("nose", "left_eye", "right_eye", "mouth_left", "mouth_right"):
        assert vis[LM[name]] == 0, name
    assert vis[LM["left_ear"]] == 1 and vis[LM["left_hip"]] == 1


def test_side_view_hides_the_far_side():
    vis = landmark_visibility(_pose(), Camera.for_view("side", SIZE, BODY.height))[0]
    for part in ("shoulder", "elbow", "knee", "eye"):
        assert vis[LM[f"right_{part}"]] == 1, part
        assert vis[LM[f"left_{part}"]] == 0, part


def test_hand_behind_the_back_is_hidden_and_in_front_is_seen():
    behind = _pose(right_shoulder=(-1.2, 0.714, 0.0), right_elbow=(1.9, 0.0, 0.0))
    front = _pose(right_shoulder=(1.2, 0.714, 0.0), right_elbow=(1.9, 0.0, 0.0))
    assert behind.points["right_wrist"][0, 1] < -0.1 < 0.1 < front.points["right_wrist"][0, 1]
    cam = Camera.for_view("front", SIZE, BODY.height)
    assert landmark_visibility(behind, cam)[0, LM["right_wrist"]] == 0
    assert landmark_visibility(front, cam)[0, LM["right_wrist"]] == 1


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31 - 1), st.sampled_from(["front", "45", "side"]))
def test_only_face_landmarks_get_the_facing_test(seed, view):
    rng = np.random.default_rng(seed)
    a = BODY.clip(rng.uniform(-2.0, 2.0, size=(3, len(JOINTS), 3)))
    pose = Pose(a, np.tile(BODY.rest[0], (3, 1)), BODY)
    cam = Camera.for_view(view, SIZE, BODY.height)
    plain = point_visibility(cam, pose.landmarks, *body_capsules(pose))
    vis = landmark_visibility(pose, cam)
    body_part = [i for i, n in enumerate(BLAZEPOSE_LANDMARKS) if n not in FACE_LANDMARKS]
    assert len(body_part) == 22
    np.testing.assert_array_equal(vis[:, body_part], plain[:, body_part])
    assert np.all(vis <= plain)


def test_off_image_points_are_not_visible():
    a = np.zeros((2, len(JOINTS), 3))
    root = np.tile(BODY.rest[0], (2, 1))
    root[1, 0] = 30.0  # walked far out of the frame
    vis = landmark_visibility(Pose(a, root, BODY), Camera.for_view("front", SIZE, BODY.height))
    assert np.delete(vis[0], HEELS).all() and not vis[1].any()


# ----------------------------------------------------------------- styles
@pytest.mark.parametrize("style", ["mannequin", "stick", "markers"])
@pytest.mark.parametrize("view", ["front", "45", "side"])
def test_styles_draw_the_figure_where_it_is(style, view):
    pose = _pose(2, right_shoulder=(np.pi / 2, 0.0, 0.0))
    cam = Camera.for_view(view, SIZE, BODY.height)
    r = make_renderer(pose, cam, style)
    assert len(r) == 2
    img = r.frame(0)
    assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
    changed = np.any(np.abs(img.astype(int) - r.background) > 30, axis=2)
    ys, xs = np.nonzero(changed)
    uv = cam.project(pose.joints[0])
    # The drawing covers the projected skeleton's box and little else.
    assert xs.min() <= uv[:, 0].min() + 3 and xs.max() >= uv[:, 0].max() - 3
    assert ys.min() <= uv[:, 1].min() + 3 and ys.max() >= uv[:, 1].max() - 3
    assert changed.mean() < 0.25


def test_mannequin_front_and_back_differ_at_the_head():
    cam = Camera.for_view("front", (320, 240), BODY.height)
    front, back = _pose(), _pose(pelvis=(0.0, 0.0, np.pi))
    u, v = np.round(cam.project(front.points["head_centre"][0])).astype(int)
    box = (slice(v - 3, v + 4), slice(u - 3, u + 4))
    face = make_renderer(front, cam, "mannequin").frame(0)[box].mean()
    hair = make_renderer(back, cam, "mannequin").frame(0)[box].mean()
    assert face > hair + 40  # skin and eyes in front, dark hair behind


def test_marker_colours_are_distinct_and_hsv_separable():
    hues = [h for h, s, v in MARKER_HSV.values()]
    assert len(set(hues)) == len(MARKER_JOINTS) == len(MARKER_COLOURS)
    circ = np.abs(np.subtract.outer(hues, hues))
    circ = np.minimum(circ, 180 - circ) + np.eye(len(hues)) * 180
    assert circ.min() >= 10
    for j, bgr in MARKER_COLOURS.items():
        hsv = cv2.cvtColor(np.array([[bgr]], np.uint8), cv2.COLOR_BGR2HSV)[0, 0]
        assert abs(int(hsv[0]) - MARKER_HSV[j][0]) <= 1 and hsv[1] == 255 and hsv[2] == 255


@pytest.mark.parametrize("view", ["front", "side"])
def test_markers_show_exactly_the_visible_joints(view):
    cam = Camera.for_view(view, (320, 240), BODY.height)
    r = make_renderer(_pose(), cam, "markers")
    img = r.frame(0)
    hsv = cv2.cvtColor(img, cv2.COLOR_BGR2HSV).astype(int)
    saturated = hsv[..., 1] > 200
    uv = cam.project(np.stack([r.pose.points[j][0] for j in MARKER_JOINTS]))
    for k, joint in enumerate(MARKER_JOINTS):
        dh = np.abs(hsv[..., 0] - MARKER_HSV[joint][0])
        mask = saturated & (np.minimum(dh, 180 - dh) <= 2)
        if r.visible[0, k]:
            u, v = np.round(uv[k]).astype(int)
            assert mask[v, u], joint
        else:
            assert mask.sum() == 0, joint
    if view == "side":
        assert not r.visible[0, MARKER_JOINTS.index("left_knee")]
        assert r.visible[0, MARKER_JOINTS.index("right_knee")]


def test_stick_figure_is_black_lines_on_white():
    cam = Camera.for_view("front", (320, 240), BODY.height)
    img = make_renderer(_pose(), cam, "stick").frame(0)
    a, b = cam.project(_pose().points["right_hip"][0]), cam.project(_pose().points["right_knee"][0])
    mid = np.round((a + b) / 2).astype(int)
    assert img[mid[1] - 1 : mid[1] + 2, mid[0] - 1 : mid[0] + 2].min() < 60
    assert np.median(img) > 200


def test_unknown_style_and_bad_pose_raise():
    with pytest.raises(SyntheticError, match="style"):
        make_renderer(_pose(), Camera.for_view("front", SIZE), "cartoon")
    a = np.zeros((2, len(JOINTS), 3))
    a[1, 3, 0] = np.nan
    with pytest.raises(SyntheticError, match="frame 1"):
        Pose(a, np.zeros((2, 3)), BODY)


# ----------------------------------------------------------------- writers and job
def test_mp4_round_trip(tmp_path):
    frames = [np.full((48, 64, 3), 40 * k, np.uint8) for k in range(5)]
    with open_writer(tmp_path / "v.mp4", 10, (64, 48)) as w:
        for f in frames:
            w.write(f)
    cap = cv2.VideoCapture(str(tmp_path / "v.mp4"))
    got = []
    while True:
        ok, f = cap.read()
        if not ok:
            break
        got.append(f)
    cap.release()
    assert len(got) == 5 and got[0].shape == (48, 64, 3)
    assert [round(float(g.mean()) / 40) for g in got] == [0, 1, 2, 3, 4]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.mp4"]


def test_png_folder_is_exact_and_replaced_whole(tmp_path):
    rng = np.random.default_rng(1)
    frames = rng.integers(0, 256, size=(3, 20, 24, 3), dtype=np.uint8)
    target = tmp_path / "frames"
    target.mkdir()
    (target / "stale.png").write_bytes(b"old")
    with open_writer(target, 25, (24, 20)) as w:
        for f in frames:
            w.write(f)
    names = sorted(p.name for p in target.iterdir())
    assert names == ["frame_000000.png", "frame_000001.png", "frame_000002.png"]
    for k, name in enumerate(names):
        np.testing.assert_array_equal(cv2.imread(str(target / name)), frames[k])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frames"]


@pytest.mark.parametrize("name", ["v.mp4", "frames"])
def test_failed_write_leaves_nothing(tmp_path, name):
    with pytest.raises(SyntheticError, match="frame 1"), open_writer(tmp_path / name, 25, (32, 24)) as w:
        w.write(np.zeros((24, 32, 3), np.uint8))
        w.write(np.zeros((24, 31, 3), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_render_pose_writes_consistent_truth(tmp_path):
    n = 6
    a = np.zeros((n, len(JOINTS), 3))
    a[:, joint_index("right_shoulder"), 0] = np.linspace(0, np.pi, n)
    pose = Pose(a, np.tile(BODY.rest[0], (n, 1)), BODY, 12.5)
    video = render_pose(pose, tmp_path, size=(96, 72), view="45", style="stick", score_json='{"a": 1}')
    assert video == tmp_path / "video.mp4" and video.stat().st_size > 0
    t = read_truth(tmp_path / "truth.npz")
    assert t.fps == 12.5 and t.n_frames == n and t.view == "45" and t.style == "stick"
    assert t.joint_names == JOINTS and t.image_size == (96, 72) and t.score == '{"a": 1}'
    np.testing.assert_allclose(t.joints, forward_kinematics(a, pose.root, BODY), atol=1e-12)
    cam = Camera(t.K, t.R, t.t, t.image_size)
    np.testing.assert_allclose(t.keypoints, cam.project(t.landmarks3d), atol=1e-9)
    # The camera written is the preset that drew the frames.
    np.testing.assert_allclose(cam.position, Camera.for_view("45", (96, 72), 1.70).position, atol=1e-12)
    assert set(np.unique(t.visibility)) <= {0.0, 1.0}


def test_visibility_of_a_long_take_equals_frame_by_frame():
    rng = np.random.default_rng(7)
    n = 300  # more than one block of the chunked test
    pose = Pose(BODY.clip(rng.uniform(-2.0, 2.0, size=(n, len(JOINTS), 3))), np.tile(BODY.rest[0], (n, 1)), BODY)
    cam = Camera.for_view("45", SIZE, BODY.height)
    a, b, r = body_capsules(pose)
    whole = point_visibility(cam, pose.landmarks, a, b, r)
    single = np.concatenate(
        [point_visibility(cam, pose.landmarks[i : i + 1], a[i : i + 1], b[i : i + 1], r) for i in range(n)]
    )
    np.testing.assert_array_equal(whole, single)
    assert 0.3 < whole.mean() < 0.95  # random poses hide some points, not all


def test_mannequin_shirt_has_a_v_neck_only_at_the_front():
    cam = Camera.for_view("front", (640, 480), BODY.height)
    front, back = _pose(), _pose(pelvis=(0.0, 0.0, np.pi))
    # A point inside the V, on the chest's front; the same pixel seen from behind is the shirt's back.
    u, v = np.round(cam.project(np.array([0.0, 0.05, 0.79]) * BODY.height)).astype(int)
    green = [int(make_renderer(p, cam, "mannequin").frame(0)[v, u, 1]) for p in (front, back)]
    assert green[0] > 110 and green[1] < 100  # skin (G ≈ 144) in front, red shirt (G ≈ 64) behind


@pytest.mark.parametrize(
    ("height", "pitch", "roll"), [(0.5, 10.0, 5.0), (1.6, -15.0, 0.0), (2.0, 17.5, 2.5), (1.0, 0.0, -8.0)]
)
def test_the_floor_is_drawn_below_the_horizon_for_any_phone_camera(height, pitch, roll):
    # Reference: geometry.  A level floor seen by an upright camera lies
    # below the horizon: the top corners show the wall, the bottom ones the
    # floor (a camera pitched up had the floor drawn above the horizon).
    from synthetic.render.camera import Camera
    from synthetic.render.scene import floor_background

    wall, floor = (236, 232, 226), (196, 204, 212)
    cam = Camera.phone("front", (640, 480), 1.7, height=height, pitch_deg=pitch, roll_deg=roll, hfov_deg=65.0)
    img = floor_background(cam, wall=wall, floor=floor)
    for y, x in ((0, 0), (0, 639)):
        np.testing.assert_array_equal(img[y, x], wall)
    for y, x in ((479, 2), (479, 637)):  # clear of the grid lines' column at the edge
        assert np.abs(img[y, x].astype(int) - floor).max() <= 30


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.floats(-1e7, 1e7), st.floats(-1e7, 1e7)), min_size=3, max_size=8),
)
def test_polygons_are_cut_to_the_box_without_leaving_it(points):
    from synthetic.render.scene import _clip_to_box

    hull = cv2.convexHull(np.array(points, np.float32).reshape(-1, 1, 2)).reshape(-1, 2).astype(float)
    cut = _clip_to_box(hull, -64.0, np.array([704.0, 544.0]))
    assert np.all(cut >= -64.0 - 1e-6) and np.all(cut <= np.array([704.0, 544.0]) + 1e-6)
    # A box corner is inside the cut polygon exactly when it is inside the hull.
    if len(cut) >= 3:
        for corner in ((-64.0, -64.0), (704.0, 544.0)):
            inside_hull = cv2.pointPolygonTest(hull.astype(np.float32).reshape(-1, 1, 2), corner, True) > 1e-3
            if inside_hull:
                assert cv2.pointPolygonTest(cut.astype(np.float32).reshape(-1, 1, 2), corner, True) >= -1e-2
