"""Fixtures of the quantiser's tests (helpers live in ``quantise_motions``)."""

from __future__ import annotations

import pytest

from quantise_motions import arm_angles, build_motion


@pytest.fixture
def fk_motion():
    return build_motion


@pytest.fixture
def arm_pose():
    return arm_angles
