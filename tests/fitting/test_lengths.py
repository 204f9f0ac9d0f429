"""Per-clip segment lengths."""

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import FittingError
from capture2notation.fitting import estimate_offsets
from capture2notation.fitting.lengths import scale_of


def _points(scale=1.0, T=10, seed=0):
    rng = np.random.default_rng(seed)
    body = Body(1.70 * scale)
    ang = body.clip(rng.normal(0, 0.4, (T, len(JOINTS), 3)))
    return body, forward_kinematics(ang, np.zeros((T, 3)), body)


@pytest.mark.parametrize("scale", [0.85, 1.0, 1.15])
def test_lengths_of_a_scaled_figure_are_recovered(scale):
    body, pts = _points(scale)
    off = estimate_offsets(pts, np.ones(pts.shape[:2]), Body())
    np.testing.assert_allclose(off, body.offsets, atol=1e-9)
    assert scale_of(off) == pytest.approx(scale_of(body.offsets), rel=1e-12)


def test_unmeasured_segments_take_the_median_ratio_and_sides_are_averaged():
    _body, pts = _points(1.1)
    conf = np.ones(pts.shape[:2])
    conf[:, joint_index("waist")] = 0.0  # pelvis->waist and waist->chest unmeasured
    pts = pts.copy()
    w, tip = joint_index("left_wrist"), joint_index("left_hand_tip")
    pts[:, tip] = pts[:, w] + 1.1 * (pts[:, tip] - pts[:, w])  # left hand 10 % longer
    off = estimate_offsets(pts, conf, Body())
    np.testing.assert_allclose(
        np.linalg.norm(off[joint_index("waist")]), 1.1 * np.linalg.norm(Body().offsets[joint_index("waist")]), rtol=1e-9
    )
    base = np.linalg.norm(Body().offsets[tip])
    for name in ("right_hand_tip", "left_hand_tip"):
        assert np.linalg.norm(off[joint_index(name)]) == pytest.approx(1.1 * 1.05 * base, rel=1e-9)


def test_nan_points_are_ignored_and_bad_shapes_rejected():
    body, pts = _points(1.0)
    pts = pts.copy()
    pts[::2, joint_index("right_wrist")] = np.nan
    off = estimate_offsets(pts, np.ones(pts.shape[:2]), Body())
    np.testing.assert_allclose(off, body.offsets, atol=1e-9)
    with pytest.raises(FittingError, match="points"):
        estimate_offsets(pts[:, :5], np.ones((10, 5)))


def test_segments_left_out_of_the_scale_do_not_move_the_others():
    from capture2notation.fitting.lengths import offsets_from_ratios

    body = Body()
    ratio = np.full(len(JOINTS), 1.0)
    ratio[0] = np.nan
    arms = [joint_index(f"{s}_{j}") for s in ("right", "left") for j in ("elbow", "wrist")]
    long_arms = ratio.copy()
    long_arms[arms] = 1.1
    keep = np.ones(len(JOINTS), bool)
    keep[arms] = False
    base = np.linalg.norm(offsets_from_ratios(ratio, body, relative=True), axis=1)
    out = np.linalg.norm(offsets_from_ratios(long_arms, body, relative=True, scale_from=keep), axis=1)
    others = np.setdiff1d(np.arange(1, len(JOINTS)), arms)
    np.testing.assert_allclose(out[others], base[others], rtol=1e-12)
    np.testing.assert_allclose(out[arms], 1.1 * base[arms], rtol=1e-12)
