"""Tempo from key-frame times (and a sound track's beats), and snapping times to a beat grid.

A score starts at beat 0 at time 0 (the renderer's and the capture's first
frame), so the beat grid has no free phase: only the period is estimated.

The estimate is a posterior over candidate tempi (:func:`estimate_tempo_detail`):

* a log-normal **prior** over the tempi of dance (:func:`tempo_log_prior`);
* the **key times** (movement starts and arrivals) on the beat grid: a
  time lies on a whole beat, a half beat or an odd quarter beat
  (:data:`LEVEL_WEIGHTS`), each point of its level equally likely over the
  phrase, with Gaussian timing error, or anywhere (:data:`OUTLIER_RATE`).
  Several parts arriving at one instant are one event of the grid, so
  times closer than the timing precision are counted once;
* the **movement durations**, hierarchically: a phrase has its own typical
  movement length, about one beat (a prior on movements per beat,
  :data:`PHRASE_DURATION_OCTAVES`), and its movements scatter around it
  (:data:`DURATION_SPREAD_OCTAVES`).  The typical length is marginalised, so
  twenty one-beat movements are one piece of evidence for "one movement a
  beat", not twenty;
* optionally other **evidence** on the same tempi, e.g. the beats of a
  sound track (:class:`~capture2notation.quantise.beats.SoundBeats`).

The motion's likelihood is tempered by :data:`EVIDENCE_WEIGHT`: its key
times and durations are not independent draws (one phrase, one rhythm), and
the tempering makes the stated confidence match how often the estimate is
right on development data (``benchmarks/bench_tempo.py`` measures it).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Protocol

import numpy as np

from ..errors import QuantiseError

__all__ = [
    "DURATION_OUTLIER_RATE",
    "DURATION_SPREAD_OCTAVES",
    "EVIDENCE_WEIGHT",
    "LEVEL_WEIGHTS",
    "MEASURED_EVIDENCE_WEIGHT",
    "OUTLIER_RATE",
    "PHRASE_DURATION_OCTAVES",
    "SAME_TEMPO",
    "TEMPO_PRIOR_BPM",
    "TEMPO_PRIOR_OCTAVES",
    "TEMPO_RANGE",
    "TempoEstimate",
    "TempoEvidence",
    "estimate_tempo",
    "estimate_tempo_detail",
    "snap",
    "tempo_log_prior",
]

#: Tempi searched by :func:`estimate_tempo_detail`, beats per minute.
TEMPO_RANGE = (30.0, 160.0)
#: Median of the log-normal tempo prior, bpm (one beat a second), chosen on
#: the development scores (random scores at 60–120 and 36–132 bpm, never
#: the held-out phrases) between the emotion presets of DESIGN.md (37–80
#: bpm, after Neagle) and quick allegro exercises (about 132 bpm).
TEMPO_PRIOR_BPM = 60.0
#: Standard deviation of the tempo prior, octaves: 37 and 132 bpm lie at
#: -1.4 σ and +2.3 σ, so half or double a tempo costs ½–2 nats of prior, and
#: the movements decide (see :func:`tempo_log_prior`).
TEMPO_PRIOR_OCTAVES = 0.5
#: Spread (octaves, one standard deviation) between phrases of their typical
#: movement length in beats, about one beat: a phrase of two-beat (or
#: half-beat) movements is 3.3 σ out, "one movement a beat" by far the
#: likeliest (0.2–0.5 tried on the development scores; 0.5 read a quarter
#: of the slow ones at double tempo).
PHRASE_DURATION_OCTAVES = 0.3
#: Spread (octaves) of the movement durations of one phrase around its
#: typical length (½ to 2 beats around 1 within ±1.5 σ).
DURATION_SPREAD_OCTAVES = 0.7
#: Share of movement durations that lie anywhere (spurious or merged
#: measured movements), spread evenly over _DURATION_SPAN_OCTAVES octaves.
DURATION_OUTLIER_RATE = 0.2
_DURATION_SPAN_OCTAVES = 8.0
#: Probabilities that a key time lies on a whole beat, a half beat (between
#: whole beats) and an odd quarter beat.  A whole beat must be more than
#: four times as likely as a half beat for phrases of whole beats to keep
#: their tempo rather than halve it (half the tempo has half the points).
LEVEL_WEIGHTS = (0.7, 0.15, 0.15)
#: Share of key times that lie on no beat (spurious or mistimed movements).
OUTLIER_RATE = 0.1
#: Tempering of the motion's log-likelihood (0–1]: the share of its key
#: times and durations that count as independent evidence, chosen so that
#: the confidence is calibrated on development scores (random seeds; never
#: the held-out phrases), measured by ``benchmarks/bench_tempo.py``.  Clean
#: key times (the dancer's own joints) count fully.
EVIDENCE_WEIGHT = 1.0
#: The same for measured key times (fitted from video: split and merged
#: movements, a frame or two of timing error): they carry little beat
#: information (their phase in the beat is nearly uniform on the
#: development renders), and at full weight their preference for double
#: the tempo exceeded 2 nats on a sixth of those clips, overriding a sound
#: track's beat; at a quarter, never.
MEASURED_EVIDENCE_WEIGHT = 0.25
#: Relative distance within which two tempi are the same reading: the
#: confidence is the posterior probability of the tempo within ±4 % of the
#: estimate (the accuracy ``benchmarks/bench_tempo.py`` scores).
SAME_TEMPO = 0.04
#: Relative distance beyond which a tempo is another reading (the runner-up).
_DISTINCT = 0.15
#: Preference (nats) for a whole number of beats per minute over a half.
_WHOLE_BPM_NATS = 4.0
#: Step of the candidate tempi, bpm.
_STEP_BPM = 0.25
#: Timing errors σ marginalised, in units of the tolerance.
_SIGMA_FACTORS = (1, 2, 4)
#: Grid of the phrase's typical log2 duration in beats, octaves.
_PHRASE_GRID = np.linspace(-3.0, 3.0, 121)


class TempoEvidence(Protocol):
    """Evidence on the tempo from outside the motion (e.g. a sound track's beats)."""

    #: What the evidence is, for the page ("the sound track").
    source: str

    def log_likelihood(self, tempi: np.ndarray) -> np.ndarray:
        """Log-likelihood (C,) of candidate tempi (C,), bpm, up to a constant."""
        ...  # pragma: no cover

    def refine(self, tempo: float) -> float | None:
        """The evidence's own precise tempo near `tempo` (bpm), or None if it has none there."""
        ...  # pragma: no cover


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
        Posterior probability that the tempo is within :data:`SAME_TEMPO`
        (4 %) of `tempo`, in [0, 1].
    source : str
        What set it: ``"the movements"``, or the evidence's source and the
        movements (``"the sound track and the movements"``).
    """

    tempo: Fraction
    runner_up: Fraction | None
    confidence: float
    source: str = "the movements"


def tempo_log_prior(tempi) -> np.ndarray:
    """Log prior density (up to a constant) of tempi: log-normal about :data:`TEMPO_PRIOR_BPM`.

    Parameters
    ----------
    tempi : array_like
        Beats per minute (> 0).

    Returns
    -------
    ndarray
        ``-½ (log2(tempo / TEMPO_PRIOR_BPM) / TEMPO_PRIOR_OCTAVES)²``.
    """
    x = np.log2(np.asarray(tempi, dtype=float) / TEMPO_PRIOR_BPM)
    return -0.5 * (x / TEMPO_PRIOR_OCTAVES) ** 2


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
    evidence: TempoEvidence | None = None,
    measured: bool = False,
) -> TempoEstimate:
    """Estimate the tempo from the times at which movements start and arrive.

    The posterior of the module docstring is evaluated on candidate tempi
    every :data:`_STEP_BPM` bpm; σ, the timing error of the key times, is
    marginalised over ``tolerance_s × (1, 2, 4)`` (the timing precision is
    not known in advance).  The best candidate is refined by least squares
    of the times on their half-beat points (or taken from the evidence's own
    precise tempo, a sound track's beats), then the whole (or half) bpm next
    to it that the posterior favours.

    Accepted ambiguity: a phrase whose every movement lasts two beats is the
    same motion as one-beat movements at half the tempo; the estimate
    prefers one movement a beat, the log-normal tempo prior weighing in,
    and its confidence says how sure it is (too sure on such phrases:
    ``docs/benchmarks/tempo.md``).

    Parameters
    ----------
    key_times : (N,) array_like
        Seconds; at least two distinct positive times are needed unless
        `evidence` is given.
    grid : Fraction
        Finest grid of the score, beats (½ or finer adds the half-beat
        level, ¼ or finer the odd grid steps).
    tempo_range : (float, float)
        Bpm range searched.
    tolerance_s : float
        Smallest timing error σ considered, seconds (about half a frame
        for clean motion, a frame for measured motion); times closer than
        it are one event.
    durations : (M,) array_like, optional
        Movement durations, seconds.
    groups : (N,) array_like of int, optional
        Group of each key time; the times of one group may share a constant
        timing bias (measured starts and arrivals are biased differently,
        by a frame or so), which the final line fit takes out.
    max_offset_s : float
        Largest such bias of the groups other than 0 in the likelihood,
        seconds: offsets in steps of `tolerance_s` up to it are marginalised
        (0: none, for clean times).
    evidence : TempoEvidence, optional
        Further evidence, added to the log-posterior untempered.
    measured : bool
        The key times and durations are measured (fitted from video), not
        clean: the motion's likelihood is tempered by
        :data:`MEASURED_EVIDENCE_WEIGHT` instead of :data:`EVIDENCE_WEIGHT`.

    Returns
    -------
    TempoEstimate
        The tempo (whole or half bpm), the runner-up reading, the confidence
        and the source.
    """
    t = np.asarray(key_times, dtype=float)
    g = np.zeros(t.shape, int) if groups is None else np.asarray(groups, dtype=int)
    if g.shape != t.shape:
        raise QuantiseError(f"groups must have one entry per key time ({t.shape}), got {g.shape}")
    keep = np.isfinite(t) & (t > 0.5 * tolerance_s)
    t, g = t[keep], g[keep]
    lo, hi = tempo_range
    if not (0 < lo < hi):
        raise QuantiseError(f"tempo range must be 0 < low < high bpm, got {tempo_range}")
    if t.size < 2 and evidence is None:
        raise QuantiseError(f"cannot estimate a tempo from {t.size} key time(s); give the tempo (--tempo BPM)")
    cand = np.arange(np.floor(lo), np.ceil(hi) + 0.5 * _STEP_BPM, _STEP_BPM)
    d = None if durations is None else np.asarray(durations, dtype=float)
    if d is not None:
        d = d[np.isfinite(d) & (d > 0)]
    te, ge = _distinct(t, g, tolerance_s, merge_groups=max_offset_s == 0.0)
    weight = MEASURED_EVIDENCE_WEIGHT if measured else EVIDENCE_WEIGHT

    def log_post(tempi):
        out = tempo_log_prior(tempi)
        if te.size >= 2:
            out = out + weight * _times_log_likelihood(te, tempi, grid, tolerance_s, ge, max_offset_s)
        if d is not None and d.size:
            out = out + weight * _durations_log_likelihood(d, tempi)
        if evidence is not None:
            out = out + evidence.log_likelihood(tempi)
        return out

    post = log_post(cand)
    # The reading most probably right: the candidate with the largest
    # posterior mass within ±SAME_TEMPO (not the highest point: a sharp
    # peak may hold less mass than a broad one).
    p = np.exp(post - post.max())
    mass = _window_mass(cand, p, SAME_TEMPO)
    best = _peak_near(cand, post, float(cand[int(np.argmax(mass))]))
    precise = evidence.refine(best) if evidence is not None else None
    best = precise if precise is not None else _refine(t, g, best, grid, tolerance_s)
    # The refined tempo, to the nearest whole bpm; or half a bpm (the
    # half of an odd tempo, e.g. 48.5 for a phrase of half beats at 97) when
    # the posterior favours it by more than :data:`_WHOLE_BPM_NATS`.
    near = np.unique([np.floor(best), np.ceil(best), round(2.0 * best) / 2.0])
    score = log_post(near) + _WHOLE_BPM_NATS * (near == np.round(near))
    pick = Fraction(int(round(2 * float(near[int(np.argmax(score))]))), 2)
    ratio = np.abs(np.log(cand / float(pick)))
    confidence = float(p[ratio <= np.log1p(SAME_TEMPO)].sum() / p.sum())
    # Runner-up: the best reading more than _DISTINCT apart (typically half or double).
    far = ratio >= np.log1p(_DISTINCT)
    runner_up = None
    if np.any(far):
        other = _peak_near(cand, post, float(cand[far][int(np.argmax(mass[far]))]))
        refined = evidence.refine(other) if evidence is not None else None
        other = refined if refined is not None else _refine(t, g, other, grid, tolerance_s)
        runner_up = Fraction(int(round(other)))
    moved = te.size >= 2 or (d is not None and d.size > 0)
    source = (
        "the movements" if evidence is None else f"{evidence.source} and the movements" if moved else evidence.source
    )
    return TempoEstimate(pick, runner_up, confidence, source)


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


def _window_mass(cand: np.ndarray, p: np.ndarray, rel: float) -> np.ndarray:
    """Sum (C,) of `p` over the candidates within a factor ``1 ± rel`` of each candidate (sorted `cand`)."""
    cum = np.r_[0.0, np.cumsum(p)]
    lo = np.searchsorted(cand, cand / (1.0 + rel), side="left")
    hi = np.searchsorted(cand, cand * (1.0 + rel), side="right")
    return cum[hi] - cum[lo]


def _peak_near(cand: np.ndarray, post: np.ndarray, tempo: float) -> float:
    """The most probable candidate within ±SAME_TEMPO of `tempo`."""
    near = np.abs(np.log(cand / tempo)) <= np.log1p(SAME_TEMPO)
    return float(cand[near][int(np.argmax(post[near]))])


def _distinct(t: np.ndarray, g: np.ndarray, tolerance_s: float, merge_groups: bool):
    """Key times with those closer than `tolerance_s` (within a group, or all) merged to their mean.

    Parts that start or arrive together mark one instant of the beat grid:
    counted once, they do not multiply the evidence of that instant.
    """
    key = np.zeros_like(g) if merge_groups else g
    out_t, out_g = [], []
    for lab in np.unique(key):
        sel = key == lab
        ts, gs = t[sel], g[sel]
        order = np.argsort(ts)
        ts, gs = ts[order], gs[order]
        cut = np.flatnonzero(np.diff(ts) > tolerance_s) + 1
        for run_t, run_g in zip(np.split(ts, cut), np.split(gs, cut)):
            out_t.append(float(run_t.mean()))
            out_g.append(int(np.bincount(run_g - run_g.min()).argmax() + run_g.min()))
    return np.asarray(out_t), np.asarray(out_g, dtype=int)


def _times_log_likelihood(
    t: np.ndarray, tempi: np.ndarray, grid: Fraction, tolerance_s: float, groups: np.ndarray, max_offset_s: float
) -> np.ndarray:
    """Log-likelihood (C,) of the key times at each tempo, σ and group offsets marginalised.

    Times of groups other than 0 may be offset by a constant of up to
    ±`max_offset_s` (in steps of `tolerance_s`, marginalised)."""
    length = float(t.max()) + 0.5
    shifts = [0.0]
    steps = int(max_offset_s / tolerance_s + 1e-9)
    if np.any(groups != 0) and steps > 0:
        shifts = list(tolerance_s * np.arange(-steps, steps + 1))
    per = []
    for c in shifts:
        tt = np.where(groups != 0, t - c, t)
        per += [_log_likelihood(tt, tempi, sigma, length, grid) for sigma in tolerance_s * np.array(_SIGMA_FACTORS)]
    return np.logaddexp.reduce(np.stack(per), axis=0) - np.log(len(per))


def _durations_log_likelihood(durations: np.ndarray, tempi: np.ndarray) -> np.ndarray:
    """Log-likelihood (C,) of movement durations (seconds) at each tempo (the module docstring).

    In beats, log2 durations scatter log-normally (:data:`DURATION_SPREAD_OCTAVES`)
    around the phrase's typical length μ, which is itself about one beat
    (:data:`PHRASE_DURATION_OCTAVES`) and is marginalised on a grid; a
    share of the durations (:data:`DURATION_OUTLIER_RATE`) lie anywhere.
    """
    y = np.log2(durations[None, :] * tempi[:, None] / 60.0)  # (C, M) log2 beats
    mu = _PHRASE_GRID
    z = (y[:, None, :] - mu[None, :, None]) / DURATION_SPREAD_OCTAVES  # (C, G, M)
    typical = np.exp(-0.5 * z**2) / (DURATION_SPREAD_OCTAVES * np.sqrt(2.0 * np.pi))
    dens = (1.0 - DURATION_OUTLIER_RATE) * typical + DURATION_OUTLIER_RATE / _DURATION_SPAN_OCTAVES
    log_mu_prior = -0.5 * (mu / PHRASE_DURATION_OCTAVES) ** 2
    log_mu_prior -= np.logaddexp.reduce(log_mu_prior)
    return np.logaddexp.reduce(np.log(dens).sum(axis=2) + log_mu_prior[None, :], axis=1)


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
_REFINE_PASSES = 2
#: Largest distance (beats) of a time from its half beat in the refinement.
_REFINE_TRIM = 0.2


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
