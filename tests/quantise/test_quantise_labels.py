"""Per-frame labels: direction, level, bend and supports (DESIGN.md thresholds)."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from quantise_motions import arm_angles

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import QuantiseError
from capture2notation.notation.model import DIRECTIONS, LEVELS
from capture2notation.quantise.labels import LABEL_PARTS, label_frames, labels_csv_text, write_labels_csv


def _label(lab, part, t=0):
    c = lab.index(part)
    d, lv, b = lab.direction[t, c], lab.level[t, c], lab.bend[t, c]
    return (list(DIRECTIONS)[d] if d >= 0 else None, LEVELS[lv] if lv >= 0 else None, int(b))


def _pose(**joint_angles_deg):
    a = np.zeros((1, len(JOINTS), 3))
    for name, v in joint_angles_deg.items():
        a[0, joint_index(name)] = np.radians(v)
    return a


def test_rest_pose_is_the_starting_pose():
    lab = label_frames(forward_kinematics(np.zeros((3, len(JOINTS), 3))), fps=25)
    assert _label(lab, "right_arm") == ("place", "low", 0)
    assert _label(lab, "left_leg") == ("place", "low", 0)
    assert _label(lab, "head")[:2] == ("place", "high")
    assert _label(lab, "chest")[:2] == ("place", "high")
    for p in ("support", "right_support", "left_support"):
        assert _label(lab, p)[:2] == ("place", "middle")


def test_arm_directions_and_elbow_bend():
    a = np.concatenate(
        [
            _pose(right_shoulder=(90, 0, 0)),  # forward middle
            _pose(right_shoulder=(0, -90, 0)),  # to the right, horizontal
            _pose(left_shoulder=(0, 90, 0)),  # to the left
            _pose(right_shoulder=(135, 0, 0)),  # forward high
            _pose(right_shoulder=(90, 0, 0), right_elbow=(62, 0, 0)),  # bend 62° -> 2
        ]
    )
    lab = label_frames(forward_kinematics(a), fps=25)
    assert _label(lab, "right_arm", 0) == ("forward", "middle", 0)
    assert _label(lab, "right_arm", 1) == ("right", "middle", 0)
    assert _label(lab, "left_arm", 2) == ("left", "middle", 0)
    assert _label(lab, "right_arm", 3) == ("forward", "high", 0)
    assert _label(lab, "right_arm", 4)[2] == 2
    assert _label(lab, "right_upper_arm", 4)[:2] == ("forward", "middle")
    assert _label(lab, "right_forearm", 4)[:2] == ("forward", "high")
    assert np.isclose(lab.bend_deg[4, lab.index("right_arm")], 62.0, atol=1e-6)


@settings(max_examples=40, deadline=None)
@given(d=st.sampled_from([d for d in DIRECTIONS if d != "place"]), lv=st.sampled_from(LEVELS))
def test_canonical_arm_vectors_classify_back(d, lv):
    a = np.zeros((1, len(JOINTS), 3))
    a[0, joint_index("right_shoulder")] = arm_angles(d, lv)
    a[0, joint_index("left_shoulder")] = arm_angles(d, lv)
    lab = label_frames(forward_kinematics(a), fps=25)
    assert _label(lab, "right_arm") == (d, lv, 0)
    assert _label(lab, "left_arm") == (d, lv, 0)
    assert _label(lab, "right_forearm")[:2] == (d, lv)


def test_support_levels_plie_releve_and_lifted_foot():
    body = Body()
    T = 4
    a = np.zeros((T, len(JOINTS), 3))
    root = np.tile(body.rest[0], (T, 1))
    # Frame 1: plié, 45° at hip and ankle, 90° knee → knees bend 90° > 30°.
    for side in ("right", "left"):
        a[1, joint_index(f"{side}_hip")] = np.radians((45, 0, 0))
        a[1, joint_index(f"{side}_knee")] = np.radians((-90, 0, 0))
        a[1, joint_index(f"{side}_ankle")] = np.radians((45, 0, 0))
    thigh = body.segment_length("right_hip", "right_knee")
    shin = body.segment_length("right_knee", "right_ankle")
    root[1, 2] -= (thigh + shin) * (1 - np.cos(np.radians(45)))
    # Frame 2: relevé, ankles plantar-flexed 30°, root raised so the toes stay down.
    for side in ("right", "left"):
        a[2, joint_index(f"{side}_ankle")] = np.radians((-30, 0, 0))
    j2 = forward_kinematics(a[2:3], root[2:3])
    root[2, 2] -= j2[0, joint_index("right_toe"), 2] - body.rest[joint_index("right_toe"), 2]
    # Frame 3: left foot lifted forward.
    a[3, joint_index("left_hip")] = np.radians((40, 0, 0))
    joints = forward_kinematics(a, root)
    lab = label_frames(joints, fps=25)
    # Stationary feet only: give every frame its own still copy by labelling them one at a time.
    got = [label_frames(np.repeat(joints[t : t + 1], 2, axis=0), fps=25) for t in range(T)]
    assert _label(got[0], "support")[:2] == ("place", "middle")
    assert _label(got[1], "support")[:2] == ("place", "low")
    assert _label(got[2], "support")[:2] == ("place", "high")
    assert _label(got[3], "right_support")[:2] == ("place", "middle")
    assert _label(got[3], "left_support")[:2] == (None, None)
    assert _label(got[3], "support")[:2] == (None, None)
    assert _label(got[3], "left_leg")[:2] == ("forward", "low")
    assert lab.supporting.shape == (T, 2)


def test_moving_foot_does_not_support():
    T = 10
    a = np.zeros((T, len(JOINTS), 3))
    root = np.tile(Body().rest[0], (T, 1))
    root[:, 0] += np.arange(T) * 0.02  # sliding 0.5 m/s: faster than 0.2 m/s
    lab = label_frames(forward_kinematics(a, root), fps=25)
    # The last frame has no future: a foot on the floor there has landed.
    assert not lab.supporting[:-1].any() and lab.supporting[-1].all()


def test_labels_csv_has_a_row_per_frame_and_part(tmp_path):
    a = np.zeros((3, len(JOINTS), 3))
    a[1:, joint_index("right_shoulder")] = np.radians((90, 0, 0))
    lab = label_frames(forward_kinematics(a), fps=25)
    path = tmp_path / "labels.csv"
    write_labels_csv(lab, path)
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    assert len(rows) == 3 * len(LABEL_PARTS)
    assert list(rows[0]) == ["frame", "time", "part", "direction", "level", "bend"]
    r = next(x for x in rows if x["frame"] == "2" and x["part"] == "right_arm")
    assert (r["direction"], r["level"], r["bend"]) == ("forward", "middle", "0")
    assert float(r["time"]) == pytest.approx(2 / 25)
    h = next(x for x in rows if x["frame"] == "0" and x["part"] == "head")
    assert h["bend"] == ""
    assert labels_csv_text(lab) == path.read_text()


def test_missing_joints_give_empty_labels_not_invented_ones():
    j = forward_kinematics(np.zeros((2, len(JOINTS), 3)))
    j[1, joint_index("right_wrist")] = np.nan
    lab = label_frames(j, fps=25)
    assert _label(lab, "right_arm", 1) == (None, None, -1)
    assert _label(lab, "left_arm", 1)[:2] == ("place", "low")


def test_bad_shapes_and_fps_are_rejected():
    with pytest.raises(QuantiseError, match="shape"):
        label_frames(np.zeros((2, 5, 3)), fps=25)
    with pytest.raises(QuantiseError, match="fps"):
        label_frames(np.zeros((2, len(JOINTS), 3)), fps=0)
