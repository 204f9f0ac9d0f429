"""Shared test helpers: the one route to the third-party fixtures."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import settings

# CI (``HYPOTHESIS_PROFILE=ci`` in .ci/run) tries a fixed set of examples, so
# that a clean checkout gives the same result every run; locally Hypothesis
# explores new examples and keeps any failure in .hypothesis/ for replay.
settings.register_profile("ci", derandomize=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

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
            pytest.skip(
                f"fixture {rel} not found under {fixtures_dir()} (set C2N_FIXTURES or place ../shared beside the repo)"
            )
        return p

    return get


@pytest.fixture(scope="session")
def pose_model_path():
    """Path of the BlazePose ONNX model, fetched on first use.

    Skips (with the reason) only when the model cannot be fetched, e.g. no
    access to the package index; with ``C2N_REQUIRE_MODEL=1`` (set in CI) that
    is a failure instead.
    """
    from capture2notation.errors import ModelError
    from capture2notation.keypoints.model import resolve_model

    try:
        return resolve_model()
    except ModelError as exc:
        if os.environ.get("C2N_REQUIRE_MODEL") == "1":
            pytest.fail(f"C2N_REQUIRE_MODEL=1 but the pose model is unavailable: {exc}")
        pytest.skip(f"BlazePose model unavailable (fetch impossible here): {exc}")


#: Headless Chromium for the ``browser`` tests (None: they skip with the reason).
CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)


def pytest_collection_modifyitems(config, items):
    """Skip the ``browser`` tests, saying why, where Chromium is not installed."""
    if CHROMIUM is not None:
        return
    skip = pytest.mark.skip(reason="chromium is not installed (apt-get install -y chromium)")
    for item in items:
        if "browser" in item.keywords:
            item.add_marker(skip)


@pytest.fixture
def chromium(tmp_path):
    """Return ``command(*flags)``: headless Chromium with a fresh profile and the flags every browser test needs."""

    def command(*flags: str) -> list[str]:
        return [
            CHROMIUM,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={tempfile.mkdtemp(dir=tmp_path)}",
            *flags,
        ]

    return command


@pytest.fixture
def still_fit():
    """``still_fit(confidence, identity_confidence=None)``: a motionless FitResult at 25 fps with these confidences."""
    import numpy as np

    from capture2notation.body import JOINTS
    from capture2notation.fitting import FitResult

    def make(confidence, identity_confidence=None):
        T = len(confidence)
        return FitResult(
            fps=25.0,
            times=np.arange(T) / 25.0,
            joints=np.zeros((T, len(JOINTS), 3)),
            angles=np.zeros((T, len(JOINTS), 3)),
            root=np.zeros((T, 3)),
            confidence=np.asarray(confidence, float),
            identity_confidence=None if identity_confidence is None else np.asarray(identity_confidence, float),
        )

    return make
