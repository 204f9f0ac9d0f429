"""Shared test helpers: the one route to the third-party fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

_DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "fixtures"


def fixtures_dir() -> Path:
    """The conformance fixtures folder (``$C2N_FIXTURES`` or ``../shared/fixtures``)."""
    return Path(os.environ.get("C2N_FIXTURES", _DEFAULT))


@pytest.fixture
def fixture_path():
    """Return a function mapping a relative fixture path to an existing file, or skip."""

    def get(rel: str) -> Path:
        p = fixtures_dir() / rel
        if not p.exists():
            pytest.skip(f"fixture {rel} not found under {fixtures_dir()} (set C2N_FIXTURES or place ../shared beside the repo)")
        return p

    return get
