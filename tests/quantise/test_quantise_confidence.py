"""Symbol confidence: the fit's confidence times the probability that the true direction lies in the symbol's cell.

Reference values are computed here from the module's stated error model
(normal interval probabilities with scipy.stats.norm), not from its output.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm

from capture2notation.body import JOINTS, Body, forward_kinematics, joint_index
from capture2notation.errors import QuantiseError
from capture2notation.notation import Score, Symbol
from capture2notation.notation.model import TURN_PART
from capture2notation.quantise.confidence import (
    ANGLE_SD_DEG,
    DEPTH_SD_DEG,
    FRAME_YAW_SD_DEG,
    direction_probability,
    score_confidence,
    symbol_margin_deg,
    turn_probability,
)


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


def _p(x, lo, hi, sd):
    return norm.cdf((hi - x) / sd) - norm.cdf((lo - x) / sd)


def _p_forward_low(el_deg: float) -> float:
    """The stated model's probability for a still arm at azimuth 0, elevation `el_deg`, isotropic error
    (no camera: no yaw error of a single view's body frame)."""
    sd_az = ANGLE_SD_DEG / np.cos(np.radians(el_deg))
    return _p(el_deg, -67.5, -22.5, ANGLE_SD_DEG) * _p(0.0, -22.5, 22.5, sd_az)


def test_a_limb_in_mid_sector_with_a_confident_fit_is_likely_right():
    joints = _held_arm(45.0)  # forward low: elevation -45, the level's centre
    s = score_confidence(_score(), joints, 25.0).symbols[0]
    assert s.confidence == pytest.approx(_p_forward_low(-45.0), abs=0.002)
    assert not s.uncertain


def test_a_limb_just_inside_a_level_boundary_is_less_sure():
    joints = _held_arm(90.0 - 22.5 - 2.0)  # elevation -24.5: 2 degrees inside low
    s = score_confidence(_score(), joints, 25.0).symbols[0]
    assert s.confidence == pytest.approx(_p_forward_low(-24.5), abs=0.002)
    assert s.confidence < score_confidence(_score(), _held_arm(45.0), 25.0).symbols[0].confidence


def test_a_limb_outside_the_symbols_cell_is_uncertain():
    joints = _held_arm(90.0 - 22.5 + 3.0)  # elevation -19.5: the middle level, not low
    s = score_confidence(_score(), joints, 25.0).symbols[0]
    assert s.confidence == pytest.approx(_p_forward_low(-19.5), abs=0.002)
    assert s.uncertain


def test_depth_along_the_line_of_sight_is_less_certain():
    # The forward-low arm points half along a camera on +y: its elevation error mixes in the depth error.
    joints = _held_arm(45.0)
    s = score_confidence(_score(), joints, 25.0, line_of_sight=np.array([0.0, 1.0, 0.0])).symbols[0]
    sd_el = np.sqrt(ANGLE_SD_DEG**2 + (DEPTH_SD_DEG**2 - ANGLE_SD_DEG**2) * 0.5)
    sd_az = np.hypot(ANGLE_SD_DEG / np.cos(np.radians(45.0)), FRAME_YAW_SD_DEG)  # azimuth tangent is across
    expect = _p(-45.0, -67.5, -22.5, sd_el) * _p(0.0, -22.5, 22.5, sd_az)
    assert s.confidence == pytest.approx(expect, abs=0.002)
    assert s.confidence < _p_forward_low(-45.0)


def test_direction_probability_at_a_boundary_is_half_the_other_factor():
    held = _unit(22.5, 0.0)  # on the forward / right_forward boundary, middle level
    p = direction_probability(held, "forward", "middle")
    sd_az = ANGLE_SD_DEG
    assert p == pytest.approx(_p(0.0, -22.5, 22.5, ANGLE_SD_DEG) * _p(22.5, -22.5, 22.5, sd_az), abs=1e-6)
    assert direction_probability(held, "forward", "middle") == pytest.approx(
        direction_probability(held, "right_forward", "middle"), abs=1e-6
    )
    assert direction_probability(np.full((3, 3), np.nan), "forward", "middle") == 0.0


def test_jitter_over_the_hold_widens_the_error():
    rng = np.random.default_rng(16)
    steady = np.repeat(_unit(15.0, 0.0), 6, axis=0)
    shaky = steady + 0.15 * rng.standard_normal(steady.shape)
    assert direction_probability(shaky, "forward", "middle") < direction_probability(steady, "forward", "middle")


def test_the_fits_confidence_lowers_it():
    joints = _held_arm(45.0)
    conf = np.ones(joints.shape[:2])
    conf[:, joint_index("right_wrist")] = 0.3
    s = score_confidence(_score(), joints, 25.0, conf).symbols[0]
    assert s.confidence == pytest.approx(0.3 * _p_forward_low(-45.0), abs=0.002)
    missing = joints.copy()
    missing[:, joint_index("right_wrist")] = np.nan
    assert score_confidence(_score(), missing, 25.0).symbols[0].confidence == 0.0


@pytest.mark.parametrize(
    ("readings", "expected"),
    [
        ([[0.9, 0.1], [0.7, 0.1]], 1.6 / 1.8),  # summed over the frames, not averaged per frame
        ([[0.0, 0.0], [0.0, 0.0]], 0.5),  # side-on throughout: nothing tells the readings apart
        ([[np.nan, np.nan], [0.1, 0.3]], 0.25),  # unknown frames carry nothing
    ],
)
def test_turn_probability_is_the_decoded_readings_share(readings, expected):
    assert turn_probability(np.array(readings)) == pytest.approx(expected, abs=1e-12)


def _turn_score():
    return Score.from_symbols([Symbol(1, 1, TURN_PART, "right", None, amount="1/4")], tempo=60)


def test_a_turn_the_decoder_cannot_tell_from_its_mirror_image_is_uncertain():
    joints = _held_arm(0.0)
    T = joints.shape[0]
    readings = np.zeros((T, 2))
    readings[:, 0] = 0.9
    readings[25:50] = [0.2, 0.7]  # during the turn (beats 1 to 2 at 60 bpm, 25 fps): mostly the mirror image
    got = score_confidence(_turn_score(), joints, 25.0, front_readings=readings).symbols[0]
    assert got.confidence == pytest.approx(0.2 / 0.9, abs=0.002)
    assert got.uncertain
    # Without readings a turn rests on the hips' confidence alone.
    assert score_confidence(_turn_score(), joints, 25.0).symbols[0].confidence == 1.0
    with pytest.raises(QuantiseError, match="front_readings"):
        score_confidence(_turn_score(), joints, 25.0, front_readings=readings[:10])
