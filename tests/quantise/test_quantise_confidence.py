"""Symbol confidence from the fit's confidence and the angle's margin to a boundary."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.notation import Score, Symbol
from capture2notation.quantise.confidence import MARGIN_FULL_DEG, score_confidence, symbol_margin_deg


def _unit(az_deg, el_deg):
    a, e = np.radians(az_deg), np.radians(el_deg)
    return np.array([[np.sin(a) * np.cos(e), np.cos(a) * np.cos(e), np.sin(e)]])


@pytest.mark.parametrize(
    ("az", "el", "margin"),
    [(0, 0, 22.5), (20, 0, 2.5), (45, 10, 12.5), (0, 80, 12.5), (0, -70, 2.5), (-22.5, 0, 0.0)],
)
def test_margin_to_the_nearest_boundary(az, el, margin):
    assert symbol_margin_deg(_unit(az, el))[0] == pytest.approx(margin, abs=1e-6)


def test_azimuth_margin_shrinks_towards_the_vertical():
    # 10 degrees of azimuth from a boundary at 60 degrees elevation is 5 degrees on the sphere.
    assert symbol_margin_deg(_unit(12.5, 60))[0] == pytest.approx(min(7.5, 10 * 0.5), abs=1e-6)


def _held_arm(rx_deg: float, T: int = 50) -> np.ndarray:
    angles = np.zeros((T, len(JOINTS), 3))
    angles[:, joint_index("right_shoulder"), 0] = np.radians(rx_deg)  # forward swing of the hanging arm
    return forward_kinematics(angles, np.tile([0.0, 0.0, 1.0], (T, 1)), Body())


def _score():
    return Score.from_symbols([Symbol(0, 1, "right_arm", "forward", "low")], tempo=60)


def test_a_limb_in_mid_sector_with_a_confident_fit_is_certain():
    joints = _held_arm(45.0)  # forward low: elevation -45, the level's centre
    s = score_confidence(_score(), joints, 25.0).symbols[0]
    assert s.confidence == pytest.approx(1.0)


def test_a_limb_near_a_level_boundary_is_uncertain():
    joints = _held_arm(90.0 - 22.5 - 2.0)  # elevation -20.5: 2 degrees from middle
    s = score_confidence(_score(), joints, 25.0).symbols[0]
    assert s.confidence == pytest.approx(2.0 / MARGIN_FULL_DEG, abs=0.02)
    assert s.uncertain


def test_the_fits_confidence_lowers_it():
    joints = _held_arm(45.0)
    conf = np.ones(joints.shape[:2])
    conf[:, joint_index("right_wrist")] = 0.3
    s = score_confidence(_score(), joints, 25.0, conf).symbols[0]
    assert s.confidence == pytest.approx(0.3)
    missing = joints.copy()
    missing[:, joint_index("right_wrist")] = np.nan
    assert score_confidence(_score(), missing, 25.0).symbols[0].confidence == 0.0
