"""Benchmark of the capture stage: speed and symbol accuracy.

Run ``/work/venv/bin/python benchmarks/bench_capture.py [--random N] [--video K]``.

Prints (never asserts):

1. quantisation speed (frames per second of :func:`segment_motion`);
2. truth round trip: built-in phrases and N random scores interpreted by the
   virtual dancer, quantised from their truth joints — exact symbol matches
   with the tempo given, and how often the estimated tempo is right;
3. with ``--video K``: the whole capture (render → keypoints → fit →
   quantise) on K random scores — symbol agreement, median start error and
   frames per second of the whole capture.

:func:`score_agreement` is the reusable metric (it wraps
:func:`capture2notation.quantise.agreement.compare_scores`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from capture2notation.notation.model import Score
from capture2notation.quantise.agreement import compare_scores, score_differences
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


def _truth_scores(n_random: int, seed: int):
    from synthetic.phrases import builtin_phrases
    from synthetic.random_scores import random_score

    scores = dict(builtin_phrases())
    rng = np.random.default_rng(seed)
    for i in range(n_random):
        kw = {"split_arms": bool(i % 5 == 4), "random_effort": bool(i % 2)}
        scores[f"random{i:03d}"] = random_score(rng, n_beats=8, **kw)
    return scores


def bench_truth(n_random: int, seed: int, fps: float = 25.0) -> None:
    """Exactness of the truth round trip, and quantisation speed."""
    from synthetic.interpret import interpret

    scores = _truth_scores(n_random, seed)
    exact = tempo_ok = 0
    frames = 0
    seconds = 0.0
    failures = []
    for name, score in scores.items():
        joints = interpret(score, fps=fps).joints()
        t0 = time.perf_counter()
        seg = segment_motion(joints, fps, tempo=score.tempo)
        seconds += time.perf_counter() - t0
        frames += joints.shape[0]
        diffs = score_differences(score, seg.score)
        exact += not diffs
        if diffs:
            failures.append((name, diffs))
        est = segment_motion(joints, fps)
        tempo_ok += est.tempo == score.tempo
    n = len(scores)
    print(f"truth round trip ({n} scores: {n - n_random} built-in + {n_random} random, {fps:g} fps)")
    print(f"  exact symbols, tempo given:      {exact}/{n} = {100 * exact / n:.1f} %")
    print(f"  estimated tempo equal to truth:  {tempo_ok}/{n} = {100 * tempo_ok / n:.1f} %")
    print(f"  quantisation speed:              {frames / seconds:,.0f} frames/s ({frames} frames)")
    for name, diffs in failures[:8]:
        print(f"  {name}: " + "; ".join(diffs[:4]))


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
            res = capture(d / "video.mp4", d / "cap", backend=backend, tempo=score.tempo, progress=False,
                          effort=False, overlay=False)
            dt = time.perf_counter() - t0
            a = score_agreement(score, res.score)
            rows.append((a, res.n_frames, dt))
            print(f"  score {i}: agreement {a['symbol_agreement']:.3f}, median start error "
                  f"{a['median_start_error']:.3f} beats, {a['unmatched']} unmatched, {res.n_frames / dt:.1f} frames/s")
    agree = np.mean([r[0]["symbol_agreement"] for r in rows])
    starts = np.nanmedian([r[0]["median_start_error"] for r in rows])
    fps = sum(r[1] for r in rows) / sum(r[2] for r in rows)
    print(f"whole capture ({backend}, {view}, {size[0]}x{size[1]}, {k} random scores, tempo given)")
    print(f"  symbol agreement (direction + level per part per beat): {100 * agree:.1f} %")
    print(f"  median start-time error: {starts:.3f} beats")
    print(f"  speed: {fps:.1f} frames/s (render excluded)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--random", type=int, default=40, help="random scores for the truth round trip")
    ap.add_argument("--video", type=int, default=0, help="random scores for the whole capture (slow)")
    ap.add_argument("--backend", default="blazepose", choices=("blazepose", "markers"))
    ap.add_argument("--view", default="front")
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args()
    bench_truth(args.random, args.seed)
    if args.video:
        bench_video(args.video, args.seed + 1, args.backend, args.view)


if __name__ == "__main__":
    main()
