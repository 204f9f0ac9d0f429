"""Quantisation: joints over time → per-frame labels, symbols and Benesh key poses.

* :func:`label_frames` / :func:`write_labels_csv` — direction, level and bend
  of every part at every frame (DESIGN.md thresholds), supports;
* :func:`segment` / :func:`segment_motion` — movements → a
  :class:`~capture2notation.notation.Score` on a beat grid (tempo given or
  :func:`estimate_tempo`);
* :func:`benesh_key_poses` / :func:`write_benesh` — Benesh key poses.

How close two scores are is :func:`capture2notation.compare.compare_scores`.
"""

from .benesh import BeneshPose, Extremity, Orientation, Stave, benesh_key_poses, estimate_stave, write_benesh
from .labels import FrameLabels, label_frames, write_labels_csv
from .segment import Movement, Segmentation, SegmentParams, segment, segment_motion
from .tempo import estimate_tempo, snap

__all__ = [
    "BeneshPose",
    "Extremity",
    "FrameLabels",
    "Movement",
    "Orientation",
    "SegmentParams",
    "Segmentation",
    "Stave",
    "benesh_key_poses",
    "estimate_stave",
    "estimate_tempo",
    "label_frames",
    "segment",
    "segment_motion",
    "snap",
    "write_benesh",
    "write_labels_csv",
]
