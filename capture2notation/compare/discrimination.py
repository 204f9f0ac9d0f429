"""Same/different emotion judgements in the manner of Neagle's Experiments 1–2.

Neagle (2005, §3.3–3.4) showed professional dancers pairs of performances and
asked whether they expressed the same or different emotions.  Experiment 1:
four emotions, ten pairs (three trials per same pair, two per different
pair: 24 trials per complexity, 72 in all) at 25 Hz on a 220×175 display;
overall 78.70 % correct.  Experiment 2: happy, sad, angry; six pairs, two
trials per pair × complexity (easy, hard) × frame rate (5, 8.33, 12.5,
25 Hz): 96 trials; overall 78.99 % correct.

Here the observer is automated: it says "same" when the two performances'
estimated Effort and tempo are close, with a threshold calibrated on a
separate seeded training set.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..errors import CompareError

__all__ = [
    "FEATURES",
    "THESIS",
    "SameDifferentObserver",
    "Trial",
    "experiment1_trials",
    "experiment2_trials",
    "feature_vector",
    "run_trials",
    "summarise",
]

#: Percentages correct that the thesis states in its text (the bar heights of
#: Figures 3.13–3.16 are given only as pictures and are not reproduced).
THESIS: dict = {
    "experiment1_overall": 78.70,
    "experiment2_overall": 78.99,
    "experiment2_same": {"angry-angry": 86.46, "happy-happy": 71.88, "sad-sad": 61.46},
    "experiment2_different": {"happy-angry": 66.67, "happy-sad": 93.75, "sad-angry": 93.75},
    "experiment1_happy-angry": 50.0,  # "equivalent to chance"
}

#: Observer features: Effort time b, weight x0, space S and log tempo.
FEATURES: tuple[str, ...] = ("time", "weight", "space", "log_tempo")

_EMOTION_ORDER = ("happy", "sad", "angry", "afraid")


def pair_name(a: str, b: str) -> str:
    """Canonical label of an emotion pair, e.g. ``happy-angry`` (thesis order)."""
    ka = _EMOTION_ORDER.index(a) if a in _EMOTION_ORDER else 99
    kb = _EMOTION_ORDER.index(b) if b in _EMOTION_ORDER else 99
    return f"{a}-{b}" if (ka, a) <= (kb, b) else f"{b}-{a}"


@dataclass(frozen=True)
class Trial:
    """One same/different trial: two performances shown one after the other."""

    emotion_a: str
    emotion_b: str
    complexity: str
    frame_rate: Fraction
    repeat: int

    @property
    def same(self) -> bool:
        return self.emotion_a == self.emotion_b

    @property
    def pair(self) -> str:
        return pair_name(self.emotion_a, self.emotion_b)


def _pairs(emotions):
    same = [(e, e) for e in emotions]
    diff = list(itertools.combinations(emotions, 2))
    return same, diff


def experiment1_trials(
    complexities=("easy", "medium", "hard"),
    emotions=("happy", "sad", "angry", "afraid"),
    frame_rate=Fraction(25),
    same_repeats: int = 3,
    different_repeats: int = 2,
) -> list[Trial]:
    """Experiment 1's design: 3 trials per same pair, 2 per different pair, per complexity.

    With the defaults: 4 × 3 + 6 × 2 = 24 trials per complexity, 72 in all.
    """
    same, diff = _pairs(emotions)
    out = []
    for c in complexities:
        for a, b in same:
            out += [Trial(a, b, c, Fraction(frame_rate), k) for k in range(same_repeats)]
        for a, b in diff:
            out += [Trial(a, b, c, Fraction(frame_rate), k) for k in range(different_repeats)]
    return out


def experiment2_trials(
    complexities=("easy", "hard"),
    frame_rates=(Fraction(5), Fraction(25, 3), Fraction(25, 2), Fraction(25)),
    emotions=("happy", "sad", "angry"),
    repeats: int = 2,
) -> list[Trial]:
    """Experiment 2's design: 6 pairs × 2 trials × complexity × frame rate (96 trials)."""
    same, diff = _pairs(emotions)
    return [
        Trial(a, b, c, Fraction(r), k)
        for c in complexities
        for r in frame_rates
        for a, b in same + diff
        for k in range(repeats)
    ]


def feature_vector(effort: dict) -> np.ndarray:
    """Observer features of one performance.

    Parameters
    ----------
    effort : dict
        ``time``, ``weight``, ``space`` (point estimates) and ``tempo``
        (bpm); missing or non-finite entries become NaN.

    Returns
    -------
    (4,) ndarray
        In the order of :data:`FEATURES`.
    """

    def get(k):
        v = effort.get(k, np.nan)
        try:
            return float(v)
        except (TypeError, ValueError):
            return np.nan

    tempo = get("tempo")
    return np.array([get("time"), get("weight"), get("space"), np.log(tempo) if tempo > 0 else np.nan])


class SameDifferentObserver:
    """Says "same" when two performances' scaled feature distance is below a threshold.

    Parameters
    ----------
    scale : (F,) array_like
        Divisor per feature (its spread in the training set).
    threshold : float
        Distance at or below which the answer is "same".
    """

    def __init__(self, scale, threshold: float):
        self.scale = np.asarray(scale, dtype=float)
        self.threshold = float(threshold)

    def distance(self, fa: np.ndarray, fb: np.ndarray) -> np.ndarray:
        """Root-mean-square scaled difference over features known on both sides.

        Parameters
        ----------
        fa, fb : (..., F) ndarray

        Returns
        -------
        (...) ndarray
            NaN when no feature is known on both sides.
        """
        d = (np.asarray(fa, float) - np.asarray(fb, float)) / self.scale
        ok = np.isfinite(d)
        n = ok.sum(-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, np.sqrt(np.where(ok, d * d, 0.0).sum(-1) / n), np.nan)

    def judge(self, fa: np.ndarray, fb: np.ndarray) -> np.ndarray:
        """True ("same") where the distance is at most the threshold.

        An undefined distance (nothing measured) is judged "different", as a
        viewer who saw nothing cannot vouch for sameness.
        """
        dist = self.distance(fa, fb)
        return np.where(np.isnan(dist), False, dist <= self.threshold)

    @classmethod
    def calibrate(cls, features: np.ndarray, emotions) -> SameDifferentObserver:
        """Fit scale and threshold on a training set of performances.

        Every pair of distinct training performances is a training trial;
        the threshold maximises the balanced accuracy (mean of the "same"
        and "different" hit rates), so the observer is not biased towards
        whichever answer has more pairs.

        Parameters
        ----------
        features : (N, F) ndarray
            One row per training performance (:func:`feature_vector`).
        emotions : (N,) sequence of str

        Returns
        -------
        SameDifferentObserver
        """
        x = np.asarray(features, dtype=float)
        e = np.asarray(emotions)
        if x.ndim != 2 or len(x) != len(e) or len(x) < 4:
            raise CompareError(f"calibration needs >= 4 performances as (N, F) features, got {x.shape}")
        if len(set(e.tolist())) < 2:
            raise CompareError("calibration needs performances of at least two emotions")
        # A feature no training performance measured keeps unit scale.
        measured = np.isfinite(x).any(axis=0)
        scale = np.ones(x.shape[1])
        scale[measured] = np.nanstd(x[:, measured], axis=0)
        scale = np.where(np.isfinite(scale) & (scale > 1e-9), scale, 1.0)
        i, j = np.triu_indices(len(x), k=1)
        obs = cls(scale, 0.0)
        dist = obs.distance(x[i], x[j])
        same = e[i] == e[j]
        if not same.any():
            raise CompareError("calibration needs at least two performances of one emotion")
        keep = np.isfinite(dist)
        dist, same = dist[keep], same[keep]
        cands = np.unique(dist)
        # Accuracy at every candidate threshold at once: sorted cumulative counts.
        hit_same = np.searchsorted(np.sort(dist[same]), cands, side="right") / max(same.sum(), 1)
        hit_diff = 1.0 - np.searchsorted(np.sort(dist[~same]), cands, side="right") / max((~same).sum(), 1)
        bal = 0.5 * (hit_same + hit_diff)
        best = np.flatnonzero(bal == bal.max())
        k = best[len(best) // 2]
        # Midway to the next distance: the rule generalises, not just the sample.
        thr = cands[k] if k + 1 >= len(cands) else 0.5 * (cands[k] + cands[k + 1])
        return cls(scale, float(thr))

    def as_dict(self) -> dict:
        return {"features": list(FEATURES), "scale": self.scale.tolist(), "threshold": self.threshold}


def run_trials(trials, pool: dict, observer: SameDifferentObserver, rng: np.random.Generator) -> list[dict]:
    """Run trials with performances drawn from a pool.

    Parameters
    ----------
    trials : sequence of Trial
    pool : dict
        ``(emotion, complexity, frame_rate) → (K, F) ndarray`` of features
        of K takes (K >= 2 so that "same" pairs show two different takes).
    observer : SameDifferentObserver
    rng : numpy.random.Generator
        Chooses the takes of each trial.

    Returns
    -------
    list of dict
        One per trial: its fields plus ``said_same``, ``correct``, ``distance``.
    """
    out = []
    for t in trials:
        try:
            pa = pool[(t.emotion_a, t.complexity, Fraction(t.frame_rate))]
            pb = pool[(t.emotion_b, t.complexity, Fraction(t.frame_rate))]
        except KeyError as exc:
            raise CompareError(f"no performances in the pool for {exc.args[0]}") from None
        if t.same:
            if len(pa) < 2:
                raise CompareError(f"a same trial needs >= 2 takes of {t.emotion_a}/{t.complexity}, got {len(pa)}")
            ia, ib = rng.choice(len(pa), size=2, replace=False)
        else:
            ia, ib = rng.integers(len(pa)), rng.integers(len(pb))
        fa, fb = pa[ia], pb[ib]
        said = bool(observer.judge(fa, fb))
        out.append(
            {
                "emotion_a": t.emotion_a,
                "emotion_b": t.emotion_b,
                "pair": t.pair,
                "same": t.same,
                "complexity": t.complexity,
                "frame_rate": float(t.frame_rate),
                "repeat": t.repeat,
                "said_same": said,
                "correct": said == t.same,
                "distance": float(observer.distance(fa, fb)),
            }
        )
    return out


def summarise(results: list[dict]) -> dict:
    """Percentages correct overall and per pair, complexity, frame rate, same/different.

    Returns
    -------
    dict
        ``{"n": trials, "overall": %, "by_pair": {pair: %}, "by_complexity":
        {...}, "by_frame_rate": {...}, "by_kind": {"same": %, "different": %}}``.
    """
    if not results:
        raise CompareError("no trials to summarise")

    def pct(rows):
        return 100.0 * float(np.mean([r["correct"] for r in rows]))

    groups: dict = defaultdict(lambda: defaultdict(list))
    for r in results:
        groups["by_pair"][r["pair"]].append(r)
        groups["by_complexity"][r["complexity"]].append(r)
        groups["by_frame_rate"][round(r["frame_rate"], 2)].append(r)
        groups["by_kind"]["same" if r["same"] else "different"].append(r)
    out = {"n": len(results), "overall": pct(results)}
    for name, g in groups.items():
        out[name] = {k: pct(v) for k, v in g.items()}
    return out
