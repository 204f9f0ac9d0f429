"""A face seen at the head (:mod:`capture2notation.keypoints.face`): the mannequin from
the front and from behind, and a real person facing the camera."""

from __future__ import annotations

import json

import numpy as np
import pytest

from capture2notation.keypoints.face import CROP_PX, FaceDetector, head_crop


def _views(pose):
    """The pose's frames and truth keypoints from the front and from behind (the camera taken round the body)."""
    from synthetic import render

    front = render.Camera.for_view("front", (640, 480), pose.body.height)
    half_turn = np.diag([-1.0, -1.0, 1.0])  # about the vertical through the performer's spot
    back = render.Camera(front.K, front.R @ half_turn, front.t, front.size)
    for cam in (front, back):
        truth = render.truth_fields(pose, cam)
        yield list(render.render_frames(pose, cam, "mannequin")), truth["keypoints"]


def test_the_mannequin_shows_a_face_from_the_front_and_none_from_behind(demo_pose):
    detector = FaceDetector()
    (front, front_xy), (back, back_xy) = _views(demo_pose(8))
    found_front = [detector(img, xy) for img, xy in zip(front, front_xy)]
    found_back = [detector(img, xy) for img, xy in zip(back, back_xy)]
    # From the front the face is drawn in every frame; the detector, like on
    # turning renders, finds it in most.  From behind there is only hair.
    assert np.mean(found_front) >= 0.5
    assert np.sum(found_back) == 0


def test_a_real_person_facing_the_camera_shows_a_face(fixture_path):
    import cv2

    video = fixture_path("mediapipe/pose_squats.mp4")
    landmarks = np.asarray(json.loads(fixture_path("mediapipe/pose_squats.full.json").read_text()), float)
    detector = FaceDetector()
    cap = cv2.VideoCapture(str(video))
    found = []
    try:
        for xy in landmarks:
            ok, image = cap.read()
            if not ok:
                break
            found.append(detector(image, xy[:, :2]))
    finally:
        cap.release()
    # She faces the camera throughout (the fixture's README).
    assert len(found) == len(landmarks)
    assert np.mean(found) >= 0.9


def test_a_head_that_cannot_be_placed_reads_nan():
    image = np.zeros((480, 640, 3), np.uint8)
    xy = np.full((33, 2), np.nan)
    assert np.isnan(FaceDetector()(image, xy))
    xy[:11] = (320.0, 100.0)  # a head, but no shoulders or hips to size the crop
    assert head_crop(image, xy) is None
    xy[11:13] = (320.0, 160.0)
    xy[23:25] = (320.0, 300.0)
    crop = head_crop(image, xy)
    assert crop.shape == (CROP_PX, CROP_PX)
    assert FaceDetector()(image, xy) == 0.0  # a black frame has no face


@pytest.mark.parametrize("where", ["left", "right", "top", "bottom"])
def test_a_head_at_the_image_edge_is_cropped_without_error(where):
    image = np.full((120, 160, 3), 128, np.uint8)
    x = {"left": -30.0, "right": 190.0}.get(where, 80.0)
    y = {"top": -30.0, "bottom": 150.0}.get(where, 60.0)
    xy = np.full((33, 2), np.nan)
    xy[:11] = (x, y)
    xy[11:13] = (x, y + 40.0)
    xy[23:25] = (x, y + 120.0)
    assert FaceDetector()(image, xy) == 0.0


@pytest.mark.model
def test_extract_looks_for_a_face_every_few_frames(blazepose, demo_pose):
    from capture2notation.keypoints import extract_frames
    from capture2notation.keypoints.face import FACE_EVERY_S
    from synthetic import render

    pose = demo_pose(12, 25.0)
    cam = render.Camera.for_view("front", (640, 480), pose.body.height)
    track = extract_frames(render.render_frames(pose, cam, "mannequin"), pose.fps, estimator=blazepose)
    looked = np.flatnonzero(np.isfinite(track.face))
    # Every FACE_EVERY_S from the first frame (every third at 25 fps).
    np.testing.assert_array_equal(looked, np.arange(0, 12, int(round(FACE_EVERY_S * 25.0))))
    assert np.mean(track.face[looked]) >= 0.5  # the mannequin faces the camera
    off = extract_frames(render.render_frames(pose, cam, "mannequin"), pose.fps, estimator=blazepose, faces=False)
    assert np.isnan(off.face).all()
