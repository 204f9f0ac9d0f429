"""Agreement beyond chance: is a candidate the same piece as the reference?

Two performances agree on a movement when the candidate's limb, at the
frame aligned to the reference's key pose, is in the same direction and
level.  Some agreement comes free: arms hang ``place low`` most of the time
in most dances, so any candidate that stands still agrees with every
reference movement back to the hanging arm.  The chance of agreeing on a
movement is therefore measured on the candidate itself: the share of its
matched frames in which that limb is in the reference's class.  Agreement
is then judged against those chances (Cohen's κ and a one-sided
Poisson-binomial test), and two performances are the same piece only when
they agree clearly beyond chance over most of both.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import CompareError

__all__ = [
    "SAME_PIECE_ALPHA",
    "SAME_PIECE_KAPPA",
    "SAME_PIECE_MATCHED",
    "Verdict",
    "chance_of_agreeing",
    "poisson_binomial_sf",
    "same_piece",
]

#: Cohen's κ (agreement beyond chance) from which two performances count as
#: the same piece: "moderate" agreement on Landis & Koch's (1977) scale.
SAME_PIECE_KAPPA = 0.4
#: One-sided significance level of the agreement count against chance.
SAME_PIECE_ALPHA = 0.05
#: Share of each performance's time that must be matched to the other.
SAME_PIECE_MATCHED = 0.5


def chance_of_agreeing(target: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """Share of frames in which each movement's limb is in its target class.

    Parameters
    ----------
    target : (M,) ndarray of int
        Class code (direction × 3 + level) the reference has at each movement.
    codes : (M, T) ndarray of int
        The candidate's class code of that movement's limb in each of T
        frames (−1 where undefined, which never agrees).

    Returns
    -------
    (M,) ndarray
        In [0, 1]; NaN when T = 0.
    """
    target = np.asarray(target)
    codes = np.asarray(codes)
    if codes.ndim != 2 or codes.shape[0] != target.shape[0]:
        raise CompareError(f"need (M, T) codes for M = {target.shape[0]} movements, got shape {codes.shape}")
    if codes.shape[1] == 0:
        return np.full(target.shape[0], np.nan)
    return np.mean(codes == target[:, None], axis=1)


def poisson_binomial_sf(k: int, p: np.ndarray) -> float:
    """P(X ≥ k) for X a sum of independent Bernoulli(p_i) (exact, O(n²)).

    Parameters
    ----------
    k : int
    p : (n,) array_like
        Success probabilities in [0, 1].
    """
    p = np.clip(np.asarray(p, float), 0.0, 1.0)
    pmf = np.zeros(p.size + 1)
    pmf[0] = 1.0
    for i, q in enumerate(p):
        pmf[1 : i + 2] = pmf[1 : i + 2] * (1 - q) + pmf[: i + 1] * q
        pmf[0] *= 1 - q
    return float(np.clip(pmf[max(int(k), 0) :].sum(), 0.0, 1.0))


@dataclass(frozen=True)
class Verdict:
    """Whether two performances are the same piece, and why.

    Attributes
    ----------
    same_piece : bool
    agreement : float
        Agreeing share of the matched movements.
    chance : float
        Mean chance of agreeing on them.
    kappa : float
        ``(agreement − chance) / (1 − chance)``; NaN without matched movements.
    p_value : float
        One-sided probability of at least this many agreements by chance.
    matched_reference, matched_candidate : float
        Share of each performance's time matched to the other.
    reason : str
        One sentence for the report and the command line.
    """

    same_piece: bool
    agreement: float
    chance: float
    kappa: float
    p_value: float
    matched_reference: float
    matched_candidate: float
    reason: str

    def as_dict(self) -> dict:
        return asdict(self)


def same_piece(agree, chance, matched_reference: float, matched_candidate: float) -> Verdict:
    """Judge agreement against chance over the matched movements.

    Parameters
    ----------
    agree : (M,) array_like of bool
        Agreement of each matched movement.
    chance : (M,) array_like
        Its chance of agreeing (:func:`chance_of_agreeing`).
    matched_reference, matched_candidate : float
        Share of each performance's time matched to the other, in [0, 1].

    Returns
    -------
    Verdict
        Same piece when κ ≥ :data:`SAME_PIECE_KAPPA`, the agreement is
        significant at :data:`SAME_PIECE_ALPHA`, and at least
        :data:`SAME_PIECE_MATCHED` of each performance is matched.
    """
    agree = np.asarray(agree, bool)
    chance = np.asarray(chance, float)
    if agree.shape != chance.shape:
        raise CompareError(f"agree and chance must have one value per movement, got {agree.shape} and {chance.shape}")
    n = agree.size
    if n:
        a = float(agree.mean())
        c = float(np.mean(chance))
        kappa = (a - c) / (1.0 - c) if c < 1.0 else (1.0 if a == 1.0 else 0.0)
        p = poisson_binomial_sf(int(agree.sum()), chance)
    else:
        a = c = kappa = float("nan")
        p = 1.0
    problems = []
    if not n:
        problems.append("no reference movement was matched")
    else:
        if not kappa >= SAME_PIECE_KAPPA or not p < SAME_PIECE_ALPHA:
            problems.append(
                f"{a:.0%} of the matched movements agree where chance alone gives {c:.0%} "
                f"(κ = {kappa:.2f}, p = {p:.2g})"
            )
    for share, who in ((matched_reference, "reference's"), (matched_candidate, "candidate's")):
        if share < SAME_PIECE_MATCHED:
            problems.append(f"only {share:.0%} of the {who} time matches the other performance")
    if problems:
        reason = "not the same piece: " + "; ".join(problems)
    else:
        reason = f"the same piece: {a:.0%} agree where chance gives {c:.0%} (κ = {kappa:.2f}, p = {p:.2g})"
    return Verdict(not problems, a, c, float(kappa), p, float(matched_reference), float(matched_candidate), reason)
