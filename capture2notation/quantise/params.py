"""Tuning of the segmentation (:func:`~.segment.segment_motion`), shared by its stages."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

__all__ = ["SegmentParams"]


@dataclass(frozen=True)
class SegmentParams:
    """Tuning of :func:`segment`.

    Parameters
    ----------
    grid : Fraction
        Beat grid for starts and durations (default ¼ beat).
    smooth_s : float or None
        Savitzky–Golay window, seconds; ``None`` chooses it from the measured
        jitter (none for clean, e.g. synthetic, motion; 0.3–0.6 s otherwise,
        with thresholds above the jitter's speed).  Setting it forces the
        noisy-motion path.
    min_speed_deg_s : float
        Floor of the low (onset) speed threshold of noisy motion, degrees per
        second (clean motion: any motion at all).
    peak_speed_deg_s : float
        A movement must peak above this speed, degrees per second.
    min_amplitude_deg : float
        Smallest angular displacement that counts as a movement, degrees.
    split_ratio : float
        An interior speed minimum below this fraction of the smaller of the
        peaks on either side splits a run into two movements.
    merge_window_s : float
        Key times of different parts closer than this are merged (their
        median), capped at 0.45 grid steps so distinct grid points never merge.
    """

    grid: Fraction = Fraction(1, 4)
    smooth_s: float | None = None
    min_speed_deg_s: float = 2.0
    peak_speed_deg_s: float = 20.0
    min_amplitude_deg: float = 10.0
    split_ratio: float = 0.35
    merge_window_s: float = 0.3
