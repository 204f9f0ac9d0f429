"""Fixtures of the quantiser's tests (helpers live in ``quantise_motions``)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

# The helpers module sits beside this file (tests are not a package).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from quantise_motions import arm_angles, build_motion


@pytest.fixture
def fk_motion():
    return build_motion


@pytest.fixture
def arm_pose():
    return arm_angles
