"""Comparing performances: resampling, alignment, metrics, sign tests, same/different trials.

* :mod:`.agreement` — symbol agreement of two scores per part per beat,
  start errors and exact differences of their normal forms
  (:func:`compare_scores`).
* :mod:`.resample` — Neagle's key-frame-preserving frame-rate reduction (eq. 3.1)
  and naive decimation.
* :mod:`.align` — DTW on limb directions, or tempo scaling between scores.
* :mod:`.metrics` — MPJPE, Procrustes-aligned MPJPE, key-pose angle errors,
  symbol agreement, timing offsets, Effort differences, verdicts.
* :mod:`.stats` — sign tests laid out like Wolofsky's Table III.
* :mod:`.discrimination` — same/different emotion trials (Neagle Exp. 1–2).
"""

from .agreement import Agreement, at_tempo, compare_scores, normalise, score_differences, symbol_agreement
from .align import Alignment, align_dtw, align_tempo, dtw, limb_features
from .discrimination import (
    THESIS,
    SameDifferentObserver,
    Trial,
    experiment1_trials,
    experiment2_trials,
    run_trials,
    summarise,
)
from .metrics import (
    MovementResult,
    agreement_by_part,
    compare_movements,
    effort_differences,
    key_frames,
    mpjpe,
    notation_agreement,
    pa_mpjpe,
    procrustes_align,
)
from .resample import as_rate, decimate, hold_map, in_between_frames, keyframe_resample
from .stats import SignTestRow, sign_test, signs_from_differences

__all__ = [
    "THESIS",
    "Agreement",
    "Alignment",
    "MovementResult",
    "SameDifferentObserver",
    "SignTestRow",
    "Trial",
    "agreement_by_part",
    "align_dtw",
    "align_tempo",
    "as_rate",
    "at_tempo",
    "compare_movements",
    "compare_scores",
    "decimate",
    "dtw",
    "effort_differences",
    "experiment1_trials",
    "experiment2_trials",
    "hold_map",
    "in_between_frames",
    "key_frames",
    "keyframe_resample",
    "limb_features",
    "mpjpe",
    "normalise",
    "notation_agreement",
    "pa_mpjpe",
    "procrustes_align",
    "run_trials",
    "score_differences",
    "sign_test",
    "signs_from_differences",
    "summarise",
    "symbol_agreement",
]
