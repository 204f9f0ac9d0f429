"""Emotion probabilities from the pooled Effort posterior and the tempo.

Each preset (happy, sad, angry, afraid; :data:`~.presets.PRESETS`) is a
Gaussian in the feature space (time b, weight x0, space S, ln tempo) centred
on the preset; its spread per feature is the performer-to-performer
variation plus estimation error, measured on a seeded synthetic calibration
set (``benchmarks/calibrate_effort.py --derive`` prints the constants below),
plus the posterior's own uncertainty for the performance being judged.
Equal prior probabilities.
"""

from __future__ import annotations

import numpy as np

from ..errors import EffortError
from ..notation.effort import PRESETS

__all__ = [
    "FEATURES",
    "PERFORMER_SD",
    "SPREAD",
    "TEMPERATURE",
    "emotion_log_likelihoods",
    "emotion_probabilities",
    "features",
    "preset_features",
    "same_or_different",
]

#: Feature order: Laban time b, weight x0, space S, natural log of tempo (bpm).
FEATURES = ("time", "weight", "space", "log_tempo")

#: Performer-to-performer variation of the synthetic calibration performers
#: (standard deviations about the preset, same order as FEATURES).  An
#: assumption of this project (Neagle gives one value per emotion): 95 % of
#: performers keep b within ±0.6, x0 within ±0.1, S within ±0.5 and tempo
#: within ±20 % of the preset.
PERFORMER_SD = (0.3, 0.05, 0.25, 0.1)

#: Spread of the estimated features about their preset, per feature, fitted
#: on the calibration set: RMS of (estimate − preset) over 120 seeded
#: synthetic performances (30 per emotion, seed 2005, 4-symbol arm phrases
#: by ``synthetic.interpret``, truth joints at 25 Hz), as printed by
#: ``benchmarks/calibrate_effort.py --derive``.
SPREAD = (0.2974, 0.0446, 0.1861, 0.1052)


#: Temperature of the emotion probabilities (log-likelihoods divided by it):
#: fitted by ``benchmarks/bench_effort_coverage.py --derive --emotion-n 100``
#: on 400 synthetic performances (fitting seed 2005) so that the claims are
#: calibrated on fresh seeds (the reliability table in docs/benchmarks/effort.md).
TEMPERATURE = 3.16


def preset_features() -> tuple[tuple[str, ...], np.ndarray]:
    """Emotion names and their (4,) feature vectors, shape (E, 4)."""
    names = tuple(PRESETS)
    mat = np.array([[p.effort.time, p.effort.weight, p.effort.space, np.log(float(p.tempo))] for p in PRESETS.values()])
    return names, mat


def features(time: float, weight: float, space: float, tempo: float) -> np.ndarray:
    """(4,) feature vector of a performance; tempo in beats per minute (> 0)."""
    if not tempo > 0:
        raise EffortError(f"tempo must be > 0 beats per minute, got {tempo}")
    return np.array([time, weight, space, np.log(tempo)], dtype=float)


def emotion_probabilities(x, sd=None, spread=SPREAD, temperature: float = TEMPERATURE) -> dict:
    """Posterior probability of each emotion preset for one performance.

    Parameters
    ----------
    x : (4,) array_like
        Features (time, weight, space, ln tempo), see :func:`features`.
    sd : (4,) array_like, optional
        Posterior standard deviation of each feature (estimation
        uncertainty of this performance), added in quadrature to `spread`.
    spread : (4,) array_like
        Calibrated spread of the features about the presets.
    temperature : float
        Divides the log-likelihoods (see :data:`TEMPERATURE`).

    Returns
    -------
    dict
        ``{emotion: p}`` over the four presets, summing to 1.
    """
    names, _ = preset_features()
    ll = emotion_log_likelihoods(x, sd, spread) / float(temperature)
    p = np.exp(ll - ll.max())
    p /= p.sum()
    return {n: float(v) for n, v in zip(names, p)}


def emotion_log_likelihoods(x, sd=None, spread=SPREAD) -> np.ndarray:
    """(E,) Gaussian log-likelihood of `x` under each preset, in :data:`PRESETS` order (equal normalisers).

    Parameters as for :func:`emotion_probabilities`.
    """
    x = np.asarray(x, dtype=float)
    if x.shape != (4,) or not np.all(np.isfinite(x)):
        raise EffortError(f"emotion features must be 4 finite numbers (time, weight, space, ln tempo), got {x}")
    var = np.asarray(spread, dtype=float) ** 2
    if sd is not None:
        var = var + np.nan_to_num(np.asarray(sd, dtype=float), nan=0.0) ** 2
    _, mu = preset_features()
    return -0.5 * np.sum((x - mu) ** 2 / var, axis=1)


def same_or_different(p1: dict, p2: dict) -> bool:
    """Automated observer of Neagle's Experiment 1: True for "same".

    Two performances are judged the same emotion when their most probable
    emotions agree (the experts answered from their best reading too).
    """
    keys = tuple(PRESETS)
    a = np.array([p1[k] for k in keys])
    b = np.array([p2[k] for k in keys])
    return bool(np.argmax(a) == np.argmax(b))
