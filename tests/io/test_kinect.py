"""Kinect v2 skeleton CSV (LabanotationSuite format): layout, tracking states, gaps, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.errors import MotionFileError
from capture2notation.fitting import PoseModel
from capture2notation.fitting.motion import read_motion
from capture2notation.io.kinect import (
    KINECT_JOINTS,
    KINECT_TO_JOINT,
    camera_to_world,
    read_kinect_csv,
    world_to_camera,
    write_kinect_csv,
)

# The performer stands 2.5 m in front of a sensor 0.8 m above the floor.
_SENSOR = np.array([0.0, 2.5, 0.8])


def _pose_sequence(T=15):
    """Angles, root and the model's points for a right-arm raise (feet on the floor)."""
    body = Body()
    model = PoseModel(body)
    ang = np.zeros((T, len(JOINTS), 3))
    ang[:, joint_index("right_shoulder"), 0] = np.linspace(0.0, 1.6, T)
    ang[:, joint_index("left_elbow"), 0] = np.linspace(0.0, 1.0, T)
    root = np.tile(body.rest[0], (T, 1))
    pts = model.forward(model.params(ang, root))
    return model, pts


def _kinect_rows(model, pts):
    """Camera-space positions (T, 25, 3) of the Kinect joints for our model's points."""
    T = pts.shape[0]
    out = np.zeros((T, 25, 3))
    for k, name in enumerate(KINECT_JOINTS):
        if name in KINECT_TO_JOINT:
            p = pts[:, model.index(KINECT_TO_JOINT[name][0])]
        elif name == "Neck":
            p = 0.5 * (pts[:, model.index("neck")] + pts[:, model.index("head_centre")])
        else:  # hands and thumbs: between wrist and hand tip
            side = "left" if "Left" in name else "right"
            p = 0.5 * (pts[:, model.index(f"{side}_wrist")] + pts[:, model.index(f"{side}_hand_tip")])
        out[:, k] = p
    # World -> camera space: the sensor looks along world -y at the performer.
    return world_to_camera(out - _SENSOR)


def test_joint_order_is_the_kinect_sdk_order():
    assert len(KINECT_JOINTS) == 25
    assert KINECT_JOINTS[:4] == ("SpineBase", "SpineMid", "Neck", "Head")
    assert KINECT_JOINTS[20] == "SpineShoulder" and KINECT_JOINTS[24] == "ThumbRight"


def test_camera_axes_map_to_ours():
    # Sensor-left (+x) is the facing performer's right (+x); up is up; away from the sensor is -y.
    np.testing.assert_allclose(
        camera_to_world(np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])), [[1, 0, 0], [0, 0, 1], [0, -1, 0]]
    )
    p = np.random.default_rng(0).normal(size=(4, 3))
    np.testing.assert_allclose(world_to_camera(camera_to_world(p)), p)


def test_csv_of_a_known_pose_reads_back_as_that_pose(tmp_path):
    model, pts = _pose_sequence()
    T = pts.shape[0]
    cam = _kinect_rows(model, pts)
    states = np.full((T, 25), 2)
    path = write_kinect_csv(tmp_path / "take.csv", np.arange(T) / 30.0, cam, states)
    first = path.read_text().splitlines()[0].split(",")
    assert len(first) == 101 and int(first[0]) > 10**7  # ticks, no header
    m = read_motion(path)
    assert m.source == "kinect" and m.fps == pytest.approx(30.0, rel=1e-5)
    truth = pts[:, : len(JOINTS)]
    limbs = [
        ("right_shoulder", "right_elbow"),
        ("right_elbow", "right_wrist"),
        ("left_elbow", "left_wrist"),
        ("right_hip", "right_knee"),
        ("left_knee", "left_ankle"),
    ]
    for a, b in limbs:
        u = truth[:, joint_index(b)] - truth[:, joint_index(a)]
        v = m.joints[:, joint_index(b)] - m.joints[:, joint_index(a)]
        cos = np.sum(u * v, -1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
        assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 3.0, (a, b)
    # Floor at z = 0 and the performer at the origin facing +y.
    assert abs(m.joints[0, joint_index("pelvis"), 0]) < 0.01 and abs(m.joints[0, joint_index("pelvis"), 1]) < 0.01
    np.testing.assert_allclose(
        m.joints[:, joint_index("right_ankle"), 2], truth[:, joint_index("right_ankle"), 2], atol=0.02
    )
    assert m.joints[0, joint_index("right_hip"), 0] > m.joints[0, joint_index("left_hip"), 0]


def test_tracking_states_and_dropped_frames(tmp_path):
    model, pts = _pose_sequence(10)
    cam = _kinect_rows(model, pts)
    states = np.full((10, 25), 2)
    states[:, KINECT_JOINTS.index("WristRight")] = 1  # inferred
    states[:, KINECT_JOINTS.index("HandTipLeft")] = 0  # not tracked
    times = np.arange(10) / 30.0
    times[5:] += 2 / 30.0  # two frames dropped after the fifth
    path = write_kinect_csv(tmp_path / "gaps.csv", times, cam, states)
    _t, pos, conf, fps = read_kinect_csv(path)
    assert pos.shape == (12, 25, 3) and fps == pytest.approx(30.0, rel=1e-5)
    assert np.all(np.isnan(pos[5:7])) and np.all(conf[5:7] == 0)
    assert np.all(np.isnan(pos[:, KINECT_JOINTS.index("HandTipLeft")]))
    np.testing.assert_allclose(conf[0, KINECT_JOINTS.index("WristRight")], 0.3)
    m = read_motion(path)
    assert np.all(np.isnan(m.joints[5:7])) and np.all(m.confidence[5:7] == 0)
    rw, lt, re = (joint_index(n) for n in ("right_wrist", "left_hand_tip", "right_elbow"))
    ok = np.r_[0:5, 7:12]
    assert np.all(m.confidence[ok, rw] < 0.35) and np.all(m.confidence[ok, lt] < 0.6)
    assert np.all(m.confidence[ok, re] > 0.8)


def test_millisecond_timestamps_are_accepted(tmp_path):
    model, pts = _pose_sequence(4)
    cam = _kinect_rows(model, pts)
    rows = [",".join([str(40 * i)] + [f"{v:.4f}" for j in range(25) for v in (*cam[i, j], 2)]) for i in range(4)]
    path = tmp_path / "ms.csv"
    path.write_text("\n".join(rows) + "\n")
    t, _, _, fps = read_kinect_csv(path)
    assert fps == pytest.approx(25.0) and t[-1] == pytest.approx(0.12)


@pytest.mark.parametrize(
    "line, message",
    [
        ("time,x,y,z,s", ":1: expected a timestamp and 25 joints"),
        (",".join(["100000000"] + ["0.1"] * 100), ":1: tracking state of SpineBase is 0.1"),
        (",".join(["100000000"] + ["a"] * 100), ":1: expected numbers, found 'a'"),
    ],
)
def test_malformed_rows_name_the_line(tmp_path, line, message):
    path = tmp_path / "bad.csv"
    path.write_text(line + "\n")
    with pytest.raises(MotionFileError, match=message):
        read_kinect_csv(path)


@settings(max_examples=25, deadline=None)
@given(T=st.integers(1, 6), seed=st.integers(0, 2**31 - 1))
def test_csv_round_trip_keeps_tracked_values(tmp_path_factory, T, seed):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(-2.0, 4.0, (T, 25, 3))
    states = rng.integers(0, 3, (T, 25))
    path = write_kinect_csv(tmp_path_factory.mktemp("k") / "r.csv", np.arange(T) / 30.0, pos, states)
    _t, got, conf, _ = read_kinect_csv(path)
    assert got.shape == (T, 25, 3)
    tracked = states > 0
    np.testing.assert_allclose(got[tracked], pos[tracked], atol=1e-6)
    assert np.all(np.isnan(got[~tracked]))
    np.testing.assert_allclose(conf, np.array([0.0, 0.3, 1.0])[states])


# --- bad input: one-line errors naming the line and the value (issue 16) --------------------------


def _fixture_with(fixture_path, tmp_path, row: int, field: int, value: str):
    """The LabanotationSuite fixture with field `field` of data row `row` (0-based) set to `value`."""
    lines = fixture_path("kinect/joints.csv").read_text().splitlines()
    cells = lines[row].split(",")
    cells[field] = value
    lines[row] = ",".join(cells)
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    "row, value, message",
    [
        (5, "nan", r":6: timestamp is 'nan'; expected a finite number"),
        (5, "inf", r":6: timestamp is 'inf'"),
        # 10¹⁵ ticks in the middle: the next row goes back in time, and the message shows both values.
        (5, "1000000000000000", r":7: timestamp 31869373727 is earlier than the 1e\+15 of line 6"),
        # 10¹⁵ ticks on the last row: 3 years after the first.
        (-1, "1000000000000000", r":371: timestamp 1e\+15 is 1e\+08 s after the first row; .* at most 6 h"),
        (0, "-1000000000000000", r":2: timestamp 31867714704 is 1e\+08 s after the first row"),
    ],
)
def test_bad_timestamps_are_one_line_errors(fixture_path, tmp_path, row, value, message):
    path = _fixture_with(fixture_path, tmp_path, row, 0, value)
    with pytest.raises(MotionFileError, match=message) as err:
        read_kinect_csv(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_rows_all_at_one_time_are_refused(tmp_path):
    row = ",".join(["100000000"] + ["0.1", "0.2", "2.0", "2"] * 25)
    path = tmp_path / "same.csv"
    path.write_text(f"{row}\n{row}\n")
    with pytest.raises(MotionFileError, match="all 2 rows have the timestamp 100000000"):
        read_kinect_csv(path)


@pytest.mark.parametrize("value", ["nan", "inf", "-1e300", "11.0"])
def test_a_corrupt_tracked_position_is_missing_with_zero_confidence(fixture_path, tmp_path, caplog, value):
    # Field 5 is SpineMid's x (SpineBase x, y, z, state come first); its state is 2 (tracked).
    path = _fixture_with(fixture_path, tmp_path, 3, 5, value)
    with caplog.at_level("WARNING", logger="capture2notation.io.kinect"):
        _t, pos, conf, _ = read_kinect_csv(path)
    _t, clean, clean_conf, _ = read_kinect_csv(fixture_path("kinect/joints.csv"))
    j = KINECT_JOINTS.index("SpineMid")
    frame = int(np.flatnonzero(np.isnan(pos[:, j, 0]) & np.isfinite(clean[:, j, 0]))[0])
    assert np.all(np.isnan(pos[frame, j])) and conf[frame, j] == 0
    keep = np.ones(pos.shape[:2], bool)
    keep[frame, j] = False
    np.testing.assert_array_equal(np.nan_to_num(pos[keep], nan=7.0), np.nan_to_num(clean[keep], nan=7.0))
    np.testing.assert_array_equal(conf[keep], clean_conf[keep])
    (msg,) = [r.getMessage() for r in caplog.records]
    assert msg.startswith(f"{path}:4: SpineMid is at [")
    assert msg.endswith("]: 1 tracked positions are not finite or beyond 10 m; read as not tracked")
