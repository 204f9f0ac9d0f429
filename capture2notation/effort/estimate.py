"""Effort of a captured phrase: per movement, pooled, and the emotion.

:func:`estimate_effort` is the library entry point used by ``c2n capture``
and ``c2n effort``; :func:`write_effort` (in :mod:`.report`) writes
``effort.json`` and the plots.
"""

from __future__ import annotations

import concurrent.futures
import logging
from dataclasses import dataclass, field

import numpy as np

from ..body import JOINTS
from ..errors import EffortError
from ..notation.model import PART_SEGMENTS, Score
from .curves import (
    MAX_CURVE_POINTS,
    MAX_EXTEND,
    SNAP_S,
    ProgressCurve,
    _snap,
    part_constants,
    progress_curve,
    refine_window,
    resample_curve,
)
from .domain import EmotionDomain, emotion_domain
from .emotion import SPREAD, emotion_probabilities, features
from .fit import SpaceEstimate
from .passages import PASSAGE_S, consensus, passage_index, thinned
from .pooled import PooledEffort, curve_space, pool_curves, pooled_space
from .posterior import Posterior, sample_posteriors

__all__ = ["EffortResult", "MovementEffort", "Passage", "estimate_effort", "movement_windows"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MovementEffort:
    """Effort of one movement (one gesture symbol).

    Attributes
    ----------
    part : str
    start, duration : float
        Beats, as in the score.
    curve : ProgressCurve
        Observed progress (window in seconds inside).
    posterior : Posterior
        (b, x0, ln σ) samples and diagnostics.
    space : SpaceEstimate
    """

    part: str
    start: float
    duration: float
    curve: ProgressCurve
    posterior: Posterior
    space: SpaceEstimate


@dataclass(frozen=True)
class Passage:
    """The pooled Effort of one passage of a long clip (:mod:`.passages`).

    Attributes
    ----------
    t_start, t_end : float
        Seconds: the first movement's start, the last one's end.
    pooled : PooledEffort
    """

    t_start: float
    t_end: float
    pooled: PooledEffort


@dataclass(frozen=True)
class EffortResult:
    """Everything ``effort.json`` reports.

    Attributes
    ----------
    movements : tuple of MovementEffort
    pooled : PooledEffort or None
        Whole phrase (None when no movement could be measured).
    parts : dict of str to PooledEffort
        Pooled per body part (parts with at least two movements).
    tempo : float
        Beats per minute, from the symbols' timing (the score's tempo).
    emotion : dict or None
        ``{happy, sad, angry, afraid: p}``; None when not read (see `domain`).
    skipped : tuple of dict
        Movements not measured, with the reason.
    domain : EmotionDomain or None
        Whether the phrase is a port de bras the presets describe, check by
        check; the emotion is read only inside it.
    passages : tuple of Passage
        A long clip's passages, each pooled (empty for one passage).
    """

    movements: tuple
    pooled: PooledEffort | None
    parts: dict
    tempo: float
    emotion: dict | None
    skipped: tuple = field(default_factory=tuple)
    domain: EmotionDomain | None = None
    passages: tuple = ()

    @property
    def emotion_text(self) -> str:
        """One line for the terminal and the page: the emotion, or why it is not read."""
        if self.emotion:
            best = max(self.emotion, key=self.emotion.get)
            ranked = sorted(self.emotion.items(), key=lambda kv: -kv[1])
            return f"{best} ({', '.join(f'{k} {v:.0%}' for k, v in ranked)})"
        why = "; ".join(self.domain.reasons) if self.domain is not None else "no pooled Effort"
        return f"not read: {why or 'no pooled Effort'}"

    def to_dict(self) -> dict:
        """The JSON-ready content of ``effort.json``."""
        pooled = None
        if self.pooled is not None:
            pooled = _pooled_dict(self.pooled)
            pooled["tempo"] = self.tempo
            pooled["parts"] = {k: _pooled_dict(v) for k, v in self.parts.items()}
        return {
            "movements": [_movement_dict(m) for m in self.movements],
            "pooled": pooled,
            "emotion": self.emotion,
            "emotion_read": self.emotion is not None,
            "emotion_text": self.emotion_text,
            "emotion_domain": self.domain.to_dict() if self.domain is not None else None,
            "skipped": list(self.skipped),
            "passages": [{"start_s": p.t_start, "end_s": p.t_end, **_pooled_dict(p.pooled)} for p in self.passages],
        }


def _effort_fields(post: Posterior, space: SpaceEstimate) -> dict:
    out = {
        "time": post.summary(0),
        "weight": post.summary(1),
        "space": {"median": space.median, "ci90": list(space.ci90)},
        "tau": float(np.max(post.tau)),
        "acceptance": post.acceptance,
        "converged": post.converged,
        # why sampling ended: "converged", "gave up" (its τ asked for more
        # steps than the budget) or "budget" (ran out of steps)
        "sampler_stop": post.stop,
        "steps": post.steps,
    }
    if post.rho is not None:
        # frame-to-frame correlation of the progress residuals (AR(1) model):
        # near 0 for jitter, near 1 for smooth capture errors
        lo, med, hi = np.percentile(post.rho, [5, 50, 95])
        out["residual_rho"] = {"median": float(med), "ci90": [float(lo), float(hi)]}
    return out


def _movement_dict(m: MovementEffort) -> dict:
    return {"part": m.part, "start": m.start, "duration": m.duration, **_effort_fields(m.posterior, m.space)}


def _pooled_dict(p: PooledEffort) -> dict:
    return {"n_movements": p.n_movements, **_effort_fields(p.posterior, p.space)}


def _neighbour_bounds(windows) -> list:
    """Per window, the (lo, hi) seconds its refinement may not cross.

    The middle of the previous and of the next window of the same part:
    a captured score often splits one movement in two (e.g. a bend change
    quantised as its own symbol), and each half may then reach into the
    other, but never past its middle (where the neighbour is surely moving).
    """
    out = [(-np.inf, np.inf)] * len(windows)
    by_part: dict = {}
    for i, (sym, _t0, _t1) in enumerate(windows):
        by_part.setdefault(sym.part, []).append(i)
    for idx in by_part.values():
        idx = sorted(idx, key=lambda i: windows[i][1])
        mids = [0.5 * (windows[i][1] + windows[i][2]) for i in idx]
        for j, i in enumerate(idx):
            lo = mids[j - 1] if j > 0 else -np.inf
            hi = mids[j + 1] if j + 1 < len(idx) else np.inf
            out[i] = (lo, hi)
    return out


def movement_windows(score: Score, times: np.ndarray) -> list:
    """Gesture symbols with their windows in seconds.

    Returns
    -------
    list of (Symbol, t_start, t_end)
        Only parts with a moving extremity (supports are not Effort-bearing).
    """
    out = []
    for sym in score.symbols:
        if sym.part in PART_SEGMENTS:
            out.append((sym, score.seconds(sym.start), score.seconds(sym.end)))
    return out


#: Frames kept beyond a movement's reach on each side when it is measured
#: on a slice of the clip (the end points use the two nearest frames, within
#: 2.5 frame steps).
_SLICE_PAD = 4

#: Most posteriors sampled together in one vectorised emcee run.  A fixed
#: size, so results do not depend on the number of worker processes; large,
#: because each emcee step costs a fixed overhead per run besides its work
#: per walker and sample (24 per run made a 60-s clip's Effort 1.5x slower).
CHUNK = 120


def _sample_job(args):
    """Worker: one chunk of posteriors (top-level so process pools can pickle it)."""
    datasets, seed, kw = args
    return sample_posteriors(datasets, rng=seed, **kw)


def _sample_all(jobs, rng, workers: int, kw: dict, chunk: int | None = None) -> list:
    """Posteriors of `jobs` ((tau, s, w, groups) each), in order.

    Jobs are dealt into ``ceil(len / chunk)`` chunks of about equal work
    (samples per walker and step; largest first, each to the lightest chunk,
    so the large pooled sets spread out), each sampled in one vectorised run
    with its own seed; chunks go to `workers` processes when there are several.
    """
    n_chunks = -(-len(jobs) // (chunk or CHUNK))
    load = np.zeros(n_chunks)
    members: list[list[int]] = [[] for _ in range(n_chunks)]
    for i in sorted(range(len(jobs)), key=lambda i: -len(jobs[i][0])):
        k = int(np.argmin(load))
        members[k].append(i)
        load[k] += len(jobs[i][0])
    members = [sorted(m) for m in members]
    seeds = rng.integers(0, 2**63 - 1, size=n_chunks)
    args = [([jobs[i] for i in m], int(seed), kw) for m, seed in zip(members, seeds)]
    if workers > 1 and n_chunks > 1:
        with concurrent.futures.ProcessPoolExecutor(max_workers=min(workers, n_chunks)) as ex:
            done = list(ex.map(_sample_job, args))
    else:
        done = [_sample_job(a) for a in args]
    posts = [None] * len(jobs)
    for m, ps in zip(members, done):
        for i, p in zip(m, ps):
            posts[i] = p
    return posts


def _sample_passage(curves, rng, workers: int, kw: dict, per_movement: bool):
    """Posteriors of one passage: each movement's (when `per_movement`), and its pooled groups by label.

    A part pools when it has at least two movements and not all of them (a
    part holding every movement pools to the phrase: sampled once).
    """
    by_part: dict[str, list] = {}
    for c in curves:
        by_part.setdefault(c.part, []).append(c)
    groups = [(p, cs) for p, cs in by_part.items() if len(cs) >= 2 and len(cs) < len(curves)]
    if curves:
        groups.append(("phrase", curves))
    jobs = [(c.tau, c.s, c.weight, None) for c in curves] if per_movement else []
    n_mov = len(jobs)
    jobs += [(t, s, w, g) for t, s, w, _, g in (pool_curves(cs) for _, cs in groups)]
    posts = _sample_all(jobs, rng, workers, kw) if jobs else []
    pooled = {label: post for (label, _), post in zip(groups, posts[n_mov:])}
    if len(by_part) == 1 and len(curves) >= 2:
        (only,) = by_part
        pooled[only] = pooled["phrase"]
    return posts[:n_mov], pooled


def estimate_effort(
    joints,
    confidence,
    fps: float,
    score: Score,
    rng: np.random.Generator | int,
    times=None,
    joint_names=JOINTS,
    workers: int = 1,
    sampler_kw: dict | None = None,
    per_movement: bool = True,
    snap: float = SNAP_S,
    refine: bool = True,
    max_points: int = MAX_CURVE_POINTS,
    passage_s: float = PASSAGE_S,
) -> EffortResult:
    """Estimate Laban Effort per movement, pooled per part and phrase, and the emotion.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres (NaN where missing).
    confidence : (T, J) ndarray or None
        Per-frame confidence in [0, 1]; None means all ones.
    fps : float
        Frame rate, Hz (used for `times` when not given).
    score : Score
        The movements (symbols, beats) and tempo.
    rng : numpy.random.Generator or int
        Seeds every posterior; results do not depend on `workers`.
    times : (T,) ndarray, optional
        Frame times in seconds, beat 0 at t = 0 (default ``arange(T) / fps``).
    joint_names : sequence of str
        Names of the J joints.
    workers : int
        Processes for the posteriors (1 = in this process).  All posteriors
        (movements and pooled sets) are sampled in vectorised chunks of
        :data:`CHUNK`; extra processes pay off only beyond one chunk.
    sampler_kw : dict, optional
        Passed to :func:`.posterior.sample_posteriors`.
    per_movement : bool
        Sample each movement's posterior (False: pooled estimates only, for
        studies that need the phrase's Effort alone).
    snap : float
        Snap window ends to frames within this many seconds (see
        :func:`.curves.progress_curve`).
    refine : bool
        Move each window's edges outward to where the extremity really
        starts and stops (:func:`.curves.refine_window`), bounded by the
        middle of the neighbouring movements of the same part.  Windows of a
        clean render are left unchanged; those of a captured score are often
        cut short by a fraction of a beat.
    max_points : int
        Most samples per movement's curve: longer curves (high frame rates,
        slow movements) are averaged into this many bins of τ
        (:func:`.curves.resample_curve`), so the cost does not grow with the
        frame rate.

    Returns
    -------
    EffortResult
    """
    if rng is None:
        raise EffortError("estimate_effort needs an explicit rng (numpy Generator or seed)")
    rng = np.random.default_rng(rng)
    joints = np.asarray(joints, dtype=float)
    if joints.ndim != 3 or joints.shape[2] != 3:
        raise EffortError(f"joints must be (T, J, 3), got shape {joints.shape}")
    if not (np.isfinite(fps) and fps > 0):
        raise EffortError(f"fps must be > 0, got {fps}")
    if times is None:
        times = np.arange(joints.shape[0]) / float(fps)
    times = np.asarray(times, dtype=float)
    kw = dict(sampler_kw or {})

    curves, syms, skipped = [], [], []
    constants: dict = {}
    windows = movement_windows(score, times)
    limits = _neighbour_bounds(windows)
    for (sym, t0, t1), lim in zip(windows, limits):
        where = {"part": sym.part, "start": float(sym.start), "duration": float(sym.duration)}
        if t0 < times[0] or t1 > times[-1] + 0.5 / fps:
            skipped.append({**where, "reason": f"window {t0:.3f}-{t1:.3f} s outside the capture"})
            continue
        if sym.part not in constants:
            constants[sym.part] = part_constants(joints, confidence, times, sym.part, joint_names)
        noise, reach = constants[sym.part]
        # the frames this movement can touch: its window, as far as the
        # refinement may move each edge, and a few frames beyond for the
        # end-point extrapolation (whole-clip arrays per movement made the
        # step grow with the square of the clip's length)
        ext = MAX_EXTEND * max(t1 - t0, 0.0) + 2 * snap
        a = max(int(np.searchsorted(times, t0 - ext)) - _SLICE_PAD, 0)
        z = int(np.searchsorted(times, t1 + ext)) + _SLICE_PAD
        jt, tt = joints[a:z], times[a:z]
        cf = None if confidence is None else confidence[a:z]
        if refine:
            if snap > 0:
                t0, t1 = _snap(t0, tt, snap), _snap(t1, tt, snap)
            if t1 > t0:
                t0, t1 = refine_window(jt, cf, tt, sym.part, t0, t1, lim, joint_names, noise=noise)
        try:
            c = progress_curve(jt, cf, tt, sym.part, t0, t1, joint_names, snap=snap, reach=reach)
        except EffortError as exc:
            skipped.append({**where, "reason": str(exc)})
            continue
        if c is None:
            skipped.append({**where, "reason": "part held (turns less than 5 degrees)"})
            continue
        # a fixed number of samples per movement: cost independent of the frame rate
        curves.append(resample_curve(c, max_points))
        syms.append(sym)
    for sk in skipped:
        log.info("effort: skipped %s at beat %s: %s", sk["part"], sk["start"], sk["reason"])

    by_part: dict[str, list] = {}
    for c in curves:
        by_part.setdefault(c.part, []).append(c)
    # A long clip is sampled passage by passage (:mod:`.passages`): memory
    # bounded, cost linear in its length.
    passage = passage_index([c.t_start for c in curves], passage_s)
    n_passages = int(passage.max()) + 1 if curves else 0
    move_posts: list = []
    pooled_posts: dict[str, list] = {}
    spans = []
    for k in range(n_passages):
        members = [c for c, p in zip(curves, passage) if p == k]
        posts, pooled = _sample_passage(members, rng, workers, kw, per_movement)
        move_posts += [thinned(p) for p in posts] if n_passages > 1 else posts
        for label, post in pooled.items():
            pooled_posts.setdefault(label, []).append(post)
        if n_passages > 1 and "phrase" in pooled:
            t0, t1 = members[0].t_start, max(c.t_end for c in members)
            spans.append(Passage(t0, t1, PooledEffort("phrase", len(members), pooled["phrase"], pooled_space(members))))
    movements = tuple(
        MovementEffort(
            part=sym.part,
            start=float(sym.start),
            duration=float(sym.duration),
            curve=c,
            posterior=post,
            space=curve_space(c),
        )
        for sym, c, post in zip(syms, curves, move_posts)
    )
    pooled_all = {}
    for label, posts in pooled_posts.items():
        cs = curves if label == "phrase" else by_part[label]
        pooled_all[label] = PooledEffort(label, len(cs), consensus(posts, rng), pooled_space(cs))
    phrase = pooled_all.pop("phrase", None)
    if phrase is not None and len(by_part) == 1 and len(curves) >= 2:
        (only,) = by_part
        pooled_all[only] = PooledEffort(only, phrase.n_movements, phrase.posterior, phrase.space)
    tempo = float(score.tempo)
    x, sd = _emotion_input(phrase, tempo) if phrase is not None else (None, None)
    domain = emotion_domain(score, [c.part for c in curves], joints, confidence, joint_names, x=x, sd=sd, spread=SPREAD)
    emotion = emotion_probabilities(x, sd) if domain.inside else None
    if not domain.inside:
        log.info("effort: emotion not read: %s", "; ".join(domain.reasons))
    return EffortResult(
        movements=movements,
        pooled=phrase,
        parts=pooled_all,
        tempo=tempo,
        emotion=emotion,
        skipped=tuple(skipped),
        domain=domain,
        passages=tuple(spans),
    )


def _emotion_input(pooled: PooledEffort, tempo: float):
    """Features and their posterior standard deviations for :func:`emotion_probabilities`."""
    smp = pooled.posterior.samples
    x = features(float(np.median(smp[:, 0])), float(np.median(smp[:, 1])), pooled.space.median, tempo)
    lo, hi = pooled.space.ci90
    # 90 % interval of a Gaussian is ±1.645 sd
    sd = np.array([np.std(smp[:, 0]), np.std(smp[:, 1]), (hi - lo) / 3.29, 0.0])
    return x, sd
