"""Left/right consistency: mirror permutation, swap evidence, the tracker's
flip-back and the mirrored (flip-test) pass, with a scripted stand-in for the
ONNX session so that the model's answers are known exactly."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from capture2notation.keypoints.blazepose import NUM_ALL, BlazePose, decode_outputs
from capture2notation.keypoints.swap import MIRROR, SWAP_PAIRS, mirror_landmarks, swap_evidence
from capture2notation.keypoints.track import LANDMARK_NAMES


def test_mirror_exchanges_every_left_with_its_right():
    assert np.array_equal(MIRROR[MIRROR], np.arange(33))
    assert MIRROR[0] == 0
    for i, name in enumerate(LANDMARK_NAMES):
        twin = name.replace("left", "@").replace("right", "left").replace("@", "right")
        assert LANDMARK_NAMES[MIRROR[i]] == twin, name
    assert all(LANDMARK_NAMES[a].startswith("left") and LANDMARK_NAMES[b].startswith("right") for a, b in SWAP_PAIRS)


def test_mirror_landmarks_reflects_depth_only_when_asked():
    x = np.arange(33 * 3, dtype=float).reshape(33, 3)
    m = mirror_landmarks(x, depth_axis=2)
    assert np.array_equal(m[:, :2], x[MIRROR, :2]) and np.array_equal(m[:, 2], -x[MIRROR, 2])
    assert np.array_equal(mirror_landmarks(x[:, 0]), x[MIRROR, 0])
    assert np.array_equal(x, np.arange(33 * 3, dtype=float).reshape(33, 3))  # input untouched


_coords = arrays(np.float64, (33, 2), elements=st.floats(-500, 500, allow_nan=False))


@settings(max_examples=60, deadline=None)
@given(_coords, _coords)
def test_swap_evidence_is_antisymmetric_under_mirroring(cur, prev):
    """Mirroring the current frame exchanges the 'same' and 'crossed' costs."""
    e = swap_evidence(cur, prev)
    assert swap_evidence(mirror_landmarks(cur), prev) == pytest.approx(-e, abs=1e-6)


def test_swap_evidence_sign_and_missing_points():
    rng = np.random.default_rng(3)
    body = rng.uniform(0, 300, (33, 2))
    moved = body + rng.normal(0, 2.0, body.shape)
    assert swap_evidence(moved, body) < 0  # as labelled: fits
    assert swap_evidence(mirror_landmarks(moved), body) > 0  # flipped: the mirror fits
    assert np.isnan(swap_evidence(np.full((33, 2), np.nan), body))
    half = moved.copy()
    half[SWAP_PAIRS[:5].ravel()] = np.nan  # pairs with a missing point are skipped
    assert swap_evidence(mirror_landmarks(half), body) > 0


# ----------------------------------------------------------- scripted model
def _skeleton() -> np.ndarray:
    """A person facing the camera in model-input pixels (256 wide): (39, 2).

    Their left is on the image right.  Points 33/34 make
    :func:`crop_from_aux` reproduce the crop they were read in, so tracking
    stays on one crop.
    """
    rng = np.random.default_rng(0)
    uv = np.empty((NUM_ALL, 2))
    uv[:33, 1] = np.linspace(40, 230, 33)
    for k in range(33):
        side = 0.0 if MIRROR[k] == k else (1.0 if "left" in LANDMARK_NAMES[k] else -1.0)
        uv[k, 0] = 128 + side * rng.uniform(15, 40)
    uv[33:] = 128.0
    uv[34] = (128.0, 128.0 - 256 / 2.5)  # side = 2 * 102.4 * 1.25 = the whole crop
    return uv


_DEPTH = np.linspace(-1.0, 1.0, 33) ** 3  # distinct depths, to see the reflection


def _outputs(uv: np.ndarray, depth: np.ndarray = _DEPTH) -> list:
    """Model outputs for input-pixel positions `uv` (39, 2) and relative depths (33,)."""
    raw = np.zeros((NUM_ALL, 5))
    raw[:, :2] = uv
    raw[:33, 2] = 20.0 * depth
    raw[:, 3] = 3.0  # visible
    world = np.zeros((NUM_ALL, 3))
    world[:, :2] = (uv - 128.0) / 256.0
    world[:33, 2] = 0.2 * depth
    heat = np.full((1, NUM_ALL, 64, 64), -10.0, np.float32)  # no heatmap refinement
    return [raw.reshape(1, -1), np.array([[0.99]]), heat, world.reshape(1, -1)]


class _ScriptedSession:
    """Answers `session.run` with the queued outputs, in order."""

    def __init__(self, answers):
        self.answers = list(answers)
        self.inputs = []

    def get_inputs(self):
        return [SimpleNamespace(name="input", shape=[1, 3, 256, 256])]

    def run(self, _names, feed):
        self.inputs.append(feed["input"])
        return self.answers.pop(0)


def _flipped_labels(uv: np.ndarray) -> np.ndarray:
    """The same picture read as seen from behind: every left label on the right point."""
    out = uv.copy()
    out[:33] = uv[MIRROR]
    return out


@pytest.mark.parametrize("fix_swaps", [True, False])
def test_tracker_flips_back_a_front_back_misreading(fix_swaps):
    uv = _skeleton()
    good = _outputs(uv)
    # Read as seen from behind: left labels on the right points, depth reflected.
    flipped = _outputs(_flipped_labels(uv), -_DEPTH[MIRROR])
    # Acquisition runs full frame + 2 refinements; then one run per frame.
    session = _ScriptedSession([good, good, good, flipped, good])
    bp = BlazePose(session=session, smooth=False, fix_swaps=fix_swaps)
    image = np.zeros((480, 640, 3), np.uint8)
    first = bp.process(image, 0.0)
    second = bp.process(image, 0.2)
    third = bp.process(image, 0.4)
    assert not session.answers
    if fix_swaps:
        for field in ("xy", "world", "visibility"):
            np.testing.assert_allclose(getattr(second, field), getattr(first, field), atol=1e-9, err_msg=field)
    else:
        np.testing.assert_allclose(second.xy[:, :2], first.xy[MIRROR, :2], atol=1e-9)
    np.testing.assert_allclose(third.xy, first.xy, atol=1e-9)  # a correct frame is left alone


def test_mirrored_pass_decodes_to_the_unmirrored_answer():
    """What the model says about the flipped crop, mapped back, is the direct answer."""
    uv = _skeleton() + np.random.default_rng(1).normal(0, 3, (NUM_ALL, 2))
    direct = _outputs(uv)
    seen = uv.copy()
    seen[:, 0] = 256.0 - seen[:, 0]  # positions in the flipped input ...
    seen[:33] = seen[MIRROR]  # ... where the person's left now looks like a right
    mirrored = _outputs(seen)
    raw = mirrored[0].reshape(NUM_ALL, 5)
    raw[:33, 2:4] = direct[0].reshape(NUM_ALL, 5)[MIRROR, 2:4]  # depth and visibility travel with the labels
    world = mirrored[3].reshape(NUM_ALL, 3)
    world[:] = direct[3].reshape(NUM_ALL, 3)[np.r_[MIRROR, np.arange(33, NUM_ALL)]] * [-1.0, 1.0, 1.0]
    crop = np.array([300.0, 250.0, 400.0, 400.0, 0.3])
    a, b = decode_outputs(direct, crop), decode_outputs(mirrored, crop, mirrored=True)
    for field in ("xy", "visibility", "world", "aux"):
        np.testing.assert_allclose(getattr(b, field), getattr(a, field), atol=1e-9, err_msg=field)


def test_flip_test_averages_consistent_passes_and_keeps_the_direct_one_otherwise():
    uv = _skeleton()
    seen = uv.copy()
    seen[:, 0] = 256.0 - seen[:, 0]
    seen[:33] = seen[MIRROR]
    nudged = seen.copy()
    nudged[:33, 1] += 4.0  # the mirrored pass reads every point 4 input pixels lower
    image = np.zeros((480, 640, 3), np.uint8)
    crop = np.array([320.0, 240.0, 512.0, 512.0, 0.0])
    bp = BlazePose(session=_ScriptedSession([_outputs(uv), _outputs(nudged)]), flip_test=True)
    both = bp.infer(image, crop)
    direct = decode_outputs(_outputs(uv), crop)
    np.testing.assert_allclose(both.xy[:, 1] - direct.xy[:, 1], 2.0 * 512 / 256, atol=1e-9)  # half of 4 px
    np.testing.assert_allclose(both.xy[:, 0], direct.xy[:, 0], atol=1e-9)
    inp = bp.session.inputs
    np.testing.assert_array_equal(inp[1], inp[0][..., ::-1])  # the second pass saw the mirror image
    # A mirrored pass that reads the body facing the other way is not averaged in.
    bp = BlazePose(session=_ScriptedSession([_outputs(uv), _outputs(_flipped_labels(seen))]), flip_test=True)
    np.testing.assert_allclose(bp.infer(image, crop).xy, direct.xy, atol=1e-9)
