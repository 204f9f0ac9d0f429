"""Temporal alignment of two performances.

Two routes (issue 4): dynamic time warping on limb-direction features when
either side is a recording, or plain tempo scaling when both sides carry a
score (the same beat then maps to the same movement).

:func:`align_performances` is the warping ``c2n score`` uses: a movement can
only be matched near its own time (within :data:`MAX_LAG_S` plus
:data:`MAX_DRIFT` of the time elapsed), and either performance may begin or
end with time matched to nothing, each unmatched frame costing
:data:`GAP_COST`; so a long candidate against a short reference is mostly
unmatched instead of being stretched over it.  :func:`align_dtw` is the
classic end-to-end warping (both performances start and end together).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body import body_frame, joint_index
from ..errors import CompareError
from ..notation.model import PART_SEGMENTS

__all__ = [
    "GAP_COST",
    "MAX_DRIFT",
    "MAX_LAG_S",
    "WARP_COST",
    "Alignment",
    "align_dtw",
    "align_performances",
    "align_tempo",
    "dtw",
    "limb_features",
]

#: Limbs whose directions drive the alignment (whole limbs, head, chest):
#: the segments that Labanotation's main columns notate.
FEATURE_PARTS: tuple[str, ...] = ("right_arm", "left_arm", "right_leg", "left_leg", "head", "chest")

#: Seconds a performer may start early or late against the reference (a
#: count-in, a cue taken late).
MAX_LAG_S = 2.0
#: Fraction of the elapsed time by which a performance may run ahead or
#: behind on top of that: a tempo up to 25 % off the reference's.
MAX_DRIFT = 0.25
#: Seconds: the widest the matching window gets however long the piece (a
#: bound on memory too: a row of the alignment holds at most 2 × 30 s of frames).
MAX_WINDOW_S = 30.0
#: Cost of leaving one frame of either performance unmatched, in the units
#: of the feature distance (mean 1 − cosine over the limbs): 1 − cos 45°.
#: Frames whose limbs lie on average within 45° — one direction sector — of
#: each other are cheaper matched than left out.
GAP_COST = 1.0 - float(np.cos(np.pi / 4))
#: Extra cost of matching a frame to one already matched (a horizontal or
#: vertical step), half the gap cost: without it, the open end lets a held
#: final pose of the reference swallow the next second of an unrelated
#: continuation whose limbs happen to lie within 45° of it.  A tempo 25 %
#: off warps a fifth of the frames: 0.04 per frame, well under the gap.
WARP_COST = GAP_COST / 2
#: Hz: the rate the warping runs at (faster sources are decimated); limb
#: directions change little within 40 ms.
ALIGN_RATE_HZ = 25.0


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
    n_ref: int | None = None
    n_cand: int | None = None

    @property
    def ref_span(self) -> tuple[int, int]:
        """First and last reference frame matched to anything."""
        return int(self.path[0, 0]), int(self.path[-1, 0])

    @property
    def cand_span(self) -> tuple[int, int]:
        """First and last candidate frame matched to anything."""
        return int(self.path[:, 1].min()), int(self.path[:, 1].max())

    def matched(self, ref_frames) -> np.ndarray:
        """Whether each reference frame lies inside the matched stretch."""
        r = np.asarray(ref_frames, dtype=int)
        lo, hi = self.ref_span
        return (r >= lo) & (r <= hi)

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
    j = np.floor(beats * 60.0 / cand_tempo * fps_cand + 0.5).astype(int)
    # Reference beats the candidate never reaches are unmatched, not pinned to its last frame.
    keep = j <= int(n_cand) - 1
    keep[0] = True
    j = np.minimum(j, int(n_cand) - 1)
    return Alignment(
        path=np.stack([i[keep], j[keep]], axis=1),
        cost=float("nan"),
        method="tempo",
        n_ref=int(n_ref),
        n_cand=int(n_cand),
    )


def align_performances(
    ref_joints: np.ndarray,
    cand_joints: np.ndarray,
    fps: float,
    *,
    max_lag_s: float = MAX_LAG_S,
    max_drift: float = MAX_DRIFT,
    gap_cost: float = GAP_COST,
    warp_cost: float = WARP_COST,
) -> Alignment:
    """Warp the candidate onto the reference near their own times, ends left open.

    Parameters
    ----------
    ref_joints, cand_joints : (T, J, 3) ndarray
        World joints at the same frame rate `fps` (resample first otherwise).
    fps : float
        Hz.
    max_lag_s, max_drift : float
        Candidate frame ``j`` may match reference frame ``i`` only when
        ``|j − i| / fps <= min(max_lag_s + max_drift · i / fps, MAX_WINDOW_S)``.
    gap_cost : float
        Cost per frame, of either side, left unmatched at the start or end.
    warp_cost : float
        Extra cost of each horizontal or vertical step (one frame matched to
        a frame already matched).

    Returns
    -------
    Alignment
        ``path`` has one pair per matched reference frame (the candidate
        frame where it is first matched); frames outside ``ref_span`` and
        ``cand_span`` are unmatched.  ``cost`` is the total cost per frame of
        both performances (unmatched frames at `gap_cost`).

    Notes
    -----
    Symmetric DTW (a diagonal step weighs its cost twice, a horizontal or
    vertical step once, so every frame of either side counts once) inside a
    Sakoe–Chiba window around equal times, with open beginnings and ends
    whose skipped frames cost `gap_cost` each.  It runs row by row over the
    window only, at :data:`ALIGN_RATE_HZ` at most: memory is one byte per
    window cell.
    """
    if not (np.isfinite(fps) and fps > 0):
        raise CompareError(f"frame rate must be > 0, got {fps!r}")
    step = max(1, int(round(fps / ALIGN_RATE_HZ)))
    fa = limb_features(np.asarray(ref_joints, float)[::step])
    fb = limb_features(np.asarray(cand_joints, float)[::step])
    rate = fps / step
    half = np.minimum(max_lag_s + max_drift * np.arange(len(fa)) / rate, MAX_WINDOW_S) * rate
    path, total = _windowed_dtw(fa, fb, half, gap_cost, warp_cost)
    n_ref, n_cand = len(ref_joints), len(cand_joints)
    # Back to full rate: each reference frame takes the candidate frame
    # interpolated along the path (first match of each decimated row).
    rows, first = np.unique(path[:, 0], return_index=True)
    r0, r1 = rows[0] * step, min(rows[-1] * step + step - 1, n_ref - 1)
    ref_full = np.arange(r0, r1 + 1)
    cand_full = np.interp(ref_full, rows * step, path[first, 1] * step)
    cand_full = np.clip(np.round(cand_full), 0, n_cand - 1).astype(int)
    cand_full = np.maximum.accumulate(cand_full)
    return Alignment(
        path=np.stack([ref_full, cand_full], axis=1),
        cost=total / (len(fa) + len(fb)),
        method="dtw",
        n_ref=n_ref,
        n_cand=n_cand,
    )


def _windowed_dtw(
    fa: np.ndarray, fb: np.ndarray, half: np.ndarray, gap: float, warp: float
) -> tuple[np.ndarray, float]:
    """Open-ended symmetric DTW inside ``|j − i| <= half[i]``; (path (L, 2), total cost)."""
    ta, tb = len(fa), len(fb)
    if ta == 0 or tb == 0:
        raise CompareError(f"cannot align an empty performance ({ta} and {tb} frames)")
    i_all = np.arange(ta)
    lo = np.maximum(0, np.ceil(i_all - half)).astype(int)
    hi = np.minimum(tb - 1, np.floor(i_all + half)).astype(int)
    ok_a = np.all(np.isfinite(fa), axis=-1)
    ok_b = np.all(np.isfinite(fb), axis=-1)
    a0, b0 = np.nan_to_num(fa), np.nan_to_num(fb)
    ptrs: list[np.ndarray] = []  # per row: 0 diagonal, 1 from above, 2 from the left, 3 start
    best_end, end_cell = np.inf, None
    prev = None
    for i in range(ta):
        if lo[i] > hi[i]:
            break  # the window has left the candidate: later rows cannot be matched
        j = np.arange(lo[i], hi[i] + 1)
        both = ok_a[i][None, :] & ok_b[j]
        n = both.sum(-1)
        dots = np.einsum("pk,jpk->jp", a0[i], b0[j])
        with np.errstate(invalid="ignore", divide="ignore"):
            c = 1.0 - np.where(n > 0, (dots * both).sum(-1) / n, 0.0)
        cand = np.full((3, len(j)), np.inf)
        if prev is not None:
            plo, pacc = prev
            k = j - 1 - plo  # diagonal from (i - 1, j - 1)
            inside = (k >= 0) & (k < len(pacc))
            cand[0, inside] = pacc[k[inside]] + 2.0 * c[inside]
            k = j - plo  # from above (i - 1, j)
            inside = (k >= 0) & (k < len(pacc))
            cand[1, inside] = pacc[k[inside]] + c[inside] + warp
        if i == 0:
            cand[2] = gap * j + 2.0 * c  # skip the candidate's first j frames
        elif j[0] == 0:
            cand[2, 0] = gap * i + 2.0 * c[0]  # skip the reference's first i frames
        choice = np.argmin(cand, axis=0)
        best = cand[choice, np.arange(len(j))]
        # Steps from the left within the row: acc[j] = min_k<=j best[k] + c[k+1..j].
        csum = np.cumsum(c + warp)
        run = np.minimum.accumulate(best - csum)
        acc = csum + run
        ptr = np.where(choice == 2, 3, choice).astype(np.int8)
        ptr[(best - csum) > run] = 2
        ptrs.append(ptr)
        prev = (lo[i], acc)
        if hi[i] == tb - 1 and np.isfinite(acc[-1]):  # end on the candidate's last frame
            cost = acc[-1] + gap * (ta - 1 - i)
            if cost < best_end:
                best_end, end_cell = cost, (i, tb - 1)
        if i == ta - 1:  # end on the reference's last frame
            ends = acc + gap * (tb - 1 - j)
            k = int(np.argmin(ends))
            if ends[k] < best_end:
                best_end, end_cell = float(ends[k]), (i, int(j[k]))
    if end_cell is None:
        raise CompareError("the performances share no time inside the matching window")
    i, jj = end_cell
    path = [(i, jj)]
    while True:
        p = ptrs[i][jj - lo[i]]
        if p == 3:
            break
        if p == 0:
            i, jj = i - 1, jj - 1
        elif p == 1:
            i -= 1
        else:
            jj -= 1
        path.append((i, jj))
    return np.asarray(path[::-1], dtype=int), float(best_end)
