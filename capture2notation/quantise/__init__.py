"""Quantisation: joints over time → per-frame labels, symbols and Benesh key poses.

* :func:`label_frames` / :func:`write_labels_csv` — direction, level and bend
  of every part at every frame (DESIGN.md thresholds), supports;
* :func:`segment` / :func:`segment_motion` — movements → a
  :class:`~capture2notation.notation.Score` on a beat grid (tempo given or
  :func:`estimate_tempo`);
* :func:`benesh_key_poses` / :func:`write_benesh` — Benesh key poses;
* :func:`compare_scores` — symbol agreement and start-time error of two
  scores, compared in time (their tempi may differ).
"""

from .agreement import Agreement, at_tempo, compare_scores, normalise, score_differences, symbol_agreement
from .benesh import BeneshPose, Extremity, Orientation, Stave, benesh_key_poses, estimate_stave, write_benesh
from .labels import FrameLabels, label_frames, write_labels_csv
from .segment import Movement, SegmentParams, Segmentation, segment, segment_motion
from .tempo import estimate_tempo, snap

__all__ = [
    "Agreement",
    "BeneshPose",
    "Extremity",
    "FrameLabels",
    "Movement",
    "Orientation",
    "SegmentParams",
    "Segmentation",
    "Stave",
    "at_tempo",
    "benesh_key_poses",
    "compare_scores",
    "estimate_stave",
    "estimate_tempo",
    "label_frames",
    "normalise",
    "score_differences",
    "segment",
    "segment_motion",
    "snap",
    "symbol_agreement",
    "write_benesh",
    "write_labels_csv",
]
