"""Heatmap refinement against a direct port of MediaPipe's loop, and on known peaks."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.keypoints.heatmap import refine_from_heatmap


def _reference(uv, hm, kernel=7, min_conf=0.5):
    """MediaPipe's RefineLandmarksFromHeatMap, loop for loop."""
    k, h, w = hm.shape
    out = uv.copy()
    for i in range(k):
        cc, cr = int(uv[i, 0] * w), int(uv[i, 1] * h)
        if cc < 0 or cc >= w or cr < 0 or cr >= h:
            continue
        off = (kernel - 1) // 2
        s = wc = wr = mx = 0.0
        for r in range(max(0, cr - off), min(h, cr + off + 1)):
            for c in range(max(0, cc - off), min(w, cc + off + 1)):
                conf = 1 / (1 + np.exp(-hm[i, r, c]))
                s += conf
                mx = max(mx, conf)
                wc += c * conf
                wr += r * conf
        if mx >= min_conf and s > 0:
            out[i] = (wc / w / s, wr / h / s)
    return out


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_matches_mediapipe_loop(seed):
    rng = np.random.default_rng(seed)
    hm = rng.normal(0.0, 3.0, (6, 16, 16))
    uv = rng.uniform(-0.1, 1.1, (6, 2))  # some outside the heatmap
    got, _ = refine_from_heatmap(uv, hm)
    np.testing.assert_allclose(got, _reference(uv, hm), atol=1e-9)


def test_symmetric_peak_recovers_its_centre():
    yy, xx = np.mgrid[0:64, 0:64]
    centre = np.array([20.25, 40.5])  # heatmap cells (x, y)
    g = 8.0 * np.exp(-((xx - centre[0]) ** 2 + (yy - centre[1]) ** 2) / (2 * 1.2**2)) - 6.0
    uv0 = (centre + np.array([1.7, -1.4])) / 64  # regressed position 2 cells off
    uv, conf = refine_from_heatmap(uv0[None], g[None])
    # The 7x7 window is not centred on the peak, so allow a quarter cell.
    np.testing.assert_allclose(uv[0] * 64, centre, atol=0.25)
    assert conf[0] > 0.5  # confident enough to have been refined


def test_low_confidence_and_outside_points_are_unchanged():
    hm = np.full((2, 64, 64), -10.0)  # sigmoid ~ 4.5e-5 everywhere
    uv0 = np.array([[0.5, 0.5], [1.2, 0.5]])
    uv, conf = refine_from_heatmap(uv0, hm)
    np.testing.assert_array_equal(uv, uv0)
    assert conf[0] == pytest.approx(1 / (1 + np.exp(10.0)))
    assert conf[1] == 0.0
