"""Benchmark of the capture stage: speed and symbol accuracy.

Run ``/work/venv/bin/python benchmarks/bench_capture.py [--random N] [--noisy N] [--video K] [--view V]``.

Prints (never asserts):

1. quantisation speed (frames per second of :func:`segment_motion`);
2. truth round trip: built-in phrases and N random scores interpreted by the
   virtual dancer, quantised from their truth joints — exact symbol matches
   with the tempo given, and whether the estimated tempo is right,
   equivalent (a factor of two that puts every symbol at the same seconds
   on the grid: the score is still exact when compared in time) or wrong;
3. noisy truth (``--noisy N``): the built-ins and N random scores with 1 and
   2 cm of Gaussian jitter on every joint coordinate (seeded) — agreement,
   start error, exact and extra symbols, tempo, quantisation speed;
4. with ``--video K``: the whole capture (render → keypoints → fit →
   quantise) on K random scores — symbol agreement, median start error and
   frames per second of the whole capture, tempo given and estimated.

:func:`score_agreement` is the reusable metric (it wraps
:func:`capture2notation.compare.agreement.compare_scores`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from capture2notation.compare.agreement import compare_scores, score_differences
from capture2notation.notation.model import Score
from capture2notation.quantise.segment import segment_motion


def score_agreement(reference: Score, captured: Score, step=Fraction(1)) -> dict:
    """Symbol agreement and start-time error of `captured` against `reference`.

    Parameters
    ----------
    reference, captured : Score
    step : Fraction
        Sampling step in beats of the per-part agreement (1 = per beat).

    Returns
    -------
    dict
        ``symbol_agreement`` (direction + level per part per beat, in
        [0, 1]), ``median_start_error`` (beats, NaN when nothing matched),
        ``matched``, ``unmatched`` (reference gesture symbols with / without a
        captured symbol of the same part and destination) and ``exact``.
    """
    a = compare_scores(reference, captured, step=step)
    return {
        "symbol_agreement": a.symbol_agreement,
        "median_start_error": a.median_start_error,
        "matched": a.matched,
        "unmatched": a.unmatched,
        "exact": a.exact,
    }


#: Random-score families of the truth benchmark: parts drawn, arms split into segments.
FAMILIES = {
    "arms": (("right_arm", "left_arm"), False),
    "arms+head": (("right_arm", "left_arm", "head"), False),
    "split arms": (("right_arm", "left_arm"), True),
    "arms+head+chest": (("right_arm", "left_arm", "head", "chest"), False),
    "full (arms, head, chest, legs, supports)": (("right_arm", "left_arm", "head", "chest", "legs"), False),
}


def dancer_misses(score, motion, tol_deg: float = 0.05) -> int:
    """Gesture symbols whose written pose the dancer does not reach exactly.

    At each gesture symbol's arrival frame, the part's vector must be within
    `tol_deg` of its canonical vector (and a limb's bend within `tol_deg` of
    30° × bend).  Joint extremes stop some targets short; the quantiser then
    reads what was performed, not what was written.
    """
    from capture2notation.notation.directions import canonical_vector
    from capture2notation.quantise.labels import label_frames

    lab = label_frames(motion.joints(), motion.fps)
    misses = 0
    for sym, _, f1 in motion.events:
        if sym.is_support or sym.part not in lab.parts:
            continue  # supports, turns and flight have no limb direction to reach
        f = min(f1, lab.vectors.shape[0] - 1)
        v = lab.vectors[f, lab.index(sym.part)]
        c = canonical_vector(sym.direction, sym.level)
        off = np.degrees(np.arctan2(np.linalg.norm(np.cross(v, c)), float(v @ c)))
        bend = lab.bend_deg[f, lab.index(sym.part)]
        bad_bend = np.isfinite(bend) and abs(bend - 30.0 * sym.bend) > tol_deg
        misses += bool(off > tol_deg or bad_bend)
    return misses


def _round_trip(scores, fps: float):
    """(exact count, tempo right count, frames, quantisation seconds, failures) over `scores`."""
    from synthetic.interpret import interpret

    exact = frames = 0
    tempo_ok = {"right": 0, "equivalent": 0, "wrong": 0}
    seconds = 0.0
    agree = []
    failures = []
    missed = exact_reached = 0
    for name, score in scores:
        motion = interpret(score, fps=fps)
        joints = motion.joints()
        miss = dancer_misses(score, motion) > 0
        missed += miss
        t0 = time.perf_counter()
        seg = segment_motion(joints, fps, tempo=score.tempo)
        seconds += time.perf_counter() - t0
        frames += joints.shape[0]
        diffs = score_differences(score, seg.score)
        exact += not diffs
        exact_reached += not diffs and not miss
        agree.append(score_agreement(score, seg.score)["symbol_agreement"])
        if diffs:
            failures.append((name, diffs))
        tempo_ok[tempo_verdict(score, segment_motion(joints, fps), diffs)] += 1
    return exact, tempo_ok, frames, seconds, failures, float(np.mean(agree)), (missed, exact_reached)


def tempo_verdict(score: Score, seg, diffs_given_tempo) -> str:
    """``right``, ``equivalent`` or ``wrong``: the estimated tempo of `seg` against `score`.

    Equivalent: another tempo whose score, compared in time, differs from
    the written one exactly as the score captured with the tempo given does
    (a factor of two with every start and duration on the grid).
    """
    if seg.tempo == score.tempo:
        return "right"
    return "equivalent" if score_differences(score, seg.score) == diffs_given_tempo else "wrong"


def bench_truth(n_random: int, seed: int, fps: float = 25.0, show: int = 3) -> None:
    """Exactness of the truth round trip (virtual dancer → joints → score), and quantisation speed."""
    import warnings

    from synthetic.phrases import builtin_phrases
    from synthetic.random_scores import random_score

    warnings.simplefilter("ignore")  # the dancer warns about targets beyond its extremes
    rows = [("built-in phrases", list(builtin_phrases().items()))]
    for label, (parts, split) in FAMILIES.items() if n_random > 0 else ():
        rng = np.random.default_rng(seed)
        rows.append(
            (
                label,
                [
                    (
                        f"{label} #{i}",
                        random_score(rng, n_beats=8, parts=parts, split_arms=split, random_effort=bool(i % 2)),
                    )
                    for i in range(n_random)
                ],
            )
        )
    print(f"truth round trip at {fps:g} fps (tempo given; half the random scores with a random Effort)")
    total_frames, total_s = 0, 0.0
    for label, scores in rows:
        exact, tempo_ok, frames, secs, failures, agree, (missed, exact_reached) = _round_trip(scores, fps)
        total_frames += frames
        total_s += secs
        n = len(scores)
        print(
            f"  {label:42s} exact {exact:3d}/{n} = {100 * exact / n:5.1f} %   agreement {100 * agree:5.1f} %   "
            f"estimated tempo right {tempo_ok['right']}/{n}, equivalent {tempo_ok['equivalent']}, "
            f"wrong {tempo_ok['wrong']}"
        )
        print(
            f"      the dancer reaches every written pose in {n - missed}/{n}; of those, exact {exact_reached}/{n - missed}"
        )
        for name, diffs in failures[:show]:
            print(f"      {name}: " + "; ".join(diffs[:3]))
    print(f"  quantisation speed: {total_frames / total_s:,.0f} frames/s ({total_frames} frames)")


def bench_noisy(n_random: int, seed: int, sigmas=(0.01, 0.02), fps: float = 25.0) -> None:
    """Truth joints plus seeded Gaussian jitter: robustness of timing, tempo and symbols."""
    import warnings

    from capture2notation.compare.agreement import normalise
    from synthetic.interpret import interpret
    from synthetic.phrases import builtin_phrases
    from synthetic.random_scores import random_score

    warnings.simplefilter("ignore")
    rng = np.random.default_rng(seed)
    scores = list(builtin_phrases().items()) + [
        (f"random #{i}", random_score(rng, n_beats=8, random_effort=bool(i % 2))) for i in range(n_random)
    ]
    motions = [(name, score, interpret(score, fps=fps).joints()) for name, score in scores]
    print(f"noisy truth: {len(scores)} scores (3 built-ins, {n_random} full random), jitter per joint coordinate")
    for sigma in sigmas:
        for given in (True, False):
            agree, starts, verdicts, frames, secs = [], [], {"right": 0, "equivalent": 0, "wrong": 0}, 0, 0.0
            n_ref = n_missing = n_extra = 0
            for k, (_name, score, joints) in enumerate(motions):
                noisy = joints + np.random.default_rng(seed + k).normal(0.0, sigma, joints.shape)
                t0 = time.perf_counter()
                seg = segment_motion(noisy, fps, tempo=score.tempo if given else None)
                secs += time.perf_counter() - t0
                frames += len(noisy)
                a = score_agreement(score, seg.score)
                agree.append(a["symbol_agreement"])
                starts.append(a["median_start_error"])
                diffs = score_differences(score, seg.score)
                extra = sum(d.startswith("extra") for d in diffs)
                n_ref += len(normalise(score).symbols)
                n_missing += len(diffs) - extra
                n_extra += extra
                if not given:
                    ref_diffs = score_differences(score, segment_motion(noisy, fps, tempo=score.tempo).score)
                    verdicts[tempo_verdict(score, seg, ref_diffs)] += 1
            tempo = (
                "given"
                if given
                else (
                    f"estimated: right {verdicts['right']}, equivalent "
                    f"{verdicts['equivalent']}, wrong {verdicts['wrong']}"
                )
            )
            print(f"  {100 * sigma:.0f} cm, tempo {tempo}")
            print(
                f"      agreement {100 * np.mean(agree):5.1f} %, median start error {np.nanmedian(starts):.3f} beats, "
                f"symbols exact {100 * (1 - n_missing / n_ref):.1f} %, extra {n_extra / n_ref:.2f} per written symbol, "
                f"{frames / secs:,.0f} frames/s"
            )


def bench_video(k: int, seed: int, backend: str, view: str, size=(640, 480)) -> None:
    """The whole capture on rendered videos of random scores."""
    from pipelines.capture import capture
    from synthetic.random_scores import random_score
    from synthetic.render import render_score

    rng = np.random.default_rng(seed)
    style = "markers" if backend == "markers" else "mannequin"
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_capture_") as tmp:
        for i in range(k):
            score = random_score(rng, n_beats=8)
            d = Path(tmp) / f"s{i}"
            render_score(score, d, fps=25.0, size=size, view=view, style=style, progress=False)
            t0 = time.perf_counter()
            res = capture(
                d / "video.mp4",
                d / "cap",
                backend=backend,
                tempo=score.tempo,
                progress=False,
                effort=False,
                overlay=False,
            )
            dt = time.perf_counter() - t0
            a = score_agreement(score, res.score)
            # The same fitted joints with the tempo estimated (compared in time).
            est = segment_motion(np.asarray(res.motion.joints), float(res.motion.fps))
            b = score_agreement(score, est.score)
            rows.append((a, res.n_frames, dt, b, est.tempo == score.tempo))
            print(
                f"  score {i}: agreement {a['symbol_agreement']:.3f}, median start error "
                f"{a['median_start_error']:.3f} beats, {a['unmatched']} unmatched, {res.n_frames / dt:.1f} frames/s; "
                f"estimated tempo {est.tempo} (written {score.tempo}): agreement {b['symbol_agreement']:.3f}"
            )
    fps = sum(r[1] for r in rows) / sum(r[2] for r in rows)
    print(f"whole capture ({backend}, {view}, {size[0]}x{size[1]}, {k} random scores)")
    for label, col in (("tempo given", 0), ("tempo estimated", 3)):
        agree = np.mean([r[col]["symbol_agreement"] for r in rows])
        starts = np.nanmedian([r[col]["median_start_error"] for r in rows])
        print(
            f"  {label}: symbol agreement (direction + level per part per beat) {100 * agree:.1f} %, "
            f"median start-time error {starts:.3f} beats"
        )
    print(f"  estimated tempo right in {sum(r[4] for r in rows)}/{k}")
    print(f"  speed: {fps:.1f} frames/s (render excluded)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--random", type=int, default=20, help="random scores per family for the truth round trip")
    ap.add_argument("--noisy", type=int, default=12, help="random scores of the noisy-truth benchmark (0: skip)")
    ap.add_argument("--video", type=int, default=0, help="random scores for the whole capture (slow)")
    ap.add_argument("--backend", default="blazepose", choices=("blazepose", "markers"))
    ap.add_argument("--view", default="front")
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args()
    bench_truth(args.random, args.seed)
    if args.noisy:
        bench_noisy(args.noisy, args.seed + 2)
    if args.video:
        bench_video(args.video, args.seed + 1, args.backend, args.view)


if __name__ == "__main__":
    main()
