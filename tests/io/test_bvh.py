"""BVH: the fixtures read with plausible figures; our files round-trip; errors name the line."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import MotionFileError
from capture2notation.fitting.motion import read_motion
from capture2notation.io.bvh import (
    bvh_positions,
    canonical_name,
    map_joints,
    parse_bvh,
    read_bvh_points,
    write_bvh,
)

FIXTURES = [("bvh/jesse_dance.bvh", 1007, 100.0), ("bvh/test_mocapbank.bvh", 455, 30.0)]


@pytest.mark.parametrize("rel, frames, fps", FIXTURES)
def test_fixtures_parse_with_their_frame_counts_and_rates(fixture_path, rel, frames, fps):
    skel = parse_bvh(fixture_path(rel))
    assert skel.motion.shape[0] == frames
    assert skel.fps == pytest.approx(fps, rel=1e-4)
    points, conf, _, _got_fps = read_bvh_points(fixture_path(rel))
    assert points.shape == (frames, len(JOINTS), 3)
    # Every joint we need is found by name in both styles.
    for name in ("pelvis", "right_shoulder", "left_elbow", "right_wrist", "left_hip", "right_knee", "left_ankle"):
        assert conf[0, joint_index(name)] == 1.0, name
    # Metres, z up: the figure is human-sized and the head is above the feet.
    extent = np.nanmax(points[..., 2], axis=1) - np.nanmin(points[..., 2], axis=1)
    assert 1.2 <= np.percentile(extent, 90) <= 2.2
    assert np.all(points[:, joint_index("neck"), 2] > points[:, joint_index("right_ankle"), 2])


def test_mixamo_and_bvh_python_shoulders_are_told_apart():
    mixamo = [
        "mixamorig:Hips",
        "mixamorig:Spine",
        "mixamorig:LeftShoulder",
        "mixamorig:LeftArm",
        "mixamorig:LeftForeArm",
        "mixamorig:LeftHand",
    ]
    m = map_joints(mixamo)
    assert mixamo[m["left_shoulder"]] == "mixamorig:LeftArm"  # LeftShoulder is the collar
    assert mixamo[m["left_elbow"]] == "mixamorig:LeftForeArm"
    other = ["Hips", "Chest", "LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist", "LeftWrist_End"]
    m = map_joints(other)
    assert other[m["left_shoulder"]] == "LeftShoulder"
    assert other[m["left_hand_tip"]] == "LeftWrist_End"
    cmu = ["Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "LowerBack", "Spine", "Spine1"]
    m = map_joints(cmu)
    assert [cmu[m[j]] for j in ("left_hip", "left_knee", "left_ankle", "left_toe", "waist", "chest")] == [
        "LeftUpLeg",
        "LeftLeg",
        "LeftFoot",
        "LeftToeBase",
        "Spine",
        "Spine1",
    ]
    assert canonical_name("mixamorig1:Left_Fore-Arm") == "leftforearm"


def test_user_map_overrides_the_table_and_unknown_names_fail():
    names = ["root", "thing_l", "thing_r"]
    m = map_joints(names, {"thing_l": "left_hip", "thing_r": "right_hip"})
    assert m["left_hip"] == 1 and m["right_hip"] == 2 and m["pelvis"] == 0
    with pytest.raises(MotionFileError, match="not one of our joints"):
        map_joints(names, {"thing_l": "left_flipper"})
    with pytest.raises(MotionFileError, match="not in the file"):
        map_joints(names, {"nope": "left_hip"})


def _motion(T=12, seed=0):
    rng = np.random.default_rng(seed)
    body = Body()
    t = np.arange(T)[:, None] / T
    ang = np.zeros((T, len(JOINTS), 3))
    ang[:, 1:] = rng.normal(0.0, 0.4, (1, len(JOINTS) - 1, 3)) * np.sin(np.pi * t)[..., None]
    ang[:, 0, 2] = 0.5 * t[:, 0]
    ang = body.clip(ang)
    root = np.tile(body.rest[0], (T, 1)) + np.c_[0.2 * t, 0.1 * t, 0 * t]
    return body, ang, root


@pytest.mark.parametrize("unit", ["cm", "m"])
def test_write_then_read_round_trips(tmp_path, unit):
    body, ang, root = _motion()
    path = write_bvh(tmp_path / "m.bvh", ang, root, 25.0, unit=unit)
    m = read_motion(path)
    assert m.source == "bvh" and m.fps == pytest.approx(25.0)
    np.testing.assert_allclose(m.angles, ang, atol=1e-6)
    np.testing.assert_allclose(m.root, root, atol=1e-6)
    np.testing.assert_allclose(m.joints, forward_kinematics(ang, root, body), atol=1e-5)


def test_written_file_is_y_up_with_our_rotation_order(tmp_path):
    body, ang, root = _motion(seed=3)
    path = write_bvh(tmp_path / "m.bvh", ang, root, 25.0, unit="m")
    skel = parse_bvh(path)
    assert skel.channels[0] == ["xposition", "yposition", "zposition", "yrotation", "zrotation", "xrotation"]
    # The file's own FK (any BVH reader) reproduces our joints in y-up axes.
    pos = bvh_positions(skel)
    idx = [skel.names.index(j) for j in JOINTS]
    fk = forward_kinematics(ang, root, body)
    np.testing.assert_allclose(pos[:, idx], np.stack([fk[..., 0], fk[..., 2], -fk[..., 1]], -1), atol=1e-5)
    # A generic reader (IK by name, not our angles) lands on the same joints.
    points, _conf, _, _ = read_bvh_points(path)
    np.testing.assert_allclose(points, fk, atol=1e-5)


@settings(max_examples=25, deadline=None)
@given(order=st.permutations(["X", "Y", "Z"]), angles=st.lists(st.floats(-170, 170), min_size=3, max_size=3))
def test_channel_order_composes_left_to_right(tmp_path_factory, order, angles):
    # One joint below the root: its child's position is R_first R_second R_third @ offset.
    chans = " ".join(f"{a}rotation" for a in order)
    text = (
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 " + chans + "\n End Site\n {\n  OFFSET 0 1 0\n }\n}\n"
        f"MOTION\nFrames: 1\nFrame Time: 0.04\n{angles[0]} {angles[1]} {angles[2]}\n"
    )
    path = tmp_path_factory.mktemp("bvh") / "one.bvh"
    path.write_text(text)
    pos = bvh_positions(parse_bvh(path))[0, 1]
    R = np.eye(3)
    for axis, deg in zip(order, angles):
        c, s = np.cos(np.deg2rad(deg)), np.sin(np.deg2rad(deg))
        i = "XYZ".index(axis)
        j, k = (i + 1) % 3, (i + 2) % 3
        m = np.eye(3)
        m[j, j] = m[k, k] = c
        m[k, j], m[j, k] = s, -s
        R = R @ m
    np.testing.assert_allclose(pos, R @ [0, 1, 0], atol=1e-9)


@pytest.mark.parametrize(
    "text, message",
    [
        ("HIERARCHY\nROOT Hips\n{\n OFFSET 0 zero 0\n", ":4: expected a number for OFFSET of Hips"),
        ("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Wrotation\n}\n", ":5: unknown channel"),
        (
            "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Xrotation\n}\nMOTION\nFrames: 3\nFrame Time: 0.1\n1 2\n",
            "2 values, expected 3 frames",
        ),
        (
            "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Xrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\nx\n",
            ":10: expected a channel value",
        ),
        ("MOTION\n", ":1: expected 'HIERARCHY'"),
    ],
)
def test_malformed_files_name_the_line(tmp_path, text, message):
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    with pytest.raises(MotionFileError, match=message):
        parse_bvh(path)


def test_file_without_needed_joints_asks_for_a_map(tmp_path):
    text = (
        "HIERARCHY\nROOT Blob\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n End Site\n {\n  OFFSET 0 1 0\n }\n}\n"
        "MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n"
    )
    path = tmp_path / "blob.bvh"
    path.write_text(text)
    with pytest.raises(MotionFileError, match="joint_map"):
        read_bvh_points(path)


def test_a_fitted_motion_with_gaps_writes_and_reads_back(tmp_path):
    from capture2notation.fitting import fit_points3d
    from capture2notation.io.bvh import write_motion_bvh

    body, ang, root = _motion(T=10, seed=4)
    pts = forward_kinematics(ang, root, body)
    conf = np.ones(pts.shape[:2])
    pts[4], conf[4] = np.nan, 0.0  # a frame with no data
    fit = fit_points3d(pts, conf, 25.0)
    assert np.all(np.isnan(fit.joints[4]))
    m = read_motion(write_motion_bvh(tmp_path / "fit.bvh", fit))
    ok = np.r_[0:4, 5:10]
    np.testing.assert_allclose(m.joints[ok], fit.joints[ok], atol=1e-5)
    np.testing.assert_allclose(m.root[4], fit.root[3], atol=1e-6)  # the gap holds the last root


# --- bad input: one-line errors naming the line and the value (issue 16) --------------------------

_MOCAP = "bvh/test_mocapbank.bvh"


def _edited(fixture_path, tmp_path, old: str, new: str, name="bad.bvh"):
    """A copy of the mocapbank fixture with the first `old` replaced by `new`."""
    text = fixture_path(_MOCAP).read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("Frames:\t455", "Frames:\t0", r":118: Frames is '0'; expected a whole number from 1 to 1000000"),
        ("Frames:\t455", "Frames:\tinf", r":118: Frames is 'inf'"),
        ("Frames:\t455", "Frames:\tnan", r":118: Frames is 'nan'"),
        ("Frames:\t455", "Frames:\t-1e308", r":118: Frames is '-1e308'"),
        ("Frames:\t455", "Frames:\t-1", r":118: Frames is '-1'"),
        ("Frames:\t455", "Frames:\t2.7", r":118: Frames is '2.7'"),
        ("Frames:\t455", "Frames:\t456", r"motion block has 27300 values, expected 456 frames"),
        ("Frame Time:\t0.033333", "Frame Time:\t1e-300", r":119: Frame Time 1e-300 s .*1e\+300 Hz is outside"),
        ("Frame Time:\t0.033333", "Frame Time:\tnan", r":119: Frame Time is nan"),
        ("Frame Time:\t0.033333", "Frame Time:\t0", r":119: Frame Time 0 s .*not positive"),
        ("CHANNELS 3 Zrotation", "CHANNELS nan Zrotation", r":9: CHANNELS count of Chest is 'nan'"),
        ("CHANNELS 3 Zrotation", "CHANNELS 1e9 Zrotation", r":9: CHANNELS count of Chest is '1e9'"),
        ("CHANNELS 3 Zrotation Xrotation", "CHANNELS 3 Zrotation Zrotation", r":9: channel 'Zrotation' .* twice"),
        ("OFFSET -0.1728 10.2870", "OFFSET nan 10.2870", r":8: OFFSET of Chest is nan"),
        ("OFFSET -0.1728 10.2870", "OFFSET 1e300 10.2870", r":8: OFFSET of Chest is 1e300"),
    ],
)
def test_bad_headers_are_one_line_errors_naming_line_and_value(fixture_path, tmp_path, old, new, message):
    path = _edited(fixture_path, tmp_path, old, new)
    with pytest.raises(MotionFileError, match=message) as err:
        parse_bvh(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_a_declared_frame_count_the_file_cannot_hold_is_refused_before_allocating(tmp_path):
    # 10⁶ frames × 6 channels would be 48 MB; the file is a few hundred bytes.
    text = (
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation"
        " Yrotation\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1000000\nFrame Time: 0.01\n0 0 0 0 0 0\n"
    )
    path = tmp_path / "short.bvh"
    path.write_text(text)
    with pytest.raises(MotionFileError, match=r"declares 6000000 values, but only 12 bytes follow"):
        parse_bvh(path)


def test_non_finite_channel_values_are_missing_joints_not_nonsense(fixture_path, tmp_path, caplog):
    """Three NaN/inf values: those joints (and all below them) are NaN with zero confidence in
    their frames; every other joint and frame reads exactly as in the clean file, and the figure
    is not rescaled."""
    text = fixture_path(_MOCAP).read_text().splitlines()
    m = text.index("MOTION")
    rows = {k: text[m + 3 + k].split() for k in (0, 47)}
    rows[0][5] = "nan"  # frame 0: the root's Yrotation -> everything but the root's own position
    rows[0][10] = "inf"  # frame 0: Chest Xrotation
    rows[47][7] = "-inf"  # frame 47: Chest Zrotation -> the chest and everything above it
    for k, r in rows.items():
        text[m + 3 + k] = " ".join(r)
    path = tmp_path / "nan3.bvh"
    path.write_text("\n".join(text) + "\n")
    with caplog.at_level("WARNING", logger="capture2notation.io.bvh"):
        bad, bad_conf, _, _ = read_bvh_points(path)
    warned = [r.getMessage() for r in caplog.records]
    assert len(warned) == 1 and ":120: Hips Yrotation is nan: 3 channel values" in warned[0]
    assert "in 2 of 455 frames" in warned[0] and not any("scaled" in w for w in warned)
    clean, conf, _, _ = read_bvh_points(fixture_path(_MOCAP))
    pelvis = joint_index("pelvis")
    assert np.all(np.isnan(np.delete(bad[0], pelvis, 0))) and np.all(np.delete(bad_conf[0], pelvis) == 0)
    np.testing.assert_array_equal(bad[0, pelvis], clean[0, pelvis])
    lost = ~np.isfinite(bad[47, :, 0])
    # The chest moves the neck, head, shoulders and arms; the legs and pelvis stay measured.
    for name in ("chest", "neck", "left_shoulder", "right_wrist"):
        assert lost[joint_index(name)], name
    for name in ("pelvis", "left_hip", "right_ankle"):
        assert not lost[joint_index(name)], name
    assert np.all(bad_conf[47, lost] == 0) and np.all(bad_conf[47, ~lost] == conf[47, ~lost])
    keep = np.r_[1:47, 48:455]
    np.testing.assert_array_equal(bad[keep], clean[keep])
    np.testing.assert_array_equal(bad[47, ~lost], clean[47, ~lost])


def test_a_motion_file_with_missing_frames_reads_as_a_normal_size_figure(fixture_path, tmp_path):
    text = fixture_path(_MOCAP).read_text().splitlines()
    m = text.index("MOTION")
    row = text[m + 3].split()
    row[5] = "nan"
    text[m + 3] = " ".join(row)
    path = tmp_path / "nan1.bvh"
    path.write_text("\n".join(text) + "\n")
    clean = read_motion(fixture_path(_MOCAP))
    got = read_motion(path)
    assert np.all(np.delete(got.confidence[0], joint_index("pelvis")) == 0)
    # Within 3 cm of the clean reading everywhere else (the fit smooths across the gap).
    np.testing.assert_allclose(got.joints[5:], clean.joints[5:], atol=0.03)
