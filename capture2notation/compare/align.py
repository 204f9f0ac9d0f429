"""Temporal alignment of two performances.

Two routes (issue 4): dynamic time warping on limb-direction features when
either side is a recording, or plain tempo scaling when both sides carry a
score (the same beat then maps to the same movement).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body import body_frame, joint_index
from ..errors import CompareError
from ..notation.model import PART_SEGMENTS

__all__ = ["Alignment", "align_dtw", "align_tempo", "dtw", "limb_features"]

#: Limbs whose directions drive the alignment (whole limbs, head, chest):
#: the segments that Labanotation's main columns notate.
FEATURE_PARTS: tuple[str, ...] = ("right_arm", "left_arm", "right_leg", "left_leg", "head", "chest")


@dataclass(frozen=True)
class Alignment:
    """A monotone map between reference and candidate frames.

    Attributes
    ----------
    path : (L, 2) ndarray of int
        Pairs (reference frame, candidate frame), both non-decreasing.
    cost : float
        Mean feature distance along the path (1 − cosine, averaged over
        limbs; 0 = identical directions); NaN for tempo scaling.
    method : str
        ``"dtw"`` or ``"tempo"``.
    """

    path: np.ndarray
    cost: float
    method: str

    def candidate_frame(self, ref_frames) -> np.ndarray:
        """Candidate frame matched to each reference frame (first match on the path).

        Parameters
        ----------
        ref_frames : array_like of int

        Returns
        -------
        ndarray of int, same shape
        """
        ref_frames = np.asarray(ref_frames, dtype=int)
        r = self.path[:, 0]
        idx = np.searchsorted(r, np.clip(ref_frames, r[0], r[-1]), side="left")
        return self.path[np.clip(idx, 0, len(r) - 1), 1]


def limb_features(joints: np.ndarray) -> np.ndarray:
    """Unit direction of each feature limb in the body frame.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres.

    Returns
    -------
    (T, P, 3) ndarray
        One unit vector per limb of :data:`FEATURE_PARTS`; NaN where a joint
        is missing.
    """
    joints = np.asarray(joints, dtype=float)
    frame = body_frame(joints)
    a = np.array([joint_index(PART_SEGMENTS[p][0]) for p in FEATURE_PARTS])
    b = np.array([joint_index(PART_SEGMENTS[p][1]) for p in FEATURE_PARTS])
    v = joints[:, b] - joints[:, a]
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        v = np.where(n > 1e-12, v / n, np.nan)
    return np.einsum("tij,tpj->tpi", frame, v)


def _cost_matrix(fa: np.ndarray, fb: np.ndarray) -> np.ndarray:
    """Mean (1 − cosine) over limbs seen in both frames; 1 where none is."""
    a = np.nan_to_num(fa)
    b = np.nan_to_num(fb)
    ok_a = np.all(np.isfinite(fa), axis=-1).astype(float)  # (Ta, P)
    ok_b = np.all(np.isfinite(fb), axis=-1).astype(float)
    dots = np.einsum("ipk,jpk->ijp", a, b)
    both = ok_a[:, None, :] * ok_b[None, :, :]
    count = both.sum(-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.where(count > 0, (dots * both).sum(-1) / count, 0.0)
    return 1.0 - cos


def dtw(cost: np.ndarray, band: int | None = None) -> tuple[np.ndarray, float]:
    """Dynamic time warping of a cost matrix, vectorised along anti-diagonals.

    Parameters
    ----------
    cost : (Ta, Tb) ndarray
        Local cost of matching frame i of A to frame j of B (finite, >= 0).
    band : int, optional
        Sakoe–Chiba half-width in frames, measured after scaling B's time
        axis to A's length; ``None`` for no constraint.

    Returns
    -------
    path : (L, 2) ndarray of int
        Matched pairs from (0, 0) to (Ta − 1, Tb − 1).
    total : float
        Accumulated cost along the path.
    """
    c = np.asarray(cost, dtype=float)
    if c.ndim != 2 or min(c.shape) == 0:
        raise CompareError(f"DTW needs a non-empty 2-D cost matrix, got shape {c.shape}")
    if not np.all(np.isfinite(c)):
        raise CompareError("DTW cost matrix contains NaN or infinite values")
    ta, tb = c.shape
    if band is not None:
        i = np.arange(ta)[:, None]
        j = np.arange(tb)[None, :] * (ta - 1) / max(tb - 1, 1)
        c = np.where(np.abs(i - j) <= max(int(band), 1), c, np.inf)
    acc = np.full((ta + 1, tb + 1), np.inf)
    acc[0, 0] = 0.0
    # Cells on anti-diagonal d = i + j depend only on diagonals d−1 and d−2,
    # so each diagonal is one vectorised step.
    for d in range(ta + tb - 1):
        i = np.arange(max(0, d - tb + 1), min(ta, d + 1))
        j = d - i
        best = np.minimum(np.minimum(acc[i, j], acc[i, j + 1]), acc[i + 1, j])
        acc[i + 1, j + 1] = c[i, j] + best
    total = float(acc[ta, tb])
    if not np.isfinite(total):
        raise CompareError(f"DTW found no path inside the band of {band} frames; widen it")
    path = [(ta - 1, tb - 1)]
    i, j = ta, tb
    while i > 1 or j > 1:
        moves = (acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1])
        k = int(np.argmin(moves))
        if k == 0:
            i, j = i - 1, j - 1
        elif k == 1:
            i -= 1
        else:
            j -= 1
        path.append((i - 1, j - 1))
    return np.asarray(path[::-1], dtype=int), total


def align_dtw(ref_joints: np.ndarray, cand_joints: np.ndarray, band: int | None = None) -> Alignment:
    """Align two performances by DTW on limb directions.

    Parameters
    ----------
    ref_joints, cand_joints : (T, J, 3) ndarray
        World joints of the reference and the candidate, at the same frame
        rate (resample first otherwise).
    band : int, optional
        Sakoe–Chiba half-width in frames.

    Returns
    -------
    Alignment
    """
    fa = limb_features(ref_joints)
    fb = limb_features(cand_joints)
    path, total = dtw(_cost_matrix(fa, fb), band=band)
    return Alignment(path=path, cost=total / len(path), method="dtw")


def align_tempo(
    n_ref: int, n_cand: int, ref_tempo: float, cand_tempo: float, fps_ref: float, fps_cand: float
) -> Alignment:
    """Align two performances of scores by their tempi: same beat ↔ same pose.

    Reference frame i at time ``i / fps_ref`` is beat ``t·tempo_ref/60``;
    the candidate reaches that beat at ``beat·60/tempo_cand``.

    Parameters
    ----------
    n_ref, n_cand : int
        Frame counts.
    ref_tempo, cand_tempo : float
        Beats per minute.
    fps_ref, fps_cand : float
        Frame rates (Hz).

    Returns
    -------
    Alignment
        One pair per reference frame (candidate frames clipped to the take).
    """
    if min(ref_tempo, cand_tempo, fps_ref, fps_cand) <= 0:
        raise CompareError(
            f"tempo and frame rates must be > 0, got tempo {ref_tempo}/{cand_tempo} bpm, fps {fps_ref}/{fps_cand}"
        )
    i = np.arange(int(n_ref))
    beats = i / fps_ref * ref_tempo / 60.0
    j = np.clip(np.floor(beats * 60.0 / cand_tempo * fps_cand + 0.5), 0, int(n_cand) - 1).astype(int)
    return Alignment(path=np.stack([i, j], axis=1), cost=float("nan"), method="tempo")
