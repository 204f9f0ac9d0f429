"""Laban Effort: the logistic model, emotion presets, and its estimation.

``estimate_effort(joints, confidence, fps, score, rng)`` → :class:`EffortResult`
(per movement, pooled per part and phrase, emotion probabilities);
``write_effort(result, outdir)`` writes ``effort.json`` and the plots.
"""

from ..notation.effort import PRESETS, TIME_RANGE, WEIGHT_RANGE, Preset, progress, progress_speed, space_radius
from .curves import ProgressCurve, progress_curve
from .emotion import emotion_probabilities, same_or_different
from .estimate import EffortResult, MovementEffort, estimate_effort, movement_windows
from .fit import fit_logistic, fit_space
from .pooled import PooledEffort, pooled_posterior
from .posterior import Posterior, sample_posterior, sample_posteriors
from .report import write_effort

__all__ = [
    "PRESETS",
    "TIME_RANGE",
    "WEIGHT_RANGE",
    "EffortResult",
    "MovementEffort",
    "PooledEffort",
    "Posterior",
    "Preset",
    "ProgressCurve",
    "emotion_probabilities",
    "estimate_effort",
    "fit_logistic",
    "fit_space",
    "movement_windows",
    "pooled_posterior",
    "progress",
    "progress_curve",
    "progress_speed",
    "same_or_different",
    "sample_posterior",
    "sample_posteriors",
    "space_radius",
    "write_effort",
]
