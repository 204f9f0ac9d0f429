"""Reading a capture's input: its kind, and the roll a video's fit takes from the camera estimate."""

from __future__ import annotations

import pytest

from capture2notation.errors import PipelineError
from pipelines.capture_input import input_kind


def test_bad_inputs_are_named(tmp_path):
    with pytest.raises(PipelineError, match="no such file"):
        input_kind(tmp_path / "missing.mp4")
    (tmp_path / "empty").mkdir()
    with pytest.raises(PipelineError, match="no images"):
        input_kind(tmp_path / "empty")
    (tmp_path / "score.txt").write_text("x")
    with pytest.raises(PipelineError, match=r"unknown input type '\.txt'"):
        input_kind(tmp_path / "score.txt")


@pytest.mark.parametrize(
    ("estimated", "taken"), [(None, 0.0), (1.5, 0.0), (-2.0, 0.0), (6.0, 4.0), (-7.5, -5.5), (40.0, 20.0)]
)
def test_the_fit_takes_the_estimated_roll_beyond_its_noise(estimated, taken):
    """The unknown camera's roll: the estimate less its noise (a dancer's leans), never beyond MAX_ROLL_DEG."""
    from types import SimpleNamespace

    from pipelines.capture_input import MAX_ROLL_DEG, ROLL_NOISE_DEG, _fit_roll

    assert (ROLL_NOISE_DEG, MAX_ROLL_DEG) == (2.0, 20.0)  # the cases below are written for these
    estimate = None if estimated is None else SimpleNamespace(roll_deg=estimated)
    assert _fit_roll(estimate) == pytest.approx(taken)


def test_a_foot_is_seen_whatever_its_label(still_fit):
    """Which foot is which may be in doubt (the pose model's left and right);
    that it is on the floor or in the air is not: the feet are seen on the
    fit's own confidence, not on the identity's."""
    import numpy as np

    from capture2notation.body import JOINTS, joint_index
    from pipelines.capture_input import FOOT_SEEN_CONFIDENCE, feet_seen

    confidence = np.full((4, len(JOINTS)), 0.9)
    confidence[3, joint_index("left_toe")] = FOOT_SEEN_CONFIDENCE / 2  # not measured
    fit = still_fit(confidence, [1.0, 0.3, np.nan, 0.3])
    assert feet_seen(fit).tolist() == [[True, True], [True, True], [True, True], [True, False]]
    # The labels' doubt still reaches the symbols of sided parts.
    assert fit.labelled_confidence()[1, joint_index("left_toe")] == pytest.approx(0.27)
