"""Curves resampled to a fixed number of points: frame-rate independent cost, same curve."""

import numpy as np
import pytest

from capture2notation.effort.curves import MAX_CURVE_POINTS, ProgressCurve, resample_curve
from capture2notation.errors import EffortError
from capture2notation.notation.effort import progress


def _curve(n, seed=0, noise=0.0):
    rng = np.random.default_rng(seed)
    tau = (np.arange(n) + 1.0) / (n + 1)
    s = progress(tau, -3.0, 0.45) + noise * rng.standard_normal(n)
    return ProgressCurve("right_arm", 0.0, 1.0, tau, s, np.ones(n), 0.01 * np.sin(np.pi * tau), 1.0, np.full(n, 0.2))


def test_short_curves_are_kept_as_measured():
    c = _curve(MAX_CURVE_POINTS)
    assert resample_curve(c) is c


def test_long_curve_is_binned_onto_the_same_logistic():
    c = _curve(240)  # 120 fps, two beats at 60 bpm
    r = resample_curve(c)
    assert r.tau.size == MAX_CURVE_POINTS
    assert np.all(np.diff(r.tau) > 0) and r.tau[0] > 0 and r.tau[-1] < 1
    # a bin 1/48 wide averages a smooth curve to within its curvature: < 2e-3
    assert np.max(np.abs(r.s - progress(r.tau, -3.0, 0.45))) < 2e-3
    assert np.allclose(r.weight, 1.0, atol=0.25) and np.all(r.weight <= 1.0)
    assert np.max(np.abs(r.radial - 0.01 * np.sin(np.pi * r.tau))) < 1e-4
    assert np.allclose(r.outward, 0.2)


def test_binning_averages_white_noise():
    r = resample_curve(_curve(480, noise=0.01))  # 10 frames per bin
    resid = r.s - progress(r.tau, -3.0, 0.45)
    assert 0.01 / np.sqrt(10) * 0.6 < np.std(resid) < 0.01 / np.sqrt(10) * 1.5


def test_lost_frames_leave_bins_out():
    c = _curve(240)
    keep = (c.tau < 0.3) | (c.tau > 0.5)
    c = ProgressCurve(c.part, 0.0, 1.0, c.tau[keep], c.s[keep], c.weight[keep], c.radial[keep], 1.0, None)
    r = resample_curve(c)
    assert r.outward is None
    assert not np.any((r.tau > 0.31) & (r.tau < 0.49))


def test_too_few_points_is_an_error():
    with pytest.raises(EffortError, match="n_points"):
        resample_curve(_curve(10), 2)


def test_every_bin_holds_the_same_number_of_frames():
    # 50 frames (two beats at 60 bpm, 25 fps) over 48 points: bins of two
    # frames each, evenly spaced and equally weighted (equal-width bins of τ
    # held one or two frames, weighted 0.5 or 1).
    c = _curve(50)
    r = resample_curve(c)
    assert r.tau.size == 25
    np.testing.assert_allclose(r.weight, 1.0)
    np.testing.assert_allclose(np.diff(r.tau), 2 * np.diff(c.tau)[0])


def test_no_bin_spans_lost_frames():
    full = _curve(100)
    keep = np.ones(100, bool)
    keep[[30, 31, 32, 61]] = False
    c = ProgressCurve(
        full.part, 0.0, 1.0, full.tau[keep], full.s[keep], full.weight[keep], full.radial[keep], 1.0, None
    )
    r = resample_curve(c)
    # A bin joining the frames on either side of a gap would sit on a lost frame's τ.
    step = np.diff(full.tau)[0]
    assert not np.any(np.abs(r.tau[:, None] - full.tau[~keep][None, :]) < 0.4 * step)
    assert r.tau.size <= MAX_CURVE_POINTS + 2
