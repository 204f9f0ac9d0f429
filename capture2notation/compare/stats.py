"""Sign tests over movements, laid out like Wolofsky's Table III (1974).

Wolofsky compared two films per assessor and question: ``+`` when the
Motion Analyzer film was rated higher, ``−`` when lower, ``0`` (dropped) when
equal, then reported the positive and negative counts, the non-zero total,
the smaller count ("total of fewer signs") and its one-tailed binomial
probability at the 5 % level (Siegel 1956).  Here the "assessors" are the
movements of a phrase and each row is one question asked of every movement
(is the candidate late?  is its limb higher? ...).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import binomtest

from ..errors import CompareError

__all__ = ["SignTestRow", "sign_test", "signs_from_differences"]


@dataclass(frozen=True)
class SignTestRow:
    """One row of a Table III style sign test.

    Attributes
    ----------
    question : str
    positive, negative : int
        Counts of ``+`` and ``−`` signs (ties dropped).
    total : int
        ``positive + negative``.
    fewer : int
        ``min(positive, negative)``.
    p : float
        One-tailed probability of `fewer` or fewer signs of one kind under
        p = 1/2 (NaN when `total` is 0).
    significant : bool
        ``p < alpha``.
    alpha : float
    """

    question: str
    positive: int
    negative: int
    total: int
    fewer: int
    p: float
    significant: bool
    alpha: float = 0.05

    def as_dict(self) -> dict:
        return asdict(self)


def signs_from_differences(diff, tolerance: float = 0.0) -> np.ndarray:
    """Signs of paired differences, ``0`` within ``±tolerance`` or where NaN.

    Parameters
    ----------
    diff : (N,) array_like
        Candidate minus reference (any unit).
    tolerance : float
        Differences no larger than this count as ties (same unit as `diff`).

    Returns
    -------
    (N,) ndarray of int in {−1, 0, 1}
    """
    d = np.asarray(diff, dtype=float)
    s = np.sign(np.nan_to_num(d)).astype(int)
    s[np.isnan(d) | (np.abs(np.nan_to_num(d)) <= tolerance)] = 0
    return s


def sign_test(signs, question: str = "", alpha: float = 0.05) -> SignTestRow:
    """Sign test of one question, as a row of Wolofsky's Table III.

    Parameters
    ----------
    signs : (N,) array_like of {−1, 0, 1}
        One sign per movement (or per assessor); zeros are ties and reduce
        the number of pairs, as in the thesis.
    question : str
        Label of the row.
    alpha : float
        Significance level (the thesis used 0.05).

    Returns
    -------
    SignTestRow

    Examples
    --------
    Question 1b of Table III: 17 positive, 5 negative signs, p = .008.

    >>> round(sign_test([1] * 17 + [-1] * 5).p, 3)
    0.008
    """
    s = np.asarray(signs)
    if s.size and not np.all(np.isin(s, (-1, 0, 1))):
        raise CompareError(f"sign test of {question!r}: signs must be -1, 0 or 1, got {np.unique(s).tolist()}")
    if not 0.0 < alpha < 1.0:
        raise CompareError(f"alpha must lie in (0, 1), got {alpha}")
    pos = int(np.sum(s == 1))
    neg = int(np.sum(s == -1))
    total = pos + neg
    fewer = min(pos, neg)
    if total == 0:
        p = float("nan")
    else:
        p = float(binomtest(fewer, total, 0.5, alternative="less").pvalue)
    return SignTestRow(question, pos, neg, total, fewer, p, bool(total and p < alpha), alpha)
