"""MediaPipe's refinement of landmark positions from the model's heatmaps.

Port of ``RefineLandmarksFromHeatMap``
(``mediapipe/calculators/util/refine_landmarks_from_heatmap_calculator.cc``),
vectorised over landmarks: for each landmark take the ``kernel_size`` square
of heatmap cells around its regressed position, turn the logits into
confidences with a sigmoid, and replace the position by the
confidence-weighted mean of the cell indices when the largest confidence in
the window reaches ``min_confidence``.  Cells outside the heatmap count as
zero confidence (MediaPipe shrinks the window at the border, which is the
same).  The pose graph uses ``kernel_size: 7`` and the default
``min_confidence_to_refine: 0.5``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["refine_from_heatmap"]


def refine_from_heatmap(
    uv: np.ndarray, heatmaps: np.ndarray, kernel_size: int = 7, min_confidence: float = 0.5
) -> tuple[np.ndarray, np.ndarray]:
    """Refine normalised landmark positions with their heatmaps.

    Parameters
    ----------
    uv : (K, 2) ndarray
        Landmark x, y normalised to the model input, in [0, 1).
    heatmaps : (K, H, W) ndarray
        Heatmap logits, one channel per landmark (the model's 39×64×64).
    kernel_size : int
        Odd window side in heatmap cells.
    min_confidence : float
        Refine only where the window's largest confidence reaches this.

    Returns
    -------
    uv : (K, 2) ndarray
        Refined positions (unchanged where not refined).
    confidence : (K,) ndarray
        Largest heatmap confidence in each window (0 outside the heatmap).
    """
    uv = np.asarray(uv, dtype=float)
    k, h, w = heatmaps.shape
    out = uv.copy()
    with np.errstate(invalid="ignore"):
        # MediaPipe truncates towards zero (C++ float→int cast).
        col = np.trunc(uv[:, 0] * w)
        row = np.trunc(uv[:, 1] * h)
    inside = np.isfinite(col) & np.isfinite(row) & (col >= 0) & (col < w) & (row >= 0) & (row < h)
    col = np.where(inside, col, 0).astype(int)
    row = np.where(inside, row, 0).astype(int)
    offsets = np.arange(kernel_size) - (kernel_size - 1) // 2
    rows = row[:, None] + offsets  # (K, S)
    cols = col[:, None] + offsets
    valid = ((rows >= 0) & (rows < h))[:, :, None] & ((cols >= 0) & (cols < w))[:, None, :]
    logits = heatmaps[
        np.arange(k)[:, None, None], np.clip(rows, 0, h - 1)[:, :, None], np.clip(cols, 0, w - 1)[:, None, :]
    ]
    conf = np.where(valid, 1.0 / (1.0 + np.exp(-logits.astype(float))), 0.0)  # (K, S, S)
    total = conf.sum(axis=(1, 2))
    peak = conf.max(axis=(1, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_col = (conf.sum(axis=1) * cols).sum(axis=1) / total
        mean_row = (conf.sum(axis=2) * rows).sum(axis=1) / total
    refine = inside & (peak >= min_confidence) & (total > 0)
    out[refine, 0] = mean_col[refine] / w
    out[refine, 1] = mean_row[refine] / h
    return out, np.where(inside, peak, 0.0)
