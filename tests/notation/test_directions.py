"""Direction, level and bend thresholds shared by renderer and quantiser (DESIGN.md)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from capture2notation.errors import NotationError
from capture2notation.notation import DIRECTIONS, LEVELS, canonical_vector, classify
from capture2notation.notation.directions import (
    SECTOR_DIRECTIONS,
    azimuth_elevation,
    bend_angle,
    bend_degree,
    classify_indices,
)

VALID = [(d, lv) for d in DIRECTIONS for lv in LEVELS if not (d == "place" and lv == "middle")]


def _vec(az_deg: float, el_deg: float) -> np.ndarray:
    az, el = np.radians(az_deg), np.radians(el_deg)
    return np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])


def _mirror(name: str) -> str:
    return name.replace("right", "@").replace("left", "right").replace("@", "left")


@pytest.mark.parametrize("direction,level", VALID)
def test_canonical_vectors_round_trip(direction, level):
    v = canonical_vector(direction, level)
    assert np.linalg.norm(v) == pytest.approx(1.0, abs=1e-12)
    assert classify(v) == (direction, level)


def test_canonical_vectors_match_design():
    np.testing.assert_allclose(canonical_vector("forward", "middle"), [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(canonical_vector("right", "middle"), [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(canonical_vector("place", "low"), [0, 0, -1], atol=1e-12)
    s = np.sqrt(0.5)
    np.testing.assert_allclose(canonical_vector("back", "high"), [0, -s, s], atol=1e-12)
    with pytest.raises(NotationError):
        canonical_vector("place", "middle")
    with pytest.raises(NotationError):
        canonical_vector("up", "high")


@pytest.mark.parametrize(
    "az,el,expected",
    [
        # Sector edges (exact edges are not reachable through trigonometry).
        (22.5 - 1e-9, 0, ("forward", "middle")),
        (22.5 + 1e-9, 0, ("right_forward", "middle")),
        (-22.5 - 1e-9, 0, ("left_forward", "middle")),
        (-22.5 + 1e-9, 0, ("forward", "middle")),
        (180, 0, ("back", "middle")),
        (-157.5 + 1e-9, 0, ("left_back", "middle")),
        (0, 22.5 - 1e-6, ("forward", "middle")),
        (0, 22.5 + 1e-6, ("forward", "high")),
        (0, -22.5 - 1e-6, ("forward", "low")),
        (90, 67.5 - 1e-6, ("right", "high")),
        (90, 67.5 + 1e-6, ("place", "high")),
        (-90, -67.5 - 1e-6, ("place", "low")),
    ],
)
def test_thresholds(az, el, expected):
    assert classify(_vec(az, el)) == expected


angles = st.tuples(st.floats(-179.9, 180.0), st.floats(-89.9, 89.9))


def _off_boundaries(az: float, el: float) -> bool:
    near_sector = min(abs((az - 22.5) % 45.0), 45.0 - abs((az - 22.5) % 45.0)) < 1e-6
    near_level = min(abs(abs(el) - 22.5), abs(abs(el) - 67.5)) < 1e-6
    return not (near_sector or near_level)


@settings(max_examples=300, deadline=None)
@given(angles, st.floats(1e-3, 1e3))
def test_classification_invariants(angle, scale):
    az, el = angle
    assume(_off_boundaries(az, el))
    v = _vec(az, el)
    d, lv = classify(v)
    assert classify(scale * v) == (d, lv)  # only the direction matters
    # Mirror left/right (x → −x).
    assert classify(v * [-1, 1, 1]) == (_mirror(d), lv)
    # Flip up/down (z → −z) swaps high and low.
    flip = {"high": "low", "low": "high", "middle": "middle"}
    assert classify(v * [1, 1, -1]) == (d, flip[lv])
    # Turning by 45° clockwise moves to the next sector.
    if d != "place":
        d2, lv2 = classify(_vec(az + 45.0, el))
        assert lv2 == lv
        assert SECTOR_DIRECTIONS.index(d2) == (SECTOR_DIRECTIONS.index(d) + 1) % 8
    # The vectorised version agrees.
    di, li = classify_indices(v[None])
    assert (list(DIRECTIONS)[di[0]], LEVELS[li[0]]) == (d, lv)


def test_vectorised_shapes_and_undefined_vectors():
    v = np.stack([canonical_vector(d, lv) for d, lv in VALID]).reshape(len(VALID), 1, 3)
    di, li = classify_indices(v)
    assert di.shape == (len(VALID), 1)
    assert [(list(DIRECTIONS)[a], LEVELS[b]) for a, b in zip(di[:, 0], li[:, 0])] == VALID
    bad = np.array([[0.0, 0.0, 0.0], [np.nan, 1.0, 0.0]])
    di, li = classify_indices(bad)
    assert di.tolist() == [-1, -1] and li.tolist() == [-1, -1]
    az, el = azimuth_elevation(bad)
    assert np.isnan(az).all() and np.isnan(el).all()
    with pytest.raises(NotationError, match="undefined"):
        classify([0.0, 0.0, 0.0])


def test_bend_angle_and_degree():
    a, m = np.array([0.0, 0.0, 0.0]), np.array([0.0, 0.0, -1.0])
    assert bend_angle(a, m, [0.0, 0.0, -2.0]) == pytest.approx(0.0, abs=1e-6)
    assert bend_angle(a, m, [0.0, 1.0, -1.0]) == pytest.approx(90.0, abs=1e-9)
    assert bend_angle(a, m, [0.0, 0.0, 0.0]) == pytest.approx(180.0, abs=1e-9)
    beta = np.array([0.0, 14.9, 15.0, 27.0, 44.9, 45.0, 90.0, 179.0, 200.0, np.nan])
    np.testing.assert_array_equal(bend_degree(beta), [0, 0, 1, 1, 1, 2, 3, 6, 6, -1])


@settings(max_examples=100, deadline=None)
@given(st.floats(0.0, 180.0), st.floats(0.1, 2.0), st.floats(0.1, 2.0))
def test_bend_angle_recovers_a_constructed_bend(beta, l1, l2):
    # Upper segment hangs down; the lower one turns by beta in the sagittal plane.
    a = np.zeros(3)
    m = np.array([0.0, 0.0, -l1])
    b = m + l2 * np.array([0.0, np.sin(np.radians(beta)), -np.cos(np.radians(beta))])
    assert bend_angle(a, m, b) == pytest.approx(beta, abs=1e-5)
