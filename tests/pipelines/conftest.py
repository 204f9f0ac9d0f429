"""Shared fixtures of the pipeline tests."""

import pytest


@pytest.fixture
def tiny_study() -> dict:
    """Options of the smallest fidelity study that runs every stage (truth capture, two frame rates)."""
    return dict(
        phrases=("figure7",),
        emotions=("happy", "sad"),
        takes=2,
        training_takes=2,
        capture="truth",
        frame_rates=(25, 5),
        resampling=("keyframe",),
        image_sizes=((320, 240),),
        views=("front",),
        cameras=(),
        compression=(0,),
        noise=(0.0,),
        bootstrap=3,
        baseline={"frame_rate": 25, "image_size": (320, 240), "view": "front", "compression": 0, "noise": 0.0},
    )
