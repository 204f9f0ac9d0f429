"""A long clip fitted in spans gives the whole clip's fit (capture2notation.fitting.spans)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import Body
from capture2notation.errors import FittingError
from capture2notation.fitting import Camera
from capture2notation.fitting.depth import DepthOptions
from capture2notation.fitting.fit import fit_keypoints
from capture2notation.fitting.solver import CHUNK, FitOptions
from capture2notation.fitting.spans import spread_frames, stitch, track_spans


@settings(deadline=None)  # a long clip's spans take a while on a loaded machine
@given(
    n=st.integers(1, 20000),
    fps=st.floats(1.0, 240.0),
    span_s=st.floats(0.5, 120.0),
    context_s=st.floats(0.0, 5.0),
)
def test_kept_frames_tile_the_clip_and_each_span_holds_its_context(n, fps, span_s, context_s):
    spans = track_spans(n, fps, span_s, context_s)
    kept = np.concatenate([np.arange(k0, k1) for _, _, k0, k1 in spans])
    np.testing.assert_array_equal(kept, np.arange(n))
    context = round(context_s * fps)
    for a, b, k0, k1 in spans:
        assert 0 <= a <= k0 < k1 <= b <= n
        assert k0 - a == min(context, k0) and b - k1 == min(context, n - k1)
    if len(spans) > 1:
        assert max(k1 - k0 for *_, k0, k1 in spans) <= max(1, round(span_s * fps))


def test_a_clip_no_longer_than_a_span_is_one_span():
    assert track_spans(1600, 25.0, 60.0, 2.0) == [(0, 1600, 0, 1600)]
    assert len(track_spans(1601, 25.0, 60.0, 2.0)) == 2
    assert track_spans(10**6, 25.0, np.inf, 2.0) == [(0, 10**6, 0, 10**6)]


@pytest.mark.parametrize(
    ("fps", "span_s", "context_s", "word"),
    [(0.0, 60.0, 2.0, "fps"), (25.0, 0.0, 2.0, "span_s"), (25.0, 60.0, -1.0, "context_s"), (np.nan, 60, 2, "fps")],
)
def test_bad_span_options_are_named(fps, span_s, context_s, word):
    with pytest.raises(FittingError, match=word):
        track_spans(100, fps, span_s, context_s)


def test_spread_frames_are_even_and_bounded():
    np.testing.assert_array_equal(spread_frames(10, 20), np.arange(10))
    sel = spread_frames(90_000, 4500)
    assert len(sel) == 4500 and sel[0] == 0 and sel[-1] == 89_999
    assert np.ptp(np.diff(sel)) <= 1


def test_stitch_needs_one_result_per_span():
    with pytest.raises(FittingError, match="one result per span"):
        stitch([], [(0, 10, 0, 10)])


def test_spans_give_the_whole_clip_fit(synth):
    # 24 s of a smooth random dance, 3 px keypoint noise and noisy world
    # landmarks, fitted whole and in 5-s spans: each span measuring its own
    # rest offsets (the arms' and legs' depth bias) moved joints by 0.56 m.
    # The whole-clip solver itself works in blocks of CHUNK frames (warm
    # started from the previous block), so frames next to its block edges
    # may differ by the solver's tolerance; elsewhere the two are the same.
    body, fps, T = Body(), 25.0, 600
    ang, root = synth.make_motion(T, seed=7, fps=fps, body=body)
    cam = Camera.default((640, 480))
    xy, conf, world, _ = synth.observe(ang, root, cam, body, noise_px=3.0, seed=8)
    world = world + np.random.default_rng(9).normal(0.0, 0.02, world.shape)
    opt = FitOptions(depth=DepthOptions(rest_offset=True))
    whole = fit_keypoints(xy, conf, fps, world=world, image_size=(640, 480), options=opt)
    spans = fit_keypoints(xy, conf, fps, world=world, image_size=(640, 480), options=replace(opt, span_s=5.0))
    gap = np.linalg.norm(whole.joints - spans.joints, axis=-1).max(axis=1)
    near_block_edge = np.abs(np.arange(T) % CHUNK - CHUNK / 2) > CHUNK / 2 - 8
    # 1 mm: far below the keypoints' own noise at this depth (3 px ~ 1 cm)
    assert np.nanmax(gap[~near_block_edge]) < 1e-3
    np.testing.assert_array_equal(whole.confidence > 0, spans.confidence > 0)
    np.testing.assert_allclose(whole.offsets, spans.offsets)
