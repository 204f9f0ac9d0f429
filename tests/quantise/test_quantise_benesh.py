"""Benesh key poses: stave heights, widths, depths, bends, head and body."""

from __future__ import annotations

import json

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import QuantiseError
from capture2notation.quantise.benesh import benesh_json, benesh_key_poses, estimate_stave, write_benesh


def _poses(*frames_deg, height=1.70):
    a = np.zeros((len(frames_deg), len(JOINTS), 3))
    for t, d in enumerate(frames_deg):
        for name, v in d.items():
            a[t, joint_index(name)] = np.radians(v)
    body = Body(height)
    root = np.tile(body.rest[0], (len(frames_deg), 1))
    return forward_kinematics(a, root, body), a


def _ext(pose, name):
    return dict(pose.extremities)[name]


@pytest.mark.parametrize("height", [1.5, 1.70, 1.9])
def test_stave_lines_follow_the_dancers_proportions(height):
    joints, _ = _poses({}, {"right_knee": (-60, 0, 0)}, height=height)
    st = estimate_stave(joints)
    body = Body(height)
    z = body.rest[:, 2]
    expect = [0.0, z[joint_index("right_knee")], z[joint_index("right_hip")], z[joint_index("right_shoulder")], height]
    assert np.allclose(st.lines, expect, atol=1e-9)


def test_extremities_on_the_stave():
    joints, angles = _poses(
        {},  # standing, arms down
        {"right_shoulder": (0, -90, 0)},  # right arm out to the side, horizontal
        {"right_shoulder": (90, 0, 0), "left_shoulder": (180, 0, 0)},  # right forward, left straight up
        {"left_hip": (-40, 0, 0)},  # left leg lifted behind
    )
    st, poses = benesh_key_poses(joints, [0, 1, 2, 3], fps=25, tempo=60, angles=angles)
    body = Body()
    wrist_z = body.rest[joint_index("right_wrist"), 2]
    knee_z, hip_z = st.lines[1], st.lines[2]
    # Standing: the hands hang between the knee and hip lines.
    h = _ext(poses[0], "right_hand")
    assert h.height == pytest.approx(1 + (wrist_z - knee_z) / (hip_z - knee_z), abs=1e-3)
    assert h.depth == "level" and h.width > 0 > _ext(poses[0], "left_hand").width
    # Arm to the side: on the shoulder line at full reach.
    h = _ext(poses[1], "right_hand")
    assert h.height == pytest.approx(3.0, abs=1e-3) and h.width == pytest.approx(1.0, abs=1e-3) and h.depth == "level"
    # Forward: shoulder height, in front; straight up: well above the head line.
    h = _ext(poses[2], "right_hand")
    assert h.height == pytest.approx(3.0, abs=1e-3) and h.depth == "front"
    up = _ext(poses[2], "left_hand")
    assert 4.5 < up.height < 6.0 and up.depth == "level"
    assert _ext(poses[3], "left_foot").depth == "behind"
    assert _ext(poses[3], "right_foot").height == pytest.approx(_ext(poses[0], "right_foot").height)
    assert poses[2].beat == 0 and poses[1].time == pytest.approx(0.04)


def test_bends_head_and_body():
    joints, angles = _poses(
        {
            "right_elbow": (90, 0, 0),
            "left_knee": (-60, 0, 0),
            "neck": (-30, 0, 0),
            "waist": (0, 20, 0),
            "chest": (0, 0, 30),
        },
    )
    _, (p,) = benesh_key_poses(joints, [0], fps=25, angles=angles)
    assert dict(p.bends) == {"right_elbow": 3, "left_knee": 2}
    assert p.head.bend > 20  # tipped forward
    assert p.body.tilt == pytest.approx(20.0, abs=1e-6)  # waist ry > 0 tips an upright trunk to the right
    assert p.body.turn < -20  # chest rz > 0 turns the shoulders to the left (anticlockwise from above)
    assert p.beat is None
    _, (q,) = benesh_key_poses(joints, [0], fps=25, default_bend={"elbow": 3})
    # Against a default of 3 (a rounded-arm style) the straight left elbow is the exception.
    assert dict(q.bends) == {"left_elbow": 0, "left_knee": 2} and np.isnan(q.head.turn)


def test_json_round_trip(tmp_path):
    joints, angles = _poses({}, {"right_shoulder": (0, -90, 0)})
    st, poses = benesh_key_poses(joints, [0, 1], fps=25, tempo=90, angles=angles)
    path = tmp_path / "benesh.json"
    write_benesh(path, st, poses, tempo=90)
    doc = json.loads(path.read_text())
    assert list(doc["stave"]["lines"]) == ["floor", "knee", "hip", "shoulder", "head_top"]
    assert doc["poses"][1]["extremities"]["right_hand"]["width"] == pytest.approx(1.0, abs=1e-3)
    assert doc["tempo"] == "90"
    assert benesh_json(st, poses, 90) == path.read_text()


def test_bad_frames_are_named():
    joints, _ = _poses({})
    with pytest.raises(QuantiseError, match="key frame 5"):
        benesh_key_poses(joints, [5], fps=25)


def test_key_poses_record_the_unwrapped_facing():
    from capture2notation.notation.formats import lab
    from synthetic import interpret

    score = lab.loads("tempo: 60\n0 1 turn right amount=1\n1 1 turn right amount=1/2\n2 1 turn left amount=1/4\n")
    m = interpret(score, fps=25)
    stave, poses = benesh_key_poses(m.joints(), [0, 25, 50, 75], 25)
    # One full turn, then a half, then back a quarter: 360, 540, 450 degrees (unwrapped).
    assert [round(p.facing, 6) for p in poses] == [0.0, 360.0, 540.0, 450.0]
    doc = json.loads(benesh_json(stave, poses))
    assert [p["facing"] for p in doc["poses"]] == [0.0, 360.0, 540.0, 450.0]
