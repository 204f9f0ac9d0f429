"""Frame-rate reduction: Neagle's key-frame-preserving resampling and naive decimation.

Neagle (2005, §3.2.4, eq. 3.1) lowered a 25 Hz video to 12.5, 8.33 and 5 Hz
without culling the frames that show the notated key poses: between
consecutive key frames ``ka < kb`` (``N = kb − ka`` source frames) the new
rate ``r`` needs ``n = ceil(N·r / R)`` intervals, and the in-between frames
are ``ka + round_half_up(N·j / n)`` for ``j = 1 … n − 1``.  The thesis' worked
examples at r = 5 Hz, R = 25 Hz: key frames 36, 56 → 41, 46, 51; key frames
0, 36 → 5, 9, 14, 18, 23, 27, 32.

All arithmetic on frame numbers is exact (integers and fractions) so the
selection never depends on floating-point rounding.
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np

from ..errors import CompareError

__all__ = [
    "as_rate",
    "decimate",
    "hold_map",
    "in_between_frames",
    "keyframe_resample",
]


def as_rate(rate, source_rate=25) -> Fraction:
    """Exact frame rate from a number or a string such as ``'25/3'``.

    A decimal rate within 0.5 % of an integer divisor of the source rate is
    snapped to it, so the thesis' "8.33 Hz" means 25/3 Hz (every third
    frame) and not 833/100 Hz.

    Parameters
    ----------
    rate : int, float, str or Fraction
        Frames per second (> 0).
    source_rate : int, float, str or Fraction
        Rate of the source, used for snapping.

    Returns
    -------
    Fraction
    """
    try:
        r = Fraction(rate) if not isinstance(rate, float) else Fraction(str(rate))
    except (ValueError, ZeroDivisionError, TypeError):
        raise CompareError(f"frame rate {rate!r} is not a number or fraction like 25/3") from None
    if r <= 0:
        raise CompareError(f"frame rate {rate!r} must be > 0 Hz")
    if isinstance(source_rate, (Fraction, int)):
        src = Fraction(source_rate)
    else:
        src = Fraction(str(source_rate))
    k = round(src / r)
    if k >= 1 and abs(float(src / k - r)) <= 0.005 * float(r):
        return src / k
    return r


def _round_half_up(num: int, den: int) -> int:
    """round_half_up(num / den) for non-negative integers, exactly."""
    return (2 * num + den) // (2 * den)


def in_between_frames(ka: int, kb: int, rate, source_rate=25) -> list[int]:
    """In-between frames of eq. 3.1 for one pair of key frames.

    Parameters
    ----------
    ka, kb : int
        Consecutive key frames, ``ka < kb``.
    rate, source_rate : number, str or Fraction
        New and original frame rates (Hz).

    Returns
    -------
    list of int
        Frames strictly between `ka` and `kb`, increasing; empty when the new
        rate needs a single interval.

    Examples
    --------
    >>> in_between_frames(36, 56, 5, 25)
    [41, 46, 51]
    >>> in_between_frames(0, 36, 5, 25)
    [5, 9, 14, 18, 23, 27, 32]
    """
    ka, kb = int(ka), int(kb)
    if kb <= ka:
        raise CompareError(f"key frames must increase, got {ka} then {kb}")
    r = as_rate(rate, source_rate)
    big_r = as_rate(source_rate, source_rate)
    n_src = kb - ka
    q = Fraction(n_src) * r / big_r
    n = max(1, -(-q.numerator // q.denominator))  # ceil, exactly
    return [ka + _round_half_up(n_src * j, n) for j in range(1, n)]


def keyframe_resample(n_frames: int, key_frames, rate, source_rate=25) -> np.ndarray:
    """Frames kept when resampling to `rate` while preserving every key frame.

    The first and last frames bound the sequence and are treated as key
    frames too, so the whole take is covered.

    Parameters
    ----------
    n_frames : int
        Number of source frames.
    key_frames : array_like of int
        Key frames (any order, duplicates ignored), in ``[0, n_frames)``.
    rate, source_rate : number, str or Fraction
        New and original frame rates (Hz); ``rate <= source_rate``.

    Returns
    -------
    (M,) ndarray of int
        Increasing frame indices, containing every key frame.
    """
    n_frames = int(n_frames)
    if n_frames < 1:
        raise CompareError(f"need at least one frame, got n_frames={n_frames}")
    keys = np.unique(np.asarray(list(key_frames), dtype=int))
    if keys.size and (keys[0] < 0 or keys[-1] >= n_frames):
        raise CompareError(f"key frames must lie in [0, {n_frames - 1}], got {keys[0]}..{keys[-1]}")
    if as_rate(rate, source_rate) > as_rate(source_rate, source_rate):
        raise CompareError(f"rate {rate} Hz exceeds the source rate {source_rate} Hz")
    keys = np.union1d(keys, [0, n_frames - 1]).astype(int)
    out = [int(keys[0])]
    for ka, kb in itertools.pairwise(keys):
        out.extend(in_between_frames(int(ka), int(kb), rate, source_rate))
        out.append(int(kb))
    return np.asarray(out, dtype=int)


def decimate(n_frames: int, rate, source_rate=25) -> np.ndarray:
    """Naive uniform decimation: frames ``round_half_up(i·R / r)``, i = 0, 1, …

    This is the direct approach the thesis rejects (its Figure 3.9): key
    poses falling between the kept frames are lost.

    Returns
    -------
    (M,) ndarray of int
        Increasing frame indices below `n_frames`, starting at 0.
    """
    n_frames = int(n_frames)
    if n_frames < 1:
        raise CompareError(f"need at least one frame, got n_frames={n_frames}")
    r = as_rate(rate, source_rate)
    big_r = as_rate(source_rate, source_rate)
    if r > big_r:
        raise CompareError(f"rate {rate} Hz exceeds the source rate {source_rate} Hz")
    step = big_r / r  # source frames per kept frame
    count = int(Fraction(n_frames - 1) / step) + 1
    i = np.arange(count, dtype=np.int64)
    # round_half_up(i * p / q) with step = p / q, in integers.
    p, q = step.numerator, step.denominator
    idx = (2 * i * p + q) // (2 * q)
    return idx[idx < n_frames].astype(int)


def hold_map(kept: np.ndarray, n_frames: int) -> np.ndarray:
    """Source frame shown at each original frame when `kept` frames are held.

    This emulates playing the reduced rate at the original rate (the bottom
    rows of Neagle's Figures 3.9 and 3.11).

    Parameters
    ----------
    kept : (M,) array_like of int
        Increasing kept frames, the first being 0.
    n_frames : int

    Returns
    -------
    (n_frames,) ndarray of int
    """
    kept = np.asarray(kept, dtype=int)
    if kept.size == 0 or kept[0] != 0 or np.any(np.diff(kept) <= 0):
        raise CompareError("kept frames must be increasing and start at frame 0")
    pos = np.searchsorted(kept, np.arange(int(n_frames)), side="right") - 1
    return kept[pos]
