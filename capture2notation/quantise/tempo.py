"""Tempo from key-frame times, and snapping times to a beat grid.

A score starts at beat 0 at time 0 (the renderer's and the capture's first
frame), so the beat grid has no free phase: only the period is estimated.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..errors import QuantiseError

__all__ = [
    "DANCE_TEMPO_BPM",
    "DURATION_OCTAVES",
    "LEVEL_WEIGHTS",
    "OUTLIER_RATE",
    "TEMPO_RANGE",
    "TempoEstimate",
    "estimate_tempo",
    "estimate_tempo_detail",
    "snap",
    "tempo_log_prior",
]

#: Tempi considered by :func:`estimate_tempo`, beats per minute; the emotion
#: presets of DESIGN.md span 37–80 bpm.
TEMPO_RANGE = (30.0, 160.0)
#: Spread (octaves, one standard deviation) of movement durations in beats
#: around one beat: ½ and 2 beats are 1.3 σ away, so doubling the tempo
#: costs 0.9 nats per movement.
DURATION_OCTAVES = 0.75
#: Tempi of dance, bpm, equally likely a priori: from the slowest emotion
#: preset of DESIGN.md (sad, 37 bpm, after Neagle) to quick allegro
#: exercises (about 132 bpm; this upper end is our assumption about class
#: music, not a cited figure).  Outside, half or double a tempo is the less
#: likely reading; inside, the durations and timing decide.
DANCE_TEMPO_BPM = (36.0, 132.0)
#: Standard deviation (octaves) of the half-normal fall-off of the tempo
#: prior outside :data:`DANCE_TEMPO_BPM`.
TEMPO_PRIOR_OCTAVES = 0.3
#: Share of movement durations that lie anywhere (spurious or merged
#: measured movements), spread evenly over _DURATION_SPAN_OCTAVES octaves
#: of duration.
DURATION_OUTLIER_RATE = 0.2
_DURATION_SPAN_OCTAVES = 6.0


def tempo_log_prior(tempi) -> np.ndarray:
    """Log prior density (up to a constant) of tempi, flat over :data:`DANCE_TEMPO_BPM`.

    Parameters
    ----------
    tempi : array_like
        Beats per minute (> 0).

    Returns
    -------
    ndarray
        0 inside the range, ``-½ (octaves outside / TEMPO_PRIOR_OCTAVES)²`` outside.
    """
    x = np.log2(np.asarray(tempi, dtype=float))
    lo, hi = np.log2(DANCE_TEMPO_BPM[0]), np.log2(DANCE_TEMPO_BPM[1])
    out = np.maximum(lo - x, 0.0) + np.maximum(x - hi, 0.0)
    return -0.5 * (out / TEMPO_PRIOR_OCTAVES) ** 2


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


def estimate_tempo_detail(
    key_times,
    grid: Fraction = Fraction(1, 4),
    tempo_range: tuple[float, float] = TEMPO_RANGE,
    tolerance_s: float = 0.04,
    durations=None,
    groups=None,
    max_offset_s: float = 0.0,
) -> TempoEstimate:
    """Estimate the tempo from the times at which movements start and arrive.

    A generative model of the key times scores each candidate tempo: a
    time lies on a whole beat (probability :data:`LEVEL_WEIGHTS` [0]), on a
    half beat (between whole beats) or on an odd grid step, each point of
    its level equally likely over the phrase, plus Gaussian timing error σ;
    a few times (:data:`OUTLIER_RATE`) are anywhere.  Because the points of a
    level are equally likely, a faster tempo — with more points — pays for
    its extra freedom (an Occam factor), while a slower one leaves times off
    its points; a whole beat is more than four times as likely as a half
    beat, so a phrase of whole beats is not read at half its tempo.  σ is
    marginalised over ``tolerance_s × (1, 2, 4)`` (the timing precision is
    not known in advance).  Movement durations, when given, are evidence too:
    in beats they lie log-normally around one beat (:data:`DURATION_OCTAVES`),
    which settles the factor-of-two ambiguity that the key times leave (a
    phrase of half-beat times fits twice its tempo as well); a weak
    prior flat over the tempi of dance music (:data:`DANCE_TEMPO_BPM`) covers the rest.  The best candidate is refined by
    least squares of the times on their grid positions, then the whole (or
    half) bpm next to it that the times favour.

    Accepted ambiguity: a phrase whose times all lie on half beats fits
    twice its tempo with whole beats just as well, and any phrase fits at
    double tempo on the same grid; the estimate may then be 2× (rarely ½×)
    the written tempo — the same movements at the same seconds, every
    start and duration still on the grid (the comparison of
    :mod:`capture2notation.compare.agreement` is made in time for this reason).

    Parameters
    ----------
    key_times : (N,) array_like
        Seconds; at least two distinct positive times are needed.
    grid : Fraction
        Finest grid of the score, beats (½ or finer adds the half-beat
        level, ¼ or finer the odd grid steps).
    tempo_range : (float, float)
        Bpm range searched.
    tolerance_s : float
        Smallest timing error σ considered, seconds (about half a frame
        for clean motion, a frame for measured motion).
    durations : (M,) array_like, optional
        Movement durations, seconds (see above).
    groups : (N,) array_like of int, optional
        Group of each key time; the times of one group may share a constant
        timing bias (measured starts and arrivals are biased differently,
        by a frame or so), which the final line fit takes out.
    max_offset_s : float
        Largest such bias of the groups other than 0 in the likelihood,
        seconds: offsets in steps of `tolerance_s` up to it are marginalised
        (0: none, for clean times).

    Returns
    -------
    TempoEstimate
        The tempo (whole or half bpm), the runner-up reading and the confidence.
    """
    t = np.asarray(key_times, dtype=float)
    g = np.zeros(t.shape, int) if groups is None else np.asarray(groups, dtype=int)
    if g.shape != t.shape:
        raise QuantiseError(f"groups must have one entry per key time ({t.shape}), got {g.shape}")
    keep = np.isfinite(t) & (t > 0.5 * tolerance_s)
    t, g = t[keep], g[keep]
    lo, hi = tempo_range
    if t.size < 2:
        raise QuantiseError(f"cannot estimate a tempo from {t.size} key time(s); give the tempo (--tempo BPM)")
    if not (0 < lo < hi):
        raise QuantiseError(f"tempo range must be 0 < low < high bpm, got {tempo_range}")
    cand = np.arange(np.floor(lo), np.ceil(hi) + 0.25, 0.25)
    d = None if durations is None else np.asarray(durations, dtype=float)
    if d is not None:
        d = d[np.isfinite(d) & (d > 0)]
    post = _log_posterior(t, cand, grid, tolerance_s, d, g, max_offset_s)
    best = _refine(t, g, float(cand[int(np.argmax(post))]), grid, tolerance_s)
    # The least-squares tempo, to the nearest whole bpm; or half a bpm (the
    # half of an odd tempo, e.g. 48.5 for a phrase of half beats at 97) when
    # the times favour it by more than :data:`_WHOLE_BPM_NATS`.
    near = np.unique([np.floor(best), np.ceil(best), round(2.0 * best) / 2.0])
    score = _log_posterior(t, near, grid, tolerance_s, d, g, max_offset_s) + _WHOLE_BPM_NATS * (near == np.round(near))
    pick = Fraction(int(round(2 * float(near[int(np.argmax(score))]))), 2)
    # Runner-up: the best reading more than _DISTINCT apart (typically half
    # or double the tempo); confidence: the posterior mass within _DISTINCT
    # of the pick (the candidates are evenly spaced in bpm).
    p = np.exp(post - post.max())
    close = np.abs(np.log(cand / float(pick))) < np.log1p(_DISTINCT)
    confidence = float(p[close].sum() / p.sum())
    runner_up = None
    if np.any(~close):
        other = _refine(t, g, float(cand[~close][int(np.argmax(post[~close]))]), grid, tolerance_s)
        runner_up = Fraction(int(round(other)))
    return TempoEstimate(pick, runner_up, confidence)


def estimate_tempo(key_times, grid: Fraction = Fraction(1, 4), **kwargs) -> Fraction:
    """Estimate the tempo from the times at which movements start and arrive.

    Parameters
    ----------
    key_times : (N,) array_like
        Seconds.
    grid : Fraction
        Finest grid of the score, beats.
    **kwargs
        As :func:`estimate_tempo_detail`.

    Returns
    -------
    Fraction
        Beats per minute, whole or half: ``estimate_tempo_detail(...).tempo``.
    """
    return estimate_tempo_detail(key_times, grid, **kwargs).tempo


@dataclass(frozen=True)
class TempoEstimate:
    """A tempo estimate with its nearest rival.

    Attributes
    ----------
    tempo : Fraction
        Beats per minute, whole or half.
    runner_up : Fraction or None
        Whole bpm of the best reading more than 15 % away (usually half or
        double `tempo`), for "tempo 72 bpm (or 36)"; None if no other was searched.
    confidence : float
        Posterior probability that the tempo is within 15 % of `tempo`, in [0, 1].
    """

    tempo: Fraction
    runner_up: Fraction | None
    confidence: float


#: Relative distance beyond which two tempi are different readings.
_DISTINCT = 0.15


#: Preference (nats) for a whole number of beats per minute over a half.
_WHOLE_BPM_NATS = 4.0


def _log_posterior(
    t: np.ndarray,
    tempi: np.ndarray,
    grid: Fraction,
    tolerance_s: float,
    durations,
    groups=None,
    max_offset_s: float = 0.0,
) -> np.ndarray:
    """Log-posterior (C,) of the candidate tempi (see :func:`estimate_tempo`).

    Times of groups other than 0 may be offset by a constant of up to
    ±`max_offset_s` (in steps of `tolerance_s`, marginalised)."""
    length = float(t.max()) + 0.5
    shifts = [0.0]
    steps = int(max_offset_s / tolerance_s + 1e-9)
    if groups is not None and np.any(groups != 0) and steps > 0:
        shifts = tolerance_s * np.arange(-steps, steps + 1)
    per = []
    for c in shifts:
        tt = np.where(groups != 0, t - c, t) if groups is not None else t
        per += [_log_likelihood(tt, tempi, sigma, length, grid) for sigma in tolerance_s * np.array(_SIGMA_FACTORS)]
    total = np.logaddexp.reduce(np.stack(per), axis=0) - np.log(len(per)) + tempo_log_prior(tempi)
    if durations is not None and durations.size:
        # Movements last about a beat (the built-in phrases: all one beat;
        # random scores: ½ to 2 beats): each duration is evidence, in beats
        # log-normal around 1 beat, DURATION_OCTAVES wide.
        # A share of measured movements are spurious (jitter read as a short
        # movement) or merged: they are anywhere in log-duration
        # (:data:`DURATION_OUTLIER_RATE`, spread over _DURATION_SPAN_OCTAVES),
        # so that a few of them cannot double the tempo on their own.
        z = np.log2(durations[None, :] * tempi[:, None] / 60.0) / DURATION_OCTAVES
        typical = np.exp(-0.5 * z**2) / (DURATION_OCTAVES * np.sqrt(2.0 * np.pi))
        dens = (1.0 - DURATION_OUTLIER_RATE) * typical + DURATION_OUTLIER_RATE / _DURATION_SPAN_OCTAVES
        total = total + np.sum(np.log(dens), axis=1)
    return total


def _refine(t: np.ndarray, g: np.ndarray, tempo: float, grid: Fraction, sigma: float) -> float:
    """Tempo from a straight-line fit of the key times on their half-beat points.

    Each time is assigned to its nearest half beat (the simplest reading:
    most movements start and arrive on whole or half beats); times more than
    :data:`_REFINE_TRIM` beats off it (quarter beats, spurious movements)
    are left out, as they pull the line more than they inform it.  Each
    group of times has its own intercept: measured starts and arrivals are
    each delayed (or advanced) by about a frame, which a line through 0
    would read as another tempo.  The fit is repeated once from the refined
    tempo, and kept only within :data:`_REFINE_SPAN` of `tempo`.  (On the
    development phrases, noisy and captured, this halved the median error of
    the quarter-grid fit, to about half a bpm.)
    """
    start = tempo
    for _ in range(_REFINE_PASSES):
        q = 30.0 / tempo  # seconds per half beat
        k = np.round(t / q)
        ok = np.abs(t - k * q) < _REFINE_TRIM * 2.0 * q
        if ok.sum() < 3 or np.ptp(k[ok]) < 2:
            return tempo
        labels = np.unique(g[ok])
        design = np.column_stack([k[ok]] + [(g[ok] == lab).astype(float) for lab in labels])
        coef, *_ = np.linalg.lstsq(design, t[ok], rcond=None)
        if coef[0] <= 0:
            return tempo
        refined = 30.0 / float(coef[0])
        if abs(refined - start) > _REFINE_SPAN * start:
            return tempo
        tempo = refined
    return tempo


#: Largest relative change of the refinement (beyond it the grid points
#: were misassigned).
_REFINE_SPAN = 0.04
#: Timing errors σ marginalised, in units of the tolerance.
_SIGMA_FACTORS = (1, 2, 4)
_REFINE_PASSES = 2
#: Largest distance (beats) of a time from its half beat in the refinement.
_REFINE_TRIM = 0.2


#: Probabilities that a key time lies on a whole beat, a half beat (between
#: whole beats) and an odd quarter beat.  A whole beat must be more than
#: four times as likely as a half beat for whole-beat phrases to keep their
#: tempo rather than halve it (see :func:`estimate_tempo`).
LEVEL_WEIGHTS = (0.7, 0.15, 0.15)
#: Share of key times that lie on no beat (spurious or mistimed movements).
OUTLIER_RATE = 0.1


def _log_likelihood(t: np.ndarray, tempi: np.ndarray, sigma: float, length: float, grid: Fraction) -> np.ndarray:
    """Log-likelihood (C,) of key times (N,) at each tempo (C,) under the beat-level mixture."""
    beat = 60.0 / tempi[:, None]  # (C, 1) seconds
    levels = [(0.0, 1.0, LEVEL_WEIGHTS[0])]
    if grid <= Fraction(1, 2):
        levels.append((0.5, 1.0, LEVEL_WEIGHTS[1]))
    if grid <= Fraction(1, 4):
        levels.append((0.25, 0.5, LEVEL_WEIGHTS[2]))
    norm = sum(w for _, _, w in levels)
    dens = np.zeros((len(tempi), len(t)))
    for offset, spacing, w in levels:
        step = spacing * beat  # seconds between points of this level
        # Signed distance to the nearest point, and the two next points either side.
        d = np.mod(t[None, :] - offset * beat + 0.5 * step, step) - 0.5 * step
        comb = sum(np.exp(-0.5 * ((d + m * step) / sigma) ** 2) for m in (-2, -1, 0, 1, 2))
        # Each of the length/step points is equally likely: weight step/length.
        dens += (w / norm) * (step / length) * comb / (sigma * np.sqrt(2 * np.pi))
    dens = (1.0 - OUTLIER_RATE) * dens + OUTLIER_RATE / length
    return np.sum(np.log(dens), axis=1)
