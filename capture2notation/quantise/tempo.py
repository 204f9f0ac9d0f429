"""Tempo from key-frame times, and snapping times to a beat grid.

A score starts at beat 0 at time 0 (the renderer's and the capture's first
frame), so the beat grid has no free phase: only the period is estimated.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..errors import QuantiseError

__all__ = ["TEMPO_RANGE", "estimate_tempo", "snap"]

#: Tempi considered by :func:`estimate_tempo`, beats per minute; the emotion
#: presets of DESIGN.md span 37–80 bpm.
TEMPO_RANGE = (30.0, 160.0)
#: Prior centre of the log-tempo preference that breaks the factor-of-two
#: ambiguity (bpm).
_PRIOR_BPM = 70.0


def snap(seconds, tempo, grid: Fraction) -> Fraction:
    """Nearest grid point, in beats, to a time in seconds.

    Parameters
    ----------
    seconds : float
        Time from the start of the capture.
    tempo : Fraction or float
        Beats per minute.
    grid : Fraction
        Grid step in beats (e.g. 1/4).

    Returns
    -------
    Fraction
        A multiple of `grid` (>= 0).
    """
    if grid <= 0:
        raise QuantiseError(f"grid step must be > 0 beats, got {grid}")
    beats = float(seconds) * float(tempo) / 60.0
    k = int(np.floor(beats / float(grid) + 0.5))
    return max(k, 0) * Fraction(grid)


def estimate_tempo(
    key_times,
    grid: Fraction = Fraction(1, 4),
    tempo_range: tuple[float, float] = TEMPO_RANGE,
    tolerance_s: float = 0.04,
    durations=None,
) -> Fraction:
    """Estimate the tempo from the times at which movements start and arrive.

    Each candidate tempo is scored by how many key times fall within
    `tolerance_s` of its beat grid (phase fixed: beat 0 at time 0), on a
    hierarchy of grids: whole beats count most, then half beats, then the
    `grid` step, so a coarser reading is preferred over an arbitrarily fine
    one.  Ties (the inherent factor-of-two ambiguity) go to the tempo nearest
    70 bpm on a log scale.  The winner is refined by least squares of the key
    times on their grid positions and rounded to a whole bpm.

    Parameters
    ----------
    key_times : (N,) array_like
        Seconds; at least two distinct positive times are needed.
    grid : Fraction
        Finest grid of the score, beats.
    tempo_range : (float, float)
        Bpm range searched.
    tolerance_s : float
        Timing tolerance, seconds (about one frame at 25 fps).
    durations : (M,) array_like, optional
        Movement durations, seconds, for the prior.

    Returns
    -------
    Fraction
        Whole beats per minute.
    """
    t = np.asarray(key_times, dtype=float)
    t = np.unique(t[np.isfinite(t) & (t > tolerance_s)])
    lo, hi = tempo_range
    if t.size < 2:
        raise QuantiseError(
            f"cannot estimate a tempo from {t.size} key time(s); give the tempo (--tempo BPM)"
        )
    cand = np.arange(np.floor(lo), np.ceil(hi) + 0.25, 0.25)
    q = 60.0 / cand * float(grid)  # grid step in seconds, (C,)
    r = t[None, :] / q[:, None]
    dist = np.abs(r - np.round(r)) * q[:, None]
    hits = np.mean(np.exp(-0.5 * (dist / tolerance_s) ** 2), axis=1)
    # A finer grid catches more times by chance: uniform offsets score
    # tol·sqrt(2π)/q on average.  Subtracting it makes the coarsest grid that
    # explains every time win, instead of ever faster tempi.
    chance = np.minimum(1.0, tolerance_s * np.sqrt(2 * np.pi) / q)
    centre = _PRIOR_BPM
    if durations is not None:
        d = np.asarray(durations, dtype=float)
        d = d[np.isfinite(d) & (d > 0)]
        if d.size:
            centre = float(np.clip(60.0 / np.median(d), lo, hi))
    prior = -0.3 * np.abs(np.log2(cand / centre))
    total = hits - chance + prior
    best = cand[int(np.argmax(total))]
    # Refine: regress times on their nearest grid positions (line through 0).
    q = 60.0 / best * float(grid)
    k = np.round(t / q)
    ok = k > 0
    if np.any(ok):
        q_fit = float(np.sum(t[ok] * k[ok]) / np.sum(k[ok] ** 2))
        refined = 60.0 * float(grid) / q_fit
        if abs(refined - best) < 0.05 * best:
            best = refined
    return Fraction(int(round(best)))
