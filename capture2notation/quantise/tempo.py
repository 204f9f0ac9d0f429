"""Tempo from key-frame times, and snapping times to a beat grid.

A score starts at beat 0 at time 0 (the renderer's and the capture's first
frame), so the beat grid has no free phase: only the period is estimated.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..errors import QuantiseError

__all__ = ["DURATION_OCTAVES", "LEVEL_WEIGHTS", "OUTLIER_RATE", "TEMPO_RANGE", "estimate_tempo", "snap"]

#: Tempi considered by :func:`estimate_tempo`, beats per minute; the emotion
#: presets of DESIGN.md span 37–80 bpm.
TEMPO_RANGE = (30.0, 160.0)
#: Spread (octaves, one standard deviation) of movement durations in beats
#: around one beat: ½ and 2 beats are 1.3 σ away, so doubling the tempo
#: costs 0.9 nats per movement.
DURATION_OCTAVES = 0.75
#: Centre of the weak log-normal tempo prior (bpm; one octave either side
#: covers the emotion presets and the random scores' 60-120).
_PRIOR_BPM = 80.0


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
    groups=None,
    max_offset_s: float = 0.0,
) -> Fraction:
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
    log-normal prior (one octave around :data:`_PRIOR_BPM`) covers the rest.  The best candidate is refined by
    least squares of the times on their grid positions, then the whole (or
    half) bpm next to it that the times favour.

    Accepted ambiguity: a phrase whose times all lie on half beats fits
    twice its tempo with whole beats just as well, and any phrase fits at
    double tempo on the same grid; the estimate may then be 2× (rarely ½×)
    the written tempo — the same movements at the same seconds, every
    start and duration still on the grid (the comparison of
    :mod:`.agreement` is made in time for this reason).

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
    Fraction
        Beats per minute, whole or half.
    """
    t = np.asarray(key_times, dtype=float)
    g = np.zeros(t.shape, int) if groups is None else np.asarray(groups, dtype=int)
    if g.shape != t.shape:
        raise QuantiseError(f"groups must have one entry per key time ({t.shape}), got {g.shape}")
    keep = np.isfinite(t) & (t > 0.5 * tolerance_s)
    t, g = t[keep], g[keep]
    lo, hi = tempo_range
    if t.size < 2:
        raise QuantiseError(
            f"cannot estimate a tempo from {t.size} key time(s); give the tempo (--tempo BPM)"
        )
    if not (0 < lo < hi):
        raise QuantiseError(f"tempo range must be 0 < low < high bpm, got {tempo_range}")
    cand = np.arange(np.floor(lo), np.ceil(hi) + 0.25, 0.25)
    d = None if durations is None else np.asarray(durations, dtype=float)
    if d is not None:
        d = d[np.isfinite(d) & (d > 0)]
    best = _refine(t, g, float(cand[int(np.argmax(_log_posterior(t, cand, grid, tolerance_s, d, g, max_offset_s)))]), grid, tolerance_s)
    # Whole bpm, or half a bpm (the half of an odd tempo, e.g. 48.5 for a
    # phrase of half beats at 97) when the times favour it by more than
    # :data:`_WHOLE_BPM_NATS`.
    near = np.unique([np.floor(best), np.ceil(best), round(2.0 * best) / 2.0])
    score = _log_posterior(t, near, grid, tolerance_s, d, g, max_offset_s) + _WHOLE_BPM_NATS * (near == np.round(near))
    pick = float(near[int(np.argmax(score))])
    return Fraction(int(round(2 * pick)), 2)


#: Preference (nats) for a whole number of beats per minute over a half.
_WHOLE_BPM_NATS = 4.0


def _log_posterior(t: np.ndarray, tempi: np.ndarray, grid: Fraction, tolerance_s: float, durations,
                   groups=None, max_offset_s: float = 0.0) -> np.ndarray:
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
        per += [_log_likelihood(tt, tempi, sigma, length, grid) for sigma in tolerance_s * np.array([1, 2, 4])]
    total = np.logaddexp.reduce(np.stack(per), axis=0) - np.log(len(per)) - 0.5 * np.log2(tempi / _PRIOR_BPM) ** 2
    if durations is not None and durations.size:
        # Movements last about a beat (the built-in phrases: all one beat;
        # random scores: ½ to 2 beats): each duration is evidence, in beats
        # log-normal around 1 beat, DURATION_OCTAVES wide.
        beats = durations[None, :] * tempi[:, None] / 60.0
        total = total - 0.5 * np.sum((np.log2(beats) / DURATION_OCTAVES) ** 2, axis=1)
    return total


def _refine(t: np.ndarray, g: np.ndarray, tempo: float, grid: Fraction, sigma: float) -> float:
    """Tempo from a straight-line fit of the key times on their grid positions.

    Each group of times has its own intercept: measured starts and arrivals
    are each delayed (or advanced) by about a frame, which a line through 0
    would read as another tempo.  Times more than 2 σ (at least a quarter
    grid step) off their grid points are left out; the refinement is kept
    only within 2 % of `tempo`.
    """
    q = 60.0 / tempo * float(grid)
    k = np.round(t / q)
    ok = np.abs(t - k * q) < max(2.0 * sigma, 0.25 * q)
    if ok.sum() < 3 or np.ptp(k[ok]) < 2:
        return tempo
    labels = np.unique(g[ok])
    design = np.column_stack([k[ok]] + [(g[ok] == lab).astype(float) for lab in labels])
    coef, *_ = np.linalg.lstsq(design, t[ok], rcond=None)
    refined = 60.0 * float(grid) / float(coef[0])
    return refined if abs(refined - tempo) < 0.02 * tempo else tempo


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
